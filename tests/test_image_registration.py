"""oracles.diagnosis.registration's correspondences, against a point-by-point reference.

The ICP fit pairs every candidate pixel with the nearest point of its own
frame's oracle lines, and every oracle sample with its frame's nearest drawn
pixel. The pairing is stacked over frames (frames padded to the most
segments); here each pair is recomputed by brute force, frame by frame, on
frames with different numbers of segments, so a pad or another frame's line
taking part would show.
"""

from __future__ import annotations

import numpy as np
import pytest
from wirecheck.core.camera import Camera
from wirecheck.oracles.diagnosis import registration
from wirecheck.oracles.diagnosis.registration import PERMUTATIONS, Registration, frame_samples

W, H = 64, 48


def _camera():
    return Camera(
        position=(0.0, 0.0, 5.0), forward=(0.0, 0.0, -1.0), up=(0.0, 1.0, 0.0), fov_y_deg=60.0, width=W, height=H
    )


def _case(rng):
    """Three frames: 1, 4 and 7 random segments, and random drawn pixels (frame 1 draws none).

    Frame 0 also has a segment left of the image: its samples map outside it, so the reverse
    pairs of a later frame start at another place among the samples inside than among all samples.
    """
    segs, images = [], []
    for k, n_px in ((1, 40), (4, 0), (7, 90)):
        segs.append(rng.uniform([-5, -5], [W + 5, H + 5], size=(k, 2, 2)))
        if k == 1:
            segs[-1] = np.concatenate([segs[-1], [[[-20.0, 5.0], [-8.0, 30.0]]]])
        img = np.zeros((H, W), bool)
        img.ravel()[rng.choice(W * H, n_px, replace=False)] = True
        images.append(img)
    return images, segs


def _point_to_segments(q, seg):
    """Nearest point of ``seg (K, 2, 2)`` to ``q (2,)``, by a loop; ties to the first segment."""
    best = (np.inf, None, None)
    for k, (a, b) in enumerate(seg):
        ab = b - a
        t = min(max(float((q - a) @ ab) / max(float(ab @ ab), 1e-300), 0.0), 1.0)
        foot = a + t * ab
        d = float(np.hypot(*(foot - q)))
        if d < best[0]:
            best = (d, foot, k)
    return best


@pytest.mark.parametrize("stack_limit", [registration.STACK_LIMIT, 0], ids=["stacked", "frame_by_frame"])
@pytest.mark.parametrize("names", [(), ("axis_swap", "mirror_vertical")])
def test_pairs_are_each_frames_own_nearest(monkeypatch, stack_limit, names):
    monkeypatch.setattr(registration, "STACK_LIMIT", stack_limit)
    rng = np.random.default_rng(7)
    cam = _camera()
    images, segs = _case(rng)
    frames = frame_samples(images, segs, cam)
    centre = np.array(cam.principal_point)
    reg = Registration(frames, W, H, centre)
    p = PERMUTATIONS[names]
    a, b = np.diag([1.1, 0.9]), np.array([0.7, -0.4])
    u, c, dist, tangent, n_fwd, n_rev = reg.pairs(p, a, b)

    # forward: candidate pixel c -> o = P^-1 a^-1 (c - b), nearest point of ITS frame's lines, u = P o
    back = np.linalg.inv(a @ p)
    want_u, want_c, want_t = [], [], []
    for f in frames:
        if not (len(f.cand) and len(f.seg_a)):
            continue
        seg = np.stack([f.seg_a, f.seg_b], axis=1)
        for cpx in f.cand:
            _d, foot, k = _point_to_segments(back @ (cpx - b), seg)
            want_u.append(p @ foot)
            want_c.append(cpx)
            want_t.append(p @ f.seg_tangents[k])
    assert n_fwd == len(want_u) == 130  # frames 0 and 2; frame 1 drew nothing
    # float64 arithmetic on coordinates below ~100 px: 1e-9 px is ~1e5 ulps of slack, far below a pixel
    np.testing.assert_allclose(u[:n_fwd], want_u, atol=1e-9)
    np.testing.assert_array_equal(c[:n_fwd], want_c)
    np.testing.assert_allclose(tangent[:n_fwd], want_t, atol=1e-12)
    np.testing.assert_allclose(dist[:n_fwd], np.hypot(*(np.array(want_u) @ a.T + b - want_c).T), atol=1e-9)

    # reverse: each oracle sample of a frame that drew pixels, mapped into the image, to its
    # frame's nearest drawn pixel (distance by brute force; EDT may pick another of equal distance)
    want_d = []
    for f, img in zip(frames, images):
        if not (len(f.samples) and len(f.cand)):
            continue
        drawn = np.argwhere(img)[:, ::-1] - centre  # (col, row) - centre
        for s in f.samples:
            t = a @ (p @ s) + b
            col, row = np.round(t + centre)
            if 0 <= col < W and 0 <= row < H:
                want_d.append(np.min(np.hypot(*(np.array([col, row]) - centre - drawn).T)))
    assert n_rev == len(want_d) > 0
    # the pair's distance is from the unrounded sample: within half a pixel's diagonal of the
    # rounded position's nearest pixel distance
    got_rounded = np.hypot(*(np.round(u[n_fwd:] @ a.T + b + centre) - centre - c[n_fwd:]).T)
    np.testing.assert_allclose(got_rounded, want_d, atol=1e-9)
    assert np.all(np.abs(dist[n_fwd:] - got_rounded) <= np.sqrt(0.5) + 1e-9)


