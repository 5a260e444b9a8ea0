"""The faulty projectors of the diagnosis proofs (tests/test_diagnosis.py, tests/test_image_diagnosis.py).

Every faulty projector is a small re-implementation of ``core.projector.projection.project_points`` with one bug
(or two) put in on purpose, on the cameras below; ``FAULTS`` maps each to the names it must get.
"""

from __future__ import annotations

import math

import numpy as np
from wirecheck.core.camera import Camera, look_at
from wirecheck.core.conventions import focal_px
from wirecheck.core.transforms import rotate_z

# ---- cameras ----------------------------------------------------------------

CAMERAS = {
    "axis": look_at((0, 0, 5), (0, 0, 0), (0, 1, 0), fov_y_deg=60, width=640, height=480),
    "oblique": look_at((3, 2, 4), (0, 0, 0), (0.3, 1, 0.1), fov_y_deg=60, width=640, height=480),
    "tall": look_at((-1, 2, 6), (0.2, 0, 0), (0.1, 1, -0.2), fov_y_deg=50, width=320, height=480),
    "wide": look_at((0.5, 0.8, 3.2), (0, 0, 0), (0, 1, 0), fov_y_deg=110, width=640, height=480),
    "ortho": look_at(
        (2, 3, 5), (0, 0, 0), (0.2, 1, 0), width=400, height=300, projection="orthographic", ortho_height=5.0
    ),
    # camera at the centre of the points: some in front, some behind
    "inside": look_at((0, 0, 0), (0.1, 0.2, -1), (0, 1, 0), fov_y_deg=90, width=640, height=480),
    # the same, with near and far inside the points' depths (|p| <= ~3.5): both planes cut some
    "clip": look_at((0, 0, 0), (0.1, 0.2, -1), (0, 1, 0), fov_y_deg=90, width=640, height=480, near=1.0, far=3.0),
}


# Calibrated cameras (core.conventions, "Calibrated cameras", "Lens distortion"):
# off-centre principal points, fx != fy, and two lenses (barrel with k3 and
# tangential terms; pincushion, 4 coefficients). Image corners reach r_n ~ 0.85,
# where both lenses are still monotonic (no fold-over).
LENS_BARREL = (-0.22, 0.06, 0.0012, -0.0009, -0.008)
LENS_PINCUSHION = (0.15, -0.04, -0.002, 0.0015)
CAMERAS.update(
    {
        "k_offc": look_at(
            (3, 2, 4), (0, 0, 0), (0.3, 1, 0.1), width=640, height=480, intrinsics=(520.0, 520.0, 360.25, 210.5)
        ),
        "k_aniso": look_at(
            (-1, 2, 6), (0.2, 0, 0), (0.1, 1, -0.2), width=320, height=480, intrinsics=(700.0, 560.0, 150.0, 250.0)
        ),
        "k_barrel": look_at(
            (0.5, 0.8, 4.0),
            (0, 0, 0),
            (0, 1, 0),
            width=640,
            height=480,
            intrinsics=(470.0, 465.0, 325.2, 236.8),
            distortion=LENS_BARREL,
        ),
        "k_pincushion": look_at(
            (-2.5, 1.5, 3.0),
            (0, 0, 0),
            (0, 1, 0),
            width=640,
            height=480,
            intrinsics=(560.0, 540.0, 300.0, 250.0),
            distortion=LENS_PINCUSHION,
        ),
    }
)
LENS_CAMERAS = ("k_barrel", "k_pincushion")
CALIBRATED_CAMERAS = ("k_offc", "k_aniso") + LENS_CAMERAS


def _with(camera: Camera, **changes) -> Camera:
    kw = dict(
        position=camera.position,
        forward=camera.forward,
        up=camera.up,
        fov_y_deg=camera.fov_y_deg,
        width=camera.width,
        height=camera.height,
        near=camera.near,
        far=camera.far,
        projection=camera.projection,
        ortho_height=camera.ortho_height,
        intrinsics=camera.intrinsics,
        distortion=camera.distortion,
    )
    kw.update(changes)
    return Camera(**kw)


