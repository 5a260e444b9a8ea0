"""A candidate that runs in its own process and speaks the candidate protocol (oracles.candidates.protocol).

:class:`SubprocessCandidate` is a picklable description (the command and its
timeouts); calling it follows the candidate contract (oracles.candidates.candidate). The
live program belongs to the calling process: it is started on the first call,
kept for the process's life (once per worker with ``--jobs``), and closed at
exit. Whatever the program does, a call ends within the timeout with pixels or
a :class:`~oracles.candidates.candidate.CandidateError` of one line:

- it hangs: killed (its whole process group) after ``timeout_s``;
- it dies (``os._exit``, a segfault, a signal): its exit status or signal;
- it closes its stdout or stdin and lives on: that, killed within ``timeout_s``;
- it answers the wrong number of points, or garbage, or before reading the
  request, or writes between requests: what it wrote;
- it answers ``{"error": ...}``: its message (the program lives on).

The timeout is per request (writing it and reading the whole reply), not per
read. A kill reaches the program's process group and (Linux) any process that
holds the program's end of one of its pipes.

After a kill or a death the next call starts the program again (a fresh
process for the next case). A program that fails to start (dies, hangs or
writes garbage before answering the header) fails every later call at once
with the same reason, instead of being started again for every case.

The program's stderr is a pipe read while waiting for each reply and
drained after it, into a buffer that keeps the last ``STDERR_KEEP`` bytes:
memory stays bounded however much the program writes, nothing goes to disk,
and what the program wrote before its reply is always there (the report is
the same on every run). :meth:`SubprocessCandidate.take_stderr` returns what
was written since the last call.

(About 700 lines: one program's life cycle, its non-blocking pipes and its
protocol state are one state machine; :class:`ForkedChild` is the Popen
stand-in for callables run in a fork.)
"""

from __future__ import annotations

import atexit
import contextlib
import os
import selectors
import shlex
import signal
import subprocess
import sys
import time
from dataclasses import dataclass

import numpy as np

from . import protocol
from .candidate import CandidateError
from .forked_candidate import ForkedChild
from .processes import await_group_end, die_with_parent, kill_pipe_holders, pipe_ends

#: Default seconds a request may take (issue 15: a hang fails the case, not the run).
DEFAULT_TIMEOUT_S = 10.0
#: Start-up (until the program answers the header) gets at least this long: a
#: Python host imports numpy and the candidate, ~0.3 s alone, seconds on a loaded machine.
MIN_START_TIMEOUT_S = 10.0
#: Bytes of the program's stderr kept per case (the tail).
STDERR_KEEP = 64 * 1024
#: Read/write chunk, and the pipe size asked for (Linux F_SETPIPE_SZ; 64 KB otherwise).
_CHUNK = 1 << 20
#: Seconds a program gets to exit after its stdin is closed, before it is killed.
_EXIT_GRACE_S = 2.0
#: Seconds, at least, to collect the exit status of a program whose pipe ended (one that is exiting).
_REAP_MIN_S = 0.05


class CandidateStartRefused(CandidateError):
    """The program could not be started, or refused at start-up with ``{"error": ...}``: a usage error."""


