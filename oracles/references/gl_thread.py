"""One thread that owns every GL call of a run: the references' pyrender contexts, used and closed there.

A GL context is current on one thread at a time. :class:`GLThread` keeps a
run's :class:`~oracles.references.pyrender_oracle.OracleCache` on one worker
thread (a single-thread executor: its tasks run first in, first out, in the
order they are asked for); every call that touches GL (a
:class:`~oracles.references.pyrender_oracle.PyrenderOracle` made, a drawing,
``gl_info``, closing them) is marshalled to it with :meth:`GLThread.submit`
or :meth:`GLThread.call`. The caller's thread meanwhile does its own numpy
work: much of a drawing runs inside the GL library, which PyOpenGL's ctypes
calls run without the GIL, so the two overlap on two cores.

``threaded=False`` runs each call in the calling thread when it is asked for
(the same results in the same order, nothing overlapped).

Nothing is left running: :meth:`GLThread.close` (on an error or Ctrl-C too)
drops the calls not yet begun, waits for the one running, closes the oracles
on the worker and joins it.
"""

from __future__ import annotations

import threading
from concurrent.futures import Future, ThreadPoolExecutor

from .pyrender_oracle import OracleCache

#: The worker thread's name prefix (a test finds the thread left behind by it).
THREAD_NAME = "wirecheck-frames"


class GLThread:
    """The run's oracles (``oracles``: an OracleCache, made here when None) and the one thread that uses them.

    ``threaded=False``: each call runs in the caller's thread, at once.
    """

    def __init__(self, oracles=None, threaded: bool = True):
        self.oracles = OracleCache() if oracles is None else oracles
        self._pool = ThreadPoolExecutor(1, thread_name_prefix=THREAD_NAME) if threaded else None
        self._pending: set[Future] = set()
        self._lock = threading.Lock()

    @property
    def threaded(self) -> bool:
        """Whether calls run on the worker (False: in the caller's thread; also once closed)."""
        return self._pool is not None

    def submit(self, fn, *args) -> Future:
        """``fn(*args)`` on the GL thread, after every call asked for before it; its Future (its result, or the
        exception it raised)."""
        if self._pool is None:
            f = Future()
            try:
                f.set_result(fn(*args))
            except Exception as exc:  # noqa: BLE001 - as the pool's future would hold it
                f.set_exception(exc)
            return f
        with self._lock:
            f = self._pool.submit(fn, *args)
            self._pending.add(f)
        f.add_done_callback(self._done)
        return f

    def _done(self, f: Future) -> None:
        with self._lock:
            self._pending.discard(f)

    def call(self, fn, *args):
        """``fn(*args)`` on the GL thread, waited for (e.g. ``gl_info``)."""
        return self.submit(fn, *args).result()

    def close(self) -> None:
        """Drop the calls not begun, close the oracles (on the GL thread) and join it; no thread is left."""
        if self._pool is None:
            self.oracles.close()
            return
        pool, self._pool = self._pool, None
        try:
            with self._lock:
                pending = list(self._pending)
            for f in pending:
                f.cancel()
            pool.submit(self.oracles.close).result()
        finally:
            pool.shutdown(wait=True, cancel_futures=True)
