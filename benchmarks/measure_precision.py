"""Measure how far correct float32 projectors are from the float64 oracle (oracles/tolerances.py cites this run).

For five correct float32 projectors -- two glm-style GL pipelines
(tests/data/candidates/glm_f32.py, tests/data/real_world/glm_gl.py: P V
premultiplied, GL's clip test), DirectXMath's left-handed one
(tests/data/real_world/d3d_lh.py), core's own pipeline with ``--dtype
float32``, and an OpenCV-style ``K [R | t]`` in float32 -- on the bundled
scenes (and the orrery example) under every crosscheck case camera: the
largest vertex error, the largest ``error / (eps32 scale)`` of any point
(scale: oracles.tolerances, per point), the case bound the harness derives, and
the largest float32 view-depth error over ``eps32 (|X| + |C|)`` (the near-plane
margin of oracles.candidates.draw).

    .venv/bin/python benchmarks/measure_precision.py [--frames 24]

About a minute on one core. Not part of CI.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "data" / "candidates"))
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "data" / "real_world"))

import d3d_lh  # noqa: E402
import glm_f32  # noqa: E402
import glm_gl  # noqa: E402
from wirecheck.core.scene.files import load_scene  # noqa: E402
from wirecheck.core.transforms import Motion  # noqa: E402
from wirecheck.oracles import tolerances  # noqa: E402
from wirecheck.oracles.candidates.core_candidate import CoreCandidate  # noqa: E402
from wirecheck.oracles.cases import cameras_for  # noqa: E402
from wirecheck.oracles.references import opencv_oracle
from wirecheck.oracles.references.convert import opencv_matrices  # noqa: E402
from wirecheck.oracles.references.faces import frame_geometry  # noqa: E402

EPS32 = tolerances.EPS["float32"]


def kcv_f32(points, camera):
    """OpenCV-style in float32: p_cv = R X + t, [u, v, 1] ~ K p_cv (affine K for orthographic)."""
    r, t, k = (np.asarray(a, dtype=np.float32) for a in opencv_matrices(camera))
    p = np.asarray(points, dtype=np.float32) @ r.T + t
    z = p[:, 2]
    vis = (z >= np.float32(camera.near)) & (z <= np.float32(camera.far))
    if camera.projection == "perspective":
        uv = p[:, :2] / np.where(z == 0, np.float32(1), z)[:, None]
    else:
        uv = p[:, :2]
    out = uv @ k[:2, :2].T + k[:2, 2]
    out[~vis] = np.nan
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--frames", type=int, default=24)
    args = ap.parse_args(argv)
    motion = Motion()
    core32 = CoreCandidate(dtype="float32")
    worst = {"glm": 0.0, "glm_gl": 0.0, "d3d": 0.0, "core": 0.0, "kcv": 0.0}
    depth_ratio = 0.0
    print(
        f"{'scene':<8} {'case':<13} {'bound px':>9} | max err px: "
        + " ".join(f"{k:>8}" for k in worst)
        + " | err/(eps scale): "
        + " ".join(f"{k:>6}" for k in worst)
    )
    for name in ("cube", "pyramid", "prism", "orrery"):
        scene = load_scene(name)
        for case in cameras_for(scene.radius):
            cam = case.camera
            frames = core32.scene_frames(scene, motion, args.frames)
            errs = {k: 0.0 for k in worst}
            ratios = {k: 0.0 for k in worst}
            scale_max = 0.0
            for f in range(1, args.frames + 1):
                p_world = frame_geometry(scene, motion, (f - 1) / args.frames)[0]
                orac = opencv_oracle.project(p_world, cam)
                points, m_core = frames.geometry(f)
                cands = {
                    "glm": glm_f32.project(p_world, cam).astype(np.float64),
                    "glm_gl": glm_gl.project(p_world, cam).astype(np.float64),
                    "d3d": d3d_lh.project(p_world, cam).astype(np.float64),
                    "core": core32.project(points, cam, m_core),
                    "kcv": kcv_f32(p_world, cam).astype(np.float64),
                }
                seen = np.isfinite(orac).all(axis=1)
                per_point = np.array(
                    [tolerances.vertex_scale(p_world[i : i + 1], orac[i : i + 1], cam) for i in np.flatnonzero(seen)]
                )
                scale_max = max(scale_max, per_point.max(initial=0.0))
                for key, c in cands.items():
                    both = seen & np.isfinite(c).all(axis=1)
                    e = np.abs(c[both] - orac[both]).max(axis=1) if both.any() else np.zeros(0)
                    errs[key] = max(errs[key], float(e.max(initial=0.0)))
                    sc = per_point[both[seen]]
                    ratios[key] = max(ratios[key], float((e / (EPS32 * sc)).max(initial=0.0)))
                # float32 view depth (glm's) against the float64 depth
                eye = np.asarray(cam.position, np.float32)
                view = glm_f32.look_at_rh(
                    eye, eye + np.asarray(cam.forward, np.float32), np.asarray(cam.up, np.float32)
                )
                p32 = np.asarray(p_world, np.float32)
                d32 = -(p32 @ view[2, :3] + view[2, 3])
                d64 = opencv_oracle.depth(p_world, cam)
                size = np.linalg.norm(p_world, axis=1) + np.linalg.norm(cam.position)
                depth_ratio = max(depth_ratio, float((np.abs(d32 - d64) / (EPS32 * size)).max()))
            bound = tolerances.vertex_bound("float32", scale_max)
            for key in worst:
                worst[key] = max(worst[key], ratios[key])
            print(
                f"{name:<8} {case.name:<13} {bound:9.2e} | {'':11} "
                + " ".join(f"{errs[k]:8.1e}" for k in worst)
                + f" | {'':16} "
                + " ".join(f"{ratios[k]:6.2f}" for k in worst)
            )
    print(
        "largest error / (eps32 scale): "
        + ", ".join(f"{k} {v:.2f}" for k, v in worst.items())
        + f"; largest float32 depth error / (eps32 (|X|+|C|)): {depth_ratio:.2f}"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
