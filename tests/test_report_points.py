"""worst_points.png: a vertex-level report's picture, the worst case's points over OpenCV's (issue 26)."""

import json
import math
import sys
from pathlib import Path

import numpy as np
from helpers import run_crosscheck as run
from PIL import Image
from wirecheck.oracles.candidates.core_candidate import CoreCandidate
from wirecheck.oracles.judge.metrics import DIFF_COLOURS
from wirecheck.oracles.runner import run_crosscheck

DATA = Path(__file__).parent / "data"
CORNER = f"{DATA / 'user_projector.py'}:project_corner"  # principal point at (W/2, H/2): off by (+0.5, +0.5)
#: float64 pixels of a 640 x 480 image are exact to ~1e-13 px; 1e-9 px leaves room and still tells 0.5 apart
EPS_PX = 1e-9


def _cube():
    from wirecheck.core.scene.files import load_scene

    return load_scene("cube")


def test_vertex_report_shows_the_worst_points_deterministically(tmp_path):
    args = (
        "--candidate",
        CORNER,
        "--scene",
        "cube",
        "--frames",
        "2",
        "--cases",
        "on_axis,oblique_roll",
        "--level",
        "vertices",
    )
    code, report, a = run(tmp_path, *args, name="a")
    _, _, b = run(tmp_path, *args, name="b")
    assert code == 1 and report["level"] == "vertices"  # the offset fails the 1e-6 px tolerance
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
    report, images = run_crosscheck(
        [_cube()], project_corner, frames=2, case_names=["on_axis"], level="vertices", candidate_name="corner"
    )
    points = images["points"]
    cand, orac = points["candidate"], points["oracle"]
    shown = np.isfinite(cand).all(axis=1) & np.isfinite(orac).all(axis=1)
    assert shown.sum() == 8  # the cube's 8 corners, all in view
    # hand-derived: cx = W/2 against OpenCV's (W-1)/2, and the same for y: every point (+0.5, +0.5)
    assert np.abs(cand[shown] - orac[shown] - 0.5).max() < EPS_PX
    assert abs(points["error_px"] - math.sqrt(0.5)) < EPS_PX
    v = points["vertex"]
    assert abs(math.hypot(*(cand[v] - orac[v])) - points["error_px"]) < EPS_PX
    worst = report["cases"][0]["worst_vertex"]
    assert (points["scene"], points["camera"], points["frame"], v) == (
        "cube",
        "on_axis",
        worst["frame"],
        worst["vertex"],
    )
    assert points["size"] == (640, 480)


def test_the_case_with_the_largest_vertex_error_is_shown():
    # float32: each case's error is its own rounding, so the cases differ; measured once: oblique_roll
    # 2.0e-5, wide_fov 2.3e-5, orthographic 2.1e-5 px, the largest in the middle of the run's order (so
    # neither "the first" nor "the last" case passes this test)
    report, images = run_crosscheck(
        [_cube()],
        CoreCandidate(dtype="float32"),
        frames=3,
        case_names=["oblique_roll", "orthographic", "wide_fov"],
        level="vertices",
    )
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


# ---------------------------------------------------------------- the fixture's report carries the picture

#: the projector's fault: every point moved by (+16, -100) image px. The cube's corners in on_axis's
#: frame 1 lie on x in {220, 252, 385, 418}, y in {140, 172, 306, 339} px (32 px apart at least), so
#: each cross is at least 16 px (about 14 PNG px) from every circle: no two marks touch. The shift
#: has a sign in y: a plot drawn with y up would put the crosses 100 px the wrong way.
SHIFT_PX = (16.0, -100.0)

SHIFTED = f"""
import json
import numpy as np
from my_projection import project


def shifted(points, camera):
    p_px = project(points, camera) + np.array({SHIFT_PX!r})
    with open("calls.jsonl", "a") as f:      # what the candidate returned, call by call
        f.write(json.dumps({{"n": len(points), "p_px": np.where(np.isnan(p_px), None, p_px).tolist()}}) + "\\n")
    return p_px


def test_shifted(wirecheck):
    wirecheck(shifted, scenes=["cube"], frames=1, cases=["on_axis"], report_dir="own")
"""


def _blobs(rgb: np.ndarray, colour: tuple) -> np.ndarray:
    """Centroids (x, y) in PNG pixels of the marks drawn in ``colour`` (within 40 per channel:
    antialiased 1-px strokes reach the colour at their centre). A mark's pieces (a circle's
    antialiased ring, a cross cut by the black line to the worst vertex) are joined by growing
    them 2 px before they are told apart; marks are >= 14 px apart (SHIFT_PX)."""
    from scipy import ndimage

    mask = np.abs(rgb - np.array(colour)).max(axis=2) <= 40
    labels, n = ndimage.label(ndimage.binary_dilation(mask, iterations=2), structure=np.ones((3, 3)))
    centres = ndimage.center_of_mass(mask, labels, range(1, n + 1))
    return np.array([(x, y) for y, x in centres]).reshape(-1, 2)


