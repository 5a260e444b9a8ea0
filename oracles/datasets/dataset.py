"""Mesh datasets: the mesh files of a folder (``--scene DIR``) or of a list (``--scene-list FILE``).

A dataset is a sorted list of :class:`MeshEntry`: the file to load and the
name it has in the report. Nothing is loaded here (the meshes are read where
they are checked, oracles.datasets.dataset_run): finding ten thousand files costs one
directory walk, and a file that cannot be read is the report's business.

Folders are walked recursively in sorted order. Symbolic links to folders are
followed once: a folder reached again (a link loop, or two links to one place)
is skipped, so the walk always ends. A file is a mesh when its suffix is one
of :data:`core.scene.files.MESH_SUFFIXES` (any case); other files are counted
and ignored. A mesh-named path that is not a regular file (a FIFO, a device,
a socket) is skipped and listed in ``Dataset.skipped``, never opened: reading
a FIFO blocks forever, a device may never end (the CLI names them in one
line, the report lists them). A folder that cannot be listed becomes an entry that fails to
load (the run reports it like an unreadable mesh, it is not silently skipped).

A scene list is UTF-8 text, one path per line; blank lines and lines whose
first non-blank character is ``#`` are ignored; relative paths are relative
to the list's folder (so a list moves with its meshes; a list read from a pipe,
``<(find ...)``, needs absolute paths); a UTF-8 byte-order mark and CRLF line
ends are read. Every entry must name a mesh file by its suffix; one that does
not exist is a load error of the run (a moved file in a long list), one listed
twice (by another spelling, or a link to it) is a usage error.

Names: a mesh is named by its path relative to the folder given
(``chairs/a.obj``; with several folders, prefixed by the folder as given),
or as written in the list, made one printable line (:func:`printable`: a file
name may hold a newline or an ESC); names are unique within a dataset
(``dataset_entries`` refuses two inputs that yield one name).
"""

from __future__ import annotations

import os
import re
import stat
from dataclasses import dataclass
from pathlib import Path

from wirecheck.core.errors import InputError
from wirecheck.core.scene.files import MESH_SUFFIXES
from wirecheck.core.user_files import RefusedFile, file_kind, read_text


@dataclass(frozen=True)
class MeshEntry:
    """One mesh of a dataset: ``name`` in the report, ``path`` to read (absolute)."""

    name: str
    path: str
    #: why this entry cannot be loaded, known before loading (an unreadable folder); None: load it
    error: str | None = None


@dataclass(frozen=True)
class Dataset:
    """The meshes to check, sorted by name, and what the walk saw besides them."""

    entries: tuple  # of MeshEntry
    sources: tuple  # the folders and lists given, as given
    other_files: int = 0  # files without a mesh suffix, ignored
    skipped: tuple = ()  # (name, what it is) of each mesh-named FIFO, device or socket: never opened

    def to_dict(self) -> dict:
        out = {"sources": list(self.sources), "meshes": len(self.entries), "other_files": self.other_files}
        if self.skipped:
            out["skipped"] = [f"{name} ({kind})" for name, kind in self.skipped]
        return out

    def skipped_line(self) -> str | None:
        """One line naming the skipped non-regular files (at most 5 by name), or None."""
        if not self.skipped:
            return None
        named = ", ".join(f"{name} ({kind})" for name, kind in self.skipped[:5])
        more = f" and {len(self.skipped) - 5} more" if len(self.skipped) > 5 else ""
        return f"skipped {len(self.skipped)} mesh-named file(s) that are not regular files, never opened: {named}{more}"


#: Control characters (C0, DEL, C1): legal in a Linux file name, but a newline would split a
#: report line in two and an ESC would drive the user's terminal.
_CONTROL = re.compile("[\x00-\x1f\x7f-\x9f]")


def printable(name: str) -> str:
    """``name`` as one line of text: a non-UTF-8 file name's bytes (surrogates from os) and control
    characters (a newline, a tab, an ESC) as backslash escapes (``\\xfe``, ``\\n``, ``\\x1b``)."""
    text = name.encode("utf-8", "surrogateescape").decode("utf-8", "backslashreplace")
    return _CONTROL.sub(lambda m: m.group().encode("unicode_escape").decode("ascii"), text)


def is_mesh_file(name: str) -> bool:
    return Path(name).suffix.lower() in MESH_SUFFIXES


