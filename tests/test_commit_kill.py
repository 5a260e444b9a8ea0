"""A commit killed (SIGKILL) after each of its renames: the next run repairs or replaces, never wedges.

core.outputs.owned counts the renames of a commit and, with WIRECHECK_KILL_AFTER_RENAME=k, the process sends
itself SIGKILL right after the k-th. For every k of a commit, in a subprocess over an earlier set: the
killed run leaves the old set, the new set or a journal; the next plain run exits 0 with a consistent
set (every listed hash true, the report's frame count = the PNGs); a user's file beside the outputs is
the same bytes throughout.
"""

import json
import os
import signal
import subprocess
import sys

import pytest
from wirecheck.core.app import cli as renderer_cli
from wirecheck.core.outputs.owned import MARKER, foreign, sha256
from wirecheck.core.outputs.staging import JOURNAL, LOCK, MANIFEST
from wirecheck.oracles import cli as crosscheck_cli

OPTIONS = ["--width", "32", "--height", "24", "--format", "png,gif"]
RENDER = [sys.executable, "-m", "wirecheck.core.app.cli", *OPTIONS]


def _render(frames, out):
    """A plain run, in this process (no kill: the variable is not set here)."""
    assert "WIRECHECK_KILL_AFTER_RENAME" not in os.environ
    return renderer_cli.main([*OPTIONS, "--frames", str(frames), "--out", str(out)])


def _run(cmd, kill_at=None):
    env = dict(os.environ)
    env.pop("WIRECHECK_KILL_AFTER_RENAME", None)
    if kill_at is not None:
        env["WIRECHECK_KILL_AFTER_RENAME"] = str(kill_at)
    return subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=120)


def _renderer_set(out):
    """The frames the report says, the PNGs there, and whether every recorded hash is true."""
    report = json.loads((out / "cube-report.json").read_text())
    pngs = sorted(p.name for p in (out / "cube-frames").iterdir() if p.suffix == ".png")
    manifest = json.loads((out / MANIFEST).read_text())["files"]
    hashes_true = all(sha256(out / n) == h for n, h in manifest.items()) and foreign(out / "cube-frames") is None
    return report["summary"]["frames"], len(pngs), hashes_true


# Renames of this commit over an earlier set, counted by hand from core/outputs/staging.py (rule 5): the journal
# (1); cube-frames/, cube.gif, cube-report.json, cube-report.txt (2 each: the old one aside, the new one in); the
# manifest (1).
RENDERER_RENAMES = 10


def test_renderer_commit_killed_after_every_rename(tmp_path):
    out = tmp_path / "out"
    frames = 3
    assert _render(frames, out) == 0
    (out / "notes.txt").write_text("the user's")
    inconsistent = 0
    for k in range(1, RENDERER_RENAMES + 2):
        old, frames = frames, 5 - frames  # 3 frames, then 2, then 3, ...: each run changes the set
        killed = _run([*RENDER, "--frames", str(frames), "--out", str(out)], kill_at=k)
        if k <= RENDERER_RENAMES:
            assert killed.returncode == -signal.SIGKILL, (k, killed.stderr)
            state = _renderer_set(out) if not (out / JOURNAL).exists() else "journal"
            # the old set, the new one, or a journal the next run finishes
            assert state in ((old, old, True), (frames, frames, True), "journal"), (k, state)
        else:
            assert killed.returncode == 0, killed.stderr  # k past the last rename: the commit is whole
        assert (out / "notes.txt").read_text() == "the user's"
        assert _render(frames, out) == 0, k
        inconsistent += _renderer_set(out) != (frames, frames, True)
        leftovers = sorted(n for n in os.listdir(out) if n.endswith(".tmp") or n in (JOURNAL, LOCK))
        assert leftovers == [], (k, leftovers)
    assert inconsistent == 0
    assert (out / "notes.txt").read_text() == "the user's"


def _tree(folder):
    return sorted(
        (str(p.relative_to(folder)), p.is_file() and p.read_bytes()) for p in folder.rglob("*") if p.name != MARKER
    )


