"""Run the cases: candidate vs OpenCV (vertices) and vs pyrender/OSMesa (pixels).

For each case (a scene under one camera) and each checked frame of the scene's
motion (frames 1, 1 + every, 1 + 2 every, ...; frame k is at t = (k - 1) / frames):

1. the model matrix comes from :func:`oracles.convert.model_matrix` (scipy,
   independent of core.transforms), giving ``p_world``;
2. **vertex stage** (levels ``vertices`` and ``pixels``): the candidate
   projects the points — core through its own pipeline,
   :func:`core.pipeline.render_frame` given no edges, so nothing is drawn — and
   OpenCV's ``projectPoints`` is the reference (``oracles.opencv_oracle``);
3. **pixel stage** (level ``pixels`` only): the candidate's frame is drawn —
   core's full pipeline when the candidate is core, else
   :func:`oracles.draw.draw_candidate` — and compared with pyrender's rendering
   of the same edges;

then all frames' points are pooled for :func:`oracles.diagnose.diagnose`.

Drawing modes (:class:`RenderMode`, the core candidate only; the pixel level):

- ``hidden_lines``: core draws with ``hidden_lines=True`` and the scene's
  faces; pyrender draws the same faces black with glPolygonOffset(1, 1) and
  the lines on top. Judged by the same pixel F1 as a plain wireframe. A scene
  without faces has nothing that could hide a line: it is compared as a plain
  wireframe, with a note (not a failure), and ``"hidden_lines": false``.
- ``cull="backface"``: core culls back faces (core.culling's rule) and draws an
  edge only if it belongs to a kept face or to none. The oracle decides front
  faces itself in float64 world space (oracles.faces), draws the kept edges,
  and, with hidden lines, gives pyrender single-sided occluders (GL's own
  back-face culling). On a closed mesh the hidden-line picture is the same
  with or without culling (culling never changes what is visible); on an
  open one the culled back faces hide nothing, in both.
- ``style="shaded"``: core's depth buffer (``Frame.depth_image``) against
  pyrender's rendering of the fan-triangulated faces (flat, no lights:
  coverage and depth only): silhouette IoU, and depth error within a derived
  bound per pixel (oracles.tolerances, oracles.metrics.shaded_scores). A scene
  without faces has nothing to shade: only its vertices are checked, with a
  note.

Several objects (``Scene.objects``, when the scene is not one static object):
the oracle side builds each object's matrix with scipy,
``M_run(t) @ M_o(t)`` (oracles.faces.object_matrices), and gives OpenCV and
pyrender world points (pyrender with an identity pose). core is set up as
``renderer`` sets it up (:class:`core.frames.SceneRenderer`): its own world
points drawn with an identity model matrix. A single static object keeps the
exact path above (pose = the run's matrix).

Cases are independent, so :func:`run_crosscheck` can spread them over worker
processes (``jobs``). Workers are started with the "spawn" method: an OSMesa
context (and llvmpipe's threads) must never be inherited through ``fork``, so
each worker creates its own :class:`PyrenderOracle` objects (one per image
size, cached for the worker's life) and loads a ``FILE.py:FUNC`` candidate
itself from the spec string. Results are gathered in case order, so the report
is the same for any number of jobs.
"""

from __future__ import annotations

import math
import os
import time
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from wirecheck.core.scene import Scene
from wirecheck.core.clipping import CLIP_MODES
from wirecheck.core.raster import RASTER_MODES
from wirecheck.core.projection import DTYPES
from wirecheck.core.transforms import Motion   # parameters only: the oracle's matrix is convert.model_matrix

from . import metrics, opencv_oracle, tolerances
from .candidate import CandidateError, call_candidate
from .cases import Case
from .convert import model_matrix
from .draw import draw_candidate

#: Oracle fidelity levels, cheapest first, and the oracles each one runs.
LEVELS = ("vertices", "pixels")
LEVEL_ORACLES = {"vertices": ("opencv",), "pixels": ("opencv", "pyrender")}

#: A frame of core's pipeline is greyscale with raster "aa": a pixel is drawn from half intensity up.
DRAWN_THRESHOLD = 128


def level_for_oracles(oracles) -> str:
    """The level an ``oracles`` list (the older way to ask) means; ValueError if none."""
    wanted = tuple(o for o in LEVEL_ORACLES["pixels"] if o in set(oracles))
    if set(oracles) - set(wanted):
        raise ValueError(f"oracles {list(oracles)!r}: expected some of {', '.join(LEVEL_ORACLES['pixels'])}")
    for level, names in LEVEL_ORACLES.items():
        if wanted == names:
            return level
    raise ValueError(f"oracles {list(oracles)!r}: expected opencv among them (vertices are always checked)")


@dataclass
class Tolerances:
    vertex_px: float = tolerances.VERTEX_TOL_PX
    min_f1_1px: float = tolerances.MIN_F1_1PX
    min_f1_0px: float = tolerances.MIN_F1_0PX
    min_iou: float = tolerances.MIN_SILHOUETTE_IOU

    def to_dict(self, shaded: bool = False) -> dict:
        if shaded:
            return {"vertex_error_px": self.vertex_px, "min_silhouette_iou": self.min_iou,
                    "depth_error": DEPTH_BOUND_TEXT}
        return {"vertex_error_px": self.vertex_px, "min_pixel_f1_1px": self.min_f1_1px,
                "min_pixel_f1_0px": self.min_f1_0px}


