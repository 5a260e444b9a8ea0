"""Model transforms as 4x4 homogeneous matrices (column vectors, see core.conventions).

All angles are in radians unless a name ends in ``_deg``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .limits import check_turns


def rotate_x(theta: float) -> np.ndarray:
    c, s = math.cos(theta), math.sin(theta)
    return np.array([[1, 0, 0, 0], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1]], dtype=np.float64)


def rotate_y(theta: float) -> np.ndarray:
    c, s = math.cos(theta), math.sin(theta)
    return np.array([[c, 0, s, 0], [0, 1, 0, 0], [-s, 0, c, 0], [0, 0, 0, 1]], dtype=np.float64)


def rotate_z(theta: float) -> np.ndarray:
    c, s = math.cos(theta), math.sin(theta)
    return np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]], dtype=np.float64)


def translate(offset) -> np.ndarray:
    m = np.eye(4)
    m[:3, 3] = np.asarray(offset, dtype=np.float64)
    return m


def scale(factor: float) -> np.ndarray:
    m = np.eye(4)
    m[0, 0] = m[1, 1] = m[2, 2] = float(factor)
    return m


def compose(*matrices: np.ndarray) -> np.ndarray:
    """``compose(A, B, C) == A @ B @ C``: the rightmost matrix applies first."""
    out = np.eye(4)
    for m in matrices:
        out = out @ m
    return out


def apply(matrix: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Apply a 4x4 affine matrix to row-stacked points ``(N, 3) -> (N, 3)``."""
    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    return points @ matrix[:3, :3].T + matrix[:3, 3]


@dataclass(frozen=True)
class Motion:
    """A model's motion over a run.

    Parameters
    ----------
    turns : (3,) tuple of float
        Full turns about X, Y and Z over the whole run (``360 * turns / frames``
        degrees per frame).
    offset : (3,) tuple of float
        A constant translation, world units.
    scale : float
        A constant uniform scale.
    pivot : (3,) tuple of float
        The point the scale and turns are about, model units (crosscheck spins
        a scene about the centre its cameras are framed on, oracles.cases).

    The model matrix at run fraction ``t`` in [0, 1) is
    ``T(offset) @ Rz @ Ry @ Rx @ S(scale)`` about the origin, and
    ``T(offset + pivot) @ Rz @ Ry @ Rx @ S(scale) @ T(-pivot)`` about a pivot
    (:mod:`wirecheck.core.conventions`).
    """

    turns: tuple[float, float, float] = (1.0, 1.0, 0.0)
    offset: tuple[float, float, float] = (0.0, 0.0, 0.0)
    scale: float = 1.0
    pivot: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def __post_init__(self):
        check_turns(self.turns, "Motion turns")

    def model_matrix(self, t: float) -> np.ndarray:
        """``T @ Rz @ Ry @ Rx @ S`` at time ``t`` in [0, 1); computed, never accumulated."""
        # Reduce whole turns before converting to radians, so that a whole number
        # of turns gives angle 0 exactly (sin(2*pi) is -2.4e-16, not 0).
        return self._matrix(tuple((t * float(k)) % 1.0 for k in self.turns))

    def frame_matrix(self, frame: int, frames: int) -> np.ndarray:
        """Model matrix of 1-based ``frame`` out of ``frames``: t = (frame - 1) / frames.

        The phase (fraction of a turn) is ``((frame - 1) * turns mod frames) / frames``:
        the product and the ``fmod`` are exact in float64 for integer turns (and
        any turns with few enough mantissa bits) up to 2^53, so a frame and the
        frame one period later get bit-identical matrices, however many frames.
        """
        n = float(frames)
        return self._matrix(tuple(math.fmod((frame - 1) * float(k), n) % n / n for k in self.turns))

    def _matrix(self, phases) -> np.ndarray:
        ax, ay, az = (2.0 * math.pi * p for p in phases)
        if not any(float(p) for p in self.pivot):  # about the origin: no T(pivot) factors at all
            return compose(translate(self.offset), rotate_z(az), rotate_y(ay), rotate_x(ax), scale(self.scale))
        to_pivot = tuple(float(o) + float(p) for o, p in zip(self.offset, self.pivot))
        return compose(
            translate(to_pivot),
            rotate_z(az),
            rotate_y(ay),
            rotate_x(ax),
            scale(self.scale),
            translate(tuple(-float(p) for p in self.pivot)),
        )
