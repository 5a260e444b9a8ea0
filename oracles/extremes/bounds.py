"""Error bounds of the extremes suite, derived from each dtype's eps and the case's scale.

Notation: ``u = eps / 2`` is the unit roundoff of the run's dtype (eps = 2.2e-16
for float64, 1.2e-7 for float32) and ``eps64`` float64's eps. Each bound's
derivation is the Notes section of its function's docstring; the suite's
report prints them (``derivation``).
"""

from __future__ import annotations

import inspect
import math

import numpy as np

from .reference import LD, norm_ld, reference_basis

EPS64 = float(np.finfo(np.float64).eps)
EPS32 = float(np.finfo(np.float32).eps)
EPS = {"float64": EPS64, "float32": EPS32}

#: Safety factor over the rounding count of ``pixel_bound`` (its Notes).
SAFETY = 2.0


def derivation(func) -> str:
    """The Notes section of ``func``'s docstring, paragraphs joined into one line each, blank-line separated."""
    doc = inspect.getdoc(func) or ""
    _, sep, notes = doc.partition("Notes\n-----\n")
    if not sep:
        return ""
    paragraphs = notes.strip().split("\n\n")
    return "\n\n".join(" ".join(line.strip() for line in p.splitlines()) for p in paragraphs)


def localize_origin(p_model) -> np.ndarray:
    """``(3,)`` the re-centring origin documented in core.projector.projection.localize (recomputed here)."""
    p = np.asarray(p_model, np.float64).reshape(-1, 3)
    fin = np.isfinite(p).all(axis=1)
    if not fin.any():
        return np.zeros(3)
    lo, hi = p[fin].min(axis=0), p[fin].max(axis=0)
    centre, half = 0.5 * lo + 0.5 * hi, 0.5 * hi - 0.5 * lo
    return centre if np.abs(centre).max() > half.max() else np.zeros(3)


def camera_error(
    dtype: str, p_model, model_matrix, camera, model_err: float = 0.0, path: str = "model_view"
) -> np.ndarray:
    """``(N, 3)`` bounds ``e_cam`` on the absolute error of core's camera x, y, z.

    Parameters
    ----------
    dtype : {"float64", "float32"}
    p_model : (N, 3) array_like
    model_matrix : (4, 4) array_like or None (identity)
    camera : core.camera.Camera
    model_err : float
        Bound per entry on the model matrix's error against the exact one
        (``motion_matrix_error`` for a Motion's matrix).
    path : {"model_view", "world"}
        ``"model_view"``: core's path (render_frame, and project_points with
        A = I). ``"world"``: a projector that casts ``p_world - position`` whole
        before rotating.

    Notes
    -----
    core computes ``p_cam = R_mv p_local + t_mv`` with ``R_mv = R A`` and
    ``t_mv = R (A o + t - position)`` formed in float64 and then cast
    (core/projector/projection.py). Each camera coordinate i is a 3-term dot product plus
    the translation's component i: with the casts of ``p_local``, ``R_mv`` and
    ``t_mv`` that is at most ~6 roundings of ``u``, i.e.
    ``e_i = 3 eps (|A| |p_local| + |t_mv_i|)``. The "world" path casts the
    relative vector whole, so every component carries
    ``3 eps (|A| |p_local| + |t_mv|)``.

    The float64 model-view subtracts magnitudes ``F = |A| |o| + |t| + |position|``
    (where 1e8 - 1e8 happens, once, in float64): ``3 eps64 F``. core's camera
    basis (cross products, normalisations) differs from the reference's by a
    few eps64, rotating the relative vector: ``2 eps64 (|A| |p_local| + |t_mv|)``.
    A model matrix that core computes from angles and the reference from the
    exact phase adds ``2 model_err |p_local|``. The sum bounds each of x, y, z.
    """
    if path not in ("model_view", "world"):
        raise ValueError(f"path {path!r}: expected 'model_view' or 'world'")
    eps = EPS[dtype]
    p = np.asarray(p_model, np.float64).reshape(-1, 3)
    m = np.eye(4) if model_matrix is None else np.asarray(model_matrix, np.float64)
    a, t = m[:3, :3], m[:3, 3]
    origin = localize_origin(p)
    s_local = np.linalg.norm(p - origin, axis=1)
    n_a = float(np.linalg.norm(a, 2))
    t_world_rel = a @ origin + t - np.asarray(camera.position, np.float64)
    t_mv = np.abs(reference_basis(camera).astype(np.float64) @ t_world_rel)  # |t_mv_i|
    t_norm = float(np.linalg.norm(t_world_rel))
    far = n_a * float(np.linalg.norm(origin)) + float(np.linalg.norm(t)) + float(np.linalg.norm(camera.position))
    rel = n_a * s_local + t_norm
    if path == "model_view":
        per = 3 * eps * (n_a * s_local[:, None] + t_mv[None, :])
    else:
        per = np.repeat((3 * eps * rel)[:, None], 3, axis=1)
    common = 2 * EPS64 * rel + 3 * EPS64 * far + 2 * model_err * s_local
    return per + common[:, None]


