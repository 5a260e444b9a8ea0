"""Scene files: the text format, mesh files (trimesh) and the bundled scenes, read into core.scene.model.Scene.

The text format (``scenes/README.md`` documents it for users)::

    # comment (anywhere after '#')
    name cube            optional; defaults to the file stem
    v X Y Z              a vertex (0-based index, local to its object, in order of appearance)
    e I J                an edge between vertices I and J
    f I J K [L ...]      a face (polygon); its boundary edges join the edge set
    object NAME          starts an object: the v/e/f lines after it belong to it
    mesh PATH            the object's geometry from a mesh file (relative to the .scene file)
    translate X Y Z      the object's offset (default 0 0 0)
    scale S              the object's uniform scale (default 1)
    spin X Y Z           the object's own full turns about X, Y, Z over the run (default 0 0 0)

Lines before the first ``object`` form an implicit object named after the
scene, so a file without ``object`` lines is one object with the identity
motion (its arrays are exactly those of the single-object format).

Other formats (``.obj .ply .stl .off .glb .gltf``) are loaded with trimesh
(imported lazily): edges are the unique edges of the faces, and OBJ ``l``
elements become edges.
"""

from __future__ import annotations

import dataclasses
import io
import os
import re
from itertools import chain
from pathlib import Path

import numpy as np

from ..errors import InputError, quiet_libraries
from ..limits import MAX_FACE_VERTICES, MAX_NAME, check_turns
from ..numbers import plain_int
from ..projector.culling import winding_problem
from ..transforms import Motion
from ..user_files import expected, open_regular, open_text, problem, read_text
from .mesh_checks import check_json, check_off, check_ply_counts, check_stl
from .mesh_checks import number as _number
from .mesh_checks import short as _short
from .mesh_companions import companion_resolver, interrupts_kept
from .model import Scene, SceneObject, face_edges, unique_edges

SCENE_DIR = Path(__file__).resolve().parents[2] / "scenes"
#: Example scenes: loadable by name (``--scene orrery``) but not built-ins, so
#: ``crosscheck``'s default run (:func:`builtin_names`) does not include them.
EXAMPLES_DIR = SCENE_DIR / "examples"
NATIVE_SUFFIX = ".scene"
MESH_SUFFIXES = (".obj", ".ply", ".stl", ".off", ".glb", ".gltf")
#: A scene name becomes part of output file names: no path separators, no leading dot.
NAME_PATTERN = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.-]*")


def _safe_stem(path) -> str:
    """A file stem usable as a scene name (characters outside NAME_PATTERN become '_')."""
    stem = re.sub(r"[^A-Za-z0-9_.-]", "_", Path(path).stem)
    return stem if NAME_PATTERN.fullmatch(stem) else "_" + stem


def _index(path, lineno, token, what, n_vertices, where="the scene has"):
    try:
        value = plain_int(token)
    except ValueError:
        raise InputError(f"{path}:{lineno}: {what} index {_short(token)}: expected an integer") from None
    if not 0 <= value < n_vertices:
        raise InputError(
            f"{path}:{lineno}: {what} index {value}: expected 0..{n_vertices - 1} "
            f"({where} {n_vertices} vertices so far)"
        )
    return value


def _winding_note(faces) -> str | None:
    """core.projector.culling.winding_problem(faces), or None without faces."""
    return winding_problem(faces) if faces else None


class _Obj:
    """An object while its lines are parsed."""

    def __init__(self, name, lineno):
        self.name, self.lineno = name, lineno
        self.vertices, self.edges, self.faces = [], [], []
        self.mesh = None  # (lineno, Scene) of a 'mesh' line
        self.geometry_line = None  # first v/e/f line
        self.motion = {}  # keyword -> (lineno, value)

    def touched(self) -> bool:
        return bool(self.vertices or self.edges or self.faces or self.mesh or self.motion)


_MOTION_KEYS = {"translate": "offset", "scale": "scale", "spin": "turns"}


