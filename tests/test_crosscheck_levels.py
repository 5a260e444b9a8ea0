"""crosscheck --level, --every, --jobs and the core candidate's settings (--dtype, --clip, --raster)."""

import json
import pickle
import sys
from pathlib import Path

import numpy as np
import pytest
from helpers import run_crosscheck as run
from wirecheck.oracles import cli
from wirecheck.oracles.candidates.core_candidate import CoreCandidate

DATA = Path(__file__).parent / "data"
USER = DATA / "user_projector.py"
PIXEL_KEYS = {"f1_0px", "f1_1px", "precision_0px", "recall_0px", "precision_1px", "recall_1px"}
VERTEX_KEYS = (
    "max_vertex_error_px",
    "mean_vertex_error_px",
    "rms_vertex_error_px",
    "worst_vertex",
    "visible_points",
    "visibility_mismatch",
    "faults",
    "verdict",
)


def without_timing(out: Path) -> str:
    report = json.loads((out / "report.json").read_text())
    report.pop("timing")
    return json.dumps(report, indent=1)


# ---------------------------------------------------------------- --level


def test_vertices_level_draws_nothing_and_never_loads_pyrender(tmp_path, monkeypatch):
    from wirecheck.core.projector import raster
    from wirecheck.oracles.judge import case as case_module
    from wirecheck.oracles.references import pyrender_oracle

    def forbidden(*_a, **_k):
        raise AssertionError("the pixel stage ran at level vertices")

    # pyrender cannot even be imported: the osmesa check, a PyrenderOracle or a
    # drawing would end the run with exit 2 or an AssertionError
    monkeypatch.setitem(sys.modules, "pyrender", None)
    monkeypatch.setattr(pyrender_oracle.PyrenderOracle, "__init__", forbidden)
    monkeypatch.setattr(raster, "line_pixels", forbidden)
    monkeypatch.setattr(case_module, "draw_candidate", forbidden)
    code, report, out = run(
        tmp_path, "--level", "vertices", "--scene", "cube", "--frames", "3", "--cases", "on_axis,near_plane"
    )
    assert code == 0
    assert report["level"] == "vertices" and report["oracles"] == ["opencv"]
    for case in report["cases"]:
        assert case["pixel_f1_0px"] is None and case["pixel_f1_1px"] is None
        assert "worst_pixel_frame" not in case and "pixel_precision_0px" not in case
        assert all(not PIXEL_KEYS & set(f) for f in case["per_frame"])
        assert case["max_vertex_error_px"] < 1e-9
    assert report["summary"]["min_pixel_f1_1px"] is None
    timing = report["timing"]
    assert timing["vertex_stage_ms_per_frame"] > 0
    for t in [timing, *timing["cases"]]:
        assert "pixel_stage_ms_per_frame" not in t and "pyrender_ms_per_frame" not in t
        assert t["vertex_stage_ms_per_frame"] > 0
    assert list((out / "img").iterdir()) == []
    assert "Level: vertices" in (out / "report.md").read_text()
    assert "nothing is drawn at level vertices" in (out / "report.html").read_text()
    # an external candidate is not drawn either (draw_candidate raises above)
    code, report, _ = run(
        tmp_path,
        "--level",
        "vertices",
        "--candidate",
        f"{USER}:project",
        "--scene",
        "prism",
        "--frames",
        "2",
        "--cases",
        "near_plane",
        name="ext",
    )
    assert code == 0 and report["cases"][0]["pixel_f1_1px"] is None


