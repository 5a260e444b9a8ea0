"""``renderer``: render a scene's motion to wireframe frames with per-frame diagnostics.

    renderer --scene cube --frames 180 --camera-z 4.0 --fov 70

Scenes of several objects (core.scene) are rendered from their world points,
``M_run(k) @ M_o(k) @ p_model``: each object's own motion first, then the
run's ``--spin/--translate/--scale``. A one-object scene that does not move on
its own keeps the single-model-matrix path of ``render_frame``.

Thin: parses arguments, calls :func:`render_run`, prints. Results go to
stdout, errors to stderr as one line with exit status 2.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import output
from .camera import Camera, camera_z, look_at
from .errors import InputError
from .pipeline import CLIP_MODES, RASTER_MODES, draw_segments, render_frame
from .projection import DTYPES, localize, world_to_cam
from .scene import Scene, load_scene, object_matrix, object_spheres, oriented_faces, world_points
from .transforms import Motion, apply

FORMATS = ("png", "ascii", "gif", "mp4")
#: --projection: one camera, or "both": perspective left, orthographic right.
PROJECTION_CHOICES = ("perspective", "orthographic", "both")
CULL_CHOICES = ("none", "backface")
STYLES = ("wireframe", "shaded")
#: --axes colours (RGB), drawn in this order (a later axis covers an earlier one).
AXIS_COLOURS = (("x", (255, 0, 0)), ("y", (0, 255, 0)), ("z", (0, 0, 255)))
#: Axis length as a multiple of the scene's bounding radius.
AXIS_LENGTH = 1.2
#: --projection both: the 1-pixel column between the two pictures.
SEPARATOR_GREY = 128
#: Frames per second of the GIF and MP4 animations.
FPS = 30
#: Above this many vertices the per-frame pixel coordinates go to a binary
#: sidecar (float64 array, shape (frames, N, 2), NaN where clipped) instead of JSON.
SIDECAR_VERTICES = 10_000


class _Parser(argparse.ArgumentParser):
    """argparse, but a usage error is one line on stderr and exit status 2."""

    def error(self, message):  # noqa: D401 - argparse API
        self.exit(2, f"{self.prog}: error: {message}\n")


def vec3(option: str, text: str) -> tuple[float, float, float]:
    parts = text.split(",")
    try:
        values = tuple(float(p) for p in parts)
    except ValueError:
        raise InputError(f"{option} {text!r}: expected three numbers X,Y,Z") from None
    if len(values) != 3 or not all(math.isfinite(v) for v in values):
        raise InputError(f"{option} {text!r}: expected three finite numbers X,Y,Z")
    return values


def build_parser() -> argparse.ArgumentParser:
    p = _Parser(prog="renderer", description=__doc__.split("\n")[0])
    p.add_argument("--scene", default="cube", help="built-in name (cube, pyramid, prism), an example "
                   "(orrery: scenes/examples/, several objects) or a file path (.scene, .obj, .ply, .stl, .off, .glb)")
    p.add_argument("--frames", type=int, default=180, help="number of frames (default 180)")
    cam = p.add_argument_group("camera (conventions: core/conventions.py)")
    cam.add_argument("--camera-z", type=float, default=None, help="camera at (0,0,D) looking at the origin, up +Y (default 4)")
    cam.add_argument("--camera-pos", default=None, metavar="X,Y,Z")
    cam.add_argument("--look-at", default=None, metavar="X,Y,Z", help="with --camera-pos (default 0,0,0)")
    cam.add_argument("--up", default=None, metavar="X,Y,Z", help="with --camera-pos (default 0,1,0)")
    cam.add_argument("--fov", type=float, default=60.0, help="full vertical FOV in degrees, edge to edge (default 60)")
    cam.add_argument("--near", type=float, default=0.1)
    cam.add_argument("--far", type=float, default=100.0)
    cam.add_argument("--width", type=int, default=640)
    cam.add_argument("--height", type=int, default=480)
    cam.add_argument("--projection", choices=PROJECTION_CHOICES, default="perspective",
                     help="both: every frame twice, side by side: perspective on the left, on the right an "
                     "orthographic camera at the same position and orientation with ortho-height = "
                     "2 d tan(fov/2), d = the distance to the look-at point (so things at the look-at "
                     "distance are the same size in both); a 1-px grey column between them, output width 2W+1")
    cam.add_argument("--ortho-height", type=float, default=None,
                     help="world units visible vertically (orthographic; default 4)")
    mot = p.add_argument_group("motion (model matrix of frame k uses t = (k-1)/frames; in a scene of several "
                               "objects it applies to the whole scene, after each object's own motion)")
    mot.add_argument("--spin", default="1,1,0", metavar="X,Y,Z", help="full turns about X, Y, Z over the run (default 1,1,0)")
    mot.add_argument("--translate", default="0,0,0", metavar="X,Y,Z")
    mot.add_argument("--scale", type=float, default=1.0)
    p.add_argument("--clip", choices=CLIP_MODES, default="clip",
                   help="clip: clip edges at near/far; endpoint: drop edges with a clipped end")
    p.add_argument("--dtype", choices=DTYPES, default="float64",
                   help="precision of every per-point operation (default float64; core/projection.py)")
    p.add_argument("--raster", choices=RASTER_MODES, default="exact",
                   help="exact: GL diamond-exit (matches Mesa); fast: integer DDA; aa: anti-aliased (Wu)")
    drw = p.add_argument_group("drawing (faces: --cull, --hidden-lines and --style shaded need a scene with faces)")
    drw.add_argument("--axes", action="store_true",
                     help="draw the world axes from the origin, X red, Y green, Z blue, length 1.2 x the "
                     "scene's bounding radius x |--scale|, through the same camera and clipping as the "
                     "edges, over the picture but, with --hidden-lines or --style shaded, hidden behind faces "
                     "like the edges; frames become RGB (grey otherwise)")
    drw.add_argument("--cull", choices=CULL_CHOICES, default="none",
                     help="backface: drop faces turned away from the camera (needs consistent winding)")
    drw.add_argument("--hidden-lines", action="store_true", help="hide edges behind faces (z-buffer)")
    drw.add_argument("--style", choices=STYLES, default="wireframe", help="shaded: flat-shaded faces")
    drw.add_argument("--light", default=None, metavar="X,Y,Z",
                     help="--style shaded: the world direction the light travels (default: from the camera's "
                     "upper left)")
    drw.add_argument("--object-culling", action=argparse.BooleanOptionalAction, default=True,
                     help="scenes of several objects: skip objects whose bounding sphere is outside the "
                     "frustum (default on; never changes the picture or the vertex and edge counts)")
    p.add_argument("--format", default="png", help="comma-separated: png, ascii, gif, mp4 (default png). mp4: "
                   "H.264 yuv420p via PyAV, 30 fps; an odd width or height is padded with one black "
                   "row/column, never scaled")
    p.add_argument("--plots", action=argparse.BooleanOptionalAction, default=False,
                   help="also write <scene>-plots.png: depth range, clipped vertices/edges (and culled "
                   "faces/objects, hidden pixels when on) against frame number (default off: matplotlib "
                   "adds about 1 s)")
    p.add_argument("--ascii-cols", type=int, default=80)
    p.add_argument("--out", default="output", help="output directory (default output/)")
    p.add_argument("--verbose", action="store_true", help="print every frame, not only first, middle and last")
    ana = p.add_argument_group("analysis and the interactive viewer (docs/interactive.md)")
    ana.add_argument("--profile", action="store_true",
                     help="time every frame's stages (transform, faces, shading, clip, raster, compose, encode, "
                     "write): a table on stdout and 'profile' in the JSON report")
    ana.add_argument("--trace-vertex", type=int, default=None, metavar="I",
                     help="print vertex I in every space (model, world, camera, clip, NDC, pixel), its visibility "
                     "and its edges' clipping; also 'trace' in the JSON report")
    ana.add_argument("--trace-frames", default=None, metavar="K,K,...",
                     help="frames of --trace-vertex (default: first, middle, last)")
    ana.add_argument("--compare", action="store_true",
                     help="render the scene at two camera distances and two FOVs (--compare-z, --compare-fov) "
                     "in a 2x2 picture and explain the difference with numbers measured from the frames")
    ana.add_argument("--compare-z", default="3,6", metavar="D1,D2", help="--compare: camera distances (default 3,6)")
    ana.add_argument("--compare-fov", default="60,90", metavar="F1,F2", help="--compare: FOVs (default 60,90)")
    ana.add_argument("--interactive", action="store_true",
                     help="serve a viewer on 127.0.0.1 (frames drawn by core; orbit, dolly, pan, the oracle "
                     "overlay, the profiler); opens no browser; Ctrl-C stops it")
    ana.add_argument("--port", type=int, default=0, help="--interactive: port (default 0: a free one, printed)")
    return p


@dataclass
class Settings:
    scene: Scene
    camera: Camera
    motion: Motion
    frames: int
    clip: str
    formats: tuple[str, ...]
    out: Path
    ascii_cols: int
    dtype: str = "float64"
    raster: str = "exact"
    ortho_camera: Camera | None = None       # --projection both: the right-hand camera
    axes: bool = False
    cull: str | None = None                  # None or "backface"
    hidden_lines: bool = False
    style: str = "wireframe"
    light: tuple | None = None
    object_culling: bool = True
    plots: bool = False

    @property
    def cameras(self) -> tuple[Camera, ...]:
        return (self.camera,) if self.ortho_camera is None else (self.camera, self.ortho_camera)

    @property
    def uses_faces(self) -> bool:
        return self.cull is not None or self.hidden_lines or self.style != "wireframe"


def settings_from_args(a: argparse.Namespace) -> Settings:
    if a.frames < 1:
        raise InputError(f"--frames {a.frames}: expected an integer >= 1")
    if not (0.0 < a.fov < 180.0):
        raise InputError(f"--fov {a.fov}: expected degrees in (0, 180)")
    if a.width < 1 or a.height < 1:
        raise InputError(f"--width/--height {a.width}x{a.height}: expected positive integers")
    if not (math.isfinite(a.scale) and a.scale != 0):
        raise InputError(f"--scale {a.scale}: expected a finite non-zero number")
    if a.ascii_cols < 1:
        raise InputError(f"--ascii-cols {a.ascii_cols}: expected an integer >= 1")
    formats = tuple(f.strip() for f in a.format.split(",") if f.strip())
    bad = [f for f in formats if f not in FORMATS]
    if bad or not formats:
        raise InputError(f"--format {a.format!r}: expected a comma-separated list of {', '.join(FORMATS)}")
    both = a.projection == "both"
    kwargs = dict(fov_y_deg=a.fov, width=a.width, height=a.height, near=a.near, far=a.far,
                  projection="perspective" if both else a.projection,
                  ortho_height=4.0 if a.ortho_height is None else a.ortho_height)
    if a.camera_pos is not None:
        if a.camera_z is not None:
            raise InputError("--camera-z and --camera-pos: expected one of them, not both")
        position, target = vec3("--camera-pos", a.camera_pos), vec3("--look-at", a.look_at or "0,0,0")
        camera = look_at(position, target, vec3("--up", a.up or "0,1,0"), **kwargs)
        distance = math.dist(position, target)
    else:
        if a.look_at is not None or a.up is not None:
            raise InputError("--look-at/--up without --camera-pos: expected --camera-pos X,Y,Z with them "
                             "(--camera-z always looks at the origin with up +Y)")
        d = 4.0 if a.camera_z is None else a.camera_z
        if not (math.isfinite(d) and d != 0):
            raise InputError(f"--camera-z {d}: expected a finite non-zero distance")
        camera = camera_z(d, **kwargs)
        distance = abs(d)
    if both and a.ortho_height is not None:
        raise InputError(f"--ortho-height {a.ortho_height} with --projection both: the orthographic half's "
                         "height is 2 d tan(fov/2), set by the perspective camera; expected no --ortho-height")
    if a.style == "shaded" and a.hidden_lines:
        raise InputError("--hidden-lines with --style shaded: a shaded frame draws no lines; expected one of them")
    ortho_camera = None
    if both:
        ortho_camera = orthographic_twin(camera, distance)
    light = None
    if a.light is not None:
        if a.style != "shaded":
            raise InputError(f"--light {a.light!r} without --style shaded: expected --style shaded with it")
        light = vec3("--light", a.light)
        if not any(light):
            raise InputError(f"--light {a.light!r}: expected a non-zero direction")
        big = max(abs(v) for v in light)
        light = tuple(v / big for v in light)            # a direction: scale it to avoid over/underflow
    motion = Motion(turns=vec3("--spin", a.spin), offset=vec3("--translate", a.translate), scale=a.scale)
    if "mp4" in formats:
        try:
            import av  # noqa: F401 - only checking that it is there
        except ImportError:
            raise InputError("--format mp4: expected the PyAV package (pip install av; "
                             "it is a dependency of wirecheck)") from None
    scene = load_scene(a.scene)
    cull = None if a.cull == "none" else a.cull
    s = Settings(scene, camera, motion, a.frames, a.clip, formats, Path(a.out), a.ascii_cols,
                 dtype=a.dtype, raster=a.raster, ortho_camera=ortho_camera, axes=a.axes, cull=cull,
                 hidden_lines=a.hidden_lines, style=a.style, light=light, object_culling=a.object_culling,
                 plots=a.plots)
    if s.uses_faces:
        asked = " ".join(f for f, on in (("--cull backface", cull), ("--hidden-lines", a.hidden_lines),
                                         ("--style shaded", a.style == "shaded")) if on)
        if not scene.faces:
            raise InputError(f"{asked}: scene {scene.name!r} ({scene.source}) has no faces: expected a scene "
                             "with faces ('f' lines or a mesh file)")
    if a.axes and not math.isfinite(AXIS_LENGTH * scene.radius * abs(motion.scale)):
        raise InputError(f"--axes with --scale {a.scale}: axis length 1.2 x radius {scene.radius:g} x |scale| "
                         "overflows float64; expected a smaller --scale")
    if cull is not None and scene.winding_note:
        raise InputError(f"--cull backface: {scene.source}: {scene.winding_note}: expected faces wound "
                         "consistently (counter-clockwise seen from outside)")
    _check_writable(s.out)
    if "png" in formats or "ascii" in formats:
        output.check_replaceable(s.out / f"{scene.name}-frames", "--out")
    return s


def orthographic_twin(camera: Camera, distance: float) -> Camera:
    """An orthographic camera with ``camera``'s pose and ``ortho_height = 2 d tan(fov_y / 2)``.

    At depth ``d`` a perspective camera sees ``2 d tan(fov_y / 2)`` world units
    vertically, so an object at the look-at distance ``d`` has the same size in
    pixels in both pictures (nearer things are bigger only in perspective).
    """
    height = 2.0 * distance * math.tan(math.radians(camera.fov_y_deg) / 2.0)
    return Camera(position=camera.position, forward=camera.forward, up=camera.up, fov_y_deg=camera.fov_y_deg,
                  width=camera.width, height=camera.height, near=camera.near, far=camera.far,
                  projection="orthographic", ortho_height=height)


def _face_kwargs(s: Settings, faces) -> dict:
    """render_frame's face keywords for this run (none at all for a plain wireframe run)."""
    if not s.uses_faces:
        return {}
    kw = {"faces": faces}
    if s.cull is not None:
        kw["cull"] = s.cull
    if s.hidden_lines:
        kw["hidden_lines"] = True
    if s.style != "wireframe":
        kw["style"] = s.style
    if s.light is not None:
        kw["light_dir"] = s.light
    return kw


