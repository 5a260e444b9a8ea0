"""oracles.judge.wire_frames.WireFrames: one measurement of a case's wireframes for every frame source.

Frames are built by slicing (a column of pixels, a segment along it) and every expected number is
worked out by hand in the comments; the tie is tests/test_tie_ends.py's (an end within GL's
sub-pixel precision of its last pixel's diamond exit).
"""

import numpy as np
import pytest
from wirecheck.oracles.judge import metrics
from wirecheck.oracles.judge.frame_pixels import FramePixels
from wirecheck.oracles.judge.wire_frames import COUNT_FRAME_KEYS, SCORE_FRAME_KEYS, KeptImage, WireFrames

H, W = 10, 8
ZONE = 2 * 2.0**-8  # tests/test_tie_ends.py: within this of the diamond's exit, an end is a sub-pixel tie


def column(last: int, x: int = 3) -> np.ndarray:
    """Rows 0..``last`` of column ``x`` drawn."""
    img = np.zeros((H, W), bool)
    img[: last + 1, x] = True
    return img


def segment(y_end: float, x: float = 3.2):
    """The segment x = 3.2 from y = 0 to ``y_end``: ``(seg0, seg1)``, (1, 2) each."""
    return np.array([[x, 0.0]]), np.array([[x, y_end]])


def add(wire: WireFrames, k: int, cand: np.ndarray, oracle: np.ndarray, y_end: float) -> dict:
    rec = {"frame": k}
    wire.add(k, FramePixels(cand, oracle), *segment(y_end), None, rec)
    return rec


@pytest.mark.parametrize("resolve, f1_0px", [(True, 1.0), (False, 10 / 11)])
def test_a_tie_is_resolved_only_where_asked(resolve, f1_0px):
    # the oracle draws rows 0..5, the candidate 0..4; the end 0.9 zone past row 5's diamond exit: a tie.
    # Resolved, the candidate is given the oracle's row 5: F1@0px 1. As drawn: P = 1, R = 5/6, F1 = 10/11.
    wire = WireFrames(SCORE_FRAME_KEYS, resolve_ties=resolve)
    rec = add(wire, 1, column(4), column(5), 5.3 + 0.9 * ZONE)
    wire.flush()
    assert rec["f1_0px"] == pytest.approx(f1_0px, abs=1e-15)
    assert rec["recall_0px"] == pytest.approx(1.0 if resolve else 5 / 6, abs=1e-15)
    assert wire.pixel_fields()["pixel_f1_0px"] == pytest.approx(f1_0px, abs=1e-15)
    assert rec["subpixel_ties"] == [0, 1]  # counted a tie either way (the balance leaves it out)


def test_a_decided_end_is_the_same_either_way():
    # the end 0.1 px past the exit: decided, the candidate lost row 5 (F1 10/11 whatever resolve_ties says)
    for resolve in (True, False):
        wire = WireFrames(SCORE_FRAME_KEYS, resolve_ties=resolve)
        rec = add(wire, 1, column(4), column(5), 5.4)
        wire.flush()
        assert rec["f1_0px"] == pytest.approx(10 / 11, abs=1e-15)


def test_frame_fields_scores_drawn_pixels_and_the_worst_frame():
    wire = WireFrames(COUNT_FRAME_KEYS, resolve_ties=False)
    # frame 1: equal columns of 6; frame 3: the candidate draws rows 0..2 of 6 (P 1, R 1/2, F1@0 2/3);
    # frame 5: the candidate one column over (0 px: nothing shared; 1 px: every pixel within 1 px)
    recs = [
        add(wire, 1, column(5), column(5), 5.4),
        add(wire, 3, column(2), column(5), 5.4),
        add(wire, 5, column(5, x=4), column(5), 5.4),
    ]
    wire.flush()
    assert [set(r) for r in recs] == [{"frame", *COUNT_FRAME_KEYS, *metrics.LINE_FRAME_KEYS}] * 3
    assert [(r["candidate_pixels"], r["oracle_pixels"]) for r in recs] == [(6, 6), (3, 6), (6, 6)]
    assert recs[1]["f1_0px"] == pytest.approx(2 / 3, abs=1e-15)
    assert (recs[2]["f1_0px"], recs[2]["f1_1px"]) == (0.0, 1.0)
    # drawn by either side: 6 + 6 + (6 + 6 - 0 shared) = 24
    assert wire.drawn_px == 24
    # the worst is the lowest (F1@1px, F1@0px): frame 3's F1@1px is 0.8 (P 1; R 4/6: rows 0..3 within 1 px)
    assert wire.worst_frame == 3
    assert wire.pixel["f1_1px"][1] == pytest.approx(0.8, abs=1e-15)
    images = wire.worst_images()
    assert images["frame"] == 3
    assert np.array_equal(images["candidate"], column(2)) and np.array_equal(images["oracle"], column(5))
    assert images["candidate"].dtype == bool
    fields = wire.pixel_fields()
    assert fields["pixel_f1_0px"] == 0.0 and fields["worst_pixel_frame"] == 3
    assert fields["pixel_f1_0px_mean"] == pytest.approx((1 + 2 / 3 + 0) / 3, abs=1e-15)


