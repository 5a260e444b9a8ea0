"""Run the cases: candidate vs OpenCV (vertices) and vs pyrender on OSMesa or EGL (pixels).

Each case (a scene under one camera) is run by :func:`oracles.judge.case.run_case`:
frames 1, 1 + every, 1 + 2 every, ... of the scene's motion, a vertex stage
and a pixel stage per frame, then the record and its verdict (oracles.judge.verdict).
This module runs every case of a run, here or in worker processes, and sums
them up into the report.

Drawing modes (:class:`RenderMode`, the core candidate only; the pixel level):

- ``hidden_lines``: core draws with ``hidden_lines=True`` and the scene's
  faces; pyrender draws the same faces black with glPolygonOffset(1, 1) and
  the lines on top. Judged by the same pixel F1 as a plain wireframe. A scene
  without faces has nothing that could hide a line: it is compared as a plain
  wireframe, with a note (not a failure), and ``"hidden_lines": false``.
- ``cull="backface"``: core culls back faces (core.projector.culling's rule) and draws an
  edge only if it belongs to a kept face or to none. The oracle decides front
  faces itself in float64 world space (oracles.references.faces), draws the kept edges,
  and, with hidden lines, gives pyrender single-sided occluders (GL's own
  back-face culling). On a closed mesh the hidden-line picture is the same
  with or without culling (culling never changes what is visible); on an
  open one the culled back faces hide nothing, in both.
- ``style="shaded"``: core's depth buffer (``Frame.depth_image``) against
  pyrender's rendering of the fan-triangulated faces (flat, no lights:
  coverage and depth only): silhouette IoU, and depth error within a derived
  bound per pixel (oracles.tolerances, oracles.judge.metrics.shaded_scores). A scene
  without faces has nothing to shade: only its vertices are checked, with a
  note.

Several objects (``Scene.objects``, when the scene is not one static object):
the oracle side builds each object's matrix with scipy,
``M_run(t) @ M_o(t)`` (oracles.references.faces.object_matrices), and gives OpenCV and
pyrender world points (pyrender with an identity pose). core is set up as
``renderer`` sets it up (:class:`core.scene.frames.SceneRenderer`): its own world
points drawn with an identity model matrix. A single static object: pyrender
gets the model points with the run's scipy matrix as pose, core its own model
matrix of the run.

Cases are independent, so :func:`run_crosscheck` can spread them over worker
processes (``jobs``). Workers are started with the "spawn" method: an OSMesa
context (and llvmpipe's threads) must never be inherited through ``fork``, so
each worker creates its own :class:`PyrenderOracle` objects (one per image
size, cached for the worker's life) and loads a ``FILE.py:FUNC`` candidate
itself from the spec string. A process's oracles live on one GL thread
(oracles.references.gl_thread), where pyrender draws a frame while the process's
own thread draws the candidate's frame and measures the frame before
(oracles.judge.case.ProjectorFrames: the same drawings, made earlier). Results are gathered in case order, so the report
is the same for any number of jobs.

Each scene's cases are framed on it (oracles.cases: the cameras about its
framing sphere, the run's turns about the framing centre); each record says
how (``"framing"``). The report names the GL that drew the oracle's frames
(``"oracle_gl"``: :meth:`oracles.references.pyrender_oracle.PyrenderOracle.gl_info`;
null at level vertices).
"""

from __future__ import annotations

import math
import threading
import time
from dataclasses import dataclass

import numpy as np
from wirecheck.core.errors import InputError
from wirecheck.core.scene.model import Scene
from wirecheck.core.transforms import Motion  # parameters only: the oracle's matrix is convert.model_matrix

from .candidates.candidate import load_candidate
from .candidates.core_candidate import CoreCandidate, RenderMode
from .cases import CASE_NAMES, Case, case_motion, cases_for
from .executors import ExecutorSpec, gather_in_order, open_executor
from .judge import gate, metrics
from .judge.case import CaseResult, run_case
from .judge.run_report import run_report, tolerances_field
from .references import opencv_oracle
from .references.convert import model_matrix
from .references.gl_thread import GLThread, ThreadOracle
from .references.pyrender_oracle import gl_platform
from .tolerances import Tolerances