#: The shaded depth bound, as stated in the report (oracles/tolerances.py derives it).
DEPTH_BOUND_TEXT = (f"per pixel, {tolerances.DEPTH_STEPS:g} depth-buffer steps + slope/{1 / tolerances.DEPTH_SNAP_PX:g}"
                    f" + {tolerances.DEPTH_EPS32:g} eps32 z")


@dataclass(frozen=True)
class RenderMode:
    """What the pixel stage draws: the style, hidden lines and back-face culling (core candidate only)."""

    style: str = "wireframe"
    hidden_lines: bool = False
    cull: str = "none"

    STYLES: ClassVar[tuple] = ("wireframe", "shaded")
    CULLS: ClassVar[tuple] = ("none", "backface")

    def __post_init__(self):
        for name, allowed in (("style", self.STYLES), ("cull", self.CULLS)):
            if getattr(self, name) not in allowed:
                raise ValueError(f"{name} {getattr(self, name)!r}: expected one of {', '.join(allowed)}")
        if self.style == "shaded" and self.hidden_lines:
            raise ValueError("hidden_lines: a shaded frame has no lines (hidden lines are for style wireframe)")

    @property
    def plain(self) -> bool:
        """A plain wireframe: faces play no part."""
        return self.style == "wireframe" and not self.hidden_lines and self.cull == "none"

    @property
    def shaded(self) -> bool:
        return self.style == "shaded"

    def to_dict(self) -> dict:
        return {"style": self.style, "hidden_lines": self.hidden_lines, "cull": self.cull}

    def core_kwargs(self) -> dict:
        """Keywords of :func:`core.pipeline.render_frame`."""
        return {"style": self.style, "hidden_lines": self.hidden_lines,
                "cull": None if self.cull == "none" else self.cull}


@dataclass
class CaseResult:
    record: dict                       # what goes into report.json
    worst_images: dict | None = None   # {"frame", "candidate", "oracle"} bool images
    timing: dict = field(default_factory=dict)
    #: every checked frame's images, bit-packed: [(frame, candidate, oracle)] (for worst.gif)
    frame_images: list | None = None


@dataclass(frozen=True)
class CoreCandidate:
    """core/ as the candidate: vertices (and frames) through core's whole pipeline.

    ``dtype``, ``clip`` and ``raster`` are passed to :func:`core.pipeline.render_frame`
    (``clip`` as its ``clip_mode``).
    """

    dtype: str = "float64"
    clip: str = "clip"
    raster: str = "exact"

    name: ClassVar[str] = "core"
    DTYPES: ClassVar[tuple] = DTYPES              # core's own lists, so the two cannot drift apart
    CLIPS: ClassVar[tuple] = CLIP_MODES
    RASTERS: ClassVar[tuple] = RASTER_MODES

    def __post_init__(self):
        for name, allowed in (("dtype", self.DTYPES), ("clip", self.CLIPS), ("raster", self.RASTERS)):
            if getattr(self, name) not in allowed:
                raise ValueError(f"{name} {getattr(self, name)!r}: expected one of {', '.join(allowed)}")

    def settings(self) -> dict:
        return {"dtype": self.dtype, "clip": self.clip, "raster": self.raster}

    def __call__(self, points, camera):  # the candidate contract, for completeness
        from wirecheck.core.projection import project_points

        return project_points(points, camera, dtype=self.dtype)

    def prepare(self, p_model: np.ndarray):
        """Points re-centred and cast once (``core.projection.localize``), as ``renderer`` does."""
        from wirecheck.core.projection import localize

        return localize(p_model, self.dtype)

    def scene_frames(self, scene, motion, frames: int):
        """core's scene-level renderer (:class:`core.frames.SceneRenderer`) in this candidate's settings.

        Its :meth:`~core.frames.SceneRenderer.geometry` gives each frame's points
        and model matrix, and its ``faces`` the faces as core draws them, as
        ``renderer`` sets them up.
        """
        from wirecheck.core.frames import SceneRenderer

        return SceneRenderer(scene, motion, frames, clip=self.clip, dtype=self.dtype, raster=self.raster,
                             object_culling=False)

    def project(self, points, camera, model_matrix: np.ndarray) -> np.ndarray:
        """Vertex pixels from core's pipeline without drawing: ``render_frame`` given no edges."""
        from wirecheck.core.pipeline import render_frame

        no_edges = np.zeros((0, 2), dtype=np.intp)
        return render_frame(points, no_edges, camera, model_matrix, self.clip, raster=self.raster).p_px

    def draw(self, points, edges: np.ndarray, camera, model_matrix: np.ndarray) -> np.ndarray:
        """The frame core draws, as a bool image (drawn where the image is >= 128)."""
        from wirecheck.core.pipeline import render_frame

        frame = render_frame(points, edges, camera, model_matrix, self.clip, raster=self.raster)
        return frame.image >= DRAWN_THRESHOLD

    def render(self, points, edges: np.ndarray, camera, model_matrix: np.ndarray, faces, mode: RenderMode):
        """core's :class:`~core.pipeline.Frame` in a drawing mode (faces None: the scene has none)."""
        from wirecheck.core.pipeline import render_frame

        return render_frame(points, edges, camera, model_matrix, self.clip, raster=self.raster, faces=faces,
                            **mode.core_kwargs())

    def draw_mode(self, points, edges: np.ndarray, camera, model_matrix: np.ndarray, faces,
                  mode: RenderMode) -> np.ndarray:
        """The frame core draws with hidden lines and/or culling, as a bool image."""
        return self.render(points, edges, camera, model_matrix, faces, mode).image >= DRAWN_THRESHOLD

    def shade(self, points, edges: np.ndarray, camera, model_matrix: np.ndarray, faces,
              mode: RenderMode) -> np.ndarray:
        """core's depth buffer of a shaded frame: ``(H, W)`` linear camera depth, +inf where empty.

        The polygon shown at each pixel (-1: none) is kept in ``self.last_face_ids``.
        """
        frame = self.render(points, edges, camera, model_matrix, faces, mode)
        if frame.depth_image is None:
            object.__setattr__(self, "last_face_ids", None)
            return np.full((camera.height, camera.width), np.inf)
        object.__setattr__(self, "last_face_ids", frame.face_ids)
        return np.asarray(frame.depth_image, dtype=np.float64)


