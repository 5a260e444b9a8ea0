"""``distortion_mismatch``: a candidate whose lens differs from the camera's, named from the radial profile.

Called by :func:`oracles.diagnosis.diagnose.diagnose` when its affine fit fails (the
candidate's pixels are no image-plane affine map of the oracle's). A lens
error is such a case: a radial polynomial bends the picture. With the
camera's own ``K`` (``fx, fy, cx, cy``) taken as right, the test is:

1. ``d_o``, ``d_c``: the oracle's and the candidate's pixels in distorted
   normalised coordinates, ``((x - cx) / fx, (y - cy) / fy)`` (OpenCV's axes,
   y down).
2. ``n``: the ideal (pinhole) normalised points, the oracle's ``d_o``
   undistorted with the camera's coefficients (Newton's method on
   ``cv2.projectPoints``' own model and Jacobian: independent of core); ``n =
   d_o`` for a camera without distortion.
3. The residual ``d_c - n`` -- what the candidate's lens did to the ideal
   picture -- is fitted by OpenCV's radial-tangential profile, linear in
   ``(k1, k2, k3, p1, p2)``::

       dx = x (k1 r2 + k2 r2^2 + k3 r2^3) + 2 p1 x y + p2 (r2 + 2 x^2)
       dy = y (k1 r2 + k2 r2^2 + k3 r2^3) + p1 (r2 + 2 y^2) + 2 p2 x y

   with ``r2 = x^2 + y^2`` of ``n``. If the fitted profile reproduces the
   candidate to ``tol_px`` (in pixels) and its effect differs from the
   camera's lens by more than ``tol_px`` somewhere, the fault is
   ``distortion_mismatch`` with the candidate's effective ``coefficients``
   (fields ``k1, k2, k3, p1, p2``; the camera's are in its ``distortion``), and ``kind``:

   * ``"added"``: the camera has no distortion, the candidate applies some;
   * ``"ignored"``: the fitted lens moves no point by more than ``tol_px``;
   * ``"k1_sign"``: the fitted k1 has the opposite sign of the camera's;
   * ``"magnitude"``: otherwise (k1, k2 or k3 of the wrong size, or p1/p2).

   ``radial_error_px`` is the largest candidate-minus-oracle error along the
   radius (pixels, outward positive) and ``at_radius_px`` where it is (pixels
   from the principal point): the profile grows as r^3 for k1, r^5 for k2,
   which is what the fit reads; ``residual_px`` is what the fit leaves.

Not recognised (left ``unexplained``): a lens error together with another
error (a wrong K, a rotation), or a rational-model camera (k4..k6) whose
candidate gets the rational part wrong.
"""

from __future__ import annotations

import numpy as np

__all__ = ["distortion_fault", "undistort"]

#: Newton iterations of :func:`undistort`: each one squares the relative error
#: once it is below ~0.1; 20 reach float64 from a start as far off as a
#: distortion of 50 % (measured: 5-6 for the case set's lens).
NEWTON_STEPS = 20

#: Columns of the least-squares design: the profile has 5 coefficients; a fit
#: needs a spread of radii, so fewer points than this (or a rank-deficient
#: design) is no diagnosis.
_COEFFS = ("k1", "k2", "k3", "p1", "p2")


