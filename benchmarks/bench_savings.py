#!/usr/bin/env python
"""What skipping the stages a wireframe does not need saves, measured in one run.

Run from the repo root::

    .venv/bin/python benchmarks/bench_savings.py [--quick] [--json PATH]

Scene: ``trimesh.creation.icosphere(subdivisions=6)`` (40,962 vertices, 122,880
edges, 81,920 triangles), ``camera_z(4.0, fov_y_deg=70)`` at 640x480, posed by
``Motion()`` (as in bench_frame.py). Every row is a stage that wirecheck (or
its pyrender oracle) skips; the table gives what the stage would add per frame
("skipped cost"), what runs now ("run cost") and the share saved,
``skipped / (run + skipped)``:

* faces: the renderer's frame loop (``localize`` once, then
  ``render_frame(points, scene.edges, ...)`` as ``core.app.run.render_run`` calls
  it) on a Scene with faces and on the same Scene without: the same work, so
  the same time within noise (checked). The skipped cost is per-face normals
  and the back-face test in numpy, from the frame's camera-space vertices.
* depth buffer: a per-frame float32 (H, W) z-buffer filled with +inf, each
  line pixel's depth (1/z interpolated along its segment: perspective-correct),
  ``np.minimum.at`` into the buffer, and the depth test before the write, in
  place of the plain ``image[rr, cc] = 255``. Raster mode "fast" (its pixel
  count per segment is known, so each pixel maps to its segment).
* clipping: ``render_frame`` clips only the edges with an end outside
  [near, far] or off the image (none on this mesh); the skipped cost is the
  clip stage (6 planes, clamp, divide, 2-D image guard) run on every edge, as
  a pipeline that clips everything does.
* pyrender (OSMesa): the oracle's setup (GL_LINES, ``RenderFlags.FLAT``, no
  lights, no faces) against a DirectionalLight and default flags (lit
  shader), and against the mesh's faces added as black occluders (FLAT,
  polygon offset, as the oracle does when given faces). Scenes built here with
  one OffscreenRenderer; the oracle class itself is timed too.
* scene loading: ``trimesh.load(process=True)`` against ``process=False``
  (core.scene.files.load_mesh_file uses ``process=False, maintain_order=True``) on a
  binary PLY of an icosphere with 163,842 vertices (``--quick``: 40,962)
  written to a temporary directory; and ``core.scene.files.load_scene`` on it.

Statistics: as bench_scale.py (median per-call time over rounds x passes x
poses, rounds alternating the order; GC off).
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

os.environ["PYOPENGL_PLATFORM"] = "osmesa"  # before anything imports pyrender / OpenGL

import numpy as np
import trimesh
from _common import print_end, print_machine, print_table, write_json
from bench_scale import OpenBLAS, bench_group, blas_info, fast_unique_edges
from wirecheck.core.camera import camera_z
from wirecheck.core.projector import clipping, raster
from wirecheck.core.projector.pipeline import render_frame
from wirecheck.core.projector.projection import cam_to_px, localize, model_to_cam
from wirecheck.core.scene.files import load_scene
from wirecheck.core.scene.model import Scene
from wirecheck.core.transforms import Motion

WIDTH, HEIGHT = 640, 480
FRAMES = 180
NOISE_FLOOR = 0.05  # faces / no faces: "identical" when the ratio is within 5 % (or the measured noise)


def make_camera():
    return camera_z(4.0, fov_y_deg=70, width=WIDTH, height=HEIGHT)


def ms(x: float) -> str:
    return f"{x:.3f}" if x < 10 else f"{x:.1f}"


# ---------------------------------------------------------------- stages we skip
def face_stage(p_cam: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Per-face normals and the back-face test, from camera-space vertices: (F,) bool front-facing.

    Camera space is x right, y up, z forward (left-handed), the camera at the
    origin: a face is front-facing when its outward normal points at the
    camera, i.e. ``n . v0 > 0`` with ``n = (v1 - v0) x (v2 - v0)`` here (the
    handedness flips the sign of the usual ``< 0``).
    """
    v0 = np.take(p_cam, faces[:, 0], axis=0)
    v1 = np.take(p_cam, faces[:, 1], axis=0)
    v2 = np.take(p_cam, faces[:, 2], axis=0)
    n = np.cross(v1 - v0, v2 - v0)
    return np.einsum("ij,ij->i", n, v0) > 0


def round_half_up(v: np.ndarray) -> np.ndarray:
    r = np.floor(v)
    return (r + (v - r >= 0.5)).astype(np.int64)


