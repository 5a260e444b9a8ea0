"""One case of a projector or of core: a scene under one camera, frame by frame, the candidate against the oracles.

The case's frames come from :class:`ProjectorFrames`, a source of the one case loop
(oracles.judge.case_loop.measure_frames). Frame ``k`` (1-based, at ``t = (k - 1) / frames``) gives:

1. **vertices** (levels ``vertices`` and ``pixels``): the oracle side's world
   points (oracles.references.faces.frame_geometry: scipy matrices, independent of core),
   OpenCV's ``projectPoints`` of them, and the candidate's pixels of the same
   points: core through its own pipeline (:func:`core.projector.pipeline.render_frame`
   given no edges, so nothing is drawn), any other candidate called on the
   world points (oracles.candidates.candidate); :meth:`CaseFrames.add_vertices` keeps them
   (scored for all frames at once, :func:`score_vertices`) and the case's scale for the
   precision-derived vertex bound (oracles.tolerances.vertex_scale);
2. **pixels** (level ``pixels``): the candidate's frame (core's full pipeline, or
   oracles.candidates.draw for another candidate) against pyrender's rendering of the same
   edges or faces, measured as a wireframe (oracles.judge.wire_frames) or shaded
   (oracles.judge.shaded_frames).

Then the frames are summed up into the case's record and judged
(oracles.judge.verdict). The drawing modes are described in oracles.runner.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
from wirecheck.core.scene.model import Scene
from wirecheck.core.transforms import Motion  # parameters only: the oracle's matrix is convert.model_matrix

from .. import tolerances
from ..candidates.candidate import CandidateError, call_candidate_precision, case_precision
from ..candidates.core_candidate import CoreCandidate, RenderMode
from ..candidates.draw import depth_margin, draw_candidate, oracle_segments
from ..cases import Case
from ..diagnosis import clip_planes
from ..references import faces as oface
from ..references import opencv_oracle
from ..references.convert import opencv_matrices
from ..references.gl_thread import ThreadOracle, submit_drawing
from ..tolerances import Tolerances
from . import metrics, owner_kernel, segment_pixels
from .case_loop import Measurements, measure_frames
from .line_ends import frames_end_places
from .shaded_frames import ShadedFrames
from .verdict import case_record, judge
from .wire_frames import SCORE_FRAME_KEYS, WireFrames

#: The note of a case whose camera has lens distortion, run at level pixels.
PIXELS_NOT_COMPARED = (
    "lens distortion: pixels not compared (GL draws straight lines between the vertices, "
    "a distorted lens bends them); vertices compared against cv2.projectPoints with the "
    "distortion coefficients"
)

#: Per-frame fields of the vertex comparison (:func:`score_vertices`).
VERTEX_FRAME_KEYS = ("max_vertex_error_px", "mean_vertex_error_px", "rms_vertex_error_px", "visible_points")


@dataclass
class CaseResult:
    record: dict  # what goes into report.json
    worst_images: dict | None = None  # {"frame", "candidate", "oracle"} bool images
    timing: dict = field(default_factory=dict)
    #: every checked frame's images, bit-packed: [(frame, candidate, oracle)] (for worst.gif)
    frame_images: list | None = None
    #: the GL that drew the oracle's frames (PyrenderOracle.gl_info), None at level vertices
    gl_info: dict | None = None
    #: with ``keep_points`` (level vertices): the worst frame's points, :func:`worst_points`
    worst_points: dict | None = None


class CaseSetup:
    """What every frame of a case shares: the scene, the camera, the faces, the candidate's set-up."""

    def __init__(
        self, scene: Scene, case: Case, frames: int, candidate, motion: Motion, mode: RenderMode, pixels: bool
    ):
        self.scene, self.case, self.cam, self.frames = scene, case, case.camera, frames
        self.candidate, self.motion, self.mode = candidate, motion, mode
        # lens distortion: GL draws straight lines, so only the vertices are compared (PIXELS_NOT_COMPARED)
        self.pixels = pixels and getattr(case.camera, "distortion", None) is None
        self.pixels_skipped = pixels and not self.pixels
        self.is_core = isinstance(candidate, CoreCandidate)
        self.cv_matrices = opencv_matrices(self.cam)  # R, t, K once, for tolerances.vertex_scale
        if not mode.plain and not self.is_core and pixels:
            raise ValueError(f"drawing mode {mode.to_dict()}: only the core candidate draws faces")
        self.edges = np.asarray(scene.edges)
        self.use_faces = pixels and len(scene.faces) > 0 and not mode.plain
        # the faces as plain ints where they are drawn; a plain wireframe only asks whether there are any
        # (converting a million faces costs more than the frame)
        self.faces = (tuple(tuple(int(i) for i in f) for f in scene.faces) if self.use_faces else scene.faces) or None
        # core is set up as renderer sets it up (core.scene.frames): its own matrices and world points,
        # and, for a multi-object scene, faces re-wound for mirrored objects
        self.core_frames = candidate.scene_frames(scene, motion, frames) if self.is_core else None
        self.core_faces = self.core_frames.faces if self.is_core and self.faces is not None else self.faces
        if self.use_faces and mode.shaded:
            self.tris, self.tri_owner = oface.fan(self.faces)
        if self.use_faces and mode.cull == "backface":
            self.owners = oface.EdgeOwners(self.edges, self.faces, len(scene.vertices))
        # the harness draws another candidate's frame; only the candidate's calls in it are its time
        self.timed = None if self.is_core else TimedCalls(candidate)
        self._planes: dict | None = None
        self._probed = False
        #: depth (world units) clipped ends are moved inside near/far beyond the precision's margin,
        #: and why (oracles.diagnosis.clip_planes.depth_slack); None until an edge crosses a plane
        self.slack, self.slack_why = 0.0, None

    def planes(self) -> dict | None:
        """The candidate's own near and far planes (oracles.diagnosis.clip_planes.probe_planes), probed once; None
        for core (its planes are the camera's by construction) or when the probe cannot run."""
        if not self._probed and not self.is_core:
            self._planes, self._probed = clip_planes.probe_planes(self.timed, self.cam), True
        return self._planes

    def draw_slack(self, p_world: np.ndarray) -> float:
        """:attr:`slack` for a frame: probed when some edge of the frame crosses near or far."""
        if self.is_core or self._probed or len(self.edges) == 0:
            return self.slack
        r_cv, t_cv, _k = self.cv_matrices
        depth = p_world @ r_cv[2] + t_cv[2]  # as opencv_oracle.depth
        d0, d1 = depth[self.edges[:, 0]], depth[self.edges[:, 1]]
        crosses = any(((d0 < plane) != (d1 < plane)).any() for plane in (self.cam.near, self.cam.far))
        if crosses:
            self.slack, self.slack_why = clip_planes.depth_slack(self.planes(), self.cam)
        return self.slack


