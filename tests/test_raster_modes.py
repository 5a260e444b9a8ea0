"""core.projector.raster's "fast" (integer DDA) and "aa" (Xiaolin Wu) modes.

Hand-derived images for the simple cases, then hypothesis properties against
independent per-pixel references written here with exact ``Fraction`` arithmetic
from the rules stated in core/projector/raster.py's docstring:

fast  ends rounded with floor(v + 1/2) (exact halves up, toward +x / +y); major axis
      x when |dx| > |dy| of the rounded ends, else y; at every integer major
      coordinate i between the rounded ends (both included) the pixel nearest to the
      minor coordinate b(i) of the rounded segment, halves to +y when y is minor and
      to -x when x is minor.
aa    major axis x when |dx| > |dy|; for every integer i whose interval
      [i - 1/2, i + 1/2] overlaps [a_lo, a_hi] in a length g > 0, pixels floor(b) and
      floor(b) + 1 (b = the line's minor coordinate at i) get (1 - f) g and f g,
      f = b - floor(b); zero weights dropped.

The fast tie rule depends only on the point (i, b(i)), which is the same in both
directions, so fast mode is symmetric under reversal (tested). OpenCV's LINE_8
walks from the left end and breaks x-major ties toward that end's row; the test
against cv2.line models exactly that difference.
"""

import math
from fractions import Fraction

import numpy as np
import pytest
from helpers import eight_connected
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_array_equal
from wirecheck.core.projector.raster import CHUNK_SEGMENTS, RASTER_MODES, line_coverage_aa, line_pixels_fast, paint_aa

W, H = 12, 10
EPS = np.finfo(np.float64).eps


def fast_img(p0, p1, w=W, h=H):
    rr, cc = line_pixels_fast(np.array([p0], float), np.array([p1], float), w, h)
    img = np.zeros((h, w), dtype=np.uint8)
    img[rr, cc] = 1
    return img


def fast_set(p0, p1, w=W, h=H):
    rr, cc = line_pixels_fast(np.array([p0], float), np.array([p1], float), w, h)
    out = list(zip(rr.tolist(), cc.tolist()))
    assert len(out) == len(set(out)), "a single segment drew a pixel twice"
    return set(out)


def aa_dict(p0, p1, w=W, h=H):
    """{(row, col): weight} of one segment; checks dtypes, uniqueness and (0, 1]."""
    rr, cc, wt = line_coverage_aa(np.array([p0], float), np.array([p1], float), w, h)
    assert rr.dtype == cc.dtype == np.intp and wt.dtype == np.float64
    assert rr.shape == cc.shape == wt.shape
    assert ((wt > 0) & (wt <= 1)).all()
    assert ((rr >= 0) & (rr < h) & (cc >= 0) & (cc < w)).all()
    out = {(r, c): x for r, c, x in zip(rr.tolist(), cc.tolist(), wt.tolist())}
    assert len(out) == len(rr), "a single segment covered a pixel twice"
    return out


def aa_img(p0, p1, w=W, h=H):
    rr, cc, wt = line_coverage_aa(np.array([p0], float), np.array([p1], float), w, h)
    return paint_aa(rr, cc, wt, w, h)


def blank(w=W, h=H):
    return np.zeros((h, w), dtype=np.uint8)


def test_raster_modes():
    assert RASTER_MODES == ("exact", "fast", "aa")


# ---- fast: one test per geometric case --------------------------------------------------


def test_fast_horizontal_includes_both_ends():
    exp = blank()
    exp[3, 2:8] = 1  # cols 2..7: 7 - 2 + 1 = 6 pixels
    assert_array_equal(fast_img((2, 3), (7, 3)), exp)
    assert_array_equal(fast_img((7, 3), (2, 3)), exp)


def test_fast_vertical():
    exp = blank()
    exp[1:7, 4] = 1  # rows 1..6
    assert_array_equal(fast_img((4, 1), (4, 6)), exp)


def test_fast_diagonals():
    exp = blank()
    exp[[1, 2, 3, 4, 5], [1, 2, 3, 4, 5]] = 1
    assert_array_equal(fast_img((1, 1), (5, 5)), exp)
    exp = blank()
    exp[[5, 4, 3, 2, 1], [1, 2, 3, 4, 5]] = 1
    assert_array_equal(fast_img((1, 5), (5, 1)), exp)


