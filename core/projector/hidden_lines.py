"""Hidden lines: the depth of each line pixel tested against a face depth buffer (core.projector.zbuffer).

A drawn line pixel at major coordinate ``i`` gets the depth of the segment at
``i``: ``t = (i - a0) / (a1 - a0)`` along the major axis (clamped to [0, 1]) and
``1/z = lerp(1/z0, 1/z1, t)`` (perspective), ``z = lerp(z0, z1, t)``
(orthographic). It is drawn when::

    z_line <= z_buffer + bias,
    bias = k max(|dz/dx|, |dz/dy|) + 2^-24 dz/dz_w,     k = 1 for raster "exact"

with k = 1, the first-order image in linear depth of ``glPolygonOffset(1, 1)`` on a 24-bit
window depth buffer, which is what the pyrender oracle applies to its faces
(``z_w`` is window depth; ``dz/dz_w = (far - near) z^2 / (far near)`` for
perspective, ``far - near`` for orthographic). The slope term is what keeps a
line on a face's boundary from being hidden by its own face: the pixel
centre is up to 1/2 px (minor axis) from the line point whose depth the line
gets, so the face's depth there differs from the line's by up to
``|dz/dminor| / 2``, half the slope term. ``dz/dx`` is the face's depth slope
at that pixel (``z^2 |d(1/z)/dx|`` under perspective). Raster modes "fast"
and "aa" put pixels up to ~1.5 px from that line point, so they use k = 2
(:data:`SLOPE_FACTOR`). tests/test_hidden_lines.py checks the result against
pyrender (faces black with glPolygonOffset(1, 1), lines on top).
"""

from __future__ import annotations

import numpy as np

from ..camera import Camera
from . import raster
from .raster import round_half_up, snap_subpixel

#: Resolution of a 24-bit window depth buffer (GL's ``r`` in glPolygonOffset).
DEPTH_UNIT = 2.0**-24
#: Slope factor of the line-vs-face bias per raster mode (module docstring):
#: "exact" pixels are within 1/2 px of their line (minor axis), as GL's, so
#: glPolygonOffset's factor 1 covers them; "fast" (ends rounded to pixels) and
#: "aa" (pixel pairs floor(b), floor(b) + 1; end pixels up to 1/2 px past the
#: end) put pixels up to ~1.5 px (L1) from the line point whose depth they get,
#: hence 2.
SLOPE_FACTOR = {"exact": 1.0, "fast": 2.0, "aa": 2.0}


def line_samples(
    p0_px: np.ndarray, p1_px: np.ndarray, width: int, height: int, mode: str = "exact"
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray | None]:
    """core.projector.raster's pixels of ``M`` segments, with the segment of each pixel.

    Returns ``(seg, rr, cc, weight)``: ``weight`` is None except for mode "aa".
    The pixels are exactly those of ``raster.line_pixels`` ("exact"),
    ``raster.line_pixels_fast`` ("fast") and, up to ~1e-9 in the weights,
    ``raster.line_coverage_aa`` ("aa").

    core.projector.raster does not say which segment a pixel came from, so each segment
    is moved along its *minor* axis into its own band of a tall (or wide)
    virtual image, by a whole number of pixels: segment m of the x-major ones
    by ``m (H + 2) + 1`` rows, of the y-major ones by ``m (W + 2) + 1`` columns.
    The rasterizer's major-axis arithmetic is untouched and its minor-axis
    arithmetic is exact in integers ("exact" snaps ends to 1/256 px first and
    works in integer grid units, "fast" rounds ends to pixels first; the
    shifted ends are pre-snapped/rounded here so the shift is exact), so the
    pixels are those of the unshifted segment, shifted. The band of a pixel
    gives its segment back; pixels in the margins (one row/column either side)
    are off the real image and are dropped.
    """
    p0 = np.asarray(p0_px, dtype=np.float64).reshape(-1, 2)
    p1 = np.asarray(p1_px, dtype=np.float64).reshape(-1, 2)
    if mode == "exact":
        p0, p1 = snap_subpixel(p0), snap_subpixel(p1)
        fn = raster.line_pixels
    elif mode == "fast":
        p0, p1 = round_half_up(p0), round_half_up(p1)
        fn = raster.line_pixels_fast
    elif mode == "aa":
        fn = raster.line_coverage_aa
    else:
        raise ValueError(f"raster mode {mode!r}: expected one of {raster.RASTER_MODES}")
    d = p1 - p0
    x_major = np.abs(d[:, 0]) > np.abs(d[:, 1])
    out = []
    for major_is_x, minor_axis, size, other in ((True, 1, height, width), (False, 0, width, height)):
        idx = np.flatnonzero(x_major == major_is_x)
        if len(idx) == 0:
            continue
        band = size + 2
        off = np.arange(len(idx), dtype=np.float64) * band + 1.0
        q0, q1 = p0[idx].copy(), p1[idx].copy()
        q0[:, minor_axis] += off
        q1[:, minor_axis] += off
        if minor_axis == 1:
            res = fn(q0, q1, other, len(idx) * band)
            minor = res[0]
        else:
            res = fn(q0, q1, len(idx) * band, other)
            minor = res[1]
        m = minor // band
        local = minor - m * band - 1
        keep = (local >= 0) & (local < size)
        seg = idx[m[keep]]
        if minor_axis == 1:
            rr, cc = local[keep], res[1][keep]
        else:
            rr, cc = res[0][keep], local[keep]
        weight = res[2][keep] if mode == "aa" else None
        out.append((seg, rr, cc, weight))
    if not out:
        e = np.zeros(0, dtype=np.intp)
        return e, e, e, (np.zeros(0) if mode == "aa" else None)
    seg = np.concatenate([o[0] for o in out])
    rr = np.concatenate([o[1] for o in out]).astype(np.intp, copy=False)
    cc = np.concatenate([o[2] for o in out]).astype(np.intp, copy=False)
    weight = np.concatenate([o[3] for o in out]) if mode == "aa" else None
    return seg, rr, cc, weight


