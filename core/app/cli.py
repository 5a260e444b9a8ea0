"""``renderer``: render a scene's motion to wireframe frames with per-frame diagnostics.

    renderer --scene cube --frames 180 --camera-z 4.0 --fov 70

Parses the options into :class:`core.app.settings.Settings`, calls
:func:`core.app.run.render_run` and prints. Results go to stdout, errors to stderr
as one line with exit status 2.
"""

from __future__ import annotations

from .startup import interrupts_from_start

interrupts_from_start("renderer")  # first: Ctrl-C while the imports below run is one line, no traceback

import argparse  # noqa: E402
import importlib.util
import math
import os
import sys
from pathlib import Path


def _load_numpy_single_threaded() -> None:
    """Import numpy with OpenBLAS sized to one thread, when this module is the first to import it.

    At load, OpenBLAS starts one worker per CPU, and they spin: ~50 ms of CPU
    (a fifth of the seed command's) that buys the renderer nothing, whose
    matrix products are 3x3 and 4x4 (core.projector.projection keeps large point arrays
    off the BLAS). ``OPENBLAS_NUM_THREADS`` is read only while the library
    loads, so it is set for the import and removed again: programs this one
    starts do not inherit it. A value the user set is left as it is.
    """
    if "numpy" in sys.modules or "OPENBLAS_NUM_THREADS" in os.environ:
        return
    os.environ["OPENBLAS_NUM_THREADS"] = "1"
    try:
        import numpy  # noqa: F401
    finally:
        del os.environ["OPENBLAS_NUM_THREADS"]


_load_numpy_single_threaded()

from ..camera import COEFFICIENT_COUNTS, Camera, camera_z, look_at, orthographic_twin
from ..errors import InputError, check_not_empty
from ..limits import MAX_FRAMES, check_image_size, check_turns
from ..numbers import plain_float, plain_int
from ..outputs.output import check_outside_scenes
from ..outputs.staging import check_out
from ..projector.clipping import CLIP_MODES
from ..projector.culling import CULL_CHOICES
from ..projector.projection import DTYPES
from ..projector.raster import RASTER_MODES
from ..projector.shading import STYLES
from ..scene.files import load_scene
from ..transforms import Motion
from .cli_help import RENDERER_EXAMPLES, OneLineParser
from .compare import main_compare
from .compose import AXIS_LENGTH
from .guard import VersionAction, run_cli
from .profile import FrameProfiler, profile_table
from .report import depth_text
from .run import FORMATS, output_names, progress_steps, render_run
from .settings import Settings
from .trace import check_vertex, parse_frames, trace_text, trace_vertex

DESCRIPTION = "renderer: render a scene's motion to wireframe frames with per-frame diagnostics."
#: --projection: one camera, or "both": perspective left, orthographic right.
PROJECTION_CHOICES = ("perspective", "orthographic", "both")


def vec3(option: str, text: str) -> tuple[float, float, float]:
    """``"X,Y,Z"`` as three finite floats; InputError naming ``option`` otherwise."""
    parts = text.split(",")
    try:
        values = tuple(plain_float(p) for p in parts)
    except ValueError:
        raise InputError(f"{option} {text!r}: expected three numbers X,Y,Z") from None
    if len(values) != 3 or not all(math.isfinite(v) for v in values):
        raise InputError(f"{option} {text!r}: expected three finite numbers X,Y,Z")
    return values


