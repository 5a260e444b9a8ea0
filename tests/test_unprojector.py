"""The way back: oracles.references.unproject_reference, check_unprojector / assert_unprojector, the CLI.

The unprojectors under test are tests/data/unprojectors.py: a correct one written from K, R, t,
a float32 one, a GL-style one through inverse(P V), and one classic mistake each.
"""

from __future__ import annotations

import math
import re
import subprocess
import sys
from collections import Counter
from pathlib import Path

import numpy as np
import pytest
from wirecheck import assert_unprojector, check_unprojector
from wirecheck.core.camera import camera_z
from wirecheck.core.errors import InputError
from wirecheck.core.scene.files import load_scene
from wirecheck.core.scene.frames import SceneRenderer
from wirecheck.core.scene.model import Scene
from wirecheck.core.transforms import Motion
from wirecheck.oracles.cases import CALIBRATED_CASE_NAMES, CASE_NAMES, cameras_for, case_motion, cases_for
from wirecheck.oracles.faults import CATALOGUE
from wirecheck.oracles.judge.metrics import depth_bound
from wirecheck.oracles.references.opencv_oracle import project as cv_project
from wirecheck.oracles.references.unproject_reference import unproject
from wirecheck.oracles.reports.fault_text import CELL_MAX
from wirecheck.oracles.reports.unprojector_report import console_lines
from wirecheck.oracles.tolerances import unproject_bound
from wirecheck.oracles.unprojector_api import unprojector_failure_text

sys.path.insert(0, str(Path(__file__).parent / "data"))
import unprojectors as U  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SPEC = "tests/data/unprojectors.py"
EPS = np.finfo(np.float64).eps


# ---------------------------------------------------------------- the reference inverse


def test_reference_hand_values():
    cam = camera_z(4.0, width=640, height=480, fov_y_deg=90)  # f = 240 px, centre (319.5, 239.5)
    # the centre at depth 4 is the origin; 240 px right of it at depth 2 is 2 * 240 / 240 = 2 units right
    x = unproject([[319.5, 239.5], [559.5, 239.5], [319.5, 479.5]], [4.0, 2.0, 2.0], cam)
    assert np.allclose(x, [[0, 0, 0], [2, 0, 2], [0, -2, 2]], atol=8 * EPS * 4)
    ortho = camera_z(4.0, width=640, height=480, projection="orthographic", ortho_height=2.0)  # 240 px per unit
    x = unproject([[559.5, 239.5]], [4.0], ortho)
    assert np.allclose(x, [[1.0, 0.0, 0.0]], atol=8 * EPS * 4)


@pytest.mark.parametrize("case", cameras_for(1.0, calibrated=True), ids=lambda c: c.name)
def test_reference_inverts_projectpoints(case):
    """OpenCV's projection (distortion included) then the inverse: the points back within their bound."""
    cam = case.camera
    rng = np.random.default_rng(5)
    x = rng.uniform(-1, 1, (400, 3))
    px = cv_project(x, cam)
    seen = np.isfinite(px).all(axis=1)
    d = (x[seen] - cam.position) @ cam.forward
    back = unproject(px[seen], d, cam)
    err = np.linalg.norm(back - x[seen], axis=1)
    assert seen.sum() > 100
    assert (err <= unproject_bound(px[seen], d, cam)).all(), err.max()


# ---------------------------------------------------------------- the check


@pytest.fixture(scope="module")
def correct_report():
    return check_unprojector(U.correct, cases="all")


def test_correct_passes_every_case(correct_report):
    r = correct_report
    assert r["verdict"] == "pass"
    assert [c["camera"] for c in r["cases"][:10]] == list(CASE_NAMES + CALIBRATED_CASE_NAMES)
    assert len(r["cases"]) == 30 and all(c["points"] > 100 for c in r["cases"])
    assert r["compared"]["points"] == sum(c["points"] for c in r["cases"]) > 10000
    assert max(c["max_error_ratio"] for c in r["cases"]) <= 1.0


