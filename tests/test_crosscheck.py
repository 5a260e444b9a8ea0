"""crosscheck end to end: exit codes, report contents, external candidates."""

import subprocess
import sys
from pathlib import Path

import pytest
from helpers import run_crosscheck as run
from wirecheck.oracles import cli
from wirecheck.oracles.cases import CASE_NAMES

DATA = Path(__file__).parent / "data"
USER = DATA / "user_projector.py"
FAULTY = DATA / "faulty_projectors.py"
CASE_KEYS = {
    "scene",
    "camera",
    "frames",
    "max_vertex_error_px",
    "mean_vertex_error_px",
    "pixel_f1_0px",
    "pixel_f1_1px",
    "faults",
    "verdict",
}


@pytest.fixture(autouse=True)
def _data_on_path(monkeypatch):
    monkeypatch.syspath_prepend(str(DATA))  # faulty_projectors imports user_projector


def test_core_passes_every_case_and_report_has_the_fields(tmp_path, capsys):
    code, report, out = run(tmp_path, "--scene", "cube", "--frames", "4")
    assert code == 0
    assert report["verdict"] == "pass"
    assert [c["camera"] for c in report["cases"]] == list(CASE_NAMES)
    for case in report["cases"]:
        assert CASE_KEYS <= set(case)
        assert case["faults"] == [] and case["verdict"] == "pass"
        # float64 on both sides: ~1e-11 px is the derived scale (oracles/tolerances.py)
        assert case["max_vertex_error_px"] < 1e-9
        assert case["pixel_f1_1px"] == 1.0
    assert set(report["timing"]) >= {"opencv_ms_per_frame", "pyrender_ms_per_frame", "candidate_ms_per_frame"}
    assert "| cube | on_axis |" in (out / "report.md").read_text()
    html = (out / "report.html").read_text()
    for src in [s.split("'")[0] for s in html.split("src='")[1:]]:
        assert (out / src).is_file()
    stdout = capsys.readouterr().out
    assert f"Report: {out / 'report.json'}" in stdout


def test_report_is_deterministic_apart_from_timing(tmp_path):
    _, a, out_a = run(tmp_path, "--scene", "pyramid", "--frames", "3", "--cases", "on_axis,near_plane", name="a")
    _, b, out_b = run(tmp_path, "--scene", "pyramid", "--frames", "3", "--cases", "on_axis,near_plane", name="b")
    a.pop("timing")
    b.pop("timing")
    assert a == b
    assert (out_a / "report.md").read_bytes() == (out_b / "report.md").read_bytes()


def test_external_correct_candidate_passes(tmp_path):
    code, report, _ = run(tmp_path, "--candidate", f"{USER}:project", "--scene", "prism", "--frames", "3")
    assert code == 0, [c["reasons"] for c in report["cases"]]


def test_half_pixel_offset_is_diagnosed(tmp_path):
    code, report, _ = run(tmp_path, "--candidate", f"{USER}:project_corner", "--scene", "cube", "--frames", "3")
    assert code == 1 and report["verdict"] == "fail"
    for case in report["cases"]:
        assert [f["name"] for f in case["faults"]] == ["pixel_offset"]
        # cx = W/2 instead of (W-1)/2: exactly half a pixel, both axes. Pixel values
        # agree to ~eps * 640 px * 10 ops ~ 1.5e-12 px and the diagnosis fit adds
        # ~3.5e-12 px (budget in tests/test_diagnosis.py), so 1e-9 px is a safe bound
        # that still tells 0.5 from any other offset.
        assert case["faults"][0]["dx"] == pytest.approx(0.5, abs=1e-9)
        assert case["faults"][0]["dy"] == pytest.approx(0.5, abs=1e-9)
        assert case["max_vertex_error_px"] == pytest.approx(0.5 * 2**0.5, abs=1e-9)