def _project_normalised(n: np.ndarray, dist: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """OpenCV's distortion of normalised points ``(N, 2)``, and its 2x2 Jacobians ``(N, 2, 2)``.

    ``cv2.projectPoints`` of ``(x, y, 1)`` with ``R = I``, ``t = 0``, ``K = I``;
    the derivative with respect to ``t_x, t_y`` is the one with respect to
    ``x, y`` (the point is ``X + t``, at depth 1).
    """
    import cv2

    pts = np.column_stack([n, np.ones(len(n))]).reshape(-1, 1, 3)
    out, jac = cv2.projectPoints(pts, np.zeros(3), np.zeros(3), np.eye(3), dist)
    jac = jac.reshape(len(n), 2, -1)[:, :, 3:5]  # d(u, v) / d(t_x, t_y)
    return out.reshape(-1, 2), jac


def undistort(d: np.ndarray, dist) -> np.ndarray:
    """Ideal normalised points whose OpenCV distortion is ``d`` ``(N, 2)`` (Newton's method)."""
    dist = np.asarray(dist, dtype=np.float64).reshape(-1)
    n = np.array(d, dtype=np.float64)
    if not dist.any() or not len(n):
        return n
    for _ in range(NEWTON_STEPS):
        f, jac = _project_normalised(n, dist)
        step = np.linalg.solve(jac, (f - d)[:, :, None])[:, :, 0]
        n -= step
        if np.abs(step).max() <= 1e-15 * max(1.0, np.abs(n).max()):
            break
    return n


def _profile_design(n: np.ndarray) -> np.ndarray:
    """``(2N, 5)`` design of the radial-tangential profile (x rows, then y rows)."""
    x, y = n[:, 0], n[:, 1]
    r2 = x * x + y * y
    xs = np.column_stack([x * r2, x * r2**2, x * r2**3, 2 * x * y, r2 + 2 * x * x])
    ys = np.column_stack([y * r2, y * r2**2, y * r2**3, r2 + 2 * y * y, 2 * x * y])
    return np.vstack([xs, ys])


def _expected(dist) -> np.ndarray:
    """The camera's ``(k1, k2, k3, p1, p2)``."""
    c = np.zeros(8)
    if dist is not None:
        c[: len(dist)] = dist
    return np.array([c[0], c[1], c[4], c[2], c[3]])


def distortion_fault(cand: np.ndarray, orac: np.ndarray, camera, tol: float) -> dict | None:
    """``distortion_mismatch`` (a dict) when a lens error explains the candidate, else None.

    Parameters
    ----------
    cand, orac : (N, 2) ndarray of float64
        Pixels of the points both sides show (finite rows).
    camera : core.camera.Camera
        Perspective; its ``K`` and ``distortion`` are the truth.
    tol : float
        Pixels: the profile must reproduce the candidate to this, and differ
        from the camera's lens by more.
    """
    if camera.projection != "perspective" or len(cand) < 2 * len(_COEFFS):
        return None
    k = np.asarray(camera.K, dtype=np.float64)
    f = np.array([k[0, 0], k[1, 1]])
    c0 = np.array([k[0, 2], k[1, 2]])
    d_o = (orac - c0) / f
    d_c = (cand - c0) / f
    lens = getattr(camera, "distortion", None)
    n = undistort(d_o, lens) if lens is not None else d_o
    design = _profile_design(n)
    target = np.concatenate([d_c[:, 0] - n[:, 0], d_c[:, 1] - n[:, 1]])
    scale = np.abs(design).max(axis=0)
    if np.any(scale == 0):
        return None
    sol, _res, rank, _sv = np.linalg.lstsq(design / scale, target, rcond=None)
    if rank < len(_COEFFS):
        return None
    fitted = sol / scale
    model = design @ fitted
    resid_px = np.abs((model - target).reshape(2, -1).T * f)
    if resid_px.max() > tol:
        return None  # not (only) a lens error
    want = design @ _expected(lens)
    if np.abs((model - want).reshape(2, -1).T * f).max() <= tol:
        return None  # the candidate's lens is the camera's
    moved = np.abs(model.reshape(2, -1).T * f).max()
    k1_true = _expected(lens)[0]
    if lens is None:
        kind = "added"
    elif moved <= tol:
        kind = "ignored"
    elif k1_true != 0 and np.sign(fitted[0]) == -np.sign(k1_true):
        kind = "k1_sign"
    else:
        kind = "magnitude"
    # the error along the radius (pixels, outward positive): its largest size, signed
    r = np.hypot(n[:, 0], n[:, 1])
    err = (d_c - d_o) * f
    radial = np.where(r > 0, (err * n).sum(axis=1) / np.where(r > 0, r, 1.0), 0.0)
    worst = int(np.argmax(np.abs(radial)))
    return {
        "name": "distortion_mismatch",
        "kind": kind,
        **{name: float(v) for name, v in zip(_COEFFS, fitted)},
        "radial_error_px": float(radial[worst]),
        "at_radius_px": float(r[worst] * f[1]),
        "residual_px": float(resid_px.max()),
    }
