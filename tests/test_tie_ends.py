"""Ties at line ends: an end within GL's sub-pixel precision of its pixel's diamond is undecided in every criterion.

A line's last pixel ``P`` is drawn when the segment exits ``P``'s diamond
(``|x - P_x| + |y - P_y| < 1/2``): with the end on the diamond's exit side,
exactly when ``|E - P|_1 >= 1/2``. The oracle's ends are within TIE_END_PX
(2^-8 px) per coordinate of exact (oracles/tolerances.py), so
``|E - P|_1`` within ``2 TIE_END_PX = 2^-7`` of 1/2 is the oracle's rounding,
not the line's (oracles.judge.line_ties.tie_ends). Such a pixel is left out
of the balance, and the candidate is given the oracle's value there for
F1@0px and the per-edge counts; a pixel outside that zone stays decided.
Expected values are worked out by hand in the comments.
"""

import numpy as np
import pytest
from wirecheck.oracles import tolerances
from wirecheck.oracles.judge import line_ties, metrics

ZONE = 2 * 2.0**-8  # 2 TIE_END_PX: an end moved by 2^-8 per coordinate moves |E - P|_1 by 2^-7


def vertical(y_end, h=10, w=8):
    """The segment x = 3.2 from y = 0 to ``y_end`` (5.3 +- a little): its last pixel (3, 5) has
    |E - P|_1 = 0.2 + (y_end - 5), 1/2 at y_end = 5.3, the diamond's exit (the segment goes on
    downwards, away from (3, 5)). The oracle draws rows 0..5 (``oracle_last`` 5) or 0..4 (4)."""
    p0, p1 = np.array([[3.2, 0.0]]), np.array([[3.2, y_end]])
    return p0, p1


def column(rows, h=10, w=8):
    img = np.zeros((h, w), bool)
    img[: rows + 1, 3] = True
    return img


def test_tie_end_zone_is_twice_tie_end_px():
    assert tolerances.TIE_END_PX * 2 == ZONE


@pytest.mark.parametrize(
    "y_end, oracle_last, cand_last, side",
    [
        (5.3 + 0.9 * ZONE, 5, 4, "oracle"),  # end 0.9 zone past the exit: the oracle drew row 5, the candidate not
        (5.3 - 0.9 * ZONE, 4, 5, "candidate"),  # end 0.9 zone before it: the oracle stopped at row 4, the candidate not
    ],
)
def test_an_end_within_the_zone_is_a_tie_in_every_criterion(y_end, oracle_last, cand_last, side):
    p0, p1 = vertical(y_end)
    cand, oracle = column(cand_last), column(oracle_last)
    s = metrics.line_scores(cand, oracle, p0, p1)
    one = [1, 0] if side == "candidate" else [0, 1]
    assert [s["candidate_only"], s["oracle_only"]] == one
    assert s["subpixel_ties"] == one  # the balance: left out as a tie
    assert s["ends"] == {"start": [0, 0], "end": [0, 0], "middle": [0, 0], "stray": [0, 0]}
    # F1@0px as drawn: 5 shared pixels of 5 and 6 -> P R with one side 5/6 -> F1 = 2 (5/6) / (1 + 5/6) = 10/11
    assert metrics.pixel_scores(cand, oracle)["f1_0px"] == pytest.approx(10 / 11, abs=1e-15)
    assert s["tie_resolved"] == {"f1_0px": 1.0, "precision_0px": 1.0, "recall_0px": 1.0}
    assert s["edge_count_max_diff"] == 0  # the raw count differs by 1 (next test)
    summary = metrics.line_summary([(1, s)])
    assert summary["subpixel_ties"] == one and summary["imbalance"] == 0 and summary["balance_p_value"] == 1.0


@pytest.mark.parametrize(
    "y_end, oracle_last, cand_last",
    [
        (5.3 + 1.1 * ZONE, 5, 4),  # just outside the zone: the oracle's row 5 is the line's, the candidate lost it
        (5.3 + 0.1, 5, 4),
    ],
)
def test_an_end_outside_the_zone_stays_decided(y_end, oracle_last, cand_last):
    p0, p1 = vertical(y_end)
    cand, oracle = column(cand_last), column(oracle_last)
    s = metrics.line_scores(cand, oracle, p0, p1)
    assert (s["oracle_only"], s["subpixel_ties"]) == (1, [0, 0])
    assert s["ends"]["end"] == [0, 1]  # decided, at the line's end
    assert s["tie_resolved"] is None  # no tie: F1@0px as drawn, 10/11
    assert s["edge_count_max_diff"] == 1


def test_only_the_exit_side_of_the_diamond_ties():
    # E = (3.2, 5.3 + 0.9 zone), |E - (3, 5)|_1 within the zone of 1/2. As the start of a segment going
    # up (towards row 0) the L1 distance from (3, 5) falls along it: E is on the diamond's entry side, and
    # the segment crosses the diamond whichever side of 1/2 E lies: (3, 5) is drawn either way, no tie
    e = np.array([[3.2, 5.3 + 0.9 * ZONE]])
    up = np.array([[3.2, 0.0]])
    q = np.array([[3.0, 5.0]])
    assert not line_ties.tie_ends(q, e, up)[0]
    # the same point as the segment's end (coming down from row 0): exit side, a tie
    assert line_ties.tie_ends(q, up, e)[0]
    # and as a start going down (leaving the diamond at once): exit side, a tie
    down = np.array([[3.2, 9.0]])
    assert line_ties.tie_ends(q, e, down)[0]


def test_an_end_at_the_image_border_decides_nothing():
    # a line leaving the picture at the top is cut at y = -1/2 for the comparison: not an end of the
    # line (GL draws on past the border). x = 3: pixel (3, 0) has |E - P|_1 = 0 + 1/2 exactly, on the
    # exit side of the segment going up, yet the crossing decides it: the oracle drew it, the candidate
    # did not -> a decided oracle-only pixel
    p0, p1 = np.array([[3.0, 6.0]]), np.array([[3.0, -40.0]])
    oracle = np.zeros((10, 8), bool)
    oracle[:7, 3] = True
    cand = oracle.copy()
    cand[0, 3] = False
    s = metrics.line_scores(cand, oracle, p0, p1)
    assert (s["oracle_only"], s["subpixel_ties"]) == (1, [0, 0])
    # without the border (box None), the cut end would have been taken for a tie
    assert line_ties.tie_ends(np.array([[3.0, 0.0]]), p0, np.array([[3.0, -0.5]]))[0]
    assert not line_ties.tie_ends(np.array([[3.0, 0.0]]), p0, np.array([[3.0, -0.5]]), box=((-0.5, -0.5), (7.5, 9.5)))[
        0
    ]
