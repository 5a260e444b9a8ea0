"""oracles.diagnosis.image_diagnose: faults named from images alone.

Each fault is injected into a copy of core's projector (the faulty projectors
of tests/test_diagnosis.py, the same ones the vertex diagnosis is proved on),
drawn to images by core's rasteriser (oracles.candidates.draw.draw_candidate: depth clip,
the faulty projection of the clipped ends, core.projector.raster.line_pixels), and
diagnosed from those images and the oracle's lines only: the faulty pixel
coordinates never reach the diagnosis. A depth-flipped renderer is drawn with
the camera looking backward (its own clipping then keeps what lies behind).
The confusion matrix of primary faults is printed in the terminal summary and
must be diagonal. Anti-aliased and 2-px-wide drawings (:func:`draw_aa`,
:func:`draw_wide`) are tested in tests/test_image_diagnosis_thick.py.
"""

from __future__ import annotations

import pickle
from collections import Counter

import numpy as np
import pytest
from diagnosis_faults import CALIBRATED_FAULTS, CAMERAS, CLIP_FAULTS, FAULTS, FOV_FACTOR, SINGLE, implied_fov
from test_diagnosis import format_confusion
from wirecheck.core.camera import look_at
from wirecheck.core.projector.clipping import clip_to_image
from wirecheck.core.projector.projection import project_points
from wirecheck.core.projector.raster import line_coverage_aa
from wirecheck.core.scene.files import load_scene
from wirecheck.core.transforms import Motion, apply
from wirecheck.oracles.candidates.draw import clip_depth, draw_candidate
from wirecheck.oracles.diagnosis.diagnose import primary
from wirecheck.oracles.diagnosis.image_diagnose import diagnose_images, flipped_camera, oracle_segments
from wirecheck.oracles.faults import NAMES as FAULT_ORDER
from wirecheck.oracles.faults import names as fault_names

pytestmark = pytest.mark.slow  # an expensive module fixture (tests/conftest.py runs such files first)

SCENES = ("cube", "pyramid", "prism")
FRAMES = (2, 7)  # of 12: two poses per scene, six images per case
MAIN_CAMERAS = ("axis", "oblique", "tall", "wide", "ortho")
# Every single fault on every camera ("transposed" is invisible on "axis", as in
# test_diagnosis); the combinations on two cameras; the camera inside the scene
# (scaled x2 around it) for a depth flip that shows the other side.
# (Not the faults that need fx != fy or a lens: test_diagnosis' calibrated cameras; nor
# float32_arith, float32 rounding of ~1e-5 px: a vertex-level fault a drawing cannot show.)
# Nor float32_k (float32 constants, ~1e-5 px) nor the depth-test faults (CLIP_FAULTS: probed on the
# projector, oracles.diagnosis.clip_planes).
CASES = [
    (f, c)
    for f in SINGLE
    for c in MAIN_CAMERAS
    if not (f == "transposed" and c == "axis")
    and f not in CALIBRATED_FAULTS
    and f not in ("float32_arith", "float32_k") + CLIP_FAULTS
]
CASES += [(f, c) for f in ("swap_mirror", "fov_aspect", "fov_offset") for c in ("oblique", "tall")]
CASES += [(f, "inside") for f in ("none", "depth_flip", "roll")]
# A view the images cannot decide a mirror on: the cube alone, centred, orthographic (its picture is
# centrally symmetric, so a left-right mirror is also an up-down one: both fit, the identity does not)
CASES += [(f, "ortho_cube") for f in ("none", "mirror_x", "mirror_y")]
IMAGE_CAMERAS = {
    **CAMERAS,
    "ortho_cube": look_at(
        (2, 3, 5), (0, 0, 0), (0.2, 1, 0), width=400, height=300, projection="orthographic", ortho_height=5.0
    ),
}
#: The names a case expects where they are not its fault's (test_diagnosis.FAULTS).
EXPECTED = {("mirror_x", "ortho_cube"): {"ambiguous"}, ("mirror_y", "ortho_cube"): {"ambiguous"}}


