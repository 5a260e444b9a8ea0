"""The numerical cases of the extremes suite: core at the edges of its input space.

Each case is a function ``case(record, pyrender)`` that measures core against the
long-double reference (measure.py) within the bounds of bounds.py and records
the outcome on a :class:`record.CaseRecord`. Its docstring's first paragraph is
the case's description; its Notes say how the case instantiates its bounds (both
printed in the report).
"""

from __future__ import annotations

import numpy as np
from wirecheck.core.camera import look_at
from wirecheck.core.errors import InputError
from wirecheck.core.projector import clipping
from wirecheck.core.projector.pipeline import render_frame
from wirecheck.core.projector.projection import DTYPES, cam_to_px, localize, model_to_cam, project_points
from wirecheck.core.transforms import Motion, compose, rotate_x, rotate_y, rotate_z, translate

from ..references import opencv_oracle
from .bounds import (
    EPS,
    EPS32,
    camera_error,
    clipped_end_bounds,
    focal_condition,
    motion_matrix_error,
    near_band,
    orthonormality_error,
)
from .measure import Pyrender, err_px, measure
from .record import CaseRecord, public
from .reference import (
    LD,
    norm_ld,
    reference_basis,
    reference_cam_to_px,
    reference_motion_matrix,
    reference_project,
    reference_world,
)


def _cube(half=0.5):
    v = np.array([[x, y, z] for x in (-half, half) for y in (-half, half) for z in (-half, half)], float)
    e = [(i, j) for i in range(8) for j in range(i + 1, 8) if bin(i ^ j).count("1") == 1]
    return v, np.array(e, np.intp)


CUBE_V, CUBE_E = _cube()


# ---- 1 ---------------------------------------------------------------------


def near_plane(c: CaseRecord, pr: Pyrender) -> None:
    """points exactly at z = near, near +- 1 ulp, near +- 1e-9 (absolute), at far +- 1 ulp, at depth 0
    and behind the camera: float64 visibility equals near <= z <= far exactly; float32 flips only inside
    its derived band.

    Notes
    -----
    This camera's basis is exactly +-1/0 and every depth is a dyadic-exact float64, so z_cam is computed
    exactly and float64 must apply near <= z <= far with no tolerance. float32 may differ only inside
    near_band (5.2e-8 at near = 0.1). Pixels: pixel_bound.
    """
    near, far = 0.1, 100.0
    # Camera at the origin looking down +Z: rows of R are (-1,0,0), (0,1,0), (0,0,1)
    # exactly, so z_cam = z_world with no rounding in either path.
    cam = look_at((0.0, 0.0, 0.0), (0.0, 0.0, 1.0), (0.0, 1.0, 0.0), near=near, far=far)
    up_, dn = np.nextafter(near, np.inf), np.nextafter(near, -np.inf)
    zs = {
        "near": near,
        "near+1ulp": up_,
        "near-1ulp": dn,
        "near+1e-9": near + 1e-9,
        "near-1e-9": near - 1e-9,
        "depth 0": 0.0,
        "depth -0": -0.0,
        "depth 5e-324": 5e-324,
        "behind -near": -near,
        "behind -1": -1.0,
        "far": far,
        "far+1ulp": np.nextafter(far, np.inf),
        "far-1ulp": np.nextafter(far, -np.inf),
        "middle 1": 1.0,
    }
    labels = list(zs)
    z = np.array([zs[k] for k in labels])
    # x, y within the image for visible ones (|x/z| < 0.5): 0.3 z and -0.2 z, plus a 1/64 offset
    p = np.stack([0.3 * np.abs(z) + 1 / 64, -0.2 * np.abs(z) - 1 / 128, z], axis=1)
    cam_ld, ref_px, ref_vis = reference_project(p, cam)
    rule = (z >= near) & (z <= far)  # the rule on the exact depths
    c.check(np.array_equal(ref_vis, rule), "reference visibility differs from the rule (reference bug)")
    c.check(bool((cam_ld[:, 2] == z.astype(LD)).all()), "reference depths are not exact (test design)")
    m = measure(p, None, cam)
    c.add(m)
    f64 = m["frames"]["float64"]
    bad = [labels[i] for i in np.flatnonzero(f64.visible != rule)]
    c.check(not bad, f"float64 visibility differs from near <= z <= far at: {', '.join(bad)}")
    c.check(bool(np.array_equal(f64.depth, z)), "float64 depth is not exactly z_cam")
    c.check(
        bool(np.isnan(f64.p_px[~rule]).all() and np.isfinite(f64.p_px[rule]).all()),
        "float64 p_px: expected NaN exactly where clipped",
    )
    pp = project_points(p, cam)
    bad_pp = [labels[i] for i in np.flatnonzero(np.isnan(pp[:, 0]) == rule)]
    c.check(not bad_pp, f"project_points visibility differs from the rule at: {', '.join(bad_pp)}")
    cv_vis = ~np.isnan(opencv_oracle.project(p, cam)[:, 0])
    # float32: flips allowed only inside the derived band (near_band): |z - plane| <= e_cam + eps32 |plane|
    f32 = m["frames"]["float32"]
    flips = f32.visible != rule
    band = near_band(cam_ld, cam, camera_error("float32", p, None, cam), EPS32)
    c.extra = {
        "near": near,
        "far": far,
        "z_offsets": "absolute (near + 1e-9, near - 1e-9) and 1 ulp",
        "float64_visibility_mismatch": len(bad),
        "opencv_visibility_mismatch": int((cv_vis != rule).sum()),
        "float32_visibility_flips": [labels[i] for i in np.flatnonzero(flips)],
        "float32_points_in_band": [labels[i] for i in np.flatnonzero(band)],
        "float32_band_at_near": float(camera_error("float32", p, None, cam)[0, 2] + EPS32 * near),
    }
    c.pyrender_note = "no edges: visibility of points only"


