"""oracles.judge.segment_pixels: each pixel's nearest segment, decided on the exact distances.

The pairing compares squared distances first and measures ``hypot`` only where
they could decide differently (a radius test on the boundary, a pixel with two
candidates within D2_SLACK). The reference below is the definition, every pair
measured: the module's distance formula (its docstring's floats, in its order of
operations), the nearest within the radius, ties to the lower index.
"""

import numpy as np
import pytest
from wirecheck.oracles.judge import segment_pixels
from wirecheck.oracles.judge.segment_pixels import frames_neighbourhoods


def _owners_naive(p0, p1, w, h, pixels, radius=1.0):
    """``(edge, pixel)`` rows: every (pixel, segment) distance as the module defines it, elementwise
    (``u = clip((ex dx + ey dy) / dd, 0, 1)``, 0 for a segment of no length; ``hypot(ex - u dx, ey - u dy)``),
    the least within ``radius``, ties to the lower index (``argmin``: the first)."""
    keep = np.isfinite(p0).all(axis=1) & np.isfinite(p1).all(axis=1)
    edges = np.flatnonzero(keep)
    a, d = p0[keep], p1[keep] - p0[keep]
    x = (pixels % w).astype(np.float64)[:, None]
    y = (pixels // w).astype(np.float64)[:, None]
    ex, ey = x - a[:, 0], y - a[:, 1]
    dx, dy = d[:, 0], d[:, 1]
    dd = dx * dx + dy * dy
    with np.errstate(divide="ignore", invalid="ignore"):
        u = (ex * dx + ey * dy) / dd
    u = np.clip(np.where(dd == 0, 0.0, u), 0.0, 1.0)
    dist = np.hypot(ex - u * dx, ey - u * dy)
    best = np.argmin(dist, axis=1)
    near = dist[np.arange(len(pixels)), best] <= radius
    return list(zip(edges[best[near]].tolist(), pixels[near].tolist())), dist


def _hostile(rng, w, h, step):
    """Segments of a small mesh: ends on a grid of ``step`` px (0: anywhere; 1: on pixel centres), shared by
    several segments, some repeated, reversed, of no length or 1e-9 px long; every end inside the box the
    pairing clips to (so the segments are its floats)."""
    pts = rng.uniform(-1.5, [w + 0.5, h + 0.5], (int(rng.integers(4, 14)), 2))
    if step:
        pts = np.round(pts / step) * step
    e = rng.integers(0, len(pts), (int(rng.integers(6, 30)), 2))
    p0, p1 = pts[e[:, 0]], pts[e[:, 1]]
    p0, p1 = np.concatenate([p0, p1[:3], p0[:2]]), np.concatenate([p1, p0[:3], p1[:2]])  # reversed, repeated
    p1[-1] = p0[-1] + 1e-9
    return p0, p1


@pytest.mark.parametrize("step", [1.0, 0.5, 0.25, 0.0], ids=["centres", "halves", "quarters", "anywhere"])
@pytest.mark.parametrize(
    "path",
    ["radius only", "1/2 first", "1/8 first", "chunks of 7 pairs"],
)
def test_owners_equal_every_pair_measured_on_hostile_frames(monkeypatch, step, path):
    """The rows (each pixel's owner) equal the definition's on frames made of ties: ends on pixel centres,
    half and quarter pixels (distances tied exactly) or anywhere (shared ends: a pixel nearest a shared end
    is as near to each segment there but for the last bit of each distance's rounding), under each of the
    pairing's paths (looked for within 1/2 or 1/8 first, folded over many chunks)."""
    monkeypatch.setattr(segment_pixels, "LEVEL_PIXELS", 10**9 if path == "radius only" else 0)
    monkeypatch.setattr(segment_pixels, "CROWDED", 0 if path == "1/8 first" else 10**9)
    if path.startswith("chunks"):
        monkeypatch.setattr(segment_pixels, "CHUNK_PAIRS", 7)
    rng = np.random.default_rng(int(step * 8) + 3)
    w, h = 22, 16
    ties = near_ties = 0
    for _ in range(12):
        p0, p1 = _hostile(rng, w, h, step)
        pixels = np.arange(w * h)
        edge, pixel, _major = frames_neighbourhoods([(p0, p1, pixels)], w, h)[0]
        expected, dist = _owners_naive(p0, p1, w, h, pixels)
        assert list(zip(edge.tolist(), pixel.tolist())) == expected
        least = dist.min(axis=1, keepdims=True)
        ties += int(((dist == least).sum(axis=1) > 1).sum())
        near_ties += int((((dist > least) & (dist <= least * (1 + 1e-12))).sum(axis=1) > 0).sum())
    # the frames hold what the test is about: pixels with two segments at the least distance, and (off the
    # grid) pixels where another segment's distance is within rounding of the least but not equal
    assert ties > 0
    if step == 0.0:
        assert near_ties > 0


def test_a_segment_beyond_the_right_edge_in_the_last_row_lists_no_column():
    """A segment 1.9 px right of the image, in its bottom rows, looked at within 1/2 px: its columns start
    past the right edge (ceil(x - 1/2) = W + 1), where the stacked pixels' rank table ends (it raised an
    IndexError before). It owns no pixel (1.9 px from the nearest centre), so the rows are those without it."""
    w, h = 64, 48
    x = np.arange(w, dtype=np.float64)
    p0 = np.column_stack([x, np.zeros(w)])  # a vertical line down each column: every pixel drawn
    p1 = np.column_stack([x, np.full(w, h - 1.0)])
    beyond = np.array([[w + 0.9, h - 2.0]]), np.array([[w + 0.9, h - 1.0]])
    pixels = np.arange(w * h)
    with_it = frames_neighbourhoods([(np.vstack([p0, beyond[0]]), np.vstack([p1, beyond[1]]), pixels)], w, h)[0]
    without = frames_neighbourhoods([(p0, p1, pixels)], w, h)[0]
    for a, b in zip(with_it, without):
        np.testing.assert_array_equal(a, b)
    assert len(with_it[1]) == w * h  # each pixel on its column's line


def test_a_segment_beyond_the_left_edge_in_the_first_row_pairs_only_its_own_frame(monkeypatch):
    """Two frames stacked: the first frame's steep segment starts left of its top-left corner, its part near row 0
    left of x = -1.5, so that row's slice ends at column floor(-1.795 + 1/2) = -2, clipped to -1 (before: the rank
    table's index -1, its last entry, listed every pixel of both frames for it, and the second frame's pixels
    near the same place in their own frame, where it has no segment, were given to it). Each frame's rows must
    be the definition's."""
    monkeypatch.setattr(segment_pixels, "LEVEL_PIXELS", 0)  # within 1/2 first, as for many pixels
    w, h = 40, 30
    line = np.array([[-1.9, -0.6]]), np.array([[1.0, 30.0]])  # x = -1.795 at y = 1/2; in the image from y = 19.5
    # vertical lines down columns 30..39 of both frames: many slices, so the rank table is used
    grid = np.array([[30.0 + k, 0.0] for k in range(10)]), np.array([[30.0 + k, h - 1.0] for k in range(10)])
    first = (np.vstack([line[0], grid[0]]), np.vstack([line[1], grid[1]]), np.arange(w * h))
    second = (grid[0], grid[1], np.arange(w * h))
    got = frames_neighbourhoods([first, second], w, h)
    for (p0, p1, pixels), (edge, pixel, _major) in zip([first, second], got):
        assert list(zip(edge.tolist(), pixel.tolist())) == _owners_naive(p0, p1, w, h, pixels)[0]


@pytest.mark.parametrize("table", [True, False], ids=["rank table", "binary search"])
def test_rank_equals_searchsorted_beyond_the_pixels_first_and_last(table):
    """_Pixels.rank, the count of pixels before each stacked flat index, is ``np.searchsorted``'s on sparse
    pixels of two stacked frames, for queries before the first pixel (down to -1, a slice clipped to column
    -1 of the first row), on and between pixels, and after the last (up to the stack's end, frames H W): its
    table spans only the pixels' own range, [first, last + 1], and a query outside reads 0 or every pixel."""
    rng = np.random.default_rng(37)
    w, h = 30, 20
    per_frame = [np.sort(rng.choice(np.arange(5 * w, 15 * w), 40, replace=False)) for _ in range(2)]
    px = segment_pixels._Pixels.of_frames(per_frame, w, h)
    queries = np.concatenate([np.arange(-1, 2 * w * h + 1), px.stacked, px.stacked + 1, px.stacked - 1])
    got = px.rank(queries, expected=10**9 if table else 0)
    assert (px._rank is not None) == table  # the path under test was taken
    np.testing.assert_array_equal(got, np.searchsorted(px.stacked, queries))
