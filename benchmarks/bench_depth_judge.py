#!/usr/bin/env python
"""A filled-and-depth frame judged, against pyrender rendering it: time per frame and memory by run length.

Run from the repo root::

    .venv/bin/python benchmarks/bench_depth_judge.py --quick      # about a minute on 2 cores
    .venv/bin/python benchmarks/bench_depth_judge.py [--json PATH]

Scenes: the bundled cube, prism and pyramid, and ``ico20k`` (``trimesh.creation.icosphere(
subdivisions=5)``: 20,480 faces; without ``--quick`` also ``ico82k``, subdivisions 6: 81,920
faces), each read as crosscheck reads a file (``load_scene`` of a binary PLY); case ``on_axis``
(640x480; without ``--quick`` also ``oblique_roll``), frames 1..F of the scenes' spin (F = 3,
``--quick``; else 6).

Per frame, in one process, one pyrender context each side made before the clock starts:

Each frame is rendered and judged ``--repeat`` times (3), back to back, and each side's best time
kept (the machine's load slows both; the best is the least disturbed), then the median over frames.

* ``pyrender``: what the user pays anyway to have the frame: a warm ``pyrender.OffscreenRenderer``
  holding the mesh (``Mesh.from_trimesh``, one directional light), the frame's model matrix set as
  the node's pose, ``renderer.render(scene)`` returning colour and depth (timed: that call).
* the judging pieces, timed each: ``read_depth_map`` of the frame's map as a float32 ``.npy``
  (core's depth buffer, written before the clock starts, as a renderer under test would);
  ``reference_depth`` (oracles/judge/depth_reference.py: pyrender's single-sample depth read back
  and linearised, its bound, the undecided pixels); ``name_depth_faults``
  (oracles/diagnosis/depth_faults.py) on the correct map (a pass), on the map x1000 (``depth_scale``,
  a value model) and on the map with its rows flipped (``mirror_vertical``: no value model fits, so
  the pixel models are fitted too, the expensive path).

A frame judged = read + reference + naming; printed against pyrender's render of the same frame,
for the correct map and for the worst faulty one (the median over frames of each ratio). Target
(issue 35): within 2x. Memory: the whole judging (map written, read, reference, naming of the flipped
map) over runs of 1, 10 and 50 frames of ``ico20k``: the peak of traced allocations (``tracemalloc``,
numpy's included) above what was held before, and the process's peak RSS (frames 2 .. n + 1 of a
51-frame spin: frame 1 is the spin's start, where the flipped sphere passes); target: flat in the
number of frames (the 50-frame peak within 1.5x the 1-frame one).
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import sys
import tempfile
import time
import tracemalloc
from pathlib import Path

os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa")

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(Path(__file__).resolve().parent))

import numpy as np  # noqa: E402
from _common import loadavg, machine_info, print_end, print_machine  # noqa: E402

#: The issue's targets.
TIME_TARGET = 2.0
MEMORY_TARGET = 1.5
MESHES = {"ico20k": 5, "ico82k": 6}


def load_scenes(names, folder: Path):
    """Bundled names as they are; ``ico*`` written as binary PLY into ``folder`` and read back."""
    import trimesh
    from wirecheck.core.scene.files import load_scene

    out = []
    for name in names:
        if name in MESHES:
            path = folder / f"{name}.ply"
            m = trimesh.creation.icosphere(subdivisions=MESHES[name])
            m.export(path)
            out.append(load_scene(str(path)))
        else:
            out.append(load_scene(name))
    return out


class UserRender:
    """A pyrender user's renderer of one scene: the mesh uploaded once, a frame = a pose and a render."""

    def __init__(self, scene, camera):
        import pyrender
        import trimesh
        from wirecheck.oracles.references import faces as oface
        from wirecheck.oracles.references.convert import camera_to_pyrender

        tris, _ = oface.fan(scene.faces)
        self.renderer = pyrender.OffscreenRenderer(camera.width, camera.height)
        self.scene = pyrender.Scene(bg_color=[0, 0, 0, 1], ambient_light=[0.2, 0.2, 0.2])
        mesh = pyrender.Mesh.from_trimesh(trimesh.Trimesh(scene.vertices, tris, process=False), smooth=False)
        self.node = self.scene.add(mesh)
        pose, cam = camera_to_pyrender(camera)
        self.scene.add(cam, pose=pose)
        self.scene.add(pyrender.DirectionalLight(intensity=3.0), pose=pose)
        self.renderer.render(self.scene)  # shaders compiled, the mesh uploaded: warm

    def frame_s(self, model_matrix) -> float:
        self.scene.set_pose(self.node, model_matrix)
        t0 = time.perf_counter()
        colour, depth = self.renderer.render(self.scene)
        elapsed = time.perf_counter() - t0
        assert colour.shape[:2] == depth.shape and (depth > 0).any()  # it drew the mesh
        return elapsed

    def close(self):
        self.renderer.delete()


