"""Name what is wrong with a renderer from its images alone.

``diagnose_images(cand_images, oracle_segments, camera, flipped_segments=None) -> list[dict]``

The same fault names as the vertex diagnosis (:mod:`oracles.diagnosis.diagnose`, whose
module docstring defines them and the conventions of their fields), found
without the candidate's vertices: the candidate's drawn pixels are
*registered* to the oracle's lines.

Inputs, per frame of one case: the candidate's image (``(H, W)`` bool, drawn
pixels True) and the oracle's line segments in pixels (``(K, 2, 2)``:
depth-clipped in world space, projected by OpenCV, not clipped to the image;
:func:`oracle_segments`). The segments are the exact lines a correct renderer
would draw, so distances to them are sub-pixel, not quantised by a second
rasteriser.

Method
======
1. **Family.** In coordinates centred on the principal point (``u = x - cx``,
   ``v = y - cy``), the candidate's line pixels ``c`` are modelled as
   ``c = d * (P @ o) + b`` for a point ``o`` on the oracle's lines: ``P`` one of
   the 8 signed axis permutations (identity, the mirrors, the flip, the swap and
   the swap with each mirror), ``d`` a positive scale per axis, ``b`` an offset.
   This is exactly the family :mod:`oracles.diagnosis.diagnose` reads its faults from.
2. **Registration.** For each ``P``, from two starts (``d = 1, b = 0``; and
   per-axis mean and spread of the two pixel sets), iterate (ICP): pair every
   candidate pixel with the nearest point of the oracle's segments (mapped back
   through the current ``d, P, b``), and every oracle sample (points every
   :data:`SAMPLE_STEP_PX` along the segments) mapped into the candidate image
   with the nearest candidate pixel (``scipy.ndimage.distance_transform_edt``'s
   indices); drop pairs farther than :data:`PAIR_CAP_PX`; refit ``d, b`` per axis
   by least squares (linear in ``d_i, b_i`` for fixed ``P``). Both directions
   are needed: pixels-to-lines alone is minimised by shrinking the candidate
   onto a line, lines-to-pixels alone by a candidate that draws everywhere.
   All frames of a case are pooled into one fit, so the sub-pixel offset is
   averaged over every line pixel of the case.
3. **Residual and confidence.** The cost is the mean of the two directions'
   mean distances, each capped at :data:`PAIR_CAP_PX` (a point with no partner
   within the cap counts as the cap). The best ``P`` is the one of least cost;
   ``residual_px`` is its cost. A named fault's ``confidence`` is ``1 - cost /
   cost without it`` (:mod:`oracles.diagnosis.image_naming`); ``unexplained``'s is ``1 -
   best / second`` against the best *other* permutation.
4. **Depth flip.** A renderer that looks backward draws what a camera with its
   forward negated sees: ``flipped_segments``. When the candidate registers to
   those better than to the oracle's own, the answer is ``depth_flip`` alone
   (as in the vertex diagnosis). A candidate that draws nothing where the
   oracle draws lines, while the backward camera also sees nothing, is the
   image of "clips everything the oracle shows": ``depth_flip`` too.
5. **Faults.** With ``residual_px <= NAMING.residual_max_px`` the faults are read off
   ``P``, ``d`` and ``b`` as in :mod:`oracles.diagnosis.diagnose` (step 4 there), with the
   pixel tolerances ``Tolerances.scale_px`` (a scale's largest effect on a drawn
   pixel) and ``Tolerances.offset_px``; otherwise the answer is ``unexplained``
   (a rotation, a shear, a 3D error: nothing of the family draws these pixels), or, when
   the identity fits and only the drawn sets differ, the visibility advice (:mod:`.image_visibility`).

Every fault carries ``confidence`` and ``residual_px``; ``pixel_offset`` is
given to sub-pixel (``dx, dy``), ``fov_mismatch`` with ``implied_fov_deg`` (or
``implied_ortho_height``), ``aspect_mismatch`` with ``implied_aspect``.
An offset is compared with the offset the same fit finds for a correct
aliased drawing of the fitted model's lines (the oracle's, scaled and mirrored
as fitted: :func:`quantisation_bias`), which is also given as
``uncertainty_px``: lines all at one fractional pixel position (a cube
square-on to a nearly orthographic camera) cannot show an offset below it.
Two permutations that fit equally well are ``ambiguous``; each fault's
confidence measures that fault; a fit that no start explains is restarted
from the scales convention mistakes give (:mod:`oracles.diagnosis.image_naming`).

Limits (measured in tests/test_image_diagnosis.py, stated in docs/frames.md):
the images must show enough line to fit (``NAMING.min_registered_px`` drawn pixels in a
case), the fault must move lines by more than the tolerances above, and a
scale below ~0.5 or above ~2 may not be recovered from the unit start.
"""

