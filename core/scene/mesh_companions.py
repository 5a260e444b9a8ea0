"""Reading a mesh's companion files safely, and keeping interrupts alive through trimesh.

A mesh file may name other files: an OBJ's ``mtllib``, a ``.mtl``'s
``map_Kd`` texture, a glTF buffer or image ``uri``. trimesh opens them
through a *resolver*. Its file resolver opens whatever the name points to,
and reading a FIFO (no writer: forever), ``/dev/zero`` (endless) or a
terminal blocks the run. :func:`companion_resolver` gives trimesh a resolver
that opens only regular files: it looks at the path with ``stat`` first, opens
without blocking (``O_NONBLOCK``, so even a file swapped for a FIFO between the
check and the open cannot block) and checks the opened file again. A refused
companion is recorded; trimesh swallows the resolver's exception (it catches
every exception around material loading), so the loader raises afterwards:
one line naming the companion (``load_mesh_file`` in core.scene.files).

trimesh also catches ``BaseException`` around material and texture loading,
which swallows a ``KeyboardInterrupt`` (SIGINT) or core.app.guard's
``Interrupted`` (SIGTERM) raised while it reads. :func:`interrupts_kept`
wraps such a call: it records the exception the signal handler raised and
raises it again once the call returns, so Ctrl-C and SIGTERM still end the run
(core.app.guard: exit 130/143, no outputs).
"""

from __future__ import annotations

import contextlib
import os
import signal
import stat
import threading
from pathlib import Path

_KINDS = ((stat.S_ISFIFO, "a FIFO"), (stat.S_ISCHR, "a character device"),
          (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket"), (stat.S_ISDIR, "a folder"))


def file_kind(mode: int) -> str:
    """What a non-regular file is, in words (``stat`` mode)."""
    return next((words for test, words in _KINDS if test(mode)), "not a regular file")


def read_regular(path: Path) -> bytes:
    """The bytes of ``path``, which must be a regular file; OSError otherwise, never blocking.

    Raises ``NotRegularFile`` (an OSError) for a FIFO, device, socket or folder.
    """
    st = os.stat(path)
    if not stat.S_ISREG(st.st_mode):
        raise NotRegularFile(path, file_kind(st.st_mode))
    fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_NOCTTY", 0))
    with os.fdopen(fd, "rb") as fh:
        st = os.fstat(fh.fileno())
        if not stat.S_ISREG(st.st_mode):          # swapped between the stat and the open
            raise NotRegularFile(path, file_kind(st.st_mode))
        return fh.read()


class NotRegularFile(OSError):
    """A companion file that is a FIFO, device, socket or folder: never read."""

    def __init__(self, path, kind: str):
        super().__init__(f"{path} is {kind}")
        self.path, self.kind = str(path), kind


_RESOLVER_CLASS = None


def companion_resolver(mesh_path: Path):
    """A trimesh resolver for ``mesh_path``'s companions that refuses non-regular files.

    Its ``refused`` list holds ``(name as written, NotRegularFile)`` for each
    companion it would not open.
    """
    global _RESOLVER_CLASS
    if _RESOLVER_CLASS is None:
        from trimesh.resolvers import FilePathResolver

        class RegularFileResolver(FilePathResolver):
            """trimesh's FilePathResolver (same lookup, same confinement to the mesh's folder), reading
            only regular files."""

            def __init__(self, source):
                super().__init__(source)
                self.refused = []

            def get(self, name: str):
                candidates = (name.strip(), name.strip().lstrip("/"), os.path.split(name)[-1])
                for candidate in candidates:
                    try:
                        path = self.absolute(candidate)
                    except ValueError:
                        continue
                    if path.exists():
                        try:
                            return read_regular(path)
                        except NotRegularFile as exc:
                            self.refused.append((name, exc))
                            raise
                self.absolute(name)          # trimesh's message for a name outside the folder
                raise FileNotFoundError(name)

            def keys(self):                   # a listing of the whole folder is never needed here
                return iter(())

        _RESOLVER_CLASS = RegularFileResolver
    return _RESOLVER_CLASS(str(mesh_path))


@contextlib.contextmanager
def interrupts_kept():
    """Re-raise, after the block, the exception a SIGINT/SIGTERM handler raised inside it.

    Code in the block that catches ``BaseException`` (trimesh) cannot swallow
    an interrupt: the handler in force (Python's default SIGINT handler, or
    core.app.guard's) is wrapped for the duration, and the exception it raised is
    raised again when the block ends. Outside the main thread (where no
    handler can be set) the block runs as it is.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    raised: list[BaseException] = []
    saved = {}
    for sig in (signal.SIGINT, signal.SIGTERM):
        old = signal.getsignal(sig)
        if not callable(old):               # SIG_DFL (the kernel ends the process) or SIG_IGN
            continue

        def handler(signum, frame, old=old):
            try:
                old(signum, frame)
            except BaseException as exc:
                raised.append(exc)
                raise

        saved[sig] = old
        signal.signal(sig, handler)
    try:
        yield
    finally:
        for sig, old in saved.items():
            signal.signal(sig, old)
    if raised:
        raise raised[0]
