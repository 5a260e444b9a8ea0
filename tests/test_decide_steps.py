"""The three pure steps of a case's judgement on hand-made evidence: oracles.judge.evidence (frozen),
oracles.judge.decide.decide (each limit just met and just missed, the bound taken from its Tolerances or
NAMING field) and oracles.judge.name_faults.name_faults (the precedence table: of two candidate names, the
table's winner).

Every input below is written by hand (no frame drawn, nothing measured by the code under test); "just
missed" is the next float past the bound (math.nextafter), so a limit compared with >= instead of > (or the
reverse), or a bound taken from another field, fails here.
"""

from __future__ import annotations

import dataclasses
import math

import pytest
from wirecheck.oracles.faults import Fault
from wirecheck.oracles.judge.decide import Verdict, decide
from wirecheck.oracles.judge.evidence import CaseEvidence, Radius, StyleRead, Visibility
from wirecheck.oracles.judge.name_faults import PRECEDENCE, name_faults
from wirecheck.oracles.tolerances import NAMING, Tolerances

TOL = Tolerances()
UP = math.inf

#: Line fields that pass every line limit (balanced, no per-edge deficit).
LINES_OK = {
    "imbalance_fraction": 0.0,
    "balance_p_value": 1.0,
    "subpixel_ties": [0, 0],
    "candidate_only": 0,
    "oracle_only": 0,
    "edge_count_max_diff": 0,
    "edge_count_worst": None,
    "imbalance": 0,
    "lines_compared": 12,
    "one_sided_by_place": {"start": [0, 0], "end": [0, 0], "middle": [0, 0]},
}
COMPARED = {"frames": 2, "vertices": 0, "pixels": 500}
RASTER_NONE = {"oracle_pixels": 400, "differing": 0, "off_by_one_across": 0, "off_by_one_at_ends": 0, "farther": 0}


def _geometry(dx=0.0, warp=0.0, end=0.0, ends=6):
    return {
        "samples": 900,
        "windows": 100,
        "found_share": 1.0,
        "offset_px": [dx, 0.0],
        "bias_px": [0.0, 0.0],
        "warp_px": warp,
        "ends_measured": ends,
        "end_px": end,
    }


def _style(
    style="antialiased",
    grey_share=0.4,
    steps=4,
    width=1.0,
    line_rule="any",
    rounded=None,
    raster=RASTER_NONE,
    placed=True,
    **geo,
):
    read = {
        "style": style,
        "width_px": width,
        "grey_share": grey_share,
        "level": 255,
        "coverage_steps": steps,
        "band_px": max(round(width), 1),
        "pixel_ratio": 1.0,
    }
    return StyleRead(line_rule, read, _geometry(**geo), raster, rounded, (), placed)


def _evidence(f1_0=1.0, f1_1=1.0, style=None, **kw):
    return CaseEvidence(
        level="frames",
        compared=kw.pop("compared", COMPARED),
        frames_checked=2,
        pixels={"pixel_f1_0px": f1_0, "pixel_f1_1px": f1_1, "worst_pixel_frame": 3},
        lines=kw.pop("lines", LINES_OK),
        style=style,
        **kw,
    )


def _names(ev, tol=TOL):
    return [f.name for f in name_faults(ev, decide(ev, tol), tol)]


# ---------------------------------------------------------------- evidence is frozen


def test_evidence_is_frozen():
    ev = _evidence(style=_style())
    with pytest.raises(dataclasses.FrozenInstanceError):
        ev.pixels = {}
    with pytest.raises(TypeError):  # its mappings are read-only views
        ev.pixels["pixel_f1_0px"] = 0.0
    with pytest.raises(TypeError):
        ev.style.geometry["offset_px"] = [9.0, 9.0]
    with pytest.raises(dataclasses.FrozenInstanceError):
        decide(ev, TOL).verdict = "pass"


def test_evidence_copies_what_it_is_given():
    pixels = {"pixel_f1_0px": 1.0, "pixel_f1_1px": 1.0, "worst_pixel_frame": 3}
    ev = CaseEvidence(level="frames", compared=COMPARED, frames_checked=2, pixels=pixels)
    pixels["pixel_f1_0px"] = 0.0  # the caller's dict changed afterwards: not the evidence
    assert ev.pixels["pixel_f1_0px"] == 1.0 and decide(ev, TOL).verdict == "pass"