def opencv_camera_error(p_world, camera) -> np.ndarray:
    """``(N, 3)`` bounds on the camera-space error of float64 ``cv2.projectPoints``.

    Notes
    -----
    OpenCV forms ``R' X + t`` with ``R' = Rodrigues(rvec)`` (a few eps off the
    exact basis) and ``t = -R position``: ``e_cv = 8 eps64 (|X| + |position|)`` in
    every component. It is not camera-relative: its error grows with the
    distance from the origin and core's does not. It also checks the reference:
    a wrong reference would disagree with OpenCV everywhere.
    """
    p = np.asarray(p_world, np.float64).reshape(-1, 3)
    e = 8 * EPS64 * (np.linalg.norm(p, axis=1) + float(np.linalg.norm(camera.position)))
    return np.repeat(e[:, None], 3, axis=1)


def focal_condition(camera) -> float:
    """``kappa_f``: the float64 rounding of the focal length, magnified by tan's conditioning.

    Notes
    -----
    ``f = (H/2) / tan(fov/2)`` in float64: the degree-to-radian conversion and
    tan round ~3 u, magnified by the condition number of ``tan(a / 2)`` in
    ``a``, which is ``a / sin(a)`` (1 at small fov, 1800 at 179.9 deg):
    ``kappa_f = 2 a / sin(a) + 2`` (2 for orthographic) times ``eps64 f r / z``.
    """
    if camera.projection != "perspective":
        return 2.0
    a = math.radians(camera.fov_y_deg)
    return 2.0 * a / math.sin(a) + 2.0


def components(e_cam, n) -> np.ndarray:
    """``(n, 3)`` per-component errors from ``(n, 3)`` or an isotropic ``(n,)`` / scalar."""
    e = np.asarray(e_cam, np.float64)
    return np.repeat(e.reshape(-1, 1), 3, axis=1) if e.ndim <= 1 else e.reshape(n, 3)


def pixel_bound(p_cam, p_px, camera, e_cam, eps: float) -> np.ndarray:
    """``(N,)`` pixel error bound from camera-space errors ``e_cam``.

    Parameters
    ----------
    p_cam : (N, 3) array_like
        The reference's camera points (float64 is plenty for a bound).
    p_px : (N, 2) array_like
        The reference's pixels.
    camera : core.camera.Camera
    e_cam : (N, 3) or (N,) array_like
        Camera-space error bounds (``camera_error``), or isotropic.
    eps : float
        The dtype's eps.

    Notes
    -----
    Perspective: ``x_px = cx + f x / z``: errors ``e_x, e_z`` move it by
    ``f (e_x + |x| e_z / z) / z``; y likewise, and the 2-D error is at most
    ``f (e_x + e_y + r e_z / z) / z`` with ``r = |x| + |y|``. The divide and the
    two products round ~3 times relative to ``f r / z`` (``2 eps f r / z``, with
    the float32 cast of f), the final ``cx +`` once relative to
    ``|x_px| + |y_px|``; the focal length adds ``kappa_f eps64 f r / z``
    (``focal_condition``). Orthographic: ``s = H / ortho_height`` replaces
    ``f / z`` and there is no divide.

    The sum counts every rounding once at its worst; the bound is ``SAFETY = 2``
    times it (the reference's own rounding, ~1e-19 relative, is absorbed in
    that factor). Every measured error / bound is reported (``max_ratio``): it
    must be <= 1; values ~1e-2..0.3 show the bound is not loose by orders of
    magnitude.
    """
    p_cam = np.asarray(p_cam, np.float64).reshape(-1, 3)
    p_px = np.asarray(p_px, np.float64).reshape(-1, 2)
    e = components(e_cam, len(p_cam))
    x, y, z = np.abs(p_cam[:, 0]), np.abs(p_cam[:, 1]), p_cam[:, 2]
    r = x + y
    px_abs = np.abs(p_px).sum(axis=1)
    kf = focal_condition(camera)
    with np.errstate(all="ignore"):  # z = 0 rows (clipped points) give inf: never compared
        if camera.projection == "perspective":
            f = camera.focal_px
            b = (
                f * (e[:, 0] + e[:, 1] + r * e[:, 2] / z) / z
                + 2 * eps * f * r / z
                + eps * px_abs
                + kf * EPS64 * f * r / z
            )
        else:
            s = camera.height / camera.ortho_height
            b = s * (e[:, 0] + e[:, 1]) + 2 * eps * s * r + eps * px_abs + kf * EPS64 * s * r
    return SAFETY * b