# ---- 2 ---------------------------------------------------------------------


def _grazing_scene(cam, near, slopes):
    """Edges in camera space crossing z = near at each slope, as float64 world points."""
    basis = reference_basis(cam)  # rows right, up, forward
    pos = np.asarray(cam.position, LD)
    ends_cam = []
    k = 0
    for s in slopes:
        for variant in range(2):
            y = LD(-0.35 + 0.1 * k)
            k += 1
            if variant == 0:  # along x, the clipped end first
                d = np.array([0.25, 0.0], dtype=LD)
            else:  # diagonal, the visible end first
                d = np.array([-0.25, -0.05], dtype=LD)
            half_dz = LD(s) * norm_ld(d)
            a = np.array([-d[0], y - d[1], LD(near) - half_dz], dtype=LD)
            b = np.array([d[0], y + d[1], LD(near) + half_dz], dtype=LD)
            ends_cam += [a, b] if variant == 0 else [b, a]
    ends_cam = np.array(ends_cam, dtype=LD)
    world = (ends_cam @ basis + pos).astype(np.float64)
    edges = np.arange(len(world)).reshape(-1, 2)
    return world, edges


def _core_clipped_ends(world, edges, cam, dt, clipped_first):
    """core's ends of ``edges`` on the near plane, ``(end_cam, end_px)`` in float64; None if one was dropped."""
    pc = model_to_cam(localize(world, dt), np.eye(4), cam)
    seg = pc[edges]
    planes = clipping.frustum_planes(cam).astype(pc.dtype)
    kept, t0, t1 = clipping.clip_segments(seg, planes)
    if not kept.all():
        return None
    out = clipping.apply_clip(seg, kept, t0, t1, (cam.near, cam.far))
    end = np.where(clipped_first[:, None], out[:, 0, :], out[:, 1, :])
    return end.astype(np.float64), cam_to_px(end, cam).astype(np.float64)


