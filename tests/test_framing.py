"""Case cameras framed on the scene (oracles.cases.framing): a mesh far from the origin fills the image."""

import math

import numpy as np
import pytest
from helpers import run_crosscheck
from wirecheck.core.scene.files import load_scene
from wirecheck.core.scene.model import Scene, SceneObject
from wirecheck.core.transforms import Motion, apply
from wirecheck.oracles.cases import case_motion, cases_for, framing
from wirecheck.oracles.references import faces as oface
from wirecheck.oracles.references import opencv_oracle
from wirecheck.oracles.references.convert import model_matrix
from wirecheck.oracles.references.pyrender_oracle import osmesa_available

HALF = 50.0  # the box's half-size
FAR = np.array([900.0, -400.0, 300.0])  # where its centre is
CUBE = load_scene("cube")  # corners (+-1, +-1, +-1)

_OK, _WHY = osmesa_available()
needs_osmesa = pytest.mark.skipif(not _OK, reason=f"pyrender/OSMesa unavailable: {_WHY}")


def far_box() -> Scene:
    return Scene("far_box", CUBE.vertices * HALF + FAR, CUBE.edges.copy(), CUBE.faces, source="test")


def write_obj(path, scene: Scene) -> None:
    lines = [f"v {float(x)!r} {float(y)!r} {float(z)!r}" for x, y, z in scene.vertices]
    lines += ["f " + " ".join(str(i + 1) for i in f) for f in scene.faces]
    path.write_text("\n".join(lines) + "\n")


def test_an_off_centre_box_is_framed_on_its_own_centre_and_turns_about_it():
    centre, radius, pivot = framing(far_box())
    # the box's centre, and its half-diagonal sqrt(3) * HALF (exact in float64 up to a few ulp)
    assert centre == pivot == tuple(FAR)
    assert radius == pytest.approx(math.sqrt(3.0) * HALF, rel=4e-16)
    on_axis = cases_for(far_box())[0]
    assert on_axis.name == "on_axis"
    assert np.allclose(on_axis.camera.position, FAR + [0.0, 0.0, 3.0 * radius], rtol=0, atol=1e-12)


def test_the_off_centre_box_fills_the_derived_fraction_of_the_image():
    """Frame 1 (rest pose) of on_axis, by hand: the camera is 3r from the centre, r = sqrt(3) h.

    The front face (z = centre + h) is at depth d = 3 sqrt(3) h - h and half as
    wide as the box, so its half-width in pixels is f h / d with
    f = 240 / tan(30 deg) = 240 sqrt(3): 240 sqrt(3) / (3 sqrt(3) - 1) = 99.07 px,
    41 % of the image's 480 rows. Framing on the origin gave a half-width of
    6.3 px: r = |FAR| + sqrt(3) h = 1108, 240 sqrt(3) h / (3 r - h).
    """
    scene = far_box()
    case = cases_for(scene)[0]
    half_px = 240.0 * math.sqrt(3.0) / (3.0 * math.sqrt(3.0) - 1.0)
    p_world = oface.frame_geometry(scene, case_motion(Motion(), case), 0.0)[0]
    p_px = opencv_oracle.project(p_world, case.camera)
    front = p_world[:, 2] > FAR[2]
    # OpenCV's float64 projection: ~1e-13 px of rounding at these magnitudes
    assert np.ptp(p_px[front, 0]) == pytest.approx(2 * half_px, abs=1e-9)
    assert np.ptp(p_px[front, 1]) == pytest.approx(2 * half_px, abs=1e-9)
    assert np.ptp(p_px[:, 1]) / case.camera.height == pytest.approx(2 * half_px / 480, abs=1e-12)
    assert 2 * half_px / 480 > 0.41


@needs_osmesa
def test_crosscheck_of_the_off_centre_box_passes_comparing_its_lines(tmp_path):
    """The whole run: pass, with the box's edges drawn at the size derived above.

    On frame 1 of on_axis the front square alone is 4 sides of 2 x 99 px, so
    the oracle draws at least 4 * 197 = 788 pixels (1 px lines, corners
    shared); every other frame turns the box about its centre, in view.
    """
    obj = tmp_path / "far_box.obj"
    write_obj(obj, far_box())
    code, report, _out = run_crosscheck(tmp_path, "--scene", str(obj), "--frames", "4")
    assert code == 0 and report["verdict"] == "pass"
    on_axis = report["cases"][0]
    assert on_axis["camera"] == "on_axis"
    assert on_axis["framing"]["pivot"] == list(FAR)
    assert on_axis["pixel_f1_1px"] == 1.0
    # pixels drawn by either side over the case's 4 frames: frame 1 alone has the front square
    assert on_axis["compared"]["pixels"] >= 788
    assert report["compared"]["pixels"] >= 788


