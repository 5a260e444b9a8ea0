"""core.projector.projection against hand-derived values and a naive per-point projector.

``naive_project`` below is an independent reference written from
core/conventions.py in plain Python math (no numpy, no core code): it builds
the camera basis itself, loops over points and applies the formulas
    x_px = cx + f x/z,  y_px = cy - f y/z,  f = (H/2)/tan(fov_y/2).
"""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose, assert_array_equal
from wirecheck.core.camera import Camera, camera_z, look_at
from wirecheck.core.projector.projection import cam_to_px, depth_mask, project_points, world_to_cam
from wirecheck.core.transforms import apply, rotate_y, rotate_z

EPS = np.finfo(np.float64).eps  # 2.2e-16
SQRT2, SQRT3, SQRT6 = math.sqrt(2.0), math.sqrt(3.0), math.sqrt(6.0)


# ---- naive reference ---------------------------------------------------------------


def _sub(a, b):
    return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]


def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def _unit(a):
    n = math.sqrt(_dot(a, a))
    return [a[0] / n, a[1] / n, a[2] / n]


def naive_basis(pos, target, up):
    fwd = _unit(_sub(target, pos))
    right = _unit(_cross(fwd, up))
    return right, _cross(right, fwd), fwd


def naive_project(
    points, pos, target, up, fov_y_deg, width, height, near, far, projection="perspective", ortho_height=2.0
):
    """Per-point loop: returns a list of (x_px, y_px) or (nan, nan), and the camera coords."""
    right, upv, fwd = naive_basis(pos, target, up)
    cx, cy = (width - 1) / 2.0, (height - 1) / 2.0
    f = (height / 2.0) / math.tan(math.radians(fov_y_deg) / 2.0)
    out, cams = [], []
    for p in points:
        d = _sub(p, pos)
        x, y, z = _dot(right, d), _dot(upv, d), _dot(fwd, d)
        cams.append((x, y, z))
        if not (near <= z <= far):
            out.append((math.nan, math.nan))
        elif projection == "perspective":
            out.append((cx + f * x / z, cy - f * y / z))
        else:
            s = height / ortho_height
            out.append((cx + s * x, cy - s * y))
    return np.array(out, dtype=float).reshape(-1, 2), np.array(cams).reshape(-1, 3), f


def px_tolerance(cams, points, pos, f, width):
    """Per-point bound on |core - naive| in pixels.

    Camera coordinates: |p - pos| up to |p| + |pos|; a 3-term dot product with
    basis vectors that carry ~3 EPS of error each gives an absolute error
    delta <= 8 EPS (|p| + |pos|). Pixel: d(f x/z) = f (dx/z + x dz/z^2), so
    <= f delta/z (1 + |x/z| + |y/z|); the final cx + f*x/z adds <= 4 roundings
    of values <= cx + f (|x/z| + |y/z|).
    """
    mag = np.abs(points).max(axis=1) * math.sqrt(3) + np.abs(pos).max() * math.sqrt(3)
    delta = 8 * EPS * mag
    z = np.abs(cams[:, 2])
    ratio = (np.abs(cams[:, 0]) + np.abs(cams[:, 1])) / z
    return f * delta / z * (1 + ratio) + 4 * EPS * (width + f * ratio)


def random_camera_and_points(rng, n=200, near=0.1, far=100.0):
    pos = rng.uniform(-10, 10, 3)
    target = pos + rng.normal(size=3)
    up = rng.normal(size=3)
    right, upv, fwd = naive_basis(pos.tolist(), target.tolist(), up.tolist())
    # camera-space samples: mostly in front, some behind / beyond far; keep every
    # depth at least 1e-3 away from near and far so both sides classify alike.
    z = rng.uniform(-5, 1.5 * far, n)
    z = z[(np.abs(z - near) > 1e-3) & (np.abs(z - far) > 1e-3)]
    xy = rng.uniform(-1, 1, (len(z), 2)) * np.maximum(np.abs(z), 1)[:, None]
    b = np.array([right, upv, fwd])
    points = pos + np.column_stack([xy, z]) @ b
    return pos, target, up, points


# ---- the seed's thinking exercise --------------------------------------------------