def _worst_per_slope(per_slope, dt, slopes, z_err, z_bound, px_err, px_bound, kappa):
    """Per slope: the worst error and the tightest bound over its two edges."""
    for i, s in enumerate(np.repeat(slopes, 2)):
        d = per_slope.setdefault(f"{s:g}", {})
        cur = d.setdefault(dt, {"z_error": 0.0, "z_bound": np.inf, "px_error": 0.0, "px_bound": np.inf, "kappa": 0.0})
        cur["z_error"] = max(cur["z_error"], float(z_err[i]))
        cur["z_bound"] = min(cur["z_bound"], float(z_bound[i]))
        cur["px_error"] = max(cur["px_error"], float(px_err[i]))
        cur["px_bound"] = min(cur["px_bound"], float(px_bound[i]))
        cur["kappa"] = max(cur["kappa"], float(kappa[i]))


def _grazing_pyrender(c: CaseRecord, pr: Pyrender, world, edges, cam, slopes):
    """pyrender per slope, judged only where float32 GL resolves the crossing."""
    f, near = cam.focal_px, cam.near
    for j, s in enumerate(slopes):
        e = edges[2 * j : 2 * j + 2]
        frame = render_frame(world, e, cam, np.eye(4))
        scores, note = pr.scores(frame.mask, world, e, cam)
        # judged only where GL's float32 vertex positions (|p| ~ 4.1, rounded by u |p| per coordinate,
        # ~3 u |p| in depth) move the crossing by < 0.5 px: 1.5 eps32 |p| / s * f / near (1e-3: 0.3 px)
        judged = 1.5 * EPS32 * 4.1 / s * f / near < 0.5
        c.add_pyrender(f"slope {s:g}", scores, note, judged=judged)
    if c.pyrender_parts:
        c.pyrender_note = (
            "F1 judged only at slopes where float32 GL resolves the crossing to < 0.5 px "
            "(1.5 eps32 |p| / slope * f / near); smaller slopes are information: there GL "
            "cannot tell the ends' depths apart and draws the whole edge"
        )


def near_grazing(c: CaseRecord, pr: Pyrender) -> None:
    """edges crossing the near plane at slopes 1e-3..1e-9 (nearly parallel to it): the clipped end lies
    on z = near and projects near the exact intersection.

    Notes
    -----
    clipped_end_bounds: at slopes <= 1e-7 float32 cannot resolve the ends' depths, and its bound lets the
    crossing lie anywhere on the edge. Points: pixel_bound.
    """
    near = 1.0
    cam = look_at((0.3, 0.2, 4.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0), near=near, far=100.0)
    slopes = (1e-3, 1e-5, 1e-7, 1e-9)
    world, edges = _grazing_scene(cam, near, slopes)
    m = measure(world, None, cam, edges=edges)
    c.add(m)
    ref_cam = m["ref"][0]
    p0, p1 = ref_cam[edges[:, 0]], ref_cam[edges[:, 1]]
    clipped_first = p0[:, 2] < LD(near)  # which end the near plane cuts
    t_star = (LD(near) - p0[:, 2]) / (p1[:, 2] - p0[:, 2])
    q_ref = p0 + t_star[:, None] * (p1 - p0)  # exact intersection (long double)
    q_px = reference_cam_to_px(q_ref, cam)
    per_slope = {}
    for dt in DTYPES:
        ends = _core_clipped_ends(world, edges, cam, dt, clipped_first)
        c.check(ends is not None, f"{dt}: a grazing edge was dropped")
        if ends is None:
            continue
        end_cam, end_px = ends
        e_cam = camera_error(dt, world, None, cam)
        e_end = np.maximum(e_cam[edges[:, 0]], e_cam[edges[:, 1]]).max(axis=1)  # worst component
        z_bound, px_bound, kappa = clipped_end_bounds(p0, p1, q_ref, q_px, e_end, cam, EPS[dt])
        z_err = np.abs(end_cam[:, 2] - near)
        px_err = err_px(end_px, q_px)
        _worst_per_slope(per_slope, dt, slopes, z_err, z_bound, px_err, px_bound, kappa)
        c.check(
            not (z_err > z_bound).any(),
            f"{dt}: clipped end off the near plane by {z_err.max():.3g} "
            f"(bound {z_bound[np.argmax(z_err / z_bound)]:.3g})",
        )
        c.check(
            not (px_err > px_bound).any(),
            f"{dt}: clipped end {px_err.max():.3g} px from the exact "
            f"intersection (max error/bound {(px_err / px_bound).max():.3g})",
        )
        c.stats[dt]["clipped_end_px_error"] = float(px_err.max())
        c.stats[dt]["clipped_end_px_ratio"] = float((px_err / px_bound).max())
        c.stats[dt]["clipped_end_z_error"] = float(z_err.max())
    c.extra = {
        "near": near,
        "per_slope": per_slope,
        "note": "per slope: worst error and tightest bound over its two edges; float32 cannot "
        "resolve depth differences below ~eps32 |p| = 5e-7, so at slopes <= 1e-7 its "
        "crossing may be anywhere on the edge (the bound says so via min(|p1-p0|, ...)).",
    }
    _grazing_pyrender(c, pr, world, edges, cam, slopes)


