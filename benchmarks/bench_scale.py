#!/usr/bin/env python
"""How wirecheck's per-frame cost grows with the mesh, 8 to 1,000,000 vertices, against OpenCV.

Run from the repo root::

    .venv/bin/python benchmarks/bench_scale.py [--quick] [--json PATH]

Meshes (all seen by ``camera_z(4.0, fov_y_deg=70)`` at 1280x960, posed by
``Motion()``; every vertex stays in [near, far] and on the image, so
``render_frame`` always takes its no-clip fast path, which is checked):

* ``cube``    ``core.scene.files.load_scene('cube')``: 8 vertices, 12 edges
* ``ico<s>``  ``trimesh.creation.icosphere(subdivisions=s)``, s = 0..8:
  12 .. 655,362 vertices; edges are the unique edges of the faces
* ``grid<n>`` an n x n height field over [-1, 1]^2,
  ``z = 0.1 sin(3x) cos(3y)``, n = 3 .. 1000 (9 .. 1,000,000 vertices);
  edges are the grid lines, 2 n (n - 1) of them

Stages, each timed per call on the same poses for every implementation:

* projection, model-space points to (N, 2) pixels:
  ``ours f64`` / ``ours f32`` is render_frame's own path from ``LocalPoints``
  (``localize`` once per scene, outside the timing): ``model_to_cam`` (the
  camera-relative model-view transform, elementwise in blocks), ``depth_mask``,
  ``cam_to_px`` (straight into the result when every point is in depth range,
  else into a NaN-filled array), cast to float64. ``ours f64 1thr`` is the same with
  OpenBLAS limited to one thread (see the caveat in benchmarks/README.md).
  ``cv2.projectPoints`` gets the same model-space points, the model-view rvec,
  tvec (composed per call from the model matrix and the camera, inside the
  timing) and K. ``cv2.transform`` is an all-OpenCV lower bound without
  projectPoints' Jacobian: ``cv2.transform`` by ``K [R | t]`` and
  ``cv2.convertPointsFromHomogeneous``.
* raster, pixel coordinates (computed outside the timing) to a (960, 1280)
  uint8 image, ``np.zeros`` included for all: ``core.projector.raster.line_pixels``
  (exact), ``line_pixels_fast`` (integer DDA) and ``line_coverage_aa`` +
  ``paint_aa`` against ``cv2.polylines(img, segs, False, 255, 1, LINE_8)`` on
  the (E, 2, 2) int32 array of rounded ends, the same with ``shift=8``
  (ends in 1/256 px) and ``LINE_AA`` with ``shift=8``.
* frame: ``render_frame(LocalPoints, edges, camera, M, raster=...)``.

Statistics: per mesh, each implementation runs k passes over the same P poses
(k from a time budget, the same poses for all), in R rounds that alternate the
order of the implementations; reported is the median per-call time over all
its calls (and the min). The log-log slope of time against V + E is fitted
over the meshes with >= 10,000 vertices, and for the exact frame also over
every mesh, 8 to 1,000,000 vertices (the 1M frame is timed in ``--quick``
too), with its cost per vertex + edge at each size.

Memory runs first, in child processes (so that the other measurements do not
set the peak): the peak RSS (VmHWM, the figure ``ru_maxrss`` reports; reset
after the setup so the frames' share is visible) and the tracemalloc peak of
a 1M-vertex frame, then RSS and tracemalloc's current size after frame 10 and
after frame 200 of one mesh (``grid316``, 99,856 vertices; ``--quick``:
``grid224``, 50,176; ``--growth-grid 1000`` for the 1M grid), each read after
``gc.collect()`` and ``malloc_trim(0)`` (outside the timing).
"""

from __future__ import annotations

import argparse
import ctypes
import gc
import glob
import json
import os
import resource
import subprocess
import sys
import time
import tracemalloc
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

import cv2
import numpy as np
import trimesh
from _common import fmt_ms, machine_info, print_end, print_machine, print_table, verdict, write_json
from wirecheck.core.camera import camera_z
from wirecheck.core.projector import raster
from wirecheck.core.projector.pipeline import render_frame
from wirecheck.core.projector.projection import cam_to_px, depth_mask, localize, model_to_cam
from wirecheck.core.scene.files import load_scene
from wirecheck.core.scene.model import unique_edges
from wirecheck.core.transforms import Motion

WIDTH, HEIGHT = 1280, 960
FRAMES = 180  # Motion() period; poses are frames of it
PROJ_SPEEDUP_TARGET = 5.0  # ours f64 >= 5x faster than cv2.projectPoints at 1M points
AGREE_TARGET_PX = 1e-9  # max |ours f64 - cv2.projectPoints|
RASTER_RATIO_TARGET = 2.0  # ours raster <= 2x cv2.polylines at the largest size
SLOPE_LIMIT = 1.15  # log-log slope of time vs V + E (1 = linear)
RSS_GROWTH_LIMIT_MIB = 8.0  # RSS after the last frame - after frame 10
TRACED_GROWTH_LIMIT_KIB = 64.0  # tracemalloc current after the last frame - after frame 10


# ---------------------------------------------------------------- meshes
def make_camera():
    return camera_z(4.0, fov_y_deg=70, width=WIDTH, height=HEIGHT)


