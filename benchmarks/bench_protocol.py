#!/usr/bin/env python
"""Per-frame cost of a candidate behind the candidate protocol, against the same projector in-process.

Run from the repo root (the three.js row needs ``npm ci`` in tests/clients/three)::

    .venv/bin/python benchmarks/bench_protocol.py [--quick] [--json PATH]

Candidates, each called through :func:`oracles.candidates.candidate.call_candidate` as
crosscheck calls it (the answer checked against the contract):

* ``in-process``  ``core.projector.projection.project_points``, a Python callable in this process
* ``python-host`` the same function run isolated (``python -m wirecheck.oracles.candidates.candidate_host``)
* ``c``           tests/clients/candidate.c built with ``cc -O2``
* ``three.js``    tests/clients/three/candidate.mjs on node (if node and three are installed)
* ``null``, ``null-host``: a projector that returns zeros, in-process and in the
  host: their difference is the transport alone (pipe, encoding, the host's
  own contract check), without any projection

Workloads:

* ``frame``: what one frame of a pixel-level crosscheck asks of a candidate,
  on every bundled scene under every case camera (frame 1 of the motion): one
  request with the scene's vertices and one with the depth-clipped ends of its
  edges (oracles.candidates.draw). Per implementation, the median over all (scene, case)
  pairs of the median of ``repeats`` timings.
* ``1M``: one request of 1,000,000 random points in front of the oblique camera:
  median of ``repeats``.

"overhead" = the implementation's time minus in-process's (for ``null-host``:
minus ``null``'s), measured in the same run. The garbage collector is disabled while timing.
"""

from __future__ import annotations

import argparse
import gc
import json
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

import numpy as np  # noqa: E402
from wirecheck.core.projector.projection import project_points  # noqa: E402
from wirecheck.core.scene.files import builtin_names, load_scene  # noqa: E402
from wirecheck.core.transforms import Motion  # noqa: E402
from wirecheck.oracles.candidates.candidate import call_candidate  # noqa: E402
from wirecheck.oracles.candidates.draw import clip_depth  # noqa: E402
from wirecheck.oracles.candidates.subprocess_candidate import SubprocessCandidate  # noqa: E402
from wirecheck.oracles.cases import cameras_for  # noqa: E402
from wirecheck.oracles.references import faces as oface  # noqa: E402


def _median_time(fn, repeats: int) -> float:
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def candidates(workdir: Path) -> dict:
    out = {
        "in-process": project_points,
        "python-host": SubprocessCandidate.python("wirecheck.core.projector.projection:project_points", timeout_s=120),
    }
    null = workdir / "null_projector.py"
    null.write_text("import numpy as np\ndef null(p, c):\n    return np.zeros((len(p), 2))\n")
    out["null"] = lambda p, c: np.zeros((len(p), 2))
    out["null-host"] = SubprocessCandidate.python(f"{null}:null", timeout_s=120)
    cc = shutil.which("cc")
    if cc:
        exe = workdir / "candidate"
        subprocess.run([cc, "-O2", "-o", str(exe), str(ROOT / "tests/clients/candidate.c"), "-lm"], check=True)
        out["c"] = SubprocessCandidate(argv=(str(exe),), timeout_s=120)
    node = shutil.which("node")
    if node and (ROOT / "tests/clients/three/node_modules/three").is_dir():
        out["three.js"] = SubprocessCandidate(
            argv=(node, str(ROOT / "tests/clients/three/candidate.mjs")), timeout_s=120
        )
    return out


def frame_requests() -> list:
    """[(p_vertices, p_edge_ends, camera)] for every bundled scene and case, frame 1."""
    motion = Motion()
    out = []
    for name in builtin_names():
        scene = load_scene(name)
        p_world = oface.frame_geometry(scene, motion, 0.0)[0]
        edges = np.asarray(scene.edges)
        for case in cameras_for(scene.radius):
            _, ends = clip_depth(p_world[edges[:, 0]], p_world[edges[:, 1]], case.camera)
            out.append((p_world, ends.reshape(-1, 3), case.camera))
    return out


def run(quick: bool) -> dict:
    repeats = 5 if quick else 31
    with tempfile.TemporaryDirectory() as tmp:
        cands = candidates(Path(tmp))
        requests = frame_requests()
        cam_1m = cameras_for(1.0)[1].camera
        p_1m = np.random.default_rng(0).uniform(-1, 1, (1_000_000, 3))
        for func in cands.values():  # start the programs (and warm numpy) outside the timing
            call_candidate(func, requests[0][0], requests[0][2])
        gc.disable()
        try:
            result = {}
            for name, func in cands.items():
                per_pair = [
                    _median_time(lambda: (call_candidate(func, pv, cam), call_candidate(func, pe, cam)), repeats)
                    for pv, pe, cam in requests
                ]
                t_1m = _median_time(lambda: call_candidate(func, p_1m, cam_1m), max(3, repeats // 6))
                result[name] = {"frame_ms": 1e3 * statistics.median(per_pair), "1M_ms": 1e3 * t_1m}
        finally:
            gc.enable()
            for func in cands.values():
                if isinstance(func, SubprocessCandidate):
                    func.close()
    for name, r in result.items():
        base = result["null" if name.startswith("null") else "in-process"]
        r["frame_overhead_ms"] = r["frame_ms"] - base["frame_ms"]
        r["1M_overhead_ms"] = r["1M_ms"] - base["1M_ms"]
    return {"repeats": repeats, "pairs": len(requests), "results": result}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="fewer repeats")
    ap.add_argument("--json", default=None, help="also write the numbers here")
    args = ap.parse_args(argv)
    out = run(args.quick)
    print(f"candidate protocol cost ({out['pairs']} scene/case frames, median of {out['repeats']} repeats)")
    print(f"{'candidate':<12} {'ms/frame':>9} {'overhead':>9} {'1M pts ms':>10} {'overhead':>9}")
    for name, r in out["results"].items():
        print(
            f"{name:<12} {r['frame_ms']:9.3f} {r['frame_overhead_ms']:+9.3f} {r['1M_ms']:10.1f} "
            f"{r['1M_overhead_ms']:+9.1f}"
        )
    if args.json:
        Path(args.json).write_text(json.dumps(out, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