def test_mirror_is_diagnosed_and_fails_pixels_too(tmp_path):
    code, report, _ = run(
        tmp_path,
        "--candidate",
        f"{FAULTY}:mirrored",
        "--scene",
        "cube",
        "--frames",
        "3",
        "--cases",
        "oblique_roll,non_square",
    )
    assert code == 1
    for case in report["cases"]:
        assert [f["name"] for f in case["faults"]] == ["mirror_horizontal"]
        assert case["pixel_f1_1px"] < 0.999


@pytest.mark.parametrize("func, needle", [("crashes", "ZeroDivisionError"), ("wrong_shape", "shape")])
def test_broken_candidate_fails_with_reason(tmp_path, func, needle):
    code, report, _ = run(
        tmp_path, "--candidate", f"{FAULTY}:{func}", "--scene", "cube", "--frames", "2", "--cases", "on_axis"
    )
    assert code == 1
    assert needle in report["cases"][0]["reasons"][0]


@pytest.mark.parametrize(
    "args, needle",
    [
        (["--frames", "0"], "--frames 0"),
        (["--scene", "nope"], "'nope'"),
        (["--candidate", "missing.py:f"], "not found"),
        (["--candidate", f"{USER}:nothere"], "nothere"),
        (["--candidate", "nocolon"], "FILE.py:FUNC"),
        (["--oracles", "opencv,blender"], "--oracles"),
        (["--cases", "on_axis,upside_down"], "upside_down"),
        (["--min-f1", "1.5"], "--min-f1"),
    ],
)
def test_usage_errors_exit_2_with_one_line(tmp_path, capsys, args, needle):
    code = cli.main(["--report-dir", str(tmp_path / "r"), *args])
    err = capsys.readouterr().err
    assert code == 2
    assert err.count("\n") == 1 and needle in err and "Traceback" not in err
    assert not (tmp_path / "r").exists()  # no half-written report


def test_missing_osmesa_exits_2_unless_opencv_only(tmp_path, capsys, monkeypatch):
    # OpenGL.osmesa failing to import is what a machine without libOSMesa shows
    import OpenGL

    monkeypatch.setitem(sys.modules, "OpenGL.osmesa", None)
    monkeypatch.delattr(OpenGL, "osmesa", raising=False)
    code = cli.main(["--report-dir", str(tmp_path / "r"), "--scene", "cube", "--frames", "1"])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and "apt-get install -y libosmesa6" in err
    code, report, _ = run(tmp_path, "--oracles", "opencv", "--scene", "cube", "--frames", "2")
    assert code == 0 and report["oracles"] == ["opencv"]
    assert report["cases"][0]["pixel_f1_1px"] is None


def test_tolerance_override_turns_pass_into_fail(tmp_path):
    # vertex errors of core are ~1e-13 px (measured); a tolerance of 0 must fail them
    code, report, _ = run(tmp_path, "--scene", "cube", "--frames", "2", "--cases", "oblique_roll", "--tol-px", "0")
    assert code == 1
    assert "max vertex error" in report["cases"][0]["reasons"][0]


@pytest.mark.slow
def test_subprocess_prints_table_and_path(tmp_path):
    out = tmp_path / "sub"
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "wirecheck.oracles.cli",
            "--scene",
            "cube",
            "--frames",
            "2",
            "--cases",
            "on_axis",
            "--report-dir",
            str(out),
        ],
        capture_output=True,
        text=True,
        cwd=Path(__file__).parent.parent,
    )
    assert proc.returncode == 0, proc.stderr
    assert proc.stderr == ""
    # first what was compared (oracles.reports.compared), then the table
    assert proc.stdout.splitlines()[0] == (
        "Compared: level pixels (OpenCV and pyrender), 2 frames per case, 1 case (1 scene x 1 camera)"
    )
    assert proc.stdout.splitlines()[1].split()[:2] == ["scene", "camera"]
    assert proc.stdout.rstrip().endswith("(also report.md, report.html)")
    assert (out / "report.json").is_file()


