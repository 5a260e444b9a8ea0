"""Line rasterization in numpy: segments in pixel space to pixel indices.

Rasterizing is separate from painting: the ``line_*`` functions return index
arrays ``rr, cc`` (and, for "aa", weights) and the caller writes the image.
Pixel convention (core.conventions): integer coordinates are pixel centres,
x right = columns, y down = rows. Three modes, :data:`RASTER_MODES`:

``"exact"`` (:func:`line_pixels`) is OpenGL's *diamond-exit* rule for 1-pixel
lines, as Mesa's llvmpipe implements it:

1. End points are first snapped to 1/256 px, the sub-pixel precision of
   Mesa's llvmpipe (``FIXED_ORDER = 8``), so that near-ties break as it does.
2. A segment is stepped along its major axis: x when ``|dx| > |dy|``, y
   otherwise (an exact diagonal is y-major, as measured against llvmpipe).
3. At each integer major coordinate ``i`` the segment's minor coordinate ``b``
   is rounded to the pixel whose diamond ``|x - xc| + |y - yc| < 1/2`` the line
   crosses there; exact halves go to +y (down) when y is the minor axis and to
   -x (left) when x is, as GL's fill convention does for llvmpipe.
4. Pixel ``i`` is drawn when the segment *exits* that diamond: the point where
   the line leaves it (in the direction of travel) lies after the start point
   and at or before the end point. So the start pixel is drawn when the start
   point is inside its diamond, and the end pixel is not drawn when the end
   point is inside its own: joined edges do not draw their shared pixel twice.

Against Mesa llvmpipe (via pyrender/OSMesa) this reproduces random segments
pixel for pixel in ~99 % of cases; the rest differ by one pixel at an end or
at a tie (README, "Pixel agreement").

``"fast"`` (:func:`line_pixels_fast`) is integer DDA (Bresenham's line; the
pixels of ``cv2.line(..., LINE_8)`` except at ties, which OpenCV breaks
toward the end with the smaller x). Both ends are rounded to the nearest pixel
centre with ``floor(v + 1/2)`` (halves toward +x / +y: unlike round-half-even
or half-away-from-zero this commutes with whole-pixel shifts). Between the
rounded ends ``(x0, y0)``, ``(x1, y1)`` the major axis is x when
``|x1 - x0| > |y1 - y0|``, else y; the line steps every integer major
coordinate from one end to the other, both ends included
(``max(|dx|, |dy|) + 1`` pixels, 8-connected; a zero-length segment draws its
one pixel), and takes the pixel nearest the exact minor coordinate there,
computed in integers: after ``k`` of ``n`` steps ``b = b0 + k db / n`` and the
pixel is ``b0 + floor((2 k db + n) / (2 n))`` when y is minor (halves to +y)
and ``b0 - floor((n - 2 k db) / (2 n))`` when x is minor (halves to -x): the
tie rule of "exact". The rule depends on the point ``(i, b)`` only, so a
reversed segment draws the same pixels.

``"aa"`` (:func:`line_coverage_aa`, painted with :func:`paint_aa`) is Xiaolin
Wu's anti-aliased line. Major axis as in "exact", ends not snapped or rounded.
For every integer major coordinate ``i`` whose pixel interval
``[i - 1/2, i + 1/2]`` overlaps the segment's major extent ``[a_lo, a_hi]``,
let ``g`` be the overlap length (1 inside, Wu's end gap at the end pixels:
the fraction of the end pixel the segment covers along the major axis) and
``b`` the minor coordinate of the segment's line at ``i``; the two pixels
``floor(b)`` and ``floor(b) + 1`` get weights ``(1 - f) g`` and ``f g`` with
``f = b - floor(b)``. Zero weights are dropped, so a zero-length segment draws
nothing, and a segment's weights add up to its major extent ``a_hi - a_lo``.
:func:`paint_aa` adds coverage over segments, clips it to 1 and scales it to
0..255 with ``floor(255 c + 1/2)``; a pixel counts as *drawn* (for
comparisons with binary images) when its value is >= 128, i.e. its coverage is
>= 1/2. Within a segment's interior the nearer of the two pixels has weight
``max(1 - f, f) >= 1/2`` and the other ``<= 1/2``, so the thresholded line is
the nearest-pixel DDA line of the *unrounded* segment (both pixels at an exact
tie ``f = 1/2``); at the end pixels ``g < 1`` may drop it.

>>> import numpy as np
>>> rr, cc = line_pixels(np.array([[0.0, 0.0]]), np.array([[4.0, 2.0]]), 5, 3)
>>> img = np.zeros((3, 5), dtype=int); img[rr, cc] = 1; img
array([[1, 0, 0, 0, 0],
       [0, 1, 1, 0, 0],
       [0, 0, 0, 1, 0]])
>>> rr, cc = line_pixels_fast(np.array([[0.0, 0.0]]), np.array([[4.0, 2.0]]), 5, 3)
>>> img = np.zeros((3, 5), dtype=int); img[rr, cc] = 1; img
array([[1, 0, 0, 0, 0],
       [0, 1, 1, 0, 0],
       [0, 0, 0, 1, 1]])
>>> rr, cc, w = line_coverage_aa(np.array([[0.0, 0.0]]), np.array([[4.0, 1.0]]), 5, 2)
>>> paint_aa(rr, cc, w, 5, 2)     # end pixels half covered; 191 = 0.75 * 255, 64 = 0.25 * 255
array([[128, 191, 128,  64,   0],
       [  0,  64, 128, 191, 128]], dtype=uint8)
"""