def build_parser() -> argparse.ArgumentParser:
    p = OneLineParser(
        prog="renderer",
        description=DESCRIPTION,
        epilog=RENDERER_EXAMPLES,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "--version",
        action=VersionAction,
        version="%(prog)s (wirecheck) {}",
        help="print the installed wirecheck version and exit",
    )
    p.add_argument(
        "--scene",
        default="cube",
        help="built-in name (cube, pyramid, prism), an example "
        "(orrery: scenes/examples/, several objects) or a file path (.scene, .obj, .ply, .stl, .off, "
        ".glb) (default cube)",
    )
    p.add_argument("--frames", type=plain_int, default=None, help="number of frames (default 180)")
    cam = p.add_argument_group("camera (conventions: wirecheck.core.conventions)")
    cam.add_argument(
        "--camera-z",
        type=plain_float,
        default=None,
        metavar="D",
        help="camera at (0,0,D) looking at the origin, up +Y (default 4)",
    )
    cam.add_argument(
        "--camera-pos",
        default=None,
        metavar="X,Y,Z",
        help="camera position, looking at --look-at with --up (default: --camera-z)",
    )
    cam.add_argument("--look-at", default=None, metavar="X,Y,Z", help="with --camera-pos (default 0,0,0)")
    cam.add_argument("--up", default=None, metavar="X,Y,Z", help="with --camera-pos (default 0,1,0)")
    cam.add_argument(
        "--fov", type=plain_float, default=None, help="full vertical FOV in degrees, edge to edge (default 60)"
    )
    cam.add_argument(
        "--intrinsics",
        default=None,
        metavar="FX,FY,CX,CY",
        help="a calibrated camera instead of --fov: focal lengths and principal point in pixels, "
        "pixel centres at integers (wirecheck.core.conventions; default: none, from --fov)",
    )
    cam.add_argument(
        "--distortion",
        default=None,
        metavar="K1,K2,P1,P2[,K3[,K4,K5,K6]]",
        help="OpenCV lens distortion of the vertices (edges stay straight lines between them; "
        "wireframes only) (default: none)",
    )
    cam.add_argument("--near", type=plain_float, default=0.1, help="near plane distance (default 0.1)")
    cam.add_argument("--far", type=plain_float, default=100.0, help="far plane distance (default 100)")
    cam.add_argument("--width", type=plain_int, default=640, help="image width in pixels (default 640)")
    cam.add_argument("--height", type=plain_int, default=480, help="image height in pixels (default 480)")
    cam.add_argument(
        "--projection",
        choices=PROJECTION_CHOICES,
        default="perspective",
        help="both: every frame twice, side by side: perspective on the left, on the right an "
        "orthographic camera at the same position and orientation with ortho-height = "
        "2 d tan(fov/2), d = the distance to the look-at point (so things at the look-at "
        "distance are the same size in both); a 1-px grey column between them, output width 2W+1 "
        "(default perspective)",
    )
    cam.add_argument(
        "--ortho-height",
        type=plain_float,
        default=None,
        help="world units visible vertically (orthographic; default 4)",
    )
    mot = p.add_argument_group(
        "motion (model matrix of frame k uses t = (k-1)/frames; in a scene of several "
        "objects it applies to the whole scene, after each object's own motion)"
    )
    mot.add_argument(
        "--spin", default=None, metavar="X,Y,Z", help="full turns about X, Y, Z over the run (default 1,1,0)"
    )
    mot.add_argument(
        "--translate",
        default="0,0,0",
        metavar="X,Y,Z",
        help="constant offset of the scene, the same in every frame (default 0,0,0)",
    )
    mot.add_argument("--scale", type=plain_float, default=1.0, help="uniform scale, non-zero (default 1)")
    p.add_argument(
        "--clip",
        choices=CLIP_MODES,
        default="clip",
        help="clip: clip edges at near/far; endpoint: drop edges with a clipped end (default clip)",
    )
    p.add_argument(
        "--dtype",
        choices=DTYPES,
        default="float64",
        help="precision of every per-point operation (default float64; wirecheck.core.projector.projection)",
    )
    p.add_argument(
        "--raster",
        choices=RASTER_MODES,
        default="exact",
        help="exact: GL diamond-exit (matches Mesa); fast: integer DDA; aa: anti-aliased (Wu) (default exact)",
    )
    drw = p.add_argument_group("drawing (faces: --cull, --hidden-lines and --style shaded need a scene with faces)")
    drw.add_argument(
        "--axes",
        action="store_true",
        help="draw the world axes from the origin, X red, Y green, Z blue, length 1.2 x the "
        "scene's bounding radius x |--scale|, through the same camera and clipping as the "
        "edges, over the picture but, with --hidden-lines or --style shaded, hidden behind faces "
        "like the edges; frames become RGB (default off: grey frames)",
    )
    drw.add_argument(
        "--cull",
        choices=CULL_CHOICES,
        default="none",
        help="backface: drop faces turned away from the camera (needs consistent winding) (default none)",
    )
    drw.add_argument("--hidden-lines", action="store_true", help="hide edges behind faces (z-buffer) (default off)")
    drw.add_argument(
        "--style", choices=STYLES, default="wireframe", help="shaded: flat-shaded faces (default wireframe)"
    )
    drw.add_argument(
        "--light",
        default=None,
        metavar="X,Y,Z",
        help="--style shaded: the world direction the light travels (default: from the camera's upper left)",
    )
    drw.add_argument(
        "--object-culling",
        action=argparse.BooleanOptionalAction,
        default=True,
        help="scenes of several objects: skip objects whose bounding sphere is outside the "
        "frustum (default on; never changes the picture or the vertex and edge counts)",
    )
    p.add_argument(
        "--format",
        default=None,
        help="comma-separated: png, ascii, gif, mp4 (default png). mp4: "
        "H.264 yuv420p via PyAV, 30 fps; an odd width or height is padded with one black "
        "row/column, never scaled",
    )
    p.add_argument(
        "--plots",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="also write <scene>-plots.png: depth range, clipped vertices/edges (and culled "
        "faces/objects, hidden pixels when on) against frame number (default off: matplotlib "
        "adds about 1 s)",
    )
    p.add_argument("--ascii-cols", type=plain_int, default=None, help="columns of the ascii frames (default 80)")
    p.add_argument("--out", default=None, help="output directory (default output/)")
    p.add_argument(
        "--verbose", action="store_true", help="print every frame (default off: only the first, middle and last)"
    )
    ana = p.add_argument_group("analysis and the interactive viewer (docs/interactive.md)")
    ana.add_argument(
        "--profile",
        action="store_true",
        help="time every frame's stages (transform, faces, shading, clip, raster, compose, encode, "
        "write): a table on stdout and 'profile' in the JSON report (default off)",
    )
    ana.add_argument(
        "--trace-vertex",
        type=plain_int,
        default=None,
        metavar="I",
        help="print vertex I in every space (model, world, camera, clip, NDC, pixel), its visibility "
        "and its edges' clipping; also 'trace' in the JSON report (default: none)",
    )
    ana.add_argument(
        "--trace-frames",
        default=None,
        metavar="K,K,...",
        help="frames of --trace-vertex (default: first, middle, last)",
    )
    ana.add_argument(
        "--compare",
        action="store_true",
        help="render the scene at two camera distances and two FOVs (--compare-z, --compare-fov) "
        "in a 2x2 picture and explain the difference with numbers measured from the frames "
        "(default off)",
    )
    ana.add_argument("--compare-z", default=None, metavar="D1,D2", help="--compare: camera distances (default 3,6)")
    ana.add_argument("--compare-fov", default=None, metavar="F1,F2", help="--compare: FOVs (default 60,90)")
    ana.add_argument(
        "--interactive",
        action="store_true",
        help="serve a viewer on 127.0.0.1 (frames drawn by core; orbit, dolly, pan, the oracle "
        "overlay, the profiler); opens no browser; Ctrl-C stops it (default off)",
    )
    ana.add_argument(
        "--port", type=plain_int, default=None, help="--interactive: port (default 0: a free one, printed)"
    )
    return p


