"""``crosscheck export DIR``: a rendering job any renderer can do, judged later by its frames.

The job is a folder::

    DIR/README.md                        what to draw and where (for the renderer's author)
    DIR/job.json                         the manifest: scenes, cases, frames, image rule, conventions
    DIR/scenes/<scene>.obj               vertices ``v`` (model space), edges ``l``, faces ``f``
    DIR/scenes/<scene>/frame_0001.obj    instead, for a scene of several moving objects: world space per frame
    DIR/cameras/<scene>/<case>/frame_0001.json   the camera and model matrix of one frame
    DIR/frames/<scene>/<case>/frame_0001.png     written by the renderer (not by export)
    DIR/frames/<scene>/<case>/filled_0001.png    the same, for a job asking for filled frames
    DIR/frames/<scene>/<case>/depth_0001.npy     the same, for a job asking for depth maps (.npy, .png, .tif)

A job asks for ``outputs`` (:data:`OUTPUTS`): wireframes (the default, and the only
output of a job.json without an ``outputs`` key), filled frames, depth maps, or any
of them together. A job that asks for more than wireframes lists, per case, its
``depth`` and ``filled`` files beside ``frames`` (empty when wireframes are not
asked for) and states the depth maps' ``depth_encoding``: format
(:data:`DEPTH_FORMATS`) and, for a 16-bit PNG, its scale in values per world unit.

A frame's JSON holds the camera in every form a renderer may want: the
fields of the candidate contract (:mod:`oracles.candidates.candidate`), OpenCV's ``K, R,
t`` (:func:`oracles.references.convert.opencv_matrices`), OpenGL's view and projection
matrices (:func:`oracles.references.convert.camera_to_gl`) and the model matrix the
oracles use (:func:`oracles.references.faces.frame_geometry`: scipy, not core). Matrices
are nested lists of rows, for column vectors (``p = M @ [x, y, z, 1]``). The
conventions are stated in the JSON itself (``conventions``), pointing to
``core/conventions.py``.

Frames are numbered as crosscheck's motion numbers them: frame ``k`` is at
``t = (k - 1) / frames``; with ``every`` only frames 1, 1 + every, ... are in
the job. ``phase`` (``crosscheck export --phase F``, ``0 <= F < 1``) moves
every frame on by ``F`` of a frame's step, ``t = (k - 1 + F) / frames``: a
short job whose frames would all be quarter-turn poses (a cube square-on,
which some faults draw pixel for pixel as a correct renderer does) then sees
the scene at oblique poses; its frames are then not crosscheck's own. ``oracles.candidates.frames_candidate`` reads the job back and judges the PNGs.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from wirecheck.core.errors import InputError
from wirecheck.core.outputs.output import FrameDir, json_dumps
from wirecheck.core.transforms import Motion

from ..cases import CASE_NAMES, case_motion, cases_for
from ..references.convert import camera_to_gl, opencv_matrices
from ..references.faces import frame_geometry

#: Version of the job format; frames_candidate refuses any other.
JOB_VERSION = 1
JOB_KIND = "wirecheck frames job"

CONVENTIONS = {
    "statement": "wirecheck.core.conventions states these once; summarised here for the renderer",
    "world": "right-handed; camera right = forward x up",
    "pixels": "x right (columns), y down (rows), origin top-left; integer coordinates are pixel centres: "
    "pixel (0, 0) covers [-0.5, 0.5]^2; principal point ((W-1)/2, (H-1)/2) unless the camera has "
    "intrinsics [fx, fy, cx, cy] (then K and gl_projection hold them)",
    "fov": "fov_y_deg is the vertical field of view, edge to edge of the image",
    "orthographic": "ortho_height world units are visible vertically (edge to edge)",
    "clipping": "a point is drawn when its depth along forward is in [near, far]; edges are clipped there",
    "matrices": "nested lists of rows, for column vectors: p' = M @ p",
    "model_matrix": "p_world = model_matrix @ [p_model, 1] (the OBJ's v are p_model)",
    "opencv": "p_cv = R @ p_world + t; [u, v, 1] ~ K @ p_cv (perspective); u, v are our pixel coordinates",
    "opengl": "p_clip = gl_projection @ gl_view @ [p_world, 1]; x_win = (x_ndc + 1) W / 2, "
    "y_win = (y_ndc + 1) H / 2 (y up, corner origin); our x_px = x_win - 0.5, y_px = H - y_win - 0.5",
}

IMAGE_RULE = {
    "wireframe": "PNG, the camera's width x height, black background, every visible edge as a white line: "
    "1-px aliased (held to GL's pixel rule), or anti-aliased, or up to ~3 px wide (judged by where "
    "the lines' centres are); a pixel's luminance over black (luminance x alpha / 255) is its "
    "coverage, and it counts as drawn when >= 128 (a transparent pixel is not drawn)",
    "filled": "PNG, the camera's width x height, black background, every face's visible part filled in any "
    "non-black colour (a pixel shows a surface when its centre is inside a face, as GL fills "
    "triangles; it counts as filled when its luminance x alpha / 255 is 1 or more); with several "
    "objects one id per object, as a grey level (1, 2, ...); no lines, no shading needed",
    "depth": "the camera's width x height, row 0 at the top, each pixel the depth along the camera's forward "
    "(z_cam: not the distance along the ray, not the GL depth buffer's [0, 1] value) of the nearest "
    "visible face at the pixel centre, in world units; 0, NaN or +inf where no face is seen",
}


#: What a job may ask a renderer to write per frame, in the order job.json lists them.
OUTPUTS = ("wireframe", "filled", "depth")
#: Depth map formats a job may ask for: the file's suffix (oracles.candidates.depth_map reads each).
DEPTH_FORMATS = {"npy": "npy", "png16": "png", "tiff": "tif"}
#: What each depth format holds, for the README.
DEPTH_FORMAT_TEXT = {
    "npy": "a 2-D float32 NumPy array (`numpy.save`), shape (height, width), depth in world units",
    "png16": "a 16-bit grey PNG, each value `round(depth x scale)` (scale {scale:g} per world unit), "
    "values up to 65535",
    "tiff": "a 32-bit float TIFF (one channel, Pillow's mode F), depth in world units",
}


def frame_name(k: int, ext: str, kind: str = "frame") -> str:
    """A frame's file name: ``frame_0001.png`` (``kind``: ``"frame"``, ``"depth"``, ``"filled"``)."""
    return f"{kind}_{k:04d}.{ext}"


