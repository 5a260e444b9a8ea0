"""The extremes suite: core at the edges of its input space, against derived error bounds.

Each case runs core (``core.pipeline.render_frame`` / ``core.projection``) in
float64 and float32 and compares it with

- an **extended-precision reference** computed here in ``np.longdouble``
  (80-bit x87 on x86-64: 64-bit mantissa, eps 1.1e-19) straight from
  ``core.conventions`` -- its own camera basis, focal length, model-view and
  divide, none of core's functions;
- **OpenCV** (``oracles.opencv_oracle.project``, float64 ``cv2.projectPoints``),
  whose own error against the reference is reported too. OpenCV is not
  camera-relative (it forms ``R X + t`` with ``|X|`` the world position), so far
  from the origin it is the *less* accurate of the two: its error is
  information, checked only against its own derived bound (which also checks
  the reference: a wrong reference would disagree with OpenCV everywhere);
- **pyrender/OSMesa** (optional): the F1 of the drawn frame.

Error bounds (:func:`camera_error`, :func:`pixel_bound`)
======================================================
Let ``u = eps / 2`` be the unit roundoff of the run's dtype (eps = 2.2e-16 for
float64, 1.2e-7 for float32) and ``eps64`` float64's eps.

*Camera space.* core computes ``p_cam = R_mv p_local + t_mv`` with ``R_mv = R A``
and ``t_mv = R (A o + t - position)`` formed in float64 and then cast
(core/projection.py). Each camera coordinate i is a 3-term dot product plus
the translation's component i: with the casts of ``p_local``, ``R_mv`` and
``t_mv`` that is at most ~6 roundings of ``u``, i.e.
``e_i = 3 eps (|A| |p_local| + |t_mv_i|)``. (``project_points`` takes the same
path with A = I: world points are re-centred by ``localize`` and the origin's
``R (o - position)`` is formed in float64. ``camera_error(path="world")`` is
the looser bound of a projector that casts the whole ``p_world - position``
before rotating: every component then carries ``3 eps (|A| |p_local| + |t_mv|)``.)
The float64 model-view subtracts magnitudes ``F = |A| |o| + |t| + |position|``
(the far-from-origin term: this is where 1e8 - 1e8 happens, once, in
float64): ``3 eps64 F``. core's camera basis (cross products, normalisations)
differs from the reference's by a few eps64, rotating the relative vector:
``2 eps64 (|A| |p_local| + |t_mv|)``. A model matrix that core computes from
angles (Motion) and the reference from the exact phase adds
``2 model_err |p_local|``. Sum: ``e_cam = (e_x, e_y, e_z)``, bounds on the
absolute errors of core's x, y, z.

*Pixels (perspective).* ``x_px = cx + f x / z``: errors ``e_x, e_z`` move it by
``f (e_x + |x| e_z / z) / z``; y likewise, and the 2-D error is at most the sum
``f (e_x + e_y + r e_z / z) / z`` with ``r = |x| + |y|``. The divide and
the two products round ~3 times relative to ``f r / z`` (``2 eps f r / z``, with the
float32 cast of f), the final ``cx +`` once relative to ``|x_px| + |y_px|``. The
focal length itself is ``(H/2) / tan(fov/2)`` in float64: the degree-to-radian
conversion and tan round ~3 u, magnified by the condition number of
``tan(a / 2)`` in ``a``, which is ``a / sin(a)`` (1 at small fov, 1800 at
179.9 deg): ``kappa_f = 2 a / sin(a) + 2`` times ``eps64 f r / z``.
Orthographic: ``s = H / ortho_height`` replaces ``f / z`` and there is no divide.
For a camera-relative point (``|p_rel| ~ z``) this is the familiar
``c eps f (|p_rel| / z) (1 + |x| / z)``.

*Safety constant.* The sum above counts every rounding once at its worst; the
bound is ``C = 2`` times it (the reference's own rounding is ~1e-19 relative and
is absorbed in that factor). Every measured ratio error / bound is reported
(``max_ratio``): it must be <= 1; values ~1e-2..0.3 show the bound is not loose
by orders of magnitude.

*OpenCV* forms ``R' X + t`` with ``R' = Rodrigues(rvec)`` (a few eps off the
exact basis) and ``t = -R position``: ``e_cv = 8 eps64 (|X| + |position|)`` in
every component of the same pixel formula: this is why OpenCV's error grows
with the distance from the origin and core's does not.

*Visibility.* A computed depth is within ``e_z`` of the exact one and near/far
are rounded to the dtype (``u |plane|``): a point whose exact depth is within
``e_z + eps |plane|`` of near or far may land on either side (``_near_band``);
anywhere else core's visibility must equal the reference's.

API
===
``EXTREME_CASES`` (names), ``run_case(name, pyrender=True) -> dict``,
``run_extremes(pyrender=True) -> dict`` and ``extremes_markdown(result) -> str``.
Results are JSON-able and deterministic except the ``"timing"`` key.
"""

from __future__ import annotations

import math
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from wirecheck.core import clipping
from wirecheck.core.camera import look_at
from wirecheck.core.errors import InputError
from wirecheck.core.pipeline import render_frame
from wirecheck.core.projection import cam_to_px, localize, model_to_cam, project_points
from wirecheck.core.transforms import Motion, compose, rotate_x, rotate_y, rotate_z, translate

from . import metrics, opencv_oracle

__all__ = ["EXTREME_CASES", "CASE_DESCRIPTIONS", "run_case", "run_extremes", "extremes_markdown",
           "reference_project", "reference_basis", "reference_focal", "camera_error", "pixel_bound",
           "opencv_camera_error", "SAFETY"]

LD = np.longdouble
EPS64 = float(np.finfo(np.float64).eps)
EPS32 = float(np.finfo(np.float32).eps)
EPS = {"float64": EPS64, "float32": EPS32}
DTYPES = ("float64", "float32")
PI_LD = 4 * np.arctan(LD(1))            # atanl: pi to 64 bits (np.pi is only 53)
#: eps of the reference's long double: 1.1e-19 for x87 80-bit (x86-64 Linux), 1.9e-34 for
#: IEEE quad (aarch64 Linux), 2.2e-16 where long double is just double (MSVC, macOS arm64):
#: there the reference is no better than core's float64 and the float64 bounds are not meaningful.
REFERENCE_EPS = float(np.finfo(LD).eps)
REFERENCE_EXTENDED = REFERENCE_EPS < 1e-18

#: Safety factor over the rounding count of :func:`pixel_bound` (module docstring).
SAFETY = 2.0

#: pyrender F1@1px required where a case's frame is well conditioned for a
#: float32 GL pipeline (crosscheck's own MIN_F1_1PX is 0.999 over ~1,500 ordinary
#: frames; these frames have few, extreme lines, where one stray end pixel weighs more).
MIN_F1_1PX = 0.99

REPO_ROOT = Path(__file__).resolve().parent.parent


# ---------------------------------------------------------------------------
# The extended-precision reference: core.conventions, in long double.
# ---------------------------------------------------------------------------

def _norm_ld(v):
    return np.sqrt((v * v).sum(axis=-1))


def _cross_ld(a, b):
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]], dtype=LD)


def reference_basis(camera) -> np.ndarray:
    """Rows ``right, up, forward`` in long double from the camera's forward and up.

    conventions: ``right = forward x up`` (normalised), ``up = right x forward``.
    """
    f = np.asarray(camera.forward, dtype=LD)
    f = f / _norm_ld(f)
    r = _cross_ld(f, np.asarray(camera.up, dtype=LD))
    r = r / _norm_ld(r)
    u = _cross_ld(r, f)
    return np.stack([r, u / _norm_ld(u), f])


def reference_focal(camera) -> LD:
    """``f_px = (H / 2) / tan(fov_y / 2)`` in long double (fov in degrees as given)."""
    return (LD(camera.height) / 2) / np.tan(LD(camera.fov_y_deg) * PI_LD / 360)


def reference_world(p_model, a_ld, t_ld) -> np.ndarray:
    """``A p + t`` in long double (only to hand OpenCV world points)."""
    return np.asarray(p_model, dtype=LD).reshape(-1, 3) @ np.asarray(a_ld, LD).T + np.asarray(t_ld, LD)