# ---- 3 ---------------------------------------------------------------------


def fov_extremes(c: CaseRecord, pr: Pyrender) -> None:
    """fov 0.01 deg (f = 2.75e6 px) and 179.9 deg (f = 0.21 px) on a 640x480 image.

    Notes
    -----
    pixel_bound: the f/z factor carries the 2.75e6 px focal length at 0.01 deg. From 1e4 away,
    render_frame's float32 lateral error is 3 eps32 |p_local| f / z ~ 1e-4 px (t_mv's lateral components
    are ~0 after the float64 model-view; project_points takes the same path), where casting
    p_world - position (|.| = 1e4) before rotating would give 3 eps32 |p_rel| f / z ~ 1 px. At 179.9 deg
    the focal length's float64 rounding is magnified by kappa_f = 2 a / sin(a) + 2 ~ 3600.
    """
    # fov 0.01 deg: the image spans 2 * 1e4 * tan(0.005 deg) = 1.75 units vertically at 1e4
    # from an oblique direction: every world axis contributes ~1e4 to x_cam, y_cam (cancelling)
    cam_small = look_at(
        1e4 * np.array([0.6, 0.48, 0.64]), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0), fov_y_deg=0.01, near=1.0, far=2e4
    )
    mm = compose(rotate_z(0.3), rotate_y(0.5), rotate_x(0.2))
    m = measure(CUBE_V, mm, cam_small, edges=CUBE_E)
    c.add(m, label="fov 0.01: ")
    scores, note = pr.scores(m["frames"]["float64"].mask, CUBE_V, CUBE_E, cam_small, mm)
    c.add_pyrender("fov 0.01", scores, note, judged=True)
    small = {dt: public(m[dt]) for dt in DTYPES}
    small["opencv"] = public(m["opencv"])
    small["project_points"] = {dt: public(m["pp_" + dt]) for dt in DTYPES}
    # fov 179.9 deg: f = 0.21 px; points up to 89.94 deg off axis (x/z up to ~950)
    cam_wide = look_at((0.0, 0.0, 4.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0), fov_y_deg=179.9, near=0.01, far=1e5)
    rng = np.random.default_rng(1799)
    theta = np.radians(np.concatenate([np.linspace(0.0, 89.0, 30), [89.9, 89.93, 89.94]]))
    phi = rng.uniform(0, 2 * np.pi, len(theta))
    rad = rng.uniform(1.0, 50.0, len(theta))
    dirs = np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)], axis=1)
    p_cam = dirs * rad[:, None]
    basis = np.stack([cam_wide.right, cam_wide.up, cam_wide.forward])
    pts = p_cam @ basis + cam_wide.position  # inputs (rounded float64 world points)
    ring = np.arange(len(pts))
    e_wide = np.stack([ring[:-1], ring[1:]], axis=1)
    m2 = measure(pts, None, cam_wide, edges=e_wide)
    c.add(m2, label="fov 179.9: ")
    scores, note = pr.scores(m2["frames"]["float64"].mask, pts, e_wide, cam_wide)
    c.add_pyrender("fov 179.9", scores, note, judged=True)
    wide = {dt: public(m2[dt]) for dt in DTYPES}
    wide["opencv"] = public(m2["opencv"])
    wide["project_points"] = {dt: public(m2["pp_" + dt]) for dt in DTYPES}
    c.extra = {
        "fov_0.01": dict(small, focal_px=cam_small.focal_px),
        "fov_179.9": dict(wide, focal_px=cam_wide.focal_px, kappa_f=focal_condition(cam_wide)),
    }


