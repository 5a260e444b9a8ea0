#!/usr/bin/env python
"""The pairing of pixels with segments (oracles.judge.segment_pixels) and the line scores built on it, on fixed
frames, written out so that two trees' results can be compared exactly (a change meant to be faster, not different).

Run from a tree's root, with that tree's Python, then compare::

    .venv/bin/python benchmarks/segment_pixels_equivalence.py run OUT.pkl [--frames PKL ...]
    .venv/bin/python benchmarks/segment_pixels_equivalence.py compare A.pkl B.pkl    # exit 0: equal

``run`` measures, for 150 seeded random frames (each under the module's own
settings and again with its chunk, level, grid and table settings forced to
their other paths), every public result of the pairing:
``frames_neighbourhoods`` (the rows), ``frames_count_differences``,
``nearest_segments`` and ``edge_neighbourhoods`` without pixels, and the whole
``LineBatch`` line scores. The frames are hostile on purpose: ends on pixel
centres, half and quarter pixels (exact distance ties), shared ends (a mesh's
vertices), repeated and reversed segments, segments of no length or of
1e-9 px, segments leaving the image. ``--frames`` adds captured frames
(pickled ``[(FramePixels, p0_px, p1_px)]``, e.g. one frame of a benchmark
mesh), scored the same way. ``compare`` prints the first difference.
"""

from __future__ import annotations

import argparse
import pickle
import sys

import numpy as np

SEED = 37
FRAMES = 150
#: the module settings forced, in turn, to reach every path of the pairing: many chunks, the levels on few
#: pixels, the grid of cells instead of box tests, row by row instead of the grid, no summed-area table
FORCED = (
    {},
    {"CHUNK_PAIRS": 64, "LEVEL_PIXELS": 1},
    {"FEW_PAIRS": 0, "LEVEL_PIXELS": 1, "FEW_SEGMENTS": 1},
    {"TABLE_CELLS": 0, "CROWDED": 0, "LEVEL_PIXELS": 1, "DENSE": 10**9},
    {"DENSE": 0, "CHUNK_PAIRS": 257},
)


def hostile_frame(rng: np.random.Generator, w: int, h: int):
    """``(p0 (E, 2), p1 (E, 2), cand (H, W) bool, oracle (H, W) bool)``: segments and two images near them."""
    kind = rng.integers(4)
    step = (1.0, 0.5, 0.25, 0.0)[kind]  # ends on a grid of this step (0: anywhere)
    n_pts = int(rng.integers(3, 40))
    pts = rng.uniform(-4, [w + 3, h + 3], (n_pts, 2))
    if step:
        pts = np.round(pts / step) * step
    n_edges = int(rng.integers(2, 80))
    e = rng.integers(0, n_pts, (n_edges, 2))  # shared ends, some of no length (e[:, 0] == e[:, 1])
    p0, p1 = pts[e[:, 0]].copy(), pts[e[:, 1]].copy()
    extra = rng.integers(0, n_edges, int(rng.integers(0, 6)))
    p0 = np.concatenate([p0, p1[extra], p0[extra[:2]]])  # reversed and repeated segments
    p1 = np.concatenate([p1, p0[extra], p1[extra[:2]]])
    if rng.random() < 0.3:  # near-degenerate: 1e-9 px long
        k = rng.integers(0, len(p0), 3)
        p1[k] = p0[k] + rng.choice([-1e-9, 1e-9], (3, 2))
    if rng.random() < 0.2:
        p0[rng.integers(0, len(p0))] = np.nan  # a row not drawn
    cand = np.zeros((h, w), bool)
    y, x = np.mgrid[0:h, 0:w]
    for a, b in zip(p0, p1):  # the pixels within ~0.7 px of each segment, then noise on each side
        if not (np.isfinite(a).all() and np.isfinite(b).all()):
            continue
        d = b - a
        dd = float(d @ d)
        u = np.clip(((x - a[0]) * d[0] + (y - a[1]) * d[1]) / dd, 0, 1) if dd > 0 else np.zeros(x.shape)
        cand |= np.hypot(x - a[0] - u * d[0], y - a[1] - u * d[1]) <= rng.choice([0.5, 0.7, 1.0])
    oracle = cand.copy()
    for img in (cand, oracle):
        flip = rng.random((h, w)) < rng.choice([0.0, 0.01, 0.05])
        img ^= flip
    return p0, p1, cand, oracle


