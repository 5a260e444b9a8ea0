"""Faces: triangulation, winding checks, back-face and bounding-sphere culling.

Faces are polygons given as tuples of vertex indices, **counter-clockwise seen
from outside** (``scenes/cube.scene``). In the right-handed world frame of
core.conventions their outward normal is therefore::

    n_world = (b - a) x (c - a)          (a, b, c: consecutive vertices)

Back faces
==========
A face is *kept* (front facing) when its outward normal and the view vector
point toward each other, i.e. the camera is on the outer side of its plane::

    perspective:   dot(n_world, p_face_world - camera.position) < 0
    orthographic:  dot(n_world, camera.forward) < 0

Faces seen exactly edge-on (dot == 0) have no visible area and are culled.

:func:`backface_keep` takes camera-space triangles (what the pipeline has; it
never forms world points). Camera space is ``p_cam = R (p_world - position)``
with rows of ``R`` = right, up, forward, a *left-handed* basis (right x up =
-forward): ``det R = -1``, and for a reflection-rotation
``(R u) x (R v) = det(R) R (u x v) = -R (u x v)``. So the cross product of the
camera-space vertices is ``n_cc = -R n_world``, while the view vector is
``R (p - position) = p_cam`` and ``R forward = (0, 0, 1)``; dot products are
preserved by ``R``, hence::

    perspective:   keep  <=>  dot(n_cc, p_cam) > 0
    orthographic:  keep  <=>  n_cc.z > 0

A model matrix with a negative determinant (a mirror) reverses the winding of
the transformed vertices; pass ``mirrored=True`` and the test is reversed.
tests/test_culling.py pins the sign: the cube seen from +Z keeps exactly its
z = +1 face.
"""

from __future__ import annotations

import numpy as np

from ..camera import Camera
from .clipping import frustum_planes

__all__ = [
    "CULL_MODES",
    "CULL_CHOICES",
    "triangulate",
    "face_of_triangle",
    "directed_edges",
    "winding_problem",
    "backface_keep",
    "sphere_outside_frustum",
]

#: Back-face culling of render_frame: None (off) or "backface".
CULL_MODES = (None, "backface")
#: The same, as the command lines spell them ("none": off).
CULL_CHOICES = tuple("none" if m is None else m for m in CULL_MODES)


def fan_triangles(faces) -> tuple[np.ndarray, np.ndarray]:
    """``(tris (T, 3) intp, face_of_tri (T,) intp)``: fan from each polygon's first vertex."""
    if isinstance(faces, np.ndarray) and faces.dtype.kind in "iu" and faces.ndim == 2:
        f, k = faces.shape
        if k < 3 or f == 0:
            return np.zeros((0, 3), dtype=np.intp), np.zeros(0, dtype=np.intp)
        faces = faces.astype(np.intp, copy=False)
        j = np.arange(1, k - 1)
        tris = np.stack([np.repeat(faces[:, :1], k - 2, axis=1), faces[:, j], faces[:, j + 1]], axis=2)
        return tris.reshape(-1, 3), np.repeat(np.arange(f, dtype=np.intp), k - 2)
    # Ragged polygons: group by length so each group is one vectorised fan.
    faces = [tuple(int(v) for v in face) for face in faces]
    lengths = np.fromiter((len(face) for face in faces), dtype=np.intp, count=len(faces))
    tris_parts, face_parts = [], []
    for k in np.unique(lengths):
        if k < 3:
            continue
        idx = np.flatnonzero(lengths == k)
        block = np.asarray([faces[i] for i in idx], dtype=np.intp).reshape(-1, int(k))
        t, f = fan_triangles(block)
        tris_parts.append(t)
        face_parts.append(idx[f])
    if not tris_parts:
        return np.zeros((0, 3), dtype=np.intp), np.zeros(0, dtype=np.intp)
    tris = np.concatenate(tris_parts)
    face_of = np.concatenate(face_parts)
    order = np.argsort(face_of, kind="stable")  # triangles in polygon order
    return tris[order], face_of[order]


