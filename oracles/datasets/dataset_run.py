"""Check every mesh of a dataset (oracles.datasets.dataset) and sum the run up: meshes passed, worst cases, faults by count.

One task per mesh: the mesh is read where the task runs (a worker of a
process pool or of a Dask cluster, oracles.executors), then each case camera
is run on it as a plain crosscheck runs it (oracles.runner). A mesh that
cannot be read, or that no camera fits, is a mesh with verdict ``"error"``
and its one-line reason: it is counted and reported, and the run goes on.

The run's verdict (the gate's rules, oracles.judge.gate, plus the meshes'):

- ``"pass"`` only when every mesh loaded and every case passed (vacuous
  cases as ``allow_vacuous`` says) and something was compared;
- a mesh that failed to load fails the run unless ``allow_load_errors``
  (a dataset with a corrupt file is not a dataset that passed);
- when no mesh loaded at all, :class:`NothingLoaded` is raised: the run
  compared nothing, whatever the flags (the CLI's exit 2).

Results are gathered in the dataset's (sorted) order, and everything that
depends on time or on where a task ran is under ``report["timing"]``: the
rest of the report is the same bytes for ``--jobs 1``, ``--jobs N`` and a
Dask cluster.
"""

from __future__ import annotations

import collections
import dataclasses
import time
from pathlib import Path

from wirecheck.core.errors import InputError, one_line
from wirecheck.core.scene.files import load_mesh_file
from wirecheck.core.transforms import Motion
from wirecheck.core.user_files import expected, problem

from ..candidates.core_candidate import RenderMode
from ..cases import calibrated_cases
from ..executors import ExecutorSpec, gather_in_order, open_executor
from ..judge import gate
from ..runner import (
    LEVEL_ORACLES,
    LEVELS,
    WORKER_LOCK,
    CaseRunner,
    RunParams,
    overall_ms,
    scene_cases,
    worker_init,
    worker_runner,
    worst_key,
)
from ..tolerances import Tolerances
from .dataset import Dataset, MeshEntry
from .memory_budget import default_budget, over_budget

#: The fields of a case record kept in a dataset's report (the per-frame detail of
#: thousands of cases would make report.json hundreds of megabytes; rerun one mesh for it).
CASE_KEYS = (
    "scene",
    "camera",
    "verdict",
    "reasons",
    "faults",
    "max_vertex_error_px",
    "mean_vertex_error_px",
    "pixel_f1_0px",
    "pixel_f1_1px",
    "silhouette_iou",
    "depth_max_error",
    "depth_error_ratio",
    "visible_points",
    "compared",
    "note",
    "candidate_stderr",
)
#: How many cases the summary names as the worst.
WORST_N = 10


class NothingLoaded(InputError):
    """No mesh of the dataset could be loaded: the run compared nothing."""


def _load(entry: MeshEntry):
    """The mesh as a Scene named by its dataset name; InputError with a one-line reason otherwise."""
    if entry.error is not None:
        raise InputError(entry.error)
    refused = problem(entry.path, "mesh")
    if refused == "missing":
        raise InputError("file not found")
    if refused is not None:
        raise InputError(f"{refused}: expected {expected('mesh')}")
    try:
        scene = load_mesh_file(Path(entry.path))
    except Exception as exc:  # any reader's failure is this mesh's, never the run's end
        text = str(exc) if isinstance(exc, InputError) else f"{type(exc).__name__}: {exc}"
        for path in (entry.path, one_line(entry.path)):  # as the reader wrote it, or made one line
            text = text.replace(f"{path}: ", "")
        raise InputError(_named(text, entry)) from None
    return dataclasses.replace(scene, name=entry.name, source=entry.name)


def _named(text: str, entry: MeshEntry) -> str:
    """``text`` with the mesh's path (as the reader wrote it, or made one line) replaced by its dataset name."""
    for path in (entry.path, one_line(entry.path)):
        text = text.replace(path, entry.name)
    return text


