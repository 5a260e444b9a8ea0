"""oracles.judge.silhouette: IoU, holes, extra and the longest run, over decided pixels; never vacuous.

Reference silhouettes come from oracles.references.fill_rule (tested in test_fill_rule.py); the
expected scores are counted by hand from how each candidate was made.
"""

from __future__ import annotations

import math
from collections import deque

import numpy as np
import pytest
from wirecheck.core.camera import look_at
from wirecheck.core.scene.files import load_scene
from wirecheck.oracles.judge.silhouette import SilhouetteScores, largest_run, score_silhouette
from wirecheck.oracles.references.fill_rule import coverage, silhouette
from wirecheck.oracles.tolerances import MIN_IOU_UNION_PX, Tolerances

TOL = Tolerances()


def _bfs_largest(mask: np.ndarray) -> int:
    """A naive reference for largest_run: breadth-first search over 8-neighbours."""
    seen = np.zeros_like(mask)
    best = 0
    for r0, c0 in zip(*np.nonzero(mask)):
        if seen[r0, c0]:
            continue
        seen[r0, c0] = True
        queue, size = deque([(r0, c0)]), 0
        while queue:
            r, c = queue.popleft()
            size += 1
            for dr in (-1, 0, 1):
                for dc in (-1, 0, 1):
                    rr, cc = r + dr, c + dc
                    if 0 <= rr < mask.shape[0] and 0 <= cc < mask.shape[1] and mask[rr, cc] and not seen[rr, cc]:
                        seen[rr, cc] = True
                        queue.append((rr, cc))
        best = max(best, size)
    return best


def _square(x0, y0, side, shape=(480, 640)):
    """An axis-aligned square's reference (two triangles, corners off the centres: no ties)."""
    x1, y1 = x0 + side, y0 + side
    return coverage([[[x0, y0], [x1, y0], [x1, y1]], [[x0, y0], [x1, y1], [x0, y1]]], shape)


# ---- the boundary measure ----------------------------------------------------------------------


def test_largest_run_counts_8_connected_pixels():
    m = np.zeros((8, 9), dtype=bool)
    m[np.arange(6), np.arange(6) + 2] = True  # a staircase: one run of 6 (diagonal neighbours)
    m[0, 8] = m[1, 8] = True  # a run of 2 at the border: no wrap-around to row 2, column 0
    m[2, 0] = True
    size, at = largest_run(m)
    assert size == 6 and m[at] and at[1] == at[0] + 2
    assert largest_run(np.zeros((3, 3), bool)) == (0, None)


def test_largest_run_agrees_with_a_breadth_first_search():
    rng = np.random.default_rng(35)
    for density in (0.05, 0.2, 0.45, 0.6):
        m = rng.random((60, 80)) < density
        assert largest_run(m)[0] == _bfs_largest(m), density
    # a long snake (the worst case for label propagation) is one run
    snake = np.zeros((41, 41), dtype=bool)
    snake[::2, :] = True
    for row in range(1, 41, 2):  # joined at alternate ends
        snake[row, 40 if row % 4 == 1 else 0] = True
    assert largest_run(snake)[0] == _bfs_largest(snake) == snake.sum()


def test_a_one_pixel_band_missing_along_one_edge_fails_though_iou_passes():
    # a 300 x 300 square; its rightmost column (300 px) dropped: IoU = 1 - 300/90000 = 0.99667,
    # above 0.99 and above the IoU limit (0.995), while the run is the whole band
    ref, ties = _square(100.3, 80.3, 300.0)
    assert ref.sum() == 300 * 300 and not ties.any()
    cand = ref.copy()
    last = np.flatnonzero(ref.any(axis=0))[-1]
    cand[:, last] = False
    s = score_silhouette(cand, ref, ties)
    assert s.iou == pytest.approx(1 - 300 / 90000, abs=1e-12) and s.iou > 0.99 and s.iou >= TOL.min_iou
    assert (s.holes, s.extra, s.longest_run_px) == (300, 0, 300)
    assert s.run_at[1] == last
    fails = s.failures(TOL)
    assert len(fails) == 1 and "300 decided pixels missing or added in one run" in fails[0]
    assert not s.passed(TOL)
    # the same band added outside the opposite edge: extra, also one run
    cand = ref.copy()
    cand[ref.any(axis=1), np.flatnonzero(ref.any(axis=0))[0] - 1] = True
    s = score_silhouette(cand, ref, ties)
    assert (s.holes, s.extra, s.longest_run_px) == (0, 300, 300) and not s.passed(TOL)


