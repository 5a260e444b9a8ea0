"""A user's projector (pinhole, pixel centres at integers, y down) and a mirrored copy of it."""

import numpy as np


def project(points, camera):
    right = np.cross(camera.forward, camera.up)
    d = points - camera.position
    x, y, z = d @ right, d @ camera.up, d @ camera.forward
    cx, cy = (camera.width - 1) / 2, (camera.height - 1) / 2
    if camera.projection == "perspective":
        f = (camera.height / 2) / np.tan(np.radians(camera.fov_y_deg) / 2)
        with np.errstate(divide="ignore", invalid="ignore"):
            px = np.stack([cx + f * x / z, cy - f * y / z], axis=1)
    else:
        s = camera.height / camera.ortho_height
        px = np.stack([cx + s * x, cy - s * y], axis=1)
    px[(z < camera.near) | (z > camera.far)] = np.nan
    return px


def mirrored(points, camera):
    px = project(points, camera)
    px[:, 0] = (camera.width - 1) - px[:, 0]
    return px
