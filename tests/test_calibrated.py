"""Calibrated pinhole cameras (fx, fy, cx, cy) and OpenCV lens distortion.

core.camera / core.projector.projection / core.projector.distortion / core.projector.clipping / core.app.trace
against hand-derived values, a naive reference of OpenCV's distortion formula,
and cv2.projectPoints (independent); the oracle conversions (oracles.references.convert,
the protocol's camera) against core's own matrices; the crosscheck cases
off_centre, non_square_pixels (pyrender's IntrinsicsCamera) and distorted
(vertices only, said in the report); hostile camera input.
"""

from __future__ import annotations

import numpy as np
import pytest
from wirecheck.core.app import trace
from wirecheck.core.camera import camera_z, look_at
from wirecheck.core.conventions import focal_px
from wirecheck.core.errors import InputError
from wirecheck.core.projector import clipping
from wirecheck.core.projector.distortion import distort
from wirecheck.core.projector.projection import cam_to_px, project_points, unproject, world_to_cam
from wirecheck.oracles.references import convert, opencv_oracle

EPS = np.finfo(np.float64).eps
LENS = (-0.22, 0.06, 0.0012, -0.0009, -0.008)
RATIONAL = (0.3, -0.05, -0.001, 0.002, 0.01, 0.25, -0.03, 0.005)


def naive_distort(x, y, c):
    """OpenCV's documented model, term by term (y down)."""
    k1, k2, p1, p2, k3, k4, k5, k6 = tuple(c) + (0.0,) * (8 - len(c))
    r2 = x**2 + y**2
    radial = (1 + k1 * r2 + k2 * r2**2 + k3 * r2**3) / (1 + k4 * r2 + k5 * r2**2 + k6 * r2**3)
    return x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x**2), y * radial + p1 * (r2 + 2 * y**2) + 2 * p2 * x * y


def random_cameras(n, seed, lens_every=2):
    """Calibrated cameras at random poses, sizes, intrinsics; every ``lens_every``-th with a lens (0: none)."""
    rng = np.random.default_rng(seed)
    out = []
    for i in range(n):
        w, h = int(rng.integers(64, 1024)), int(rng.integers(64, 1024))
        intr = (
            rng.uniform(0.3, 3) * w,
            rng.uniform(0.3, 3) * h,
            rng.uniform(-0.2, 1.2) * w,
            rng.uniform(-0.2, 1.2) * h,
        )
        lens = None
        if lens_every and i % lens_every == 0:
            lens = tuple(rng.uniform(-0.3, 0.3, 2)) + tuple(rng.uniform(-0.01, 0.01, 2)) + (rng.uniform(-0.05, 0.05),)
        target = rng.uniform(-0.5, 0.5, 3)
        out.append(
            (
                look_at(
                    rng.uniform(-5, 5, 3),
                    target,
                    (0, 1, 0),
                    width=w,
                    height=h,
                    near=0.1,
                    far=100,
                    intrinsics=intr,
                    distortion=lens,
                ),
                target,
            )
        )
    return out


# ---- the convention, pinned ------------------------------------------------------


def test_fov_camera_k_is_unchanged():
    """A FOV camera's K is f_px of its FOV on both axes and the centred principal point, exactly."""
    cam = camera_z(4.0, fov_y_deg=70.0, width=321, height=200)
    f = focal_px(70.0, 200)
    np.testing.assert_array_equal(cam.K, [[f, 0, 160.0], [0, f, 99.5], [0, 0, 1]])
    assert cam.focal_xy == (f, f) and cam.intrinsics is None and cam.distortion is None
    assert "intrinsics" not in cam.to_dict() and "distortion" not in cam.to_dict()


def test_centred_intrinsics_are_the_fov_camera_to_the_bit():
    """fx = fy = f_px and the centred point give the same bytes as the FOV camera (one formula)."""
    cam = look_at((1.0, 2.0, 5.0), (0, 0, 0), (0.2, 1, 0), fov_y_deg=55.0, width=640, height=480)
    f = cam.focal_px
    twin = cam.with_intrinsics(f, f)
    pts = np.random.default_rng(0).uniform(-1, 1, (500, 3))
    assert project_points(pts, twin).tobytes() == project_points(pts, cam).tobytes()
    # the implied FOV: 2 atan((H/2) / f) is fov again, to a few ulp of tan/atan
    assert twin.fov_y_deg == pytest.approx(55.0, rel=8 * EPS)


