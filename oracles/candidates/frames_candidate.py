"""``crosscheck --candidate-frames DIR``: a renderer's frames job, read and checked.

``DIR`` is a job written by :mod:`oracles.candidates.export` with the renderer's PNGs
under ``frames/`` (and, for a job that asks for them, its filled frames and depth maps
there too: job.json's ``filled`` and ``depth`` of each case). This module reads and checks the job (its manifest, OBJ,
cameras and frames); :mod:`oracles.judge.frames_judge` judges the frames, one at a
time, by the one judge of every path (:mod:`oracles.judge.decide`).

A gate never passes on nothing: the job must list cases and frames, every
listed frame must be there at its camera's size and readable, and a PNG under
``frames/`` that the job does not list is refused too (frames of another
job). Each problem is one line of :class:`FramesError` (exit 2).
"""

from __future__ import annotations

import json
import math
import os
from pathlib import Path

import numpy as np
from wirecheck.core.camera import Camera
from wirecheck.core.errors import InputError
from wirecheck.core.limits import MAX_FRAMES, check_image_size
from wirecheck.core.scene.files import NAME_PATTERN
from wirecheck.core.user_files import read_text

from .depth_map import DEFAULT_PNG_SCALE, read_depth_map
from .export import DEPTH_FORMATS, JOB_KIND, JOB_VERSION, OUTPUTS, frame_name, job_outputs, output_files
from .job_as_exported import camera_file_problem, camera_keys_problem, job_keys_problem
from .png_frame import FrameProblem, check_png, escape_controls, file_problem, read_grey, read_png  # noqa: F401 (read_png re-exported)

#: Problem lines shown before "... and N more".
MAX_LINES = 20
#: Entries walked under ``frames/`` before the walk stops: a job lists at most
#: MAX_FRAMES frames per case, and links between folders must not make the walk unbounded.
MAX_WALK = 200_000


class FramesError(InputError):
    """The job or its frames cannot be judged: one line per problem."""

    def __init__(self, problems: list[str]):
        self.problems = problems = [escape_controls(p) for p in problems]  # a file name may hold an ESC
        shown = problems[:MAX_LINES]
        more = len(problems) - len(shown)
        super().__init__("\n".join(shown + ([f"... and {more} more"] if more else [])))

    def __str__(self) -> str:  # one line per problem, kept apart (InputError joins lines into one)
        return Exception.__str__(self)


def _no_duplicate_keys(pairs: list) -> dict:
    """``json.loads``' object hook: a key given twice is a ValueError (JSON keeps the last one, silently)."""
    out = {}
    for key, value in pairs:
        if key in out:
            raise ValueError(f"key {key!r} given twice")
        out[key] = value
    return out


def read_json(path: Path, kind: str = "job"):
    """The JSON of a job file (UTF-8, a BOM allowed; ``kind`` "job" or "camera", core.user_files.LIMITS);
    ValueError for a key given twice, a file that is not regular or over the limit."""
    return json.loads(read_text(path, kind), object_pairs_hook=_no_duplicate_keys)


def load_job(job_dir: Path) -> dict:
    """The manifest ``DIR/job.json``, checked; FramesError otherwise."""
    path = Path(job_dir) / "job.json"
    if not Path(job_dir).is_dir():
        raise FramesError(
            [
                f"--candidate-frames {str(job_dir)!r}: not a directory: expected a job folder "
                "written by 'crosscheck export'"
            ]
        )
    problem = file_problem(path, "job")
    if problem is not None:
        raise FramesError([f"{path}: {problem}: expected a job folder written by 'crosscheck export'"])
    try:
        job = read_json(path)
    except (OSError, ValueError, RecursionError) as exc:  # RecursionError: arrays nested 100,000 deep
        raise FramesError([f"{path}: unreadable ({exc}): expected the JSON 'crosscheck export' wrote"]) from None
    if not isinstance(job, dict) or job.get("kind") != JOB_KIND:
        raise FramesError(
            [f"{path}: not a wirecheck frames job (kind {job.get('kind') if isinstance(job, dict) else None!r})"]
        )
    if job.get("version") != JOB_VERSION or not _is_int(job.get("version")):
        raise FramesError([f"{path}: job version {job.get('version')!r}: expected {JOB_VERSION} (export it again)"])
    if not job.get("cases"):
        raise FramesError([f"{path}: the job lists no frames: nothing to judge"])
    problem = job_keys_problem(job) or _job_problem(job)
    if problem is not None:
        raise FramesError([f"{path}: {problem} (export the job again)"])
    return job


