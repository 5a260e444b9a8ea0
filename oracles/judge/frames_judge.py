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

The case's frames come from :class:`JobFrames`, a source of the one case loop
(oracles.judge.case_loop.measure_frames), whose wireframes are measured as a projector's are
(oracles.judge.wire_frames.WireFrames, judged as drawn, the drawing rule read by the case's style).
A job that asks for depth maps or filled frames (``outputs``, oracles.candidates.export)
has them measured in the same loop: pyrender draws the frame's faces (on the
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

from ..candidates import frames_candidate
from ..candidates.draw import oracle_segments as line_segments
from ..candidates.export import job_outputs
from ..candidates.frame_prefetch import FramePrefetch, reader_for
from ..candidates.frames_candidate import face_objects, read_frame
from ..diagnosis.image_diagnose import diagnose_images, flipped_camera, oracle_segments
from ..diagnosis.image_visibility import set_difference
from ..faults import Fault
from ..references import opencv_oracle
from ..tolerances import MIN_IOU_UNION_PX, Tolerances
from . import f1_radius, metrics
from .case_loop import Measurements, measure_frames
from .decide import decide, filled_reasons
from .depth_frames import DepthFrames
from .depth_reference import from_render
from .evidence import CaseEvidence, Visibility
from .filled_frames import FilledFrames
from .job_read import differs, read_job
from .line_style import CaseStyle, style_record
from .name_faults import name_faults, wants_visibility
from .record import finish_record, wire_fields
from .run_report import run_report, tolerances_field
from .wire_frames import COUNT_FRAME_KEYS, WireFrames, flat_image

#: Frames of a case kept for the image diagnosis (evenly spaced, first and last included).
#: The diagnosis samples at most 3,600 points a case (oracles.diagnosis.registration.MAX_POINTS_PER_CASE),
#: 150 a frame at 24 frames: more frames would add few points each and cost memory.
DIAGNOSIS_FRAMES = 24


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
    :func:`read_frame` already made (read ahead: oracles.candidates.frame_prefetch).
    """
    grey = read_frame(path, width, height, job) if grey is None else grey
    return style.frame_flat(grey, orac, *frame, segs=segs)


def diagnosis_frames(n: int, limit: int = DIAGNOSIS_FRAMES) -> set:
    """The indices (0-based, of a case's ``n`` frames) kept for the image diagnosis: all, or ``limit`` evenly spaced."""
    if n <= limit:
        return set(range(n))
    return {int(i) for i in np.round(np.linspace(0, n - 1, limit))}


class JobFrames:
    """A renderer's frames of one case of a job, as a source of the case loop (oracles.judge.case_loop): each
    frame's inputs (the job's OBJ, camera and model matrix), pyrender's drawing and the frame's files, read
    ahead (``ahead``: oracles.candidates.frame_prefetch.FramePrefetch.frames; each step's error raised at its frame
    and step). Beside the measurements, the source keeps core's second opinion on the wireframes
    (``core_min``: each score's minimum over the frames, never deciding) and the drawn pixels of the frames
    kept for the image diagnosis (``keep``: their indices, :func:`diagnosis_frames`)."""

    def __init__(self, job_dir, job, c: dict, ahead, style, keep: set):
        self.job_dir, self.job, self.c, self.ahead, self.style, self.keep = job_dir, job, c, ahead, style, keep
        self.core_min: dict = {}
        self.diag: list = []  # (drawn pixels' flat indices, shape, segments, the flipped camera's segments)
        self.camera = None  # the last frame's
        self.objects = (None, None)  # (faces, each face's object), kept while the faces are the same object

    def __iter__(self):
        for i, (k, ahead) in enumerate(zip(self.job["frame_numbers"], self.ahead)):
            yield JobFrame(self, i, k, ahead)

    def visibility_inputs(self) -> tuple[list, list, list]:
        """The kept frames' ``(drawn images, oracle segments, the flipped camera's segments)``, for the image
        diagnosis and the visibility advice."""
        images = [flat_image(flat, shape) for flat, shape, _, _ in self.diag]
        return images, [s for _, _, s, _ in self.diag], [f for _, _, _, f in self.diag]


class JobFrame:
    """Frame ``k`` (the ``i``-th listed) of :class:`JobFrames` (oracles.judge.case_loop.SourceFrame)."""

    def __init__(self, source: JobFrames, i: int, k: int, ahead):
        self.source, self.i, self.number, self.ahead = source, i, k, ahead
        self.inputs = ahead.inputs()  # (p_model, edges, camera, model_matrix)
        source.camera = self.inputs[2]

    def _path(self, kind: str) -> Path:
        return Path(self.source.job_dir) / self.source.c[kind][self.i]

    def wireframe(self, frame_rec: dict) -> tuple:
        """``(FramePixels, seg0, seg1, segs)``: the PNG's drawn pixels (:func:`candidate_pixels`, read by the
        case's style) against pyrender's, where the oracle's lines lie (OpenCV's pixels of the ends; only edges
        the depth planes cut are clipped) and the lines a correct renderer draws; core's second opinion into
        ``frame_rec``."""
        src, (p_model, edges, camera, m) = self.source, self.inputs
        p_world = p_model @ m[:3, :3].T + m[:3, 3]
        seg0, seg1 = line_segments(p_world, edges, camera, opencv_oracle.project(p_world, camera))
        segs = oracle_segments(p_world, edges, camera)
        orac = self.ahead.oracle()
        job = (src.job_dir, src.job)
        grey = self.ahead.grey()
        cand = candidate_pixels(
            self._path("frames"), src.c["width"], src.c["height"], src.style, orac, self.inputs, segs, job, grey=grey
        )
        core = _drawn(pipeline.render_frame(p_model, edges, camera, m).image)
        fp = metrics.FramePixels.from_indices(orac.shape, cand, np.flatnonzero(orac))
        # core's second opinion: the candidate's drawn pixels are fp's (one scan of each image)
        cs = metrics.pixel_scores(None, None, pixels=metrics.FramePixels.from_indices(orac.shape, fp.cand_idx, core))
        for key in metrics.PIXEL_SCORE_KEYS:
            src.core_min[key] = min(src.core_min.get(key, 1.0), float(cs[key]))
        # beside the candidate's F1s, which the measurement writes in their places (report.json's order)
        frame_rec.update({"f1_0px": None, "f1_1px": None, "core_f1_0px": cs["f1_0px"], "core_f1_1px": cs["f1_1px"]})
        if self.i in src.keep:
            src.diag.append((fp.cand_idx, orac.shape, segs, oracle_segments(p_world, edges, flipped_camera(camera))))
        return fp, seg0, seg1, segs

    def depth_map(self) -> tuple:
        """``(path, camera, reference)``: the depth file against the depth reference made of pyrender's faces
        (oracles.judge.depth_reference.from_render, read ahead)."""
        self.ahead.faces()  # pyrender's faces: the depth maps' reference (its error raised at this step)
        return self._path("depth"), self.inputs[2], self.ahead.reference()[0]

    def filled(self) -> dict:
        """FilledFrames.add's inputs: the filled PNG, the frame's world points and faces (the fill rule's
        silhouette, read ahead when the job has no depth map), each face's object, pyrender's triangle ids."""
        src, (p_model, _edges, camera, m) = self.source, self.inputs
        _covered, _z, ids, _tris, polygons = self.ahead.faces()
        if src.objects[0] is not polygons:
            src.objects = polygons, face_objects(src.job, src.c["scene"], polygons)
        made = self.ahead.reference
        return {
            "path": self._path("filled"),
            "p_world": p_model @ m[:3, :3].T + m[:3, 3],
            "faces": polygons,
            "camera": camera,
            "job": (src.job_dir, src.job),
            "objects": src.objects[1],
            "hint": ids,
            "reference": None if "depth" in job_outputs(src.job) else (lambda: made()[1]),
        }

    def spent(self, kind: str, seconds: float) -> None:
        """Nothing: a job's run is timed whole."""


def judge_case(
    job_dir, job, scene: str, case: str, oracles, tol, diagnose: bool = True, line_rule: str = "any", job_read=None
):
    """One case of a job: ``(record, worst images)``; pyrender is the verdict's oracle, core a second opinion.

    ``oracles``: the run's oracles.candidates.frame_prefetch.FramePrefetch (frames
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
    style = CaseStyle(line_rule, job_read.as_dict() if job_read is not None else None)
    # a renderer's frames are judged as drawn, their rule read by the style (oracles.judge.wire_frames.WireFrames)
    rounded_tie_px = tol.rounded_end_tie_px if line_rule != "geometry" else None
    wires = (
        WireFrames(COUNT_FRAME_KEYS, resolve_ties=False, style=style, rounded_tie_px=rounded_tie_px) if wire else None
    )
    measured = Measurements(wire=wires, depth=depth, filled=filled)
    # each frame's inputs, pyrender's drawing and its PNG's grey levels, read ahead on the GL thread
    # (frame_prefetch: each step's error raised here, at its frame and step), with the work that needs only the
    # drawing made there too, beside this thread's work on the frames before it (_reference_maker)
    ahead = reader_for(oracles).frames(job_dir, job, c, numbers, _reference_maker(depth, filled, job, scene))
    source = JobFrames(job_dir, job, c, ahead, style, kept)
    measure_frames(source, measured)
    ahead.close()
    camera = source.camera
    diagnosed, images, segments = (), [], []
    if wire:
        wires.flush()
        images, segments, flipped = source.visibility_inputs()
        if diagnose:
            diagnosed = tuple(Fault.of(f) for f in diagnose_images(images, segments, camera, flipped, tol=tol))
    filled_fields = filled.fields(MIN_IOU_UNION_PX) if filled else None
    ev = case_evidence(
        measured,
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
    rec = case_record(job, scene, case, camera, ev, verdict, names, measured.per_frame, source.core_min)
    worst = wires.worst_images() if wire else None
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


def _drawn(image: np.ndarray) -> np.ndarray:
    """Ascending flat indices of the pixels of ``image`` that are >= 128."""
    return np.flatnonzero(image.reshape(-1) >= 128)


def case_evidence(
    measured: Measurements,
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
    compared = {"frames": len(numbers), "vertices": 0, "pixels": measured.drawn_px}
    surfaces = {"depth_map": depth_map, "filled": filled, "depth_faults": depth_faults, "filled_faults": filled_faults}
    if style is None:
        return CaseEvidence(level="frames", compared=compared, frames_checked=len(numbers), **surfaces)
    pixels, lines, line_named = wire_fields(measured.wire, tol)
    radius = f1_radius.radius_read(
        style.classify(), measured.wire.radius, numbers, pixels["pixel_f1_1px"], pixels["worst_pixel_frame"]
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
        style=style.read(diagnosed or line_named, tol, measured.wire.rounded()),
        drew_pixels=any(f["candidate_pixels"] for f in measured.per_frame),
        **surfaces,
    )


def case_record(
    job: dict, scene: str, case: str, camera, ev: CaseEvidence, verdict, names: tuple, per_frame: list, core_min: dict
) -> dict:
    """A case's record (its entry in report.json's ``cases``), built once from its evidence, verdict and names;
    beside them core's second opinion (``core_min``, never deciding) and the per-frame numbers (``per_frame``). Its faults, verdict,
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
                    k: core_min[k]
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
    return finish_record(rec, ev, verdict, names, per_frame)


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
