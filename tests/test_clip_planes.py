"""oracles.diagnosis.clip_planes and the clipping_plane fault: exact candidates that clip at the wrong place.

Each candidate below is exact (float64 pinhole, the camera's own K) wherever it draws, and differs only
in its depth test; the expected planes are the values written into its test, never the probe's.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
import wirecheck
from wirecheck.core.camera import look_at
from wirecheck.core.scene.files import load_scene
from wirecheck.core.scene.model import Scene
from wirecheck.oracles.diagnosis import clip_planes
from wirecheck.oracles.diagnosis.clip_planes import clip_fault, depth_slack, probe_planes
from wirecheck.oracles.diagnosis.diagnose import diagnose
from wirecheck.oracles.faults import hint_text
from wirecheck.oracles.references.opencv_oracle import project as oracle_project
from wirecheck.oracles.reports.fault_text import hints as fault_hints

sys.path.insert(0, str(Path(__file__).parent / "data"))
import gl_float32_matrix  # noqa: E402

# Points of the cube spun about y: seen from z = 5 they lie at depths 5 -+ 1.73, so near = 4.5 and
# far = 6 each cut some of them off.
CAM = look_at((0, 0, 5), (0, 0, 0), (0, 1, 0), fov_y_deg=60, width=640, height=480, near=4.5, far=6.0)
_ANGLES = np.linspace(0.0, 2 * np.pi, 12, endpoint=False)
_CUBE = load_scene("cube").vertices
POINTS = np.concatenate(
    [_CUBE @ np.array([[np.cos(a), 0, np.sin(a)], [0, 1, 0], [-np.sin(a), 0, np.cos(a)]]).T for a in _ANGLES]
)
# The fitted planes are bracketed to ~1e-11 relative (6 refining calls of 63x on a ~16 % grid step,
# clip_planes); the tests' 1e-6 relative (the brief's) is far above that and far below any plane error.
REL = 1e-6


def pinhole(points, camera, test):
    """Exact float64 pixels, NaN where ``test(z)`` is False (z: depth along forward)."""
    r = np.stack([camera.right, camera.up, camera.forward])
    p_cam = (np.asarray(points, float) - camera.position) @ r.T
    z = p_cam[:, 2]
    cx, cy = camera.principal_point
    fx, fy = camera.focal_xy
    with np.errstate(divide="ignore", invalid="ignore"):
        out = np.stack([cx + fx * p_cam[:, 0] / z, cy - fy * p_cam[:, 1] / z], axis=1)
    out[~test(z, camera)] = np.nan
    return out


F32_NEAR = float(np.nextafter(np.float32(CAM.near), np.float32(np.inf)))  # rounded up: clips inside near

CANDIDATES = {
    "correct": (lambda z, c: (z >= c.near) & (z <= c.far), None),
    "z_positive": (lambda z, c: (z > 0) & (z <= c.far), "z_positive"),  # the slides' tan typo copy
    "float32_near": (lambda z, c: (z >= F32_NEAR) & (z <= c.far), "float32_near"),
    "none": (lambda z, c: np.ones(len(z), bool), "none"),  # never returns NaN
    "swapped": (lambda z, c: (z >= c.far) & (z <= c.near), "swapped"),  # near and far exchanged
    "near_doubled": (lambda z, c: (z >= 4.75) & (z <= c.far), "near"),
    "far_short": (lambda z, c: (z >= c.near) & (z <= 5.5), "far"),
}
EXPECTED_FIT = {
    "z_positive": (0.0, CAM.far),
    "float32_near": (F32_NEAR, CAM.far),
    "near_doubled": (4.75, CAM.far),
    "far_short": (CAM.near, 5.5),
    "correct": (CAM.near, CAM.far),
}


def _candidate(name):
    test, _ = CANDIDATES[name]
    return lambda points, camera: pinhole(points, camera, test)


def _points_with_gap(name):
    """POINTS, plus points on the axis at depths inside [near, far] that a float32 near drops (its gap
    is 1 float32 ulp of 4.5, 4.8e-7)."""
    gap = np.linspace(CAM.near, F32_NEAR, 5)[1:-1]
    return np.concatenate([POINTS, CAM.position + gap[:, None] * np.asarray(CAM.forward)])


@pytest.mark.parametrize("name", sorted(EXPECTED_FIT))
def test_probe_fits_the_candidates_planes(name):
    planes = probe_planes(_candidate(name), CAM)
    want_near, want_far = EXPECTED_FIT[name]
    assert planes["near_fit"] == pytest.approx(want_near, rel=REL, abs=1e-9 * CAM.near)
    assert planes["far_fit"] == pytest.approx(want_far, rel=REL)


@pytest.mark.parametrize("name", sorted(CANDIDATES))
def test_diagnose_names_the_clipping_plane(name):
    func = _candidate(name)
    pts = _points_with_gap(name)
    ref = oracle_project(pts, CAM)
    got = diagnose(func(pts, CAM), ref, CAM, tol_px=1e-6, float32_px=1e-3, planes=probe_planes(func, CAM))
    kind = CANDIDATES[name][1]
    if kind is None:
        assert got == []
        return
    # exact wherever it draws: the only fault is where it clips, never unexplained or a depth flip
    assert [(f["name"], f["kind"]) for f in got] == [("clipping_plane", kind)], got
    if name in EXPECTED_FIT:
        assert got[0]["near_fit"] == pytest.approx(EXPECTED_FIT[name][0], rel=REL, abs=1e-9 * CAM.near)
    hints = dict(fault_hints(got))
    # the kind's own hint (the catalogue's hints of clipping_plane, oracles.faults), naming the plane at fault; never the rotation advice
    plane = "far" if kind == "far" else "near"
    assert plane in hints["clipping_plane"] and "rotation" not in hints["clipping_plane"]


def test_visibility_only_unexplained_advises_visibility_not_rotation():
    """Without the probe, an exact candidate clipping at z > 0 is unexplained, but its hint names the sets."""
    func = _candidate("z_positive")
    ref = oracle_project(POINTS, CAM)
    cand = func(POINTS, CAM)
    (u,) = diagnose(cand, ref, CAM, tol_px=1e-6)
    only_cand = int((np.isfinite(cand).all(axis=1) & ~np.isfinite(ref).all(axis=1)).sum())
    assert u["name"] == "unexplained" and u["residual_px"] <= 1e-6 and u["candidate_only"] == only_cand > 0
    assert f"{only_cand} points shown only by the candidate" in u["hint"]
    assert "rotation" not in u["hint"].replace("not the rotation", "")


# A far plane that float32 cannot hold: 6.1 rounds down to 6.0999999046 (1.6e-8 relative, within the
# float32 limit of clip_planes, 4 eps32 (1 + far / near) = 1.1e-6, and far above PLANE_REL_TOL's 1e-9)
CAM_F32_FAR = look_at((0, 0, 5), (0, 0, 0), (0, 1, 0), fov_y_deg=60, width=640, height=480, near=4.5, far=6.1)
F32_FAR = float(np.float32(CAM_F32_FAR.far))


def test_a_float32_far_plane_is_named_float32_far():
    """An exact projector whose far test went through float32 (``z <= float32(far)``): it drops the points
    between float32(far) and far that the oracle keeps, and nothing else."""
    assert F32_FAR < CAM_F32_FAR.far
    func = lambda points, camera: pinhole(points, camera, lambda z, c: (z >= c.near) & (z <= np.float32(c.far)))
    gap = np.linspace(F32_FAR, CAM_F32_FAR.far, 5)[1:-1]  # kept by the oracle, dropped here
    pts = np.concatenate([POINTS, CAM_F32_FAR.position + gap[:, None] * np.asarray(CAM_F32_FAR.forward)])
    ref = oracle_project(pts, CAM_F32_FAR)
    cand = func(pts, CAM_F32_FAR)
    assert int((np.isfinite(ref).all(axis=1) & ~np.isfinite(cand).all(axis=1)).sum()) == len(gap)
    planes = probe_planes(func, CAM_F32_FAR)
    got = diagnose(cand, ref, CAM_F32_FAR, tol_px=1e-6, float32_px=1e-3, planes=planes)
    assert [(f["name"], f["kind"]) for f in got] == [("clipping_plane", "float32_far")], got
    (f,) = got
    # near is the camera's; far is float32(far): the probe brackets a plane to ~3e-12 relative (0.16 / 63^6),
    # so 1e-10 tells F32_FAR from far (1.6e-8 apart), which REL (1e-6) could not
    assert f["near_fit"] == pytest.approx(CAM_F32_FAR.near, rel=REL)
    assert f["far_fit"] == pytest.approx(F32_FAR, rel=1e-10) and f["far_fit"] != pytest.approx(
        CAM_F32_FAR.far, rel=1e-9
    )
    assert (f["near"], f["far"]) == (CAM_F32_FAR.near, CAM_F32_FAR.far)
    hint = dict(fault_hints(got))["clipping_plane"]
    assert hint == hint_text("clipping_plane", "float32_far") and "far plane went through float32" in hint


@pytest.mark.parametrize("name,kind", [("z_positive", "z_positive"), ("none", "none")])
def test_a_run_names_the_clipping_plane(name, kind):
    """Through check_projector (the probe run by the judge, oracles.judge.case): the near_plane case, whose near
    plane cuts the cube, fails as clipping_plane of its kind with its hint (was unexplained(residual_px=3e-13)
    with the rotation advice); on_axis, where nothing is clipped, passes."""
    report = wirecheck.check_projector(
        _candidate(name), scenes=["cube"], cases=["near_plane", "on_axis"], frames=4, isolate=False
    )
    by = {c["camera"]: c for c in report["cases"]}
    assert by["on_axis"]["verdict"] == "pass" and by["on_axis"]["faults"] == []
    case = by["near_plane"]
    assert case["verdict"] == "fail"
    assert [(f["name"], f["kind"]) for f in case["faults"]] == [("clipping_plane", kind)], case["faults"]
    # z > 0 keeps points at 1e-9 near, the probe's nearest depth: near_fit 0.0; never clipping: no plane
    assert case["faults"][0]["near_fit"] == (0.0 if kind == "z_positive" else None)
    assert dict(fault_hints(case["faults"]))["clipping_plane"] == hint_text("clipping_plane", kind)


def test_a_broken_probe_is_no_fault():
    def crashes_on_axis(points, camera):
        raise ZeroDivisionError("boom")

    assert probe_planes(crashes_on_axis, CAM) is None
    assert clip_fault(None, CAM) is None and depth_slack(None, CAM) == (0.0, None)


# ---- clipped ends for a float32-rounded GL matrix (PyGLM) ----------------------


def _cube(scale):
    s = load_scene("cube")
    return Scene(name=f"cube_x{scale}", vertices=s.vertices * scale, edges=s.edges, faces=s.faces)


@pytest.mark.slow  # crosscheck runs
def test_float32_matrix_projector_keeps_its_clipped_ends():
    """PyGLM's float32 perspective in a float64 projector: on the cube scaled 0.9 its near plane is
    near (1 + 8.6e-8) (float32 rounding of A, B in -w <= A z + B), and edges cross near in near_plane.
    The ends are placed past that plane, so it passes; with the float64 nudge alone (1e-9 of a segment)
    it loses whole edges (measured: F1@1px 0.72, line_pixel_bias(oracle_only=3888))."""
    report = wirecheck.check_projector(
        gl_float32_matrix.project,
        scenes=[_cube(0.9)],
        cases=["near_plane"],
        frames=8,
        isolate=False,
        oracles=("opencv", "pyrender"),
    )
    (case,) = report["cases"]
    assert case["verdict"] == "pass", case["reasons"]
    assert "line_pixel_bias" not in {f["name"] for f in case["faults"]}
    planes = probe_planes(gl_float32_matrix.project, wirecheck.oracles.cases.cases_for(_cube(0.9))[2].camera)
    assert case["clipped_ends"]["inward_depth"] > 0 and "float32 rounding" in case["clipped_ends"]["reason"]
    assert planes["near_fit"] > case["camera_spec"]["near"]
    # said in report.md's Notes
    from wirecheck.oracles.reports.report import case_notes

    assert any("clipped ends moved" in text for _c, text in case_notes(report))


@pytest.mark.slow  # crosscheck runs
def test_float32_matrix_slack_is_what_keeps_the_ends(monkeypatch):
    """The control: the same run with the slack taken away fails on line pixels."""
    monkeypatch.setattr(clip_planes, "depth_slack", lambda planes, camera: (0.0, None))
    report = wirecheck.check_projector(
        gl_float32_matrix.project,
        scenes=[_cube(0.9)],
        cases=["near_plane"],
        frames=8,
        isolate=False,
        oracles=("opencv", "pyrender"),
    )
    assert report["cases"][0]["verdict"] == "fail"


@pytest.mark.slow  # crosscheck runs
def test_float32_matrix_constants_are_precision_limited():
    """The same projector on on_axis (fov 60: 1/tan(30 deg) and 1/(aspect tan) rounded to float32, scales
    1 - 4e-8 and 1 - 2e-8): its vertices are exact to ~1e-13 px for that map, so the fit names the map,
    and the map is float32 rounding of its constants: precision_limited, never fov_mismatch(scale=0.99999998)
    or aspect_mismatch(implied_aspect=1.3333334)."""
    report = wirecheck.check_projector(
        gl_float32_matrix.project, scenes=["cube"], cases=["on_axis"], frames=3, isolate=False
    )
    (case,) = report["cases"]
    assert [(f["name"], f.get("kind")) for f in case["faults"]] == [("precision_limited", "float32_constants")]
    eps32 = 2.0**-23
    f = case["faults"][0]
    assert 0 < abs(f["scale_y"] - 1) <= eps32 and 0 < abs(f["scale_x"] - 1) <= 2 * eps32
    # the float64 control passes
    assert (
        wirecheck.check_projector(
            gl_float32_matrix.project_exact, scenes=["cube"], cases=["on_axis"], frames=3, isolate=False
        )["verdict"]
        == "pass"
    )
