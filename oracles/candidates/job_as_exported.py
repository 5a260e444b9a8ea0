"""A frames job's JSON held to what ``crosscheck export`` writes: every key, and every camera field.

A camera JSON says one camera several ways: the candidate contract's fields
(``camera``), OpenCV's ``K``, ``R``, ``t_cv``, GL's ``gl_view`` and
``gl_projection``, ``right``, with the frame's ``model_matrix``. The judge
draws from ``camera`` and ``model_matrix``; a renderer from any of them. A file
edited in one place only (``K``, a missing ``near`` that the camera's default
would fill, a camera copied over another frame's) would have the renderer and
the judge draw different pictures from one file, and the renderer blamed. So a
frame's camera JSON must be :func:`oracles.candidates.export.camera_json` of
its own camera and model matrix, and a ``job.json`` must hold the keys export
writes, no more (a typo'd key is otherwise read as absent). Each problem is
one phrase naming the field, its value and the value expected.
"""

from __future__ import annotations

import difflib
import functools

import numpy as np
from wirecheck.core.camera import Camera
from wirecheck.core.scene.files import load_scene

#: Relative tolerance of a camera JSON's numbers against export's, of max(1, |expected|): the numbers are
#: recomputed from the file's own camera (its JSON floats round-trip exactly) by a few dozen float64
#: operations (normalising, a cross product, a tangent, 4x4 products), within ~1e-14 relative; a value
#: edited by less than 1e-9 moves a point by under 1e-9 x 16384 px (the largest side) < 2e-5 px.
REL_TOL = 1e-9


def _keys_problem(where: str, keys, expected, required=None) -> str | None:
    """An unknown key (with the nearest expected one) or a missing one of ``required`` (default: all)."""
    prefix = f"{where}: " if where else ""
    for key in keys:
        if key not in expected:
            close = difflib.get_close_matches(str(key), list(expected), n=1)
            hint = f" (did you mean {close[0]!r}?)" if close else ""
            return f"{prefix}unknown key {str(key)[:40]!r}{hint}: expected {', '.join(expected)}"
    for key in expected if required is None else required:
        if key not in keys:
            return f"{prefix}no {key!r}: expected {', '.join(expected)}"
    return None


@functools.lru_cache(maxsize=1)
def exported_keys() -> dict:
    """The keys of a job.json export writes: ``{"job", "scene", "case", "motion"}`` -> tuple of keys, from a
    one-frame job of the cube with a phase (so that ``motion.phase`` is there), built in memory."""
    from .export import build_job

    job, _files = build_job([load_scene("cube")], frames=1, case_names=["on_axis"], phase=0.5)
    full, _files = build_job(
        [load_scene("cube")], frames=1, case_names=["on_axis"], phase=0.5, outputs=("wireframe", "filled", "depth")
    )
    return {
        "job": tuple(job),
        "scene": tuple(job["scenes"][0]),
        "case": tuple(job["cases"][0]),
        "motion": tuple(job["motion"]),
        "outputs_job": tuple(full),
        "outputs_case": tuple(full["cases"][0]),
        "outputs_scene": tuple(full["scenes"][0]),
    }


def job_keys_problem(job: dict) -> str | None:
    """What key of a ``job.json`` (top level, ``motion``, each scene and case row) is not export's; None if none.

    ``motion.phase`` may be absent (export writes it only for a phase other than 0). A job with
    ``outputs`` (filled frames, depth maps: oracles.candidates.export.OUTPUTS) holds the keys export
    writes for one, every case its ``filled`` and ``depth`` lists; a job without holds none of them."""
    keys = exported_keys()
    outputs = "outputs" in job
    problem = _keys_problem("", job, keys["outputs_job" if outputs else "job"])
    if problem is None and isinstance(job.get("motion"), dict):
        problem = _keys_problem("motion", job["motion"], keys["motion"], required=("turns",))
    for what in ("scene", "case"):
        rows = job.get(what + "s")
        expected = keys[f"outputs_{what}"] if outputs else keys[what]
        for i, row in enumerate(rows if isinstance(rows, list) else []):
            if problem is None and isinstance(row, dict):
                problem = _keys_problem(f"{what}s[{i}]", row, expected)
    return problem


