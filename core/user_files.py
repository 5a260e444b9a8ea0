"""Opening a file wirecheck reads: regular files only, never blocking, each kind with a size limit.

Every file a run reads (a config, a scene list, a ``.scene`` file, a mesh and
the files it names, a job's ``job.json``, cameras, OBJs and frames, a
``--candidate FILE.py``) is opened here. Opening a FIFO for reading waits for
a writer, forever; ``/dev/zero`` and ``/dev/urandom`` never end; a terminal
steals the input; a folder is no file. So a path is

1. looked at with ``stat`` (symbolic links followed: a link to a regular file
   is a normal input) and refused unless it is a regular file, never opened;
2. opened with ``O_NONBLOCK`` (a FIFO swapped in after the ``stat`` cannot
   block the open) and ``O_NOCTTY``, and checked again through the
   descriptor, which is the file every later read sees;
3. refused when larger than its kind's limit (:data:`LIMITS`), and read no
   further than the limit even if it grows meanwhile.

A refusal is a :class:`RefusedFile`, an InputError of one line: which file,
what it is (a FIFO, a character device, a folder, its size and the limit),
what was expected. The limits and their reasons are the table of
docs/reliability.md ("Files wirecheck reads").
"""

from __future__ import annotations

import io
import os
import stat
from typing import NamedTuple

from .errors import InputError

MiB = 1 << 20


class Limit(NamedTuple):
    """The largest file of one kind, in bytes; what the file is (for messages) and why the limit is what it is."""

    size: int
    what: str
    why: str


#: kind -> Limit. Each is far above any real file of its kind and low enough that reading it
#: (wholly, into memory, and parsing it in Python) stays within seconds and a few GB.
LIMITS = {
    "config": Limit(
        4 * MiB,
        "a pyproject.toml or settings file",
        "a pyproject.toml is a few KB; tomllib took 10 s for 16 MiB (2 busy cores), so about 3 s here",
    ),
    "scene list": Limit(
        64 * MiB,
        "a scene list (one mesh path a line)",
        "a million paths of 60 characters; every line is kept in memory",
    ),
    "scene": Limit(
        64 * MiB,
        "a .scene file",
        "about two million 'v'/'e' lines of 30 bytes, parsed in Python; a larger model is a mesh file",
    ),
    "mesh": Limit(
        2048 * MiB,
        "a mesh file",
        "trimesh holds the file and several arrays of it in memory (a 2 GiB binary PLY is "
        "about 100 million triangles at 19 bytes each, far beyond a legible wireframe)",
    ),
    "mesh companion": Limit(
        2048 * MiB,
        "a file a mesh names (mtllib, texture, glTF buffer)",
        "read wholly into memory by trimesh; as large as a mesh",
    ),
    "job": Limit(
        256 * MiB,
        "a job.json of 'crosscheck export'",
        "export writes about 40 bytes a frame of a case (its path): 100,000 frames (the limit) of "
        "21 cases are 84 MB; read wholly and parsed as JSON",
    ),
    "camera": Limit(1 * MiB, "a camera file of 'crosscheck export'", "export writes about 1.5 KB a frame"),
    "job mesh": Limit(2048 * MiB, "an OBJ of 'crosscheck export'", "as a mesh file"),
    "frame": Limit(
        512 * MiB,
        "a PNG frame",
        "the largest frame, 2^25 pixels of 16-bit RGBA, is 256 MiB unpacked; deflate adds "
        "under 0.1% to data it cannot compress",
    ),
    "depth map": Limit(
        512 * MiB,
        "a depth map (.npy, .tif, .png)",
        "the largest frame's depth, 2^25 pixels of float64, is 256 MiB; a TIFF or .npy adds its header only",
    ),
    "candidate": Limit(16 * MiB, "a candidate's Python file", "a module of 300,000 lines; Python compiles it whole"),
}

_KINDS = (
    (stat.S_ISFIFO, "a FIFO"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISSOCK, "a socket"),
    (stat.S_ISDIR, "a folder"),
)
_FLAGS = os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_NOCTTY", 0) | getattr(os, "O_CLOEXEC", 0)


def file_kind(mode: int) -> str:
    """What a file of ``stat`` mode ``mode`` is, in words (``"a FIFO"``, ``"a folder"``, ``"a regular file"``)."""
    if stat.S_ISREG(mode):
        return "a regular file"
    return next((words for test, words in _KINDS if test(mode)), "not a regular file")


