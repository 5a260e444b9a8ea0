"""The ``renderer`` CLI: output lines, JSON report, PNG frames, determinism, bad input.

In-process through core.app.cli.main([...]) (stdout/stderr captured), plus one
subprocess run of the installed entry point.
"""

import json
import math
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from helpers import run_renderer as run
from numpy.testing import assert_allclose, assert_array_equal
from PIL import Image
from wirecheck.core.camera import camera_z, look_at
from wirecheck.core.errors import InputError
from wirecheck.core.outputs.output import MARKER

EPS = np.finfo(np.float64).eps
SEED_ARGS = ["--scene", "cube", "--frames", "180", "--camera-z", "4.0", "--fov", "70"]
CUBE = [(-1, -1, -1), (1, -1, -1), (1, 1, -1), (-1, 1, -1), (-1, -1, 1), (1, -1, 1), (1, 1, 1), (-1, 1, 1)]
F70 = 240.0 / math.tan(math.radians(35.0))  # f = (H/2)/tan(fov/2) = 342.7555


def naive_depth_range(k, frames, turns=(1.0, 1.0, 0.0), d=4.0):
    """Depths (d - z_world) of the cube at frame k: Rx(ax) then Ry(ay), plain math."""
    t = (k - 1) / frames
    ax, ay = 2 * math.pi * t * turns[0], 2 * math.pi * t * turns[1]
    depths = []
    for x, y, z in CUBE:
        z1 = math.sin(ax) * y + math.cos(ax) * z  # only z matters for depth
        z2 = -math.sin(ay) * x + math.cos(ay) * z1
        depths.append(d - z2)
    return min(depths), max(depths)


def seed_expected_stdout(out):
    lines = [
        "Scene: cube (8 vertices, 12 edges)",
        # rest pose: depths 4 - 1 = 3 and 4 + 1 = 5
        "Frame 001: visible_vertices=8 clipped=0 depth=[3.00, 5.00]",
    ]
    for k in (90, 180):  # frames >= 180 print 1, frames // 2, frames
        lo, hi = naive_depth_range(k, 180)
        lines.append(f"Frame {k:03d}: visible_vertices=8 clipped=0 depth=[{lo:.2f}, {hi:.2f}]")
    lines += [f"Exported frames: {out}/cube-frames/", f"Summary: {out}/cube-report.txt"]
    return "\n".join(lines) + "\n"


@pytest.fixture(scope="module")
def seed_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("seed") / "out"
    rc, stdout, stderr = run(SEED_ARGS, out)
    return out, rc, stdout, stderr


# ---- the seed command ----------------------------------------------------------------


def test_seed_command_prints_six_lines(seed_run):
    out, rc, stdout, stderr = seed_run
    assert (rc, stderr) == (0, "")
    assert stdout == seed_expected_stdout(out)
    assert len(stdout.splitlines()) == 6


def test_seed_depth_lines_are_not_at_rounding_ties():
    # guard for the exact-text comparison above: the naive depths are not within float
    # noise (1e-12) of a .xx5 rounding boundary
    for k in (90, 180):
        for v in naive_depth_range(k, 180):
            assert abs((v * 100) % 1 - 0.5) > 1e-6


def test_seed_json_scene_and_camera(seed_run):
    out = seed_run[0]
    rep = json.loads((out / "cube-report.json").read_text())
    assert rep["scene"]["name"] == "cube"
    assert (rep["scene"]["vertices"], rep["scene"]["edges"]) == (8, 12)
    cam = rep["camera"]
    assert cam["position"] == [0.0, 0.0, 4.0]
    assert cam["forward"] == [0.0, 0.0, -1.0]
    assert cam["up"] == [0.0, 1.0, 0.0]
    assert (cam["fov_y_deg"], cam["width"], cam["height"]) == (70.0, 640, 480)
    assert (cam["near"], cam["far"], cam["projection"]) == (0.1, 100.0, "perspective")
    assert len(rep["frames"]) == 180
    assert [f["frame"] for f in rep["frames"]] == list(range(1, 181))


