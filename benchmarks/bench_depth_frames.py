"""A job's depth maps (and filled frames) judged: the judge's time per frame against pyrender drawing it.

    .venv/bin/python benchmarks/bench_depth_frames.py                          # the cube, 12 frames, depth
    .venv/bin/python benchmarks/bench_depth_frames.py --scene ICOSPHERE.obj --outputs filled,depth --frames 24
    .venv/bin/python benchmarks/bench_depth_frames.py --scene cube --outputs filled,depth --repeat 3   # best of three

(``--scene`` takes a built-in name or a mesh file: README's icosphere(4) is
``trimesh.creation.icosphere(subdivisions=4).export('ICOSPHERE.obj')``.)

A job is exported (one scene, case ``oblique_roll``, every frame checked, ``--outputs``) and drawn by
core (tests/clients/core_depth_job.py: a correct renderer). In this process, its imports done and
pyrender's context made before any clock starts, and in this order on the same frames:

- **judge**: oracles.judge.frames_judge.run_frames, whole (the pre-check of every file, each frame's
  inputs, pyrender's faces on the GL thread read ahead, each map read and judged, each filled frame
  scored against the fill rule), per frame;
- **pyrender**: ``PyrenderOracle.render_faces(..., with_ids=True)`` of each frame alone, the drawing the
  judge asks for (faces, depth, triangle ids), per frame;
- **depth own**: the judge's own depth work on each frame given pyrender's drawing
  (oracles.judge.depth_frames.DepthFrames.add with the reference made from it), per frame.

Printed: the three times per frame, judge / pyrender (the issue's target: within 2x), and the load
average before and after (the machine is shared: state it with the numbers). ``--repeat N``: the judge
and pyrender's drawing each timed N times in turn, the best of each printed (a shared machine's
noise is all slower).
"""

from __future__ import annotations

import argparse
import shutil
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(Path(__file__).parent))
sys.path.insert(0, str(ROOT / "tests"))

from _common import loadavg  # noqa: E402


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scene", default="cube")
    p.add_argument("--frames", type=int, default=12)
    p.add_argument("--outputs", default="depth")
    p.add_argument("--repeat", type=int, default=1, help="time the judge and pyrender N times each: the best")
    args = p.parse_args(argv)

    from clients.core_depth_job import render_job
    from wirecheck.oracles.candidates.frames_candidate import frame_faces, frame_inputs, load_job
    from wirecheck.oracles.cli import main as crosscheck
    from wirecheck.oracles.judge.depth_frames import DepthFrames
    from wirecheck.oracles.judge.depth_reference import from_render
    from wirecheck.oracles.judge.frames_judge import run_frames
    from wirecheck.oracles.references.faces import fan
    from wirecheck.oracles.references.pyrender_oracle import OracleCache

    load_before = loadavg()
    tmp = Path(tempfile.mkdtemp(prefix="bench-depth-"))
    try:
        job_dir = tmp / "job"
        assert (
            crosscheck(
                [
                    "export",
                    str(job_dir),
                    "--scene",
                    args.scene,
                    "--cases",
                    "oblique_roll",
                    "--frames",
                    str(args.frames),
                    "--outputs",
                    args.outputs,
                ]
            )
            == 0
        )
        render_job(job_dir)
        job = load_job(job_dir)
        c = job["cases"][0]
        n = len(job["frame_numbers"])
        inputs = [frame_inputs(job_dir, job, c["scene"], c["case"], k) for k in job["frame_numbers"]]
        tris = [fan(frame_faces(job_dir, job, c["scene"], k))[0] for k in job["frame_numbers"]]
        run_frames(job_dir)  # warm: pyrender's context, its programs, imports
        oracles = OracleCache()
        cam = inputs[0][2]
        oracle = oracles.get(cam.width, cam.height)
        oracle.render_faces(inputs[0][0], tris[0], cam, model_matrix=inputs[0][3], with_ids=True)  # warm
        judge = pyrender = float("inf")
        for _ in range(max(1, args.repeat)):  # in turn: the judge, then pyrender alone
            t0 = time.perf_counter()
            report, _ = run_frames(job_dir)
            judge = min(judge, (time.perf_counter() - t0) / n)
            assert report["verdict"] == "pass", report["cases"][0]["reasons"]
            drawn = []
            t0 = time.perf_counter()
            for (p_model, _e, camera, m), t in zip(inputs, tris):
                drawn.append(oracle.render_faces(p_model, t, camera, model_matrix=m, with_ids=True))
            pyrender = min(pyrender, (time.perf_counter() - t0) / n)
        oracles.close()
        own = None
        if "depth" in args.outputs:
            depth = DepthFrames(job)
            t0 = time.perf_counter()
            for i, ((_p, _e, camera, _m), (covered, z, ids), t) in enumerate(zip(inputs, drawn, tris)):
                depth.add(
                    job["frame_numbers"][i], job_dir / c["depth"][i], camera, from_render(covered, z, ids, t, camera)
                )
            own = (time.perf_counter() - t0) / n
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    print(f"{args.scene}, oblique_roll, {n} frames of {cam.width}x{cam.height}, outputs {args.outputs}")
    best = f" (best of {args.repeat})" if args.repeat > 1 else ""
    print(f"  judge (run_frames, whole)      {judge * 1e3:8.1f} ms a frame{best}")
    print(f"  pyrender render_faces alone    {pyrender * 1e3:8.1f} ms a frame{best}")
    if own is not None:
        print(f"  depth own work (read + judge)  {own * 1e3:8.1f} ms a frame")
    print(f"  judge / pyrender: {judge / pyrender:.2f} (target <= 2)")
    print(
        f"  load average before {' '.join(load_before or ['?'])}, after {' '.join(loadavg() or ['?'])} "
        "(2 cores, shared)"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
