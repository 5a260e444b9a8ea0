"""The extended-precision reference: core.conventions, in long double.

Built straight from ``core.conventions`` -- its own camera basis, focal length,
model-view and divide, none of core's functions -- in ``np.longdouble``
(80-bit x87 on x86-64: 64-bit mantissa, eps 1.1e-19).
"""

from __future__ import annotations

import numpy as np

LD = np.longdouble
PI_LD = 4 * np.arctan(LD(1))  # atanl: pi to 64 bits (np.pi is only 53)
#: eps of the reference's long double: 1.1e-19 for x87 80-bit (x86-64 Linux), 1.9e-34 for
#: IEEE quad (aarch64 Linux), 2.2e-16 where long double is just double (MSVC, macOS arm64):
#: there the reference is no better than core's float64 and the float64 bounds are not meaningful.
REFERENCE_EPS = float(np.finfo(LD).eps)
REFERENCE_EXTENDED = REFERENCE_EPS < 1e-18


def norm_ld(v):
    """``(...,)`` Euclidean norm over the last axis, in the input's (long double) precision."""
    return np.sqrt((v * v).sum(axis=-1))


def _cross_ld(a, b):
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]], dtype=LD)


def reference_basis(camera) -> np.ndarray:
    """``(3, 3)`` rows ``right, up, forward`` in long double from the camera's forward and up.

    conventions: ``right = forward x up`` (normalised), ``up = right x forward``.
    """
    f = np.asarray(camera.forward, dtype=LD)
    f = f / norm_ld(f)
    r = _cross_ld(f, np.asarray(camera.up, dtype=LD))
    r = r / norm_ld(r)
    u = _cross_ld(r, f)
    return np.stack([r, u / norm_ld(u), f])


def reference_focal(camera) -> LD:
    """``f_px = (H / 2) / tan(fov_y / 2)`` in long double (fov in degrees as given)."""
    return (LD(camera.height) / 2) / np.tan(LD(camera.fov_y_deg) * PI_LD / 360)


def reference_world(p_model, a_ld, t_ld) -> np.ndarray:
    """``(N, 3)`` ``A p + t`` in long double (only to hand OpenCV world points)."""
    return np.asarray(p_model, dtype=LD).reshape(-1, 3) @ np.asarray(a_ld, LD).T + np.asarray(t_ld, LD)


def reference_project(p_model, camera, model_matrix=None, *, a_ld=None, t_ld=None):
    """Long-double reference: ``(p_cam (N, 3), p_px (N, 2), visible (N,) bool)``, p_px NaN where clipped.

    ``p_cam = R (A p + (t - position))``: the same sum as ``R (A p + t - position)``
    with ``t - position`` taken first, which for float64 inputs of equal
    magnitude is exact in a 64-bit mantissa (so the reference stays accurate at
    1e8 from the origin). ``A, t`` are the float64 model matrix's, taken as
    exact, or ``a_ld, t_ld`` computed by the caller in long double.
    """
    p = np.asarray(p_model, dtype=np.float64).reshape(-1, 3).astype(LD)
    m = np.eye(4) if model_matrix is None else np.asarray(model_matrix, np.float64)
    a = np.asarray(m[:3, :3] if a_ld is None else a_ld, dtype=LD)
    t = np.asarray(m[:3, 3] if t_ld is None else t_ld, dtype=LD)
    rel = p @ a.T + (t - np.asarray(camera.position, dtype=LD))  # p_world - position
    p_cam = rel @ reference_basis(camera).T
    z = p_cam[:, 2]
    visible = (z >= LD(camera.near)) & (z <= LD(camera.far))
    px = np.full((len(p), 2), np.nan, dtype=LD)
    cx, cy = (LD(camera.width) - 1) / 2, (LD(camera.height) - 1) / 2
    if camera.projection == "perspective":
        f = reference_focal(camera)
        zv = z[visible]
        px[visible, 0] = cx + f * p_cam[visible, 0] / zv
        px[visible, 1] = cy - f * p_cam[visible, 1] / zv
    else:
        s = LD(camera.height) / LD(camera.ortho_height)
        px[visible, 0] = cx + s * p_cam[visible, 0]
        px[visible, 1] = cy - s * p_cam[visible, 1]
    return p_cam, px, np.asarray(visible, bool)


def reference_cam_to_px(p_cam, camera) -> np.ndarray:
    """``(N, 2)`` perspective pixels of long-double camera points, no clipping (the exact crossings)."""
    z = p_cam[:, 2]
    f = reference_focal(camera)
    cx, cy = (LD(camera.width) - 1) / 2, (LD(camera.height) - 1) / 2
    return np.stack([cx + f * p_cam[:, 0] / z, cy - f * p_cam[:, 1] / z], axis=1)


def reference_motion_matrix(turns, offset, scale, frame: int, frames: int) -> tuple[np.ndarray, np.ndarray]:
    """``(A (3, 3), t (3,))`` in long double of Motion frame ``frame`` of ``frames`` (integer turns).

    conventions: ``T Rz Ry Rx S`` with angle_i = 2 pi phase_i and phase_i the
    exact rational ``((frame - 1) turns_i mod frames) / frames`` (Python integers).
    """
    angles = [2 * PI_LD * LD((frame - 1) * int(k) % frames) / LD(frames) for k in turns]
    (cx_, sx), (cy_, sy), (cz, sz) = ((np.cos(a), np.sin(a)) for a in angles)
    rx = np.array([[1, 0, 0], [0, cx_, -sx], [0, sx, cx_]], dtype=LD)
    ry = np.array([[cy_, 0, sy], [0, 1, 0], [-sy, 0, cy_]], dtype=LD)
    rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]], dtype=LD)
    return rz @ ry @ rx * LD(scale), np.asarray(offset, dtype=LD)
