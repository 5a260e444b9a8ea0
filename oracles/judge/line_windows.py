"""Where the line measure looks along the oracle's segments: the windows across each line, clear of junctions.

:func:`windows` is :func:`oracles.judge.line_style.measure`'s geometry: it
depends on the segments and the image size only, so one frame's windows serve
every image measured on its lines (the candidate's, a reference drawing's).
Each window's numbers are found elementwise, so the windows that the image's
border or a junction drops are dropped first, and the per-window arrays are
built for the windows kept only (a frame of a few long lines has thousands of
steps along them; the frames judge finds them once a frame).

The junction test (a window is dropped when another segment comes within the
guard) is decided for each (window, segment) pair by :func:`oracles.segment_geometry.seg_distance`'s
arithmetic, but only for the pairs that can be that close: a window farther
than the guard from a segment's bounding box is farther from the segment, and
along a line the windows in a box form one interval, found per pair of
segments (:func:`_near_pairs`). Segments with coordinates past 1e150 (whose
squared lengths could overflow to a NaN distance) take every pair.
"""

from __future__ import annotations

import numpy as np

from ..segment_geometry import pair_distance, seg_distance

#: Points whose distances to every segment are found at once (the ``(n, K)`` temporaries stay small).
CHUNK_ELEMENTS = 1 << 16


def _near_pairs(segs, i, major, a_maj, a_min, d_maj, d_min, start, count, guard):
    """``(window, segment)`` index pairs that may lie within ``guard`` of each other: every pair that does.

    The windows of long segment ``l`` (``segs[i[l]]``) lie on its line at major positions ``start[l] +
    0, 1, ... count[l] - 1`` (window ``sum(count[:l]) + step``). A point farther than ``guard`` from a
    segment's bounding box is farther from the segment, so for each (long segment, other segment) pair
    only the positions whose point falls in the other's box grown by ``guard + 1`` are kept, the interval
    widened by a step each side (whatever the rounding of the interval's ends).
    """
    lo_xy, hi_xy = np.minimum(segs[:, 0], segs[:, 1]) - guard - 1, np.maximum(segs[:, 0], segs[:, 1]) + guard + 1
    ll, jj = np.nonzero(i[:, None] != np.arange(len(segs))[None])  # (long segment, another segment)
    k = np.arange(len(i))[ll]
    maj0, maj1 = lo_xy[jj, major[ll]], hi_xy[jj, major[ll]]
    min0, min1 = lo_xy[jj, 1 - major[ll]], hi_xy[jj, 1 - major[ll]]
    slope = (d_min / d_maj)[k]  # |slope| <= 1: the major axis
    flat = slope == 0
    step = np.where(flat, 1.0, slope)  # a flat line's e0, e1 are not used (lo, hi below)
    e0 = a_maj[k] + (min0 - a_min[k]) / step
    e1 = a_maj[k] + (min1 - a_min[k]) / step
    inside = (min0 <= a_min[k]) & (a_min[k] <= min1)
    lo = np.where(flat, np.where(inside, -np.inf, np.inf), np.minimum(e0, e1))
    hi = np.where(flat, np.where(inside, np.inf, -np.inf), np.maximum(e0, e1))
    first = np.maximum(np.ceil(np.maximum(np.maximum(lo, maj0), start[k]) - 1), start[k])
    last = np.minimum(np.floor(np.minimum(np.minimum(hi, maj1), start[k] + count[k] - 1) + 1), start[k] + count[k] - 1)
    n = np.maximum(last - first + 1, 0).astype(np.intp)
    base = (np.cumsum(count) - count)[k] + (np.where(n > 0, first, start[k]) - start[k]).astype(np.intp)  # n = 0: any
    windows = np.repeat(base - (np.cumsum(n) - n), n) + np.arange(int(n.sum()))
    return windows, np.repeat(jj, n)


