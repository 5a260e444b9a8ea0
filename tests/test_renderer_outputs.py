"""Renderer outputs: --axes colours, mp4, gif, plots, --projection both."""

import json
import math

import numpy as np
import pytest
from helpers import run_renderer as run
from numpy.testing import assert_array_equal
from PIL import Image
from wirecheck.core.app.compose import SEPARATOR_GREY
from wirecheck.core.outputs.output import pad_even


def frame(out, scene, k=1):
    im = Image.open(out / f"{scene}-frames" / f"frame_{k:04d}.png")
    return np.asarray(im.convert("L") if im.mode == "1" else im)  # bilevel frames as 0/255


# ---- --axes ---------------------------------------------------------------------------------


def test_axes_colours_and_directions(tmp_path):
    # Camera at (0, 0, 4) looking at the origin, up +Y, 201 x 151 (odd, so the principal point
    # (100, 75) is a pixel centre), fov 60: f = 75.5 / tan 30 = 130.77 px. The axes are
    # 1.2 x the cube's radius sqrt 3 = 2.078 long, at depth 4: X runs from (100, 75) right to
    # x = 100 + f 2.078 / 4 = 167.95 on row 75, Y up to y = 75 - 67.95 = 7.05 in column 100,
    # Z points at the camera and projects to the centre alone (a zero-length line).
    # Diamond-exit: the start pixel is drawn, the end pixel (its diamond holds the end) is not.
    rc, _, err = run(
        [
            "--scene",
            "cube",
            "--frames",
            "1",
            "--spin",
            "0,0,0",
            "--width",
            "201",
            "--height",
            "151",
            "--camera-z",
            "4",
            "--axes",
        ],
        tmp_path,
    )
    assert (rc, err) == (0, "")
    img = frame(tmp_path, "cube")
    assert img.shape == (151, 201, 3)
    red = np.argwhere((img == (255, 0, 0)).all(axis=2))
    green = np.argwhere((img == (0, 255, 0)).all(axis=2))
    assert set(red[:, 0].tolist()) == {75}  # on the centre row ...
    assert red[:, 1].min() == 101 and red[:, 1].max() == 167  # ... right of the centre (100 is Y's)
    assert len(red) == 67
    assert set(green[:, 1].tolist()) == {100}  # in the centre column ...
    assert green[:, 0].min() == 8 and green[:, 0].max() == 75  # ... above the centre
    assert len(green) == 68
    assert not (img == (0, 0, 255)).all(axis=2).any()
    # the rest of the picture is the grey wireframe: every other pixel has r = g = b
    others = ~((img == (255, 0, 0)).all(axis=2) | (img == (0, 255, 0)).all(axis=2))
    assert (img[others][:, 0] == img[others][:, 1]).all() and (img[others][:, 1] == img[others][:, 2]).all()
    rep = json.loads((tmp_path / "cube-report.json").read_text())
    assert rep["drawing"]["axes"] is True and rep["drawing"]["axis_length"] == 1.2 * math.sqrt(3)


def test_no_axes_frames_stay_grey(tmp_path):
    rc, _, _ = run(["--scene", "cube", "--frames", "1", "--width", "64", "--height", "48"], tmp_path)
    assert rc == 0
    # grey, not RGB: a wireframe drawn with the exact raster is bilevel (0/255), written as 1-bit grey
    assert Image.open(tmp_path / "cube-frames" / "frame_0001.png").mode == "1"


def test_axes_are_clipped_like_edges(tmp_path):
    # Camera at (0.3, 0.3, 1) looking down -Z, 81 x 61, fov 60: f = 30.5 / tan 30 = 52.83 px,
    # centre (40, 30). The Z axis (0, 0, z), z in [0, 2.078], is at camera offset (-0.3, -0.3)
    # and depth 1 - z: in front of the near plane (0.1) only for z <= 0.9. The origin projects
    # to (40 - 0.3 f, 30 + 0.3 f) = (24.15, 45.85) and the visible part runs from there to the
    # lower left, off the image. Unclipped, the part behind the camera would mirror to the
    # upper right of the centre.
    rc, _, err = run(
        [
            "--scene",
            "cube",
            "--frames",
            "1",
            "--spin",
            "0,0,0",
            "--camera-pos",
            "0.3,0.3,1",
            "--look-at",
            "0.3,0.3,0",
            "--width",
            "81",
            "--height",
            "61",
            "--axes",
            "--format",
            "png,ascii",
        ],
        tmp_path,
    )
    assert (rc, err) == (0, "")
    blue = np.argwhere((frame(tmp_path, "cube") == (0, 0, 255)).all(axis=2))
    assert len(blue) >= 10
    assert blue[:, 1].max() <= 25 and blue[:, 0].min() >= 45
    assert "#" in (tmp_path / "cube-frames" / "frame_0001.txt").read_text()


