"""oracles.references.convert: hand-derived values and round trips of both conversions."""

import math

import numpy as np
import pytest
from wirecheck.core.camera import camera_z, look_at
from wirecheck.core.transforms import Motion
from wirecheck.oracles.references import convert

EPS = np.finfo(np.float64).eps

CAMERAS = {
    "camera_z": camera_z(4.0, fov_y_deg=90.0, width=640, height=480, near=1.0, far=10.0),
    "oblique_roll": look_at(
        (3.0, -2.0, 5.0),
        (0.3, 0.1, -0.2),
        up=(0.4, 1.0, 0.3),
        fov_y_deg=47.5,
        width=320,
        height=200,
        near=0.25,
        far=50.0,
    ),
    "looking_down": look_at(
        (0.5, 6.0, 0.2), (0.0, 0.0, 0.0), up=(0.0, 0.0, -1.0), fov_y_deg=30.0, width=101, height=77
    ),
    "ortho_oblique": look_at(
        (4.0, 3.0, -4.0),
        (0.0, 0.5, 0.0),
        up=(0.2, 1.0, 0.0),
        projection="orthographic",
        ortho_height=3.5,
        width=160,
        height=90,
    ),
}


def _rodrigues_tol(rvec, scale):
    """Round-trip tolerance through cv2.Rodrigues.

    R -> rvec recovers the axis from (R - R^T) / (2 sin theta), so its error is
    about eps / |sin theta| (measured: <= 5 eps / |sin theta| over 5000 random
    cameras). 16 eps / |sin theta| with a floor on |sin theta| of 1e-6 (theta
    exactly pi, as for camera_z, takes OpenCV's exact diagonal branch), times
    the magnitude of the quantity compared.
    """
    s = abs(math.sin(float(np.linalg.norm(rvec))))
    return 16 * EPS * max(scale, 1.0) / max(s, 1e-6)


def test_opencv_hand_values_camera_z():
    # camera at (0,0,4) looking at -Z, up +Y: right = +X, so OpenCV rows are
    # (1,0,0), (0,-1,0), (0,0,-1): a rotation by pi about x; t = -R p = (0,0,4).
    rvec, tvec, k = convert.camera_to_opencv(CAMERAS["camera_z"])
    # R = diag(1, -1, -1) is exact (unit axis vectors), and theta = pi takes
    # OpenCV's diagonal branch: axis = sqrt((R_ii + 1) / 2) exact, theta from
    # acos(-1) or atan2: a few ulp of pi. 4 ulp of pi.
    np.testing.assert_allclose(rvec, [math.pi, 0.0, 0.0], rtol=0, atol=4 * EPS * math.pi)
    np.testing.assert_array_equal(tvec, [0.0, 0.0, 4.0])
    # f = 240 / tan(45 deg); tan(pi/4) is 1 - 1 ulp in float64, so 2 ulp of 240.
    np.testing.assert_allclose(k, [[240.0, 0, 319.5], [0, 240.0, 239.5], [0, 0, 1]], rtol=0, atol=2 * EPS * 240)


def test_opencv_orthographic_affine_k():
    cam = CAMERAS["ortho_oblique"]
    _, _, k = convert.camera_to_opencv(cam)
    # s = H / ortho_height = 90 / 3.5; centre (159.5, 44.5); exact arithmetic.
    np.testing.assert_array_equal(k, [[90 / 3.5, 0, 79.5], [0, 90 / 3.5, 44.5], [0, 0, 1]])


