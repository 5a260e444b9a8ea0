"""Each convention of core/conventions.py pinned by a test that fails if it were reversed.

Hand derivations are in the comments. Unless stated otherwise the camera is
``camera_z(D)``: at (0, 0, D) looking at the origin with up +Y, so (derived in
core/conventions.py) right = +X, up = +Y, forward = -Z and
p_cam = (x, y, D - z) exactly (all rotation entries are 0 or +-1).
"""

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal
from wirecheck.core.camera import camera_z, look_at
from wirecheck.core.conventions import PIXEL_CENTRE_OFFSET, focal_px, principal_point
from wirecheck.core.projector.projection import project_points, world_to_cam
from wirecheck.core.transforms import apply, compose, rotate_x, rotate_y, rotate_z, translate

EPS = np.finfo(np.float64).eps  # 2.2e-16

# Pixel tolerance for values of magnitude <= 640 computed with ~6 float64
# operations (each <= 0.5 ulp = EPS/2 relative): 6 * 1.1e-16 * 640 = 4.3e-13.
PX_TOL = 1e-12


# The default camera below, by hand (core/conventions.py): 640 x 480, so the
# principal point is ((640 - 1) / 2, (480 - 1) / 2) = (319.5, 239.5); fov_y 60,
# so f = (480 / 2) / tan(30 deg) = 240 sqrt(3) = 415.69 px. Literals, not
# core's Camera.principal_point / focal_px: a test must not take its expected
# value from the code under test.
CX, CY = 319.5, 239.5
F = 240.0 * math.sqrt(3.0)


def cam(D=4.0, **kw):
    kw.setdefault("width", 640)
    kw.setdefault("height", 480)
    kw.setdefault("fov_y_deg", 60.0)
    return camera_z(D, **kw)


# ---- screen orientation ------------------------------------------------------


def test_plus_x_shows_on_the_right():
    c = cam()
    ((x, y),) = project_points([[1.0, 0.0, 0.0]], c)
    # p_cam = (1, 0, 4): x_px = cx + f/4 (> cx), y_px = cy.
    assert x > CX
    assert_allclose([x, y], [CX + F / 4.0, CY], rtol=0, atol=PX_TOL)


def test_plus_y_shows_up():
    c = cam()
    ((x, y),) = project_points([[0.0, 1.0, 0.0]], c)
    # p_cam = (0, 1, 4): y_px = cy - f/4 (< cy: pixel rows grow downward).
    assert y < CY
    assert_allclose([x, y], [CX, CY - F / 4.0], rtol=0, atol=PX_TOL)


def test_right_is_forward_cross_up_camera_z():
    c = cam()
    # forward = -Z, up = +Y: (-Z) x (+Y) = +X. (up x forward would give -X.)
    assert_array_equal(c.forward, [0.0, 0.0, -1.0])
    assert_array_equal(c.up, [0.0, 1.0, 0.0])
    assert_array_equal(c.right, [1.0, 0.0, 0.0])


def test_right_is_forward_cross_up_looking_down_plus_z():
    # forward = +Z, up = +Y: (+Z) x (+Y) = (0*0 - 1*1, 1*0 - 0*0, 0) = -X.
    c = look_at((0, 0, 0), (0, 0, 1), (0, 1, 0))
    assert_array_equal(c.right, [-1.0, 0.0, 0.0])
    # so a world point at +X shows on the LEFT of this camera
    ((x, _),) = project_points([[1.0, 0.0, 5.0]], c)
    assert x < CX  # look_at's defaults are 640 x 480 too


@pytest.mark.parametrize("seed", range(5))
def test_right_is_forward_cross_up_general(seed):
    rng = np.random.default_rng(seed)
    c = look_at(rng.normal(size=3) * 5, rng.normal(size=3), rng.normal(size=3))
    # Unit vectors: cross-product rounding is a few EPS per component.
    assert_allclose(c.right, np.cross(c.forward, c.up), rtol=0, atol=8 * EPS)
    # camera basis is left-handed: right x up = -forward
    assert_allclose(np.cross(c.right, c.up), -c.forward, rtol=0, atol=8 * EPS)


def test_world_to_cam_rows_are_right_up_forward():
    c = look_at((1.0, 2.0, 3.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    m = c.world_to_cam
    assert_array_equal(m[0, :3], c.right)
    assert_array_equal(m[1, :3], c.up)
    assert_array_equal(m[2, :3], c.forward)
    # the camera's own position maps to the camera-space origin; position is
    # ~3.7 units, the 3-term dot product rounds ~3 times: 3 * EPS * 4 ~ 2.7e-15
    assert_allclose(apply(m, [c.position])[0], [0, 0, 0], rtol=0, atol=1e-14)


# ---- depth -------------------------------------------------------------------


def test_depth_positive_in_front_negative_behind():
    c = cam(D=4.0, near=0.1)
    p_cam = world_to_cam(np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 5.0]]), c)
    # origin is 4 in front of the camera; z = 5 is 1 behind it (p_cam z = D - z)
    assert_array_equal(p_cam[:, 2], [4.0, -1.0])
    px = project_points([[0.0, 0.0, 0.0], [0.0, 0.0, 5.0]], c)
    assert np.all(np.isfinite(px[0]))
    assert np.all(np.isnan(px[1]))


