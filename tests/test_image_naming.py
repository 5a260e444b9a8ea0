"""oracles.diagnosis.image_naming: an offset is judged against the fitted model's own lines.

A rectangle of axis-aligned lines is drawn by core's rasteriser, scaled 0.75 about the principal point
(a pure FOV fault). Its edges lie at u = 98.7 and -90.65 px from the centre (cx = 319.5, cy = 239.5):
the oracle's lines at x = 418.2 and 228.85 round by -0.2 and +0.15 (mean -0.025 px: no bias), the
scaled ones at 393.525 and 251.5125 round by +0.475 and +0.4875 (mean +0.48 px): a correct drawing of
the scaled lines sits 0.48 px off, beyond the 0.2-px offset tolerance, and is no pixel_offset.
"""

from __future__ import annotations

import numpy as np
import pytest
from wirecheck.core.camera import look_at
from wirecheck.core.projector.raster import line_pixels
from wirecheck.oracles.diagnosis import image_diagnose, image_naming
from wirecheck.oracles.diagnosis.image_diagnose import diagnose_images
from wirecheck.oracles.diagnosis.model_lines import model_images
from wirecheck.oracles.tolerances import OFFSET_TOL_PX

CAM = look_at((0, 0, 5), (0, 0, 0), (0, 1, 0), fov_y_deg=60, width=640, height=480)
CX, CY = CAM.principal_point
SCALE = 0.75
pytestmark = pytest.mark.slow  # two image diagnoses, ~5 s each


def _rectangle(right, left, bottom, top):
    c = np.array([[-left, -top], [right, -top], [right, bottom], [-left, bottom]]) + [CX, CY]
    return np.stack([c, np.roll(c, -1, axis=0)], axis=1)


def _draw(segs):
    img = np.zeros((CAM.height, CAM.width), bool)
    rr, cc = line_pixels(segs[:, 0], segs[:, 1], CAM.width, CAM.height)
    img[rr, cc] = True
    return img


SEGS = [_rectangle(98.7, 90.65, 98.7, 90.65)] * 2
CAND = [_draw((s - [CX, CY]) * SCALE + [CX, CY]) for s in SEGS]


def test_rounding_of_the_scaled_lines_is_no_offset():
    got = diagnose_images(CAND, SEGS, CAM)
    assert [f["name"] for f in got] == ["fov_mismatch"], got
    # two lines per axis, each rounded to its pixel: the scale to ~1 px over ~190 px, 5e-3 relative
    assert got[0]["scale"] == pytest.approx(SCALE, abs=5e-3)


def test_the_oracles_bias_would_have_named_an_offset(monkeypatch):
    """The control: judged against the oracle lines' bias (-0.025 px) the 0.48 px is an offset."""
    bias = image_diagnose.quantisation_bias
    oracle_bias = bias(SEGS, CAM)
    model_bias = bias(SEGS, CAM, np.eye(2), np.array([SCALE, SCALE]))
    # hand-derived above: the model's lines sit 0.48 px off on both axes, the oracle's ~0
    assert np.all(np.abs(oracle_bias) < 0.1) and np.all(np.abs(model_bias - 0.48) < 0.05)
    assert np.max(np.abs(model_bias - oracle_bias)) > OFFSET_TOL_PX
    monkeypatch.setattr(image_diagnose, "quantisation_bias", lambda segs, cam, p=None, d=None: bias(segs, cam))
    # axis-aligned lines are the same pixels under either aliased rule (read_rules may read either or both):
    # GL's alone here
    monkeypatch.setattr(image_naming, "read_rules", lambda *args: {"gl": args[-1]})
    assert "pixel_offset" in [f["name"] for f in diagnose_images(CAND, SEGS, CAM)]


