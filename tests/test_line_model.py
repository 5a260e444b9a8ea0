"""oracles.line_model: one model of a drawn line, checked case by case and against independent drawers.

Expected images are built by slicing (hand-derived), or drawn by Pillow's ``ImageDraw.line`` and OpenCV's
``cv2.line`` (independent implementations of the rounded-ends rule), never by the model under test.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
from wirecheck.oracles import line_model as lm

sys.path.insert(0, str(Path(__file__).resolve().parent / "clients"))
import heldout_draw as hd  # noqa: E402


def _image(segs, shape, rule="rounded"):
    drawn, ties = lm.expected(np.asarray(segs, dtype=float).reshape(-1, 2, 2), shape, rule)
    return drawn, ties


def test_horizontal_line_draws_both_rounded_ends():
    # (1.2, 2.4) -> (5.6, 2.4): ends round to (1, 2) and (6, 2); 6 pixels, both ends drawn
    drawn, ties = _image([[[1.2, 2.4], [5.6, 2.4]]], (5, 8))
    expected = np.zeros((5, 8), bool)
    expected[2, 1:7] = True
    assert (drawn == expected).all() and not ties.any()


def test_vertical_and_reversed_lines():
    drawn, _ = _image([[[3.0, 6.4], [3.0, 0.6]]], (8, 5))  # rounds to (3, 6) -> (3, 1)
    expected = np.zeros((8, 5), bool)
    expected[1:7, 3] = True
    assert (drawn == expected).all()


def test_diagonal_line():
    drawn, ties = _image([[[0.0, 0.0], [3.0, 3.0]]], (4, 4))
    assert (drawn == np.eye(4, dtype=bool)).all() and not ties.any()


def test_minor_half_pixel_is_a_tie_both_sides():
    # (0, 0) -> (2, 1): at x = 1 the exact y is 0.5: (1, 0) and (1, 1) both ties; the ends are decided
    drawn, ties = _image([[[0.0, 0.0], [2.0, 1.0]]], (3, 4))
    assert drawn[0, 0] and drawn[1, 2] and drawn[:, 1].sum() == 1
    assert ties[0, 1] and ties[1, 1] and ties.sum() == 2
    # transposed, (0, 0) -> (1, 2): at y = 1 the exact x is 0.5, so (0, 1) on the image's first column and
    # (1, 1) are the ties
    drawn, ties = _image([[[0.0, 0.0], [1.0, 2.0]]], (4, 3))
    assert drawn[0, 0] and drawn[2, 1] and drawn[1, :].sum() == 1
    assert ties[1, 0] and ties[1, 1] and ties.sum() == 2


def test_end_on_a_half_pixel_is_a_tie():
    # (0, 0) -> (3.5, 0): rounds up to 4 (floor(v + 1/2)); 3 is as right within END_TIE_PX: pixel 4 a tie
    drawn, ties = _image([[[0.0, 0.0], [3.5, 0.0]]], (1, 6))
    assert drawn[0, :5].all() and not drawn[0, 5]
    assert ties[0, 4] and ties.sum() == 1
    # 1/16 px from the half (beyond 1/32): decided
    _, ties = _image([[[0.0, 0.0], [3.5 + 1 / 16, 0.0]]], (1, 6))
    assert not ties.any()


def _pillow(a, b, shape):
    from PIL import Image, ImageDraw

    im = Image.new("L", (shape[1], shape[0]), 0)
    ImageDraw.Draw(im).line([tuple(np.floor(a + 0.5)), tuple(np.floor(b + 0.5))], fill=255)
    return np.asarray(im) > 0


def _cv2(a, b, shape):
    import cv2

    img = np.zeros(shape, np.uint8)
    cv2.line(
        img, tuple(int(v) for v in np.floor(a + 0.5)), tuple(int(v) for v in np.floor(b + 0.5)), 255, 1, cv2.LINE_8
    )
    return img > 0


@pytest.mark.parametrize(
    "draw",
    [_pillow, _cv2, lambda a, b, s: hd.draw_bresenham(np.array([[a, b]]), s[1], s[0]) > 0],
    ids=["pillow", "cv2_line_8", "bresenham"],
)
def test_independent_rounded_drawers_agree_outside_the_ties(draw):
    # 300 random segments inside a 80x90 image: every pixel of Pillow's, OpenCV's LINE_8 and a textbook
    # Bresenham is the model's, and back, except at the model's ties (measured: 0 of ~11,000 pixels differ)
    rng = np.random.default_rng(7)
    shape = (80, 90)
    differ = drawn_total = 0
    for _ in range(300):
        a, b = rng.uniform(1, 78, 2), rng.uniform(1, 78, 2)
        drawn, ties = _image([[a, b]], shape)
        differ += int(((draw(a, b, shape) ^ drawn) & ~ties).sum())
        drawn_total += int(drawn.sum())
    assert drawn_total > 5000 and differ == 0


def test_ends_outside_the_image_decide_nothing():
    # segments leaving the image: Pillow drawn from the ends where they lie, and the held-out client that
    # clips 4 px outside the image first, then rounds: every pixel either way is the model's or a tie
    rng = np.random.default_rng(11)
    shape = (60, 70)
    for _ in range(100):
        a, b = rng.uniform(-40, 110, 2), rng.uniform(-40, 110, 2)
        drawn, ties = _image([[a, b]], shape)
        assert not ((_pillow(a, b, shape) ^ drawn) & ~ties).any()
        clipped = hd.draw_pillow(np.array([[a, b]]), shape[1], shape[0]) > 0
        assert not ((clipped ^ drawn) & ~ties).any()


def _pillow_clipped(segs, shape, margin_px):
    """Pillow's line between the rounded ends of ``segs`` clipped to the image grown by ``margin_px`` (its
    border at -1/2 - margin_px and W - 1/2 + margin_px), by the held-out client's own clipper."""
    return _pillow_segments(hd.clip_rect(np.asarray(segs, dtype=float), shape[1], shape[0], margin_px + 0.5), shape)


