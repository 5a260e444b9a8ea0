"""The one judge of a case: its evidence against the tolerances, a verdict and its reasons.

:func:`decide` is the only place a case's verdict is made, on every path (a projector's vertices and the
pixels the harness draws from them, core's own frames, a renderer's PNGs): a pure function of the case's
frozen evidence (:class:`oracles.judge.evidence.CaseEvidence`) and :class:`~oracles.tolerances.Tolerances`
(with :data:`oracles.tolerances.NAMING` for the thresholds no run sets). It fails a case for each limit
missed, one reason each:

- the vertex bound and points visible to one side only, where vertices were compared;
- the pixel F1 at the radius the lines' width allows (oracles.judge.f1_radius; F1@1px for 1-px lines);
- GL's pixel rule (F1@0px, the one-sided balance, the per-edge counts: :func:`gl_rule_reasons`), unless
  the lines are of a style no pixel rule holds, or a correct drawing by the rounded-ends rule under
  ``--line-rule any`` (:func:`judge_style`);
- a renderer's line centres, ends and warp against their bounds (:func:`judge_style`);
- the shaded limits (regions inside a silhouette, IoU, faces, depth);
- a renderer's depth maps and filled frames (``depth_map``, ``filled``: oracles.judge.depth_frames,
  filled_frames): depth error over its bound, holes and extra surface, blank frames, the silhouette's
  longest run and IoU, object ids;
- the gate (:mod:`oracles.judge.gate`): a case that misses no limit but compared nothing is ``"vacuous"``;
- the oracle's own precision: past ``tol.oracle_limit_px`` (oracles.references.oracle_precision) the pixels are
  set aside and the case is judged on its vertices alone.

The names are :func:`oracles.judge.name_faults.name_faults`'s, from the same evidence and this verdict.
:func:`pixel_fields` is the measurement both paths collect alike.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from .. import faults as catalogue
from ..faults import Fault
from ..tolerances import NAMING, Tolerances, line_failures
from . import gate
from .evidence import CaseEvidence, Radius, StyleRead

__all__ = [
    "Verdict",
    "StyleJudgement",
    "decide",
    "judge_style",
    "gl_rule_reasons",
    "rounded_rule_failures",
    "pixel_fields",
    "depth_map_reasons",
    "filled_reasons",
    "RULE_FAULTS",
    "ROUNDED_RULE_NAME",
]

#: Faults a correct drawing under another aliased rule leaves under GL's: the diagnosis may name only these
#: for the pixels to be read as the rounded-ends rule's correct drawing (their own names give way to it).
RULE_FAULTS = ("unexplained", "pixel_offset", "raster_rule") + catalogue.names("line_count")
#: The rounded-ends rule, in words (oracles.line_model).
ROUNDED_RULE_NAME = "ends rounded to pixel centres (Bresenham, Pillow, cv2.line)"


@dataclass(frozen=True)
class StyleJudgement:
    """A renderer's lines (the style read) held to the tolerances: the bounds, what misses them, the rule read.

    ``offset_tol_px``, ``warp_tol_px``: the centres' bounds for this style; ``moved``, ``warped``,
    ``end_out``: the measured centres, warp and free ends miss them (only where the centres were measured);
    ``rounded_failures``: the limits a correct drawing by the rounded-ends rule misses (None: not judged);
    ``rule_read``: the rule the pixels were read as (``"gl"``, ``"rounded"``; None: no pixel rule holds the
    lines); ``rounded_case``: ``"correct"`` (a correct drawing by the rounded-ends rule) or ``"biased"``
    (that rule's drawing but for a bias of its one-sided pixels, ``--line-rule any``), else None;
    ``pixel_rule``: GL's limits decide; ``gl_reasons``: GL's limits missed; ``only_gl``: nothing else of
    F1 missed; ``failures``: the reasons the style adds; ``job_moved``: the job's pooled offset
    (oracles.judge.job_read), not the case's own, misses ``offset_tol_px`` (``moved`` is then set too).
    """

    offset_tol_px: float
    warp_tol_px: float
    moved: bool
    warped: bool
    end_out: bool
    rounded_failures: tuple[str, ...] | None
    rule_read: str | None
    rounded_case: str | None
    pixel_rule: bool
    gl_reasons: tuple[str, ...]
    only_gl: bool
    failures: tuple[str, ...]
    job_moved: bool = False


@dataclass(frozen=True)
class Verdict:
    """A case's verdict (``"pass"``, ``"fail"``, ``"vacuous"``), its reasons, and the style's judgement."""

    verdict: str
    reasons: tuple[str, ...]
    style: StyleJudgement | None = None
    #: The reasons the case had with its pixels, set aside because the pyrender oracle's own error bound
    #: exceeds Tolerances.oracle_limit_px (its pixels then say nothing of the candidate); None: the pixels were judged.
    set_aside: tuple[str, ...] | None = None


def pixel_fields(pixel: dict, worst_frame) -> dict:
    """A case's pixel fields from its frames' scores (``pixel``: metrics.PIXEL_SCORE_KEYS -> per-frame list).

    The minimum over the frames decides (the worst frame); the means are
    reported beside it. ``worst_frame``: the frame with the lowest (F1@1px, F1@0px).
    """
    return {
        "pixel_f1_0px": float(min(pixel["f1_0px"])),
        "pixel_f1_1px": float(min(pixel["f1_1px"])),
        "pixel_f1_0px_mean": float(np.mean(pixel["f1_0px"])),
        "pixel_f1_1px_mean": float(np.mean(pixel["f1_1px"])),
        "pixel_precision_0px": float(min(pixel["precision_0px"])),
        "pixel_recall_0px": float(min(pixel["recall_0px"])),
        "pixel_precision_1px": float(min(pixel["precision_1px"])),
        "pixel_recall_1px": float(min(pixel["recall_1px"])),
        "worst_pixel_frame": worst_frame,
    }


def _vertex_reasons(v, tol: Tolerances) -> list[str]:
    out = []
    if v.get("max_vertex_error_px") is not None:
        bound = v.get("vertex_bound_px", tol.vertex_px)
        if v["max_vertex_error_px"] > bound:
            judged = (v.get("precision") or {}).get("judged_as", "float64")
            out.append(
                f"max vertex error {v['max_vertex_error_px']:.3g} px > {bound:.3g} px "
                f"({judged} bound; frame {v['worst_vertex']['frame']}, "
                f"vertex {v['worst_vertex']['vertex']})"
            )
    vm = v.get("visibility_mismatch")
    if vm is not None and (vm["candidate_only"] or vm["oracle_only"]):
        out.append(
            f"visible sets differ: {vm['candidate_only']} points shown only by the candidate, "
            f"{vm['oracle_only']} only by the oracle"
        )
    return out


def _radius_reasons(px: Mapping[str, Any], r: Radius | None, tol: Tolerances) -> list[str]:
    """F1 at the radius the lines' width allows (``r``, oracles.judge.f1_radius; None: F1@1px of the pixel
    fields ``px``), held to ``min_f1_1px``."""
    radius, f1, frame = (
        (r.radius_px, r.f1, r.frame) if r is not None else (1, px["pixel_f1_1px"], px["worst_pixel_frame"])
    )
    if f1 < tol.min_f1_1px:
        return [
            f"pixel F1@{radius}px {f1:.4f} < {tol.min_f1_1px} (frame {frame}"
            + ("; lines read wider than 1 px" if radius > 1 else "")
            + ")"
        ]
    return []


def gl_rule_reasons(px: Mapping[str, Any], lines: Mapping[str, Any] | None, tol: Tolerances) -> list[str]:
    """The limits of GL's pixel rule the case misses: F1@0px (of the pixel fields ``px``), the balance and the
    per-edge counts (of the ``lines``)."""
    out = []
    if px["pixel_f1_0px"] < tol.min_f1_0px:
        out.append(f"pixel F1@0px {px['pixel_f1_0px']:.4f} < {tol.min_f1_0px}")
    if lines is not None:
        out += line_failures(dict(lines), tol)
    return out


def rounded_rule_failures(rounded, tol: Tolerances) -> list[str]:
    """Why pixels are no correct drawing by the rounded-ends rule: its F1@0px (worst frame), at least
    ``rule_f1_0px`` (or the run's F1@0px floor if higher: a rule is read from its pixels), and its line
    fields' balance and per-edge counts (oracles.tolerances.line_failures), as GL's are judged."""
    out = []
    floor = max(tol.min_f1_0px, tol.rule_f1_0px)
    if rounded["pixel_f1_0px"] < floor:
        out.append(f"pixel F1@0px {rounded['pixel_f1_0px']:.4f} < {floor} against the rounded-ends rule too")
    return out + [f"{r} (the rounded-ends rule)" for r in line_failures(rounded["lines"], tol)]


def judge_style(
    s: StyleRead,
    pf0: float,
    diagnosed: tuple[Fault, ...],
    tol: Tolerances,
    gl_reasons: list[str],
    radius_reasons: list[str],
) -> StyleJudgement:
    """The style read ``s`` held to ``tol``: the centres' bounds and the rule read (:class:`StyleJudgement`).

    ``pf0``: the case's F1@0px against GL's rule; ``diagnosed``: what the diagnosis named
    (CaseEvidence.diagnosed); ``gl_reasons``, ``radius_reasons``: GL's limits and the F1 radius's missed.

    Binary lines (1 px or wide) are held to ``rule_offset_px`` (another aliased rule's, or a wide rule's,
    snapped ends), grey lines to ``offset_px`` plus half a coverage step; the warp to ``scale_px``, binary
    lines half a pixel more (NAMING.binary_warp_px); free ends within ``-end_px`` and half the width plus
    ``end_px``. Aliased lines under ``--line-rule gl``/``any`` are held to GL's pixel rule, unless their
    pixels are a correct drawing by the rounded-ends rule (its limits met, the centres in place, nothing
    but GL's pixel rule failing and the diagnosis naming only :data:`RULE_FAULTS`): under ``any`` GL's limits
    then go, under ``gl`` a reason says which rule was read. Under ``any``, pixels that are the rounded-ends
    rule's but for a bias of its one-sided pixels are judged by that rule's limits instead of GL's.
    """
    read, geo, rounded = s.read, s.geometry, s.rounded
    binary = read["grey_share"] <= NAMING.grey_share_max
    offset_tol = tol.rule_offset_px if binary else tol.offset_px + 0.5 / read["coverage_steps"]
    warp_tol = tol.scale_px + (NAMING.binary_warp_px if binary else 0.0)
    d = s.offset_px
    moved = s.placed and max(abs(d[0]), abs(d[1])) > offset_tol
    warped = s.placed and geo["warp_px"] > warp_tol
    job = s.job or {}
    job_d = job.get("offset_px")
    # one renderer places every case's lines alike (oracles.judge.job_read): the median of the cases' offsets
    # (where the case's own offset already misses the bound on lines no pixel rule holds, that one is reported)
    job_moved = bool(
        job_d is not None
        and s.placed
        and not (moved and not s.by_rule)
        and max(abs(job_d[0]), abs(job_d[1])) > offset_tol
    )
    end = geo["end_px"]
    end_out = bool(
        s.placed
        and geo["ends_measured"] >= NAMING.min_ends
        and (end < -tol.end_px or end > read["width_px"] / 2 + tol.end_px)
    )
    failures = []
    if s.placed and not s.by_rule:
        if moved:
            failures.append(
                f"line centres offset by ({d[0]:.2f}, {d[1]:.2f}) px > {offset_tol:.3g} "
                f"({s.style} lines, {geo['samples']} samples)"
            )
        if end_out:
            failures.append(
                f"line ends {end:+.2f} px from the segments' ends: expected "
                f"{-tol.end_px} to {read['width_px'] / 2 + tol.end_px:.2f} ({s.style} lines)"
            )
        if warped:
            failures.append(
                f"line centres moved by up to {geo['warp_px']:.2f} px by a scale, rotation "
                f"or shear > {warp_tol:.3g} ({s.style} lines)"
            )
    if job_moved:
        failures.append(
            f"the job's line centres offset by ({job_d[0]:.2f}, {job_d[1]:.2f}) px > {offset_tol:.3g} (the median "
            f"of {job['offset_cases']} cases' offsets: one renderer places every case's lines; this case's own "
            f"({d[0]:.2f}, {d[1]:.2f}))"
        )
        moved = True
    only_gl = bool(gl_reasons) and not radius_reasons
    only_rule = only_gl and all(f.name in RULE_FAULTS for f in diagnosed)
    rule_read: str | None = None
    rounded_case: str | None = None
    rounded_failures: tuple[str, ...] | None = None
    if s.by_rule and rounded is not None:
        rounded_failures = tuple(rounded_rule_failures(rounded, tol))
        rf0 = rounded["pixel_f1_0px"]
        rule_read = (
            "rounded" if (not rounded_failures and not gl_reasons and not moved and not warped and rf0 > pf0) else "gl"
        )
        if not rounded_failures and not moved and not warped and only_rule:
            rule_read, rounded_case = "rounded", "correct"
            if s.line_rule == "gl":  # another rule's correct drawing, named; no count deficit
                failures.append(
                    f"the pixels are a correct drawing by another rule than GL's ({ROUNDED_RULE_NAME}: "
                    f"F1@0px {rf0:.4f} against it, {pf0:.4f} against GL's)"
                )
        elif s.line_rule == "any" and only_rule and pf0 < rf0 and rf0 >= max(tol.min_f1_0px, tol.rule_f1_0px):
            # the rounded-ends rule's pixels but for a bias of its one-sided pixels (a dropped end pixel)
            rule_read, rounded_case = "rounded", "biased"
            failures += rounded_failures
        if (
            job.get("rule") == "rounded"
            and rule_read == "gl"
            and s.line_rule == "any"
            and only_rule
            and not moved
            and not warped
            and rf0 >= max(tol.min_f1_0px, tol.rule_f1_0px)
        ):  # the job's cases read the rounded-ends rule: this one is held to it too (oracles.judge.job_read),
            # where its pixels are that rule's drawing (F1@0px) but for what its limits say
            rule_read, rounded_case = "rounded", "correct" if not rounded_failures else "biased"
            failures += rounded_failures
    elif s.by_rule:
        rule_read = "gl"
    return StyleJudgement(
        offset_tol,
        warp_tol,
        moved,
        warped,
        end_out,
        rounded_failures,
        rule_read,
        rounded_case,
        pixel_rule=s.by_rule and rule_read != "rounded",
        gl_reasons=tuple(gl_reasons),
        only_gl=only_gl,
        failures=tuple(failures),
        job_moved=job_moved,
    )


def _blank(frames: list, what: str) -> list[str]:
    """The reason of a case whose ``what`` (depth maps, filled frames) are blank in ``frames``; [] if none."""
    if not frames:
        return []
    shown = ", ".join(map(str, frames[:5])) + (", ..." if len(frames) > 5 else "")
    return [
        f"{what} blank where the reference shows a surface (frame{'s' if len(frames) > 1 else ''} {shown}): "
        "nothing compared there"
    ]


def depth_map_reasons(d: dict, tol: Tolerances) -> list[str]:
    """The limits a case's depth maps miss (``record["depth_map"]``, oracles.judge.depth_frames)."""
    out = []
    if d["max_error_ratio"] is not None and d["max_error_ratio"] > tol.max_depth_error_ratio:
        r, c = d["worst_pixel"]
        out.append(
            f"depth error {d['max_error']:.3g} is {d['max_error_ratio']:.3g} x its bound "
            f"(> {tol.max_depth_error_ratio:g}; frame {d['worst_frame']}, row {r}, column {c})"
        )
    if d["reference_px"] and not d["compared_px"]:
        out.append(
            f"depth maps compare nothing: no pixel shows a surface on both sides "
            f"({d['reference_px']} reference pixels): never a pass"
        )
    out += _blank(d["blank_frames"], "depth map")
    if d["holes_px"] > tol.max_surface_holes_px:
        out.append(
            f"depth map: {d['holes_px']} pixels of the reference's surface left empty away from its "
            f"silhouette's boundary (> {tol.max_surface_holes_px}; most in frame {d['holes_worst_frame']})"
        )
    if d["extra_px"] > tol.max_surface_extra_px:
        out.append(
            f"depth map: {d['extra_px']} pixels of surface where the reference has none, away from its "
            f"silhouette's boundary (> {tol.max_surface_extra_px}; most in frame {d['extra_worst_frame']})"
        )
    return out


def filled_reasons(f: dict, tol: Tolerances) -> list[str]:
    """The limits a case's filled frames miss (``record["filled"]``, oracles.judge.filled_frames): blank frames,
    the longest run of decided pixels missing or added (oracles.judge.silhouette), the IoU."""
    out = _blank(f["blank_frames"], "filled frame")
    if f["longest_run_px"] > tol.max_silhouette_run_px:
        r, c = f["run_at"]
        out.append(
            f"filled silhouette: {f['longest_run_px']} decided pixels missing or added in one run (frame "
            f"{f['run_frame']}, row {r}, column {c}; > {tol.max_silhouette_run_px}); {f['holes_px']} holes, "
            f"{f['extra_px']} extra in all"
        )
    if f["min_iou"] is not None and f["min_iou"] < tol.min_iou:
        out.append(f"filled silhouette IoU {f['min_iou']:.4f} < {tol.min_iou} (frame {f['iou_worst_frame']})")
    if f.get("object_id_px") is not None and f["object_id_px"] > tol.max_object_id_px:
        out.append(
            f"filled frames: {f['object_id_px']} decided pixels show another object's id than the "
            f"reference's (> {tol.max_object_id_px}; most in frame {f['object_id_worst_frame']})"
        )
    return out


def _shaded_reasons(sh, tol: Tolerances) -> list[str]:
    out = []
    if sh["silhouette_mismatch_inside"]:
        out.append(
            f"{sh['silhouette_mismatch_inside']} pixels covered by one side only lie inside its "
            "silhouette, not on its boundary (a hole or a misplaced region)"
        )
    if sh["silhouette_iou_gated"] is not None and sh["silhouette_iou_gated"] < tol.min_iou:
        out.append(f"silhouette IoU {sh['silhouette_iou_gated']:.4f} < {tol.min_iou} (frame {sh['worst_pixel_frame']})")
    if sh["face_disagreements_inside"]:
        out.append(
            f"{sh['face_disagreements_inside']} pixels show a different face than the oracle "
            "away from any boundary between the two faces (a visibility error)"
        )
    if sh["depth_error_ratio"] is not None and sh["depth_error_ratio"] > 1.0:
        out.append(
            f"depth error {sh['depth_max_error']:.3g} > its bound {sh['depth_error_bound']:.3g} "
            f"(error/bound up to {sh['depth_error_ratio']:.3g}, frame {sh['depth_worst_frame']})"
        )
    return out


def decide(ev: CaseEvidence, tol: Tolerances) -> Verdict:
    """The case's verdict and its reasons, in this order: the candidate's error, the vertices, the pixel F1 at
    the lines' radius, GL's pixel rule (where it decides), the style's failures, the shaded limits, the depth
    maps' and filled frames' limits; then the
    gate (oracles.judge.gate.case_verdict) at ``ev.level``."""
    why = [ev.error] if ev.error else []
    if ev.frames_checked and ev.vertices is not None:
        why += _vertex_reasons(ev.vertices, tol)
    style = None
    if ev.pixels is not None and ev.pixels.get("pixel_f1_0px") is not None:
        radius = _radius_reasons(ev.pixels, ev.radius, tol)
        gl = gl_rule_reasons(ev.pixels, ev.lines, tol)
        why += radius
        if ev.style is not None:
            style = judge_style(ev.style, ev.pixels["pixel_f1_0px"], ev.diagnosed, tol, gl, radius)
        why += gl if style is None or style.pixel_rule else []
        why += list(style.failures) if style is not None else []
    if ev.shaded is not None and ev.shaded.get("silhouette_iou") is not None:
        why += _shaded_reasons(ev.shaded, tol)
    if ev.depth_map is not None:
        why += depth_map_reasons(ev.depth_map, tol)
    if ev.filled is not None:
        why += filled_reasons(ev.filled, tol)
    verdict, reasons = gate.case_verdict(dict(ev.compared), why, ev.level, ev.points)
    if ev.oracle_bound_px is not None and ev.oracle_bound_px > tol.oracle_limit_px and verdict != "vacuous":
        return _vertices_only(ev, tol, tuple(reasons), style)
    return Verdict(verdict, tuple(reasons), style)


def _vertices_only(ev: CaseEvidence, tol: Tolerances, reasons: tuple, style) -> Verdict:
    """Past the oracle's precision limit the pixels say nothing of the candidate: the case judged on its
    vertices alone, ``"fail"`` only for a vertex failure (or the candidate's error), else ``"vacuous"`` (which
    fails the run, oracles.judge.gate), with an ``oracle_precision`` reason first."""
    vertices = dataclasses.replace(
        ev,
        level="vertices",
        pixels=None,
        lines=None,
        shaded=None,
        style=None,
        compared={**ev.compared, "pixels": None},
        oracle_bound_px=None,
    )
    alone = decide(vertices, tol)
    why = (
        f"oracle_precision: the pyrender oracle's own error bound {ev.oracle_bound_px:.3g} px exceeds "
        f"{tol.oracle_limit_px:.3g} px (float32 at this camera and mesh size); its pixels are not judged"
    )
    vertex_reasons = alone.reasons if alone.verdict == "fail" else ()
    return Verdict("fail" if vertex_reasons else "vacuous", (why,) + vertex_reasons, style, set_aside=reasons)
