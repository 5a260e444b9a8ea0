"""What ``--help`` ends with (examples), and the argument parser both CLIs use.

Both CLIs (``renderer`` in core.app.cli, ``crosscheck`` and ``crosscheck export`` in oracles)
use these, so their help and their usage errors read alike: :class:`OneLineParser` says a usage
error in one line (exit 2) and reads a negative number given as an option's value
(``--phase -inf``, ``--camera-pos -1,2,3``) as that value, where argparse alone takes
``-inf`` for an option and says "expected one argument".
"""

from __future__ import annotations

import argparse
import re
import sys

RENDERER_EXAMPLES = """\
examples:
  renderer                                        180 frames of the cube to output/cube-frames/
  renderer --scene pyramid --frames 60 --fov 70 --format png,gif
  renderer --camera-pos 3,2,4 --look-at 0,0,0 --hidden-lines --style shaded
  renderer --intrinsics 460,460,389.5,194.5 --distortion=-0.2,0.05,0,0
  renderer --trace-vertex 6 --trace-frames 90     one vertex through every space
  renderer --interactive                          a viewer in the browser (127.0.0.1)
docs: docs/renderer.md"""

CROSSCHECK_EXAMPLES = """\
examples:
  crosscheck                                      core's projector, every scene, pixels, 24 frames
  crosscheck --candidate my_proj.py:project       your projector (FILE.py:FUNC or MODULE:FUNC)
  crosscheck --candidate my_proj.py:project --scene cube --level vertices --frames 4
  crosscheck --candidate-cmd './proj --stdio'     a projector in any language (docs/protocol.md)
  crosscheck export job/ ; crosscheck --candidate-frames job/   judge a renderer's own PNGs
  crosscheck --junit-xml out.xml --report-dir reports/ci        for CI
  crosscheck --suite extremes                     numerical extremes; --sweep: speed vs accuracy
  crosscheck --suite spec --candidate my_proj.py:project   the specification's matrix and checks
settings also come from [tool.wirecheck] in pyproject.toml (docs/pytest.md); docs: docs/crosscheck.md"""

_ONE_ARGUMENT = re.compile(r"^argument (--[\w-]+)(?:/[^:]*)?: expected one argument$")


def usage_hint(message: str) -> str:
    """argparse's ``message``, with how to give a value starting with ``-`` for "expected one argument".

    argparse reads ``--distortion -0.2,0.05`` as an option followed by another option
    (``-0.2,...`` looks like one), and says only "expected one argument".
    """
    m = _ONE_ARGUMENT.match(message)
    if m is None:
        return message
    return f"{message} (a value starting with '-' is given with '=': {m.group(1)}=-0.2,...)"


#: A value that starts like a negative number or a list of them: ``-1``, ``-.5``, ``-1e5``, ``-inf``,
#: ``-nan``, ``-1,2,3``. argparse takes only ``-1`` and ``-1.5`` for numbers (no exponent, inf, nan or list).
_NEGATIVE_VALUE = re.compile(r"-(?:\d|\.\d|inf|nan)", re.IGNORECASE)
_LONG_OPTION = re.compile(r"--[A-Za-z][\w-]*")


def attach_negative_values(args: list[str]) -> list[str]:
    """``args`` with ``--opt -VALUE`` joined into ``--opt=-VALUE`` when ``-VALUE`` starts like a negative number.

    No option of wirecheck's is a dash and a digit, or ``-inf``/``-nan``, so such a token after a long
    option is its value. The option decides what it accepts (a flag without a value says so in its line);
    nothing after ``--`` is touched.
    """
    out: list[str] = []
    for i, token in enumerate(args):
        if "--" in args[:i]:
            out += args[i:]
            break
        if out and _NEGATIVE_VALUE.match(token) and _LONG_OPTION.fullmatch(out[-1]):
            out[-1] = f"{out[-1]}={token}"
        else:
            out.append(token)
    return out


class OneLineParser(argparse.ArgumentParser):
    """argparse, but a usage error is one line on stderr (exit 2) and ``--opt -1e5`` gives ``-1e5`` to ``--opt``."""

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {usage_hint(message)}\n")

    def parse_known_args(self, args=None, namespace=None):
        return super().parse_known_args(attach_negative_values(list(sys.argv[1:] if args is None else args)), namespace)
