"""Error metrics: vertex errors between two projections, pixel agreement between two frames.

Pixel agreement follows the Khronos conformance idea for line rasterization:
at tolerance ``t`` a drawn pixel counts as matched when the other image has a
drawn pixel within Chebyshev distance ``t`` (t = 1: its 3x3 neighbourhood).

    precision@t = matched candidate pixels / candidate pixels
    recall@t    = matched oracle pixels    / oracle pixels
    F1@t        = 2 P R / (P + R)

Two blank images agree perfectly (F1 = 1); one blank and one not give 0.

A wireframe frame's metrics share one scan of each image (:class:`FramePixels`);
after it they work on the drawn pixels only, and a case's line metrics are
computed for its frames together (:class:`LineBatch`; the pairing of pixels
with segments is oracles.judge.segment_pixels).
"""

from __future__ import annotations

import numpy as np

from .. import tolerances
from ..references.pyrender_oracle import depth_step
from .frame_pixels import FramePixels
from .line_ends import PLACES, end_attribution, frames_end_places, resolve_ties  # noqa: F401
from .segment_pixels import edge_neighbourhoods, frames_count_differences, frames_neighbourhoods  # noqa: F401


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
        "candidate_only": int((cand_vis & ~orac_vis).sum()),  # shown by the candidate, clipped by the oracle
        "oracle_only": int((~cand_vis & orac_vis).sum()),  # clipped by the candidate, shown by the oracle
        "max_px": None,
        "mean_px": None,
        "rms_px": None,
        "worst_index": None,  # None: nothing compared
    }
    if both.any():
        err = np.hypot(*(cand_px[both] - oracle_px[both]).T)
        if not np.all(np.isfinite(err)):
            out.update(max_px=float("inf"), mean_px=float("inf"), rms_px=float("inf"))
            out["worst_index"] = int(np.flatnonzero(both)[np.flatnonzero(~np.isfinite(err))[0]])
            return out
        k = int(np.argmax(err))
        out.update(
            max_px=float(err[k]),
            mean_px=float(err.mean()),
            rms_px=float(np.sqrt((err**2).mean())),
            worst_index=int(np.flatnonzero(both)[k]),
        )
    return out


def vertex_errors_frames(cand_frames: list, oracle_frames: list) -> list[dict]:
    """:func:`vertex_errors` of several frames: ``[vertex_errors(c, o) for c, o in zip(...)]``, the same floats.

    Frames of one size whose points are all visible on both sides and finite
    are scored together (the row-wise reductions of a ``(F, N)`` array add
    each row as a 1-D array is added); the others one by one.
    """
    out: list = [None] * len(cand_frames)
    sizes = {np.shape(c) for c in cand_frames} | {np.shape(o) for o in oracle_frames}
    if len(sizes) == 1 and cand_frames and len(cand_frames[0]):
        c, o = np.stack(cand_frames), np.stack(oracle_frames)
        with np.errstate(invalid="ignore", over="ignore"):
            d = c - o
            err = np.hypot(d[..., 0], d[..., 1])
            whole = np.isfinite(c).all(axis=(1, 2)) & np.isfinite(o).all(axis=(1, 2)) & np.isfinite(err).all(axis=1)
        if whole.any():
            e = err[whole]
            k = np.argmax(e, axis=1)
            mx, mean, rms = e[np.arange(len(e)), k], e.mean(axis=1), np.sqrt((e**2).mean(axis=1))
            n = c.shape[1]
            for j, f in enumerate(np.flatnonzero(whole)):
                out[f] = {
                    "points": n,
                    "visible_both": n,
                    "candidate_only": 0,
                    "oracle_only": 0,
                    "max_px": float(mx[j]),
                    "mean_px": float(mean[j]),
                    "rms_px": float(rms[j]),
                    "worst_index": int(k[j]),
                }
    return [r if r is not None else vertex_errors(c, o) for r, c, o in zip(out, cand_frames, oracle_frames)]


def _within(mask_from: np.ndarray, mask_to: np.ndarray, tol: int) -> np.ndarray:
    """For each True pixel of ``mask_from`` (row-major order): is a True pixel of ``mask_to`` within ``tol`` (Chebyshev)?"""
    return FramePixels(mask_from, mask_to).within(tol)


