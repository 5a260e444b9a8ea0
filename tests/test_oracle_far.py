"""The pyrender oracle is right wherever the scene is, and says when a case is beyond its precision (issue 27).

pyrender computes ``P V M p`` in float32. Given world coordinates 1e5 from
the origin, the rounding of the vertices alone (2^-24 x 1e5 = 6e-3 units) is
0.6 px at 100 px per unit: the oracle's lines moved and correct code failed.
The oracle now hands pyrender each vertex's offset from the mesh's centre
and a node pose taking it to eye space, both computed in float64
(oracles.references.convert.gl_eye_pose), and records its own error bound per case
(oracles.references.oracle_precision).
"""

from __future__ import annotations

import numpy as np
import pytest
from wirecheck.core.camera import Camera
from wirecheck.oracles.references import oracle_precision as op
from wirecheck.oracles.references.convert import camera_to_gl, centre_of, gl_eye_pose
from wirecheck.oracles.references.pyrender_oracle import osmesa_available
from wirecheck.oracles.tolerances import ORACLE_LIMIT_PX

_OK, _WHY = osmesa_available()
needs_gl = pytest.mark.skipif(not _OK, reason=f"pyrender/OSMesa unavailable: {_WHY}")

FAR = 1e5
CUBE = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float) * 0.7
CUBE_FACES = [(1, 2, 4, 3), (5, 7, 8, 6), (1, 5, 6, 2), (3, 4, 8, 7), (1, 3, 7, 5), (2, 6, 8, 4)]


def write_cube(path, offset: float, scale: float = 1.0):
    v = CUBE * scale + offset
    path.write_text(
        "".join(f"v {a!r} {b!r} {c!r}\n" for a, b, c in v.tolist())
        + "".join("f " + " ".join(map(str, f)) + "\n" for f in CUBE_FACES)
    )
    return path


def _camera(position, w=320, h=240, near=0.1):
    return Camera(
        position=position,
        forward=(-1.0, -0.6, -2.0),
        up=(0.0, 1.0, 0.0),
        width=w,
        height=h,
        near=near,
        far=100.0,
        fov_y_deg=50.0,
    )


def _window_f32(p_model, eye_pose_or_mvp, camera, centred: bool) -> np.ndarray:
    """A float32 model of pyrender's vertex shader: ``(P V) M`` then the vertex, divide, viewport.

    ``centred``: the oracle's inputs (offsets and an eye pose, camera at the identity); else
    pyrender's as they were (world-sized vertices, ``V`` from the camera's world position).
    """
    f32 = np.float32
    view, proj = camera_to_gl(camera)
    if centred:
        q = (p_model - centre_of(p_model)).astype(f32)
        pv, m = proj.astype(f32), eye_pose_or_mvp.astype(f32)
    else:
        q = p_model.astype(f32)
        pv, m = proj.astype(f32) @ view.astype(f32), eye_pose_or_mvp.astype(f32)
    clip = np.concatenate([q, np.ones((len(q), 1), f32)], axis=1) @ (pv @ m).T
    ndc = clip[:, :2] / clip[:, 3:4]
    return np.stack(
        [(ndc[:, 0] + f32(1)) * f32(camera.width / 2), (ndc[:, 1] + f32(1)) * f32(camera.height / 2)], axis=1
    ).astype(np.float64)


def _window_exact(p_world, camera) -> np.ndarray:
    view, proj = camera_to_gl(camera)
    clip = np.concatenate([p_world, np.ones((len(p_world), 1))], axis=1) @ (proj @ view).T
    ndc = clip[:, :2] / clip[:, 3:4]
    return np.stack([(ndc[:, 0] + 1) * camera.width / 2, (ndc[:, 1] + 1) * camera.height / 2], axis=1)


@pytest.mark.parametrize("offset", [0.0, 2e3, FAR])
def test_the_bound_holds_for_a_float32_model_of_the_shader_and_the_old_inputs_broke_it(offset):
    rng = np.random.default_rng(7)
    p_model = rng.uniform(-1, 1, (400, 3)) + offset
    centre = np.full(3, offset)
    cam = _camera(centre + (2.0, 1.2, 4.0))
    pose = gl_eye_pose(cam, None, centre_of(p_model))
    bound = op.frame_bound_px(cam, pose, op.mesh_radius(p_model - centre_of(p_model)))
    exact = _window_exact(p_model, cam)
    err_now = np.abs(_window_f32(p_model, pose, cam, centred=True) - exact).max()
    err_then = np.abs(_window_f32(p_model, np.eye(4), cam, centred=False) - exact).max()
    # the oracle's inputs now: within its bound, and the bound within what the tie zone assumes
    assert err_now <= bound <= ORACLE_LIMIT_PX
    if offset == FAR:  # the old inputs, far away: rounding of 1e5-sized values, ~1e-2 px and more
        assert err_then > 10 * ORACLE_LIMIT_PX


