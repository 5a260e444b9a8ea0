"""A case's record (its entry in report.json's ``cases``): what every source's record ends with.

Each source writes its measured fields first (a projector's: oracles.judge.verdict.case_record; a
renderer's frames: oracles.judge.frames_judge.case_record), its wireframes' alike (:func:`wire_fields`),
with a ``faults`` slot where its report shows them; :func:`finish_record` then writes what the case's evidence, verdict and names say, the same way for
both: the faults named (oracles.judge.name_faults), the verdict and its reasons (oracles.judge.decide), the
oracle's own precision where pyrender's bound was measured, and the per-frame numbers last.
"""

from __future__ import annotations

from ..diagnosis.diagnose import diagnose_lines
from ..faults import Fault
from .evidence import CaseEvidence


def wire_fields(wire, tol) -> tuple[dict, dict, tuple]:
    """A case's wireframe fields, measured and written the same way for every source: ``(pixels, lines,
    line_faults)`` from its oracles.judge.wire_frames.WireFrames (after its flush): the pixel fields (minima,
    means, the worst frame), the line fields pooled over the frames, and the faults those line fields name
    (oracles.diagnosis.diagnose.diagnose_lines, as Faults). The record takes ``pixels`` and ``lines`` as they
    are; the evidence takes them with ``line_faults``."""
    lines = wire.line_fields()
    return wire.pixel_fields(), lines, tuple(Fault.of(f) for f in diagnose_lines(lines, tol))


def finish_record(
    rec: dict, ev: CaseEvidence, verdict, names: tuple, per_frame: list, oracle_limit_px: float | None = None
) -> dict:
    """``rec`` given its ``faults`` (``names`` as report.json holds them: oracles.faults.Fault.as_dict), then
    ``verdict`` and ``reasons``; ``oracle_bound_px`` and ``oracle_limit_px`` where the evidence has the
    pyrender oracle's own bound (``oracle_limit_px``: the run's Tolerances.oracle_limit_px), ``oracle_precision``
    where the verdict set the pixels aside past it; then ``per_frame``. Returns ``rec``."""
    rec["faults"] = [f.as_dict() for f in names]
    rec["verdict"], rec["reasons"] = verdict.verdict, list(verdict.reasons)
    if ev.oracle_bound_px is not None:
        rec["oracle_bound_px"] = float(ev.oracle_bound_px)
        rec["oracle_limit_px"] = oracle_limit_px
    if verdict.set_aside is not None:
        rec["oracle_precision"] = True
    rec["per_frame"] = per_frame
    return rec
