"""The frames path judged by the one judge (oracles.judge.decide): lines, balance, per-edge counts, each threshold.

A job is exported and its frames drawn by core (tests/test_frames_candidate.py
shows how): core's exact frames must pass; the same frames with every line's
last pixel dropped (tests/raster_mutants.drop_last, ~8 pixels a frame, all at
one end) must fail as ``line_end_bias``, as on the projector path; and for
each threshold a frame set where it alone turns pass into fail (every other
criterion switched off, as tests/test_line_gate.py does for the projector
path). The frames path and the projector path must count the same one-sided
pixels for the same frames.
"""

from __future__ import annotations

import json
import shutil
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from helpers import fill_job  # tests/ is on sys.path (rootdir conftest)
from raster_mutants import drop_last
from wirecheck.core.projector import raster
from wirecheck.core.scene.files import load_scene
from wirecheck.oracles import tolerances
from wirecheck.oracles.cli import main
from wirecheck.oracles.judge import metrics
from wirecheck.oracles.judge.frames_judge import diagnosis_frames, run_frames
from wirecheck.oracles.runner import CoreCandidate, Tolerances, run_crosscheck

# frames 1 and 4 of 6 (the cube square-on and half a turn on), seen by an oblique camera and an orthographic one
ARGS = ["--scene", "cube", "--cases", "oblique_roll,orthographic", "--frames", "6", "--every", "3"]

# Every other criterion switched off so that only the one under test can decide
# (as tests/test_line_gate.OPEN): F1 floors 0, balance alpha 0 (p < 0 never), counts of any size.
OPEN = Tolerances(
    vertex_px=1.0,
    min_f1_1px=0.0,
    min_f1_0px=0.0,
    min_iou=0.0,
    balance_alpha=0.0,
    max_imbalance=1.0,
    max_edge_count_diff=10**6,
)


