"""core.scene.frames.SceneRenderer: the scene-level API renderer and crosscheck share."""

import doctest

import numpy as np
import wirecheck
from numpy.testing import assert_array_equal
from wirecheck.core.camera import look_at
from wirecheck.core.scene import frames
from wirecheck.core.scene.files import load_scene
from wirecheck.core.transforms import Motion
from wirecheck.oracles.references import opencv_oracle
from wirecheck.oracles.references.faces import frame_geometry

CAM = look_at((0.0, 2.0, 9.0), (0.0, 0.0, 0.0), near=0.5, far=50.0)


def test_module_doctest():
    result = doctest.testmod(frames)
    assert result.attempted > 0 and result.failed == 0


def test_top_level_export():
    assert wirecheck.SceneRenderer is frames.SceneRenderer


def test_several_moving_objects_against_scipy_and_opencv():
    """The orrery's vertex pixels against the oracle side: scipy's M_run @ M_o, OpenCV's projectPoints.

    Both sides are float64 on coordinates of size ~5 projected with f ~ 400 px:
    a few ulp of 5 times f/z (~100) is ~1e-12 px; 1e-9 px leaves room and still
    fails for any real error in the set-up (a wrong motion order moves points by pixels).
    """
    scene = load_scene("orrery")
    motion = Motion(turns=(0.5, 1.0, 0.0))
    r = frames.SceneRenderer(scene, motion, 8)
    assert not r.single
    for k in (1, 4, 8):
        p_world, _, _, _ = frame_geometry(scene, motion, (k - 1) / 8)
        frame, info = r.render(k, CAM)
        ref = opencv_oracle.project(p_world, CAM)
        assert_array_equal(np.isnan(frame.p_px), np.isnan(ref))
        ok = ~np.isnan(ref)
        assert np.abs(frame.p_px[ok] - ref[ok]).max() < 1e-9


def test_object_culling_changes_neither_picture_nor_counts():
    """Module docstring: an object outside the frustum cannot put a pixel on the image."""
    scene = load_scene("orrery")
    motion = Motion(turns=(0.0, 1.0, 0.0))
    narrow = look_at((0.0, 0.0, 9.0), (3.0, 0.0, 0.0), fov_y_deg=15.0, near=0.5, far=50.0)
    on = frames.SceneRenderer(scene, motion, 12, hidden_lines=True, object_culling=True)
    off = frames.SceneRenderer(scene, motion, 12, hidden_lines=True, object_culling=False)
    culled = 0
    for k in range(1, 13):
        f_on, i_on = on.render(k, narrow)
        f_off, i_off = off.render(k, narrow)
        assert_array_equal(f_on.image, f_off.image)
        assert i_on["clipped_edges"] == i_off["clipped_edges"]
        assert i_off["objects_culled"] is None
        culled += i_on["objects_culled"]
    assert culled > 0  # the camera does leave objects out, so the check compares something
