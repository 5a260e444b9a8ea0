"""A case's wireframes, measured frame by frame: one measurement for every frame source.

Each frame hands in its drawn pixels against pyrender's (a
oracles.judge.frame_pixels.FramePixels: a projector's frame drawn by the harness, core's,
or a renderer's PNG read by the line style) and the oracle's segments; :meth:`WireFrames.add`
scores it (F1 at 0 and 1 px, metrics.pixel_scores), writes its per-frame fields, queues its
lines (metrics.LineBatch: scored with later frames), counts the pixels either side drew and
keeps the worst frame's pixels. After the case's frames, :meth:`WireFrames.flush` scores the
lines still queued, and the case's pixel and line fields are read from it.

Where the sources really differ, the measurement says so in its parameters (:class:`WireFrames`):
the 0 px scores of a frame with sub-pixel ties (``resolve_ties``), the per-frame fields
(``frame_keys``), and, for a renderer's own drawing, the read of its drawing rule (``style``,
``rounded_tie_px``). Depth maps and filled frames are measured beside it
(oracles.judge.depth_frames, oracles.judge.filled_frames).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import line_model
from . import f1_radius, metrics
from .decide import pixel_fields

#: A projector's per-frame pixel fields: every score of metrics.pixel_scores.
SCORE_FRAME_KEYS = metrics.PIXEL_SCORE_KEYS
#: A renderer's frames' per-frame pixel fields: the F1s and each side's drawn pixels.
COUNT_FRAME_KEYS = ("f1_0px", "f1_1px", "candidate_pixels", "oracle_pixels")


@dataclass(frozen=True)
class KeptImage:
    """A bool image kept for worst.gif: its drawn pixels' flat indices (a wireframe: ~1 % of the
    image, already found by frame_pixels.FramePixels), or its bits packed (a filled silhouette)."""

    shape: tuple
    flat: np.ndarray | None = None
    bits: np.ndarray | None = None

    @classmethod
    def of(cls, image: np.ndarray, flat: np.ndarray | None = None) -> KeptImage:
        """``image`` kept: as ``flat`` (its drawn pixels' ascending flat indices) when given, else packed."""
        if flat is not None:
            return cls(image.shape, flat=flat)
        return cls(image.shape, bits=np.packbits(image))

    def image(self) -> np.ndarray:
        """The ``(H, W)`` bool image back."""
        h, w = self.shape
        if self.flat is not None:
            out = np.zeros(h * w, bool)
            out[self.flat] = True
            return out.reshape(h, w)
        return np.unpackbits(self.bits, count=h * w).reshape(h, w).astype(bool)


class WireFrames:
    """A case's wireframe frames, scored one at a time; nothing kept per frame but numbers and the worst
    frame's pixels (and, with ``kept``, each frame's pixels for worst.gif).

    Parameters
    ----------
    frame_keys : tuple of str
        The pixel scores written into each frame's record (:data:`SCORE_FRAME_KEYS` for a projector,
        :data:`COUNT_FRAME_KEYS` for a renderer's frames); the line fields (metrics.LINE_FRAME_KEYS)
        follow when the frame's lines are scored.
    resolve_ties : bool
        Whether a frame's 0 px scores are those with its sub-pixel ties undecided (metrics.line_scores'
        ``tie_resolved``: the candidate given the oracle's value at each tie), in its record and in the
        case's scores. A projector's lines are drawn by GL's rule from the candidate's own float ends
        (core's raster, or the harness's, oracles.candidates.draw): at a tie either pixel is that rule's,
        so F1@0px judges the decided pixels, as the balance and the per-edge counts do. A renderer's own
        frames (``False``) are judged as drawn: their rule is read from them (``style``), and the ties
        of the rules allowed are left out by that read (oracles.judge.line_style, line_ties).
    style : oracles.judge.line_style.CaseStyle or None
        A renderer's drawing read over the case (None: the harness drew the frames by GL's rule, there is
        no other rule to read). Given, each frame's differing pixels are counted by where they lie
        (CaseStyle.count_rule) and its F1 at the wider radii is kept (oracles.judge.f1_radius).
    rounded_tie_px : float or None
        Given, each frame is scored too against a correct drawing by the rounded-ends rule
        (oracles.line_model, the rule's ties within this distance left out of both): the other rule a
        renderer's aliased lines may follow (``Tolerances.rounded_end_tie_px``); None where only GL's
        rule, or the geometry alone, is judged.
    kept : list or None
        Where each frame's ``(frame, KeptImage candidate, KeptImage oracle)`` is appended (worst.gif), or None.
    """

    def __init__(
        self,
        frame_keys: tuple = SCORE_FRAME_KEYS,
        resolve_ties: bool = True,
        style=None,
        rounded_tie_px: float | None = None,
        kept: list | None = None,
    ):
        self.frame_keys, self.resolve_ties = tuple(frame_keys), resolve_ties
        self.style, self.rounded_tie_px, self.kept = style, rounded_tie_px, kept
        self.pixel: dict = {key: [] for key in metrics.PIXEL_SCORE_KEYS}  # each frame's scores, in frame order
        self.lines: list = []  # (frame, metrics.line_scores)
        self.radius: list = []  # with a style: each frame's F1 at the wider radii (f1_radius.frame_scores)
        self.drawn_px = 0  # pixels drawn by either side, over the frames (oracles.judge.gate)
        self._batch = metrics.LineBatch()  # frames waiting for their line scores
        self._worst: tuple | None = None  # ((f1_1px, f1_0px), frame, FramePixels)
        self._rounded_f1: list = []  # each frame's F1@0px against the rounded-ends rule
        self._rounded_batch = metrics.LineBatch()
        self._rounded_lines: list = []

    def add(self, k: int, fp, seg0: np.ndarray, seg1: np.ndarray, segs, frame_rec: dict) -> dict:
        """Frame ``k`` scored: ``fp`` its FramePixels, ``seg0``/``seg1`` ``(E, 2)`` the oracle's segments' ends
        in pixels (NaN: an edge not drawn), ``frame_rec`` its record (written into, its line fields once its
        lines are scored), ``segs`` ``(E, 2, 2)`` the lines a correct renderer draws (with ``style`` or
        ``rounded_tie_px``). Returns the frame's metrics.pixel_scores."""
        if self.style is not None:
            self.style.count_rule(fp, segs)
        if self.rounded_tie_px is not None:
            self._add_rounded(k, fp, segs, seg0, seg1, self.rounded_tie_px)
        ps = metrics.pixel_scores(None, None, pixels=fp)
        if self.style is not None:
            self.radius.append(f1_radius.frame_scores(fp, ps))
        for key, values in self.pixel.items():
            values.append(ps[key])
        self.drawn_px += ps["candidate_pixels"] + ps["oracle_pixels"] - ps["both_pixels"]
        frame_rec.update({key: ps[key] for key in self.frame_keys})
        at = len(self.pixel["f1_0px"]) - 1  # this frame's place in self.pixel
        self._record_lines(self._batch.add((k, frame_rec, at), fp, seg0, seg1))  # scored with later frames
        key = (ps["f1_1px"], ps["f1_0px"])
        if self._worst is None or key < self._worst[0]:
            self._worst = (key, k, fp)
        if self.kept is not None:
            h_w = fp.shape
            self.kept.append((k, KeptImage(h_w, flat=fp.cand_idx), KeptImage(h_w, flat=fp.oracle_idx)))
        return ps

    def _add_rounded(self, k: int, fp, segs: np.ndarray, seg0, seg1, tie_px: float) -> None:
        """The frame's drawn pixels against a correct drawing of ``segs`` by the rounded-ends rule
        (oracles.line_model), the rule's ties left out of both."""
        model, ties = line_model.expected(segs, fp.shape, "rounded", tie_px)
        keep = ~ties.reshape(-1)
        cand = fp.cand_idx
        rp = metrics.FramePixels.from_indices(fp.shape, cand[keep[cand]], np.flatnonzero(model.reshape(-1) & keep))
        self._rounded_f1.append(float(metrics.pixel_scores(None, None, tols=(0,), pixels=rp)["f1_0px"]))
        self._rounded_lines.extend(self._rounded_batch.add(k, rp, seg0, seg1))

    def _record_lines(self, scored: list) -> None:
        """Frames' line scores (``[((frame, frame record, place in self.pixel), scores)]``) into the case and
        their records; with ``resolve_ties``, a frame with ties has its 0 px scores replaced (class docstring)."""
        for (k, frame_rec, at), ls in scored:
            self.lines.append((k, ls))
            frame_rec.update({name: ls[name] for name in metrics.LINE_FRAME_KEYS})
            if self.resolve_ties:
                for name, value in (ls["tie_resolved"] or {}).items():
                    frame_rec[name] = self.pixel[name][at] = value

    def flush(self) -> None:
        """Score the lines of the frames still queued (after the case's last frame)."""
        self._record_lines(self._batch.flush())

    @property
    def measured(self) -> bool:
        """Whether some frame was scored."""
        return bool(self.pixel["f1_0px"])

    @property
    def worst_frame(self) -> int | None:
        """The frame with the lowest ``(F1@1px, F1@0px)`` (the first of equals), None before any."""
        return self._worst[1] if self._worst is not None else None

    def worst_images(self) -> dict | None:
        """``{"frame", "candidate", "oracle"}``: the worst frame's bool images, None before any frame."""
        if self._worst is None:
            return None
        _key, k, fp = self._worst
        return {
            "frame": k,
            "candidate": flat_image(fp.cand_idx, fp.shape),
            "oracle": flat_image(fp.oracle_idx, fp.shape),
        }

    def pixel_fields(self) -> dict:
        """The case's pixel fields (oracles.judge.decide.pixel_fields: minima, means, the worst frame)."""
        return pixel_fields(self.pixel, self.worst_frame)

    def line_fields(self) -> dict:
        """The case's line fields pooled over its frames (metrics.line_summary); after :meth:`flush`."""
        return metrics.line_summary(self.lines)

    def rounded(self) -> dict | None:
        """The case's pixels against the rounded-ends rule (CaseStyle.read's ``rounded``), None when not
        measured or without frames."""
        self._rounded_lines.extend(self._rounded_batch.flush())
        if not self._rounded_f1:
            return None
        return {"pixel_f1_0px": min(self._rounded_f1), "lines": metrics.line_summary(self._rounded_lines)}


def flat_image(flat: np.ndarray, shape: tuple) -> np.ndarray:
    """The ``(H, W)`` bool image drawing the flat indices ``flat``."""
    out = np.zeros(shape[0] * shape[1], bool)
    out[flat] = True
    return out.reshape(shape)