def test_vertex_results_are_the_same_at_both_levels(tmp_path):
    """Level vertices takes core's vertices from the same pipeline, only without drawing."""
    args = ("--scene", "pyramid", "--frames", "3", "--cases", "near_plane,orthographic")
    _, v, _ = run(tmp_path, "--level", "vertices", *args, name="v")
    _, p, out_p = run(tmp_path, *args, name="p")
    assert p["level"] == "pixels" and p["oracles"] == ["opencv", "pyrender"]
    for cv, cp in zip(v["cases"], p["cases"], strict=True):
        assert {k: cv[k] for k in VERTEX_KEYS} == {k: cp[k] for k in VERTEX_KEYS}
        assert [f["max_vertex_error_px"] for f in cv["per_frame"]] == [
            f["max_vertex_error_px"] for f in cp["per_frame"]
        ]
        assert cp["pixel_f1_1px"] == 1.0
    timing = p["timing"]
    for t in [timing, *timing["cases"]]:
        assert t["vertex_stage_ms_per_frame"] > 0 and t["pixel_stage_ms_per_frame"] > 0
        # the oracles are OpenCV and pyrender; the harness is what the stages spend besides
        # them and the candidate (vertex stage = harness part + opencv + candidate projection)
        assert t["oracles_ms_per_frame"] == pytest.approx(t["opencv_ms_per_frame"] + t["pyrender_ms_per_frame"])
        # pyrender draws on the GL thread beside the stage: the stage holds the part it waited for
        assert t["harness_ms_per_frame"] == pytest.approx(
            t["vertex_stage_ms_per_frame"]
            + t["pixel_stage_ms_per_frame"]
            + t["pixel_metrics_beside_ms_per_frame"]
            - t["opencv_ms_per_frame"]
            - t["pyrender_wait_ms_per_frame"]
            - t["candidate_project_ms_per_frame"]
            - t["candidate_draw_ms_per_frame"]
        )
    assert timing["harness_overhead_ratio"] == pytest.approx(
        timing["harness_ms_per_frame"] / timing["oracles_ms_per_frame"]
    )
    html = (out_p / "report.html").read_text()
    assert "Time per frame" in html and "pixel stage (ms/frame)" in html


@pytest.mark.parametrize("oracles, level", [("opencv", "vertices"), ("opencv,pyrender", "pixels")])
def test_oracles_is_an_alias_of_level(tmp_path, oracles, level):
    code, report, _ = run(
        tmp_path, "--oracles", oracles, "--level", level, "--scene", "cube", "--frames", "1", "--cases", "on_axis"
    )
    assert code == 0 and report["level"] == level


# ---------------------------------------------------------------- --every


def test_every_3_over_7_frames_checks_1_4_7_at_their_own_times(tmp_path):
    args = ("--level", "vertices", "--scene", "cube", "--frames", "7", "--cases", "oblique_roll")
    code, report, out = run(tmp_path, *args, "--every", "3", name="every3")
    assert code == 0
    assert report["every"] == 3 and report["frames"] == 7 and report["frames_checked"] == 3
    case = report["cases"][0]
    assert [f["frame"] for f in case["per_frame"]] == [1, 4, 7] and case["frames_checked"] == 3
    assert report["timing"]["cases"][0]["frames_timed"] == 3
    assert "3 of 7 frames of the motion (frames 1, 4, 7: every 3)" in (out / "report.md").read_text()
    # frame k is still at t = (k - 1) / 7: the same numbers as those frames of the full run
    _, full, _ = run(tmp_path, *args, name="every1")
    assert full["every"] == 1 and full["frames_checked"] == 7
    by_frame = {f["frame"]: f for f in full["cases"][0]["per_frame"]}
    assert case["per_frame"] == [by_frame[k] for k in (1, 4, 7)]


# ---------------------------------------------------------------- --jobs


