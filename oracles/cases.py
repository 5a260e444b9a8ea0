"""The fixed set of cameras crosscheck runs each scene under.

Every camera is placed relative to the scene's bounding-sphere radius ``r``
(about the origin), so the same set fits any scene. The first seven are the
default set (``CASE_NAMES``); the calibrated ones (``CALIBRATED_CASE_NAMES``)
run when named (``--cases off_centre,...``): a projector written for the FOV
camera of the candidate contract is not wrong on those seven, and its
verdicts stay what they were. The table is repeated in docs/crosscheck.md
("Cases").

    name          what it exercises
    on_axis       camera on +Z at 3r, looking at the origin, fov 60, 640x480
    oblique_roll  from (2, 1.5, 2.5) r, up tilted (0.3, 1, 0.2): roll, all three axes
    near_plane    inside the bounding sphere with near = 0.35 r: edges cross the near plane
    wide_fov      fov 120 at 1.4 r: strong perspective, edges leave the image
    narrow_fov    fov 8 at 25 r: nearly orthographic
    non_square    320x480 portrait, oblique, fov 50: aspect handling
    orthographic  orthographic from an oblique direction, 3r visible vertically
    (named with --cases only:)
    off_centre    calibrated K: principal point (70, -45) px off centre, fx = fy
    non_square_pixels  calibrated K: fx = 1.3 fy (centred): per-axis focal lengths
    distorted     calibrated K with OpenCV lens distortion (k1, k2, p1, p2, k3):
                  vertices only (GL draws straight lines; the report says so)
"""

from __future__ import annotations

from dataclasses import dataclass

from wirecheck.core.camera import Camera, look_at


@dataclass(frozen=True)
class Case:
    name: str
    camera: Camera


def cameras_for(radius: float, calibrated: bool = False) -> list[Case]:
    """The default cases for a scene of bounding radius ``radius``; with ``calibrated``, the calibrated ones too."""
    r = radius if radius > 0 else 1.0
    o = (0.0, 0.0, 0.0)
    return [
        Case("on_axis", look_at((0, 0, 3 * r), o, (0, 1, 0), fov_y_deg=60, near=0.1 * r, far=10 * r)),
        Case("oblique_roll", look_at((2 * r, 1.5 * r, 2.5 * r), o, (0.3, 1.0, 0.2), fov_y_deg=55,
                                     near=0.1 * r, far=10 * r)),
        Case("near_plane", look_at((0.1 * r, 0.15 * r, 0.75 * r), (0, 0, -r), (0, 1, 0), fov_y_deg=90,
                                   near=0.35 * r, far=10 * r)),
        Case("wide_fov", look_at((0.2 * r, 0.3 * r, 1.4 * r), o, (0, 1, 0), fov_y_deg=120, near=0.05 * r, far=10 * r)),
        Case("narrow_fov", look_at((0.5 * r, 1.0 * r, 25 * r), o, (0, 1, 0), fov_y_deg=8, near=r, far=50 * r)),
        Case("non_square", look_at((-2 * r, 1.0 * r, 2.5 * r), o, (0, 1, 0), fov_y_deg=50, width=320, height=480,
                                   near=0.1 * r, far=10 * r)),
        Case("orthographic", look_at((2 * r, 2 * r, 3 * r), o, (0, 1, 0), projection="orthographic",
                                     ortho_height=3 * r, near=0.1 * r, far=10 * r)),
    ] + (calibrated_cases(r, o) if calibrated else [])


#: The distorted case's lens (OpenCV order k1, k2, p1, p2, k3): a moderate barrel
#: lens of the size calibrations of webcams report. r * radial(r) is increasing
#: out to the image corners (r_n <= 0.87 here: 1 + 3 k1 r2 + 5 k2 r2^2 + 7 k3 r2^3 > 0.6),
#: so the image is not folded.
DISTORTION = (-0.22, 0.06, 0.0012, -0.0009, -0.008)


def calibrated_cases(r: float, o=(0.0, 0.0, 0.0)) -> list[Case]:
    """The calibrated cameras (intrinsics fx, fy, cx, cy; lens distortion), 640x480, 2.6-3 r from ``o``."""
    o = tuple(float(v) for v in o)

    def at(offset):
        return tuple(c + d * r for c, d in zip(o, offset))

    return [
        Case("off_centre", look_at(at((-1.5, 1.0, 2.6)), o, (0, 1, 0), near=0.1 * r, far=10 * r,
                                   intrinsics=(460.0, 460.0, 319.5 + 70.0, 239.5 - 45.0))),
        Case("non_square_pixels", look_at(at((1.2, -0.8, 2.8)), o, (0, 1, 0), near=0.1 * r, far=10 * r,
                                          intrinsics=(520.0, 400.0, 319.5, 239.5))),
        Case("distorted", look_at(at((0.4, 0.6, 2.6)), o, (0, 1, 0), near=0.1 * r, far=10 * r,
                                  intrinsics=(470.0, 465.0, 325.2, 236.8), distortion=DISTORTION)),
    ]


#: The default set, and what ``--cases`` may name besides (in this order).
CASE_NAMES = tuple(c.name for c in cameras_for(1.0))
CALIBRATED_CASE_NAMES = tuple(c.name for c in calibrated_cases(1.0))
ALL_CASE_NAMES = CASE_NAMES + CALIBRATED_CASE_NAMES


def case_table() -> str:
    return __doc__.split("\n\n", 2)[2].strip()


__all__ = ["Case", "cameras_for", "calibrated_cases", "CASE_NAMES", "CALIBRATED_CASE_NAMES", "ALL_CASE_NAMES",
           "DISTORTION"]
