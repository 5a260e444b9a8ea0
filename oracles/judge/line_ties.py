r"""Sub-pixel ties: one-sided line pixels that the line itself does not decide.

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
(oracles.tolerances, with its derivation): each end may move by
``TIE_END_PX`` per coordinate, which moves the crossing by at most that
times ``1 + |m|``.

A one-sided pixel is a tie only when, besides, the image that lacks it drew
its partner across that boundary (``k`` for ``k + 1`` and the reverse): the
two images chose differently at the tie, or one drew both of its pixels (two
overlapping segments decided apart). A pixel lost from a line (a gap, a
dropped end) or drawn off it has no drawn partner and stays decided.

Ties at the ends (:func:`tie_ends`). A line's first and last pixels are
decided by its ends, not by a crossing: pixel ``P`` is drawn when the segment
exits ``P``'s diamond, so where an end ``E`` lies on the diamond's exit side
(going on along the segment from ``E`` leaves the diamond), ``P`` is drawn
exactly when ``E`` is outside it, ``|E - P|_1 >= 1/2``::

         /\
        / P\ *E        E at the diamond's exit: drawn when |E - P|_1 >= 1/2
        \  /
         \/

An end moved by at most ``end_px`` per coordinate moves ``|E - P|_1`` by at
most ``2 end_px``: within that of ``1/2`` the oracle's answer is its
rounding's, not the line's, and ``P`` is a tie whichever image drew it. There
is no partner to ask for (the other answer is "not drawn"), so what it can
excuse is bounded by the zone alone: an end falls in it with probability
about ``4 (2 end_px) / 2 = 4 end_px`` (the band ``2 end_px`` wide in ``L1``
along the diamond's exit half, ``sqrt 2`` long, over a pixel's area), 1/64
of line ends: a line short or long at every end is still named on the rest.
An end on the image's border (where a line leaving the picture is cut for
the comparison, not by the renderer) is no end of the line and decides
nothing.
"""

from __future__ import annotations

import numpy as np

from ..tolerances import TIE_END_PX


def tie_crossings(
    q_px: np.ndarray, a_px: np.ndarray, b_px: np.ndarray, end_px: float = TIE_END_PX
) -> tuple[np.ndarray, np.ndarray]:
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
    for major in (1, 0):  # y-major (crossing rows) first, then x-major
        minor = 1 - major
        dj, dn = d[:, major], d[:, minor]
        ok = (np.abs(dj) >= np.abs(dn)) & (dj != 0)
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (q[:, major] - a[:, major]) / dj  # where the segment reaches the pixel's row/column
            slope = np.abs(dn / dj)
            off = a[:, minor] + t * dn - q[:, minor]  # crossing minus the pixel centre, across the line
        ok &= (t >= 0.0) & (t <= 1.0)
        hit = ok & ~tie & (np.abs(np.abs(off) - 0.5) <= (1.0 + slope) * end_px)
        tie |= hit
        partner[hit, minor] += np.where(off[hit] > 0, 1, -1)
    return tie, partner


def tie_ends(
    q_px: np.ndarray, a_px: np.ndarray, b_px: np.ndarray, box: tuple | None = None, end_px: float = TIE_END_PX
) -> np.ndarray:
    """``(P,)`` bool: which pixels are decided by an end of their segment within ``end_px`` per coordinate.

    Pixel ``q`` is an end tie (module docstring) when an end ``E`` of its
    segment ``a -> b`` has ``| |E - q|_1 - 1/2 | <= 2 end_px`` and lies on
    the exit side of ``q``'s diamond: the ``L1`` distance from ``q`` grows
    along ``b - a`` at ``E`` (a coordinate of ``E - q`` within ``2 end_px``
    of 0 counts either way). ``box``: ``((x, y), (x, y))``, the corners the
    segments were cut to; an end within ``1e-6`` px of its border is left out.
    """
    q = np.asarray(q_px, np.float64).reshape(-1, 2)
    a = np.asarray(a_px, np.float64).reshape(-1, 2)
    b = np.asarray(b_px, np.float64).reshape(-1, 2)
    d = b - a
    zone = 2.0 * end_px
    tie = np.zeros(len(q), bool)
    for e in (a, b):
        off = e - q
        near = np.abs(np.abs(off).sum(axis=1) - 0.5) <= zone
        slope_l1 = np.where(np.abs(off) <= zone, np.abs(d), np.sign(off) * d).sum(axis=1)
        real = (d != 0).any(axis=1)
        if box is not None:
            (x0, y0), (x1, y1) = box
            edge = np.column_stack([e[:, 0] - x0, x1 - e[:, 0], e[:, 1] - y0, y1 - e[:, 1]])
            real &= ~(np.abs(edge) <= 1e-6).any(axis=1)
        tie |= near & (slope_l1 >= 0) & real
    return tie


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