# ---- 4 ---------------------------------------------------------------------


def _zigzag(width, height, fov=60.0):
    """A camera 4 units up +Z and a zig-zag filling the long side of the image."""
    cam = look_at(
        (0.0, 0.0, 4.0),
        (0.0, 0.0, 0.0),
        (0.0, 1.0, 0.0),
        fov_y_deg=fov,
        width=width,
        height=height,
        near=0.1,
        far=100.0,
    )
    f = cam.focal_px
    n = 41
    lim_x = 0.95 * (width / 2) / f * 4  # world extent that fills 95 % of each side at depth 4
    lim_y = 0.95 * (height / 2) / f * 4
    if width >= height:
        xs = np.linspace(-lim_x, lim_x, n)
        ys = np.where(np.arange(n) % 2 == 0, lim_y, -lim_y)
    else:
        ys = np.linspace(-lim_y, lim_y, n)
        xs = np.where(np.arange(n) % 2 == 0, lim_x, -lim_x)
    v = np.stack([xs, ys, np.zeros(n)], axis=1)
    e = np.stack([np.arange(n - 1), np.arange(1, n)], axis=1)
    return cam, v, e


def aspect_extremes(c: CaseRecord, pr: Pyrender) -> None:
    """4000x4 and 4x4000 images, zig-zag lines across the long side.

    Notes
    -----
    pixel_bound; f = 3.46 px (4000x4) and 3464 px (4x4000), |x_px| up to 4000.
    """
    mm = compose(translate((1e-3, -1e-3, 0.05)), rotate_y(1e-5))
    for w, h in ((4000, 4), (4, 4000)):
        cam, v, e = _zigzag(w, h)
        m = measure(v, mm, cam, edges=e)
        c.add(m, label=f"{w}x{h}: ")
        frame = m["frames"]["float64"]
        c.check(
            int(frame.mask.sum()) > max(w, h) // 2,
            f"{w}x{h}: expected a line across the long side, got {int(frame.mask.sum())} pixels",
        )
        scores, note = pr.scores(frame.mask, v, e, cam, mm)
        c.add_pyrender(f"{w}x{h}", scores, note, judged=True)
        if scores is not None:
            c.pyrender_note = "OSMesa renders both 4000x4 and 4x4000 (no size limit hit)"
        c.extra[f"{w}x{h}"] = {
            "focal_px": cam.focal_px,
            "core_pixels": int(frame.mask.sum()),
            "float64": public(m["float64"]),
            "float32": public(m["float32"]),
        }


# ---- 5 ---------------------------------------------------------------------


