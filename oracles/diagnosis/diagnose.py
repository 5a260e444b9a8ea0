"""Name what is wrong with a candidate projector, from its pixels and an oracle's.

``diagnose(cand_px, oracle_px, camera, tol_px=1e-6, float32_px=None) -> list[dict]``

Both inputs are ``(N, 2)`` pixel coordinates of the *same* world points (pooled
over all frames of a case), with a non-finite row (NaN, in practice) where that
projector clipped the point. A row with any non-finite coordinate counts as
clipped. The answer is ``[]`` when the candidate agrees: the same points are
visible to both, and on those the largest coordinate error is ``<= tol_px``.
Otherwise it is a list of faults, the *primary* fault first (in the order of
precedence of the catalogue, oracles.faults), each a dict with ``"name"`` and fields.

Method
======
1. **Visibility.** ``vis_c``/``vis_o`` = rows finite in the candidate/oracle.
   If both see something between them and they have (nearly) no visible point
   in common -- at most ``NAMING.depth_flip_max_overlap`` of the union -- the candidate
   looks backward: ``depth_flip``, and nothing else is reported (there is
   nothing to fit). This includes "the candidate clips everything the oracle
   shows" (a camera flipped away from a scene that lies wholly in front).
2. **Affine fit.** On points visible to both, in coordinates centred on the
   camera's principal point (``u = x - cx, v = y - cy``, ``cx = (W-1)/2``,
   ``cy = (H-1)/2``), fit ``cand_c = A @ oracle_c + b`` by least squares.
3. **Named model.** Snap ``A`` to the nearest signed axis permutation ``P``
   (diagonal if ``|A00|+|A11| >= |A01|+|A10|``, else anti-diagonal; the signs
   of the dominant entries), then refit each candidate axis separately:
   ``cand_i = d_i * (P @ oracle_c)_i + b_i``. If that model (per-axis positive
   scale + offset after a signed permutation) reproduces the candidate to
   ``tol_px`` everywhere, the faults are read off ``P``, ``d`` and ``b``;
   otherwise the map is a rotation, a shear, or not affine at all (a 3D error:
   transposed rotation, wrong rotation order, roll...), and the answer is a
   single ``unexplained``.
4. **Significance.** A parameter is reported only when its effect on some
   pixel exceeds ``tol_px``: ``|d_i - 1| * max|q_i| > tol_px`` for a scale,
   ``|b_i - expected_i| > tol_px`` for an offset, ``|d_x - d_y| * max|q_x| >
   tol_px`` for an aspect. So ``tol_px`` is the one knob: anything whose pixel
   effect is below it counts as agreement, and there is no separate tolerance
   on the entries of ``A`` (it would have to be ``tol_px / image extent``
   anyway, which is what the pixel-effect test is). The snap to ``P`` is a
   discrete choice, and a wrong snap cannot pass step 3's residual test.
   A disagreement above ``tol_px`` that leaves no named parameter significant
   is reported as ``unexplained`` (never ``[]``).

Faults
======
==================  ==========================================  ===================================
name                recognised by                               fields
==================  ==========================================  ===================================
depth_flip          visible sets (nearly) disjoint: the         oracle_visible, candidate_visible,
                    candidate shows what the oracle clips and   common_visible
                    clips what it shows
clipping_plane      the visible sets differ and the candidate's kind ("z_positive", "float32_near",
                    own planes, probed (``planes``,            "float32_far", "near", "far", "none",
                    oracles.diagnosis.clip_planes), are not the camera's  "swapped"), near_fit, far_fit, near, far
axis_swap           ``P`` anti-diagonal (x and y exchanged)     --
mirror_horizontal   ``P = diag(-1, 1)`` (after any swap)        --
mirror_vertical     ``P = diag(1, -1)`` (after any swap)        --
axis_flip           ``P = diag(-1, -1)``: turned 180 deg        --
aspect_mismatch     ``d_x != d_y``                              implied_aspect, scale_x, scale_y
fov_mismatch        ``d_y != 1`` (alone when ``d_x = d_y``,     scale, implied_fov_deg (None for
                    else with aspect_mismatch)                  ortho), implied_ortho_height (None
                                                                for perspective)
pixel_offset        ``b`` minus the shift the named linear      dx, dy
                    faults imply, nonzero
distortion_mismatch the named model fails, and OpenCV's radial-  kind ("added", "ignored", "k1_sign",
                    tangential profile on the camera's K        "magnitude"), k1, k2, k3, p1, p2
                    explains the candidate: a lens error        (the candidate's), radial_error_px,
                    (oracles.diagnosis.lens_diagnose)                     at_radius_px, residual_px
line_end_bias       (pixels; vertices agree) one-sided pixels   end ("first", "last", "both"),
                    fail the line gate and sit at line ends     pixels_per_line (signed), lines,
                    (:func:`diagnose_lines`)                    candidate_only, oracle_only
line_pixel_bias     (pixels; vertices agree) as above, but not  candidate_only, oracle_only,
                    at the ends: thicker/thinner lines, strays  net_start, net_end, net_middle,
                                                                net_stray
precision_limited   (a candidate judged at float64) the         residual_px, float64_bound_px,
                    disagreement is float32 rounding: the       float32_bound_px
                    diagnosis at the float32 bound explains
                    it (see "Precision" below); or the fitted  (kind "float32_constants": scale_x,
                    scales and offset are float32 rounding of   scale_y, dx, dy)
                    the constants (:func:`rounded_constants`)
unexplained         the named model does not fit (rotation,     residual_px (max), residual_rms_px,
                    shear, not affine); or the visible sets     affine_residual_px, affine, offset,
                    differ without a depth flip; or too few     rotation_deg, visibility_mismatches,
                    common points to fit                        common_visible, underdetermined
==================  ==========================================  ===================================

Precision
---------
``tol_px`` is the caller's bound for the candidate's precision
(oracles.tolerances.vertex_bound: 1e-6 px for float64, ~1e-3 px for a
float32 candidate on the bundled cases), so steps 3 and 4 fit *through* the
candidate's rounding noise: a float32 projector with a mirror and a half-pixel
offset is named ``mirror_vertical`` + ``pixel_offset``, not ``unexplained``.
A candidate judged at float64 whose error is float32 rounding is told so: with
``float32_px`` (the float32 bound of the same points) given, the diagnosis is
run again at ``float32_px`` when the float64 one leaves noise (its named model
misses by more than ``tol_px``); when the float32 one names no
``unexplained`` (nor a depth flip) and its named model leaves at most
``float32_px`` (a lens error leaves more), the answer is its faults plus
``precision_limited`` (the residual left by them and both bounds). A float64
mirror, or a genuine 1e-4 px offset, fitted to 1e-13 px stays a plain
``mirror_vertical`` or ``pixel_offset``: rounding leaves noise, a fault does not.

Details and decisions
---------------------
* **Combinations.** Several named faults may come together (``fov_mismatch`` +
  ``pixel_offset``; ``axis_swap`` + ``mirror_horizontal`` is a 90 deg turn).
  Mirrors are named in the *candidate's* image axes, i.e. applied after the swap:
  ``cand = M @ S @ oracle``.
* **Expected shifts.** The mirrors and the flip of a candidate that mirrors
  whole pixel coordinates (``x -> (W-1) - x``) are pure sign changes in centred
  coordinates: no shift. A raw swap ``(x, y) -> (y, x)`` is ``u' = v + (cy-cx)``,
  ``v' = u + (cx-cy)``: on a non-square image it shifts by ``cx - cy`` per axis.
  A swap candidate might also centre with the other image size, or mirror with
  ``W-1`` or ``H-1`` after swapping, so for a swap each axis may legitimately
  shift by ``0`` or ``+-(cx - cy)``; the nearest of these is taken as expected
  and only the rest is a ``pixel_offset``. (A genuine offset equal to
  ``+-(cx-cy)`` on top of a swap is therefore not reported; on a square image
  ``cx = cy`` and nothing is forgiven.)
* **FOV.** ``d_y = f_cand / f`` is the candidate's vertical focal length over the
  true one, so ``implied_fov_deg = 2 atan(tan(fov_y / 2) / d_y)``: the vertical
  FOV (edge to edge, as in core.conventions) that the candidate effectively used.
* **Aspect.** A GL-style candidate computes ``f_x = (W/2) / (a tan(fov_y/2))``
  with its own aspect ``a``; so ``implied_aspect = (W/H) * d_y / d_x``. The right
  answer is ``W/H``; a candidate that took ``f_x`` from the width
  (``(W/2)/tan(fov/2)``) implicitly used ``a = 1``.
* **Orthographic.** A wrong ortho scale is the orthographic analogue of a wrong
  FOV and is named ``fov_mismatch`` too, with ``implied_ortho_height =
  ortho_height / d_y`` (and ``implied_fov_deg = None``). The aspect formula is
  the same (ortho width = ``a * ortho_height``).
* **Degenerate inputs.** ``N = 0``, or both projectors clipping everything, is
  agreement (``[]``). With fewer than 3 non-collinear common points (see
  ``NAMING.degenerate_ratio``) no linear map can be fitted; only a constant offset is
  tried (``pixel_offset`` if it explains the points), else ``unexplained`` with
  ``underdetermined = True``.
* **rotation_deg** (in ``unexplained``) is the rotation part of ``A``,
  ``atan2(A10 - A01, A00 + A11)``, in pixel axes (y down): a camera rolled by
  +r about its forward axis shows as -r. With ``affine_residual_px <= tol_px``
  the error is a pure image-plane map (a roll, a shear); otherwise it is a 3D
  error (transposed rotation, rotation order, wrong position).
* **Invisible faults.** A fault that does not change the pixels (a transposed
  rotation on a camera whose rotation is symmetric, e.g. on the Z axis) cannot
  be diagnosed and gives ``[]``.
"""