def camera_keys_problem(cam_json) -> str | None:
    """Whether a camera JSON is an object whose ``camera`` holds the contract's keys (``intrinsics`` optional,
    as export writes it for a calibrated camera only); None when it does or has no ``camera`` object
    (left to the reading, which names it)."""
    if not isinstance(cam_json, dict):
        return f"a JSON {type(cam_json).__name__}: expected the object 'crosscheck export' wrote"
    if not isinstance(cam_json.get("camera"), dict):
        return None
    contract = tuple(Camera((0.0, 0.0, 1.0), (0.0, 0.0, -1.0), (0.0, 1.0, 0.0)).to_dict())
    cam = cam_json["camera"]
    problem = _keys_problem("camera", cam, contract + ("intrinsics",), required=contract)
    for key, value in cam.items():
        expected = _CAMERA_TYPES.get(key)
        if problem is None and expected is not None and not _is_type(value, expected):
            problem = f"camera.{key} {_short(value)}: expected {expected}"
    return problem


#: What each camera field holds, as export writes it (core.camera.Camera.to_dict).
_CAMERA_TYPES = {
    "position": "3 numbers",
    "forward": "3 numbers",
    "up": "3 numbers",
    "fov_y_deg": "a number",
    "width": "an integer",
    "height": "an integer",
    "near": "a number",
    "far": "a number",
    "projection": "a string",
    "ortho_height": "a number",
    "intrinsics": "4 numbers",
}


def _is_number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _is_type(value, expected: str) -> bool:
    if expected.endswith(" numbers"):
        n = int(expected.split()[0])
        return isinstance(value, list) and len(value) == n and all(_is_number(v) for v in value)
    if expected == "an integer":
        return _is_number(value) and isinstance(value, int)
    return _is_number(value) if expected == "a number" else isinstance(value, str)


def camera_file_problem(
    cam_json: dict, camera, model: np.ndarray, job: dict, scene: str, case: str, k: int
) -> str | None:
    """How a frame's camera JSON differs from what export writes for its camera and model matrix; None if not.

    ``camera`` and ``model`` are those read from the file; the model matrix must be affine (its last row
    ``[0, 0, 0, 1]``): the oracles use its top three rows, a GL renderer all four.
    """
    if not np.array_equal(model[3], [0.0, 0.0, 0.0, 1.0]) or any(
        isinstance(v, bool) for v in cam_json["model_matrix"][3]
    ):
        return (
            f"model_matrix[3] {[float(v) for v in model[3]]}: expected [0.0, 0.0, 0.0, 1.0] (an affine model "
            "matrix: the oracles use its top three rows)"
        )
    phase = job["motion"].get("phase", 0.0)
    return _differs("", cam_json, _expected(camera, model, scene, case, k, job["frames"], phase))


#: The last camera's export JSON: a case's frames share one Camera object (oracles.candidates.frames_candidate
#: makes it once while the file's ``camera`` is unchanged), so its matrices are computed once a case.
_LAST: dict = {}


def _expected(camera, model, scene: str, case: str, k: int, frames: int, phase: float) -> dict:
    """:func:`oracles.candidates.export.camera_json` of these arguments; for the camera of the last call, that
    call's JSON with the fields of the other arguments (frame, time, model matrix, names) replaced: the rest
    are the camera's alone."""
    from .export import camera_json, frame_time, matrix_rows

    if _LAST.get("camera") is not camera:
        _LAST.update(camera=camera, json=camera_json(camera, model, scene, case, k, frames, phase))
        return _LAST["json"]
    return {
        **_LAST["json"],
        "scene": scene,
        "case": case,
        "frame": k,
        "t": frame_time(k, frames, phase),
        "model_matrix": matrix_rows(model),
    }


def _differs(where: str, value, expected) -> str | None:
    """The first place where ``value`` (a file's JSON) is not ``expected`` (export's), as a phrase; None if none."""
    if isinstance(expected, dict):
        if not isinstance(value, dict):
            return f"{where} {_short(value)}: expected an object"
        problem = _keys_problem(where, value, tuple(expected))
        for key in expected:
            problem = problem or _differs(f"{where}.{key}" if where else key, value[key], expected[key])
        return problem
    if isinstance(expected, list):
        if not (isinstance(value, list) and len(value) == len(expected)):
            return f"{where} {_short(value)}: expected {len(expected)} values"
        for i, (v, e) in enumerate(zip(value, expected)):
            problem = _differs(f"{where}[{i}]", v, e)
            if problem:
                return problem
        return None
    if isinstance(expected, (int, float)) and not isinstance(expected, bool):
        number = isinstance(value, (int, float)) and not isinstance(value, bool)
        if isinstance(expected, int) and not isinstance(value, int):
            number = False  # a count or a size: an integer, as export writes it
        if number and abs(value - expected) <= REL_TOL * max(1.0, abs(expected)):
            return None
        return f"{where} {_short(value)}: expected {expected!r}"
    return None if value == expected else f"{where} {_short(value)}: expected {expected!r}"


def _short(value) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."
