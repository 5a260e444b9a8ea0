"""The interactive viewer without a browser: camera controls, frames, bad input, HTTP API, shutdown.

Camera expectations are derived by hand (core.conventions): the camera at
(0, 0, 4) looking at the origin with up +Y has right = +X; turning it 90 deg
about +Y (Rodrigues, right-handed) puts it at (4, 0, 0) with right = -Z.
f = (H/2)/tan(30 deg) = 240 sqrt(3) for the default FOV 60.
"""

import base64
import contextlib
import io
import json
import math
import os
import shlex
import signal
import subprocess
import sys
import threading
import urllib.error
import urllib.request

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal
from PIL import Image
from wirecheck.core.app.cli import build_parser, main, settings_from_args
from wirecheck.core.app.viewer import DOLLY_PER_UNIT, View, Viewer, dolly, orbit, pan
from wirecheck.core.app.viewer_http import Server
from wirecheck.core.camera import look_at
from wirecheck.core.outputs.output import png_bytes
from wirecheck.core.projector.pipeline import render_frame
from wirecheck.core.projector.projection import project_points
from wirecheck.core.transforms import Motion

F60 = 240.0 * math.sqrt(3.0)
# a few float64 rotations of values ~4: 1e-12 is ~10^3 eps x scale
TOL = 1e-12


def settings(tmp_path, *args):
    return settings_from_args(build_parser().parse_args(list(args) + ["--out", str(tmp_path / "out")]))


def start_view(**kw):
    base = dict(
        position=(0.0, 0.0, 4.0),
        target=(0.0, 0.0, 0.0),
        up=(0.0, 1.0, 0.0),
        fov=60.0,
        near=0.1,
        far=100.0,
        ortho_height=4.0,
    )
    base.update(kw)
    return View(**base)


def test_orbit_left_drag_turns_the_camera_90_degrees_about_up():
    v = orbit(start_view(), -180.0, 0.0)  # 180 px x 0.5 deg/px, drag left: camera to +X
    assert_allclose(v.position, (4.0, 0.0, 0.0), atol=TOL)
    assert_allclose(v.up, (0.0, 1.0, 0.0), atol=TOL)
    cam = v.camera(640, 480)
    assert_allclose(cam.right, (0.0, 0.0, -1.0), atol=TOL)
    # vertex (1, 1, 1): p_cam = (right, up, forward) . (p - position) = (-1, 1, 3)
    assert_allclose(project_points(np.array([[1.0, 1.0, 1.0]]), cam)[0], (319.5 - F60 / 3, 239.5 - F60 / 3), atol=1e-9)


def test_orbit_down_drag_raises_the_camera_and_turns_up_with_it():
    v = orbit(start_view(), 0.0, 180.0)  # drag down 90 deg: camera over the top
    assert_allclose(v.position, (0.0, 4.0, 0.0), atol=TOL)
    assert_allclose(v.up, (0.0, 0.0, -1.0), atol=TOL)
    v2 = orbit(v, 0.0, 180.0)  # past the pole: no degenerate up
    assert_allclose(v2.position, (0.0, 0.0, -4.0), atol=TOL)
    assert_allclose(v2.up, (0.0, -1.0, 0.0), atol=TOL)


def test_dolly_scales_the_distance():
    v = dolly(start_view(), 100.0)
    assert_allclose(v.position, (0.0, 0.0, 4.0 * math.exp(100 * DOLLY_PER_UNIT)), atol=TOL)
    assert_allclose(dolly(v, -100.0).position, (0.0, 0.0, 4.0), atol=TOL)


@pytest.mark.parametrize("projection", ["perspective", "orthographic"])
def test_pan_moves_the_look_at_point_with_the_mouse(projection):
    v0 = orbit(start_view(projection=projection), -37.0, 21.0)
    v = pan(v0, 50.0, 30.0, 480)
    cam = v.camera(640, 480)
    # the old look-at point (at the look-at distance) follows the mouse by exactly (50, 30) px
    assert_allclose(project_points(np.array([v0.target]), cam)[0], (319.5 + 50, 239.5 + 30), atol=1e-9)
    assert_allclose(np.subtract(v.position, v.target), np.subtract(v0.position, v0.target), atol=TOL)


