"""Issue 36, item 1: a file the user writes into an output folder while a rerun commits is never removed.

A rerun checks ownership, then hashes its new frames, swaps the new folder in and removes the old one. A
note written into ``out/cube-frames/`` after the check (while the frames are hashed) was deleted with the
old folder, exit 0, nothing said. Now the old outputs are removed after the swap, by their hashes
(core.outputs.owned.retire): what the user wrote meanwhile is moved into the folder in place, or kept where
it is, and the run says so in one line and exits 2.

``WIRECHECK_PAUSE_AT_STEP=k`` + ``WIRECHECK_PAUSE_FILE`` (core.outputs.owned.step) stop a commit at its k-th
step (the check, then each rename) until the test has written into the folder; every step is tried.
"""

import os
import subprocess
import sys
import time

import pytest
from wirecheck.core.app import cli as renderer_cli
from wirecheck.core.outputs import owned
from wirecheck.core.outputs.owned import MARKER
from wirecheck.core.outputs.staging import JOURNAL, LOCK
from wirecheck.oracles import cli as crosscheck_cli

OPTIONS = ["--width", "32", "--height", "24", "--format", "png"]
NOTE = b"the user's note, written during the commit\n"


def _env(**extra):
    env = {k: v for k, v in os.environ.items() if not k.startswith("WIRECHECK_")}
    env.update(extra)
    return env


def _paused_run(cmd, step, pause_file, act):
    """Run ``cmd`` paused at commit step ``step``; ``act()`` while it waits. Whether it paused, rc, stderr."""
    proc = subprocess.Popen(
        cmd,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        env=_env(WIRECHECK_PAUSE_AT_STEP=str(step), WIRECHECK_PAUSE_FILE=str(pause_file)),
    )
    paused = False
    deadline = time.monotonic() + 120
    while proc.poll() is None and time.monotonic() < deadline:
        if pause_file.exists():
            act()
            paused = True
            pause_file.unlink()
            break
        time.sleep(0.01)
    err = proc.communicate(timeout=120)[1].decode()
    return paused, proc.returncode, err