def line_sample_depth(
    seg: np.ndarray,
    rr: np.ndarray,
    cc: np.ndarray,
    a_px: np.ndarray,
    b_px: np.ndarray,
    z_a: np.ndarray,
    z_b: np.ndarray,
    projection: str,
) -> np.ndarray:
    """Depth of each line pixel on its segment ``a -> b`` (module docstring).

    ``t`` is the pixel centre's coordinate along the segment's major axis (x
    when ``|dx| > |dy|``), relative to ``a`` and ``b``, clamped to [0, 1];
    then ``1/z = (1 - t)/z_a + t/z_b`` (perspective) or ``z = (1 - t) z_a + t z_b``.
    ``a_px, b_px, z_a, z_b`` are per segment (indexed by ``seg``).
    """
    a = np.asarray(a_px, dtype=np.float64)[seg]
    b = np.asarray(b_px, dtype=np.float64)[seg]
    d = b - a
    x_major = np.abs(d[:, 0]) > np.abs(d[:, 1])
    num = np.where(x_major, cc - a[:, 0], rr - a[:, 1])
    den = np.where(x_major, d[:, 0], d[:, 1])
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(den != 0, num / den, 0.0)
    t = np.clip(t, 0.0, 1.0)
    za = np.asarray(z_a, dtype=np.float64)[seg]
    zb = np.asarray(z_b, dtype=np.float64)[seg]
    if projection == "perspective":
        return 1.0 / ((1.0 - t) / za + t / zb)
    return (1.0 - t) * za + t * zb


def occlusion_bias(z_buf: np.ndarray, grad: np.ndarray, camera: Camera, factor: float = 1.0) -> np.ndarray:
    """``bias`` of the line depth test at pixels of depth ``z_buf`` (module docstring).

    ``grad`` ``(K, 2)`` is the covering triangle's :func:`triangle_gradients`.
    ``factor * max(|dz/dx|, |dz/dy|) + 2^-24 dz/dz_w``: with factor 1,
    glPolygonOffset(1, 1) on a 24-bit depth buffer, to first order, in linear depth.
    """
    g = factor * np.abs(grad).max(axis=1)
    near, far = float(camera.near), float(camera.far)
    if camera.projection == "perspective":
        z2 = z_buf * z_buf
        return g * z2 + DEPTH_UNIT * (far - near) * z2 / (far * near)
    return g + DEPTH_UNIT * (far - near)


def visible_line_samples(
    seg,
    rr,
    cc,
    a_px,
    b_px,
    z_a,
    z_b,
    depth: np.ndarray,
    face: np.ndarray,
    grad: np.ndarray,
    camera: Camera,
    slope_factor: float = 1.0,
) -> np.ndarray:
    """``(K,) bool``: line pixels not hidden by the depth buffer (``z_line <= z_buf + bias``).

    ``slope_factor`` multiplies the slope term of the bias (:data:`SLOPE_FACTOR`).
    """
    z_line = line_sample_depth(seg, rr, cc, a_px, b_px, z_a, z_b, camera.projection)
    z_buf = depth[rr, cc]
    f = face[rr, cc]
    covered = f >= 0
    visible = np.ones(len(seg), dtype=bool)
    if covered.any():
        zb = z_buf[covered]
        bias = occlusion_bias(zb, grad[f[covered]], camera, slope_factor)
        visible[covered] = z_line[covered] <= zb + bias
    return visible