#: Options whose default is None so that one given explicitly is seen: their defaults once checked.
DEFAULTS = {
    "frames": 180,
    "spin": "1,1,0",
    "format": "png",
    "plots": False,
    "ascii_cols": 80,
    "out": "output",
    "compare_z": "3,6",
    "compare_fov": "60,90",
    "port": 0,
}

#: Options a mode never reads (option, attribute), refused rather than silently ignored.
_UNUSED = {
    "compare": [
        ("--frames", "frames"),
        ("--format", "format"),
        ("--plots/--no-plots", "plots"),
        ("--ascii-cols", "ascii_cols"),
        ("--verbose", "verbose"),
        ("--profile", "profile"),
        ("--trace-vertex", "trace_vertex"),
        ("--trace-frames", "trace_frames"),
        ("--fov", "fov"),
        ("--camera-z", "camera_z"),
        ("--camera-pos", "camera_pos"),
        ("--look-at", "look_at"),
        ("--up", "up"),
        ("--ortho-height", "ortho_height"),
        ("--spin", "spin"),
        ("--axes", "axes"),
        ("--interactive", "interactive"),
        ("--port", "port"),
    ],
    "interactive": [
        ("--out", "out"),
        ("--format", "format"),
        ("--plots/--no-plots", "plots"),
        ("--ascii-cols", "ascii_cols"),
        ("--verbose", "verbose"),
        ("--profile", "profile"),
        ("--trace-vertex", "trace_vertex"),
        ("--trace-frames", "trace_frames"),
        ("--compare-z", "compare_z"),
        ("--compare-fov", "compare_fov"),
    ],
}