def _pillow_segments(segs, shape):
    from PIL import Image, ImageDraw

    im = Image.new("L", (shape[1], shape[0]), 0)
    for a, b in segs:
        ImageDraw.Draw(im).line([tuple(np.floor(a + 0.5)), tuple(np.floor(b + 0.5))], fill=255)
    return np.asarray(im) > 0


@pytest.mark.parametrize(
    "seg, margin",
    [
        # the clipper's end on the border y = 59.5 reads 59.49999999999999 and rounds down: a pixel at
        # (5, 49) moves across the line (GL-style clipping's float error along the line)
        ([[-31.97655814642069, -7.080662262852734], [17.893928623567668, 70.89228816925471]], 0.0),
        # cut 1 px out at y = -1.5 and rounded to (-1, -1): from (29, 31) that line (32 steps in y, 30 in x) is
        # on a half pixel at rows 23 and 7, where Pillow takes (21, 23) and (6, 7), the model's line (22, 23)
        # and (7, 7)
        ([[29.22850262275037, 31.285033946878002], [-1.2161481529916571, -1.9247190446328446]], 1.0),
        # a segment that passes 0.3 px outside the image's corner, cut 1 px out: its rounded ends' line draws
        # the corner pixel (0, 0)
        ([[78.31567102229828, -37.8974861961944], [-7.666534088260306, 2.5467670384520247]], 1.0),
        # leaving through the top at a shallow angle: cut at the border, (53.27, -0.5) -> (53, 0), it draws
        # (53, 0) and (54, 0), which the line to the far end (rounded from (56, 0)) leaves at once
        ([[55.54425309821815, 0.4680070645805472], [-33.853971409570796, -37.52085467072064]], 0.0),
    ],
    ids=["cut_on_a_half_pixel", "a_cuts_own_half_pixel", "passing_outside", "leaving_at_a_shallow_angle"],
)
def test_lines_cut_at_the_border_grown_by_a_margin_decide_nothing(seg, margin):
    # three segments where the model's drawing, less its ties, missed a pixel of a renderer that clips at the
    # border grown by one of CLIP_MARGINS_PX and then rounds (found by the random test below, seeds 11 and 3)
    shape = (60, 70)
    drawn, ties = _image([seg], shape)
    assert not ((_pillow_clipped([seg], shape, margin) ^ drawn) & ~ties).any()


