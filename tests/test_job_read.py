"""One renderer, one reading (oracles.judge.job_read): a job's cases pooled into one read of its renderer, and
a case judged again under it.

The records and the evidence below are written by hand (nothing drawn or measured by the code under test);
the end-to-end tests draw small jobs with the held-out renderers of tests/clients/heldout_draw.py, whose
cases were measured to read the renderer otherwise than the job's other cases before the job's read
existed (docs/frames.md, "Held-out renderers").
"""

from __future__ import annotations

import dataclasses
import json
import math
import shutil
import sys
from pathlib import Path

import pytest
from test_decide_steps import TOL, _aliased, _evidence, _style
from wirecheck.oracles.cli import main
from wirecheck.oracles.judge.decide import decide
from wirecheck.oracles.judge.job_read import MIN_OFFSET_CASES, JobRead, differs, read_job
from wirecheck.oracles.judge.name_faults import name_faults

sys.path.insert(0, str(Path(__file__).parent / "clients"))
import heldout_draw as hd  # noqa: E402

UP = math.inf


def _rec(style="aliased", rule="gl", offset=(0.0, 0.0), names=(), verdict=None, tol_px=0.35):
    verdict = verdict or ("fail" if names else "pass")
    return {
        "verdict": verdict,
        "faults": [{"name": n} for n in names],
        "line_style": {
            "style": style,
            "rule_read": rule,
            "offset_tol_px": tol_px,
            "geometry": {"offset_px": None if offset is None else list(offset)},
        },
    }


# ---------------------------------------------------------------- the job's read


def test_the_job_reads_what_most_cases_read_and_imposes_nothing_on_a_tie():
    job = read_job([_rec(), _rec(), _rec(style="antialiased", rule=None)])
    assert (job.cases, job.style, job.rule) == (3, "aliased", "gl")
    tie = read_job([_rec(), _rec(style="wide", rule="rounded")])
    assert (tie.style, tie.rule) == (None, None)
    assert read_job([{"verdict": "pass", "faults": []}]).cases == 0  # a case without wireframes reads nothing


def test_the_jobs_offset_is_the_median_of_enough_cases_and_skips_misplaced_lines():
    # the median per axis (one case's own move, 2.0 px, does not move it); a mirrored case's centres measure
    # stray crossings, not the renderer's placement: left out
    recs = [_rec(offset=(0.5, 0.4)), _rec(offset=(0.0, 0.0)), _rec(offset=(0.6, 2.0)), _rec(offset=(0.45, 0.5))]
    recs.append(_rec(offset=(-9.0, -9.0), names=("mirror_vertical",)))
    job = read_job(recs)
    assert job.offset_px == pytest.approx((0.475, 0.45)) and job.offset_cases == 4
    # fewer than MIN_OFFSET_CASES measured: no job offset (a case's own is not pooled)
    few = read_job([_rec(offset=(0.5, 0.5))] * (MIN_OFFSET_CASES - 1) + [_rec(offset=None)])
    assert few.offset_px is None and few.offset_cases == MIN_OFFSET_CASES - 1


def test_the_jobs_rule_name_is_the_one_most_failing_cases_get_and_raster_rule_on_a_tie():
    assert read_job([_rec(names=("line_pixel_bias",))] * 2 + [_rec(names=("raster_rule",))]).rule_name == (
        "line_pixel_bias"
    )
    assert read_job([_rec(names=("line_pixel_bias",)), _rec(names=("raster_rule",))]).rule_name == "raster_rule"
    # one failing case is its own; an end fault or two names are no rule name
    assert read_job([_rec(names=("line_pixel_bias",)), _rec()]).rule_name is None
    assert read_job([_rec(names=("line_end_bias",))] * 3).rule_name is None
    assert read_job([_rec(names=("raster_rule", "pixel_offset"))] * 3).rule_name is None


