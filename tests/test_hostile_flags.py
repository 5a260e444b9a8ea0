"""Numeric flags of renderer, crosscheck and crosscheck export given negative and non-finite values (issue 36).

argparse alone reads ``--phase -inf`` as the option ``--phase`` followed by an option ``-inf`` and says
"expected one argument"; it takes only ``-1`` and ``-1.5`` for negative numbers, not ``-1e5``, ``-inf``,
``-nan`` or a list ``-1,2,3``. Every such value now reaches its option, which accepts it (a negative
translation) or refuses it in one line naming the flag, the value and what it expects.
"""

import json

import pytest
from wirecheck.core.app import cli as renderer_cli
from wirecheck.core.app.cli_help import attach_negative_values
from wirecheck.oracles import cli as crosscheck_cli


def run(main, argv, capsys):
    try:
        rc = main(argv)
    except SystemExit as exc:
        rc = exc.code
    out, err = capsys.readouterr()
    return rc, out, err


def test_export_phase_minus_inf_names_the_flag_and_what_it_expects(tmp_path, capsys):
    # before: "crosscheck export: error: argument --phase: expected one argument"
    rc, _, err = run(
        crosscheck_cli.main, ["export", str(tmp_path / "job"), "--scene", "cube", "--phase", "-inf"], capsys
    )
    assert (rc, err) == (
        2,
        "crosscheck: error: --phase -inf: expected a number in [0, 1) (a share of a frame's step)\n",
    )
    assert not (tmp_path / "job").exists()


def test_a_negative_exponent_value_reaches_its_option(tmp_path, capsys):
    """``--spin -2e0,1,0``: the job's motion is what was given (before: "expected one argument")."""
    rc, _, err = run(
        crosscheck_cli.main,
        [
            "export",
            str(tmp_path / "job"),
            "--scene",
            "cube",
            "--cases",
            "on_axis",
            "--frames",
            "1",
            "--spin",
            "-2e0,1,0",
        ],
        capsys,
    )
    assert rc == 0, err
    assert json.loads((tmp_path / "job" / "job.json").read_text())["motion"]["turns"] == [-2.0, 1.0, 0.0]


RENDERER_BASE = ["--scene", "cube", "--frames", "1", "--width", "32", "--height", "24", "--format", "png"]
#: (flag, a hostile value, what the one line must say besides the flag), per CLI; with what the flag needs beside it
RENDERER_FLAGS = [
    ("--camera-z", "-inf", [], "expected a finite non-zero distance"),
    ("--fov", "-inf", [], "expected degrees in (0, 180)"),
    ("--near", "-inf", [], "expected a finite distance"),
    ("--far", "-nan", [], "expected a finite distance"),
    ("--ortho-height", "-inf", ["--projection", "orthographic"], "expected a finite number > 0"),
    ("--scale", "-inf", [], "expected a finite non-zero number"),
    ("--frames", "-1e5", [], "invalid int value"),
    ("--width", "-inf", [], "invalid int value"),
    ("--height", "-nan", [], "invalid int value"),
    ("--ascii-cols", "-1e5", [], "invalid int value"),
    ("--trace-vertex", "-inf", [], "invalid int value"),
    ("--port", "-inf", ["--interactive"], "invalid int value"),
    ("--camera-pos", "-inf,0,0", [], "expected three finite numbers X,Y,Z"),
    ("--look-at", "-nan,0,0", ["--camera-pos", "3,2,4"], "expected three finite numbers X,Y,Z"),
    ("--up", "-inf,1,0", ["--camera-pos", "3,2,4"], "expected three finite numbers X,Y,Z"),
    ("--spin", "-inf,0,0", [], "expected three finite numbers X,Y,Z"),
    ("--translate", "-inf,0,0", [], "expected three finite numbers X,Y,Z"),
    ("--light", "-inf,0,0", ["--style", "shaded"], "expected three finite numbers X,Y,Z"),
    ("--intrinsics", "-inf,1,1,1", [], "finite numbers"),
    ("--distortion", "-inf,0,0,0", [], "finite numbers"),
]
CROSSCHECK_FLAGS = [
    ("--frames", "-1e5", [], "invalid int value"),
    ("--every", "-inf", [], "invalid int value"),
    ("--jobs", "-nan", [], "invalid int value"),
    ("--candidate-timeout", "-inf", ["--candidate-cmd", "true"], "expected a number of seconds > 0"),
    ("--scheduler-timeout", "-inf", ["--executor", "dask"], "expected a number of seconds > 0"),
    ("--tol-px", "-inf", [], "expected a finite number >= 0"),
    ("--min-f1", "-inf", ["--level", "pixels"], "expected a number in [0, 1]"),
    ("--min-f1-0px", "-nan", ["--level", "pixels"], "expected a number in [0, 1]"),
    ("--min-iou", "-inf", ["--level", "pixels"], "expected a number in [0, 1]"),
    ("--spin", "-inf,0,0", [], "expected three finite numbers X,Y,Z"),
]
EXPORT_FLAGS = [
    ("--frames", "-1e5", [], "invalid int value"),
    ("--every", "-inf", [], "invalid int value"),
    ("--phase", "-1e5", [], "expected a number in [0, 1)"),
    ("--spin", "-inf,0,0", [], "expected three finite numbers X,Y,Z"),
    ("--depth-scale", "-1e3", [], "expected a finite number of values per world unit > 0"),
]


