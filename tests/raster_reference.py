"""The "exact" raster as main computed it before the two-test rewrite: every candidate pixel tested.

``candidates_reference(p0, p1, w, h)`` has the signature of
``core.projector.raster._line_pixels`` (ends already snapped to 1/256 px) and follows the
rule of core/projector/raster.py's docstring literally: for every integer major
coordinate ``i`` between ``floor`` and ``ceil`` of the ends, the pixel nearest
the line (integer arithmetic, ties as stated), then the diamond-exit test at
that pixel. core's :func:`~wirecheck.core.projector.raster._line_pixels` must return the
same arrays (same pixels, same order) on every input: it only skips the tests
whose outcome the rule fixes and does the arithmetic in another order.
"""

import numpy as np
from wirecheck.core.projector.raster import SUBPIXEL, major_minor


def candidates_reference(p0_px, p1_px, width, height):
    x_major, a0, a1, b0, b1 = major_minor(p0_px, p1_px)
    travel = np.where(a1 >= a0, 1.0, -1.0)  # direction along the major axis
    lo = np.floor(np.minimum(a0, a1)).astype(np.intp)  # candidate major coordinates lo..hi
    hi = np.ceil(np.maximum(a0, a1)).astype(np.intp)
    n = hi - lo + 1
    da = a1 - a0
    with np.errstate(divide="ignore", invalid="ignore"):
        slope = np.where(da != 0, (b1 - b0) / da, 0.0)
    seg = np.repeat(np.arange(len(n)), n)
    i = lo[seg] + (np.arange(int(n.sum())) - np.repeat(np.cumsum(n) - n, n))
    # minor coordinate at i, exactly: b(i) = num / unit in grid units
    ia0, ia1 = (np.round(v * SUBPIXEL).astype(np.int64) for v in (a0, a1))
    ib0, ib1 = (np.round(v * SUBPIXEL).astype(np.int64) for v in (b0, b1))
    den = ia1 - ia0
    sign = np.where(den < 0, -1, 1)
    den_s = np.where(den == 0, 1, den * sign)[seg]  # > 0
    num = sign[seg] * (ib0[seg] * den[seg] + (i * int(SUBPIXEL) - ia0[seg]) * (ib1 - ib0)[seg])
    num = np.where(den[seg] == 0, ib0[seg], num)  # zero length: b = b0
    unit = int(SUBPIXEL) * den_s  # b = num / unit pixels
    xm = x_major[seg]
    j = np.where(
        xm,
        (2 * num + unit) // (2 * unit),  # floor(b + 1/2): halves to +y
        -((unit - 2 * num) // (2 * unit)),
    )  # ceil(b - 1/2):  halves to -x
    e = (num - j * unit) / unit  # offset from the pixel centre, [-1/2, 1/2]
    s = travel[seg]
    m = slope[seg] * s  # minor change per unit of travel, |m| <= 1
    # distance u >= 0 along travel to where the line leaves the diamond:
    # |u| + |e + m u| <= 1/2  <=>  u (1 + m) <= 1/2 - e  and  u (1 - m) <= 1/2 + e
    with np.errstate(divide="ignore", invalid="ignore"):
        u_a = np.where(1 + m > 0, (0.5 - e) / (1 + m), np.inf)
        u_b = np.where(1 - m > 0, (0.5 + e) / (1 - m), np.inf)
    # the exit point i + s u against the ends, as u against the ends' offsets from i (exact: the
    # sum would round by the size of i, and an end on a diamond's edge would depend on where it is)
    u = np.minimum(u_a, u_b)
    drawn = (u > s * (a0[seg] - i)) & (u <= s * (a1[seg] - i))
    i, j, xm = i[drawn], j[drawn].astype(np.intp), xm[drawn]
    cc = np.where(xm, i, j)
    rr = np.where(xm, j, i)
    inside = (cc >= 0) & (cc < width) & (rr >= 0) & (rr < height)
    return rr[inside], cc[inside]
