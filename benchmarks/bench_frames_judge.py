"""The frames judge (``crosscheck --candidate-frames``): peak memory by job length, time per frame vs pyrender.

    .venv/bin/python benchmarks/bench_frames_judge.py                     # 24 and 720 frames at 640x480 (minutes)
    .venv/bin/python benchmarks/bench_frames_judge.py --frames 24,96      # quicker
    .venv/bin/python benchmarks/bench_frames_judge.py --size 160x120      # the memory target, small images (quick)

For each length a job is exported (the cube, case ``on_axis``, every frame
checked; ``--size``: its camera's image size changed in the job's files) and
its frames drawn by core (a correct renderer); then a fresh interpreter
judges it (oracles.judge.frames_judge.run_frames) and reports its peak
resident memory (``ru_maxrss``) and wall time, and, in the same process and
on the same frames afterwards, pyrender drawing each frame alone (the
oracle's share of the judging: ``PyrenderOracle.render``, its context
already made), and, for the longest job, pyrender alone in a fresh
interpreter of its own (the target's pyrender: its time after the judge, in
the judge's process, moves with what the judge left in memory). The modules the judge uses are imported before the clock
starts (an interpreter's start, as pyrender's context is made outside its
timing); everything else the judging does is timed, the pre-check of every
frame and the image diagnosis included. Printed: peak RSS of each job and
the ratio of the longest to the shortest (target <= 1.5: memory flat in the
job's length), and the judge's seconds per frame against pyrender's on the
same frames (target <= 1.5), both measured in this run. pyrender's
time is its whole drawing of a frame as pyrender returns it (colour and
depth); the judge asks for the colour only (``render(depth=False)``), and
that drawing's time is printed too (the stricter comparison).

The judge reads frames ahead on a worker thread (oracles.candidates.frame_prefetch):
the oracle's calls then overlap the judge's own work, so "rest" (the wall
time less the worker's time in ``PyrenderOracle.render``) is no longer the
judge's own work alone: it is less than that by the overlap.

``--oracle core`` judges against core's drawing instead of pyrender's (the
oracle stands in, its verdict the same on core's frames): the judge's own
memory, without what pyrender's renders keep (the oracle's growth is
measured apart, by the default run's numbers against these).
"""

from __future__ import annotations

import argparse
import inspect
import json
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))

from _common import loadavg  # noqa: E402


def resize_job(path: Path, width: int, height: int) -> None:
    """Give every camera of an exported job the image size ``width`` x ``height`` (job.json and each frame's
    ``camera``; the frames judge reads no other field of a frame's JSON; the principal point follows the size)."""
    import json as _json

    job = _json.loads((path / "job.json").read_text())
    for c in job["cases"]:
        c["width"], c["height"] = width, height
    (path / "job.json").write_text(_json.dumps(job))
    for f in sorted((path / "cameras").rglob("*.json")):
        cam = _json.loads(f.read_text())
        cam["camera"]["width"], cam["camera"]["height"] = width, height
        f.write_text(_json.dumps(cam))


def make_job(path: Path, frames: int, size: tuple | None = None) -> None:
    """Export a job of ``frames`` frames (every one checked; ``size``: ``(W, H)`` of its images) and draw them
    with core."""
    from PIL import Image
    from wirecheck.core.projector.pipeline import render_frame
    from wirecheck.oracles.candidates.frames_candidate import frame_inputs, load_job
    from wirecheck.oracles.cli import main

    assert main(["export", str(path), "--scene", "cube", "--cases", "on_axis", "--frames", str(frames)]) == 0
    if size is not None:
        resize_job(path, *size)
    job = load_job(path)
    for c in job["cases"]:
        for rel in c["frames"]:
            k = int(Path(rel).stem.split("_")[-1])
            p, e, cam, m = frame_inputs(path, job, c["scene"], c["case"], k)
            (path / rel).parent.mkdir(parents=True, exist_ok=True)
            Image.fromarray(render_frame(p, e, cam, m).image).save(path / rel)


class CoreOracle:
    """core's drawing in the place of pyrender's (``--oracle core``): nothing kept between frames."""

    def render(self, p_model, edges, camera, model_matrix=None):
        from wirecheck.core.projector.pipeline import render_frame

        return render_frame(p_model, edges, camera, model_matrix).image >= 128, None

    def gl_info(self):
        return None

    def close(self):
        pass


