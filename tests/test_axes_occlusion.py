"""``--axes`` with ``--hidden-lines`` or ``--style shaded``: the axes are hidden behind faces.

Hand-derived geometry: the unit cube at rest, camera at (0, 0, 4), FOV 60
(f = 240 sqrt(3) = 415.692), 640x480. The X axis runs from the origin (inside
the cube) to x = L = 1.2 sqrt(3) = 2.0785 at depth 4, so it projects to
x_px = 319.5 + f x / 4 on row 239.5. The front face (z = 1, depth 3) covers
x_px <= 319.5 + f / 3 = 458.06, i.e. pixel centres up to column 458: the axis is
hidden there and visible from column 459 to its end at 319.5 + f L / 4 = 535.5.
"""

import math

import numpy as np
import pytest
from helpers import run_renderer
from numpy.testing import assert_array_equal
from PIL import Image
from wirecheck.core.camera import camera_z
from wirecheck.core.projector.pipeline import draw_segments, render_frame

F60 = 240.0 * math.sqrt(3.0)
END = 319.5 + F60 * 1.2 * math.sqrt(3.0) / 4  # 535.5


def red_columns(path):
    img = np.asarray(Image.open(path).convert("RGB"))
    red = (img == (255, 0, 0)).all(axis=2)
    return np.flatnonzero(red.any(axis=0))


def run(args, out):
    rc, _, err = run_renderer(args, out)
    assert rc == 0, err


@pytest.mark.parametrize("mode", [["--hidden-lines"], ["--style", "shaded"]])
def test_x_axis_is_hidden_behind_the_front_face(tmp_path, mode):
    run(["--frames", "2", "--spin", "0,0,0", "--camera-z", "4", "--axes"] + mode, tmp_path)
    cols = red_columns(tmp_path / "cube-frames" / "frame_0001.png")
    assert cols.min() == 459  # first pixel centre right of 458.06
    assert abs(cols.max() - END) <= 1.0  # the axis' end pixel, within the raster's 1 px


def test_without_faces_the_axes_are_drawn_over_everything(tmp_path):
    run(["--frames", "2", "--spin", "0,0,0", "--camera-z", "4", "--axes"], tmp_path)
    cols = red_columns(tmp_path / "cube-frames" / "frame_0001.png")
    assert cols.min() in (319, 320)  # from the origin's pixel, 319.5


def test_draw_segments_without_occluders_draws_as_the_pipeline_draws_an_edge():
    cam = camera_z(1.5, fov_y_deg=100, near=0.7)
    # one segment crossing the near plane and one leaving the image: both take the clipping path
    p = np.array([[0.3, 0.2, 1.2], [-0.4, -0.1, -3.0], [0.1, 0.1, 0.0], [9.0, 0.5, -1.0]])
    edges = np.array([[0, 1], [2, 3]])
    want = render_frame(p, edges, cam, np.eye(4)).image
    seg_cam = (p @ cam.world_to_cam[:3, :3].T + cam.world_to_cam[:3, 3])[edges]
    assert_array_equal(draw_segments(seg_cam, cam), want)
    assert (want > 0).sum() > 100  # something was drawn


def test_endpoint_clip_drops_an_axis_with_a_clipped_end(tmp_path):
    # camera at (1.5, 1, 3), forward -(1.5, 1, 3)/3.5: the Z axis runs from depth 3.5 (origin)
    # through 2.64 (leaving the cube at z = 1) to 1.72 (its end, z = 2.08), so near = 2 cuts it
    # outside the cube, where nothing hides it: --clip clip draws z in [1, 1.75], endpoint nothing
    cam = ["--frames", "2", "--spin", "0,0,0", "--camera-pos", "1.5,1,3", "--near", "2", "--axes", "--hidden-lines"]
    run(cam + ["--clip", "endpoint"], tmp_path / "e")
    run(cam, tmp_path / "c")
    blue = [
        (np.asarray(Image.open(tmp_path / d / "cube-frames" / "frame_0001.png").convert("RGB")) == (0, 0, 255))
        .all(axis=2)
        .sum()
        for d in ("e", "c")
    ]
    assert blue[0] == 0 and blue[1] > 10
