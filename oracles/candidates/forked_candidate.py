"""A Python callable as a candidate program, without an importable module: a forked copy of this process
serving the candidate protocol (docs/protocol.md) for it, with the interface of a ``subprocess.Popen``.

A lambda or a closure cannot be imported by the candidate host
(oracles.candidates.candidate_host); oracles.candidates.isolation forks instead, so it still runs
in a process of its own, and one that calls ``os._exit`` or hangs fails its
cases instead of ending the caller's pytest.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time

from . import protocol
from .candidate_host import serve_loaded
from .processes import die_with_parent


class ForkedChild:
    """A forked copy of this process serving the candidate protocol for ``func``: what Popen gives, for it.

    The child gets its own session (so the program group can be killed), dies
    with its parent (Linux), sends its prints and stderr to the stderr pipe,
    and always ends with ``os._exit``: it never returns into the caller's code.
    ``close_fds``: the parent's ends of other live programs' pipes, closed in
    the child (a program would otherwise never see EOF on its stdin while the
    fork lives).
    """

    def __init__(self, func, close_fds=()):
        in_r, in_w = os.pipe()
        out_r, out_w = os.pipe()
        err_r, err_w = os.pipe()
        pid = os.fork()
        if pid == 0:  # the child
            code = 1
            try:
                os.setsid()
                die_with_parent()
                sys.dont_write_bytecode = True  # as the candidate host: no __pycache__ from its imports
                for fd in (in_w, out_r, err_r, *close_fds):
                    os.close(fd)
                os.dup2(err_w, 1)
                os.dup2(err_w, 2)
                sys.stdout = sys.stderr = open(2, "w", buffering=1, closefd=False)
                stdin, out = os.fdopen(in_r, "rb"), os.fdopen(out_w, "wb")

                def send(data: bytes) -> None:
                    out.write(data)
                    out.flush()

                if stdin.readline() == protocol.HEADER:
                    send(protocol.HEADER)
                    code = serve_loaded(func, stdin, send)
                else:
                    send(protocol.encode_error(f"expected the header {protocol.HEADER!r}"))
                    code = 2
            except BaseException:  # noqa: BLE001 - the child must never return
                code = 1
            finally:
                os._exit(code)
        for fd in (in_r, out_w, err_w):
            os.close(fd)
        self.pid = pid
        self.args = ("<forked>",)
        self.returncode = None
        self.stdin = os.fdopen(in_w, "wb", buffering=0)
        self.stdout = os.fdopen(out_r, "rb", buffering=0)
        self.stderr = os.fdopen(err_r, "rb", buffering=0)

    def poll(self):
        if self.returncode is None:
            pid, status = os.waitpid(self.pid, os.WNOHANG)
            if pid:
                self.returncode = os.waitstatus_to_exitcode(status)
        return self.returncode

    def wait(self, timeout=None):
        deadline = None if timeout is None else time.monotonic() + timeout
        while self.poll() is None:
            if deadline is not None and time.monotonic() > deadline:
                raise subprocess.TimeoutExpired(self.args, timeout)
            time.sleep(0.001)
        return self.returncode

    def kill(self) -> None:
        if self.returncode is None:
            try:
                os.kill(self.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