def depth_stage(rr, cc, count, z0, z1, height, width) -> np.ndarray:
    """z-buffered painting of the "fast" raster's pixels; returns the image.

    ``count[m]`` pixels of segment m, in order from its first end (what
    line_pixels_fast returns when every pixel is on the image); ``z0, z1`` the
    camera depths of the ends.
    """
    seg = np.repeat(np.arange(len(count)), count)
    k = np.arange(len(rr)) - np.repeat(np.cumsum(count) - count, count)
    t = (k / np.maximum(count - 1, 1)[seg]).astype(np.float32)
    inv0 = (1.0 / z0).astype(np.float32)[seg]
    inv1 = (1.0 / z1).astype(np.float32)[seg]
    z = 1.0 / (inv0 + t * (inv1 - inv0))  # perspective-correct along the segment
    zbuf = np.full((height, width), np.inf, dtype=np.float32)
    np.minimum.at(zbuf, (rr, cc), z)
    keep = z <= zbuf[rr, cc]
    image = np.zeros((height, width), dtype=np.uint8)
    image[rr[keep], cc[keep]] = 255
    return image


def plain_paint(rr, cc, height, width) -> np.ndarray:
    image = np.zeros((height, width), dtype=np.uint8)
    image[rr, cc] = 255
    return image


# ---------------------------------------------------------------- pyrender
class PyrenderScenes:
    """Three pyrender scenes on one OffscreenRenderer: flat lines, lit lines, flat lines + faces."""

    def __init__(self, vertices, edges, faces, camera):
        import pyrender
        from wirecheck.oracles.references.convert import camera_to_pyrender

        self.pr = pyrender
        self.renderer = pyrender.OffscreenRenderer(camera.width, camera.height)
        pose, cam = camera_to_pyrender(camera)
        pos = np.asarray(vertices, dtype=np.float32)
        white = pyrender.MetallicRoughnessMaterial(baseColorFactor=[1.0, 1.0, 1.0, 1.0])
        black = pyrender.MetallicRoughnessMaterial(baseColorFactor=[0.0, 0.0, 0.0, 1.0], doubleSided=True)

        def lines():
            return pyrender.Primitive(
                positions=pos, indices=edges.astype(np.uint32), mode=pyrender.constants.GLTF.LINES, material=white
            )

        def tris():
            return pyrender.Primitive(
                positions=pos, indices=faces.astype(np.uint32), mode=pyrender.constants.GLTF.TRIANGLES, material=black
            )

        self.scenes, self.nodes = {}, {}
        for name, prims in (("flat", [lines()]), ("lit", [lines()]), ("faces", [lines(), tris()])):
            sc = pyrender.Scene(bg_color=[0.0, 0.0, 0.0, 1.0], ambient_light=[0.0, 0.0, 0.0])
            self.nodes[name] = sc.add(pyrender.Mesh(prims))
            sc.add(cam, pose=pose)
            if name == "lit":
                sc.add(pyrender.DirectionalLight(color=np.ones(3), intensity=3.0), pose=pose)
            self.scenes[name] = sc

    def render(self, name, model_matrix):
        from OpenGL import GL

        pr = self.pr
        self.scenes[name].set_pose(self.nodes[name], model_matrix)
        if name == "faces":  # as PyrenderOracle._polygon_offset
            self.renderer._platform.make_current()
            GL.glEnable(GL.GL_POLYGON_OFFSET_FILL)
            GL.glPolygonOffset(1.0, 1.0)
        flags = pr.RenderFlags.NONE if name == "lit" else pr.RenderFlags.FLAT
        colour, depth = self.renderer.render(self.scenes[name], flags)
        if name == "faces":
            GL.glDisable(GL.GL_POLYGON_OFFSET_FILL)
        return colour[:, :, 0] > 127, depth

    def close(self):
        self.renderer.delete()