def parse_scene_text(
    text: str, path: str = "<string>", name: str | None = None, base_dir: str | os.PathLike | None = None
) -> Scene:
    """Parse the text format. ``base_dir`` (default: the directory of ``path``) resolves ``mesh`` paths."""
    base = Path(base_dir) if base_dir is not None else Path(path).parent
    implicit = _Obj(None, 0)
    objs = [implicit]
    cur = implicit
    single = True  # no 'object' line yet: messages speak of "the scene"
    # lines end at "\n" (and "\r\n") only, as editors count them: str.splitlines() would also end one at
    # U+2028, U+0085, \x0c, \x1c..\x1e, turning the rest of a comment into a statement
    for lineno, raw in enumerate(text.split("\n"), start=1):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        tag, *fields = line.split()
        where = "the scene has" if single else f"object {cur.name!r} has"
        if tag == "name":
            if len(fields) != 1 or not NAME_PATTERN.fullmatch(fields[0]):
                raise InputError(
                    f"{path}:{lineno}: name {_short(' '.join(fields))}: expected one word of letters, "
                    "digits, '_', '.', '-' (it names output files)"
                )
            name = fields[0]
        elif tag in ("v", "e", "f"):
            if cur.mesh is not None:
                raise InputError(
                    f"{path}:{lineno}: {_short(line)}: expected no v/e/f lines in an object that takes "
                    f"its geometry from 'mesh' (line {cur.mesh[0]}); start a new 'object' first"
                )
            cur.geometry_line = cur.geometry_line or lineno
            if tag == "v":
                if len(fields) != 3:
                    raise InputError(
                        f"{path}:{lineno}: vertex {_short(line)}: expected 'v X Y Z' (3 numbers), got {len(fields)}"
                    )
                cur.vertices.append([_number(path, lineno, t, "vertex coordinate") for t in fields])
            elif tag == "e":
                if len(fields) != 2:
                    raise InputError(
                        f"{path}:{lineno}: edge {_short(line)}: expected 'e I J' (2 indices), got {len(fields)}"
                    )
                cur.edges.append([_index(path, lineno, t, "edge", len(cur.vertices), where) for t in fields])
            else:
                if len(fields) < 3:
                    raise InputError(
                        f"{path}:{lineno}: face {_short(line)}: expected 'f I J K ...' (3 or more indices), "
                        f"got {len(fields)}"
                    )
                if len(fields) > MAX_FACE_VERTICES:
                    raise InputError(
                        f"{path}:{lineno}: face of {len(fields)} indices: expected at most "
                        f"{MAX_FACE_VERTICES} (a larger surface is a mesh: give it as a mesh file)"
                    )
                cur.faces.append(tuple(_index(path, lineno, t, "face", len(cur.vertices), where) for t in fields))
        elif tag == "object":
            if len(fields) != 1 or not NAME_PATTERN.fullmatch(fields[0]):
                raise InputError(
                    f"{path}:{lineno}: object {_short(' '.join(fields))}: expected 'object NAME', one word "
                    "of letters, digits, '_', '.', '-'"
                )
            dup = next((o for o in objs[1:] if o.name == fields[0]), None)
            if dup is not None:
                raise InputError(
                    f"{path}:{lineno}: object {_short(fields[0])}: expected a new name (line {dup.lineno} "
                    "already starts an object of that name)"
                )
            cur = _Obj(fields[0], lineno)
            objs.append(cur)
            single = False
        elif tag == "mesh":
            if len(fields) != 1:
                raise InputError(
                    f"{path}:{lineno}: mesh {_short(' '.join(fields))}: expected 'mesh PATH' "
                    "(one path without spaces, relative to the scene file)"
                )
            if cur.mesh is not None or cur.geometry_line is not None:
                first = cur.mesh[0] if cur.mesh is not None else cur.geometry_line
                raise InputError(
                    f"{path}:{lineno}: mesh {_short(fields[0])}: expected one source of geometry per "
                    f"object (line {first} already gives it); start a new 'object' first"
                )
            mesh_path = Path(fields[0])
            if not mesh_path.is_absolute():
                mesh_path = base / mesh_path
            if mesh_path.suffix.lower() not in MESH_SUFFIXES:
                raise InputError(
                    f"{path}:{lineno}: mesh {_short(fields[0])}: expected a file ending in {' '.join(MESH_SUFFIXES)}"
                )
            refused = problem(mesh_path, "mesh")
            if refused == "missing":
                raise InputError(
                    f"{path}:{lineno}: mesh {_short(fields[0])}: expected an existing file ({mesh_path} not found)"
                )
            if refused is not None:
                raise InputError(
                    f"{path}:{lineno}: mesh {_short(fields[0])}: {mesh_path}: {refused}: expected {expected('mesh')}"
                )
            try:
                cur.mesh = (lineno, load_mesh_file(mesh_path))
            except InputError as exc:
                raise InputError(f"{path}:{lineno}: mesh {_short(fields[0])}: {exc}") from None
        elif tag in _MOTION_KEYS:
            if tag in cur.motion:
                raise InputError(
                    f"{path}:{lineno}: {tag} {_short(' '.join(fields))}: expected one '{tag}' per object "
                    f"(line {cur.motion[tag][0]} already gives it)"
                )
            if tag == "scale":
                if len(fields) != 1:
                    raise InputError(
                        f"{path}:{lineno}: scale {_short(' '.join(fields))}: expected 'scale S' (1 number)"
                    )
                s = _number(path, lineno, fields[0], "scale")
                if s == 0.0:
                    raise InputError(f"{path}:{lineno}: scale {_short(fields[0])}: expected a non-zero number")
                cur.motion[tag] = (lineno, s)
            else:
                if len(fields) != 3:
                    raise InputError(
                        f"{path}:{lineno}: {tag} {_short(' '.join(fields))}: expected '{tag} X Y Z' "
                        f"(3 numbers), got {len(fields)}"
                    )
                values = tuple(_number(path, lineno, t, tag) for t in fields)
                if tag == "spin":
                    check_turns(values, f"{path}:{lineno}: spin")
                cur.motion[tag] = (lineno, values)
        else:
            raise InputError(
                f"{path}:{lineno}: {_short(tag)}: expected a line starting with 'v', 'e', 'f', 'name', "
                "'object', 'mesh', 'translate', 'scale', 'spin' or '#'"
            )
    scene_name = name or _safe_stem(path)
    _check_name_length(scene_name, path)
    if len(objs) > 1 and not implicit.touched():
        objs = objs[1:]  # nothing before the first 'object'
    implicit.name = scene_name
    if len(objs) > 1 and objs[0] is implicit:
        dup = next((o for o in objs[1:] if o.name == scene_name), None)
        if dup is not None:
            raise InputError(
                f"{path}:{dup.lineno}: object {dup.name!r}: expected a name other than the scene's "
                "(the lines before the first 'object' form an object named after the scene)"
            )
    vertices, edges, faces, objects = [], [], [], []
    n = 0
    for o in objs:
        if o.mesh is not None:
            m = o.mesh[1]
            o_vertices, o_edges = m.vertices, m.edges
            o_faces = m.faces
        else:
            o_vertices = np.asarray(o.vertices, dtype=np.float64).reshape(-1, 3)
            o_edges = np.concatenate([np.asarray(o.edges, dtype=np.intp).reshape(-1, 2), face_edges(o.faces)])
            o_faces = o.faces
        vertices.append(o_vertices)
        edges.append(np.asarray(o_edges, dtype=np.intp).reshape(-1, 2) + n)
        faces += [tuple(int(i) + n for i in f) for f in o_faces]
        kw = {key: o.motion[tag][1] for tag, key in _MOTION_KEYS.items() if tag in o.motion}
        motion = Motion(**{"turns": (0.0, 0.0, 0.0), "offset": (0.0, 0.0, 0.0), "scale": 1.0, **kw})
        objects.append(SceneObject(o.name, n, n + len(o_vertices), motion))
        n += len(o_vertices)
    faces = tuple(faces)
    return Scene(
        name=scene_name,
        vertices=np.concatenate(vertices).reshape(-1, 3) if vertices else np.zeros((0, 3)),
        edges=unique_edges(np.concatenate(edges)) if edges else np.zeros((0, 2), dtype=np.intp),
        faces=faces,
        source=str(path),
        objects=tuple(objects),
        winding_note=_winding_note(faces),
    )


