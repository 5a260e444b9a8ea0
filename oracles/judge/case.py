"""One case: a scene under one camera, frame by frame, the candidate against the oracles.

Frame ``k`` (1-based, at ``t = (k - 1) / frames``) goes through two stages:

1. **vertex stage** (levels ``vertices`` and ``pixels``): the oracle side's world
   points (oracles.references.faces.frame_geometry: scipy matrices, independent of core),
   OpenCV's ``projectPoints`` of them, and the candidate's pixels of the same
   points: core through its own pipeline (:func:`core.projector.pipeline.render_frame`
   given no edges, so nothing is drawn), any other candidate called on the
   world points (oracles.candidates.candidate); :func:`vertex_stage` scores them and keeps
   the case's scale for the precision-derived vertex bound
   (oracles.tolerances.vertex_scale);
2. **pixel stage** (level ``pixels``): the candidate's frame (core's full
   pipeline, or oracles.candidates.draw for another candidate) against pyrender's
   rendering of the same edges, faces or shading (:func:`pixel_stage`).

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
from .verdict import LINE_FRAME_KEYS, SHADED_FRAME_KEYS, case_record, judge

#: The note of a case whose camera has lens distortion, run at level pixels.
PIXELS_NOT_COMPARED = (
    "lens distortion: pixels not compared (GL draws straight lines between the vertices, "
    "a distorted lens bends them); vertices compared against cv2.projectPoints with the "
    "distortion coefficients"
)


@dataclass(frozen=True)
class KeptImage:
    """A bool image kept for worst.gif: its drawn pixels' flat indices (a wireframe: ~1 % of the
    image, already found by frame_pixels.FramePixels), or its bits packed (a filled silhouette)."""

    shape: tuple
    flat: np.ndarray | None = None
    bits: np.ndarray | None = None

    @classmethod
    def of(cls, image: np.ndarray, flat: np.ndarray | None = None) -> KeptImage:
        """``image`` kept: as ``flat`` (its drawn pixels' ascending flat indices) when given, else packed."""
        if flat is not None:
            return cls(image.shape, flat=flat)
        return cls(image.shape, bits=np.packbits(image))

    def image(self) -> np.ndarray:
        """The ``(H, W)`` bool image back."""
        h, w = self.shape
        if self.flat is not None:
            out = np.zeros(h * w, bool)
            out[self.flat] = True
            return out.reshape(h, w)
        return np.unpackbits(self.bits, count=h * w).reshape(h, w).astype(bool)


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
    pixel: dict = field(default_factory=lambda: {key: [] for key in metrics.PIXEL_SCORE_KEYS})
    shaded: list = field(default_factory=list)  # (frame, shaded scores)
    lines: list = field(default_factory=list)  # (frame, metrics.line_scores) of wireframes
    kept: list | None = None  # (frame, KeptImage candidate, KeptImage oracle)
    worst: tuple | None = None  # (key, frame, candidate image, oracle image)
    error: str | None = None
    line_batch: metrics.LineBatch = field(default_factory=metrics.LineBatch)  # frames waiting for line scores
    drawn_px: int = 0  # pixels drawn by either side, over the frames (oracles.judge.gate)
    oracle_bound_px: float = 0.0  # pyrender's own error bound, largest over the frames
    planes: dict | None = None  # the candidate's probed planes (oracles.diagnosis.clip_planes)
    #: seconds: vertex stage = setup + cv + proj + vmetric; pixel stage = draw + hdraw + pr + pmetric
    #: (hdraw: the harness drawing an external candidate's frame, less the candidate's own calls)
    seconds: dict = field(
        default_factory=lambda: dict.fromkeys(("setup", "cv", "proj", "vmetric", "draw", "hdraw", "pr", "pmetric"), 0.0)
    )

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
    acc = CaseFrames(kept=[] if keep_frames and setup.pixels else None)
    for k in range(first, frames + 1, every):
        t0 = time.perf_counter()
        geometry = oface.frame_geometry(scene, motion, (k - 1) / frames)
        t1 = time.perf_counter()
        oracle_px = opencv_oracle.project(geometry[0], setup.cam)
        t2 = time.perf_counter()
        try:
            cand_px, points, m_core, returned = candidate_vertices(setup, k, geometry[0])
            acc.returned.add(returned)
            t3 = time.perf_counter()
            precision = case_precision(tol.precision, acc.returned)[0]
            calls_before = setup.timed.seconds if setup.timed else 0.0
            cand_img, cand_depth = (
                candidate_frame(setup, points, m_core, geometry[0], precision) if setup.pixels else (None, None)
            )
            t4 = time.perf_counter()
            own_draw = setup.timed.seconds - calls_before if setup.timed else t4 - t3
        except CandidateError as exc:
            acc.error = f"frame {k}: {exc}"
            break
        acc.seconds["setup"] += t1 - t0
        acc.seconds["cv"] += t2 - t1
        acc.seconds["proj"] += t3 - t2
        acc.seconds["draw"] += own_draw
        acc.seconds["hdraw"] += t4 - t3 - own_draw
        t5 = time.perf_counter()
        projected = oracle_px  # OpenCV's pixels of every point, for the oracle's segments
        if precision != "float64":
            cand_px, oracle_px = forgive_depth_ties(acc, setup, geometry[0], cand_px, oracle_px, precision)
        frame_rec = vertex_stage(acc, k, cand_px, oracle_px)
        acc.scales.add(geometry[0], oracle_px, setup.cam, setup.cv_matrices)
        t6 = acc.add("vmetric", t5)
        if setup.pixels:
            pixel_stage(
                setup, acc, k, frame_rec, geometry, cand_img, cand_depth, pyrender_oracle, want_images, t6, projected
            )
    t7 = time.perf_counter()
    score_vertices(acc)
    if acc.cand_px and not setup.is_core and visibility_differs(acc):
        acc.planes = setup.planes()  # where the candidate clips, to name a clipping_plane
    acc.scale = acc.scales.flush(setup.cam, setup.cv_matrices)
    t7 = acc.add("vmetric", t7)
    record_lines(acc, acc.line_batch.flush())
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
    if acc.worst is not None:
        images = {"frame": acc.worst[1], "candidate": acc.worst[2], "oracle": acc.worst[3]}
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


def vertex_stage(acc: CaseFrames, k: int, cand_px: np.ndarray, oracle_px: np.ndarray) -> dict:
    """Keep frame ``k``'s vertex pixels and OpenCV's for the case; return the frame's record.

    The record's vertex fields are filled by :func:`score_vertices`, for all
    frames at once (metrics.vertex_errors_frames).
    """
    acc.cand_px.append(cand_px)
    acc.oracle_px.append(oracle_px)
    frame_rec = {
        "frame": k,
        "max_vertex_error_px": None,
        "mean_vertex_error_px": None,
        "rms_vertex_error_px": None,
        "visible_points": None,
    }
    acc.per_frame.append(frame_rec)
    return frame_rec


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


def pixel_stage(
    setup: CaseSetup,
    acc: CaseFrames,
    k: int,
    frame_rec: dict,
    geometry,
    cand_img,
    cand_depth,
    pyrender_oracle,
    want_images: bool,
    t0: float,
    oracle_px: np.ndarray | None = None,
) -> None:
    """pyrender's frame ``k`` against the candidate's: scores into ``frame_rec`` and ``acc`` (time from ``t0``).

    ``oracle_px``: OpenCV's pixels of the frame's world points, when the vertex stage has them.
    """
    p_world, matrices, pr_vertices, pr_pose = geometry
    mode, cam, scene = setup.mode, setup.cam, setup.scene
    fp = None  # the wireframe's drawn pixels (frame_pixels.FramePixels)
    mirrored = oface.mirrored_vertices(scene, matrices) if setup.use_faces and mode.cull == "backface" else None
    if mode.shaded:
        if setup.use_faces:
            triangles = oface.gl_triangles(setup.tris, mirrored)
            t0 = acc.add("pmetric", t0)  # the harness's inputs to pyrender
            orac_img, orac_depth, ids = pyrender_oracle.render_faces(
                pr_vertices, triangles, cam, model_matrix=pr_pose, cull=mode.cull == "backface", with_ids=True
            )
        else:
            orac_img = np.zeros((cam.height, cam.width), bool)
        t1 = acc.add("pr", t0)
        if setup.use_faces:
            acc.oracle_bound_px = max(acc.oracle_bound_px, getattr(pyrender_oracle, "last_bound_px", 0.0))
        cand_img = np.isfinite(cand_depth)
        if setup.use_faces:
            cand_faces = getattr(setup.candidate, "last_face_ids", None)
            orac_faces = np.where(ids >= 0, setup.tri_owner[np.maximum(ids, 0)], -1)  # triangle -> polygon
            ss = metrics.shaded_scores(
                cand_depth,
                orac_img,
                orac_depth,
                metrics.depth_bound(orac_depth, orac_img, cam),
                metrics.occlusion_boundary(ids, setup.tris),
                cand_faces=cand_faces,
                oracle_faces=orac_faces,
            )
            acc.shaded.append((k, ss))
            acc.drawn_px += ss["silhouette_union_px"]
            frame_rec.update({key: ss[key] for key in SHADED_FRAME_KEYS})
            key = (ss["silhouette_iou"], -(ss["depth_error_ratio"] or 0.0))
        else:
            key = None
    else:
        draw_edges, occluders = setup.edges, None
        seg0, seg1 = oracle_segments(p_world, setup.edges, cam, oracle_px)  # where the oracle's lines lie
        if setup.use_faces and mode.cull == "backface":
            kept = setup.owners.kept(oface.front_faces(p_world, setup.faces, cam, mirrored))
            draw_edges = setup.edges[kept]
            seg0[~kept] = seg1[~kept] = np.nan
        if setup.use_faces and mode.hidden_lines:
            occluders = oface.gl_polygons(setup.faces, mirrored)
        t0 = acc.add("pmetric", t0)  # the oracle's segments and the edges to draw: harness, not pyrender
        # the colour only (the mask pyrender's colour-and-depth read gives, without the depth's read back and
        # linearisation: tests/test_oracle_gl.py)
        orac_img, _depth = pyrender_oracle.render(
            pr_vertices,
            draw_edges,
            cam,
            model_matrix=pr_pose,
            faces=occluders,
            cull=mode.cull == "backface",
            depth=False,
        )
        t1 = acc.add("pr", t0)
        acc.oracle_bound_px = max(acc.oracle_bound_px, getattr(pyrender_oracle, "last_bound_px", 0.0))
        fp = metrics.FramePixels(cand_img, orac_img)  # one scan of each image
        ps = metrics.pixel_scores(None, None, pixels=fp)
        acc.drawn_px += ps["candidate_pixels"] + ps["oracle_pixels"] - ps["both_pixels"]
        for name, values in acc.pixel.items():
            values.append(ps[name])
        frame_rec.update({name: ps[name] for name in metrics.PIXEL_SCORE_KEYS})
        at = len(acc.pixel["f1_0px"]) - 1  # this frame's place in acc.pixel
        record_lines(acc, acc.line_batch.add((k, frame_rec, at), fp, seg0, seg1))  # scored with later frames
        key = (ps["f1_1px"], ps["f1_0px"])
    if want_images and key is not None and (acc.worst is None or key < acc.worst[0]):
        acc.worst = (key, k, cand_img.copy(), orac_img.copy())
    if acc.kept is not None:
        acc.kept.append(
            (
                k,
                KeptImage.of(cand_img, fp.cand_idx if fp else None),
                KeptImage.of(orac_img, fp.oracle_idx if fp else None),
            )
        )
    acc.add("pmetric", t1)


def record_lines(acc: CaseFrames, scored: list) -> None:
    """Frames' line scores (metrics.LineBatch: ``[((frame, frame record, place in acc.pixel), scores)]``) into
    ``acc`` and their records.

    A frame with sub-pixel ties has its scores at 0 px replaced by those with
    the ties undecided (metrics.line_scores' ``tie_resolved``), in its record
    and in ``acc.pixel``: F1@0px judges the decided pixels, as the balance does.
    """
    for (k, frame_rec, at), ls in scored:
        acc.lines.append((k, ls))
        frame_rec.update({name: ls[name] for name in LINE_FRAME_KEYS})
        for name, value in (ls["tie_resolved"] or {}).items():
            frame_rec[name] = acc.pixel[name][at] = value


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
