"""Model and world space to camera space to pixel space, in float64 or float32.

Precision (the ``dtype`` of a run, float64 by default)
======================================================
Every transform is **camera-relative**: the camera position is subtracted in
float64 *before* any rotation and before any cast to float32. For a model
matrix ``M = [A | t]`` and a camera with rotation ``R`` (rows right, up,
forward) at ``position``::

    p_cam = R (A p_model + t - position)
          = (R A) p_model + R (t - position)        # the model-view matrix

The 3x3 ``R A`` and the translation ``R (t - position)`` are computed in float64
from 3-vectors (cheap, exact up to a few eps), then cast to the run's dtype,
and only then applied to the N points. So a unit object 1e8 from the origin,
seen from 4 units away, is transformed with a translation of about 4, not
1e8 - 1e8: float32 keeps ~1e-7 relative precision of *4*, i.e. sub-pixel.

Vertices that are themselves far from their model origin (a scan in
georeferenced coordinates, say) are re-centred once per scene by
:func:`localize`: ``p_local = p_model - origin`` in float64, then cast; the
origin is folded into the model-view translation. ``origin`` is zero when the
vertices already surround their model origin, so ordinary scenes are not
perturbed by a subtraction.

In float32 every per-point operation (rotation, depth test, divide) runs in
float32; near and far are rounded to float32 for the depth test.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..camera import Camera
from ..errors import InputError
from .distortion import distort

DTYPES = ("float64", "float32")


def resolve_dtype(dtype) -> np.dtype:
    """``"float64"``/``"float32"`` (or the numpy types) to a numpy dtype; InputError otherwise."""
    try:
        dt = np.dtype(dtype)
    except TypeError:
        dt = None
    if dt is None or dt.name not in DTYPES:
        raise InputError(f"dtype {dtype!r}: expected one of {', '.join(DTYPES)}")
    return dt


@dataclass(frozen=True)
class LocalPoints:
    """A scene's vertices prepared for one dtype: ``p_model = origin + p_local``."""

    origin: np.ndarray  # (3,) float64
    p_local: np.ndarray  # (N, 3) in the run's dtype

    @property
    def dtype(self) -> np.dtype:
        return self.p_local.dtype

    def __len__(self) -> int:
        return len(self.p_local)


def localize(p_model: np.ndarray, dtype="float64") -> LocalPoints:
    """Re-centre vertices that lie far from their model origin, then cast (once per scene)."""
    dt = resolve_dtype(dtype)
    p_model = np.asarray(p_model, dtype=np.float64).reshape(-1, 3)
    origin = np.zeros(3)
    finite = np.isfinite(p_model).all(axis=1)
    if finite.any():
        lo, hi = p_model[finite].min(axis=0), p_model[finite].max(axis=0)
        centre = 0.5 * lo + 0.5 * hi  # halves first: no overflow near 1e308
        half_extent = 0.5 * hi - 0.5 * lo
        # Far from its own origin: farther (on some axis) than the object's largest half-extent.
        if np.abs(centre).max() > half_extent.max():
            origin = centre
    p_local = p_model - origin if origin.any() else p_model
    return LocalPoints(origin=origin, p_local=np.ascontiguousarray(p_local, dtype=dt))


def model_view(model_matrix: np.ndarray, camera: Camera, origin=None) -> tuple[np.ndarray, np.ndarray]:
    """``(R_mv, t_mv)`` in float64: ``p_cam = R_mv @ p_local + t_mv``, camera-relative.

    ``origin`` (default 0) is :attr:`LocalPoints.origin`.
    """
    r_cam = np.stack([camera.right, camera.up, camera.forward])
    a = model_matrix[:3, :3]
    t_world = model_matrix[:3, 3] if origin is None else a @ origin + model_matrix[:3, 3]
    return r_cam @ a, r_cam @ (t_world - camera.position)  # subtract first, then rotate


#: Rows per block of :func:`model_to_cam`: 64k rows x 3 x 8 bytes = 1.5 MB, inside L2/L3.
BLOCK_ROWS = 65536


def model_to_cam(points: LocalPoints, model_matrix: np.ndarray, camera: Camera) -> np.ndarray:
    """``(N, 3)`` camera-space points, in ``points.dtype``.

    ``p_cam[:, i] = ((x R_i0 + y R_i1) + z R_i2) + t_i``, evaluated elementwise in
    blocks, not with ``@``: a matrix product goes to the BLAS library, whose
    threads stall on a loaded machine and whose summation order depends on the
    CPU's kernel. Elementwise numpy has one order everywhere: same inputs, same
    bytes.
    """
    r_mv, t_mv = model_view(model_matrix, camera, points.origin)
    dt = points.dtype
    r = r_mv.astype(dt)
    t = t_mv.astype(dt)
    p = points.p_local
    out = np.empty((len(p), 3), dtype=dt)
    for start in range(0, len(p), BLOCK_ROWS):
        blk = p[start : start + BLOCK_ROWS]
        o = out[start : start + BLOCK_ROWS]
        x, y, z = blk[:, 0], blk[:, 1], blk[:, 2]
        for i in range(3):
            oi = o[:, i]
            np.multiply(x, r[i, 0], out=oi)
            oi += y * r[i, 1]
            oi += z * r[i, 2]
            oi += t[i]
    return out


def world_to_cam(p_world: np.ndarray, camera: Camera, dtype="float64") -> np.ndarray:
    """``(N, 3)`` world points to camera space (x right, y up, z forward = depth).

    The same camera-relative path as a frame: world points are the model points
    of an identity model matrix, re-centred by :func:`localize` when far from
    the origin; ``origin - position`` is rotated in float64 and cast once.
    """
    return model_to_cam(localize(p_world, dtype), _IDENTITY, camera)


