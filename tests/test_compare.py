"""``renderer --compare``: two camera distances and two FOVs, measured from the frames.

Predictions are hand-derived for the unit cube on axis (core/app/compare.py's
docstring): front width 2f/(D-1), back 2f/(D+1), ratio (D+1)/(D-1) = 2 at D = 3
and 1.4 at D = 6, depth compression 1/(D+1); FOV scale tan(30)/tan(45) = 1/sqrt(3).
"""

import json
import math

import numpy as np
import pytest
from helpers import run_renderer as run
from PIL import Image
from wirecheck.core.app.compare import crossings


def test_crossings_are_run_centres():
    img = np.zeros((3, 12), np.uint8)
    img[1, [1, 2, 5, 9, 10, 11]] = 255  # runs [1,2], [5], [9,11]
    assert crossings(img, 1) == [1.5, 5.0, 10.0]
    assert crossings(img, 0) == []


@pytest.fixture(scope="module")
def compared(tmp_path_factory):
    out = tmp_path_factory.mktemp("compare")
    rc, stdout, err = run(["--compare"], out)
    assert rc == 0, err
    return out, stdout, json.loads((out / "cube-compare.json").read_text())


def test_widths_ratios_and_compression_against_the_formulas(compared):
    _, _, report = compared
    views = {(v["camera_z"], v["fov_y_deg"]): v for v in report["views"]}
    assert sorted(views) == [(3.0, 60.0), (3.0, 90.0), (6.0, 60.0), (6.0, 90.0)]
    for (d, fov), v in views.items():
        f = 240.0 / math.tan(math.radians(fov / 2))
        m = v["measured"]
        assert m is not None, (d, fov)
        w_front, w_back = 2 * f / (d - 1), 2 * f / (d + 1)
        # each crossing is a drawn pixel within 0.5 px of the true line: widths within 1 px
        assert abs(m["front_width_px"] - w_front) <= 1.0
        assert abs(m["back_width_px"] - w_back) <= 1.0
        ratio = (d + 1) / (d - 1)  # 2 at D = 3, 1.4 at D = 6
        assert v["predicted"]["ratio"] == pytest.approx(ratio)
        # error propagation of the 1-px bound through wf / wb
        assert abs(m["ratio"] - ratio) <= (1 + ratio) / (w_back - 1)
        assert v["predicted"]["depth_compression"] == pytest.approx(1 / (d + 1))
        assert abs(m["depth_compression"] - 1 / (d + 1)) < 0.01
    assert report["fov_scale_predicted"] == pytest.approx(1 / math.sqrt(3))
    # the front width at D = 3 is ~415 px: 1 px on each of two widths is < 0.5 % of the scale
    assert report["fov_scale_measured"] == pytest.approx(1 / math.sqrt(3), rel=0.005)


def test_picture_and_text(compared):
    out, stdout, _ = compared
    img = np.asarray(Image.open(out / "cube-compare.png"))
    assert img.shape == (2 * 480 + 1, 2 * 640 + 1)  # 2x2 panels, 1-px grey separators
    assert (img[480] == 128).all() and (img[:, 640] == 128).all()
    # the top-left panel (D = 3, FOV 60) has the largest cube: more drawn pixels than the bottom-right
    assert (img[:480, :640] >= 128).sum() > 2 * (img[481:, 641:] >= 128).sum()
    assert "2.000" in stdout and "1.400" in stdout and "0.5774" in stdout
    assert (out / "cube-compare.txt").read_text() == stdout.split("Picture:")[0]


@pytest.mark.parametrize(
    "args, needle",
    [
        (["--compare", "--compare-z", "3"], "--compare-z '3': expected two numbers"),
        (["--compare", "--compare-z", "0.5,6"], "--compare-z 0.5: the scene's front (z = 1)"),
        (["--compare", "--compare-fov", "60,180"], "--compare-fov '60,180'"),
        (["--compare", "--compare-z", "nan,3"], "--compare-z 'nan,3'"),
    ],
)
def test_bad_compare_input(tmp_path, args, needle):
    rc, _, err = run(args, tmp_path)
    assert rc == 2 and needle in err and err.count("\n") == 1
    assert not (tmp_path / "cube-compare.png").exists()


@pytest.mark.parametrize(
    "verts, what",
    [
        ("v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n", "flat in z"),  # no depth: front width = back width
        ("v 0 -1 -1\nv 0 1 -1\nv 0 1 1\nv 0 -1 1\n", "flat in x"),  # no width: nothing to measure
    ],
)
def test_compare_on_a_scene_without_width_or_depth_is_one_error_line(tmp_path, verts, what):
    # Found by the renderer fuzz: such a scene divided by zero (exit 3) in the predicted widths.
    mesh = tmp_path / "flat.obj"
    mesh.write_text(verts + "f 1 2 3 4\n")
    rc, out, err = run(["--scene", str(mesh), "--compare"], tmp_path / "out")
    assert rc == 2, what
    assert "--compare: scene 'flat'" in err and "expected a scene with width in x and depth in z" in err
    assert err.count("\n") == 1 and not (tmp_path / "out").exists()
