"""oracles.judge.surfaces: holes and extra surface counted away from the reference silhouette's boundary.

Expected masks derived by hand from the rule (a hole: covered with its eight neighbours covered, past the
image's edge counting as covered; extra: shown with no covered pixel among itself and its eight neighbours).
"""

from __future__ import annotations

import numpy as np
from wirecheck.oracles.judge.surfaces import surface_mismatch


def test_a_block_in_the_middle_one_hole_and_extra_only_off_its_ring():
    covered = np.zeros((7, 9), bool)
    covered[2:5, 3:6] = True  # rows 2-4, columns 3-5
    holes, extra = surface_mismatch(np.zeros_like(covered), covered)
    expected = np.zeros_like(covered)
    expected[3, 4] = True  # the block's one pixel with all eight neighbours covered
    np.testing.assert_array_equal(holes, expected)
    assert not extra.any()
    holes, extra = surface_mismatch(np.ones_like(covered), covered)
    ring = np.zeros_like(covered)
    ring[1:6, 2:7] = True  # the block grown by one pixel: covered or beside a covered pixel
    assert not holes.any()
    np.testing.assert_array_equal(extra, ~ring)  # 63 - 25 = 38 pixels
    assert extra.sum() == 38


def test_a_block_at_the_image_corner_the_edge_counts_as_covered():
    covered = np.zeros((5, 6), bool)
    covered[:3, :3] = True
    holes, extra = surface_mismatch(np.zeros_like(covered), covered)
    expected = np.zeros_like(covered)
    expected[:2, :2] = True  # past the edge counts as covered: (0, 0), (0, 1), (1, 0), (1, 1)
    np.testing.assert_array_equal(holes, expected)
    holes, extra = surface_mismatch(np.ones_like(covered), covered)
    assert not holes.any() and extra.sum() == 30 - 16  # rows and columns 0-3 are covered or beside it


def test_nothing_covered_every_shown_pixel_is_extra():
    shown = np.zeros((4, 4), bool)
    shown[1, 2] = shown[3, 0] = True
    holes, extra = surface_mismatch(shown, np.zeros((4, 4), bool))
    assert not holes.any()
    np.testing.assert_array_equal(extra, shown)