def _is_int(value) -> bool:
    return isinstance(value, int) and not isinstance(value, bool)


def _job_problem(job: dict) -> str | None:
    """What in a job.json is not as ``crosscheck export`` writes it, in one phrase; None when all is.

    A job is hand-editable JSON: every field the judging reads is checked here,
    so that an edited or damaged one is a usage error naming the field, never a
    crash later or numbers in the report that mean nothing.
    """
    frames, every = job.get("frames"), job.get("every")
    if not (_is_int(frames) and 1 <= frames <= MAX_FRAMES):
        return f"frames {frames!r}: expected an integer in 1..{MAX_FRAMES}"
    if not (_is_int(every) and 1 <= every <= frames):
        return f"every {every!r}: expected an integer in 1..frames ({frames})"
    checked = list(range(1, frames + 1, every))
    if job.get("frame_numbers") != checked:
        return f"frame_numbers {str(job.get('frame_numbers'))[:60]}: expected 1, 1+every, ... up to frames"
    turns = (job.get("motion") or {}).get("turns") if isinstance(job.get("motion"), dict) else None
    if not (
        isinstance(turns, list)
        and len(turns) == 3
        and all(isinstance(t, (int, float)) and not isinstance(t, bool) and np.isfinite(t) for t in turns)
    ):
        return f"motion.turns {turns!r}: expected three finite numbers"
    phase = job["motion"].get("phase", 0.0)
    if not (isinstance(phase, (int, float)) and not isinstance(phase, bool) and 0.0 <= phase < 1.0):
        return f"motion.phase {phase!r}: expected a number in [0, 1) (crosscheck export --phase)"
    if job.get("style") != "wireframe":
        return f"style {job.get('style')!r}: expected 'wireframe' (the frames judged are wireframes)"
    problem = _outputs_problem(job)
    if problem is not None:
        return problem
    outputs = job_outputs(job)
    scenes, cases = job.get("scenes"), job.get("cases")
    if not (isinstance(scenes, list) and scenes and all(isinstance(r, dict) for r in scenes)):
        return "scenes: expected a list of the job's scenes"
    names = set()
    for r in scenes:
        name, obj = r.get("name"), r.get("obj")
        if not (isinstance(name, str) and NAME_PATTERN.fullmatch(name)) or name in names:
            return f"scene name {name!r}: expected a name of letters, digits, '_', '.', '-', each scene once"
        names.add(name)
        expected = {"model": f"scenes/{name}.obj", "world per frame": f"scenes/{name}/frame_NNNN.obj"}
        if expected.get(r.get("space")) != obj:
            return (
                f"scene {name!r}: space {r.get('space')!r}, obj {obj!r}: expected space 'model' with "
                f"obj {expected['model']!r}, or 'world per frame' with {expected['world per frame']!r}"
            )
        if r.get("space") == "model" and not all(
            _is_int(r.get(k)) and r[k] >= 0 for k in ("vertices", "edges", "faces")
        ):
            return (
                f"scene {name!r}: vertices {r.get('vertices')!r}, edges {r.get('edges')!r}, faces "
                f"{r.get('faces')!r}: expected counts"
            )
        objects = r.get("objects")
        if "outputs" in job and not (
            isinstance(objects, list)
            and objects
            and all(_is_int(n) and n > 0 for n in objects)
            and sum(objects) == r.get("vertices")
        ):
            return (
                f"scene {name!r}: objects {str(objects)[:60]}: expected each object's vertex count (> 0), "
                f"{r.get('vertices')!r} in all"
            )
    if not (isinstance(cases, list) and all(isinstance(c, dict) for c in cases)):
        return "cases: expected a list of the job's cases"
    pairs = set()
    for c in cases:
        scene, case, w, h = c.get("scene"), c.get("case"), c.get("width"), c.get("height")
        if (
            not isinstance(scene, str)
            or scene not in names
            or not (isinstance(case, str) and NAME_PATTERN.fullmatch(case))
        ):
            return f"case {scene!r} / {case!r}: expected a scene of 'scenes' and a case name"
        if (scene, case) in pairs:  # judged twice, it would count twice in the summary
            return f"case {scene} / {case}: listed twice: expected each case once"
        pairs.add((scene, case))
        if not (_is_int(w) and _is_int(h)):
            return f"case {scene} / {case}: width {w!r}, height {h!r}: expected integers"
        try:
            check_image_size(w, h, f"case {scene} / {case}: width x height")
        except InputError as exc:
            return str(exc)
        written = output_files(scene, case, checked, outputs, (job.get("depth_encoding") or {}).get("format", "npy"))
        for key in ("frames", "filled", "depth") if "outputs" in job else ("frames",):
            if c.get(key) != written[key]:
                pattern = (
                    f"frames/{scene}/{case}/{Path(written[key][0]).stem.split('_')[0]}_NNNN"
                    f"{Path(written[key][0]).suffix} for each of frame_numbers"
                    if written[key]
                    else "[] (the job's outputs do not ask for them)"
                )
                return f"case {scene} / {case}: {key} {str(c.get(key))[:80]}: expected {pattern}"
    return None


