"""``crosscheck --candidate-frames`` starts, as every result does (docs/pytest.md), with what it compared.

Before: the frames path began with the table, and a run with ``--every 2`` elsewhere said "every 2th checked".
The blank job is cube / on_axis, frames 1 and 3 of 4 (``--frames 4 --every 2``): 4 frames per case, 1 in 2.
"""

from __future__ import annotations

import helpers  # tests/ is on sys.path (rootdir conftest)
from wirecheck.oracles import cli as crosscheck_cli


def test_the_first_line_says_what_was_compared(tmp_path, capsys):
    job = helpers.blank_job(tmp_path / "job")
    capsys.readouterr()
    assert crosscheck_cli.main(["--candidate-frames", str(job), "--report-dir", str(tmp_path / "r")]) == 1
    first = capsys.readouterr().out.splitlines()[0]
    assert first == (
        "Compared: level frames (a renderer's PNGs against pyrender; core's beside it), 4 frames per "
        "case (1 in 2 checked), 1 case (1 scene x 1 camera)"
    ), first
