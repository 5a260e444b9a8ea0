"""core.projector.raster.line_pixels: one test per geometric case (expected image built by
slicing, scikit-image style), the module doctest, and hypothesis properties against
``naive_diamond_exit``, an independent per-pixel implementation of the rule stated in
core/projector/raster.py's docstring (GL's diamond-exit rule, pixel centres at integers):

    ends snapped to 1/256 px; pixel (c, r) is drawn when the segment's line crosses
    the open diamond |x - c| + |y - r| < 1/2 and the point where it leaves the
    diamond (in the direction of travel) lies after the start point and at or
    before the end point.

Consequences used below (derived from that rule):
* a segment between two pixel centres draws its start pixel and not its end pixel,
  so it draws max(|di|, |dj|) pixels (joined edges do not draw the shared pixel twice);
* a zero-length segment draws nothing (the exit point is after the end point);
* reversing a segment changes only its end pixels; if neither end lies in a diamond
  it draws the same pixels.
"""

import doctest
import math

import numpy as np
import pytest
from helpers import eight_connected
from hypothesis import example, given, settings
from hypothesis import strategies as st
from numpy.testing import assert_array_equal
from wirecheck.core.projector import raster
from wirecheck.core.projector.raster import SUBPIXEL, line_pixels

W, H = 12, 10


def draw(p0, p1, w=W, h=H):
    rr, cc = line_pixels(np.array([p0], float), np.array([p1], float), w, h)
    img = np.zeros((h, w), dtype=np.uint8)
    img[rr, cc] = 1
    return img


def pixel_set(p0, p1, w=W, h=H):
    rr, cc = line_pixels(np.array([p0], float), np.array([p1], float), w, h)
    out = list(zip(rr.tolist(), cc.tolist()))
    assert len(out) == len(set(out)), "a single segment drew a pixel twice"
    return set(out)


def blank():
    return np.zeros((H, W), dtype=np.uint8)


# ---- naive reference -----------------------------------------------------------------

T_TIE = 1e-9  # parameter-space tie band: ends are on a 1/256 grid, lengths <= 100 px,
# so genuine non-ties differ from 0/1 by >= (1/256)^2/100 ~ 1.5e-7 >> 1e-9


def naive_diamond_exit(p0, p1, w, h):
    """(drawn, ambiguous) pixel sets (row, col) by checking every pixel's diamond."""
    snap = lambda v: round(v * 256.0) / 256.0
    x0, y0, x1, y1 = snap(p0[0]), snap(p0[1]), snap(p1[0]), snap(p1[1])
    dx, dy = x1 - x0, y1 - y0
    drawn, ambiguous = set(), set()
    if dx == 0 and dy == 0:
        return drawn, ambiguous
    for c in range(math.floor(min(x0, x1)) - 1, math.ceil(max(x0, x1)) + 2):
        for r in range(math.floor(min(y0, y1)) - 1, math.ceil(max(y0, y1)) + 2):
            if not (0 <= c < w and 0 <= r < h):
                continue
            # the line p0 + t d inside the closed diamond: sx (x - c) + sy (y - r) <= 1/2
            t_lo, t_hi, empty = -math.inf, math.inf, False
            for sx, sy in ((1, 1), (1, -1), (-1, 1), (-1, -1)):
                a = sx * dx + sy * dy
                b = 0.5 - sx * (x0 - c) - sy * (y0 - r)
                if a > 0:
                    t_hi = min(t_hi, b / a)
                elif a < 0:
                    t_lo = max(t_lo, b / a)
                elif b < 0:
                    empty = True
            if empty or t_hi < t_lo - T_TIE:
                continue  # misses the diamond
            tm = 0.5 * (t_lo + t_hi)
            l1_mid = abs(x0 + tm * dx - c) + abs(y0 + tm * dy - r)
            if t_hi - t_lo <= T_TIE or l1_mid >= 0.5 - 1e-12:
                ambiguous.add((r, c))  # touches only the boundary: a tie
                continue
            if abs(t_hi) <= T_TIE or abs(t_hi - 1) <= T_TIE:
                ambiguous.add((r, c))  # exits exactly at an end
            elif 0 < t_hi <= 1:
                drawn.add((r, c))
    return drawn, ambiguous