def expected(fault, camera_name):
    return EXPECTED.get((fault, camera_name), FAULTS[fault][1])


def _scene_frames(camera_name):
    motion = Motion(turns=(1.0, 2.0, 1.0), scale=2.0) if camera_name == "inside" else Motion()
    for name in ("cube",) if camera_name == "ortho_cube" else SCENES:
        sc = load_scene(name)
        for k in FRAMES:
            yield apply(motion.frame_matrix(k, 12), sc.vertices), np.asarray(sc.edges)


def _segments_px(fn, p_world, edges, cam):
    """The faulty renderer's 2D segments (depth clip, its projection, image clip): ``(K, 2, 2)``."""
    _, ends = clip_depth(p_world[edges[:, 0]], p_world[edges[:, 1]], cam)
    px = fn(ends.reshape(-1, 3), cam).reshape(-1, 2, 2)
    _, q0, q1 = clip_to_image(px[:, 0], px[:, 1], cam.width, cam.height)
    return q0, q1


def draw_aa(fn, p_world, edges, cam):
    """core's anti-aliased raster (Wu): every pixel with any coverage counts as drawn."""
    q0, q1 = _segments_px(fn, p_world, edges, cam)
    img = np.zeros((cam.height, cam.width), bool)
    rr, cc, w = line_coverage_aa(q0, q1, cam.width, cam.height)
    img[rr[w > 0], cc[w > 0]] = True
    return img


def draw_wide(fn, p_world, edges, cam, width_px=2.0):
    """A GL-style wide line: pixels whose centre lies within width/2 of the segment (naive distance)."""
    q0, q1 = _segments_px(fn, p_world, edges, cam)
    img = np.zeros((cam.height, cam.width), bool)
    yy, xx = np.mgrid[0 : cam.height, 0 : cam.width]
    pts = np.stack([xx.ravel(), yy.ravel()], axis=1).astype(float)
    for a, b in zip(q0, q1):
        lo = np.floor(np.minimum(a, b) - width_px).astype(int)
        hi = np.ceil(np.maximum(a, b) + width_px).astype(int)
        box = (pts[:, 0] >= lo[0]) & (pts[:, 0] <= hi[0]) & (pts[:, 1] >= lo[1]) & (pts[:, 1] <= hi[1])
        p = pts[box]
        ab = b - a
        t = np.clip(((p - a) @ ab) / max(ab @ ab, 1e-300), 0.0, 1.0)
        near = np.hypot(*(a + t[:, None] * ab - p).T) <= width_px / 2.0
        img.ravel()[np.flatnonzero(box)[near]] = True
    return img


def diagnose_fault(fault, camera_name, draw=draw_candidate):
    cam = IMAGE_CAMERAS[camera_name]
    fn, _ = FAULTS[fault]
    images, segs, flipped = [], [], []
    for p_world, edges in _scene_frames(camera_name):
        if fault == "depth_flip":  # the renderer's camera looks backward, clipping included
            images.append(draw(project_points, p_world, edges, flipped_camera(cam)))
        else:
            images.append(draw(fn, p_world, edges, cam))
        segs.append(oracle_segments(p_world, edges, cam))
        flipped.append(oracle_segments(p_world, edges, flipped_camera(cam)))
    return diagnose_images(images, segs, cam, flipped)


def _memoised_quantisation_bias():
    """``image_diagnose.quantisation_bias`` computed once per distinct input.

    It depends on the oracle's lines and the camera only, not on the
    candidate's images, so every fault on one camera asks for the same value
    (73 cases, 7 distinct inputs; ~0.09 s each). The key is the exact input
    (the camera and the segments' bytes), so the value is the one the
    function gives.
    """
    from wirecheck.oracles.diagnosis import image_diagnose

    compute, done = image_diagnose.quantisation_bias, {}

    def cached(oracle_segs, camera, p=None, d=None):
        segs = [np.asarray(s, dtype=np.float64) for s in oracle_segs]
        model = tuple(None if v is None else np.asarray(v, dtype=np.float64).tobytes() for v in (p, d))
        key = (pickle.dumps(camera), tuple((s.shape, s.tobytes()) for s in segs), model)
        if key not in done:
            done[key] = compute(oracle_segs, camera, p, d)
        return done[key].copy()

    return cached


