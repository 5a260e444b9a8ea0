"""Two camera distances and two FOVs, compared from the frames: ``renderer --compare``.

The scene is rendered at rest (frame 1 of its motion) by cameras on +Z at
distances ``D1, D2`` looking at the origin, with FOVs ``F1, F2``: a 2x2 picture,
rows by distance, columns by FOV (``<scene>-compare.png``; 1-px grey lines
between the panels).

What changes, for a box of half-width ``a`` whose front face is at ``z_front``
and back face at ``z_back`` (the unit cube: a = 1, z = +1 and -1), seen on axis
with focal length ``f = (H/2)/tan(fov/2)`` (core.conventions)::

    front width  w_front = 2 f a / (D - z_front)      (D - 1 for the cube)
    back width   w_back  = 2 f a / (D - z_back)       (D + 1 for the cube)
    ratio        w_front / w_back = (D - z_back)/(D - z_front) = (D + 1)/(D - 1)
    depth compression: the pixels a unit of depth spans on the receding edges,
        (w_front - w_back) / 2 / (z_front - z_back), per pixel of a unit of
        front width, w_front / (2 a):  = a / (D - z_back) = 1 / (D + 1)

The FOV only scales ``f``: every size in the picture scales by
``tan(F1/2) / tan(F2/2)`` and the ratios above do not change. Distance changes
the ratios: a nearer camera exaggerates depth (the front face twice the back at
D = 3), a farther one flattens it toward the orthographic picture (ratio -> 1,
compression -> 0).

The widths are measured from the drawn pixels: along the image row through the
principal point a box seen on axis crosses four vertical edges (front left,
back left, back right, front right); each crossing's position is the centre of
its run of drawn pixels. A line's pixel is within 0.5 px of the true crossing
(the rasterizer's diamond rule), so each width is within 1 px of the formula.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from ..camera import camera_z
from ..errors import InputError
from ..numbers import plain_float
from ..outputs import output
from ..outputs.staging import Staging
from ..scene.model import world_points
from .compose import picture, side_by_side

#: Drawn pixels: at least half coverage (raster "aa"), as the crosscheck's threshold.
DRAWN = 128


def parse_pair(option: str, text: str, lo: float, hi: float) -> tuple[float, float]:
    """``"3,6"`` to (3.0, 6.0), each finite and in (lo, hi); InputError otherwise."""
    try:
        vals = tuple(plain_float(x) for x in text.split(","))
    except ValueError:
        vals = ()
    if len(vals) != 2 or not all(math.isfinite(v) and lo < v < hi for v in vals):
        raise InputError(f"{option} {text!r}: expected two numbers A,B in ({lo:g}, {hi:g})")
    return vals


def crossings(image: np.ndarray, row: int) -> list[float]:
    """Centres (x, px) of the runs of drawn pixels along ``row``, left to right."""
    drawn = np.asarray(image)[row] >= DRAWN
    if drawn.ndim > 1:
        drawn = drawn.any(axis=-1)
    edges = np.diff(np.concatenate([[0], drawn.astype(np.int8), [0]]))
    starts, stops = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
    return [(a + b - 1) / 2.0 for a, b in zip(starts, stops)]


def box_of(vertices: np.ndarray) -> dict:
    """Half-width (x) and front/back z of the scene's bounding box at rest."""
    v = np.asarray(vertices, dtype=np.float64)
    return {
        "half_width": float(max(abs(v[:, 0].min()), abs(v[:, 0].max()))),
        "z_front": float(v[:, 2].max()),
        "z_back": float(v[:, 2].min()),
    }


def predicted(distance: float, fov: float, height: int, box: dict) -> dict:
    """The formulas of the module docstring for one camera."""
    f = (height / 2.0) / math.tan(math.radians(fov) / 2.0)
    a, zf, zb = box["half_width"], box["z_front"], box["z_back"]
    w_front, w_back = 2 * f * a / (distance - zf), 2 * f * a / (distance - zb)
    return {
        "front_width_px": w_front,
        "back_width_px": w_back,
        "ratio": w_front / w_back,
        "depth_compression": (w_front - w_back) / 2 / (zf - zb) / (w_front / (2 * a)),
    }


