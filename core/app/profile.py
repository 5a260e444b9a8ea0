"""Per-stage frame timing: ``renderer --profile`` and the interactive viewer's profiler.

A frame's time is split into stages timed as consecutive laps: the pipeline's
own (:data:`core.projector.pipeline.STAGES`, filled by ``render_frame(timing=...)``),
then what the caller does with the frame (:data:`OUTPUT_STAGES`: composing the
axes and pictures, encoding, writing; the viewer adds ``transfer``). The frame
total is clocked separately around all of it, so ``other = total - sum(stages)``
is what no stage claimed (scene set-up per frame, bookkeeping) and shows when a
stage is missing.

Timings vary run to run; they live in their own report field (``profile``) and
never change a frame or another field.
"""

from __future__ import annotations

import time
from collections import deque

import numpy as np

from ..projector.pipeline import STAGES as PIPELINE_STAGES

#: After the pipeline: compose (axes overlay, side-by-side pictures, the
#: diagnostics record), encode (PNG/ASCII/GIF/MP4 bytes), write (files).
OUTPUT_STAGES = ("compose", "encode", "write")
#: Every stage of ``renderer --profile``, in order.
STAGES = PIPELINE_STAGES + OUTPUT_STAGES


class FrameProfiler:
    """Collects per-stage seconds frame by frame; keeps the last ``window`` frames.

    Use::

        prof.begin()                       # starts the frame's total clock
        render_frame(..., timing=prof.current)
        t = prof.lap("compose", t0)        # or prof.add("encode", seconds)
        prof.end()                         # the frame's total

    ``window=None`` keeps every frame (``renderer --profile``).
    """

    def __init__(self, stages=STAGES, window: int | None = None):
        self.stages = tuple(stages)
        self.frames: deque = deque(maxlen=window)
        self.current: dict = {}
        self._t0 = 0.0

    def begin(self) -> float:
        self.current = {}
        self._t0 = time.perf_counter()
        return self._t0

    def lap(self, stage: str, t0: float) -> float:
        """Add ``now - t0`` to ``stage``; return now (the next lap's start)."""
        t = time.perf_counter()
        self.add(stage, t - t0)
        return t

    def add(self, stage: str, seconds: float) -> None:
        if stage not in self.stages:
            raise ValueError(f"stage {stage!r}: expected one of {', '.join(self.stages)}")
        self.current[stage] = self.current.get(stage, 0.0) + seconds

    def end(self, total: float | None = None) -> dict:
        """Close the frame (``total`` seconds, default: since :meth:`begin`); return its record in ms."""
        if total is None:
            total = time.perf_counter() - self._t0
        rec = {s: 1e3 * self.current.get(s, 0.0) for s in self.stages}
        rec["other"] = 1e3 * total - sum(rec.values())
        rec["total"] = 1e3 * total
        self.frames.append(rec)
        self.current = {}
        return rec

    def summary(self) -> dict:
        """``{"frames", "fps", "stages": {name: {"mean_ms", "p50_ms", "p95_ms", "share"}}}``.

        ``share`` is the stage's part of the summed frame totals; ``fps`` is
        1000 / mean total (frames per second this loop would sustain).
        """
        n = len(self.frames)
        out = {"frames": n, "fps": None, "stages": {}}
        if n == 0:
            return out
        keys = self.stages + ("other", "total")
        table = np.array([[f[k] for k in keys] for f in self.frames])  # (n, stages + 2) ms
        sum_total = float(table[:, -1].sum())
        for j, key in enumerate(keys):
            col = table[:, j]
            out["stages"][key] = {
                "mean_ms": float(col.mean()),
                "p50_ms": float(np.percentile(col, 50)),
                "p95_ms": float(np.percentile(col, 95)),
                "share": float(col.sum() / sum_total) if sum_total > 0 else None,
            }
        mean_total = out["stages"]["total"]["mean_ms"]
        out["fps"] = 1e3 / mean_total if mean_total > 0 else None
        return out


def profile_table(summary: dict) -> str:
    """The summary as a text table: one row per stage, then other and total."""
    lines = [
        f"Profile: {summary['frames']} frames" + (f", {summary['fps']:.1f} frames/s" if summary["fps"] else ""),
        f"{'stage':<10} {'mean ms':>9} {'p50 ms':>9} {'p95 ms':>9} {'share':>7}",
    ]
    for name, st in summary["stages"].items():
        share = "-" if st["share"] is None else f"{100 * st['share']:.1f}%"
        lines.append(f"{name:<10} {st['mean_ms']:>9.3f} {st['p50_ms']:>9.3f} {st['p95_ms']:>9.3f} {share:>7}")
    return "\n".join(lines) + "\n"