class TimedCalls:
    """A candidate callable that adds the seconds spent in its calls to :attr:`seconds`."""

    def __init__(self, func):
        self.func, self.seconds = func, 0.0

    def __call__(self, points, camera):
        t = time.perf_counter()
        try:
            return self.func(points, camera)
        finally:
            self.seconds += time.perf_counter() - t


class ScaleBatch:
    """Frames waiting for :func:`oracles.tolerances.vertex_scale`, measured together.

    A frame's scale is the largest of its points' (elementwise), so the
    largest over several frames is the scale of their points together: one
    call for a case's frames instead of one per frame (~15 numpy calls on a
    few points each). Frames wait until the waiting points reach ``limit``.
    """

    def __init__(self, limit: int = 1 << 16):
        self.limit, self.value = limit, 0.0
        self._waiting: list = []
        self._rows = 0

    def add(self, p_world: np.ndarray, p_px: np.ndarray, camera, matrices=None) -> None:
        self._waiting.append((p_world, p_px))
        self._rows += len(p_world)
        if self._rows >= self.limit:
            self.flush(camera, matrices)

    def flush(self, camera, matrices=None) -> float:
        """The largest scale of every frame so far."""
        if self._waiting:
            p_world = np.concatenate([np.asarray(w, np.float64).reshape(-1, 3) for w, _ in self._waiting])
            p_px = np.concatenate([np.asarray(p, np.float64).reshape(-1, 2) for _, p in self._waiting])
            self.value = max(self.value, tolerances.vertex_scale(p_world, p_px, camera, matrices))
            self._waiting, self._rows = [], 0
        return self.value