def judge(path: Path, oracle_name: str = "pyrender") -> dict:
    """Judge the job (this process only): peak RSS, seconds per frame, and pyrender's per frame after."""
    import cv2  # noqa: F401  (the modules the judging imports, before the clock: an interpreter's start)
    import scipy.ndimage  # noqa: F401
    import scipy.spatial.transform  # noqa: F401
    import wirecheck.oracles.diagnosis.image_diagnose  # noqa: F401
    import wirecheck.oracles.judge.decide  # noqa: F401
    import wirecheck.oracles.judge.line_style  # noqa: F401
    from wirecheck.oracles.references import pyrender_oracle

    pyrender_oracle.gl_platform()  # the GL platform chosen before pyrender is imported
    import pyrender  # noqa: F401
    from wirecheck.oracles.candidates.frames_candidate import frame_inputs, load_job
    from wirecheck.oracles.judge.frames_judge import run_frames
    from wirecheck.oracles.references.pyrender_oracle import PyrenderOracle

    if oracle_name == "core":
        pyrender_oracle.OracleCache.get = lambda self, w, h: CoreOracle()
        pyrender_oracle.OracleCache.gl_info = lambda self: None
    inside = {"s": 0.0}  # the oracle's seconds inside the judge
    render = (CoreOracle if oracle_name == "core" else PyrenderOracle).render

    def timed(self, *args, **kwargs):
        t = time.perf_counter()
        try:
            return render(self, *args, **kwargs)
        finally:
            inside["s"] += time.perf_counter() - t

    (CoreOracle if oracle_name == "core" else PyrenderOracle).render = timed

    t0 = time.perf_counter()
    report, _ = run_frames(path)
    wall = time.perf_counter() - t0
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    frames = report["compared"]["frames"]
    (CoreOracle if oracle_name == "core" else PyrenderOracle).render = render
    job = load_job(path)
    c = job["cases"][0]
    colour_only = "depth" in inspect.signature(render).parameters  # PyrenderOracle.render(depth=False)
    oracle, seconds, seconds_colour = None, 0.0, 0.0
    for rel in c["frames"]:
        k = int(Path(rel).stem.split("_")[-1])
        p, e, cam, m = frame_inputs(path, job, c["scene"], c["case"], k)
        if oracle is None:
            oracle = PyrenderOracle(cam.width, cam.height)
            oracle.render(p, e, cam, model_matrix=m)  # the context made, as in the judge
        t = time.perf_counter()
        oracle.render(p, e, cam, model_matrix=m)
        seconds += time.perf_counter() - t
        if colour_only:
            t = time.perf_counter()
            oracle.render(p, e, cam, model_matrix=m, depth=False)
            seconds_colour += time.perf_counter() - t
    oracle.close()
    return {
        "frames": frames,
        "verdict": report["verdict"],
        "peak_rss_mb": round(peak, 1),
        "judge_s": round(wall, 2),
        "judge_ms_per_frame": round(1e3 * wall / frames, 2),
        "pyrender_ms_per_frame": round(1e3 * seconds / frames, 2),
        "colour_only_ms_per_frame": round(1e3 * seconds_colour / frames, 2) if colour_only else None,
        "oracle_in_judge_ms_per_frame": round(1e3 * inside["s"] / frames, 2),
    }


