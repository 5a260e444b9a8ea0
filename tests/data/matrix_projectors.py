"""Projectors that take the camera's matrices as they are, as a wrapper around a library would.

``opencv_style`` hands ``K``, ``R``, ``t`` and ``distortion`` to ``cv2.projectPoints``;
``gl_style`` multiplies ``projection_matrix @ view_matrix``, divides and applies
the viewport (it has no lens: it is wrong on a distorted camera, and crosscheck
says ``distortion_mismatch``). Neither computes a focal length or a principal
point itself. Orthographic cameras: ``K`` is affine there (no division).
"""

import cv2
import numpy as np


def _clip_depth(points, camera, px):
    z = (points - camera.position) @ camera.forward
    px[(z < camera.near) | (z > camera.far)] = np.nan
    return px


def opencv_style(points, camera):
    points = np.asarray(points, dtype=np.float64)
    if camera.projection == "orthographic":
        p_cv = points @ camera.R.T + camera.t
        px = p_cv[:, :2] * np.diag(camera.K)[:2] + camera.K[:2, 2]
    else:
        rvec, _ = cv2.Rodrigues(camera.R)
        px, _ = cv2.projectPoints(points.reshape(-1, 1, 3), rvec, camera.t, camera.K, camera.distortion)
        px = px.reshape(-1, 2)
    return _clip_depth(points, camera, px)


def gl_style(points, camera):
    points = np.asarray(points, dtype=np.float64)
    clip = np.column_stack([points, np.ones(len(points))]) @ (camera.projection_matrix @ camera.view_matrix).T
    with np.errstate(divide="ignore", invalid="ignore"):
        ndc = clip[:, :3] / clip[:, 3:]
    px = np.column_stack([(ndc[:, 0] + 1) * camera.width / 2 - 0.5, (1 - ndc[:, 1]) * camera.height / 2 - 0.5])
    return _clip_depth(points, camera, px)