# ---------------------------------------------------------------- decide: each limit, just met and just missed


def test_f1_at_one_pixel_decides_at_min_f1_1px():
    assert decide(_evidence(f1_1=TOL.min_f1_1px), TOL).verdict == "pass"
    v = decide(_evidence(f1_1=math.nextafter(TOL.min_f1_1px, -UP)), TOL)
    assert v.verdict == "fail" and v.reasons[0].startswith("pixel F1@1px")


def test_f1_at_the_radius_decides_not_f1_at_one_pixel():
    # lines read 3 px wide: the F1 at radius 2 is held to min_f1_1px; F1@1px beside it does not decide
    wide = dict(f1_1=0.5, radius=Radius(2, TOL.min_f1_1px, 4))
    assert decide(_evidence(**wide), TOL).verdict == "pass"
    v = decide(_evidence(f1_1=0.5, radius=Radius(2, math.nextafter(TOL.min_f1_1px, -UP), 4)), TOL)
    assert v.reasons == (
        f"pixel F1@2px {math.nextafter(TOL.min_f1_1px, -UP):.4f} < {TOL.min_f1_1px} "
        "(frame 4; lines read wider than 1 px)",
    )


def test_f1_at_zero_pixels_decides_at_min_f1_0px():
    assert decide(_evidence(f1_0=TOL.min_f1_0px), TOL).verdict == "pass"
    v = decide(_evidence(f1_0=math.nextafter(TOL.min_f1_0px, -UP)), TOL)
    assert v.verdict == "fail" and v.reasons[0].startswith("pixel F1@0px")


def test_edge_counts_decide_at_max_edge_count_diff():
    worst = {"edge": 3, "diff": -TOL.max_edge_count_diff - 1, "frame": 2}
    at = dict(LINES_OK, edge_count_max_diff=TOL.max_edge_count_diff, edge_count_worst=worst)
    past = dict(LINES_OK, edge_count_max_diff=TOL.max_edge_count_diff + 1, edge_count_worst=worst)
    assert decide(_evidence(lines=at), TOL).verdict == "pass"
    assert decide(_evidence(lines=past), TOL).reasons[0].startswith("edge 3 has -4 pixels")


def test_grey_lines_offset_decides_at_offset_px_plus_half_a_coverage_step():
    # antialiased lines in 4 coverage steps: offset_px + 0.5 / 4 (Tolerances.offset_px, line_style's rule)
    bound = TOL.offset_px + 0.5 / 4
    assert decide(_evidence(style=_style(dx=bound)), TOL).verdict == "pass"
    v = decide(_evidence(style=_style(dx=math.nextafter(bound, UP))), TOL)
    assert v.verdict == "fail" and v.reasons == (
        f"line centres offset by (0.33, 0.00) px > {bound:.3g} (antialiased lines, 900 samples)",
    )
    assert v.style.moved and not v.style.warped


def test_aliased_lines_held_to_gl_are_not_held_to_their_centres():
    # aliased lines under --line-rule gl: GL's pixel rule decides (here met), the centres' offset is measured
    # (moved) but adds no reason of its own
    v = decide(
        _evidence(style=_style(style="aliased", grey_share=0.0, line_rule="gl", dx=0.5, warp=2.0, end=-2.0)), TOL
    )
    assert v.style.moved and v.style.warped and v.style.end_out and v == Verdict("pass", (), v.style)


def test_binary_wide_lines_offset_decides_at_rule_offset_px():
    binary = dict(style="wide", grey_share=NAMING.grey_share_max, width=3.0)
    assert decide(_evidence(style=_style(dx=-TOL.rule_offset_px, **binary)), TOL).verdict == "pass"
    assert decide(_evidence(style=_style(dx=-math.nextafter(TOL.rule_offset_px, UP), **binary)), TOL).verdict == "fail"
    # a grey share just past NAMING.grey_share_max is grey: the tighter offset_px bound holds it
    grey = dict(binary, grey_share=math.nextafter(NAMING.grey_share_max, UP))
    assert decide(_evidence(style=_style(dx=TOL.rule_offset_px, **grey)), TOL).verdict == "fail"


