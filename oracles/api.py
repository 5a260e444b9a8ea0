"""crosscheck from Python: gate your own projector inside your own pytest suite.

    from wirecheck.oracles.api import assert_projector

    def test_my_projector_matches_the_references():
        assert_projector(my_project)        # AssertionError naming the fault if not

``my_project(points, camera) -> (N, 2)`` follows the candidate contract
(:mod:`oracles.candidates.candidate`). A projector in another language is given as
``cmd="./my_projector --flag"`` (the candidate protocol, docs/protocol.md).

Isolation: a candidate given as a string (``"FILE.py:FUNC"``) or ``cmd`` runs
in its own process under a per-request timeout (``timeout_s``), so a crash,
``os._exit`` or a hang fails a case instead of ending or blocking your test
run. A callable runs isolated too: in the candidate host when another
process can import it (a module-level function of an importable module),
else (a lambda, a closure, a bound method) in a forked copy of this process;
``isolate=False`` runs it in this process, quicker but unprotected. An
isolated candidate's process is started for one call and ends with it (none
is left idle in a test run of many checks). By default only the OpenCV vertex oracle runs (fast,
no OpenGL needed); pass ``oracles=("opencv", "pyrender")`` to compare drawn
pixels too.
"""

from __future__ import annotations

from wirecheck.core.errors import InputError
from wirecheck.core.outputs.output import claim, release_claim

from . import tolerances
from .call_args import checked_flag, checked_seconds
from .candidates.caller_state import caller_state_kept
from .candidates.isolation import api_candidate
from .candidates.subprocess_candidate import DEFAULT_TIMEOUT_S, closing_started
from .config import settings_for
from .judge import gate
from .references.pyrender_oracle import GLUnavailable, gl_available
from .reports.compared import hint_lines, what_text
from .reports.fault_text import case_cell
from .reports.fmt import short_repr
from .reports.report import compared_text, not_passed, write_report
from .reports.report_option import checked_report_dir
from .runner import run_crosscheck
from .tolerances import Tolerances

#: check_projector's settings when neither the call nor ``[tool.wirecheck]`` gives them: vertices
#: (OpenCV only, no OpenGL) over 8 frames, quick enough for a unit test; crosscheck's own are
#: pixels over 24 frames (docs/pytest.md, "Two questions, two sets of defaults").
API_DEFAULTS = {
    "frames": 8,
    "oracles": ("opencv",),
    "tol_px": tolerances.VERTEX_TOL_PX,
    "min_f1": tolerances.MIN_F1_1PX,
    "min_f1_0px": tolerances.MIN_F1_0PX,
    "turns": (1.0, 1.0, 0.0),
    "timeout_s": DEFAULT_TIMEOUT_S,
}


