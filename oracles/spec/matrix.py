"""The specification's test matrix: 2 scenes x 2 camera distances x 2 FOVs x 3 frame counts = 24 runs.

Each run is one case of :func:`oracles.runner.run_crosscheck` (the candidate
against OpenCV's vertices and pyrender's pixels, judged and named as any case),
under a camera placed as the specification and ``renderer --camera-z D --fov F``
place it: at (0, 0, D) looking at the origin, up +Y, 640x480, near 0.1, far 100;
the scene turning once about X and once about Y over the run (the renderer's
default spin), frames 1..N at t = (k - 1) / N.

    scene            what (scenes/examples/, loaded by name)
    unit_cube        A: a unit cube (side 1) centred at the origin
    offset_pyramid   B: a pyramid (base side 1, height 1) translated by (0.5, 0.25, -0.5)

The bundled ``cube`` has side 2 (corners at +-1, NDC's cube); the
specification's unit cube is its own scene. Both scenes are examples, not
built-ins, so the main job's scene list and counts are unchanged.
"""

from __future__ import annotations

from wirecheck.core.camera import look_at
from wirecheck.core.scene.files import load_scene

from ..cases import Case
from ..runner import run_crosscheck
from ..tolerances import Tolerances

#: The specification's scenes (A, B), its camera distances, FOVs (degrees, vertical) and frame counts.
SCENES = ("unit_cube", "offset_pyramid")
CAMERA_Z = (3.0, 6.0)
FOVS = (60.0, 90.0)
FRAME_COUNTS = (1, 30, 180)
#: The renderer's default spin: one full turn about X and one about Y over each run.
TURNS = (1.0, 1.0, 0.0)
#: The renderer's default camera otherwise (``renderer --help``).
CAMERA = {"width": 640, "height": 480, "near": 0.1, "far": 100.0}

#: Runs in the matrix: every scene x distance x FOV x frame count.
RUNS = len(SCENES) * len(CAMERA_Z) * len(FOVS) * len(FRAME_COUNTS)


def case_name(z: float, fov: float) -> str:
    """``z3_fov60``: a camera of the matrix by its distance and FOV."""
    return f"z{z:g}_fov{fov:g}"


def spec_cases() -> tuple[Case, ...]:
    """The four cameras of the matrix, each at (0, 0, z) looking at the origin (``renderer --camera-z z --fov F``)."""
    return tuple(
        Case(case_name(z, fov), look_at((0.0, 0.0, z), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0), fov_y_deg=fov, **CAMERA))
        for z in CAMERA_Z
        for fov in FOVS
    )


def run_matrix(
    candidate, level: str = "pixels", candidate_name: str = "core", progress=None, precision: str | None = None
) -> dict:
    """The 24 runs: ``{"runs": [record...], "compared": totals, "oracle_gl", "seconds"}``.

    Each record is a crosscheck case record (oracles.judge.verdict) with
    ``"frames"`` and ``"run"`` (``scene/camera/frames``) added, in matrix order
    (frame count, then scene, then camera). ``progress(done, total)`` after each
    frame count. ``precision``: the candidate's declared precision (``--candidate-precision``;
    default: the dtype it returns).
    """
    scenes = [load_scene(name) for name in SCENES]
    runs, gl, seconds = [], None, 0.0
    totals = {"cases": 0, "frames": 0, "vertices": 0, "pixels": 0 if level == "pixels" else None}
    for i, frames in enumerate(FRAME_COUNTS):
        report, _ = run_crosscheck(
            scenes,
            candidate,
            frames=frames,
            level=level,
            turns=TURNS,
            tol=Tolerances(precision=precision),
            candidate_name=candidate_name,
            animation=False,
            cases=spec_cases(),
        )
        gl = gl or report["oracle_gl"]
        seconds += report["timing"]["wall_s"]
        for key in ("cases", "frames", "vertices"):
            totals[key] += report["compared"][key]
        if level == "pixels":
            totals["pixels"] += report["compared"]["pixels"]
        for record in report["cases"]:
            record.pop("framing")  # the camera is placed by the specification (camera_spec), not framed
            runs.append({"run": f"{record['scene']}/{record['camera']}/{frames}", "frames": frames, **record})
        if progress:
            progress(i + 1, len(FRAME_COUNTS))
    return {"runs": runs, "compared": totals, "oracle_gl": gl, "seconds": seconds}