def output_files(scene: str, case: str, checked, outputs, depth_format: str = "npy") -> dict:
    """The files a case's renderer writes, per output: ``{"frames": [...], "filled": [...], "depth": [...]}``
    (``frames``: the wireframes; a list is empty when its output is not asked for)."""
    where = f"frames/{scene}/{case}"
    ext = DEPTH_FORMATS[depth_format]
    return {
        "frames": [f"{where}/{frame_name(k, 'png')}" for k in checked] if "wireframe" in outputs else [],
        "filled": [f"{where}/{frame_name(k, 'png', 'filled')}" for k in checked] if "filled" in outputs else [],
        "depth": [f"{where}/{frame_name(k, ext, 'depth')}" for k in checked] if "depth" in outputs else [],
    }


def job_outputs(job: dict) -> tuple:
    """What a (checked) job asks for: its ``outputs``, wireframes alone when it has none."""
    return tuple(job.get("outputs", ("wireframe",)))


def matrix_rows(m) -> list:
    return [[float(x) for x in row] for row in np.asarray(m, dtype=np.float64)]


def _obj_text(vertices: np.ndarray, edges, faces, header: str) -> str:
    lines = [f"# {header}"]
    lines += [f"v {x!r} {y!r} {z!r}" for x, y, z in np.asarray(vertices, dtype=np.float64).tolist()]
    lines += [f"l {int(a) + 1} {int(b) + 1}" for a, b in np.asarray(edges).reshape(-1, 2).tolist()]
    lines += ["f " + " ".join(str(int(i) + 1) for i in f) for f in faces]
    return "\n".join(lines) + "\n"


def frame_time(k: int, frames: int, phase: float = 0.0) -> float:
    """``t`` of frame ``k`` (module docstring): ``(k - 1 + phase) / frames``."""
    return (k - 1 + phase) / frames if phase else (k - 1) / frames


def camera_json(camera, model: np.ndarray, scene: str, case: str, k: int, frames: int, phase: float = 0.0) -> dict:
    """Everything a renderer needs to draw frame ``k`` of one case."""
    r, t, kk = opencv_matrices(camera)
    view, proj = camera_to_gl(camera)
    return {
        "scene": scene,
        "case": case,
        "frame": k,
        "t": frame_time(k, frames, phase),
        "camera": camera.to_dict(),
        "right": [float(x) for x in camera.right],
        "model_matrix": matrix_rows(model),
        "K": matrix_rows(kk),
        "R": matrix_rows(r),
        "t_cv": [float(x) for x in t],
        "gl_view": matrix_rows(view),
        "gl_projection": matrix_rows(proj),
        "conventions": "see job.json (conventions); wirecheck.core.conventions states them once",
    }


