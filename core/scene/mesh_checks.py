"""Format checks of mesh files, run before trimesh reads them: errors with file:line, not trimesh's.

trimesh reads a truncated or foreign STL as an empty mesh, takes any first
line of an OFF file for its header, drops a short PLY face row and names broken
glTF JSON "FileNotFoundError": each check here turns such a file into one
InputError naming the file, the line and the value. Also the two helpers every
scene-file message uses: :func:`number` (a finite float token) and
:func:`short` (a value cut for a message).
"""

from __future__ import annotations

import math
import os
from pathlib import Path

from ..errors import InputError
from ..numbers import plain_float
from ..user_files import open_regular, open_text, read_regular


def check_stl(path: Path) -> None:
    """InputError unless ``path`` is a complete binary STL or a well-formed ASCII one (with file:line)."""
    with open_regular(path, "mesh") as fh:
        size = os.fstat(fh.fileno()).st_size
        data = fh.read(84)
    if size >= 84:
        count = int.from_bytes(data[80:84], "little")
        if size == 84 + 50 * count:
            return  # binary, even when the header starts with 'solid'
    if not data.lstrip()[:5].lower() == b"solid":
        if size < 84:
            raise InputError(
                f"{path}: {size} bytes: expected a binary STL (an 84-byte header, then 50 "
                "bytes a triangle) or an ASCII STL starting with 'solid'"
            )
        raise InputError(
            f"{path}: {size} bytes, its header declares {count} triangles: expected "
            f"84 + 50 x {count} = {84 + 50 * count} bytes of binary STL (truncated, or not an STL)"
        )
    check_ascii_stl(path, read_regular(path, "mesh").decode("latin-1"))


def check_off(path: Path) -> None:
    """InputError (file:line) unless ``path`` is an OFF file: 'OFF', counts, then as many vertices and faces."""
    with open_text(path, "mesh") as fh:
        rows = [(n, line.split("#", 1)[0].split()) for n, line in enumerate(fh, start=1)]
    rows = [(n, parts) for n, parts in rows if parts]
    if not rows or rows[0][1][0] not in ("OFF", "COFF"):
        n, parts = rows[0] if rows else (1, ["(empty)"])
        raise InputError(f"{path}:{n}: {short(' '.join(parts))}: expected the header 'OFF' (or 'COFF')")
    head_n, head = rows[0]
    if len(head) == 1:  # the counts on the next line
        rows = rows[1:]
        head_n, head = rows[0] if rows else (head_n, [])
        head = ["OFF", *head]
    counts = head[1:4]
    if len(counts) < 2 or not all(t.isdigit() for t in counts):
        raise InputError(
            f"{path}:{head_n}: counts {short(' '.join(head[1:]))}: expected 'VERTICES FACES EDGES' (integers >= 0)"
        )
    n_v, n_f = int(counts[0]), int(counts[1])
    body = rows[1:]
    if len(body) < n_v + n_f:
        raise InputError(
            f"{path}:{head_n}: {n_v} vertices and {n_f} faces declared, {len(body)} lines follow: "
            "expected a complete file (truncated?)"
        )
    for n, parts in body[:n_v]:
        if len(parts) < 3:
            raise InputError(f"{path}:{n}: vertex {short(' '.join(parts))}: expected 'X Y Z'")
        for t in parts[:3]:
            number(path, n, t, "vertex coordinate")
    for n, parts in body[n_v : n_v + n_f]:
        size = int(parts[0]) if parts[0].isdigit() else -1
        if size < 3 or len(parts) < size + 1 or not all(t.isdigit() and int(t) < n_v for t in parts[1 : size + 1]):
            raise InputError(
                f"{path}:{n}: face {short(' '.join(parts))}: expected 'N I1 ... IN', N >= 3, indices 0..{n_v - 1}"
            )


