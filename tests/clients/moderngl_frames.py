"""A renderer of a wirecheck frames job written as a moderngl user would: OpenGL on EGL, MSAA optional.

``python moderngl_frames.py JOB [--samples N] [--no-flip]``

For every case and frame listed in ``JOB/job.json`` it draws the OBJ's edges
as ``GL_LINES`` with ``gl_position = P V M p`` from the camera JSON's
``gl_projection``, ``gl_view`` and ``model_matrix`` (GL clips at near and
far), white on black, into a framebuffer of the camera's size (``--samples``
> 0: multisampled, resolved by a copy: anti-aliased lines), reads it back
and writes the PNG top row first. Only numpy, moderngl, Pillow and the job's
files: nothing of wirecheck.

``--no-flip`` is a typical mistake: the rows written as GL reads them,
bottom first (the image upside down).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

VERTEX = """#version 330
uniform mat4 mvp;
in vec3 in_pos;
void main() { gl_Position = mvp * vec4(in_pos, 1.0); }
"""
FRAGMENT = """#version 330
out vec4 colour;
void main() { colour = vec4(1.0); }
"""


def read_obj(path: Path):
    verts, edges = [], []
    for line in path.read_text().splitlines():
        parts = line.split()
        if parts and parts[0] == "v":
            verts.append([float(x) for x in parts[1:4]])
        elif parts and parts[0] == "l":
            edges.append([int(x) - 1 for x in parts[1:3]])
    return np.array(verts).reshape(-1, 3), np.array(edges, dtype=int).reshape(-1, 2)


def main(argv=None) -> int:
    import moderngl
    from PIL import Image

    ap = argparse.ArgumentParser()
    ap.add_argument("job")
    ap.add_argument("--samples", type=int, default=0)
    ap.add_argument("--no-flip", action="store_true")
    args = ap.parse_args(argv)
    job_dir = Path(args.job)
    job = json.loads((job_dir / "job.json").read_text())
    scenes = {s["name"]: s for s in job["scenes"]}
    ctx = moderngl.create_standalone_context(backend="egl")
    prog = ctx.program(vertex_shader=VERTEX, fragment_shader=FRAGMENT)
    for c in job["cases"]:
        w, h = c["width"], c["height"]
        fbo = ctx.simple_framebuffer((w, h), samples=args.samples)
        out = ctx.simple_framebuffer((w, h)) if args.samples else fbo
        for rel in c["frames"]:
            k = int(Path(rel).stem.split("_")[-1])
            scene = scenes[c["scene"]]
            obj = scene["obj"] if scene["space"] == "model" else f"scenes/{c['scene']}/frame_{k:04d}.obj"
            v, e = read_obj(job_dir / obj)
            cam = json.loads((job_dir / f"cameras/{c['scene']}/{c['case']}/frame_{k:04d}.json").read_text())
            m = np.array(cam["model_matrix"]) if scene["space"] == "model" else np.eye(4)
            mvp = np.array(cam["gl_projection"]) @ np.array(cam["gl_view"]) @ m
            prog["mvp"].write(mvp.T.astype("f4").tobytes())          # GLSL reads column-major
            vbo = ctx.buffer(v[e].reshape(-1, 3).astype("f4").tobytes())
            vao = ctx.vertex_array(prog, [(vbo, "3f", "in_pos")])
            fbo.use()
            fbo.clear(0.0, 0.0, 0.0, 1.0)
            vao.render(moderngl.LINES)
            if args.samples:
                ctx.copy_framebuffer(out, fbo)
            rgb = np.frombuffer(out.read(components=3), np.uint8).reshape(h, w, 3)
            img = rgb if args.no_flip else rgb[::-1]                   # GL's rows run bottom up
            (job_dir / rel).parent.mkdir(parents=True, exist_ok=True)
            Image.fromarray(np.ascontiguousarray(img)).save(job_dir / rel)
            vao.release()
            vbo.release()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