@dataclass
class CaseFrames:
    """What the checked frames of a case gathered, in frame order."""

    cand_px: list = field(default_factory=list)  # (N, 2) per frame
    returned: set = field(default_factory=set)  # the precisions of the candidate's answers
    depth_ties: int = 0  # points left out by forgive_depth_ties
    scale: float = 0.0  # largest tolerances.vertex_scale over the frames
    scales: ScaleBatch = field(default_factory=lambda: ScaleBatch())  # frames waiting for vertex_scale
    oracle_px: list = field(default_factory=list)
    frame_errors: list = field(default_factory=list)  # (max error px, frame, worst vertex)
    per_frame: list = field(default_factory=list)  # the record's per_frame items
    wire: WireFrames | None = None  # the wireframes' scores (oracles.judge.wire_frames), at level pixels
    shaded: ShadedFrames | None = None  # the shaded frames' scores (oracles.judge.shaded_frames), style shaded
    kept: list | None = None  # (frame, KeptImage candidate, KeptImage oracle)
    error: str | None = None
    oracle_bound_px: float = 0.0  # pyrender's own error bound, largest over the frames
    planes: dict | None = None  # the candidate's probed planes (oracles.diagnosis.clip_planes)
    #: seconds: vertex stage = setup + cv + proj + vmetric; pixel stage = draw + hdraw + prwait + pmetric
    #: (hdraw: the harness drawing an external candidate's frame, less the candidate's own calls; pr:
    #: pyrender's own drawing, on the GL thread; prwait: the part of it, and of the metrics made beside it,
    #: this thread waited for; pbeside: the pixel metrics made on the GL thread, pixels_beside)
    seconds: dict = field(
        default_factory=lambda: dict.fromkeys(
            ("setup", "cv", "proj", "vmetric", "draw", "hdraw", "pr", "prwait", "pmetric", "pbeside", "once"), 0.0
        )
    )
    #: owner_kernel.setup_seconds() as last seen (:meth:`spend`)
    once_seen: float = field(default_factory=lambda: owner_kernel.setup_seconds())

    def measurements(self) -> Measurements:
        """The case loop's measurements (oracles.judge.case_loop): the vertices (this), its wireframes or shaded
        frames where pixels are compared."""
        return Measurements(vertices=self, wire=self.wire, shaded=self.shaded, per_frame=self.per_frame)

    @property
    def drawn_px(self) -> int:
        """Pixels drawn by either side over the frames (oracles.judge.gate)."""
        return self.measurements().drawn_px

    def add_vertices(self, k: int, setup: CaseSetup, p_world, cand_px, oracle_px, precision: str, frame_rec: dict):
        """Frame ``k``'s vertices: the candidate's pixels ``cand_px`` ``(N, 2)`` and OpenCV's ``oracle_px`` of the
        world points ``p_world``, the candidate judged as ``precision``; their errors are taken for all frames
        at once (:func:`score_vertices`), their fields in ``frame_rec`` None until then."""
        if precision != "float64":
            cand_px, oracle_px = forgive_depth_ties(self, setup, p_world, cand_px, oracle_px, precision)
        self.cand_px.append(cand_px)
        self.oracle_px.append(oracle_px)
        frame_rec.update(dict.fromkeys(VERTEX_FRAME_KEYS))
        self.scales.add(p_world, oracle_px, setup.cam, setup.cv_matrices)

    def add(self, key: str, t0: float) -> float:
        """The seconds since ``t0`` into ``seconds[key]``; the time now."""
        t = time.perf_counter()
        self.spend(key, t - t0)
        return t

    def spend(self, key: str, seconds: float) -> None:
        """``seconds`` into ``seconds[key]``, less any one-time set-up made meanwhile (the compiled owner search
        made ready on its first use, oracles.judge.owner_kernel.setup_seconds: ``seconds["once"]``, not a
        frame's time, as pyrender's context and the other first calls are not, CaseRunner.warm_up)."""
        once = owner_kernel.setup_seconds() - self.once_seen
        if once:
            self.once_seen += once
            self.seconds["once"] += once
            seconds -= once
        self.seconds[key] += seconds


