"""A renderer run: every frame of a scene's motion rendered, composed and written, and its report.

:class:`Settings` says what to render (``renderer``'s options, validated by
core.app.cli); :func:`render_run` renders frame 1..frames through
:class:`core.scene.frames.SceneRenderer` (one camera, or two side by side), writes
the frames, animations and reports into one temporary folder, moves them into
place together (core.outputs.staging) and returns the report dict (core.app.report).
"""

from __future__ import annotations

import contextlib
import time

import numpy as np

from ..errors import InputError
from ..outputs import output
from ..outputs.frame_writer import ForkedPngWriter, can_fork
from ..outputs.gif import GifWriter
from ..outputs.staging import Staging
from .compose import overlay, picture, side_by_side
from .motion_plot import plot_png
from .report import frame_record, run_report, summary_text
from .settings import Settings

#: Output formats: frames as PNG and ASCII text, animations as GIF and MP4.
FORMATS = ("png", "ascii", "gif", "mp4")
#: Frames per second of the GIF and MP4 animations.
FPS = 30
#: Above this many vertices the per-frame pixel coordinates go to a binary
#: sidecar (float64 array, shape (frames, N, 2), NaN where clipped) instead of JSON.
SIDECAR_VERTICES = 10_000


def progress_steps(s: Settings) -> int:
    """Steps :func:`render_run` reports to ``progress``: per frame rendered and per GIF frame, then the MP4 flush.

    Both animations are encoded as the frames are rendered (memory flat in the
    frame count); the MP4 encoder's flush at the end is one more step.
    """
    return s.frames * (2 if "gif" in s.formats else 1) + ("mp4" in s.formats)


def output_names(s: Settings) -> list[str]:
    """The names a run of ``s`` may write in ``s.out`` (core.outputs.staging checks and moves them; a folder ends in ``/``)."""
    name = s.scene.name
    names = [f"{name}-frames/"] if ("png" in s.formats or "ascii" in s.formats) else []
    names += [f"{name}.{fmt}" for fmt in ("gif", "mp4") if fmt in s.formats]
    if len(s.scene.vertices) > SIDECAR_VERTICES:
        names += [f"{name}-vertices_px.npy", f"{name}-vertices_px-orthographic.npy"][: len(s.cameras)]
    if s.plots:
        names.append(f"{name}-plots.png")
    return names + [f"{name}-report.json", f"{name}-report.txt"]


def render_run(s: Settings, log=None, progress=None, profiler=None, extra: dict | None = None) -> dict:
    """Render every frame, write the outputs together (core.outputs.staging), return the report dict.

    Every output is written into a temporary folder in ``s.out`` and moved
    into place at the end; on any failure (or SIGINT/SIGTERM, raised as an
    exception by core.app.guard) nothing of the run is left. ``log(k, frame,
    info)`` is called for each frame (the caller decides what to print);
    ``progress(stage)`` once per step of :func:`progress_steps` (``stage``:
    "render", "gif" or "mp4"). ``profiler`` (a
    :class:`core.app.profile.FrameProfiler`) times each frame's stages; its
    summary becomes the report's ``profile`` field. ``extra`` fields are added
    to the report (``trace``).
    """
    stage = Staging(s.out, output_names(s))
    try:
        report = _render_into(s, stage, log, progress or (lambda stage: None), profiler, extra)
        stage.commit()
    except BaseException:
        stage.abort()
        raise
    return report


