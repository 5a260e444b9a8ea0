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


#: The per-frame scores of :func:`pixel_scores` a case keeps, in report order.
PIXEL_SCORE_KEYS = ("f1_0px", "f1_1px", "precision_0px", "recall_0px", "precision_1px", "recall_1px")


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


# ---------------------------------------------------------------- shaded frames: silhouette and depth

_NEIGHBOURS = ((-1, -1), (-1, 0), (-1, 1), (0, -1), (0, 1), (1, -1), (1, 0), (1, 1))


def _shifted(a: np.ndarray, dy: int, dx: int, fill) -> np.ndarray:
    """``out[y, x] = a[y + dy, x + dx]``, ``fill`` outside the image."""
    out = np.full_like(a, fill)
    h, w = a.shape
    ys, yd = (slice(dy, h), slice(0, h - dy)) if dy >= 0 else (slice(0, h + dy), slice(-dy, h))
    xs, xd = (slice(dx, w), slice(0, w - dx)) if dx >= 0 else (slice(0, w + dx), slice(-dx, w))
    out[yd, xd] = a[ys, xs]
    return out


def interior(mask: np.ndarray) -> np.ndarray:
    """Pixels of ``mask`` whose 8 neighbours are all in it (erosion by 1 px; outside the image counts as in)."""
    out = mask.copy()
    for dy, dx in _NEIGHBOURS:
        out &= _shifted(mask, dy, dx, True)
    return out


