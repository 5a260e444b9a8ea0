r"""Filled silhouettes under GL's fill rule, with the pixel centres that no renderer decides (ties).

Pixel convention (core.conventions): x right, y down, integer coordinates are pixel centres.
Written here from the rule, in float64, sharing no code with core's rasterizer.

The fill rule
=============
A pixel is covered when its centre is inside a triangle. With the triangle oriented so that
the edge functions ``E(p) = (Q - P) x (p - P) = (Qx - Px)(py - Py) - (Qy - Py)(px - Px)`` of
its edges ``P -> Q`` are positive inside, a centre is inside when every ``E > 0``, or
``E == 0`` on a **top** edge (horizontal, ``Qx > Px``: the interior below it) or a **left**
edge (``Qy < Py``: the interior to its right). Zero-area triangles cover nothing::

    (0,0) top   (4,0)        the right triangle (0,0), (4,0), (0,4): centres on the top
      * * * * o              edge (y = 0) and the left edge (x = 0) are in, those on the
      * * * o                hypotenuse x + y = 4 are out; every centre on an edge is a tie
      * * o
      * o                    * covered   o on the hypotenuse, not covered
      o

Ties
====
A renderer rounds each vertex before it decides (GL snaps to 1/256 px after float32
arithmetic): each vertex may move by ``tie_px`` (Euclidean), so every point of an edge moves
by at most ``tie_px``, and a centre farther than that from every edge is decided as here. A
centre within ``tie_px`` of an **open** edge is a tie (either answer is correct) unless some
triangle holds it farther than ``tie_px`` from all of that triangle's edges. An edge is
*closed* when triangles on both of its sides share it (the same two end points, in the
image, to the bit): those triangles' shared ends move together, so no centre near it can fall
into a crack and the union of the two covers it whatever the rounding; every other edge
(the silhouette's contour, an open mesh's border, a near-plane cut, a T-junction) is open.

``tie_px`` is :data:`GL_TIE_PX` unless given: ``sqrt(2) x oracles.tolerances.TIE_END_PX``
(the per-coordinate move of a GL vertex, derived there) as a distance.

Object ids (:func:`silhouette`): at each covered centre, the object of the nearest triangle
(depth along ``forward``: ``1/z`` is linear in the image under perspective, ``z`` under
orthographic). Where the two nearest objects' depths are within their depth bounds
(:func:`depth_bound`), the pixel's id is :data:`ID_TIE` (either object is correct).

Coverage and ties are taken one box row at a time (boxes clipped to the image, grown by
``tie_px``): along a row each edge function, evaluated in float64 as the rule writes it, is
monotone, so a triangle's centres on the row are a span, found from the edge lines' crossings
and checked with the edge functions themselves at its ends; the work scales with the rows the
triangles cover, and the centres are the same, bit for bit, as a per-centre pass
(tests/test_fill_rule.py's naive pass). Only the few centres within ``tie_px`` of an open
edge's line are measured against the segment. :func:`silhouette` may be given a guess of the
triangle covering each centre (pyrender's triangle ids): each run of one guess along a row is
checked by the rule at its two ends, and only the box rows that hold a centre not held so are
taken as spans (the same result, whatever the guess). With several objects, a
per-centre pass over batches of boxes of like size keeps every covered centre's depth and
object, and one sort finds each pixel's nearest two objects
(``benchmarks/bench_fill_rule.py``: 100,000 triangles at 640x480).
"""

from __future__ import annotations

import math

import numpy as np

from .convert import camera_basis, intrinsics
from .faces import fan
from .pyrender_oracle import depth_step

__all__ = [
    "GL_TIE_PX",
    "ID_TIE",
    "NO_OBJECT",
    "coverage",
    "silhouette",
    "project_clipped",
    "open_edges",
    "corner_edges",
    "depth_bound",
]

#: How far a GL renderer may move a vertex before deciding coverage (px, Euclidean):
#: sqrt(2) x oracles.tolerances.TIE_END_PX = sqrt(2) x (2^-9 snap + 2^-9 float32), derived there.
GL_TIE_PX = math.sqrt(2.0) * 2.0**-8

#: ``object_ids`` where no triangle covers the pixel centre.
NO_OBJECT = -1
#: ``object_ids`` where the two nearest objects are within their depth bounds (either is correct).
ID_TIE = -2

# Depth bound of a GL depth test (oracles.tolerances, "The shaded depth comparison", derives
# these three; a test checks that they are the same numbers): steps of the 24-bit buffer,
# the 1/256-px snap times the depth slope, float32 roundings of z.
_DEPTH_STEPS = 4.0
_DEPTH_SNAP_PX = 1.0 / 256.0
_DEPTH_EPS32 = 16.0
_EPS32 = 2.0**-23

#: A hint of triangle ids is checked when the boxes' rows times this exceed the image's pixels (:func:`_rows`).
_HINT_ROWS_PER_PIXEL = 16

#: Bounding-box samples per batch (~10 float64 temporaries of this length: ~40 MB).
_CHUNK = 1 << 19


def depth_bound(z: np.ndarray, slope: np.ndarray, camera) -> np.ndarray:
    """How far a GL depth test may be off at camera depth ``z`` with depth slope ``slope`` (per px).

    ``4 step(z) + slope / 256 + 16 eps32 z`` (oracles.tolerances, DEPTH_STEPS, DEPTH_SNAP_PX,
    DEPTH_EPS32); ``step`` is one level of a 24-bit buffer (pyrender_oracle.depth_step).
    """
    z = np.asarray(z, dtype=np.float64)
    return _DEPTH_STEPS * depth_step(z, camera) + _DEPTH_SNAP_PX * slope + _DEPTH_EPS32 * _EPS32 * z


def _edge_keys(tris_px: np.ndarray) -> tuple[np.ndarray, ...]:
    """Each triangle edge ``k`` (``v_k -> v_k+1``), ``(3T,)`` each in the corners' order: its two ends in
    (x, y) order, ``lo_x, lo_y, hi_x, hi_y`` (both triangles of a shared edge get the same key), and the
    opposite vertex ``third_x, third_y``."""
    p = tris_px + 0.0  # -0.0 -> 0.0: equal keys compare equal
    x, y = p[..., 0].ravel(), p[..., 1].ravel()  # v0, v1, v2 of each triangle
    k = np.arange(len(x)).reshape(-1, 3)
    nxt, opp = k[:, [1, 2, 0]].ravel(), k[:, [2, 0, 1]].ravel()  # v1, v2, v0 and v2, v0, v1
    bx, by = x[nxt], y[nxt]
    flip = (bx < x) | ((bx == x) & (by < y))
    return np.where(flip, bx, x), np.where(flip, by, y), np.where(flip, x, bx), np.where(flip, y, by), x[opp], y[opp]


