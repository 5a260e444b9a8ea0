"""Hand-edited job files of ``crosscheck --candidate-frames DIR``: one line naming the file, the field and what
export writes there, exit 2, no report. Each case below was judged before its fix (exit 0 or 1, a report written)
as if the edit were not there: the judge read other fields than the renderer had drawn from.

A camera JSON says one camera several ways (the contract's fields, OpenCV's K, R, t_cv, GL's matrices); the
judge draws from the contract's fields and the model matrix, a renderer from any of them. So every field must be
what ``crosscheck export`` writes for that camera and model matrix (oracles.candidates.export.camera_json): the
expected values below come from the unedited file, not from the code under test.
"""

from __future__ import annotations

import json

import helpers  # tests/ is on sys.path (rootdir conftest)
import pytest
from wirecheck.oracles import cli as crosscheck_cli
from wirecheck.oracles.candidates.frames_candidate import frame_inputs, load_job

CAM = "cameras/cube/on_axis/frame_0001.json"
ORRERY = str(__import__("pathlib").Path(__file__).parents[1] / "scenes" / "examples" / "orrery.scene")


@pytest.fixture(scope="module")
def blank(tmp_path_factory):
    return helpers.blank_job(tmp_path_factory.mktemp("job") / "job")


@pytest.fixture
def job(blank, tmp_path):
    import shutil

    shutil.copytree(blank, tmp_path / "job")
    return tmp_path / "job"


def _edit(path, edit):
    data = json.loads(path.read_text())
    edit(data)
    path.write_text(json.dumps(data, indent=1))


def judged(job, tmp_path, capsys):
    rc = crosscheck_cli.main(["--candidate-frames", str(job), "--report-dir", str(tmp_path / "r")])
    err = capsys.readouterr().err
    assert not (tmp_path / "r").exists(), "a report was written for an edited job"
    return rc, err


def assert_one_line(rc, err, *needles):
    assert rc == 2 and err.count("\n") == 1 and err.startswith("crosscheck: error: "), (rc, err)
    assert "Traceback" not in err
    for n in needles:
        assert n in err, (n, err)


def original(job, *keys):
    value = json.loads((job / CAM).read_text())
    for k in keys:
        value = value[k]
    return value


@pytest.mark.parametrize(
    "edit, needle",
    [
        # K, R, t_cv, the GL matrices, right: what a renderer draws from; the judge draws from "camera"
        (lambda d: d["K"][0].__setitem__(0, 400.0), "K[0][0] 400.0: expected "),
        (lambda d: d["gl_projection"][0].__setitem__(0, 2.0), "gl_projection[0][0] 2.0: expected "),
        (lambda d: d["R"].reverse(), "R[0][0] "),
        (lambda d: d["t_cv"].__setitem__(2, 7.0), "t_cv[2] 7.0: expected "),
        # the contract's fields: one missing is not the default's business
        (lambda d: d["camera"].pop("near"), "camera: no 'near': expected "),
        (lambda d: d["camera"].__setitem__("fov_y_deg", 50.0), "K[0][0] "),
        # a camera file copied over another frame's
        (lambda d: d.__setitem__("frame", 3), "frame 3: expected 1"),
        (lambda d: d.__setitem__("case", "oblique_roll"), "case 'oblique_roll': expected 'on_axis'"),
        # a typo'd or extra key
        (
            lambda d: d.__setitem__("modle_matrix", d["model_matrix"]),
            "unknown key 'modle_matrix' (did you mean 'model_matrix'?)",
        ),
        (lambda d: d["camera"].__setitem__("focal", 3.0), "camera: unknown key 'focal'"),
        # a field of the wrong type, named (before: "TypeError: must be real number, not str"; "camera Truex480")
        (lambda d: d["camera"].__setitem__("fov_y_deg", "55"), "camera.fov_y_deg '55': expected a number"),
        (lambda d: d["camera"].__setitem__("width", True), "camera.width True: expected an integer"),
        (lambda d: d["camera"].__setitem__("up", [0, 1]), "camera.up [0, 1]: expected 3 numbers"),
        # a JSON true is no 1.0
        (
            lambda d: (
                d["model_matrix"][0].__setitem__(0, True)
                if d["model_matrix"][0][0] == 1.0
                else d["model_matrix"][3].__setitem__(3, True)
            ),
            "model_matrix[",
        ),
    ],
)
def test_an_edited_camera_json_is_one_line(job, tmp_path, capsys, edit, needle):
    _edit(job / CAM, edit)
    rc, err = judged(job, tmp_path, capsys)
    assert_one_line(rc, err, f"{job / CAM}: ", needle, "export the job again")