def test_warp_decides_at_scale_px_and_binary_lines_half_a_pixel_more():
    assert decide(_evidence(style=_style(warp=TOL.scale_px)), TOL).verdict == "pass"
    assert (
        decide(_evidence(style=_style(warp=math.nextafter(TOL.scale_px, UP))), TOL)
        .reasons[0]
        .startswith("line centres moved by up to")
    )
    binary = dict(style="wide", grey_share=0.0, width=3.0)
    bound = TOL.scale_px + NAMING.binary_warp_px
    assert decide(_evidence(style=_style(warp=bound, **binary)), TOL).verdict == "pass"
    assert decide(_evidence(style=_style(warp=math.nextafter(bound, UP), **binary)), TOL).verdict == "fail"


def test_free_ends_decide_at_end_px_and_half_the_width_past_it():
    assert decide(_evidence(style=_style(end=-TOL.end_px)), TOL).verdict == "pass"
    assert (
        decide(_evidence(style=_style(end=math.nextafter(-TOL.end_px, -UP))), TOL)
        .reasons[0]
        .startswith("line ends -0.50 px")
    )
    far = 3.0 / 2 + TOL.end_px  # a 3-px line's cap reaches half its width
    assert decide(_evidence(style=_style(end=far, width=3.0, style="wide")), TOL).verdict == "pass"
    assert decide(_evidence(style=_style(end=math.nextafter(far, UP), width=3.0, style="wide")), TOL).verdict == "fail"
    # fewer free ends than NAMING.min_ends: their median does not decide
    short = math.nextafter(-TOL.end_px, -UP)
    assert decide(_evidence(style=_style(end=short, ends=NAMING.min_ends - 1)), TOL).verdict == "pass"
    assert decide(_evidence(style=_style(end=short, ends=NAMING.min_ends)), TOL).verdict == "fail"


def test_unplaced_lines_are_not_held_to_their_centres():
    # the registration found the lines mirrored (not placed): their centroid offset says nothing
    assert decide(_evidence(style=_style(dx=5.0, placed=False)), TOL).verdict == "pass"


def _aliased(rounded_f1, line_rule, **geo):
    rounded = {"pixel_f1_0px": rounded_f1, "lines": LINES_OK}
    return _style(
        style="aliased",
        grey_share=0.0,
        line_rule=line_rule,
        rounded=rounded,
        raster=dict(RASTER_NONE, differing=8, off_by_one_at_ends=8),
        **geo,
    )


@pytest.mark.parametrize("line_rule", ["any", "gl"])
def test_the_rounded_ends_rule_is_read_from_rule_f1_0px(line_rule):
    # aliased pixels 0.9 against GL's rule (< min_f1_0px), rule_f1_0px against the rounded ends': a correct
    # drawing by that rule (passes under any; named raster_rule under gl); just under it: GL's limit decides
    ok = _evidence(f1_0=0.9, style=_aliased(TOL.rule_f1_0px, line_rule))
    v = decide(ok, TOL)
    assert v.style.rule_read == "rounded" and v.style.rounded_case == "correct" and not v.style.pixel_rule
    if line_rule == "any":
        assert v.verdict == "pass" and _names(ok) == []
    else:
        assert v.verdict == "fail" and v.reasons[0].startswith("the pixels are a correct drawing by another rule")
        assert _names(ok) == ["raster_rule"]
    under = _evidence(f1_0=0.9, style=_aliased(math.nextafter(TOL.rule_f1_0px, -UP), line_rule))
    v = decide(under, TOL)
    assert v.verdict == "fail" and v.style.rule_read == "gl" and v.style.pixel_rule
    assert v.reasons[0] == f"pixel F1@0px 0.9000 < {TOL.min_f1_0px}"