def check_projector(
    func=None,
    scenes=None,
    frames: int | None = None,
    cases=None,
    oracles=None,
    tol_px: float | None = None,
    min_f1: float | None = None,
    min_f1_0px: float | None = None,
    turns=None,
    allow_vacuous: bool = False,
    *,
    cmd=None,
    timeout_s: float | None = None,
    isolate: bool | None = None,
    precision: str | None = None,
    config=None,
    report_dir=None,
) -> dict:
    """Crosscheck a projector against OpenCV (and pyrender) and return the report.

    A setting not given (None) comes from ``[tool.wirecheck]`` in the nearest ``pyproject.toml``
    at or above the working directory, as for crosscheck, else from :data:`API_DEFAULTS`
    (every bundled scene, the default cases, 8 frames, vertices only).

    Parameters
    ----------
    func : callable or str, optional
        The candidate, ``func(points, camera) -> p_px``: ``points`` (N, 3)
        float64 world coordinates, ``camera`` with the fields of
        :class:`~wirecheck.core.camera.Camera`, ``p_px`` (N, 2) pixels with
        NaN rows where clipped (:mod:`wirecheck.oracles.candidates.candidate`). Or a
        ``"FILE.py:FUNC"`` / ``"MODULE:FUNC"`` string.
    scenes : sequence of str or Scene, optional
        Names, paths or :class:`~wirecheck.core.scene.model.Scene` objects
        (default: every bundled scene).
    frames : int
        Frames of each scene's motion per case (>= 1).
    cases : sequence of str, optional
        Names from :data:`wirecheck.oracles.cases.ALL_CASE_NAMES` (default: the
        default set ``CASE_NAMES``; the calibrated cases run when named).
    oracles : tuple of {"opencv", "pyrender"}, or str
        ``("opencv",)`` compares vertices only (no OpenGL needed);
        ``("opencv", "pyrender")`` compares drawn pixels too. A string is
        one name or a comma-separated list (``"opencv,pyrender"``).
    tol_px, min_f1, min_f1_0px : float
        Vertex tolerance in pixels; F1 floors at 1 px and 0 px.
    turns : (3,) tuple of float
        The scenes' spin: full turns about X, Y, Z over the run.
    allow_vacuous : bool
        Let a case that compared nothing (every point clipped in every frame)
        pass; by default its verdict ``"vacuous"`` fails the report. True or
        False only (a string such as ``"no"`` would be truthy).
    cmd : str or sequence of str, optional
        Instead of ``func``: a projector program speaking the candidate
        protocol (docs/protocol.md), as a command line or an argv list.
    timeout_s : float
        Seconds each request to an isolated candidate may take (default 10).
    isolate : bool, optional
        None or True (default None): run ``func`` in its own process (the
        candidate host for a string or an importable function, a forked copy
        of this process for a lambda or a closure); False: run a callable in
        this process (an ``os._exit`` in it then ends your test run).
    precision : {"float32", "float64"}, optional
        What the projector computes in; its vertex bound is derived from it
        (:func:`wirecheck.oracles.tolerances.vertex_bound`). Default None:
        inferred from the dtype it returns (float32 arrays: float32). A
        declared precision wins over the returned dtype: float64 declared and
        float32 returned is judged at float64, and its float32 rounding is
        named ``precision_limited``.
    config : str, Path or False, optional
        The file whose ``[tool.wirecheck]`` fills the settings not given (default: the nearest
        ``pyproject.toml`` at or above the working directory); False: no file.
    report_dir : str or Path, optional
        Write the report there as crosscheck's ``--report-dir`` does: report.json, report.md and
        report.html with their pictures (worst_points.png at level vertices; the worst frames,
        their crops and worst.gif at level pixels). A folder wirecheck did not write is never
        replaced (ValueError). Default None: nothing is written.

    Returns
    -------
    dict
        The report, as written to report.json: ``verdict``, ``cases`` (each
        with its ``verdict``, ``faults``, ``reasons`` and errors), ``compared``.

    Raises
    ------
    ValueError
        (:class:`~wirecheck.core.errors.InputError`) Inputs that would compare
        nothing: no scene or case, an unknown or repeated name, ``frames`` < 1,
        a NaN or boolean tolerance, a precision other than float32 or float64,
        ``timeout_s`` not finite and > 0; neither ``func`` nor ``cmd``, or both;
        a ``report_dir`` that is a file, or a folder with files wirecheck did not write.
    TypeError
        An argument of the wrong kind, named with its value and what was
        expected: ``func`` not callable (nor a string) or not callable as
        ``func(points, camera)``, ``cmd`` not a string or a list of strings,
        a ``timeout_s``, ``isolate`` or ``allow_vacuous`` of the wrong type.
    RuntimeError
        (:class:`~wirecheck.oracles.references.pyrender_oracle.GLUnavailable`) ``"pyrender"`` asked for
        but its GL cannot draw here: one line naming the missing library and its fix.

    Notes
    -----
    The caller's process-wide settings are as they were after the call
    (:mod:`wirecheck.oracles.candidates.caller_state`): warning filters, numpy's error
    state and print options, ``os.environ``, ``sys.path``, the current
    directory, logging and signal handlers.
    """
    run_dir = checked_report_dir(report_dir)
    if run_dir is not None:
        claim(run_dir, "report_dir")  # held until the report is in place: one run per folder
    try:
        report, images = run_check(
            func,
            scenes,
            frames,
            cases,
            oracles,
            tol_px,
            min_f1,
            min_f1_0px,
            turns,
            allow_vacuous,
            cmd=cmd,
            timeout_s=timeout_s,
            isolate=isolate,
            precision=precision,
            config=config,
        )
        if run_dir is not None:
            write_report(run_dir, report, images)
    finally:
        if run_dir is not None:
            release_claim(run_dir)
    return report


