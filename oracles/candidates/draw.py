"""Drawing an external candidate's projection, so its pixels can be compared too.

A candidate only maps points to pixels. To draw its wireframe, the harness
clips each edge in world space against the near and far planes (depth is
affine along a segment, so this is exact), asks the candidate to project the
clipped ends, clips the 2D segments to the image and rasterises them with
core's line rasterizer. A correct candidate then draws what core draws.

A clipped end lies on the near (or far) plane, where the candidate's own depth
test decides in its own precision: computed in float32, the end's depth may
come out a rounding below ``near`` and the candidate rightly clips it, losing
the whole edge. So each clipped end is moved inside ``[near, far]`` by more
than the candidate's depth rounding at that point, ``DEPTH_ROUNDINGS eps
(|X| + |C|)`` (oracles.tolerances; eps of the candidate's precision), and
never less than ``_INWARD`` of the kept segment. A correct candidate at its
precision then cannot reject it; the end moves by ~1e-6 of a unit in depth
for float32 (a small fraction of a pixel unless the edge is seen end-on).
"""

from __future__ import annotations

import numpy as np
from wirecheck.core.projector.clipping import clip_to_image
from wirecheck.core.projector.raster import line_pixels

from ..references import opencv_oracle
from ..tolerances import DEPTH_ROUNDINGS, EPS
from .candidate import call_candidate

#: Clipped ends are moved at least this fraction of the kept segment inward
#: (1e-9 of a segment is far below a pixel for any segment shorter than 1e8 px).
_INWARD = 1e-9
#: At most this fraction of the kept segment: a kept part shorter than the
#: depth margin keeps its middle half.
_MAX_INWARD = 0.25


def depth_margin(p_world: np.ndarray, camera, precision: str) -> np.ndarray:
    """``(N,)``: how far a candidate of ``precision`` may misplace each point's depth, ``DEPTH_ROUNDINGS eps (|X| + |C|)``."""
    size = np.linalg.norm(p_world, axis=1) + float(np.linalg.norm(camera.position))
    return DEPTH_ROUNDINGS * EPS[precision] * size


def clip_depth(p0_world, p1_world, camera, precision: str = "float64", slack: float = 0.0):
    """Keep the parts of segments with depth in [near, far]: ``(kept, ends (K, 2, 3))``.

    A clipped end is moved inward by :func:`depth_margin` at ``precision`` in
    depth (module docstring), or by ``slack`` (depth units) when larger: the
    candidate's own planes, probed, lie that far inside (oracles.diagnosis.clip_planes.depth_slack);
    at least ``_INWARD`` and at most ``_MAX_INWARD`` of the kept part.
    """
    d0 = opencv_oracle.depth(p0_world, camera)
    d1 = opencv_oracle.depth(p1_world, camera)
    if np.all((d0 >= camera.near) & (d0 <= camera.far) & (d1 >= camera.near) & (d1 <= camera.far)):
        # nothing clipped (a NaN depth is not in range: below): the general path's ends, to the bit
        d = p1_world - p0_world
        ends = np.stack([p0_world + np.zeros(len(d0))[:, None] * d, p0_world + np.ones(len(d0))[:, None] * d], axis=1)
        return np.ones(len(d0), bool), ends
    t_in = np.zeros(len(d0))
    t_out = np.ones(len(d0))
    with np.errstate(divide="ignore", invalid="ignore"):
        for plane, sign in ((camera.near, 1.0), (camera.far, -1.0)):
            s0 = sign * (d0 - plane)  # >= 0 inside
            s1 = sign * (d1 - plane)
            t = s0 / (s0 - s1)
            t_in = np.where((s0 < 0) & (s1 >= 0), np.maximum(t_in, t), t_in)
            t_out = np.where((s0 >= 0) & (s1 < 0), np.minimum(t_out, t), t_out)
            t_in = np.where((s0 < 0) & (s1 < 0), 2.0, t_in)  # both outside: drop
    kept = t_in <= t_out
    span = (t_out - t_in)[kept]
    d = (p1_world - p0_world)[kept]
    margin = np.maximum(
        np.maximum(depth_margin(p0_world[kept], camera, precision), depth_margin(p1_world[kept], camera, precision)),
        slack,
    )
    with np.errstate(divide="ignore", invalid="ignore"):  # depth constant along it: never clipped, never moved
        margin_t = margin / np.abs(d1 - d0)[kept]
    inward = np.clip(margin_t, _INWARD * span, _MAX_INWARD * span)
    a = t_in[kept] + np.where(t_in[kept] > 0, inward, 0.0)
    b = t_out[kept] - np.where(t_out[kept] < 1, inward, 0.0)
    ends = np.stack([p0_world[kept] + a[:, None] * d, p0_world[kept] + b[:, None] * d], axis=1)
    return kept, ends


def draw_candidate(
    func, p_world: np.ndarray, edges: np.ndarray, camera, precision: str = "float64", slack: float = 0.0
) -> np.ndarray:
    """``(H, W)`` bool image of the candidate's wireframe (``precision``: the candidate's, and ``slack``:
    its probed planes' depth offset, for the clipped ends; :func:`clip_depth`)."""
    image = np.zeros((camera.height, camera.width), bool)
    if len(edges) == 0:
        return image
    _, ends = clip_depth(p_world[edges[:, 0]], p_world[edges[:, 1]], camera, precision, slack)
    if len(ends) == 0:
        return image
    px = call_candidate(func, ends.reshape(-1, 3), camera).reshape(-1, 2, 2)
    _, q0, q1 = clip_to_image(px[:, 0], px[:, 1], camera.width, camera.height)
    rr, cc = line_pixels(q0, q1, camera.width, camera.height)
    image[rr, cc] = True
    return image


def oracle_segments(
    p_world: np.ndarray, edges: np.ndarray, camera, p_px: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """``(E, 2)`` twice: each edge's ends in pixels by OpenCV, clipped to [near, far] in depth; NaN if none left.

    The oracle's float64 picture of where each line lies, for attributing
    drawn pixels to edges (:func:`oracles.judge.metrics.line_scores`).
    ``p_px``: ``opencv_oracle.project(p_world, camera)``, when the caller has
    it; an edge whose two ends are both in [near, far] then takes its ends
    from it, and only the edges the depth planes cut are clipped and projected.
    """
    p0 = np.full((len(edges), 2), np.nan)
    p1 = np.full((len(edges), 2), np.nan)
    if len(edges) == 0:
        return p0, p1
    cut = np.ones(len(edges), bool)
    if p_px is not None:
        seen = np.isfinite(p_px).all(axis=1)  # project's NaN rows: depth outside [near, far]
        whole = seen[edges[:, 0]] & seen[edges[:, 1]]
        if whole.all():  # every edge in [near, far]: its ends, gathered
            return (
                np.take(np.asarray(p_px, np.float64), edges[:, 0], axis=0),
                np.take(np.asarray(p_px, np.float64), edges[:, 1], axis=0),
            )
        p0[whole], p1[whole] = p_px[edges[whole, 0]], p_px[edges[whole, 1]]
        cut = ~whole
        if not cut.any():
            return p0, p1
    e = edges[cut]
    kept, ends = clip_depth(p_world[e[:, 0]], p_world[e[:, 1]], camera)
    if len(ends):
        px = opencv_oracle.project(ends.reshape(-1, 3), camera).reshape(-1, 2, 2)
        rows = np.flatnonzero(cut)[kept]
        p0[rows], p1[rows] = px[:, 0], px[:, 1]
    return p0, p1