def test_a_biased_rounded_drawing_is_judged_by_that_rule_from_rule_f1_0px():
    # --line-rule any: pixels the rounded ends' (F1@0px rule_f1_0px against it) but for a dropped end pixel
    # (an edge 4 pixels short): that rule's limits and its line fault, not GL's; just under rule_f1_0px GL's
    # limits decide, and lines where the oracle's are, off by one pixel only, are raster_rule
    worst = {"edge": 1, "diff": -(TOL.max_edge_count_diff + 1), "frame": 2}
    short = dict(LINES_OK, edge_count_max_diff=TOL.max_edge_count_diff + 1, edge_count_worst=worst)
    end_fault = (Fault("line_end_bias", {"end": "last", "pixels_per_line": -1.0}),)

    def ev(rounded_f1):
        s = dataclasses.replace(
            _aliased(rounded_f1, "any"), rounded={"pixel_f1_0px": rounded_f1, "lines": short}, rounded_faults=end_fault
        )
        return _evidence(f1_0=0.9, style=s)

    v = decide(ev(TOL.rule_f1_0px), TOL)
    assert v.style.rounded_case == "biased" and v.reasons == (
        "edge 1 has -4 pixels against the oracle's count (allowed +-3; frame 2) (the rounded-ends rule)",
    )
    assert _names(ev(TOL.rule_f1_0px)) == ["line_end_bias"]
    below = ev(math.nextafter(TOL.rule_f1_0px, -UP))
    assert decide(below, TOL).style.rounded_case is None and _names(below) == ["raster_rule"]


def test_the_rounded_rule_is_read_only_where_the_diagnosis_names_no_camera_fault():
    # a rule fault named (pixel_offset: a rule's snapped ends move lines) leaves the read; a camera fault does not
    def ev(fault):
        return _evidence(f1_0=0.9, style=_aliased(1.0, "any"), image_faults=(fault,))

    rule = ev(Fault("pixel_offset", {"dx": 0.3, "dy": 0.0}))
    assert decide(rule, TOL).verdict == "pass" and _names(rule) == []
    camera = ev(Fault("fov_mismatch", {"implied_fov_deg": 40.0}))
    assert decide(camera, TOL).style.rounded_case is None and _names(camera) == ["fov_mismatch"]


def test_pixels_that_pass_gl_are_read_as_the_rule_that_fits_them_more_closely():
    # GL's limits met (F1@0px at its floor or more): the rule read is the rounded ends' only where its F1@0px
    # is higher than GL's, never at a tie
    def read(f1_gl, f1_rounded):
        return decide(_evidence(f1_0=f1_gl, style=_aliased(f1_rounded, "any")), TOL).style.rule_read

    assert read(TOL.min_f1_0px, 1.0) == "rounded"
    assert read(1.0, 1.0) == "gl"
    assert read(0.99, 0.99) == "gl"


def test_raster_rule_records_by_hand():
    # 8 of the oracle's 400 pixels off by one at the ends; the centres 0.1 px off in x (placed, not moved)
    def record(rounded_f1):
        ev = _evidence(f1_0=0.9, style=_aliased(rounded_f1, "gl", dx=0.1))
        (f,) = name_faults(ev, decide(ev, TOL), TOL)
        return f.as_dict()

    shares = {"share_off_by_one_across": 0.0, "share_off_by_one_at_ends": 0.02, "share_farther": 0.0}
    rounded = record(1.0)  # a correct drawing by the rounded ends, under gl
    assert {k: v for k, v in rounded.items() if k != "note"} == {
        "name": "raster_rule",
        **shares,
        "confidence": 1.0,
        "offset_px": [0.1, 0.0],
        "residual_px": None,
        "rule": "rounded",
    }
    other = record(math.nextafter(TOL.rule_f1_0px, -UP))  # not the rounded ends': another rule, GL-placed
    assert {k: v for k, v in other.items() if k != "note"} == {
        "name": "raster_rule",
        **shares,
        "confidence": 1.0,
        "offset_px": [0.1, 0.0],
        "residual_px": None,
    }
    assert other["note"].startswith("the lines are where the oracle's are (centres within 0.10 px)")


def test_a_biased_rounded_read_needs_the_rounded_rule_to_fit_more_closely_than_gls():
    # GL's per-edge counts fail, the rounded ends' too, both F1@0px 0.99: a tie is no rounded read (GL decides)
    worst = {"edge": 1, "diff": -(TOL.max_edge_count_diff + 1), "frame": 2}
    short = dict(LINES_OK, edge_count_max_diff=TOL.max_edge_count_diff + 1, edge_count_worst=worst)

    def case(rounded_f1):
        s = dataclasses.replace(_aliased(rounded_f1, "any"), rounded={"pixel_f1_0px": rounded_f1, "lines": short})
        return decide(_evidence(f1_0=0.99, style=s, lines=short), TOL).style

    assert case(0.99).rounded_case is None and case(0.99).pixel_rule
    assert case(math.nextafter(0.99, UP)).rounded_case == "biased"


