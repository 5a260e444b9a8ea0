"""The references' GL thread (oracles.references.gl_thread): every call on one thread, in the order asked for;
a call's exception kept for its caller; the oracles closed on that thread and no thread left behind."""

from __future__ import annotations

import threading

import pytest
from wirecheck.oracles.references.gl_thread import THREAD_NAME, GLThread


class Oracles:
    """A stand-in OracleCache: records the thread each call and the closing ran on."""

    def __init__(self):
        self.threads, self.closed_on = [], None

    def draw(self, k):
        self.threads.append(threading.current_thread())
        return k * k

    def close(self):
        self.closed_on = threading.current_thread()


def _workers() -> list:
    return [t for t in threading.enumerate() if t.name.startswith(THREAD_NAME)]


def test_every_call_runs_on_one_worker_in_order_and_the_oracles_close_there():
    oracles = Oracles()
    gl = GLThread(oracles)
    try:
        futures = [gl.submit(oracles.draw, k) for k in range(6)]
        assert [f.result() for f in futures] == [0, 1, 4, 9, 16, 25]
        assert gl.call(oracles.draw, 7) == 49
        workers = set(oracles.threads)
        assert len(workers) == 1 and threading.current_thread() not in workers
    finally:
        gl.close()
    assert oracles.closed_on in workers  # the contexts are released on the thread that made them current
    assert _workers() == [] and not gl.threaded


def test_a_calls_exception_is_raised_in_its_caller_and_the_thread_goes_on():
    gl = GLThread(Oracles())
    try:
        with pytest.raises(ZeroDivisionError):
            gl.call(lambda: 1 / 0)
        assert gl.call(lambda: 2 + 2) == 4
    finally:
        gl.close()
    assert _workers() == []


def test_unthreaded_calls_run_in_the_callers_thread_at_once():
    oracles = Oracles()
    gl = GLThread(oracles, threaded=False)
    f = gl.submit(oracles.draw, 3)
    assert f.done() and f.result() == 9  # done before anything waited for it
    assert oracles.threads == [threading.current_thread()]
    with pytest.raises(ZeroDivisionError):
        gl.submit(lambda: 1 / 0).result()
    gl.close()
    assert oracles.closed_on is threading.current_thread()
