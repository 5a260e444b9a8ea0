"""One writer per output at a time: a lock file held with ``flock``, which the kernel releases with its process.

A lock is the file at ``path`` locked with ``fcntl.flock(LOCK_EX | LOCK_NB)``.
Whatever ends the holder (exit, SIGKILL, the OOM killer) closes its file and
releases the lock, so a lock never outlives its process and a pid reused by
another program blocks nothing: the pid written in the file is only for the
message. The holder removes the file when it releases it; a taker checks,
after locking, that the file it locked is still the one at ``path`` (not
removed meanwhile), else it tries again. A file at ``path`` that is not a
wirecheck lock (a user's file of that name, a link) is refused, never
locked, written or removed.
"""

from __future__ import annotations

import errno
import fcntl
import os
from pathlib import Path

from ..errors import InputError

PREFIX = "wirecheck lock pid "


def _is_ours(fd: int) -> bool:
    st = os.fstat(fd)
    if st.st_size > 100:
        return False
    data = os.pread(fd, 101, 0)
    if data == b"":
        return True
    text = data.decode("ascii", "replace")
    return text.startswith(PREFIX) and text[len(PREFIX):].strip().isdigit()


class Lock:
    """The lock at ``path`` taken by this process; :meth:`release` gives it back (and removes the file)."""

    def __init__(self, path: Path, option: str, what: str):
        self.path = Path(path)
        self.fd = None
        for _ in range(10):
            try:
                fd = os.open(self.path, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW | os.O_CLOEXEC, 0o666)
            except OSError as exc:
                if exc.errno not in (errno.ELOOP, errno.EISDIR):      # not a link or a folder in its place
                    raise InputError(f"{option} {what!r}: cannot create {self.path.name} there ({exc.strerror}): "
                                     "expected a writable folder and a shorter name") from None
                raise InputError(f"{option} {what!r}: {self.path.name} there was not written by wirecheck: "
                                 "expected a wirecheck output folder or a new one (nothing was changed)") from None
            try:
                if not _is_ours(fd):
                    raise InputError(f"{option} {what!r}: {self.path.name} there was not written by wirecheck: "
                                     "expected a wirecheck output folder or a new one (nothing was changed)")
                try:
                    fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                except BlockingIOError:
                    holder = os.pread(fd, 100, 0).decode("ascii", "replace")[len(PREFIX):].strip()
                    who = f" (process {holder})" if holder.isdigit() else ""
                    raise InputError(f"{option} {what!r} is being written by another wirecheck run{who}: "
                                     "expected one run per output at a time; wait for it or write elsewhere") from None
                try:
                    same = os.path.samestat(os.fstat(fd), os.stat(self.path, follow_symlinks=False))
                except FileNotFoundError:
                    same = False
                if not same:          # released and removed by its holder between our open and our lock
                    os.close(fd)
                    continue
                os.ftruncate(fd, 0)
                os.pwrite(fd, f"{PREFIX}{os.getpid()}\n".encode(), 0)
            except BaseException:
                if fd is not None:
                    try:
                        os.close(fd)
                    except OSError:
                        pass
                raise
            self.fd = fd
            return
        raise InputError(f"{option} {what!r}: could not take {self.path.name}: expected one run at a time")

    def release(self) -> None:
        if self.fd is None:
            return
        try:
            self.path.unlink()         # still locked: nobody else can hold this file now
        except FileNotFoundError:
            pass
        os.close(self.fd)
        self.fd = None


def holder(path: Path) -> str | None:
    """None when nobody holds the lock at ``path``; else who does ("process N", or "" when the file does not say).

    Probes with a shared lock taken and dropped at once. A file that is not a lock of ours: None (the
    taker refuses it with its own message).
    """
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_CLOEXEC)
    except OSError:
        return None
    try:
        if not _is_ours(fd):
            return None
        try:
            fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
        except BlockingIOError:
            pid = os.pread(fd, 100, 0).decode("ascii", "replace")[len(PREFIX):].strip()
            return f"process {pid}" if pid.isdigit() else ""
        return None
    finally:
        os.close(fd)      # drops the probe's shared lock, if taken