def test_a_case_that_compared_no_pixel_is_vacuous():
    ev = _evidence(compared={"frames": 2, "vertices": 0, "pixels": 0})
    assert decide(ev, TOL) == Verdict(
        "vacuous", ("vacuous: neither side drew a pixel in any of the 2 checked frames: nothing compared",)
    )


def test_the_vertex_bound_decides_on_the_projector_path():
    def ev(err):
        return CaseEvidence(
            level="vertices",
            compared={"frames": 1, "vertices": 8, "pixels": None},
            frames_checked=1,
            vertices={"max_vertex_error_px": err, "vertex_bound_px": 1e-6, "worst_vertex": {"frame": 1, "vertex": 2}},
        )

    assert decide(ev(1e-6), TOL).verdict == "pass"
    assert decide(ev(math.nextafter(1e-6, UP)), TOL).reasons == (
        "max vertex error 1e-06 px > 1e-06 px (float64 bound; frame 1, vertex 2)",
    )


def test_past_the_oracles_precision_limit_the_pixels_are_set_aside():
    # Tolerances.oracle_limit_px: at the limit the pixels are judged; just past it they are set aside, the
    # case judged on its vertices alone (vacuous here: they agree), the pixel-read line fault goes and the
    # reasons the pixels gave stay on record. The limit is 2^-9 px (docs/tolerances.md: the float32 share of
    # the tie zone's TIE_END_PX)
    ORACLE_LIMIT_PX = 2.0**-9
    assert TOL.oracle_limit_px == ORACLE_LIMIT_PX

    def ev(bound):
        return CaseEvidence(
            level="pixels",
            compared={"frames": 1, "vertices": 8, "pixels": 300},
            frames_checked=1,
            pixels={"pixel_f1_0px": 0.5, "pixel_f1_1px": 1.0, "worst_pixel_frame": 1},
            vertices={"max_vertex_error_px": 0.0, "vertex_bound_px": 1e-6, "worst_vertex": {"frame": 1, "vertex": 0}},
            line_faults=(Fault("line_pixel_bias", {"candidate_only": 9, "oracle_only": 0}),),
            oracle_bound_px=bound,
        )

    at = decide(ev(ORACLE_LIMIT_PX), TOL)
    assert at.verdict == "fail" and at.set_aside is None and _names(ev(ORACLE_LIMIT_PX)) == ["line_pixel_bias"]
    past = decide(ev(math.nextafter(ORACLE_LIMIT_PX, UP)), TOL)
    assert past.verdict == "vacuous" and past.reasons[0].startswith("oracle_precision: the pyrender oracle's")
    assert past.set_aside == at.reasons and _names(ev(math.nextafter(ORACLE_LIMIT_PX, UP))) == []
    # the limit is the record's: moved just past the bound, the same case's pixels are judged again
    moved = dataclasses.replace(TOL, oracle_limit_px=math.nextafter(ORACLE_LIMIT_PX, UP))
    assert decide(ev(math.nextafter(ORACLE_LIMIT_PX, UP)), moved) == at
    # a vertex failure still fails the case, after the oracle_precision reason
    wrong = dataclasses.replace(
        ev(math.nextafter(ORACLE_LIMIT_PX, UP)),
        vertices={"max_vertex_error_px": 0.5, "vertex_bound_px": 1e-6, "worst_vertex": {"frame": 1, "vertex": 0}},
    )
    v = decide(wrong, TOL)
    assert v.verdict == "fail" and v.reasons[1:] == (
        "max vertex error 0.5 px > 1e-06 px (float64 bound; frame 1, vertex 0)",
    )


# ---------------------------------------------------------------- name_faults: the precedence table


def test_the_diagnosis_wins_over_the_line_counts():
    ev = _evidence(
        f1_0=0.5,
        image_faults=(Fault("fov_mismatch", {"implied_fov_deg": 40.0}),),
        line_faults=(Fault("line_end_bias", {"end": "last"}),),
    )
    assert _names(ev) == ["fov_mismatch"]
    assert _names(dataclasses.replace(ev, image_faults=())) == ["line_end_bias"]


