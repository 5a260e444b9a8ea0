"""PNG frames finished by a second process while this one renders the next ones.

A renderer run spends about half of each frame's time on the PNG: packing the
bits, compressing them (zlib) and creating the file. Threads do not overlap
that with rendering (the rendering holds the GIL nearly all the time; measured:
slower than writing in line), so :class:`ForkedPngWriter` forks one child
that does the compressing and the writing. The parent packs each bilevel
frame's scanlines (:func:`core.outputs.output.bilevel_rows`, 1/8 of the image's bytes) and
sends them down a pipe; the child compresses them and writes the file with the
same functions as :func:`core.outputs.output.png_bytes`, so the files are the same
bytes. A frame that is not bilevel (anti-aliased, shaded, RGB) is encoded and
written by the parent itself.

Errors reach the parent: the child reports an ``OSError`` (disk full, ...) as
the same ``OSError``, anything else as a RuntimeError, raised by the next
:meth:`ForkedPngWriter.put` or by :meth:`ForkedPngWriter.close`. Leaving the
``with`` block, even on an error or an interrupt, waits for the child, so no
file is written after the caller cleans up. The child ignores SIGINT (Ctrl-C
stops the parent, which ends the pipe) and exits with ``os._exit``: none of
the parent's ``finally`` blocks, ``atexit`` handlers or buffered output run
twice.
"""

from __future__ import annotations

import os
import signal
import struct
import threading
from pathlib import Path

import numpy as np

from .output import bilevel_png_from_rows, bilevel_rows, is_bilevel, png_bytes, write_all, write_file

#: Fewer frames than this are written in line: forking costs a few ms.
MIN_FRAMES = 32

_HEADER = struct.Struct(">IIII")  # width, height, length of the path, length of the scanlines


def can_fork(frames: int) -> bool:
    """Whether a run of ``frames`` PNG frames gains from :class:`ForkedPngWriter`.

    It needs ``os.fork``, a second CPU, enough frames to pay for the fork, and
    a process with no other thread (forking copies only the calling thread; a
    lock held by another one would stay locked in the child).
    """
    if not hasattr(os, "fork") or frames < MIN_FRAMES or threading.active_count() != 1:
        return False
    try:
        cpus = len(os.sched_getaffinity(0))
    except AttributeError:  # not Linux
        cpus = os.cpu_count() or 1
    return cpus >= 2


class ForkedPngWriter:
    """``put(path, image)`` writes ``png_bytes(image)`` to ``path``, bilevel frames by a child process.

    ``image`` is ``(H, W)`` or ``(H, W, 3)`` uint8. Use as a context manager
    (module docstring); :meth:`close` waits for every frame to be written and
    raises the child's error, if any.
    """

    def __init__(self):
        to_child, self._pipe = os.pipe()
        errors, self._child_errors = os.pipe()
        pid = os.fork()
        if pid == 0:  # the child: never returns
            os.close(self._pipe)
            os.close(errors)
            _child(to_child, self._child_errors)
        os.close(to_child)
        os.close(self._child_errors)
        self._errors = errors
        self._pid = pid

    def put(self, path: Path, image: np.ndarray) -> None:
        if not is_bilevel(image):
            write_file(path, png_bytes(image))
            return
        name = os.fsencode(path)
        rows = bilevel_rows(image)
        h, w = image.shape
        try:
            write_all(self._pipe, _HEADER.pack(w, h, len(name), len(rows)) + name + rows)
        except BrokenPipeError:  # the child stopped: say why
            self._finish()
            raise RuntimeError("frame writer process ended early") from None

    def close(self) -> None:
        self._finish()

    def _finish(self) -> None:
        """End the pipe, wait for the child, raise its error (once)."""
        if self._pid is None:
            return
        os.close(self._pipe)
        report = _read_all(self._errors)
        os.close(self._errors)
        _, status = os.waitpid(self._pid, 0)
        self._pid = None
        if report:
            kind, _, rest = report.partition(b"\0")
            if kind == b"OSError":
                number, strerror, filename = rest.decode("utf-8", "replace").split("\0")
                raise OSError(int(number), strerror, filename or None)
            raise RuntimeError(f"frame writer process: {rest.decode('utf-8', 'replace')}")
        if status != 0:
            raise RuntimeError(f"frame writer process ended with status {status}")

    def __enter__(self):
        return self

    def __exit__(self, exc_type, exc, tb):
        if exc_type is None:
            self._finish()
        elif self._pid is not None:  # already failing: wait, keep the first error
            try:
                self._finish()
            except Exception:  # noqa: BLE001 - the caller's error comes first
                pass
        return False


def _child(source: int, errors: int) -> None:
    """Read frames from ``source`` until it ends, write each; the first error goes to ``errors``; exit."""
    report = b""
    try:
        signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C: the parent stops, the pipe ends
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
        with os.fdopen(source, "rb") as pipe:
            while header := pipe.read(_HEADER.size):
                w, h, n_name, n_rows = _HEADER.unpack(header)
                path = pipe.read(n_name)
                rows = pipe.read(n_rows)
                if len(path) != n_name or len(rows) != n_rows:
                    raise EOFError("frame cut short")
                write_file(path, bilevel_png_from_rows(rows, w, h))
    except OSError as exc:
        report = (
            b"OSError\0"
            + "\0".join(
                (str(exc.errno or 0), exc.strerror or str(exc), os.fsdecode(exc.filename) if exc.filename else "")
            ).encode()
        )
    except BaseException as exc:  # noqa: BLE001 - reported to the parent
        report = f"{type(exc).__name__}: {exc}".encode()
    finally:
        try:
            write_all(errors, report)
        finally:
            os._exit(0 if not report else 1)


def _read_all(fd: int) -> bytes:
    chunks = []
    while chunk := os.read(fd, 65536):
        chunks.append(chunk)
    return b"".join(chunks)