def run_case(
    scene: Scene,
    case: Case,
    frames: int,
    candidate,
    motion: Motion,
    tol: Tolerances,
    pyrender_oracle=None,
    want_images: bool = True,
    every: int = 1,
    mode: RenderMode | None = None,
    keep_frames: bool = False,
    first: int = 1,
    keep_points: bool = False,
) -> CaseResult:
    """One case; the pixel stage runs when ``pyrender_oracle`` is given.

    Frames ``first, first + every, ...`` up to ``frames`` are checked (the
    viewer's overlay checks one frame: ``first=k, every=frames``).

    ``mode`` is the drawing mode of the pixel stage (oracles.runner); with
    ``keep_frames`` every checked frame's images are kept (:class:`KeptImage`) in
    :attr:`CaseResult.frame_images`; with ``keep_points`` the worst frame's
    points of both sides in :attr:`CaseResult.worst_points`.
    """
    setup = CaseSetup(scene, case, frames, candidate, motion, mode or RenderMode(), pyrender_oracle is not None)
    kept = [] if keep_frames and setup.pixels else None
    acc = CaseFrames(kept=kept)
    if setup.pixels and setup.mode.shaded:
        tris, owner = (setup.tris, setup.tri_owner) if setup.use_faces else (None, None)
        acc.shaded = ShadedFrames(setup.cam, tris, owner, want_images, kept)
    elif setup.pixels:
        acc.wire = WireFrames(SCORE_FRAME_KEYS, resolve_ties=True, kept=kept)
    source = ProjectorFrames(setup, acc, tol, pyrender_oracle, range(first, frames + 1, every))
    measure_frames(source, acc.measurements())
    t7 = time.perf_counter()
    score_vertices(acc)
    if acc.cand_px and not setup.is_core and visibility_differs(acc):
        acc.planes = setup.planes()  # where the candidate clips, to name a clipping_plane
    acc.scale = acc.scales.flush(setup.cam, setup.cv_matrices)
    t7 = acc.add("vmetric", t7)
    if acc.wire is not None:
        acc.wire.flush()
    acc.add("pmetric", t7)
    rec, ev = case_record(
        setup, acc, tol, points=len(scene.vertices), oracle_bound_px=acc.oracle_bound_px if setup.pixels else None
    )
    if setup.slack_why:  # the clipped ends were placed for the candidate's own (float32-rounded) planes
        rec["clipped_ends"] = {"inward_depth": setup.slack, "reason": setup.slack_why}
    if setup.pixels_skipped:
        rec["note"] = PIXELS_NOT_COMPARED
    judge(rec, ev, tol, acc.per_frame)
    images = None
    if want_images and setup.pixels:
        images = (acc.shaded or acc.wire).worst_images()
    return CaseResult(
        record=rec,
        worst_images=images,
        timing=case_timing(acc, setup.pixels),
        frame_images=acc.kept,
        worst_points=worst_points(setup, acc, rec) if keep_points else None,
    )


def worst_points(setup: CaseSetup, acc: CaseFrames, rec: dict) -> dict | None:
    """The frame of the case's worst vertex: both sides' pixels (``(N, 2)``, NaN where a side
    clipped the point), the vertex, its error and the image size; None when nothing was compared."""
    worst = rec.get("worst_vertex") or {}
    if worst.get("frame") is None:
        return None
    i = next(i for i, f in enumerate(acc.per_frame) if f["frame"] == worst["frame"])
    return {
        "scene": rec["scene"],
        "camera": rec["camera"],
        "frame": worst["frame"],
        "vertex": worst["vertex"],
        "error_px": worst["error_px"],
        "size": (int(setup.cam.width), int(setup.cam.height)),
        "candidate": np.asarray(acc.cand_px[i], np.float64),
        "oracle": np.asarray(acc.oracle_px[i], np.float64),
    }


def visibility_differs(acc: CaseFrames) -> bool:
    """Whether some point of the case is visible to one side only."""
    return any(
        (np.isfinite(c).all(axis=1) != np.isfinite(o).all(axis=1)).any() for c, o in zip(acc.cand_px, acc.oracle_px)
    )


def candidate_vertices(setup: CaseSetup, k: int, p_world: np.ndarray):
    """``(cand_px (N, 2), points, m_core, precision)`` of frame ``k``; CandidateError when the candidate fails.

    ``points`` and ``m_core`` are core's own set-up of the frame (None for
    another candidate), reused by :func:`candidate_frame`; ``precision`` is
    that of the answer (core: its ``dtype``).
    """
    if not setup.is_core:
        cand_px, precision = call_candidate_precision(setup.candidate, p_world, setup.cam)
        return cand_px, None, None, precision
    try:
        points, m_core = setup.core_frames.geometry(k)
        return setup.candidate.project(points, setup.cam, m_core), points, m_core, setup.candidate.dtype
    except Exception as exc:  # core crashing is a failed case, not a crashed run
        raise CandidateError(f"core raised {type(exc).__name__}: {exc}") from exc


