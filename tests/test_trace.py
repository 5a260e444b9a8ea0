"""``renderer --trace-vertex``: one vertex through model, world, camera, clip, NDC and pixel space.

Expected values are derived by hand from core.conventions' formulas for the
unit cube (vertex 6 = (1, 1, 1)), 640x480, near 0.1, far 100:
f = (H/2)/tan(fov/2); at fov 60, f = 240 sqrt(3) = 415.6922.
"""

import json
import math

import numpy as np
import pytest
from helpers import run_renderer as run
from numpy.testing import assert_allclose
from wirecheck.core.app.trace import clip_matrix, ndc_to_px, trace_vertex
from wirecheck.core.camera import camera_z, look_at
from wirecheck.core.scene.files import load_scene
from wirecheck.core.transforms import Motion

F60 = 240.0 * math.sqrt(3.0)
# float64 arithmetic on values of size ~500 with a handful of operations: 1e-9 is
# ~10^4 eps x scale, far below anything a wrong formula would give
TOL = 1e-9


def test_rest_pose_every_space_by_hand():
    cube = load_scene("cube")
    cam = camera_z(4.0)  # at (0, 0, 4), forward -Z: p_cam = (x, y, 4 - z)
    rec = trace_vertex(cube, Motion(), cam, 6, 1, 180)
    n, f = 0.1, 100.0
    assert rec["model"] == [1.0, 1.0, 1.0]
    assert rec["world"] == [1.0, 1.0, 1.0]  # frame 1 is the rest pose
    assert_allclose(rec["camera"], [1.0, 1.0, 3.0], atol=TOL)
    z_clip = (f + n) / (f - n) * 3.0 - 2 * f * n / (f - n)  # = 2.805806
    assert_allclose(rec["clip"], [2 * F60 / 640, 2 * F60 / 480, z_clip, 3.0], atol=TOL)
    assert_allclose(rec["clip"][:2], [1.2990381056766578, math.sqrt(3.0)], atol=TOL)
    assert_allclose(rec["ndc"], [F60 / 3 / 320, F60 / 3 / 240, z_clip / 3.0], atol=TOL)
    assert_allclose(rec["pixel"], [319.5 + F60 / 3, 239.5 - F60 / 3], atol=TOL)  # (458.0641, 100.9359)
    assert_allclose(rec["pixel_from_ndc"], rec["pixel"], atol=TOL)
    assert rec["visible"] and rec["on_image"]
    assert sorted(tuple(e["edge"]) for e in rec["edges"]) == [(6, 2), (6, 5), (6, 7)]
    assert all(e["status"] == "whole" for e in rec["edges"])


def test_rotated_frame_by_hand():
    # spin 0,1,0 over 4 frames: frame 2 is t = 1/4, Ry(90 deg): (x, y, z) -> (z, y, -x)
    rec = trace_vertex(load_scene("cube"), Motion(turns=(0.0, 1.0, 0.0)), camera_z(4.0), 6, 2, 4)
    assert_allclose(rec["world"], [1.0, 1.0, -1.0], atol=TOL)
    assert_allclose(rec["camera"], [1.0, 1.0, 5.0], atol=TOL)
    assert_allclose(rec["pixel"], [319.5 + F60 / 5, 239.5 - F60 / 5], atol=TOL)


def test_near_plane_clipping_by_hand():
    # camera at z = 1.5, near 1, fov 120 (f = 240 / tan 60 = 138.564): vertex 6 at z_cam 0.5 is
    # behind the near plane; its edge to vertex 2 (z_cam 2.5) enters at t = (1 - 0.5) / (2.5 - 0.5) = 1/4
    f = 240.0 / math.tan(math.radians(60.0))
    cam = camera_z(1.5, fov_y_deg=120.0, near=1.0)
    rec = trace_vertex(load_scene("cube"), Motion(), cam, 6, 1, 10)
    assert not rec["visible"]
    assert rec["ndc"] is None and rec["pixel"] is None
    e = next(e for e in rec["edges"] if e["edge"] == [6, 2])
    assert e["status"] == "clipped" and e["cut_by"] == ["near"]
    # vertex 6 is also above the top edge (y_px = 239.5 - f / 0.5 < -0.5), but the near plane cuts first
    assert e["ends_outside"] == ["near", "top"]
    assert_allclose(e["t"], [0.25, 1.0], atol=TOL)
    assert_allclose(e["ends_camera"], [[1, 1, 1.0], [1, 1, 2.5]], atol=TOL)
    assert_allclose(e["ends_pixel"], [[319.5 + f, 239.5 - f], [319.5 + f / 2.5, 239.5 - f / 2.5]], atol=TOL)
    # edge 6-7 runs at z_cam 0.5 entirely: dropped by the near plane
    assert next(e for e in rec["edges"] if e["edge"] == [6, 7])["status"] == "dropped"


