"""``crosscheck --suite spec`` (oracles/spec/): the specification's test matrix and named checks.

core passes the 24 runs and 7 checks, each counted; the classic mistakes fail with their
fault names; each critical check fails, alone, against a projector broken for it; an edge
case fails against its own mistake; a suite that ran less than the specification never
passes; options the suite cannot honour are one line and exit 2.
"""

from __future__ import annotations

import contextlib
import io
import json
import re
from pathlib import Path

import numpy as np
import pytest
from wirecheck.core.scene.files import load_scene
from wirecheck.oracles import cli
from wirecheck.oracles.candidates.candidate import load_candidate
from wirecheck.oracles.candidates.protocol import encode_request
from wirecheck.oracles.spec import run_checks, suite_verdict

DATA = Path(__file__).parent / "data"
FAULTY = DATA / "faulty_projectors.py"

# The specification's matrix, written out here (not read from oracles.spec):
SCENES = ("unit_cube", "offset_pyramid")
CAMERAS = ("z3_fov60", "z3_fov90", "z6_fov60", "z6_fov90")
FRAME_COUNTS = (1, 30, 180)
CHECKS = [
    "known_point",
    "rotation_invariance",
    "depth_monotonicity",
    "clip_safety",
    "near_plane_depth",
    "behind_camera",
    "empty_mesh",
]
CRITICAL = CHECKS[:4]


