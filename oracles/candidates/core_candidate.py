"""core as a candidate: :class:`CoreCandidate`, and the drawing modes it is judged in (:class:`RenderMode`).

Any other candidate is a function of the contract in oracles.candidates.candidate, judged
on its vertices and on its frames drawn by oracles.candidates.draw. core is judged
through its own pipeline instead, set up as ``renderer`` sets it up
(core.scene.frames.SceneRenderer), so the frames judged are the frames it draws.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from wirecheck.core.projector import pipeline
from wirecheck.core.projector.clipping import CLIP_MODES
from wirecheck.core.projector.culling import CULL_CHOICES
from wirecheck.core.projector.projection import DTYPES, localize, project_points
from wirecheck.core.projector.raster import RASTER_MODES
from wirecheck.core.projector.shading import STYLES
from wirecheck.core.scene.frames import SceneRenderer

#: A frame of core's pipeline is greyscale with raster "aa": a pixel is drawn from half intensity up.
DRAWN_THRESHOLD = 128


@dataclass(frozen=True)
class RenderMode:
    """What the pixel stage draws: the style, hidden lines and back-face culling (core candidate only)."""

    style: str = "wireframe"
    hidden_lines: bool = False
    cull: str = "none"

    STYLES: ClassVar[tuple] = STYLES  # core's own lists
    CULLS: ClassVar[tuple] = CULL_CHOICES

    def __post_init__(self):
        for name, allowed in (("style", self.STYLES), ("cull", self.CULLS)):
            if getattr(self, name) not in allowed:
                raise ValueError(f"{name} {getattr(self, name)!r}: expected one of {', '.join(allowed)}")
        if self.style == "shaded" and self.hidden_lines:
            raise ValueError("hidden_lines: a shaded frame has no lines (hidden lines are for style wireframe)")

    @property
    def plain(self) -> bool:
        """A plain wireframe: faces play no part."""
        return self.style == "wireframe" and not self.hidden_lines and self.cull == "none"

    @property
    def shaded(self) -> bool:
        return self.style == "shaded"

    def to_dict(self) -> dict:
        return {"style": self.style, "hidden_lines": self.hidden_lines, "cull": self.cull}

    def core_kwargs(self) -> dict:
        """Keywords of :func:`core.projector.pipeline.render_frame`."""
        return {
            "style": self.style,
            "hidden_lines": self.hidden_lines,
            "cull": None if self.cull == "none" else self.cull,
        }


@dataclass(frozen=True)
class CoreCandidate:
    """core/ as the candidate: vertices (and frames) through core's whole pipeline.

    ``dtype``, ``clip`` and ``raster`` are passed to :func:`core.projector.pipeline.render_frame`
    (``clip`` as its ``clip_mode``).
    """

    dtype: str = "float64"
    clip: str = "clip"
    raster: str = "exact"

    name: ClassVar[str] = "core"
    DTYPES: ClassVar[tuple] = DTYPES  # core's own lists, so the two cannot drift apart
    CLIPS: ClassVar[tuple] = CLIP_MODES
    RASTERS: ClassVar[tuple] = RASTER_MODES

    def __post_init__(self):
        for name, allowed in (("dtype", self.DTYPES), ("clip", self.CLIPS), ("raster", self.RASTERS)):
            if getattr(self, name) not in allowed:
                raise ValueError(f"{name} {getattr(self, name)!r}: expected one of {', '.join(allowed)}")

    def settings(self) -> dict:
        return {"dtype": self.dtype, "clip": self.clip, "raster": self.raster}

    def __call__(self, points, camera):  # the candidate contract, for completeness
        return project_points(points, camera, dtype=self.dtype)

    def prepare(self, p_model: np.ndarray):
        """Points re-centred and cast once (``core.projector.projection.localize``), as ``renderer`` does."""
        return localize(p_model, self.dtype)

    def scene_frames(self, scene, motion, frames: int):
        """core's scene-level renderer (:class:`core.scene.frames.SceneRenderer`) in this candidate's settings.

        Its :meth:`~core.scene.frames.SceneRenderer.geometry` gives each frame's points
        and model matrix, and its ``faces`` the faces as core draws them, as
        ``renderer`` sets them up.
        """
        return SceneRenderer(
            scene, motion, frames, clip=self.clip, dtype=self.dtype, raster=self.raster, object_culling=False
        )

    def project(self, points, camera, model_matrix: np.ndarray) -> np.ndarray:
        """Vertex pixels from core's pipeline without drawing: ``render_frame`` given no edges."""
        no_edges = np.zeros((0, 2), dtype=np.intp)
        return pipeline.render_frame(points, no_edges, camera, model_matrix, self.clip, raster=self.raster).p_px

    def draw(self, points, edges: np.ndarray, camera, model_matrix: np.ndarray) -> np.ndarray:
        """The frame core draws, as a bool image (drawn where the image is >= 128)."""
        frame = pipeline.render_frame(points, edges, camera, model_matrix, self.clip, raster=self.raster)
        return frame.image >= DRAWN_THRESHOLD

    def render(self, points, edges: np.ndarray, camera, model_matrix: np.ndarray, faces, mode: RenderMode):
        """core's :class:`~core.projector.pipeline.Frame` in a drawing mode (faces None: the scene has none)."""
        return pipeline.render_frame(
            points, edges, camera, model_matrix, self.clip, raster=self.raster, faces=faces, **mode.core_kwargs()
        )

    def draw_mode(
        self, points, edges: np.ndarray, camera, model_matrix: np.ndarray, faces, mode: RenderMode
    ) -> np.ndarray:
        """The frame core draws with hidden lines and/or culling, as a bool image."""
        return self.render(points, edges, camera, model_matrix, faces, mode).image >= DRAWN_THRESHOLD

    def shade(self, points, edges: np.ndarray, camera, model_matrix: np.ndarray, faces, mode: RenderMode) -> np.ndarray:
        """core's depth buffer of a shaded frame: ``(H, W)`` linear camera depth, +inf where empty.

        The polygon shown at each pixel (-1: none) is kept in ``self.last_face_ids``.
        """
        frame = self.render(points, edges, camera, model_matrix, faces, mode)
        if frame.depth_image is None:
            object.__setattr__(self, "last_face_ids", None)
            return np.full((camera.height, camera.width), np.inf)
        object.__setattr__(self, "last_face_ids", frame.face_ids)
        return np.asarray(frame.depth_image, dtype=np.float64)
