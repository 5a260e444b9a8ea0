"""A projector written outside wirecheck, as a user would: plain numpy, no core/ imports.

`project` follows the contract; `project_corner` makes the classic mistake of
putting the principal point at (W/2, H/2) (pixel-corner convention), which
crosscheck reports as pixel_offset dx=0.5, dy=0.5.
"""

import numpy as np


def project(points, camera, cx=None, cy=None):
    right = np.cross(camera.forward, camera.up)
    d = points - camera.position
    x, y, z = d @ right, d @ camera.up, d @ camera.forward
    cx = (camera.width - 1) / 2 if cx is None else cx
    cy = (camera.height - 1) / 2 if cy is None else cy
    if camera.projection == "perspective":
        f = (camera.height / 2) / np.tan(np.radians(camera.fov_y_deg) / 2)
        with np.errstate(divide="ignore", invalid="ignore"):
            px = np.stack([cx + f * x / z, cy - f * y / z], axis=1)
    else:
        s = camera.height / camera.ortho_height
        px = np.stack([cx + s * x, cy - s * y], axis=1)
    px[(z < camera.near) | (z > camera.far)] = np.nan
    return px


def project_corner(points, camera):
    return project(points, camera, cx=camera.width / 2, cy=camera.height / 2)