@pytest.fixture(scope="module")
def job_dir(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("job") / "job"
    assert main(["export", str(path)] + ARGS) == 0
    return path


def _filled(job_dir: Path, tmp: Path, edit=lambda img: img) -> Path:
    d = tmp / "filled"
    shutil.copytree(job_dir, d)
    fill_job(d, edit)
    return d


@pytest.fixture(scope="module")
def exact(job_dir, tmp_path_factory) -> Path:
    return _filled(job_dir, tmp_path_factory.mktemp("exact"))


@pytest.fixture(scope="module")
def short(job_dir, tmp_path_factory) -> Path:
    """Core's frames with every line's last pixel dropped (the rasterizer patched while they are drawn)."""
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(raster, "_line_pixels", drop_last)
        return _filled(job_dir, tmp_path_factory.mktemp("short"))


@pytest.fixture(scope="module")
def stray(job_dir, tmp_path_factory) -> Path:
    """Core's frames and pixel (0, 0), far from every line (F1@1px < 1, nothing else changes but balance)."""

    def edit(img):
        img[0, 0] = 255
        return img

    return _filled(job_dir, tmp_path_factory.mktemp("stray"), edit)


def test_core_exact_frames_pass_with_line_scores(exact):
    report, _ = run_frames(exact)
    assert report["verdict"] == "pass", [c["reasons"] for c in report["cases"]]
    for case in report["cases"]:
        lines = case["lines"]
        # core's exact lines against Mesa's: a few tie pixels decided either way, none systematic
        assert abs(lines["imbalance_fraction"]) <= tolerances.MAX_IMBALANCE_FRACTION
        assert lines["edge_count_max_diff"] <= 1 and lines["lines_compared"] > 0
        assert case["faults"] == [] and all("candidate_only" in f for f in case["per_frame"])
        # each frame's fields in report.json's order: the candidate's F1s, core's second opinion, the counts,
        # then the lines' (metrics.LINE_FRAME_KEYS)
        assert all(
            list(f)
            == ["frame", "f1_0px", "f1_1px", "core_f1_0px", "core_f1_1px", "candidate_pixels", "oracle_pixels"]
            + list(metrics.LINE_FRAME_KEYS)
            for f in case["per_frame"]
        )
    # the report states every limit the frames were judged by, the line gate's included
    assert report["tolerances"]["max_edge_count_diff"] == tolerances.MAX_EDGE_COUNT_DIFF
    assert report["tolerances"]["balance_alpha"] == tolerances.BALANCE_ALPHA


def test_compared_counts_and_the_worst_frame(exact):
    """``compared``: the frames, no vertex, and the pixels drawn by either side (the gate's "nothing
    compared"); the worst frame's images are that frame's."""
    from PIL import Image
    from wirecheck.oracles.candidates.frames_candidate import load_job

    report, images = run_frames(exact)
    job = load_job(exact)
    for case, listed in zip(report["cases"], job["cases"]):
        per = case["per_frame"]
        # the worst frame's images: the frame of least (F1@1px, F1@0px), the first of ties, and its PNG's pixels
        worst = min(per, key=lambda f: (f["f1_1px"], f["f1_0px"]))["frame"]
        im = images[(case["scene"], case["camera"])]
        assert im["frame"] == case["worst_pixel_frame"] == worst
        rel = listed["frames"][[f["frame"] for f in per].index(worst)]
        assert np.array_equal(im["candidate"], np.asarray(Image.open(exact / rel).convert("L")) >= 128)
        # the candidate's count, read here from its PNGs by the frames rule (drawn where grey >= 128)
        assert [f["candidate_pixels"] for f in per] == [
            int((np.asarray(Image.open(exact / rel).convert("L")) >= 128).sum()) for rel in listed["frames"]
        ]
        # |A u B| lies in [max(|A|, |B|), |A| + |B|), the upper end open as the two sides share pixels
        # (core's exact lines against the oracle's: F1@0px near 1)
        low = sum(max(f["candidate_pixels"], f["oracle_pixels"]) for f in per)
        high = sum(f["candidate_pixels"] + f["oracle_pixels"] for f in per)
        assert low <= case["compared"]["pixels"] < high, (low, case["compared"]["pixels"], high)
        # every listed frame compared, and no vertex: a renderer's frames carry none
        assert (case["compared"]["frames"], case["compared"]["vertices"]) == (len(listed["frames"]), 0)
    assert report["compared"]["pixels"] == sum(c["compared"]["pixels"] for c in report["cases"])


def test_frames_minus_each_last_pixel_fail_as_line_end_bias(short):
    report, _ = run_frames(short)
    assert report["verdict"] == "fail"
    for case in report["cases"]:
        # what the old frames judge saw: F1 at both tolerances above its floors (so it passed, exit 0)
        assert case["pixel_f1_1px"] >= tolerances.MIN_F1_1PX and case["pixel_f1_0px"] >= tolerances.MIN_F1_0PX
        assert case["verdict"] == "fail"
        assert case["reasons"][0].startswith("one-sided pixels unbalanced"), case["reasons"]
        assert case["lines"]["oracle_only"] > 5 * case["lines"]["candidate_only"]
        (fault,) = case["faults"]
        # most of the 12 lines lose their last pixel; some of those are drawn by a line starting
        # there: as on the projector path (tests/test_line_gate.py), -0.3 to -1 per line
        assert fault["name"] == "line_end_bias" and fault["end"] == "last", fault
        assert -1.0 <= fault["pixels_per_line"] <= -0.3, fault


def test_frames_cli_exit_1_for_the_short_lines(short, tmp_path, capsys):
    assert main(["--candidate-frames", str(short), "--report-dir", str(tmp_path / "rep")]) == 1
    assert "line_end_bias" in capsys.readouterr().out


@pytest.fixture(scope="module")
def mirrored(job_dir, tmp_path_factory) -> Path:
    """Core's frames flipped left to right (a renderer with x mirrored)."""
    return _filled(job_dir, tmp_path_factory.mktemp("mirrored"), lambda img: img[:, ::-1].copy())


def test_a_geometric_fault_is_named_before_the_lines(mirrored):
    # a mirrored picture fails the line gate too (whole lines elsewhere: per-edge counts off by
    # tens of pixels), but the fault is the mirror, named from the images; a line fault is named
    # only when the geometry agrees
    report, _ = run_frames(mirrored)
    case = next(c for c in report["cases"] if c["camera"] == "oblique_roll")
    assert case["verdict"] == "fail" and case["lines"]["edge_count_max_diff"] > tolerances.MAX_EDGE_COUNT_DIFF
    assert [f["name"] for f in case["faults"]] == ["mirror_horizontal"], case["faults"]


def test_both_paths_count_the_same_one_sided_pixels(monkeypatch, short):
    """The projector path on core (rasterizer patched alike) against the frames path on core's PNGs."""
    monkeypatch.setattr(raster, "_line_pixels", drop_last)
    projector, _ = run_crosscheck(
        [load_scene("cube")],
        CoreCandidate(),
        frames=6,
        every=3,
        case_names=["oblique_roll", "orthographic"],
        animation=False,
    )
    frames, _ = run_frames(short)
    keys = ("candidate_only", "oracle_only", "subpixel_ties", "edge_count_max_diff", "one_sided_by_place")
    for p, f in zip(projector["cases"], frames["cases"]):
        assert (p["scene"], p["camera"]) == (f["scene"], f["camera"])
        assert {k: p["lines"][k] for k in keys} == {k: f["lines"][k] for k in keys}
        assert [x["name"] for x in p["faults"]] == [x["name"] for x in f["faults"]] == ["line_end_bias"]


# ---------------------------------------------------------------- each threshold decides, on the frames path


def _decides(job, field, at, past, prefix, base=OPEN):
    """``field`` = ``at`` passes, ``field`` = ``past`` fails, with exactly the one reason ``prefix``."""
    ok, _ = run_frames(job, tol=replace(base, **{field: at}))
    assert ok["verdict"] == "pass", [c["reasons"] for c in ok["cases"]]
    bad, _ = run_frames(job, tol=replace(base, **{field: past}))
    worst = [c for c in bad["cases"] if c["verdict"] == "fail"]
    assert bad["verdict"] == "fail" and worst
    for c in worst:
        assert len(c["reasons"]) == 1 and c["reasons"][0].startswith(prefix), c["reasons"]
    return worst


def _lowest(job, key):
    report, _ = run_frames(job, tol=OPEN)
    assert report["verdict"] == "pass"
    return min(c[key] for c in report["cases"])


def test_min_f1_1px_decides_on_frames(stray):
    f1 = _lowest(stray, "pixel_f1_1px")
    assert 0.99 < f1 < 1.0  # one stray pixel among ~1,000
    failed = _decides(stray, "min_f1_1px", f1, np.nextafter(f1, 2.0), "pixel F1@1px")
    # the geometry is right (nothing named from the images) and the line gate is off: a failure
    # nothing explains is `unexplained`, never "no fault" (oracles.judge.decide.decide); its advice says
    # which sets differ (oracles.diagnosis.image_visibility): pixel (0, 0), far from every line, in each of
    # the case's two frames, and no oracle pixel missing
    for c in failed:
        (fault,) = c["faults"]
        assert fault["name"] == "unexplained", c["faults"]
        assert (fault["candidate_only_px"], fault["oracle_only_px"]) == (2, 0), fault
        assert "rotation" not in fault["hint"].replace("not the rotation", ""), fault


def test_min_f1_0px_decides_on_frames(short):
    f1 = _lowest(short, "pixel_f1_0px")
    assert 0.98 < f1 < 1.0  # ~8 end pixels among ~1,000
    _decides(short, "min_f1_0px", f1, np.nextafter(f1, 2.0), "pixel F1@0px")


def test_balance_decides_on_frames(short):
    report, _ = run_frames(short, tol=OPEN)
    fracs = [abs(c["lines"]["imbalance_fraction"]) for c in report["cases"]]
    ps = [c["lines"]["balance_p_value"] for c in report["cases"]]
    assert min(fracs) > 2e-3 and max(ps) < 1e-3  # ~8 of ~1,000 pixels a frame, all one-sided one way
    # the net fraction alone (alpha 1: every p rejects symmetry): allowed up to the largest case's, then
    # just below the smallest case's
    _decides(
        short,
        "max_imbalance",
        max(fracs),
        np.nextafter(min(fracs), 0.0),
        "one-sided pixels unbalanced",
        base=replace(OPEN, balance_alpha=1.0),
    )
    # the sign test alone (any net fraction too much): alpha 0 never rejects, just above the largest p does
    _decides(
        short,
        "balance_alpha",
        0.0,
        np.nextafter(max(ps), 2.0),
        "one-sided pixels unbalanced",
        base=replace(OPEN, max_imbalance=0.0),
    )


def test_edge_count_decides_on_frames(short):
    report, _ = run_frames(short, tol=OPEN)
    worst = max(c["lines"]["edge_count_max_diff"] for c in report["cases"])
    assert worst >= 1  # a line one pixel short
    _decides(short, "max_edge_count_diff", worst, worst - 1, "edge ")


def test_diagnosis_frames_are_evenly_spread():
    assert diagnosis_frames(5, 24) == {0, 1, 2, 3, 4}
    # 720 frames, 24 kept: 0 and 719, steps of 719 / 23 = 31.26 rounded
    kept = sorted(diagnosis_frames(720, 24))
    assert len(kept) == 24 and kept[0] == 0 and kept[-1] == 719
    assert all(31 <= b - a <= 32 for a, b in zip(kept, kept[1:]))


def test_readme_says_when_every_frame_is_a_quarter_turn():
    from wirecheck.oracles.candidates.export import build_job

    cube = [load_scene("cube")]
    # frame k turns (k - 1) / frames of a turn about X and Y (spin 1,1,0): with 4 frames, 0, 1/4, 1/2, 3/4
    _job, files = build_job(cube, frames=4, case_names=["on_axis"])
    readme = files["README.md"].decode()
    assert "## What this job cannot reveal" in readme
    assert "**Every frame of this job is a quarter-turn pose** (frames 1, 2, 3, 4 of\n4, spin 1,1,0)" in readme
    # frames 1, 6, 11, 16, 21 of 24: frame 6 turns 5/24 of a turn = 5/6 of a quarter: oblique
    _job, files = build_job(cube, frames=24, every=5, case_names=["on_axis"])
    readme = files["README.md"].decode()
    assert "## What this job cannot reveal" in readme and "quarter-turn pose" not in readme


def _core_frames(files: dict, job: dict, scene) -> dict:
    """Core's drawing of every frame of a built job (``{case: [bool image per frame]}``), from its camera files."""
    import json

    from wirecheck.core.camera import Camera
    from wirecheck.core.projector.pipeline import render_frame

    out = {}
    for c in job["cases"]:
        out[c["case"]] = []
        for k in job["frame_numbers"]:
            cj = json.loads(files[f"cameras/{scene.name}/{c['case']}/frame_{k:04d}.json"])
            out[c["case"]].append(
                render_frame(scene.vertices, scene.edges, Camera(**cj["camera"]), np.asarray(cj["model_matrix"])).image
                >= 128
            )
    return out


def test_export_phase_moves_a_short_job_off_the_quarter_turns(tmp_path, capsys):
    from itertools import combinations

    from wirecheck.oracles.candidates.export import build_job, quarter_turn_frames
    from wirecheck.oracles.candidates.frames_candidate import FramesError, load_job

    cube = load_scene("cube")
    cases = ["on_axis", "oblique_roll", "orthographic"]
    # --frames 4, crosscheck's own poses: quarter turns (0, 1/4, 1/2, 3/4 of a turn about X and Y); the
    # cube on the optical axis is then square-on in every frame: four identical pictures, each its own
    # mirror image (left-right and up-down), which a mirrored renderer draws pixel for pixel
    job, files = build_job([cube], frames=4, case_names=cases)
    on_axis = _core_frames(files, job, cube)["on_axis"]
    assert quarter_turn_frames(job) and all((img == on_axis[0]).all() for img in on_axis)
    assert all((img[:, ::-1] == img).all() and (img[::-1] == img).all() for img in on_axis)
    # --phase 0.3: frame k at t = (k - 0.7) / 4 (0.3 of a frame's step on): no quarter turn; in no case
    # do two frames draw the same pixels, nor is a frame its own mirror image
    job, files = build_job([cube], frames=4, case_names=cases, phase=0.3)
    assert not quarter_turn_frames(job) and job["motion"]["phase"] == 0.3
    assert json.loads(files["cameras/cube/on_axis/frame_0002.json"])["t"] == pytest.approx(1.3 / 4, abs=1e-15)
    for case, images in _core_frames(files, job, cube).items():
        assert not any((a == b).all() for a, b in combinations(images, 2)), case
        assert not any((img[:, ::-1] == img).all() or (img[::-1] == img).all() for img in images), case
    readme = files["README.md"].decode()
    assert "quarter-turn pose" not in readme and "(`--phase 0.3`)" in readme
    # the job reads back; a phase outside [0, 1) is refused, on the command line and in job.json
    path = tmp_path / "job"
    assert main(["export", str(path), "--scene", "cube", "--cases", "on_axis", "--frames", "4", "--phase", "0.3"]) == 0
    assert load_job(path)["motion"]["phase"] == 0.3
    assert main(["export", str(tmp_path / "bad"), "--scene", "cube", "--frames", "4", "--phase", "1"]) == 2
    assert "--phase 1.0: expected a number in [0, 1)" in capsys.readouterr().err
    manifest = json.loads((path / "job.json").read_text())
    manifest["motion"]["phase"] = -0.5
    (path / "job.json").write_text(json.dumps(manifest))
    with pytest.raises(FramesError, match=r"motion.phase -0.5: expected a number in \[0, 1\)"):
        load_job(path)
