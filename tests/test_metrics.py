"""oracles.metrics against hand-counted images and hand-derived errors."""

import numpy as np
import pytest

from oracles.metrics import diff_image, pixel_scores, vertex_errors


def test_vertex_errors_hand_values():
    # errors 3-4-5 triangle (5 px) and 0; one point clipped by each side
    cand = np.array([[3.0, 4.0], [10.0, 10.0], [np.nan, np.nan], [1.0, 1.0]])
    orac = np.array([[0.0, 0.0], [10.0, 10.0], [5.0, 5.0], [np.nan, np.nan]])
    ve = vertex_errors(cand, orac)
    assert ve["max_px"] == 5.0 and ve["worst_index"] == 0
    assert ve["mean_px"] == 2.5
    assert ve["rms_px"] == pytest.approx(np.sqrt(12.5), rel=1e-15)  # sqrt((25 + 0) / 2)
    assert (ve["visible_both"], ve["candidate_only"], ve["oracle_only"]) == (2, 1, 1)


def test_pixel_scores_shifted_line():
    # a 10-px horizontal line vs the same line one row down: nothing matches
    # exactly, everything matches within 1 px (Chebyshev)
    a = np.zeros((8, 12), bool); a[3, 1:11] = True
    b = np.zeros((8, 12), bool); b[4, 1:11] = True
    s = pixel_scores(a, b)
    assert s["f1_0px"] == 0.0
    assert s["f1_1px"] == 1.0


def test_pixel_scores_partial():
    # candidate draws 10 px, oracle 8 of them plus 2 elsewhere (far away):
    # P@0 = 8/10, R@0 = 8/10 -> F1 = 0.8
    a = np.zeros((20, 20), bool); a[2, 0:10] = True
    b = np.zeros((20, 20), bool); b[2, 0:8] = True; b[15, 15:17] = True
    s = pixel_scores(a, b)
    assert s["precision_0px"] == 0.8 and s["recall_0px"] == 0.8
    assert s["f1_0px"] == pytest.approx(0.8, abs=1e-15)
    # at 1 px: a's pixels 8, 9 are within 1 of b's pixel 7? only pixel 8 is -> P = 9/10;
    # b's far pixels are unmatched -> R = 8/10
    assert s["precision_1px"] == 0.9 and s["recall_1px"] == 0.8


def test_pixel_scores_blank_images():
    z = np.zeros((4, 4), bool)
    one = z.copy(); one[1, 1] = True
    assert pixel_scores(z, z)["f1_0px"] == 1.0           # both blank: agree
    assert pixel_scores(one, z)["f1_1px"] == 0.0         # one blank: disagree
    assert pixel_scores(z, one)["f1_1px"] == 0.0


def test_diff_image_colours():
    a = np.array([[1, 1, 0, 0]], bool)
    b = np.array([[1, 0, 1, 0]], bool)
    d = diff_image(a, b)
    assert d[0, 0].tolist() == [255, 255, 255]     # both
    assert d[0, 1].tolist() == [255, 70, 70]       # candidate only: red
    assert d[0, 2].tolist() == [60, 170, 255]      # oracle only: blue
    assert d[0, 3].tolist() == [0, 0, 0]
