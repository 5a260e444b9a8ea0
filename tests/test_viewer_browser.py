"""The viewer in a real browser: headless Chromium driven by tests/browser/viewer_session.mjs.

The session drags, scrolls, shift-drags, toggles the overlay and hidden lines,
types bad values, steps and plays; it records what the page shows. Here the
records are checked against hand-derived numbers (test_viewer.py's docstring:
f = 240 sqrt(3), the camera at (0, 0, 4) turned 90 deg about +Y is at (4, 0, 0)
with right = -Z) and against metrics computed independently.

Needs node, tests/browser/node_modules (npm ci) and /usr/bin/chromium; set up
by tests/browser/setup.sh (CI runs it). Without them the test is skipped with
the reason, unless WIRECHECK_REQUIRE_BROWSER=1 (set by .ci/run), which makes
their absence a failure.
"""

import json
import math
import os
import shutil
import subprocess
import time
from pathlib import Path

import pytest
from numpy.testing import assert_allclose
from wirecheck.core.app.cli import build_parser, settings_from_args
from wirecheck.core.app.viewer import DOLLY_PER_UNIT, STAGES, Viewer
from wirecheck.core.app.viewer_http import Server
from wirecheck.core.camera import look_at
from wirecheck.core.projector.pipeline import render_frame
from wirecheck.core.transforms import Motion

pytestmark = pytest.mark.slow  # an expensive module fixture (tests/conftest.py runs such files first)

BROWSER_DIR = Path(__file__).parent / "browser"
CHROMIUM = os.environ.get("WIRECHECK_CHROMIUM", "/usr/bin/chromium")
F60 = 240.0 * math.sqrt(3.0)
TOL = 1e-9  # a few dozen float64 rotations/scalings of values ~5: far below any sign or axis error


def _missing() -> str | None:
    if shutil.which("node") is None:
        return "node not found"
    if not (BROWSER_DIR / "node_modules" / "playwright-core").is_dir():
        return "tests/browser/node_modules/playwright-core missing (run tests/browser/setup.sh)"
    if not os.access(CHROMIUM, os.X_OK):
        return f"{CHROMIUM} not found (run tests/browser/setup.sh)"
    return None


class _SlowFirst:
    """The overlay, its first answer 1 s late: pyrender's start-up on a cold machine (seconds), which a
    warm one may not show; the page's loading line appears after 0.3 s of waiting (viewer.js)."""

    def __init__(self, overlay):
        self.overlay, self.first = overlay, True

    def __call__(self, *args):
        if self.first:
            self.first = False
            time.sleep(1.0)
        return self.overlay(*args)

    def close(self):
        self.overlay.close()


@pytest.fixture(scope="module")
def session(tmp_path_factory):
    why = _missing()
    if why:
        if os.environ.get("WIRECHECK_REQUIRE_BROWSER") == "1":
            pytest.fail(f"browser test required (WIRECHECK_REQUIRE_BROWSER=1) but {why}")
        pytest.skip(f"browser test skipped: {why}")
    from wirecheck.oracles.live import LiveOverlay
    from wirecheck.oracles.references.pyrender_oracle import osmesa_available  # sets PYOPENGL_PLATFORM first

    ok, why = osmesa_available()
    assert ok, why
    tmp = tmp_path_factory.mktemp("browser")
    s = settings_from_args(build_parser().parse_args(["--frames", "180", "--out", str(tmp / "out")]))
    overlay = _SlowFirst(LiveOverlay())
    server = Server(Viewer(s, overlay=overlay)).start()
    out = tmp / "session.json"
    profiles = tmp / "profiles"  # Chromium's profile goes here, not into the system temporary folder
    profiles.mkdir()
    try:
        proc = subprocess.run(
            ["node", str(BROWSER_DIR / "viewer_session.mjs"), server.url, str(out)],
            capture_output=True,
            text=True,
            timeout=180,
            env=dict(os.environ, WIRECHECK_CHROMIUM=CHROMIUM, WIRECHECK_PROFILE_PARENT=str(profiles)),
        )
    finally:
        server.stop()
    assert proc.returncode == 0, proc.stderr[-3000:]
    data = json.loads(out.read_text())
    data["profiles_left"] = sorted(p.name for p in profiles.iterdir())
    data["by"] = {r["label"]: r for r in data["records"]}
    data["scene"] = s.scene
    return data


def test_the_chromium_profile_is_removed(session):
    """Each session made a wirecheck-chromium-* profile (2-3 MB) and left it in the system temporary folder."""
    assert session["profiles_left"] == []