def far_from_origin(c: CaseRecord, pr: Pyrender) -> None:
    """a unit cube 1e8 from the world origin seen from 4 units away, placed by the model matrix; by
    vertices at 1e8 (re-centred by localize); and by vertices at 1e8 under a model rotation about the
    world origin (where float64 must round A o, |A o| = 1e8).

    Notes
    -----
    pixel_bound with F = |A| |o| + |t| + |position| ~ 2e8: float64 3 eps64 F f / z ~ 1e-5 px (the
    float64 model-view: exact here when A = I, as Sterbenz makes t - position exact; real when A o must
    be rounded), float32 3 eps32 (|p_local| + |t_mv_i|) f / z ~ 5e-4 px (t_mv ~ 4, not 1e8): both
    sub-pixel; OpenCV's bound 8 eps64 (|X| + |position|) f / z (not camera-relative).
    """
    o = 1e8 * np.array([0.6, 0.48, 0.64])  # |o| = 1e8
    cam = look_at(o + (0.3, 0.2, 4.0), o, (0.0, 1.0, 0.0), near=0.1, far=100.0)
    rot = compose(rotate_z(0.3), rotate_y(0.5), rotate_x(0.2))
    # (a) unit cube at the model origin, placed by the model matrix's translation
    mm = compose(translate(o), rot)
    ma = measure(CUBE_V, mm, cam, edges=CUBE_E)
    c.add(ma, label="model matrix: ")
    # (b) the same cube's vertices at 1e8 themselves, identity model matrix (localize re-centres)
    vb = (reference_world(CUBE_V, rot[:3, :3], o)).astype(np.float64)
    mb = measure(vb, None, cam, edges=CUBE_E)
    c.add(mb, label="vertices at 1e8: ")
    # (c) vertices at 1e8 AND a model rotation about the world origin: A o (1e8) is formed in
    # float64, so here the 3 eps64 F term of the bound is real (core ~ OpenCV's error)
    a_c = compose(rotate_z(0.7), rotate_x(0.4))
    ao = reference_world(o[None, :], a_c[:3, :3], np.zeros(3))[0]
    cam_c = look_at(
        (ao + np.array([0.3, 0.2, 4.0], dtype=LD)).astype(np.float64),
        ao.astype(np.float64),
        (0.0, 1.0, 0.0),
        near=0.1,
        far=100.0,
    )
    vc = (reference_world(CUBE_V, rot[:3, :3] @ a_c[:3, :3].T, o)).astype(np.float64)
    mc = measure(vc, a_c, cam_c, edges=CUBE_E)
    c.add(mc, label="vertices at 1e8, rotated: ")
    c.check(int(mc["frames"]["float64"].mask.sum()) > 100, "rotated far cube: expected it drawn on screen")
    for dt in DTYPES:
        worst = max(ma[dt]["max_error_px"], mb[dt]["max_error_px"], mc[dt]["max_error_px"])
        c.check(worst < 0.5, f"{dt}: {worst:.3g} px: expected sub-pixel")
    c.check(
        bool(np.array_equal(ma["frames"]["float64"].mask, mb["frames"]["float64"].mask)),
        "the two placements draw different float64 frames",
    )
    c.extra = {
        "model_matrix": {dt: public(ma[dt]) for dt in DTYPES} | {"opencv": public(ma["opencv"])},
        "vertices_at_1e8": {dt: public(mb[dt]) for dt in DTYPES} | {"opencv": public(mb["opencv"])},
        "vertices_at_1e8_rotated": {dt: public(mc[dt]) for dt in DTYPES} | {"opencv": public(mc["opencv"])},
        "origin_distance": float(np.linalg.norm(o)),
    }
    sa, note = pr.scores(ma["frames"]["float64"].mask, CUBE_V, CUBE_E, cam, mm)
    c.add_pyrender("model matrix", sa, note, judged=False)
    sb, note = pr.scores(mb["frames"]["float64"].mask, vb, CUBE_E, cam)
    c.add_pyrender("vertices at 1e8", sb, note, judged=False)
    if sa is not None:
        c.pyrender_note = (
            "information only: pyrender/GL is float32 and not camera-relative, at 1e8 "
            "float32 spacing is 8 units, larger than the cube"
        )


# ---- 6 ---------------------------------------------------------------------


