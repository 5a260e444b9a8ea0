"""Composing a run's pictures: the frame's image, the world axes on top, two cameras side by side.

Images are ``(H, W)`` grey or ``(H, W, 3)`` RGB uint8 (pixel convention:
core.conventions). The axes are drawn by core's own pipeline, one edge each.
"""

from __future__ import annotations

import math

import numpy as np

from ..camera import Camera
from ..projector.pipeline import Frame, draw_segments, render_frame
from ..projector.projection import world_to_cam

#: World axes (RGB), drawn in this order (a later axis covers an earlier one).
AXIS_COLOURS = (("x", (255, 0, 0)), ("y", (0, 255, 0)), ("z", (0, 0, 255)))
#: Axis length as a multiple of the scene's bounding radius.
AXIS_LENGTH = 1.2
#: Two pictures side by side: the 1-pixel column between them.
SEPARATOR_GREY = 128

_IDENTITY = np.eye(4)
_IDENTITY.setflags(write=False)


def picture(frame: Frame, style: str) -> np.ndarray:
    """The frame's image: the wireframe, or with style "shaded" the pipeline's shaded picture."""
    if style == "shaded" and frame.shaded is not None:
        return np.asarray(frame.shaded)
    return frame.image


def axis_length(radius: float, scale: float) -> float:
    """``AXIS_LENGTH`` x ``radius`` x ``|scale|`` (``AXIS_LENGTH`` for an empty or point scene)."""
    r = radius * abs(scale)
    return AXIS_LENGTH * (r if r > 0 and math.isfinite(r) else 1.0)


def axis_layers(
    length: float, camera: Camera, clip: str, dtype: str, raster: str, frame: Frame | None = None
) -> list[tuple[tuple[int, int, int], np.ndarray]]:
    """``[(rgb, coverage (H, W) uint8)]`` for the X, Y, Z axes of ``length`` from the origin.

    Each axis is one edge through core's pipeline, so it is clipped and
    rasterized as the scene's edges are; ``coverage`` is 255 on its pixels
    (0..255 for raster "aa"). Without faces the world axes do not move:
    compute this once per camera and run. With ``frame`` rendered with hidden
    lines or shaded (it has a depth buffer), the axes are depth-tested against
    its faces like its own edges (:func:`core.projector.pipeline.draw_segments`), so
    they are computed per frame.
    """
    points = np.array([[0.0, 0.0, 0.0], [length, 0.0, 0.0], [0.0, length, 0.0], [0.0, 0.0, length]])
    if frame is not None and frame.tri_ids is not None:
        p_cam = world_to_cam(points, camera)  # camera
        layers = []
        for i, (_, rgb) in enumerate(AXIS_COLOURS, start=1):
            seg_cam = p_cam[[0, i]][None]
            if clip == "endpoint" and not ((camera.near <= seg_cam[0, :, 2]) & (seg_cam[0, :, 2] <= camera.far)).all():
                seg_cam = seg_cam[:0]  # clip "endpoint": a clipped end drops the edge
            layers.append((rgb, draw_segments(seg_cam, camera, raster, occluders=frame)))
        return layers
    layers = []
    for i, (_, rgb) in enumerate(AXIS_COLOURS, start=1):
        f = render_frame(points, np.array([[0, i]]), camera, _IDENTITY, clip, dtype=dtype, raster=raster)
        layers.append((rgb, f.image))
    return layers


def _rgb(image: np.ndarray) -> np.ndarray:
    """A new ``(H, W, 3)`` uint8 copy of a grey or RGB image."""
    out = np.empty(image.shape[:2] + (3,), dtype=np.uint8)
    out[...] = image if image.ndim == 3 else image[:, :, None]
    return out


def overlay(image: np.ndarray, layers) -> np.ndarray:
    """RGB ``image`` (grey is replicated) with each layer's colour blended in by its coverage, in order.

    ``out = (out (255 - c) + colour c + 127) // 255`` on the covered pixels: for
    coverage 255 (rasters "exact", "fast") the pixel is exactly the colour.
    """
    out = _rgb(image)
    for colour, cov in layers:
        rows, cols = np.nonzero(cov)
        if len(rows) == 0:
            continue
        c = cov[rows, cols].astype(np.uint32)[:, None]
        old = out[rows, cols].astype(np.uint32)
        out[rows, cols] = ((old * (255 - c) + np.asarray(colour, dtype=np.uint32) * c + 127) // 255).astype(np.uint8)
    return out


def side_by_side(left: np.ndarray, right: np.ndarray) -> np.ndarray:
    """``left | grey 1-px column | right`` (both grey, or both made RGB): width ``2 W + 1``."""
    if left.ndim != right.ndim:
        left, right = (im if im.ndim == 3 else _rgb(im) for im in (left, right))
    sep = np.full(left.shape[:1] + (1,) + left.shape[2:], SEPARATOR_GREY, dtype=np.uint8)
    return np.concatenate([left, sep, right], axis=1)
