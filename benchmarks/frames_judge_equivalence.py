"""Are two versions of the frames judge's outputs the same to the byte? (a change meant to be a speed-up only)

    .venv/bin/python benchmarks/frames_judge_equivalence.py jobs DIR            # export and draw 27 varied jobs
    PYTHONPATH=/tmp/base .venv/bin/python benchmarks/frames_judge_equivalence.py judge DIR OUT_BEFORE
    .venv/bin/python benchmarks/frames_judge_equivalence.py judge DIR OUT_AFTER   # (/tmp/base/wirecheck: the old tree)
    .venv/bin/python benchmarks/frames_judge_equivalence.py compare OUT_BEFORE OUT_AFTER

``jobs``: cube, pyramid and prism under seven cameras, drawn by core (as is,
with a stray pixel, each line's last pixel dropped, mirrored), antialiased (and
shifted by half a pixel), 3 px wide, by Pillow's rule, by GL's rule shifted by
half a pixel; core's frames saved as RGB, RGBA, 16-bit grey, grey + alpha,
palette and 1-bit PNGs; two 96-frame jobs past the line samples' cap.
``judge``: ``crosscheck --candidate-frames`` on each (``--line-rule gl``, and
``geometry`` on nine), with whichever wirecheck is first on the path: each
report folder plus its exit status and printed lines. ``compare``: every
file of each folder byte for byte, ``report.json`` without its ``timing``
(and the output manifest without report.json's hash, the printed lines
without the folder's name). Exit 1 when any differs. Minutes on 2 cores.
"""

from __future__ import annotations

import contextlib
import io
import json
import shutil
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
GEOMETRY = {"a_core", "a_aa", "a_pillow", "a_gl_half", "b_core", "b_wide", "b_aa_half", "b_short", "c96_aa"}
A = [
    "--scene",
    "cube",
    "--scene",
    "pyramid",
    "--cases",
    "oblique_roll,non_square,orthographic",
    "--frames",
    "6",
    "--every",
    "3",
]
B = [
    "--scene",
    "prism",
    "--scene",
    "cube",
    "--cases",
    "on_axis,wide_fov,near_plane,off_centre",
    "--frames",
    "8",
    "--every",
    "2",
    "--phase",
    "0.3",
]
C = ["--scene", "cube", "--cases", "on_axis", "--frames", "96"]


