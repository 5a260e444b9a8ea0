#!/usr/bin/env python
"""crosscheck's harness overhead: the harness's time per frame over the oracles' (issue 12, target <= 0.15).

Run from the repo root::

    .venv/bin/python benchmarks/bench_harness.py [--repeats 3] [--quick] [--json PATH]

Each repeat is the README's main job (``crosscheck``: every bundled scene, the
7 case cameras, 24 frames; ``--quick``: 8 frames) in this process, into a
temporary report folder (``--scene PATH [--cases ...]``: that scene instead,
e.g. a dense mesh, where the target does not hold: docs/performance.md). The ratio is the one the run writes into
``report.json`` (``timing.harness_overhead_ratio``; its definition:
docs/performance.md#harness-overhead), so both sides are measured in the same
run, frame by frame; the median over the repeats is the result. The harness
is broken down by wrapping some of its functions (``PARTS``) in timers
here, which the report does not do. Also printed: the per-run costs the per-frame ratio leaves out (set-up,
reports and plots), from the process's wall time.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import statistics
import sys
import tempfile
import time
from collections import defaultdict
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from _common import machine_info, print_end, print_machine  # noqa: E402

TARGET = 0.15

#: (module attribute to wrap, label): the harness's parts, timed in this process only
PARTS = (
    ("wirecheck.oracles.judge.case:oface.frame_geometry", "oracle-side geometry (scipy model matrix)"),
    ("wirecheck.oracles.judge.case:oracle_segments", "oracle's segments (depth clip + OpenCV of the ends)"),
    ("wirecheck.oracles.judge.metrics:vertex_errors_frames", "vertex metrics (errors, scale; per case)"),
    ("wirecheck.oracles.judge.case:ScaleBatch.flush", "vertex metrics (errors, scale; per case)"),
    ("wirecheck.oracles.judge.metrics:FramePixels.__init__", "pixel metrics (scan + F1)"),
    ("wirecheck.oracles.judge.metrics:pixel_scores", "pixel metrics (scan + F1)"),
    ("wirecheck.oracles.judge.metrics:LineBatch.add", "line metrics (batched per case)"),
    ("wirecheck.oracles.judge.metrics:LineBatch.flush", "line metrics (batched per case)"),
)
LABELS = tuple(dict.fromkeys(label for _, label in PARTS))


#: labels being timed now (LineBatch.add calls LineBatch.flush: timed once)
_ACTIVE: set = set()


def _wrap(spec: str, seconds: dict, label: str) -> None:
    import importlib

    module_name, attr = spec.split(":")
    owner = importlib.import_module(module_name)
    *path, name = attr.split(".")
    for p in path:
        owner = getattr(owner, p)
    inner = getattr(owner, name)

    def timed(*args, **kwargs):
        if label in _ACTIVE:  # called inside another timed part of the same label
            return inner(*args, **kwargs)
        _ACTIVE.add(label)
        t = time.perf_counter()
        try:
            return inner(*args, **kwargs)
        finally:
            seconds[label] += time.perf_counter() - t
            _ACTIVE.discard(label)

    setattr(owner, name, timed)


def run_once(frames: int, seconds: dict, scene_args: list | None = None) -> dict:
    """One crosscheck of the bundled scenes; its report's timing and the process's view of it."""
    from wirecheck.oracles import cli

    before = dict(seconds)
    with tempfile.TemporaryDirectory() as tmp:
        t = time.perf_counter()
        with contextlib.redirect_stdout(io.StringIO()):
            code = cli.main([*(scene_args or []), "--frames", str(frames), "--report-dir", str(Path(tmp) / "run")])
        wall = time.perf_counter() - t
        if code != 0:
            raise SystemExit(
                f"bench_harness: crosscheck exited {code} on {scene_args or 'the bundled scenes'} (expected 0)"
            )
        report = json.loads((Path(tmp) / "run" / "report.json").read_text())
    timing = report["timing"]
    n = sum(c["frames_timed"] for c in timing["cases"])
    if n == 0:
        raise SystemExit("bench_harness: the run timed no frame")
    parts = {k: 1e3 * (seconds[k] - before.get(k, 0.0)) / n for k in seconds}
    return {"frames": n, "wall_s": wall, "run_s": timing["wall_s"], "timing": timing, "parts_ms_per_frame": parts}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=3, help="crosscheck runs (default 3)")
    ap.add_argument("--quick", action="store_true", help="8 frames per case instead of 24")
    ap.add_argument("--json", type=Path, help="also write the results here")
    ap.add_argument(
        "--scene",
        metavar="PATH",
        help="a mesh or scene file instead of the bundled scenes (e.g. a dense mesh: the target is "
        "set for the bundled scenes)",
    )
    ap.add_argument("--cases", help="crosscheck --cases (default: crosscheck's)")
    args = ap.parse_args(argv)
    if args.repeats < 1:
        ap.error("--repeats: expected an integer >= 1")
    frames = 8 if args.quick else 24
    t_start = time.perf_counter()
    info = machine_info(frames=frames, repeats=args.repeats)
    print_machine("crosscheck harness overhead", info)

    seconds = defaultdict(float)
    for spec, label in PARTS:
        _wrap(spec, seconds, label)
    scene_args = (["--scene", args.scene] if args.scene else []) + (["--cases", args.cases] if args.cases else [])
    runs = [run_once(frames, seconds, scene_args) for _ in range(args.repeats)]

    keys = (
        "harness_ms_per_frame",
        "oracles_ms_per_frame",
        "opencv_ms_per_frame",
        "pyrender_ms_per_frame",
        "candidate_ms_per_frame",
        "harness_overhead_ratio",
    )
    print(f"\n{'run':>4}  " + "  ".join(f"{k.replace('_ms_per_frame', ' ms/frame'):>22}" for k in keys))
    for i, r in enumerate(runs, 1):
        print(f"{i:>4}  " + "  ".join(f"{r['timing'][k]:>22.4f}" for k in keys))
    med = {k: statistics.median(r["timing"][k] for r in runs) for k in keys}
    print(f"{'med':>4}  " + "  ".join(f"{med[k]:>22.4f}" for k in keys))

    print("\nharness, by part (ms/frame, median over runs; timers added by this benchmark):")
    for label in LABELS:
        print(f"  {label:55s} {statistics.median(r['parts_ms_per_frame'][label] for r in runs):8.3f}")
    print(
        f"  {'(the rest: bookkeeping, images kept for the report)':55s} "
        f"{med['harness_ms_per_frame'] - sum(statistics.median(r['parts_ms_per_frame'][l] for r in runs) for l in LABELS):8.3f}"
    )

    run_s = statistics.median(r["run_s"] for r in runs)
    wall_s = statistics.median(r["wall_s"] for r in runs)
    print(
        f"\nper run, outside the per-frame ratio: {wall_s - run_s:.2f} s of {wall_s:.2f} s "
        "(validating inputs, writing report.json/.md/.html and the plots)"
    )
    ratio = med["harness_overhead_ratio"]
    print(f"\nharness_overhead_ratio {ratio:.3f} (target <= {TARGET}: {'met' if ratio <= TARGET else 'NOT met'})")
    print_end(info, t_start)
    if args.json:
        args.json.write_text(
            json.dumps(
                {
                    "machine": info,
                    "median": med,
                    "runs": [
                        {k: v for k, v in r.items() if k != "timing"} | {"timing": {k: r["timing"][k] for k in keys}}
                        for r in runs
                    ],
                },
                indent=1,
            )
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
