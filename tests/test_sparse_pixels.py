"""The drawn pixels found eight bytes at a time (oracles/judge/sparse_pixels.py) against np.flatnonzero.

The reference is the definition, ``np.flatnonzero(image.reshape(-1) >= level)``;
images of every density (empty, a few pixels, lines, noise, full), sizes that
are not a multiple of 8 bytes, bool and uint8, a pixel in the last byte.
"""

from __future__ import annotations

import numpy as np
import pytest

from wirecheck.oracles.judge.sparse_pixels import flat_drawn


@pytest.mark.parametrize("shape", [(480, 640), (7, 13), (1, 1), (3, 5), (0, 4)])
@pytest.mark.parametrize("density", [0.0, 0.001, 0.05, 0.5, 1.0])
@pytest.mark.parametrize("level", [1, 128, 255])
def test_same_indices_as_flatnonzero(shape, density, level):
    rng = np.random.default_rng(hash((shape, density, level)) % 2 ** 32)
    image = np.where(rng.random(shape) < density, rng.integers(0, 256, shape), 0).astype(np.uint8)
    if image.size:
        image.reshape(-1)[-1] = 200                        # a pixel in the last byte (past the last whole word)
    want = np.flatnonzero(image.reshape(-1) >= level)
    got = flat_drawn(image, level)
    assert got.dtype == want.dtype and np.array_equal(got, want)
    as_bool = image >= 128
    assert np.array_equal(flat_drawn(as_bool), np.flatnonzero(as_bool))


def test_a_strided_view_is_read_as_its_pixels():
    image = np.zeros((6, 10), np.uint8)
    image[2, 3] = image[5, 9] = 255
    view = image[:, ::-1]                                  # not contiguous: read as the view's pixels
    assert np.array_equal(flat_drawn(view, 128), np.flatnonzero(view.reshape(-1) >= 128))