def test_seed_json_frame_one_hand_derived(seed_run):
    out = seed_run[0]
    fr = json.loads((out / "cube-report.json").read_text())["frames"][0]
    assert set(fr) == {"frame", "visible_vertices", "clipped", "clipped_edges", "min_depth", "max_depth", "vertices_px"}
    assert (fr["visible_vertices"], fr["clipped"], fr["clipped_edges"]) == (8, 0, 0)
    assert (fr["min_depth"], fr["max_depth"]) == (3.0, 5.0)
    # rest pose, camera_z(4): p_cam = (x, y, 4 - z); pixel (319.5 + f x/(4-z), 239.5 - f y/(4-z)),
    # f = 240/tan 35: e.g. corner (-1,-1,-1): (319.5 - f/5, 239.5 + f/5) = (250.949, 308.051)
    expected = [[319.5 + F70 * x / (4 - z), 239.5 - F70 * y / (4 - z)] for x, y, z in CUBE]
    # values <= 640 after ~6 float64 operations: 6 * 1.1e-16 * 640 = 4e-13 (JSON floats round-trip)
    assert_allclose(fr["vertices_px"], expected, rtol=0, atol=1e-12)
    assert_allclose(fr["vertices_px"][0], [319.5 - F70 / 5, 239.5 + F70 / 5], rtol=0, atol=1e-12)


def test_seed_json_drawing_defaults_and_objects(seed_run):
    rep = json.loads((seed_run[0] / "cube-report.json").read_text())
    assert rep["drawing"] == {
        "projection": "perspective",
        "axes": False,
        "axis_length": None,
        "cull": None,
        "hidden_lines": False,
        "style": "wireframe",
        "light": None,
        "object_culling": True,
    }
    assert rep["scene"]["objects"] == [
        {"name": "cube", "vertices": 8, "spin": [0.0, 0.0, 0.0], "translate": [0.0, 0.0, 0.0], "scale": 1.0}
    ]
    assert "camera_orthographic" not in rep and "objects_culled" not in rep["summary"]
    assert not (seed_run[0] / "cube-plots.png").exists()  # --plots is off by default


@pytest.mark.parametrize("k", [2, 46, 90, 135, 180])
def test_seed_json_depths_match_naive(seed_run, k):
    fr = json.loads((seed_run[0] / "cube-report.json").read_text())["frames"][k - 1]
    # depth 4 - z of rotated unit-cube corners (|z| <= sqrt 3): ~6 roundings of values <= 6
    assert_allclose([fr["min_depth"], fr["max_depth"]], naive_depth_range(k, 180), rtol=0, atol=6 * EPS * 6)


def test_seed_png_frames(seed_run):
    out = seed_run[0]
    names = sorted(n for n in os.listdir(out / "cube-frames") if n != MARKER)
    assert names == [f"frame_{k:04d}.png" for k in range(1, 181)]
    img = np.asarray(Image.open(out / "cube-frames" / "frame_0001.png").convert("L"))
    assert img.shape == (480, 640) and img.dtype == np.uint8
    assert set(np.unique(img).tolist()) == {0, 255}
    # rest pose: front face corners at 319.5 +- f/3 = 205.25 / 433.75 (cols 205..434),
    # rows 239.5 -+ f/3 = 125.25 / 353.75: the drawing spans those pixel ranges exactly
    # (to within the rasteriser's choice of end pixels: +-1)
    rows, cols = np.nonzero(img)
    assert abs(rows.min() - 125) <= 1 and abs(rows.max() - 354) <= 1
    assert abs(cols.min() - 205) <= 1 and abs(cols.max() - 434) <= 1


def test_seed_summary_txt(seed_run):
    txt = (seed_run[0] / "cube-report.txt").read_text()
    assert txt.startswith("Scene: cube (8 vertices, 12 edges) from scenes/cube.scene\n")
    assert "Frames: 180 (0 with clipping)" in txt


def test_determinism_byte_identical_png_and_json(seed_run, tmp_path):
    a = seed_run[0]
    b = tmp_path / "again"
    rc, _, _ = run(SEED_ARGS, b)
    assert rc == 0
    assert (a / "cube-report.json").read_bytes() == (b / "cube-report.json").read_bytes()
    fa = sorted(n for n in os.listdir(a / "cube-frames") if n != MARKER)
    fb = sorted(n for n in os.listdir(b / "cube-frames") if n != MARKER)
    assert fa == fb and len(fa) == 180
    for name in fa:
        assert (a / "cube-frames" / name).read_bytes() == (b / "cube-frames" / name).read_bytes(), name


def test_subprocess_entry_point(tmp_path):
    exe = shutil.which("renderer", path=str(Path(sys.executable).parent))
    cmd = [exe] if exe else [sys.executable, "-m", "wirecheck.core.app.cli"]
    out = tmp_path / "sub"
    proc = subprocess.run(cmd + SEED_ARGS + ["--out", str(out)], capture_output=True, text=True, timeout=120)
    assert (proc.stdout, proc.stderr, proc.returncode) == (seed_expected_stdout(out), "", 0)