def test_a_half_pixel_shift_fails():
    # the prism seen obliquely (the oblique_roll camera), principal point moved by half a pixel
    # (cx = W/2, the classic mistake)
    scene = load_scene("prism")
    cam = look_at((2.0, 1.5, 2.5), (0.0, 0.0, 0.0), (0.3, 1.0, 0.2), fov_y_deg=55, near=0.1, far=10.0)
    f = (cam.height / 2) / math.tan(math.radians(cam.fov_y_deg) / 2)
    cx, cy = (cam.width - 1) / 2, (cam.height - 1) / 2
    shifted = look_at(
        (2.0, 1.5, 2.5), (0.0, 0.0, 0.0), (0.3, 1.0, 0.2), near=0.1, far=10.0, intrinsics=(f, f, cx + 0.5, cy)
    )
    ref, ties, _ = silhouette(scene.vertices, scene.faces, cam, (cam.height, cam.width))
    cand, _, _ = silhouette(scene.vertices, scene.faces, shifted, (cam.height, cam.width))
    s = score_silhouette(cand, ref, ties)
    # measured: 165 holes and 171 extra along the left and right edges, in runs of up to 4 px;
    # IoU 0.99516 would pass it alone (limit 0.995): the run fails it
    assert s.holes > 100 and s.extra > 100 and s.longest_run_px > 1
    assert s.iou > TOL.min_iou
    assert not s.passed(TOL) and "in one run" in s.failures(TOL)[0]
    # ... and the very same camera given by its intrinsics passes: the shift is the fault
    same = look_at((2.0, 1.5, 2.5), (0.0, 0.0, 0.0), (0.3, 1.0, 0.2), near=0.1, far=10.0, intrinsics=(f, f, cx, cy))
    cand, _, _ = silhouette(scene.vertices, scene.faces, same, (cam.height, cam.width))
    s = score_silhouette(cand, ref, ties)
    assert s.passed(TOL) and s.iou == 1.0 and s.longest_run_px == 0


def test_disagreements_at_ties_do_not_count():
    # the right triangle of test_fill_rule: every centre on its edges is a tie
    ref, ties = coverage([[[2, 2], [40, 2], [2, 40]]], (48, 48))
    cand = ref ^ ties  # every tie answered the other way
    s = score_silhouette(cand, ref, ties)
    assert ties.sum() == 3 * 38 and s.ties_px == 3 * 38
    assert (s.holes, s.extra, s.longest_run_px, s.iou) == (0, 0, 0, 1.0)
    assert s.passed(TOL)


def test_holes_and_extra_are_counted_and_scattered_pixels_make_short_runs():
    ref, ties = _square(10.3, 10.3, 40.0, shape=(64, 64))
    cand = ref.copy()
    cand[20, 20:23] = False  # a hole of 3 in a row
    cand[30, 30] = False  # and one alone
    cand[60, 5] = cand[60, 60] = True  # two extra, apart
    s = score_silhouette(cand, ref, ties)
    assert (s.holes, s.extra, s.longest_run_px) == (4, 2, 3)
    assert s.run_at == (20, 20)
    assert s.union_px == 1600 + 2 and s.iou == pytest.approx((1600 - 4) / 1602)
    assert s.ref_px == 1600 and s.cand_px == 1600 - 4 + 2 and s.decided_px == 64 * 64
    assert not s.passed(TOL)
    # a limit of 3 passes it (the IoU, 0.9963, is above 0.995); 2 does not
    assert s.passed(Tolerances(max_silhouette_run_px=3))
    assert "in one run" in " ".join(s.failures(Tolerances(max_silhouette_run_px=2)))


