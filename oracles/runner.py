"""Run the cases: candidate vs OpenCV (vertices) and vs pyrender/OSMesa (pixels).

For each case (a scene under one camera) and each frame of the scene's motion:

1. the model matrix comes from :func:`oracles.convert.model_matrix` (scipy,
   independent of core.transforms), giving ``p_world``;
2. the candidate projects ``p_world``; OpenCV's ``projectPoints`` is the
   reference (``oracles.opencv_oracle``);
3. the candidate's frame is drawn — core's own full pipeline when the candidate
   is core, else :func:`oracles.draw.draw_candidate` — and compared with
   pyrender's rendering of the same edges;

then all frames' points are pooled for :func:`oracles.diagnose.diagnose`.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from core.scene import Scene
from core.transforms import Motion   # parameters only: the oracle's matrix is convert.model_matrix

from . import metrics, opencv_oracle, tolerances
from .candidate import CandidateError, call_candidate
from .cases import Case
from .convert import model_matrix
from .draw import draw_candidate


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


class CoreCandidate:
    """core/ as the candidate: vertices through core's whole pipeline."""

    name = "core"

    def __call__(self, points, camera):  # the contract, for completeness
        from core.projection import project_points

        return project_points(points, camera)


def run_case(scene: Scene, case: Case, frames: int, candidate, motion: Motion,
             tol: Tolerances, pyrender_oracle=None, want_images: bool = True) -> CaseResult:
    cam = case.camera
    is_core = isinstance(candidate, CoreCandidate)
    edges = np.asarray(scene.edges)
    cand_all, orac_all = [], []
    frame_errors = []
    per_frame = []
    f1_0, f1_1, prec_0, rec_0, prec_1, rec_1 = [], [], [], [], [], []
    worst = None                     # (key, frame, cand_img, oracle_img)
    t_cand = t_cv = t_pr = 0.0
    error = None
    if is_core:
        from core.pipeline import render_frame
    for k in range(1, frames + 1):
        t = (k - 1) / frames
        m = model_matrix(motion.turns, motion.offset, motion.scale, t)
        p_world = scene.vertices @ m[:3, :3].T + m[:3, 3]
        t0 = time.perf_counter()
        oracle_px = opencv_oracle.project(p_world, cam)
        t_cv += time.perf_counter() - t0
        t0 = time.perf_counter()
        try:
            if is_core:
                frame = render_frame(scene.vertices, edges, cam, motion.frame_matrix(k, frames), "clip")
                cand_px, cand_img = frame.p_px, frame.image > 0
            else:
                cand_px = call_candidate(candidate, p_world, cam)
                cand_img = draw_candidate(candidate, p_world, edges, cam) if pyrender_oracle else None
        except CandidateError as exc:
            error = f"frame {k}: {exc}"
            break
        t_cand += time.perf_counter() - t0
        cand_all.append(cand_px)
        orac_all.append(oracle_px)
        ve = metrics.vertex_errors(cand_px, oracle_px)
        if ve["max_px"] is not None:
            frame_errors.append((ve["max_px"], k, ve["worst_index"]))
        frame_rec = {"frame": k, "max_vertex_error_px": ve["max_px"], "mean_vertex_error_px": ve["mean_px"],
                     "rms_vertex_error_px": ve["rms_px"], "visible_points": ve["visible_both"]}
        per_frame.append(frame_rec)
        if pyrender_oracle is not None:
            t0 = time.perf_counter()
            orac_img, _depth = pyrender_oracle.render(scene.vertices, edges, cam, model_matrix=m)
            t_pr += time.perf_counter() - t0
            ps = metrics.pixel_scores(cand_img, orac_img)
            f1_0.append(ps["f1_0px"]); f1_1.append(ps["f1_1px"])
            prec_0.append(ps["precision_0px"]); rec_0.append(ps["recall_0px"])
            prec_1.append(ps["precision_1px"]); rec_1.append(ps["recall_1px"])
            frame_rec.update({key: ps[key] for key in ("f1_0px", "f1_1px", "precision_0px", "recall_0px",
                                                       "precision_1px", "recall_1px")})
            key = (ps["f1_1px"], ps["f1_0px"])
            if want_images and (worst is None or key < worst[0]):
                worst = (key, k, cand_img.copy(), orac_img.copy())
    done = len(cand_all)
    rec = {"scene": scene.name, "camera": case.name, "camera_spec": cam.to_dict(), "frames": frames}
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
    timing = {"candidate_ms_per_frame": 1e3 * t_cand / max(done, 1),
              "opencv_ms_per_frame": 1e3 * t_cv / max(done, 1)}
    if pyrender_oracle is not None:
        timing["pyrender_ms_per_frame"] = 1e3 * t_pr / max(done, 1)
    images = None
    if worst is not None:
        images = {"frame": worst[1], "candidate": worst[2], "oracle": worst[3]}
    return CaseResult(record=rec, worst_images=images, timing=timing)