# ---- one test per geometric case --------------------------------------------------------


def test_horizontal():
    # centres (2,3) -> (7,3): start pixel drawn, end pixel not: cols 2..6 of row 3
    exp = blank()
    exp[3, 2:7] = 1
    assert_array_equal(draw((2, 3), (7, 3)), exp)


def test_vertical():
    # (4,1) -> (4,6): rows 1..5 of col 4 (y-major: |dx| > |dy| is false)
    exp = blank()
    exp[1:6, 4] = 1
    assert_array_equal(draw((4, 1), (4, 6)), exp)


def test_reversed_direction_between_centres_swaps_the_undrawn_end():
    # (7,3) -> (2,3): starts at col 7, ends at col 2 (not drawn): cols 3..7
    exp = blank()
    exp[3, 3:8] = 1
    assert_array_equal(draw((7, 3), (2, 3)), exp)


@pytest.mark.parametrize("p0,p1", [((2.4, 3.4), (7.6, 3.4)), ((1.3, 0.7), (9.7, 6.3)), ((0.6, 8.7), (10.8, 1.4))])
def test_reversed_direction_gives_same_pixels_when_ends_outside_diamonds(p0, p1):
    # each end has |x - round x| + |y - round y| > 1/2: it lies in no diamond, so every
    # diamond the segment crosses is entered and left inside it, in either direction
    for x, y in (p0, p1):
        assert abs(x - round(x)) + abs(y - round(y)) > 0.5
    assert_array_equal(draw(p0, p1), draw(p1, p0))
    assert draw(p0, p1).any()


def test_horizontal_between_non_centres():
    # y = 3.4: the line crosses the diamonds of row 3 where |x - c| < 0.1; x in [2.4, 7.6]
    # contains those of cols 3..7 entirely: cols 3..7
    exp = blank()
    exp[3, 3:8] = 1
    assert_array_equal(draw((2.4, 3.4), (7.6, 3.4)), exp)


def test_diagonal_45():
    # (1,1) -> (5,5): through the centres (k,k); (5,5) is the end: not drawn
    exp = blank()
    exp[[1, 2, 3, 4], [1, 2, 3, 4]] = 1
    assert_array_equal(draw((1, 1), (5, 5)), exp)


def test_antidiagonal_45():
    # (1,5) -> (5,1): x,y = (1,5),(2,4),(3,3),(4,2) drawn, (5,1) is the end
    exp = blank()
    exp[[5, 4, 3, 2], [1, 2, 3, 4]] = 1
    assert_array_equal(draw((1, 5), (5, 1)), exp)


@pytest.mark.parametrize("p", [(3.0, 4.0), (3.2, 4.4), (0.5, 0.5)])
def test_single_point_zero_length_draws_nothing(p):
    # the exit point of the pixel's diamond is beyond the end point (== start point)
    assert_array_equal(draw(p, p), blank())


def test_steep_line_with_ties():
    # (2,0) -> (4,8): y-major, x = 2 + y/4 at rows 0..7 (row 8 is the end, not drawn):
    # 2, 2.25, 2.5, 2.75, 3, 3.25, 3.5, 3.75 -> nearest col, halves to -x (left):
    # 2, 2, 2, 3, 3, 3, 3, 4
    exp = blank()
    exp[np.arange(8), [2, 2, 2, 3, 3, 3, 3, 4]] = 1
    assert_array_equal(draw((2, 0), (4, 8)), exp)


def test_shallow_line_docstring_example():
    # (0,0) -> (4,2): x-major, y = x/2 at cols 0..3: 0, .5, 1, 1.5 -> halves to +y (down):
    # rows 0, 1, 1, 2; col 4 is the end
    exp = np.zeros((3, 5), np.uint8)
    exp[[0, 1, 1, 2], [0, 1, 2, 3]] = 1
    assert_array_equal(draw((0, 0), (4, 2), 5, 3), exp)


