"""A depth map's faults named from its values against the reference's linear depth.

Over the pixels where both maps show a surface, with ``r`` the reference's depth along
``forward`` (float64), ``c`` the candidate's and ``rho = |(x_n, y_n, 1)|`` the length of
the pixel's ray per unit of depth (``x_n = (x - cx) / fx``, ``y_n = (y - cy) / fy``;
1 under orthographic projection), each fault is a model ``c = g(r)``:

    name              model                                      fitted / reported
    depth_scale       c = k r                                    k = median(c / r)
    depth_offset      c = r + b                                  b = median(c - r)
    depth_is_range    c = rho r   (or c = r / rho: the reverse)  -
    depth_reversed    1/c = K - 1/r   (orthographic: c = S - r)  K = the camera's 1/near + 1/far (S = near + far); the median fitted K (S)
    depth_encoding    c = a + b / r   (orthographic: a + b r),   near and far that fit, window [0, 1]
                      c within [-1, 1]                           or NDC [-1, 1], reversed or not
    depth_precision   c = r to one float16 ulp (every c a        the step
                      float16), or to one quantisation step q
                      (the least gap between c's values)

A map **passes** when every compared pixel is within its allowance, ``bound + encoding``
(the reference's per-pixel bound and the candidate encoding's own resolution,
oracles.candidates.depth_map). A model **explains** a failing map when every compared
pixel's residual ``|c - g(r)|`` is within ``NAMING.depth_fit_slack`` (oracles.tolerances) allowances
carried through the model (``|g'(r)| bound + encoding``, plus the model's own step for
``depth_precision``). When none does and the reference's face ids are given, the camera
mistakes that move pixels rather than values are fitted (oracles.diagnosis.depth_pixels:
``mirror_vertical``, ``mirror_horizontal``, ``pixel_offset``, ``fov_mismatch``). Among the models that explain it the one with the fewest fitted
parameters is named, then the closest; when models of two names explain it (a flat surface
seen square-on: scale and offset alike), ``ambiguous`` with both; none: ``unexplained``,
with what was measured (``fit_ratios``: each model's worst residual over its allowance).
Zero pixels compared (a blank map, all NaN, no overlap) is ``vacuous``: never a pass.

Every name is the fault catalogue's (oracles.faults: its ``depth`` source, hints included), and a
named fault is a :class:`oracles.faults.Fault` read from ``"depth"``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .. import faults as catalogue
from ..faults import Fault
from ..tolerances import NAMING
from .depth_pixels import pixel_models, sample

__all__ = ["DEPTH_FAULTS", "DepthDiagnosis", "name_depth_faults", "ray_lengths"]


#: Every name this module gives: the catalogue's names read from depth maps, in precedence order.
DEPTH_FAULTS = catalogue.names(source="depth")


@dataclass(frozen=True)
class DepthDiagnosis:
    """The verdict on one depth map: ``"pass"``, ``"fail"`` or ``"vacuous"`` (nothing compared, never a pass),
    its ``faults`` (each a :class:`Fault` read from ``"depth"``: its hint is the depth map's) and what was measured."""

    verdict: str
    faults: tuple[Fault, ...] = ()
    measured: dict = field(default_factory=dict)

    @property
    def passed(self) -> bool:
        return self.verdict == "pass"

    @property
    def names(self) -> tuple:
        return tuple(f.name for f in self.faults)


def ray_lengths(camera) -> np.ndarray:
    """``(H, W)`` float64: ``rho = |(x_n, y_n, 1)|`` per pixel centre (1 everywhere under orthographic projection).

    Range along the pixel's ray is ``rho`` times depth along ``forward`` (pinhole rays: a
    lens's distortion is not undone).
    """
    w, h = int(camera.width), int(camera.height)
    if camera.projection != "perspective":
        return np.ones((h, w))
    k = np.asarray(camera.K, dtype=np.float64)
    x_n = (np.arange(w, dtype=np.float64) - k[0, 2]) / k[0, 0]
    y_n = (np.arange(h, dtype=np.float64) - k[1, 2]) / k[1, 1]
    return np.sqrt(1.0 + x_n[None, :] ** 2 + y_n[:, None] ** 2)


def name_depth_faults(candidate, reference, bound, camera, encoding=0.0, faces=None) -> DepthDiagnosis:
    """Judge a depth map against the reference and name what is wrong with it (module docstring).

    Parameters
    ----------
    candidate : (H, W) array_like of float
        The map to judge, depth along ``forward``; NaN, inf or 0 where no surface.
    reference : (H, W) array_like of float
        The reference's linear depth (float64), NaN, inf or 0 where no surface.
    bound : (H, W) array_like of float, or float
        The reference's per-pixel bound (oracles.judge.metrics.depth_bound).
    camera : core.camera.Camera
        The frame's camera (rays, near and far).
    encoding : (H, W) array_like of float, or float
        The candidate encoding's resolution (oracles.candidates.depth_map.DepthMap.encoding_bound).
    faces : (H, W) array_like of int, optional
        Which planar face the reference shows at each pixel (-1: none). Given, the camera
        mistakes that move pixels are fitted too (oracles.diagnosis.depth_pixels:
        mirror_vertical, mirror_horizontal, pixel_offset, fov_mismatch).

    Returns
    -------
    DepthDiagnosis
        ``measured`` holds ``compared_px``, ``candidate_px``, ``reference_px``, ``max_error``,
        ``max_error_ratio`` and ``worst_pixel`` (row, column) when anything was compared.
    """
    cand = np.asarray(candidate, dtype=np.float64)
    ref = np.asarray(reference, dtype=np.float64)
    with np.errstate(invalid="ignore"):
        cand_on = np.isfinite(cand) & (cand != 0)
        ref_on = np.isfinite(ref) & (ref > 0)
    both = cand_on & ref_on
    at = np.flatnonzero(both)  # the compared pixels, flat, in row order (as both's mask picks them)
    measured = {
        "compared_px": len(at),
        "candidate_px": int(np.count_nonzero(cand_on)),
        "reference_px": int(np.count_nonzero(ref_on)),
    }
    if not len(at):
        return DepthDiagnosis("vacuous", (), measured)
    full_b = np.broadcast_to(np.asarray(bound, dtype=np.float64), cand.shape)
    full_enc = np.broadcast_to(np.asarray(encoding, dtype=np.float64), cand.shape)
    c, r = _at(cand, at), _at(ref, at)
    b = _at(full_b, at)
    enc = _at(full_enc, at)
    err = np.abs(c - r)
    allow = b + enc
    ratio = _ratio(err, allow)
    worst = int(np.argmax(ratio))
    row, col = divmod(int(at[worst]), cand.shape[1])
    measured.update(max_error=float(err.max()), max_error_ratio=float(ratio[worst]), worst_pixel=[row, col])
    if ratio[worst] <= 1.0:
        return DepthDiagnosis("pass", (), measured)
    # a failing map's medians (what scale and offset would fit), measured only where they say something
    measured.update(median_ratio_c_over_r=float(np.median(c / r)), median_c_minus_r=float(np.median(c - r)))
    rho = ray_lengths(camera)[both]
    fits = []  # (parameters fitted, max residual / allowance, fault)
    for n_params, model in _models(c, r, rho, b, enc, camera):
        if model is None:
            continue
        name, params, c_hat, slope, extra = model
        fit = float(_ratio(np.abs(c - c_hat), np.abs(slope) * b + enc + extra).max())
        if np.isfinite(fit):
            fits.append((n_params, fit, name, params))
    if faces is not None and not any(f[1] <= NAMING.depth_fit_slack for f in fits):
        # no value model explains it: the maps that move pixels (tried only then: they cost a fit each)
        fits += _pixel_fits(
            np.where(cand_on, cand, np.nan), np.where(ref_on, ref, np.nan), np.asarray(faces), full_b, full_enc, camera
        )
    measured["fit_ratios"] = {}
    for _, fit, name, _ in fits:  # each model's worst residual / allowance (the best of a name's)
        measured["fit_ratios"][name] = min(fit, measured["fit_ratios"].get(name, np.inf))
    explained = sorted((f for f in fits if f[1] <= NAMING.depth_fit_slack), key=lambda f: (f[0], f[1]))
    names = list(dict.fromkeys(f[2] for f in explained))
    if len(names) > 1:
        # the compared depths do not separate the models (one flat surface square-on: scale and offset alike)
        return DepthDiagnosis("fail", (Fault("ambiguous", {"alternatives": ", ".join(names)}, "depth"),), measured)
    if explained:
        _, fit, name, params = explained[0]
        measured["fit_ratio"] = fit
        return DepthDiagnosis("fail", (Fault(name, params, "depth"),), measured)
    return DepthDiagnosis("fail", (Fault("unexplained", {}, "depth"),), measured)


def _pixel_fits(cand, ref, faces, bound, enc, camera) -> list:
    """``(n_params, fit ratio, name, params)`` of each pixel map that keeps the surfaces on each other."""
    out = []
    pts = np.argwhere(np.isfinite(cand))[:, ::-1].astype(np.float64)
    c = cand[pts[:, 1].astype(int), pts[:, 0].astype(int)]
    h, w = ref.shape
    for name, n_params, params, transform in pixel_models(cand, ref, faces, camera):
        q = transform(pts)
        depth, inside, outside, _grad = sample(ref, faces, camera, q)
        if outside.mean() > NAMING.depth_outside_max or inside.mean() < NAMING.depth_interior_min:
            continue
        qi = np.clip(np.rint(q[inside]).astype(np.int64), 0, [w - 1, h - 1])
        allow = bound[qi[:, 1], qi[:, 0]] + enc[pts[inside, 1].astype(int), pts[inside, 0].astype(int)]
        fit = float(_ratio(np.abs(c[inside] - depth[inside]), allow).max())
        if np.isfinite(fit):
            out.append((n_params, fit, name, params))
    return out


def _at(image: np.ndarray, flat: np.ndarray) -> np.ndarray:
    """``image`` (H, W) at the flat positions ``flat``: ``image.ravel()[flat]`` without copying a broadcast one."""
    if image.strides == (0, 0):  # one value broadcast (a scalar bound or encoding step)
        return np.full(len(flat), image[0, 0]) if image.size else np.zeros(0)
    return image.reshape(-1)[flat]


def _ratio(err: np.ndarray, allow: np.ndarray) -> np.ndarray:
    """``err / allow``, 0 where both are 0 and inf where only the allowance is."""
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(err == 0, 0.0, err / allow)


def _models(c, r, rho, b, enc, camera):
    """``(parameters fitted, model or None)`` for each fault of the module's table.

    A model is ``(name, params, c_hat, |g'(r)|, extra allowance)``.
    """
    perspective = camera.projection == "perspective"
    near, far = float(camera.near), float(camera.far)
    zero = np.zeros_like(c)
    # depth_is_range: rays alone, nothing fitted (orthographic rays are all depth)
    if perspective:
        up = np.abs(c - rho * r).max() <= np.abs(c - r / rho).max()
        yield (
            0,
            (
                "depth_is_range",
                {"stored": "range along the ray" if up else "depth / ray length"},
                rho * r if up else r / rho,
                rho if up else 1.0 / rho,
                zero,
            ),
        )
    # depth_precision: float16 values, or one quantisation step
    yield 0, _precision(c, r)
    yield 0, _quantised(c, r)
    k = float(np.median(c / r))
    yield 1, ("depth_scale", {"k": k}, k * r, np.full_like(r, k), zero)
    off = float(np.median(c - r))
    yield 1, ("depth_offset", {"b": off, "b_over_near": off / near}, r + off, np.ones_like(r), zero)
    # depth_reversed: reversed-Z read back by the standard formula swaps the camera's own near and far, so
    # the model is the camera's (nothing fitted): 1/c = (1/near + 1/far) - 1/r (orthographic c = near + far
    # - r). The median sum is reported beside it. A free sum would fit other maps by chance: a pyramid seen
    # head-on with its rows flipped fits 1/c + 1/r = 0.43 (the camera's 5.83) to 0.07 allowances
    if perspective:
        k_cam = 1.0 / near + 1.0 / far
        with np.errstate(divide="ignore", invalid="ignore"):
            kk = float(np.median(1.0 / c + 1.0 / r))
            c_hat = 1.0 / (k_cam - 1.0 / r)
        yield 0, ("depth_reversed", {"sum_of_inverses": kk, "camera_1/near+1/far": k_cam}, c_hat, c_hat**2 / r**2, zero)
    else:
        s = float(np.median(c + r))
        yield 0, ("depth_reversed", {"sum": s, "camera_near+far": near + far}, near + far - r, np.ones_like(r), zero)
    yield 2, _encoding(c, r, camera)


def _precision(c, r):
    """float16 storage: every value a float16, each within one float16 ulp of the reference."""
    with np.errstate(over="ignore"):
        c16 = c.astype(np.float16)
    if not (np.isfinite(c16).all() and (c16.astype(np.float64) == c).all()):
        return None
    ulp = np.spacing(np.abs(r).astype(np.float16)).astype(np.float64)
    return (
        "depth_precision",
        {"format": "float16", "step_at_median_depth": float(np.median(ulp))},
        r,
        np.ones_like(r),
        ulp,
    )


def _quantised(c, r):
    """A uniform quantisation: values on a grid of a least gap ``q``, each within ``q`` of the reference."""
    levels = np.unique(c)
    if len(levels) < 2:
        return None
    gaps = np.diff(levels)
    q = float(gaps.min())
    units = gaps / q
    if np.abs(units - np.round(units)).max() > NAMING.depth_step_tolerance:
        return None
    return (
        "depth_precision",
        {"format": "quantised", "step": q, "levels": int(len(levels))},
        r,
        np.ones_like(r),
        np.full_like(r, q),
    )


def _encoding(c, r, camera):
    """A stored depth-buffer value: ``c = a + b x`` with ``x = 1/r`` (perspective) or ``r``; near and far read back."""
    lo, hi = float(c.min()), float(c.max())
    if lo < -1.0 - NAMING.depth_encoding_margin or hi > 1.0 + NAMING.depth_encoding_margin:
        return None
    perspective = camera.projection == "perspective"
    x = 1.0 / r if perspective else r
    xm, cm = float(x.mean()), float(c.mean())
    sxx = float(((x - xm) ** 2).sum())
    if sxx == 0.0:
        return None
    slope = float(((x - xm) * (c - cm)).sum()) / sxx
    a = cm - slope * xm
    # window z: c(n) = 0, c(f) = 1; NDC: c(n) = -1, c(f) = 1; reversed: the two ends exchanged
    reversed_z = (slope > 0) if perspective else (slope < 0)
    at_near, at_far = (1.0, 0.0) if reversed_z else (0.0, 1.0)
    candidates = {"window [0, 1]": (at_near, at_far)}
    if not reversed_z:
        candidates["NDC [-1, 1]"] = (-1.0, 1.0)
    best = None
    for kind, (v_near, v_far) in candidates.items():
        with np.errstate(divide="ignore", invalid="ignore"):
            if perspective:  # v = a + slope / d  ->  d = slope / (v - a)
                n_fit, f_fit = slope / (v_near - a), slope / (v_far - a)
            else:  # v = a + slope d    ->  d = (v - a) / slope
                n_fit, f_fit = (v_near - a) / slope, (v_far - a) / slope
        miss = (
            abs(np.log(abs(n_fit) / camera.near)) + abs(np.log(abs(f_fit) / camera.far))
            if n_fit and f_fit and np.isfinite(n_fit) and np.isfinite(f_fit)
            else np.inf
        )
        if best is None or miss < best[0]:
            best = (miss, kind, float(n_fit), float(f_fit))
    _, kind, n_fit, f_fit = best
    c_hat = a + slope * x
    d_slope = np.abs(slope) / r**2 if perspective else np.full_like(r, abs(slope))
    params = {"stored": kind, "reversed": bool(reversed_z), "near": n_fit, "far": f_fit}
    return "depth_encoding", params, c_hat, d_slope, np.zeros_like(r)