def _check_name_length(name: str, path) -> None:
    if len(name) > MAX_NAME:
        raise InputError(
            f"{path}: scene name {name[:40]!r}... of {len(name)} characters: expected at most "
            f"{MAX_NAME} (it names output files; give a shorter 'name' line or file name)"
        )


def _obj_statements(path: Path):
    """``(line number, tokens, raw line)`` of each OBJ line that holds a statement (comments dropped)."""
    with open_text(path, "mesh") as fh:
        for lineno, raw in enumerate(fh, start=1):
            parts = raw.split("#", 1)[0].split()
            if parts:
                yield lineno, parts, raw


@dataclasses.dataclass
class _ShortFaces:
    """OBJ faces of fewer than 3 vertex indices (trimesh drops them silently): where, how many."""

    first_line: int = 0
    first_text: str = ""
    edges: int = 0  # two-index faces, read as edges
    points: int = 0  # one-index faces, skipped (a point draws nothing)

    def add(self, lineno: int, raw: str, n_indices: int) -> None:
        if not self.first_line:
            self.first_line, self.first_text = lineno, raw.strip()
        if n_indices == 2:
            self.edges += 1
        else:
            self.points += 1

    def note(self, path) -> str | None:
        """The one warning line (file, first line, counts), or None when every face has 3 indices or more."""
        n = self.edges + self.points
        if not n:
            return None
        what = "; ".join(
            part
            for part in (
                f"{self.edges} of two read as edges" if self.edges else "",
                f"{self.points} of one skipped (a point draws nothing)" if self.points else "",
            )
            if part
        )
        return (
            f"{path}:{self.first_line}: {n} face{'s' * (n != 1)} with fewer than 3 vertex indices "
            f"(first {_short(self.first_text)}): {what}"
        )