def reference_project(p_model, camera, model_matrix=None, *, a_ld=None, t_ld=None):
    """Long-double reference: ``(p_cam, p_px, visible)``, p_px NaN where clipped.

    ``p_cam = R (A p + (t - position))``: the same sum as ``R (A p + t - position)``
    with ``t - position`` taken first, which for float64 inputs of equal
    magnitude is exact in a 64-bit mantissa (so the reference stays accurate at
    1e8 from the origin). ``A, t`` are the float64 model matrix's, taken as
    exact, or ``a_ld, t_ld`` computed by the caller in long double.
    """
    p = np.asarray(p_model, dtype=np.float64).reshape(-1, 3).astype(LD)
    m = np.eye(4) if model_matrix is None else np.asarray(model_matrix, np.float64)
    a = np.asarray(m[:3, :3] if a_ld is None else a_ld, dtype=LD)
    t = np.asarray(m[:3, 3] if t_ld is None else t_ld, dtype=LD)
    rel = p @ a.T + (t - np.asarray(camera.position, dtype=LD))        # p_world - position
    p_cam = rel @ reference_basis(camera).T
    z = p_cam[:, 2]
    visible = (z >= LD(camera.near)) & (z <= LD(camera.far))
    px = np.full((len(p), 2), np.nan, dtype=LD)
    cx, cy = (LD(camera.width) - 1) / 2, (LD(camera.height) - 1) / 2
    if camera.projection == "perspective":
        f = reference_focal(camera)
        zv = z[visible]
        px[visible, 0] = cx + f * p_cam[visible, 0] / zv
        px[visible, 1] = cy - f * p_cam[visible, 1] / zv
    else:
        s = LD(camera.height) / LD(camera.ortho_height)
        px[visible, 0] = cx + s * p_cam[visible, 0]
        px[visible, 1] = cy - s * p_cam[visible, 1]
    return p_cam, px, np.asarray(visible, bool)


def reference_motion_matrix(turns, offset, scale, frame: int, frames: int) -> tuple[np.ndarray, np.ndarray]:
    """``(A, t)`` in long double of Motion frame ``frame`` of ``frames`` (integer turns).

    conventions: ``T Rz Ry Rx S`` with angle_i = 2 pi phase_i and phase_i the
    exact rational ``((frame - 1) turns_i mod frames) / frames`` (Python integers).
    """
    angles = [2 * PI_LD * LD((frame - 1) * int(k) % frames) / LD(frames) for k in turns]
    (cx_, sx), (cy_, sy), (cz, sz) = ((np.cos(a), np.sin(a)) for a in angles)
    rx = np.array([[1, 0, 0], [0, cx_, -sx], [0, sx, cx_]], dtype=LD)
    ry = np.array([[cy_, 0, sy], [0, 1, 0], [-sy, 0, cy_]], dtype=LD)
    rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]], dtype=LD)
    return rz @ ry @ rx * LD(scale), np.asarray(offset, dtype=LD)


# ---------------------------------------------------------------------------
# Derived bounds (module docstring)
# ---------------------------------------------------------------------------

def localize_origin(p_model) -> np.ndarray:
    """The re-centring origin documented in core.projection.localize (recomputed here)."""
    p = np.asarray(p_model, np.float64).reshape(-1, 3)
    fin = np.isfinite(p).all(axis=1)
    if not fin.any():
        return np.zeros(3)
    lo, hi = p[fin].min(axis=0), p[fin].max(axis=0)
    centre, half = 0.5 * lo + 0.5 * hi, 0.5 * hi - 0.5 * lo
    return centre if np.abs(centre).max() > half.max() else np.zeros(3)


def camera_error(dtype: str, p_model, model_matrix, camera, model_err: float = 0.0,
                 path: str = "model_view") -> np.ndarray:
    """``(N, 3)`` bounds ``e_cam`` on the absolute error of core's camera x, y, z (module docstring).

    ``path="model_view"`` (render_frame): the translation ``t_mv`` is cast to the
    dtype per component, so component i rounds relative to ``|t_mv_i|``:
    ``3 eps (|A| |p_local| + |t_mv_i|)``; project_points takes this path too. ``path="world"``
    (a projector that casts the relative vector whole):
    ``p_world - position`` is cast whole and then rotated in the dtype, so every
    component carries ``3 eps (|A| |p_local| + |t_mv|)``. Both add
    ``2 eps64 (|A| |p_local| + |t_mv|) + 3 eps64 F + 2 model_err |p_local|``.
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
    t_mv = np.abs(reference_basis(camera).astype(np.float64) @ t_world_rel)     # |t_mv_i|
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
    """``(N, 3)``: ``e_cv = 8 eps64 (|X| + |position|)`` per component (OpenCV is not camera-relative)."""
    p = np.asarray(p_world, np.float64).reshape(-1, 3)
    e = 8 * EPS64 * (np.linalg.norm(p, axis=1) + float(np.linalg.norm(camera.position)))
    return np.repeat(e[:, None], 3, axis=1)


def focal_condition(camera) -> float:
    """``kappa_f = 2 a / sin(a) + 2``: float64 rounding of f, magnified by tan's conditioning."""
    if camera.projection != "perspective":
        return 2.0
    a = math.radians(camera.fov_y_deg)
    return 2.0 * a / math.sin(a) + 2.0


def _components(e_cam, n) -> np.ndarray:
    e = np.asarray(e_cam, np.float64)
    return np.repeat(e.reshape(-1, 1), 3, axis=1) if e.ndim <= 1 else e.reshape(n, 3)


def pixel_bound(p_cam, p_px, camera, e_cam, eps: float) -> np.ndarray:
    """``(N,)`` pixel error bound from camera-space errors ``e_cam`` ((N, 3) or (N,) isotropic).

    Perspective: ``2 [f (e_x + e_y + r e_z / z) / z + 2 eps f r / z + eps (|x_px| + |y_px|)
    + kappa_f eps64 f r / z]``; orthographic: ``2 [s (e_x + e_y) + 2 eps s r + eps (|x_px| +
    |y_px|) + kappa_f eps64 s r]``. ``p_cam``, ``p_px``: the reference's (float64 is
    plenty for a bound).
    """
    p_cam = np.asarray(p_cam, np.float64).reshape(-1, 3)
    p_px = np.asarray(p_px, np.float64).reshape(-1, 2)
    e = _components(e_cam, len(p_cam))
    x, y, z = np.abs(p_cam[:, 0]), np.abs(p_cam[:, 1]), p_cam[:, 2]
    r = x + y
    px_abs = np.abs(p_px).sum(axis=1)
    kf = focal_condition(camera)
    with np.errstate(all="ignore"):      # z = 0 rows (clipped points) give inf: never compared
        if camera.projection == "perspective":
            f = camera.focal_px
            b = (f * (e[:, 0] + e[:, 1] + r * e[:, 2] / z) / z + 2 * eps * f * r / z + eps * px_abs
                 + kf * EPS64 * f * r / z)
        else:
            s = camera.height / camera.ortho_height
            b = s * (e[:, 0] + e[:, 1]) + 2 * eps * s * r + eps * px_abs + kf * EPS64 * s * r
    return SAFETY * b


# ---------------------------------------------------------------------------
# Measuring
# ---------------------------------------------------------------------------

def _f(v):
    """JSON-able float: None for NaN / None, the strings "inf" / "-inf" for infinities."""
    if v is None:
        return None
    v = float(v)
    if math.isnan(v):
        return None
    return v if math.isfinite(v) else ("inf" if v > 0 else "-inf")     # strict JSON has no inf


def _err_px(a_px, ref_px) -> np.ndarray:
    d = (np.asarray(a_px, LD) - np.asarray(ref_px, LD)).astype(np.float64)
    return np.hypot(d[:, 0], d[:, 1])


def _stats(px, visible, ref_px, ref_visible, bound, band=None) -> dict:
    """Max error and the bound at that point, max error/bound, visibility mismatches.

    ``band``: ``(N,)`` distance from the nearest of near/far within which the
    computed depth may round to the other side (a flip there is allowed).
    """
    both = visible & ref_visible
    flips = visible != ref_visible
    out = {"points": int(len(px)), "compared": int(both.sum()),
           "visible_mismatch": int(flips.sum()),
           "visible_mismatch_outside_band": int(flips.sum() if band is None else (flips & ~band).sum()),
           "max_error_px": None, "bound_px": None, "max_ratio": None}
    if both.any():
        err = _err_px(px[both], ref_px[both])
        b = bound[both]
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = np.where(err == 0, 0.0, err / b)
        ratio = np.where(np.isnan(ratio), np.inf, ratio)
        k = int(np.argmax(err))
        out.update(max_error_px=float(err[k]), bound_px=float(b[k]), max_ratio=float(ratio.max()))
    return out


def _near_band(ref_cam, camera, e_cam, eps) -> np.ndarray:
    """``(N,) bool``: the depth is within ``e_cam + eps |plane|`` of near or far.

    The computed depth is within e_cam of the exact one, and the plane itself is
    rounded to the dtype (u |plane|); outside this band the visibility is decided.
    """
    z = np.asarray(ref_cam, LD)[:, 2]
    e_z = _components(e_cam, len(z))[:, 2]
    out = np.zeros(len(z), bool)
    for plane in (camera.near, camera.far):
        out |= (np.abs(z - LD(plane)).astype(np.float64) <= e_z + eps * abs(plane))
    return out


def _within(stats: dict) -> bool:
    return stats["max_ratio"] is None or stats["max_ratio"] <= 1.0


