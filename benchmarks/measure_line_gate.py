"""Measure the line gate's statistics (oracles/tolerances.py cites this run).

For core's exact raster (correct), the drop-last-pixel mutant and an unbiased
random-end renderer (tests/raster_mutants.py), over the bundled scenes, the
orrery example, the hidden-line + back-face mode and random edge soups, under
every crosscheck camera: cases passed, pooled candidate-only / oracle-only
pixels and how many of them are sub-pixel ties (oracles.judge.line_ties), the
largest |net imbalance| / oracle pixels and the smallest sign-test p (both
over the decided pixels, ties left out)
and the largest per-edge count difference.

    .venv/bin/python benchmarks/measure_line_gate.py [--frames 24]

A few minutes on one core. Not part of CI.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from raster_mutants import drop_last, random_ends  # noqa: E402
from wirecheck.core.projector import raster  # noqa: E402
from wirecheck.core.scene.files import load_scene, parse_scene_text  # noqa: E402
from wirecheck.oracles.runner import CoreCandidate, RenderMode, run_crosscheck  # noqa: E402


def random_scenes(n: int = 5, seed: int = 16) -> list:
    """``n`` random edge soups: 6..23 vertices in [-1, 1]^3, V..3V random edges."""
    rng = np.random.default_rng(seed)
    out = []
    for s in range(n):
        nv = int(rng.integers(6, 24))
        v = rng.uniform(-1, 1, size=(nv, 3))
        edges = set()
        for _ in range(int(rng.integers(nv, 3 * nv))):
            i, j = (int(x) for x in rng.integers(0, nv, 2))
            if i != j:
                edges.add((min(i, j), max(i, j)))
        text = (
            f"name random{s}\n"
            + "".join(f"v {a:.6f} {b:.6f} {c:.6f}\n" for a, b, c in v)
            + "".join(f"e {i} {j}\n" for i, j in sorted(edges))
        )
        out.append(parse_scene_text(text))
    return out


def summarise(label: str, report: dict) -> str:
    cases = report["cases"]
    lines = [c["lines"] for c in cases]
    c = sum(x["candidate_only"] for x in lines)
    o = sum(x["oracle_only"] for x in lines)
    tc = sum(x["subpixel_ties"][0] for x in lines)
    to = sum(x["subpixel_ties"][1] for x in lines)
    frac = max(abs(x["imbalance_fraction"]) for x in lines)
    p = min(x["balance_p_value"] for x in lines)
    cnt = max(x["edge_count_max_diff"] for x in lines)
    passed = sum(x["verdict"] == "pass" for x in cases)
    ends = sum(1 for x in cases if x["faults"] and x["faults"][0]["name"] == "line_end_bias")
    return f"| {label} | {passed}/{len(cases)} | {c} | {o} | {tc} + {to} | {frac:.2e} | {p:.2g} | {cnt} | {ends} |"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--frames", type=int, default=24)
    args = ap.parse_args(argv)
    bundled = [load_scene(n) for n in ("cube", "pyramid", "prism")]
    sets = [
        ("bundled", bundled, None),
        ("orrery", [load_scene("orrery")], None),
        ("hidden+cull", bundled + [load_scene("orrery")], RenderMode(hidden_lines=True, cull="backface")),
        ("random", random_scenes(), None),
    ]
    print(
        "| scenes, raster | passed | cand-only | oracle-only | of them ties | max abs net/oracle px | min p | "
        "max edge count diff | line_end_bias |"
    )
    print("|---|---|---|---|---|---|---|---|---|")
    original = raster._line_pixels
    for raster_name, fn in (("correct", original), ("drop last", drop_last), ("random ends", random_ends)):
        raster._line_pixels = fn
        try:
            for label, scenes, mode in sets:
                report, _ = run_crosscheck(scenes, CoreCandidate(), frames=args.frames, mode=mode, animation=False)
                print(summarise(f"{label}, {raster_name}", report), flush=True)
        finally:
            raster._line_pixels = original
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