def test_fast_shallow_line_ties_go_down():
    # (0,0) -> (4,2): x-major, y = x/2 at cols 0..4: 0, .5, 1, 1.5, 2 -> halves to +y:
    # rows 0, 1, 1, 2, 2 (the module doctest)
    exp = blank(5, 3)
    exp[[0, 1, 1, 2, 2], [0, 1, 2, 3, 4]] = 1
    assert_array_equal(fast_img((0, 0), (4, 2), 5, 3), exp)
    # reversed: the same pixels (the tie rule looks at b, not at the direction)
    assert_array_equal(fast_img((4, 2), (0, 0), 5, 3), exp)
    # rising to the right, (0,2) -> (4,0): y = 2 - x/2: 2, 1.5, 1, .5, 0 -> 2, 2, 1, 1, 0
    exp = blank(5, 3)
    exp[[2, 2, 1, 1, 0], [0, 1, 2, 3, 4]] = 1
    assert_array_equal(fast_img((0, 2), (4, 0), 5, 3), exp)


def test_fast_steep_line_ties_go_left():
    # (2,0) -> (4,8): y-major, x = 2 + y/4 at rows 0..8:
    # 2, 2.25, 2.5, 2.75, 3, 3.25, 3.5, 3.75, 4 -> halves to -x: 2, 2, 2, 3, 3, 3, 3, 4, 4
    exp = blank()
    exp[np.arange(9), [2, 2, 2, 3, 3, 3, 3, 4, 4]] = 1
    assert_array_equal(fast_img((2, 0), (4, 8)), exp)
    assert_array_equal(fast_img((4, 8), (2, 0)), exp)


def test_fast_rounds_ends_half_up():
    # (2.5, 3.49) -> (6.49, 3.5) rounds to (3, 3) -> (6, 4): x-major, n = 3,
    # y = 3 + k/3: 3, 3.33, 3.67, 4 -> rows 3, 3, 4, 4 at cols 3..6
    exp = blank()
    exp[[3, 3, 4, 4], [3, 4, 5, 6]] = 1
    assert_array_equal(fast_img((2.5, 3.49), (6.49, 3.5)), exp)
    # halves go up on both sides of 0 (-0.5 -> 0, not -1) and 0.49999999999999994 -> 0
    # although 0.49999999999999994 + 0.5 == 1.0 in floats
    assert fast_set((-0.5, 0.49999999999999994), (-0.5, 0.49999999999999994)) == {(0, 0)}


@pytest.mark.parametrize("p,pix", [((3.0, 4.0), (4, 3)), ((3.2, 4.4), (4, 3)), ((0.5, 0.5), (1, 1))])
def test_fast_zero_length_draws_its_pixel(p, pix):
    exp = blank()
    exp[pix] = 1
    assert_array_equal(fast_img(p, p), exp)


def test_fast_out_of_bounds_dropped():
    # (-3,2) -> (3,2) in a 5x4 image: cols -3..3 drawn, 0..3 kept
    exp = blank(5, 4)
    exp[2, 0:4] = 1
    assert_array_equal(fast_img((-3, 2), (3, 2), 5, 4), exp)


@pytest.mark.parametrize("p0,p1", [((-10, -10), (-2, -5)), ((20, 3), (30, 3)), ((3, -4), (8, -1))])
def test_fast_segment_fully_outside_draws_nothing(p0, p1):
    assert fast_set(p0, p1) == set()


def test_fast_empty_input():
    rr, cc = line_pixels_fast(np.zeros((0, 2)), np.zeros((0, 2)), W, H)
    assert rr.shape == cc.shape == (0,) and rr.dtype == np.intp


def test_fast_several_segments_at_once_is_union_of_single_calls():
    p0 = np.array([[2, 3], [4, 1], [1, 1], [0.4, 7.6]], float)
    p1 = np.array([[7, 3], [4, 6], [5, 5], [10.2, 9.1]], float)
    rr, cc = line_pixels_fast(p0, p1, W, H)
    assert set(zip(rr.tolist(), cc.tolist())) == set().union(*(fast_set(a, b) for a, b in zip(p0, p1)))