# ---- pixel centres -------------------------------------------------------------


@pytest.mark.parametrize("w,h,expected", [(640, 480, (319.5, 239.5)), (5, 3, (2.0, 1.0)), (1, 1, (0.0, 0.0))])
def test_principal_point_is_image_centre_in_pixel_centre_coordinates(w, h, expected):
    # Pixel (0,0) covers [-0.5, 0.5]; the image spans [-0.5, W-0.5], centre (W-1)/2.
    assert principal_point(w, h) == expected
    assert cam(width=w, height=h).principal_point == expected


@pytest.mark.parametrize("w,h", [(640, 480), (5, 3), (101, 37)])
def test_point_on_optical_axis_lands_on_principal_point(w, h):
    c = cam(width=w, height=h)
    px = project_points([[0.0, 0.0, 0.0], [0.0, 0.0, -7.0]], c)
    # x_cam = y_cam = 0 exactly, so cx + f*0/z is cx exactly
    assert_array_equal(px, [[(w - 1) / 2, (h - 1) / 2]] * 2)


def test_gl_pixel_centre_offset_is_half():
    # GL window coordinates put centres at half-integers; ours at integers.
    assert PIXEL_CENTRE_OFFSET == 0.5


# ---- field of view -------------------------------------------------------------


def test_focal_length_formula():
    # f = (H/2)/tan(fov/2); fov 90 -> f = 240 / tan(45 deg) = 240 (tan(pi/4) is
    # 1 - 1.1e-16 in float64, so f = 240 * (1 + 1.1e-16): tolerance 2 ulp of 240)
    assert_allclose(focal_px(90.0, 480), 240.0, rtol=2 * EPS)
    # fov 60: tan 30 = 1/sqrt(3) -> f = 240 sqrt(3)
    assert_allclose(focal_px(60.0, 480), 240.0 * math.sqrt(3.0), rtol=4 * EPS)


@pytest.mark.parametrize("fov", [30.0, 60.0, 90.0, 120.0])
@pytest.mark.parametrize("w,h", [(640, 480), (320, 240), (100, 300)])
def test_vertical_fov_is_edge_to_edge(fov, w, h):
    c = cam(D=10.0, fov_y_deg=fov, width=w, height=h, far=1000.0)
    z = 5.0  # depth of the test points
    ty = math.tan(math.radians(fov) / 2.0)
    tx = (w / h) * ty  # horizontal half-FOV tangent
    # world z = D - z_cam. Top edge of the vertical FOV: y/z = tan(fov/2) ->
    # y_px = cy - f*ty = (H-1)/2 - H/2 = -0.5 (top edge of row 0).
    # Bottom: H - 0.5. Right: x/z = (W/H) ty -> x_px = (W-1)/2 + W/2 = W - 0.5.
    pts = [[0.0, z * ty, 10.0 - z], [0.0, -z * ty, 10.0 - z], [z * tx, 0.0, 10.0 - z], [-z * tx, 0.0, 10.0 - z]]
    px = project_points(pts, c)
    cx, cy = (w - 1) / 2, (h - 1) / 2
    expected = [[cx, -0.5], [cx, h - 0.5], [w - 0.5, cy], [-0.5, cy]]
    assert_allclose(px, expected, rtol=0, atol=PX_TOL)


# ---- rotations and matrix order ----------------------------------------------


# |cos(pi/2)| in float64 is 6.1e-17 < EPS: a 90-degree rotation of a unit
# vector is exact up to EPS per component.
@pytest.mark.parametrize(
    "rot,src,dst",
    [
        (rotate_z, [1, 0, 0], [0, 1, 0]),  # +X -> +Y
        (rotate_x, [0, 1, 0], [0, 0, 1]),  # +Y -> +Z
        (rotate_y, [0, 0, 1], [1, 0, 0]),  # +Z -> +X
    ],
)
def test_rotations_are_right_handed(rot, src, dst):
    assert_allclose(apply(rot(math.pi / 2), [src])[0], dst, rtol=0, atol=EPS)


def test_rotate_z_90_shows_counter_clockwise_on_screen():
    # camera_z looks down -Z, so +Z points at the viewer: rotate_z(90) turns the
    # point (1,0,0) (right of centre) to (0,1,0) (above centre) on screen.
    c = cam(D=4.0)
    ((x, y),) = project_points(apply(rotate_z(math.pi / 2), [[1.0, 0.0, 0.0]]), c)
    # x_cam = cos(pi/2) = 6e-17: x_px - cx = f * 6e-17 / 4 ~ 5e-15
    assert_allclose([x, y], [CX, CY - F / 4.0], rtol=0, atol=PX_TOL)


