"""Reference point projection with OpenCV (``cv2.projectPoints``).

Same contract as ``core.projector.projection.project_points``: world points ``(N, 3)`` to
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


#: The last camera converted and its conversion. A case calls this module
#: several times a frame with the same frozen camera; converting it (a scipy
#: rotation, the basis) cost ~0.2 ms a call against ~0.01 ms for projectPoints.
#: One entry holding the camera itself: identity cannot be reused while cached.
_last: tuple = (None, None)


def _conversion(camera: Camera) -> dict:
    global _last
    cached_camera, conv = _last
    if cached_camera is camera and type(camera) is Camera:  # frozen: same object, same values
        return conv
    # R rows: right, -up, forward (see convert.camera_to_opencv); built from the
    # camera's vectors rather than through Rodrigues, to keep depth exact.
    right, up, forward = camera_basis(camera)
    r_cv = np.stack([right, -up, forward])
    t_cv = -r_cv @ np.asarray(camera.position, dtype=np.float64)
    rvec, tvec, k = camera_to_opencv(camera)
    conv = {
        "r": r_cv,
        "t": t_cv,
        "rvec": rvec,
        "tvec": tvec,
        "k": k,
        "right": right,
        "up": up,
        "dist": distortion_coefficients(camera) if camera.projection == "perspective" else None,
    }
    for a in conv.values():
        if a is not None:
            a.setflags(write=False)  # shared between calls: nobody may change it
    _last = (camera, conv)
    return conv


def _r_t(camera: Camera) -> tuple[np.ndarray, np.ndarray]:
    conv = _conversion(camera)
    return conv["r"], conv["t"]


def depth(p_world: np.ndarray, camera: Camera) -> np.ndarray:
    """``(N,)`` float64: OpenCV's camera depth ``z_cv`` of ``(N, 3)`` world points (ours too: along ``forward``)."""
    p_world = np.asarray(p_world, dtype=np.float64).reshape(-1, 3)
    r_cv, t_cv = _r_t(camera)
    return p_world @ r_cv[2] + t_cv[2]


def project(p_world: np.ndarray, camera: Camera) -> np.ndarray:
    """Project world points to pixels; NaN rows outside ``[near, far]``.

    Perspective: ``cv2.projectPoints`` (float64) with ``rvec, tvec, K`` from
    :func:`oracles.references.convert.camera_to_opencv` and the camera's distortion
    coefficients (:func:`oracles.references.convert.distortion_coefficients`; zeros when
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
    conv = _conversion(camera)
    k = conv["k"]
    if camera.projection == "perspective":
        import cv2

        pts, _ = cv2.projectPoints(p_world[visible].reshape(-1, 1, 3), conv["rvec"], conv["tvec"], k, conv["dist"])
        p_px[visible] = pts.reshape(-1, 2)
    else:
        d = p_world[visible] - camera.position
        s = k[0, 0]  # H / ortho_height
        right, up = conv["right"], conv["up"]
        p_px[visible, 0] = k[0, 2] + s * (d @ right)
        p_px[visible, 1] = k[1, 2] - s * (d @ up)
    return p_px