@pytest.mark.parametrize("coeffs", [LENS, RATIONAL, (0.1, -0.02, 0.003, 0.001)], ids=["5", "8", "4"])
def test_distort_matches_naive_formula(coeffs):
    p = np.random.default_rng(1).uniform(-0.9, 0.9, (1000, 2))
    x, y = naive_distort(p[:, 0], p[:, 1], coeffs)
    # Horner form against term by term: ~15 roundings on values <= ~2: 16 eps x 2.
    np.testing.assert_allclose(distort(p, coeffs), np.column_stack([x, y]), rtol=0, atol=32 * EPS)


def test_core_matches_projectpoints():
    """core against cv2.projectPoints on 200 random calibrated cameras, half with a lens.

    Points within r_n <= 1 of the axis. Each side makes ~25 roundings (rotation
    5, divide 1, distortion ~15, K 2) of quantities bounded by S = max|p_px| +
    max(fx, fy): <= 25 eps S each, 50 eps S for the difference; 64 eps S.
    Measured 8.1 eps S.
    """
    worst = 0.0
    for cam, target in random_cameras(200, seed=7):
        pts = target + np.random.default_rng(1).uniform(-1, 1, (300, 3))
        p_cam = world_to_cam(pts, cam)
        rn = np.hypot(p_cam[:, 0], p_cam[:, 1]) / np.where(p_cam[:, 2] > 0, p_cam[:, 2], np.inf)
        pts = pts[(p_cam[:, 2] > cam.near) & (rn <= 1)]
        if not len(pts):
            continue
        got, want = project_points(pts, cam), opencv_oracle.project(pts, cam)
        s = np.abs(want).max() + max(cam.focal_xy)
        worst = max(worst, np.abs(got - want).max() / (EPS * s))
    assert worst <= 64, worst


def test_unproject_calibrated_and_refuses_a_lens():
    cam = look_at((1, 2, 5), (0, 0, 0), width=640, height=480, intrinsics=(500.0, 420.0, 300.5, 250.25))
    pts = np.random.default_rng(2).uniform(-1, 1, (100, 3))
    back = unproject(project_points(pts, cam), world_to_cam(pts, cam)[:, 2], cam)
    # forward and back: ~20 roundings of coordinates <= ~7: 64 eps x 7.
    np.testing.assert_allclose(back, pts, rtol=0, atol=64 * EPS * 7)
    with pytest.raises(ValueError, match="distortion"):
        unproject(np.zeros((1, 2)), np.ones(1), cam.with_distortion(LENS))


# ---- clipping and the GL-style clip matrix -----------------------------------------


def test_side_planes_follow_fx_fy_cx_cy():
    """A point unprojected onto each image edge lies on its side plane; a pixel beyond is outside."""
    cam = look_at((1, 2, 5), (0, 0, 0), width=320, height=200, intrinsics=(500.0, 300.0, 40.0, 170.0))
    planes = clipping.frustum_planes(cam)[2:]  # left, right, top, bottom
    edges = [(-0.5, 100.0), (319.5, 100.0), (160.0, -0.5), (160.0, 199.5)]
    beyond = [(-0.6, 100.0), (319.6, 100.0), (160.0, -0.6), (160.0, 199.6)]
    z = 3.0
    for plane, on, out in zip(planes, edges, beyond):
        cx, cy = cam.principal_point
        fx, fy = cam.focal_xy
        for (x, y), want in ((on, 0.0), (out, None)):
            p_cam = np.array([(x - cx) * z / fx, -(y - cy) * z / fy, z])
            d = plane[:3] @ p_cam + plane[3]
            if want is None:
                assert d < 0  # 0.1 px outside: d ~ -0.3, far from noise
            else:
                # plane terms ~ f x ~ 1e3 x 3: a few roundings, 16 eps x 3e3
                assert abs(d) <= 16 * EPS * 3e3


