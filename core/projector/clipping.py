"""Clipping segments in camera space, before the perspective divide.

Every plane is a half-space ``n . p_cam + d >= 0`` (inside). A segment
``p(t) = p0 + t (p1 - p0)``, t in [0, 1], is clipped against each plane in
turn (Liang-Barsky): with signed distances ``d0, d1`` of its ends,

    case 1  d0 >= 0 and d1 >= 0   both ends inside: kept as is
    case 2  d0 <  0 and d1 <  0   both ends outside: dropped
    case 3  d0 <  0 <= d1         enters: t_enter = max(t_enter, d0 / (d0 - d1))
    case 4  d0 >= 0 >  d1         leaves: t_exit  = min(t_exit,  d0 / (d0 - d1))
    case 5  after all planes, t_enter > t_exit: the pieces kept by different
            planes do not overlap (e.g. the segment passes beside the frustum
            corner): dropped

A point exactly on a plane (d = 0) is inside: a segment lying on the near plane
is drawn. The planes are near (z >= near), far (z <= far) and, so that no
projected coordinate can overflow, the four sides of the image, written
linearly in camera space (for perspective, ``x_px >= -0.5`` is
``f x + (cx + 0.5) z >= 0``, valid once z > 0 is guaranteed by the near plane,
which is therefore clipped first).

Triangles (:func:`clip_triangles`, for the depth buffer of core.projector.zbuffer) are
clipped against one plane at a time by Sutherland-Hodgman: a triangle with 3
vertices inside is kept, with 0 dropped, with 1 inside cut to one triangle,
with 2 inside cut to a quad split along a diagonal (0-2 triangles out per
triangle in, winding kept).
"""

from __future__ import annotations

import numpy as np

from ..camera import Camera
from .projection import cam_to_px

#: How edges crossing near or far are handled: "clip" cuts them at the plane,
#: "endpoint" drops an edge with an end outside [near, far].
CLIP_MODES = ("clip", "endpoint")


def frustum_planes(camera: Camera, guard_px: float = 0.0, sides: bool = True) -> np.ndarray:
    """``(P, 4)`` planes ``[nx, ny, nz, d]`` in camera space, near and far first.

    The side planes sit ``guard_px`` pixels outside the image edges
    ([-0.5, W - 0.5] x [-0.5, H - 0.5]).
    """
    planes = [[0.0, 0.0, 1.0, -camera.near], [0.0, 0.0, -1.0, camera.far]]
    if sides:
        cx, cy = camera.principal_point
        left = cx + 0.5 + guard_px  # pixels from cx to the left edge
        right = camera.width - 0.5 + guard_px - cx
        top = cy + 0.5 + guard_px
        bottom = camera.height - 0.5 + guard_px - cy
        if camera.projection == "perspective":
            fx, fy = camera.focal_xy  # a distorted camera: the undistorted frustum (core.projector.distortion)
            planes += [[fx, 0.0, left, 0.0], [-fx, 0.0, right, 0.0], [0.0, -fy, top, 0.0], [0.0, fy, bottom, 0.0]]
        else:
            s = camera.height / camera.ortho_height
            planes += [[s, 0.0, 0.0, left], [-s, 0.0, 0.0, right], [0.0, -s, 0.0, top], [0.0, s, 0.0, bottom]]
    return np.asarray(planes, dtype=np.float64)


