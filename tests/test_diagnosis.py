"""oracles.diagnosis.diagnose: inject each fault into a copy of the projector, check the name.

Every faulty projector (tests/diagnosis_faults.py) is a small re-implementation of
``core.projector.projection.project_points`` with one bug (or two) put in on purpose. The
reference side is ``oracles.references.opencv_oracle.project`` when it imports, else
core's own projector. Each (fault, camera) pair must give EXACTLY the expected
set of fault names; the confusion matrix over all pairs is printed in the
terminal summary (via tests/conftest.py) and must be diagonal.
"""

from __future__ import annotations

import math
from collections import Counter

import numpy as np
import pytest
from diagnosis_faults import (  # the faulty projectors and their cameras
    CALIBRATED_CAMERAS,
    CALIBRATED_FAULTS,
    CAMERAS,
    CLIP_FAULTS,
    FAULTS,
    LENS_CAMERAS,
    LENS_PINCUSHION,
    PP_SHIFT,
    SINGLE,
    _lens_with,
    _project,
    _with,
    f_depth_flip,
    f_fov_offset,
    f_none,
    f_swap,
    implied_fov,
)
from wirecheck.core.camera import look_at
from wirecheck.core.projector.projection import project_points
from wirecheck.core.scene.files import load_scene
from wirecheck.core.transforms import Motion, apply
from wirecheck.oracles.diagnosis.clip_planes import probe_planes
from wirecheck.oracles.diagnosis.diagnose import diagnose, primary
from wirecheck.oracles.faults import NAMES as FAULT_ORDER
from wirecheck.oracles.faults import names as fault_names
from wirecheck.oracles.tolerances import vertex_bound, vertex_scale

try:
    from wirecheck.oracles.references.opencv_oracle import project as oracle_project

    ORACLE = "opencv"
except ImportError:  # pragma: no cover - fallback only
    oracle_project = project_points
    ORACLE = "core"

# ---- numeric error budget (the tolerances below are derived from this) -------
# Pixel noise delta: the faulty projectors (numpy) and the oracle (cv2) compute
# the same pixels in a different order, ~10 float64 operations on values up to
# ~640 px: delta <= 2.2e-16 x 640 x 10 ~ 1.5e-12 px (measured 1.1e-13; the
# "inside" camera, with points near its near plane at up to ~4e3 px, 1e-10).
# diagnose's per-axis fit cand = d q + b has the design [q / max|q|, 1], of
# condition number <= 2.3 for these cameras (measured), and every fitted axis
# reaches >= 100 px from the centre. So a fitted scale d is off by
# <= 2.3 x delta / 100 px ~ 3.5e-14 (relative), an offset b by
# <= 2.3 x delta ~ 3.5e-12 px; the affine fit (same conditioning) alike.
#
# TOL, the agreement tolerance handed to diagnose: it must sit far above that
# noise (1e-10 px at worst, "inside": 1e4 x margin) and far below the smallest
# injected effect (the 0.5 deg roll moves pixels by ~1.25 px, the half-pixel
# offset by 0.5 px, the fov factor 0.8 by tens of px: >= 5e5 x margin).
TOL = 1e-6
FRAMES = 12
SCENES = ("cube", "pyramid", "prism")


# ---- points -----------------------------------------------------------------


def pooled_points(motion: Motion = Motion(), frames: int = FRAMES) -> np.ndarray:
    """World points of all bundled scenes over all frames of a run, stacked."""
    out = []
    for name in SCENES:
        v = load_scene(name).vertices
        out += [apply(motion.frame_matrix(k, frames), v) for k in range(1, frames + 1)]
    return np.concatenate(out)


POINTS = pooled_points()
# For depth_flip with both sets non-empty: a camera inside a spread of points.
POINTS_AROUND = pooled_points(Motion(turns=(1.0, 2.0, 1.0), scale=2.0))