def _given(a, attr: str) -> bool:
    return getattr(a, attr) not in (None, False)


def check_combinations(a: argparse.Namespace) -> None:
    """InputError for an option that the other options make ineffective (it would be silently ignored)."""
    for mode, unused in _UNUSED.items():
        if getattr(a, mode):
            for option, attr in unused:
                if _given(a, attr):
                    raise InputError(f"{option} with --{mode}: --{mode} does not use it; expected one of them")
    if a.compare and a.projection != "perspective":
        raise InputError(
            f"--projection {a.projection} with --compare: its four cameras are perspective; expected one of them"
        )
    for option, attr, needs, on in (
        ("--port", "port", "--interactive", a.interactive),
        ("--compare-z", "compare_z", "--compare", a.compare),
        ("--compare-fov", "compare_fov", "--compare", a.compare),
    ):
        if _given(a, attr) and not on:
            raise InputError(
                f"{option} {getattr(a, attr)!r} without {needs}: expected {needs} with it (it has no effect otherwise)"
            )
    if (
        a.ortho_height is not None
        and a.projection == "perspective"
        and math.isfinite(a.ortho_height)
        and a.ortho_height > 0
        and not a.compare
    ):
        raise InputError(
            f"--ortho-height {a.ortho_height} with --projection perspective: expected "
            "--projection orthographic with it (it has no effect otherwise)"
        )
    if a.ascii_cols is not None and not a.compare and not a.interactive:
        formats = [f.strip() for f in (a.format or DEFAULTS["format"]).split(",")]
        if "ascii" not in formats:
            raise InputError(
                f"--ascii-cols {a.ascii_cols} without ascii in --format: expected --format "
                "with ascii (it has no effect otherwise)"
            )