def test_the_fixtures_vertex_report_plots_the_points_where_they_were_projected(pytester):
    pytester.makepyfile(my_projection=(DATA / "user_projector.py").read_text())
    pytester.makepyfile(test_user=SHIFTED)
    pytester.syspathinsert()
    result = pytester.runpytest("--wirecheck-report", "reports")
    result.assert_outcomes(failed=1)
    out = pytester.path / "reports" / "test_user.py_test_shifted-c1fc865c"  # + SHA-1 of the id
    assert "src='worst_points.png'" in (out / "report.html").read_text()
    # the call's own report_dir (check_projector's keyword) holds the same report
    own = pytester.path / "own"
    assert (own / "worst_points.png").read_bytes() == (out / "worst_points.png").read_bytes()
    result.stdout.fnmatch_lines(["E         report: own/report.html"])
    # the frame's points as the candidate returned them (one frame: the cube's 8 corners); OpenCV's
    # are these less the shift (user_projector.project agrees with OpenCV to ~1e-13 px:
    # tests/test_api.py), so the expected picture comes from the candidate, not from the plot's code
    calls = [json.loads(line) for line in (pytester.path / "calls.jsonl").read_text().splitlines()]
    frames = {json.dumps(c["p_px"]) for c in calls if c["n"] == 8}
    assert len(frames) == 1
    p_cand = np.array(json.loads(frames.pop()), float)
    p_orac = p_cand - np.array(SHIFT_PX)
    rgb = np.asarray(Image.open(out / "worst_points.png").convert("RGB"), int)
    # the legend (right of the axes) repeats each marker once: keep the axes, left of its right spine,
    # the right-most column with a dark run taller than half the picture
    dark = (rgb.max(axis=2) < 80).sum(axis=0)
    right = int(np.nonzero(dark > rgb.shape[0] // 2)[0].max())
    crosses = _blobs(rgb[:, :right], DIFF_COLOURS["candidate_only"])
    circles = _blobs(rgb[:, :right], DIFF_COLOURS["oracle_only"])
    assert len(crosses) == len(circles) == 8
    # one mapping from image px to PNG px for both sides (aspect equal: one scale, rows down), fitted
    # on the crosses' extents; a mark is its point's place within 1.5 PNG px (a marker's centroid
    # is its centre to ~0.5 px of antialiasing, the fit's scale adds < 0.5 px over 600 px)
    scale = np.ptp(crosses, axis=0) / np.ptp(p_cand, axis=0)
    assert abs(scale[0] - scale[1]) < 0.01 * scale[0]
    offset = crosses.min(axis=0) - scale.mean() * p_cand.min(axis=0)

    def placed(p_px):
        return offset + scale.mean() * p_px

    for marks, p_px in ((crosses, p_cand), (circles, p_orac)):
        d = np.linalg.norm(marks[:, None, :] - placed(p_px)[None, :, :], axis=2)
        assert d.min(axis=0).max() < 1.5 and d.min(axis=1).max() < 1.5  # each point has its mark, and back


def test_the_api_writes_the_same_picture_as_crosscheck(tmp_path):
    # assert_projector(report_dir=...) writes the report crosscheck --report-dir writes for the same run:
    # the same worst_points.png, byte for byte (a report is deterministic), and says where it is
    from wirecheck import assert_projector

    settings = ("--scene", "cube", "--cases", "on_axis", "--frames", "2", "--level", "vertices")
    code, _, cli_dir = run(tmp_path, "--candidate", CORNER, *settings)
    api_dir = tmp_path / "api"
    try:
        assert_projector(CORNER, scenes=["cube"], cases=["on_axis"], frames=2, config=False, report_dir=api_dir)
        raise RuntimeError("a half-pixel offset passed")
    except AssertionError as exc:
        message = str(exc)
    assert code == 1 and message.endswith(f"report: {api_dir / 'report.html'}")
    cli_png = (cli_dir / "worst_points.png").read_bytes()
    assert (api_dir / "worst_points.png").read_bytes() == cli_png
    assert "src='worst_points.png'" in (api_dir / "report.html").read_text()


def test_a_report_dir_that_is_not_a_folder_is_refused_before_the_run(tmp_path):
    import pytest
    from wirecheck import check_projector

    mine = tmp_path / "notes.txt"
    mine.write_text("mine\n")
    with pytest.raises(ValueError, match="notes.txt' is a file: expected a folder"):
        check_projector(CORNER, report_dir=mine, config=False)
    with pytest.raises(TypeError, match="report_dir 42: expected a folder path"):
        check_projector(CORNER, report_dir=42, config=False)
    assert mine.read_text() == "mine\n"
