"""Are two versions of the frames judge's outputs the same to the byte? (a change meant to be a speed-up only)

    .venv/bin/python benchmarks/frames_judge_equivalence.py jobs DIR            # export and draw 40 varied jobs
    .venv/bin/python benchmarks/frames_judge_equivalence.py depth-jobs DIR      # the 13 filled and depth ones alone
    PYTHONPATH=/tmp/base .venv/bin/python benchmarks/frames_judge_equivalence.py judge DIR OUT_BEFORE
    .venv/bin/python benchmarks/frames_judge_equivalence.py judge DIR OUT_AFTER   # (/tmp/base/wirecheck: the old tree)
    .venv/bin/python benchmarks/frames_judge_equivalence.py compare OUT_BEFORE OUT_AFTER

``jobs``: cube, pyramid and prism under seven cameras, drawn by core (as is,
with a stray pixel, each line's last pixel dropped, mirrored), antialiased (and
shifted by half a pixel), 3 px wide, by Pillow's rule, by GL's rule shifted by
half a pixel; core's frames saved as RGB, RGBA, 16-bit grey, grey + alpha,
palette and 1-bit PNGs; two 96-frame jobs past the line samples' cap. With
``--outputs filled,depth`` (the ``d_`` jobs, drawn by tests/clients/core_depth_job.py):
cube, pyramid and prism under the seven cameras as is and as a 16-bit PNG at
scale 1000; the z-buffer stored, x1000, rows flipped (depth and filled), half a
pixel and K from the horizontal FOV (the perspective cameras), a band missing
along the filled frames' top edge; the orrery's three objects with their ids,
permuted and all one; an icosphere(4) (5,120 faces); one job with wireframes too.
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
D = ["--scene", "cube", "--scene", "pyramid", "--scene", "prism", "--frames", "5", "--every", "2", "--phase", "0.3"]
D_ONE = ["--cases", "oblique_roll,orthographic,near_plane", "--frames", "5", "--every", "2", "--phase", "0.3"]


def _exporter(out: Path):
    """``export(name, args)``: ``crosscheck export out/name args`` (a folder there before is replaced)."""
    from wirecheck.oracles.cli import main

    def export(name, args):
        d = out / name
        out.mkdir(parents=True, exist_ok=True)
        if d.exists():
            shutil.rmtree(d)
        assert main(["export", str(d)] + args) == 0
        return d

    return export


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
    from wirecheck.oracles.diagnosis.image_diagnose import oracle_segments

    export = _exporter(out)

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
    make_depth_jobs(out, export)


def make_depth_jobs(out: Path, export) -> None:
    """The jobs with filled frames and depth maps (module docstring), drawn by core's depth client."""
    import numpy as np
    import trimesh

    sys.path[:0] = [str(ROOT / "tests")]
    from clients.core_depth_job import CAMERA_MISTAKES, MISTAKES, render_job

    fd = ["--outputs", "filled,depth"]
    render_job(export("d_core", D + fd))
    render_job(export("d_png16", D + fd + ["--depth-format", "png16", "--depth-scale", "1000"]))
    for name in ("zbuffer", "x1000"):
        render_job(export(f"d_{name}", ["--scene", "cube", "--scene", "prism"] + D_ONE + fd), MISTAKES[name])
    render_job(
        export("d_rows", ["--scene", "cube", "--scene", "pyramid"] + D_ONE + fd),
        MISTAKES["rows_flipped"],
        lambda covered: covered[::-1],
    )
    for name, mistake in CAMERA_MISTAKES.items():
        render_job(
            export(f"d_{name}", ["--scene", "cube", "--cases", "oblique_roll,wide_fov"] + D_ONE[2:] + fd),
            camera=mistake,
        )

    def drop_top(covered):  # each column's top covered pixel left out: a 1-px band along the top edge
        out = covered.copy()
        cols = np.flatnonzero(covered.any(axis=0))
        out[covered.argmax(axis=0)[cols], cols] = False
        return out

    render_job(export("d_band", ["--scene", "pyramid"] + D_ONE + fd), filled=drop_top)
    orrery = str(ROOT / "scenes" / "examples" / "orrery.scene")
    for name, ids in (("", lambda o: o), ("_permuted", lambda o: 2 - o), ("_one_id", np.zeros_like)):
        render_job(export(f"d_orrery{name}", ["--scene", orrery] + D_ONE + fd), object_ids=ids)
    mesh = out / "icosphere4.obj"  # a file beside the jobs: judge reads folders only
    trimesh.creation.icosphere(subdivisions=4).export(str(mesh))
    render_job(
        export(
            "d_icosphere",
            ["--scene", str(mesh), "--cases", "oblique_roll,near_plane,orthographic", "--frames", "4"] + fd,
        )
    )
    render_job(export("d_wire", ["--scene", "prism"] + D_ONE + ["--outputs", "wireframe,filled,depth"]))


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
    elif cmd == "depth-jobs":  # the filled and depth jobs alone
        make_depth_jobs(Path(args[0]), _exporter(Path(args[0])))
    elif cmd == "judge":
        judge(Path(args[0]), Path(args[1]))
    else:
        sys.exit(compare(Path(args[0]), Path(args[1])))
