#!/usr/bin/env python
"""Per-frame time of wirecheck's "exact" frame against pyrender (Mesa llvmpipe) and OpenCV.

Run from the repo root::

    .venv/bin/python benchmarks/bench_frame.py [--quick] [--json PATH]

Cases (both: camera ``camera_z(4.0, fov_y_deg=70)``, 640x480, ``Motion()``,
180 frames, frame k at t = (k - 1) / 180; ``--quick`` times every 3rd frame
of the icosphere):

* ``cube``       the built-in scene ``core.scene.files.load_scene('cube')``
* ``icosphere``  ``trimesh.creation.icosphere(subdivisions=6)``: 40,962
  vertices, 122,880 unique edges (``core.scene.model.unique_edges(face_edges(...))``)

A *frame* is the same work on every side: this frame's model matrix and the
scene's model-space vertices in, a finished image in host memory out (model
transform, projection, line drawing, image). What is per scene, not per frame,
is built once outside the timing on every side: our ``LocalPoints``
(``localize``) and edge array; OpenCV's rvec/tvec/K and edge array; pyrender's
scene, whose vertex and index buffers go to the GL driver once (at the warm-up
render), as a viewer would keep them.

* ``ours``      ``core.projector.pipeline.render_frame(LocalPoints, edges, camera, M)``,
  raster "exact" (GL's diamond-exit rule): model -> camera -> pixels, the
  clip test, the line pixels, painting into a new ``(H, W) uint8`` image.
* ``pyrender``  ``scene.set_pose(mesh_node, M)`` and
  ``OffscreenRenderer.render(scene, RenderFlags.FLAT)`` on OSMesa (llvmpipe,
  CPU): the draw of one ``GL_LINES`` primitive and the read-back, which
  pyrender always does for colour (``(H, W, 3) uint8``) and depth. That
  depth read-back is pyrender's cost, not ours: its API has no colour-only
  render.
* ``opencv``    ``p_world = p_model @ M[:3, :3].T + M[:3, 3]`` (numpy),
  ``cv2.projectPoints`` (R rows = [right, -up, forward], t = -R @ position,
  K from ``camera.focal_px`` / ``camera.principal_point``), rounding to int32,
  gathering the (E, 2, 2) segment array, ``np.zeros`` image, then
  ``cv2.polylines(img, segs, isClosed=False, color=255, thickness=1,
  lineType=cv2.LINE_8)``.

And the drawing alone, icosphere, from the same projected pixel coordinates
(ours, computed outside the timing) to a new ``(H, W) uint8`` image:

* ``ours``       ``np.take`` of the edge ends, ``raster.line_pixels`` and the
  paint, as ``render_frame`` does them;
* ``cv2 L8``     ``cv2.polylines`` LINE_8 on the ends rounded to int32 pixels;
* ``cv2 L8 s8``  the same with ``shift=8`` on ends in 1/256 px (our
  sub-pixel grid): OpenCV's closest equivalent of an exact rule.
  The (E, 2, 2) int32 arrays are built outside the timing.

The garbage collector is disabled while timing (as ``timeit`` does). Repeats
of the frame loop rotate which implementation runs first.

Statistics: for each repeat, the median and the 90th percentile of the
per-frame times; reported are the medians of those over the repeats (and the
best repeat's median as ``min``). Ratios and targets use the medians.
"""

from __future__ import annotations

import argparse
import gc
import os
import sys
import time
import tracemalloc

import cv2
import numpy as np
import trimesh
from _common import machine_info, print_machine, print_table, verdict, write_json
from wirecheck.core.camera import camera_z
from wirecheck.core.projector import raster
from wirecheck.core.projector.pipeline import render_frame
from wirecheck.core.projector.projection import localize, project_points
from wirecheck.core.scene.files import load_scene
from wirecheck.core.scene.model import face_edges, unique_edges
from wirecheck.core.transforms import Motion

FRAMES = 180
WIDTH, HEIGHT = 640, 480
CUBE_TARGET_MS = 1.0  # ours, cube frame (median) <= 1 ms
ICO_TARGET_RATIO = 1.0  # ours, icosphere frame and drawing (median) <= 1 x pyrender's / OpenCV's


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