# ---- aa: one test per geometric case ---------------------------------------------------


def test_aa_horizontal_between_centres():
    # (2,3) -> (7,3): cols 2..7; the end pixels are half covered along x
    # (g = 2.5 - 2 = 0.5 and 7 - 6.5 = 0.5), b = 3 exactly: one pixel per column
    assert aa_dict((2, 3), (7, 3)) == {(3, 2): 0.5, (3, 3): 1.0, (3, 4): 1.0, (3, 5): 1.0, (3, 6): 1.0, (3, 7): 0.5}
    exp = blank()
    exp[3, 2:8] = [128, 255, 255, 255, 255, 128]  # floor(255 * 0.5 + 0.5) = 128
    assert_array_equal(aa_img((2, 3), (7, 3)), exp)


def test_aa_horizontal_off_centre_splits_between_rows():
    # y = 3.25 from x = 2 to 5: f = 0.25 -> rows 3 and 4 get 0.75 g and 0.25 g,
    # g = 0.5, 1, 1, 0.5 at cols 2..5
    want = {}
    for c, g in zip(range(2, 6), (0.5, 1, 1, 0.5)):
        want[(3, c)], want[(4, c)] = 0.75 * g, 0.25 * g
    assert aa_dict((2, 3.25), (5, 3.25)) == want
    assert aa_dict((5, 3.25), (2, 3.25)) == want


def test_aa_vertical_and_diagonal_are_y_major():
    assert aa_dict((4, 1), (4, 4)) == {(1, 4): 0.5, (2, 4): 1.0, (3, 4): 1.0, (4, 4): 0.5}
    # |dx| == |dy|: y-major like "exact"; x = y at each row: one pixel per row
    assert aa_dict((1, 1), (4, 4)) == {(1, 1): 0.5, (2, 2): 1.0, (3, 3): 1.0, (4, 4): 0.5}


def test_aa_shallow_line_with_ties():
    # (0,0) -> (4,1): y = x/4 at cols 0..4: 0, .25, .5, .75, 1 (the module doctest)
    assert aa_dict((0, 0), (4, 1), 5, 2) == {
        (0, 0): 0.5,
        (0, 1): 0.75,
        (1, 1): 0.25,
        (0, 2): 0.5,
        (1, 2): 0.5,  # a tie: both halves, both drawn when thresholded
        (0, 3): 0.25,
        (1, 3): 0.75,
        (1, 4): 0.5,
    }
    img = aa_img((0, 0), (4, 1), 5, 2)
    assert_array_equal(img, [[128, 191, 128, 64, 0], [0, 64, 128, 191, 128]])


def test_aa_ends_inside_one_pixel_and_on_pixel_boundaries():
    # both ends in column 3: g = 3.4 - 3.1 = 0.3 (up to float rounding)
    got = aa_dict((3.1, 2.0), (3.4, 2.0))
    assert list(got) == [(2, 3)] and got[(2, 3)] == pytest.approx(0.3, abs=4 * EPS)
    # ends on the boundaries x = 1.5 and 3.5: exactly columns 2 and 3, fully covered
    assert aa_dict((1.5, 2.0), (3.5, 2.0)) == {(2, 2): 1.0, (2, 3): 1.0}


@pytest.mark.parametrize("p", [(3.0, 4.0), (3.2, 4.4), (0.5, 0.5)])
def test_aa_zero_length_covers_nothing(p):
    assert aa_dict(p, p) == {}


def test_aa_out_of_bounds_dropped():
    # y = -0.25: rows -1 (weight 0.25 g, dropped) and 0 (0.75 g); x from 1 to 3 in a 5x3 image
    assert aa_dict((1, -0.25), (3, -0.25), 5, 3) == {(0, 1): 0.375, (0, 2): 0.75, (0, 3): 0.375}
    assert aa_dict((-3, 1), (1, 1), 5, 3) == {(1, 0): 1.0, (1, 1): 0.5}
    assert aa_dict((20, 3), (30, 3), 5, 3) == {}


def test_aa_empty_input():
    rr, cc, wt = line_coverage_aa(np.zeros((0, 2)), np.zeros((0, 2)), W, H)
    assert rr.shape == cc.shape == wt.shape == (0,) and wt.dtype == np.float64
    assert_array_equal(paint_aa(rr, cc, wt, W, H), blank())


