"""Jobs that ask for depth maps and filled frames (``crosscheck export --outputs ...``), judged end to end by
``crosscheck --candidate-frames`` (oracles.judge.depth_frames, filled_frames, in the frames judge's case loop).

The candidate renderer is core's own depth buffer (core.projector.zbuffer, ``style="shaded"``), drawn from the
job's own files as a renderer would: correct, its maps pass as float32 .npy and as a 16-bit PNG at scale 1000;
with one mistake injected each, they fail with the name of that mistake (the expected name is the mistake's,
written here, never read from the code under test). A job never passes on nothing: a blank or all-NaN map fails,
a missing or wrong-size file and a hand-edited encoding are one line on stderr and exit 2.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
from clients.core_depth_job import CAMERA_MISTAKES, MISTAKES, render_job  # tests/ is on sys.path (rootdir conftest)
from helpers import run_crosscheck
from wirecheck.oracles.candidates.frames_candidate import load_job
from wirecheck.oracles.cli import main
from wirecheck.oracles.judge.surfaces import surface_mismatch

# frames 1, 4, 7 of 7, moved on by 0.3 of a step (no quarter-turn pose: a flipped cube is not the cube),
# through a perspective camera at an angle and the orthographic one
ARGS = ["--scene", "cube", "--cases", "oblique_roll,orthographic", "--frames", "7", "--every", "3", "--phase", "0.3"]


def export(path: Path, *extra) -> Path:
    assert main(["export", str(path), *ARGS, *extra]) == 0
    return path


def fill(job_dir: Path, mistake=MISTAKES["none"], filled=lambda covered: covered) -> Path:
    """Every file the job lists, drawn by core (tests/clients/core_depth_job.py: the job's files read without
    wirecheck's reader), its depth maps made by ``mistake(z, camera)`` from core's linear depth."""
    render_job(job_dir, mistake, filled)
    return job_dir


@pytest.fixture(scope="module")
def depth_job(tmp_path_factory) -> Path:
    return export(tmp_path_factory.mktemp("depth") / "job", "--outputs", "depth")


def copy(job: Path, tmp_path: Path) -> Path:
    shutil.copytree(job, tmp_path / "job")
    return tmp_path / "job"


def test_core_depth_as_float32_npy_passes(depth_job, tmp_path, capsys):
    job = fill(copy(depth_job, tmp_path))
    code, report, _ = run_crosscheck(tmp_path, "--candidate-frames", str(job))
    assert code == 0, capsys.readouterr().out
    for case in report["cases"]:
        d = case["depth_map"]
        # every reference pixel compared (the cube's faces meet at shared vertices: no occlusion boundary)
        assert d["compared_px"] == d["reference_px"] > 0 and d["holes_px"] == d["extra_px"] == 0
        assert d["max_error_ratio"] <= 1.0 and d["encoding"] == "npy float32"
    assert report["outputs"] == ["depth"] and report["compared"]["pixels"] > 0


def test_core_depth_as_png16_at_scale_1000_passes(tmp_path, capsys):
    job = fill(export(tmp_path / "job", "--outputs", "depth", "--depth-format", "png16", "--depth-scale", "1000"))
    code, report, _ = run_crosscheck(tmp_path, "--candidate-frames", str(job))
    assert code == 0, capsys.readouterr().out
    assert {c["depth_map"]["encoding"] for c in report["cases"]} == {"png uint16 / 1000"}
    # rounded to 1 mm: the error is half the 1 mm step plus core's own difference from pyrender (at most
    # 2.9e-5 on these frames as float32 .npy, the test above): within 0.5e-3 + 1e-4, and the step shows
    worst = max(c["depth_map"]["max_error"] for c in report["cases"])
    assert 0.4e-3 < worst <= 0.5e-3 + 1e-4


@pytest.mark.parametrize(
    "mistake, expected",
    [
        ("zbuffer", "depth_encoding"),  # the z-buffer's [0, 1] value stored as depth
        ("x1000", "depth_scale"),  # millimetres written where world units were asked for
        ("rows_flipped", "mirror_vertical"),  # GL's bottom row written first
    ],
)
def test_a_mistaken_depth_map_fails_with_its_name(depth_job, tmp_path, capsys, mistake, expected):
    job = fill(copy(depth_job, tmp_path), MISTAKES[mistake])
    code, report, _ = run_crosscheck(tmp_path, "--candidate-frames", str(job))
    out = capsys.readouterr().out
    assert code == 1, out
    for case in report["cases"]:
        assert case["verdict"] == "fail"
        assert [f["name"] for f in case["faults"]] == [expected], (case["camera"], case["faults"])
    assert expected in out


@pytest.fixture(scope="module")
def perspective_job(tmp_path_factory) -> Path:
    """A perspective camera alone: an orthographic camera has no K to get wrong."""
    path = tmp_path_factory.mktemp("persp") / "job"
    assert main(["export", str(path), *ARGS[:3], "oblique_roll", *ARGS[4:], "--outputs", "depth"]) == 0
    return path


@pytest.mark.parametrize(
    "mistake, expected",
    [
        ("half_pixel", "pixel_offset"),  # cx = W / 2 for (W - 1) / 2: the map moved by half a pixel
        ("fov_horizontal", "fov_mismatch"),  # K from the FOV taken as the horizontal one
    ],
)
def test_a_camera_mistake_in_a_depth_map_is_named(perspective_job, tmp_path, mistake, expected):
    job = copy(perspective_job, tmp_path)
    render_job(job, camera=CAMERA_MISTAKES[mistake])
    code, report, _ = run_crosscheck(tmp_path, "--candidate-frames", str(job))
    assert code == 1
    (case,) = report["cases"]
    assert [f["name"] for f in case["faults"]] == [expected], case["faults"]
    fault = case["faults"][0]
    # the mistakes' own numbers (docs/depth.md: fitted within 0.01 px, the scale within 1e-4): half a pixel
    # each way, read back where the reference is sampled (T(p) = p + d: d = -0.5); the focal length H / W
    if expected == "pixel_offset":
        assert abs(fault["dx"] + 0.5) < 0.01 and abs(fault["dy"] + 0.5) < 0.01, fault
    else:
        assert abs(fault["scale"] - case["camera_spec"]["height"] / case["camera_spec"]["width"]) < 1e-4, fault


def test_a_blank_map_fails(depth_job, tmp_path, capsys):
    job = fill(copy(depth_job, tmp_path), lambda z, cam: np.zeros_like(z))
    code, report, _ = run_crosscheck(tmp_path, "--candidate-frames", str(job))
    assert code == 1
    for case in report["cases"]:
        assert case["verdict"] == "fail" and case["depth_map"]["compared_px"] == 0
        assert case["depth_map"]["blank_frames"] == [1, 4, 7]
        assert any("compare nothing" in r for r in case["reasons"])


def test_an_all_nan_map_fails(depth_job, tmp_path):
    job = fill(copy(depth_job, tmp_path), lambda z, cam: np.full_like(z, np.nan))
    code, report, _ = run_crosscheck(tmp_path, "--candidate-frames", str(job))
    assert code == 1 and {c["verdict"] for c in report["cases"]} == {"fail"}


def test_a_map_whose_surface_never_meets_the_references_fails(depth_job, tmp_path):
    """Zero overlap through a job: each map shows a surface (1.0) exactly where the reference shows none and
    nothing where it shows one: no pixel compared on both sides, never a pass (not blank either: the map
    draws)."""
    job = fill(copy(depth_job, tmp_path), lambda z, cam: np.where(z > 0, 0.0, 1.0))
    code, report, _ = run_crosscheck(tmp_path, "--candidate-frames", str(job))
    assert code == 1
    for case in report["cases"]:
        d = case["depth_map"]
        assert case["verdict"] == "fail" and d["compared_px"] == 0 and d["reference_px"] > 0
        assert d["blank_frames"] == []  # each map draws a surface: the failure is the overlap, not a blank
        assert any("compare nothing" in r for r in case["reasons"])


def test_a_hole_inside_the_surface_fails(depth_job, tmp_path):
    """A 3x3 patch of no surface in the middle of a face: 9 holes a frame (the patch and its neighbours are
    covered by the reference: away from any boundary), nothing else."""

    def hole(z, cam):
        out = z.copy()
        rows, cols = np.nonzero(z > 0)
        r, c = int(np.median(rows)), int(np.median(cols))
        assert (z[r - 2 : r + 3, c - 2 : c + 3] > 0).all()  # the patch and its ring on the surface
        out[r - 1 : r + 2, c - 1 : c + 2] = 0.0
        return out

    job = fill(copy(depth_job, tmp_path), hole)
    code, report, _ = run_crosscheck(tmp_path, "--candidate-frames", str(job))
    assert code == 1
    for case in report["cases"]:
        assert case["depth_map"]["holes_px"] == 9 * 3 and case["depth_map"]["extra_px"] == 0
        assert any("left empty" in r for r in case["reasons"])


def test_core_depth_as_float_tiff_passes(tmp_path, capsys):
    job = fill(export(tmp_path / "job", "--outputs", "depth", "--depth-format", "tiff"))
    assert load_job(job)["cases"][0]["depth"][0].endswith("/depth_0001.tif")
    code, report, _ = run_crosscheck(tmp_path, "--candidate-frames", str(job))
    assert code == 0, capsys.readouterr().out
    assert {c["depth_map"]["encoding"] for c in report["cases"]} == {"tiff float32"}


def _one_line(capsys, *needles):
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err, err
    for needle in needles:
        assert needle in err, err
    return err


def test_a_wrong_size_map_is_exit_2(depth_job, tmp_path, capsys):
    job = fill(copy(depth_job, tmp_path))
    path = job / load_job(job)["cases"][0]["depth"][1]
    np.save(path, np.ones((10, 12), np.float32))
    capsys.readouterr()
    code, report, run = run_crosscheck(tmp_path, "--candidate-frames", str(job))
    assert code == 2 and report is None and not run.exists()
    _one_line(capsys, str(path), "expected 640x480")


def test_a_missing_map_is_exit_2(depth_job, tmp_path, capsys):
    job = fill(copy(depth_job, tmp_path))
    path = job / load_job(job)["cases"][1]["depth"][2]
    path.unlink()
    capsys.readouterr()
    code, report, _ = run_crosscheck(tmp_path, "--candidate-frames", str(job))
    assert code == 2 and report is None
    _one_line(capsys, str(path), "missing")


@pytest.mark.parametrize(
    "encoding, needle",
    [
        ({"format": "exr", "scale": None}, "depth_encoding"),
        ({"format": "png16", "scale": 0}, "depth_encoding.scale 0"),
        ({"format": "npy", "scale": 1000.0}, "expected null"),
    ],
)
def test_a_hand_edited_encoding_is_exit_2(depth_job, tmp_path, capsys, encoding, needle):
    job = fill(copy(depth_job, tmp_path))
    data = json.loads((job / "job.json").read_text())
    data["depth_encoding"] = encoding
    (job / "job.json").write_text(json.dumps(data))
    capsys.readouterr()
    code, report, _ = run_crosscheck(tmp_path, "--candidate-frames", str(job))
    assert code == 2 and report is None
    _one_line(capsys, "job.json", needle)


def test_hand_edited_objects_are_exit_2(depth_job, tmp_path, capsys):
    job = fill(copy(depth_job, tmp_path))
    data = json.loads((job / "job.json").read_text())
    data["scenes"][0]["objects"] = [4, 3]  # the cube has 8 vertices
    (job / "job.json").write_text(json.dumps(data))
    capsys.readouterr()
    code, report, _ = run_crosscheck(tmp_path, "--candidate-frames", str(job))
    assert code == 2 and report is None
    _one_line(capsys, "job.json", "objects [4, 3]", "8 in all")


def test_a_map_under_another_suffix_than_asked_is_exit_2(depth_job, tmp_path, capsys):
    """The job asks for .npy: a .png beside it is not the job's (and the .npy is missing)."""
    job = fill(copy(depth_job, tmp_path))
    path = job / load_job(job)["cases"][0]["depth"][0]
    path.rename(path.with_suffix(".png"))
    capsys.readouterr()
    code, _report, _ = run_crosscheck(tmp_path, "--candidate-frames", str(job))
    assert code == 2
    err = capsys.readouterr().err
    assert "not a frame of this job" in err and "missing" in err and "Traceback" not in err


def test_wireframes_filled_frames_and_depth_together(tmp_path, capsys):
    job = fill(export(tmp_path / "job", "--outputs", "depth,wireframe,filled"))
    listed = load_job(job)["cases"][0]
    assert [Path(p).name for p in listed["frames"] + listed["filled"] + listed["depth"]][::3] == [
        "frame_0001.png",
        "filled_0001.png",
        "depth_0001.npy",
    ]
    code, report, _ = run_crosscheck(tmp_path, "--candidate-frames", str(job))
    assert code == 0, capsys.readouterr().out
    for case in report["cases"]:
        assert case["pixel_f1_1px"] >= 0.999 and case["filled"]["min_iou"] == 1.0
        assert case["filled"]["holes_px"] == case["filled"]["extra_px"] == case["filled"]["longest_run_px"] == 0


def drop_top(covered: np.ndarray) -> np.ndarray:
    """``covered`` without the topmost covered pixel of each column of its left half: a one-pixel band missing
    along the silhouette's upper left edge."""
    out = covered.copy()
    cols = np.flatnonzero(covered.any(axis=0))
    cols = cols[: len(cols) // 2]
    out[covered.argmax(axis=0)[cols], cols] = False
    return out


@pytest.fixture(scope="module")
def filled_job(tmp_path_factory) -> Path:
    return export(tmp_path_factory.mktemp("filled") / "job", "--outputs", "filled")


def test_filled_frames_flipped_or_blank_fail(filled_job, tmp_path):
    job = fill(copy(filled_job, tmp_path), filled=lambda covered: covered[::-1])
    code, report, _ = run_crosscheck(tmp_path, "--candidate-frames", str(job), name="flipped")
    assert code == 1
    assert all(c["filled"]["min_iou"] < 0.995 and c["filled"]["extra_px"] > 0 for c in report["cases"])
    # named from the silhouettes (oracles.diagnosis.silhouette_faults): the rows written bottom first. An
    # orthographic cube's silhouette is centrally symmetric (a parallel projection of a centrally symmetric
    # solid), so its rows flipped are its columns flipped: ambiguous between the two mirrors
    named = {c["camera"]: c["faults"] for c in report["cases"]}
    assert [f["name"] for f in named["oblique_roll"]] == ["mirror_vertical"]
    (f,) = named["orthographic"]
    assert f["name"] == "ambiguous" and f["alternatives"] == "mirror_horizontal, mirror_vertical"
    fill(job, filled=np.zeros_like)
    code, report, _ = run_crosscheck(tmp_path, "--candidate-frames", str(job), name="blank")
    assert code == 1
    assert all(c["filled"]["blank_frames"] == [1, 4, 7] for c in report["cases"])
    assert all(any("blank where the reference shows a surface" in r for r in c["reasons"]) for c in report["cases"])


def test_a_one_pixel_band_missing_along_an_edge_fails(filled_job, tmp_path):
    """The band is a run of decided pixels as long as the silhouette is wide (the fill rule's ties, pixel
    centres within 2^-8 px of an edge, are a few of them at most), which IoU alone hides on a silhouette of
    tens of thousands of pixels: the run fails the case (oracles.judge.silhouette, tests/test_silhouette.py)."""
    job = fill(copy(filled_job, tmp_path), filled=drop_top)
    code, report, _ = run_crosscheck(tmp_path, "--candidate-frames", str(job))
    assert code == 1
    for case in report["cases"]:
        f = case["filled"]
        assert f["longest_run_px"] >= 50 and f["extra_px"] == 0, f
        assert any("in one run" in r for r in case["reasons"])
    assert min(c["filled"]["min_iou"] for c in report["cases"]) >= 0.995  # IoU alone would pass


def test_a_default_export_is_a_wireframe_job_as_before(tmp_path):
    """No --outputs: job.json without the new keys (every existing job and doc sample unchanged)."""
    job = json.loads((export(tmp_path / "job") / "job.json").read_text())
    assert "outputs" not in job and "depth_encoding" not in job
    assert set(job["cases"][0]) == {"scene", "case", "width", "height", "frames"}


def test_the_readme_says_what_to_write(tmp_path):
    job = export(tmp_path / "job", "--outputs", "depth", "--depth-format", "png16", "--depth-scale", "5000")
    text = " ".join((job / "README.md").read_text().split())
    assert "frames/<scene>/<case>/depth_NNNN.png" in text and "scale 5000 per world unit" in text
    assert "depth along the camera's forward" in text and "row 0 at the top" in text
    assert "0, NaN or +inf where no face is seen" in text
    assert json.loads((job / "job.json").read_text())["depth_encoding"] == {"format": "png16", "scale": 5000.0}
    # a GL renderer's depth buffer made linear from gl_projection's standard depth range (the formula a
    # moderngl client follows and passes with: tests/test_depth_job_renderers.py), the rows flipped
    assert "`d = 2 f n / ((f + n) - (2 z - 1) (f - n))` (orthographic: `d = n + z (f - n)`)" in text
    assert "GL's row 0 is the bottom row" in text
    assert "the fan of triangles from its first vertex" in text
    assert "world per frame" not in text  # the cube: one OBJ in model space


@pytest.mark.parametrize("outputs", [[], ["--outputs", "filled,depth"]])
def test_the_readme_says_where_a_world_space_scene_is(tmp_path, outputs):
    """The orrery (several moving objects) has no scenes/orrery.obj: its OBJ per frame is in world space."""
    job = tmp_path / "job"
    assert (
        main(
            [
                "export",
                str(job),
                "--scene",
                "orrery",
                "--scene",
                "cube",
                "--cases",
                "on_axis",
                "--frames",
                "2",
                *outputs,
            ]
        )
        == 0
    )
    text = " ".join((job / "README.md").read_text().split())
    assert "`orrery` (its `space` in job.json: `world per frame`, several moving objects)" in text
    assert "`scenes/<scene>/frame_NNNN.obj`, its `v` already in world space" in text
    assert "`model_matrix` is the identity" in text and "`cube`" not in text  # the cube's OBJ is in model space
    assert (job / "scenes/orrery/frame_0002.obj").is_file() and not (job / "scenes/orrery.obj").exists()
    assert ("A GL depth buffer read back is not depth" in text) == bool(outputs)  # only where depth is asked


@pytest.mark.parametrize(
    "args, needle",
    [
        (["--outputs", "depth,normals"], "unknown 'normals'"),
        (["--outputs", "depth,depth"], "one given twice"),
        (["--outputs", "depth", "--depth-format", "png16", "--depth-scale", "0"], "--depth-scale 0"),
        (["--outputs", "depth", "--depth-format", "png16", "--depth-scale", "nan"], "--depth-scale nan"),
        (["--outputs", "depth", "--depth-scale", "1000"], "expected --depth-format png16"),
        (["--outputs", "filled", "--depth-format", "npy"], "expected --outputs with depth"),
    ],
)
def test_export_refuses_bad_outputs(tmp_path, capsys, args, needle):
    assert main(["export", str(tmp_path / "job"), *ARGS, *args]) == 2
    _one_line(capsys, needle)
    assert not (tmp_path / "job").exists()


def test_surface_mismatch_counts_away_from_the_boundary():
    """Hand-derived: a 4x4 covered square at rows/columns 2..5 of a 9x9 image. Its interior (pixels whose 8
    neighbours are covered) is rows/columns 3..4; pixels with no covered pixel among their 8 neighbours are
    those outside rows/columns 1..6."""
    covered = np.zeros((9, 9), bool)
    covered[2:6, 2:6] = True
    shown = np.zeros_like(covered)  # nothing shown: every interior pixel is a hole
    holes, extra = surface_mismatch(shown, covered)
    assert holes.sum() == 4 and holes[3:5, 3:5].all() and not extra.any()
    shown = np.ones_like(covered)  # everything shown: the extra pixels are the far ring
    holes, extra = surface_mismatch(shown, covered)
    assert not holes.any() and extra.sum() == 81 - 36 and not extra[1:7, 1:7].any()
    full = np.ones((3, 3), bool)  # the image's edge is no boundary: a covered picture's every pixel
    assert surface_mismatch(np.zeros_like(full), full)[0].all()


def test_assert_frames_names_the_depth_fault(depth_job, tmp_path):
    """The Python API judges a depth job by the same judge: a correct one passes, one x1000 is named."""
    from wirecheck import assert_frames, check_frames

    job = fill(copy(depth_job, tmp_path))
    report = check_frames(job)
    assert report["verdict"] == "pass" and all("depth_map" in c for c in report["cases"])
    fill(job, MISTAKES["x1000"])
    with pytest.raises(AssertionError, match=r"depth_scale\(k=1000"):
        assert_frames(job)


ORRERY = str(Path(__file__).parents[1] / "scenes" / "examples" / "orrery.scene")


@pytest.fixture(scope="module")
def orrery_job(tmp_path_factory) -> Path:
    """Three moving objects (scenes/examples/orrery.scene): a world-space OBJ per frame, one id per object."""
    path = tmp_path_factory.mktemp("orrery") / "job"
    assert main(["export", str(path), "--scene", ORRERY, *ARGS[2:], "--outputs", "filled,depth"]) == 0
    return path


def test_several_objects_ids_and_depth(orrery_job, tmp_path):
    """Core's levels 1, 2, 3 per object pass, as do the ids permuted (ids are labels); one level for every
    object fails on the pixels of the objects that are not the level's most frequent."""
    assert json.loads((orrery_job / "job.json").read_text())["scenes"][0]["objects"] == [8, 5, 6]
    job = copy(orrery_job, tmp_path)
    render_job(job)
    code, report, _ = run_crosscheck(tmp_path, "--candidate-frames", str(job), name="ids")
    assert code == 0, [c["reasons"] for c in report["cases"]]
    assert all(c["filled"]["object_id_px"] == 0 and c["depth_map"]["compared_px"] > 0 for c in report["cases"])
    render_job(job, object_ids=lambda o: 2 - o)
    code, report, _ = run_crosscheck(tmp_path, "--candidate-frames", str(job), name="permuted")
    assert code == 0
    render_job(job, object_ids=np.zeros_like)
    code, report, _ = run_crosscheck(tmp_path, "--candidate-frames", str(job), name="one_id")
    assert code == 1
    for case in report["cases"]:
        assert case["filled"]["object_id_px"] > 0 and case["filled"]["longest_run_px"] == 0
        assert any("another object's id" in r for r in case["reasons"])
