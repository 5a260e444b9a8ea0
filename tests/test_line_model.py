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
    # no count: the width rounded, 3 -> within 1.5: rows 1-3 of columns 1..8 (24) and each cap's rows 2
    # and 3 (1.04, sqrt(1 + 0.49) = 1.22; row 1's is sqrt(1 + 1.69) = 1.64 away): 28
    assert lm.band_holding(segs, (6, 10), 0, 3.0).sum() == 28
