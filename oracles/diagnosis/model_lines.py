"""The oracle's segments as a model renderer draws them under a fitted ``(P, d, b)``: GL's rule or ends
rounded to pixel centres (:func:`model_lines`, :func:`model_images`), and the bias those pixels have
against the exact lines (:func:`quantisation_bias`).

Its own module because the naming (oracles.diagnosis.image_naming) and the rule read
(oracles.diagnosis.rule_read) both draw the model.
"""

from __future__ import annotations

import numpy as np
from wirecheck.core.projector.clipping import clip_to_image

from .. import line_model
from .registration import MAX_POINTS_PER_CASE, MAX_POINTS_PER_FRAME, Registration, frame_samples, points_per_frame


def model_images(oracle_segs, camera, p, d, shift=None, snapped: bool = False) -> list[np.ndarray]:
    """The fitted model's lines (``u -> d (p u)`` about the principal point, then ``+ shift``) drawn aliased.

    ``snapped``: by the rule that rounds each end to a pixel centre first (oracles.line_model's
    ``"rounded"`` rule: Bresenham's, OpenCV's LINE_8, Pillow's 1-px line); otherwise by GL's
    (oracles.line_model's ``"gl"``). Both drawn on the lines clipped to the image.
    """
    centre = np.array(camera.principal_point)
    shift = np.zeros(2) if shift is None else np.asarray(shift, dtype=np.float64)
    images = []
    for segs in oracle_segs:
        segs = np.asarray(segs, dtype=np.float64).reshape(-1, 2, 2)
        segs = ((segs - centre) @ p.T) * d + centre + shift  # the model's lines (identity: the oracle's)
        _, q0, q1 = clip_to_image(segs[:, 0], segs[:, 1], camera.width, camera.height)
        shape = (camera.height, camera.width)
        if snapped:  # the line model's rounded ends (its drawing alone: the ties are not needed here)
            img = np.zeros(shape, bool)
            rr, cc = line_model.rounded_pixels(np.stack([q0, q1], axis=1), shape)
            img[rr, cc] = True
        else:  # GL's rule: the line model's drawing (oracles.line_model)
            img, _ = line_model.expected(np.stack([q0, q1], axis=1), shape, "gl")
        images.append(img)
    return images


def quantisation_bias(oracle_segs, camera, p=None, d=None, snapped: bool = False) -> np.ndarray:
    """The offset this fit finds for a *correct* aliased drawing of these lines: ``(2,)`` px.

    With ``p`` and ``d`` (a signed axis permutation and per-axis scales), of
    the lines mapped by ``u -> d (p u)`` about the principal point: the bias of
    a fitted model's own lines (oracles.diagnosis.image_naming).

    Pixel centres sit up to half a pixel from a line; over slanted lines at
    every fractional position this averages out (< 0.05 px measured), but lines
    that are all axis-aligned at one fractional position (a cube square-on,
    nearly orthographic) are drawn half a pixel off in one direction, and no
    image can tell that from an offset. The oracle's own lines drawn by core's
    rasteriser (integer pixel centres, like GL's rule on these lines) give that
    bias; an offset is a fault only when it differs from it. ``snapped``: drawn
    by the rule that rounds the ends to pixel centres first (:func:`rule_bias`).
    """
    p = np.eye(2) if p is None else np.asarray(p, dtype=np.float64)
    d = np.ones(2) if d is None else np.asarray(d, dtype=np.float64)
    centre = np.array(camera.principal_point)
    images = model_images(oracle_segs, camera, p, d, snapped=snapped)
    limit = points_per_frame(len(images), MAX_POINTS_PER_CASE, MAX_POINTS_PER_FRAME)  # as diagnose_images
    reg = Registration(frame_samples(images, oracle_segs, camera, limit), camera.width, camera.height, centre)
    if not any(len(f.cand) for f in reg.frames):
        return np.zeros(2)
    _a, b, _cost = reg.fit(p, np.diag(d), np.zeros(2))
    return b


def model_lines(oracle_segs, camera, p, d, shift, snapped: bool) -> list[np.ndarray]:
    """The model's lines moved by ``shift``, clipped to the image; ``snapped``: each end rounded to a pixel centre."""
    centre = np.array(camera.principal_point)
    out = []
    for segs in oracle_segs:
        segs = ((np.asarray(segs, dtype=np.float64).reshape(-1, 2, 2) - centre) @ p.T) * d + centre + shift
        _, q0, q1 = clip_to_image(segs[:, 0], segs[:, 1], camera.width, camera.height)
        q = np.stack([q0, q1], axis=1)
        out.append(np.floor(q + 0.5) if snapped else q)
    return out


#: Shifts (px) about the snapped rule's line position at which its ends are rounded: the fitted offset's
#: own error (~0.01 px pooled) decides the rounding of ends that fall on a half pixel (an orthographic
#: view scaled by 4/3 puts many there), so each axis is tried at the position and 0.02 px either side.
JITTER = [np.array([sx, sy]) for sx in (-0.02, 0.0, 0.02) for sy in (-0.02, 0.0, 0.02)]