def _per_frame_ms(seconds: float, frames: int) -> float:
    return 1e3 * seconds / max(frames, 1)


def _case_faces(scene: Scene):
    """The scene's polygons as a tuple of index tuples, None when it has none."""
    faces = tuple(tuple(int(i) for i in f) for f in scene.faces)
    return faces or None


def run_case(scene: Scene, case: Case, frames: int, candidate, motion: Motion,
             tol: Tolerances, pyrender_oracle=None, want_images: bool = True, every: int = 1,
             mode: RenderMode | None = None, keep_frames: bool = False, first: int = 1) -> CaseResult:
    """One case; the pixel stage runs when ``pyrender_oracle`` is given.

    Frames ``first, first + every, ...`` up to ``frames`` are checked (the
    viewer's overlay checks one frame: ``first=k, every=frames``).

    ``mode`` is the drawing mode of the pixel stage (module docstring); with
    ``keep_frames`` every checked frame's images are kept (bit-packed) in
    :attr:`CaseResult.frame_images`.
    """
    from . import faces as oface

    mode = mode or RenderMode()
    cam = case.camera
    is_core = isinstance(candidate, CoreCandidate)
    pixels = pyrender_oracle is not None
    if not mode.plain and not is_core and pixels:
        raise ValueError(f"drawing mode {mode.to_dict()}: only the core candidate draws faces")
    edges = np.asarray(scene.edges)
    faces = _case_faces(scene)
    use_faces = pixels and faces is not None and not mode.plain
    # core is set up as renderer sets it up (core.frames): its own matrices and world points,
    # and, for a multi-object scene, faces re-wound for mirrored objects
    core_frames = candidate.scene_frames(scene, motion, frames) if is_core else None
    core_faces = core_frames.faces if is_core and faces is not None else faces
    if use_faces and mode.shaded:
        tris, tri_owner = oface.fan(faces)
    if use_faces and mode.cull == "backface":
        owners = oface.EdgeOwners(edges, faces, len(scene.vertices))
    cand_all, orac_all = [], []
    frame_errors = []
    per_frame = []
    f1_0, f1_1, prec_0, rec_0, prec_1, rec_1 = [], [], [], [], [], []
    shaded = []                      # per-frame shaded scores
    kept_frames = [] if keep_frames and pixels else None
    worst = None                     # (key, frame, cand_img, oracle_img)
    # seconds: vertex stage = t_setup + t_cv + t_proj + t_vmetric; pixel stage = t_draw + t_pr + t_pmetric
    t_setup = t_cv = t_proj = t_vmetric = t_draw = t_pr = t_pmetric = 0.0
    error = None
    for k in range(first, frames + 1, every):
        t0 = time.perf_counter()
        p_world, matrices, pr_vertices, pr_pose = oface.frame_geometry(scene, motion, (k - 1) / frames)
        t1 = time.perf_counter()
        oracle_px = opencv_oracle.project(p_world, cam)
        t2 = time.perf_counter()
        try:
            if is_core:
                try:
                    points, m_core = core_frames.geometry(k)
                    cand_px = candidate.project(points, cam, m_core)
                except Exception as exc:      # core crashing is a failed case, not a crashed run
                    raise CandidateError(f"core raised {type(exc).__name__}: {exc}") from exc
            else:
                cand_px = call_candidate(candidate, p_world, cam)
            t3 = time.perf_counter()
            cand_img = cand_depth = None
            if pixels:
                if is_core:
                    try:
                        if mode.plain:
                            cand_img = candidate.draw(points, edges, cam, m_core)
                        elif mode.shaded:
                            cand_depth = candidate.shade(points, edges, cam, m_core, core_faces, mode)
                        else:
                            cand_img = candidate.draw_mode(points, edges, cam, m_core, core_faces, mode)
                    except Exception as exc:
                        raise CandidateError(f"core raised {type(exc).__name__}: {exc}") from exc
                else:
                    cand_img = draw_candidate(candidate, p_world, edges, cam)
            t4 = time.perf_counter()
        except CandidateError as exc:
            error = f"frame {k}: {exc}"
            break
        t_setup += t1 - t0
        t_cv += t2 - t1
        t_proj += t3 - t2
        t_draw += t4 - t3
        t5 = time.perf_counter()
        cand_all.append(cand_px)
        orac_all.append(oracle_px)
        ve = metrics.vertex_errors(cand_px, oracle_px)
        if ve["max_px"] is not None:
            frame_errors.append((ve["max_px"], k, ve["worst_index"]))
        frame_rec = {"frame": k, "max_vertex_error_px": ve["max_px"], "mean_vertex_error_px": ve["mean_px"],
                     "rms_vertex_error_px": ve["rms_px"], "visible_points": ve["visible_both"]}
        per_frame.append(frame_rec)
        t6 = time.perf_counter()
        t_vmetric += t6 - t5
        if not pixels:
            continue
        mirrored = (oface.mirrored_vertices(scene, matrices) if use_faces and mode.cull == "backface"
                    else None)
        if mode.shaded:
            if use_faces:
                orac_img, orac_depth, ids = pyrender_oracle.render_faces(
                    pr_vertices, oface.gl_triangles(tris, mirrored), cam, model_matrix=pr_pose,
                    cull=mode.cull == "backface", with_ids=True)
            else:
                orac_img = np.zeros((cam.height, cam.width), bool)
            t7 = time.perf_counter()
            t_pr += t7 - t6
            cand_img = np.isfinite(cand_depth)
            if use_faces:
                cand_faces = getattr(candidate, "last_face_ids", None)
                orac_faces = np.where(ids >= 0, tri_owner[np.maximum(ids, 0)], -1)   # triangle -> polygon
                ss = metrics.shaded_scores(cand_depth, orac_img, orac_depth,
                                           metrics.depth_bound(orac_depth, orac_img, cam),
                                           metrics.occlusion_boundary(ids, tris),
                                           cand_faces=cand_faces, oracle_faces=orac_faces)
                shaded.append((k, ss))
                frame_rec.update({key: ss[key] for key in SHADED_FRAME_KEYS})
                key = (ss["silhouette_iou"], -(ss["depth_error_ratio"] or 0.0))
            else:
                key = None
        else:
            draw_edges, occluders = edges, None
            if use_faces and mode.cull == "backface":
                draw_edges = edges[owners.kept(oface.front_faces(p_world, faces, cam, mirrored))]
            if use_faces and mode.hidden_lines:
                occluders = oface.gl_polygons(faces, mirrored)
            orac_img, _depth = pyrender_oracle.render(pr_vertices, draw_edges, cam, model_matrix=pr_pose,
                                                      faces=occluders, cull=mode.cull == "backface")
            t7 = time.perf_counter()
            t_pr += t7 - t6
            ps = metrics.pixel_scores(cand_img, orac_img)
            f1_0.append(ps["f1_0px"]); f1_1.append(ps["f1_1px"])
            prec_0.append(ps["precision_0px"]); rec_0.append(ps["recall_0px"])
            prec_1.append(ps["precision_1px"]); rec_1.append(ps["recall_1px"])
            frame_rec.update({key: ps[key] for key in ("f1_0px", "f1_1px", "precision_0px", "recall_0px",
                                                       "precision_1px", "recall_1px")})
            key = (ps["f1_1px"], ps["f1_0px"])
        if want_images and key is not None and (worst is None or key < worst[0]):
            worst = (key, k, cand_img.copy(), orac_img.copy())
        if kept_frames is not None:
            kept_frames.append((k, np.packbits(cand_img), np.packbits(orac_img)))
        t_pmetric += time.perf_counter() - t7
    done = len(cand_all)
    rec = {"scene": scene.name, "camera": case.name, "camera_spec": cam.to_dict(), "frames": frames,
           "frames_checked": done}
    if pixels and mode.hidden_lines:
        rec["hidden_lines"] = faces is not None
    if done:
        cand = np.concatenate(cand_all)
        orac = np.concatenate(orac_all)
        ve = metrics.vertex_errors(cand, orac)
        worst_v = max(frame_errors, key=lambda e: (e[0], -e[1])) if frame_errors else (None, None, None)
        rec.update({
            "max_vertex_error_px": ve["max_px"],
            "mean_vertex_error_px": ve["mean_px"],
            "rms_vertex_error_px": ve["rms_px"],
            "worst_vertex": {"frame": worst_v[1], "vertex": worst_v[2], "error_px": worst_v[0]},
            "visible_points": ve["visible_both"],
            "visibility_mismatch": {"candidate_only": ve["candidate_only"], "oracle_only": ve["oracle_only"]},
        })
        from .diagnose import diagnose

        faults = diagnose(cand, orac, cam, tol_px=tol.vertex_px)
    else:
        rec.update({"max_vertex_error_px": None, "mean_vertex_error_px": None, "rms_vertex_error_px": None})
        faults = []
    if f1_0:
        worst_frame = worst[1] if worst else None
        rec.update({
            "pixel_f1_0px": float(min(f1_0)), "pixel_f1_1px": float(min(f1_1)),
            "pixel_f1_0px_mean": float(np.mean(f1_0)), "pixel_f1_1px_mean": float(np.mean(f1_1)),
            "pixel_precision_0px": float(min(prec_0)), "pixel_recall_0px": float(min(rec_0)),
            "pixel_precision_1px": float(min(prec_1)), "pixel_recall_1px": float(min(rec_1)),
            "worst_pixel_frame": worst_frame,
        })
    else:
        rec.update({"pixel_f1_0px": None, "pixel_f1_1px": None})
    if pixels and mode.shaded:
        rec.update(_shaded_summary(shaded, worst))
    rec["faults"] = faults
    reasons = []
    if error:
        reasons.append(error)
    if done and len(scene.vertices) == 0:
        rec["note"] = "nothing to check: the scene has no vertices"
    elif done and rec["visible_points"] == 0:
        rec["note"] = "no point visible to both projectors: only the visible/clipped sets were compared"
    elif done and pixels and not mode.plain and faces is None:
        rec["note"] = {"shaded": "no faces: nothing to shade; only the vertices were checked",
                       "wireframe": "no faces: nothing hides or culls a line; compared as a plain wireframe"
                       }[mode.style]
    if done:
        if rec["max_vertex_error_px"] is not None and rec["max_vertex_error_px"] > tol.vertex_px:
            reasons.append(f"max vertex error {rec['max_vertex_error_px']:.3g} px > {tol.vertex_px:.3g} px "
                           f"(frame {rec['worst_vertex']['frame']}, vertex {rec['worst_vertex']['vertex']})")
        vm = rec["visibility_mismatch"]
        if vm["candidate_only"] or vm["oracle_only"]:
            reasons.append(f"visible sets differ: {vm['candidate_only']} points shown only by the candidate, "
                           f"{vm['oracle_only']} only by the oracle")
    if f1_0:
        if rec["pixel_f1_1px"] < tol.min_f1_1px:
            reasons.append(f"pixel F1@1px {rec['pixel_f1_1px']:.4f} < {tol.min_f1_1px} "
                           f"(frame {rec['worst_pixel_frame']})")
        if rec["pixel_f1_0px"] < tol.min_f1_0px:
            reasons.append(f"pixel F1@0px {rec['pixel_f1_0px']:.4f} < {tol.min_f1_0px}")
    if shaded:
        if rec["silhouette_mismatch_inside"]:
            reasons.append(f"{rec['silhouette_mismatch_inside']} pixels covered by one side only lie inside its "
                           "silhouette, not on its boundary (a hole or a misplaced region)")
        if rec["silhouette_iou_gated"] is not None and rec["silhouette_iou_gated"] < tol.min_iou:
            reasons.append(f"silhouette IoU {rec['silhouette_iou_gated']:.4f} < {tol.min_iou} "
                           f"(frame {rec['worst_pixel_frame']})")
        if rec["face_disagreements_inside"]:
            reasons.append(f"{rec['face_disagreements_inside']} pixels show a different face than the oracle "
                           "away from any boundary between the two faces (a visibility error)")
        if rec["depth_error_ratio"] is not None and rec["depth_error_ratio"] > 1.0:
            reasons.append(f"depth error {rec['depth_max_error']:.3g} > its bound {rec['depth_error_bound']:.3g} "
                           f"(error/bound up to {rec['depth_error_ratio']:.3g}, frame {rec['depth_worst_frame']})")
    rec["verdict"] = "fail" if reasons else "pass"
    rec["reasons"] = reasons
    rec["per_frame"] = per_frame
    timing = {"frames_timed": done,
              "vertex_stage_ms_per_frame": _per_frame_ms(t_setup + t_cv + t_proj + t_vmetric, done),
              "candidate_project_ms_per_frame": _per_frame_ms(t_proj, done),
              "opencv_ms_per_frame": _per_frame_ms(t_cv, done)}
    if pixels:
        timing.update({"pixel_stage_ms_per_frame": _per_frame_ms(t_draw + t_pr + t_pmetric, done),
                       "candidate_draw_ms_per_frame": _per_frame_ms(t_draw, done),
                       "pyrender_ms_per_frame": _per_frame_ms(t_pr, done),
                       "pixel_metrics_ms_per_frame": _per_frame_ms(t_pmetric, done)})
    timing["candidate_ms_per_frame"] = _per_frame_ms(t_proj + t_draw, done)
    images = None
    if worst is not None:
        images = {"frame": worst[1], "candidate": worst[2], "oracle": worst[3]}
    return CaseResult(record=rec, worst_images=images, timing=timing, frame_images=kept_frames)


