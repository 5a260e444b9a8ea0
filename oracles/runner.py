"""Run the cases: candidate vs OpenCV (vertices) and vs pyrender/OSMesa (pixels).

For each case (a scene under one camera) and each checked frame of the scene's
motion (frames 1, 1 + every, 1 + 2 every, ...; frame k is at t = (k - 1) / frames):

1. the model matrix comes from :func:`oracles.convert.model_matrix` (scipy,
   independent of core.transforms), giving ``p_world``;
2. **vertex stage** (levels ``vertices`` and ``pixels``): the candidate
   projects the points — core through its own pipeline,
   :func:`core.pipeline.render_frame` given no edges, so nothing is drawn — and
   OpenCV's ``projectPoints`` is the reference (``oracles.opencv_oracle``);
3. **pixel stage** (level ``pixels`` only): the candidate's frame is drawn —
   core's full pipeline when the candidate is core, else
   :func:`oracles.draw.draw_candidate` — and compared with pyrender's rendering
   of the same edges;

then all frames' points are pooled for :func:`oracles.diagnose.diagnose`.

Cases are independent, so :func:`run_crosscheck` can spread them over worker
processes (``jobs``). Workers are started with the "spawn" method: an OSMesa
context (and llvmpipe's threads) must never be inherited through ``fork``, so
each worker creates its own :class:`PyrenderOracle` objects (one per image
size, cached for the worker's life) and loads a ``FILE.py:FUNC`` candidate
itself from the spec string. Results are gathered in case order, so the report
is the same for any number of jobs.
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from core.scene import Scene
from core.transforms import Motion   # parameters only: the oracle's matrix is convert.model_matrix

from . import metrics, opencv_oracle, tolerances
from .candidate import CandidateError, call_candidate
from .cases import Case
from .convert import model_matrix
from .draw import draw_candidate

#: Oracle fidelity levels, cheapest first, and the oracles each one runs.
LEVELS = ("vertices", "pixels")
LEVEL_ORACLES = {"vertices": ("opencv",), "pixels": ("opencv", "pyrender")}

#: A frame of core's pipeline is greyscale with raster "aa": a pixel is drawn from half intensity up.
DRAWN_THRESHOLD = 128


def level_for_oracles(oracles) -> str:
    """The level an ``oracles`` list (the older way to ask) means; ValueError if none."""
    wanted = tuple(o for o in LEVEL_ORACLES["pixels"] if o in set(oracles))
    if set(oracles) - set(wanted):
        raise ValueError(f"oracles {list(oracles)!r}: expected some of {', '.join(LEVEL_ORACLES['pixels'])}")
    for level, names in LEVEL_ORACLES.items():
        if wanted == names:
            return level
    raise ValueError(f"oracles {list(oracles)!r}: expected opencv among them (vertices are always checked)")


@dataclass
class Tolerances:
    vertex_px: float = tolerances.VERTEX_TOL_PX
    min_f1_1px: float = tolerances.MIN_F1_1PX
    min_f1_0px: float = tolerances.MIN_F1_0PX

    def to_dict(self) -> dict:
        return {"vertex_error_px": self.vertex_px, "min_pixel_f1_1px": self.min_f1_1px,
                "min_pixel_f1_0px": self.min_f1_0px}


@dataclass
class CaseResult:
    record: dict                       # what goes into report.json
    worst_images: dict | None = None   # {"frame", "candidate", "oracle"} bool images
    timing: dict = field(default_factory=dict)


@dataclass(frozen=True)
class CoreCandidate:
    """core/ as the candidate: vertices (and frames) through core's whole pipeline.

    ``dtype``, ``clip`` and ``raster`` are passed to :func:`core.pipeline.render_frame`
    (``clip`` as its ``clip_mode``).
    """

    dtype: str = "float64"
    clip: str = "clip"
    raster: str = "exact"

    name: ClassVar[str] = "core"
    DTYPES: ClassVar[tuple] = ("float64", "float32")
    CLIPS: ClassVar[tuple] = ("clip", "endpoint")
    RASTERS: ClassVar[tuple] = ("exact", "fast", "aa")

    def __post_init__(self):
        for name, allowed in (("dtype", self.DTYPES), ("clip", self.CLIPS), ("raster", self.RASTERS)):
            if getattr(self, name) not in allowed:
                raise ValueError(f"{name} {getattr(self, name)!r}: expected one of {', '.join(allowed)}")

    def settings(self) -> dict:
        return {"dtype": self.dtype, "clip": self.clip, "raster": self.raster}

    def __call__(self, points, camera):  # the candidate contract, for completeness
        from core.projection import project_points

        return project_points(points, camera, dtype=self.dtype)

    def prepare(self, p_model: np.ndarray):
        """The scene's vertices re-centred and cast once (``core.projection.localize``), as ``renderer`` does."""
        from core.projection import localize

        return localize(p_model, self.dtype)

    def project(self, points, camera, model_matrix: np.ndarray) -> np.ndarray:
        """Vertex pixels from core's pipeline without drawing: ``render_frame`` given no edges."""
        from core.pipeline import render_frame

        no_edges = np.zeros((0, 2), dtype=np.intp)
        return render_frame(points, no_edges, camera, model_matrix, self.clip, raster=self.raster).p_px

    def draw(self, points, edges: np.ndarray, camera, model_matrix: np.ndarray) -> np.ndarray:
        """The frame core draws, as a bool image (drawn where the image is >= 128)."""
        from core.pipeline import render_frame

        frame = render_frame(points, edges, camera, model_matrix, self.clip, raster=self.raster)
        return frame.image >= DRAWN_THRESHOLD