@dataclass(frozen=True)
class SubprocessCandidate:
    """A projector program spoken to over stdin/stdout (the candidate protocol).

    Parameters
    ----------
    argv : tuple of str
        The command and its arguments (no shell).
    timeout_s : float
        Seconds each request may take.
    start_timeout_s : float or None
        Seconds until the program answers the header (default: the larger of
        ``timeout_s`` and ``MIN_START_TIMEOUT_S``).
    label : str
        The name in messages and the report.
    env : tuple of (str, str)
        Variables added to the program's environment.
    python_spec : str or None
        Set for a Python candidate run by :mod:`oracles.candidates.candidate_host`: its
        messages are then the in-process contract's, verbatim.
    forked : callable or None
        A Python callable no other process can import (a lambda, a closure):
        run in a forked copy of this process (POSIX) that serves the same
        protocol; ``argv`` is then only its label.
    """

    argv: tuple
    timeout_s: float = DEFAULT_TIMEOUT_S
    start_timeout_s: float | None = None
    label: str = ""
    env: tuple = ()
    python_spec: str | None = None
    forked: object = None

    def __post_init__(self):
        if not self.argv:
            raise ValueError("argv: expected a command")
        if not (self.timeout_s > 0 and np.isfinite(self.timeout_s)):
            raise ValueError(f"timeout_s {self.timeout_s!r}: expected a number of seconds > 0")

    @classmethod
    def from_command(cls, command: str, timeout_s: float = DEFAULT_TIMEOUT_S, **kwargs) -> SubprocessCandidate:
        """From a command line, split as a POSIX shell would (``shlex.split``), run without a shell."""
        try:
            argv = tuple(shlex.split(command))
        except ValueError as exc:
            raise ValueError(f"{command!r}: {exc}") from None
        if not argv:
            raise ValueError(f"{command!r}: expected a command")
        return cls(argv=argv, timeout_s=timeout_s, label=kwargs.pop("label", command), **kwargs)

    @classmethod
    def python(cls, spec: str, timeout_s: float = DEFAULT_TIMEOUT_S, pythonpath=(), **kwargs) -> SubprocessCandidate:
        """A ``FILE.py:FUNC`` / ``MODULE:FUNC`` candidate run isolated, by :mod:`oracles.candidates.candidate_host`.

        ``pythonpath``: folders the host puts first on ``sys.path`` (for a
        ``MODULE:FUNC`` importable only from the caller's path). ``unproject=True``: the spec is
        an unprojector, served for :meth:`unproject`.
        """
        env = (("WIRECHECK_HOST_PATH", os.pathsep.join(pythonpath)),) if pythonpath else ()
        mode = ("--unproject",) if kwargs.pop("unproject", False) else ()
        return cls(
            argv=(sys.executable, "-m", "wirecheck.oracles.candidates.candidate_host", *mode, spec),
            timeout_s=timeout_s,
            label=kwargs.pop("label", spec),
            env=env,
            python_spec=spec,
            **kwargs,
        )

    @classmethod
    def fork(cls, func, timeout_s: float = DEFAULT_TIMEOUT_S, label: str = "") -> SubprocessCandidate:
        """``func`` run in a forked child process (:class:`ForkedChild`); POSIX only."""
        return cls(
            argv=("<forked>",),
            timeout_s=timeout_s,
            label=label or repr(func),
            python_spec=label or repr(func),
            forked=func,
        )

    @property
    def name(self) -> str:
        return self.label or shlex.join(self.argv)

    def settings(self) -> dict:
        """For the report: how the candidate ran."""
        return {
            "isolation": "subprocess",
            "protocol": protocol.VERSION,
            "command": list(self.argv) if self.python_spec is None else None,
            "timeout_s": self.timeout_s,
        }

    def __call__(self, points, camera) -> np.ndarray:
        """The candidate contract: ``(N, 3)`` world points to ``(N, 2)`` pixels; CandidateError on any fault."""
        return _live(self).project(np.asarray(points, dtype=np.float64).reshape(-1, 3), camera)

    def unproject(self, pixels, depth, camera) -> np.ndarray:
        """The unprojector contract over the protocol (a request of kind ``unproject``): ``(N, 3)`` world points."""
        rows = np.column_stack(
            [np.asarray(pixels, dtype=np.float64).reshape(-1, 2), np.asarray(depth, dtype=np.float64).reshape(-1)]
        )
        return _live(self).project(rows, camera, kind="unproject")

    def answer_precision(self) -> str:
        """The precision the program's last reply declared (``"float64"`` when it said none; docs/protocol.md)."""
        program = _PROGRAMS.get(self)
        return program.precision if program else "float64"

    def start(self) -> None:
        """Start the program now (if not running); CandidateError (CandidateStartRefused) if it cannot."""
        _live(self).ensure_started()

    def take_stderr(self) -> str:
        """The program's stderr since the last call (its last STDERR_KEEP bytes), as text."""
        program = _PROGRAMS.get(self)
        return program.take_stderr() if program else ""

    def close(self) -> None:
        """Close the program (stdin closed, then killed after a grace period)."""
        program = _PROGRAMS.pop(self, None)
        if program:
            program.close()


#: The live programs of this process, by description.
_PROGRAMS: dict = {}


def _live(spec: SubprocessCandidate) -> _Program:
    program = _PROGRAMS.get(spec)
    if program is None:
        program = _PROGRAMS[spec] = _Program(spec)
    return program


@contextlib.contextmanager
def closing_started():
    """Close, when the block ends, every program started inside it: a run's candidates end with the run.

    A process that makes many runs (a test suite calling the API or ``cli.main``
    once per test, each with its own candidate) would otherwise keep an idle
    program per candidate until it exits. Programs live before the block are
    left running.
    """
    before = set(_PROGRAMS)
    try:
        yield
    finally:
        for spec in [s for s in _PROGRAMS if s not in before]:
            spec.close()


