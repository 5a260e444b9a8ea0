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
checked by the rule at its two ends, and only the triangles whose box holds a centre not held
so are taken row by row (the same result, whatever the guess). With several objects, a
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


def _edge_keys(tris_px: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each triangle edge ``k`` (``v_k -> v_k+1``) as ``(key (3T, 4), flip (3T,) bool, third (3T, 2))``.

    The key is the edge's two ends in (x, y) order, so that both triangles of a shared edge get
    the same key; ``third`` is the opposite vertex.
    """
    p = tris_px + 0.0  # -0.0 -> 0.0: equal keys compare equal
    a = p.reshape(-1, 2)  # v0, v1, v2 of each triangle
    b = np.roll(p, -1, axis=1).reshape(-1, 2)  # v1, v2, v0
    third = np.roll(p, -2, axis=1).reshape(-1, 2)  # v2, v0, v1
    flip = (b[:, 0] < a[:, 0]) | ((b[:, 0] == a[:, 0]) & (b[:, 1] < a[:, 1]))
    lo = np.where(flip[:, None], b, a)
    hi = np.where(flip[:, None], a, b)
    return np.concatenate([lo, hi], axis=1), flip, third


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
    key, _flip, third = _edge_keys(tris_px)
    d = key[:, 2:] - key[:, :2]
    side = np.sign(d[:, 0] * (third[:, 1] - key[:, 1]) - d[:, 1] * (third[:, 0] - key[:, 0]))
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
    :func:`_rows`, on the rows with a ``near_open`` centre only: the ties ask it nothing else)."""

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
    finite = np.isfinite(lo).all(axis=1) & np.isfinite(hi).all(axis=1)
    seen = finite & (hi[:, 0] >= 0) & (lo[:, 0] <= width - 1) & (hi[:, 1] >= 0) & (lo[:, 1] <= height - 1)
    idx = np.flatnonzero(seen)
    if tri_z is None:  # coverage alone: each box row's centres decided as spans
        t = idx
        guess = None
        # the hint's checks cost a pass over the image: worth it where the boxes' rows are many (measured: an
        # icosphere(4)'s 5,120 triangles, ~50,000 rows, 14.0 -> 12.4 ms a frame; the bundled scenes' 12-26
        # triangles, a few thousand rows, 5.3 -> 6.5 ms with it)
        if hint is not None and _HINT_ROWS_PER_PIXEL * (y1[t] - y0[t] + 1).sum() > height * width:
            first, last, guessed = hint()  # the hint's triangles as indices into the seen ones
            where = np.full(len(tris), -1, dtype=np.int64)
            where[t] = np.arange(len(t))
            guessed = where[guessed]
            guess = first[guessed >= 0], last[guessed >= 0], guessed[guessed >= 0]
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
    per centre.

    ``guess`` (``(first, last, triangles)``: runs of flat centres along a row, an index into ``tris`` each):
    each run is checked by the rule against its triangle alone (:func:`_covers`); a centre held so is
    covered whatever the other triangles do, so the spans are taken only for the triangles whose box holds
    a centre not held so.
    """
    height, width = shape
    edges = []  # per edge k: (P, dx, dy, reach, top_left), per triangle
    for k in range(3):
        p, q = tris[:, k], tris[:, (k + 1) % 3]
        dx, dy = q[:, 0] - p[:, 0], q[:, 1] - p[:, 1]
        edges.append((p, dx, dy, tie_px * np.sqrt(dx * dx + dy * dy), (dy < 0) | ((dy == 0) & (dx > 0))))
    boxes = (x0, y0, x1, y1)
    every = np.arange(len(tris))
    todo = every
    if guess is not None:
        held = _covers(guess, tris, area2, boxes, edges, height * width, width)
        out.inside |= held
        todo = every[_boxes_meet(~held.reshape(shape), boxes)]
    tri, py = _box_rows(todo, y0, y1)
    in_lo, in_hi = x0[tri], np.where(area2[tri] > 0, x1[tri], x0[tri] - 1.0)  # zero-area triangles cover nothing
    for p, dx, dy, _reach, top_left in edges:
        lo, hi = _half_line(dx[tri] * (py - p[tri, 1]), dy[tri], p[tri, 0], 0.0, ~top_left[tri], x0[tri], x1[tri])
        np.maximum(in_lo, lo, out=in_lo)
        np.minimum(in_hi, hi, out=in_hi)
    _paint(out.inside, py * width, in_lo, in_hi)
    for k, (p, dx, dy, reach, _top_left) in enumerate(edges):
        # near an open edge: within tie_px of its line (E >= -reach and not E > reach), then of the segment
        tri, py = _box_rows(np.flatnonzero(is_open[:, k]), y0, y1)
        if len(tri) == 0:
            continue
        args = (dx[tri] * (py - p[tri, 1]), dy[tri], p[tri, 0])
        n_lo, n_hi = _half_line(*args, -reach[tri], False, x0[tri], x1[tri])
        f_lo, f_hi = _half_line(*args, reach[tri], True, x0[tri], x1[tri])
        dec, inc = args[1] > 0, args[1] < 0
        n_lo = np.where(dec, np.maximum(n_lo, f_hi + 1.0), n_lo)
        n_hi = np.where(inc, np.minimum(n_hi, f_lo - 1.0), n_hi)
        n_hi = np.where(~(dec | inc) & (f_lo <= f_hi), n_lo - 1.0, n_hi)  # flat: the whole row is far, or none
        ii, px = _span_cells(np.arange(len(tri)), n_lo, n_hi)
        if len(ii):
            t, y = tri[ii], py[ii]
            rx, ry = px - p[t, 0], y - p[t, 1]
            sx, sy = dx[t], dy[t]
            length2 = sx * sx + sy * sy
            with np.errstate(invalid="ignore", divide="ignore"):
                u = np.where(length2 > 0, np.clip((rx * sx + ry * sy) / length2, 0.0, 1.0), 0.0)
            near = np.hypot(rx - u * sx, ry - u * sy) <= tie_px
            out.near_open[(y[near] * width + px[near]).astype(np.int64)] = True
    band = out.near_open.reshape(shape)
    if not band.any():
        return
    # robust (inside, and every E > reach) on the band's rows, for the triangles whose box meets the band
    tri, py = _box_rows(every[_boxes_meet(band, boxes)], y0, y1)
    keep = band.any(axis=1)[py.astype(np.int64)]
    tri, py = tri[keep], py[keep]
    far_lo, far_hi = x0[tri], np.where(area2[tri] > 0, x1[tri], x0[tri] - 1.0)
    for p, dx, dy, reach, top_left in edges:
        args = (dx[tri] * (py - p[tri, 1]), dy[tri], p[tri, 0])
        for thr, strict in ((0.0, ~top_left[tri]), (reach[tri], True)):
            lo, hi = _half_line(*args, thr, strict, x0[tri], x1[tri])
            far_lo, far_hi = np.maximum(far_lo, lo), np.minimum(far_hi, hi)
    _paint(out.robust, py * width, far_lo, far_hi)


def _box_rows(which, y0, y1):
    """``(triangle, py)``: one entry per row of each box of the triangles ``which``."""
    count = (y1[which] - y0[which] + 1).astype(np.int64)
    tri = np.repeat(which, count)
    return tri, y0[tri] + (np.arange(len(tri)) - np.repeat(np.cumsum(count) - count, count))


def _boxes_meet(mask: np.ndarray, boxes) -> np.ndarray:
    """``(T,) bool``: the boxes ``(x0, y0, x1, y1)`` (inclusive, on the image) holding a True centre of ``mask``
    (its summed-area table, cv2.integral)."""
    import cv2  # lazily, as every OpenCV use of the oracles

    table = cv2.integral(mask.view(np.uint8), sdepth=cv2.CV_32S)
    x0, y0, x1, y1 = (b.astype(np.int64) for b in boxes)
    return table[y1 + 1, x1 + 1] - table[y0, x1 + 1] - table[y1 + 1, x0] + table[y0, x0] > 0


def _covers(guess, tris, area2, boxes, edges, n: int, width: int) -> np.ndarray:
    """Flat bool (``n`` centres): the runs ``guess`` (``(first, last, triangle)``, along one row each) whose two
    ends are inside their guessed triangle by the rule (in its box, every edge ``E > 0``, or ``E == 0`` on a
    top or left edge; each ``E`` computed as :func:`_batch` computes it). On a row a triangle's centres are a
    span (:func:`_rows`), so a run whose two ends are in it is in it whole."""
    first, last, t = guess
    py = (first // width).astype(np.float64)
    ok = area2[t] > 0
    x0, y0, x1, y1 = boxes
    ok &= (py >= y0[t]) & (py <= y1[t])
    x0, x1 = x0[t], x1[t]
    per_edge = [(p[t, 0], dy[t], dx[t] * (py - p[t, 1]), top_left[t]) for p, dx, dy, _reach, top_left in edges]
    for end in (first, last):
        px = (end % width).astype(np.float64)
        ok &= (px >= x0) & (px <= x1)
        for p_x, dy, e_row, top_left in per_edge:  # each taken once for both ends
            e = e_row - dy * (px - p_x)
            ok &= (e > 0) | ((e == 0) & top_left)
    held = np.zeros(n, dtype=bool)
    _paint(
        held,
        first[ok] - first[ok] % width,
        (first[ok] % width).astype(np.float64),
        (last[ok] % width).astype(np.float64),
    )
    return held


def _half_line(e_row, dy, px0, thr, strict, bx0, bx1):
    """``(lo, hi)``: the centres ``px`` in ``[bx0, bx1]`` where ``E = e_row - dy (px - px0)`` is ``> thr``
    (``strict``) or ``>= thr``, as a span (empty: ``lo > hi``); every argument per entry (or a scalar).

    ``E`` is monotone in ``px`` (:func:`_rows`): the span is the box's centres on one side of the line's
    crossing ``px0 + (e_row - thr) / dy``. Its last centre inside (``dy > 0``: the span ends there) or its
    last centre outside (``dy < 0``: the span begins after it) is the crossing rounded down, held to the box,
    and checked with ``E`` at it and at the next centre (computed exactly as the batched pass computes it);
    the few entries the check refuses (a crossing within rounding of a centre) are moved a centre at a time.
    """
    n = len(e_row)
    thr, strict = np.broadcast_to(thr, (n,)), np.broadcast_to(strict, (n,))

    def holds(px, i=slice(None)):
        e = e_row[i] - dy[i] * (px - px0[i])
        return np.where(strict[i], e > thr[i], e >= thr[i])

    dec = dy > 0  # in: px <= last; dy < 0: in from first = last + 1 on; dy == 0: E is e_row on the whole row
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        cross = px0 + (e_row - thr) / dy
    flat = ~(dec | (dy < 0))
    last = np.clip(np.floor(np.where(flat, bx1, cross)), bx0 - 1.0, bx1)  # last centre with dec's E in
    in_at = holds(last)  # E at ``last`` and at ``last + 1``, by each entry's direction
    in_next = holds(last + 1.0)
    below, above = last < bx0, last >= bx1  # past the box: that side's centre is not asked about
    ok = np.where(dec, (below | in_at) & (above | ~in_next), (below | ~in_at) & (above | in_next))
    for i in np.flatnonzero(~ok & ~flat):  # a crossing within rounding of a centre: move a centre at a time
        sign = 1.0 if dec[i] else -1.0  # +: E falls with px
        while last[i] < bx1[i] and (holds(last[i] + 1.0, i) if sign > 0 else not holds(last[i] + 1.0, i)):
            last[i] += 1.0
        while last[i] >= bx0[i] and (not holds(last[i], i) if sign > 0 else holds(last[i], i)):
            last[i] -= 1.0
    lo = np.where(dec | flat, bx0, last + 1.0)
    hi = np.where(dec, last, bx1)
    hi = np.where(flat & ~holds(px0), lo - 1.0, hi)  # a flat edge: the whole row or none of it
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
    z = p_cam[:, 2][tris]  # (T, 3)
    near, far = float(camera.near), float(camera.far)
    whole = ((z >= near) & (z <= far)).all(axis=1)
    gone = (z < near).all(axis=1) | (z > far).all(axis=1)
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


def _image_triangles(hint, whole, shape) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``hint``'s runs along each row of one fan triangle kept whole by the clip planes: ``(first, last, triangle)``,
    flat centres and that triangle's index among the image triangles (the whole ones come first, in the fan's
    order)."""
    flat = np.asarray(hint).reshape(shape[0] * shape[1])
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
    return first[keep], last[keep], tri[keep]


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
        None if hint is None or several else (lambda: _image_triangles(hint, whole, shape)),
    )
    inside = buf.inside.reshape(shape)
    ties = (buf.near_open & ~buf.robust).reshape(shape)
    ids = np.where(buf.inside, 0, NO_OBJECT).astype(np.int64)
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
