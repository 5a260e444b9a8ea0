#!/usr/bin/env python
"""The peer of the seed command, written as a pyrender user would: the same job, no wirecheck.

    python benchmarks/peer_seed_pyrender.py OUT_DIR [--frames 180]

Renders the cube's 12 edges for ``--frames`` frames with pyrender on OSMesa
(camera at (0, 0, 4) looking down -Z, vertical FOV 70 degrees, 640x480, near
0.1, far 100), spinning one full turn about X and one about Y over the run
(frame k at t = (k - 1) / frames, model matrix Ry(2 pi t) @ Rx(2 pi t)), and
writes each frame as an 8-bit grey PNG with Pillow (its default settings).
``benchmarks/bench_seed.py`` times it against ``renderer --scene cube
--frames 180 --camera-z 4.0 --fov 70``.
"""

import argparse
import math
import os
from pathlib import Path

os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa")

import numpy as np  # noqa: E402
import pyrender  # noqa: E402
from PIL import Image  # noqa: E402

CUBE = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], np.float32)
EDGES = np.array(
    [[a, b] for a in range(8) for b in range(a + 1, 8) if np.abs(CUBE[a] - CUBE[b]).sum() == 2], np.uint32
)  # the 12 unit-step pairs


def rotation(t: float) -> np.ndarray:
    a = 2 * math.pi * t
    c, s = math.cos(a), math.sin(a)
    rx = np.array([[1, 0, 0, 0], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1]])
    ry = np.array([[c, 0, s, 0], [0, 1, 0, 0], [-s, 0, c, 0], [0, 0, 0, 1]])
    return ry @ rx


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--frames", type=int, default=180)
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    white = pyrender.MetallicRoughnessMaterial(baseColorFactor=[1.0, 1.0, 1.0, 1.0])
    mesh = pyrender.Mesh(
        [pyrender.Primitive(positions=CUBE, indices=EDGES, mode=pyrender.constants.GLTF.LINES, material=white)]
    )
    scene = pyrender.Scene(bg_color=[0, 0, 0, 1], ambient_light=[0, 0, 0])
    node = scene.add(mesh)
    pose = np.eye(4)
    pose[2, 3] = 4.0
    scene.add(pyrender.PerspectiveCamera(yfov=math.radians(70), aspectRatio=640 / 480, znear=0.1, zfar=100), pose=pose)
    renderer = pyrender.OffscreenRenderer(640, 480)
    for k in range(1, args.frames + 1):
        scene.set_pose(node, rotation((k - 1) / args.frames))
        color, _ = renderer.render(scene, flags=pyrender.RenderFlags.FLAT)
        Image.fromarray(color[:, :, 0]).save(out / f"frame_{k:04d}.png")
    renderer.delete()


if __name__ == "__main__":
    main()
