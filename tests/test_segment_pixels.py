"""oracles.judge.segment_pixels: each pixel's nearest segment, decided on the exact distances.

The pairing compares squared distances first and measures ``hypot`` only where
they could decide differently (a radius test on the boundary, a pixel with two
candidates within D2_SLACK). The reference below is the definition, every pair
measured: the module's distance formula (its docstring's floats, in its order of
operations), the nearest within the radius, ties to the lower index.
"""

import numpy as np
import pytest
from pairing_reference import owners_naive as _owners_naive
from wirecheck.oracles.judge import owner_kernel, segment_pixels
from wirecheck.oracles.judge.frame_pixels import FramePixels
from wirecheck.oracles.judge.segment_pixels import frames_neighbourhoods


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
    [
        "radius only",
        "1/2 first",
        "1/8 first",
        "chunks of 7 pairs",
        "compiled, radius only",
        "compiled, 1/2 first",
        "compiled, 1/8 first",
    ],
)
def test_owners_equal_every_pair_measured_on_hostile_frames(monkeypatch, step, path):
    """The rows (each pixel's owner) equal the definition's on frames made of ties: ends on pixel centres,
    half and quarter pixels (distances tied exactly) or anywhere (shared ends: a pixel nearest a shared end
    is as near to each segment there but for the last bit of each distance's rounding), under each of the
    pairing's paths (looked for within 1/2 or 1/8 first, folded over many chunks; the numpy pairing or the
    compiled one, oracles.judge.owner_kernel)."""
    compiled = path.startswith("compiled")
    if compiled:
        assert owner_kernel.available(), owner_kernel.why_not()
    monkeypatch.setattr(segment_pixels, "KERNEL_PIXELS", 0 if compiled else 10**9)
    monkeypatch.setattr(segment_pixels, "LEVEL_PIXELS", 10**9 if path.endswith("radius only") else 0)
    monkeypatch.setattr(segment_pixels, "CROWDED", 0 if path.endswith("1/8 first") else 10**9)
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


@pytest.mark.parametrize("compiled", [False, True], ids=["numpy", "compiled"])
def test_a_segment_beyond_the_right_edge_in_the_last_row_lists_no_column(monkeypatch, compiled):
    """A segment 1.9 px right of the image, in its bottom rows, looked at within 1/2 px: its columns start
    past the right edge (ceil(x - 1/2) = W + 1), where the stacked pixels' rank table ends (it raised an
    IndexError before). It owns no pixel (1.9 px from the nearest centre), so the rows are those without it."""
    monkeypatch.setattr(segment_pixels, "KERNEL_PIXELS", 0 if compiled else 10**9)
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


@pytest.mark.parametrize("compiled", [False, True], ids=["numpy", "compiled"])
def test_a_segment_beyond_the_left_edge_in_the_first_row_pairs_only_its_own_frame(monkeypatch, compiled):
    """Two frames stacked: the first frame's steep segment starts left of its top-left corner, its part near row 0
    left of x = -1.5, so that row's slice ends at column floor(-1.795 + 1/2) = -2, clipped to -1 (before: the rank
    table's index -1, its last entry, listed every pixel of both frames for it, and the second frame's pixels
    near the same place in their own frame, where it has no segment, were given to it). Each frame's rows must
    be the definition's."""
    monkeypatch.setattr(segment_pixels, "LEVEL_PIXELS", 0)  # within 1/2 first, as for many pixels
    monkeypatch.setattr(segment_pixels, "KERNEL_PIXELS", 0 if compiled else 10**9)
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


@pytest.mark.parametrize("seed", range(6))
def test_a_few_pixels_among_many_segments_have_the_definitions_owners_when_compiled(seed):
    """The compiled pairing with fewer pixels than segments (a frame's pixels drawn by the oracle alone, whose
    owners are looked for after the candidate's: oracles.judge.segment_pixels._known_owners) first tests each
    segment's grown box against the 8-px cells holding a pixel; the pixels lie on the cells' edges (columns and
    rows 7, 8, 15, 16, ...) and the segments end within a pixel of them, so a box one cell short misses pairs.
    Each pixel's owner must be the definition's, as the numpy pairing's is."""
    assert owner_kernel.available(), owner_kernel.why_not()
    rng = np.random.default_rng(seed)
    w, h = 48, 40
    edges_at = np.array([7.0, 8.0, 15.0, 16.0, 23.0, 24.0, 31.0, 32.0, 39.0, 40.0])
    pixels = np.unique(rng.choice(edges_at[edges_at < h].astype(int), 12) * w + rng.choice(edges_at.astype(int), 12))
    centre = rng.uniform([0, 0], [w - 1, h - 1], (300, 2))
    p0 = centre + rng.uniform(-1.2, 1.2, (300, 2))
    p1 = centre + rng.uniform(-1.2, 1.2, (300, 2))
    segs = segment_pixels._Segments([(p0, p1)], w, h, 1.0)
    px = segment_pixels._Pixels.of_frames([pixels], w, h)
    sid, pos = segs.nearest(px, large=True)
    got = list(zip(segs.edge[sid].tolist(), pixels[pos].tolist()))
    assert got == _owners_naive(p0, p1, w, h, pixels)[0]
    assert len(got) >= 4  # pixels with an owner, to compare