@pytest.mark.parametrize("command", ["report", "export"])
def test_report_and_job_commit_killed_at_its_one_rename(tmp_path, capsys, command):
    """A report folder or an export job is swapped in by one rename (renameat2 exchange): killed right after
    it, the new folder is in place; the old one, left beside it, is removed by the next run."""
    target = tmp_path / "t"
    if command == "report":
        args = ["--report-dir", str(target), "--scene", "cube", "--cases", "on_axis", "--oracles", "opencv"]
    else:
        args = ["export", str(target), "--scene", "cube", "--cases", "on_axis"]
    assert crosscheck_cli.main([*args, "--frames", "1"]) == 0
    killed = _run([sys.executable, "-m", "wirecheck.oracles.cli", *args, "--frames", "2"], kill_at=1)
    assert killed.returncode == -signal.SIGKILL, killed.stderr
    assert foreign(target) is None  # a whole folder of ours in place
    leftover = [n for n in os.listdir(tmp_path) if n != "t"]
    assert len(leftover) == 2  # the old folder and the lock file, both hidden
    after_kill = _tree(target)
    assert crosscheck_cli.main([*args, "--frames", "2"]) == 0, capsys.readouterr().err
    assert os.listdir(tmp_path) == ["t"]  # the killed run's temporaries removed
    if command == "export":
        assert _tree(target) == after_kill  # the killed run had put the new job in place whole


# Renames of a report folder's or an export job's commit, counted by hand from core/outputs/output.py
# (FrameDir.commit): a first run moves its folder in (1, RENAME_NOREPLACE); a rerun swaps it with the old one
# (1, RENAME_EXCHANGE), then removes the old one by its listing (no rename unless a user's file is kept).
FRAMEDIR_RENAMES = 1


@pytest.mark.slow
@pytest.mark.parametrize("command", ["report", "export"])
@pytest.mark.parametrize("earlier", [False, True], ids=["first_run", "rerun"])
def test_crosscheck_and_export_killed_after_every_rename(tmp_path, capsys, command, earlier):
    """Issue 36: kill -9 of crosscheck and crosscheck export after each rename of the commit, on a first run
    and on a rerun, then a plain rerun: a whole folder of ours in place with the rerun's contents, no
    temporaries, no lock, and a user's file beside it the same bytes throughout."""
    target = tmp_path / "t"
    if command == "report":
        args = ["--report-dir", str(target), "--scene", "cube", "--cases", "on_axis", "--oracles", "opencv"]
    else:
        args = ["export", str(target), "--scene", "cube", "--cases", "on_axis"]
    (tmp_path / "notes.txt").write_text("the user's")
    for k in range(1, FRAMEDIR_RENAMES + 2):
        if earlier:
            assert crosscheck_cli.main([*args, "--frames", "1"]) == 0
        killed = _run([sys.executable, "-m", "wirecheck.oracles.cli", *args, "--frames", "2"], kill_at=k)
        if k <= FRAMEDIR_RENAMES:
            assert killed.returncode == -signal.SIGKILL, (k, killed.stderr)
        else:
            assert killed.returncode == 0, killed.stderr
        assert foreign(target) is None  # the old folder or the new one, whole
        capsys.readouterr()
        assert crosscheck_cli.main([*args, "--frames", "3"]) == 0, (k, capsys.readouterr().err)
        assert foreign(target) is None
        if command == "report":
            assert json.loads((target / "report.json").read_text())["frames"] == 3
        else:
            assert {len(c["frames"]) for c in json.loads((target / "job.json").read_text())["cases"]} == {3}
        assert sorted(os.listdir(tmp_path)) == ["notes.txt", "t"], (k, os.listdir(tmp_path))
        assert (tmp_path / "notes.txt").read_text() == "the user's"
        if not earlier:
            for entry in os.listdir(tmp_path):
                if entry == "t":
                    os.rename(tmp_path / "t", tmp_path / f"gone{k}")  # the next try starts without a folder
                    os.rename(tmp_path / f"gone{k}", tmp_path / ".." / f"{tmp_path.name}-gone{k}")
