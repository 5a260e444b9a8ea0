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
from pathlib import Path

import numpy as np
from job_files import job_frames

VERTEX = """#version 330
uniform mat4 mvp;
in vec3 in_pos;
void main() { gl_Position = mvp * vec4(in_pos, 1.0); }
"""
FRAGMENT = """#version 330
out vec4 colour;
void main() { colour = vec4(1.0); }
"""


def main(argv=None) -> int:
    import moderngl
    from PIL import Image

    ap = argparse.ArgumentParser()
    ap.add_argument("job")
    ap.add_argument("--samples", type=int, default=0)
    ap.add_argument("--no-flip", action="store_true")
    args = ap.parse_args(argv)
    job_dir = Path(args.job)
    ctx = moderngl.create_standalone_context(backend="egl")
    prog = ctx.program(vertex_shader=VERTEX, fragment_shader=FRAGMENT)
    buffers = {}  # (w, h): the framebuffers of that size
    for c, png, v, e, cam, model in job_frames(job_dir):
        w, h = c["width"], c["height"]
        if (w, h) not in buffers:
            fbo = ctx.simple_framebuffer((w, h), samples=args.samples)
            buffers[w, h] = (fbo, ctx.simple_framebuffer((w, h)) if args.samples else fbo)
        fbo, out = buffers[w, h]
        m = np.array(cam["model_matrix"]) if model else np.eye(4)
        mvp = np.array(cam["gl_projection"]) @ np.array(cam["gl_view"]) @ m
        prog["mvp"].write(mvp.T.astype("f4").tobytes())  # GLSL reads column-major
        vbo = ctx.buffer(v[e].reshape(-1, 3).astype("f4").tobytes())
        vao = ctx.vertex_array(prog, [(vbo, "3f", "in_pos")])
        fbo.use()
        fbo.clear(0.0, 0.0, 0.0, 1.0)
        vao.render(moderngl.LINES)
        if args.samples:
            ctx.copy_framebuffer(out, fbo)
        rgb = np.frombuffer(out.read(components=3), np.uint8).reshape(h, w, 3)
        img = rgb if args.no_flip else rgb[::-1]  # GL's rows run bottom up
        png.parent.mkdir(parents=True, exist_ok=True)
        Image.fromarray(np.ascontiguousarray(img)).save(png)
        vao.release()
        vbo.release()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
