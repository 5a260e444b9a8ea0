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