@pytest.mark.parametrize("where", ["corner", "middle", "two_clusters", "everywhere"])
def test_the_nearest_pixel_map_is_exact_within_the_pairs_reach(where):
    # brute force over every pixel of a 120 x 90 image: the distance to the map's pixel equals the
    # distance to the nearest drawn pixel wherever that is within the cap plus a rounded sample's
    # 0.71 px (pairs the fit can keep); farther away, the map's pixel is farther than that too
    # (the pair is dropped and the cost capped, whichever pixel it is)
    from wirecheck.oracles.diagnosis.registration import PAIR_CAP_PX, _nearest_pixel_map

    rng = np.random.default_rng(3)
    img = np.zeros((90, 120), bool)
    boxes = {
        "corner": [(0, 12, 0, 15)],
        "middle": [(40, 50, 50, 64)],
        "two_clusters": [(5, 12, 8, 20), (70, 85, 90, 118)],
        "everywhere": [(0, 90, 0, 120)],
    }[where]
    density = 0.02 if where == "everywhere" else 0.2  # ~200 drawn pixels everywhere: a small brute force
    for r0, r1, c0, c1 in boxes:
        img[r0:r1, c0:c1] = rng.random((r1 - r0, c1 - c0)) < density
    rr, cc = np.nonzero(img)
    near = _nearest_pixel_map(img, rr, cc)
    qr, qc = np.mgrid[0:90, 0:120]
    q = np.stack([qr.ravel(), qc.ravel()], axis=1).astype(float)
    drawn = np.stack([rr, cc], axis=1).astype(float)
    d_true = np.min(np.hypot(q[:, None, 0] - drawn[None, :, 0], q[:, None, 1] - drawn[None, :, 1]), axis=1)
    d_map = np.hypot(q[:, 0] - near // 120, q[:, 1] - near % 120)
    assert img.ravel()[near].all()  # always a drawn pixel
    reach = PAIR_CAP_PX + np.sqrt(0.5)
    inside = d_true <= reach
    assert inside.sum() > 300  # both parts are checked on many pixels
    assert (~inside).sum() > 500 or where == "everywhere"  # (everywhere: the box is the whole image)
    np.testing.assert_array_equal(d_map[inside], d_true[inside])
    assert np.all(d_map[~inside] > reach)


def test_oracle_samples_reach_half_the_image_beyond_each_side():
    # oracle samples are taken along the lines within the image grown by half its size per side
    # (a scale fault of 1/2 brings those parts into the picture): a segment crossing far past every side
    # is sampled exactly across the grown image, [-0.5 - W/2, W - 0.5 + W/2] (clip_to_image's pixel-edge
    # bounds, shifted), at SAMPLE_STEP_PX = 0.5 px: 2 W / 0.5 steps, 4 W + 1 samples; likewise for H
    horizontal = np.array([[[-10.0 * W, 20.25], [11.0 * W, 20.25]]])
    pts, tangents = registration._samples(horizontal, W, H)
    assert len(pts) == 4 * W + 1
    assert pts[0] == pytest.approx([-0.5 - W / 2, 20.25]) and pts[-1] == pytest.approx([W - 0.5 + W / 2, 20.25])
    assert np.allclose(np.diff(pts[:, 0]), 0.5) and np.allclose(tangents, [1.0, 0.0])
    vertical = np.array([[[30.25, 9.0 * H], [30.25, -12.0 * H]]])  # drawn upward: samples run from the start
    pts, tangents = registration._samples(vertical, W, H)
    assert len(pts) == 4 * H + 1
    assert pts[0] == pytest.approx([30.25, H - 0.5 + H / 2]) and pts[-1] == pytest.approx([30.25, -0.5 - H / 2])
    assert np.allclose(tangents, [0.0, -1.0])