def test_compose_applies_rightmost_first():
    p = [[1.0, 0.0, 0.0]]
    t = translate((1.0, 0.0, 0.0))
    r = rotate_z(math.pi / 2)
    # compose(T, R): rotate first: (1,0,0) -> (0,1,0), then +X: (1,1,0)
    # compose(R, T): translate first: (2,0,0), then rotate: (0,2,0)
    # cos(pi/2) = 6e-17 times coordinates <= 2 plus rounding: < 4 EPS
    assert_allclose(apply(compose(t, r), p)[0], [1.0, 1.0, 0.0], rtol=0, atol=4 * EPS)
    assert_allclose(apply(compose(r, t), p)[0], [0.0, 2.0, 0.0], rtol=0, atol=4 * EPS)


def test_column_vector_convention_matches_matrix_product():
    # p' = M @ p for column vectors; apply() of row-stacked points is the same.
    m = compose(translate((1.0, -2.0, 3.0)), rotate_y(0.3), rotate_x(-1.1))
    p = np.array([0.5, 2.0, -4.0])
    expected = (m @ np.append(p, 1.0))[:3]
    # |p| ~ 4.5, matrix entries <= 1: a few roundings of values ~ 5: 8 * EPS * 5
    assert_allclose(apply(m, [p])[0], expected, rtol=0, atol=8 * EPS * 5)


def test_tiny_camera_offsets_still_give_unit_axes():
    # position 1e-200 above the target: forward = (0, 0, -1e-200). Scaled by its
    # largest component first it is (0, 0, -1) exactly; its norm taken directly
    # would underflow (1e-400 -> 0) and give NaN.
    c = look_at((0.0, 0.0, 1e-200), (0.0, 0.0, 0.0), (0.0, 1e-200, 0.0))
    assert_array_equal(c.forward, [0.0, 0.0, -1.0])
    assert_array_equal(c.up, [0.0, 1.0, 0.0])
    assert_array_equal(c.right, [1.0, 0.0, 0.0])


def test_world_to_cam_of_camera_z_by_hand():
    # camera_z(4): right +X, up +Y, forward -Z, at (0, 0, 4): p_cam = (x, y, 4 - z),
    # an affine 4 x 4 whose last row is (0, 0, 0, 1)
    assert_array_equal(cam(D=4.0).world_to_cam, [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, -1, 4], [0, 0, 0, 1]])


def test_orthographic_scale_that_overflows_is_refused():
    # H / ortho_height = 480 / 1e-320 = inf: refused when the camera is built, naming the field
    from wirecheck.core.errors import InputError

    with pytest.raises(InputError, match="ortho-height"):
        cam(projection="orthographic", ortho_height=1e-320)
    cam(projection="orthographic", ortho_height=1e-300)  # 4.8e302: finite, accepted


def test_calibrated_intrinsics_fx_on_columns_cx_added():
    """x_px = cx + fx x/z, y_px = cy - fy y/z (core.conventions): fx on columns, cx added.

    Camera at (0, 0, 4) looking at -Z: p_cam = (x, y, 4 - z). The world point
    (1, 2, 0) is p_cam (1, 2, 4): x = 100.25 + 500/4 = 225.25, y = 50.5 - 600/4
    = -99.5, exact in float64 (dyadic). Swapping fx and fy, or cx and cy, or
    the sign of the y term, changes both numbers.
    """
    cam = camera_z(4.0, width=640, height=480, intrinsics=(500.0, 300.0, 100.25, 50.5))
    assert project_points([[1.0, 2.0, 0.0]], cam).tolist() == [[225.25, -99.5]]
    np.testing.assert_array_equal(cam.K, [[500, 0, 100.25], [0, 300, 50.5], [0, 0, 1]])


def test_distortion_acts_on_y_down_normalised_points():
    """OpenCV's model on (x/z, -y/z): y down, so p1/p2 keep OpenCV's signs.

    Camera at (0, 0, 4), K = [[400, 0, 320], [0, 400, 240]]. World (2, 2, 0) is
    p_cam (2, 2, 4): x_n = 0.5, y_n = -0.5 (y down). With p1 = 0.01 alone:
    x_d = x + 2 p1 x y = 0.5 - 0.005 = 0.495, y_d = y + p1 (r2 + 2 y^2) = -0.5 +
    0.01 = -0.49, so the pixel is (320 + 198, 240 - 196) = (518, 44). A y-up
    normalised point (0.5, +0.5) would give (522, 36); a reversed p1 (512, 36).
    k1 alone scales the radius: world (0, 2, 0) -> y_n = -0.5, r2 = 0.25,
    y_d = -0.5 (1 + 0.1 / 4) = -0.5125, y_px = 240 - 205 = 35.
    """
    cam = camera_z(4.0, width=640, height=480, intrinsics=(400.0, 400.0, 320.0, 240.0))
    got = project_points([[2.0, 2.0, 0.0]], cam.with_distortion((0.0, 0.0, 0.01, 0.0)))
    assert_allclose(got, [[518.0, 44.0]], rtol=0, atol=PX_TOL)
    got = project_points([[0.0, 2.0, 0.0]], cam.with_distortion((0.1, 0.0, 0.0, 0.0)))
    assert_allclose(got, [[320.0, 35.0]], rtol=0, atol=PX_TOL)
