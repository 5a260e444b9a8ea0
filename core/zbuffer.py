"""Triangles into a depth buffer, and the depth of line pixels against it.

Pixel convention (core.conventions): integer coordinates are pixel centres, x
right (columns), y down (rows). Depth is the **linear camera depth** ``z_cam``
everywhere (not a window depth): ``+inf`` where nothing was drawn.

Triangle rasterization (:func:`rasterize_triangles`)
====================================================
1. Vertices are snapped to 1/256 px (:data:`SUBPIXEL`), the sub-pixel grid of
   Mesa's llvmpipe (also used by core.raster for lines). Every edge function
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
   llvmpipe (measured on a cube at 640x480: a plane through the snapped
   vertices differs from pyrender's depth by up to 1.1e-4, ~|dz/dpx| / 512;
   the unsnapped plane by 6e-6, pyrender's own quantisation; see
   tests/test_zbuffer.py for the bound).
4. Nearest wins; equal depths go to the lower triangle index.

Work is vectorised over the rows of per-triangle bounding boxes (clipped to
the image): on a row each edge function is affine in x, so the covered
centres form one span, solved per edge by a rounded division and then
corrected by evaluating ``E`` exactly at its ends (so the top-left rule holds
exactly). Batches hold at most :data:`CHUNK_SAMPLES` bounding-box pixels, big
triangles split into row slabs, so memory stays bounded whatever the triangle
sizes; 100k triangles of a sphere filling a 640x480 image take ~0.1-0.2 s.

Triangles are clipped in camera space first (:func:`clip_triangles`,
Sutherland-Hodgman against one plane at a time, 0-2 triangles out per
triangle in): against near and far always, and against side planes
:data:`GUARD_PX` pixels outside the image only when some vertex projects
beyond them (so coordinates stay small; the image itself is unaffected).

Lines against the buffer (:func:`visible_line_samples`)
=======================================================
A drawn line pixel at major coordinate ``i`` gets the depth of the segment at
``i``: ``t = (i - a0) / (a1 - a0)`` along the major axis (clamped to [0, 1]) and
``1/z = lerp(1/z0, 1/z1, t)`` (perspective), ``z = lerp(z0, z1, t)``
(orthographic). It is drawn when::

    z_line <= z_buffer + bias,
    bias = k max(|dz/dx|, |dz/dy|) + 2^-24 dz/dz_w,     k = 1 for raster "exact"

with k = 1, the first-order image in linear depth of ``glPolygonOffset(1, 1)`` on a 24-bit
window depth buffer, which is what the pyrender oracle applies to its faces
(``z_w`` is window depth; ``dz/dz_w = (far - near) z^2 / (far near)`` for
perspective, ``far - near`` for orthographic). The slope term is what keeps a
line on a face's boundary from being hidden by its own face: the pixel
centre is up to 1/2 px (minor axis) from the line point whose depth the line
gets, so the face's depth there differs from the line's by up to
``|dz/dminor| / 2``, half the slope term. ``dz/dx`` is the face's depth slope
at that pixel (``z^2 |d(1/z)/dx|`` under perspective). Raster modes "fast"
and "aa" put pixels up to ~1.5 px from that line point, so they use k = 2
(:data:`SLOPE_FACTOR`). Measured against pyrender (faces black with
glPolygonOffset(1, 1), lines on top): F1@1px = 1.0 and F1@0 >= 0.998 on a cube
and an icosphere (tests/test_hidden_lines.py).
"""

from __future__ import annotations

import numpy as np

from . import raster as _raster
from .camera import Camera
from .clipping import frustum_planes
from .projection import cam_to_px

__all__ = ["SUBPIXEL", "CHUNK_SAMPLES", "GUARD_PX", "DEPTH_UNIT", "SLOPE_FACTOR", "clip_triangles",
           "clip_triangles_near", "project_triangles", "rasterize_triangles",
           "triangle_gradients", "line_samples", "line_sample_depth", "occlusion_bias",
           "visible_line_samples"]