def test_random_lines_cut_at_every_margin_decide_nothing():
    # 300 random segments leaving a 60 x 70 image, each clipped at the border grown by each margin of
    # CLIP_MARGINS_PX and drawn by Pillow between the rounded ends: every pixel either way is the model's or a
    # tie (before the cut's rounding along the line, its own half pixels and segments passing just outside
    # were ties: 2 of the 1,500 drawings differed)
    rng = np.random.default_rng(11)
    shape = (60, 70)
    differ = 0
    for _ in range(300):
        seg = [rng.uniform(-40, 110, 2), rng.uniform(-40, 110, 2)]
        drawn, ties = _image([seg], shape)
        for m in (0.0, 1.0, 2.0, 4.0, 8.0):  # the margins the model's docstring promises (CLIP_MARGINS_PX)
            differ += int(((_pillow_clipped([seg], shape, m) ^ drawn) & ~ties).any())
    assert differ == 0


def test_a_dropped_end_pixel_is_no_tie():
    # the model's pixels less the line's last one: that pixel is a decided difference (the ends are not ties)
    a, b = np.array([2.2, 3.1]), np.array([30.3, 17.8])
    drawn, ties = _image([[a, b]], (40, 40))
    assert drawn[18, 30] and not ties[18, 30]


def test_gl_rule_is_core_raster_line():
    # GL's diamond exit: (0.5, 0.2) -> (4.0, 0.2) leaves the diamond of (0, 0)? |0.5| + 0.2 >= 1/2: the start is
    # outside it, so pixel 0 is not drawn... drawn pixels are those the segment exits: 1, 2, 3 (4's diamond
    # holds the end: not drawn)
    drawn, ties = _image([[[0.5, 0.2], [4.0, 0.2]]], (1, 6), rule="gl")
    assert drawn[0].tolist() == [False, True, True, True, False, False] and not ties.any()


def test_unknown_rule_is_refused():
    with pytest.raises(ValueError, match="rule 'bresenham'"):
        lm.expected(np.zeros((0, 2, 2)), (4, 4), "bresenham")


def test_band_pixels_symmetric_and_leaning():
    # a horizontal line at y = 2.3: width 2 takes the centres within 1 of it, rows 2 and 3 (1.3 .. 3.3)
    band = lm.band_pixels(np.array([[[1.0, 2.3], [8.0, 2.3]]]), (6, 10), 2.0)
    assert band[:, 4].tolist() == [False, False, True, True, False, False]
    # leaning 0.5 px along the left normal (dy, -dx) / |d| = (0, -1): centre 1.8, rows 1 and 2
    band = lm.band_pixels(np.array([[[1.0, 2.3], [8.0, 2.3]]]), (6, 10), 2.0, lean_px=0.5)
    assert band[:, 4].tolist() == [False, True, True, False, False, False]


