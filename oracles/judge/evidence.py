"""What a case measured, frozen: the one input of the verdict (:func:`oracles.judge.decide.decide`) and of the
names (:func:`oracles.judge.name_faults.name_faults`).

Each path collects its measurements into a :class:`CaseEvidence` once its frames are scored; nothing edits
it afterwards (assignment raises ``FrozenInstanceError``; its mappings are read-only views). A renderer's
frames add the style read of their lines (:class:`StyleRead`, oracles.judge.line_style.CaseStyle.read) and,
where the images fit the oracle's lines but the case fails, the visible sets that differ (:class:`Visibility`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any

from ..faults import Fault

__all__ = ["StyleRead", "Radius", "Visibility", "CaseEvidence", "frozen_map"]


def frozen_map(values: Mapping | None) -> Mapping | None:
    """A read-only view of a copy of ``values`` (None stays None)."""
    return None if values is None else MappingProxyType(dict(values))


@dataclass(frozen=True)
class StyleRead:
    """A renderer's lines read from its frames (oracles.judge.line_style): what they are, where they are.

    ``line_rule``: the run's ``--line-rule``; ``read``: the classification (``style``, ``width_px``,
    ``grey_share``, ``level``, ``coverage_steps``, ``band_px``, ``pixel_ratio``); ``geometry``: the
    centres' pooled offset, warp and free ends (CaseStyle.geometry); ``raster``: the differing pixels
    counted by where they lie; ``rounded``: the pixels against a correct drawing by the rounded-ends rule
    (``pixel_f1_0px``, ``lines``; None when not drawn); ``rounded_faults``: the line fault those lines name
    (oracles.diagnosis.diagnose.diagnose_lines); ``placed``: the centres were measured on lines that lie
    where the oracle's do (enough of them found, no mirror or swap named from the images); ``job``: the
    read of the renderer pooled over the job's cases, where it is imposed on this case
    (oracles.judge.job_read.JobRead.as_dict; None: the case's own read alone).
    """

    line_rule: str
    read: Mapping[str, Any]
    geometry: Mapping[str, Any]
    raster: Mapping[str, int]
    rounded: Mapping[str, Any] | None
    rounded_faults: tuple[Fault, ...]
    placed: bool
    job: Mapping[str, Any] | None = None

    def __post_init__(self):
        for name in ("read", "geometry", "raster", "rounded", "job"):
            object.__setattr__(self, name, frozen_map(getattr(self, name)))

    @property
    def style(self) -> str:
        return self.read["style"]

    @property
    def by_rule(self) -> bool:
        """Whether a pixel rule can hold the lines: aliased lines under ``--line-rule gl`` or ``any``."""
        return self.style == "aliased" and self.line_rule in ("gl", "any")

    @property
    def offset_px(self) -> tuple[float, float]:
        """The pooled centre offset ``(dx, dy)`` (px) where the centres were measured, else (0, 0)."""
        if not self.placed:
            return (0.0, 0.0)
        dx, dy = self.geometry["offset_px"]
        return (float(dx), float(dy))

    @property
    def raster_shares(self) -> dict:
        """The differing pixels off by one across the line, at the ends, and farther, as shares of the oracle's
        pixels (aliased lines that differ; else empty)."""
        rs = self.raster
        if self.style != "aliased" or not rs["differing"]:
            return {}
        n = max(rs["oracle_pixels"], 1)
        return {
            "share_off_by_one_across": rs["off_by_one_across"] / n,
            "share_off_by_one_at_ends": rs["off_by_one_at_ends"] / n,
            "share_farther": rs["farther"] / n,
        }


@dataclass(frozen=True)
class Radius:
    """The F1 radius the lines' width allows (oracles.judge.f1_radius) and the worst frame's F1 there."""

    radius_px: int
    f1: float
    frame: Any


@dataclass(frozen=True)
class Visibility:
    """Pixels on one side only over the diagnosed frames (oracles.diagnosis.image_visibility.set_difference):
    ``candidate_only_px``, ``oracle_only_px``, over ``frames_diagnosed`` of the case's ``frames_checked``."""

    candidate_only_px: int
    oracle_only_px: int
    frames_diagnosed: int
    frames_checked: int


@dataclass(frozen=True)
class CaseEvidence:
    """One case's measurements (module docstring).

    ``level``: what the case compared (oracles.judge.gate: ``"vertices"``, ``"pixels"``, ``"frames"``);
    ``compared``: frames, vertices, pixels; ``frames_checked``: the frames judged (0: no vertex is judged); ``pixels``: the pixel fields (oracles.judge.decide.pixel_fields:
    ``pixel_f1_0px``... ``worst_pixel_frame``; None: no pixel compared); ``lines``: the pooled line
    fields against GL's rule (oracles.judge.metrics.line_summary; None without lines); ``radius``: the F1
    radius (None: 1 px, F1@1px); ``vertices``: the vertex fields (``max_vertex_error_px``,
    ``vertex_bound_px``, ``worst_vertex``, ``precision``, ``visibility_mismatch``; None: no vertex
    compared); ``shaded``: the shaded fields (None: a wireframe); ``image_faults``: the faults the
    diagnosis named from the vertices or the images; ``line_faults``: those GL's line counts name;
    ``style``: the style read (a renderer's frames); ``drew_pixels``: some frame drew a pixel by the 128
    rule; ``visibility``: the sets that differ (measured only where the names ask for it); ``error``:
    the candidate's error; ``points``: the scene's vertex count; ``oracle_bound_px``: the pyrender oracle's own
    error bound where pixels were drawn (oracles.references.oracle_precision); ``depth_map``, ``filled``: a
    renderer's depth maps' and filled frames' fields (oracles.judge.depth_frames, filled_frames; None: the job
    asks for none); ``depth_faults``: what its failing depth maps' values name (oracles.diagnosis.depth_faults);
    ``filled_faults``: the camera mistake its failing filled frames' silhouettes show
    (oracles.diagnosis.silhouette_faults).
    """

    level: str
    compared: Mapping[str, Any]
    frames_checked: int
    pixels: Mapping[str, Any] | None = None
    lines: Mapping[str, Any] | None = None
    radius: Radius | None = None
    vertices: Mapping[str, Any] | None = None
    shaded: Mapping[str, Any] | None = None
    image_faults: tuple[Fault, ...] = ()
    line_faults: tuple[Fault, ...] = ()
    style: StyleRead | None = None
    drew_pixels: bool = True
    visibility: Visibility | None = None
    error: str | None = None
    points: int | None = None
    oracle_bound_px: float | None = None
    depth_map: Mapping[str, Any] | None = None
    filled: Mapping[str, Any] | None = None
    depth_faults: tuple[Fault, ...] = ()
    filled_faults: tuple[Fault, ...] = ()

    def __post_init__(self):
        for name in ("compared", "pixels", "lines", "vertices", "shaded", "depth_map", "filled"):
            object.__setattr__(self, name, frozen_map(getattr(self, name)))
        object.__setattr__(self, "image_faults", tuple(self.image_faults))
        object.__setattr__(self, "line_faults", tuple(self.line_faults))
        object.__setattr__(self, "depth_faults", tuple(self.depth_faults))
        object.__setattr__(self, "filled_faults", tuple(self.filled_faults))

    @property
    def diagnosed(self) -> tuple[Fault, ...]:
        """What the diagnosis named: the faults read from the vertices or images, else GL's line faults."""
        return self.image_faults or self.line_faults