def test_the_expected_value_is_the_exported_one(job, tmp_path, capsys):
    k00 = original(job, "K", 0, 0)
    _edit(job / CAM, lambda d: d["K"][0].__setitem__(0, 400.0))
    rc, err = judged(job, tmp_path, capsys)
    assert_one_line(rc, err, f"K[0][0] 400.0: expected {k00!r}")


def test_a_model_matrix_that_is_not_affine_is_refused(job, tmp_path, capsys):
    """The oracles use the model matrix's top three rows; a GL renderer all four (w = z here): they would draw
    different pictures from one file."""
    _edit(job / CAM, lambda d: d["model_matrix"].__setitem__(3, [0.0, 0.0, 1.0, 0.0]))
    rc, err = judged(job, tmp_path, capsys)
    assert_one_line(rc, err, f"{job / CAM}: model_matrix[3] [0.0, 0.0, 1.0, 0.0]: expected [0.0, 0.0, 0.0, 1.0]")


@pytest.mark.parametrize(
    "edit, needle",
    [
        (lambda d: d.__setitem__("evrey", 2), "unknown key 'evrey' (did you mean 'every'?)"),
        (lambda d: d.pop("conventions"), "no 'conventions'"),
        (lambda d: d["cases"][0].__setitem__("widht", 640), "cases[0]: unknown key 'widht' (did you mean 'width'?)"),
        (lambda d: d["scenes"][0].__setitem__("colour", "red"), "scenes[0]: unknown key 'colour'"),
        (lambda d: d["motion"].__setitem__("phse", 0.3), "motion: unknown key 'phse' (did you mean 'phase'?)"),
        (lambda d: d.__setitem__("version", 1.0), "version 1.0: expected 1"),
    ],
)
def test_an_edited_job_json_is_one_line(job, tmp_path, capsys, edit, needle):
    _edit(job / "job.json", edit)
    rc, err = judged(job, tmp_path, capsys)
    assert_one_line(rc, err, f"{job / 'job.json'}: ", needle)


def test_an_unedited_job_reads_as_exported(blank):
    """The check does not misfire: every frame of the exported job (perspective and orthographic, calibrated
    intrinsics, a phase, a scene of several moving objects) is read without a problem."""
    import tempfile
    from pathlib import Path

    from wirecheck.oracles import cli

    with tempfile.TemporaryDirectory() as tmp:
        for args in (
            ["--scene", "cube", "--cases", "orthographic,non_square", "--frames", "3", "--phase", "0.3"],
            ["--scene", "pyramid", "--cases", "off_centre,non_square_pixels", "--frames", "2"],
            ["--scene", ORRERY, "--cases", "near_plane", "--frames", "4", "--every", "3", "--spin", "0.25,1,3"],
        ):
            out = Path(tmp) / "j"
            assert cli.main(["export", str(out), *args]) == 0
            job = load_job(out)
            for c in job["cases"]:
                for k in job["frame_numbers"]:
                    frame_inputs(out, job, c["scene"], c["case"], k)
            import shutil

            shutil.rmtree(out)


@pytest.mark.parametrize(
    "line, needle",
    [
        ("f 1 99 3", "'f 1 99 3': expected 'f I J K ...' (3 or more of 1..8)"),
        ("f 1 2", "'f 1 2': expected 'f I J K ...'"),
        ("f 1 x 3", "'f 1 x 3': expected 'f I J K ...'"),
        ("vt 0.5 0.5", "'vt 0.5 0.5': expected 'f I J K ...' (3 or more of 1..8), 'v', 'l' or a '#' comment"),
    ],
)
def test_an_edited_obj_face_or_record_is_one_line(job, tmp_path, capsys, line, needle):
    """Faces are not judged, but a renderer may read them (hidden lines): before, any 'f' line or unknown
    record was skipped and the job judged (correct frames: exit 0)."""
    obj = job / "scenes/cube.obj"
    n = len(obj.read_text().splitlines())
    obj.write_text(obj.read_text() + line + "\n")
    rc, err = judged(job, tmp_path, capsys)
    assert_one_line(rc, err, f"{obj}:{n + 1}: {needle}")


@pytest.mark.parametrize(
    "edit, needle",
    [
        (lambda d: d["K"][1].__setitem__(2, 200.0), "K[1][2] 200.0: expected "),
        (lambda d: d.__setitem__("t", 0.0), "t 0.0: expected 0.5"),
    ],
)
def test_an_edit_in_a_later_frame_of_a_case_is_found(job, tmp_path, capsys, edit, needle):
    """The camera's own fields are computed once a case (the first frame's): a later frame's file is still
    held to them, and to its own frame number and time (frame 3 of 4: t = 2 / 4)."""
    cam3 = job / "cameras/cube/on_axis/frame_0003.json"
    _edit(cam3, edit)
    rc, err = judged(job, tmp_path, capsys)
    assert_one_line(rc, err, f"{cam3}: ", needle)
