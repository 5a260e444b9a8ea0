"""The way back: pixels and depth along ``forward`` to world points, the exact inverse of the conventions.

Written from OpenCV's ``R, t, K`` of the camera (:func:`oracles.references.convert.opencv_matrices`,
built from the camera's own vectors, not from core), in float64::

    p_cv = R @ X + t                     OpenCV camera: x right, y down, z forward (= depth d)
    perspective:   u = cx + fx x_cv / z,   v = cy + fy y_cv / z
                   ->  x_cv = (u - cx) d / fx,   y_cv = (v - cy) d / fy,   z_cv = d
    orthographic:  u = cx + s x_cv,        v = cy + s y_cv          (s = H / ortho_height)
                   ->  x_cv = (u - cx) / s,      y_cv = (v - cy) / s,       z_cv = d
    X = R^T (p_cv - t)

(``u, v`` in pixel-centre coordinates, core.conventions.) A camera with lens distortion
has its pixels undistorted first by OpenCV's ``cv2.undistortPointsIter`` to the normalised
``(x_cv / z, y_cv / z)`` (:func:`undistort`), iterated to :data:`UNDISTORT_EPS` (OpenCV 5 has no
``undistortPointsIter``: the same iteration is ``cv2.undistortPoints(..., criteria=)`` there).
"""

from __future__ import annotations

import numpy as np

from .convert import distortion_coefficients, opencv_matrices

__all__ = ["UNDISTORT_EPS", "UNDISTORT_ITERATIONS", "cam_points", "undistort", "unproject"]

#: cv2.undistortPointsIter stops when an iteration moves the normalised point by less than
#: this (or after UNDISTORT_ITERATIONS): 1e-15 normalised is 1e-12 px at f = 1000 px, far under
#: any bound a candidate is held to (measured on the distorted case's lens, r_n <= 0.87: the
#: round trip projectPoints -> undistortPointsIter returns the points to 3e-15 normalised).
UNDISTORT_EPS = 1e-15
UNDISTORT_ITERATIONS = 200


def undistort(p_px: np.ndarray, camera) -> np.ndarray:
    """``(N, 2)`` ideal normalised coordinates ``(x_cv / z, y_cv / z)`` of distorted pixels (OpenCV's axes)."""
    import cv2

    _r, _t, k = opencv_matrices(camera)
    pts = np.ascontiguousarray(p_px, dtype=np.float64).reshape(-1, 1, 2)
    if len(pts) == 0:
        return np.zeros((0, 2))
    criteria = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, UNDISTORT_ITERATIONS, UNDISTORT_EPS)
    if hasattr(cv2, "undistortPointsIter"):  # OpenCV 4's name for undistortPoints with a criterion
        out = cv2.undistortPointsIter(pts, k, distortion_coefficients(camera), None, None, criteria)
    else:  # OpenCV 5 folded it in (equal to the last bit: docs/depth.md)
        out = cv2.undistortPoints(pts, k, distortion_coefficients(camera), R=None, P=None, criteria=criteria)
    return out.reshape(-1, 2)


def cam_points(p_px, depth, camera) -> np.ndarray:
    """``(N, 3)`` float64 OpenCV camera-space points ``p_cv`` of pixels ``(N, 2)`` at depths ``(N,)`` (module docstring)."""
    p_px = np.asarray(p_px, dtype=np.float64).reshape(-1, 2)
    d = np.asarray(depth, dtype=np.float64).reshape(-1)
    _r, _t, k = opencv_matrices(camera)
    fx, fy, cx, cy = k[0, 0], k[1, 1], k[0, 2], k[1, 2]
    if camera.projection != "perspective":
        return np.stack([(p_px[:, 0] - cx) / fx, (p_px[:, 1] - cy) / fy, d], axis=1)
    if getattr(camera, "distortion", None) is not None:
        xy_n = undistort(p_px, camera)
    else:
        xy_n = np.stack([(p_px[:, 0] - cx) / fx, (p_px[:, 1] - cy) / fy], axis=1)
    return np.stack([xy_n[:, 0] * d, xy_n[:, 1] * d, d], axis=1)


def unproject(p_px, depth, camera) -> np.ndarray:
    """``(N, 3)`` float64 world points of pixels ``p_px`` ``(N, 2)`` at depths along ``forward`` ``(N,)``.

    Parameters
    ----------
    p_px : (N, 2) array_like of float
        Pixel coordinates, x right, y down, integers at pixel centres (core.conventions).
    depth : (N,) array_like of float
        Depth along the camera's ``forward`` (``z_cam``), world units.
    camera : core.camera.Camera
        The candidate contract's camera (oracles.candidates.candidate).

    Returns
    -------
    (N, 3) ndarray of float64
        ``X = R^T (p_cv - t)``.

    Examples
    --------
    >>> from wirecheck.core.camera import camera_z
    >>> cam = camera_z(4.0, width=640, height=480)          # at (0, 0, 4) looking at the origin
    >>> unproject([[319.5, 239.5]], [4.0], cam).round(12).tolist()   # the image centre, 4 units in front
    [[0.0, 0.0, 0.0]]
    """
    r, t, _k = opencv_matrices(camera)
    p_cv = cam_points(p_px, depth, camera)
    return (p_cv - t) @ r  # row-stacked R^T (p_cv - t)