def test_failing_report_says_what_to_check(tmp_path):
    _, _, out = run(
        tmp_path, "--candidate", f"{FAULTY}:mirrored", "--scene", "cube", "--frames", "2", "--cases", "oblique_roll"
    )
    md = (out / "report.md").read_text()
    assert "## What to check" in md and "`mirror_horizontal`: left and right are exchanged" in md


def _write(tmp_path, text):
    f = tmp_path / "cand.py"
    f.write_text(text)
    return f


def test_candidate_exiting_at_import_is_a_usage_error(tmp_path, capsys):
    cand = _write(tmp_path, "import sys\nsys.exit(0)\ndef f(p, c):\n    return p[:, :2]\n")
    assert cli.main(["--candidate", f"{cand}:f", "--report-dir", str(tmp_path / "r")]) == 2
    assert "SystemExit" in capsys.readouterr().err


def test_candidate_with_wrong_signature_is_a_usage_error(tmp_path, capsys):
    cand = _write(tmp_path, "def f(points):\n    return points[:, :2]\n")
    assert cli.main(["--candidate", f"{cand}:f", "--report-dir", str(tmp_path / "r")]) == 2
    assert "f(points, camera)" in capsys.readouterr().err


def test_candidate_exiting_during_the_run_fails_not_passes(tmp_path):
    cand = _write(tmp_path, "def f(p, c):\n    raise SystemExit(0)\n")
    code, report, _ = run(
        tmp_path, "--candidate", f"{cand}:f", "--scene", "cube", "--frames", "1", "--cases", "on_axis"
    )
    assert code == 1 and "SystemExit" in report["cases"][0]["reasons"][0]


def test_infinite_output_is_a_contract_violation(tmp_path, capsys):
    cand = _write(tmp_path, "import numpy as np\ndef f(p, c):\n    return np.full((len(p), 2), np.inf)\n")
    code, report, _ = run(
        tmp_path, "--candidate", f"{cand}:f", "--scene", "cube", "--frames", "1", "--cases", "on_axis"
    )
    assert code == 1
    assert "expected finite pixel coordinates" in report["cases"][0]["reasons"][0]
    assert "expected finite pixel coordinates" in capsys.readouterr().out  # reasons on the console too


def test_per_frame_errors_and_precision_recall_at_0px(tmp_path):
    _, report, _ = run(tmp_path, "--scene", "cube", "--frames", "3", "--cases", "oblique_roll")
    case = report["cases"][0]
    assert [f["frame"] for f in case["per_frame"]] == [1, 2, 3]
    assert max(f["max_vertex_error_px"] for f in case["per_frame"]) == case["max_vertex_error_px"]
    assert case["pixel_f1_0px"] == min(f["f1_0px"] for f in case["per_frame"])
    for key in ("pixel_precision_0px", "pixel_recall_0px"):
        assert 0.98 <= case[key] <= 1.0  # measured >= 0.9958 (oracles/tolerances.py)


def test_empty_scene_is_vacuous_and_fails_unless_allowed(tmp_path):
    empty = tmp_path / "empty.scene"
    empty.write_text("# no vertices\n")
    code, report, _ = run(tmp_path, "--scene", str(empty), "--frames", "1", "--cases", "on_axis")
    case = report["cases"][0]
    assert code == 1 and report["verdict"] == "fail"
    assert case["verdict"] == "vacuous" and case["max_vertex_error_px"] is None
    assert case["reasons"] == ["vacuous: the scene has no vertices: nothing compared"]
    assert report["compared"] == {"cases": 0, "frames": 1, "vertices": 0, "pixels": 0}
    code, report, _ = run(
        tmp_path, "--scene", str(empty), "--frames", "1", "--cases", "on_axis", "--allow-vacuous", name="allowed"
    )
    assert code == 0 and report["verdict"] == "pass" and report["cases"][0]["verdict"] == "vacuous"