def test_a_case_differs_where_its_own_read_is_not_the_jobs():
    job = JobRead(21, "aliased", "rounded", "raster_rule", (0.0, 0.0), 21)
    assert not differs(_rec(rule="rounded"), job)
    assert differs(_rec(style="antialiased", rule="rounded"), job)
    assert differs(_rec(rule="gl"), job)
    assert differs(_rec(rule="rounded", names=("line_pixel_bias",)), job)
    assert not differs(_rec(rule="rounded", names=("line_end_bias",)), job)
    moved = dataclasses.replace(job, offset_px=(0.5, 0.5))
    assert differs(_rec(rule="rounded"), moved)  # the job's lines are moved, this case named nothing of it
    assert not differs(_rec(rule="rounded", names=("pixel_offset",)), moved)
    assert not differs({"verdict": "pass", "faults": []}, moved)  # no wireframe: nothing to read


# ---------------------------------------------------------------- a case under the job's read


def _with_job(style, **job):
    return dataclasses.replace(style, job={"offset_px": None, "offset_cases": 0, **job})


@pytest.mark.parametrize("style", ["aliased", "antialiased"])
def test_the_jobs_offset_just_past_the_bound_fails_a_case_whose_own_reads_none(style):
    # the case's own centres in place (0, 0); the job's median just past the case's offset bound (binary lines:
    # rule_offset_px; grey: offset_px + half a coverage step): pixel_offset with the job's numbers; just at it:
    # the case passes as it did alone
    s = _aliased(1.0, "any") if style == "aliased" else _style()
    bound = TOL.rule_offset_px if style == "aliased" else TOL.offset_px + 0.5 / 4
    past = _evidence(style=_with_job(s, offset_px=[math.nextafter(bound, UP), 0.0], offset_cases=20))
    v = decide(past, TOL)
    assert v.verdict == "fail" and v.style.job_moved and "the job's line centres offset" in v.reasons[-1]
    (f,) = name_faults(past, v, TOL)
    assert f.name == "pixel_offset" and f.params["dx"] == math.nextafter(bound, UP)
    assert f.params["measured_by"] == "the job's line centroids (median of 20 cases)"
    at = _evidence(style=_with_job(s, offset_px=[bound, 0.0], offset_cases=20))
    assert decide(at, TOL).verdict == "pass" and name_faults(at, decide(at, TOL), TOL) == ()


def test_the_jobs_offset_never_replaces_a_cases_own_offset_failure():
    # grey lines moved 0.6 px in this case: its own offset is reported, once (not the job's 0.5)
    s = _with_job(_style(dx=0.6), offset_px=[0.5, 0.5], offset_cases=20)
    v = decide(_evidence(style=s), TOL)
    assert not v.style.job_moved and sum("offset" in r for r in v.reasons) == 1 and "(0.60, 0.00)" in v.reasons[0]


def test_the_jobs_rounded_rule_holds_a_case_that_read_gls_alone():
    # aliased pixels 0.9 against GL's rule and 0.99 against the rounded ends' but with an end bias of that
    # rule's (its F1 alone would read "rounded" only if higher than GL's: here GL's rule was read): with the
    # job reading the rounded-ends rule, the case is held to that rule's limits
    lines = {
        "imbalance_fraction": 0.02,
        "balance_p_value": 1e-6,
        "subpixel_ties": [0, 0],
        "candidate_only": 0,
        "oracle_only": 24,
        "edge_count_max_diff": 0,
        "edge_count_worst": None,
        "imbalance": -24,
        "lines_compared": 12,
        "one_sided_by_place": {"start": [0, 12], "end": [0, 12], "middle": [0, 0]},
    }
    s = _aliased(0.99, "any")
    s = dataclasses.replace(s, rounded={"pixel_f1_0px": 0.99, "lines": lines})
    alone = _evidence(f1_0=0.995, style=s, lines=lines)  # GL's F1 higher than the rounded ends': GL read
    assert decide(alone, TOL).style.rule_read == "gl"
    pooled = _evidence(f1_0=0.995, style=_with_job(s, rule="rounded"), lines=lines)
    v = decide(pooled, TOL)
    assert v.style.rule_read == "rounded" and v.style.rounded_case == "biased" and not v.style.pixel_rule
    assert any(r.endswith("(the rounded-ends rule)") for r in v.reasons)
    # under the rule's F1 floor the job's rule cannot hold it: GL's read stays
    low = dataclasses.replace(s, rounded={"pixel_f1_0px": math.nextafter(TOL.rule_f1_0px, -UP), "lines": lines})
    assert decide(_evidence(f1_0=0.995, style=_with_job(low, rule="rounded"), lines=lines), TOL).style.rule_read == (
        "gl"
    )