def _check_writable(out: Path) -> None:
    try:
        out.mkdir(parents=True, exist_ok=True)
        probe = out / ".wirecheck-write-test"
        probe.write_bytes(b"")
        probe.unlink()
    except OSError as exc:
        raise InputError(f"--out {str(out)!r}: cannot write there ({exc.strerror or exc}): expected a writable directory") from None


def frame_record(k: int, frame, sidecar: bool, info: dict | None = None) -> dict:
    """One frame's diagnostics (the report's ``frames`` items).

    Always: ``frame``, ``visible_vertices``, ``clipped`` (vertices outside
    [near, far]), ``clipped_edges`` (edges cut or dropped by near/far),
    ``min_depth``/``max_depth`` (of the visible vertices) and, unless a sidecar
    holds them, ``vertices_px``. Only when the run has them (``info``):
    ``objects_culled`` (scenes of several objects: objects left out by frustum
    culling, None when object culling is off), ``faces_total`` (the scene's
    faces: runs with --cull/--hidden-lines/--style shaded), ``faces_culled``
    (--cull backface: back faces among the faces of the objects not left out),
    ``hidden_pixels`` (--hidden-lines: line pixels hidden by faces).
    """
    info = info or {}
    rng = frame.depth_range
    rec = {
        "frame": k,
        "visible_vertices": frame.visible_vertices,
        "clipped": frame.clipped_vertices,
        "clipped_edges": int(info.get("clipped_edges", frame.clipped_edges)),
        "min_depth": None if rng is None else rng[0],
        "max_depth": None if rng is None else rng[1],
    }
    for key in ("objects_culled", "faces_total", "faces_culled", "hidden_pixels"):
        if key in info:
            rec[key] = None if info[key] is None else int(info[key])
    if not sidecar:
        rec["vertices_px"] = [None if not v else [float(x), float(y)]
                              for (x, y), v in zip(frame.p_px.tolist(), frame.visible.tolist())]
    return rec