# ---- animations ----------------------------------------------------------------------------


def test_mp4_frame_count_size_and_determinism(tmp_path):
    av = pytest.importorskip("av")
    args = ["--scene", "cube", "--frames", "6", "--width", "161", "--height", "121", "--format", "mp4"]
    rc, out, err = run(args, tmp_path / "a")
    assert (rc, err) == (0, "")
    path = tmp_path / "a" / "cube.mp4"
    assert f"Animation: {path}" in out
    assert not (tmp_path / "a" / "cube-frames").exists()  # mp4 alone writes no frame files
    with av.open(str(path)) as c:
        frames = [f.to_ndarray(format="gray") for f in c.decode(video=0)]
    # 161 x 121 is odd both ways: padded (not scaled) to 162 x 122 for yuv420p
    assert len(frames) == 6 and frames[0].shape == (122, 162)
    assert frames[0][121].max() <= 16 and frames[0][:, 161].max() <= 16  # the padding stays black (H.264 noise)
    assert run(args, tmp_path / "b")[0] == 0
    assert (tmp_path / "b" / "cube.mp4").read_bytes() == path.read_bytes()  # (heap patterns: test_mp4_determinism)
    assert not [p for p in (tmp_path / "a").iterdir() if p.name.endswith(".tmp")]


def test_pad_even_pads_without_scaling():
    im = np.arange(15, dtype=np.uint8).reshape(3, 5)
    p = pad_even(im)
    assert p.shape == (4, 6)
    assert_array_equal(p[:3, :5], im)
    assert not p[3].any() and not p[:, 5].any()
    assert pad_even(np.zeros((4, 6), np.uint8)).shape == (4, 6)


def test_gif_frame_count(tmp_path):
    rc, _, _ = run(
        ["--scene", "pyramid", "--frames", "5", "--width", "80", "--height", "60", "--format", "gif", "--axes"],
        tmp_path,
    )
    assert rc == 0
    with Image.open(tmp_path / "pyramid.gif") as g:
        assert g.n_frames == 5 and g.size == (80, 60)


# ---- plots -----------------------------------------------------------------------------------


def test_plots_png_size_and_determinism(tmp_path):
    pytest.importorskip("matplotlib")
    args = ["--scene", "cube", "--frames", "12", "--width", "64", "--height", "48", "--camera-z", "2.5", "--plots"]
    rc, out, err = run(args, tmp_path / "a")
    assert (rc, err) == (0, "")
    path = tmp_path / "a" / "cube-plots.png"
    assert f"Plots: {path}" in out
    with Image.open(path) as im:
        assert im.size == (900, 650)  # FIGSIZE 9 x 6.5 in at 100 dpi
    run(args, tmp_path / "b")
    assert (tmp_path / "b" / "cube-plots.png").read_bytes() == path.read_bytes()
    # off by default: no plot, no "Plots:" line
    rc, out, _ = run(args[:-1], tmp_path / "c")
    assert rc == 0 and not (tmp_path / "c" / "cube-plots.png").exists() and "Plots:" not in out


# ---- --projection both ------------------------------------------------------------------------


def half_extents(img, w):
    """(col span, row span) of the drawn pixels of the left and the right picture."""
    out = []
    for half in (img[:, :w], img[:, w + 1 :]):
        rows, cols = np.nonzero(half)
        out.append((cols.max() - cols.min(), rows.max() - rows.min()))
    return out


