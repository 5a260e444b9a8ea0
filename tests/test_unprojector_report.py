"""The unprojector's report folder (oracles.reports.unprojector_report): ``crosscheck --unprojector``'s
``--report-dir`` / ``--run`` / ``--no-report`` and ``check_unprojector(report_dir=...)``.

What the folder holds is checked against the report the check returned (its numbers read back from
report.json, each fault kind's hint from the catalogue); two runs of the same inputs give the same bytes
but for report.json's ``"timing"``; a folder or file wirecheck did not write is refused with one line
and left as it was. (A user's file, folder, link or edit inside an earlier report folder of ours:
tests/test_output_safety.py, kind ``unprojector_report``.)
"""

from __future__ import annotations

import json
import os
import stat
import sys
from pathlib import Path

import pytest
from wirecheck import assert_unprojector, check_unprojector
from wirecheck.core.errors import InputError
from wirecheck.core.outputs.output import MARKER
from wirecheck.oracles import cli as crosscheck_cli
from wirecheck.oracles.faults import CATALOGUE

sys.path.insert(0, str(Path(__file__).parent / "data"))
import unprojectors as U  # noqa: E402

SPEC = str(Path(__file__).parent / "data" / "unprojectors.py")
#: One scene, two cameras, one frame: a run of about a second.
SMALL = ["--scene", "cube", "--cases", "on_axis,wide_fov", "--frames", "1"]


def _run(*args) -> int:
    return crosscheck_cli.main(["--unprojector", f"{SPEC}:horizontal_fov", *SMALL, *args])


def _files(folder: Path) -> dict:
    """Every path under ``folder`` (the listing file too) with its bytes; None for a folder, "fifo" for a
    FIFO (never opened: a read would wait for a writer)."""
    out = {}
    for d, ds, fs in os.walk(folder):
        for n in ds + fs:
            p = os.path.join(d, n)
            out[os.path.relpath(p, folder)] = (
                None if os.path.isdir(p) else "fifo" if stat.S_ISFIFO(os.lstat(p).st_mode) else open(p, "rb").read()
            )
    return out


def test_report_json_holds_the_returned_report(tmp_path):
    report = check_unprojector(
        U.horizontal_fov, scenes=["cube"], frames=1, cases=["on_axis", "wide_fov"], report_dir=tmp_path / "r"
    )
    assert sorted(p.name for p in (tmp_path / "r").iterdir()) == sorted([MARKER, "report.json", "report.md"])
    written = json.loads((tmp_path / "r" / "report.json").read_text())
    assert report["verdict"] == "fail" and len(report["cases"]) == 2
    # every number read back as it was returned: json keeps a float's 17 digits, so == is exact
    assert (
        written["compared"]
        == report["compared"]
        == {"cases": 2, "frames": 2, "points": sum(c["points"] for c in report["cases"])}
    )
    for got, case in zip(written["cases"], report["cases"]):
        for key in (
            "scene",
            "camera",
            "verdict",
            "points",
            "max_error",
            "max_error_ratio",
            "bound_at_worst",
            "worst",
            "precision",
            "reasons",
            "measured",
        ):
            assert got[key] == case[key], key
        assert got["faults"] == case["faults"] and got["faults"][0]["name"] == "fov_mismatch"
    assert written["settings"] == {
        "scenes": ["cube"],
        "cases": ["on_axis", "wide_fov"],
        "frames": 1,
        "turns": [1.0, 1.0, 0.0],
        "stride": 8,
        "allow_vacuous": False,
    }
    assert written["timing"]["wall_s"] == report["timing"]["wall_s"] > 0
    md = (tmp_path / "r" / "report.md").read_text()
    # the table's rows: one per case, the error and ratio as the console prints them
    for case in report["cases"]:
        row = (
            f"| cube | {case['camera']} | {case['points']:,} | {case['max_error']:.2e} | "
            f"{case['max_error_ratio']:.3g} | fail | {case['faults'][0]['short']} |"
        )
        assert row in md.splitlines(), row
    # two cases with fov_mismatch: what to check once, the catalogue's hint for an unprojector's points
    hint = f"- `fov_mismatch`: {CATALOGUE['fov_mismatch'].hints['points']}"
    assert md.splitlines().count(hint) == 1
    assert "FAIL: 0/2 cases, 2 frames" in md and "16 eps of its precision" in md
    assert "wall_s" not in md and "ms_per_frame" not in md