def _per_frame_ms(seconds: float, frames: int) -> float:
    return 1e3 * seconds / max(frames, 1)


def run_case(scene: Scene, case: Case, frames: int, candidate, motion: Motion,
             tol: Tolerances, pyrender_oracle=None, want_images: bool = True, every: int = 1) -> CaseResult:
    """One case; the pixel stage runs when ``pyrender_oracle`` is given."""
    cam = case.camera
    is_core = isinstance(candidate, CoreCandidate)
    pixels = pyrender_oracle is not None
    edges = np.asarray(scene.edges)
    cand_all, orac_all = [], []
    frame_errors = []
    per_frame = []
    f1_0, f1_1, prec_0, rec_0, prec_1, rec_1 = [], [], [], [], [], []
    worst = None                     # (key, frame, cand_img, oracle_img)
    # seconds: vertex stage = t_setup + t_cv + t_proj + t_vmetric; pixel stage = t_draw + t_pr + t_pmetric
    t_setup = t_cv = t_proj = t_vmetric = t_draw = t_pr = t_pmetric = 0.0
    error = None
    core_points = candidate.prepare(scene.vertices) if is_core else None   # once per scene, not per frame
    for k in range(1, frames + 1, every):
        t0 = time.perf_counter()
        t = (k - 1) / frames
        m = model_matrix(motion.turns, motion.offset, motion.scale, t)
        p_world = scene.vertices @ m[:3, :3].T + m[:3, 3]
        t1 = time.perf_counter()
        oracle_px = opencv_oracle.project(p_world, cam)
        t2 = time.perf_counter()
        try:
            if is_core:
                m_core = motion.frame_matrix(k, frames)
                cand_px = candidate.project(core_points, cam, m_core)
            else:
                cand_px = call_candidate(candidate, p_world, cam)
            t3 = time.perf_counter()
            cand_img = None
            if pixels:
                if is_core:
                    cand_img = candidate.draw(core_points, edges, cam, m_core)
                else:
                    cand_img = draw_candidate(candidate, p_world, edges, cam)
            t4 = time.perf_counter()
        except CandidateError as exc:
            error = f"frame {k}: {exc}"
            break
        t_setup += t1 - t0
        t_cv += t2 - t1
        t_proj += t3 - t2
        t_draw += t4 - t3
        t5 = time.perf_counter()
        cand_all.append(cand_px)
        orac_all.append(oracle_px)
        ve = metrics.vertex_errors(cand_px, oracle_px)
        if ve["max_px"] is not None:
            frame_errors.append((ve["max_px"], k, ve["worst_index"]))
        frame_rec = {"frame": k, "max_vertex_error_px": ve["max_px"], "mean_vertex_error_px": ve["mean_px"],
                     "rms_vertex_error_px": ve["rms_px"], "visible_points": ve["visible_both"]}
        per_frame.append(frame_rec)
        t6 = time.perf_counter()
        t_vmetric += t6 - t5
        if pixels:
            orac_img, _depth = pyrender_oracle.render(scene.vertices, edges, cam, model_matrix=m)
            t7 = time.perf_counter()
            t_pr += t7 - t6
            ps = metrics.pixel_scores(cand_img, orac_img)
            f1_0.append(ps["f1_0px"]); f1_1.append(ps["f1_1px"])
            prec_0.append(ps["precision_0px"]); rec_0.append(ps["recall_0px"])
            prec_1.append(ps["precision_1px"]); rec_1.append(ps["recall_1px"])
            frame_rec.update({key: ps[key] for key in ("f1_0px", "f1_1px", "precision_0px", "recall_0px",
                                                       "precision_1px", "recall_1px")})
            key = (ps["f1_1px"], ps["f1_0px"])
            if want_images and (worst is None or key < worst[0]):
                worst = (key, k, cand_img.copy(), orac_img.copy())
            t_pmetric += time.perf_counter() - t7
    done = len(cand_all)
    rec = {"scene": scene.name, "camera": case.name, "camera_spec": cam.to_dict(), "frames": frames,
           "frames_checked": done}
    if done:
        cand = np.concatenate(cand_all)
        orac = np.concatenate(orac_all)
        ve = metrics.vertex_errors(cand, orac)
        worst_v = max(frame_errors, key=lambda e: (e[0], -e[1])) if frame_errors else (None, None, None)
        rec.update({
            "max_vertex_error_px": ve["max_px"],
            "mean_vertex_error_px": ve["mean_px"],
            "rms_vertex_error_px": ve["rms_px"],
            "worst_vertex": {"frame": worst_v[1], "vertex": worst_v[2], "error_px": worst_v[0]},
            "visible_points": ve["visible_both"],
            "visibility_mismatch": {"candidate_only": ve["candidate_only"], "oracle_only": ve["oracle_only"]},
        })
        from .diagnose import diagnose

        faults = diagnose(cand, orac, cam, tol_px=tol.vertex_px)
    else:
        rec.update({"max_vertex_error_px": None, "mean_vertex_error_px": None, "rms_vertex_error_px": None})
        faults = []
    if f1_0:
        worst_frame = worst[1] if worst else None
        rec.update({
            "pixel_f1_0px": float(min(f1_0)), "pixel_f1_1px": float(min(f1_1)),
            "pixel_f1_0px_mean": float(np.mean(f1_0)), "pixel_f1_1px_mean": float(np.mean(f1_1)),
            "pixel_precision_0px": float(min(prec_0)), "pixel_recall_0px": float(min(rec_0)),
            "pixel_precision_1px": float(min(prec_1)), "pixel_recall_1px": float(min(rec_1)),
            "worst_pixel_frame": worst_frame,
        })
    else:
        rec.update({"pixel_f1_0px": None, "pixel_f1_1px": None})
    rec["faults"] = faults
    reasons = []
    if error:
        reasons.append(error)
    if done and len(scene.vertices) == 0:
        rec["note"] = "nothing to check: the scene has no vertices"
    elif done and rec["visible_points"] == 0:
        rec["note"] = "no point visible to both projectors: only the visible/clipped sets were compared"
    if done:
        if rec["max_vertex_error_px"] is not None and rec["max_vertex_error_px"] > tol.vertex_px:
            reasons.append(f"max vertex error {rec['max_vertex_error_px']:.3g} px > {tol.vertex_px:.3g} px "
                           f"(frame {rec['worst_vertex']['frame']}, vertex {rec['worst_vertex']['vertex']})")
        vm = rec["visibility_mismatch"]
        if vm["candidate_only"] or vm["oracle_only"]:
            reasons.append(f"visible sets differ: {vm['candidate_only']} points shown only by the candidate, "
                           f"{vm['oracle_only']} only by the oracle")
    if f1_0:
        if rec["pixel_f1_1px"] < tol.min_f1_1px:
            reasons.append(f"pixel F1@1px {rec['pixel_f1_1px']:.4f} < {tol.min_f1_1px} "
                           f"(frame {rec['worst_pixel_frame']})")
        if rec["pixel_f1_0px"] < tol.min_f1_0px:
            reasons.append(f"pixel F1@0px {rec['pixel_f1_0px']:.4f} < {tol.min_f1_0px}")
    rec["verdict"] = "fail" if reasons else "pass"
    rec["reasons"] = reasons
    rec["per_frame"] = per_frame
    timing = {"frames_timed": done,
              "vertex_stage_ms_per_frame": _per_frame_ms(t_setup + t_cv + t_proj + t_vmetric, done),
              "candidate_project_ms_per_frame": _per_frame_ms(t_proj, done),
              "opencv_ms_per_frame": _per_frame_ms(t_cv, done)}
    if pixels:
        timing.update({"pixel_stage_ms_per_frame": _per_frame_ms(t_draw + t_pr + t_pmetric, done),
                       "candidate_draw_ms_per_frame": _per_frame_ms(t_draw, done),
                       "pyrender_ms_per_frame": _per_frame_ms(t_pr, done),
                       "pixel_metrics_ms_per_frame": _per_frame_ms(t_pmetric, done)})
    timing["candidate_ms_per_frame"] = _per_frame_ms(t_proj + t_draw, done)
    images = None
    if worst is not None:
        images = {"frame": worst[1], "candidate": worst[2], "oracle": worst[3]}
    return CaseResult(record=rec, worst_images=images, timing=timing)