#: Oracle fidelity levels, cheapest first, and the oracles each one runs.
LEVELS = ("vertices", "pixels")
LEVEL_ORACLES = {"vertices": ("opencv",), "pixels": ("opencv", "pyrender")}


def level_for_oracles(oracles) -> str:
    """The level an ``oracles`` list (the older way to ask) means; ValueError if none."""
    wanted = tuple(o for o in LEVEL_ORACLES["pixels"] if o in set(oracles))
    if set(oracles) - set(wanted):
        raise ValueError(f"oracles {list(oracles)!r}: expected some of {', '.join(LEVEL_ORACLES['pixels'])}")
    for level, names in LEVEL_ORACLES.items():
        if wanted == names:
            return level
    raise ValueError(f"oracles {list(oracles)!r}: expected opencv among them (vertices are always checked)")


# ---------------------------------------------------------------- running cases, here or in workers


@dataclass(frozen=True)
class RunParams:
    """What every case of a run shares; picklable (sent to workers)."""

    frames: int
    every: int
    level: str
    motion: Motion
    tol: Tolerances
    candidate: object  # a picklable callable (CoreCandidate), or a "FILE.py:FUNC" spec string
    mode: RenderMode = RenderMode()
    keep_frames: bool = False  # every checked frame's images, for worst.gif
    keep_points: bool = False  # the worst frame's points of each case, for worst_points.png (level vertices)


class CaseRunner:
    """Runs cases with cached resources: pyrender oracles by image size, loaded candidates by spec.

    One per process: the parent's (``jobs=1``) is closed at the end of the run;
    a worker's lives as long as the worker. The first call into OpenCV, scipy,
    core or a new OpenGL context costs up to ~100 ms of one-time set-up; each
    process pays it once on a dummy input before its first case, so the times
    per frame measure the frames (and do not grow with ``jobs``). An external
    candidate is never called on such a dummy input.
    """

    _DUMMY_POINTS = np.array([[-0.5, -0.5, 0.0], [0.5, 0.5, 0.0]])
    _DUMMY_EDGES = np.array([[0, 1]], dtype=np.intp)

    def __init__(self, threaded: bool = True):
        #: the process's pyrender oracles, on one GL thread (oracles.references.gl_thread): pyrender draws a
        #: frame there while this thread draws the candidate's and measures the frame before
        self.gl = GLThread(threaded=threaded)
        self.candidates = {}
        self.warm = False

    def candidate(self, ref):
        if not isinstance(ref, str):
            return ref
        if ref not in self.candidates:
            self.candidates[ref] = load_candidate(ref)
        return self.candidates[ref]

    _DUMMY_TRIANGLE = (
        np.array([[-0.5, -0.5, 0.0], [0.5, -0.5, 0.0], [0.0, 0.5, 0.0]]),
        np.array([[0, 1, 2]], dtype=np.int64),
    )

    def renderer(self, camera, mode: RenderMode | None = None) -> ThreadOracle:
        size = (camera.width, camera.height)
        new = size not in self.gl.oracles
        oracle = ThreadOracle(self.gl, *size)
        if new:
            if camera.distortion is not None:  # GL has no lens; the shaders do not depend on it
                camera = camera.with_distortion(None)
            oracle.render(self._DUMMY_POINTS, self._DUMMY_EDGES, camera)  # compiles the shaders
            oracle.render(self._DUMMY_POINTS, self._DUMMY_EDGES, camera, depth=False)  # the pixel stage's read
            if mode is not None and mode.shaded:
                oracle.render_faces(*self._DUMMY_TRIANGLE, camera)  # and the id shader
        return oracle

    def warm_up(self, camera, candidate, level: str) -> None:
        pts, eye = self._DUMMY_POINTS, np.eye(4)
        model_matrix((1.0, 1.0, 0.0), (0.0, 0.0, 0.0), 1.0, 0.25)
        orac = opencv_oracle.project(pts, camera)
        metrics.vertex_errors(orac, orac)
        if isinstance(candidate, CoreCandidate):
            candidate.project(pts, camera, eye)
            if level == "pixels":
                candidate.draw(pts, self._DUMMY_EDGES, camera, eye)
        if level == "pixels":
            blank = np.zeros((camera.height, camera.width), bool)
            metrics.pixel_scores(blank, blank)
        self.warm = True

    def run(self, scene: Scene, case: Case, params: RunParams) -> CaseResult:
        candidate = self.candidate(params.candidate)
        if not self.warm:
            self.warm_up(case.camera, candidate, params.level)
        pyr = self.renderer(case.camera, params.mode) if params.level == "pixels" else None
        result = run_case(
            scene,
            case,
            params.frames,
            candidate,
            case_motion(params.motion, case),
            params.tol,
            pyrender_oracle=pyr,
            every=params.every,
            mode=params.mode,
            keep_frames=params.keep_frames,
            keep_points=params.keep_points,
        )
        result.record["framing"] = case.framing()
        result.gl_info = pyr.gl_info() if pyr is not None else None
        stderr = candidate.take_stderr() if hasattr(candidate, "take_stderr") else ""
        if stderr:  # an isolated candidate's stderr during this case (oracles.candidates.subprocess_candidate)
            result.record["candidate_stderr"] = stderr
        return result

    def close(self) -> None:
        self.gl.close()


