"""A filled frame's silhouette against the fill-rule reference: IoU, holes, extra, the longest run.

The reference (oracles.references.fill_rule) marks the pixel centres a correct renderer may
decide either way (ties); every other pixel is *decided*, and a correct renderer agrees with
the reference on all of them (oracles.tolerances, "Filled frames"). So the scores count
decided pixels only:

- ``iou``: decided pixels covered by both over decided pixels covered by either;
- ``holes``: decided pixels the reference covers and the candidate does not; ``extra``: the
  reverse;
- ``longest_run_px``: the largest 8-connected set of decided disagreements (holes and extra
  together), the boundary measure. A band missing along one edge is one run as long as the
  edge, a half-pixel shift one run per edge; a correct renderer has none (0).

Never vacuous: a blank candidate, a reference with no decided covered pixel, or no decided
pixel at all gives ``vacuous`` (a sentence saying which), and such scores never pass.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..tolerances import MIN_IOU_UNION_PX

__all__ = ["SilhouetteScores", "score_silhouette", "largest_run"]

# The 8-neighbours that follow a pixel in row-major order: every 8-adjacent pair once.
_FORWARD = ((0, 1), (1, -1), (1, 0), (1, 1))


@dataclass(frozen=True)
class SilhouetteScores:
    """A filled frame's silhouette scores (module docstring); counts in pixels.

    ``vacuous`` is None when the comparison says something, else why it does not (the
    candidate is blank, the reference covers no decided pixel, nothing is decided): then
    :meth:`failures` is that sentence alone and :meth:`passed` is False, whatever the numbers.
    ``iou`` is NaN when no decided pixel is covered by either. ``run_at`` is ``(row, col)`` of
    one pixel of the longest run, None when there is none.
    """

    decided_px: int
    ties_px: int
    ref_px: int
    cand_px: int
    union_px: int
    iou: float
    holes: int
    extra: int
    longest_run_px: int
    run_at: tuple[int, int] | None
    vacuous: str | None

    def failures(self, tol) -> list[str]:
        """Why these scores fail the limits ``tol`` (an oracles.tolerances.Tolerances); [] when they pass.

        ``min_iou`` is applied from MIN_IOU_UNION_PX decided pixels up (a few-pixel
        silhouette's IoU is one boundary decision); ``max_silhouette_run_px`` always.
        """
        if self.vacuous is not None:
            return [self.vacuous]
        out = []
        if self.longest_run_px > tol.max_silhouette_run_px:
            row, col = self.run_at
            out.append(
                f"silhouette: {self.longest_run_px} decided pixels missing or added in one run "
                f"(at row {row}, column {col}; limit {tol.max_silhouette_run_px}); "
                f"{self.holes} holes, {self.extra} extra in all"
            )
        if self.union_px >= MIN_IOU_UNION_PX and not self.iou >= tol.min_iou:
            out.append(f"silhouette IoU {self.iou:.6f} below {tol.min_iou:g} over {self.union_px} decided pixels")
        return out

    def passed(self, tol) -> bool:
        """True when the comparison is not vacuous and nothing fails."""
        return not self.failures(tol)


def largest_run(mask: np.ndarray) -> tuple[int, tuple[int, int] | None]:
    """The largest 8-connected set of True pixels of ``mask`` (H, W): ``(size, (row, col) of one)``.

    Labels propagate as the smallest index over 8-adjacent pairs, with pointer jumping, over
    the True pixels only (O(n log n) for n of them).
    """
    mask = np.asarray(mask, dtype=bool)
    rows, cols = np.nonzero(mask)
    n = len(rows)
    if n == 0:
        return 0, None
    height, width = mask.shape
    index = np.full((height + 2, width + 2), -1, dtype=np.int64)  # a border of -1: no wrap-around
    index[rows + 1, cols + 1] = np.arange(n)
    pairs_a, pairs_b = [], []
    for dr, dc in _FORWARD:
        other = index[rows + 1 + dr, cols + 1 + dc]
        hit = other >= 0
        pairs_a.append(np.flatnonzero(hit))
        pairs_b.append(other[hit])
    a, b = np.concatenate(pairs_a), np.concatenate(pairs_b)
    label = np.arange(n)
    while True:
        low = np.minimum(label[a], label[b])
        new = label.copy()
        np.minimum.at(new, a, low)
        np.minimum.at(new, b, low)
        new = new[new]  # pointer jumping
        if np.array_equal(new, label):
            break
        label = new
    sizes = np.bincount(label, minlength=n)
    root = int(np.argmax(sizes))
    return int(sizes[root]), (int(rows[root]), int(cols[root]))


def score_silhouette(cand, ref, ties) -> SilhouetteScores:
    """Score a candidate's covered pixels against the reference's, leaving the ties out.

    Parameters
    ----------
    cand : (H, W) bool
        The candidate's covered pixels (any non-black pixel of its filled frame).
    ref : (H, W) bool
        The reference's (oracles.references.fill_rule: ``inside``).
    ties : (H, W) bool
        Pixels either answer is correct at (fill_rule's ``ties``).

    Returns
    -------
    SilhouetteScores
    """
    cand, ref, ties = (np.asarray(m, dtype=bool) for m in (cand, ref, ties))
    if not cand.shape == ref.shape == ties.shape or cand.ndim != 2:
        raise ValueError(
            f"silhouettes of shapes {cand.shape}, {ref.shape} and ties {ties.shape}: "
            "expected three (H, W) masks of one shape"
        )
    # every count but the ties' over the box of the pixels either side covers (nothing is counted outside it)
    ties_px = int(np.count_nonzero(ties))
    n_decided = ties.size - ties_px
    box = _covered_box(cand | ref)
    cand, ref, decided = cand[box], ref[box], ~ties[box]
    both = int(np.count_nonzero(cand & ref & decided))
    union = int(np.count_nonzero((cand | ref) & decided))
    holes_mask = ref & ~cand & decided
    extra_mask = cand & ~ref & decided
    run, at = largest_run(holes_mask | extra_mask)
    if at is not None:
        at = (at[0] + int(box[0].start), at[1] + int(box[1].start))
    ref_px = int(np.count_nonzero(ref))
    ref_decided = int(np.count_nonzero(ref & decided))
    vacuous = None
    if n_decided == 0:
        vacuous = "silhouette: no decided pixel to compare (every pixel is a tie)"
    elif not cand.any():
        vacuous = "silhouette: the candidate's frame is blank (no covered pixel)"
    elif ref_decided == 0:
        vacuous = "silhouette: the reference covers no decided pixel (nothing to compare the candidate with)"
    return SilhouetteScores(
        decided_px=n_decided,
        ties_px=ties_px,
        ref_px=ref_px,
        cand_px=int(np.count_nonzero(cand)),
        union_px=union,
        iou=both / union if union else float("nan"),
        holes=int(np.count_nonzero(holes_mask)),
        extra=int(np.count_nonzero(extra_mask)),
        longest_run_px=run,
        run_at=at,
        vacuous=vacuous,
    )


def _covered_box(mask: np.ndarray) -> tuple[slice, slice]:
    """The rows and columns of ``mask`` (H, W) that hold a True pixel, as one box (an empty one when none)."""
    rows, cols = np.flatnonzero(mask.any(axis=1)), np.flatnonzero(mask.any(axis=0))
    if len(rows) == 0:
        return np.s_[0:0, 0:0]
    return np.s_[rows[0] : rows[-1] + 1, cols[0] : cols[-1] + 1]