def check_mesh(
    entry: MeshEntry, params: RunParams, case_names, runner=None, budget: int | None = None
) -> tuple[dict, dict, dict | None]:
    """``(mesh record, timing, oracle GL info or None)`` of one mesh under every case in ``case_names``.

    ``runner`` (:class:`oracles.runner._CaseRunner`): None in a worker process
    (its own runner, made on first use). ``budget``: bytes a mesh may need
    (oracles.datasets.memory_budget); a mesh over it is an error, not checked.
    """
    t0 = time.perf_counter()
    record = {"mesh": entry.name}
    try:
        scene = _load(entry)
        cases = scene_cases(scene, case_names, params.motion)
    except InputError as exc:
        text = str(exc)
        if text.startswith(f"{entry.name}:"):  # "NAME: why" or "NAME:LINE: why": the record names the mesh
            rest = text[len(entry.name) + 1 :]
            line, sep, why = rest.partition(": ")
            text = f"line {line}: {why}" if sep and line.isdigit() else rest.lstrip()
        record.update(verdict="error", error=text)
        return record, {"mesh": entry.name, "load_s": time.perf_counter() - t0, "cases": []}, None
    t_load = time.perf_counter() - t0
    record.update(vertices=len(scene.vertices), edges=len(scene.edges), faces=len(scene.faces))
    why = over_budget(len(scene.vertices), len(scene.edges), len(scene.faces), budget)
    if why is not None:  # one mesh's load error, not the machine's memory
        record.update(verdict="error", error=why)
        return record, {"mesh": entry.name, "load_s": t_load, "cases": []}, None
    if scene.load_notes:  # read leniently (core.scene.files): said in the report, the mesh checked
        record["warnings"] = [_named(note, entry) for note in scene.load_notes]
    results = [runner.run(scene, case, params) for case in cases]
    rows = [{k: r.record[k] for k in CASE_KEYS if k in r.record} for r in results]
    verdicts = {row["verdict"] for row in rows}
    record["verdict"] = "fail" if "fail" in verdicts else "vacuous" if "vacuous" in verdicts else "pass"
    record["cases"] = rows
    timing = {
        "mesh": entry.name,
        "load_s": t_load,
        "check_s": time.perf_counter() - t0 - t_load,
        "cases": [{"camera": case.name, **r.timing} for case, r in zip(cases, results)],
    }
    gl = next((r.gl_info for r in results if getattr(r, "gl_info", None) is not None), None)
    return record, timing, gl


def _worker_check_mesh(
    entry: MeshEntry, params: RunParams, case_names, budget: int | None = None
) -> tuple[dict, dict, dict | None]:
    with WORKER_LOCK:
        return check_mesh(entry, params, case_names, worker_runner(), budget)


def faults_by_count(meshes: list[dict]) -> list[dict]:
    """``[{"fault", "cases", "meshes"}]``: each fault named in any case, most frequent first (then by name)."""
    cases, meshes_with = collections.Counter(), collections.Counter()
    for m in meshes:
        names = [f["name"] for c in m.get("cases", []) for f in c.get("faults", [])]
        cases.update(names)
        meshes_with.update(set(names))
    return [
        {"fault": f, "cases": n, "meshes": meshes_with[f]}
        for f, n in sorted(cases.items(), key=lambda item: (-item[1], item[0]))
    ]


#: Failed cases are worse than vacuous ones, which are worse than passes, whatever their scores
#: (a case fails on a reason its F1 may not show, e.g. one-sided pixels, oracles.judge.verdict).
_VERDICT_RANK = {"fail": 0, "vacuous": 1, "pass": 2}