_WORKER_RUNNER: CaseRunner | None = None
WORKER_LOCK = threading.Lock()


def worker_init() -> None:
    global _WORKER_RUNNER
    from multiprocessing.util import Finalize

    gl_platform()  # the parent's PYOPENGL_PLATFORM (crosscheck --gl), inherited; osmesa if unset
    _WORKER_RUNNER = CaseRunner()
    Finalize(_WORKER_RUNNER, _WORKER_RUNNER.close, exitpriority=10)  # free the GL contexts at exit


def worker_runner() -> CaseRunner:
    """This worker process's runner, made on first use (a Dask worker has no initializer)."""
    if _WORKER_RUNNER is None:
        worker_init()
    return _WORKER_RUNNER


def _worker_run(scene: Scene, case: Case, params: RunParams) -> CaseResult:
    from .candidates.subprocess_candidate import SubprocessCandidate, close_all_but

    with WORKER_LOCK:  # a Dask worker may run tasks in several threads: one GL user at a time
        # a worker outlives a run on a Dask cluster: programs of earlier runs' candidates end here
        close_all_but(params.candidate if isinstance(params.candidate, SubprocessCandidate) else None)
        return worker_runner().run(scene, case, params)


def _run_tasks(
    tasks, params: RunParams, jobs: int, on_result=None, isolate: bool = False, executor: ExecutorSpec | None = None
) -> tuple[list[CaseResult], int]:
    """Results in task order, and the number of worker processes used (0: in this process).

    ``on_result(result)`` is called on each result as it is gathered, in task
    order (it may drop what it does not need to keep, e.g. frame images).
    ``isolate``: use a worker even for one job, so that the candidate cannot end this process.
    ``executor`` (oracles.executors): where the tasks run (default: ``jobs`` local processes).
    """
    on_result = on_result or (lambda result: None)
    spec = executor or ExecutorSpec(jobs=jobs)
    with open_executor(spec, len(tasks), initializer=worker_init, isolate=isolate) as (pool, workers):
        if pool is None:
            runner = CaseRunner()
            try:
                results = []
                for scene, case in tasks:
                    results.append(runner.run(scene, case, params))
                    on_result(results[-1])
                return results, 0
            finally:
                runner.close()
        return gather_in_order(pool, _worker_run, [(scene, case, params) for scene, case in tasks], on_result), workers