def _obj_lines(path: Path, short: _ShortFaces | None = None) -> list[tuple[int, int]]:
    """Edges from OBJ ``l`` elements and from faces of two indices (1-based, possibly negative, 'v/vt' forms).

    ``short`` counts the faces of fewer than three indices (:class:`_ShortFaces`).
    """
    n_v = 0
    pairs = []
    for lineno, parts, raw in _obj_statements(path):
        if parts[0] == "v":
            n_v += 1
        elif parts[0] in ("f", "fo") and len(parts) < 4:
            if short is not None:
                short.add(lineno, raw, len(parts) - 1)
            if len(parts) == 3:  # an edge: its two indices, read as an 'l' element's
                pairs.append(tuple(_obj_index(path, lineno, tok, n_v, "face") for tok in parts[1:]))
        elif parts[0] == "l":
            if len(parts) < 3:  # a line of one vertex draws nothing
                raise InputError(
                    f"{path}:{lineno}: line element {_short(raw.strip())}: expected 2 or more vertex indices"
                )
            idx = []
            for tok in parts[1:]:
                idx.append(_obj_index(path, lineno, tok, n_v, "line element"))
            pairs += list(zip(idx[:-1], idx[1:]))
    return pairs


def _obj_index(path, lineno: int, tok: str, n_v: int, what: str) -> int:
    """The 0-based vertex of an OBJ index token (1-based, or negative: back from the ``n_v`` read so far)."""
    try:
        k = int(tok.split("/")[0])
    except ValueError:
        raise InputError(f"{path}:{lineno}: {what} index {_short(tok)}: expected an integer") from None
    k = k - 1 if k > 0 else n_v + k
    if not 0 <= k < n_v:
        raise InputError(f"{path}:{lineno}: {what} index {_short(tok)}: expected 1..{n_v}")
    return k