def test_the_aliased_rule_is_read_from_the_pixels():
    """A slanted triangle drawn by GL's rule (core's exact) and by the rule that rounds ends first (Bresenham's):
    rule_bias reads each one's rule, and the bias it returns is that rule's own."""
    from wirecheck.core.projector.raster import line_pixels_fast

    # ends at fractional positions (0.3-0.45 px from a pixel centre): rounding them moves each line
    tri = np.array([[CX - 101.3, CY + 60.4], [CX + 87.35, CY + 75.7], [CX + 12.6, CY - 93.45]])
    segs = [np.stack([tri, np.roll(tri, -1, axis=0)], axis=1)] * 2
    eye, one = np.eye(2), np.ones(2)
    gl_bias = image_naming.quantisation_bias(segs, CAM)
    snapped_bias = image_naming.quantisation_bias(segs, CAM, snapped=True)
    for draw, rule in ((line_pixels, "gl"), (line_pixels_fast, "snapped")):
        img = np.zeros((CAM.height, CAM.width), bool)
        rr, cc = draw(segs[0][:, 0], segs[0][:, 1], CAM.width, CAM.height)
        img[rr, cc] = True
        # a correct drawing's fitted offset is its rule's bias (the definition of quantisation_bias)
        b = gl_bias if rule == "gl" else snapped_bias
        got, bias = image_naming.rule_bias([img, img], segs, CAM, eye, one, b, gl_bias)
        assert got == rule
        np.testing.assert_array_equal(bias, b)


def test_the_snapped_model_is_the_line_models_rounded_rule_at_half_pixel_ties():
    # the diagnosis' rounded-ends model breaks an exact half-pixel tie as oracles.line_model's "rounded" rule does:
    # the nearest pixel floor(minor + 1/2), to +x and +y alike (core's line_pixels_fast breaks x-minor ties to -x).
    # By hand: (10, 10) -> (11, 12), y-major, 2 steps: at y = 11 the exact x is 10.5: x = 11, so (10, 10),
    # (11, 11), (11, 12); (20, 30) -> (22, 31), x-major: at x = 21 the exact y is 30.5: y = 31. Ends at
    # .2 and .4 from a centre round to it. Identity model (p = I, d = 1, no shift).
    segs = [np.array([[[10.2, 9.6], [11.0, 12.4]], [[20.0, 30.3], [21.6, 31.0]]])]
    (img,) = model_images(segs, CAM, np.eye(2), np.ones(2), snapped=True)
    assert sorted(zip(*np.nonzero(img)[::-1])) == [(10, 10), (11, 11), (11, 12), (20, 30), (21, 31), (22, 31)]


def test_scale_starts_are_the_convention_mistakes_ratios():
    # the restarts of a fit no usual start explains (image_naming.scale_starts) are the scales a convention
    # mistake gives: an aspect of 4:3 or 16:9 either way round, a half or double angle or size (2, 1/2), and
    # the camera's own W/H and H/W; each on both axes, on x alone and on y alone
    from wirecheck.oracles.diagnosis.image_naming import scale_starts

    def starts(camera):
        return sorted({tuple(round(float(v), 12) for v in d) for d in scale_starts(camera)})

    def expected(ratios):
        return sorted({tuple(round(v, 12) for v in d) for r in ratios for d in ((r, r), (r, 1.0), (1.0, r))})

    mistakes = [4 / 3, 3 / 4, 16 / 9, 9 / 16, 2.0, 0.5]
    # a 16:9 camera's W/H and H/W are among the mistakes: nothing more
    assert starts(look_at((0, 0, 5), (0, 0, 0), (0, 1, 0), width=640, height=360)) == expected(mistakes)
    # a square camera's W/H = H/W = 1 adds only the unit scale
    assert starts(look_at((0, 0, 5), (0, 0, 0), (0, 1, 0), width=480, height=480)) == expected(mistakes + [1.0])