def candidate_frame(setup: CaseSetup, points, m_core, p_world: np.ndarray, precision: str = "float64"):
    """``(image, depth)``: the candidate's frame (a bool image), or its depth buffer when shaded.

    ``precision``: the candidate's, for the ends clipped at the near and far planes (oracles.candidates.draw).
    """
    cand, cam, mode = setup.candidate, setup.cam, setup.mode
    if not setup.is_core:
        return draw_candidate(setup.timed, p_world, setup.edges, cam, precision, setup.draw_slack(p_world)), None
    try:
        if mode.plain:
            return cand.draw(points, setup.edges, cam, m_core), None
        if mode.shaded:
            return None, cand.shade(points, setup.edges, cam, m_core, setup.core_faces, mode)
        return cand.draw_mode(points, setup.edges, cam, m_core, setup.core_faces, mode), None
    except Exception as exc:
        raise CandidateError(f"core raised {type(exc).__name__}: {exc}") from exc


def forgive_depth_ties(
    acc: CaseFrames, setup: CaseSetup, p_world: np.ndarray, cand_px: np.ndarray, oracle_px: np.ndarray, precision: str
) -> tuple[np.ndarray, np.ndarray]:
    """Leave out points whose depth is within the candidate's rounding of near or far and that one side clips.

    A float32 candidate decides such a point on its own rounded depth
    (oracles.candidates.draw.depth_margin), so either answer is correct; the point is
    counted in ``acc.depth_ties`` (the record's ``depth_ties``) and compared
    as clipped by both.
    """
    camera, (r_cv, t_cv, _k) = setup.cam, setup.cv_matrices
    depth = p_world @ r_cv[2] + t_cv[2]  # as opencv_oracle.depth
    margin = depth_margin(p_world, camera, precision)
    tie = (np.abs(depth - camera.near) <= margin) | (np.abs(depth - camera.far) <= margin)
    tie &= np.isfinite(cand_px).all(axis=1) != np.isfinite(oracle_px).all(axis=1)
    if not tie.any():
        return cand_px, oracle_px
    acc.depth_ties += int(tie.sum())
    cand_px, oracle_px = cand_px.copy(), oracle_px.copy()
    cand_px[tie] = oracle_px[tie] = np.nan
    return cand_px, oracle_px


def score_vertices(acc: CaseFrames) -> None:
    """Every kept frame's vertex errors into its record and ``acc.frame_errors``."""
    for frame_rec, ve in zip(acc.per_frame, metrics.vertex_errors_frames(acc.cand_px, acc.oracle_px)):
        if ve["max_px"] is not None:
            acc.frame_errors.append((ve["max_px"], frame_rec["frame"], ve["worst_index"]))
        frame_rec.update(
            {
                "max_vertex_error_px": ve["max_px"],
                "mean_vertex_error_px": ve["mean_px"],
                "rms_vertex_error_px": ve["rms_px"],
                "visible_points": ve["visible_both"],
            }
        )