@pytest.mark.parametrize("name", list(CAMERAS))
def test_opencv_round_trip(name):
    cam = CAMERAS[name]
    rvec, tvec, k = convert.camera_to_opencv(cam)
    back = convert.opencv_to_camera(rvec, tvec, k, cam.width, cam.height, cam.near, cam.far, projection=cam.projection)
    tol_dir = _rodrigues_tol(rvec, 1.0)
    tol_pos = _rodrigues_tol(rvec, np.abs(cam.position).max())
    np.testing.assert_allclose(back.position, cam.position, rtol=0, atol=tol_pos)
    np.testing.assert_allclose(back.forward, cam.forward, rtol=0, atol=tol_dir)
    np.testing.assert_allclose(back.up, cam.up, rtol=0, atol=tol_dir)
    np.testing.assert_allclose(back.right, cam.right, rtol=0, atol=tol_dir)
    assert back.projection == cam.projection
    if cam.projection == "perspective":
        # fov -> f -> fov through tan and atan: a few ulp of the angle.
        assert back.fov_y_deg == pytest.approx(cam.fov_y_deg, rel=8 * EPS)
    else:
        # s = H / ortho_height, then H / s: two roundings, <= 1 ulp each; 4 eps.
        assert back.ortho_height == pytest.approx(cam.ortho_height, rel=4 * EPS)


def test_opencv_to_camera_rejects_foreign_k():
    rvec, tvec, k = convert.camera_to_opencv(CAMERAS["camera_z"])
    skewed = k.copy()
    skewed[0, 1] = 0.5  # skew: no camera of ours has it
    with pytest.raises(ValueError, match="skew"):
        convert.opencv_to_camera(rvec, tvec, skewed, 640, 480, 1.0, 10.0)
    rvec, tvec, k = convert.camera_to_opencv(CAMERAS["ortho_oblique"])
    k = k.copy()
    k[0, 2] += 3.0  # orthographic cameras stay centred
    with pytest.raises(ValueError, match="principal point"):
        convert.opencv_to_camera(rvec, tvec, k, 160, 90, 1.0, 10.0, projection="orthographic")


def test_opencv_to_camera_off_centre_k_is_calibrated():
    rvec, tvec, k = convert.camera_to_opencv(CAMERAS["camera_z"])
    k = k.copy()
    k[0, 2] += 3.0  # off-centre principal point
    cam = convert.opencv_to_camera(rvec, tvec, k, 640, 480, 1.0, 10.0, dist=(0.1, 0.0, 0.0, 0.0))
    # the K entries are carried over as they are: exact
    assert cam.intrinsics == (k[0, 0], k[1, 1], 322.5, 239.5)
    assert cam.distortion == (0.1, 0.0, 0.0, 0.0)


def test_pyrender_hand_values_camera_z():
    pose, pcam = convert.camera_to_pyrender(CAMERAS["camera_z"])
    # columns right, up, -forward, position: identity rotation, translated to z=4
    np.testing.assert_array_equal(pose, [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 4], [0, 0, 0, 1]])
    # pyrender measures cx, cy from the corner: (W-1)/2 + 0.5 = W/2 exactly.
    assert (pcam.cx, pcam.cy) == (320.0, 240.0)
    # f = 240 / tan(45 deg); tan(pi/4) is 1 - 1 ulp in float64 -> <= 2 ulp of 240.
    assert pcam.fx == pcam.fy == pytest.approx(240.0, rel=2 * EPS)
    assert (pcam.znear, pcam.zfar) == (1.0, 10.0)
    # pyrender's projection matrix maps the camera-space point (1, 1, -4) to
    # window (320 + 60, 240 + 60) from the bottom-left corner, i.e. row
    # 480 - 300 = 180 from the top (corner origin) = pixel centre 179.5.
    p = pcam.get_projection_matrix(640, 480) @ np.array([1.0, 1.0, -4.0, 1.0])
    ndc = p[:3] / p[3]
    x_win, y_win = (ndc[0] + 1) * 320, (ndc[1] + 1) * 240
    # fx carries 2 ulp (above); P00 = 2 fx / W, the product with (1, 1, -4, 1)
    # (P02 = 1 - 2 cx / W = 0 exactly), the division by w = 4 (exact), + 1 and
    # x 320 add <= 1 ulp each: ~6 relative roundings on a value of ~380, i.e.
    # <= 6 x 2.2e-16 x 380 ~ 5e-13 px (measured 0). 1e-12 leaves 2x margin --
    # enough, since every step is counted -- and is far below the 0.5 px
    # corner/centre shift the check is about.
    assert x_win - 0.5 == pytest.approx(379.5, abs=1e-12)
    assert (480 - y_win) - 0.5 == pytest.approx(179.5, abs=1e-12)


