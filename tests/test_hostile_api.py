"""The Python API and the pytest plugin against a demanding user (oracles/api.py, pytest_plugin.py, junit.py).

A usage error is a ValueError/TypeError naming the argument, its value and
what was expected, raised before the projector is called; a projector's
answer outside the contract fails its case with one clear reason, never a
pass; a check leaves the caller's process-wide settings as it found them;
reports and JUnit XML hold any name. Each test was seen to fail before its
fix. (tests/test_api.py, test_gate.py, test_pytest_plugin.py, test_junit.py
cover the ordinary uses.)
"""

import json
import os
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
from wirecheck.core.projector.projection import project_points
from wirecheck.oracles.api import check_projector

DATA = Path(__file__).parent / "data"
ONE = dict(scenes=["cube"], frames=1, cases=["on_axis"])  # 8 vertices, 1 frame: the cheapest check


def _raises_always(points, camera):
    raise RuntimeError("this projector must never be called")


# ---------------------------------------------------------------- usage errors name the argument


@pytest.mark.parametrize(
    "kwargs, kind, needle",
    [
        ({"func": 42}, TypeError, "func 42: expected a callable func(points, camera)"),
        ({"func": Path("proj.py")}, TypeError, "func PosixPath('proj.py'): expected a callable"),
        ({"func": np.zeros(3)}, TypeError, "func array([0., 0., 0.]): expected a callable"),
        ({"func": lambda points: points}, TypeError, "(points) cannot be called as func(points, camera)"),
        ({"func": None}, ValueError, "no candidate: expected func"),
        ({"cmd": [1, 2]}, TypeError, "cmd [1, 2]: expected a command line (str) or an argv list of str"),
        ({"cmd": 42}, TypeError, "cmd 42: expected a command line"),
        ({"timeout_s": "10"}, TypeError, "timeout_s '10': expected a number of seconds > 0"),
        ({"isolate": "no"}, TypeError, "isolate 'no': expected True or False"),
        ({"allow_vacuous": "no"}, TypeError, "allow_vacuous 'no': expected True or False"),
        ({"allow_vacuous": None}, TypeError, "allow_vacuous None: expected True or False"),
        # timeout_s=None and oracles=None are "not given": [tool.wirecheck]'s value or the default (docs/pytest.md)
        ({"scenes": 42}, ValueError, "scenes 42: expected a scene name, a path or a Scene"),
        ({"scenes": ["cube", None]}, ValueError, "scenes: None (NoneType): expected a scene name"),
        ({"cases": 42}, ValueError, "cases 42: expected a list of case names"),
        ({"tol_px": True}, ValueError, "tol_px True: expected a finite number >= 0"),
        ({"min_f1": True}, ValueError, "min_f1 True: expected a number in [0, 1]"),
    ],
)
def test_a_bad_argument_is_one_line_naming_it_before_the_projector_runs(kwargs, kind, needle):
    # before the fix: deep TypeErrors from Python/numpy ("'int' object is not iterable", "'>' not
    # supported"), allow_vacuous="no" taken as True, a non-callable failing each case at run time
    func = None if "cmd" in kwargs else _raises_always
    args = {"func": func, "isolate": False if func else None, **ONE, **kwargs}
    with pytest.raises(kind) as info:
        check_projector(args.pop("func"), **args)
    text = str(info.value)
    assert needle in text and "\n" not in text


def test_arguments_given_in_other_reasonable_forms_work():
    # a Path for one scene, a string for one oracle, numpy arrays of names, a numpy integer of frames
    report = check_projector(
        project_points,
        scenes=Path(DATA.parent.parent / "scenes" / "cube.scene"),
        frames=np.int64(1),
        cases=np.array(["on_axis"]),
        oracles="opencv",
        isolate=False,
    )
    # float64 on both sides: ~1e-11 px at most (oracles/tolerances.py derivation)
    assert report["verdict"] == "pass" and report["level"] == "vertices"
    assert report["compared"] == {"cases": 1, "frames": 1, "vertices": 8, "pixels": None}
    assert report["summary"]["max_vertex_error_px"] < 1e-9


# ---------------------------------------------------------------- what a projector returns


class _ArrayLike:
    """A torch-like tensor: not an ndarray, but converts through ``__array__``."""

    def __init__(self, a):
        self.a = a

    def __array__(self, dtype=None, copy=None):
        return self.a if dtype is None else self.a.astype(dtype)


def _readonly(a):
    a.setflags(write=False)
    return a


