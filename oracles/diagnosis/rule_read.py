"""Which aliased rules may have drawn a candidate's lines, and what a fault must stand against (image_naming).

Two aliased rules are told apart (:func:`oracles.diagnosis.image_naming.rule_bias`): GL's (each line
stepped along its exact ends) and the one that rounds each end to a pixel centre first (Bresenham's,
OpenCV's LINE_8, Pillow's 1-px line). Each has a bias of its own: the offset and scale the registration
finds on a correct drawing by that rule. A rule is read from which model's lines the candidate's pixels
fit closer (the registration's cost), but the two costs are not always far enough apart to say:

* **A tie.** The costs read the rule poorly. Measured on the held-out renderers (benchmarks/
  measure_heldout_frames.py, 21 cases each): correct rounded-ends frames (Bresenham, OpenCV's LINE_8,
  Pillow's 1-px line) fit GL's lines closer on 4-5 cases of 21, by up to 30 % of the cost (LINE_8,
  pyramid / non_square: 0.374 against 0.485), where the two rules' biases differ by 0.15-0.21 px; the
  wrong-axis FOV drawn by Bresenham on prism / wide_fov by 2 % (0.361 against 0.368: the fitted scale,
  1.3317 for 4/3, puts the model's rounded ends up to a fifth of a pixel from the renderer's near the
  image's edge). Correct GL-rule frames (core's raster) fit the rounded-ends lines closer only where both
  rules draw the same pixels (square-on cubes, by up to 38 %; the same bias). So a rule is read alone only
  when the other rule's cost exceeds its own by more than ``NAMING.rule_tie`` of it (oracles.tolerances);
  within that, both are read (:func:`read_rules`).
* **Standing against every rule read.** A fault that one rule's own bias would explain is no fault of a
  renderer that may follow that rule: an offset is named only when it stands against the bias of every
  rule read (:func:`oracles.diagnosis.image_naming.name_faults`), a scale only when it stands against the
  tolerance of every rule read (:func:`standing_scale_faults`).
"""

from __future__ import annotations

import numpy as np

from ..tolerances import NAMING
from .diagnose import scale_faults
from .model_lines import JITTER, model_lines, quantisation_bias
from .registration import MAX_POINTS_PER_CASE, MAX_POINTS_PER_FRAME, Registration, frame_samples, points_per_frame

__all__ = ["read_rules", "standing_scale_faults"]


def _costs(cand_images, oracle_segs, camera, p, d, b):
    """``(snapped bias, GL model's cost, snapped model's cost)`` of the candidate's pixels.

    GL's model at the fitted offset; the rounded ends' model at the best of the positions the fit cannot
    tell apart (:data:`oracles.diagnosis.model_lines.JITTER`: ends on a half pixel round either way).
    """
    snapped_bias = quantisation_bias(oracle_segs, camera, p, d, snapped=True)
    limit = points_per_frame(len(cand_images), MAX_POINTS_PER_CASE, MAX_POINTS_PER_FRAME)
    nearest = None

    def cost(lines):
        nonlocal nearest
        frames = frame_samples(cand_images, lines, camera, limit, nearest)
        nearest = [f.nearest for f in frames]  # one distance transform per image, reused
        reg = Registration(frames, camera.width, camera.height, np.array(camera.principal_point))
        return reg.cost(np.eye(2), np.eye(2), np.zeros(2))

    gl = cost(model_lines(oracle_segs, camera, p, d, b, False))
    snapped = min(cost(model_lines(oracle_segs, camera, p, d, b - snapped_bias + step, True)) for step in JITTER)
    return snapped_bias, gl, snapped


def read_rules(cand_images, oracle_segs, camera, p, d, b, gl_bias) -> dict:
    """``{rule: its offset bias}`` for each aliased rule the candidate's pixels may follow, closest first.

    ``p, d, b``: the fitted model (signed permutation, per-axis scales, offset); ``gl_bias``: GL's
    bias for it (:func:`oracles.diagnosis.model_lines.quantisation_bias`). The closer rule is the one
    whose model the pixels fit closer (:func:`_costs`), as :func:`oracles.diagnosis.image_naming.rule_bias`
    reads it; the other is read too when its cost is within ``NAMING.rule_tie`` of the closer one's.
    """
    snapped_bias, gl, snapped = _costs(cand_images, oracle_segs, camera, p, d, b)
    rules = {"gl": np.asarray(gl_bias, dtype=np.float64), "snapped": snapped_bias}
    order = ["snapped", "gl"] if snapped < gl else ["gl", "snapped"]
    tie = max(gl, snapped) <= (1.0 + NAMING.rule_tie) * min(gl, snapped)
    return {rule: rules[rule] for rule in (order if tie else order[:1])}


def standing_scale_faults(faults: list, d, reach, tol: float, camera, rules) -> list:
    """The scale faults of ``faults`` that stand under every rule of ``rules`` (:func:`read_rules`).

    Under the rule that rounds the ends a scale must move a pixel by more than ``tol`` plus
    ``NAMING.rounded_end_px`` (oracles.tolerances); under GL's, by more than ``tol`` (``faults`` were named so).
    """
    if "snapped" not in rules:
        return faults
    loose = {f["name"] for f in scale_faults(float(d[0]), float(d[1]), reach, tol + NAMING.rounded_end_px, camera)}
    return [f for f in faults if f["name"] in loose]
