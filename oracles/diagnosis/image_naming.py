"""Naming a registered picture: from the fitted ``c = d (P o) + b`` to faults (oracles.diagnosis.image_diagnose).

The registration (:mod:`oracles.diagnosis.registration`, driven by oracles.diagnosis.image_diagnose) fits every signed axis
permutation ``P`` with per-axis scales ``d`` and an offset ``b``; this module
reads the faults off the winner, and says what the images cannot decide:

* **Ambiguity.** When a second permutation other than the identity fits
  within ``NamingThresholds.ambiguous_ratio`` (oracles.tolerances) of the best (a
  horizontal mirror of a view that is also up-down symmetric: a cube
  square-on, an orthographic view), the permutations they do not share are
  reported as one ``ambiguous`` fault with ``alternatives`` (both names) and a
  hint that gives both names' hints; the names they share (an ``axis_swap``
  in both) are named as usual.
* **Offset against the model's own lines.** A fitted offset is a fault only
  when it differs from the offset the same fit finds for a correct drawing of
  the *fitted model's* lines (the oracle's lines scaled and mirrored by ``d``
  and ``P``; :func:`oracles.diagnosis.image_diagnose.quantisation_bias`): scaled lines
  sit at other fractional pixel positions than the oracle's, with a
  quantisation bias of their own (0.17 px measured on quarter-turn frames of a
  0.75 FOV fault), which is no ``pixel_offset``. The drawing's aliased rule is
  the one read from the candidate's pixels (:func:`rule_bias`): GL's, or one that
  rounds the ends to pixel centres first (Bresenham, OpenCV's LINE_8), whose
  rounded ends have a bias of their own; when the pixels fit both rules' lines
  alike (:mod:`oracles.diagnosis.rule_read`), the offset must stand against both
  biases, and a scale against both rules' tolerances.
* **Confidence of each fault.** ``1 - cost / cost without it``: a permutation
  (or ``ambiguous``) against the identity's fit, a scale against the unit scale
  (``fov_mismatch``) or equal scales (``aspect_mismatch``), an offset against
  the model's bias. It measures the named fault, not how far the mirror
  alternatives are (0 on a symmetric picture whatever its fault).
* **Scale starts.** Few frames of a large scale fault (fx x 16/9, K x 4/3) can
  trap the fit from the unit and moment starts in a wrong affine map; when the
  best fit is no member of the family, the identity and the best permutation
  are fitted again from the scales a convention mistake gives
  (:func:`scale_starts`).
"""

from __future__ import annotations

import math

import numpy as np

from .. import faults as catalogue
from .diagnose import scale_faults
from .model_lines import model_images, quantisation_bias
from .registration import (
    MAX_POINTS_PER_CASE,
    MAX_POINTS_PER_FRAME,
    PERMUTATIONS,
    SCREEN_ITERATIONS,
    Registration,
    frame_samples,
    points_per_frame,
)
from .rule_read import read_rules, standing_scale_faults

__all__ = [
    "scale_starts",
    "name_faults",
    "ambiguous_fault",
    "quantisation_bias",
    "restart_scales",
    "rule_bias",
    "rule_off_diagonal",
]

#: Ratios a convention mistake scales an axis by: H/W and W/H (the aspect or FOV of the other axis),
#: the common aspects 4/3 and 16/9 and their inverses, and 2 and 1/2 (a half-angle or a half-size).
_RATIOS = (4 / 3, 3 / 4, 16 / 9, 9 / 16, 2.0, 0.5)


def scale_starts(camera) -> list[np.ndarray]:
    """``(2,)`` scale starts ``(d_x, d_y)``: each ratio on both axes, on x alone and on y alone."""
    ratios = sorted(set(_RATIOS) | {camera.width / camera.height, camera.height / camera.width})
    out = []
    for r in ratios:
        out += [np.array([r, r]), np.array([r, 1.0]), np.array([1.0, r])]
    return out


