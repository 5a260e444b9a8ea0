"""Scenes: one or more objects of vertices, edges and optional faces, and where each is in a frame.

Files (the text format, mesh files, the bundled scenes) are read by core.scene.files.

Several objects: ``Scene.vertices``, ``edges`` and ``faces`` hold every
object, concatenated in file order (each object's indices offset by the
vertices before it); ``Scene.objects`` says which vertex rows belong to which
object and how it moves. The world position of a vertex of object ``o`` at
frame ``k`` of ``n`` is::

    p_world = M_run(k) @ M_o(k) @ p_model

``M_o`` is the object's own motion (``translate``, ``scale``, ``spin``:
``T @ Rz @ Ry @ Rx @ S`` as every core.transforms.Motion), applied first;
``M_run`` is the run's motion (``renderer --spin/--translate/--scale``),
applied after it to the whole scene. :func:`world_points` computes it.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..transforms import Motion, apply

#: An object that does not move: no turns, no offset, scale 1.
STATIC = Motion(turns=(0.0, 0.0, 0.0), offset=(0.0, 0.0, 0.0), scale=1.0)


def is_static(motion: Motion) -> bool:
    """True when ``motion`` is the identity in every frame."""
    return (
        all(float(t) == 0.0 for t in motion.turns)
        and all(float(o) == 0.0 for o in motion.offset)
        and float(motion.scale) == 1.0
    )


@dataclass(frozen=True)
class SceneObject:
    """One object of a scene: rows ``vertex_start:vertex_stop`` of ``Scene.vertices``.

    ``motion`` is the object's own motion (applied before the run's motion).
    """

    name: str
    vertex_start: int
    vertex_stop: int
    motion: Motion = STATIC

    @property
    def vertex_count(self) -> int:
        return self.vertex_stop - self.vertex_start


@dataclass(frozen=True)
class Scene:
    """A scene: one mesh, or several objects each with its own mesh and motion.

    Parameters
    ----------
    name : str
    vertices : (N, 3) ndarray of float64
        Model-space points of every object, concatenated (read-only).
    edges : (E, 2) ndarray of intp
        Unique vertex index pairs, ``i < j``.
    faces : tuple of tuple of int
        Polygons, counter-clockwise seen from outside; ``()`` for none.
    source : str
        Where the scene came from (a path, or ``scenes/cube.scene`` for bundled ones).
    objects : tuple of SceneObject
        The objects in file order; ``()`` means one static object of everything.
    winding_note : str or None
        Why the faces' winding is inconsistent, if it is.
    load_notes : tuple of str
        Warning lines: what was read leniently from the file (docs/datasets.md).
    """

    name: str
    vertices: np.ndarray  # (N, 3) float64, p_model
    edges: np.ndarray  # (E, 2) intp, unique, i < j
    faces: tuple = field(default=())  # tuple of index tuples (polygons)
    source: str = ""
    #: The objects, in file order; () when built by hand means one static object of everything.
    objects: tuple = field(default=())
    #: None, or why the faces' winding is inconsistent (core.projector.culling.winding_problem).
    winding_note: str | None = None
    #: What loading the file read leniently, one warning line each (file:line, what, how many):
    #: e.g. OBJ faces of two indices read as edges (core.scene.files).
    load_notes: tuple = ()

    def __post_init__(self):
        self.vertices.setflags(write=False)
        self.edges.setflags(write=False)
        if not self.objects:
            object.__setattr__(self, "objects", (SceneObject(self.name, 0, len(self.vertices), STATIC),))

    @property
    def is_single_static(self) -> bool:
        """One object with the identity motion: a frame's model matrix is the run's alone."""
        return (
            len(self.objects) == 1
            and is_static(self.objects[0].motion)
            and self.objects[0].vertex_start == 0
            and self.objects[0].vertex_stop == len(self.vertices)
        )

    @property
    def radius(self) -> float:
        """Bounding-sphere radius about the origin (0 for an empty scene).

        With objects that move, a bound that holds in every frame of their own
        motion: ``max_o |translate_o| + |scale_o| * r_o``, where ``r_o`` is the
        radius of object ``o``'s vertices about its own origin (a spin keeps
        that distance).
        """
        if self.is_single_static:
            return _radius(self.vertices)
        best = 0.0
        for o in self.objects:
            if o.vertex_count == 0:
                continue
            r = _radius(self.vertices[o.vertex_start : o.vertex_stop])
            best = max(best, _radius(np.asarray([o.motion.offset], dtype=np.float64)) + abs(o.motion.scale) * r)
        return best

    def object_edge_ranges(self) -> list[tuple[int, int]]:
        """``(start, stop)`` rows of ``edges`` of each object (edges are sorted, objects' vertices contiguous)."""
        first = self.edges[:, 0] if len(self.edges) else np.zeros(0, dtype=np.intp)
        return [
            (int(np.searchsorted(first, o.vertex_start)), int(np.searchsorted(first, o.vertex_stop)))
            for o in self.objects
        ]

    def object_face_ranges(self) -> list[tuple[int, int]]:
        """``(start, stop)`` items of ``faces`` of each object (faces are kept in object order)."""
        first = np.asarray([f[0] for f in self.faces], dtype=np.intp)
        out, start = [], 0
        for o in self.objects:
            stop = start + int(np.count_nonzero((first >= o.vertex_start) & (first < o.vertex_stop)))
            out.append((start, stop))
            start = stop
        return out


def radius_about(points: np.ndarray, centre) -> float:
    """Largest distance of ``(N, 3)`` points from ``centre`` (0 for none), without overflowing squares."""
    return _radius(np.asarray(points, dtype=np.float64) - np.asarray(centre, dtype=np.float64))


def _radius(vertices: np.ndarray) -> float:
    if len(vertices) == 0:
        return 0.0
    big = float(np.abs(vertices).max())  # scale first: squares of 1e155 overflow
    if big == 0.0:
        return 0.0
    return big * float(np.sqrt(((vertices / big) ** 2).sum(axis=1).max()))


def object_matrix(obj: SceneObject, run_motion: Motion, frame: int, frames: int) -> np.ndarray:
    """World matrix of ``obj`` at 1-based ``frame`` of ``frames``: ``M_run(k) @ M_o(k)``."""
    return run_motion.frame_matrix(frame, frames) @ obj.motion.frame_matrix(frame, frames)


def oriented_faces(scene: Scene, run_motion: Motion) -> tuple:
    """``scene.faces`` with the winding of mirrored objects reversed.

    An object whose world matrix ``M_run @ M_o`` has a negative determinant (an
    odd number of negative scales) turns its counter-clockwise faces clockwise.
    Drawn from world points with an identity model matrix, the pipeline cannot
    see that, so the faces are re-wound here; the sign is constant over a run
    (rotations have determinant +1, scales are constant).
    """
    # sign of (s_run s_o)^3, from the signs alone: the product can overflow or underflow
    flip = [(run_motion.scale < 0) != (o.motion.scale < 0) for o in scene.objects]
    if not any(flip):
        return scene.faces
    starts = [o.vertex_start for o in scene.objects]
    stops = [o.vertex_stop for o in scene.objects]
    out = []
    for f in scene.faces:
        k = next(i for i, (a, b) in enumerate(zip(starts, stops)) if a <= f[0] < b)
        out.append(tuple(reversed(f)) if flip[k] else tuple(f))
    return tuple(out)


def world_points(scene: Scene, run_motion: Motion, frame: int, frames: int) -> np.ndarray:
    """``(N, 3)`` float64 world positions of every vertex at 1-based ``frame`` of ``frames``.

    Object ``o``'s rows are ``(M_run(k) @ M_o(k)) p_model`` (module docstring).
    """
    out = np.empty((len(scene.vertices), 3), dtype=np.float64)
    m_run = run_motion.frame_matrix(frame, frames)
    for o in scene.objects:
        rows = slice(o.vertex_start, o.vertex_stop)
        out[rows] = apply(m_run @ o.motion.frame_matrix(frame, frames), scene.vertices[rows])
    return out


def object_spheres(scene: Scene) -> list[tuple[np.ndarray, float]]:
    """Each object's bounding sphere in its model space: (centre, radius).

    The centre is the midpoint of the bounding box; the radius the largest
    distance from it, widened by 1e-9 relative (and 1e-300 absolute) so that
    rounding in a frame's transform cannot put a vertex outside it.
    An object without vertices gets radius -1 (nothing to draw, always culled).
    """
    out = []
    for o in scene.objects:
        v = scene.vertices[o.vertex_start : o.vertex_stop]
        if len(v) == 0:
            out.append((np.zeros(3), -1.0))
            continue
        lo, hi = v.min(axis=0), v.max(axis=0)
        centre = 0.5 * lo + 0.5 * hi
        r = _radius(v - centre)
        out.append((centre, r * (1.0 + 1e-9) + 1e-300))
    return out


def unique_edges(edges: np.ndarray) -> np.ndarray:
    """Sort each edge (i < j), drop self-loops and duplicates; sorted output."""
    edges = np.asarray(edges, dtype=np.intp).reshape(-1, 2)
    edges = np.sort(edges, axis=1)
    edges = edges[edges[:, 0] != edges[:, 1]]
    if len(edges) == 0:
        return np.zeros((0, 2), dtype=np.intp)
    # One integer key per edge, i * (max + 1) + j, sorted, and each key unlike its
    # predecessor kept: the same sorted rows as np.unique(axis=0), ~3x faster (no
    # structured-dtype view); not 1-D np.unique either, which imports numpy.ma
    # (~15 ms of the seed command). Indices are < 2^31 in any mesh that fits in
    # memory, so keys fit in int64.
    span = int(edges.max()) + 1
    if edges.min() >= 0 and span < 2**31:
        keys = np.sort(edges[:, 0].astype(np.int64) * span + edges[:, 1])
        keys = keys[np.concatenate(([True], keys[1:] != keys[:-1]))]
        return np.stack([keys // span, keys % span], axis=1).astype(np.intp)
    return np.unique(edges, axis=0)


def face_edges(faces) -> np.ndarray:
    """Boundary edges ``(i, j)`` of every polygon, in order; vectorised for an ``(F, k)`` array."""
    if isinstance(faces, np.ndarray) and faces.ndim == 2:
        faces = faces.astype(np.intp, copy=False)
        return np.stack([faces, np.roll(faces, -1, axis=1)], axis=2).reshape(-1, 2)
    pairs = [(f[k], f[(k + 1) % len(f)]) for f in faces for k in range(len(f))]
    return np.asarray(pairs, dtype=np.intp).reshape(-1, 2)