# (fault, camera) pairs. "inside" is for depth_flip only (both visible sets
# non-empty); "transposed" is invisible on the "axis" camera (its rotation
# diag(1, 1, -1) is its own transpose), tested separately below.
MAIN_CAMERAS = ("axis", "oblique", "tall", "wide", "ortho")
CASES = [
    (f, c)
    for f in FAULTS
    for c in MAIN_CAMERAS
    if not (f == "transposed" and c == "axis")
    and f not in CALIBRATED_FAULTS
    and f not in CLIP_FAULTS
    # the ortho camera's constants (scale 300/5 = 60, cx 199.5, cy 149.5) are exact in float32
    and not (f == "float32_k" and c == "ortho")
]
CASES += [("none", "inside"), ("depth_flip", "inside"), ("roll", "inside")]
CASES += [(f, "clip") for f in ("none", "depth_flip") + CLIP_FAULTS]
# calibrated cameras: the faults of a principal point, of fx/fy and of the lens, and
# the unexplained ones, which a lens profile must not absorb
CASES += [(f, c) for f in ("none", "pp_offset", "fov", "depth_flip", "roll", "transposed") for c in CALIBRATED_CAMERAS]
CASES += [(f, c) for f, cams in CALIBRATED_FAULTS.items() for c in cams]


def points_for(camera_name):
    return POINTS_AROUND if camera_name in ("inside", "clip") else POINTS


def float32_bound(pts, cam, ref) -> float:
    """The float32 vertex bound of these points (oracles.tolerances: derived from eps32 and the scene's scale)."""
    return vertex_bound("float32", vertex_scale(pts, ref, cam), TOL)


def run_case(fault, camera_name, dtype=np.float64):
    """Diagnose ``fault`` on a camera; float64: at TOL, with the float32 bound for precision_limited (as
    oracles.judge.verdict does for a float64 candidate); float32 (the twin): at the float32 bound."""
    cam = CAMERAS[camera_name]
    pts = points_for(camera_name)
    fn, _ = FAULTS[fault]
    ref = oracle_project(pts, cam)
    bound32 = float32_bound(pts, cam, ref)
    # the candidate's own planes, probed as oracles.judge.case does when the visible sets differ
    if dtype == np.float32:
        planes = probe_planes(lambda q, c: fn(q, c, np.float32), cam)
        return diagnose(fn(pts, cam, np.float32), ref, cam, tol_px=bound32, planes=planes)
    return diagnose(fn(pts, cam), ref, cam, tol_px=TOL, float32_px=bound32, planes=probe_planes(fn, cam))


@pytest.fixture(scope="module")
def results():
    return {(f, c): run_case(f, c) for f, c in CASES}


#: The float32 twins: every fault but float32_arith (float32 already), computed in float32.
CASES32 = [(f, c) for f, c in CASES if f not in ("float32_arith", "float32_k")]


@pytest.fixture(scope="module")
def results32():
    return {(f, c): run_case(f, c, np.float32) for f, c in CASES32}


# ---- the exact set of names per pair ---------------------------------------


@pytest.mark.parametrize("fault,camera_name", CASES)
def test_expected_names(results, fault, camera_name):
    got = results[(fault, camera_name)]
    names = [d["name"] for d in got]
    assert set(names) == FAULTS[fault][1], got
    assert len(names) == len(set(names))
    assert names == sorted(names, key=FAULT_ORDER.index)  # primary first


@pytest.mark.parametrize("fault,camera_name", CASES32)
def test_float32_twin_gets_the_same_names(results, results32, fault, camera_name):
    """The fault computed in float32 and judged at the float32 bound: the names of its float64 twin."""
    got = results32[(fault, camera_name)]
    assert [d["name"] for d in got] == [d["name"] for d in results[(fault, camera_name)]], got


@pytest.mark.parametrize("camera_name", MAIN_CAMERAS)
def test_float32_twin_offset_and_fov(results32, camera_name):
    cam = CAMERAS[camera_name]
    bound = float32_bound(POINTS, cam, oracle_project(POINTS, cam))
    (off,) = [d for d in results32[("fov_offset", camera_name)] if d["name"] == "pixel_offset"]
    # the fitted offset carries the float32 noise, at most the bound (a fit averages it down)
    assert abs(off["dx"] - 0.5) <= bound and abs(off["dy"] - 0.5) <= bound
    (fov,) = [d for d in results32[("fov", camera_name)] if d["name"] == "fov_mismatch"]
    # the scale d_y is off by <= bound / reach (>= 100 px) relative, ~1e-5; 1e-3 deg on ~50 deg is above that
    got = fov["implied_fov_deg"] if cam.projection == "perspective" else fov["implied_ortho_height"]
    assert got == pytest.approx(implied_fov(cam), rel=1e-4)


