"""The candidate's effective near and far planes, from the points it keeps and drops.

A projector returns NaN for a point it clips. When its visible set differs
from the oracle's, the pixels cannot say *where* its clipping planes are; the
candidate itself can: :func:`probe_planes` calls it on points along the
camera's optical axis (depth = distance along ``forward``) and brackets the
depths where it starts and stops returning pixels, to ~1e-10 relative.

:func:`clip_fault` names what the fitted planes show (``clipping_plane``,
:mod:`oracles.diagnosis.diagnose`), and :func:`depth_slack` says how far inside
``[near, far]`` a clipped end must be for a correct projector *at the
precision its planes show* to keep it (oracles.candidates.draw): a float64 projector
whose GL projection matrix went through float32 clips at near (1 + ~1e-8),
which the float64 nudge (1e-9 of a segment) does not clear.

Kinds of ``clipping_plane`` (``near_fit`` / ``far_fit``: the fitted planes,
None where the candidate never clips on that side):

==================  =========================================================
kind                the candidate ...
==================  =========================================================
``z_positive``      keeps every point in front of the camera (``z > 0``), not
                    only those beyond ``near`` (``near_fit`` ~ 0)
``float32_near``    clips at ``near`` rounded to float32 (or through a float32
``float32_far``     projection matrix): off by more than float64 rounding, at
                    most ``NAMING.float32_plane_roundings`` eps32 relative
                    (``far``: eps32 far/near, the GL matrix's conditioning)
``near``, ``far``   clips at another plane (a wrong value)
``none``            never clips: keeps points behind the camera too
``swapped``         keeps no depth at all, in front or behind: near and far
                    swapped in a ``near <= z <= far`` test (or an inverted
                    test)
==================  =========================================================
"""

from __future__ import annotations

import numpy as np

from .. import faults as catalogue
from ..candidates.candidate import CandidateError, call_candidate
from ..tolerances import EPS, NAMING

__all__ = ["probe_planes", "clip_fault", "depth_slack"]

#: Probe depths per sign: geometric from 1e-9 near to 1e3 far (steps of ~16 % for far/near = 1000).
GRID_POINTS = 240
#: Points per bracket per refining call, and calls: each call shrinks a bracket 63x, 6 calls 6e10x.
REFINE_POINTS = 64
REFINE_ROUNDS = 6


def _axis_points(camera, depth: np.ndarray) -> np.ndarray:
    forward = np.asarray(camera.forward, dtype=np.float64)
    forward = forward / np.linalg.norm(forward)
    return np.asarray(camera.position, dtype=np.float64) + depth[:, None] * forward


def _kept(func, camera, depth: np.ndarray) -> np.ndarray:
    px = call_candidate(func, _axis_points(camera, depth), camera)
    if px.shape != (len(depth), 2):
        raise CandidateError(f"candidate returned shape {px.shape} for {len(depth)} probe points")
    return np.isfinite(px).all(axis=1)


def probe_planes(func, camera) -> dict | None:
    """The candidate's clipping along the optical axis, or None when the probe cannot run.

    Returns ``{"near_fit", "far_fit", "front", "behind"}``: the fitted near
    and far depths (None where it keeps the grid's end: no plane that side;
    ``near_fit`` 0.0 when it keeps points at 1e-9 near), whether it keeps any
    point in front and any behind the camera. A candidate that fails on the
    probe (raises, wrong shape) gives None: the probe is an aid to naming,
    never a reason to fail a case.
    """
    near, far = float(camera.near), float(camera.far)
    if not 0 < near < far < np.inf:
        return None  # no positive depth range to probe
    grid = np.geomspace(1e-9 * near, 1e3 * far, GRID_POINTS)
    grid = np.unique(np.concatenate([grid, [near, far]]))
    try:
        kept = _kept(func, camera, np.concatenate([grid, -grid]))
    except (CandidateError, ValueError, FloatingPointError):
        return None
    front, behind = kept[: len(grid)], kept[len(grid) :]
    out = {"near_fit": None, "far_fit": None, "front": bool(front.any()), "behind": bool(behind.any())}
    if not front.any():
        return out
    first, last = int(np.argmax(front)), len(grid) - 1 - int(np.argmax(front[::-1]))
    brackets = {}
    if first == 0:
        out["near_fit"] = 0.0
    else:
        brackets["near_fit"] = (grid[first - 1], grid[first], False)  # (dropped, kept, rising)
    if last < len(grid) - 1:
        brackets["far_fit"] = (grid[last], grid[last + 1], True)  # (kept, dropped, falling)
    try:
        for _ in range(REFINE_ROUNDS):
            if not brackets:
                break
            spans = {k: np.linspace(lo, hi, REFINE_POINTS + 2)[1:-1] for k, (lo, hi, _f) in brackets.items()}
            got = _kept(func, camera, np.concatenate(list(spans.values())))
            at = 0
            for key, (lo, hi, falling) in list(brackets.items()):
                depth, k = spans[key], got[at : at + REFINE_POINTS]
                at += REFINE_POINTS
                if falling:  # kept below, dropped above: the last kept before the first dropped
                    drop = np.flatnonzero(~k)
                    j = int(drop[0]) if len(drop) else REFINE_POINTS
                    lo, hi = (depth[j - 1] if j else lo), (depth[j] if j < REFINE_POINTS else hi)
                else:  # dropped below, kept above
                    keep = np.flatnonzero(k)
                    j = int(keep[0]) if len(keep) else REFINE_POINTS
                    lo, hi = (depth[j - 1] if j else lo), (depth[j] if j < REFINE_POINTS else hi)
                brackets[key] = (lo, hi, falling)
    except (CandidateError, ValueError, FloatingPointError):
        return None
    for key, (lo, hi, _f) in brackets.items():
        out[key] = float(0.5 * (lo + hi))
    return out


