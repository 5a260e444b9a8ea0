"""Image candidates: ``crosscheck export DIR`` and ``crosscheck --candidate-frames DIR``.

The job's camera JSON is checked against hand-written projections (the
pinhole formula with K, R, t; the GL pipeline with the view and projection
matrices) reproducing OpenCV's pixels; the judge is checked with frames whose
verdict is known (core's own frames, a mirrored copy); and every way a frames
folder could be judged on nothing (empty, absent, another job's, missing,
wrong size, unreadable, extra) is an exit 2 with one line per problem and no
report written.
"""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path

import numpy as np
import pytest
from helpers import fill_job  # tests/ is on sys.path (rootdir conftest)
from PIL import Image
from wirecheck.core.scene.files import load_scene
from wirecheck.oracles.candidates.export import build_job
from wirecheck.oracles.candidates.frames_candidate import FramesError, frame_inputs, load_job, read_obj
from wirecheck.oracles.cli import main
from wirecheck.oracles.references import opencv_oracle

ARGS = ["--scene", "cube", "--cases", "on_axis,non_square,orthographic", "--frames", "6", "--every", "3"]


def _export(path: Path, args=ARGS) -> Path:
    assert main(["export", str(path)] + args) == 0
    return path


@pytest.fixture(scope="module")
def job_dir(tmp_path_factory) -> Path:
    return _export(tmp_path_factory.mktemp("job") / "job")


@pytest.fixture
def filled(job_dir, tmp_path) -> Path:
    d = tmp_path / "filled"
    shutil.copytree(job_dir, d)
    fill_job(d)
    return d


# ---- the job ----------------------------------------------------------------


def test_job_lists_every_case_and_frame(job_dir):
    job = json.loads((job_dir / "job.json").read_text())
    assert [(c["scene"], c["case"]) for c in job["cases"]] == [
        ("cube", "on_axis"),
        ("cube", "non_square"),
        ("cube", "orthographic"),
    ]
    assert job["frame_numbers"] == [1, 4]
    assert job["cases"][1]["frames"] == [
        "frames/cube/non_square/frame_0001.png",
        "frames/cube/non_square/frame_0004.png",
    ]
    assert (job["cases"][1]["width"], job["cases"][1]["height"]) == (320, 480)
    readme = (job_dir / "README.md").read_text()
    assert "frames/<scene>/<case>/frame_NNNN.png" in readme and "antialias: false" in readme
    assert (job_dir / "frames").is_dir() and not any((job_dir / "frames").iterdir())


def test_obj_is_the_scene(job_dir):
    v, e = read_obj(job_dir / "scenes" / "cube.obj")
    scene = load_scene("cube")
    assert np.array_equal(v, scene.vertices)  # repr() floats: exact round trip
    assert np.array_equal(e, np.asarray(scene.edges))


def _read_obj_by_lines(path: Path):
    """read_obj's reading of a file, line by line, as it read every file before it read export's layout a
    block at a time (that reading, copied): ``(vertices, edges, faces)``, or the first bad line's message."""
    verts, edges, faces = [], [], []
    for lineno, line in enumerate(path.read_text(encoding="utf-8").splitlines(), start=1):
        parts = line.split()
        try:
            if parts and parts[0] == "v":
                verts.append([float(x) for x in parts[1:]])
                if len(parts) != 4 or not all(map(math.isfinite, verts[-1])):
                    raise ValueError
            elif parts and parts[0] == "l":
                edges.append([int(x) - 1 for x in parts[1:]])
                if len(parts) != 3 or not all(0 <= i < len(verts) for i in edges[-1]):
                    raise ValueError
            elif parts and not parts[0].startswith("#"):
                face = [int(x) - 1 for x in parts[1:] if x.lstrip("-").isdigit()] if parts[0] == "f" else []
                if len(face) < max(3, len(parts) - 1) or not all(0 <= i < len(verts) for i in face):
                    return (
                        f"{path}:{lineno}: {line.strip()[:60]!r}: expected 'f I J K ...' (3 or more "
                        f"of 1..{len(verts)}), 'v', 'l' or a '#' comment, as 'crosscheck export' wrote"
                    )
                faces.append(tuple(face))
        except ValueError:
            return (
                f"{path}:{lineno}: {line.strip()[:60]!r}: expected 'v X Y Z' (finite) or 'l I J' "
                f"(1..{len(verts)}), as 'crosscheck export' wrote"
            )
    return np.asarray(verts, dtype=np.float64).reshape(-1, 3), np.asarray(edges, dtype=np.intp).reshape(-1, 2), faces


