"""Issue 36, item 2: a lock is verified, never trusted by its name.

Before: a file named ``<out>/.wirecheck-lock`` or ``.NAME.wirecheck-lock`` was opened, written in place
("wirecheck lock pid N") and deleted: through a hard link the write landed in a user's file elsewhere; a FIFO
hung ``renderer`` forever and gave crosscheck "[Errno 29] Illegal seek". Now (core.outputs.lockfile) a file
found there is opened with O_NOFOLLOW | O_NONBLOCK and taken for a lock only when it is a regular file with
one link and wirecheck's content; anything else is one line, exit 2, naming the file and how to clear it,
and is left exactly as it was. Every run is a subprocess with a timeout: a hang fails, never blocks pytest.
"""

import os
import socket
import subprocess
import sys

import pytest
from wirecheck.core.outputs.staging import LOCK

RENDER = [sys.executable, "-m", "wirecheck.core.app.cli", "--width", "32", "--height", "24", "--frames", "1"]
CROSSCHECK = [sys.executable, "-m", "wirecheck.oracles.cli"]
USERS = b"the user's own file, elsewhere\n"


def _plant(path, kind, elsewhere):
    """A ``kind`` of file at ``path``; ``elsewhere`` is a user's file outside every output folder."""
    if kind == "empty":
        path.write_bytes(b"")
    elif kind == "hard_link":
        os.link(elsewhere, path)
    elif kind == "symlink":
        os.symlink(elsewhere, path)
    elif kind == "fifo":
        os.mkfifo(path)
    elif kind == "directory":
        path.mkdir()
        (path / "inside").write_bytes(b"x")
    elif kind == "foreign":
        path.write_bytes(b"my notes\n")
    elif kind == "huge":
        with open(path, "wb") as fh:
            fh.truncate(8 << 20)
    elif kind == "socket":
        sock = socket.socket(socket.AF_UNIX)
        sock.bind(str(path))
        return sock
    return None


def _state(path):
    st = os.lstat(path)
    data = None
    if os.path.isfile(path) and not os.path.islink(path):
        with open(path, "rb") as fh:
            data = fh.read(64)
    return st.st_mode, st.st_ino, st.st_nlink, st.st_size, data


KINDS = ["empty", "hard_link", "symlink", "fifo", "directory", "foreign", "huge", "socket"]


def _target(tmp_path, command):
    """(argv, lock path) of one run of ``command`` whose lock is planted."""
    if command == "renderer":
        out = tmp_path / "out"
        out.mkdir()
        return [*RENDER, "--out", str(out)], out / LOCK
    if command == "report":
        return (
            [
                *CROSSCHECK,
                "--report-dir",
                str(tmp_path / "r"),
                "--scene",
                "cube",
                "--cases",
                "on_axis",
                "--oracles",
                "opencv",
                "--frames",
                "1",
            ],
            tmp_path / ".r.wirecheck-lock",
        )
    return [
        *CROSSCHECK,
        "export",
        str(tmp_path / "j"),
        "--scene",
        "cube",
        "--cases",
        "on_axis",
        "--frames",
        "1",
    ], tmp_path / ".j.wirecheck-lock"


def _check_refused(tmp_path, command, kind):
    user = tmp_path / "thesis.tex"
    user.write_bytes(USERS)
    argv, lock = _target(tmp_path, command)
    sock = _plant(lock, kind, user)
    try:
        before = _state(lock)
        run = subprocess.run(argv, capture_output=True, text=True, timeout=60)
        assert run.returncode == 2, (kind, run.returncode, run.stderr)
        assert run.stderr.count("\n") == 1 and "Traceback" not in run.stderr, run.stderr
        assert str(lock) in run.stderr and "remove or rename it" in run.stderr, run.stderr
        assert _state(lock) == before  # not written, not removed, not replaced
        assert user.read_bytes() == USERS  # nothing written through a link
        outputs = [n for n in os.listdir(lock.parent) if n not in (lock.name, "thesis.tex", "out")]
        assert outputs == [], outputs  # nothing else written
    finally:
        if sock is not None:
            sock.close()


@pytest.mark.parametrize("kind", KINDS)
def test_renderer_refuses_a_planted_lock(tmp_path, kind):
    _check_refused(tmp_path, "renderer", kind)


@pytest.mark.slow
@pytest.mark.parametrize("command", ["report", "export"])
@pytest.mark.parametrize("kind", ["empty", "hard_link", "fifo", "directory"])
def test_crosscheck_refuses_a_planted_lock(tmp_path, command, kind):
    _check_refused(tmp_path, command, kind)


@pytest.mark.slow
@pytest.mark.parametrize("command", ["report", "export"])
def test_a_stale_lock_of_a_dead_process_blocks_nothing(tmp_path, command):
    """A lock of ours whose process is gone (flock released by the kernel): the run takes it, and leaves none."""
    dead = subprocess.Popen(["true"])
    dead.wait()
    argv, lock = _target(tmp_path, command)
    lock.write_text(f"wirecheck lock pid {dead.pid}\n")
    run = subprocess.run(argv, capture_output=True, text=True, timeout=60)
    assert run.returncode == 0, run.stderr
    assert not os.path.lexists(lock)


def test_lock_file_is_never_seen_without_its_content(tmp_path):
    """A lock is born whole (written, locked, then renamed into place): the file at the lock's name holds
    "wirecheck lock pid N" from its first moment, and it is gone after release."""
    from wirecheck.core.outputs.lockfile import Lock, holder

    path = tmp_path / LOCK
    lock = Lock(path, "--out", str(tmp_path))
    try:
        assert path.read_bytes() == f"wirecheck lock pid {os.getpid()}\n".encode()
        assert os.stat(path).st_nlink == 1
        assert holder(path) == f"process {os.getpid()}"
        assert sorted(os.listdir(tmp_path)) == [LOCK]  # no temporary left beside it
    finally:
        lock.release()
    assert os.listdir(tmp_path) == []


def test_release_never_removes_a_file_put_in_the_locks_place(tmp_path):
    """The holder removes the file at the lock's name only while it is the one it holds."""
    from wirecheck.core.outputs.lockfile import Lock

    path = tmp_path / LOCK
    lock = Lock(path, "--out", str(tmp_path))
    os.rename(path, tmp_path / "moved")
    path.write_bytes(b"the user's")
    lock.release()
    assert path.read_bytes() == b"the user's"