def walk_folder(root: Path, skipped: list | None = None) -> tuple[list[MeshEntry], int]:
    """The mesh files under ``root`` (sorted, links to folders followed once) and the count of other files.

    ``skipped`` (a list) receives ``(name, what it is)`` of each mesh-named
    FIFO, device or socket: looked at with ``stat`` only, never opened.

    Depth-first with an explicit stack (a folder nested thousands deep is not a recursion limit).
    """
    entries, other = [], 0
    seen = set()
    stack = [(Path(root), "")]
    while stack:
        folder, rel = stack.pop()
        try:
            st = folder.stat()
            key = (st.st_dev, st.st_ino)
            if key in seen:  # a link loop, or a second link to a folder already walked
                continue
            seen.add(key)
            with os.scandir(folder) as it:
                items = sorted(it, key=lambda e: e.name)
        except OSError as exc:
            entries.append(
                MeshEntry(name=rel or ".", path=str(folder), error=f"folder could not be read: {exc.strerror or exc}")
            )
            continue
        folders = []
        for item in items:
            item_rel = f"{rel}/{item.name}" if rel else item.name
            try:
                is_dir = item.is_dir()  # follows links
            except OSError:
                is_dir = False
            if is_dir:
                folders.append((Path(item.path), item_rel))
            elif is_mesh_file(item.name):
                kind = _not_regular(item)
                if kind is not None:
                    if skipped is not None:
                        skipped.append((printable(item_rel), kind))
                    continue
                entries.append(MeshEntry(name=item_rel, path=os.path.abspath(item.path)))
            else:
                other += 1
        stack += reversed(folders)  # the first in name order is walked first
    return entries, other


def _not_regular(item: os.DirEntry) -> str | None:
    """What ``item`` is when it exists and is not a regular file (links followed); None otherwise."""
    try:
        mode = item.stat().st_mode  # follows links; a broken link is the loader's "file not found"
    except OSError:
        return None
    return None if stat.S_ISREG(mode) else file_kind(mode)


def read_list(list_path: Path) -> list[MeshEntry]:
    """The entries of a scene list; InputError (with FILE:LINE) for a line that names no mesh file."""
    try:
        text = read_text(list_path, "scene list")  # a BOM (Windows editors) is not part of line 1
    except UnicodeDecodeError as exc:
        raise InputError(
            f"--scene-list {str(list_path)!r}: not UTF-8 text ({exc.reason} at byte {exc.start}): "
            "expected one path per line"
        ) from None
    except RefusedFile as exc:  # a FIFO, /dev/zero, a folder, a file over the limit: never read
        raise InputError(f"--scene-list {exc}") from None
    base = list_path.parent
    entries, lines = [], {}
    for lineno, raw in enumerate(text.splitlines(), start=1):
        line = raw.strip()
        if not line or line.startswith("#"):
            continue
        if "\0" in line:
            raise InputError(f"{list_path}:{lineno}: a NUL character: expected a path")
        if not is_mesh_file(line):
            raise InputError(
                f"{list_path}:{lineno}: {line!r}: expected a mesh file ending in "
                f"{' '.join(MESH_SUFFIXES)} (folders go in --scene DIR)"
            )
        path = Path(line) if Path(line).is_absolute() else base / line
        key = os.path.normpath(os.path.abspath(path))
        same = os.path.realpath(key)  # a link to a mesh already listed is that mesh
        if same in lines:
            raise InputError(
                f"{list_path}:{lineno}: {line!r}: listed twice (line {lines[same]}"
                f"{'' if same == key else ', through a link'}): expected each mesh once"
            )
        lines[same] = lineno
        entries.append(MeshEntry(name=os.path.normpath(line), path=key))
    return entries


def dataset_entries(folders=(), lists=()) -> Dataset:
    """The dataset of ``folders`` (each walked) and scene ``lists``; InputError when it has no mesh.

    Entries are sorted by name (the report's order, whatever the order of
    the walk); a name given by two inputs is an InputError.
    """
    entries, other, skipped = [], 0, []
    for folder in folders:
        root = Path(folder)
        if not root.is_dir():
            raise InputError(f"--scene {str(folder)!r}: expected a folder of mesh files")
        n_skipped = len(skipped)
        found, n_other = walk_folder(root, skipped)
        if not found:
            odd = len(skipped) - n_skipped
            raise InputError(
                f"--scene {str(folder)!r}: no mesh files in this folder "
                f"(looked for {' '.join(MESH_SUFFIXES)}; {n_other} other files"
                f"{f', {odd} mesh-named files that are not regular files' if odd else ''}): "
                "nothing to check"
            )
        if len(folders) > 1:  # several folders may each hold a 0001.obj: name them by folder too
            prefix = str(folder).rstrip("/\\") or "/"
            found = [MeshEntry(f"{prefix}/{e.name}", e.path, e.error) for e in found]
        entries += found
        other += n_other
    for lst in lists:
        found = read_list(Path(lst))
        if not found:
            raise InputError(
                f"--scene-list {str(lst)!r}: no paths in this list (only blank lines and comments): nothing to check"
            )
        entries += found
    if not entries:
        raise InputError("no dataset given: expected --scene DIR or --scene-list FILE")
    # a file name that is not UTF-8 (os gives its bytes as surrogates) is named with \x escapes:
    # the reports are UTF-8 text (a surrogate cannot be written there)
    entries = [MeshEntry(printable(e.name), e.path, e.error) for e in entries]
    entries.sort(key=lambda e: e.name)
    for a, b in zip(entries, entries[1:]):
        if a.name == b.name:
            raise InputError(
                f"two meshes named {a.name!r} ({printable(a.path)}, {printable(b.path)}): the report "
                "names meshes by their path under the folder or in the list: expected each name once"
            )
    return Dataset(
        entries=tuple(entries),
        sources=tuple(printable(str(s)) for s in (*folders, *lists)),
        other_files=other,
        skipped=tuple(skipped),
    )