from __future__ import annotations

import numpy as np

#: The rasterization rules (module docstring): OpenGL diamond-exit, integer DDA, Wu anti-aliased.
RASTER_MODES = ("exact", "fast", "aa")

#: Sub-pixel grid (1/256 px): llvmpipe's fixed-point precision for vertex positions.
SUBPIXEL = 256.0


def snap_subpixel(p_px: np.ndarray) -> np.ndarray:
    """Coordinates rounded to the :data:`SUBPIXEL` grid (float64)."""
    return np.round(p_px * SUBPIXEL) / SUBPIXEL


#: Segments rasterized per batch. Keeps the per-segment temporaries (about 30
#: arrays of this length) inside the L2 cache: one batch of 100k+ segments
#: makes tens of MB of temporaries that glibc maps and unmaps on every frame,
#: and the page faults cost as much as the arithmetic. Batching does not change
#: the result (same pixels, same order).
CHUNK_SEGMENTS = 8192

#: "exact" computes its integer grid arithmetic in float64 (exact below 2^53,
#: and faster than int64 division) when every end is within this many grid
#: units (1/256 px) of the origin: 2^23 units = 32,768 px. Then every product
#: and sum in :func:`_line_pixels` stays below 2^51. Farther ends take int64.
_FLOAT_GRID_LIMIT = 2.0**23


def line_pixels(p0_px: np.ndarray, p1_px: np.ndarray, width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
    """Pixels of ``M`` segments from ``p0_px[m]`` to ``p1_px[m]``.

    Parameters
    ----------
    p0_px, p1_px : (M, 2) ndarray of float
        Segment ends ``[x, y]`` in pixel coordinates. They should already be
        clipped to the image (pixels outside ``width x height`` are dropped, but
        a segment millions of pixels long would still be stepped through).
    width, height : int
        Image size.

    Returns
    -------
    rr, cc : (K,) ndarray of intp
        Row and column of each drawn pixel: segment after segment, each
        segment's pixels in increasing major coordinate.
    """
    p0_px, p1_px = _as_ends(p0_px, p1_px)
    if len(p0_px) == 0:
        empty = np.zeros(0, dtype=np.intp)
        return empty, empty
    parts = [
        _line_pixels(
            snap_subpixel(p0_px[k : k + CHUNK_SEGMENTS]), snap_subpixel(p1_px[k : k + CHUNK_SEGMENTS]), width, height
        )
        for k in range(0, len(p0_px), CHUNK_SEGMENTS)
    ]
    if len(parts) == 1:
        return parts[0]
    return np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts])


def major_minor(p0_px: np.ndarray, p1_px: np.ndarray) -> tuple[np.ndarray, ...]:
    """``(x_major, a0, a1, b0, b1)`` of ``M`` segments: x is the major axis when ``|dx| > |dy|``.

    ``x_major`` is ``(M,)`` bool; ``a0, a1`` are the ends' major and ``b0, b1``
    their minor coordinates, ``(M,)`` each.
    """
    d = p1_px - p0_px
    x_major = np.abs(d[:, 0]) > np.abs(d[:, 1])
    a0 = np.where(x_major, p0_px[:, 0], p0_px[:, 1])
    a1 = np.where(x_major, p1_px[:, 0], p1_px[:, 1])
    b0 = np.where(x_major, p0_px[:, 1], p0_px[:, 0])
    b1 = np.where(x_major, p1_px[:, 1], p1_px[:, 0])
    return x_major, a0, a1, b0, b1