#: Per-frame fields of a shaded comparison (oracles.metrics.shaded_scores).
SHADED_FRAME_KEYS = ("silhouette_iou", "silhouette_union_px", "silhouette_mismatch_inside", "depth_pixels", "depth_max_error", "depth_mean_error",
                     "depth_error_bound", "depth_error_ratio", "face_disagreements", "face_disagreements_inside")


def _shaded_summary(shaded: list, worst) -> dict:
    """A case's shaded fields from its frames' scores (None where nothing was compared)."""
    out = {"silhouette_iou": None, "silhouette_iou_mean": None, "depth_max_error": None,
           "depth_mean_error": None, "depth_error_bound": None, "depth_error_ratio": None,
           "depth_worst_frame": None, "depth_pixels": 0, "worst_pixel_frame": None,
           "face_disagreements": 0, "face_disagreements_inside": 0,
           "silhouette_mismatch_inside": 0, "silhouette_iou_gated": None}
    if not shaded:
        return out
    from .tolerances import MIN_IOU_UNION_PX

    out["silhouette_mismatch_inside"] = int(sum(s.get("silhouette_mismatch_inside", 0) for _, s in shaded))
    gated = [s["silhouette_iou"] for _, s in shaded if s.get("silhouette_union_px", 0) >= MIN_IOU_UNION_PX]
    out["silhouette_iou_gated"] = float(min(gated)) if gated else None     # IoU over frames big enough to judge
    out["face_disagreements"] = int(sum(s.get("face_disagreements", 0) for _, s in shaded))
    out["face_disagreements_inside"] = int(sum(s.get("face_disagreements_inside", 0) for _, s in shaded))
    ious = [s["silhouette_iou"] for _, s in shaded]
    out.update(silhouette_iou=float(min(ious)), silhouette_iou_mean=float(np.mean(ious)),
               worst_pixel_frame=worst[1] if worst else None)
    with_depth = [(k, s) for k, s in shaded if s["depth_max_error"] is not None]
    if with_depth:
        pixels = sum(s["depth_pixels"] for _, s in with_depth)
        k_err, s_err = max(with_depth, key=lambda e: (e[1]["depth_max_error"], -e[0]))
        k_ratio, s_ratio = max(with_depth, key=lambda e: (e[1]["depth_error_ratio"], -e[0]))
        out.update(depth_max_error=s_err["depth_max_error"], depth_error_bound=s_err["depth_error_bound"],
                   depth_mean_error=float(sum(s["depth_mean_error"] * s["depth_pixels"]
                                              for _, s in with_depth) / pixels),
                   depth_error_ratio=s_ratio["depth_error_ratio"], depth_worst_frame=k_ratio,
                   depth_pixels=int(pixels))
    return out