def ambiguous_fault(names: tuple, other: tuple, **common) -> tuple[list[dict], dict]:
    """``(shared faults, ambiguous fault)`` for two permutations' names that fit equally well."""
    shared = [n for n in names if n in other]
    alternatives = ["+".join(n for n in group if n not in shared) or "none" for group in (names, other)]
    each = "; ".join(f"if {alt}: {catalogue.kind(alt.split('+')[0]).hint}" for alt in alternatives if alt != "none")
    return (
        [{"name": n, **common} for n in shared],
        {
            "name": "ambiguous",
            **common,
            "alternatives": alternatives,
            "hint": catalogue.hint_text(
                "ambiguous", "alternatives", first=alternatives[0], second=alternatives[1], each=each
            ),
        },
    )


def _confidence(cost: float, without: float) -> float:
    return float(max(0.0, 1.0 - cost / without)) if without > 0 else 0.0


def name_faults(
    reg, ranked, plain, camera, oracle_segs, reach, bias_fn, scale_tol, offset_tol, ratio, residual, cand_images=None
) -> list[dict]:
    """The faults of the winner of ``ranked`` (``[(cost, names, P, a, b)]``, best first; ``plain``: the
    identity's fit), in the vocabulary of :func:`oracles.diagnosis.diagnose.scale_faults`.

    ``reg``: the fine registration (its ``cost``), ``bias_fn``: ``quantisation_bias(segs, camera, p, d)``,
    ``scale_tol``/``offset_tol``: the pixel tolerances of a scale and an offset, ``ratio``: the ambiguity
    ratio, ``residual``: the winner's cost, ``cand_images``: the candidate's frames (the aliased rule read
    from them sets the bias an offset is compared with, :func:`rule_bias`; without them GL's).
    """
    cost, names, p, a, b = ranked[0]
    d = np.diag(a)
    cx, cy = camera.principal_point
    faults: list[dict] = []
    if names:
        common = {"confidence": _confidence(cost, plain[0]), "residual_px": residual}
        other = next((r for r in ranked[1:] if r[1] not in ((), names)), None)
        if other is not None and other[0] <= cost * (1.0 + ratio):
            shared, amb = ambiguous_fault(names, other[1], **common)
            faults += shared + [amb]
        else:
            faults += [{"name": n, **common} for n in names]
    scale = scale_faults(float(d[0]), float(d[1]), reach, scale_tol, camera, confidence=0.0, residual_px=residual)
    rules = {}  # the aliased rules the pixels may follow (rule_read), read once

    def read():
        if not rules:
            rules.update(read_rules(cand_images, oracle_segs, camera, p, d, b, bias_fn(oracle_segs, camera, p, d)))
        return rules

    if scale and cand_images is not None:  # a scale the rounded ends' own would explain is no fault
        scale = standing_scale_faults(scale, d, reach, scale_tol, camera, read())
    for f in scale:
        undo = np.eye(2) if f["name"] == "fov_mismatch" else np.diag([d[1], d[1]])
        f["confidence"] = _confidence(cost, reg.cost(p, undo, b))
        faults.append(f)
    expected = np.zeros(2)
    if "axis_swap" in names:
        shift = cx - cy  # as oracles.diagnosis.diagnose: a raw swap shifts by +-(cx - cy)
        allowed = np.array([-shift, 0.0, shift])
        expected = np.array([allowed[np.argmin(np.abs(allowed - b[i]))] for i in range(2)])
    off = b - expected
    bias = bias_fn(oracle_segs, camera, p, d)
    rule, read_as = "gl", ["gl"]
    if np.max(np.abs(off - bias)) > offset_tol and cand_images is not None:
        # another rule's own bias? The offset stands only against every rule read: the one explaining most
        read_as = list(read())
        rule, bias = min(read().items(), key=lambda kv: np.max(np.abs(off - kv[1])))
    if np.max(np.abs(off - bias)) > offset_tol:
        faults.append(
            {
                "name": "pixel_offset",
                "confidence": _confidence(cost, reg.cost(p, a, expected + bias)),
                "residual_px": residual,
                "dx": float(off[0]),
                "dy": float(off[1]),
                "uncertainty_px": float(np.max(np.abs(bias))),
                "bias_rule": rule,
                "rules_read": read_as,
            }
        )
    return catalogue.ordered(faults)


def rotation_deg(a_free: np.ndarray) -> float:
    """The rotation part of a free affine map (y down), in degrees."""
    return math.degrees(math.atan2(a_free[1, 0] - a_free[0, 1], a_free[0, 0] + a_free[1, 1]))