def seed_camera():
    # Camera at the origin looking down +Z, up +Y, 640x480, fov_y 120 deg:
    # forward = +Z, right = forward x up = (+Z) x (+Y) = -X, up = +Y,
    # so p_cam = (-x, y, z). f = 240 / tan(60 deg) = 240/sqrt(3) = 80 sqrt(3).
    return look_at((0, 0, 0), (0, 0, 1), (0, 1, 0), fov_y_deg=120.0, width=640, height=480, near=0.1, far=100.0)


def test_seed_points_rotated_45_about_y_camera_space():
    # Ry(45): x' = c x + s z, y' = y, z' = -s x + c z with c = s = sqrt(2)/2:
    #   (1,1,4) -> (5 sqrt2/2, 1, 3 sqrt2/2)
    #   (1,1,8) -> (9 sqrt2/2, 1, 7 sqrt2/2)
    p_world = apply(rotate_y(math.pi / 4), [[1.0, 1.0, 4.0], [1.0, 1.0, 8.0]])
    # magnitudes <= 6.4, ~4 roundings each (cos/sin of pi/4 are 1 ulp apart): 4 EPS * 6.4
    tol = 4 * EPS * 6.4
    assert_allclose(p_world, [[5 * SQRT2 / 2, 1, 3 * SQRT2 / 2], [9 * SQRT2 / 2, 1, 7 * SQRT2 / 2]], rtol=0, atol=tol)
    p_cam = world_to_cam(p_world, seed_camera())
    assert_allclose(p_cam, [[-5 * SQRT2 / 2, 1, 3 * SQRT2 / 2], [-9 * SQRT2 / 2, 1, 7 * SQRT2 / 2]], rtol=0, atol=tol)


def test_seed_points_rotated_45_about_y_pixels():
    c = seed_camera()
    px = project_points(apply(rotate_y(math.pi / 4), [[1.0, 1.0, 4.0], [1.0, 1.0, 8.0]]), c)
    # point 1: x/z = -5/3, y/z = 1/(3 sqrt2/2) = sqrt2/3
    #   x_px = 319.5 - 80 sqrt3 * 5/3 = 319.5 - 400/sqrt3          ~  88.56
    #   y_px = 239.5 - 80 sqrt3 * sqrt2/3 = 239.5 - 80 sqrt6/3      ~ 174.18
    # point 2: x/z = -9/7, y/z = sqrt2/7
    #   x_px = 319.5 - 720 sqrt3/7                                  ~ 141.35
    #   y_px = 239.5 - 80 sqrt6/7                                   ~ 211.51
    expected = [[319.5 - 400 / SQRT3, 239.5 - 80 * SQRT6 / 3], [319.5 - 720 * SQRT3 / 7, 239.5 - 80 * SQRT6 / 7]]
    # x/z carries ~6 EPS relative error, times f|x/z| <= 240, plus cx + ...: 6 EPS * 320 ~ 4e-13
    assert_allclose(px, expected, rtol=0, atol=1e-12)


# The principal point of a 640 x 480 image, by hand (core/conventions.py):
# ((640 - 1) / 2, (480 - 1) / 2). Literal: never core's Camera.principal_point.
CX, CY = 319.5, 239.5


def test_seed_farther_point_is_closer_to_principal_point():
    c = seed_camera()
    cx, cy = CX, CY
    px = project_points(apply(rotate_y(math.pi / 4), [[1.0, 1.0, 4.0], [1.0, 1.0, 8.0]]), c)
    off = px - [cx, cy]
    # |off1| = f sqrt(25 + 2)/3 = 80 sqrt3 * sqrt27 / 3 = 240 exactly;
    # |off2| = f sqrt(81 + 2)/7 = 80 sqrt(249)/7 ~ 180.3: the farther point is closer.
    dist = np.hypot(off[:, 0], off[:, 1])
    assert_allclose(dist, [240.0, 80 * math.sqrt(249) / 7], rtol=0, atol=1e-12)
    assert dist[1] < dist[0]
    # both have y = 1: vertical offsets shrink by the depth ratio z2/z1 = 7/3 exactly
    assert_allclose(off[0, 1] / off[1, 1], 7 / 3, rtol=8 * EPS)


def test_perspective_shrink_by_depth_ratio_unrotated():
    # (1,1,4) and (1,1,8) before rotation: same x, y; depth ratio 2 -> offset ratio 2.
    c = seed_camera()
    off = project_points([[1.0, 1.0, 4.0], [1.0, 1.0, 8.0]], c) - [CX, CY]
    f = 80 * SQRT3
    # p_cam = (-1, 1, 4) and (-1, 1, 8): offsets (-f/4, -f/4) and (-f/8, -f/8)
    assert_allclose(off, [[-f / 4, -f / 4], [-f / 8, -f / 8]], rtol=0, atol=1e-12)


