"""``crosscheck --sweep``: every core setting, its cost and its accuracy, in one run.

The settings are dtype x clip mode x raster mode (2 x 2 x 3 = 12). Each is run
on the bundled scenes and on a large mesh (an icosphere) under every case
camera (oracles/cases.py). The oracles' answers do not depend on the setting,
so each frame's references are computed once and shared:

* OpenCV's ``projectPoints`` of the frame's world points (vertex reference);
* pyrender/OSMesa's rendering of the edges (pixel reference).

For each setting we record

* ``ms_per_frame``: median time of ``core.projector.pipeline.render_frame`` per frame,
  split by scene group ("bundled" scenes and the "large" mesh), each frame set
  up by :class:`core.scene.frames.SceneRenderer` as ``renderer`` sets it up;
* ``max_vertex_error_px`` against OpenCV (over all frames and cases);
* ``pixel_f1_0px`` / ``pixel_f1_1px``: the minimum over frames of the
  edge-pixel F1 against pyrender, and their means.

A setting is on the **Pareto front** when no other setting is at least as
fast *and* at least as accurate (on both the vertex error and F1@0px) and
strictly better on one.

Timings live under each row's ``timing`` key and in the plot only: the rest of
``sweep.json`` is identical run to run.
"""

from __future__ import annotations

import itertools
import statistics
import time
from collections import namedtuple

import numpy as np
from wirecheck.core.outputs.output import FrameDir, json_dumps
from wirecheck.core.projector.clipping import CLIP_MODES
from wirecheck.core.projector.pipeline import render_frame
from wirecheck.core.projector.projection import DTYPES
from wirecheck.core.projector.raster import RASTER_MODES
from wirecheck.core.scene.frames import SceneRenderer
from wirecheck.core.scene.model import Scene, face_edges, unique_edges
from wirecheck.core.transforms import Motion

from .cases import CASE_NAMES, case_motion, cases_for
from .judge import metrics
from .references import faces as oface
from .references import opencv_oracle
from .references.pyrender_oracle import OracleCache
from .reports.report import gl_text

#: The default setting, the one crosscheck gates on.
DEFAULT = ("float64", "clip", "exact")


class Setting(namedtuple("Setting", "dtype clip raster")):
    """One setting of core: its dtype, clip mode and raster mode."""

    @property
    def key(self) -> str:
        return f"{self.dtype}/{self.clip}/{self.raster}"


def all_settings() -> list[Setting]:
    return [Setting(d, c, r) for d, c, r in itertools.product(DTYPES, CLIP_MODES, RASTER_MODES)]


def large_mesh(subdivisions: int = 5) -> Scene:
    """An icosphere of radius 1: 10,242 vertices and 30,720 edges at 5 subdivisions."""
    import trimesh

    mesh = trimesh.creation.icosphere(subdivisions=subdivisions, radius=1.0)
    faces = np.asarray(mesh.faces)
    edges = unique_edges(face_edges(faces))
    return Scene(
        name=f"icosphere{subdivisions}",
        vertices=np.array(mesh.vertices, dtype=np.float64),
        edges=edges,
        source=f"trimesh.creation.icosphere(subdivisions={subdivisions})",
    )


def _pareto(rows: list[dict]) -> None:
    """Mark rows on the front of (time on the large mesh, vertex error, -F1@0px)."""

    def cost(r):
        return (r["timing"]["ms_per_frame_large"], r["max_vertex_error_px"], -r["pixel_f1_0px"])

    for r in rows:
        c = cost(r)
        r["timing"]["pareto"] = not any(
            all(a <= b for a, b in zip(cost(o), c)) and any(a < b for a, b in zip(cost(o), c))
            for o in rows
            if o is not r
        )