# ---------------------------------------------------------------- pyrender path
class PyrenderFrame:
    """pyrender on OSMesa: one scene with the mesh as one GL_LINES primitive, white, unlit."""

    def __init__(self, p_model, edges, camera):
        os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa")
        import pyrender
        from wirecheck.oracles.references.convert import camera_to_pyrender

        self._pr = pyrender
        self.renderer = pyrender.OffscreenRenderer(camera.width, camera.height)
        self.scene = pyrender.Scene(bg_color=[0.0, 0.0, 0.0, 1.0], ambient_light=[0.0, 0.0, 0.0])
        white = pyrender.MetallicRoughnessMaterial(baseColorFactor=[1.0, 1.0, 1.0, 1.0])
        prim = pyrender.Primitive(
            positions=p_model.astype(np.float32),
            indices=edges.astype(np.uint32),
            mode=pyrender.constants.GLTF.LINES,
            material=white,
        )
        self.node = self.scene.add(pyrender.Mesh([prim]))
        pose, cam = camera_to_pyrender(camera)
        self.scene.add(cam, pose=pose)

    def __call__(self, model_matrix):
        """The (H, W, 3) uint8 colour image of one frame (pyrender also reads the depth back)."""
        self.scene.set_pose(self.node, model_matrix)
        colour, _depth = self.renderer.render(self.scene, self._pr.RenderFlags.FLAT)
        return colour

    def close(self):
        self.renderer.delete()


def pyrender_unavailable() -> str | None:
    """Why pyrender cannot render here (None when it can)."""
    os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa")
    from wirecheck.oracles.references.pyrender_oracle import osmesa_available

    ok, why = osmesa_available()
    return None if ok else why


# ---------------------------------------------------------------- drawing alone
def ours_draw(p_px, edges, width, height):
    """render_frame's drawing of ``edges`` from vertex pixels: gather, exact line pixels, paint."""
    image = np.zeros((height, width), dtype=np.uint8)
    rr, cc = raster.line_pixels(np.take(p_px, edges[:, 0], axis=0), np.take(p_px, edges[:, 1], axis=0), width, height)
    image.reshape(-1)[rr * width + cc] = 255
    return image


def cv_draw(segs, width, height, shift=0):
    image = np.zeros((height, width), dtype=np.uint8)
    cv2.polylines(image, segs, False, 255, 1, cv2.LINE_8, shift)
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


def rotated(names: list[str], r: int) -> list[str]:
    """``names`` rotated by ``r``: each implementation runs first in turn."""
    k = r % len(names)
    return names[k:] + names[:k]


def time_impls(impls: dict, items, repeats: int, warmup: int) -> dict:
    """Per-frame times of each ``impls[name](item)`` over ``items``, ``repeats`` times, order rotated."""
    for fn in impls.values():  # warm-up (caches, allocator, lazy imports, GL buffers)
        time_loop(fn, items[:warmup])
    loops = {name: [] for name in impls}
    for r in range(repeats):
        for name in rotated(list(impls), r):
            loops[name].append(time_loop(impls[name], items))
    return {name: summarise(v) for name, v in loops.items()}


def bench_case(p_model, edges, camera, matrices, repeats, warmup, with_pyrender):
    rvec, tvec, k = opencv_camera(camera)
    points = localize(p_model, "float64")
    impls = {
        "ours": lambda m: render_frame(points, edges, camera, m),
        "opencv": lambda m: opencv_frame(p_model, edges, m, rvec, tvec, k, camera.height, camera.width),
    }
    pr = PyrenderFrame(p_model, edges, camera) if with_pyrender else None
    if pr is not None:
        impls["pyrender"] = pr
    try:
        return time_impls(impls, matrices, repeats, warmup)
    finally:
        if pr is not None:
            pr.close()


def bench_drawing(p_model, edges, camera, matrices, repeats, warmup):
    """The drawing alone (ours vs cv2.polylines) from the same pixel coordinates, one set per pose."""
    w, h = camera.width, camera.height
    px = [render_frame(p_model, edges, camera, m).p_px for m in matrices]
    segs = [np.rint(p).astype(np.int32)[edges] for p in px]
    segs8 = [np.rint(p * raster.SUBPIXEL).astype(np.int32)[edges] for p in px]
    idx = list(range(len(px)))
    impls = {
        "ours": lambda i: ours_draw(px[i], edges, w, h),
        "cv2_LINE_8": lambda i: cv_draw(segs[i], w, h),
        "cv2_LINE_8_shift8": lambda i: cv_draw(segs8[i], w, h, 8),
    }
    res = time_impls(impls, idx, repeats, warmup)
    a = ours_draw(px[0], edges, w, h) > 0
    same = render_frame(p_model, edges, camera, matrices[0]).image > 0
    res["same_pixels_as_render_frame"] = bool(np.array_equal(a, same))
    return res