# ---- image orientation ---------------------------------------------------------------


def test_png_row_zero_is_top(tmp_path):
    # pyramid at rest, camera_z(4), fov 70: apex (0,1,0) at depth 4 -> y = 239.5 - f/4 =
    # 153.81 (the TOP of the drawing), front base corners (+-1,-1,1) at depth 3 ->
    # y = 239.5 + f/3 = 353.75 (the bottom). A vertically flipped PNG would span
    # 479 - 354 = 125 .. 479 - 154 = 325 instead.
    rc, _, _ = run(["--scene", "pyramid", "--frames", "1", "--camera-z", "4", "--fov", "70"], tmp_path)
    assert rc == 0
    img = np.asarray(Image.open(tmp_path / "pyramid-frames" / "frame_0001.png").convert("L"))
    rows = np.nonzero(img)[0]
    assert abs(rows.min() - round(239.5 - F70 / 4)) <= 1
    assert abs(rows.max() - round(239.5 + F70 / 3)) <= 1


# ---- bad input ---------------------------------------------------------------------------


def bad_cases(tmp):
    bad_scene = tmp / "bad.scene"
    bad_scene.write_text("v 0 0 0\nv 1 zz 0\n")
    a_file = tmp / "regular_file"
    a_file.write_text("x")
    return [
        # (args, substrings the single stderr line must contain)
        (["--scene", str(bad_scene)], [f"{bad_scene}:2:", "'zz'"]),
        (["--scene", "nosuchscene"], ["'nosuchscene'"]),
        (["--fov", "0"], ["--fov 0.0"]),
        (["--fov", "180"], ["--fov 180.0"]),
        (["--fov", "-5"], ["--fov -5.0"]),
        (["--frames", "0"], ["--frames 0"]),
        (["--camera-pos", "0,5,0", "--look-at", "0,0,0", "--up", "0,1,0"], ["up [0.0, 1.0, 0.0]", "parallel"]),
        (["--camera-pos", "1,2,3", "--look-at", "1,2,3"], ["[1.0, 2.0, 3.0]", "look-at"]),
        (["--camera-z", "0"], ["--camera-z 0.0"]),
        (["--frames", "abc"], ["'abc'"]),  # argparse: SystemExit(2)
    ], a_file


BAD_IDS = [
    "malformed-scene",
    "unknown-scene",
    "fov0",
    "fov180",
    "fov-5",
    "frames0",
    "up-parallel",
    "at-look-at",
    "camera-z0",
    "frames-not-int",
]


@pytest.mark.parametrize("i", range(len(BAD_IDS)), ids=BAD_IDS)
def test_bad_input_one_line_exit_2_nothing_written(tmp_path, i):
    cases, _ = bad_cases(tmp_path)
    args, needles = cases[i]
    out = tmp_path / "out"
    rc, stdout, stderr = run(args, out)
    assert rc == 2
    assert stdout == ""
    lines = stderr.splitlines()
    assert len(lines) == 1 and stderr.endswith("\n")
    assert lines[0].startswith("renderer: error: ")
    for n in needles:
        assert n in lines[0]
    assert "Traceback" not in stderr
    assert not out.exists()  # all checks happen before the output dir is touched


def test_unwritable_out_under_a_regular_file(tmp_path):
    _, a_file = bad_cases(tmp_path)
    out = a_file / "sub"
    rc, stdout, stderr = run(["--frames", "1"], out)
    assert (rc, stdout) == (2, "")
    assert len(stderr.splitlines()) == 1
    assert f"--out '{out}'" in stderr and "Traceback" not in stderr
    assert a_file.read_text() == "x"
    assert sorted(os.listdir(tmp_path)) == ["bad.scene", "regular_file"]


