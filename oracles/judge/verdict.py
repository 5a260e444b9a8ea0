"""A case's record (its line in report.json) from its frames, and the verdict with its reasons.

The verdict is decided by oracles.judge.decide, the one judge of every path (a
projector's, core's, a renderer's frames). A case fails for every limit of
oracles.tolerances it misses, each named in a reason: the vertex error, points visible to one side only, the pixel F1 at 1
and 0 px, the one-sided pixel balance and the per-edge pixel counts of the
lines (oracles.tolerances.line_failures); shaded: regions covered by one side inside the other's silhouette,
the silhouette IoU, faces that differ away from their boundaries, the depth
error beyond its bound. A candidate that fails the contract (oracles.candidates.candidate)
fails the case with that error.
"""

from __future__ import annotations

import numpy as np

from ..candidates.candidate import case_precision
from ..diagnosis.diagnose import diagnose
from ..faults import Fault
from ..tolerances import MIN_IOU_UNION_PX, Tolerances, vertex_bound
from . import metrics
from .decide import decide
from .evidence import CaseEvidence
from .name_faults import name_faults
from .record import finish_record, wire_fields


def case_record(
    setup, acc, tol: Tolerances, points: int | None = None, oracle_bound_px: float | None = None
) -> tuple[dict, CaseEvidence]:
    """The case's fields from its frames (``setup``: oracles.judge.case.CaseSetup, ``acc``: its CaseFrames), and
    the same measurements frozen as its evidence: ``(record, evidence)``.

    Vertex errors pooled over the frames, the worst vertex, the pixel scores' minima and means, the shaded
    summary, and a note when there was nothing to compare; its ``faults`` slot is left empty for :func:`judge`
    (the names are name_faults', from the evidence). The evidence holds the vertex, pixel, line and shaded
    fields, the faults oracles.diagnosis.diagnose names from the vertices (``image_faults``) and those the line
    fields name (``line_faults``, oracles.diagnosis.diagnose.diagnose_lines), the candidate's error
    (``acc.error``), the scene's vertex count (``points``) and pyrender's own bound (``oracle_bound_px``, where
    pixels were drawn); its level is ``"pixels"`` where pixels were compared, else ``"vertices"``.
    ``precision`` says what the candidate was judged as (declared, or as it returned; core:
    its ``--dtype``) and ``vertex_bound_px`` the bound its vertices were held
    to (oracles.tolerances.vertex_bound).
    """
    done = len(acc.cand_px)
    rec = {
        "scene": setup.scene.name,
        "camera": setup.case.name,
        "camera_spec": setup.cam.to_dict(),
        "frames": setup.frames,
        "frames_checked": done,
    }
    precision, source = case_precision(tol.precision, acc.returned)
    if setup.is_core and tol.precision is None and acc.returned:
        source = "core --dtype"
    bound = vertex_bound(precision, acc.scale, tol.vertex_px)
    rec["precision"] = {
        "judged_as": precision,
        "source": source,
        "returned": sorted(acc.returned) if acc.returned else None,
    }
    rec["vertex_bound_px"] = bound
    vertices = {"vertex_bound_px": bound, "precision": rec["precision"]}
    if acc.depth_ties:  # points on near/far to within the candidate's rounding, clipped by one side only
        rec["depth_ties"] = acc.depth_ties
    if setup.pixels and setup.mode.hidden_lines:
        rec["hidden_lines"] = setup.faces is not None
    faults = []
    if done:
        cand, orac = np.concatenate(acc.cand_px), np.concatenate(acc.oracle_px)
        ve = metrics.vertex_errors(cand, orac)
        worst_v = max(acc.frame_errors, key=lambda e: (e[0], -e[1])) if acc.frame_errors else (None, None, None)
        vertices.update(
            {
                "max_vertex_error_px": ve["max_px"],
                "worst_vertex": {"frame": worst_v[1], "vertex": worst_v[2], "error_px": worst_v[0]},
                "visibility_mismatch": {"candidate_only": ve["candidate_only"], "oracle_only": ve["oracle_only"]},
            }
        )
        rec.update(
            {
                "max_vertex_error_px": ve["max_px"],
                "mean_vertex_error_px": ve["mean_px"],
                "rms_vertex_error_px": ve["rms_px"],
                "worst_vertex": vertices["worst_vertex"],
                "visible_points": ve["visible_both"],
                "visibility_mismatch": vertices["visibility_mismatch"],
            }
        )
        bound32 = vertex_bound("float32", acc.scale, tol.vertex_px) if precision == "float64" else None
        faults = diagnose(cand, orac, setup.cam, tol_px=bound, float32_px=bound32, planes=acc.planes)
    else:
        vertices["max_vertex_error_px"] = None
        rec.update({"max_vertex_error_px": None, "mean_vertex_error_px": None, "rms_vertex_error_px": None})
    lines, shaded, line_faults = None, None, ()
    if acc.wire is not None and acc.wire.measured:
        pixels, lines, line_faults = wire_fields(acc.wire, tol)
        rec.update(pixels)
        rec["lines"] = lines
    else:
        pixels = {"pixel_f1_0px": None, "pixel_f1_1px": None}
        rec.update(pixels)
    if setup.pixels and setup.mode.shaded:
        shaded = shaded_summary(acc.shaded.scores, acc.shaded.worst)
        rec.update(shaded)
        pixels = {**pixels, "worst_pixel_frame": shaded["worst_pixel_frame"]}
    rec["faults"] = []  # named by judge (name_faults: a line fault only when the vertices agree)
    rec["compared"] = {
        "frames": done,
        "vertices": rec.get("visible_points", 0),
        "pixels": acc.drawn_px if setup.pixels else None,
    }
    if done and setup.pixels and not setup.mode.plain and setup.faces is None:
        rec["note"] = {
            "shaded": "no faces: nothing to shade; only the vertices were checked",
            "wireframe": "no faces: nothing hides or culls a line; compared as a plain wireframe",
        }[setup.mode.style]
    ev = CaseEvidence(
        level="pixels" if setup.pixels else "vertices",
        compared=rec["compared"],
        frames_checked=done,
        pixels={k: pixels[k] for k in PIXEL_KEYS if k in pixels},
        lines=lines,
        vertices={k: vertices[k] for k in VERTEX_KEYS if k in vertices},
        shaded={k: shaded[k] for k in SHADED_KEYS if k in shaded} if shaded is not None else None,
        image_faults=tuple(Fault.of(f) for f in faults),
        line_faults=line_faults,
        error=acc.error,
        points=points,
        oracle_bound_px=oracle_bound_px,
    )
    return rec, ev