def check_outputs(outputs, depth_format: str = "npy", depth_scale: float = 1000.0) -> tuple:
    """``outputs`` (a list or a comma-separated string) in :data:`OUTPUTS` order; InputError naming the
    option for an unknown or repeated output, a depth format not in :data:`DEPTH_FORMATS`, or a PNG scale
    that is not a finite number > 0 with 65535 / scale finite."""
    given = [o.strip() for o in outputs.split(",")] if isinstance(outputs, str) else list(outputs)
    bad = [o for o in given if o not in OUTPUTS]
    if bad or not given or len(set(given)) != len(given):
        why = f"unknown {', '.join(map(repr, bad))}" if bad else ("none given" if not given else "one given twice")
        raise InputError(
            f"--outputs {','.join(map(str, given))!r}: {why}: expected one or more of "
            f"{', '.join(OUTPUTS)}, each once (e.g. wireframe,depth)"
        )
    if depth_format not in DEPTH_FORMATS:
        raise InputError(f"--depth-format {depth_format!r}: expected one of {', '.join(DEPTH_FORMATS)}")
    if not (
        isinstance(depth_scale, (int, float))
        and not isinstance(depth_scale, bool)
        and math.isfinite(depth_scale)
        and depth_scale > 0
        and math.isfinite(65535.0 / depth_scale)
    ):
        raise InputError(
            f"--depth-scale {depth_scale!r}: expected a finite number of values per world unit > 0 "
            "(1000: millimetres per metre)"
        )
    return tuple(o for o in OUTPUTS if o in given)


def build_job(
    scenes,
    frames: int = 24,
    every: int = 1,
    case_names=None,
    motion=None,
    phase: float = 0.0,
    outputs=("wireframe",),
    depth_format: str = "npy",
    depth_scale: float = 1000.0,
) -> tuple[dict, dict]:
    """The manifest and the files of a job: ``(job, {relative path: bytes})``; ``phase``: module docstring
    (0: crosscheck's own poses, and job.json without a ``motion.phase``). ``outputs``: what the renderer
    writes (:data:`OUTPUTS`; wireframes alone: job.json as before, without ``outputs``); ``depth_format``
    and ``depth_scale`` (values per world unit of a 16-bit PNG): its depth maps' encoding."""
    outputs = check_outputs(outputs, depth_format, depth_scale)
    plain = outputs == ("wireframe",)
    motion = motion or Motion()
    files: dict[str, bytes] = {}
    scene_rows, case_rows = [], []
    checked = list(range(1, frames + 1, every))
    for scene in scenes:
        single = scene.is_single_static
        faces = [tuple(int(i) for i in f) for f in scene.faces]
        if single:
            path = f"scenes/{scene.name}.obj"
            files[path] = _obj_text(
                scene.vertices, scene.edges, faces, f"{scene.name}: model space; each frame's JSON has its model_matrix"
            ).encode()
        scene_rows.append(
            {
                "name": scene.name,
                "space": "model" if single else "world per frame",
                "obj": f"scenes/{scene.name}.obj" if single else f"scenes/{scene.name}/frame_NNNN.obj",
                "vertices": int(len(scene.vertices)),
                "edges": int(len(scene.edges)),
                "faces": len(faces),
                # the objects' vertex counts, in the OBJ's order: a face is its first vertex's object
                **({} if plain else {"objects": [int(o.vertex_stop - o.vertex_start) for o in scene.objects]}),
            }
        )
        cases = cases_for(scene, motion, calibrated=True)
        scene_motion = case_motion(motion, cases[0])  # one framing, one pivot per scene
        geometry = {}
        for k in checked:
            p_world, _m, _pr_vertices, pose = frame_geometry(scene, scene_motion, frame_time(k, frames, phase))
            geometry[k] = pose if single else np.eye(4)
            if not single:
                files[f"scenes/{scene.name}/{frame_name(k, 'obj')}"] = _obj_text(
                    p_world, scene.edges, faces, f"{scene.name} frame {k}: world space"
                ).encode()
        for case in cases:
            if case.name not in (CASE_NAMES if case_names is None else case_names):
                continue
            if case.camera.distortion is not None:  # frames are judged by pixels: not for a lens (oracles.judge.case)
                raise InputError(
                    f"--cases {case.name}: lens distortion: a frames job is judged by its pixels, "
                    "which GL cannot draw through a lens; expected cases without distortion"
                )
            for k in checked:
                files[f"cameras/{scene.name}/{case.name}/{frame_name(k, 'json')}"] = json_dumps(
                    camera_json(case.camera, geometry[k], scene.name, case.name, k, frames, phase)
                ).encode()
            written = output_files(scene.name, case.name, checked, outputs, depth_format)
            case_rows.append(
                {
                    "scene": scene.name,
                    "case": case.name,
                    "width": case.camera.width,
                    "height": case.camera.height,
                    "frames": written["frames"],
                    **({} if plain else {"filled": written["filled"], "depth": written["depth"]}),
                }
            )
    job = {
        "kind": JOB_KIND,
        "version": JOB_VERSION,
        "style": "wireframe",
        "frames": frames,
        "every": every,
        "frame_numbers": checked,
        "motion": {"turns": list(motion.turns), **({"phase": float(phase)} if phase else {})},
        "image": IMAGE_RULE["wireframe"],
        "conventions": CONVENTIONS,
        "scenes": scene_rows,
        "cases": case_rows,
    }
    if not plain:
        job.update(
            outputs=list(outputs),
            filled_image=IMAGE_RULE["filled"],
            depth_image=IMAGE_RULE["depth"],
            depth_encoding={"format": depth_format, "scale": float(depth_scale) if depth_format == "png16" else None},
        )
    files["job.json"] = json_dumps(job).encode()
    files["README.md"] = readme(job).encode()
    return job, files