def test_frame_is_core_render_frame_byte_for_byte(tmp_path):
    s = settings(tmp_path, "--frames", "12", "--hidden-lines")
    viewer = Viewer(s)
    resp = viewer.respond([{"op": "orbit", "dx": 33, "dy": -17}, {"op": "step", "n": 4}])
    assert resp["error"] is None and resp["view"]["frame"] == 5
    v = viewer.view
    cam = look_at(v.position, v.target, v.up, fov_y_deg=60.0, near=0.1, far=100.0)
    cube = s.scene
    frame = render_frame(
        cube.vertices, cube.edges, cam, Motion().frame_matrix(5, 12), faces=cube.faces, hidden_lines=True
    )
    png = base64.b64decode(resp["image"])
    assert png == png_bytes(frame.image)
    assert_array_equal(np.asarray(Image.open(io.BytesIO(png)).convert("L")), frame.image)  # bilevel PNG: 0/255
    assert resp["vertices_px"][6] == frame.p_px[6].tolist()


def test_the_printed_command_line_writes_the_same_png(tmp_path):
    s = settings(tmp_path, "--frames", "8", "--scene", "prism")
    viewer = Viewer(s)
    resp = viewer.respond(
        [
            {"op": "orbit", "dx": 71, "dy": 40},
            {"op": "dolly", "delta": -130},
            {"op": "pan", "dx": 12, "dy": -9},
            {"op": "set", "field": "axes", "value": True},
            {"op": "set", "field": "cull", "value": True},
            {"op": "step", "n": 2},
        ]
    )
    assert resp["error"] is None
    cmd, comment = resp["command"].split("   # ")
    args = shlex.split(cmd)[1:]
    assert "--cull" in args and "--axes" in args and comment == "frame_0003.png"
    out = tmp_path / "cli"
    with contextlib.redirect_stdout(io.StringIO()):
        assert main(args + ["--out", str(out)]) == 0
    assert (out / "prism-frames" / "frame_0003.png").read_bytes() == base64.b64decode(resp["image"])


@pytest.mark.parametrize(
    "ops, needle",
    [
        ([{"op": "set", "field": "fov", "value": "NaN"}], "fov 'NaN': expected a finite number"),
        ([{"op": "set", "field": "near", "value": "500"}], "expected > near"),
        ([{"op": "set", "field": "fov", "value": "180"}], "camera fov 180.0"),
        (
            [{"op": "set", "field": "style", "value": "shaded"}, {"op": "set", "field": "hidden_lines", "value": True}],
            "hidden lines with style shaded",
        ),
        ([{"op": "set", "field": "colour", "value": "red"}], "field 'colour'"),
        ([{"op": "warp"}], "expected orbit, pan, dolly"),
        ([{"op": "orbit", "dx": "x", "dy": 0}], "dx 'x'"),
        ([{"op": "step", "n": 1.5}], "step 1.5"),
        ("orbit", "ops 'orbit': expected a list"),
    ],
)
def test_bad_input_is_a_message_and_the_view_stays(tmp_path, ops, needle):
    viewer = Viewer(settings(tmp_path, "--frames", "6"))
    before = viewer.respond([{"op": "orbit", "dx": 10, "dy": 0}])
    resp = viewer.respond(ops)
    assert needle in resp["error"]
    assert resp["view"] == before["view"]  # nothing half-applied
    assert resp["image"] == before["image"]


def test_reset_and_step_wrap(tmp_path):
    viewer = Viewer(settings(tmp_path, "--frames", "6"))
    resp = viewer.respond([{"op": "orbit", "dx": 100, "dy": 40}, {"op": "step", "n": -1}, {"op": "reset"}])
    assert list(resp["view"]["position"]) == [0.0, 0.0, 4.0] and resp["view"]["frame"] == 6


def _get(url, data=None):
    req = urllib.request.Request(url, data=data, headers={"Content-Type": "application/json"} if data else {})
    with urllib.request.urlopen(req, timeout=30) as r:
        return r.status, r.headers.get("Content-Type"), r.read()


