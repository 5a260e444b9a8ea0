"""Which oracle segment each pixel near the lines belongs to: the pairing behind the line gate's edge counts.

A pixel (flat index ``y W + x``, pixel centres on integers, core.conventions)
belongs to segment ``e`` (``p0_px[e] -> p1_px[e]``, NaN rows skipped) when
its centre is within ``radius`` (Euclidean) of the segment and no other
segment is nearer (ties: the lower index), so each pixel belongs to one
segment at most. Every pixel a 1-px line rasterizer draws for a segment lies
within ``sqrt(2)/2`` of it (within 1/2 of the line across the major axis,
within 1/2 beyond an end along it), so ``radius = 1`` holds all of a line's
pixels, from either renderer.

The rows come back as three ``(K,)`` int64 arrays ``(edge, pixel, major)``,
one row per pixel, ascending by pixel; ``major`` is the pixel's coordinate
along its segment's major axis (x when ``|dx| > |dy|``, else y).

Given the drawn pixels (the usual case), pairs are found row by row: the
pixels are sorted row-major, so the ones of one row between two columns are
one slice of them. For each row a segment's grown box spans, the slice runs
over the columns its part near that row reaches; each pair found is
measured. For a few pixels, a grid of cells lists the segments near each
cell instead. Pairs come in chunks (:data:`CHUNK_PAIRS`) and are folded into
one nearest segment per pixel as they come, so memory is bounded by the
image, the segments and the chunk, never by the segments' drawn length
(a pixel under a soup of long edges is near hundreds of them). A pixel's
nearest segment is looked for within 1/2 px first (1/8 where the segments
crowd the pixels), and within ``radius`` only for the pixels with none that
near (:meth:`_Segments.nearest`): a drawn pixel is within 1/2 of the line
that drew it, and most of its pairs within 1 are farther. Pairs are compared by their squared distances,
and their distances (``hypot``, the floats every decision is taken on) are measured only where the two
could decide differently (:data:`D2_SLACK`): a pair on the radius, a pixel with two candidates as near.
The frames of a case are done in one pass: they are stacked
one above the other, and a segment looks only at its own frame's rows, so no
pair mixes two frames and each frame's rows are the ones it would get alone;
distances are measured in the frame's own coordinates, so they are the same
floats too.

The line gate's counts (:func:`frames_count_differences`) and ends
(:func:`nearest_segments`) use this pairing; :func:`edge_neighbourhoods`
gives the rows themselves.
"""

from __future__ import annotations

import copy

import numpy as np

from ..segment_geometry import clip_to_box
from . import owner_kernel

_EMPTY = np.zeros(0, dtype=np.int64)
_NONE = np.iinfo(np.int64).max  # no owner yet (:meth:`_Segments.owners`)

#: Pairs of a segment and a pixel (or rows a run of segments spans) measured at once: the pairing
#: streams its pairs in chunks of about this many, so that its memory is bounded by the image and
#: this, whatever the drawn length of the segments (a soup of long edges pairs each pixel with
#: hundreds: 10^8 pairs a frame). 2^15 pairs: ~4 MB of temporaries in _near, each array 256 KiB, near the
#: L2 cache's size: the pairing of every drawn pixel of a 20k-60k face mesh took 16-18 ms of CPU in chunks
#: of 2^15, 19-28 ms in chunks of 2^19 (its arrays of 1.5-1.8 MB each: cache misses, and pages the
#: allocator returns to the system and faults in again); a soup's 505 against 590.
CHUNK_PAIRS = 1 << 15
#: :meth:`_Segments.pairs_any` tests each pixel against every segment's box when there are at most
#: this many (pixel, segment) tests (a frame's few one-sided pixels: ~10 ms), rather than list every
#: segment in a grid of cells first (~100 ms for 30,000 segments) ...
FEW_PAIRS = 1 << 22
#: ... and at most this many pixels: a box test costs 7-9 ns a (pixel, segment) pair, listing a segment in the
#: grid ~0.4 us (measured on a 1,008- and a 30,720-segment frame: 100 pixels' box tests 0.9 and 20 ms, the
#: grid 0.39 and 10.9 ms), so the grid wins from ~45 pixels on (a 1,000-edge frame's ~1,000 edge midpoints,
#: oracles.judge.segment_pixels._compared: 21 ms of box tests, under 1 ms through the grid).
BOXED_PIXELS = 48

#: :func:`frames_count_differences` counts every drawn pixel at once when the frames hold more than
#: one segment per this many drawn pixels (a dense mesh: most segments a few pixels long, where
#: looking at midpoints and one-sided pixels first would pair most pixels several times over).
DENSE = 8

#: How far (px) past ``radius`` the boxes and row spans that list candidate pairs reach: a margin for
#: the rounding of the spans' arithmetic and of the distance itself (each ~1e-12 px on coordinates of
#: at most ~10^4 px, the frame's grown box), so that every pair whose computed distance is within
#: ``radius`` is listed; a pair listed beyond it is measured and dropped.
GROW_PX = 1e-6

#: The radii (px) within which :meth:`_Segments.nearest` looks first, in turn, before ``radius``: a
#: pixel with a segment within one of them has its nearest there, and is not paired with the farther
#: ones. A drawn pixel is within 1/2 of the line that drew it (the diamond rule): within 1/2, a drawn
#: pixel of the benchmark's meshes is paired with 35-50 % of the segments within 1.
LEVELS = (0.5,)
#: ... and where the segments' rows outnumber the pixels by more than :data:`CROWDED` (a soup of long
#: edges: ~700 segments within 1 px of each drawn pixel, 95 % of the pixels with one within 1/8, which
#: pairs each with 12 % of them): 1/8 first.
CROWDED_LEVELS = (0.125, 0.5)
CROWDED = 64
#: :meth:`_Segments.boxes_holding`'s summed-area table of the pixels is made up to this many cells (frames
#: x (H + 1) x (W + 1), int32: 32 MiB); over it, the pixels left after a first radius are paired by
#: :meth:`_Segments.pairs_any`.
TABLE_CELLS = 1 << 23
#: :func:`nearest_segments` first keeps only the segments whose unclipped boxes, grown by its radius and
#: :data:`REACH_MARGIN_PX`, hold one of the pixels (a frame's few one-sided pixels among 10^4 - 10^5
#: segments: clipping and pairing every segment cost ~10 ms), when the frames hold at least this many.
FEW_SEGMENTS = 4096
#: A clipped end is ``p0 + t (p1 - p0)``, ``t`` in [0, 1]: within ~1e-12 px of the segment's box on
#: coordinates of ~10^4 px; a whole pixel of margin keeps every segment that can pair (the pairs are
#: measured after).
REACH_MARGIN_PX = 1.0
#: A pair's squared distance ``d2`` (``ex^2 + ey^2``, three roundings) is within ~4e-16 (relative) of the
#: square of its distance (``hypot``, under 1 ulp), so a pair whose ``d2`` is more than this (relative) from
#: ``radius^2``, or from a nearer pair's ``d2``, is on the same side of the radius, or farther, by its
#: distance too: :meth:`_Segments._near` and :meth:`_Segments.owners` measure ``hypot`` only for the pairs
#: within it (a radius test on the boundary, a pixel with two candidates as near).
D2_SLACK = 2.0**-30
#: ... and an absolute slack for squared distances that underflow (offsets under 1e-154 px).
D2_TINY = 1e-280
#: :meth:`_Segments.nearest` of every drawn pixel runs the compiled pairing (oracles.judge.owner_kernel: the same
#: owners) from this many pixels on: a frame of a 20k-60k face mesh (40,000-60,000 drawn pixels) in 5-8 ms of CPU
#: against 15-22 for the numpy pairing; below, the numpy pairing costs a few ms at most, less than making the
#: compiled kernel ready in a process (numba's import and its cache's load, ~0.6 s once), which most runs (the
#: bundled scenes' ~1,000-pixel frames) then never pay.
KERNEL_PIXELS = 1 << 13
#: :meth:`_Segments.nearest` looks within :data:`LEVELS` first only for at least this many pixels
#: (fewer: one search costs less than the calls of several).
LEVEL_PIXELS = 1024