#: The per-frame scores of :func:`pixel_scores` a case keeps, in report order.
PIXEL_SCORE_KEYS = ("f1_0px", "f1_1px", "precision_0px", "recall_0px", "precision_1px", "recall_1px")

#: The per-frame fields of a wireframe's line comparison (:func:`line_scores`) a case keeps, on both paths.
LINE_FRAME_KEYS = ("candidate_only", "oracle_only", "subpixel_ties", "edge_count_max_diff", "edge_count_worst_edge")


def pixel_scores(cand: np.ndarray, oracle: np.ndarray, tols=(0, 1), pixels: FramePixels | None = None) -> dict:
    """Precision, recall and F1 of ``cand`` against ``oracle`` (both (H, W) bool) at each tolerance.

    ``pixels``: the frame's :class:`FramePixels`, when the caller has it (then
    ``cand`` and ``oracle`` are not read).
    """
    fp = pixels if pixels is not None else FramePixels(cand, oracle)
    n_cand, n_orac = len(fp.cand_idx), len(fp.oracle_idx)
    out = {"candidate_pixels": n_cand, "oracle_pixels": n_orac, "both_pixels": fp.both}
    for t in tols:
        if not n_cand and not n_orac:
            p = r = f1 = 1.0
        elif not n_cand or not n_orac:
            p = 1.0 if not n_cand else 0.0
            r = 1.0 if not n_orac else 0.0
            f1 = 0.0
        else:
            # a count over a length: the float the mean of the bool array gives
            p = int(np.count_nonzero(fp.within(t, True))) / n_cand
            r = int(np.count_nonzero(fp.within(t, False))) / n_orac
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


def occlusion_boundary(ids: np.ndarray, triangles: np.ndarray, box=None) -> np.ndarray:
    """Pixels next to a pixel that shows a triangle sharing no vertex with theirs.

    ``ids`` is a triangle-id image (-1: none). Two triangles that share a vertex
    meet there, so depth is continuous across the line between them; between
    triangles that share none (an occluding object or fold in front of
    another) depth jumps, and which of the two a pixel centre within
    rounding of that line shows is decided by each renderer's rounding. Such
    pixels (one on each side) are left out of the depth comparison.

    Each unordered pair of 8-neighbours is taken once, within the rows and columns that hold a triangle
    (nothing is marked elsewhere; ``box``, two slices, when the caller has them), as a pair of flat positions
    ``(i, i + step)`` in that box with a column of -1 after each row (no pair wraps onto the next row), one
    direction at a time; only the pairs that show two triangles are compared (in int32 where the vertex
    numbers fit: half the bytes of int64).
    """
    ids = np.asarray(ids)
    out = np.zeros(ids.shape, bool)
    if box is None:
        shown = ids >= 0
        rows, cols = np.flatnonzero(shown.any(axis=1)), np.flatnonzero(shown.any(axis=0))
        if len(rows) == 0:
            return out
        box = np.s_[rows[0] : rows[-1] + 1, cols[0] : cols[-1] + 1]
    part = ids[box]
    h, w = part.shape
    corners = np.asarray(triangles).reshape(-1, 3)
    small = corners.size == 0 or (int(corners.max()) < 2**31 and len(corners) < 2**31)
    corners = np.ascontiguousarray(corners.T, dtype=np.int32 if small else np.int64)  # (3, T): each corner's row
    padded = np.full((h, w + 1), -1, dtype=corners.dtype)
    padded[:, :w] = part
    flat = padded.ravel()
    shows = flat >= 0
    apart = np.zeros(len(flat), bool)  # this pixel and its neighbour, of each pair sharing no vertex
    for dy, dx in _NEIGHBOURS[4:]:  # pixel (y, x) and its neighbour (y + dy, x + dx), dy >= 0
        step = dy * (w + 1) + dx
        n = len(flat) - step
        if n <= 0:  # one row: no pair below it
            continue
        a, b = flat[:n], flat[step:]
        first = np.flatnonzero((a != b) & shows[:n] & shows[step:])
        at_a, at_b = a[first], b[first]
        ta, tb = [c[at_a] for c in corners], [c[at_b] for c in corners]  # each row taken alone: 1-D takes are fast
        shared = ta[0] == tb[0]
        for i in range(3):  # nine 1-D comparisons: no (n, 3, 3) temporary
            for j in range(3):
                if i or j:
                    shared |= ta[i] == tb[j]
        first = first[~shared]
        apart[first] = True
        apart[first + step] = True
    out[box] = apart.reshape(h, w + 1)[:, :w]
    return out