def test_out_of_bounds_pixels_dropped():
    # (-3,2) -> (3,2) in a 5x4 image: cols -3..2 would be drawn; only 0..2 are in bounds
    exp = np.zeros((4, 5), np.uint8)
    exp[2, 0:3] = 1
    assert_array_equal(draw((-3, 2), (3, 2), 5, 4), exp)


@pytest.mark.parametrize("p0,p1", [((-10, -10), (-2, -5)), ((20, 3), (30, 3)), ((3, -4), (8, -1))])
def test_segment_fully_outside_draws_nothing(p0, p1):
    assert pixel_set(p0, p1) == set()


def test_empty_input():
    rr, cc = line_pixels(np.zeros((0, 2)), np.zeros((0, 2)), W, H)
    assert rr.shape == cc.shape == (0,)


def test_several_segments_at_once_is_union_of_single_calls():
    p0 = np.array([[2, 3], [4, 1], [1, 1]], float)
    p1 = np.array([[7, 3], [4, 6], [5, 5]], float)
    rr, cc = line_pixels(p0, p1, W, H)
    together = set(zip(rr.tolist(), cc.tolist()))
    assert together == pixel_set(p0[0], p1[0]) | pixel_set(p0[1], p1[1]) | pixel_set(p0[2], p1[2])


def test_doctest_in_module_runs():
    result = doctest.testmod(raster, verbose=False)
    assert result.attempted > 0
    assert result.attempted >= 1
    assert result.failed == 0


# ---- properties ----------------------------------------------------------------------

PW, PH = 40, 30
coord = st.floats(-5.0, 45.0, allow_nan=False, allow_infinity=False)
inside_x = st.floats(0.0, PW - 1.0)
inside_y = st.floats(0.0, PH - 1.0)


@settings(max_examples=300, deadline=None)
@given(x0=coord, y0=coord, x1=coord, y1=coord)
def test_matches_naive_diamond_exit(x0, y0, x1, y1):
    got = pixel_set((x0, y0), (x1, y1), PW, PH)
    want, ambiguous = naive_diamond_exit((x0, y0), (x1, y1), PW, PH)
    assert got - ambiguous == want - ambiguous
    # a tie pixel may go either way, but only if the line touches it
    assert got <= want | ambiguous


def seg_distance(px, py, x0, y0, x1, y1):
    dx, dy = x1 - x0, y1 - y0
    L2 = dx * dx + dy * dy
    t = 0.0 if L2 == 0 else max(0.0, min(1.0, ((px - x0) * dx + (py - y0) * dy) / L2))
    return math.hypot(px - (x0 + t * dx), py - (y0 + t * dy))


# A drawn pixel's diamond is left at a point of the (snapped) segment, on the diamond's
# boundary: L1 distance 1/2 from the centre, so Euclidean <= 1/2. Snapping moves each
# end by <= 1/512 per coordinate (<= sqrt2/512 in all), hence every point of the snapped
# segment is within sqrt2/512 of the original: bound 1/2 + sqrt2/512 = 0.50276
# (tighter than the 0.5 sqrt2 = 0.707 of a nearest-pixel rule). Float slack: values
# <= 50 and ~10 operations: 10 * 2.2e-16 * 50 ~ 1e-13.
DIST_BOUND = 0.5 + math.sqrt(2) / 512 + 1e-12


@settings(max_examples=300, deadline=None)
@given(x0=coord, y0=coord, x1=coord, y1=coord)
def test_every_drawn_pixel_near_the_segment(x0, y0, x1, y1):
    for r, c in pixel_set((x0, y0), (x1, y1), PW, PH):
        assert seg_distance(c, r, x0, y0, x1, y1) <= DIST_BOUND
        assert 0 <= r < PH and 0 <= c < PW


