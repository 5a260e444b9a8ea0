"""Camera and model-matrix conversions into foreign conventions, and back.

Independent of ``core``'s matrices and projection: a :class:`core.camera.Camera`
is read only for its attributes (``position, forward, up, right, fov_y_deg,
width, height, near, far, projection, ortho_height, intrinsics, distortion``),
and the two-line focal length / principal point formulas of
:mod:`core.conventions` are duplicated here on purpose::

    f_px = (H / 2) / tan(fov_y / 2)
    cx, cy = (W - 1) / 2, (H - 1) / 2         (integer pixel coords = centres)

unless the camera is calibrated (``intrinsics = (fx, fy, cx, cy)``, taken as
given). ``distortion`` is OpenCV's ``distCoeffs`` as is (:func:`distortion_coefficients`).

Our camera space is x right, y up, z forward (``core.conventions``); OpenCV's is
x right, y down, z forward; pyrender's (OpenGL's) is x right, y up, z backward.
"""

from __future__ import annotations

import functools
import math
import os

import numpy as np
from wirecheck.core.camera import Camera

__all__ = [
    "camera_to_opencv",
    "opencv_matrices",
    "opencv_to_camera",
    "camera_to_pyrender",
    "intrinsics",
    "distortion_coefficients",
    "pyrender_pose_to_camera",
    "camera_to_gl",
    "model_matrix",
    "centre_of",
    "gl_eye_pose",
]

# Relative tolerance for "K describes a centred, square-pixel camera": K built
# by camera_to_opencv is exact to float64 rounding (~1e-16 relative); 1e-9
# leaves room for a K that went through text or float32-free arithmetic.
_K_RTOL = 1e-9


def _focal_px(fov_y_deg: float, height: int) -> float:
    # duplicate of core.conventions.focal_px (independence is the point)
    return (height / 2.0) / math.tan(math.radians(fov_y_deg) / 2.0)


def _principal_point(width: int, height: int) -> tuple[float, float]:
    # duplicate of core.conventions.principal_point
    return (width - 1) / 2.0, (height - 1) / 2.0


def intrinsics(camera) -> tuple[float, float, float, float]:
    """``(fx, fy, cx, cy)`` of a perspective camera: its ``intrinsics`` if calibrated, else from the FOV."""
    given = getattr(camera, "intrinsics", None)
    if given is not None:
        fx, fy, cx, cy = (float(v) for v in given)
        return fx, fy, cx, cy
    f = _focal_px(camera.fov_y_deg, camera.height)
    cx, cy = _principal_point(camera.width, camera.height)
    return f, f, cx, cy


def distortion_coefficients(camera) -> np.ndarray:
    """OpenCV's ``distCoeffs`` for the camera: its ``distortion`` as given, else ``zeros(5)`` (none)."""
    given = getattr(camera, "distortion", None)
    return np.zeros(5) if given is None else np.asarray(given, dtype=np.float64).reshape(-1)


