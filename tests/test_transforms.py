"""core.transforms: rotation matrices, composition order and Motion (time -> model matrix).

The independent reference is Rodrigues' formula in plain Python math:
R = cos(a) I + sin(a) [k]x + (1 - cos(a)) k k^T for a unit axis k.
"""

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal
from wirecheck.core.transforms import Motion, apply, compose, rotate_x, rotate_y, rotate_z, scale, translate

EPS = np.finfo(np.float64).eps  # 2.2e-16
AXES = {rotate_x: (1.0, 0.0, 0.0), rotate_y: (0.0, 1.0, 0.0), rotate_z: (0.0, 0.0, 1.0)}


def rodrigues(axis, a):
    """3x3 rotation by angle a (radians, right-handed) about unit axis, plain Python."""
    kx, ky, kz = axis
    c, s = math.cos(a), math.sin(a)
    k = [[0.0, -kz, ky], [kz, 0.0, -kx], [-ky, kx, 0.0]]
    kk = [[kx * kx, kx * ky, kx * kz], [ky * kx, ky * ky, ky * kz], [kz * kx, kz * ky, kz * kz]]
    return [[c * (i == j) + s * k[i][j] + (1 - c) * kk[i][j] for j in range(3)] for i in range(3)]


def matmul3(a, b):
    return [[sum(a[i][m] * b[m][j] for m in range(3)) for j in range(3)] for i in range(3)]


def naive_model(turns, offset, sc, t):
    """T Rz Ry Rx S at time t, built from Rodrigues matrices (4x4 nested lists)."""
    ax, ay, az = (2 * math.pi * t * k for k in turns)
    r = matmul3(rodrigues((0, 0, 1), az), matmul3(rodrigues((0, 1, 0), ay), rodrigues((1, 0, 0), ax)))
    return [[r[i][0] * sc, r[i][1] * sc, r[i][2] * sc, offset[i]] for i in range(3)] + [[0, 0, 0, 1]]


# ---- rotations -------------------------------------------------------------------

ANGLES_DEG = list(range(0, 361, 15)) + [-30, 720 + 45]


@pytest.mark.parametrize("rot", list(AXES))
@pytest.mark.parametrize("deg", ANGLES_DEG)
def test_rotation_matches_rodrigues(rot, deg):
    a = math.radians(deg)
    # entries are cos/sin or 0/1; Rodrigues adds (1-c)*0 terms: <= 2 roundings of
    # values <= 1: 2 * EPS
    assert_allclose(rot(a)[:3, :3], rodrigues(AXES[rot], a), rtol=0, atol=2 * EPS)
    assert_array_equal(rot(a)[3], [0, 0, 0, 1])
    assert_array_equal(rot(a)[:3, 3], [0, 0, 0])


@pytest.mark.parametrize("rot", list(AXES))
@pytest.mark.parametrize("deg", range(0, 360, 10))
def test_rotation_invariance_over_360_degrees(rot, deg):
    """Rotations are isometries at every angle: norms of the cube corners are kept."""
    r = rot(math.radians(deg))
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float)
    out = apply(r, corners)
    # |p| = sqrt(3) ~ 1.7; each output component has 2 products + 1 sum: 3 roundings
    # of values <= 1.7, so |out| differs by <= ~6 EPS * 1.7 ~ 2.3e-15
    assert_allclose(np.linalg.norm(out, axis=1), math.sqrt(3.0), rtol=0, atol=6 * EPS * 2)
    assert_allclose(r[:3, :3] @ r[:3, :3].T, np.eye(3), rtol=0, atol=4 * EPS)
    assert_allclose(np.linalg.det(r[:3, :3]), 1.0, rtol=0, atol=8 * EPS)  # proper rotation, not a mirror


def test_translate_and_scale():
    p = np.array([[1.0, -2.0, 3.0]])
    assert_array_equal(apply(translate((10.0, 20.0, 30.0)), p), [[11.0, 18.0, 33.0]])
    assert_array_equal(apply(scale(2.5), p), [[2.5, -5.0, 7.5]])


