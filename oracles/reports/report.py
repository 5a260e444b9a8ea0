"""report.json, report.md and report.html for a crosscheck run; atomic.

The run directory is filled under a temporary name and renamed at the end,
so a directory called ``reports/<run>`` is always complete. Timings live only
under the top-level ``"timing"`` key of report.json and in report.html;
everything else, report.md included, is deterministic (the same for any
``--jobs``), and so are the figures (oracles.reports.plots): ``vertex_error.png``
(per-frame vertex error of every case), ``pixels.png`` (per-frame F1@0px, or
silhouette IoU and depth error / bound when shaded) and ``worst.gif`` (every
checked frame of the worst case: candidate | oracle | diff).
"""

from __future__ import annotations

import html
import math
from pathlib import Path

import numpy as np

from wirecheck.core.outputs.output import FrameDir, json_dumps, png_bytes

from .fault_text import FULL_DIGITS, case_cell, full_text, hints, notes
from ..judge.metrics import DIFF_COLOURS, diff_image
from .report_crops import crop_caption, crop_image
from ..judge.line_style import summary_lines
from . import plots
from .points_plot import points_png


def _fmt_err(v) -> str:
    return "-" if v is None else f"{v:.2e}"


def _fmt_f1(v) -> str:
    return "-" if v is None else f"{v:.4f}"


def _count(n: int, unit: str) -> str:
    return f"{n:,} {unit}" + ("" if n == 1 else "s")


def compared_text(report: dict) -> str:
    """How much a run compared, e.g. "504 frames, 4,032 vertices, 1,234,567 pixels compared"."""
    c = report["compared"]
    parts = [_count(c["frames"], "frame"), f"{c['vertices']:,} {'vertex' if c['vertices'] == 1 else 'vertices'}"]
    if c.get("pixels") is not None:
        parts.append(_count(c["pixels"], "pixel"))
    return ", ".join(parts) + " compared"


def vacuous_text(report: dict) -> str:
    """"" or, when cases compared nothing, how many and whether that was allowed."""
    n = report["summary"].get("vacuous", 0)
    if not n:
        return ""
    allowed = "allowed by --allow-vacuous" if report.get("allow_vacuous") else "a failure unless --allow-vacuous"
    return f"{_count(n, 'case')} vacuous (compared nothing: {allowed})"


def not_passed(report: dict) -> list[dict]:
    """The cases that make the run fail: failed ones, and vacuous ones unless allowed."""
    allowed = ("pass", "vacuous") if report.get("allow_vacuous") else ("pass",)
    return [c for c in report["cases"] if c["verdict"] not in allowed]


def _is_shaded(cases: list[dict]) -> bool:
    return any("silhouette_iou" in c for c in cases)


def _fmt_ratio(v) -> str:
    return "-" if v is None else f"{v:.3g}"


def _pixel_f1(case: dict, key: str) -> str:
    """An F1 for the table; "-" when no pixel was drawn by either side (two blank frames score 1.0)."""
    return "-" if (case.get("compared") or {}).get("pixels") == 0 else _fmt_f1(case.get(key))


def _has_surfaces(cases: list[dict]) -> bool:
    """Whether a frames job's cases hold depth maps or filled frames (oracles.judge.depth_frames, filled_frames)."""
    return any("depth_map" in c or "filled" in c for c in cases)


def _surface_count(case: dict, key: str) -> str:
    """Holes or extra pixels of a case's depth maps and filled frames, summed; "-" when it has neither."""
    parts = [case[k][key] for k in ("depth_map", "filled") if k in case]
    return f"{sum(parts):,}" if parts else "-"


def table_rows(cases: list[dict]) -> list[list[str]]:
    if _has_surfaces(cases):
        return [[c["scene"], c["camera"], _pixel_f1(c, "pixel_f1_0px") if "pixel_f1_0px" in c else "-",
                 _pixel_f1(c, "pixel_f1_1px") if "pixel_f1_1px" in c else "-",
                 _fmt_f1((c.get("filled") or {}).get("min_iou")),
                 _fmt_ratio((c.get("depth_map") or {}).get("max_error_ratio")),
                 _surface_count(c, "holes_px"), _surface_count(c, "extra_px"), c["verdict"],
                 case_cell(c["faults"], c.get("camera_spec"))] for c in cases]
    if _is_shaded(cases):
        return [[c["scene"], c["camera"], _fmt_err(c.get("max_vertex_error_px")), _fmt_f1(c.get("silhouette_iou")),
                 _fmt_err(c.get("depth_max_error")), _fmt_ratio(c.get("depth_error_ratio")), c["verdict"],
                 case_cell(c["faults"], c.get("camera_spec"))] for c in cases]
    return [[c["scene"], c["camera"], _fmt_err(c.get("max_vertex_error_px")), _pixel_f1(c, "pixel_f1_0px"),
             _pixel_f1(c, "pixel_f1_1px"), c["verdict"], case_cell(c["faults"], c.get("camera_spec"))]
            for c in cases]


