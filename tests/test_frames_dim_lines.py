"""Lines drawn too dim to count (a grey colour, half alpha) are said to be dim, not a backward camera.

The frames are core's correct drawing of the blank job at level 127 (a pixel counts as drawn from 128:
docs/frames.md), as a grey 8-bit PNG and as white RGBA at alpha 127. Before: the case failed with
``depth_flip`` ("a camera looking backward sees nothing here either"), whose advice is the camera.
"""

from __future__ import annotations

import json

import helpers  # tests/ is on sys.path (rootdir conftest)
import numpy as np
import pytest
from PIL import Image
from wirecheck.oracles import cli as crosscheck_cli


def _grey(img, path):
    Image.fromarray(np.where(img >= 128, 127, 0).astype(np.uint8)).save(path)


def _alpha(img, path):
    rgba = np.zeros(img.shape + (4,), np.uint8)
    rgba[..., :3] = 255
    rgba[..., 3] = np.where(img >= 128, 127, 0)
    Image.fromarray(rgba, "RGBA").save(path)


@pytest.mark.parametrize("write", [_grey, _alpha])
def test_dim_lines_are_named_by_their_level(tmp_path, capsys, write):
    job = helpers.blank_job(tmp_path / "job")
    helpers.fill_job(job)
    for p in sorted((job / "frames/cube/on_axis").glob("*.png")):
        write(np.asarray(Image.open(p)), p)
    assert crosscheck_cli.main(["--candidate-frames", str(job), "--report-dir", str(tmp_path / "r")]) == 1
    capsys.readouterr()
    (case,) = json.loads((tmp_path / "r/report.json").read_text())["cases"]
    assert [f["name"] for f in case["faults"]] == ["unexplained"], case["faults"]
    assert case["faults"][0]["line_level"] == 127
    what_to_check = (tmp_path / "r/report.md").read_text()
    assert "at level 127 of 255" in what_to_check and "Draw the lines white and opaque" in what_to_check


def test_a_blank_frame_keeps_the_diagnosis(tmp_path, capsys):
    """Nothing at all in the frames (level 0): no line level to name; the image diagnosis' fault stays."""
    job = helpers.blank_job(tmp_path / "job")
    assert crosscheck_cli.main(["--candidate-frames", str(job), "--report-dir", str(tmp_path / "r")]) == 1
    capsys.readouterr()
    (case,) = json.loads((tmp_path / "r/report.json").read_text())["cases"]
    assert [f["name"] for f in case["faults"]] == ["depth_flip"]
