"""Render a wirecheck job's depth maps, filled frames and wireframes with core, as a renderer's author would.

    python tests/clients/core_depth_job.py JOB_DIR [--mistake NAME]

Reads ``job.json``, the OBJ files (``v``, ``l``, ``f``) and each frame's camera JSON itself (numpy and json,
not wirecheck's job reader: the judge's own reader is what is tested) and draws every file the job lists
(``frames``, ``filled``, ``depth`` of each case) with core's renderer (``style="shaded"``: core's depth
buffer, linear ``z_cam``), written in the job's ``depth_encoding``. ``--mistake`` writes the depth maps
with one classic mistake (:data:`MISTAKES`: of the values; :data:`CAMERA_MISTAKES`: of a perspective camera's
K, the faces drawn through it), for the tests and docs/depth.md's sample.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

import numpy as np
from PIL import Image
from wirecheck.core.camera import Camera
from wirecheck.core.projector.pipeline import render_frame

if __package__:  # imported by the tests (clients.core_depth_job)
    from .job_files import read_obj_faces, write_depth
else:  # run as a script: its folder is on sys.path
    from job_files import read_obj_faces, write_depth


def window_depth(z: np.ndarray, cam: Camera) -> np.ndarray:
    """The GL depth buffer's value, glDepthRange [0, 1], of linear depth ``z`` (0 where none)."""
    n, f = cam.near, cam.far
    with np.errstate(divide="ignore", invalid="ignore"):
        w = f * (z - n) / ((f - n) * z) if cam.projection == "perspective" else (z - n) / (f - n)
    return np.where(z > 0, w, 0.0)


#: The mistakes ``--mistake`` injects into a depth map ``z`` (linear depth along forward, 0 where none).
MISTAKES = {
    "none": lambda z, cam: z,
    "zbuffer": window_depth,  # the depth buffer's [0, 1] value stored as depth
    "x1000": lambda z, cam: z * 1000.0,  # millimetres written where world units were asked
    "rows_flipped": lambda z, cam: z[::-1],  # GL's bottom row written first
}


def _half_pixel(cam: Camera) -> Camera:
    """The principal point at (W / 2, H / 2) instead of ((W - 1) / 2, (H - 1) / 2)."""
    fx, fy = cam.focal_xy
    return cam.with_intrinsics(fx, fy, cam.width / 2, cam.height / 2)


def _fov_horizontal(cam: Camera) -> Camera:
    """K from the FOV taken as the horizontal one: f = (W / 2) / tan(fov / 2) on both axes."""
    f = (cam.width / 2) / math.tan(math.radians(cam.fov_y_deg) / 2)
    return cam.with_intrinsics(f, f)


#: Camera mistakes ``--mistake`` draws the depth maps with (perspective cameras only: the others draw as asked).
CAMERA_MISTAKES = {"half_pixel": _half_pixel, "fov_horizontal": _fov_horizontal}


def frames(job_dir: Path):
    """Every frame of the job: ``(case row, index in its lists, camera, p_model, edges, faces, model_matrix)``."""
    job = json.loads((job_dir / "job.json").read_text())
    scenes = {s["name"]: s for s in job["scenes"]}
    for c in job["cases"]:
        scene = scenes[c["scene"]]
        for i, k in enumerate(job["frame_numbers"]):
            obj = scene["obj"] if scene["space"] == "model" else f"scenes/{c['scene']}/frame_{k:04d}.obj"
            v, e, f = read_obj_faces(job_dir / obj)
            cam_json = json.loads((job_dir / f"cameras/{c['scene']}/{c['case']}/frame_{k:04d}.json").read_text())
            yield c, i, Camera(**cam_json["camera"]), v, e, f, np.array(cam_json["model_matrix"])


def render_job(
    job_dir, mistake=MISTAKES["none"], filled=lambda covered: covered, camera=None, object_ids=lambda objects: objects
) -> None:
    """Write every file the job lists (module docstring); ``mistake(z, camera)`` makes each depth map from core's
    depth, ``filled(covered)`` each filled frame's surface from core's; ``camera`` (one of
    :data:`CAMERA_MISTAKES`) changes a perspective camera before the faces are drawn. A filled frame of a
    scene of several objects (job.json's ``objects``: vertex counts) holds grey level ``1 + object_ids(o)``
    where core shows object ``o``; of one object, 200."""
    job_dir = Path(job_dir)
    job = json.loads((job_dir / "job.json").read_text())
    enc = job.get("depth_encoding") or {}
    counts = {s["name"]: s.get("objects", [s["vertices"]]) for s in job["scenes"]}
    for c, i, cam, v, e, f, m in frames(job_dir):
        drawn = camera(cam) if camera is not None and cam.projection == "perspective" else cam
        frame = render_frame(v, e, drawn, m, faces=f, style="shaded")
        z = np.where(np.isfinite(frame.depth_image), frame.depth_image, 0.0)
        stops = np.cumsum(counts[c["scene"]])
        face_object = np.searchsorted(stops, [face[0] for face in f], side="right")
        seen = np.where(frame.face_ids >= 0, face_object[np.maximum(frame.face_ids, 0)], -1)
        level = np.where(seen >= 0, 1 + object_ids(seen), 0) if len(stops) > 1 else np.full(z.shape, 200)
        for key, write in (
            ("frames", lambda p: Image.fromarray(render_frame(v, e, cam, m).image).save(p)),
            ("filled", lambda p: Image.fromarray(np.where(filled(z > 0), level, 0).astype(np.uint8)).save(p)),
            ("depth", lambda p: write_depth(p, mistake(z, cam), enc)),
        ):
            for rel in (c.get(key) or [])[i : i + 1]:
                (job_dir / rel).parent.mkdir(parents=True, exist_ok=True)
                write(job_dir / rel)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("job")
    p.add_argument("--mistake", choices=sorted(MISTAKES) + sorted(CAMERA_MISTAKES), default="none")
    args = p.parse_args(argv)
    render_job(Path(args.job), MISTAKES.get(args.mistake, MISTAKES["none"]), camera=CAMERA_MISTAKES.get(args.mistake))
    return 0


if __name__ == "__main__":
    sys.exit(main())
