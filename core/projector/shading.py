"""Flat (per-face Lambert) shading of a face-id buffer.

``light_dir`` is the direction the light **travels** (from the light toward
the scene), in world space. A face with unit outward normal ``n`` gets::

    intensity = ambient + (1 - ambient) * max(0, n . (-light_dir))

and the grey level ``floor(255 * intensity + 1/2)`` (halves up); pixels with
no face (id -1) are 0. Normals are the outward normals of faces wound
counter-clockwise seen from outside (core.projector.culling); the lighting is one-sided,
so a face seen from behind gets the ambient term only (unless lit from
behind). Visibility is decided beforehand by core.projector.zbuffer: this module only
colours the face ids it is given.

The default light (:func:`default_light_dir`) comes from the camera's upper
left, from behind the viewer: it travels along ``forward + right - up``
(normalised), i.e. toward the scene, to the right and down the image.
"""

from __future__ import annotations

import numpy as np

from ..camera import Camera

__all__ = ["STYLES", "DEFAULT_AMBIENT", "default_light_dir", "face_intensity", "shade"]

#: What a frame shows: the edges, or the faces flat-shaded.
STYLES = ("wireframe", "shaded")

DEFAULT_AMBIENT = 0.15


def default_light_dir(camera: Camera) -> np.ndarray:
    """``(3,)`` world direction of travel of the default light: ``normalise(forward + right - up)``."""
    v = np.asarray(camera.forward) + np.asarray(camera.right) - np.asarray(camera.up)
    return v / np.linalg.norm(v)


def face_intensity(normals_world: np.ndarray, light_dir_world, ambient: float = DEFAULT_AMBIENT) -> np.ndarray:
    """``(F,) float64`` Lambert intensity in [ambient, 1] of each face (module docstring).

    Normals and the light direction need not be unit length (they are
    normalised here); a zero normal (degenerate face) gets the ambient term.
    """
    n = np.asarray(normals_world, dtype=np.float64).reshape(-1, 3)
    light = np.asarray(light_dir_world, dtype=np.float64).reshape(3)
    big = np.abs(light).max()
    if np.isfinite(big) and big > 0:
        light = light / big  # a direction: scaled first, so norm() cannot over/underflow
    norm_l = np.linalg.norm(light)
    if not (np.isfinite(norm_l) and norm_l > 0):
        raise ValueError(f"light_dir {light.tolist()}: expected a finite non-zero direction")
    length = np.linalg.norm(n, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        cos = np.where(length > 0, (n @ (-light / norm_l)) / length, 0.0)
    return ambient + (1.0 - ambient) * np.clip(cos, 0.0, 1.0)


def shade(
    face_ids: np.ndarray, normals_world: np.ndarray, light_dir_world, ambient: float = DEFAULT_AMBIENT
) -> np.ndarray:
    """``(H, W) uint8`` flat-shaded image of a face-id buffer.

    Parameters
    ----------
    face_ids : (H, W) int array
        Index into ``normals_world`` of the face seen at each pixel, -1 for none.
    normals_world : (F, 3) array
        Outward face normals in world space (any length).
    light_dir_world : (3,) array
        Direction the light travels (from the light toward the scene).
    ambient : float in [0, 1]
    """
    if not 0.0 <= ambient <= 1.0:
        raise ValueError(f"ambient {ambient!r}: expected a value in [0, 1]")
    face_ids = np.asarray(face_ids)
    level = np.floor(255.0 * face_intensity(normals_world, light_dir_world, ambient) + 0.5)
    lut = np.concatenate([[0], level]).astype(np.uint8)  # id -1 -> 0
    return lut[face_ids + 1]
