#!/usr/bin/env python
"""The seed command against its pyrender + Pillow peer, whole processes, in one run.

    .venv/bin/python benchmarks/bench_seed.py [--repeats 5] [--frames 180]

Times ``renderer --scene cube --frames 180 --camera-z 4.0 --fov 70`` (PNG
frames) and ``benchmarks/peer_seed_pyrender.py`` (the same frames drawn by
pyrender on OSMesa and saved by Pillow) as whole processes, imports included,
alternating which runs first. Prints the median wall time of each and their
ratio; target: ratio <= 0.15 (issue 12). The machine is shared and noisy: the
ratio of medians from interleaved runs is the figure, not either time alone.

Both run as installed code runs: with bytecode cached. One untimed run of
each comes first, and every run goes without ``PYTHONDONTWRITEBYTECODE``, so
wirecheck's modules (an editable install: compiled on first import) are not
compiled again in every timed run while the peer's libraries (pyrender,
trimesh, Pillow: compiled by pip) never are; with that variable set, compiling
core's modules was ~60 ms of a ~300 ms renderer run.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
TARGET_RATIO = 0.15


#: The runs' environment: this one, less PYTHONDONTWRITEBYTECODE (module docstring).
ENV = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}


def wall(cmd: list[str]) -> float:
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=ENV)
    return time.perf_counter() - t0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeats", type=int, default=5, help="interleaved runs of each (default 5)")
    ap.add_argument("--frames", type=int, default=180, help="frames per run (default 180)")
    args = ap.parse_args(argv)
    ours, peer = [], []
    with tempfile.TemporaryDirectory() as tmp:
        ours_cmd = [
            sys.executable,
            "-m",
            "wirecheck.core.app.cli",
            "--scene",
            "cube",
            "--frames",
            str(args.frames),
            "--camera-z",
            "4.0",
            "--fov",
            "70",
            "--out",
            f"{tmp}/ours",
        ]
        peer_cmd = [sys.executable, str(HERE / "peer_seed_pyrender.py"), f"{tmp}/peer", "--frames", str(args.frames)]
        wall(ours_cmd), wall(peer_cmd)  # untimed: bytecode written, files cached
        for r in range(args.repeats):
            pair = [(ours, ours_cmd), (peer, peer_cmd)]
            for times, cmd in pair if r % 2 == 0 else pair[::-1]:
                times.append(wall(cmd))
    o, p = statistics.median(ours), statistics.median(peer)
    ratio = o / p
    print(f"seed command, {args.frames} PNG frames, median of {args.repeats} interleaved runs:")
    print(f"  renderer (wirecheck)     {o:7.3f} s")
    print(f"  pyrender + Pillow (peer) {p:7.3f} s")
    print(f"  ratio {ratio:.3f}  target <= {TARGET_RATIO}  {'MET' if ratio <= TARGET_RATIO else 'NOT MET'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
