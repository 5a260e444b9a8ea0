"""crosscheck's figures: worst.gif (every checked frame of the worst case) and the per-frame plots."""


import numpy as np
import pytest
from PIL import Image

from wirecheck.oracles.metrics import DIFF_COLOURS
from wirecheck.oracles.plots import STRIP_PX, worst_gif
from wirecheck.oracles.runner import worst_key
from helpers import run_crosscheck as run


def gif_frames(path):
    im = Image.open(path)
    frames = []
    for k in range(im.n_frames):
        im.seek(k)
        frames.append(np.asarray(im.convert("RGB")))
    return im.size, frames


def test_worst_gif_has_every_checked_frame_side_by_side(tmp_path):
    code, report, out = run(tmp_path, "--scene", "cube", "--scene", "pyramid", "--frames", "7", "--every", "3",
                            "--cases", "oblique_roll,non_square")
    assert code == 0 and report["frames_checked"] == 3
    worst = report["worst_case"]
    # the worst case: lowest F1@1, then F1@0, then the largest vertex error
    ranked = min(report["cases"], key=worst_key)
    assert (worst["scene"], worst["camera"]) == (ranked["scene"], ranked["camera"])
    assert worst["frames_checked"] == 3 and worst["animation"] == "worst.gif"
    w, h = ranked["camera_spec"]["width"], ranked["camera_spec"]["height"]
    size, frames = gif_frames(out / "worst.gif")
    assert size == (3 * w + 2, h + STRIP_PX)          # ours | oracle | diff, 1-px separators; progress strip
    assert len(frames) == 3                           # one per checked frame (1, 4, 7)
    first = frames[0]
    assert (first[:h, w] == 128).all() and (first[:h, 2 * w + 1] == 128).all()   # grey separators
    colours = {tuple(c) for c in first[:h, 2 * w + 2:].reshape(-1, 3)}
    assert colours <= {(0, 0, 0), *DIFF_COLOURS.values()} and DIFF_COLOURS["both"] in colours
    # the panels are the frames: white where drawn, and the diff agrees with them
    ours, oracle, diff = first[:h, :w, 0] > 0, first[:h, w + 1:2 * w + 1, 0] > 0, first[:h, 2 * w + 2:]
    assert ours.sum() > 100 and (np.all(diff == DIFF_COLOURS["both"], axis=2) == (ours & oracle)).all()
    md, html = (out / "report.md").read_text(), (out / "report.html").read_text()
    assert "[worst.gif](worst.gif)" in md and "src='worst.gif'" in html
    assert f"{worst['scene']} / {worst['camera']}, all 3 checked frames" in md


def test_gif_keeps_identical_frames_apart(tmp_path):
    # no motion: every frame is the same picture; Pillow would merge them without the progress bar
    code, report, out = run(tmp_path, "--scene", "prism", "--frames", "4", "--spin", "0,0,0", "--cases", "on_axis")
    assert code == 0
    _, frames = gif_frames(out / "worst.gif")
    assert len(frames) == 4
    h = report["cases"][0]["camera_spec"]["height"]
    assert all((f[:h] == frames[0][:h]).all() for f in frames)       # same panels, different bars
    # more frames than columns: still one GIF frame each
    blank = [np.zeros((2, 2), bool)] * 20
    data = worst_gif({"candidate": blank, "oracle": blank})
    assert Image.open(__import__("io").BytesIO(data)).n_frames == 20


def test_plots_are_deterministic_and_embedded(tmp_path):
    args = ("--scene", "cube", "--frames", "3", "--cases", "on_axis,orthographic")
    _, _, a = run(tmp_path, *args, name="a")
    _, _, b = run(tmp_path, *args, name="b")
    for name in ("vertex_error.png", "pixels.png", "worst.gif"):
        assert (a / name).read_bytes() == (b / name).read_bytes(), name
    png = Image.open(a / "vertex_error.png")
    assert png.format == "PNG" and "Software" not in png.info
    html = (a / "report.html").read_text()
    assert "src='vertex_error.png'" in html and "src='pixels.png'" in html
    for src in [s.split("'")[0] for s in html.split("src='")[1:]]:
        assert (a / src).is_file(), src
    md = (a / "report.md").read_text()
    assert "[vertex_error.png](vertex_error.png)" in md and "[pixels.png](pixels.png)" in md


def test_level_vertices_plots_vertices_only(tmp_path):
    code, report, out = run(tmp_path, "--level", "vertices", "--scene", "cube", "--frames", "2",
                            "--cases", "on_axis")
    assert code == 0 and "worst_case" not in report
    assert (out / "vertex_error.png").is_file()
    assert not (out / "worst.gif").exists() and not (out / "pixels.png").exists()


def test_plots_survive_zero_none_and_failing_cases(tmp_path):
    empty = tmp_path / "empty.scene"
    empty.write_text("# nothing\n")
    code, _, out = run(tmp_path, "--scene", str(empty), "--scene", "cube", "--frames", "1", "--cases", "on_axis",
                       "--tol-px", "0")          # tolerance 0: no line on the log axis, and the cube fails
    assert code == 1 and (out / "vertex_error.png").is_file() and (out / "worst.gif").is_file()


@pytest.mark.parametrize("style", ["shaded"])
def test_shaded_plot_has_iou_and_depth(tmp_path, style):
    code, report, out = run(tmp_path, "--style", style, "--scene", "cube", "--frames", "2", "--cases", "on_axis")
    assert code == 0 and (out / "pixels.png").is_file()
    size, frames = gif_frames(out / "worst.gif")
    assert len(frames) == 2 and size[0] == 3 * 640 + 2
    assert "per-frame silhouette IoU and depth error / bound" in (out / "report.md").read_text()