def test_the_line_centres_win_over_the_registrations_offset():
    # antialiased lines moved: the registration's pixel_offset gives way to the centres' own
    moved = math.nextafter(TOL.offset_px + 0.5 / 4, UP)
    ev = _evidence(style=_style(dx=moved), image_faults=(Fault("pixel_offset", {"dx": 0.4, "dy": 0.0}),))
    (f,) = name_faults(ev, decide(ev, TOL), TOL)
    assert f.as_dict() == {
        "name": "pixel_offset",
        "dx": moved,
        "dy": 0.0,
        "uncertainty_px": 0.0,
        "confidence": 1.0,
        "residual_px": None,
        "measured_by": "line centroids",
    }
    # a warp beyond its bound keeps the registration's scale fault beside the measure
    warped = _evidence(style=_style(warp=2.0), image_faults=(Fault("fov_mismatch", {"implied_fov_deg": 40.0}),))
    assert _names(warped) == ["fov_mismatch"]
    assert _names(dataclasses.replace(warped, style=_style(warp=0.0))) == []


def test_ends_past_their_bound_are_line_end_bias_with_their_median():
    short = math.nextafter(-TOL.end_px, -UP)
    ev = _evidence(style=_style(end=short))
    assert decide(ev, TOL).reasons == (
        f"line ends {short:+.2f} px from the segments' ends: expected "
        f"{-TOL.end_px} to {0.5 + TOL.end_px:.2f} (antialiased lines)",
    )
    (f,) = name_faults(ev, decide(ev, TOL), TOL)
    assert f.as_dict() == {
        "name": "line_end_bias",
        "end_px": short,
        "ends_measured": 6,
        "confidence": 1.0,
        "residual_px": None,
        "measured_by": "line ends",
        "note": "the lines stop 0.50 px before their ends (median of 6 free ends; a cap may add half the width)",
    }


def test_ends_that_run_on_are_said_to_run_on():
    # a 0.5-px antialiased line whose ends run 0.8 px on (past 0.25 + end_px): named, and said to run on
    ev = _evidence(style=_style(end=0.8, width=0.5))
    (f,) = name_faults(ev, decide(ev, TOL), TOL)
    assert f.name == "line_end_bias" and f.params["note"].startswith("the lines run on 0.80 px past their ends")


def test_the_biased_rounded_rules_line_fault_replaces_only_count_faults():
    # --line-rule any, pixels the rounded ends' but biased (test above): its line fault replaces GL's count
    # faults and an unexplained; a pixel_offset the diagnosis named stays, and with no rounded line fault GL's
    # count fault stays
    worst = {"edge": 1, "diff": -(TOL.max_edge_count_diff + 1), "frame": 2}
    short = dict(LINES_OK, edge_count_max_diff=TOL.max_edge_count_diff + 1, edge_count_worst=worst)
    rounded_end = (Fault("line_end_bias", {"end": "last", "pixels_per_line": -1.0}),)

    def names(diagnosed, rounded_faults):
        s = dataclasses.replace(
            _aliased(TOL.rule_f1_0px, "any"),
            rounded={"pixel_f1_0px": TOL.rule_f1_0px, "lines": short},
            rounded_faults=rounded_faults,
        )
        return _names(_evidence(f1_0=0.9, style=s, line_faults=diagnosed))

    gl_bias = (Fault("line_pixel_bias", {"candidate_only": 0, "oracle_only": 30}),)
    assert names(gl_bias, rounded_end) == ["line_end_bias"]
    assert names(gl_bias, ()) == ["line_pixel_bias"]
    offset = (Fault("pixel_offset", {"dx": 0.1, "dy": 0.0}),)
    assert names(offset, rounded_end) == ["pixel_offset"]


def test_gl_limits_and_the_radius_both_missed_are_no_rule_read():
    # F1 at the radius missed too: the pixels are not read as the rounded ends' (only GL's limits may fail
    # for that), and GL's F1@0px still decides
    ev = _evidence(f1_0=0.9, f1_1=math.nextafter(TOL.min_f1_1px, -UP), style=_aliased(1.0, "any"))
    v = decide(ev, TOL)
    assert v.style.rounded_case is None and v.style.pixel_rule
    assert [r.split(" <")[0] for r in v.reasons] == ["pixel F1@1px 0.9990", "pixel F1@0px 0.9000"]


