"""Unprojectors for tests/test_unprojector.py: a correct one, a float32 one, and one classic mistake each.

Each is ``unproject(pixels (N, 2), depth (N,), camera) -> (N, 3)`` written from the camera's
K, R, t as a user would (OpenCV's camera: x right, y down, z forward; ``p_cv = R X + t``).
"""

from __future__ import annotations

import cv2
import numpy as np


def _normalised(pixels, camera, cx=None, cy=None, fx=None, fy=None):
    k = camera.K
    fx = k[0, 0] if fx is None else fx
    fy = k[1, 1] if fy is None else fy
    cx = k[0, 2] if cx is None else cx
    cy = k[1, 2] if cy is None else cy
    if camera.projection != "perspective":
        return (pixels[:, 0] - cx) / fx, (pixels[:, 1] - cy) / fy
    if camera.distortion is not None:
        criteria = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 100, 1e-15)
        if hasattr(cv2, "undistortPointsIter"):
            xy = cv2.undistortPointsIter(
                pixels.reshape(-1, 1, 2), k, np.array(camera.distortion), None, None, criteria
            ).reshape(-1, 2)
        else:  # OpenCV 5: undistortPoints takes the criterion itself
            xy = cv2.undistortPoints(
                pixels.reshape(-1, 1, 2), k, np.array(camera.distortion), R=None, P=None, criteria=criteria
            ).reshape(-1, 2)
        return xy[:, 0], xy[:, 1]
    return (pixels[:, 0] - cx) / fx, (pixels[:, 1] - cy) / fy


def _to_world(x_n, y_n, depth, camera, transpose=False):
    if camera.projection == "perspective":
        p_cv = np.stack([x_n * depth, y_n * depth, depth], axis=1)
    else:
        p_cv = np.stack([x_n, y_n, depth], axis=1)
    r, t = camera.R, camera.t
    rot = r if transpose else r.T
    return (p_cv - t) @ rot.T


def correct(pixels, depth, camera):
    return _to_world(*_normalised(pixels, camera), depth, camera)


def correct_float32(pixels, depth, camera):
    """The same arithmetic in float32 (a shader's): inputs, camera and every step rounded to float32."""
    f32 = np.float32
    p = pixels.astype(f32)
    d = depth.astype(f32)
    k = camera.K.astype(f32)
    x_n = (p[:, 0] - k[0, 2]) / k[0, 0]
    y_n = (p[:, 1] - k[1, 2]) / k[1, 1]
    if camera.projection == "perspective":
        p_cv = np.stack([x_n * d, y_n * d, d], axis=1)
    else:
        p_cv = np.stack([x_n, y_n, d], axis=1)
    return (p_cv - camera.t.astype(f32)) @ camera.R.astype(f32)


def gl_unproject(pixels, depth, camera):
    """Correct, the GL way: NDC from the window position and depth, through inverse(P V) (worse conditioned)."""
    w, h = camera.width, camera.height
    p, v = camera.projection_matrix, camera.view_matrix
    x_ndc = 2.0 * (pixels[:, 0] + 0.5) / w - 1.0
    y_ndc = 1.0 - 2.0 * (pixels[:, 1] + 0.5) / h
    eye_z = -depth
    clip = p @ np.stack([np.zeros_like(eye_z), np.zeros_like(eye_z), eye_z, np.ones_like(eye_z)])
    z_ndc = clip[2] / clip[3]
    ndc = np.stack([x_ndc, y_ndc, z_ndc, np.ones_like(x_ndc)])
    world = np.linalg.inv(p @ v) @ ndc
    return (world[:3] / world[3]).T


def half_pixel(pixels, depth, camera):
    """cx = W / 2, cy = H / 2 (GL's window centre)."""
    return _to_world(*_normalised(pixels, camera, cx=camera.width / 2, cy=camera.height / 2), depth, camera)


def rows_flipped(pixels, depth, camera):
    flipped = np.column_stack([pixels[:, 0], camera.height - 1 - pixels[:, 1]])
    return _to_world(*_normalised(flipped, camera), depth, camera)


def horizontal_fov(pixels, depth, camera):
    """K built from fov_y_deg taken as the horizontal FOV: f = (W / 2) / tan(fov / 2)."""
    f = (camera.width / 2) / np.tan(np.radians(camera.fov_y_deg) / 2)
    return _to_world(*_normalised(pixels, camera, fx=f, fy=f), depth, camera)


def ray_distance(pixels, depth, camera):
    """Depth taken as distance along the ray: the ray normalised before scaling by it."""
    x_n, y_n = _normalised(pixels, camera)
    norm = np.sqrt(1 + x_n**2 + y_n**2)
    return _to_world(x_n, y_n, depth / norm, camera)


def transposed(pixels, depth, camera):
    return _to_world(*_normalised(pixels, camera), depth, camera, transpose=True)


def raises(pixels, depth, camera):
    raise RuntimeError("not implemented")


def exits(pixels, depth, camera):
    """Ends the process with status 0: must fail its case, never pass a gate."""
    import sys

    sys.exit(0)


def hard_exit(pixels, depth, camera):
    """Ends its process at once, status 0 (no Python clean-up): run isolated, it fails its case."""
    import os

    os._exit(0)


def wrong_shape(pixels, depth, camera):
    return correct(pixels, depth, camera)[:, :2]


def correct_two(points, camera):
    """A projector's signature, not an unprojector's."""
    return points