def test_two_runs_same_bytes_but_timing(tmp_path, capsys):
    assert _run("--report-dir", str(tmp_path / "a")) == 1
    assert _run("--report-dir", str(tmp_path / "b")) == 1
    a, b = _files(tmp_path / "a"), _files(tmp_path / "b")
    assert sorted(a) == sorted(b) == sorted([MARKER, "report.json", "report.md"])
    assert a["report.md"] == b["report.md"]
    ja, jb = json.loads(a["report.json"]), json.loads(b["report.json"])
    ta, tb = ja.pop("timing"), jb.pop("timing")
    assert ja == jb and list(ja) == list(jb)
    assert [(t["scene"], t["camera"]) for t in ta["cases"]] == [("cube", "on_axis"), ("cube", "wide_fov")]
    assert all(t["ms_per_frame"] > 0 for t in ta["cases"] + tb["cases"])
    out = capsys.readouterr().out
    assert out.rstrip().splitlines()[-1] == f"Report: {tmp_path / 'b' / 'report.md'} (also report.json)"


def test_run_and_no_report(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert _run("--run", "r1") == 1
    assert json.loads((tmp_path / "reports" / "r1" / "report.json").read_text())["run"] == "r1"
    assert (
        (tmp_path / "reports" / "r1" / "report.md")
        .read_text()
        .startswith("# crosscheck unprojector report (r1): FAIL\n")
    )
    capsys.readouterr()
    assert _run("--no-report") == 1
    assert capsys.readouterr().out.rstrip().splitlines()[-1] == "Report: none written (--no-report)"
    assert sorted(os.listdir(tmp_path)) == ["reports"] and os.listdir(tmp_path / "reports") == ["r1"]
    assert _run() == 1  # the default: reports/<UTC time>/
    (made,) = set(os.listdir(tmp_path / "reports")) - {"r1"}
    assert len(made) == len("20261207-040000") and (tmp_path / "reports" / made / "report.md").is_file()
    capsys.readouterr()
    assert _run("--no-report", "--run", "x") == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("crosscheck: error: --no-report with --run")


def _foreign_dir(target: Path) -> str:
    target.mkdir()
    (target / "notes.txt").write_text("mine")
    return "is a directory not written by wirecheck"


def _fifo_inside(target: Path) -> str:
    target.mkdir()
    os.mkfifo(target / "pipe")
    return "is a directory not written by wirecheck"


def _fifo(target: Path) -> str:
    os.mkfifo(target)
    return "is a file"


def _file(target: Path) -> str:
    target.write_text("mine")
    return "is a file"


def _planted(target: Path) -> str:
    """An earlier report of ours, with the user's file put into it."""
    assert _run("--report-dir", str(target)) == 1
    (target / "analysis.md").write_text("my notes")
    return "analysis.md (a file not written by wirecheck)"


@pytest.mark.parametrize("make", [_foreign_dir, _fifo_inside, _fifo, _file, _planted])
def test_a_folder_not_written_by_wirecheck_is_refused(tmp_path, capsys, make):
    target = tmp_path / "t"
    needle = make(target)
    before = _files(tmp_path)
    capsys.readouterr()
    assert _run("--report-dir", str(target)) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1 and err.startswith("crosscheck: error: --report-dir ")
    assert f"--report-dir {str(target)!r}" in err and needle in err and "nothing was changed" in err, err
    assert _files(tmp_path) == before  # every byte, every name: nothing added or removed


def test_api_refuses_before_running(tmp_path):
    calls = []

    def spy(pixels, depth, camera):
        calls.append(len(pixels))
        return U.correct(pixels, depth, camera)

    _foreign_dir(tmp_path / "t")
    with pytest.raises(InputError, match="is a directory not written by wirecheck"):
        check_unprojector(spy, scenes=["cube"], frames=1, cases=["on_axis"], report_dir=tmp_path / "t")
    (tmp_path / "f").write_text("mine")
    with pytest.raises(InputError, match="is a file"):
        check_unprojector(spy, scenes=["cube"], frames=1, cases=["on_axis"], report_dir=tmp_path / "f")
    with pytest.raises(TypeError, match="report_dir 3"):
        check_unprojector(spy, scenes=["cube"], frames=1, cases=["on_axis"], report_dir=3)
    assert calls == [] and (tmp_path / "t" / "notes.txt").read_text() == "mine"
    assert (tmp_path / "f").read_text() == "mine"
    assert sorted(os.listdir(tmp_path)) == ["f", "t"]  # no lock or temporary left beside them


def test_assert_unprojector_names_its_report(tmp_path):
    with pytest.raises(AssertionError) as info:
        assert_unprojector(U.rows_flipped, scenes=["cube"], frames=1, cases=["on_axis"], report_dir=tmp_path / "r")
    assert str(info.value).splitlines()[-1] == f"  report: {tmp_path / 'r' / 'report.md'}"
    assert (
        json.loads((tmp_path / "r" / "report.json").read_text())["cases"][0]["faults"][0]["name"] == "mirror_vertical"
    )
    report = assert_unprojector(U.correct, scenes=["cube"], frames=1, cases=["on_axis"], report_dir=tmp_path / "r")
    assert json.loads((tmp_path / "r" / "report.json").read_text())["verdict"] == report["verdict"] == "pass"