def worst_cases(meshes: list[dict], n: int = WORST_N) -> list[dict]:
    """The ``n`` worst cases over the dataset: failed first, then by oracles.runner.worst_key (ties: dataset order)."""
    rows = [c for m in meshes for c in m.get("cases", []) if c.get("compared", {}).get("frames")]
    keep = (
        "scene",
        "camera",
        "verdict",
        "max_vertex_error_px",
        "pixel_f1_0px",
        "pixel_f1_1px",
        "silhouette_iou",
        "depth_error_ratio",
        "faults",
        "reasons",
    )
    ranked = sorted(rows, key=lambda c: (_VERDICT_RANK.get(c["verdict"], 0), worst_key(c)))
    return [{k: c[k] for k in keep if k in c} for c in ranked[:n]]


def summarize(meshes: list[dict], level: str, allow_vacuous: bool, allow_load_errors: bool) -> tuple[str, dict, dict]:
    """``(verdict, compared, summary)`` of the mesh records (module docstring for the verdict)."""
    records = [c for m in meshes for c in m.get("cases", [])]
    compared = gate.compared_totals(records, level)
    errors = [m for m in meshes if m["verdict"] == "error"]
    counts = collections.Counter(m["verdict"] for m in meshes)
    verdict = gate.run_verdict(records, compared, level, allow_vacuous)
    if errors and not allow_load_errors:
        verdict = "fail"
    summary = {
        "meshes": len(meshes),
        "passed": counts["pass"],
        "failed": counts["fail"],
        "vacuous": counts["vacuous"],
        "load_errors": len(errors),
        "cases": len(records),
        "cases_failed": sum(1 for r in records if r["verdict"] == "fail"),
        "faults": faults_by_count(meshes),
        "worst_cases": worst_cases(meshes),
        "errors": [{"mesh": m["mesh"], "error": m["error"]} for m in errors],
    }
    warned = [{"mesh": m["mesh"], "warning": w} for m in meshes for w in m.get("warnings", [])]
    if warned:  # read leniently, and checked (core.scene.files)
        summary["warnings"] = warned
    return verdict, compared, summary