ACCEPTED = {  # converts to the right (8, 2) float pixels: passes
    "list of lists": lambda p, c: project_points(p, c).tolist(),
    "np.matrix": lambda p, c: np.asmatrix(project_points(p, c)),
    "__array__": lambda p, c: _ArrayLike(project_points(p, c)),
    "read-only": lambda p, c: _readonly(project_points(p, c)),
    "Fortran order": lambda p, c: np.asfortranarray(project_points(p, c)),
    "float32": lambda p, c: project_points(p, c).astype(np.float32),
}


@pytest.mark.filterwarnings("ignore:the matrix subclass:PendingDeprecationWarning")
@pytest.mark.parametrize("name", ACCEPTED)
def test_array_likes_in_other_forms_are_judged_on_their_values(name):
    report = check_projector(ACCEPTED[name], isolate=False, **ONE)
    case = report["cases"][0]
    assert report["verdict"] == "pass" and case["compared"]["vertices"] == 8
    judged = case["precision"]["judged_as"]
    assert judged == ("float32" if name == "float32" else "float64")


REFUSED = {  # nothing to compare, or numbers that are not pixels: fails with this reason
    "None": (lambda p, c: None, "candidate returned shape (): expected (8, 2)"),
    "empty": (lambda p, c: np.zeros((0, 2)), "candidate returned shape (0, 2): expected (8, 2)"),
    "generator": (
        lambda p, c: (r for r in project_points(p, c)),
        "candidate returned generator that is not an array of floats",
    ),
    "strings": (
        lambda p, c: project_points(p, c).astype(str),
        "candidate returned an array of <U32 (strings): expected an (N, 2) float array",
    ),
    "booleans": (
        lambda p, c: np.ones((len(p), 2), bool),
        "candidate returned an array of bool (booleans): expected an (N, 2) float array",
    ),
    "datetimes": (
        lambda p, c: np.zeros((len(p), 2), "M8[s]"),
        "candidate returned an array of datetime64[s] (datetimes)",
    ),
}


@pytest.mark.parametrize("name", REFUSED)
def test_answers_outside_the_contract_fail_with_one_reason(name):
    # before the fix, strings passed (numpy casts "12.5" to 12.5) and booleans and datetimes were
    # judged as 0/1 and seconds: a vertex error instead of the contract violation
    func, reason = REFUSED[name]
    report = check_projector(func, isolate=False, **ONE)
    case = report["cases"][0]
    assert report["verdict"] == "fail" and len(case["reasons"]) == 1
    assert case["reasons"][0].startswith(f"frame 1: {reason}")


def test_float16_and_integers_are_judged_and_fail_on_their_rounding():
    # float16 is judged as float32 (oracles/candidates/candidate.py): its ~0.1 px rounding at a 640 px image
    # (eps16 = 9.8e-4 x 320 px / 2) is far over the float32 bound; integer pixels miss by up to 0.5 px
    for dtype, judged in ((np.float16, "float32"), (np.int64, "float64")):
        report = check_projector(lambda p, c: np.round(project_points(p, c)).astype(dtype), isolate=False, **ONE)
        case = report["cases"][0]
        assert report["verdict"] == "fail" and case["precision"]["judged_as"] == judged
        assert case["reasons"][0].startswith("max vertex error")


# ---------------------------------------------------------------- the caller's globals


def test_a_check_puts_back_the_globals_a_projector_changed(tmp_path):
    # a projector run in this process (isolate=False) that changes process-wide settings: all go back
    def meddles(points, camera):
        np.seterr(all="ignore")
        np.set_printoptions(precision=2)
        os.chdir(tmp_path)
        sys.path.append(str(tmp_path))
        os.environ["WIRECHECK_HOSTILE_API"] = "1"
        import warnings

        warnings.simplefilter("ignore")
        import logging

        logging.getLogger().setLevel(logging.CRITICAL)
        return project_points(points, camera)

    import logging
    import warnings

    before = (
        np.geterr(),
        np.get_printoptions(),
        os.getcwd(),
        list(sys.path),
        dict(os.environ),
        list(warnings.filters),
        logging.getLogger().level,
    )
    report = check_projector(meddles, isolate=False, **ONE)
    after = (
        np.geterr(),
        np.get_printoptions(),
        os.getcwd(),
        list(sys.path),
        dict(os.environ),
        list(warnings.filters),
        logging.getLogger().level,
    )
    assert report["verdict"] == "pass"
    for name, b, a in zip(
        ("seterr", "printoptions", "cwd", "sys.path", "environ", "warnings", "logging"), before, after
    ):
        assert a == b, name