def test_http_api_and_clean_stop(tmp_path):
    viewer = Viewer(settings(tmp_path, "--frames", "6"))
    server = Server(viewer).start()
    url = server.url
    try:
        status, ctype, body = _get(url)
        assert status == 200 and ctype.startswith("text/html") and b'id="frame"' in body
        assert b"addEventListener" in _get(url + "viewer.js")[2]
        status, _, body = _get(url + "api/frame", json.dumps({"ops": [{"op": "orbit", "dx": -180, "dy": 0}]}).encode())
        resp = json.loads(body)
        assert_allclose(resp["camera"]["position"], (4.0, 0.0, 0.0), atol=TOL)
        assert_allclose(resp["vertices_px"][6], (319.5 - F60 / 3, 239.5 - F60 / 3), atol=1e-9)
        assert set(resp["timing_ms"]) >= {"transform", "clip", "raster", "compose", "encode", "total"}
        with pytest.raises(urllib.error.HTTPError) as exc:
            _get(url + "api/frame", b"{not json")
        assert exc.value.code == 400
        with pytest.raises(urllib.error.HTTPError) as exc:
            _get(url + "etc/passwd")
        assert exc.value.code == 404
        assert json.loads(_get(url + "api/frame")[2])["error"] is None  # still serving
    finally:
        server.stop()
    assert not server.thread.is_alive()
    assert not [t for t in threading.enumerate() if t.name.startswith("wirecheck")]
    with pytest.raises(urllib.error.URLError):
        _get(url + "api/frame")


def test_overlay_f1_equals_metrics_computed_independently(tmp_path):
    from wirecheck.oracles.judge import metrics
    from wirecheck.oracles.live import LiveOverlay
    from wirecheck.oracles.references import opencv_oracle
    from wirecheck.oracles.references.pyrender_oracle import (
        PyrenderOracle,
        osmesa_available,
    )  # sets PYOPENGL_PLATFORM first

    ok, why = osmesa_available()
    assert ok, why  # .ci/setup.sh installs libOSMesa
    s = settings(tmp_path, "--frames", "10")
    overlay = LiveOverlay()
    try:
        viewer = Viewer(s, overlay=overlay)
        resp = viewer.respond([{"op": "orbit", "dx": 47, "dy": 23}, {"op": "step", "n": 3}], want_overlay=True)
    finally:
        overlay.close()
    ov = resp["overlay"]
    v = viewer.view
    cam = look_at(v.position, v.target, v.up)
    m = Motion().frame_matrix(4, 10)
    cube = s.scene
    core_img = render_frame(cube.vertices, cube.edges, cam, m).image >= 128
    with PyrenderOracle(640, 480) as pr:
        oracle_img, _ = pr.render(cube.vertices, cube.edges, cam, model_matrix=m)
    ps = metrics.pixel_scores(core_img, oracle_img)
    p_world = cube.vertices @ m[:3, :3].T + m[:3, 3]
    # F1@0px is over the decided pixels: at a sub-pixel tie the candidate takes the oracle's value
    # (metrics.line_scores' tie_resolved, on OpenCV's segments of the frame)
    from wirecheck.oracles.candidates.draw import oracle_segments

    ls = metrics.line_scores(core_img, oracle_img, *oracle_segments(p_world, cube.edges, cam))
    assert ov["f1_0px"] == (ls["tie_resolved"] or ps)["f1_0px"] and ov["f1_1px"] == ps["f1_1px"]
    assert 0.5 < ps["f1_0px"] <= ov["f1_0px"] <= 1.0  # a real comparison: both drew the cube
    err = np.hypot(*(project_points(p_world, cam) - opencv_oracle.project(p_world, cam)).T).max()
    assert ov["max_vertex_error_px"] == pytest.approx(err, abs=1e-9)
    assert ov["verdict"] == "pass" and ov["faults"] == []
    diff = np.asarray(Image.open(io.BytesIO(base64.b64decode(ov["diff_image"]))))
    assert (diff == 255).all(axis=2).sum() == (core_img & oracle_img).sum()  # white: both drew


def test_interactive_cli_serves_and_stops_on_ctrl_c(tmp_path):
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    proc = subprocess.Popen(
        [sys.executable, "-m", "wirecheck.core.app.cli", "--interactive", "--frames", "4"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
    )
    try:
        line = proc.stdout.readline()
        assert line.startswith("Viewer: http://127.0.0.1:"), line + proc.stderr.read()
        url = line.split()[1]
        assert json.loads(_get(url + "api/frame")[2])["error"] is None
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=20)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 0, err
    assert "Viewer stopped." in out and "Traceback" not in err


def test_bad_port_is_exit_2(tmp_path):
    e = io.StringIO()
    with contextlib.redirect_stderr(e):
        rc = main(["--interactive", "--port", "70000"])  # no --out: --interactive writes nothing
    assert rc == 2 and "--port 70000" in e.getvalue() and e.getvalue().count("\n") == 1