def test_a_case_named_by_the_other_rule_name_gets_the_jobs():
    # GL's F1@0px missed alone on lines in place: raster_rule alone; the job's failing cases are line_pixel_bias:
    # the case gets that name, its numbers its own line fields'
    lines = {
        "imbalance_fraction": 0.0,
        "balance_p_value": 1.0,
        "subpixel_ties": [1, 2],
        "candidate_only": 30,
        "oracle_only": 12,
        "edge_count_max_diff": 0,
        "edge_count_worst": None,
        "imbalance": 0,
        "lines_compared": 12,
        "one_sided_by_place": {"start": [0, 0], "end": [0, 0], "middle": [29, 10], "stray": [1, 2]},
    }
    s = dataclasses.replace(_aliased(0.5, "any"), raster={**_aliased(0.5, "any").raster, "differing": 40})
    alone = _evidence(f1_0=0.9, style=s, lines=lines)
    assert [f.name for f in name_faults(alone, decide(alone, TOL), TOL)] == ["raster_rule"]
    pooled = _evidence(f1_0=0.9, style=_with_job(s, rule_name="line_pixel_bias"), lines=lines)
    (f,) = name_faults(pooled, decide(pooled, TOL), TOL)
    assert f.name == "line_pixel_bias" and (f.params["candidate_only"], f.params["oracle_only"]) == (29, 10)
    assert (f.params["net_middle"], f.params["net_stray"]) == (19, -1)
    back = _evidence(f1_0=0.9, style=_with_job(s, rule_name="raster_rule"), lines=lines)
    assert [f.name for f in name_faults(back, decide(back, TOL), TOL)] == ["raster_rule"]


def test_the_summary_says_which_cases_were_judged_under_the_jobs_read():
    # report.md / stdout: one line, once, naming how many cases were judged again and the job's read, by hand
    from wirecheck.oracles.judge.line_style import summary_lines

    job = {
        "cases": 21,
        "style": "aliased",
        "rule": "gl",
        "rule_name": None,
        "offset_px": [0.5, 0.49],
        "offset_cases": 19,
    }
    base = {"style": "aliased", "line_rule": "any", "width_px": 1.0, "judged_by": "x"}
    cases = [{"line_style": {**base, "job_read": job}}] * 2 + [{"line_style": base}]
    lines = [x for x in summary_lines(cases) if x.startswith("One renderer")]
    assert lines == [
        "One renderer, one reading: 2 cases read the renderer otherwise than the job's 21 cases together and were "
        "judged again under the job's read (style aliased, rule gl, offset (0.50, 0.49) px)"
    ]
    assert not [x for x in summary_lines([{"line_style": base}]) if x.startswith("One renderer")]


# ---------------------------------------------------------------- end to end: one renderer, one name


@pytest.fixture(scope="module")
def square_on_job(tmp_path_factory) -> Path:
    # four cases of the cube: narrow_fov shows its lines square-on to the grid, where a half-pixel move reads
    # (0, 0) (each line moved to a pixel boundary, drawn on one side of it); the other three show it
    path = tmp_path_factory.mktemp("jobread") / "job"
    args = ["export", str(path), "--scene", "cube", "--cases", "narrow_fov,on_axis,oblique_roll,orthographic"]
    assert main(args + ["--frames", "6", "--every", "3"]) == 0
    return path


def _judged(job: Path, tmp_path: Path, draw, **mistake) -> tuple[int, dict]:
    d = tmp_path / "job"
    shutil.copytree(job, d)
    hd.render(d, draw, hd.project_gl, **mistake)
    rc = main(["--candidate-frames", str(d), "--report-dir", str(tmp_path / "rep")])
    cases = json.loads((tmp_path / "rep" / "report.json").read_text())["cases"]
    assert len(cases) == 4 and all(c["frames_checked"] == 2 for c in cases)  # every case judged: not nothing
    return rc, {c["camera"]: c for c in cases}