def quarter_turn_frames(job: dict) -> bool:
    """Whether every checked frame's pose turns the scene by whole quarter turns about each axis.

    Frame ``k`` turns by ``turns * t`` of a full turn about X, Y and Z
    (core.transforms.Motion; ``t`` of :func:`frame_time`): with ``--frames 4``
    and the default spin every frame is a quarter-turn pose, which shows a
    cube square-on (``--phase 0.3``: none is).
    """
    turns = np.asarray(job["motion"]["turns"], dtype=np.float64)
    phase = float(job["motion"].get("phase", 0.0))
    quarters = [turns * 4.0 * frame_time(k, job["frames"], phase) for k in job["frame_numbers"]]
    return all(np.all(np.abs(q - np.round(q)) < 1e-9) for q in quarters)


def short_job_note(job: dict) -> str:
    """The README's section on what the job's frames cannot reveal."""
    n = len(job["frame_numbers"])
    text = f"""## What this job cannot reveal

The verdict rests on the {n} frame{"s" if n != 1 else ""} listed per case, and on nothing between them: a
fault that shows only at other poses (a line crossing the near plane, an edge
leaving the picture at some angle) goes unseen. The faults are named from at
most 24 of a case's frames (evenly spaced)."""
    phase = float(job["motion"].get("phase", 0.0))
    if phase:
        text += f"""

Every frame is moved on by {phase:g} of a frame's step (`--phase {phase:g}`): frame `k` is
drawn at `t = (k - 1 + {phase:g}) / {job["frames"]}` of the motion, not at crosscheck's own `(k - 1) / {job["frames"]}`."""
    if quarter_turn_frames(job):
        shown = ", ".join(str(k) for k in job["frame_numbers"][:6]) + (", ..." if n > 6 else "")
        text += f"""

**Every frame of this job is a quarter-turn pose** (frames {shown} of
{job["frames"]}, spin {",".join(f"{t:g}" for t in job["motion"]["turns"])}): a cube is seen square-on in each, a
picture that a mirror, an axis swap or flip, a transposed rotation, a wrong
rotation order or a camera looking backward can map onto itself, so such
faults may draw the very pixels a correct renderer draws and pass. Export
it again with `--phase 0.3` (every frame moved on by 0.3 of a frame's step:
no frame is then a quarter turn, and with 1 to 8 frames no two frames of a
bundled scene and case draw the same pixels, nor is one its own mirror
image), more frames, or a number of frames that is not a multiple of 4 (e.g.
`--frames 24 --every 5`, `--frames 7`), to see the scene at oblique poses."""
    return text + "\n"


