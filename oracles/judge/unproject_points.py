"""What an unprojector is given and what it must give back: visible surface points of a scene frame.

Core draws the frame's faces into its depth buffer (core.projector.zbuffer, depth along
``forward`` at pixel centres) under the case's camera without its lens; every covered pixel
centre on a grid of ``stride`` pixels (rows and columns ``stride // 2 + i stride``) is a
sample: its pixel ``(x, y)``, its depth ``d``, and the world point ``X`` the exact inverse
gives (oracles.references.unproject_reference, independent of core). A camera with lens
distortion is given ``X``'s distorted pixel (OpenCV's ``projectPoints``) instead, so the
expected answer stays ``X`` exactly. Core only picks which points are visible; what is
expected of them is the reference's.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from wirecheck.core.scene.frames import SceneRenderer
from wirecheck.core.scene.model import Scene
from wirecheck.core.transforms import Motion

from ..cases import Case, case_motion
from ..references.opencv_oracle import project as cv_project
from ..references.unproject_reference import unproject

__all__ = ["DEFAULT_STRIDE", "Samples", "surface_samples"]

#: One sample every 8 pixels each way: ~600 points on a 640x480 frame the scene half fills.
DEFAULT_STRIDE = 8


@dataclass(frozen=True)
class Samples:
    """``p_px`` (N, 2) pixels given, ``depth`` (N,) along forward given, ``p_world`` (N, 3) expected."""

    p_px: np.ndarray
    depth: np.ndarray
    p_world: np.ndarray

    def __len__(self) -> int:
        return len(self.depth)


def surface_samples(
    scene: Scene,
    case: Case,
    motion: Motion,
    k: int,
    frames: int,
    stride: int = DEFAULT_STRIDE,
    renderer: SceneRenderer | None = None,
) -> Samples:
    """The samples of frame ``k`` (1-based, of ``frames``) of ``scene`` through ``case``'s camera (module docstring).

    ``renderer``: a ``SceneRenderer(scene, case_motion(motion, case), frames, style="shaded")`` to reuse.
    """
    cam = case.camera
    pinhole = cam.with_distortion(None) if getattr(cam, "distortion", None) is not None else cam
    if renderer is None:
        renderer = SceneRenderer(scene, case_motion(motion, case), frames, style="shaded")
    frame, _ = renderer.render(k, pinhole)
    depth = frame.depth_image
    if depth is None:  # a wireframe: no surface to sample
        return Samples(np.zeros((0, 2)), np.zeros(0), np.zeros((0, 3)))
    start = stride // 2
    rows, cols = np.mgrid[start : cam.height : stride, start : cam.width : stride]
    d = depth[rows, cols]
    on = np.isfinite(d)
    p_px = np.column_stack([cols[on], rows[on]]).astype(np.float64)
    d = d[on].astype(np.float64)
    p_world = unproject(p_px, d, pinhole)
    if pinhole is not cam:
        p_px = cv_project(p_world, cam)
    return Samples(p_px, d, p_world)
