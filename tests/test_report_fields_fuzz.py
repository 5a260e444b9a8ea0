"""Every report writer survives a measured number that is not one: each float field of a real report (and
each field already null), one at a time, set to None (JSON's null for inf/NaN, or 'not measured'), inf and
NaN; report.json/md/html, JUnit, the console table, the first lines and the line-style summary are written
without an exception. Integer counts are left alone: they are counted, never measured, and never inf."""

import copy
import json
import math
import shutil

import pytest
from helpers import blank_job
from wirecheck.oracles import cli
from wirecheck.oracles.judge.line_style import summary_lines
from wirecheck.oracles.reports.compared import hint_lines, what_text
from wirecheck.oracles.reports.console_run import verdict_line
from wirecheck.oracles.reports.junit import junit_xml
from wirecheck.oracles.reports.report import _html, console_table, markdown, write_report
from wirecheck.oracles.tolerances import Tolerances

ODD = (None, math.inf, math.nan)
#: Fields that are null in a real report but never numbers (a run name, settings, a command, a precision name).
NOT_NUMBERS = {"run", "candidate_settings", "command", "candidate_precision"}


def _paths(obj, path=()):
    """Paths of the float (or null) leaves of ``obj``; of a per-frame list, its first entry only."""
    if isinstance(obj, bool):
        return
    if isinstance(obj, float) or obj is None and path[-1] not in NOT_NUMBERS:
        yield path
    elif isinstance(obj, dict):
        for k, v in obj.items():
            if k != "timing" or path:  # timings: wall-clock numbers, fuzzed below anyway
                yield from _paths(v, path + (k,))
    elif isinstance(obj, list):
        for i, v in enumerate(obj[:1] if path and path[-1] == "per_frame" else obj):
            yield from _paths(v, path + (i,))


def _with(report, path, value):
    out = copy.deepcopy(report)
    node = out
    for k in path[:-1]:
        node = node[k]
    node[path[-1]] = value
    return out


def _write_all(report, tmp_path, files: bool):
    """Every writer of a report: JUnit, what the command prints, and (``files``) the run folder: write_report
    nulls inf and NaN before its markdown, html and figures, so the folder is written for None only (each
    write draws the figures: the slow part); its markdown and html are called on inf and NaN directly."""
    failing = [c for c in report["cases"] if c["verdict"] != "pass"]
    if files:
        write_report(tmp_path / "run", report, {})
        shutil.rmtree(tmp_path / "run")
    _html(report, [], set())
    junit_xml(report)
    console_table(report["cases"])
    markdown(report, set())  # direct too: a caller that did not null inf/NaN first
    what_text(report)
    hint_lines(report, failing)
    summary_lines(report["cases"])
    if report.get("level") == "frames":
        verdict_line(report, Tolerances())


@pytest.fixture(scope="module")
def reports(tmp_path_factory):
    """A failing projector's report (pixels level) and a blank renderer's frames report."""
    base = tmp_path_factory.mktemp("fuzz")
    assert (
        cli.main(
            [
                "--scene",
                "cube",
                "--frames",
                "2",
                "--cases",
                "on_axis,oblique_roll",
                "--candidate",
                "tests/data/user_projector.py:project_corner",
                "--report-dir",
                str(base / "p"),
            ]
        )
        == 1
    )
    job = blank_job(base / "job")
    assert cli.main(["--candidate-frames", str(job), "--report-dir", str(base / "f")]) == 1
    return [json.loads((base / d / "report.json").read_text()) for d in ("p", "f")]


@pytest.mark.parametrize("which", [0, 1], ids=["projector", "frames"])
def test_every_float_field_odd(reports, which, tmp_path):
    report = reports[which]
    paths = list(_paths(report)) + [("timing", k) for k, v in report.get("timing", {}).items() if isinstance(v, float)]
    assert len(paths) > 40  # the fuzz reaches the case fields, not just the top level
    crashes = []
    for path in paths:
        for value in ODD:
            try:
                _write_all(_with(report, path, value), tmp_path, files=value is None)
            except Exception as exc:  # collected: every crash named at once
                crashes.append(f"{path}={value}: {type(exc).__name__}: {exc}")
    assert not crashes, "\n".join(crashes[:40]) + f"\n({len(crashes)} in all)"


def test_dataset_timing_not_measured():
    """The dataset run's timing line: a null (or inf) time prints as the module's '-' (None) or 'inf', no
    TypeError; the expected text is written out by hand."""
    from wirecheck.oracles.datasets.dataset_report import timing_text

    t = {"executor": "local", "workers": 2, "wall_s": None, "startup_s": math.inf, "meshes_per_s": math.nan}
    assert timing_text({"timing": t}) == "Timing: - s (inf s starting workers), nan meshes/s (local, 2 process(es))"
