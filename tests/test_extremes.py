"""The extremes suite (oracles/extremes/) through pytest: every case must pass its derived bounds.

The bounds and their derivations live in oracles/extremes/bounds.py (each
function's docstring); here we assert the verdicts, that the suite works
without OSMesa, that its output is deterministic and JSON-able, that the
derivations reach the report, that the bounds are not vacuous, and that the
suite does catch a planted fault. The input-validation checks at the same
extremes (up parallel to forward, NaN / inf input) are CLI tests
(tests/test_renderer_cli.py).
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from wirecheck.oracles import extremes
from wirecheck.oracles.extremes import EXTREME_CASES, bounds, cases, extremes_markdown, measure, run_case, run_extremes
from wirecheck.oracles.references.pyrender_oracle import osmesa_available
from wirecheck.oracles.tolerances import MIN_F1_1PX_EXTREMES

HAVE_OSMESA = osmesa_available()[0]

# The reference needs a long double wider than float64 (x87 80-bit on x86-64 Linux).
pytestmark = pytest.mark.skipif(
    not extremes.REFERENCE_EXTENDED, reason="np.longdouble is plain float64 here: no extended-precision reference"
)


@pytest.fixture(scope="module")
def suite_without_pyrender():
    """The whole suite once, as ``crosscheck --suite extremes`` without OSMesa would run it."""
    return run_extremes(pyrender=False)


def _why(case: dict) -> str:
    return f"{case['name']}: " + "; ".join(case["reasons"])


@pytest.mark.parametrize("name", EXTREME_CASES)
def test_case_passes(name):
    case = run_case(name, pyrender=HAVE_OSMESA)
    assert case["name"] == name
    assert case["verdict"] == "pass", _why(case)
    # every compared point was within its own bound (max error/bound <= 1), in both dtypes
    for dt in ("float64", "float32"):
        stats = case[dt]
        assert stats["max_ratio"] is not None and stats["max_ratio"] <= 1.0, (dt, stats)
        assert stats["max_error_px"] <= stats["bound_px"], (dt, stats)
        assert stats["visible_mismatch_outside_band"] == 0, (dt, stats)
    if HAVE_OSMESA and case["pyrender"] is not None and case["pyrender"]["f1_1px_judged"] is not None:
        assert case["pyrender"]["f1_1px_judged"] >= MIN_F1_1PX_EXTREMES


def test_suite_runs_without_pyrender(suite_without_pyrender):
    res = suite_without_pyrender
    assert res["verdict"] == "pass", [_why(c) for c in res["cases"] if c["verdict"] != "pass"]
    assert [c["name"] for c in res["cases"]] == list(EXTREME_CASES)
    assert res["pyrender"] is False
    for c in res["cases"]:
        assert c["pyrender"] is None and c["pyrender_note"], c["name"]
    json.dumps(res, allow_nan=False)  # strict JSON: no NaN / inf anywhere
    md = extremes_markdown(res)
    assert md.count("\n| ") == len(EXTREME_CASES) + 2  # header, rule, one row per case
    for name in EXTREME_CASES:
        assert f"| {name} |" in md and f"**{name}**" in md


def test_report_prints_every_derivation(suite_without_pyrender):
    # The derivations live in docstrings (bounds.py Notes, each case's Notes): each must be
    # non-empty and reach extremes.md, and every bound a case names must be derived there.
    res = suite_without_pyrender
    md = extremes_markdown(res)
    assert list(res["bounds"]) == [f.__name__ for f in bounds.DERIVED]
    for name, text in res["bounds"].items():
        assert len(text) > 80, name
        for paragraph in text.split("\n\n"):
            assert paragraph in md, (name, paragraph)
    for case in cases.CASES:
        c = next(r for r in res["cases"] if r["name"] == case.__name__)
        assert c["bound_derivation"] == bounds.derivation(case) and c["bound_derivation"], c["name"]
        assert f"Bound: {c['bound_derivation']}" in md
        named = [
            b
            for b in (
                "camera_error",
                "pixel_bound",
                "focal_condition",
                "near_band",
                "clipped_end_bounds",
                "motion_matrix_error",
                "orthonormality_error",
            )
            if b in c["bound_derivation"]
        ]
        assert named, c["name"]
        assert all(f"- **{b}**: " in md for b in named), (c["name"], named)


def test_results_are_deterministic(suite_without_pyrender):
    # everything but "timing" is a pure function of the code: run a case again, compare
    again = run_case("near_grazing", pyrender=False)
    first = next(c for c in suite_without_pyrender["cases"] if c["name"] == "near_grazing")
    assert json.dumps(again, sort_keys=True) == json.dumps(first, sort_keys=True)
    assert set(suite_without_pyrender) == {
        "suite",
        "verdict",
        "pyrender",
        "oracle_gl",
        "reference",
        "bounds",
        "cases",
        "timing",
    }
    assert suite_without_pyrender["oracle_gl"] is None  # no GL drew anything


def test_bounds_are_not_vacuous(suite_without_pyrender):
    # A bound that is orders of magnitude above every measured error could not catch a
    # real loss of precision. Each case's worst point reaches >= 1/1000 of its bound
    # (measured: 0.002 .. 0.11 in float64, 0.01 .. 0.11 in float32).
    for c in suite_without_pyrender["cases"]:
        for dt in ("float64", "float32"):
            if c[dt] is not None:
                assert c[dt]["max_ratio"] >= 1e-3, (c["name"], dt, c[dt]["max_ratio"])


def test_suite_catches_a_strict_near_test(monkeypatch):
    # Planted fault: visibility z > near instead of z >= near. A point exactly at
    # the near plane must then fail the near_plane case.
    from wirecheck.core.projector import pipeline

    def strict(p_cam, camera):
        z = p_cam[:, 2]
        return (z > z.dtype.type(camera.near)) & (z <= z.dtype.type(camera.far))

    monkeypatch.setattr(pipeline, "depth_mask", strict)
    case = run_case("near_plane", pyrender=False)
    assert case["verdict"] == "fail"
    assert any("visibility differs" in r and "near," in r + "," for r in case["reasons"]), case["reasons"]


def test_suite_catches_a_tiny_pixel_offset(monkeypatch):
    # Planted fault: every float64 pixel 1e-9 px off. Invisible to a 1e-6 px
    # tolerance, but ~100x the derived float64 bound of the far-from-origin case.
    real = measure.render_frame

    def shifted(*args, **kwargs):
        frame = real(*args, **kwargs)
        if kwargs.get("dtype", "float64") == "float64":
            object.__setattr__(frame, "p_px", frame.p_px + 1e-9)
        return frame

    monkeypatch.setattr(measure, "render_frame", shifted)
    case = run_case("gimbal_lock", pyrender=False)
    assert case["verdict"] == "fail"
    assert any("float64: error" in r for r in case["reasons"]), case["reasons"]


def test_reference_is_independent_of_core_basis():
    # The long-double reference builds its own basis from forward and up: a camera
    # whose stored `right` were reversed would not move the reference.
    from types import SimpleNamespace

    from wirecheck.core.camera import look_at

    cam = look_at((3, 2, 4), (0, 0, 0), (0.3, 1.0, 0.1), fov_y_deg=55)
    liar = SimpleNamespace(
        **{
            k: getattr(cam, k)
            for k in (
                "position",
                "forward",
                "up",
                "fov_y_deg",
                "width",
                "height",
                "near",
                "far",
                "projection",
                "ortho_height",
            )
        },
        right=-cam.right,
    )
    pts = np.random.default_rng(3).uniform(-1, 1, (20, 3))
    a = extremes.reference_project(pts, cam)[1]
    b = extremes.reference_project(pts, liar)[1]
    assert np.array_equal(a, b)


def test_camera_rejects_a_fov_or_ortho_height_whose_scale_overflows():
    # fov 1e-320 deg is in (0, 180) but (H/2)/tan(fov/2) = inf; ortho-height 1e-320
    # gives H/ortho_height = inf. The camera must name the parameter, not a vertex.
    from wirecheck.core.camera import camera_z
    from wirecheck.core.errors import InputError

    with pytest.raises(InputError, match="camera fov 1e-320"):
        camera_z(4.0, fov_y_deg=1e-320)
    with pytest.raises(InputError, match="camera ortho-height 1e-320"):
        camera_z(4.0, projection="orthographic", ortho_height=1e-320)


def test_look_at_accepts_a_camera_1e_minus_200_from_its_target():
    # |forward| = 1e-200 underflows to 0 in np.linalg.norm (its square is 1e-400):
    # the points differ, so the camera is valid and looks along -Z.
    from wirecheck.core.camera import look_at

    cam = look_at((0.0, 0.0, 1e-200), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    assert cam.forward.tolist() == [0.0, 0.0, -1.0] and cam.right.tolist() == [1.0, 0.0, 0.0]
