"""Reading a wirecheck frames job as a renderer's author would: its OBJ files and each frame's camera JSON;
writing a depth map in the job's encoding.

Shared by the test clients in this folder (each a renderer of its own); only
numpy, Pillow and the job's files, nothing of wirecheck (its own reader is
``wirecheck.oracles.candidates.frames_candidate.read_obj``: a client that used
it would not be independent of the judge).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np


def read_obj_faces(path: Path) -> tuple[np.ndarray, np.ndarray, list]:
    """The OBJ's ``v`` vertices ``(N, 3)``, ``l`` edges ``(K, 2)`` and ``f`` faces (tuples), 0-based."""
    verts, edges, faces = [], [], []
    for line in path.read_text().splitlines():
        parts = line.split()
        if parts and parts[0] == "v":
            verts.append([float(x) for x in parts[1:4]])
        elif parts and parts[0] == "l":
            edges.append([int(x) - 1 for x in parts[1:3]])
        elif parts and parts[0] == "f":
            faces.append(tuple(int(x) - 1 for x in parts[1:]))
    return np.array(verts).reshape(-1, 3), np.array(edges, dtype=int).reshape(-1, 2), faces


def read_obj(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """The OBJ's ``v`` vertices ``(N, 3)`` and ``l`` edges ``(K, 2)``, 0-based."""
    verts, edges, _faces = read_obj_faces(path)
    return verts, edges


def _obj_path(scene: dict, k: int) -> str:
    """The OBJ of frame ``k``: the scene's one model-space OBJ, or its world-space OBJ of that frame."""
    return scene["obj"] if scene["space"] == "model" else f"scenes/{scene['name']}/frame_{k:04d}.obj"


def _camera(job_dir: Path, c: dict, k: int) -> dict:
    return json.loads((job_dir / f"cameras/{c['scene']}/{c['case']}/frame_{k:04d}.json").read_text())


def job_frames(job_dir: Path):
    """Every frame ``job.json`` lists, in its order: ``(case, png path, vertices, edges, camera json, model?)``.

    ``model``: the vertices are ``p_model`` (one OBJ per scene, posed by the
    camera JSON's ``model_matrix``); else ``p_world`` (an OBJ per frame).
    """
    job_dir = Path(job_dir)
    job = json.loads((job_dir / "job.json").read_text())
    scenes = {s["name"]: s for s in job["scenes"]}
    for c in job["cases"]:
        scene = scenes[c["scene"]]
        for rel in c["frames"]:
            k = int(Path(rel).stem.split("_")[-1])
            v, e = read_obj(job_dir / _obj_path(scene, k))
            yield c, job_dir / rel, v, e, _camera(job_dir, c, k), scene["space"] == "model"


def job_surfaces(job_dir: Path):
    """Every frame of a job that asks for filled frames or depth maps, as the job's README says to render it:
    ``(case, camera json, p_world (N, 3), triangles (T, 3), object of each triangle (T,), files)``.

    ``p_world = model_matrix @ [v, 1]`` (the camera JSON's; the identity for a scene whose OBJ is in world
    space per frame); each ``f`` face fanned into triangles from its first vertex; a face's object is its
    first vertex's, from the scene's ``objects`` (vertex counts in the OBJ's order), 0 for the first;
    ``files``: ``{"filled": path or None, "depth": path or None}``, the paths job.json lists for the frame
    (``job["frame_numbers"]`` give each list's order)."""
    job_dir = Path(job_dir)
    job = json.loads((job_dir / "job.json").read_text())
    scenes = {s["name"]: s for s in job["scenes"]}
    for c in job["cases"]:
        scene = scenes[c["scene"]]
        stops = np.cumsum(scene["objects"])
        for i, k in enumerate(job["frame_numbers"]):
            v, _e, faces = read_obj_faces(job_dir / _obj_path(scene, k))
            cam = _camera(job_dir, c, k)
            p_world = (np.asarray(cam["model_matrix"], dtype=np.float64) @ np.c_[v, np.ones(len(v))].T).T[:, :3]
            triangles = np.array([(f[0], f[j], f[j + 1]) for f in faces for j in range(1, len(f) - 1)]).reshape(-1, 3)
            objects = np.searchsorted(stops, triangles[:, 0], side="right")
            files = {key: (job_dir / c[key][i] if c.get(key) else None) for key in ("filled", "depth")}
            yield c, cam, p_world, triangles, objects, files


def write_depth(path: Path, depth: np.ndarray, encoding: dict) -> None:
    """Write a depth map (world units, 0 where no surface) in job.json's ``depth_encoding``: ``npy`` float32,
    ``png16`` ``round(depth x scale)`` as 16-bit grey, ``tiff`` 32-bit float (Pillow's mode F)."""
    from PIL import Image

    path.parent.mkdir(parents=True, exist_ok=True)
    if encoding["format"] == "npy":
        np.save(path, depth.astype(np.float32))
    elif encoding["format"] == "png16":  # rounded to the scale's step, as BOP's writers do
        Image.fromarray(np.rint(depth * encoding["scale"]).astype(np.uint16)).save(path)
    else:
        Image.fromarray(depth.astype(np.float32), mode="F").save(path)
