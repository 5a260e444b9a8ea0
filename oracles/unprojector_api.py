"""The way back, judged: an unprojector from pixels and depth to world points, against the exact inverse.

    from wirecheck import assert_unprojector

    def test_my_unprojector():
        assert_unprojector(my_unproject)     # AssertionError naming the fault if not

``my_unproject(pixels, depth, camera) -> (N, 3)``: ``pixels`` ``(N, 2)`` float64 in the
project's pixel convention (x right, y down, integers at pixel centres), ``depth`` ``(N,)``
float64 along the camera's ``forward`` (``z_cam``, as a depth map holds it), ``camera`` the
projector contract's (:mod:`wirecheck.oracles.candidates.candidate`: ``K``, ``R``, ``t``,
``position``, ``forward``, ``up``, ...); it returns the world points, float64 or float32.

Every bundled scene (or those given) under every case camera: the visible surface points
of each frame (oracles.judge.unproject_points) against the exact inverse
(oracles.references.unproject_reference; OpenCV's undistortion for a camera with a lens),
each point within ``oracles.tolerances.unproject_bound`` (eps of the answer's precision
times the point's scale, never under 1e-6 px at its depth). A failing case's fault is named
by oracles.diagnosis.unproject_faults. A ``"FILE.py:FUNC"`` unprojector runs in its own process
(the candidate host, oracles.candidates.candidate_host): an ``os._exit`` or a crash fails its
case; a callable runs in this process.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
from wirecheck.core.errors import InputError
from wirecheck.core.outputs.output import claim, release_claim
from wirecheck.core.scene.frames import SceneRenderer
from wirecheck.core.transforms import Motion

from .call_args import checked_flag, checked_seconds
from .candidates.candidate import load_candidate
from .candidates.subprocess_candidate import DEFAULT_TIMEOUT_S, SubprocessCandidate, closing_started
from .cases import case_motion, cases_for
from .config import settings_for
from .diagnosis.unproject_faults import name_unproject_faults
from .judge import gate
from .judge.unproject_points import DEFAULT_STRIDE, surface_samples
from .reports.fault_text import below_table, case_cell, cell
from .reports.report_option import checked_report_dir
from .reports.unprojector_report import failing, flat_faults, write_unprojector_report
from .tolerances import unproject_bound

__all__ = ["UNPROJECT_DEFAULTS", "assert_unprojector", "check_unprojector", "flat_faults", "unprojector_failure_text"]

#: Settings when neither the call nor ``[tool.wirecheck]`` gives them: 2 frames of the scenes' spin per case,
#: one sample every 8 px, 10 s a request.
UNPROJECT_DEFAULTS = {"frames": 2, "turns": (1.0, 1.0, 0.0), "stride": DEFAULT_STRIDE, "timeout_s": DEFAULT_TIMEOUT_S}


def check_unprojector(
    func=None,
    scenes=None,
    frames: int | None = None,
    cases=None,
    turns=None,
    stride: int | None = None,
    allow_vacuous: bool = False,
    *,
    cmd: str | None = None,
    timeout_s: float | None = None,
    config=None,
    report_dir=None,
) -> dict:
    """Judge an unprojector against the exact inverse of the conventions and return the report.

    Parameters
    ----------
    func : callable or str
        ``func(pixels (N, 2), depth (N,), camera) -> (N, 3)`` world points (module docstring),
        or a ``"FILE.py:FUNC"`` / ``"MODULE:FUNC"`` string.
    scenes : sequence of str or Scene, optional
        Names, paths or scenes with faces (default: every bundled scene).
    frames : int
        Frames of each scene's motion per case (default 2).
    cases : sequence of str, optional
        Names from :data:`wirecheck.oracles.cases.ALL_CASE_NAMES` (default: the default
        seven; ``"calibrated"`` adds the calibrated ones, the distorted lens included).
    turns : (3,) tuple of float
        The scenes' spin, full turns about X, Y, Z over the run.
    stride : int
        One sample every ``stride`` pixels each way (>= 1, default 8).
    cmd : str, optional
        Instead of ``func``: an unprojector program speaking the candidate protocol's
        ``unproject`` requests (docs/protocol.md), as a command line; it is started once and ends
        with the check.
    allow_vacuous : bool
        Let a case with no visible surface point in any frame pass (its verdict ``"vacuous"``); by
        default it fails the report, as for check_projector and check_frames. A run with no point
        at all is an error either way (below). True or False only.
    timeout_s : float
        Seconds each request to ``cmd`` or to a ``"FILE.py:FUNC"`` unprojector may take (default 10).
    config : str, Path or False, optional
        The file whose ``[tool.wirecheck]`` fills ``scenes``, ``cases``, ``frames``, ``turns`` (its
        ``spin``) and ``timeout_s`` (its ``candidate-timeout``) where not given, as for
        :func:`~wirecheck.oracles.api.check_projector` (default: the nearest ``pyproject.toml`` at or
        above the working directory); False: no file. Its ``candidate`` is a projector and is not read.
    report_dir : str or Path, optional
        Write report.json and report.md there, pass or fail, as ``crosscheck --unprojector
        --report-dir`` does (oracles.reports.unprojector_report). A folder wirecheck did not write
        is never replaced (ValueError, before anything runs). Default None: nothing is written.

    Returns
    -------
    dict
        ``verdict`` ("pass" or "fail"), ``candidate``, ``cases`` (each: ``scene``, ``camera``,
        ``verdict``, ``points``, ``max_error``, ``max_error_ratio``, ``worst`` (frame, pixel),
        ``precision``, ``faults`` with ``name``, ``params``, ``hint`` (the catalogue's, oracles.faults, for an
        unprojector's points) and ``short`` (its table cell), and ``reasons``), ``compared``,
        ``settings`` (``scenes``, ``cases``, ``frames``, ``turns``, ``stride``) and ``timing``
        (``wall_s``, and each case's ``ms_per_frame``: the only values that differ between runs).

    Raises
    ------
    ValueError
        (InputError) Inputs that would compare nothing: an unknown scene or case, ``frames``
        or ``stride`` < 1, a spec string that does not load, or a run whose scenes give no
        visible surface point at all (a wireframe has none); a ``report_dir`` that is a file or
        holds anything wirecheck did not write.
    TypeError
        ``func`` neither callable nor a string, ``report_dir`` not a path, ``allow_vacuous`` not a
        bool, ``timeout_s`` not a number.
    """
    checked_flag(allow_vacuous, "allow_vacuous")
    given = {"scenes": scenes, "frames": frames, "cases": cases, "turns": turns, "timeout_s": timeout_s}
    settings = settings_for(given, config, UNPROJECT_DEFAULTS)
    scenes, frames, cases, turns, timeout_s = (settings.get(k) for k in given)
    timeout_s = checked_seconds(timeout_s)
    run_dir = checked_report_dir(report_dir)
    if run_dir is not None:
        claim(run_dir, "report_dir")  # checked and held before anything runs: one run per folder
    try:
        report = _check(func, scenes, frames, cases, turns, stride, cmd, timeout_s, allow_vacuous)
        if run_dir is not None:
            write_unprojector_report(run_dir, report, "report_dir")
    finally:
        if run_dir is not None:
            release_claim(run_dir)
    return report


def _check(func, scenes, frames, cases, turns, stride, cmd, timeout_s, allow_vacuous) -> dict:
    """:func:`check_unprojector` without its report folder."""
    started = time.perf_counter()
    stride = UNPROJECT_DEFAULTS["stride"] if stride is None else stride
    if isinstance(stride, bool) or not isinstance(stride, (int, np.integer)) or stride < 1:
        raise InputError(f"stride {stride!r}: expected an integer >= 1 (pixels between samples)")
    if (func is None) == (cmd is None):
        raise InputError('unprojector: expected one of func (a callable or "FILE.py:FUNC") and cmd (a program)')
    name = (
        cmd if cmd is not None else func if isinstance(func, str) else getattr(func, "__qualname__", None) or repr(func)
    )
    spec = None
    if isinstance(func, str):
        load_candidate(func, "unprojector", ("pixels", "depth", "camera"))  # a typo is an input error, here
        spec, func = func, None
    elif func is not None and not callable(func):
        raise TypeError(f'func {func!r}: expected a callable func(pixels, depth, camera) or a "FILE.py:FUNC" string')
    inputs = gate.run_inputs(scenes, frames, 1, cases, turns)
    motion = Motion(turns=inputs.turns)
    records, case_ms = [], []
    with closing_started():  # a program started for the check ends with it
        if cmd is not None:
            try:
                func = SubprocessCandidate.from_command(cmd, timeout_s=timeout_s).unproject
            except ValueError as exc:
                raise InputError(f"unprojector command {exc}") from None
        elif spec is not None:  # in its own process: os._exit or a crash fails its case, not the run
            func = SubprocessCandidate.python(spec, timeout_s=timeout_s, unproject=True).unproject
        for scene in inputs.scenes:
            by_name = {c.name: c for c in cases_for(scene, motion, calibrated=True)}
            for case_name in inputs.case_names:
                case_started = time.perf_counter()
                records.append(_judge_case(func, scene, by_name[case_name], motion, inputs.frames, stride))
                case_ms.append((time.perf_counter() - case_started) * 1000.0 / inputs.frames)
    points = sum(r["points"] for r in records)
    if points == 0:
        raise InputError(
            f"unprojector {name}: no visible surface point in {len(records)} case(s) "
            "(scenes without faces?): a check that compares nothing is no pass"
        )
    allowed = ("pass", "vacuous") if allow_vacuous else ("pass",)
    verdict = "pass" if all(r["verdict"] in allowed for r in records) else "fail"
    settings = {
        "scenes": [s.name for s in inputs.scenes],
        "cases": list(inputs.case_names),
        "frames": inputs.frames,
        "turns": [float(t) for t in inputs.turns],
        "stride": int(stride),
        "allow_vacuous": bool(allow_vacuous),
    }
    timing = {
        "wall_s": time.perf_counter() - started,
        "cases": [{"scene": r["scene"], "camera": r["camera"], "ms_per_frame": ms} for r, ms in zip(records, case_ms)],
    }
    return {
        "verdict": verdict,
        "candidate": name,
        "cases": records,
        "compared": {"cases": len(records), "frames": len(records) * inputs.frames, "points": points},
        "settings": settings,
        "timing": timing,
    }


def _judge_case(func, scene, case, motion, frames: int, stride: int) -> dict:
    """One scene x camera: every frame's samples through ``func``, errors against their bounds, faults."""
    cam = case.camera
    record = {
        "scene": scene.name,
        "camera": case.name,
        "verdict": "pass",
        "points": 0,
        "max_error": None,
        "max_error_ratio": None,
        "worst": None,
        "precision": None,
        "faults": [],
        "reasons": [],
    }
    renderer = SceneRenderer(scene, case_motion(motion, case), frames, style="shaded") if scene.faces else None
    given, got, bounds, frame_of = [], [], [], []
    precisions = set()
    for k in range(1, frames + 1):
        s = surface_samples(scene, case, motion, k, frames, stride, renderer) if renderer is not None else None
        if s is None or len(s) == 0:
            continue
        record["points"] += len(s)  # offered: a candidate that fails them still compared them
        try:
            out = func(s.p_px.copy(), s.depth.copy(), cam)
            arr = np.asarray(out)
            if arr.dtype.kind not in "fiu" or arr.shape != (len(s), 3):
                raise ValueError(
                    f"returned {type(out).__name__} of shape {getattr(arr, 'shape', None)} and dtype "
                    f"{getattr(arr, 'dtype', None)}: expected an ({len(s)}, 3) float array"
                )
        except (Exception, SystemExit) as exc:  # its failure (or its sys.exit) fails its case, in one line
            record["verdict"] = "fail"
            record["reasons"].append(f"frame {k}: unprojector {type(exc).__name__}: {' '.join(str(exc).split())[:200]}")
            continue
        told = getattr(getattr(func, "__self__", None), "answer_precision", None)  # a program's own word
        precision = (
            told()
            if told is not None
            else ("float32" if arr.dtype.kind == "f" and arr.dtype.itemsize <= 4 else "float64")
        )
        precisions.add(precision)
        given.append(s)
        got.append(arr.astype(np.float64))
        bounds.append(unproject_bound(s.p_px, s.depth, cam, precision))
        frame_of.append(np.full(len(s), k))
    if record["reasons"]:
        return record
    if record["points"] == 0:
        record["verdict"] = "vacuous"
        record["reasons"].append("vacuous: no visible surface point in any frame")
        return record
    p_px = np.concatenate([s.p_px for s in given])
    depth = np.concatenate([s.depth for s in given])
    expected = np.concatenate([s.p_world for s in given])
    cand = np.concatenate(got)
    bound = np.concatenate(bounds)
    frame = np.concatenate(frame_of)
    with np.errstate(invalid="ignore"):
        err = np.linalg.norm(cand - expected, axis=1)
    err = np.where(np.isfinite(err), err, np.inf)
    ratio = err / bound
    i = int(np.argmax(ratio))
    record.update(
        max_error=float(err[i]),
        max_error_ratio=float(ratio[i]),
        bound_at_worst=float(bound[i]),
        worst={"frame": int(frame[i]), "pixel": [float(v) for v in p_px[i]], "depth": float(depth[i])},
        precision="float32" if "float32" in precisions else "float64",
    )
    if ratio[i] <= 1.0:
        return record
    record["verdict"] = "fail"
    bad = int((ratio > 1.0).sum())
    record["reasons"].append(
        f"{bad} of {len(err)} points off: max error {err[i]:.3g} > bound {bound[i]:.3g} "
        f"(frame {int(frame[i])}, pixel ({p_px[i, 0]:.6g}, {p_px[i, 1]:.6g}), depth {depth[i]:.6g})"
    )
    faults, measured = name_unproject_faults(p_px, depth, cam, cand, bound)
    record["faults"] = [
        {"name": f.name, "params": dict(f.params), "hint": f.hint, "short": cell(f.as_dict())} for f in faults
    ]
    record["measured"] = measured
    return record


def unprojector_failure_text(report: dict) -> str | None:
    """The failing cases, their faults (a cell each, oracles.reports.fault_text) and reasons, then what to
    check once per fault kind; None when the verdict is pass."""
    bad = failing(report)
    if not bad:
        return None
    lines = [f"{len(bad)} of {len(report['cases'])} unprojector cases failed for {report['candidate']}:"]
    for c in bad:
        cells = case_cell(c["faults"]) if c["faults"] else "none named"
        lines.append(f"  {c['scene']} / {c['camera']}: faults: {cells}; " + "; ".join(c["reasons"]))
    lines += below_table(bad, source="points")
    comp = report["compared"]
    lines.append(f"  in all: {comp['cases']} cases, {comp['frames']} frames, {comp['points']:,} points compared")
    return "\n".join(lines)


def assert_unprojector(func=None, **kwargs) -> dict:
    """:func:`check_unprojector`, raising AssertionError with the diagnosis unless the verdict is pass.

    Parameters
    ----------
    func : callable or str, optional
        As for :func:`check_unprojector` (or ``cmd=`` among the keywords, as for assert_projector).
    **kwargs
        Any keyword of :func:`check_unprojector`.

    Returns
    -------
    dict
        The report, when every case passed.

    Raises
    ------
    AssertionError
        Naming each failing case, its faults and reasons, and what to check.
    """
    __tracebackhide__ = True
    report = check_unprojector(func, **kwargs)
    text = unprojector_failure_text(report)
    if text is not None:
        if kwargs.get("report_dir") is not None:
            text += f"\n  report: {Path(kwargs['report_dir']) / 'report.md'}"
        raise AssertionError(text)
    return report
