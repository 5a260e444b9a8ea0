"""A renderer's filled frames of a frames job, measured frame by frame inside the case loop.

The case loop (oracles.judge.case_loop, fed by oracles.judge.frames_judge.JobFrames) hands each frame's filled PNG, its world points and
faces (the job's own OBJ and camera) to :meth:`FilledFrames.add`; the case's fields go into its
record (:meth:`FilledFrames.fields`, ``record["filled"]``) and :mod:`oracles.judge.decide` alone
decides on them. Per frame:

- the PNG is read as every frame of the job is (:func:`oracles.candidates.frames_candidate.read_frame`:
  grey levels, luminance x alpha / 255); a pixel is filled when its level is 1 or more (any
  colour but black: object ids 1, 2, ... as grey levels are filled);
- the reference is the silhouette under GL's fill rule with the pixel centres no renderer decides
  (ties) left out (:func:`oracles.references.fill_rule.silhouette`, ``Tolerances.fill_tie_px``);
- :func:`oracles.judge.silhouette.score_silhouette` scores the decided pixels: IoU, holes,
  extra, and the longest run of disagreements (the boundary measure: a one-pixel band missing
  along one edge is one run as long as the edge).

A frame whose candidate is blank where the reference covers decided pixels is named in
``blank_frames`` (never a pass). With several objects (job.json's ``objects`` of the scene: a
face belongs to its first vertex's object), the fill rule's object ids are compared with the
frame's grey levels (:func:`object_id_misses`).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..candidates.frames_candidate import read_frame
from ..diagnosis.silhouette_faults import SilhouetteFrame, name_silhouette_faults
from ..references.faces import fan
from ..references.fill_rule import corner_edges, silhouette
from .silhouette import score_silhouette

#: Failing filled frames of a case kept for naming (oracles.diagnosis.silhouette_faults fits one camera mistake
#: to them together; a fit costs about half a second a frame at 640x480, up to 3 s where the border cuts it).
NAMED_FRAMES = 2


class FilledFrames:
    """A case's filled frames, measured one frame at a time (module docstring); nothing kept but numbers, and
    the first :data:`NAMED_FRAMES` frames with a decided pixel off (their masks, for :meth:`faults`)."""

    def __init__(self, tie_px: float):
        self.tie_px = float(tie_px)
        self.frames = []
        self.failing: list[SilhouetteFrame] = []
        # (faces, fan(faces), the fan's edges grouped by vertex indices): a model-space scene's faces are one
        # object a case
        self._fanned = (None, None, None)

    def reference(self, p_world: np.ndarray, faces, camera, objects=None, hint=None) -> tuple:
        """The fill rule's silhouette of ``faces`` (index tuples into ``p_world`` (N, 3)) through ``camera``:
        ``(inside, ties, object ids)`` (oracles.references.fill_rule.silhouette); ``objects``: each face's
        object (F,), or None; ``hint``: pyrender's triangle ids of the faces' fan, which spare the fill rule
        work (the silhouette is the same: each id is checked by the rule)."""
        several = objects is not None and len(np.unique(objects)) > 1
        if self._fanned[0] is not faces:
            fanned = fan(faces)
            self._fanned = (faces, fanned, corner_edges(fanned[0]))
        return silhouette(
            p_world,
            faces,
            camera,
            (int(camera.height), int(camera.width)),
            face_objects=objects if several else None,
            tie_px=self.tie_px,
            hint=hint,
            fanned=self._fanned[1],
            edges=self._fanned[2],
        )

    def add(
        self, k: int, path: Path, p_world: np.ndarray, faces, camera, job=None, objects=None, hint=None, reference=None
    ) -> dict:
        """Frame ``k``'s filled PNG at ``path`` against the fill-rule silhouette of ``faces`` (index tuples into
        ``p_world`` (N, 3)) through ``camera``; its per-frame record. ``job``: ``(job_dir, job)``, for
        :func:`read_frame`'s listing of a job's problems; ``objects``: each face's object (F,), when the
        scene has several (their ids are then judged: :func:`object_id_misses`); ``hint``: as for
        :meth:`reference`; ``reference``: a function giving :meth:`reference`'s result made already (on the
        frames judge's reading thread, oracles.candidates.frame_prefetch), called once the PNG is read."""
        h, w = int(camera.height), int(camera.width)
        grey = read_frame(path, w, h, job)
        shown = grey >= 1
        several = objects is not None and len(np.unique(objects)) > 1
        if reference is None:
            inside, ties, ids = self.reference(p_world, faces, camera, objects, hint)
        else:
            inside, ties, ids = reference()
        s = score_silhouette(shown, inside, ties)
        rec = {
            "frame": k,
            "iou": float(s.iou) if np.isfinite(s.iou) else None,
            "union_px": s.union_px,
            "candidate_px": s.cand_px,
            "reference_px": s.ref_px,
            "ties_px": s.ties_px,
            "holes_px": s.holes,
            "extra_px": s.extra,
            "longest_run_px": s.longest_run_px,
            "run_at": list(s.run_at) if s.run_at else None,
            "vacuous": s.vacuous,
            "reference_decided_px": int(np.count_nonzero(inside & ~ties)),
            "object_id_px": object_id_misses(grey, shown & ~ties, ids) if several else None,
        }
        self.frames.append(rec)
        if (s.holes or s.extra) and not s.vacuous and len(self.failing) < NAMED_FRAMES:
            self.failing.append(SilhouetteFrame(shown, inside, ties, camera, p_world, tuple(faces)))
        return rec

    def faults(self) -> tuple:
        """The camera mistake the case's failing frames show (oracles.diagnosis.silhouette_faults), or ()."""
        return name_silhouette_faults(self.failing) if self.failing else ()

    def fields(self, min_union_px: int) -> dict:
        """The case's ``filled`` record: the lowest IoU among frames of at least ``min_union_px`` decided pixels
        of union (None when none is that large), the longest run and where, sums of the rest."""
        f = self.frames
        gated = [r for r in f if r["iou"] is not None and r["union_px"] >= min_union_px]
        worst = min(gated, key=lambda r: r["iou"]) if gated else None
        run = max(f, key=lambda r: r["longest_run_px"])
        return {
            "frames": len(f),
            "reference": "GL's fill rule, ties left out",
            "min_iou": worst["iou"] if worst else None,
            "iou_worst_frame": worst["frame"] if worst else None,
            "longest_run_px": run["longest_run_px"],
            "run_frame": run["frame"],
            "run_at": run["run_at"],
            "union_px": sum(r["union_px"] for r in f),
            "candidate_px": sum(r["candidate_px"] for r in f),
            "reference_px": sum(r["reference_px"] for r in f),
            "ties_px": sum(r["ties_px"] for r in f),
            "holes_px": sum(r["holes_px"] for r in f),
            "extra_px": sum(r["extra_px"] for r in f),
            "blank_frames": [r["frame"] for r in f if r["candidate_px"] == 0 and r["reference_decided_px"]],
            "object_id_px": (None if f[0]["object_id_px"] is None else sum(r["object_id_px"] for r in f)),
            "object_id_worst_frame": (
                None if f[0]["object_id_px"] is None else max(f, key=lambda r: r["object_id_px"])["frame"]
            ),
            "per_frame": f,
        }


def object_id_misses(grey: np.ndarray, compared: np.ndarray, ids: np.ndarray) -> int:
    """Pixels of ``compared`` (filled, not a tie) whose grey level is not the reference object's id.

    Ids are labels: each grey level is read as the reference object it shows most often
    (``ids``: oracles.references.fill_rule.silhouette's, -1 none, -2 a tie between two objects within
    their depth bounds, left out), and a pixel of that level showing another object is a miss. Two
    objects drawn with one level: the smaller one's pixels all miss.
    """
    keep = compared & (ids >= 0)
    levels, objects = grey[keep].astype(np.int64), ids[keep]
    if not len(levels):
        return 0
    table = np.zeros((256, int(objects.max()) + 1), dtype=np.int64)
    np.add.at(table, (levels, objects), 1)
    return int(len(levels) - table.max(axis=1).sum())