def depth_text(frame) -> str:
    rng = frame.depth_range
    return "depth=[none]" if rng is None else f"depth=[{rng[0]:.2f}, {rng[1]:.2f}]"


def _sphere_test():
    """core.culling.sphere_outside_frustum, or None when this build has no core.culling."""
    try:
        from .culling import sphere_outside_frustum
    except ImportError:
        return None
    return sphere_outside_frustum


class FrameRenderer:
    """Renders frame ``k`` of a run through one camera, whatever the scene's objects.

    A single object without motion of its own: ``render_frame(vertices, edges,
    camera, M_run(k))``, exactly as a one-object renderer. Several objects (or
    one that moves on its own): the world points :func:`core.scene.world_points`
    with the identity model matrix. Then, with object culling on, objects whose
    bounding sphere (core.scene.object_spheres, moved by the object's world
    matrix) lies outside the camera's frustum have their edges and faces left
    out. Every point of such an object is outside one frustum plane, so none of
    its edges or faces could put a pixel on the image: the picture is the same
    without culling. All vertices are still projected, and the edges left out
    that have an end outside [near, far] are added back to ``clipped_edges``, so
    the per-frame counts do not depend on culling either.
    """

    def __init__(self, s: "Settings"):
        self.s = s
        scene = s.scene
        self.single = scene.is_single_static
        self.points = localize(scene.vertices, s.dtype) if self.single else None
        self.edge_ranges = scene.object_edge_ranges()
        self.face_ranges = scene.object_face_ranges()
        self.spheres = object_spheres(scene)
        self.sphere_test = _sphere_test() if (s.object_culling and not self.single) else None
        self.extra_info = {}
        # world points are drawn with an identity matrix: mirrored objects' faces re-wound
        self.faces = scene.faces if self.single else oriented_faces(scene, s.motion)

    def render(self, k: int, camera: Camera, timing: dict | None = None):
        """``(frame, info)``: the pipeline's Frame and this frame's counts for :func:`frame_record`.

        ``timing``: render_frame's per-stage seconds are added to it (core.profile).
        """
        s, scene = self.s, self.s.scene
        t0 = time.perf_counter() if timing is not None else 0.0
        if self.single:
            m = s.motion.frame_matrix(k, s.frames)
            _add_time(timing, "transform", t0)                      # the model matrix is part of the transform
            frame = render_frame(self.points, scene.edges, camera, m, s.clip,
                                 raster=s.raster, timing=timing, **_face_kwargs(s, scene.faces))
            return frame, self._info(frame, None, 0)
        with np.errstate(over="ignore", invalid="ignore"):   # overflow shows as inf: reported below
            p_world = world_points(scene, s.motion, k, s.frames)
        bad = ~np.isfinite(p_world).all(axis=1)
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            obj = next(o for o in scene.objects if o.vertex_start <= i < o.vertex_stop)
            raise InputError(
                f"{scene.source}: vertex {i - obj.vertex_start} of object {obj.name!r} "
                f"{scene.vertices[i].tolist()} moves beyond the float64 range in frame {k}: expected "
                f"coordinates whose world position (after the object's and the run's scale) fits in a float64")
        culled = self._culled_objects(k, camera) if self.sphere_test is not None else []
        edges, faces, dropped = scene.edges, self.faces, None
        if culled:
            keep_e = np.ones(len(scene.edges), dtype=bool)
            keep_f = np.ones(len(scene.faces), dtype=bool)
            for i in culled:
                keep_e[slice(*self.edge_ranges[i])] = False
                keep_f[slice(*self.face_ranges[i])] = False
            dropped = scene.edges[~keep_e]
            edges = scene.edges[keep_e]
            faces = tuple(f for f, keep in zip(self.faces, keep_f) if keep)
        _add_time(timing, "transform", t0)                          # world points and object culling
        frame = render_frame(p_world, edges, camera, _IDENTITY, s.clip, dtype=s.dtype, raster=s.raster,
                             timing=timing, **_face_kwargs(s, faces))
        return frame, self._info(frame, dropped, len(culled))

    def _culled_objects(self, k: int, camera: Camera) -> list[int]:
        s = self.s
        out = []
        for i, (obj, (centre, radius)) in enumerate(zip(s.scene.objects, self.spheres)):
            if obj.vertex_count == 0:
                continue                      # nothing to draw: not counted as culled
            m = object_matrix(obj, s.motion, k, s.frames)
            c_world = apply(m, centre)[0]
            r_world = radius * abs(s.motion.scale * obj.motion.scale)
            # widen by far more than the rounding of apply() (a few eps of |c| + r)
            r_world += 1e-9 * (float(np.abs(c_world).max()) + r_world)
            if np.all(np.isfinite(c_world)) and math.isfinite(r_world):
                with np.errstate(all="ignore"):            # near-overflow coordinates: no warnings
                    if self.sphere_test(c_world, r_world, camera):
                        out.append(i)
        return out

    def _info(self, frame, dropped_edges, n_culled: int) -> dict:
        s = self.s
        info = {"clipped_edges": frame.clipped_edges}
        if dropped_edges is not None and len(dropped_edges):
            whole = frame.visible[dropped_edges[:, 0]] & frame.visible[dropped_edges[:, 1]]
            info["clipped_edges"] += int(len(dropped_edges) - whole.sum())
        if not self.single:                   # None: culling off (or no core.culling in this build)
            info["objects_culled"] = n_culled if self.sphere_test is not None else None
        if s.uses_faces:
            info["faces_total"] = len(s.scene.faces)
        if s.cull is not None:
            info["faces_culled"] = getattr(frame, "faces_culled", None)
        if s.hidden_lines:
            info["hidden_pixels"] = getattr(frame, "hidden_pixels", None)
        return info