@pytest.mark.slow
def test_jobs_2_gives_the_report_of_jobs_1(tmp_path):
    args = ("--scene", "cube", "--scene", "pyramid", "--frames", "3", "--cases", "on_axis,near_plane")
    code1, r1, out1 = run(tmp_path, *args, "--jobs", "1", name="j1")
    code2, r2, out2 = run(tmp_path, *args, "--jobs", "2", name="j2")
    assert code1 == code2 == 0
    assert r1["timing"]["workers"] == 0 and r2["timing"]["workers"] == 2 and r2["timing"]["jobs"] == 2
    assert [(c["scene"], c["camera"]) for c in r2["cases"]] == [
        ("cube", "on_axis"),
        ("cube", "near_plane"),
        ("pyramid", "on_axis"),
        ("pyramid", "near_plane"),
    ]
    assert [(t["scene"], t["camera"]) for t in r2["timing"]["cases"]] == [
        (c["scene"], c["camera"]) for c in r2["cases"]
    ]
    assert without_timing(out1) == without_timing(out2)  # byte for byte, apart from timing
    assert (out1 / "report.md").read_bytes() == (out2 / "report.md").read_bytes()
    imgs = sorted(p.name for p in (out1 / "img").iterdir())
    # 4 worst frames x (candidate, oracle, diff, and the enlarged crop of the worst disagreement)
    assert len(imgs) == 16 and imgs == sorted(p.name for p in (out2 / "img").iterdir())
    for name in imgs:
        assert (out1 / "img" / name).read_bytes() == (out2 / "img" / name).read_bytes()


@pytest.mark.slow
def test_file_candidate_runs_in_workers(tmp_path):
    # a faulty projector from a file outside sys.path: each worker starts its own candidate host
    args = (
        "--candidate",
        f"{USER}:project_corner",
        "--scene",
        "prism",
        "--frames",
        "2",
        "--cases",
        "oblique_roll,non_square,orthographic",
    )
    code1, _, out1 = run(tmp_path, *args, name="j1")
    code2, r2, out2 = run(tmp_path, *args, "--jobs", "2", name="j2")
    assert code1 == code2 == 1
    assert r2["timing"]["workers"] == 2 and r2["candidate_settings"]["isolation"] == "subprocess"
    for case in r2["cases"]:
        assert [f["name"] for f in case["faults"]] == ["pixel_offset"]
        assert case["pixel_f1_1px"] is not None
    assert without_timing(out1) == without_timing(out2)


def test_more_jobs_than_cases_is_fine(tmp_path):
    code, report, _ = run(
        tmp_path, "--level", "vertices", "--scene", "cube", "--frames", "1", "--cases", "on_axis", "--jobs", "4"
    )
    assert code == 0 and len(report["cases"]) == 1 and report["timing"]["jobs"] == 4


# ---------------------------------------------------------------- usage errors


@pytest.mark.parametrize(
    "args, needle",
    [
        (["--every", "0"], "--every 0"),
        (["--every", "-2"], "--every -2"),
        (["--every", "x"], "--every"),
        (["--jobs", "0"], "--jobs 0"),
        (["--jobs", "2.5"], "--jobs"),
        (["--level", "voxels"], "--level"),
        (["--level", "vertices", "--oracles", "opencv,pyrender"], "contradicts --level vertices"),
        (["--level", "pixels", "--oracles", "opencv"], "contradicts --level pixels"),
        (["--oracles", "pyrender"], "--oracles"),
        (["--dtype", "float16"], "--dtype"),
        (["--clip", "none"], "--clip"),
        (["--raster", "smooth"], "--raster"),
        (["--dtype", "float32", "--candidate", f"{USER}:project"], "--dtype"),
        (["--clip", "clip", "--raster", "aa", "--candidate", f"{USER}:project"], "--clip, --raster"),
    ],
)
def test_bad_values_exit_2_with_one_line(tmp_path, capsys, args, needle):
    try:
        code = cli.main(["--report-dir", str(tmp_path / "r"), "--scene", "cube", *args])
    except SystemExit as exc:  # argparse's own checks (types, choices) exit from parse_args
        code = exc.code
    err = capsys.readouterr().err
    assert code == 2
    assert err.count("\n") == 1 and needle in err and "Traceback" not in err, err
    assert not (tmp_path / "r").exists()


# ---------------------------------------------------------------- the core candidate's settings