def edge_neighbourhoods(
    p0_px: np.ndarray,
    p1_px: np.ndarray,
    width: int,
    height: int,
    radius: float = 1.0,
    mask: np.ndarray | None = None,
    pixels: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The pixels near each segment: ``(edge, pixel, major)`` (module docstring).

    ``mask`` ((H, W) bool, optional) keeps only the pixels where it is True
    (the drawn ones): each pixel's nearest segment is decided among the same
    segments, so the kept pixels' rows are the same as without it, for a
    fraction of the work. ``pixels`` (ascending flat indices) is the same as a
    mask True at those pixels only. Without either, every pixel of the image
    is a candidate (found from the segments: the ``(2 reach + 1)^2`` pixels
    around each 1-px step along them).
    """
    if pixels is None and mask is not None:
        pixels = np.flatnonzero(np.asarray(mask, bool))
    if pixels is not None:
        return frames_neighbourhoods([(p0_px, p1_px, pixels)], width, height, radius)[0]
    return _from_segments(p0_px, p1_px, width, height, radius)


def frames_neighbourhoods(frames, width: int, height: int, radius: float = 1.0) -> list[tuple]:
    """:func:`edge_neighbourhoods` of several frames of one size, in one pass (module docstring).

    Parameters
    ----------
    frames : sequence of (p0_px (E, 2), p1_px (E, 2), pixels (P,))
        Each frame's segments and its drawn pixels (ascending flat indices).
    width, height : int
    radius : float

    Returns
    -------
    list of (edge, pixel, major), one per frame, each three (K,) int64 arrays.
    """
    if not frames:
        return []
    segs = _Segments([(p0, p1) for p0, p1, _ in frames], width, height, radius)
    px = _Pixels.of_frames([pixels for _, _, pixels in frames], width, height)
    sid, pos = segs.nearest(px, every=True)
    edge, local, major = segs.rows(px, sid, pos)
    cut = np.searchsorted(pos, np.cumsum(px.counts)[:-1])  # the frames' rows, split
    return list(zip(np.split(edge, cut), np.split(local, cut), np.split(major, cut)))


def pixel_owners(p0_px: np.ndarray, p1_px: np.ndarray, width: int, height: int, flat: np.ndarray, radius: float = 1.0):
    """``(len(flat),)`` int64: the edge each pixel belongs to (module docstring), -1 where none is within
    ``radius``; ``flat`` ascending flat indices of one frame.

    Owning is a property of the pixel and the frame's segments alone, so these are the owners
    :func:`frames_count_differences` finds for the same pixels among any others: given them
    (``known``), it looks only for the rest's (a projector's frame: the candidate's pixels'
    owners are found while pyrender draws, oracles.judge.case).
    """
    flat = np.asarray(flat, np.int64).reshape(-1)
    edge = np.full(len(flat), -1, np.int64)
    segs = _Segments([(p0_px, p1_px)], width, height, radius)
    if len(segs) and len(flat):
        sid, pos = segs.nearest(_Pixels.of_frames([flat], width, height), every=True)
        edge[pos] = segs.edge[sid]
    return edge


def _known_owners(segs: _Segments, drawn: _Pixels, known) -> tuple:
    """``(sid, pos)`` of :meth:`_Segments.nearest` over ``drawn`` (every drawn pixel of the frames), taking
    the owners of the pixels ``known`` gives (per frame, None or ``(flat, edge)``: :func:`pixel_owners`) and
    looking only for the others'."""
    w, h = segs.width, segs.height
    first_edge = np.cumsum(segs.counts) - segs.counts
    sid_of = np.full(int(segs.counts.sum()) + 1, -1, np.int64)  # (frame, edge) -> segment; the last: none
    sid_of[first_edge[segs.frame] + segs.edge] = np.arange(len(segs))
    # each stacked pixel's known owner (-1: none within the radius), -2 where not known: one image a frame
    owner_at = np.full(len(known) * w * h, -2, np.int32)
    for k, given in enumerate(known):
        if given is not None:
            flat, edge = given
            at = np.where(edge < 0, len(sid_of) - 1, first_edge[k] + edge)
            owner_at[np.asarray(flat, np.int64) + k * w * h] = sid_of[at]
    owner = owner_at[drawn.stacked].astype(np.int64)
    rest = np.flatnonzero(owner == -2)
    if len(rest):  # a few pixels (drawn by the oracle alone)
        sid_rest, pos_rest = segs.nearest(drawn.subset(rest), large=True)
        owner[rest] = -1
        owner[rest[pos_rest]] = sid_rest
    pos = np.flatnonzero(owner >= 0)
    return owner[pos], pos


