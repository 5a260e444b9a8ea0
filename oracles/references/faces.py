"""The oracle side's own handling of faces: world points per object, fans, back faces, kept edges.

Independent of core (core.scene.model.world_points, core.projector.culling): the rules are the
project's (stated in core.projector.culling's docstring and scenes/README.md), the code
is written again here from them, in float64 world space.

- Faces are polygons, counter-clockwise seen from outside; a polygon is
  split into a fan from its first vertex (``(f0, fk, fk+1)``), as GL would
  draw a convex polygon and as core does.
- A triangle is a **front face** when the camera is on the outer side of its
  plane: ``n = (b - a) x (c - a)`` (outward in a right-handed world), and
  ``dot(n, a - camera.position) < 0`` (perspective) or ``dot(n, forward) < 0``
  (orthographic). An object whose matrix mirrors (negative determinant)
  reverses the winding of its world points, so its outward normal is ``-n``.
  A polygon is kept when any of its triangles is a front face.
- With back-face culling an edge is drawn when it belongs to a kept polygon
  or to no polygon at all.
- GL decides front faces by the winding in the window (counter-clockwise =
  front), which equals the world-space rule above for an unmirrored object;
  for a mirrored one the polygons are handed to GL reversed
  (:func:`gl_polygons`), so that GL culls the same faces.
"""

from __future__ import annotations

from itertools import chain

import numpy as np

from .convert import camera_basis, model_matrix


def fan(faces) -> tuple[np.ndarray, np.ndarray]:
    """``(triangles (T, 3) int64, owner (T,) int64)``: each polygon fanned from its first vertex.

    Polygon ``i`` of ``n`` corners gives ``(f[0], f[k], f[k + 1])`` for ``k = 1 .. n - 2``, in that
    order, polygon after polygon; one of fewer than 3 corners gives none. ``faces``: a sequence of index
    sequences, or an ``(F, n)`` array.
    """
    if isinstance(faces, np.ndarray) and faces.ndim == 2:
        lengths = np.full(len(faces), faces.shape[1], dtype=np.int64)
        flat = faces.astype(np.int64).ravel()
    else:
        lengths = np.fromiter(map(len, faces), dtype=np.int64, count=len(faces))
        flat = np.fromiter(chain.from_iterable(faces), dtype=np.int64, count=int(lengths.sum()))
    per = np.maximum(lengths - 2, 0)  # triangles of each polygon
    owner = np.repeat(np.arange(len(lengths), dtype=np.int64), per)
    k = np.arange(len(owner), dtype=np.int64) - np.repeat(np.cumsum(per) - per, per) + 1  # 1 .. n - 2
    first = (np.cumsum(lengths) - lengths)[owner]  # where each polygon starts in ``flat``
    tris = np.stack([flat[first], flat[first + k], flat[first + k + 1]], axis=1)
    return tris.reshape(-1, 3), owner


def object_matrices(scene, run_turns, t: float, pivot=(0.0, 0.0, 0.0)) -> list[np.ndarray]:
    """Each object's world matrix at time ``t``: ``M_run(t) @ M_o(t)`` (object's motion first), via scipy.

    The run turns about ``pivot`` (core.transforms.Motion).
    """
    m_run = model_matrix(run_turns, (0.0, 0.0, 0.0), 1.0, t, pivot)
    out = []
    for o in scene.objects:
        m = o.motion
        out.append(m_run @ model_matrix(m.turns, m.offset, m.scale, t))
    return out


def world_points(scene, matrices) -> np.ndarray:
    """``(N, 3)`` float64: each object's rows through its matrix."""
    out = np.empty((len(scene.vertices), 3), dtype=np.float64)
    for o, m in zip(scene.objects, matrices):
        rows = slice(o.vertex_start, o.vertex_stop)
        out[rows] = scene.vertices[rows] @ m[:3, :3].T + m[:3, 3]
    return out


def frame_geometry(scene, motion, t: float):
    """The oracle side of one frame at time ``t``: ``(p_world, matrices, pr_vertices, pr_pose)``.

    A single static object: one scipy model matrix of the run's motion, and
    pyrender gets the model points with that matrix as the node pose. Several
    objects (or one with its own motion): each object's ``M_run @ M_o``
    (:func:`object_matrices`), and pyrender gets the world points, no pose.
    """
    if scene.is_single_static:
        m = model_matrix(motion.turns, motion.offset, motion.scale, t, motion.pivot)
        return scene.vertices @ m[:3, :3].T + m[:3, 3], [m], scene.vertices, m
    matrices = object_matrices(scene, motion.turns, t, motion.pivot)
    p_world = world_points(scene, matrices)
    return p_world, matrices, p_world, None


