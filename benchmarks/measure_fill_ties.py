#!/usr/bin/env python
"""How wide the fill-rule tie zone must be: pyrender's and core's silhouettes against the reference.

Run from the repo root::

    .venv/bin/python benchmarks/measure_fill_ties.py [FRAMES]      # about 40 s at 4 frames, 2 cores

Every bundled scene (scenes/*.scene and scenes/examples/*.scene) under each default case camera
(oracles.cases), FRAMES frames (default 4) of the default spin (1, 1, 0): the reference
(oracles.references.fill_rule.coverage, every face, cut to near/far) with tie zones from 0 to
2^-6 px, pyrender's filled render (PyrenderOracle.render_faces, culling off) and core's
``--style shaded`` depth buffer (core.projector.pipeline.render_frame). Printed per zone: the
pixels where pyrender and core differ from the reference outside the ties, and the ties.
docs/depth.md ("Filled frames: the fill rule and ties") quotes the run at 4 frames.
"""

from __future__ import annotations

import sys

import numpy as np
from wirecheck.core.projector import pipeline
from wirecheck.core.scene.files import builtin_names, example_names, load_scene
from wirecheck.core.transforms import Motion
from wirecheck.oracles.cases import case_motion, cases_for
from wirecheck.oracles.references import faces as oface
from wirecheck.oracles.references import fill_rule
from wirecheck.oracles.references.pyrender_oracle import PyrenderOracle


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    frames = int(argv[0]) if argv else 4
    zones = [0.0, 2**-12, 2**-10, 2**-9, 2**-8, fill_rule.GL_TIE_PX, 2**-6]
    names = list(builtin_names()) + [f"scenes/examples/{n}.scene" for n in example_names()]
    oracles = {}
    motion0 = Motion(turns=(1.0, 1.0, 0.0))
    res = {z: [0, 0, 0] for z in zones}  # pyrender's decided differences, core's, ties
    n_frames, ref_px = 0, 0
    try:
        for name in names:
            scene = load_scene(name)
            tris, _owner = oface.fan(scene.faces)
            for case in cases_for(scene, motion0):
                cam, motion = case.camera, case_motion(motion0, case)
                key = (cam.width, cam.height)
                if key not in oracles:
                    oracles[key] = PyrenderOracle(*key)
                for k in range(frames):
                    p_world, _m, pr_vertices, pr_pose = oface.frame_geometry(scene, motion, k / frames)
                    gl, _depth = oracles[key].render_faces(pr_vertices, tris, cam, model_matrix=pr_pose, cull=False)
                    frame = pipeline.render_frame(
                        pr_vertices,
                        scene.edges,
                        cam,
                        np.eye(4) if pr_pose is None else pr_pose,
                        faces=scene.faces,
                        style="shaded",
                    )
                    core = np.isfinite(frame.depth_image)
                    tris_px, _z, _ = fill_rule.project_clipped(p_world, scene.faces, cam)
                    is_open = fill_rule.open_edges(tris_px)
                    for z in zones:
                        inside, ties = fill_rule.coverage(tris_px, (cam.height, cam.width), tie_px=z, is_open=is_open)
                        res[z][0] += int(((gl != inside) & ~ties).sum())
                        res[z][1] += int(((core != inside) & ~ties).sum())
                        res[z][2] += int(ties.sum())
                    n_frames += 1
                    ref_px += int(inside.sum())
    finally:
        for o in oracles.values():
            o.close()
    print(f"{n_frames} frames, {ref_px} reference pixels")
    for z in zones:
        print(
            f"tie zone {z:.6f} px: pyrender differs at {res[z][0]} decided pixels, core at {res[z][1]}; "
            f"{res[z][2]} ties"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
