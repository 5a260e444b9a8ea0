"""The frames judge reads frames ahead on one GL thread (oracles.candidates.frame_prefetch): the same errors at the
same frame, the same reports, and no thread left behind.

A PNG whose pixels cannot be decoded is read on the worker while the judge
scores the frames before it: the error must still surface when the judge
reaches that frame (the frames before it judged, none after), with the
message a full check of the job gives (check_frames with decoding: what the
judge raised before it read ahead), exit 2 with those lines and no report.
"""

from __future__ import annotations

import shutil
import threading
from pathlib import Path

import pytest
from helpers import fill_job  # tests/ is on sys.path (rootdir conftest)
from wirecheck.oracles.candidates import frame_prefetch
from wirecheck.oracles.candidates.frames_candidate import FramesError, check_frames, load_job
from wirecheck.oracles.cli import main
from wirecheck.oracles.judge import frames_judge
from wirecheck.oracles.judge.frames_judge import run_frames

# one case of 6 frames: frame 4 is read ahead (frame_prefetch.AHEAD = 2) while frames 2 and 3 are judged
ARGS = ["--scene", "cube", "--cases", "on_axis", "--frames", "6"]
BAD = "frames/cube/on_axis/frame_0004.png"


@pytest.fixture(scope="module")
def filled(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("job") / "job"
    assert main(["export", str(path)] + ARGS) == 0
    fill_job(path)
    return path


@pytest.fixture
def damaged(filled, tmp_path) -> Path:
    """The job with frame 4's first IDAT bytes zeroed: its header and size are right, its pixels undecodable."""
    d = tmp_path / "job"
    shutil.copytree(filled, d)
    data = bytearray((d / BAD).read_bytes())
    at = data.index(b"IDAT") + 4 + 2  # past the zlib header
    data[at : at + 16] = bytes(16)
    (d / BAD).write_bytes(bytes(data))
    return d


def _workers() -> list:
    return [t for t in threading.enumerate() if t.name.startswith("wirecheck-frames")]


def _count_judged(monkeypatch) -> list:
    """The frames whose candidate pixels the judge computed (frames_judge.candidate_pixels' calls), in order."""
    judged, real = [], frames_judge.candidate_pixels

    def counted(path, *args, **kwargs):
        judged.append(Path(path).name)
        return real(path, *args, **kwargs)

    monkeypatch.setattr(frames_judge, "candidate_pixels", counted)
    return judged


def test_an_undecodable_frame_read_ahead_raises_at_its_own_frame_with_the_full_checks_message(damaged, monkeypatch):
    # the expected message: the full check's (every frame decoded), independent of the judge and its thread
    with pytest.raises(FramesError) as full:
        check_frames(damaged, load_job(damaged), decode=True)
    assert "frame_0004.png: unreadable as PNG" in str(full.value)
    judged = _count_judged(monkeypatch)
    with pytest.raises(FramesError) as got:
        run_frames(damaged, diagnose=False)
    assert str(got.value) == str(full.value)
    assert got.value.problems == full.value.problems
    # frames 1-3 judged, then the error: not earlier (when it was read ahead), not later
    assert judged == ["frame_0001.png", "frame_0002.png", "frame_0003.png"]
    assert _workers() == []


def test_the_cli_says_it_in_the_same_lines_exit_2_and_writes_nothing(damaged, tmp_path, capsys):
    with pytest.raises(FramesError) as full:
        check_frames(damaged, load_job(damaged), decode=True)
    rc = main(["--candidate-frames", str(damaged), "--report-dir", str(tmp_path / "rep")])
    err = capsys.readouterr().err
    assert rc == 2
    assert "Traceback" not in err
    assert err.strip().splitlines() == [f"crosscheck: error: {p}" for p in full.value.problems]
    assert len(full.value.problems) == 1
    assert not (tmp_path / "rep").exists()
    assert _workers() == []


def test_an_interrupt_in_the_judges_thread_stops_the_worker(filled, monkeypatch):
    """Ctrl-C while frame 2 is scored (frames 3 and 4 read ahead): KeyboardInterrupt comes out, no thread stays."""
    real, calls = frames_judge.candidate_pixels, []

    def interrupted(*args, **kwargs):
        calls.append(1)
        if len(calls) == 2:
            raise KeyboardInterrupt
        return real(*args, **kwargs)

    monkeypatch.setattr(frames_judge, "candidate_pixels", interrupted)
    closed = []
    real_close = frame_prefetch.FramePrefetch.close

    def close(self):
        real_close(self)
        closed.append(self.oracles._by_size == {})  # every context released

    monkeypatch.setattr(frame_prefetch.FramePrefetch, "close", close)
    with pytest.raises(KeyboardInterrupt):
        run_frames(filled, diagnose=False)
    assert len(calls) == 2 and closed == [True]
    assert _workers() == []


def test_reading_ahead_gives_the_report_of_reading_in_turn(filled, monkeypatch):
    """The same report (timing aside) whether the frames are read on the worker or in the judge's thread."""
    ahead, _ = run_frames(filled)
    monkeypatch.setattr(frames_judge, "FramePrefetch", lambda: frame_prefetch.FramePrefetch(threaded=False))
    in_turn, _ = run_frames(filled)
    for report in (ahead, in_turn):
        del report["timing"]
    assert ahead == in_turn
    assert ahead["compared"]["frames"] == 6 and ahead["verdict"] == "pass"


@pytest.mark.parametrize("ahead", [1, 2])
def test_frames_are_asked_for_ahead_frames_beyond_the_one_judged(monkeypatch, ahead):
    """While frame k is judged, the worker has been given frames 1 .. k + ahead (the last ones of the case: up
    to its end) and no more: ``ahead`` frames overlap the judge's work, and memory stays flat."""
    asked = []

    def read(oracles, job_dir, job, c, k, rel, cache):  # the worker's reading, recorded in its order
        asked.append(k)
        return k

    monkeypatch.setattr(frame_prefetch, "read_ahead", read)

    class Oracles:
        def close(self):
            pass

    reader = frame_prefetch.FramePrefetch(Oracles(), threaded=True, ahead=ahead)
    try:
        got, seen = [], []
        for k in reader.frames("job", {}, {"frames": [f"f{i}.png" for i in range(1, 7)]}, [1, 2, 3, 4, 5, 6]):
            reader.call(lambda: None)  # first in, first out: every frame asked for before it has been read
            got.append(k)
            seen.append(list(asked))
        assert got == [1, 2, 3, 4, 5, 6]
        assert seen == [list(range(1, min(k + ahead, 6) + 1)) for k in got]
    finally:
        reader.close()
    assert _workers() == []


@pytest.fixture(scope="module")
def filled_depth(tmp_path_factory) -> Path:
    """A job of filled frames and depth maps (ARGS' 6 frames), drawn by core's depth client."""
    from clients.core_depth_job import render_job

    path = tmp_path_factory.mktemp("fd") / "job"
    assert main(["export", str(path)] + ARGS + ["--outputs", "filled,depth"]) == 0
    render_job(path)
    return path


@pytest.mark.parametrize("threaded", [True, False])
def test_a_reference_made_ahead_is_raised_at_its_own_frame(filled_depth, threaded):
    """The judge's ``reference`` (a filled frame's silhouette) runs on the worker after the frame's drawing of its
    faces; what it raises is kept with that frame and raised when the judge asks for it there, the frames
    around it untouched."""
    job = load_job(filled_depth)
    case = job["cases"][0]
    made = []

    def reference(inputs, faces):  # the worker's calls, in frame order: the third one fails
        made.append(len(made) + 1)
        if len(made) == 3:
            raise ValueError("third frame")
        return len(made), inputs[2].width, faces[0].shape

    reader = frame_prefetch.FramePrefetch(threaded=threaded)
    try:
        got = []
        for i, frame in enumerate(reader.frames(filled_depth, job, case, job["frame_numbers"], reference)):
            assert frame.faces()[0].shape == (case["height"], case["width"])
            if i == 2:
                with pytest.raises(ValueError, match="third frame"):
                    frame.reference()
            else:
                got.append(frame.reference())
    finally:
        reader.close()
    assert [g[0] for g in got] == [1, 2, 4, 5, 6]
    assert {g[1:] for g in got} == {(case["width"], (case["height"], case["width"]))}
    assert _workers() == []


def test_filled_frames_judged_ahead_give_the_report_of_reading_in_turn(filled_depth, monkeypatch):
    """The silhouettes made on the worker (with pyrender's ids as their hint) give the report (timing aside) of
    reading every frame in the judge's thread."""
    ahead, _ = run_frames(filled_depth)
    monkeypatch.setattr(frames_judge, "FramePrefetch", lambda: frame_prefetch.FramePrefetch(threaded=False))
    in_turn, _ = run_frames(filled_depth)
    for report in (ahead, in_turn):
        del report["timing"]
    assert ahead == in_turn
    (case,) = ahead["cases"]
    assert case["filled"]["frames"] == 6 and case["filled"]["reference_px"] > 0 and ahead["verdict"] == "pass"