def _outputs_problem(job: dict) -> str | None:
    """What in a job's ``outputs`` and ``depth_encoding`` is not as export writes them; None if all is
    (a job without ``outputs`` asks for wireframes alone)."""
    if "outputs" not in job:
        return None
    outputs = job["outputs"]
    if not (
        isinstance(outputs, list)
        and outputs
        and all(isinstance(o, str) for o in outputs)
        and outputs == [o for o in OUTPUTS if o in outputs]
    ):
        return (
            f"outputs {str(outputs)[:60]}: expected some of {', '.join(map(repr, OUTPUTS))}, each once, in that order"
        )
    if outputs == ["wireframe"]:
        return "outputs ['wireframe']: expected no 'outputs' key for a job of wireframes alone"
    enc = job.get("depth_encoding")
    fmt = enc.get("format") if isinstance(enc, dict) else None
    if not (
        isinstance(enc, dict) and set(enc) == {"format", "scale"} and isinstance(fmt, str) and fmt in DEPTH_FORMATS
    ):
        return f"depth_encoding {str(enc)[:60]}: expected {{'format': one of {', '.join(DEPTH_FORMATS)}, 'scale': ...}}"
    scale = enc["scale"]
    if fmt == "png16":
        if not (
            isinstance(scale, (int, float))
            and not isinstance(scale, bool)
            and np.isfinite(scale)
            and scale > 0
            and np.isfinite(65535.0 / scale)
        ):
            return (
                f"depth_encoding.scale {scale!r}: expected a finite number of values per world unit > 0 "
                "(crosscheck export --depth-scale; 1000: millimetres per metre)"
            )
    elif scale is not None:
        return f"depth_encoding.scale {scale!r} with format {fmt!r}: expected null (a scale is a 16-bit PNG's)"
    return None


def _walk(frames_dir: Path) -> list[Path]:
    """Every entry under ``frames_dir`` that is not a folder; links to folders followed, a link loop is not.

    A folder is not entered again below itself (a loop); the walk stops with a
    FramesError past :data:`MAX_WALK` entries. A folder that cannot be listed
    is skipped: its listed frames are reported one by one.
    """
    out, n = [], 0
    stack = [(frames_dir, frozenset())]
    while stack:
        folder, above = stack.pop()
        try:
            st = folder.stat()
            key = (st.st_dev, st.st_ino)
            if key in above:
                continue
            with os.scandir(folder) as it:
                items = sorted(it, key=lambda e: e.name)
        except OSError:
            continue
        for item in items:
            n += 1
            if n > MAX_WALK:
                raise FramesError(
                    [
                        f"{frames_dir}: more than {MAX_WALK:,} files and folders: expected the "
                        f"job's frames (frames/<scene>/<case>/frame_NNNN.png); the walk was in {folder} "
                        "(a link to a folder elsewhere?)"
                    ]
                )
            try:
                is_dir = item.is_dir()
            except OSError:
                is_dir = False
            if is_dir:
                stack.append((Path(item.path), above | {key}))
            else:
                out.append(Path(item.path))
    return out


