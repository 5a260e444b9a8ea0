"""Which pixels of an antialiased frame are drawn: the 128 rule, plus the ridge across each thin line.

A frame's pixels are drawn where the coverage is at least half (grey >= 128,
docs/frames.md). A 1-px antialiased line exactly between two pixels covers
each by half: a renderer that rounds 127.5 down writes 127 | 127 and the line
vanishes under that rule; a 0.5-px line peaks at coverage 0.5 (127) wherever
it lies. Yet the line is there, and its centre is measured exactly from the
grey levels (oracles.judge.line_style.measure).

For a frame of grey levels (antialiased: oracles.judge.line_style reads it), a
pixel is also drawn when it is a *ridge* across a line (its coverage at least
that of both neighbours in its row and more than one of them, or the same in
its column: not along a line, where the coverage stays level) holding at least
:func:`ridge_min` coverage. A line at most 1 px wide splits its coverage
across a row or column between at most two pixels, so the larger of them
holds at least half of what the line puts there, and that is at least half
its width (more on a slant: a column crosses it over ``width / |cos|``); so a
line from ``NAMING.ridge_min_width_px`` (oracles.tolerances) on has a ridge pixel on every row or
column it crosses. A fringe pixel beside a brighter one is no ridge, so
the rule adds no pixel off the line's centre, and binary frames are left to
the 128 rule (GL's pixel rule judges them).
"""

from __future__ import annotations

import numpy as np

from ..tolerances import NAMING


def ridge_min() -> int:
    """A ridge pixel's least grey level: half of ``NAMING.ridge_min_width_px``'s coverage (0.25 of 255 =
    63.75 for 0.5 px), rounded down so that a renderer that rounds 63.75 down still draws it."""
    return int(255 * NAMING.ridge_min_width_px / 2)


def drawn(grey: np.ndarray) -> np.ndarray:
    """``(H, W)`` bool: the pixels of the antialiased frame ``grey`` (uint8) drawn (module docstring)."""
    g = np.asarray(grey).astype(np.int16)
    pad = np.pad(g, 1)  # outside the image: background
    ridge = np.zeros(g.shape, bool)
    for a, b in ((pad[1:-1, :-2], pad[1:-1, 2:]), (pad[:-2, 1:-1], pad[2:, 1:-1])):  # the row, the column
        ridge |= (g >= a) & (g >= b) & ((g > a) | (g > b))
    return (g >= 128) | ((g >= ridge_min()) & ridge)