# ---- a re-implementation of the projector with knobs for the faults -----------


def naive_distort(x, y, coeffs):
    """OpenCV's distortion (its documentation's formula), written out term by term; y down."""
    k1, k2, p1, p2, k3, k4, k5, k6 = tuple(coeffs) + (0.0,) * (8 - len(coeffs))
    r2 = x**2 + y**2
    radial = (1 + k1 * r2 + k2 * r2**2 + k3 * r2**3) / (1 + k4 * r2 + k5 * r2**2 + k6 * r2**3)
    return (x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x**2), y * radial + p1 * (r2 + 2 * y**2) + 2 * p2 * x * y)


_LENS = "the camera's"


def _project(
    p_world, camera, *, rotation=None, fx=None, fy=None, cx=None, cy=None, dist=_LENS, dtype=np.float64, keep=None
):
    """core.projector.projection.project_points, with the rotation, focal lengths (or
    ortho scales), principal point, lens distortion and depth test (``keep(z, camera)``)
    replaceable; every value in ``dtype`` (float32: the float32 twin of a fault)."""
    p = np.asarray(p_world, dtype=dtype).reshape(-1, 3)
    r = np.stack([camera.right, camera.up, camera.forward]) if rotation is None else rotation
    r, position = np.asarray(r, dtype=dtype), np.asarray(camera.position, dtype=dtype)
    p_cam = (p - position) @ r.T
    z = p_cam[:, 2]
    vis = (z >= dtype(camera.near)) & (z <= dtype(camera.far)) if keep is None else keep(z, camera)
    pcx, pcy = camera.principal_point
    cx = dtype(pcx if cx is None else cx)
    cy = dtype(pcy if cy is None else cy)
    dist = camera.distortion if dist is _LENS else dist
    if camera.projection == "perspective":
        cfx, cfy = camera.focal_xy
        fx = dtype(cfx if fx is None else fx)
        fy = dtype(cfy if fy is None else fy)
        z_safe = np.where(vis, z, dtype(1.0))
        if dist is None:
            x, y = cx + fx * p_cam[:, 0] / z_safe, cy - fy * p_cam[:, 1] / z_safe
        else:
            xd, yd = naive_distort(p_cam[:, 0] / z_safe, -p_cam[:, 1] / z_safe, dist)
            x, y = cx + fx * xd, cy + fy * yd
    else:
        s = camera.height / camera.ortho_height
        fx = dtype(s if fx is None else fx)
        fy = dtype(s if fy is None else fy)
        x, y = cx + fx * p_cam[:, 0], cy - fy * p_cam[:, 1]
    out = np.stack([x, y], axis=1)
    out[~vis] = np.nan
    return out


def _scale_for(camera, fov_or_height):
    """Focal length (perspective, from a vertical FOV) or ortho scale (from an ortho height)."""
    if camera.projection == "perspective":
        return focal_px(fov_or_height, camera.height)
    return camera.height / fov_or_height


def f_none(p, cam, dtype=np.float64):
    return _project(p, cam, dtype=dtype)


def f_mirror_x(p, cam, dtype=np.float64):
    out = _project(p, cam, dtype=dtype)
    out[:, 0] = (cam.width - 1) - out[:, 0]
    return out


def f_mirror_y(p, cam, dtype=np.float64):
    out = _project(p, cam, dtype=dtype)
    out[:, 1] = (cam.height - 1) - out[:, 1]
    return out


def f_flip(p, cam, dtype=np.float64):
    return f_mirror_y(p, cam, dtype) * np.array([-1, 1], dtype) + np.array([cam.width - 1, 0], dtype)


def f_swap(p, cam, dtype=np.float64):
    return _project(p, cam, dtype=dtype)[:, ::-1].copy()


def f_swap_mirror(p, cam, dtype=np.float64):
    """Turned 90 degrees: swap, then mirror x of the result."""
    out = f_swap(p, cam, dtype)
    out[:, 0] = (cam.width - 1) - out[:, 0]
    return out