#: Vertex snapping grid (1/256 px), as llvmpipe and core.raster.
SUBPIXEL = 256.0
#: Candidate pixels (bounding-box samples) per batch: ~10 float64 temporaries of
#: this length, i.e. a few tens of MB at most.
CHUNK_SAMPLES = 1 << 19
#: Side planes for triangles reaching far off the image, in pixels beyond the edges.
GUARD_PX = 4096.0
#: Resolution of a 24-bit window depth buffer (GL's ``r`` in glPolygonOffset).
DEPTH_UNIT = 2.0 ** -24
#: Slope factor of the line-vs-face bias per raster mode (module docstring):
#: "exact" pixels are within 1/2 px of their line (minor axis), as GL's, so
#: glPolygonOffset's factor 1 covers them; "fast" (ends rounded to pixels) and
#: "aa" (pixel pairs floor(b), floor(b) + 1; end pixels up to 1/2 px past the
#: end) put pixels up to ~1.5 px (L1) from the line point whose depth they get,
#: hence 2.
SLOPE_FACTOR = {"exact": 1.0, "fast": 2.0, "aa": 2.0}
_E_STEP = 1.0 / (SUBPIXEL * SUBPIXEL)     # edge functions are multiples of 2^-16


# ---- clipping in camera space ---------------------------------------------

