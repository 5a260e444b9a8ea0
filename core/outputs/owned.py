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

Nothing here is trusted by its name: a marker is read with ``O_NOFOLLOW |
O_NONBLOCK`` (:func:`read_regular`: a FIFO never blocks, a link is never
followed) and only when it is a regular file with one link; walks are
iterative (an output nested thousands deep is walked, not a RecursionError).

An old folder is removed after it was swapped out of place, never before,
and only by its listing (:func:`retire`): each listed file is hashed again
and removed only when its bytes are the listed ones, each folder removed only
when empty. Whatever else is there (a note the user wrote into the folder
while the run hashed its frames, a file edited meanwhile) is moved back into
the folder now in place, under its own name or beside it, and named to the
caller: a user's file is never removed, however the timing falls.

The moves of a commit go through :func:`rename`, :func:`exchange` and
:func:`rename_noreplace`, which count them: with
``WIRECHECK_KILL_AFTER_RENAME=k`` in the environment the process sends itself
SIGKILL right after the k-th, so that a test can stop a commit at every step
(tests/test_commit_kill.py). Every step of a commit (the check, then each
move) also calls :func:`step`: with ``WIRECHECK_PAUSE_AT_STEP=k`` and
``WIRECHECK_PAUSE_FILE=PATH`` the process creates PATH at the k-th step and
waits (up to a minute) until it is removed, so that a test can write into an
output folder at that very moment (tests/test_commit_window.py).
"""

from __future__ import annotations

import ctypes
import errno
import hashlib
import json
import os
import signal
import stat
import time
from pathlib import Path

MARKER = ".wirecheck-output"
#: A file in every temporary folder of ours from its creation: a killed run's temporaries are recognised by
#: it (and a folder killed between its move into place and the removal of this file is still ours).
TAG = ".wirecheck-staging"
_KIND = "wirecheck output folder"
_KILL_ENV = "WIRECHECK_KILL_AFTER_RENAME"
_PAUSE_ENV, _PAUSE_FILE_ENV = "WIRECHECK_PAUSE_AT_STEP", "WIRECHECK_PAUSE_FILE"
_renames = 0
_steps = 0
#: The largest marker read (a listing of 100,000 frames is ~10 MB).
MAX_MARKER_BYTES = 64 << 20
_OPEN_FLAGS = os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK | os.O_CLOEXEC


def sha256(path) -> str:
    fd = os.open(path, _OPEN_FLAGS)
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            raise OSError(errno.EINVAL, "not a regular file", str(path))
        return hash_fd(fd)
    finally:
        os.close(fd)


def hash_fd(fd: int) -> str:
    h = hashlib.sha256()
    while block := os.read(fd, 1 << 20):
        h.update(block)
    return h.hexdigest()


def read_regular(path, limit: int) -> bytes:
    """The bytes of ``path``, opened without following a link or blocking; ValueError (saying what it is)
    unless a regular file with one link of at most ``limit`` bytes."""
    try:
        fd = os.open(path, _OPEN_FLAGS)
    except OSError as exc:
        raise ValueError("a symbolic link" if exc.errno == errno.ELOOP else exc.strerror) from None
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise ValueError("not a regular file")
        if st.st_nlink != 1:
            raise ValueError(f"a file with {st.st_nlink} hard links")
        if st.st_size > limit:
            raise ValueError(f"a file of {st.st_size:,} bytes (at most {limit:,})")
        data = os.pread(fd, limit + 1, 0)
        if len(data) > limit:
            raise ValueError(f"a file of more than {limit:,} bytes")
        return data
    finally:
        os.close(fd)


def _walk(folder: Path):
    """``(relative path, DirEntry)`` of everything under ``folder``, parents before children, sorted.

    Depth first with an explicit stack: no recursion limit however deep the folder is nested.
    """
    stack = [(Path(folder), "", None)]
    while stack:
        path, rel, it = stack.pop()
        if it is None:
            with os.scandir(path) as scan:
                it = iter(sorted(scan, key=lambda e: e.name))
        entry = next(it, None)
        if entry is None:
            continue
        stack.append((path, rel, it))
        name = f"{rel}{entry.name}"
        yield name, entry
        if entry.is_dir(follow_symlinks=False):
            stack.append((Path(entry.path), name + "/", None))


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
    try:
        text = read_regular(Path(folder) / MARKER, MAX_MARKER_BYTES).decode("utf-8")
    except (ValueError, OSError):  # UnicodeDecodeError is a ValueError
        return None
    if text == "":
        return {}, set()  # an earlier wirecheck's empty marker: lists nothing
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
    if not is_regular(path / MARKER):
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
    return is_regular(path / MARKER) and foreign(path) is None


def step() -> None:
    """One step of a commit done (module docstring: a test may pause the process here)."""
    global _steps
    _steps += 1
    pause_at, pause_file = os.environ.get(_PAUSE_ENV), os.environ.get(_PAUSE_FILE_ENV)
    if pause_at and pause_file and pause_at.isdigit() and _steps == int(pause_at):
        with open(pause_file, "x", encoding="ascii") as fh:
            fh.write(f"{os.getpid()}\n")
        deadline = time.monotonic() + 60
        while os.path.lexists(pause_file) and time.monotonic() < deadline:
            time.sleep(0.005)


def _count() -> None:
    global _renames
    _renames += 1
    kill_at = os.environ.get(_KILL_ENV)
    if kill_at and kill_at.isdigit() and _renames == int(kill_at):
        os.kill(os.getpid(), signal.SIGKILL)
    step()


def rename(src, dst) -> None:
    """``os.replace(src, dst)``, counted (module docstring)."""
    os.replace(src, dst)
    _count()


_RENAME_NOREPLACE = 1
_RENAME_EXCHANGE = 2
_AT_FDCWD = -100


def _renameat2(a, b, flags: int) -> int:
    """0 done, else the errno (``ENOSYS`` where the call is missing)."""
    try:
        fn = ctypes.CDLL(None, use_errno=True).renameat2
    except (OSError, AttributeError):
        return errno.ENOSYS
    fn.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_uint]
    if fn(_AT_FDCWD, os.fsencode(a), _AT_FDCWD, os.fsencode(b), flags) == 0:
        return 0
    return ctypes.get_errno()


def exchange(a: Path, b: Path) -> bool:
    """Swap ``a`` and ``b`` (both must exist) in one step (Linux ``renameat2``); False where unsupported."""
    err = _renameat2(a, b, _RENAME_EXCHANGE)
    if err == 0:
        _count()
        return True
    if err in (errno.EINVAL, errno.ENOSYS, errno.EOPNOTSUPP):
        return False
    raise OSError(err, os.strerror(err), str(a))


def rename_noreplace(src, dst, counted: bool = True) -> bool:
    """Rename ``src`` to ``dst`` unless something is at ``dst`` (then False; nothing is replaced), counted
    (module docstring) unless ``counted`` is False (a lock file, which is no step of a commit).

    Linux ``renameat2(RENAME_NOREPLACE)``; elsewhere a file is linked then unlinked (``link`` never
    replaces), a folder renamed after a check.
    """
    err = _renameat2(src, dst, _RENAME_NOREPLACE)
    if err in (errno.EINVAL, errno.ENOSYS, errno.EOPNOTSUPP):
        try:
            if os.path.isdir(src) and not os.path.islink(src):
                if os.path.lexists(dst):
                    return False
                os.rename(src, dst)
            else:
                os.link(src, dst, follow_symlinks=False)
                os.unlink(src)
            err = 0
        except FileExistsError:
            err = errno.EEXIST
        except OSError as exc:
            err = exc.errno
    if err == 0:
        if counted:
            _count()
        return True
    if err in (errno.EEXIST, errno.ENOTEMPTY):
        return False
    raise OSError(err, os.strerror(err), str(src))


def remove_tree(folder: Path) -> None:
    """Remove ``folder`` and everything in it, iteratively (no recursion limit), without following links.

    Only for folders that are wholly ours (a temporary being filled); a folder that was in place goes
    through :func:`retire`.
    """
    folder = Path(folder)
    if not os.path.lexists(folder):
        return
    if not os.path.isdir(folder) or os.path.islink(folder):
        os.unlink(folder)
        return
    dirs = [folder]
    for _rel, entry in _walk(folder):
        if entry.is_dir(follow_symlinks=False):
            dirs.append(Path(entry.path))
        else:
            _unlink_quiet(entry.path)
    for d in reversed(dirs):  # children before parents
        try:
            os.rmdir(d)
        except FileNotFoundError:
            pass


def _unlink_quiet(path) -> None:
    try:
        os.unlink(path)
    except FileNotFoundError:
        pass


def _remove_listed(folder: Path) -> None:
    """Remove from ``folder`` each listed file whose bytes are still the listed ones, then each folder
    left empty, then the marker and ``folder`` itself if nothing else is left (:func:`retire`)."""
    listed = listing(folder)
    files, _ = listed if listed is not None else ({}, set())
    dirs = []
    for rel, entry in list(_walk(folder)):
        if entry.is_dir(follow_symlinks=False):
            dirs.append(entry.path)
        elif rel in files and not entry.is_symlink():
            try:
                fd = os.open(entry.path, _OPEN_FLAGS)
            except OSError:
                continue
            try:
                st = os.fstat(fd)
                if (
                    stat.S_ISREG(st.st_mode)
                    and st.st_nlink == 1
                    and hash_fd(fd) == files[rel]
                    and os.path.samestat(st, os.lstat(entry.path))
                ):
                    os.unlink(entry.path)
            finally:
                os.close(fd)
    for d in reversed(dirs):
        try:
            os.rmdir(d)
        except OSError:  # not empty: a file of the user's is in it
            pass
    if listed is not None:  # the listing read above: ours, whatever is left beside it
        _unlink_quiet(Path(folder) / MARKER)
    if is_regular(Path(folder) / TAG):
        _unlink_quiet(Path(folder) / TAG)
    try:
        os.rmdir(folder)
    except OSError:
        pass


def retire(old: Path, live: Path) -> list[str]:
    """Remove the old folder ``old`` (just swapped out of ``live``'s place) by its listing (module docstring).

    What is not removed (not listed, or not the listed bytes) is the user's: it is moved into ``live`` at
    its own relative path, or beside it as ``NAME.kept`` (``.kept2``, ...) when ``live`` has that name.
    Returns the paths kept, relative to ``live``'s parent; [] when the old folder was wholly ours.
    """
    old, live = Path(old), Path(live)
    _remove_listed(old)
    if not os.path.lexists(old):
        return []
    if not os.path.lexists(live):  # the folder in place is gone: the old one goes back whole
        if rename_noreplace(old, live):
            return [live.name]
    kept = []
    stack = [""]
    while stack:
        rel = stack.pop()
        with os.scandir(old / rel) as it:
            entries = sorted(it, key=lambda e: e.name)
        for entry in entries:
            name = f"{rel}{entry.name}"
            target = live / name
            if entry.is_dir(follow_symlinks=False) and is_dir_here(target):
                stack.append(name + "/")
                continue
            n, free = 1, target
            while not rename_noreplace(entry.path, free):
                free = target.with_name(f"{target.name}.kept{n if n > 1 else ''}")
                n += 1
            kept.append(f"{live.name}/{free.relative_to(live)}")
    remove_tree(old)  # empty folders only, now
    return kept


def is_dir_here(path) -> bool:
    try:
        return stat.S_ISDIR(os.lstat(path).st_mode)
    except OSError:
        return False


def is_regular(path: Path) -> bool:
    try:
        return stat.S_ISREG(os.lstat(path).st_mode)
    except OSError:
        return False