HEADER = ["scene", "camera", "max vertex err (px)", "F1@0px", "F1@1px", "verdict", "faults"]
SHADED_HEADER = ["scene", "camera", "max vertex err (px)", "silhouette IoU", "max depth err", "depth err / bound",
                 "verdict", "faults"]


SURFACES_HEADER = ["scene", "camera", "F1@0px", "F1@1px", "filled IoU", "depth err / bound", "holes", "extra",
                   "verdict", "faults"]


def header(cases: list[dict]) -> list[str]:
    if _has_surfaces(cases):
        return SURFACES_HEADER
    return SHADED_HEADER if _is_shaded(cases) else HEADER


def console_table(cases: list[dict]) -> str:
    head = header(cases)
    rows = [head] + table_rows(cases)
    widths = [max(len(r[i]) for r in rows) for i in range(len(head) - 1)]
    lines = []
    for r in rows:
        lines.append("  ".join(r[i].ljust(widths[i]) for i in range(len(widths))) + "  " + r[-1])
    return "\n".join(lines)


LEVEL_TEXT = {
    "vertices": "the candidate's vertex pixels against OpenCV only (nothing drawn, no pyrender)",
    "pixels": "vertex pixels against OpenCV, and drawn frames against pyrender",
}


def level_text(report: dict) -> str:
    level = report.get("level", "pixels")
    return f"{level} ({LEVEL_TEXT[level]})" if level in LEVEL_TEXT else str(level)


def frames_text(report: dict) -> str:
    frames, every = report["frames"], report.get("every", 1)
    if every == 1:
        return f"all {frames} frames of the motion"
    checked = list(range(1, frames + 1, every))
    shown = ", ".join(map(str, checked)) if len(checked) <= 4 else ", ".join(map(str, checked[:3])) + ", ..."
    return f"{len(checked)} of {frames} frames of the motion (frames {shown}: every {every})"


def settings_text(report: dict) -> str:
    settings = report.get("candidate_settings")
    return ", ".join(f"{k} = {v}" for k, v in settings.items()) if settings else ""


def drawing_text(report: dict) -> str:
    """The drawing mode in one sentence (style, hidden lines, culling)."""
    style = report.get("style", "wireframe")
    if report.get("level") == "vertices":
        return "nothing drawn (level vertices)"
    if style == "shaded":
        what = ("shaded faces: core's depth buffer against pyrender's (flat, unlit), "
                "silhouette IoU and depth error")
    elif report.get("hidden_lines"):
        what = "wireframe with hidden lines (pyrender: faces black with glPolygonOffset(1, 1), lines on top)"
    else:
        what = "wireframe"
    cull = report.get("cull", "none")
    cull_text = ("back faces culled (GL back-face culling in pyrender; the oracle's own front-face test "
                 "picks the edges)" if cull == "backface" else "no culling")
    return (f"style = {style}, hidden_lines = {str(bool(report.get('hidden_lines'))).lower()}, cull = {cull}: "
            f"{what}; {cull_text}")


def gl_text(report: dict) -> str | None:
    """The GL that drew the oracle's frames, in one line (None when pyrender did not run)."""
    gl = report.get("oracle_gl")
    if not gl:
        return None
    buffers = "single-sample buffers" if gl["samples"] == 0 else f"{gl['samples']}x multisample buffers"
    return f"pyrender on {gl['platform']}: {gl['vendor']}, {gl['renderer']}, OpenGL {gl['version']}, {buffers}"


