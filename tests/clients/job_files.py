"""Reading a wirecheck frames job as a renderer's author would: its OBJ files and each frame's camera JSON.

Shared by the test clients in this folder (each a renderer of its own); only
numpy and the job's files, nothing of wirecheck (its own reader is
``wirecheck.oracles.candidates.frames_candidate.read_obj``: a client that used
it would not be independent of the judge).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np


def read_obj(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """The OBJ's ``v`` vertices ``(N, 3)`` and ``l`` edges ``(K, 2)``, 0-based."""
    verts, edges = [], []
    for line in path.read_text().splitlines():
        parts = line.split()
        if parts and parts[0] == "v":
            verts.append([float(x) for x in parts[1:4]])
        elif parts and parts[0] == "l":
            edges.append([int(x) - 1 for x in parts[1:3]])
    return np.array(verts).reshape(-1, 3), np.array(edges, dtype=int).reshape(-1, 2)


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
        model = scene["space"] == "model"
        for rel in c["frames"]:
            k = int(Path(rel).stem.split("_")[-1])
            obj = scene["obj"] if model else f"scenes/{c['scene']}/frame_{k:04d}.obj"
            v, e = read_obj(job_dir / obj)
            cam = json.loads((job_dir / f"cameras/{c['scene']}/{c['case']}/frame_{k:04d}.json").read_text())
            yield c, job_dir / rel, v, e, cam, model