def test_orbit_drag_moves_a_known_vertex_to_its_predicted_pixel(session):
    start, after = session["by"]["start"]["json"], session["by"]["orbit"]["json"]
    assert_allclose(start["camera"]["position"], (0, 0, 4), atol=TOL)
    # vertex 6 = (1, 1, 1): p_cam = (1, 1, 3) at the start, (-1, 1, 3) after turning 90 deg about +Y
    assert_allclose(start["vertices_px"][6], (319.5 + F60 / 3, 239.5 - F60 / 3), atol=TOL)
    assert_allclose(after["camera"]["position"], (4, 0, 0), atol=TOL)
    assert_allclose(after["camera"]["forward"], (-1, 0, 0), atol=TOL)
    assert_allclose(after["vertices_px"][6], (319.5 - F60 / 3, 239.5 - F60 / 3), atol=TOL)
    assert session["by"]["orbit"]["image"] != session["by"]["start"]["image"]
    assert "position (4.0000, 0.0000, 0.0000)" in session["by"]["orbit"]["cameraText"].replace("-0.0000", "0.0000")


def test_wheel_dollies_and_shift_drag_pans(session):
    d = 4 * math.exp(100 * DOLLY_PER_UNIT)
    assert_allclose(session["by"]["dolly"]["json"]["camera"]["position"], (d, 0, 0), atol=TOL)
    # pan (+50, +30) px: camera and look-at move by (-50 right + 30 up) px, right = -Z, up = +Y,
    # one px = 2 d tan(30 deg) / 480 world units at the look-at distance d
    u = 2 * d * math.tan(math.radians(30)) / 480
    pan = session["by"]["pan"]["json"]
    assert_allclose(pan["view"]["target"], (0, 30 * u, 50 * u), atol=TOL)
    assert_allclose(pan["camera"]["position"], (d, 30 * u, 50 * u), atol=TOL)
    assert session["by"]["pan"]["image"] != session["by"]["dolly"]["image"]
    assert session["by"]["pan"]["command"].startswith("renderer --scene cube --frames 180 --camera-pos=")


def test_overlay_f1_matches_independent_metrics_for_that_view(session):
    from wirecheck.oracles.judge import metrics
    from wirecheck.oracles.references.pyrender_oracle import PyrenderOracle

    ov = session["overlay"]
    v = session["by"]["pan"]["json"]["view"]
    cam = look_at(v["position"], v["target"], v["up"])
    cube = session["scene"]
    m = Motion().frame_matrix(v["frame"], 180)
    core_img = render_frame(cube.vertices, cube.edges, cam, m).image >= 128
    with PyrenderOracle(640, 480) as pr:
        oracle_img, _ = pr.render(cube.vertices, cube.edges, cam, model_matrix=m)
    ps = metrics.pixel_scores(core_img, oracle_img)
    assert ov["f1_0px"] == ps["f1_0px"] and ov["f1_1px"] == ps["f1_1px"]
    assert ov["verdict"] == "pass" and ov["faults"] == []
    assert session["diffSrc"] > 100  # the diff picture was shown


def test_modes_bad_input_and_motion(session):
    by = session["by"]
    assert by["hidden"]["json"]["view"]["hidden_lines"] is True
    assert by["hidden"]["image"] != by["pan"]["image"]
    assert "--hidden-lines" in by["hidden"]["command"]
    assert "fov 'NaN': expected a finite number" in by["fov-nan"]["message"]
    assert by["fov-nan"]["json"]["view"] == by["hidden"]["json"]["view"]
    assert "expected > near" in by["near-far"]["message"]
    assert by["near-far"]["json"]["view"] == by["hidden"]["json"]["view"]
    # the server kept running: a step afterwards works and clears the message
    assert by["step"]["message"] is None and by["step"]["json"]["frame"] == 2
    assert by["played"]["json"]["frame"] > 2


def test_profiler_shows_every_stage_and_the_page_logs_no_errors(session):
    assert session["profileRows"] == list(STAGES) + ["oracle", "transfer", "server", "roundtrip"]
    assert "frames/s over the last" in session["fpsText"]
    assert session["consoleErrors"] == []


def test_rough_edges_loading_banner_controls_reset_reload(session):
    # the first overlay takes seconds (pyrender starts): the page says so meanwhile
    assert session["busyShown"] and "overlay" in session["busyShown"]
    # 1,400 x 900 with the overlay on: the controls' column starts inside the window, right of the panes
    box = session["controlsBox"]
    assert box["x"] + min(box["width"], 300) <= 1400 and 0 <= box["y"] < 900
    # scrolled to the end of a 600-px-high window, the error banner is still at the top of the view
    assert session["messageBox"] is not None and 0 <= session["messageBox"]["y"] < 600
    by = session["by"]
    assert by["played"]["json"]["frame"] > 2
    start = by["start"]["json"]["view"]
    assert by["reset"]["json"]["view"] == start and by["reset"]["json"]["frame"] == 1  # frame reset too
    assert by["reload"]["json"]["view"] == start and session["overlayAfterReload"] is False
