"""A seeded dataset of varied meshes for the specificity benchmark (benchmarks/bench_specificity.py).

``make_dataset(folder, n, seed)`` writes ``n`` meshes into ``folder`` and
returns one :class:`MeshInfo` per file. The same ``(n, seed)`` writes the same
files (the meshes are drawn from one ``numpy.random.default_rng(seed)``; each
mesh's parameters come from its own child generator, so mesh ``i`` does not
depend on ``n``). Nothing is committed: the files are made at run time.

The kinds, in turn (``KINDS``):

* ``primitive``: every closed trimesh primitive (box, icosahedron, icosphere,
  UV sphere, capsule, torus, annulus, revolved profile);
* ``cylinder`` / ``cone``: 3 to 64 sections (the side edges seen end-on
  overlap the caps' spokes: the sub-pixel ties of oracles.judge.line_ties);
* ``extrusion``: a random star-shaped polygon, fan-triangulated and extruded;
* ``hull``: the convex hull of 8 to 60 random points;
* ``plate``: a box 1e-3 to 1e-2 of its width thick;
* ``grid``: a flat or bent (cylindrical) grid of 2 to 24 x 2 to 24 quads,
  split into triangles: many collinear edges that meet end to end.

Every mesh is scaled by ``10^U(-3, 4)`` (its size 1e-3 ... 1e4) and one in
four is moved ``10^U(3, 5)`` (1e3 ... 1e5) from the origin in a random
direction (``MeshInfo.offset``; ``far`` says which). The formats cycle through
OBJ, STL, PLY, OFF and GLB (STL holds float32 coordinates: a far, small mesh
loses detail in the file, which both the candidate and the oracles then see).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

KINDS = ("primitive", "cylinder", "cone", "extrusion", "hull", "plate", "grid")
SUFFIXES = (".obj", ".stl", ".ply", ".off", ".glb")
#: One mesh in this many is moved away from the origin.
FAR_EVERY = 4
#: A moved mesh's distance from the origin: 10^U(FAR_EXP).
FAR_EXP = (3.0, 5.0)
#: A mesh's size (its largest extent before scaling is about 1): 10^U(SCALE_EXP).
SCALE_EXP = (-3.0, 4.0)


@dataclass(frozen=True)
class MeshInfo:
    """One generated file: its name, kind, vertex count, size (largest extent), offset from the origin."""

    name: str
    kind: str
    detail: str
    vertices: int
    size: float
    offset: float

    @property
    def far(self) -> bool:
        """Moved from the origin (``FAR_EXP``)."""
        return self.offset > 0.0


def _primitive(rng, i):
    import trimesh

    k = i // len(KINDS)
    makers = [
        ("box", lambda: trimesh.creation.box(extents=rng.uniform(0.3, 1.0, 3))),
        ("icosahedron", lambda: trimesh.creation.icosahedron()),
        ("icosphere", lambda: trimesh.creation.icosphere(subdivisions=int(rng.integers(0, 4)))),
        ("uv_sphere", lambda: trimesh.creation.uv_sphere(count=[int(rng.integers(4, 33))] * 2)),
        (
            "capsule",
            lambda: trimesh.creation.capsule(
                height=rng.uniform(0.2, 1.5), radius=0.4, count=[int(rng.integers(4, 25))] * 2
            ),
        ),
        (
            "torus",
            lambda: trimesh.creation.torus(
                major_radius=1.0,
                minor_radius=rng.uniform(0.1, 0.5),
                major_sections=int(rng.integers(3, 49)),
                minor_sections=int(rng.integers(3, 17)),
            ),
        ),
        (
            "annulus",
            lambda: trimesh.creation.annulus(
                r_min=rng.uniform(0.1, 0.8), r_max=1.0, height=rng.uniform(0.05, 1.0), sections=int(rng.integers(3, 65))
            ),
        ),
        (
            "revolve",
            lambda: trimesh.creation.revolve(
                np.column_stack([rng.uniform(0.1, 1.0, 6), np.sort(rng.uniform(-1, 1, 6))]),
                sections=int(rng.integers(3, 49)),
            ),
        ),
    ]
    name, make = makers[k % len(makers)]
    return make(), name


def _round(rng, i, kind):
    import trimesh

    sections = int(rng.integers(3, 65))
    make = trimesh.creation.cylinder if kind == "cylinder" else trimesh.creation.cone
    return make(radius=rng.uniform(0.2, 1.0), height=rng.uniform(0.1, 2.0), sections=sections), f"{sections} sections"


def _extrusion(rng, i):
    import trimesh

    n = int(rng.integers(3, 25))
    angle = np.sort(rng.uniform(0, 2 * np.pi, n))
    radius = rng.uniform(0.3, 1.0, n)
    ring = np.column_stack([radius * np.cos(angle), radius * np.sin(angle)])
    vertices = np.vstack([[0.0, 0.0], ring])  # star-shaped about its centre: a fan triangulates it
    faces = np.array([[0, 1 + j, 1 + (j + 1) % n] for j in range(n)])
    return trimesh.creation.extrude_triangulation(vertices, faces, height=rng.uniform(0.05, 1.5)), f"{n}-gon"


def _hull(rng, i):
    import trimesh

    n = int(rng.integers(8, 61))
    return trimesh.Trimesh(rng.normal(size=(n, 3))).convex_hull, f"{n} points"


def _plate(rng, i):
    import trimesh

    t = float(10 ** rng.uniform(-3, -2))
    return trimesh.creation.box(extents=[1.0, rng.uniform(0.2, 1.0), t]), f"thickness {t:.1e}"


def _grid(rng, i):
    import trimesh

    nx, ny = (int(v) for v in rng.integers(2, 25, 2))
    u, v = np.meshgrid(np.linspace(0, 1, nx + 1), np.linspace(0, 1, ny + 1), indexing="ij")
    bent = bool(rng.integers(0, 2))
    if bent:  # rolled about the y axis: rows of collinear edges, bent columns
        a = u * rng.uniform(0.5, 3.0)
        xyz = np.stack([np.sin(a), v, 1.0 - np.cos(a)], axis=-1)
    else:
        xyz = np.stack([u, v, np.zeros_like(u)], axis=-1)
    idx = np.arange((nx + 1) * (ny + 1)).reshape(nx + 1, ny + 1)
    q = np.stack([idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]], axis=-1).reshape(-1, 4)
    faces = np.vstack([q[:, [0, 1, 2]], q[:, [0, 2, 3]]])
    return trimesh.Trimesh(xyz.reshape(-1, 3), faces, process=False), f"{nx}x{ny}{' bent' if bent else ''}"


def make_mesh(i: int, seed: int):
    """Mesh ``i`` of the dataset of ``seed``: ``(trimesh.Trimesh, kind, detail, size, offset)``."""
    rng = np.random.default_rng([seed, i])
    kind = KINDS[i % len(KINDS)]
    if kind == "primitive":
        mesh, detail = _primitive(rng, i)
    elif kind in ("cylinder", "cone"):
        mesh, detail = _round(rng, i, kind)
    else:
        mesh, detail = {"extrusion": _extrusion, "hull": _hull, "plate": _plate, "grid": _grid}[kind](rng, i)
    mesh.apply_translation(-mesh.bounds.mean(axis=0))
    mesh.apply_transform(_rotation(rng))  # two in three turned, one in three axis-aligned
    extent = float(np.max(mesh.extents)) or 1.0
    size = float(10 ** rng.uniform(*SCALE_EXP))
    mesh.apply_scale(size / extent)
    offset = 0.0
    if i % FAR_EVERY == FAR_EVERY - 1:
        offset = float(10 ** rng.uniform(*FAR_EXP))
        direction = rng.normal(size=3)
        mesh.apply_translation(offset * direction / np.linalg.norm(direction))
    return mesh, kind, detail, size, offset


def _rotation(rng) -> np.ndarray:
    """A random rotation (4x4), or the identity one time in three (axis-aligned meshes: the end-on views)."""
    from scipy.spatial.transform import Rotation

    m = np.eye(4)
    if rng.integers(0, 3):
        m[:3, :3] = Rotation.from_quat(rng.normal(size=4)).as_matrix()
    return m


def make_dataset(folder: Path, n: int, seed: int = 27) -> list[MeshInfo]:
    """Write ``n`` meshes into ``folder`` (``NNNN-kind.suffix``); ``[MeshInfo]`` in name order."""
    folder = Path(folder)
    out = []
    for i in range(n):
        mesh, kind, detail, size, offset = make_mesh(i, seed)
        name = f"{i:04d}-{kind}{SUFFIXES[(i // len(KINDS)) % len(SUFFIXES)]}"
        mesh.export(folder / name)
        out.append(MeshInfo(name, kind, detail, len(mesh.vertices), size, offset))
    return out
