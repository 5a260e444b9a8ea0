"""``renderer``: render a scene's motion to wireframe frames with per-frame diagnostics.

    renderer --scene cube --frames 180 --camera-z 4.0 --fov 70

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
from .pipeline import CLIP_MODES, RASTER_MODES, render_frame
from .projection import DTYPES, localize
from .scene import Scene, load_scene
from .transforms import Motion

FORMATS = ("png", "ascii", "gif")
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
    p.add_argument("--scene", default="cube", help="built-in name (cube, pyramid, prism) or a file path "
                   "(.scene, .obj, .ply, .stl, .off, .glb)")
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
    cam.add_argument("--projection", choices=("perspective", "orthographic"), default="perspective")
    cam.add_argument("--ortho-height", type=float, default=4.0, help="world units visible vertically (orthographic)")
    mot = p.add_argument_group("motion (model matrix of frame k uses t = (k-1)/frames)")
    mot.add_argument("--spin", default="1,1,0", metavar="X,Y,Z", help="full turns about X, Y, Z over the run (default 1,1,0)")
    mot.add_argument("--translate", default="0,0,0", metavar="X,Y,Z")
    mot.add_argument("--scale", type=float, default=1.0)
    p.add_argument("--clip", choices=CLIP_MODES, default="clip",
                   help="clip: clip edges at near/far; endpoint: drop edges with a clipped end")
    p.add_argument("--dtype", choices=DTYPES, default="float64",
                   help="precision of every per-point operation (default float64; core/projection.py)")
    p.add_argument("--raster", choices=RASTER_MODES, default="exact",
                   help="exact: GL diamond-exit (matches Mesa); fast: integer DDA; aa: anti-aliased (Wu)")
    p.add_argument("--format", default="png", help="comma-separated: png, ascii, gif (default png)")
    p.add_argument("--ascii-cols", type=int, default=80)
    p.add_argument("--out", default="output", help="output directory (default output/)")
    p.add_argument("--verbose", action="store_true", help="print every frame, not only first, middle and last")
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
    kwargs = dict(fov_y_deg=a.fov, width=a.width, height=a.height, near=a.near, far=a.far,
                  projection=a.projection, ortho_height=a.ortho_height)
    if a.camera_pos is not None:
        if a.camera_z is not None:
            raise InputError("--camera-z and --camera-pos: expected one of them, not both")
        camera = look_at(vec3("--camera-pos", a.camera_pos), vec3("--look-at", a.look_at or "0,0,0"),
                         vec3("--up", a.up or "0,1,0"), **kwargs)
    else:
        if a.look_at is not None or a.up is not None:
            raise InputError("--look-at/--up without --camera-pos: expected --camera-pos X,Y,Z with them "
                             "(--camera-z always looks at the origin with up +Y)")
        d = 4.0 if a.camera_z is None else a.camera_z
        if not (math.isfinite(d) and d != 0):
            raise InputError(f"--camera-z {d}: expected a finite non-zero distance")
        camera = camera_z(d, **kwargs)
    motion = Motion(turns=vec3("--spin", a.spin), offset=vec3("--translate", a.translate), scale=a.scale)
    scene = load_scene(a.scene)
    out = Path(a.out)
    _check_writable(out)
    if "png" in formats or "ascii" in formats:
        output.check_replaceable(out / f"{scene.name}-frames", "--out")
    return Settings(scene, camera, motion, a.frames, a.clip, formats, out, a.ascii_cols,
                    dtype=a.dtype, raster=a.raster)


def _check_writable(out: Path) -> None:
    try:
        out.mkdir(parents=True, exist_ok=True)
        probe = out / ".wirecheck-write-test"
        probe.write_bytes(b"")
        probe.unlink()
    except OSError as exc:
        raise InputError(f"--out {str(out)!r}: cannot write there ({exc.strerror or exc}): expected a writable directory") from None


def frame_record(k: int, frame, sidecar: bool) -> dict:
    rng = frame.depth_range
    rec = {
        "frame": k,
        "visible_vertices": frame.visible_vertices,
        "clipped": frame.clipped_vertices,
        "clipped_edges": frame.clipped_edges,
        "min_depth": None if rng is None else rng[0],
        "max_depth": None if rng is None else rng[1],
    }
    if not sidecar:
        rec["vertices_px"] = [None if not v else [float(x), float(y)]
                              for (x, y), v in zip(frame.p_px.tolist(), frame.visible.tolist())]
    return rec


def depth_text(frame) -> str:
    rng = frame.depth_range
    return "depth=[none]" if rng is None else f"depth=[{rng[0]:.2f}, {rng[1]:.2f}]"


def render_run(s: Settings, log=None, progress=None) -> dict:
    """Render every frame, write outputs atomically, return the report dict.

    ``log(k, frame)`` is called for each frame (the CLI decides what to print).
    """
    name = s.scene.name
    frames_dir = s.out / f"{name}-frames"
    json_path = s.out / f"{name}-report.json"
    txt_path = s.out / f"{name}-report.txt"
    sidecar = len(s.scene.vertices) > SIDECAR_VERTICES
    sidecar_path = s.out / f"{name}-vertices_px.npy"
    fdir = output.FrameDir(frames_dir, "--out") if ("png" in s.formats or "ascii" in s.formats) else None
    records, gif_images, all_px = [], [], []
    t_start = time.perf_counter()
    render_seconds = 0.0
    points = localize(s.scene.vertices, s.dtype)      # re-centred and cast once, not per frame
    try:
        for k in range(1, s.frames + 1):
            t0 = time.perf_counter()
            frame = render_frame(points, s.scene.edges, s.camera,
                                 s.motion.frame_matrix(k, s.frames), s.clip, raster=s.raster)
            render_seconds += time.perf_counter() - t0
            overflow = frame.visible & ~np.isfinite(frame.p_px).all(axis=1)
            if overflow.any():
                i = int(np.flatnonzero(overflow)[0])
                raise InputError(
                    f"{s.scene.source}: vertex {i} {s.scene.vertices[i].tolist()} projects beyond the float64 "
                    f"range in frame {k}: expected coordinates whose pixel position fits in a float64 "
                    f"(|f * x / z| < 1.8e308)")
            if fdir is not None and "png" in s.formats:
                fdir.write(f"frame_{k:04d}.png", output.png_bytes(frame.image))
            if fdir is not None and "ascii" in s.formats:
                fdir.write(f"frame_{k:04d}.txt", output.ascii_frame(frame.image, s.ascii_cols).encode())
            if "gif" in s.formats:
                gif_images.append(frame.image)
            if sidecar:
                all_px.append(frame.p_px)
            records.append(frame_record(k, frame, sidecar))
            if log:
                log(k, frame)
            if progress:
                progress(k)
        if fdir is not None:
            fdir.commit()
    except BaseException:
        if fdir is not None:
            fdir.abort()
        raise
    if "gif" in s.formats:
        output.atomic_write_bytes(s.out / f"{name}.gif", output.gif_bytes(gif_images))
    depths = [(r["min_depth"], r["max_depth"]) for r in records if r["min_depth"] is not None]
    report = {
        "scene": {"name": name, "source": s.scene.source, "vertices": int(len(s.scene.vertices)),
                  "edges": int(len(s.scene.edges)), "faces": len(s.scene.faces)},
        "camera": s.camera.to_dict(),
        "motion": {"turns": list(s.motion.turns), "translate": list(s.motion.offset),
                   "scale": s.motion.scale, "frames": s.frames},
        "clip": s.clip,
        "dtype": s.dtype,
        "raster": s.raster,
        "summary": {
            "frames": s.frames,
            "frames_with_clipping": sum(1 for r in records if r["clipped"] or r["clipped_edges"]),
            "min_depth": min(d[0] for d in depths) if depths else None,
            "max_depth": max(d[1] for d in depths) if depths else None,
        },
        "frames": records,
    }
    if sidecar:
        import io

        buf = io.BytesIO()
        np.save(buf, np.stack(all_px) if all_px else np.zeros((0, 0, 2)))
        output.atomic_write_bytes(sidecar_path, buf.getvalue())
        report["vertices_px_file"] = sidecar_path.name
    output.atomic_write_text(json_path, output.json_dumps(report))
    wall = time.perf_counter() - t_start
    output.atomic_write_text(txt_path, summary_text(report, render_seconds, wall))
    report["_paths"] = {"frames": frames_dir if fdir else None, "json": json_path, "txt": txt_path}
    return report


def summary_text(report: dict, render_seconds: float, wall_seconds: float) -> str:
    sc, cam, sm = report["scene"], report["camera"], report["summary"]
    lines = [
        f"Scene: {sc['name']} ({sc['vertices']} vertices, {sc['edges']} edges) from {sc['source']}",
        f"Camera: {cam['projection']} at {cam['position']} forward {[round(v, 6) for v in cam['forward']]} "
        f"up {[round(v, 6) for v in cam['up']]}",
        f"        fov_y={cam['fov_y_deg']} deg, {cam['width']}x{cam['height']}, near={cam['near']}, far={cam['far']}",
        f"Motion: turns={report['motion']['turns']} translate={report['motion']['translate']} scale={report['motion']['scale']}",
        f"Clip mode: {report['clip']}, dtype: {report['dtype']}, raster: {report['raster']}",
        f"Frames: {sm['frames']} ({sm['frames_with_clipping']} with clipping)",
        "Depth over the run: " + ("none visible" if sm["min_depth"] is None
                                  else f"[{sm['min_depth']:.4f}, {sm['max_depth']:.4f}]"),
        "",
        "frame  visible  clipped  clipped_edges  min_depth  max_depth",
    ]
    for r in report["frames"]:
        dmin = "-" if r["min_depth"] is None else f"{r['min_depth']:.4f}"
        dmax = "-" if r["max_depth"] is None else f"{r['max_depth']:.4f}"
        lines.append(f"{r['frame']:>5}  {r['visible_vertices']:>7}  {r['clipped']:>7}  {r['clipped_edges']:>13}  {dmin:>9}  {dmax:>9}")
    lines += ["", "Timing (varies run to run; everything above is deterministic):",
              f"  projection + raster: {1e3 * render_seconds / max(sm['frames'], 1):.3f} ms/frame",
              f"  wall time incl. export: {wall_seconds:.3f} s"]
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
    width = max(3, len(str(s.frames)))
    shown = {1, (s.frames + 1) // 2, s.frames}
    if s.frames >= 180:
        shown = {1, s.frames // 2, s.frames}

    print(f"Scene: {s.scene.name} ({len(s.scene.vertices)} vertices, {len(s.scene.edges)} edges)")
    progress, close, write = _progress_bar(s.frames)

    def log(k, frame):
        if args.verbose or k in shown:
            write(f"Frame {k:0{width}d}: visible_vertices={frame.visible_vertices} "
                  f"clipped={frame.clipped_vertices} {depth_text(frame)}")

    try:
        report = render_run(s, log=log, progress=progress)
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
    paths = report["_paths"]
    if paths["frames"] is not None:
        print(f"Exported frames: {paths['frames']}/")
    if "gif" in s.formats:
        print(f"Animation: {s.out / (s.scene.name + '.gif')}")
    print(f"Summary: {paths['txt']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
