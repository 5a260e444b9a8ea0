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
import time
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


class ThreadOracle:
    """The run's :class:`~oracles.references.pyrender_oracle.PyrenderOracle` of one image size, used through the
    run's GL thread: every call is marshalled there (:meth:`GLThread.call`), and :meth:`submit` asks for a
    drawing without waiting for it, so that the caller measures one frame while pyrender draws the next."""

    def __init__(self, gl: GLThread, width: int, height: int):
        self.gl, self.size = gl, (int(width), int(height))

    def _call(self, method: str, args: tuple, kwargs: dict):
        """``oracle.method(*args, **kwargs)`` on the GL thread: :func:`drawing`'s tuple."""
        return drawing(self.gl.oracles.get(*self.size), method, args, kwargs)

    def submit(self, method: str, *args, **kwargs) -> Future:
        """``method`` (``"render"``, ``"render_faces"``) drawn on the GL thread after the calls before it: a Future
        of :func:`drawing`'s tuple."""
        return self.gl.submit(self._call, method, args, kwargs)

    def after(self, fn, *args) -> Future:
        """``fn(*args)`` on the GL thread after the drawings asked for before it (work on a drawing, beside the
        caller's: oracles.judge.case.pixels_beside); its Future."""
        return self.gl.submit(fn, *args)

    def render(self, *args, **kwargs):
        """:meth:`PyrenderOracle.render`, waited for."""
        return self.submit("render", *args, **kwargs).result()[0]

    def render_faces(self, *args, **kwargs):
        """:meth:`PyrenderOracle.render_faces`, waited for."""
        return self.submit("render_faces", *args, **kwargs).result()[0]

    def gl_info(self) -> dict:
        """:meth:`PyrenderOracle.gl_info`, asked on the GL thread."""
        return self.gl.call(lambda: self.gl.oracles.get(*self.size).gl_info())


def drawing(oracle, method: str, args: tuple, kwargs: dict) -> tuple:
    """``(result, bound, seconds, bound_seconds)``: ``oracle.method(*args, **kwargs)``, the seconds it took (the
    oracle's own time: wall time, Mesa's own threads included), then the oracle's error bound for it
    (``last_bound_px``, 0 where it has none) and the CPU seconds that took in this thread (the harness's: a bound
    on the oracle's float32 rounding, oracles.references.pyrender_oracle)."""
    t = time.perf_counter()
    out = getattr(oracle, method)(*args, **kwargs)
    seconds = time.perf_counter() - t
    t = time.thread_time()  # this thread's CPU: its wall time beside another thread's work would count that too
    bound = getattr(oracle, "last_bound_px", 0.0)
    return out, bound, seconds, time.thread_time() - t


def submit_drawing(oracle, method: str, *args, **kwargs) -> Future:
    """``oracle``'s drawing asked for: on its GL thread without waiting (a :class:`ThreadOracle`), or drawn now
    in this thread (a PyrenderOracle itself); a Future of :func:`drawing`'s tuple either way."""
    if isinstance(oracle, ThreadOracle):
        return oracle.submit(method, *args, **kwargs)
    f: Future = Future()
    try:
        f.set_result(drawing(oracle, method, args, kwargs))
    except Exception as exc:  # noqa: BLE001 - raised where the drawing is waited for, as the thread's would be
        f.set_exception(exc)
    return f
