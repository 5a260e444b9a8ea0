"""The pytest plugin (oracles/pytest_plugin.py), run as a user's pytest would load it: by its entry point.

Each test builds a small user project with pytester and runs pytest on it in
process; the plugin is never named with ``-p``, so the ``pytest11`` entry point
is what loads it.
"""

import json
from importlib.metadata import entry_points
from pathlib import Path

import pytest

DATA = Path(__file__).parent / "data"

#: The report folders of the user's tests: the id's characters, "-" and the first 8 hex digits of the SHA-1
#: of "test_user.py::test_mirrored" / "...::test_two_checks" (docs/pytest.md), computed once by hand (hashlib.sha1)
MIRRORED_DIR = "test_user.py_test_mirrored-674c9e30"
TWO_CHECKS_DIR = "test_user.py_test_two_checks-8ac2ae87"

MIRRORED = """
def mirrored(points, camera):
    px = project(points, camera)
    px[:, 0] = (camera.width - 1) - px[:, 0]
    return px
"""

USER_TESTS = """
from my_projection import project, mirrored


def test_good(wirecheck):
    report = wirecheck(project, scenes=["cube"], frames=2, cases=["on_axis", "orthographic"])
    assert report["verdict"] == "pass" and report["summary"]["cases"] == 2


def test_mirrored(wirecheck):
    wirecheck(mirrored, scenes=["cube"], frames=2, cases=["on_axis"])
"""


@pytest.fixture
def project(pytester):
    # not "user_projector": other tests import tests/data/user_projector.py under that name
    pytester.makepyfile(my_projection=(DATA / "user_projector.py").read_text() + MIRRORED)
    pytester.syspathinsert()
    return pytester


def test_registered_through_the_pytest11_entry_point():
    eps = {ep.name: ep.value for ep in entry_points(group="pytest11")}
    assert eps.get("wirecheck") == "wirecheck.oracles.pytest_plugin"


def test_pass_and_fail_with_the_fault_and_without_harness_frames(project):
    project.makepyfile(test_user=USER_TESTS)
    result = project.runpytest()
    result.assert_outcomes(passed=1, failed=1)
    out = result.stdout.str()
    # the user's own line is the traceback, then the diagnosis
    result.stdout.fnmatch_lines(
        [
            '>       wirecheck(mirrored, scenes=[[]"cube"[]], frames=2, cases=[[]"on_axis"[]])',
            "E       Failed: Compared: level vertices (OpenCV), 2 frames per case, 1 case (1 scene x 1 camera)",
            "E       1 of 1 crosscheck cases failed for mirrored:",
            "E         cube / on_axis: faults: mirror_horizontal; max vertex error * px > 1e-06 px *",
            "E         what to check, mirror_horizontal: left and right are exchanged*",
            "test_user.py:10: Failed",
        ]
    )
    for harness in ("pytest_plugin.py", "oracles/api.py", "oracles/runner.py", "During handling"):
        assert harness not in out


def test_settings_come_from_the_table_then_the_command_line_then_the_call(project):
    project.makepyprojecttoml(
        '[tool.wirecheck]\ncandidate = "my_projection.py:project"\nscenes = ["prism"]\n'
        'cases = ["near_plane", "wide_fov"]\nframes = 2\nlevel = "vertices"\n'
    )
    project.makepyfile(
        test_user="""
def test_table(wirecheck, request):
    report = wirecheck()                 # the table's candidate, scenes, cases
    frames = request.config.getoption("wirecheck_frames") or 2
    assert [(c["scene"], c["camera"]) for c in report["cases"]] == [("prism", "near_plane"), ("prism", "wide_fov")]
    assert (report["frames"], report["level"]) == (frames, "vertices")


def test_call_wins(wirecheck):
    report = wirecheck(frames=4, cases=["orthographic"])
    assert report["frames"] == 4 and [c["camera"] for c in report["cases"]] == ["orthographic"]
"""
    )
    project.runpytest().assert_outcomes(passed=2)
    project.runpytest("--wirecheck-frames", "3").assert_outcomes(passed=2)


@pytest.mark.parametrize(
    "table, needle",
    [
        ("frame = 2\n", "unknown key 'frame' (did you mean 'frames'?)"),
        ("cases = []\n", "cases = []: expected a non-empty list"),
        ("frames = 0\n", "frames = 0: expected an integer >= 1"),
    ],
)
def test_a_bad_table_is_a_usage_error_before_any_test(project, table, needle):
    path = project.makepyprojecttoml("[tool.wirecheck]\n" + table)
    project.makepyfile(test_user=USER_TESTS)
    result = project.runpytest()
    assert result.ret == pytest.ExitCode.USAGE_ERROR
    assert f"wirecheck: {path}: [tool.wirecheck] {needle}" in result.stderr.str()


def test_zero_frames_on_the_command_line_is_a_usage_error(project):
    project.makepyfile(test_user=USER_TESTS)
    result = project.runpytest("--wirecheck-frames", "0")
    assert result.ret == pytest.ExitCode.USAGE_ERROR and "--wirecheck-frames 0" in result.stderr.str()