def test_a_small_float64_fault_is_not_precision_limited():
    """A genuine 1e-4 px offset (below the float32 bound, ~1e-3 px) in float64 arithmetic leaves no noise:
    it is a pixel_offset, not float32 rounding."""
    cam = CAMERAS["oblique"]
    ref = oracle_project(POINTS, cam)
    got = diagnose(f_none(POINTS, cam) + 1e-4, ref, cam, tol_px=TOL, float32_px=float32_bound(POINTS, cam, ref))
    assert [d["name"] for d in got] == ["pixel_offset"], got
    # pixels of <= ~640 px plus 1e-4 are exact to ~1e-13 px; the fitted offset alike (budget above)
    assert got[0]["dx"] == pytest.approx(1e-4, abs=1e-9)


def test_float32_arith_is_precision_limited_not_unexplained(results):
    for cam in MAIN_CAMERAS:
        (f,) = results[("float32_arith", cam)]
        assert f["name"] == "precision_limited"
        assert TOL < f["residual_px"] <= f["float32_bound_px"]


def test_inside_camera_sees_both_sides():
    cam = CAMERAS["inside"]
    vis = np.isfinite(oracle_project(POINTS_AROUND, cam)).all(axis=1)
    back = np.isfinite(f_depth_flip(POINTS_AROUND, cam)).all(axis=1)
    assert vis.sum() > 10 and back.sum() > 10 and not np.any(vis & back)


def test_transposed_rotation_invisible_on_axis():
    """diag(1, 1, -1) is its own transpose: no pixel changes, so nothing to name."""
    assert run_case("transposed", "axis") == []


# ---- the numbers -------------------------------------------------------------


@pytest.mark.parametrize("camera_name", MAIN_CAMERAS)
def test_implied_fov(results, camera_name):
    cam = CAMERAS[camera_name]
    for fault in ("fov", "fov_aspect", "fov_offset"):
        (fov,) = [d for d in results[(fault, camera_name)] if d["name"] == "fov_mismatch"]
        if cam.projection == "perspective":
            # implied_fov = 2 atan(t / d_y), t = tan(fov/2): |d fov / d ln d_y| =
            # 2 t d_y / (t^2 + d_y^2) <= 1 rad = 57.3 deg, times d_y's relative
            # error 3.5e-14 (budget above) ~ 2e-12 deg, plus a few ulp of the
            # ~50 deg angle from tan/atan (~1e-14). Measured 6e-14 deg; 1e-9 deg
            # leaves 500x margin over the bound (was 1e-6: loose by ~1e6).
            assert fov["implied_fov_deg"] == pytest.approx(implied_fov(cam), abs=1e-9)
            assert fov["implied_ortho_height"] is None
        else:
            assert fov["implied_fov_deg"] is None
            # ortho_height / d_y: relative error = d_y's, 3.5e-14, + 1 ulp of the
            # division (measured 2.2e-16); rel 1e-9 leaves a wide margin.
            assert fov["implied_ortho_height"] == pytest.approx(implied_fov(cam), rel=1e-9)


@pytest.mark.parametrize("camera_name", ("axis", "tall", "wide"))
def test_implied_fov_of_horizontal_fov(results, camera_name):
    """f from the width: the vertical FOV it amounts to is 2 atan((H/W) tan(fov/2))."""
    cam = CAMERAS[camera_name]
    (fov,) = results[("fov_horizontal", camera_name)]
    want = math.degrees(2 * math.atan(cam.height / cam.width * math.tan(math.radians(cam.fov_y_deg) / 2)))
    # Same error as in test_implied_fov: <= 57.3 deg x 3.5e-14 ~ 2e-12 deg, plus
    # a few ulp of want's own tan/atan (~1e-14). Measured 3e-14; 1e-9 deg leaves
    # 500x margin (was 1e-6: loose by ~1e6).
    assert fov["implied_fov_deg"] == pytest.approx(want, abs=1e-9)
    # direction: a wider image with f from the width -> longer focal -> narrower FOV
    assert (fov["implied_fov_deg"] < cam.fov_y_deg) == (cam.width > cam.height)
    # the scale is W/H exactly (to ~3.5e-14, above): the hint says which FOV was used
    assert "horizontal FOV (or the width)" in fov["hint"]