def test_the_bound_of_a_centred_camera_by_hand():
    # camera 5 units from the centre of a radius-1 mesh along its forward axis, M = I:
    # t = (0, 0, -5), rho = 1, w_lo = 5 - 1 = 4; 320 x 240, fov 50 -> f = 120 / tan(25 deg), P00 = 2 f / 320,
    # P11 = 2 f / 240 (= f / 120); |x_ndc| <= 1.
    # x: u (W / 2) (10 P00 (0 + 1) + 7 (5 + 1)) / 4 + 2 u W;  y: u (H / 2) (10 P11 + 42) / 4 + 2 u H
    f = 120 / np.tan(np.radians(25))
    u = 2.0**-24
    bx = u * 160 * (10 * 2 * f / 320 + 42) / 4 + 2 * u * 320
    by = u * 120 * (10 * f / 120 + 42) / 4 + 2 * u * 240
    cam = Camera(
        position=(0.0, 0.0, 5.0),
        forward=(0.0, 0.0, -1.0),
        up=(0.0, 1.0, 0.0),
        width=320,
        height=240,
        near=0.1,
        far=100.0,
        fov_y_deg=50.0,
    )
    pose = gl_eye_pose(cam, None, (0.0, 0.0, 0.0))
    assert op.frame_bound_px(cam, pose, 1.0) == pytest.approx(max(bx, by), rel=1e-12)


@needs_gl
def test_a_mesh_1e5_from_the_origin_passes_with_core_and_fails_half_a_pixel_off(tmp_path):
    from wirecheck.core.projector.projection import project_points
    from wirecheck.oracles.api import check_projector

    obj = write_cube(tmp_path / "far.obj", FAR)
    kw = dict(
        scenes=[str(obj)],
        frames=3,
        cases=["on_axis", "oblique_roll", "near_plane", "orthographic"],
        oracles="opencv,pyrender",
        isolate=False,
    )

    def core(points, camera):
        return project_points(points, camera)

    def half_pixel(points, camera):
        return project_points(points, camera) + 0.5

    good = check_projector(core, **kw)
    assert good["verdict"] == "pass", [c["reasons"] for c in good["cases"]]
    for case in good["cases"]:
        # the oracle's bound is in the record, within the tie zone's float32 share, and the pixels agree
        assert 0 < case["oracle_bound_px"] <= case["oracle_limit_px"] == 2.0**-9
        assert case["pixel_f1_1px"] == 1.0
    bad = check_projector(half_pixel, **kw)
    assert bad["verdict"] == "fail"
    for case in bad["cases"]:
        assert case["verdict"] == "fail" and not case.get("oracle_precision")
        assert case["pixel_f1_0px"] < 0.9  # the pixels see the shift too: lines a half pixel off


@needs_gl
def test_a_case_beyond_the_oracles_precision_is_named_and_does_not_blame_the_candidate(tmp_path):
    from wirecheck.core.scene.files import load_scene
    from wirecheck.core.transforms import Motion
    from wirecheck.oracles.candidates.core_candidate import CoreCandidate
    from wirecheck.oracles.cases import Case
    from wirecheck.oracles.judge.case import run_case
    from wirecheck.oracles.references.pyrender_oracle import PyrenderOracle
    from wirecheck.oracles.tolerances import Tolerances

    # a 1,400-unit cube seen from 3 units above one face with near 0.01: the nearest drawn point is 0.01
    # deep and the clip magnitudes ~2e3 (703 to the centre + rho 1.2e3), so the w term alone is
    # u 160 7 2e3 / 0.01 ~ 13 px (the bound: 29 px), far beyond 2^-9
    scene = load_scene(str(write_cube(tmp_path / "big.obj", 0.0, scale=1000.0)))
    cam = Camera(
        position=(0.0, 0.0, 703.0),
        forward=(0.1, 0.05, -1.0),
        up=(0.0, 1.0, 0.0),
        width=320,
        height=240,
        near=0.01,
        far=5000.0,
        fov_y_deg=60.0,
    )
    with PyrenderOracle(320, 240) as oracle:
        res = run_case(
            scene,
            Case("inside", cam),
            2,
            CoreCandidate(),
            Motion(turns=(0.0, 0.0, 0.0)),
            Tolerances(),
            pyrender_oracle=oracle,
        )
    rec = res.record
    assert rec["oracle_bound_px"] > 100 * ORACLE_LIMIT_PX
    assert rec["verdict"] == "vacuous" and rec["oracle_precision"] is True
    assert rec["reasons"][0].startswith("oracle_precision: the pyrender oracle's own error bound")


def test_a_bound_that_overflows_is_no_bound_and_beyond_the_limit():
    # a radius of 1e308 makes the magnitudes overflow float64: no finite bound, so the case cannot be judged
    cam = _camera((0.0, 0.0, 5.0))
    bound = op.frame_bound_px(cam, gl_eye_pose(cam, None, (0.0, 0.0, 0.0)), 1e308)
    assert bound == float("inf") and bound > ORACLE_LIMIT_PX


@needs_gl
def test_a_vertex_at_1e300_is_vacuous_and_names_no_fault_from_the_pixels(tmp_path):
    """A triangle reaching 1e300: the oracle's bound overflows (no finite bound), its pixels are not judged,
    so no line fault is read from them (before: ``line_pixel_bias`` from the line counts beside the vacuous
    verdict); the vertices, within core's bound, name nothing either."""
    import json

    from wirecheck.oracles import cli

    (tmp_path / "big.obj").write_text("v 0 0 0\nv 1e300 0 0\nv 0 1 0\nf 1 2 3\n")
    assert (
        cli.main(
            [
                "--scene",
                str(tmp_path / "big.obj"),
                "--frames",
                "2",
                "--cases",
                "on_axis",
                "--report-dir",
                str(tmp_path / "r"),
            ]
        )
        == 1
    )  # vacuous: a failure of the run
    (case,) = json.loads((tmp_path / "r" / "report.json").read_text())["cases"]
    assert case["verdict"] == "vacuous" and case["oracle_precision"] is True
    assert case["faults"] == []