def test_pyrender_orthographic_magnification():
    cam = CAMERAS["ortho_oblique"]
    _, pcam = convert.camera_to_pyrender(cam)
    assert pcam.ymag == 3.5 / 2  # halving is exact
    # xmag = ymag * W / H: the same two roundings in the same order as the
    # expected value, so equal; rel = 1 ulp in case pyrender re-rounds it.
    assert pcam.xmag == pytest.approx(3.5 / 2 * 160 / 90, rel=EPS)


@pytest.mark.parametrize("name", list(CAMERAS))
def test_pyrender_round_trip(name):
    cam = CAMERAS[name]
    pose, pcam = convert.camera_to_pyrender(cam)
    # The pose holds the camera's own unit vectors: no arithmetic, so the only
    # error is Camera re-normalising them (a few ulp).
    np.testing.assert_allclose(pose[:3, :3].T @ pose[:3, :3], np.eye(3), rtol=0, atol=8 * EPS)
    assert np.linalg.det(pose[:3, :3]) == pytest.approx(1.0, abs=8 * EPS)  # right-handed
    back = convert.pyrender_pose_to_camera(pose, pcam, cam.width, cam.height)
    np.testing.assert_allclose(back.position, cam.position, rtol=0, atol=0)
    for attr in ("forward", "up", "right"):
        np.testing.assert_allclose(getattr(back, attr), getattr(cam, attr), rtol=0, atol=8 * EPS)
    assert (back.near, back.far, back.projection) == (cam.near, cam.far, cam.projection)
    if cam.projection == "perspective":
        # fov -> f -> fov through tan and atan: a few ulp of the angle (as above).
        assert back.fov_y_deg == pytest.approx(cam.fov_y_deg, rel=8 * EPS)
    else:
        assert back.ortho_height == cam.ortho_height  # x / 2 then x 2: exact


MOTIONS = [
    Motion(),
    Motion(turns=(0.0, 0.0, 1.0)),
    Motion(turns=(0.37, -1.25, 2.0), offset=(1.5, -0.25, 3.0), scale=2.5),
    Motion(turns=(3.0, 0.5, -0.75), offset=(0.0, 10.0, -4.0), scale=0.1),
]


@pytest.mark.parametrize("motion", MOTIONS, ids=range(len(MOTIONS)))
@pytest.mark.parametrize("t", [0.0, 0.1, 0.25, 0.5, 0.7, 35 / 36])
def test_model_matrix_matches_core(motion, t):
    ours = convert.model_matrix(motion.turns, motion.offset, motion.scale, t)
    core = motion.model_matrix(t)
    # scipy goes through a quaternion: each rotation entry carries a few ulp of
    # error (of magnitude 1), times the scale; translation is copied exactly.
    tol = 16 * EPS * motion.scale
    np.testing.assert_allclose(ours[:3, :3], core[:3, :3], rtol=0, atol=tol)
    np.testing.assert_array_equal(ours[:3, 3], core[:3, 3])
    np.testing.assert_array_equal(ours[3], [0, 0, 0, 1])


def test_model_matrix_hand_values():
    # a quarter turn about Z maps +X to +Y (right-handed, core.conventions)
    m = convert.model_matrix((0.0, 0.0, 1.0), (0.0, 0.0, 0.0), 1.0, 0.25)
    # cos(pi/2) rounds to 6e-17, not 0, and scipy's quaternion path adds a few
    # ulp to entries of magnitude 1: 4 eps.
    np.testing.assert_allclose(m[:3, :3] @ [1, 0, 0], [0, 1, 0], rtol=0, atol=4 * EPS)
    # X first, then Y: Rx(90) takes +Y to +Z, Ry(90) takes +Z to +X.
    m = convert.model_matrix((1.0, 1.0, 0.0), (1.0, 2.0, 3.0), 2.0, 0.25)
    # two quarter turns: a few ulp per entry, doubled by the composition (8 eps),
    # times the scale 2; the translation is added exactly.
    np.testing.assert_allclose(m @ [0, 1, 0, 1], [1 + 2, 2, 3, 1], rtol=0, atol=8 * EPS * 2)