def world_scenes_note(job: dict) -> str:
    """The README's bullet for scenes whose OBJ is in world space per frame (several moving objects), or ''."""
    names = [s["name"] for s in job["scenes"] if s["space"] != "model"]
    if not names:
        return ""
    which = ", ".join(f"`{n}`" for n in names)
    return f"""
- {which} ({"its" if len(names) == 1 else "their"} `space` in job.json: `world per frame`, several moving
  objects): no `scenes/<scene>.obj`, but one OBJ per frame,
  `scenes/<scene>/frame_NNNN.obj`, its `v` already in world space (the
  camera files' `model_matrix` is the identity)."""


def readme(job: dict) -> str:
    if job_outputs(job) != ("wireframe",):
        return outputs_readme(job)
    n_frames = sum(len(c["frames"]) for c in job["cases"])
    first = job["cases"][0]
    return f"""# A wirecheck rendering job

Draw every frame listed below with your renderer, then run

    crosscheck --candidate-frames THIS_FOLDER

to have your renderer's own pixels judged against pyrender (OpenGL) and
wirecheck's core renderer, by the same rules as a projector: edge-pixel F1
at 0 and 1 px, the balance of pixels drawn by one side only, each line's
length in pixels, diff images, the worst frames, and, when something is off,
the name of the fault (mirror, axis swap, FOV, aspect, half-pixel offset,
depth flip, lines short or long at an end).

## What to draw

{job["image"]}.

- {len(job["cases"])} cases (a scene under a camera), {n_frames} frames in all.
- Scenes: `scenes/<scene>.obj` (model space: `v` vertices, `l` edges, `f`
  faces, 1-based). Draw the `l` edges (a line per edge); the faces are for
  shaded renderers and for hidden lines, which this job does not ask for.{world_scenes_note(job)}
- Cameras: `cameras/<scene>/<case>/frame_NNNN.json` gives the camera as
  position/forward/up/fov_y_deg/width/height/near/far/projection/ortho_height,
  as OpenCV `K`, `R`, `t_cv`, and as OpenGL `gl_view` and `gl_projection`, and
  the frame's `model_matrix` (p_world = model_matrix @ [v, 1]). Matrices are
  rows, for column vectors. The conventions are in `job.json` (`conventions`).
- Clip edges at the near and far planes (depth along `forward` in
  [near, far]); draw what falls inside the image.

## Where to write

`frames/<scene>/<case>/frame_NNNN.png`, the same numbers as the camera files,
e.g. `{first["frames"][0]}` ({first["width"]} x {first["height"]}). Every
listed frame must be there, at its camera's size: one still PNG (8- or
16-bit grey, RGB, RGBA or palette; no JPEG renamed, no animated PNG).

## Line style

Any: the judge reads it from the frames. A 1-px aliased line (WebGL:
`antialias: false`; OpenGL: no multisampling, no GL_LINE_SMOOTH) is held to
GL's pixel rule: the 0-px F1 compares pixel for pixel. Anti-aliased lines and
lines up to ~3 px wide cannot follow that rule; they are judged by where each
line's centre lies (to a fraction of a pixel), and the report says which style
it read. Aliased lines that round each end to a pixel centre (Pillow's
ImageDraw.line, Bresenham, OpenCV's cv2.line) pass when they are a correct
drawing by that rule, and the report says so; `--line-rule gl` holds them to
GL's rule (`raster_rule`), `--line-rule geometry` judges the geometry only. A line is judged where it is drawn: a
renderer that moves lines onto pixel centres is held to that move. matplotlib
does so by default for horizontal and vertical lines (`snap`): draw with
`snap=False`, or square-on frames read as a `pixel_offset` of up to half a pixel.
Pillow's ImageDraw truncates float coordinates: give it rounded ones, or its
lines read as `pixel_offset` (-0.5, -0.5).

""" + short_job_note(job)


def gl_depth_note(job: dict) -> str:
    """The README's bullet on a GL depth buffer read back, for a job that asks for depth maps, or ''."""
    if "depth" not in job_outputs(job):
        return ""
    return """
- A GL depth buffer read back is not depth: `gl_projection` is OpenGL's
  standard projection (glFrustum / glOrtho: near to NDC z -1, far to +1), so
  a window depth `z` in [0, 1] (glDepthRange 0, 1) is depth
  `d = 2 f n / ((f + n) - (2 z - 1) (f - n))` (orthographic:
  `d = n + z (f - n)`) with `n`, `f` the camera's near and far, and 1 where
  nothing was drawn; GL's row 0 is the bottom row (flip the rows once)."""


