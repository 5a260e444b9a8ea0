"""Same job, same frames, same report: ``crosscheck --candidate-frames`` judged twice writes the same bytes.

report.md, report.html and every picture are byte-identical; report.json is, once its ``timing`` field
(the only place a run's times live) is taken out; ``.wirecheck-output`` lists report.json's hash, so it
differs with the timing and is left out. The frames fail (moved 2 px right; the blank job's frames are
square-on, where a mirror draws the same pixels), so that the image diagnosis, the fault text and the
diff pictures are compared too.
"""

from __future__ import annotations

import json

import helpers  # tests/ is on sys.path (rootdir conftest)
import numpy as np
from wirecheck.oracles import cli as crosscheck_cli


def _tree(folder) -> dict:
    return {p.relative_to(folder).as_posix(): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def test_a_job_judged_twice_writes_the_same_report(tmp_path, capsys):
    job = helpers.blank_job(tmp_path / "job")
    helpers.fill_job(job, edit=lambda img: np.roll(img, 2, axis=1))
    trees = []
    for name in ("r1", "r2"):
        assert crosscheck_cli.main(["--candidate-frames", str(job), "--report-dir", str(tmp_path / name)]) == 1
        trees.append(_tree(tmp_path / name))
    out = capsys.readouterr().out
    assert "pixel_offset(" in out, out
    a, b = trees
    assert sorted(a) == sorted(b)
    assert {"report.md", "report.html", "pixels.png"} <= set(a) and any(n.endswith("-diff.png") for n in a)
    reports = [json.loads(t.pop("report.json")) for t in (a, b)]
    for t in (a, b):
        t.pop(".wirecheck-output", None)
    assert [r.pop("timing").keys() for r in reports][0] == {"wall_s"}
    assert reports[0] == reports[1]
    differ = [n for n in a if a[n] != b[n]]
    assert differ == [], differ