def check_json(path: Path) -> None:
    """InputError (file:line:column) unless ``path`` holds one JSON object, as a .gltf does."""
    import json

    try:
        doc = json.loads(read_regular(path, "mesh"))
    except UnicodeDecodeError as exc:
        raise InputError(f"{path}: not UTF-8 text ({exc.reason} at byte {exc.start}): expected glTF JSON") from None
    except json.JSONDecodeError as exc:
        raise InputError(f"{path}:{exc.lineno}:{exc.colno}: not JSON ({exc.msg}): expected glTF JSON") from None
    if not isinstance(doc, dict):
        raise InputError(f'{path}: a JSON {type(doc).__name__}: expected a glTF object ({{"asset": ...}})')


_STL_TOKENS = frozenset(("solid", "facet", "outer", "vertex", "endloop", "endfacet", "endsolid"))


def check_ascii_stl(path: Path, text: str) -> None:
    """InputError (file:line) unless every line is an STL statement and every facet has 3 vertices."""
    in_facet, vertices, lineno, last = False, 0, 0, None
    for lineno, raw in enumerate(text.splitlines(), start=1):
        parts = raw.split()
        if not parts:
            continue
        tag = parts[0].lower()
        if tag not in _STL_TOKENS:
            raise InputError(
                f"{path}:{lineno}: {short(raw.strip())}: expected an ASCII STL statement "
                "(solid, facet normal, outer loop, vertex X Y Z, endloop, endfacet, endsolid)"
            )
        if tag == "vertex":
            if len(parts) != 4 or not in_facet:
                raise InputError(f"{path}:{lineno}: {short(raw.strip())}: expected 'vertex X Y Z' inside a facet")
            for t in parts[1:]:
                number(path, lineno, t, "vertex coordinate")
            vertices += 1
        elif tag == "facet":
            if in_facet:
                raise InputError(f"{path}:{lineno}: facet: expected 'endfacet' before the next facet")
            in_facet, vertices = True, 0
        elif tag == "endfacet":
            if not in_facet or vertices != 3:
                raise InputError(f"{path}:{lineno}: endfacet after {vertices} vertices: expected a facet of 3 vertices")
            in_facet = False
        last = tag
    if in_facet or last != "endsolid":
        raise InputError(
            f"{path}:{lineno}: the file ends {'inside a facet' if in_facet else 'without endsolid'}: "
            "expected a complete ASCII STL (truncated?)"
        )


def check_ply_counts(path: Path, n_vertices: int, n_faces: int) -> None:
    """InputError when fewer vertices or faces were read than the PLY header declares (a truncated file).

    trimesh reads what is there and drops a short face row silently. Faces may
    be more than declared (polygons split into triangles), never fewer.
    """
    with open_regular(path, "mesh") as fh:
        head = fh.read(1 << 16).split(b"end_header", 1)[0].decode("latin-1")
    for lineno, line in enumerate(head.splitlines(), start=1):
        parts = line.split()
        if parts[:1] == ["element"] and len(parts) == 3 and parts[2].isdigit() and parts[1] in ("vertex", "face"):
            declared, read = int(parts[2]), n_vertices if parts[1] == "vertex" else n_faces
            if read < declared or (parts[1] == "vertex" and read != declared):
                raise InputError(
                    f"{path}:{lineno}: {line.strip()!r}, but {read} {'vertices' if parts[1] == 'vertex' else 'faces'} were read: expected "
                    "a complete file (truncated?)"
                )


def number(path, lineno, token, what):
    try:
        value = plain_float(token)
    except ValueError:
        raise InputError(f"{path}:{lineno}: {what} {short(token)}: expected a number") from None
    if not math.isfinite(value):
        raise InputError(f"{path}:{lineno}: {what} {short(token)}: expected a finite number")
    return value


def short(text: str) -> str:
    """``repr(text)``, cut to 80 characters (a path of 300 characters names nothing more in 300)."""
    return repr(text) if len(text) <= 80 else f"{text[:60]!r}... ({len(text)} characters)"