def test_report_option_writes_the_report_of_each_failing_check(project):
    project.makepyfile(
        test_user=USER_TESTS
        + """

def test_two_checks(wirecheck):
    try:
        wirecheck(mirrored, scenes=["cube"], frames=2, cases=["wide_fov"])
    except BaseException:
        pass
    wirecheck(mirrored, scenes=["pyramid"], frames=2, cases=["oblique_roll"])
"""
    )
    result = project.runpytest("--wirecheck-report", "reports")
    result.assert_outcomes(passed=1, failed=2)
    root = project.path / "reports"
    assert sorted(p.name for p in root.iterdir()) == [MIRRORED_DIR, TWO_CHECKS_DIR, TWO_CHECKS_DIR + "-2"]
    expected = {
        MIRRORED_DIR: ("cube", "on_axis"),
        TWO_CHECKS_DIR: ("cube", "wide_fov"),
        TWO_CHECKS_DIR + "-2": ("pyramid", "oblique_roll"),
    }
    for name, (scene, camera) in expected.items():
        report = json.loads((root / name / "report.json").read_text())
        case = report["cases"][0]
        assert (case["scene"], case["camera"], case["faults"][0]["name"]) == (scene, camera, "mirror_horizontal")
        assert (root / name / "report.html").is_file()
    result.stdout.fnmatch_lines(
        [f"E         report: reports/{MIRRORED_DIR}/report.html", "3 report(s) of failing checks under reports"]
    )


def test_no_projector_anywhere_fails_the_test(project):
    project.makepyfile(test_user="def test_it(wirecheck):\n    wirecheck()\n")
    result = project.runpytest()
    result.assert_outcomes(failed=1)
    result.stdout.fnmatch_lines(["*wirecheck(): no projector*"])


def test_a_report_that_did_not_pass_is_never_silent():
    from wirecheck.oracles.api import failure_text

    # hand-made reports: the fixture fails whenever failure_text is not None
    case = {"scene": "cube", "camera": "on_axis", "verdict": "pass", "faults": [], "reasons": []}
    assert failure_text({"candidate": "f", "verdict": "pass", "cases": [case]}) is None
    assert (
        failure_text({"candidate": "f", "verdict": "fail", "cases": [case]})
        == "crosscheck of f: verdict fail with no failing case"
    )
    assert failure_text({"candidate": "f", "verdict": "fail", "cases": []}) is not None


def test_report_option_on_a_file_is_a_usage_error_and_the_file_is_kept(project):
    project.makepyfile(test_user=USER_TESTS)
    (project.path / "notes.txt").write_text("mine\n")
    result = project.runpytest("--wirecheck-report", "notes.txt")
    assert result.ret == pytest.ExitCode.USAGE_ERROR and "is not a directory" in result.stderr.str()
    assert (project.path / "notes.txt").read_text() == "mine\n"


def test_a_report_folder_not_written_by_wirecheck_is_left_alone(project):
    project.makepyfile(test_user=USER_TESTS)
    theirs = project.path / "reports" / MIRRORED_DIR
    theirs.mkdir(parents=True)
    (theirs / "keep.txt").write_text("mine\n")
    result = project.runpytest("--wirecheck-report", "reports")
    result.assert_outcomes(passed=1, failed=1)
    result.stdout.fnmatch_lines(["E         report not written: *not written by wirecheck*"])
    assert [p.name for p in theirs.iterdir()] == ["keep.txt"] and (theirs / "keep.txt").read_text() == "mine\n"


PUNCTUATION_IDS = ["a/b", "a::b", "a]b", "a[b", "a b", "a+b"]


def test_test_ids_that_differ_only_in_punctuation_get_a_report_folder_each(project):
    """Six failing tests whose ids differ only in punctuation: six folders, each with its own test's report.

    Before, ``/``, ``::`` and brackets were made ``_`` one-to-one with no hash: the first four ids all wrote
    ``test_user.py_test_shift_a_b`` and each report replaced the one before.
    """
    project.makepyfile(
        test_user=f"""
import pytest
from my_projection import project

@pytest.mark.parametrize("shift", [1.0, 2.0, 3.0, 4.0, 5.0, 6.0], ids={PUNCTUATION_IDS!r})
def test_shift(wirecheck, shift):
    wirecheck(lambda p, c: project(p, c) + shift, scenes=["cube"], frames=1, cases=["on_axis"])
"""
    )
    result = project.runpytest("--wirecheck-report", "reports", "-p", "no:xdist")
    result.assert_outcomes(failed=6)
    folders = sorted((project.path / "reports").iterdir())
    assert len(folders) == 6, [f.name for f in folders]
    # each shift s moves every vertex by (s, s): the worst vertex error is s * sqrt(2), one folder per test
    shifts = sorted(
        round(json.loads((f / "report.json").read_text())["summary"]["max_vertex_error_px"] / 2**0.5, 6)
        for f in folders
    )
    assert shifts == [1.0, 2.0, 3.0, 4.0, 5.0, 6.0]


def test_report_folder_names_are_one_to_one_and_fit_a_file_name():
    from wirecheck.oracles.pytest_plugin import report_name

    ids = [f"t.py::test[{p}]" for p in PUNCTUATION_IDS] + ["t.py::test_a_b", "t.py::test[a_b]", "t.py::test[a]-2"]
    names = [report_name(i) for i in ids]
    assert len(set(names)) == len(ids), names
    # "t.py::test[a/b]": its characters with runs of others made "_", "-", then sha1("t.py::test[a/b]")[:8],
    # computed by hand: hashlib.sha1(b"t.py::test[a/b]").hexdigest()[:8]
    assert names[0] == "t.py_test_a_b-577e9e1b"
    assert len(report_name("t.py::test[" + "x" * 300 + "]")) == 120 + 1 + 8  # under NAME_MAX (255 bytes)