# ---------------------------------------------------------------- running cases, here or in workers

@dataclass(frozen=True)
class _RunParams:
    """What every case of a run shares; picklable (sent to workers)."""

    frames: int
    every: int
    level: str
    motion: Motion
    tol: Tolerances
    candidate: object        # a picklable callable (CoreCandidate), or a "FILE.py:FUNC" spec string


class _CaseRunner:
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

    def __init__(self):
        self.renderers = {}
        self.candidates = {}
        self.warm = False

    def candidate(self, ref):
        if not isinstance(ref, str):
            return ref
        if ref not in self.candidates:
            from .candidate import load_candidate

            self.candidates[ref] = load_candidate(ref)
        return self.candidates[ref]

    def renderer(self, camera):
        size = (camera.width, camera.height)
        if size not in self.renderers:
            from .pyrender_oracle import PyrenderOracle

            self.renderers[size] = PyrenderOracle(*size)
            self.renderers[size].render(self._DUMMY_POINTS, self._DUMMY_EDGES, camera)   # compiles the shaders
        return self.renderers[size]

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

    def run(self, scene: Scene, case: Case, params: _RunParams) -> CaseResult:
        candidate = self.candidate(params.candidate)
        if not self.warm:
            self.warm_up(case.camera, candidate, params.level)
        pyr = self.renderer(case.camera) if params.level == "pixels" else None
        return run_case(scene, case, params.frames, candidate, params.motion,
                        params.tol, pyrender_oracle=pyr, every=params.every)

    def close(self) -> None:
        renderers, self.renderers = self.renderers, {}
        for r in renderers.values():
            r.close()


