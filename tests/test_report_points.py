"""worst_points.png: a vertex-level report's picture, the worst case's points over OpenCV's (issue 26)."""

import math
import sys
from pathlib import Path

import numpy as np
from PIL import Image

from wirecheck.oracles.candidates.core_candidate import CoreCandidate
from wirecheck.oracles.judge.metrics import DIFF_COLOURS
from wirecheck.oracles.runner import run_crosscheck
from helpers import run_crosscheck as run

DATA = Path(__file__).parent / "data"
CORNER = f"{DATA / 'user_projector.py'}:project_corner"   # principal point at (W/2, H/2): off by (+0.5, +0.5)
#: float64 pixels of a 640 x 480 image are exact to ~1e-13 px; 1e-9 px leaves room and still tells 0.5 apart
EPS_PX = 1e-9


def _cube():
    from wirecheck.core.scene.files import load_scene

    return load_scene("cube")


def test_vertex_report_shows_the_worst_points_deterministically(tmp_path):
    args = ("--candidate", CORNER, "--scene", "cube", "--frames", "2", "--cases", "on_axis,oblique_roll",
            "--level", "vertices")
    code, report, a = run(tmp_path, *args, name="a")
    _, _, b = run(tmp_path, *args, name="b")
    assert code == 1 and report["level"] == "vertices"          # the offset fails the 1e-6 px tolerance
    assert (a / "worst_points.png").read_bytes() == (b / "worst_points.png").read_bytes()
    png = Image.open(a / "worst_points.png")
    assert png.format == "PNG" and "Software" not in png.info
    html = (a / "report.html").read_text()
    assert "src='worst_points.png'" in html
    assert "[worst_points.png](worst_points.png)" in (a / "report.md").read_text()
    # both sides are drawn in their diff colours: red crosses (candidate), blue circles (OpenCV);
    # antialiased 1-px strokes reach the colour itself at their centre (within 40 of 255 per channel)
    rgb = np.asarray(png.convert("RGB"), int)
    for side in ("candidate_only", "oracle_only"):
        near = np.abs(rgb - np.array(DIFF_COLOURS[side])).max(axis=2) <= 40
        assert near.sum() > 0, side


def test_the_points_are_the_frame_of_the_worst_vertex():
    sys.path.insert(0, str(DATA))
    try:
        from user_projector import project_corner
    finally:
        sys.path.remove(str(DATA))
    report, images = run_crosscheck([_cube()], project_corner, frames=2, case_names=["on_axis"],
                                    level="vertices", candidate_name="corner")
    points = images["points"]
    cand, orac = points["candidate"], points["oracle"]
    shown = np.isfinite(cand).all(axis=1) & np.isfinite(orac).all(axis=1)
    assert shown.sum() == 8                                       # the cube's 8 corners, all in view
    # hand-derived: cx = W/2 against OpenCV's (W-1)/2, and the same for y: every point (+0.5, +0.5)
    assert np.abs(cand[shown] - orac[shown] - 0.5).max() < EPS_PX
    assert abs(points["error_px"] - math.sqrt(0.5)) < EPS_PX
    v = points["vertex"]
    assert abs(math.hypot(*(cand[v] - orac[v])) - points["error_px"]) < EPS_PX
    worst = report["cases"][0]["worst_vertex"]
    assert (points["scene"], points["camera"], points["frame"], v) == ("cube", "on_axis", worst["frame"],
                                                                       worst["vertex"])
    assert points["size"] == (640, 480)


def test_the_case_with_the_largest_vertex_error_is_shown():
    # float32: each case's error is its own rounding, so the cases differ; measured once: oblique_roll
    # 2.0e-5, wide_fov 2.3e-5, orthographic 2.1e-5 px, the largest in the middle of the run's order (so
    # neither "the first" nor "the last" case passes this test)
    report, images = run_crosscheck([_cube()], CoreCandidate(dtype="float32"), frames=3,
                                    case_names=["oblique_roll", "orthographic", "wide_fov"],
                                    level="vertices")
    errors = {(c["scene"], c["camera"]): c["max_vertex_error_px"] for c in report["cases"]}
    assert len(set(errors.values())) == 3 and max(errors, key=errors.get) == ("cube", "wide_fov")
    points = images["points"]
    assert (points["scene"], points["camera"]) == max(errors, key=errors.get)
    assert points["error_px"] == max(errors.values())


def test_a_pixel_report_has_no_points_figure(tmp_path):
    code, _, out = run(tmp_path, "--scene", "cube", "--frames", "2", "--cases", "on_axis")
    assert code == 0
    assert not (out / "worst_points.png").exists()
    assert "worst_points" not in (out / "report.html").read_text()
    assert "worst_points" not in (out / "report.md").read_text()