def _figures(report: dict, files: set) -> list[tuple[str, str]]:
    """(file, caption) of the figures written beside the report."""
    out = []
    if "vertex_error.png" in files:
        out.append(("vertex_error.png", "per-frame max vertex error of every case (log scale)"))
    if "worst_points.png" in files:
        out.append(("worst_points.png", "the worst case's frame: the candidate's points (x) over OpenCV's (o), "
                    "the worst vertex ringed"))
    if "pixels.png" in files:
        out.append(("pixels.png", "per-frame silhouette IoU and depth error / bound of every case"
                    if report.get("style") == "shaded" else "per-frame F1@0px of every case"))
    return out


def _worst_text(report: dict) -> str | None:
    w = report.get("worst_case")
    if not w:
        return None
    return (f"{w['scene']} / {w['camera']}, all {w['frames_checked']} checked frames "
            "(candidate | oracle | diff; the bar under them is the frame's place in the run)")


def _fmt_wall(v, spec: str) -> str:
    """Wall seconds, '-' when not a finite number (null in report.json)."""
    return "-" if v is None or not math.isfinite(v) else format(v, spec)


def _fmt_ms(v) -> str:
    return "-" if v is None else f"{v:.3g}"


def timing_rows(report: dict) -> list[list[str]]:
    """Rows of ``[scene, camera, vertex stage ms/frame, pixel stage ms/frame]``, then the overall row."""
    timing = report.get("timing") or {}
    rows = [[t["scene"], t["camera"], _fmt_ms(t.get("vertex_stage_ms_per_frame")),
             _fmt_ms(t.get("pixel_stage_ms_per_frame"))] for t in timing.get("cases", [])]
    rows.append(["all cases", "", _fmt_ms(timing.get("vertex_stage_ms_per_frame")),
                 _fmt_ms(timing.get("pixel_stage_ms_per_frame"))])
    return rows


TIMING_HEADER = ["scene", "camera", "vertex stage (ms/frame)", "pixel stage (ms/frame)"]


def timing_line(report: dict) -> str:
    """One console line: each level's time per frame, jobs and wall time."""
    t = report.get("timing") or {}
    parts = [f"vertex stage {_fmt_ms(t.get('vertex_stage_ms_per_frame'))} ms/frame"]
    if t.get("pixel_stage_ms_per_frame") is not None:
        parts.append(f"pixel stage {_fmt_ms(t.get('pixel_stage_ms_per_frame'))} ms/frame")
    return (f"Level {report.get('level', 'pixels')}: " + ", ".join(parts)
            + f" ({t.get('jobs', 1)} job(s), {_fmt_wall(t.get('wall_s', 0.0), '.1f')} s wall)")


def precision_text(report: dict) -> str:
    """"float32 (returned); vertex bound 1.15e-03 to 2.70e-03 px": what the candidate was judged as (oracles.tolerances)."""
    cases = [c for c in report["cases"] if c.get("precision")]
    if not cases:
        return ""
    def one(p: dict) -> str:
        other = [r for r in p.get("returned") or [] if r != p["judged_as"]]
        return f"{p['judged_as']} ({p['source']}" + (f"; returned {', '.join(other)})" if other else ")")

    judged = sorted({one(c["precision"]) for c in cases})
    # None: a bound that is not finite (report.json holds no inf: a vertex at 1e300 overflows it)
    bounds = [float("inf") if c.get("vertex_bound_px") is None else c["vertex_bound_px"] for c in cases]
    lo, hi = min(bounds), max(bounds)
    span = f"{lo:.3g} px" if lo == hi else f"{lo:.3g} to {hi:.3g} px"
    return f"{', '.join(judged)}; vertex bound {span}"


def case_notes(report: dict) -> list[tuple[dict, str]]:
    """``(case, text)`` for each case's ``note`` (what was not compared, and why), each case whose
    clipped ends were placed for the candidate's probed planes (``clipped_ends``, oracles.diagnosis.clip_planes),
    then each vacuous case allowed by ``--allow-vacuous`` (its reasons): the Notes of report.md and
    report.html."""
    failing = not_passed(report)
    notes = [(c, c["note"]) for c in report["cases"] if c.get("note")]
    notes += [(c, f"clipped ends moved {c['clipped_ends']['inward_depth']:.3g} inside the planes: "
                  f"{c['clipped_ends']['reason']}") for c in report["cases"] if c.get("clipped_ends")]
    notes += [(c, "; ".join(c["reasons"]) + " (allowed)") for c in report["cases"]
              if c["verdict"] == "vacuous" and c not in failing]
    return notes


