#!/usr/bin/env python
"""Per-frame projection + raster time of wirecheck against OpenCV.

Run from the repo root::

    .venv/bin/python benchmarks/bench_frame.py [--quick] [--json PATH]

Cases (both: camera ``camera_z(4.0, fov_y_deg=70)``, 640x480, ``Motion()``,
180 frames, frame k at t = (k - 1) / 180):

* ``cube``       the built-in scene ``core.scene_files.load_scene('cube')``
* ``icosphere``  ``trimesh.creation.icosphere(subdivisions=6)``: 40,962
  vertices, 122,880 unique edges (``core.scene.unique_edges(face_edges(...))``)

Implementations, each timed per frame from model-space vertices to a finished
(H, W) uint8 image:

* ``ours``    ``core.pipeline.render_frame(p_model, edges, camera, M)``
* ``opencv``  ``p_world = p_model @ M[:3, :3].T + M[:3, 3]`` (numpy),
  ``cv2.projectPoints`` (R rows = [right, -up, forward], t = -R @ position,
  K from ``camera.focal_px`` / ``camera.principal_point``), rounding to int32,
  gathering the (E, 2, 2) segment array, ``np.zeros`` image, then
  ``cv2.polylines(img, segs, isClosed=False, color=255, thickness=1,
  lineType=cv2.LINE_8)``.

Fairness: the model transform and the image allocation are inside the timed
region for BOTH (``render_frame`` does both itself). The 180 model matrices,
the camera's rvec/tvec/K and the edge array are built once, outside. The
garbage collector is disabled while timing (as ``timeit`` does). Repeats of
the 180-frame loop alternate which implementation runs first.

Statistics: for each repeat, the median and the 90th percentile of the 180
per-frame times; reported are the medians of those over the repeats (and the
best repeat's median as ``min``). Targets use the medians.
"""

from __future__ import annotations

import argparse
import gc
import sys
import time
import tracemalloc

import cv2
import numpy as np
import trimesh

from _common import machine_info, print_machine, print_table, verdict, write_json
from wirecheck.core.camera import camera_z
from wirecheck.core.pipeline import render_frame
from wirecheck.core.projection import project_points
from wirecheck.core.scene import face_edges, unique_edges
from wirecheck.core.scene_files import load_scene
from wirecheck.core.transforms import Motion

FRAMES = 180
WIDTH, HEIGHT = 640, 480
CUBE_TARGET_MS = 1.0          # ours, cube frame (median) <= 1 ms
ICO_TARGET_RATIO = 2.0        # ours, icosphere frame (median) <= 2 x OpenCV's


# ---------------------------------------------------------------- the scenes
def make_camera():
    return camera_z(4.0, fov_y_deg=70, width=WIDTH, height=HEIGHT)


def load_cases() -> dict[str, tuple[np.ndarray, np.ndarray]]:
    cube = load_scene("cube")
    ico = trimesh.creation.icosphere(subdivisions=6)
    ico_v = np.ascontiguousarray(ico.vertices, dtype=np.float64)
    ico_e = unique_edges(face_edges(np.asarray(ico.faces).tolist()))
    assert len(ico_e) == len(ico.edges_unique), "unique edges disagree with trimesh"
    return {
        "cube": (np.ascontiguousarray(cube.vertices, dtype=np.float64), np.asarray(cube.edges, dtype=np.intp)),
        "icosphere": (ico_v, ico_e),
    }


# ---------------------------------------------------------------- OpenCV path
def opencv_camera(camera):
    """rvec, tvec, K of ``camera`` in OpenCV's convention (y down)."""
    r = np.stack([camera.right, -camera.up, camera.forward])
    tvec = -r @ camera.position
    rvec, _ = cv2.Rodrigues(r)
    f = camera.focal_px
    cx, cy = camera.principal_point
    k = np.array([[f, 0.0, cx], [0.0, f, cy], [0.0, 0.0, 1.0]])
    return rvec, tvec, k


def opencv_frame(p_model, edges, model_matrix, rvec, tvec, k, height, width):
    """The same work as ``render_frame`` with OpenCV: a (H, W) uint8 image."""
    p_world = p_model @ model_matrix[:3, :3].T + model_matrix[:3, 3]
    img_pts, _jac = cv2.projectPoints(p_world, rvec, tvec, k, None)
    pts = np.rint(img_pts.reshape(-1, 2)).astype(np.int32)
    image = np.zeros((height, width), dtype=np.uint8)
    cv2.polylines(image, pts[edges], False, 255, 1, cv2.LINE_8)
    return image


# ---------------------------------------------------------------- timing
def time_loop(fn, matrices) -> np.ndarray:
    """Per-frame wall time (s) of ``fn(M)`` over ``matrices``; GC off."""
    out = np.empty(len(matrices))
    perf = time.perf_counter
    gc_was_on = gc.isenabled()
    gc.disable()
    try:
        for i, m in enumerate(matrices):
            t0 = perf()
            fn(m)
            out[i] = perf() - t0
    finally:
        if gc_was_on:
            gc.enable()
    return out