def measure(image: np.ndarray, row: int) -> dict | None:
    """Front and back widths from the four crossings of ``row``; None unless there are exactly four."""
    xs = crossings(image, row)
    if len(xs) != 4:
        return None
    w_front, w_back = xs[3] - xs[0], xs[2] - xs[1]
    return {
        "crossings_px": xs,
        "front_width_px": w_front,
        "back_width_px": w_back,
        "ratio": w_front / w_back if w_back > 0 else None,
    }


def run_compare(s, distances, fovs) -> tuple[dict, np.ndarray]:
    """Render the four views; return (report, 2x2 picture). ``s`` is the run's core.app.settings.Settings."""
    box = box_of(world_points(s.scene, s.motion, 1, s.frames))  # at rest, with --scale/--translate
    depth = box["z_front"] - box["z_back"]
    if not (depth > 0 and box["half_width"] > 0):  # the widths and their ratio would divide by zero
        raise InputError(
            f"--compare: scene {s.scene.name!r} at rest spans x up to {box['half_width']:g} and z from "
            f"{box['z_back']:g} to {box['z_front']:g}: expected a scene with width in x and depth in z "
            "(the comparison measures its front and back widths)"
        )
    for d in distances:
        if not d - box["z_front"] > s.camera.near:
            raise InputError(
                f"--compare-z {d:g}: the scene's front (z = {box['z_front']:g}) must be beyond the "
                f"near plane ({s.camera.near:g}): expected distances > {box['z_front'] + s.camera.near:g}"
            )
    row = int(round((s.camera.height - 1) / 2.0 + 0.5))  # the row just below the centre line cy
    views, rows = [], []
    for d in distances:
        pics = []
        for fov in fovs:
            cam = camera_z(
                d, fov_y_deg=fov, width=s.camera.width, height=s.camera.height, near=s.camera.near, far=s.camera.far
            )
            frame, _ = replace(s, camera=cam, ortho_camera=None).scene_renderer().render(1, cam)
            img = picture(frame, s.style)
            pics.append(img)
            m = measure(img, row)
            p = predicted(d, fov, s.camera.height, box)
            v = {"camera_z": d, "fov_y_deg": fov, "focal_px": cam.focal_px, "measured": m, "predicted": p}
            if m is not None and depth > 0 and m["front_width_px"] > 0:
                a = box["half_width"]
                v["measured"]["depth_compression"] = (
                    (m["front_width_px"] - m["back_width_px"]) / 2 / depth / (m["front_width_px"] / (2 * a))
                )
            views.append(v)
        rows.append(side_by_side(*pics))
    sep = np.full((1,) + rows[0].shape[1:], 128, dtype=np.uint8)
    grid = np.concatenate([rows[0], sep, rows[1]], axis=0)
    report = {
        "scene": s.scene.name,
        "box": box,
        "row_measured": row,
        "distances": list(distances),
        "fovs": list(fovs),
        "views": views,
        "fov_scale_predicted": math.tan(math.radians(fovs[0]) / 2) / math.tan(math.radians(fovs[1]) / 2),
    }
    by = {(v["camera_z"], v["fov_y_deg"]): v for v in views}
    if all(v["measured"] for v in views):
        report["fov_scale_measured"] = (
            by[(distances[0], fovs[1])]["measured"]["front_width_px"]
            / by[(distances[0], fovs[0])]["measured"]["front_width_px"]
        )
    return report, grid


