"""Line rasterization in numpy: segments in pixel space to pixel indices.

Rasterizing is separate from painting: :func:`line_pixels` returns index
arrays ``rr, cc`` and the caller writes ``img[rr, cc] = value``.

The rule is OpenGL's *diamond-exit* rule for 1-pixel lines, written in our
pixel convention (integer coordinates are pixel centres, core.conventions):

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

>>> import numpy as np
>>> rr, cc = line_pixels(np.array([[0.0, 0.0]]), np.array([[4.0, 2.0]]), 5, 3)
>>> img = np.zeros((3, 5), dtype=int); img[rr, cc] = 1; img
array([[1, 0, 0, 0, 0],
       [0, 1, 1, 0, 0],
       [0, 0, 0, 1, 0]])
"""

from __future__ import annotations

import numpy as np

#: Sub-pixel grid (1/256 px): llvmpipe's fixed-point precision for vertex positions.
SUBPIXEL = 256.0

#: Segments rasterized per batch. Keeps the per-sample temporaries small (a few
#: hundred kB): one batch of 100k+ segments makes tens of MB of temporaries that
#: glibc maps and unmaps on every frame, and the page faults cost as much as
#: the arithmetic. Batching does not change the result (same pixels, same order).
CHUNK_SEGMENTS = 4096


def line_pixels(p0_px: np.ndarray, p1_px: np.ndarray, width: int, height: int
                ) -> tuple[np.ndarray, np.ndarray]:
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
        Row and column of each drawn pixel.
    """
    p0_px = np.round(np.asarray(p0_px, dtype=np.float64).reshape(-1, 2) * SUBPIXEL) / SUBPIXEL
    p1_px = np.round(np.asarray(p1_px, dtype=np.float64).reshape(-1, 2) * SUBPIXEL) / SUBPIXEL
    if len(p0_px) == 0:
        empty = np.zeros(0, dtype=np.intp)
        return empty, empty
    if len(p0_px) <= CHUNK_SEGMENTS:
        return _line_pixels(p0_px, p1_px, width, height)
    parts = [_line_pixels(p0_px[k:k + CHUNK_SEGMENTS], p1_px[k:k + CHUNK_SEGMENTS], width, height)
             for k in range(0, len(p0_px), CHUNK_SEGMENTS)]
    return np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts])


def _line_pixels(p0_px: np.ndarray, p1_px: np.ndarray, width: int, height: int
                 ) -> tuple[np.ndarray, np.ndarray]:
    """:func:`line_pixels` of a non-empty batch of already snapped end points."""
    d = p1_px - p0_px
    x_major = np.abs(d[:, 0]) > np.abs(d[:, 1])
    # major (a) and minor (b) coordinates of both ends
    a0 = np.where(x_major, p0_px[:, 0], p0_px[:, 1])
    a1 = np.where(x_major, p1_px[:, 0], p1_px[:, 1])
    b0 = np.where(x_major, p0_px[:, 1], p0_px[:, 0])
    b1 = np.where(x_major, p1_px[:, 1], p1_px[:, 0])
    travel = np.where(a1 >= a0, 1.0, -1.0)            # direction along the major axis
    lo = np.floor(np.minimum(a0, a1)).astype(np.intp)  # candidate major coordinates lo..hi
    hi = np.ceil(np.maximum(a0, a1)).astype(np.intp)
    n = hi - lo + 1
    da = a1 - a0
    with np.errstate(divide="ignore", invalid="ignore"):
        slope = np.where(da != 0, (b1 - b0) / da, 0.0)
    seg = np.repeat(np.arange(len(n)), n)
    i = lo[seg] + (np.arange(int(n.sum())) - np.repeat(np.cumsum(n) - n, n))
    # Minor coordinate at i, exactly: the ends are on the 1/256 grid, so in
    # grid units b(i) = num / den with integers (|values| < 2^53 for any image
    # that fits in memory), and rounding at exact halves cannot depend on the
    # direction of travel through float error.
    ia0, ia1 = (np.round(v * SUBPIXEL).astype(np.int64) for v in (a0, a1))
    ib0, ib1 = (np.round(v * SUBPIXEL).astype(np.int64) for v in (b0, b1))
    den = ia1 - ia0
    sign = np.where(den < 0, -1, 1)
    den_s = np.where(den == 0, 1, den * sign)[seg]                # > 0
    num = sign[seg] * (ib0[seg] * den[seg] + (i * int(SUBPIXEL) - ia0[seg]) * (ib1 - ib0)[seg])
    num = np.where(den[seg] == 0, ib0[seg], num)                 # zero length: b = b0
    unit = int(SUBPIXEL) * den_s                                 # b = num / unit pixels
    xm = x_major[seg]
    j = np.where(xm, (2 * num + unit) // (2 * unit),             # floor(b + 1/2): halves to +y
                 -((unit - 2 * num) // (2 * unit)))              # ceil(b - 1/2):  halves to -x
    e = (num - j * unit) / unit                                  # offset from the pixel centre, [-1/2, 1/2]
    s = travel[seg]
    m = slope[seg] * s                                 # minor change per unit of travel, |m| <= 1
    # Distance u >= 0 along travel to where the line leaves the diamond:
    # |u| + |e + m u| <= 1/2  <=>  u (1 + m) <= 1/2 - e  and  u (1 - m) <= 1/2 + e.
    with np.errstate(divide="ignore", invalid="ignore"):
        u_a = np.where(1 + m > 0, (0.5 - e) / (1 + m), np.inf)
        u_b = np.where(1 - m > 0, (0.5 + e) / (1 - m), np.inf)
    exit_at = i + s * np.minimum(u_a, u_b)
    drawn = (s * (exit_at - a0[seg]) > 0) & (s * (a1[seg] - exit_at) >= 0)
    i, j, xm = i[drawn], j[drawn].astype(np.intp), xm[drawn]
    cc = np.where(xm, i, j)
    rr = np.where(xm, j, i)
    inside = (cc >= 0) & (cc < width) & (rr >= 0) & (rr < height)
    if inside.all():                                   # the usual case: skip two gathers
        return rr, cc
    return rr[inside], cc[inside]