def test_clip_matrix_encodes_the_intrinsics():
    """GL's clip -> NDC -> viewport gives core's pixel for off-centre, fx != fy cameras."""
    for cam, target in random_cameras(50, seed=3, lens_every=0):
        pts = target + np.random.default_rng(4).uniform(-1, 1, (50, 3))
        p_cam = world_to_cam(pts, cam)
        p_cam = p_cam[p_cam[:, 2] > cam.near]
        clip = np.column_stack([p_cam, np.ones(len(p_cam))]) @ trace.clip_matrix(cam).T
        px = trace.ndc_to_px(clip[:, :3] / clip[:, 3:], cam)
        want = cam_to_px(p_cam, cam)
        # ~10 roundings through NDC of values <= S = max|p_px| + W + H: 32 eps S
        s = np.abs(want).max() + cam.width + cam.height
        np.testing.assert_allclose(px, want, rtol=0, atol=32 * EPS * s)


def test_clip_matrix_of_a_fov_camera_has_no_offset_terms():
    """(cx + 0.5) = W/2 exactly for a centred camera: the off-centre terms are exactly 0."""
    for w, h in ((640, 480), (321, 233), (1, 1), (7, 16384)):
        p = trace.clip_matrix(camera_z(4.0, width=w, height=h))
        assert (p[0, 2], p[1, 2]) == (0.0, 0.0)


# ---- the contract's matrices and the oracle's conversions ------------------------

CALIBRATED = {
    "offc": look_at(
        (3, 2, 4), (0, 0, 0), (0.3, 1, 0.1), width=640, height=480, intrinsics=(520.0, 520.0, 360.25, 210.5)
    ),
    "aniso": look_at(
        (-1, 2, 6),
        (0.2, 0, 0),
        (0.1, 1, -0.2),
        width=320,
        height=480,
        intrinsics=(700.0, 560.0, 150.0, 250.0),
        distortion=LENS,
    ),
}


@pytest.mark.parametrize("name", list(CALIBRATED))
def test_contract_matrices_match_the_oracle_side(name):
    """Camera.K/R/t/view/projection (core) equal oracles.references.convert's (built independently)."""
    cam = CALIBRATED[name]
    r, t, k = convert.opencv_matrices(cam)
    view, proj = convert.camera_to_gl(cam)
    np.testing.assert_array_equal(cam.K, k)  # the same numbers, no arithmetic
    # rows of unit vectors: equal up to the re-normalisation's ulp; t and view's
    # translation are R @ position (|position| <= 7): 8 eps x 7
    np.testing.assert_allclose(cam.R, r, rtol=0, atol=8 * EPS)
    np.testing.assert_allclose(cam.t, t, rtol=0, atol=8 * EPS * 7)
    np.testing.assert_allclose(cam.view_matrix, view, rtol=0, atol=8 * EPS * 7)
    np.testing.assert_allclose(cam.projection_matrix, proj, rtol=0, atol=4 * EPS)
    np.testing.assert_array_equal(
        convert.distortion_coefficients(cam), np.zeros(5) if cam.distortion is None else cam.distortion
    )


def test_gl_matrices_give_the_pixels_of_projectpoints():
    """P @ V, divide, viewport, flip: the pixels of cv2.projectPoints for an undistorted calibrated camera."""
    cam = CALIBRATED["offc"]
    pts = np.random.default_rng(5).uniform(-1, 1, (200, 3))
    view, proj = convert.camera_to_gl(cam)
    clip = np.column_stack([pts, np.ones(len(pts))]) @ (proj @ view).T
    ndc = clip[:, :3] / clip[:, 3:]
    px = np.column_stack([(ndc[:, 0] + 1) * cam.width / 2 - 0.5, cam.height - (ndc[:, 1] + 1) * cam.height / 2 - 0.5])
    # ~15 roundings of values <= ~1e3 px: 32 eps x 1e3
    np.testing.assert_allclose(px, opencv_oracle.project(pts, cam), rtol=0, atol=32 * EPS * 1e3)


