"""Property tests (hypothesis): core vs OpenCV in float32 and float64, through both of
core's paths; project/unproject round trips; orthonormality of composed rotations.

tests/test_core_vs_opencv.py already checks float64 ``project_points`` against
OpenCV; here the same random cameras also run in **float32**, points may sit
far from the world origin (camera-relative precision), and the model-view path
of ``render_frame`` runs with random model matrices.

Bounds come from oracles/extremes/bounds.py (``camera_error``, ``pixel_bound``; the
derivations are their docstrings), evaluated at the long-double reference's
camera coordinates and pixels:

    e_i = 3 eps (|A| |p_local| + |t_mv_i|) + 2 eps64 (...) + 3 eps64 F   (camera x, y, z; render_frame)
    e_i = 3 eps (|A| |p_local| + |t_mv|)   + ...                          (a projector casting p_world - position whole: path="world")
    px <= 2 [ f (e_x + e_y + r e_z / z) / z + 2 eps f r / z + eps (|x_px| + |y_px|) + kappa_f eps64 f r / z ]

with eps the dtype's (float32: 1.2e-7). OpenCV's own error is the same formula
with e_cv = 8 eps64 (|X| + |position|), so core and OpenCV agree within the sum
of the two bounds (triangle inequality through the exact value).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from wirecheck.core.camera import look_at
from wirecheck.core.projector.pipeline import render_frame
from wirecheck.core.projector.projection import project_points, unproject
from wirecheck.core.transforms import Motion, compose, rotate_x, rotate_y, rotate_z
from wirecheck.oracles.extremes import (
    EPS,
    EPS64,
    LD,
    REFERENCE_EXTENDED,
    camera_error,
    opencv_camera_error,
    pixel_bound,
    reference_project,
    reference_world,
)
from wirecheck.oracles.references import opencv_oracle
from wirecheck.oracles.references.convert import model_matrix as scipy_model_matrix

# The bounds are evaluated at a long-double reference: it must be wider than float64.
needs_extended = pytest.mark.skipif(
    not REFERENCE_EXTENDED, reason="np.longdouble is plain float64 here: no extended-precision reference"
)

DTYPE = st.sampled_from(["float64", "float32"])


def random_camera(rng, fov, width, height, distance, ortho, target):
    direction = rng.normal(size=3)
    position = np.asarray(target) + distance * direction / np.linalg.norm(direction)
    up = rng.normal(size=3)
    fwd = np.asarray(target) - position
    if np.linalg.norm(np.cross(fwd, up)) < 1e-3 * np.linalg.norm(fwd) * np.linalg.norm(up):
        up = np.cross(fwd, [1.0, 0.0, 0.0]) + [0.0, 0.0, 1.0]
    return look_at(
        position,
        target,
        up,
        fov_y_deg=fov,
        width=width,
        height=height,
        near=0.01 * distance,
        far=3 * distance,
        projection="orthographic" if ortho else "perspective",
        ortho_height=distance,
    )


def near_band(ref_cam, camera, e, eps):
    """Points whose exact depth is within e_z (+ the plane's rounding to the dtype, u |plane|)
    of near or far: there two correct computations may disagree on visibility."""
    z = ref_cam[:, 2]
    out = np.zeros(len(z), bool)
    for plane in (camera.near, camera.far):
        out |= np.abs(z - LD(plane)).astype(float) <= e[:, 2] + eps * abs(plane)
    return out


def assert_agrees_with_opencv(cand_px, p_world, camera, e_core, eps_core, ref):
    """core's pixels vs OpenCV's within bound(core) + bound(OpenCV), visibility outside the band."""
    ref_cam, ref_px, _ = ref
    cv_px = opencv_oracle.project(p_world, camera)
    e_cv = opencv_camera_error(p_world, camera)
    band = near_band(ref_cam, camera, e_core + e_cv, eps_core)
    vis_c, vis_o = ~np.isnan(cand_px[:, 0]), ~np.isnan(cv_px[:, 0])
    assert np.array_equal(vis_c[~band], vis_o[~band])
    both = vis_c & vis_o
    if not both.any():
        return
    bound = (
        pixel_bound(ref_cam, ref_px, camera, e_core, eps_core) + pixel_bound(ref_cam, ref_px, camera, e_cv, EPS64)
    )[both]
    err = np.hypot(*(cand_px[both] - cv_px[both]).T)
    assert np.all(err <= bound), float((err / bound).max())


# ---- 1a: project_points (world path), both dtypes, points possibly far from the origin ----


@needs_extended
@settings(max_examples=120, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    fov=st.one_of(st.floats(0.01, 179.9), st.sampled_from([0.01, 1.0, 90.0, 179.9])),
    width=st.integers(1, 4096),
    height=st.integers(1, 4096),
    distance=st.floats(0.5, 1e4),
    far_away=st.sampled_from([0.0, 1e3, 1e6, 1e8]),
    ortho=st.booleans(),
    dtype=DTYPE,
)
def test_project_points_matches_opencv(seed, fov, width, height, distance, far_away, ortho, dtype):
    rng = np.random.default_rng(seed)
    target = far_away * rng.normal(size=3) / math.sqrt(3)  # the scene may sit ~1e8 from the origin
    cam = random_camera(rng, fov, width, height, distance, ortho, target)
    pts = target + rng.uniform(-1, 1, (200, 3)) * distance
    ref = reference_project(pts, cam)
    # project_points takes render_frame's model-view path with A = I: the points are
    # re-centred by localize, R (o - position) is formed in float64 and cast per
    # component, so camera component i carries 3 eps (|p_local| + |t_mv_i|):
    # camera_error(path="model_view").
    e_core = camera_error(dtype, pts, None, cam)
    assert_agrees_with_opencv(project_points(pts, cam, dtype), pts, cam, e_core, EPS[dtype], ref)


# ---- 1b: render_frame's model-view path with a random model matrix, both dtypes ----


@needs_extended
@settings(max_examples=120, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    fov=st.one_of(st.floats(0.5, 170.0), st.sampled_from([0.01, 179.9])),
    size=st.tuples(st.integers(1, 2048), st.integers(1, 2048)),
    radius=st.floats(0.01, 1e3),
    far_away=st.sampled_from([0.0, 1e4, 1e8]),
    scale=st.floats(0.1, 10.0),
    dtype=DTYPE,
)
def test_render_frame_model_view_matches_opencv(seed, fov, size, radius, far_away, scale, dtype):
    rng = np.random.default_rng(seed)
    turns = rng.uniform(-3, 3, 3)
    offset = far_away * rng.normal(size=3) / math.sqrt(3)
    # the model matrix comes from scipy (oracles.references.convert), not core.transforms
    m = scipy_model_matrix(turns, offset, scale, float(rng.uniform(0, 1)))
    p_model = rng.uniform(-1, 1, (150, 3)) * radius
    distance = 4 * radius * scale
    cam = random_camera(rng, fov, size[0], size[1], distance, False, offset)
    frame = render_frame(p_model, np.zeros((0, 2), int), cam, m, dtype=dtype)
    ref = reference_project(p_model, cam, m)
    # OpenCV gets world points A p + t, rounded once to float64: that rounding
    # (eps64 |X|) is inside OpenCV's 8 eps64 (|X| + |position|).
    p_world = reference_world(p_model, m[:3, :3], m[:3, 3]).astype(np.float64)
    e_core = camera_error(dtype, p_model, m, cam)
    assert_agrees_with_opencv(frame.p_px, p_world, cam, e_core, EPS[dtype], ref)
    # depth is z_cam of every vertex: within e_cam of the exact one
    assert np.all(np.abs(frame.depth - ref[0][:, 2].astype(float)) <= 2 * e_core[:, 2])


# ---- 2: project then unproject at the known depth ----


@needs_extended
@settings(max_examples=150, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    fov=st.one_of(st.floats(0.01, 179.9), st.sampled_from([0.01, 179.9])),
    width=st.integers(1, 4096),
    height=st.integers(1, 4096),
    distance=st.floats(0.5, 1e4),
    far_away=st.sampled_from([0.0, 1e6]),
    ortho=st.booleans(),
)
def test_unproject_inverts_project(seed, fov, width, height, distance, far_away, ortho):
    rng = np.random.default_rng(seed)
    target = far_away * rng.normal(size=3) / math.sqrt(3)
    cam = random_camera(rng, fov, width, height, distance, ortho, target)
    pts = target + rng.uniform(-1, 1, (200, 3)) * distance
    ref_cam, ref_px, ref_vis = reference_project(pts, cam)
    px = project_points(pts, cam)
    vis = ~np.isnan(px[:, 0]) & ref_vis
    if not vis.any():
        return
    z = ref_cam[vis, 2].astype(np.float64)  # the known depth (exact to u |z|)
    back = unproject(px[vis], z, cam)
    # Derivation. Projection leaves the pixel within B_px (pixel_bound). Unprojection
    # maps a pixel error to a lateral one times k = z / f (orthographic: 1 / s); its
    # own arithmetic rounds (x_px - cx) relative to |x_px| + |cx| (u), then * k (2u,
    # with k's own rounding); the given depth is within u |z| of the exact one, and
    # moves the lateral coordinate by u |x_cam| too. Then R^T p_cam (3u |p_cam| plus
    # core's basis, 2 eps |p_cam|) + position (u (|p| + |position|)):
    #   |back - p| <= 2 [ k (B_px + eps (|x_px| + |y_px| + cx + cy)) + 5 eps |p_cam| + eps (|p| + |position|) ]
    e_cam = camera_error("float64", pts, None, cam)
    b_px = pixel_bound(ref_cam, ref_px, cam, e_cam, EPS64)[vis]
    k = z / cam.focal_px if cam.projection == "perspective" else np.full_like(z, cam.ortho_height / cam.height)
    cx, cy = cam.principal_point
    p_cam_norm = np.linalg.norm(ref_cam[vis].astype(float), axis=1)
    bound = 2 * (
        k * (b_px + EPS64 * (np.abs(px[vis]).sum(axis=1) + cx + cy))
        + 5 * EPS64 * p_cam_norm
        + EPS64 * (np.linalg.norm(pts[vis], axis=1) + np.linalg.norm(cam.position))
    )
    err = np.linalg.norm(back - pts[vis], axis=1)
    assert np.all(err <= bound), float((err / bound).max())


# ---- 3: composed rotations stay orthonormal ----
#
# Why ~n eps suffices for n factors. Each rotate_* has entries c, s with
# c^2 + s^2 = 1 within ~2 eps (math.cos/sin are within 1 ulp), so each factor's
# Q^T Q - I is within 2 eps per entry. A float64 product fl(P Q) = P Q + E with
# |E_ij| <= 3u sum_k |P_ik| |Q_kj| <= 1.5 eps (Cauchy-Schwarz: rows and columns
# of near-orthonormal matrices have norm ~1). For a near-orthonormal X, the
# defect of X + E grows by at most 2 |E|_2 <= 2 * 3 * 1.5 eps = 9 eps. So after
# n factors (n - 1 products) and the check's own product (1.5 eps):
#   |R^T R - I|_max <= (2 n + 9 (n - 1) + 2) eps <= (11 n + 2) eps,
# linear in n (errors of random sign grow ~sqrt(n); the linear bound is the
# worst case). n <= 200 gives <= 2202 eps = 4.9e-13 < 1e-12.

ROT = {"x": rotate_x, "y": rotate_y, "z": rotate_z}


def defect(a):
    a = a[:3, :3]
    return float(np.abs(a.T @ a - np.eye(3)).max())


@settings(max_examples=100, deadline=None)
@given(
    factors=st.lists(
        st.tuples(st.sampled_from("xyz"), st.one_of(st.floats(-7.0, 7.0), st.floats(-1e4, 1e4))),
        min_size=1,
        max_size=200,
    )
)
def test_composed_rotations_stay_orthonormal(factors):
    r = compose(*(ROT[axis](angle) for axis, angle in factors))
    n = len(factors)
    d = defect(r)
    assert d <= (11 * n + 2) * EPS64
    assert d <= 1e-12
    assert np.array_equal(r[3], [0, 0, 0, 1]) and np.array_equal(r[:3, 3], [0, 0, 0])


@settings(max_examples=100, deadline=None)
@given(
    turns=st.tuples(*[st.integers(-(10**6), 10**6)] * 3),
    frames=st.integers(1, 10**7),
    ks=st.lists(st.integers(1, 10**7), min_size=1, max_size=50),
)
def test_motion_rotations_stay_orthonormal(turns, frames, ks):
    motion = Motion(turns=tuple(float(t) for t in turns))
    mats = [motion.frame_matrix(k, frames) for k in ks]
    # one frame matrix: 3 factors -> (11 * 3 + 2) eps = 35 eps
    for m in mats:
        assert defect(m) <= 35 * EPS64
    # the product of all of them: 3 len(ks) factors
    n = 3 * len(mats)
    d = defect(compose(*mats))
    assert d <= (11 * n + 2) * EPS64
    assert d <= 1e-12