def outputs_readme(job: dict) -> str:
    """The README of a job asking for filled frames or depth maps (beside wireframes or instead of them)."""
    outputs = job_outputs(job)
    first = job["cases"][0]
    n = len(job["frame_numbers"])
    enc = job["depth_encoding"]
    asked = {"wireframe": "wireframes", "filled": "filled frames", "depth": "depth maps"}
    files = []
    if "wireframe" in outputs:
        files.append(
            f"- `frames/<scene>/<case>/frame_NNNN.png`: the wireframe. {job['image']}. Any line style: "
            "the judge reads it from the frames (a wireframe-only job's README says how)."
        )
    if "filled" in outputs:
        files.append(
            f"- `frames/<scene>/<case>/filled_NNNN.png`: the filled frame. {job['filled_image']} "
            "(job.json's `objects` of each scene: its objects' vertex counts, in the OBJ's order; a face "
            "belongs to its first vertex's object)."
        )
    if "depth" in outputs:
        ext = DEPTH_FORMATS[enc["format"]]
        what = DEPTH_FORMAT_TEXT[enc["format"]].format(scale=enc["scale"] or 0.0)
        files.append(f"- `frames/<scene>/<case>/depth_NNNN.{ext}`: the depth map, {what}; {job['depth_image']}.")
    listed = next(c for c in (first["frames"], first["filled"], first["depth"]) if c)
    return f"""# A wirecheck rendering job

Render every frame listed below with your renderer, writing its
{", ".join(asked[o] for o in outputs)}, then run

    crosscheck --candidate-frames THIS_FOLDER

to have them judged against pyrender (OpenGL): wireframes as a wireframe job's
(edge-pixel F1, line balance and counts); filled frames by their silhouette
against the faces GL fills (IoU, pixels one side fills away from the other's
boundary); depth maps against pyrender's depth made linear in float64, each
pixel within its bound (24-bit depth steps, the encoding's own step), the
surface the map leaves empty (holes) and the surface it shows where the
reference has none (extra) counted; and, when something is off, the name of
the fault (a stored z-buffer, range for depth, a scale such as millimetres
read as metres, an offset, reversed-Z, half floats, rows flipped, a
half-pixel principal point, K from the horizontal FOV).

## What to render

- {len(job["cases"])} cases (a scene under a camera), {n} frame{"s" if n != 1 else ""} each.
- Scenes: `scenes/<scene>.obj` (model space: `v` vertices, `l` edges, `f`
  faces, 1-based). Wireframes draw the `l` edges; filled frames and depth
  maps render the `f` faces (both sides: no back-face culling); a face of
  more than three vertices is the fan of triangles from its first vertex,
  `(f0, fk, fk+1)`, as the reference draws it.{world_scenes_note(job)}
- Cameras: `cameras/<scene>/<case>/frame_NNNN.json` gives the camera as
  position/forward/up/fov_y_deg/width/height/near/far/projection/ortho_height,
  as OpenCV `K`, `R`, `t_cv`, and as OpenGL `gl_view` and `gl_projection`, and
  the frame's `model_matrix` (p_world = model_matrix @ [v, 1]). Matrices are
  rows, for column vectors. The conventions are in `job.json` (`conventions`).
- Clip at the near and far planes (depth along `forward` in [near, far]).{gl_depth_note(job)}

## What to write, and where

Every file below, for every frame number of the camera files, at its
camera's size (e.g. `{listed[0]}`, {first["width"]} x {first["height"]});
job.json lists each one (`frames`, `filled`, `depth` of each case):

{chr(10).join(files)}

A missing file, one of the wrong size or of another encoding is an input
error (exit 2), never a pass; so is a file under `frames/` that job.json does
not list.

""" + short_job_note(job)


def write_job(
    out_dir: Path,
    scenes,
    frames: int = 24,
    every: int = 1,
    case_names=None,
    motion=None,
    phase: float = 0.0,
    outputs=("wireframe",),
    depth_format: str = "npy",
    depth_scale: float = 1000.0,
) -> dict:
    """Write the job to ``out_dir`` atomically (a temporary folder renamed over it); the manifest."""
    job, files = build_job(
        scenes,
        frames=frames,
        every=every,
        case_names=case_names,
        motion=motion,
        phase=phase,
        outputs=outputs,
        depth_format=depth_format,
        depth_scale=depth_scale,
    )
    out_dir = Path(out_dir)
    out = FrameDir(out_dir, "export DIR")
    try:
        for rel, data in sorted(files.items()):
            path = out.tmp / rel
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_bytes(data)
        (out.tmp / "frames").mkdir()
        out.commit()
    except BaseException:
        out.abort()
        raise
    return job