def load_frames(job_dir: Path, job: dict) -> dict:
    """Every listed frame as a grey image (oracles.candidates.png_frame.read_grey): ``{(scene, case): [(k, image)]}``;
    FramesError listing every problem."""
    return _frames(job_dir, job, keep=True)


def check_frames(job_dir: Path, job: dict, decode: bool = True) -> None:
    """:func:`load_frames`' checks, every frame read and dropped (memory flat in the job's length).

    ``decode=False``: every check but the decoding of the pixels (the files, their PNG headers and
    sizes, the frames of another job): the judge then decodes each frame once, as it judges it, and
    calls this again with ``decode=True`` on a frame it cannot decode, so that the same problems are
    listed as a full check would list them (:func:`read_frame`).
    """
    _frames(job_dir, job, keep=False, decode=decode)


def _frames(job_dir: Path, job: dict, keep: bool, decode: bool = True) -> dict:
    job_dir = Path(job_dir)
    frames_dir = job_dir / "frames"
    if not frames_dir.is_dir():
        problem = file_problem(frames_dir)
        raise FramesError(
            [
                f"{frames_dir}: {problem or 'a file, not a folder'}: the renderer's frames go there "
                "(frames/<scene>/<case>/frame_NNNN.png; see README.md)"
            ]
        )
    found = {p.relative_to(job_dir).as_posix() for p in _walk(frames_dir)}
    if not found:
        raise FramesError(
            [
                f"{frames_dir}: empty: expected the renderer's frames "
                "(frames/<scene>/<case>/frame_NNNN.png; see README.md)"
            ]
        )
    listed = {f for c in job["cases"] for f in case_files(c)}
    if not found & listed:
        example = sorted(found)[0]
        raise FramesError(
            [
                f"{frames_dir}: none of its {len(found)} files is a frame of this job "
                f"(e.g. {example}; expected e.g. {sorted(listed)[0]}): frames of another job?"
            ]
        )
    problems = [
        f"{job_dir / rel}: not a frame of this job (expected only the files job.json lists)"
        for rel in sorted(found - listed)
    ]
    out = {}
    scale = (job.get("depth_encoding") or {}).get("scale") or DEFAULT_PNG_SCALE
    for c in job["cases"]:
        images = []
        for rel in case_files(c):
            path = job_dir / rel
            k = int(Path(rel).stem.split("_")[-1])
            problem = file_problem(path, "depth map" if rel in c.get("depth", ()) else "frame")
            if problem is not None:
                problems.append(f"{path}: {problem} (frame {k} of {c['scene']} / {c['case']})")
                continue
            try:
                if rel in c.get("depth", ()):  # its size and encoding, read as the judge will read it
                    if decode:
                        read_depth_map(path, c["width"], c["height"], scale)
                    continue
                if not decode:
                    check_png(path, c["width"], c["height"])
                    continue
                image = read_grey(path, c["width"], c["height"])
                if keep and rel in c["frames"]:
                    images.append((k, image))
            except FrameProblem as exc:
                problems.append(f"{path}: {exc}")
            except InputError as exc:  # read_depth_map's line names the file
                problems.append(str(exc))
            except Exception as exc:  # Pillow's many ways to say "not an image"
                problems.append(f"{path}: unreadable as PNG ({type(exc).__name__}: {exc})")
        out[(c["scene"], c["case"])] = images
    if problems:
        raise FramesError(problems)
    return out


