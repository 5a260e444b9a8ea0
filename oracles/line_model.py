r"""One model of a drawn line: the pixels a correct drawing of segments gives under a raster rule.

Pixel space is :mod:`wirecheck.core.conventions`': pixel ``(x, y)`` has its centre at integer
coordinates, ``x`` to the right, ``y`` down; an image is ``(H, W)``, indexed ``[y, x]``; a segment is
``[[x0, y0], [x1, y1]]`` in px, so ``segs_px`` is ``(K, 2, 2)`` float. Functions return index arrays
(``rr, cc``: rows and columns) or ``(H, W)`` bool masks; the caller paints (as ``skimage.draw``).

Rules (:data:`RULES`):

``"gl"``
    GL's diamond-exit rule as Mesa's llvmpipe draws it (the oracle's): one pixel per step of the
    major axis, the first pixel drawn when the segment leaves its diamond, the last not when the end
    lies inside its own (:func:`wirecheck.core.projector.raster.line_pixels`, [docs/raster.md]).
    Its sub-pixel ties are :mod:`oracles.judge.line_ties`'.
``"rounded"``
    Each end rounded to the nearest pixel centre (``floor(v + 1/2)``), then one pixel per step of the
    major axis between the rounded ends, **both ends drawn**, each the pixel nearest the rounded line's
    exact minor coordinate (:func:`rounded_pixels`): Bresenham's line, Pillow's ``ImageDraw.line`` given
    rounded ends, OpenCV's ``cv2.line`` ``LINE_8``. A line of ``n`` steps has ``n + 1`` pixels where GL's
    has ``n``. Both rules are unbiased: a correct drawing's pixels lie within half a pixel of the exact
    line, on either side alike.

What the rules cannot decide (:func:`rounded_ties`), a mask of pixels that a correct drawing may or
may not take:

1. *across the line*: where the rounded line's minor coordinate is exactly a half pixel, the pixels
   either side (Bresenham's error term, Pillow's and OpenCV's each break it their own way); and so for
   the line between each rounding of its ends in 2. and 3.;
2. *at an end*: an end within ``end_tie_px`` of a half pixel on an axis (a fixed-point renderer rounds
   its own way: OpenCV's 4 fraction bits put an end within 1/32 px of the half on it): every pixel that
   differs between the drawings with that end rounded down or up;
3. *an end made by the image border*: an end outside the image is rounded where it lies by a renderer
   that draws the whole line and drops the pixels outside, and near the border by one that clips first:
   every pixel that differs between the drawings with that end rounded, or replaced by the pixels
   around where the line crosses the border grown by a few pixels (:data:`CLIP_MARGINS_PX`): either way
   across the line, and along it where the crossing is a half pixel (a renderer's float error rounds it
   either way). A segment passing within 2 px of the image counts as reaching it. An end outside the
   image draws no end pixel, so it decides no end fault.

A binary band of width ``w`` (:func:`band_pixels`): the pixel centres within ``w / 2`` of the line
(across it), moved ``lean`` px along its normal: the symmetric reference of wide binary lines.
"""

from __future__ import annotations

import numpy as np
from wirecheck.core.projector.clipping import clip_to_image
from wirecheck.core.projector.raster import line_pixels

from .tolerances import ROUNDED_END_TIE_PX

__all__ = [
    "RULES",
    "END_TIE_PX",
    "rounded_pixels",
    "rounded_ties",
    "expected",
    "band_distances",
    "band_pixels",
    "band_holding",
]

#: The aliased rules the model draws (module docstring).
RULES = ("gl", "rounded")

#: How close to a half pixel (px, per axis) a rounded-rule end may be rounded either way: the default of
#: Tolerances.rounded_end_tie_px (oracles.tolerances, with its derivation).
END_TIE_PX = ROUNDED_END_TIE_PX