from __future__ import annotations

import numpy as np
from wirecheck.core.camera import Camera

from ..candidates import draw
from ..tolerances import NAMING, Tolerances
from .image_naming import name_faults, restart_scales, rotation_deg, rule_off_diagonal
from .image_visibility import in_place, visibility_fault
from .model_lines import quantisation_bias
from .registration import (
    MAX_POINTS_PER_CASE,
    MAX_POINTS_PER_FRAME,
    PAIR_CAP_PX,
    SCREEN_POINTS_PER_CASE,
    SCREEN_POINTS_PER_FRAME,
    Registration,
    frame_samples,
    points_per_frame,
    register,
    segments_in_image,
)

__all__ = ["diagnose_images", "oracle_segments", "flipped_camera"]


# ---------------------------------------------------------------- the oracle's lines


def oracle_segments(p_world: np.ndarray, edges: np.ndarray, camera) -> np.ndarray:
    """The lines a correct renderer draws: ``(K, 2, 2)`` pixel segment ends, of the edges with a part in depth.

    :func:`oracles.candidates.draw.oracle_segments` (each edge clipped to depth [near, far] in world space,
    projected by OpenCV; not clipped to the image) in the fit's shape: the two ends stacked, the edges
    it leaves NaN (nothing in depth) dropped.
    """
    edges = np.asarray(edges, dtype=np.intp).reshape(-1, 2)
    p0, p1 = draw.oracle_segments(np.asarray(p_world, dtype=np.float64), edges, camera)
    px = np.stack([p0, p1], axis=1)
    return px[np.isfinite(px).all(axis=(1, 2))]


def flipped_camera(camera):
    """The camera looking backward (forward negated, up kept): what a depth-flipped renderer draws."""
    return Camera(
        position=camera.position,
        forward=-np.asarray(camera.forward),
        up=camera.up,
        fov_y_deg=camera.fov_y_deg,
        width=camera.width,
        height=camera.height,
        near=camera.near,
        far=camera.far,
        projection=camera.projection,
        ortho_height=camera.ortho_height,
        intrinsics=getattr(camera, "intrinsics", None),
    )


# ---------------------------------------------------------------- geometry helpers