def test_a_swap_about_the_principal_point_is_no_offset():
    # x and y exchanged about the principal point ((u, v) -> (v, u), centred): an axis swap whose fitted
    # offset is 0, one of the offsets a swap may carry (0, or +-(cx - cy) for a swap of raw pixel
    # coordinates, 80 px here): named axis_swap alone, no pixel_offset. The lines: an asymmetric open
    # polyline within 150 px of the centre (inside the 640 x 480 image either way round), two frames
    pts = np.array([[-150.0, -120.0], [130.0, -60.0], [40.0, 140.0], [-90.0, 60.0], [-20.0, -10.0]])
    segs = np.stack([pts[:-1], pts[1:]], axis=1) + [CX, CY]
    swapped = (segs - [CX, CY])[:, :, ::-1] + [CX, CY]
    got = diagnose_images([_draw(swapped)] * 2, [segs] * 2, CAM)
    assert [f["name"] for f in got] == ["axis_swap"], got


def test_a_scale_stands_against_every_rule_read():
    # oracles.diagnosis.rule_read: under the rule that rounds the ends a scale must move the farthest pixel by
    # more than the tolerance plus half a pixel (0.5 + 0.5 px here). Hand-derived at a reach of 100 px per axis:
    # scales (1, 1.006) make an aspect of 0.006 x 100 = 0.6 px and move y's farthest pixel by 0.6 px (a FOV);
    # (1, 1.012): 1.2 px each
    from wirecheck.oracles.diagnosis.diagnose import scale_faults
    from wirecheck.oracles.diagnosis.rule_read import standing_scale_faults

    reach, tol = np.array([100.0, 100.0]), 0.5
    for d, under_gl, under_both in (
        ((1.0, 1.006), ["aspect_mismatch", "fov_mismatch"], []),
        ((1.0, 1.012), ["aspect_mismatch", "fov_mismatch"], ["aspect_mismatch", "fov_mismatch"]),
    ):
        named = scale_faults(d[0], d[1], reach, tol, CAM)
        assert [f["name"] for f in named] == under_gl
        gl_only = standing_scale_faults(named, np.array(d), reach, tol, CAM, {"gl": np.zeros(2)})
        assert [f["name"] for f in gl_only] == under_gl
        for rules in ({"snapped": np.zeros(2)}, {"gl": np.zeros(2), "snapped": np.zeros(2)}):
            got = standing_scale_faults(named, np.array(d), reach, tol, CAM, rules)
            assert [f["name"] for f in got] == under_both


@pytest.mark.parametrize(
    "gl_cost, snapped_cost, read",
    [
        (0.361, 0.368, ["gl", "snapped"]),  # Bresenham's wrong-axis FOV, prism / wide_fov: 2 % apart, a tie
        (0.374, 0.485, ["gl", "snapped"]),  # LINE_8, pyramid / non_square: 30 %, still a tie (the margin's case)
        (0.300, 0.401, ["gl"]),  # 34 % > 1/3: GL's alone
        (0.401, 0.300, ["snapped"]),  # and the rounded ends' alone
        (0.300, 0.399, ["gl", "snapped"]),  # 33 % < 1/3: a tie
    ],
)
def test_two_rules_are_read_within_the_tie_margin(monkeypatch, gl_cost, snapped_cost, read):
    # read_rules reads one rule only when the other's cost exceeds it by more than NAMING.rule_tie (1/3) of it
    # (rule_read's docstring: above the largest misread measured, 30 %); the closer rule first
    from wirecheck.oracles.diagnosis import rule_read

    snapped_bias, gl_bias = np.array([0.2, -0.1]), np.array([0.01, 0.02])
    monkeypatch.setattr(rule_read, "_costs", lambda *args: (snapped_bias, gl_cost, snapped_cost))
    got = rule_read.read_rules(None, None, CAM, np.eye(2), np.ones(2), np.zeros(2), gl_bias)
    assert sorted(got) == sorted(read) and next(iter(got)) == read[0 if gl_cost < snapped_cost else -1]
    for rule, bias in got.items():
        np.testing.assert_array_equal(bias, gl_bias if rule == "gl" else snapped_bias)