def occlusion_boundary(ids: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """Pixels next to a pixel that shows a triangle sharing no vertex with theirs.

    ``ids`` is a triangle-id image (-1: none). Two triangles that share a vertex
    meet there, so depth is continuous across the line between them; between
    triangles that share none (an occluding object or fold in front of
    another) depth jumps, and which of the two a pixel centre within
    rounding of that line shows is decided by each renderer's rounding. Such
    pixels (one on each side) are left out of the depth comparison.
    """
    out = np.zeros(ids.shape, bool)
    triangles = np.asarray(triangles).reshape(-1, 3)
    for dy, dx in _NEIGHBOURS[4:]:         # each unordered neighbour pair once; mark both ends
        other = _shifted(ids, dy, dx, -1)
        m = (ids != other) & (ids >= 0) & (other >= 0)
        if not m.any():
            continue
        a, b = triangles[ids[m]], triangles[other[m]]
        apart = ~(a[:, :, None] == b[:, None, :]).any(axis=(1, 2))
        hit = np.zeros(ids.shape, bool)
        hit[m] = apart                                   # this pixel, whose neighbour (dy, dx) is apart
        out |= hit | _shifted(hit, -dy, -dx, False)      # and that neighbour
    return out


def shaded_scores(cand_depth: np.ndarray, oracle_covered: np.ndarray, oracle_depth: np.ndarray,
                  depth_bound: np.ndarray | None = None, exclude: np.ndarray | None = None,
                  cand_faces: np.ndarray | None = None, oracle_faces: np.ndarray | None = None) -> dict:
    """Silhouette IoU and depth errors of a shaded frame against the oracle's.

    ``cand_depth``: the candidate's camera depth, +inf (or NaN) where nothing
    covers the pixel; ``oracle_covered`` / ``oracle_depth``: the oracle's
    coverage and camera depth. Depth is compared over the pixels covered by
    both whose 8 neighbours are covered by both (no silhouette pixel of
    either), minus ``exclude`` (occlusion boundaries). With ``cand_faces`` and
    ``oracle_faces`` (the polygon each shows, -1: none), depth is compared only
    where both show the same polygon: where they differ, the two renderers made
    a different *visibility* decision, which is legitimate only on a boundary
    between the two polygons (a pixel centre within rounding of the line where
    one face passes in front of another; e.g. faces meeting at a vertex, seen
    from inside, with one of them cut by the near plane). Such pixels are
    counted in ``face_disagreements``; those on no boundary between the two
    polygons (no 3x3 neighbour where the oracle shows the candidate's polygon,
    nor where the candidate shows the oracle's; a face seen edge-on is a
    1-px sliver in one image) are ``face_disagreements_inside`` and must be 0:
    a wrong face in the middle of a region is a visibility error.
    ``depth_bound`` (per
    pixel, same shape) turns the errors into ``depth_error_ratio`` = max of
    error / bound (<= 1: within the bound); ``depth_error_bound`` is the bound
    at the pixel of ``depth_max_error``.
    """
    cand_depth = np.asarray(cand_depth, dtype=np.float64)
    cand = np.isfinite(cand_depth)
    orac = np.asarray(oracle_covered, bool)
    if cand.shape != orac.shape:
        raise ValueError(f"image shapes differ: {cand.shape} vs {orac.shape}")
    union = int((cand | orac).sum())
    inter = int((cand & orac).sum())
    # Pixels covered by one image only that are interior in it (all 8 neighbours
    # covered there): not a boundary decision but a hole or a misplaced region.
    only = cand ^ orac
    inside = (only & cand & interior(cand)) | (only & orac & interior(orac))
    out = {"candidate_pixels": int(cand.sum()), "oracle_pixels": int(orac.sum()),
           "silhouette_iou": 1.0 if union == 0 else inter / union, "silhouette_union_px": union,
           "silhouette_mismatch_inside": int(inside.sum()),
           "depth_pixels": 0, "depth_max_error": None, "depth_mean_error": None, "depth_error_bound": None,
           "depth_error_ratio": None, "depth_worst_pixel": None,
           "face_disagreements": 0, "face_disagreements_inside": 0}
    compared = interior(cand) & interior(orac) & cand & orac
    if exclude is not None:
        compared &= ~exclude
    if cand_faces is not None and oracle_faces is not None:
        cf = np.asarray(cand_faces)
        of = np.asarray(oracle_faces)
        disagree = cand & orac & (cf != of)
        near = np.zeros(cf.shape, bool)
        for dy, dx in _NEIGHBOURS:     # on a boundary between the two faces in either image
            near |= (_shifted(of, dy, dx, -2) == cf) | (_shifted(cf, dy, dx, -2) == of)
        out["face_disagreements"] = int(disagree.sum())
        out["face_disagreements_inside"] = int((disagree & ~near).sum())
        compared &= ~disagree
    if compared.any():
        err = np.abs(cand_depth[compared] - np.asarray(oracle_depth, np.float64)[compared])
        k = int(np.argmax(err))
        idx = np.flatnonzero(compared.ravel())
        out.update(depth_pixels=int(compared.sum()), depth_max_error=float(err[k]),
                   depth_mean_error=float(err.mean()),
                   depth_worst_pixel=[int(idx[k] // cand.shape[1]), int(idx[k] % cand.shape[1])])
        if depth_bound is not None:
            bound = np.asarray(depth_bound, np.float64)[compared]
            out["depth_error_bound"] = float(bound[k])
            with np.errstate(divide="ignore", invalid="ignore"):
                ratio = np.where(err == 0, 0.0, err / bound)
            out["depth_error_ratio"] = float(ratio.max())
    return out


def depth_slope(depth: np.ndarray, covered: np.ndarray) -> np.ndarray:
    """Largest |depth change| to a covered 4-neighbour, per pixel (0 where none)."""
    d = np.where(covered, np.asarray(depth, np.float64), np.nan)
    slope = np.zeros(d.shape)
    for dy, dx in ((0, 1), (0, -1), (1, 0), (-1, 0)):
        with np.errstate(invalid="ignore"):
            slope = np.fmax(slope, np.abs(_shifted(d, dy, dx, np.nan) - d))
    return np.nan_to_num(slope, nan=0.0)


def depth_bound(depth: np.ndarray, covered: np.ndarray, camera) -> np.ndarray:
    """Per-pixel bound on |z_candidate - z_oracle| for the oracle's ``depth`` (oracles.tolerances)."""
    from . import tolerances
    from .pyrender_oracle import depth_step

    depth = np.asarray(depth, np.float64)
    eps32 = float(np.finfo(np.float32).eps)
    return (tolerances.DEPTH_STEPS * depth_step(depth, camera)
            + tolerances.DEPTH_SNAP_PX * depth_slope(depth, covered)
            + tolerances.DEPTH_EPS32 * eps32 * np.abs(depth))
