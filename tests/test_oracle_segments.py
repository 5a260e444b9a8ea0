"""oracles.candidates.draw.oracle_segments: the oracle's segments, against pixels derived by hand.

Camera at the origin looking down -z, 640 x 480, fov_y 90 deg: f = 240 px
(H / 2 / tan 45 deg), principal point (319.5, 239.5) (pixel centres on
integers, core.conventions), so a point (x, y, -z) lands on
``(319.5 + 240 x / z, 239.5 - 240 y / z)``. near = 1, far = 10.
"""

import numpy as np
import pytest
from wirecheck.core.camera import look_at
from wirecheck.oracles.candidates.draw import oracle_segments
from wirecheck.oracles.references import opencv_oracle

CAM = look_at((0.0, 0.0, 0.0), (0.0, 0.0, -1.0), fov_y_deg=90.0, width=640, height=480, near=1.0, far=10.0)

P_WORLD = np.array(
    [
        [1.0, 0.0, -2.0],
        [-1.0, 0.5, -4.0],  # edge 0: both ends inside [near, far]
        [0.5, 0.0, -0.5],
        [0.5, 0.0, -3.0],  # edge 1: first end in front of near: cut at depth 1
        [0.0, 0.0, -0.2],
        [1.0, 1.0, -0.5],  # edge 2: both in front of near: nothing left
        [2.0, 0.0, -20.0],
        [2.0, 0.0, -5.0],  # edge 3: first end beyond far: cut at depth 10
    ]
)
EDGES = np.array([[0, 1], [2, 3], [4, 5], [6, 7]])

#: by hand from the module docstring's formula; NaN: nothing of the edge in [near, far]
EXPECTED_P0 = np.array([[319.5 + 120.0, 239.5], [319.5 + 120.0, 239.5], [np.nan, np.nan], [319.5 + 48.0, 239.5]])
EXPECTED_P1 = np.array([[319.5 - 60.0, 239.5 - 30.0], [319.5 + 40.0, 239.5], [np.nan, np.nan], [319.5 + 96.0, 239.5]])

#: A cut end moves inside [near, far] by at least 1e-9 of the edge's parameter
#: (oracles.candidates.draw._INWARD; the depth margin, ~2e-15 in depth here, is smaller).
#: Edge 1 at the near plane: depth changes 2.5 per unit of the parameter, and
#: the pixel 240 x / z^2 = 120 px per unit of depth, so 300 px per unit of the
#: parameter: the end moves <= 3e-7 px (edge 3 at the far plane: <= 3e-8 px).
#: f itself is 240 to 3e-14.
TOL_PX = 1e-6


@pytest.mark.parametrize("given", [False, True], ids=["projects-itself", "reuses-vertex-pixels"])
def test_segments_match_hand_derived_pixels(given):
    p_px = opencv_oracle.project(P_WORLD, CAM) if given else None
    p0, p1 = oracle_segments(P_WORLD, EDGES, CAM, p_px)
    np.testing.assert_array_equal(np.isnan(p0), np.isnan(EXPECTED_P0))
    np.testing.assert_array_equal(np.isnan(p1), np.isnan(EXPECTED_P1))
    np.testing.assert_allclose(p0, EXPECTED_P0, rtol=0, atol=TOL_PX, equal_nan=True)
    np.testing.assert_allclose(p1, EXPECTED_P1, rtol=0, atol=TOL_PX, equal_nan=True)


def test_given_pixels_serve_only_whole_edges():
    """Edges with both ends in [near, far] take the given rows as they are; cut edges are projected anew."""
    p_px = opencv_oracle.project(P_WORLD, CAM)
    marked = p_px.copy()
    marked[np.isfinite(marked)] += 1000.0  # a shift no projection of these points gives
    p0, p1 = oracle_segments(P_WORLD, EDGES, CAM, marked)
    np.testing.assert_array_equal(p0[0], marked[0])
    np.testing.assert_array_equal(p1[0], marked[1])
    # edge 1's far end (vertex 3) is inside, but the edge is cut: both of its ends come from OpenCV
    np.testing.assert_allclose(p0[1:2], EXPECTED_P0[1:2], atol=TOL_PX)
    np.testing.assert_allclose(p1[1:2], EXPECTED_P1[1:2], atol=TOL_PX)


def test_no_edges():
    p0, p1 = oracle_segments(P_WORLD, np.zeros((0, 2), np.int64), CAM, opencv_oracle.project(P_WORLD, CAM))
    assert p0.shape == p1.shape == (0, 2)


def test_every_edge_whole_takes_the_given_rows_into_new_arrays():
    """Every edge in [near, far] (edge 0 both ways, and vertex 3 to vertex 0): each end is its vertex's
    given row, in arrays of their own (the caller blanks culled edges in them; the given pixels stay)."""
    p_px = opencv_oracle.project(P_WORLD, CAM)
    marked = p_px.copy()
    marked[np.isfinite(marked)] += 1000.0
    kept = marked.copy()
    edges = np.array([[0, 1], [1, 0], [3, 0]])
    p0, p1 = oracle_segments(P_WORLD, edges, CAM, marked)
    np.testing.assert_array_equal(p0, marked[[0, 1, 3]])
    np.testing.assert_array_equal(p1, marked[[1, 0, 0]])
    assert p0.dtype == p1.dtype == np.float64 and p0.shape == p1.shape == (3, 2)
    p0[0] = p1[0] = np.nan
    np.testing.assert_array_equal(marked, kept)