def test_pyrender_intrinsics_camera_and_round_trip():
    cam = CALIBRATED["offc"]  # (convert imports pyrender on OSMesa: PYOPENGL_PLATFORM first)
    pose, pcam = convert.camera_to_pyrender(cam)
    # pyrender measures cx, cy from the pixel corner: + 0.5, exact for these values
    assert (pcam.fx, pcam.fy, pcam.cx, pcam.cy) == (520.0, 520.0, 360.75, 211.0)
    back = convert.pyrender_pose_to_camera(pose, pcam, cam.width, cam.height)
    assert back.intrinsics == cam.intrinsics  # - 0.5 undoes + 0.5 exactly
    with pytest.raises(ValueError, match="lens distortion"):
        convert.camera_to_pyrender(CALIBRATED["aniso"])


def test_protocol_camera_and_host_rebuild():
    from wirecheck.oracles.candidates.candidate_host import _camera
    from wirecheck.oracles.candidates.protocol import camera_message

    cam = CALIBRATED["aniso"]
    msg = camera_message(cam)
    assert msg["intrinsics"] == list(cam.intrinsics) and msg["distortion"] == list(cam.distortion)
    assert msg["K"] == cam.K.tolist()
    back = _camera(msg)
    assert (back.intrinsics, back.distortion) == (cam.intrinsics, cam.distortion)
    plain = camera_message(camera_z(4.0))
    assert plain["intrinsics"] is None and plain["distortion"] is None


# ---- hostile input ------------------------------------------------------------------


@pytest.mark.parametrize(
    "kwargs,match",
    [
        (dict(intrinsics=(500.0, 500.0, 320.0)), "intrinsics fx,fy,cx,cy: expected 4 numbers"),
        (dict(intrinsics=(500.0, float("nan"), 320.0, 240.0)), "expected finite numbers"),
        (dict(intrinsics=(-500.0, 500.0, 320.0, 240.0)), "expected focal lengths > 0"),
        (dict(intrinsics=(1e300, 500.0, 320.0, 240.0)), r"expected \|fx\|"),
        (dict(intrinsics=(1e-300, 500.0, 320.0, 240.0)), "expected focal lengths >="),
        (dict(intrinsics="abcd"), "expected 4 numbers"),
        (dict(intrinsics=(500.0, 500.0, 320.0, 240.0), projection="orthographic"), "expected a perspective camera"),
        (dict(distortion=(0.1, 0.2, 0.3)), "expected 4, 5 or 8 numbers"),
        (dict(distortion=(0.1, float("inf"), 0.0, 0.0)), "k2=inf"),
        (dict(distortion=(1e9, 0.0, 0.0, 0.0)), "k1=1000000000.0"),
        (dict(distortion=(0.1, 0.0, 0.0, 0.0), projection="orthographic"), "expected a perspective camera"),
    ],
)
def test_hostile_camera_input(kwargs, match):
    with pytest.raises(InputError, match=match):
        look_at((0, 0, 4), (0, 0, 0), **kwargs)


def test_with_k_refuses_skew_and_all_zero_lens_is_none():
    cam = camera_z(4.0)
    with pytest.raises(InputError, match="no skew"):
        cam.with_K([[500, 1, 320], [0, 500, 240], [0, 0, 1]])
    assert cam.with_K([[500, 0, 320], [0, 400, 240], [0, 0, 1]]).intrinsics == (500.0, 400.0, 320.0, 240.0)
    assert cam.with_distortion((0.0, 0.0, 0.0, 0.0, 0.0)).distortion is None


# ---- the crosscheck cases -------------------------------------------------------------