# ---------------------------------------------------------------- running cases, here or in workers

@dataclass(frozen=True)
class _RunParams:
    """What every case of a run shares; picklable (sent to workers)."""

    frames: int
    every: int
    level: str
    motion: Motion
    tol: Tolerances
    candidate: object        # a picklable callable (CoreCandidate), or a "FILE.py:FUNC" spec string
    mode: RenderMode = RenderMode()
    keep_frames: bool = False   # every checked frame's images, for worst.gif


class _CaseRunner:
    """Runs cases with cached resources: pyrender oracles by image size, loaded candidates by spec.

    One per process: the parent's (``jobs=1``) is closed at the end of the run;
    a worker's lives as long as the worker. The first call into OpenCV, scipy,
    core or a new OpenGL context costs up to ~100 ms of one-time set-up; each
    process pays it once on a dummy input before its first case, so the times
    per frame measure the frames (and do not grow with ``jobs``). An external
    candidate is never called on such a dummy input.
    """

    _DUMMY_POINTS = np.array([[-0.5, -0.5, 0.0], [0.5, 0.5, 0.0]])
    _DUMMY_EDGES = np.array([[0, 1]], dtype=np.intp)

    def __init__(self):
        from .pyrender_oracle import OracleCache

        self.renderers = OracleCache()
        self.candidates = {}
        self.warm = False

    def candidate(self, ref):
        if not isinstance(ref, str):
            return ref
        if ref not in self.candidates:
            from .candidate import load_candidate

            self.candidates[ref] = load_candidate(ref)
        return self.candidates[ref]

    _DUMMY_TRIANGLE = (np.array([[-0.5, -0.5, 0.0], [0.5, -0.5, 0.0], [0.0, 0.5, 0.0]]),
                       np.array([[0, 1, 2]], dtype=np.int64))

    def renderer(self, camera, mode: RenderMode | None = None):
        size = (camera.width, camera.height)
        new = size not in self.renderers
        oracle = self.renderers.get(*size)
        if new:
            oracle.render(self._DUMMY_POINTS, self._DUMMY_EDGES, camera)   # compiles the shaders
            if mode is not None and mode.shaded:
                oracle.render_faces(*self._DUMMY_TRIANGLE, camera)         # and the id shader
        return oracle

    def warm_up(self, camera, candidate, level: str) -> None:
        pts, eye = self._DUMMY_POINTS, np.eye(4)
        model_matrix((1.0, 1.0, 0.0), (0.0, 0.0, 0.0), 1.0, 0.25)
        orac = opencv_oracle.project(pts, camera)
        metrics.vertex_errors(orac, orac)
        if isinstance(candidate, CoreCandidate):
            candidate.project(pts, camera, eye)
            if level == "pixels":
                candidate.draw(pts, self._DUMMY_EDGES, camera, eye)
        if level == "pixels":
            blank = np.zeros((camera.height, camera.width), bool)
            metrics.pixel_scores(blank, blank)
        self.warm = True

    def run(self, scene: Scene, case: Case, params: _RunParams) -> CaseResult:
        candidate = self.candidate(params.candidate)
        if not self.warm:
            self.warm_up(case.camera, candidate, params.level)
        pyr = self.renderer(case.camera, params.mode) if params.level == "pixels" else None
        return run_case(scene, case, params.frames, candidate, params.motion,
                        params.tol, pyrender_oracle=pyr, every=params.every, mode=params.mode,
                        keep_frames=params.keep_frames)

    def close(self) -> None:
        self.renderers.close()