_WORKER_RUNNER: _CaseRunner | None = None


def _worker_init() -> None:
    global _WORKER_RUNNER
    from multiprocessing.util import Finalize

    os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa")
    _WORKER_RUNNER = _CaseRunner()
    Finalize(_WORKER_RUNNER, _WORKER_RUNNER.close, exitpriority=10)   # free the GL contexts at exit


def _worker_run(scene: Scene, case: Case, params: _RunParams) -> CaseResult:
    return _WORKER_RUNNER.run(scene, case, params)


def _run_tasks(tasks, params: _RunParams, jobs: int) -> tuple[list[CaseResult], int]:
    """Results in task order, and the number of worker processes used (0: in this process)."""
    workers = min(jobs, len(tasks))
    if workers <= 1:
        runner = _CaseRunner()
        try:
            return [runner.run(scene, case, params) for scene, case in tasks], 0
        finally:
            runner.close()
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    # "spawn": a fresh interpreter per worker, so no OpenGL/OSMesa state or thread is inherited.
    ctx = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(max_workers=workers, mp_context=ctx, initializer=_worker_init) as pool:
        futures = [pool.submit(_worker_run, scene, case, params) for scene, case in tasks]
        try:
            return [f.result() for f in futures], workers
        except BaseException:
            for f in futures:
                f.cancel()
            raise


def _overall_ms(timing_cases: list[dict], key: str):
    """Time per frame over all cases (weighted by the frames each case timed)."""
    rows = [t for t in timing_cases if key in t]
    frames = sum(t["frames_timed"] for t in rows)
    if not rows:
        return None
    return sum(t[key] * t["frames_timed"] for t in rows) / frames if frames else 0.0


