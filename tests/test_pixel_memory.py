"""The pixel metrics' memory is bounded by the image, not by the drawn length of the edges (issue 37).

A soup of long segments pairs every pixel with hundreds of segments: the
pairing (oracles.judge.segment_pixels) holding every pair at once grew with
the edges' total length (6 GiB for one frame of 50,000 random triangles).
"""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest
from wirecheck.oracles.judge import metrics, segment_pixels

W, H = 200, 150  # the image
EDGES = 3000  # segments across it: ~100 px each, 3,000 x ~100 x ~5 = 1.5M pixel pairs


def _soup(seed: int = 37):
    rng = np.random.default_rng(seed)
    return rng.uniform(0, [W, H], (EDGES, 2)), rng.uniform(0, [W, H], (EDGES, 2))


def _images():
    """Every pixel drawn by both, but for two sparse grids of one-sided pixels (the dense path: every
    drawn pixel given its nearest segment)."""
    cand = np.ones((H, W), bool)
    orac = cand.copy()
    cand[::17, ::13] = False
    orac[5::19, 3::11] = False
    return cand, orac


def _frame_metrics(p0, p1, cand, orac):
    fp = metrics.FramePixels(cand, orac)
    scores = metrics.pixel_scores(None, None, pixels=fp)
    batch = metrics.LineBatch()
    batch.add(1, fp, p0, p1)
    return scores, batch.flush()[0][1]


def test_a_soup_of_long_edges_is_judged_in_memory_bounded_by_the_image(monkeypatch):
    chunk = 1 << 16
    monkeypatch.setattr(segment_pixels, "CHUNK_PAIRS", chunk)
    p0, p1 = _soup()
    cand, orac = _images()
    tracemalloc.start()
    try:
        _frame_metrics(p0, p1, cand, orac)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    # The bound, from what the pairing may hold at once:
    # - per pixel of the image, ~200 B: the drawn pixels' flat indices in FramePixels and in the
    #   stacked copies (candidate, oracle, drawn, one-sided: 5 x 8 B), their x and y (16 B), the
    #   rank table (int32 and its cumsum: 8 B), the nearest distance and owner (16 B), the owners'
    #   rows (edge, pixel, major: 24 B) and the temporaries of each step (~2x);
    # - per segment, ~400 B: ends, clipped ends, direction and the gathered columns (~15 float64
    #   pairs and scalars) and the clipping's temporaries;
    # - per pair of a chunk, ~250 B: _near's ~16 live float64 / int64 arrays (128 B) and the
    #   spans of a run of as many rows (~15 int64 / float64 arrays: 120 B).
    # Holding every pair at once (the old pairing) took 134 MB here, 5x over.
    bound = 200 * W * H + 400 * EDGES + 250 * chunk
    assert peak <= bound, f"pixel metrics peaked at {peak / 1e6:.1f} MB: expected <= {bound / 1e6:.1f} MB"


def test_chunked_pairing_gives_the_same_scores(monkeypatch):
    # a chunk of 1,000 pairs splits the pairing ~1,500 ways; the scores are those of one chunk
    p0, p1 = _soup(5)
    cand, orac = _images()
    whole = _frame_metrics(p0, p1, cand, orac)
    monkeypatch.setattr(segment_pixels, "CHUNK_PAIRS", 1000)
    assert _frame_metrics(p0, p1, cand, orac) == whole


@pytest.mark.parametrize(
    "limit, weights, cuts",
    [
        (5, [2, 2, 2, 2], [(0, 2), (2, 4)]),
        (5, [9, 1, 1], [(0, 1), (1, 3)]),  # an item over the limit goes alone
        (5, [], []),
        (3, [1, 1, 1, 1, 1, 1, 1], [(0, 3), (3, 6), (6, 7)]),
    ],
)
def test_cuts(limit, weights, cuts):
    assert segment_pixels._cuts(np.array(weights, np.int64), limit) == cuts
