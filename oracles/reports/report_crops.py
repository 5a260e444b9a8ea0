"""Enlarged crops of report.html's worst frames: where candidate and oracle disagree most, 6x.

At 1:1 a sub-pixel fault is invisible: a line drawn half a pixel off leaves red/blue pairs one
pixel wide that a browser's scaling blends into white. The crop is the ``CROP_PX`` square with
the most disagreeing pixels (candidate-only or oracle-only, found with a summed-area table),
drawn as the diff image (white both, red candidate only, blue oracle only) and enlarged by
``SCALE`` with nearest-neighbour repetition, so every pixel is a visible block.
"""

from __future__ import annotations

import numpy as np

from ..judge.metrics import diff_image

#: Side of the cropped square in image pixels, and the enlargement (docs use 6x).
CROP_PX = 40
SCALE = 6


def worst_window(candidate: np.ndarray, oracle: np.ndarray, size: int = CROP_PX) -> tuple[int, int, int]:
    """``(x0, y0, count)``: the top-left of the ``size`` square (clamped to the image) holding the most
    pixels drawn by one side only, and that count (0: the frames agree; the window is the top left)."""
    disagree = np.asarray(candidate, bool) ^ np.asarray(oracle, bool)
    h, w = disagree.shape
    sy, sx = min(size, h), min(size, w)
    sat = np.zeros((h + 1, w + 1), np.int64)
    sat[1:, 1:] = disagree.cumsum(0).cumsum(1)
    counts = sat[sy:, sx:] - sat[:-sy, sx:] - sat[sy:, :-sx] + sat[:-sy, :-sx]   # (h-sy+1, w-sx+1)
    y0, x0 = np.unravel_index(int(np.argmax(counts)), counts.shape)             # first maximum: deterministic
    return int(x0), int(y0), int(counts[y0, x0])


def crop_image(candidate: np.ndarray, oracle: np.ndarray, size: int = CROP_PX,
               scale: int = SCALE) -> tuple[np.ndarray, tuple[int, int, int]]:
    """The enlarged diff crop, ``(size*scale, size*scale, 3)`` uint8, and ``(x0, y0, count)`` of its window."""
    x0, y0, count = worst_window(candidate, oracle, size)
    diff = diff_image(candidate, oracle)[y0:y0 + size, x0:x0 + size]
    return np.repeat(np.repeat(diff, scale, axis=0), scale, axis=1), (x0, y0, count)


def crop_caption(window: tuple[int, int, int], size: int = CROP_PX, scale: int = SCALE) -> str:
    x0, y0, count = window
    return (f"diff, {scale}x: x {x0}..{x0 + size - 1}, y {y0}..{y0 + size - 1} "
            f"({count} pixel{'s' if count != 1 else ''} drawn by one side only)")