@pytest.mark.parametrize(
    "cam",
    [
        look_at((2.0, 1.5, 2.5), (0, 0, 0), (0.3, 1.0, 0.2), fov_y_deg=55, width=320, height=480, near=0.5, far=9.0),
        look_at((2.0, 2.0, 3.0), (0, 0, 0), projection="orthographic", ortho_height=3.0, near=0.5, far=9.0),
    ],
)
def test_clip_matrix_agrees_with_core_projection(cam):
    """The GL-form clip matrix, divided and mapped to pixels, lands on core's pixels (both projections)."""
    cube = load_scene("cube")
    for i in range(8):
        rec = trace_vertex(cube, Motion(), cam, i, 3, 10)
        assert_allclose(rec["pixel_from_ndc"], rec["pixel"], atol=TOL * 10)
        assert -1.0 <= rec["ndc"][2] <= 1.0  # inside [near, far]
    # boundary values: z_ndc = -1 on the near plane, +1 on the far plane
    p = clip_matrix(cam)
    for z, want in ((cam.near, -1.0), (cam.far, 1.0)):
        c = p @ [0.0, 0.0, z, 1.0]
        assert c[2] / c[3] == pytest.approx(want, abs=1e-12)
    # NDC corners are the image's outer edges
    assert_allclose(
        ndc_to_px(np.array([[-1.0, 1.0, 0.0], [1.0, -1.0, 0.0]]), cam),
        [[-0.5, -0.5], [cam.width - 0.5, cam.height - 0.5]],
        atol=TOL,
    )


def test_cli_prints_and_reports_the_trace(tmp_path):
    rc, out, err = run(["--frames", "4", "--spin", "0,1,0", "--trace-vertex", "6", "--trace-frames", "1,2"], tmp_path)
    assert rc == 0, err
    assert "Trace: vertex 6, frame 1" in out and "Trace: vertex 6, frame 2" in out
    assert "  camera  ( 1.000000,  1.000000,  5.000000)   depth z_cam = 5.000000" in out
    report = json.loads((tmp_path / "cube-report.json").read_text())
    assert [t["frame"] for t in report["trace"]] == [1, 2]
    # the traced pixel is the one the pipeline drew for that frame
    assert_allclose(report["trace"][1]["pixel"], report["frames"][1]["vertices_px"][6], atol=0)


def test_default_trace_frames_are_first_middle_last(tmp_path):
    rc, out, err = run(["--frames", "180", "--format", "ascii", "--trace-vertex", "0"], tmp_path)
    assert rc == 0, err
    report = json.loads((tmp_path / "cube-report.json").read_text())
    assert [t["frame"] for t in report["trace"]] == [1, 90, 180]


@pytest.mark.parametrize(
    "args, needle",
    [
        (["--trace-vertex", "8"], "--trace-vertex 8: scene 'cube' has 8 vertices: expected an index in [0, 7]"),
        (["--trace-vertex", "-1"], "--trace-vertex -1: scene 'cube' has 8 vertices"),
        (["--trace-vertex", "0", "--trace-frames", "0,3"], "--trace-frames '0,3': expected comma-separated"),
        (["--trace-vertex", "0", "--trace-frames", "x"], "--trace-frames 'x'"),
        (["--trace-frames", "1"], "without --trace-vertex"),
    ],
)
def test_bad_trace_input_is_one_line_and_exit_2(tmp_path, args, needle):
    rc, out, err = run(["--frames", "5"] + args, tmp_path / "o")
    assert rc == 2
    assert needle in err and err.count("\n") == 1 and "Traceback" not in err
    assert not (tmp_path / "o" / "cube-report.json").exists()
