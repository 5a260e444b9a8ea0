"""Triangles into a depth buffer: coverage by the top-left rule, perspective-correct depth.

Pixel convention (core.conventions): integer coordinates are pixel centres, x
right (columns), y down (rows). Depth is the **linear camera depth** ``z_cam``
everywhere (not a window depth): ``+inf`` where nothing was drawn.

Triangle rasterization (:func:`rasterize_triangles`)
====================================================
1. Vertices are snapped to 1/256 px (:data:`SUBPIXEL`), the sub-pixel grid of
   Mesa's llvmpipe (also used by core.projector.raster for lines). Every edge function
   below is then an exact multiple of 2^-16 px^2, computed exactly in float64
   for coordinates within +-2^16 px (the guard band of
   :func:`project_triangles` keeps them there), so ties are decided exactly.
2. A pixel is covered when its centre ``(x, y)`` (integers) is inside the
   triangle. With the triangle oriented so that the edge functions
   ``E(p) = (Q - P) x (p - P) = (Qx - Px)(y - Py) - (Qy - Py)(x - Px)`` of its
   edges ``P -> Q`` are positive inside (clockwise *on screen*, y down), a
   centre is covered when every ``E > 0``, or ``E == 0`` on a **top** or
   **left** edge (the GL/D3D top-left rule). In y-down pixel space, with this
   orientation, a top edge is horizontal with ``Qx > Px`` (the interior is
   below it, at larger y), and a left edge has ``Qy < Py`` (it goes up the
   screen; the interior is to its right). Two triangles sharing an edge
   traverse it in opposite directions, so exactly one of them owns a centre
   on it. Degenerate (zero-area) triangles cover nothing.
3. Depth at a covered centre is perspective-correct: ``1/z`` is linear in
   screen space under perspective (``z`` under orthographic), so it is
   evaluated at the centre on the plane through the three vertices
   (``1/z = 1/z_a + g . (p - a)``, ``g`` its screen-space gradient). That plane
   goes through the *unsnapped* vertices: snapping decides coverage only, as in
   llvmpipe (a plane through snapped vertices is off by ~|dz/dpx| / 512;
   tests/test_zbuffer.py bounds the difference from pyrender's depth).
4. Nearest wins; equal depths go to the lower triangle index.

Work is vectorised over the rows of per-triangle bounding boxes (clipped to
the image): on a row each edge function is affine in x, so the covered
centres form one span, solved per edge by a rounded division and then
corrected by evaluating ``E`` exactly at its ends (so the top-left rule holds
exactly). Batches hold at most :data:`CHUNK_SAMPLES` bounding-box pixels, big
triangles split into row slabs, so memory stays bounded whatever the triangle
sizes.

Triangles are clipped in camera space first (core.projector.clipping.clip_triangles):
against near and far always, and against side planes :data:`GUARD_PX` pixels
outside the image only when some vertex projects beyond them (so coordinates
stay small; the image itself is unaffected). Lines are tested against the
buffer in core.projector.hidden_lines.
"""

from __future__ import annotations

import numpy as np

from ..camera import Camera
from .clipping import clip_triangles, clip_triangles_near, frustum_planes
from .projection import cam_to_px
from .raster import SUBPIXEL, snap_subpixel

__all__ = ["CHUNK_SAMPLES", "GUARD_PX", "project_triangles", "rasterize_triangles", "triangle_gradients"]

#: Candidate pixels (bounding-box samples) per batch: ~10 float64 temporaries of
#: this length, i.e. a few tens of MB at most.
CHUNK_SAMPLES = 1 << 19
#: Side planes for triangles reaching far off the image, in pixels beyond the edges.
GUARD_PX = 4096.0
_E_STEP = 1.0 / (SUBPIXEL * SUBPIXEL)  # edge functions are multiples of 2^-16