def _suite(tmp_path, *args, name="run"):
    """``crosscheck --suite spec --report-dir tmp_path/name args`` in-process: ``(rc, spec.json, stdout, stderr)``."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            rc = cli.main(["--suite", "spec", "--report-dir", str(tmp_path / name), *args])
        except SystemExit as exc:  # argparse usage errors
            rc = exc.code
    path = tmp_path / name / "spec.json"
    return rc, (json.loads(path.read_text()) if path.exists() else None), out.getvalue(), err.getvalue()


@pytest.fixture(scope="module")
def core_suite(tmp_path_factory):
    """The whole suite on core at level pixels, once."""
    return _suite(tmp_path_factory.mktemp("spec"))


@pytest.mark.slow
def test_core_passes_every_run_and_check(core_suite):
    rc, result, out, err = core_suite
    assert rc == 0, out + err
    assert result["verdict"] == "pass" and result["why"] == []
    runs = result["runs"]
    assert [r["run"] for r in runs] == [f"{s}/{c}/{n}" for n in FRAME_COUNTS for s in SCENES for c in CAMERAS]
    for r in runs:
        assert r["verdict"] == "pass", (r["run"], r["reasons"])
        # one camera per run, every frame checked; both scenes stay within 1.62 of the origin, in front of
        # a camera at z >= 3 (near 0.1), so every vertex of every frame is compared: 8 (cube) or 5 (pyramid)
        assert r["compared"]["frames"] == r["frames_checked"] == r["frames"]
        assert r["compared"]["vertices"] == (8 if r["scene"] == "unit_cube" else 5) * r["frames"]
        assert r["compared"]["pixels"] > 0
        z, fov = re.fullmatch(r"z(\d)_fov(\d\d)", r["camera"]).groups()
        assert r["camera_spec"]["position"] == [0.0, 0.0, float(z)] and r["camera_spec"]["fov_y_deg"] == float(fov)
        assert r["camera_spec"]["forward"] == [0.0, 0.0, -1.0] and r["camera_spec"]["up"] == [0.0, 1.0, 0.0]
    assert [c["name"] for c in result["checks"]] == CHECKS
    assert [c["kind"] for c in result["checks"]] == ["critical"] * 4 + ["edge"] * 3
    assert all(c["verdict"] == "pass" for c in result["checks"]), result["checks"]
    # 2 scenes x 4 cameras x (1 + 30 + 180) frames; (8 + 5) vertices x 4 cameras x 211 frames
    compared = result["summary"]["compared"]
    assert (compared["cases"], compared["frames"], compared["vertices"]) == (24, 1688, 10972)
    assert result["summary"]["runs"] == result["summary"]["runs_passed"] == 24
    assert result["summary"]["checks"] == result["summary"]["checks_passed"] == 7
    lines = out.splitlines()
    assert lines[-2].startswith("PASS: 24/24 runs (1,688 frames, 10,972 vertices, ")
    assert lines[-2].endswith(" pixels compared), 7/7 named checks")
    assert (Path(lines[-1].split()[1])).parent.joinpath("spec.md").is_file()


@pytest.mark.slow
def test_known_values_reach_the_report(core_suite):
    _, result, _, _ = core_suite
    known = result["checks"][0]
    # (0.6, -0.9, 1.5) from (0, 0, 3): depth 1.5, normalised (0.4, -0.6); f = 240 px at FOV 90, H 480:
    # (319.5 + 240 * 0.4, 239.5 + 240 * 0.6)
    assert known["expected"]["pixels"][6] == pytest.approx([415.5, 383.5], abs=1e-12)
    assert known["got_normalised"][6] == pytest.approx([0.4, -0.6], abs=1e-12)
    assert known["error_px"] <= known["bound_px"] == 1e-6


def test_the_scenes_are_the_specifications():
    cube = load_scene("unit_cube")
    # a unit cube: side 1 along each axis, centred at the origin
    assert cube.vertices.max(axis=0).tolist() == [0.5] * 3 and cube.vertices.min(axis=0).tolist() == [-0.5] * 3
    assert len(cube.edges) == 12
    pyramid = load_scene("offset_pyramid")
    text = (Path(__file__).parents[1] / "scenes" / "examples" / "offset_pyramid.scene").read_text()
    assert re.search(r"^translate 0\.5 0\.25 -0\.5$", text, re.M)  # the translation, stated in the file
    (obj,) = pyramid.objects
    assert obj.motion.offset == (0.5, 0.25, -0.5) and obj.motion.turns == (0.0, 0.0, 0.0)
    assert len(pyramid.vertices) == 5 and len(pyramid.edges) == 8


@pytest.mark.slow
@pytest.mark.parametrize(
    "func,fault,check,runs_pass",
    [
        ("mirrored", "mirror_horizontal", "known_point", False),
        ("horizontal_fov", "fov_mismatch", "known_point", False),
        # no point of the matrix is ever behind the camera: only the named checks can see the missing clip
        ("no_clipping", "clipping_plane", "clip_safety", True),
    ],
)
def test_classic_mistakes_fail_with_their_names(tmp_path, func, fault, check, runs_pass):
    rc, result, out, err = _suite(tmp_path, "--level", "vertices", "--candidate", f"{FAULTY}:{func}")
    assert rc == 1, err
    assert result["verdict"] == "fail"
    runs = result["runs"]
    assert len(runs) == 24 and all(r["compared"]["vertices"] > 0 for r in runs)
    if runs_pass:
        assert all(r["verdict"] == "pass" for r in runs)
    else:
        assert all(r["verdict"] == "fail" and r["faults"][0]["name"] == fault for r in runs), [
            (r["run"], r["faults"]) for r in runs
        ]
    failed = {c["name"]: c for c in result["checks"] if c["verdict"] == "fail"}
    assert check in failed and [f["name"] for f in failed[check]["faults"]] == [fault]
    if func == "horizontal_fov":
        # f from the width: 320 / 240 = W / H, the scale the hint names
        assert failed[check]["faults"][0]["scale"] == pytest.approx(4 / 3, rel=1e-12)
        assert "horizontal FOV" in failed[check]["faults"][0]["hint"]
    if func == "no_clipping":
        assert failed[check]["faults"][0]["kind"] == "none"
        assert set(failed) == {"clip_safety", "near_plane_depth", "behind_camera"}
    else:
        assert set(failed) == {"known_point"}
    assert f"what to check, {fault}:" in out


@pytest.mark.parametrize(
    "func,check",
    [
        ("mirrored", "known_point"),  # x negated about cx
        ("fixed_orientation", "rotation_invariance"),  # ignores forward/up: right only on the -Z axis
        ("depth_clamped", "depth_monotonicity"),  # divides by min(z, 10)
        ("divides_before_clipping", "clip_safety"),  # ZeroDivisionError on the camera's plane
    ],
)
def test_each_critical_check_fails_alone_against_its_broken_projector(func, check):
    results = run_checks(load_candidate(f"{FAULTY}:{func}"))
    assert [c["name"] for c in results] == CHECKS
    assert [c["name"] for c in results if c["verdict"] == "fail"] == [check], results
    failed = next(c for c in results if c["name"] == check)
    assert failed["reasons"]


@pytest.mark.parametrize(
    "func,check,fault",
    [
        ("clips_at_camera", "near_plane_depth", "z_positive"),  # keeps 0 < z < near
        ("fails_on_empty", "empty_mesh", None),  # np.max of no points raises
    ],
)
def test_edge_cases_fail_against_their_mistakes(func, check, fault):
    results = run_checks(load_candidate(f"{FAULTY}:{func}"))
    assert [c["name"] for c in results if c["verdict"] == "fail"] == [check]
    failed = next(c for c in results if c["name"] == check)
    assert [f.get("kind") for f in failed["faults"]] == ([fault] if fault else [])


def test_the_correct_user_projector_passes_every_check():
    results = run_checks(load_candidate(f"{DATA / 'user_projector.py'}:project"))
    assert [(c["name"], c["verdict"]) for c in results] == [(n, "pass") for n in CHECKS]


def test_float32_candidates_are_held_to_their_precision():
    glm = DATA / "candidates" / "glm_f32.py"
    # float32 answers: judged at the float32 bound (~1e-3 px), as the runs judge them
    assert all(c["verdict"] == "pass" for c in run_checks(load_candidate(f"{glm}:project")))
    # the same float32 values returned as float64: 3e-5 px off, past the float64 bound, named for what it is
    # (a float32 near plane, a float32 computation), and passing once declared float32
    f64_view = load_candidate(f"{glm}:project_f64_view")
    failed = {c["name"]: c for c in run_checks(f64_view) if c["verdict"] == "fail"}
    assert set(failed) == {"known_point", "rotation_invariance", "near_plane_depth"}
    assert [f["name"] for f in failed["known_point"]["faults"]] == ["precision_limited"]
    assert [f.get("kind") for f in failed["near_plane_depth"]["faults"]] == ["float32_near"]
    declared = run_checks(f64_view, precision="float32")
    assert [c["verdict"] for c in declared] == ["pass"] * 7
    assert 1e-4 < declared[0]["bound_px"] < 1e-2 and declared[0]["error_px"] > 1e-6


@pytest.mark.slow
def test_declared_precision_reaches_the_runs_and_the_checks(tmp_path):
    rc, result, out, err = _suite(
        tmp_path,
        "--level",
        "vertices",
        "--candidate-precision",
        "float32",
        "--candidate",
        f"{DATA / 'candidates' / 'glm_f32.py'}:project_f64_view",
    )
    assert rc == 0, out + err
    assert result["candidate_precision"] == "float32"
    assert {(r["precision"]["judged_as"], r["precision"]["source"]) for r in result["runs"]} == {
        ("float32", "declared")
    }
    assert all(1e-4 < c["bound_px"] < 1e-2 for c in result["checks"][:2])


def test_a_suite_that_ran_less_never_passes():
    verdict, why = suite_verdict([], [])
    assert verdict == "fail"
    assert why == [
        "0 runs compared: expected the matrix's 24",
        "0 named checks run: expected the 7 of the specification",
    ]
    runs = [{"run": f"r{i}", "verdict": "pass"} for i in range(24)]
    checks = [{"name": n, "verdict": "pass"} for n in CHECKS]
    assert suite_verdict(runs, checks) == ("pass", [])
    assert suite_verdict(runs[:23], checks)[0] == "fail"
    assert suite_verdict(runs, checks[:6])[0] == "fail"
    vacuous = runs[:23] + [{"run": "r23", "verdict": "vacuous"}]
    assert suite_verdict(vacuous, checks) == ("fail", ["1 runs not passed: r23"])


@pytest.mark.parametrize(
    "args,needle",
    [
        (["--frames", "3"], "--suite spec with --frames: "),
        (["--scene", "cube"], "--suite spec with --scene: "),
        (["--candidate-precision", "float32"], "--suite spec with --candidate-precision float32 and no --candidate: "),
        (["--dtype", "float32"], "--suite spec with --dtype: "),
        (["--hidden-lines"], "--hidden-lines with --suite spec: "),
        (["--junit-xml", "x.xml"], "--junit-xml with --suite spec: "),
        (["--candidate", "nowhere.py:f"], "--candidate 'nowhere.py:f': file 'nowhere.py' not found"),
    ],
)
def test_options_the_suite_cannot_honour_are_one_line(tmp_path, args, needle):
    rc, result, out, err = _suite(tmp_path, *args)
    assert rc == 2 and out == ""
    assert err.count("\n") == 1 and err.startswith("crosscheck: error: ") and needle in err, err
    assert result is None and not (tmp_path / "run").exists()


def test_a_request_of_no_points_is_its_line_alone():
    # docs/protocol.md: N may be 0; the request is then the JSON line and no bytes of points
    assert bytes(encode_request(1, np.zeros((0, 3)), "{}")) == b'{"request":1,"n":0,"camera":{}}\n'


def _strict(text: str):
    """spec.json parsed as strict JSON: NaN, Infinity and -Infinity are not JSON."""

    def refuse(name):
        raise ValueError(f"{name} in spec.json")

    return json.loads(text, parse_constant=refuse)


@pytest.mark.slow
@pytest.mark.parametrize("func", ["nan_everywhere", "far_off"])
def test_a_nan_or_inf_candidate_fails_with_a_report(tmp_path, func):
    # found by benchmarks/fuzz_round5.py: a candidate answering NaN (or 1e300, whose distances overflow) made
    # known_point's error_px inf and its pixels NaN; writing spec.json raised ValueError (exit 3, "internal
    # error", no report). Such values are null in spec.json (as in report.json) and the suite fails.
    rc, result, out, err = _suite(tmp_path, "--level", "vertices", "--candidate", f"{FAULTY}:{func}")
    assert rc == 1 and "internal error" not in err, err
    result = _strict((tmp_path / "run" / "spec.json").read_text())
    assert result["verdict"] == "fail" and result["summary"]["runs_passed"] == 0
    known = result["checks"][0]
    assert known["name"] == "known_point" and known["verdict"] == "fail" and known["reasons"]
    assert known["error_px"] is None  # inf for NaN (checks._worst), null in JSON
    assert "FAIL: 0/24 runs" in out