def _ids(flags):
    return [f"{f} {v}" for f, v, _, _ in flags]


def _check_refused(rc, err, flag, value, needle):
    assert rc == 2 and err.count("\n") == 1, err
    assert "expected one argument" not in err and "Traceback" not in err
    assert flag in err and needle in err, err


@pytest.mark.parametrize("flag, value, extra, needle", RENDERER_FLAGS, ids=_ids(RENDERER_FLAGS))
def test_renderer_numeric_flag_given_a_hostile_negative_value(tmp_path, capsys, flag, value, extra, needle):
    rc, _, err = run(renderer_cli.main, [*RENDERER_BASE, "--out", str(tmp_path / "out"), *extra, flag, value], capsys)
    _check_refused(rc, err, flag, value, needle)
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("flag, value, extra, needle", CROSSCHECK_FLAGS, ids=_ids(CROSSCHECK_FLAGS))
def test_crosscheck_numeric_flag_given_a_hostile_negative_value(tmp_path, capsys, flag, value, extra, needle):
    argv = [
        "--scene",
        "cube",
        "--level",
        "vertices",
        "--frames",
        "1",
        "--cases",
        "on_axis",
        "--report-dir",
        str(tmp_path / "rep"),
        *extra,
        flag,
        value,
    ]
    rc, _, err = run(crosscheck_cli.main, argv, capsys)
    _check_refused(rc, err, flag, value, needle)
    assert not (tmp_path / "rep").exists()


@pytest.mark.parametrize("flag, value, extra, needle", EXPORT_FLAGS, ids=_ids(EXPORT_FLAGS))
def test_export_numeric_flag_given_a_hostile_negative_value(tmp_path, capsys, flag, value, extra, needle):
    argv = ["export", str(tmp_path / "job"), "--scene", "cube", "--cases", "on_axis", "--frames", "1", flag, value]
    rc, _, err = run(crosscheck_cli.main, argv, capsys)
    _check_refused(rc, err, flag, value, needle)
    assert not (tmp_path / "job").exists()


def test_a_unicode_digit_is_refused_by_crosscheck_as_by_renderer(capsys):
    # '\u0664' (ARABIC-INDIC DIGIT FOUR) is 4 to Python's int(), to no C strtol: before, crosscheck ran 4 frames
    rc, _, err = run(crosscheck_cli.main, ["--scene", "cube", "--frames", "\u0664"], capsys)
    assert rc == 2 and "argument --frames: invalid int value" in err, err


@pytest.mark.parametrize(
    "argv, expected",
    [
        (["--phase", "-inf"], ["--phase=-inf"]),
        (["--spin", "-1,2,3", "--frames", "4"], ["--spin=-1,2,3", "--frames", "4"]),
        (["--far", "-1e5"], ["--far=-1e5"]),
        (["--near", "-.5"], ["--near=-.5"]),
        (["--x", "-NaN"], ["--x=-NaN"]),
        (["--scene", "-h"], ["--scene", "-h"]),  # an option, not a number: argparse's to judge
        (["-h", "-1"], ["-h", "-1"]),  # after a short option: argparse's own rule
        (["--a=1", "-1"], ["--a=1", "-1"]),  # the option has its value already
        (["--", "--a", "-1"], ["--", "--a", "-1"]),  # nothing after "--" is an option
        (["export", "-1"], ["export", "-1"]),  # a positional that looks like a number
    ],
)
def test_attach_negative_values(argv, expected):
    assert attach_negative_values(argv) == expected