def test_bad_input_subprocess_no_traceback(tmp_path):
    # the same contract through a real process (stderr must be exactly one line)
    proc = subprocess.run(
        [sys.executable, "-m", "wirecheck.core.app.cli", "--fov", "0", "--out", str(tmp_path / "o")],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert (proc.returncode, proc.stdout) == (2, "")
    assert proc.stderr == "renderer: error: --fov 0.0: expected degrees in (0, 180)\n"


# ---- non-finite input and up parallel to forward --------------------------------------

#: (args, strings the one stderr line must contain): every camera option rejects NaN and inf.
NONFINITE_ARGS = [
    (["--camera-pos", "nan,0,4"], ["--camera-pos", "nan"]),
    (["--camera-pos", "0,inf,4"], ["--camera-pos", "inf"]),
    (["--camera-pos", "1,2,3", "--look-at", "0,nan,0"], ["--look-at", "nan"]),
    (["--camera-pos", "1,2,3", "--up", "0,-inf,0"], ["--up", "inf"]),
    (["--fov", "inf"], ["--fov", "inf"]),
    (["--fov", "nan"], ["--fov", "nan"]),
    (["--camera-z", "nan"], ["--camera-z", "nan"]),
    (["--camera-z=-inf"], ["--camera-z", "inf"]),  # "--camera-z -inf": argparse takes -inf for an option
    (["--near", "nan"], ["near", "nan"]),
    (["--far", "inf"], ["far", "inf"]),
    (["--projection", "orthographic", "--ortho-height", "nan"], ["ortho-height", "nan"]),
    (["--scale", "inf"], ["--scale", "inf"]),
    (["--spin", "nan,0,0"], ["--spin", "nan"]),
    (["--translate", "0,0,inf"], ["--translate", "inf"]),
    # up parallel and anti-parallel (scaled) to forward: |forward x up| = 0 (core/camera.py)
    (["--camera-pos", "0,5,0", "--look-at", "0,0,0", "--up", "0,1,0"], ["up"]),
    (["--camera-pos", "0,5,0", "--look-at", "0,0,0", "--up", "0,-3,0"], ["up"]),
]

#: (file name, text, the line the error must name, the token it must quote)
NONFINITE_SCENES = [
    ("nan_vertex.scene", "# a NaN vertex on line 3\nv 0 0 0\nv nan 1 0\nv 1 1 1\ne 0 1\ne 1 2\n", 3, "nan"),
    ("inf_vertex.scene", "v 0 0 0\nv 1 1 1\nv 0 -inf 0\ne 0 1\ne 1 2\n", 3, "-inf"),
    ("overflow_vertex.scene", "v 0 0 0\nv 1e999 1 1\ne 0 1\n", 2, "1e999"),
    ("nan_vertex.obj", "v 0 0 0\nv 1 1 1\nv 1 NaN 0\nf 1 2 3\n", 3, "NaN"),
]


def assert_one_error_line(rc, stdout, stderr, needles):
    """Exit 2, nothing on stdout, one 'renderer: error:' line on stderr naming every needle."""
    lines = stderr.splitlines()
    assert (rc, stdout) == (2, ""), stderr
    assert len(lines) == 1 and lines[0].startswith("renderer: error: "), stderr
    assert "Traceback" not in stderr
    for n in needles:
        assert n in lines[0], (n, lines[0])


@pytest.mark.parametrize("args, needles", NONFINITE_ARGS, ids=[" ".join(a) for a, _ in NONFINITE_ARGS])
def test_nonfinite_or_parallel_camera_one_line_exit_2(tmp_path, args, needles):
    out = tmp_path / "out"
    assert_one_error_line(*run(args + ["--frames", "2"], out), needles)
    assert not out.exists()


@pytest.mark.parametrize("fname, text, line, token", NONFINITE_SCENES, ids=[s[0] for s in NONFINITE_SCENES])
def test_nonfinite_vertex_names_file_line_and_value(tmp_path, fname, text, line, token):
    path = tmp_path / fname
    path.write_text(text)
    out = tmp_path / "out"
    assert_one_error_line(*run(["--scene", str(path), "--frames", "2"], out), [f"{path}:{line}:", token])
    assert not out.exists()


def test_nonfinite_input_subprocess_no_traceback(tmp_path):
    # the same contract through real processes: a NaN camera argument and a NaN vertex in a file
    fname, text, line, token = NONFINITE_SCENES[0]
    (tmp_path / fname).write_text(text)
    for args, needles in (
        (["--camera-pos", "nan,0,4"], ["--camera-pos", "nan"]),
        (["--scene", str(tmp_path / fname)], [f"{tmp_path / fname}:{line}:", token]),
    ):
        proc = subprocess.run(
            [sys.executable, "-m", "wirecheck.core.app.cli", *args, "--frames", "2", "--out", str(tmp_path / "o")],
            capture_output=True,
            text=True,
            timeout=120,
        )
        assert_one_error_line(proc.returncode, proc.stdout, proc.stderr, needles)


@pytest.mark.parametrize(
    "up", [(0.0, 1.0, 0.0), (0.0, -1.0, 0.0), (0.0, 1e-3, 0.0)], ids=["parallel", "anti-parallel", "parallel-scaled"]
)
def test_look_at_rejects_up_parallel_to_forward(up):
    # |forward x up| = 0 < 1e-9 |up| (core/camera.py): InputError, no other exception type
    with pytest.raises(InputError, match="parallel"):
        look_at((0.0, 5.0, 0.0), (0.0, 0.0, 0.0), up)


def test_look_at_up_1e_minus_6_off_forward_is_orthonormal():
    # a valid (if odd) camera, not an error. forward = (0, -1, 0) exactly, so forward x up =
    # (0, 0, 1e-6) has no rounding: only the normalisations round (~1 eps each); 8 eps allows them
    cam = look_at((0.0, 5.0, 0.0), (0.0, 0.0, 0.0), (1e-6, 1.0, 0.0))
    b = np.stack([cam.right, cam.up, cam.forward])
    assert np.abs(b @ b.T - np.eye(3)).max() <= 8 * EPS


# ---- empty mesh ------------------------------------------------------------------------


def test_empty_mesh_renders_blank_frames(tmp_path):
    scene = tmp_path / "empty.scene"
    scene.write_text("name empty\n")
    out = tmp_path / "out"
    rc, stdout, stderr = run(["--scene", str(scene), "--frames", "3"], out)
    assert (rc, stderr) == (0, "")
    assert stdout.splitlines() == [
        "Scene: empty (0 vertices, 0 edges)",
        "Frame 001: visible_vertices=0 clipped=0 depth=[none]",
        "Frame 002: visible_vertices=0 clipped=0 depth=[none]",
        "Frame 003: visible_vertices=0 clipped=0 depth=[none]",
        f"Exported frames: {out}/empty-frames/",
        f"Summary: {out}/empty-report.txt",
    ]
    for k in (1, 2, 3):
        img = np.asarray(Image.open(out / "empty-frames" / f"frame_{k:04d}.png").convert("L"))
        assert img.shape == (480, 640) and not img.any()
    rep = json.loads((out / "empty-report.json").read_text())
    assert (rep["scene"]["vertices"], rep["scene"]["edges"]) == (0, 0)
    for fr in rep["frames"]:
        assert fr["visible_vertices"] == fr["clipped"] == fr["clipped_edges"] == 0
        assert fr["min_depth"] is None and fr["max_depth"] is None and fr["vertices_px"] == []
    assert rep["summary"]["min_depth"] is None


# ---- clip modes through the CLI ------------------------------------------------------------


def test_clip_mode_endpoint_draws_subset_of_clip(tmp_path):
    # camera inside the cube (z = 0.5): the 4 edges along z cross the near plane.
    common = ["--scene", "cube", "--frames", "1", "--camera-z", "0.5", "--fov", "70"]
    assert run(common + ["--clip", "clip"], tmp_path / "c")[0] == 0
    assert run(common + ["--clip", "endpoint"], tmp_path / "e")[0] == 0
    c = np.asarray(Image.open(tmp_path / "c" / "cube-frames" / "frame_0001.png").convert("L")) > 0
    e = np.asarray(Image.open(tmp_path / "e" / "cube-frames" / "frame_0001.png").convert("L")) > 0
    # endpoint keeps only the back face square (cols 91..548, rows 11..468, see
    # test_clipping); clip adds the 4 diagonals, 11-12 pixels each, running to rows 0 / 479
    assert not (e & ~c).any()
    assert 4 * 10 <= c.sum() - e.sum() <= 4 * 13
    assert not e[:11].any() and not e[469:].any()
    assert c[0].any() and c[479].any()
    rc = json.loads((tmp_path / "c" / "cube-report.json").read_text())
    re_ = json.loads((tmp_path / "e" / "cube-report.json").read_text())
    assert (rc["clip"], re_["clip"]) == ("clip", "endpoint")
    for r in (rc, re_):
        f = r["frames"][0]
        assert (f["visible_vertices"], f["clipped"], f["clipped_edges"]) == (4, 4, 8)
        assert sum(v is None for v in f["vertices_px"]) == 4


# ---- sidecar -----------------------------------------------------------------------------


def test_sidecar_for_large_scene(tmp_path):
    trimesh = pytest.importorskip("trimesh")
    ico = trimesh.creation.icosphere(subdivisions=5)  # 10 * 4^5 + 2 = 10242 vertices
    path = tmp_path / "ico.ply"
    ico.export(path)
    out = tmp_path / "out"
    rc, stdout, stderr = run(["--scene", str(path), "--frames", "2"], out)
    assert (rc, stderr) == (0, "")
    n = 10 * 4**5 + 2
    assert stdout.splitlines()[0] == f"Scene: ico ({n} vertices, {3 * n - 6} edges)"  # Euler: E = 3V - 6
    rep = json.loads((out / "ico-report.json").read_text())
    assert rep["vertices_px_file"] == "ico-vertices_px.npy"
    assert all("vertices_px" not in fr for fr in rep["frames"])
    px = np.load(out / rep["vertices_px_file"])
    assert px.shape == (2, n, 2) and px.dtype == np.float64
    cam = camera_z(4.0, fov_y_deg=60.0, width=640, height=480, near=0.1, far=100.0)
    # the PLY holds the coordinates as float32: read them back (independently of core)
    v = np.asarray(trimesh.load(path, process=False).vertices, dtype=np.float64)
    assert_allclose(v, ico.vertices, rtol=0, atol=1.2e-7)  # float32 eps 1.2e-7 x |v| = 1
    # frame 1 is the rest pose; frame 2 uses the default spin (1,1,0) at t = 1/2.
    # The reference is independent of core: scipy's model matrix and
    # cv2.projectPoints (oracles/). Two float64 pipelines with different
    # operations: ~20 roundings of values <= 640 px each, 20 * EPS * 640 ~ 3e-12;
    # 1e-9 px leaves margin and any convention error is >= 0.5 px.
    from wirecheck.oracles.references import opencv_oracle
    from wirecheck.oracles.references.convert import model_matrix

    for k in (1, 2):
        m = model_matrix((1.0, 1.0, 0.0), (0.0, 0.0, 0.0), 1.0, (k - 1) / 2)
        want = opencv_oracle.project(v @ m[:3, :3].T + m[:3, 3], cam)
        assert_array_equal(np.isnan(px[k - 1]), np.isnan(want))
        assert_allclose(px[k - 1], want, rtol=0, atol=1e-9)


# ---- finite but extreme scene coordinates ------------------------------------------------


def test_huge_finite_vertex_is_not_a_crash(tmp_path):
    """A scene the parser accepts (all coordinates finite) must not end in a traceback.

    v 1e308 0 0 is visible at depth 4, but f * x / z = 343 * 1e308 / 4 overflows to inf:
    the run must either report it (exit 2, one line) or write valid JSON (no inf/NaN).
    """
    scene = tmp_path / "huge.scene"
    scene.write_text("v 1e308 0 0\nv 0 0 0\ne 0 1\n")
    out = tmp_path / "out"
    try:
        rc, stdout, stderr = run(["--scene", str(scene), "--frames", "1", "--fov", "70"], out)
    except Exception as exc:  # noqa: BLE001 - the failure being tested for
        pytest.fail(f"renderer raised {type(exc).__name__}: {exc}")
    assert "Traceback" not in stderr
    if rc == 2:
        assert len(stderr.splitlines()) == 1
        assert not (out / "huge-report.json").exists()
    else:
        assert rc == 0
        rep = json.loads((out / "huge-report.json").read_text())  # strict JSON parsed back
        for xy in rep["frames"][0]["vertices_px"]:
            assert xy is None or all(math.isfinite(v) for v in xy)


# ---- --help and the progress bar ---------------------------------------------------


def test_every_option_has_help_with_its_default_and_no_markup():
    from helpers import assert_help_states_defaults
    from wirecheck.core.app.cli import build_parser

    assert_help_states_defaults(build_parser())


def test_progress_counts_every_frame_and_the_animation_encoding(tmp_path):
    """One step per frame rendered, per GIF frame encoded (as it is rendered), and the MP4 flush.

    6 frames: 6 GIF steps, each before its frame's render step, then the
    MP4 flush: 6 + 6 + 1 = 13 = progress_steps.
    """
    from wirecheck.core.app.cli import build_parser, settings_from_args
    from wirecheck.core.app.run import progress_steps, render_run

    s = settings_from_args(build_parser().parse_args(["--frames", "6", "--format", "gif,mp4", "--out", str(tmp_path)]))
    stages = []
    render_run(s, progress=stages.append)
    assert stages == ["gif", "render"] * 6 + ["mp4"]
    assert len(stages) == progress_steps(s) == 13
