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


import opencv_k  # noqa: E402

CALIBRATED = ["off_centre", "non_square_pixels", "distorted"]


def test_opencv_k_by_hand_passes_calibrated_and_distorted_cases():
    # The documented projectPoints model written out in numpy: every case passes.
    report = _check(opencv_k.project, ["on_axis"] + CALIBRATED)
    assert report["verdict"] == "pass"
    assert {c["camera"] for c in report["cases"]} == {"on_axis", *CALIBRATED}


def _lens_faults(func):
    report = _check(func, CALIBRATED)
    assert report["verdict"] == "fail"
    for case in report["cases"]:
        if case["camera"] != "distorted":
            assert case["verdict"] == "pass", case["camera"]  # no lens there: nothing to get wrong
    return [
        (case["camera_spec"]["distortion"], _faults(case)["distortion_mismatch"])
        for case in report["cases"]
        if case["camera"] == "distorted"
    ]


def test_opencv_k_without_the_lens_is_distortion_ignored():
    for coeffs, fault in _lens_faults(opencv_k.project_no_lens):
        assert fault["kind"] == "ignored"
        # the candidate behaves as a lens with every coefficient zero
        assert fault["k1"] == pytest.approx(0.0, abs=1e-9) and fault["k2"] == pytest.approx(0.0, abs=1e-9)


def test_opencv_k_with_k1_flipped_is_named_with_the_candidates_k1():
    for coeffs, fault in _lens_faults(opencv_k.project_k1_sign):
        assert fault["kind"] == "k1_sign"
        # the fitted lens is the camera's with k1 negated; other coefficients as given.
        # 1e-9: the fit is linear least squares over exact float64 pixels (residual ~1e-13 px)
        assert fault["k1"] == pytest.approx(-coeffs[0], abs=1e-9)
        assert fault["k2"] == pytest.approx(coeffs[1], abs=1e-9)
        assert (fault["p1"], fault["p2"]) == pytest.approx((coeffs[2], coeffs[3]), abs=1e-9)


# ---- float32 candidates (glm, DirectXMath): judged at their precision (oracles/tolerances.py) ----

ALL_CASES = PERSPECTIVE + ["orthographic"]


def _judged_float32(case):
    # the float32 arrays they return make them float32 candidates, held to the derived
    # bound (~1e-3 px on these cases) instead of 1e-6 px
    assert case["precision"]["judged_as"] == "float32" and case["precision"]["source"] == "returned"
    assert 1e-4 < case["vertex_bound_px"] < 5e-3


@pytest.mark.parametrize("func", [glm_gl.project, d3d_lh.project], ids=["glm", "d3d"])
def test_float32_gl_and_d3d_projectors_wrapped_correctly_pass_at_both_levels(func):
    report = _check(func, ALL_CASES)
    assert report["verdict"] == "pass"
    for case in report["cases"]:
        _judged_float32(case)
    pixels = _check(func, ["near_plane", "wide_fov", "orthographic"], oracles=("opencv", "pyrender"))
    assert pixels["verdict"] == "pass"
    assert all(c["pixel_f1_1px"] == 1.0 for c in pixels["cases"])


def test_glm_window_coordinates_are_a_vertical_mirror_and_half_a_pixel():
    # projectNO's window: x_win = x_px + 0.5 and y_win = H - y_px - 0.5 = (H - 1) - y_px + 0.5:
    # y mirrored about the image centre, and +0.5 on both axes.
    report = _check(glm_gl.project_naive, ALL_CASES)
    for case in report["cases"]:
        _judged_float32(case)
        faults = _faults(case)
        assert list(faults) == ["mirror_vertical", "pixel_offset"], case["faults"]
        # fitted through float32 noise: the offset within the case's bound of 0.5
        assert faults["pixel_offset"]["dx"] == pytest.approx(0.5, abs=case["vertex_bound_px"])
        assert faults["pixel_offset"]["dy"] == pytest.approx(0.5, abs=case["vertex_bound_px"])


def test_d3d_left_handed_on_a_right_handed_world_is_a_horizontal_mirror():
    # LookAtLH's x = up x z is -(forward x up) = -right in a right-handed world: x mirrored.
    report = _check(d3d_lh.project_naive, ALL_CASES)
    for case in report["cases"]:
        _judged_float32(case)
        assert [f["name"] for f in case["faults"]] == ["mirror_horizontal"], case["faults"]