def camera_basis(camera) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(right, up, forward)`` built here from the spec's ``forward`` and ``up``.

    Independent of core's ``Camera.right``: ``right = forward x up`` (the
    project's handedness, stated in core.conventions), normalised, and
    ``up = right x forward``. If core's cross product were reversed, the oracle
    would not follow it.
    """
    forward = np.asarray(camera.forward, dtype=np.float64)
    forward = forward / np.linalg.norm(forward)
    right = np.cross(forward, np.asarray(camera.up, dtype=np.float64))
    right = right / np.linalg.norm(right)
    return right, np.cross(right, forward), forward


def _cv2():
    import cv2

    return cv2


def _rotation():
    """scipy's ``Rotation``, imported on first use: a process that only encodes or decodes the candidate
    protocol (the candidate host) never builds a rotation, and scipy.spatial is ~0.3 s of its start."""
    from scipy.spatial.transform import Rotation

    return Rotation


# ---- OpenCV ---------------------------------------------------------------


def camera_to_opencv(camera: Camera) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Our camera as OpenCV extrinsics and intrinsics.

    OpenCV (``cv2.projectPoints``, pinhole model)::

        p_cv = R @ X + t          camera x right, y down, z forward
        [u, v, 1] ~ K @ p_cv      K = [[fx, 0, cx], [0, fy, cy], [0, 0, 1]]

    with integer pixel coordinates at pixel centres, as ours. So the rows of
    ``R`` are ``right, -up, forward`` (our camera y negated), ``t = -R @
    position``, ``rvec`` = the rotation vector of ``R``, and ``K`` uses ``f_px`` and
    ``(cx, cy)`` from ``core.conventions`` (recomputed here), or the camera's
    ``intrinsics`` when calibrated. Lens distortion is not in ``K``: pass
    :func:`distortion_coefficients` as ``distCoeffs``.

    Orthographic cameras get the same ``rvec, tvec`` and an *affine* ``K``:
    ``[[s, 0, cx], [0, s, cy], [0, 0, 1]]`` with ``s = H / ortho_height``,
    meant as ``[u, v] = (K @ [x_cv, y_cv, 1])[:2]`` (no division by depth).
    ``cv2.projectPoints`` has no orthographic model; do not pass it this K.

    Parameters
    ----------
    camera : Camera

    Returns
    -------
    rvec : (3,) ndarray, Rodrigues rotation vector world -> OpenCV camera.
    tvec : (3,) ndarray, translation world -> OpenCV camera.
    K : (3, 3) ndarray, intrinsics (affine for orthographic, see above).
    """
    right, up, forward = camera_basis(camera)
    r_cv = np.stack([right, -up, forward])
    tvec = -r_cv @ np.asarray(camera.position, dtype=np.float64)
    # R -> rvec with scipy (through a quaternion): cv2.Rodrigues(R) loses up to
    # ~4e3 eps near 180-degree rotations (measured), which then shows as oracle
    # error; the other direction (rvec -> R, inside projectPoints) is well conditioned.
    rvec = _rotation().from_matrix(r_cv).as_rotvec()
    if camera.projection == "perspective":
        fx, fy, cx, cy = intrinsics(camera)
    else:
        fx = fy = camera.height / camera.ortho_height
        cx, cy = _principal_point(camera.width, camera.height)
    k = np.array([[fx, 0.0, cx], [0.0, fy, cy], [0.0, 0.0, 1.0]])
    return rvec.reshape(3), tvec, k


