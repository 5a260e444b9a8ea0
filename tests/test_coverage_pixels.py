"""Which pixels of an antialiased frame are drawn (oracles.judge.coverage_pixels): hand-built rows.

Expected values from the rule: drawn at grey >= 128, or at a ridge (at least
both neighbours in the row and more than one, or the same in the column) of grey >= ridge_min() =
int(255 * 0.5 / 2) = 63, the coverage a 0.5-px line leaves in each of two
pixels it falls between (0.25 of 255 = 63.75, rounded down).
"""

import numpy as np
from wirecheck.oracles.judge import coverage_pixels


def _row(values, rows=5):
    """A vertical antialiased line: the same row of grey levels repeated (columns 0..)."""
    return np.tile(np.array(values, np.uint8), (rows, 1))


def test_ridge_min_is_a_quarter_of_full_coverage_rounded_down():
    assert coverage_pixels.ridge_min() == 63


def test_a_1px_line_between_two_pixels_is_drawn_in_both():
    # 127 | 127 (a renderer rounding 127.5 down): both are ridges (each >= its neighbours 0 and 127)
    got = coverage_pixels.drawn(_row([0, 0, 127, 127, 0, 0]))
    assert got[:, [2, 3]].all() and not got[:, [0, 1, 4, 5]].any()


def test_the_fringe_beside_a_brighter_pixel_is_not_drawn():
    # a line at 2.7: coverage 0.3 | 0.7 -> 76 | 178; 76 lies beside a brighter pixel (no ridge across the
    # line; along it, down the column, the coverage stays level: no ridge either) and under 128
    # (rows 1-3: on the first and last row the line ends, and its fringe is a ridge down the column)
    got = coverage_pixels.drawn(_row([0, 0, 76, 178, 0, 0]))[1:-1]
    assert got[:, 3].all() and not got[:, [0, 1, 2, 4, 5]].any()
    # a 2-px line at 3.0: 127 | 255 | 127: the fringes are no ridge, the centre is drawn by the 128 rule
    got = coverage_pixels.drawn(_row([0, 0, 127, 255, 127, 0]))[1:-1]
    assert got[:, 3].all() and not got[:, [0, 1, 2, 4, 5]].any()


def test_a_half_pixel_line_is_read_and_a_thinner_one_is_not():
    # 0.5 px between two pixels: 63 | 63 (63.75 rounded down) drawn; 0.4 px: 51 | 51 is not
    assert coverage_pixels.drawn(_row([0, 63, 63, 0]))[:, [1, 2]].all()
    assert not coverage_pixels.drawn(_row([0, 51, 51, 0])).any()


def test_a_ridge_along_a_column_counts_too():
    # a horizontal line between rows 1 and 2 (127 over 127): ridges down each column
    img = np.zeros((4, 5), np.uint8)
    img[1:3] = 127
    got = coverage_pixels.drawn(img)
    assert got[1:3].all() and not got[[0, 3]].any()