def _floor_div_float(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``floor(a / b)`` of exact integers held in float64, ``|a| < 2^53``: exact (see _line_pixels)."""
    return np.floor(a / b)


def _floor_div_int(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a // b


def _line_pixels(p0_px: np.ndarray, p1_px: np.ndarray, width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
    """:func:`line_pixels` of a non-empty batch of already snapped end points.

    All in the segment's *travel* coordinate ``I = s i`` (``s = +1`` when the
    major coordinate grows from start to end, else -1) and in integer grid
    units (1/256 px), so that every rounding is decided exactly:

    * the minor coordinate at major pixel ``i`` is ``b = num / unit`` with
      integers ``unit = 256 |da|`` and ``num`` affine in ``I``; the drawn pixel
      is ``j = t floor(P / Q)`` with ``P = 2 t num + unit``, ``Q = 2 unit``
      (``t = +1`` for x-major: halves to +y; ``t = -1`` for y-major: halves
      to -x). ``floor(P / Q)`` in float64 is exact: a non-integer quotient of
      integers is at least ``1 / Q`` from the next integer, more than the
      rounding error of ``P / Q`` while ``|P| < 2^53``.
    * where the line leaves pixel ``I``'s diamond, ``X(I)``, lies in
      ``[I, I + 1/2]``. Pixel ``I`` is drawn when ``A0 < X(I) <= A1`` (the
      ends, in travel coordinates). Every ``I > floor(A0)`` passes the first
      test (``X >= I > A0``), every ``I < floor(A1)`` the second
      (``X <= I + 1/2 < A1``), and ``X(I)`` grows with ``I``: the drawn
      pixels are ``floor(A0) .. floor(A1)`` less the first when
      ``X(floor(A0)) <= A0`` and less the last when ``X(floor(A1)) > A1``.
      So ``X`` is evaluated twice per segment (:func:`_exit_travel`), with the
      float operations of the rule as stated, and the pixels between are
      generated without a test.
    """
    g0 = p0_px * SUBPIXEL  # grid units: exact integers (the ends are snapped)
    g1 = p1_px * SUBPIXEL
    if min(g0.min(), g1.min()) >= -_FLOAT_GRID_LIMIT and max(g0.max(), g1.max()) <= _FLOAT_GRID_LIMIT:
        floor_div, one = _floor_div_float, 1.0
    else:
        g0, g1 = g0.astype(np.int64), g1.astype(np.int64)
        floor_div, one = _floor_div_int, 1
    d = g1 - g0
    ad = np.abs(d)
    x_major = ad[:, 0] > ad[:, 1]
    da = np.where(x_major, d[:, 0], d[:, 1])  # major and minor change, grid units
    db = np.where(x_major, d[:, 1], d[:, 0])
    ga0 = np.where(x_major, g0[:, 0], g0[:, 1])
    gb0 = np.where(x_major, g0[:, 1], g0[:, 0])
    s = np.where(da >= 0, one, -one)  # direction of travel along the major axis
    den = np.abs(da)
    ta0 = s * ga0  # the ends in travel coordinates, grid units
    ta1 = ta0 + den
    np.maximum(den, one, out=den)  # zero length: db = 0 too, any den > 0 will do
    t = np.where(x_major, one, -one)  # rounding side: +1 halves to +y, -1 halves to -x
    # The diamond's exit (_exit_travel) divides by 1 + t m and 1 - t m, with
    # m = db / den: the rule's float slope times s (the same quotient, rounded once).
    tm = db / den
    tm *= t
    d1 = 1.0 + tm
    d2 = 1.0 - tm
    unit = 256 * den
    q = 2 * unit
    # P(I) = 2 t num(I) + unit, num(I) = gb0 den + (256 I - ta0) db
    t2db = 2 * t * db
    p0 = 2 * t * gb0
    p0 *= den
    p0 += unit
    p0 -= t2db * ta0
    dp = 256 * t2db
    i_start = floor_div(ta0, 256)
    i_end = floor_div(ta1, 256)
    # X(I) <= A0 as u(I) <= A0 - I: the end's offset from the pixel, exact (a whole number of grid
    # units over 256), so the decision does not depend on where the pixel is (I + u would round)
    first = i_start + (_exit_travel(i_start, p0, dp, q, unit, d1, d2, floor_div) <= (ta0 - 256 * i_start) / SUBPIXEL)
    last = i_end - (_exit_travel(i_end, p0, dp, q, unit, d1, d2, floor_div) > (ta1 - 256 * i_end) / SUBPIXEL)
    count = last - first
    count += 1
    count = np.maximum(count, 0).astype(np.intp)
    # the drawn pixels, segment after segment, each in increasing major
    # coordinate i = s I from i_lo: i = (sample index) + (i_lo - the segment's first sample index)
    i_lo = np.where(s > 0, first, -last)
    i_lo -= np.cumsum(count) - count
    seg = np.repeat(np.arange(len(count)), count)
    i = np.arange(len(seg), dtype=p0.dtype)
    i += i_lo[seg]
    dp *= s  # P as a function of i
    j = floor_div(p0[seg] + dp[seg] * i, q[seg])
    j *= t[seg]
    i = i.astype(np.intp)
    j = j.astype(np.intp)
    xm = x_major[seg]
    cc = np.where(xm, i, j)
    rr = np.where(xm, j, i)
    if len(rr) == 0 or (rr.min() >= 0 and cc.min() >= 0 and rr.max() < height and cc.max() < width):
        return rr, cc  # the usual case: skip the mask and two gathers
    inside = (cc >= 0) & (cc < width) & (rr >= 0) & (rr < height)
    return rr[inside], cc[inside]


def _exit_travel(i, p0, dp, q, unit, d1, d2, floor_div) -> np.ndarray:
    """Travel ``u = X - I`` from the centre of pixel ``I`` to where the line leaves its diamond.

    The rule's float operations on the rule's values (module docstring,
    step 4). The offset from the pixel centre is ``e = (num - j unit) / unit``;
    ``E = (P - Q floor(P / Q) - unit) / Q`` is ``t e`` exactly (the same
    integers, divided once). The distance along travel to the boundary is
    ``u = min((1/2 - e) / (1 + m), (1/2 + e) / (1 - m))``, here
    ``min((1/2 - E) / (1 + t m), (1/2 + E) / (1 - t m))``: the same two
    quotients, swapped when ``t = -1``. A zero denominator means that bound is
    absent (``fmin`` drops its inf or NaN). ``u`` is compared with the ends'
    offsets ``A - I`` (exact), not ``X = I + u`` with ``A``: the sum would round
    by the size of ``I``, and an end exactly on a diamond's edge (common on the
    1/256 grid) would be decided differently a whole pixel away.
    """
    p = p0 + dp * i
    e_t = (p - floor_div(p, q) * q - unit) / q
    with np.errstate(divide="ignore", invalid="ignore"):
        u = np.fmin((0.5 - e_t) / d1, (0.5 + e_t) / d2)
    return u


def _as_ends(p0_px, p1_px) -> tuple[np.ndarray, np.ndarray]:
    return (np.asarray(p0_px, dtype=np.float64).reshape(-1, 2), np.asarray(p1_px, dtype=np.float64).reshape(-1, 2))


def _batched(fn, p0: np.ndarray, p1: np.ndarray, width: int, height: int) -> tuple:
    """``fn`` over batches of :data:`CHUNK_SEGMENTS` segments, results concatenated."""
    if len(p0) <= CHUNK_SEGMENTS:
        return fn(p0, p1, width, height)
    parts = [
        fn(p0[k : k + CHUNK_SEGMENTS], p1[k : k + CHUNK_SEGMENTS], width, height)
        for k in range(0, len(p0), CHUNK_SEGMENTS)
    ]
    return tuple(np.concatenate(arrays) for arrays in zip(*parts))


def _keep_inside(rr: np.ndarray, cc: np.ndarray, width: int, height: int, *extra: np.ndarray) -> tuple:
    inside = (cc >= 0) & (cc < width) & (rr >= 0) & (rr < height)
    if inside.all():  # the usual case: skip the gathers
        return (rr, cc) + extra
    return (rr[inside], cc[inside]) + tuple(e[inside] for e in extra)


def line_pixels_fast(p0_px: np.ndarray, p1_px: np.ndarray, width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
    """Pixels of ``M`` segments by integer DDA (raster mode "fast", module docstring).

    Ends are rounded to pixel centres with ``floor(v + 1/2)``; the line between
    them is 8-connected and includes both ends: ``max(|dx|, |dy|) + 1`` pixels
    of the rounded ends, each the nearest to the exact minor coordinate (ties
    to +y when y is minor, to -x when x is minor, as in "exact"). Same
    parameters and return values as :func:`line_pixels`; pixels outside the
    image are dropped.
    """
    p0, p1 = _as_ends(p0_px, p1_px)
    if len(p0) == 0:
        empty = np.zeros(0, dtype=np.intp)
        return empty, empty
    return _batched(
        _line_pixels_fast, round_half_up(p0).astype(np.int64), round_half_up(p1).astype(np.int64), width, height
    )


def round_half_up(v: np.ndarray) -> np.ndarray:
    """``floor(v + 1/2)`` (float64), exactly: ``v + 0.5`` itself can round up (0.49999999999999994 + 0.5 == 1.0)."""
    r = np.floor(v)
    return r + (v - r >= 0.5)  # v - floor(v) is exact


def _line_pixels_fast(q0: np.ndarray, q1: np.ndarray, width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
    """:func:`line_pixels_fast` of a non-empty batch of rounded (int64) end points."""
    d = q1 - q0
    x_major = np.abs(d[:, 0]) > np.abs(d[:, 1])
    n = np.maximum(np.abs(d[:, 0]), np.abs(d[:, 1]))  # steps; n + 1 pixels
    # After k steps: major = a0 + s k, minor = b0 + t q(k) with
    #   q(k) = floor((2 k db' + n) / (2 n)),
    # x-major: db' = dy, t = +1 (floor(b + 1/2): halves to +y);
    # y-major: db' = -dx, t = -1 (ceil(b - 1/2) = b0 - floor((n - 2 k dx) / (2 n)): halves to -x).
    # Written per axis, with no per-pixel select:
    #   x = x0 + kx k + mx q,   y = y0 + ky k + my q.
    sgn = np.sign(d)
    kx = np.where(x_major, sgn[:, 0], 0)
    ky = np.where(x_major, 0, sgn[:, 1])
    mx = np.where(x_major, 0, -1)
    my = np.where(x_major, 1, 0)
    two_db = 2 * np.where(x_major, d[:, 1], -d[:, 0])
    two_n = 2 * np.maximum(n, 1)  # n = 0: k = 0 only, q = 0
    count = n + 1
    k = np.arange(int(count.sum()), dtype=np.int64) - np.repeat(np.cumsum(count) - count, count)
    q = (k * np.repeat(two_db, count) + np.repeat(n, count)) // np.repeat(two_n, count)
    cc = np.repeat(q0[:, 0], count) + np.repeat(kx, count) * k + np.repeat(mx, count) * q
    rr = np.repeat(q0[:, 1], count) + np.repeat(ky, count) * k + np.repeat(my, count) * q
    return _keep_inside(rr.astype(np.intp, copy=False), cc.astype(np.intp, copy=False), width, height)


def line_coverage_aa(
    p0_px: np.ndarray, p1_px: np.ndarray, width: int, height: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Anti-aliased coverage of ``M`` segments, Xiaolin Wu's rule (raster mode "aa").

    At each integer major coordinate ``i`` the segment reaches, the pixels
    ``floor(b)`` and ``floor(b) + 1`` either side of the line's minor
    coordinate ``b`` there get ``(1 - f) g`` and ``f g``, ``f = b - floor(b)``,
    where ``g`` is the length of ``[i - 1/2, i + 1/2]`` the segment covers along
    the major axis (1 except at the two end pixels). See the module docstring.

    Parameters
    ----------
    p0_px, p1_px : (M, 2) ndarray of float
        Segment ends ``[x, y]`` in pixel coordinates, not rounded or snapped.
    width, height : int
        Image size; pixels outside it are dropped.

    Returns
    -------
    rr, cc : (K,) ndarray of intp
        Row and column of each covered pixel; a pixel appears at most once per
        segment but may repeat across segments (:func:`paint_aa` adds them).
    weight : (K,) ndarray of float64
        Coverage in (0, 1].
    """
    p0, p1 = _as_ends(p0_px, p1_px)
    if len(p0) == 0:
        empty = np.zeros(0, dtype=np.intp)
        return empty, empty, np.zeros(0, dtype=np.float64)
    return _batched(_line_coverage_aa, p0, p1, width, height)