def _add_time(timing: dict | None, stage: str, t0: float) -> None:
    if timing is not None:
        timing[stage] = timing.get(stage, 0.0) + (time.perf_counter() - t0)


_IDENTITY = np.eye(4)
_IDENTITY.setflags(write=False)


def picture(frame, s: "Settings") -> np.ndarray:
    """The frame's image: the wireframe (or, with --style shaded, the pipeline's shaded picture)."""
    if s.style == "shaded":
        shaded = getattr(frame, "shaded", None)
        if shaded is not None:
            return np.asarray(shaded)
    return frame.image


def axis_length(s: "Settings") -> float:
    """``AXIS_LENGTH`` x the scene's bounding radius x |--scale| (1.2 for an empty or point scene)."""
    r = s.scene.radius * abs(s.motion.scale)
    return AXIS_LENGTH * (r if r > 0 and math.isfinite(r) else 1.0)


def axis_layers(s: "Settings", camera: Camera, frame=None) -> list[tuple[tuple[int, int, int], np.ndarray]]:
    """``[(rgb, coverage)]`` for the X, Y, Z axes: each drawn by core's pipeline as one edge.

    The world axes do not move, so without faces this is computed once per
    camera and run. With ``frame`` rendered with hidden lines or shaded (it
    has a depth buffer), the axes are depth-tested against its faces like its
    own edges (:func:`core.pipeline.draw_segments`), so they are computed per
    frame. ``coverage`` is the edge's image (255 on its pixels; 0..255 for raster "aa").
    """
    n = axis_length(s)
    points = np.array([[0.0, 0.0, 0.0], [n, 0.0, 0.0], [0.0, n, 0.0], [0.0, 0.0, n]])
    if frame is not None and getattr(frame, "tri_ids", None) is not None:
        p_cam = world_to_cam(points, camera)                          # camera
        layers = []
        for i, (_, rgb) in enumerate(AXIS_COLOURS, start=1):
            seg_cam = p_cam[[0, i]][None]
            if s.clip == "endpoint" and not ((camera.near <= seg_cam[0, :, 2]) & (seg_cam[0, :, 2] <= camera.far)).all():
                seg_cam = seg_cam[:0]                                 # --clip endpoint: a clipped end drops the edge
            layers.append((rgb, draw_segments(seg_cam, camera, s.raster, occluders=frame)))
        return layers
    layers = []
    for i, (_, rgb) in enumerate(AXIS_COLOURS, start=1):
        f = render_frame(points, np.array([[0, i]]), camera, _IDENTITY, s.clip, dtype=s.dtype, raster=s.raster)
        layers.append((rgb, f.image))
    return layers


