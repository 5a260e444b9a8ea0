"""The fixed set of cameras crosscheck runs each scene under.

Every camera is placed relative to the scene's bounding-sphere radius ``r``
(about the origin), so the same set fits any scene. The table is repeated in
the README ("Cases").

    name          what it exercises
    on_axis       camera on +Z at 3r, looking at the origin, fov 60, 640x480
    oblique_roll  from (2, 1.5, 2.5) r, up tilted (0.3, 1, 0.2): roll, all three axes
    near_plane    inside the bounding sphere with near = 0.35 r: edges cross the near plane
    wide_fov      fov 120 at 1.4 r: strong perspective, edges leave the image
    narrow_fov    fov 8 at 25 r: nearly orthographic
    non_square    320x480 portrait, oblique, fov 50: aspect handling
    orthographic  orthographic from an oblique direction, 3r visible vertically
"""

from __future__ import annotations

from dataclasses import dataclass

from wirecheck.core.camera import Camera, look_at


@dataclass(frozen=True)
class Case:
    name: str
    camera: Camera


def cameras_for(radius: float) -> list[Case]:
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
    ]


CASE_NAMES = tuple(c.name for c in cameras_for(1.0))


def case_table() -> str:
    return __doc__.split("\n\n", 2)[2].strip()


__all__ = ["Case", "cameras_for", "CASE_NAMES"]