def test_band_holding_the_candidates_count():
    # a horizontal line at y = 2.3 over columns 1..8 (10 x 6): centre distances 0.3 (row 2), 0.7 (row 3),
    # 1.3 (row 1), 1.7 (row 4) in each column, and more past the ends (round caps)
    segs = np.array([[[1.0, 2.3], [8.0, 2.3]]])
    # 16 centres: the 8 columns' rows 2 and 3 (every centre within 0.7; the 17th nearest is a cap's,
    # column 0 or 9 on row 2, sqrt(1 + 0.09) = 1.04 away) -> h = 0.87, rows 2 and 3 exactly
    band = lm.band_holding(segs, (6, 10), 16, 1.5)
    assert band.sum() == 16 and band[2:4, 1:9].all()
    # 8 centres: row 2 alone (0.3; the 9th is 0.7) -> the 1-px band, whatever width was read
    band = lm.band_holding(segs, (6, 10), 8, 2.0)
    assert band.sum() == 8 and band[2, 1:9].all()
    # 17 centres: the 17th and 18th nearest are the two caps' row-2 centres, both 1.04 away, so h = 1.04 and
    # no band holds exactly 17: it holds 18 (rows 2 and 3, and both caps' row 2), not the 16 within 0.7
    band = lm.band_holding(segs, (6, 10), 17, 1.5)
    assert band.sum() == 18 and band[2:4, 1:9].all() and band[2, 0] and band[2, 9]
    # no count: the width rounded, 3 -> within 1.5: rows 1-3 of columns 1..8 (24) and each cap's rows 2
    # and 3 (1.04, sqrt(1 + 0.49) = 1.22; row 1's is sqrt(1 + 1.69) = 1.64 away): 28
    assert lm.band_holding(segs, (6, 10), 0, 3.0).sum() == 28


def _mask(shape, pixels):
    out = np.zeros(shape, bool)
    for x, y in pixels:
        out[y, x] = True
    return out


@pytest.mark.parametrize("transpose", [False, True], ids=["x_major", "y_major"])
def test_a_tie_on_the_first_column_or_row_outside_is_dropped(transpose):
    # (1, 0) -> (3, 1) in a 2-wide image: the minor half pixel is at x = 2 (y = 0.5), the column just past
    # the image (x == W), where the end (3, 1) also lies: inside, only (1, 0) is drawn, by every rounding
    # of the outside end (cut at the border: (2, 0) or (2, 1); 1 px out: (3, 0) or (3, 1)); no tie, no
    # error. Transposed the same at the row just past the image (y == H).
    seg, shape, pixel = [[1.0, 0.0], [3.0, 1.0]], (3, 2), (1, 0)
    if transpose:
        seg, shape, pixel = [p[::-1] for p in seg], shape[::-1], pixel[::-1]
    drawn, ties = _image([seg], shape)
    assert (drawn == _mask(shape, [pixel])).all() and not ties.any()


@pytest.mark.parametrize("reverse", [False, True], ids=["end", "start"])
@pytest.mark.parametrize("width, below", [(6, 2**-51), (16384, 2**-40)], ids=["narrow", "widest"])
def test_an_end_inside_the_margin_is_rounded_where_it_lies(reverse, width, below):
    # 3.5 - 2^-51 (the float below 3.5) rounds to 3: pixels 0..3, pixel 4 a tie (within 1/32 px of the
    # half). Shifted by the clip's margin (6, the image's larger side) and back it would read 3.5 (9.5 - 2^-51
    # is a quarter of 9.5's ulp 2^-49 from it) and draw pixel 4: an end the margin did not cut is kept exactly.
    # In the widest image (core.limits.MAX_SIDE 16384) the shift's error is up to half of 16387.5's ulp 2^-38:
    # 3.5 - 2^-40 (a quarter ulp) reads 3.5 shifted, and must still not count as a cut (the test for a cut
    # is relative to the margin, 1e-9 x 16387.5 = 1.6e-5 px, not 1e-9 / 16387.5 = 6e-14 px)
    seg = [[0.0, 0.0], [3.5 - below, 0.0]]
    drawn, ties = _image([seg[::-1] if reverse else seg], (1, width))
    assert drawn[0, :6].tolist() == [True] * 4 + [False] * 2 and drawn.sum() == 4
    assert ties[0, :6].tolist() == [False] * 4 + [True, False] and ties.sum() == 1


@pytest.mark.parametrize(
    "segs",
    [np.zeros((0, 2, 2)), [[[np.nan, 1.0], [2.0, 2.0]]], [[[100.0, 100.0], [200.0, 100.0]]]],
    ids=["none", "not_finite", "beyond_the_margin"],
)
@pytest.mark.parametrize("rule", lm.RULES)
def test_no_segment_draws_nothing(segs, rule):
    # no segment, one with a NaN end, one wholly past the clip's margin (4 px around a 4 x 4 image): no pixel
    drawn, ties = lm.expected(np.asarray(segs, dtype=float).reshape(-1, 2, 2), (4, 4), rule)
    assert not drawn.any() and not ties.any()


