#!/usr/bin/env python
"""One frame of a large mesh through crosscheck's pixel stage, against pyrender drawing the same edges.

Run from the repo root::

    .venv/bin/python benchmarks/bench_pixel_scale.py --quick     # a few minutes on 2 cores
    .venv/bin/python benchmarks/bench_pixel_scale.py [--json PATH] [--plot PNG] [--only NAME,...]

Meshes (generated, seeded: the same files every run, written as binary PLY
into a temporary folder):

* ``soup50k``   50,000 independent triangles, corners uniform in [-1, 1]^3
  (long edges across the whole image, as in a broken scan; seed 37)
* ``sphere327k`` ``trimesh.creation.icosphere(subdivisions=7)``: 327,680 faces
* ``ico20k``    ``icosphere(subdivisions=5)``: 20,480 faces
* ``grid40k``, ``grid60k`` a triangulated height field (``z = 0.1 sin 3x cos 3y``)
  of about 40,000 and 60,000 faces
* ``sweep<E>``  the same height field with about E = 10^2 .. 10^6 edges
  (``--quick``: 10^2 .. 10^5)
* ``grid1000k`` the height field of about 1,000,000 faces (1.5M edges): the memory target

Each measurement runs in a fresh interpreter (so that one's peak does not set
the next one's):

* ``wirecheck``: ``core.scene.files.load_scene`` reads the PLY (as crosscheck
  does), then one case (``on_axis``, 640x480, frame 1 of 1) runs by the
  runner's own case runner (warm-up included, as a run pays it): the core
  candidate against OpenCV and pyrender. Reported: the pixel stage per frame
  (``pixel_stage_ms_per_frame``: the candidate's drawing, the pixel metrics and
  the wait for pyrender's drawing, which runs on the GL thread beside them:
  oracles.judge.case.ProjectorFrames), the pixel metrics alone, pyrender's own
  time in the harness and the part of it waited for (JSON), the process's wall
  time and its peak RSS (``ru_maxrss``).
* ``pyrender``: what a user would write instead: trimesh reads the PLY, the
  unique edges of its faces go to pyrender as one LINES primitive, one frame
  is drawn at the same size from the same camera distance (its shaders
  compiled first on a one-line scene, as wirecheck's warm-up does). Reported:
  the draw call (``renderer.render``, the mesh's upload included: one frame of
  a new mesh), a second draw (``redraw``: a frame of a run), the process's
  wall time and its peak RSS.

Targets (issue 37), each printed PASS or FAIL:

* the soup and the sphere: wirecheck's process within 3x pyrender's and under 1 GiB;
* 20k-60k faces: the pixel stage per frame within 2x pyrender's draw call;
* a 1M-face mesh (``grid1000k``): wirecheck's peak RSS under 1.5 GiB.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
HERE = Path(__file__).resolve().parent

SEED = 37
WIDTH, HEIGHT = 640, 480  # the on_axis case's image
GIB = 2**30
SOUP_TIME_RATIO = 3.0  # wirecheck's process <= 3x pyrender's (soup, sphere)
SOUP_RSS_GIB = 1.0  # ... and under 1 GiB
MESH_STAGE_RATIO = 2.0  # pixel stage per frame <= 2x pyrender's draw (20k-60k faces)
MILLION_RSS_GIB = 1.5  # a 1M-face mesh's peak RSS


# ---------------------------------------------------------------- meshes
def grid_faces(n: int):
    """An n x n height field, each cell two triangles: ``(vertices, faces)``."""
    import numpy as np

    u = np.linspace(-1.0, 1.0, n)
    x, y = np.meshgrid(u, u)
    v = np.stack([x.ravel(), y.ravel(), 0.1 * np.sin(3 * x.ravel()) * np.cos(3 * y.ravel())], axis=1)
    idx = np.arange(n * n).reshape(n, n)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel()
    f = np.concatenate([np.stack([a, b, d], 1), np.stack([a, d, c], 1)])
    return v, f


def grid_for_edges(edges: int) -> int:
    """The side n whose grid has about ``edges`` unique edges (3 (n-1)^2 + 2 (n-1))."""
    return max(2, int(round((edges / 3) ** 0.5)) + 1)


def grid_for_faces(faces: int) -> int:
    return max(2, int(round((faces / 2) ** 0.5)) + 1)


def make_mesh(name: str):
    """``(vertices (N, 3), faces (F, 3))`` of a named mesh (module docstring)."""
    import numpy as np
    import trimesh

    if name == "soup50k":
        rng = np.random.default_rng(SEED)
        v = rng.uniform(-1.0, 1.0, (50_000 * 3, 3))
        return v, np.arange(len(v)).reshape(-1, 3)
    if name.startswith("sphere") or name.startswith("ico"):
        s = {"sphere327k": 7, "ico20k": 5}[name]
        m = trimesh.creation.icosphere(subdivisions=s)
        return np.asarray(m.vertices), np.asarray(m.faces)
    if name.startswith("grid"):
        return grid_faces(grid_for_faces(int(name[4:-1]) * 1000))
    if name.startswith("sweep"):
        return grid_faces(grid_for_edges(int(float(name[5:]))))
    raise ValueError(name)


def write_mesh(name: str, folder: Path) -> tuple[Path, int, int]:
    """The mesh as binary PLY in ``folder``: ``(path, faces, unique edges)``."""
    import numpy as np
    import trimesh

    v, f = make_mesh(name)
    path = folder / f"{name}.ply"
    if not path.exists():
        trimesh.Trimesh(v, f, process=False).export(path)
    e = np.sort(f[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
    n_edges = len(np.unique(e[:, 0].astype(np.int64) * len(v) + e[:, 1]))
    return path, len(f), n_edges


# ---------------------------------------------------------------- children (one measurement each)
def peak_rss_bytes() -> int:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


def child_wirecheck(path: str, t_start: float) -> dict:
    os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa")
    from wirecheck.core.scene.files import load_scene
    from wirecheck.oracles.candidates.core_candidate import CoreCandidate
    from wirecheck.oracles.runner import run_crosscheck

    t0 = time.perf_counter()
    scene = load_scene(path)
    t_load = time.perf_counter() - t0
    t0 = time.perf_counter()
    report, _images = run_crosscheck([scene], CoreCandidate(), frames=1, case_names=["on_axis"], animation=False)
    t_case = time.perf_counter() - t0
    case = report["cases"][0]
    tm = report["timing"]
    return {
        "load_s": t_load,
        "case_s": t_case,
        "verdict": case.get("verdict"),
        "pixel_stage_ms": tm.get("pixel_stage_ms_per_frame"),
        "pixel_metrics_ms": tm.get("pixel_metrics_ms_per_frame"),
        "pyrender_in_ms": tm.get("pyrender_ms_per_frame"),
        "pyrender_wait_ms": tm.get("pyrender_wait_ms_per_frame"),
        "draw_ms": tm.get("candidate_draw_ms_per_frame"),
        "wall_s": time.perf_counter() - t_start,
        "peak_rss": peak_rss_bytes(),
    }


def child_pyrender(path: str, t_start: float) -> dict:
    """As a pyrender user would draw the mesh's edges: one frame, on_axis's camera distance and FOV."""
    os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa")
    import math

    import numpy as np
    import pyrender
    import trimesh

    renderer = pyrender.OffscreenRenderer(WIDTH, HEIGHT)
    scene = pyrender.Scene(bg_color=[0, 0, 0, 1], ambient_light=[0, 0, 0])
    white = pyrender.MetallicRoughnessMaterial(baseColorFactor=[1.0, 1.0, 1.0, 1.0])
    warm = pyrender.Primitive(
        positions=np.array([[0, 0, 0], [1, 1, 0]], np.float32),
        indices=np.array([[0, 1]], np.uint32),
        mode=pyrender.constants.GLTF.LINES,
        material=white,
    )
    warm_node = scene.add(pyrender.Mesh([warm]))
    pose = np.eye(4)
    pose[2, 3] = 3.0
    cam_node = scene.add(
        pyrender.PerspectiveCamera(yfov=math.radians(60), aspectRatio=WIDTH / HEIGHT, znear=0.05, zfar=10.0), pose=pose
    )
    renderer.render(scene, flags=pyrender.RenderFlags.FLAT)  # the shaders compiled, as wirecheck's warm-up
    t0 = time.perf_counter()
    mesh = trimesh.load(path, process=False)
    v = np.asarray(mesh.vertices, np.float64)
    centre = (v.max(axis=0) + v.min(axis=0)) / 2
    radius = float(np.linalg.norm(v - centre, axis=1).max())
    edges = mesh.edges_unique.astype(np.uint32)
    load = time.perf_counter() - t0
    scene.remove_node(warm_node)
    prim = pyrender.Primitive(
        positions=(v - centre).astype(np.float32), indices=edges, mode=pyrender.constants.GLTF.LINES, material=white
    )
    scene.add(pyrender.Mesh([prim]))
    pose[2, 3] = 3.0 * radius
    scene.remove_node(cam_node)
    scene.add(
        pyrender.PerspectiveCamera(
            yfov=math.radians(60), aspectRatio=WIDTH / HEIGHT, znear=0.05 * radius, zfar=10 * radius
        ),
        pose=pose,
    )
    t0 = time.perf_counter()
    color, _ = renderer.render(scene, flags=pyrender.RenderFlags.FLAT)  # the mesh uploaded and drawn
    draw = time.perf_counter() - t0
    t0 = time.perf_counter()
    renderer.render(scene, flags=pyrender.RenderFlags.FLAT)  # a frame of a run: drawn only
    redraw = time.perf_counter() - t0
    drawn = int((color[:, :, 0] > 0).sum())
    renderer.delete()
    return {
        "load_s": load,
        "draw_ms": 1e3 * draw,
        "redraw_ms": 1e3 * redraw,
        "drawn_px": drawn,
        "wall_s": time.perf_counter() - t_start,
        "peak_rss": peak_rss_bytes(),
    }


def measure(side: str, path: Path, timeout: float) -> dict:
    """One fresh interpreter measuring ``side`` on ``path``; its JSON line, or ``{"error": ...}``."""
    t0 = time.perf_counter()
    try:
        proc = subprocess.run(
            [sys.executable, str(Path(__file__)), "--child", side, str(path)],
            cwd=ROOT,
            capture_output=True,
            text=True,
            timeout=timeout,
        )
    except subprocess.TimeoutExpired:
        return {"error": f"over {timeout:.0f} s"}
    wall = time.perf_counter() - t0
    lines = [ln for ln in proc.stdout.splitlines() if ln.startswith("{")]
    if proc.returncode != 0 or not lines:
        return {"error": (proc.stderr.strip().splitlines() or [f"exit {proc.returncode}"])[-1][:160]}
    out = json.loads(lines[-1])
    out["process_s"] = wall  # the process as the parent saw it: start-up and imports included
    return out


# ---------------------------------------------------------------- the table
def mesh_names(quick: bool, only: list[str] | None) -> list[str]:
    sweep = [f"sweep1e{k}" for k in ((2, 3, 4, 5) if quick else (2, 3, 4, 5, 6))]
    names = ["soup50k", "sphere327k", "ico20k", "grid40k", "grid60k"] + sweep + ["grid1000k"]
    if quick:
        names = ["soup50k", "sphere327k", "ico20k", "grid60k"] + sweep + ["grid1000k"]
    return [n for n in names if not only or n in only]


def gib(b) -> str:
    return "-" if b is None else f"{b / GIB:.2f}"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="fewer meshes (a few minutes on 2 cores)")
    ap.add_argument("--only", default=None, help="comma-separated mesh names to run (default: all)")
    ap.add_argument("--timeout", type=float, default=600.0, help="seconds one measurement may take (default 600)")
    ap.add_argument("--json", default=None, help="also write the rows as JSON to this file")
    ap.add_argument("--plot", default=None, help="the sweep's time and memory against edges as a PNG")
    ap.add_argument("--label", default="", help="a label for this run in the table's title (e.g. before)")
    ap.add_argument(
        "--baseline",
        default=None,
        metavar="JSON",
        help="an earlier run's --json (e.g. before a change): its sweep drawn beside this one's in --plot",
    )
    ap.add_argument("--child", nargs=2, metavar=("SIDE", "PATH"), help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.child:
        t_start = time.perf_counter()
        side, path = args.child
        print(json.dumps((child_wirecheck if side == "wirecheck" else child_pyrender)(path, t_start)))
        return 0

    sys.path.insert(0, str(HERE))
    from _common import machine_info, print_end, print_machine, print_table, verdict, write_json

    info = machine_info(benchmark="bench_pixel_scale", label=args.label)
    print_machine(f"bench_pixel_scale {args.label}".strip(), info)
    t_start = time.perf_counter()
    rows = []
    with tempfile.TemporaryDirectory(prefix="wirecheck-pixel-scale-") as tmp:
        for name in mesh_names(args.quick, args.only.split(",") if args.only else None):
            path, n_faces, n_edges = write_mesh(name, Path(tmp))
            wc = measure("wirecheck", path, args.timeout)
            pr = measure("pyrender", path, args.timeout)
            rows.append({"mesh": name, "faces": n_faces, "edges": n_edges, "wirecheck": wc, "pyrender": pr})
            print(f"  {name}: done", flush=True)
    header = (
        f"{'mesh':<11} {'faces':>9} {'edges':>9} | {'load s':>7} {'stage ms':>9} {'metrics ms':>10} "
        f"{'wall s':>7} {'RSS GiB':>7} {'verdict':>7} | {'pr draw ms':>10} {'pr wall s':>9} {'pr GiB':>6} "
        f"| {'stage/draw':>10} {'wall/wall':>9}"
    )

    def fmt(r):
        wc, pr = r["wirecheck"], r["pyrender"]
        if "error" in wc or "error" in pr:  # a side that failed or ran out of time: what it said
            return f"{r['mesh']:<11} {r['faces']:>9} {r['edges']:>9} | wirecheck: {wc.get('error', 'ok')}; pyrender: {pr.get('error', 'ok')}"
        return (
            f"{r['mesh']:<11} {r['faces']:>9} {r['edges']:>9} | {wc['load_s']:>7.2f} {wc['pixel_stage_ms']:>9.1f} "
            f"{wc['pixel_metrics_ms']:>10.1f} {wc['process_s']:>7.2f} {gib(wc['peak_rss']):>7} {wc['verdict']:>7} | "
            f"{pr['draw_ms']:>10.1f} {pr['process_s']:>9.2f} {gib(pr['peak_rss']):>6} | "
            f"{wc['pixel_stage_ms'] / pr['draw_ms']:>10.2f} {wc['process_s'] / pr['process_s']:>9.2f}"
        )

    print()
    print_table("One frame (on_axis, 640x480), each side in a fresh process", header, [fmt(r) for r in rows])
    by = {r["mesh"]: r for r in rows if "error" not in r["wirecheck"] and "error" not in r["pyrender"]}
    targets = []
    for name in ("soup50k", "sphere327k"):
        if name in by:
            wc, pr = by[name]["wirecheck"], by[name]["pyrender"]
            ratio = wc["process_s"] / pr["process_s"]
            targets.append(
                (
                    f"{name}: process {ratio:.2f}x pyrender's (<= {SOUP_TIME_RATIO:g}x), peak "
                    f"{gib(wc['peak_rss'])} GiB (< {SOUP_RSS_GIB:g})",
                    ratio <= SOUP_TIME_RATIO and wc["peak_rss"] < SOUP_RSS_GIB * GIB,
                )
            )
    for name in ("ico20k", "grid40k", "grid60k"):
        if name in by:
            wc, pr = by[name]["wirecheck"], by[name]["pyrender"]
            ratio = wc["pixel_stage_ms"] / pr["draw_ms"]
            targets.append(
                (
                    f"{name}: pixel stage {ratio:.2f}x pyrender's draw (<= {MESH_STAGE_RATIO:g}x)",
                    ratio <= MESH_STAGE_RATIO,
                )
            )
    if "grid1000k" in by:
        wc = by["grid1000k"]["wirecheck"]
        targets.append(
            (
                f"grid1000k ({by['grid1000k']['faces']} faces): peak {gib(wc['peak_rss'])} GiB (< {MILLION_RSS_GIB:g})",
                wc["peak_rss"] < MILLION_RSS_GIB * GIB,
            )
        )
    for text, ok in targets:
        print(f"  {verdict(ok)}  {text}")
    if args.plot:
        baseline = None
        if args.baseline:
            data = json.loads(Path(args.baseline).read_text())
            baseline = (data["machine"].get("label") or "baseline", data["rows"])
        plot(rows, args.plot, args.label, baseline)
    info["elapsed_s"] = print_end(info, t_start)
    if args.json:
        write_json(args.json, machine=info, rows=rows, targets=[{"target": t, "met": ok} for t, ok in targets])
    return 0


def plot(rows: list, png: str, label: str, baseline: tuple | None = None) -> None:
    """The height fields' (sweep and grid1000k) pixel stage and peak RSS against edges, wirecheck and pyrender (and ``baseline``'s wirecheck)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    def sweep(rs):
        return sorted(
            (
                r
                for r in rs
                if (r["mesh"].startswith("sweep") or r["mesh"] == "grid1000k")
                and "error" not in r["wirecheck"]
                and "error" not in r["pyrender"]
            ),
            key=lambda r: r["edges"],
        )

    fig, (a, b) = plt.subplots(1, 2, figsize=(10, 4))
    runs = [(label or "wirecheck", sweep(rows), "o-")] + ([(baseline[0], sweep(baseline[1]), "o:")] if baseline else [])
    for name, rs, style in runs:
        e = [r["edges"] for r in rs]
        a.loglog(e, [r["wirecheck"]["pixel_stage_ms"] for r in rs], style, label=f"wirecheck pixel stage ({name})")
        b.loglog(e, [r["wirecheck"]["peak_rss"] / 2**20 for r in rs], style, label=f"wirecheck process ({name})")
    rs = sweep(rows)
    e = [r["edges"] for r in rs]
    a.loglog(e, [r["pyrender"]["draw_ms"] for r in rs], "s--", label="pyrender draw")
    b.loglog(e, [r["pyrender"]["peak_rss"] / 2**20 for r in rs], "s--", label="pyrender process")
    a.set_xlabel("edges")
    a.set_ylabel("ms, one frame")
    b.set_xlabel("edges")
    b.set_ylabel("peak RSS (MiB)")
    a.legend(fontsize=8)
    b.legend(fontsize=8)
    fig.suptitle("One frame at 640x480, height-field meshes of 10^2 to 1.5x10^6 edges (sweep and grid1000k)")
    fig.tight_layout()
    fig.savefig(png, dpi=80)
    print(f"wrote {png}")


if __name__ == "__main__":
    sys.exit(main())