def test_float32_and_gl_style_pass():
    r = check_unprojector(U.correct_float32)
    assert r["verdict"] == "pass" and {c["precision"] for c in r["cases"]} == {"float32"}
    # the same float32 answers handed back as float64 are held to float64's bound, and fail
    as64 = check_unprojector(lambda p, d, c: U.correct_float32(p, d, c).astype(np.float64), scenes=["cube"], frames=1)
    assert as64["verdict"] == "fail"
    # inverse(P V) on NDC: worse conditioned than K, R, t; within the 1e-6 px floor
    assert check_unprojector(U.gl_unproject)["verdict"] == "pass"


def persp(names):
    return [n for n in names if n != "orthographic"]


#: (unprojector, cases it is a mistake in, the name expected)
MISTAKES = [
    ("half_pixel", CASE_NAMES, "pixel_offset"),
    ("rows_flipped", CASE_NAMES + CALIBRATED_CASE_NAMES, "mirror_vertical"),
    ("horizontal_fov", persp(CASE_NAMES), "fov_mismatch"),
    ("ray_distance", persp(CASE_NAMES) + list(CALIBRATED_CASE_NAMES), "depth_is_range"),
    ("transposed", [n for n in CASE_NAMES if n != "on_axis"] + list(CALIBRATED_CASE_NAMES), "rotation_transposed"),
]


@pytest.fixture(scope="module")
def mistake_reports():
    return {func: check_unprojector(getattr(U, func), cases=list(cases), frames=1) for func, cases, _ in MISTAKES}


def test_each_mistake_named_alone(mistake_reports, summary_section):
    counts = Counter()
    for func, cases, expected in MISTAKES:
        for c in mistake_reports[func]["cases"]:
            got = "+".join(f["name"] for f in c["faults"]) or c["verdict"]
            counts[(expected, got)] += 1
    names = [e for _, _, e in MISTAKES]
    cols = names + sorted({g for _, g in counts} - set(names))
    lines = [
        "unprojector mistakes (rows injected, columns named), 3 scenes, 1 frame each",
        " " * 20 + " ".join(f"{n[:12]:>12}" for n in cols),
    ]
    lines += [f"{r:<20}" + " ".join(f"{counts[(r, c)] or '.':>12}" for c in cols) for r in names]
    summary_section("unprojector confusion matrix", "\n".join(lines))
    assert not {k: v for k, v in counts.items() if k[0] != k[1]}, counts
    assert sum(counts.values()) == 3 * sum(len(c) for _, c, _ in MISTAKES)


def test_fitted_numbers(mistake_reports):
    for c in mistake_reports["half_pixel"]["cases"]:
        p = c["faults"][0]["params"]
        assert p["dx"] == pytest.approx(-0.5, abs=1e-9) and p["dy"] == pytest.approx(-0.5, abs=1e-9)
    cams = {case.name: case.camera for case in cameras_for(1.0)}
    for c in mistake_reports["horizontal_fov"]["cases"]:
        cam = cams[c["camera"]]
        p = c["faults"][0]["params"]
        # K from the horizontal FOV: f' = (W/2) / tan(fov/2), so the scale is f / f' = H / W and the implied
        # vertical FOV 2 atan((H / W) tan(fov / 2))
        assert p["scale"] == pytest.approx(cam.height / cam.width, rel=1e-9)
        want = math.degrees(2 * math.atan(cam.height / cam.width * math.tan(math.radians(cam.fov_y_deg) / 2)))
        assert p["implied_fov_y_deg"] == pytest.approx(want, rel=1e-9)


def test_transposed_is_invisible_where_r_is_symmetric():
    """On axis, R = diag(1, -1, -1) is its own transpose: the mistake changes nothing, and passes."""
    cam = cases_for(load_scene("cube"))[0].camera
    assert np.array_equal(cam.R, cam.R.T)
    assert check_unprojector(U.transposed, cases=["on_axis"], frames=1)["verdict"] == "pass"


