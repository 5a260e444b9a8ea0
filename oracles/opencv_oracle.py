"""Reference point projection with OpenCV (``cv2.projectPoints``).

Same contract as ``core.projection.project_points``: world points ``(N, 3)`` to
pixels ``(N, 2)``, NaN rows where the camera depth is outside ``[near, far]``.
``cv2.projectPoints`` culls nothing (a point behind the camera comes back
mirrored through the centre of projection), so depth is computed here from the
OpenCV ``R, t`` and masked before projecting.
"""

from __future__ import annotations

import numpy as np

from wirecheck.core.camera import Camera

from .convert import camera_basis, camera_to_opencv, distortion_coefficients

__all__ = ["project", "depth"]


def _r_t(camera: Camera) -> tuple[np.ndarray, np.ndarray]:
    # R rows: right, -up, forward (see convert.camera_to_opencv); built from the
    # camera's vectors rather than through Rodrigues, to keep depth exact.
    right, up, forward = camera_basis(camera)
    r_cv = np.stack([right, -up, forward])
    return r_cv, -r_cv @ np.asarray(camera.position, dtype=np.float64)


def depth(p_world: np.ndarray, camera: Camera) -> np.ndarray:
    """``(N,)`` float64: OpenCV's camera depth ``z_cv`` of ``(N, 3)`` world points (ours too: along ``forward``)."""
    p_world = np.asarray(p_world, dtype=np.float64).reshape(-1, 3)
    r_cv, t_cv = _r_t(camera)
    return p_world @ r_cv[2] + t_cv[2]


def project(p_world: np.ndarray, camera: Camera) -> np.ndarray:
    """Project world points to pixels; NaN rows outside ``[near, far]``.

    Perspective: ``cv2.projectPoints`` (float64) with ``rvec, tvec, K`` from
    :func:`oracles.convert.camera_to_opencv` and the camera's distortion
    coefficients (:func:`oracles.convert.distortion_coefficients`; zeros when
    it has none).
    Orthographic: the closed form (no OpenCV model exists)::

        s = H / ortho_height
        x_px = cx + s * right . (X - position)
        y_px = cy - s * up . (X - position)

    Parameters
    ----------
    p_world : (N, 3) array_like
    camera : Camera

    Returns
    -------
    p_px : (N, 2) ndarray of float64, NaN rows where depth is outside [near, far].
    """
    p_world = np.asarray(p_world, dtype=np.float64).reshape(-1, 3)
    p_px = np.full((len(p_world), 2), np.nan)
    z = depth(p_world, camera)
    visible = (z >= camera.near) & (z <= camera.far)
    if not visible.any():
        return p_px
    rvec, tvec, k = camera_to_opencv(camera)
    if camera.projection == "perspective":
        import cv2
        pts, _ = cv2.projectPoints(p_world[visible].reshape(-1, 1, 3), rvec, tvec, k,
                                   distortion_coefficients(camera))
        p_px[visible] = pts.reshape(-1, 2)
    else:
        d = p_world[visible] - camera.position
        s = k[0, 0]                                     # H / ortho_height
        right, up, _ = camera_basis(camera)
        p_px[visible, 0] = k[0, 2] + s * (d @ right)
        p_px[visible, 1] = k[1, 2] - s * (d @ up)
    return p_px