def open_edges(tris_px, corners=None, grouped=None) -> np.ndarray:
    """``(T, 3) bool``: edge ``k`` (``v_k -> v_k+1``) of each triangle is open (module docstring).

    Closed: some triangle with the same two end points has its third vertex strictly on one side
    of the edge's line and some other strictly on the other. End points are the same when their
    coordinates are (-0.0 and 0.0 alike; a NaN is the same as nothing): each distinct point gets one
    number, and an edge's key is its two points' numbers. ``corners`` (``(T, 3)`` int, optional): a
    number per corner such that corners of one number have the same coordinates (a mesh's vertex
    indices); then only one corner of each number is compared with the others, and where no two
    numbers have the same coordinates the edges are grouped by the numbers themselves (the same
    groups). ``grouped``: :func:`corner_edges` of ``corners``, when the caller has it already (a
    mesh's triangles, frame after frame).
    """
    tris_px = np.asarray(tris_px, dtype=np.float64).reshape(-1, 3, 2)
    if len(tris_px) == 0:
        return np.zeros((0, 3), dtype=bool)
    lo_x, lo_y, hi_x, hi_y, third_x, third_y = _edge_keys(tris_px)
    side = np.sign((hi_x - lo_x) * (third_y - lo_y) - (hi_y - lo_y) * (third_x - lo_x))
    points = np.ascontiguousarray(tris_px + 0.0).reshape(-1, 2).view(np.complex128).ravel()  # (x, y) as one
    if corners is None:
        _, point = np.unique(points, return_inverse=True, equal_nan=False)  # by x, then y; NaN each its own
        group = _edge_groups(point.reshape(-1, 3), len(points))
    else:
        one, number, group = corner_edges(corners) if grouped is None else grouped
        distinct, point = np.unique(points[one], return_inverse=True, equal_nan=False)
        if len(distinct) < len(one):  # two numbers at one point: the edges grouped by points
            group = _edge_groups(point[number].reshape(-1, 3), len(points))
    pos = np.bincount(group, weights=(side > 0)) > 0
    neg = np.bincount(group, weights=(side < 0)) > 0
    return ~(pos & neg)[group].reshape(-1, 3)


def corner_edges(corners) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """What :func:`open_edges` needs of ``corners`` (``(T, 3)`` int) alone: ``(one, number, group)``, the first
    corner of each distinct number, each corner's number as an index into them, and each edge's group (edges
    ``v_k -> v_k+1`` in ``corners.ravel()``'s order, one group per unordered pair of numbers)."""
    _, one, number = np.unique(np.asarray(corners).ravel(), return_index=True, return_inverse=True)
    return one, number, _edge_groups(number.reshape(-1, 3), len(one))


def _edge_groups(point: np.ndarray, n: int) -> np.ndarray:
    """``(3T,)`` int: each edge's group, edges ``k`` (``v_k -> v_k+1``) of ``point`` (``(T, 3)`` numbers below
    ``n``) grouped by their two ends' numbers, either way round."""
    a, b = point.ravel(), np.roll(point, -1, axis=1).ravel()  # edge k's two ends
    n = np.int64(n)
    edge = np.minimum(a, b) * n + np.maximum(a, b)
    order = np.argsort(edge, kind="stable")
    ks = edge[order]
    new = np.ones(len(ks), dtype=bool)
    new[1:] = ks[1:] != ks[:-1]
    group = np.empty(len(ks), dtype=np.int64)
    group[order] = np.cumsum(new) - 1
    return group


