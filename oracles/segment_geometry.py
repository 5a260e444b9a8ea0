"""2-D segments in pixel space, on the oracle side: the distance of points to segments and the parts of
segments inside a box.

- :func:`seg_distance`: every point against every segment, ``(N, K)``;
- :func:`pair_distance`: each point against its own segment, ``(N,)``, with :func:`seg_distance`'s
  arithmetic element by element (the same value to the bit for the same pair);
- :func:`nearest_on_segments`: each point's nearest point on any of the segments, its distance and its
  segment (the registration's correspondences: squared distances compared, in chunks of points);
- :func:`clip_to_box`: Liang-Barsky against any box ``[lo, hi]``, every row kept in place with a mask.

Here rather than in core: the judge and the diagnosis measure the candidate against the oracle's lines
with their own geometry, never core's (core.projector.clipping.clip_to_image is the renderer's own guard,
against the image only, returning the kept rows).
"""

from __future__ import annotations

import numpy as np

__all__ = ["seg_distance", "pair_distance", "nearest_on_segments", "clip_to_box"]


def seg_distance(q: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``(N, K)`` distance of points ``q (N, 2)`` to segments ``a -> b (K, 2)`` (x and y apart: no (N, K, 2) array)."""
    abx, aby = b[:, 0] - a[:, 0], b[:, 1] - a[:, 1]
    len2 = np.maximum(abx * abx + aby * aby, 1e-300)
    qx, qy = q[:, 0:1], q[:, 1:2]
    t = np.clip(((qx - a[:, 0]) * abx + (qy - a[:, 1]) * aby) / len2, 0.0, 1.0)
    return np.hypot(a[:, 0] + t * abx - qx, a[:, 1] + t * aby - qy)


def pair_distance(q: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``(N,)`` distance of each point ``q[n]`` to its segment ``a[n] -> b[n]``: :func:`seg_distance`'s
    arithmetic, element by element, so each pair's value is the same to the bit."""
    abx, aby = b[:, 0] - a[:, 0], b[:, 1] - a[:, 1]
    len2 = np.maximum(abx * abx + aby * aby, 1e-300)
    qx, qy = q[:, 0], q[:, 1]
    t = np.clip(((qx - a[:, 0]) * abx + (qy - a[:, 1]) * aby) / len2, 0.0, 1.0)
    return np.hypot(a[:, 0] + t * abx - qx, a[:, 1] + t * aby - qy)


def nearest_on_segments(q: np.ndarray, a: np.ndarray, b: np.ndarray):
    """For points ``q (N, 2)``: the nearest point on segments ``a -> b (K, 2)``, its distance and segment."""
    out = np.empty_like(q)
    dist = np.empty(len(q))
    which = np.empty(len(q), dtype=np.intp)
    ab = b - a
    len2 = np.maximum(ab[:, 0] * ab[:, 0] + ab[:, 1] * ab[:, 1], 1e-300)
    step = max(1, 2_000_000 // max(len(a), 1))
    for k in range(0, len(q), step):
        qx, qy = q[k : k + step, 0:1], q[k : k + step, 1:2]  # (n, 1): against every segment at once
        t = np.clip(((qx - a[:, 0]) * ab[:, 0] + (qy - a[:, 1]) * ab[:, 1]) / len2, 0.0, 1.0)
        fx, fy = a[:, 0] + t * ab[:, 0], a[:, 1] + t * ab[:, 1]
        dx, dy = fx - qx, fy - qy
        d2 = dx * dx + dy * dy
        j = np.argmin(d2, axis=1)
        rows = np.arange(len(qx))
        out[k : k + step, 0], out[k : k + step, 1] = fx[rows, j], fy[rows, j]
        dist[k : k + step] = np.sqrt(d2[rows, j])
        which[k : k + step] = j
    return out, dist, which


#: :func:`clip_to_box` keeps a segment whole, without its ratios, when both ends are inside the box by
#: more than this (px): far beyond the ratios' rounding (~1e-16 relative) on a box of < 10^9 px.
INSIDE_PX = 1e-3


def clip_to_box(p0: np.ndarray, p1: np.ndarray, lo: np.ndarray, hi: np.ndarray):
    """Liang-Barsky: the parts of segments ``p0 -> p1`` inside the box ``[lo, hi]``: ``(kept, q0, q1)``.

    A segment with both ends inside the box by more than :data:`INSIDE_PX` is
    kept whole, ``t`` from 0 to 1, without the four ratios: each ratio is then
    below 0 (entering) or above 1 (leaving) by far more than its rounding, so
    the general formula gives ``t0 = 0``, ``t1 = 1`` too, and the same floats.
    """
    p0, p1 = np.asarray(p0, np.float64), np.asarray(p1, np.float64)
    d = p1 - p0
    inside = np.ones(len(p0), bool)
    columns = p0.shape[1] if p0.ndim == 2 else 0
    lo_in = np.broadcast_to(np.asarray(lo, np.float64) + INSIDE_PX, (columns,))
    hi_in = np.broadcast_to(np.asarray(hi, np.float64) - INSIDE_PX, (columns,))
    for k in range(columns):  # column by column: no reduction over the rows' 2 values
        for q in (p0[:, k], p1[:, k]):
            inside &= q > lo_in[k]
            inside &= q < hi_in[k]
    if inside.all():
        return inside, p0 + 0.0 * d, p0 + d
    with np.errstate(invalid="ignore"):  # rows not inside are overwritten below
        keep, q0, q1 = inside.copy(), p0 + 0.0 * d, p0 + d
    rest = np.flatnonzero(~inside)
    keep[rest], q0[rest], q1[rest] = _clip_ratios(p0[rest], p1[rest], lo, hi)
    return keep, q0, q1


def _clip_ratios(p0: np.ndarray, p1: np.ndarray, lo: np.ndarray, hi: np.ndarray):
    """:func:`clip_to_box` by the four boundaries' ratios (Liang-Barsky), for any segments."""
    d = p1 - p0
    # the four boundaries at once: p t <= q for (x >= lo_x, y >= lo_y, x <= hi_x, y <= hi_y)
    p = np.concatenate([-d, d], axis=1)
    q = np.concatenate([p0 - lo, hi - p0], axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        r = q / p
        keep = np.isfinite(p0 + p1).all(axis=1) & ~((p == 0) & (q < 0)).any(axis=1)
        t0 = np.maximum(0.0, np.where(p < 0, r, -np.inf).max(axis=1))  # entering: the last boundary
        t1 = np.minimum(1.0, np.where(p > 0, r, np.inf).min(axis=1))  # leaving: the first
    keep &= t0 <= t1
    return keep, p0 + t0[:, None] * d, p0 + t1[:, None] * d
