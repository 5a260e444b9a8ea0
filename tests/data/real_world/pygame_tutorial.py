"""The projection of the classic pygame "3D in 2D" tutorials, wrapped for a camera.

The tutorials' ``Point3D.project`` (camera on the -Z axis, looking +Z)::

    factor = fov / (viewer_distance + self.z)
    x = self.x * factor + win_width / 2
    y = -self.y * factor + win_height / 2

``fov`` there is a focal length in pixels (256 in the tutorial). A user who
wraps it for a camera with a field of view moves the point into camera space
and derives ``fov`` from the angle. ``project_as_written`` does what such
wrappers usually do: the focal length from the *width* (the FOV taken as
horizontal) and the centre at ``W / 2, H / 2`` (pixel corners); ``project``
uses the vertical FOV and the pixel-centre principal point of the contract.
Perspective only: the tutorials have no orthographic view.
"""

import numpy as np


def _cam(points, camera):
    right = np.cross(camera.forward, camera.up)
    d = np.asarray(points, float) - camera.position
    return d @ right, d @ camera.up, d @ camera.forward


def _project(points, camera, f, cx, cy):
    x, y, z = _cam(points, camera)
    with np.errstate(divide="ignore", invalid="ignore"):
        factor = f / z
    px = np.stack([x * factor + cx, -y * factor + cy], axis=1)
    px[(z < camera.near) | (z > camera.far)] = np.nan
    return px


def project_as_written(points, camera):
    f = (camera.width / 2) / np.tan(np.radians(camera.fov_y_deg) / 2)
    return _project(points, camera, f, camera.width / 2, camera.height / 2)


def project(points, camera):
    f = (camera.height / 2) / np.tan(np.radians(camera.fov_y_deg) / 2)
    return _project(points, camera, f, (camera.width - 1) / 2, (camera.height - 1) / 2)