def _round_half_up(v: np.ndarray) -> np.ndarray:
    """``floor(v + 1/2)`` exactly (``v + 0.5`` itself may round up)."""
    r = np.floor(v)
    return r + (v - r >= 0.5)


def _step(a: np.ndarray, b: np.ndarray):
    """The rounded rule between integer ends ``a, b`` ``(K, 2)`` int64: ``(x, y, tie_x, tie_y, seg)``.

    Every pixel of every segment (``seg`` its row in ``a``); ``tie_*``: the partner pixel across the line
    where the minor coordinate is exactly a half pixel (the pixel itself elsewhere).
    """
    d = b - a
    x_major = np.abs(d[:, 0]) > np.abs(d[:, 1])  # a diagonal steps y (its minor is exact anyway)
    n = np.maximum(np.abs(d[:, 0]), np.abs(d[:, 1]))
    seg = np.repeat(np.arange(len(a)), n + 1)
    start = np.cumsum(n + 1) - (n + 1)
    k = np.arange(len(seg)) - start[seg]
    nn = np.maximum(n[seg], 1)
    major_ax = np.where(x_major, 0, 1)[seg]
    minor_ax = 1 - major_ax
    a_major = np.take_along_axis(a[seg], major_ax[:, None], 1)[:, 0]
    a_minor = np.take_along_axis(a[seg], minor_ax[:, None], 1)[:, 0]
    d_major = np.take_along_axis(d[seg], major_ax[:, None], 1)[:, 0]
    d_minor = np.take_along_axis(d[seg], minor_ax[:, None], 1)[:, 0]
    major = a_major + np.sign(d_major) * k
    # exact minor = a_minor + k d_minor / n; nearest pixel floor(exact + 1/2) in integers:
    num = 2 * k * d_minor + nn  # 2 n (exact - a_minor) + n
    minor = a_minor + np.floor_divide(num, 2 * nn)
    tied = (np.mod(num, 2 * nn) == 0) & (n[seg] > 0)  # exact minor on a half pixel: minor or minor - 1
    partner = minor - tied
    x = np.where(major_ax == 0, major, minor)
    y = np.where(major_ax == 0, minor, major)
    tx = np.where(major_ax == 0, major, partner)
    ty = np.where(major_ax == 0, partner, major)
    return x, y, tx, ty, seg


def _paint(shape, x, y) -> np.ndarray:
    h, w = shape
    img = np.zeros(shape, bool)
    inside = (x >= 0) & (x < w) & (y >= 0) & (y < h)
    img[y[inside], x[inside]] = True
    return img


def _clip(segs_px: np.ndarray, shape):
    """``(q0, q1, cut0, cut1)``: the segments clipped to the image grown by its larger side on every side
    (Liang-Barsky; segments outside it or not finite dropped), and whether each end was cut.

    An end outside the image but within that margin is rounded where it lies, as a renderer that draws
    the whole line and drops the pixels outside does; only ends farther out are cut (and rounded either
    way: :func:`rounded_ties`), which bounds the work whatever the segment.
    """
    h, w = shape
    g = float(max(h, w))
    segs_px = np.asarray(segs_px, dtype=np.float64).reshape(-1, 2, 2)
    kept, q0, q1 = clip_to_image(segs_px[:, 0] + g, segs_px[:, 1] + g, int(w + 2 * g), int(h + 2 * g))
    a, b = segs_px[kept, 0], segs_px[kept, 1]
    # an end the margin did not cut is kept exactly (the shift by g and back may round its last bit)
    cut0 = np.any(np.abs(q0 - g - a) > 1e-9 * (g + np.abs(a)), axis=1)
    cut1 = np.any(np.abs(q1 - g - b) > 1e-9 * (g + np.abs(b)), axis=1)
    return np.where(cut0[:, None], q0 - g, a), np.where(cut1[:, None], q1 - g, b), cut0, cut1