def core_map(scene, case, motion, k: int, frames: int) -> np.ndarray:
    """Core's depth buffer of frame ``k`` (NaN where empty): a correct renderer's map."""
    from wirecheck.core.scene.frames import SceneRenderer
    from wirecheck.oracles.cases import case_motion

    renderer = SceneRenderer(scene, case_motion(motion, case), frames, style="shaded")
    frame, _ = renderer.render(k, case.camera)
    return frame.depth_image


def judge_frame(oracle, scene, case, motion, k: int, frames: int, folder: Path, maps=("pass", "x1000", "flipped")):
    """Write frame ``k``'s maps (not timed), then time each judging piece: ``{piece: seconds}``, ``{map: names}``."""
    from wirecheck.oracles.candidates.depth_map import read_depth_map
    from wirecheck.oracles.diagnosis.depth_faults import name_depth_faults
    from wirecheck.oracles.judge.depth_reference import reference_depth

    cam = case.camera
    depth = core_map(scene, case, motion, k, frames).astype(np.float32)
    written = {"pass": depth, "x1000": depth * np.float32(1000.0), "flipped": depth[::-1]}
    paths = {}
    for name in maps:
        paths[name] = folder / f"{name}.npy"
        np.save(paths[name], written[name])
    times, names = {}, {}
    t0 = time.perf_counter()
    dm = read_depth_map(paths["pass"], cam.width, cam.height)
    times["read"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    ref = reference_depth(oracle, scene, case, motion, k, frames)
    times["reference"] = time.perf_counter() - t0
    compared, faces = ref.compared_depth(), ref.compared_faces()
    for name in maps:
        m = dm if name == "pass" else read_depth_map(paths[name], cam.width, cam.height)
        t0 = time.perf_counter()
        d = name_depth_faults(m.depth, compared, ref.bound, cam, m.encoding_bound(), faces=faces)
        times[f"name_{name}"] = time.perf_counter() - t0
        names[name] = d.verdict if d.passed else ",".join(d.names)
    return times, names


def timing_rows(scenes, case_names, frames: int, folder: Path, repeat: int) -> list[dict]:
    from wirecheck.core.transforms import Motion
    from wirecheck.oracles.cases import case_motion, cases_for
    from wirecheck.oracles.references import faces as oface
    from wirecheck.oracles.references.pyrender_oracle import PyrenderOracle

    motion = Motion(turns=(1.0, 1.0, 0.0))
    rows, oracles = [], {}
    for scene in scenes:
        for case in (c for c in cases_for(scene, motion) if c.name in case_names):
            cam = case.camera
            oracle = oracles.setdefault((cam.width, cam.height), PyrenderOracle(cam.width, cam.height))
            judge_frame(oracle, scene, case, motion, 1, frames, folder)  # warm: the mesh uploaded once
            user = UserRender(scene, cam)
            per = []
            for k in range(1, frames + 1):
                _p_world, _m, _v, pose = oface.frame_geometry(scene, case_motion(motion, case), (k - 1) / frames)
                render_s, times = float("inf"), {}
                for _ in range(repeat):  # best of ``repeat``, each side: the machine's load moves both
                    render_s = min(render_s, user.frame_s(pose))
                    got, names = judge_frame(oracle, scene, case, motion, k, frames, folder)
                    times = {key: min(v, times.get(key, float("inf"))) for key, v in got.items()}
                per.append((render_s, times, names))
            user.close()
            med = {key: statistics.median(t[key] for _, t, _ in per) for key in per[0][1]}
            render = statistics.median(r for r, _, _ in per)
            base = med["read"] + med["reference"]
            ratio_pass = statistics.median((t["read"] + t["reference"] + t["name_pass"]) / r for r, t, _ in per)
            ratio_worst = statistics.median(
                (t["read"] + t["reference"] + max(t["name_x1000"], t["name_flipped"])) / r for r, t, _ in per
            )
            rows.append(
                {
                    "scene": scene.name,
                    "faces": len(scene.faces),
                    "camera": case.name,
                    "frames": frames,
                    "pyrender_ms": 1e3 * render,
                    **{f"{k}_ms": 1e3 * v for k, v in med.items()},
                    "judged_pass_ms": 1e3 * (base + med["name_pass"]),
                    "ratio_pass": ratio_pass,
                    "ratio_worst": ratio_worst,
                    "names": sorted({n for _, _, ns in per for n in [f"{k}={v}" for k, v in ns.items()]}),
                }
            )
    for oracle in oracles.values():
        oracle.close()
    return rows


def memory_rows(scene, counts, folder: Path) -> list[dict]:
    """The whole judging over runs of ``n`` frames: traced peak above the start, and the process's peak RSS."""
    from wirecheck.core.transforms import Motion
    from wirecheck.oracles.cases import cases_for
    from wirecheck.oracles.references.pyrender_oracle import PyrenderOracle

    motion = Motion(turns=(1.0, 1.0, 0.0))
    case = next(c for c in cases_for(scene, motion) if c.name == "on_axis")
    oracle = PyrenderOracle(case.camera.width, case.camera.height)
    judge_frame(oracle, scene, case, motion, 1, 1, folder, maps=("flipped", "pass"))  # warm
    rows = []
    tracemalloc.start()
    for n in counts:
        held = tracemalloc.get_traced_memory()[0]
        tracemalloc.reset_peak()
        t0 = time.perf_counter()
        # frames 2 .. n + 1 of one spin of max(counts) + 1 frames (frame 1, the spin's start, is symmetric:
        # its flipped map passes without the pixel models): what a run keeps of each frame, its names
        kept = [
            judge_frame(oracle, scene, case, motion, k, max(counts) + 1, folder, maps=("flipped", "pass"))[1]
            for k in range(2, n + 2)
        ]
        peak = tracemalloc.get_traced_memory()[1] - held
        rows.append(
            {
                "frames": n,
                "traced_peak_mib": peak / 2**20,
                "seconds": time.perf_counter() - t0,
                "peak_rss_mib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
                "names": sorted({f"{k}={v}" for d in kept for k, v in d.items()}),
            }
        )
    tracemalloc.stop()
    oracle.close()
    return rows


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--quick", action="store_true", help="ico20k only, on_axis, 3 frames")
    p.add_argument("--json", metavar="PATH", help="write the numbers there")
    p.add_argument(
        "--repeat",
        type=int,
        default=3,
        metavar="R",
        help="each frame rendered and judged R times, the best time of each side kept (default 3)",
    )
    args = p.parse_args(argv)
    t_start = time.perf_counter()
    info = machine_info(quick=args.quick)
    print_machine("bench_depth_judge: a filled-and-depth frame judged vs pyrender rendering it", info)
    names = ["cube", "prism", "pyramid", "ico20k"] + ([] if args.quick else ["ico82k"])
    case_names = ("on_axis",) if args.quick else ("on_axis", "oblique_roll")
    frames = 3 if args.quick else 6
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        scenes = load_scenes(names, folder)
        rows = timing_rows(scenes, case_names, frames, folder, args.repeat)
        print(
            f"\nPer frame (median over {frames} frames of each side's best of {args.repeat}; ms): pyrender = "
            "renderer.render(scene), colour and depth, warm; judged = read + reference + naming"
        )
        head = (
            "scene",
            "faces",
            "camera",
            "pyrender",
            "read",
            "reference",
            "name ok",
            "name x1000",
            "name flip",
            "judged ok",
            "/pyrender ok",
            "/pyrender worst",
        )
        table = [head] + [
            (
                r["scene"],
                f"{r['faces']:,}",
                r["camera"],
                f"{r['pyrender_ms']:.1f}",
                f"{r['read_ms']:.1f}",
                f"{r['reference_ms']:.1f}",
                f"{r['name_pass_ms']:.1f}",
                f"{r['name_x1000_ms']:.1f}",
                f"{r['name_flipped_ms']:.1f}",
                f"{r['judged_pass_ms']:.1f}",
                f"{r['ratio_pass']:.2f}",
                f"{r['ratio_worst']:.2f}",
            )
            for r in rows
        ]
        widths = [max(len(t[i]) for t in table) for i in range(len(head))]
        for t in table:
            print("  " + "  ".join(v.rjust(w) for v, w in zip(t, widths)))
        for r in rows:
            print(f"  {r['scene']} / {r['camera']}: named {', '.join(r['names'])}")
        worst = max(r["ratio_worst"] for r in rows)
        worst_ok = max(r["ratio_pass"] for r in rows)
        print(
            f"\nTime target (judged within {TIME_TARGET:g}x pyrender's render): correct maps at most "
            f"{worst_ok:.2f}x, faulty maps at most {worst:.2f}x: "
            f"{'PASS' if max(worst, worst_ok) <= TIME_TARGET else 'FAIL'}"
        )
        mem_scene = next(s for s in scenes if s.name == "ico20k")
        mem = memory_rows(mem_scene, (1, 10, 50), folder)
    print(
        f"\nMemory over a run of n frames (ico20k / on_axis, the flipped map named each frame; "
        f"load {' '.join(loadavg() or [])}):"
    )
    for r in mem:
        print(
            f"  {r['frames']:>3} frames: traced peak {r['traced_peak_mib']:.1f} MiB above the start, "
            f"process peak RSS {r['peak_rss_mib']:.0f} MiB, {r['seconds']:.1f} s ({', '.join(r['names'])})"
        )
    growth = mem[-1]["traced_peak_mib"] / mem[0]["traced_peak_mib"]
    print(
        f"Memory target (50 frames' traced peak within {MEMORY_TARGET:g}x 1 frame's): {growth:.2f}x: "
        f"{'PASS' if growth <= MEMORY_TARGET else 'FAIL'}"
    )
    print_end(info, t_start)
    if args.json:
        Path(args.json).write_text(json.dumps({"machine": info, "frames": rows, "memory": mem}, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
