"""Measure the frames judge on held-out renderers (docs/frames.md, "Held-out renderers", cites this run).

Exports a job (every bundled scene, the seven cases, frames 1 and 4 of 6), draws
it with each renderer of tests/clients/heldout_draw.py (Pillow, matplotlib's
Agg, OpenCV, a Wu and a Bresenham line: drawing code of their own from the
job's camera contract) and with GL's rule (core's raster, the reference
aliased rule), correct and with typical mistakes (a half pixel, the FOV of the
wrong axis, fx 3 % over fy, rows not flipped), judges it with
``crosscheck --candidate-frames`` and prints per renderer the verdicts and
faults counted over the cases, the style read, the width, F1@0px against GL's
rule, the largest measured centre offset, and the pixel offsets named.

    .venv/bin/python benchmarks/measure_heldout_frames.py [OUT] [--only NAME ...] [--cases] [--line-rule gl|geometry]

About 25 s a renderer on one core (15 minutes in all). Not part of CI.
"""

from __future__ import annotations

import argparse
import collections
import contextlib
import io
import json
import shutil
import sys
import tempfile
from functools import partial
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "clients"))

import heldout_draw as hd  # noqa: E402
from wirecheck.oracles.cli import main  # noqa: E402

mpl, cv2_line, pillow = hd.draw_matplotlib, hd.draw_cv2, hd.draw_pillow
GL, LOOKAT = hd.project_gl, hd.project_lookat
HALF = {"half_pixel": True}
ASPECT = {"aspect": 1.03}


def draw_gl_rule(segs, w, h):
    """GL's rule: wirecheck core's exact line raster (the pixels pyrender draws for these lines), white on black."""
    import numpy as np
    from wirecheck.core.projector.clipping import clip_to_image
    from wirecheck.core.projector.raster import line_pixels

    img = np.zeros((h, w), np.uint8)
    segs = np.asarray(segs, dtype=np.float64).reshape(-1, 2, 2)
    _, q0, q1 = clip_to_image(segs[:, 0], segs[:, 1], w, h)
    rr, cc = line_pixels(q0, q1, w, h)
    img[rr, cc] = 255
    return img


#: name -> (drawer, projection, mistake)
RENDERERS = {
    "pillow 1px": (pillow, GL, {}),
    "pillow 2px": (partial(pillow, width=2), GL, {}),
    "pillow 3px": (partial(pillow, width=3), GL, {}),
    "pillow 4x supersampled": (hd.draw_pillow_supersampled, GL, {}),
    **{f"matplotlib aa {w}px": (partial(mpl, linewidth_px=w), LOOKAT, {}) for w in (0.5, 1.0, 1.5, 2.0)},
    **{
        f"matplotlib aliased {w}px": (partial(mpl, linewidth_px=w, antialiased=False), LOOKAT, {})
        for w in (0.5, 1.0, 1.5, 2.0)
    },
    "wu": (hd.draw_wu, GL, {}),
    "bresenham": (hd.draw_bresenham, LOOKAT, {}),
    **{f"cv2 {t}": (partial(cv2_line, line_type=t), GL, {}) for t in ("LINE_8", "LINE_4", "LINE_AA")},
    # one typical mistake each
    "pillow 1px, half pixel": (pillow, GL, HALF),
    "pillow 2px, half pixel": (partial(pillow, width=2), GL, HALF),
    "pillow 3px, half pixel": (partial(pillow, width=3), GL, HALF),
    "pillow 4x supersampled, half pixel": (hd.draw_pillow_supersampled, GL, HALF),
    "matplotlib aa 1.0px, rows not flipped": (partial(mpl, linewidth_px=1.0), LOOKAT, {"flip_rows": False}),
    "matplotlib aa 1.5px, half pixel": (partial(mpl, linewidth_px=1.5, half_pixel=True), LOOKAT, {}),
    "wu, half pixel": (hd.draw_wu, GL, HALF),
    "bresenham, FOV of the wrong axis": (hd.draw_bresenham, LOOKAT, {"fov_axis": "x"}),
    "cv2 LINE_8, FOV of the wrong axis": (partial(cv2_line, line_type="LINE_8"), LOOKAT, {"fov_axis": "x"}),
    "cv2 LINE_AA, half pixel": (partial(cv2_line, line_type="LINE_AA"), GL, HALF),
    # fx 3 % over fy: an aspect mistake drawn by GL's rule and by the rules that round the ends
    "gl rule (core)": (draw_gl_rule, LOOKAT, {}),
    "gl rule (core), aspect 1.03": (draw_gl_rule, LOOKAT, ASPECT),
    "gl rule (core), half pixel": (draw_gl_rule, GL, HALF),
    "gl rule (core), FOV of the wrong axis": (draw_gl_rule, LOOKAT, {"fov_axis": "x"}),
    "pillow 1px, FOV of the wrong axis": (pillow, LOOKAT, {"fov_axis": "x"}),
    "bresenham, aspect 1.03": (hd.draw_bresenham, LOOKAT, ASPECT),
    "cv2 LINE_8, aspect 1.03": (partial(cv2_line, line_type="LINE_8"), LOOKAT, ASPECT),
    "pillow 1px, aspect 1.03": (pillow, LOOKAT, ASPECT),
}


