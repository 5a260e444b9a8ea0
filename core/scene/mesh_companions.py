"""Reading a mesh's companion files safely, and keeping interrupts alive through trimesh.

A mesh file may name other files: an OBJ's ``mtllib``, a ``.mtl``'s
``map_Kd`` texture, a glTF buffer or image ``uri``. trimesh opens them
through a *resolver*. Its file resolver opens whatever the name points to,
and reading a FIFO (no writer: forever), ``/dev/zero`` (endless) or a
terminal blocks the run. :func:`companion_resolver` gives trimesh a resolver
that opens only regular files (core.user_files: it looks at the path with
``stat`` first, opens without blocking, so even a file swapped for a FIFO
between the check and the open cannot block, and checks the opened file again). A refused
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
import threading
from pathlib import Path

from ..user_files import RefusedFile, read_regular


def read_companion(path: Path) -> bytes:
    """The bytes of a companion file: a regular file within its limit (core.user_files); RefusedFile otherwise."""
    return read_regular(path, "mesh companion")


_RESOLVER_CLASS = None


def companion_resolver(mesh_path: Path):
    """A trimesh resolver for ``mesh_path``'s companions that refuses non-regular files.

    Its ``refused`` list holds ``(name as written, RefusedFile)`` for each
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
                            return read_companion(path)
                        except RefusedFile as exc:
                            self.refused.append((name, exc))
                            raise
                self.absolute(name)  # trimesh's message for a name outside the folder
                raise FileNotFoundError(name)

            def keys(self):  # a listing of the whole folder is never needed here
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
        if not callable(old):  # SIG_DFL (the kernel ends the process) or SIG_IGN
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