def fold_ties(samples: dict, band_px: int, end_px: float = TIE_END_PX, segs: np.ndarray | None = None) -> None:
    """Count either choice at an exact tie of a binary line's band as right, in place: ``samples`` of
    oracles.judge.line_style.measure, on a binary drawing whose lines are ``band_px`` pixels across.

    A binary line ``band_px`` pixels across whose band edge (the exact minor coordinate
    plus ``band_px / 2``) falls on a pixel centre (within ``(1 + |m|) end_px``, as
    :func:`tie_crossings`) must leave out one of the two edge pixels: a correct
    renderer's centroid there is half a pixel to either side (a 1-px line at
    x = 319.5 drawn in column 319 or 320; the reference drawing takes both).
    Such a sample's offset across the line, ``e`` along the minor axis, is moved
    half a pixel towards zero (``e - sign(e) min(|e|, 1/2)``): both choices
    read 0, no bias either way; a line a whole pixel off still reads half a pixel.
    ``segs``: the frame's oracle segments ``(K, 2, 2)`` (``samples["segment"]``
    indexes them): the samples of lines whose ends tie are left out (:func:`drop_end_ties`).
    """
    normal, offset, point = samples["normal"], samples["offset"], samples["point"]
    if len(offset) == 0:
        return
    minor = (np.abs(normal[:, 1]) > np.abs(normal[:, 0])).astype(np.intp)  # the normal's larger component
    k = np.arange(len(offset))
    across = normal[k, minor]
    slope = np.sqrt(np.maximum(1.0 / across**2 - 1.0, 0.0))
    edge = point[k, minor] + band_px / 2.0
    tie = np.abs(edge - np.rint(edge)) <= (1.0 + slope) * end_px
    e = offset[tie] / across[tie]
    offset[tie] = (e - np.sign(e) * np.minimum(np.abs(e), 0.5)) * across[tie]
    if segs is not None:
        drop_end_ties(samples, segs, end_px)


def end_ties(segs: np.ndarray, end_px: float = TIE_END_PX) -> np.ndarray:
    """``(K,)`` bool: which segments ``(K, 2, 2)`` have an end coordinate on a pixel boundary ``k + 1/2``
    (within ``end_px``, as the ties above)."""
    segs = np.asarray(segs, dtype=np.float64).reshape(-1, 2, 2)
    return (np.abs(segs - np.floor(segs) - 0.5) <= end_px).any(axis=(1, 2))


def drop_end_ties(samples: dict, segs: np.ndarray, end_px: float = TIE_END_PX) -> None:
    """Leave out, in place, the samples of segments with an end on a pixel boundary (:func:`end_ties`),
    unless every segment of the frame has one.

    A binary rule that rounds a line's ends to pixel centres (OpenCV's
    ``cv2.line``, Pillow's) has no right answer for an end coordinate on the
    boundary ``k + 1/2`` between two pixels: ``k`` and ``k + 1`` are equally
    near, and a rule that always takes one (OpenCV: upwards) moves every line
    ending there the same way, by ``(1 - t) / 2`` px along that axis at
    parameter ``t`` from the end, up to half a pixel. Such a line's centres
    cannot tell that rounding from a half-pixel offset near the end (a shift
    is both ends moved), so they are no evidence of where the lines are: the
    offset is measured on the other lines. Counting either rounding as right
    on them instead (moving each sample by ``(1 - t) |n_i| / 2`` towards zero)
    would read a half-pixel offset of those lines as a quarter. What it cannot
    hide: the other lines keep every sample; a frame whose every line ends on
    a boundary keeps them all (judged as before: either rounding may fail it).
    """
    if len(samples["offset"]) == 0:
        return
    tied = end_ties(segs, end_px)
    if tied.all() or not tied.any():  # every segment tied, or none: every sample kept
        return
    keep = ~tied[samples["segment"]]
    n = len(keep)
    for key, value in samples.items():
        if isinstance(value, np.ndarray) and len(value) == n:
            samples[key] = value[keep]
