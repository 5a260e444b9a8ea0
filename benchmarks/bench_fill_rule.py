#!/usr/bin/env python
"""The fill-rule reference's cost against pyrender's filled render of the same triangles.

Run from the repo root::

    .venv/bin/python benchmarks/bench_fill_rule.py [--repeat N]

Meshes: ``trimesh.creation.icosphere(subdivisions=s)`` for s = 3..6 (1,280 to 81,920
triangles) and the s = 6 sphere with 18,080 of its faces drawn twice (100,000 triangles),
seen by a 640x480 camera at distance 3 (the sphere fills ~30 % of the image). Timed, best of
``--repeat`` calls on the same frame:

* ``silhouette``: oracles.references.fill_rule.silhouette (projection, near/far cut, open
  edges, coverage and ties), one object;
* ``silhouette 2 obj``: the same with the faces split into two objects (a depth pass per
  object for the ids);
* ``pyrender``: PyrenderOracle.render_faces (cull off, with ids), its draw and read-back.

The ratio printed is silhouette / pyrender, measured in this run.
"""

from __future__ import annotations

import argparse
import time

import numpy as np


def _best(fn, repeat: int) -> float:
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args(argv)
    import trimesh
    from wirecheck.core.camera import look_at
    from wirecheck.oracles.references.fill_rule import silhouette
    from wirecheck.oracles.references.pyrender_oracle import PyrenderOracle

    cam = look_at((0.4, 0.3, 3.0), (0.0, 0.0, 0.0), near=0.1, far=20.0)
    meshes = []
    for s in (3, 4, 5, 6):
        m = trimesh.creation.icosphere(subdivisions=s)
        meshes.append((f"ico{s}", np.asarray(m.vertices), np.asarray(m.faces)))
    v, f = meshes[-1][1], meshes[-1][2]
    meshes.append(("ico6+", v, np.concatenate([f, f[: 100_000 - len(f)]])))
    print(f"{'mesh':8s} {'triangles':>9s} {'silhouette':>11s} {'2 objects':>10s} {'pyrender':>9s} {'ratio':>6s}")
    with PyrenderOracle(cam.width, cam.height) as oracle:
        for name, v, f in meshes:
            faces = [tuple(t) for t in f]
            halves = np.arange(len(f)) % 2
            shape = (cam.height, cam.width)
            t_sil = _best(lambda: silhouette(v, faces, cam, shape), args.repeat)
            t_two = _best(lambda: silhouette(v, faces, cam, shape, halves), args.repeat)
            t_pr = _best(lambda: oracle.render_faces(v, f, cam, cull=False, with_ids=True), args.repeat)
            print(
                f"{name:8s} {len(f):9d} {t_sil * 1e3:9.0f}ms {t_two * 1e3:8.0f}ms {t_pr * 1e3:7.0f}ms "
                f"{t_sil / t_pr:6.2f}"
            )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