@pytest.mark.slow
def test_a_half_pixel_renderer_is_pixel_offset_in_every_case(square_on_job, tmp_path, capsys):
    # Pillow 1 px with the half pixel left out: before the job's read, narrow_fov measured (0, 0) and was named
    # raster_rule (held-out: 2 of 21 cases); now every case is pixel_offset, narrow_fov with the job's median
    rc, cases = _judged(square_on_job, tmp_path, hd.draw_pillow, half_pixel=True)
    assert rc == 1 and all(c["verdict"] == "fail" for c in cases.values())
    assert {c["faults"][0]["name"] for c in cases.values()} == {"pixel_offset"}, {
        k: c["faults"] for k, c in cases.items()
    }
    square = cases["narrow_fov"]
    assert square["line_style"]["geometry"]["offset_px"] == [0.0, 0.0]  # its own lines cannot show the move
    (f,) = square["faults"]
    assert f["measured_by"].startswith("the job's line centroids")
    assert f["dx"] == pytest.approx(0.5, abs=0.1) and f["dy"] == pytest.approx(0.5, abs=0.1)
    assert square["line_style"]["job_read"]["offset_cases"] >= MIN_OFFSET_CASES


@pytest.mark.slow
def test_a_correct_renderer_pooled_stays_a_pass(square_on_job, tmp_path, capsys):
    # the twin: the same renderer without the mistake passes every case, none judged again
    rc, cases = _judged(square_on_job, tmp_path, hd.draw_pillow)
    assert rc == 0 and all(c["verdict"] == "pass" and c["faults"] == [] for c in cases.values())
    assert not any("job_read" in c["line_style"] for c in cases.values())


# ---------------------------------------------------------------- the read's edges, by hand


def test_three_cases_are_enough_for_the_jobs_offset():
    # three: the fewest whose median leaves one case's own move out (two of three agree; of two, the median is
    # their mean). Per axis: x (0.45, 0.5, 0.6) -> 0.5, y (0.0, 0.4, 2.0) -> 0.4
    job = read_job([_rec(offset=(0.5, 0.4)), _rec(offset=(0.45, 0.0)), _rec(offset=(0.6, 2.0))])
    assert job.offset_px == (0.5, 0.4) and job.offset_cases == 3


def test_three_styles_read_once_each_impose_none():
    # a three-way tie is a tie too (the two most common share the top count): no style imposed
    recs = [_rec(), _rec(style="wide", rule="rounded"), _rec(style="antialiased", rule=None)]
    assert read_job(recs).style is None


@pytest.mark.parametrize("offset", [(0.5, 0.0), (0.0, 0.5), (-0.5, 0.0), (0.0, -0.5)])
def test_the_jobs_offset_on_either_axis_past_the_cases_bound_differs(offset):
    # the job's lines moved half a pixel along one axis (either sign), the case's bound 0.35 px and no
    # pixel_offset of its own: judged again; a job offset exactly at the bound is not beyond it
    job = JobRead(21, "aliased", "gl", None, offset, 21)
    assert differs(_rec(), job)
    assert not differs(_rec(tol_px=0.5), job)
    assert differs(_rec(tol_px=math.nextafter(0.5, -UP)), job)


def test_the_jobs_read_as_a_record_is_plain_json():
    # report.json's job_read: the offset a list of two Python floats (a tuple would read back as a list and
    # differ), None kept as None
    job = JobRead(4, "aliased", "rounded", "raster_rule", (0.5, 0.25), 3)
    assert job.as_dict() == {
        "cases": 4,
        "style": "aliased",
        "rule": "rounded",
        "rule_name": "raster_rule",
        "offset_px": [0.5, 0.25],
        "offset_cases": 3,
    }
    assert json.loads(json.dumps(job.as_dict())) == job.as_dict()
    assert dataclasses.replace(job, offset_px=None, offset_cases=2).as_dict()["offset_px"] is None