def test_every_bundled_scene_keeps_the_origin_framing():
    # hand values: the cube's and pyramid's corners are at sqrt(3), the prism's at sqrt(2);
    # the orrery's bound is |planet offset| 2.5 + scale 0.5 * sqrt(3) (core.scene.model.Scene.radius)
    expected = {
        "cube": math.sqrt(3),
        "pyramid": math.sqrt(3),
        "prism": math.sqrt(2),
        "orrery": 2.5 + 0.5 * math.sqrt(3),
    }
    for name, r in expected.items():
        centre, radius, pivot = framing(load_scene(name))
        assert centre == pivot == (0.0, 0.0, 0.0), name
        assert radius == pytest.approx(r, rel=1e-15), name
        assert cases_for(load_scene(name))[0].camera.position == pytest.approx((0.0, 0.0, 3 * r), rel=1e-15)


def _moving_far_scene() -> Scene:
    """Two objects far from the origin: a box turning about its own origin, a static one beside it."""
    v = np.concatenate([CUBE.vertices * 10.0, CUBE.vertices * 5.0 + [0.0, 40.0, 0.0]])
    edges = np.concatenate([CUBE.edges, CUBE.edges + len(CUBE.vertices)])
    n = len(CUBE.vertices)
    objects = (
        SceneObject("spinner", 0, n, Motion(turns=(0.0, 2.0, 1.0), offset=(2000.0, 100.0, -50.0), scale=2.0)),
        SceneObject("still", n, 2 * n, Motion(turns=(0.0, 0.0, 0.0), offset=(2060.0, 0.0, 0.0), scale=1.0)),
    )
    return Scene("far_pair", v, edges, (), source="test", objects=objects)


@pytest.mark.parametrize("make", [far_box, _moving_far_scene])
def test_the_framing_sphere_holds_the_scene_in_every_frame(make):
    """Every vertex of every frame (the oracle's own scipy matrices) lies inside the sphere.

    Bound: |p - c| <= r up to float64 rounding of coordinates of size ~2e3
    (a few ulp: 2e3 * 1e-15 = 2e-12; 1e-9 leaves room and is still far below
    a pixel).
    """
    scene = make()
    centre, radius, pivot = framing(scene)
    assert pivot != (0.0, 0.0, 0.0)  # both are away from the origin: reframed
    case = cases_for(scene)[0]
    motion = case_motion(Motion(turns=(1.0, 1.0, 0.0)), case)
    worst = 0.0
    for k in range(97):
        p_world = oface.frame_geometry(scene, motion, k / 97)[0]
        worst = max(worst, float(np.linalg.norm(p_world - centre, axis=1).max()))
    assert worst <= radius + 1e-9
    # and the sphere is not loose: the frames reach at least 90 % of it (the spinner's
    # corners sweep a sphere of 2 * 10 sqrt(3) about its offset, the still box is beside it)
    assert worst >= 0.9 * radius


def test_a_pivot_turns_about_its_point_in_core_and_in_the_oracle():
    """A quarter turn about Z at pivot c takes c + (1, 0, 0) to c + (0, 1, 0) (right-handed, conventions)."""
    c = (900.0, -400.0, 300.0)
    p = np.array([[901.0, -400.0, 300.0]])
    want = np.array([[900.0, -399.0, 300.0]])
    core_m = Motion(turns=(0.0, 0.0, 1.0), pivot=c).model_matrix(0.25)
    assert np.allclose(apply(core_m, p), want, rtol=0, atol=1e-12)
    oracle_m = model_matrix((0.0, 0.0, 1.0), (0.0, 0.0, 0.0), 1.0, 0.25, pivot=c)
    assert np.allclose(p @ oracle_m[:3, :3].T + oracle_m[:3, 3], want, rtol=0, atol=1e-12)
    # the pivot itself never moves, and scale is about it too
    m = Motion(turns=(0.3, 0.7, 0.1), scale=2.0, pivot=c).model_matrix(0.4)
    assert np.allclose(apply(m, np.array([c])), [c], rtol=0, atol=1e-12)
