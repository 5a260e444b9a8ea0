"""``renderer --interactive``: a local browser viewer whose frames are drawn by core.

The page (``core/app/viewer_static/``) only sends input and shows what comes back:
every frame is core's pipeline (the ``renderer``'s own frame set-up, picture and
axes, PNG-encoded by :func:`core.outputs.output.png_bytes`), so a frame here is
byte-for-byte the PNG ``renderer`` writes for the command line the page shows.

Camera controls (pure functions over :class:`View`; signs in core.conventions)

- orbit: a drag of ``(dx, dy)`` CSS pixels turns the camera about the look-at
  point: by ``-dx * DEG_PER_PX`` about the camera's up (drag right: the camera
  goes left, the scene turns right with the mouse), then by ``-dy * DEG_PER_PX``
  about its right (drag down: the camera goes up, the scene's top tilts toward
  the viewer). ``up`` turns with the camera, so it never becomes parallel to
  ``forward``.
- dolly: a wheel ``delta`` scales the distance to the look-at point by
  ``exp(delta * DOLLY_PER_UNIT)``.
- pan (shift-drag): camera and look-at point move by ``-dx right + dy up`` times
  the world size of a pixel at the look-at distance (``2 d tan(fov/2) / H``;
  orthographic ``ortho_height / H``), so a point at that distance follows the
  mouse exactly.

The server (core.app.viewer_http) is :class:`http.server.ThreadingHTTPServer` on 127.0.0.1. Requests
are serialised by one lock (apply, render and answer happen under it, so a
response is always one consistent view and its frame), and the page keeps at
most one request in flight, merging the input that arrives meanwhile into the
next one: a slow frame never queues a backlog. API: ``GET /api/frame`` (the
current frame), ``POST /api/frame`` with ``{"ops": [...], "overlay": bool}``
(see :meth:`Viewer.apply`). Bad ops (a NaN in a field, near > far) come back
as ``"error"`` with the previous view unchanged; a bad request (body, size,
method, path, Host, Origin) is a 4xx with a JSON ``{"error": ...}`` and no
frame. Any local process or web page can reach the port, so every request is
treated as hostile input: bodies are capped (:data:`MAX_BODY_BYTES`), the work
per request is bounded (:data:`MAX_OPS`), a slow client is dropped
(:data:`REQUEST_TIMEOUT_S`), and only requests addressed to
``127.0.0.1:PORT`` or ``localhost:PORT`` from the page's own origin are served
(DNS rebinding, cross-site POSTs). The error answers are listed in
docs/interactive.md.

The oracle overlay (pyrender's frame of the same view, the diff, F1 and the
vertex error) is an optional callable given to :class:`Viewer`;
:class:`LazyOverlay` (given it by core.app.viewer_http.main_interactive) loads ``wirecheck.oracles.live`` on first use
(core itself never imports the oracles: this is the one optional hook).
"""

from __future__ import annotations

import base64
import math
import sys
import threading
import time
from dataclasses import asdict, dataclass, replace

import numpy as np

from ..camera import Camera, look_at
from ..errors import InputError
from ..outputs import output
from ..projector.pipeline import STAGES as PIPELINE_STAGES
from ..scene.files import builtin_names, example_names
from .compose import overlay, picture
from .profile import FrameProfiler

#: Orbit: degrees per CSS pixel of drag.
DEG_PER_PX = 0.5
#: Dolly: the distance is multiplied by exp(wheel delta x this) (a wheel notch of 100: x1.105).
DOLLY_PER_UNIT = 0.001
#: Server-side stages of a viewer frame (the page adds "transfer").
STAGES = PIPELINE_STAGES + ("compose", "encode")
#: Frames the server's profiler keeps (p50/p95 over these).
WINDOW = 120
#: Vertices whose pixels the page shows as JSON (the first ones of the scene).
SHOWN_VERTICES = 16
#: Most ops one request may carry. The page merges its input (one orbit, pan or dolly per run of
#: drags, one set per field), so it sends a handful; an orbit costs ~0.2 ms (look_at twice, on the
#: loaded 2-core box), so 256 ops hold the viewer's lock for ~50 ms at most, about one slow frame.
MAX_OPS = 256


