"""A gate never passes on nothing (oracles.judge.gate): every way a check could compare nothing.

Inputs that would compare nothing are usage errors, the same through the CLI
(exit 2, one stderr line, no traceback, no report) and the API (ValueError).
A case that ran but compared nothing is "vacuous" and fails the run unless
allowed. Each test below was seen to fail with its check removed.
"""

import io
import json
import math
import sys
from pathlib import Path

import numpy as np
import pytest
from wirecheck.core.camera import look_at
from wirecheck.core.errors import InputError
from wirecheck.oracles import cases as cases_mod
from wirecheck.oracles import cli
from wirecheck.oracles.api import assert_projector, check_projector
from wirecheck.oracles.judge import gate
from wirecheck.oracles.runner import CoreCandidate, run_crosscheck

DATA = Path(__file__).parent / "data"
USER = DATA / "user_projector.py"


def _raises_always(points, camera):
    raise RuntimeError("this projector must never be called")


def cli_usage_error(tmp_path, capsys, *args) -> str:
    """Run the CLI; assert exit 2, one stderr line, no traceback, no report; return the line."""
    out = tmp_path / "r"
    code = cli.main(["--report-dir", str(out), *args])
    err = capsys.readouterr().err
    assert code == 2, err
    assert err.startswith("crosscheck: error: ") and err.count("\n") == 1 and "Traceback" not in err
    assert not out.exists()
    return err


# ---------------------------------------------------------------- inputs that compare nothing: usage errors


@pytest.mark.parametrize(
    "args, needle",
    [
        (["--frames", "0"], "--frames 0"),
        (["--frames", "-3"], "--frames -3"),
        (["--frames", "3", "--every", "5"], "--every 5 with --frames 3"),
        (["--cases", ""], "--cases ''"),
        (["--cases", ","], "--cases ','"),
        (["--cases", "on_axiz"], "'on_axiz'"),
        (["--cases", "on_axis,on_axis"], "on_axis given twice"),
        (["--scene", ""], "--scene ''"),
        (["--scene", "cube", "--scene", "cube"], "two scenes named 'cube'"),
        (["--scene", "cube", "--scene", "scenes/cube.scene"], "two scenes named 'cube'"),
        (["--tol-px", "nan"], "--tol-px nan"),
        (["--min-f1", "nan"], "--min-f1 nan"),
        (["--spin", "nan,0,0"], "--spin 'nan,0,0'"),
        (["--run", ""], "--run ''"),
        (["--sweep", "--cases", ","], "--cases ','"),
    ],
)
def test_cli_inputs_that_compare_nothing_exit_2(tmp_path, capsys, args, needle):
    err = cli_usage_error(tmp_path, capsys, "--level", "vertices", *args)
    assert needle in err


def test_cli_empty_scene_folder_and_unmatched_glob_exit_2(tmp_path, capsys):
    folder = tmp_path / "scenes"
    folder.mkdir()
    # a folder is a dataset (oracles/datasets/dataset.py): an empty one has nothing to check
    assert "no mesh files in this folder" in cli_usage_error(
        tmp_path, capsys, "--level", "vertices", "--scene", str(folder)
    )
    # a shell glob that matches nothing arrives as the pattern itself
    err = cli_usage_error(tmp_path, capsys, "--level", "vertices", "--scene", str(folder / "*.obj"))
    assert "file not found" in err