def test_scale_hints_only_for_their_ratios(results):
    """A 0.8 FOV factor is no W/H: the generic hint (the catalogue's, oracles.faults) stays."""
    (fov,) = results[("fov", "axis")]
    assert "hint" not in fov


@pytest.mark.parametrize("camera_name", ["axis", "tall"])
def test_pixel_count_minus_one_hint(camera_name):
    """x = (ndc + 1) (W - 1) / 2: x scaled by (W - 1) / W, y by (H - 1) / H (about the centre: no offset)."""
    cam = CAMERAS[camera_name]
    fx, fy = cam.focal_xy
    w, h = cam.width, cam.height
    got = diagnose(
        _project(POINTS, cam, fx=fx * (w - 1) / w, fy=fy * (h - 1) / h), oracle_project(POINTS, cam), cam, tol_px=TOL
    )
    faults = {f["name"]: f for f in got}
    assert set(faults) == {"aspect_mismatch", "fov_mismatch"}
    assert "pixel count minus one" in faults["aspect_mismatch"]["hint"]
    assert "pixel count minus one" in faults["fov_mismatch"]["hint"]


def test_float32_aspect_is_precision_limited():
    """A GL-style fx = (W / 2) / (a tan(fov / 2)) with a = float32(4 / 3) = 1.3333334: x scaled by
    1 - 3e-8, 1e-5 px at the image edge (> TOL), far below any aspect fault: precision_limited, not
    aspect_mismatch(implied_aspect=1.3333334)."""
    cam = CAMERAS["axis"]
    a32 = float(np.float32(cam.width / cam.height))
    fy = cam.focal_xy[1]
    ref = oracle_project(POINTS, cam)
    got = diagnose(
        _project(POINTS, cam, fx=fy * (cam.width / cam.height) / a32),
        ref,
        cam,
        tol_px=TOL,
        float32_px=float32_bound(POINTS, cam, ref),
    )
    assert [(f["name"], f.get("kind")) for f in got] == [("precision_limited", "float32_constants")], got
    # the fitted scale is (W/H) / a32 to ~3.5e-14 relative (budget above)
    assert got[0]["scale_x"] / got[0]["scale_y"] == pytest.approx((cam.width / cam.height) / a32, rel=1e-12)


def test_float32_principal_point_is_precision_limited():
    """A float64 projector whose principal point went through float32 (cx = 360.3 -> 360.29998779): the
    lines shift by -1.2e-5 px, above TOL and far below any convention's half pixel: precision_limited with
    that offset, not pixel_offset(dx=-1.2e-05). Judged without the float32 bound it stays pixel_offset."""
    cam = look_at((3, 2, 4), (0, 0, 0), (0.3, 1, 0.1), width=640, height=480, intrinsics=(520.0, 520.0, 360.3, 210.7))
    cx32, cy32 = float(np.float32(360.3)), float(np.float32(210.7))
    ref = oracle_project(POINTS, cam)
    cand = _project(POINTS, cam, cx=cx32, cy=cy32)
    got = diagnose(cand, ref, cam, tol_px=TOL, float32_px=float32_bound(POINTS, cam, ref))
    assert [(f["name"], f.get("kind")) for f in got] == [("precision_limited", "float32_constants")], got
    # the fitted offset is the rounding itself: pixels of ~600 px exact to ~1e-13 px (budget above)
    assert got[0]["dx"] == pytest.approx(cx32 - 360.3, abs=1e-11)
    assert got[0]["dy"] == pytest.approx(cy32 - 210.7, abs=1e-11)
    assert [f["name"] for f in diagnose(cand, ref, cam, tol_px=TOL)] == ["pixel_offset"]


@pytest.mark.parametrize("camera_name", MAIN_CAMERAS)
def test_implied_aspect(results, camera_name):
    for fault in ("aspect", "fov_aspect"):
        (asp,) = [d for d in results[(fault, camera_name)] if d["name"] == "aspect_mismatch"]
        # width-based fx = aspect 1. implied_aspect = (W/H) d_y / d_x: two fitted
        # scales, 3.5e-14 relative each, + 2 ulp of the products ~ 7e-14 on a
        # value of ~1 (measured 9e-16); abs 1e-9 leaves >1e4 x margin.
        assert asp["implied_aspect"] == pytest.approx(1.0, abs=1e-9)


