"""What ``--help`` ends with (examples) and the hint added to argparse's "expected one argument".

Both CLIs (``renderer`` in core.app.cli, ``crosscheck`` in oracles.cli) use these, so their help
and their usage errors read alike.
"""

from __future__ import annotations

import re

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