def _orient(tris_px: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Triangles turned so that their edge functions are positive inside, their doubled areas, which turned."""
    a, b, c = tris_px[:, 0], tris_px[:, 1], tris_px[:, 2]
    area2 = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    out = tris_px.copy()
    neg = area2 < 0
    out[neg, 1], out[neg, 2] = tris_px[neg, 2], tris_px[neg, 1]
    return out, np.abs(area2), neg


class _Buffers:
    """The per-pixel results of one pass, flat over ``H x W`` (``robust`` in full from :func:`_batch`; from
    :func:`_rows`, on the box rows that hold a ``near_open`` centre only: the ties ask it nothing else)."""

    def __init__(self, shape, depth: bool):
        n = shape[0] * shape[1]
        self.inside = np.zeros(n, dtype=bool)
        self.near_open = np.zeros(n, dtype=bool)
        self.robust = np.zeros(n, dtype=bool)
        self.samples = [] if depth else None  # (cell, object, z, slope) nearest per object and batch


def _raster(
    tris_px: np.ndarray,
    is_open: np.ndarray,
    shape,
    tie_px: float,
    tri_z: np.ndarray | None = None,
    tri_object: np.ndarray | None = None,
    perspective: bool = True,
    hint: np.ndarray | None = None,
) -> _Buffers:
    """One pass over the triangles: coverage, centres near open edges, centres held robustly.

    With ``tri_z`` and ``tri_object``: also each object's nearest depth (and slope) at the centres it covers.
    Without them, ``hint`` (a function giving ``(first, last, triangles)``: runs of flat centres along a row,
    and the triangle guessed to cover each run) spares the work of :func:`_rows` where it is right, called
    where the boxes' rows are many (:data:`_HINT_ROWS_PER_PIXEL`).
    """
    height, width = int(shape[0]), int(shape[1])
    out = _Buffers((height, width), tri_z is not None)
    if len(tris_px) == 0 or height == 0 or width == 0:
        return out
    # is_open follows the caller's vertex order; orient, and carry the open flags along with
    # the edges (swapping v1 and v2 reverses the triangle: edges 0, 1, 2 become 2, 1, 0)
    tris, area2, swapped = _orient(tris_px)
    is_open = np.where(swapped[:, None], is_open[:, ::-1], is_open)
    if tri_z is not None:
        tri_z = np.where(swapped[:, None], tri_z[:, [0, 2, 1]], tri_z)
    a, b, c = tris[:, 0], tris[:, 1], tris[:, 2]  # the corners' least and greatest x and y, one pass each
    lo = np.floor(np.minimum(np.minimum(a, b), c) - tie_px)
    hi = np.ceil(np.maximum(np.maximum(a, b), c) + tie_px)
    x0 = np.clip(lo[:, 0], 0, width - 1)
    y0 = np.clip(lo[:, 1], 0, height - 1)
    x1 = np.clip(hi[:, 0], 0, width - 1)
    y1 = np.clip(hi[:, 1], 0, height - 1)
    finite = np.isfinite(lo) & np.isfinite(hi)
    finite = finite[:, 0] & finite[:, 1]
    seen = finite & (hi[:, 0] >= 0) & (lo[:, 0] <= width - 1) & (hi[:, 1] >= 0) & (lo[:, 1] <= height - 1)
    idx = np.flatnonzero(seen)
    if tri_z is None:  # coverage alone: each box row's centres decided as spans
        t = idx
        guess = None
        # the hint's checks cost a pass over the image: worth it where the boxes' rows are many (measured: an
        # icosphere(4)'s 5,120 triangles, ~50,000 rows, 14.0 -> 12.4 ms a frame; the bundled scenes' 12-26
        # triangles, a few thousand rows, 5.3 -> 6.5 ms with it)
        if hint is not None and _HINT_ROWS_PER_PIXEL * (y1[t] - y0[t] + 1).sum() > height * width:

            def guess(row_lo: int, row_hi: int):  # the hint's runs on these rows, as indices into the seen ones
                first, last, guessed = hint(row_lo, row_hi)
                where = np.full(len(tris), -1, dtype=np.int64)
                where[t] = np.arange(len(t))
                guessed = where[guessed]
                return first[guessed >= 0], last[guessed >= 0], guessed[guessed >= 0]

        _rows(out, tris[t], area2[t], is_open[t], x0[t], y0[t], x1[t], y1[t], (height, width), tie_px, guess)
        return out
    bw = (x1[idx] - x0[idx] + 1).astype(np.int64)
    bh = (y1[idx] - y0[idx] + 1).astype(np.int64)
    # buckets: boxes rounded up to a multiple of half their power of two (<= 2.25x the samples, but fewer
    # batches: a 5,120-face icosphere's frame ~20 % faster than with quarters, 8 % slower on the bundled scenes)
    gws, ghs = _round_up(bw), _round_up(bh)
    bucket = gws * (1 << 20) + ghs
    for b in np.unique(bucket):
        members = idx[bucket == b]
        gw, gh = int(b >> 20), int(b & ((1 << 20) - 1))
        per = max(1, _CHUNK // (gw * gh))
        for s in range(0, len(members), per):
            t = members[s : s + per]
            _batch(
                out,
                tris[t],
                area2[t],
                is_open[t],
                x0[t],
                y0[t],
                x1[t],
                y1[t],
                gw,
                gh,
                width,
                tie_px,
                None if tri_z is None else tri_z[t],
                None if tri_z is None else tri_object[t],
                perspective,
            )
    return out


def _rows(out: _Buffers, tris, area2, is_open, x0, y0, x1, y1, shape, tie_px, guess=None) -> None:
    """:func:`_batch`'s coverage and near-open centres (no depths), one box row at a time as spans; the robust
    centres only where there is a near-open one (all that :func:`coverage`'s ties ask of them).

    On a box row (``py`` fixed) an edge function ``E(px) = dx (py - Py) - dy (px - Px)`` evaluated in
    float64 is monotone in ``px`` (each rounding is monotone: non-increasing for ``dy > 0``, non-decreasing
    for ``dy < 0``, constant for ``dy == 0``), so the centres where ``E > t`` (or ``E >= t``) are a
    half-line, found from the line's crossing and checked with ``E`` itself, computed as :func:`_batch`
    computes it (:func:`_half_line`). The coverage (every edge ``E > 0``, ``E >= 0`` on a top or left
    edge), each open edge's band (``|E| <= tie_px |PQ|``, then the distance to the segment at each centre)
    and the robust centres (every ``E > tie_px |PQ|``) are then intersections of spans: the same centres as
    :func:`_batch`, bit for bit (tests/test_fill_rule.py's naive pass), with work per box row instead of
    per centre; the half-lines of one question, every edge's, in one :func:`_half_line` call.

    ``guess`` (a function of the first and last image rows the boxes span, giving ``(first, last,
    triangles)``: runs of flat centres along a row, in row-major order, an index into ``tris`` each): each run
    is checked by the rule against its triangle alone (:func:`_covers`); a centre held so is covered whatever
    the other triangles do, so the spans are taken only on the box rows that hold a centre not held so. The
    robust centres are taken only on the box rows that hold a near-open centre.
    """
    if len(tris) == 0:
        return
    height, width = shape
    tab = _Table(tris, area2, (x0, y0, x1, y1), tie_px)
    if guess is None:
        tri, py = _box_rows(np.arange(len(tris)), y0, y1)
    else:  # over the boxes' bounding box, ``region``
        rx0, ry0, rx1, ry1 = (int(x0.min()), int(y0.min()), int(x1.max()), int(y1.max()))
        held = _covers(guess(ry0, ry1), tab, (rx0, ry0, rx1, ry1), width)
        out.inside.reshape(shape)[ry0 : ry1 + 1, rx0 : rx1 + 1] |= held
        tri, py = _rows_meeting(~held, (rx0, ry0), (x0, y0, x1, y1))
    in_lo, in_hi = _spans(tab, tri, py)
    _paint(out.inside, py * width, in_lo, in_hi)
    # near an open edge: within tie_px of its line (E >= -reach and not E > reach), then of the segment
    j = np.flatnonzero(is_open.T.ravel())  # the open edges, as k x T + triangle
    t = j % len(tris)
    j, py = _box_rows(j, y0[t], y1[t])
    if len(j) == 0:
        return
    px_, py_, dx_, dy_, reach_ = tab.edges()  # each (3T,): k x T + triangle
    t = j % len(tris)
    e_row, dy, px0, reach = dx_[j] * (py - py_[j]), dy_[j], px_[j], reach_[j]
    bx0, bx1 = x0[t], x1[t]
    lo, hi = _half_line(  # E >= -reach, then E > reach
        *(np.concatenate([a, a]) for a in (e_row, dy, px0)),
        np.concatenate([-reach, reach]),
        np.repeat([False, True], len(j)),
        np.concatenate([bx0, bx0]),
        np.concatenate([bx1, bx1]),
    )
    (n_lo, f_lo), (n_hi, f_hi) = lo.reshape(2, -1), hi.reshape(2, -1)
    dec, inc = dy > 0, dy < 0
    n_lo = np.where(dec, np.maximum(n_lo, f_hi + 1.0), n_lo)
    n_hi = np.where(inc, np.minimum(n_hi, f_lo - 1.0), n_hi)
    n_hi = np.where(~(dec | inc) & (f_lo <= f_hi), n_lo - 1.0, n_hi)  # flat: the whole row is far, or none
    ii, px = _span_cells(np.arange(len(j)), n_lo, n_hi)
    e, y = j[ii], py[ii]
    rx, ry = px - px_[e], y - py_[e]
    sx, sy = dx_[e], dy_[e]
    length2 = sx * sx + sy * sy
    with np.errstate(invalid="ignore", divide="ignore"):
        u = np.where(length2 > 0, np.clip((rx * sx + ry * sy) / length2, 0.0, 1.0), 0.0)
    at = np.hypot(rx - u * sx, ry - u * sy) <= tie_px
    near = (y[at] * width + px[at]).astype(np.int64)
    if len(near) == 0:
        return
    out.near_open[near] = True
    # robust (inside, and every E > reach) on the box rows that hold a near-open centre
    row, col = near // width, near % width
    cx0, cy0, cx1, cy1 = int(col.min()), int(row.min()), int(col.max()), int(row.max())
    band = out.near_open.reshape(shape)[cy0 : cy1 + 1, cx0 : cx1 + 1]
    tri, py = _rows_meeting(band, (cx0, cy0), (x0, y0, x1, y1))
    far_lo, far_hi = _spans(tab, tri, py, robust=True)
    _paint(out.robust, py * width, far_lo, far_hi)


class _Table:
    """What the row spans read of each triangle, one row per quantity (numpy's fast axis the triangles):
    ``rows`` ``(20, T)`` float64: for each edge ``k`` (``P = v_k -> Q = v_k+1``) ``Px`` (3 rows), ``Py``,
    ``dx``, ``dy`` (``Q - P``); the boxes' ``x0``, ``x1``; the doubled areas; each edge's ``reach``
    (``tie_px |PQ|``, 3 rows); the boxes' ``y0``, ``y1``. A question's rows come first (:meth:`take`).
    ``top_left`` ``(3, T)`` bool."""

    #: The rows :func:`_spans` reads (the reach's only for the robust centres), and all of them.
    SPANS, ROBUST, ALL = 15, 18, 20

    def __init__(self, tris: np.ndarray, area2, boxes, tie_px: float):
        self.rows = np.empty((20, len(tris)))
        p_x, p_y, dx, dy = self.rows[:12].reshape(4, 3, len(tris))
        p_x[...], p_y[...] = tris[..., 0].T, tris[..., 1].T
        q = np.roll(tris, -1, axis=1)  # v1, v2, v0
        np.subtract(q[..., 0].T, p_x, out=dx)
        np.subtract(q[..., 1].T, p_y, out=dy)
        x0, y0, x1, y1 = boxes
        self.rows[12], self.rows[13], self.rows[14], self.rows[18], self.rows[19] = x0, x1, area2, y0, y1
        np.multiply(tie_px, np.sqrt(dx * dx + dy * dy), out=self.rows[15:18])
        self.top_left = (dy < 0) | ((dy == 0) & (dx > 0))

    def edges(self) -> tuple[np.ndarray, ...]:
        """``Px, Py, dx, dy, reach``, each ``(3T,)``: edge ``k`` of triangle ``t`` at ``k T + t``."""
        r = self.rows
        return r[0:3].ravel(), r[3:6].ravel(), r[6:9].ravel(), r[9:12].ravel(), r[15:18].ravel()

    def take(self, tri, upto: int = ALL) -> tuple[np.ndarray, np.ndarray]:
        """``(rows (upto, M), top_left (3, M))`` of the triangles ``tri``: the first ``upto`` rows only."""
        return np.take(self.rows[:upto], tri, axis=1), np.take(self.top_left, tri, axis=1)


def _spans(tab: _Table, tri, py, robust: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """``(lo, hi)``: on each box row ``(tri, py)`` (float), the centres of the triangle's box inside it by the rule
    (every edge ``E > 0``, or ``E >= 0`` on a top or left edge), and with ``robust`` also farther than its reach
    from every edge line (``E > tie_px |PQ|``), as one span (empty: ``lo > hi``; empty for a zero-area
    triangle); one :func:`_half_line` call a test, over the three edges at once."""
    rows, top_left = tab.take(tri, _Table.ROBUST if robust else _Table.SPANS)
    p_x, p_y, dx, dy = rows[:12].reshape(4, 3, -1)  # each (3, M): edge by edge
    bx0, bx1, area2 = rows[12], rows[13], rows[14]
    e_row = dx * (py - p_y)
    span_lo, span_hi = bx0, np.where(area2 > 0, bx1, bx0 - 1.0)  # zero-area triangles cover nothing
    for thr, strict in ((0.0, ~top_left), (rows[15:18], True))[: 2 if robust else 1]:
        lo, hi = _half_line(e_row, dy, p_x, thr, strict, bx0, bx1)
        for k in range(3):
            span_lo, span_hi = np.maximum(span_lo, lo[k]), np.minimum(span_hi, hi[k])
    return span_lo, span_hi


def _box_rows(which, y0, y1):
    """``(which, py)``: one entry per row ``y0[i] .. y1[i]`` of each entry ``which[i]`` (``y0, y1``: per entry)."""
    count = (y1 - y0 + 1).astype(np.int64)
    rows = np.repeat(np.arange(len(which)), count)
    return which[rows], y0[rows] + (np.arange(len(rows)) - np.repeat(np.cumsum(count) - count, count))


def _rows_meeting(mask: np.ndarray, corner, boxes) -> tuple[np.ndarray, np.ndarray]:
    """``(tri, py)``: the box rows of the boxes ``(x0, y0, x1, y1)`` (inclusive, on the image; float) that hold
    a True centre of ``mask``, an ``(h, w)`` part of the image whose first centre is ``corner`` ``(x, y)``.

    Boxes first, then their rows, each by four looks into ``mask``'s summed-area table (cv2.integral)."""
    import cv2  # lazily, as every OpenCV use of the oracles

    h, w = mask.shape
    table = cv2.integral(np.ascontiguousarray(mask).view(np.uint8), sdepth=cv2.CV_32S).ravel()
    x0, y0, x1, y1 = (np.asarray(b).astype(np.int64) for b in boxes)
    # each box cut to the mask's part (empty: a0 >= a1 or b0 >= b1), as the table's columns and rows
    a0, a1 = np.clip(x0 - corner[0], 0, w), np.clip(x1 - corner[0] + 1, 0, w)
    b0, b1 = np.clip(y0 - corner[1], 0, h) * (w + 1), np.clip(y1 - corner[1] + 1, 0, h) * (w + 1)
    hit = (a0 < a1) & (b0 < b1)
    hit &= table[b1 + a1] - table[b0 + a1] - table[b1 + a0] + table[b0 + a0] > 0
    which = np.flatnonzero(hit)
    which, r = _box_rows(which, b0[which] // (w + 1), b1[which] // (w + 1) - 1)
    a0, a1, r = a0[which], a1[which], r * (w + 1)
    keep = table[r + (w + 1) + a1] - table[r + a1] - table[r + (w + 1) + a0] + table[r + a0] > 0
    return which[keep], (r[keep] // (w + 1) + corner[1]).astype(np.float64)


def _covers(guess, tab: _Table, region, width: int) -> np.ndarray:
    """``(h, w)`` bool over ``region`` ``(x0, y0, x1, y1)`` (inclusive, holding every box): the centres of the
    runs ``guess`` (``(first, last, triangle)``: flat centres along one row each, in row-major order, none
    overlapping) whose two ends are inside their guessed triangle by the rule (in its box, every edge ``E >
    0``, or ``E == 0`` on a top or left edge; each ``E`` computed as :func:`_batch` computes it). On a row a
    triangle's centres are a span (:func:`_rows`), so a run whose two ends are in it is in it whole."""
    first, last, t = guess
    row = first // width
    c0, c1 = first - row * width, last - row * width
    py = row.astype(np.float64)
    rows, top_left = tab.take(t)
    p_x, p_y, dx, dy = rows[:12].reshape(4, 3, -1)  # each (3, N): edge by edge
    x0, x1, area2, y0, y1 = rows[12], rows[13], rows[14], rows[18], rows[19]
    ok = (area2 > 0) & (py >= y0) & (py <= y1) & (c0 >= x0) & (c1 <= x1)
    e_row = dx * (py - p_y)
    for end in (c0, c1):
        e = e_row - dy * (end.astype(np.float64) - p_x)
        e_in = (e > 0) | ((e == 0) & top_left)
        ok &= e_in[0] & e_in[1] & e_in[2]
    # the held runs painted as the run-length image they make: gap, run, gap, ..., gap
    rx0, ry0, rx1, ry1 = region
    w = rx1 - rx0 + 1
    start = (row[ok] - ry0) * w + (c0[ok] - rx0)
    bounds = np.empty(2 * len(start) + 2, dtype=np.int64)
    bounds[0], bounds[-1] = 0, (ry1 - ry0 + 1) * w
    bounds[1:-1:2], bounds[2:-1:2] = start, start + (c1[ok] - c0[ok] + 1)
    runs = np.zeros(len(bounds) - 1, dtype=bool)
    runs[1::2] = True
    return np.repeat(runs, np.diff(bounds)).reshape(ry1 - ry0 + 1, w)


def _half_line(e_row, dy, px0, thr, strict, bx0, bx1):
    """``(lo, hi)``: the centres ``px`` in ``[bx0, bx1]`` where ``E = e_row - dy (px - px0)`` is ``> thr``
    (``strict``) or ``>= thr``, as a span (empty: ``lo > hi``); every argument per entry (or a scalar).

    ``E`` is monotone in ``px`` (:func:`_rows`): the span is the box's centres on one side of the line's
    crossing ``px0 + (e_row - thr) / dy``. Its last centre inside (``dy > 0``: the span ends there) or its
    last centre outside (``dy < 0``: the span begins after it) is the crossing rounded down, held to the box,
    and checked with ``E`` at it and at the next centre (computed exactly as the batched pass computes it);
    the few entries the check refuses (a crossing within rounding of a centre) are moved a centre at a time.
    """
    shape = np.broadcast_shapes(*(np.shape(a) for a in (e_row, dy, px0, thr, strict, bx0, bx1)))
    # ``E >= thr`` is ``E > the float below thr`` (no float lies between): one comparison for both kinds
    below_thr = np.where(strict, thr, np.nextafter(thr, -np.inf))
    e_row, dy, px0, below_thr = (np.broadcast_to(a, shape) for a in (e_row, dy, px0, below_thr))

    def holds(px, i=...):
        return e_row[i] - dy[i] * (px - px0[i]) > below_thr[i]

    dec = dy > 0  # in: px <= last; dy < 0: in from first = last + 1 on; dy == 0: E is e_row on the whole row
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        cross = px0 + (e_row - thr) / dy
    flat = ~(dec | (dy < 0))
    last = np.where(flat, bx1, cross)  # the last centre with dec's E in: the crossing rounded down, in the box
    np.floor(last, out=last)
    np.maximum(last, bx0 - 1.0, out=last)
    np.minimum(last, bx1, out=last)
    in_at = holds(last)  # E at ``last`` and at ``last + 1``: in, then out (dec), or out, then in
    in_next = holds(last + 1.0)
    ok = ((last < bx0) | (in_at == dec)) & ((last >= bx1) | (in_next != dec))  # past the box: not asked
    ok |= flat
    box0, box1 = np.broadcast_to(bx0, shape), np.broadcast_to(bx1, shape)
    for i in zip(*np.nonzero(~ok)):  # a crossing within rounding of a centre: move a centre at a time
        sign = 1.0 if dec[i] else -1.0  # +: E falls with px
        while last[i] < box1[i] and (holds(last[i] + 1.0, i) if sign > 0 else not holds(last[i] + 1.0, i)):
            last[i] += 1.0
        while last[i] >= box0[i] and (not holds(last[i], i) if sign > 0 else holds(last[i], i)):
            last[i] -= 1.0
    lo = np.where(dec | flat, bx0, last + 1.0)
    hi = np.where(dec, last, bx1)
    if flat.any():  # a flat edge (dy == 0): E is e_row at every centre (``in_at``), the whole row or none of it
        hi = np.where(flat & ~in_at, lo - 1.0, hi)
    return lo, hi


def _span_cells(entries, lo, hi):
    """``(entry, px)`` of every centre of the spans ``[lo, hi]`` (one per entry of ``entries``)."""
    n = np.maximum(hi - lo + 1.0, 0.0).astype(np.int64)
    which = np.repeat(np.arange(len(entries)), n)
    step = np.arange(len(which)) - np.repeat(np.cumsum(n) - n, n)
    return entries[which], lo[which] + step


def _paint(flat: np.ndarray, row_start, lo, hi) -> None:
    """Set ``flat[row_start + lo : row_start + hi + 1]`` for every non-empty span."""
    entries, px = _span_cells(np.arange(len(lo)), lo, hi)
    flat[(row_start[entries] + px).astype(np.int64)] = True


def _round_up(n: np.ndarray) -> np.ndarray:
    """``n`` (>= 1) rounded up to a multiple of ``2^max(0, floor(log2 n) - 1)``: at most 50 % more."""
    step = np.left_shift(1, np.maximum(0, np.floor(np.log2(n)).astype(np.int64) - 1))
    return -(-n // step) * step


def _cells(x0, y0, width, tri, row, col) -> np.ndarray:
    """Flat pixel indices of the centres at ``row, col`` of triangle ``tri``'s box (whose corner is ``x0, y0``)."""
    return ((y0[tri] + row) * width + (x0[tri] + col)).astype(np.int64)


def _batch(out: _Buffers, tris, area2, is_open, x0, y0, x1, y1, gw, gh, width, tie_px, tri_z, tri_object, perspective):
    # The boxes' centres in 3 axes (triangle, row, column): a row shares py and a column px, so each edge
    # function's two products are taken per row and per column and only their difference over the boxes.
    # The longer of the triangle and column axes goes last (numpy's inner loop): (gh, gw, n) for many small
    # boxes, (n, gh, gw) for few large ones; ``.transpose(tri_major)`` is (n, gh, gw) either way.
    if len(tris) >= gw:
        tri, row, col, tri_major = (1, 1, -1), (-1, 1, 1), (1, -1, 1), (2, 0, 1)
    else:
        tri, row, col, tri_major = (-1, 1, 1), (1, -1, 1), (1, 1, -1), (0, 1, 2)
    px = x0.reshape(tri) + np.arange(gw).reshape(col)  # centres, float
    py = y0.reshape(tri) + np.arange(gh).reshape(row)
    valid = (px <= x1.reshape(tri)) & (py <= y1.reshape(tri))  # in the box (clipped to the image)
    inside = valid & (area2 > 0).reshape(tri)
    far_from_edges = inside.copy()  # farther than tie_px from every edge line
    for k in range(3):
        p, q = tris[:, k], tris[:, (k + 1) % 3]
        dx, dy = q[:, 0] - p[:, 0], q[:, 1] - p[:, 1]
        e = dx.reshape(tri) * (py - p[:, 1].reshape(tri)) - dy.reshape(tri) * (px - p[:, 0].reshape(tri))
        top_left = (dy < 0) | ((dy == 0) & (dx > 0))
        inside &= e >= 0  # E > 0, or E == 0 on a top or left edge:
        on_line = e == 0  # E == 0 is rare off axis-aligned edges
        if on_line.any():
            on_line &= ~top_left.reshape(tri)
            inside &= ~on_line
        reach = tie_px * np.sqrt(dx * dx + dy * dy)  # |e| / length <= tie_px, undivided
        far_from_edges &= e > reach.reshape(tri)  # inside it: e >= 0, so |e| > reach
        # near an open edge (few triangles have one): within tie_px of its line, then of the segment itself
        rows = np.flatnonzero(is_open[:, k])
        if len(rows) == 0:
            continue
        ii, r, c = np.nonzero(
            (np.abs(e.transpose(tri_major)[rows]) <= reach[rows, None, None]) & valid.transpose(tri_major)[rows]
        )
        if len(ii):
            ii = rows[ii]
            rx, ry = (x0[ii] + c) - p[ii, 0], (y0[ii] + r) - p[ii, 1]
            sx, sy = dx[ii], dy[ii]
            length2 = sx * sx + sy * sy
            with np.errstate(invalid="ignore", divide="ignore"):
                t = np.where(length2 > 0, np.clip((rx * sx + ry * sy) / length2, 0.0, 1.0), 0.0)
            near = np.hypot(rx - t * sx, ry - t * sy) <= tie_px
            out.near_open[_cells(x0, y0, width, ii[near], r[near], c[near])] = True
    cell = py * width + px  # flat pixel index (exact in float)
    out.inside[cell[inside].astype(np.int64)] = True
    far_from_edges &= inside
    out.robust[cell[far_from_edges].astype(np.int64)] = True
    if tri_z is None or not inside.any():
        return
    rows, r, cols = np.nonzero(inside.transpose(tri_major))  # covered, triangle by triangle, row-major
    cells = _cells(x0, y0, width, rows, r, cols)
    # depth at the centres: w = 1/z (perspective) or z (orthographic) on the plane through the vertices
    a, b, c = tris[:, 0], tris[:, 1], tris[:, 2]
    w = 1.0 / tri_z if perspective else tri_z
    det = area2  # > 0 where inside
    e1, e2 = b - a, c - a
    dw1, dw2 = (w[:, 1] - w[:, 0]), (w[:, 2] - w[:, 0])
    with np.errstate(invalid="ignore", divide="ignore"):
        gx = (dw1 * e2[:, 1] - dw2 * e1[:, 1]) / det
        gy = (dw2 * e1[:, 0] - dw1 * e2[:, 0]) / det
    wp = w[rows, 0] + gx[rows] * ((x0[rows] + cols) - a[rows, 0]) + gy[rows] * ((y0[rows] + r) - a[rows, 1])
    if perspective:
        z = 1.0 / wp
        slope = z * z * (np.abs(gx) + np.abs(gy))[rows]  # |dz/dx| + |dz/dy| = z^2 |dw|
    else:
        z = wp
        slope = (np.abs(gx) + np.abs(gy))[rows]
    out.samples.append((cells, tri_object[rows], z, slope))


def _nearest_per_object(cells, objects, z, slope):
    """The nearest sample of each (cell, object): ``(cells, objects, z, slope)`` sorted by cell, then z."""
    key = cells * (objects.max(initial=0) + 1) + objects  # objects are 0, 1, ...: one key per pair
    by_z = np.argsort(z)
    order = by_z[np.argsort(key[by_z], kind="stable")]  # by key, then z (lexsort is ~5x slower)
    cells, objects, z, slope, key = cells[order], objects[order], z[order], slope[order], key[order]
    first = np.ones(len(cells), dtype=bool)
    first[1:] = key[1:] != key[:-1]
    cells, objects, z, slope = cells[first], objects[first], z[first], slope[first]
    by_z = np.argsort(z)
    order = by_z[np.argsort(cells[by_z], kind="stable")]
    return cells[order], objects[order], z[order], slope[order]


def coverage(tris_px, shape, tie_px: float = GL_TIE_PX, is_open=None) -> tuple[np.ndarray, np.ndarray]:
    """Pixel centres covered by triangles under GL's fill rule, and the ties (module docstring).

    Parameters
    ----------
    tris_px : (T, 3, 2) array_like
        Triangles in pixel coordinates (x right, y down, integers at pixel centres), float64.
    shape : (H, W)
    tie_px : float
        How far a renderer may move a vertex before it decides (px); 0 leaves only the
        centres exactly on an open edge as ties.
    is_open : (T, 3) bool, optional
        Which edges (``v_k -> v_k+1``) are open; :func:`open_edges` of ``tris_px`` if None.

    Returns
    -------
    inside : (H, W) bool, the centre is in some triangle.
    ties : (H, W) bool, a renderer may answer either way there.
    """
    tris_px = np.asarray(tris_px, dtype=np.float64).reshape(-1, 3, 2)
    if is_open is None:
        is_open = open_edges(tris_px)
    buf = _raster(tris_px, np.asarray(is_open, dtype=bool).reshape(-1, 3), shape, float(tie_px))
    shape = (int(shape[0]), int(shape[1]))
    return buf.inside.reshape(shape), (buf.near_open & ~buf.robust).reshape(shape)


def _clip_polygon(poly: np.ndarray, z_min: float, z_max: float) -> np.ndarray:
    """A convex polygon (k, 3) in camera space cut to ``z_min <= z <= z_max`` (Sutherland-Hodgman).

    A cut point on an edge is computed from the edge's ends in a fixed order (the end inside
    first), so two triangles sharing the edge get the same point to the bit.
    """
    for plane, sign in ((z_min, 1.0), (z_max, -1.0)):  # keep sign (z - plane) >= 0
        if len(poly) == 0:
            break
        out = []
        for i in range(len(poly)):
            p, q = poly[i], poly[(i + 1) % len(poly)]
            p_in, q_in = bool(sign * (p[2] - plane) >= 0), bool(sign * (q[2] - plane) >= 0)
            if p_in:
                out.append(p)
            if p_in != q_in:
                a, b = (p, q) if p_in else (q, p)
                t = (plane - a[2]) / (b[2] - a[2])
                cut = a + t * (b - a)
                cut[2] = plane
                out.append(cut)
        poly = np.asarray(out, dtype=np.float64).reshape(-1, 3)
    return poly


def project_clipped(p_world, faces, camera) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The faces as image triangles: ``(tris_px (T, 3, 2), tri_z (T, 3), owner (T,))``.

    Polygons are fanned from their first vertex (oracles.references.faces.fan), every face
    kept (back faces too: a silhouette is all faces), cut to ``near <= z <= far`` in camera
    space before the divide (a cut triangle is fanned again), then projected by the
    conventions (perspective ``x = cx + fx x/z, y = cy - fy y/z``; orthographic with
    ``s = H / ortho_height`` and the centred principal point). ``owner`` is the face of each.
    """
    return _project(p_world, fan(faces), camera)[:3]


def _project(p_world, fanned, camera):
    """:func:`project_clipped` of the fan ``fanned`` (``(triangles, owner)``), the fan triangles kept whole
    (``(T_fan,) bool``: they are the first image triangles, in the fan's order) and the image triangles'
    corners numbered for :func:`open_edges` (``(T, 3)``: a whole triangle's vertex indices)."""
    if getattr(camera, "distortion", None) is not None:
        raise ValueError("a distorted camera's silhouette is curved: no fill-rule reference for it")
    p_world = np.asarray(p_world, dtype=np.float64).reshape(-1, 3)
    right, up, forward = camera_basis(camera)
    world_to_cam = np.stack([right, up, forward])
    p_cam = (p_world - np.asarray(camera.position, dtype=np.float64)) @ world_to_cam.T
    tris, owner = fanned
    z = p_cam[:, 2][tris.T]  # (3, T): corner by corner
    near, far = float(camera.near), float(camera.far)
    between, before, beyond = (z >= near) & (z <= far), z < near, z > far
    whole = between[0] & between[1] & between[2]
    gone = (before[0] & before[1] & before[2]) | (beyond[0] & beyond[1] & beyond[2])
    cuts, cut_owner = [np.zeros((0, 3, 3))], [owner[whole]]
    for i in np.flatnonzero(~whole & ~gone):
        poly = _clip_polygon(p_cam[tris[i]], near, far)
        if len(poly) >= 3:
            cuts.append(np.stack([np.stack([poly[0], poly[k], poly[k + 1]]) for k in range(1, len(poly) - 1)]))
            cut_owner.append(np.full(len(poly) - 2, owner[i]))
    owner = np.concatenate(cut_owner).astype(np.int64)  # the whole triangles' first, then the cut ones'
    cut_cam = np.concatenate(cuts).reshape(-1, 3, 3)
    # the corners' numbers: a whole triangle's are its vertex indices, each cut corner one of its own
    kept = tris[whole]
    corners = np.concatenate([kept.ravel(), len(p_cam) + np.arange(3 * len(cut_cam))]).reshape(-1, 3)
    # a whole triangle's corners are its vertices projected (each vertex once: the same numbers as corner by
    # corner), a cut one's its own points; a vertex in no whole triangle may be behind the eye (its division
    # by z <= 0 never used)
    with np.errstate(divide="ignore", invalid="ignore"):
        tris_px = np.concatenate([_to_px(p_cam, camera)[kept], _to_px(cut_cam, camera)]).reshape(-1, 3, 2)
    zc = np.concatenate([p_cam[:, 2][kept], cut_cam[..., 2]]).reshape(-1, 3)
    return tris_px, zc, owner, whole, corners


def _to_px(p_cam: np.ndarray, camera) -> np.ndarray:
    """``(..., 2)``: camera-space points ``(..., 3)`` projected by the conventions (:func:`project_clipped`)."""
    x, y, zc = p_cam[..., 0], p_cam[..., 1], p_cam[..., 2]
    if camera.projection == "perspective":
        fx, fy, cx, cy = intrinsics(camera)
        return np.stack([cx + fx * x / zc, cy - fy * y / zc], axis=-1)
    s = camera.height / camera.ortho_height
    cx, cy = (camera.width - 1) / 2.0, (camera.height - 1) / 2.0
    return np.stack([cx + s * x, cy - s * y], axis=-1)


def _image_triangles(hint, whole, shape, row_lo: int, row_hi: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``hint``'s runs along each row ``row_lo .. row_hi`` of one fan triangle kept whole by the clip planes:
    ``(first, last, triangle)``, flat centres of the image and that triangle's index among the image triangles
    (the whole ones come first, in the fan's order)."""
    flat = np.asarray(hint)[row_lo : row_hi + 1].reshape(-1)
    begins = np.ones(len(flat), dtype=bool)
    np.not_equal(flat[1:], flat[:-1], out=begins[1:])
    begins[:: shape[1]] = True  # a run ends with its row
    first = np.flatnonzero(begins)
    last = np.append(first[1:], len(flat)) - 1
    fan_tri = flat[first]
    index = np.full(len(whole) + 1, -1, dtype=np.int64)
    index[np.flatnonzero(whole)] = np.arange(int(whole.sum()))
    tri = index[np.where((fan_tri >= 0) & (fan_tri < len(whole)), fan_tri, len(whole))]
    keep = tri >= 0
    offset = row_lo * shape[1]
    return first[keep] + offset, last[keep] + offset, tri[keep]


def silhouette(
    p_world, faces, camera, shape, face_objects=None, tie_px: float = GL_TIE_PX, hint=None, fanned=None, edges=None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A frame's reference silhouette: ``(inside, ties, object_ids)``, each ``(H, W)``.

    Parameters
    ----------
    p_world : (N, 3) array_like
        World points of the frame (after each object's matrix).
    faces : sequence of index tuples
        Polygons (any winding: back faces count).
    camera : core.camera.Camera
        Without distortion (ValueError otherwise).
    shape : (H, W)
    face_objects : (F,) int, optional
        The object of each face (0, 1, ...); all faces one object (id 0) if None.
    tie_px : float
        As in :func:`coverage`.
    hint : (H, W) int, optional
        A guess of the fan triangle covering each centre, -1 none (pyrender's triangle ids of
        ``fan(faces)``). Each guess is checked by the rule against its triangle alone, and the
        triangles are rasterized only where a box holds a centre not held so: the same result
        as without it, right or wrong, with less work where it is right. Not used with several objects.
    fanned : ((T, 3), (T,)) int, optional
        ``oracles.references.faces.fan(faces)``, when the caller has it already.
    edges : tuple, optional
        :func:`corner_edges` of the fan's triangles (``fanned[0]``), when the caller has it already (a
        case's frames of one mesh): used on a frame where the clip planes cut no triangle.

    Returns
    -------
    inside : (H, W) bool
    ties : (H, W) bool
    object_ids : (H, W) int64, the object of the nearest face at each covered centre,
        :data:`NO_OBJECT` where none, :data:`ID_TIE` where two objects are within depth bounds.
    """
    if face_objects is not None and len(face_objects) != len(faces):
        raise ValueError(f"face_objects has {len(face_objects)} entries for {len(faces)} faces: expected one per face")
    tris_px, tri_z, owner, whole, corners = _project(p_world, fan(faces) if fanned is None else fanned, camera)
    shape = (int(shape[0]), int(shape[1]))
    if hint is not None and np.shape(hint) != shape:
        raise ValueError(f"a hint of shape {np.shape(hint)} for an image of {shape}")
    is_open = open_edges(tris_px, corners, edges if edges is not None and whole.all() else None)
    objects = np.zeros(0, dtype=np.int64)
    if face_objects is not None and len(owner):
        tri_object = np.asarray(face_objects, dtype=np.int64).reshape(-1)[owner]
        objects, tri_object = np.unique(tri_object, return_inverse=True)  # tri_object: 0, 1, ... here
    several = len(objects) > 1
    buf = _raster(
        tris_px,
        is_open,
        shape,
        float(tie_px),
        tri_z if several else None,
        tri_object if several else None,
        camera.projection == "perspective",
        None if hint is None or several else (lambda lo, hi: _image_triangles(hint, whole, shape, lo, hi)),
    )
    inside = buf.inside.reshape(shape)
    ties = (buf.near_open & ~buf.robust).reshape(shape)
    ids = np.subtract(buf.inside, 1, dtype=np.int64)  # 0 where covered, NO_OBJECT (-1) where not
    if len(objects):
        if several and buf.samples:
            cells, objs, z, slope = _nearest_per_object(*(np.concatenate(c) for c in zip(*buf.samples)))
            objs = objects[objs]
            first = np.ones(len(cells), dtype=bool)
            first[1:] = cells[1:] != cells[:-1]
            ids = np.full(shape[0] * shape[1], NO_OBJECT, dtype=np.int64)
            ids[cells[first]] = objs[first]
            # the second nearest object, where one follows the nearest in the same cell
            nxt = np.flatnonzero(first[:-1] & ~first[1:]) if len(cells) > 1 else np.zeros(0, np.int64)
            bound = depth_bound(z, slope, camera)
            tie = z[nxt + 1] - z[nxt] <= bound[nxt] + bound[nxt + 1]
            ids[cells[nxt[tie]]] = ID_TIE
            ids = np.where(buf.inside, ids, NO_OBJECT)
        else:
            ids = np.where(buf.inside, objects[0], NO_OBJECT).astype(np.int64)
    return inside, ties, ids.reshape(shape)