def test_crosscheck_calibrated_cases(tmp_path):
    """core against pyrender's IntrinsicsCamera and cv2.projectPoints; the lens case by its vertices."""
    from helpers import run_crosscheck
    from wirecheck.oracles.judge.case import PIXELS_NOT_COMPARED
    from wirecheck.oracles.references.pyrender_oracle import osmesa_available

    if not osmesa_available()[0]:
        pytest.skip("no OSMesa")
    code, report, _ = run_crosscheck(
        tmp_path,
        "--scene",
        "cube",
        "--scene",
        "prism",
        "--frames",
        "6",
        "--cases",
        "off_centre,non_square_pixels,distorted",
    )
    assert code == 0 and report["verdict"] == "pass"
    by = {(c["scene"], c["camera"]): c for c in report["cases"]}
    for scene in ("cube", "prism"):
        for name in ("off_centre", "non_square_pixels"):
            c = by[(scene, name)]
            # measured F1@0px >= 0.997, F1@1px 1.0: the run's floors (0.98, 0.999) hold
            assert c["pixel_f1_1px"] >= 0.999 and c["pixel_f1_0px"] >= 0.98 and c["compared"]["pixels"] > 0
            assert c["max_vertex_error_px"] <= 1e-6
        lens = by[(scene, "distorted")]
        assert lens["note"] == PIXELS_NOT_COMPARED
        assert lens["pixel_f1_0px"] is None and lens["compared"]["pixels"] is None
        assert lens["compared"]["vertices"] > 0 and lens["max_vertex_error_px"] <= 1e-6
        assert lens["camera_spec"]["distortion"] == list(LENS_OF_CASES())


def LENS_OF_CASES():  # noqa: N802
    from wirecheck.oracles.cases import DISTORTION

    return DISTORTION


def test_only_distorted_cases_at_level_pixels_is_refused(tmp_path):
    """It would compare no pixel: exit 2 with one line, not a pass and not a vacuous fail."""
    import contextlib
    import io

    from wirecheck.oracles import cli

    err = io.StringIO()
    with contextlib.redirect_stderr(err):
        code = cli.main(
            ["--report-dir", str(tmp_path / "r"), "--scene", "cube", "--frames", "2", "--cases", "distorted"]
        )
    assert code == 2 and "lens distortion" in err.getvalue() and len(err.getvalue().strip().splitlines()) == 1
    assert not (tmp_path / "r").exists()


def test_faults_of_calibrated_candidates_through_crosscheck():
    """A candidate with its principal point off, and one ignoring the lens, named through the API."""
    from wirecheck.oracles.api import check_projector

    def pp_off(points, camera):
        p = project_points(points, camera)
        return p + [2.0, -1.0]

    def no_lens(points, camera):
        return project_points(points, camera.with_distortion(None))

    rep = check_projector(pp_off, scenes=["cube"], frames=3, cases=["off_centre", "non_square_pixels"], isolate=False)
    for c in rep["cases"]:
        (f,) = c["faults"]
        # an exactly representable shift of pixels <= 640: the fit recovers it to ~1e-12 px
        assert f["name"] == "pixel_offset" and (f["dx"], f["dy"]) == pytest.approx((2.0, -1.0), abs=1e-9)
    rep = check_projector(no_lens, scenes=["cube"], frames=3, cases=["distorted"], isolate=False)
    (c,) = rep["cases"]
    assert c["verdict"] == "fail" and [f["name"] for f in c["faults"]] == ["distortion_mismatch"]
    assert c["faults"][0]["kind"] == "ignored"


def test_export_calibrated_cases_and_refuses_a_lens(tmp_path):
    from wirecheck.core.scene.files import load_scene
    from wirecheck.oracles.candidates.export import build_job
    from wirecheck.oracles.cases import CASE_NAMES

    job, files = build_job([load_scene("cube")], frames=2)
    assert [c["case"] for c in job["cases"]] == list(CASE_NAMES)  # the default set, unchanged
    job, files = build_job([load_scene("cube")], frames=2, case_names=["off_centre"])
    cam = __import__("json").loads(files["cameras/cube/off_centre/frame_0001.json"])
    assert cam["camera"]["intrinsics"] == [460.0, 460.0, 389.5, 194.5] and cam["K"][0][2] == 389.5
    with pytest.raises(InputError, match="lens distortion"):
        build_job([load_scene("cube")], frames=2, case_names=["off_centre", "distorted"])


