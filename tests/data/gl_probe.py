"""Run in a fresh interpreter with PYOPENGL_PLATFORM set: what the pyrender oracle draws, as JSON on stdout.

Used by tests/test_oracle_gl.py (the GL platform is fixed per process, at
PyOpenGL's import, so each platform gets its own interpreter).
"""

import json
import sys

import numpy as np


def gl_strings_of_a_fresh_context() -> dict:
    """glGetString of a plain pyrender OffscreenRenderer's context (not the oracle's code)."""
    import pyrender  # noqa: F401  (PyOpenGL imported through pyrender first, as the oracle does)
    from OpenGL import GL

    r = plain_renderer(8, 8)
    r._platform.make_current()
    out = {
        k: GL.glGetString(n).decode()
        for k, n in (("vendor", GL.GL_VENDOR), ("renderer", GL.GL_RENDERER), ("version", GL.GL_VERSION))
    }
    return out, r


def plain_renderer(width: int, height: int):
    """pyrender's OffscreenRenderer as pyrender sets it up (its 4x buffers), kept from ending the EGL display."""
    import pyrender
    from wirecheck.oracles.references.pyrender_oracle import _spare_the_display

    r = pyrender.OffscreenRenderer(width, height)
    if hasattr(r._platform, "_egl_display"):
        _spare_the_display(r._platform)
    return r


def coverage_levels(renderer, scene) -> list:
    import pyrender

    colour, _depth = renderer.render(scene, pyrender.RenderFlags.FLAT)
    return sorted(int(v) for v in np.unique(colour[:, :, 0]))


def colour_only_agrees() -> dict:
    """The oracle's colour-only masks (``render(depth=False)``) against its masks read with depth (pyrender's read).

    The cube from 12 directions, with and without its faces (hidden lines),
    with face culling, perspective and orthographic, at 61x47 (rows not a
    multiple of 4 bytes: the read's packing shows) and 640x480.
    """
    from wirecheck.core.camera import look_at
    from wirecheck.core.scene.files import load_scene
    from wirecheck.oracles.references.pyrender_oracle import PyrenderOracle

    cube = load_scene("cube")
    faces = tuple(tuple(f) for f in cube.faces)
    out = {"compared": 0, "differ": 0, "drawn": 0}
    for w, h in ((61, 47), (640, 480)):
        with PyrenderOracle(w, h) as oracle:
            for i in range(12):
                a = 2 * np.pi * i / 12
                eye = (3.5 * np.cos(a), 1.2 + 0.3 * (i % 3), 3.5 * np.sin(a))
                cam = look_at(
                    eye,
                    (0, 0, 0),
                    (0, 1, 0),
                    width=w,
                    height=h,
                    near=0.1,
                    far=20,
                    projection="orthographic" if i % 4 == 3 else "perspective",
                    ortho_height=3.0,
                )
                for occluders, cull in ((None, False), (faces, False), (faces, True)):
                    with_depth, _ = oracle.render(cube.vertices, cube.edges, cam, faces=occluders, cull=cull)
                    colour_only, none = oracle.render(
                        cube.vertices, cube.edges, cam, faces=occluders, cull=cull, depth=False
                    )
                    out["compared"] += 1
                    out["differ"] += (
                        none is not None or colour_only.dtype != bool or not np.array_equal(colour_only, with_depth)
                    )
                    out["drawn"] += int(with_depth.sum())
    return out


def main() -> int:
    from wirecheck.core.camera import look_at
    from wirecheck.oracles.references.pyrender_oracle import PyrenderOracle, gl_available

    ok, why = gl_available()
    if not ok:
        print(json.dumps({"available": False, "why": why}))
        return 0
    fresh, raw = gl_strings_of_a_fresh_context()
    # two slanted lines: any anti-aliasing leaves partial coverage along them
    p_world = np.array([[-0.9, -0.7, 0.0], [0.8, 0.6, 0.0], [-0.9, 0.5, 0.0], [0.9, 0.45, 0.0]])
    edges = np.array([[0, 1], [2, 3]])
    cam = look_at((0, 0, 3), (0, 0, 0), (0, 1, 0), width=64, height=48, fov_y_deg=60, near=0.1, far=10)
    with PyrenderOracle(64, 48) as oracle, PyrenderOracle(32, 48) as other:
        mask, _depth = oracle.render(p_world, edges, cam)
        levels = coverage_levels(oracle._renderer, oracle._scene)
        info = oracle.gl_info()
        other.close()  # closing one oracle must leave the others working
        again, _ = oracle.render(p_world, edges, cam)
    # control: pyrender's own buffers, as pyrender allocates them, on the same scene
    raw_scene = oracle._scene
    control = plain_renderer(64, 48)
    raw_levels = coverage_levels(control, raw_scene)
    control.delete()
    raw.delete()
    print(
        json.dumps(
            {
                "available": True,
                "fresh": fresh,
                "info": info,
                "levels": levels,
                "raw_levels": raw_levels,
                "drawn": int(mask.sum()),
                "same_after_close": bool((again == mask).all()),
                "colour_only": colour_only_agrees(),
            }
        )
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
