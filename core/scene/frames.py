"""A scene's frames: frame ``k`` of a scene's motion through one camera.

The scene-level entry to core. ``renderer`` draws every frame through
:class:`SceneRenderer`; crosscheck drives the core candidate with its
per-frame points and matrices (:meth:`SceneRenderer.geometry`), so both run
core the same way.

How a frame is set up (``M_run(k)`` is the run's motion, ``M_o(k)`` an
object's own, core.transforms.Motion):

- one object that does not move on its own: its vertices are re-centred and
  cast once (core.projector.projection.localize) and frame ``k`` is
  ``render_frame(points, edges, camera, M_run(k))``;
- several objects, or one that moves on its own: the world points
  ``M_run(k) @ M_o(k) @ p_model`` (core.scene.model.world_points), drawn with the
  identity model matrix; mirrored objects' faces come re-wound
  (core.scene.model.oriented_faces).

With object culling, an object whose bounding sphere (core.scene.model.object_spheres,
moved by its world matrix) lies outside the frustum has its edges and faces
left out. Every point of such an object is outside one frustum plane, so none
of its edges or faces could put a pixel on the image: the picture is the same
without culling. All vertices are still projected, and the edges left out that
have an end outside [near, far] are added back to ``clipped_edges``, so the
per-frame counts do not depend on culling either.
"""

from __future__ import annotations

import math
import time

import numpy as np

from ..camera import Camera
from ..errors import InputError
from ..projector.culling import sphere_outside_frustum
from ..projector.pipeline import Frame, render_frame
from ..projector.projection import LocalPoints, localize
from ..transforms import Motion, apply
from .model import Scene, object_matrix, object_spheres, oriented_faces, world_points

#: The model matrix of a frame drawn from world points.
IDENTITY = np.eye(4)
IDENTITY.setflags(write=False)

_NO_EDGES = np.zeros((0, 2), dtype=np.intp)