def load_mesh_file(path: Path) -> Scene:
    """A mesh file read with trimesh into a Scene; InputError (one line) for a file that is not one.

    Companion files the mesh names (an OBJ's ``mtllib``, a texture, a glTF
    buffer) are read only when they are regular files (core.scene.mesh_companions):
    a FIFO or a device there is refused by name, never opened, so loading never
    blocks. Ctrl-C and SIGTERM during trimesh's reading end the run even though
    trimesh catches every exception around it.
    """
    import trimesh  # lazy: only mesh files need it

    with open_regular(path, "mesh"):  # a FIFO, a device, a folder or a file over the limit: one line, never read
        pass
    suffix = path.suffix.lower()
    if suffix == ".obj":
        _check_obj(path)  # every 'v' and 'f' line first: errors with file:line, not trimesh's
    elif suffix == ".stl":
        check_stl(path)  # trimesh reads a truncated or foreign STL as an empty mesh, silently
    elif suffix == ".off":
        check_off(path)  # trimesh takes any first line for 'OFF' and reads a short face list as none
    elif suffix == ".gltf":
        check_json(path)  # trimesh's message for broken JSON is "FileNotFoundError: model.gltf"
    resolver = companion_resolver(path)
    absolute = _obj_absolute_indices(path) if suffix == ".obj" else None
    if absolute is not None:  # read from memory: no resolver, so trimesh reads no companion
        source, resolver = {"file_obj": io.BytesIO(absolute.encode("utf-8")), "file_type": "obj"}, None
    else:  # trimesh reads the file opened here, never the name: a FIFO put there meanwhile cannot block
        source = {"file_obj": open_regular(path, "mesh"), "file_type": suffix[1:], "resolver": resolver}
    try:
        with interrupts_kept(), quiet_libraries(), source["file_obj"]:  # trimesh logs tracebacks it recovers from
            loaded = trimesh.load(**source, process=False, maintain_order=True)
    except Exception as exc:  # trimesh raises many types; one line for the user
        _check_refused(path, resolver)
        raise InputError(
            f"{path}: could not be read as {path.suffix[1:].upper()}: {type(exc).__name__}: {exc}"
        ) from None
    _check_refused(path, resolver)
    if isinstance(loaded, trimesh.Scene):
        loaded = loaded.to_geometry() if hasattr(loaded, "to_geometry") else loaded.dump(concatenate=True)
    if path.suffix.lower() == ".stl" and hasattr(loaded, "merge_vertices"):
        # STL stores every triangle's corners separately: merge equal positions,
        # or every shared edge would be counted and drawn twice
        with quiet_libraries():
            loaded.merge_vertices()
    vertices = np.asarray(getattr(loaded, "vertices", np.zeros((0, 3))), dtype=np.float64)
    if vertices.size % 3 or (vertices.ndim == 2 and vertices.shape[1] != 3):
        raise InputError(f"{path}: vertices of shape {vertices.shape}: expected 3 coordinates per vertex")
    vertices = vertices.reshape(-1, 3)
    try:
        faces = np.asarray(getattr(loaded, "faces", np.zeros((0, 3))), dtype=np.intp)
    except (TypeError, ValueError, OverflowError) as exc:
        raise InputError(f"{path}: faces could not be read as integer indices ({exc})") from None
    if faces.size == 0:
        faces = np.zeros((0, 3), dtype=np.intp)
    if faces.ndim != 2:
        raise InputError(f"{path}: faces of shape {faces.shape}: expected rows of vertex indices")
    if suffix == ".ply":
        check_ply_counts(path, len(vertices), len(faces))
    bad = (faces < 0) | (faces >= len(vertices))
    if bad.any():
        f, k = (int(i) for i in np.argwhere(bad)[0])
        value = int(faces[f, k])
        # the readers store indices as 32-bit integers: one beyond that range is read as -2**31
        said = (
            f"a vertex index beyond 32-bit integers (read as {value})"
            if value in (-(2**31), 2**31 - 1)
            else f"vertex index {value}"
        )
        raise InputError(
            f"{path}: face {f} has {said}: expected 0..{len(vertices) - 1} (the file has {len(vertices)} vertices)"
        )
    edges = [face_edges(faces)] if len(faces) else []
    short = _ShortFaces()
    if path.suffix.lower() == ".obj":
        line_pairs = _obj_lines(path, short)
        if line_pairs:
            if len(vertices) == 0 or max(max(p) for p in line_pairs) >= len(vertices):
                # trimesh dropped the line-only vertices: read them ourselves
                vertices = _obj_vertices(path)
            edges.append(np.asarray(line_pairs, dtype=np.intp))
    if not np.all(np.isfinite(vertices)):
        bad = np.argwhere(~np.isfinite(vertices))[0]
        raise InputError(f"{path}: vertex {bad[0]} has {vertices[bad[0]].tolist()}: expected finite coordinates")
    all_edges = np.concatenate(edges) if edges else np.zeros((0, 2), dtype=np.intp)
    # the Scene's faces are tuples of Python ints; the winding is checked on the array (the same edges)
    winding = winding_problem(faces) if len(faces) else None
    faces = tuple(
        chain.from_iterable(
            map(tuple, faces[k : k + 65536].tolist())  # a block at a time:
            for k in range(0, len(faces), 65536)
        )
    )  # no list of all rows
    _check_name_length(_safe_stem(path), path)
    return Scene(
        name=_safe_stem(path),
        vertices=vertices,
        edges=unique_edges(all_edges),
        faces=faces,
        source=str(path),
        winding_note=winding,
        load_notes=tuple(n for n in (short.note(path),) if n),
    )


