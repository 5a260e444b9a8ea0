"""An unprojector's faults, named by the mistake that reproduces its points.

Each fault is the exact inverse (oracles.references.unproject_reference.unproject) with one
classic mistake put in, its parameter (if any) fitted from the candidate's points
reprojected by the reference projection (OpenCV's ``projectPoints``; ``u', v'``):

    name                 the mistake                                       fitted
    pixel_offset         pixels moved by (dx, dy): cx = W / 2 for (W - 1) / 2   dx, dy = median(u' - u, v' - v)
    mirror_vertical      rows flipped: v -> H - 1 - v                       -
    mirror_horizontal    columns flipped: u -> W - 1 - u                    -
    fov_mismatch         focal length f / s (K from the horizontal FOV)     s = median((u' - cx) / (u - cx))
    depth_is_range       depth taken for distance along the ray            -
    rotation_transposed  R where R^T belongs: X = R (p_cv - t), or R p_cv + C   -
    distortion_mismatch  the lens's distortion not undone                  -

A fault explains the candidate when every point is within ``NAMING.unproject_fit_slack`` (oracles.tolerances) of its bound
of the mistaken inverse's point. Two names that both explain it (a view where rows flipped
is also a transposed rotation) are ``ambiguous``; none: ``unexplained``, with the median
pixel shift, scale and depth ratio measured. Every name is the fault catalogue's (oracles.faults:
its ``points`` source, hints included), and a named fault is a :class:`oracles.faults.Fault` read
from ``"points"``.
"""

from __future__ import annotations

import math

import numpy as np

from .. import faults as catalogue
from ..faults import Fault
from ..references.convert import opencv_matrices
from ..references.opencv_oracle import project as cv_project
from ..references.unproject_reference import cam_points, unproject
from ..tolerances import NAMING

__all__ = ["UNPROJECT_FAULTS", "name_unproject_faults"]

#: Every name this module gives: the catalogue's names read from an unprojector's points, in precedence order.
UNPROJECT_FAULTS = catalogue.names(source="points")


def name_unproject_faults(p_px, depth, camera, cand, bound) -> tuple[list, dict]:
    """``(faults, measured)`` for a candidate whose points ``cand`` ``(N, 3)`` missed their bounds: the
    faults a list of :class:`Fault` read from ``"points"`` (one: the mistake, ``ambiguous`` or ``unexplained``).

    ``p_px`` ``(N, 2)`` and ``depth`` ``(N,)`` are what it was given; ``bound`` ``(N,)`` world
    units (oracles.tolerances.unproject_bound).
    """
    p = np.asarray(p_px, dtype=np.float64).reshape(-1, 2)
    d = np.asarray(depth, dtype=np.float64).reshape(-1)
    x_c = np.asarray(cand, dtype=np.float64).reshape(-1, 3)
    bound = np.asarray(bound, dtype=np.float64).reshape(-1)
    measured = _measured(p, d, camera, x_c)
    fits = {}
    for name, params, x_hyp in _mistakes(p, d, camera, measured):
        with np.errstate(invalid="ignore"):
            ratio = float(np.max(np.linalg.norm(x_c - x_hyp, axis=1) / bound))
        if math.isfinite(ratio) and ratio < fits.get(name, (np.inf,))[0]:
            fits[name] = (ratio, params)
    measured["fit_ratios"] = {n: r for n, (r, _) in fits.items()}
    names = [n for n, (r, _) in sorted(fits.items(), key=lambda kv: kv[1][0]) if r <= NAMING.unproject_fit_slack]
    if len(names) > 1:
        return [Fault("ambiguous", {"alternatives": ", ".join(names)}, "points")], measured
    if names:
        return [Fault(names[0], fits[names[0]][1], "points")], measured
    return [Fault("unexplained", {}, "points")], measured


def _reproject(x_world, camera) -> np.ndarray:
    """``(N, 3)``: the points' pixels ``u', v'`` (OpenCV's projection, distortion included) and depth ``d'``."""
    r, t, _k = opencv_matrices(camera)
    d = x_world @ r[2] + t[2]
    finite = np.isfinite(x_world).all(axis=1)
    uv = np.full((len(x_world), 2), np.nan)
    if finite.any():
        uv[finite] = cv_project(x_world[finite], camera)  # NaN outside [near, far]
    return np.column_stack([uv, d])


def _measured(p, d, camera, x_c) -> dict:
    """The candidate's points read back: median pixel shift, scale about the principal point, depth ratio."""
    back = _reproject(x_c, camera)
    k = np.asarray(camera.K, dtype=np.float64)
    cx, cy = k[0, 2], k[1, 2]
    shift = back[:, :2] - p
    with np.errstate(invalid="ignore", divide="ignore"):
        far_x = np.abs(p[:, 0] - cx) > 1.0  # scale read where the point is off the centre
        far_y = np.abs(p[:, 1] - cy) > 1.0
        sx = (back[far_x, 0] - cx) / (p[far_x, 0] - cx)
        sy = (back[far_y, 1] - cy) / (p[far_y, 1] - cy)
        ratio = back[:, 2] / d
    med = lambda a: float(np.nanmedian(a)) if np.isfinite(a).any() else float("nan")  # noqa: E731
    return {
        "median_shift_px": [med(shift[:, 0]), med(shift[:, 1])],
        "median_scale": [med(sx), med(sy)],
        "median_depth_ratio": med(ratio),
    }


def _mistakes(p, d, camera, measured):
    """``(name, params, X (N, 3))`` of each mistaken inverse (module docstring)."""
    w, h = camera.width, camera.height
    r, t, k = opencv_matrices(camera)
    cx, cy = k[0, 2], k[1, 2]
    dx, dy = measured["median_shift_px"]
    if math.isfinite(dx) and math.isfinite(dy):
        yield "pixel_offset", {"dx": dx, "dy": dy}, unproject(p + [dx, dy], d, camera)
    yield "mirror_vertical", {}, unproject(np.column_stack([p[:, 0], h - 1 - p[:, 1]]), d, camera)
    yield "mirror_horizontal", {}, unproject(np.column_stack([w - 1 - p[:, 0], p[:, 1]]), d, camera)
    sx, sy = measured["median_scale"]
    perspective = camera.projection == "perspective"
    if perspective and math.isfinite(sx) and math.isfinite(sy) and sx + sy > 0:
        s = 0.5 * (sx + sy)
        implied = math.degrees(2.0 * math.atan((h / 2.0) / (k[1, 1] / s)))
        yield (
            "fov_mismatch",
            {"scale": s, "implied_fov_y_deg": implied},
            unproject(np.column_stack([cx + s * (p[:, 0] - cx), cy + s * (p[:, 1] - cy)]), d, camera),
        )
    p_cv = cam_points(p, d, camera)
    if perspective:
        rho = np.linalg.norm(p_cv, axis=1) / d
        yield "depth_is_range", {}, unproject(p, d / rho, camera)
    yield "rotation_transposed", {"form": "R (p_cv - t)"}, (p_cv - t) @ r.T
    yield "rotation_transposed", {"form": "R p_cv + C"}, p_cv @ r.T - t @ r
    if perspective and getattr(camera, "distortion", None) is not None:
        pinhole = np.stack([(p[:, 0] - cx) / k[0, 0] * d, (p[:, 1] - cy) / k[1, 1] * d, d], axis=1)
        yield "distortion_mismatch", {}, (pinhole - t) @ r