def scene_cases(scene: Scene, case_names, motion: Motion) -> list[Case]:
    """The cases of ``scene`` named in ``case_names`` (framed on the scene, oracles.cases.cases_for).

    InputError when no camera fits the scene.
    """
    try:
        cases = cases_for(scene, motion, calibrated=bool(set(case_names) - set(CASE_NAMES)))
    except InputError as exc:
        raise InputError(f"{scene.source}: no camera fits this scene ({exc})") from None
    return [case for case in cases if case.name in case_names]


def overall_ms(timing_cases: list[dict], key: str):
    """Time per frame over all cases (weighted by the frames each case timed)."""
    rows = [t for t in timing_cases if key in t]
    frames = sum(t["frames_timed"] for t in rows)
    if not rows:
        return None
    return sum(t[key] * t["frames_timed"] for t in rows) / frames if frames else 0.0


def run_crosscheck(
    scenes,
    candidate,
    frames: int = 24,
    case_names=None,
    oracles=None,
    turns=(1.0, 1.0, 0.0),
    tol: Tolerances | None = None,
    candidate_name: str = "candidate",
    *,
    level: str | None = None,
    every: int = 1,
    jobs: int = 1,
    candidate_spec: str | None = None,
    mode: RenderMode | None = None,
    animation: bool = True,
    allow_vacuous: bool = False,
    progress=None,
    isolate: bool = False,
    executor: ExecutorSpec | None = None,
    cases: tuple | None = None,
) -> tuple[dict, dict]:
    """Every scene under every case camera: the report dict and the worst-frame images.

    ``level`` is "vertices" (OpenCV only) or "pixels" (OpenCV and pyrender, the
    default); ``oracles`` (("opencv",) or ("opencv", "pyrender")) is the older
    way to say the same, and must agree with ``level`` when both are given.
    Frames 1, 1 + ``every``, ... of the ``frames``-frame motion are checked.
    With ``jobs`` > 1 the cases run in that many worker processes; a candidate
    that is not core is then best given as ``candidate_spec`` ("FILE.py:FUNC"),
    which each worker loads (``candidate`` itself must otherwise be picklable).

    ``mode`` (:class:`RenderMode`) is the drawing mode of the pixel stage
    (hidden lines, back-face culling, shaded); anything but the plain
    wireframe needs the core candidate and level "pixels".

    ``images[(scene, camera)] = {"frame", "candidate", "oracle"}``; with
    ``animation`` (level pixels), ``images["animation"]`` holds every checked
    frame of the worst case (lowest F1, or IoU when shaded, then largest
    vertex error): ``{"scene", "camera", "frames": [k...], "candidate": [...],
    "oracle": [...]}`` (bool images), for worst.gif; at level vertices,
    ``images["points"]`` holds the worst vertex's frame of the case with the
    largest vertex error (oracles.judge.case.worst_points), for
    worst_points.png. Raises InputError when no
    camera can be placed for a scene (coordinates too large), ValueError for a
    bad level, ``jobs`` or mode, and InputError (a ValueError) for inputs that
    would compare nothing (:func:`oracles.judge.gate.run_inputs`: no scene, case or
    frame, an unknown or repeated name, ``every`` > ``frames``, a NaN tolerance).

    A case that compared nothing is ``"vacuous"`` and fails the run unless
    ``allow_vacuous`` (oracles.judge.gate); ``report["compared"]`` counts what was
    compared. ``progress(cases_done, cases, frames_done, frames)`` is called
    before the first case and after each. With ``isolate`` the cases run in
    worker processes even for ``jobs=1``: a candidate that ends its process
    (``os._exit(0)``) raises BrokenProcessPool here instead of ending the run
    with status 0; the candidate must then be given as ``candidate_spec``.
    ``executor`` (:class:`oracles.executors.ExecutorSpec`) sends the cases to
    a Dask cluster instead (same report; ``jobs`` is then the spec's).

    ``cases``: fixed cameras (:class:`oracles.cases.Case`, distinct names),
    each scene run under every one of them instead of the cameras framed on it
    (``case_names`` must then be None; the spec suite, oracles.spec, places its
    cameras as the specification does).
    """
    if oracles is not None:
        implied = level_for_oracles(oracles)
        if level is not None and level != implied:
            raise ValueError(f"level {level!r} contradicts oracles {list(oracles)!r} (level {implied!r})")
        level = implied
    level = level or "pixels"
    if level not in LEVELS:
        raise ValueError(f"level {level!r}: expected one of {', '.join(LEVELS)}")
    if jobs < 1:
        raise ValueError(f"jobs {jobs}: expected an integer >= 1")
    mode = mode or RenderMode()
    if not mode.plain:
        if level != "pixels":
            raise ValueError(f"drawing mode {mode.to_dict()}: needs level pixels (nothing is drawn at {level})")
        if not isinstance(candidate, CoreCandidate):
            raise ValueError(f"drawing mode {mode.to_dict()}: only the core candidate draws faces")
    tol = tol or Tolerances()
    inputs = gate.run_inputs(scenes, frames, every, case_names, turns, tol)
    frames, every = inputs.frames, inputs.every
    motion = Motion(turns=inputs.turns)
    t_run = time.perf_counter()
    if cases is not None:
        names = [case.name for case in cases]
        if case_names is not None or not names or len(set(names)) != len(names):
            raise ValueError(f"cases {names}: expected at least one Case, distinct names, and no case_names")
        tasks = [(scene, case) for scene in inputs.scenes for case in cases]
    else:
        tasks = [(scene, case) for scene in inputs.scenes for case in scene_cases(scene, inputs.case_names, motion)]
    if level == "pixels" and tasks and all(case.camera.distortion is not None for _, case in tasks):
        raise InputError(
            f"cases {', '.join(inputs.case_names)} at level pixels: lens distortion: their pixels "
            "are not compared (GL draws straight lines), so the run would compare no pixel; "
            "expected level vertices or a case without distortion"
        )
    is_core = isinstance(candidate, CoreCandidate)
    ref = candidate if is_core or candidate_spec is None else candidate_spec
    keep_frames = animation and level == "pixels"
    params = RunParams(
        frames=frames,
        every=every,
        level=level,
        motion=motion,
        tol=tol,
        candidate=ref,
        mode=mode,
        keep_frames=keep_frames,
        keep_points=level == "vertices",
    )
    worst = _WorstCase(mode)
    n_frames = len(tasks) * inputs.frames_checked
    cases_done = 0

    worst_points = []  # the case with the largest vertex error so far (inf included); ties: the first

    def on_result(result: CaseResult) -> None:
        nonlocal cases_done
        if keep_frames:
            worst.offer(result)
        if result.worst_points is not None:
            if not worst_points or _points_error(result.worst_points) > _points_error(worst_points[0]):
                worst_points[:] = [result.worst_points]
            result.worst_points = None  # kept once, not per case
        cases_done += 1
        if progress:
            progress(cases_done, len(tasks), cases_done * inputs.frames_checked, n_frames)

    if progress:
        progress(0, len(tasks), 0, n_frames)
    results, workers = _run_tasks(tasks, params, jobs, on_result=on_result, isolate=isolate, executor=executor)

    records, images, timing_cases = [], {}, []
    gl = next((r.gl_info for r in results if r.gl_info is not None), None)  # one driver per machine
    for (scene, case), result in zip(tasks, results):
        records.append(result.record)
        timing_cases.append({"scene": scene.name, "camera": case.name, **result.timing})
        if result.worst_images:
            images[(scene.name, case.name)] = result.worst_images

    if worst_points:
        images["points"] = worst_points[0]
    worst_case = None
    if worst.result is not None:
        images["animation"] = worst.animation()
        worst_case = {
            "scene": images["animation"]["scene"],
            "camera": images["animation"]["camera"],
            "frames_checked": len(images["animation"]["frames"]),
            "animation": "worst.gif",
        }
    timing = {"vertex_stage_ms_per_frame": overall_ms(timing_cases, "vertex_stage_ms_per_frame")}
    if level == "pixels":
        timing["pixel_stage_ms_per_frame"] = overall_ms(timing_cases, "pixel_stage_ms_per_frame")
    for key in (
        "candidate_ms_per_frame",
        "candidate_project_ms_per_frame",
        "opencv_ms_per_frame",
        "harness_ms_per_frame",
        "oracles_ms_per_frame",
    ):
        timing[key] = overall_ms(timing_cases, key)
    oracles_ms = timing["oracles_ms_per_frame"]
    # issue 12's target is <= 0.15; reported on every run, never gated (a timing)
    timing["harness_overhead_ratio"] = (timing["harness_ms_per_frame"] / oracles_ms) if oracles_ms else None
    if level == "pixels":
        for key in (
            "candidate_draw_ms_per_frame",
            "pyrender_ms_per_frame",
            "pyrender_wait_ms_per_frame",
            "pixel_metrics_ms_per_frame",
            "pixel_metrics_beside_ms_per_frame",
        ):
            timing[key] = overall_ms(timing_cases, key)
    timing.update(
        {
            "executor": executor.kind if executor else "local",
            "jobs": jobs,
            "workers": workers,
            "wall_s": time.perf_counter() - t_run,
            "cases": timing_cases,
        }
    )
    report = run_report(
        records,
        level,
        allow_vacuous,
        {
            "candidate": candidate_name,
            "candidate_settings": candidate.settings() if hasattr(candidate, "settings") else None,
            **mode.to_dict(),
            "oracles": list(LEVEL_ORACLES[level]),
            "oracle_gl": gl,
            "frames": frames,
            "every": every,
            "frames_checked": len(range(1, frames + 1, every)),
            "motion": {"turns": list(motion.turns)},
            "tolerances": tolerances_field(tol, level, shaded=mode.shaded),
            **({"worst_case": worst_case} if worst_case else {}),
            "timing": timing,
        },
        shaded=mode.shaded,
    )
    return report, images


