"""report.html's enlarged crops: the window with the most disagreement, nearest-neighbour 6x."""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image
from wirecheck.oracles.judge.metrics import DIFF_COLOURS
from wirecheck.oracles.reports.report_crops import CROP_PX, SCALE, crop_image, worst_window

ROOT = Path(__file__).resolve().parent.parent


def _half_pixel_pair():
    """A 40-px horizontal line at y = 100 (candidate) and y = 101 (oracle), x 200..239, in 480x640."""
    cand = np.zeros((480, 640), bool)
    oracle = np.zeros((480, 640), bool)
    cand[100, 200:240] = True
    oracle[101, 200:240] = True
    return cand, oracle


def test_the_window_holds_every_disagreeing_pixel():
    cand, oracle = _half_pixel_pair()
    # 80 pixels disagree (40 each side); every 40x40 window with x0 = 200 and y0 in 62..100 holds all 80;
    # the first in row-major order is y0 = 101 - 39 = 62
    assert worst_window(cand, oracle) == (200, 62, 80)


def test_the_crop_is_the_diff_enlarged_pixel_for_pixel():
    cand, oracle = _half_pixel_pair()
    img, (x0, y0, _) = crop_image(cand, oracle)
    assert img.shape == (CROP_PX * SCALE, CROP_PX * SCALE, 3)
    # image pixel (y 100, x 200) is crop pixel (38, 0): the SCALE x SCALE block at rows 228..233
    red = np.array(DIFF_COLOURS["candidate_only"], np.uint8)
    blue = np.array(DIFF_COLOURS["oracle_only"], np.uint8)
    assert (img[(100 - y0) * SCALE : (101 - y0) * SCALE, 0:SCALE] == red).all()
    assert (img[(101 - y0) * SCALE : (102 - y0) * SCALE, 0:SCALE] == blue).all()
    assert (img[: (100 - y0) * SCALE] == 0).all()  # nothing drawn above the pair


def test_frames_that_agree_give_an_empty_window():
    a = np.zeros((30, 50), bool)
    a[5, 5:20] = True
    assert worst_window(a, a) == (0, 0, 0)  # image smaller than the window: clamped


@pytest.mark.slow
def test_report_html_shows_the_crop_of_a_half_pixel_offset(tmp_path):
    run = tmp_path / "r"
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "wirecheck.oracles.cli",
            "--candidate",
            str(ROOT / "tests/data/user_projector.py") + ":project_corner",
            "--scene",
            "cube",
            "--cases",
            "on_axis",
            "--frames",
            "1",
            "--report-dir",
            str(run),
        ],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 1, done.stderr
    html = (run / "report.html").read_text()
    assert "img/cube-on_axis-crop.png" in html and "diff, 6x: x " in html
    crop = np.asarray(Image.open(run / "img/cube-on_axis-crop.png").convert("RGB"))
    assert crop.shape == (240, 240, 3)
    colours = {tuple(c) for c in crop.reshape(-1, 3)}
    # a half-pixel shift leaves pixels drawn by one side only, in both colours, inside the crop
    assert tuple(DIFF_COLOURS["candidate_only"]) in colours and tuple(DIFF_COLOURS["oracle_only"]) in colours
