"""The one judge of a case: its record's fields against the tolerances, a verdict and its reasons.

Every way a candidate reaches wirecheck ends here: a projector's vertices
(with the pixels the harness draws from them), core's own frames, and a
renderer's PNGs read by :mod:`oracles.judge.frames_judge`. Each path gathers the
same record fields from its frames; this module alone decides on them:

- the vertex bound (``max_vertex_error_px`` > ``vertex_bound_px``) and points
  visible to one side only, where vertices were compared;
- the pixel F1 at 1 px and at 0 px (``pixel_f1_1px``, ``pixel_f1_0px``: the
  worst frame's; a renderer's lines read wider than 1 px: F1 at the radius
  their width allows, ``pixel_f1_radius`` at ``f1_radius_px``,
  oracles.judge.f1_radius), the one-sided pixel balance (a sign test) and the per-edge
  pixel counts of the lines, sub-pixel ties left out
  (:func:`oracles.tolerances.line_failures` on the record's ``lines``); for a
  renderer's lines of a style GL's pixel rule cannot hold (anti-aliased, wide),
  the line centres, ends and warp measured from its images instead
  (``line_style``, oracles.judge.line_style);
- the shaded limits (regions inside a silhouette, IoU, faces, depth);
- a renderer's depth maps and filled frames (``depth_map``, ``filled``:
  oracles.judge.depth_frames, filled_frames): depth error over its bound, holes and
  extra surface, blank frames, the silhouette's longest run and IoU;
- the gate (:mod:`oracles.judge.gate`): a case that misses no limit but compared
  nothing is ``"vacuous"``;
- the ``unexplained`` rule: a case that fails without a candidate error and
  whose diagnosis named nothing gets the fault ``unexplained`` (a disagreement
  is never "no fault").

:func:`pixel_fields` and :func:`line_faults` are the parts of a record both
paths build alike: the pixel scores' minima and means over the frames, and
the line fault named when the geometry agrees.
"""

from __future__ import annotations

import numpy as np

from . import gate
from ..tolerances import Tolerances, line_failures
from ..diagnosis.diagnose import diagnose_lines

#: The fault of a failing case that no diagnosis explains.
UNEXPLAINED = {"name": "unexplained"}


def pixel_fields(pixel: dict, worst_frame) -> dict:
    """A case's pixel fields from its frames' scores (``pixel``: metrics.PIXEL_SCORE_KEYS -> per-frame list).

    The minimum over the frames decides (the worst frame); the means are
    reported beside it. ``worst_frame``: the frame with the lowest (F1@1px, F1@0px).
    """
    return {
        "pixel_f1_0px": float(min(pixel["f1_0px"])), "pixel_f1_1px": float(min(pixel["f1_1px"])),
        "pixel_f1_0px_mean": float(np.mean(pixel["f1_0px"])), "pixel_f1_1px_mean": float(np.mean(pixel["f1_1px"])),
        "pixel_precision_0px": float(min(pixel["precision_0px"])), "pixel_recall_0px": float(min(pixel["recall_0px"])),
        "pixel_precision_1px": float(min(pixel["precision_1px"])), "pixel_recall_1px": float(min(pixel["recall_1px"])),
        "worst_pixel_frame": worst_frame,
    }


def line_faults(rec: dict, tol: Tolerances, faults: list) -> list:
    """``faults``, or, when they are none and the case has line fields, the line fault those name.

    A line fault (``line_end_bias``, ``line_pixel_bias``: oracles.diagnosis.diagnose.diagnose_lines)
    is named only when the geometry agrees: no vertex fault, no fault named
    from the images.
    """
    if faults or "lines" not in rec:
        return faults
    return diagnose_lines(rec["lines"], tol)


