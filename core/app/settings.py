"""What one ``renderer`` run is asked to do: :class:`Settings` (the options, validated by core.app.cli).

Its own module because both the run (core.app.run) and its report (core.app.report) read it.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ..camera import Camera
from ..scene.frames import SceneRenderer
from ..scene.model import Scene
from ..transforms import Motion
from .compose import axis_layers, axis_length


@dataclass
class Settings:
    """One renderer run (``renderer``'s options, validated)."""

    scene: Scene
    camera: Camera
    motion: Motion
    frames: int
    clip: str
    formats: tuple[str, ...]
    out: Path
    ascii_cols: int
    dtype: str = "float64"
    raster: str = "exact"
    ortho_camera: Camera | None = None  # --projection both: the right-hand camera
    axes: bool = False
    cull: str | None = None  # None or "backface"
    hidden_lines: bool = False
    style: str = "wireframe"
    light: tuple | None = None
    object_culling: bool = True
    plots: bool = False

    @property
    def cameras(self) -> tuple[Camera, ...]:
        return (self.camera,) if self.ortho_camera is None else (self.camera, self.ortho_camera)

    @property
    def uses_faces(self) -> bool:
        return self.cull is not None or self.hidden_lines or self.style != "wireframe"

    def axis_layers(self, camera: Camera, frame=None) -> list:
        """:func:`core.app.compose.axis_layers` of this run (``frame``: depth-tested against its faces)."""
        return axis_layers(
            axis_length(self.scene.radius, self.motion.scale), camera, self.clip, self.dtype, self.raster, frame
        )

    def scene_renderer(self) -> SceneRenderer:
        return SceneRenderer(
            self.scene,
            self.motion,
            self.frames,
            clip=self.clip,
            dtype=self.dtype,
            raster=self.raster,
            cull=self.cull,
            hidden_lines=self.hidden_lines,
            style=self.style,
            light=self.light,
            object_culling=self.object_culling,
        )