def pyrender_alone(path: Path) -> dict:
    """pyrender drawing the job's frames in a fresh interpreter (as the judge's own run starts): the modules
    and the context made before the clock (one warm-up render), then ``PyrenderOracle.render`` of every frame,
    pyrender's full frame (``OffscreenRenderer.render``: colour and depth); then, in a second pass, the
    colour-only call the judge makes (``depth=False``)."""
    from wirecheck.oracles.references import pyrender_oracle

    pyrender_oracle.gl_platform()
    import pyrender  # noqa: F401
    from wirecheck.oracles.candidates.frames_candidate import frame_inputs, load_job
    from wirecheck.oracles.references.pyrender_oracle import PyrenderOracle

    job = load_job(path)
    c = job["cases"][0]
    inputs = [frame_inputs(path, job, c["scene"], c["case"], int(Path(rel).stem.split("_")[-1])) for rel in c["frames"]]
    oracle = PyrenderOracle(inputs[0][2].width, inputs[0][2].height)
    oracle.render(*inputs[0][:3], model_matrix=inputs[0][3])
    out = {}
    for key, kwargs in (("pyrender_fresh_ms_per_frame", {}), ("colour_only_fresh_ms_per_frame", {"depth": False})):
        t = time.perf_counter()
        for p, e, cam, m in inputs:
            oracle.render(p, e, cam, model_matrix=m, **kwargs)
        out[key] = round(1e3 * (time.perf_counter() - t) / len(inputs), 2)
    oracle.close()
    return out


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--frames", default="24,720", help="job lengths, comma-separated (default 24,720)")
    p.add_argument(
        "--oracle",
        choices=("pyrender", "core"),
        default="pyrender",
        help="what the judge compares with (core: the judge's own memory, without pyrender's)",
    )
    p.add_argument("--size", help="image size WxH of the job's camera (default: the case's own, 640x480)")
    p.add_argument("--child", help=argparse.SUPPRESS)
    p.add_argument("--pyrender-child", help=argparse.SUPPRESS)
    a = p.parse_args(argv)
    size = tuple(int(v) for v in a.size.lower().split("x")) if a.size else None
    if a.child:
        print(json.dumps(judge(Path(a.child), a.oracle)))
        return 0
    if a.pyrender_child:
        print(json.dumps(pyrender_alone(Path(a.pyrender_child))))
        return 0
    lengths = [int(x) for x in a.frames.split(",")]
    print(
        f"# bench_frames_judge: cube / on_axis, frames {lengths}, {a.size or '640x480'}, judged against "
        f"{a.oracle}; load at start {loadavg()}"
    )
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for n in lengths:
            job = Path(tmp) / f"job{n}"
            make_job(job, n, size)
            out = subprocess.run(
                [sys.executable, __file__, "--child", str(job), "--oracle", a.oracle],
                capture_output=True,
                text=True,
                check=True,
            )
            rows.append(json.loads(out.stdout.strip().splitlines()[-1]))
            if a.oracle == "pyrender" and n == lengths[-1]:
                alone = subprocess.run(
                    [sys.executable, __file__, "--pyrender-child", str(job)], capture_output=True, text=True, check=True
                )
                rows[-1].update(json.loads(alone.stdout.strip().splitlines()[-1]))
    # pyrender ms/frame: a fresh oracle drawing the job's frames after the judging; oracle in judge: the
    # oracle's own calls while judging (pyrender's, or core's with --oracle core); the rest is the judge's
    print(
        f"{'frames':>7} {'verdict':>8} {'peak RSS MB':>12} {'judge ms/frame':>15} {'pyrender ms/frame':>18} "
        f"{'judge/pyrender':>15} {'oracle in judge':>16} {'rest/pyrender':>14}"
    )
    for r in rows:
        rest = r["judge_ms_per_frame"] - r["oracle_in_judge_ms_per_frame"]
        print(
            f"{r['frames']:>7} {r['verdict']:>8} {r['peak_rss_mb']:>12.1f} {r['judge_ms_per_frame']:>15.2f} "
            f"{r['pyrender_ms_per_frame']:>18.2f} {r['judge_ms_per_frame'] / r['pyrender_ms_per_frame']:>15.2f} "
            f"{r['oracle_in_judge_ms_per_frame']:>16.2f} {rest / r['pyrender_ms_per_frame']:>14.2f}"
        )
    first, last = rows[0], rows[-1]
    print(
        f"peak RSS {last['frames']} / {first['frames']} frames: {last['peak_rss_mb'] / first['peak_rss_mb']:.2f} "
        "(target <= 1.5)"
    )
    if "pyrender_fresh_ms_per_frame" in last:
        # the target's pyrender: a fresh interpreter drawing the same frames, as the judge's run is timed from
        # one (pyrender's time after the judge, in the judge's process, moves with what the judge left in
        # memory: 9-13 ms measured on the same frames, so it is printed, not taken)
        print(
            f"judge / pyrender per frame ({last['frames']} frames): "
            f"{last['judge_ms_per_frame'] / last['pyrender_fresh_ms_per_frame']:.2f} (target <= 1.5; pyrender "
            f"{last['pyrender_fresh_ms_per_frame']:.2f} ms a frame in a fresh process, "
            f"{last['pyrender_ms_per_frame']:.2f} after the judge in its process)"
        )
        print(
            f"judge / pyrender's colour-only drawing per frame ({last['frames']} frames): "
            f"{last['judge_ms_per_frame'] / last['colour_only_fresh_ms_per_frame']:.2f} "
            f"({last['colour_only_fresh_ms_per_frame']:.2f} ms a frame in a fresh process: render(depth=False), "
            "the judge's own call)"
        )
    else:
        print(
            f"judge / pyrender per frame ({last['frames']} frames): "
            f"{last['judge_ms_per_frame'] / last['pyrender_ms_per_frame']:.2f} (target <= 1.5)"
        )
    if last["colour_only_ms_per_frame"] and "pyrender_fresh_ms_per_frame" not in last:
        print(
            f"judge / the oracle's colour-only drawing per frame ({last['frames']} frames): "
            f"{last['judge_ms_per_frame'] / last['colour_only_ms_per_frame']:.2f} "
            f"({last['colour_only_ms_per_frame']:.2f} ms: render(depth=False), the judge's own call)"
        )
    print(f"# load at end {loadavg()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
