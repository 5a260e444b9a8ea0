"""A depth map rendered as a moderngl user would: OpenGL on EGL, the depth attachment read back.

``python moderngl_depth.py DIR``: for each ``DIR/NAME.npz`` (``p_world``, ``triangles`` and the
camera's ``projection_matrix``, ``view_matrix``, ``width``, ``height``, ``near``, ``far``,
``projection``) writes ``DIR/NAME.correct.npy``, ``DIR/NAME.zbuffer.npy`` and
``DIR/NAME.no_flip.npy``. Run in its own process, as a renderer is: its EGL context never
shares a process with the pyrender oracle's.

``render_depth(p_world, triangles, camera, mistake=None) -> (H, W) float32``: the triangles
drawn with ``gl_Position = P V p`` from the camera's ``projection_matrix`` and ``view_matrix``
(the contract's OpenGL matrices), the framebuffer's depth attachment read as floats, made
linear (perspective ``d = 2 f n / ((f + n) - z_ndc (f - n))`` with ``z_ndc = 2 z_win - 1``;
orthographic ``d = n + z_win (f - n)``), 0 where nothing was drawn, rows flipped to put row 0
on top. Only numpy and moderngl: nothing of wirecheck.

``mistake``: ``"zbuffer"`` stores the window depth as read (the classic), ``"no_flip"`` keeps
GL's bottom-up rows.
"""

from __future__ import annotations

import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np

VERTEX = """#version 330
uniform mat4 pv;
in vec3 in_pos;
void main() { gl_Position = pv * vec4(in_pos, 1.0); }
"""
FRAGMENT = """#version 330
out vec4 colour;
void main() { colour = vec4(1.0); }
"""

_CTX = {}


def _context():
    import moderngl

    if "ctx" not in _CTX:
        ctx = moderngl.create_standalone_context(backend="egl")
        _CTX["ctx"] = ctx
        _CTX["prog"] = ctx.program(vertex_shader=VERTEX, fragment_shader=FRAGMENT)
    return _CTX["ctx"], _CTX["prog"]


def render_depth(p_world, triangles, camera, mistake=None) -> np.ndarray:
    import moderngl

    ctx, prog = _context()
    w, h = camera.width, camera.height
    fbo = ctx.framebuffer(color_attachments=[ctx.renderbuffer((w, h))], depth_attachment=ctx.depth_renderbuffer((w, h)))
    fbo.use()
    fbo.clear(0.0, 0.0, 0.0, 1.0, depth=1.0)
    ctx.enable(moderngl.DEPTH_TEST)
    pv = np.asarray(camera.projection_matrix) @ np.asarray(camera.view_matrix)
    prog["pv"].write(pv.T.astype("f4").tobytes())  # GLSL reads column-major
    tris = np.asarray(p_world, dtype="f4")[np.asarray(triangles).reshape(-1)]
    vbo = ctx.buffer(tris.tobytes())
    vao = ctx.vertex_array(prog, [(vbo, "3f", "in_pos")])
    vao.render(moderngl.TRIANGLES)
    z_win = (
        np.frombuffer(fbo.read(components=1, attachment=-1, dtype="f4"), dtype="f4").reshape(h, w).astype(np.float64)
    )
    vao.release(), vbo.release(), fbo.release()
    drawn = z_win < 1.0
    n, f = float(camera.near), float(camera.far)
    if mistake == "zbuffer":
        depth = np.where(drawn, z_win, 0.0)
    elif camera.projection == "perspective":
        depth = np.where(drawn, 2.0 * f * n / ((f + n) - (2.0 * z_win - 1.0) * (f - n)), 0.0)
    else:
        depth = np.where(drawn, n + z_win * (f - n), 0.0)
    if mistake != "no_flip":
        depth = depth[::-1]
    return depth.astype(np.float32)


MISTAKES = {"correct": None, "zbuffer": "zbuffer", "no_flip": "no_flip"}


def main(argv=None) -> int:
    folder = Path((sys.argv[1:] if argv is None else argv)[0])
    for request in sorted(folder.glob("*.npz")):
        with np.load(request) as data:
            camera = SimpleNamespace(
                projection_matrix=data["projection_matrix"],
                view_matrix=data["view_matrix"],
                width=int(data["width"]),
                height=int(data["height"]),
                near=float(data["near"]),
                far=float(data["far"]),
                projection=str(data["projection"]),
            )
            for label, mistake in MISTAKES.items():
                np.save(
                    folder / f"{request.stem}.{label}.npy",
                    render_depth(data["p_world"], data["triangles"], camera, mistake),
                )
    return 0


if __name__ == "__main__":
    sys.exit(main())