@pytest.mark.parametrize("compiled", [False, True], ids=["numpy", "compiled"])
@pytest.mark.parametrize("seed", range(4))
def test_count_differences_given_the_candidates_owners_equal_those_found_with_the_rest(monkeypatch, compiled, seed):
    """A projector's frame has its candidate pixels' owners found while pyrender draws (pixel_owners, as
    oracles.judge.case does); the per-edge count differences given them must equal those found from every
    drawn pixel: two frames of a dense mesh (more segments than 1/8 of the pixels: the one-pass path), the
    first given its candidate's owners (some pixels owned by none: drawn 1-1.5 px off every segment), the
    second not, each with pixels only one side draws (the ones whose owners are looked for after)."""
    if compiled:
        assert owner_kernel.available(), owner_kernel.why_not()
    monkeypatch.setattr(segment_pixels, "KERNEL_PIXELS", 0 if compiled else 10**9)
    rng = np.random.default_rng(seed)
    w, h = 40, 30
    frames, known = [], []
    for k in range(2):
        centre = rng.uniform([0, 0], [w - 1, h - 1], (500, 2))
        p0 = np.round((centre + rng.uniform(-2, 2, (500, 2))) * 2) / 2  # half pixels: exact ties
        p1 = np.round((centre + rng.uniform(-2, 2, (500, 2))) * 2) / 2
        p0[::50] = np.nan  # edges not drawn
        oracle = np.sort(rng.choice(w * h, 300, replace=False))
        cand = np.union1d(np.setdiff1d(oracle, rng.choice(oracle, 20)), rng.choice(w * h, 25))
        fp = FramePixels.from_indices((h, w), cand, oracle)
        frames.append((p0, p1, fp))
        known.append((cand, segment_pixels.pixel_owners(p0, p1, w, h, cand)) if k == 0 else None)
    assert (known[0][1] == -1).any() and (known[0][1] >= 0).any()  # owned pixels, and some owned by none
    assert len(frames[0][2].only()[1]) > 0  # pixels the oracle alone draws: looked for after
    expected = segment_pixels.frames_count_differences(frames, w, h)
    got = segment_pixels.frames_count_differences(frames, w, h, known=known)
    for (d_exp, n_exp), (d_got, n_got) in zip(expected, got):
        np.testing.assert_array_equal(d_got, d_exp)
        assert n_got == n_exp
    assert any(np.any(d != 0) for d, _ in expected)  # edges that count differently: something compared


@pytest.mark.parametrize(
    "count", [20, 48, 49, 300], ids=["20 px: boxes", "48 px: boxes", "49 px: grid", "300 px: grid"]
)
def test_some_pixels_of_a_frame_have_the_definitions_owners_through_boxes_or_the_grid(monkeypatch, count):
    """Some pixels of a frame (edge midpoints, one-sided pixels) are paired with every segment's box up to
    BOXED_PIXELS of them, through a grid of cells beyond; either way each pixel's owner is the definition's
    (numpy pairing: the compiled one is not asked for so few pixels)."""
    monkeypatch.setattr(segment_pixels, "KERNEL_PIXELS", 10**9)
    rng = np.random.default_rng(count)
    w, h = 60, 45
    owned = 0
    for _ in range(3):
        p0, p1 = _hostile(rng, w, h, 0.5)
        pixels = np.sort(rng.choice(w * h, count, replace=False))
        segs = segment_pixels._Segments([(p0, p1)], w, h, 1.0)
        px = segment_pixels._Pixels.of_frames([pixels], w, h)
        sid, pos = segs.nearest(px)
        assert (segs._cells is None) == (count <= segment_pixels.BOXED_PIXELS)  # the path under test was taken
        got = list(zip(segs.edge[sid].tolist(), pixels[pos].tolist()))
        assert got == _owners_naive(p0, p1, w, h, pixels)[0]
        owned += len(got)
    assert owned > 0  # pixels near the segments: owners compared
