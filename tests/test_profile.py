"""Per-stage frame timing: render_frame(timing=...), core.app.profile.FrameProfiler, ``renderer --profile``."""

import json

import numpy as np
import pytest
from helpers import run_renderer as run
from numpy.testing import assert_array_equal
from wirecheck.core.app.profile import STAGES, FrameProfiler, profile_table
from wirecheck.core.camera import camera_z
from wirecheck.core.projector.pipeline import STAGES as PIPELINE_STAGES
from wirecheck.core.projector.pipeline import render_frame
from wirecheck.core.scene.files import load_scene
from wirecheck.core.transforms import Motion

MODES = {"wireframe": {}, "hidden": {"hidden_lines": True}, "cull": {"cull": "backface"}, "shaded": {"style": "shaded"}}


@pytest.mark.parametrize("mode", MODES)
def test_timing_changes_no_pixel_and_times_the_stages_that_ran(mode):
    cube = load_scene("cube")
    cam = camera_z(2.5, near=1.2)  # the near plane cuts the cube: the clip stage runs
    m = Motion().frame_matrix(7, 24)
    kw = dict(faces=cube.faces, **MODES[mode]) if MODES[mode] else {}
    plain = render_frame(cube.vertices, cube.edges, cam, m, **kw)
    timing = {}
    timed = render_frame(cube.vertices, cube.edges, cam, m, timing=timing, **kw)
    assert_array_equal(timed.image, plain.image)
    assert_array_equal(timed.p_px, plain.p_px)
    ran = {
        "wireframe": {"transform", "faces", "clip", "raster"},
        "hidden": {"transform", "faces", "clip", "raster"},
        "cull": {"transform", "faces", "clip", "raster"},
        "shaded": {"transform", "faces", "shading"},
    }[mode]
    assert set(timing) == ran
    assert set(timing) <= set(PIPELINE_STAGES)
    assert all(v > 0 for v in timing.values())


def test_timing_accumulates_over_calls(monkeypatch):
    # a clock that ticks 1 s per reading: each stage's lap is a whole number of
    # ticks whatever the machine's load, so three frames' must be three times one's
    from wirecheck.core.projector import pipeline

    ticks = iter(range(10**6))
    monkeypatch.setattr(pipeline, "_clock", lambda: float(next(ticks)))
    cube = load_scene("cube")
    timing = {}
    for _ in range(3):
        render_frame(cube.vertices, cube.edges, camera_z(4.0), np.eye(4), timing=timing)
    once = {}
    render_frame(cube.vertices, cube.edges, camera_z(4.0), np.eye(4), timing=once)
    assert once["raster"] >= 1.0
    assert timing == {stage: 3 * t for stage, t in once.items()}


def test_profiler_summary_against_hand_computed_numbers():
    prof = FrameProfiler(stages=("a", "b"))
    # frames (seconds): a = 1, 2, 3 ms; b = 4 ms each; totals 6, 7, 10 ms -> other 1, 1, 3 ms
    for a, total in ((1e-3, 6e-3), (2e-3, 7e-3), (3e-3, 10e-3)):
        prof.begin()
        prof.add("a", a)
        prof.add("b", 4e-3)
        prof.end(total=total)
    s = prof.summary()
    st = s["stages"]
    assert s["frames"] == 3
    assert st["a"]["mean_ms"] == pytest.approx(2.0)
    assert st["a"]["p50_ms"] == pytest.approx(2.0)
    # numpy's linear percentile: p95 of (1, 2, 3) = 1 + 0.95 * 2 = 2.9
    assert st["a"]["p95_ms"] == pytest.approx(2.9)
    assert st["other"]["mean_ms"] == pytest.approx(5.0 / 3)
    assert st["total"]["mean_ms"] == pytest.approx(23.0 / 3)
    assert st["b"]["share"] == pytest.approx(12.0 / 23.0)
    assert s["fps"] == pytest.approx(1000.0 / (23.0 / 3))
    text = profile_table(s)
    assert "a              2.000     2.000     2.900" in text
    with pytest.raises(ValueError, match="stage 'c'"):
        prof.add("c", 1.0)


def test_profiler_window_keeps_the_last_frames():
    prof = FrameProfiler(stages=("a",), window=2)
    for ms in (1, 2, 3):
        prof.begin()
        prof.add("a", ms * 1e-3)
        prof.end(total=ms * 1e-3)
    assert prof.summary()["stages"]["a"]["mean_ms"] == pytest.approx(2.5)  # frames 2 and 3


def test_renderer_profile_table_and_report(tmp_path):
    rc, out, err = run(["--frames", "20", "--profile"], tmp_path)
    assert rc == 0, err
    report = json.loads((tmp_path / "cube-report.json").read_text())
    prof = report["profile"]
    assert prof["frames"] == 20
    stages = prof["stages"]
    assert list(stages) == list(STAGES) + ["other", "total"]
    for name in ("transform", "raster", "compose", "encode", "write"):
        assert stages[name]["mean_ms"] > 0, name
        assert stages[name]["p50_ms"] <= stages[name]["p95_ms"]
        assert f"\n{name:<10} " in out
    # The laps never overlap: a time counted by two stages would make the stages' sum
    # exceed the frame's total and "other" (total - sum) negative. How much of the frame
    # the laps cover is a timing, measured by benchmarks/bench_viewer.py, not asserted here.
    assert stages["other"]["mean_ms"] >= 0
    assert "Profile: 20 frames" in out


def test_no_profile_no_timing_in_the_report(tmp_path):
    rc, _, err = run(["--frames", "3"], tmp_path)
    assert rc == 0, err
    assert "profile" not in json.loads((tmp_path / "cube-report.json").read_text())