def explain(report: dict) -> str:
    """The comparison in words, with the measured and predicted numbers."""
    box, views = report["box"], report["views"]
    (d1, d2), (f1, f2) = report["distances"], report["fovs"]
    lines = [
        f"Compare: {report['scene']} at rest, camera on +Z at {d1:g} and {d2:g}, FOV {f1:g} and {f2:g} "
        f"(picture: rows camera_z {d1:g}, {d2:g}; columns FOV {f1:g}, {f2:g})",
        f"Box: half-width {box['half_width']:g}, front z = {box['z_front']:g}, back z = {box['z_back']:g}; "
        f"widths measured on row {report['row_measured']}",
        "",
        f"{'camera_z':>8} {'fov':>5} {'front px':>17} {'back px':>17} {'front/back':>19} {'depth compr.':>19}",
        f"{'':>8} {'':>5} {'meas.':>8} {'pred.':>8} {'meas.':>8} {'pred.':>8} {'meas.':>9} {'pred.':>9} "
        f"{'meas.':>9} {'pred.':>9}",
    ]
    for v in views:
        m, p = v["measured"], v["predicted"]
        if m is None:
            lines.append(
                f"{v['camera_z']:>8g} {v['fov_y_deg']:>5g}  not measurable: the centre row does not cross "
                "four vertical edges (the measurement needs a box seen on axis)"
            )
            continue
        lines.append(
            f"{v['camera_z']:>8g} {v['fov_y_deg']:>5g} {m['front_width_px']:>8.1f} {p['front_width_px']:>8.1f} "
            f"{m['back_width_px']:>8.1f} {p['back_width_px']:>8.1f} {m['ratio']:>9.3f} {p['ratio']:>9.3f} "
            f"{m['depth_compression']:>9.3f} {p['depth_compression']:>9.3f}"
        )
    lines += [
        "",
        f"Distance: the front face is nearer than the back by {box['z_front'] - box['z_back']:g}; at "
        f"D = {d1:g} that is a large part of the distance, so the front face shows "
        f"{views[0]['predicted']['ratio']:.3f}x the back's width ((D - z_back)/(D - z_front)); at D = {d2:g} "
        f"only {views[2]['predicted']['ratio']:.3f}x. The nearer camera exaggerates depth (the receding edges "
        f"span {views[0]['predicted']['depth_compression']:.3f} px per unit of depth for each px per unit of "
        f"front width, against {views[2]['predicted']['depth_compression']:.3f} at D = {d2:g}): the farther "
        "picture is flatter, closer to an orthographic one (ratio 1, compression 0).",
        f"FOV: a wider FOV shortens the focal length, so everything shrinks by tan({f1:g}/2)/tan({f2:g}/2) = "
        f"{report['fov_scale_predicted']:.4f}"
        + (f" (measured {report['fov_scale_measured']:.4f})" if "fov_scale_measured" in report else "")
        + "; the ratios do not change: FOV zooms, distance changes the perspective.",
    ]
    return "\n".join(lines) + "\n"


def main_compare(s, z_text: str, fov_text: str) -> int:
    """``renderer --compare``: write ``<scene>-compare.png/.json/.txt`` to ``s.out`` and print the explanation."""
    import sys

    try:
        distances = parse_pair("--compare-z", z_text, 0.0, math.inf)
        fovs = parse_pair("--compare-fov", fov_text, 0.0, 180.0)
    except InputError as exc:
        print(f"renderer: error: {exc}", file=sys.stderr)
        return 2
    name = s.scene.name
    names = [f"{name}-compare.png", f"{name}-compare.json", f"{name}-compare.txt"]
    # written together, never over a file wirecheck did not write; --out held from here to the end
    stage = Staging(s.out, names)
    try:
        try:
            report, grid = run_compare(s, distances, fovs)
        except InputError as exc:
            stage.abort()
            print(f"renderer: error: {exc}", file=sys.stderr)
            return 2
        text = explain(report)
        stage.path(names[0]).write_bytes(output.png_bytes(grid))
        stage.path(names[1]).write_text(output.json_dumps(report), encoding="utf-8")
        stage.path(names[2]).write_text(text, encoding="utf-8")
        stage.commit()
    except BaseException:
        stage.abort()
        raise
    print(text, end="")
    print(f"Picture: {s.out / f'{name}-compare.png'}")
    return 0