def test_iou_limit_applies_from_the_union_floor_up():
    ref, ties = _square(10.3, 10.3, 40.0, shape=(64, 64))  # 1600 px, above MIN_IOU_UNION_PX
    cand = ref.copy()
    cand[11:21, 11:51] = False  # 400 holes: IoU 0.75
    loose = Tolerances(max_silhouette_run_px=10**6)
    s = score_silhouette(cand, ref, ties)
    assert s.iou == pytest.approx(0.75) and not s.passed(loose)
    assert "IoU 0.750000 below 0.995" in s.failures(loose)[0]
    # a silhouette under the floor: its IoU is one boundary decision, so only the run decides
    small, small_ties = _square(10.3, 10.3, 10.0, shape=(64, 64))
    assert small.sum() < MIN_IOU_UNION_PX
    cand = small.copy()
    cand[11, 11:21] = False
    s = score_silhouette(cand, small, small_ties)
    assert s.iou == pytest.approx(0.9) and s.passed(loose) and not s.passed(TOL)


# ---- never vacuous -----------------------------------------------------------------------------

VERY_LOOSE = Tolerances(max_silhouette_run_px=10**9, min_iou=0.0)


def test_a_blank_candidate_never_passes():
    ref, ties = _square(10.3, 10.3, 40.0, shape=(64, 64))
    s = score_silhouette(np.zeros_like(ref), ref, ties)
    assert s.vacuous and "blank" in s.vacuous
    assert not s.passed(VERY_LOOSE) and s.failures(VERY_LOOSE) == [s.vacuous]


def test_an_empty_reference_never_passes():
    empty = np.zeros((64, 64), dtype=bool)
    for cand in (empty, ~empty):
        s = score_silhouette(cand, empty, empty)
        assert s.vacuous is not None and not s.passed(VERY_LOOSE)
    assert np.isnan(score_silhouette(empty, empty, empty).iou)


def test_nothing_decided_never_passes():
    ref, _ = _square(10.3, 10.3, 40.0, shape=(64, 64))
    s = score_silhouette(ref, ref, np.ones_like(ref))
    assert s.decided_px == 0 and "no decided pixel" in s.vacuous and not s.passed(VERY_LOOSE)


def test_a_reference_covered_only_at_ties_never_passes():
    ref, ties = coverage([[[2, 2], [3, 2], [2, 3]]], (8, 8))  # a half-pixel triangle: its centres on edges
    assert ref.any() and not (ref & ~ties).any()
    s = score_silhouette(ref, ref, ties)
    assert "reference covers no decided pixel" in s.vacuous and not s.passed(VERY_LOOSE)


def test_masks_of_other_shapes_are_refused():
    a = np.zeros((4, 5), bool)
    with pytest.raises(ValueError, match="one shape"):
        score_silhouette(a, np.zeros((5, 4), bool), a)
    with pytest.raises(ValueError, match="one shape"):
        score_silhouette(np.zeros(5, bool), np.zeros(5, bool), np.zeros(5, bool))


def test_scores_are_frozen():
    ref, ties = _square(10.3, 10.3, 40.0, shape=(64, 64))
    s = score_silhouette(ref, ref, ties)
    assert isinstance(s, SilhouetteScores)
    with pytest.raises(AttributeError):
        s.iou = 0.0


def test_the_tie_distance_grows_with_the_frame_scale_past_4096_px():
    from wirecheck.oracles import tolerances

    # up to 4,096 px the float32 rounding (4 eps32 scale) is within the 2^-9 FILL_TIE_PX assumes
    assert tolerances.fill_tie_bound(0.0) == tolerances.fill_tie_bound(4096.0) == tolerances.FILL_TIE_PX
    # at 2^16 px: 4 x 2^-23 x 2^16 = 2^-5 of rounding, plus the 2^-9 snap, times sqrt 2
    assert tolerances.fill_tie_bound(2.0**16) == pytest.approx(math.sqrt(2) * (2**-9 + 2**-5), rel=1e-15)