def test_projection_both_side_by_side(tmp_path):
    # A square (+-1, +-1, 0) at the look-at point, camera at distance d = 4, fov 60, 161 x 121.
    # Perspective: f = 60.5 / tan 30 = 104.79 px, side = 2 f / 4 = 52.39 px.
    # Orthographic twin: ortho_height = 2 d tan 30 = 4.6188, s = 121 / 4.6188 = 26.197 px per
    # unit, side = 2 s = 52.39 px: the same, as at the look-at distance it must be.
    sq = tmp_path / "sq.scene"
    sq.write_text("v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 0 1 2 3\n")
    w, h = 161, 121
    rc, _, err = run(
        [
            "--scene",
            str(sq),
            "--frames",
            "2",
            "--spin",
            "0,0,0",
            "--camera-z",
            "4",
            "--width",
            str(w),
            "--height",
            str(h),
            "--projection",
            "both",
            "--format",
            "png,gif",
        ],
        tmp_path,
    )
    assert (rc, err) == (0, "")
    img = frame(tmp_path, "sq")
    assert img.shape == (h, 2 * w + 1)
    assert (img[:, w] == SEPARATOR_GREY).all()
    (pc, pr), (oc, orr) = half_extents(img, w)
    side = 2 * (60.5 / math.tan(math.radians(30))) / 4
    # drawn spans: the line ends snap to pixels, so each span is side +- 1
    assert abs(pc - side) <= 1 and abs(pr - side) <= 1
    assert abs(oc - pc) <= 1 and abs(orr - pr) <= 1
    rep = json.loads((tmp_path / "sq-report.json").read_text())
    assert rep["camera"]["projection"] == "perspective"
    cam_o = rep["camera_orthographic"]
    assert cam_o["projection"] == "orthographic" and cam_o["position"] == [0.0, 0.0, 4.0]
    assert math.isclose(cam_o["ortho_height"], 8 * math.tan(math.radians(30)), rel_tol=1e-15)
    fr = rep["frames"][0]
    o = fr["orthographic"]
    assert set(o) == set(fr) - {"frame", "orthographic"}
    # same pose, same near/far: same depths and counts; different pixels (x = 80 + 26.197 x)
    assert (o["min_depth"], o["max_depth"], o["clipped"]) == (fr["min_depth"], fr["max_depth"], fr["clipped"])
    assert abs(o["vertices_px"][1][0] - (80 + 121 / (8 * math.tan(math.radians(30))))) < 1e-9
    with Image.open(tmp_path / "sq.gif") as g:
        # (the 2 frames are the same picture: Pillow stores them as one frame of twice the duration)
        assert g.size == (2 * w + 1, h)


def test_projection_both_cube_nearer_than_look_at_is_bigger_in_perspective(tmp_path):
    # The cube at rest, camera at 4: its front face (depth 3) spans 2 f / 3 = 69.86 px in
    # perspective (the outline), but 2 s = 52.39 px in the orthographic half, where front and
    # back faces coincide.
    w, h = 161, 121
    rc, _, _ = run(
        [
            "--scene",
            "cube",
            "--frames",
            "1",
            "--spin",
            "0,0,0",
            "--camera-z",
            "4",
            "--width",
            str(w),
            "--height",
            str(h),
            "--projection",
            "both",
        ],
        tmp_path,
    )
    assert rc == 0
    (pc, _), (oc, _) = half_extents(frame(tmp_path, "cube"), w)
    f = 60.5 / math.tan(math.radians(30))
    assert abs(pc - 2 * f / 3) <= 1 and abs(oc - 2 * f / 4) <= 1


def test_projection_both_with_axes_and_mp4(tmp_path):
    av = pytest.importorskip("av")
    w, h = 64, 48
    rc, _, err = run(
        [
            "--scene",
            "orrery",
            "--frames",
            "3",
            "--camera-z",
            "8",
            "--width",
            str(w),
            "--height",
            str(h),
            "--projection",
            "both",
            "--axes",
            "--format",
            "png,mp4",
        ],
        tmp_path,
    )
    assert (rc, err) == (0, "")
    img = frame(tmp_path, "orrery")
    assert img.shape == (h, 2 * w + 1, 3)
    assert (img[:, w] == SEPARATOR_GREY).all()
    for half in (img[:, :w], img[:, w + 1 :]):  # both pictures have their axes
        assert (half == (255, 0, 0)).all(axis=2).any() and (half == (0, 255, 0)).all(axis=2).any()
    with av.open(str(tmp_path / "orrery.mp4")) as c:
        frames = list(c.decode(video=0))
    assert len(frames) == 3 and (frames[0].width, frames[0].height) == (2 * w + 2, h)  # 129 -> 130


# ---- shaded style through the CLI -----------------------------------------------------------


def test_shaded_style_writes_grey_faces(tmp_path):
    rc, out, err = run(
        [
            "--scene",
            "cube",
            "--frames",
            "1",
            "--width",
            "64",
            "--height",
            "48",
            "--style",
            "shaded",
            "--light",
            "0,0,-1",
        ],
        tmp_path,
    )
    assert (rc, err) == (0, "")
    img = frame(tmp_path, "cube")
    assert img.ndim == 2 and img.any()
    rep = json.loads((tmp_path / "cube-report.json").read_text())
    assert rep["drawing"]["style"] == "shaded" and rep["drawing"]["light"] == [0.0, 0.0, -1.0]
    assert rep["frames"][0]["faces_total"] == 6
