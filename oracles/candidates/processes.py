"""The processes a candidate program leaves: its group, the holders of its pipes, and the child that
dies with its parent (Linux, through /proc and prctl).

A candidate program may start children (a shell's background job, a helper it
spawned) that hold its pipes, or leave its process group with ``setsid``.
Closing a program (oracles.candidates.subprocess_candidate) kills its group and every
process still holding one of its pipes, found through ``/proc/*/fd``, and
waits at most :data:`GROUP_END_S` for them to be gone. A daemon that closed
its pipes and left its group is out of reach, as documented (docs/protocol.md).
"""

from __future__ import annotations

import contextlib
import os
import signal
import time

#: Seconds a killed program's group gets to be gone (a SIGKILL ends a process in milliseconds).
GROUP_END_S = 1.0


def die_with_parent() -> None:
    """In the child, before exec: SIGKILL when crosscheck's process ends (Linux), so no hung program outlives a
    killed run. Elsewhere a program still sees EOF on stdin when crosscheck ends."""
    try:
        import ctypes

        ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        pass


def await_group_end(pgid: int) -> None:
    """Return once no process of group ``pgid`` (killed) runs, or after ``GROUP_END_S``.

    A SIGKILL is delivered asynchronously: without this, a program's own child
    could still be running when the call that ended it returns. A member that
    has ended but is not this process's child is left to its new parent (init)
    to reap; where there is no ``/proc``, this returns at once.
    """
    deadline = time.monotonic() + GROUP_END_S
    while time.monotonic() < deadline:
        try:
            os.killpg(pgid, 0)
        except (ProcessLookupError, PermissionError):
            return  # no member at all: the usual case, at the cost of one call
        if not groupruns(pgid):
            return
        time.sleep(0.001)


def pipe_ends(proc) -> dict:
    """``{pipe inode: access mode}`` of the program's ends of its three pipes (read stdin, write stdout, stderr)."""
    try:
        return {
            os.fstat(proc.stdin.fileno()).st_ino: os.O_RDONLY,
            os.fstat(proc.stdout.fileno()).st_ino: os.O_WRONLY,
            os.fstat(proc.stderr.fileno()).st_ino: os.O_WRONLY,
        }
    except (OSError, ValueError):
        return {}


def kill_pipe_holders(ends: dict) -> None:
    """SIGKILL every other process that ``/proc`` shows holding one of the program's pipe ends ``ends``.

    A process the program started in a session of its own (``setsid``, a
    daemon) escapes its process group, but while it holds the program's stdout
    or stdin it is still the program's, and it would outlive the run. (A process
    that closed them is out of reach; this process's own ends, and a fork of
    it that inherited them, are the other direction and are left alone.)
    """
    if not ends:
        return
    try:
        names = os.listdir("/proc")
    except OSError:
        return
    me, held = os.getpid(), []
    for name in names:
        if not name.isdigit() or int(name) == me:
            continue
        try:
            for fd in os.listdir(f"/proc/{name}/fd"):
                link = os.readlink(f"/proc/{name}/fd/{fd}")
                if not link.startswith("pipe:["):
                    continue
                mode = ends.get(int(link[6:-1]))
                if mode is None:
                    continue
                with open(f"/proc/{name}/fdinfo/{fd}") as fh:
                    flags = next(int(ln.split()[1], 8) for ln in fh if ln.startswith("flags:"))
                if flags & os.O_ACCMODE == mode:
                    held.append(int(name))
                    break
        except (OSError, ValueError, StopIteration):
            continue
    for pid in held:
        with contextlib.suppress(ProcessLookupError, PermissionError):
            os.kill(pid, signal.SIGKILL)
    deadline = time.monotonic() + GROUP_END_S
    while held and time.monotonic() < deadline:
        held = [pid for pid in held if runs(pid)]
        time.sleep(0.001)


def running_group(pid) -> int | None:
    """The process group of ``pid`` if ``/proc`` shows it running (not a zombie), else None."""
    try:
        with open(f"/proc/{pid}/stat", "rb") as fh:
            state, _ppid, pgrp = fh.read().rsplit(b")", 1)[1].split()[:3]
        return None if state == b"Z" else int(pgrp)
    except (OSError, ValueError):
        return None


def runs(pid: int) -> bool:
    """Whether ``/proc`` shows ``pid`` running (not a zombie)."""
    return running_group(pid) is not None


def groupruns(pgid: int) -> bool:
    """Whether ``/proc`` shows a process of group ``pgid`` that is not a zombie (False without ``/proc``)."""
    try:
        names = os.listdir("/proc")
    except OSError:
        return False
    return any(name.isdigit() and running_group(name) == pgid for name in names)