def restart_scales(coarse, fine, ranked: list, camera) -> list:
    """``ranked`` with the identity and the best permutation fitted again from :func:`scale_starts`."""
    screened = []
    for names, p in {(): PERMUTATIONS[()], ranked[0][1]: ranked[0][2]}.items():
        for d0 in scale_starts(camera):
            a, b, c = coarse.fit(p, np.diag(d0), np.zeros(2), iterations=SCREEN_ITERATIONS)
            screened.append((c, names, p, a, b))
    best = {}
    for c, names, p, a, b in sorted(screened, key=lambda r: r[0]):
        best.setdefault(names, (c, names, p, a, b))
    out = {r[1]: r for r in ranked}
    for c, names, p, a, b in best.values():
        a, b, c = fine.fit(p, a, b)
        if c < out[names][0]:
            out[names] = (c, names, p, a, b)
    return sorted(out.values(), key=lambda r: r[0])


def rule_bias(cand_images, oracle_segs, camera, p, d, b, gl_bias) -> tuple[str, np.ndarray]:
    """``(rule read, its bias)``: which aliased rule drew the candidate's lines, GL's or ends snapped.

    An aliased rule that rounds each end to a pixel centre before stepping
    (Bresenham, OpenCV's LINE_8) moves each line by up to half a pixel: pooled
    over a case's few lines its own bias reaches 0.19-0.25 px (measured on
    quarter-turn cubes and pyramids given a 4/3 FOV), where GL's rule has 0.02.
    Each rule's account of the candidate: GL's, the model's lines where the fit
    put them (offset ``b``); the snapped rule's, the model's lines moved by
    ``b`` less that rule's bias with their ends rounded to pixel centres (the
    segments such a renderer steps along, whatever its tie-breaking; the
    best of :data:`JITTER`'s positions). The rule
    whose lines the candidate's pixels fit closer (the registration's cost) is
    the one read: a GL-rule renderer with a half-pixel offset lies on its
    exact lines, so its offset is still measured against GL's bias. When the
    two costs are too close to say, both rules are read
    (:func:`oracles.diagnosis.rule_read.read_rules`); this is the closer one.
    """
    # the renderer's lines are known to the fit's precision; ends at a half pixel round either way under it
    rule, bias = next(iter(read_rules(cand_images, oracle_segs, camera, p, d, b, gl_bias).items()))
    return rule, bias


def rule_off_diagonal(cand_images, oracle_segs, camera, fit, a_free, reach, off_diagonal) -> float:
    """The free affine fit's off-diagonal (px) less that of a correct drawing of the model by the rule read.

    ``fit``: the named model's ``(p, a, b)``. Lines whose ends are rounded to
    pixel centres (:func:`rule_bias` reads that rule) are each turned by up to
    half a pixel over their length; pooled over a case's few lines the free fit
    finds a shear of its own in them (0.35 px measured on a quarter-turn
    pyramid given a 4/3 FOV, where GL's rule leaves <= 0.04 px). The same
    fit on the model's lines drawn by that rule gives that shear; what is left
    is the candidate's. Under GL's rule ``off_diagonal`` is returned as it is;
    with both rules read (a tie), the smaller of the two: it must stand against both.
    """
    p, a, b = fit
    d = np.diag(a)
    rules = read_rules(cand_images, oracle_segs, camera, p, d, b, quantisation_bias(oracle_segs, camera, p, d))
    if "snapped" not in rules:
        return off_diagonal
    images = model_images(oracle_segs, camera, p, d, b - rules["snapped"], snapped=True)
    limit = points_per_frame(len(images), MAX_POINTS_PER_CASE, MAX_POINTS_PER_FRAME)
    reg = Registration(
        frame_samples(images, oracle_segs, camera, limit), camera.width, camera.height, np.array(camera.principal_point)
    )
    own, _b, _cost = reg.fit(p, a, b, affine=True)
    left = np.asarray(a_free) - own
    snapped = float(max(abs(left[0, 1]) * reach[1], abs(left[1, 0]) * reach[0]))
    return min(snapped, off_diagonal) if "gl" in rules else snapped  # it stands against every rule read
