"""One vertex traced through every space: ``renderer --trace-vertex I``.

For vertex ``I`` of a scene in frame ``k`` of a run::

    p_model  --model matrix M(k)-->  p_world  --world_to_cam-->  p_cam
             --clip_matrix-->  p_clip (homogeneous)  --divide by w-->  p_ndc
             --viewport-->  p_px

core's pipeline goes from camera space straight to pixels (it clips in camera
space and never forms clip coordinates; core.conventions); ``p_clip`` and
``p_ndc`` are given here in OpenGL's form (:func:`clip_matrix`) so the trace can
be read against any textbook or GL pipeline, and the pixel from NDC is checked
against core's own. The pixel reported is the one the pipeline drew
(``render_frame``'s ``p_px``). For each edge of the vertex the trace says whether
the pipeline's clipping (core.projector.clipping) keeps it whole, shortens it (the planes
that cut it, the kept parameter range and the new ends) or drops it.
"""

from __future__ import annotations

import numpy as np

from ..camera import Camera
from ..errors import InputError
from ..numbers import plain_int
from ..projector import clipping
from ..projector.projection import cam_to_px, world_to_cam
from ..scene.model import Scene, object_matrix
from ..transforms import Motion, apply

#: core.projector.clipping.frustum_planes' order.
PLANE_NAMES = ("near", "far", "left", "right", "top", "bottom")


def clip_matrix(camera: Camera) -> np.ndarray:
    """4x4 ``p_clip = P @ [p_cam, 1]`` in OpenGL's form for core's camera space (z forward).

    Perspective: ``w = z_cam``; after the divide x_ndc, y_ndc are -1..1 from the
    left/bottom image edge to the right/top one, and z_ndc is -1 at near, +1 at
    far (``glFrustum`` with z negated, as camera z points forward here)::

        x_clip = (2 fx / W) x_cam + (2 (cx + 0.5) / W - 1) z_cam
        y_clip = (2 fy / H) y_cam + (1 - 2 (cy + 0.5) / H) z_cam
        z_clip = (far + near)/(far - near) z_cam - 2 far near/(far - near)
        w_clip = z_cam

    (``glFrustum``'s off-centre terms; ``+ 0.5``: GL pixel centres sit at
    half-integers, core.conventions. A centred camera, ``cx = (W - 1)/2``, has
    both z terms exactly 0; fx = fy = f_px of the FOV unless calibrated.) The
    undistorted projection: with lens distortion ``pixel_from_ndc`` is the
    ideal pixel, not the distorted one drawn.

    Orthographic (``s = H / ortho_height`` px per unit): ``x_clip = (2 s / W)
    x_cam``, ``y_clip = (2 s / H) y_cam``, ``z_clip = 2 (z_cam - near)/(far -
    near) - 1``, ``w_clip = 1``.
    """
    w, h, n, f = camera.width, camera.height, camera.near, camera.far
    p = np.zeros((4, 4))
    if camera.projection == "perspective":
        fx, fy = camera.focal_xy
        cx, cy = camera.principal_point
        p[0, 0], p[1, 1] = 2 * fx / w, 2 * fy / h
        p[0, 2], p[1, 2] = 2 * (cx + 0.5) / w - 1, 1 - 2 * (cy + 0.5) / h
        p[2, 2], p[2, 3] = (f + n) / (f - n), -2 * f * n / (f - n)
        p[3, 2] = 1.0
    else:
        s = h / camera.ortho_height
        p[0, 0], p[1, 1] = 2 * s / w, 2 * s / h
        p[2, 2], p[2, 3] = 2 / (f - n), -2 * n / (f - n) - 1
        p[3, 3] = 1.0
    return p


def ndc_to_px(p_ndc: np.ndarray, camera: Camera) -> np.ndarray:
    """``(..., 3)`` NDC to ``(..., 2)`` pixels (pixel centres at integers, y down; core.conventions)."""
    p_ndc = np.asarray(p_ndc, dtype=np.float64)
    x = (p_ndc[..., 0] + 1.0) * camera.width / 2.0 - 0.5
    y = (1.0 - p_ndc[..., 1]) * camera.height / 2.0 - 0.5
    return np.stack([x, y], axis=-1)