def _rel(fit: float, plane: float) -> float:
    return (fit - plane) / plane


def _float32_limit(camera, which: str) -> float:
    """Relative distance of a plane that float32 rounding of the plane or of a GL matrix can explain."""
    eps = NAMING.float32_plane_roundings * EPS["float32"]
    return eps if which == "near" else eps * (1.0 + camera.far / camera.near)


def _hint(kind: str) -> str:
    """What to check for a ``clipping_plane`` of ``kind`` (the catalogue's hints, oracles.faults)."""
    return catalogue.hint_text("clipping_plane", kind)


def clip_fault(planes: dict | None, camera) -> dict | None:
    """``clipping_plane`` from :func:`probe_planes`'s answer; None when the planes are the camera's."""
    if planes is None:
        return None
    near, far = float(camera.near), float(camera.far)
    fields = {"near_fit": planes["near_fit"], "far_fit": planes["far_fit"], "near": near, "far": far}
    if not planes["front"] and not planes["behind"]:
        return {"name": "clipping_plane", "kind": "swapped", **fields, "hint": _hint("swapped")}
    if not planes["front"]:
        return None  # keeps only points behind: a depth flip, named by the pixels
    n_fit, f_fit = planes["near_fit"], planes["far_fit"]
    if n_fit is None or (planes["behind"] and n_fit == 0.0):
        return {"name": "clipping_plane", "kind": "none", **fields, "near_fit": None, "hint": _hint("none")}
    kind = None
    if abs(_rel(n_fit, near)) > NAMING.plane_rel_tol:
        if n_fit < NAMING.plane_rel_tol * near:
            kind = "z_positive"
        elif abs(_rel(n_fit, near)) <= _float32_limit(camera, "near"):
            kind = "float32_near"
        else:
            kind = "near"
    elif f_fit is None:
        kind = "far"
    elif abs(_rel(f_fit, far)) > NAMING.plane_rel_tol:
        kind = "float32_far" if abs(_rel(f_fit, far)) <= _float32_limit(camera, "far") else "far"
    if kind is None:
        return None
    return {"name": "clipping_plane", "kind": kind, **fields, "hint": _hint(kind)}


def depth_slack(planes: dict | None, camera) -> tuple[float, str | None]:
    """``(depth, why)``: how far (world units of depth) inside near or far a clipped end must lie for
    this candidate's own planes to keep it, when they differ from the camera's by float32 rounding only
    (0.0 and None otherwise: a plane off by more is a fault, not accommodated)."""
    if planes is None or not planes["front"]:
        return 0.0, None
    slack, why = 0.0, []
    for which, plane in (("near", float(camera.near)), ("far", float(camera.far))):
        fit = planes[f"{which}_fit"]
        if fit is None:
            continue
        inward = (fit - plane) if which == "near" else (plane - fit)
        if NAMING.plane_rel_tol * plane < inward <= _float32_limit(camera, which) * plane:
            slack = max(slack, 2.0 * inward)
            why.append(f"the candidate clips at {which} {fit!r} (camera: {plane!r}; float32 rounding)")
    return slack, ("; ".join(why) or None)
