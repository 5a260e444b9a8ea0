"""Line rasterization in numpy: segments in pixel space to pixel indices.

Rasterizing is separate from painting: :func:`line_pixels` returns index
arrays ``rr, cc`` and the caller writes ``img[rr, cc] = value``.

Rule (pixel centres at integer coordinates, see core.conventions): a segment is
stepped along its major axis (x when |dx| >= |dy|, ties go to x) at every
integer coordinate from ``round(a0)`` to ``round(a1)`` inclusive, and at each
step the minor coordinate of the segment is evaluated there and rounded
(``floor(v + 0.5)``: halves round toward +x / +y, i.e. right and down). Both end
pixels are drawn. This selects, in the middle of a segment, the same pixels as
OpenGL's diamond-exit rule (the pixel whose diamond the line crosses at each
column centre); at the two ends GL's rule may leave out one pixel (the end
pixel when the end point lies inside its diamond). See README, "Pixel agreement".

>>> import numpy as np
>>> rr, cc = line_pixels(np.array([[0.0, 0.0]]), np.array([[4.0, 2.0]]), 5, 3)
>>> img = np.zeros((3, 5), dtype=int); img[rr, cc] = 1; img
array([[1, 0, 0, 0, 0],
       [0, 1, 1, 0, 0],
       [0, 0, 0, 1, 1]])
"""

from __future__ import annotations

import numpy as np


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
        Row and column of each drawn pixel (duplicates possible where segments
        meet).
    """
    p0_px = np.asarray(p0_px, dtype=np.float64).reshape(-1, 2)
    p1_px = np.asarray(p1_px, dtype=np.float64).reshape(-1, 2)
    if len(p0_px) == 0:
        empty = np.zeros(0, dtype=np.intp)
        return empty, empty
    d = p1_px - p0_px
    x_major = np.abs(d[:, 0]) >= np.abs(d[:, 1])
    # major (a) and minor (b) coordinates of both ends
    a0 = np.where(x_major, p0_px[:, 0], p0_px[:, 1])
    a1 = np.where(x_major, p1_px[:, 0], p1_px[:, 1])
    b0 = np.where(x_major, p0_px[:, 1], p0_px[:, 0])
    b1 = np.where(x_major, p1_px[:, 1], p1_px[:, 0])
    i0 = np.floor(a0 + 0.5).astype(np.intp)
    i1 = np.floor(a1 + 0.5).astype(np.intp)
    step = np.where(i1 >= i0, 1, -1)
    n = np.abs(i1 - i0) + 1                          # samples per segment
    da = a1 - a0
    with np.errstate(divide="ignore", invalid="ignore"):
        slope = np.where(da != 0, (b1 - b0) / da, 0.0)
    seg = np.repeat(np.arange(len(n)), n)
    k = np.arange(int(n.sum())) - np.repeat(np.cumsum(n) - n, n)
    i = i0[seg] + step[seg] * k                      # major coordinate, integer
    b = b0[seg] + (i - a0[seg]) * slope[seg]         # minor coordinate at i
    # The end samples lie up to half a pixel beyond the segment; keep their
    # minor coordinate on the segment rather than extrapolating.
    lo = np.minimum(b0, b1)[seg]
    hi = np.maximum(b0, b1)[seg]
    j = np.floor(np.clip(b, lo, hi) + 0.5).astype(np.intp)
    xm = x_major[seg]
    cc = np.where(xm, i, j)
    rr = np.where(xm, j, i)
    inside = (cc >= 0) & (cc < width) & (rr >= 0) & (rr < height)
    return rr[inside], cc[inside]