def test_the_first_of_equal_frames_is_the_worst_and_kept_images_round_trip():
    kept = []
    wire = WireFrames(SCORE_FRAME_KEYS, kept=kept)
    add(wire, 2, column(2), column(5), 5.4)
    add(wire, 4, column(2), column(5), 5.4)  # the same scores: frame 2 stays the worst
    assert wire.worst_frame == 2
    assert [k for k, _, _ in kept] == [2, 4]
    assert all(np.array_equal(c.image(), column(2)) and np.array_equal(o.image(), column(5)) for _, c, o in kept)


def test_nothing_measured_before_a_frame():
    wire = WireFrames()
    assert not wire.measured and wire.worst_frame is None and wire.worst_images() is None
    assert wire.rounded() is None


def test_kept_image_packed_or_flat_gives_the_image_back():
    img = column(4)
    assert np.array_equal(KeptImage.of(img).image(), img)
    assert np.array_equal(KeptImage.of(img, np.flatnonzero(img)).image(), img)


def test_a_tie_replaces_its_own_frames_scores_only():
    # frame 1 decided (the end 0.1 px past the exit: 10/11), frame 2 a tie (resolved: 1): each keeps its own
    wire = WireFrames(SCORE_FRAME_KEYS, resolve_ties=True)
    add(wire, 1, column(4), column(5), 5.4)
    add(wire, 2, column(4), column(5), 5.3 + 0.9 * ZONE)
    wire.flush()
    assert wire.pixel["f1_0px"] == pytest.approx([10 / 11, 1.0], abs=1e-15)


def test_the_rounded_ends_rule_is_scored_where_asked():
    # the segment x = 3.2 from y = 0.2 to 5.2: ends rounded to (3, 0) and (3, 5), both drawn: rows 0..5
    # (no tie: neither end nor the line's x is near a half pixel). A drawing of rows 0..5 is that rule's
    # (F1 1); rows 0..4 lose its end (P 1, R 5/6: F1 10/11). The case's is the worst frame's.
    segs = np.array([[[3.2, 0.2], [3.2, 5.2]]])
    seg0, seg1 = segs[:, 0], segs[:, 1]
    wire = WireFrames(COUNT_FRAME_KEYS, resolve_ties=False, rounded_tie_px=2.0**-5)
    wire.add(1, FramePixels(column(5), column(4)), seg0, seg1, segs, {"frame": 1})
    assert wire.rounded()["pixel_f1_0px"] == 1.0
    wire.add(2, FramePixels(column(4), column(4)), seg0, seg1, segs, {"frame": 2})
    rounded = wire.rounded()
    assert rounded["pixel_f1_0px"] == pytest.approx(10 / 11, abs=1e-15)
    # its lines: frame 2's missing end pixel is the one pixel only the rule draws
    assert rounded["lines"]["oracle_only"] == 1 and rounded["lines"]["candidate_only"] == 0
    assert WireFrames().rounded() is None  # not asked: nothing scored


class Style:
    """A stand-in for a renderer's line style: records the frames it is asked to count."""

    def __init__(self):
        self.counted = []

    def count_rule(self, fp, segs):
        self.counted.append((fp.shape, segs))


def test_a_style_counts_each_frame_and_keeps_its_wider_radii():
    style = Style()
    segs = np.array([[[3.2, 0.0], [3.2, 5.4]]])
    wire = WireFrames(COUNT_FRAME_KEYS, resolve_ties=False, style=style)
    wire.add(1, FramePixels(column(5), column(5)), *segment(5.4), segs, {"frame": 1})
    wire.add(2, FramePixels(column(5, x=6), column(5)), *segment(5.4), segs, {"frame": 2})
    assert [shape for shape, _ in style.counted] == [(H, W), (H, W)] and style.counted[0][1] is segs
    # frame 1 all within 1 px: every wider radius's F1 is 1; frame 2 three columns over: F1 0 within 2 px,
    # 1 from 3 px on
    assert len(wire.radius) == 2 and set(wire.radius[0].values()) == {1.0}
    assert wire.radius[1] and wire.radius[1] == {r: (1.0 if r >= 3 else 0.0) for r in wire.radius[1]}
    assert 2 in wire.radius[1]  # the first radius past F1@1px
    assert WireFrames().radius == []