# ---- naive reference on random input -----------------------------------------------


@pytest.mark.parametrize("seed", range(20))
def test_project_points_matches_naive_reference(seed):
    rng = np.random.default_rng(seed)
    fov = rng.uniform(10, 150)
    w, h = int(rng.integers(1, 2000)), int(rng.integers(1, 2000))
    pos, target, up, pts = random_camera_and_points(rng)
    c = look_at(pos, target, up, fov_y_deg=fov, width=w, height=h, near=0.1, far=100.0)
    got = project_points(pts, c)
    want, cams, f = naive_project(pts.tolist(), pos.tolist(), target.tolist(), up.tolist(), fov, w, h, 0.1, 100.0)
    assert_array_equal(np.isnan(got), np.isnan(want))
    vis = ~np.isnan(want[:, 0])
    assert vis.sum() > 10 and (~vis).sum() > 0  # both branches exercised
    tol = px_tolerance(cams[vis], pts[vis], pos, f, w)
    assert np.all(np.abs(got[vis] - want[vis]) <= tol[:, None])


@settings(max_examples=200, deadline=None)
@given(x=st.floats(-50, 50), y=st.floats(-50, 50), z=st.floats(0.1, 100))
def test_single_point_matches_formula_hypothesis(x, y, z):
    # camera_z(D=0 is invalid) -> camera at (0,0,200) looking at origin: p_cam = (x, y, 200 - z_w)
    c = camera_z(200.0, fov_y_deg=60.0, width=640, height=480, near=0.1, far=100.0)
    ((xp, yp),) = project_points([[x, y, 200.0 - z]], c)
    f = 240.0 * SQRT3
    # 200 - (200 - z) may differ from z by ulp(200)/2 = 1.4e-14 absolute: relative
    # 1.4e-14/z <= 1.4e-13 at z = 0.1; the pixel offset f|x|/z <= 416*50/0.1 = 2e5,
    # so tol = 2e5 * (1.4e-14/z_rel + 6 EPS) -> bound computed per point:
    off_x, off_y = f * x / z, f * y / z
    rel = 1.5e-14 / z + 6 * EPS
    if 200.0 - (200.0 - z) < 0.1:  # rounding pushed the depth below near: clipped
        assert math.isnan(xp)
        return
    assert abs(xp - (319.5 + off_x)) <= abs(off_x) * rel + 4 * EPS * 320
    assert abs(yp - (239.5 - off_y)) <= abs(off_y) * rel + 4 * EPS * 240


# ---- orthographic ------------------------------------------------------------------


def test_orthographic_scale_is_height_over_ortho_height():
    c = camera_z(10.0, projection="orthographic", ortho_height=4.0, width=640, height=480, near=0.1, far=100.0)
    # s = 480 / 4 = 120 px per unit; depth does not matter.
    pts = [[1.0, 2.0, 0.0], [1.0, 2.0, 5.0], [-0.5, -1.0, -50.0], [0.0, -2.0, 0.0]]
    px = project_points(pts, c)
    # (1,2): x = 319.5 + 120 = 439.5, y = 239.5 - 240 = -0.5 (top edge: ortho_height/2 up)
    expected = [[439.5, -0.5], [439.5, -0.5], [259.5, 359.5], [319.5, 479.5]]
    assert_array_equal(px, expected)  # every value is exact in binary (multiples of 0.5)


def test_orthographic_matches_naive():
    rng = np.random.default_rng(7)
    pos, target, up, pts = random_camera_and_points(rng, near=-5.0, far=50.0)
    c = look_at(
        pos, target, up, projection="orthographic", ortho_height=3.0, width=320, height=200, near=-5.0, far=50.0
    )
    got = project_points(pts, c)
    want, cams, _ = naive_project(
        pts.tolist(), pos.tolist(), target.tolist(), up.tolist(), 60.0, 320, 200, -5.0, 50.0, "orthographic", 3.0
    )
    assert_array_equal(np.isnan(got), np.isnan(want))
    vis = ~np.isnan(want[:, 0])
    # s = 200/3 ~ 67; camera coordinates err <= 8 EPS (|p| + |pos|) <= 8 EPS * 300 = 5.3e-13;
    # times s: 3.6e-11, plus rounding of values <= s*|x| ~ 1e4: 4 EPS * 1e4 = 9e-12
    assert_allclose(got[vis], want[vis], rtol=0, atol=5e-11)


