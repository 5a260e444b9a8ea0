"""Camera space to pixel space: perspective and orthographic (see core.conventions)."""

from __future__ import annotations

import numpy as np

from .camera import Camera
from .transforms import apply


def world_to_cam(p_world: np.ndarray, camera: Camera) -> np.ndarray:
    """``(N, 3)`` world points to camera space (x right, y up, z forward = depth)."""
    return apply(camera.world_to_cam, p_world)


def depth_mask(p_cam: np.ndarray, camera: Camera) -> np.ndarray:
    """``(N,) bool``: True where ``near <= z_cam <= far`` (NaN depth is outside)."""
    z = p_cam[:, 2]
    return (z >= camera.near) & (z <= camera.far)


def cam_to_px(p_cam: np.ndarray, camera: Camera) -> np.ndarray:
    """``(N, 3)`` camera points to ``(N, 2)`` pixels. No masking.

    Precondition for perspective: every ``z_cam`` is positive (callers clip at
    the near plane first). A point at z = 0 gives inf, z < 0 a mirrored point.
    A result beyond the float64 range is inf, silently: callers check
    (``renderer`` reports it as an input error).
    """
    cx, cy = camera.principal_point
    with np.errstate(over="ignore"):
        if camera.projection == "perspective":
            f = camera.focal_px
            inv_z = 1.0 / p_cam[:, 2]
            x_px = cx + f * p_cam[:, 0] * inv_z
            y_px = cy - f * p_cam[:, 1] * inv_z
        else:
            s = camera.height / camera.ortho_height
            x_px = cx + s * p_cam[:, 0]
            y_px = cy - s * p_cam[:, 1]
    return np.stack([x_px, y_px], axis=1)


def project_points(p_world: np.ndarray, camera: Camera) -> np.ndarray:
    """World points to pixels, NaN rows for points outside [near, far].

    This is the candidate contract of ``crosscheck``: ``(N, 3) -> (N, 2)``.
    """
    p_world = np.asarray(p_world, dtype=np.float64).reshape(-1, 3)
    p_cam = world_to_cam(p_world, camera)
    visible = depth_mask(p_cam, camera)
    p_px = np.full((len(p_world), 2), np.nan)
    if visible.any():
        p_px[visible] = cam_to_px(p_cam[visible], camera)
    return p_px