def test_no_pixel_fields_no_style_judgement_and_no_names_from_it():
    ev = CaseEvidence(level="frames", compared=COMPARED, frames_checked=2, style=_style(dx=5.0))
    v = decide(ev, TOL)
    assert v == Verdict("pass", ()) and name_faults(ev, v, TOL) == ()


def test_raster_shares_by_hand():
    counts = {"oracle_pixels": 200, "differing": 10, "off_by_one_across": 4, "off_by_one_at_ends": 4, "farther": 2}
    s = _style(style="aliased", grey_share=0.0, raster=counts)
    assert s.raster_shares == {"share_off_by_one_across": 0.02, "share_off_by_one_at_ends": 0.02, "share_farther": 0.01}
    assert _style(style="aliased", grey_share=0.0, raster=dict(counts, oracle_pixels=0)).raster_shares == {
        "share_off_by_one_across": 4.0,
        "share_off_by_one_at_ends": 4.0,
        "share_farther": 2.0,
    }
    assert _style(style="aliased", grey_share=0.0, raster=dict(counts, differing=0)).raster_shares == {}
    assert _style(style="antialiased", raster=counts).raster_shares == {}


def test_the_offset_of_unplaced_lines_is_none_of_theirs():
    assert _style(dx=0.3).offset_px == (0.3, 0.0)
    assert _style(dx=0.3, placed=False).offset_px == (0.0, 0.0)
    # a correct drawing by the rounded ends under gl: raster_rule carries the placed offset, else (0, 0)
    s = dataclasses.replace(_aliased(1.0, "gl"), placed=False)
    (f,) = name_faults(_evidence(f1_0=0.9, style=s), decide(_evidence(f1_0=0.9, style=s), TOL), TOL)
    assert (f.name, f.params["offset_px"], f.params["rule"]) == ("raster_rule", [0.0, 0.0], "rounded")


def test_dim_lines_win_over_the_images():
    ev = _evidence(f1_0=0.0, f1_1=0.0, style=_style(), image_faults=(Fault("depth_flip"),), drew_pixels=False)
    for lvl in (1, NAMING.drawn_level - 1):  # the dimmest line there is, and the brightest under 128
        dim = dataclasses.replace(ev, style=dataclasses.replace(ev.style, read={**ev.style.read, "level": lvl}))
        (f,) = name_faults(dim, decide(dim, TOL), TOL)
        assert f.name == "unexplained" and f.params["line_level"] == lvl
    # some frame drew a pixel by the rule: the lines are not all too dim, the images' name stands
    drew = dataclasses.replace(dim, drew_pixels=True)
    assert _names(drew) == ["depth_flip"]
    at_level = dataclasses.replace(ev.style, read={**ev.style.read, "level": NAMING.drawn_level})
    assert _names(dataclasses.replace(ev, style=at_level)) == ["depth_flip"]
    for nothing in (0, None):  # no line at all (level 0 or unread): the images' name
        dark = dataclasses.replace(ev.style, read={**ev.style.read, "level": nothing})
        assert _names(dataclasses.replace(ev, style=dark)) == ["depth_flip"]


def test_unexplained_only_when_failing_and_nothing_named():
    assert _names(_evidence(f1_0=0.5)) == ["unexplained"]
    assert _names(_evidence()) == []
    assert _names(_evidence(f1_0=0.5, error="candidate raised ValueError")) == []
    # a passing case whose image registration fitted nothing (the diagnosis's own unexplained: Pillow's
    # 2- and 3-px lines on 4 of the held-out cases) has nothing to explain: no name; a failing one keeps it
    unfit = (Fault("unexplained"),)
    assert _names(_evidence(image_faults=unfit)) == []
    assert _names(_evidence(f1_0=0.5, image_faults=unfit)) == ["unexplained"]


