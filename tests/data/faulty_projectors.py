"""Candidates with known faults, written against the contract only (no core imports)."""

import numpy as np
from user_projector import project


def mirrored(points, camera):
    px = project(points, camera)
    px[:, 0] = (camera.width - 1) - px[:, 0]
    return px


def crashes(points, camera):
    raise ZeroDivisionError("boom")


def wrong_shape(points, camera):
    return np.zeros((len(points), 3))


def offset_when_large(points, camera):
    """Correct for points within 1.5 of the origin, half a pixel off (the pixel-corner mistake) when any is
    farther: a candidate that fails the large meshes of a dataset and passes the small ones
    (tests/test_dataset.py; rotations about the origin keep a point's distance)."""
    if len(points) == 0 or np.max(np.linalg.norm(points, axis=1)) <= 1.5:
        return project(points, camera)
    return project(points, camera, cx=camera.width / 2, cy=camera.height / 2)


def horizontal_fov(points, camera):
    """The FOV applied horizontally: f = (W / 2) / tan(fov / 2), from the width (the contract's fov is vertical)."""
    right = np.cross(camera.forward, camera.up)
    d = points - camera.position
    x, y, z = d @ right, d @ camera.up, d @ camera.forward
    f = (camera.width / 2) / np.tan(np.radians(camera.fov_y_deg) / 2)
    with np.errstate(divide="ignore", invalid="ignore"):
        px = np.stack([(camera.width - 1) / 2 + f * x / z, (camera.height - 1) / 2 - f * y / z], axis=1)
    px[(z < camera.near) | (z > camera.far)] = np.nan
    return px


def no_clipping(points, camera):
    """No clipping before the divide: every point goes through x / z, those behind the camera too."""
    right = np.cross(camera.forward, camera.up)
    d = points - camera.position
    x, y, z = d @ right, d @ camera.up, d @ camera.forward
    f = (camera.height / 2) / np.tan(np.radians(camera.fov_y_deg) / 2)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.stack([(camera.width - 1) / 2 + f * x / z, (camera.height - 1) / 2 - f * y / z], axis=1)


def fixed_orientation(points, camera):
    """The camera's position used, its forward and up ignored: always looking down -Z with +Y up."""
    d = points - camera.position
    x, y, z = d[:, 0], d[:, 1], -d[:, 2]
    f = (camera.height / 2) / np.tan(np.radians(camera.fov_y_deg) / 2)
    with np.errstate(divide="ignore", invalid="ignore"):
        px = np.stack([(camera.width - 1) / 2 + f * x / z, (camera.height - 1) / 2 - f * y / z], axis=1)
    px[(z < camera.near) | (z > camera.far)] = np.nan
    return px


def depth_clamped(points, camera):
    """Divides by the depth clamped to 10 (a fog or LOD range taken for the depth): beyond 10 units
    nothing gets smaller."""
    right = np.cross(camera.forward, camera.up)
    d = points - camera.position
    x, y, z = d @ right, d @ camera.up, d @ camera.forward
    f = (camera.height / 2) / np.tan(np.radians(camera.fov_y_deg) / 2)
    w = np.minimum(z, 10.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        px = np.stack([(camera.width - 1) / 2 + f * x / w, (camera.height - 1) / 2 - f * y / w], axis=1)
    px[(z < camera.near) | (z > camera.far)] = np.nan
    return px


def divides_before_clipping(points, camera):
    """Divides each point in Python floats, then clips: a point on the camera's plane (z = 0) raises
    ZeroDivisionError before its depth is ever tested."""
    right = np.cross(camera.forward, camera.up)
    f = (camera.height / 2) / np.tan(np.radians(camera.fov_y_deg) / 2)
    out = []
    for p in points:
        d = p - camera.position
        x, y, z = float(d @ right), float(d @ camera.up), float(d @ camera.forward)
        u, v = x / z, y / z
        out.append(
            [np.nan, np.nan]
            if not camera.near <= z <= camera.far
            else [(camera.width - 1) / 2 + f * u, (camera.height - 1) / 2 - f * v]
        )
    return np.array(out, dtype=np.float64).reshape(-1, 2)


def clips_at_camera(points, camera):
    """Clips at the camera (keeps every z > 0), not at the near plane."""
    px = no_clipping(points, camera)
    z = (points - camera.position) @ camera.forward
    px[~((z > 0) & (z <= camera.far))] = np.nan
    return px


def fails_on_empty(points, camera):
    """Correct, but takes the largest coordinate first: numpy's max of no points raises ValueError."""
    if np.abs(points).max() > 1e12:
        raise ValueError("too far")
    return project(points, camera)


def nan_everywhere(points, camera):
    """NaN for every point, in front of the camera or not: every check that compares a pixel fails."""
    return np.full((len(points), 2), np.nan)


def far_off(points, camera):
    """1e300 px for every point: finite, but its distances to the right pixels overflow to inf."""
    return np.full((len(points), 2), 1e300)