def test_model_matrix_memo_gives_each_caller_its_own_matrix():
    """model_matrix is memoised: a caller writing into its matrix must not change the next caller's."""
    first = convert.model_matrix((0.0, 0.0, 1.0), (1.0, 2.0, 3.0), 1.0, 0.25)
    first[:] = 0.0
    again = convert.model_matrix((0.0, 0.0, 1.0), (1.0, 2.0, 3.0), 1.0, 0.25)
    np.testing.assert_array_equal(again[:3, 3], [1.0, 2.0, 3.0])  # the offset, copied exactly
    # -0.0 and 0.0 compare equal but are different inputs: each gets its own translation's sign
    neg = convert.model_matrix((0.0, 0.0, 0.0), (-0.0, 0.0, 0.0), 1.0, 0.0)
    pos = convert.model_matrix((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), 1.0, 0.0)
    assert np.signbit(neg[0, 3]) and not np.signbit(pos[0, 3])


# ---- OpenGL matrices (the candidate protocol's view_matrix / projection_matrix)


def test_gl_hand_values_camera_z():
    # camera_z: at (0, 0, 4) looking down -Z, up +Y: GL eye space is world space shifted by -4 in z
    view, proj = convert.camera_to_gl(CAMERAS["camera_z"])
    expected_view = np.eye(4)
    expected_view[2, 3] = -4.0
    np.testing.assert_array_equal(view, expected_view)
    # fov 90: f = 1 / tan(45 deg) = 1 (to 1 ulp); aspect 640/480; near 1, far 10
    g = 1.0 / math.tan(math.radians(45.0))
    expected = np.array([[g * 480 / 640, 0, 0, 0], [0, g, 0, 0], [0, 0, -11.0 / 9.0, -20.0 / 9.0], [0, 0, -1.0, 0]])
    np.testing.assert_allclose(proj, expected, rtol=4 * EPS, atol=0)


@pytest.mark.parametrize("name", sorted(CAMERAS))
def test_gl_matrices_give_opencv_pixels(name):
    # x_px = (x_ndc + 1) W/2 - 0.5, y_px = (1 - y_ndc) H/2 - 0.5 (docs/protocol.md); the NDC cube
    # holds exactly the points with depth in [near, far] (z_ndc = -1 at near, +1 at far)
    from wirecheck.oracles.references import opencv_oracle

    cam = CAMERAS[name]
    p_world = np.random.default_rng(5).uniform(-8, 8, (4000, 3))
    view, proj = convert.camera_to_gl(cam)
    clip = np.c_[p_world, np.ones(len(p_world))] @ (proj @ view).T
    ndc = clip[:, :3] / clip[:, 3:]
    px = np.c_[(ndc[:, 0] + 1) * cam.width / 2 - 0.5, (1 - ndc[:, 1]) * cam.height / 2 - 0.5]
    ref = opencv_oracle.project(p_world, cam)
    depth = opencv_oracle.depth(p_world, cam)
    inside = (depth >= cam.near) & (depth <= cam.far)
    assert (np.isfinite(ref[:, 0]) == inside).all() and 100 < inside.sum() < len(p_world)
    # away from the planes (1e-9 relative), the NDC depth test decides visibility as the depth does
    clear = np.abs(depth - cam.near) > 1e-9 * cam.far
    clear &= np.abs(depth - cam.far) > 1e-9 * cam.far
    assert ((np.abs(ndc[:, 2]) <= 1) == inside)[clear].all()
    # float64 through a 4x4 product and a divide: ~10 eps relative, amplified by |p_world| / depth
    # (<= 14 / 0.25 = 56) on coordinates < 1e5 px: < 1e-8 px; relative 1e-12 of the coordinate
    err = np.abs(px[inside] - ref[inside]).max(axis=1)
    assert (err <= 1e-12 * np.maximum(np.abs(ref[inside]).max(axis=1), 1.0)).all()