STATE_SCRIPT = r"""
import json, logging, os, signal, sys, warnings
import numpy as np

def state():
    return {"filters": [repr(f) for f in warnings.filters], "err": np.geterr(), "print": repr(np.get_printoptions()),
            "environ": dict(os.environ), "path": sys.path[:], "cwd": os.getcwd(),
            "log": [logging.root.level, len(logging.root.handlers), logging.root.manager.disable],
            "signals": {str(s): repr(signal.getsignal(s)) for s in signal.valid_signals()},
            "bytecode": sys.dont_write_bytecode, "matplotlib": "matplotlib" in sys.modules and
            dict.__getitem__(sys.modules["matplotlib"].rcParams, "backend")}

from wirecheck.oracles.api import check_projector
from wirecheck.core.projector.projection import project_points
before = state()
check_projector(project_points, scenes=["cube"], frames=1, cases=["on_axis"], isolate=False)
check_projector(lambda p, c: project_points(p, c), scenes=["cube"], frames=1, cases=["on_axis"])   # forked
print(json.dumps([before, state()]))
"""


def test_a_first_check_in_a_process_leaves_its_imports_side_effects_behind():
    # the first check imports scipy (adds warning filters) and OpenCV (prepends LD_LIBRARY_PATH in
    # os.environ): a fresh interpreter, so that those imports happen inside the call
    env = {k: v for k, v in os.environ.items() if k != "LD_LIBRARY_PATH"}
    proc = subprocess.run([sys.executable, "-c", STATE_SCRIPT], capture_output=True, text=True, timeout=120, env=env)
    assert proc.returncode == 0, proc.stderr
    before, after = json.loads(proc.stdout)
    for key in before:
        assert after[key] == before[key], key


# ---------------------------------------------------------------- reports and JUnit XML hold any name


def test_junit_xml_with_control_characters_and_undecodable_bytes_parses():
    from wirecheck.oracles.reports.junit import junit_xml

    # a scene or candidate named by a file name: control characters, "]]>", lone surrogates
    # (Python's surrogateescape for a non-UTF-8 byte); ElementTree writes them as they are
    case = {
        "scene": 'c\x01]]>\udcff<&"',
        "camera": "on\x00axis",
        "verdict": "fail",
        "faults": [{"name": "mirror_horizontal"}],
        "reasons": ["r\x07 \ud800 ]]>"],
        "note": "n\x0b",
    }
    report = {"candidate": "/tmp/p\udcff.py:f\x1b", "cases": [case], "verdict": "fail", "level": "vertices"}
    root = ET.fromstring(junit_xml(report))
    testcase = root.find("testsuite/testcase")
    # each character XML cannot hold is written as a Python escape; the undecodable byte as its value
    assert (testcase.get("classname"), testcase.get("name")) == ('c\\x01]]>\\xff<&"', "on\\x00axis")
    assert testcase.find("failure").get("message").endswith("r\\x07 \\ud800 ]]>")
    assert root.find("testsuite/properties/property").get("value") == "/tmp/p\\xff.py:f\\x1b"
    assert testcase.find("system-out").text == "note: n\\x0b\n"


def test_a_candidate_at_a_non_utf8_path_gets_its_reports(tmp_path, capsys):
    from wirecheck.oracles import cli

    folder = Path(os.fsdecode(bytes(tmp_path) + b"/p\x01\xff"))
    folder.mkdir()
    (folder / "u.py").write_bytes((DATA / "user_projector.py").read_bytes())
    out, junit = tmp_path / "out", tmp_path / "j.xml"
    # before the fix: exit 3, UnicodeEncodeError writing report.md, no report.md/html nor JUnit file
    code = cli.main(
        [
            "--report-dir",
            str(out),
            "--junit-xml",
            str(junit),
            "--level",
            "vertices",
            "--frames",
            "1",
            "--cases",
            "on_axis",
            "--scene",
            "cube",
            "--candidate",
            f"{folder}/u.py:project",
        ]
    )
    assert code == 0, capsys.readouterr().err
    assert "\\xff" in ET.parse(junit).getroot().find("testsuite/properties/property").get("value")
    assert "\\udcff/u.py:project" in (out / "report.md").read_text(encoding="utf-8")
    assert json.loads((out / "report.json").read_text())["candidate"].endswith("\udcff/u.py:project")


# ---------------------------------------------------------------- the pytest plugin


@pytest.fixture(scope="module")
def loaded(tmp_path_factory):
    """A failing check's report written once here, so that pytester's in-process runs import nothing new.

    Such a run unloads the modules it imported, and a C extension (numpy.fft's, under matplotlib) cannot
    load twice in one process: the next run's import would fail.
    """
    from wirecheck.oracles.reports.report import write_report

    report = check_projector(lambda p, c: project_points(p, c) + 0.5, isolate=False, **ONE)
    write_report(tmp_path_factory.mktemp("loaded") / "r", report, {})