@pytest.mark.parametrize(
    "kwargs, needle",
    [
        ({"frames": 0}, "frames 0"),
        ({"frames": -3}, "frames -3"),
        ({"frames": 2.5}, "frames 2.5"),
        ({"cases": ["on_axiz"]}, "'on_axiz'"),
        ({"cases": "axis"}, "'axis'"),  # a string is a comma-separated list, not a substring match
        ({"cases": []}, "no case named"),
        ({"cases": ""}, "no case named"),
        ({"cases": ["on_axis", "on_axis"]}, "given twice"),
        ({"scenes": []}, "no scene given"),
        ({"scenes": ["nope"]}, "'nope'"),
        ({"scenes": [""]}, "''"),
        ({"scenes": ["cube", "cube"]}, "two scenes named 'cube'"),
        ({"tol_px": math.nan}, "tol_px nan"),
        ({"min_f1": math.nan}, "min_f1 nan"),
        ({"turns": (math.nan, 0, 0)}, "turns"),
        ({"oracles": ()}, "expected opencv among them"),
    ],
)
def test_api_inputs_that_compare_nothing_raise_before_calling_the_projector(kwargs, needle):
    # the projector raises on every call: a pass here would mean nothing was called, i.e. nothing compared
    with pytest.raises(ValueError, match=None) as info:
        assert_projector(_raises_always, **{"scenes": ["cube"], "frames": 2, **kwargs})
    assert needle in str(info.value) and "\n" not in str(info.value)


def test_every_larger_than_frames_is_an_error_in_the_library():
    scene = gate.resolve_scenes(["cube"])
    with pytest.raises(InputError, match="every 5 with frames 3: only frame 1 would be checked"):
        run_crosscheck(scene, CoreCandidate(), frames=3, every=5, level="vertices")
    # every == frames is allowed: it checks frame 1 (the stride ends the motion)
    report, _ = run_crosscheck(scene, CoreCandidate(), frames=3, every=3, level="vertices", case_names=["on_axis"])
    assert report["frames_checked"] == 1 and report["compared"]["frames"] == 1


def test_no_bundled_scenes_found_is_a_usage_error(tmp_path, capsys, monkeypatch):
    import wirecheck.core.scene.files as scene_mod

    monkeypatch.setattr(scene_mod, "SCENE_DIR", tmp_path / "empty")  # an installation without scenes
    assert "no bundled scenes found" in cli_usage_error(tmp_path, capsys, "--level", "vertices")
    with pytest.raises(ValueError, match="no bundled scenes found"):
        check_projector(_raises_always, frames=1)


# ---------------------------------------------------------------- candidates that return nothing


def test_candidate_returning_all_nan_fails_as_visibility_mismatch():
    def all_clipped(points, camera):
        return np.full((len(points), 2), np.nan)

    report = check_projector(all_clipped, scenes=["cube"], frames=2, cases=["on_axis"])
    case = report["cases"][0]
    # on_axis sees all 8 cube vertices in both frames (3r away, fov 60): 16 points only the oracle shows
    assert report["verdict"] == "fail" and case["verdict"] == "fail"
    assert case["visibility_mismatch"] == {"candidate_only": 0, "oracle_only": 16}
    assert any("visible sets differ" in r for r in case["reasons"])
    with pytest.raises(AssertionError, match="1 of 1 crosscheck cases failed"):
        assert_projector(all_clipped, scenes=["cube"], frames=2, cases=["on_axis"], allow_vacuous=True)


def test_candidate_that_ends_the_process_with_status_0_fails(tmp_path):
    import subprocess

    # os._exit skips every handler: in-process, crosscheck itself would end with status 0 and no report.
    # Run as a subprocess, so that a regression fails this test instead of ending pytest with status 0.
    killer = tmp_path / "killer.py"
    killer.write_text("import os\n\ndef project(points, camera):\n    os._exit(0)\n")
    out = tmp_path / "r"
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "wirecheck.oracles.cli",
            "--report-dir",
            str(out),
            "--level",
            "vertices",
            "--candidate",
            f"{killer}:project",
            "--scene",
            "cube",
            "--frames",
            "1",
            "--cases",
            "on_axis",
        ],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 1, (proc.returncode, proc.stderr)
    # the candidate runs in its own process (oracles.candidates.isolation): its case fails and the report is written
    assert proc.stderr == "" and "FAIL: 0/1 cases" in proc.stdout
    report = json.loads((out / "report.json").read_text())
    assert report["cases"][0]["reasons"] == ["frame 1: candidate exited with status 0 during a request of 8 points"]


def test_candidate_returning_an_empty_array_fails():
    report = check_projector(lambda points, camera: np.zeros((0, 2)), scenes=["cube"], frames=1, cases=["on_axis"])
    case = report["cases"][0]
    assert report["verdict"] == "fail" and case["verdict"] == "fail"
    assert "shape (0, 2): expected (8, 2)" in case["reasons"][0]


