"""Inputs at the edges of the face modes: each either works or is one clear line, exit 2.

Found by an internal review of the culling / hidden-line / shaded / multi-object
work; each test reproduces the reported case.
"""

import subprocess
import sys

import numpy as np
import pytest
from wirecheck.core.camera import camera_z, look_at
from wirecheck.core.projector.culling import backface_keep, degenerate
from wirecheck.core.projector.pipeline import render_frame
from wirecheck.core.scene.files import load_scene, parse_scene_text
from wirecheck.core.scene.model import oriented_faces
from wirecheck.core.transforms import Motion, scale


def _cli(module, args, tmp_path):
    proc = subprocess.run([sys.executable, "-m", module, *args], capture_output=True, text=True, cwd=tmp_path)
    return proc.returncode, proc.stdout, proc.stderr


@pytest.mark.parametrize(
    "args,needle",
    [
        (["--axes", "--scale", "1e308"], "--axes with --scale"),
        (["--style", "shaded", "--hidden-lines"], "--hidden-lines with --style shaded"),
        (["--projection", "both", "--ortho-height", "40"], "--ortho-height 40.0 with --projection both"),
    ],
)
def test_renderer_rejects_contradictory_or_overflowing_options(args, needle, tmp_path):
    rc, out, err = _cli("wirecheck.core.app.cli", ["--frames", "2", "--out", str(tmp_path / "o"), *args], tmp_path)
    assert rc == 2 and needle in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "o" / "cube-frames").exists()


@pytest.mark.parametrize("light", ["1e308,1e308,1e308", "1e-320,0,0"])
def test_light_direction_of_any_finite_magnitude_works(light, tmp_path):
    # a direction: only its sign pattern and ratios matter; it is scaled by its
    # largest component before normalising, so neither overflows nor underflows
    rc, out, err = _cli(
        "wirecheck.core.app.cli",
        ["--frames", "1", "--style", "shaded", "--light", light, "--out", str(tmp_path / "o")],
        tmp_path,
    )
    assert rc == 0, err


@pytest.mark.parametrize(
    "args,needle",
    [
        (["--suite", "extremes", "--frames", "3"], "--suite extremes with --frames"),
        (["--suite", "extremes", "--scene", "cube"], "--suite extremes with --scene"),
        (["--sweep", "--jobs", "2"], "--sweep with --jobs 2"),
    ],
)
def test_crosscheck_rejects_options_a_mode_would_ignore(args, needle, tmp_path):
    rc, out, err = _cli("wirecheck.oracles.cli", [*args, "--report-dir", str(tmp_path / "r")], tmp_path)
    assert rc == 2 and needle in err and len(err.strip().splitlines()) == 1


def test_zero_area_face_is_culled_and_covers_nothing_in_every_frame():
    # Three collinear vertices: the cross product is rounding noise (~1e-16), so
    # without the relative test its sign flickered from frame to frame.
    scene = parse_scene_text("v 0 0 0\nv 1 0 0\nv 2 0 0\nf 0 1 2\n", "degen.scene")
    cam = look_at((2.0, 1.5, 2.5), (0.0, 0.0, 0.0))
    m = Motion()
    for k in range(1, 9):
        fr = render_frame(scene.vertices, scene.edges, cam, m.frame_matrix(k, 8), faces=scene.faces, cull="backface")
        assert fr.faces_culled == 1 and not fr.image.any()
        sh = render_frame(scene.vertices, scene.edges, cam, m.frame_matrix(k, 8), faces=scene.faces, style="shaded")
        assert not sh.image.any() and np.isinf(sh.depth_image).all()
    tri = np.array([[[0, 0, 5.0], [1, 0, 5.0], [2, 0, 5.0]]])
    assert degenerate(tri).all() and not backface_keep(tri, "perspective").any()


@pytest.mark.parametrize("s", [1.0, 1e-110])
def test_mirroring_is_decided_by_signs_not_by_an_underflowing_determinant(s):
    # scale(-s) has determinant -s^3: -1e-330 underflows to -0.0, which is not < 0.
    # The cube is centrally symmetric, so +s and -s must show the same faces.
    cube = load_scene("cube")
    cam = camera_z(4.0 * s, fov_y_deg=60, near=0.1 * s, far=100 * s)
    m = Motion(turns=(0.13, 0.27, 0.0)).frame_matrix(2, 4)
    plus = render_frame(cube.vertices, cube.edges, cam, m @ scale(s), faces=cube.faces, cull="backface")
    minus = render_frame(cube.vertices, cube.edges, cam, m @ scale(-s), faces=cube.faces, cull="backface")
    # from outside a convex solid, front faces are between 1 and 3 of 6
    assert plus.faces_culled == minus.faces_culled and 3 <= plus.faces_culled <= 5
    # mirrored objects in a multi-object scene: re-wound from the signs alone
    scene = parse_scene_text("object a\nscale -1e-110\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", "m.scene")
    assert oriented_faces(scene, Motion(scale=1e300)) == ((2, 1, 0),)