@pytest.mark.parametrize("aspect", [1.0, 0.75, 4 / 3 * 1.1])
def test_implied_aspect_gl_style(aspect):
    """A GL-style candidate with its own aspect a: fx = (W/2) / (a tan(fov/2)) = f (W/H) / a."""
    cam = CAMERAS["oblique"]
    cand = _project(POINTS, cam, fx=cam.focal_px * (cam.width / cam.height) / aspect)
    (asp,) = diagnose(cand, oracle_project(POINTS, cam), cam, tol_px=TOL)
    assert asp["name"] == "aspect_mismatch"
    # As in test_implied_aspect: ~7e-14 relative (measured 4.4e-16); rel 1e-9.
    assert asp["implied_aspect"] == pytest.approx(aspect, rel=1e-9)


@pytest.mark.parametrize("camera_name", MAIN_CAMERAS)
def test_half_pixel_offset(results, camera_name):
    for fault in ("offset", "fov_offset"):
        (off,) = [d for d in results[(fault, camera_name)] if d["name"] == "pixel_offset"]
        # A fitted offset b is off by <= cond x delta = 2.3 x 1.5e-12 ~ 3.5e-12 px
        # (budget above; measured 1.9e-14). 1e-9 px leaves ~300x margin
        # (was 1e-6: loose by ~1e6, and as coarse as TOL itself).
        assert off["dx"] == pytest.approx(0.5, abs=1e-9)
        assert off["dy"] == pytest.approx(0.5, abs=1e-9)


@pytest.mark.parametrize("camera_name", ("oblique", "tall"))
def test_swap_with_offset(camera_name):
    """The raw swap's own shift (cx - cy) is expected; an extra half pixel is not."""
    cam = CAMERAS[camera_name]
    got = diagnose(f_swap(POINTS, cam) + [0.5, -0.25], oracle_project(POINTS, cam), cam, tol_px=TOL)
    assert [d["name"] for d in got] == ["axis_swap", "pixel_offset"]
    # As in test_half_pixel_offset: the fitted offset, minus the exactly
    # representable expected shift cx - cy, is off by <= ~3.5e-12 px (measured
    # 4.3e-14); 1e-9 px leaves ~300x margin (was 1e-6).
    assert (got[1]["dx"], got[1]["dy"]) == pytest.approx((0.5, -0.25), abs=1e-9)


@pytest.mark.parametrize("camera_name", MAIN_CAMERAS + CALIBRATED_CAMERAS)
def test_principal_point_offset(results, camera_name):
    (off,) = results[("pp_offset", camera_name)]
    # As in test_half_pixel_offset: <= ~3.5e-12 px from the fit; 1e-9 px.
    assert (off["dx"], off["dy"]) == pytest.approx(PP_SHIFT, abs=1e-9)


@pytest.mark.parametrize("camera_name", CALIBRATED_FAULTS["fxfy_swap"])
def test_fxfy_swap_scales(results, camera_name):
    """Swapped, x is scaled by fy / fx and y by fx / fy."""
    fx, fy = CAMERAS[camera_name].focal_xy
    asp, fov = results[("fxfy_swap", camera_name)]
    # fitted scales: 3.5e-14 relative (budget above; the lens cameras' fit has
    # the same conditioning, measured 1e-15); rel 1e-9.
    assert (asp["scale_x"], asp["scale_y"]) == pytest.approx((fy / fx, fx / fy), rel=1e-9)
    assert fov["scale"] == pytest.approx(fx / fy, rel=1e-9)


LENS_KINDS = {"lens_ignored": "ignored", "k1_sign": "k1_sign", "k2_wrong": "magnitude"}
LENS_OF = {
    "lens_ignored": lambda cam: (0.0, 0.0, 0.0, 0.0),
    "k1_sign": lambda cam: _lens_with(cam, 0, -1.0),
    "k2_wrong": lambda cam: _lens_with(cam, 1, 2.0),
}