# ---- depth -------------------------------------------------------------------------


def test_depth_monotonicity():
    c = camera_z(10.0, fov_y_deg=60.0, near=0.5, far=100.0)
    cx, cy = CX, CY  # 640 x 480 (camera_z's default)
    f = 240.0 * SQRT3  # (480 / 2) / tan(30 deg)
    zw = np.linspace(9.5, -80.0, 60)  # depth D - z from 0.5 to 90, increasing
    pts = np.column_stack([np.ones_like(zw), np.ones_like(zw), zw])
    depth = world_to_cam(pts, c)[:, 2]
    assert_array_equal(depth, 10.0 - zw)  # translation by exact 10, signs exact
    assert np.all(np.diff(depth) > 0)
    px = project_points(pts, c)
    off = px[:, 0] - cx
    # farther -> strictly closer to the principal point, exactly f/depth
    assert np.all(np.diff(off) < 0)
    # px = cx + f/z is rounded at magnitude <= cx + f/0.5 ~ 1150, so after subtracting
    # cx the offset carries an absolute error ~ 2 roundings of 1150: 4 EPS * 1200
    assert_allclose(off, f / depth, rtol=0, atol=4 * EPS * 1200)
    assert_allclose(cy - px[:, 1], f / depth, rtol=0, atol=4 * EPS * 1200)


@pytest.mark.parametrize("deg", range(0, 361, 15))
def test_rotation_about_optical_axis_keeps_distance_to_principal_point(deg):
    # camera_z looks down -Z; rotating (1,0,0) about Z by theta moves its image on
    # a circle of radius f/4 about (cx, cy), counter-clockwise on screen:
    # (cx + r cos theta, cy - r sin theta).
    c = camera_z(4.0, fov_y_deg=70.0)
    cx, cy = CX, CY  # 640 x 480 (camera_z's default)
    th = math.radians(deg)
    ((x, y),) = project_points(apply(rotate_z(th), [[1.0, 0.0, 0.0]]), c)
    r = 240.0 / math.tan(math.radians(35.0)) / 4.0  # f = (480 / 2) / tan(70 deg / 2), at depth 4
    # cos/sin rounding EPS times r ~ 86, plus cx rounding: 4 EPS * 320
    assert_allclose([x, y], [cx + r * math.cos(th), cy - r * math.sin(th)], rtol=0, atol=4 * EPS * 320)


# ---- visibility ----------------------------------------------------------------------


def test_visibility_near_and_far_inclusive():
    c = camera_z(10.0, near=1.0, far=20.0)
    # p_cam z = 10 - z_world, exact for these values
    pts = [
        [0.1, 0.1, 9.0],  # z = near exactly: visible
        [0.1, 0.1, 9.5],  # z = 0.5 < near: clipped
        [0.1, 0.1, -10.0],  # z = far exactly: visible
        [0.1, 0.1, -10.5],  # z = 20.5 > far: clipped
        [0.1, 0.1, 10.0],  # z = 0: clipped (never divided by)
        [0.1, 0.1, 11.0],
    ]  # behind: clipped
    px = project_points(pts, c)
    assert_array_equal(np.isnan(px).all(axis=1), [False, True, False, True, True, True])
    assert_array_equal(np.isnan(px).any(axis=1), np.isnan(px).all(axis=1))
    assert_array_equal(depth_mask(world_to_cam(np.array(pts), c), c), [True, False, True, False, False, False])


def test_project_points_accepts_empty_input():
    px = project_points(np.zeros((0, 3)), camera_z(4.0))
    assert px.shape == (0, 2)


# ---- extremes ----------------------------------------------------------------------


@pytest.mark.parametrize("fov", [1e-3, 179.9])
@pytest.mark.parametrize("seed", range(3))
def test_extreme_fov_finite_and_matching_naive(fov, seed):
    rng = np.random.default_rng(100 + seed)
    pos, target, up, pts = random_camera_and_points(rng)
    c = look_at(pos, target, up, fov_y_deg=fov, width=640, height=480, near=0.1, far=100.0)
    got = project_points(pts, c)
    want, cams, f = naive_project(pts.tolist(), pos.tolist(), target.tolist(), up.tolist(), fov, 640, 480, 0.1, 100.0)
    vis = ~np.isnan(want[:, 0])
    assert_array_equal(np.isnan(got[:, 0]), ~vis)
    assert np.all(np.isfinite(got[vis]))
    # f is 2.75e7 (fov 1e-3) or 0.21 (fov 179.9); the bound scales with f (see px_tolerance)
    tol = px_tolerance(cams[vis], pts[vis], pos, f, 640)
    assert np.all(np.abs(got[vis] - want[vis]) <= tol[:, None])