def summarise(loops: list[np.ndarray]) -> dict:
    meds = [float(np.median(x)) * 1e3 for x in loops]
    p90s = [float(np.percentile(x, 90)) * 1e3 for x in loops]
    return {
        "median_ms": float(np.median(meds)),
        "p90_ms": float(np.median(p90s)),
        "min_median_ms": float(min(meds)),
        "mean_ms": float(np.mean([x.mean() for x in loops])) * 1e3,
        "repeat_median_ms": meds,
        "repeat_p90_ms": p90s,
        "frames": int(len(loops[0])),
        "repeats": len(loops),
    }


def bench_case(p_model, edges, camera, matrices, repeats, warmup):
    rvec, tvec, k = opencv_camera(camera)
    impls = {
        "ours": lambda m: render_frame(p_model, edges, camera, m),
        "opencv": lambda m: opencv_frame(p_model, edges, m, rvec, tvec, k, camera.height, camera.width),
    }
    for fn in impls.values():                       # warm-up (caches, allocator, lazy imports)
        time_loop(fn, matrices[:warmup])
    loops = {name: [] for name in impls}
    order = list(impls)
    for r in range(repeats):
        for name in (order if r % 2 == 0 else order[::-1]):
            loops[name].append(time_loop(impls[name], matrices))
    return {name: summarise(v) for name, v in loops.items()}


# ---------------------------------------------------------------- checks
def sanity(p_model, edges, camera, matrices, frames_idx):
    """Outside timing: does ours take the no-clip fast path (every vertex within
    [near, far] and on the image), and do the two implementations draw nearly
    the same pixels? OpenCV rounds the end points, then runs Bresenham; ours
    steps the exact segment, so lines may differ by one pixel sideways: the
    IoU is low for long lines, "within 1 px" is the meaningful agreement."""
    rvec, tvec, k = opencv_camera(camera)
    clip_frames = 0
    inter = union = near_a = near_b = n_a = n_b = 0
    kernel = np.ones((3, 3), np.uint8)
    for i, m in enumerate(matrices):
        p_px = project_points(p_model @ m[:3, :3].T + m[:3, 3], camera)
        x, y = p_px[:, 0], p_px[:, 1]      # NaN (clipped) compares False: counted as off
        on = (x >= -0.5) & (x <= camera.width - 0.5) & (y >= -0.5) & (y <= camera.height - 0.5)
        clip_frames += not on.all()
        if i in frames_idx:
            a = render_frame(p_model, edges, camera, m).image > 0
            b = opencv_frame(p_model, edges, m, rvec, tvec, k, camera.height, camera.width) > 0
            inter += int((a & b).sum())
            union += int((a | b).sum())
            near_a += int((a & (cv2.dilate(b.view(np.uint8), kernel) > 0)).sum())
            near_b += int((b & (cv2.dilate(a.view(np.uint8), kernel) > 0)).sum())
            n_a += int(a.sum())
            n_b += int(b.sum())
    return {"frames_through_clipping": clip_frames,
            "pixel_iou_vs_opencv": inter / union if union else 1.0,
            "ours_within_1px_of_opencv": near_a / n_a if n_a else 1.0,
            "opencv_within_1px_of_ours": near_b / n_b if n_b else 1.0,
            "pixel_check_frames": len(frames_idx)}


def peak_memory(p_model, edges, camera, matrix) -> dict:
    """tracemalloc peak of one frame of ours (numpy reports its buffers)."""
    render_frame(p_model, edges, camera, matrix)
    tracemalloc.start()
    try:
        base = tracemalloc.get_traced_memory()[0]
        tracemalloc.reset_peak()
        frame = render_frame(p_model, edges, camera, matrix)
        current, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    del frame
    return {"peak_extra_bytes": int(peak - base), "result_bytes": int(current - base),
            "input_bytes": int(p_model.nbytes + edges.nbytes)}


