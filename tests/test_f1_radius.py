"""F1 at the radius of the lines' width (oracles.judge.f1_radius): what it lets pass, and what it cannot hide.

Lines read wide or antialiased are held to F1 at ``1 + ceil((n - 1) / 2)`` px
(``n``: the measured width rounded, the pixels across); aliased 1-px lines to
F1@1px. The wider radius must not pass a missing line or a line moved by a
pixel: 3-px renderings of core's geometry (tests/test_line_style.py's
``_band``) with one edge left out, or shifted by 1 px, still fail.
"""

from __future__ import annotations

import numpy as np
import pytest
from test_line_style import _fill, _judge, draw_wide, job_dir  # noqa: F401 - job_dir: the module's fixture
from wirecheck.oracles.judge import f1_radius
from wirecheck.oracles.judge.decide import decide
from wirecheck.oracles.judge.evidence import CaseEvidence, Radius
from wirecheck.oracles.tolerances import Tolerances


@pytest.mark.parametrize(
    "style, width, radius",
    [
        # aliased: 1-px lines, F1@1px whatever the width measured (0.71-1 across a 1-px line)
        ("aliased", 1.0, 1),
        ("aliased", 0.71, 1),
        # antialiased 1-px lines: n = 1, no reach past a 1-px line: 1; a 1.5-px one rounds to n = 2
        ("antialiased", 1.0, 1),
        ("antialiased", 1.41, 1),
        ("antialiased", 1.5, 2),
        # wide: n = 2 -> 1 + ceil(1/2) = 2; n = 3 -> 1 + 1 = 2; n = 4 -> 1 + ceil(3/2) = 3; n = 5 -> 3
        ("wide", 1.83, 2),
        ("wide", 3.0, 2),
        ("wide", 3.24, 2),
        ("wide", 4.0, 3),
        ("wide", 5.0, 3),
        # past 5 px the radius stays MAX_RADIUS_PX = 3 (stricter for the line, never looser)
        ("wide", 9.0, 3),
    ],
)
def test_radius_from_the_width_read(style, width, radius):
    assert f1_radius.radius_px({"style": style, "width_px": width}) == radius


def _reasons(f1_1px: float, radius: int, f1_radius: float, frame: int = 4) -> list:
    ev = CaseEvidence(
        level="frames",
        compared={"frames": 2, "vertices": 0, "pixels": 100},
        frames_checked=2,
        pixels={"pixel_f1_0px": 1.0, "pixel_f1_1px": f1_1px, "worst_pixel_frame": 1},
        radius=Radius(radius, f1_radius, frame),
    )
    return list(decide(ev, Tolerances()).reasons)


def test_the_f1_at_the_radius_alone_decides():
    # by hand: the gate's bound 0.999 applies to the F1 at the case's radius, not to F1@1px beside it
    assert _reasons(0.995, 2, 0.9995) == []
    assert _reasons(1.0, 2, 0.998) == ["pixel F1@2px 0.9980 < 0.999 (frame 4; lines read wider than 1 px)"]
    # an aliased case (radius 1): F1@1px itself, its worst frame, as before
    assert _reasons(0.998, 1, 0.998, frame=1) == ["pixel F1@1px 0.9980 < 0.999 (frame 1)"]


def test_radius_read_takes_the_worst_frame_at_the_radius():
    per_frame = [{2: 0.9991, 3: 1.0}, {2: 0.9993, 3: 1.0}]
    assert f1_radius.radius_read({"style": "wide", "width_px": 3.0}, per_frame, [1, 4], 0.99, 4) == Radius(2, 0.9991, 1)
    assert f1_radius.radius_read({"style": "aliased", "width_px": 1.0}, per_frame, [1, 4], 0.99, 4) == Radius(
        1, 0.99, 4
    )


def _without_longest(segs, w, h):
    """A correct 3-px drawing of every line but the longest (that edge left out of the frame)."""
    longest = int(np.argmax(np.hypot(*(segs[:, 1] - segs[:, 0]).T)))
    return draw_wide(np.delete(segs, longest, axis=0), w, h)


def test_a_missing_edge_of_wide_lines_fails(job_dir, tmp_path, capsys):  # noqa: F811
    rc, report = _judge(_fill(job_dir, tmp_path, _without_longest), tmp_path)
    assert rc == 1 and len(report["cases"]) == 4
    for c in report["cases"]:
        assert c["line_style"]["style"] == "wide" and c["f1_radius_px"] == 2
        # the edge's oracle pixels have no candidate pixel within 2 px but where it meets other lines:
        # recall falls by about its share of the oracle's pixels (a sixth to a ninth of the lines), far
        # under the gate's 0.999
        assert c["verdict"] == "fail" and c["pixel_f1_radius"] < 0.99
        assert any(r.startswith("pixel F1@2px") for r in c["reasons"]), c["reasons"]


@pytest.mark.parametrize("shift", [(1.0, 0.0), (0.0, -1.0)], ids=["right", "up"])
def test_wide_lines_moved_by_a_pixel_fail_as_pixel_offset(job_dir, tmp_path, capsys, shift):  # noqa: F811
    rc, report = _judge(_fill(job_dir, tmp_path, draw_wide, shift=shift), tmp_path)
    assert rc == 1 and len(report["cases"]) == 4
    for c in report["cases"]:
        assert c["verdict"] == "fail"
        f = next(f for f in c["faults"] if f["name"] == "pixel_offset")
        # drawn 1 px off: the centres measured within 0.05 px of it (as the half-pixel test's bound)
        assert (f["dx"], f["dy"]) == (pytest.approx(shift[0], abs=0.05), pytest.approx(shift[1], abs=0.05))
        assert any("line centres offset" in r for r in c["reasons"])


def test_the_style_note_says_the_radius():
    # report.md / stdout: a style whose cases were held to a wider radius says so (the widest of its cases);
    # at radius 1 the note is as before
    from wirecheck.oracles.judge.line_style import CANNOT_SHOW, summary_lines

    def case(width, radius):
        return {
            "line_style": {
                "style": "wide",
                "line_rule": "gl",
                "width_px": width,
                "judged_by": "the centres",
                "f1_radius_px": radius,
            }
        }

    assert summary_lines([case(1.83, 2), case(3.0, 2)]) == [
        "Line style read: wide (2 cases, 1.83-3.00 px wide, --line-rule gl): judged by the centres; "
        f"F1 at up to 2 px (the width); cannot show {CANNOT_SHOW['wide']}"
    ]
    assert "F1 at up to" not in summary_lines([case(1.0, 1)])[0]


def test_radius_takes_the_band_read_from_the_pixel_count():
    # binary lines read wide by their pixel count (1.5x the oracle's, band_px 2: oracles.judge.even_lean), with
    # a median width of 0.99 (Pillow's width 2 near an axis): n = 2 pixels across -> 1 + ceil(1/2) = 2, not 1
    assert f1_radius.radius_px({"style": "wide", "width_px": 0.99, "band_px": 2}) == 2
    assert f1_radius.radius_px({"style": "wide", "width_px": 0.99}) == 1
