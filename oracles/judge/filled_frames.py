"""A renderer's filled frames of a frames job, measured frame by frame inside the frames judge's case loop.

:func:`oracles.judge.frames_judge.judge_case` hands each frame's filled PNG and pyrender's
coverage of the frame's faces (its pixel centres inside a triangle, as GL fills them) to
:meth:`FilledFrames.add`; the case's fields go into its record (:meth:`FilledFrames.fields`,
``record["filled"]``) and :mod:`oracles.judge.decide` alone decides on them. Per frame:

- the PNG is read as every frame of the job is (:func:`oracles.candidates.frames_candidate.read_frame`:
  grey levels, luminance x alpha / 255); a pixel is filled when its level is 1 or more (any
  colour but black: object ids 1, 2, ... as grey levels are filled);
- the silhouette IoU against pyrender's, decided as ``--style shaded``'s (``Tolerances.min_iou``,
  not applied below ``MIN_IOU_UNION_PX`` pixels of union, oracles.tolerances);
- holes and extra surface away from the reference silhouette's boundary
  (:func:`oracles.judge.surfaces.surface_mismatch`).

The reference is pyrender's silhouette; the fill rule's own model with its ties (a branch
of its own) is not used yet. Several objects' ids are read as one surface: which object
each pixel shows is not judged yet.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..candidates.frames_candidate import read_frame
from .surfaces import surface_mismatch


class FilledFrames:
    """A case's filled frames, measured one frame at a time (module docstring); nothing kept but numbers."""

    def __init__(self):
        self.frames = []

    def add(self, k: int, path: Path, covered: np.ndarray, job=None, grey: np.ndarray | None = None) -> dict:
        """Frame ``k``'s filled PNG at ``path`` against pyrender's ``covered`` (H, W) bool; its per-frame record.

        ``job``: ``(job_dir, job)``, for :func:`read_frame`'s listing of a job's problems."""
        h, w = covered.shape
        grey = read_frame(path, w, h, job) if grey is None else grey
        shown = grey >= 1
        both, union = int((shown & covered).sum()), int((shown | covered).sum())
        holes, extra = surface_mismatch(shown, covered)
        rec = {"frame": k, "iou": both / union if union else None, "union_px": union,
               "candidate_px": int(shown.sum()), "reference_px": int(covered.sum()),
               "holes_px": int(holes.sum()), "extra_px": int(extra.sum())}
        self.frames.append(rec)
        return rec

    def fields(self, min_union_px: int) -> dict:
        """The case's ``filled`` record: the lowest IoU among frames of at least ``min_union_px`` pixels of
        union (None when none is that large), sums of the rest."""
        f = self.frames
        gated = [r for r in f if r["iou"] is not None and r["union_px"] >= min_union_px]
        worst = min(gated, key=lambda r: r["iou"]) if gated else None
        holes = max(f, key=lambda r: r["holes_px"])
        extra = max(f, key=lambda r: r["extra_px"])
        return {"frames": len(f), "reference": "pyrender's silhouette",
                "min_iou": worst["iou"] if worst else None, "iou_worst_frame": worst["frame"] if worst else None,
                "union_px": sum(r["union_px"] for r in f), "candidate_px": sum(r["candidate_px"] for r in f),
                "reference_px": sum(r["reference_px"] for r in f),
                "holes_px": sum(r["holes_px"] for r in f), "holes_worst_frame": holes["frame"],
                "extra_px": sum(r["extra_px"] for r in f), "extra_worst_frame": extra["frame"],
                "blank_frames": [r["frame"] for r in f if r["candidate_px"] == 0 and r["reference_px"]],
                "per_frame": f}