def test_calibrated_cases_run_only_when_named():
    """The default set is the seven FOV cases: a FOV-only projector's verdicts do not change."""
    from wirecheck.oracles.cases import ALL_CASE_NAMES, CALIBRATED_CASE_NAMES, CASE_NAMES, cameras_for
    from wirecheck.oracles.judge.gate import resolve_cases

    assert CASE_NAMES == (
        "on_axis",
        "oblique_roll",
        "near_plane",
        "wide_fov",
        "narrow_fov",
        "non_square",
        "orthographic",
    )
    assert CALIBRATED_CASE_NAMES == ("off_centre", "non_square_pixels", "distorted")
    assert resolve_cases(None) == CASE_NAMES and [c.name for c in cameras_for(2.0)] == list(CASE_NAMES)
    assert resolve_cases("distorted,on_axis") == ("on_axis", "distorted")
    assert [c.name for c in cameras_for(2.0, calibrated=True)] == list(ALL_CASE_NAMES)


# ---- renderer flags ---------------------------------------------------------------------


@pytest.mark.parametrize(
    "args,match",
    [
        (["--intrinsics", "500,400,300"], "--intrinsics '500,400,300': expected 4 finite numbers"),
        (["--intrinsics=-5,400,300,200"], "expected focal lengths > 0"),
        (["--intrinsics", "500,400,nan,200"], "expected 4 finite numbers"),
        (["--intrinsics", "500,400,300,200", "--fov", "50"], "--fov and --intrinsics: expected one of them"),
        (["--intrinsics", "500,400,300,200", "--projection", "both"], "expected --projection perspective"),
        (["--distortion", "0.1,0,0"], "expected 4 or 5 or 8 finite numbers"),
        (["--distortion", "1e9,0,0,0"], r"k1=1000000000.0: expected finite numbers with \|value\| <= 10000"),
        (["--distortion", "0.1,0,0,0", "--hidden-lines"], "faces do not; expected a wireframe"),
        (["--distortion", "0.1,0,0,0", "--compare"], "its cameras are set by FOV"),
    ],
)
def test_renderer_lens_flags_hostile(tmp_path, args, match):
    import re

    from helpers import run_renderer

    out = tmp_path / "out"
    frames = [] if "--compare" in args else ["--frames", "2"]  # --compare refuses --frames (it renders at rest)
    rc, _, err = run_renderer([*frames, *args], out)
    assert rc == 2 and len(err.strip().splitlines()) == 1 and re.search(match, err), err
    assert not out.exists()  # nothing written


def test_renderer_centred_intrinsics_draw_the_fov_frames(tmp_path):
    """--intrinsics f,f,(W-1)/2,(H-1)/2 with f of --fov 60 gives the same PNG bytes (one projection formula)."""
    from helpers import run_renderer

    f = focal_px(60.0, 480)
    rc1, _, _ = run_renderer(["--frames", "3", "--format", "png"], tmp_path / "fov")
    rc2, _, _ = run_renderer(
        ["--frames", "3", "--format", "png", f"--intrinsics={f!r},{f!r},319.5,239.5"], tmp_path / "k"
    )
    assert rc1 == rc2 == 0
    a = sorted((tmp_path / "fov" / "cube-frames").glob("*.png"))
    b = sorted((tmp_path / "k" / "cube-frames").glob("*.png"))
    assert len(a) == len(b) == 3 and [p.read_bytes() for p in a] == [p.read_bytes() for p in b]


def test_wrappers_that_take_the_cameras_matrices():
    """A cv2.projectPoints wrapper (K, R, t, distortion) passes every case, through the candidate host
    (the protocol's camera rebuilt); a GL wrapper (projection @ view) passes all but the lens, named."""
    from pathlib import Path

    from wirecheck.oracles.api import check_projector
    from wirecheck.oracles.cases import ALL_CASE_NAMES

    spec = str(Path(__file__).parent / "data" / "matrix_projectors.py")
    rep = check_projector(f"{spec}:opencv_style", scenes=["cube"], frames=3, cases=list(ALL_CASE_NAMES))
    assert rep["verdict"] == "pass" and [c["camera"] for c in rep["cases"]] == list(ALL_CASE_NAMES)
    rep = check_projector(f"{spec}:gl_style", scenes=["cube"], frames=3, cases=list(ALL_CASE_NAMES))
    verdicts = {c["camera"]: (c["verdict"], [f["name"] for f in c["faults"]]) for c in rep["cases"]}
    assert verdicts.pop("distorted") == ("fail", ["distortion_mismatch"])
    assert all(v == ("pass", []) for v in verdicts.values()) and len(verdicts) == 9