def frames_count_differences(frames, width: int, height: int, radius: float = 1.0, known=None) -> list[tuple]:
    """Per-edge count differences of several frames, looking only where they can differ.

    An edge's count (oracles.judge.metrics.edge_counts) is the number of distinct
    major-axis coordinates among the drawn pixels it owns (module docstring).
    Owning is a property of the pixel and the segments alone, so:

    - an edge that owns no one-sided pixel owns the same pixels in both
      images, and its counts are equal: only the owners of one-sided pixels
      are counted, from the drawn pixels near them;
    - an edge is *compared* (counted in either image) when it owns some
      drawn pixel: most do at the pixel nearest their midpoint, and only the
      rest are looked for among the drawn pixels near them.

    On a dense mesh (:data:`DENSE`) every drawn pixel's owner is found in one
    pass instead: the compared edges are the owners, and the counts are taken
    over the rows of the owners of one-sided pixels only.

    The results equal the full count over every drawn pixel
    (:func:`frames_neighbourhoods` and oracles.judge.metrics.edge_counts), for a
    fraction of the work when the frames mostly agree.

    Parameters
    ----------
    frames : sequence of (p0_px (E, 2), p1_px (E, 2), pixels)
        Each frame's segments and its two images' drawn pixels
        (oracles.judge.frame_pixels.FramePixels: ``cand_idx``, ``oracle_idx``, ``drawn()``, ``only()``).

    known : sequence of None or (flat, edge), one per frame, optional
        Some of a frame's pixels with their owners found before (:func:`pixel_owners`):
        a dense frame looks only for the other pixels' owners.

    Returns
    -------
    list of (diff (E,) int64, compared int), one per frame: candidate count
    minus oracle count per edge, and how many edges either image counts.
    """
    if not frames:
        return []
    segs = _Segments([(p0, p1) for p0, p1, _ in frames], width, height, radius)
    drawn = _Pixels.of_frames([fp.drawn() for _, _, fp in frames], width, height)
    one_sided = _Pixels.of_frames([np.sort(np.concatenate(fp.only())) for _, _, fp in frames], width, height)
    first_edge = np.cumsum(segs.counts) - segs.counts  # frame k's edges in one flat array of all
    diff_all = np.zeros(int(segs.counts.sum()), np.int64)
    compared = np.zeros(len(segs), bool)
    if len(segs) and len(drawn):
        if len(segs) * DENSE > len(drawn):  # a dense mesh: one pass over every drawn pixel is cheaper
            if known is not None and any(k is not None for k in known):
                sid, pos = _known_owners(segs, drawn, known)
            else:
                sid, pos = segs.nearest(drawn, every=True)
            compared[sid] = True  # every drawn pixel is drawn by one image at least
            # only the owners of one-sided pixels can count differently: their rows alone are counted
            mine = np.zeros(len(segs), bool)
            mine[sid[one_sided.has(drawn.stacked[pos])]] = True
            owners = np.flatnonzero(mine)
            cc = oc = np.zeros(len(segs), np.int64)
            if len(owners):
                keep = mine[sid]
                cc, oc = _counts_of(segs, *_sides(frames, width, height), drawn, sid[keep], pos[keep])
        else:
            compared = _compared(segs, drawn)
            owners = _unique(segs.nearest(one_sided)[0])
            cc = oc = np.zeros(len(segs), np.int64)
            if len(owners):
                cc, oc = _counts_near(segs, *_sides(frames, width, height), drawn.subset(segs.near(drawn, owners)))
        diff_all[first_edge[segs.frame[owners]] + segs.edge[owners]] = (cc - oc)[owners]
    n_compared = np.bincount(segs.frame[compared], minlength=len(frames))
    return [(d, int(n)) for d, n in zip(np.split(diff_all, first_edge[1:]), n_compared)]


def _sides(frames, width: int, height: int) -> tuple[_Pixels, _Pixels]:
    """The candidate's and the oracle's drawn pixels of ``frames`` (:func:`frames_count_differences`'), stacked:
    made only where some edge can count differently."""
    cand = _Pixels.of_frames([fp.cand_idx for _, _, fp in frames], width, height)
    return cand, _Pixels.of_frames([fp.oracle_idx for _, _, fp in frames], width, height)


def _compared(segs: _Segments, drawn: _Pixels) -> np.ndarray:
    """``(S,)`` bool: whether each segment owns a drawn pixel (the pixel at its midpoint, or another near it)."""
    w, h = segs.width, segs.height
    mid = np.floor((segs.q0 + segs.q1) / 2 + 0.5).astype(np.int64)
    on = (mid[:, 0] >= 0) & (mid[:, 0] < w) & (mid[:, 1] >= 0) & (mid[:, 1] < h)
    mid_stacked = np.where(on, (mid[:, 1] + segs.frame * h) * w + mid[:, 0], -1)
    on &= drawn.has(mid_stacked)
    mids = drawn.subset(_unique(np.searchsorted(drawn.stacked, mid_stacked[on])))
    m_sid, m_pos = segs.nearest(mids)
    owner_at = np.full(len(mids), -1, np.int64)
    owner_at[m_pos] = m_sid
    seg_on = np.flatnonzero(on)
    compared = np.zeros(len(segs), bool)
    compared[seg_on] = owner_at[np.searchsorted(mids.stacked, mid_stacked[seg_on])] == seg_on
    rest = np.flatnonzero(~compared)  # the others: the owners of the drawn pixels near them
    if len(rest):
        near = drawn.subset(segs.near(drawn, rest))
        compared[_unique(segs.nearest(near)[0])] = True
    return compared


def _counts_near(segs: _Segments, cand: _Pixels, orac: _Pixels, near: _Pixels, every: bool = False):
    """``(cc, oc)``, ``(S,)`` each: every segment's count in the candidate's and the oracle's image, over
    the drawn pixels ``near`` only (right for the segments all of whose pixels are among them);
    ``every``: ``near`` is every drawn pixel (paired row by row)."""
    sid, pos = segs.nearest(near, every)
    return _counts_of(segs, cand, orac, near, sid, pos)


def _counts_of(segs: _Segments, cand: _Pixels, orac: _Pixels, near: _Pixels, sid: np.ndarray, pos: np.ndarray):
    """:func:`_counts_near` given the owner ``sid`` of the pixels at positions ``pos`` of ``near``."""
    _, _, major = segs.rows(near, sid, pos)
    cc = _distinct_per_segment(sid, major, len(segs), cand.has(near.stacked[pos]))
    if np.array_equal(cand.stacked, orac.stacked):  # the frames agree (ties resolved): once
        return cc, cc
    return cc, _distinct_per_segment(sid, major, len(segs), orac.has(near.stacked[pos]))


def _cuts(weights: np.ndarray, limit: int) -> list[tuple[int, int]]:
    """``[(lo, hi)]``: consecutive ranges of ``weights`` whose sums are at most ``limit`` (an item over
    ``limit`` alone), covering them all in order."""
    total = np.cumsum(weights)
    out, lo, base = [], 0, 0
    while lo < len(total):
        hi = max(int(np.searchsorted(total, base + limit, side="right")), lo + 1)
        out.append((lo, hi))
        base, lo = int(total[hi - 1]), hi
    return out


def _unique(a: np.ndarray) -> np.ndarray:
    """The distinct values of an int array, ascending (a sort: numpy's hashed unique is slower on these sizes)."""
    a = np.sort(a)
    if len(a) > 1:
        a = a[np.concatenate([[True], a[1:] != a[:-1]])]
    return a