def run_crosscheck(scenes, candidate, frames: int = 24, case_names=None, oracles=None,
                   turns=(1.0, 1.0, 0.0), tol: Tolerances | None = None, candidate_name: str = "candidate",
                   *, level: str | None = None, every: int = 1, jobs: int = 1,
                   candidate_spec: str | None = None) -> tuple[dict, dict]:
    """Every scene under every case camera: the report dict and the worst-frame images.

    ``level`` is "vertices" (OpenCV only) or "pixels" (OpenCV and pyrender, the
    default); ``oracles`` (("opencv",) or ("opencv", "pyrender")) is the older
    way to say the same, and must agree with ``level`` when both are given.
    Frames 1, 1 + ``every``, ... of the ``frames``-frame motion are checked.
    With ``jobs`` > 1 the cases run in that many worker processes; a candidate
    that is not core is then best given as ``candidate_spec`` ("FILE.py:FUNC"),
    which each worker loads (``candidate`` itself must otherwise be picklable).

    ``images[(scene, camera)] = {"frame", "candidate", "oracle"}``. Raises
    InputError when no camera can be placed for a scene (coordinates too large),
    ValueError for a bad level, ``every`` or ``jobs``.
    """
    from core.errors import InputError

    from .cases import cameras_for

    if oracles is not None:
        implied = level_for_oracles(oracles)
        if level is not None and level != implied:
            raise ValueError(f"level {level!r} contradicts oracles {list(oracles)!r} (level {implied!r})")
        level = implied
    level = level or "pixels"
    if level not in LEVELS:
        raise ValueError(f"level {level!r}: expected one of {', '.join(LEVELS)}")
    if every < 1:
        raise ValueError(f"every {every}: expected an integer >= 1")
    if jobs < 1:
        raise ValueError(f"jobs {jobs}: expected an integer >= 1")
    tol = tol or Tolerances()
    motion = Motion(turns=tuple(float(x) for x in turns))
    t_run = time.perf_counter()
    tasks = []
    for scene in scenes:
        try:
            scene_cases = cameras_for(scene.radius)
        except InputError as exc:
            raise InputError(f"{scene.source}: no camera fits this scene ({exc})") from None
        tasks += [(scene, case) for case in scene_cases if case_names is None or case.name in case_names]
    is_core = isinstance(candidate, CoreCandidate)
    ref = candidate if is_core or candidate_spec is None else candidate_spec
    params = _RunParams(frames=frames, every=every, level=level, motion=motion, tol=tol, candidate=ref)
    results, workers = _run_tasks(tasks, params, jobs)

    records, images, timing_cases = [], {}, []
    for (scene, case), result in zip(tasks, results):
        records.append(result.record)
        timing_cases.append({"scene": scene.name, "camera": case.name, **result.timing})
        if result.worst_images:
            images[(scene.name, case.name)] = result.worst_images

    failed = sum(1 for r in records if r["verdict"] != "pass")
    vertex_errs = [r["max_vertex_error_px"] for r in records if r.get("max_vertex_error_px") is not None]
    f1_0 = [r["pixel_f1_0px"] for r in records if r.get("pixel_f1_0px") is not None]
    f1_1 = [r["pixel_f1_1px"] for r in records if r.get("pixel_f1_1px") is not None]
    timing = {"vertex_stage_ms_per_frame": _overall_ms(timing_cases, "vertex_stage_ms_per_frame")}
    if level == "pixels":
        timing["pixel_stage_ms_per_frame"] = _overall_ms(timing_cases, "pixel_stage_ms_per_frame")
    for key in ("candidate_ms_per_frame", "candidate_project_ms_per_frame", "opencv_ms_per_frame"):
        timing[key] = _overall_ms(timing_cases, key)
    if level == "pixels":
        for key in ("candidate_draw_ms_per_frame", "pyrender_ms_per_frame", "pixel_metrics_ms_per_frame"):
            timing[key] = _overall_ms(timing_cases, key)
    timing.update({"jobs": jobs, "workers": workers, "wall_s": time.perf_counter() - t_run,
                   "cases": timing_cases})
    report = {
        "tool": "wirecheck crosscheck",
        "verdict": "fail" if failed else "pass",
        "candidate": candidate_name,
        "candidate_settings": candidate.settings() if is_core else None,
        "level": level,
        "oracles": list(LEVEL_ORACLES[level]),
        "frames": frames,
        "every": every,
        "frames_checked": len(range(1, frames + 1, every)),
        "motion": {"turns": list(motion.turns)},
        "tolerances": tol.to_dict(),
        "summary": {"cases": len(records), "passed": len(records) - failed, "failed": failed,
                    "max_vertex_error_px": max(vertex_errs) if vertex_errs else None,
                    "min_pixel_f1_0px": min(f1_0) if f1_0 else None,
                    "min_pixel_f1_1px": min(f1_1) if f1_1 else None},
        "cases": records,
        "timing": timing,
    }
    return report, images