#: What a hostile or hand-edited OBJ may hold where export writes a number (each read by float() or int()).
_ODD_TOKENS = ["1.5", "-1", "+1", "0", "1_0", "\u0663", "nan", "inf", "1e999", "9" * 25, "x", "0x1p3", "1e", "--2"]


def _random_obj(rng) -> str:
    """An OBJ as export lays it out (comments, then v, l, f lines; faces of one size), one in three of them
    edited once: a token swapped for an odd one, a token dropped or added, two lines swapped, a blank or
    comment line inserted, a tab for a space, a face of another size, an index past the vertices."""
    n_v = int(rng.integers(0, 8))
    lines = ["# scene: model space"] * int(rng.integers(0, 3))
    lines += [
        "v " + " ".join(repr(float(x)) for x in rng.normal(size=3).round(int(rng.integers(0, 9)))) for _ in range(n_v)
    ]
    if n_v:
        k = int(rng.integers(3, 6))
        lines += [f"l {a} {b}" for a, b in rng.integers(1, n_v + 1, size=(int(rng.integers(0, 6)), 2))]
        lines += ["f " + " ".join(map(str, rng.integers(1, n_v + 1, size=k))) for _ in range(int(rng.integers(0, 5)))]
    at = int(rng.integers(0, len(lines))) if lines else 0
    edit = int(rng.integers(0, 24))  # 0 to 7: an edit; the rest: as export wrote it
    if lines and edit == 0:
        parts = lines[at].split(" ")
        parts[int(rng.integers(0, len(parts)))] = str(rng.choice(_ODD_TOKENS))
        lines[at] = " ".join(parts)
    elif lines and edit == 1:
        lines[at] = lines[at].rsplit(" ", 1)[0] if rng.random() < 0.5 else lines[at] + " 1"
    elif lines and edit == 2:
        other = int(rng.integers(0, len(lines)))
        lines[at], lines[other] = lines[other], lines[at]
    elif edit == 3:
        lines.insert(at, str(rng.choice(["", "# note", "  # indented", "vn 0 0 1", "o cube"])))
    elif lines and edit == 4:
        lines[at] = lines[at].replace(" ", "\t", 1)
    elif n_v and edit == 5:
        lines.append("f " + " ".join(map(str, rng.integers(1, n_v + 1, size=int(rng.integers(3, 7))))))
    elif edit == 6:
        lines.append(str(rng.choice([f"l 1 {n_v + 1}", f"f 1 2 {n_v + 1}", "l 0 1", "f 0 1 2"])))
    elif lines and edit == 7:
        lines[at] = lines[at].replace(" ", "  ")
    return "\n".join(lines) + ("\n" if rng.random() < 0.8 else "")


def test_read_obj_equals_the_line_by_line_reading(tmp_path):
    """3,000 OBJ texts as export lays them out, one in three edited (_random_obj): read_obj gives what the
    line-by-line reading gives (its values to the bit, the same index dtype, the faces as tuples), or the same
    message for the same line."""
    rng = np.random.default_rng(35)
    path = tmp_path / "mesh.obj"
    kinds = {"read": 0, "refused": 0}
    for _ in range(3000):
        path.write_text(_random_obj(rng), encoding="utf-8")
        want = _read_obj_by_lines(path)
        if isinstance(want, str):
            with pytest.raises(FramesError) as info:
                read_obj(path, with_faces=True)
            assert info.value.problems == FramesError([want]).problems
            kinds["refused"] += 1
            continue
        got = read_obj(path, with_faces=True)
        for a, b in zip(got[:2], want[:2]):
            assert a.dtype == b.dtype and a.shape == b.shape and np.array_equal(a, b)
            assert np.array_equal(np.signbit(a), np.signbit(b))  # -0.0 read as -0.0
        assert got[2] == want[2] and all(type(i) is int for face in got[2] for i in face)
        kinds["read"] += 1
    assert kinds["read"] > 1500 and kinds["refused"] > 300, kinds