def case_files(c: dict) -> list:
    """Every file a case's renderer writes (job.json's ``frames``, ``filled``, ``depth``), frame by frame."""
    lists = [c[key] for key in ("frames", "filled", "depth") if c.get(key)]
    return [rel for group in zip(*lists) for rel in group]


def read_obj(path: Path, with_faces: bool = False) -> tuple:
    """The ``v`` and ``l`` records of an OBJ export wrote: ``(vertices (N, 3), edges (E, 2) 0-based)``;
    ``with_faces``: ``(vertices, edges, faces)``, each face a tuple of 0-based indices.

    FramesError (file:line) for a record that is not as export writes it: 3
    finite coordinates, 2 indices of vertices before it; ``f`` faces (not
    judged, but a renderer may read them) of 3 or more such indices; nothing
    but ``v``, ``l``, ``f`` and ``#`` comments.
    """
    problem = file_problem(path, "job mesh")
    if problem is not None:
        raise FramesError([f"{path}: {problem}: expected the OBJ 'crosscheck export' wrote"])
    try:
        text = read_text(path, "job mesh", encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise FramesError([f"{path}: unreadable ({exc}): expected the OBJ 'crosscheck export' wrote"]) from None
    read = _obj_blocks(text)
    verts, edges, faces = _obj_lines(path, text) if read is None else read
    return (verts, edges, faces) if with_faces else (verts, edges)


def _obj_lines(path: Path, text: str) -> tuple:
    """:func:`read_obj`'s reading of ``text`` (the file ``path``'s), line by line: ``(vertices, edges, faces)``
    or the first bad line's FramesError."""
    verts, edges, faces = [], [], []
    for lineno, line in enumerate(text.splitlines(), start=1):
        parts = line.split()
        try:
            if parts and parts[0] == "v":
                verts.append([float(x) for x in parts[1:]])
                if len(parts) != 4 or not all(map(math.isfinite, verts[-1])):
                    raise ValueError
            elif parts and parts[0] == "l":
                edges.append([int(x) - 1 for x in parts[1:]])
                if len(parts) != 3 or not all(0 <= i < len(verts) for i in edges[-1]):
                    raise ValueError
            elif parts and not parts[0].startswith("#"):
                face = [int(x) - 1 for x in parts[1:] if x.lstrip("-").isdigit()] if parts[0] == "f" else []
                if len(face) < max(3, len(parts) - 1) or not all(0 <= i < len(verts) for i in face):
                    raise FramesError(
                        [
                            f"{path}:{lineno}: {line.strip()[:60]!r}: expected 'f I J K ...' (3 or more "
                            f"of 1..{len(verts)}), 'v', 'l' or a '#' comment, as 'crosscheck export' wrote"
                        ]
                    )
                faces.append(tuple(face))
        except ValueError as exc:
            if isinstance(exc, FramesError):
                raise
            raise FramesError(
                [
                    f"{path}:{lineno}: {line.strip()[:60]!r}: expected 'v X Y Z' (finite) or 'l I J' "
                    f"(1..{len(verts)}), as 'crosscheck export' wrote"
                ]
            ) from None
    return np.asarray(verts, dtype=np.float64).reshape(-1, 3), np.asarray(edges, dtype=np.intp).reshape(-1, 2), faces


def _obj_blocks(text: str) -> tuple | None:
    """:func:`_obj_lines`' result for a text laid out as export writes an OBJ, read a block at a time: ``#``
    lines, then ``v X Y Z`` lines (finite), ``l I J`` lines and ``f`` lines of one length (ASCII indices), every
    index of a vertex (all come first); None for any other text, which is then read line by line (a
    5,120-face mesh: ~45 ms line by line, read once a case on the frames judge's reading thread)."""
    lines = text.splitlines()
    heads = [line[:2] for line in lines]
    at = 0
    while at < len(heads) and heads[at][:1] == "#":
        at += 1
    counts = [heads.count(head) for head in ("v ", "l ", "f ")]
    if at + sum(counts) != len(lines):
        return None
    blocks = []
    for head, n in zip(("v ", "l ", "f "), counts):
        if heads[at : at + n] != [head] * n:
            return None
        blocks.append(" ".join(lines[at : at + n]).split())
        at += n
    (v, e, f), (n_v, n_e, n_f) = blocks, counts
    k = len(f) // n_f if n_f else 4  # tokens a face line
    if len(v) != 4 * n_v or len(e) != 3 * n_e or len(f) != k * n_f or k < 4:
        return None
    if v[::4] != ["v"] * n_v or e[::3] != ["l"] * n_e or f[::k] != ["f"] * n_f:
        return None
    del v[::4], e[::3], f[::k]
    digits = "".join(f)
    if not (digits.isascii() and digits.isdigit()) and f:  # as a line's 'x.lstrip("-").isdigit()' and int(x)
        return None
    try:
        verts = np.array(list(map(float, v)), dtype=np.float64).reshape(-1, 3)
        edges = np.array(list(map(int, e)), dtype=np.int64) - 1
        corners = np.array(list(map(int, f)), dtype=np.int64) - 1
    except (ValueError, OverflowError):  # a value a line's reading refuses, or an index past int64
        return None
    if not np.isfinite(verts).all() or not all(((i >= 0) & (i < n_v)).all() for i in (edges, corners)):
        return None
    faces = list(map(tuple, corners.reshape(n_f, k - 1).tolist()))
    return verts, edges.astype(np.intp).reshape(-1, 2), faces


def _frame_camera(path: Path, cache: dict | None = None):
    """``(camera, model_matrix (4, 4))`` of a frame's JSON; FramesError naming the file otherwise.

    ``cache``: the last camera made, by its JSON fields; the same fields give
    the same Camera object back (a case's camera is fixed: converted once by
    oracles.references.opencv_oracle, which keeps the last camera by identity).
    """
    problem = file_problem(path, "camera")
    if problem is not None:
        raise FramesError([f"{path}: {problem}: expected the camera 'crosscheck export' wrote"])
    try:
        cam_json = read_json(path, "camera")
    except (OSError, ValueError, RecursionError) as exc:
        raise FramesError(
            [f"{path}: unreadable ({type(exc).__name__}: {exc}): expected the camera JSON 'crosscheck export' wrote"]
        ) from None
    problem = camera_keys_problem(cam_json)
    if problem is not None:
        raise FramesError([f"{path}: {problem} (export the job again)"])
    try:
        if cache is not None and cache.get("camera_json") == cam_json["camera"]:
            camera = cache["camera"]
        else:
            camera = Camera(**cam_json["camera"])
            if cache is not None:
                cache.update(camera_json=cam_json["camera"], camera=camera)
        m = np.asarray(cam_json["model_matrix"], dtype=np.float64)
        if m.shape != (4, 4) or not np.all(np.isfinite(m)):
            raise ValueError(f"model_matrix of shape {m.shape}: expected 4x4 finite numbers")
    except (OSError, ValueError, KeyError, TypeError, AttributeError, OverflowError, RecursionError) as exc:
        what = f"no {exc}" if isinstance(exc, KeyError) else str(exc)
        raise FramesError(
            [f"{path}: unreadable ({type(exc).__name__}: {what}): expected the camera JSON 'crosscheck export' wrote"]
        ) from None
    return camera, m, cam_json


def frame_inputs(job_dir: Path, job: dict, scene: str, case: str, k: int, cache: dict | None = None):
    """``(p_model (N, 3), edges (E, 2), camera, model_matrix (4, 4))`` of one frame, from the job's files.

    ``cache``: a dict kept by the caller over one case's frames: the scene's
    OBJ (model space) is then read once, and an unchanged camera made once.
    """
    job_dir = Path(job_dir)
    row = next(s for s in job["scenes"] if s["name"] == scene)  # load_job checked it is there
    obj = job_dir / (row["obj"] if row["space"] == "model" else f"scenes/{scene}/{frame_name(k, 'obj')}")
    if cache is not None and cache.get("obj") == obj:
        p_model, edges = cache["mesh"]
    else:
        p_model, edges, faces = read_obj(obj, with_faces=True)
        if cache is not None:  # the faces of the file just read, for frame_faces
            cache.update(faces_obj=obj, faces=faces)
        if cache is not None and row["space"] == "model":
            cache.update(obj=obj, mesh=(p_model, edges))
    if row["space"] == "model" and (len(p_model), len(edges)) != (row["vertices"], row["edges"]):
        raise FramesError(
            [
                f"{obj}: {len(p_model)} vertices, {len(edges)} edges: expected {row['vertices']} and "
                f"{row['edges']} (job.json's; the file was changed or cut short)"
            ]
        )
    path = job_dir / f"cameras/{scene}/{case}/{frame_name(k, 'json')}"
    camera, m, cam_json = _frame_camera(path, cache)
    c = next(c for c in job["cases"] if (c["scene"], c["case"]) == (scene, case))
    if (camera.width, camera.height) != (c["width"], c["height"]):  # the frames were read at the job's size
        size = f"{camera.width}x{camera.height}"
        raise FramesError(
            [
                f"{path}: camera {size[:40]}{'...' if len(size) > 40 else ''}: expected "
                f"{c['width']}x{c['height']} "
                f"(job.json's size of {scene} / {case}; export the job again)"
            ]
        )
    problem = camera_file_problem(cam_json, camera, m, job, scene, case, k)  # as export wrote it, in every form
    if problem is not None:
        raise FramesError(
            [
                f"{path}: {problem} (what 'crosscheck export' writes for this file's camera and "
                "model matrix: the file was edited; export the job again)"
            ]
        )
    return p_model, edges, camera, m


def frame_faces(job_dir: Path, job: dict, scene: str, k: int, cache: dict | None = None) -> list:
    """The ``f`` records of frame ``k``'s OBJ (0-based index tuples): the faces a filled frame or a depth map
    shows. ``cache``: as :func:`frame_inputs`' (which keeps the faces of the OBJ it read last): each OBJ
    read once."""
    row = next(s for s in job["scenes"] if s["name"] == scene)
    obj = Path(job_dir) / (row["obj"] if row["space"] == "model" else f"scenes/{scene}/{frame_name(k, 'obj')}")
    if cache is not None and cache.get("faces_obj") == obj:
        faces = cache["faces"]
    else:
        _v, _e, faces = read_obj(obj, with_faces=True)
        if cache is not None:
            cache.update(faces_obj=obj, faces=faces)
    if row["space"] == "model" and len(faces) != row.get("faces"):
        raise FramesError(
            [f"{obj}: {len(faces)} faces: expected {row.get('faces')} (job.json's; the file was changed or cut short)"]
        )
    return faces


def face_objects(job: dict, scene: str, faces: list) -> np.ndarray:
    """``(F,)`` int64: the object (0, 1, ... in job.json's ``objects`` of the scene) of each face, that of its
    first vertex (an object's faces index its own vertices)."""
    row = next(s for s in job["scenes"] if s["name"] == scene)
    stops = np.cumsum(row["objects"])
    first = np.fromiter((f[0] for f in faces), dtype=np.int64, count=len(faces))
    return np.searchsorted(stops, first, side="right")


def read_frame(path: Path, width: int, height: int, job=None) -> np.ndarray:
    """A frame's grey levels (oracles.candidates.png_frame.read_grey), decoded once, as it is judged.

    The job's frames were checked before the judging began, all but their
    pixels' decoding (oracles.candidates.frames_candidate.check_frames with
    ``decode=False``): a frame that cannot be decoded makes the full check run
    (``job``: ``(job_dir, job)``), so that every problem of the job is listed,
    as when the check decodes every frame first; FramesError either way.
    """
    try:
        return read_grey(path, width, height)
    except FrameProblem as exc:
        problem = str(exc)
    except Exception as exc:  # noqa: BLE001 - Pillow's many ways to say "not an image"
        problem = f"unreadable as PNG ({type(exc).__name__}: {exc})"
    if job is not None:
        check_frames(*job)  # raises, listing every problem of the job
    raise FramesError([f"{path}: {problem}"])
