"""What several test modules share: the two CLIs run in-process, 8-connectivity of pixels, a guard against
blocking, and a frames job drawn by core."""

from __future__ import annotations

import contextlib
import io
import json
import signal


def run_renderer(args, out) -> tuple[int, str, str]:
    """``renderer`` with ``args + --out out``, stdout/stderr captured: ``(rc, stdout, stderr)``."""
    from wirecheck.core.app.cli import main

    o, e = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(o), contextlib.redirect_stderr(e):
        try:
            rc = main(list(args) + ["--out", str(out)])
        except SystemExit as exc:  # argparse usage errors
            rc = exc.code
    return rc, o.getvalue(), e.getvalue()


def run_crosscheck(tmp_path, *args, name="run"):
    """``crosscheck --report-dir tmp_path/name args``: ``(exit code, report.json or None, run dir)``."""
    from wirecheck.oracles import cli

    out = tmp_path / name
    code = cli.main(["--report-dir", str(out), *args])
    report = json.loads((out / "report.json").read_text()) if (out / "report.json").exists() else None
    return code, report, out


def eight_connected(pixels) -> bool:
    """True when the ``(row, col)`` pixels form one 8-connected set (or none)."""
    pixels = set(pixels)
    if not pixels:
        return True
    start = next(iter(pixels))
    seen, stack = {start}, [start]
    while stack:
        r, c = stack.pop()
        for dr in (-1, 0, 1):
            for dc in (-1, 0, 1):
                q = (r + dr, c + dc)
                if q in pixels and q not in seen:
                    seen.add(q)
                    stack.append(q)
    return seen == pixels


def assert_help_states_defaults(parser) -> None:
    """Every option of ``parser`` but -h/--version has help naming its default; no reStructuredText in --help."""
    for action in parser._actions:
        if action.dest not in ("help", "version"):  # -h and --version take no value
            assert action.help and "default" in action.help, action.option_strings
    text = parser.format_help()
    assert "``" not in text and ":func:" not in text and ":mod:" not in text


def blank_job(job):
    """Export a frames job of cube / on_axis, frames 1 and 3 of 4, into ``job`` and fill it with black
    640x480 PNGs (a renderer that drew nothing: judged, it fails); returns ``job``."""
    from PIL import Image
    from wirecheck.oracles import cli

    assert cli.main(["export", str(job), "--scene", "cube", "--cases", "on_axis", "--frames", "4", "--every", "2"]) == 0
    (job / "frames/cube/on_axis").mkdir(parents=True)
    for k in (1, 3):
        Image.new("L", (640, 480)).save(job / f"frames/cube/on_axis/frame_{k:04d}.png")
    return job


def process_runs(pid: int) -> bool:
    """Whether ``/proc`` shows ``pid`` running: False once it has ended, reaped or not (a zombie has ended;
    only its parent's reaping is left). Linux."""
    from pathlib import Path

    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except (FileNotFoundError, ProcessLookupError):
        return False
    return state != "Z"


@contextlib.contextmanager
def no_block(seconds=5, error=TimeoutError):
    """Fail (instead of hanging the suite) when the block blocks: opening a FIFO waits for a writer forever.
    ``error``: the exception raised then (a BaseException one the code under test cannot catch)."""

    def expire(*_):
        raise error(f"blocked for {seconds} s (a FIFO opened?)")

    old = signal.signal(signal.SIGALRM, expire)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)


def fill_job(job_dir, edit=lambda img: img, camera=lambda cam: cam) -> None:
    """Draw every listed frame of an exported job with core from the job's own files (a correct renderer);
    ``edit`` changes each image before it is written, ``camera`` the job's camera before it draws (a fault
    injected: scaled intrinsics)."""
    from pathlib import Path

    from PIL import Image
    from wirecheck.core.projector.pipeline import render_frame
    from wirecheck.oracles.candidates.frames_candidate import frame_inputs, load_job

    job_dir = Path(job_dir)
    job = load_job(job_dir)
    for c in job["cases"]:
        for rel in c["frames"]:
            k = int(Path(rel).stem.split("_")[-1])
            p, e, cam, m = frame_inputs(job_dir, job, c["scene"], c["case"], k)
            (job_dir / rel).parent.mkdir(parents=True, exist_ok=True)
            Image.fromarray(edit(render_frame(p, e, camera(cam), m).image.copy())).save(job_dir / rel)


