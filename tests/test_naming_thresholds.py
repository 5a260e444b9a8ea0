"""Each naming threshold of oracles.tolerances.NamingThresholds that was a module constant of the diagnosis
(image_diagnose, image_visibility, rule_read, diagnose, clip_planes, unproject_faults, depth_pixels,
silhouette_faults) or of the line measures (even_lean, line_ends, coverage_pixels, line_profile) decides a
name or which limits hold: on a hand-made input the name flips when the threshold is moved across the value
measured on that input, both sides asserted.

The record is moved with dataclasses.replace and put where the diagnosis reads it (each module's ``NAMING``,
read at call time). The measured values are computed here by hand (numpy on the hand-made points) or read
from the diagnosis' own output on the unmoved record (silhouette_polish_below's: with polishing off), and
each moved threshold is placed on either side.
The verdict thresholds of Tolerances have theirs beside their fields' other tests
(tests/test_decide_steps.py: ``oracle_limit_px``; tests/test_line_rule.py: offset, scale, rule offset, ends).
"""

from __future__ import annotations

import dataclasses
import math
import sys

import numpy as np
import pytest
from wirecheck.core.camera import look_at
from wirecheck.core.projector.raster import line_pixels
from wirecheck.oracles.diagnosis import rule_read
from wirecheck.oracles.diagnosis.clip_planes import clip_fault
from wirecheck.oracles.diagnosis.depth_faults import name_depth_faults
from wirecheck.oracles.diagnosis.depth_pixels import UNDECIDED_FACE
from wirecheck.oracles.diagnosis.diagnose import diagnose, diagnose_lines, rounded_constants, scale_faults
from wirecheck.oracles.diagnosis.image_diagnose import diagnose_images
from wirecheck.oracles.diagnosis.image_visibility import set_difference
from wirecheck.oracles.diagnosis.silhouette_faults import SilhouetteFrame, name_silhouette_faults
from wirecheck.oracles.diagnosis.unproject_faults import name_unproject_faults
from wirecheck.oracles.judge import coverage_pixels, even_lean
from wirecheck.oracles.judge.free_ends import measure_ends
from wirecheck.oracles.judge.line_ends import end_attribution
from wirecheck.oracles.judge.line_profile import pooled_offset
from wirecheck.oracles.judge.line_style import fit_lines, measure
from wirecheck.oracles.references.fill_rule import silhouette
from wirecheck.oracles.references.unproject_reference import unproject
from wirecheck.oracles.tolerances import EPS, NAMING, NamingThresholds, Tolerances

UP, DOWN = math.inf, -math.inf
TOL = Tolerances()


@pytest.fixture
def naming(monkeypatch):
    """``naming(**fields)``: NAMING with ``fields`` moved, in every wirecheck module that reads it."""

    def move(**fields):
        moved = dataclasses.replace(NAMING, **fields)
        for name, module in list(sys.modules.items()):
            if name.startswith("wirecheck.oracles") and isinstance(getattr(module, "NAMING", None), NamingThresholds):
                monkeypatch.setattr(module, "NAMING", moved)
        return moved

    return move


def _names(faults):
    return [f["name"] for f in faults]


# ---------------------------------------------------------------- the vertex diagnosis (diagnose)