def close_all_but(keep=None) -> None:
    """Close every live program but ``keep``'s (a :class:`SubprocessCandidate`, or None: close all).

    A long-lived worker (a Dask cluster's) serves run after run: it keeps the
    program of the run it is serving, not an idle one per candidate it has served.
    """
    for spec in [s for s in _PROGRAMS if s != keep]:
        spec.close()


@atexit.register
def _close_all() -> None:
    for spec in list(_PROGRAMS):
        spec.close()


def _live_pipe_fds() -> list:
    """This process's ends of every live program's pipes: a fork closes them, or a program would never see
    EOF on its stdin while the fork lives (its close would wait out ``_EXIT_GRACE_S``, then kill it)."""
    return [
        f.fileno()
        for program in _PROGRAMS.values()
        if program.proc is not None
        for f in (program.proc.stdin, program.proc.stdout, program.proc.stderr)
        if not f.closed
    ]


class _Died(Exception):
    """The pipe ended: ``args[0]`` is which ("stdout": EOF on it; "stdin": the program stopped reading)."""


class _TimedOut(Exception):
    """The deadline passed: ``args[0]`` says how far the exchange got (:func:`_progress`)."""


def _progress(sent: int, total: int, got: int, end) -> str:
    """How far a timed-out request got, for its reason ('' when all was sent and nothing came back)."""
    if sent < total:
        return f" ({sent} of the request's {total} bytes had reached its stdin)"
    if got and end is None:
        return f" (its reply line had {got} bytes and no newline)"
    if got:
        return f" (its reply had {got} of {end} bytes)"
    return ""


def _status_text(returncode) -> str:
    if returncode is None:
        return "closed its stdout"
    if returncode < 0:
        try:
            return f"was killed by signal {signal.Signals(-returncode).name}"
        except ValueError:
            return f"was killed by signal {-returncode}"
    return f"exited with status {returncode}"


def _early(sent: int, total: int) -> str:
    """The reason for a reply (an error reply too) that came before the request was all written: the
    program would read the rest as its next request."""
    return (
        f"answered before reading the whole request ({sent} of {total} bytes had reached its stdin): "
        "expected the reply after the request"
    )