@pytest.mark.parametrize("reverse", [False, True], ids=["end", "start"])
def test_an_end_just_outside_the_image_is_cut_either_way(reverse):
    # (4, 0.4) -> (-0.7, 0.4) in 2 x 6: the end is outside (x < -1/2), so a renderer may draw to it
    # (rounded to (-1, 0)), or cut the line at the border x = -1/2 (y 0.4: rounded to (0, 0) or, across the
    # line, (0, 1)), or 1 px out and beyond (at the end itself: (-1, 0) or (-1, 1)). From (4, 0) the lines
    # to (0, 1) and (-1, 1) step down a row at x = 2 (a half pixel: the lower row) and x = 1: every pixel of
    # columns 0..2 in rows 0 and 1 is drawn by some roundings, not all; (3, 0) and (4, 0) by all
    seg = [[4.0, 0.4], [-0.7, 0.4]]
    drawn, ties = _image([seg[::-1] if reverse else seg], (2, 6))
    assert (drawn == _mask((2, 6), [(x, 0) for x in range(5)])).all()
    assert (ties == _mask((2, 6), [(x, y) for x in range(3) for y in range(2)])).all()


@pytest.mark.parametrize("reverse", [False, True], ids=["end", "start"])
def test_an_end_on_the_images_first_half_pixel_is_inside(reverse):
    # (5, 0) -> (-0.5, 0.9) in 2 x 6: x = -0.5 is the image's edge, not outside it, so the end is rounded
    # only along x (a half pixel: 0 or -1), y 0.9 -> 1: from (5, 0) the line to (0, 1) (5 steps of 1/5)
    # steps down at x = 2 (y 0.6); the line to (-1, 1) (6 steps of 1/6) is at y = 0.5 there, a half pixel:
    # (2, 0) and (2, 1) are ties, nothing else. Were the end outside, a cut there rounded across (to (0, 0))
    # would make columns 0..2 of rows 0 and 1 ties
    seg = [[5.0, 0.0], [-0.5, 0.9]]
    drawn, ties = _image([seg[::-1] if reverse else seg], (2, 6))
    assert (drawn == _mask((2, 6), [(5, 0), (4, 0), (3, 0), (2, 1), (1, 1), (0, 1)])).all()
    assert (ties == _mask((2, 6), [(2, 0), (2, 1)])).all()


@pytest.mark.parametrize("reverse", [False, True], ids=["end", "start"])
def test_an_end_on_the_images_last_half_pixel_is_inside(reverse):
    # (0, 0) -> (5.5, 0.9) in 2 x 6: x = 5.5 = W - 1/2 is the image's edge, not outside it, so the end is
    # rounded only along x (a half pixel: 5 or 6), y 0.9 -> 1: the lines to (5, 1) and (6, 1) draw the same
    # pixels inside, (0..2, 0) and (3..5, 1); the one tie is across the line to (6, 1) at x = 3 (y = 0.5).
    # Were the end outside, a cut there rounded across (to (6, 0)) would make all of x = 3..5 ties
    seg = [[0.0, 0.0], [5.5, 0.9]]
    drawn, ties = _image([seg[::-1] if reverse else seg], (2, 6))
    assert (drawn == _mask((2, 6), [(0, 0), (1, 0), (2, 0), (3, 1), (4, 1), (5, 1)])).all()
    assert (ties == _mask((2, 6), [(3, 0), (3, 1)])).all()