def test_failing_candidates_fail_their_cases():
    for func, text in (
        (U.raises, "unprojector RuntimeError: not implemented"),
        (U.wrong_shape, "expected an ("),
        (U.exits, "unprojector SystemExit: 0"),
    ):
        r = check_unprojector(func, scenes=["cube"], cases=["on_axis"], frames=1)
        assert r["verdict"] == "fail" and r["cases"][0]["points"] > 0
        assert text in r["cases"][0]["reasons"][0]
    with pytest.raises(AssertionError, match="mirror_vertical"):
        assert_unprojector(U.rows_flipped, scenes=["cube"], cases=["oblique_roll"], frames=1)
    # a spec string runs isolated: the same verdicts as the callable, float32 precision carried over the wire
    assert check_unprojector(f"{SPEC}:correct", scenes=["cube"], frames=1, cases="all")["verdict"] == "pass"
    r32 = check_unprojector(f"{SPEC}:correct_float32", scenes=["cube"], frames=1)
    assert r32["verdict"] == "pass" and {c["precision"] for c in r32["cases"]} == {"float32"}


def test_never_vacuous():
    cube = load_scene("cube")
    bare = Scene(name="bare", vertices=cube.vertices, edges=cube.edges)  # a wireframe: no surface
    with pytest.raises(InputError, match="compares nothing is no pass"):
        check_unprojector(U.correct, scenes=[bare])
    for bad in ({"frames": 0}, {"cases": ["nope"]}, {"stride": 0}):
        with pytest.raises(InputError):
            check_unprojector(U.correct, **bad)
    with pytest.raises(InputError, match="cannot be called as correct_two"):
        check_unprojector(f"{SPEC}:correct_two")
    with pytest.raises(TypeError):
        check_unprojector(42)


# ---------------------------------------------------------------- the round trip


def mesh_distance_ratios(unproject_func) -> list:
    """Core's depth map of frame 2 of 7 of each scene and default case, every 50th covered pixel
    back-projected by ``unproject_func``: each point's distance to the mesh (trimesh) over its bound.

    A depth error e along forward moves the point by e rho along its ray (rho = |(x_n, y_n, 1)|), so its
    distance to the surface is at most rho e. The depth map is held to a 24-bit buffer's bound
    (metrics.depth_bound); the unprojection adds its own (tolerances.unproject_bound).
    """
    import trimesh

    out = []
    for name in ("cube", "prism", "pyramid"):
        scene = load_scene(name)
        for case in cases_for(scene):
            cam = case.camera
            frames = SceneRenderer(scene, case_motion(Motion(turns=(1.0, 1.0, 0.0)), case), 7, style="shaded")
            frame, _ = frames.render(2, cam)
            covered = np.isfinite(frame.depth_image)
            rows, cols = (a[::50] for a in np.nonzero(covered))
            p_px = np.column_stack([cols, rows]).astype(float)
            d = frame.depth_image[rows, cols]
            x = unproject_func(p_px, d, cam)
            fan = [(f[0], f[k], f[k + 1]) for f in scene.faces for k in range(1, len(f) - 1)]
            dist = np.full(len(x), np.inf)
            for tri in trimesh.Trimesh(frames.world_points(2), fan, process=False).triangles:
                closest = trimesh.triangles.closest_point(np.repeat(tri[None], len(x), axis=0), x)
                dist = np.minimum(dist, np.linalg.norm(closest - x, axis=1))
            k = cam.K
            rho = (
                np.hypot(np.hypot((p_px[:, 0] - k[0, 2]) / k[0, 0], (p_px[:, 1] - k[1, 2]) / k[1, 1]), 1.0)
                if cam.projection == "perspective"
                else 1.0
            )
            bound = rho * depth_bound(frame.depth_image, covered, cam)[rows, cols] + unproject_bound(p_px, d, cam)
            out.append((name, case.name, float((dist / bound).max())))
    return out