def _write_note(folder):
    """What a user does: ``mkdir -p folder && echo ... > folder/note.txt``."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "note.txt").write_bytes(NOTE)


def _assert_one_line(err):
    assert err.count("\n") == 1 and "Traceback" not in err, err


# Steps of a renderer rerun over an earlier png set, counted by hand from core/outputs/staging.py: the check (1),
# the journal (2), cube-frames/ aside and in (3, 4), cube-report.json (5, 6), cube-report.txt (7, 8), the
# manifest (9).
RENDERER_STEPS = 9


@pytest.mark.slow
def test_renderer_note_written_at_every_step_of_the_commit_is_kept(tmp_path):
    out = tmp_path / "out"
    frames_dir = out / "cube-frames"
    cmd = [sys.executable, "-m", "wirecheck.core.app.cli", *OPTIONS, "--out", str(out)]
    steps, outcomes = 0, {}
    for step in range(1, RENDERER_STEPS + 3):
        assert subprocess.run([*cmd, "--frames", "2"], env=_env(), capture_output=True).returncode == 0
        paused, rc, err = _paused_run(
            [*cmd, "--frames", "3"], step, tmp_path / "pause", lambda: _write_note(frames_dir)
        )
        if not paused:
            assert rc == 0, err  # past the last step: a plain run
            break
        steps += 1
        assert (frames_dir / "note.txt").read_bytes() == NOTE, (step, err)  # never removed, where it was put
        if rc == 2:
            _assert_one_line(err)
            assert "note.txt" in err or "appeared" in err, err
        else:
            assert rc == 0 and err == "", (step, err)  # written into the new folder: nothing to remove
        if os.path.exists(out / JOURNAL):  # the folder was put where the new one goes: the commit waits
            assert rc == 2 and "appeared" in err, err
            os.rename(frames_dir, tmp_path / "moved-away")
            assert subprocess.run([*cmd, "--frames", "3"], env=_env(), capture_output=True).returncode == 0
            assert (tmp_path / "moved-away" / "note.txt").read_bytes() == NOTE
        else:
            pngs = sorted(n for n in os.listdir(frames_dir) if n.endswith(".png"))
            assert pngs == ["frame_0001.png", "frame_0002.png", "frame_0003.png"], (step, pngs)  # the new set
            os.unlink(frames_dir / "note.txt")  # the user moves it away; the next step starts clean
        outcomes[step] = rc
        assert sorted(n for n in os.listdir(out) if n.endswith(".tmp") or n in (LOCK, JOURNAL)) == [], step
    assert steps == RENDERER_STEPS, outcomes
    # written into the old folder (after the check, before the swap): kept in the new one, said, exit 2
    assert outcomes[1] == outcomes[2] == 2, outcomes
    assert outcomes[RENDERER_STEPS] == 0, outcomes  # written into the new folder: nothing to say


@pytest.mark.slow
@pytest.mark.parametrize("command", ["report", "export"])
def test_report_and_job_note_written_at_every_step_is_kept(tmp_path, command):
    target = tmp_path / "t"
    if command == "report":
        args = ["--report-dir", str(target), "--scene", "cube", "--cases", "on_axis", "--oracles", "opencv"]
    else:
        args = ["export", str(target), "--scene", "cube", "--cases", "on_axis"]
    cmd = [sys.executable, "-m", "wirecheck.oracles.cli", *args]
    outcomes = {}
    for step in (1, 2, 3):  # the check (1), the exchange (2); 3: past the last step
        assert subprocess.run([*cmd, "--frames", "1"], env=_env(), capture_output=True).returncode == 0
        paused, rc, err = _paused_run([*cmd, "--frames", "2"], step, tmp_path / "pause", lambda: _write_note(target))
        if not paused:
            assert step == 3 and rc == 0, err
            break
        assert (target / "note.txt").read_bytes() == NOTE, (step, err)
        if rc == 2:
            _assert_one_line(err)
            assert "note.txt" in err and "kept" in err, err
        assert owned.listing(target) is not None and "note.txt" not in owned.listing(target)[0]  # the new folder
        outcomes[step] = rc
        os.unlink(target / "note.txt")
        assert sorted(os.listdir(tmp_path)) == ["t"], os.listdir(tmp_path)  # no temporaries, no lock
    assert outcomes == {1: 2, 2: 0}


def test_note_written_while_the_frames_are_hashed_is_kept(tmp_path, capsys, monkeypatch):
    """The issue's own timing, without the pause hook: the note lands while the new frames are sealed."""
    out = tmp_path / "out"
    assert renderer_cli.main([*OPTIONS, "--frames", "2", "--out", str(out)]) == 0
    seal = owned.seal

    def seal_and_write(folder):
        _write_note(out / "cube-frames")  # the user, while wirecheck hashes its new frames
        seal(folder)

    monkeypatch.setattr(owned, "seal", seal_and_write)
    capsys.readouterr()
    rc = renderer_cli.main([*OPTIONS, "--frames", "3", "--out", str(out)])
    err = capsys.readouterr().err
    assert (out / "cube-frames" / "note.txt").read_bytes() == NOTE
    assert rc == 2 and err.count("\n") == 1 and "note.txt" in err and "kept" in err, err
    assert (out / "cube-frames" / "frame_0003.png").is_file()  # the new set is in place, whole
    assert owned.foreign(out / "cube-frames") == "note.txt (a file not written by wirecheck)"


def test_frame_edited_during_the_commit_is_kept_beside_the_new_one(tmp_path, capsys, monkeypatch):
    out = tmp_path / "out"
    assert renderer_cli.main([*OPTIONS, "--frames", "2", "--out", str(out)]) == 0
    seal = owned.seal

    def seal_and_edit(folder):
        (out / "cube-frames" / "frame_0001.png").write_bytes(b"edited by the user")
        seal(folder)

    monkeypatch.setattr(owned, "seal", seal_and_edit)
    capsys.readouterr()
    rc = renderer_cli.main([*OPTIONS, "--frames", "3", "--out", str(out)])
    err = capsys.readouterr().err
    assert rc == 2 and "frame_0001.png.kept" in err, err
    assert (out / "cube-frames" / "frame_0001.png.kept").read_bytes() == b"edited by the user"
    assert (out / "cube-frames" / "frame_0001.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"  # the new frame


@pytest.mark.slow
def test_report_note_written_while_sealing_is_kept(tmp_path, capsys, monkeypatch):
    target = tmp_path / "r"
    args = [
        "--report-dir",
        str(target),
        "--scene",
        "cube",
        "--cases",
        "on_axis",
        "--oracles",
        "opencv",
        "--frames",
        "1",
    ]
    assert crosscheck_cli.main(args) == 0
    seal = owned.seal

    def seal_and_write(folder):
        _write_note(target)
        seal(folder)

    monkeypatch.setattr(owned, "seal", seal_and_write)
    capsys.readouterr()
    rc = crosscheck_cli.main(args)
    err = capsys.readouterr().err
    assert (target / "note.txt").read_bytes() == NOTE
    assert rc == 2 and err.count("\n") == 1 and "note.txt" in err, err
    assert (target / MARKER).is_file() and (target / "report.json").is_file()
    assert sorted(os.listdir(tmp_path)) == ["r"]