def clip_segments(seg_cam: np.ndarray, planes: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Clip ``(M, 2, 3)`` segments against half-spaces; Liang-Barsky, vectorised.

    Returns ``(kept, t_enter, t_exit)``: ``kept`` is ``(M,) bool`` and the kept
    part of segment m is ``p0 + t (p1 - p0)`` for t in [t_enter[m], t_exit[m]].
    """
    p0 = seg_cam[:, 0, :]
    p1 = seg_cam[:, 1, :]
    m = len(seg_cam)
    t_enter = np.zeros(m, dtype=seg_cam.dtype)  # in the run's dtype (float32 or float64)
    t_exit = np.ones(m, dtype=seg_cam.dtype)
    kept = np.ones(m, dtype=bool)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):  # inf/NaN are handled below
        for n_x, n_y, n_z, d in planes:
            d0 = n_x * p0[:, 0] + n_y * p0[:, 1] + n_z * p0[:, 2] + d
            d1 = n_x * p1[:, 0] + n_y * p1[:, 1] + n_z * p1[:, 2] + d
            out0 = d0 < 0
            out1 = d1 < 0
            kept &= ~(out0 & out1)  # case 2
            t_cross = d0 / (d0 - d1)
            enter = out0 & ~out1  # case 3
            t_enter = np.where(enter, np.maximum(t_enter, t_cross), t_enter)
            leave = ~out0 & out1  # case 4
            t_exit = np.where(leave, np.minimum(t_exit, t_cross), t_exit)
            kept &= ~(np.isnan(d0) | np.isnan(d1))  # NaN input: dropped
    kept &= t_enter <= t_exit  # case 5
    return kept, t_enter, t_exit


def apply_clip(
    seg_cam: np.ndarray,
    kept: np.ndarray,
    t_enter: np.ndarray,
    t_exit: np.ndarray,
    depth_range: tuple[float, float] | None = None,
) -> np.ndarray:
    """The kept parts of the segments, ``(K, 2, 3)``.

    ``p0 + t (p1 - p0)`` loses about ``eps * |p|`` of absolute precision: at
    coordinates of 1e16 that is the whole near distance, and a clipped end
    could land at z <= 0. Every kept point lies in the frustum by construction,
    so with ``depth_range = (near, far)`` its depth is clamped back into it and
    the divide stays safe whatever the magnitudes.
    """
    p0 = seg_cam[kept, 0, :]
    d = seg_cam[kept, 1, :] - p0
    out = np.stack([p0 + t_enter[kept, None] * d, p0 + t_exit[kept, None] * d], axis=1)
    if depth_range is not None:
        np.clip(out[..., 2], depth_range[0], depth_range[1], out=out[..., 2])
    return out


def clip_edges(seg_cam: np.ndarray, camera: Camera) -> tuple[np.ndarray, ...]:
    """Segments ``(E, 2, 3)`` in camera space clipped to the frustum, projected, then cut to the image.

    Returns ``(seg_cam (K, 2, 3), seg_px (K, 2, 2), on (K,) bool, p0_px (M, 2),
    p1_px (M, 2))``: the ``K`` segments left inside the frustum (camera space,
    in ``seg_cam``'s dtype) and their pixels, which of them reach the image, and
    those ``M`` cut to it (:func:`clip_to_image`).
    """
    planes = frustum_planes(camera).astype(seg_cam.dtype)
    kept, t0, t1 = clip_segments(seg_cam, planes)
    seg_cam = apply_clip(seg_cam, kept, t0, t1, (camera.near, camera.far))  # camera, inside the frustum
    seg_px = cam_to_px(seg_cam.reshape(-1, 3), camera).reshape(-1, 2, 2)  # pixels
    on, p0_px, p1_px = clip_to_image(seg_px[:, 0], seg_px[:, 1], camera.width, camera.height)
    return seg_cam, seg_px, on, p0_px, p1_px


def clip_to_image(
    p0_px: np.ndarray, p1_px: np.ndarray, width: int, height: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Liang-Barsky in pixel space against [-0.5, W - 0.5] x [-0.5, H - 0.5].

    A last guard before rasterizing: whatever precision the 3D clip lost, the
    rasterizer is never asked to step through more than the image. Segments
    with a non-finite end are dropped. Returns ``(kept, q0, q1)``.
    """
    d = p1_px - p0_px
    t0 = np.zeros(len(d), dtype=d.dtype)
    t1 = np.ones(len(d), dtype=d.dtype)
    kept = np.all(np.isfinite(p0_px), axis=1) & np.all(np.isfinite(p1_px), axis=1)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        for axis, lo, hi in ((0, -0.5, width - 0.5), (1, -0.5, height - 0.5)):
            for p, q in ((-d[:, axis], p0_px[:, axis] - lo), (d[:, axis], hi - p0_px[:, axis])):
                parallel = p == 0
                kept &= ~(parallel & (q < 0))  # parallel and outside
                r = q / p
                t0 = np.where(~parallel & (p < 0), np.maximum(t0, r), t0)
                t1 = np.where(~parallel & (p > 0), np.minimum(t1, r), t1)
        kept &= t0 <= t1
        q0 = p0_px[kept] + t0[kept, None] * d[kept]
        q1 = p0_px[kept] + t1[kept, None] * d[kept]
    return kept, q0, q1


# ---- triangles ----------------------------------------------------------------


def clip_triangles(
    tri_cam: np.ndarray, planes, src: np.ndarray | None = None, snap_z: list | None = None
) -> tuple[np.ndarray, np.ndarray]:
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
    dist = tri @ n + d  # (T, 3)
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
    one = count == 1  # A inside, B and C outside
    if one.any():
        t, dd = rotated(one, np.argmax(inside[one], axis=1))
        a, b, c = t[:, 0], t[:, 1], t[:, 2]
        keep = dd[:, 0] > 0  # A on the plane: nothing left
        out_tri.append(np.stack([a, cut(a, dd[:, 0], b, dd[:, 1]), cut(a, dd[:, 0], c, dd[:, 2])], axis=1)[keep])
        out_src.append(src[one][keep])
    two = count == 2  # O outside, B and C inside
    if two.any():
        t, dd = rotated(two, np.argmin(inside[two], axis=1))
        o, b, c = t[:, 0], t[:, 1], t[:, 2]
        p_ob = cut(b, dd[:, 1], o, dd[:, 0])  # == b when b is on the plane
        p_co = cut(c, dd[:, 2], o, dd[:, 0])  # == c when c is on the plane
        k1, k2 = dd[:, 1] > 0, dd[:, 2] > 0
        out_tri.append(np.stack([p_ob, b, c], axis=1)[k1])
        out_tri.append(np.stack([p_ob, c, p_co], axis=1)[k2])
        out_src += [src[two][k1], src[two][k2]]
    return np.concatenate(out_tri), np.concatenate(out_src)


def clip_triangles_near(tri_cam: np.ndarray, near: float, far: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Clip triangles to ``z >= near`` (and ``z <= far`` when given); see :func:`clip_triangles`.

    Returns ``(tri (T', 3, 3), src (T',))``; new vertices lie exactly on the plane.
    """
    planes = [[0.0, 0.0, 1.0, -float(near)]]
    snap = [float(near)]
    if far is not None:
        planes.append([0.0, 0.0, -1.0, float(far)])
        snap.append(float(far))
    return clip_triangles(tri_cam, planes, snap_z=snap)