def reasons(rec: dict, tol: Tolerances, error: str | None = None) -> list[str]:
    """Every limit of ``tol`` the case's record misses, one line each (``error``: the candidate's, first)."""
    out = [error] if error else []
    if rec["frames_checked"] and rec.get("max_vertex_error_px") is not None:
        bound = rec.get("vertex_bound_px", tol.vertex_px)
        if rec["max_vertex_error_px"] > bound:
            judged = rec.get("precision", {}).get("judged_as", "float64")
            out.append(f"max vertex error {rec['max_vertex_error_px']:.3g} px > {bound:.3g} px "
                       f"({judged} bound; frame {rec['worst_vertex']['frame']}, "
                       f"vertex {rec['worst_vertex']['vertex']})")
    if rec["frames_checked"] and "visibility_mismatch" in rec:
        vm = rec["visibility_mismatch"]
        if vm["candidate_only"] or vm["oracle_only"]:
            out.append(f"visible sets differ: {vm['candidate_only']} points shown only by the candidate, "
                       f"{vm['oracle_only']} only by the oracle")
    if rec.get("pixel_f1_0px") is not None:
        # lines read wider than 1 px: F1 at the radius their width allows (oracles.judge.f1_radius)
        radius, f1 = rec.get("f1_radius_px", 1), rec.get("pixel_f1_radius", rec["pixel_f1_1px"])
        if f1 < tol.min_f1_1px:
            out.append(f"pixel F1@{radius}px {f1:.4f} < {tol.min_f1_1px} (frame {rec.get('pixel_f1_radius_frame', rec['worst_pixel_frame'])}"
                       + ("; lines read wider than 1 px" if radius > 1 else "") + ")")
        out += pixel_rule_reasons(rec, tol) if rec.get("line_style", {}).get("pixel_rule", True) else []
        out += rec.get("line_style", {}).get("failures", [])
    if rec.get("silhouette_iou") is not None:
        out += _shaded_reasons(rec, tol)
    if "depth_map" in rec:
        out += depth_map_reasons(rec["depth_map"], tol)
    if "filled" in rec:
        out += filled_reasons(rec["filled"], tol)
    return out


def _blank(frames: list, what: str) -> list[str]:
    """The reason of a case whose ``what`` (depth maps, filled frames) are blank in ``frames``; [] if none."""
    if not frames:
        return []
    shown = ", ".join(map(str, frames[:5])) + (", ..." if len(frames) > 5 else "")
    return [f"{what} blank where the reference shows a surface (frame{'s' if len(frames) > 1 else ''} {shown}): "
            "nothing compared there"]


def depth_map_reasons(d: dict, tol: Tolerances) -> list[str]:
    """The limits a case's depth maps miss (``record["depth_map"]``, oracles.judge.depth_frames)."""
    out = []
    if d["max_error_ratio"] is not None and d["max_error_ratio"] > tol.max_depth_error_ratio:
        r, c = d["worst_pixel"]
        out.append(f"depth error {d['max_error']:.3g} is {d['max_error_ratio']:.3g} x its bound "
                   f"(> {tol.max_depth_error_ratio:g}; frame {d['worst_frame']}, row {r}, column {c})")
    if d["reference_px"] and not d["compared_px"]:
        out.append(f"depth maps compare nothing: no pixel shows a surface on both sides "
                   f"({d['reference_px']} reference pixels): never a pass")
    out += _blank(d["blank_frames"], "depth map")
    if d["holes_px"] > tol.max_surface_holes_px:
        out.append(f"depth map: {d['holes_px']} pixels of the reference's surface left empty away from its "
                   f"silhouette's boundary (> {tol.max_surface_holes_px}; most in frame {d['holes_worst_frame']})")
    if d["extra_px"] > tol.max_surface_extra_px:
        out.append(f"depth map: {d['extra_px']} pixels of surface where the reference has none, away from its "
                   f"silhouette's boundary (> {tol.max_surface_extra_px}; most in frame {d['extra_worst_frame']})")
    return out