def test_an_end_below_the_image_may_be_cut_one_pixel_out():
    # (1, 1) -> (4, 5.5) in 3 x 4 (y-major, leaving through the bottom). A renderer that clips 1 px below the
    # image cuts at y = 3.5, x = 1 + 3 * 2.5 / 4.5 = 2.67: rounded across to (2, 4) or (3, 4); from (1, 1) the
    # line to (2, 4) is at x = 1 + 1/3 on row 2 (pixel (1, 2)); every other rounding (the border: (2, 3),
    # (3, 3); 2 px out, y = 4.5, x = 3.33: (3, 5), (4, 5); the end, (4, 5 or 6), (5, 6)) is at x >= 1.5 there
    # (pixel (2, 2)). So (1, 2) and (2, 2) are ties; (1, 1) and (2, 2) drawn (to (4, 6): x = 1.6 on row 2)
    drawn, ties = _image([[[1.0, 1.0], [4.0, 5.5]]], (3, 4))
    assert (drawn == _mask((3, 4), [(1, 1), (2, 2)])).all()
    assert (ties == _mask((3, 4), [(1, 2), (2, 2)])).all()


def test_bands_at_the_images_edges_and_around_a_point():
    # a line at y = 4.7 from x = 1 to 9.6 in 6 x 10, width 2: rows 4 (0.7 away) and 5 (0.3) of columns 1..9,
    # the band's reach cut at the image's last row and column (row 3 is 1.7 away; column 0's row 5, 1.04)
    band = lm.band_pixels(np.array([[[1.0, 4.7], [9.6, 4.7]]]), (6, 10), 2.0)
    assert (band == _mask((6, 10), [(x, y) for x in range(1, 10) for y in (4, 5)])).all()
    # a band is closed: a line on row 2 (x = 1..9, 8 px long), width 2: rows 1 and 3 exactly 1 away are in it,
    # and so is the start cap's (0, 2), 1 from (1, 2)
    band = lm.band_pixels(np.array([[[1.0, 2.0], [9.0, 2.0]]]), (6, 10), 2.0)
    assert (band == _mask((6, 10), [(x, y) for x in range(1, 10) for y in (1, 2, 3)] + [(0, 2)])).all()
    # a segment of no length is a point, its band a disc: around (2, 2.3) within 1, (2, 2) and (2, 3) (0.3
    # and 0.7; (1, 2) and (3, 2) are 1.04 away); the band holding 2 centres is the same, halfway to 1.04
    point = np.array([[[2.0, 2.3], [2.0, 2.3]]])
    assert (lm.band_pixels(point, (5, 5), 2.0) == _mask((5, 5), [(2, 2), (2, 3)])).all()
    assert (lm.band_holding(point, (5, 5), 2, 2.0) == _mask((5, 5), [(2, 2), (2, 3)])).all()


def test_an_end_exactly_end_tie_px_from_the_half_is_a_tie():
    # 3.5 + 1/32 (exact in binary) is exactly END_TIE_PX = 1/32 from the half: within it (the bound is closed),
    # so pixel 4 is a tie; 1/16 past the half it was decided (test_end_on_a_half_pixel_is_a_tie)
    assert lm.END_TIE_PX == 1 / 32
    drawn, ties = _image([[[0.0, 0.0], [3.5 + 1 / 32, 0.0]]], (1, 6))
    assert drawn[0].tolist() == [True] * 5 + [False] and ties[0].tolist() == [False] * 4 + [True, False]


def test_an_end_beyond_the_margin_is_cut_at_it():
    # (1, 2) -> (7, -1.5) in 2 x 3: the margin is the larger side, 3 px, so the line is cut at x = 2.5 + 3 =
    # 5.5, y = 2 - 3.5 x 4.5 / 6 = -0.625, rounded to (6, -1); from (1, 2) that line (5 steps, y down 3/5 a
    # step) is at y = 2 - 0.6 = 1.4 at x = 2: pixel (2, 1), the one drawn inside. Drawn to the end itself,
    # (7, -1.5) -> (7, -1), the line would be at y = 1.5 there and draw (2, 2), outside
    drawn, _ = _image([[[1.0, 2.0], [7.0, -1.5]]], (2, 3))
    assert (drawn == _mask((2, 3), [(2, 1)])).all()