@pytest.mark.parametrize("camera_name", LENS_CAMERAS)
@pytest.mark.parametrize("fault", list(LENS_KINDS))
def test_lens_fault_reads_the_candidates_lens(results, fault, camera_name):
    """kind, and the coefficients the candidate used (k1, k2, k3, p1, p2), read off the radial profile."""
    (got,) = results[(fault, camera_name)]
    assert got["kind"] == LENS_KINDS[fault]
    lens = tuple(LENS_OF[fault](CAMERAS[camera_name])) + (0.0,) * 5
    want = {"k1": lens[0], "k2": lens[1], "p1": lens[2], "p2": lens[3], "k3": lens[4]}
    # Pixel noise <= 1.5e-12 px (budget above) is <= 3.2e-15 in normalised units
    # (f >= 465 px). The profile's design, columns scaled to 1, has condition
    # number <= 92 (measured on both lenses) and its smallest column (r^7, k3)
    # reaches 0.0039: a coefficient is off by <= 92 x 3.2e-15 / 0.0039 ~ 7.5e-11
    # (measured <= 1.4e-13). 1e-9 leaves >10x over the bound.
    assert {k: got[k] for k in want} == pytest.approx(want, abs=1e-9)
    assert got["residual_px"] <= TOL


def test_lens_added_to_a_camera_without_one():
    cam = CAMERAS["k_offc"]
    (got,) = diagnose(_project(POINTS, cam, dist=LENS_PINCUSHION), oracle_project(POINTS, cam), cam, tol_px=TOL)
    assert (got["name"], got["kind"]) == ("distortion_mismatch", "added")
    assert got["k1"] == pytest.approx(LENS_PINCUSHION[0], abs=1e-9)  # bound as above


def test_unexplained_fields(results):
    (u,) = results[("roll", "oblique")]
    # A 0.5 deg roll moves points ~140 px from the centre by ~1.2 px (measured
    # residual 1.25 px) >> TOL; a roll about the optical axis with fx = fy is
    # exactly an image rotation, so its affine residual is only the pixel noise
    # (measured 1.1e-13 px) << TOL.
    assert u["residual_px"] > TOL
    assert u["affine_residual_px"] < TOL  # a roll is an image rotation...
    # ...of the roll angle (y down). rotation_deg = atan2(A10 - A01, A00 + A11):
    # entries of A off by <= 3.5e-14 (budget above), so the angle by ~1e-13 rad
    # = 6e-12 deg (measured 9e-15); 1e-9 deg leaves ~150x margin (was 1e-6).
    assert u["rotation_deg"] == pytest.approx(-0.5, abs=1e-9)
    (t,) = results[("transposed", "oblique")]
    # Not affine at all: measured residual 21.5 px, affine residual 1.8 px. The
    # 1 px threshold is not a noise bound: it only has to be >> TOL (1e6 x) to
    # show a 3D error that no image-plane map explains, with ~2x headroom.
    assert t["residual_px"] > 1.0 and t["affine_residual_px"] > 1.0


# ---- degenerate inputs -------------------------------------------------------


def test_degenerate_inputs():
    cam = CAMERAS["axis"]
    assert diagnose(np.zeros((0, 2)), np.zeros((0, 2)), cam) == []
    nan = np.full((5, 2), np.nan)
    assert diagnose(nan, nan, cam) == []
    one = np.array([[10.0, 20.0]])
    assert diagnose(one, one, cam) == []
    (off,) = diagnose(one + 0.5, one, cam)
    # exact equality: 10.5 - 10 and 20.5 - 20 are exact in float64, and the
    # mean of one value is that value.
    assert off["name"] == "pixel_offset" and (off["dx"], off["dy"]) == (0.5, 0.5)
    # two points, mirrored: cannot be fitted -> unexplained, underdetermined
    two = np.array([[10.0, 20.0], [30.0, 50.0]])
    (u,) = diagnose(two * [-1, 1] + [cam.width - 1, 0], two, cam)
    assert u["name"] == "unexplained" and u["underdetermined"]
    # collinear points with an offset: the offset is still found
    line = np.column_stack([np.linspace(0, 600, 7), np.full(7, 100.0)])
    assert [d["name"] for d in diagnose(line + [0.5, 0.5], line, cam)] == ["pixel_offset"]
    # the candidate clips everything the oracle shows: the flip of a scene in front
    pts = oracle_project(POINTS, cam)
    assert primary(diagnose(np.full_like(pts, np.nan), pts, cam)) == "depth_flip"
    with pytest.raises(ValueError):
        diagnose(np.zeros((3, 2)), np.zeros((4, 2)), cam)