@settings(max_examples=300, deadline=None)
@given(i0=st.integers(0, PW - 1), j0=st.integers(0, PH - 1), i1=st.integers(0, PW - 1), j1=st.integers(0, PH - 1))
def test_pixel_count_between_centres(i0, j0, i1, j1):
    got = pixel_set((i0, j0), (i1, j1), PW, PH)
    # start drawn, end not (its diamond contains the end point), one pixel per major step
    assert len(got) == max(abs(i1 - i0), abs(j1 - j0))
    if (i0, j0) != (i1, j1):
        assert (j0, i0) in got and (j1, i1) not in got
        # the segment closed at both ends is the union of both directions
        assert len(got | pixel_set((i1, j1), (i0, j0), PW, PH)) == max(abs(i1 - i0), abs(j1 - j0)) + 1


@settings(max_examples=300, deadline=None)
@given(x0=inside_x, y0=inside_y, x1=inside_x, y1=inside_y)
def test_drawn_set_is_8_connected_and_one_pixel_per_major_step(x0, y0, x1, y1):
    got = pixel_set((x0, y0), (x1, y1), PW, PH)
    assert eight_connected(got)
    # one pixel per major coordinate, on consecutive major coordinates
    x_major = abs(x1 - x0) > abs(y1 - y0)
    major = sorted(c if x_major else r for r, c in got)
    assert major == list(range(major[0], major[0] + len(major))) if major else True


def outside_diamonds(x, y, margin=2 / 256):
    # snapping moves a coordinate by <= 1/512; a margin of 2/256 in L1 keeps the snapped
    # end outside every diamond
    return abs(x - round(x)) + abs(y - round(y)) > 0.5 + margin


# an end point off every diamond: integer + offsets with |fx|, |fy| in [0.26, 0.5], so
# |fx| + |fy| >= 0.52 > 0.5 + 2/256 (snapping moves each coordinate by <= 1/512)
off = st.tuples(st.floats(0.26, 0.5), st.sampled_from((-1, 1)))
corner_point = st.builds(
    lambda i, j, fx, fy: (i + fx[0] * fx[1], j + fy[0] * fy[1]), st.integers(-3, 43), st.integers(-3, 33), off, off
)


@settings(max_examples=300, deadline=None)
@given(p0=corner_point, p1=corner_point)
def test_reversal_same_pixels_when_ends_outside_diamonds(p0, p1):
    assert outside_diamonds(*p0) and outside_diamonds(*p1)
    fwd = pixel_set(p0, p1, PW, PH)
    bwd = pixel_set(p1, p0, PW, PH)
    _, ambiguous = naive_diamond_exit(p0, p1, PW, PH)
    assert fwd - ambiguous == bwd - ambiguous


@settings(max_examples=200, deadline=None)
@given(x0=coord, y0=coord, x1=coord, y1=coord, ox=st.integers(0, 20), oy=st.integers(0, 20))
# the start exactly on pixel (0, 0)'s diamond edge (0.3515625 + 0.1484375 = 1/2, both on the 1/256
# grid): the exit test once compared I + u with the start, and the sum rounds differently at I = 1
@example(x0=0.3515625, y0=0.1484375, x1=0.25, y1=11.0, ox=0, oy=1)
def test_out_of_bounds_dropping_equals_cropping_a_larger_canvas(x0, y0, x1, y1, ox, oy):
    # translating by whole pixels commutes with the rule (and with 1/256 snapping), so the
    # small image must be exactly the crop of the segment drawn, shifted, on a big canvas
    small = pixel_set((x0, y0), (x1, y1), PW, PH)
    big = pixel_set((x0 + ox, y0 + oy), (x1 + ox, y1 + oy), PW + 100, PH + 100)
    crop = {(r - oy, c - ox) for r, c in big if 0 <= r - oy < PH and 0 <= c - ox < PW}
    assert small == crop


def test_subpixel_grid_is_llvmpipe_256():
    assert SUBPIXEL == 256.0