def settings_from_args(a: argparse.Namespace) -> Settings:
    """The run the options ask for; InputError (one line, naming the option) for anything invalid."""
    check_combinations(a)
    for attr, value in DEFAULTS.items():
        if getattr(a, attr) is None:
            setattr(a, attr, value)
    if not 1 <= a.frames <= MAX_FRAMES:
        raise InputError(f"--frames {a.frames}: expected an integer in 1..{MAX_FRAMES:,} (limits.MAX_FRAMES)")
    check_not_empty([("--out", a.out)])
    fov_given = a.fov is not None
    a.fov = 60.0 if a.fov is None else a.fov
    if not (0.0 < a.fov < 180.0):
        raise InputError(f"--fov {a.fov}: expected degrees in (0, 180)")
    check_image_size(a.width, a.height, "--width/--height")
    lens = _lens_options(a, fov_given)
    if a.ortho_height is not None and not (math.isfinite(a.ortho_height) and a.ortho_height > 0):
        raise InputError(f"--ortho-height {a.ortho_height}: expected a finite number > 0")
    if not (math.isfinite(a.scale) and a.scale != 0):
        raise InputError(f"--scale {a.scale}: expected a finite non-zero number")
    for option, value in (("--near", a.near), ("--far", a.far)):
        if not math.isfinite(value):  # the camera's own check names no option
            raise InputError(f"{option} {value}: expected a finite distance (near > 0 in perspective, far > near)")
    if a.ascii_cols < 1:
        raise InputError(f"--ascii-cols {a.ascii_cols}: expected an integer >= 1")
    formats = tuple(f.strip() for f in a.format.split(","))
    bad = [f for f in formats if f not in FORMATS]
    if bad:
        raise InputError(
            f"--format {a.format!r}: {bad[0]!r} is not a format: expected a comma-separated list "
            f"of {', '.join(FORMATS)} (lower case, no empty item)"
        )
    twice = next((f for i, f in enumerate(formats) if f in formats[:i]), None)
    if twice is not None:
        raise InputError(f"--format {a.format!r}: {twice!r} given twice: expected each format once")
    both = a.projection == "both"
    kwargs = dict(
        fov_y_deg=a.fov,
        width=a.width,
        height=a.height,
        near=a.near,
        far=a.far,
        projection="perspective" if both else a.projection,
        ortho_height=4.0 if a.ortho_height is None else a.ortho_height,
        **lens,
    )
    if a.camera_pos is not None:
        if a.camera_z is not None:
            raise InputError("--camera-z and --camera-pos: expected one of them, not both")
        position, target = vec3("--camera-pos", a.camera_pos), vec3("--look-at", a.look_at or "0,0,0")
        camera = look_at(position, target, vec3("--up", a.up or "0,1,0"), **kwargs)
        distance = math.dist(position, target)
    else:
        if a.look_at is not None or a.up is not None:
            raise InputError(
                "--look-at/--up without --camera-pos: expected --camera-pos X,Y,Z with them "
                "(--camera-z always looks at the origin with up +Y)"
            )
        d = 4.0 if a.camera_z is None else a.camera_z
        if not (math.isfinite(d) and d != 0):
            raise InputError(f"--camera-z {d}: expected a finite non-zero distance")
        camera = camera_z(d, **kwargs)
        distance = abs(d)
    _check_dtype_range(camera, a)
    if both and a.ortho_height is not None:
        raise InputError(
            f"--ortho-height {a.ortho_height} with --projection both: the orthographic half's "
            "height is 2 d tan(fov/2), set by the perspective camera; expected no --ortho-height"
        )
    if a.style == "shaded" and a.hidden_lines:
        raise InputError("--hidden-lines with --style shaded: a shaded frame draws no lines; expected one of them")
    ortho_camera = None
    if both:
        ortho_camera = orthographic_twin(camera, distance)
    frame_width = 2 * a.width + 1 if both else a.width
    if "ascii" in formats and a.ascii_cols > frame_width:
        raise InputError(
            f"--ascii-cols {a.ascii_cols}: expected at most the frame's width, {frame_width} pixels "
            "(a character covers at least one pixel)"
        )
    light = None
    if a.light is not None:
        if a.style != "shaded":
            raise InputError(f"--light {a.light!r} without --style shaded: expected --style shaded with it")
        light = vec3("--light", a.light)
        if not any(light):
            raise InputError(f"--light {a.light!r}: expected a non-zero direction")
        big = max(abs(v) for v in light)
        light = tuple(v / big for v in light)  # a direction: scale it to avoid over/underflow
    motion = Motion(
        turns=check_turns(vec3("--spin", a.spin), "--spin"), offset=vec3("--translate", a.translate), scale=a.scale
    )
    if "mp4" in formats and importlib.util.find_spec("av") is None:
        raise InputError("--format mp4: expected the PyAV package (pip install av; it is a dependency of wirecheck)")
    scene = load_scene(a.scene)
    for note in scene.load_notes:  # read leniently (core.scene.files): one line each, the run goes on
        print(f"renderer: warning: {note}", file=sys.stderr)
    cull = None if a.cull == "none" else a.cull
    s = Settings(
        scene,
        camera,
        motion,
        a.frames,
        a.clip,
        formats,
        Path(a.out),
        a.ascii_cols,
        dtype=a.dtype,
        raster=a.raster,
        ortho_camera=ortho_camera,
        axes=a.axes,
        cull=cull,
        hidden_lines=a.hidden_lines,
        style=a.style,
        light=light,
        object_culling=a.object_culling,
        plots=a.plots,
    )
    if s.uses_faces:
        asked = " ".join(
            f
            for f, on in (
                ("--cull backface", cull),
                ("--hidden-lines", a.hidden_lines),
                ("--style shaded", a.style == "shaded"),
            )
            if on
        )
        if not scene.faces:
            raise InputError(
                f"{asked}: scene {scene.name!r} ({scene.source}) has no faces: expected a scene "
                "with faces ('f' lines or a mesh file)"
            )
    if a.axes and not math.isfinite(AXIS_LENGTH * scene.radius * abs(motion.scale)):
        raise InputError(
            f"--axes with --scale {a.scale}: axis length 1.2 x radius {scene.radius:g} x |scale| "
            "overflows float64; expected a smaller --scale"
        )
    if cull is not None and scene.winding_note:
        raise InputError(
            f"--cull backface: {scene.source}: {scene.winding_note}: expected faces wound "
            "consistently (counter-clockwise seen from outside)"
        )
    if not a.interactive:
        check_outside_scenes(s.out, "--out", "an output folder elsewhere (output/ by default)")
        check_out(s.out, output_names(s))
    return s