def test_aa_several_segments_is_concatenation_and_paint_accumulates():
    p0 = np.array([[2, 3], [2, 3], [1, 1.3]], float)
    p1 = np.array([[7, 3], [7, 3], [9.7, 6.2]], float)
    rr, cc, wt = line_coverage_aa(p0, p1, W, H)
    acc = {}
    for a, b in zip(p0, p1):
        for k, v in aa_dict(a, b).items():
            acc[k] = acc.get(k, 0.0) + v
    got = {}
    for r, c, v in zip(rr.tolist(), cc.tolist(), wt.tolist()):
        got[(r, c)] = got.get((r, c), 0.0) + v
    assert got == pytest.approx(acc, abs=0)
    img = paint_aa(rr, cc, wt, W, H)
    # the doubled segment: 0.5 + 0.5 -> 255 at its ends, 1 + 1 clipped to 1 -> 255 inside
    assert (img[3, 2:8] == 255).all()


def test_paint_aa_rounding_and_threshold():
    rr = np.array([0, 0, 0, 0, 0, 0, 0])
    cc = np.arange(7)
    wt = np.array([0.5, np.nextafter(0.5, 0.0), 1.0, 2 / 255, 0.5 / 255, np.nextafter(0.5 / 255, 0), 1e-300])
    img = paint_aa(rr, cc, wt, 7, 1)
    assert img.dtype == np.uint8
    # floor(255 c + 1/2): 0.5 -> 128 ("drawn"), just below 0.5 -> 127, 2/255 -> 2,
    # 0.5/255 -> 1 (a half rounds up), just below it -> 0
    assert_array_equal(img, [[128, 127, 255, 2, 1, 0, 0]])


# ---- references ----------------------------------------------------------------------------


def round_half_up(v):
    return math.floor(Fraction(v) + Fraction(1, 2))


def nearest(b, minor_is_y):
    """Pixel nearest to the exact Fraction b; halves to +y (minor y) or -x (minor x)."""
    return math.floor(b + Fraction(1, 2)) if minor_is_y else math.ceil(b - Fraction(1, 2))


def naive_fast(p0, p1, w, h, cv2_ties=False):
    """Pixel set of the fast rule, per integer major coordinate, in Fractions.

    With ``cv2_ties``: OpenCV LINE_8's tie rule instead (it walks from the end with the
    smaller x; an x-major tie keeps the row of that end, a y-major tie the column: -x).
    """
    x0, y0, x1, y1 = (round_half_up(v) for v in (*p0, *p1))
    x_major = abs(x1 - x0) > abs(y1 - y0)
    a0, a1, b0, b1 = (x0, x1, y0, y1) if x_major else (y0, y1, x0, x1)
    out = set()
    for i in range(min(a0, a1), max(a0, a1) + 1):
        b = Fraction(b0) if a0 == a1 else b0 + Fraction(i - a0, a1 - a0) * (b1 - b0)
        j = nearest(b, x_major)
        if cv2_ties and x_major and b - math.floor(b) == Fraction(1, 2):
            left_row = y0 if x0 < x1 else y1
            j = math.floor(b) if left_row < b else math.ceil(b)
        r, c = (j, i) if x_major else (i, j)
        if 0 <= r < h and 0 <= c < w:
            out.add((r, c))
    return out


def aa_reference(p0, p1):
    """(x_major, [(i, g, b)]) of the aa rule in Fractions of the float ends (no image bounds)."""
    # the major axis from the float differences, as core computes it
    x_major = abs(p1[0] - p0[0]) > abs(p1[1] - p0[1])
    x0, y0, x1, y1 = (Fraction(v) for v in (*p0, *p1))
    a0, a1, b0, b1 = (x0, x1, y0, y1) if x_major else (y0, y1, x0, x1)
    lo, hi = min(a0, a1), max(a0, a1)
    cols = []
    for i in range(math.floor(lo) - 1, math.ceil(hi) + 2):
        g = min(hi, i + Fraction(1, 2)) - max(lo, i - Fraction(1, 2))
        if g > 0:
            b = b0 + (i - a0) * (b1 - b0) / (a1 - a0)
            cols.append((i, g, b))
    return x_major, cols