class _Pyrender:
    """One PyrenderOracle per image size, created on demand, closed by :meth:`close`."""

    def __init__(self, enabled: bool):
        from .pyrender_oracle import OracleCache

        self.oracles = OracleCache()
        self.note = None
        self.enabled = enabled
        if not enabled:
            self.note = "pyrender disabled (run_extremes(pyrender=False))"
            return
        from .pyrender_oracle import osmesa_available
        ok, msg = osmesa_available()
        if not ok:
            self.enabled, self.note = False, f"pyrender unavailable: {msg}"

    def render(self, vertices, edges, camera, model_matrix=None) -> np.ndarray:
        mask, _ = self.oracles.get(camera.width, camera.height).render(vertices, edges, camera,
                                                                       model_matrix=model_matrix)
        return mask

    def close(self):
        self.oracles.close()


def _pyrender_scores(pr: _Pyrender, frame_mask, vertices, edges, camera, model_matrix=None):
    """``(scores dict, note)``; scores None when pyrender is not run."""
    if not pr.enabled:
        return None, pr.note
    try:
        mask = pr.render(vertices, edges, camera, model_matrix)
    except Exception as exc:  # OSMesa may refuse a size: say so
        return None, f"pyrender failed: {type(exc).__name__}: {exc}"
    s = metrics.pixel_scores(frame_mask, mask)
    return {"f1_0px": s["f1_0px"], "f1_1px": s["f1_1px"], "core_pixels": s["candidate_pixels"],
            "pyrender_pixels": s["oracle_pixels"]}, None


def _measure(p_model, model_matrix, camera, *, edges=None, model_err=0.0, a_ld=None, t_ld=None,
             frames=None) -> dict:
    """core in both dtypes and OpenCV against the long-double reference.

    Returns ``{"float64": stats, "float32": stats, "opencv": stats, "frames": {dtype: Frame},
    "ref": (p_cam, p_px, visible)}``.
    """
    p_model = np.asarray(p_model, np.float64).reshape(-1, 3)
    m = np.eye(4) if model_matrix is None else np.asarray(model_matrix, np.float64)
    edges = np.zeros((0, 2), np.intp) if edges is None else np.asarray(edges, np.intp).reshape(-1, 2)
    ref_cam, ref_px, ref_vis = reference_project(p_model, camera, m, a_ld=a_ld, t_ld=t_ld)
    out = {"ref": (ref_cam, ref_px, ref_vis), "frames": {}}
    for dt in DTYPES:
        frame = render_frame(p_model, edges, camera, m, dtype=dt) if frames is None else frames[dt]
        e_cam = camera_error(dt, p_model, m, camera, model_err)
        bound = pixel_bound(ref_cam, ref_px, camera, e_cam, EPS[dt])
        out[dt] = _stats(frame.p_px, frame.visible, ref_px, ref_vis, bound,
                         _near_band(ref_cam, camera, e_cam, EPS[dt]))
        out["frames"][dt] = frame
    # OpenCV on the world points (rounded to float64 once: part of its input error)
    a = m[:3, :3] if a_ld is None else a_ld
    t = m[:3, 3] if t_ld is None else t_ld
    p_world = reference_world(p_model, a, t).astype(np.float64)
    cv_px = opencv_oracle.project(p_world, camera)
    e_cv = opencv_camera_error(p_world, camera)
    cv_bound = pixel_bound(ref_cam, ref_px, camera, e_cv, EPS64)
    out["opencv"] = _stats(cv_px, ~np.isnan(cv_px[:, 0]), ref_px, ref_vis, cv_bound,
                           _near_band(ref_cam, camera, e_cv, EPS64))
    # core's world path (project_points, crosscheck's candidate contract) on the same world points
    for dt in DTYPES:
        pp = project_points(p_world, camera, dt)
        e_w = camera_error(dt, p_world, None, camera, model_err)     # project_points: model-view path, A = I
        out["pp_" + dt] = _stats(pp, ~np.isnan(pp[:, 0]), ref_px, ref_vis,
                                 pixel_bound(ref_cam, ref_px, camera, e_w, EPS[dt]),
                                 _near_band(ref_cam, camera, e_w, EPS[dt]))
    f64 = out["frames"]["float64"]
    both = f64.visible & ~np.isnan(cv_px[:, 0])
    out["float64"]["vs_opencv_px"] = float(_err_px(f64.p_px[both], cv_px[both]).max()) if both.any() else None
    out["p_world"] = p_world
    return out


def _merge(a: dict, b: dict) -> dict:
    """Two stats dicts of the same dtype as one (worst of both)."""
    if a is None:
        return dict(b)
    out = dict(a)
    for k in ("points", "compared", "visible_mismatch", "visible_mismatch_outside_band"):
        out[k] = a[k] + b[k]
    if b["max_error_px"] is not None and (a["max_error_px"] is None or b["max_error_px"] > a["max_error_px"]):
        out["max_error_px"], out["bound_px"] = b["max_error_px"], b["bound_px"]
    if b["max_ratio"] is not None and (a["max_ratio"] is None or b["max_ratio"] > a["max_ratio"]):
        out["max_ratio"] = b["max_ratio"]
    if "vs_opencv_px" in a or "vs_opencv_px" in b:
        vals = [v for v in (a.get("vs_opencv_px"), b.get("vs_opencv_px")) if v is not None]
        out["vs_opencv_px"] = max(vals) if vals else None
    return out


def _public(stats: dict | None) -> dict | None:
    if stats is None:
        return None
    return {k: (_f(v) if isinstance(v, (float, np.floating)) else v) for k, v in stats.items()}


class _Case:
    """Accumulates one case's result."""

    def __init__(self, name: str):
        self.name = name
        self.stats = {"float64": None, "float32": None, "opencv": None,
                      "pp_float64": None, "pp_float32": None}
        self.extra = {}
        self.reasons = []
        self.pyrender_note = None
        self.pyrender_parts = {}

    def add(self, m: dict, *, label=""):
        for k in self.stats:
            self.stats[k] = _merge(self.stats[k], m[k])
        for dt in DTYPES + tuple("pp_" + d for d in DTYPES):
            s = m[dt]
            if not _within(s):
                self.fail(f"{label}{dt.replace('pp_', 'project_points ')}: error {s['max_error_px']:.3g} px "
                          f"exceeds its bound "
                          f"(max error/bound {s['max_ratio']:.3g})")
            if s["visible_mismatch_outside_band"]:
                self.fail(f"{label}{dt.replace('pp_', 'project_points ')}: "
                          f"{s['visible_mismatch_outside_band']} points visible/clipped unlike "
                          f"the reference, farther than rounding from near/far")
        if not _within(m["opencv"]):
            self.fail(f"{label}reference and OpenCV disagree beyond OpenCV's bound "
                      f"(ratio {m['opencv']['max_ratio']:.3g}): check the reference")

    def check(self, ok: bool, reason: str):
        if not ok:
            self.fail(reason)

    def fail(self, reason: str):
        self.reasons.append(reason)

    def add_pyrender(self, label: str, scores, note, *, judged: bool):
        if scores is None:
            self.pyrender_note = note
            return
        self.pyrender_parts[label] = dict(scores, judged=judged)
        if judged and scores["f1_1px"] < MIN_F1_1PX:
            self.fail(f"pyrender {label}: F1@1px {scores['f1_1px']:.4f} < {MIN_F1_1PX}")

    def result(self) -> dict:
        pyr = None
        if self.pyrender_parts:
            parts = self.pyrender_parts
            pyr = {"f1_0px": min(p["f1_0px"] for p in parts.values()),
                   "f1_1px": min(p["f1_1px"] for p in parts.values()),
                   "frames": parts}
            judged = [p for p in parts.values() if p["judged"]]
            pyr["f1_1px_judged"] = min(p["f1_1px"] for p in judged) if judged else None
        return {
            "name": self.name,
            "description": CASE_DESCRIPTIONS[self.name],
            "bound_derivation": CASE_BOUNDS[self.name],
            "float64": _public(self.stats["float64"]),
            "float32": _public(self.stats["float32"]),
            "opencv": _public(self.stats["opencv"]),
            "project_points": {dt: _public(self.stats["pp_" + dt]) for dt in DTYPES}
            if self.stats["pp_float64"] is not None else None,
            "pyrender": pyr,
            "pyrender_note": self.pyrender_note,
            "details": _jsonable(self.extra),
            "verdict": "fail" if self.reasons else "pass",
            "reasons": list(self.reasons),
        }


def _jsonable(x):
    if isinstance(x, dict):
        return {str(k): _jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_jsonable(v) for v in x]
    if isinstance(x, (bool, np.bool_)):
        return bool(x)
    if isinstance(x, (int, np.integer)):
        return int(x)
    if isinstance(x, (float, np.floating)):
        return _f(x)
    return x


