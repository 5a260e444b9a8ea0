"""One frame, top to bottom: model -> world -> camera -> clip -> pixels -> raster.

Each line of :func:`render_frame` names the space it produces (see
core.conventions for the spaces).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import clipping, raster
from .camera import Camera
from .projection import cam_to_px, depth_mask
from .transforms import apply

CLIP_MODES = ("clip", "endpoint")


@dataclass(frozen=True)
class Frame:
    image: np.ndarray          # (H, W) uint8, 255 on line pixels
    p_px: np.ndarray           # (N, 2) float64, NaN where clipped
    depth: np.ndarray          # (N,) z_cam of every vertex
    visible: np.ndarray        # (N,) bool: near <= depth <= far
    clipped_edges: int         # edges dropped or shortened by near/far

    @property
    def visible_vertices(self) -> int:
        return int(self.visible.sum())

    @property
    def clipped_vertices(self) -> int:
        return int(len(self.visible) - self.visible.sum())

    @property
    def depth_range(self) -> tuple[float, float] | None:
        """(min, max) depth of the visible vertices, None when there are none."""
        if not self.visible.any():
            return None
        d = self.depth[self.visible]
        return float(d.min()), float(d.max())


def render_frame(p_model: np.ndarray, edges: np.ndarray, camera: Camera,
                 model_matrix: np.ndarray, clip_mode: str = "clip") -> Frame:
    """Project and draw one wireframe frame."""
    if clip_mode not in CLIP_MODES:
        raise ValueError(f"clip_mode {clip_mode!r}: expected one of {CLIP_MODES}")
    n = len(p_model)
    image = np.zeros((camera.height, camera.width), dtype=np.uint8)
    p_world = apply(model_matrix, p_model)                          # world
    p_cam = apply(camera.world_to_cam, p_world)                     # camera
    visible = depth_mask(p_cam, camera)                             # near <= z <= far
    p_px = np.full((n, 2), np.nan)
    if visible.any():
        p_px[visible] = cam_to_px(p_cam[visible], camera)          # pixels
    ends_visible = visible[edges[:, 0]] & visible[edges[:, 1]] if len(edges) else np.zeros(0, bool)
    # Depth is affine along an edge, so near/far leave an edge whole exactly when
    # both ends are in [near, far]: every other edge is cut or dropped by them.
    clipped_edges = int(len(edges) - ends_visible.sum())

    if len(edges):
        on_image = _inside_image(p_px, camera)
        if visible.all() and on_image.all():
            # Fast path, the common case: nothing to clip. Reuse vertex pixels.
            # (np.take gathers rows of an (N, 2) array ~10x faster than p_px[idx].)
            seg0_px = np.take(p_px, edges[:, 0], axis=0)
            seg1_px = np.take(p_px, edges[:, 1], axis=0)
        else:
            if clip_mode == "endpoint":
                edges = edges[ends_visible]                         # drop edges with a failing end
            seg_cam = p_cam[edges]                                  # camera, (E, 2, 3)
            planes = clipping.frustum_planes(camera)
            kept, t0, t1 = clipping.clip_segments(seg_cam, planes)
            seg_cam = clipping.apply_clip(seg_cam, kept, t0, t1,
                                          (camera.near, camera.far))  # camera, inside the frustum
            seg_px = cam_to_px(seg_cam.reshape(-1, 3), camera).reshape(-1, 2, 2)  # pixels
            _, seg0_px, seg1_px = clipping.clip_to_image(seg_px[:, 0], seg_px[:, 1],
                                                         camera.width, camera.height)  # pixels, on the image
        rr, cc = raster.line_pixels(seg0_px, seg1_px, camera.width, camera.height)
        image[rr, cc] = 255                                         # painted
    return Frame(image=image, p_px=p_px, depth=p_cam[:, 2], visible=visible,
                 clipped_edges=clipped_edges)


def _inside_image(p_px: np.ndarray, camera: Camera) -> np.ndarray:
    x, y = p_px[:, 0], p_px[:, 1]
    return (x >= -0.5) & (x <= camera.width - 0.5) & (y >= -0.5) & (y <= camera.height - 0.5)