def _numbers(option: str, text: str, counts: tuple) -> tuple:
    """``"A,B,..."`` as finite floats, as many as one of ``counts``; InputError naming ``option`` otherwise."""
    try:
        values = tuple(plain_float(p) for p in text.split(","))
    except ValueError:
        values = ()
    if len(values) not in counts or not all(math.isfinite(v) for v in values):
        raise InputError(f"{option} {text!r}: expected {' or '.join(map(str, counts))} finite numbers, comma-separated")
    return values


def _lens_options(a, fov_given: bool) -> dict:
    """``--intrinsics`` and ``--distortion`` as Camera fields; InputError for a combination that ignores them."""

    out = {}
    if a.intrinsics is not None:
        if fov_given:
            raise InputError("--fov and --intrinsics: expected one of them (the intrinsics give the focal lengths)")
        out["intrinsics"] = _numbers("--intrinsics", a.intrinsics, (4,))
    if a.distortion is not None:
        out["distortion"] = _numbers("--distortion", a.distortion, COEFFICIENT_COUNTS)
    if out:
        given = " ".join(f"--{k}" for k in out)
        if a.projection != "perspective":
            raise InputError(
                f"{given} with --projection {a.projection}: expected --projection perspective "
                "(a calibrated camera is a pinhole)"
            )
        if a.compare or a.interactive:
            raise InputError(
                f"{given} with --{'compare' if a.compare else 'interactive'}: its cameras are "
                "set by FOV; expected one of them"
            )
    if "distortion" in out and (a.hidden_lines or a.style == "shaded"):
        raise InputError(
            "--distortion with --hidden-lines or --style shaded: only vertices go through the lens, "
            "faces do not; expected a wireframe"
        )
    if out:
        try:  # the camera's own checks, named by the option
            Camera(
                position=(0.0, 0.0, 1.0),
                forward=(0.0, 0.0, -1.0),
                up=(0.0, 1.0, 0.0),
                width=a.width,
                height=a.height,
                **out,
            )
        except InputError as exc:
            raise InputError(f"{given} {' '.join(repr(getattr(a, k)) for k in out)}: {exc}") from None
    return out