_WORKER_RUNNER: _CaseRunner | None = None


def _worker_init() -> None:
    global _WORKER_RUNNER
    from multiprocessing.util import Finalize

    os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa")
    _WORKER_RUNNER = _CaseRunner()
    Finalize(_WORKER_RUNNER, _WORKER_RUNNER.close, exitpriority=10)   # free the GL contexts at exit


def _worker_run(scene: Scene, case: Case, params: _RunParams) -> CaseResult:
    return _WORKER_RUNNER.run(scene, case, params)


def _run_tasks(tasks, params: _RunParams, jobs: int, on_result=None) -> tuple[list[CaseResult], int]:
    """Results in task order, and the number of worker processes used (0: in this process).

    ``on_result(result)`` is called on each result as it is gathered, in task
    order (it may drop what it does not need to keep, e.g. frame images).
    """
    on_result = on_result or (lambda result: None)
    workers = min(jobs, len(tasks))
    if workers <= 1:
        runner = _CaseRunner()
        try:
            results = []
            for scene, case in tasks:
                results.append(runner.run(scene, case, params))
                on_result(results[-1])
            return results, 0
        finally:
            runner.close()
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    # "spawn": a fresh interpreter per worker, so no OpenGL/OSMesa state or thread is inherited.
    ctx = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(max_workers=workers, mp_context=ctx, initializer=_worker_init) as pool:
        futures = [pool.submit(_worker_run, scene, case, params) for scene, case in tasks]
        try:
            results = []
            for i, f in enumerate(futures):
                results.append(f.result())
                futures[i] = None          # the future held the result too
                on_result(results[-1])
            return results, workers
        except BaseException:
            for f in futures:
                if f is not None:
                    f.cancel()
            raise


