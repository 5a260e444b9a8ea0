"""One writer per output at a time: a lock file held with ``flock``, which the kernel releases with its process.

A lock is the file at ``path`` locked with ``fcntl.flock(LOCK_EX | LOCK_NB)``.
Whatever ends the holder (exit, SIGKILL, the OOM killer) closes its file and
releases the lock, so a lock never outlives its process and a pid reused by
another program blocks nothing: the pid written in the file is only for the
message.

A lock file is never written in place. It is born whole: written under a
unique temporary name (``<name>.<unique>.tmp``), locked, then renamed to
``path`` with ``RENAME_NOREPLACE``, so that a file already there (a user's,
a link, a FIFO) is never replaced, and every lock of ours holds
``wirecheck lock pid N`` from the first moment. A file found at ``path`` is
opened with ``O_NOFOLLOW | O_NONBLOCK`` (a FIFO never blocks, a link is never
followed) and taken for a lock of ours only when it is a regular file with one
link and exactly that content; anything else is refused with one line naming
it and how to clear it, and is never written, locked or removed. A lock of
ours that nobody holds (its process is gone) is removed under its own lock and
a fresh one is made. The holder removes its file when it releases it, and only
when the file at ``path`` is still the one it holds.
"""

from __future__ import annotations

import errno
import fcntl
import os
import re
import stat
import tempfile
from pathlib import Path

from ..errors import InputError
from .owned import rename_noreplace

PREFIX = "wirecheck lock pid "
_CONTENT = re.compile(rb"wirecheck lock pid (\d{1,10})\n")
_OPEN_FLAGS = os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK | os.O_CLOEXEC


def what_is(fd: int) -> str | None:
    """None when the open file ``fd`` is a lock of ours (regular, one link, our content); else what it is."""
    st = os.fstat(fd)
    if not stat.S_ISREG(st.st_mode):
        return _kind(st.st_mode)
    if st.st_nlink != 1:
        return f"a file with {st.st_nlink} hard links"
    if st.st_size == 0:
        return "an empty file"
    if st.st_size > 40 or _CONTENT.fullmatch(os.pread(fd, 41, 0)) is None:
        return "a file not written by wirecheck"
    return None


def _kind(mode: int) -> str:
    for test, name in (
        (stat.S_ISFIFO, "a FIFO"),
        (stat.S_ISDIR, "a folder"),
        (stat.S_ISSOCK, "a socket"),
        (stat.S_ISCHR, "a character device"),
        (stat.S_ISBLK, "a block device"),
        (stat.S_ISLNK, "a symbolic link"),
    ):
        if test(mode):
            return name
    return "not a regular file"


def _pid(fd: int) -> str:
    found = _CONTENT.fullmatch(os.pread(fd, 41, 0))
    return found.group(1).decode() if found else ""


def _refusal(option: str, what: str, path: Path, kind: str) -> InputError:
    return InputError(
        f"{option} {what!r}: {str(path)!r} is {kind}, not a lock of wirecheck's: nothing was "
        "changed; expected wirecheck's own lock file or none there (remove or rename it if no "
        "wirecheck run is writing there)"
    )


def _open_existing(path: Path, option: str, what: str) -> int | None:
    """The found file at ``path`` opened without following or blocking; None when it is gone meanwhile."""
    try:
        return os.open(path, _OPEN_FLAGS)
    except FileNotFoundError:
        return None
    except OSError as exc:
        kind = {errno.ELOOP: "a symbolic link", errno.ENXIO: "a socket"}.get(exc.errno)
        if kind is None:
            raise InputError(
                f"{option} {what!r}: cannot open {str(path)!r} ({exc.strerror}): expected wirecheck's "
                "own lock file or none there (remove or rename it if no wirecheck run is writing "
                "there)"
            ) from None
        raise _refusal(option, what, path, kind) from None


def _create_locked(path: Path, option: str, what: str) -> int | None:
    """A new lock file of ours, locked and renamed into place; None when a file is at ``path`` already."""
    try:
        fd, tmp = tempfile.mkstemp(prefix=f"{path.name}.", suffix=".tmp", dir=path.parent)
    except OSError as exc:
        raise InputError(
            f"{option} {what!r}: cannot create {path.name} there ({exc.strerror}): "
            "expected a writable folder and a shorter name"
        ) from None
    try:
        os.write(fd, f"{PREFIX}{os.getpid()}\n".encode())
        os.fchmod(fd, 0o644)
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)  # a new file: nobody else has it
        if not rename_noreplace(tmp, path, counted=False):
            os.unlink(tmp)
            os.close(fd)
            return None
    except BaseException:
        if os.path.lexists(tmp):
            os.unlink(tmp)
        os.close(fd)
        raise
    return fd


class Lock:
    """The lock at ``path`` taken by this process; :meth:`release` gives it back (and removes the file)."""

    def __init__(self, path: Path, option: str, what: str):
        self.path = Path(path)
        self.fd = None
        for _ in range(20):
            fd = _create_locked(self.path, option, what)
            if fd is not None:
                self.fd = fd
                return
            fd = _open_existing(self.path, option, what)
            if fd is None:
                continue  # released and removed meanwhile: try again
            try:
                kind = what_is(fd)
                if kind is not None:
                    raise _refusal(option, what, self.path, kind)
                try:
                    fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                except BlockingIOError:
                    pid = _pid(fd)
                    who = f" (process {pid})" if pid else ""
                    raise InputError(
                        f"{option} {what!r} is being written by another wirecheck run{who}: "
                        "expected one run per output at a time; wait for it or write elsewhere"
                    ) from None
                # a lock of ours that nobody holds: its process is gone. Removed under its own lock, if still there
                if _same(fd, self.path) and what_is(fd) is None:
                    os.unlink(self.path)
            finally:
                os.close(fd)
        raise InputError(f"{option} {what!r}: could not take {self.path.name}: expected one run at a time")

    def release(self) -> None:
        if self.fd is None:
            return
        if _same(self.fd, self.path):  # still ours and still locked: nobody else can hold it now
            os.unlink(self.path)
        os.close(self.fd)
        self.fd = None


def _same(fd: int, path: Path) -> bool:
    try:
        return os.path.samestat(os.fstat(fd), os.stat(path, follow_symlinks=False))
    except FileNotFoundError:
        return False


def holder(path: Path) -> str | None:
    """None when nobody holds the lock at ``path``; else who does ("process N", or "" when the file does not say).

    Probes with a shared lock taken and dropped at once, on the file opened without following a link or
    blocking on a FIFO. A file that is not a lock of ours: None (the taker refuses it with its own message).
    """
    try:
        fd = os.open(path, _OPEN_FLAGS)
    except OSError:
        return None
    try:
        if what_is(fd) is not None:
            return None
        try:
            fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
        except BlockingIOError:
            pid = _pid(fd)
            return f"process {pid}" if pid else ""
        return None
    finally:
        os.close(fd)  # drops the probe's shared lock, if taken
