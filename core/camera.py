"""Cameras: a frozen dataclass validated when built, and ``world_to_cam``.

Axes and signs are defined in :mod:`core.conventions`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from .conventions import focal_px, principal_point
from .errors import InputError

PROJECTIONS = ("perspective", "orthographic")

# A camera whose forward and up are closer than this to parallel has no
# well-defined "right": |forward x up| below 1e-9 means the angle is < 1e-9 rad,
# far below anything a user means on purpose, far above float64 noise (1e-16).
_DEGENERATE_CROSS = 1e-9


#: Intrinsics are bounded by this factor of the larger image side: fx, fy, |cx|,
#: |cy| <= 1e6 x side and fx, fy >= side / 1e6. A focal length of 1e6 sides is a
#: field of view of 1e-4 degrees; one of 1e-6 sides sees all but 1e-4 degrees of
#: the half-space, so pixels stay within ~1e12 of the image for points inside
#: the frustum's reach, far from float64 (and float32) overflow.
_MAX_INTRINSIC = 1e6


def _numbers(name: str, value, shape: tuple) -> tuple:
    """``value`` as a flat tuple of finite Python floats of ``shape``; InputError otherwise."""
    try:
        v = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        v = None
    if v is None or v.shape != shape:
        raise InputError(f"camera {name}: expected {' x '.join(map(str, shape))} numbers, got {value!r}")
    if not np.all(np.isfinite(v)):
        raise InputError(f"camera {name}: expected finite numbers, got {value!r}")
    return tuple(float(x) for x in v.reshape(-1))


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
    intrinsics : (4,) tuple of float or None
        ``(fx, fy, cx, cy)`` in pixels, a calibrated pinhole camera
        (perspective only; :mod:`wirecheck.core.conventions`, "Calibrated
        cameras"). ``None`` (the default): ``fx = fy = f_px`` from
        ``fov_y_deg`` and the centred principal point. When given,
        ``fov_y_deg`` is replaced by the FOV ``fy`` implies, for reports.
        Easiest built with :meth:`with_intrinsics` or :meth:`with_K`.
    distortion : tuple of float or None
        OpenCV lens distortion ``(k1, k2, p1, p2[, k3[, k4, k5, k6]])``
        (4, 5 or 8 numbers; perspective only; :mod:`wirecheck.core.projector.distortion`).
        ``None`` or all zeros: no distortion (stored as ``None``).

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
    intrinsics: tuple | None = None
    distortion: tuple | None = None
    right: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        position = _vec3("position", self.position)
        forward = _vec3("forward", self.forward)
        up = _vec3("up", self.up)
        if not np.any(forward):
            raise InputError("camera forward: expected a non-zero direction (is the camera at the look-at point?)")
        forward = forward / np.abs(forward).max()  # scale first: norm() of 1e-200 underflows to 0
        forward = forward / np.linalg.norm(forward)
        if np.any(up):
            up = up / np.abs(up).max()  # likewise for a tiny up
        right = np.cross(forward, up)
        nr = np.linalg.norm(right)
        if nr < _DEGENERATE_CROSS * max(np.linalg.norm(up), 1e-300):
            raise InputError(
                f"camera up {up.tolist()}: expected a direction not parallel to forward {forward.tolist()}"
            )
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
        if (
            not (isinstance(self.width, (int, np.integer)) and isinstance(self.height, (int, np.integer)))
            or self.width < 1
            or self.height < 1
        ):
            raise InputError(f"camera size {self.width}x{self.height}: expected positive integers")
        if self.projection == "perspective" and not (0.0 < float(self.fov_y_deg) < 180.0):
            raise InputError(f"camera fov {self.fov_y_deg!r}: expected degrees in (0, 180)")
        if not (math.isfinite(self.near) and math.isfinite(self.far)):
            raise InputError(f"camera near/far {self.near!r}/{self.far!r}: expected finite numbers")
        if self.projection == "perspective" and not self.near > 0:
            raise InputError(f"camera near {self.near!r}: expected > 0 for a perspective camera")
        if not self.far > self.near:
            raise InputError(f"camera far {self.far!r}: expected > near ({self.near!r})")
        if not (math.isfinite(self.ortho_height) and self.ortho_height > 0):  # also perspective: it is reported
            raise InputError(f"camera ortho-height {self.ortho_height!r}: expected a finite number > 0")
        self._check_intrinsics()
        # A positive but tiny fov or ortho-height passes the range checks yet makes the
        # focal length / pixel scale overflow to inf: say so here, not later as a
        # "vertex projects beyond the float64 range".
        if self.projection == "perspective" and not math.isfinite(self.focal_px):
            raise InputError(
                f"camera fov {self.fov_y_deg!r}: focal length (H/2)/tan(fov/2) overflows float64; expected a larger fov"
            )
        if self.projection == "orthographic" and not math.isfinite(self.height / self.ortho_height):
            raise InputError(
                f"camera ortho-height {self.ortho_height!r}: pixel scale H/ortho-height overflows "
                "float64; expected a larger ortho-height"
            )

    def _check_intrinsics(self) -> None:
        """Validate and normalise ``intrinsics`` and ``distortion`` (tuples of floats, or None)."""
        if self.intrinsics is not None:
            values = _numbers("intrinsics fx,fy,cx,cy", self.intrinsics, (4,))
            if self.projection != "perspective":
                raise InputError(
                    f"camera intrinsics {list(values)}: expected a perspective camera (got {self.projection})"
                )
            fx, fy, cx, cy = values
            if not (fx > 0 and fy > 0):
                raise InputError(f"camera intrinsics fx={fx!r}, fy={fy!r}: expected focal lengths > 0 (pixels)")
            limit = _MAX_INTRINSIC * max(self.width, self.height)
            if max(fx, fy, abs(cx), abs(cy)) > limit:
                raise InputError(
                    f"camera intrinsics {list(values)}: expected |fx|, |fy|, |cx|, |cy| <= "
                    f"{limit:g} ({_MAX_INTRINSIC:g} x the larger image side)"
                )
            if min(fx, fy) < max(self.width, self.height) / _MAX_INTRINSIC:
                raise InputError(
                    f"camera intrinsics fx={fx!r}, fy={fy!r}: expected focal lengths >= "
                    f"{max(self.width, self.height) / _MAX_INTRINSIC:g} px (the larger image "
                    f"side / {_MAX_INTRINSIC:g}: a field of view under 180 degrees by a margin)"
                )
            object.__setattr__(self, "intrinsics", values)
            object.__setattr__(self, "fov_y_deg", math.degrees(2.0 * math.atan((self.height / 2.0) / fy)))
        if self.distortion is not None:
            coeffs = check_coefficients(self.distortion)
            if coeffs is not None and self.projection != "perspective":
                raise InputError(
                    f"camera distortion {list(coeffs)}: expected a perspective camera (got {self.projection})"
                )
            object.__setattr__(self, "distortion", coeffs)

    # ---- derived quantities (see core.conventions) -------------------------
    @property
    def calibrated(self) -> bool:
        """True when built from intrinsics (fx, fy, cx, cy) rather than from the vertical FOV."""
        return self.intrinsics is not None

    @property
    def focal_xy(self) -> tuple[float, float]:
        """``(fx, fy)`` in pixels (perspective): the intrinsics, else ``f_px`` of the FOV for both."""
        if self.intrinsics is not None:
            return self.intrinsics[0], self.intrinsics[1]
        f = focal_px(self.fov_y_deg, self.height)
        return f, f

    @property
    def focal_px(self) -> float:
        """The vertical focal length ``fy`` in pixels (``f_px`` of the FOV when not calibrated)."""
        return self.focal_xy[1]

    @property
    def principal_point(self) -> tuple[float, float]:
        """``(cx, cy)``: the intrinsics', else the centred one (core.conventions)."""
        if self.intrinsics is not None:
            return self.intrinsics[2], self.intrinsics[3]
        return principal_point(self.width, self.height)

    @property
    def K(self) -> np.ndarray:  # noqa: N802 (the name every calibration text uses)
        """``(3, 3)`` intrinsic matrix ``[[fx, 0, cx], [0, fy, cy], [0, 0, 1]]`` (a new array).

        Orthographic: the affine ``[[s, 0, cx], [0, s, cy], [0, 0, 1]]`` with
        ``s = H / ortho_height`` (no division by depth).
        """
        cx, cy = self.principal_point
        if self.projection == "perspective":
            fx, fy = self.focal_xy
        else:
            fx = fy = self.height / self.ortho_height
        return np.array([[fx, 0.0, cx], [0.0, fy, cy], [0.0, 0.0, 1.0]])

    # ---- the same camera as the matrices other libraries take (candidate contract) ----
    @property
    def R(self) -> np.ndarray:  # noqa: N802
        """``(3, 3)`` world -> OpenCV camera rotation (rows right, -up, forward: OpenCV's y is down)."""
        return np.stack([self.right, -self.up, self.forward])

    @property
    def t(self) -> np.ndarray:
        """``(3,)`` world -> OpenCV camera translation: ``p_cv = R @ p_world + t``."""
        return -self.R @ self.position

    @property
    def view_matrix(self) -> np.ndarray:
        """``(4, 4)`` world -> OpenGL eye space (x right, y up, z backward: rows right, up, -forward)."""
        m = np.eye(4)
        m[:3, :3] = np.stack([self.right, self.up, -self.forward])
        m[:3, 3] = -m[:3, :3] @ self.position
        return m

    @property
    def projection_matrix(self) -> np.ndarray:
        """``(4, 4)`` OpenGL eye -> clip (``glFrustum`` / ``glOrtho`` form; NDC z -1 at near).

        Perspective, from the intrinsics (GL pixel centres at half-integers)::

            [[2 fx / W, 0, 1 - 2 (cx + 0.5) / W, 0],
             [0, 2 fy / H, 2 (cy + 0.5) / H - 1, 0],
             [0, 0, (far + near) / (near - far), 2 far near / (near - far)],
             [0, 0, -1, 0]]

        so ``x_win = (x_ndc + 1) W / 2 = x_px + 0.5`` and ``y_win = H - (y_px +
        0.5)`` (GL's window y is up). Orthographic: ``diag(2 s / W, 2 s / H,
        -2 / (far - near), 1)`` with ``[2, 3] = -(far + near) / (far - near)``,
        ``s = H / ortho_height``. Lens distortion is not in it.
        """
        w, h, n, f = self.width, self.height, float(self.near), float(self.far)
        cx, cy = self.principal_point
        p = np.zeros((4, 4))
        if self.projection == "perspective":
            fx, fy = self.focal_xy
            p[0, 0], p[1, 1] = 2.0 * fx / w, 2.0 * fy / h
            p[0, 2], p[1, 2] = 1.0 - 2.0 * (cx + 0.5) / w, 2.0 * (cy + 0.5) / h - 1.0
            p[2, 2], p[2, 3], p[3, 2] = (f + n) / (n - f), 2.0 * f * n / (n - f), -1.0
        else:
            s = h / self.ortho_height
            p[0, 0], p[1, 1] = 2.0 * s / w, 2.0 * s / h
            p[2, 2], p[2, 3], p[3, 3] = -2.0 / (f - n), -(f + n) / (f - n), 1.0
        return p

    def _replace_lens(self, **changes) -> Camera:
        """``dataclasses.replace`` keeping the pose's vectors to the bit (re-normalising may move an ulp)."""
        cam = replace(self, **changes)
        for name in ("position", "forward", "up", "right"):
            object.__setattr__(cam, name, getattr(self, name))
        return cam

    def with_intrinsics(self, fx: float, fy: float, cx: float | None = None, cy: float | None = None) -> Camera:
        """This camera (same pose, to the bit) with calibrated intrinsics (``cx, cy`` default: centred)."""
        c0x, c0y = principal_point(self.width, self.height)
        return self._replace_lens(intrinsics=(fx, fy, c0x if cx is None else cx, c0y if cy is None else cy))

    def with_K(self, K) -> Camera:  # noqa: N802
        """This camera with the intrinsics of a ``(3, 3)`` K: no skew, last row ``0 0 1``."""
        k = _numbers("K", K, (3, 3))
        if k[1] != 0 or k[3] != 0 or (k[6], k[7], k[8]) != (0.0, 0.0, 1.0):
            raise InputError(
                f"camera K {[list(k[i : i + 3]) for i in (0, 3, 6)]}: expected "
                "[[fx, 0, cx], [0, fy, cy], [0, 0, 1]] (no skew)"
            )
        return self.with_intrinsics(k[0], k[4], k[2], k[5])

    def with_distortion(self, coefficients) -> Camera:
        """This camera (same pose, to the bit) with OpenCV distortion coefficients (``None``: none)."""
        return self._replace_lens(distortion=coefficients)

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
            # only when set: the dictionary of an uncalibrated camera is unchanged
            **({"intrinsics": list(self.intrinsics)} if self.intrinsics is not None else {}),
            **({"distortion": list(self.distortion)} if self.distortion is not None else {}),
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
    if not np.any(forward):  # exact test: norm() underflows to 0 below ~1e-160
        raise InputError(
            f"camera position {position.tolist()}: expected a point different from look-at {target.tolist()}"
        )
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
    return Camera(
        position=camera.position,
        forward=camera.forward,
        up=camera.up,
        fov_y_deg=camera.fov_y_deg,
        width=camera.width,
        height=camera.height,
        near=camera.near,
        far=camera.far,
        projection="orthographic",
        ortho_height=height,
    )