def test_visibility_mismatch_without_flip():
    """A wrong far plane changes a few points only: unexplained, with the count."""
    cam = _with(CAMERAS["oblique"], far=5.4)
    cand = project_points(POINTS, _with(cam, far=5.6))
    got = diagnose(cand, oracle_project(POINTS, cam), cam, tol_px=TOL)
    assert [d["name"] for d in got] == ["unexplained"]
    # same camera apart from far: the common points' pixels agree to the pixel
    # noise (~1e-13 px) <= TOL.
    assert got[0]["visibility_mismatches"] > 0 and got[0]["residual_px"] <= TOL


def test_below_tolerance_is_agreement():
    cam = CAMERAS["oblique"]
    ref = oracle_project(POINTS, cam)
    # 1e-7 and 1e-5 px bracket TOL = 1e-6 by 10x either way; adding them to
    # pixels of <= ~640 px is exact to ~1e-13 px, far inside that bracket.
    assert diagnose(ref + 1e-7, ref, cam, tol_px=TOL) == []
    assert primary(diagnose(ref + 1e-5, ref, cam, tol_px=TOL)) == "pixel_offset"


def test_large_pooled_input_is_fast():
    cam = CAMERAS["wide"]
    rng = np.random.default_rng(0)
    pts = rng.uniform(-2, 2, size=(100_000, 3))
    got = diagnose(f_fov_offset(pts, cam), oracle_project(pts, cam), cam, tol_px=TOL)
    assert {d["name"] for d in got} == {"fov_mismatch", "pixel_offset"}


# ---- confusion matrix --------------------------------------------------------


def confusion(results):
    """rows: injected single fault (by its expected primary name); columns: diagnosed primary."""
    # the vertex faults: the line faults come from the pixels (tests/test_line_gate.py)
    # a projector's names: those read from any source or the vertices (not the lines', a renderer's images'
    # (ambiguous), a depth map's or an unprojector's)
    labels = ["none"] + [n for n in FAULT_ORDER if n in fault_names(source="any") + fault_names(source="vertices")]
    counts = Counter()
    for (fault, cam), got in results.items():
        if fault not in SINGLE:
            continue
        want = FAULTS[fault][1]
        row = "none" if not want else min(want, key=FAULT_ORDER.index)
        counts[(row, primary(got))] += 1
    rows = [r for r in labels if any(counts[(r, c)] for c in labels)]
    return labels, rows, counts


def format_confusion(labels, rows, counts):
    short = {
        n: n.replace("mirror_horizontal", "mirr_h")
        .replace("mirror_vertical", "mirr_v")
        .replace("_mismatch", "")
        .replace("pixel_", "")
        .replace("unexplained", "unexpl")
        for n in labels
    }
    width = max(len(r) for r in rows) + 1
    lines = [
        f"confusion matrix (oracle: {ORACLE}; rows injected, columns diagnosed primary)",
        " " * width + " ".join(f"{short[c]:>8}" for c in labels),
    ]
    for r in rows:
        lines.append(f"{r:<{width}}" + " ".join(f"{counts[(r, c)] or '.':>8}" for c in labels))
    return "\n".join(lines)


def test_confusion_matrix_is_diagonal(results, summary_section):
    labels, rows, counts = confusion(results)
    # shown in the terminal summary of every run (tests/conftest.py), pass or fail
    summary_section("diagnosis confusion matrix", format_confusion(labels, rows, counts))
    off = {k: v for k, v in counts.items() if k[0] != k[1] and v}
    assert not off, off
    assert set(rows) == set(labels)  # every fault name was injected


def test_float32_confusion_matrix_is_diagonal(results32, summary_section):
    labels, rows, counts = confusion(results32)
    summary_section(
        "diagnosis confusion matrix, float32 twins (judged at the float32 bound)",
        format_confusion(labels, rows, counts),
    )
    off = {k: v for k, v in counts.items() if k[0] != k[1] and v}
    assert not off, off
    assert set(rows) == set(labels) - {"precision_limited"}  # every fault but the float64-only one
