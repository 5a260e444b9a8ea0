"""The line measure's windows (oracles.judge.line_windows) against a window-by-window reference.

The reference enumerates the windows from their definition (line_style.windows' docstring): every
integer step of a segment's major axis GUARD_PX clear of its ends, inside the image with its whole
window, and farther than GUARD_PX from every other segment, that distance found point by point
with Python's own arithmetic (math.hypot): no numpy array, no interval, no bounding box. The
segment sets are drawn at random with a fixed seed, shifted to integer and half-integer positions
so that lines meet and run side by side (junctions, parallel lines at 4 and 5 px).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from wirecheck.oracles.judge.line_style import GUARD_PX, PROFILE_RADIUS_PX, windows

W, H = 220, 140


def _distance(px, py, a, b) -> float:
    abx, aby = b[0] - a[0], b[1] - a[1]
    len2 = abx * abx + aby * aby
    t = 0.0 if len2 == 0 else min(max(((px - a[0]) * abx + (py - a[1]) * aby) / len2, 0.0), 1.0)
    return math.hypot(a[0] + t * abx - px, a[1] + t * aby - py)


def _reference(segs) -> list:
    """``(segment, major position, exact minor)`` of every window, segment by segment, ascending."""
    out = []
    r = PROFILE_RADIUS_PX
    for s, (a, b) in enumerate(segs):
        d = b - a
        length = math.hypot(d[0], d[1])
        if length < 2 * GUARD_PX + 1:
            continue
        major = 0 if abs(d[0]) >= abs(d[1]) else 1
        minor = 1 - major
        along = GUARD_PX * abs(d[major]) / length
        lo = max(math.ceil(min(a[major], b[major]) + along), 0)
        hi = min(math.floor(max(a[major], b[major]) - along), (W, H)[major] - 1)
        for pos in range(lo, hi + 1):
            exact = a[minor] + (pos - a[major]) * d[minor] / d[major]
            centre = round(exact)
            if centre - r < 0 or centre + r > (H, W)[major] - 1:
                continue
            p = (pos, exact) if major == 0 else (exact, pos)
            if all(_distance(p[0], p[1], segs[o][0], segs[o][1]) > GUARD_PX for o in range(len(segs)) if o != s):
                out.append((s, pos, exact))
    return out


def _segment_sets():
    rng = np.random.default_rng(23)
    sets = []
    for n in (1, 2, 3, 5, 8, 12, 20):
        for _ in range(4):
            segs = rng.uniform(-40, 260, (n, 2, 2))
            segs[: n // 2] = np.round(segs[: n // 2] * 2) / 2  # half pixels: lines meet, run side by side
            sets.append(segs)
    # a square's frame, lines 4 and 5 px apart (one pair nearer than GUARD_PX = 4.5, one farther), a crossing
    sets.append(
        np.array(
            [
                [[20, 20], [200, 20]],
                [[200, 20], [200, 120]],
                [[200, 120], [20, 120]],
                [[20, 120], [20, 20]],
                [[30, 60], [190, 60]],
                [[30, 64], [190, 64]],
                [[30, 90], [190, 90]],
                [[30, 95], [190, 95]],
                [[60, 30], [150, 110]],
            ],
            dtype=float,
        )
    )
    # a segment past 1e150 px (its squared length overflows: every distance to it is NaN, which drops the window)
    sets.append(np.array([[[-1e200, 60], [1e200, 60]], [[20, 63], [200, 63]], [[20, 100], [200, 100]]]))
    return sets


@pytest.mark.parametrize("k", range(len(_segment_sets())))
def test_windows_are_those_of_the_definition(k):
    segs = _segment_sets()[k]
    got = windows(segs, (H, W))
    expected = _reference(segs)
    major_of = lambda s: 0 if abs(segs[s][1][0] - segs[s][0][0]) >= abs(segs[s][1][1] - segs[s][0][1]) else 1
    pos = [int(p[major_of(s)]) for s, p in zip(got["segment"], got["point"])]
    assert list(zip(got["segment"].tolist(), pos)) == [(s, p) for s, p, _ in expected]
    # the exact line's minor coordinate: the same formula, float64 both (a few ulps of 250 px)
    assert np.allclose(got["exact"], [e for _, _, e in expected], rtol=0, atol=1e-9)
    # each window's pixels: 2 r + 1 across the line, centred on the rounded exact line, at the step, as
    # flat indices y W + x (a horizontal line's window is a column: rows centre - r .. centre + r)
    r = PROFILE_RADIUS_PX
    flat = [
        [(round(e) + o) * W + p if major_of(s) == 0 else p * W + round(e) + o for o in range(-r, r + 1)]
        for s, p, e in expected
    ]
    assert got["flat"].shape == (len(expected), 2 * r + 1) and got["flat"].tolist() == flat


def test_the_reference_sees_junctions():
    # the hand-made set (lines 4 px apart: within GUARD_PX) loses windows to its junctions; a lone
    # segment keeps every step GUARD_PX clear of its ends: 180 px long, steps 25..195 (171 windows)
    frame = _segment_sets()[-2]
    assert len(_reference(frame[4:6])) == 0 < len(_reference(frame[6:8]))
    assert len(windows(np.array([[[20.0, 70.0], [200.0, 70.0]]]), (H, W))["segment"]) == 171