def _cube(half=0.5):
    v = np.array([[x, y, z] for x in (-half, half) for y in (-half, half) for z in (-half, half)], float)
    e = [(i, j) for i in range(8) for j in range(i + 1, 8) if bin(i ^ j).count("1") == 1]
    return v, np.array(e, np.intp)


CUBE_V, CUBE_E = _cube()


# ---------------------------------------------------------------------------
# The cases
# ---------------------------------------------------------------------------

CASE_DESCRIPTIONS = {
    "near_plane": "points exactly at z = near, near +- 1 ulp, near +- 1e-9 (absolute), at far +- 1 ulp, at "
                  "depth 0 and behind the camera: float64 visibility equals near <= z <= far exactly; "
                  "float32 flips only inside its derived band",
    "near_grazing": "edges crossing the near plane at slopes 1e-3..1e-9 (nearly parallel to it): the "
                    "clipped end lies on z = near and projects near the exact intersection",
    "fov_extremes": "fov 0.01 deg (f = 2.75e6 px) and 179.9 deg (f = 0.21 px) on a 640x480 image",
    "aspect_extremes": "4000x4 and 4x4000 images, zig-zag lines across the long side",
    "far_from_origin": "a unit cube 1e8 from the world origin seen from 4 units away, placed by the model "
                       "matrix; by vertices at 1e8 (re-centred by localize); and by vertices at 1e8 under a "
                       "model rotation about the world origin (where float64 must round A o, |A o| = 1e8)",
    "subpixel_object": "a unit cube 1e5 away: the whole cube is < 0.01 px on screen",
    "rotation_period": "Motion(turns=(1000, 3000, 500)) over 1,000,000 frames has period 2000: frame k and "
                       "k + 2000 give bit-identical model matrices, p_px and images",
    "gimbal_lock": "pitch exactly +-90 deg (Ry at 1/4 and 3/4 turn) with roll and yaw; cameras looking "
                   "straight down (-Y) and up (+Y) with up = -Z / +Z",
    "up_parallel": "up parallel (and anti-parallel) to forward: look_at raises InputError; the renderer "
                   "CLI exits 2 with one stderr line and no traceback",
    "nonfinite_input": "NaN / inf camera arguments and NaN / inf vertices in .scene and .obj files: exit 2, "
                       "one stderr line naming the option or file:line and the value",
}

#: Per case: how its bounds are derived (shown in extremes_markdown and in each result).
CASE_BOUNDS = {
    "near_plane": "visibility: this camera's basis is exactly +-1/0 and every depth is a dyadic-exact "
                  "float64, so z_cam is computed exactly and float64 must apply near <= z <= far with no "
                  "tolerance. float32 may differ only where |z - plane| <= e_z + eps32 |plane| (_near_band): "
                  "e_z = 3 eps32 (|p_local| + |t_mv_z|) + ... covers the casts and the 3-term dot, "
                  "eps32 |plane| the rounding of near/far to float32 (5.2e-8 at near = 0.1). "
                  "Pixels: pixel_bound (module docstring).",
    "near_grazing": "|z_end - near| <= 8 eps (|z0| + |z1| + near) + e_cam: the crossing t = d0/(d0-d1) is "
                    "computed from the computed depths (2 roundings), z0 + t (z1 - z0) adds 3; a depth "
                    "error e_cam may leave the end unclipped. Along the edge the crossing is ill-conditioned: "
                    "a depth error e_cam moves it by kappa e_cam, kappa = |p1 - p0| / |z1 - z0| (1/slope), "
                    "at most the whole edge: lateral error <= min(|p1 - p0|, 2 kappa e_cam) + e_cam, "
                    "in pixels times f/near (2 + r/near), plus the rounding terms of pixel_bound.",
    "fov_extremes": "pixel_bound: the f/z factor carries the 2.75e6 px focal length at 0.01 deg. From 1e4 "
                    "away, render_frame's float32 lateral error is 3 eps32 |p_local| f / z ~ 1e-4 px (t_mv's "
                    "lateral components are ~0 after the float64 model-view; project_points takes the same path), "
                    "where casting p_world - position (|.| = 1e4) before rotating would give "
                    "3 eps32 |p_rel| f / z ~ 1 px. At 179.9 deg "
                    "the focal length's float64 rounding is magnified by kappa_f = 2 a / sin(a) + 2 ~ 3600.",
    "aspect_extremes": "pixel_bound; f = 3.46 px (4000x4) and 3464 px (4x4000), |x_px| up to 4000.",
    "far_from_origin": "pixel_bound with F = |A| |o| + |t| + |position| ~ 2e8: float64 3 eps64 F f / z "
                       "~ 1e-5 px (the float64 model-view: exact here when A = I, as Sterbenz makes t - "
                       "position exact; real when A o must be rounded), float32 3 eps32 (|p_local| + |t_mv_i|) "
                       "f / z ~ 5e-4 px (t_mv ~ 4, not 1e8): both sub-pixel; OpenCV's bound 8 eps64 "
                       "(|X| + |position|) f / z (not camera-relative).",
    "subpixel_object": "pixel_bound; drawn pixels: all within 1 px of the projected centre, at most 4.",
    "rotation_period": "bit-identical (no tolerance): the phase ((k-1) turns mod n) / n is exact in float64. "
                       "Matrix vs the long-double rotation of the exact phase: 16 eps64 per entry "
                       "(angle 2 pi p: 2 roundings, cos/sin 1 ulp each, two 3x3 products 3u each, "
                       "summed over 3 factors). Pixels: pixel_bound with model_err = 16 eps64.",
    "gimbal_lock": "R^T R - I <= 16 eps64 per entry (3 factors with |c^2 + s^2 - 1| <= 2 eps each, two "
                   "products adding 1.5 eps per entry each, the check's own product 1.5 eps); pixels: "
                   "pixel_bound with model_err = 16 eps64.",
    "up_parallel": "exact: |forward x up| = 0 < 1e-9 |up| (core/camera.py) must raise InputError.",
    "nonfinite_input": "exact: exit status 2, one line on stderr starting 'renderer: error:', no "
                       "traceback, naming the option or the file and line and the bad token.",
}

EXTREME_CASES = tuple(CASE_DESCRIPTIONS)


# ---- 1 ---------------------------------------------------------------------

def _case_near_plane(pr: _Pyrender) -> dict:
    c = _Case("near_plane")
    near, far = 0.1, 100.0
    # Camera at the origin looking down +Z: rows of R are (-1,0,0), (0,1,0), (0,0,1)
    # exactly, so z_cam = z_world with no rounding in either path.
    cam = look_at((0.0, 0.0, 0.0), (0.0, 0.0, 1.0), (0.0, 1.0, 0.0), near=near, far=far)
    up_, dn = np.nextafter(near, np.inf), np.nextafter(near, -np.inf)
    zs = {"near": near, "near+1ulp": up_, "near-1ulp": dn, "near+1e-9": near + 1e-9, "near-1e-9": near - 1e-9,
          "depth 0": 0.0, "depth -0": -0.0, "depth 5e-324": 5e-324, "behind -near": -near, "behind -1": -1.0,
          "far": far, "far+1ulp": np.nextafter(far, np.inf), "far-1ulp": np.nextafter(far, -np.inf),
          "middle 1": 1.0}
    labels = list(zs)
    z = np.array([zs[k] for k in labels])
    # x, y within the image for visible ones (|x/z| < 0.5): 0.3 z and -0.2 z, plus a 1/64 offset
    p = np.stack([0.3 * np.abs(z) + 1 / 64, -0.2 * np.abs(z) - 1 / 128, z], axis=1)
    cam_ld, ref_px, ref_vis = reference_project(p, cam)
    rule = (z >= near) & (z <= far)                  # the rule on the exact depths
    c.check(np.array_equal(ref_vis, rule), "reference visibility differs from the rule (reference bug)")
    c.check(bool((cam_ld[:, 2] == z.astype(LD)).all()), "reference depths are not exact (test design)")
    m = _measure(p, None, cam)
    c.add(m)
    f64 = m["frames"]["float64"]
    bad = [labels[i] for i in np.flatnonzero(f64.visible != rule)]
    c.check(not bad, f"float64 visibility differs from near <= z <= far at: {', '.join(bad)}")
    c.check(bool(np.array_equal(f64.depth, z)), "float64 depth is not exactly z_cam")
    c.check(bool(np.isnan(f64.p_px[~rule]).all() and np.isfinite(f64.p_px[rule]).all()),
            "float64 p_px: expected NaN exactly where clipped")
    pp = project_points(p, cam)
    bad_pp = [labels[i] for i in np.flatnonzero(np.isnan(pp[:, 0]) == rule)]
    c.check(not bad_pp, f"project_points visibility differs from the rule at: {', '.join(bad_pp)}")
    cv_vis = ~np.isnan(opencv_oracle.project(p, cam)[:, 0])
    # float32: flips allowed only inside the derived band (_near_band): |z - plane| <= e_cam + eps32 |plane|
    f32 = m["frames"]["float32"]
    flips = f32.visible != rule
    band = _near_band(cam_ld, cam, camera_error("float32", p, None, cam), EPS32)
    c.extra = {"near": near, "far": far, "z_offsets": "absolute (near + 1e-9, near - 1e-9) and 1 ulp",
               "float64_visibility_mismatch": len(bad), "opencv_visibility_mismatch": int((cv_vis != rule).sum()),
               "float32_visibility_flips": [labels[i] for i in np.flatnonzero(flips)],
               "float32_points_in_band": [labels[i] for i in np.flatnonzero(band)],
               "float32_band_at_near": float(camera_error("float32", p, None, cam)[0, 2] + EPS32 * near)}
    c.pyrender_note = "no edges: visibility of points only"
    return c.result()


