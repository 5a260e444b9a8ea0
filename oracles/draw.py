"""Drawing an external candidate's projection, so its pixels can be compared too.

A candidate only maps points to pixels. To draw its wireframe, the harness
clips each edge in world space against the near and far planes (depth is
affine along a segment, so this is exact), asks the candidate to project the
clipped ends, clips the 2D segments to the image and rasterises them with
core's line rasterizer. A correct candidate then draws what core draws.
"""

from __future__ import annotations

import numpy as np

from wirecheck.core.clipping import clip_to_image
from wirecheck.core.raster import line_pixels

from . import opencv_oracle
from .candidate import call_candidate

#: Clipped ends are moved this fraction of the kept segment inward, so that a
#: point computed to lie exactly on the near plane is not clipped by the
#: candidate because of one ulp of rounding (1e-9 of a segment is far below a
#: pixel for any segment shorter than 1e8 px).
_INWARD = 1e-9


def clip_depth(p0_world, p1_world, camera):
    """Keep the parts of segments with depth in [near, far]: ``(kept, ends (K, 2, 3))``."""
    d0 = opencv_oracle.depth(p0_world, camera)
    d1 = opencv_oracle.depth(p1_world, camera)
    t_in = np.zeros(len(d0))
    t_out = np.ones(len(d0))
    with np.errstate(divide="ignore", invalid="ignore"):
        for plane, sign in ((camera.near, 1.0), (camera.far, -1.0)):
            s0 = sign * (d0 - plane)          # >= 0 inside
            s1 = sign * (d1 - plane)
            t = s0 / (s0 - s1)
            t_in = np.where((s0 < 0) & (s1 >= 0), np.maximum(t_in, t), t_in)
            t_out = np.where((s0 >= 0) & (s1 < 0), np.minimum(t_out, t), t_out)
            t_in = np.where((s0 < 0) & (s1 < 0), 2.0, t_in)   # both outside: drop
    kept = t_in <= t_out
    span = (t_out - t_in)[kept]
    a = t_in[kept] + np.where(t_in[kept] > 0, _INWARD * span, 0.0)
    b = t_out[kept] - np.where(t_out[kept] < 1, _INWARD * span, 0.0)
    d = (p1_world - p0_world)[kept]
    ends = np.stack([p0_world[kept] + a[:, None] * d, p0_world[kept] + b[:, None] * d], axis=1)
    return kept, ends


def draw_candidate(func, p_world: np.ndarray, edges: np.ndarray, camera) -> np.ndarray:
    """``(H, W)`` bool image of the candidate's wireframe."""
    image = np.zeros((camera.height, camera.width), bool)
    if len(edges) == 0:
        return image
    _, ends = clip_depth(p_world[edges[:, 0]], p_world[edges[:, 1]], camera)
    if len(ends) == 0:
        return image
    px = call_candidate(func, ends.reshape(-1, 3), camera).reshape(-1, 2, 2)
    _, q0, q1 = clip_to_image(px[:, 0], px[:, 1], camera.width, camera.height)
    rr, cc = line_pixels(q0, q1, camera.width, camera.height)
    image[rr, cc] = True
    return image


def oracle_segments(p_world: np.ndarray, edges: np.ndarray, camera) -> tuple[np.ndarray, np.ndarray]:
    """``(E, 2)`` twice: each edge's ends in pixels by OpenCV, clipped to [near, far] in depth; NaN if none left.

    The oracle's float64 picture of where each line lies, for attributing
    drawn pixels to edges (:func:`oracles.metrics.line_scores`).
    """
    p0 = np.full((len(edges), 2), np.nan)
    p1 = np.full((len(edges), 2), np.nan)
    if len(edges) == 0:
        return p0, p1
    kept, ends = clip_depth(p_world[edges[:, 0]], p_world[edges[:, 1]], camera)
    if len(ends):
        px = opencv_oracle.project(ends.reshape(-1, 3), camera).reshape(-1, 2, 2)
        p0[kept], p1[kept] = px[:, 0], px[:, 1]
    return p0, p1