class ProjectorFrames:
    """A projector's or core's frames, as a source of the case loop (oracles.judge.case_loop): frame by frame,
    the oracle side's world points (oracles.references.faces.frame_geometry), OpenCV's pixels of them, the
    candidate's pixels (:func:`candidate_vertices`) and, where pixels are compared, its frame
    (:func:`candidate_frame`: core draws its own, the harness draws another candidate's) and pyrender's
    drawing of the same edges or faces. A candidate that fails at a frame ends the frames there (``acc.error``).

    pyrender draws ahead (:meth:`_oracle_side`): a frame's drawing is asked for before the candidate draws
    the frame, and the next frame's before this one is measured. Given the run's GL thread
    (oracles.references.gl_thread.ThreadOracle), pyrender draws there while this thread draws the
    candidate's frame and measures the frame before (much of a drawing runs inside the GL library, without
    the GIL); given a PyrenderOracle itself, it draws when asked, in this thread. The drawings, and what
    is measured of them, are the same either way; only when they are made changes.
    """

    def __init__(self, setup: CaseSetup, acc: CaseFrames, tol: Tolerances, pyrender_oracle, numbers: range):
        self.setup, self.acc, self.tol, self.oracle, self.numbers = setup, acc, tol, pyrender_oracle, numbers

    def __iter__(self):
        setup, acc = self.setup, self.acc
        numbers = list(self.numbers)
        ahead = None  # the next frame's oracle side, made while this frame is measured
        try:
            for i, k in enumerate(numbers):
                side = ahead if ahead is not None else self._oracle_side(k)
                ahead = None
                t2 = time.perf_counter()
                try:
                    cand_px, points, m_core, returned = candidate_vertices(setup, k, side.geometry[0])
                    acc.returned.add(returned)
                    t3 = time.perf_counter()
                    precision = case_precision(self.tol.precision, acc.returned)[0]
                    calls_before = setup.timed.seconds if setup.timed else 0.0
                    cand_img, cand_depth = (
                        candidate_frame(setup, points, m_core, side.geometry[0], precision)
                        if setup.pixels
                        else (None, None)
                    )
                    t4 = time.perf_counter()
                    own_draw = setup.timed.seconds - calls_before if setup.timed else t4 - t3
                except CandidateError as exc:
                    side.cancel()
                    acc.error = f"frame {k}: {exc}"
                    return
                acc.seconds["proj"] += t3 - t2
                acc.seconds["draw"] += own_draw
                acc.seconds["hdraw"] += t4 - t3 - own_draw
                if side.threaded and side.segments is not None and np.count_nonzero(cand_img) >= OWNERS_AHEAD_PX:
                    # a large frame: what needs only its two drawings is made on the GL thread after pyrender's
                    # drawing, while this thread finds the candidate pixels' owners (ProjectorFrame.wireframe)
                    side.beside = self.oracle.after(pixels_beside, side.drawing, cand_img, *side.segments)
                if i + 1 < len(numbers) and setup.pixels:  # pyrender draws the next frame while this one is measured
                    ahead = self._oracle_side(numbers[i + 1])
                yield ProjectorFrame(self, side, cand_px, precision, cand_img, cand_depth)
        finally:
            if ahead is not None:  # the loop stopped early: the drawing asked for is not waited for
                ahead.cancel()

    def _oracle_side(self, k: int) -> OracleSide:
        """Frame ``k``'s oracle side: its geometry and, where pixels are compared, pyrender's drawing of the
        edges the mode draws or of the faces asked for first (oracles.references.gl_thread.submit_drawing),
        then OpenCV's pixels and the oracle's segments of a wireframe (where its lines lie)."""
        setup, acc = self.setup, self.acc
        t = time.perf_counter()
        geometry = oface.frame_geometry(setup.scene, setup.motion, (k - 1) / setup.frames)
        t = acc.add("setup", t)
        side = OracleSide(k, geometry)
        side.threaded = isinstance(self.oracle, ThreadOracle)
        p_world, _matrices, pr_vertices, pr_pose = geometry
        mode, cam = setup.mode, setup.cam
        kept = None  # the edges of front faces (backface culling), None: all
        if setup.pixels and (setup.use_faces or not mode.shaded):
            mirrored = None
            if setup.use_faces and mode.cull == "backface":
                mirrored = oface.mirrored_vertices(setup.scene, geometry[1])
            if mode.shaded:
                method, args = "render_faces", (pr_vertices, oface.gl_triangles(setup.tris, mirrored), cam)
                kwargs = {"model_matrix": pr_pose, "cull": mode.cull == "backface", "with_ids": True}
            else:
                draw_edges, occluders = setup.edges, None
                if setup.use_faces and mode.cull == "backface":
                    kept = setup.owners.kept(oface.front_faces(p_world, setup.faces, cam, mirrored))
                    draw_edges = setup.edges[kept]
                if setup.use_faces and mode.hidden_lines:
                    occluders = oface.gl_polygons(setup.faces, mirrored)
                # the colour only (the mask pyrender's colour-and-depth read gives, without the depth's read
                # back and linearisation: tests/test_oracle_gl.py)
                method, args = "render", (pr_vertices, draw_edges, cam)
                kwargs = {"model_matrix": pr_pose, "faces": occluders, "cull": mode.cull == "backface", "depth": False}
            t = acc.add("pmetric", t)  # the harness's inputs to pyrender
            side.drawing = submit_drawing(self.oracle, method, *args, **kwargs)
            t = acc.add("prwait", t)  # asking for it (all of the drawing, when drawn in this thread)
        side.oracle_px = opencv_oracle.project(p_world, cam)
        t = acc.add("cv", t)
        if setup.pixels and not mode.shaded:
            seg0, seg1 = oracle_segments(p_world, setup.edges, cam, side.oracle_px)  # where the oracle's lines lie
            if kept is not None:
                seg0[~kept] = seg1[~kept] = np.nan
            side.segments = (seg0, seg1)
            acc.add("pmetric", t)  # harness, not pyrender
        return side