def test_depth_map_back_onto_the_mesh():
    ratios = mesh_distance_ratios(U.correct)
    assert len(ratios) == 21 and all(r <= 1.0 for _, _, r in ratios), ratios
    assert max(r for _, _, r in ratios) > 0  # measured: 0.021 at most
    # a half-pixel unprojector misses the mesh somewhere in every case (measured: 18 to 278 bounds)
    assert all(r > 1.0 for _, _, r in mesh_distance_ratios(U.half_pixel))


# ---------------------------------------------------------------- the CLI


def crosscheck(*args):
    """crosscheck in a process of its own; --no-report: no reports/<UTC time>/ folder in the repository
    (the report folder: tests/test_unprojector_report.py)."""
    return subprocess.run(
        [sys.executable, "-m", "wirecheck.oracles.cli", *args, "--no-report"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=300,
    )


def test_cli_pass_fail_error():
    ok = crosscheck("--unprojector", f"{SPEC}:correct", "--scene", "cube", "--frames", "1")
    assert ok.returncode == 0, ok.stderr
    assert "PASS: 7/7 cases" in ok.stdout and "points compared" in ok.stdout
    bad = crosscheck("--unprojector", f"{SPEC}:rows_flipped", "--scene", "cube", "--frames", "1")
    assert bad.returncode == 1 and "mirror_vertical" in bad.stdout and "FAIL: 0/7 cases" in bad.stdout
    assert "rows are not flipped" in bad.stdout  # what to check
    for args in ([f"{SPEC}:nope"], ["nofile.py:f"], [f"{SPEC}:correct", "--cases", "nope"]):
        err = crosscheck("--unprojector", *args, "--scene", "cube")
        assert err.returncode == 2 and err.stdout == "" and len(err.stderr.strip().splitlines()) == 1, err.stderr
    both = crosscheck("--unprojector", f"{SPEC}:correct", "--candidate", f"{SPEC}:correct")
    assert both.returncode == 2 and "--unprojector" in both.stderr
    gone = crosscheck("--unprojector", f"{SPEC}:exits", "--scene", "cube", "--frames", "1", "--cases", "on_axis")
    assert gone.returncode == 1 and "SystemExit" in gone.stdout
    # FILE.py:FUNC runs in its own process: an os._exit(0) fails its case (exit 1), never a pass
    hard = crosscheck("--unprojector", f"{SPEC}:hard_exit", "--scene", "cube", "--frames", "1", "--cases", "on_axis")
    assert hard.returncode == 1 and "FAIL: 0/1 cases" in hard.stdout, (hard.stdout, hard.stderr)


def test_faults_are_short_cells_and_each_kind_hint_once():
    """The assertion's message and the console table show a cell per case (oracles.reports.fault_text,
    <= 60 characters) and what to check once per fault kind, the catalogue's hint for an unprojector."""
    report = check_unprojector(
        U.horizontal_fov, scenes=["cube"], frames=1, cases=["on_axis", "wide_fov", "orthographic"]
    )
    for c in report["cases"]:  # the record's shape: name, params, hint, short
        assert [sorted(f) for f in c["faults"]] == [["hint", "name", "params", "short"]]
        assert type(c["faults"][0]["params"]) is dict
    text = unprojector_failure_text(report)
    cells = re.findall(r": faults: (.*?); ", text)
    # K from the horizontal FOV: f = (W / 2) / tan(fov / 2), so the FOV implied is 2 atan((H / W) tan(fov / 2))
    cams = {case.name: case.camera for case in cases_for(load_scene("cube"))}
    implied = [
        math.degrees(2 * math.atan(c.height / c.width * math.tan(math.radians(c.fov_y_deg) / 2)))
        for c in (cams["on_axis"], cams["wide_fov"])
    ]
    # orthographic: that f taken for its pixels per unit; fov_mismatch is fitted on perspective cameras only
    assert cells == [f"fov_mismatch(fov={implied[0]:.4g})", f"fov_mismatch(fov={implied[1]:.4g})", "unexplained"]
    table = console_lines(report)
    assert [line.split()[-1] for line in table[1:4]] == cells and all(len(c) <= CELL_MAX for c in cells)
    for lines in (text.splitlines(), table):
        checks = [line for line in lines if line.startswith("  what to check, ")]
        assert checks == [
            f"  what to check, fov_mismatch: {CATALOGUE['fov_mismatch'].hints['points']}",
            f"  what to check, unexplained: {CATALOGUE['unexplained'].hints['points']}",
        ]


# ---------------------------------------------------------------- over the protocol

CLIENT = f"{sys.executable} tests/clients/unproject_client.py"


def test_protocol_request_line():
    from wirecheck.oracles.candidates.protocol import camera_text, encode_request

    cam = camera_z(4.0)
    rows = np.array([[1.0, 2.0, 3.0]])
    msg = encode_request(7, rows, camera_text(cam), kind="unproject")
    line, _, payload = bytes(msg).partition(b"\n")
    assert line.startswith(b'{"request":7,"kind":"unproject","n":1,"camera":{')
    assert np.frombuffer(payload, "<f8").tolist() == [1.0, 2.0, 3.0]
    assert b'"kind"' not in bytes(encode_request(7, rows, camera_text(cam)))  # a projection: unchanged


def test_protocol_client(monkeypatch):
    monkeypatch.chdir(ROOT)
    r = check_unprojector(cmd=CLIENT, frames=1)
    assert r["verdict"] == "pass" and r["compared"]["points"] > 10000
    bad = check_unprojector(cmd=f"{CLIENT} --mistake rows_flipped", scenes=["cube"], frames=1, cases=["oblique_roll"])
    assert [f["name"] for f in bad["cases"][0]["faults"]] == ["mirror_vertical"]
    refused = check_unprojector(cmd=f"{CLIENT} --mistake error", scenes=["cube"], frames=1, cases=["on_axis"])
    assert refused["verdict"] == "fail" and "refused on purpose" in refused["cases"][0]["reasons"][0]
    with pytest.raises(InputError, match="expected one of func"):
        check_unprojector(U.correct, cmd=CLIENT)


def test_assert_unprojector_takes_a_program_as_assert_projector_does(monkeypatch):
    """``assert_unprojector(cmd=...)``: the same shape as assert_projector's (the candidate optional when a
    program is given), failing with the program's fault named."""
    monkeypatch.chdir(ROOT)
    with pytest.raises(AssertionError, match="mirror_vertical"):
        assert_unprojector(cmd=f"{CLIENT} --mistake rows_flipped", scenes=["cube"], frames=1, cases=["oblique_roll"])


def test_cli_unprojector_cmd():
    ok = crosscheck("--unprojector-cmd", CLIENT, "--scene", "pyramid", "--frames", "1")
    assert ok.returncode == 0 and "PASS: 7/7 cases" in ok.stdout, ok.stderr
    bad = crosscheck("--unprojector-cmd", f"{CLIENT} --mistake rows_flipped", "--scene", "pyramid", "--frames", "1")
    assert bad.returncode == 1 and "mirror_vertical" in bad.stdout
    both = crosscheck("--unprojector-cmd", CLIENT, "--unprojector", f"{SPEC}:correct")
    assert both.returncode == 2 and "--unprojector-cmd" in both.stderr


@pytest.mark.parametrize("value", ["0", "-1", "nan", "inf", "1e9"])
def test_cli_hostile_candidate_timeout(value, capsys):
    # --candidate-timeout 0 with --unprojector reached SubprocessCandidate's ValueError: exit 3, "internal
    # error" (found by benchmarks/fuzz_round5.py); checked as for --candidate: one line, exit 2
    from wirecheck.oracles import cli

    code = cli.main(
        [
            "--unprojector",
            f"{SPEC}:correct",
            "--scene",
            "cube",
            "--cases",
            "on_axis",
            "--frames",
            "1",
            "--candidate-timeout",
            value,
        ]
    )
    out, err = capsys.readouterr()
    assert code == 2 and out == "" and len(err.strip().splitlines()) == 1, err
    assert err.startswith(f"crosscheck: error: --candidate-timeout {float(value)}: expected a number of seconds > 0")