# ---- 2 ---------------------------------------------------------------------

def _grazing_scene(cam, near, slopes):
    """Edges in camera space crossing z = near at each slope, as float64 world points."""
    basis = reference_basis(cam)                      # rows right, up, forward
    pos = np.asarray(cam.position, LD)
    ends_cam = []
    k = 0
    for s in slopes:
        for variant in range(2):
            y = LD(-0.35 + 0.1 * k)
            k += 1
            if variant == 0:      # along x, the clipped end first
                d = np.array([0.25, 0.0], dtype=LD)
            else:                 # diagonal, the visible end first
                d = np.array([-0.25, -0.05], dtype=LD)
            half_dz = LD(s) * _norm_ld(d)
            a = np.array([-d[0], y - d[1], LD(near) - half_dz], dtype=LD)
            b = np.array([d[0], y + d[1], LD(near) + half_dz], dtype=LD)
            ends_cam += [a, b] if variant == 0 else [b, a]
    ends_cam = np.array(ends_cam, dtype=LD)
    world = (ends_cam @ basis + pos).astype(np.float64)
    edges = np.arange(len(world)).reshape(-1, 2)
    return world, edges


def _case_near_grazing(pr: _Pyrender) -> dict:
    c = _Case("near_grazing")
    near = 1.0
    cam = look_at((0.3, 0.2, 4.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0), near=near, far=100.0)
    slopes = (1e-3, 1e-5, 1e-7, 1e-9)
    world, edges = _grazing_scene(cam, near, slopes)
    m = _measure(world, None, cam, edges=edges)
    c.add(m)
    ref_cam = m["ref"][0]
    p0, p1 = ref_cam[edges[:, 0]], ref_cam[edges[:, 1]]
    clipped_first = p0[:, 2] < LD(near)            # which end the near plane cuts
    t_star = (LD(near) - p0[:, 2]) / (p1[:, 2] - p0[:, 2])
    q_ref = p0 + t_star[:, None] * (p1 - p0)        # exact intersection (long double)
    _, q_px, q_vis = _project_cam_ld(q_ref, cam)
    per_slope = {}
    f = cam.focal_px
    for dt in DTYPES:
        eps = EPS[dt]
        e_cam = camera_error(dt, world, None, cam)
        points = localize(world, dt)
        pc = model_to_cam(points, np.eye(4), cam)
        seg = pc[edges]
        planes = clipping.frustum_planes(cam).astype(pc.dtype)
        kept, t0, t1 = clipping.clip_segments(seg, planes)
        c.check(bool(kept.all()), f"{dt}: a grazing edge was dropped")
        if not kept.all():
            continue
        out = clipping.apply_clip(seg, kept, t0, t1, (cam.near, cam.far))
        end_cam = np.where(clipped_first[:, None], out[:, 0, :], out[:, 1, :]).astype(np.float64)
        end_px = cam_to_px(np.where(clipped_first[:, None], out[:, 0, :], out[:, 1, :]), cam).astype(np.float64)
        e_end = np.maximum(e_cam[edges[:, 0]], e_cam[edges[:, 1]]).max(axis=1)   # worst component
        z0, z1 = np.abs(p0[:, 2]).astype(float), np.abs(p1[:, 2]).astype(float)
        z_bound = 8 * eps * (z0 + z1 + near) + e_end
        z_err = np.abs(end_cam[:, 2] - near)
        seg_len = _norm_ld(p1 - p0).astype(float)
        kappa = seg_len / np.abs(p1[:, 2] - p0[:, 2]).astype(float)
        lateral = np.minimum(seg_len, 2 * kappa * e_end) + e_end + 8 * eps * (
            _norm_ld(p0).astype(float) + _norm_ld(p1).astype(float))
        qc = q_ref.astype(np.float64)
        r = np.abs(qc[:, 0]) + np.abs(qc[:, 1])
        px_bound = SAFETY * (f / near * lateral * (2 + r / near) + 2 * eps * f * r / near
                             + eps * np.abs(q_px.astype(float)).sum(axis=1)
                             + focal_condition(cam) * EPS64 * f * r / near)
        px_err = _err_px(end_px, q_px)
        for i, s in enumerate(np.repeat(slopes, 2)):
            d = per_slope.setdefault(f"{s:g}", {})
            cur = d.setdefault(dt, {"z_error": 0.0, "z_bound": np.inf, "px_error": 0.0, "px_bound": np.inf,
                                    "kappa": 0.0})
            cur["z_error"] = max(cur["z_error"], float(z_err[i]))
            cur["z_bound"] = min(cur["z_bound"], float(z_bound[i]))
            cur["px_error"] = max(cur["px_error"], float(px_err[i]))
            cur["px_bound"] = min(cur["px_bound"], float(px_bound[i]))
            cur["kappa"] = max(cur["kappa"], float(kappa[i]))
        bad_z = z_err > z_bound
        bad_px = px_err > px_bound
        c.check(not bad_z.any(), f"{dt}: clipped end off the near plane by {z_err.max():.3g} "
                                 f"(bound {z_bound[np.argmax(z_err / z_bound)]:.3g})")
        c.check(not bad_px.any(), f"{dt}: clipped end {px_err.max():.3g} px from the exact intersection "
                                  f"(max error/bound {(px_err / px_bound).max():.3g})")
        c.stats[dt]["clipped_end_px_error"] = float(px_err.max())
        c.stats[dt]["clipped_end_px_ratio"] = float((px_err / px_bound).max())
        c.stats[dt]["clipped_end_z_error"] = float(z_err.max())
    c.extra = {"near": near, "per_slope": per_slope,
               "note": "per slope: worst error and tightest bound over its two edges; float32 cannot "
                       "resolve depth differences below ~eps32 |p| = 5e-7, so at slopes <= 1e-7 its "
                       "crossing may be anywhere on the edge (the bound says so via min(|p1-p0|, ...))."}
    # pyrender: per slope (float32 GL: the crossing moves by ~eps32 |p| / slope world units)
    for j, s in enumerate(slopes):
        e = edges[2 * j:2 * j + 2]
        frame = render_frame(world, e, cam, np.eye(4))
        scores, note = _pyrender_scores(pr, frame.mask, world, e, cam)
        # judged only where GL's float32 vertex positions (|p| ~ 4.1, rounded by u |p| per coordinate,
        # ~3 u |p| in depth) move the crossing by < 0.5 px: 1.5 eps32 |p| / s * f / near (1e-3: 0.3 px)
        judged = 1.5 * EPS32 * 4.1 / s * f / near < 0.5
        c.add_pyrender(f"slope {s:g}", scores, note, judged=judged)
    if c.pyrender_parts:
        c.pyrender_note = ("F1 judged only at slopes where float32 GL resolves the crossing to < 0.5 px "
                           "(1.5 eps32 |p| / slope * f / near); smaller slopes are information: there GL "
                           "cannot tell the ends' depths apart and draws the whole edge")
    return c.result()


def _project_cam_ld(p_cam, camera):
    z = p_cam[:, 2]
    f = reference_focal(camera)
    cx, cy = (LD(camera.width) - 1) / 2, (LD(camera.height) - 1) / 2
    px = np.stack([cx + f * p_cam[:, 0] / z, cy - f * p_cam[:, 1] / z], axis=1)
    return p_cam, px, np.ones(len(p_cam), bool)


# ---- 3 ---------------------------------------------------------------------