def clip_triangles(tri_cam: np.ndarray, planes, src: np.ndarray | None = None,
                   snap_z: list | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Clip ``(T, 3, 3)`` camera-space triangles against half-spaces ``n . p + d >= 0``.

    Sutherland-Hodgman, one plane at a time; per plane a triangle gives 0
    (all vertices outside), 1 (all inside, or one inside) or 2 (two inside: a
    quad, split along a diagonal) triangles, in the winding of the input. A
    vertex on the plane (distance 0) is inside; pieces of zero area (a
    triangle touching the plane from outside) are dropped, as are triangles
    with a non-finite coordinate.

    Parameters
    ----------
    tri_cam : (T, 3, 3) array
    planes : (P, 4) array of ``[nx, ny, nz, d]``
    src : (T,) intp, optional
        Source index of each input triangle (default ``arange(T)``).
    snap_z : list of (P,) float or None, optional
        For each plane, a depth to set exactly on the vertices it creates (the
        near/far planes: no rounding can put a clipped vertex at z < near).

    Returns
    -------
    tri : (T', 3, 3) float64, in order of ``src``
    src : (T',) intp, the input triangle each output triangle came from.
    """
    tri = np.asarray(tri_cam, dtype=np.float64).reshape(-1, 3, 3)
    src = np.arange(len(tri), dtype=np.intp) if src is None else np.asarray(src, dtype=np.intp)
    finite = np.isfinite(tri).all(axis=(1, 2))
    if not finite.all():
        tri, src = tri[finite], src[finite]
    planes = np.asarray(planes, dtype=np.float64).reshape(-1, 4)
    for p, plane in enumerate(planes):
        z_new = None if snap_z is None else snap_z[p]
        tri, src = _clip_plane(tri, src, plane[:3], plane[3], z_new)
    order = np.argsort(src, kind="stable")
    return tri[order], src[order]


def _clip_plane(tri, src, n, d, z_new):
    dist = tri @ n + d                                   # (T, 3)
    inside = dist >= 0
    count = inside.sum(axis=1)
    if count.min(initial=3) == 3:
        return tri, src
    out_tri = [tri[count == 3]]
    out_src = [src[count == 3]]
    rot = np.arange(3)

    def rotated(mask, first):
        # vertices rotated so that vertex `first` comes first (winding kept)
        idx = (first[:, None] + rot[None, :]) % 3
        t = np.take_along_axis(tri[mask], idx[:, :, None], axis=1)
        dd = np.take_along_axis(dist[mask], idx, axis=1)
        return t, dd

    def cut(p_in, d_in, p_out, d_out):
        # point where the edge from an inside vertex to an outside one meets the plane
        with np.errstate(divide="ignore", invalid="ignore"):
            t = d_in / (d_in - d_out)
        q = p_in + t[:, None] * (p_out - p_in)
        if z_new is not None:
            q[:, 2] = z_new
        return q

    # A piece with a vertex on the plane (distance 0) that would repeat that
    # vertex has zero area and is not emitted.
    one = count == 1                                     # A inside, B and C outside
    if one.any():
        t, dd = rotated(one, np.argmax(inside[one], axis=1))
        a, b, c = t[:, 0], t[:, 1], t[:, 2]
        keep = dd[:, 0] > 0                              # A on the plane: nothing left
        out_tri.append(np.stack([a, cut(a, dd[:, 0], b, dd[:, 1]),
                                 cut(a, dd[:, 0], c, dd[:, 2])], axis=1)[keep])
        out_src.append(src[one][keep])
    two = count == 2                                     # O outside, B and C inside
    if two.any():
        t, dd = rotated(two, np.argmin(inside[two], axis=1))
        o, b, c = t[:, 0], t[:, 1], t[:, 2]
        p_ob = cut(b, dd[:, 1], o, dd[:, 0])             # == b when b is on the plane
        p_co = cut(c, dd[:, 2], o, dd[:, 0])             # == c when c is on the plane
        k1, k2 = dd[:, 1] > 0, dd[:, 2] > 0
        out_tri.append(np.stack([p_ob, b, c], axis=1)[k1])
        out_tri.append(np.stack([p_ob, c, p_co], axis=1)[k2])
        out_src += [src[two][k1], src[two][k2]]
    return np.concatenate(out_tri), np.concatenate(out_src)


def clip_triangles_near(tri_cam: np.ndarray, near: float, far: float | None = None
                        ) -> tuple[np.ndarray, np.ndarray]:
    """Clip triangles to ``z >= near`` (and ``z <= far`` when given); see :func:`clip_triangles`.

    Returns ``(tri (T', 3, 3), src (T',))``; new vertices lie exactly on the plane.
    """
    planes = [[0.0, 0.0, 1.0, -float(near)]]
    snap = [float(near)]
    if far is not None:
        planes.append([0.0, 0.0, -1.0, float(far)])
        snap.append(float(far))
    return clip_triangles(tri_cam, planes, snap_z=snap)


def project_triangles(tri_cam: np.ndarray, camera: Camera
                      ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Clip to [near, far] (and the guard band if needed), then project.

    Returns ``(tri_px (T', 3, 2), tri_z (T', 3), src (T',))`` in float64.
    """
    tri, src = clip_triangles_near(tri_cam, camera.near, camera.far)
    tri_px = cam_to_px(tri.reshape(-1, 3), camera).reshape(-1, 3, 2)
    lo_x, hi_x = -0.5 - GUARD_PX, camera.width - 0.5 + GUARD_PX
    lo_y, hi_y = -0.5 - GUARD_PX, camera.height - 0.5 + GUARD_PX
    with np.errstate(invalid="ignore"):
        off = ~((tri_px[..., 0] >= lo_x) & (tri_px[..., 0] <= hi_x)
                & (tri_px[..., 1] >= lo_y) & (tri_px[..., 1] <= hi_y)).all(axis=1)
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
            px = np.round(raw * SUBPIXEL) / SUBPIXEL
            z = np.where(ok[:, None], z, 1.0)
            area2 = _area2(px)
        flip = area2 < 0                                  # make E > 0 inside
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
        self.p = p                                         # (T, 3, 2) edge start
        self.dx = q[..., 0] - p[..., 0]                    # (T, 3)
        self.dy = q[..., 1] - p[..., 1]
        top_left = (self.dy < 0) | ((self.dy == 0) & (self.dx > 0))
        self.thr = np.where(top_left, 0.0, _E_STEP)        # E >= thr  <=>  covered by this edge
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
        self.anchor = a                                    # value w0 at vertex a
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


def rasterize_triangles(tri_px: np.ndarray, tri_z: np.ndarray, width: int, height: int,
                        projection: str = "perspective") -> tuple[np.ndarray, np.ndarray]:
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
        _raster_batch(s, tri_id[start:stop], x0[start:stop], y0[start:stop], bw[start:stop],
                      bh[start:stop], width, depth, face)
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
    n_i = bw[r_t]                                     # i in [0, n_i - 1]
    lo = np.zeros(rows, dtype=np.int64)
    hi = n_i - 1
    for edge in range(3):
        dx, dy = s.dx[t, edge], s.dy[t, edge]
        a = -dy
        # E_row - thr: covered by this edge  <=>  rest + a i >= 0   (exact)
        rest = dx * (fy - s.p[t, edge, 1]) + a * (fx0 - s.p[t, edge, 0]) - s.thr[t, edge]
        with np.errstate(divide="ignore", invalid="ignore"):
            q = -rest / a                             # rounded; fixed up exactly below
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
    win = z == depth[pix]                 # at the new minimum (possibly tied with the old one)
    if not win.any():
        return
    pw = pix[win]
    face[pw] = np.where(old_z[win] == z[win], old_f[win], np.iinfo(np.int32).max)
    np.minimum.at(face, pw, ts[win])      # ties: the lower triangle index


# ---- lines against the depth buffer -----------------------------------------

def _round_half_up(v: np.ndarray) -> np.ndarray:
    r = np.floor(v)
    return r + (v - r >= 0.5)


def line_samples(p0_px: np.ndarray, p1_px: np.ndarray, width: int, height: int, mode: str = "exact"
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray | None]:
    """core.raster's pixels of ``M`` segments, with the segment of each pixel.

    Returns ``(seg, rr, cc, weight)``: ``weight`` is None except for mode "aa".
    The pixels are exactly those of ``raster.line_pixels`` ("exact"),
    ``raster.line_pixels_fast`` ("fast") and, up to ~1e-9 in the weights,
    ``raster.line_coverage_aa`` ("aa").

    core.raster does not say which segment a pixel came from, so each segment
    is moved along its *minor* axis into its own band of a tall (or wide)
    virtual image, by a whole number of pixels: segment m of the x-major ones
    by ``m (H + 2) + 1`` rows, of the y-major ones by ``m (W + 2) + 1`` columns.
    The rasterizer's major-axis arithmetic is untouched and its minor-axis
    arithmetic is exact in integers ("exact" snaps ends to 1/256 px first and
    works in integer grid units, "fast" rounds ends to pixels first; the
    shifted ends are pre-snapped/rounded here so the shift is exact), so the
    pixels are those of the unshifted segment, shifted. The band of a pixel
    gives its segment back; pixels in the margins (one row/column either side)
    are off the real image and are dropped.
    """
    p0 = np.asarray(p0_px, dtype=np.float64).reshape(-1, 2)
    p1 = np.asarray(p1_px, dtype=np.float64).reshape(-1, 2)
    if mode == "exact":
        p0 = np.round(p0 * SUBPIXEL) / SUBPIXEL
        p1 = np.round(p1 * SUBPIXEL) / SUBPIXEL
        fn = _raster.line_pixels
    elif mode == "fast":
        p0, p1 = _round_half_up(p0), _round_half_up(p1)
        fn = _raster.line_pixels_fast
    elif mode == "aa":
        fn = _raster.line_coverage_aa
    else:
        raise ValueError(f"raster mode {mode!r}: expected one of {_raster.RASTER_MODES}")
    d = p1 - p0
    x_major = np.abs(d[:, 0]) > np.abs(d[:, 1])
    out = []
    for major_is_x, minor_axis, size, other in ((True, 1, height, width), (False, 0, width, height)):
        idx = np.flatnonzero(x_major == major_is_x)
        if len(idx) == 0:
            continue
        band = size + 2
        off = np.arange(len(idx), dtype=np.float64) * band + 1.0
        q0, q1 = p0[idx].copy(), p1[idx].copy()
        q0[:, minor_axis] += off
        q1[:, minor_axis] += off
        if minor_axis == 1:
            res = fn(q0, q1, other, len(idx) * band)
            minor = res[0]
        else:
            res = fn(q0, q1, len(idx) * band, other)
            minor = res[1]
        m = minor // band
        local = minor - m * band - 1
        keep = (local >= 0) & (local < size)
        seg = idx[m[keep]]
        if minor_axis == 1:
            rr, cc = local[keep], res[1][keep]
        else:
            rr, cc = res[0][keep], local[keep]
        weight = res[2][keep] if mode == "aa" else None
        out.append((seg, rr, cc, weight))
    if not out:
        e = np.zeros(0, dtype=np.intp)
        return e, e, e, (np.zeros(0) if mode == "aa" else None)
    seg = np.concatenate([o[0] for o in out])
    rr = np.concatenate([o[1] for o in out]).astype(np.intp, copy=False)
    cc = np.concatenate([o[2] for o in out]).astype(np.intp, copy=False)
    weight = np.concatenate([o[3] for o in out]) if mode == "aa" else None
    return seg, rr, cc, weight


def line_sample_depth(seg: np.ndarray, rr: np.ndarray, cc: np.ndarray, a_px: np.ndarray,
                      b_px: np.ndarray, z_a: np.ndarray, z_b: np.ndarray, projection: str) -> np.ndarray:
    """Depth of each line pixel on its segment ``a -> b`` (module docstring).

    ``t`` is the pixel centre's coordinate along the segment's major axis (x
    when ``|dx| > |dy|``), relative to ``a`` and ``b``, clamped to [0, 1];
    then ``1/z = (1 - t)/z_a + t/z_b`` (perspective) or ``z = (1 - t) z_a + t z_b``.
    ``a_px, b_px, z_a, z_b`` are per segment (indexed by ``seg``).
    """
    a = np.asarray(a_px, dtype=np.float64)[seg]
    b = np.asarray(b_px, dtype=np.float64)[seg]
    d = b - a
    x_major = np.abs(d[:, 0]) > np.abs(d[:, 1])
    num = np.where(x_major, cc - a[:, 0], rr - a[:, 1])
    den = np.where(x_major, d[:, 0], d[:, 1])
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(den != 0, num / den, 0.0)
    t = np.clip(t, 0.0, 1.0)
    za = np.asarray(z_a, dtype=np.float64)[seg]
    zb = np.asarray(z_b, dtype=np.float64)[seg]
    if projection == "perspective":
        return 1.0 / ((1.0 - t) / za + t / zb)
    return (1.0 - t) * za + t * zb


def occlusion_bias(z_buf: np.ndarray, grad: np.ndarray, camera: Camera, factor: float = 1.0) -> np.ndarray:
    """``bias`` of the line depth test at pixels of depth ``z_buf`` (module docstring).

    ``grad`` ``(K, 2)`` is the covering triangle's :func:`triangle_gradients`.
    ``factor * max(|dz/dx|, |dz/dy|) + 2^-24 dz/dz_w``: with factor 1,
    glPolygonOffset(1, 1) on a 24-bit depth buffer, to first order, in linear depth.
    """
    g = factor * np.abs(grad).max(axis=1)
    near, far = float(camera.near), float(camera.far)
    if camera.projection == "perspective":
        z2 = z_buf * z_buf
        return g * z2 + DEPTH_UNIT * (far - near) * z2 / (far * near)
    return g + DEPTH_UNIT * (far - near)


def visible_line_samples(seg, rr, cc, a_px, b_px, z_a, z_b, depth: np.ndarray, face: np.ndarray,
                         grad: np.ndarray, camera: Camera, slope_factor: float = 1.0) -> np.ndarray:
    """``(K,) bool``: line pixels not hidden by the depth buffer (``z_line <= z_buf + bias``).

    ``slope_factor`` multiplies the slope term of the bias (:data:`SLOPE_FACTOR`).
    """
    z_line = line_sample_depth(seg, rr, cc, a_px, b_px, z_a, z_b, camera.projection)
    z_buf = depth[rr, cc]
    f = face[rr, cc]
    covered = f >= 0
    visible = np.ones(len(seg), dtype=bool)
    if covered.any():
        zb = z_buf[covered]
        bias = occlusion_bias(zb, grad[f[covered]], camera, slope_factor)
        visible[covered] = z_line[covered] <= zb + bias
    return visible
