"""crosscheck's figures: worst.gif (every checked frame of the worst case) and the per-frame plots."""

import numpy as np
import pytest
from helpers import run_crosscheck as run
from PIL import Image
from wirecheck.oracles.judge.metrics import DIFF_COLOURS
from wirecheck.oracles.reports.plots import STRIP_PX, worst_gif
from wirecheck.oracles.runner import worst_key


def gif_frames(path):
    im = Image.open(path)
    frames = []
    for k in range(im.n_frames):
        im.seek(k)
        frames.append(np.asarray(im.convert("RGB")))
    return im.size, frames


def test_worst_gif_has_every_checked_frame_side_by_side(tmp_path):
    code, report, out = run(
        tmp_path,
        "--scene",
        "cube",
        "--scene",
        "pyramid",
        "--frames",
        "7",
        "--every",
        "3",
        "--cases",
        "oblique_roll,non_square",
    )
    assert code == 0 and report["frames_checked"] == 3
    worst = report["worst_case"]
    # the worst case: lowest F1@1, then F1@0, then the largest vertex error
    ranked = min(report["cases"], key=worst_key)
    assert (worst["scene"], worst["camera"]) == (ranked["scene"], ranked["camera"])
    assert worst["frames_checked"] == 3 and worst["animation"] == "worst.gif"
    w, h = ranked["camera_spec"]["width"], ranked["camera_spec"]["height"]
    size, frames = gif_frames(out / "worst.gif")
    assert size == (3 * w + 2, h + STRIP_PX)  # ours | oracle | diff, 1-px separators; progress strip
    assert len(frames) == 3  # one per checked frame (1, 4, 7)
    first = frames[0]
    assert (first[:h, w] == 128).all() and (first[:h, 2 * w + 1] == 128).all()  # grey separators
    colours = {tuple(c) for c in first[:h, 2 * w + 2 :].reshape(-1, 3)}
    assert colours <= {(0, 0, 0), *DIFF_COLOURS.values()} and DIFF_COLOURS["both"] in colours
    # the panels are the frames: white where drawn, and the diff agrees with them
    ours, oracle, diff = first[:h, :w, 0] > 0, first[:h, w + 1 : 2 * w + 1, 0] > 0, first[:h, 2 * w + 2 :]
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
    assert all((f[:h] == frames[0][:h]).all() for f in frames)  # same panels, different bars
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
    code, report, out = run(tmp_path, "--level", "vertices", "--scene", "cube", "--frames", "2", "--cases", "on_axis")
    assert code == 0 and "worst_case" not in report
    assert (out / "vertex_error.png").is_file()
    assert not (out / "worst.gif").exists() and not (out / "pixels.png").exists()


def test_plots_survive_zero_none_and_failing_cases(tmp_path):
    empty = tmp_path / "empty.scene"
    empty.write_text("# nothing\n")
    code, _, out = run(
        tmp_path, "--scene", str(empty), "--scene", "cube", "--frames", "1", "--cases", "on_axis", "--tol-px", "0"
    )  # tolerance 0: no line on the log axis, and the cube fails
    assert code == 1 and (out / "vertex_error.png").is_file() and (out / "worst.gif").is_file()


@pytest.mark.parametrize("style", ["shaded"])
def test_shaded_plot_has_iou_and_depth(tmp_path, style):
    code, report, out = run(tmp_path, "--style", style, "--scene", "cube", "--frames", "2", "--cases", "on_axis")
    assert code == 0 and (out / "pixels.png").is_file()
    size, frames = gif_frames(out / "worst.gif")
    assert len(frames) == 2 and size[0] == 3 * 640 + 2
    assert "per-frame silhouette IoU and depth error / bound" in (out / "report.md").read_text()


# ---------------------------------------------------------------- what the plots show, read back

# The first case's line is tab10[0] = (31, 119, 180); the tolerance / limit line
# is "#b00" = (187, 0, 0). Anti-aliased over the white background these blend
# towards white, so pixels are classified by hue: blue where B exceeds R by 60
# (the blend half-way to white, (143, 187, 217), still does by 74), red where R
# exceeds G and B by 80. Grid lines and text are grey or black.
BLUE = "blue"
RED = "red"


def _pixels_of(png: bytes, hue):
    """Rows and columns of the ``hue`` pixels of ``png``."""
    img = np.asarray(Image.open(__import__("io").BytesIO(png)).convert("RGB")).astype(int)
    r, g, b = img[..., 0], img[..., 1], img[..., 2]
    mask = (b > r + 60) & (b > g + 20) if hue == BLUE else (r > g + 80) & (r > b + 80)
    return np.nonzero(mask)


