"""Where a renderer's free line ends stop, measured from its image (for :mod:`oracles.judge.line_style`).

Where lines meet, an end pixel is covered by the other line's pixels (an
antialiased fringe, a wide line's width); only a *free* end, with no other
segment near, shows where its line stops. There the coverage summed across
the line, followed along it past the end, falls from the line's width to 0;
the end is where it crosses half the width. A butt end measures 0 past the
exact end, a round or square cap up to half the width; a dropped or added
pixel moves it by 1.
"""

from __future__ import annotations

import numpy as np

from ..segment_geometry import seg_distance
from ..tolerances import NAMING
from .line_profile import GUARD_PX, PROFILE_RADIUS_PX

#: A segment end is measured when no other segment comes this close to it (px): the profile along the
#: line (4 px past the end) stays clear of every other line's window.
FREE_END_PX = GUARD_PX + 4.0
#: Along-line profile of an end: from this far inside the line (px) to END_REACH_PX past its end.
END_INSIDE_PX = 6.0
END_REACH_PX = 4.0


def _bilinear(cov: np.ndarray, q: np.ndarray, level: float = 1.0) -> np.ndarray:
    """Coverage ``cov / level`` at points ``q (..., 2)`` (x, y; pixel centres at integers), bilinear; 0 outside."""
    h, w = cov.shape
    x0, y0 = np.floor(q[..., 0]).astype(np.intp), np.floor(q[..., 1]).astype(np.intp)
    fx, fy = q[..., 0] - x0, q[..., 1] - y0
    out = np.zeros(q.shape[:-1])
    for dx, dy, wgt in ((0, 0, (1 - fx) * (1 - fy)), (1, 0, fx * (1 - fy)), (0, 1, (1 - fx) * fy), (1, 1, fx * fy)):
        xx, yy = x0 + dx, y0 + dy
        ok = (xx >= 0) & (xx < w) & (yy >= 0) & (yy < h)
        out[ok] += wgt[ok] * (cov[yy[ok], xx[ok]] / level)
    return out


def measure_ends(cov: np.ndarray, segs: np.ndarray, level: float = 1.0) -> np.ndarray:
    """Where each free end of the oracle's segments stops in the image: ``(E,)`` px past the exact end.

    An end is free when inside the image (the profile too) and no other
    segment comes within :data:`FREE_END_PX`. Along the line, from
    :data:`END_INSIDE_PX` inside to :data:`END_REACH_PX` past the end, every
    0.25 px, the coverage summed across the line (bilinear, 0.5 px steps,
    :data:`PROFILE_RADIUS_PX` each side) is the line's width there; the end is
    where it last falls to half the width of the line's inner part. The
    coverage is ``cov / level`` (``cov`` may be the grey levels, ``level`` the line's).
    Every end's test and profile are computed together; the ends come in the
    segments' order, each segment's start before its end.
    """
    h, w = cov.shape
    segs = np.asarray(segs, dtype=np.float64).reshape(-1, 2, 2)
    s = np.arange(-END_INSIDE_PX, END_REACH_PX + 1e-9, 0.25)
    t = np.arange(-PROFILE_RADIUS_PX, PROFILE_RADIUS_PX + 1e-9, 0.5)
    margin = PROFILE_RADIUS_PX + END_REACH_PX + 2
    d = segs[:, 1] - segs[:, 0]
    length = np.hypot(d[:, 0], d[:, 1])
    long_enough = np.flatnonzero(length >= END_INSIDE_PX + 2)
    if len(long_enough) == 0:
        return np.zeros(0)
    unit = d[long_enough] / length[long_enough, None]
    normal = np.stack([-unit[:, 1], unit[:, 0]], axis=1)
    # each segment's start (outward: -unit), then its end (+unit)
    seg = np.repeat(long_enough, 2)
    end = segs[long_enough].reshape(-1, 2)
    out_dir = np.stack([-unit, unit], axis=1).reshape(-1, 2)
    normal = np.repeat(normal, 2, axis=0)
    free = (margin <= end[:, 0]) & (end[:, 0] <= w - 1 - margin) & (margin <= end[:, 1]) & (end[:, 1] <= h - 1 - margin)
    if len(segs) > 1 and free.any():
        dist = seg_distance(end, segs[:, 0], segs[:, 1])
        dist[np.arange(len(end)), seg] = np.inf  # its own segment
        free &= dist.min(axis=1) > FREE_END_PX
    end, out_dir, normal = end[free], out_dir[free], normal[free]
    if len(end) == 0:
        return np.zeros(0)
    q = (
        end[:, None, None, :]
        + s[None, :, None, None] * out_dir[:, None, None, :]
        + t[None, None, :, None] * normal[:, None, None, :]
    )  # (ends, len(s), len(t), 2)
    masses = _bilinear(cov, q, level).sum(axis=2) * 0.5
    out = []
    for mass in masses:
        inner = float(np.median(mass[s <= -2.5]))
        if inner < NAMING.profile_min_mass:
            continue
        above = np.flatnonzero(mass >= inner / 2.0)
        k = above.max()
        if k + 1 >= len(s):  # still drawn at the end of the reach
            out.append(float(s[-1]))
            continue
        m0, m1 = mass[k], mass[k + 1]  # cross half the inner width between s[k] and s[k + 1]
        out.append(float(s[k] + (s[k + 1] - s[k]) * (m0 - inner / 2.0) / max(m0 - m1, 1e-12)))
    return np.asarray(out)