def _render_into(s: Settings, stage: Staging, log, step, profiler, extra) -> dict:
    name = s.scene.name
    sidecar = len(s.scene.vertices) > SIDECAR_VERTICES
    frames_dir = None
    if "png" in s.formats or "ascii" in s.formats:
        frames_dir = stage.path(f"{name}-frames")
        frames_dir.mkdir()
        (frames_dir / output.MARKER).write_bytes(b"")
    records = []
    sidecar_names = [f"{name}-vertices_px.npy", f"{name}-vertices_px-orthographic.npy"]
    all_px = [None for _ in s.cameras]  # the sidecars, filled frame by frame (memory flat in the frame count)
    t_start = time.perf_counter()
    render_seconds = 0.0
    renderer = s.scene_renderer()
    layers = [s.axis_layers(cam) for cam in s.cameras] if s.axes else None
    lap = profiler.lap if profiler is not None else (lambda stage, t: 0.0)
    with contextlib.ExitStack() as files:
        mp4 = gif = png_writer = None
        # PNG frames by a second process (--profile times them in line), forked before the encoders open
        if frames_dir is not None and "png" in s.formats and profiler is None and can_fork(s.frames):
            png_writer = files.enter_context(ForkedPngWriter())
        if "mp4" in s.formats:
            mp4 = output.Mp4Writer(files.enter_context(open(stage.path(f"{name}.mp4"), "wb")), FPS)
        if "gif" in s.formats:
            gif = GifWriter(
                files.enter_context(open(stage.path(f"{name}.gif"), "wb")), FPS, progress=lambda: step("gif")
            )
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
                img = picture(frame, s.style)
                if layers and frame.tri_ids is not None:  # faces in a depth buffer: axes depth-tested
                    pictures.append(overlay(img, s.axis_layers(cam, frame)))
                else:
                    pictures.append(overlay(img, layers[c]) if layers else img)
                recs.append(frame_record(k, frame, sidecar, info))
                if sidecar:
                    if all_px[c] is None:  # the bytes np.save writes, one frame at a time
                        all_px[c] = files.enter_context(open(stage.path(sidecar_names[c]), "wb"))
                        np.lib.format.write_array_header_1_0(
                            all_px[c],
                            {
                                "descr": np.lib.format.dtype_to_descr(frame.p_px.dtype),
                                "fortran_order": False,
                                "shape": (s.frames, *frame.p_px.shape),
                            },
                        )
                    all_px[c].write(np.ascontiguousarray(frame.p_px).tobytes())
                if c == 0:
                    first = (frame, info)
                lap("compose", t)
            t = time.perf_counter()
            rec = recs[0]
            if len(recs) > 1:
                rec["orthographic"] = {key: v for key, v in recs[1].items() if key != "frame"}
            image = pictures[0] if len(pictures) == 1 else side_by_side(*pictures)
            t = lap("compose", t)
            for fmt, encode in (
                ("png", output.png_bytes),
                ("ascii", lambda im: output.ascii_frame(im, s.ascii_cols).encode()),
            ):
                if fmt == "png" and png_writer is not None:
                    png_writer.put(frames_dir / f"frame_{k:04d}.png", image)
                elif frames_dir is not None and fmt in s.formats:
                    data = encode(image)
                    t = lap("encode", t)
                    output.write_file(frames_dir / f"frame_{k:04d}.{'png' if fmt == 'png' else 'txt'}", data)
                    t = lap("write", t)
            if mp4 is not None:
                mp4.add(image)
                t = lap("encode", t)
            if gif is not None:
                gif.add(image)
                t = lap("encode", t)
            records.append(rec)
            if profiler is not None:
                profiler.end()
            if log:
                log(k, *first)
            step("render")
        if png_writer is not None:
            png_writer.close()
        if mp4 is not None:
            mp4.commit()
            step("mp4")
        if gif is not None:
            gif.close()
    report = run_report(s, records)
    report.update(extra or {})
    if profiler is not None:
        report["profile"] = profiler.summary()
    if sidecar:
        report["vertices_px_file"] = sidecar_names[0]
        if s.ortho_camera is not None:
            report["vertices_px_file_orthographic"] = sidecar_names[1]
    plot_seconds = None
    if s.plots:
        t0 = time.perf_counter()
        cam_text = "perspective (left picture)" if s.ortho_camera is not None else s.camera.projection
        stage.path(f"{name}-plots.png").write_bytes(plot_png(records, f"{name}: {s.frames} frames, {cam_text} camera"))
        plot_seconds = time.perf_counter() - t0
    stage.path(f"{name}-report.json").write_text(output.json_dumps(report), encoding="utf-8")
    wall = time.perf_counter() - t_start
    stage.path(f"{name}-report.txt").write_text(
        summary_text(report, render_seconds, wall, plot_seconds), encoding="utf-8", errors="backslashreplace"
    )  # a non-UTF-8 path
    out = s.out
    report["_paths"] = {
        "frames": out / f"{name}-frames" if frames_dir else None,
        "json": out / f"{name}-report.json",
        "txt": out / f"{name}-report.txt",
        "gif": out / f"{name}.gif" if gif is not None else None,
        "mp4": out / f"{name}.mp4" if mp4 is not None else None,
        "plots": out / f"{name}-plots.png" if s.plots else None,
    }
    return report


def _check_overflow(s: Settings, frame, k: int) -> None:
    overflow = frame.visible & ~np.isfinite(frame.p_px).all(axis=1)
    if overflow.any():
        i = int(np.flatnonzero(overflow)[0])
        raise InputError(
            f"{s.scene.source}: vertex {i} {s.scene.vertices[i].tolist()} projects beyond the {s.dtype} "
            f"range in frame {k}: expected coordinates whose pixel position fits in a {s.dtype} "
            f"(|f * x / z| < {float(np.finfo(s.dtype).max):.2g})"
        )
