"""Peak memory of a GIF of many frames: core.outputs.gif's streaming writer against Pillow's ``save_all``.

    .venv/bin/python benchmarks/bench_gif_memory.py                 # 2,000 frames, 640x480 (~3 min on 2 cores)
    .venv/bin/python benchmarks/bench_gif_memory.py --frames 200    # quicker

Each encoder runs in a fresh interpreter on the same frames (the spinning
cube, ``renderer``'s defaults: 640x480, one turn about X and Y) and reports
its peak resident memory (``ru_maxrss``) and the GIF's size. "pillow" is what
``renderer --format gif`` did before core.outputs.gif: every frame converted to a
palette image and kept until ``save_all`` writes them.
"""

from __future__ import annotations

import argparse
import io
import json
import resource
import subprocess
import sys
import time


def encode(mode: str, frames: int) -> dict:
    from wirecheck.core.app.compose import picture
    from wirecheck.core.camera import camera_z
    from wirecheck.core.scene.frames import SceneRenderer
    from wirecheck.core.scene.model import load_scene
    from wirecheck.core.transforms import Motion

    cam = camera_z(4.0, fov_y_deg=60.0, width=640, height=480)
    renderer = SceneRenderer(load_scene("cube"), Motion(), frames)
    images = (picture(renderer.render(k, cam)[0], "wireframe") for k in range(1, frames + 1))
    t0 = time.perf_counter()
    buf = io.BytesIO()
    if mode == "stream":
        from wirecheck.core.outputs.gif import GifWriter

        w = GifWriter(buf, 30)
        for im in images:
            w.add(im)
        w.close()
    else:
        from PIL import Image

        pics = [Image.fromarray(im).convert("P") for im in images]  # the old code kept every frame
        pics[0].save(buf, format="GIF", save_all=True, append_images=pics[1:], duration=33, loop=0, optimize=False)
    return {
        "mode": mode,
        "frames": frames,
        "seconds": round(time.perf_counter() - t0, 2),
        "gif_bytes": len(buf.getvalue()),
        "peak_rss_mb": round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024, 1),
    }


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--frames", type=int, default=2000)
    p.add_argument("--child", choices=("stream", "pillow"), help=argparse.SUPPRESS)
    a = p.parse_args(argv)
    if a.child:
        print(json.dumps(encode(a.child, a.frames)))
        return 0
    rows = []
    for frames in sorted({max(1, a.frames // 10), a.frames}):
        for mode in ("pillow", "stream"):
            out = subprocess.run(
                [sys.executable, __file__, "--child", mode, "--frames", str(frames)],
                capture_output=True,
                text=True,
                check=True,
            )
            rows.append(json.loads(out.stdout))
    print("| encoder | frames | peak RSS (MB) | GIF (KB) | encode + render (s) |")
    print("|---|---:|---:|---:|---:|")
    for r in rows:
        print(f"| {r['mode']} | {r['frames']} | {r['peak_rss_mb']} | {r['gif_bytes'] / 1024:.0f} | {r['seconds']} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