def test_an_end_a_hair_past_the_margin_is_cut():
    # (1, 0) -> (-3.5 - 1e-8, 2) in 2 x 3: the end lies 1e-8 px past the margin's border x = -1/2 - 3 (1.5e-9
    # of margin + |end|, far above the shift's float error, 1e-16 of it): a cut, at x = -3.5 exactly, rounded
    # up to (-3, 2) (y 2 - 4.4e-9 -> 2). From (1, 0) that line (4 steps, y up 1/2 a step) is at y = 0.5 on
    # x = 0: (0, 1) drawn, (0, 0) and (0, 1) ties. Were the end kept, (-4, 2): y = 0.4 there, (0, 0) drawn
    drawn, ties = _image([[[1.0, 0.0], [-3.5 - 1e-8, 2.0]]], (2, 3))
    assert (drawn == _mask((2, 3), [(1, 0), (0, 1)])).all()
    assert (ties == _mask((2, 3), [(0, 0), (0, 1)])).all()


def test_band_holding_searches_within_half_the_width_plus_a_pixel():
    # around the point (2, 2.3), a band 2.4 px wide searches centres within 1.2 + 1 = 2.2 px: 16 of them, the
    # farthest (0, 3) and (4, 3) at sqrt(4 + 0.49) = 2.12 (then (2, 0) at 2.3). Holding 16, h is halfway from
    # 2.12 to the reach, 2.16: those 16. (Searching within round(2.4) / 2 + 1 = 2.0 instead finds 12, fewer
    # than 16: the 2-px band, 2 centres)
    point = np.array([[[2.0, 2.3], [2.0, 2.3]]])
    yy, xx = np.mgrid[0:5, 0:5]
    within = np.hypot(xx - 2.0, yy - 2.3) <= 2.2
    assert within.sum() == 16
    assert (lm.band_holding(point, (5, 5), 16, 2.4) == within).all()


def test_a_cut_is_rounded_either_way_across_the_line():
    # (5, 0) -> (8, 7.5) in 3 x 6, a steep line (x 3 over y 7.5) leaving through the right then the bottom:
    # its cuts are rounded either way in x, across it (the border: (5.5, 1.25) -> (5, 1) or (6, 1); 1 px out,
    # (6.4, 3.5) -> (6, 4) or (7, 4); 2 px out, (6.8, 4.5) -> (6, 5) or (7, 5); 4 px out, (7.6, 6.5) ->
    # (7, 7) or (8, 7)); the end itself is rounded either way in y (7.5: (8, 7) or (8, 8)). From (5, 0), the
    # line to (6, 5) alone stays on x = 5 at y = 2 (x = 5.4 there): (5, 2) is a tie; (5, 1) too (the lines to
    # (6, 1) and (7, 4) leave x = 5 at once). Rounded in y instead, no rounding keeps (5, 2)
    drawn, ties = _image([[[5.0, 0.0], [8.0, 7.5]]], (3, 6))
    assert (drawn == _mask((3, 6), [(5, 0), (5, 1)])).all()
    assert (ties == _mask((3, 6), [(5, 1), (5, 2)])).all()


def test_gl_rule_in_an_image_wider_than_tall():
    # (1, 0.2) -> (1, 4.6) in 2 x 6: GL draws the pixels whose diamonds the segment leaves, (1, 0) and (1, 1)
    # inside; the line goes on below the image's 2 rows (not its 6 columns): nothing else drawn
    drawn, ties = _image([[[1.0, 0.2], [1.0, 4.6]]], (2, 6), rule="gl")
    assert (drawn == _mask((2, 6), [(1, 0), (1, 1)])).all() and not ties.any()


def test_a_band_of_several_segments_is_their_union():
    # two lines, y = 1.2 from x = 1 to 4 and x = 6.3 from y = 0 to 4, in 5 x 8, width 1: the first takes
    # row 1 of columns 1..4 (0.2 away), the second column 6 of rows 0..4 (0.3 away); nothing else within 1/2
    segs = np.array([[[1.0, 1.2], [4.0, 1.2]], [[6.3, 0.0], [6.3, 4.0]]])
    band = lm.band_pixels(segs, (5, 8), 1.0)
    assert (band == _mask((5, 8), [(x, 1) for x in range(1, 5)] + [(6, y) for y in range(5)])).all()