def results(frames, w: int, h: int) -> list:
    """Every public result of the pairing on ``frames`` (``[(FramePixels, p0, p1)]``, one size)."""
    from wirecheck.oracles.judge import metrics
    from wirecheck.oracles.judge import segment_pixels as sp

    out = []
    drawn = [(p0, p1, fp.drawn()) for fp, p0, p1 in frames]
    out.append(("neighbourhoods", sp.frames_neighbourhoods(drawn, w, h)))
    out.append(("neighbourhoods r=0.6", sp.frames_neighbourhoods(drawn, w, h, 0.6)))
    out.append(("count_differences", sp.frames_count_differences([(p0, p1, fp) for fp, p0, p1 in frames], w, h)))
    only = [(p0, p1, np.sort(np.concatenate(fp.only()))) for fp, p0, p1 in frames]
    box = ((-0.5, -0.5), (w - 0.5, h - 0.5))
    out.append(("nearest_segments", sp.nearest_segments(only, w, h, 1.5, box)))
    out.append(("nearest_segments drawn", sp.nearest_segments(drawn, w, h, 1.0, box)))
    if w * h <= 5000:
        out.append(("from_segments", [sp.edge_neighbourhoods(p0, p1, w, h) for fp, p0, p1 in frames[:2]]))
    batch = metrics.LineBatch()
    for k, (fp, p0, p1) in enumerate(frames):
        batch.add(k, fp, p0, p1)
    out.append(("line_scores", batch.flush()))
    return out


def run(out_path: str, captured: list[str]) -> int:
    from wirecheck.oracles.judge import segment_pixels as sp
    from wirecheck.oracles.judge.frame_pixels import FramePixels

    rng = np.random.default_rng(SEED)
    sets = []
    for _ in range(FRAMES // 3):  # three frames of one size at a time (a case's batch)
        w, h = int(rng.integers(8, 60)), int(rng.integers(6, 45))
        frames = []
        for _ in range(3):
            p0, p1, cand, oracle = hostile_frame(rng, w, h)
            frames.append((FramePixels(cand, oracle), p0, p1))
        sets.append((frames, w, h))
    for path in captured:
        with open(path, "rb") as f:
            frames = pickle.load(f)
        h, w = frames[0][0].shape
        sets.append((frames, w, h))
    defaults = {name: getattr(sp, name) for name in {k for forced in FORCED for k in forced}}
    got = []
    for forced in FORCED:
        for name, value in {**defaults, **forced}.items():
            setattr(sp, name, value)
        for i, (frames, w, h) in enumerate(sets):
            if forced and i >= FRAMES // 3 and "CHUNK_PAIRS" in forced and forced["CHUNK_PAIRS"] < 1000:
                continue  # a captured mesh frame in chunks of 64 pairs: minutes, and the random frames reach it
            got.append((str(forced), i, results(frames, w, h)))
    with open(out_path, "wb") as f:
        pickle.dump(got, f)
    print(f"wrote {out_path}: {len(got)} frame sets x {len(got[0][2]) if got else 0} results")
    return 0


def first_difference(a, b, where: str = "") -> str | None:
    """Where ``a`` and ``b`` differ (arrays bitwise, floats exactly), or None."""
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        a, b = np.asarray(a), np.asarray(b)
        if (
            a.shape != b.shape
            or a.dtype.kind != b.dtype.kind
            or not np.array_equal(a, b, equal_nan=a.dtype.kind == "f")
        ):
            return f"{where}: arrays differ ({a.shape} {a.dtype} vs {b.shape} {b.dtype})"
        return None
    if isinstance(a, dict) and isinstance(b, dict):
        if a.keys() != b.keys():
            return f"{where}: keys {sorted(a)} vs {sorted(b)}"
        for k in a:
            d = first_difference(a[k], b[k], f"{where}.{k}")
            if d:
                return d
        return None
    if isinstance(a, (list, tuple)) and isinstance(b, (list, tuple)):
        if len(a) != len(b):
            return f"{where}: lengths {len(a)} vs {len(b)}"
        for k, (x, y) in enumerate(zip(a, b)):
            d = first_difference(x, y, f"{where}[{k}]")
            if d:
                return d
        return None
    same = a == b or (isinstance(a, float) and isinstance(b, float) and a != a and b != b)
    return None if same and type(a) is type(b) else f"{where}: {a!r} vs {b!r}"


def compare(a_path: str, b_path: str) -> int:
    with open(a_path, "rb") as f:
        a = pickle.load(f)
    with open(b_path, "rb") as f:
        b = pickle.load(f)
    diff = first_difference(a, b)
    if diff:
        print(f"differ: {diff}")
        return 1
    print(f"equal: {len(a)} frame sets, every result the same")
    return 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run")
    r.add_argument("out")
    r.add_argument("--frames", nargs="*", default=[], help="pickled [(FramePixels, p0_px, p1_px)] of one size each")
    c = sub.add_parser("compare")
    c.add_argument("a")
    c.add_argument("b")
    args = ap.parse_args(argv)
    return run(args.out, args.frames) if args.cmd == "run" else compare(args.a, args.b)


if __name__ == "__main__":
    sys.exit(main())