@dataclass(frozen=True)
class View:
    """What the page controls: the camera pose and lens, the drawing mode, the frame."""

    position: tuple
    target: tuple
    up: tuple
    fov: float
    near: float
    far: float
    ortho_height: float
    projection: str = "perspective"
    style: str = "wireframe"
    hidden_lines: bool = False
    cull: bool = False
    axes: bool = False
    frame: int = 1

    def camera(self, width: int, height: int) -> Camera:
        return look_at(
            self.position,
            self.target,
            self.up,
            fov_y_deg=self.fov,
            width=width,
            height=height,
            near=self.near,
            far=self.far,
            projection=self.projection,
            ortho_height=self.ortho_height,
        )


def view_of(s) -> View:
    """The starting view of a run's settings (``s``: core.app.cli's Settings)."""
    c = s.camera
    d = _look_distance(s)
    target = tuple(float(v) for v in c.position + d * c.forward)
    return View(
        position=tuple(float(v) for v in c.position),
        target=target,
        up=tuple(float(v) for v in c.up),
        fov=float(c.fov_y_deg),
        near=float(c.near),
        far=float(c.far),
        ortho_height=float(c.ortho_height),
        projection=c.projection,
        style=s.style,
        hidden_lines=s.hidden_lines,
        cull=s.cull is not None,
        axes=s.axes,
    )


def _look_distance(s) -> float:
    """Distance from the camera to its look-at point (--camera-z D: |D|; else the origin's depth, min 1e-6)."""
    c = s.camera
    d = float(np.dot(-c.position, c.forward))
    return d if d > 1e-6 else max(float(np.linalg.norm(c.position)), 1.0)


def _rotate(v: np.ndarray, axis: np.ndarray, deg: float) -> np.ndarray:
    """Rodrigues: ``v`` turned by ``deg`` about the unit ``axis`` (right-handed)."""
    a = math.radians(deg)
    return v * math.cos(a) + np.cross(axis, v) * math.sin(a) + axis * np.dot(axis, v) * (1 - math.cos(a))


def orbit(view: View, dx: float, dy: float) -> View:
    """Turn the camera about the look-at point (module docstring for the signs)."""
    pos, tgt, up = (np.asarray(v, dtype=np.float64) for v in (view.position, view.target, view.up))
    cam = look_at(pos, tgt, up)
    offset = pos - tgt
    yaw, pitch = -dx * DEG_PER_PX, -dy * DEG_PER_PX
    offset = _rotate(offset, cam.up, yaw)
    right = _rotate(cam.right, cam.up, yaw)
    offset = _rotate(offset, right, pitch)
    new_up = _rotate(cam.up, right, pitch)
    return replace(view, position=tuple((tgt + offset).tolist()), up=tuple(new_up.tolist()))


def dolly(view: View, delta: float) -> View:
    """Scale the distance to the look-at point by ``exp(delta * DOLLY_PER_UNIT)``."""
    tgt = np.asarray(view.target, dtype=np.float64)
    try:
        scale = math.exp(delta * DOLLY_PER_UNIT)
    except OverflowError:  # delta > ~7e5: beyond float64
        scale = math.inf
    with np.errstate(all="ignore"):  # inf, nan or 0 from an extreme delta: refused below
        offset = (np.asarray(view.position, dtype=np.float64) - tgt) * scale
    if not (math.isfinite(scale) and np.isfinite(offset).all() and np.any(offset)):
        raise InputError(f"dolly {delta!r}: the camera would reach the look-at point or infinity")
    return replace(view, position=tuple((tgt + offset).tolist()))


def pixel_size(view: View, height: int) -> float:
    """World size of one pixel at the look-at distance."""
    if view.projection == "orthographic":
        return view.ortho_height / height
    d = float(np.linalg.norm(np.subtract(view.position, view.target)))
    return 2.0 * d * math.tan(math.radians(view.fov) / 2.0) / height