@pytest.fixture(scope="module")
def results():
    from wirecheck.oracles.diagnosis import image_diagnose

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(image_diagnose, "quantisation_bias", _memoised_quantisation_bias())
        return {(f, c): diagnose_fault(f, c) for f, c in CASES}


@pytest.mark.parametrize("fault,camera_name", CASES)
def test_expected_names(results, fault, camera_name):
    got = results[(fault, camera_name)]
    assert {f["name"] for f in got} == expected(fault, camera_name), got


@pytest.mark.parametrize("fault", ["mirror_x", "mirror_y"])
def test_an_undecidable_mirror_gives_both_names_and_hints(results, fault):
    from wirecheck.oracles.faults import CATALOGUE
    from wirecheck.oracles.reports.fault_text import hints as fault_hints

    (amb,) = results[(fault, "ortho_cube")]
    assert sorted(amb["alternatives"]) == ["mirror_horizontal", "mirror_vertical"]
    (hint,) = [h for n, h in fault_hints([amb]) if n == "ambiguous"]
    assert CATALOGUE["mirror_horizontal"].hint in hint and CATALOGUE["mirror_vertical"].hint in hint
    # the confidence measures the mirror against no mirror (which does not fit), not against the other mirror
    assert amb["confidence"] > 0.5


def test_a_rotation_keeps_the_rotation_advice(results):
    # a roll or a transposed rotation moves the lines: the visibility advice (oracles.diagnosis.image_visibility,
    # for lines in place whose drawn sets differ) is never given to it
    rotations = [key for key in results if key[0] in ("roll", "transposed")]
    assert len(rotations) >= 5
    for key in rotations:
        for f in results[key]:
            assert f["name"] == "unexplained" and "hint" not in f and "candidate_only_px" not in f, (key, f)


def test_every_fault_has_confidence_and_residual(results):
    for key, got in results.items():
        for f in got:
            assert 0.0 <= f["confidence"] <= 1.0, (key, f)
            assert f["residual_px"] is not None and f["residual_px"] >= 0.0, (key, f)


@pytest.mark.parametrize("camera_name", MAIN_CAMERAS)
def test_implied_fov(results, camera_name):
    # the injected FOV is 0.8 x the camera's (test_diagnosis.implied_fov); from pixels the
    # scale is fitted to ~5e-4 (pooled ICP), so the implied FOV to 0.1 degree (0.01 of the height)
    (f,) = results[("fov", camera_name)]
    cam = CAMERAS[camera_name]
    if cam.projection == "perspective":
        assert f["implied_fov_deg"] == pytest.approx(implied_fov(cam), abs=0.1)
    else:
        assert f["implied_ortho_height"] == pytest.approx(cam.ortho_height * FOV_FACTOR, rel=2e-3)


@pytest.mark.parametrize("camera_name", MAIN_CAMERAS)
def test_implied_aspect(results, camera_name):
    # f_aspect takes fx from the width: aspect 1 (test_diagnosis: implied aspect = 1)
    (f,) = results[("aspect", camera_name)]
    assert f["implied_aspect"] == pytest.approx(1.0, abs=5e-3)


@pytest.mark.parametrize("camera_name", MAIN_CAMERAS)
def test_half_pixel_offset_to_sub_pixel(results, camera_name):
    # f_offset centres on (W/2, H/2): +0.5 px on both axes. Measured from pixels
    # (point-to-line ICP pooled over six frames): 0.46-0.51; asserted to 0.06 px, a
    # tenth of a pixel's width either side, far from 0 (no fault) and 1 (a whole pixel).
    (f,) = results[("offset", camera_name)]
    assert f["dx"] == pytest.approx(0.5, abs=0.06)
    assert f["dy"] == pytest.approx(0.5, abs=0.06)