def run_dataset(
    dataset: Dataset,
    candidate,
    *,
    frames: int = 24,
    case_names=None,
    turns=(1.0, 1.0, 0.0),
    tol: Tolerances | None = None,
    level: str = "pixels",
    every: int = 1,
    mode: RenderMode | None = None,
    candidate_name: str = "candidate",
    allow_vacuous: bool = False,
    allow_load_errors: bool = False,
    executor: ExecutorSpec | None = None,
    progress=None,
    memory_budget="auto",
) -> dict:
    """Every mesh of ``dataset`` under every case: the report dict (module docstring).

    ``candidate`` is as for :func:`oracles.runner.run_crosscheck` (picklable
    when the meshes run in workers). ``progress(meshes_done, meshes)`` is
    called before the first mesh and after each. Raises InputError for inputs
    that would compare nothing (oracles.judge.gate.run_settings) and
    :class:`NothingLoaded` when no mesh could be read. ``memory_budget``:
    bytes one mesh may need (oracles.datasets.memory_budget), ``"auto"`` for
    half the machine's memory shared by the local workers, None for no budget.
    """
    if level not in LEVELS:
        raise ValueError(f"level {level!r}: expected one of {', '.join(LEVELS)}")
    mode = mode or RenderMode()
    tol = tol or Tolerances()
    executor = executor or ExecutorSpec()
    inputs = gate.run_settings(frames, every, case_names, turns, tol)
    if level == "pixels":
        distorted = {c.name for c in calibrated_cases(1.0) if c.camera.distortion is not None}
        if set(inputs.case_names) <= distorted:  # as oracles.runner.run_crosscheck says it
            raise InputError(
                f"cases {', '.join(inputs.case_names)} at level pixels: lens distortion: their "
                "pixels are not compared (GL draws straight lines), so the run would compare no "
                "pixel; expected level vertices or a case without distortion"
            )
    params = RunParams(
        frames=inputs.frames,
        every=inputs.every,
        level=level,
        motion=Motion(turns=inputs.turns),
        tol=tol,
        candidate=candidate,
        mode=mode,
        keep_frames=False,
    )
    # "auto": the workers on this machine share it (a remote cluster's machines: one worker's share)
    budget = (
        default_budget(executor.jobs if executor.scheduler is None else 1) if memory_budget == "auto" else memory_budget
    )
    entries = list(dataset.entries)
    t_run = time.perf_counter()
    done = 0

    def on_result(result) -> None:
        nonlocal done
        done += 1
        if progress:
            progress(done, len(entries))

    if progress:
        progress(0, len(entries))
    with open_executor(executor, len(entries), initializer=worker_init) as (pool, workers):
        startup_s = time.perf_counter() - t_run  # a Dask cluster's start, or nothing
        if pool is None:
            runner = CaseRunner()
            try:
                results = []
                for entry in entries:
                    results.append(check_mesh(entry, params, inputs.case_names, runner, budget))
                    on_result(results[-1])
            finally:
                runner.close()
        else:
            items = [(entry, params, inputs.case_names, budget) for entry in entries]
            results = gather_in_order(pool, _worker_check_mesh, items, on_result)
    wall_s = time.perf_counter() - t_run
    meshes = [r[0] for r in results]
    if all(m["verdict"] == "error" for m in meshes):
        first = meshes[0]
        raise NothingLoaded(
            f"none of the {len(meshes)} meshes could be loaded (first: {first['mesh']}: "
            f"{first['error']}): nothing compared"
        )
    verdict, compared, summary = summarize(meshes, level, allow_vacuous, allow_load_errors)
    return {
        "tool": "wirecheck crosscheck",
        "verdict": verdict,
        "allow_vacuous": allow_vacuous,
        "allow_load_errors": allow_load_errors,
        "dataset": dataset.to_dict(),
        "compared": compared,
        "candidate": candidate_name,
        "candidate_settings": candidate.settings() if hasattr(candidate, "settings") else None,
        "level": level,
        "oracle_gl": next((r[2] for r in results if r[2] is not None), None),  # one driver per machine
        **mode.to_dict(),
        "oracles": list(LEVEL_ORACLES[level]),
        "frames": inputs.frames,
        "every": inputs.every,
        "frames_checked": inputs.frames_checked,
        "cameras": list(inputs.case_names),
        "motion": {"turns": list(inputs.turns)},
        "tolerances": tol.to_dict(shaded=mode.shaded),
        "summary": summary,
        "meshes": meshes,
        "timing": _timing([r[1] for r in results], executor, workers, wall_s, startup_s, level),
    }


def _timing(
    per_mesh: list[dict], executor: ExecutorSpec, workers: int, wall_s: float, startup_s: float, level: str
) -> dict:
    """Times of the run: per-frame stage means over every case (as a plain run's), and meshes per second.

    ``meshes_per_s`` counts from the moment the workers were ready (``startup_s``
    is the executor's start: a process pool's or a Dask cluster's).
    """
    cases = [c for m in per_mesh for c in m["cases"]]
    keys = [
        "vertex_stage_ms_per_frame",
        "candidate_ms_per_frame",
        "opencv_ms_per_frame",
        "harness_ms_per_frame",
        "oracles_ms_per_frame",
    ]
    if level == "pixels":
        keys += ["pixel_stage_ms_per_frame", "pyrender_ms_per_frame", "pixel_metrics_ms_per_frame"]
    timing = {k: overall_ms(cases, k) for k in keys}
    oracles_ms, harness_ms = timing["oracles_ms_per_frame"], timing["harness_ms_per_frame"]
    timing["harness_overhead_ratio"] = harness_ms / oracles_ms if oracles_ms and harness_ms is not None else None
    busy_s = sum(m["load_s"] + m.get("check_s", 0.0) for m in per_mesh)
    run_s = wall_s - startup_s
    timing.update(
        {
            **executor.to_dict(),
            "workers": workers,
            "wall_s": wall_s,
            "startup_s": startup_s,
            "meshes_per_s": len(per_mesh) / run_s if run_s > 0 else None,
            "mesh_s_mean": busy_s / len(per_mesh),
            "meshes": per_mesh,
        }
    )
    return timing