def require_renderer(probe: str, what: str) -> None:
    """Skip (or fail, when WIRECHECK_REQUIRE_EGL=1: .ci/run) where ``python -c probe`` fails: a real
    renderer (moderngl, VTK) that cannot open its headless context here."""
    import os
    import subprocess
    import sys

    import pytest

    proc = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, timeout=120)
    if proc.returncode != 0:
        why = (proc.stderr.strip().splitlines() or ["no output"])[-1]
        if os.environ.get("WIRECHECK_REQUIRE_EGL") == "1":
            pytest.fail(f"{what} required (WIRECHECK_REQUIRE_EGL=1) but: {why}")
        pytest.skip(f"{what} unavailable: {why}")


def draw_and_judge(script, job_dir, tmp_path, *args, cases=6, frames=2) -> tuple[int, dict]:
    """Copy the exported ``job_dir``, draw it with the renderer client ``script`` (``args``: its mistake
    flags), judge it with ``crosscheck --candidate-frames``; the exit status and report.json, after checking
    that ``cases`` cases of ``frames`` frames each were compared."""
    import shutil
    import subprocess
    import sys

    from wirecheck.oracles.cli import main

    job = tmp_path / "job"
    shutil.copytree(job_dir, job)
    proc = subprocess.run([sys.executable, str(script), str(job), *args], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-3000:]
    rc = main(["--candidate-frames", str(job), "--report-dir", str(tmp_path / "rep")])
    report = json.loads((tmp_path / "rep" / "report.json").read_text())
    assert len(report["cases"]) == cases and all(c["frames_checked"] == frames for c in report["cases"])
    return rc, report


def depth_client_judged(folder, client: str, camera_fields, mistakes, motion, k: int = 2, frames: int = 7) -> list:
    """A real renderer's depth maps, judged: ``[(scene, case, mistake or None, DepthDiagnosis, camera)]``.

    Each bundled scene (cube, prism, pyramid) under each default case camera, frame ``k`` of ``frames`` of
    ``motion``: its fan triangles, world points and ``camera_fields(camera)`` (the fields the client reads,
    a dict) written to ``folder/<scene>-<case>.npz``; ``tests/clients/<client>`` run on ``folder`` in its own
    process, as its users run it, writing ``<scene>-<case>.<mistake>.npy`` for each of ``mistakes``
    (``"correct"`` among them); each map read by oracles.candidates.depth_map and named against pyrender's
    depth (oracles.judge.depth_reference) by oracles.diagnosis.depth_faults. The caller skips where the
    renderer or OSMesa is missing.
    """
    import subprocess
    import sys
    from pathlib import Path

    import numpy as np
    from wirecheck.core.scene.files import load_scene
    from wirecheck.core.scene.frames import SceneRenderer
    from wirecheck.oracles.candidates.depth_map import read_depth_map
    from wirecheck.oracles.cases import case_motion, cases_for
    from wirecheck.oracles.diagnosis.depth_faults import name_depth_faults
    from wirecheck.oracles.judge.depth_reference import reference_depth
    from wirecheck.oracles.references.pyrender_oracle import OracleCache

    refs = []
    cache = OracleCache()
    try:
        for name in ("cube", "prism", "pyramid"):
            scene = load_scene(name)
            fan = np.array([(f[0], f[j], f[j + 1]) for f in scene.faces for j in range(1, len(f) - 1)])
            for case in cases_for(scene):
                cam = case.camera
                refs.append(
                    (name, case, reference_depth(cache.get(cam.width, cam.height), scene, case, motion, k, frames))
                )
                np.savez(
                    Path(folder) / f"{name}-{case.name}.npz",
                    triangles=fan,
                    p_world=SceneRenderer(scene, case_motion(motion, case), frames).world_points(k),
                    width=cam.width,
                    height=cam.height,
                    near=cam.near,
                    far=cam.far,
                    projection=cam.projection,
                    **camera_fields(cam),
                )
    finally:
        cache.close()
    script = Path(__file__).parent / "clients" / client
    subprocess.run([sys.executable, str(script), str(folder)], check=True, timeout=300)
    out = []
    for name, case, ref in refs:
        cam = case.camera
        for mistake in mistakes:
            depth = read_depth_map(Path(folder) / f"{name}-{case.name}.{mistake}.npy", cam.width, cam.height)
            d = name_depth_faults(
                depth.depth, ref.compared_depth(), ref.bound, cam, depth.encoding_bound(), faces=ref.compared_faces()
            )
            out.append((name, case.name, None if mistake == "correct" else mistake, d, cam))
    return out