def _check_refused(path: Path, resolver) -> None:
    """InputError naming the first companion file of ``path`` the resolver refused (a FIFO, a device)."""
    if resolver is not None and resolver.refused:
        name, exc = resolver.refused[0]
        raise InputError(
            f"{path}: the file it names {_short(name)} ({exc.path}): {exc.problem}: expected {expected(exc.kind)}"
        )


#: OBJ statements (the Wavefront spec's, free-form geometry included); others are ignored by readers,
#: so a file without vertices is only "empty" when every line is one of these.
OBJ_KEYWORDS = frozenset(
    "v vt vn vp f fo l p o g s mg mtllib usemtl usemap maplib lod bevel c_interp d_interp shadow_obj "
    "trace_obj ctech stech cstype deg bmat step curv curv2 surf parm trim hole scrv sp end con call csh".split()
)


def _check_obj(path: Path) -> None:
    """InputError (file:line) for a bad 'v' line, a face index out of range, or nothing OBJ in the file.

    Face indices are 1-based, or negative counting back from the vertices read
    so far (the OBJ spec); 0 and anything beyond are named here rather than
    left to trimesh's IndexError without a line. A file with no vertex whose
    lines are not OBJ statements (binary data, another format renamed) is not
    an empty mesh: its first such line is named.
    """
    n_v, foreign, beyond = 0, None, None  # beyond: (index, line, token) of the largest 1-based index
    for lineno, parts, raw in _obj_statements(path):
        if parts[0] == "v":
            if len(parts) < 4:
                raise InputError(f"{path}:{lineno}: vertex {_short(raw.strip())}: expected 'v X Y Z' (3 numbers)")
            for t in parts[1:4]:
                _number(path, lineno, t, "vertex coordinate")
            n_v += 1
        elif parts[0] in ("f", "fo"):
            if len(parts) < 2:
                raise InputError(f"{path}:{lineno}: face {_short(raw.strip())}: expected vertex indices")
            for tok in parts[1:]:
                try:
                    k = int(tok.split("/")[0])
                except ValueError:
                    raise InputError(f"{path}:{lineno}: face index {_short(tok)}: expected an integer") from None
                if k == 0 or n_v + k < 0:
                    raise InputError(
                        f"{path}:{lineno}: face index {_short(tok)}: expected a 1-based index or "
                        f"-1..-{n_v} (counting back over the {n_v} vertices before this line)"
                    )
                if beyond is None or k > beyond[0]:
                    beyond = (k, lineno, tok)
        elif parts[0] not in OBJ_KEYWORDS and foreign is None:
            foreign = (lineno, raw.strip())
    if beyond is not None and beyond[0] > n_v:
        k, lineno, tok = beyond
        raise InputError(
            f"{path}:{lineno}: face index {_short(tok)}: "
            + (
                f"expected 1..{n_v} (the file has {n_v} vertices)"
                if n_v
                else "the file has no vertices ('v X Y Z' lines): expected some"
            )
        )
    if n_v == 0 and foreign is not None:
        lineno, text = foreign
        raise InputError(
            f"{path}:{lineno}: {_short(text)}: expected an OBJ statement (v, f, l, o, g, ...); no vertex in the file"
        )


def _obj_absolute_indices(path: Path) -> str | None:
    """The OBJ text with every negative (relative) index of f/fo/l made absolute; None when there is none.

    The OBJ spec counts a negative index back from the vertices (texture
    coordinates, normals) read *so far*; trimesh counts it from the end of the
    file (a face before a later 'v' line took other vertices, silently) and
    fails on 'f -3/1 ...' and 'f -3//1 ...'.
    """
    counts = {"v": 0, "vt": 0, "vn": 0}
    kinds = ("v", "vt", "vn")  # the fields of 'v/vt/vn'
    lines, changed = [], False
    with open_text(path, "mesh") as fh:
        for raw in fh:
            parts = raw.split("#", 1)[0].split()
            if parts and parts[0] in counts:
                counts[parts[0]] += 1
            elif parts and parts[0] in ("f", "fo", "l") and "-" in raw.split("#", 1)[0]:
                tokens = []
                for tok in parts[1:]:
                    fields = tok.split("/")
                    for i, field in enumerate(fields[:3]):
                        if field.startswith("-") and field[1:].isdigit():
                            fields[i] = str(counts[kinds[i]] + 1 + int(field))
                    tokens.append("/".join(fields))
                raw, changed = " ".join([parts[0], *tokens]) + "\n", True
            lines.append(raw)
    return "".join(lines) if changed else None