# ---------------------------------------------------------------- main
def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="fewer repeats and poses, a smaller file to load")
    ap.add_argument("--json", metavar="PATH", help="also write the results as JSON to PATH")
    args = ap.parse_args(argv)
    t_start = time.perf_counter()
    cfg = (
        {"budget_s": 0.15, "rounds": 2, "max_passes": 10, "poses": 4, "load_subdiv": 6, "load_repeats": 2}
        if args.quick
        else {"budget_s": 0.8, "rounds": 3, "max_passes": 50, "poses": 8, "load_subdiv": 7, "load_repeats": 3}
    )
    blas = OpenBLAS()
    info = blas_info(blas)
    camera = make_camera()
    motion = Motion()
    mats = [motion.frame_matrix(1 + k * FRAMES // cfg["poses"], FRAMES) for k in range(cfg["poses"])]
    n_poses = len(mats)

    mesh = trimesh.creation.icosphere(subdivisions=6)
    v = np.ascontiguousarray(mesh.vertices, dtype=np.float64)
    faces = np.asarray(mesh.faces, dtype=np.intp)
    e = fast_unique_edges(faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), len(v))

    print_machine(
        "wirecheck savings benchmark: what the skipped stages would cost",
        info,
        libraries=(
            f"python {info['python']}, numpy {info['numpy']} (OpenBLAS threads {info['openblas_threads']}), "
            f"cv2 {info['cv2']}, trimesh {info['trimesh']}"
        ),
    )
    print(
        f"  icosphere(6): {len(v):,} V, {len(e):,} E, {len(faces):,} F; camera_z(4.0, fov_y_deg=70) "
        f"{WIDTH}x{HEIGHT}; {n_poses} Motion() poses; mode {'quick' if args.quick else 'full'}"
    )
    print(flush=True)

    bg = dict(n_poses=n_poses, budget_s=cfg["budget_s"], rounds=cfg["rounds"], max_passes=cfg["max_passes"])
    rows, details = [], {}

    # ---- 1. faces: the frame loop on a Scene with and without faces; face processing as it would cost
    scene_faces = Scene("ico6", v.copy(), e.copy(), faces=tuple(map(tuple, faces.tolist())))
    scene_plain = Scene("ico6", v.copy(), e.copy())
    pts_f = localize(scene_faces.vertices)
    pts_p = localize(scene_plain.vertices)
    p_cams = [model_to_cam(pts_p, m, camera) for m in mats]
    front = face_stage(p_cams[0], faces)
    t_faces = bench_group(
        {
            "scene_with_faces": lambda i: render_frame(pts_f, scene_faces.edges, camera, mats[i]),
            "scene_without_faces": lambda i: render_frame(pts_p, scene_plain.edges, camera, mats[i]),
            "face_stage": lambda i: face_stage(p_cams[i], faces),
        },
        **bg,
    )
    with_f = t_faces["scene_with_faces"]["median_ms"]
    without_f = t_faces["scene_without_faces"]["median_ms"]
    face_ms = t_faces["face_stage"]["median_ms"]
    ratio_faces = with_f / without_f
    noise = max(
        abs(t_faces[k]["median_ms"] - t_faces[k]["min_ms"]) / t_faces[k]["median_ms"]
        for k in ("scene_with_faces", "scene_without_faces")
    )
    identical = abs(ratio_faces - 1.0) <= max(NOISE_FLOOR, noise)
    details["faces"] = {
        "timings": t_faces,
        "ratio_with_over_without": ratio_faces,
        "noise": noise,
        "identical_within_noise": identical,
        "front_facing_fraction_pose0": float(front.mean()),
    }
    rows.append(
        {
            "stage": "faces: normals + back-face test",
            "skipped_ms": face_ms,
            "run_ms": with_f,
            "note": f"scene with faces {ms(with_f)} ms vs without {ms(without_f)} ms "
            f"(ratio {ratio_faces:.3f}: {'identical' if identical else 'NOT identical'} within noise "
            f"{max(NOISE_FLOOR, noise):.0%}); front-facing {front.mean():.1%} of faces",
        }
    )

    # ---- 2. depth buffer (raster "fast")
    frames = [render_frame(pts_p, e, camera, m, raster="fast") for m in mats]
    prep = []
    for f, pc in zip(frames, p_cams):
        q0 = round_half_up(np.take(f.p_px, e[:, 0], axis=0))
        q1 = round_half_up(np.take(f.p_px, e[:, 1], axis=0))
        count = np.abs(q1 - q0).max(axis=1) + 1
        rr, cc = raster.line_pixels_fast(
            np.take(f.p_px, e[:, 0], axis=0), np.take(f.p_px, e[:, 1], axis=0), WIDTH, HEIGHT
        )
        prep.append((rr, cc, count, pc[e[:, 0], 2], pc[e[:, 1], 2]))
    depth_ok = all(len(p[0]) == int(p[2].sum()) for p in prep)
    if depth_ok:
        # the z-buffered image equals the plain one for a wireframe (lines never hide lines)
        same = all(
            np.array_equal(depth_stage(*p, HEIGHT, WIDTH), plain_paint(p[0], p[1], HEIGHT, WIDTH)) for p in prep[:1]
        )
        t_depth = bench_group(
            {
                "frame_fast": lambda i: render_frame(pts_p, e, camera, mats[i], raster="fast"),
                "plain_paint": lambda i: plain_paint(prep[i][0], prep[i][1], HEIGHT, WIDTH),
                "zbuffer_paint": lambda i: depth_stage(*prep[i], HEIGHT, WIDTH),
            },
            **bg,
        )
        extra = t_depth["zbuffer_paint"]["median_ms"] - t_depth["plain_paint"]["median_ms"]
        details["depth_buffer"] = {
            "timings": t_depth,
            "extra_ms": extra,
            "pixels_pose0": int(len(prep[0][0])),
            "zbuffer_image_equals_plain": same,
        }
        rows.append(
            {
                "stage": "depth buffer (z-test line pixels)",
                "skipped_ms": extra,
                "run_ms": t_depth["frame_fast"]["median_ms"],
                "note": f"raster fast; z-buffered paint {ms(t_depth['zbuffer_paint']['median_ms'])} ms vs plain "
                f"paint {ms(t_depth['plain_paint']['median_ms'])} ms, {len(prep[0][0]):,} px; "
                f"same image: {same}",
            }
        )
    else:
        details["depth_buffer"] = {"skipped": "line_pixels_fast dropped pixels: per-pixel segment ids unknown"}
        print("  depth buffer row skipped: the fast raster's pixel count does not match its segments")
    frames = prep = None  # free them (the lambdas above are done)

    # ---- 3. clipping: only the edges with an end outside, vs every edge through the clip stage
    # render_frame clips only edges with an end out of [near, far] or off the image: on this mesh
    # (always on the image) that is none. The skipped cost is the clip stage on every edge, as a
    # pipeline that clips everything would run it: 6 planes (Liang-Barsky), the clamp, the divide
    # and the 2-D image guard, from camera-space points computed outside the timing.
    planes = clipping.frustum_planes(camera)
    p_cams = [model_to_cam(pts_p, mats[i], camera) for i in range(n_poses)]

    def clip_all(i):
        seg_cam = p_cams[i][e]
        kept, t0, t1 = clipping.clip_segments(seg_cam, planes)
        seg_cam = clipping.apply_clip(seg_cam, kept, t0, t1, (camera.near, camera.far))
        seg_px = cam_to_px(seg_cam.reshape(-1, 3), camera).reshape(-1, 2, 2)
        return clipping.clip_to_image(seg_px[:, 0], seg_px[:, 1], WIDTH, HEIGHT)

    on_image = all(bool(clip_all(i)[0].all()) for i in range(n_poses))
    t_clip = bench_group(
        {
            "render_frame": lambda i: render_frame(pts_p, e, camera, mats[i]),
            "clip_every_edge": clip_all,
        },
        **bg,
    )
    p_cams = None
    details["clipping"] = {"timings": t_clip, "every_edge_kept_whole_all_poses": on_image}
    rows.append(
        {
            "stage": "clipping every edge (6 planes + image)",
            "skipped_ms": t_clip["clip_every_edge"]["median_ms"],
            "run_ms": t_clip["render_frame"]["median_ms"],
            "note": f"clip stage on all {len(e):,} edges {ms(t_clip['clip_every_edge']['median_ms'])} ms, "
            f"whole frame {ms(t_clip['render_frame']['median_ms'])} ms; every edge inside (nothing to "
            f"clip) in every pose: {on_image}",
        }
    )
    print(f"  core rows done ({time.perf_counter() - t_start:.1f} s)", flush=True)

    # ---- 4. pyrender
    pyr = None
    try:
        from wirecheck.oracles.references.pyrender_oracle import PyrenderOracle, osmesa_available

        ok, msg = osmesa_available()
    except Exception as exc:  # noqa: BLE001
        ok, msg = False, f"{type(exc).__name__}: {exc}"
    if ok:
        pyr = PyrenderScenes(v, e, faces, camera)
        masks = {name: pyr.render(name, mats[0])[0] for name in ("flat", "lit", "faces")}
        t_pyr = bench_group(
            {name: (lambda i, name=name: pyr.render(name, mats[i])) for name in ("flat", "lit", "faces")},
            n_poses=n_poses,
            budget_s=cfg["budget_s"],
            rounds=cfg["rounds"],
            max_passes=cfg["max_passes"],
        )
        pyr.close()
        with PyrenderOracle(WIDTH, HEIGHT) as oracle:
            m_or, _ = oracle.render(v, e, camera, mats[0])
            t_or = bench_group(
                {"oracle_flat": lambda i: oracle.render(v, e, camera, mats[i])},
                n_poses=n_poses,
                budget_s=cfg["budget_s"],
                rounds=cfg["rounds"],
                max_passes=cfg["max_passes"],
            )
        flat = t_pyr["flat"]["median_ms"]
        details["pyrender"] = {
            "timings": {**t_pyr, **t_or},
            "pixels_pose0": {k: int(m.sum()) for k, m in masks.items()},
            "flat_equals_oracle_pose0": bool(np.array_equal(masks["flat"], m_or)),
        }
        rows.append(
            {
                "stage": "pyrender: light + lit shader",
                "skipped_ms": t_pyr["lit"]["median_ms"] - flat,
                "run_ms": flat,
                "note": f"DirectionalLight, default flags {ms(t_pyr['lit']['median_ms'])} ms vs FLAT "
                f"{ms(flat)} ms (oracle class {ms(t_or['oracle_flat']['median_ms'])} ms; "
                f"same pixels as the oracle: {details['pyrender']['flat_equals_oracle_pose0']})",
            }
        )
        rows.append(
            {
                "stage": "pyrender: faces as occluders",
                "skipped_ms": t_pyr["faces"]["median_ms"] - flat,
                "run_ms": flat,
                "note": f"{len(faces):,} black triangles, FLAT {ms(t_pyr['faces']['median_ms'])} ms; line "
                f"pixels {masks['flat'].sum():,} -> {masks['faces'].sum():,} (hidden lines removed)",
            }
        )
    else:
        details["pyrender"] = {"skipped": msg}
        print(f"  pyrender rows skipped: {msg}")
    print(f"  pyrender rows done ({time.perf_counter() - t_start:.1f} s)", flush=True)

    # ---- 5. scene loading
    big = trimesh.creation.icosphere(subdivisions=cfg["load_subdiv"])
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / f"ico{cfg['load_subdiv']}.ply"
        big.export(path)
        size_mib = path.stat().st_size / 2**20
        t_load = {"process_true": [], "process_false": [], "core_load_scene": []}
        for r in range(cfg["load_repeats"]):
            order = ["process_false", "process_true", "core_load_scene"]
            for name in order if r % 2 == 0 else order[::-1]:
                t0 = time.perf_counter()
                if name == "core_load_scene":
                    sc = load_scene(str(path))
                else:
                    loaded = trimesh.load(str(path), process=(name == "process_true"), maintain_order=True)
                t_load[name].append(time.perf_counter() - t0)
        n_loaded = (len(loaded.vertices), len(loaded.faces))
    load_med = {k: float(np.median(x)) * 1e3 for k, x in t_load.items()}
    details["loading"] = {
        "file": f"icosphere({cfg['load_subdiv']}) binary PLY",
        "file_mib": size_mib,
        "vertices": len(big.vertices),
        "faces": len(big.faces),
        "median_ms": load_med,
        "all_ms": {k: [t * 1e3 for t in x] for k, x in t_load.items()},
        "core_scene_edges": int(len(sc.edges)),
        "loaded_last": list(map(int, n_loaded)),
        "core_uses": "process=False, maintain_order=True",
    }
    rows.append(
        {
            "stage": "load: trimesh process=True",
            "skipped_ms": load_med["process_true"] - load_med["process_false"],
            "run_ms": load_med["process_false"],
            "per": "load",
            "note": f"{len(big.vertices):,} V PLY ({size_mib:.1f} MiB), once per run; core uses process=False; "
            f"core.scene.files.load_scene total {ms(load_med['core_load_scene'])} ms",
        }
    )

    # ---- table
    print()
    hdr = f"{'stage':<36} {'skipped cost ms':>15} {'run cost ms':>12} {'saving':>7}"
    lines = []
    for r in rows:
        r["saving"] = r["skipped_ms"] / (r["run_ms"] + r["skipped_ms"]) if r["run_ms"] + r["skipped_ms"] > 0 else 0.0
        per = " (per load)" if r.get("per") == "load" else ""
        lines.append(f"{r['stage']:<36} {ms(r['skipped_ms']):>15} {ms(r['run_ms']):>12} {r['saving']:>7.1%}{per}")
    print_table(
        "skipped cost = what the stage would add; run cost = what runs now; saving = skipped / (run + skipped)",
        hdr,
        lines,
    )
    for r in rows:
        print(f"  {r['stage']}: {r['note']}")
    elapsed = print_end(info, t_start)

    if args.json:
        config = {
            "width": WIDTH,
            "height": HEIGHT,
            "camera": "camera_z(4.0, fov_y_deg=70)",
            "mesh": "icosphere(6)",
            "quick": args.quick,
            **cfg,
        }
        write_json(args.json, machine=info, config=config, rows=rows, details=details, elapsed_s=elapsed)
    return 0


if __name__ == "__main__":
    sys.exit(main())