def rounded_pixels(segs_px: np.ndarray, shape) -> tuple[np.ndarray, np.ndarray]:
    """``rr, cc : (N,) ndarray of int``: the pixels of ``segs_px`` ``(K, 2, 2)`` under the ``"rounded"`` rule.

    Ends outside the image are rounded where they lie (:func:`_clip`); pixels outside the image are
    dropped. Pixels may repeat (segments that meet).

    >>> img = np.zeros((3, 6), int)
    >>> rr, cc = rounded_pixels(np.array([[[0.2, 0.4], [4.6, 1.6]]]), img.shape)
    >>> img[rr, cc] = 1
    >>> img
    array([[1, 1, 0, 0, 0, 0],
           [0, 0, 1, 1, 0, 0],
           [0, 0, 0, 0, 1, 1]])
    """
    q0, q1, _, _ = _clip(segs_px, shape)
    if not len(q0):
        empty = np.zeros(0, np.intp)
        return empty, empty
    x, y, _, _, _ = _step(_round_half_up(q0).astype(np.int64), _round_half_up(q1).astype(np.int64))
    h, w = shape
    inside = (x >= 0) & (x < w) & (y >= 0) & (y < h)
    return y[inside].astype(np.intp), x[inside].astype(np.intp)


#: How far outside the image (px) a renderer that clips its lines first may cut them, each a place an end
#: outside the image may be rounded at (the held-out clients cut 4 px out; GL clips at the image, 0).
CLIP_MARGINS_PX = (0.0, 1.0, 2.0, 4.0, 8.0)


def _end_choices(q: np.ndarray, cuts: list, outside: np.ndarray, end_tie_px: float) -> np.ndarray:
    """``(K, 4 + 4 len(cuts), 2)`` int64: the integer pixels an end may round to (rows repeated where fewer).

    ``q`` the ends as :func:`_clip` keeps them, ``cuts`` where the segments cross the image's border grown
    by each of :data:`CLIP_MARGINS_PX` (the ends themselves when inside that), ``outside`` whether each
    end lies outside the image.
    """

    def corners(lo, hi):
        return np.stack(
            [
                np.stack([lo[:, 0], lo[:, 1]], 1),
                np.stack([hi[:, 0], lo[:, 1]], 1),
                np.stack([lo[:, 0], hi[:, 1]], 1),
                np.stack([hi[:, 0], hi[:, 1]], 1),
            ],
            axis=1,
        )

    base = _round_half_up(q)
    fuzzy = np.abs(q - np.floor(q) - 0.5) <= end_tie_px  # per axis
    near = corners(np.where(fuzzy, np.floor(q), base), np.where(fuzzy, np.floor(q) + 1, base))
    # an end outside the image: the renderer may cut the line anywhere out to it, then round either way
    # across the line; along it, a cut on a border across the line lies on a half pixel, which a renderer's
    # float error rounds down as well as up (the end moves a pixel outside the image, the line's slope with
    # it: an inner pixel may move)
    out = [near]
    for c in cuts:
        d = c - q
        minor = (
            np.where(np.abs(d[:, :1]) >= np.abs(d[:, 1:]), [[False, True]], [[True, False]])
            if len(q)
            else np.zeros((0, 2), bool)
        )
        rounded = _round_half_up(c)
        lo = np.where(minor, np.floor(c), rounded)
        hi = np.where(minor, np.floor(c) + 1, rounded)
        down = np.where(~minor & (np.abs(c - np.floor(c) - 0.5) <= end_tie_px), np.floor(c), rounded)
        out.append(np.where(outside[:, None, None], np.stack([lo, hi, down, rounded], axis=1), near))
    return np.concatenate(out, axis=1).astype(np.int64)