def _curve_rows(png: bytes):
    """Row of the first case's curve at its first, middle and last point (3 frames: equally spaced columns)."""
    rr, cc = _pixels_of(png, BLUE)
    assert len(rr) > 50, "no curve drawn"
    # The legend's sample line is the same colour, apart (right of the axes):
    # keep the widest run of adjacent columns, the curve.
    cols = np.unique(cc)
    runs = np.split(cols, np.flatnonzero(np.diff(cols) > 3) + 1)
    run = max(runs, key=len)
    keep = (cc >= run[0]) & (cc <= run[-1])
    rr, cc = rr[keep], cc[keep]
    # The markers (3 px) and the line end at the first and last frames: the
    # curve's columns span [x1 - r, x3 + r]; frame 2 is midway.
    lo, hi = cc.min(), cc.max()
    cols = (lo + 1, (lo + hi) // 2, hi - 1)
    return [float(np.median(rr[np.abs(cc - c) <= 1])) for c in cols], (lo, hi)


def _limit_row(png: bytes) -> float:
    rr, _ = _pixels_of(png, RED)
    rows, counts = np.unique(rr, return_counts=True)
    return float(rows[np.argmax(counts)])  # the dashed line: the row with most red pixels (not the label)


def _report(per_frame, shaded=False, tol=None):
    tolerances = (
        {"vertex_error_px": 1e-6, "min_silhouette_iou": 0.995}
        if shaded
        else {"vertex_error_px": tol or 1e-6, "min_pixel_f1_0px": 0.98}
    )
    return {
        "level": "pixels",
        "style": "shaded" if shaded else "wireframe",
        "tolerances": tolerances,
        "cases": [{"scene": "s", "camera": "c", "per_frame": per_frame}],
    }


def test_pixels_png_draws_the_f1_curve_and_its_limit_where_they_belong():
    from wirecheck.oracles.reports.plots import pixel_png

    # F1@0 = 0.2, 0.6, 0.8 at frames 1..3, limit 0.98; linear y axis, rows grow downward
    png = pixel_png(_report([{"frame": k, "f1_0px": v} for k, v in ((1, 0.2), (2, 0.6), (3, 0.8))]))
    (y1, y2, y3), _ = _curve_rows(png)
    y_lim = _limit_row(png)
    assert y_lim < y3 < y2 < y1  # 0.98 above 0.8 above 0.6 above 0.2
    # linear axis: row gaps in proportion to value gaps, (0.6 - 0.2) / (0.8 - 0.6) = 2 and
    # (0.98 - 0.8) / (0.8 - 0.6) = 0.9; ~110 px per 0.4, +-1.5 px of reading: +-5 %
    assert abs((y1 - y2) / (y2 - y3) - 2.0) < 0.1
    assert abs((y3 - y_lim) / (y2 - y3) - 0.9) < 0.1


def test_vertex_error_png_is_a_log_axis_with_the_tolerance_line():
    from wirecheck.oracles.reports.plots import vertex_error_png

    # errors 1e-12, 1e-10, 1e-8 and the tolerance 1e-6: equal steps of 100x, so
    # on a log axis three equal row gaps (and 0 px would be drawn at 1e-16)
    png = vertex_error_png(
        _report([{"frame": k, "max_vertex_error_px": v} for k, v in ((1, 1e-12), (2, 1e-10), (3, 1e-8))])
    )
    (y1, y2, y3), _ = _curve_rows(png)
    y_tol = _limit_row(png)
    assert y_tol < y3 < y2 < y1
    gaps = np.array([y1 - y2, y2 - y3, y3 - y_tol])
    assert gaps.min() > 20 and gaps.max() - gaps.min() <= 3, gaps  # equal within the reading (+-1.5 px)


def test_shaded_pixels_png_has_two_panels_iou_above_depth():
    from wirecheck.oracles.reports.plots import pixel_png

    frames = [
        {"frame": k, "silhouette_iou": v, "depth_error_ratio": r}
        for k, v, r in ((1, 0.9, 0.01), (2, 0.95, 0.1), (3, 0.99, 1.0))
    ]
    png = pixel_png(_report(frames, shaded=True))
    rr, cc = _pixels_of(png, BLUE)
    h = Image.open(__import__("io").BytesIO(png)).size[1]
    top, bottom = rr < h / 2, rr >= h / 2
    assert top.sum() > 30 and bottom.sum() > 30  # one curve in each panel
    for part in (top, bottom):  # both rise left to right
        left = rr[part & (cc <= cc[part].min() + 1)].mean()
        right = rr[part & (cc >= cc[part].max() - 1)].mean()
        assert right < left
    red, _ = _pixels_of(png, RED)
    assert (red < h / 2).any() and (red >= h / 2).any()  # a limit line in each: 0.995 and 1.0


def test_decade_labels_are_unicode_powers_of_ten():
    from wirecheck.oracles.reports.plots import _decade_label

    # hand-written: superscript minus U+207B, superscript digits (U+2070, U+00B9, U+00B2, U+00B3, U+2074..9)
    assert _decade_label(1e-6) == "10\u207b\u2076"
    assert _decade_label(1e-16) == "10\u207b\u00b9\u2076"
    assert _decade_label(1.0) == "10\u2070"
    assert _decade_label(1000.0) == "10\u00b3"
    assert _decade_label(2e-6) == "" and _decade_label(0.0) == "" and _decade_label(-1.0) == ""


def test_a_wide_log_axis_is_labelled_at_powers_of_ten_without_minor_ticks():
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from wirecheck.oracles.reports.plots import _log_y

    def axis(lo, hi):
        fig = Figure()
        FigureCanvasAgg(fig)
        ax = fig.add_subplot(1, 1, 1)
        ax.plot([0, 1], [lo, hi])
        _log_y(ax)
        fig.canvas.draw()
        return ax

    wide = axis(1e-16, 1e-6)  # 10 decades: more than plots.MINOR_TICKS_MAX_DECADES
    assert len(wide.yaxis.get_minorticklocs()) == 0
    labels = [t.get_text() for t in wide.get_yticklabels() if t.get_text()]
    assert labels and all(s.startswith("10") and "$" not in s for s in labels)
    assert "10\u207b\u2078" in labels or "10\u207b\u2077" in labels  # some decade inside the span
    # a narrow span keeps matplotlib's own minor ticks (and labels between decades)
    narrow = axis(2e-13, 6e-13)
    assert len(narrow.yaxis.get_minorticklocs()) > 0