def run_crosscheck(scenes, candidate, frames: int = 24, case_names=None, oracles=("opencv", "pyrender"),
                   turns=(1.0, 1.0, 0.0), tol: Tolerances | None = None, candidate_name: str = "candidate"
                   ) -> tuple[dict, dict]:
    """Every scene under every case camera: the report dict and the worst-frame images.

    ``images[(scene, camera)] = {"frame", "candidate", "oracle"}``. Raises
    InputError when no camera can be placed for a scene (coordinates too large).
    """
    import time as _time

    from core.errors import InputError

    from .cases import cameras_for

    tol = tol or Tolerances()
    motion = Motion(turns=tuple(float(x) for x in turns))
    records, images, timing_cases = [], {}, []
    t_run = _time.perf_counter()
    renderers = {}
    try:
        for scene in scenes:
            try:
                scene_cases = cameras_for(scene.radius)
            except InputError as exc:
                raise InputError(f"{scene.source}: no camera fits this scene ({exc})") from None
            for case in scene_cases:
                if case_names is not None and case.name not in case_names:
                    continue
                pyr = None
                if "pyrender" in oracles:
                    from .pyrender_oracle import PyrenderOracle

                    size = (case.camera.width, case.camera.height)
                    if size not in renderers:
                        renderers[size] = PyrenderOracle(*size)
                    pyr = renderers[size]
                result = run_case(scene, case, frames, candidate, motion, tol, pyrender_oracle=pyr)
                records.append(result.record)
                timing_cases.append({"scene": scene.name, "camera": case.name, **result.timing})
                if result.worst_images:
                    images[(scene.name, case.name)] = result.worst_images
    finally:
        for r in renderers.values():
            r.close()

    def mean_of(key):
        vals = [t[key] for t in timing_cases if key in t]
        return sum(vals) / len(vals) if vals else None

    failed = sum(1 for r in records if r["verdict"] != "pass")
    vertex_errs = [r["max_vertex_error_px"] for r in records if r.get("max_vertex_error_px") is not None]
    f1_0 = [r["pixel_f1_0px"] for r in records if r.get("pixel_f1_0px") is not None]
    f1_1 = [r["pixel_f1_1px"] for r in records if r.get("pixel_f1_1px") is not None]
    report = {
        "tool": "wirecheck crosscheck",
        "verdict": "fail" if failed else "pass",
        "candidate": candidate_name,
        "oracles": list(oracles),
        "frames": frames,
        "motion": {"turns": list(motion.turns)},
        "tolerances": tol.to_dict(),
        "summary": {"cases": len(records), "passed": len(records) - failed, "failed": failed,
                    "max_vertex_error_px": max(vertex_errs) if vertex_errs else None,
                    "min_pixel_f1_0px": min(f1_0) if f1_0 else None,
                    "min_pixel_f1_1px": min(f1_1) if f1_1 else None},
        "cases": records,
        "timing": {"candidate_ms_per_frame": mean_of("candidate_ms_per_frame"),
                   "opencv_ms_per_frame": mean_of("opencv_ms_per_frame"),
                   "pyrender_ms_per_frame": mean_of("pyrender_ms_per_frame"),
                   "wall_s": _time.perf_counter() - t_run,
                   "cases": timing_cases},
    }
    return report, images