def near_band(ref_cam, camera, e_cam, eps) -> np.ndarray:
    """``(N,) bool``: the exact depth is within ``e_z + eps |plane|`` of near or far.

    Notes
    -----
    A computed depth is within ``e_z`` (``camera_error``) of the exact one
    and near/far are rounded to the dtype (``eps |plane|``, 5.2e-8 at near = 0.1
    in float32): a point inside this band may land on either side of the plane;
    anywhere else core's visibility must equal the reference's.
    """
    z = np.asarray(ref_cam, LD)[:, 2]
    e_z = components(e_cam, len(z))[:, 2]
    out = np.zeros(len(z), bool)
    for plane in (camera.near, camera.far):
        out |= np.abs(z - LD(plane)).astype(np.float64) <= e_z + eps * abs(plane)
    return out


def clipped_end_bounds(p0_cam, p1_cam, q_cam, q_px, e_end, camera, eps: float):
    """Bounds on the end that near-plane clipping puts on an edge: ``(z_bound, px_bound, kappa)``, each ``(E,)``.

    Parameters
    ----------
    p0_cam, p1_cam : (E, 3) long-double arrays
        The reference's edge ends in camera space.
    q_cam : (E, 3) long-double array
        The exact intersection with ``z = near``.
    q_px : (E, 2) long-double array
        Its pixels.
    e_end : (E,) array
        The larger camera-space error (``camera_error``) of the two ends.
    camera : core.camera.Camera
    eps : float
        The dtype's eps.

    Notes
    -----
    ``|z_end - near| <= 8 eps (|z0| + |z1| + near) + e_cam``: the crossing
    ``t = d0 / (d0 - d1)`` is computed from the computed depths (2 roundings),
    ``z0 + t (z1 - z0)`` adds 3; a depth error e_cam may leave the end unclipped.

    Along the edge the crossing is ill-conditioned: a depth error e_cam moves it
    by ``kappa e_cam``, ``kappa = |p1 - p0| / |z1 - z0|`` (1/slope), at most the
    whole edge: lateral error ``<= min(|p1 - p0|, 2 kappa e_cam) + e_cam``, in
    pixels times ``f / near (2 + r / near)``, plus the rounding terms of
    ``pixel_bound``.
    """
    near, f = camera.near, camera.focal_px
    z0, z1 = np.abs(p0_cam[:, 2]).astype(float), np.abs(p1_cam[:, 2]).astype(float)
    z_bound = 8 * eps * (z0 + z1 + near) + e_end
    seg_len = norm_ld(p1_cam - p0_cam).astype(float)
    kappa = seg_len / np.abs(p1_cam[:, 2] - p0_cam[:, 2]).astype(float)
    lateral = (
        np.minimum(seg_len, 2 * kappa * e_end)
        + e_end
        + 8 * eps * (norm_ld(p0_cam).astype(float) + norm_ld(p1_cam).astype(float))
    )
    qc = q_cam.astype(np.float64)
    r = np.abs(qc[:, 0]) + np.abs(qc[:, 1])
    px_bound = SAFETY * (
        f / near * lateral * (2 + r / near)
        + 2 * eps * f * r / near
        + eps * np.abs(q_px.astype(float)).sum(axis=1)
        + focal_condition(camera) * EPS64 * f * r / near
    )
    return z_bound, px_bound, kappa


def motion_matrix_error() -> float:
    """Bound per entry on a Motion model matrix against the long-double rotation of the exact phase.

    Notes
    -----
    16 eps64 per entry: the angle ``2 pi p`` rounds twice, cos and sin are
    within 1 ulp each, and the two 3x3 products add 3u each, summed over the 3
    factors. The phase ``((k - 1) turns mod n) / n`` itself is exact in float64,
    so frames one period apart are bit-identical (no tolerance).
    """
    return 16 * EPS64


def orthonormality_error() -> float:
    """Bound per entry on ``R^T R - I`` of a Motion rotation.

    Notes
    -----
    16 eps64 per entry: 3 factors with ``|c^2 + s^2 - 1| <= 2 eps`` each, two
    products adding 1.5 eps per entry each, the check's own product 1.5 eps.
    """
    return 16 * EPS64


#: The bound functions whose derivations the report prints, in this order.
DERIVED = (
    camera_error,
    pixel_bound,
    focal_condition,
    opencv_camera_error,
    near_band,
    clipped_end_bounds,
    motion_matrix_error,
    orthonormality_error,
)