@pytest.mark.parametrize("case", ["on_axis", "non_square", "orthographic"])
def test_camera_json_reproduces_opencv_pixels(job_dir, case):
    # Hand-written projections from the JSON alone, against OpenCV's pixels of the same
    # world points: float64 round-off on values ~1e3 px, so 1e-9 px is far above noise.
    cam_json = json.loads((job_dir / "cameras" / "cube" / case / "frame_0004.json").read_text())
    v, _ = read_obj(job_dir / "scenes" / "cube.obj")
    m = np.array(cam_json["model_matrix"])
    p_world = v @ m[:3, :3].T + m[:3, 3]
    _p, _e, cam, _m = frame_inputs(job_dir, load_job(job_dir), "cube", case, 4)
    want = opencv_oracle.project(p_world, cam)
    k, r, t = np.array(cam_json["K"]), np.array(cam_json["R"]), np.array(cam_json["t_cv"])
    p_cv = p_world @ r.T + t
    if cam_json["camera"]["projection"] == "perspective":
        uvw = p_cv @ k.T
        pinhole = uvw[:, :2] / uvw[:, 2:]
    else:  # K is affine: [u, v] = K[:2, :2] p_cv[:2] + K[:2, 2]
        pinhole = p_cv[:, :2] @ k[:2, :2].T + k[:2, 2]
    np.testing.assert_allclose(pinhole, want, atol=1e-9)
    w, h = cam_json["camera"]["width"], cam_json["camera"]["height"]
    clip = (
        np.c_[p_world, np.ones(len(p_world))] @ (np.array(cam_json["gl_projection"]) @ np.array(cam_json["gl_view"])).T
    )
    ndc = clip[:, :3] / clip[:, 3:]
    gl_px = np.c_[(ndc[:, 0] + 1) * w / 2 - 0.5, h - (ndc[:, 1] + 1) * h / 2 - 0.5]
    np.testing.assert_allclose(gl_px, want, atol=1e-9)
    assert np.all(np.abs(ndc[:, 2]) <= 1)  # inside near/far: the cube is within the frustum


def test_export_is_deterministic(tmp_path):
    _job1, files1 = build_job([load_scene("cube")], frames=6, every=3)
    _job2, files2 = build_job([load_scene("cube")], frames=6, every=3)
    assert files1 == files2


def test_export_refuses_a_foreign_folder(tmp_path, capsys):
    d = tmp_path / "mine"
    d.mkdir()
    (d / "keep.txt").write_text("x")
    assert main(["export", str(d)] + ARGS) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "not written by wirecheck" in err
    assert (d / "keep.txt").read_text() == "x" and sorted(p.name for p in d.iterdir()) == ["keep.txt"]


# ---- judging frames -----------------------------------------------------------


def test_core_frames_pass(filled, tmp_path, capsys):
    rc = main(["--candidate-frames", str(filled), "--report-dir", str(tmp_path / "rep")])
    out = capsys.readouterr().out
    assert rc == 0, out
    report = json.loads((tmp_path / "rep" / "report.json").read_text())
    assert report["level"] == "frames" and report["summary"]["cases"] == 3
    for c in report["cases"]:
        # core judged against core: the same pixels
        assert c["core"]["f1_0px"] == 1.0 and c["core"]["f1_1px"] == 1.0
        assert c["pixel_f1_1px"] >= 0.999 and c["faults"] == []
        assert c["frames_checked"] == 2
    assert (tmp_path / "rep" / "report.html").is_file() and (tmp_path / "rep" / "pixels.png").is_file()
    assert not (tmp_path / "rep" / "vertex_error.png").exists()  # no vertex was compared


def test_mirrored_frames_fail_and_are_named(filled, tmp_path, capsys):
    fill_job(filled, lambda img: img[:, ::-1])
    rc = main(["--candidate-frames", str(filled), "--report-dir", str(tmp_path / "rep")])
    out = capsys.readouterr().out
    assert rc == 1
    report = json.loads((tmp_path / "rep" / "report.json").read_text())
    # non_square looks at the cube obliquely: the mirror shows. (on_axis at frames 1 and 4,
    # t = 0 and 0.5 of turns (1, 1, 0), shows the cube square-on: a mirror changes nothing.)
    by = {c["camera"]: c for c in report["cases"]}
    assert by["non_square"]["verdict"] == "fail"
    assert [f["name"] for f in by["non_square"]["faults"]] == ["mirror_horizontal"], out
    assert by["on_axis"]["verdict"] == "pass" and by["on_axis"]["faults"] == []
    assert (tmp_path / "rep" / "img").is_dir()


