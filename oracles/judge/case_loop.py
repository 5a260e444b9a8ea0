"""One case loop for every frame source: each frame of a case fed to the measurements the case asks for.

A frame source gives a case's frames in order: a projector's or core's
(oracles.judge.case.ProjectorFrames: the candidate called on the frame's points, its frame
drawn by core or by the harness, pyrender drawing on request) and a renderer's job
(oracles.judge.frames_judge.JobFrames: the frame's files and pyrender's drawing read ahead,
oracles.candidates.frame_prefetch). Each frame (:class:`SourceFrame`) has a number and gives,
for each kind of frame the case measures, the candidate's drawing and the oracle's:

============  ==================================================  ==========================================
kind          measurement                                         the frame gives
============  ==================================================  ==========================================
vertices      oracles.judge.case.CaseFrames.add_vertices          ``vertices()``: the candidate's and
                                                                  OpenCV's pixels of the frame's points
wireframe     oracles.judge.wire_frames.WireFrames.add            ``wireframe(record)``: the drawn pixels
                                                                  against pyrender's, the oracle's segments
shaded        oracles.judge.shaded_frames.ShadedFrames.add        ``shaded()``: the depth buffer, pyrender's
                                                                  faces
depth map     oracles.judge.depth_frames.DepthFrames.add          ``depth_map()``: the file, its reference
filled        oracles.judge.filled_frames.FilledFrames.add        ``filled()``: the file, the fill rule's
                                                                  inputs
============  ==================================================  ==========================================

A new kind of frame is a measurement here and a method of the sources that have it, not a
harness. The frame's record (``{"frame": k}``, then each measurement's per-frame fields) joins
the case's ``per_frame`` when the case measures vertices, wireframes or shaded frames; depth maps
and filled frames keep their per-frame numbers in their own fields. A source that fails at a
frame (a candidate's error) stops giving frames; the case keeps what the frames before it measured.
"""

from __future__ import annotations

import time
from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Any, Protocol


class SourceFrame(Protocol):
    """One frame of a case as its source gives it (module docstring); a method is called only where the
    case measures that kind."""

    number: int

    def vertices(self) -> tuple: ...

    def wireframe(self, frame_rec: dict) -> tuple: ...

    def shaded(self) -> tuple: ...

    def depth_map(self) -> tuple: ...

    def filled(self) -> dict: ...

    def spent(self, kind: str, seconds: float) -> None:
        """The seconds a measurement of ``kind`` took on this frame (the source's timing)."""


@dataclass
class Measurements:
    """The measurements a case asks for, each None where it does not; what the frames' records gathered."""

    vertices: Any = None
    wire: Any = None
    shaded: Any = None
    depth: Any = None
    filled: Any = None
    per_frame: list = field(default_factory=list)
    surface_px: int = 0  # pixels either side shows in the depth maps and filled frames (oracles.judge.gate)

    @property
    def drawn_px(self) -> int:
        """Pixels drawn by either side over the case's frames, of every kind."""
        wire = self.wire.drawn_px if self.wire is not None else 0
        shaded = self.shaded.drawn_px if self.shaded is not None else 0
        return wire + shaded + self.surface_px


def measure_frames(frames: Iterable[SourceFrame], m: Measurements) -> None:
    """Each frame of ``frames`` measured by each of ``m``'s measurements, in the table's order."""
    recorded = m.vertices is not None or m.wire is not None or m.shaded is not None
    for frame in frames:
        k = frame.number
        frame_rec = {"frame": k}
        if recorded:
            m.per_frame.append(frame_rec)
        if m.vertices is not None:
            vertex_inputs = frame.vertices()
            t = time.perf_counter()
            m.vertices.add_vertices(k, *vertex_inputs, frame_rec)
            frame.spent("vertices", time.perf_counter() - t)
        if m.wire is not None:
            wire_inputs = frame.wireframe(frame_rec)
            t = time.perf_counter()
            m.wire.add(k, *wire_inputs, frame_rec)
            frame.spent("wireframe", time.perf_counter() - t)
        if m.shaded is not None:
            shaded_inputs = frame.shaded()
            t = time.perf_counter()
            m.shaded.add(k, *shaded_inputs, frame_rec)
            frame.spent("shaded", time.perf_counter() - t)
        if m.depth is not None:
            m.surface_px += m.depth.add(k, *frame.depth_map())["union_px"]
        if m.filled is not None:
            m.surface_px += m.filled.add(k, **frame.filled())["union_px"]