def run_check(
    func=None,
    scenes=None,
    frames=None,
    cases=None,
    oracles=None,
    tol_px=None,
    min_f1=None,
    min_f1_0px=None,
    turns=None,
    allow_vacuous=False,
    *,
    cmd=None,
    timeout_s=None,
    isolate=None,
    precision=None,
    config=None,
) -> tuple[dict, dict]:
    """:func:`check_projector`'s work: the report and its pictures' data.

    The second value is what :func:`wirecheck.oracles.reports.report.write_report` draws: the
    worst frames' images at level pixels, the worst case's points (``images["points"]``,
    worst_points.png) at level vertices; the ``wirecheck`` fixture's ``--wirecheck-report``
    writes them, so its reports show what crosscheck's show.
    """
    given = {
        "scenes": scenes,
        "frames": frames,
        "cases": cases,
        "oracles": oracles,
        "tol_px": tol_px,
        "min_f1": min_f1,
        "min_f1_0px": min_f1_0px,
        "turns": turns,
        "timeout_s": timeout_s,
        "precision": precision,
    }
    settings = settings_for(given, config, API_DEFAULTS)
    scenes, frames, cases, oracles, tol_px, min_f1, min_f1_0px, turns, timeout_s, precision = (
        settings.get(k) for k in given
    )
    if func is None and cmd is None:  # the table's candidate, as for the fixture
        func, cmd = settings.get("candidate"), settings.get("candidate_cmd")
    func, cmd = _candidate_args(func, cmd)
    checked_flag(allow_vacuous, "allow_vacuous")
    if isolate is not None:
        checked_flag(isolate, "isolate", "(or None: the default)")
    timeout_s = checked_seconds(timeout_s)
    oracles = _oracles(oracles)
    tol = Tolerances(tol_px, min_f1, min_f1_0px, precision=_precision(precision))
    inputs = gate.run_inputs(scenes, frames, 1, cases, turns, tol)  # before any OpenGL set-up
    with caller_state_kept(), closing_started():  # the caller's globals as they were; no process left
        name, func = api_candidate(func, cmd, timeout_s, isolate)
        if "pyrender" in oracles:
            ok, message = gl_available()
            if not ok:
                raise GLUnavailable(message)
        report, images = run_crosscheck(
            inputs.scenes,
            func,
            frames=inputs.frames,
            case_names=inputs.case_names,
            oracles=oracles,
            turns=inputs.turns,
            tol=tol,
            candidate_name=name,
            allow_vacuous=allow_vacuous,
        )
    return {"run": None, **report}, images  # report.json's fields: "run" is crosscheck's --run name


def _candidate_args(func, cmd):
    """``(func, cmd)`` checked: exactly one given, ``func`` a callable of two arguments or a spec string,
    ``cmd`` a command string or a sequence of strings; TypeError/ValueError naming the argument otherwise."""
    import inspect
    import os

    if func is None and cmd is None:
        raise ValueError('no candidate: expected func (a callable or "FILE.py:FUNC") or cmd (a program)')
    if func is not None and cmd is not None:
        raise ValueError(f"func {short_repr(func)} and cmd {short_repr(cmd)}: expected one candidate, not both")
    if cmd is not None:
        if isinstance(cmd, (str, os.PathLike)):
            return None, os.fspath(cmd)
        argv = list(cmd) if isinstance(cmd, (list, tuple)) else None
        if argv is None or not all(isinstance(a, (str, os.PathLike)) for a in argv):
            raise TypeError(f"cmd {short_repr(cmd)}: expected a command line (str) or an argv list of str")
        return None, [os.fspath(a) for a in argv]
    if isinstance(func, str):
        return func, None
    if not callable(func):
        raise TypeError(
            f'func {short_repr(func)}: expected a callable func(points, camera) or a "FILE.py:FUNC" / '
            '"MODULE:FUNC" string'
        )
    try:
        signature = inspect.signature(func)
    except (TypeError, ValueError):  # builtins and C callables without one: found out when called
        return func, None
    try:
        signature.bind(None, None)
    except TypeError:
        name = getattr(func, "__qualname__", None) or short_repr(func)
        raise TypeError(
            f"func {name}{signature} cannot be called as func(points, camera): expected "
            "the candidate contract (wirecheck.oracles.candidates.candidate)"
        ) from None
    return func, None