def confusion(results):
    # the vertex diagnosis' names; line_end_bias / line_pixel_bias are per-edge pixel counts
    # of a drawing the harness made itself (oracles.diagnosis.diagnose.diagnose_lines), not this family
    # (nor distortion_mismatch: frames of a distorted camera are not compared, oracles.judge.case;
    # nor precision_limited: float32 rounding is far below a pixel)
    # (nor a depth map's or an unprojector's own names): those read from any source, and the images' ambiguous
    labels = ["none"] + [n for n in FAULT_ORDER if n in fault_names(source="any") + fault_names(source="images")]
    counts = Counter()
    for (fault, cam), got in results.items():
        if fault not in SINGLE:
            continue
        want = expected(fault, cam)
        counts[("none" if not want else min(want, key=FAULT_ORDER.index), primary(got))] += 1
    rows = [r for r in labels if any(counts[(r, c)] for c in labels)]
    return labels, rows, counts


def test_confusion_matrix_is_diagonal(results, summary_section):
    labels, rows, counts = confusion(results)
    text = format_confusion(labels, rows, counts).replace("confusion matrix (oracle", "images only (oracle lines")
    summary_section("image diagnosis confusion matrix", text)
    off = {k: v for k, v in counts.items() if k[0] != k[1] and v}
    assert not off, off
    assert set(rows) == set(labels)  # every fault name was injected


def test_blank_candidate_is_a_depth_flip_only_when_the_backward_view_is_empty():
    cam = CAMERAS["axis"]
    ((p_world, edges),) = list(_scene_frames("axis"))[:1]
    blank = [np.zeros((cam.height, cam.width), bool)]
    segs = [oracle_segments(p_world, edges, cam)]
    assert primary(diagnose_images(blank, segs, cam, [np.zeros((0, 2, 2))])) == "depth_flip"
    # the backward camera would see lines: drawing nothing is not a depth flip
    assert primary(diagnose_images(blank, segs, cam, segs)) == "unexplained"
    # nothing to draw, nothing drawn: agreement
    assert diagnose_images(blank, [np.zeros((0, 2, 2))], cam) == []


@pytest.mark.parametrize("fault", ["none", "fov_offset", "mirror_x"])
def test_a_case_of_many_frames_is_fitted_on_the_points_of_six(fault, monkeypatch):
    # 24 frames of the cube: every frame contributes, MAX_POINTS_PER_CASE // 24 = 150 points per
    # frame and direction (six frames keep their 600 each), so the fit costs what a six-frame
    # case costs; the names are those of the six-frame cases above
    from wirecheck.oracles.diagnosis import image_diagnose

    sizes = []
    init = image_diagnose.Registration.__init__

    def counting(self, frames, *args):
        init(self, frames, *args)
        sizes.append((len(frames), len(self._cand), len(self._samples)))

    monkeypatch.setattr(image_diagnose.Registration, "__init__", counting)
    cam = CAMERAS["oblique"]
    fn, want = FAULTS[fault]
    sc = load_scene("cube")
    images, segs = [], []
    for k in range(24):
        p_world = apply(Motion().frame_matrix(k, 24), sc.vertices)
        images.append(draw_candidate(fn, p_world, np.asarray(sc.edges), cam))
        segs.append(oracle_segments(p_world, np.asarray(sc.edges), cam))
    got = diagnose_images(images, segs, cam)
    assert {f["name"] for f in got} == want, got
    fine, coarse = sizes[0], sizes[1]  # the fit's and the screening's registrations
    assert fine[0] == 24 and 24 * 100 < fine[1] <= image_diagnose.MAX_POINTS_PER_CASE
    assert 24 * 100 < fine[2] <= image_diagnose.MAX_POINTS_PER_CASE
    assert coarse[1] <= image_diagnose.SCREEN_POINTS_PER_CASE and coarse[2] <= image_diagnose.SCREEN_POINTS_PER_CASE
