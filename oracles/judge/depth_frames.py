"""A renderer's depth maps of a frames job, measured frame by frame inside the case loop.

The case loop (oracles.judge.case_loop, fed by oracles.judge.frames_judge.JobFrames) hands each frame's depth file and the
frame's reference (pyrender's faces, :func:`oracles.judge.depth_reference.from_render`:
linear float64 depth, its per-pixel bound, the undecided pixels) to :meth:`DepthFrames.add`;
the case's fields go into its record (:meth:`DepthFrames.fields`, ``record["depth_map"]``)
and :mod:`oracles.judge.decide` alone decides on them (``Tolerances.max_depth_error_ratio``,
``max_surface_holes_px``, ``max_surface_extra_px``). Per frame:

- the map is read by :func:`oracles.candidates.depth_map.read_depth_map` with the job's
  encoding (a missing file, a wrong size, another encoding, a negative depth: one line,
  FramesError, exit 2);
- its values are judged and named by :func:`oracles.diagnosis.depth_faults.name_depth_faults`
  where both show a surface and the reference's is decided (error / allowance, the
  allowance being the reference's bound plus the encoding's step);
- the surfaces are compared: **holes**, reference surface the map leaves empty, and
  **extra**, surface the map shows where the reference has none, each counted away from
  the reference silhouette's boundary (:func:`oracles.judge.surfaces.surface_mismatch`): a pixel centre on the
  boundary is inside or outside by each renderer's rounding.

A map that shows no surface where the reference shows one (blank, all NaN) fails on its
holes, and compares nothing: never a pass. The faults are the depth diagnosis' names for
the case's failing frames (at most :data:`DIAGNOSED_FRAMES` of them fitted with the
pixel models): the name given to most of them, its numbers those of its first frame.
"""

from __future__ import annotations

from collections import Counter
from pathlib import Path

import numpy as np
from wirecheck.core.errors import InputError

from ..candidates.depth_map import DEFAULT_PNG_SCALE, read_depth_map
from ..candidates.frames_candidate import FramesError
from ..diagnosis.depth_faults import name_depth_faults
from .depth_reference import ReferenceDepth
from .surfaces import surface_mismatch

#: Failing frames of a case whose maps are fitted with the pixel models too (rows flipped, half a pixel, K
#: from the FOV: oracles.diagnosis.depth_pixels, a fit each); the value models are fitted on every one.
DIAGNOSED_FRAMES = 4


class DepthFrames:
    """A case's depth maps, measured one frame at a time (module docstring); nothing kept but numbers."""

    def __init__(self, job: dict):
        enc = job["depth_encoding"]
        self.scale = float(enc["scale"]) if enc.get("scale") else DEFAULT_PNG_SCALE
        self.frames = []  # per-frame numbers
        self.diagnoses = []  # (k, DepthDiagnosis) of the failing frames
        self.encoding = None

    def add(self, k: int, path: Path, camera, ref: ReferenceDepth) -> dict:
        """Frame ``k``'s map at ``path`` against ``ref`` (the frame's reference); its per-frame record."""
        try:
            dm = read_depth_map(path, int(camera.width), int(camera.height), self.scale)
        except InputError as exc:  # the line names the file; every problem of a job is exit 2
            raise FramesError([str(exc)]) from None
        self.encoding = dm.encoding
        shown = np.isfinite(dm.depth)
        holes, extra = surface_mismatch(shown, ref.covered)
        args = (dm.depth, ref.compared_depth(), ref.bound, camera, dm.encoding_bound())
        diag = name_depth_faults(*args)  # the faces are read only to name a failing map: taken then
        if diag.verdict == "fail" and len(self.diagnoses) < DIAGNOSED_FRAMES:
            diag = name_depth_faults(*args, faces=ref.compared_faces())
        m = diag.measured
        rec = {
            "frame": k,
            "verdict": diag.verdict,
            "compared_px": m["compared_px"],
            "union_px": int(np.count_nonzero(shown | ref.covered)),
            "candidate_px": m["candidate_px"],
            "reference_px": int(np.count_nonzero(ref.covered)),
            "holes_px": int(np.count_nonzero(holes)),
            "extra_px": int(np.count_nonzero(extra)),
            "max_error": m.get("max_error"),
            "max_error_ratio": _finite(m.get("max_error_ratio")),
            "worst_pixel": m.get("worst_pixel"),
        }
        if diag.verdict == "fail":
            self.diagnoses.append((k, diag))
        self.frames.append(rec)
        return rec

    def fields(self) -> dict:
        """The case's ``depth_map`` record: sums and the worst frame's numbers (module docstring)."""
        f = self.frames
        worst = max(f, key=lambda r: -1.0 if r["max_error_ratio"] is None else r["max_error_ratio"])
        ratios = [r["max_error_ratio"] for r in f if r["max_error_ratio"] is not None]
        holes = max(f, key=lambda r: r["holes_px"])
        extra = max(f, key=lambda r: r["extra_px"])
        return {
            "frames": len(f),
            "encoding": self.encoding,
            "compared_px": sum(r["compared_px"] for r in f),
            "reference_px": sum(r["reference_px"] for r in f),
            "candidate_px": sum(r["candidate_px"] for r in f),
            "max_error_ratio": max(ratios) if ratios else None,
            "max_error": worst["max_error"] if ratios else None,
            "worst_frame": worst["frame"] if ratios else None,
            "worst_pixel": worst["worst_pixel"] if ratios else None,
            "holes_px": sum(r["holes_px"] for r in f),
            "holes_worst_frame": holes["frame"],
            "extra_px": sum(r["extra_px"] for r in f),
            "extra_worst_frame": extra["frame"],
            "blank_frames": [r["frame"] for r in f if r["candidate_px"] == 0 and r["reference_px"]],
            "per_frame": f,
        }

    def faults(self) -> list[dict]:
        """The depth diagnosis' fault of the case (module docstring), as record dicts with their hint; [] if none."""
        names = Counter(d.names[0] for _k, d in self.diagnoses if d.faults)
        if not names:
            return []
        name = names.most_common(1)[0][0]
        k, diag = next((k, d) for k, d in self.diagnoses if d.faults and d.names[0] == name)
        fault = diag.faults[0]
        return [
            {
                **fault.as_dict(),
                "hint": fault.hint,
                "depth_frames": sum(names.values()),
                "depth_frames_named": names[name],
                "first_frame": k,
            }
        ]


def _finite(value):
    """``value`` as a float, None when nothing was compared; an infinite ratio (an error where the allowance
    is 0) as the largest float: report.json holds no inf, and None would read as nothing compared."""
    if value is None:
        return None
    return float(value) if np.isfinite(value) else float(np.finfo(np.float64).max)
