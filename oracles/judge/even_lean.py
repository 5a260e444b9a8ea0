"""Binary lines of an even width: a centreline known only to half a pixel either side, fitted edge by edge.

A binary band ``n`` pixels across (``n`` odd) can centre itself on the pixel
nearest the exact line; one of an even width cannot: the exact line falls
between its two middle pixels only when it lies on a pixel boundary, and
otherwise the renderer must choose on which side the extra half pixel goes.
Along the minor axis (``e`` the exact line's coordinate at a step, ``h = n /
2 / |n_minor|`` the band's half extent there), the three correct choices are
the pixels whose centres lie in

- ``[e - h, e + h]``: symmetric (``n`` or ``n + 1`` pixels; the reference of
  :func:`oracles.judge.line_style._reference`);
- ``[e + 1/2 - h, e + 1/2 + h]`` or ``[e - 1/2 - h, e - 1/2 + h]``: the band
  leaning half a pixel to one side (exactly ``n`` pixels but at a tie).

Pillow's ``ImageDraw.line(width=2)`` leans to the right of the direction it
draws each line in (measured: 0.49-0.50 px along the normal for lines within
30 degrees of an axis, 0.06-0.17 px nearer the diagonal), so the side differs
from edge to edge with the order the renderer takes the ends in, which the
image does not say. Its ends rounded to pixel centres first, a leaning line of
the ``[e + 1/2 - h, e + 1/2 + h]`` band is pixel for pixel Pillow's on axis-
aligned lines: a line up to 1.0 px off its exact position (0.5 rounding, 0.5
lean) and still correct. Pillow's width 2 draws lines within 30 degrees of an
axis about 1.2 pixels across: their median width reads 1.0-1.7, so binary
lines are also read wide where they draw :attr:`oracles.tolerances.NamingThresholds.wide_pixel_ratio` times the
oracle's pixels (:meth:`oracles.judge.line_style.CaseStyle.classify`).

So each edge's centre is known only up to that choice. Its measured centres
less each choice's (:func:`reference_offsets`) give three residuals per edge
(their means over the edge's samples, which average out the band's
quantisation along it), and one offset ``d`` for the whole case is fitted
with each edge taking the choice nearest ``n . d`` (:func:`fit`): on a grid of
``d``, taken only where it explains the edges' means better than ``d = 0``
(each edge its nearest choice there) by more than the ends' rounding would 99
times in 100 (:data:`EDGE_NOISE_PX2`, :data:`CHI2_2_P99`, over the case's
effective number of edges), then refined by least squares with those choices.

The fit (``leaning``) explains the edges' means better than the symmetric band
by ``NAMING.lean_gain_px2`` (or the edges are too few to test the symmetric band,
``NAMING.max_untested_edges``; oracles.tolerances); it replaces the symmetric band's measure only
where that one fails the case (an offset past the binary lines' 0.35 px or a
warp past theirs: :meth:`oracles.judge.line_style.CaseStyle.geometry`,
``geometry["lean"]["used"]``), the lean being the last explanation: a renderer of
symmetric even bands, and every odd width, keep the measure of
:mod:`oracles.judge.line_style` unchanged, so a symmetric band moved by half
a pixel (which bands leaning with the move would explain at ``d = 0`` on
axis-aligned lines only) is still measured as moved, to 0.02 px.

What stays sharp: ``d`` is one offset for every edge, so a leaning renderer's
lines moved by half a pixel read about half a pixel wherever its edges lean
both ways about the move (an edge leaning with the move sits a whole pixel
off, which no choice at ``d = 0`` explains). What an even-width image cannot
show: a move of half a pixel across edges that all lean against it is pixel
for pixel a correct drawing leaning the other way (the ``[e - 1/2 ...]`` and
``[e + 1/2 ...]`` bands of lines half a pixel apart are the same pixels), and
then the smaller offset is read; with rounded ends (Pillow) a half-pixel move
reads 0.3-0.9 px (each end moves 0 or 1 px), and a move along lines near an
axis is absorbed by their leans.
"""

from __future__ import annotations

import numpy as np

from ..tolerances import NAMING
from .line_profile import pooled_offset

#: How far (px, along the minor axis) an even band may lean off the exact line: half a pixel.
LEAN_PX = 0.5
#: The offsets tried (px, each axis) before the least-squares refinement: a whole band-step either way
#: of a 2-px line's largest correct offset (1.0 px: rounding and lean), at a twentieth of a pixel.
GRID_REACH_PX = 2.0
GRID_STEP_PX = 0.05
#: The noise of an edge's mean offset (px^2) for a renderer that rounds the ends to pixel centres first
#: (Pillow): each end moved by up to half a pixel per coordinate, uniformly (variance 1/12 along the
#: normal), the edge's mean offset by their mean (1/24).
EDGE_NOISE_PX2 = 1.0 / 24.0
#: The 99th percentile of chi-square with 2 degrees of freedom (-2 ln 0.01): what fitting an offset
#: ``(dx, dy)`` gains on edges of pure noise, in units of that noise over the edges, 1 time in 100.
CHI2_2_P99 = -2.0 * np.log(0.01)
#: What a case record keeps of the fit (line_style.geometry: ``geometry["lean"]``).
REPORTED = (
    "leaning",
    "offset_px",
    "ms",
    "ms_symmetric",
    "leaning_edges",
    "edges",
    "edges_eff",
    "gain_px2",
    "evidence_px2",
)


