"""``--help`` ends with examples that parse; a value starting with '-' gets the '=' hint."""

import re
import shlex
import subprocess
import sys

import pytest
from wirecheck.core.app.cli import build_parser as renderer_parser
from wirecheck.core.app.cli_help import CROSSCHECK_EXAMPLES, RENDERER_EXAMPLES, usage_hint
from wirecheck.oracles.cli import build_parser as crosscheck_parser


def _example_commands(text, program):
    """The command of each example line (the description after two or more spaces dropped)."""
    out = []
    for line in text.splitlines():
        if not line.startswith(f"  {program}"):
            continue
        for part in line.strip().split(" ; "):
            out.append(re.split(r"\s{2,}", part.strip())[0])
    return out


@pytest.mark.parametrize(
    "program, text, parser",
    [("renderer", RENDERER_EXAMPLES, renderer_parser), ("crosscheck", CROSSCHECK_EXAMPLES, crosscheck_parser)],
)
def test_every_example_parses(program, text, parser, capsys):
    commands = _example_commands(text, program)
    assert len(commands) >= 6
    for command in commands:
        argv = shlex.split(command)[1:]
        if argv[:1] == ["export"]:  # crosscheck's export subcommand has its own parser
            continue
        parser().parse_args(argv)  # a usage error would SystemExit(2) here
    assert text.splitlines()[0] == "examples:"
    assert parser().format_help().rstrip().endswith(text.splitlines()[-1])


def test_a_negative_value_without_equals_gets_the_hint():
    assert usage_hint("argument --distortion: expected one argument") == (
        "argument --distortion: expected one argument (a value starting with '-' is given with '=': "
        "--distortion=-0.2,...)"
    )
    assert usage_hint("argument --fov: invalid float value: 'x'") == "argument --fov: invalid float value: 'x'"


def test_renderer_says_so_in_one_line():
    # a value starting with '-' that is no number is still argparse's to refuse
    done = subprocess.run(
        [sys.executable, "-m", "wirecheck.core.app.cli", "--out", "-x"], capture_output=True, text=True, timeout=60
    )
    assert done.returncode == 2
    assert done.stderr.splitlines() == [
        "renderer: error: argument --out: expected one argument (a value "
        "starting with '-' is given with '=': --out=-0.2,...)"
    ]


def test_a_negative_number_needs_no_equals():
    # before: "argument --distortion: expected one argument" (argparse takes -0.2,0.05,0,0 for an option)
    args = renderer_parser().parse_args(["--distortion", "-0.2,0.05,0,0", "--camera-pos", "-1e5,2,3"])
    assert (args.distortion, args.camera_pos) == ("-0.2,0.05,0,0", "-1e5,2,3")