def judge(job: Path, out: Path, name: str, line_rule: str | None = None) -> list:
    draw, project, mistake = RENDERERS[name]
    d = out / "job"
    shutil.rmtree(out, ignore_errors=True)
    shutil.copytree(job, d)
    hd.render(d, draw, project, **mistake)
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        main(
            ["--candidate-frames", str(d), "--report-dir", str(out / "rep")]
            + (["--line-rule", line_rule] if line_rule else [])
        )
    cases = json.loads((out / "rep" / "report.json").read_text())["cases"]
    shutil.rmtree(out)
    return cases


def summary(name: str, cases: list, per_case: bool) -> str:
    verdicts = collections.Counter()
    styles = collections.Counter()
    widths, f1_0, offs, named = [], [], [], []
    lines = []
    for c in cases:
        names = "+".join(f["name"] for f in c["faults"]) or "-"
        verdicts[f"{c['verdict']} {names}"] += 1
        ls = c["line_style"]
        styles[ls["style"]] += 1
        widths.append(ls["width_px"])
        f1_0.append(c["pixel_f1_0px"])
        off = ls["geometry"]["offset_px"]
        if off is not None:
            offs.append(max(map(abs, off)))
        named += [(f["dx"], f["dy"]) for f in c["faults"] if f["name"] == "pixel_offset"]
        if per_case:
            lines.append(
                f"    {c['scene']:8s} {c['camera']:13s} {c['verdict']:4s} F1@1px {c['pixel_f1_1px']:.4f} "
                f"F1@0px {c['pixel_f1_0px']:.4f} {ls['style']} offset {off} {names}"
            )
    head = (
        f"{name}: {dict(verdicts)}; style {dict(styles)}, width {min(widths):.2f}-{max(widths):.2f}, "
        f"F1@0px {min(f1_0):.2f}-{max(f1_0):.2f}, max |offset| {max(offs, default=float('nan')):.3f}"
    )
    if named:
        head += (
            f"; pixel_offset dx {min(p[0] for p in named):.2f}..{max(p[0] for p in named):.2f} "
            f"dy {min(p[1] for p in named):.2f}..{max(p[1] for p in named):.2f}"
        )
    return "\n".join([head] + lines)


def run(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("out", nargs="?", help="a folder for the job and the reports (default: a temporary one)")
    ap.add_argument("--only", nargs="+", choices=sorted(RENDERERS), help="these renderers only")
    ap.add_argument("--cases", action="store_true", help="one line per case too")
    ap.add_argument(
        "--line-rule",
        choices=("any", "gl", "geometry"),
        default=None,
        help="crosscheck's --line-rule (default: crosscheck's own, any)",
    )
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(args.out or tmp)
        job = out / "job"
        shutil.rmtree(job, ignore_errors=True)
        with contextlib.redirect_stdout(io.StringIO()):
            assert main(["export", str(job), "--frames", "6", "--every", "3"]) == 0
        for k, name in enumerate(args.only or RENDERERS):
            print(summary(name, judge(job, out / f"r{k}", name, args.line_rule), args.cases), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(run())