def project_triangles(tri_cam: np.ndarray, camera: Camera) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Clip to [near, far] (and the guard band if needed), then project.

    Returns ``(tri_px (T', 3, 2), tri_z (T', 3), src (T',))`` in float64.
    """
    tri, src = clip_triangles_near(tri_cam, camera.near, camera.far)
    tri_px = cam_to_px(tri.reshape(-1, 3), camera).reshape(-1, 3, 2)
    lo_x, hi_x = -0.5 - GUARD_PX, camera.width - 0.5 + GUARD_PX
    lo_y, hi_y = -0.5 - GUARD_PX, camera.height - 0.5 + GUARD_PX
    with np.errstate(invalid="ignore"):
        off = ~(
            (tri_px[..., 0] >= lo_x) & (tri_px[..., 0] <= hi_x) & (tri_px[..., 1] >= lo_y) & (tri_px[..., 1] <= hi_y)
        ).all(axis=1)
    if off.any():
        # Only the triangles reaching beyond the guard band: clipping moves
        # nothing inside the image, and the common case pays nothing.
        sides = frustum_planes(camera, guard_px=GUARD_PX)[2:]
        far_tri, far_src = clip_triangles(tri[off], sides, src[off])
        far_px = cam_to_px(far_tri.reshape(-1, 3), camera).reshape(-1, 3, 2)
        tri = np.concatenate([tri[~off], far_tri])
        tri_px = np.concatenate([tri_px[~off], far_px])
        src = np.concatenate([src[~off], far_src])
        order = np.argsort(src, kind="stable")
        tri, tri_px, src = tri[order], tri_px[order], src[order]
    return tri_px, tri[..., 2].copy(), src


# ---- triangle setup ---------------------------------------------------------


class _Setup:
    """Snapped, oriented triangles with their edge functions (module docstring)."""

    def __init__(self, tri_px, tri_z, projection):
        raw = np.asarray(tri_px, dtype=np.float64).reshape(-1, 3, 2)
        z = np.asarray(tri_z, dtype=np.float64).reshape(-1, 3)
        with np.errstate(invalid="ignore", over="ignore"):
            ok = np.isfinite(raw).all(axis=(1, 2)) & np.isfinite(z).all(axis=1)
            raw = np.where(ok[:, None, None], raw, 0.0)
            px = snap_subpixel(raw)
            z = np.where(ok[:, None], z, 1.0)
            area2 = _area2(px)
        flip = area2 < 0  # make E > 0 inside
        px = np.where(flip[:, None, None], px[:, [0, 2, 1]], px)
        raw = np.where(flip[:, None, None], raw[:, [0, 2, 1]], raw)
        z = np.where(flip[:, None], z[:, [0, 2, 1]], z)
        self.ok = ok & (area2 != 0)
        self.area2 = np.abs(area2)
        self.px = px
        self.perspective = projection == "perspective"
        # edge k is opposite vertex k: (b -> c), (c -> a), (a -> b)
        p = px[:, [1, 2, 0]]
        q = px[:, [2, 0, 1]]
        self.p = p  # (T, 3, 2) edge start
        self.dx = q[..., 0] - p[..., 0]  # (T, 3)
        self.dy = q[..., 1] - p[..., 1]
        top_left = (self.dy < 0) | ((self.dy == 0) & (self.dx > 0))
        self.thr = np.where(top_left, 0.0, _E_STEP)  # E >= thr  <=>  covered by this edge
        # Depth plane: the value interpolated linearly in screen space (1/z under
        # perspective, z otherwise) through the *unsnapped* vertices, as llvmpipe
        # does (snapping is for coverage only; measured: snapped planes differ from
        # pyrender's depth by ~slope/512, unsnapped ones by its quantisation only).
        # Where snapping changed the orientation (sub-pixel slivers) the snapped
        # vertices are used instead.
        with np.errstate(divide="ignore"):
            w = 1.0 / z if self.perspective else z
        plane_px = np.where((_area2(raw) > 0)[:, None, None], raw, px)
        a, b, c = plane_px[:, 0], plane_px[:, 1], plane_px[:, 2]
        with np.errstate(divide="ignore", invalid="ignore"):
            a2 = _area2(plane_px)
            e_dx = np.stack([c[:, 0] - b[:, 0], a[:, 0] - c[:, 0], b[:, 0] - a[:, 0]], axis=1)
            e_dy = np.stack([c[:, 1] - b[:, 1], a[:, 1] - c[:, 1], b[:, 1] - a[:, 1]], axis=1)
            gx = (-e_dy * w).sum(axis=1) / a2
            gy = (e_dx * w).sum(axis=1) / a2
        ok_plane = self.ok & np.isfinite(gx) & np.isfinite(gy)
        self.ok = ok_plane
        self.gx = np.where(ok_plane, gx, 0.0)
        self.gy = np.where(ok_plane, gy, 0.0)
        self.anchor = a  # value w0 at vertex a
        self.w0 = w[:, 0]

    def gradients(self) -> np.ndarray:
        """``(T, 2)`` screen-space gradient of the interpolated value (1/z or z)."""
        return np.stack([self.gx, self.gy], axis=1)


def _area2(px: np.ndarray) -> np.ndarray:
    """Twice the signed area ``(b - a) x (c - a)`` of ``(T, 3, 2)`` triangles (y down)."""
    a, b, c = px[:, 0], px[:, 1], px[:, 2]
    return (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])


def triangle_gradients(tri_px: np.ndarray, tri_z: np.ndarray, projection: str) -> np.ndarray:
    """``(T, 2)``: ``d/dx, d/dy`` (per pixel) of ``1/z`` (perspective) or ``z`` (orthographic).

    Zero for degenerate or non-finite triangles.
    """
    return _Setup(tri_px, tri_z, projection).gradients()


def rasterize_triangles(
    tri_px: np.ndarray, tri_z: np.ndarray, width: int, height: int, projection: str = "perspective"
) -> tuple[np.ndarray, np.ndarray]:
    """Depth-buffer ``T`` projected triangles (module docstring for the rules).

    Parameters
    ----------
    tri_px : (T, 3, 2) array
        Vertex pixel coordinates (clipped at near/far beforehand).
    tri_z : (T, 3) array
        Their camera depths ``z_cam``.
    width, height : int
    projection : "perspective" or "orthographic"
        Selects perspective-correct (1/z) or linear depth interpolation.

    Returns
    -------
    depth : (H, W) float64, linear ``z_cam`` of the nearest triangle, +inf where empty.
    face : (H, W) int32, its index into ``tri_px``, -1 where empty.
    """
    s = _Setup(tri_px, tri_z, projection)
    depth = np.full(width * height, np.inf)
    face = np.full(width * height, -1, dtype=np.int32)
    if not s.ok.any():
        return depth.reshape(height, width), face.reshape(height, width)
    xs, ys = s.px[..., 0], s.px[..., 1]
    with np.errstate(invalid="ignore"):
        x0 = np.clip(np.ceil(xs.min(axis=1)), 0, width)
        x1 = np.clip(np.floor(xs.max(axis=1)), -1, width - 1)
        y0 = np.clip(np.ceil(ys.min(axis=1)), 0, height)
        y1 = np.clip(np.floor(ys.max(axis=1)), -1, height - 1)
    bw = (x1 - x0 + 1).astype(np.int64)
    bh = (y1 - y0 + 1).astype(np.int64)
    live = s.ok & (bw > 0) & (bh > 0)
    tri_id = np.flatnonzero(live)
    x0, y0, bw, bh = x0[live].astype(np.int64), y0[live].astype(np.int64), bw[live], bh[live]
    # Split bounding boxes taller than a batch into row slabs.
    rows_max = np.maximum(CHUNK_SAMPLES // bw, 1)
    pieces = -(-bh // rows_max)
    if (pieces > 1).any():
        pid = np.repeat(np.arange(len(tri_id)), pieces)
        k = np.arange(len(pid)) - np.repeat(np.cumsum(pieces) - pieces, pieces)
        y_start = y0[pid] + k * rows_max[pid]
        bh = np.minimum(rows_max[pid], y0[pid] + bh[pid] - y_start)
        tri_id, x0, y0, bw = tri_id[pid], x0[pid], y_start, bw[pid]
    count = bw * bh
    ends = np.cumsum(count)
    start = 0
    while start < len(count):
        base = ends[start] - count[start]
        stop = max(int(np.searchsorted(ends, base + CHUNK_SAMPLES, side="right")), start + 1)
        _raster_batch(
            s, tri_id[start:stop], x0[start:stop], y0[start:stop], bw[start:stop], bh[start:stop], width, depth, face
        )
        start = stop
    return depth.reshape(height, width), face.reshape(height, width)


def _raster_batch(s: _Setup, tri, x0, y0, bw, bh, width, depth, face) -> None:
    """Rasterize one batch: per bounding-box row, the exact span of covered centres."""
    # Rows: (triangle, y). On row y the edge function is affine in the column
    # offset i = x - x0:  E = E_row + a i,  E_row = dx (y - Py) - dy (x0 - Px),
    # a = -dy, all exact multiples of 2^-16. Each edge bounds i from one side.
    rows = int(bh.sum())
    r_t = np.repeat(np.arange(len(tri)), bh)
    y = y0[r_t] + (np.arange(rows, dtype=np.int64) - np.repeat(np.cumsum(bh) - bh, bh))
    t = tri[r_t]
    fx0 = x0[r_t].astype(np.float64)
    fy = y.astype(np.float64)
    n_i = bw[r_t]  # i in [0, n_i - 1]
    lo = np.zeros(rows, dtype=np.int64)
    hi = n_i - 1
    for edge in range(3):
        dx, dy = s.dx[t, edge], s.dy[t, edge]
        a = -dy
        # E_row - thr: covered by this edge  <=>  rest + a i >= 0   (exact)
        rest = dx * (fy - s.p[t, edge, 1]) + a * (fx0 - s.p[t, edge, 0]) - s.thr[t, edge]
        with np.errstate(divide="ignore", invalid="ignore"):
            q = -rest / a  # rounded; fixed up exactly below
        pos, neg = a > 0, a < 0
        # a > 0: i >= q
        c = np.clip(np.ceil(np.where(pos, q, 0.0)), 0, n_i).astype(np.int64)
        c -= pos & (c > 0) & (rest + a * (c - 1) >= 0)
        c += pos & (c < n_i) & (rest + a * c < 0)
        lo = np.where(pos, np.maximum(lo, c), lo)
        # a < 0: i <= q
        c = np.clip(np.floor(np.where(neg, q, 0.0)), -1, n_i - 1).astype(np.int64)
        c += neg & (c < n_i - 1) & (rest + a * (c + 1) >= 0)
        c -= neg & (c >= 0) & (rest + a * c < 0)
        hi = np.where(neg, np.minimum(hi, c), hi)
        # a == 0 (horizontal edge): the whole row or nothing
        hi = np.where((a == 0) & (rest < 0), -1, hi)
    count = np.maximum(hi - lo + 1, 0)
    if not count.any():
        return
    # Covered centres, with the depth plane stepped along the row.
    base = s.w0[t] + s.gx[t] * (fx0 + lo - s.anchor[t, 0]) + s.gy[t] * (fy - s.anchor[t, 1])
    n = int(count.sum())
    rep = np.repeat(np.arange(rows), count)
    k = np.arange(n, dtype=np.int64) - np.repeat(np.cumsum(count) - count, count)
    val = base[rep] + s.gx[t][rep] * k
    z = 1.0 / val if s.perspective else val
    pix = y[rep] * width + (x0[r_t] + lo)[rep] + k
    ts = t[rep].astype(np.int32)
    old_z = depth[pix]
    old_f = face[pix]
    np.minimum.at(depth, pix, z)
    win = z == depth[pix]  # at the new minimum (possibly tied with the old one)
    if not win.any():
        return
    pw = pix[win]
    face[pw] = np.where(old_z[win] == z[win], old_f[win], np.iinfo(np.int32).max)
    np.minimum.at(face, pw, ts[win])  # ties: the lower triangle index