def _overall_ms(timing_cases: list[dict], key: str):
    """Time per frame over all cases (weighted by the frames each case timed)."""
    rows = [t for t in timing_cases if key in t]
    frames = sum(t["frames_timed"] for t in rows)
    if not rows:
        return None
    return sum(t[key] * t["frames_timed"] for t in rows) / frames if frames else 0.0


def run_crosscheck(scenes, candidate, frames: int = 24, case_names=None, oracles=None,
                   turns=(1.0, 1.0, 0.0), tol: Tolerances | None = None, candidate_name: str = "candidate",
                   *, level: str | None = None, every: int = 1, jobs: int = 1,
                   candidate_spec: str | None = None, mode: RenderMode | None = None,
                   animation: bool = True) -> tuple[dict, dict]:
    """Every scene under every case camera: the report dict and the worst-frame images.

    ``level`` is "vertices" (OpenCV only) or "pixels" (OpenCV and pyrender, the
    default); ``oracles`` (("opencv",) or ("opencv", "pyrender")) is the older
    way to say the same, and must agree with ``level`` when both are given.
    Frames 1, 1 + ``every``, ... of the ``frames``-frame motion are checked.
    With ``jobs`` > 1 the cases run in that many worker processes; a candidate
    that is not core is then best given as ``candidate_spec`` ("FILE.py:FUNC"),
    which each worker loads (``candidate`` itself must otherwise be picklable).

    ``mode`` (:class:`RenderMode`) is the drawing mode of the pixel stage
    (hidden lines, back-face culling, shaded); anything but the plain
    wireframe needs the core candidate and level "pixels".

    ``images[(scene, camera)] = {"frame", "candidate", "oracle"}``; with
    ``animation`` (level pixels), ``images["animation"]`` holds every checked
    frame of the worst case (lowest F1, or IoU when shaded, then largest
    vertex error): ``{"scene", "camera", "frames": [k...], "candidate": [...],
    "oracle": [...]}`` (bool images), for worst.gif. Raises InputError when no
    camera can be placed for a scene (coordinates too large), ValueError for a
    bad level, ``every``, ``jobs`` or mode.
    """
    from wirecheck.core.errors import InputError

    from .cases import cameras_for

    if oracles is not None:
        implied = level_for_oracles(oracles)
        if level is not None and level != implied:
            raise ValueError(f"level {level!r} contradicts oracles {list(oracles)!r} (level {implied!r})")
        level = implied
    level = level or "pixels"
    if level not in LEVELS:
        raise ValueError(f"level {level!r}: expected one of {', '.join(LEVELS)}")
    if every < 1:
        raise ValueError(f"every {every}: expected an integer >= 1")
    if jobs < 1:
        raise ValueError(f"jobs {jobs}: expected an integer >= 1")
    mode = mode or RenderMode()
    if not mode.plain:
        if level != "pixels":
            raise ValueError(f"drawing mode {mode.to_dict()}: needs level pixels (nothing is drawn at {level})")
        if not isinstance(candidate, CoreCandidate):
            raise ValueError(f"drawing mode {mode.to_dict()}: only the core candidate draws faces")
    tol = tol or Tolerances()
    motion = Motion(turns=tuple(float(x) for x in turns))
    t_run = time.perf_counter()
    tasks = []
    for scene in scenes:
        try:
            scene_cases = cameras_for(scene.radius)
        except InputError as exc:
            raise InputError(f"{scene.source}: no camera fits this scene ({exc})") from None
        tasks += [(scene, case) for case in scene_cases if case_names is None or case.name in case_names]
    is_core = isinstance(candidate, CoreCandidate)
    ref = candidate if is_core or candidate_spec is None else candidate_spec
    keep_frames = animation and level == "pixels"
    params = _RunParams(frames=frames, every=every, level=level, motion=motion, tol=tol, candidate=ref,
                        mode=mode, keep_frames=keep_frames)
    worst = _WorstCase(mode)
    results, workers = _run_tasks(tasks, params, jobs, on_result=worst.offer if keep_frames else None)

    records, images, timing_cases = [], {}, []
    for (scene, case), result in zip(tasks, results):
        records.append(result.record)
        timing_cases.append({"scene": scene.name, "camera": case.name, **result.timing})
        if result.worst_images:
            images[(scene.name, case.name)] = result.worst_images

    worst_case = None
    if worst.result is not None:
        images["animation"] = worst.animation()
        worst_case = {"scene": images["animation"]["scene"], "camera": images["animation"]["camera"],
                      "frames_checked": len(images["animation"]["frames"]), "animation": "worst.gif"}
    failed = sum(1 for r in records if r["verdict"] != "pass")
    vertex_errs = [r["max_vertex_error_px"] for r in records if r.get("max_vertex_error_px") is not None]
    f1_0 = [r["pixel_f1_0px"] for r in records if r.get("pixel_f1_0px") is not None]
    f1_1 = [r["pixel_f1_1px"] for r in records if r.get("pixel_f1_1px") is not None]
    timing = {"vertex_stage_ms_per_frame": _overall_ms(timing_cases, "vertex_stage_ms_per_frame")}
    if level == "pixels":
        timing["pixel_stage_ms_per_frame"] = _overall_ms(timing_cases, "pixel_stage_ms_per_frame")
    for key in ("candidate_ms_per_frame", "candidate_project_ms_per_frame", "opencv_ms_per_frame"):
        timing[key] = _overall_ms(timing_cases, key)
    if level == "pixels":
        for key in ("candidate_draw_ms_per_frame", "pyrender_ms_per_frame", "pixel_metrics_ms_per_frame"):
            timing[key] = _overall_ms(timing_cases, key)
    timing.update({"jobs": jobs, "workers": workers, "wall_s": time.perf_counter() - t_run,
                   "cases": timing_cases})
    summary = {"cases": len(records), "passed": len(records) - failed, "failed": failed,
               "max_vertex_error_px": max(vertex_errs) if vertex_errs else None,
               "min_pixel_f1_0px": min(f1_0) if f1_0 else None,
               "min_pixel_f1_1px": min(f1_1) if f1_1 else None}
    if mode.shaded and level == "pixels":
        ious = [r["silhouette_iou"] for r in records if r.get("silhouette_iou") is not None]
        derr = [r["depth_max_error"] for r in records if r.get("depth_max_error") is not None]
        ratio = [r["depth_error_ratio"] for r in records if r.get("depth_error_ratio") is not None]
        summary.update({"min_silhouette_iou": min(ious) if ious else None,
                        "max_depth_error": max(derr) if derr else None,
                        "max_depth_error_ratio": max(ratio) if ratio else None})
    report = {
        "tool": "wirecheck crosscheck",
        "verdict": "fail" if failed else "pass",
        "candidate": candidate_name,
        "candidate_settings": candidate.settings() if is_core else None,
        "level": level,
        **mode.to_dict(),
        "oracles": list(LEVEL_ORACLES[level]),
        "frames": frames,
        "every": every,
        "frames_checked": len(range(1, frames + 1, every)),
        "motion": {"turns": list(motion.turns)},
        "tolerances": tol.to_dict(shaded=mode.shaded),
        "summary": summary,
        **({"worst_case": worst_case} if worst_case else {}),
        "cases": records,
        "timing": timing,
    }
    return report, images


