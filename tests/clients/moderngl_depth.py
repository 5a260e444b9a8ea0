"""A depth map rendered as a moderngl user would: OpenGL on EGL, the depth attachment read back.

``python moderngl_depth.py DIR``: for each ``DIR/NAME.npz`` (``p_world``, ``triangles`` and the
camera's ``projection_matrix``, ``view_matrix``, ``width``, ``height``, ``near``, ``far``,
``projection``) writes ``DIR/NAME.correct.npy``, ``DIR/NAME.zbuffer.npy`` and
``DIR/NAME.no_flip.npy``. Run in its own process, as a renderer is: its EGL context never
shares a process with the pyrender oracle's.

``python moderngl_depth.py --job JOB [--mistake zbuffer|no_flip]``: an exported job
(``crosscheck export JOB --outputs filled,depth``) rendered as its README asks, read as a user
reads it (tests/clients/job_files.py: job.json, the OBJ's ``f`` faces, each frame's camera JSON,
``p_world = model_matrix @ [v, 1]``), the camera's ``gl_projection`` and ``gl_view`` as
``projection_matrix`` and ``view_matrix``; each filled frame from the colour attachment (grey level
``1 + object``: one id per object, the scene's ``objects``), each depth map from the depth
attachment, written in job.json's ``depth_encoding``; ``--mistake`` applied to every frame.

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

import argparse
import json
import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
from job_files import job_surfaces, write_depth

VERTEX = """#version 330
uniform mat4 pv;
in vec3 in_pos;
in float in_level;
flat out float level;
void main() { gl_Position = pv * vec4(in_pos, 1.0); level = in_level; }
"""
FRAGMENT = """#version 330
flat in float level;
out vec4 colour;
void main() { colour = vec4(level / 255.0); }
"""

_CTX = {}


def _context():
    import moderngl

    if "ctx" not in _CTX:
        ctx = moderngl.create_standalone_context(backend="egl")
        _CTX["ctx"] = ctx
        _CTX["prog"] = ctx.program(vertex_shader=VERTEX, fragment_shader=FRAGMENT)
    return _CTX["ctx"], _CTX["prog"]


def render(p_world, triangles, camera, mistake=None, levels=None) -> tuple[np.ndarray, np.ndarray]:
    """``(depth (H, W) float32, filled (H, W) uint8)``: the depth map (module docstring) and the colour
    attachment's grey levels, ``levels[i]`` (1 to 255; 255 when None) where triangle ``i`` is nearest, 0 where
    nothing was drawn; ``mistake`` applied to both (``"zbuffer"`` to the depth map alone)."""
    import moderngl

    ctx, prog = _context()
    w, h = camera.width, camera.height
    fbo = ctx.framebuffer(color_attachments=[ctx.renderbuffer((w, h))], depth_attachment=ctx.depth_renderbuffer((w, h)))
    fbo.use()
    fbo.clear(0.0, 0.0, 0.0, 1.0, depth=1.0)
    ctx.enable(moderngl.DEPTH_TEST)
    pv = np.asarray(camera.projection_matrix) @ np.asarray(camera.view_matrix)
    prog["pv"].write(pv.T.astype("f4").tobytes())  # GLSL reads column-major
    triangles = np.asarray(triangles).reshape(-1, 3)
    levels = np.full(len(triangles), 255.0) if levels is None else np.asarray(levels, dtype=np.float64)
    tris = np.c_[np.asarray(p_world, dtype="f4")[triangles.reshape(-1)], np.repeat(levels, 3)].astype("f4")
    vbo = ctx.buffer(tris.tobytes())
    vao = ctx.vertex_array(prog, [(vbo, "3f 1f", "in_pos", "in_level")])
    vao.render(moderngl.TRIANGLES)
    z_win = (
        np.frombuffer(fbo.read(components=1, attachment=-1, dtype="f4"), dtype="f4").reshape(h, w).astype(np.float64)
    )
    filled = np.frombuffer(fbo.read(components=1), dtype=np.uint8).reshape(h, w)
    vao.release(), vbo.release(), fbo.release()
    drawn = z_win < 1.0
    n, f = float(camera.near), float(camera.far)
    if mistake == "zbuffer":
        depth = np.where(drawn, z_win, 0.0)
    elif camera.projection == "perspective":
        depth = np.where(drawn, 2.0 * f * n / ((f + n) - (2.0 * z_win - 1.0) * (f - n)), 0.0)
    else:
        depth = np.where(drawn, n + z_win * (f - n), 0.0)
    if mistake != "no_flip":  # GL's row 0 is the bottom
        depth, filled = depth[::-1], filled[::-1]
    return depth.astype(np.float32), np.ascontiguousarray(filled)


def render_depth(p_world, triangles, camera, mistake=None) -> np.ndarray:
    return render(p_world, triangles, camera, mistake)[0]


MISTAKES = {"correct": None, "zbuffer": "zbuffer", "no_flip": "no_flip"}


def render_job(job_dir: Path, mistake=None) -> None:
    """Every filled frame and depth map the exported job at ``job_dir`` lists (module docstring)."""
    from PIL import Image

    encoding = json.loads((job_dir / "job.json").read_text()).get("depth_encoding")
    for c, cam_json, p_world, triangles, objects, files in job_surfaces(job_dir):
        cam = cam_json["camera"]
        camera = SimpleNamespace(
            projection_matrix=cam_json["gl_projection"],
            view_matrix=cam_json["gl_view"],
            width=cam["width"],
            height=cam["height"],
            near=cam["near"],
            far=cam["far"],
            projection=cam["projection"],
        )
        depth, filled = render(p_world, triangles, camera, mistake, levels=1 + objects)
        if files["filled"] is not None:
            files["filled"].parent.mkdir(parents=True, exist_ok=True)
            Image.fromarray(filled).save(files["filled"])
        if files["depth"] is not None:
            write_depth(files["depth"], depth, encoding)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("folder", type=Path)
    ap.add_argument("--job", action="store_true", help="the folder is an exported job (module docstring)")
    ap.add_argument("--mistake", choices=("zbuffer", "no_flip"), help="with --job: one mistake, every frame")
    args = ap.parse_args(argv)
    if args.job:
        render_job(args.folder, args.mistake)
        return 0
    for request in sorted(args.folder.glob("*.npz")):
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
                    args.folder / f"{request.stem}.{label}.npy",
                    render_depth(data["p_world"], data["triangles"], camera, mistake),
                )
    return 0


if __name__ == "__main__":
    sys.exit(main())
