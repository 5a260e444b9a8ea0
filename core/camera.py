"""Cameras: a frozen dataclass validated when built, and ``world_to_cam``.

Axes and signs are defined in :mod:`core.conventions`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .conventions import focal_px, principal_point
from .errors import InputError

PROJECTIONS = ("perspective", "orthographic")

# A camera whose forward and up are closer than this to parallel has no
# well-defined "right": |forward x up| below 1e-9 means the angle is < 1e-9 rad,
# far below anything a user means on purpose, far above float64 noise (1e-16).
_DEGENERATE_CROSS = 1e-9


def _vec3(name: str, value) -> np.ndarray:
    v = np.asarray(value, dtype=np.float64)
    if v.shape != (3,):
        raise InputError(f"camera {name}: expected 3 numbers, got {value!r}")
    if not np.all(np.isfinite(v)):
        raise InputError(f"camera {name}: expected finite numbers, got {value!r}")
    return v


@dataclass(frozen=True)
class Camera:
    """A pinhole (or orthographic) camera, frozen and validated when built.

    Build cameras with :func:`look_at` or :func:`camera_z` rather than by
    hand. Axes, pixel centres and the FOV axis are those of
    :mod:`wirecheck.core.conventions`.

    Parameters
    ----------
    position : (3,) array_like of float
        The centre of projection, world coordinates.
    forward : (3,) array_like of float
        View direction (any non-zero length; stored unit length).
    up : (3,) array_like of float
        Toward the top of the image; need not be orthogonal to ``forward``
        (stored as its unit component orthogonal to it).
    fov_y_deg : float
        Full vertical field of view in degrees, edge to edge of the image
        (perspective only), in (0, 180).
    width, height : int
        Image size in pixels.
    near, far : float
        Clip planes: a point is visible when ``near <= depth <= far``.
    projection : {"perspective", "orthographic"}
    ortho_height : float
        World units visible vertically (orthographic only).

    Attributes
    ----------
    right : (3,) ndarray of float64
        ``forward x up``: toward the right of the image.

    Raises
    ------
    InputError
        Non-finite values, a zero ``forward``, ``up`` parallel to ``forward``,
        or a size, FOV or clip range out of its domain.
    """

    position: np.ndarray
    forward: np.ndarray
    up: np.ndarray
    fov_y_deg: float = 60.0
    width: int = 640
    height: int = 480
    near: float = 0.1
    far: float = 100.0
    projection: str = "perspective"
    ortho_height: float = 2.0
    right: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        position = _vec3("position", self.position)
        forward = _vec3("forward", self.forward)
        up = _vec3("up", self.up)
        if not np.any(forward):
            raise InputError("camera forward: expected a non-zero direction (is the camera at the look-at point?)")
        forward = forward / np.abs(forward).max()   # scale first: norm() of 1e-200 underflows to 0
        forward = forward / np.linalg.norm(forward)
        if np.any(up):
            up = up / np.abs(up).max()              # likewise for a tiny up
        right = np.cross(forward, up)
        nr = np.linalg.norm(right)
        if nr < _DEGENERATE_CROSS * max(np.linalg.norm(up), 1e-300):
            raise InputError(
                f"camera up {up.tolist()}: expected a direction not parallel to forward {forward.tolist()}")
        right = right / nr
        up = np.cross(right, forward)  # re-orthogonalised, unit by construction
        object.__setattr__(self, "position", position)
        object.__setattr__(self, "forward", forward)
        object.__setattr__(self, "up", up / np.linalg.norm(up))
        object.__setattr__(self, "right", right)
        for a in (self.position, self.forward, self.up, self.right):
            a.setflags(write=False)
        if self.projection not in PROJECTIONS:
            raise InputError(f"camera projection {self.projection!r}: expected one of {', '.join(PROJECTIONS)}")
        if not (isinstance(self.width, (int, np.integer)) and isinstance(self.height, (int, np.integer))) \
                or self.width < 1 or self.height < 1:
            raise InputError(f"camera size {self.width}x{self.height}: expected positive integers")
        if self.projection == "perspective" and not (0.0 < float(self.fov_y_deg) < 180.0):
            raise InputError(f"camera fov {self.fov_y_deg!r}: expected degrees in (0, 180)")
        if not (math.isfinite(self.near) and math.isfinite(self.far)):
            raise InputError(f"camera near/far {self.near!r}/{self.far!r}: expected finite numbers")
        if self.projection == "perspective" and not self.near > 0:
            raise InputError(f"camera near {self.near!r}: expected > 0 for a perspective camera")
        if not self.far > self.near:
            raise InputError(f"camera far {self.far!r}: expected > near ({self.near!r})")
        if not (math.isfinite(self.ortho_height) and self.ortho_height > 0):   # also perspective: it is reported
            raise InputError(f"camera ortho-height {self.ortho_height!r}: expected a finite number > 0")
        # A positive but tiny fov or ortho-height passes the range checks yet makes the
        # focal length / pixel scale overflow to inf: say so here, not later as a
        # "vertex projects beyond the float64 range".
        if self.projection == "perspective" and not math.isfinite(self.focal_px):
            raise InputError(f"camera fov {self.fov_y_deg!r}: focal length (H/2)/tan(fov/2) overflows float64; "
                             "expected a larger fov")
        if self.projection == "orthographic" and not math.isfinite(self.height / self.ortho_height):
            raise InputError(f"camera ortho-height {self.ortho_height!r}: pixel scale H/ortho-height overflows "
                             "float64; expected a larger ortho-height")

    # ---- derived quantities (see core.conventions) -------------------------
    @property
    def focal_px(self) -> float:
        return focal_px(self.fov_y_deg, self.height)

    @property
    def principal_point(self) -> tuple[float, float]:
        return principal_point(self.width, self.height)

    @property
    def world_to_cam(self) -> np.ndarray:
        """4x4 matrix taking p_world to p_cam (x right, y up, z forward)."""
        m = np.eye(4)
        r = np.stack([self.right, self.up, self.forward])
        m[:3, :3] = r
        m[:3, 3] = -r @ self.position
        return m

    def to_dict(self) -> dict:
        return {
            "position": [float(x) for x in self.position],
            "forward": [float(x) for x in self.forward],
            "up": [float(x) for x in self.up],
            "fov_y_deg": float(self.fov_y_deg),
            "width": int(self.width),
            "height": int(self.height),
            "near": float(self.near),
            "far": float(self.far),
            "projection": self.projection,
            "ortho_height": float(self.ortho_height),
        }


def look_at(position, target, up=(0.0, 1.0, 0.0), **kwargs) -> Camera:
    """A camera at ``position`` looking at ``target``.

    Parameters
    ----------
    position, target : (3,) array_like of float
        World coordinates; they must differ.
    up : (3,) array_like of float
        Toward the top of the image; need not be orthogonal to the view direction.
    **kwargs
        Any other :class:`Camera` field (``fov_y_deg``, ``width``, ``height``,
        ``near``, ``far``, ``projection``, ``ortho_height``).

    Returns
    -------
    Camera

    Examples
    --------
    >>> cam = look_at((0, 0, 4), (0, 0, 0), fov_y_deg=70)
    >>> cam.forward.tolist(), cam.up.tolist()
    ([0.0, 0.0, -1.0], [0.0, 1.0, 0.0])
    """
    position = _vec3("position", position)
    target = _vec3("look-at", target)
    forward = target - position
    if not np.any(forward):                     # exact test: norm() underflows to 0 below ~1e-160
        raise InputError(f"camera position {position.tolist()}: expected a point different from look-at {target.tolist()}")
    return Camera(position=position, forward=forward, up=_vec3("up", up), **kwargs)


def camera_z(distance: float, **kwargs) -> Camera:
    """The ``--camera-z D`` shortcut: a camera at (0, 0, D) looking at the origin, up +Y.

    Parameters
    ----------
    distance : float
        D, the camera's z coordinate (non-zero).
    **kwargs
        Any other :class:`Camera` field.

    Returns
    -------
    Camera
    """
    return look_at((0.0, 0.0, float(distance)), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0), **kwargs)


def orthographic_twin(camera: Camera, distance: float) -> Camera:
    """An orthographic camera with ``camera``'s pose and ``ortho_height = 2 d tan(fov_y / 2)``.

    At depth ``d`` a perspective camera sees ``2 d tan(fov_y / 2)`` world units
    vertically, so an object at the look-at distance ``d`` has the same size in
    pixels in both pictures (nearer things are bigger only in perspective).
    """
    height = 2.0 * distance * math.tan(math.radians(camera.fov_y_deg) / 2.0)
    return Camera(position=camera.position, forward=camera.forward, up=camera.up, fov_y_deg=camera.fov_y_deg,
                  width=camera.width, height=camera.height, near=camera.near, far=camera.far,
                  projection="orthographic", ortho_height=height)