# ---- fast: properties ----------------------------------------------------------------------

PW, PH = 40, 30
coord = st.floats(-5.0, 45.0, allow_nan=False, allow_infinity=False)
inside_x = st.floats(-0.49, PW - 0.51)  # rounds to a column 0..PW-1
inside_y = st.floats(-0.49, PH - 0.51)
# halves and quarters make exact ties and exact rounding halves common
grid_coord = st.integers(-20, 180).map(lambda k: k / 4)


@settings(max_examples=300, deadline=None)
@given(
    x0=st.one_of(coord, grid_coord),
    y0=st.one_of(coord, grid_coord),
    x1=st.one_of(coord, grid_coord),
    y1=st.one_of(coord, grid_coord),
)
def test_fast_matches_naive(x0, y0, x1, y1):
    assert fast_set((x0, y0), (x1, y1), PW, PH) == naive_fast((x0, y0), (x1, y1), PW, PH)


@settings(max_examples=300, deadline=None)
@given(x0=inside_x, y0=inside_y, x1=inside_x, y1=inside_y)
def test_fast_in_image_count_ends_connectivity(x0, y0, x1, y1):
    got = fast_set((x0, y0), (x1, y1), PW, PH)
    i0, j0, i1, j1 = (round_half_up(v) for v in (x0, y0, x1, y1))
    assert len(got) == max(abs(i1 - i0), abs(j1 - j0)) + 1
    assert (j0, i0) in got and (j1, i1) in got
    assert eight_connected(got)
    # one pixel per major coordinate
    x_major = abs(i1 - i0) > abs(j1 - j0)
    assert len({c if x_major else r for r, c in got}) == len(got)


@settings(max_examples=300, deadline=None)
@given(
    x0=st.one_of(coord, grid_coord),
    y0=st.one_of(coord, grid_coord),
    x1=st.one_of(coord, grid_coord),
    y1=st.one_of(coord, grid_coord),
)
def test_fast_symmetric_under_reversal(x0, y0, x1, y1):
    # the tie rule depends on b(i) only, and b(i) is the same point in both directions
    assert fast_set((x0, y0), (x1, y1), PW, PH) == fast_set((x1, y1), (x0, y0), PW, PH)


@settings(max_examples=300, deadline=None)
@given(x0=coord, y0=coord, x1=coord, y1=coord)
def test_fast_pixels_within_half_pixel_chebyshev_of_rounded_segment(x0, y0, x1, y1):
    # Bound: pixel (i, j) (major, minor) is drawn at a major coordinate i between the
    # rounded ends, so the point (i, b(i)) lies on the rounded segment, and
    # |j - b(i)| <= 1/2 by the nearest-pixel rule; the Chebyshev distance from the
    # centre to the segment is at most the distance to that point, max(0, |j - b|) <= 1/2.
    # Checked exactly (Fractions), no float slack needed.
    i0, j0, i1, j1 = (round_half_up(v) for v in (x0, y0, x1, y1))
    x_major = abs(i1 - i0) > abs(j1 - j0)
    a0, a1, b0, b1 = (i0, i1, j0, j1) if x_major else (j0, j1, i0, i1)
    for r, c in fast_set((x0, y0), (x1, y1), PW, PH):
        i, j = (c, r) if x_major else (r, c)
        assert min(a0, a1) <= i <= max(a0, a1)
        b = Fraction(b0) if a0 == a1 else b0 + Fraction(i - a0, a1 - a0) * (b1 - b0)
        assert abs(j - b) <= Fraction(1, 2)


@settings(max_examples=200, deadline=None)
@given(x0=grid_coord, y0=grid_coord, x1=grid_coord, y1=grid_coord, ox=st.integers(0, 20), oy=st.integers(0, 20))
def test_fast_out_of_bounds_dropping_equals_cropping_a_larger_canvas(x0, y0, x1, y1, ox, oy):
    # floor(v + 1/2) commutes with whole-pixel shifts (quarters keep v + ox exact)
    small = fast_set((x0, y0), (x1, y1), PW, PH)
    big = fast_set((x0 + ox, y0 + oy), (x1 + ox, y1 + oy), PW + 100, PH + 100)
    assert small == {(r - oy, c - ox) for r, c in big if 0 <= r - oy < PH and 0 <= c - ox < PW}