@pytest.mark.parametrize("s", [1e-6, 1e6])
def test_coordinate_scales(s):
    # camera at the origin looking down +Z: p_cam = (-x, y, z) exactly; perspective is
    # scale invariant: pixels of s*P equal pixels of P.
    c = Camera(
        position=(0, 0, 0), forward=(0, 0, 1), up=(0, 1, 0), fov_y_deg=60.0, width=640, height=480, near=1e-7, far=1e8
    )
    rng = np.random.default_rng(5)
    p = np.column_stack([rng.uniform(-1, 1, (50, 2)), rng.uniform(1, 10, 50)])
    base = project_points(p, c)
    scaled = project_points(p * s, c)
    assert np.all(np.isfinite(scaled))
    # s*x and s*z each round once (EPS/2), so (s x)/(s z) = x/z (1 + 2 EPS);
    # the offset f|x/z| <= 416: 3 EPS * 416, plus 1 EPS of cx
    assert_allclose(scaled, base, rtol=0, atol=4 * EPS * 416)
    f = 240 * SQRT3
    assert_allclose(scaled[:, 0], 319.5 - f * p[:, 0] / p[:, 2], rtol=0, atol=4 * EPS * 416)


def test_cam_to_px_perspective_formula_direct():
    c = camera_z(4.0, fov_y_deg=90.0, width=100, height=50)
    # f = 25 / tan(45) = 25 (1 + 1.1e-16); cx = 49.5, cy = 24.5
    px = cam_to_px(np.array([[2.0, 1.0, 4.0], [-2.0, -1.0, 2.0]]), c)
    assert_allclose(px, [[49.5 + 12.5, 24.5 - 6.25], [49.5 - 25, 24.5 + 12.5]], rtol=0, atol=4 * EPS * 64)


# ---- localize: far-off models are re-centred ------------------------------------------


def test_localize_recentres_a_model_far_from_its_origin():
    from wirecheck.core.projector.projection import localize

    # a box from (999, 1000, 1001) to (1001, 1002, 1003): centre (1000, 1001, 1002), half-extent 1;
    # |centre| > 1, so the points are stored relative to the centre (exact: all small integers)
    p = np.array([[999.0, 1000.0, 1001.0], [1001.0, 1002.0, 1003.0]])
    lp = localize(p, "float32")
    assert_array_equal(lp.origin, [1000.0, 1001.0, 1002.0])
    assert_array_equal(lp.p_local, [[-1, -1, -1], [1, 1, 1]]) and lp.p_local.dtype == np.float32
    # a box about its own origin stays as it is: centre (0.5, 0, 0), half-extent 1.5
    q = np.array([[-1.0, -1.0, -1.0], [2.0, 1.0, 1.0]])
    lq = localize(q)
    assert_array_equal(lq.origin, [0.0, 0.0, 0.0])
    assert_array_equal(lq.p_local, q)


def test_float32_pixels_are_the_plain_float32_expressions():
    # cam_to_px computes in p_cam's dtype: x_px = (x f) (1 / z) + cx, y_px = cy - (y f) (1 / z),
    # every operation rounded to float32. The naive float32 numpy expressions give the same bits.
    from wirecheck.core.camera import camera_z

    c = camera_z(4.0, fov_y_deg=60.0)  # 640 x 480
    p = np.random.default_rng(3).uniform([-2, -2, 0.5], [2, 2, 9], size=(200, 3)).astype(np.float32)
    f32 = np.float32(240.0 * SQRT3)  # (480 / 2) / tan(30 deg), rounded to float32
    inv_z = np.float32(1.0) / p[:, 2]
    want_x = (p[:, 0] * f32) * inv_z + np.float32(CX)
    want_y = np.float32(CY) - (p[:, 1] * f32) * inv_z
    got = cam_to_px(p, c)
    assert got.dtype == np.float32
    assert_array_equal(got, np.column_stack([want_x, want_y]))
