#!/usr/bin/env python
"""Peak memory of a dataset run at 40 and 320 meshes: does it grow with the work?

Run from the repo root::

    .venv/bin/python benchmarks/bench_memory.py                    # about 2 minutes on 2 cores
    .venv/bin/python benchmarks/bench_memory.py --as-shipped       # pyrender's own program cache (the leak)
    .venv/bin/python benchmarks/bench_memory.py --json out.json

Each size runs in a fresh process (``crosscheck``'s library call,
:func:`oracles.datasets.dataset_run.run_dataset`, ``jobs 1``, the core candidate at
the pixel level): ``N`` copies of one 4-face mesh (a tetrahedron, OBJ) in a
temporary folder, ``--cases`` cameras x ``--frames`` frames each, so the
320-mesh run draws 8x the frames of the 40-mesh one with the same image
sizes. The child prints its own peak resident set (``VmHWM`` of
/proc/self/status). Target: the 320-mesh peak within 1.3x of the 40-mesh
peak (a run's memory does not grow with the work). ``--as-shipped`` undoes
:func:`oracles.references.pyrender_programs.stabilise_program_cache` in the child, to
show what the fix is worth (pyrender compiles a shader program per frame).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from _common import machine_info, print_end, print_machine  # noqa: E402

SIZES = (40, 320)
TARGET_RATIO = 1.3
TETRA_OBJ = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"

CHILD = r"""
import json, sys, time
if {as_shipped!r}:
    import wirecheck.oracles.references.pyrender_oracle as po
    po.stabilise_program_cache = lambda renderer: None
from wirecheck.oracles.candidates.core_candidate import CoreCandidate
from wirecheck.oracles.datasets.dataset import dataset_entries
from wirecheck.oracles.datasets.dataset_run import run_dataset
t0 = time.perf_counter()
report = run_dataset(dataset_entries([{folder!r}]), CoreCandidate(), frames={frames}, case_names={cases!r},
                     candidate_name="core")
wall = time.perf_counter() - t0
hwm = [l for l in open("/proc/self/status") if l.startswith("VmHWM:")][0].split()[1]
print(json.dumps({{"peak_rss_mb": int(hwm) / 1024, "wall_s": wall, "verdict": report["verdict"],
                  "passed": report["summary"]["passed"]}}))
"""


def run_size(n: int, frames: int, cases: list[str], as_shipped: bool) -> dict:
    with tempfile.TemporaryDirectory(prefix="bench_memory.") as tmp:
        for i in range(n):
            Path(tmp, f"tetra{i:04d}.obj").write_text(TETRA_OBJ)
        code = CHILD.format(folder=tmp, frames=frames, cases=cases, as_shipped=as_shipped)
        env = dict(os.environ, PYOPENGL_PLATFORM=os.environ.get("PYOPENGL_PLATFORM", "osmesa"))
        done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, cwd=ROOT)
        if done.returncode != 0:
            tail = (done.stderr.strip().splitlines() or ["(no stderr)"])[-1]
            raise SystemExit(f"bench_memory: the {n}-mesh run failed (exit {done.returncode}): {tail}")
        return json.loads(done.stdout.strip().splitlines()[-1])


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--frames", type=int, default=8, help="frames per case (default 8)")
    ap.add_argument("--cases", default="on_axis,orthographic", help="cameras per mesh (default on_axis,orthographic)")
    ap.add_argument("--as-shipped", action="store_true", help="pyrender's own program cache (shows the leak)")
    ap.add_argument("--json", default=None, help="also write the results as JSON to this file")
    args = ap.parse_args(argv)
    cases = args.cases.split(",")
    t_start = time.perf_counter()
    info = machine_info(frames=args.frames, cases=args.cases, as_shipped=args.as_shipped)
    print_machine("bench_memory: peak RSS of a dataset run at 40 and 320 meshes (core candidate, level pixels)", info)
    print(
        f"  {len(cases)} cameras ({args.cases}) x {args.frames} frames per mesh; "
        f"{'pyrender program cache as shipped' if args.as_shipped else 'program cache keyed by context address'}\n"
    )
    print(f"{'meshes':>7} {'frames':>7} {'peak MB':>9} {'wall s':>8}  verdict", flush=True)
    rows = {}
    for n in SIZES:
        r = rows[n] = run_size(n, args.frames, cases, args.as_shipped)
        print(
            f"{n:>7} {n * len(cases) * args.frames:>7} {r['peak_rss_mb']:>9.1f} {r['wall_s']:>8.1f}  "
            f"{r['verdict']} ({r['passed']}/{n})",
            flush=True,
        )
    ratio = rows[SIZES[1]]["peak_rss_mb"] / rows[SIZES[0]]["peak_rss_mb"]
    grow = (rows[SIZES[1]]["peak_rss_mb"] - rows[SIZES[0]]["peak_rss_mb"]) / (
        (SIZES[1] - SIZES[0]) * len(cases) * args.frames
    )
    ok = ratio <= TARGET_RATIO
    print(
        f"\npeak ratio {SIZES[1]}/{SIZES[0]}: {ratio:.2f}x (target <= {TARGET_RATIO}x: {'met' if ok else 'MISSED'}); "
        f"growth {grow * 1e3:.1f} kB per extra frame"
    )
    elapsed = print_end(info, t_start)
    if args.json:
        Path(args.json).write_text(
            json.dumps(
                {"machine": info, "runs": rows, "ratio": ratio, "growth_mb_per_frame": grow, "elapsed_s": elapsed},
                indent=2,
            )
        )
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