# ---------------------------------------------------------------- checks
def sanity(p_model, edges, camera, matrices, frames_idx, with_pyrender):
    """Outside timing: does ours take the no-clip fast path (every vertex within
    [near, far] and on the image), and how close are the pictures? OpenCV
    rounds the end points, then runs Bresenham; ours steps the exact segment,
    so lines may differ by one pixel sideways: the IoU is low for long lines,
    "within 1 px" is the meaningful agreement. Against pyrender (whose rule
    ours emulates) the pixels should be the same: IoU at 0 px."""
    rvec, tvec, k = opencv_camera(camera)
    pr = PyrenderFrame(p_model, edges, camera) if with_pyrender else None
    clip_frames = 0
    inter = union = near_a = near_b = n_a = n_b = 0
    pr_inter = pr_union = 0
    kernel = np.ones((3, 3), np.uint8)
    try:
        for i, m in enumerate(matrices):
            p_px = project_points(p_model @ m[:3, :3].T + m[:3, 3], camera)
            x, y = p_px[:, 0], p_px[:, 1]  # NaN (clipped) compares False: counted as off
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
                if pr is not None:
                    c = pr(m)[:, :, 0] > 127
                    pr_inter += int((a & c).sum())
                    pr_union += int((a | c).sum())
    finally:
        if pr is not None:
            pr.close()
    out = {
        "frames_through_clipping": clip_frames,
        "pixel_iou_vs_opencv": inter / union if union else None,
        "ours_within_1px_of_opencv": near_a / n_a if n_a else None,
        "opencv_within_1px_of_ours": near_b / n_b if n_b else None,
        "pixel_check_frames": len(frames_idx),
        "ours_pixels": n_a,
    }
    if pr is not None:
        out["pixel_iou_vs_pyrender"] = pr_inter / pr_union if pr_union else None
    return out


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
    return {
        "peak_extra_bytes": int(peak - base),
        "result_bytes": int(current - base),
        "input_bytes": int(p_model.nbytes + edges.nbytes),
    }