# ---------------------------------------------------------------- cases that ran but compared nothing: vacuous


@pytest.fixture()
def camera_looking_away(monkeypatch):
    """Every case camera replaced by one that looks away from the scene: every point is clipped."""

    def away(radius, *_framing):
        r = radius if radius > 0 else 1.0
        cam = look_at((0, 0, 3 * r), (0, 0, 6 * r), (0, 1, 0), fov_y_deg=60, near=0.1 * r, far=10 * r)
        return [cases_mod.Case("on_axis", cam)]

    monkeypatch.setattr(cases_mod, "cameras_for", away)


@pytest.mark.parametrize("level", ["vertices", "pixels"])
def test_every_vertex_outside_the_frustum_is_vacuous_and_fails_unless_allowed(
    camera_looking_away, tmp_path, capsys, level
):
    out = tmp_path / "r"
    code = cli.main(
        ["--report-dir", str(out), "--level", level, "--scene", "cube", "--frames", "2", "--cases", "on_axis"]
    )
    report = json.loads((out / "report.json").read_text())
    stdout = capsys.readouterr().out
    case = report["cases"][0]
    assert code == 1 and report["verdict"] == "fail"
    assert case["verdict"] == "vacuous" and case["visibility_mismatch"] == {"candidate_only": 0, "oracle_only": 0}
    assert "no vertex visible to both sides" in case["reasons"][0]
    assert report["compared"] == {"cases": 0, "frames": 2, "vertices": 0, "pixels": 0 if level == "pixels" else None}
    assert report["summary"]["vacuous"] == 1 and report["summary"]["passed"] == 0
    assert any(ln.split()[:2] == ["cube", "on_axis"] and "vacuous" in ln.split() for ln in stdout.splitlines())
    assert "1 case vacuous (compared nothing: a failure unless --allow-vacuous)" in stdout
    md = (out / "report.md").read_text()
    assert "## Why cases failed" in md and "no vertex visible to both sides" in md
    if level == "pixels":  # two blank frames score F1 = 1.0: the table shows "-", not a perfect score
        assert "| cube | on_axis | - | - | - | vacuous |" in md
    assert "vacuous" in (out / "report.html").read_text()

    code = cli.main(
        [
            "--report-dir",
            str(tmp_path / "allowed"),
            "--level",
            level,
            "--scene",
            "cube",
            "--frames",
            "2",
            "--cases",
            "on_axis",
            "--allow-vacuous",
        ]
    )
    allowed = json.loads((tmp_path / "allowed" / "report.json").read_text())
    assert code == 0 and allowed["verdict"] == "pass" and allowed["cases"][0]["verdict"] == "vacuous"
    assert "allowed" in (tmp_path / "allowed" / "report.md").read_text()


def test_junit_counts_a_vacuous_case_as_a_failure_or_allowed_as_skipped(camera_looking_away, tmp_path):
    import xml.etree.ElementTree as ET

    args = ["--level", "vertices", "--scene", "cube", "--frames", "1", "--cases", "on_axis"]
    for name, extra, failures, skipped in (("plain", [], "1", "0"), ("allowed", ["--allow-vacuous"], "0", "1")):
        junit = tmp_path / f"{name}.xml"
        cli.main(["--report-dir", str(tmp_path / name), "--junit-xml", str(junit), *args, *extra])
        suite = ET.parse(junit).getroot()
        assert (suite.get("failures"), suite.get("skipped")) == (failures, skipped)
        case = suite.find("testsuite/testcase")
        assert case.find("failure" if failures == "1" else "skipped") is not None
        assert "no vertex visible to both sides" in ET.tostring(case, encoding="unicode")


def test_api_vacuous_case_raises_unless_allowed(camera_looking_away):
    with pytest.raises(AssertionError, match="vacuous: no vertex visible to both sides"):
        assert_projector(f"{USER}:project", scenes=["cube"], frames=2)
    report = assert_projector(f"{USER}:project", scenes=["cube"], frames=2, allow_vacuous=True)
    assert report["verdict"] == "pass" and report["cases"][0]["verdict"] == "vacuous"


