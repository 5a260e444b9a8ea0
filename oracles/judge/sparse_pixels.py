"""The drawn pixels of a sparse image, found without a pass over every pixel.

A frame of lines is mostly background: a 640 x 480 frame of a cube has about
2,000 drawn pixels of 307,200. ``np.flatnonzero(image >= 128)`` makes a bool
image and scans all of it; here the image's bytes are read eight at a time
(as 64-bit words, a scan an eighth as long), and only the bytes of the words
that are not zero are looked at. The result is the same array: ascending flat
indices ``y W + x``.
"""

from __future__ import annotations

import numpy as np


def flat_drawn(image: np.ndarray, level: int = 1) -> np.ndarray:
    """Ascending flat indices of the pixels of ``image`` that are ``>= level`` (``level`` >= 1), as
    ``np.flatnonzero(image.reshape(-1) >= level)`` (a bool image: its True pixels).

    ``image``: uint8 or bool, any shape. A pixel ``>= level >= 1`` is not zero,
    so it lies in a 64-bit word of the image's bytes that is not zero.
    """
    flat = np.ascontiguousarray(image).reshape(-1)
    if flat.dtype == bool:
        flat = flat.view(np.uint8)
    elif flat.dtype != np.uint8:
        raise TypeError(f"image of {flat.dtype}: expected uint8 or bool")
    n = len(flat) - len(flat) % 8
    words = flat[:n].view(np.uint64)
    hit = np.flatnonzero(words != 0)                            # the 8-byte words that hold a pixel not 0
    rows, cols = np.nonzero((words[hit].view(np.uint8) >= level).reshape(-1, 8))
    idx = hit[rows] * 8 + cols
    if n < len(flat):                                           # the last bytes, past the last whole word
        idx = np.concatenate([idx, n + np.flatnonzero(flat[n:] >= level)])
    return idx
