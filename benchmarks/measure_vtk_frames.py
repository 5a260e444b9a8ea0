"""Measure the frames judge on VTK (docs/frames.md, "VTK, measured", cites this run).

Exports a job (every bundled scene, the seven cases, frames 1 and 4 of 6), draws
it with tests/clients/vtk_frames.py (an offscreen vtkRenderWindow, as a VTK user
would write it) in a subprocess, correct and with each typical mistake
(``--mistake horizontal_fov``, ``--mistake no_flip``), judges each with
``crosscheck --candidate-frames`` and prints one line per case: F1@0px, F1@1px,
the verdict and the faults named, per set-up.

    .venv/bin/python benchmarks/measure_vtk_frames.py [OUT]

About 15 s a set-up on one core. Not part of CI: vtk is not a dependency of
wirecheck; exits 2 with one line when vtk cannot be imported.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

CLIENT = Path(__file__).resolve().parents[1] / "tests" / "clients" / "vtk_frames.py"
SETUPS = {"correct": [], "horizontal_fov": ["--mistake", "horizontal_fov"], "no_flip": ["--mistake", "no_flip"]}


def judge(job: Path, out: Path, flags: list) -> list:
    """The report's cases for the job drawn by the VTK client with ``flags``."""
    from wirecheck.oracles.cli import main

    d = out / "job"
    shutil.rmtree(out, ignore_errors=True)
    shutil.copytree(job, d)
    drawn = subprocess.run(
        [sys.executable, str(CLIENT), str(d), *flags], cwd=CLIENT.parent, capture_output=True, text=True
    )
    if drawn.returncode != 0:
        raise SystemExit(
            f"vtk_frames.py {' '.join(flags)} exited {drawn.returncode}: {drawn.stderr.strip().splitlines()[-1:]}"
        )
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        main(["--candidate-frames", str(d), "--report-dir", str(out / "rep")])
    return json.loads((out / "rep" / "report.json").read_text())["cases"]


def run(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("out", nargs="?", help="a folder for the job and the reports (default: a temporary one)")
    args = ap.parse_args(argv)
    try:
        import vtk  # noqa: F401
    except ImportError as exc:
        print(f"measure_vtk_frames: vtk is not importable ({exc}); pip install vtk to measure", file=sys.stderr)
        return 2
    from wirecheck.oracles.cli import main

    with tempfile.TemporaryDirectory() as tmp:
        out = Path(args.out or tmp)
        job = out / "job"
        shutil.rmtree(job, ignore_errors=True)
        with contextlib.redirect_stdout(io.StringIO()):
            assert main(["export", str(job), "--frames", "6", "--every", "3"]) == 0
        results = {name: judge(job, out / name, flags) for name, flags in SETUPS.items()}
    print(f"{'scene':8s} {'camera':13s} " + " | ".join(f"{n:>40s}" for n in SETUPS))
    for row in zip(*results.values()):
        cells = []
        for c in row:
            names = "+".join(f["name"] for f in c["faults"]) or "-"
            cells.append(f"{c['pixel_f1_0px']:.4f} {c['pixel_f1_1px']:.4f} {c['verdict']:4s} {names:>21s}")
        print(f"{row[0]['scene']:8s} {row[0]['camera']:13s} " + " | ".join(f"{s:>40s}" for s in cells))
    for name, cases in results.items():
        verdicts = {}
        for c in cases:
            key = f"{c['verdict']} {'+'.join(f['name'] for f in c['faults']) or '-'}"
            verdicts[key] = verdicts.get(key, 0) + 1
        print(f"{name}: {verdicts}")
    return 0


if __name__ == "__main__":
    raise SystemExit(run())