def test_core_candidate_is_a_small_frozen_picklable_dataclass():
    c = CoreCandidate(dtype="float32", clip="endpoint", raster="aa")
    assert pickle.loads(pickle.dumps(c)) == c and c.name == "core"
    assert c.settings() == {"dtype": "float32", "clip": "endpoint", "raster": "aa"}
    with pytest.raises(AttributeError):
        c.dtype = "float64"
    with pytest.raises(ValueError):
        CoreCandidate(raster="smooth")


def test_core_settings_reach_render_frame(monkeypatch):
    from wirecheck.core.projector import pipeline
    from wirecheck.oracles.cases import cameras_for

    calls = []

    def fake_render_frame(p_model, edges, camera, model_matrix, clip_mode="clip", **kw):
        calls.append((clip_mode, kw))
        image = np.zeros((camera.height, camera.width), np.uint8)
        image[0, :3] = (127, 128, 255)  # "aa" coverage: drawn from 128 up

        class F:
            pass

        f = F()
        f.image, f.p_px = image, np.zeros((len(p_model), 2))
        return f

    monkeypatch.setattr(pipeline, "render_frame", fake_render_frame)
    cam = cameras_for(1.0)[0].camera
    pts, edges = np.zeros((2, 3)), np.array([[0, 1]])
    CoreCandidate().project(CoreCandidate().prepare(pts), cam, np.eye(4))
    cand = CoreCandidate(dtype="float32", clip="endpoint", raster="aa")
    prepared = cand.prepare(pts)
    assert prepared.dtype == np.float32  # the dtype reaches core through localize()
    img = cand.draw(prepared, edges, cam, np.eye(4))
    assert calls[0] == ("clip", {"raster": "exact"})
    assert calls[1] == ("endpoint", {"raster": "aa"})
    assert img[0, :3].tolist() == [False, True, True] and img.sum() == 2


def test_clip_endpoint_reaches_core_and_the_pixel_oracle_sees_it(tmp_path):
    # near_plane: edges cross the near plane; "endpoint" drops them where pyrender clips them
    code, report, _ = run(
        tmp_path, "--clip", "endpoint", "--scene", "cube", "--frames", "4", "--cases", "near_plane,on_axis"
    )
    assert code == 1
    assert report["candidate_settings"] == {"dtype": "float64", "clip": "endpoint", "raster": "exact"}
    on_axis, near = report["cases"]  # cases run in the order of oracles.cases.CASE_NAMES
    assert near["max_vertex_error_px"] < 1e-9 and near["pixel_f1_1px"] < 0.9  # measured 0.72
    assert on_axis["verdict"] == "pass" and on_axis["pixel_f1_1px"] == 1.0  # nothing to clip there


def test_default_settings_are_recorded(tmp_path):
    _, report, out = run(tmp_path, "--level", "vertices", "--scene", "cube", "--frames", "1", "--cases", "on_axis")
    assert report["candidate_settings"] == {"dtype": "float64", "clip": "clip", "raster": "exact"}
    assert "(dtype = float64, clip = clip, raster = exact)" in (out / "report.md").read_text()


def test_float32_reaches_core(tmp_path):
    code, report, _ = run(
        tmp_path, "--level", "vertices", "--dtype", "float32", "--scene", "cube", "--frames", "2", "--cases", "on_axis"
    )
    err = report["cases"][0]["max_vertex_error_px"]
    # float64 gives ~1e-13 px; float32 rounding shows at ~1e-5 px (eps 6e-8 x 640 px)
    assert 1e-9 < err < 1e-2, err
    assert report["candidate_settings"]["dtype"] == "float32"


@pytest.mark.parametrize("raster", ["fast", "aa"])
def test_other_rasters_are_drawn_and_judged(tmp_path, raster):
    code, report, _ = run(
        tmp_path, "--raster", raster, "--scene", "cube", "--frames", "2", "--cases", "on_axis,oblique_roll"
    )
    assert report["candidate_settings"]["raster"] == raster
    for case in report["cases"]:
        assert case["max_vertex_error_px"] < 1e-9  # the rasterizer changes pixels, not vertices
        assert case["pixel_f1_1px"] > 0.9, (raster, case["pixel_f1_1px"])