def _oracles(oracles) -> tuple:
    """``oracles`` as a tuple of names; a string is one name or a comma-separated list (``"opencv,pyrender"``)."""
    if isinstance(oracles, str):
        return tuple(o.strip() for o in oracles.split(",") if o.strip())
    if not isinstance(oracles, (list, tuple)) or not all(isinstance(o, str) for o in oracles):
        raise TypeError(
            f"oracles {short_repr(oracles)}: expected a tuple of names among opencv, pyrender "
            '("opencv": vertices; ("opencv", "pyrender"): pixels too)'
        )
    return tuple(oracles)


def _precision(precision):
    """``precision`` checked: None, "float32" or "float64"; InputError (a ValueError) otherwise."""
    if precision is not None and precision not in tolerances.PRECISIONS:
        raise InputError(
            f"precision {precision!r}: expected one of {', '.join(tolerances.PRECISIONS)} "
            "(or None: inferred from the dtype the projector returns)"
        )
    return precision


def failure_text(report: dict) -> str | None:
    """The diagnosis of a report's failing cases (faults, reasons, what to check); None when its verdict is pass.

    Failing cases are the failed ones and the vacuous ones (compared nothing) unless the run allowed them.
    """
    failing = not_passed(report)
    if not failing:
        if report["verdict"] == "pass":
            return None
        return f"crosscheck of {report['candidate']}: verdict {report['verdict']} with no failing case" + (
            f" ({compared_text(report)})" if "compared" in report else ""
        )
    lines = [f"{len(failing)} of {len(report['cases'])} crosscheck cases failed for {report['candidate']}:"]
    lines[0] = f"{what_text(report)}\n{lines[0]}"
    for c in failing:  # a vacuous case's reason starts with "vacuous:"
        lines.append(
            f"  {c['scene']} / {c['camera']}: faults: {case_cell(c['faults'], c.get('camera_spec'))}; "
            + "; ".join(c["reasons"])
        )
    lines += hint_lines(report, failing)
    if "compared" in report:
        lines.append(f"  in all: {compared_text(report)}")
    return "\n".join(lines)


def assert_projector(func=None, **kwargs) -> dict:
    """:func:`check_projector`, raising AssertionError with the diagnosis unless the verdict is pass.

    Parameters
    ----------
    func : callable or str, optional
        The candidate, as for :func:`check_projector` (or ``cmd=`` among the keywords).
    **kwargs
        Any keyword of :func:`check_projector`.

    Returns
    -------
    dict
        The report, when every case passed.

    Raises
    ------
    AssertionError
        Naming each failing case, its faults and reasons, and what to check.
    """
    __tracebackhide__ = True  # pytest: the failure points at the caller's line
    return raise_unless_pass(check_projector(func, **kwargs), kwargs.get("report_dir"))


def raise_unless_pass(report: dict, report_dir=None) -> dict:
    """``report`` when its verdict is pass; else AssertionError with :func:`failure_text` (and, with
    ``report_dir``, the report's path last): the body of assert_projector and assert_frames."""
    __tracebackhide__ = True
    text = failure_text(report)
    if text is None:
        return report
    if report_dir is not None:
        from pathlib import Path

        text += f"\n  report: {Path(report_dir) / 'report.html'}"
    raise AssertionError(text)