def run_sweep(
    scenes: list[Scene],
    frames: int = 12,
    every: int = 1,
    case_names=None,
    turns=(1.0, 1.0, 0.0),
    large: Scene | None = None,
    pyrender: bool = True,
    repeats: int = 3,
    progress=None,
) -> dict:
    """Run every setting; return the sweep report (see the module docstring)."""
    settings = all_settings()
    groups = [("bundled", s) for s in scenes] + ([("large", large)] if large is not None else [])
    motion = Motion(turns=tuple(float(x) for x in turns))
    frame_ids = list(range(1, frames + 1, every))
    acc = {
        s.key: {"err": [], "f1_0": [], "f1_1": [], "t": {"bundled": [], "large": []}, "cand_only": 0, "orac_only": 0}
        for s in settings
    }
    oracles = OracleCache()
    try:
        for group, scene in groups:
            edges = np.asarray(scene.edges)
            cases = cases_for(scene, motion, calibrated=True)
            scene_motion = case_motion(motion, cases[0])  # one framing, one pivot per scene
            core = {
                d: SceneRenderer(scene, scene_motion, frames, dtype=d) for d in DTYPES
            }  # as renderer sets frames up
            for case in cases:
                if case.name not in (CASE_NAMES if case_names is None else case_names):
                    continue
                cam = case.camera
                pyr = None
                if pyrender and cam.distortion is None:  # a lens: vertices only (oracles.judge.case)
                    pyr = oracles.get(cam.width, cam.height)
                for k in frame_ids:
                    p_world, _, pr_vertices, pr_pose = oface.frame_geometry(scene, scene_motion, (k - 1) / frames)
                    ref_img = pyr.render(pr_vertices, edges, cam, model_matrix=pr_pose)[0] if pyr else None
                    ref_px = opencv_oracle.project(p_world, cam)
                    for s in settings:
                        a = acc[s.key]
                        best = np.inf
                        for _ in range(repeats):
                            t0 = time.perf_counter()
                            points, m = core[s.dtype].geometry(k)
                            frame = render_frame(points, edges, cam, m, s.clip, raster=s.raster)
                            best = min(best, time.perf_counter() - t0)
                        a["t"][group].append(best)
                        ve = metrics.vertex_errors(frame.p_px, ref_px)
                        if ve["max_px"] is not None:
                            a["err"].append(ve["max_px"])
                        a["cand_only"] += ve["candidate_only"]
                        a["orac_only"] += ve["oracle_only"]
                        if ref_img is not None:
                            ps = metrics.pixel_scores(frame.mask, ref_img)
                            a["f1_0"].append(ps["f1_0px"])
                            a["f1_1"].append(ps["f1_1px"])
                if progress:
                    progress(f"{scene.name}/{case.name}")
        gl = oracles.gl_info()
    finally:
        oracles.close()

    rows = []
    for s in settings:
        a = acc[s.key]
        row = {
            "setting": s.key,
            "dtype": s.dtype,
            "clip": s.clip,
            "raster": s.raster,
            "default": (s.dtype, s.clip, s.raster) == DEFAULT,
            "max_vertex_error_px": max(a["err"]) if a["err"] else None,
            "visibility_mismatches": a["cand_only"] + a["orac_only"],
            "pixel_f1_0px": min(a["f1_0"]) if a["f1_0"] else None,
            "pixel_f1_1px": min(a["f1_1"]) if a["f1_1"] else None,
            "pixel_f1_0px_mean": float(np.mean(a["f1_0"])) if a["f1_0"] else None,
            "pixel_f1_1px_mean": float(np.mean(a["f1_1"])) if a["f1_1"] else None,
            "timing": {
                "ms_per_frame_bundled": 1e3 * statistics.median(a["t"]["bundled"]) if a["t"]["bundled"] else None,
                "ms_per_frame_large": 1e3 * statistics.median(a["t"]["large"]) if a["t"]["large"] else None,
            },
        }
        rows.append(row)
    if pyrender and large is not None:
        _pareto(rows)
    return {
        "tool": "wirecheck crosscheck --sweep",
        "scenes": [s.name for s in scenes],
        "large_mesh": None
        if large is None
        else {
            "name": large.name,
            "source": large.source,
            "vertices": int(len(large.vertices)),
            "edges": int(len(large.edges)),
        },
        "cases": list(case_names) if case_names is not None else list(CASE_NAMES),
        "frames": frames,
        "every": every,
        "frames_checked": len(frame_ids),
        "motion": {"turns": list(motion.turns)},
        "oracles": ["opencv"] + (["pyrender"] if pyrender else []),
        "oracle_gl": gl,
        "timing_method": f"min of {repeats} calls of render_frame per frame, median over frames",
        "settings": rows,
    }


# ---- output ------------------------------------------------------------------


def _e(v) -> str:
    return "-" if v is None else f"{v:.2g}"


def _f(v) -> str:
    return "-" if v is None else f"{v:.4f}"


def _ms(v) -> str:
    return "-" if v is None else f"{v:.2f}"


