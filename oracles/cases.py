"""The fixed set of cameras crosscheck runs each scene under, framed on the scene.

Every camera is placed relative to the scene's framing sphere, centre ``c`` and
radius ``r`` (:func:`framing`), so the same set fits any scene, wherever it
is. The first seven are the default set (``CASE_NAMES``); the calibrated ones
(``CALIBRATED_CASE_NAMES``) run when named (``--cases calibrated``, ...): a
projector written for the FOV camera of the candidate contract is not wrong
on those seven, and its verdicts stay what they were. The table is repeated in
docs/crosscheck.md ("Cases").

    name          what it exercises
    on_axis       camera at c + 3r on +Z, looking at c, fov 60, 640x480
    oblique_roll  from c + (2, 1.5, 2.5) r, up tilted (0.3, 1, 0.2): roll, all three axes
    near_plane    inside the framing sphere with near = 0.35 r: edges cross the near plane
    wide_fov      fov 120 at 1.4 r: strong perspective, edges leave the image
    narrow_fov    fov 8 at 25 r: nearly orthographic
    non_square    320x480 portrait, oblique, fov 50: aspect handling
    orthographic  orthographic from an oblique direction, 3r visible vertically
    (named with --cases only:)
    off_centre    calibrated K: principal point (70, -45) px off centre, fx = fy
    non_square_pixels  calibrated K: fx = 1.3 fy (centred): per-axis focal lengths
    distorted     calibrated K with OpenCV lens distortion (k1, k2, p1, p2, k3):
                  vertices only (GL draws straight lines; the report says so)

The framing sphere holds the scene in every frame of the run. Two spheres
qualify: the one about the origin (``Scene.radius``, a bound over the
objects' own motions; the run's turns about the origin keep it), and the one
about the centre ``c`` of the scene's box over its objects' motions
(:func:`centred_sphere`), with the run turning about ``c`` instead
(``Motion.pivot``, :func:`case_motion`). The scene is framed on ``c`` when
the origin is outside that box (a mesh placed away from the origin: it now
spins in place and fills the image), or when the origin's sphere is at least
:data:`REFRAME_RATIO` times the centred one (the origin near a corner of the
box; with the origin inside, the ratio is at most ``1 + sqrt(3)``, as each
half-extent of the box is at most ``r``). Otherwise, as for a scene modelled
about the origin (every bundled scene: ratios 1 to 1.05), the origin framing
and spin are kept, bit for bit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from wirecheck.core.camera import Camera, look_at
from wirecheck.core.scene.model import Scene, radius_about
from wirecheck.core.transforms import Motion

#: A scene whose box holds the origin is framed on its own centre only when
#: the origin's sphere is at least this many times larger (it would fill at
#: most half the image it can); below that it keeps turning about the origin
#: it was modelled about (the orrery: 3.37 against 3.22, a 1.05 ratio).
REFRAME_RATIO = 2.0

ORIGIN = (0.0, 0.0, 0.0)


@dataclass(frozen=True)
class Case:
    """A named camera, framed on the sphere (``centre``, ``radius``).

    ``pivot`` is the model point the run turns about (the framing centre
    before the run's offset; the origin unless the scene was reframed).
    """

    name: str
    camera: Camera
    pivot: tuple = ORIGIN
    centre: tuple = ORIGIN
    radius: float = 1.0

    def framing(self) -> dict:
        """The case's framing, for reports: ``{"centre", "radius", "pivot"}``."""
        return {
            "centre": [float(x) for x in self.centre],
            "radius": float(self.radius),
            "pivot": [float(x) for x in self.pivot],
        }


def cameras_for(radius: float, centre=ORIGIN, pivot=ORIGIN, calibrated: bool = False) -> list[Case]:
    """The cases' cameras about the sphere (``centre``, ``radius``), each with ``pivot``.

    The default cases; with ``calibrated``, the calibrated ones too.
    """
    r = radius if radius > 0 else 1.0
    cx, cy, cz = (float(x) for x in centre)
    moved = any((cx, cy, cz))

    def at(x, y, z):
        # about the origin, the very tuples used before framing existed (same bytes)
        return (cx + x, cy + y, cz + z) if moved else (x, y, z)

    o = at(0.0, 0.0, 0.0)
    framed = {"pivot": tuple(float(x) for x in pivot), "centre": (cx, cy, cz), "radius": float(r)}
    return [
        Case("on_axis", look_at(at(0, 0, 3 * r), o, (0, 1, 0), fov_y_deg=60, near=0.1 * r, far=10 * r), **framed),
        Case(
            "oblique_roll",
            look_at(at(2 * r, 1.5 * r, 2.5 * r), o, (0.3, 1.0, 0.2), fov_y_deg=55, near=0.1 * r, far=10 * r),
            **framed,
        ),
        Case(
            "near_plane",
            look_at(at(0.1 * r, 0.15 * r, 0.75 * r), at(0, 0, -r), (0, 1, 0), fov_y_deg=90, near=0.35 * r, far=10 * r),
            **framed,
        ),
        Case(
            "wide_fov",
            look_at(at(0.2 * r, 0.3 * r, 1.4 * r), o, (0, 1, 0), fov_y_deg=120, near=0.05 * r, far=10 * r),
            **framed,
        ),
        Case(
            "narrow_fov", look_at(at(0.5 * r, 1.0 * r, 25 * r), o, (0, 1, 0), fov_y_deg=8, near=r, far=50 * r), **framed
        ),
        Case(
            "non_square",
            look_at(
                at(-2 * r, 1.0 * r, 2.5 * r),
                o,
                (0, 1, 0),
                fov_y_deg=50,
                width=320,
                height=480,
                near=0.1 * r,
                far=10 * r,
            ),
            **framed,
        ),
        Case(
            "orthographic",
            look_at(
                at(2 * r, 2 * r, 3 * r),
                o,
                (0, 1, 0),
                projection="orthographic",
                ortho_height=3 * r,
                near=0.1 * r,
                far=10 * r,
            ),
            **framed,
        ),
    ] + (calibrated_cases(r, o, framed) if calibrated else [])


#: The distorted case's lens (OpenCV order k1, k2, p1, p2, k3): a moderate barrel
#: lens of the size calibrations of webcams report. r * radial(r) is increasing
#: out to the image corners (r_n <= 0.87 here: 1 + 3 k1 r2 + 5 k2 r2^2 + 7 k3 r2^3 > 0.6),
#: so the image is not folded.
DISTORTION = (-0.22, 0.06, 0.0012, -0.0009, -0.008)


def calibrated_cases(r: float, o=ORIGIN, framed: dict | None = None) -> list[Case]:
    """The calibrated cameras (intrinsics fx, fy, cx, cy; lens distortion), 640x480, 2.6-3 r from ``o``."""
    o = tuple(float(v) for v in o)
    framed = framed or {}

    def at(offset):
        return tuple(c + d * r for c, d in zip(o, offset))

    return [
        Case(
            "off_centre",
            look_at(
                at((-1.5, 1.0, 2.6)),
                o,
                (0, 1, 0),
                near=0.1 * r,
                far=10 * r,
                intrinsics=(460.0, 460.0, 319.5 + 70.0, 239.5 - 45.0),
            ),
            **framed,
        ),
        Case(
            "non_square_pixels",
            look_at(
                at((1.2, -0.8, 2.8)), o, (0, 1, 0), near=0.1 * r, far=10 * r, intrinsics=(520.0, 400.0, 319.5, 239.5)
            ),
            **framed,
        ),
        Case(
            "distorted",
            look_at(
                at((0.4, 0.6, 2.6)),
                o,
                (0, 1, 0),
                near=0.1 * r,
                far=10 * r,
                intrinsics=(470.0, 465.0, 325.2, 236.8),
                distortion=DISTORTION,
            ),
            **framed,
        ),
    ]


def centred_sphere(scene: Scene) -> tuple[np.ndarray, float, bool]:
    """``(c (3,), r, holds_origin)``: the centre of the scene's box over its objects' own motions, a radius about it.

    A static object contributes its points (``offset + scale * p``); a turning
    one the sphere its points sweep (about ``offset``, radius
    ``|scale| * max |p|``: a turn about the object's origin keeps that
    distance). ``r`` bounds the scene about ``c`` in every frame;
    ``holds_origin`` says whether the box holds the origin.
    """
    if scene.is_single_static:
        v = scene.vertices
        if len(v) == 0:
            return np.zeros(3), 0.0, True
        lo, hi = v.min(axis=0), v.max(axis=0)
        c = 0.5 * lo + 0.5 * hi
        return c, radius_about(v, c), bool(np.all(lo <= 0.0) and np.all(hi >= 0.0))
    parts = []  # (points (K, 3) or None, centre (3,), sphere radius)
    for o in scene.objects:
        if o.vertex_count == 0:
            continue
        m, v = o.motion, scene.vertices[o.vertex_start : o.vertex_stop]
        off = np.asarray(m.offset, dtype=np.float64)
        if not any(float(t) for t in m.turns):
            parts.append((off + float(m.scale) * v, off, 0.0))
        else:
            parts.append((None, off, abs(float(m.scale)) * radius_about(v, ORIGIN)))
    if not parts:
        return np.zeros(3), 0.0, True
    lo = np.min([p.min(axis=0) if p is not None else off - rho for p, off, rho in parts], axis=0)
    hi = np.max([p.max(axis=0) if p is not None else off + rho for p, off, rho in parts], axis=0)
    c = 0.5 * lo + 0.5 * hi
    r = max(radius_about(p, c) if p is not None else radius_about(off[None], c) + rho for p, off, rho in parts)
    return c, r, bool(np.all(lo <= 0.0) and np.all(hi >= 0.0))


def framing(scene: Scene, motion: Motion | None = None) -> tuple[tuple, float, tuple]:
    """``(centre, radius, pivot)``: the sphere the cameras are placed about (module docstring).

    ``centre`` and ``radius`` are in world units under the run's ``motion``
    (its offset and scale; the default has neither); ``pivot`` is the model
    point the run turns about (the origin, or the scene's centre).
    """
    motion = motion or Motion()
    r_origin = scene.radius
    c, r_centre, holds_origin = centred_sphere(scene)
    s = abs(float(motion.scale))
    finite = math.isfinite(r_centre) and bool(np.all(np.isfinite(c)))
    if finite and (not holds_origin or REFRAME_RATIO * r_centre <= r_origin):
        pivot = tuple(float(x) for x in c)
        radius = r_centre
    else:
        pivot, radius = ORIGIN, r_origin
    if s != 1.0:
        radius = s * radius
    centre = tuple(float(o) + p for o, p in zip(motion.offset, pivot))
    return centre, radius, pivot


def cases_for(scene: Scene, motion: Motion | None = None, calibrated: bool = False) -> list[Case]:
    """The cases of ``scene`` under the run's ``motion``, framed on it (:func:`framing`)."""
    centre, radius, pivot = framing(scene, motion)
    return cameras_for(radius, centre, pivot, calibrated)


def case_motion(motion: Motion, case: Case) -> Motion:
    """The run's ``motion`` turning about the case's pivot (``motion`` itself about the origin)."""
    if not any(case.pivot):
        return motion
    return replace(motion, pivot=tuple(case.pivot))


CASE_NAMES = tuple(c.name for c in cameras_for(1.0))
CALIBRATED_CASE_NAMES = tuple(c.name for c in calibrated_cases(1.0))
ALL_CASE_NAMES = CASE_NAMES + CALIBRATED_CASE_NAMES


def case_table() -> str:
    return __doc__.split("\n\n", 2)[2].split("\n\n", 1)[0].strip()


__all__ = [
    "Case",
    "cameras_for",
    "cases_for",
    "case_motion",
    "framing",
    "centred_sphere",
    "calibrated_cases",
    "CASE_NAMES",
    "CALIBRATED_CASE_NAMES",
    "ALL_CASE_NAMES",
    "DISTORTION",
    "REFRAME_RATIO",
]