_IDENTITY = np.eye(4)
_IDENTITY.setflags(write=False)


def depth_mask(p_cam: np.ndarray, camera: Camera) -> np.ndarray:
    """``(N,) bool``: True where ``near <= z_cam <= far`` (NaN depth is outside).

    Compared in ``p_cam``'s dtype: in float32, near and far are rounded to float32.
    """
    z = p_cam[:, 2]
    near, far = z.dtype.type(camera.near), z.dtype.type(camera.far)
    return (z >= near) & (z <= far)


def cam_to_px(p_cam: np.ndarray, camera: Camera) -> np.ndarray:
    """``(N, 3)`` camera points to ``(N, 2)`` pixels, in ``p_cam``'s dtype. No masking.

    Precondition for perspective: every ``z_cam`` is positive (callers clip at
    the near plane first). A point at z = 0 gives inf, z < 0 a mirrored point.
    A result beyond the dtype's range is inf, silently: callers check
    (``renderer`` reports it as an input error).
    """
    f_t = p_cam.dtype.type if p_cam.dtype.kind == "f" else np.float64
    cx, cy = (f_t(c) for c in camera.principal_point)
    out = np.empty((len(p_cam), 2), dtype=np.result_type(p_cam.dtype, np.float32))
    x_px, y_px = out[:, 0], out[:, 1]
    # In place, in the order of  x_px = cx + (f x) / z  and  y_px = cy - (f y) / z
    # (with 1/z computed once): the same bits as the plain expressions, fewer temporaries.
    with np.errstate(over="ignore", invalid="ignore"):
        if camera.projection == "perspective" and camera.distortion is not None:
            return _distorted_px(p_cam, camera, f_t, out)
        if camera.projection == "perspective":
            fx, fy = (f_t(f) for f in camera.focal_xy)
            inv_z = f_t(1.0) / p_cam[:, 2]
            np.multiply(p_cam[:, 0], fx, out=x_px)
            x_px *= inv_z
            x_px += cx
            np.multiply(p_cam[:, 1], fy, out=y_px)
            y_px *= inv_z
            np.subtract(cy, y_px, out=y_px)
        else:
            s = f_t(camera.height / camera.ortho_height)
            np.multiply(p_cam[:, 0], s, out=x_px)
            x_px += cx
            np.multiply(p_cam[:, 1], s, out=y_px)
            np.subtract(cy, y_px, out=y_px)
    return out


def _distorted_px(p_cam: np.ndarray, camera: Camera, f_t, out: np.ndarray) -> np.ndarray:
    """Perspective with lens distortion (core.projector.distortion): ideal normalised, distorted, then pixels."""
    inv_z = f_t(1.0) / p_cam[:, 2]
    p_n = np.empty(out.shape, dtype=out.dtype)
    np.multiply(p_cam[:, 0], inv_z, out=p_n[:, 0])
    np.multiply(p_cam[:, 1], -inv_z, out=p_n[:, 1])  # OpenCV's y is down
    p_d = distort(p_n, camera.distortion)
    fx, fy = (f_t(f) for f in camera.focal_xy)
    cx, cy = (f_t(c) for c in camera.principal_point)
    out[:, 0] = cx + fx * p_d[:, 0]
    out[:, 1] = cy + fy * p_d[:, 1]
    return out


def project_points(p_world: np.ndarray, camera: Camera, dtype="float64") -> np.ndarray:
    """World points to pixels, NaN rows for points outside [near, far].

    This is the candidate contract of ``crosscheck``.

    Parameters
    ----------
    p_world : (N, 3) array_like of float
        World coordinates.
    camera : Camera
    dtype : {"float64", "float32"}
        Precision of the computation (camera-relative in both).

    Returns
    -------
    p_px : (N, 2) ndarray of float64
        Pixel coordinates (x right, y down, integers at pixel centres), NaN
        where the point's depth is outside [near, far].

    Examples
    --------
    >>> from wirecheck.core.camera import camera_z
    >>> project_points([[0, 0, 0]], camera_z(4.0, width=640, height=480)).tolist()
    [[319.5, 239.5]]
    """
    p_cam = world_to_cam(p_world, camera, dtype)
    visible = depth_mask(p_cam, camera)
    p_px = np.full((len(p_cam), 2), np.nan)
    if visible.any():
        p_px[visible] = cam_to_px(p_cam[visible], camera)
    return p_px


def unproject(p_px: np.ndarray, depth: np.ndarray, camera: Camera) -> np.ndarray:
    """Pixels and camera depths ``z_cam`` back to world points (float64); inverse of projection.

    Perspective: ``x_cam = (x_px - cx) z / fx``, ``y_cam = -(y_px - cy) z / fy``;
    orthographic: ``x_cam = (x_px - cx) / s``, ``y_cam = -(y_px - cy) / s``.
    Then ``p_world = position + R^T p_cam``. A distorted camera raises
    ValueError (undistortion is iterative and not modelled here).
    """
    if camera.distortion is not None:
        raise ValueError("unproject: a camera with lens distortion is not supported (no undistortion model)")
    p_px = np.asarray(p_px, dtype=np.float64).reshape(-1, 2)
    z = np.asarray(depth, dtype=np.float64).reshape(-1)
    cx, cy = camera.principal_point
    if camera.projection == "perspective":
        fx, fy = camera.focal_xy
        kx, ky = z / fx, z / fy
    else:
        kx = ky = np.full_like(z, camera.ortho_height / camera.height)
    p_cam = np.stack([(p_px[:, 0] - cx) * kx, -(p_px[:, 1] - cy) * ky, z], axis=1)
    r_cam = np.stack([camera.right, camera.up, camera.forward])
    return p_cam @ r_cam + camera.position