def _case_fov_extremes(pr: _Pyrender) -> dict:
    c = _Case("fov_extremes")
    # fov 0.01 deg: the image spans 2 * 1e4 * tan(0.005 deg) = 1.75 units vertically at 1e4
    # from an oblique direction: every world axis contributes ~1e4 to x_cam, y_cam (cancelling)
    cam_small = look_at(1e4 * np.array([0.6, 0.48, 0.64]), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0), fov_y_deg=0.01,
                        near=1.0, far=2e4)
    mm = compose(rotate_z(0.3), rotate_y(0.5), rotate_x(0.2))
    m = _measure(CUBE_V, mm, cam_small, edges=CUBE_E)
    c.add(m, label="fov 0.01: ")
    scores, note = _pyrender_scores(pr, m["frames"]["float64"].mask, CUBE_V, CUBE_E, cam_small, mm)
    c.add_pyrender("fov 0.01", scores, note, judged=True)
    small = {dt: _public(m[dt]) for dt in DTYPES}
    small["opencv"] = _public(m["opencv"])
    small["project_points"] = {dt: _public(m["pp_" + dt]) for dt in DTYPES}
    # fov 179.9 deg: f = 0.21 px; points up to 89.94 deg off axis (x/z up to ~950)
    cam_wide = look_at((0.0, 0.0, 4.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0), fov_y_deg=179.9, near=0.01, far=1e5)
    rng = np.random.default_rng(1799)
    theta = np.radians(np.concatenate([np.linspace(0.0, 89.0, 30), [89.9, 89.93, 89.94]]))
    phi = rng.uniform(0, 2 * np.pi, len(theta))
    rad = rng.uniform(1.0, 50.0, len(theta))
    dirs = np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)], axis=1)
    p_cam = dirs * rad[:, None]
    basis = np.stack([cam_wide.right, cam_wide.up, cam_wide.forward])
    pts = p_cam @ basis + cam_wide.position          # inputs (rounded float64 world points)
    ring = np.arange(len(pts))
    e_wide = np.stack([ring[:-1], ring[1:]], axis=1)
    m2 = _measure(pts, None, cam_wide, edges=e_wide)
    c.add(m2, label="fov 179.9: ")
    scores, note = _pyrender_scores(pr, m2["frames"]["float64"].mask, pts, e_wide, cam_wide)
    c.add_pyrender("fov 179.9", scores, note, judged=True)
    wide = {dt: _public(m2[dt]) for dt in DTYPES}
    wide["opencv"] = _public(m2["opencv"])
    wide["project_points"] = {dt: _public(m2["pp_" + dt]) for dt in DTYPES}
    c.extra = {"fov_0.01": dict(small, focal_px=cam_small.focal_px),
               "fov_179.9": dict(wide, focal_px=cam_wide.focal_px, kappa_f=focal_condition(cam_wide))}
    return c.result()


# ---- 4 ---------------------------------------------------------------------

def _zigzag(width, height, fov=60.0):
    """A camera 4 units up +Z and a zig-zag filling the long side of the image."""
    cam = look_at((0.0, 0.0, 4.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0), fov_y_deg=fov, width=width, height=height,
                  near=0.1, far=100.0)
    f = cam.focal_px
    n = 41
    lim_x = 0.95 * (width / 2) / f * 4          # world extent that fills 95 % of each side at depth 4
    lim_y = 0.95 * (height / 2) / f * 4
    if width >= height:
        xs = np.linspace(-lim_x, lim_x, n)
        ys = np.where(np.arange(n) % 2 == 0, lim_y, -lim_y)
    else:
        ys = np.linspace(-lim_y, lim_y, n)
        xs = np.where(np.arange(n) % 2 == 0, lim_x, -lim_x)
    v = np.stack([xs, ys, np.zeros(n)], axis=1)
    e = np.stack([np.arange(n - 1), np.arange(1, n)], axis=1)
    return cam, v, e


def _case_aspect_extremes(pr: _Pyrender) -> dict:
    c = _Case("aspect_extremes")
    mm = compose(translate((1e-3, -1e-3, 0.05)), rotate_y(1e-5))
    for w, h in ((4000, 4), (4, 4000)):
        cam, v, e = _zigzag(w, h)
        m = _measure(v, mm, cam, edges=e)
        c.add(m, label=f"{w}x{h}: ")
        frame = m["frames"]["float64"]
        c.check(int(frame.mask.sum()) > max(w, h) // 2, f"{w}x{h}: expected a line across the long side, "
                                                        f"got {int(frame.mask.sum())} pixels")
        scores, note = _pyrender_scores(pr, frame.mask, v, e, cam, mm)
        c.add_pyrender(f"{w}x{h}", scores, note, judged=True)
        if scores is not None:
            c.pyrender_note = "OSMesa renders both 4000x4 and 4x4000 (no size limit hit)"
        c.extra[f"{w}x{h}"] = {"focal_px": cam.focal_px, "core_pixels": int(frame.mask.sum()),
                               "float64": _public(m["float64"]), "float32": _public(m["float32"])}
    return c.result()


# ---- 5 ---------------------------------------------------------------------

def _case_far_from_origin(pr: _Pyrender) -> dict:
    c = _Case("far_from_origin")
    o = 1e8 * np.array([0.6, 0.48, 0.64])                       # |o| = 1e8
    cam = look_at(o + (0.3, 0.2, 4.0), o, (0.0, 1.0, 0.0), near=0.1, far=100.0)
    rot = compose(rotate_z(0.3), rotate_y(0.5), rotate_x(0.2))
    # (a) unit cube at the model origin, placed by the model matrix's translation
    mm = compose(translate(o), rot)
    ma = _measure(CUBE_V, mm, cam, edges=CUBE_E)
    c.add(ma, label="model matrix: ")
    # (b) the same cube's vertices at 1e8 themselves, identity model matrix (localize re-centres)
    vb = (reference_world(CUBE_V, rot[:3, :3], o)).astype(np.float64)
    mb = _measure(vb, None, cam, edges=CUBE_E)
    c.add(mb, label="vertices at 1e8: ")
    # (c) vertices at 1e8 AND a model rotation about the world origin: A o (1e8) is formed in
    # float64, so here the 3 eps64 F term of the bound is real (core ~ OpenCV's error)
    a_c = compose(rotate_z(0.7), rotate_x(0.4))
    ao = reference_world(o[None, :], a_c[:3, :3], np.zeros(3))[0]
    cam_c = look_at((ao + np.array([0.3, 0.2, 4.0], dtype=LD)).astype(np.float64), ao.astype(np.float64),
                    (0.0, 1.0, 0.0), near=0.1, far=100.0)
    vc = (reference_world(CUBE_V, rot[:3, :3] @ a_c[:3, :3].T, o)).astype(np.float64)
    mc = _measure(vc, a_c, cam_c, edges=CUBE_E)
    c.add(mc, label="vertices at 1e8, rotated: ")
    c.check(int(mc["frames"]["float64"].mask.sum()) > 100, "rotated far cube: expected it drawn on screen")
    for dt in DTYPES:
        worst = max(ma[dt]["max_error_px"], mb[dt]["max_error_px"], mc[dt]["max_error_px"])
        c.check(worst < 0.5, f"{dt}: {worst:.3g} px: expected sub-pixel")
    c.check(bool(np.array_equal(ma["frames"]["float64"].mask, mb["frames"]["float64"].mask)),
            "the two placements draw different float64 frames")
    c.extra = {
        "model_matrix": {dt: _public(ma[dt]) for dt in DTYPES} | {"opencv": _public(ma["opencv"])},
        "vertices_at_1e8": {dt: _public(mb[dt]) for dt in DTYPES} | {"opencv": _public(mb["opencv"])},
        "vertices_at_1e8_rotated": {dt: _public(mc[dt]) for dt in DTYPES} | {"opencv": _public(mc["opencv"])},
        "origin_distance": float(np.linalg.norm(o)),
    }
    sa, note = _pyrender_scores(pr, ma["frames"]["float64"].mask, CUBE_V, CUBE_E, cam, mm)
    c.add_pyrender("model matrix", sa, note, judged=False)
    sb, note = _pyrender_scores(pr, mb["frames"]["float64"].mask, vb, CUBE_E, cam)
    c.add_pyrender("vertices at 1e8", sb, note, judged=False)
    if sa is not None:
        c.pyrender_note = ("information only: pyrender/GL is float32 and not camera-relative, at 1e8 "
                           "float32 spacing is 8 units, larger than the cube")
    return c.result()


# ---- 6 ---------------------------------------------------------------------