def _rgb(image: np.ndarray) -> np.ndarray:
    """A new ``(H, W, 3)`` uint8 copy of a grey or RGB image."""
    out = np.empty(image.shape[:2] + (3,), dtype=np.uint8)
    out[...] = image if image.ndim == 3 else image[:, :, None]
    return out


def overlay(image: np.ndarray, layers) -> np.ndarray:
    """RGB ``image`` (grey is replicated) with each layer's colour blended in by its coverage, in order.

    ``out = (out (255 - c) + colour c + 127) // 255`` on the covered pixels: for
    coverage 255 (rasters "exact", "fast") the pixel is exactly the colour.
    """
    out = _rgb(image)
    for colour, cov in layers:
        rows, cols = np.nonzero(cov)
        if len(rows) == 0:
            continue
        c = cov[rows, cols].astype(np.uint32)[:, None]
        old = out[rows, cols].astype(np.uint32)
        out[rows, cols] = ((old * (255 - c) + np.asarray(colour, dtype=np.uint32) * c + 127) // 255).astype(np.uint8)
    return out


def side_by_side(left: np.ndarray, right: np.ndarray) -> np.ndarray:
    """``left | grey 1-px column | right`` (both grey, or both made RGB)."""
    if left.ndim != right.ndim:
        left, right = (im if im.ndim == 3 else _rgb(im) for im in (left, right))
    sep = np.full(left.shape[:1] + (1,) + left.shape[2:], SEPARATOR_GREY, dtype=np.uint8)
    return np.concatenate([left, sep, right], axis=1)


def render_run(s: Settings, log=None, progress=None, profiler=None, extra: dict | None = None) -> dict:
    """Render every frame, write outputs atomically, return the report dict.

    ``log(k, frame, info)`` is called for each frame (the CLI decides what to print).
    ``profiler`` (a :class:`core.profile.FrameProfiler`) times each frame's
    stages; its summary becomes the report's ``profile`` field. ``extra``
    fields are added to the report (``trace``).
    """
    name = s.scene.name
    frames_dir = s.out / f"{name}-frames"
    json_path = s.out / f"{name}-report.json"
    txt_path = s.out / f"{name}-report.txt"
    plots_path = s.out / f"{name}-plots.png"
    mp4_path = s.out / f"{name}.mp4"
    sidecar = len(s.scene.vertices) > SIDECAR_VERTICES
    sidecar_paths = [s.out / f"{name}-vertices_px.npy", s.out / f"{name}-vertices_px-orthographic.npy"]
    fdir = output.FrameDir(frames_dir, "--out") if ("png" in s.formats or "ascii" in s.formats) else None
    mp4 = None
    records, gif_images = [], []
    all_px = [[] for _ in s.cameras]
    t_start = time.perf_counter()
    render_seconds = 0.0
    renderer = FrameRenderer(s)
    layers = [axis_layers(s, cam) for cam in s.cameras] if s.axes else None
    lap = profiler.lap if profiler is not None else (lambda stage, t: 0.0)
    try:
        if "mp4" in s.formats:
            mp4 = output.Mp4Writer(mp4_path, FPS)
        for k in range(1, s.frames + 1):
            if profiler is not None:
                profiler.begin()
            pictures, recs = [], []
            for c, cam in enumerate(s.cameras):
                t0 = time.perf_counter()
                frame, info = renderer.render(k, cam, timing=profiler.current if profiler else None)
                t = time.perf_counter()
                render_seconds += t - t0
                _check_overflow(s, frame, k)
                img = picture(frame, s)
                if layers and frame.tri_ids is not None:          # faces in a depth buffer: axes depth-tested
                    pictures.append(overlay(img, axis_layers(s, cam, frame)))
                else:
                    pictures.append(overlay(img, layers[c]) if layers else img)
                recs.append(frame_record(k, frame, sidecar, info))
                if sidecar:
                    all_px[c].append(frame.p_px)
                if c == 0:
                    first = (frame, info)
                lap("compose", t)
            t = time.perf_counter()
            rec = recs[0]
            if len(recs) > 1:
                rec["orthographic"] = {key: v for key, v in recs[1].items() if key != "frame"}
            image = pictures[0] if len(pictures) == 1 else side_by_side(*pictures)
            t = lap("compose", t)
            if fdir is not None and "png" in s.formats:
                data = output.png_bytes(image)
                t = lap("encode", t)
                fdir.write(f"frame_{k:04d}.png", data)
                t = lap("write", t)
            if fdir is not None and "ascii" in s.formats:
                data = output.ascii_frame(image, s.ascii_cols).encode()
                t = lap("encode", t)
                fdir.write(f"frame_{k:04d}.txt", data)
                t = lap("write", t)
            if "gif" in s.formats:
                gif_images.append(image)
            if mp4 is not None:
                mp4.add(image)
                t = lap("encode", t)
            records.append(rec)
            if profiler is not None:
                profiler.end()
            if log:
                log(k, *first)
            if progress:
                progress(k)
        if fdir is not None:
            fdir.commit()
        if mp4 is not None:
            mp4.commit()
    except BaseException:
        if fdir is not None:
            fdir.abort()
        if mp4 is not None:
            mp4.abort()
        raise
    if "gif" in s.formats:
        output.atomic_write_bytes(s.out / f"{name}.gif", output.gif_bytes(gif_images, FPS))
    report = _report(s, records)
    report.update(extra or {})
    if profiler is not None:
        report["profile"] = profiler.summary()
    if sidecar:
        import io

        for c, path in enumerate(sidecar_paths[:len(s.cameras)]):
            buf = io.BytesIO()
            np.save(buf, np.stack(all_px[c]) if all_px[c] else np.zeros((0, 0, 2)))
            output.atomic_write_bytes(path, buf.getvalue())
        report["vertices_px_file"] = sidecar_paths[0].name
        if s.ortho_camera is not None:
            report["vertices_px_file_orthographic"] = sidecar_paths[1].name
    plot_seconds = None
    if s.plots:
        from .motion_plot import plot_png

        t0 = time.perf_counter()
        cam_text = "perspective (left picture)" if s.ortho_camera is not None else s.camera.projection
        output.atomic_write_bytes(plots_path, plot_png(records, f"{name}: {s.frames} frames, {cam_text} camera"))
        plot_seconds = time.perf_counter() - t0
    output.atomic_write_text(json_path, output.json_dumps(report))
    wall = time.perf_counter() - t_start
    output.atomic_write_text(txt_path, summary_text(report, render_seconds, wall, plot_seconds))
    report["_paths"] = {"frames": frames_dir if fdir else None, "json": json_path, "txt": txt_path,
                        "gif": s.out / f"{name}.gif" if "gif" in s.formats else None,
                        "mp4": mp4_path if mp4 is not None else None,
                        "plots": plots_path if s.plots else None}
    return report


def _check_overflow(s: Settings, frame, k: int) -> None:
    overflow = frame.visible & ~np.isfinite(frame.p_px).all(axis=1)
    if overflow.any():
        i = int(np.flatnonzero(overflow)[0])
        raise InputError(
            f"{s.scene.source}: vertex {i} {s.scene.vertices[i].tolist()} projects beyond the float64 "
            f"range in frame {k}: expected coordinates whose pixel position fits in a float64 "
            f"(|f * x / z| < 1.8e308)")


def _report(s: Settings, records: list[dict]) -> dict:
    sc = s.scene
    depths = [(r["min_depth"], r["max_depth"]) for r in records if r["min_depth"] is not None]
    scene = {"name": sc.name, "source": sc.source, "vertices": int(len(sc.vertices)),
             "edges": int(len(sc.edges)), "faces": len(sc.faces),
             "objects": [{"name": o.name, "vertices": o.vertex_count, "spin": list(o.motion.turns),
                          "translate": list(o.motion.offset), "scale": o.motion.scale} for o in sc.objects]}
    if sc.faces:
        scene["winding_note"] = sc.winding_note
    summary = {
        "frames": s.frames,
        "frames_with_clipping": sum(1 for r in records if r["clipped"] or r["clipped_edges"]),
        "min_depth": min(d[0] for d in depths) if depths else None,
        "max_depth": max(d[1] for d in depths) if depths else None,
    }
    for key in ("objects_culled", "faces_culled", "hidden_pixels"):
        if records and key in records[0]:
            summary[key] = sum(r[key] or 0 for r in records)       # total over the run
    report = {
        "scene": scene,
        "camera": s.camera.to_dict(),
    }
    if s.ortho_camera is not None:
        report["camera_orthographic"] = s.ortho_camera.to_dict()
    report.update({
        "motion": {"turns": list(s.motion.turns), "translate": list(s.motion.offset),
                   "scale": s.motion.scale, "frames": s.frames},
        "clip": s.clip,
        "dtype": s.dtype,
        "raster": s.raster,
        "drawing": {"projection": "both" if s.ortho_camera is not None else s.camera.projection,
                    "axes": s.axes, "axis_length": axis_length(s) if s.axes else None,
                    "cull": s.cull, "hidden_lines": s.hidden_lines, "style": s.style,
                    "light": None if s.light is None else list(s.light), "object_culling": s.object_culling},
        "summary": summary,
        "frames": records,
    })
    return report


#: Optional per-frame columns of the text report: (key, header).
_EXTRA_COLUMNS = (("objects_culled", "objects_culled"), ("faces_total", "faces"),
                  ("faces_culled", "faces_culled"), ("hidden_pixels", "hidden_pixels"))


def summary_text(report: dict, render_seconds: float, wall_seconds: float, plot_seconds=None) -> str:
    sc, cam, sm = report["scene"], report["camera"], report["summary"]
    lines = [
        f"Scene: {sc['name']} ({sc['vertices']} vertices, {sc['edges']} edges) from {sc['source']}",
    ]
    if len(sc["objects"]) > 1:
        lines.append(f"Objects: {len(sc['objects'])}: " + ", ".join(
            f"{o['name']} ({o['vertices']} vertices, spin {o['spin']}, translate {o['translate']}, "
            f"scale {o['scale']})" for o in sc["objects"]))
    cams = [("Camera", cam)] + ([("Right camera", report["camera_orthographic"])]
                                if "camera_orthographic" in report else [])
    for label, c in cams:
        pad = " " * len(label)
        lines += [
            f"{label}: {c['projection']} at {c['position']} forward {[round(v, 6) for v in c['forward']]} "
            f"up {[round(v, 6) for v in c['up']]}",
            f"{pad}  fov_y={c['fov_y_deg']} deg, {c['width']}x{c['height']}, near={c['near']}, far={c['far']}"
            + (f", ortho_height={c['ortho_height']:.6g}" if c["projection"] == "orthographic" else ""),
        ]
    dr = report["drawing"]
    lines += [
        f"Motion: turns={report['motion']['turns']} translate={report['motion']['translate']} scale={report['motion']['scale']}",
        f"Clip mode: {report['clip']}, dtype: {report['dtype']}, raster: {report['raster']}",
        f"Drawing: projection={dr['projection']} axes={'on' if dr['axes'] else 'off'} cull={dr['cull'] or 'none'} "
        f"hidden_lines={'on' if dr['hidden_lines'] else 'off'} style={dr['style']}"
        + (f" light={dr['light']}" if dr["light"] else ""),
        f"Frames: {sm['frames']} ({sm['frames_with_clipping']} with clipping)",
        "Depth over the run: " + ("none visible" if sm["min_depth"] is None
                                  else f"[{sm['min_depth']:.4f}, {sm['max_depth']:.4f}]"),
    ]
    for key in ("objects_culled", "faces_culled", "hidden_pixels"):
        if key in sm:
            lines.append(f"Total {key.replace('_', ' ')} over the run: {sm[key]}")
    frames = report["frames"]
    extra = [(k, h) for k, h in _EXTRA_COLUMNS if frames and k in frames[0]]
    lines += ["", "frame  visible  clipped  clipped_edges  min_depth  max_depth" + "".join(f"  {h}" for _, h in extra)]
    for r in frames:
        dmin = "-" if r["min_depth"] is None else f"{r['min_depth']:.4f}"
        dmax = "-" if r["max_depth"] is None else f"{r['max_depth']:.4f}"
        cells = "".join(f"  {'-' if r[k] is None else r[k]:>{len(h)}}" for k, h in extra)
        lines.append(f"{r['frame']:>5}  {r['visible_vertices']:>7}  {r['clipped']:>7}  {r['clipped_edges']:>13}  "
                     f"{dmin:>9}  {dmax:>9}{cells}")
    lines += ["", "Timing (varies run to run; everything above is deterministic):",
              f"  projection + raster: {1e3 * render_seconds / max(sm['frames'], 1):.3f} ms/frame"
              + (" (both cameras)" if "camera_orthographic" in report else ""),
              f"  wall time incl. export: {wall_seconds:.3f} s"]
    if plot_seconds is not None:
        lines.append(f"  plots (matplotlib): {plot_seconds:.3f} s")
    return "\n".join(lines) + "\n"


def _progress_bar(total: int):
    """A tqdm bar on stderr for long runs, only when stderr is a terminal.

    Returns ``(update, close, write)``; ``write`` prints a line to stdout
    without tearing the bar.
    """
    if total < 50 or not sys.stderr.isatty():
        return None, lambda: None, print
    try:
        from tqdm import tqdm
    except ImportError:  # optional
        return None, lambda: None, print
    bar = tqdm(total=total, file=sys.stderr, unit="frame", leave=False)
    return (lambda k: bar.update(1)), bar.close, (lambda line: tqdm.write(line, file=sys.stdout))


def main(argv=None) -> int:
    try:
        return _main(argv)
    except BrokenPipeError:
        # stdout was closed (e.g. `renderer | head`): stop quietly, as a SIGPIPE would
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141


def _main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    try:
        s = settings_from_args(args)
    except InputError as exc:
        print(f"renderer: error: {exc}", file=sys.stderr)
        return 2
    if args.interactive:
        from .viewer import main_interactive

        return main_interactive(s, args.port)
    if args.compare:
        from .compare import main_compare

        return main_compare(s, args.compare_z, args.compare_fov)
    try:
        traces = _traces(args, s)
    except InputError as exc:
        print(f"renderer: error: {exc}", file=sys.stderr)
        return 2
    width = max(3, len(str(s.frames)))
    shown = {1, (s.frames + 1) // 2, s.frames}
    if s.frames >= 180:
        shown = {1, s.frames // 2, s.frames}

    if s.scene.faces and s.scene.winding_note:
        print(f"renderer: warning: {s.scene.source}: {s.scene.winding_note}", file=sys.stderr)
    objects = f", {len(s.scene.objects)} objects" if len(s.scene.objects) > 1 else ""
    print(f"Scene: {s.scene.name} ({len(s.scene.vertices)} vertices, {len(s.scene.edges)} edges{objects})")
    progress, close, write = _progress_bar(s.frames)

    def log(k, frame, info):
        if args.verbose or k in shown:
            extra = "".join(f" {key}={info[key]}" for key in ("objects_culled", "faces_culled", "hidden_pixels")
                            if info.get(key) is not None)
            write(f"Frame {k:0{width}d}: visible_vertices={frame.visible_vertices} "
                  f"clipped={frame.clipped_vertices} {depth_text(frame)}{extra}")

    profiler = None
    if args.profile:
        from .profile import FrameProfiler

        profiler = FrameProfiler()
    try:
        report = render_run(s, log=log, progress=progress, profiler=profiler,
                            extra={"trace": traces} if traces else None)
    except InputError as exc:
        close()
        print(f"renderer: error: {exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:
        close()
        raise
    except OSError as exc:
        close()
        print(f"renderer: error: writing to {str(s.out)!r} failed: {exc}", file=sys.stderr)
        return 2
    close()
    if traces:
        from .trace import trace_text

        for rec in traces:
            print(trace_text(rec, s.camera), end="")
    if profiler is not None:
        from .profile import profile_table

        print(profile_table(report["profile"]), end="")
    paths = report["_paths"]
    if paths["frames"] is not None:
        print(f"Exported frames: {paths['frames']}/")
    for key in ("gif", "mp4"):
        if paths[key] is not None:
            print(f"Animation: {paths[key]}")
    if paths["plots"] is not None:
        print(f"Plots: {paths['plots']}")
    print(f"Summary: {paths['txt']}")
    return 0


def _traces(args, s: Settings) -> list[dict]:
    """--trace-vertex: the vertex in every space in each traced frame (core.trace), [] without it."""
    if args.trace_vertex is None:
        if args.trace_frames is not None:
            raise InputError(f"--trace-frames {args.trace_frames!r} without --trace-vertex: expected --trace-vertex I")
        return []
    from .trace import check_vertex, parse_frames, trace_vertex

    check_vertex(s.scene, args.trace_vertex)
    renderer = FrameRenderer(s)
    out = []
    for k in parse_frames(args.trace_frames, s.frames):
        frame, _ = renderer.render(k, s.camera)
        out.append(trace_vertex(s.scene, s.motion, s.camera, args.trace_vertex, k, s.frames,
                                frame.p_px[args.trace_vertex]))
    return out


if __name__ == "__main__":
    sys.exit(main())
