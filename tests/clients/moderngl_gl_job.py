"""A renderer of a wirecheck frames job written as a moderngl (OpenGL 3.3 core) user would.

``python moderngl_gl_job.py JOB [--no-flip] [--aspect-h-over-w] [--half-pixel]``

For every case and frame listed in ``JOB/job.json`` it reads the OBJ's ``v``
and ``l`` lines and the frame's camera JSON, and draws the edges with
``GL_LINES`` (1 px, no multisampling, no line smoothing, no depth test: a
wireframe shows every edge) white on black into an offscreen framebuffer of
the camera's size on a headless EGL context
(``moderngl.create_standalone_context(backend="egl")``; Mesa's llvmpipe where
there is no GPU). The vertex shader is ``gl_Position = u_mvp * vec4(p_model, 1)``
with ``u_mvp = gl_projection @ gl_view @ model_matrix`` from the camera JSON,
multiplied on the CPU in float64 (one float32 rounding, not three); GL clips at
near and far. The framebuffer is read back and its rows flipped (GL's window
origin is the bottom-left corner, a PNG's the top-left), then written as an
8-bit grey PNG with Pillow. Only numpy, moderngl, Pillow and the job's files:
nothing of wirecheck.

Typical mistakes, one flag each:

- ``--no-flip``: the read-back rows written as they come (bottom row first):
  the image upside down.
- ``--aspect-h-over-w``: the projection built with aspect H / W instead of
  W / H (``P[0][0]`` scaled by ``(W / H)^2``): x stretched (or squeezed).
- ``--half-pixel``: a Direct3D 9-style half-pixel offset added in clip space
  (x_ndc + 1 / W, y_ndc - 1 / H): every line moved by (+0.5, +0.5) px in the
  image's x right, y down pixels.
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path

import numpy as np
from job_files import job_frames

VERTEX_SHADER = """
#version 330
uniform mat4 u_mvp;
in vec3 in_position;
void main() { gl_Position = u_mvp * vec4(in_position, 1.0); }
"""

FRAGMENT_SHADER = """
#version 330
out vec4 f_color;
void main() { f_color = vec4(1.0); }
"""


def mvp_matrix(cam: dict, width: int, height: int, aspect_h_over_w: bool, half_pixel: bool) -> np.ndarray:
    """``gl_projection @ gl_view @ model_matrix`` (float64), with the chosen mistake applied to the projection."""
    proj = np.array(cam["gl_projection"], dtype=np.float64)
    if aspect_h_over_w:
        proj[0] *= (width / height) ** 2  # f / (H / W) where f / (W / H) was right
    if half_pixel:
        shift = np.eye(4)
        shift[0, 3], shift[1, 3] = 1.0 / width, -1.0 / height  # NDC units: 2 / W is one pixel
        proj = shift @ proj
    return proj @ np.array(cam["gl_view"], dtype=np.float64) @ np.array(cam["model_matrix"], dtype=np.float64)


class Renderer:
    """One EGL context, a program, and a single-sample framebuffer per image size."""

    def __init__(self):
        import moderngl

        self.ctx = moderngl.create_standalone_context(backend="egl")
        self.prog = self.ctx.program(vertex_shader=VERTEX_SHADER, fragment_shader=FRAGMENT_SHADER)
        self.fbos: dict[tuple[int, int], object] = {}

    def draw(
        self, p_model: np.ndarray, edges: np.ndarray, mvp: np.ndarray, width: int, height: int, flip: bool
    ) -> np.ndarray:
        """The frame as ``(H, W)`` uint8, row 0 at the top when ``flip`` (else GL's bottom row first)."""
        import moderngl

        fbo = self.fbos.get((width, height))
        if fbo is None:
            fbo = self.ctx.framebuffer(color_attachments=[self.ctx.renderbuffer((width, height), 4, samples=0)])
            self.fbos[(width, height)] = fbo
        fbo.use()
        fbo.viewport = (0, 0, width, height)
        self.ctx.disable(moderngl.DEPTH_TEST | moderngl.BLEND)
        self.ctx.line_width = 1.0
        fbo.clear(0.0, 0.0, 0.0, 1.0)
        # uniform mat4 is column-major: the transpose of the row-major matrix, as bytes
        self.prog["u_mvp"].write(mvp.T.astype("f4").tobytes())
        vbo = self.ctx.buffer(p_model[edges.reshape(-1)].astype("f4").tobytes())
        vao = self.ctx.vertex_array(self.prog, [(vbo, "3f", "in_position")])
        vao.render(moderngl.LINES)
        raw = fbo.read(components=1, alignment=1)  # rows from the bottom of the window up
        vao.release()
        vbo.release()
        pixels = np.frombuffer(raw, dtype=np.uint8).reshape(height, width)
        return pixels[::-1] if flip else pixels


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("job")
    ap.add_argument("--no-flip", action="store_true", help="mistake: write the read-back rows bottom first")
    ap.add_argument("--aspect-h-over-w", action="store_true", help="mistake: aspect H/W in the projection")
    ap.add_argument("--half-pixel", action="store_true", help="mistake: a half-pixel offset in clip space")
    args = ap.parse_args(argv)
    from PIL import Image

    job_dir = Path(args.job)
    renderer = Renderer()
    for c, out, p_model, edges, cam, model in job_frames(job_dir):
        width, height = c["width"], c["height"]
        if not model:
            cam = dict(cam, model_matrix=np.eye(4).tolist())  # world-space vertices per frame
        mvp = mvp_matrix(cam, width, height, args.aspect_h_over_w, args.half_pixel)
        pixels = renderer.draw(p_model, edges, mvp, width, height, flip=not args.no_flip)
        out.parent.mkdir(parents=True, exist_ok=True)
        tmp = out.with_name(out.name + ".tmp")
        Image.fromarray(pixels, mode="L").save(tmp, format="PNG")
        os.replace(tmp, out)
    renderer.ctx.release()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
