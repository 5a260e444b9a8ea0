"""One report builder for both sources of frames (oracles.judge.run_report): what is counted from the cases'
records, the keys each source writes and in which order, and a field no source writes refused."""

from __future__ import annotations

import pytest
from wirecheck.oracles.judge.run_report import run_report, summary, tolerances_field
from wirecheck.oracles.tolerances import Tolerances


def _projector_case(verdict, vertex_px, f1_0, f1_1, frames=3, vertices=24, pixels=500) -> dict:
    return {
        "verdict": verdict,
        "max_vertex_error_px": vertex_px,
        "pixel_f1_0px": f1_0,
        "pixel_f1_1px": f1_1,
        "compared": {"frames": frames, "vertices": vertices, "pixels": pixels},
    }


def _frames_case(verdict, f1_0, f1_1, core_0, core_1, pixels=400) -> dict:
    return {
        "verdict": verdict,
        "max_vertex_error_px": None,
        "pixel_f1_0px": f1_0,
        "pixel_f1_1px": f1_1,
        "core": {"f1_0px": core_0, "f1_1px": core_1},
        "compared": {"frames": 4, "vertices": 0, "pixels": pixels},
    }


PROJECTOR_FIELDS = {
    "candidate": "mine",
    "candidate_settings": None,
    "style": "wireframe",
    "hidden_lines": False,
    "cull": "none",
    "oracles": ["opencv", "pyrender"],
    "oracle_gl": None,
    "frames": 6,
    "every": 2,
    "frames_checked": 3,
    "motion": {"turns": [1.0, 1.0, 0.0]},
    "tolerances": {},
    "timing": {"wall_s": 0.0},
}


def test_a_projector_run_counts_its_cases_and_writes_its_keys_in_its_order():
    records = [
        _projector_case("pass", 0.25, 0.99, 1.0),
        _projector_case("fail", 3.5, 0.40, 0.75),
        _projector_case("vacuous", None, None, None, frames=3, vertices=0, pixels=0),
    ]
    report = run_report(records, "pixels", True, PROJECTOR_FIELDS)
    # counted by hand from the three records: two cases compared something (the vacuous one is not counted)
    assert report["compared"] == {"cases": 2, "frames": 9, "vertices": 48, "pixels": 1000}
    assert report["summary"] == {
        "cases": 3,
        "passed": 1,
        "failed": 1,
        "vacuous": 1,
        "max_vertex_error_px": 3.5,
        "min_pixel_f1_0px": 0.40,
        "min_pixel_f1_1px": 0.75,
    }
    assert report["verdict"] == "fail"  # a failed case fails the run
    # the projector's order (as report.json has always been written): counts first, then what was run
    assert list(report) == [
        "tool",
        "verdict",
        "allow_vacuous",
        "compared",
        "candidate",
        "candidate_settings",
        "level",
        "style",
        "hidden_lines",
        "cull",
        "oracles",
        "oracle_gl",
        "frames",
        "every",
        "frames_checked",
        "motion",
        "tolerances",
        "summary",
        "cases",
        "timing",
    ]


def test_a_vacuous_case_fails_the_run_unless_allowed():
    records = [_projector_case("pass", 0.1, 1.0, 1.0), _projector_case("vacuous", None, None, None, pixels=0)]
    assert run_report(records, "pixels", False, PROJECTOR_FIELDS)["verdict"] == "fail"
    assert run_report(records, "pixels", True, PROJECTOR_FIELDS)["verdict"] == "pass"


def test_a_renderers_frames_have_cores_second_opinion_and_their_own_order():
    records = [_frames_case("pass", 0.97, 1.0, 0.96, 0.99), _frames_case("pass", 0.95, 0.98, 0.97, 0.995)]
    fields = {
        **{k: v for k, v in PROJECTOR_FIELDS.items() if k != "oracles"},
        "oracles": ["pyrender", "core"],
        "line_rule": "any",
        "motion": {"turns": [1.0, 1.0, 0.0]},
    }
    report = run_report(records, "frames", False, fields)
    assert report["compared"] == {"cases": 2, "frames": 8, "vertices": 0, "pixels": 800}
    assert report["summary"]["min_core_f1_0px"] == 0.96 and report["summary"]["min_core_f1_1px"] == 0.99
    assert report["summary"]["min_pixel_f1_0px"] == 0.95 and report["verdict"] == "pass"
    keys = list(report)
    # the frames' order: the settings first, the counts after the tolerances
    assert keys.index("tolerances") < keys.index("allow_vacuous") < keys.index("line_rule") < keys.index("compared")
    assert keys[-3:] == ["summary", "cases", "timing"]


def test_no_core_minima_without_core_and_a_depth_only_job_has_them_empty():
    assert "min_core_f1_0px" not in summary([_projector_case("pass", 0.1, 1.0, 1.0)], "pixels")
    depth_only = {"verdict": "pass", "compared": {"frames": 2, "vertices": 0, "pixels": 10}}
    got = summary([depth_only], "frames", second_opinion=True)
    assert got["min_core_f1_0px"] is None and got["min_pixel_f1_0px"] is None


def test_a_field_no_source_writes_is_refused():
    with pytest.raises(ValueError, match="typo_field"):
        run_report([_projector_case("pass", 0.1, 1.0, 1.0)], "pixels", False, {**PROJECTOR_FIELDS, "typo_field": 1})
    with pytest.raises(ValueError, match="line_rule"):  # a frames field in a projector's report
        run_report([_projector_case("pass", 0.1, 1.0, 1.0)], "pixels", False, {**PROJECTOR_FIELDS, "line_rule": "gl"})


def test_a_renderers_frames_are_held_to_no_candidate_precision():
    tol = Tolerances()
    frames = tolerances_field(tol, "frames")
    assert "candidate_precision" not in frames and "candidate_precision" in tolerances_field(tol, "pixels")
    assert "max_depth_error_ratio" not in frames
    assert "max_depth_error_ratio" in tolerances_field(tol, "frames", outputs=("wireframe", "depth"))
