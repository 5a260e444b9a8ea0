"""Two surfaces' pixels compared away from a silhouette's boundary: holes and extra surface.

A renderer's depth map (oracles.judge.depth_frames) shows a surface at some
pixels; the reference (pyrender's faces) covers others. Where they differ on
the reference silhouette's boundary, the difference is a rounding decision;
away from it, it is a fault. (A filled frame is held to the fill rule's
decided pixels instead: oracles.judge.silhouette.)
"""

from __future__ import annotations

import numpy as np


def surface_mismatch(shown: np.ndarray, covered: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(holes, extra)``, ``(H, W)`` bool: where ``covered`` (the reference's surface) is not ``shown``,
    and where ``shown`` is and ``covered`` is not, each away from the boundary of ``covered``.

    A hole is counted where the reference covers the pixel and its eight neighbours (past the image's edge
    counts as covered: the picture's border is no silhouette edge), an extra pixel where the reference
    covers neither it nor any of its eight neighbours. The pixels left out are those beside the reference
    silhouette's boundary, which a correct renderer may decide either way: a centre within rounding of a
    silhouette edge (oracles.tolerances.MIN_SILHOUETTE_IOU's derivation: llvmpipe's 1/256 px snapping)
    has a neighbour across that edge. A band of boundary pixels lost or added is a silhouette measure's to
    find (IoU), not this one's.
    """
    holes, near = np.zeros(covered.shape, dtype=bool), np.zeros(covered.shape, dtype=bool)
    rows, cols = np.flatnonzero(covered.any(axis=1)), np.flatnonzero(covered.any(axis=0))
    if len(rows):  # both masks differ from nothing only within the covered pixels' box grown by one pixel
        h, w = covered.shape
        box = np.s_[max(rows[0] - 1, 0) : min(rows[-1] + 2, h), max(cols[0] - 1, 0) : min(cols[-1] + 2, w)]
        inside = covered[box]
        # past the box's own edge: the image's edge (counts as covered, False in ~covered's pad) or an uncovered
        # pixel beside an uncovered one (no pixel there is covered, so none of them is a hole either way)
        holes[box] = inside & ~_any_near(~inside, False) & ~shown[box]
        near[box] = _any_near(inside, False)
    return holes, shown & ~near


def _any_near(mask: np.ndarray, outside: bool) -> np.ndarray:
    """``(H, W)`` bool: ``mask`` at the pixel or any of its eight neighbours (``outside``: past the edge)."""
    h, w = mask.shape
    padded = np.pad(mask, 1, constant_values=outside)
    out = np.zeros((h, w), dtype=bool)
    for dy in range(3):
        for dx in range(3):
            out |= padded[dy : dy + h, dx : dx + w]
    return out