def test_visibility_rewrites_the_unexplained_where_the_images_name_nothing():
    ev = _evidence(f1_0=0.5, visibility=Visibility(40, 0, 2, 2))
    (f,) = name_faults(ev, decide(ev, TOL), TOL)
    assert (f.name, f.params["candidate_only_px"], f.params["oracle_only_px"]) == ("unexplained", 40, 0)
    # a line_pixel_bias made of whole pieces of line (40 far pixels of 60 decided, >= visibility_share) too
    bias = Fault("line_pixel_bias", {"candidate_only": 60, "oracle_only": 0})
    far = dataclasses.replace(ev, line_faults=(bias,))
    assert [(f.name, f.params.get("line_fault")) for f in name_faults(far, decide(far, TOL), TOL)] == [
        ("unexplained", "line_pixel_bias")
    ]
    near = dataclasses.replace(far, visibility=Visibility(29, 0, 2, 2))  # 29 < 0.5 x 60: a line width
    assert _names(near) == ["line_pixel_bias"]


def test_the_table_lists_every_step_once_in_order():
    steps = [r.step for r in PRECEDENCE]
    assert steps == [
        "diagnosis",
        "line_centres",
        "line_rule",
        "job_read",
        "dim_lines",
        "surfaces",
        "unexplained",
        "visibility",
        "oracle_precision",
    ]
    assert all(r.why for r in PRECEDENCE)


def test_depth_maps_name_their_faults_only_where_their_limits_are_missed():
    # a depth-only case (no wireframe): its maps' error 3.2 x the bound > max_depth_error_ratio (1) fails it
    # and adds what their values named (depth_scale); at 0.5 x the bound the same named fault is not a name
    # (the limits decide, the naming only explains), and the case passes
    def depth_map(ratio):
        return {
            "max_error_ratio": ratio,
            "max_error": 0.1 * ratio,
            "worst_pixel": [3, 4],
            "worst_frame": 1,
            "reference_px": 500,
            "compared_px": 480,
            "blank_frames": [],
            "holes_px": 0,
            "extra_px": 0,
            "holes_worst_frame": None,
            "extra_worst_frame": None,
        }

    scale = Fault("depth_scale", {"k": 1000.0}, "depth")
    ev = CaseEvidence(
        level="frames",
        compared={"frames": 1, "vertices": 0, "pixels": 500},
        frames_checked=1,
        depth_map=depth_map(3.2),
        depth_faults=(scale,),
    )
    verdict = decide(ev, TOL)
    assert verdict.verdict == "fail" and [f.name for f in name_faults(ev, verdict, TOL)] == ["depth_scale"]
    ok = dataclasses.replace(ev, depth_map=depth_map(0.5))
    assert decide(ok, TOL).verdict == "pass" and name_faults(ok, decide(ok, TOL), TOL) == ()


def test_a_mistake_read_from_the_depth_maps_and_the_silhouettes_is_named_once():
    # rows not flipped: the depth maps' values and the filled frames' silhouettes both name mirror_vertical
    # (held-out: moderngl and Open3D jobs read "mirror_vertical; mirror_vertical"); one name, the depth maps'
    # (read first), beside a name only the silhouettes give
    depth = {
        "max_error_ratio": 40.0,
        "max_error": 4.0,
        "worst_pixel": [3, 4],
        "worst_frame": 1,
        "reference_px": 500,
        "compared_px": 480,
        "blank_frames": [],
        "holes_px": 0,
        "extra_px": 0,
        "holes_worst_frame": None,
        "extra_worst_frame": None,
    }
    filled = {
        "blank_frames": [],
        "longest_run_px": 90,
        "run_at": [10, 12],
        "run_frame": 1,
        "holes_px": 400,
        "extra_px": 400,
        "min_iou": 0.2,
        "iou_worst_frame": 1,
    }
    from_depth = Fault("mirror_vertical", {"source_of": "depth"})
    ev = CaseEvidence(
        level="frames",
        compared={"frames": 1, "vertices": 0, "pixels": 500},
        frames_checked=1,
        depth_map=depth,
        filled=filled,
        depth_faults=(from_depth,),
        filled_faults=(Fault("mirror_vertical", {"source_of": "silhouettes"}), Fault("pixel_offset", {"dx": 0.5})),
    )
    named = name_faults(ev, decide(ev, TOL), TOL)
    assert [f.name for f in named] == ["mirror_vertical", "pixel_offset"] and named[0] is from_depth