def test_compose_of_nothing_is_identity_and_order_is_left_to_right_product():
    assert_array_equal(compose(), np.eye(4))
    a, b, c = rotate_x(0.3), translate((1.0, 2.0, 3.0)), scale(2.0)
    assert_array_equal(compose(a, b, c), (np.eye(4) @ a) @ b @ c)
    assert not np.allclose(compose(a, b), compose(b, a))


def test_compose_translate_rotate_hand_computed():
    # p = (1,0,0). compose(T(0,0,5), Ry(90)): Ry first: +X -> -Z: (0,0,-1), then T: (0,0,4)
    # compose(Ry(90), T(0,0,5)): T first: (1,0,5), then Ry: x' = c x + s z = 5,
    # z' = -s x + c z = -1: (5,0,-1).
    p = [[1.0, 0.0, 0.0]]
    t, r = translate((0.0, 0.0, 5.0)), rotate_y(math.pi / 2)
    # cos(pi/2) = 6e-17 times coordinates <= 5, plus rounding of values <= 5: 4 EPS * 5
    assert_allclose(apply(compose(t, r), p)[0], [0.0, 0.0, 4.0], rtol=0, atol=4 * EPS * 5)
    assert_allclose(apply(compose(r, t), p)[0], [5.0, 0.0, -1.0], rtol=0, atol=4 * EPS * 5)


# ---- Motion ----------------------------------------------------------------------


def test_frame_one_is_rest_pose_identity():
    m = Motion()
    assert_array_equal(m.frame_matrix(1, 180), np.eye(4))  # bitwise: angles are exactly 0
    assert_array_equal(m.model_matrix(0.0), np.eye(4))


@pytest.mark.parametrize("k", [1, 2, 45, 90, 91, 179, 180])
def test_frame_k_of_n_uses_t_equals_k_minus_1_over_n(k):
    m = Motion(turns=(1.0, 2.0, 0.5), offset=(1.0, 0.0, -2.0), scale=1.5)
    # frame_matrix reduces the phase exactly ((k-1)*turns mod n, then / n) where
    # model_matrix rounds t = (k-1)/n first: phases differ by at most 1 ulp of a
    # value < 1 (eps), angles by 2*pi*eps, so entries (rotation x scale 1.5) by
    # <= 2*pi*eps*1.5 per factor; 3 rotation factors: bound 3 * 2*pi*1.5 * eps.
    bound = 3 * 2 * np.pi * 1.5 * np.finfo(float).eps
    np.testing.assert_allclose(m.frame_matrix(k, 180), m.model_matrix((k - 1) / 180), rtol=0, atol=bound)


@pytest.mark.parametrize("k", [1, 2, 3, 999, 123_457, 998_001])
def test_frame_and_frame_one_period_later_are_bit_identical_over_a_million_frames(k):
    # 1000, 3000 and 500 turns over 1,000,000 frames: every axis repeats after
    # 2000 frames (2000 * 500 = 1e6). The phase is exact integer arithmetic in
    # float64 ((k-1)*turns < 2^53, fmod exact), so the matrices must match to the
    # bit, with no accumulation; half a period later (z at half a turn) they must not.
    m = Motion(turns=(1000.0, 3000.0, 500.0))
    assert_array_equal(m.frame_matrix(k, 1_000_000), m.frame_matrix(k + 2000, 1_000_000))
    assert not np.array_equal(m.frame_matrix(k, 1_000_000), m.frame_matrix(k + 1000, 1_000_000))