def reference_offsets(normal: np.ndarray, point: np.ndarray, band_px: int) -> np.ndarray:
    """``(3, M)``: each sample's centroid offset (px, along ``normal``) of the band ``band_px`` pixels
    across leaning ``-1/2``, ``0`` and ``+1/2`` px on the minor axis (module docstring), at the exact
    line's ``point``: the centroid of the whole pixel coordinates in ``[e + s - h, e + s + h]``."""
    minor = (np.abs(normal[:, 1]) > np.abs(normal[:, 0])).astype(np.intp)
    k = np.arange(len(normal))
    across, e = normal[k, minor], point[k, minor]
    half = band_px / 2.0 / np.maximum(np.abs(across), 1e-12)
    out = np.empty((3, len(e)))
    for i, s in enumerate((-LEAN_PX, 0.0, LEAN_PX)):
        lo, hi = np.ceil(e + s - half - 1e-9), np.floor(e + s + half + 1e-9)
        out[i] = ((lo + hi) / 2.0 - e) * across
    return out


def _edge_means(edge: np.ndarray, values: np.ndarray):
    """``(keys, counts, means (len(values), E))`` of ``values (S, M)`` per edge key."""
    keys, inv, counts = np.unique(edge, return_inverse=True, return_counts=True)
    sums = np.zeros((values.shape[0], len(keys)))
    for i in range(values.shape[0]):
        sums[i] = np.bincount(inv, weights=values[i], minlength=len(keys))
    return keys, inv, counts, sums / counts


def fit(normal: np.ndarray, offset: np.ndarray, point: np.ndarray, edge: np.ndarray, band_px: int):
    """The case's offset with each edge's lean chosen (module docstring), or None (too few samples).

    ``normal``, ``offset``, ``point``, ``edge``: the pooled samples of
    :func:`oracles.judge.line_style.measure` (``edge``: a key per frame and
    segment). Returns ``{"offset" (2,), "ms" (mean square residual, px^2),
    "ms_symmetric", "leaning_edges", "edges", "corrected"}``: ``corrected`` the
    samples' offsets less their edge's chosen band's (``d`` plus noise where
    the fit holds; what the affine warp is measured on).
    """
    if len(offset) < NAMING.profile_min_samples:
        return None
    refs = reference_offsets(normal, point, band_px)
    resid = offset[None] - refs  # (3, M): -1/2, 0, +1/2
    keys, inv, counts, means = _edge_means(edge, resid)
    n_edge = np.zeros((len(keys), 2))
    n_edge[inv] = normal  # one normal per segment
    used = counts >= NAMING.min_edge_samples
    if used.sum() == 0:
        return None
    w, r, n = counts[used].astype(float), means[:, used], n_edge[used]
    total = float(counts.sum())
    # the symmetric band alone: the least-squares offset over the edges' means and what it leaves
    sw = np.sqrt(w)
    d_sym, *_ = np.linalg.lstsq(n * sw[:, None], r[1] * sw, rcond=None)
    ms_sym = float(w @ (r[1] - n @ d_sym) ** 2) / w.sum()
    # every edge its nearest lean, one offset: the best on a grid, taken only where it explains the edges
    # better than no offset (each edge its nearest lean at d = 0) by more than EDGE_NOISE_PX2 would, 99
    # times in 100, over the case's edges (their effective number: the weights' (sum w)^2 / sum w^2)
    g = np.arange(-GRID_REACH_PX, GRID_REACH_PX + 1e-9, GRID_STEP_PX)
    grid = np.stack(np.meshgrid(g, g, indexing="ij"), axis=-1).reshape(-1, 2)
    cost = np.min((r[:, :, None] - (n @ grid.T)[None]) ** 2, axis=0)  # (E, G): each edge's nearest lean
    between = (w @ cost) / w.sum()  # per sample, between the edges' means
    gain = float(w @ np.min(r**2, axis=0)) / w.sum() - float(between.min())
    edges_eff = float(w.sum() ** 2 / (w**2).sum())
    evidence = CHI2_2_P99 * EDGE_NOISE_PX2 / edges_eff
    tied = np.flatnonzero(between <= between.min() + 1e-12)  # equal fits (a flat direction): the smallest
    best = grid[tied[np.argmin(np.hypot(grid[tied, 0], grid[tied, 1]))]] if gain > evidence else np.zeros(2)
    choice = np.argmin((r - (n @ best)[None]) ** 2, axis=0)  # (E_used,) 0, 1, 2
    edge_choice = np.ones(len(keys), np.intp)  # edges with too few samples: symmetric
    edge_choice[np.flatnonzero(used)] = choice
    corrected = resid[edge_choice[inv], np.arange(len(offset))]
    d, _ = pooled_offset(normal, corrected)
    ms = float(w @ (r[choice, np.arange(len(w))] - n @ d) ** 2) / w.sum()
    # the leaning bands replace the symmetric one where they explain the edges better, or where the edges
    # cannot test the symmetric band (two numbers fitted to at most NAMING.max_untested_edges edges' worth)
    leaning = ms < ms_sym - NAMING.lean_gain_px2 or edges_eff <= NAMING.max_untested_edges
    return {
        "leaning": bool(leaning),
        "offset": d,
        "offset_px": [float(v) for v in d],
        "ms": ms,
        "ms_symmetric": ms_sym,
        "leaning_edges": int((choice != 1).sum()),
        "gain_px2": gain,
        "evidence_px2": evidence,
        "edges": int(used.sum()),
        "edges_eff": edges_eff,
        "samples": int(total),
        "corrected": corrected,
    }