def mirrored_vertices(scene, matrices) -> np.ndarray:
    """``(N,) bool``: vertices of objects whose matrix has a negative determinant."""
    out = np.zeros(len(scene.vertices), dtype=bool)
    for o, m in zip(scene.objects, matrices):
        if np.linalg.slogdet(m[:3, :3])[0] < 0:  # the sign alone: det() underflows at 1e-110 scales
            out[o.vertex_start : o.vertex_stop] = True
    return out


def front_faces(p_world: np.ndarray, faces, camera, mirrored: np.ndarray | None = None) -> np.ndarray:
    """``(F,) bool``: polygons with at least one front-facing triangle (module docstring)."""
    tris, owner = fan(faces)
    keep = np.zeros(len(faces), dtype=bool)
    if len(tris) == 0:
        return keep
    a, b, c = (p_world[tris[:, i]] for i in range(3))

    def unit_scale(v):  # a positive factor per row: signs unchanged, no under/overflow at 1e+-110
        big = np.abs(v).max(axis=1, keepdims=True)
        return np.where(big > 0, v / np.where(big > 0, big, 1.0), 0.0)

    e1, e2 = unit_scale(b - a), unit_scale(c - a)
    n = np.cross(e1, e2)
    if mirrored is not None:
        n[mirrored[tris[:, 0]]] *= -1.0
    # Within 16 eps of zero the sign is rounding noise (same margin as core, derived
    # there): zero-area faces (|n| <= 16 eps |e1| |e2|) and edge-on ones are back faces.
    eps16 = 16 * np.finfo(np.float64).eps
    with np.errstate(over="ignore", invalid="ignore"):
        n_len = np.linalg.norm(n, axis=1)
        if camera.projection == "perspective":
            view = unit_scale(a - np.asarray(camera.position, dtype=np.float64))
            s = np.einsum("ij,ij->i", n, view)
            tol = eps16 * n_len * np.linalg.norm(view, axis=1)
        else:
            s = n @ camera_basis(camera)[2]
            tol = eps16 * n_len
        flat = ~(n_len > eps16 * np.linalg.norm(e1, axis=1) * np.linalg.norm(e2, axis=1))
    keep[owner[(s < -tol) & ~flat]] = True
    return keep


class EdgeOwners:
    """Which polygons each of a scene's edges belongs to, for :meth:`kept`; built once per scene."""

    def __init__(self, edges: np.ndarray, faces, n_vertices: int):
        edges = np.sort(np.asarray(edges, dtype=np.int64).reshape(-1, 2), axis=1)
        base = np.int64(n_vertices + 1)
        pairs, owner = [], []
        for i, f in enumerate(faces):
            for k in range(len(f)):
                pairs.append((f[k], f[(k + 1) % len(f)]))
                owner.append(i)
        pairs = np.sort(np.asarray(pairs, dtype=np.int64).reshape(-1, 2), axis=1)
        self._face_key = pairs[:, 0] * base + pairs[:, 1]
        self._owner = np.asarray(owner, dtype=np.int64)
        self._edge_key = edges[:, 0] * base + edges[:, 1]
        self._in_face = np.isin(self._edge_key, self._face_key)

    def kept(self, face_kept: np.ndarray) -> np.ndarray:
        """``(E,) bool``: edges of a kept polygon, or of no polygon."""
        in_kept = np.isin(self._edge_key, self._face_key[face_kept[self._owner]])
        return in_kept | ~self._in_face


def gl_polygons(faces, mirrored: np.ndarray | None):
    """The polygons as GL should get them: reversed for mirrored objects (module docstring)."""
    if mirrored is None or not mirrored.any():
        return faces
    return tuple(tuple(reversed(f)) if mirrored[f[0]] else tuple(f) for f in faces)


def gl_triangles(triangles: np.ndarray, mirrored: np.ndarray | None) -> np.ndarray:
    """Fan triangles for GL: the winding of mirrored objects' triangles reversed."""
    if mirrored is None or not mirrored.any() or len(triangles) == 0:
        return triangles
    out = triangles.copy()
    flip = mirrored[triangles[:, 0]]
    out[flip] = triangles[flip][:, ::-1]
    return out