def _case_subpixel_object(pr: _Pyrender) -> dict:
    c = _Case("subpixel_object")
    d = 1e5
    cam = look_at((0.0, 0.0, d), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0), near=1.0, far=2e5)
    f = cam.focal_px
    # put the cube's centre at pixel (400.2, 150.3): inside a pixel, away from its edges
    centre_px = np.array([400.2, 150.3])
    cx, cy = cam.principal_point
    offset = ((centre_px[0] - cx) * d / f, -(centre_px[1] - cy) * d / f, 0.0)
    mm = compose(translate(offset), rotate_y(0.4), rotate_x(0.3))
    m = _measure(CUBE_V, mm, cam, edges=CUBE_E)
    c.add(m)
    ref_px = m["ref"][1].astype(np.float64)
    extent = float(np.ptp(ref_px, axis=0).max())
    c.extra = {"screen_extent_px": extent, "centre_px": centre_px.tolist()}
    c.check(extent < 0.01, f"the cube covers {extent:.3g} px: expected < 0.01 (test design)")
    rc = np.floor(ref_px.mean(axis=0) + 0.5)                    # the pixel under the cube
    for dt in DTYPES:
        mask = m["frames"][dt].mask
        rows, cols = np.nonzero(mask)
        c.extra[f"{dt}_pixels"] = int(mask.sum())
        c.check(len(rows) <= 4, f"{dt}: {len(rows)} pixels drawn for a sub-pixel cube: expected <= 4")
        near_ok = (np.abs(cols - rc[0]) <= 1).all() and (np.abs(rows - rc[1]) <= 1).all()
        c.check(bool(near_ok), f"{dt}: pixels drawn away from the cube's pixel {rc.tolist()}")
    scores, note = _pyrender_scores(pr, m["frames"]["float64"].mask, CUBE_V, CUBE_E, cam, mm)
    if scores is not None:
        c.extra["pyrender_pixels"] = scores["pyrender_pixels"]
        c.check(scores["pyrender_pixels"] <= 4, f"pyrender drew {scores['pyrender_pixels']} pixels: expected <= 4")
    c.add_pyrender("cube", scores, note, judged=False)
    if scores is not None:
        c.pyrender_note = ("F1 not judged: whether a line shorter than 0.01 px lights a pixel is decided "
                           "by sub-pixel tie rules; both must draw <= 4 pixels")
    return c.result()


# ---- 7 ---------------------------------------------------------------------