def rounded_ties(segs_px: np.ndarray, shape, end_tie_px: float = END_TIE_PX) -> np.ndarray:
    """``(H, W)`` bool: the pixels a correct ``"rounded"`` drawing of ``segs_px`` may or may not take.

    The ties of the module docstring: both pixels where the rounded line's minor coordinate is exactly a
    half pixel; and every pixel drawn by some rounding of the segment's ends but not by all, where an end
    lies within ``end_tie_px`` of a half pixel on an axis, or outside the image (then any of the pixels
    around where the line crosses the image's border grown by :data:`CLIP_MARGINS_PX`, or the end itself).
    """
    q0, q1, _, _ = _clip(segs_px, shape)
    ties = np.zeros(shape, bool)
    if not len(q0):
        return ties
    h, w = shape
    # segments that reach the image grown by 2 px: a rounding of a segment that passes just outside the
    # image (ends and pixels move at most a pixel, each pixel within half a pixel of its line) may draw inside
    seen, _, _ = clip_to_image(q0 + 2, q1 + 2, w + 4, h + 4)
    out0 = np.any((q0 < -0.5) | (q0 > np.array([w, h]) - 0.5), axis=1) & seen
    out1 = np.any((q1 < -0.5) | (q1 > np.array([w, h]) - 0.5), axis=1) & seen
    cuts0, cuts1 = [], []
    for m in CLIP_MARGINS_PX:
        kept, b0, b1 = clip_to_image(q0 + m, q1 + m, int(w + 2 * m), int(h + 2 * m))
        c0, c1 = q0.copy(), q1.copy()
        c0[kept], c1[kept] = b0 - m, b1 - m
        cuts0.append(c0)
        cuts1.append(c1)
    c0, c1 = _end_choices(q0, cuts0, out0, end_tie_px), _end_choices(q1, cuts1, out1, end_tie_px)
    fuzzy = np.any(c0 != c0[:, :1], axis=(1, 2)) | np.any(c1 != c1[:, :1], axis=(1, 2))
    x, y, tx, ty, _ = _step(_round_half_up(q0).astype(np.int64), _round_half_up(q1).astype(np.int64))
    across = (tx != x) | (ty != y)
    ties |= _paint(shape, x[across], y[across]) | _paint(shape, tx[across], ty[across])
    groups, a, b, sizes = [], [], [], []
    for i in np.flatnonzero(fuzzy & seen):  # each fuzzy segment's roundings, drawn in one batch
        u0, u1 = np.unique(c0[i], axis=0), np.unique(c1[i], axis=0)
        a.append(np.repeat(u0, len(u1), axis=0))
        b.append(np.tile(u1, (len(u0), 1)))
        groups += [len(sizes)] * (len(u0) * len(u1))
        sizes.append(len(u0) * len(u1))
    if sizes:
        px, py, vx, vy, variant = _step(np.concatenate(a), np.concatenate(b))
        # each rounding's own half pixels across the line are ties too (as the main line's above)
        across = (vx != px) | (vy != py)
        ties |= _paint(shape, px[across], py[across]) | _paint(shape, vx[across], vy[across])
        ok = (px >= 0) & (px < w) & (py >= 0) & (py < h)
        # each (segment, pixel) counted once per variant that draws it: a tie when some draw it, not all
        key = np.unique((variant[ok].astype(np.int64) * (h * w)) + py[ok] * w + px[ok])
        pixel, variant_of = key % (h * w), key // (h * w)
        pair, count = np.unique(np.asarray(groups)[variant_of] * (h * w) + pixel, return_counts=True)
        undecided = count < np.asarray(sizes)[pair // (h * w)]
        ties.reshape(-1)[pair[undecided] % (h * w)] = True
    return ties


def expected(
    segs_px: np.ndarray, shape, rule: str = "gl", end_tie_px: float = END_TIE_PX
) -> tuple[np.ndarray, np.ndarray]:
    """``(drawn, ties)``: two ``(H, W)`` bool masks, a correct drawing of ``segs_px`` under ``rule`` and the
    pixels it cannot decide (for ``"gl"``: none here, :mod:`oracles.judge.line_ties` finds GL's against a
    candidate's pixels)."""
    if rule not in RULES:
        raise ValueError(f"rule {rule!r}: expected one of {', '.join(RULES)}")
    drawn = np.zeros(shape, bool)
    if rule == "gl":
        q0, q1, _, _ = _clip(segs_px, shape)
        rr, cc = line_pixels(q0, q1, shape[1], shape[0])
        drawn[rr, cc] = True
        return drawn, np.zeros(shape, bool)
    rr, cc = rounded_pixels(segs_px, shape)
    drawn[rr, cc] = True
    return drawn, rounded_ties(segs_px, shape, end_tie_px)


def band_distances(segs_px: np.ndarray, shape, reach_px: float, lean_px: float = 0.0) -> np.ndarray:
    """``(H, W)`` float: each pixel centre's distance to the nearest segment, where it is within ``reach_px``
    (beyond: inf); each segment moved ``lean_px`` along its left normal ``(dy, -dx) / |d|``. Distances are
    to the segment (an end's cap is round)."""
    h, w = shape
    dist = np.full(shape, np.inf)
    for a, b in np.asarray(segs_px, dtype=np.float64).reshape(-1, 2, 2):
        d = b - a
        length = float(np.hypot(*d))
        normal = np.array([d[1], -d[0]]) / length if length > 0 else np.zeros(2)
        a, b = a + lean_px * normal, b + lean_px * normal
        lo = np.maximum(np.floor(np.minimum(a, b) - reach_px), 0).astype(int)
        hi = np.minimum(np.ceil(np.maximum(a, b) + reach_px), [w - 1, h - 1]).astype(int)
        if np.any(hi < lo):
            continue
        yy, xx = np.mgrid[lo[1] : hi[1] + 1, lo[0] : hi[0] + 1]
        q = np.stack([xx.ravel(), yy.ravel()], axis=1).astype(float)
        t = np.clip(((q - a) @ d) / max(length * length, 1e-300), 0.0, 1.0)
        near = np.hypot(*(q - (a + t[:, None] * d)).T).reshape(yy.shape)
        window = dist[lo[1] : hi[1] + 1, lo[0] : hi[0] + 1]
        np.minimum(window, near, out=window)
    return dist


def band_pixels(segs_px: np.ndarray, shape, width_px: float, lean_px: float = 0.0) -> np.ndarray:
    """``(H, W)`` bool: the pixel centres within ``width_px / 2`` of each segment, moved ``lean_px`` along
    its left normal ``(dy, -dx) / |d|`` (a binary band of width ``w``; 0: symmetric). Distances are to the
    segment (an end's cap is round)."""
    return band_distances(segs_px, shape, width_px / 2.0, lean_px) <= width_px / 2.0


def band_holding(segs_px: np.ndarray, shape, count: int, width_px: float) -> np.ndarray:
    """``(H, W)`` bool: the binary band around the segments that holds ``count`` pixel centres.

    A band of half-width ``h`` centred on the lines is every centre within ``h`` of them. Where the lines
    sit at one fractional position (square-on), bands of widths up to a pixel apart hold the same centres,
    so a width read from pixel counts (2 for a 1.5 px band at some positions) does not say which ``h``
    drew them. Of the bands centred on the lines, the one holding ``count`` centres (``h`` halfway between
    the ``count``-th nearest centre's distance and the next's, searched within ``width_px / 2 + 1`` px) is
    the drawing a renderer centred on them made with that many pixels: its centres are the candidate's
    when the candidate's band is centred, and a band moved off the lines holds other centres. Where fewer
    than ``count`` centres lie within reach, or ``count`` < 1: the band of ``width_px`` rounded.
    """
    half = round(width_px) / 2.0
    reach = max(half, width_px / 2.0) + 1.0
    dist = band_distances(segs_px, shape, reach)
    if count >= 1:
        near = np.sort(dist[dist <= reach])
        if len(near) >= count:
            half = (near[count - 1] + (near[count] if len(near) > count else reach)) / 2.0
    return dist <= half
