"""Issue 36, item 5: one run owns its target from its start to its end.

Before: crosscheck took the report folder's lock only to write it, so run A (3,000 frames) started first and
run B (1 frame) started 3 s later both exited 0: B wrote its report, then A silently replaced it. Now the
folder is claimed when the run starts (core.outputs.output.claim): a second run into it exits 2 at once with
one line naming the holder's pid, and the first run's report is the one in place. The renderer's ``--out``
is held from its start by core.outputs.staging (checked here as well).
"""

import json
import os
import subprocess
import sys
import time

import pytest
from wirecheck.core.outputs.staging import LOCK

CROSSCHECK = [sys.executable, "-m", "wirecheck.oracles.cli"]


def _wait_for(path, proc, seconds=60):
    deadline = time.monotonic() + seconds
    while not os.path.lexists(path) and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.02)
    return os.path.lexists(path)


def _second_run_refused(long_cmd, short_cmd, lock):
    """Start ``long_cmd``; once it holds ``lock`` (or after 3 s, as the issue's try), run ``short_cmd``."""
    first = subprocess.Popen(long_cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    try:
        _wait_for(lock, first, seconds=3)
        t0 = time.monotonic()
        second = subprocess.run(short_cmd, capture_output=True, text=True, timeout=120)
        second_s = time.monotonic() - t0
        still_running = first.poll() is None
        first_err = first.communicate(timeout=300)[1].decode()
    finally:
        if first.poll() is None:
            first.kill()
            first.wait()
    return first.returncode, first_err, second, second_s, still_running, first.pid


@pytest.mark.slow
@pytest.mark.parametrize("command", ["report", "export"])
def test_second_run_into_a_held_target_exits_2_at_once(tmp_path, command):
    target = tmp_path / "t"
    if command == "report":
        base = [
            *CROSSCHECK,
            "--report-dir",
            str(target),
            "--scene",
            "cube",
            "--cases",
            "on_axis",
            "--oracles",
            "opencv",
        ]
        long_cmd, short_cmd = [*base, "--frames", "3000"], [*base, "--frames", "1"]
    else:
        base = [*CROSSCHECK, "export", str(target), "--cases", "on_axis,oblique_roll"]
        long_cmd, short_cmd = [*base, "--frames", "600"], [*base, "--scene", "cube", "--frames", "1"]
    rc_a, err_a, b, b_s, a_running, pid_a = _second_run_refused(long_cmd, short_cmd, tmp_path / ".t.wirecheck-lock")
    assert b.returncode == 2 and b.stderr.count("\n") == 1, b.stderr
    assert f"being written by another wirecheck run (process {pid_a})" in b.stderr, b.stderr
    assert a_running, "run A ended before run B was refused: the test proves nothing"
    assert rc_a == 0, err_a
    if command == "report":
        report = json.loads((target / "report.json").read_text())
        assert report["frames"] == 3000  # A's report, never B's
    else:
        job = json.loads((target / "job.json").read_text())
        assert max(len(c["frames"]) for c in job["cases"]) == 600
    assert sorted(os.listdir(tmp_path)) == ["t"]  # no lock, no temporaries


@pytest.mark.slow
def test_second_renderer_into_a_held_out_exits_2_at_once(tmp_path):
    out = tmp_path / "out"
    base = [sys.executable, "-m", "wirecheck.core.app.cli", "--width", "64", "--height", "48", "--out", str(out)]
    rc_a, err_a, b, b_s, a_running, pid_a = _second_run_refused(
        [*base, "--frames", "1500"], [*base, "--frames", "1"], out / LOCK
    )
    assert b.returncode == 2 and f"(process {pid_a})" in b.stderr and b.stderr.count("\n") == 1, b.stderr
    assert a_running
    assert rc_a == 0, err_a
    assert json.loads((out / "cube-report.json").read_text())["summary"]["frames"] == 1500


@pytest.mark.slow
def test_claim_is_held_until_release_and_creates_no_folder_for_a_failed_run(tmp_path):
    """In process: a claimed report folder refuses a second claimer; released, its created parents go."""
    from wirecheck.core.errors import InputError
    from wirecheck.core.outputs.output import claim, release_claim

    target = tmp_path / "a" / "b" / "report"
    claim(target, "--report-dir")
    try:
        assert sorted(os.listdir(tmp_path / "a" / "b")) == [".report.wirecheck-lock"]
        other = subprocess.run(
            [
                *CROSSCHECK,
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
            ],
            capture_output=True,
            text=True,
            timeout=120,
        )
        assert other.returncode == 2 and f"(process {os.getpid()})" in other.stderr, other.stderr
    finally:
        release_claim(target)
    assert os.listdir(tmp_path) == []  # the parents it made are gone with it
    with pytest.raises(InputError):  # the claim checks the target as before
        (tmp_path / "r").mkdir()
        (tmp_path / "r" / "mine.txt").write_text("x")
        claim(tmp_path / "r", "--report-dir")
    assert sorted(os.listdir(tmp_path)) == ["r"]
