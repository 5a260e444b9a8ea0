"""crosscheck --no-report: the table and the verdict, no report folder (issue 26, rough edge 6)."""

import os
import xml.etree.ElementTree as ET

import pytest
from wirecheck.oracles import cli

#: A fast run: one scene, one camera, two frames, OpenCV only.
QUICK = ("--scene", "cube", "--frames", "2", "--cases", "on_axis", "--level", "vertices")


def _listing(folder):
    """Every path under ``folder``, relative: what a run wrote there."""
    return sorted(
        os.path.relpath(os.path.join(d, n), folder) for d, dirs, files in os.walk(folder) for n in dirs + files
    )


@pytest.mark.parametrize(
    "extra, status",
    [
        ((), 0),
        # tol 0: core's float64 error on the cube is ~6e-14 px > 0, a fail
        (("--tol-px", "0"), 1),
    ],
)
def test_no_report_writes_nothing_and_keeps_the_exit_status(tmp_path, monkeypatch, capsys, extra, status):
    (tmp_path / "mine.txt").write_text("a user's file\n")
    monkeypatch.chdir(tmp_path)
    before = _listing(tmp_path)
    assert cli.main([*QUICK, *extra, "--no-report"]) == status
    assert _listing(tmp_path) == before  # no reports/, nothing else
    out = capsys.readouterr().out.splitlines()
    assert out[-1] == "Report: none written (--no-report)"
    assert any(line.startswith(("PASS:", "FAIL:")) for line in out) and out[1].split()[:2] == ["scene", "camera"]


def test_the_default_folder_says_how_to_turn_it_off(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert cli.main(list(QUICK)) == 0
    runs = list((tmp_path / "reports").iterdir())
    assert len(runs) == 1 and (runs[0] / "report.json").is_file()
    assert capsys.readouterr().out.splitlines()[-1] == (
        f"Report: reports/{runs[0].name}/report.json (also report.md, report.html; --no-report writes none)"
    )


def test_a_chosen_folder_is_not_told_about_no_report(tmp_path, capsys):
    assert cli.main([*QUICK, "--report-dir", str(tmp_path / "r")]) == 0
    assert capsys.readouterr().out.splitlines()[-1] == (
        f"Report: {tmp_path / 'r' / 'report.json'} (also report.md, report.html)"
    )


def test_no_report_still_writes_the_junit_file(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert cli.main([*QUICK, "--no-report", "--junit-xml", "j.xml"]) == 0
    assert _listing(tmp_path) == ["j.xml"]
    cases = ET.parse(tmp_path / "j.xml").getroot().iter("testcase")
    assert [(c.get("classname"), c.get("name")) for c in cases] == [("cube", "on_axis")]


@pytest.mark.parametrize(
    "clash, named",
    [
        (("--report-dir", "r"), "--report-dir"),
        (("--run", "x"), "--run"),
        (("--sweep",), "--sweep"),
        (("--suite", "extremes"), "--suite"),
        (("--run", "x", "--report-dir", "r"), "--report-dir, --run"),
    ],
)
def test_no_report_with_a_report_option_is_one_line_exit_2(tmp_path, monkeypatch, capsys, clash, named):
    monkeypatch.chdir(tmp_path)
    assert cli.main([*QUICK, "--no-report", *clash]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err == (
        f"crosscheck: error: --no-report with {named}: --no-report writes no report folder; "
        "expected one or the other (--junit-xml is still written with --no-report)\n"
    )
    assert _listing(tmp_path) == []


@pytest.mark.parametrize(
    "drawn, status",
    [
        (True, 0),  # core's frames: a correct renderer
        (False, 1),
    ],
)  # black frames: nothing drawn, a fail
def test_no_report_judges_a_frames_job_and_writes_only_the_junit_file(tmp_path, monkeypatch, capsys, drawn, status):
    """A CI gate on a renderer's frames wants the exit status alone: the job is judged, its table and verdict
    printed, and nothing written but ``--junit-xml`` (the job's own files untouched)."""
    import helpers

    job = helpers.blank_job(tmp_path / "job")
    if drawn:
        helpers.fill_job(job)
    monkeypatch.chdir(tmp_path)
    before = _listing(tmp_path)
    capsys.readouterr()
    assert cli.main(["--candidate-frames", "job", "--no-report", "--junit-xml", "j.xml"]) == status
    assert _listing(tmp_path) == sorted(before + ["j.xml"])
    out = capsys.readouterr().out.splitlines()
    assert out[-1] == "Report: none written (--no-report)"
    assert any(line.startswith("PASS:" if drawn else "FAIL:") for line in out)
    failures = [c for c in ET.parse(tmp_path / "j.xml").getroot().iter("testcase") if c.find("failure") is not None]
    assert len(failures) == (0 if drawn else 1)