class SceneRenderer:
    """Renders frame ``k`` (1-based, of ``frames``) of ``scene`` under ``motion`` (module docstring).

    Parameters
    ----------
    scene : core.scene.model.Scene
    motion : core.transforms.Motion
        The run's motion, applied after each object's own.
    frames : int
        Frames in the run: frame ``k`` is at ``t = (k - 1) / frames``.
    clip, dtype, raster, cull, hidden_lines, style, light
        As :func:`core.projector.pipeline.render_frame` (``clip`` is its ``clip_mode``,
        ``light`` its ``light_dir``). Faces are used only for ``cull``,
        ``hidden_lines`` or style "shaded".
    object_culling : bool
        Leave out objects outside the frustum (scenes of several objects only;
        never changes the picture or the counts).

    Examples
    --------
    >>> from wirecheck import Motion, SceneRenderer, camera_z, load_scene
    >>> frames = SceneRenderer(load_scene("cube"), Motion(turns=(1, 1, 0)), 12)
    >>> frame, info = frames.render(1, camera_z(4.0))
    >>> frame.image.shape, frame.p_px.shape, info["clipped_edges"]
    ((480, 640), (8, 2), 0)
    """

    def __init__(
        self,
        scene: Scene,
        motion: Motion,
        frames: int,
        *,
        clip: str = "clip",
        dtype: str = "float64",
        raster: str = "exact",
        cull: str | None = None,
        hidden_lines: bool = False,
        style: str = "wireframe",
        light=None,
        object_culling: bool = True,
    ):
        self.scene, self.motion, self.frames = scene, motion, frames
        self.clip, self.dtype, self.raster = clip, dtype, raster
        self.cull, self.hidden_lines, self.style, self.light = cull, hidden_lines, style, light
        self.single = scene.is_single_static
        self.object_culling = object_culling and not self.single
        self.points = localize(scene.vertices, dtype) if self.single else None
        #: The faces as core draws them: re-wound for mirrored objects drawn from world points.
        self.faces = scene.faces if self.single else oriented_faces(scene, motion)
        self._edge_ranges = scene.object_edge_ranges()
        self._face_ranges = scene.object_face_ranges()
        self._spheres = object_spheres(scene)

    @property
    def uses_faces(self) -> bool:
        return self.cull is not None or self.hidden_lines or self.style != "wireframe"

    def world_points(self, k: int) -> np.ndarray:
        """``(N, 3)`` float64 world points ``p_world`` of frame ``k`` (inf where they overflow)."""
        with np.errstate(over="ignore", invalid="ignore"):
            return world_points(self.scene, self.motion, k, self.frames)

    def geometry(self, k: int) -> tuple[LocalPoints, np.ndarray]:
        """Frame ``k`` as :func:`render_frame` takes it: ``(points, model_matrix)``.

        ``points`` are the ``N`` vertices as :class:`~core.projector.projection.LocalPoints`
        (``p_model`` of a single static object, else ``p_world``);
        ``model_matrix`` is ``(4, 4)`` float64 (the identity for world points).
        """
        if self.single:
            return self.points, self.motion.frame_matrix(k, self.frames)
        return localize(self.world_points(k), self.dtype), IDENTITY

    def draw(
        self,
        points: LocalPoints,
        model_matrix: np.ndarray,
        camera: Camera,
        edges: np.ndarray | None = None,
        faces=None,
        timing: dict | None = None,
    ) -> Frame:
        """One :func:`render_frame` call with this renderer's settings (default: all edges and faces)."""
        edges = self.scene.edges if edges is None else edges
        return render_frame(
            points,
            edges,
            camera,
            model_matrix,
            self.clip,
            raster=self.raster,
            timing=timing,
            **self._face_kwargs(self.faces if faces is None else faces),
        )

    def project(self, points: LocalPoints, model_matrix: np.ndarray, camera: Camera) -> np.ndarray:
        """``(N, 2)`` vertex pixels, NaN where clipped: the pipeline given no edges, so nothing is drawn."""
        return render_frame(points, _NO_EDGES, camera, model_matrix, self.clip, raster=self.raster).p_px

    def render(self, k: int, camera: Camera, timing: dict | None = None) -> tuple[Frame, dict]:
        """Frame ``k`` through ``camera``: ``(frame, info)``.

        ``frame`` is the pipeline's :class:`~core.projector.pipeline.Frame` (``image``
        ``(H, W)`` uint8, ``p_px`` ``(N, 2)`` float64 with NaN where clipped,
        ``depth`` ``(N,)``); ``info`` its counts for the report
        (core.app.report.frame_record): ``clipped_edges`` and, when the run has them,
        ``objects_culled``, ``faces_total``, ``faces_culled``, ``hidden_pixels``.
        ``timing``: render_frame's per-stage seconds are added to it, the
        frame's set-up (model matrix, world points, object culling) as
        "transform" (core.app.profile). Raises InputError when a world point of
        the frame overflows float64.
        """
        t0 = time.perf_counter() if timing is not None else 0.0
        if self.single:
            points, m = self.geometry(k)
            _add_time(timing, "transform", t0)
            frame = self.draw(points, m, camera, timing=timing)
            return frame, self._info(frame, None, 0)
        p_world = self.world_points(k)
        self._check_finite(p_world, k)
        culled = self._culled_objects(k, camera) if self.object_culling else []
        edges, faces, dropped = self.scene.edges, self.faces, None
        if culled:
            keep_e = np.ones(len(self.scene.edges), dtype=bool)
            keep_f = np.ones(len(self.scene.faces), dtype=bool)
            for i in culled:
                keep_e[slice(*self._edge_ranges[i])] = False
                keep_f[slice(*self._face_ranges[i])] = False
            dropped = self.scene.edges[~keep_e]
            edges = self.scene.edges[keep_e]
            faces = tuple(f for f, keep in zip(self.faces, keep_f) if keep)
        points = localize(p_world, self.dtype)
        _add_time(timing, "transform", t0)
        frame = self.draw(points, IDENTITY, camera, edges, faces, timing=timing)
        return frame, self._info(frame, dropped, len(culled))

    def _face_kwargs(self, faces) -> dict:
        """render_frame's face keywords (none at all for a plain wireframe)."""
        if not self.uses_faces:
            return {}
        kw = {"faces": faces}
        if self.cull is not None:
            kw["cull"] = self.cull
        if self.hidden_lines:
            kw["hidden_lines"] = True
        if self.style != "wireframe":
            kw["style"] = self.style
        if self.light is not None:
            kw["light_dir"] = self.light
        return kw

    def _check_finite(self, p_world: np.ndarray, k: int) -> None:
        bad = ~np.isfinite(p_world).all(axis=1)
        if bad.any():
            scene = self.scene
            i = int(np.flatnonzero(bad)[0])
            obj = next(o for o in scene.objects if o.vertex_start <= i < o.vertex_stop)
            raise InputError(
                f"{scene.source}: vertex {i - obj.vertex_start} of object {obj.name!r} "
                f"{scene.vertices[i].tolist()} moves beyond the float64 range in frame {k}: expected "
                f"coordinates whose world position (after the object's and the run's scale) fits in a float64"
            )

    def _culled_objects(self, k: int, camera: Camera) -> list[int]:
        out = []
        for i, (obj, (centre, radius)) in enumerate(zip(self.scene.objects, self._spheres)):
            if obj.vertex_count == 0:
                continue  # nothing to draw: not counted as culled
            m = object_matrix(obj, self.motion, k, self.frames)
            c_world = apply(m, centre)[0]
            r_world = radius * abs(self.motion.scale * obj.motion.scale)
            # widen by far more than the rounding of apply() (a few eps of |c| + r)
            r_world += 1e-9 * (float(np.abs(c_world).max()) + r_world)
            if np.all(np.isfinite(c_world)) and math.isfinite(r_world):
                with np.errstate(all="ignore"):  # near-overflow coordinates: no warnings
                    if sphere_outside_frustum(c_world, r_world, camera):
                        out.append(i)
        return out

    def _info(self, frame: Frame, dropped_edges, n_culled: int) -> dict:
        info = {"clipped_edges": frame.clipped_edges}
        if dropped_edges is not None and len(dropped_edges):
            whole = frame.visible[dropped_edges[:, 0]] & frame.visible[dropped_edges[:, 1]]
            info["clipped_edges"] += int(len(dropped_edges) - whole.sum())
        if not self.single:  # None: object culling off
            info["objects_culled"] = n_culled if self.object_culling else None
        if self.uses_faces:
            info["faces_total"] = len(self.scene.faces)
        if self.cull is not None:
            info["faces_culled"] = frame.faces_culled
        if self.hidden_lines:
            info["hidden_pixels"] = frame.hidden_pixels
        return info


def _add_time(timing: dict | None, stage: str, t0: float) -> None:
    if timing is not None:
        timing[stage] = timing.get(stage, 0.0) + (time.perf_counter() - t0)