def make_jobs(out: Path) -> None:
    import numpy as np
    from PIL import Image

    sys.path[:0] = [str(ROOT / "tests")]
    from raster_mutants import drop_last
    from test_line_style import draw_antialiased, draw_pillow, draw_wide
    from wirecheck.core.projector import raster
    from wirecheck.core.projector.clipping import clip_to_image
    from wirecheck.core.projector.pipeline import render_frame
    from wirecheck.oracles.candidates.frames_candidate import frame_inputs, load_job
    from wirecheck.oracles.cli import main
    from wirecheck.oracles.diagnosis.image_diagnose import oracle_segments

    def export(name, args):
        d = out / name
        if d.exists():
            shutil.rmtree(d)
        assert main(["export", str(d)] + args) == 0
        return d

    def each(d, fn, save=lambda img, p: Image.fromarray(img).save(p)):
        job = load_job(d)
        for c in job["cases"]:
            for rel in c["frames"]:
                k = int(Path(rel).stem.split("_")[-1])
                p, e, cam, m = frame_inputs(d, job, c["scene"], c["case"], k)
                (d / rel).parent.mkdir(parents=True, exist_ok=True)
                save(fn(p, e, cam, m), d / rel)

    def core(p, e, cam, m):
        return render_frame(p, e, cam, m).image.copy()

    def gl(s, w, h):
        img = np.zeros((h, w), np.uint8)
        _, q0, q1 = clip_to_image(s[:, 0], s[:, 1], w, h)
        rr, cc = raster.line_pixels(q0, q1, w, h)
        img[rr, cc] = 255
        return img

    def styled(draw, shift=(0, 0)):
        return lambda p, e, cam, m: draw(
            oracle_segments(p @ m[:3, :3].T + m[:3, 3], e, cam) + np.asarray(shift), cam.width, cam.height
        )

    def stray(*x):
        img = core(*x)
        img[0, 0] = 255
        return img

    for args, tag in ((A, "a"), (B, "b")):
        each(export(f"{tag}_core", args), core)
        each(export(f"{tag}_stray", args), stray)
        each(export(f"{tag}_mirror", args), lambda *x: core(*x)[:, ::-1].copy())
        each(export(f"{tag}_aa", args), styled(draw_antialiased))
        each(export(f"{tag}_aa_half", args), styled(draw_antialiased, (0.5, 0.5)))
        each(export(f"{tag}_wide", args), styled(draw_wide))
        each(export(f"{tag}_pillow", args), styled(draw_pillow))
        each(export(f"{tag}_gl_half", args), styled(gl, (0.5, 0.5)))
        original, raster._line_pixels = raster._line_pixels, drop_last
        try:
            each(export(f"{tag}_short", args), core)
        finally:
            raster._line_pixels = original
    grey = lambda img: np.stack([img, img // 2, img], -1)
    each(export("a_rgb", A), core, lambda img, p: Image.fromarray(grey(img)).save(p))
    each(
        export("a_rgba", A),
        core,
        lambda img, p: Image.fromarray(np.stack([img, img, img, np.where(img > 0, 255, 0).astype(np.uint8)], -1)).save(
            p
        ),
    )
    each(export("a_grey16", A), core, lambda img, p: Image.fromarray(img.astype(np.uint16) * 257).save(p))
    each(export("a_la", A), core, lambda img, p: Image.fromarray(np.stack([img, img], -1), "LA").save(p))
    each(export("a_pal", A), core, lambda img, p: Image.fromarray(img).convert("P").save(p))
    each(export("a_bit1", A), core, lambda img, p: Image.fromarray(img > 127).save(p))
    each(export("a_aa_rgb", A), styled(draw_antialiased), lambda img, p: Image.fromarray(img).convert("RGB").save(p))
    each(export("c96_core", C), core)
    each(export("c96_aa", C), styled(draw_antialiased))


def judge(jobs: Path, out: Path) -> None:
    from wirecheck.oracles.cli import main

    for j in sorted(p for p in jobs.iterdir() if p.is_dir()):
        for rule in ("gl", "geometry") if j.name in GEOMETRY else ("gl",):
            d = out / f"{j.name}-{rule}"
            if d.exists():
                shutil.rmtree(d)
            buf = io.StringIO()
            with contextlib.redirect_stdout(buf), contextlib.redirect_stderr(buf):
                rc = main(["--candidate-frames", str(j), "--report-dir", str(d), "--line-rule", rule])
            d.mkdir(parents=True, exist_ok=True)
            (d / "stdout.txt").write_text(f"rc {rc}\n" + buf.getvalue().replace(str(out), "OUT"))
            print(j.name, rule, rc, flush=True)


def _timeless(o):
    if isinstance(o, dict):
        return {k: _timeless(v) for k, v in o.items() if k != "timing"}
    return [_timeless(v) for v in o] if isinstance(o, list) else o


def compare(a: Path, b: Path) -> int:
    bad = n = 0
    for d in sorted(x for x in a.iterdir() if x.is_dir()):
        e = b / d.name
        fa = sorted(p.relative_to(d) for p in d.rglob("*") if p.is_file())
        fb = sorted(p.relative_to(e) for p in e.rglob("*") if p.is_file()) if e.exists() else []
        if fa != fb:
            print("files differ:", d.name, sorted(set(fa) ^ set(fb)))
            bad += 1
        for rel in set(fa) & set(fb):
            n += 1
            x, y = (d / rel).read_bytes(), (e / rel).read_bytes()
            if rel.name == "report.json":
                x, y = _timeless(json.loads(x)), _timeless(json.loads(y))
            elif rel.name == ".wirecheck-output":  # the files' hashes, report.json's (timing) left out
                x, y = json.loads(x), json.loads(y)
                x["files"].pop("report.json", None)
                y["files"].pop("report.json", None)
            if x != y:
                print("DIFF", d.name, rel)
                bad += 1
    print(f"compared {n} files, {bad} differ")
    return 1 if bad or not n else 0


if __name__ == "__main__":
    cmd, *args = sys.argv[1:]
    if cmd == "jobs":
        make_jobs(Path(args[0]))
    elif cmd == "judge":
        judge(Path(args[0]), Path(args[1]))
    else:
        sys.exit(compare(Path(args[0]), Path(args[1])))