from __future__ import annotations

import math

import numpy as np

from .. import faults as catalogue
from ..tolerances import EPS, NAMING, line_failures
from .clip_planes import clip_fault
from .lens_diagnose import distortion_fault

__all__ = ["diagnose", "diagnose_lines", "line_pixel_fields", "primary"]


def _sign(x: float) -> int:
    return -1 if x < 0 else 1


def _max_abs(a: np.ndarray) -> float:
    return float(np.max(np.abs(a))) if a.size else 0.0


def primary(faults: list[dict]) -> str:
    """The primary fault's name, or ``"none"`` for an empty diagnosis."""
    return faults[0]["name"] if faults else "none"


def _sorted(faults: list[dict]) -> list[dict]:
    return catalogue.ordered(faults)


def _fit_affine(o: np.ndarray, c: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Least squares ``c = o @ A.T + b``; ``o`` normalised for conditioning."""
    r = _max_abs(o) or 1.0
    design = np.column_stack([o / r, np.ones(len(o))])
    x, *_ = np.linalg.lstsq(design, c, rcond=None)
    return x[:2].T / r, x[2]


def _fit_axis(q: np.ndarray, c: np.ndarray) -> tuple[float, float]:
    """Least squares ``c = d * q + b`` for one axis."""
    r = _max_abs(q) or 1.0
    design = np.column_stack([q / r, np.ones(len(q))])
    x, *_ = np.linalg.lstsq(design, c, rcond=None)
    return float(x[0] / r), float(x[1])


def _unexplained(**fields) -> dict:
    return {"name": "unexplained", **fields}


def scale_faults(sx: float, sy: float, reach, tol: float, camera, **fields) -> list[dict]:
    """``aspect_mismatch`` and ``fov_mismatch`` from the fitted scales ``sx, sy`` of the pixel axes.

    A scale is named when it moves the farthest point of its axis (``reach``,
    pixels from the principal point) by more than ``tol`` pixels; the implied
    aspect, FOV (perspective) or ortho height is what the candidate used.
    ``fields`` are added to each fault (the image diagnosis' confidence).
    """
    faults = []
    w, h = camera.width, camera.height
    minus_one = {"x": (w - 1) / w, "y": (h - 1) / h}
    if abs(sx - sy) * reach[0] > tol:
        fault = {"name": "aspect_mismatch", **fields, "implied_aspect": (w / h) * sy / sx, "scale_x": sx, "scale_y": sy}
        if (
            abs(sx - minus_one["x"]) * reach[0] <= tol
            or abs(sx / sy - minus_one["x"]) * reach[0] <= tol
            or abs(sy / sx - minus_one["y"]) * reach[1] <= tol
        ):
            fault["hint"] = catalogue.hint_text("aspect_mismatch", "minus_one")
        elif abs(sx / sy - (w / h) ** 2) * reach[0] <= tol:
            fault["hint"] = catalogue.hint_text("aspect_mismatch", "inverted")
        elif abs(sx / sy - w / h) * reach[0] <= tol or abs(sx / sy - h / w) * reach[0] <= tol:
            fault["hint"] = catalogue.hint_text("aspect_mismatch", "width")
        faults.append(fault)
    if abs(sy - 1.0) * reach[1] > tol:
        fault = {"name": "fov_mismatch", **fields, "scale": sy, "implied_fov_deg": None, "implied_ortho_height": None}
        if abs(sy - w / h) * reach[1] <= tol or abs(sy - h / w) * reach[1] <= tol:
            fault["hint"] = catalogue.hint_text("fov_mismatch", "horizontal_fov")
        elif abs(sy - minus_one["y"]) * reach[1] <= tol:
            fault["hint"] = catalogue.hint_text("fov_mismatch", "minus_one")
        if camera.projection == "perspective":
            half = math.tan(math.radians(camera.fov_y_deg) / 2.0)
            fault["implied_fov_deg"] = math.degrees(2.0 * math.atan(half / sy))
        else:
            fault["implied_ortho_height"] = camera.ortho_height / sy
        faults.append(fault)
    return faults


def diagnose(
    cand_px, oracle_px, camera, tol_px: float = 1e-6, float32_px: float | None = None, planes: dict | None = None
) -> list[dict]:
    """Name the faults of a candidate projector; ``[]`` when it agrees.

    With ``float32_px`` (the float32 rounding bound of these points,
    oracles.tolerances.vertex_bound; given for a candidate judged at float64)
    a disagreement at ``tol_px`` that the same diagnosis at ``float32_px``
    explains is named ``precision_limited`` (module docstring). With
    ``planes`` (oracles.diagnosis.clip_planes.probe_planes: the candidate's own near and
    far, probed) a visible set that differs is named ``clipping_plane``.

    Parameters
    ----------
    cand_px, oracle_px : (N, 2) array_like
        Pixels of the same world points from the candidate and the oracle,
        non-finite rows where that projector clipped the point.
    camera : core.camera.Camera
        The camera both were asked to use (for ``cx, cy``, the FOV or ortho
        height, and the aspect).
    tol_px : float
        Agreement tolerance in pixels; a fault whose largest pixel effect is
        below it is not reported.

    Returns
    -------
    list of dict, primary fault first; see the module docstring.
    """
    return [_advised(f, tol_px) for f in _diagnose(cand_px, oracle_px, camera, tol_px, float32_px, planes)]


def _advised(fault: dict, tol_px: float) -> dict:
    """An ``unexplained`` whose pixels agree to ``tol_px`` gets the visibility advice (its ``hint``)."""
    if fault["name"] != "unexplained" or not fault.get("residual_px", 0.0) <= tol_px:
        return fault
    a, b = fault.get("candidate_only", 0), fault.get("oracle_only", 0)
    return {
        **fault,
        "hint": catalogue.hint_text(
            "unexplained", "visible_sets", residual=fault["residual_px"], tol=tol_px, candidate_only=a, oracle_only=b
        ),
    }


def _diagnose(cand_px, oracle_px, camera, tol_px, float32_px, planes) -> list[dict]:
    fine: dict = {}
    faults = _diagnose_at(cand_px, oracle_px, camera, tol_px, fine, planes)
    if not faults or float32_px is None or not float32_px > tol_px:
        return faults
    if fine.get("residual_px", 0.0) <= tol_px:
        # a named model fits to float64 accuracy: no rounding noise; but its scales and offset may be
        # the rounding of a float32 constant (a float32 K or GL matrix in a float64 projector)
        return rounded_constants(faults, camera, fine, tol_px, float32_px)
    coarse_info: dict = {}
    coarse = _diagnose_at(cand_px, oracle_px, camera, float32_px, coarse_info, planes)
    if any(f["name"] in ("unexplained", "depth_flip") for f in coarse) or coarse_info["residual_px"] > float32_px:
        return faults  # float32 rounding does not explain it either (e.g. a lens bends the map)
    return _sorted(
        coarse
        + [
            {
                "name": "precision_limited",
                "residual_px": coarse_info["residual_px"],
                "float64_bound_px": float(tol_px),
                "float32_bound_px": float(float32_px),
            }
        ]
    )


#: The named faults a float32 constant can fake (mirrors and swaps are exact in any precision).
_ROUNDABLE = catalogue.names("scale", "offset")


def rounded_constants(faults: list[dict], camera, info: dict, tol_px: float, float32_px: float) -> list[dict]:
    """``faults`` with scale and offset faults replaced by ``precision_limited`` when the fitted map's
    deviation from identity is within float32 rounding of the case's constants.

    Scales within ``NAMING.constant_roundings`` eps32 of 1 and an offset within
    ``NAMING.constant_roundings`` eps32 x (the farthest pixel from the principal
    point) are the rounding of a float32 K, aspect or matrix (``fov_mismatch(scale=1.00000001)``,
    ``aspect_mismatch(implied_aspect=1.3333334)``, ``pixel_offset(dx=-6.1e-06)``); a genuine 1e-4 px
    offset on a 640-px image is above its 7.6e-5 px and stays named.
    """
    named = [f for f in faults if f["name"] in _ROUNDABLE]
    if not named or any(f["name"] in ("unexplained", "depth_flip", "clipping_plane") for f in faults):
        return faults
    eps = NAMING.constant_roundings * EPS["float32"]
    d = info.get("scale")
    if d is None:
        return faults
    shift = [f for f in faults if f["name"] == "pixel_offset"]
    off = np.array([shift[0]["dx"], shift[0]["dy"]]) if shift else np.zeros(2)
    cx, cy = camera.principal_point
    reach = max(cx, cy, camera.width - 1 - cx, camera.height - 1 - cy)
    if np.max(np.abs(d - 1.0)) > eps or np.max(np.abs(off)) > eps * reach:
        return faults
    kept = [f for f in faults if f["name"] not in _ROUNDABLE]
    return _sorted(
        kept
        + [
            {
                "name": "precision_limited",
                "kind": "float32_constants",
                "residual_px": float(info["residual_px"]),
                "scale_x": float(d[0]),
                "scale_y": float(d[1]),
                "dx": float(off[0]),
                "dy": float(off[1]),
                "float64_bound_px": float(tol_px),
                "float32_bound_px": float(float32_px),
            }
        ]
    )


def _diagnose_at(
    cand_px, oracle_px, camera, tol_px: float, info: dict | None = None, planes: dict | None = None
) -> list[dict]:
    """:func:`diagnose` at one tolerance; ``info["residual_px"]``: the named model's largest residual,
    ``info["scale"]``, ``info["offset"]``, ``info["reach"]``: the named model's per-axis fit."""
    info = {} if info is None else info
    cand = np.asarray(cand_px, dtype=np.float64)
    orac = np.asarray(oracle_px, dtype=np.float64)
    if cand.size == 0 and orac.size == 0:
        return []
    cand = cand.reshape(-1, 2) if cand.ndim != 2 else cand
    orac = orac.reshape(-1, 2) if orac.ndim != 2 else orac
    if cand.shape != orac.shape or cand.shape[1] != 2:
        raise ValueError(f"diagnose: expected two (N, 2) arrays of the same N, got {cand.shape} and {orac.shape}")
    tol = float(tol_px)
    if not tol >= 0:
        raise ValueError(f"diagnose: tol_px {tol_px!r}: expected >= 0")

    vis_c = np.isfinite(cand).all(axis=1)
    vis_o = np.isfinite(orac).all(axis=1)
    both = vis_c & vis_o
    n_both, n_union = int(both.sum()), int((vis_c | vis_o).sum())
    mismatches = int((vis_c != vis_o).sum())
    if n_union == 0:
        return []  # N = 0 or both clip everything
    info["residual_px"] = _max_abs(cand[both] - orac[both])
    if mismatches == 0 and info["residual_px"] <= tol:
        return []

    clip = clip_fault(planes, camera) if mismatches else None
    if clip is not None and clip["kind"] == "swapped":
        return [clip]  # keeps nothing, in front or behind: not a flip
    # 1. depth flip: visible sets (nearly) swapped
    if mismatches and n_both <= NAMING.depth_flip_max_overlap * n_union:
        return [
            {
                "name": "depth_flip",
                "oracle_visible": int(vis_o.sum()),
                "candidate_visible": int(vis_c.sum()),
                "common_visible": n_both,
            }
        ]

    vis_fields = {
        "visibility_mismatches": mismatches,
        "common_visible": n_both,
        "candidate_only": int((vis_c & ~vis_o).sum()),
        "oracle_only": int((vis_o & ~vis_c).sum()),
    }
    cx, cy = camera.principal_point
    centre = np.array([cx, cy])
    o = orac[both] - centre
    c = cand[both] - centre

    # degenerate: fewer than 3 non-collinear common points -> offset only
    spread = o - o.mean(axis=0) if n_both else o
    sv = np.linalg.svd(spread, compute_uv=False) if n_both >= 2 else np.zeros(2)
    if n_both < 3 or sv[0] == 0 or sv[-1] < NAMING.degenerate_ratio * sv[0]:
        faults = []
        if n_both:
            off = (c - o).mean(axis=0)
            resid = c - o - off
            info["residual_px"] = _max_abs(resid)
            if _max_abs(resid) <= tol:
                if _max_abs(off) > tol:
                    faults.append({"name": "pixel_offset", "dx": float(off[0]), "dy": float(off[1])})
                if clip is not None:
                    faults.append(clip)
                elif mismatches:
                    faults.append(
                        _unexplained(residual_px=0.0, residual_rms_px=0.0, **vis_fields, underdetermined=True)
                    )
                return _sorted(faults)
            res = c - o
        else:
            res = np.zeros((0, 2))
        return [
            _unexplained(
                residual_px=_max_abs(res),
                residual_rms_px=float(np.sqrt(np.mean(res**2))) if res.size else 0.0,
                **vis_fields,
                underdetermined=True,
            )
        ]

    # 2. affine fit
    a, b = _fit_affine(o, c)
    affine_res = c - (o @ a.T + b)
    diag_weight = abs(a[0, 0]) + abs(a[1, 1])
    swap = abs(a[0, 1]) + abs(a[1, 0]) > diag_weight
    if swap:
        signs = (_sign(a[0, 1]), _sign(a[1, 0]))
        q = o[:, ::-1] * signs
    else:
        signs = (_sign(a[0, 0]), _sign(a[1, 1]))
        q = o * signs

    # 3. named model: per-axis positive scale + offset after the signed permutation
    d = np.empty(2)
    off = np.empty(2)
    for i in range(2):
        d[i], off[i] = _fit_axis(q[:, i], c[:, i])
    named_res = c - (q * d + off)
    reach = np.max(np.abs(q), axis=0)  # largest |coordinate| per candidate axis
    named_max = info["residual_px"] = _max_abs(named_res)
    info.update(scale=d.copy(), offset=off.copy(), reach=np.max(np.abs(q), axis=0))
    collapsed = bool(np.any(d * reach <= tol))  # an axis the candidate squashed flat
    if named_max > tol or collapsed:
        lens = None if mismatches or collapsed else distortion_fault(cand[both], orac[both], camera, tol)
        if lens is not None:
            return [lens]
        rot = math.degrees(math.atan2(a[1, 0] - a[0, 1], a[0, 0] + a[1, 1]))
        return [
            _unexplained(
                residual_px=named_max,
                residual_rms_px=float(np.sqrt(np.mean(named_res**2))),
                affine_residual_px=_max_abs(affine_res),
                affine=a.tolist(),
                offset=b.tolist(),
                rotation_deg=rot,
                **vis_fields,
                underdetermined=False,
            )
        ]

    # 4. read the faults off P, d, b
    faults: list[dict] = []
    if swap:
        faults.append({"name": "axis_swap"})
    mirror = {(-1, 1): "mirror_horizontal", (1, -1): "mirror_vertical", (-1, -1): "axis_flip"}.get(signs)
    if mirror:
        faults.append({"name": mirror})
    faults += scale_faults(float(d[0]), float(d[1]), reach, tol, camera)
    expected = np.zeros(2)
    if swap:
        shift = cx - cy  # a raw swap moves each axis by +-(cx - cy)
        allowed = np.array([-shift, 0.0, shift])
        expected = np.array([allowed[np.argmin(np.abs(allowed - off[i]))] for i in range(2)])
    residual_offset = off - expected
    if _max_abs(residual_offset) > tol:
        faults.append({"name": "pixel_offset", "dx": float(residual_offset[0]), "dy": float(residual_offset[1])})
    if clip is not None:
        faults.append(clip)  # the visible sets differ where the probed planes say
    elif mismatches or not faults:
        # visible sets differ without a depth flip (near/far?), or an error too
        # small to name: still a disagreement, so say so
        faults.append(
            _unexplained(
                residual_px=named_max,
                residual_rms_px=float(np.sqrt(np.mean(named_res**2))),
                affine_residual_px=_max_abs(affine_res),
                affine=a.tolist(),
                offset=b.tolist(),
                rotation_deg=math.degrees(math.atan2(a[1, 0] - a[0, 1], a[0, 0] + a[1, 1])),
                **vis_fields,
                underdetermined=False,
            )
        )
    return _sorted(faults)


def diagnose_lines(lines: dict, tol) -> list[dict]:
    """Name a systematic line-pixel fault from a case's pooled line fields; [] when they pass.

    ``lines`` is :func:`oracles.judge.metrics.line_summary`'s output and ``tol`` the
    run's tolerances; nothing is named unless :func:`oracles.tolerances.line_failures`
    fails it. The decided one-sided pixels (sub-pixel ties left out, as in the
    balance; ``candidate_only`` and ``oracle_only`` below count these) are
    split by where they lie along the
    oracle's segments (``one_sided_by_place``): net pixels per line at the
    segment's first point (``start``) and last point (``end``), candidate minus
    oracle (negative: the candidate's lines are short there). Where one end or
    both carry at least ``NAMING.line_end_min_px`` per line and together at least
    half of the net imbalance, the fault is ``line_end_bias`` with ``end``
    (``"first"``, ``"last"`` or ``"both"``) and ``pixels_per_line`` (signed);
    otherwise ``line_pixel_bias`` (lines thicker or thinner, or stray pixels),
    with the one-sided counts by place. Nothing is named when every one-sided
    pixel is a tie (0 decided on either side).
    """
    tc, to = lines["subpixel_ties"]
    decided = {"candidate_only": int(lines["candidate_only"] - tc), "oracle_only": int(lines["oracle_only"] - to)}
    if not line_failures(lines, tol) or not (decided["candidate_only"] or decided["oracle_only"]):
        return []  # no line fault on undecided pixels alone
    n = max(lines["lines_compared"], 1)
    places = lines["one_sided_by_place"]
    net = {p: places[p][0] - places[p][1] for p in places}  # candidate-only minus oracle-only
    per_line = {"first": net["start"] / n, "last": net["end"] / n}
    ends = [e for e in ("first", "last") if abs(per_line[e]) >= NAMING.line_end_min_px]
    total = lines["imbalance"]
    at_ends = sum(net[{"first": "start", "last": "end"}[e]] for e in ends)
    if ends and abs(at_ends) >= 0.5 * abs(total):
        return [
            {
                "name": "line_end_bias",
                "end": ends[0] if len(ends) == 1 else "both",
                "pixels_per_line": float(sum(per_line[e] for e in ends)),
                "lines": int(lines["lines_compared"]),
                **decided,
            }
        ]
    return [{"name": "line_pixel_bias", **line_pixel_fields(lines)}]


def line_pixel_fields(lines: dict) -> dict:
    """``line_pixel_bias``'s fields from a case's pooled line fields (:func:`diagnose_lines`): the decided
    one-sided pixels (ties left out) and the net pixels, candidate minus oracle, by where they lie."""
    tc, to = lines["subpixel_ties"]
    places = lines["one_sided_by_place"]
    return {
        "candidate_only": int(lines["candidate_only"] - tc),
        "oracle_only": int(lines["oracle_only"] - to),
        **{f"net_{p}": int(places[p][0] - places[p][1]) for p in ("start", "end", "middle", "stray")},
    }
