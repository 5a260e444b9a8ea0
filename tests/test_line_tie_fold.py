"""A binary line exactly between two pixels (oracles.judge.line_ties.fold_ties): either column is right.

Hand-built frames measured by oracles.judge.line_style.measure; the expected
offsets are worked out in the comments (pixel centres at whole numbers,
core.conventions): a 1-px line at x = 319.5 must be drawn in column 319 or
320, whose centroid is half a pixel to either side; the tie reads 0 for both,
a line a whole pixel off still reads half a pixel, and a line off the tie is
measured as before.
"""

import numpy as np
import pytest
from wirecheck.oracles.judge import line_style, line_ties

H, W = 64, 640


def _vertical(x_exact, cols, y0=56.0, y1=8.0):
    """The offsets of a vertical segment at ``x_exact`` (drawn upwards: unit (0, -1), normal (1, 0), so an
    offset is the centroid's x less ``x_exact``) over one image where ``cols`` are drawn, folded as a binary
    line ``len(cols)`` pixels across."""
    img = np.zeros((H, W))
    img[:, cols] = 1.0
    segs = np.array([[[x_exact, y0], [x_exact, y1]]])
    got = line_style.measure(img, segs)
    assert len(got["offset"]) >= 30  # 48 rows less the guard at each end: a real sample
    line_ties.fold_ties(got, len(cols))
    return got["offset"]


@pytest.mark.parametrize("col", [319, 320])
def test_either_column_of_a_tie_reads_zero(col):
    # centroid 319 or 320 against 319.5: -0.5 or +0.5 before the fold, 0 after (either choice is right)
    assert np.abs(_vertical(319.5, [col])).max() < 1e-12


def test_a_line_a_whole_pixel_off_a_tie_still_reads_half_a_pixel():
    # column 321 against 319.5: e = 1.5, folded by half a pixel: 1.0. Column 318: e = -1.5 -> -1.0
    assert _vertical(319.5, [321]) == pytest.approx(1.0, abs=1e-12)
    assert _vertical(319.5, [318]) == pytest.approx(-1.0, abs=1e-12)


def test_off_the_tie_nothing_is_folded():
    # x = 319.4 is 0.1 px from the tie (far beyond (1 + 0) 2^-8 px): column 320 reads 0.6, column 319 -0.4
    assert _vertical(319.4, [320]) == pytest.approx(0.6, abs=1e-9)
    assert _vertical(319.4, [319]) == pytest.approx(-0.4, abs=1e-9)


def test_an_even_width_ties_on_a_pixel_centre():
    # a 2-px band at x = 320 (edges 319 and 321, both pixel centres): columns 319-320 or 320-321, centroid
    # 319.5 or 320.5: +-0.5 -> 0. At x = 319.5 a 2-px line has one band (319, 320), no tie: columns 320-321
    # are a whole pixel off and read 1.0
    assert np.abs(_vertical(320.0, [319, 320])).max() < 1e-12
    assert np.abs(_vertical(320.0, [320, 321])).max() < 1e-12
    assert _vertical(319.5, [320, 321]) == pytest.approx(1.0, abs=1e-9)


# ---- ties at a segment's ends (oracles.judge.line_ties.drop_end_ties) ----


def _samples(segment, n):
    """``n`` hand-built samples of segment index ``segment`` (offsets 0.5: a half-pixel offset)."""
    return {
        "offset": np.full(n, 0.5),
        "normal": np.tile([1.0, 0.0], (n, 1)),
        "point": np.zeros((n, 2)),
        "width": np.ones(n),
        "mass": np.ones(n),
        "segment": np.full(n, segment, np.intp),
        "windows": n,
        "found": n,
    }


def _join(*parts):
    return {
        k: (np.concatenate([p[k] for p in parts]) if isinstance(parts[0][k], np.ndarray) else sum(p[k] for p in parts))
        for k in parts[0]
    }


# segment 0 ends at x = 319.5 (a boundary: columns 319 and 320 equally near); segment 1 nowhere near one:
# x = 319.4 is 0.1 px from it, y = 40.3 0.2 px, far beyond TIE_END_PX = 2^-8 px
SEGS = np.array([[[319.5, 10.0], [359.8, 40.0]], [[319.4, 10.0], [359.8, 40.3]]])


def test_end_ties_are_ends_on_a_pixel_boundary():
    assert list(line_ties.end_ties(SEGS)) == [True, False]
    # within 2^-8 px of the boundary still a tie (a renderer's snap and float32 rounding); 2^-7 px off not
    assert list(line_ties.end_ties(SEGS + [[[2**-9, 0], [0, 0]], [[0, 0], [0, 0.2]]])) == [True, True]
    assert list(line_ties.end_ties(SEGS[:1] + [[[2**-7, 0], [0, 0]]])) == [False]


def test_the_lines_of_tied_ends_are_left_out_and_the_others_kept():
    got = _join(_samples(0, 30), _samples(1, 20))
    line_ties.drop_end_ties(got, SEGS)
    # segment 0's 30 samples left out, every array alike; segment 1's 20 kept with their half-pixel offset;
    # the windows looked at are still counted
    assert list(got["segment"]) == [1] * 20 and len(got["point"]) == len(got["width"]) == 20
    assert list(got["offset"]) == [0.5] * 20 and (got["windows"], got["found"]) == (50, 50)


def test_a_frame_whose_every_line_ties_keeps_them_all():
    got = _samples(0, 30)
    line_ties.drop_end_ties(got, SEGS[:1])
    assert len(got["offset"]) == 30