def subpixel_object(c: CaseRecord, pr: Pyrender) -> None:
    """a unit cube 1e5 away: the whole cube is < 0.01 px on screen.

    Notes
    -----
    pixel_bound; drawn pixels: all within 1 px of the projected centre, at most 4.
    """
    d = 1e5
    cam = look_at((0.0, 0.0, d), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0), near=1.0, far=2e5)
    f = cam.focal_px
    # put the cube's centre at pixel (400.2, 150.3): inside a pixel, away from its edges
    centre_px = np.array([400.2, 150.3])
    cx, cy = cam.principal_point
    offset = ((centre_px[0] - cx) * d / f, -(centre_px[1] - cy) * d / f, 0.0)
    mm = compose(translate(offset), rotate_y(0.4), rotate_x(0.3))
    m = measure(CUBE_V, mm, cam, edges=CUBE_E)
    c.add(m)
    ref_px = m["ref"][1].astype(np.float64)
    extent = float(np.ptp(ref_px, axis=0).max())
    c.extra = {"screen_extent_px": extent, "centre_px": centre_px.tolist()}
    c.check(extent < 0.01, f"the cube covers {extent:.3g} px: expected < 0.01 (test design)")
    rc = np.floor(ref_px.mean(axis=0) + 0.5)  # the pixel under the cube
    for dt in DTYPES:
        mask = m["frames"][dt].mask
        rows, cols = np.nonzero(mask)
        c.extra[f"{dt}_pixels"] = int(mask.sum())
        c.check(len(rows) <= 4, f"{dt}: {len(rows)} pixels drawn for a sub-pixel cube: expected <= 4")
        near_ok = (np.abs(cols - rc[0]) <= 1).all() and (np.abs(rows - rc[1]) <= 1).all()
        c.check(bool(near_ok), f"{dt}: pixels drawn away from the cube's pixel {rc.tolist()}")
    scores, note = pr.scores(m["frames"]["float64"].mask, CUBE_V, CUBE_E, cam, mm)
    if scores is not None:
        c.extra["pyrender_pixels"] = scores["pyrender_pixels"]
        c.check(scores["pyrender_pixels"] <= 4, f"pyrender drew {scores['pyrender_pixels']} pixels: expected <= 4")
    c.add_pyrender("cube", scores, note, judged=False)
    if scores is not None:
        c.pyrender_note = (
            "F1 not judged: whether a line shorter than 0.01 px lights a pixel is decided "
            "by sub-pixel tie rules; both must draw <= 4 pixels"
        )


# ---- 7 ---------------------------------------------------------------------