# ---------------------------------------------------------------- report
def fmt_ratio(x, digits: int = 2) -> str:
    return "-" if x is None else f"{x:.{digits}f}"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument(
        "--quick",
        action="store_true",
        help="fewer repeats (cube 2, icosphere 1), every 3rd icosphere frame, a shorter warm-up",
    )
    ap.add_argument(
        "--repeats",
        type=int,
        default=None,
        help="repeats of the frame loop for every case (default: cube 5, icosphere 3)",
    )
    ap.add_argument("--json", metavar="PATH", help="also write the results as JSON to PATH")
    args = ap.parse_args(argv)
    if args.repeats is not None and args.repeats < 1:
        ap.error(f"--repeats {args.repeats}: expected an integer >= 1")

    t_start = time.perf_counter()
    if args.repeats is not None:
        repeats = {"cube": args.repeats, "icosphere": args.repeats}
    elif args.quick:
        repeats = {"cube": 2, "icosphere": 1}
    else:
        repeats = {"cube": 5, "icosphere": 3}
    warmup = {"cube": 30 if args.quick else 180, "icosphere": 3 if args.quick else 8}
    stride = {"cube": 1, "icosphere": 3 if args.quick else 1}

    unavailable = pyrender_unavailable()
    if unavailable is not None:
        # the targets are ratios to pyrender: without it there is nothing to compare
        print(f"bench_frame: pyrender cannot render here ({unavailable})", file=sys.stderr)
        return 2

    camera = make_camera()
    motion = Motion()
    matrices = [motion.frame_matrix(k, FRAMES) for k in range(1, FRAMES + 1)]
    cases = load_cases()
    info = machine_info()

    print_machine("wirecheck frame benchmark", info)
    print(
        f"  camera_z(4.0, fov_y_deg=70) {WIDTH}x{HEIGHT}, Motion() = {motion.turns} turns, {FRAMES} frames"
        f"{' (icosphere: every 3rd)' if stride['icosphere'] > 1 else ''}"
    )
    print("  a frame, every side: model-space vertices + this frame's model matrix in, finished image in host")
    print("  memory out (transform, projection, lines, image); per-scene set-up outside the timing (ours:")
    print("  LocalPoints, edges; OpenCV: rvec/tvec/K, edges; pyrender: the scene, its GL buffers uploaded once)")
    print("  ours = render_frame raster 'exact'; pyrender = set_pose + render(FLAT) on OSMesa llvmpipe (reads")
    print("  colour and depth back); opencv = numpy transform + projectPoints + rint + gather + polylines LINE_8")
    print()

    results = {}
    for name, (p_model, edges) in cases.items():
        mats = matrices[:: stride[name]]
        res = bench_case(p_model, edges, camera, mats, repeats[name], warmup[name], with_pyrender=True)
        res["frames_timed"] = len(mats)
        res["ratio_vs_opencv"] = res["ours"]["median_ms"] / res["opencv"]["median_ms"]
        res["ratio_vs_pyrender"] = res["ours"]["median_ms"] / res["pyrender"]["median_ms"]
        res["vertices"], res["edges"] = int(len(p_model)), int(len(edges))
        check_idx = set(range(FRAMES)) if name == "cube" else {0, 45, 90, 135}
        res["checks"] = sanity(p_model, edges, camera, matrices, check_idx, with_pyrender=True)
        results[name] = res
    ico_v, ico_e = cases["icosphere"]
    drawing = bench_drawing(
        ico_v, ico_e, camera, matrices[:: stride["icosphere"]], repeats["icosphere"], warmup["icosphere"]
    )
    drawing["ratio_vs_cv2_LINE_8"] = drawing["ours"]["median_ms"] / drawing["cv2_LINE_8"]["median_ms"]
    drawing["ratio_vs_cv2_LINE_8_shift8"] = drawing["ours"]["median_ms"] / drawing["cv2_LINE_8_shift8"]["median_ms"]

    memory = peak_memory(*cases["icosphere"], camera, matrices[0])

    hdr = (
        f"{'case':<10} {'V':>6} {'E':>7}  {'impl':<9} {'median ms':>10} {'p90 ms':>9} "
        f"{'min ms':>9} {'mean ms':>9}  {'frames x reps':>13}"
    )
    rows = []
    for name, res in results.items():
        for impl in ("ours", "pyrender", "opencv"):
            st = res[impl]
            rows.append(
                f"{name:<10} {res['vertices']:>6} {res['edges']:>7}  {impl:<9} {st['median_ms']:>10.3f} "
                f"{st['p90_ms']:>9.3f} {st['min_median_ms']:>9.3f} {st['mean_ms']:>9.3f}  "
                f"{st['frames']:>6} x {st['repeats']:<4}"
            )
        rows.append(f"{'':<10} {'':>6} {'':>7}  {'ours/pr':<9} {res['ratio_vs_pyrender']:>10.2f}")
        rows.append(f"{'':<10} {'':>6} {'':>7}  {'ours/cv':<9} {res['ratio_vs_opencv']:>10.2f}")
    print_table("whole frame, median ms per frame", hdr, rows)

    hdr = f"{'drawing alone, icosphere':<32} {'median ms':>10} {'p90 ms':>9} {'min ms':>9}  {'ours/this':>9}"
    rows = []
    for impl, label in (
        ("ours", "ours exact (take+raster+paint)"),
        ("cv2_LINE_8", "cv2.polylines LINE_8"),
        ("cv2_LINE_8_shift8", "cv2.polylines LINE_8 shift=8"),
    ):
        st = drawing[impl]
        ratio = drawing["ours"]["median_ms"] / st["median_ms"]
        rows.append(
            f"{label:<32} {st['median_ms']:>10.3f} {st['p90_ms']:>9.3f} {st['min_median_ms']:>9.3f}  {ratio:>9.2f}"
        )
    print_table("the same projected pixel coordinates to a (480, 640) uint8 image", hdr, rows)

    for name, res in results.items():
        c = res["checks"]
        print(
            f"check {name}: frames through the clipping path {c['frames_through_clipping']}/{FRAMES}; "
            f"over {c['pixel_check_frames']} frames ({c['ours_pixels']} of our pixels): IoU vs pyrender "
            f"{fmt_ratio(c.get('pixel_iou_vs_pyrender'), 4)} (same rule); vs OpenCV IoU "
            f"{fmt_ratio(c['pixel_iou_vs_opencv'], 3)}, within 1 px {c['ours_within_1px_of_opencv']:.4f} (ours) / "
            f"{c['opencv_within_1px_of_ours']:.4f} (cv)"
        )
    print(f"check drawing alone: same pixels as render_frame's image: {drawing['same_pixels_as_render_frame']}")
    print(
        f"memory: one icosphere frame of ours, tracemalloc peak extra "
        f"{memory['peak_extra_bytes'] / 2**20:.1f} MiB (result kept {memory['result_bytes'] / 2**20:.1f} MiB; "
        f"inputs {memory['input_bytes'] / 2**20:.1f} MiB)"
    )
    print()

    cube_ms = results["cube"]["ours"]["median_ms"]
    ico = results["icosphere"]
    ico_ms = ico["ours"]["median_ms"]
    targets = [
        {
            "name": "cube frame <= 1 ms",
            "value": cube_ms,
            "limit": CUBE_TARGET_MS,
            "unit": "ms",
            "pass": cube_ms <= CUBE_TARGET_MS,
        },
        {
            "name": f"icosphere frame <= {ICO_TARGET_RATIO:g}x pyrender (llvmpipe)",
            "value": ico["ratio_vs_pyrender"],
            "limit": ICO_TARGET_RATIO,
            "unit": "x",
            "pass": ico["ratio_vs_pyrender"] <= ICO_TARGET_RATIO,
        },
        {
            "name": f"icosphere frame <= {ICO_TARGET_RATIO:g}x OpenCV (projectPoints + polylines)",
            "value": ico["ratio_vs_opencv"],
            "limit": ICO_TARGET_RATIO,
            "unit": "x",
            "pass": ico["ratio_vs_opencv"] <= ICO_TARGET_RATIO,
        },
        {
            "name": f"icosphere drawing <= {ICO_TARGET_RATIO:g}x cv2.polylines LINE_8",
            "unit": "x",
            "value": drawing["ratio_vs_cv2_LINE_8"],
            "limit": ICO_TARGET_RATIO,
            "pass": drawing["ratio_vs_cv2_LINE_8"] <= ICO_TARGET_RATIO,
        },
        {
            "name": f"icosphere drawing <= {ICO_TARGET_RATIO:g}x cv2.polylines LINE_8 shift=8",
            "unit": "x",
            "value": drawing["ratio_vs_cv2_LINE_8_shift8"],
            "limit": ICO_TARGET_RATIO,
            "pass": drawing["ratio_vs_cv2_LINE_8_shift8"] <= ICO_TARGET_RATIO,
        },
    ]
    print(
        f"targets (ours, medians; icosphere frame {ico_ms:.2f} ms, pyrender {ico['pyrender']['median_ms']:.2f} ms, "
        f"OpenCV {ico['opencv']['median_ms']:.2f} ms):"
    )
    for t in targets:
        value = f"{t['value']:.3f} ms" if t["unit"] == "ms" else f"ratio {t['value']:.2f}"
        print(f"  {verdict(t['pass'], 'MISS'):<4}  {t['name']:<58} {value}")
    elapsed = time.perf_counter() - t_start
    print(f"\ntotal benchmark time {elapsed:.1f} s")

    if args.json:
        config = {
            "frames": FRAMES,
            "stride": stride,
            "width": WIDTH,
            "height": HEIGHT,
            "camera": "camera_z(4.0, fov_y_deg=70)",
            "motion_turns": list(motion.turns),
            "repeats": repeats,
            "warmup_frames": warmup,
            "quick": args.quick,
            "timed_region": "model-space vertices + model matrix -> image in host memory, every side",
            "statistic": "median over repeats of per-repeat median / p90 of per-frame times",
        }
        write_json(
            args.json,
            machine=info,
            config=config,
            results=results,
            drawing=drawing,
            memory=memory,
            targets=targets,
            elapsed_s=elapsed,
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