def pan(view: View, dx: float, dy: float, height: int) -> View:
    """Move camera and look-at point so the look-at plane follows the mouse by ``(dx, dy)`` px."""
    cam = look_at(view.position, view.target, view.up)
    move = (-dx * cam.right + dy * cam.up) * pixel_size(view, height)
    return replace(
        view,
        position=tuple((np.asarray(view.position) + move).tolist()),
        target=tuple((np.asarray(view.target) + move).tolist()),
    )


def short_repr(value, limit: int = 60) -> str:
    """``repr(value)``, cut to ``limit`` characters: an error message echoes hostile input in one short line."""
    r = repr(value)
    return r if len(r) <= limit else r[: limit - 3] + "..."


def _number(name, text):
    """A finite float from a JSON number or a typed string (``"61.5"``); InputError otherwise."""
    try:
        v = math.nan if isinstance(text, bool) else float(text)
    except (TypeError, ValueError, OverflowError):  # OverflowError: an integer beyond float64
        v = math.nan
    if not math.isfinite(v):
        raise InputError(f"{name} {short_repr(text)}: expected a finite number")
    return v


def _choice(allowed):
    def parse(name, text):
        if text not in allowed:
            raise InputError(f"{name} {short_repr(text)}: expected one of {', '.join(allowed)}")
        return text

    return parse


def _flag(name, value):
    if not isinstance(value, bool):
        raise InputError(f"{name} {short_repr(value)}: expected true or false")
    return value


#: Fields the page may set, with their parsers.
FIELDS = {
    "fov": _number,
    "near": _number,
    "far": _number,
    "ortho_height": _number,
    "projection": _choice(("perspective", "orthographic")),
    "style": _choice(("wireframe", "shaded")),
    "hidden_lines": _flag,
    "cull": _flag,
    "axes": _flag,
}


