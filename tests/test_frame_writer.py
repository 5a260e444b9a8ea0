"""core.outputs.frame_writer: PNG frames written by a forked child are the in-line encoder's bytes; errors reach the parent."""

from __future__ import annotations

import errno
import os
import subprocess
import sys

import numpy as np
import pytest
from wirecheck.core.outputs.frame_writer import ForkedPngWriter
from wirecheck.core.outputs.output import MARKER, is_bilevel, png_bytes

pytestmark = pytest.mark.skipif(not hasattr(os, "fork"), reason="needs os.fork")


def _images() -> list[np.ndarray]:
    """Bilevel frames (even and odd widths, one empty), an 8-bit grey one and an RGB one."""
    rng = np.random.default_rng(7)
    out = [rng.choice(np.array([0, 255], np.uint8), size=shape) for shape in [(48, 64), (5, 13), (1, 1), (0, 0)]]
    out.append(rng.integers(0, 256, size=(9, 11), dtype=np.uint8))  # aa-like grey: Pillow, in the parent
    out.append(rng.integers(0, 256, size=(6, 7, 3), dtype=np.uint8))  # RGB (--axes)
    return out


def test_files_are_the_in_line_encoders_bytes(tmp_path):
    images = _images()
    assert [is_bilevel(im) for im in images] == [True] * 4 + [False] * 2  # both paths are taken
    with ForkedPngWriter() as writer:
        for k, im in enumerate(images):
            writer.put(tmp_path / f"frame_{k}.png", im)
    for k, im in enumerate(images):
        assert (tmp_path / f"frame_{k}.png").read_bytes() == png_bytes(im), k


def test_a_write_error_in_the_child_is_raised_in_the_parent_as_the_same_oserror(tmp_path):
    missing = tmp_path / "missing" / "frame_1.png"
    with pytest.raises(FileNotFoundError) as caught:
        with ForkedPngWriter() as writer:
            writer.put(missing, np.zeros((8, 8), np.uint8))
    assert caught.value.errno == errno.ENOENT and caught.value.filename == str(missing)


def test_leaving_on_an_error_waits_for_the_child_and_keeps_the_callers_error(tmp_path):
    with pytest.raises(KeyError):
        with ForkedPngWriter() as writer:
            writer.put(tmp_path / "a.png", np.zeros((8, 8), np.uint8))
            pid = writer._pid
            raise KeyError("the caller's")
    with pytest.raises(ChildProcessError):  # reaped: no zombie left behind
        os.waitpid(pid, os.WNOHANG)
    assert (tmp_path / "a.png").read_bytes() == png_bytes(np.zeros((8, 8), np.uint8))  # queued before: written


def test_no_fork_with_other_threads_few_frames_or_one_cpu():
    """In a fresh interpreter (this one may hold other threads: pytest-xdist's)."""
    code = (
        "import os, threading\n"
        "from wirecheck.core.outputs.frame_writer import MIN_FRAMES, can_fork\n"
        "alone = can_fork(MIN_FRAMES), can_fork(MIN_FRAMES - 1)\n"
        "stop = threading.Event(); t = threading.Thread(target=stop.wait); t.start()\n"
        "threaded = can_fork(10_000)\n"
        "stop.set(); t.join()\n"
        "print(*alone, threaded, len(os.sched_getaffinity(0)) >= 2)\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    at_min, below_min, threaded, two_cpus = done.stdout.split()
    assert (at_min, below_min, threaded) == (two_cpus, "False", "False")


@pytest.mark.skipif(len(os.sched_getaffinity(0)) < 2, reason="one CPU: frames are written in line")
def test_renderer_frames_from_the_child_equal_the_in_line_ones(tmp_path):
    """The seed command's path (frames >= MIN_FRAMES, two CPUs) against --profile's (always in line)."""

    def frames(out, *extra):
        cmd = [
            sys.executable,
            "-m",
            "wirecheck.core.app.cli",
            "--frames",
            "40",
            "--fov",
            "70",
            "--out",
            str(out),
            *extra,
        ]
        assert subprocess.run(cmd, capture_output=True).returncode == 0
        d = out / "cube-frames"
        return {n: (d / n).read_bytes() for n in sorted(os.listdir(d)) if n != MARKER}

    forked, in_line = frames(tmp_path / "a"), frames(tmp_path / "b", "--profile")
    assert len(forked) == 40 and forked == in_line
