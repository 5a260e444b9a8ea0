"""A dataset run's memory budget: a mesh that would need more is one load error, not the machine's memory.

Checking a mesh holds its vertices, edges and faces several times over
(trimesh's arrays, the scene, the oracle's and the candidate's frames, the
line metrics' segments) on top of what every case holds whatever the mesh
(the interpreter, OpenGL and pyrender, the images, one chunk of the line
metrics' pairs: oracles.judge.segment_pixels.CHUNK_PAIRS). The pixel stage's
memory no longer grows with the edges' drawn length, so a mesh's need is
estimated from its counts alone (:func:`estimate_bytes`), measured with
benchmarks/bench_pixel_scale.py (peak RSS of one case, one frame):

    mesh                              vertices   edges     faces     peak RSS   estimate
    50,000 random long triangles      150,000    150,000   50,000    0.62 GiB   0.60 GiB
    height field of ~1M faces         501,264    1,500,961 999,698   0.96 GiB   1.43 GiB

(the estimate errs high on large meshes, trimesh's load-time copies being
counted whole, and 0.02 GiB low on the soup, whose long lines fill every
chunk of pairs). A mesh whose estimate is over the budget gets verdict
``"error"`` with one line saying so (oracles.datasets.dataset_run): the run
goes on, and fails unless ``--allow-load-errors``, as for a file that cannot
be read.
"""

from __future__ import annotations

import os
from fractions import Fraction

GIB = 2**30

#: What any case holds (bytes): the interpreter with numpy, OpenCV, trimesh and pyrender (~0.22 GiB),
#: an OpenGL context and its buffers, the frames' images and one chunk of the line metrics' pairs
#: (2^15 pairs x ~250 B: 8 MiB; the base was set when a chunk was 2^19 pairs, 0.12 GiB), with room for
#: the allocator.
BASE_BYTES = int(0.5 * GIB)
#: Bytes per vertex: trimesh's and the scene's float64 copies, the frame's world and pixel points
#: on both sides (OpenCV's and the candidate's), each a few (N, 3) or (N, 2) float64 arrays.
VERTEX_BYTES = 200
#: Bytes per edge: the scene's pairs and unique_edges' sort, both sides' segments and clipped ends,
#: the line metrics' segment columns (~400 B: tests/test_pixel_memory.py's derivation).
EDGE_BYTES = 400
#: Bytes per face: trimesh's arrays and caches while loading and the scene's tuple of index tuples
#: (a tuple of three Python ints: ~150 B).
FACE_BYTES = 300
#: The default budget's share of the machine's memory, split between the workers that check meshes at once.
DEFAULT_SHARE = 0.5


def gib_bytes(gib: float) -> int:
    """``gib`` GiB (finite, >= 0) in whole bytes, exactly: ``int(gib * 2**30)`` overflows to inf above ~1.7e299 GiB."""
    return int(Fraction(gib) * GIB)


def estimate_bytes(vertices: int, edges: int, faces: int) -> int:
    """Bytes one case of a mesh of these counts needs at most (module docstring)."""
    return BASE_BYTES + VERTEX_BYTES * int(vertices) + EDGE_BYTES * int(edges) + FACE_BYTES * int(faces)


def machine_bytes() -> int | None:
    """The machine's physical memory (bytes), or None where it cannot be read."""
    try:
        return int(os.sysconf("SC_PHYS_PAGES")) * int(os.sysconf("SC_PAGE_SIZE"))
    except (ValueError, OSError, AttributeError):
        return None


def default_budget(workers: int = 1) -> int | None:
    """Half the machine's memory, shared by ``workers`` meshes checked at once (None: not known, no budget)."""
    total = machine_bytes()
    return None if total is None else int(total * DEFAULT_SHARE / max(int(workers), 1))


def over_budget(vertices: int, edges: int, faces: int, budget: int | None) -> str | None:
    """Why a mesh of these counts is not checked under ``budget`` bytes (one line), or None when it fits."""
    if budget is None:
        return None
    need = estimate_bytes(vertices, edges, faces)
    if need <= budget:
        return None
    return (
        f"needs about {size_text(need)} to check ({vertices} vertices, {edges} edges, {faces} faces): "
        f"over the memory budget of {size_text(budget)} a mesh (--memory-budget GIB to change it)"
    )


def size_text(n_bytes: int) -> str:
    """``1.50 GiB``, or ``513 MiB`` under 1 GiB."""
    return f"{n_bytes / GIB:.2f} GiB" if n_bytes >= GIB else f"{n_bytes / 2**20:.0f} MiB"
