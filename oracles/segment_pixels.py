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
over the columns its part near that row reaches; each pair found is measured. The frames of a case are done in one pass
(:func:`frames_neighbourhoods`): they are stacked one above the other, and
a segment looks only at its own frame's rows, so no pair mixes two frames and
each frame's rows are the ones it would get alone; distances are measured in
the frame's own coordinates, so they are the same floats too.
"""

from __future__ import annotations

import numpy as np

_EMPTY = np.zeros(0, dtype=np.int64)


def clip_segments(p0: np.ndarray, p1: np.ndarray, lo: np.ndarray, hi: np.ndarray):
    """Liang-Barsky: the parts of segments ``p0 -> p1`` inside the box ``[lo, hi]``: ``(kept, q0, q1)``."""
    d = p1 - p0
    # the four boundaries at once: p t <= q for (x >= lo_x, y >= lo_y, x <= hi_x, y <= hi_y)
    p = np.concatenate([-d, d], axis=1)
    q = np.concatenate([p0 - lo, hi - p0], axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        r = q / p
        keep = np.isfinite(p0 + p1).all(axis=1) & ~((p == 0) & (q < 0)).any(axis=1)
        t0 = np.maximum(0.0, np.where(p < 0, r, -np.inf).max(axis=1))     # entering: the last boundary
        t1 = np.minimum(1.0, np.where(p > 0, r, np.inf).min(axis=1))      # leaving: the first
    keep &= t0 <= t1
    return keep, p0 + t0[:, None] * d, p0 + t1[:, None] * d


def edge_neighbourhoods(p0_px: np.ndarray, p1_px: np.ndarray, width: int, height: int,
                        radius: float = 1.0, mask: np.ndarray | None = None,
                        pixels: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
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
    pad = radius + 1.0
    grow = radius + 0.5            # each box is grown by a further 1/2 px, against rounding
    pitch = height                                         # frame k's rows start at k H in the stack
    seg0, seg1, seg_frame, edge_of = [], [], [], []
    pix, pix_frame = [], []
    for k, (p0, p1, pixels) in enumerate(frames):
        p0 = np.asarray(p0, np.float64).reshape(-1, 2)
        p1 = np.asarray(p1, np.float64).reshape(-1, 2)
        seg0.append(p0)
        seg1.append(p1)
        seg_frame.append(np.full(len(p0), k, np.int64))
        edge_of.append(np.arange(len(p0), dtype=np.int64))
        pixels = np.asarray(pixels, np.int64).reshape(-1)
        pix.append(pixels)
        pix_frame.append(np.full(len(pixels), k, np.int64))
    n_pix = np.array([len(p) for p in pix])
    empty = [(_EMPTY, _EMPTY, _EMPTY) for _ in frames]
    p0, p1 = np.concatenate(seg0), np.concatenate(seg1)
    keep, q0, q1 = clip_segments(p0, p1, np.array([-pad, -pad]), np.array([width - 1 + pad, height - 1 + pad]))
    if not keep.any() or not n_pix.sum():
        return empty
    q0, q1 = q0[keep], q1[keep]
    s_frame, s_edge = np.concatenate(seg_frame)[keep], np.concatenate(edge_of)[keep]
    pix, p_frame = np.concatenate(pix), np.concatenate(pix_frame)

    # pixels in the frame's own coordinates and in the stack (frame k's rows start at k * pitch)
    y = pix // width
    x = pix - y * width
    stacked = (y + p_frame * pitch) * width + x          # ascending: frame-major, then row-major
    # each row a segment's grown box spans, with the columns the segment's part within ``grow``
    # of that row reaches, grown: a pixel centre within ``radius`` of the segment is in them
    # (the nearest point is within ``radius`` in y, so in that part, and within ``radius`` in x)
    d_seg = q1 - q0
    # (rows of the frame only: a row off it would slice the next frame's pixels)
    row_lo = np.maximum(np.ceil(np.minimum(q0[:, 1], q1[:, 1]) - grow), 0).astype(np.int64)
    row_hi = np.minimum(np.floor(np.maximum(q0[:, 1], q1[:, 1]) + grow), height - 1).astype(np.int64)
    n_rows = np.maximum(row_hi - row_lo + 1, 0)
    seg = np.repeat(np.arange(len(q0)), n_rows)
    row = row_lo[seg] + np.arange(int(n_rows.sum())) - np.repeat(np.cumsum(n_rows) - n_rows, n_rows)
    dy = d_seg[seg, 1]
    with np.errstate(divide="ignore", invalid="ignore"):
        ta = np.where(dy != 0, (row - grow - q0[seg, 1]) / dy, 0.0)
        tb = np.where(dy != 0, (row + grow - q0[seg, 1]) / dy, 1.0)
    xa = q0[seg, 0] + np.clip(np.minimum(ta, tb), 0.0, 1.0) * d_seg[seg, 0]
    xb = q0[seg, 0] + np.clip(np.maximum(ta, tb), 0.0, 1.0) * d_seg[seg, 0]
    col_lo = np.maximum(np.ceil(np.minimum(xa, xb) - grow), 0).astype(np.int64)
    col_hi = np.minimum(np.floor(np.maximum(xa, xb) + grow), width - 1).astype(np.int64)
    # the drawn pixels of one row between two columns are one slice of ``stacked``
    start = (row + s_frame[seg] * pitch) * width
    a = np.searchsorted(stacked, start + col_lo)
    n = np.maximum(np.searchsorted(stacked, start + col_hi + 1) - a, 0)
    sid = np.repeat(seg, n)
    pos = np.arange(int(n.sum())) + np.repeat(a - (np.cumsum(n) - n), n)

    # the point of the segment nearest the pixel centre: a + u d, u in [0, 1], in the frame's coordinates
    dd_seg = d_seg[:, 0] * d_seg[:, 0] + d_seg[:, 1] * d_seg[:, 1]
    ex, ey = x[pos] - q0[sid, 0], y[pos] - q0[sid, 1]
    dx, dy, dd = d_seg[sid, 0], d_seg[sid, 1], dd_seg[sid]
    with np.errstate(divide="ignore", invalid="ignore"):
        u = np.clip(np.where(dd > 0, (ex * dx + ey * dy) / dd, 0.0), 0.0, 1.0)
    dist = np.hypot(ex - u * dx, ey - u * dy)
    near = dist <= radius
    sid, pos, dist = sid[near], pos[near], dist[near]
    # each pixel to its nearest segment only (ties: the lower index), so that one pixel more or
    # less changes one edge's count by at most one; only pixels near several segments need the choice
    several = np.bincount(pos, minlength=len(stacked))[pos] > 1
    if several.any():
        multi = np.flatnonzero(several)
        order = multi[np.lexsort((sid[multi], dist[multi], pos[multi]))]
        first = np.ones(len(order), bool)
        first[1:] = pos[order[1:]] != pos[order[:-1]]
        chosen = np.concatenate([np.flatnonzero(~several), order[first]])
        sid, pos = sid[chosen], pos[chosen]
    # one row per pixel: back in pixel order by placing each row at its pixel
    slot = np.full(len(stacked), -1, np.int64)
    slot[pos] = np.arange(len(pos))
    rows = slot[slot >= 0]
    sid, pos = sid[rows], pos[rows]
    x_major = np.abs(d_seg[sid, 0]) > np.abs(d_seg[sid, 1])
    major = np.where(x_major, x[pos], y[pos])
    edge, local = s_edge[sid], pix[pos]
    cut = np.searchsorted(pos, np.cumsum(n_pix)[:-1])      # the frames' rows, split
    return list(zip(np.split(edge, cut), np.split(local, cut), np.split(major, cut)))


def _from_segments(p0_px, p1_px, width: int, height: int, radius: float):
    """:func:`edge_neighbourhoods` with every pixel a candidate: the pixels around 1-px steps along each segment."""
    p0 = np.asarray(p0_px, np.float64).reshape(-1, 2)
    p1 = np.asarray(p1_px, np.float64).reshape(-1, 2)
    pad = radius + 1.0
    keep, q0, q1 = clip_segments(p0, p1, np.array([-pad, -pad]), np.array([width - 1 + pad, height - 1 + pad]))
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
    pixels = np.unique(cy[inside] * width + cx[inside])     # every candidate pixel, once, ascending
    return frames_neighbourhoods([(p0, p1, pixels)], width, height, radius)[0]