class RefusedFile(InputError):
    """A file that is not read: not a regular file, missing, unreadable or over its kind's limit.

    ``path`` the file as given, ``problem`` what it is (``"a FIFO, not a regular file"``,
    ``"too large (3,221,225,472 bytes)"``), ``kind`` its key in LIMITS.
    """

    def __init__(self, path, problem: str, kind: str):
        self.path, self.problem, self.kind = str(path), problem, kind
        super().__init__(f"{path}: {problem}: expected {expected(kind)}")


def expected(kind: str) -> str:
    """What a file of ``kind`` must be, for a message: a regular file of at most its limit."""
    limit = LIMITS[kind]
    return f"{limit.what}, a regular file of at most {_size(limit.size)} (docs/reliability.md)"


def _size(n: int) -> str:
    return f"{n // MiB:,} MiB" if n % MiB == 0 and n >= MiB else f"{n:,} bytes"


def _problem(mode: int, size: int, kind: str) -> str | None:
    if not stat.S_ISREG(mode):
        return f"{file_kind(mode)}, not a regular file"
    if size > LIMITS[kind].size:
        return f"too large ({size:,} bytes)"
    return None


def _os_problem(path, exc: OSError) -> str:
    if isinstance(exc, FileNotFoundError):
        return "a broken link" if os.path.islink(path) else "missing"
    return f"unreadable ({exc.strerror or exc})"


def problem(path, kind: str) -> str | None:
    """Why ``path`` would be refused as a ``kind`` (from ``stat`` alone, nothing opened); None when it would not."""
    try:
        st = os.stat(path)
    except (OSError, ValueError) as exc:  # ValueError: a NUL in the name
        return _os_problem(path, exc) if isinstance(exc, OSError) else "a name holding a NUL character"
    return _problem(st.st_mode, st.st_size, kind)


def open_regular(path, kind: str):
    """``path`` opened for binary reading when it is a regular file within ``kind``'s limit; RefusedFile otherwise.

    Never blocks: nothing but a regular file is opened, and the open itself is
    non-blocking. The returned file is the one checked; read it, not the name.
    """
    why = problem(path, kind)
    if why is not None:
        raise RefusedFile(path, why, kind)
    try:
        fd = os.open(path, _FLAGS)
    except OSError as exc:
        raise RefusedFile(path, _os_problem(path, exc), kind) from None
    try:
        st = os.fstat(fd)
        why = _problem(st.st_mode, st.st_size, kind)  # replaced between the stat and the open
        if why is not None:
            raise RefusedFile(path, why, kind)
        return os.fdopen(fd, "rb")
    except BaseException:
        os.close(fd)
        raise


def read_regular(path, kind: str) -> bytes:
    """The bytes of ``path`` (:func:`open_regular`); RefusedFile when it grows past the limit while read.

    Memory is the file's size, not the limit: the first read asks for the size ``fstat`` gives plus one
    byte (a file that grew, or a ``/proc`` file of size 0, is read on in 1 MiB steps up to the limit).
    """
    limit = LIMITS[kind].size
    chunks, total = [], 0
    with open_regular(path, kind) as fh:
        want = os.fstat(fh.fileno()).st_size + 1
        try:
            while chunk := fh.read(min(want, limit + 1 - total)):
                chunks.append(chunk)
                total += len(chunk)
                if total > limit:
                    raise RefusedFile(path, f"too large (it grew past {limit:,} bytes while read)", kind)
                want = MiB
        except OSError as exc:  # EIO, a file on a failing disk
            raise RefusedFile(path, _os_problem(path, exc), kind) from None
    return b"".join(chunks)


def read_text(path, kind: str, encoding: str = "utf-8-sig", errors: str = "strict") -> str:
    """The text of ``path`` (:func:`read_regular`); UnicodeDecodeError for bytes that are not ``encoding``.

    The default ``utf-8-sig`` drops a byte-order mark (Windows editors write one).
    """
    return read_regular(path, kind).decode(encoding, errors)


def open_text(path, kind: str, encoding: str = "utf-8", errors: str = "replace"):
    """``path`` opened as text (:func:`open_regular`), for reading line by line."""
    return io.TextIOWrapper(open_regular(path, kind), encoding=encoding, errors=errors)


def is_regular(path) -> bool:
    """True when ``path`` is a regular file (links followed), looked at with ``stat`` only."""
    try:
        return stat.S_ISREG(os.stat(path).st_mode)
    except (OSError, ValueError):
        return False


__all__ = [
    "LIMITS",
    "RefusedFile",
    "expected",
    "file_kind",
    "is_regular",
    "open_regular",
    "open_text",
    "problem",
    "read_regular",
    "read_text",
]