def _line_coverage_aa(
    p0: np.ndarray, p1: np.ndarray, width: int, height: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`line_coverage_aa` of a non-empty batch."""
    x_major, a0, a1, b0, b1 = major_minor(p0, p1)
    # Work from the end with the smaller major coordinate, so that a reversed
    # segment runs the same float operations and gets the same weights.
    swap = a1 < a0
    a_lo, a_hi = np.where(swap, a1, a0), np.where(swap, a0, a1)
    b_lo, b_hi = np.where(swap, b1, b0), np.where(swap, b0, b1)
    da = a_hi - a_lo
    with np.errstate(divide="ignore", invalid="ignore"):
        slope = np.where(da > 0, (b_hi - b_lo) / da, 0.0)  # |slope| <= 1
    # pixels lo..hi: those whose interval [i - 1/2, i + 1/2] overlaps [a_lo, a_hi]
    # in more than a point (an end on a pixel boundary does not reach past it)
    lo = round_half_up(a_lo).astype(np.int64)  # floor(a_lo + 1/2)
    hi = -round_half_up(-a_hi).astype(np.int64)  # ceil(a_hi - 1/2)
    count = np.maximum(hi - lo + 1, 0)
    seg = np.repeat(np.arange(len(count)), count)
    i = lo[seg] + (np.arange(int(count.sum()), dtype=np.int64) - np.repeat(np.cumsum(count) - count, count))
    fi = i.astype(np.float64)
    al, ah = a_lo[seg], a_hi[seg]
    g = np.minimum(ah, fi + 0.5) - np.maximum(al, fi - 0.5)  # 1 exactly inside: (i + 1/2) - (i - 1/2)
    b = b_lo[seg] + (fi - al) * slope[seg]  # the line's minor coordinate at i
    jf = np.floor(b)
    f = b - jf  # exact (the fraction bits of b)
    # the pair (floor(b), floor(b) + 1) of each major step, side by side
    major = np.repeat(i, 2)
    minor = np.stack([jf, jf + 1.0], axis=1).ravel().astype(np.int64)
    weight = np.stack([(1.0 - f) * g, f * g], axis=1).ravel()
    xm = np.repeat(x_major[seg], 2)
    cc = np.where(xm, major, minor).astype(np.intp, copy=False)
    rr = np.where(xm, minor, major).astype(np.intp, copy=False)
    keep = weight > 0
    if not keep.all():
        rr, cc, weight = rr[keep], cc[keep], weight[keep]
    return _keep_inside(rr, cc, width, height, weight)


def paint_aa(rr: np.ndarray, cc: np.ndarray, weight: np.ndarray, width: int, height: int) -> np.ndarray:
    """Accumulate coverage into an ``(height, width)`` uint8 image.

    Coverage is summed per pixel (``np.bincount``), clipped to [0, 1] and
    scaled with ``floor(255 c + 1/2)`` (halves up; deterministic). A pixel is
    *drawn*, for comparisons with binary images, when its value is >= 128,
    which is exactly coverage >= 1/2 (``255 c + 1/2 >= 128  <=>  c >= 1/2``).
    """
    rr = np.asarray(rr, dtype=np.intp)
    cc = np.asarray(cc, dtype=np.intp)
    weight = np.asarray(weight, dtype=np.float64)
    flat = rr * width + cc
    image = np.zeros(width * height, dtype=np.uint8)
    if len(flat) * 8 < width * height:
        # Few pixels (a small scene on a big image): sum per distinct pixel and
        # touch only those, instead of five passes over a float image. bincount
        # adds in input order on both paths, so the sums are bit-identical.
        idx, inverse = np.unique(flat, return_inverse=True)
        acc = np.bincount(inverse, weights=weight, minlength=len(idx))
        image[idx] = np.floor(np.clip(acc, 0.0, 1.0) * 255.0 + 0.5).astype(np.uint8)
        return image.reshape(height, width)
    acc = np.bincount(flat, weights=weight, minlength=width * height)
    return np.floor(np.clip(acc, 0.0, 1.0) * 255.0 + 0.5).astype(np.uint8).reshape(height, width)