def markdown_table(sweep: dict) -> str:
    big = sweep["large_mesh"]
    head = (
        "| setting (dtype/clip/raster) | ms/frame bundled | ms/frame "
        f"{big['name'] if big else 'large'} | max vertex error px | F1@0px min | F1@1px min | Pareto |"
    )
    lines = [head, "|---|---:|---:|---:|---:|---:|:---:|"]
    for r in sweep["settings"]:
        name = f"**{r['setting']}** (default)" if r["default"] else r["setting"]
        t = r["timing"]
        lines.append(
            f"| {name} | {_ms(t['ms_per_frame_bundled'])} | {_ms(t['ms_per_frame_large'])} | "
            f"{_e(r['max_vertex_error_px'])} | {_f(r['pixel_f1_0px'])} | {_f(r['pixel_f1_1px'])} | "
            f"{'yes' if t.get('pareto') else ''} |"
        )
    return "\n".join(lines) + "\n"


def markdown(sweep: dict) -> str:
    big = sweep["large_mesh"]
    out = [
        "# wirecheck speed/accuracy sweep",
        "",
        f"Scenes: {', '.join(sweep['scenes'])}"
        + (f"; large mesh: {big['name']} ({big['vertices']:,} vertices, {big['edges']:,} edges)" if big else ""),
        f"Cases: {', '.join(sweep['cases'])}; frames {sweep['frames_checked']} of {sweep['frames']} "
        f"(every {sweep['every']}); oracles: {', '.join(sweep['oracles'])}.",
        f"Timing: {sweep['timing_method']}.",
        "",
        *([f"Oracle GL: {gl_text(sweep)}.", ""] if gl_text(sweep) else []),
        markdown_table(sweep),
        "",
        "![Pareto plot](sweep.png)",
        "",
    ]
    return "\n".join(out)