def fast_unique_edges(edges: np.ndarray, n_vertices: int) -> np.ndarray:
    """``core.scene.model.unique_edges`` via a 1-D key (``np.unique(axis=0)`` takes ~6 s at 2M edges)."""
    e = np.sort(np.asarray(edges, dtype=np.int64).reshape(-1, 2), axis=1)
    e = e[e[:, 0] != e[:, 1]]
    key = np.unique(e[:, 0] * n_vertices + e[:, 1])
    return np.stack([key // n_vertices, key % n_vertices], axis=1).astype(np.intp)


def icosphere(subdivisions: int) -> tuple[np.ndarray, np.ndarray]:
    mesh = trimesh.creation.icosphere(subdivisions=subdivisions)
    v = np.ascontiguousarray(mesh.vertices, dtype=np.float64)
    f = np.asarray(mesh.faces, dtype=np.int64)
    e = fast_unique_edges(f[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), len(v))
    if subdivisions <= 5:  # same set as core's own unique_edges
        assert np.array_equal(e, unique_edges(f[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2)))
    return v, e


def grid(n: int) -> tuple[np.ndarray, np.ndarray]:
    u = np.linspace(-1.0, 1.0, n)
    x, y = np.meshgrid(u, u)
    v = np.stack([x.ravel(), y.ravel(), 0.1 * np.sin(3 * x.ravel()) * np.cos(3 * y.ravel())], axis=1)
    idx = np.arange(n * n, dtype=np.intp).reshape(n, n)
    e = np.concatenate(
        [
            np.stack([idx[:, :-1].ravel(), idx[:, 1:].ravel()], axis=1),
            np.stack([idx[:-1, :].ravel(), idx[1:, :].ravel()], axis=1),
        ]
    )
    return np.ascontiguousarray(v), e


def mesh_list(quick: bool) -> list[tuple[str, str, object]]:
    """(name, family, builder) in increasing size."""
    if quick:
        ico = (0, 3, 5, 6)
        grids = (10, 32, 100, 316, 1000)
    else:
        ico = tuple(range(9))
        grids = (3, 10, 32, 100, 316, 1000)
    out = [
        (
            "cube",
            "cube",
            lambda: (
                np.ascontiguousarray(load_scene("cube").vertices, dtype=np.float64),
                np.asarray(load_scene("cube").edges, dtype=np.intp),
            ),
        )
    ]
    out += [(f"ico{s}", "icosphere", (lambda s=s: icosphere(s))) for s in ico]
    out += [(f"grid{n}", "grid", (lambda n=n: grid(n))) for n in grids]
    return out


# ---------------------------------------------------------------- OpenBLAS threads
class OpenBLAS:
    """numpy's bundled OpenBLAS, for setting its thread count (no threadpoolctl here)."""

    def __init__(self):
        self.set = self.get = None
        libs = sorted(glob.glob(str(Path(np.__file__).resolve().parent.parent / "numpy.libs" / "*openblas*.so*")))
        for path in libs:
            try:
                lib = ctypes.CDLL(path)
            except OSError:
                continue
            for s_name, g_name in (
                ("scipy_openblas_set_num_threads64_", "scipy_openblas_get_num_threads64_"),
                ("openblas_set_num_threads64_", "openblas_get_num_threads64_"),
                ("openblas_set_num_threads", "openblas_get_num_threads"),
            ):
                if hasattr(lib, s_name) and hasattr(lib, g_name):
                    self.set, self.get = getattr(lib, s_name), getattr(lib, g_name)
                    self.set.argtypes = [ctypes.c_int]
                    self.path = path
                    return

    @property
    def available(self) -> bool:
        return self.set is not None

    def threads(self) -> int | None:
        return int(self.get()) if self.available else None


# ---------------------------------------------------------------- implementations
def ours_project(points, m, camera) -> np.ndarray:
    """render_frame's projection, line for line: model-view, depth test, pixels, float64."""
    p_cam = model_to_cam(points, m, camera)
    visible = depth_mask(p_cam, camera)
    if visible.all():  # as render_frame: no gather/scatter when all are visible
        p_px = cam_to_px(p_cam, camera)
    else:
        p_px = np.full((len(points), 2), np.nan, dtype=p_cam.dtype)
        if visible.any():
            p_px[visible] = cam_to_px(p_cam[visible], camera)
    return p_px.astype(np.float64, copy=False)


def cv_model_view(m, camera):
    """OpenCV's R, t for model-space points: camera rows [right, -up, forward], camera-relative."""
    r_cam = np.stack([camera.right, -camera.up, camera.forward])
    return r_cam @ m[:3, :3], r_cam @ (m[:3, 3] - camera.position)


def cv_intrinsics(camera) -> np.ndarray:
    f = camera.focal_px
    cx, cy = camera.principal_point
    return np.array([[f, 0.0, cx], [0.0, f, cy], [0.0, 0.0, 1.0]])


def cv_project(p_model, m, camera, k) -> np.ndarray:
    r, t = cv_model_view(m, camera)
    rvec, _ = cv2.Rodrigues(r)
    img_pts, _jac = cv2.projectPoints(p_model, rvec, t, k, None)
    return img_pts.reshape(-1, 2)


def cv_transform(p_model3, m, camera, k) -> np.ndarray:
    """All-OpenCV projection without the Jacobian: K [R | t] by cv2.transform, then divide."""
    r, t = cv_model_view(m, camera)
    p = k @ np.hstack([r, t[:, None]])
    h = cv2.transform(p_model3, p)
    return cv2.convertPointsFromHomogeneous(h).reshape(-1, 2)


# ---------------------------------------------------------------- timing
def time_calls(fn, args_list, passes: int) -> list[float]:
    out = []
    perf = time.perf_counter
    for _ in range(passes):
        for a in args_list:
            t0 = perf()
            fn(a)
            out.append(perf() - t0)
    return out


def bench_group(impls: dict, n_poses: int, budget_s: float, rounds: int, max_passes: int) -> dict:
    """Median per-call ms of each ``impls[name](pose_index)`` over the same poses.

    Warm-up: one pass. Each implementation then makes ``passes`` passes over
    the poses per round (from ``budget_s`` and its warm-up time), in ``rounds``
    rounds alternating the order of the implementations. GC is off.
    """
    poses = list(range(n_poses))
    gc_was_on = gc.isenabled()
    gc.disable()
    try:
        passes = {}
        for name, fn in impls.items():
            t_warm = sum(time_calls(fn, poses, 1))
            passes[name] = int(np.clip(budget_s / max(t_warm, 1e-9), 1, max_passes))
        times = {name: [] for name in impls}
        order = list(impls)
        for r in range(rounds):
            for name in order if r % 2 == 0 else order[::-1]:
                times[name] += time_calls(impls[name], poses, passes[name])
    finally:
        if gc_was_on:
            gc.enable()
    return {
        name: {
            "median_ms": float(np.median(t)) * 1e3,
            "min_ms": float(np.min(t)) * 1e3,
            "p90_ms": float(np.percentile(t, 90)) * 1e3,
            "calls": len(t),
        }
        for name, t in times.items()
    }


def slope(xs, ys) -> float | None:
    if len(xs) < 2:
        return None
    return float(np.polyfit(np.log(xs), np.log(ys), 1)[0])


# ---------------------------------------------------------------- one mesh
def bench_mesh(name, family, v, e, camera, matrices, cfg, blas) -> dict:
    n_v, n_e = len(v), len(e)
    size = n_v + n_e
    n_poses = cfg["poses_small"] if size < 100_000 else cfg["poses_100k"] if size < 1_000_000 else cfg["poses_1m"]
    mats = matrices[:: len(matrices) // n_poses][:n_poses]
    lp64 = localize(v, "float64")
    lp32 = localize(v, "float32")
    k = cv_intrinsics(camera)
    v3 = v.reshape(-1, 1, 3)
    res = {"name": name, "family": family, "vertices": n_v, "edges": n_e, "poses": n_poses}

    # ---- checks, outside the timing: fast path, agreement
    px = [ours_project(lp64, m, camera) for m in mats]
    on = [
        np.all((p[:, 0] >= -0.5) & (p[:, 0] <= WIDTH - 0.5) & (p[:, 1] >= -0.5) & (p[:, 1] <= HEIGHT - 0.5)) for p in px
    ]
    res["poses_through_clipping"] = int(sum(not o for o in on))
    d64 = d32 = dxf = 0.0
    for m, p in zip(mats, px):
        ref = cv_project(v, m, camera, k)
        d64 = max(d64, float(np.abs(p - ref).max()))
        d32 = max(d32, float(np.abs(ours_project(lp32, m, camera) - ref).max()))
        dxf = max(dxf, float(np.abs(cv_transform(v3, m, camera, k) - ref).max()))
        del ref
    res["max_abs_diff_px"] = {"ours_f64": d64, "ours_f32": d32, "cv2_transform": dxf}

    big = n_v >= 1_000_000
    budget = cfg["budget_s"]
    rounds = cfg["rounds"] if not big else min(cfg["rounds"], 2)  # 1M: 2 rounds of 2 poses
    max_passes = cfg["max_passes"]

    # ---- projection
    proj = {
        "ours_f64": lambda i: ours_project(lp64, mats[i], camera),
        "ours_f32": lambda i: ours_project(lp32, mats[i], camera),
        "cv2_projectPoints": lambda i: cv_project(v, mats[i], camera, k),
        "cv2_transform": lambda i: cv_transform(v3, mats[i], camera, k),
    }
    if blas.available:
        default_threads = blas.threads()

        def one_thread(i):
            blas.set(1)
            try:
                return ours_project(lp64, mats[i], camera)
            finally:
                blas.set(default_threads)

        proj["ours_f64_1thr"] = one_thread
    res["projection"] = bench_group(proj, n_poses, budget, rounds, max_passes)

    # ---- raster (pixel coordinates computed above, outside the timing)
    do_raster = not (big and cfg["skip_1m_raster"])
    if do_raster:
        seg0 = [np.take(p, e[:, 0], axis=0) for p in px]
        seg1 = [np.take(p, e[:, 1], axis=0) for p in px]
        segs = [np.rint(p).astype(np.int32)[e] for p in px]
        segs8 = [np.rint(p * 256.0).astype(np.int32)[e] for p in px]

        def r_exact(i):
            img = np.zeros((HEIGHT, WIDTH), np.uint8)
            rr, cc = raster.line_pixels(seg0[i], seg1[i], WIDTH, HEIGHT)
            img[rr, cc] = 255
            return img

        def r_fast(i):
            img = np.zeros((HEIGHT, WIDTH), np.uint8)
            rr, cc = raster.line_pixels_fast(seg0[i], seg1[i], WIDTH, HEIGHT)
            img[rr, cc] = 255
            return img

        def r_aa(i):
            rr, cc, w = raster.line_coverage_aa(seg0[i], seg1[i], WIDTH, HEIGHT)
            return raster.paint_aa(rr, cc, w, WIDTH, HEIGHT)

        def cv_l8(i):
            img = np.zeros((HEIGHT, WIDTH), np.uint8)
            cv2.polylines(img, segs[i], False, 255, 1, cv2.LINE_8)
            return img

        def cv_l8s8(i):
            img = np.zeros((HEIGHT, WIDTH), np.uint8)
            cv2.polylines(img, segs8[i], False, 255, 1, cv2.LINE_8, 8)
            return img

        def cv_aa(i):
            img = np.zeros((HEIGHT, WIDTH), np.uint8)
            cv2.polylines(img, segs8[i], False, 255, 1, cv2.LINE_AA, 8)
            return img

        rast = {
            "ours_exact": r_exact,
            "ours_fast": r_fast,
            "ours_aa": r_aa,
            "cv2_LINE_8": cv_l8,
            "cv2_LINE_8_shift8": cv_l8s8,
        }
        if cfg["cv_aa"]:
            rast["cv2_LINE_AA_shift8"] = cv_aa
        res["raster"] = bench_group(rast, n_poses, budget, rounds, max_passes)
        # pixel agreement on pose 0 (outside the timing)
        a_fast = r_fast(0) > 0
        a_ex = r_exact(0) > 0
        b8 = cv_l8(0) > 0
        b8s = cv_l8s8(0) > 0

        def iou(a, b):
            u = int((a | b).sum())
            return int((a & b).sum()) / u if u else 1.0

        res["raster_pixels_pose0"] = {
            "ours_exact": int(a_ex.sum()),
            "cv2_LINE_8": int(b8.sum()),
            "cv2_LINE_8_shift8": int(b8s.sum()),
            "iou_exact_vs_cv2_shift8": iou(a_ex, b8s),
            "iou_fast_vs_cv2_LINE_8": iou(a_fast, b8),
        }
        del seg0, seg1, segs, segs8
    del px

    # ---- whole frame
    if not (big and cfg["skip_1m_frame"]):
        frame = {"render_frame_exact": lambda i: render_frame(lp64, e, camera, mats[i])}
        if not (big and cfg["frame_1m_exact_only"]):
            frame["render_frame_fast"] = lambda i: render_frame(lp64, e, camera, mats[i], raster="fast")
        if cfg["frame_aa"] and not (big and cfg["frame_1m_exact_only"]):
            frame["render_frame_aa"] = lambda i: render_frame(lp64, e, camera, mats[i], raster="aa")
        res["frame"] = bench_group(frame, n_poses, budget, rounds, max_passes)
    return res


# ---------------------------------------------------------------- memory (child process)
def _status_mib(key: str) -> float:
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith(key + ":"):
                return int(line.split()[1]) / 1024.0
    return float("nan")


def rss_mib() -> float:
    """Current resident set size (VmRSS)."""
    return _status_mib("VmRSS")


def hwm_mib() -> float:
    """Peak resident set size of this process image (VmHWM; what ru_maxrss reports, minus inheritance)."""
    return _status_mib("VmHWM")


def maxrss_mib() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def malloc_trim() -> bool:
    """Give glibc's free heap pages back to the OS, so RSS shows live memory (not the allocator's cache)."""
    try:
        return bool(ctypes.CDLL("libc.so.6").malloc_trim(0))
    except (OSError, AttributeError):
        return False


def reset_hwm() -> bool:
    """Reset VmHWM to the current RSS (Linux >= 4.0: write 5 to /proc/self/clear_refs)."""
    try:
        with open("/proc/self/clear_refs", "w") as fh:
            fh.write("5")
        return True
    except OSError:
        return False


def memory_child(spec: dict) -> dict:
    """Run in a fresh process: memory of ``frames`` frames of one grid mesh.

    Peak RSS is VmHWM, reset to the current RSS after the setup (mesh built,
    ``localize`` done) where the kernel allows it, so ``peak - setup`` is what
    the frames add. ru_maxrss is reported too; on Linux it can carry the
    parent's RSS at the fork, which is why the parent runs these first.
    """
    camera = make_camera()
    motion = Motion()
    impl = spec["impl"]
    trace = spec.get("trace", True)
    v, e = grid(spec["grid"])
    lp = localize(v, "float64")
    k = cv_intrinsics(camera)
    out = {
        "impl": impl,
        "mesh": f"grid{spec['grid']}",
        "vertices": len(v),
        "edges": len(e),
        "input_mib": (v.nbytes + e.nbytes) / 2**20,
        "raster": spec.get("raster", "exact"),
    }
    gc.collect()
    out["hwm_setup_mib"] = hwm_mib()
    out["hwm_reset"] = reset_hwm()
    out["rss_setup_mib"] = rss_mib()

    if impl == "ours":

        def frame(m):
            return render_frame(lp, e, camera, m, raster=out["raster"]).image
    else:

        def frame(m):
            pts = np.rint(cv_project(v, m, camera, k)).astype(np.int32)
            img = np.zeros((HEIGHT, WIDTH), np.uint8)
            cv2.polylines(img, pts[e], False, 255, 1, cv2.LINE_8)
            return img

    n = spec["frames"]
    checkpoints = sorted({c for c in (1, 10, 50, 100, 150, 200, n) if c <= n})
    if trace:
        tracemalloc.start()
        base = tracemalloc.get_traced_memory()[0]
    marks = {}
    t0 = time.perf_counter()
    img = None
    for i in range(1, n + 1):
        img = frame(motion.frame_matrix(i, FRAMES))
        if i == 1 and trace:
            out["traced_peak_frame1_mib"] = (tracemalloc.get_traced_memory()[1] - base) / 2**20
        if i in checkpoints:
            # tracemalloc counts objects parked on CPython's free lists (the 3-tuple list holds up
            # to 2000, ~128 KiB) as allocated; a full collection empties them. Not in the timing.
            if trace:
                mark = {"traced_current_before_collect_kib": (tracemalloc.get_traced_memory()[0] - base) / 1024}
            else:
                mark = {}
            gc.collect()
            hwm = hwm_mib()  # before malloc_trim, which does not lower it anyway
            malloc_trim()
            mark.update({"rss_mib": rss_mib(), "hwm_mib": hwm})
            if trace:
                mark["traced_current_kib"] = (tracemalloc.get_traced_memory()[0] - base) / 1024
            marks[i] = mark
    out["seconds"] = time.perf_counter() - t0
    if trace:
        out["traced_peak_mib"] = (tracemalloc.get_traced_memory()[1] - base) / 2**20
        tracemalloc.stop()
    out["frames"] = n
    out["marks"] = marks
    out["hwm_mib"] = hwm_mib()
    out["maxrss_mib"] = maxrss_mib()
    out["image_sum"] = int(img.sum()) if img is not None else 0
    return out


def run_child(spec: dict) -> dict:
    cmd = [sys.executable, str(Path(__file__).resolve()), "--memory-child", json.dumps(spec)]
    proc = subprocess.run(cmd, capture_output=True, text=True, cwd=str(ROOT))
    if proc.returncode != 0:
        raise RuntimeError(f"memory child failed: {proc.stderr[-2000:]}")
    return json.loads(proc.stdout.strip().splitlines()[-1])


# ---------------------------------------------------------------- machine
def blas_info(blas: OpenBLAS) -> dict:
    """:func:`_common.machine_info` with OpenBLAS's thread count and the BLAS environment variables."""
    return machine_info(
        openblas_threads=blas.threads(),
        blas_env={
            k: os.environ[k] for k in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS") if k in os.environ
        },
    )


# ---------------------------------------------------------------- main
def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument(
        "--quick",
        action="store_true",
        help="fewer meshes, poses and repeats; at 1M vertices no raster row and only the exact frame",
    )
    ap.add_argument("--json", metavar="PATH", help="also write the results as JSON to PATH")
    ap.add_argument(
        "--growth-grid",
        type=int,
        metavar="N",
        help="grid size n (n x n vertices) of the 200-frame growth test (default 316, --quick 224; "
        "1000 = 1M vertices, about 4 minutes)",
    )
    ap.add_argument("--memory-child", metavar="SPEC", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.memory_child:
        print(json.dumps(memory_child(json.loads(args.memory_child))))
        return 0

    t_start = time.perf_counter()
    blas = OpenBLAS()
    cfg = (
        {
            "budget_s": 0.04,
            "rounds": 3,
            "max_passes": 25,
            "poses_small": 4,
            "poses_100k": 2,
            "poses_1m": 1,
            "skip_1m_raster": True,
            "skip_1m_frame": False,
            "frame_1m_exact_only": True,
            "cv_aa": False,
            "frame_aa": False,
            "growth": {"grid": 224, "frames": 200},
            "peak": {"grid": 1000, "frames": 2},
            "cv_peak": False,
        }
        if args.quick
        else {
            "budget_s": 0.25,
            "rounds": 3,
            "max_passes": 200,
            "poses_small": 8,
            "poses_100k": 4,
            "poses_1m": 2,
            "skip_1m_raster": False,
            "skip_1m_frame": False,
            "frame_1m_exact_only": False,
            "cv_aa": True,
            "frame_aa": True,
            "growth": {"grid": 316, "frames": 200},
            "peak": {"grid": 1000, "frames": 3},
            "cv_peak": True,
        }
    )
    if args.growth_grid:
        cfg["growth"]["grid"] = args.growth_grid
    camera = make_camera()
    motion = Motion()
    matrices = [motion.frame_matrix(i, FRAMES) for i in range(1, FRAMES + 1)]
    info = blas_info(blas)

    print_machine(
        "wirecheck scale benchmark",
        info,
        libraries=(
            f"python {info['python']}, numpy {info['numpy']} (OpenBLAS threads {info['openblas_threads']}"
            f"{', env ' + str(info['blas_env']) if info['blas_env'] else ''}), cv2 {info['cv2']} "
            f"(threads {info['cv2_threads']}), trimesh {info['trimesh']}"
        ),
    )
    print(f"  camera_z(4.0, fov_y_deg=70) {WIDTH}x{HEIGHT}, Motion() poses; raster modes: exact, fast, aa")
    print(
        f"  mode: {'quick' if args.quick else 'full'}; per implementation and mesh: {cfg['rounds']} rounds, "
        f"passes over the poses from a {cfg['budget_s']:g} s budget (max {cfg['max_passes']})"
    )
    print(flush=True)

    # Memory first, in child processes: on Linux a child's ru_maxrss can start at
    # the parent's RSS, so the parent should still be small.
    mem = {"ours_peak": run_child({"impl": "ours", "grid": cfg["peak"]["grid"], "frames": cfg["peak"]["frames"]})}
    if cfg["cv_peak"]:
        mem["opencv_peak"] = run_child(
            {"impl": "opencv", "grid": cfg["peak"]["grid"], "frames": cfg["peak"]["frames"], "trace": False}
        )
    mem["ours_growth"] = run_child({"impl": "ours", "grid": cfg["growth"]["grid"], "frames": cfg["growth"]["frames"]})
    for child in mem.values():  # JSON turned the checkpoint keys into strings
        child["marks"] = {int(i): mk for i, mk in child["marks"].items()}
    print(f"  memory children done ({time.perf_counter() - t_start:.1f} s)", flush=True)

    results = []
    for name, family, build in mesh_list(args.quick):
        v, e = build()
        t0 = time.perf_counter()
        res = bench_mesh(name, family, v, e, camera, matrices, cfg, blas)
        res["bench_s"] = time.perf_counter() - t0
        results.append(res)
        p = res["projection"]
        print(
            f"  {name:<9} V={len(v):>9,} E={len(e):>9,}  proj f64 {fmt_ms(p['ours_f64']['median_ms'])} ms, "
            f"cv2 {fmt_ms(p['cv2_projectPoints']['median_ms'])} ms  ({res['bench_s']:.1f} s)",
            flush=True,
        )
        del v, e
        gc.collect()
    print()

    # ---- tables
    proj_cols = [
        ("ours_f64", "f64"),
        ("ours_f64_1thr", "f64 1thr"),
        ("ours_f32", "f32"),
        ("cv2_projectPoints", "cv2.pP"),
        ("cv2_transform", "cv2.xf"),
    ]
    hdr = (
        f"{'mesh':<9} {'V':>9} {'E':>9} | "
        + " ".join(f"{h:>9}" for _, h in proj_cols)
        + f" | {'pP/f64':>7} {'max|d| f64':>10} {'f32':>8} {'cv2.xf':>8}"
    )
    rows = []
    for r in results:
        p = r["projection"]
        cells = " ".join(f"{fmt_ms(p[c]['median_ms']) if c in p else '-':>9}" for c, _ in proj_cols)
        d = r["max_abs_diff_px"]
        rows.append(
            f"{r['name']:<9} {r['vertices']:>9,} {r['edges']:>9,} | {cells} | "
            f"{p['cv2_projectPoints']['median_ms'] / p['ours_f64']['median_ms']:>7.2f} "
            f"{d['ours_f64']:>10.1e} {d['ours_f32']:>8.1e} {d['cv2_transform']:>8.1e}"
        )
    print_table(
        "projection, model space -> (N, 2) pixels, median ms per call (pP = cv2.projectPoints, "
        "xf = cv2.transform + convertPointsFromHomogeneous; max|d| = px vs cv2.pP)",
        hdr,
        rows,
    )

    rast_cols = [
        ("ours_exact", "exact"),
        ("ours_fast", "fast"),
        ("ours_aa", "aa"),
        ("cv2_LINE_8", "cv2 L8"),
        ("cv2_LINE_8_shift8", "cv2 L8 s8"),
        ("cv2_LINE_AA_shift8", "cv2 AA s8"),
    ]
    hdr = (
        f"{'mesh':<9} {'E':>9} | "
        + " ".join(f"{h:>9}" for _, h in rast_cols)
        + f" | {'fast/L8':>7} {'exact/s8':>8} {'aa/AA':>6}"
    )

    def raster_row(r):
        if "raster" not in r:
            return f"{r['name']:<9} {r['edges']:>9,} | (skipped in --quick)"
        q = r["raster"]
        cells = " ".join(f"{fmt_ms(q[c]['median_ms']) if c in q else '-':>9}" for c, _ in rast_cols)

        def ratio(a, b):
            return f"{q[a]['median_ms'] / q[b]['median_ms']:.2f}" if a in q and b in q else "-"

        return (
            f"{r['name']:<9} {r['edges']:>9,} | {cells} | {ratio('ours_fast', 'cv2_LINE_8'):>7} "
            f"{ratio('ours_exact', 'cv2_LINE_8_shift8'):>8} {ratio('ours_aa', 'cv2_LINE_AA_shift8'):>6}"
        )

    print_table(
        f"raster, pixel ends -> ({HEIGHT}, {WIDTH}) uint8 image incl. np.zeros, median ms per call "
        "(L8 = cv2.polylines LINE_8 on rounded ends, s8 = shift=8 ends in 1/256 px)",
        hdr,
        [raster_row(r) for r in results],
    )

    frame_cols = [("render_frame_exact", "exact"), ("render_frame_fast", "fast"), ("render_frame_aa", "aa")]
    hdr = f"{'mesh':<9} {'V+E':>10} | " + " ".join(f"{h:>9}" for _, h in frame_cols) + " | clip poses"

    def frame_row(r):
        if "frame" not in r:
            return f"{r['name']:<9} {r['vertices'] + r['edges']:>10,} | (skipped in --quick)"
        f = r["frame"]
        cells = " ".join(f"{fmt_ms(f[c]['median_ms']) if c in f else '-':>9}" for c, _ in frame_cols)
        return (
            f"{r['name']:<9} {r['vertices'] + r['edges']:>10,} | {cells} | {r['poses_through_clipping']}/{r['poses']}"
        )

    print_table("whole frame, render_frame(LocalPoints, ...), median ms per call", hdr, [frame_row(r) for r in results])

    # ---- slopes
    slopes = {}
    big = [r for r in results if r["vertices"] >= 10_000]
    stage_impls = (
        [("projection", c) for c, _ in proj_cols]
        + [("raster", c) for c, _ in rast_cols]
        + [("frame", c) for c, _ in frame_cols]
    )
    print(
        "log-log slope of median time against V + E, meshes with >= 10,000 vertices "
        f"(all / icospheres / grids; PASS when the 'all' slope <= {SLOPE_LIMIT})"
    )
    for stage, impl in stage_impls:
        row = {}
        for fam in ("all", "icosphere", "grid"):
            rs = [r for r in big if stage in r and impl in r[stage] and (fam == "all" or r["family"] == fam)]
            row[fam] = slope([r["vertices"] + r["edges"] for r in rs], [r[stage][impl]["median_ms"] for r in rs])
            row[f"{fam}_n"] = len(rs)
        if row["all"] is None:
            continue
        slopes[f"{stage}.{impl}"] = row
        tag = verdict(row["all"] <= SLOPE_LIMIT) if impl.startswith(("ours", "render")) else "(ref)"
        print(
            f"  {stage:<10} {impl:<20} {row['all']:6.3f} / "
            f"{row['icosphere'] if row['icosphere'] is not None else float('nan'):6.3f} / "
            f"{row['grid'] if row['grid'] is not None else float('nan'):6.3f}   "
            f"(n={row['all_n']})  {tag}"
        )
    # the exact frame over the whole range, 8 .. 10^6 vertices: the fixed cost of a
    # call (~0.2 ms) dominates the small meshes, so this slope is below the one above;
    # linear means no size at which the cost per element grows
    full = [r for r in results if "frame" in r and "render_frame_exact" in r["frame"]]
    xs = [r["vertices"] + r["edges"] for r in full]
    ys = [r["frame"]["render_frame_exact"]["median_ms"] for r in full]
    slopes["frame.render_frame_exact.whole_range"] = {
        "all": slope(xs, ys),
        "all_n": len(full),
        "vertices": [min(r["vertices"] for r in full), max(r["vertices"] for r in full)],
    }
    row = slopes["frame.render_frame_exact.whole_range"]
    print(
        f"  frame      render_frame_exact, all {row['all_n']} meshes, {row['vertices'][0]:,} .. "
        f"{row['vertices'][1]:,} vertices: slope {row['all']:.3f}  {verdict(row['all'] <= SLOPE_LIMIT)}"
    )
    print(
        "  cost per vertex + edge, exact frame: "
        + ", ".join(f"{r['name']} {y * 1e6 / x:.0f} ns" for r, x, y in sorted(zip(full, xs, ys), key=lambda t: t[1]))
    )
    print(flush=True)

    # ---- memory (measured first, see above)
    print("memory (child processes, run before anything else; peak = VmHWM, reset after the setup):")
    for key in ("ours_peak", "opencv_peak"):
        if key not in mem:
            continue
        pk = mem[key]
        who = (
            "ours, render_frame exact"
            if key == "ours_peak"
            else "opencv, projectPoints + rint + gather + polylines LINE_8"
        )
        traced = (
            f"; tracemalloc peak of frame 1 {pk['traced_peak_frame1_mib']:.0f} MiB"
            if "traced_peak_frame1_mib" in pk
            else "; tracemalloc does not see OpenCV's buffers"
        )
        print(
            f"  {who}: {pk['mesh']} ({pk['vertices']:,} V, {pk['edges']:,} E; inputs {pk['input_mib']:.0f} MiB), "
            f"{pk['frames']} frames: peak RSS {pk['hwm_mib']:.0f} MiB = {pk['rss_setup_mib']:.0f} MiB after setup "
            f"+ {pk['hwm_mib'] - pk['rss_setup_mib']:.0f} MiB for the frames (ru_maxrss {pk['maxrss_mib']:.0f} MiB)"
            f"{traced}"
        )
    growth = mem["ours_growth"]
    g = cfg["growth"]
    m10, mlast = growth["marks"][10], growth["marks"][g["frames"]]
    d_rss = mlast["rss_mib"] - m10["rss_mib"]
    d_tr = mlast["traced_current_kib"] - m10["traced_current_kib"]
    d_tr_raw = mlast["traced_current_before_collect_kib"] - m10["traced_current_before_collect_kib"]
    print(
        f"  ours, {growth['mesh']} ({growth['vertices']:,} V, {growth['edges']:,} E), {g['frames']} frames in "
        f"{growth['seconds']:.1f} s (tracemalloc on); frame results dropped each frame; RSS read after "
        "gc.collect() and malloc_trim(0):"
    )
    for i, mk in growth["marks"].items():
        print(
            f"    after frame {int(i):>3}: RSS {mk['rss_mib']:8.1f} MiB, peak RSS {mk['hwm_mib']:8.1f} MiB, "
            f"tracemalloc current {mk['traced_current_kib']:9.1f} KiB "
            f"(before gc.collect {mk['traced_current_before_collect_kib']:9.1f} KiB)"
        )
    print(
        f"    growth frame 10 -> {g['frames']}: RSS {d_rss:+.2f} MiB (peak RSS {mlast['hwm_mib'] - m10['hwm_mib']:+.2f} MiB), "
        f"tracemalloc {d_tr:+.2f} KiB after gc.collect() "
        f"({d_tr_raw:+.2f} KiB before it: CPython free lists, bounded)"
    )
    print()

    # ---- targets
    one_m = [r for r in results if r["vertices"] >= 1_000_000]
    r1m = one_m[-1]
    p1m = r1m["projection"]
    speedup = p1m["cv2_projectPoints"]["median_ms"] / p1m["ours_f64"]["median_ms"]
    speedup_1thr = (
        p1m["cv2_projectPoints"]["median_ms"] / p1m["ours_f64_1thr"]["median_ms"] if "ours_f64_1thr" in p1m else None
    )
    agree_1m = r1m["max_abs_diff_px"]["ours_f64"]
    agree_all = max(r["max_abs_diff_px"]["ours_f64"] for r in results)
    rast_big = [r for r in results if "raster" in r][-1]
    q = rast_big["raster"]
    targets = [
        {
            "name": f"projection {r1m['name']} f64 >= {PROJ_SPEEDUP_TARGET:g}x faster than cv2.projectPoints",
            "ours_ms": p1m["ours_f64"]["median_ms"],
            "cv2_ms": p1m["cv2_projectPoints"]["median_ms"],
            "speedup": speedup,
            "pass": speedup >= PROJ_SPEEDUP_TARGET,
        },
        {
            "name": f"projection {r1m['name']} f64 agrees with cv2.projectPoints within {AGREE_TARGET_PX:g} px",
            "max_abs_diff_px": agree_1m,
            "max_abs_diff_px_all_sizes": agree_all,
            "pass": agree_1m <= AGREE_TARGET_PX,
        },
    ]
    if speedup_1thr is not None:
        targets.append(
            {
                "name": "(info) same with OpenBLAS at 1 thread",
                "ours_ms": p1m["ours_f64_1thr"]["median_ms"],
                "speedup": speedup_1thr,
                "pass": speedup_1thr >= PROJ_SPEEDUP_TARGET,
                "info": True,
            }
        )
    for ours, cv, label in (
        ("ours_fast", "cv2_LINE_8", "fast vs cv2.polylines LINE_8 (rounded ends)"),
        ("ours_exact", "cv2_LINE_8_shift8", "exact vs cv2.polylines LINE_8 shift=8"),
        ("ours_exact", "cv2_LINE_8", "exact vs cv2.polylines LINE_8 (rounded ends)"),
    ):
        if ours in q and cv in q:
            ratio = q[ours]["median_ms"] / q[cv]["median_ms"]
            targets.append(
                {
                    "name": f"raster {rast_big['name']} {label} <= {RASTER_RATIO_TARGET:g}x",
                    "ours_ms": q[ours]["median_ms"],
                    "cv2_ms": q[cv]["median_ms"],
                    "ratio": ratio,
                    "pass": ratio <= RASTER_RATIO_TARGET,
                }
            )
    for key, row in slopes.items():
        impl = key.split(".", 1)[1]
        if impl.startswith(("ours", "render")):
            targets.append(
                {"name": f"slope {key} <= {SLOPE_LIMIT}", "slope": row["all"], "pass": row["all"] <= SLOPE_LIMIT}
            )
    targets.append(
        {
            "name": f"no growth over {g['frames']} frames of {growth['mesh']}: RSS < {RSS_GROWTH_LIMIT_MIB:g} MiB, "
            f"tracemalloc < {TRACED_GROWTH_LIMIT_KIB:g} KiB",
            "rss_growth_mib": d_rss,
            "peak_rss_growth_mib": mlast["hwm_mib"] - m10["hwm_mib"],
            "traced_growth_kib": d_tr,
            "traced_growth_before_collect_kib": d_tr_raw,
            "pass": d_rss < RSS_GROWTH_LIMIT_MIB and d_tr < TRACED_GROWTH_LIMIT_KIB,
        }
    )

    print("targets:")
    for t in targets:
        extra = ""
        if "speedup" in t:
            vs = f" vs cv2 {t['cv2_ms']:.1f} ms" if "cv2_ms" in t else ""
            extra = f"ours {t['ours_ms']:.1f} ms{vs}, speedup {t['speedup']:.2f}x"
        elif "max_abs_diff_px" in t:
            extra = f"max |d| {t['max_abs_diff_px']:.2e} px (all sizes {t['max_abs_diff_px_all_sizes']:.2e})"
        elif "ratio" in t:
            extra = f"ours {t['ours_ms']:.1f} ms vs cv2 {t['cv2_ms']:.1f} ms, ratio {t['ratio']:.2f}"
        elif "slope" in t:
            extra = f"slope {t['slope']:.3f}"
        elif "rss_growth_mib" in t:
            extra = f"RSS {t['rss_growth_mib']:+.2f} MiB, tracemalloc {t['traced_growth_kib']:+.2f} KiB"
        status = ("info " + verdict(t["pass"])) if t.get("info") else verdict(t["pass"])
        print(f"  {status:<9} {t['name']}: {extra}")

    elapsed = print_end(info, t_start)

    if args.json:
        config = {
            "width": WIDTH,
            "height": HEIGHT,
            "camera": "camera_z(4.0, fov_y_deg=70)",
            "motion": "Motion(), frames of 180",
            "quick": args.quick,
            **cfg,
            "statistic": "median per-call time over rounds x passes x poses",
        }
        write_json(
            args.json,
            machine=info,
            config=config,
            results=results,
            slopes=slopes,
            memory=mem,
            targets=targets,
            elapsed_s=elapsed,
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
