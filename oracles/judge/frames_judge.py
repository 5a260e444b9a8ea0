"""Judge a renderer's own frames (``crosscheck --candidate-frames DIR``), frame by frame, by the one judge.

Each listed frame of a job (oracles.candidates.export, checked by
oracles.candidates.frames_candidate) is read (:func:`candidate_pixels`: the one place
where a frame's file becomes the bool image of drawn pixels that is judged),
drawn by pyrender from the job's own files (OBJ vertices, the frame's camera
and model matrix: the oracle the verdict rests on) and by core (a second
opinion, reported, never deciding), and scored as the projector path scores
its frames: edge-pixel F1 at 0 and 1 px (oracles.judge.metrics.pixel_scores), and
the line scores against the oracle's segments (oracles.judge.metrics.line_scores:
one-sided pixels and their balance, per-edge counts, where the one-sided
pixels lie, sub-pixel ties), the segments known from the job's camera and
scene (oracles.candidates.draw.oracle_segments). After the frames, the case's measurements are frozen
(:func:`case_evidence`: oracles.judge.evidence), its verdict decided from them (oracles.judge.decide.decide,
at level ``frames``: no vertex compared), its faults named from both (oracles.judge.name_faults: the images'
names, else the lines'), and its record built once (:func:`case_record`).

A job that asks for depth maps or filled frames (``outputs``, oracles.candidates.export)
has them measured in the same frame loop: pyrender draws the frame's faces (on the
GL thread, read ahead), each depth map is read and judged against that depth
(oracles.judge.depth_frames), each filled frame against the fill rule's
silhouette (oracles.judge.filled_frames); their fields join the case's record
(``depth_map``, ``filled``) and the one verdict. Without wireframes, no line
field is measured and no worst-frame images are kept.

Frames are streamed: a frame's images are dropped once it is scored, so
memory does not grow with the job. What is kept per case: the worst frame's
two images (for report.md's picture), at most :data:`DIAGNOSIS_FRAMES`
frames' drawn pixels for the image diagnosis (evenly spaced over the case;
its samples are capped per case anyway), and a per-frame record of numbers.
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from dataclasses import replace
from pathlib import Path

import numpy as np
from wirecheck.core.projector import pipeline

from .. import line_model
from ..candidates import frames_candidate
from ..candidates.draw import oracle_segments as line_segments
from ..candidates.export import job_outputs
from ..candidates.frames_candidate import face_objects, read_frame
from ..diagnosis.diagnose import diagnose_lines
from ..diagnosis.image_diagnose import diagnose_images, flipped_camera, oracle_segments
from ..diagnosis.image_visibility import set_difference
from ..faults import Fault
from ..references import opencv_oracle
from ..tolerances import MIN_IOU_UNION_PX, Tolerances
from . import f1_radius, metrics
from .decide import decide, filled_reasons, pixel_fields
from .depth_frames import DepthFrames
from .depth_reference import from_render
from .evidence import CaseEvidence, Visibility
from .filled_frames import FilledFrames
from .frame_prefetch import FramePrefetch, reader_for
from .job_read import differs, read_job
from .line_style import CaseStyle, style_record
from .name_faults import name_faults, wants_visibility
from .record import finish_record
from .run_report import run_report, tolerances_field

#: Frames of a case kept for the image diagnosis (evenly spaced, first and last included).
#: The diagnosis samples at most 3,600 points a case (oracles.diagnosis.registration.MAX_POINTS_PER_CASE),
#: 150 a frame at 24 frames: more frames would add few points each and cost memory.
DIAGNOSIS_FRAMES = 24

#: Per-frame fields of the line comparison: the projector path's (oracles.judge.metrics.LINE_FRAME_KEYS).
LINE_FRAME_KEYS = metrics.LINE_FRAME_KEYS


def candidate_pixels(
    path: Path,
    width: int,
    height: int,
    style,
    orac: np.ndarray,
    frame: tuple,
    segs: np.ndarray | None = None,
    job=None,
    grey: np.ndarray | None = None,
) -> np.ndarray:
    """The pixels a frame file draws, as ascending flat indices ``y W + x``: what the judge compares with the oracle's.

    Every frame of the frames path goes through here, once: its grey levels
    (:func:`read_frame`) are read by the case's line style
    (oracles.judge.line_style.CaseStyle.frame: the style, line centres and ends
    measured against ``frame`` = ``(p_model, edges, camera, model_matrix)``
    and its oracle segments ``segs``), and the pixels compared are those drawn
    by the rule (coverage >= 128; CaseStyle.frame_flat). ``job``: ``(job_dir, job)``, for
    :func:`read_frame`'s listing of a job's problems. ``grey``: the frame's
    :func:`read_frame` already made (read ahead: oracles.judge.frame_prefetch).
    """
    grey = read_frame(path, width, height, job) if grey is None else grey
    return style.frame_flat(grey, orac, *frame, segs=segs)


def diagnosis_frames(n: int, limit: int = DIAGNOSIS_FRAMES) -> set:
    """The indices (0-based, of a case's ``n`` frames) kept for the image diagnosis: all, or ``limit`` evenly spaced."""
    if n <= limit:
        return set(range(n))
    return {int(i) for i in np.round(np.linspace(0, n - 1, limit))}


class _CaseFrames:
    """What a case's frames gathered, frame by frame (no image kept beyond :data:`DIAGNOSIS_FRAMES`)."""

    def __init__(self):
        self.pixel = {key: [] for key in metrics.PIXEL_SCORE_KEYS}
        self.core_min = {}
        self.radius = []  # each frame's F1 at the wider radii (f1_radius)
        self.per_frame, self.lines = [], []
        self.batch = metrics.LineBatch()
        self.drawn_px = 0
        self.worst = None  # ((f1_1px, f1_0px), frame, candidate, oracle)
        self.diag = []  # (KeptImage-like flat indices, shape, segments, flipped)
        self.rounded_f1 = []  # each frame's F1@0px against the rounded-ends rule (line_model)
        self.rounded_batch = metrics.LineBatch()
        self.rounded_lines = []

    def add_rounded(self, k, cand: np.ndarray, segs: np.ndarray, shape: tuple, seg0, seg1, tol) -> None:
        """Score a frame's drawn pixels ``cand`` (flat) against a correct drawing of ``segs`` by the
        rounded-ends rule (oracles.line_model), the rule's ties left out of both."""
        model, ties = line_model.expected(segs, shape, "rounded", tol.rounded_end_tie_px)
        keep = ~ties.reshape(-1)
        fp = metrics.FramePixels.from_indices(shape, cand[keep[cand]], np.flatnonzero(model.reshape(-1) & keep))
        self.rounded_f1.append(float(metrics.pixel_scores(None, None, tols=(0,), pixels=fp)["f1_0px"]))
        self.rounded_lines.extend(self.rounded_batch.add(k, fp, seg0, seg1))

    def rounded(self) -> dict | None:
        """The case's pixels against the rounded-ends rule (CaseStyle.judge's ``rounded``), None without frames."""
        self.rounded_lines.extend(self.rounded_batch.flush())
        if not self.rounded_f1:
            return None
        return {"pixel_f1_0px": min(self.rounded_f1), "lines": metrics.line_summary(self.rounded_lines)}

    def visibility_inputs(self) -> tuple[list, list, list]:
        """The kept frames' ``(drawn images, oracle segments, the flipped camera's segments)``, for the image
        diagnosis and the visibility advice."""
        images = [_image(flat, shape) for flat, shape, _, _ in self.diag]
        return images, [s for _, _, s, _ in self.diag], [f for _, _, _, f in self.diag]

    def record_lines(self, scored: list) -> None:
        for (k, frame_rec), ls in scored:
            self.lines.append((k, ls))
            frame_rec.update({name: ls[name] for name in LINE_FRAME_KEYS})


def judge_case(
    job_dir, job, scene: str, case: str, oracles, tol, diagnose: bool = True, line_rule: str = "any", job_read=None
):
    """One case of a job: ``(record, worst images)``; pyrender is the verdict's oracle, core a second opinion.

    ``oracles``: the run's oracles.judge.frame_prefetch.FramePrefetch (frames
    read ahead on its GL thread), or an OracleCache (read in this thread).

    ``line_rule``: ``"any"`` holds aliased 1-px lines to a correct drawing by GL's rule or the
    rounded-ends rule (oracles.line_model), ``"gl"`` to GL's pixel rule alone,
    ``"geometry"`` judges where the lines are only (oracles.judge.line_style).

    Each frame's wireframe, depth map and filled frame, as the job asks for them (module
    docstring); the worst images are None for a job without wireframes. ``job_read``: the read of the
    renderer pooled over the job's cases, imposed on this one (oracles.judge.job_read.JobRead), or None.
    """
    c = next(c for c in job["cases"] if (c["scene"], c["case"]) == (scene, case))
    numbers = job["frame_numbers"]
    outputs = job_outputs(job)
    wire = "wireframe" in outputs
    depth = DepthFrames(job) if "depth" in outputs else None  # each frame's depth map (depth_frames)
    filled = FilledFrames(tol.fill_tie_px) if "filled" in outputs else None  # each filled PNG (filled_frames)
    kept = diagnosis_frames(len(numbers)) if diagnose and wire else set()
    acc = _CaseFrames()
    style = CaseStyle(line_rule, job_read.as_dict() if job_read is not None else None)
    camera = None
    # each frame's inputs, pyrender's drawing and its PNG's grey levels, read ahead on the GL thread
    # (frame_prefetch: each step's error raised here, at its frame and step), with the work that needs only the
    # drawing made there too, beside this thread's work on the frames before it (_reference_maker)
    ahead = reader_for(oracles).frames(job_dir, job, c, numbers, _reference_maker(depth, filled, job, scene))
    objects = (None, None)  # (faces, each face's object), kept while the faces are the same object
    for i, (k, frame) in enumerate(zip(numbers, ahead)):
        p_model, edges, camera, m = frame.inputs()
        if wire:
            _wireframe(
                acc,
                style,
                Path(job_dir) / c["frames"][i],
                c,
                k,
                frame,
                (p_model, edges, camera, m),
                (job_dir, job),
                tol,
                line_rule,
                i in kept,
            )
        if depth or filled:
            covered, z, ids, tris, polygons = frame.faces()  # pyrender's faces: the depth maps' reference
            if depth:
                rec_k = depth.add(k, Path(job_dir) / c["depth"][i], camera, frame.reference()[0])
                acc.drawn_px += rec_k["union_px"]
            if filled:  # the fill rule's silhouette (filled_frames)
                if objects[0] is not polygons:
                    objects = polygons, face_objects(job, scene, polygons)
                rec_k = filled.add(
                    k,
                    Path(job_dir) / c["filled"][i],
                    p_model @ m[:3, :3].T + m[:3, 3],
                    polygons,
                    camera,
                    (job_dir, job),
                    objects[1],
                    hint=ids,
                    reference=None if depth else (lambda made=frame.reference: made()[1]),
                )
                acc.drawn_px += rec_k["union_px"]
        del frame
    ahead.close()
    diagnosed, images, segments = (), [], []
    if wire:
        acc.record_lines(acc.batch.flush())
        images, segments, flipped = acc.visibility_inputs()
        if diagnose:
            diagnosed = tuple(Fault.of(f) for f in diagnose_images(images, segments, camera, flipped, tol=tol))
    filled_fields = filled.fields(MIN_IOU_UNION_PX) if filled else None
    ev = case_evidence(
        acc,
        style if wire else None,
        numbers,
        diagnosed,
        tol,
        depth_map=depth.fields() if depth else None,
        filled=filled_fields,
        depth_faults=tuple(Fault.of(f) for f in depth.faults()) if depth else (),
        # the silhouettes' fit (~0.5 s a frame) only where the filled frames miss a limit: name_faults uses
        # their names there alone
        filled_faults=filled.faults() if filled and filled_reasons(filled_fields, tol) else (),
    )
    verdict = decide(ev, tol)
    names = name_faults(ev, verdict, tol)
    if diagnose and images and wants_visibility(names, ev, verdict) and _wireframe_fails(ev, tol):
        # the images fit the oracle's lines (nothing named from them) and the case fails: which sets differ?
        ev = replace(ev, visibility=Visibility(*set_difference(images, segments, camera), len(images), len(numbers)))
        names = name_faults(ev, verdict, tol)
    rec = case_record(job, scene, case, camera, ev, verdict, names, acc)
    worst = {"frame": acc.worst[1], "candidate": acc.worst[2], "oracle": acc.worst[3]} if wire else None
    return rec, worst


def _reference_maker(depth, filled, job, scene: str):
    """The frame reader's ``reference`` for a case's depth maps and filled frames (None without either): from a
    frame's inputs and pyrender's drawing of its faces alone, ``(depth reference, silhouette)``. With depth maps,
    the depth reference (:func:`from_render`) is made on the reading thread and the fill rule's silhouette
    (FilledFrames.reference, pyrender's triangle ids as its hint) by the judge (None here): the reading thread
    already draws, and the two threads' work is then near even (icosphere(4): ~17 ms a frame each, against ~24
    and ~13 with the silhouette read ahead); with filled frames alone, the silhouette is made there."""
    if depth is None and filled is None:
        return None

    objects = [None, None]  # (faces, their objects): a model-space scene's faces are one object a case

    def make(inputs, faces):
        p_model, _edges, camera, m = inputs
        covered, z, ids, tris, polygons = faces
        if depth is not None:
            return from_render(covered, z, ids, tris, camera), None
        if objects[0] is not polygons:
            objects[:] = polygons, face_objects(job, scene, polygons)
        return None, filled.reference(p_model @ m[:3, :3].T + m[:3, 3], polygons, camera, objects[1], hint=ids)

    return make


def _wireframe_fails(ev: CaseEvidence, tol) -> bool:
    """Whether the case's wireframes miss a limit of their own (not only its depth maps or filled frames)."""
    if ev.depth_map is None and ev.filled is None:
        return True
    return decide(replace(ev, depth_map=None, filled=None), tol).verdict == "fail"


def _wireframe(
    acc: _CaseFrames, style, path: Path, c: dict, k: int, frame, inputs: tuple, job, tol, line_rule: str, keep: bool
) -> None:
    """Frame ``k``'s wireframe PNG (``path``) scored into ``acc`` (``frame``: its FrameAhead; ``inputs``:
    ``(p_model, edges, camera, model_matrix)``; ``keep``: its drawn pixels kept for the image diagnosis)."""
    p_model, edges, camera, m = inputs
    p_world = p_model @ m[:3, :3].T + m[:3, 3]
    # where the oracle's lines lie: OpenCV's pixels of the ends; only edges the depth planes cut are clipped
    seg0, seg1 = line_segments(p_world, edges, camera, opencv_oracle.project(p_world, camera))
    segs = oracle_segments(p_world, edges, camera)  # the lines a correct renderer draws
    orac = frame.oracle()
    cand = candidate_pixels(path, c["width"], c["height"], style, orac, inputs, segs, job, grey=frame.grey())
    core = _drawn(pipeline.render_frame(p_model, edges, camera, m).image)
    fp = metrics.FramePixels.from_indices(orac.shape, cand, np.flatnonzero(orac))
    style.count_rule(fp, segs)
    if line_rule != "geometry":
        acc.add_rounded(k, cand, segs, orac.shape, seg0, seg1, tol)
    ps = metrics.pixel_scores(None, None, pixels=fp)
    # core's second opinion: the candidate's drawn pixels are fp's (one scan of each image)
    cs = metrics.pixel_scores(None, None, pixels=metrics.FramePixels.from_indices(orac.shape, fp.cand_idx, core))
    acc.radius.append(f1_radius.frame_scores(fp, ps))
    for key, values in acc.pixel.items():
        values.append(ps[key])
    for key in metrics.PIXEL_SCORE_KEYS:
        acc.core_min[key] = min(acc.core_min.get(key, 1.0), float(cs[key]))
    acc.drawn_px += ps["candidate_pixels"] + ps["oracle_pixels"] - ps["both_pixels"]
    frame_rec = {
        "frame": k,
        "f1_0px": ps["f1_0px"],
        "f1_1px": ps["f1_1px"],
        "core_f1_0px": cs["f1_0px"],
        "core_f1_1px": cs["f1_1px"],
        "candidate_pixels": ps["candidate_pixels"],
        "oracle_pixels": ps["oracle_pixels"],
    }
    acc.per_frame.append(frame_rec)
    acc.record_lines(acc.batch.add((k, frame_rec), fp, seg0, seg1))  # scored with later frames
    key = (ps["f1_1px"], ps["f1_0px"])
    if acc.worst is None or key < acc.worst[0]:
        acc.worst = (key, k, _image(cand, orac.shape), orac.copy())
    if keep:
        acc.diag.append((fp.cand_idx, orac.shape, segs, oracle_segments(p_world, edges, flipped_camera(camera))))


def _drawn(image: np.ndarray) -> np.ndarray:
    """Ascending flat indices of the pixels of ``image`` that are >= 128."""
    return np.flatnonzero(image.reshape(-1) >= 128)


def _image(flat: np.ndarray, shape: tuple) -> np.ndarray:
    out = np.zeros(shape[0] * shape[1], bool)
    out[flat] = True
    return out.reshape(shape)


def case_evidence(
    acc: _CaseFrames,
    style: CaseStyle | None,
    numbers: list,
    diagnosed: tuple,
    tol,
    depth_map=None,
    filled=None,
    depth_faults: tuple = (),
    filled_faults: tuple = (),
) -> CaseEvidence:
    """What a case's frames measured, frozen (oracles.judge.evidence): its pixel scores, lines, F1 radius,
    the diagnosis's faults (``diagnosed``), GL's line faults, the style read and what was compared; its depth
    maps' and filled frames' fields and the faults their values and silhouettes name. ``style`` None: the job asks for no
    wireframe (no pixel or line field)."""
    compared = {"frames": len(numbers), "vertices": 0, "pixels": acc.drawn_px}
    surfaces = {"depth_map": depth_map, "filled": filled, "depth_faults": depth_faults, "filled_faults": filled_faults}
    if style is None:
        return CaseEvidence(level="frames", compared=compared, frames_checked=len(numbers), **surfaces)
    pixels = pixel_fields(acc.pixel, acc.worst[1])
    lines = metrics.line_summary(acc.lines)
    line_named = tuple(Fault.of(f) for f in diagnose_lines(lines, tol))
    radius = f1_radius.radius_read(
        style.classify(), acc.radius, numbers, pixels["pixel_f1_1px"], pixels["worst_pixel_frame"]
    )
    return CaseEvidence(
        level="frames",
        compared=compared,
        frames_checked=len(numbers),
        pixels=pixels,
        lines=lines,
        radius=radius,
        image_faults=diagnosed,
        line_faults=line_named,
        style=style.read(diagnosed or line_named, tol, acc.rounded()),
        drew_pixels=any(f["candidate_pixels"] for f in acc.per_frame),
        **surfaces,
    )


def case_record(
    job: dict, scene: str, case: str, camera, ev: CaseEvidence, verdict, names: tuple, acc: _CaseFrames
) -> dict:
    """A case's record (its entry in report.json's ``cases``), built once from its evidence, verdict and names;
    beside them core's second opinion (never deciding) and the per-frame numbers (``acc``). Its faults, verdict,
    reasons and per-frame numbers are written as every source's are (oracles.judge.record.finish_record)."""
    rec = {
        "scene": scene,
        "camera": case,
        "camera_spec": camera.to_dict(),
        "frames": job["frames"],
        "frames_checked": ev.frames_checked,
        "max_vertex_error_px": None,
    }
    if ev.pixels is not None:
        rec.update(
            {
                **ev.pixels,
                "core": {
                    k: acc.core_min[k]
                    for k in ("f1_0px", "f1_1px", "precision_0px", "recall_0px", "precision_1px", "recall_1px")
                },
                "lines": dict(ev.lines),
            }
        )
    rec["faults"] = []  # its place in the record; the names are written by finish_record
    if ev.pixels is not None:
        rec.update(
            {
                "f1_radius_px": ev.radius.radius_px,
                "pixel_f1_radius": ev.radius.f1,
                "pixel_f1_radius_frame": ev.radius.frame,
                "line_style": style_record(ev.style, verdict.style, ev.radius.radius_px),
            }
        )
    for key in ("depth_map", "filled"):
        if getattr(ev, key) is not None:
            rec[key] = _plain(getattr(ev, key))
    rec["compared"] = dict(ev.compared)
    return finish_record(rec, ev, verdict, names, acc.per_frame)


def _plain(value):
    """``value`` with every read-only mapping made a dict again (report.json's record)."""
    if isinstance(value, Mapping):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return type(value)(_plain(v) for v in value)
    return value


def run_frames(
    job_dir,
    tol=None,
    diagnose: bool = True,
    name: str | None = None,
    allow_vacuous: bool = False,
    line_rule: str = "any",
) -> tuple[dict, dict]:
    """Judge the job's frames: the report dict (as crosscheck's) and the worst-frame images.

    Every listed frame is checked first (oracles.candidates.frames_candidate.check_frames:
    FramesError, exit 2, listing every frame that is missing, of the wrong
    size, not a PNG or not this job's), then the cases are judged one frame
    at a time, each frame decoded once (a frame that cannot be decoded: the
    same FramesError, :func:`read_frame`). A case where neither side drew a pixel is ``"vacuous"`` and
    fails the run unless ``allow_vacuous`` (as :mod:`oracles.judge.gate`).
    """
    tol = tol or Tolerances()
    t0 = time.perf_counter()
    job = frames_candidate.load_job(job_dir)
    frames_candidate.check_frames(job_dir, job, decode=False)  # each frame is decoded once, as it is judged
    reader = FramePrefetch()  # the GL thread: every oracle call, and the frames read ahead of the judge
    records, images = [], {}
    try:
        for c in job["cases"]:
            rec, worst = judge_case(
                job_dir, job, c["scene"], c["case"], reader, tol, diagnose=diagnose, line_rule=line_rule
            )
            records.append(rec)
            if worst is not None:  # a job without wireframes: no line images to show
                images[(c["scene"], c["case"])] = worst
        # one renderer, one reading: the cases that read it otherwise than the job are judged again under the
        # job's read (oracles.judge.job_read)
        pooled = read_job(records)
        for i, c in enumerate(job["cases"]):
            if differs(records[i], pooled):
                records[i], worst = judge_case(
                    job_dir,
                    job,
                    c["scene"],
                    c["case"],
                    reader,
                    tol,
                    diagnose=diagnose,
                    line_rule=line_rule,
                    job_read=pooled,
                )
                if worst is not None:
                    images[(c["scene"], c["case"])] = worst
        gl = reader.call(reader.oracles.gl_info)
    finally:
        reader.close()
    outputs = job_outputs(job)
    report = run_report(
        records,
        "frames",
        allow_vacuous,
        {
            "candidate": name or f"frames:{Path(job_dir).name}",
            "candidate_settings": None,
            "style": "wireframe",
            "hidden_lines": False,
            "cull": "none",
            "oracles": ["pyrender", "core"],
            "oracle_gl": gl,
            "frames": job["frames"],
            "every": job["every"],
            "frames_checked": len(job["frame_numbers"]),
            "motion": job["motion"],
            "tolerances": tolerances_field(tol, "frames", outputs=outputs),
            "line_rule": line_rule,
            **(
                {} if outputs == ("wireframe",) else {"outputs": list(outputs), "depth_encoding": job["depth_encoding"]}
            ),
            "timing": {"wall_s": time.perf_counter() - t0},
        },
    )
    return report, images
