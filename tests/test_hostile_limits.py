"""Limits and late errors (issue 25, items 7 and 9): every limit a usage error before work starts, and an
error about an output found before any output is written.

Each test failed before its fix: exit 3 with a traceback in a log, or exit 2 after the report folder was
written, or a whole job built in memory before its target was looked at.
"""

from __future__ import annotations

import json
import os
import shutil
import time

import helpers  # tests/ is on sys.path (rootdir conftest)
import pytest
from wirecheck.core.limits import MAX_CANDIDATE_TIMEOUT_S as MAX_TIMEOUT_S
from wirecheck.core.limits import MAX_FRAMES
from wirecheck.oracles import cli as crosscheck_cli


def one_line(rc, err, *needles):
    assert rc == 2, err
    assert err.count("\n") == 1 and err.startswith("crosscheck: error: ") and "Traceback" not in err, err
    for n in needles:
        assert n in err, (n, err)


VERTICES = ["--scene", "cube", "--cases", "on_axis", "--frames", "1", "--level", "vertices"]


@pytest.mark.parametrize("seconds", ["3e6", "86400.5", "1e308"])
def test_a_candidate_timeout_past_a_day_is_a_usage_error(tmp_path, capsys, seconds):
    """Before: exit 3, OverflowError ('timeout is too large') from poll, whose millisecond timeout is a C int."""
    rc = crosscheck_cli.main(
        [*VERTICES, "--report-dir", str(tmp_path / "r"), "--candidate-cmd", "true", "--candidate-timeout", seconds]
    )
    one_line(rc, capsys.readouterr().err, "--candidate-timeout", "at most 86400")
    assert not (tmp_path / "r").exists()


def test_the_largest_timeout_is_accepted():
    # the bound itself: 86400 s = 86,400,000 ms, under the C int poll takes (2^31 - 1 = 2,147,483,647 ms)
    assert MAX_TIMEOUT_S * 1000 < 2**31 - 1


def test_a_candidate_timeout_past_a_day_in_pyproject(tmp_path, capsys, monkeypatch):
    (tmp_path / "pyproject.toml").write_text("[tool.wirecheck]\ncandidate-timeout = 3e6\n")
    monkeypatch.chdir(tmp_path)
    rc = crosscheck_cli.main([*VERTICES, "--report-dir", str(tmp_path / "r")])
    one_line(
        rc, capsys.readouterr().err, "pyproject.toml: [tool.wirecheck] candidate-timeout = 3000000.0", "at most 86400"
    )
    assert not (tmp_path / "r").exists()


@pytest.mark.parametrize("frames", [str(MAX_FRAMES + 1), "9" * 30, "0"])
def test_export_frames_past_the_limit_are_a_usage_error(tmp_path, capsys, frames):
    """Before: 10^29 gave exit 3 (OverflowError in range), 100,001 built the whole job (no limit)."""
    rc = crosscheck_cli.main(["export", str(tmp_path / "job"), "--frames", frames])
    one_line(rc, capsys.readouterr().err, f"--frames {frames}", f"1..{MAX_FRAMES:,}")
    assert os.listdir(tmp_path) == []


def test_export_frames_that_are_not_an_integer(tmp_path, capsys):
    with pytest.raises(SystemExit) as info:
        crosscheck_cli.main(["export", str(tmp_path / "job"), "--frames", "2.2e29"])
    assert info.value.code == 2 and "--frames" in capsys.readouterr().err
    assert os.listdir(tmp_path) == []


def test_export_looks_at_its_target_before_building(tmp_path, capsys):
    """A refused target is refused at once: 100,000 frames of every scene would take minutes to build.
    The bound: the refusal with 100,000 frames takes under 10 x that of 1 frame plus 1 s (a build of the
    job is linear in the frames: 10^5 times one frame's work, minutes)."""
    target = tmp_path / "job"
    target.mkdir()
    (target / "notes.md").write_text("the user's")

    def refuse(frames):
        t0 = time.perf_counter()
        rc = crosscheck_cli.main(["export", str(target), "--frames", str(frames)])
        one_line(rc, capsys.readouterr().err, str(target), "not written by wirecheck")
        return time.perf_counter() - t0

    small = refuse(1)
    assert refuse(MAX_FRAMES) < 10 * small + 1.0
    assert (target / "notes.md").read_text() == "the user's" and os.listdir(target) == ["notes.md"]


def _unwritable(tmp_path):
    """A folder no file can be created in, even by root (os.access says yes to root): /proc, else a chmod."""
    if os.geteuid() == 0:
        return "/proc"
    d = tmp_path / "ro"
    d.mkdir()
    d.chmod(0o555)
    return str(d)


def test_junit_into_an_unwritable_folder_is_found_before_the_report(tmp_path, capsys):
    """Before: the report folder was written, then writing the XML failed (exit 2 with output)."""
    folder = _unwritable(tmp_path)
    rc = crosscheck_cli.main([*VERTICES, "--report-dir", str(tmp_path / "r"), "--junit-xml", f"{folder}/j.xml"])
    one_line(rc, capsys.readouterr().err, f"--junit-xml '{folder}/j.xml'", "is not writable")
    assert not (tmp_path / "r").exists() and not os.path.exists(f"{folder}/j.xml")


@pytest.mark.parametrize(
    "key, value",
    [("candidate-cmd", '"echo a\\u0000b"'), ("scenes", '["cu\\u0000be"]'), ("candidate", '"x.py:f\\u0000"')],
)
def test_a_nul_in_a_config_value_is_one_line(tmp_path, capsys, monkeypatch, key, value):
    """Before (candidate-cmd): exit 3, ValueError 'embedded null byte' when the command was started."""
    (tmp_path / "pyproject.toml").write_text(f"[tool.wirecheck]\n{key} = {value}\n")
    monkeypatch.chdir(tmp_path)
    rc = crosscheck_cli.main(["--frames", "1", "--level", "vertices", "--report-dir", str(tmp_path / "r")])
    one_line(rc, capsys.readouterr().err, f"[tool.wirecheck] {key} = ", "NUL")
    assert not (tmp_path / "r").exists()


@pytest.mark.parametrize("scene", [["cube"], {"name": "cube"}])
def test_an_unhashable_scene_in_job_json_is_one_line(tmp_path, capsys, scene):
    """Before: exit 3, TypeError 'unhashable type: list' testing the case's scene against the job's scenes."""
    job = helpers.blank_job(tmp_path / "job")
    data = json.loads((job / "job.json").read_text())
    data["cases"][0]["scene"] = scene
    (job / "job.json").write_text(json.dumps(data))
    rc = crosscheck_cli.main(["--candidate-frames", str(job), "--report-dir", str(tmp_path / "r")])
    one_line(rc, capsys.readouterr().err, "job.json: case ", "expected a scene of 'scenes'")
    assert not (tmp_path / "r").exists()
    shutil.rmtree(job)


def test_the_api_timeout_has_the_same_limit():
    """check_projector(timeout_s=3e6) reached the same poll as the CLI: OverflowError in the middle of a run."""
    from wirecheck.oracles.api import check_projector

    with pytest.raises(
        ValueError,
        match=r"timeout_s 3000000.0: expected a finite number of seconds > 0 and at "
        r"most 86400 \(one day\)",
    ):
        check_projector(cmd="true", timeout_s=3e6)