class OracleSide:
    """One frame's oracle side (:meth:`ProjectorFrames._oracle_side`): ``geometry`` (frame_geometry's
    ``(p_world, matrices, pr_vertices, pr_pose)``), ``oracle_px`` (OpenCV's pixels), the oracle's
    ``segments`` ``(seg0, seg1)`` of a wireframe, and pyrender's ``drawing`` (a Future of
    ``(result, last_bound_px, seconds)``), None where not drawn."""

    def __init__(self, k: int, geometry: tuple):
        self.number, self.geometry = k, geometry
        self.oracle_px: np.ndarray | None = None
        self.segments: tuple | None = None
        self.drawing = None
        self.beside = None  # a Future of pixels_beside's, where it is made on the GL thread
        #: whether pyrender draws on another thread (the run's GL thread): then the measures that need only the
        #: candidate's frame are taken while it draws (:func:`candidate_owners`)
        self.threaded = False

    def drawn(self, acc: CaseFrames):
        """pyrender's drawing, waited for: the wait is the pixel stage's (``acc.seconds["prwait"]``), the GL
        thread's own seconds pyrender's (``"pr"``), and its error bound's (oracles.references.gl_thread.drawing)
        the harness's beside the stage (``"pbeside"``); the bound joins ``acc.oracle_bound_px``."""
        t = time.perf_counter()
        out, bound, seconds, bound_seconds = self.drawing.result()
        acc.add("prwait", t)
        acc.seconds["pr"] += seconds
        acc.seconds["pbeside"] += bound_seconds
        acc.oracle_bound_px = max(acc.oracle_bound_px, bound)
        return out

    def cancel(self) -> None:
        """The drawing asked for is not needed (a queued one is dropped, a running one finishes unread)."""
        if self.drawing is not None:
            self.drawing.cancel()


class ProjectorFrame:
    """One frame of :class:`ProjectorFrames` (oracles.judge.case_loop.SourceFrame)."""

    def __init__(self, source: ProjectorFrames, side: OracleSide, cand_px, precision, cand_img, cand_depth):
        self.source, self.side, self.number, self.geometry = source, side, side.number, side.geometry
        self.oracle_px, self.cand_px, self.precision = side.oracle_px, cand_px, precision
        self.cand_img, self.cand_depth = cand_img, cand_depth

    def vertices(self) -> tuple:
        """``(setup, p_world, cand_px, oracle_px, precision)``: CaseFrames.add_vertices' inputs."""
        return self.source.setup, self.geometry[0], self.cand_px, self.oracle_px, self.precision

    def wireframe(self, frame_rec: dict) -> tuple:
        """``(FramePixels, seg0, seg1, None)``: the candidate's frame against pyrender's drawing of the edges the
        mode draws (hidden lines, culled faces), and where the oracle's lines lie (OpenCV's pixels of the ends)."""
        acc = self.source.acc
        owners = None
        if self.side.beside is not None:  # while pyrender draws: the candidate's pixels' owners (OracleSide)
            t0 = time.perf_counter()
            owners = candidate_owners(self.cand_img, *self.side.segments)
            acc.add("pmetric", t0)
        if self.side.beside is not None:  # the frame's pixels and their places, made beside (pixels_beside)
            self.side.drawn(acc)
            t = time.perf_counter()
            fp, ends, seconds = self.side.beside.result()
            acc.add("prwait", t)
            acc.seconds["pbeside"] += seconds
            fp.ends, fp.owners = ends, owners
        else:
            orac_img, _depth = self.side.drawn(acc)
            t = time.perf_counter()
            fp = metrics.FramePixels(self.cand_img, orac_img)  # one scan of each image
            acc.add("pmetric", t)
        return (fp, *self.side.segments, None)

    def shaded(self) -> tuple:
        """``(depth buffer, the faces it shows, pyrender's (covered, depth, triangle ids))``; the drawing None
        without faces."""
        setup = self.source.setup
        drawing = self.side.drawn(self.source.acc) if self.side.drawing is not None else None
        return self.cand_depth, getattr(setup.candidate, "last_face_ids", None) if setup.use_faces else None, drawing

    def spent(self, kind: str, seconds: float) -> None:
        """A measurement's seconds: the vertex stage's, or the pixel stage's metrics."""
        self.source.acc.spend("vmetric" if kind == "vertices" else "pmetric", seconds)


#: A candidate frame's pixels have their owning edges found while pyrender draws (:func:`candidate_owners`), and
#: the frame's pixels and their places made on the GL thread after its drawing (:func:`pixels_beside`), from
#: this many drawn pixels on (a frame of a 20k-60k face mesh: 40,000-60,000, whose owner search is 15-16 ms
#: of CPU; a frame of the bundled scenes, ~1,000, is scored with the case's other frames in one pass,
#: metrics.LineBatch, whose per-call overhead a frame's own search would pay again).
OWNERS_AHEAD_PX = 1 << 13