FOV_FACTOR = 0.8


def implied_fov(cam):
    """What the fov fault used: fov * 0.8 (perspective) or ortho_height * 0.8."""
    return (cam.fov_y_deg if cam.projection == "perspective" else cam.ortho_height) * FOV_FACTOR


def f_fov(p, cam, dtype=np.float64):
    s = _scale_for(cam, implied_fov(cam))
    if cam.calibrated:  # both focal lengths scaled alike: fx/fy kept
        fx, fy = cam.focal_xy
        return _project(p, cam, fx=fx * s / fy, fy=s, dtype=dtype)
    return _project(p, cam, fx=s, fy=s, dtype=dtype)


def f_fov_horizontal(p, cam, dtype=np.float64):
    """The vertical FOV taken as the horizontal one (f from the width, both axes)."""
    s = _scale_for(cam, cam.fov_y_deg if cam.projection == "perspective" else cam.ortho_height)
    s *= cam.width / cam.height
    return _project(p, cam, fx=s, fy=s, dtype=dtype)


def f_aspect(p, cam, dtype=np.float64):
    """fx from the width-based formula: (W/2) / tan(fov/2), i.e. aspect 1."""
    s = _scale_for(cam, cam.fov_y_deg if cam.projection == "perspective" else cam.ortho_height)
    return _project(p, cam, fx=s * cam.width / cam.height, dtype=dtype)


def f_fov_aspect(p, cam, dtype=np.float64):
    s = _scale_for(cam, implied_fov(cam))
    return _project(p, cam, fx=s * cam.width / cam.height, fy=s, dtype=dtype)


def f_offset(p, cam, dtype=np.float64):
    """Pixel-corner convention: cx = W/2, cy = H/2."""
    return _project(p, cam, cx=cam.width / 2, cy=cam.height / 2, dtype=dtype)


def f_fov_offset(p, cam, dtype=np.float64):
    return f_fov(p, cam, dtype) + dtype(0.5)


def f_depth_flip(p, cam, dtype=np.float64):
    """Forward negated: the camera looks backward."""
    return _project(p, _with(cam, forward=-cam.forward), dtype=dtype)


def f_transposed(p, cam, dtype=np.float64):
    r = np.stack([cam.right, cam.up, cam.forward])
    return _project(p, cam, rotation=r.T, dtype=dtype)


def f_roll(p, cam, dtype=np.float64):
    """A 0.5 degree roll error about the view axis."""
    r = np.stack([cam.right, cam.up, cam.forward])
    return _project(p, cam, rotation=rotate_z(math.radians(0.5))[:3, :3] @ r, dtype=dtype)


def f_float32_arith(p, cam, dtype=np.float64):
    """Correct, but computed in float32 whatever ``dtype``: float32 rounding in a float64-judged candidate."""
    return f_none(p, cam, np.float32).astype(np.float64)


PP_SHIFT = (3.25, -1.5)


def f_pp_offset(p, cam, dtype=np.float64):
    """The principal point off by (3.25, -1.5) px."""
    cx, cy = cam.principal_point
    return _project(p, cam, cx=cx + PP_SHIFT[0], cy=cy + PP_SHIFT[1], dtype=dtype)


def f_fxfy_swap(p, cam, dtype=np.float64):
    """fx and fy exchanged."""
    fx, fy = cam.focal_xy
    return _project(p, cam, fx=fy, fy=fx, dtype=dtype)


def f_lens_ignored(p, cam, dtype=np.float64):
    return _project(p, cam, dist=None, dtype=dtype)


def _lens_with(cam, index, factor):
    c = list(cam.distortion)
    c[index] *= factor
    return tuple(c)


def f_k1_sign(p, cam, dtype=np.float64):
    return _project(p, cam, dist=_lens_with(cam, 0, -1.0), dtype=dtype)


def f_k2_wrong(p, cam, dtype=np.float64):
    """k2 twice its size."""
    return _project(p, cam, dist=_lens_with(cam, 1, 2.0), dtype=dtype)


