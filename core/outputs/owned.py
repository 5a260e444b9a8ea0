"""Which files in an output folder wirecheck wrote: the folder's listing, checked before any replace.

Every folder wirecheck writes (a renderer's ``<name>-frames/``, a crosscheck
report folder, an export job) holds ``.wirecheck-output`` (core.outputs.output.MARKER),
written last, just before the folder is moved into place: a JSON listing of
every file in the folder (relative path and SHA-256) and every sub-folder. A
later run replaces the folder only when everything in it is listed with the
same bytes: a file the user put there (``job/render.sh``, ``rep/analysis.md``,
a note in ``out/cube-frames/``), a file edited since, a link or an unlisted
folder makes the run refuse with one line naming it, before anything is
written. An empty marker (written by wirecheck before the listing existed)
lists nothing: such a folder is replaced only when it holds nothing else.

The moves of a commit go through :func:`rename` and :func:`exchange`, which
count them: with ``WIRECHECK_KILL_AFTER_RENAME=k`` in the environment the
process sends itself SIGKILL right after the k-th, so that a test can stop a
commit at every step (tests/test_commit_kill.py).
"""

from __future__ import annotations

import ctypes
import errno
import hashlib
import json
import os
import signal
import stat
from pathlib import Path

MARKER = ".wirecheck-output"
#: A file in every temporary folder of ours from its creation: a killed run's temporaries are recognised by
#: it (and a folder killed between its move into place and the removal of this file is still ours).
TAG = ".wirecheck-staging"
_KIND = "wirecheck output folder"
_KILL_ENV = "WIRECHECK_KILL_AFTER_RENAME"
_renames = 0


def sha256(path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def _walk(folder: Path, rel: str = ""):
    """``(relative path, DirEntry)`` of everything under ``folder``, parents before children, sorted."""
    with os.scandir(folder) as it:
        entries = sorted(it, key=lambda e: e.name)
    for entry in entries:
        name = f"{rel}{entry.name}"
        yield name, entry
        if entry.is_dir(follow_symlinks=False):
            yield from _walk(Path(entry.path), name + "/")


def seal(folder: Path) -> None:
    """Write the listing of everything in ``folder`` into its MARKER (call it when the folder is complete)."""
    folder = Path(folder)
    files, folders = {}, []
    for rel, entry in _walk(folder):
        if rel in (MARKER, TAG):
            continue
        if entry.is_dir(follow_symlinks=False):
            folders.append(rel)
        elif entry.is_file(follow_symlinks=False):
            files[rel] = sha256(entry.path)
    text = json.dumps({"kind": _KIND, "version": 1, "files": files, "folders": folders}, indent=1, sort_keys=True)
    (folder / MARKER).write_text(text + "\n", encoding="utf-8")


def listing(folder: Path) -> tuple[dict, set] | None:
    """``({file: sha256}, {folder})`` from ``folder``'s MARKER; None when there is no marker of ours."""
    marker = Path(folder) / MARKER
    try:
        if marker.is_symlink() or not marker.is_file() or marker.stat().st_size > (64 << 20):
            return None
        text = marker.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError):
        return None
    if text == "":
        return {}, set()            # an earlier wirecheck's empty marker: lists nothing
    try:
        data = json.loads(text)
        files, folders = data["files"], data["folders"]
        if data.get("kind") != _KIND or not isinstance(files, dict) or not isinstance(folders, list):
            return None
        return {str(k): str(v) for k, v in files.items()}, {str(f) for f in folders}
    except (ValueError, KeyError, TypeError, AttributeError):
        return None


def foreign(folder: Path) -> str | None:
    """The first entry of ``folder`` wirecheck did not write (relative path and why), None when all are ours.

    ``folder`` must hold a MARKER; "(no listing)" when it is not one of ours.
    """
    listed = listing(folder)
    if listed is None:
        return f"{MARKER} (not a listing of wirecheck's)"
    files, folders = listed
    for rel, entry in _walk(Path(folder)):
        if rel in (MARKER, TAG):
            continue
        if entry.is_symlink():
            return f"{rel} (a link)"
        if entry.is_dir(follow_symlinks=False):
            if rel not in folders:
                return f"{rel}/ (a folder not written by wirecheck)"
        elif not entry.is_file(follow_symlinks=False):
            return f"{rel} (not a regular file)"
        elif rel not in files:
            return f"{rel} (a file not written by wirecheck)"
        elif sha256(entry.path) != files[rel]:
            return f"{rel} (a file changed since wirecheck wrote it)"
    return None


def ours(path: Path) -> str | None:
    """None when ``path`` may be replaced as a folder of ours (absent, empty, or all listed); else why not."""
    path = Path(path)
    if not path.exists() and not path.is_symlink():
        return None
    if path.is_symlink():
        return "a symbolic link"
    if not path.is_dir():
        return "a file"
    if not (path / MARKER).is_file():
        return None if not any(path.iterdir()) else "a directory not written by wirecheck"
    found = foreign(path)
    return None if found is None else f"a folder of wirecheck's holding {found}"


def is_leftover(path: Path) -> bool:
    """Whether the folder ``path`` is a temporary of ours: tagged, or a complete output whose listing holds."""
    path = Path(path)
    if path.is_symlink() or not path.is_dir():
        return False
    if os.path.lexists(path / TAG):
        return True
    return (path / MARKER).is_file() and foreign(path) is None


def _count() -> None:
    global _renames
    _renames += 1
    kill_at = os.environ.get(_KILL_ENV)
    if kill_at and kill_at.isdigit() and _renames == int(kill_at):
        os.kill(os.getpid(), signal.SIGKILL)


def rename(src, dst) -> None:
    """``os.replace(src, dst)``, counted (module docstring)."""
    os.replace(src, dst)
    _count()


_RENAME_EXCHANGE = 2
_AT_FDCWD = -100


def exchange(a: Path, b: Path) -> bool:
    """Swap ``a`` and ``b`` (both must exist) in one step (Linux ``renameat2``); False where unsupported."""
    try:
        fn = ctypes.CDLL(None, use_errno=True).renameat2
    except (OSError, AttributeError):
        return False
    fn.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_uint]
    if fn(_AT_FDCWD, os.fsencode(a), _AT_FDCWD, os.fsencode(b), _RENAME_EXCHANGE) == 0:
        _count()
        return True
    err = ctypes.get_errno()
    if err in (errno.EINVAL, errno.ENOSYS, errno.EOPNOTSUPP):
        return False
    raise OSError(err, os.strerror(err), str(a))


def is_regular(path: Path) -> bool:
    try:
        return stat.S_ISREG(os.lstat(path).st_mode)
    except OSError:
        return False
