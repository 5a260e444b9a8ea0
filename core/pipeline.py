"""One frame, top to bottom: model -> camera -> clip -> pixels -> raster.

Each line of :func:`render_frame` names the space it produces (see
core.conventions for the spaces). Model to camera is one camera-relative
model-view transform (core.projection explains why: precision in float32 and
far from the origin); world coordinates are never formed per point.

Only what a frame needs is computed: faces are never touched (a wireframe
uses edges only), there is no depth buffer, and the clipping stage runs only
when some vertex is outside [near, far] or off the image.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import clipping, raster
from .camera import Camera
from .projection import LocalPoints, cam_to_px, depth_mask, localize, model_to_cam, resolve_dtype

CLIP_MODES = ("clip", "endpoint")
RASTER_MODES = ("exact", "fast", "aa")


@dataclass(frozen=True)
class Frame:
    image: np.ndarray          # (H, W) uint8: 255 on line pixels (raster "aa": coverage 0..255)
    p_px: np.ndarray           # (N, 2) float64, NaN where clipped (computed in the run's dtype)
    depth: np.ndarray          # (N,) float64 z_cam of every vertex
    visible: np.ndarray        # (N,) bool: near <= depth <= far
    clipped_edges: int         # edges dropped or shortened by near/far

    @property
    def mask(self) -> np.ndarray:
        """``(H, W) bool``: the drawn pixels (coverage >= 1/2 for raster "aa")."""
        return self.image >= 128

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


def render_frame(p_model, edges: np.ndarray, camera: Camera, model_matrix: np.ndarray,
                 clip_mode: str = "clip", *, dtype=None, raster: str = "exact") -> Frame:
    """Project and draw one wireframe frame.

    ``p_model`` is an ``(N, 3)`` array or, to skip re-centring and casting on
    every frame, the :class:`~core.projection.LocalPoints` of
    :func:`~core.projection.localize`. ``dtype`` ("float64" default, or
    "float32") is the precision of every per-point operation; with
    ``LocalPoints`` it defaults to theirs. ``raster`` is one of
    :data:`RASTER_MODES` (core.raster).
    """
    if clip_mode not in CLIP_MODES:
        raise ValueError(f"clip_mode {clip_mode!r}: expected one of {CLIP_MODES}")
    if raster not in RASTER_MODES:
        raise ValueError(f"raster {raster!r}: expected one of {RASTER_MODES}")
    if isinstance(p_model, LocalPoints):
        points = p_model
        if dtype is not None and resolve_dtype(dtype) != points.dtype:
            raise ValueError(f"dtype {dtype!r} differs from the LocalPoints' {points.dtype}")
    else:
        points = localize(p_model, "float64" if dtype is None else dtype)
    n = len(points)
    edges = np.asarray(edges).reshape(-1, 2)
    p_cam = model_to_cam(points, model_matrix, camera)              # camera (model-view, camera-relative)
    visible = depth_mask(p_cam, camera)                             # near <= z <= far
    p_px = np.full((n, 2), np.nan, dtype=p_cam.dtype)
    if visible.any():
        p_px[visible] = cam_to_px(p_cam[visible], camera)          # pixels
    ends_visible = visible[edges[:, 0]] & visible[edges[:, 1]] if len(edges) else np.zeros(0, bool)
    # Depth is affine along an edge, so near/far leave an edge whole exactly when
    # both ends are in [near, far]: every other edge is cut or dropped by them.
    clipped_edges = int(len(edges) - ends_visible.sum())

    image = np.zeros((camera.height, camera.width), dtype=np.uint8)
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
            planes = clipping.frustum_planes(camera).astype(p_cam.dtype)
            kept, t0, t1 = clipping.clip_segments(seg_cam, planes)
            seg_cam = clipping.apply_clip(seg_cam, kept, t0, t1,
                                          (camera.near, camera.far))  # camera, inside the frustum
            seg_px = cam_to_px(seg_cam.reshape(-1, 3), camera).reshape(-1, 2, 2)  # pixels
            _, seg0_px, seg1_px = clipping.clip_to_image(seg_px[:, 0], seg_px[:, 1],
                                                         camera.width, camera.height)  # pixels, on the image
        _paint(image, seg0_px, seg1_px, raster)                     # painted
    return Frame(image=image, p_px=p_px.astype(np.float64, copy=False),
                 depth=p_cam[:, 2].astype(np.float64), visible=visible, clipped_edges=clipped_edges)


def _paint(image: np.ndarray, seg0_px: np.ndarray, seg1_px: np.ndarray, mode: str) -> None:
    h, w = image.shape
    if mode == "exact":
        rr, cc = raster.line_pixels(seg0_px, seg1_px, w, h)
        image[rr, cc] = 255
    elif mode == "fast":
        rr, cc = raster.line_pixels_fast(seg0_px, seg1_px, w, h)
        image[rr, cc] = 255
    else:
        rr, cc, weight = raster.line_coverage_aa(seg0_px, seg1_px, w, h)
        image[...] = raster.paint_aa(rr, cc, weight, w, h)


def _inside_image(p_px: np.ndarray, camera: Camera) -> np.ndarray:
    x, y = p_px[:, 0], p_px[:, 1]
    return (x >= -0.5) & (x <= camera.width - 0.5) & (y >= -0.5) & (y <= camera.height - 0.5)