def rotation_period(c: CaseRecord, pr: Pyrender) -> None:
    """Motion(turns=(1000, 3000, 500)) over 1,000,000 frames has period 2000: frame k and k + 2000 give
    bit-identical model matrices, p_px and images.

    Notes
    -----
    bit-identical (no tolerance): the phase ((k-1) turns mod n) / n is exact in float64. Matrix vs the
    long-double rotation of the exact phase: motion_matrix_error. Pixels: pixel_bound with model_err =
    motion_matrix_error.
    """
    turns, frames, period = (1000, 3000, 500), 1_000_000, 2000
    motion = Motion(turns=tuple(float(t) for t in turns))
    cam = look_at((0.3, 0.2, 4.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    ks = [1, 2, 777, 123_457, 499_999, 997_001, 997_999, 998_000]
    mat_err = 0.0
    identical = {"matrix": True, "p_px": True, "image": True}
    for k in ks:
        m0 = motion.frame_matrix(k, frames)
        m1 = motion.frame_matrix(k + period, frames)
        same_m = m0.tobytes() == m1.tobytes()
        identical["matrix"] &= same_m
        c.check(same_m, f"frames {k} and {k + period}: model matrices differ")
        a_ld, t_ld = reference_motion_matrix(turns, (0, 0, 0), 1.0, k, frames)
        mat_err = max(mat_err, float(np.abs(m0[:3, :3].astype(LD) - a_ld).max()))
        fr = {}
        for kk, mk in ((k, m0), (k + period, m1)):
            fr[kk] = {dt: render_frame(CUBE_V, CUBE_E, cam, mk, dtype=dt) for dt in DTYPES}
        for dt in DTYPES:
            a, b = fr[k][dt], fr[k + period][dt]
            same_px = a.p_px.tobytes() == b.p_px.tobytes()
            same_img = a.image.tobytes() == b.image.tobytes()
            identical["p_px"] &= same_px
            identical["image"] &= same_img
            c.check(
                same_px and same_img,
                f"{dt}: frames {k} and {k + period} differ in {'p_px' if not same_px else 'image'}",
            )
        m = measure(CUBE_V, m0, cam, edges=CUBE_E, model_err=motion_matrix_error(), a_ld=a_ld, t_ld=t_ld, frames=fr[k])
        c.add(m, label=f"frame {k}: ")
    c.check(
        mat_err <= motion_matrix_error(), f"model matrix {mat_err:.3g} from the exact rotation: expected <= 16 eps64"
    )
    # the last frame of the run closes the loop: frame 1 + frames is frame 1 again
    c.check(
        motion.frame_matrix(1, frames).tobytes() == motion.frame_matrix(1 + frames, frames).tobytes(),
        "frame 1 + frames differs from frame 1",
    )
    c.extra = {
        "turns": list(turns),
        "frames": frames,
        "period": period,
        "sampled_k": ks,
        "bit_identical": identical,
        "matrix_error_vs_exact": mat_err,
        "matrix_error_bound": motion_matrix_error(),
    }
    c.pyrender_note = "not needed: the check is bit-identity between core's own frames"


# ---- 8 ---------------------------------------------------------------------


def gimbal_lock(c: CaseRecord, pr: Pyrender) -> None:
    """pitch exactly +-90 deg (Ry at 1/4 and 3/4 turn) with roll and yaw; cameras looking straight down
    (-Y) and up (+Y) with up = -Z / +Z.

    Notes
    -----
    R^T R - I: orthonormality_error; pixels: pixel_bound with model_err = motion_matrix_error.
    """
    turns, frames = (3, 2, 5), 8  # frame 2: phases (3/8, 1/4, 5/8); frame 4: (1/8, 3/4, 7/8)
    motion = Motion(turns=tuple(float(t) for t in turns), offset=(0.1, -0.2, 0.3))
    cam = look_at((0.3, 0.2, 4.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    ortho_err = 0.0
    for k, pitch in ((2, 90), (4, -90)):
        mk = motion.frame_matrix(k, frames)
        a = mk[:3, :3]
        d = float(np.abs(a.T @ a - np.eye(3)).max())
        ortho_err = max(ortho_err, d)
        a_ld, t_ld = reference_motion_matrix(turns, motion.offset, 1.0, k, frames)
        m = measure(CUBE_V, mk, cam, edges=CUBE_E, model_err=motion_matrix_error(), a_ld=a_ld, t_ld=t_ld)
        c.add(m, label=f"pitch {pitch:+d}: ")
        c.extra[f"pitch_{pitch:+d}_frame"] = k
        scores, note = pr.scores(m["frames"]["float64"].mask, CUBE_V, CUBE_E, cam, mk)
        c.add_pyrender(f"pitch {pitch:+d}", scores, note, judged=True)
    c.check(ortho_err <= orthonormality_error(), f"R^T R - I = {ortho_err:.3g}: expected <= 16 eps64")
    c.extra["orthonormality_error"] = ortho_err
    c.extra["orthonormality_bound"] = orthonormality_error()
    # cameras straight down / up the Y axis, with up along -Z / +Z
    for name, pos, up in (("down", (0.0, 5.0, 0.0), (0.0, 0.0, -1.0)), ("up", (0.0, -5.0, 0.0), (0.0, 0.0, 1.0))):
        try:
            cv = look_at(pos, (0.0, 0.0, 0.0), up)
        except InputError as exc:
            c.fail(f"camera looking {name}: {exc}")
            continue
        mm = compose(rotate_y(0.3), rotate_x(0.1))
        m = measure(CUBE_V, mm, cv, edges=CUBE_E)
        c.add(m, label=f"looking {name}: ")
        scores, note = pr.scores(m["frames"]["float64"].mask, CUBE_V, CUBE_E, cv, mm)
        c.add_pyrender(f"looking {name}", scores, note, judged=True)
        c.extra[f"looking_{name}_right"] = [float(x) for x in cv.right]


#: The cases in suite order.
CASES = (
    near_plane,
    near_grazing,
    fov_extremes,
    aspect_extremes,
    far_from_origin,
    subpixel_object,
    rotation_period,
    gimbal_lock,
)