#: The lengths OpenCV's ``distCoeffs`` may have that this model covers:
#: (k1, k2, p1, p2), (..., k3), (..., k3, k4, k5, k6). The thin-prism and tilted
#: models (12 and 14 numbers) are not modelled.
COEFFICIENT_COUNTS = (4, 5, 8)


#: Largest |coefficient|. Calibrated lenses have |k| up to about 10^2 (rational
#: models of fisheye-like lenses); 10^4 leaves room for any real lens, while
#: k r2^3 stays below 1e4 * 1e12 inside the intrinsics' 1e6-side reach
#: (core.camera), far from float64 overflow.
MAX_COEFFICIENT = 1e4


NAMES = ("k1", "k2", "p1", "p2", "k3", "k4", "k5", "k6")


def check_coefficients(coefficients) -> tuple | None:
    """``coefficients`` as a tuple of floats, ``None`` when absent or all zero; InputError otherwise.

    Parameters
    ----------
    coefficients : sequence of float or None
        ``(k1, k2, p1, p2[, k3[, k4, k5, k6]])``, OpenCV's order.
    """
    if coefficients is None:
        return None
    try:
        c = np.asarray(coefficients, dtype=np.float64)
    except (TypeError, ValueError):
        c = None
    if c is None or c.ndim != 1 or len(c) not in COEFFICIENT_COUNTS:
        raise InputError(
            f"camera distortion {coefficients!r}: expected 4, 5 or 8 numbers "
            "(k1, k2, p1, p2[, k3[, k4, k5, k6]], OpenCV's order)"
        )
    bad = [f"{n}={v!r}" for n, v in zip(NAMES, c.tolist()) if not (math.isfinite(v) and abs(v) <= MAX_COEFFICIENT)]
    if bad:
        raise InputError(
            f"camera distortion {', '.join(bad)}: expected finite numbers with |value| <= {MAX_COEFFICIENT:g}"
        )
    if not c.any():
        return None
    return tuple(float(x) for x in c)