def filled_reasons(f: dict, tol: Tolerances) -> list[str]:
    """The limits a case's filled frames miss (``record["filled"]``, oracles.judge.filled_frames): blank frames,
    the longest run of decided pixels missing or added (oracles.judge.silhouette), the IoU."""
    out = _blank(f["blank_frames"], "filled frame")
    if f["longest_run_px"] > tol.max_silhouette_run_px:
        r, c = f["run_at"]
        out.append(f"filled silhouette: {f['longest_run_px']} decided pixels missing or added in one run (frame "
                   f"{f['run_frame']}, row {r}, column {c}; > {tol.max_silhouette_run_px}); {f['holes_px']} holes, "
                   f"{f['extra_px']} extra in all")
    if f["min_iou"] is not None and f["min_iou"] < tol.min_iou:
        out.append(f"filled silhouette IoU {f['min_iou']:.4f} < {tol.min_iou} (frame {f['iou_worst_frame']})")
    if f.get("object_id_px") is not None and f["object_id_px"] > tol.max_object_id_px:
        out.append(f"filled frames: {f['object_id_px']} decided pixels show another object's id than the "
                   f"reference's (> {tol.max_object_id_px}; most in frame {f['object_id_worst_frame']})")
    return out


def pixel_rule_reasons(rec: dict, tol: Tolerances) -> list[str]:
    """The limits of GL's pixel rule the record misses: F1@0px, the balance, the per-edge counts.

    They decide unless the lines read from a renderer's frames are of a style
    that cannot follow the rule (anti-aliased, wide; or ``--line-rule
    geometry``): ``rec["line_style"]["pixel_rule"]`` False (oracles.judge.line_style),
    whose geometric ``failures`` decide instead.
    """
    out = []
    if rec["pixel_f1_0px"] < tol.min_f1_0px:
        out.append(f"pixel F1@0px {rec['pixel_f1_0px']:.4f} < {tol.min_f1_0px}")
    if "lines" in rec:
        out += line_failures(rec["lines"], tol)
    return out


def _shaded_reasons(rec: dict, tol: Tolerances) -> list[str]:
    out = []
    if rec["silhouette_mismatch_inside"]:
        out.append(f"{rec['silhouette_mismatch_inside']} pixels covered by one side only lie inside its "
                   "silhouette, not on its boundary (a hole or a misplaced region)")
    if rec["silhouette_iou_gated"] is not None and rec["silhouette_iou_gated"] < tol.min_iou:
        out.append(f"silhouette IoU {rec['silhouette_iou_gated']:.4f} < {tol.min_iou} "
                   f"(frame {rec['worst_pixel_frame']})")
    if rec["face_disagreements_inside"]:
        out.append(f"{rec['face_disagreements_inside']} pixels show a different face than the oracle "
                   "away from any boundary between the two faces (a visibility error)")
    if rec["depth_error_ratio"] is not None and rec["depth_error_ratio"] > 1.0:
        out.append(f"depth error {rec['depth_max_error']:.3g} > its bound {rec['depth_error_bound']:.3g} "
                   f"(error/bound up to {rec['depth_error_ratio']:.3g}, frame {rec['depth_worst_frame']})")
    return out


def decide(rec: dict, tol: Tolerances, error: str | None = None, points: int | None = None,
           level: str | None = None) -> None:
    """Set ``rec["verdict"]`` and ``rec["reasons"]``; a failure nothing explains gets ``unexplained``.

    ``level``: what the case compared, for the gate (oracles.judge.gate.vacuous_reason):
    ``"vertices"``, ``"pixels"`` (vertices and pixels) or ``"frames"`` (a
    renderer's frames: pixels only); None: ``"vertices"`` when
    ``rec["compared"]["pixels"]`` is None, else ``"pixels"``. ``points``: the
    scene's vertex count.
    """
    why = reasons(rec, tol, error)
    if why and not error and not rec.get("faults"):
        rec["faults"] = [dict(UNEXPLAINED)]
    if level is None:
        level = "vertices" if rec["compared"]["pixels"] is None else "pixels"
    rec["verdict"], rec["reasons"] = gate.case_verdict(rec["compared"], why, level, points)