def _distinct_per_segment(sid: np.ndarray, major: np.ndarray, n_segments: int, kept: np.ndarray) -> np.ndarray:
    """``(n_segments,)``: the number of distinct ``major`` values of each segment's rows where ``kept``."""
    sid, major = sid[kept], major[kept]
    span = int(major.max()) + 1 if len(major) else 1
    keys = _unique(sid * span + major)
    return np.bincount(keys // span, minlength=n_segments)


def nearest_segments(frames, width: int, height: int, radius: float, box: tuple):
    """Each pixel's nearest segment within ``radius``, among its frame's segments clipped to ``box``.

    Parameters
    ----------
    frames : sequence of (p0_px (E, 2), p1_px (E, 2), pixels (P,))
        Each frame's segments in pixels (NaN rows skipped) and some of its
        pixels (ascending flat indices ``y W + x``).
    radius : float
    box : ((x, y), (x, y))
        The corners the segments are clipped to first.

    Returns
    -------
    owner : (sum P,) int64
        The pixels of all frames in order: index into ``q0, q1`` of each
        one's nearest segment within ``radius`` (ties: the lower index), -1
        where none is that near.
    q0, q1 : (K, 2) float64
        The kept segments of all frames, clipped, frame after frame (from :data:`FEW_SEGMENTS`
        segments on, only those whose boxes reach one of the pixels: the others own none).
    frame : (sum P,) int64
        Each pixel's frame.
    """
    frames = [
        (np.asarray(p0, np.float64).reshape(-1, 2), np.asarray(p1, np.float64).reshape(-1, 2), pixels)
        for p0, p1, pixels in frames
    ]
    if sum(len(p0) for p0, _, _ in frames) >= FEW_SEGMENTS:  # only the segments that can reach a pixel
        frames = [
            (np.take(p0, k, axis=0), np.take(p1, k, axis=0), pixels)  # by index: a 2-D mask is slower
            for (p0, p1, pixels), k in zip(
                frames,
                map(np.flatnonzero, _reaching(frames, width, height, radius + REACH_MARGIN_PX)),
            )
        ]
    segs = _Segments([(p0, p1) for p0, p1, _ in frames], width, height, radius, box=box)
    px = _Pixels.of_frames([pixels for _, _, pixels in frames], width, height)
    owner = np.full(len(px), -1, np.int64)
    sid, pos = segs.nearest(px)
    owner[pos] = sid
    return owner, segs.q0, segs.q1, px.at()[0]


def _reaching(frames, width: int, height: int, reach: float, cell: int = 8) -> list[np.ndarray]:
    """For each frame ``(p0 (E, 2), p1 (E, 2), pixels)``: ``(E,)`` bool, True for every segment whose box (of
    its ends, unclipped) grown by ``reach`` holds one of the frame's pixels (and for some others: the boxes
    are widened to whole square cells of ``cell`` px, a summed-area table of the cells holding pixels);
    False for non-finite rows, which clipping drops. Frames given the same segments (the same arrays: both
    sides of a frame's one-sided pixels) have their boxes' cells found once."""
    out = []
    nx, ny = -(-width // cell), -(-height // cell)
    cells: dict = {}  # the segments' cells, by the arrays' memory
    for p0, p1, pixels in frames:
        pixels = np.asarray(pixels, np.int64).reshape(-1)
        hit = np.zeros(len(p0), bool)
        if len(pixels) and len(p0):
            table = np.zeros((ny + 1, nx + 1), np.int32)
            table[pixels // width // cell + 1, pixels % width // cell + 1] = 1
            np.cumsum(table, axis=0, out=table)
            np.cumsum(table, axis=1, out=table)
            key = tuple((a.__array_interface__["data"][0], a.shape, a.strides) for a in (p0, p1))
            if key not in cells:
                cells[key] = _box_cells(p0, p1, reach, cell, nx, ny)
            finite, corners = cells[key]
            t = table.reshape(-1)  # the box's four corners in the table, each a flat index
            hit = ((t[corners[3]] - t[corners[1]] - t[corners[2]] + t[corners[0]]) > 0) & finite
        out.append(hit)
    return out


def _box_cells(p0: np.ndarray, p1: np.ndarray, reach: float, cell: int, nx: int, ny: int):
    """``(finite, corners)``: the rows whose ends are finite, and the cells ``[c0, c1) x [r0, r1)`` of ``cell`` px
    each segment's box grown by ``reach`` spans, as the flat indices of ``(r0, c0), (r0, c1), (r1, c0), (r1, c1)``
    in a ``(ny + 1, nx + 1)`` summed-area table (:func:`_reaching`)."""
    with np.errstate(invalid="ignore", over="ignore"):
        total = p0 + p1  # clip_to_box keeps only the rows where this is finite
        finite = np.isfinite(total[:, 0]) & np.isfinite(total[:, 1])
        every = bool(finite.all())
        ends = []
        for k, n in ((0, nx), (1, ny)):
            a, b = (p0[:, k], p1[:, k]) if every else (np.where(finite, p0[:, k], 0.0), np.where(finite, p1[:, k], 0.0))
            lo, hi = np.minimum(a, b), np.maximum(a, b)
            lo -= reach
            hi += reach
            lo /= cell
            hi /= cell
            # x in [lo, hi] has its cell x // cell in [floor(lo / cell), floor(hi / cell)]: [first, stop)
            first = np.clip(np.floor(lo, out=lo), 0, n, out=lo).astype(np.int64)
            hi = np.floor(hi, out=hi)
            hi += 1
            stop = np.clip(hi, 0, n, out=hi).astype(np.int64)
            ends += [first, np.maximum(stop, first, out=stop)]
    c0, c1, r0, r1 = ends
    r0 *= nx + 1
    r1 *= nx + 1
    return finite, (r0 + c0, r0 + c1, r1 + c0, r1 + c1)


class _Pixels:
    """Pixels of several frames of one size, stacked: frame ``k``'s rows start at row ``k H``.

    ``stacked``: flat indices in the stack, ascending (frame-major, then
    row-major); ``counts``: pixels per frame, when built from frames.
    """

    def __init__(self, stacked: np.ndarray, width: int, height: int, counts: np.ndarray | None = None):
        self.stacked, self.width, self.height, self.counts = stacked, width, height, counts
        self.frames = len(counts) if counts is not None else 0  # frames stacked (0: not known)
        self._xy = None  # (x, y) of every pixel as float64, made on first use (:meth:`xy`)
        self._rank = None  # :meth:`rank`'s table, made when it pays

    @classmethod
    def of_frames(cls, per_frame, width: int, height: int) -> _Pixels:
        """From one ascending flat-index array per frame."""
        per_frame = [np.asarray(p, np.int64).reshape(-1) for p in per_frame]
        counts = np.array([len(p) for p in per_frame], np.int64)
        if not per_frame:
            return cls(_EMPTY, width, height, counts)
        offset = np.repeat(np.arange(len(per_frame), dtype=np.int64) * (width * height), counts)
        return cls(np.concatenate(per_frame) + offset, width, height, counts)

    def __len__(self) -> int:
        return len(self.stacked)

    def at(self, pos=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(frame, y, x)`` of the pixels at positions ``pos`` (default all), in their frames' coordinates."""
        s = self.stacked if pos is None else self.stacked[pos]
        row = s // self.width
        frame = row // self.height
        return frame, row - frame * self.height, s - row * self.width

    def xy(self) -> tuple[np.ndarray, np.ndarray]:
        """``(x, y)``, ``(P,)`` float64 each: every pixel's column and row in its frame (found once)."""
        if self._xy is None:
            _, y, x = self.at()
            self._xy = (x.astype(np.float64), y.astype(np.float64))
        return self._xy

    def rank(self, stacked: np.ndarray, expected: int | None = None) -> np.ndarray:
        """``np.searchsorted(self.stacked, stacked)`` for stacked flat indices in ``[0, frames H W]``.

        Many queries (a long segment's rows) look up a table of one entry per
        pixel of the stacked frames (their count so far, int32: bounded by the
        images), built once; a few are binary searches. ``expected``: how many
        queries the caller will make in all (in several calls), when known.
        """
        # the table spans the pixels' own flat indices, [first, last + 1]: a query below is 0, above ``len``
        size = int(self.stacked[-1] - self.stacked[0]) + 2 if len(self.stacked) else 0
        many = len(stacked) if expected is None else expected
        if self._rank is None and size and many > size // 4 and size < 2**31:
            table = np.zeros(size, np.int32)
            table[self.stacked - (self.stacked[0] - 1)] = 1
            self._rank = np.cumsum(table, dtype=np.int32, out=table)  # in place: the table is all it takes
        if self._rank is not None:
            at = stacked - self.stacked[0]
            np.clip(at, 0, size - 1, out=at)
            return self._rank[at].astype(np.int64)
        return np.searchsorted(self.stacked, stacked)

    def has(self, stacked: np.ndarray) -> np.ndarray:
        """Whether each stacked flat index is one of these pixels."""
        stacked = np.asarray(stacked, np.int64)
        if len(self.stacked) == 0:
            return np.zeros(stacked.shape, bool)
        at = np.minimum(np.searchsorted(self.stacked, stacked), len(self.stacked) - 1)
        return self.stacked[at] == stacked

    def subset(self, pos: np.ndarray) -> _Pixels:
        """The pixels at ascending positions ``pos``."""
        out = _Pixels(self.stacked[pos], self.width, self.height)
        out.frames = self.frames
        return out


class _Segments:
    """Segments of several frames of one size, clipped to each frame's box grown by ``radius + 1``
    (or to ``box``, ``(lo, hi)`` corners, when given)."""

    def __init__(self, per_frame, width: int, height: int, radius: float, box: tuple | None = None):
        self.width, self.height, self.radius = width, height, radius
        pad = radius + 1.0
        lo, hi = box if box is not None else ((-pad, -pad), (width - 1 + pad, height - 1 + pad))
        self.grow = radius + GROW_PX  # each box is grown a little further, against rounding
        p0 = [np.asarray(a, np.float64).reshape(-1, 2) for a, _ in per_frame]
        p1 = [np.asarray(b, np.float64).reshape(-1, 2) for _, b in per_frame]
        self.counts = np.array([len(a) for a in p0], np.int64)
        self.one_frame = len(p0) == 1
        if self.one_frame:  # its edges in order, all of frame 0 (a read-only view of one 0: no memory)
            frame, edge = np.broadcast_to(np.zeros(1, np.int64), (len(p0[0]),)), np.arange(len(p0[0]), dtype=np.int64)
        else:
            frame = np.repeat(np.arange(len(p0), dtype=np.int64), self.counts)
            edge = np.arange(int(self.counts.sum())) - np.repeat(np.cumsum(self.counts) - self.counts, self.counts)
        p0 = np.concatenate(p0) if p0 else np.zeros((0, 2))
        p1 = np.concatenate(p1) if p1 else np.zeros((0, 2))
        keep, q0, q1 = clip_to_box(p0, p1, np.asarray(lo, np.float64), np.asarray(hi, np.float64))
        if keep.all():  # every segment reaches the box: no copies
            self.q0, self.q1, self.frame, self.edge = q0, q1, frame, edge
        else:
            self.q0, self.q1 = q0[keep], q1[keep]
            self.frame, self.edge = frame[keep], edge[keep]
        # the columns _near gathers per pair, contiguous (np.take of a 1-D array: the same floats, faster);
        # each difference is the one ``q1 - q0`` gives, taken column by column (no (S, 2) array of them)
        qx, qy = np.ascontiguousarray(self.q0[:, 0]), np.ascontiguousarray(self.q0[:, 1])
        dx, dy = np.subtract(self.q1[:, 0], qx), np.subtract(self.q1[:, 1], qy)
        self.dd = dx * dx
        self.dd += dy * dy
        self._cols = (qx, qy, dx, dy, self.dd)
        self._points = bool((self.dd == 0).any())  # a segment of no length (_near's u is 0 for it)
        self._cells = None  # the grid of pairs_any, made on first use
        self._rows = None  # _rows_spanned, counted on first use
        self._y = None  # _y_range, found on first use

    def __len__(self) -> int:
        return len(self.q0)

    def within(self, radius: float) -> _Segments:
        """These segments, pairing within ``radius`` (the arrays shared; the grid and row counts its own)."""
        out = copy.copy(self)
        out.radius, out.grow = radius, radius + GROW_PX
        out._cells = out._rows = None
        return out

    def nearest(self, px: _Pixels, every: bool = False, large: bool = False):
        """:meth:`owners` of the pixels ``px`` over all segments, looking within :data:`LEVELS` first.

        The pixels with a pair within a level's radius have their nearest
        segment among those pairs (every segment as near, ties included, is
        one of them); only the others are paired within the next radius.
        ``every``: ``px`` is every drawn pixel (paired row by row, :meth:`pairs`;
        else :meth:`pairs_any`). The same ``(sid, pos)`` as one search within
        ``radius``. With :data:`KERNEL_PIXELS` pixels or more of ``every``, or ``large`` (some
        pixels of a frame that large: its other pixels' owners were found so), by the compiled
        pairing (oracles.judge.owner_kernel) where it is available: the same owners.
        """
        levels = []
        if len(px) >= LEVEL_PIXELS:
            crowded = self._crowded(CROWDED * len(px))
            levels = [r for r in (CROWDED_LEVELS if crowded else LEVELS) if r < self.radius]
        if (large or (every and len(px) >= KERNEL_PIXELS)) and owner_kernel.available():  # the same owners, compiled
            owner = owner_kernel.owners(
                px.stacked,
                self.width,
                self.height,
                px.frames,
                self.q0,
                self.q1,
                self._cols,
                None if self.one_frame else self.frame,
                (*levels, self.radius),
                GROW_PX,
                D2_SLACK,
                D2_TINY,
            )
            pos = np.flatnonzero(owner >= 0)
            return owner[pos], pos
        sid_parts, pos_parts = [], []
        rest = None  # positions in px still without an owner (None: all)
        for k, r in enumerate(levels + [self.radius]):
            segs = self.within(r) if r != self.radius else self
            sub = px if rest is None else px.subset(rest)
            if k == 0:
                chunks = segs.pairs(sub) if every else segs.pairs_any(sub)
            else:  # the rest: only the segments whose boxes hold one of them
                which = segs.boxes_holding(sub)
                chunks = segs.pairs_any(sub) if which is None else segs.pairs(sub, which)
            sid, pos = segs.owners(sub, chunks)
            sid_parts.append(sid)
            pos_parts.append(pos if rest is None else rest[pos])
            found = np.zeros(len(sub), bool)
            found[pos] = True
            rest = np.flatnonzero(~found) if rest is None else rest[~found]
            if len(rest) == 0:
                break
        if len(sid_parts) == 1:
            return sid_parts[0], pos_parts[0]
        pos = np.concatenate(pos_parts)
        order = np.argsort(pos, kind="stable")
        return np.concatenate(sid_parts)[order], pos[order]

    def boxes_holding(self, px: _Pixels) -> np.ndarray | None:
        """Ascending indices of the segments whose box grown by ``grow`` holds one of the pixels ``px`` (all
        that can pair with them), from a summed-area table of the pixels per frame; None when that table
        would be over :data:`TABLE_CELLS` cells."""
        n_frames = int(self.frame.max()) + 1 if len(self) else 0
        w, h = self.width, self.height
        if len(self) == 0 or n_frames * (h + 1) * (w + 1) > TABLE_CELLS:
            return None
        frame, y, x = px.at()
        table = np.zeros((n_frames, h + 1, w + 1), np.int32)
        keep = frame < n_frames
        table[frame[keep], y[keep] + 1, x[keep] + 1] = 1
        np.cumsum(table, axis=1, out=table)  # in place: the table is all the memory it takes
        np.cumsum(table, axis=2, out=table)
        y_lo, y_hi = self._y_range()
        x_lo = np.minimum(self.q0[:, 0], self.q1[:, 0])
        x_hi = np.maximum(self.q0[:, 0], self.q1[:, 0])
        # the box's columns and rows (pixel centres on integers), clipped to the frame: [c0, c1] x [r0, r1]
        c0 = np.clip(np.ceil(x_lo - self.grow), 0, w).astype(np.int64)
        c1 = np.clip(np.floor(x_hi + self.grow), -1, w - 1).astype(np.int64) + 1
        r0 = np.clip(np.ceil(y_lo - self.grow), 0, h).astype(np.int64)
        r1 = np.clip(np.floor(y_hi + self.grow), -1, h - 1).astype(np.int64) + 1
        c1, r1 = np.maximum(c1, c0), np.maximum(r1, r0)  # an empty box: no pixel
        f = self.frame
        inside = table[f, r1, c1] - table[f, r0, c1] - table[f, r1, c0] + table[f, r0, c0]
        return np.flatnonzero(inside > 0)

    def pairs(self, px: _Pixels, which: np.ndarray | None = None):
        """``(sid, pos, d2)`` chunks (``d2``: squared distances, :meth:`_near`): each pair of a segment (of
        ``which``, ascending, default all) and a pixel within ``radius``, at most about :data:`CHUNK_PAIRS`
        pairs a chunk, by ascending segment.

        Row by row (:meth:`_spans` of 1-row bands): the pixels of a row
        between two columns are one slice of ``stacked``; each is measured.
        The segments go in runs spanning at most :data:`CHUNK_PAIRS` rows,
        and a run's slices in chunks of at most that many pixels (a slice
        over it alone): memory is bounded whatever the segments' length.
        """
        if (len(self) if which is None else len(which)) == 0 or len(px) == 0:
            return
        w, h = self.width, self.height
        rows = self._rows_of(which)
        queries = 2 * int(rows.sum())  # every run's slices, both ends: one rank table for all of them
        for lo, hi in _cuts(rows, CHUNK_PAIRS):
            seg, row, col_lo, col_hi = self._spans(np.arange(lo, hi) if which is None else which[lo:hi], 1)
            # the pixels of one row between two columns are one slice of ``stacked``
            start = row * w if self.one_frame else (row + self.frame[seg] * h) * w
            a = px.rank(start + col_lo, queries)
            n = np.maximum(px.rank(start + col_hi + 1, queries) - a, 0)
            for s0, s1 in _cuts(n, CHUNK_PAIRS):
                nn = n[s0:s1]
                sid = np.repeat(seg[s0:s1], nn)
                pos = np.arange(int(nn.sum())) + np.repeat(a[s0:s1] - (np.cumsum(nn) - nn), nn)
                yield self._near(px, sid, pos)

    def near(self, px: _Pixels, which: np.ndarray) -> np.ndarray:
        """Ascending positions of the pixels within ``radius`` of some segment of ``which`` (ascending)."""
        hit = np.zeros(len(px), bool)
        for _sid, pos, _d2 in self.pairs(px, which):
            hit[pos] = True
        return np.flatnonzero(hit)

    def pairs_any(self, px: _Pixels):
        """:meth:`pairs` over all segments, for a subset of the pixels: each against every segment of its
        frame when that is few pairs (and no grid is made yet), else through a grid of cells.

        Each segment is listed in the square cells its part near each band of
        cell rows reaches (as :meth:`pairs` does row by row); a pixel is
        measured against the segments listed in its cell. Cost ~ pixels x
        segments per cell, whatever the segments' total length. The cells'
        side follows the segments' typical length (:meth:`_cell_side`), so a
        dense mesh's many short segments are not listed together. Chunks of
        whole pixels (every pair of a pixel in one chunk), at most about
        :data:`CHUNK_PAIRS` pairs each.
        """
        if len(px) == 0 or len(self) == 0:
            return
        frame = px.at()[0]
        per_frame = np.bincount(self.frame, minlength=int(frame.max()) + 1)
        n = per_frame[frame]  # each pixel against all of its frame's segments
        if self._cells is None and int(n.sum()) <= 4 * (len(px) + len(self)):
            first = (np.cumsum(per_frame) - per_frame)[frame]  # segments are in frame order
            for lo, hi in _cuts(n, CHUNK_PAIRS):
                nn = n[lo:hi]
                pos = np.repeat(np.arange(lo, hi), nn)
                sid = np.arange(int(nn.sum())) + np.repeat(first[lo:hi] - (np.cumsum(nn) - nn), nn)
                yield self._near(px, sid, pos)
            return
        if self._cells is None and len(px) * len(self) <= FEW_PAIRS and len(px) <= BOXED_PIXELS:
            yield from self._pairs_boxed(px, frame)  # a few pixels: no grid of every segment
            return
        keys, listed = self._cell_index()
        _, y, x = px.at()
        cell = self._cell
        key = (frame * self._cells_y + y // cell) * self._cells_x + x // cell
        a = np.searchsorted(keys, key, side="left")
        n = np.searchsorted(keys, key, side="right") - a
        if int(n.sum()) > 2 * (self._rows_spanned() + len(px)):  # crowded cells: row by row is cheaper
            yield from self.pairs(px)
            return
        for lo, hi in _cuts(n, CHUNK_PAIRS):
            nn = n[lo:hi]
            pos = np.repeat(np.arange(lo, hi), nn)
            sid = listed[np.arange(int(nn.sum())) + np.repeat(a[lo:hi] - (np.cumsum(nn) - nn), nn)]
            yield self._near(px, sid, pos)

    def _pairs_boxed(self, px: _Pixels, frame: np.ndarray):
        """:meth:`pairs_any` by a box test of every pixel against every segment of its frame: the pairs
        whose pixel centre is within ``radius`` of the segment's box (all those within ``radius`` of the
        segment), measured. ``frame``: each pixel's."""
        r = self.grow  # radius and the margin of :data:`GROW_PX`
        lo_x, hi_x = np.minimum(self.q0[:, 0], self.q1[:, 0]) - r, np.maximum(self.q0[:, 0], self.q1[:, 0]) + r
        lo_y, hi_y = np.minimum(self.q0[:, 1], self.q1[:, 1]) - r, np.maximum(self.q0[:, 1], self.q1[:, 1]) + r
        x, y = px.xy()
        for lo, hi in _cuts(np.full(len(px), len(self), np.int64), CHUNK_PAIRS):
            cx, cy = x[lo:hi, None], y[lo:hi, None]
            inside = (
                (cx >= lo_x) & (cx <= hi_x) & (cy >= lo_y) & (cy <= hi_y) & (frame[lo:hi, None] == self.frame[None, :])
            )
            pos, sid = np.nonzero(inside)
            yield self._near(px, sid, pos + lo)

    def _cell_index(self) -> tuple[np.ndarray, np.ndarray]:
        """``(keys, sid)``, sorted by key: each segment once per cell it is listed in (:meth:`pairs_any`)."""
        if self._cells is None:
            cell = self._cell = self._cell_side()
            self._cells_x, self._cells_y = -(-self.width // cell), -(-self.height // cell)
            seg, band, col_lo, col_hi = self._spans(np.arange(len(self)), cell)
            c0 = col_lo // cell
            n = np.where(col_lo > col_hi, 0, col_hi // cell - c0 + 1)
            sid = np.repeat(seg, n)
            cx = np.repeat(c0, n) + np.arange(int(n.sum())) - np.repeat(np.cumsum(n) - n, n)
            keys = (self.frame[sid] * self._cells_y + np.repeat(band, n)) * self._cells_x + cx
            order = np.argsort(keys, kind="stable")
            self._cells = (keys[order], sid[order])
        return self._cells

    def _crowded(self, limit: int) -> bool:
        """Whether :meth:`_rows_spanned` is over ``limit``; without counting them when a bound says not: a
        segment's grown box spans at most ``|dy| + 2 grow + 1`` rows."""
        if self._rows is None and float(np.abs(self._cols[3]).sum()) + len(self) * (2 * self.grow + 1) <= limit:
            return False
        return self._rows_spanned() > limit

    def _rows_spanned(self) -> int:
        """How many (segment, row) slices :meth:`pairs` takes over all segments."""
        if self._rows is None:
            self._rows = int(self._rows_of(None).sum())
        return self._rows

    def _rows_of(self, which: np.ndarray | None) -> np.ndarray:
        """``(len(which),)`` int64: the rows of the frame each segment (of ``which``; None: all) grown box spans
        (:meth:`pairs`' slices)."""
        y_lo, y_hi = self._y_range()
        if which is not None:
            y_lo, y_hi = y_lo[which], y_hi[which]
        lo = np.maximum(np.ceil(np.subtract(y_lo, self.grow)), 0)
        hi = np.minimum(np.floor(np.add(y_hi, self.grow)), self.height - 1)
        hi -= lo
        hi += 1
        return np.maximum(hi, 0, out=hi).astype(np.int64)

    def _cell_side(self) -> int:
        """The grid's cell side (px): the segments' median length, a power of two in [4, 32].

        A segment is listed in ~(length / side + 1) cells per band of cells it
        crosses, and a cell holds ~(side / length + 1) segments of each line
        through it: a side near the typical length keeps both near 1.
        """
        lengths = np.sort(np.maximum(np.abs(self._cols[2]), np.abs(self._cols[3])))
        length = lengths[len(lengths) // 2] if len(lengths) else 16.0
        return int(2 ** np.clip(np.round(np.log2(max(length, 1.0))), 2, 5))

    def _spans(self, which: np.ndarray, band: int):
        """``(seg, b, col_lo, col_hi)``: for each band of ``band`` rows a segment's grown box spans (rows
        of the frame only), the columns its part within ``grow`` of the band reaches, grown, clipped to the
        frame (a pixel centre within ``radius`` of the segment in those rows is in those columns: the
        nearest point is within ``radius`` in y, so in that part, and within ``radius`` in x)."""
        grow, w, h = self.grow, self.width, self.height
        qx, qy, dx, dy = self._cols[:4]
        y_lo, y_hi = self._y_range()
        b_lo = np.maximum(np.ceil(y_lo[which] - grow), 0).astype(np.int64) // band
        b_hi = np.minimum(np.floor(y_hi[which] + grow), h - 1).astype(np.int64) // band
        n = np.maximum(b_hi - b_lo + 1, 0)
        seg = np.repeat(which, n)
        b = np.arange(int(n.sum())) + np.repeat(b_lo - (np.cumsum(n) - n), n)
        seg_dy = np.take(dy, seg)
        # t of the band's top and bottom (+ 2 grow + band - 1) along each segment; a flat one: all of it
        rel = b * band - grow
        rel -= np.take(qy, seg)
        with np.errstate(divide="ignore", invalid="ignore"):
            ta = rel / seg_dy
            rel += (band - 1) + 2 * grow
            tb = np.divide(rel, seg_dy, out=rel)
        t_lo, t_hi = np.minimum(ta, tb), np.maximum(ta, tb, out=ta)
        flat = seg_dy == 0
        if flat.any():
            t_lo[flat], t_hi[flat] = 0.0, 1.0
        seg_qx, seg_dx = np.take(qx, seg), np.take(dx, seg)
        xa = np.clip(t_lo, 0.0, 1.0, out=t_lo)
        xa *= seg_dx
        xa += seg_qx
        xb = np.clip(t_hi, 0.0, 1.0, out=t_hi)
        xb *= seg_dx
        xb += seg_qx
        lo, hi = np.minimum(xa, xb), np.maximum(xa, xb, out=xb)
        lo -= grow
        hi += grow
        # col_lo in [0, w], col_hi in [-1, w - 1]: a part beyond the right or the left edge (a box grown by more
        # than this radius) lists no column, and its slice's ends stay within the stacked frames (the rank
        # table's index -1 is its last entry: a slice of the first frame's first row would list every pixel)
        col_lo = np.clip(np.ceil(lo, out=lo), 0, w).astype(np.int64)
        col_hi = np.clip(np.floor(hi, out=hi), -1, w - 1).astype(np.int64)
        return seg, b, col_lo, col_hi

    def _y_range(self) -> tuple[np.ndarray, np.ndarray]:
        """``(y_lo, y_hi)``, ``(S,)`` each: the lower and upper y of each segment (found once)."""
        if self._y is None:
            self._y = (np.minimum(self.q0[:, 1], self.q1[:, 1]), np.maximum(self.q0[:, 1], self.q1[:, 1]))
        return self._y

    def _offsets(self, px: _Pixels, sid: np.ndarray, pos: np.ndarray):
        """``(ex, ey, spare)``: each pair's pixel centre minus the point of its segment nearest it, and a spare
        float array of the same length (the pairs' scratch, reused by the caller)."""
        qx, qy, dx, dy, dd = (np.take(c, sid) for c in self._cols)
        # the point of the segment nearest the pixel centre: a + u d, u in [0, 1], in the frame's coordinates
        # (in place, each float as ``clip(where(dd > 0, (ex dx + ey dy) / dd, 0), 0, 1)`` and
        # ``(ex - u dx, ey - u dy)`` give it)
        x, y = px.xy()
        ex, ey = np.take(x, pos), np.take(y, pos)
        ex -= qx
        ey -= qy
        u = np.multiply(ex, dx, out=qx)
        u += np.multiply(ey, dy, out=qy)
        with np.errstate(divide="ignore", invalid="ignore"):
            u /= dd
        if self._points:
            u[dd == 0] = 0.0
        np.clip(u, 0.0, 1.0, out=u)
        ex -= np.multiply(u, dx, out=dx)
        ey -= np.multiply(u, dy, out=dy)
        return ex, ey, dd

    def _dist(self, px: _Pixels, sid: np.ndarray, pos: np.ndarray) -> np.ndarray:
        """The pairs' distances, ``hypot`` of :meth:`_offsets` (the floats every decision is taken on)."""
        ex, ey, _ = self._offsets(px, sid, pos)
        return np.hypot(ex, ey, out=ex)

    def _near(self, px: _Pixels, sid: np.ndarray, pos: np.ndarray):
        """The pairs ``(sid, pos)`` within ``radius``, with their squared distances ``d2`` (:data:`D2_SLACK`).

        A pair is within ``radius`` when its distance (:meth:`_dist`) is; ``hypot``
        is computed only for the pairs whose ``d2`` is within :data:`D2_SLACK` of
        ``radius^2``, where the two could disagree.
        """
        ex, ey, d2 = self._offsets(px, sid, pos)
        np.multiply(ex, ex, out=d2)
        d2 += np.multiply(ey, ey, out=ey)
        r2 = self.radius * self.radius
        keep = d2 <= r2 * (1 + D2_SLACK)
        border = np.flatnonzero(keep & (d2 >= r2 * (1 - D2_SLACK)))
        if len(border):
            keep[border[self._dist(px, sid[border], pos[border]) > self.radius]] = False
        k = np.flatnonzero(keep)
        return np.take(sid, k), np.take(pos, k), np.take(d2, k)

    def owners(self, px: _Pixels, chunks):
        """``(sid, pos)``, one per pixel that has a pair in ``chunks`` (:meth:`pairs` or :meth:`pairs_any`,
        over all segments), ascending by pixel.

        Each pixel goes to its nearest segment only (the least distance,
        :meth:`_dist`; ties: the lower index), so that one pixel more or less
        changes one edge's count by at most one. The chunks' squared distances
        are folded into one entry per pixel (the least so far); a pair stays
        a candidate only while within :data:`D2_SLACK` of it (the nearest
        segment always is). A pixel left with one candidate has it as its
        nearest; only the pixels with several have their candidates'
        distances measured, and the least of those (then the lowest index)
        wins.
        """
        least = np.full(len(px), np.inf)
        parts: list = []
        held, limit = 0, len(px) + CHUNK_PAIRS
        for sid, pos, d2 in chunks:
            np.minimum.at(least, pos, d2)
            k = np.flatnonzero(d2 <= np.take(least, pos) * (1 + D2_SLACK) + D2_TINY)
            parts.append((np.take(sid, k), np.take(pos, k), np.take(d2, k)))
            held += len(k)
            if held > limit:  # bounded by the pixels (and their ties): the candidates a later chunk beat go
                parts = [self._still_near(parts, least)]
                held = len(parts[0][0])
                limit = max(limit, 2 * held)
        if not parts:
            return _EMPTY, _EMPTY
        sid, pos = (parts[0] if len(parts) == 1 else self._still_near(parts, least))[:2]
        owner = np.full(len(px), _NONE, np.int64)
        count = np.bincount(pos, minlength=len(px))
        one = np.flatnonzero(np.take(count, pos) == 1)
        owner[np.take(pos, one)] = np.take(sid, one)
        if len(one) < len(pos):  # several candidates: the least distance, then the lowest index
            many = np.flatnonzero(np.take(count, pos) > 1)
            sid, pos = np.take(sid, many), np.take(pos, many)
            dist = self._dist(px, sid, pos)
            nearest = np.full(len(px), np.inf)
            np.minimum.at(nearest, pos, dist)
            best = np.flatnonzero(dist == np.take(nearest, pos))
            np.minimum.at(owner, np.take(pos, best), np.take(sid, best))
        pos = np.flatnonzero(owner != _NONE)
        return owner[pos], pos

    @staticmethod
    def _still_near(parts: list, least: np.ndarray) -> tuple:
        """``(sid, pos, d2)`` of the candidates in ``parts`` still within :data:`D2_SLACK` of their pixel's ``least``."""
        sid, pos, d2 = (np.concatenate(c) for c in zip(*parts))
        k = np.flatnonzero(d2 <= np.take(least, pos) * (1 + D2_SLACK) + D2_TINY)
        return np.take(sid, k), np.take(pos, k), np.take(d2, k)

    def rows(self, px: _Pixels, sid: np.ndarray, pos: np.ndarray):
        """``(edge, pixel, major)`` of owner pairs (module docstring), pixels flat in their frames."""
        x_major = np.abs(np.take(self._cols[2], sid)) > np.abs(np.take(self._cols[3], sid))
        _, y, x = px.at(pos)
        return self.edge[sid], y * self.width + x, np.where(x_major, x, y)


def _from_segments(p0_px, p1_px, width: int, height: int, radius: float):
    """:func:`edge_neighbourhoods` with every pixel a candidate: the pixels around 1-px steps along each segment."""
    p0 = np.asarray(p0_px, np.float64).reshape(-1, 2)
    p1 = np.asarray(p1_px, np.float64).reshape(-1, 2)
    pad = radius + 1.0
    keep, q0, q1 = clip_to_box(p0, p1, np.array([-pad, -pad]), np.array([width - 1 + pad, height - 1 + pad]))
    if not keep.any():
        return _EMPTY, _EMPTY, _EMPTY
    q0, q1 = q0[keep], q1[keep]
    reach = int(np.ceil(radius)) + 1
    # every pixel centre within ``radius`` of a segment is within ``reach`` (per
    # axis) of the rounded point of some 1-px step along it
    steps = np.ceil(np.max(np.abs(q1 - q0), axis=1)).astype(np.intp) + 1
    seg = np.repeat(np.arange(len(q0)), steps)
    t = (np.arange(int(steps.sum())) - np.repeat(np.cumsum(steps) - steps, steps)) / np.maximum(steps - 1, 1)[seg]
    pts = q0[seg] + t[:, None] * (q1 - q0)[seg]
    offs = np.arange(-reach, reach + 1)
    ox, oy = np.meshgrid(offs, offs)
    cx = (np.round(pts[:, 0])[:, None] + ox.ravel()[None, :]).astype(np.int64).ravel()
    cy = (np.round(pts[:, 1])[:, None] + oy.ravel()[None, :]).astype(np.int64).ravel()
    inside = (cx >= 0) & (cx < width) & (cy >= 0) & (cy < height)
    pixels = _unique(cy[inside] * width + cx[inside])  # every candidate pixel, once, ascending
    return frames_neighbourhoods([(p0, p1, pixels)], width, height, radius)[0]