def diagnose_images(cand_images, oracle_segs, camera, flipped_segs=None, tol=None) -> list[dict]:
    """Name the faults of a renderer from its frames; ``[]`` when its lines are the oracle's.

    Parameters
    ----------
    cand_images : sequence of (H, W) bool ndarray
        The candidate's frames of one case (drawn pixels True).
    oracle_segs : sequence of (K, 2, 2) ndarray
        The oracle's line segments of the same frames (:func:`oracle_segments`).
    camera : core.camera.Camera
        The case's camera (principal point, FOV or ortho height, size).
    flipped_segs : sequence of (K, 2, 2) ndarray, optional
        The lines seen by :func:`flipped_camera`; without them ``depth_flip``
        is not considered.
    tol : oracles.tolerances.Tolerances, optional
        Its ``scale_px`` and ``offset_px`` name a scale and an offset (default
        ``Tolerances()``'s). The naming thresholds are :data:`oracles.tolerances.NAMING`'s.

    Returns
    -------
    list of dict, primary fault first (precedence: oracles.faults);
    every fault has ``confidence`` and ``residual_px``.
    """
    tol = Tolerances() if tol is None else tol
    scale_tol, offset_tol = tol.scale_px, tol.offset_px
    cand_images = list(cand_images)
    oracle_segs = list(oracle_segs)
    if len(cand_images) != len(oracle_segs):
        raise ValueError(f"{len(cand_images)} images but {len(oracle_segs)} frames of oracle lines")
    cx, cy = camera.principal_point
    centre = np.array([cx, cy])
    drawn = sum(int(np.count_nonzero(i)) for i in cand_images)
    oracle_drawn = segments_in_image(oracle_segs, camera)
    flipped_drawn = segments_in_image(flipped_segs, camera) if flipped_segs is not None else None
    if drawn == 0 and oracle_drawn == 0:
        return []
    if drawn == 0:
        if flipped_drawn == 0:
            return [
                {
                    "name": "depth_flip",
                    "confidence": 0.5,
                    "residual_px": 0.0,
                    "candidate_pixels": 0,
                    "note": "the candidate drew nothing where the oracle draws lines; a camera looking "
                    "backward sees nothing here either",
                }
            ]
        return [
            {
                "name": "unexplained",
                "confidence": 1.0,
                "residual_px": PAIR_CAP_PX,
                "candidate_pixels": 0,
                "note": "the candidate drew nothing where the oracle draws lines",
            }
        ]
    if drawn < NAMING.min_registered_px:
        return [
            {
                "name": "unexplained",
                "confidence": 0.0,
                "residual_px": None,
                "candidate_pixels": drawn,
                "underdetermined": True,
                "note": f"only {drawn} drawn pixels: expected at least {NAMING.min_registered_px} to register",
            }
        ]

    limit = points_per_frame(len(cand_images), MAX_POINTS_PER_CASE, MAX_POINTS_PER_FRAME)
    screen = points_per_frame(len(cand_images), SCREEN_POINTS_PER_CASE, SCREEN_POINTS_PER_FRAME)
    frames = frame_samples(cand_images, oracle_segs, camera, limit)
    nearest = [f.nearest for f in frames]  # one distance transform per image
    fine = Registration(frames, camera.width, camera.height, centre)
    coarse = Registration(
        frame_samples(cand_images, oracle_segs, camera, screen, nearest), camera.width, camera.height, centre
    )
    ranked = register(coarse, fine)
    if ranked[0][0] > NAMING.residual_max_px:  # no member fits from the usual starts: a large scale?
        ranked = restart_scales(coarse, fine, ranked, camera)
    plain = next(r for r in ranked if r[1] == ())
    if plain[0] <= ranked[0][0] * (1.0 + NAMING.ambiguous_ratio):
        ranked = [plain] + [r for r in ranked if r is not plain]  # a symmetric picture: no permutation
    cost, names, p, a, b = ranked[0]
    second = ranked[1][0] if len(ranked) > 1 else PAIR_CAP_PX
    confidence = float(max(0.0, 1.0 - cost / second)) if second > 0 else 0.0

    if flipped_segs is not None and flipped_drawn:
        back = Registration(
            frame_samples(cand_images, flipped_segs, camera, limit, nearest), camera.width, camera.height, centre
        )
        b_cost = back.cost(np.eye(2), np.eye(2), np.zeros(2))
        if b_cost < cost and b_cost <= NAMING.residual_max_px:
            return [
                {
                    "name": "depth_flip",
                    "confidence": float(max(0.0, 1.0 - b_cost / cost)),
                    "residual_px": b_cost,
                    "residual_unflipped_px": cost,
                }
            ]

    # the named model against a free affine map: a rotation or shear the family cannot draw
    reach = np.max(np.abs(np.concatenate([f.samples for f in frames]) @ p.T), axis=0)
    reach = np.minimum(reach, [camera.width / 2.0, camera.height / 2.0])  # the part an image can show
    a_free, b_free, cost_free = fine.fit(p, a, b, affine=True)
    off_diagonal = max(abs(a_free[0, 1]) * reach[1], abs(a_free[1, 0]) * reach[0])
    if cost <= NAMING.residual_max_px and off_diagonal > NAMING.rotation_px:  # another aliased rule's own shear?
        off_diagonal = rule_off_diagonal(cand_images, oracle_segs, camera, (p, a, b), a_free, reach, off_diagonal)
    if cost > NAMING.residual_max_px or off_diagonal > NAMING.rotation_px:
        fault = {
            "name": "unexplained",
            "confidence": confidence,
            "residual_px": cost,
            "best_family": list(names) or ["none"],
            "scale": np.diag(a).tolist(),
            "offset": b.tolist(),
            "affine": a_free.tolist(),
            "affine_residual_px": cost_free,
            "off_diagonal_px": float(off_diagonal),
            "rotation_deg": rotation_deg(a_free),
        }
        matched = fine.matched(p, a, b)  # the lines in place, only the drawn sets differ?
        if in_place(
            names,
            np.diag(a),
            b,
            off_diagonal,
            reach,
            matched,
            (scale_tol, offset_tol, NAMING.rotation_px, NAMING.residual_max_px),
        ):
            fault = visibility_fault(fault, cand_images, oracle_segs, camera, matched)
        return [fault]
    return name_faults(
        fine,
        ranked,
        plain,
        camera,
        oracle_segs,
        reach,
        quantisation_bias,
        scale_tol,
        offset_tol,
        NAMING.ambiguous_ratio,
        cost,
        cand_images,
    )