def _judge(job: Path, tmp_path, capsys):
    rc = main(["--candidate-frames", str(job), "--report-dir", str(tmp_path / "rep")])
    err = capsys.readouterr().err
    assert "Traceback" not in err
    assert not (tmp_path / "rep").exists()  # nothing written on an input error
    return rc, err.strip().splitlines()


def test_missing_frames_one_line_each(filled, tmp_path, capsys):
    (filled / "frames/cube/on_axis/frame_0004.png").unlink()
    (filled / "frames/cube/orthographic/frame_0001.png").unlink()
    rc, lines = _judge(filled, tmp_path, capsys)
    assert rc == 2 and len(lines) == 2
    assert lines[0].endswith("frames/cube/on_axis/frame_0004.png: missing (frame 4 of cube / on_axis)")
    assert "orthographic/frame_0001.png: missing" in lines[1]


def test_wrong_size_and_unreadable(filled, tmp_path, capsys):
    Image.fromarray(np.zeros((480, 640), np.uint8)).save(filled / "frames/cube/non_square/frame_0001.png")
    (filled / "frames/cube/on_axis/frame_0001.png").write_bytes(b"not a png")
    rc, lines = _judge(filled, tmp_path, capsys)
    assert rc == 2 and len(lines) == 2
    assert "on_axis/frame_0001.png: unreadable as PNG" in lines[0]
    assert lines[1].endswith("non_square/frame_0001.png: size 640x480: expected 320x480 (the camera's)")


def _damage_pixels(path: Path) -> None:
    """Zero 16 bytes of the first IDAT's data: the header and size stay right, the pixels cannot be decoded."""
    data = bytearray(path.read_bytes())
    at = data.index(b"IDAT") + 4 + 2  # past the zlib header
    data[at : at + 16] = bytes(16)
    path.write_bytes(bytes(data))


def test_frames_that_cannot_be_decoded_are_all_listed(filled, tmp_path, capsys):
    # frames are decoded once, as they are judged (the check before reads headers and sizes): a frame whose
    # pixels cannot be decoded, met after other frames were judged, still lists every such frame of the job
    # (the last frame of the first case, the first of the last case), exit 2, no report written
    for rel in ("frames/cube/on_axis/frame_0004.png", "frames/cube/orthographic/frame_0001.png"):
        _damage_pixels(filled / rel)
    rc, lines = _judge(filled, tmp_path, capsys)
    assert rc == 2 and len(lines) == 2, lines
    assert "on_axis/frame_0004.png: unreadable as PNG" in lines[0]
    assert "orthographic/frame_0001.png: unreadable as PNG" in lines[1]
    assert not (tmp_path / "rep").exists()


def test_extra_frame_is_refused(filled, tmp_path, capsys):
    shutil.copy(filled / "frames/cube/on_axis/frame_0001.png", filled / "frames/cube/on_axis/frame_0002.png")
    rc, lines = _judge(filled, tmp_path, capsys)
    assert rc == 2 and len(lines) == 1 and "frame_0002.png: not a frame of this job" in lines[0]


def test_empty_or_absent_frames_folder(job_dir, tmp_path, capsys):
    d = tmp_path / "empty"
    shutil.copytree(job_dir, d)
    rc, lines = _judge(d, tmp_path, capsys)
    assert rc == 2 and len(lines) == 1 and "frames: empty" in lines[0]
    shutil.rmtree(d / "frames")
    rc, lines = _judge(d, tmp_path, capsys)
    assert rc == 2 and len(lines) == 1 and "frames: missing" in lines[0]


def test_frames_of_another_job(filled, tmp_path, capsys):
    other = _export(tmp_path / "other", ["--scene", "pyramid", "--cases", "on_axis", "--frames", "6", "--every", "3"])
    shutil.rmtree(other / "frames")
    shutil.copytree(filled / "frames", other / "frames")
    rc, lines = _judge(other, tmp_path, capsys)
    assert rc == 2 and len(lines) == 1 and "none of its 6 files is a frame of this job" in lines[0]


def test_not_a_job(tmp_path, capsys):
    rc, lines = _judge(tmp_path / "nowhere", tmp_path, capsys)
    assert rc == 2 and "not a directory" in lines[0]
    d = tmp_path / "d"
    d.mkdir()
    rc, lines = _judge(d, tmp_path, capsys)
    assert rc == 2 and "job.json: missing" in lines[0]
    (d / "job.json").write_text(json.dumps({"kind": "wirecheck frames job", "version": 99}))
    rc, lines = _judge(d, tmp_path, capsys)
    assert rc == 2 and "job version 99: expected 1" in lines[0]
    (d / "job.json").write_text(json.dumps({"kind": "wirecheck frames job", "version": 1, "cases": []}))
    rc, lines = _judge(d, tmp_path, capsys)
    assert rc == 2 and "lists no frames" in lines[0]