# ---------------------------------------------------------------- report
def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true",
                    help="fewer repeats (cube 2, icosphere 1) and a shorter warm-up")
    ap.add_argument("--repeats", type=int, default=None,
                    help="repeats of the 180-frame loop for every case (default: cube 5, icosphere 2)")
    ap.add_argument("--json", metavar="PATH", help="also write the results as JSON to PATH")
    args = ap.parse_args(argv)

    t_start = time.perf_counter()
    if args.repeats is not None:
        repeats = {"cube": args.repeats, "icosphere": args.repeats}
    elif args.quick:
        repeats = {"cube": 2, "icosphere": 1}
    else:
        repeats = {"cube": 5, "icosphere": 2}
    warmup = {"cube": 30 if args.quick else 180, "icosphere": 3 if args.quick else 8}

    camera = make_camera()
    motion = Motion()
    matrices = [motion.frame_matrix(k, FRAMES) for k in range(1, FRAMES + 1)]
    cases = load_cases()
    info = machine_info()

    print_machine("wirecheck frame benchmark", info)
    print(f"  camera_z(4.0, fov_y_deg=70) {WIDTH}x{HEIGHT}, Motion() = {motion.turns} turns, {FRAMES} frames")
    print("  timed per frame: model transform + projection + raster + image, both implementations")
    print()

    results = {}
    for name, (p_model, edges) in cases.items():
        res = bench_case(p_model, edges, camera, matrices, repeats[name], warmup[name])
        res["ratio_median"] = res["ours"]["median_ms"] / res["opencv"]["median_ms"]
        res["ratio_p90"] = res["ours"]["p90_ms"] / res["opencv"]["p90_ms"]
        res["vertices"], res["edges"] = int(len(p_model)), int(len(edges))
        check_idx = set(range(FRAMES)) if name == "cube" else {0, 45, 90, 135}
        res["checks"] = sanity(p_model, edges, camera, matrices, check_idx)
        results[name] = res

    memory = peak_memory(*cases["icosphere"], camera, matrices[0])

    hdr = (f"{'case':<10} {'V':>6} {'E':>7}  {'impl':<7} {'median ms':>10} {'p90 ms':>9} "
           f"{'min ms':>9} {'mean ms':>9}  {'reps':>4}")
    rows = []
    for name, res in results.items():
        for impl in ("ours", "opencv"):
            s = res[impl]
            rows.append(f"{name:<10} {res['vertices']:>6} {res['edges']:>7}  {impl:<7} {s['median_ms']:>10.3f} "
                        f"{s['p90_ms']:>9.3f} {s['min_median_ms']:>9.3f} {s['mean_ms']:>9.3f}  "
                        f"{s['repeats']:>4}")
        rows.append(f"{'':<10} {'':>6} {'':>7}  {'ours/cv':<7} {res['ratio_median']:>10.2f} "
                    f"{res['ratio_p90']:>9.2f}")
    print_table(None, hdr, rows)
    for name, res in results.items():
        c = res["checks"]
        print(f"check {name}: frames through the clipping path {c['frames_through_clipping']}/{FRAMES}; "
              f"pixels vs OpenCV over {c['pixel_check_frames']} frames: IoU {c['pixel_iou_vs_opencv']:.3f}, "
              f"within 1 px {c['ours_within_1px_of_opencv']:.4f} (ours) / {c['opencv_within_1px_of_ours']:.4f} (cv)")
    print(f"memory: one icosphere frame of ours, tracemalloc peak extra "
          f"{memory['peak_extra_bytes'] / 2**20:.1f} MiB (result kept {memory['result_bytes'] / 2**20:.1f} MiB; "
          f"inputs {memory['input_bytes'] / 2**20:.1f} MiB)")
    print()

    cube_ms = results["cube"]["ours"]["median_ms"]
    ico_ms = results["icosphere"]["ours"]["median_ms"]
    ico_cv = results["icosphere"]["opencv"]["median_ms"]
    targets = [
        {"name": "cube frame <= 1 ms", "value_ms": cube_ms, "limit_ms": CUBE_TARGET_MS,
         "pass": cube_ms <= CUBE_TARGET_MS},
        {"name": "icosphere frame <= 2x OpenCV", "value_ms": ico_ms, "limit_ms": ICO_TARGET_RATIO * ico_cv,
         "pass": ico_ms <= ICO_TARGET_RATIO * ico_cv},
    ]
    print("targets (ours, median per frame):")
    print(f"  cube frame <= {CUBE_TARGET_MS:g} ms                 {cube_ms:8.3f} ms  "
          f"{verdict(targets[0]['pass'], 'MISS')}")
    print(f"  icosphere frame <= {ICO_TARGET_RATIO:g}x OpenCV ({ICO_TARGET_RATIO * ico_cv:.1f} ms)  "
          f"{ico_ms:8.3f} ms  {verdict(targets[1]['pass'], 'MISS')}  (ratio {ico_ms / ico_cv:.2f})")
    elapsed = time.perf_counter() - t_start
    print(f"\ntotal benchmark time {elapsed:.1f} s")

    if args.json:
        config = {"frames": FRAMES, "width": WIDTH, "height": HEIGHT, "camera": "camera_z(4.0, fov_y_deg=70)",
                  "motion_turns": list(motion.turns), "repeats": repeats, "warmup_frames": warmup,
                  "quick": args.quick, "timed_region": "model transform + projection + raster + image, both",
                  "statistic": "median over repeats of per-repeat median / p90 of per-frame times"}
        write_json(args.json, machine=info, config=config, results=results, memory=memory, targets=targets,
                   elapsed_s=elapsed)
    return 0


if __name__ == "__main__":
    sys.exit(main())