def test_points_without_edges_are_vacuous_at_level_pixels_only(tmp_path, capsys):
    points = tmp_path / "points.scene"
    points.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\n")
    code = cli.main(
        ["--report-dir", str(tmp_path / "px"), "--scene", str(points), "--frames", "2", "--cases", "on_axis"]
    )
    case = json.loads((tmp_path / "px" / "report.json").read_text())["cases"][0]
    # 3 points visible on_axis in 2 frames were compared; nothing was drawn by either side
    assert code == 1 and case["verdict"] == "vacuous" and case["compared"] == {"frames": 2, "vertices": 6, "pixels": 0}
    assert "neither side drew a pixel" in case["reasons"][0]
    code = cli.main(
        [
            "--report-dir",
            str(tmp_path / "v"),
            "--level",
            "vertices",
            "--scene",
            str(points),
            "--frames",
            "2",
            "--cases",
            "on_axis",
        ]
    )
    assert code == 0


def test_run_verdict_needs_something_compared():
    ok = {"verdict": "pass", "compared": {"frames": 2, "vertices": 16, "pixels": 100}}
    totals = gate.compared_totals([ok], "pixels")
    assert totals == {"cases": 1, "frames": 2, "vertices": 16, "pixels": 100}
    assert gate.run_verdict([ok], totals, "pixels") == "pass"
    # no records, or records that compared no frame: never a pass, allowed or not
    assert gate.run_verdict([], {"cases": 0, "frames": 0, "vertices": 0, "pixels": 0}, "pixels", True) == "fail"
    # a "pass" record that somehow counted no pixel at level pixels: the run still fails
    hollow = {"verdict": "pass", "compared": {"frames": 2, "vertices": 16, "pixels": 0}}
    assert gate.run_verdict([hollow], gate.compared_totals([hollow], "pixels"), "pixels") == "fail"


# ---------------------------------------------------------------- how much was compared


def test_summary_line_and_report_count_what_was_compared(tmp_path, capsys):
    from PIL import Image

    out = tmp_path / "r"
    code = cli.main(["--report-dir", str(out), "--scene", "cube", "--frames", "1", "--cases", "on_axis"])
    report = json.loads((out / "report.json").read_text())
    # the cube's 8 vertices are all in view on_axis (3r away, fov 60); one frame
    assert code == 0 and report["compared"]["frames"] == 1 and report["compared"]["vertices"] == 8
    # pixels compared = pixels drawn by either side; with one frame, the worst-frame images are that frame
    cand = np.asarray(Image.open(out / "img" / "cube-on_axis-candidate.png")) > 0
    orac = np.asarray(Image.open(out / "img" / "cube-on_axis-oracle.png")) > 0
    union = int((cand | orac).sum())
    assert union > 0 and report["compared"]["pixels"] == union
    stdout = capsys.readouterr().out
    assert f"PASS: 1/1 cases, 1 frame, 8 vertices, {union:,} pixels compared (" in stdout
    assert f"Compared: 1 frame, 8 vertices, {union:,} pixels compared." in (out / "report.md").read_text()


# ---------------------------------------------------------------- --run with --report-dir


def test_run_name_goes_under_report_dir_and_into_the_report(tmp_path, capsys, monkeypatch):
    base = tmp_path / "reports-here"
    args = ["--level", "vertices", "--scene", "cube", "--frames", "1", "--cases", "on_axis"]
    assert cli.main(["--report-dir", str(base), "--run", "a", *args]) == 0
    assert cli.main(["--report-dir", str(base), "--run", "b", *args]) == 0
    assert sorted(p.name for p in base.iterdir()) == ["a", "b"]  # neither overwrote the other
    assert json.loads((base / "a" / "report.json").read_text())["run"] == "a"
    assert "# crosscheck report (b): PASS" in (base / "b" / "report.md").read_text()
    # --report-dir alone: that folder itself; --run alone: reports/RUN in the current folder
    assert cli.main(["--report-dir", str(tmp_path / "plain"), *args]) == 0
    assert json.loads((tmp_path / "plain" / "report.json").read_text())["run"] is None
    monkeypatch.chdir(tmp_path)
    assert cli.main(["--run", "c", *args]) == 0
    assert json.loads((tmp_path / "reports" / "c" / "report.json").read_text())["run"] == "c"


