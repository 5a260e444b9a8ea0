"""What to check on a renderer's own frames: the drawing library's own choices (the catalogue's frames_hint, oracles.faults).

A correct matplotlib renderer that keeps its default snapping, or Pillow given float coordinates, reads as
``pixel_offset`` (0.46 px and -0.5 px measured, docs/frames.md); a renderer of another aliased rule can read
as ``line_end_bias``. On the frames path the hint names those choices; a projector's lines are drawn by the
harness, which has none of them, so its hints stay the generic ones.
"""

from __future__ import annotations

from wirecheck.oracles.faults import CATALOGUE
from wirecheck.oracles.reports.compared import hint_lines
from wirecheck.oracles.reports.fault_text import hints as fault_hints
from wirecheck.oracles.reports.junit import failure_text

FAULTS = [{"name": "pixel_offset", "dx": 0.46, "dy": 0.46}, {"name": "line_end_bias"}]


def test_frames_hints_name_the_drawing_librarys_choices():
    hints = dict(fault_hints(FAULTS, frames=True))
    assert hints["pixel_offset"].startswith(CATALOGUE["pixel_offset"].hint) and "snap=False" in hints["pixel_offset"]
    assert "round them" in hints["pixel_offset"]
    assert hints["line_end_bias"].startswith(CATALOGUE["line_end_bias"].hint)
    assert "--line-rule geometry" in hints["line_end_bias"]


def test_a_projectors_hints_stay_generic():
    assert dict(fault_hints(FAULTS)) == {n: CATALOGUE[n].hint for n in ("pixel_offset", "line_end_bias")}


def test_the_console_and_junit_follow_the_reports_level():
    case = {"scene": "cube", "camera": "on_axis", "verdict": "fail", "faults": FAULTS[:1], "reasons": ["r"]}
    frames = hint_lines({"level": "frames"}, [case])
    pixels = hint_lines({"level": "pixels"}, [case])
    assert len(frames) == len(pixels) == 1 and "snap=False" in frames[0] and "snap=False" not in pixels[0]
    assert "snap=False" in failure_text(case, frames=True) and "snap=False" not in failure_text(case)


def test_the_verdict_line_claims_f1_at_0px_only_where_it_judged():
    from wirecheck.oracles.reports.console_run import f1_0px_clause

    def case(style, rule="gl"):
        return {"line_style": {"style": style, "line_rule": rule}}

    assert f1_0px_clause([case("aliased")] * 3, 0.98) == "F1@0px >= 0.98"
    assert f1_0px_clause([case("antialiased"), case("wide")], 0.98) == (
        "F1@0px reported, not judged: no case is held to GL's pixel rule"
    )
    assert f1_0px_clause([case("aliased", "geometry")], 0.98).startswith("F1@0px reported, not judged")
    assert f1_0px_clause([case("aliased"), case("antialiased")], 0.98) == (
        "F1@0px >= 0.98 in the 1 case held to GL's pixel rule"
    )
    # --line-rule any: a case read as the rounded ends' is held to that rule's F1@0px, and the line says so
    rounded = {"line_style": {"style": "aliased", "line_rule": "any", "rule_read": "rounded"}}
    assert f1_0px_clause([rounded, case("aliased", "any")], 0.98) == (
        "F1@0px >= 0.98 in the 2 cases held to a pixel rule (GL's, or the rounded ends' in 1)"
    )


def test_a_faults_list_of_floats_is_written_as_its_numbers():
    """A per-axis value (``scale=[sx, sy]``) is written as each float is, not as Python's repr of the list."""
    from wirecheck.oracles.reports.fault_text import full_text

    text = full_text([{"name": "unexplained", "scale": [0.622011633928914, 0.8000000000000003]}])
    # four significant digits, trailing zeros dropped (oracles.reports.fmt.distinct): 0.6220 -> 0.622, 0.8000 -> 0.8
    assert text == "unexplained(scale=[0.622, 0.8])", text