def candidate_owners(cand_img: np.ndarray, seg0: np.ndarray, seg1: np.ndarray) -> tuple | None:
    """``(flat, edge)``: the candidate's drawn pixels and the edge owning each (-1: none;
    oracles.judge.segment_pixels.pixel_owners), for a frame whose line scores look for every drawn pixel's
    owner (``DENSE``); None for a sparser frame."""
    flat = np.flatnonzero(cand_img)
    if len(seg0) * segment_pixels.DENSE <= len(flat):
        return None
    h, w = cand_img.shape
    return flat, segment_pixels.pixel_owners(seg0, seg1, w, h, flat)


def pixels_beside(drawing, cand_img: np.ndarray, seg0: np.ndarray, seg1: np.ndarray) -> tuple:
    """``(FramePixels, (ends, ties), CPU seconds)``: a wireframe's drawn pixels against pyrender's ``drawing`` (its
    Future, done: this runs on the GL thread right after it) and where its one-sided pixels lie
    (oracles.judge.line_ends.frames_end_places, which the frame's line scores take: metrics.LineBatch),
    made on the GL thread while this frame's candidate pixels' owners are found in the case's thread
    (:func:`candidate_owners`, compiled: no GIL held)."""
    t = time.thread_time()  # this thread's CPU: its wall time beside the case's thread would count that one's too
    orac_img = drawing.result()[0][0]  # (image, depth) of gl_thread.drawing's tuple
    fp = metrics.FramePixels(cand_img, orac_img)  # one scan of each image
    ties: list = []
    ends = frames_end_places([(fp, seg0, seg1)], ties)[0]
    return fp, (ends, ties[0]), time.thread_time() - t


def _per_frame_ms(seconds: float, frames: int) -> float:
    return 1e3 * seconds / max(frames, 1)


def case_timing(acc: CaseFrames, pixels: bool) -> dict:
    """The case's milliseconds per checked frame, by stage and by side (candidate, OpenCV, pyrender)."""
    sec, done = acc.seconds, len(acc.cand_px)
    timing = {
        "frames_timed": done,
        "vertex_stage_ms_per_frame": _per_frame_ms(sec["setup"] + sec["cv"] + sec["proj"] + sec["vmetric"], done),
        "candidate_project_ms_per_frame": _per_frame_ms(sec["proj"], done),
        "opencv_ms_per_frame": _per_frame_ms(sec["cv"], done),
    }
    if pixels:
        timing.update(
            {
                "pixel_stage_ms_per_frame": _per_frame_ms(
                    sec["draw"] + sec["hdraw"] + sec["prwait"] + sec["pmetric"], done
                ),
                "candidate_draw_ms_per_frame": _per_frame_ms(sec["draw"], done),
                # pyrender's own drawing, on the GL thread beside this one's work (ProjectorFrames), and the
                # part of it the stage waited for: vertex stage + pixel stage = harness + candidate + OpenCV +
                # this wait (docs/performance.md#harness-overhead)
                "pyrender_ms_per_frame": _per_frame_ms(sec["pr"], done),
                "pyrender_wait_ms_per_frame": _per_frame_ms(sec["prwait"], done),
                # the pixel metrics wherever made; of them, those made on the GL thread beside the stage
                "pixel_metrics_ms_per_frame": _per_frame_ms(sec["pmetric"] + sec["pbeside"], done),
                "pixel_metrics_beside_ms_per_frame": _per_frame_ms(sec["pbeside"], done),
            }
        )
    if sec["once"]:  # one-time set-up made inside the case (owner_kernel's first use): not a frame's time
        timing["one_time_setup_ms"] = 1e3 * sec["once"]
    timing["candidate_ms_per_frame"] = _per_frame_ms(sec["proj"] + sec["draw"], done)
    # the harness: everything timed that is not the candidate, OpenCV or pyrender
    # (docs/performance.md#harness-overhead), against the oracles' own time
    harness = sec["setup"] + sec["vmetric"] + sec["hdraw"] + sec["pmetric"] + sec["pbeside"]
    timing["harness_ms_per_frame"] = _per_frame_ms(harness, done)
    timing["oracles_ms_per_frame"] = _per_frame_ms(sec["cv"] + sec["pr"], done)
    return timing
