"""The pairing's definition, every (pixel, segment) pair measured: the reference of tests/test_segment_pixels.py
and tests/test_owner_kernel.py (oracles.judge.segment_pixels and oracles.judge.owner_kernel are held to it)."""

import numpy as np


def owners_naive(p0, p1, w, h, pixels, radius=1.0):
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