def _grid(n=200):
    """``n`` points spread in 2D about a 640 x 480 camera's principal point (px)."""
    i = np.arange(n, dtype=np.float64)
    return np.stack([320.0 + 7.0 * (i % 20) - 66.5, 240.0 + 9.0 * (i // 20) - 40.5], axis=1)


CAM = look_at((0, 0, 5), (0, 0, 0), (0, 1, 0), fov_y_deg=60, width=640, height=480)


def test_depth_flip_max_overlap(naming):
    # 200 points seen: the oracle sees 0-100, the candidate 98-199, both 98 and 99 (where the pixels agree):
    # 2 in common out of a union of 200, an overlap of exactly 0.01 = the default bound (<=: a depth flip)
    p = _grid()
    orac, cand = p.copy(), p.copy()
    orac[100:] = np.nan
    cand[:98] = np.nan
    assert _names(diagnose(cand, orac, CAM)) == ["depth_flip"]
    naming(depth_flip_max_overlap=math.nextafter(0.01, DOWN))
    assert "depth_flip" not in _names(diagnose(cand, orac, CAM))


def test_degenerate_ratio(naming):
    # points nearly on a line (three rows 0.1 px apart), seen scaled by 1.1 about the principal point: a
    # fov_mismatch while the spread's smaller singular value is above degenerate_ratio of the larger,
    # else only an offset is tried (it explains nothing here): unexplained, underdetermined
    x = np.linspace(-100.0, 100.0, 21)
    o = np.stack([np.tile(x, 3), np.repeat([-0.1, 0.0, 0.1], 21)], axis=1)
    sv = np.linalg.svd(o - o.mean(axis=0), compute_uv=False)
    ratio = sv[-1] / sv[0]  # ~1.4e-3, far above the default 1e-6
    centre = np.array(CAM.principal_point)
    orac, cand = centre + o, centre + 1.1 * o
    assert "fov_mismatch" in _names(diagnose(cand, orac, CAM))
    naming(degenerate_ratio=ratio / 2)
    assert "fov_mismatch" in _names(diagnose(cand, orac, CAM))
    naming(degenerate_ratio=ratio * 2)
    (f,) = diagnose(cand, orac, CAM)
    assert f["name"] == "unexplained" and f["underdetermined"] is True


def test_constant_roundings(naming):
    # a fitted offset of 5e-5 px on a 640 x 480 image: within constant_roundings eps32 x the farthest pixel
    # from the principal point it is a float32 constant's rounding (precision_limited), beyond it an offset
    cx, cy = CAM.principal_point
    reach = max(cx, cy, CAM.width - 1 - cx, CAM.height - 1 - cy)
    roundings = 5e-5 / (EPS["float32"] * reach)  # the offset in roundings: ~1.31, under the default 2
    faults = [{"name": "pixel_offset", "dx": 5e-5, "dy": 0.0}]
    info = {"scale": np.ones(2), "residual_px": 0.0}
    assert _names(rounded_constants(faults, CAM, info, 1e-6, 1e-3)) == ["precision_limited"]
    naming(constant_roundings=roundings * 1.001)
    assert _names(rounded_constants(faults, CAM, info, 1e-6, 1e-3)) == ["precision_limited"]
    naming(constant_roundings=roundings * 0.999)
    assert rounded_constants(faults, CAM, info, 1e-6, 1e-3) == faults


def test_line_end_min_px(naming):
    # 100 lines, 30 oracle-only pixels at their last ends and none elsewhere: 0.3 a line, at least
    # line_end_min_px (0.25) and all of the imbalance: line_end_bias; past 0.3, line_pixel_bias
    lines = {
        "imbalance_fraction": -0.01,
        "balance_p_value": 1e-9,
        "subpixel_ties": [0, 0],
        "candidate_only": 0,
        "oracle_only": 30,
        "edge_count_max_diff": 0,
        "edge_count_worst": None,
        "imbalance": -30,
        "lines_compared": 100,
        "one_sided_by_place": {"start": [0, 0], "end": [0, 30], "middle": [0, 0], "stray": [0, 0]},
    }
    (f,) = diagnose_lines(lines, TOL)
    assert f["name"] == "line_end_bias" and f["end"] == "last" and f["pixels_per_line"] == -0.3
    naming(line_end_min_px=0.3)
    assert _names(diagnose_lines(lines, TOL)) == ["line_end_bias"]
    naming(line_end_min_px=math.nextafter(0.3, UP))
    assert _names(diagnose_lines(lines, TOL)) == ["line_pixel_bias"]


# ---------------------------------------------------------------- the rules read (rule_read)


def test_rule_tie(naming, monkeypatch):
    # GL's model fits at cost 0.300, the rounded ends' at 0.390: 30 % apart, within rule_tie (1/3) both
    # rules are read; with the margin under 30 %, GL's alone
    snapped_bias, gl_bias = np.array([0.2, -0.1]), np.array([0.01, 0.02])
    monkeypatch.setattr(rule_read, "_costs", lambda *args: (snapped_bias, 0.300, 0.390))

    def read():
        return list(rule_read.read_rules(None, None, CAM, np.eye(2), np.ones(2), np.zeros(2), gl_bias))

    assert read() == ["gl", "snapped"]
    naming(rule_tie=0.31)
    assert read() == ["gl", "snapped"]
    naming(rule_tie=0.29)
    assert read() == ["gl"]


def test_rounded_end_px(naming):
    # a scale of 1.008 over 100 px moves the farthest pixel 0.8 px: a fov_mismatch at scale_px 0.5 under GL's
    # rule; under the rounded ends' it must also beat scale_px + rounded_end_px (default 1.0: it does not)
    d, reach = np.array([1.008, 1.008]), np.array([100.0, 100.0])
    effect = (1.008 - 1.0) * 100.0  # 0.8 px
    faults = scale_faults(1.008, 1.008, reach, TOL.scale_px, CAM)
    assert _names(faults) == ["fov_mismatch"]
    rules = {"gl": np.zeros(2), "snapped": np.zeros(2)}
    assert rule_read.standing_scale_faults(faults, d, reach, TOL.scale_px, CAM, rules) == []
    assert rule_read.standing_scale_faults(faults, d, reach, TOL.scale_px, CAM, {"gl": np.zeros(2)}) == faults
    naming(rounded_end_px=effect - TOL.scale_px - 0.01)
    assert rule_read.standing_scale_faults(faults, d, reach, TOL.scale_px, CAM, rules) == faults
    naming(rounded_end_px=effect - TOL.scale_px + 0.01)
    assert rule_read.standing_scale_faults(faults, d, reach, TOL.scale_px, CAM, rules) == []


# ---------------------------------------------------------------- the image diagnosis (image_diagnose)

SMALL = look_at((0, 0, 5), (0, 0, 0), (0, 1, 0), fov_y_deg=60, width=200, height=150)
#: An L-shaped outline and a stroke off the principal point (px from it): no mirror or swap of it fits.
SHAPE = np.array(
    [
        [[-60.3, -40.2], [30.6, -40.2]],
        [[30.6, -40.2], [30.6, -5.7]],
        [[30.6, -5.7], [-20.1, -5.7]],
        [[-20.1, -5.7], [-20.1, 50.4]],
        [[-20.1, 50.4], [-60.3, 50.4]],
        [[-60.3, 50.4], [-60.3, -40.2]],
        [[45.2, 10.3], [80.7, 55.9]],
    ]
)


def _segs(transform=np.eye(2)):
    return SHAPE @ np.asarray(transform).T + np.array(SMALL.principal_point)


def _draw(segs):
    img = np.zeros((SMALL.height, SMALL.width), bool)
    rr, cc = line_pixels(segs[:, 0], segs[:, 1], SMALL.width, SMALL.height)
    img[rr, cc] = True
    return img


ORACLE = [_segs()] * 2


def test_min_registered_px(naming):
    # a correct drawing of the shape: named nothing once it has min_registered_px drawn pixels
    cand = [_draw(s) for s in ORACLE]
    drawn = int(sum(np.count_nonzero(i) for i in cand))
    assert drawn > NAMING.min_registered_px
    naming(min_registered_px=drawn)
    assert diagnose_images(cand, ORACLE, SMALL) == []
    naming(min_registered_px=drawn + 1)
    (f,) = diagnose_images(cand, ORACLE, SMALL)
    assert f["name"] == "unexplained" and f["underdetermined"] is True


def test_residual_max_px(naming):
    # the same correct drawing sits 0.30-0.33 px from its lines (docs/frames.md: 1-px aliased lines): a fit
    # below residual_max_px (0.85) names nothing; with the bound at 0.2, under that cost, nothing fits
    cand = [_draw(s) for s in ORACLE]
    assert diagnose_images(cand, ORACLE, SMALL) == []
    naming(residual_max_px=0.2)
    (f,) = diagnose_images(cand, ORACLE, SMALL)
    assert f["name"] == "unexplained" and 0.2 < f["residual_px"] <= NAMING.residual_max_px


def test_rotation_px(naming):
    # the shape rolled 0.5 degrees about the principal point: the free affine fit's off-diagonal terms
    # move a pixel by 0.77-1.17 px (docs/frames.md), over rotation_px (0.3): unexplained with its rotation;
    # with the bound above what it measures here, the roll is not named unexplained
    r = math.radians(0.5)
    roll = [[math.cos(r), -math.sin(r)], [math.sin(r), math.cos(r)]]
    cand = [_draw(_segs(roll))] * 2
    (f,) = diagnose_images(cand, ORACLE, SMALL)
    assert f["name"] == "unexplained" and NAMING.rotation_px < f["off_diagonal_px"], f
    naming(rotation_px=f["off_diagonal_px"])
    assert "unexplained" not in _names(diagnose_images(cand, ORACLE, SMALL))


def test_ambiguous_ratio(naming):
    # the shape mirrored left-right: the mirror fits it far better than the identity (relative cost
    # difference measured here: several times over); named mirror_horizontal while the identity's cost
    # exceeds the mirror's by more than ambiguous_ratio, else the identity is kept (and fits nothing)
    cand = [_draw(_segs([[-1.0, 0.0], [0.0, 1.0]]))] * 2
    assert _names(diagnose_images(cand, ORACLE, SMALL)) == ["mirror_horizontal"]
    naming(ambiguous_ratio=1e3)
    assert "mirror_horizontal" not in _names(diagnose_images(cand, ORACLE, SMALL))


# ---------------------------------------------------------------- the drawn sets (image_visibility)


def test_near_px(naming):
    # the oracle's one horizontal line drawn as is, plus one pixel 2 rows below it: a pixel on the candidate's
    # side only while near_px is under its 2 px; at 2 px it has a partner within reach
    segs = np.array([[[20.0, 50.0], [150.0, 50.0]]])
    img = _draw(segs)
    img[52, 80] = True
    cand_only, oracle_only = set_difference([img], [segs], SMALL)
    assert cand_only > 0 and oracle_only == 0
    naming(near_px=math.nextafter(2.0, DOWN))
    assert set_difference([img], [segs], SMALL)[0] > 0
    naming(near_px=2.0)
    assert set_difference([img], [segs], SMALL) == (0, 0)


# ---------------------------------------------------------------- the candidate's planes (clip_planes)

PLANES_CAM = look_at((0, 0, 5), (0, 0, 0), (0, 1, 0), fov_y_deg=60, width=640, height=480, near=4.5, far=6.0)


def _kind(near_fit):
    planes = {"front": True, "behind": False, "near_fit": near_fit, "far_fit": PLANES_CAM.far}
    fault = clip_fault(planes, PLANES_CAM)
    return None if fault is None else fault["kind"]


def test_plane_rel_tol(naming):
    # a near plane fitted 3e-9 (relative) inside the camera's: past plane_rel_tol (1e-9) it is off, by float32
    # rounding at most (4 eps32 = 4.8e-7); within a tolerance of 4e-9 it is the camera's
    near_fit = PLANES_CAM.near * (1.0 + 3e-9)
    assert _kind(near_fit) == "float32_near"
    naming(plane_rel_tol=2e-9)
    assert _kind(near_fit) == "float32_near"
    naming(plane_rel_tol=4e-9)
    assert _kind(near_fit) is None


def test_float32_plane_roundings(naming):
    # a near plane 2 eps32 (relative) off: within float32_plane_roundings (4) eps32 a float32 rounding, past a
    # bound of 1.9 eps32 a wrong plane
    near_fit = PLANES_CAM.near * (1.0 + 2.0 * EPS["float32"])
    assert _kind(near_fit) == "float32_near"
    naming(float32_plane_roundings=2.1)
    assert _kind(near_fit) == "float32_near"
    naming(float32_plane_roundings=1.9)
    assert _kind(near_fit) == "near"


# ---------------------------------------------------------------- an unprojector's points (unproject_faults)


def test_unproject_fit_slack(naming):
    # the points of an inverse with its rows flipped, each moved 3 bounds along x (world units): the rows
    # flipped explain them within 3 bounds, within unproject_fit_slack (4); with the slack under 3, nothing does
    cam = look_at((1.0, 2.0, 6.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0), fov_y_deg=50, width=320, height=240)
    u, v = np.meshgrid(np.linspace(20.0, 300.0, 6), np.linspace(15.0, 225.0, 5))
    p_px = np.stack([u.ravel(), v.ravel()], axis=1)
    depth = np.linspace(3.0, 8.0, len(p_px))
    bound = np.full(len(p_px), 1e-3)
    flipped = unproject(np.stack([p_px[:, 0], cam.height - 1 - p_px[:, 1]], axis=1), depth, cam)
    cand = flipped + [3e-3, 0.0, 0.0]
    faults, measured = name_unproject_faults(p_px, depth, cam, cand, bound)
    assert [f.name for f in faults] == ["mirror_vertical"]
    assert measured["fit_ratios"]["mirror_vertical"] == pytest.approx(3.0, rel=1e-6)
    naming(unproject_fit_slack=3.01)
    assert [f.name for f in name_unproject_faults(p_px, depth, cam, cand, bound)[0]] == ["mirror_vertical"]
    naming(unproject_fit_slack=2.99)
    assert [f.name for f in name_unproject_faults(p_px, depth, cam, cand, bound)[0]] == ["unexplained"]


# ---------------------------------------------------------------- binary lines of an even width (even_lean)


def _axis_bands(leans_h, leans_v, per_edge=10):
    """Samples of horizontal (normal (0, 1)) and vertical (normal (1, 0)) 2-px bands at whole-pixel
    coordinates, leaning ``leans_*[k]`` half pixels: a 2-px band about y = 10 covers rows 9-10 leaning
    -1/2, 9-11 not leaning (centroid 10), 10-11 leaning +1/2, so its centroid offset is lean / 2 exactly
    (even_lean's module docstring). ``(normal, offset, point, edge)``."""
    normal, offset, point, edge = [], [], [], []
    for k, (n, lean) in enumerate([((0.0, 1.0), s) for s in leans_h] + [((1.0, 0.0), s) for s in leans_v]):
        along, at = np.linspace(30.0, 300.0, per_edge), np.full(per_edge, 10.0 + 7 * k)
        normal.append(np.tile(n, (per_edge, 1)))
        point.append(np.c_[along, at] if n[1] else np.c_[at, along])
        offset.append(np.full(per_edge, 0.5 * lean))
        edge.append(np.full(per_edge, k))
    return tuple(np.concatenate(x) for x in (normal, offset, point, edge))


def test_lean_gain_px2(naming):
    # 40 edges, 2 horizontal and 2 vertical ones leaning +-1/2 px (cancelling per axis): the leans explain
    # every edge (ms 0), the symmetric band leaves 1/2 px on 4 of 40 (ms_symmetric 1/4 x 4/40 = 0.025 px^2),
    # over lean_gain_px2 (1/64) the lean is taken; with a gain of 0.026 asked for, it is not
    samples = _axis_bands([1, -1] + [0] * 18, [1, -1] + [0] * 18)
    got = even_lean.fit(*samples, 2)
    assert got["ms"] == pytest.approx(0.0, abs=1e-12) and got["ms_symmetric"] == pytest.approx(0.025, abs=1e-12)
    assert got["leaning"] and got["edges_eff"] == pytest.approx(40.0)
    naming(lean_gain_px2=0.024)
    assert even_lean.fit(*samples, 2)["leaning"]
    naming(lean_gain_px2=0.026)
    assert not even_lean.fit(*samples, 2)["leaning"]


def test_max_untested_edges(naming):
    # 3 symmetric edges of equal weight (ms = ms_symmetric = 0): at most max_untested_edges (3) edges' worth
    # cannot test the symmetric band, so the lean is used; with the bound under 3 they test it
    samples = _axis_bands([0, 0], [0])
    got = even_lean.fit(*samples, 2)
    assert got["edges_eff"] == pytest.approx(3.0) and got["ms"] == 0.0 == got["ms_symmetric"] and got["leaning"]
    naming(max_untested_edges=3.0)
    assert even_lean.fit(*samples, 2)["leaning"]
    naming(max_untested_edges=2.99)
    assert not even_lean.fit(*samples, 2)["leaning"]


def test_min_edge_samples(naming):
    # 4 edges of 10 samples each: every edge counts while min_edge_samples <= 10; at 11 none does (no fit)
    samples = _axis_bands([0, 1], [0, -1], per_edge=10)
    assert even_lean.fit(*samples, 2)["edges"] == 4
    naming(min_edge_samples=10)
    assert even_lean.fit(*samples, 2)["edges"] == 4
    naming(min_edge_samples=11)
    assert even_lean.fit(*samples, 2) is None


# ---------------------------------------------------------------- where one-sided pixels lie (line_ends)


def test_end_reach_px(naming):
    # a line from (1, 2) to (8.3, 2) drawn on row 2, columns 1-8; the candidate drops column 7, 1.3 px from
    # the line's end: within end_reach_px (1.5) an end pixel, past a reach of 1.29 px one in the middle
    p0, p1 = np.array([[1.0, 2.0]]), np.array([[8.3, 2.0]])
    oracle = np.zeros((5, 12), bool)
    oracle[2, 1:9] = True
    cand = oracle.copy()
    cand[2, 7] = False
    assert end_attribution(cand, oracle, p0, p1) == {
        "start": [0, 0],
        "end": [0, 1],
        "middle": [0, 0],
        "stray": [0, 0],
        "tie": [0, 0],
    }
    naming(end_reach_px=1.31)
    assert end_attribution(cand, oracle, p0, p1)["end"] == [0, 1]
    naming(end_reach_px=1.29)
    got = end_attribution(cand, oracle, p0, p1)
    assert got["end"] == [0, 0] and got["middle"] == [0, 1]


# ---------------------------------------------------------------- antialiased frames (coverage_pixels)


def test_ridge_min_width_px(naming):
    # a vertical line between columns 2 and 3 at grey 63 | 63 (a 0.49-px line, 63 / 255 = 0.247 of full
    # coverage each): ridges from half of ridge_min_width_px's coverage up, int(255 x 0.5 / 2) = 63: drawn;
    # from 0.502 px on (int(64.0) = 64) they are not
    grey = np.tile(np.array([0, 0, 63, 63, 0, 0], np.uint8), (5, 1))
    assert coverage_pixels.drawn(grey)[:, [2, 3]].all()
    naming(ridge_min_width_px=0.5)
    assert coverage_pixels.drawn(grey)[:, [2, 3]].all()
    naming(ridge_min_width_px=0.502)
    assert not coverage_pixels.drawn(grey).any()


# ---------------------------------------------------------------- the line style's read (line_style, f1_radius)


def test_max_radius_px_caps_the_f1_radius_read_when_called(naming):
    # a 7-px wide line: 1 + ceil((7 - 1) / 2) = 4 px, capped at max_radius_px (3): 3; moved to 4 it is 4, and the
    # radii each frame's F1 is computed at follow (2..3, then 2..4)
    from wirecheck.oracles.judge import f1_radius

    read = {"style": "wide", "width_px": 7.0, "band_px": 7}
    assert f1_radius.radius_px(read) == 3 and f1_radius.radii() == (2, 3)
    naming(max_radius_px=4)
    assert f1_radius.radius_px(read) == 4 and f1_radius.radii() == (2, 3, 4)


def test_wide_min_px_decides_a_binary_lines_style_when_called(naming):
    # a case's histogram by hand: 350 pixels at 255 over 200 px of line, no free-line width sample, so the width
    # is the coverage over the length: 350 / 200 = 1.75 px, wide from wide_min_px (1.75) on; just above it the
    # same pixels are "aliased" (no drawn-pixel ratio: no oracle pixel counted)
    from wirecheck.oracles.judge.line_style import CaseStyle

    style = CaseStyle()
    style.hist[255] = 350
    style.length_px = 200.0
    assert NAMING.wide_min_px == 1.75 and style.classify()["style"] == "wide"
    naming(wide_min_px=math.nextafter(1.75, UP))
    assert style.classify()["style"] == "aliased"


# ---------------------------------------------------------------- a line's profile across it (line_profile)


def test_profile_min_mass_decides_a_sample_and_a_free_end(naming):
    # one horizontal line from (15, 12) to (45, 12), drawn as row 12 at coverage 1/2 (exact in binary): every
    # window across it (7 rows, 3 each side) holds a mass of 0.5 centred on the line, a sample from
    # profile_min_mass (0.5) on; its free ends' inner mass (bilinear every 0.5 px across: 1/4 + 1/2 + 1/4,
    # times the 0.5 px step) is 0.5 too, measured from the same bound on
    segs = np.array([[[15.0, 12.0], [45.0, 12.0]]])
    cov = np.zeros((25, 60))
    cov[12, 15:46] = 0.5
    got = measure(cov, segs)
    assert got["found"] == got["windows"] > 0 and np.all(got["mass"] == 0.5) and np.all(got["offset"] == 0.0)
    assert len(measure_ends(cov, segs)) == 2
    naming(profile_min_mass=0.5)
    assert measure(cov, segs)["found"] == got["windows"] and len(measure_ends(cov, segs)) == 2
    naming(profile_min_mass=math.nextafter(0.5, UP))
    assert measure(cov, segs)["found"] == 0 and len(measure_ends(cov, segs)) == 0


def test_profile_min_samples_decides_whether_the_geometry_is_measured(naming):
    # 20 samples, 10 of two vertical lines (normal +x, at x = -50 and 50) offset 0.25 and 10 of two horizontal
    # ones (normal +y, at y = -30 and 30) offset -0.125: the pooled offset is (0.25, -0.125) exactly, both axes
    # determined, and the affine fit (lines of two places each way fix its six numbers) the same offset with no
    # warp, from profile_min_samples (20) on; asked for 21, nothing is measured. even_lean's fit (4 edges of 5
    # samples) likewise.
    normal = np.array([[1.0, 0.0]] * 10 + [[0.0, 1.0]] * 10)
    offset = np.array([0.25] * 10 + [-0.125] * 10)
    along = np.linspace(-40.0, 40.0, 10)
    across = np.tile([-1.0, 1.0], 5)
    point = np.concatenate([np.c_[50.0 * across, along], np.c_[1.5 * along, 30.0 * across]])
    lean = _axis_bands([0, 0], [0, 0], per_edge=5)
    d, determined = pooled_offset(normal, offset)
    assert determined.tolist() == [True, True] and d.tolist() == pytest.approx([0.25, -0.125], abs=1e-15)
    d, m = fit_lines(normal, offset, point, np.zeros(2))
    assert d.tolist() == pytest.approx([0.25, -0.125], abs=1e-12) and np.abs(m).max() < 1e-12
    assert even_lean.fit(*lean, 2)["edges"] == 4
    naming(profile_min_samples=20)
    assert pooled_offset(normal, offset)[1].tolist() == [True, True] and even_lean.fit(*lean, 2) is not None
    assert fit_lines(normal, offset, point, np.zeros(2)) is not None
    naming(profile_min_samples=21)
    d, determined = pooled_offset(normal, offset)
    assert determined.tolist() == [False, False] and d.tolist() == [0.0, 0.0]
    assert even_lean.fit(*lean, 2) is None and fit_lines(normal, offset, point, np.zeros(2)) is None


# ---------------------------------------------------------------- a depth map's pixel maps (depth_pixels, depth_faults)

DEPTH_CAM = look_at((0, 0, 5), (0, 0, 0), (0, 1, 0), fov_y_deg=60, width=64, height=48)


def _mirrored_plane(rows, cols, undecided_cols=0, extra=()):
    """A plane's depth map over ``rows`` x ``cols`` (inclusive; face 0, its first ``undecided_cols`` columns
    UNDECIDED_FACE) and the candidate: its rows read back bottom first (mirror_vertical), plus a surface pixel
    of depth 4 at each ``extra`` (x, y). ``1 / depth = 0.2 + 0.001 x + 0.002 y`` is affine in the pixel (a
    plane under perspective): the mirror lands on whole pixels, so it fits with no residual, and no value
    model (scale, offset, range, reversed, encoding, precision) nor the fitted offset or scale draws the
    flipped slope."""
    yy, xx = np.mgrid[0:48, 0:64].astype(np.float64)
    (r0, r1), (c0, c1) = rows, cols
    ref, faces = np.full((48, 64), np.nan), np.full((48, 64), -1)
    ref[r0 : r1 + 1, c0 : c1 + 1] = 1.0 / (0.2 + 0.001 * xx + 0.002 * yy)[r0 : r1 + 1, c0 : c1 + 1]
    faces[r0 : r1 + 1, c0 : c1 + 1] = 0
    faces[r0 : r1 + 1, c0 : c0 + undecided_cols] = UNDECIDED_FACE
    cand = ref[::-1].copy()
    for x, y in extra:
        cand[y, x] = 4.0
    return cand, ref, faces


def _depth_names(cand, ref, faces):
    return name_depth_faults(cand, ref, 1e-6, DEPTH_CAM, faces=faces).names


def test_depth_outside_max(naming):
    # an 18 x 22 plane (396 px, rows 12-29 over rows 18-35 mirrored: they overlap) and 4 stray candidate pixels in
    # the top right corner, whose mirrors (rows 45-46) have four empty neighbours: 4 of 400 surface pixels land
    # on nothing, 0.01, at most depth_outside_max (0.01): mirror_vertical; just under it the map is not tried
    plane = _mirrored_plane((12, 29), (10, 31), extra=[(60, 1), (61, 1), (62, 1), (60, 2)])
    assert np.count_nonzero(np.isfinite(plane[0])) == 400
    assert _depth_names(*plane) == ("mirror_vertical",)
    naming(depth_outside_max=0.01)
    assert _depth_names(*plane) == ("mirror_vertical",)
    naming(depth_outside_max=math.nextafter(0.01, DOWN))
    assert _depth_names(*plane) == ("unexplained",)


def test_depth_interior_min(naming):
    # a 21 x 40 plane (840 px, rows 13-33, columns 12-51) whose first 18 columns show a surface of an undecided
    # face: a candidate pixel lands inside one face where its four neighbours are face 0, columns 30-50 and
    # mirrored rows 13-32, 21 x 20 = 420 of 840, exactly depth_interior_min (0.5): mirror_vertical; just above
    # it the map is not tried
    plane = _mirrored_plane((13, 33), (12, 51), undecided_cols=18)
    assert np.count_nonzero(np.isfinite(plane[0])) == 840
    assert _depth_names(*plane) == ("mirror_vertical",)
    naming(depth_interior_min=0.5)
    assert _depth_names(*plane) == ("mirror_vertical",)
    naming(depth_interior_min=math.nextafter(0.5, UP))
    assert _depth_names(*plane) == ("unexplained",)


#: An orthographic camera for the value models of a depth map (depth_faults): no ray lengths, so only the
#: values decide (depth_is_range is a perspective mistake); near 1, far 11.
ORTHO_CAM = look_at(
    (0, 0, 5),
    (0, 0, 0),
    (0, 1, 0),
    projection="orthographic",
    ortho_height=2.0,
    width=64,
    height=48,
    near=1.0,
    far=11.0,
)


def test_depth_fit_slack(naming):
    # a map stored x1000 (millimetres read as metres) with one pixel 4.0 more: the reference 2 + n / 8 (n the
    # pixel's flat index; eighths, exact in binary), the candidate 1000 times it (exact), the scale fitted as
    # the median of c / r (exactly 1000), the allowance carried through it 1000 x 0.001 = 1.0 (exact in float):
    # the worst residual is 4.0 allowances, at depth_fit_slack (4.0): depth_scale; just under it no model
    # explains the map (offset, reversed, quantised, float16 and encoding miss by orders of magnitude)
    ref = 2.0 + np.arange(48 * 64, dtype=np.float64).reshape(48, 64) / 8.0
    cand = 1000.0 * ref
    cand[20, 30] += 4.0
    assert name_depth_faults(cand, ref, 1e-3, ORTHO_CAM).names == ("depth_scale",)
    naming(depth_fit_slack=4.0)
    assert name_depth_faults(cand, ref, 1e-3, ORTHO_CAM).names == ("depth_scale",)
    naming(depth_fit_slack=math.nextafter(4.0, DOWN))
    assert name_depth_faults(cand, ref, 1e-3, ORTHO_CAM).names == ("unexplained",)


def test_depth_encoding_margin(naming):
    # window depth stored from an orthographic camera (near 1, far 11): c = (r - 1) / 10, so r = 1 + 10 c, with
    # c evenly from 0.05 to 1 + 2^-18 (the farthest pixels a little beyond far). The encoding model is tried
    # only when every value is within 1 + depth_encoding_margin: at hi - 1 exactly (1 + (hi - 1) == hi in
    # float) the map is depth_encoding; a margin one float of 1.0 smaller (1 + m < hi) leaves it unexplained
    hi = 1.0 + 2.0**-18
    cand = np.linspace(0.05, hi, 48 * 64).reshape(48, 64)
    ref = 1.0 + 10.0 * cand
    assert cand.max() == hi
    naming(depth_encoding_margin=hi - 1.0)
    assert name_depth_faults(cand, ref, 1e-6, ORTHO_CAM).names == ("depth_encoding",)
    naming(depth_encoding_margin=math.nextafter(hi, DOWN) - 1.0)
    assert name_depth_faults(cand, ref, 1e-6, ORTHO_CAM).names == ("unexplained",)


def test_depth_step_tolerance(naming):
    # a map quantised on steps of 0.25 whose upper levels are moved by 2^-12: levels 1 + 0.25 k (k < 24) plus
    # 2^-12 for k >= 12 (all exact in binary), so the least gap is 0.25 and one gap is 0.25 + 2^-12, 1 + 2^-10
    # steps: off a whole step by exactly 2^-10. The reference is each level plus up to 0.1 (under the step, so
    # the quantised model explains the residuals). At depth_step_tolerance 2^-10 the map is depth_precision;
    # one float under it, the step is no step: unexplained
    k = np.arange(48 * 64).reshape(48, 64) % 24
    cand = 1.0 + 0.25 * k + np.where(k >= 12, 2.0**-12, 0.0)
    ref = cand + 0.1 * np.sin(np.arange(48 * 64).reshape(48, 64) + 0.5)
    naming(depth_step_tolerance=2.0**-10)
    assert name_depth_faults(cand, ref, 1e-6, ORTHO_CAM).names == ("depth_precision",)
    naming(depth_step_tolerance=math.nextafter(2.0**-10, DOWN))
    assert name_depth_faults(cand, ref, 1e-6, ORTHO_CAM).names == ("unexplained",)


# ---------------------------------------------------------------- a filled frame's silhouette (silhouette_faults)

SIL_CAM = look_at((0, 0, 5), (0, 0, 0), (0, 1, 0), fov_y_deg=60, width=96, height=72)


def _shifted_silhouette(corners_px, holes=(), strays=()):
    """One face with its corners at ``corners_px`` (pixels, on the plane z = 0 five units in front of SIL_CAM), its
    reference silhouette (the fill rule's ``inside``, ``ties``), and a candidate: the reference one column to
    the right (a pixel offset of exactly 1 px: the fill rule is the same under a whole-pixel move), with the
    pixels ``holes`` (x, y) left out and ``strays`` added. ``(frame, inside)``."""
    k = np.asarray(SIL_CAM.K, dtype=np.float64)
    px = np.asarray(corners_px, dtype=np.float64)
    p_world = np.column_stack(
        [(px[:, 0] - k[0, 2]) * 5.0 / k[0, 0], -(px[:, 1] - k[1, 2]) * 5.0 / k[1, 1], np.zeros(len(px))]
    )
    faces = (tuple(range(len(px))),)
    inside, ties, _ = silhouette(p_world, faces, SIL_CAM, (SIL_CAM.height, SIL_CAM.width))
    cand = np.roll(inside, 1, axis=1)
    for x, y in holes:
        cand[y, x] = False
    for x, y in strays:
        cand[y, x] = True
    return SilhouetteFrame(cand, inside, ties, SIL_CAM, p_world, faces), inside


def test_silhouette_allowance(naming):
    # a 30 x 20 rectangle between pixel-centre midpoints (x 20.5-50.5, y 20.5-40.5: columns 21-50, rows 21-40, no
    # tie), moved 1 px right, with 4 of its inner pixels left out: 2 x 30 + 2 x 20 - 4 = 96 boundary pixels, and
    # the offset (its edges half a pixel from any centre, so the moments' small bias flips none) misses the 4
    # holes alone: 4 / 96 = 1/24 <= silhouette_allowance (0.05): pixel_offset; just under 1/24, unexplained
    frame, inside = _shifted_silhouette(
        [(20.5, 20.5), (50.5, 20.5), (50.5, 40.5), (20.5, 40.5)], holes=[(30, 30), (31, 30), (30, 31), (31, 31)]
    )
    hand = np.zeros_like(inside)
    hand[21:41, 21:51] = True
    assert np.array_equal(inside, hand) and not frame.ties.any()
    (f,) = name_silhouette_faults([frame])
    assert f.name == "pixel_offset" and (f.params["misses"], f.params["boundary_px"]) == (4, 96)
    naming(silhouette_allowance=4 / 96)
    assert [f.name for f in name_silhouette_faults([frame])] == ["pixel_offset"]
    naming(silhouette_allowance=math.nextafter(4 / 96, DOWN))
    (f,) = name_silhouette_faults([frame])
    assert f.name == "unexplained" and f.params["best"] == "pixel_offset"


def test_silhouette_polish_below(naming):
    # a triangle with slanted edges, moved 1 px right, and one stray pixel in the image's far corner: the stray
    # pulls the moments' offset off 1 px, so the moments' fit misses the stray and the decided centres within
    # that bias of the slanted edges (measured below, polishing off: more than an allowance); polished on its
    # misses the offset misses the stray alone. Polished from silhouette_polish_below x silhouette_allowance x
    # the boundary pixels up to those misses: pixel_offset; with the bound just under them, unexplained
    frame, _ = _shifted_silhouette([(20.3, 15.2), (70.9, 25.7), (33.1, 60.4)], strays=[(90, 70)])
    (f,) = name_silhouette_faults([frame])
    assert f.name == "pixel_offset" and f.params["misses"] == 1
    boundary = f.params["boundary_px"]
    naming(silhouette_polish_below=0.0)
    (f,) = name_silhouette_faults([frame])
    assert f.name == "unexplained" and f.params["boundary_px"] == boundary
    moments_misses = f.params["fit_ratios"]["pixel_offset"] * boundary  # the moments' fit, not polished
    assert 1 < moments_misses / (NAMING.silhouette_allowance * boundary) < NAMING.silhouette_polish_below
    # the least float bound whose allowance product (bound x allowance x boundary pixels) reaches those misses
    at = moments_misses / (NAMING.silhouette_allowance * boundary)
    while at * NAMING.silhouette_allowance * boundary < moments_misses:
        at = math.nextafter(at, UP)
    while math.nextafter(at, DOWN) * NAMING.silhouette_allowance * boundary >= moments_misses:
        at = math.nextafter(at, DOWN)
    naming(silhouette_polish_below=at)
    assert [f.name for f in name_silhouette_faults([frame])] == ["pixel_offset"]
    naming(silhouette_polish_below=math.nextafter(at, DOWN))
    assert [f.name for f in name_silhouette_faults([frame])] == ["unexplained"]
