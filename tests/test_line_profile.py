"""oracles.judge.line_profile.pooled_offset: the least-squares offset of a case's samples, at its limits.

The values are derived by hand: samples ``offset_i = n_i . d`` of a known ``d`` give ``d`` back exactly
when the normals span both axes; an axis no normal weighs (fewer than 5 % of the samples' weight) is
neither fitted nor determined; fewer than 20 samples (the documented minimum) measure nothing.
"""

from __future__ import annotations

import numpy as np
from wirecheck.oracles.judge.line_profile import pooled_offset

D = np.array([0.25, -0.125])  # exact in binary: the fit gives it back to rounding (lstsq, ~1e-16)


def _samples(n_x: int, n_y: int) -> tuple[np.ndarray, np.ndarray]:
    """``n_x`` samples of vertical lines (normal +x) and ``n_y`` of horizontal ones (normal +y), offset by D."""
    normal = np.array([[1.0, 0.0]] * n_x + [[0.0, 1.0]] * n_y)
    return normal, normal @ D


def test_twenty_samples_are_measured_nineteen_are_not():
    d, determined = pooled_offset(*_samples(10, 10))
    assert determined.tolist() == [True, True]
    np.testing.assert_allclose(d, D, rtol=0, atol=1e-15)
    d, determined = pooled_offset(*_samples(10, 9))
    assert determined.tolist() == [False, False] and d.tolist() == [0.0, 0.0]


def test_an_axis_is_determined_from_five_percent_of_the_weight():
    # 1 of 20 samples on x: its weight 1 is exactly 5 % of 20 (0.05 * 20 == 1.0 in float64): determined
    d, determined = pooled_offset(*_samples(1, 19))
    assert determined.tolist() == [True, True]
    np.testing.assert_allclose(d, D, rtol=0, atol=1e-15)
    # 1 of 21: below 5 % (1 < 1.05): x is neither fitted nor determined, y still is
    d, determined = pooled_offset(*_samples(1, 20))
    assert determined.tolist() == [False, True]
    assert d[0] == 0.0 and abs(d[1] - D[1]) < 1e-15