@pytest.mark.parametrize(
    "turns,frames,k",
    [((2, 2, 0), 180, 91), ((3, 0, 0), 3, 2), ((6, 3, 0), 180, 61), ((1, 1, 0), 2, 2), ((4, 0, 2), 8, 3)],
)
def test_whole_turns_return_bitwise_to_frame_one(turns, frames, k):
    # turns=(2,2,0), frames=180, frame 91: t = 90/180 = 0.5, 2*0.5 = 1 whole turn on
    # each axis; (3,0,0), 3, frame 2: t = 1/3, 3t = 1.0 in float64; (6,3,0), 180, frame
    # 61: t = 1/3: 2 and 1 turns. Not whole (must differ): (1,1,0), 2, frame 2: half a
    # turn; (4,0,2), 8, frame 3: t = 1/4, 4t = 1 but 2t = 1/2 on z.
    m = Motion(turns=turns, offset=(0.5, -1.0, 2.0), scale=2.0)
    t = (k - 1) / frames
    whole = all(float(t * n).is_integer() for n in turns)
    if whole:
        assert_array_equal(m.frame_matrix(k, frames), m.frame_matrix(1, frames))
    else:
        assert not np.array_equal(m.frame_matrix(k, frames), m.frame_matrix(1, frames))


def test_whole_turn_example_is_whole():
    # guard for the parametrization above: the seed's case really is a whole turn
    m = Motion(turns=(2.0, 2.0, 0.0))
    assert_array_equal(m.frame_matrix(91, 180), np.eye(4))


@pytest.mark.parametrize("t", [0.0, 0.1, 0.25, 0.37, 0.5, 0.9, 0.999])
def test_model_matrix_matches_naive_T_Rz_Ry_Rx_S(t):
    turns, offset, sc = (1.0, 2.0, 3.0), (1.0, -2.0, 0.5), 1.5
    got = Motion(turns=turns, offset=offset, scale=sc).model_matrix(t)
    # core reduces whole turns first ((t*k) % 1), Rodrigues uses 2 pi t k directly:
    # angles agree to ~ EPS * 2 pi * 3 turns ~ 4e-15 rad, the 3-matrix product adds
    # ~ 6 roundings of entries <= 1.5: total < 4e-15 * 1.5 + 6 * EPS * 1.5 ~ 8e-15
    assert_allclose(got, naive_model(turns, offset, sc, t), rtol=0, atol=1e-14)


def test_model_matrix_is_computed_not_accumulated():
    # Frame k of a very long run equals the directly computed matrix; accumulating
    # 10^5 small rotations would drift ~ sqrt(1e5) * EPS ~ 7e-14, far above the
    # single-computation error bound used here (see previous test: 1e-14 at 3 turns;
    # with 1 turn the angle error is 2 pi * EPS ~ 1.4e-15).
    n = 100_000
    m = Motion(turns=(1.0, 1.0, 0.0))
    for k in (2, 12_345, 99_999, 100_000):
        t = (k - 1) / n
        assert_allclose(m.frame_matrix(k, n), naive_model((1.0, 1.0, 0.0), (0, 0, 0), 1.0, t), rtol=0, atol=1e-14)


def test_model_matrix_order_hand_computed():
    """T @ Rz @ Ry @ Rx @ S: scale, then X, then Y, then Z, then translate."""
    # turns (1,1,0) at t = 1/4: ax = ay = 90 deg. p = (0,1,0):
    # S(2): (0,2,0); Rx(90): +Y -> +Z: (0,0,2); Ry(90): +Z -> +X: (2,0,0); T: (2,0,5).
    # (Rx after Ry would give (0,0,2)+T = (0,0,7); T before S would give (0,2,10)->...)
    m = Motion(turns=(1.0, 1.0, 0.0), offset=(0.0, 0.0, 5.0), scale=2.0)
    # cos(pi/2) = 6e-17 times values <= 2, added to 5: rounding of 5 is 4.4e-16
    assert_allclose(apply(m.model_matrix(0.25), [[0.0, 1.0, 0.0]])[0], [2.0, 0.0, 5.0], rtol=0, atol=4 * EPS * 5)
    # turns (0,1,1) at t = 1/4: p = (0,0,1): Ry(90): (1,0,0); then Rz(90): (0,1,0).
    # (Rz first would give Ry(Rz p) = Ry (0,0,1) = (1,0,0).)
    m = Motion(turns=(0.0, 1.0, 1.0))
    assert_allclose(apply(m.model_matrix(0.25), [[0.0, 0.0, 1.0]])[0], [0.0, 1.0, 0.0], rtol=0, atol=4 * EPS)