def plot_png(sweep: dict, path) -> None:
    """Two panels against time per frame on the large mesh: max vertex error (log) and F1@0px."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = [r for r in sweep["settings"] if r["timing"]["ms_per_frame_large"] is not None]
    if not rows:
        rows = sweep["settings"]
        xkey, xlabel = "ms_per_frame_bundled", "ms per frame (bundled scenes)"
    else:
        big = sweep["large_mesh"]["name"]
        xkey, xlabel = "ms_per_frame_large", f"ms per frame ({big})"
    markers = {"exact": "o", "fast": "s", "aa": "^"}
    colours = {"float64": "tab:blue", "float32": "tab:orange"}
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2), dpi=100)
    panels = [
        ("max_vertex_error_px", "max vertex error vs OpenCV (px, log)", True),
        ("pixel_f1_0px", "edge-pixel F1@0px vs pyrender (min over frames)", False),
    ]
    for ax, (key, ylabel, log) in zip(axes, panels):
        pts = []
        for r in rows:
            x, y = r["timing"][xkey], r[key]
            if y is None:
                continue
            if log:
                y = max(y, 1e-16)
            hollow = r["clip"] == "endpoint"
            ax.scatter(
                [x],
                [y],
                marker=markers[r["raster"]],
                s=60,
                facecolors="none" if hollow else colours[r["dtype"]],
                edgecolors=colours[r["dtype"]],
                linewidths=1.5,
                zorder=3,
            )
            pts.append((x, y, r))
        # This panel's own 2-D front: no other point is as fast and as good on this metric.
        better = (lambda a, b: a <= b) if log else (lambda a, b: a >= b)
        front = sorted(
            (
                p
                for p in pts
                if not any(o[0] <= p[0] and better(o[1], p[1]) and (o[0] < p[0] or o[1] != p[1]) for o in pts)
            ),
            key=lambda p: p[0],
        )
        if front:
            ax.step([p[0] for p in front], [p[1] for p in front], "k--", where="post", lw=0.8, zorder=2)
        for x, y, r in pts:
            if r["default"]:
                ax.annotate("default", (x, y), textcoords="offset points", xytext=(6, 6), fontsize=8)
        if log:
            ax.set_yscale("log")
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
        ax.grid(True, alpha=0.3)
    from matplotlib.lines import Line2D

    legend = (
        [Line2D([], [], marker=m, ls="", color="grey", label=f"raster {k}") for k, m in markers.items()]
        + [Line2D([], [], marker="o", ls="", color=c, label=k) for k, c in colours.items()]
        + [
            Line2D([], [], marker="o", ls="", mfc="none", color="grey", label="clip endpoint"),
            Line2D([], [], ls="--", color="k", label="Pareto front"),
        ]
    )
    axes[1].legend(handles=legend, fontsize=8, loc="lower right")
    fig.suptitle("wirecheck: speed against accuracy, every dtype x clip x raster setting")
    fig.tight_layout()
    fig.savefig(path, format="png", metadata={"Software": None})
    plt.close(fig)


def html(sweep: dict) -> str:
    import html as _h

    rows = []
    for r in sweep["settings"]:
        t = r["timing"]
        rows.append(
            "<tr>"
            + "".join(
                f"<td>{_h.escape(str(v))}</td>"
                for v in (
                    r["setting"] + (" (default)" if r["default"] else ""),
                    _ms(t["ms_per_frame_bundled"]),
                    _ms(t["ms_per_frame_large"]),
                    _e(r["max_vertex_error_px"]),
                    _f(r["pixel_f1_0px"]),
                    _f(r["pixel_f1_1px"]),
                    "yes" if t.get("pareto") else "",
                )
            )
            + "</tr>"
        )
    big = sweep["large_mesh"]
    return (
        "<!doctype html><meta charset='utf-8'><title>wirecheck sweep</title>"
        "<style>body{font-family:sans-serif;margin:2em}td,th{padding:2px 8px;text-align:right}"
        "td:first-child{text-align:left}</style>"
        "<h1>wirecheck speed/accuracy sweep</h1>"
        f"<p>Scenes: {_h.escape(', '.join(sweep['scenes']))}"
        + (
            f"; large mesh: {_h.escape(big['name'])} ({big['vertices']:,} vertices, {big['edges']:,} edges)"
            if big
            else ""
        )
        + f". Cases: {_h.escape(', '.join(sweep['cases']))}. Frames checked: {sweep['frames_checked']}.</p>"
        "<table><tr><th>setting</th><th>ms/frame bundled</th><th>ms/frame large</th>"
        "<th>max vertex error px</th><th>F1@0px min</th><th>F1@1px min</th><th>Pareto</th></tr>"
        + "".join(rows)
        + "</table><p><img src='sweep.png' alt='Pareto plot'></p>\n"
    )


def write_sweep(run_dir, sweep: dict) -> None:
    """``sweep.json`` (timings under each row's ``timing``), ``sweep.md``, ``sweep.html``, ``sweep.png``; atomic."""
    import tempfile
    from pathlib import Path

    run_dir = Path(run_dir)
    run_dir.parent.mkdir(parents=True, exist_ok=True)
    out = FrameDir(run_dir, "--report-dir")
    try:
        out.write("sweep.json", json_dumps(sweep).encode())
        out.write("sweep.md", markdown(sweep).encode())
        out.write("sweep.html", html(sweep).encode())
        with tempfile.TemporaryDirectory() as tmp:
            png = Path(tmp) / "sweep.png"
            plot_png(sweep, png)
            out.write("sweep.png", png.read_bytes())
        out.commit()
    except BaseException:
        out.abort()
        raise


def default_failures(sweep: dict, vertex_px: float, min_f1_1px: float, min_f1_0px: float) -> list[str]:
    """Why the default setting is out of tolerance (empty when it is within)."""
    d = next(r for r in sweep["settings"] if r["default"])
    reasons = []
    if d["max_vertex_error_px"] is None:  # a gate never passes on nothing (oracles.judge.gate)
        reasons.append("no vertex was compared (every point clipped in every case)")
    if d["max_vertex_error_px"] is not None and d["max_vertex_error_px"] > vertex_px:
        reasons.append(f"max vertex error {d['max_vertex_error_px']:.3g} px > {vertex_px:g}")
    if d["visibility_mismatches"]:
        reasons.append(f"{d['visibility_mismatches']} points clipped by one side only")
    if d["pixel_f1_1px"] is not None and d["pixel_f1_1px"] < min_f1_1px:
        reasons.append(f"F1@1px {d['pixel_f1_1px']:.4f} < {min_f1_1px}")
    if d["pixel_f1_0px"] is not None and d["pixel_f1_0px"] < min_f1_0px:
        reasons.append(f"F1@0px {d['pixel_f1_0px']:.4f} < {min_f1_0px}")
    return reasons
