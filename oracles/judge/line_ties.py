"""Sub-pixel ties: one-sided line pixels that the line itself does not decide.

A 1-px line (GL's diamond-exit rule; core.projector.raster) draws, at each pixel row a
y-major segment crosses, the pixel whose column holds the crossing (columns
and rows exchanged for an x-major segment)::

        x = k - 1/2      k + 1/2      k + 3/2
            |    k    |    k+1    |
    row y --+---------*-----------+--      * the line crosses row y at x_c
            |         ^ x_c within eps of k + 1/2: k or k + 1 is a tie

When the crossing ``x_c`` lies within the renderer's sub-pixel precision
``eps`` of the boundary ``k + 1/2`` between two pixels, which of ``k`` and
``k + 1`` is drawn depends on how the renderer rounded the segment's ends,
not on the segment: the oracle (Mesa) may put it on either side, and two
collinear segments that overlap (a cap's spoke and a side edge seen end-on)
may go one to each side. A disagreement there says nothing about the
candidate, so the line gate counts it apart (``subpixel_ties``) and leaves it
out of the balance sign test (oracles.judge.metrics.line_summary).

``eps`` for a segment of minor/major slope ``m`` is ``(1 + |m|) TIE_END_PX``
(oracles.judge.tolerances, with its derivation): each end may move by
``TIE_END_PX`` per coordinate, which moves the crossing by at most that
times ``1 + |m|``.

A one-sided pixel is a tie only when, besides, the image that lacks it drew
its partner across that boundary (``k`` for ``k + 1`` and the reverse): the
two images chose differently at the tie, or one drew both of its pixels (two
overlapping segments decided apart). A pixel lost from a line (a gap, a
dropped end) or drawn off it has no drawn partner and stays decided.
"""

from __future__ import annotations

import numpy as np

from .tolerances import TIE_END_PX


def tie_crossings(q_px: np.ndarray, a_px: np.ndarray, b_px: np.ndarray,
                  end_px: float = TIE_END_PX) -> tuple[np.ndarray, np.ndarray]:
    """Which pixels lie beside a sub-pixel tie of their segment, and the partner pixel across it.

    Parameters
    ----------
    q_px : (P, 2) ndarray
        Pixel centres ``[x, y]`` (whole numbers; core.conventions).
    a_px, b_px : (P, 2) ndarray
        Each pixel's segment, ``a -> b`` in pixel coordinates (the oracle's;
        a zero-length segment has no tie).
    end_px : float
        How far a renderer may move an end, per coordinate.

    Returns
    -------
    tie : (P,) ndarray of bool
        The segment crosses the pixel's row (y-major segment; column, x-major;
        both for an exact diagonal) between its ends, within
        ``(1 + |m|) end_px`` of one of the pixel's two boundaries across it.
    partner : (P, 2) ndarray of int64
        The pixel on the other side of that boundary (meaningful where ``tie``).
    """
    q = np.asarray(q_px, np.float64).reshape(-1, 2)
    a = np.asarray(a_px, np.float64).reshape(-1, 2)
    d = np.asarray(b_px, np.float64).reshape(-1, 2) - a
    tie = np.zeros(len(q), bool)
    partner = q.astype(np.int64)
    for major in (1, 0):                                  # y-major (crossing rows) first, then x-major
        minor = 1 - major
        dj, dn = d[:, major], d[:, minor]
        ok = (np.abs(dj) >= np.abs(dn)) & (dj != 0)
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (q[:, major] - a[:, major]) / dj          # where the segment reaches the pixel's row/column
            slope = np.abs(dn / dj)
            off = a[:, minor] + t * dn - q[:, minor]      # crossing minus the pixel centre, across the line
        ok &= (t >= 0.0) & (t <= 1.0)
        hit = ok & ~tie & (np.abs(np.abs(off) - 0.5) <= (1.0 + slope) * end_px)
        tie |= hit
        partner[hit, minor] += np.where(off[hit] > 0, 1, -1)
    return tie, partner


def partner_drawn(partner: np.ndarray, frame: np.ndarray, shape: tuple, drawn: np.ndarray) -> np.ndarray:
    """``(P,)`` bool: whether each ``partner`` pixel ``[x, y]`` of frame ``frame`` is drawn (outside the
    ``(H, W)`` image: not).

    ``drawn``: ascending flat indices ``k H W + y W + x`` of the pixels drawn in
    each frame ``k`` by the image that lacks the tie pixel.
    """
    h, w = shape
    x, y = partner[:, 0], partner[:, 1]
    inside = (x >= 0) & (x < w) & (y >= 0) & (y < h)
    out = np.zeros(len(partner), bool)
    if inside.any() and len(drawn):
        key = (np.asarray(frame)[inside] * (h * w) + y[inside] * w + x[inside]).astype(np.int64)
        at = np.minimum(np.searchsorted(drawn, key), len(drawn) - 1)
        out[inside] = drawn[at] == key
    return out