def f_float32_k(p, cam, dtype=np.float64):
    """float64 arithmetic with float32 constants (a np.float32 K): fitted scales 1 + ~3e-8."""
    fx, fy = cam.focal_xy if cam.projection == "perspective" else (_scale_for(cam, cam.ortho_height),) * 2
    cx, cy = cam.principal_point
    f32 = [float(np.float32(v)) for v in (fx, fy, cx, cy)]
    return _project(p, cam, fx=f32[0], fy=f32[1], cx=f32[2], cy=f32[3], dtype=dtype)


def f_clip_z_positive(p, cam, dtype=np.float64):
    """Keeps every point in front (z > 0), not only beyond near."""
    return _project(p, cam, dtype=dtype, keep=lambda z, c: (z > 0) & (z <= dtype(c.far)))


def f_clip_none(p, cam, dtype=np.float64):
    """Never clips (no NaN): points behind the camera come out mirrored through the centre."""
    return _project(p, cam, dtype=dtype, keep=lambda z, c: np.abs(z) > 0)


def f_clip_swapped(p, cam, dtype=np.float64):
    """near and far exchanged in near <= z <= far: keeps nothing."""
    return _project(p, cam, dtype=dtype, keep=lambda z, c: (z >= dtype(c.far)) & (z <= dtype(c.near)))


FAULTS = {
    "none": (f_none, set()),
    "float32_k": (f_float32_k, {"precision_limited"}),
    "clip_z_positive": (f_clip_z_positive, {"clipping_plane"}),
    "clip_none": (f_clip_none, {"clipping_plane"}),
    "clip_swapped": (f_clip_swapped, {"clipping_plane"}),
    "float32_arith": (f_float32_arith, {"precision_limited"}),
    "mirror_x": (f_mirror_x, {"mirror_horizontal"}),
    "mirror_y": (f_mirror_y, {"mirror_vertical"}),
    "flip": (f_flip, {"axis_flip"}),
    "swap": (f_swap, {"axis_swap"}),
    "fov": (f_fov, {"fov_mismatch"}),
    "fov_horizontal": (f_fov_horizontal, {"fov_mismatch"}),
    "aspect": (f_aspect, {"aspect_mismatch"}),
    "offset": (f_offset, {"pixel_offset"}),
    "depth_flip": (f_depth_flip, {"depth_flip"}),
    "transposed": (f_transposed, {"unexplained"}),
    "roll": (f_roll, {"unexplained"}),
    # combinations
    "swap_mirror": (f_swap_mirror, {"axis_swap", "mirror_horizontal"}),
    "fov_aspect": (f_fov_aspect, {"aspect_mismatch", "fov_mismatch"}),
    "fov_offset": (f_fov_offset, {"fov_mismatch", "pixel_offset"}),
    # calibrated cameras. Swapping fx and fy scales x by fy/fx and y by fx/fy:
    # both an aspect and a vertical focal length error, aspect first.
    "pp_offset": (f_pp_offset, {"pixel_offset"}),
    "fxfy_swap": (f_fxfy_swap, {"aspect_mismatch", "fov_mismatch"}),
    "lens_ignored": (f_lens_ignored, {"distortion_mismatch"}),
    "k1_sign": (f_k1_sign, {"distortion_mismatch"}),
    "k2_wrong": (f_k2_wrong, {"distortion_mismatch"}),
}
SINGLE = [k for k in FAULTS if k not in ("swap_mirror", "fov_aspect", "fov_offset")]
#: Faults of the depth test, on the "clip" camera only (its near and far planes cut the points).
CLIP_FAULTS = ("clip_z_positive", "clip_none", "clip_swapped")
#: Faults that need a calibrated camera: fx != fy, or a lens.
CALIBRATED_FAULTS = {
    "fxfy_swap": ("k_aniso", "k_barrel", "k_pincushion"),
    "lens_ignored": LENS_CAMERAS,
    "k1_sign": LENS_CAMERAS,
    "k2_wrong": LENS_CAMERAS,
}