def shaded_summary(shaded: list, worst) -> dict:
    """A case's shaded fields from its frames' scores (None where nothing was compared)."""
    out = {
        "silhouette_iou": None,
        "silhouette_iou_mean": None,
        "depth_max_error": None,
        "depth_mean_error": None,
        "depth_error_bound": None,
        "depth_error_ratio": None,
        "depth_worst_frame": None,
        "depth_pixels": 0,
        "worst_pixel_frame": None,
        "face_disagreements": 0,
        "face_disagreements_inside": 0,
        "silhouette_mismatch_inside": 0,
        "silhouette_iou_gated": None,
    }
    if not shaded:
        return out
    out["silhouette_mismatch_inside"] = int(sum(s.get("silhouette_mismatch_inside", 0) for _, s in shaded))
    gated = [s["silhouette_iou"] for _, s in shaded if s.get("silhouette_union_px", 0) >= MIN_IOU_UNION_PX]
    out["silhouette_iou_gated"] = float(min(gated)) if gated else None  # IoU over frames big enough to judge
    out["face_disagreements"] = int(sum(s.get("face_disagreements", 0) for _, s in shaded))
    out["face_disagreements_inside"] = int(sum(s.get("face_disagreements_inside", 0) for _, s in shaded))
    ious = [s["silhouette_iou"] for _, s in shaded]
    out.update(
        silhouette_iou=float(min(ious)),
        silhouette_iou_mean=float(np.mean(ious)),
        worst_pixel_frame=worst[1] if worst else None,
    )
    with_depth = [(k, s) for k, s in shaded if s["depth_max_error"] is not None]
    if with_depth:
        pixels = sum(s["depth_pixels"] for _, s in with_depth)
        k_err, s_err = max(with_depth, key=lambda e: (e[1]["depth_max_error"], -e[0]))
        k_ratio, s_ratio = max(with_depth, key=lambda e: (e[1]["depth_error_ratio"], -e[0]))
        out.update(
            depth_max_error=s_err["depth_max_error"],
            depth_error_bound=s_err["depth_error_bound"],
            depth_mean_error=float(sum(s["depth_mean_error"] * s["depth_pixels"] for _, s in with_depth) / pixels),
            depth_error_ratio=s_ratio["depth_error_ratio"],
            depth_worst_frame=k_ratio,
            depth_pixels=int(pixels),
        )
    return out


#: A projector case's vertex and shaded fields, as its evidence holds them (oracles.judge.evidence).
VERTEX_KEYS = ("max_vertex_error_px", "vertex_bound_px", "worst_vertex", "precision", "visibility_mismatch")
SHADED_KEYS = (
    "silhouette_iou",
    "silhouette_iou_gated",
    "silhouette_mismatch_inside",
    "face_disagreements_inside",
    "depth_error_ratio",
    "depth_max_error",
    "depth_error_bound",
    "depth_worst_frame",
    "worst_pixel_frame",
)
PIXEL_KEYS = ("pixel_f1_0px", "pixel_f1_1px", "worst_pixel_frame")


def judge(rec: dict, ev: CaseEvidence, tol: Tolerances, per_frame: list) -> None:
    """The case decided from its evidence (oracles.judge.decide.decide: one reason per limit missed) and its
    faults named (oracles.judge.name_faults: a failure nothing explains is ``unexplained``; past the oracle's
    precision limit the names read from pixels go), written into ``rec`` (oracles.judge.record.finish_record).

    "fail" when a limit is missed; else "vacuous" when the case compared nothing
    (``rec["compared"]``; ``ev.points``: the scene's vertex count), else "pass" (oracles.judge.gate).
    Past the oracle's limit (``ev.oracle_bound_px`` beyond it) the case is judged on its vertices alone
    (``oracle_precision``: True).
    """
    verdict = decide(ev, tol)
    finish_record(rec, ev, verdict, name_faults(ev, verdict, tol), per_frame, tol.oracle_limit_px)