def _case_rotation_period(pr: _Pyrender) -> dict:
    c = _Case("rotation_period")
    turns, frames, period = (1000, 3000, 500), 1_000_000, 2000
    motion = Motion(turns=tuple(float(t) for t in turns))
    cam = look_at((0.3, 0.2, 4.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    ks = [1, 2, 777, 123_457, 499_999, 997_001, 997_999, 998_000]
    mat_err = 0.0
    identical = {"matrix": True, "p_px": True, "image": True}
    for k in ks:
        m0 = motion.frame_matrix(k, frames)
        m1 = motion.frame_matrix(k + period, frames)
        same_m = m0.tobytes() == m1.tobytes()
        identical["matrix"] &= same_m
        c.check(same_m, f"frames {k} and {k + period}: model matrices differ")
        a_ld, t_ld = reference_motion_matrix(turns, (0, 0, 0), 1.0, k, frames)
        mat_err = max(mat_err, float(np.abs(m0[:3, :3].astype(LD) - a_ld).max()))
        fr = {}
        for kk, mk in ((k, m0), (k + period, m1)):
            fr[kk] = {dt: render_frame(CUBE_V, CUBE_E, cam, mk, dtype=dt) for dt in DTYPES}
        for dt in DTYPES:
            a, b = fr[k][dt], fr[k + period][dt]
            same_px = a.p_px.tobytes() == b.p_px.tobytes()
            same_img = a.image.tobytes() == b.image.tobytes()
            identical["p_px"] &= same_px
            identical["image"] &= same_img
            c.check(same_px and same_img, f"{dt}: frames {k} and {k + period} differ in "
                                          f"{'p_px' if not same_px else 'image'}")
        m = _measure(CUBE_V, m0, cam, edges=CUBE_E, model_err=16 * EPS64, a_ld=a_ld, t_ld=t_ld,
                     frames=fr[k])
        c.add(m, label=f"frame {k}: ")
    c.check(mat_err <= 16 * EPS64, f"model matrix {mat_err:.3g} from the exact rotation: expected <= 16 eps64")
    # the last frame of the run closes the loop: frame 1 + frames is frame 1 again
    c.check(motion.frame_matrix(1, frames).tobytes() == motion.frame_matrix(1 + frames, frames).tobytes(),
            "frame 1 + frames differs from frame 1")
    c.extra = {"turns": list(turns), "frames": frames, "period": period, "sampled_k": ks,
               "bit_identical": identical, "matrix_error_vs_exact": mat_err,
               "matrix_error_bound": 16 * EPS64}
    c.pyrender_note = "not needed: the check is bit-identity between core's own frames"
    return c.result()


# ---- 8 ---------------------------------------------------------------------

def _case_gimbal_lock(pr: _Pyrender) -> dict:
    c = _Case("gimbal_lock")
    turns, frames = (3, 2, 5), 8            # frame 2: phases (3/8, 1/4, 5/8); frame 4: (1/8, 3/4, 7/8)
    motion = Motion(turns=tuple(float(t) for t in turns), offset=(0.1, -0.2, 0.3))
    cam = look_at((0.3, 0.2, 4.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    ortho_err = 0.0
    for k, pitch in ((2, 90), (4, -90)):
        mk = motion.frame_matrix(k, frames)
        a = mk[:3, :3]
        d = float(np.abs(a.T @ a - np.eye(3)).max())
        ortho_err = max(ortho_err, d)
        a_ld, t_ld = reference_motion_matrix(turns, motion.offset, 1.0, k, frames)
        m = _measure(CUBE_V, mk, cam, edges=CUBE_E, model_err=16 * EPS64, a_ld=a_ld, t_ld=t_ld)
        c.add(m, label=f"pitch {pitch:+d}: ")
        c.extra[f"pitch_{pitch:+d}_frame"] = k
        scores, note = _pyrender_scores(pr, m["frames"]["float64"].mask, CUBE_V, CUBE_E, cam, mk)
        c.add_pyrender(f"pitch {pitch:+d}", scores, note, judged=True)
    c.check(ortho_err <= 16 * EPS64, f"R^T R - I = {ortho_err:.3g}: expected <= 16 eps64")
    c.extra["orthonormality_error"] = ortho_err
    c.extra["orthonormality_bound"] = 16 * EPS64
    # cameras straight down / up the Y axis, with up along -Z / +Z
    for name, pos, up in (("down", (0.0, 5.0, 0.0), (0.0, 0.0, -1.0)), ("up", (0.0, -5.0, 0.0), (0.0, 0.0, 1.0))):
        try:
            cv = look_at(pos, (0.0, 0.0, 0.0), up)
        except InputError as exc:
            c.fail(f"camera looking {name}: {exc}")
            continue
        mm = compose(rotate_y(0.3), rotate_x(0.1))
        m = _measure(CUBE_V, mm, cv, edges=CUBE_E)
        c.add(m, label=f"looking {name}: ")
        scores, note = _pyrender_scores(pr, m["frames"]["float64"].mask, CUBE_V, CUBE_E, cv, mm)
        c.add_pyrender(f"looking {name}", scores, note, judged=True)
        c.extra[f"looking_{name}_right"] = [float(x) for x in cv.right]
    return c.result()


# ---- 9, 10: the renderer CLI -------------------------------------------------

def _run_cli(arg_lists, tmp: Path):
    """Run ``python -m core.cli ARGS --out DIR`` for each, in parallel: [(rc, stderr)]."""
    env = dict(os.environ)
    env["PYTHONPATH"] = str(REPO_ROOT) + (os.pathsep + env["PYTHONPATH"] if env.get("PYTHONPATH") else "")
    procs = []
    for i, args in enumerate(arg_lists):
        out = tmp / f"out{i}"
        procs.append(subprocess.Popen([sys.executable, "-m", "wirecheck.core.cli", *args, "--frames", "2", "--out", str(out)],
                                      cwd=str(REPO_ROOT), env=env, stdin=subprocess.DEVNULL,
                                      stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True))
    results = []
    for p in procs:
        try:
            _, err = p.communicate(timeout=120)
        except subprocess.TimeoutExpired:
            p.kill()
            _, err = p.communicate()
        results.append((p.returncode, err))
    return results


def _check_cli(c: _Case, label: str, args, rc: int, err: str, must_contain=()):
    lines = err.splitlines()
    rec = {"args": list(args), "exit": rc, "stderr": err.strip()}
    ok = rc == 2 and len(lines) == 1 and "Traceback" not in err and lines[0].startswith("renderer: error:")
    missing = [s for s in must_contain if s not in err]
    if not ok:
        c.fail(f"{label}: exit {rc}, {len(lines)} stderr lines: expected exit 2 and one "
               f"'renderer: error:' line ({err.strip()[:200]!r})")
    elif missing:
        c.fail(f"{label}: the message {lines[0]!r} does not name {missing}")
    rec["ok"] = ok and not missing
    return rec


def _case_up_parallel(pr: _Pyrender) -> dict:
    c = _Case("up_parallel")
    for name, up in (("parallel", (0.0, 1.0, 0.0)), ("anti-parallel", (0.0, -1.0, 0.0)),
                     ("parallel, scaled", (0.0, 1e-3, 0.0))):
        try:
            look_at((0.0, 5.0, 0.0), (0.0, 0.0, 0.0), up)
        except InputError as exc:
            c.extra[f"look_at_{name}"] = str(exc)
        except Exception as exc:  # any other exception type is a bug
            c.fail(f"look_at with up {name}: {type(exc).__name__} instead of InputError")
        else:
            c.fail(f"look_at with up {name} to forward: no error")
    # 1e-6 rad off parallel: a valid (if odd) camera, basis orthonormal
    cam = look_at((0.0, 5.0, 0.0), (0.0, 0.0, 0.0), (1e-6, 1.0, 0.0))
    b = np.stack([cam.right, cam.up, cam.forward])
    c.check(float(np.abs(b @ b.T - np.eye(3)).max()) <= 8 * EPS64, "up 1e-6 rad off forward: basis not orthonormal")
    with tempfile.TemporaryDirectory(prefix="wirecheck-extremes-") as tmp:
        args_list = [["--camera-pos", "0,5,0", "--look-at", "0,0,0", "--up", "0,1,0"],
                     ["--camera-pos", "0,5,0", "--look-at", "0,0,0", "--up", "0,-3,0"]]
        c.extra["cli"] = [_check_cli(c, " ".join(a), a, rc, err, must_contain=("up",))
                          for a, (rc, err) in zip(args_list, _run_cli(args_list, Path(tmp)))]
    c.pyrender_note = "not applicable (input validation)"
    return c.result()


#: (label, args, strings the error line must contain); scene files are written to a temp dir.
_NONFINITE_ARGS = [
    (["--camera-pos", "nan,0,4"], ("--camera-pos", "nan")),
    (["--camera-pos", "0,inf,4"], ("--camera-pos", "inf")),
    (["--camera-pos", "1,2,3", "--look-at", "0,nan,0"], ("--look-at", "nan")),
    (["--camera-pos", "1,2,3", "--up", "0,-inf,0"], ("--up", "inf")),
    (["--fov", "inf"], ("--fov", "inf")),
    (["--fov", "nan"], ("--fov", "nan")),
    (["--camera-z", "nan"], ("--camera-z", "nan")),
    (["--camera-z=-inf"], ("--camera-z", "inf")),   # "--camera-z -inf": argparse takes -inf for an option
    (["--near", "nan"], ("near", "nan")),
    (["--far", "inf"], ("far", "inf")),
    (["--projection", "orthographic", "--ortho-height", "nan"], ("ortho-height", "nan")),
    (["--scale", "inf"], ("--scale", "inf")),
    (["--spin", "nan,0,0"], ("--spin", "nan")),
    (["--translate", "0,0,inf"], ("--translate", "inf")),
]

_NONFINITE_SCENES = [
    ("nan_vertex.scene", "# a NaN vertex on line 3\nv 0 0 0\nv nan 1 0\nv 1 1 1\ne 0 1\ne 1 2\n", 3, "nan"),
    ("inf_vertex.scene", "v 0 0 0\nv 1 1 1\nv 0 -inf 0\ne 0 1\ne 1 2\n", 3, "-inf"),
    ("overflow_vertex.scene", "v 0 0 0\nv 1e999 1 1\ne 0 1\n", 2, "1e999"),
    ("nan_vertex.obj", "v 0 0 0\nv 1 1 1\nv 1 NaN 0\nf 1 2 3\n", 3, "NaN"),
]


def _case_nonfinite_input(pr: _Pyrender) -> dict:
    c = _Case("nonfinite_input")
    with tempfile.TemporaryDirectory(prefix="wirecheck-extremes-") as tmp:
        tmp = Path(tmp)
        jobs = [(" ".join(a), a, must) for a, must in _NONFINITE_ARGS]
        for fname, text, line, token in _NONFINITE_SCENES:
            path = tmp / fname
            path.write_text(text)
            jobs.append((fname, ["--scene", str(path)], (f"{path}:{line}", token)))
        results = _run_cli([a for _, a, _ in jobs], tmp)
        c.extra["cli"] = [_check_cli(c, label, a, rc, err, must)
                          for (label, a, must), (rc, err) in zip(jobs, results)]
        for r in c.extra["cli"]:                        # temp paths vary: keep results deterministic
            r["stderr"] = r["stderr"].replace(str(tmp), "<tmp>")
            r["args"] = [x.replace(str(tmp), "<tmp>") for x in r["args"]]
    c.pyrender_note = "not applicable (input validation)"
    return c.result()


_CASE_FUNCS = {
    "near_plane": _case_near_plane,
    "near_grazing": _case_near_grazing,
    "fov_extremes": _case_fov_extremes,
    "aspect_extremes": _case_aspect_extremes,
    "far_from_origin": _case_far_from_origin,
    "subpixel_object": _case_subpixel_object,
    "rotation_period": _case_rotation_period,
    "gimbal_lock": _case_gimbal_lock,
    "up_parallel": _case_up_parallel,
    "nonfinite_input": _case_nonfinite_input,
}
assert tuple(_CASE_FUNCS) == EXTREME_CASES


def _run(name: str, pr: _Pyrender) -> dict:
    try:
        return _CASE_FUNCS[name](pr)
    except Exception as exc:  # a crash in core is a failed case, reported, not a crashed suite
        c = _Case(name)
        c.fail(f"crashed: {type(exc).__name__}: {exc}")
        return c.result()


def run_case(name: str, pyrender: bool = True) -> dict:
    """One case by name (see :data:`EXTREME_CASES`); its own pyrender oracles, closed after."""
    if name not in _CASE_FUNCS:
        raise ValueError(f"case {name!r}: expected one of {', '.join(EXTREME_CASES)}")
    pr = _Pyrender(pyrender)
    try:
        return _run(name, pr)
    finally:
        pr.close()


def run_extremes(pyrender: bool = True) -> dict:
    """Every case; ``{"verdict", "cases": [...], "timing": {...}}`` (only "timing" varies run to run)."""
    pr = _Pyrender(pyrender)
    cases, seconds = [], {}
    t_all = time.perf_counter()
    try:
        for name in EXTREME_CASES:
            t0 = time.perf_counter()
            cases.append(_run(name, pr))
            seconds[name] = time.perf_counter() - t0
    finally:
        pr.close()
    return {
        "suite": "extremes",
        "verdict": "pass" if all(c["verdict"] == "pass" for c in cases) else "fail",
        "pyrender": pr.enabled,
        "reference": {"dtype": "longdouble", "eps": REFERENCE_EPS, "extended": REFERENCE_EXTENDED},
        "cases": cases,
        "timing": {"total_seconds": time.perf_counter() - t_all, "case_seconds": seconds},
    }


def _fmt(v, digits=2):
    if v is None:
        return "-"
    return v if isinstance(v, str) else f"{v:.{digits}g}"      # "inf" (see _f) as is


def extremes_markdown(result: dict) -> str:
    """A Markdown table of the cases and one line per case on what it checks and its bound."""
    lines = [f"## Extremes suite: {result['verdict'].upper()}", "",
             "| case | float64 error px | bound px | float32 error px | bound px | pyrender F1@1 | verdict |",
             "| --- | --- | --- | --- | --- | --- | --- |"]
    for c in result["cases"]:
        f64, f32 = c["float64"] or {}, c["float32"] or {}
        pyr = c["pyrender"]
        if pyr is None:
            pyr_txt = "-"
        elif pyr.get("f1_1px_judged") is None:
            pyr_txt = f"{pyr['f1_1px']:.3f} (info)"
        else:
            pyr_txt = f"{pyr['f1_1px_judged']:.3f}"
            if pyr["f1_1px"] < pyr["f1_1px_judged"]:
                pyr_txt += f" (info frames: {pyr['f1_1px']:.3f})"
        lines.append(f"| {c['name']} | {_fmt(f64.get('max_error_px'))} | {_fmt(f64.get('bound_px'))} | "
                     f"{_fmt(f32.get('max_error_px'))} | {_fmt(f32.get('bound_px'))} | {pyr_txt} | "
                     f"{c['verdict']} |")
    lines += ["", "Bound px is the bound at the point of the largest error (every point's error must be "
                  "within its own bound). pyrender F1@1: the smallest over the frames a case judges; "
                  "(info) frames are reported, not judged. "
                  "Errors are against a long-double reference computed from core/conventions.py.", ""]
    for c in result["cases"]:
        lines.append(f"- **{c['name']}**: {c['description']}. Bound: {c['bound_derivation']}")
        pp = c.get("project_points")
        if pp:
            lines.append(f"  (project_points, the world path: float64 {_fmt(pp['float64']['max_error_px'])} px, "
                         f"float32 {_fmt(pp['float32']['max_error_px'])} px, bound "
                         f"{_fmt(pp['float32']['bound_px'])} px)")
        if c["pyrender_note"]:
            lines.append(f"  (pyrender: {c['pyrender_note']})")
        for r in c["reasons"]:
            lines.append(f"  - FAIL: {r}")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":  # python -m oracles.extremes [--no-pyrender] [--json PATH]
    import json

    res = run_extremes(pyrender="--no-pyrender" not in sys.argv)
    if "--json" in sys.argv:
        Path(sys.argv[sys.argv.index("--json") + 1]).write_text(json.dumps(res, indent=1) + "\n")
    print(extremes_markdown(res))
    sys.exit(0 if res["verdict"] == "pass" else 1)