def test_the_report_summary_comes_from_the_test_reports(pytester, loaded):
    # under pytest-xdist the checks run in workers: the summary counts what the reports carry
    # (user_properties), not what the controller's process wrote; pytest's --junitxml gets the path
    pytester.makepyfile(
        test_user="""
from wirecheck.core.projector.projection import project_points

def test_shifted(wirecheck):
    wirecheck(lambda p, c: project_points(p, c) + 0.5, scenes=["cube"], frames=1, cases=["on_axis"], isolate=False)
"""
    )
    result = pytester.runpytest("--wirecheck-report", "reps", "--junitxml", "pytest.xml", "-p", "no:xdist")
    result.assert_outcomes(failed=1)
    result.stdout.fnmatch_lines(["1 report(s) of failing checks under reps"])
    prop = ET.parse(pytester.path / "pytest.xml").getroot().find(".//testcase/properties/property")
    shifted = "test_user.py_test_shifted-c1fc865c"  # + the first 8 hex digits of sha1("test_user.py::test_shifted")
    assert (prop.get("name"), prop.get("value")) == ("wirecheck_report", f"reps/{shifted}")
    assert (pytester.path / "reps" / shifted / "report.json").is_file()


def test_test_ids_that_differ_only_in_replaced_characters_get_their_own_reports(pytester, loaded):
    # "[a b]" and "[a_b]" were both DIR/test_user.py_test_shift_a_b: the second report replaced the
    # first; a parameter id "cube-2" was the folder name of test_shift[cube]'s second check
    pytester.makepyfile(
        test_user="""
import pytest
from wirecheck.core.projector.projection import project_points

@pytest.mark.parametrize("shift", [0.5, 0.25, 0.125, 2.0], ids=["a b", "a_b", "cube-2", "cube"])
def test_shift(wirecheck, shift):
    try:
        wirecheck(lambda p, c: project_points(p, c) + shift, scenes=["cube"], frames=1, cases=["on_axis"],
                  isolate=False)
    finally:
        if shift == 2.0:
            wirecheck(lambda p, c: project_points(p, c) + 1.0, scenes=["cube"], frames=1, cases=["on_axis"],
                      isolate=False)
"""
    )
    result = pytester.runpytest("--wirecheck-report", "reps", "-p", "no:xdist")
    result.assert_outcomes(failed=4)
    folders = sorted((pytester.path / "reps").iterdir())
    # each shift moves every vertex by (s, s): max error s * sqrt(2), one folder per check
    errors = sorted(
        round(json.loads((f / "report.json").read_text())["summary"]["max_vertex_error_px"] ** 2 / 2, 6)
        for f in folders
    )
    assert errors == [0.015625, 0.0625, 0.25, 1.0, 4.0] and len(folders) == 5
    assert sum(f.name.startswith("test_user.py_test_shift_a_b-") for f in folders) == 2


def test_a_long_test_id_gets_a_folder_name_the_file_system_takes(tmp_path):
    from wirecheck.oracles.pytest_plugin import report_name

    # a parametrized id of 300 characters: 120 kept + "-" + 8 hex digits, under NAME_MAX (255 bytes)
    names = [report_name(f"t.py::test[{c * 300}]") for c in "xy"]
    assert [len(n) for n in names] == [129, 129] and names[0] != names[1]
    (tmp_path / names[0]).mkdir()  # before: OSError "File name too long", "report not written"


def test_an_empty_list_answers_an_empty_request():
    # a list-of-lists projector (accepted above) answers no points with [], shape (0,): it was refused
    # ("returned shape (0,): expected (0, 2)"), so the spec suite's empty_mesh check failed a correct
    # candidate (found by benchmarks/fuzz_round5.py). [] for no points is (0, 2); for 8 points it is still refused.
    from wirecheck.core.camera import camera_z
    from wirecheck.oracles.candidates.candidate import CandidateError, call_candidate_precision
    from wirecheck.oracles.spec import run_checks

    def as_list(p, c):
        return project_points(p, c).tolist()

    px, precision = call_candidate_precision(as_list, np.zeros((0, 3)), camera_z(4.0))
    assert px.shape == (0, 2) and px.dtype == np.float64 and precision == "float64"
    with pytest.raises(CandidateError, match=r"returned shape \(0,\): expected \(8, 2\)"):
        call_candidate_precision(lambda p, c: [], np.zeros((8, 3)), camera_z(4.0))
    (empty,) = run_checks(as_list, names=("empty_mesh",))
    assert empty["verdict"] == "pass", empty["reasons"]