def test_a_band_leaning_far_is_the_whole_segment_moved():
    # (0, 0) -> (4, 4), width 1, leaning 2 px along the left normal (4, -4) / |d|: the segment moved to
    # (1.41, -1.41) -> (5.41, 2.59), on the line x - y = 2 sqrt(2). The centres within 1/2 of it have
    # |x - y - 2.83| <= 0.71, so x - y = 3: (3, 0), (4, 1) and (5, 2) in 6 x 6 (each projects inside the
    # segment, 0.12 px from it; the caps reach no other centre). (5, 2) lies past both unmoved ends' x
    drawn = lm.band_pixels(np.array([[[0.0, 0.0], [4.0, 4.0]]]), (6, 6), 1.0, lean_px=2.0)
    assert (drawn == _mask((6, 6), [(3, 0), (4, 1), (5, 2)])).all()


def test_a_cut_exactly_end_tie_px_past_a_half_pixel_along_the_line_is_rounded_either_way():
    # (3, 1) -> (4, 6.0625) in 6 x 4, steep, leaves through the right border x = 3.5 at y = 1 + 5.0625 / 2 =
    # 3.53125, exactly END_TIE_PX past the half along the line (the bound is closed): that cut rounds to
    # (3, 4) or (4, 4) across, and down along it to (4, 3); past 1 px out the end itself, (4, 6) or (4, 7).
    # From (3, 1): the line to (4, 3) leaves x = 3 at y = 2 (a half pixel there: (3, 2) and (4, 2) ties), the
    # lines to (4, 4) at y = 3, to (4, 6) and (4, 7) at y = 4, to (3, 4) never. So (3, 2), (3, 3) and (3, 4)
    # are ties; (3, 1) and, on the line to (4, 6), (3, 2) and (3, 3) drawn
    drawn, ties = _image([[[3.0, 1.0], [4.0, 6.0625]]], (6, 4))
    assert (drawn == _mask((6, 4), [(3, 1), (3, 2), (3, 3)])).all()
    assert (ties == _mask((6, 4), [(3, 2), (3, 3), (3, 4)])).all()


def test_an_end_past_the_margin_side_inside_the_grown_image_is_kept_exactly():
    # (0, 0) -> (6.5 - 2^-50, 1) in 2 x 6: the end lies farther out than the margin (6) but inside the grown
    # image (x <= 5.5 + 6), so it is kept as it is, rounded to 6 (not the 6.5 it reads shifted by 6 and back:
    # 12.5 - 2^-50 is half of 12.5's ulp below it and rounds to even, 12.5). From (0, 0) to (6, 1): y = 0 up to
    # x = 2, a half pixel at x = 3 (rounded up: (3, 1)), y = 1 after; to (7, 1) it would be (3, 0)
    drawn, _ = _image([[[0.0, 0.0], [6.5 - 2**-50, 1.0]]], (2, 6))
    assert (drawn == _mask((2, 6), [(0, 0), (1, 0), (2, 0), (3, 1), (4, 1), (5, 1)])).all()


def test_a_band_in_a_one_column_image():
    # a vertical line x = 0 from y = 1 to 3 in a 5 x 1 image, width 1: rows 1..3 (on it); rows 0 and 4 are 1
    # from its ends. The band's window is that one column
    band = lm.band_pixels(np.array([[[0.0, 1.0], [0.0, 3.0]]]), (5, 1), 1.0)
    assert band[:, 0].tolist() == [False, True, True, True, False]


def test_band_holding_one_centre():
    # around the point (2, 2.3), the band holding 1 centre: h halfway from 0.3 ((2, 2)) to 0.7 ((2, 3)), 0.5:
    # (2, 2) alone, whatever the width read
    point = np.array([[[2.0, 2.3], [2.0, 2.3]]])
    assert (lm.band_holding(point, (5, 5), 1, 2.0) == _mask((5, 5), [(2, 2)])).all()