def test_fast_batches_equal_one_call_per_segment():
    rng = np.random.default_rng(3)
    m = CHUNK_SEGMENTS + 300
    p0 = rng.uniform(-5, 45, size=(m, 2))
    p1 = p0 + rng.uniform(-6, 6, size=(m, 2))
    rr, cc = line_pixels_fast(p0, p1, PW, PH)
    per = [line_pixels_fast(p0[k : k + 1], p1[k : k + 1], PW, PH) for k in range(m)]
    assert_array_equal(rr, np.concatenate([p[0] for p in per]))
    assert_array_equal(cc, np.concatenate([p[1] for p in per]))


# ---- fast against cv2.line (LINE_8) ------------------------------------------------------


def test_fast_against_cv2_line(summary_section):
    """cv2.line LINE_8 on integer ends: same count, same ends, and the same pixels up to
    the tie rule: OpenCV walks from the end with the smaller x and, in an x-major tie,
    keeps that end's row (so "\\"-leaning x-major lines, dx * dy > 0, put ties at -y
    where we put them at +y); its y-major ties go to -x, as ours do.

    F1 bound: a tie at step k needs 2 k db = n (mod 2 n), i.e. with g = gcd(2 db, 2 n)
    (even), g | n and ties every 2 n / g >= 2 steps, never at k = 0 or n: at most
    n/2 of the n + 1 pixels (n even) differ, so F1 = (n + 1 - t) / (n + 1) > 1/2.
    """
    cv2 = pytest.importorskip("cv2")
    rng = np.random.default_rng(11)
    w, h = 64, 48
    n_seg, identical, f1s = 1500, 0, []
    for _ in range(n_seg):
        p0, p1 = rng.integers(0, [w, h]), rng.integers(0, [w, h])
        ref = np.zeros((h, w), np.uint8)
        cv2.line(ref, (int(p0[0]), int(p0[1])), (int(p1[0]), int(p1[1])), 255, 1, cv2.LINE_8)
        theirs = set(zip(*(a.tolist() for a in np.nonzero(ref))))
        ours = fast_set(tuple(p0.tolist()), tuple(p1.tolist()), w, h)
        assert len(ours) == len(theirs)
        assert {(p0[1], p0[0]), (p1[1], p1[0])} <= ours & theirs
        assert theirs == naive_fast(p0.tolist(), p1.tolist(), w, h, cv2_ties=True)
        f1 = len(ours & theirs) / len(ours)  # equal sizes: F1 = precision = recall
        assert f1 > 0.5
        f1s.append(f1)
        identical += ours == theirs
    f1s = np.array(f1s)
    summary_section(
        "fast raster vs cv2.line LINE_8 (integer ends, 64x48)",
        f"{n_seg} segments: identical {identical} ({identical / n_seg:.1%}), "
        f"F1@0 mean {f1s.mean():.4f} min {f1s.min():.4f}",
    )


# ---- aa: properties ----------------------------------------------------------------------

# interior segments: ends in [1, W-2] x [1, H-2], so every pixel the rule touches
# (the line at the end columns is extrapolated by <= 1/2 along the major axis, hence
# <= 1/2 along the minor: b in [1/2, H - 3/2], pixels floor(b), floor(b) + 1 in
# [0, H - 1]) is inside the image and nothing is dropped
int_x = st.floats(1.0, PW - 2.0)
int_y = st.floats(1.0, PH - 2.0)
grid_x = st.integers(4, 4 * (PW - 2)).map(lambda k: k / 4)
grid_y = st.integers(4, 4 * (PH - 2)).map(lambda k: k / 4)
TIE_BAND = Fraction(1, 10**9)  # b is computed in floats (error ~1e-14 px here)


