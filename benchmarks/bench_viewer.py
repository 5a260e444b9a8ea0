#!/usr/bin/env python
"""Frame rate of the interactive viewer (``renderer --interactive``), through its HTTP API.

Run from the repo root::

    .venv/bin/python benchmarks/bench_viewer.py [--frames N]

Scenes: the built-in ``cube`` and ``trimesh.creation.icosphere(subdivisions=6)``
(40,962 vertices, 122,880 edges, written to a temporary .obj and loaded as the
renderer loads a mesh). For each scene and drawing mode a viewer server runs on
127.0.0.1 and a client (urllib, one request at a time, as the page does) sends
N orbit drags of 5 px; each reply carries core's PNG frame. Reported: frames per
second over the round trips (everything but the browser's decode and paint), the
round trip's p50/p95, and the server's per-stage p50 (core.app.profile).

Informational: no target is gated (times on a shared machine vary); the
README's figure comes from this script.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
import urllib.request
from pathlib import Path

import numpy as np
from wirecheck.core.app.cli import build_parser, settings_from_args
from wirecheck.core.app.viewer import STAGES, Viewer
from wirecheck.core.app.viewer_http import Server

MODES = {"wireframe": [], "hidden-lines": ["--hidden-lines"], "shaded": ["--style", "shaded"]}


def _post(url: str, ops) -> dict:
    req = urllib.request.Request(
        url + "api/frame", data=json.dumps({"ops": ops}).encode(), headers={"Content-Type": "application/json"}
    )
    with urllib.request.urlopen(req, timeout=60) as r:
        return json.loads(r.read())


def run(scene: str, mode_args, frames: int, out: Path) -> dict:
    s = settings_from_args(
        build_parser().parse_args(
            ["--scene", scene, "--camera-z", "4", "--frames", "180", "--out", str(out)] + mode_args
        )
    )
    server = Server(Viewer(s)).start()
    try:
        _post(server.url, [])  # warm-up: caches, first PNG
        rts = []
        for _ in range(frames):
            t0 = time.perf_counter()
            resp = _post(server.url, [{"op": "orbit", "dx": 5, "dy": 0}])
            rts.append(1e3 * (time.perf_counter() - t0))
        prof = resp["profile"]["stages"]
    finally:
        server.stop()
    rts = np.array(rts)
    return {
        "fps": 1e3 / rts.mean(),
        "p50": float(np.percentile(rts, 50)),
        "p95": float(np.percentile(rts, 95)),
        "stages_p50": {k: prof[k]["p50_ms"] for k in STAGES},
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--frames", type=int, default=40)
    a = ap.parse_args(argv)
    import trimesh

    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        ico = trimesh.creation.icosphere(subdivisions=6)
        ico_path = tmp / "icosphere6.obj"
        ico.export(ico_path)
        print(f"viewer frame rate over HTTP, {a.frames} orbit requests each (640x480)")
        print(f"{'scene':<12} {'mode':<13} {'fps':>6} {'p50 ms':>8} {'p95 ms':>8}   server p50 ms per stage")
        for scene, path in (("cube", "cube"), ("ico6 (40962)", str(ico_path))):
            for mode, args in MODES.items():
                r = run(path, args, a.frames, tmp / "out")
                stages = " ".join(f"{k}={v:.1f}" for k, v in r["stages_p50"].items() if v >= 0.05)
                print(f"{scene:<12} {mode:<13} {r['fps']:>6.1f} {r['p50']:>8.1f} {r['p95']:>8.1f}   {stages}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
