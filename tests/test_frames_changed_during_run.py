"""Frames that change while ``crosscheck --candidate-frames`` runs: one line, exit 2, no report, never a hang.

The job's frames are checked (files, headers) before the judging begins, and each frame's pixels
are decoded later, as it is judged: a renderer still writing, or a script swapping files, can change
a frame in between. Each test makes that change between the check and the decoding.
"""

from __future__ import annotations

import os

import helpers  # tests/ is on sys.path (rootdir conftest)
import pytest
from helpers import no_block
from PIL import Image
from wirecheck.oracles import cli as crosscheck_cli
from wirecheck.oracles.candidates import frames_candidate
from wirecheck.oracles.candidates.png_frame import FrameProblem, check_png, read_grey

FRAME = "frames/cube/on_axis/frame_0003.png"


class Blocked(BaseException):
    """Raised by :func:`hang_guard`: a BaseException, so that no ``except Exception`` of the run takes it
    for a frame's problem (helpers.no_block's TimeoutError would be read as one, after the wait)."""


def hang_guard(seconds):
    return no_block(seconds, Blocked)


def test_reading_a_fifo_named_like_a_frame_never_blocks(tmp_path):
    """Before: read_grey opened the path and waited for a writer forever (the check before it was by name)."""
    fifo = tmp_path / "f.png"
    os.mkfifo(fifo)
    for read in (read_grey, check_png):
        with no_block(), pytest.raises(FrameProblem, match="^a FIFO, not a regular file$"):
            read(fifo, 4, 4)


def test_a_folder_or_device_named_like_a_frame_is_named(tmp_path):
    (tmp_path / "d.png").mkdir()
    with pytest.raises(FrameProblem, match="^a folder, not a regular file$"):
        read_grey(tmp_path / "d.png", 4, 4)
    with no_block(), pytest.raises(FrameProblem, match="^a character device, not a regular file$"):
        read_grey("/dev/zero", 4, 4)


@pytest.fixture
def job(tmp_path):
    return helpers.blank_job(tmp_path / "job")


def _swap_after_check(monkeypatch, job, swap):
    """Run ``swap(path of FRAME)`` right after the judge's first check of the job (decode=False)."""
    real = frames_candidate.check_frames

    def check_then_swap(job_dir, job_dict, decode=True):
        real(job_dir, job_dict, decode)
        if not decode:
            swap(job / FRAME)

    monkeypatch.setattr(frames_candidate, "check_frames", check_then_swap)


@pytest.mark.parametrize(
    "swap, needle",
    [
        (lambda p: (p.unlink(), os.mkfifo(p)), "a FIFO, not a regular file (frame 3 of cube / on_axis)"),
        (lambda p: p.write_bytes(p.read_bytes()[:60]), "truncated"),
        (lambda p: Image.new("L", (64, 48)).save(p), "size 64x48: expected 640x480 (the camera's)"),
    ],
)
def test_a_frame_changed_after_the_check_is_one_line(job, tmp_path, capsys, monkeypatch, swap, needle):
    """Before (the FIFO): the run blocked forever in the decoding's open()."""
    _swap_after_check(monkeypatch, job, swap)
    with hang_guard(120):  # the judging of the job's first frame takes a few seconds
        rc = crosscheck_cli.main(["--candidate-frames", str(job), "--report-dir", str(tmp_path / "r")])
    err = capsys.readouterr().err
    assert rc == 2 and err.count("\n") == 1 and err.startswith(f"crosscheck: error: {job / FRAME}: "), err
    assert needle in err and "Traceback" not in err
    assert not (tmp_path / "r").exists()
