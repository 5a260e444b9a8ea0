"""Visibility advice for an ``unexplained`` of the image diagnosis whose lines sit where the oracle's do.

A renderer that clips at another plane than [near, far] (at z > 0, a far
plane too close, none at all) draws every line it keeps exactly where the
oracle's lines are, and draws more or fewer of them. The registration
(:mod:`oracles.diagnosis.image_diagnose`) then fits the identity with no
scale, offset or rotation, and the pairs it finds are as close as a correct
drawing's; only the unpaired pixels (whole pieces of line on one side) raise
its cost above ``NAMING.residual_max_px`` (oracles.tolerances). That
is a visibility, clipping or raster question, not a rotation order: as on the
projector path (:func:`oracles.diagnosis.diagnose.diagnose`'s advice), the
``unexplained`` says which sets differ instead.

The sets are counted in pixels over the diagnosed frames, at the 1 px of
F1@1px: ``candidate_only_px``, drawn pixels with no oracle line pixel within
1 px; ``oracle_only_px``, pixels of the oracle's lines (drawn by core's
rasteriser from the exact segments) with no drawn pixel within 1 px.
"""

from __future__ import annotations

import numpy as np
from wirecheck.core.projector import raster
from wirecheck.core.projector.clipping import clip_to_image

from .. import faults as catalogue
from ..tolerances import NAMING

__all__ = ["set_difference", "visibility_fault", "in_place", "frames_visibility", "visibility_names"]


def _oracle_image(segs, camera) -> np.ndarray:
    segs = np.asarray(segs, dtype=np.float64).reshape(-1, 2, 2)
    img = np.zeros((camera.height, camera.width), bool)
    if len(segs):
        _, q0, q1 = clip_to_image(segs[:, 0], segs[:, 1], camera.width, camera.height)
        rr, cc = raster.line_pixels(q0, q1, camera.width, camera.height)
        img[rr, cc] = True
    return img


def _beyond(a: np.ndarray, b: np.ndarray) -> int:
    """Pixels of ``a`` with no pixel of ``b`` within ``NAMING.near_px`` (all of ``a`` when ``b`` is empty)."""
    from scipy.ndimage import distance_transform_edt

    if not b.any():
        return int(np.count_nonzero(a))
    return int(np.count_nonzero(a & (distance_transform_edt(~b) > NAMING.near_px)))


def set_difference(cand_images, oracle_segs, camera) -> tuple[int, int]:
    """``(candidate_only_px, oracle_only_px)`` over the frames (module docstring)."""
    cand_only = oracle_only = 0
    for img, segs in zip(cand_images, oracle_segs):
        img = np.asarray(img, bool)
        orac = _oracle_image(segs, camera)
        cand_only += _beyond(img, orac)
        oracle_only += _beyond(orac, img)
    return cand_only, oracle_only


def in_place(names, d, b, off_diagonal, reach, matched, tols) -> bool:
    """Whether a fit is the identity within the tolerances and its paired points are a correct drawing's.

    ``names``: the fitted permutation's fault names (none), ``d``: its scales, ``b``: its offset (px),
    ``off_diagonal``: the free affine map's off-diagonal effect (px), ``reach``: ``(2,)`` px from the
    principal point, ``matched``: the mean distance of the pairs within the cap (px), ``tols``:
    ``(scale, offset, rotation, residual)`` tolerances in px.
    """
    scale_tol, offset_tol, rotation_tol, residual_max = tols
    return (
        not names
        and float(np.max(np.abs(np.asarray(d) - 1.0) * np.asarray(reach))) <= scale_tol
        and float(np.max(np.abs(b))) <= offset_tol
        and off_diagonal <= rotation_tol
        and matched <= residual_max
    )


def visibility_fault(
    fault: dict, cand_images, oracle_segs, camera, matched_px: float | None, counts: tuple[int, int] | None = None
) -> dict:
    """``fault`` (an ``unexplained``) with the counts of :func:`set_difference` and the visibility ``hint``;
    unchanged when no pixel is on one side only (then nothing says the sets differ).

    ``matched_px``: the mean distance of the fit's pairs (None: the images fit the oracle's lines, no
    fault named from them); ``counts``: :func:`set_difference`'s, when already counted.
    """
    cand_only, oracle_only = counts if counts is not None else set_difference(cand_images, oracle_segs, camera)
    if not (cand_only or oracle_only):
        return fault
    where = (
        "the drawn lines lie on the oracle's"
        if matched_px is None
        else f"the drawn lines lie on the oracle's (paired pixels {matched_px:.2g} px away on average, as a "
        "correct drawing's)"
    )
    return {
        **fault,
        "candidate_only_px": cand_only,
        "oracle_only_px": oracle_only,
        **({} if matched_px is None else {"matched_residual_px": float(matched_px)}),
        "hint": catalogue.hint_text(
            "unexplained",
            "drawn_sets",
            where=where,
            candidate_only=cand_only,
            oracle_only=oracle_only,
            near=NAMING.near_px,
        ),
    }


def frames_visibility(faults: list, cand_images, oracle_segs, camera, frames_checked: int) -> list:
    """A frames case's ``faults`` when its images fit the oracle's lines (nothing named from them).

    A bare ``unexplained`` (oracles.judge.decide's) gets the visibility advice. A ``line_pixel_bias`` whose
    one-sided pixels are mostly whole pieces of line becomes that ``unexplained`` (:func:`visibility_names`).
    ``cand_images``, ``oracle_segs``: the diagnosed frames (of the case's ``frames_checked``).
    """
    if len(faults) != 1 or not len(cand_images) or faults[0]["name"] not in ("unexplained", "line_pixel_bias"):
        return faults
    counts = set_difference(cand_images, oracle_segs, camera)
    return visibility_names(faults, counts, len(cand_images), frames_checked)


def visibility_names(
    faults: list,
    counts: tuple[int, int],
    frames_diagnosed: int,
    frames_checked: int,
    share: float = NAMING.visibility_share,
) -> list:
    """:func:`frames_visibility` on the sets already counted (``counts``: :func:`set_difference` over
    ``frames_diagnosed`` frames): a bare ``unexplained`` gets the advice; a ``line_pixel_bias`` becomes it when
    at least ``share`` of its decided one-sided pixels, per frame, lie farther than ``NAMING.near_px`` from the
    other side (a line drawn too thick or too thin never leaves a pixel that far), its name kept under
    ``line_fault`` (oracles.tolerances.NamingThresholds.visibility_share)."""
    if faults[0]["name"] == "unexplained":
        return [visibility_fault(faults[0], None, None, None, None, counts)]
    decided = faults[0]["candidate_only"] + faults[0]["oracle_only"]
    if sum(counts) * frames_checked < share * decided * frames_diagnosed:
        return faults
    return [visibility_fault({"name": "unexplained", "line_fault": faults[0]["name"]}, None, None, None, None, counts)]
