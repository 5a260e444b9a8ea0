"""Measuring: core in both dtypes, OpenCV and pyrender against the long-double reference.

Every projector's pixels are compared with the reference point by point, each
against its own bound (oracles.extremes.bounds); pyrender's frame is scored by
edge-pixel F1.
"""

from __future__ import annotations

import numpy as np
from wirecheck.core.projector.pipeline import render_frame
from wirecheck.core.projector.projection import DTYPES, project_points

from ..judge import metrics
from ..references import opencv_oracle
from ..references.pyrender_oracle import OracleCache, osmesa_available
from .bounds import EPS, EPS64, camera_error, near_band, opencv_camera_error, pixel_bound
from .reference import LD, reference_project, reference_world


def err_px(a_px, ref_px) -> np.ndarray:
    """``(N,)`` Euclidean pixel distance, the difference taken in long double."""
    d = (np.asarray(a_px, LD) - np.asarray(ref_px, LD)).astype(np.float64)
    return np.hypot(d[:, 0], d[:, 1])


def stats(px, visible, ref_px, ref_visible, bound, band=None) -> dict:
    """Max error and the bound at that point, max error/bound, visibility mismatches.

    ``band``: ``(N,) bool``, points whose depth may round to the other side of
    near or far (:func:`bounds.near_band`): a visibility flip there is allowed.
    """
    both = visible & ref_visible
    flips = visible != ref_visible
    out = {
        "points": int(len(px)),
        "compared": int(both.sum()),
        "visible_mismatch": int(flips.sum()),
        "visible_mismatch_outside_band": int(flips.sum() if band is None else (flips & ~band).sum()),
        "max_error_px": None,
        "bound_px": None,
        "max_ratio": None,
    }
    if both.any():
        err = err_px(px[both], ref_px[both])
        b = bound[both]
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = np.where(err == 0, 0.0, err / b)
        ratio = np.where(np.isnan(ratio), np.inf, ratio)
        k = int(np.argmax(err))
        out.update(max_error_px=float(err[k]), bound_px=float(b[k]), max_ratio=float(ratio.max()))
    return out


def within(s: dict) -> bool:
    """Every compared point within its bound (or nothing compared)."""
    return s["max_ratio"] is None or s["max_ratio"] <= 1.0


def measure(p_model, model_matrix, camera, *, edges=None, model_err=0.0, a_ld=None, t_ld=None, frames=None) -> dict:
    """core in both dtypes, its world path and OpenCV against the long-double reference.

    Parameters
    ----------
    p_model : (N, 3) array_like
    model_matrix : (4, 4) array_like or None
    camera : core.camera.Camera
    edges : (E, 2) array_like of int, optional
    model_err : float
        Passed to :func:`bounds.camera_error`.
    a_ld, t_ld : long-double (3, 3), (3,), optional
        The exact model matrix, where the float64 one is not (Motion).
    frames : {dtype: Frame}, optional
        core's frames already rendered by the caller.

    Returns
    -------
    dict
        ``{"float64", "float32", "opencv", "pp_float64", "pp_float32": stats,
        "frames": {dtype: Frame}, "ref": (p_cam, p_px, visible), "p_world"}``.
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
        out[dt] = stats(frame.p_px, frame.visible, ref_px, ref_vis, bound, near_band(ref_cam, camera, e_cam, EPS[dt]))
        out["frames"][dt] = frame
    # OpenCV on the world points (rounded to float64 once: part of its input error)
    a = m[:3, :3] if a_ld is None else a_ld
    t = m[:3, 3] if t_ld is None else t_ld
    p_world = reference_world(p_model, a, t).astype(np.float64)
    cv_px = opencv_oracle.project(p_world, camera)
    e_cv = opencv_camera_error(p_world, camera)
    cv_bound = pixel_bound(ref_cam, ref_px, camera, e_cv, EPS64)
    out["opencv"] = stats(
        cv_px, ~np.isnan(cv_px[:, 0]), ref_px, ref_vis, cv_bound, near_band(ref_cam, camera, e_cv, EPS64)
    )
    # core's world path (project_points, crosscheck's candidate contract) on the same world points
    for dt in DTYPES:
        pp = project_points(p_world, camera, dt)
        e_w = camera_error(dt, p_world, None, camera, model_err)  # project_points: model-view path, A = I
        out["pp_" + dt] = stats(
            pp,
            ~np.isnan(pp[:, 0]),
            ref_px,
            ref_vis,
            pixel_bound(ref_cam, ref_px, camera, e_w, EPS[dt]),
            near_band(ref_cam, camera, e_w, EPS[dt]),
        )
    f64 = out["frames"]["float64"]
    both = f64.visible & ~np.isnan(cv_px[:, 0])
    out["float64"]["vs_opencv_px"] = float(err_px(f64.p_px[both], cv_px[both]).max()) if both.any() else None
    out["p_world"] = p_world
    return out


class Pyrender:
    """One PyrenderOracle per image size (pyrender_oracle.OracleCache), or a note saying why none."""

    def __init__(self, enabled: bool):
        self.oracles = OracleCache()
        self.gl = None
        self.note = None
        self.enabled = enabled
        if not enabled:
            self.note = "pyrender disabled (run_extremes(pyrender=False))"
            return
        ok, msg = osmesa_available()
        if not ok:
            self.enabled, self.note = False, f"pyrender unavailable: {msg}"

    def scores(self, frame_mask, vertices, edges, camera, model_matrix=None):
        """``(scores dict, note)``: F1 of core's frame against pyrender's; scores None when not run."""
        if not self.enabled:
            return None, self.note
        try:
            mask, _ = self.oracles.get(camera.width, camera.height).render(
                vertices, edges, camera, model_matrix=model_matrix
            )
        except Exception as exc:  # OSMesa may refuse a size: say so
            return None, f"pyrender failed: {type(exc).__name__}: {exc}"
        s = metrics.pixel_scores(frame_mask, mask)
        return {
            "f1_0px": s["f1_0px"],
            "f1_1px": s["f1_1px"],
            "core_pixels": s["candidate_pixels"],
            "pyrender_pixels": s["oracle_pixels"],
        }, None

    def close(self):
        """Release the GL contexts; :attr:`gl` keeps the GL that drew (None if nothing was drawn)."""
        self.gl = self.oracles.gl_info()
        self.oracles.close()