def _points_error(points: dict) -> float:
    return -math.inf if points["error_px"] is None else points["error_px"]


def worst_key(record: dict) -> tuple:
    """Ranking of cases for worst.gif, smallest = worst: lowest F1 (IoU when shaded), then largest vertex error."""
    verr = record.get("max_vertex_error_px")
    verr = -math.inf if verr is None else verr
    if "silhouette_iou" in record:
        iou = record.get("silhouette_iou")
        ratio = record.get("depth_error_ratio") or 0.0
        return (1.0 if iou is None else iou, -ratio, -verr)
    f1_1, f1_0 = record.get("pixel_f1_1px"), record.get("pixel_f1_0px")
    return (1.0 if f1_1 is None else f1_1, 1.0 if f1_0 is None else f1_0, -verr)


class _WorstCase:
    """Keeps the frame images of the worst case seen so far (cases offered in task order)."""

    def __init__(self, mode: RenderMode):
        self.mode = mode
        self.result = None
        self.key = None

    def offer(self, result: CaseResult) -> None:
        frames = result.frame_images
        if not frames:
            result.frame_images = None
            return
        key = worst_key(result.record)
        if self.result is None or key < self.key:  # ties: the first case in order stays
            if self.result is not None:
                self.result.frame_images = None
            self.result, self.key = result, key
        else:
            result.frame_images = None

    def animation(self) -> dict:
        rec = self.result.record
        frames = self.result.frame_images
        return {
            "scene": rec["scene"],
            "camera": rec["camera"],
            "frames": [k for k, _, _ in frames],
            "candidate": [c.image() for _, c, _ in frames],
            "oracle": [o.image() for _, _, o in frames],
            "shaded": self.mode.shaded,
        }