def _obj_vertices(path: Path) -> np.ndarray:
    out = []
    for lineno, parts, raw in _obj_statements(path):
        if parts[0] == "v":
            if len(parts) < 4:
                raise InputError(f"{path}:{lineno}: vertex {_short(raw.strip())}: expected 'v X Y Z' (3 numbers)")
            out.append([_number(path, lineno, t, "vertex coordinate") for t in parts[1:4]])
    return np.asarray(out, dtype=np.float64).reshape(-1, 3)


def builtin_names() -> list[str]:
    """The built-in scenes: ``scenes/*.scene`` (not ``scenes/examples/``)."""
    return sorted(p.stem for p in SCENE_DIR.glob("*" + NATIVE_SUFFIX) if p.is_file())


def example_names() -> list[str]:
    """The example scenes in ``scenes/examples/``: loadable by name, not run by default."""
    return sorted(p.stem for p in EXAMPLES_DIR.glob("*" + NATIVE_SUFFIX) if p.is_file())


def load_scene(name_or_path: str) -> Scene:
    """A bundled scene by name, or a scene or mesh file by path.

    Parameters
    ----------
    name_or_path : str
        A built-in name (``cube``, ``pyramid``, ``prism``), an example name
        (``orrery``), or a path to a ``.scene`` file (the format:
        ``scenes/README.md``) or a mesh (.obj, .ply, .stl, .off, .glb, .gltf).

    Returns
    -------
    Scene
        ``vertices`` (N, 3) float64, ``edges`` (E, 2) int, ``faces`` (tuples
        of vertex indices; empty without faces) and its objects.

    Raises
    ------
    InputError
        One sentence naming the file, the line and the value when the name is
        unknown or the file is unreadable or malformed.
    """
    path = Path(name_or_path)
    is_path = os.sep in name_or_path or path.suffix != ""
    if not is_path:
        for folder in (SCENE_DIR, EXAMPLES_DIR):
            candidate = folder / (name_or_path + NATIVE_SUFFIX)
            if candidate.is_file():
                path = candidate
                break
        else:
            raise InputError(
                f"--scene {name_or_path!r}: expected a built-in scene "
                f"({', '.join(builtin_names() + example_names())}) or a file path"
            )
    try:
        if path.is_dir():
            raise InputError(f"--scene {name_or_path!r} is a directory: expected a scene file")
        if not path.is_file():
            try:
                os.stat(path)  # ELOOP (a symbolic link loop), EACCES: named by the OSError below
            except FileNotFoundError:
                raise InputError(f"--scene {name_or_path!r}: file not found") from None
            refused = problem(path, "scene")
            raise InputError(
                f"--scene {name_or_path!r}: {refused}: expected a scene or mesh file "
                "(never opened: reading it could block forever)"
            )
    except OSError as exc:  # ENAMETOOLONG, ELOOP, EACCES on a folder of the path
        raise InputError(f"--scene {_short(name_or_path)}: {exc.strerror or exc}: expected a readable file") from None
    suffix = path.suffix.lower()
    if suffix in MESH_SUFFIXES:
        return load_mesh_file(path)
    if suffix not in (NATIVE_SUFFIX, ".txt"):
        raise InputError(
            f"{path}: suffix {path.suffix!r}: expected {NATIVE_SUFFIX} or one of {' '.join(MESH_SUFFIXES)}"
        )
    try:
        text = read_text(path, "scene")  # a byte-order mark (Windows editors) is not a tag
    except UnicodeDecodeError as exc:
        raise InputError(f"{path}: could not be read: {exc}") from None
    scene = parse_scene_text(text, str(path))
    folder = path.resolve().parent
    if folder in (SCENE_DIR, EXAMPLES_DIR):
        # bundled: a checkout-independent source, so reports are the same everywhere
        rel = folder.relative_to(SCENE_DIR.parent).as_posix()
        scene = dataclasses.replace(scene, source=f"{rel}/{path.name}")
    return scene