def windows(segs: np.ndarray, shape, radius: int, guard: float) -> dict:
    """The windows across the segments ``segs`` ``(K, 2, 2)`` (px) in an image of ``shape`` ``(H, W)``.

    Along each segment long enough (``2 guard + 1`` px), at every integer step
    of its major axis ``guard`` px clear of its ends and inside the image, a
    window of ``2 radius + 1`` pixels across it, whose pixels are all inside
    the image and which no other segment comes within ``guard`` of (a
    junction, a crossing); segment by segment, each in ascending steps.
    ``flat``: ``(n, 2 radius + 1)`` flat pixel indices ``y W + x`` of each window, across the line;
    ``minor``: their coordinate along the minor axis (float); ``exact``: the
    exact line's there; ``across``: the unit normal's minor component;
    ``normal`` ``(n, 2)``: the unit normal; ``segment``: the window's segment;
    ``point`` ``(n, 2)``: the exact line's point at the window (x, y).
    """
    h, w = shape
    r = radius
    segs = np.asarray(segs, dtype=np.float64).reshape(-1, 2, 2)
    a, b = segs[:, 0], segs[:, 1]
    d = b - a
    length = np.hypot(d[:, 0], d[:, 1])
    i = np.flatnonzero(length >= 2 * guard + 1)
    a, b, d, length = a[i], b[i], d[i], length[i]
    major = np.where(np.abs(d[:, 0]) >= np.abs(d[:, 1]), 0, 1)
    minor = 1 - major
    k = np.arange(len(i))
    a_maj, b_maj, d_maj = a[k, major], b[k, major], d[k, major]
    a_min, d_min = a[k, minor], d[k, minor]
    along = guard * np.abs(d_maj) / length  # guard along the line, on the major axis
    extent = np.where(major == 0, w, h)
    start = np.maximum(np.ceil(np.minimum(a_maj, b_maj) + along), 0)
    stop = np.minimum(np.floor(np.maximum(a_maj, b_maj) - along), extent - 1)
    count = np.maximum(stop - start + 1, 0).astype(np.intp)
    owner = np.repeat(np.arange(len(i)), count)  # the windows, segment by segment
    pos = np.repeat(start - (np.cumsum(count) - count), count) + np.arange(len(owner))
    minor_exact = a_min[owner] + (pos - a_maj[owner]) * d_min[owner] / d_maj[owner]
    centre = np.rint(minor_exact)
    horizontal = major[owner] == 0
    keep = (centre - r >= 0) & (centre + r <= np.where(horizontal, h, w) - 1)
    pt = np.empty((len(pos), 2))
    pt[:, 0] = np.where(horizontal, pos, minor_exact)
    pt[:, 1] = np.where(horizontal, minor_exact, pos)
    if len(segs) > 1 and keep.any():  # drop windows near another segment
        if np.all(np.abs(segs) < 1e150):  # squares finite: no distance is NaN
            win, other = _near_pairs(segs, i, major, a_maj, a_min, d_maj, d_min, start, count, guard)
            near = ~(pair_distance(pt[win], segs[other, 0], segs[other, 1]) > guard)
            keep[win[near]] = False
        else:  # every pair (a NaN distance drops the window)
            idx = np.flatnonzero(keep)
            chunk = max(1, CHUNK_ELEMENTS // len(segs))
            for c in range(0, len(idx), chunk):
                sel = idx[c : c + chunk]
                dist = seg_distance(pt[sel], segs[:, 0], segs[:, 1])
                dist[np.arange(len(sel)), i[owner[sel]]] = np.inf  # its own segment
                keep[sel] = dist.min(axis=1) > guard
    owner, pos, minor_exact, centre, horizontal, pt = (
        owner[keep],
        pos[keep],
        minor_exact[keep],
        centre[keep],
        horizontal[keep],
        pt[keep],
    )
    unit = d / length[:, None]
    normal = np.empty_like(unit)
    normal[:, 0], normal[:, 1] = -unit[:, 1], unit[:, 0]
    offsets = np.arange(-r, r + 1)
    win = centre[:, None] + offsets[None]  # (n, 2r + 1) minor coordinates
    # each window's pixels, y W + x: along a row (horizontal line: the window is a column) or a column
    pos_i, centre_i = pos.astype(np.intp), centre.astype(np.intp)
    step = np.where(horizontal, w, 1)  # the flat index's step across the line
    first = np.where(horizontal, pos_i + (centre_i - r) * w, pos_i * w + centre_i - r)
    return {
        "flat": first[:, None] + step[:, None] * np.arange(2 * r + 1)[None],
        "minor": win,
        "exact": minor_exact,
        "across": normal[owner, minor[owner]],
        "normal": normal[owner],
        "segment": i[owner],
        "point": pt,
    }