def test_options_the_job_fixes_are_usage_errors(filled, tmp_path, capsys):
    for extra in (
        ["--scene", "cube"],
        ["--frames", "3"],
        ["--candidate", "wirecheck.core.projector.projection:project_points"],
        ["--cases", "on_axis"],
    ):
        rc = main(["--candidate-frames", str(filled), "--report-dir", str(tmp_path / "rep")] + extra)
        err = capsys.readouterr().err
        assert rc == 2 and "the job fixes scenes, cases and frames" in err, (extra, err)


def test_several_moving_objects_are_exported_in_world_space(tmp_path, capsys):
    # the orrery's objects move on their own: one world-space OBJ per frame, identity model
    # matrix, the vertices being the oracle's own world points (oracles.references.faces, scipy)
    from wirecheck.core.transforms import Motion
    from wirecheck.oracles.references.faces import frame_geometry

    path = str(Path(__file__).parents[1] / "scenes" / "examples" / "orrery.scene")
    job = _export(tmp_path / "job", ["--scene", path, "--cases", "oblique_roll", "--frames", "6", "--every", "3"])
    scene = load_scene(path)
    for k in (1, 4):
        v, _e = read_obj(job / "scenes" / scene.name / f"frame_{k:04d}.obj")
        p_world = frame_geometry(scene, Motion(), (k - 1) / 6)[0]
        assert np.array_equal(v, p_world)
        cam_json = json.loads((job / "cameras" / scene.name / "oblique_roll" / f"frame_{k:04d}.json").read_text())
        assert np.array_equal(np.array(cam_json["model_matrix"]), np.eye(4))
    fill_job(job)
    assert main(["--candidate-frames", str(job), "--report-dir", str(tmp_path / "rep")]) == 0, capsys.readouterr()
    (case,) = json.loads((tmp_path / "rep" / "report.json").read_text())["cases"]
    assert case["core"]["f1_0px"] == 1.0 and case["faults"] == []


def test_project_settings_do_not_apply_to_frames_and_junit_is_written(filled, tmp_path, capsys):
    # [tool.wirecheck] configures projector checks (scenes, cases, frames): a job's frames do not
    # use them, so they are not usage errors here; --junit-xml gets one test case per case
    cfg = tmp_path / "pyproject.toml"
    cfg.write_text('[tool.wirecheck]\nscenes = ["pyramid"]\ncases = ["on_axis"]\nframes = 3\n')
    junit = tmp_path / "frames.xml"
    rc = main(
        [
            "--candidate-frames",
            str(filled),
            "--report-dir",
            str(tmp_path / "rep"),
            "--config",
            str(cfg),
            "--junit-xml",
            str(junit),
        ]
    )
    assert rc == 0, capsys.readouterr().err
    import xml.etree.ElementTree as ET

    cases = ET.parse(junit).getroot().iter("testcase")
    assert len(list(cases)) == 3


def test_a_case_where_nothing_is_drawn_is_vacuous(tmp_path, capsys):
    # points without edges: the oracle draws nothing, a blank frame agrees with it, and that
    # compares nothing (as oracles.judge.gate): exit 1 unless --allow-vacuous
    scene = tmp_path / "dots.scene"
    scene.write_text("name dots\nv -1 -1 0\nv 1 1 0\nv 0 1 1\n")
    job = _export(tmp_path / "job", ["--scene", str(scene), "--cases", "on_axis", "--frames", "2"])
    for k in (1, 2):
        (job / "frames/dots/on_axis").mkdir(parents=True, exist_ok=True)
        Image.fromarray(np.zeros((480, 640), np.uint8)).save(job / f"frames/dots/on_axis/frame_{k:04d}.png")
    assert main(["--candidate-frames", str(job), "--report-dir", str(tmp_path / "r1")]) == 1
    (case,) = json.loads((tmp_path / "r1" / "report.json").read_text())["cases"]
    assert case["verdict"] == "vacuous" and "nothing compared" in case["reasons"][0]
    assert main(["--candidate-frames", str(job), "--report-dir", str(tmp_path / "r2"), "--allow-vacuous"]) == 0
    capsys.readouterr()