def opencv_matrices(camera: Camera) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``R, t, K`` of :func:`camera_to_opencv` as matrices: ``p_cv = R @ X + t``, ``K`` as there.

    ``R`` is built from the camera's vectors (rows ``right, -up, forward``), not
    through a rotation vector, so it carries no Rodrigues rounding.

    Returns
    -------
    R : (3, 3) ndarray, t : (3,) ndarray, K : (3, 3) ndarray (affine for orthographic).
    """
    right, up, forward = camera_basis(camera)
    r_cv = np.stack([right, -up, forward])
    _rvec, _tvec, k = camera_to_opencv(camera)
    return r_cv, -r_cv @ np.asarray(camera.position, dtype=np.float64), k


def opencv_to_camera(
    rvec, tvec, K, width: int, height: int, near: float, far: float, projection: str = "perspective", dist=None
) -> Camera:
    """Inverse of :func:`camera_to_opencv`.

    From ``p_cv = R X + t`` (rows of ``R``: right, -up, forward)::

        position = -R^T t,   right = R[0],  up = -R[1],  forward = R[2]
        fov_y = 2 atan((H / 2) / fy)            (perspective)
        ortho_height = H / fy                   (orthographic, affine K)

    A centred square-pixel ``K`` gives a FOV camera (as above); any other ``K``
    without skew a calibrated camera (``intrinsics = (fx, fy, cx, cy)``,
    perspective only). ``dist``: OpenCV ``distCoeffs`` (4, 5 or 8 numbers, or
    None). Raises ``ValueError`` for skew, or an orthographic ``K`` that is
    not centred and square.
    """
    cv2 = _cv2()
    r_cv, _ = cv2.Rodrigues(np.asarray(rvec, dtype=np.float64).reshape(3, 1))
    tvec = np.asarray(tvec, dtype=np.float64).reshape(3)
    K = np.asarray(K, dtype=np.float64)
    fx, fy, cx, cy = K[0, 0], K[1, 1], K[0, 2], K[1, 2]
    cx0, cy0 = _principal_point(width, height)
    scale = max(abs(fx), abs(cx0), 1.0)
    if abs(K[0, 1]) > _K_RTOL * scale:
        raise ValueError(f"K {K.tolist()}: expected no skew (K[0][1] = 0)")
    centred = (
        math.isclose(fx, fy, rel_tol=_K_RTOL) and abs(cx - cx0) <= _K_RTOL * scale and abs(cy - cy0) <= _K_RTOL * scale
    )
    if not centred and projection != "perspective":
        raise ValueError(
            f"K {K.tolist()}: expected square pixels and principal "
            f"point ({cx0}, {cy0}) for a {width}x{height} orthographic image"
        )
    position = -r_cv.T @ tvec
    kwargs = dict(width=width, height=height, near=near, far=far, projection=projection, distortion=dist)
    if projection == "perspective" and centred:
        kwargs["fov_y_deg"] = math.degrees(2.0 * math.atan((height / 2.0) / fy))
    elif projection == "perspective":
        kwargs["intrinsics"] = (fx, fy, cx, cy)
    else:
        kwargs["ortho_height"] = height / fy
    return Camera(position=position, forward=r_cv[2], up=-r_cv[1], **kwargs)


# ---- pyrender -------------------------------------------------------------


def _pyrender():
    os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa")
    import pyrender

    return pyrender


def camera_to_pyrender(camera: Camera):
    """Our camera as a pyrender camera node pose and a pyrender camera.

    pyrender (OpenGL) cameras look down their local -Z with +Y up, so the pose
    (camera-to-world) has columns ``[right, up, -forward, position]``.

    Perspective -> ``pyrender.IntrinsicsCamera(fx=fx, fy=fy, cx=cx + 0.5,
    cy=cy + 0.5, znear=near, zfar=far)`` (``fx = fy = f`` and a centred
    ``(cx, cy)`` unless the camera is calibrated). pyrender measures ``cx, cy`` from the
    pixel *corner*: its ``IntrinsicsCamera.get_projection_matrix`` is::

        P[0][0] = 2.0 * fx / width
        P[1][1] = 2.0 * fy / height
        P[0][2] = 1.0 - 2.0 * cx / width
        P[1][2] = 2.0 * cy / height - 1.0
        P[3][2] = -1.0

    which, through the viewport transform (window x = (x_ndc + 1) W / 2, pixel
    centres at half-integers) and the row flip of the read-back, gives
    ``x_win = cx + fx x / d`` and ``row_win = cy - fy y / d`` in corner-origin
    coordinates, i.e. ``x_px = x_win - 0.5``: hence the ``+ 0.5``.
    (On macOS pyrender doubles fx, fy, cx, cy for retina; not handled here.)

    Orthographic -> ``pyrender.OrthographicCamera(xmag=ortho_height/2 * W/H,
    ymag=ortho_height/2, znear=near, zfar=far)`` (``P[0][0] = 1/xmag``,
    ``P[1][1] = 1/ymag``; pyrender recomputes xmag from the viewport aspect).
    pyrender requires ``znear > 0`` here, so orthographic cameras with
    ``near <= 0`` raise ``ValueError``, and so do cameras with lens distortion
    (GL draws straight lines: there is no pyrender camera for them).

    Returns
    -------
    pose : (4, 4) ndarray, camera-to-world.
    pyrender_camera : pyrender.IntrinsicsCamera or pyrender.OrthographicCamera
    """
    pyrender = _pyrender()
    pose = np.eye(4)
    right, up, forward = camera_basis(camera)
    pose[:3, 0] = right
    pose[:3, 1] = up
    pose[:3, 2] = -forward
    pose[:3, 3] = camera.position
    w, h = camera.width, camera.height
    if getattr(camera, "distortion", None) is not None:
        raise ValueError(
            f"camera distortion {list(camera.distortion)}: pyrender (GL) draws no lens distortion; "
            "only the vertices of a distorted camera can be compared"
        )
    if camera.projection == "perspective":
        fx, fy, cx, cy = intrinsics(camera)
        cam = pyrender.IntrinsicsCamera(fx=fx, fy=fy, cx=cx + 0.5, cy=cy + 0.5, znear=camera.near, zfar=camera.far)
    else:
        if not camera.near > 0:
            raise ValueError(f"camera near {camera.near!r}: pyrender's OrthographicCamera needs znear > 0")
        ymag = camera.ortho_height / 2.0
        cam = pyrender.OrthographicCamera(xmag=ymag * w / h, ymag=ymag, znear=camera.near, zfar=camera.far)
    return pose, cam


def pyrender_pose_to_camera(pose, pyrender_camera, width: int, height: int) -> Camera:
    """Inverse of :func:`camera_to_pyrender`.

    ``position = pose[:3, 3]``, ``up = pose[:3, 1]``, ``forward = -pose[:3, 2]``;
    ``fov_y = 2 atan((H / 2) / fy)`` for a centred square-pixel
    ``IntrinsicsCamera`` (``cx = W / 2``, ``cy = H / 2`` from the corner, ``fx
    = fy``), else a calibrated camera with ``intrinsics = (fx, fy, cx - 0.5,
    cy - 0.5)``; ``ortho_height = 2 ymag`` for an ``OrthographicCamera``.
    """
    pyrender = _pyrender()
    pose = np.asarray(pose, dtype=np.float64)
    kwargs = dict(width=width, height=height, near=pyrender_camera.znear, far=pyrender_camera.zfar)
    if isinstance(pyrender_camera, pyrender.IntrinsicsCamera):
        c = pyrender_camera
        tol = _K_RTOL * max(c.fx, width, 1.0)
        if math.isclose(c.fx, c.fy, rel_tol=_K_RTOL) and abs(c.cx - width / 2) <= tol and abs(c.cy - height / 2) <= tol:
            kwargs["fov_y_deg"] = math.degrees(2.0 * math.atan((height / 2.0) / c.fy))
        else:
            kwargs["intrinsics"] = (c.fx, c.fy, c.cx - 0.5, c.cy - 0.5)
    elif isinstance(pyrender_camera, pyrender.OrthographicCamera):
        kwargs["projection"] = "orthographic"
        kwargs["ortho_height"] = 2.0 * pyrender_camera.ymag
    else:
        raise TypeError(f"unsupported pyrender camera {type(pyrender_camera).__name__}")
    return Camera(position=pose[:3, 3], forward=-pose[:3, 2], up=pose[:3, 1], **kwargs)


# ---- OpenGL (view and projection matrices) --------------------------------


def camera_to_gl(camera: Camera) -> tuple[np.ndarray, np.ndarray]:
    """Our camera as OpenGL view and projection matrices (column vectors).

    OpenGL (``gluLookAt`` / ``gluPerspective`` / ``glOrtho``)::

        p_clip = P @ V @ [X, 1]        eye space x right, y up, z backward
        p_ndc = p_clip[:3] / p_clip[3]   in [-1, 1]^3 inside the frustum
        x_win = (x_ndc + 1) W / 2,  y_win = (y_ndc + 1) H / 2   (corner origin, y up)

    ``V`` has rows ``right, up, -forward`` and translation ``-R @ position``.
    Perspective ``P``: ``f = 1 / tan(fov_y / 2)``, ``a = W / H``::

        [[f/a, 0, 0, 0], [0, f, 0, 0],
         [0, 0, (far+near)/(near-far), 2 far near/(near-far)], [0, 0, -1, 0]]

    A calibrated camera (``fx, fy, cx, cy``) gets ``glFrustum``'s off-centre
    form instead: ``P[0, 0] = 2 fx / W``, ``P[1, 1] = 2 fy / H``, ``P[0, 2] =
    1 - 2 (cx + 0.5) / W``, ``P[1, 2] = 2 (cy + 0.5) / H - 1`` (pyrender's
    ``IntrinsicsCamera`` matrix, with its corner-origin ``cx + 0.5``); centred
    and square, it is the matrix above. Lens distortion is not in ``P``
    (GL cannot divide it in).

    Orthographic ``P`` (``glOrtho`` with ``top = ortho_height / 2``,
    ``right = a top``): ``diag(1/right, 1/top, -2/(far-near), 1)`` with
    ``P[2, 3] = -(far+near)/(far-near)``. Our pixels are then
    ``x_px = x_win - 0.5``, ``y_px = H - y_win - 0.5`` (integer coordinates
    at pixel centres, y down: core.conventions).

    Returns
    -------
    view : (4, 4) ndarray, world -> GL eye.
    projection : (4, 4) ndarray, GL eye -> clip.
    """
    right, up, forward = camera_basis(camera)
    r_gl = np.stack([right, up, -forward])
    view = np.eye(4)
    view[:3, :3] = r_gl
    view[:3, 3] = -r_gl @ np.asarray(camera.position, dtype=np.float64)
    aspect = camera.width / camera.height
    n, f = float(camera.near), float(camera.far)
    proj = np.zeros((4, 4))
    if camera.projection == "perspective":
        if getattr(camera, "intrinsics", None) is None:
            g = 1.0 / math.tan(math.radians(camera.fov_y_deg) / 2.0)
            proj[0, 0], proj[1, 1] = g / aspect, g
        else:
            fx, fy, cx, cy = intrinsics(camera)
            w, h = camera.width, camera.height
            proj[0, 0], proj[1, 1] = 2.0 * fx / w, 2.0 * fy / h
            proj[0, 2], proj[1, 2] = 1.0 - 2.0 * (cx + 0.5) / w, 2.0 * (cy + 0.5) / h - 1.0
        proj[2, 2], proj[2, 3] = (f + n) / (n - f), 2.0 * f * n / (n - f)
        proj[3, 2] = -1.0
    else:
        top = camera.ortho_height / 2.0
        proj[0, 0], proj[1, 1] = 1.0 / (aspect * top), 1.0 / top
        proj[2, 2], proj[2, 3] = -2.0 / (f - n), -(f + n) / (f - n)
        proj[3, 3] = 1.0
    return view, proj


# ---- re-centring for float32 (pyrender) ----------------------------------


def centre_of(vertices) -> np.ndarray:
    """``(3,)`` float64: the midpoint of the finite rows' bounding box (zeros when none is finite).

    The point the pyrender oracle subtracts, in float64, from the vertices
    before they are rounded to float32 (:func:`gl_eye_pose`): what pyrender
    then holds is each vertex's offset from it, at most the mesh's half
    diagonal, wherever the mesh is.
    """
    v = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    v = v[np.isfinite(v).all(axis=1)]
    if len(v) == 0:
        return np.zeros(3)
    return 0.5 * (v.min(axis=0) + v.max(axis=0))


def gl_eye_pose(camera, model_matrix=None, centre=(0.0, 0.0, 0.0)) -> np.ndarray:
    """``(4, 4)`` float64: centred model coordinates ``q = p - centre`` to GL eye coordinates.

    The world position of ``p`` is ``M p = M_lin q + (M_lin c + t)``; the eye
    coordinates are ``R_gl (M p - position)`` with ``R_gl``'s rows ``right,
    up, -forward`` (:func:`camera_basis`), so::

        pose[:3, :3] = R_gl M_lin
        pose[:3, 3]  = R_gl ((M_lin c + t) - position)     (the centre in eye space)

    all in float64 here, with the centre's world position taken relative to
    the camera before anything is rounded. Given to pyrender as the mesh
    node's pose with the camera node at the identity, it leaves the GPU only
    magnitudes of the mesh's size and of its distance from the camera to hold
    in float32, not the scene's distance from the world origin.
    """
    right, up, forward = camera_basis(camera)
    r_gl = np.stack([right, up, -forward])
    m = np.eye(4) if model_matrix is None else np.asarray(model_matrix, dtype=np.float64)
    c = np.asarray(centre, dtype=np.float64)
    c_world = m[:3, :3] @ c + m[:3, 3]
    pose = np.eye(4)
    pose[:3, :3] = r_gl @ m[:3, :3]
    pose[:3, 3] = r_gl @ (c_world - np.asarray(camera.position, dtype=np.float64))
    return pose


# ---- model motion ---------------------------------------------------------


def model_matrix(turns, offset, scale: float, t: float, pivot=(0.0, 0.0, 0.0)) -> np.ndarray:
    """The scene's model matrix at time ``t``, built with scipy.

    Must equal ``T @ Rz(az) @ Ry(ay) @ Rx(ax) @ S`` with
    ``a_i = 2 pi ((t * turns_i) % 1)`` (``core.conventions``, "Motion"); about
    a non-zero ``pivot`` c, ``p -> R S (p - c) + c + offset``.
    scipy: *lowercase* axes in ``Rotation.from_euler`` are extrinsic (about the
    fixed axes, in the order given), so ``from_euler("xyz", [ax, ay, az])`` is
    "rotate about x, then fixed y, then fixed z" = ``Rz @ Ry @ Rx`` (equal to the
    intrinsic ``"ZYX"`` with angles ``[az, ay, ax]``).

    Returns
    -------
    (4, 4) ndarray, the caller's own (a copy of the memoised matrix).
    """
    # keyed on the floats' bytes: -0.0 and 0.0 stay apart, a NaN finds itself
    key = np.concatenate([np.ravel(turns), np.ravel(offset), [scale, t], np.ravel(pivot)]).astype(np.float64)
    return _model_matrix(key.tobytes()).copy()


@functools.lru_cache(maxsize=4096)
def _model_matrix(key: bytes) -> np.ndarray:
    """:func:`model_matrix` memoised on its arguments' float64 bytes: every camera of a scene asks for the
    same frames' matrices, and scipy's ``Rotation`` costs ~0.1 ms a call (4,096 entries of 128 B)."""
    v = np.frombuffer(key, dtype=np.float64)
    if len(v) != 11:
        raise ValueError(f"model_matrix: turns, offset and pivot take 3 values each, got {len(v) - 2} in all")
    turns, offset, scale, t, pivot = v[0:3], v[3:6], v[6], v[7], v[8:11]
    ax, ay, az = (2.0 * math.pi * ((t * float(k)) % 1.0) for k in turns)
    m = np.eye(4)
    m[:3, :3] = _rotation().from_euler("xyz", [ax, ay, az]).as_matrix() * float(scale)
    m[:3, 3] = np.asarray(offset, dtype=np.float64)
    c = np.asarray(pivot, dtype=np.float64)
    if c.any():
        m[:3, 3] += c - m[:3, :3] @ c
    return m
