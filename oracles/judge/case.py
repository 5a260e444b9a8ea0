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
from ..tolerances import Tolerances
from . import metrics
from .case_loop import Measurements, measure_frames
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
    #: seconds: vertex stage = setup + cv + proj + vmetric; pixel stage = draw + hdraw + pr + pmetric
    #: (hdraw: the harness drawing an external candidate's frame, less the candidate's own calls)
    seconds: dict = field(
        default_factory=lambda: dict.fromkeys(("setup", "cv", "proj", "vmetric", "draw", "hdraw", "pr", "pmetric"), 0.0)
    )

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
        t = time.perf_counter()
        self.seconds[key] += t - t0
        return t


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
    (:func:`candidate_frame`: core draws its own, the harness draws another candidate's); pyrender draws when a
    measurement asks. A candidate that fails at a frame ends the frames there (``acc.error``)."""

    def __init__(self, setup: CaseSetup, acc: CaseFrames, tol: Tolerances, pyrender_oracle, numbers: range):
        self.setup, self.acc, self.tol, self.oracle, self.numbers = setup, acc, tol, pyrender_oracle, numbers

    def __iter__(self):
        setup, acc = self.setup, self.acc
        for k in self.numbers:
            t0 = time.perf_counter()
            geometry = oface.frame_geometry(setup.scene, setup.motion, (k - 1) / setup.frames)
            t1 = time.perf_counter()
            oracle_px = opencv_oracle.project(geometry[0], setup.cam)
            t2 = time.perf_counter()
            try:
                cand_px, points, m_core, returned = candidate_vertices(setup, k, geometry[0])
                acc.returned.add(returned)
                t3 = time.perf_counter()
                precision = case_precision(self.tol.precision, acc.returned)[0]
                calls_before = setup.timed.seconds if setup.timed else 0.0
                cand_img, cand_depth = (
                    candidate_frame(setup, points, m_core, geometry[0], precision) if setup.pixels else (None, None)
                )
                t4 = time.perf_counter()
                own_draw = setup.timed.seconds - calls_before if setup.timed else t4 - t3
            except CandidateError as exc:
                acc.error = f"frame {k}: {exc}"
                return
            acc.seconds["setup"] += t1 - t0
            acc.seconds["cv"] += t2 - t1
            acc.seconds["proj"] += t3 - t2
            acc.seconds["draw"] += own_draw
            acc.seconds["hdraw"] += t4 - t3 - own_draw
            yield ProjectorFrame(self, k, geometry, oracle_px, cand_px, precision, cand_img, cand_depth)


class ProjectorFrame:
    """One frame of :class:`ProjectorFrames` (oracles.judge.case_loop.SourceFrame)."""

    def __init__(self, source: ProjectorFrames, k: int, geometry, oracle_px, cand_px, precision, cand_img, cand_depth):
        self.source, self.number, self.geometry = source, k, geometry
        self.oracle_px, self.cand_px, self.precision = oracle_px, cand_px, precision
        self.cand_img, self.cand_depth = cand_img, cand_depth

    def vertices(self) -> tuple:
        """``(setup, p_world, cand_px, oracle_px, precision)``: CaseFrames.add_vertices' inputs."""
        return self.source.setup, self.geometry[0], self.cand_px, self.oracle_px, self.precision

    def _mirrored(self):
        setup = self.source.setup
        if setup.use_faces and setup.mode.cull == "backface":
            return oface.mirrored_vertices(setup.scene, self.geometry[1])
        return None

    def wireframe(self, frame_rec: dict) -> tuple:
        """``(FramePixels, seg0, seg1, None)``: the candidate's frame against pyrender's drawing of the edges the
        mode draws (hidden lines, culled faces), and where the oracle's lines lie (OpenCV's pixels of the ends)."""
        setup, acc = self.source.setup, self.source.acc
        t0 = time.perf_counter()
        p_world, _matrices, pr_vertices, pr_pose = self.geometry
        mode, cam = setup.mode, setup.cam
        mirrored = self._mirrored()
        draw_edges, occluders = setup.edges, None
        seg0, seg1 = oracle_segments(p_world, setup.edges, cam, self.oracle_px)  # where the oracle's lines lie
        if setup.use_faces and mode.cull == "backface":
            kept = setup.owners.kept(oface.front_faces(p_world, setup.faces, cam, mirrored))
            draw_edges = setup.edges[kept]
            seg0[~kept] = seg1[~kept] = np.nan
        if setup.use_faces and mode.hidden_lines:
            occluders = oface.gl_polygons(setup.faces, mirrored)
        t0 = acc.add("pmetric", t0)  # the oracle's segments and the edges to draw: harness, not pyrender
        # the colour only (the mask pyrender's colour-and-depth read gives, without the depth's read back and
        # linearisation: tests/test_oracle_gl.py)
        orac_img, _depth = self.source.oracle.render(
            pr_vertices,
            draw_edges,
            cam,
            model_matrix=pr_pose,
            faces=occluders,
            cull=mode.cull == "backface",
            depth=False,
        )
        t1 = acc.add("pr", t0)
        acc.oracle_bound_px = max(acc.oracle_bound_px, getattr(self.source.oracle, "last_bound_px", 0.0))
        fp = metrics.FramePixels(self.cand_img, orac_img)  # one scan of each image
        acc.add("pmetric", t1)
        return fp, seg0, seg1, None

    def shaded(self) -> tuple:
        """``(depth buffer, the faces it shows, pyrender's (covered, depth, triangle ids))``; the drawing None
        without faces."""
        setup, acc = self.source.setup, self.source.acc
        t0 = time.perf_counter()
        drawing = None
        if setup.use_faces:
            _p_world, _matrices, pr_vertices, pr_pose = self.geometry
            triangles = oface.gl_triangles(setup.tris, self._mirrored())
            t0 = acc.add("pmetric", t0)  # the harness's inputs to pyrender
            drawing = self.source.oracle.render_faces(
                pr_vertices,
                triangles,
                setup.cam,
                model_matrix=pr_pose,
                cull=setup.mode.cull == "backface",
                with_ids=True,
            )
        acc.add("pr", t0)
        if setup.use_faces:
            acc.oracle_bound_px = max(acc.oracle_bound_px, getattr(self.source.oracle, "last_bound_px", 0.0))
        return self.cand_depth, getattr(setup.candidate, "last_face_ids", None) if setup.use_faces else None, drawing

    def spent(self, kind: str, seconds: float) -> None:
        """A measurement's seconds: the vertex stage's, or the pixel stage's metrics."""
        self.source.acc.seconds["vmetric" if kind == "vertices" else "pmetric"] += seconds


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
                    sec["draw"] + sec["hdraw"] + sec["pr"] + sec["pmetric"], done
                ),
                "candidate_draw_ms_per_frame": _per_frame_ms(sec["draw"], done),
                "pyrender_ms_per_frame": _per_frame_ms(sec["pr"], done),
                "pixel_metrics_ms_per_frame": _per_frame_ms(sec["pmetric"], done),
            }
        )
    timing["candidate_ms_per_frame"] = _per_frame_ms(sec["proj"] + sec["draw"], done)
    # the harness: everything timed that is not the candidate, OpenCV or pyrender
    # (docs/performance.md#harness-overhead), against the oracles' own time
    harness = sec["setup"] + sec["vmetric"] + sec["hdraw"] + sec["pmetric"]
    timing["harness_ms_per_frame"] = _per_frame_ms(harness, done)
    timing["oracles_ms_per_frame"] = _per_frame_ms(sec["cv"] + sec["pr"], done)
    return timing