def triangulate(faces) -> np.ndarray:
    """``(T, 3) intp`` triangles: polygon ``(v0, v1, ..., vk)`` becomes ``(v0, vi, vi+1)``.

    ``faces`` is a sequence of index tuples (any lengths >= 3; shorter ones are
    skipped) or an ``(F, k)`` integer array. Triangles come in polygon order and
    keep the polygon's winding. See :func:`face_of_triangle` for the map back.
    """
    return fan_triangles(faces)[0]


def face_of_triangle(faces) -> np.ndarray:
    """``(T,) intp``: the polygon index of each triangle of :func:`triangulate`."""
    return fan_triangles(faces)[1]


def directed_edges(faces) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Boundary edges ``i -> j`` of every polygon, in order: ``(i, j, face, position)``.

    Polygon ``(v0, ..., vk)`` gives ``v0->v1, ..., vk->v0``; all arrays ``(K,)`` int.
    """
    if isinstance(faces, np.ndarray) and faces.dtype.kind in "iu" and faces.ndim == 2:
        f, k = faces.shape
        flat = faces.astype(np.int64).ravel()
        lengths = np.full(f, k, dtype=np.intp)
    else:
        faces = [tuple(int(v) for v in face) for face in faces]
        lengths = np.fromiter((len(f) for f in faces), dtype=np.intp, count=len(faces))
        flat = np.fromiter((v for f in faces for v in f), dtype=np.int64, count=int(lengths.sum()))
    face_id = np.repeat(np.arange(len(lengths)), lengths)
    starts = np.cumsum(lengths) - lengths
    pos = np.arange(len(flat)) - np.repeat(starts, lengths)
    nxt = np.where(pos + 1 < np.repeat(lengths, lengths), np.arange(len(flat)) + 1, np.repeat(starts, lengths))
    return flat, flat[nxt], face_id, pos


def winding_problem(faces) -> str | None:
    """A one-line message if two faces traverse the same directed edge, else None.

    Consistently wound faces of a mesh use each directed edge ``i -> j`` at most
    once (the neighbour across an edge traverses it ``j -> i``). Reported: the
    first violation in face order (the smallest later face, then its first such
    edge), naming the earlier face too. Self-loops (repeated consecutive
    indices) are ignored.
    """
    i, j, face_id, pos = directed_edges(faces)
    keep = i != j
    i, j, face_id, pos = i[keep], j[keep], face_id[keep], pos[keep]
    if len(i) == 0:
        return None
    order = np.lexsort((pos, face_id, j, i))  # by edge, then face, then position
    i, j, face_id, pos = i[order], j[order], face_id[order], pos[order]
    same = (i[1:] == i[:-1]) & (j[1:] == j[:-1])
    if not same.any():
        return None
    # group start (first use of each directed edge) for every element
    new_group = np.concatenate([[True], ~same])
    first = np.maximum.accumulate(np.where(new_group, np.arange(len(i)), 0))
    dup = np.flatnonzero(~new_group)  # later uses of an already used edge
    k = dup[np.lexsort((pos[dup], face_id[dup]))[0]]  # smallest later face, then position
    a, b = int(face_id[first[k]]), int(face_id[k])
    edge = f"{int(i[k])}->{int(j[k])}"
    if a == b:
        return f"face {a} traverses edge {edge} twice: inconsistent winding"
    return f"faces {a} and {b} both traverse edge {edge} in the same direction: inconsistent winding"


def triangle_cross_cam(tri_cam: np.ndarray) -> np.ndarray:
    """``(T, 3)``: ``(b - a) x (c - a)`` of camera-space triangles (``= -R n_world``)."""
    tri_cam = np.asarray(tri_cam, dtype=np.float64)
    return np.cross(tri_cam[:, 1] - tri_cam[:, 0], tri_cam[:, 2] - tri_cam[:, 0])


#: Relative tolerance of the orientation tests, in units of float64 eps: the
#: cross product of two edges carries ~3 roundings per component relative to
#: |e1| |e2|, the dot with the view vector ~3 more relative to |n| |p|; 16 eps
#: covers both with margin. Inside it, the sign is rounding noise.
ORIENTATION_EPS = 16 * np.finfo(np.float64).eps


def degenerate(tri_cam: np.ndarray) -> np.ndarray:
    """``(T,) bool``: zero-area triangles (collinear or repeated vertices, up to rounding).

    ``|(b - a) x (c - a)| <= ORIENTATION_EPS |b - a| |c - a|``: the normal is
    rounding noise. Such a face covers nothing and has no front or back: it is
    culled and never rasterized, so its edges do not flicker with the noise.
    """
    tri_cam = np.asarray(tri_cam, dtype=np.float64).reshape(-1, 3, 3)
    e1 = _unit_scale(tri_cam[:, 1] - tri_cam[:, 0])
    e2 = _unit_scale(tri_cam[:, 2] - tri_cam[:, 0])
    with np.errstate(over="ignore", invalid="ignore"):
        n = np.linalg.norm(np.cross(e1, e2), axis=1)
        scale = np.linalg.norm(e1, axis=1) * np.linalg.norm(e2, axis=1)
    return ~(n > ORIENTATION_EPS * scale)


def _unit_scale(v: np.ndarray) -> np.ndarray:
    """Rows divided by their largest |component| (zero rows kept): signs of the
    products below do not depend on a positive scale, and at 1e-110 or 1e110
    unscaled cross and dot products underflow or overflow."""
    big = np.abs(v).max(axis=1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(big > 0, v / np.where(big > 0, big, 1.0), 0.0)


def backface_keep(tri_cam: np.ndarray, projection: str, mirrored: bool = False) -> np.ndarray:
    """``(T,) bool``: True for front-facing triangles (module docstring for the rule).

    Parameters
    ----------
    tri_cam : (T, 3, 3) array
        Camera-space triangles ``[a, b, c]``, counter-clockwise seen from
        outside in the (right-handed) world.
    projection : "perspective" or "orthographic"
    mirrored : bool
        The model matrix has a negative determinant (reverses the winding).
    """
    tri_cam = np.asarray(tri_cam, dtype=np.float64).reshape(-1, 3, 3)
    # Each vector scaled by a positive factor of its own: the signs are unchanged.
    n_cc = np.cross(_unit_scale(tri_cam[:, 1] - tri_cam[:, 0]), _unit_scale(tri_cam[:, 2] - tri_cam[:, 0]))
    with np.errstate(over="ignore", invalid="ignore"):
        if projection == "perspective":
            a = _unit_scale(tri_cam[:, 0])
            s = np.einsum("ij,ij->i", n_cc, a)  # dot(n_cc, p_cam) = -dot(n_world, view)
            tol = ORIENTATION_EPS * np.linalg.norm(n_cc, axis=1) * np.linalg.norm(a, axis=1)
        else:
            s = n_cc[:, 2]  # n_cc . (0, 0, 1) = -dot(n_world, forward)
            tol = ORIENTATION_EPS * np.linalg.norm(n_cc, axis=1)
    # Edge-on (|s| within rounding of 0) and zero-area faces are culled: their sign is noise.
    keep = s < -tol if mirrored else s > tol
    return keep & ~degenerate(tri_cam)


def sphere_outside_frustum(center_world, radius: float, camera: Camera) -> bool:
    """True when a sphere lies entirely outside one of the six frustum planes.

    The planes are :func:`core.projector.clipping.frustum_planes` (near, far and the four
    image sides) in camera space; a plane's signed distance is normalised by
    the length of its normal, and the sphere is outside when that distance is
    below ``-radius`` for some plane. Conservative: a sphere near a frustum
    corner may be outside without being culled, a visible one is never culled.
    """
    c = np.asarray(center_world, dtype=np.float64).reshape(3)
    r_cam = np.stack([camera.right, camera.up, camera.forward])
    c_cam = r_cam @ (c - camera.position)  # camera-relative, as everywhere
    planes = frustum_planes(camera)
    dist = (planes[:, :3] @ c_cam + planes[:, 3]) / np.linalg.norm(planes[:, :3], axis=1)
    return bool(np.any(dist < -float(radius)))