class Viewer:
    """The server's state: the run's settings, the current :class:`View`, the profiler.

    ``overlay(settings, camera, frame) -> dict`` is the optional oracle overlay
    (``wirecheck.oracles.live``); ``None`` means none is available.
    """

    def __init__(self, s, overlay=None):
        self.s = s
        self.start = view_of(s)
        self.view = self.start
        self.overlay = overlay
        self.profiler = FrameProfiler(STAGES, window=WINDOW)
        self.lock = threading.Lock()
        self._renderers = {}

    # ---- input
    def apply(self, ops) -> View:
        """The view after ``ops`` (a list of dicts), or InputError with the view unchanged.

        ``{"op": "orbit"|"pan", "dx", "dy"}``, ``{"op": "dolly", "delta"}``,
        ``{"op": "set", "field", "value"}`` (:data:`FIELDS`), ``{"op": "step", "n"}``
        (frames, wrapping), ``{"op": "reset"}``. At most :data:`MAX_OPS` ops; an op
        that would take the camera out of the float64 range is refused.
        """
        if not isinstance(ops, list):
            raise InputError(f"ops {short_repr(ops)}: expected a list")
        if len(ops) > MAX_OPS:
            raise InputError(f"ops: {len(ops)} in one request; expected at most {MAX_OPS}")
        v = self.view
        h = self.s.camera.height
        for op in ops:
            with np.errstate(all="ignore"):  # an op driving the camera to inf/nan is refused below
                v = self._apply_one(v, op, h)
            if not np.isfinite([*v.position, *v.target, *v.up]).all():
                raise InputError(f"op {short_repr(op)}: the camera would leave the float64 range")
        self.settings(v)  # validates camera and mode
        return v

    def _apply_one(self, v: View, op, h: int) -> View:
        """The view after one op (:meth:`apply`)."""
        kind = op.get("op") if isinstance(op, dict) else None
        if kind in ("orbit", "pan"):
            dx, dy = _number("dx", op.get("dx")), _number("dy", op.get("dy"))
            v = orbit(v, dx, dy) if kind == "orbit" else pan(v, dx, dy, h)
        elif kind == "dolly":
            v = dolly(v, _number("delta", op.get("delta")))
        elif kind == "set":
            name = op.get("field")
            if not isinstance(name, str) or name not in FIELDS:
                raise InputError(f"field {short_repr(name)}: expected one of {', '.join(FIELDS)}")
            v = replace(v, **{name: FIELDS[name](name, op.get("value"))})
        elif kind == "step":
            n = op.get("n")
            if not isinstance(n, int) or isinstance(n, bool):
                raise InputError(f"step {short_repr(n)}: expected an integer")
            v = replace(v, frame=(v.frame - 1 + n) % self.s.frames + 1)
        elif kind == "reset":
            v = replace(self.start, frame=v.frame)
        else:
            raise InputError(f"op {short_repr(op)}: expected orbit, pan, dolly, set, step or reset")
        return v

    def settings(self, v: View):
        """The run's settings for view ``v`` (InputError if the camera or the mode is invalid)."""
        cam = v.camera(self.s.camera.width, self.s.camera.height)
        if v.style == "shaded" and v.hidden_lines:
            raise InputError("hidden lines with style shaded: a shaded frame draws no lines; expected one of them")
        if (v.style == "shaded" or v.hidden_lines or v.cull) and not self.s.scene.faces:
            raise InputError(f"scene {self.s.scene.name!r} has no faces: hidden lines, culling and shading need faces")
        return replace(
            self.s,
            camera=cam,
            ortho_camera=None,
            style=v.style,
            hidden_lines=v.hidden_lines,
            cull="backface" if v.cull else None,
            axes=v.axes,
            light=self.s.light if v.style == "shaded" else None,
        )

    # ---- output
    def frame_png(self, v: View, timing: dict | None = None):
        """``(png bytes, Frame, settings)`` of view ``v``: exactly what ``renderer`` writes for its command line."""
        s = self.settings(v)
        key = (s.style, s.hidden_lines, s.cull)
        if key not in self._renderers:
            self._renderers[key] = s.scene_renderer()  # the renderer's own frame set-up
        frame, _ = self._renderers[key].render(v.frame, s.camera, timing=timing)
        t1 = time.perf_counter()
        img = picture(frame, s.style)
        if s.axes:
            img = overlay(img, s.axis_layers(s.camera, frame))
        t2 = time.perf_counter()
        png = output.png_bytes(img)
        t3 = time.perf_counter()
        if timing is not None:
            timing["compose"] = timing.get("compose", 0.0) + (t2 - t1)
            timing["encode"] = timing.get("encode", 0.0) + (t3 - t2)
        return png, frame, s

    def command(self, v: View) -> str:
        """The ``renderer`` command line that writes this frame (``frame_<k>.png``), floats exact (repr)."""
        s = self.s
        scene = s.scene.name if s.scene.name in builtin_names() + example_names() else s.scene.source
        r = lambda xs: ",".join(repr(float(x)) for x in xs)  # noqa: E731 - repr round-trips floats
        # OPTION=VALUE: a value starting with "-" is not taken for an option
        args = [
            "renderer",
            "--scene",
            scene,
            "--frames",
            str(s.frames),
            f"--camera-pos={r(v.position)}",
            f"--look-at={r(v.target)}",
            f"--up={r(v.up)}",
            f"--fov={v.fov!r}",
            f"--near={v.near!r}",
            f"--far={v.far!r}",
        ]
        if (s.camera.width, s.camera.height) != (640, 480):
            args += ["--width", str(s.camera.width), "--height", str(s.camera.height)]
        if v.projection == "orthographic":
            args += ["--projection", "orthographic", f"--ortho-height={v.ortho_height!r}"]
        m = s.motion
        if tuple(m.turns) != (1.0, 1.0, 0.0):
            args += [f"--spin={r(m.turns)}"]
        if tuple(m.offset) != (0.0, 0.0, 0.0):
            args += [f"--translate={r(m.offset)}"]
        if m.scale != 1.0:
            args += [f"--scale={m.scale!r}"]
        for opt, val, default in (
            ("--clip", s.clip, "clip"),
            ("--dtype", s.dtype, "float64"),
            ("--raster", s.raster, "exact"),
        ):
            if val != default:
                args += [opt, val]
        if v.hidden_lines:
            args.append("--hidden-lines")
        if v.cull:
            args += ["--cull", "backface"]
        if v.style == "shaded":
            args += ["--style", "shaded"]
            if s.light is not None:
                args += [f"--light={r(s.light)}"]
        if v.axes:
            args.append("--axes")
        if not s.object_culling:
            args.append("--no-object-culling")
        return " ".join(args) + f"   # frame_{v.frame:04d}.png"

    def respond(self, ops=None, want_overlay: bool = False) -> dict:
        """Apply ``ops``, render, and return the page's JSON (the error, if any, with the last good view)."""
        with self.lock:
            error = None
            try:
                if ops:
                    self.view = self.apply(ops)
            except InputError as exc:
                error = str(exc)
            v = self.view
            self.profiler.begin()
            png, frame, s = self.frame_png(v, timing=self.profiler.current)
            t_enc = time.perf_counter()
            image = base64.b64encode(png).decode("ascii")
            self.profiler.add("encode", time.perf_counter() - t_enc)
            rec = self.profiler.end()
            cam = s.camera
            n = min(SHOWN_VERTICES, len(frame.p_px))
            out = {
                "error": error,
                "view": asdict(v),
                "frames": s.frames,
                "camera": {
                    k: cam.to_dict()[k]
                    for k in (
                        "position",
                        "forward",
                        "up",
                        "fov_y_deg",
                        "near",
                        "far",
                        "projection",
                        "ortho_height",
                        "width",
                        "height",
                    )
                },
                "command": self.command(v),
                "image": image,
                "vertices_px": [
                    None if not vis else [float(x), float(y)]
                    for (x, y), vis in zip(frame.p_px[:n].tolist(), frame.visible[:n].tolist())
                ],
                "timing_ms": rec,
                "profile": self.profiler.summary(),
                "overlay": None,
                "overlay_ms": 0.0,
            }
            if want_overlay:
                t0 = time.perf_counter()
                out["overlay"] = self._overlay(s, v)
                out["overlay_ms"] = 1e3 * (time.perf_counter() - t0)  # crosscheck of the view, not the frame
            return out

    def _overlay(self, s, v: View) -> dict:
        if self.overlay is None:
            return {"error": "the oracle overlay is not available (wirecheck.oracles could not be loaded)"}
        try:
            return self.overlay(s, s.camera, v.frame)
        except Exception as exc:  # an oracle failure is shown, not fatal
            return {"error": f"oracle overlay failed: {type(exc).__name__}: {exc}"}


def _load_overlay():
    """``(overlay, None)``: the oracle overlay (wirecheck.oracles.live); ``(None, why)`` when it cannot
    load, ``why`` one line (no libOSMesa: the missing library and the command that installs it)."""
    try:
        from importlib import import_module

        return import_module("wirecheck.oracles.live").LiveOverlay(), None
    except Exception as exc:  # e.g. no libOSMesa: the viewer runs without it
        why = " ".join(str(exc).split()) or type(exc).__name__
        print(f"renderer: warning: oracle overlay unavailable: {why}", file=sys.stderr)
        return None, why


class LazyOverlay:
    """Loads the oracle overlay on its first use (most sessions never turn it on); when it cannot
    load, every request's error says why and how to fix it, in the page's banner."""

    def __init__(self):
        self._impl, self._why, self._tried = None, None, False

    def __call__(self, s, camera, frame):
        if not self._tried:
            self._tried = True
            self._impl, self._why = _load_overlay()
        if self._impl is None:
            return {"error": f"the oracle overlay is not available: {self._why}"}
        return self._impl(s, camera, frame)

    def close(self):
        if self._impl is not None:
            self._impl.close()
