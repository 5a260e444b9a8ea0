"""Scenes: vertices, edges and optional faces; the text format and mesh files.

The text format (``scenes/README.md`` documents it for users)::

    # comment (anywhere after '#')
    name cube            optional; defaults to the file stem
    v X Y Z              a vertex (0-based index in order of appearance)
    e I J                an edge between vertices I and J
    f I J K [L ...]      a face (polygon); its boundary edges join the edge set

Other formats (``.obj .ply .stl .off .glb .gltf``) are loaded with trimesh
(imported lazily): edges are the unique edges of the faces, and OBJ ``l``
elements become edges.
"""

from __future__ import annotations

import math
import os
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .errors import InputError

SCENE_DIR = Path(__file__).resolve().parent.parent / "scenes"
NATIVE_SUFFIX = ".scene"
MESH_SUFFIXES = (".obj", ".ply", ".stl", ".off", ".glb", ".gltf")
#: A scene name becomes part of output file names: no path separators, no leading dot.
NAME_PATTERN = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.-]*")


def _safe_stem(path) -> str:
    """A file stem usable as a scene name (characters outside NAME_PATTERN become '_')."""
    stem = re.sub(r"[^A-Za-z0-9_.-]", "_", Path(path).stem)
    return stem if NAME_PATTERN.fullmatch(stem) else "_" + stem


@dataclass(frozen=True)
class Scene:
    name: str
    vertices: np.ndarray                     # (N, 3) float64, p_model
    edges: np.ndarray                        # (E, 2) intp, unique, i < j
    faces: tuple = field(default=())         # tuple of index tuples (polygons)
    source: str = ""

    def __post_init__(self):
        self.vertices.setflags(write=False)
        self.edges.setflags(write=False)

    @property
    def radius(self) -> float:
        """Bounding-sphere radius about the origin (0 for an empty scene)."""
        if len(self.vertices) == 0:
            return 0.0
        big = float(np.abs(self.vertices).max())       # scale first: squares of 1e155 overflow
        if big == 0.0:
            return 0.0
        return big * float(np.sqrt(((self.vertices / big) ** 2).sum(axis=1).max()))


def unique_edges(edges: np.ndarray) -> np.ndarray:
    """Sort each edge (i < j), drop self-loops and duplicates; sorted output."""
    edges = np.asarray(edges, dtype=np.intp).reshape(-1, 2)
    edges = np.sort(edges, axis=1)
    edges = edges[edges[:, 0] != edges[:, 1]]
    if len(edges) == 0:
        return np.zeros((0, 2), dtype=np.intp)
    return np.unique(edges, axis=0)


def face_edges(faces) -> np.ndarray:
    pairs = [(f[k], f[(k + 1) % len(f)]) for f in faces for k in range(len(f))]
    return np.asarray(pairs, dtype=np.intp).reshape(-1, 2)


def _number(path, lineno, token, what):
    try:
        value = float(token)
    except ValueError:
        raise InputError(f"{path}:{lineno}: {what} {token!r}: expected a number") from None
    if not math.isfinite(value):
        raise InputError(f"{path}:{lineno}: {what} {token!r}: expected a finite number")
    return value


def _index(path, lineno, token, what, n_vertices):
    try:
        value = int(token)
    except ValueError:
        raise InputError(f"{path}:{lineno}: {what} index {token!r}: expected an integer") from None
    if not 0 <= value < n_vertices:
        raise InputError(f"{path}:{lineno}: {what} index {value}: expected 0..{n_vertices - 1} "
                         f"(the scene has {n_vertices} vertices so far)")
    return value


def parse_scene_text(text: str, path: str = "<string>", name: str | None = None) -> Scene:
    vertices, edges, faces = [], [], []
    for lineno, raw in enumerate(text.splitlines(), start=1):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        tag, *fields = line.split()
        if tag == "name":
            if len(fields) != 1 or not NAME_PATTERN.fullmatch(fields[0]):
                raise InputError(f"{path}:{lineno}: name {' '.join(fields)!r}: expected one word of letters, "
                                 "digits, '_', '.', '-' (it names output files)")
            name = fields[0]
        elif tag == "v":
            if len(fields) != 3:
                raise InputError(f"{path}:{lineno}: vertex {line!r}: expected 'v X Y Z' (3 numbers), got {len(fields)}")
            vertices.append([_number(path, lineno, t, "vertex coordinate") for t in fields])
        elif tag == "e":
            if len(fields) != 2:
                raise InputError(f"{path}:{lineno}: edge {line!r}: expected 'e I J' (2 indices), got {len(fields)}")
            edges.append([_index(path, lineno, t, "edge", len(vertices)) for t in fields])
        elif tag == "f":
            if len(fields) < 3:
                raise InputError(f"{path}:{lineno}: face {line!r}: expected 'f I J K ...' (3 or more indices), got {len(fields)}")
            faces.append(tuple(_index(path, lineno, t, "face", len(vertices)) for t in fields))
        else:
            raise InputError(f"{path}:{lineno}: {tag!r}: expected a line starting with 'v', 'e', 'f', 'name' or '#'")
    all_edges = np.concatenate([np.asarray(edges, dtype=np.intp).reshape(-1, 2), face_edges(faces)])
    return Scene(
        name=name or _safe_stem(path),
        vertices=np.asarray(vertices, dtype=np.float64).reshape(-1, 3),
        edges=unique_edges(all_edges),
        faces=tuple(faces),
        source=str(path),
    )