def grouped_notes(report: dict) -> list[tuple[str, str]]:
    """``(where, text)``: each distinct :func:`case_notes` text once, ``where`` the cases that have it
    (``cube / distorted, pyramid / distorted``), then each fault kind's note once (``where`` its name;
    oracles.reports.fault_text.notes): the Notes of report.md and report.html."""
    by: dict[str, list[str]] = {}
    for c, text in case_notes(report):
        by.setdefault(text, []).append(f"{c['scene']} / {c['camera']}")
    return ([(", ".join(where), text) for text, where in by.items()]
            + [(name, text) for name, text in notes(report["cases"])])


def _line_styles(report: dict) -> list[str]:
    """The line styles read from a renderer's frames (--candidate-frames; oracles.judge.line_style)."""
    return summary_lines(report["cases"])


def markdown(report: dict, files: set | None = None) -> str:
    """report.md; ``files``: the figures written beside it (linked when present)."""
    files = files or set()
    s = report["summary"]
    settings = settings_text(report)
    head = header(report["cases"])
    run = f" ({report['run']})" if report.get("run") else ""
    out = [f"# crosscheck report{run}: {report['verdict'].upper()}", "",
           f"Candidate: `{report['candidate']}`" + (f" ({settings})" if settings else "")
           + f". Oracles: {', '.join(report['oracles'])}. "
           f"Cases: {s['cases']} ({s['passed']} pass, {s['failed']} fail, {s.get('vacuous', 0)} vacuous). "
           f"Compared: {compared_text(report)}." + (f" {vacuous_text(report)}." if vacuous_text(report) else ""), "",
           f"Level: {level_text(report)}. Checked: {frames_text(report)}.", "",
           f"Drawing: {drawing_text(report)}.", "",
           *([f"Oracle GL: {gl_text(report)}.", ""] if gl_text(report) else []),
           "Tolerances: " + ", ".join(f"{k} = {v}" for k, v in report["tolerances"].items()), "",
           *([f"Candidate precision: {precision_text(report)} (wirecheck.oracles.tolerances).", ""]
             if precision_text(report) else []),
           *[x for line in _line_styles(report) for x in (line + ".", "")],
           "| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for r in table_rows(report["cases"]):
        out.append("| " + " | ".join(r) + " |")
    failing = not_passed(report)
    if failing:
        out += ["", "## Why cases failed", ""]
        for c in failing:
            out.append(f"- **{c['scene']} / {c['camera']}**: " + "; ".join(c["reasons"]))
            if c["faults"]:             # the whole record, rounded (report.json keeps every digit)
                out.append(f"  - faults: {full_text(c['faults'], c.get('camera_spec'), FULL_DIGITS)}")
        names = hints((f for c in failing for f in c["faults"]), report.get("level") == "frames")
        if names:
            out += ["", "## What to check", ""]
            out += [f"- `{n}`: {h}" for n, h in names]
    figures = _figures(report, files)
    if figures or "worst.gif" in files:
        out += ["", "## Figures", ""]
        if "worst.gif" in files and _worst_text(report):
            out.append(f"- [worst.gif](worst.gif): the worst case, {_worst_text(report)}")
        out += [f"- [{name}]({name}): {caption}" for name, caption in figures]
    shown_notes = grouped_notes(report)
    if shown_notes:
        out += ["", "## Notes", ""]
        out += [f"- {where}: {note}" for where, note in shown_notes]
    out += ["", "Conventions: see `wirecheck.core.conventions`. Images of the worst frames, and the time per frame "
            "of each stage (vertex, pixel) per case: `report.html` (and `\"timing\"` in `report.json`; "
            "timings are kept out of this file so that it is the same on every run).", ""]
    return "\n".join(out)


def _html(report: dict, shown: list[tuple[dict, str, str]], files: set | None = None) -> str:
    files = files or set()
    head = header(report["cases"])
    e = html.escape
    legend = " ".join(f'<span class="chip" style="color:rgb{col}">&#9632; {e(name.replace("_", " "))}</span>'
                      for name, col in DIFF_COLOURS.items())
    rows = "".join("<tr>" + "".join(f"<td>{e(x)}</td>" for x in r) + "</tr>" for r in table_rows(report["cases"]))
    parts = [
        "<!doctype html><html><head><meta charset='utf-8'><title>crosscheck report</title>",
        "<style>body{font-family:sans-serif;background:#fafafa;margin:2em}"
        "table{border-collapse:collapse}td,th{border:1px solid #ccc;padding:2px 8px}"
        ".row{display:grid;grid-template-columns:repeat(4,1fr);gap:8px}"
        ".row figure{margin:0}.row figcaption{font-size:90%;color:#444}"
        # thin lines: scale smoothly when shrunk (pixelated scaling drops pixels); click for 1:1
        ".row img{width:100%;image-rendering:auto;border:1px solid #888;background:#000}"
        ".row .crop img{width:auto;max-width:100%;image-rendering:pixelated}"   # enlarged: blocks stay blocks
        ".chip{background:#000;padding:1px 6px;border-radius:3px}"
        ".anim{max-width:100%;image-rendering:pixelated;border:1px solid #888}.plot{max-width:100%}"
        ".fail{color:#b00}.pass{color:#070}section{margin:0 0 2em 0}</style></head><body>",
        f"<h1>crosscheck: <span class='{e(report['verdict'])}'>{e(report['verdict'].upper())}</span></h1>",
        f"<p>Candidate <code>{e(report['candidate'])}</code>"
        + (f" ({e(settings_text(report))})" if settings_text(report) else "")
        + f"; oracles {e(', '.join(report['oracles']))}.</p>",
        f"<p>Compared: {e(compared_text(report))}. {e(vacuous_text(report))}</p>",
        f"<p>Level {e(level_text(report))}. Checked: {e(frames_text(report))}.</p>",
        f"<p>Drawing: {e(drawing_text(report))}.</p>",
        f"<p>Oracle GL: {e(gl_text(report))}.</p>" if gl_text(report) else "",
        *([f"<p>Candidate precision: {e(precision_text(report))}.</p>"] if precision_text(report) else []),
        "<table><tr>" + "".join(f"<th>{e(h)}</th>" for h in head) + "</tr>" + rows + "</table>",
    ]
    failing = not_passed(report)
    if failing:
        parts.append("<h2>Why cases failed</h2><ul>" + "".join(
            f"<li><b>{e(c['scene'])} / {e(c['camera'])}</b>: {e('; '.join(c['reasons']))}</li>"
            for c in failing) + "</ul>")
    shown_notes = grouped_notes(report)
    if shown_notes:
        parts.append("<h2>Notes</h2><ul>" + "".join(
            f"<li class='note'><b>{e(where)}</b>: {e(note)}</li>" for where, note in shown_notes) + "</ul>")
    names = hints((f for c in report["cases"] for f in c["faults"]), report.get("level") == "frames")
    if names:
        parts.append("<h2>What to check</h2><ul>" + "".join(
            f"<li><code>{e(n)}</code>: {e(h)}</li>" for n, h in names) + "</ul>")
    timing = report.get("timing") or {}
    if timing and any(cell != _fmt_ms(None) for row in timing_rows(report) for cell in row[2:]):   # not all dashes
        trows = "".join("<tr>" + "".join(f"<td>{e(x)}</td>" for x in r) + "</tr>" for r in timing_rows(report))
        parts.append(
            "<h2>Time per frame</h2><p>Vertex stage: the candidate's projection and OpenCV; pixel stage: the "
            "candidate's drawing, pyrender and the pixel metrics"
            + (" (not run at level vertices)" if report.get("level") == "vertices" else "")
            + f". {e(str(timing.get('jobs', 1)))} job(s), {_fmt_wall(timing.get('wall_s', 0.0), '.2f')} s wall.</p>"
            "<table><tr>" + "".join(f"<th>{e(h)}</th>" for h in TIMING_HEADER) + "</tr>" + trows + "</table>")
    if "worst.gif" in files and _worst_text(report):
        parts.append(f"<h2>Worst case, every frame</h2><p>{e(_worst_text(report))}: "
                     f"{legend}.</p><p><a href='worst.gif'><img class='anim' src='worst.gif' "
                     "alt='worst case, every checked frame'></a></p>")
    for name, caption in _figures(report, files):
        parts.append(f"<h2>{e(caption[0].upper() + caption[1:])}</h2>"
                     f"<p><a href='{name}'><img class='plot' src='{name}' alt='{e(caption)}'></a></p>")
    if report.get("level") == "vertices":
        parts.append("<h2>Worst frames</h2><p>None: nothing is drawn at level vertices "
                     "(run with <code>--level pixels</code> to compare frames).</p>")
    else:
        parts.append(
            f"<h2>Worst frames</h2><p>Each row: the candidate's frame, the oracle's (pyrender), and their diff: "
            f"{legend}. Click an image for full size.</p>")
    for case, stem, crop in shown:
        figs = "".join(
            f"<figure><figcaption>{label}</figcaption><a href='img/{stem}-{kind}.png'>"
            f"<img src='img/{stem}-{kind}.png' alt='{label}'></a></figure>"
            for kind, label in (("candidate", "candidate"), ("oracle", "oracle (pyrender)"), ("diff", "diff")))
        figs += (f"<figure class='crop'><figcaption>{e(crop)}</figcaption><a href='img/{stem}-crop.png'>"
                 f"<img src='img/{stem}-crop.png' alt='{e(crop)}'></a></figure>")
        if "silhouette_iou" in case:
            scores = (f"silhouette IoU {_fmt_f1(case.get('silhouette_iou'))}, depth error / bound "
                      f"{_fmt_ratio(case.get('depth_error_ratio'))}")
        else:
            scores = f"F1@0 {_fmt_f1(case.get('pixel_f1_0px'))}, F1@1 {_fmt_f1(case.get('pixel_f1_1px'))}"
        parts.append(
            f"<section><p><b>{e(case['scene'])} / {e(case['camera'])}</b>, frame "
            f"{case.get('worst_pixel_frame')}: {scores}, "
            f"faults: {e(case_cell(case['faults'], case.get('camera_spec')))}</p>"
            f"<div class='row'>{figs}</div></section>")
    parts.append("</body></html>\n")
    return "\n".join(parts)


def finite_or_null(obj):
    """JSON has no inf or NaN: such values (a candidate's overflow) become null."""
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if isinstance(obj, dict):
        return {k: finite_or_null(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [finite_or_null(v) for v in obj]
    return obj


def write_report(run_dir: Path, report: dict, images: dict, worst_n: int = 6) -> Path:
    """Write the run directory atomically; ``images[(scene, camera)] = {frame, candidate, oracle}``.

    ``images["animation"]`` (oracles.runner.run_crosscheck) becomes worst.gif,
    ``images["points"]`` (level vertices) worst_points.png;
    the per-frame figures are drawn from the report itself.
    """
    run_dir = Path(run_dir)
    run_dir.parent.mkdir(parents=True, exist_ok=True)
    out = FrameDir(run_dir, "--report-dir")
    try:
        (out.tmp / "img").mkdir()
        # worst frames: every failing case, then the lowest F1 of the rest
        ranked = sorted(report["cases"], key=lambda c: (c["verdict"] == "pass", c.get("pixel_f1_1px") or 0,
                                                        c.get("pixel_f1_0px") or 0))
        shown = []
        for case in ranked:
            key = (case["scene"], case["camera"])
            if key not in images or (len(shown) >= worst_n and case["verdict"] == "pass"):
                continue
            im = images[key]
            stem = f"{case['scene']}-{case['camera']}"
            out.write(f"img/{stem}-candidate.png", png_bytes(np.where(im["candidate"], 255, 0).astype(np.uint8)))
            out.write(f"img/{stem}-oracle.png", png_bytes(np.where(im["oracle"], 255, 0).astype(np.uint8)))
            out.write(f"img/{stem}-diff.png", png_bytes(diff_image(im["candidate"], im["oracle"])))
            crop, window = crop_image(im["candidate"], im["oracle"])
            out.write(f"img/{stem}-crop.png", png_bytes(crop))
            shown.append((case, stem, crop_caption(window)))
        report = finite_or_null(report)
        files = set()
        if images.get("animation"):
            out.write("worst.gif", plots.worst_gif(images["animation"]))
            files.add("worst.gif")
        if images.get("points") and report.get("level") == "vertices":
            out.write("worst_points.png", points_png(images["points"]))
            files.add("worst_points.png")
        for name, draw in (("vertex_error.png", plots.vertex_error_png), ("pixels.png", plots.pixel_png)):
            data = draw(report)
            if data is not None:
                out.write(name, data)
                files.add(name)
        out.write("report.json", json_dumps(report).encode())
        # a name from a non-UTF-8 file name holds its bytes as lone surrogates: written as \udcff escapes
        out.write("report.md", markdown(report, files).encode("utf-8", "backslashreplace"))
        out.write("report.html", _html(report, shown, files).encode("utf-8", "backslashreplace"))
        out.commit()
    except BaseException:
        out.abort()
        raise
    return run_dir
