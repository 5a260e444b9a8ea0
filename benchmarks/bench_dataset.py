#!/usr/bin/env python
"""Meshes per second of a dataset run (``crosscheck --scene DIR``) on 1 and 2 processes and a 2-worker Dask cluster.

Run from the repo root::

    .venv/bin/python benchmarks/bench_dataset.py                 # 200 meshes, about 3 minutes on 2 cores
    .venv/bin/python benchmarks/bench_dataset.py --meshes 40     # CI's size
    .venv/bin/python benchmarks/bench_dataset.py --json out.json

The dataset is generated into a temporary folder: trimesh primitives (box,
icosphere, cylinder, cone, capsule, torus) of varied sizes and resolutions,
origin-centred, written as OBJ, PLY, STL and OFF in turn (seeded: the same
files every run). Each mesh is checked by the core candidate at the pixel
level under a stated budget (default 2 cameras x 2 frames: ``--cases``,
``--frames``), as ``crosscheck`` would check it, by the library call the CLI
makes (:func:`oracles.datasets.dataset_run.run_dataset`) with three executors:

* ``jobs 1``: in this process;
* ``jobs 2``: a process pool of 2 spawn workers;
* ``dask 2``: a Dask ``LocalCluster`` of 2 worker processes on 127.0.0.1;
* ``cluster`` (with ``--scheduler tcp://HOST:PORT``): a running Dask cluster's
  workers (the temporary folder must be on a file system they share: set
  ``TMPDIR`` to it).

Meshes per second count from the moment the workers are ready; a pool's or a
cluster's start is printed apart (``startup``). The per-mesh cost is the jobs-1
time divided by the meshes; the wall time for 10,000 meshes on N workers is
extrapolated from it two ways: ideal (cost x 10,000 / N) and at the parallel
efficiency measured here with 2 workers (a 2-core machine shared with the
parent: a lower bound for machines with a core per worker). The three reports
are compared apart from timing, and the benchmark says whether they agree.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

import numpy as np  # noqa: E402
from _common import machine_info, print_end, print_machine  # noqa: E402

SUFFIXES = (".obj", ".ply", ".stl", ".off")
EXTRAPOLATE_MESHES = 10_000
EXTRAPOLATE_WORKERS = (1, 2, 8, 32, 128)


def make_dataset(folder: Path, n: int, seed: int = 12) -> list[tuple[str, int]]:
    """``n`` origin-centred trimesh primitives of varied size and resolution in ``folder``: ``[(name, vertices)]``."""
    import trimesh

    rng = np.random.default_rng(seed)
    makers = [
        lambda s, k: trimesh.creation.box(extents=s * rng.uniform(0.5, 2.0, 3)),
        lambda s, k: trimesh.creation.icosphere(subdivisions=int(k % 4), radius=s),
        lambda s, k: trimesh.creation.cylinder(radius=s, height=s * rng.uniform(0.5, 3), sections=8 + 8 * int(k % 6)),
        lambda s, k: trimesh.creation.cone(radius=s, height=s * rng.uniform(0.5, 3), sections=8 + 8 * int(k % 6)),
        lambda s, k: trimesh.creation.capsule(radius=s / 2, height=s, count=[8 + 4 * int(k % 4)] * 2),
        lambda s, k: trimesh.creation.torus(
            major_radius=s, minor_radius=s / 4, major_sections=12 + 4 * int(k % 5), minor_sections=8
        ),
    ]
    out = []
    for i in range(n):
        mesh = makers[i % len(makers)](float(10 ** rng.uniform(-1, 2)), i // len(makers))
        mesh.apply_translation(-mesh.bounds.mean(axis=0))  # origin-centred (cameras look at the origin)
        name = f"{i:04d}{SUFFIXES[(i // len(makers)) % len(SUFFIXES)]}"
        mesh.export(folder / name)
        out.append((name, len(mesh.vertices)))
    return out


def run(dataset, spec, frames: int, cases: str) -> dict:
    from wirecheck.oracles.candidates.core_candidate import CoreCandidate
    from wirecheck.oracles.datasets.dataset_run import run_dataset

    candidate = CoreCandidate()
    return run_dataset(dataset, candidate, frames=frames, case_names=cases, candidate_name="core", executor=spec)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--meshes", type=int, default=200, help="meshes in the generated dataset (default 200)")
    ap.add_argument("--frames", type=int, default=2, help="frames of the motion per case (default 2)")
    ap.add_argument("--cases", default="on_axis,orthographic", help="cameras per mesh (default on_axis,orthographic)")
    ap.add_argument("--json", default=None, help="also write the results as JSON to this file (default: none)")
    ap.add_argument(
        "--scheduler",
        default=None,
        metavar="tcp://HOST:PORT",
        help="also run on this Dask scheduler's cluster (its workers need the same wirecheck and the "
        "dataset's folder at the same path: docs/datasets.md) (default: none)",
    )
    args = ap.parse_args(argv)
    if args.meshes < 2 or args.frames < 1:
        ap.error("expected --meshes >= 2 and --frames >= 1")
    from wirecheck.oracles.datasets.dataset import dataset_entries
    from wirecheck.oracles.executors import ExecutorSpec

    t_start = time.perf_counter()
    info = machine_info(meshes=args.meshes, frames=args.frames, cases=args.cases)
    print_machine("bench_dataset: meshes per second of a dataset run (core candidate, level pixels)", info)
    n_cases = len(args.cases.split(","))
    print(f"  budget per mesh: {n_cases} cameras ({args.cases}) x {args.frames} frames, vertices and pixels")
    runs = {}
    with tempfile.TemporaryDirectory(prefix="bench_dataset.") as tmp:
        made = make_dataset(Path(tmp), args.meshes)
        sizes = [v for _, v in made]
        print(
            f"  dataset: {args.meshes} meshes ({', '.join(SUFFIXES)}), {min(sizes)}..{max(sizes)} vertices "
            f"(median {int(np.median(sizes))})\n"
        )
        dataset = dataset_entries([tmp])
        print(f"{'executor':<8} {'meshes/s':>9} {'speed-up':>9} {'startup s':>10} {'wall s':>8}  verdict", flush=True)
        rows = {}
        executors = [
            ("jobs 1", ExecutorSpec(jobs=1)),
            ("jobs 2", ExecutorSpec(jobs=2)),
            ("dask 2", ExecutorSpec(kind="dask", jobs=2)),
        ]
        if args.scheduler:
            executors.append(("cluster", ExecutorSpec(kind="dask", scheduler=args.scheduler)))
        for label, spec in executors:
            report = runs[label] = run(dataset, spec, args.frames, args.cases)
            t, base = report["timing"], runs["jobs 1"]["timing"]
            r = rows[label] = {
                "meshes_per_s": t["meshes_per_s"],
                "startup_s": t["startup_s"],
                "wall_s": t["wall_s"],
                "speedup": t["meshes_per_s"] / base["meshes_per_s"],
                "verdict": report["verdict"],
                "passed": report["summary"]["passed"],
            }
            print(
                f"{label:<8} {r['meshes_per_s']:>9.2f} {r['speedup']:>8.2f}x {r['startup_s']:>10.2f} "
                f"{r['wall_s']:>8.1f}  {r['verdict']} ({r['passed']}/{args.meshes} meshes)",
                flush=True,
            )
    base = runs["jobs 1"]["timing"]
    per_mesh_s = (base["wall_s"] - base["startup_s"]) / args.meshes
    not_passed = [
        f"{m['mesh']} ({m['verdict']}: " + "; ".join(r for c in m.get("cases", []) for r in c["reasons"]) + ")"
        for m in runs["jobs 1"]["meshes"]
        if m["verdict"] != "pass"
    ]
    if not_passed:  # a finding about core against the oracles, not about the executors
        print("not passed (core against the oracles): " + ", ".join(not_passed))
    stripped = [{k: v for k, v in r.items() if k != "timing"} for r in runs.values()]
    same = all(s == stripped[0] for s in stripped)
    print(f"\nreports apart from timing: {'identical' if same else 'DIFFERENT'} for {', '.join(runs)}")
    eff = rows["dask 2"]["speedup"] / 2
    print(
        f"\nper-mesh cost (jobs 1): {per_mesh_s * 1e3:.0f} ms; parallel efficiency of dask with 2 workers "
        f"here: {eff:.0%}"
    )
    print(f"extrapolated wall time for {EXTRAPOLATE_MESHES:,} meshes at this budget (plus the cluster's start):")
    print(f"{'workers':>8} {'ideal':>10} {'at ' + format(eff, '.0%'):>10}")
    extrapolated = {}
    for n in EXTRAPOLATE_WORKERS:
        ideal = EXTRAPOLATE_MESHES * per_mesh_s / n
        measured = ideal / (eff if n > 1 else 1.0)
        extrapolated[n] = {"ideal_s": ideal, "at_measured_efficiency_s": measured}
        print(f"{n:>8} {_hms(ideal):>10} {_hms(measured):>10}")
    elapsed = print_end(info, t_start)
    if args.json:
        Path(args.json).write_text(
            json.dumps(
                {
                    "machine": info,
                    "runs": rows,
                    "per_mesh_s": per_mesh_s,
                    "not_passed": not_passed,
                    "verdicts": {
                        m["mesh"]: {
                            "verdict": m["verdict"],
                            "cases": [
                                [c["camera"], c["verdict"], [f["name"] for f in c.get("faults", [])]]
                                for c in m.get("cases", [])
                            ],
                        }
                        for m in runs["jobs 1"]["meshes"]
                    },
                    "reports_identical": same,
                    "extrapolated": extrapolated,
                    "elapsed_s": elapsed,
                },
                indent=2,
            )
        )
    return 0 if same else 1


def _hms(seconds: float) -> str:
    h, rem = divmod(int(round(seconds)), 3600)
    m, s = divmod(rem, 60)
    return f"{h}:{m:02d}:{s:02d}"


if __name__ == "__main__":
    sys.exit(main())
