"""oracles.judge.shaded_frames.ShadedFrames: core's shaded frames measured in the case loop, on hand-made buffers.

An 8x8 orthographic camera (near 0.1, far 100): one 24-bit depth step is (f - n) / (2^24 - 1) ~ 6e-6,
so the bound on a flat surface at depth 5 is at least 4 steps ~ 2.4e-5 (oracles.tolerances.DEPTH_STEPS);
an error of 1e-9 is within it (0 < ratio < 1). pyrender's drawing is a 4x4 block of one triangle
(id 0, face 0) at depth 5; the candidate covers all of it or its top three rows.
"""

from types import SimpleNamespace

import numpy as np
import pytest
from wirecheck.oracles.judge.shaded_frames import SHADED_FRAME_KEYS, ShadedFrames

CAM = SimpleNamespace(width=8, height=8, near=0.1, far=100.0, projection="orthographic")
BLOCK = np.s_[2:6, 2:6]


def oracle():
    covered = np.zeros((8, 8), bool)
    covered[BLOCK] = True
    depth = np.where(covered, 5.0, 0.0)
    ids = np.where(covered, 0, -1)
    return covered, depth, ids


def candidate(rows: int = 4, error: float = 0.0):
    """The candidate's depth buffer: the block's first ``rows`` rows at depth 5 + ``error``, inf elsewhere."""
    depth = np.full((8, 8), np.inf)
    depth[2 : 2 + rows, 2:6] = 5.0 + error
    return depth


def faces(depth):
    return np.where(np.isfinite(depth), 0, -1)


def frames(kept=None, want_images=True):
    shaded = ShadedFrames(CAM, np.array([[0, 1, 2]]), np.array([0]), want_images, kept)
    recs = []
    for k, (rows, error) in zip((1, 3, 5, 7, 9), ((4, 0.0), (3, 0.0), (3, 1e-9), (3, 1e-9), (4, 0.0))):
        rec = {"frame": k}
        depth = candidate(rows, error)
        shaded.add(k, depth, faces(depth), oracle(), rec)
        recs.append(rec)
    return shaded, recs


def test_each_frame_is_scored_and_the_worst_is_the_lowest_iou_then_the_largest_depth_error():
    kept = []
    shaded, recs = frames(kept)
    assert [set(r) for r in recs] == [{"frame", *SHADED_FRAME_KEYS}] * 5
    # 12 of the 16 block pixels: IoU 12 / 16; the union is the block's 16 either way
    assert [r["silhouette_iou"] for r in recs] == [1.0, 0.75, 0.75, 0.75, 1.0]
    assert shaded.drawn_px == 5 * 16
    assert recs[1]["depth_error_ratio"] == 0.0 and 0.0 < recs[2]["depth_error_ratio"] < 1.0
    # frames 3, 5, 7 share IoU 0.75; 5 and 7 have the larger depth error: frame 5, the first of them
    assert shaded.worst[1] == 5 and [k for k, _ in shaded.scores] == [1, 3, 5, 7, 9]
    images = shaded.worst_images()
    assert images["frame"] == 5
    assert np.array_equal(images["candidate"], np.isfinite(candidate(3))) and np.array_equal(
        images["oracle"], oracle()[0]
    )
    assert [k for k, _, _ in kept] == [1, 3, 5, 7, 9]
    assert np.array_equal(kept[1][1].image(), np.isfinite(candidate(3))) and np.array_equal(
        kept[1][2].image(), oracle()[0]
    )


def test_no_images_kept_unless_asked():
    shaded, _ = frames(want_images=False)
    assert shaded.worst is None and shaded.worst_images() is None
    assert [k for k, _ in shaded.scores] == [1, 3, 5, 7, 9]  # still scored


def test_a_scene_without_faces_is_drawn_not_scored():
    kept = []
    shaded = ShadedFrames(CAM, kept=kept)
    rec = {"frame": 1}
    shaded.add(1, candidate(), None, None, rec)
    assert rec == {"frame": 1} and shaded.scores == [] and shaded.drawn_px == 0 and shaded.worst is None
    assert not kept[0][2].image().any() and kept[0][1].image().sum() == 16  # pyrender drew nothing


def test_a_face_shown_where_the_oracle_shows_another_is_counted():
    # the candidate shows face 0 on the block's top row where the oracle, given triangle id 1 there, shows
    # face 1 (tri_owner [0, 1]): 4 pixels on the boundary between the two faces' regions (face_disagreements)
    shaded = ShadedFrames(CAM, np.array([[0, 1, 2], [2, 3, 0]]), np.array([0, 1]), True)
    covered, depth, ids = oracle()
    ids = ids.copy()
    ids[2, 2:6] = 1
    rec = {"frame": 1}
    cand = candidate()
    shaded.add(1, cand, faces(cand), (covered, depth, ids), rec)
    assert rec["face_disagreements"] == 4
    assert rec["silhouette_iou"] == pytest.approx(1.0)


def test_a_wrong_face_everywhere_is_a_disagreement_inside():
    # the candidate shows face 1 over the whole block, the oracle face 0: 16 disagreements, and none is on a
    # boundary between the two faces (neither image shows the other's face anywhere): 16 inside
    shaded = ShadedFrames(CAM, np.array([[0, 1, 2], [2, 3, 0]]), np.array([0, 1]), True)
    rec = {"frame": 1}
    cand = candidate()
    shaded.add(1, cand, np.where(np.isfinite(cand), 1, -1), oracle(), rec)
    assert (rec["face_disagreements"], rec["face_disagreements_inside"]) == (16, 16)
