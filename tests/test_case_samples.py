"""A case's samples kept as one array per field (oracles/judge/case_samples.py) against per-frame lists.

The reference is the definition: each frame's arrays in a list, a halving
``v[::2]`` of every frame's arrays, the pooled field their concatenation in
frame order. Frames of 0, 1, 2 and odd numbers of samples, halvings between
any two frames, must give the same arrays to the bit.
"""

from __future__ import annotations

import numpy as np
import pytest
from wirecheck.oracles.judge.case_samples import CaseSamples


def _frame(rng, n):
    return {
        "offset": rng.normal(size=n),
        "normal": rng.normal(size=(n, 2)),
        "segment": rng.integers(0, 9, n),
        "windows": n + 3,
        "found": n,
    }


@pytest.mark.parametrize("seed", range(6))
def test_halvings_and_pooling_match_per_frame_lists(seed):
    rng = np.random.default_rng(seed)
    store, ref = CaseSamples(), []
    for step in range(40):
        frame = _frame(rng, int(rng.choice([0, 1, 2, 3, 7, 50, 51])))
        store.add(frame)
        ref.append(frame)
        if rng.random() < 0.3:
            store.halve()
            ref = [{k: (v[::2] if isinstance(v, np.ndarray) else v) for k, v in x.items()} for x in ref]
        assert len(store) == len(ref) and store.kept == sum(len(x["offset"]) for x in ref)
        for key in ("offset", "normal", "segment"):
            got, want = store.pooled(key), np.concatenate([x[key] for x in ref])
            assert got.dtype == want.dtype and got.shape == want.shape and np.array_equal(got, want)
    # the counts are summed over every frame added, never thinned
    assert store.counts == {"windows": sum(x["windows"] for x in ref), "found": sum(x["found"] for x in ref)}


def test_no_frame_pools_to_nothing():
    store = CaseSamples()
    store.halve()
    assert len(store) == 0 and store.kept == 0 and store.pooled("offset").shape == (0,)
