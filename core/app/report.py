"""A renderer run's report: one record per frame, the report dict (``<scene>-report.json``) and its text.

Everything but the timing lines of :func:`summary_text` is deterministic: the
same run gives the same report.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .compose import axis_length

if TYPE_CHECKING:
    from ..projector.pipeline import Frame
    from .settings import Settings


def frame_record(k: int, frame: Frame, sidecar: bool, info: dict | None = None) -> dict:
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
        rec["vertices_px"] = [
            None if not v else [float(x), float(y)] for (x, y), v in zip(frame.p_px.tolist(), frame.visible.tolist())
        ]
    return rec


def depth_text(frame: Frame) -> str:
    """``depth=[min, max]`` of the visible vertices, 2 decimals (``depth=[none]``: none visible)."""
    rng = frame.depth_range
    return "depth=[none]" if rng is None else f"depth=[{rng[0]:.2f}, {rng[1]:.2f}]"


def run_report(s: Settings, records: list[dict]) -> dict:
    """The report dict of a run: scene, cameras, motion, settings, summary and the frame ``records``."""
    sc = s.scene
    depths = [(r["min_depth"], r["max_depth"]) for r in records if r["min_depth"] is not None]
    scene = {
        "name": sc.name,
        "source": sc.source,
        "vertices": int(len(sc.vertices)),
        "edges": int(len(sc.edges)),
        "faces": len(sc.faces),
        "objects": [
            {
                "name": o.name,
                "vertices": o.vertex_count,
                "spin": list(o.motion.turns),
                "translate": list(o.motion.offset),
                "scale": o.motion.scale,
            }
            for o in sc.objects
        ],
    }
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
            summary[key] = sum(r[key] or 0 for r in records)  # total over the run
    report = {
        "scene": scene,
        "camera": s.camera.to_dict(),
    }
    if s.ortho_camera is not None:
        report["camera_orthographic"] = s.ortho_camera.to_dict()
    report.update(
        {
            "motion": {
                "turns": list(s.motion.turns),
                "translate": list(s.motion.offset),
                "scale": s.motion.scale,
                "frames": s.frames,
            },
            "clip": s.clip,
            "dtype": s.dtype,
            "raster": s.raster,
            "drawing": {
                "projection": "both" if s.ortho_camera is not None else s.camera.projection,
                "axes": s.axes,
                "axis_length": axis_length(s.scene.radius, s.motion.scale) if s.axes else None,
                "cull": s.cull,
                "hidden_lines": s.hidden_lines,
                "style": s.style,
                "light": None if s.light is None else list(s.light),
                "object_culling": s.object_culling,
            },
            "summary": summary,
            "frames": records,
        }
    )
    return report


#: Optional per-frame columns of the text report: (key, header).
_EXTRA_COLUMNS = (
    ("objects_culled", "objects_culled"),
    ("faces_total", "faces"),
    ("faces_culled", "faces_culled"),
    ("hidden_pixels", "hidden_pixels"),
)


def summary_text(report: dict, render_seconds: float, wall_seconds: float, plot_seconds=None) -> str:
    """``<scene>-report.txt``: the run's settings, a table of the frames, then the timings."""
    sc, cam, sm = report["scene"], report["camera"], report["summary"]
    lines = [
        f"Scene: {sc['name']} ({sc['vertices']} vertices, {sc['edges']} edges) from {sc['source']}",
    ]
    if len(sc["objects"]) > 1:
        lines.append(
            f"Objects: {len(sc['objects'])}: "
            + ", ".join(
                f"{o['name']} ({o['vertices']} vertices, spin {o['spin']}, translate {o['translate']}, "
                f"scale {o['scale']})"
                for o in sc["objects"]
            )
        )
    cams = [("Camera", cam)] + (
        [("Right camera", report["camera_orthographic"])] if "camera_orthographic" in report else []
    )
    for label, c in cams:
        pad = " " * len(label)
        lines += [
            f"{label}: {c['projection']} at {c['position']} forward {[round(v, 6) for v in c['forward']]} "
            f"up {[round(v, 6) for v in c['up']]}",
            f"{pad}  fov_y={c['fov_y_deg']} deg, {c['width']}x{c['height']}, near={c['near']}, far={c['far']}"
            + (f", ortho_height={c['ortho_height']:.6g}" if c["projection"] == "orthographic" else "")
            + (f", intrinsics fx,fy,cx,cy={c['intrinsics']}" if c.get("intrinsics") else "")
            + (f", distortion={c['distortion']} (vertices only)" if c.get("distortion") else ""),
        ]
    dr = report["drawing"]
    lines += [
        f"Motion: turns={report['motion']['turns']} translate={report['motion']['translate']} scale={report['motion']['scale']}",
        f"Clip mode: {report['clip']}, dtype: {report['dtype']}, raster: {report['raster']}",
        f"Drawing: projection={dr['projection']} axes={'on' if dr['axes'] else 'off'} cull={dr['cull'] or 'none'} "
        f"hidden_lines={'on' if dr['hidden_lines'] else 'off'} style={dr['style']}"
        + (f" light={dr['light']}" if dr["light"] else ""),
        f"Frames: {sm['frames']} ({sm['frames_with_clipping']} with clipping)",
        "Depth over the run: "
        + ("none visible" if sm["min_depth"] is None else f"[{sm['min_depth']:.4f}, {sm['max_depth']:.4f}]"),
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
        lines.append(
            f"{r['frame']:>5}  {r['visible_vertices']:>7}  {r['clipped']:>7}  {r['clipped_edges']:>13}  "
            f"{dmin:>9}  {dmax:>9}{cells}"
        )
    lines += [
        "",
        "Timing (varies run to run; everything above is deterministic):",
        f"  projection + raster: {1e3 * render_seconds / max(sm['frames'], 1):.3f} ms/frame"
        + (" (both cameras)" if "camera_orthographic" in report else ""),
        f"  wall time incl. export: {wall_seconds:.3f} s",
    ]
    if plot_seconds is not None:
        lines.append(f"  plots (matplotlib): {plot_seconds:.3f} s")
    return "\n".join(lines) + "\n"