def _obj_lines(path: Path) -> list[tuple[int, int]]:
    """Edges from OBJ ``l`` elements (1-based, possibly negative, 'v/vt' forms)."""
    n_v = 0
    pairs = []
    with open(path, encoding="utf-8", errors="replace") as fh:
        for lineno, raw in enumerate(fh, start=1):
            parts = raw.split("#", 1)[0].split()
            if not parts:
                continue
            if parts[0] == "v":
                n_v += 1
            elif parts[0] == "l":
                idx = []
                for tok in parts[1:]:
                    try:
                        k = int(tok.split("/")[0])
                    except ValueError:
                        raise InputError(f"{path}:{lineno}: line element index {tok!r}: expected an integer") from None
                    k = k - 1 if k > 0 else n_v + k
                    if not 0 <= k < n_v:
                        raise InputError(f"{path}:{lineno}: line element index {tok!r}: expected 1..{n_v}")
                    idx.append(k)
                pairs += list(zip(idx[:-1], idx[1:]))
    return pairs


def load_mesh_file(path: Path) -> Scene:
    import trimesh  # lazy: only mesh files need it

    if path.suffix.lower() == ".obj":
        _obj_vertices(path)   # validate every 'v' line first: errors with file:line, not trimesh's
    try:
        loaded = trimesh.load(str(path), process=False, maintain_order=True)
    except Exception as exc:  # trimesh raises many types; one line for the user
        raise InputError(f"{path}: could not be read as {path.suffix[1:].upper()}: {exc}") from None
    if isinstance(loaded, trimesh.Scene):
        loaded = loaded.to_geometry() if hasattr(loaded, "to_geometry") else loaded.dump(concatenate=True)
    if path.suffix.lower() == ".stl" and hasattr(loaded, "merge_vertices"):
        # STL stores every triangle's corners separately: merge equal positions,
        # or every shared edge would be counted and drawn twice
        loaded.merge_vertices()
    vertices = np.asarray(getattr(loaded, "vertices", np.zeros((0, 3))), dtype=np.float64)
    if vertices.size % 3 or (vertices.ndim == 2 and vertices.shape[1] != 3):
        raise InputError(f"{path}: vertices of shape {vertices.shape}: expected 3 coordinates per vertex")
    vertices = vertices.reshape(-1, 3)
    faces = np.asarray(getattr(loaded, "faces", np.zeros((0, 3))), dtype=np.intp)
    if faces.size == 0:
        faces = np.zeros((0, 3), dtype=np.intp)
    edges = [face_edges(faces.tolist())] if len(faces) else []
    if path.suffix.lower() == ".obj":
        line_pairs = _obj_lines(path)
        if line_pairs:
            if len(vertices) == 0 or max(max(p) for p in line_pairs) >= len(vertices):
                # trimesh dropped the line-only vertices: read them ourselves
                vertices = _obj_vertices(path)
            edges.append(np.asarray(line_pairs, dtype=np.intp))
    if not np.all(np.isfinite(vertices)):
        bad = np.argwhere(~np.isfinite(vertices))[0]
        raise InputError(f"{path}: vertex {bad[0]} has {vertices[bad[0]].tolist()}: expected finite coordinates")
    all_edges = np.concatenate(edges) if edges else np.zeros((0, 2), dtype=np.intp)
    return Scene(name=_safe_stem(path), vertices=vertices, edges=unique_edges(all_edges),
                 faces=tuple(tuple(int(i) for i in f) for f in faces), source=str(path))


def _obj_vertices(path: Path) -> np.ndarray:
    out = []
    with open(path, encoding="utf-8", errors="replace") as fh:
        for lineno, raw in enumerate(fh, start=1):
            parts = raw.split("#", 1)[0].split()
            if parts and parts[0] == "v":
                if len(parts) < 4:
                    raise InputError(f"{path}:{lineno}: vertex {raw.strip()!r}: expected 'v X Y Z' (3 numbers)")
                out.append([_number(path, lineno, t, "vertex coordinate") for t in parts[1:4]])
    return np.asarray(out, dtype=np.float64).reshape(-1, 3)


def builtin_names() -> list[str]:
    return sorted(p.stem for p in SCENE_DIR.glob("*" + NATIVE_SUFFIX))


def load_scene(name_or_path: str) -> Scene:
    """A built-in scene by name (``cube``) or a file path (.scene or a mesh format)."""
    path = Path(name_or_path)
    is_path = os.sep in name_or_path or path.suffix != ""
    if not is_path:
        builtin = SCENE_DIR / (name_or_path + NATIVE_SUFFIX)
        if builtin.is_file():
            path = builtin
        else:
            raise InputError(f"--scene {name_or_path!r}: expected a built-in scene "
                             f"({', '.join(builtin_names())}) or a file path")
    if path.is_dir():
        raise InputError(f"--scene {name_or_path!r} is a directory: expected a scene file")
    if not path.is_file():
        raise InputError(f"--scene {name_or_path!r}: file not found")
    suffix = path.suffix.lower()
    if suffix in MESH_SUFFIXES:
        return load_mesh_file(path)
    if suffix not in (NATIVE_SUFFIX, ".txt"):
        raise InputError(f"{path}: suffix {path.suffix!r}: expected {NATIVE_SUFFIX} or one of {' '.join(MESH_SUFFIXES)}")
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: could not be read: {exc}") from None
    scene = parse_scene_text(text, str(path))
    if path.resolve().parent == SCENE_DIR:
        # built-in: a checkout-independent source, so reports are the same everywhere
        scene = Scene(scene.name, scene.vertices, scene.edges, scene.faces, f"scenes/{path.name}")
    return scene