def worst_key(record: dict) -> tuple:
    """Ranking of cases for worst.gif, smallest = worst: lowest F1 (IoU when shaded), then largest vertex error."""
    verr = record.get("max_vertex_error_px")
    verr = -math.inf if verr is None else verr
    if "silhouette_iou" in record:
        iou = record.get("silhouette_iou")
        ratio = record.get("depth_error_ratio") or 0.0
        return (1.0 if iou is None else iou, -ratio, -verr)
    f1_1, f1_0 = record.get("pixel_f1_1px"), record.get("pixel_f1_0px")
    return (1.0 if f1_1 is None else f1_1, 1.0 if f1_0 is None else f1_0, -verr)


class _WorstCase:
    """Keeps the frame images of the worst case seen so far (cases offered in task order)."""

    def __init__(self, mode: RenderMode):
        self.mode = mode
        self.result = None
        self.key = None

    def offer(self, result: CaseResult) -> None:
        frames = result.frame_images
        if not frames:
            result.frame_images = None
            return
        key = worst_key(result.record)
        if self.result is None or key < self.key:      # ties: the first case in order stays
            if self.result is not None:
                self.result.frame_images = None
            self.result, self.key = result, key
        else:
            result.frame_images = None

    def animation(self) -> dict:
        rec = self.result.record
        h, w = rec["camera_spec"]["height"], rec["camera_spec"]["width"]

        def unpack(bits):
            return np.unpackbits(bits, count=h * w).reshape(h, w).astype(bool)

        frames = self.result.frame_images
        return {"scene": rec["scene"], "camera": rec["camera"], "frames": [k for k, _, _ in frames],
                "candidate": [unpack(c) for _, c, _ in frames], "oracle": [unpack(o) for _, _, o in frames],
                "shaded": self.mode.shaded}