# ---------------------------------------------------------------- progress on a terminal only


class _FakeTTY(io.StringIO):
    def isatty(self):
        return True


def test_progress_on_a_terminal_is_written_then_cleared(tmp_path, monkeypatch):
    tty = _FakeTTY()
    monkeypatch.setattr(sys, "stderr", tty)
    code = cli.main(
        [
            "--report-dir",
            str(tmp_path / "r"),
            "--level",
            "vertices",
            "--scene",
            "cube",
            "--frames",
            "3",
            "--cases",
            "on_axis,orthographic",
        ]
    )
    text = tty.getvalue()
    assert code == 0
    # 2 cases x 3 frames: before the first case, after each
    lines = [t.rstrip() for t in text.split("\r") if t.strip()]
    assert lines == [
        "crosscheck: 0/2 cases, 0/6 frames",
        "crosscheck: 1/2 cases, 3/6 frames",
        "crosscheck: 2/2 cases, 6/6 frames",
    ]
    width = len("crosscheck: 0/2 cases, 0/6 frames")
    assert text.endswith("\r" + " " * width + "\r")  # cleared: blanks over the line, cursor at its start


def test_no_progress_when_stderr_is_not_a_terminal(tmp_path, capsys):
    code = cli.main(
        [
            "--report-dir",
            str(tmp_path / "r"),
            "--level",
            "vertices",
            "--scene",
            "cube",
            "--frames",
            "2",
            "--cases",
            "on_axis",
        ]
    )
    assert code == 0 and capsys.readouterr().err == ""


# ---------------------------------------------------------------- fault numbers tell the value from nominal


def test_fault_numbers_are_printed_distinct_from_their_nominal_values():
    from wirecheck.oracles.reports.fault_text import full_text as fault_text
    from wirecheck.oracles.reports.fmt import distinct

    camera = {"width": 640, "height": 480, "fov_y_deg": 60.0, "ortho_height": 3.0}
    faults = [
        {"name": "aspect_mismatch", "implied_aspect": 1.33264, "scale_x": 1.0005, "scale_y": 1.0},
        {"name": "fov_mismatch", "scale": 0.99999, "implied_fov_deg": 60.000412, "implied_ortho_height": None},
    ]
    text = fault_text(faults, camera)
    # 4:3 = 1.33333...: 4 significant digits print both as 1.333, 5 tell them apart
    assert "implied_aspect=1.3326," in text and "scale_x=1.0005," in text and "scale_y=1)" in text
    assert "scale=0.99999," in text and "implied_fov_deg=60.0004)" in text
    # far from nominal: 4 significant digits, as before
    assert distinct(1.5, 4 / 3) == "1.5" and distinct(0.25, 0.0) == "0.25"
    assert distinct(1.0000004e-06, 1e-06) == "1.0000004e-06"


# ---------------------------------------------------------------- case groups


def test_case_groups_expand_to_their_members_in_table_order():
    # The groups are written out by hand here (the case table in docs/crosscheck.md),
    # not read from gate.CASE_GROUPS.
    default = ("on_axis", "oblique_roll", "near_plane", "wide_fov", "narrow_fov", "non_square", "orthographic")
    calibrated = ("off_centre", "non_square_pixels", "distorted")
    assert gate.resolve_cases("default") == default
    assert gate.resolve_cases("calibrated") == calibrated
    assert gate.resolve_cases("all") == default + calibrated
    assert gate.resolve_cases("calibrated,on_axis") == ("on_axis",) + calibrated
    with pytest.raises(InputError, match="distorted given twice"):
        gate.resolve_cases("calibrated,distorted")