class _Program:
    """One running program and its protocol state."""

    def __init__(self, spec: SubprocessCandidate):
        self.spec = spec
        self.proc = None
        self.start_error = None  # sticky: (exception class, message)
        self.buf = bytearray()
        self.requests = 0
        self.camera = self.camera_json = None
        self.precision = "float64"  # what the last reply declared
        self.err = bytearray()  # the program's stderr not yet taken (its tail)
        self.err_cut = 0  # bytes dropped from its front since the last take

    # ---- life cycle

    def ensure_started(self) -> None:
        if self.start_error is not None:
            cls, message = self.start_error
            raise cls(message)
        if self.proc is not None:
            return
        try:
            self._start()
        except CandidateError as exc:
            self.start_error = (type(exc), str(exc))
            raise

    def _start(self) -> None:
        spec = self.spec
        env = dict(os.environ)
        env.update(dict(spec.env))
        try:
            if spec.forked is not None:
                proc = ForkedChild(spec.forked, _live_pipe_fds())
            else:
                proc = subprocess.Popen(
                    spec.argv,
                    stdin=subprocess.PIPE,
                    stdout=subprocess.PIPE,
                    stderr=subprocess.PIPE,
                    env=env,
                    start_new_session=True,
                    bufsize=0,
                    preexec_fn=die_with_parent,
                )
        except OSError as exc:
            raise CandidateStartRefused(f"cannot start {spec.argv[0]!r}: {exc.strerror or exc}") from None
        self.proc = proc
        self.buf = bytearray()
        for f in (proc.stdin, proc.stdout, proc.stderr):
            os.set_blocking(f.fileno(), False)
            try:
                import fcntl

                fcntl.fcntl(f.fileno(), fcntl.F_SETPIPE_SZ, _CHUNK)
            except (ImportError, AttributeError, OSError):
                pass  # a smaller pipe only costs speed
        limit = spec.start_timeout_s or max(spec.timeout_s, MIN_START_TIMEOUT_S)
        what = "at start-up, before answering the protocol header"
        try:
            end = self._exchange(
                protocol.HEADER,
                self._line_end,
                limit,
                f"candidate did not answer the protocol header within {limit:g} s (start-up); it was killed",
                what,
            )
            line = bytes(self.buf[:end])
            del self.buf[:end]
            protocol.check_hello(line)
        except protocol.CandidateReportedError as exc:
            self._kill()
            raise CandidateStartRefused(
                str(exc) if spec.python_spec else f"candidate refused to start: {exc}"
            ) from None
        except protocol.ProtocolError as exc:
            self._kill()
            raise CandidateError(f"candidate {exc}{self._stderr_hint()}") from None

    def close(self) -> None:
        proc, self.proc = self.proc, None
        if proc is not None:
            ends = pipe_ends(proc)
            try:
                proc.stdin.close()
            except OSError:
                pass
            try:
                proc.wait(timeout=_EXIT_GRACE_S)
            except subprocess.TimeoutExpired:
                pass
            # the program if it lingers, and what it started that still runs (a shell's child, a
            # helper): its group outlives a leader that exited (only a new session of its own escapes)
            self._killpg(proc)
            proc.wait()
            await_group_end(proc.pid)
            kill_pipe_holders(ends)
            self._drain_stderr(proc)
            proc.stdout.close()
            proc.stderr.close()

    @staticmethod
    def _killpg(proc) -> None:
        try:
            os.killpg(proc.pid, signal.SIGKILL)  # the program and anything it started
        except (ProcessLookupError, PermissionError):
            try:
                proc.kill()
            except ProcessLookupError:
                pass

    def _kill(self) -> None:
        proc, self.proc = self.proc, None
        if proc is None:
            return
        self._killpg(proc)
        proc.wait()
        await_group_end(proc.pid)
        kill_pipe_holders(pipe_ends(proc))
        self._drain_stderr(proc)  # all it wrote is in the pipe now
        for f in (proc.stdin, proc.stdout, proc.stderr):
            try:
                f.close()
            except OSError:
                pass

    def _reap(self, pipe: str, deadline: float) -> str:
        """After a pipe ended: the exit status in words, or (alive at ``deadline``) what it did, then killed.

        The wait counts against the request's own time (at least ``_REAP_MIN_S``,
        for a program that is exiting; at most ``_EXIT_GRACE_S``): a program that
        closes a pipe and lives on ends the request within its timeout, as a hang does.
        """
        proc = self.proc
        try:
            proc.wait(timeout=max(min(deadline - time.monotonic(), _EXIT_GRACE_S), _REAP_MIN_S))
        except subprocess.TimeoutExpired:
            self._kill()
            return f"closed its {pipe} but went on running (it was killed)"
        self._kill()  # closes the pipes; the group may hold children
        return _status_text(proc.returncode)

    # ---- requests

    def project(self, p_world: np.ndarray, camera, kind: str | None = None) -> np.ndarray:
        """One request: world points to pixels ``(N, 2)``; with ``kind="unproject"``, rows ``(x_px, y_px,
        depth)`` to world points ``(N, 3)``."""
        self.ensure_started()
        self.requests += 1
        n = len(p_world)
        columns = 3 if kind == "unproject" else 2
        if self.camera is not camera:  # a case asks with one camera object: its JSON is made once
            self.camera, self.camera_json = camera, protocol.camera_text(camera)
        payload = protocol.encode_request(self.requests, p_world, self.camera_json, kind)
        what = f"a request of {n} points"
        header = {}

        def reply_end(buf):
            if "end" not in header:
                line_end = self._line_end(buf)
                if line_end is None:
                    return None
                header["line"] = line_end
                header["end"] = line_end + protocol.reply_length(bytes(buf[:line_end]), n, columns)
                header["precision"] = protocol.reply_precision(bytes(buf[:line_end]))
            return header["end"]

        try:
            self._read_pending()
            if self.buf:
                raise protocol.ProtocolError(
                    f"wrote {len(self.buf)} bytes outside a reply: {protocol.shown(bytes(self.buf))}"
                )
            end = self._exchange(
                payload,
                reply_end,
                self.spec.timeout_s,
                f"candidate timed out after {self.spec.timeout_s:g} s on {what}{{progress}}; "
                "it was killed "
                "(and is started again for the next case)",
                f"during {what}",
            )
        except protocol.CandidateReportedError as exc:
            del self.buf[: header["line"]]
            if self.spec.python_spec:
                raise CandidateError(str(exc)) from None
            raise CandidateError(f"candidate reported an error: {exc}") from None
        except protocol.ProtocolError as exc:
            self._kill()
            raise CandidateError(f"candidate {exc} (on {what}); it was killed{self._stderr_hint()}") from None
        with memoryview(self.buf) as view:  # decoded straight from the buffer (one copy)
            p_px = protocol.decode_points(view[header["line"] : end], columns)
        del self.buf[:end]
        self.precision = header["precision"]
        return p_px

    def _exchange(self, payload: bytes, end_of, limit_s: float, timed_out: str, died_while: str) -> int:
        """:meth:`_transfer` within ``limit_s``; a hang (killed) or a death becomes one CandidateError."""
        deadline = time.monotonic() + limit_s
        try:
            return self._transfer(payload, end_of, deadline)
        except _TimedOut as exc:
            self._kill()
            raise CandidateError(f"{timed_out.format(progress=exc.args[0])}{self._stderr_hint()}") from None
        except _Died as exc:
            status = self._reap(exc.args[0], deadline)
            raise CandidateError(f"candidate {status} {died_while}{self._stderr_hint()}") from None

    def _line_end(self, buf) -> int | None:
        """Index just past the first newline, None if none yet; ProtocolError if the line is too long."""
        i = buf.find(b"\n", 0, protocol.MAX_LINE)
        if i >= 0:
            return i + 1
        if len(buf) >= protocol.MAX_LINE:
            raise protocol.ProtocolError(
                f"wrote {protocol.shown(bytes(buf))} with no newline in its first "
                f"{protocol.MAX_LINE} bytes: expected a JSON line"
            )
        return None

    def _transfer(self, payload: bytes, end_of, deadline: float) -> int:
        """Write ``payload`` while reading into ``self.buf`` until ``end_of(buf)`` bytes are there.

        Both directions at once (a program may answer while still reading);
        _TimedOut past ``deadline``, _Died on EOF or a closed stdin.
        """
        proc = self.proc
        w, r, e = proc.stdin.fileno(), proc.stdout.fileno(), proc.stderr.fileno()
        view = memoryview(payload)
        sent = 0
        sel = selectors.DefaultSelector()
        try:
            if payload:
                sel.register(w, selectors.EVENT_WRITE)
            sel.register(r, selectors.EVENT_READ)
            sel.register(e, selectors.EVENT_READ)
            while True:
                try:
                    end = end_of(self.buf)
                except protocol.CandidateReportedError:
                    if sent < len(payload):
                        raise protocol.ProtocolError(_early(sent, len(payload))) from None
                    raise
                if end is not None and len(self.buf) >= end:
                    if sent < len(payload):  # its answer cannot depend on bytes it never got
                        raise protocol.ProtocolError(_early(sent, len(payload)))
                    self._drain_stderr(proc)  # what it wrote before replying
                    return end
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    raise _TimedOut(_progress(sent, len(payload), len(self.buf), end))
                for key, _ in sel.select(remaining):
                    if key.fd == e:
                        if not self._drain_stderr(proc):
                            sel.unregister(e)  # closed: the program may live on without it
                    elif key.fd == w:
                        try:
                            sent += os.write(w, view[sent : sent + _CHUNK])
                        except BlockingIOError:
                            continue
                        except (BrokenPipeError, ConnectionResetError):
                            raise _Died("stdin") from None
                        if sent == len(payload):
                            sel.unregister(w)
                    else:
                        try:
                            chunk = os.read(r, _CHUNK)
                        except BlockingIOError:
                            continue
                        if not chunk:
                            raise _Died("stdout")
                        self.buf += chunk
        finally:
            sel.close()

    def _read_pending(self) -> None:
        """Read into ``self.buf`` what the program wrote since its last reply (nothing, if it keeps to the
        protocol): bytes sent ahead of a request are then named as such, not taken as its reply."""
        try:
            chunk = os.read(self.proc.stdout.fileno(), protocol.MAX_LINE)
        except (BlockingIOError, OSError):
            return
        self.buf += chunk  # b"" (EOF) too: the exchange then finds it

    # ---- stderr

    def _drain_stderr(self, proc) -> bool:
        """Read what the program's stderr pipe holds into the kept tail; False once it is closed."""
        fd = proc.stderr.fileno()
        while True:
            try:
                chunk = os.read(fd, _CHUNK)
            except BlockingIOError:
                return True
            except OSError:
                return False
            if not chunk:
                return False
            self.err += chunk
            extra = len(self.err) - STDERR_KEEP
            if extra > 0:
                del self.err[:extra]
                self.err_cut += extra

    def take_stderr(self) -> str:
        if self.proc is not None:
            self._drain_stderr(self.proc)
        text = (f"[... {self.err_cut} bytes before]\n" if self.err_cut else "") + self.err.decode("utf-8", "replace")
        self.err, self.err_cut = bytearray(), 0
        return text

    def _stderr_hint(self) -> str:
        """'; its stderr ends: "..."' from the last non-empty line of the program's stderr, if any."""
        lines = [ln.strip() for ln in self.err[-4096:].decode("utf-8", "replace").splitlines() if ln.strip()]
        return f"; its stderr ends: {lines[-1][:300]!r}" if lines else ""
