"""Projectors written the way real code writes them (tests/data/real_world/), judged end to end.

Each file follows a public library or tutorial formula by formula (glm, DirectXMath,
Ray Tracing in One Weekend, the pygame tutorials, an OpenCV-style calibrated camera).
The expected verdicts and fault parameters below are derived by hand from those
formulas, in the comments; none comes from wirecheck.
"""
from __future__ import annotations

import sys
from pathlib import Path

import pytest

import wirecheck

sys.path.insert(0, str(Path(__file__).parent / "data" / "real_world"))

import d3d_lh  # noqa: E402
import glm_gl  # noqa: E402
import pygame_tutorial  # noqa: E402
import rtiow  # noqa: E402

PERSPECTIVE = ["on_axis", "oblique_roll", "near_plane", "wide_fov", "narrow_fov", "non_square"]
# The fitted parameters are least-squares estimates over exact float64 pixels;
# 1e-6 relative is far above their float64 noise (~1e-12) and far below any
# difference between the faults' values (>= 1e-3 relative).
REL = 1e-6


def _check(func, cases=None, **kw):
    return wirecheck.check_projector(func, cases=cases, frames=3, isolate=False, **kw)


def _faults(case):
    return {f["name"]: f for f in case["faults"]}


def test_rtiow_v4_pixel_centres_pass():
    # v4 looks through pixel00_loc = upper-left + half a pixel step: the contract exactly.
    report = _check(rtiow.project_v4, PERSPECTIVE)
    assert report["verdict"] == "pass"
    assert report["compared"]["vertices"] > 0


def test_rtiow_v3_viewport_edges_are_a_scale_of_w_minus_1_over_w():
    # v3: u = i / (W - 1) spans the viewport edge to edge, so pixel steps are
    # (W - 1) / W of the contract's horizontally and (H - 1) / H vertically.
    report = _check(rtiow.project_v3, PERSPECTIVE)
    assert report["verdict"] == "fail"
    for case in report["cases"]:
        w, h = case["camera_spec"]["width"], case["camera_spec"]["height"]
        faults = _faults(case)
        assert set(faults) == {"aspect_mismatch", "fov_mismatch"}, case["camera"]
        assert faults["aspect_mismatch"]["scale_x"] == pytest.approx((w - 1) / w, rel=REL)
        assert faults["aspect_mismatch"]["scale_y"] == pytest.approx((h - 1) / h, rel=REL)


def test_pygame_tutorial_wrapped_correctly_passes():
    report = _check(pygame_tutorial.project, PERSPECTIVE)
    assert report["verdict"] == "pass"


def test_pygame_tutorial_as_written_is_a_horizontal_fov_and_a_corner_centre():
    # f from the width instead of the height: every distance scaled by W / H;
    # centre at (W/2, H/2) instead of ((W-1)/2, (H-1)/2): offset (+0.5, +0.5).
    report = _check(pygame_tutorial.project_as_written, PERSPECTIVE)
    assert report["verdict"] == "fail"
    for case in report["cases"]:
        w, h = case["camera_spec"]["width"], case["camera_spec"]["height"]
        faults = _faults(case)
        assert set(faults) == {"fov_mismatch", "pixel_offset"}, case["camera"]
        assert faults["fov_mismatch"]["scale"] == pytest.approx(w / h, rel=REL)
        assert faults["pixel_offset"]["dx"] == pytest.approx(0.5, abs=1e-6)
        assert faults["pixel_offset"]["dy"] == pytest.approx(0.5, abs=1e-6)
