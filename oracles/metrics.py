"""Error metrics: vertex errors between two projections, pixel agreement between two frames.

Pixel agreement follows the Khronos conformance idea for line rasterization:
at tolerance ``t`` a drawn pixel counts as matched when the other image has a
drawn pixel within Chebyshev distance ``t`` (t = 1: its 3x3 neighbourhood).

    precision@t = matched candidate pixels / candidate pixels
    recall@t    = matched oracle pixels    / oracle pixels
    F1@t        = 2 P R / (P + R)

Two blank images agree perfectly (F1 = 1); one blank and one not give 0.
"""

from __future__ import annotations

import numpy as np


def vertex_errors(cand_px: np.ndarray, oracle_px: np.ndarray) -> dict:
    """Compare ``(N, 2)`` projections with NaN rows for clipped points.

    Returns max / mean / RMS pixel error over the points both show, where the
    worst one is, and how the visible sets differ.
    """
    cand_vis = ~np.isnan(cand_px).any(axis=1)
    orac_vis = ~np.isnan(oracle_px).any(axis=1)
    both = cand_vis & orac_vis
    out = {
        "points": int(len(cand_px)),
        "visible_both": int(both.sum()),
        "candidate_only": int((cand_vis & ~orac_vis).sum()),   # shown by the candidate, clipped by the oracle
        "oracle_only": int((~cand_vis & orac_vis).sum()),      # clipped by the candidate, shown by the oracle
        "max_px": None, "mean_px": None, "rms_px": None, "worst_index": None,   # None: nothing compared
    }
    if both.any():
        err = np.hypot(*(cand_px[both] - oracle_px[both]).T)
        if not np.all(np.isfinite(err)):
            out.update(max_px=float("inf"), mean_px=float("inf"), rms_px=float("inf"))
            out["worst_index"] = int(np.flatnonzero(both)[np.flatnonzero(~np.isfinite(err))[0]])
            return out
        k = int(np.argmax(err))
        out.update(max_px=float(err[k]), mean_px=float(err.mean()),
                   rms_px=float(np.sqrt((err ** 2).mean())), worst_index=int(np.flatnonzero(both)[k]))
    return out


def _within(mask_from: np.ndarray, mask_to: np.ndarray, tol: int) -> np.ndarray:
    """For each True pixel of ``mask_from``: is a True pixel of ``mask_to`` within ``tol`` (Chebyshev)?"""
    if tol == 0:
        return mask_to[mask_from]
    from scipy.ndimage import binary_dilation

    grown = binary_dilation(mask_to, structure=np.ones((3, 3), bool), iterations=tol)
    return grown[mask_from]


def pixel_scores(cand: np.ndarray, oracle: np.ndarray, tols=(0, 1)) -> dict:
    """Precision, recall and F1 of ``cand`` against ``oracle`` (both (H, W) bool) at each tolerance."""
    cand = np.asarray(cand, bool)
    oracle = np.asarray(oracle, bool)
    if cand.shape != oracle.shape:
        raise ValueError(f"image shapes differ: {cand.shape} vs {oracle.shape}")
    out = {"candidate_pixels": int(cand.sum()), "oracle_pixels": int(oracle.sum()),
           "both_pixels": int((cand & oracle).sum())}
    for t in tols:
        if not cand.any() and not oracle.any():
            p = r = f1 = 1.0
        elif not cand.any() or not oracle.any():
            p = 1.0 if not cand.any() else 0.0
            r = 1.0 if not oracle.any() else 0.0
            f1 = 0.0
        else:
            p = float(_within(cand, oracle, t).mean())
            r = float(_within(oracle, cand, t).mean())
            f1 = 0.0 if p + r == 0 else 2 * p * r / (p + r)
        out[f"precision_{t}px"] = p
        out[f"recall_{t}px"] = r
        out[f"f1_{t}px"] = f1
    return out


#: Diff image colours: both drew, only the candidate drew, only the oracle drew.
DIFF_COLOURS = {"both": (255, 255, 255), "candidate_only": (255, 70, 70), "oracle_only": (60, 170, 255)}


def diff_image(cand: np.ndarray, oracle: np.ndarray) -> np.ndarray:
    """``(H, W, 3)`` uint8: white where both drew, red candidate-only, blue oracle-only."""
    cand = np.asarray(cand, bool)
    oracle = np.asarray(oracle, bool)
    img = np.zeros(cand.shape + (3,), np.uint8)
    img[cand & oracle] = DIFF_COLOURS["both"]
    img[cand & ~oracle] = DIFF_COLOURS["candidate_only"]
    img[~cand & oracle] = DIFF_COLOURS["oracle_only"]
    return img