@settings(max_examples=200, deadline=None)
@given(
    x0=st.one_of(int_x, grid_x), y0=st.one_of(int_y, grid_y), x1=st.one_of(int_x, grid_x), y1=st.one_of(int_y, grid_y)
)
def test_aa_weights_threshold_and_total(x0, y0, x1, y1):
    got = aa_dict((x0, y0), (x1, y1), PW, PH)
    x_major, cols = aa_reference((x0, y0), (x1, y1))
    by_major = {}
    for (r, c), wt in got.items():
        by_major.setdefault(c if x_major else r, {})[r if x_major else c] = wt
    assert set(by_major) <= {i for i, _, _ in cols}
    n_cols = len(cols)
    for i, g, b in cols:
        ws = by_major.get(i, {})
        # the pair (1 - f) g + f g = g; interior steps g = 1: (1 - f) is rounded once
        # (<= eps/2), f exact, the float sum once more: |sum - 1| <= eps. End steps: g has
        # one rounding, each product one more: <= 4 eps.
        assert sum(ws.values()) == pytest.approx(float(g), abs=(1 if g == 1 else 4) * EPS)
        f = b - math.floor(b)
        drawn = {j for j, wt in ws.items() if wt >= 0.5}
        near = nearest(b, x_major)
        if abs(f - Fraction(1, 2)) <= TIE_BAND:
            assert drawn <= {math.floor(b), math.floor(b) + 1}
            if g == 1:
                assert drawn
        elif g == 1:
            assert drawn == {near}  # interior: the nearest pixel, and only it
        else:
            assert drawn <= {near}  # end pixel: g < 1 may drop it
    # total coverage = sum of g = a_hi - a_lo (telescoping). Tolerance: each column's
    # pair is within 4 eps of g (above), and the float sum of 2 n_cols terms, partial
    # sums <= 2 n_cols, adds <= 2 n_cols * (2 n_cols) eps in the worst (sequential) case.
    length = abs(x1 - x0) if x_major else abs(y1 - y0)
    total = float(np.sum(list(got.values())))
    assert total == pytest.approx(length, abs=(4 * n_cols + 4 * n_cols * n_cols) * EPS + 2 * EPS * PW)


@settings(max_examples=200, deadline=None)
@given(x0=coord, y0=coord, x1=coord, y1=coord)
def test_aa_symmetric_under_reversal_and_thresholds_like_paint(x0, y0, x1, y1):
    fwd = aa_dict((x0, y0), (x1, y1), PW, PH)
    assert fwd == aa_dict((x1, y1), (x0, y0), PW, PH)  # computed from the lower end: bit-equal
    img = aa_img((x0, y0), (x1, y1), PW, PH)
    drawn = {(r, c) for r, c in zip(*(a.tolist() for a in np.nonzero(img >= 128)))}
    assert drawn == {k for k, v in fwd.items() if v >= 0.5}


def test_aa_long_interior_segment_total_coverage():
    # a 30-px x-major segment: columns 5..35, coverage sums to 30.0 up to the bound above
    got = aa_dict((5.3, 7.1), (35.3, 19.4), PW, PH)
    n_cols = 31
    assert sum(got.values()) == pytest.approx(30.0, abs=(4 * n_cols + 4 * n_cols**2) * EPS)


def test_aa_batches_equal_one_call_per_segment():
    rng = np.random.default_rng(4)
    m = CHUNK_SEGMENTS + 300
    p0 = rng.uniform(-5, 45, size=(m, 2))
    p1 = p0 + rng.uniform(-6, 6, size=(m, 2))
    got = line_coverage_aa(p0, p1, PW, PH)
    per = [line_coverage_aa(p0[k : k + 1], p1[k : k + 1], PW, PH) for k in range(m)]
    for a, k in zip(got, range(3)):
        assert_array_equal(a, np.concatenate([p[k] for p in per]))


@pytest.mark.parametrize("n", [50, 5000])  # 50*8 < 40*30: sparse path; 5000*8 >= 1200: dense path
def test_paint_aa_both_accumulation_paths_equal_an_in_order_reference(n):
    # np.add.at sums in input order, as bincount does on both paths: bit-identical.
    rng = np.random.default_rng(n)
    w, h = 40, 30
    rr, cc = rng.integers(0, h, n), rng.integers(0, w, n)
    weight = rng.uniform(0.0, 0.7, n)
    acc = np.zeros((h, w))
    np.add.at(acc, (rr, cc), weight)
    expected = np.floor(np.clip(acc, 0, 1) * 255 + 0.5).astype(np.uint8)
    assert_array_equal(paint_aa(rr, cc, weight, w, h), expected)
