"""A frame's drawn pixels, candidate's and oracle's, found once: :class:`FramePixels`.

Its own module because the line measures (oracles.judge.metrics) and the line ends
(oracles.judge.line_ends) both read it.
"""

from __future__ import annotations

import numpy as np


class FramePixels:
    """The drawn pixels of a candidate frame and the oracle's, found once and shared by one frame's metrics.

    A wireframe covers under 1 % of an image, so each image is scanned once
    (``np.flatnonzero``) and every metric after that (:func:`pixel_scores`,
    :func:`line_scores`) works on the drawn pixels' indices: lookups, not
    passes over the whole image. The images themselves are not kept, so a
    case can hold its frames' pixels until it scores their lines together
    (:class:`LineBatch`).

    Attributes
    ----------
    shape : (H, W)
    cand_idx, oracle_idx : (Nc,), (No,) ndarray of intp
        Flat indices ``y W + x`` of each image's drawn pixels, ascending (row-major).
    cand_in_oracle, oracle_in_cand : (Nc,), (No,) ndarray of bool
        Whether each drawn pixel is drawn in the other image too.
    owners : (flat, edge) or None
        Some of these pixels' owning edges, found before the frame was scored (oracles.judge.segment_pixels
        .pixel_owners: a projector's candidate pixels, while pyrender drew), for its line scores; None.
    ends : (places, ties) or None
        Where the one-sided pixels lie and the sub-pixel ties among them (oracles.judge.line_ends
        .frames_end_places' item and tie pixels), made before the frame was scored (oracles.judge.case
        .pixels_beside), for its line scores; None.
    """

    owners: tuple | None = None
    ends: tuple | None = None

    def __init__(self, cand: np.ndarray, oracle: np.ndarray):
        cand = np.asarray(cand, bool)
        oracle = np.asarray(oracle, bool)
        if cand.shape != oracle.shape:
            raise ValueError(f"image shapes differ: {cand.shape} vs {oracle.shape}")
        self.shape = cand.shape
        self.cand_idx = np.flatnonzero(cand)
        self.oracle_idx = np.flatnonzero(oracle)
        self.cand_in_oracle = oracle.reshape(-1)[self.cand_idx]
        self.oracle_in_cand = cand.reshape(-1)[self.oracle_idx]
        self._only = None

    @classmethod
    def from_indices(cls, shape: tuple, cand_idx: np.ndarray, oracle_idx: np.ndarray) -> FramePixels:
        """The frame whose images draw the ascending flat indices ``cand_idx`` and ``oracle_idx`` (``(H, W)`` ``shape``)."""
        fp = cls.__new__(cls)
        fp.shape = tuple(shape)
        fp.cand_idx, fp.oracle_idx = cand_idx, oracle_idx
        fp.cand_in_oracle = fp.has(cand_idx, of_candidate=False)  # a binary search each: no sort
        fp.oracle_in_cand = fp.has(oracle_idx, of_candidate=True)
        fp._only = None
        return fp

    def exchanged(self, cand_out: np.ndarray, cand_in: np.ndarray) -> FramePixels | None:
        """The frame with the candidate's ``cand_out`` taken out and ``cand_in`` put in, or None.

        ``cand_out``: candidate-only pixels, ``cand_in``: oracle-only pixels, ascending
        flat indices each; None (the caller builds the frame anew) when they are
        not. The same frame as ``from_indices`` of the changed candidate pixels gives, found by a merge:
        the pixels the other image draws change only at those places (a
        candidate-only pixel is in no oracle lookup; an oracle-only one put in is
        drawn by both), so no lookup over all the pixels is made again.
        """
        cand_out = np.asarray(cand_out, np.int64).reshape(-1)
        cand_in = np.asarray(cand_in, np.int64).reshape(-1)
        at_out = np.searchsorted(self.cand_idx, cand_out)
        at_in = np.searchsorted(self.oracle_idx, cand_in)
        only_c, only_o = ~self.cand_in_oracle, ~self.oracle_in_cand
        if len(cand_out) and (
            np.any(at_out >= len(self.cand_idx))
            or np.any(self.cand_idx[np.minimum(at_out, len(self.cand_idx) - 1)] != cand_out)
            or not only_c[at_out].all()
            or np.any(np.diff(cand_out) <= 0)
        ):
            return None
        if len(cand_in) and (
            np.any(at_in >= len(self.oracle_idx))
            or np.any(self.oracle_idx[np.minimum(at_in, len(self.oracle_idx) - 1)] != cand_in)
            or not only_o[at_in].all()
            or np.any(np.diff(cand_in) <= 0)
        ):
            return None
        keep = np.ones(len(self.cand_idx), bool)
        keep[at_out] = False
        kept, kept_in = self.cand_idx[keep], self.cand_in_oracle[keep]
        where = np.searchsorted(kept, cand_in)
        fp = FramePixels.__new__(FramePixels)
        fp.shape = self.shape
        fp.cand_idx = np.insert(kept, where, cand_in.astype(kept.dtype))
        fp.oracle_idx = self.oracle_idx
        fp.cand_in_oracle = np.insert(kept_in, where, True)
        fp.oracle_in_cand = self.oracle_in_cand.copy()
        fp.oracle_in_cand[at_in] = True
        fp._only = None
        return fp

    @property
    def both(self) -> int:
        """Pixels drawn by both images."""
        return int(np.count_nonzero(self.cand_in_oracle))

    @property
    def identical(self) -> bool:
        """Whether the two images draw the same pixels."""
        return len(self.cand_idx) == len(self.oracle_idx) == self.both

    def only(self) -> tuple[np.ndarray, np.ndarray]:
        """Flat indices of the candidate-only and the oracle-only pixels, ascending (found once)."""
        if self._only is None:
            self._only = (self.cand_idx[~self.cand_in_oracle], self.oracle_idx[~self.oracle_in_cand])
        return self._only

    def drawn(self) -> np.ndarray:
        """Flat indices of the pixels drawn by either image, ascending."""
        if self.identical:
            return self.cand_idx
        extra = self.oracle_idx[~self.oracle_in_cand]  # few, and none of them the candidate's: merged, not sorted
        return np.insert(self.cand_idx, np.searchsorted(self.cand_idx, extra), extra)

    def has(self, flat: np.ndarray, of_candidate: bool = True) -> np.ndarray:
        """``(K,)`` bool: whether the candidate's (else the oracle's) image draws each flat index."""
        idx = self.cand_idx if of_candidate else self.oracle_idx
        flat = np.asarray(flat, np.int64)
        if len(idx) == 0:
            return np.zeros(flat.shape, bool)
        at = np.minimum(np.searchsorted(idx, flat), len(idx) - 1)
        return idx[at] == flat

    def within(self, tol: int, of_candidate: bool = True) -> np.ndarray:
        """For each drawn pixel of one image (row-major): is a pixel of the other within ``tol`` (Chebyshev)?

        ``of_candidate``: the candidate's pixels against the oracle's (else the
        reverse). A pixel both draw is within any ``tol``; for the others, the
        ``(2 tol + 1)^2`` pixels around each are looked up among the other
        image's (outside the image counts as not drawn).
        """
        inside = self.cand_in_oracle if of_candidate else self.oracle_in_cand
        if tol == 0:
            return inside
        idx = self.cand_idx if of_candidate else self.oracle_idx
        out = inside.copy()
        rest = np.flatnonzero(~inside)
        if len(rest) == 0:
            return out
        h, w = self.shape
        rows, cols = np.divmod(idx[rest], w)
        offs = np.arange(-tol, tol + 1)
        ry = (rows[:, None, None] + offs[None, :, None]).repeat(len(offs), axis=2)
        cx = (cols[:, None, None] + offs[None, None, :]).repeat(len(offs), axis=1)
        valid = (ry >= 0) & (ry < h) & (cx >= 0) & (cx < w)
        found = self.has(np.where(valid, ry * w + cx, -1).reshape(len(rest), -1), not of_candidate)
        out[rest] = (found & valid.reshape(len(rest), -1)).any(axis=1)
        return out
