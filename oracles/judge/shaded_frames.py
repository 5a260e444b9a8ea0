"""Core's shaded frames (``--style shaded``), measured frame by frame in the case loop (oracles.judge.case_loop).

Each frame's depth buffer (inf where nothing is drawn) and the faces it shows are scored against
pyrender's drawing of the same faces (metrics.shaded_scores: the silhouettes' IoU, one-sided regions
inside the other's silhouette, the depth error within pyrender's bound, which face shows); the case's
fields are oracles.judge.verdict.shaded_summary's. A scene without faces has nothing to shade: its
frames are drawn (for worst.gif) and not scored.
"""

from __future__ import annotations

import numpy as np

from . import metrics
from .wire_frames import KeptImage

#: Per-frame fields of a shaded comparison (oracles.judge.metrics.shaded_scores).
SHADED_FRAME_KEYS = (
    "silhouette_iou",
    "silhouette_union_px",
    "silhouette_mismatch_inside",
    "depth_pixels",
    "depth_max_error",
    "depth_mean_error",
    "depth_error_bound",
    "depth_error_ratio",
    "face_disagreements",
    "face_disagreements_inside",
)


class ShadedFrames:
    """A case's shaded frames (module docstring). ``tris`` ``(T, 3)`` and ``tri_owner`` ``(T,)``: the scene's
    faces fanned into triangles and each triangle's face (oracles.references.faces.fan), None without faces;
    ``want_images``: the worst frame's images kept; ``kept``: where each frame's images are appended (worst.gif)."""

    def __init__(self, camera, tris=None, tri_owner=None, want_images: bool = True, kept: list | None = None):
        self.camera, self.tris, self.tri_owner = camera, tris, tri_owner
        self.want_images, self.kept = want_images, kept
        self.scores: list = []  # (frame, shaded scores)
        self.drawn_px = 0  # pixels either side's silhouette covers, over the frames (oracles.judge.gate)
        self.worst: tuple | None = None  # (key, frame, candidate image, oracle image)

    def add(self, k: int, cand_depth: np.ndarray, cand_faces, drawing, frame_rec: dict) -> None:
        """Frame ``k``: the candidate's depth buffer ``cand_depth`` ``(H, W)`` and the face each pixel shows
        (``cand_faces``, or None) against pyrender's ``drawing`` ``(covered, depth, triangle ids)`` (None
        without faces); its fields into ``frame_rec``."""
        cam = self.camera
        cand_img = np.isfinite(cand_depth)
        key = None
        if drawing is None:
            orac_img = np.zeros((cam.height, cam.width), bool)
        else:
            orac_img, orac_depth, ids = drawing
            orac_faces = np.where(ids >= 0, self.tri_owner[np.maximum(ids, 0)], -1)  # triangle -> polygon
            ss = metrics.shaded_scores(
                cand_depth,
                orac_img,
                orac_depth,
                metrics.depth_bound(orac_depth, orac_img, cam),
                metrics.occlusion_boundary(ids, self.tris),
                cand_faces=cand_faces,
                oracle_faces=orac_faces,
            )
            self.scores.append((k, ss))
            self.drawn_px += ss["silhouette_union_px"]
            frame_rec.update({key: ss[key] for key in SHADED_FRAME_KEYS})
            key = (ss["silhouette_iou"], -(ss["depth_error_ratio"] or 0.0))
        if self.want_images and key is not None and (self.worst is None or key < self.worst[0]):
            self.worst = (key, k, cand_img.copy(), orac_img.copy())
        if self.kept is not None:
            self.kept.append((k, KeptImage.of(cand_img), KeptImage.of(orac_img)))

    def worst_images(self) -> dict | None:
        """``{"frame", "candidate", "oracle"}``: the worst frame's images, None when none was scored."""
        if self.worst is None:
            return None
        return {"frame": self.worst[1], "candidate": self.worst[2], "oracle": self.worst[3]}
