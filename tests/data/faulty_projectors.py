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