def model_matrix_of(scene: Scene, motion: Motion, vertex: int, k: int, frames: int) -> np.ndarray:
    """The model matrix that takes ``vertex`` to world space in frame ``k`` (its object's, then the run's)."""
    if scene.is_single_static:
        return motion.frame_matrix(k, frames)
    obj = next(o for o in scene.objects if o.vertex_start <= vertex < o.vertex_stop)
    return object_matrix(obj, motion, k, frames)


def check_vertex(scene: Scene, vertex: int) -> None:
    if not 0 <= vertex < len(scene.vertices):
        raise InputError(
            f"--trace-vertex {vertex}: scene {scene.name!r} has {len(scene.vertices)} vertices: "
            f"expected an index in [0, {len(scene.vertices) - 1}]"
        )


def parse_frames(text: str | None, frames: int) -> list[int]:
    """``--trace-frames 1,90,180`` (default: first, middle, last) as sorted unique frame numbers."""
    if text is None:
        return sorted({1, max(1, frames // 2) if frames >= 180 else (frames + 1) // 2, frames})
    try:
        ks = [plain_int(x) for x in text.split(",") if x.strip()]
    except ValueError:
        ks = []
    if not ks or any(not 1 <= k <= frames for k in ks):
        raise InputError(f"--trace-frames {text!r}: expected comma-separated frame numbers in [1, {frames}]")
    return sorted(set(ks))


def trace_vertex(
    scene: Scene, motion: Motion, camera: Camera, vertex: int, k: int, frames: int, p_px_drawn=None
) -> dict:
    """The vertex's coordinates in every space, its visibility and its edges' clipping, in frame ``k``.

    ``p_px_drawn`` is the pixel the pipeline drew for it (``Frame.p_px[vertex]``),
    reported as ``pixel``; without it, core's ``cam_to_px`` of ``p_cam``.
    """
    check_vertex(scene, vertex)
    m = model_matrix_of(scene, motion, vertex, k, frames)
    p_model = np.asarray(scene.vertices[vertex], dtype=np.float64)
    p_world = apply(m, p_model)[0]  # world
    p_cam = world_to_cam(p_world[None], camera)[0]  # camera
    p_clip = clip_matrix(camera) @ np.append(p_cam, 1.0)  # clip (homogeneous)
    visible = bool(camera.near <= p_cam[2] <= camera.far)
    p_ndc = p_clip[:3] / p_clip[3] if visible else None  # NDC (only in front: w > 0)
    if p_px_drawn is not None:
        p_px = None if not np.all(np.isfinite(p_px_drawn)) else np.asarray(p_px_drawn, dtype=np.float64)
    else:
        p_px = cam_to_px(p_cam[None], camera)[0] if visible else None  # pixels
    on_image = bool(
        p_px is not None and -0.5 <= p_px[0] <= camera.width - 0.5 and -0.5 <= p_px[1] <= camera.height - 0.5
    )
    rec = {
        "frame": k,
        "t": (k - 1) / frames,
        "vertex": vertex,
        "model": p_model.tolist(),
        "world": p_world.tolist(),
        "camera": p_cam.tolist(),
        "depth": float(p_cam[2]),
        "clip": _floats(p_clip),
        "ndc": None if p_ndc is None else _floats(p_ndc),
        "pixel": None if p_px is None else p_px.tolist(),
        "pixel_from_ndc": None if p_ndc is None else _floats(ndc_to_px(p_ndc, camera)),
        "visible": visible,
        "on_image": on_image,
        "edges": _edges(scene, motion, camera, vertex, k, frames, p_cam),
    }
    return rec


def _floats(v) -> list:
    """``v`` as a list, a value that overflowed float64 as None (JSON has no inf).

    GL's clip form overflows where core's pipeline does not: its z row holds
    2 f n / (n - f), infinite for a far plane near 1e308.
    """
    return [float(x) if np.isfinite(x) else None for x in np.asarray(v, dtype=np.float64)]


def _edges(scene, motion, camera, vertex, k, frames, p_cam) -> list[dict]:
    """Each edge of ``vertex`` (this vertex as its start) through core.projector.clipping's planes."""
    edges = np.asarray(scene.edges).reshape(-1, 2)
    mine = edges[(edges == vertex).any(axis=1)]
    planes = clipping.frustum_planes(camera)
    out = []
    for a, b in mine:
        other = int(b if a == vertex else a)
        m_o = model_matrix_of(scene, motion, other, k, frames)
        q_cam = world_to_cam(apply(m_o, scene.vertices[other]), camera)[0]
        seg = np.stack([p_cam, q_cam])[None]  # camera, (1, 2, 3)
        kept, t0, t1 = clipping.clip_segments(seg, planes)
        dist = seg[0] @ planes[:, :3].T + planes[:, 3]  # (2 ends, 6 planes) signed distances
        outside = [j for j in range(len(planes)) if (dist[:, j] < 0).any()]
        e = {"edge": [vertex, other], "ends_outside": [PLANE_NAMES[j] for j in outside]}
        if not kept[0]:
            e["status"] = "dropped"
        elif t0[0] == 0.0 and t1[0] == 1.0:
            e["status"] = "whole"
        else:
            ends_cam = seg[0, 0] + np.array([t0[0], t1[0]])[:, None] * (seg[0, 1] - seg[0, 0])
            # the planes that set the kept range: their crossing is t_enter or t_exit
            cross = {j: dist[0, j] / (dist[0, j] - dist[1, j]) for j in outside if (dist[:, j] < 0).sum() == 1}
            e["cut_by"] = [
                PLANE_NAMES[j]
                for j, tc in cross.items()
                if np.isclose(tc, t0[0], rtol=1e-12, atol=0) or np.isclose(tc, t1[0], rtol=1e-12, atol=0)
            ]
            e.update(
                status="clipped",
                t=[float(t0[0]), float(t1[0])],
                ends_camera=ends_cam.tolist(),
                ends_pixel=cam_to_px(ends_cam, camera).tolist(),
            )
        out.append(e)
    return out


def _fmt(v, digits=6) -> str:
    return "(" + ", ".join("overflow" if x is None else f"{x: .{digits}f}" for x in v) + ")"


def trace_text(rec: dict, camera: Camera) -> str:
    """The trace of one frame as the lines ``renderer`` prints."""
    lines = [
        f"Trace: vertex {rec['vertex']}, frame {rec['frame']} (t = {rec['t']:.6f})",
        f"  model   {_fmt(rec['model'])}",
        f"  world   {_fmt(rec['world'])}   after the model matrix",
        f"  camera  {_fmt(rec['camera'])}   depth z_cam = {rec['depth']:.6f}",
        f"  clip    {_fmt(rec['clip'])}   homogeneous, before the divide",
    ]
    if rec["ndc"] is None:
        lines.append(
            f"  ndc     -   (clipped: z_cam {rec['depth']:.6g} outside [near {camera.near:g}, "
            f"far {camera.far:g}]; never divided)"
        )
    else:
        lines.append(f"  ndc     {_fmt(rec['ndc'])}")
    lines.append(
        "  pixel   "
        + ("-" if rec["pixel"] is None else f"{_fmt(rec['pixel'], 4)}   {'on' if rec['on_image'] else 'off'} the image")
    )
    lines.append(
        f"  visible: {'yes' if rec['visible'] else 'no'} (near {camera.near:g} <= z_cam <= far {camera.far:g})"
    )
    for e in rec["edges"]:
        a, b = e["edge"]
        text = f"  edge {a}-{b}: {e['status']}"
        if e["status"] == "clipped":
            text += (
                f" by {', '.join(e['cut_by'])}: kept t in [{e['t'][0]:.6f}, {e['t'][1]:.6f}], "
                f"ends at px {_fmt(e['ends_pixel'][0], 3)} and {_fmt(e['ends_pixel'][1], 3)}"
            )
        elif e["status"] == "dropped":
            text += f" (ends outside {', '.join(e['ends_outside'])})"
        lines.append(text)
    return "\n".join(lines) + "\n"
