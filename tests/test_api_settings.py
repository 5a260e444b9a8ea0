"""check_projector / assert_projector read [tool.wirecheck] as crosscheck does, and every result
says first what was compared (level, frames, cases): the API's defaults (vertices, 8 frames)
are not crosscheck's (pixels, 24 frames), and a reader must see which were used."""

import re
import subprocess
import sys
import time
from pathlib import Path

import pytest
from wirecheck import assert_projector, check_projector

ROOT = Path(__file__).resolve().parent.parent
GOOD = str(ROOT / "tests" / "data" / "user_projector.py") + ":project"
MIRRORED = str(ROOT / "tests" / "data" / "faulty_projectors.py") + ":mirrored"


@pytest.fixture
def project(tmp_path, monkeypatch):
    (tmp_path / "pyproject.toml").write_text(
        '[tool.wirecheck]\nscenes = ["cube"]\ncases = ["on_axis"]\nframes = 2\n', encoding="utf-8"
    )
    sub = tmp_path / "tests"
    sub.mkdir()
    monkeypatch.chdir(sub)  # the nearest pyproject.toml at or above the working directory
    return tmp_path


def _cases(report):
    return [(c["scene"], c["camera"]) for c in report["cases"]]


def test_the_table_chooses_scenes_cases_and_frames(project):
    report = check_projector(GOOD)
    assert _cases(report) == [("cube", "on_axis")] and report["frames"] == 2
    assert report["compared"]["frames"] == 2  # 1 case x 2 frames


def test_a_keyword_wins_over_the_table(project):
    report = check_projector(GOOD, frames=3, cases=["near_plane"])
    assert _cases(report) == [("cube", "near_plane")] and report["frames"] == 3


def test_config_false_ignores_the_table(project):
    report = check_projector(GOOD, config=False, scenes=["cube"], frames=1)
    assert len(report["cases"]) == 7  # the seven default case cameras, not the table's one


def test_a_bad_table_is_a_value_error_naming_the_file(project):
    (project / "pyproject.toml").write_text("[tool.wirecheck]\nframe = 2\n", encoding="utf-8")
    with pytest.raises(ValueError, match=r"pyproject\.toml.*unknown key 'frame'"):
        check_projector(GOOD)


def test_the_failure_starts_with_what_was_compared(project):
    with pytest.raises(AssertionError) as info:
        assert_projector(MIRRORED)
    first, second = str(info.value).splitlines()[:2]
    assert first == "Compared: level vertices (OpenCV), 2 frames per case, 1 case (1 scene x 1 camera)"
    assert second.startswith("1 of 1 crosscheck cases failed")


def test_pytest_shows_the_callers_line_not_wirecheck_source(project):
    (project / "tests" / "test_p.py").write_text(
        f"from wirecheck import assert_projector\n\ndef test_p():\n    assert_projector({MIRRORED!r})\n",
        encoding="utf-8",
    )
    done = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "test_p.py"],
        cwd=project / "tests",
        capture_output=True,
        text=True,
        timeout=180,
    )
    assert done.returncode == 1
    assert ">       assert_projector(" in done.stdout  # the test's own line
    assert "check_projector(func, **kwargs)" not in done.stdout  # wirecheck's frame hidden
    assert "E       AssertionError: Compared: level vertices (OpenCV), 2 frames per case" in done.stdout


def test_cli_says_what_it_compared_and_each_hint_once(tmp_path):
    started = time.monotonic()
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "wirecheck.oracles.cli",
            "--candidate",
            MIRRORED,
            "--scene",
            "cube",
            "--cases",
            "on_axis,oblique_roll",
            "--level",
            "vertices",
            "--frames",
            "2",
            "--report-dir",
            str(tmp_path / "r"),
        ],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=180,
    )
    assert done.returncode == 1, done.stderr
    lines = done.stdout.splitlines()
    assert lines[0] == "Compared: level vertices (OpenCV), 2 frames per case, 2 cases (1 scene x 2 cameras)"
    hints = [line for line in lines if line.startswith("  what to check, ")]
    assert len(hints) == 1 and hints[0].startswith("  what to check, mirror_horizontal: left and right")
    # the wall time printed counts the process from its start: more than the cases' own wall (imports
    # alone take > 0.1 s), less than this test measured around the whole subprocess
    m = re.search(r"\(1 job\(s\), ([\d.]+) s wall; ([\d.]+) s in all, with start-up and the report\)", done.stdout)
    assert m, done.stdout
    cases_wall, in_all = float(m.group(1)), float(m.group(2))
    assert cases_wall + 0.1 < in_all <= time.monotonic() - started + 0.05  # 0.05: the one-decimal rounding


def test_the_returned_report_has_the_fields_of_report_json(tmp_path):
    # docs/pytest.md: check_projector "returns the report (the fields of report.json)"; the same
    # run from the command line writes the report.json it is compared with
    from helpers import run_crosscheck

    settings = ("--scene", "cube", "--cases", "on_axis", "--frames", "1", "--level", "vertices")
    code, written, _ = run_crosscheck(tmp_path, "--candidate", GOOD, *settings)
    report = check_projector(GOOD, scenes=["cube"], cases=["on_axis"], frames=1, config=False)
    assert code == 0 and report["verdict"] == "pass"
    assert list(report) == list(written) and report["run"] is None