def shaded_scores(
    cand_depth: np.ndarray,
    oracle_covered: np.ndarray,
    oracle_depth: np.ndarray,
    depth_bound: np.ndarray | None = None,
    exclude: np.ndarray | None = None,
    cand_faces: np.ndarray | None = None,
    oracle_faces: np.ndarray | None = None,
) -> dict:
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
    out = {
        "candidate_pixels": int(cand.sum()),
        "oracle_pixels": int(orac.sum()),
        "silhouette_iou": 1.0 if union == 0 else inter / union,
        "silhouette_union_px": union,
        "silhouette_mismatch_inside": int(inside.sum()),
        "depth_pixels": 0,
        "depth_max_error": None,
        "depth_mean_error": None,
        "depth_error_bound": None,
        "depth_error_ratio": None,
        "depth_worst_pixel": None,
        "face_disagreements": 0,
        "face_disagreements_inside": 0,
    }
    compared = interior(cand) & interior(orac) & cand & orac
    if exclude is not None:
        compared &= ~exclude
    if cand_faces is not None and oracle_faces is not None:
        cf = np.asarray(cand_faces)
        of = np.asarray(oracle_faces)
        disagree = cand & orac & (cf != of)
        near = np.zeros(cf.shape, bool)
        for dy, dx in _NEIGHBOURS:  # on a boundary between the two faces in either image
            near |= (_shifted(of, dy, dx, -2) == cf) | (_shifted(cf, dy, dx, -2) == of)
        out["face_disagreements"] = int(disagree.sum())
        out["face_disagreements_inside"] = int((disagree & ~near).sum())
        compared &= ~disagree
    if compared.any():
        err = np.abs(cand_depth[compared] - np.asarray(oracle_depth, np.float64)[compared])
        k = int(np.argmax(err))
        idx = np.flatnonzero(compared.ravel())
        out.update(
            depth_pixels=int(compared.sum()),
            depth_max_error=float(err[k]),
            depth_mean_error=float(err.mean()),
            depth_worst_pixel=[int(idx[k] // cand.shape[1]), int(idx[k] % cand.shape[1])],
        )
        if depth_bound is not None:
            bound = np.asarray(depth_bound, np.float64)[compared]
            out["depth_error_bound"] = float(bound[k])
            with np.errstate(divide="ignore", invalid="ignore"):
                ratio = np.where(err == 0, 0.0, err / bound)
            out["depth_error_ratio"] = float(ratio.max())
    return out


def depth_slope(depth: np.ndarray, covered: np.ndarray, box=None) -> np.ndarray:
    """Largest |depth change| to a covered 4-neighbour, per pixel (0 where none).

    Each neighbouring pair's change is taken once, across columns then rows, and given to both
    pixels of the pair (``fmax`` keeps 0 where the change is NaN: a pixel not covered); an infinite
    change is the largest float, as ``nan_to_num`` made it. Taken over the covered pixels' bounding box
    (0 outside it: no pair there has two covered pixels); ``box``: that box (two slices), when the caller has
    it."""
    covered = np.asarray(covered, bool)
    out = np.zeros(covered.shape)
    if box is None:
        rows, cols = np.flatnonzero(covered.any(axis=1)), np.flatnonzero(covered.any(axis=0))
        if len(rows) == 0:
            return out
        box = np.s_[rows[0] : rows[-1] + 1, cols[0] : cols[-1] + 1]  # every pair with a change lies within
    d = np.array(np.asarray(depth, np.float64)[box])  # the depth with NaN where not covered
    np.copyto(d, np.nan, where=~covered[box])
    slope = out[box]
    h, w = d.shape
    change = np.empty(max(h * (w - 1), (h - 1) * w))  # each direction's changes in turn
    with np.errstate(invalid="ignore"):
        for first, second in ((np.s_[:, :-1], np.s_[:, 1:]), (np.s_[:-1], np.s_[1:])):
            step = change[: d[first].size].reshape(d[first].shape)
            np.subtract(d[second], d[first], out=step)
            np.abs(step, out=step)
            np.fmax(slope[first], step, out=slope[first])
            np.fmax(slope[second], step, out=slope[second])
    np.minimum(slope, np.finfo(np.float64).max, out=slope)  # an infinite change: the largest float
    return out


def depth_bound(depth: np.ndarray, covered: np.ndarray, camera, slope: np.ndarray | None = None) -> np.ndarray:
    """Per-pixel bound on |z_candidate - z_oracle| for the oracle's ``depth`` (oracles.tolerances);
    ``slope``: :func:`depth_slope` of ``depth`` and ``covered`` when the caller has it already.

    ``DEPTH_STEPS x depth_step + DEPTH_SNAP_PX x slope + DEPTH_EPS32 x eps32 x |depth|``, summed in that order
    into one array."""
    depth = np.asarray(depth, np.float64)
    eps32 = float(np.finfo(np.float32).eps)
    out = depth_step(depth, camera)
    out *= tolerances.DEPTH_STEPS
    out += tolerances.DEPTH_SNAP_PX * (depth_slope(depth, covered) if slope is None else slope)
    term = np.abs(depth)
    term *= tolerances.DEPTH_EPS32 * eps32
    out += term
    return out


# ---------------------------------------------------------------- one-sided pixels and per-edge counts


def sign_test_p(k: int, n: int) -> float:
    """Two-sided sign-test p-value: ``k`` of ``n`` differing pixels candidate-only, each with p = 1/2 under H0.

    ``2 P(X <= min(k, n - k))`` for ``X ~ Binomial(n, 1/2)`` (the distribution is
    symmetric, so this is the exact two-sided test), capped at 1; 1 when ``n = 0``.
    """
    if n <= 0:
        return 1.0
    from scipy.special import bdtr  # the binomial CDF; scipy.stats costs ~1 s to import

    return float(min(1.0, 2.0 * bdtr(min(k, n - k), n, 0.5)))


def pixel_balance(cand: np.ndarray, oracle: np.ndarray) -> dict:
    """Pixels drawn by one image only: ``candidate_only``, ``oracle_only`` and ``imbalance`` (their difference)."""
    cand = np.asarray(cand, bool)
    oracle = np.asarray(oracle, bool)
    c = int((cand & ~oracle).sum())
    o = int((oracle & ~cand).sum())
    return {"candidate_only": c, "oracle_only": o, "imbalance": c - o}


def balance_scores(candidate_only: int, oracle_only: int, oracle_pixels: int, ties=(0, 0)) -> dict:
    """A case's pooled balance: the net imbalance, as a fraction of the oracle's pixels, and its sign-test p.

    ``ties``: how many of the candidate-only and of the oracle-only pixels are
    sub-pixel ties (oracles.judge.line_ties), reported as ``subpixel_ties`` and left
    out of ``imbalance``, its fraction and the sign test: those are over the
    decided one-sided pixels only.
    """
    tc, to = (int(t) for t in ties)
    c, o = candidate_only - tc, oracle_only - to
    return {
        "candidate_only": int(candidate_only),
        "oracle_only": int(oracle_only),
        "subpixel_ties": [tc, to],
        "imbalance": int(c - o),
        "imbalance_fraction": (c - o) / max(oracle_pixels, 1),
        "balance_p_value": sign_test_p(c, c + o),
    }


def edge_counts(image: np.ndarray, near: tuple, n_edges: int) -> np.ndarray:
    """``(n_edges,)`` int: each edge's length in drawn pixels, counted along its major axis.

    ``near`` is :func:`edge_neighbourhoods`' output. An edge's count is the
    number of distinct major-axis coordinates among the drawn pixels near it:
    what a 1-px line of it covers, as in Khronos' per-line count, without
    rendering lines singly. Which pixel a renderer takes at a major
    coordinate (a tie across the line) does not change it; a pixel more or
    less at an end does. A pixel counts for the nearest line only, in both
    images alike (at a shared vertex or a crossing the lines share out the
    pixels near it by distance).
    """
    return _counts(np.asarray(image, bool).reshape(-1)[near[1]], near, n_edges)


def _counts(drawn: np.ndarray, near: tuple, n_edges: int) -> np.ndarray:
    """:func:`edge_counts` given, for each of ``near``'s rows, whether its pixel is drawn."""
    edge, _pix, major = near
    span = int(major.max()) + 1 if len(major) else 1
    keys = np.sort(edge[drawn] * span + major[drawn])
    distinct = np.ones(len(keys), bool)
    distinct[1:] = keys[1:] != keys[:-1]
    return np.bincount(keys[distinct] // span, minlength=n_edges)[:n_edges]


def edge_count_scores(cand: np.ndarray, oracle: np.ndarray, near: tuple, n_edges: int) -> dict:
    """Per-edge pixel counts of both images (:func:`edge_counts`): the largest difference, and where."""
    return _count_scores(edge_counts(cand, near, n_edges), edge_counts(oracle, near, n_edges))


def _count_scores(cc: np.ndarray, oc: np.ndarray) -> dict:
    """:func:`edge_count_scores` of the two images' per-edge counts."""
    return _diff_scores(cc - oc, int(((cc > 0) | (oc > 0)).sum()))


def _diff_scores(diff: np.ndarray, compared: int) -> dict:
    """:func:`edge_count_scores` of the per-edge count differences and the number of edges counted."""
    n_edges = len(diff)
    k = int(np.argmax(np.abs(diff))) if n_edges else 0
    return {
        "edges_compared": compared,
        "edge_count_max_diff": int(abs(diff[k])) if n_edges else 0,
        "edge_count_worst_edge": k if n_edges and diff[k] != 0 else None,
        "edge_count_worst_diff": int(diff[k]) if n_edges else 0,
        "edge_count_diff_sum": int(diff.sum()),
        "edge_count_diffs": diff,
    }


def line_scores(
    cand: np.ndarray,
    oracle: np.ndarray,
    p0_px: np.ndarray,
    p1_px: np.ndarray,
    pixels: FramePixels | None = None,
    counts: tuple | None = None,
    ends: dict | None = None,
    ties: tuple | None = None,
    resolved: FramePixels | None = None,
) -> dict:
    """One wireframe frame against the oracle's: one-sided pixels, per-edge counts, where the one-sided lie.

    ``p0_px, p1_px`` : (E, 2) the oracle's segments of the drawn edges (NaN
    rows: not drawn). Returns :func:`pixel_balance`'s fields,
    :func:`edge_count_scores`' (without the per-edge array), ``ends``
    (:func:`end_attribution`, the decided one-sided pixels),
    ``subpixel_ties`` (``[candidate_only, oracle_only]``: those that are
    sub-pixel ties, oracles.judge.line_ties) and ``tie_resolved``: None when the
    frame has no tie, else the frame's F1, precision and recall at 0 px
    (``f1_0px``, ``precision_0px``, ``recall_0px``) with the candidate given
    the oracle's value at every tie (oracles.judge.line_ends.resolve_ties); the
    per-edge counts are always taken so. A tie is undecided in every criterion.

    ``pixels``: the frame's :class:`FramePixels`, when the caller has it (then
    ``cand`` and ``oracle`` are not read); ``counts``: ``(diff, compared)``,
    the per-edge count differences (ties resolved) and the number of edges
    counted, when the caller has them (:func:`frames_count_differences`,
    :class:`LineBatch`); ``ends`` and ``ties``: the frame's
    :func:`frames_end_places` and its tie pixels, when the caller has them;
    ``resolved``: ``resolve_ties(pixels, ties)``, when the caller has it.
    """
    fp = pixels if pixels is not None else FramePixels(cand, oracle)
    h, w = fp.shape
    both = fp.both
    c, o = len(fp.cand_idx) - both, len(fp.oracle_idx) - both
    out = {"candidate_only": c, "oracle_only": o, "imbalance": c - o, "oracle_pixels": len(fp.oracle_idx)}
    if ends is None:
        found: list = []
        ends = frames_end_places([(fp, p0_px, p1_px)], found)[0] if c + o else {k: [0, 0] for k in PLACES}
        ties = found[0] if found else None
    if resolved is not None:  # the caller's resolve_ties(fp, ties)
        rp = resolved
    else:
        rp = resolve_ties(fp, ties) if ties is not None else fp  # the candidate as the oracle at the ties
    if counts is None:
        near = edge_neighbourhoods(p0_px, p1_px, w, h, pixels=rp.drawn())  # counts look at drawn pixels only
        n_edges = len(np.asarray(p0_px).reshape(-1, 2))
        cc = _counts(rp.has(near[1], True), near, n_edges)
        ec = _count_scores(cc, cc if rp.identical else _counts(rp.has(near[1], False), near, n_edges))
    else:
        ec = _diff_scores(*counts)
    del ec["edge_count_diffs"]
    out.update(ec)
    ends = dict(ends)
    out["subpixel_ties"] = ends.pop("tie")
    out["ends"] = ends
    out["tie_resolved"] = None
    if rp is not fp:
        ps = pixel_scores(None, None, tols=(0,), pixels=rp)
        out["tie_resolved"] = {k: ps[k] for k in ("f1_0px", "precision_0px", "recall_0px")}
    return out


class LineBatch:
    """Wireframe frames waiting for their :func:`line_scores`, scored together.

    The per-edge counts (:func:`frames_count_differences`: only where the
    frames differ, and each edge's midpoint) of a frame of ~1,000 drawn
    pixels cost mostly numpy's per-call overhead, so a case's frames are
    counted in one pass. A frame waits until
    :meth:`flush`, or until the waiting frames hold ``limit`` pixels and
    segments (memory stays bounded on large meshes: a 100k-edge frame goes
    alone).
    """

    def __init__(self, limit: int = 1 << 18):
        self.limit = limit
        self._waiting: list = []
        self._size = 0

    def add(self, key, pixels: FramePixels, p0_px: np.ndarray, p1_px: np.ndarray) -> list:
        """Queue a frame (``key``: the caller's, given back); ``[(key, line_scores)]`` of the frames flushed."""
        self._waiting.append((key, pixels, p0_px, p1_px))
        self._size += len(pixels.cand_idx) + len(pixels.oracle_idx) + len(p0_px)
        return self.flush() if self._size >= self.limit else []

    def flush(self) -> list:
        """``[(key, line_scores)]`` of every waiting frame, in the order they came."""
        out, waiting = [], self._waiting
        self._waiting, self._size = [], 0
        start = 0
        while start < len(waiting):  # runs of one image size, paired together
            shape = waiting[start][1].shape
            stop = start
            while stop < len(waiting) and waiting[stop][1].shape == shape:
                stop += 1
            run = waiting[start:stop]
            ties: list = []
            if all(fp.ends is not None for _, fp, _, _ in run):  # made with the frames (FramePixels.ends)
                ends = [fp.ends[0] for _, fp, _, _ in run]
                ties = [fp.ends[1] for _, fp, _, _ in run]
            else:
                ends = frames_end_places([(fp, p0, p1) for _, fp, p0, p1 in run], ties)
            resolved = [resolve_ties(fp, t) for (_, fp, _, _), t in zip(run, ties)]  # once a frame
            counts = frames_count_differences(
                [(p0, p1, rp) for (_, _, p0, p1), rp in zip(run, resolved)],
                shape[1],
                shape[0],
                known=[fp.owners for _, fp, _, _ in run],
            )  # counted with the ties undecided
            for _, fp, _, _ in run:
                fp.owners = fp.ends = None  # used: not kept with the frame's pixels
            out.extend(
                (key, line_scores(None, None, p0, p1, pixels=fp, counts=c, ends=e, ties=t, resolved=rp))
                for (key, fp, p0, p1), c, e, t, rp in zip(run, counts, ends, ties, resolved)
            )
            start = stop
        return out


def line_summary(frames: list) -> dict:
    """A case's line fields pooled over its frames' :func:`line_scores` (``[(frame, scores)]``)."""
    c = sum(s["candidate_only"] for _, s in frames)
    o = sum(s["oracle_only"] for _, s in frames)
    ties = [sum(s["subpixel_ties"][i] for _, s in frames) for i in (0, 1)]
    out = balance_scores(c, o, sum(s["oracle_pixels"] for _, s in frames), ties)
    k, worst = max(frames, key=lambda e: (e[1]["edge_count_max_diff"], -e[0])) if frames else (None, None)
    ends = {p: [sum(s["ends"][p][i] for _, s in frames) for i in (0, 1)] for p in ("start", "end", "middle", "stray")}
    out.update(
        edge_count_max_diff=worst["edge_count_max_diff"] if worst else 0,
        edge_count_worst={"frame": k, "edge": worst["edge_count_worst_edge"], "diff": worst["edge_count_worst_diff"]}
        if worst
        else None,
        lines_compared=int(sum(s["edges_compared"] for _, s in frames)),
        one_sided_by_place=ends,
    )
    return out