def _check_dtype_range(camera, a) -> None:
    """InputError when the camera's pixel scale overflows --dtype (float32 tops out at 3.4e38)."""
    import numpy as np

    big = float(np.finfo(a.dtype).max)
    if camera.projection == "perspective" and not camera.focal_px < big:
        raise InputError(
            f"--fov {a.fov} with --dtype {a.dtype}: focal length (H/2)/tan(fov/2) = "
            f"{camera.focal_px:.3g} px overflows {a.dtype} (largest {big:.3g}): expected a larger "
            "--fov or --dtype float64"
        )
    if camera.projection == "orthographic" and not camera.height / camera.ortho_height < big:
        raise InputError(
            f"--ortho-height {camera.ortho_height} with --dtype {a.dtype}: pixel scale "
            f"H/ortho-height overflows {a.dtype} (largest {big:.3g}): expected a larger --ortho-height "
            "or --dtype float64"
        )


def _progress_bar(total: int, frames: int):
    """A tqdm bar on stderr for long runs (``frames`` >= 50), only when stderr is a terminal.

    Returns ``(step, close, write)``: ``step(stage)`` advances the bar by one of
    ``total`` steps (the stage, "render" or an animation's encoding, is shown);
    ``write`` prints a line to stdout without tearing the bar.
    """
    if frames < 50 or not sys.stderr.isatty():
        return None, lambda: None, print
    from tqdm import tqdm

    tqdm.monitor_interval = 0  # no monitor thread: core.outputs.frame_writer forks only a single-threaded process
    bar = tqdm(total=total, file=sys.stderr, unit="step", desc="render", leave=False)

    def step(stage: str) -> None:
        if bar.desc != stage:
            bar.set_description_str(stage, refresh=False)
        bar.update(1)

    return step, bar.close, (lambda line: tqdm.write(line, file=sys.stdout))


def main(argv=None) -> int:
    return run_cli("renderer", _main, argv)


def _main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    s = settings_from_args(args)  # InputError: one line, exit 2 (core.app.guard)
    if args.interactive:
        from .viewer_http import main_interactive

        return main_interactive(s, args.port)
    if args.compare:
        return main_compare(s, args.compare_z, args.compare_fov)
    traces = _traces(args, s)
    width = max(3, len(str(s.frames)))
    shown = {1, (s.frames + 1) // 2, s.frames}
    if s.frames >= 180:
        shown = {1, s.frames // 2, s.frames}

    objects = f", {len(s.scene.objects)} objects" if len(s.scene.objects) > 1 else ""
    print(f"Scene: {s.scene.name} ({len(s.scene.vertices)} vertices, {len(s.scene.edges)} edges{objects})")
    progress, close, write = _progress_bar(progress_steps(s), s.frames)

    def log(k, frame, info):
        if args.verbose or k in shown:
            extra = "".join(
                f" {key}={info[key]}"
                for key in ("objects_culled", "faces_culled", "hidden_pixels")
                if info.get(key) is not None
            )
            write(
                f"Frame {k:0{width}d}: visible_vertices={frame.visible_vertices} "
                f"clipped={frame.clipped_vertices} {depth_text(frame)}{extra}"
            )

    profiler = None
    if args.profile:
        profiler = FrameProfiler()
    try:
        report = render_run(
            s, log=log, progress=progress, profiler=profiler, extra={"trace": traces} if traces else None
        )
    finally:
        close()
    if s.scene.faces and s.scene.winding_note:  # after the run: an error line is the only line
        print(f"renderer: warning: {s.scene.source}: {s.scene.winding_note}", file=sys.stderr)
    if traces:
        for rec in traces:
            print(trace_text(rec, s.camera), end="")
    if profiler is not None:
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
    """--trace-vertex: the vertex in every space in each traced frame (core.app.trace), [] without it."""
    if args.trace_vertex is None:
        if args.trace_frames is not None:
            raise InputError(f"--trace-frames {args.trace_frames!r} without --trace-vertex: expected --trace-vertex I")
        return []
    check_vertex(s.scene, args.trace_vertex)
    renderer = s.scene_renderer()
    out = []
    for k in parse_frames(args.trace_frames, s.frames):
        frame, _ = renderer.render(k, s.camera)
        out.append(
            trace_vertex(s.scene, s.motion, s.camera, args.trace_vertex, k, s.frames, frame.p_px[args.trace_vertex])
        )
    return out


if __name__ == "__main__":
    sys.exit(main())
