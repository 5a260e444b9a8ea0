"""The radius at which a renderer's frames are held to the edge-pixel F1, by the width of the lines read.

F1@1px counts a drawn pixel as right when a pixel of the other image lies
within 1 px (Chebyshev): right for 1-px lines, whose pixels a correct
renderer of another rule, or an end snapped to a pixel centre, puts at most
one pixel from the oracle's. A line ``n`` pixels across (the width the style
read measured, :class:`oracles.judge.line_style.CaseStyle`, rounded: the pixels a
binary line draws across it) reaches ``(n - 1) / 2`` pixels past a 1-px
line on each side, a whole pixel more on one side when ``n`` is even (an even
width leans one way: :func:`radius_px` rounds up). Its correct pixels then lie
within ``1 + ceil((n - 1) / 2)`` px of the oracle's 1-px line: the 1 px that
F1@1px already allows, plus that reach. So a frame read ``wide`` or
``antialiased`` is held to F1 at that radius; an ``aliased`` frame (1 px) keeps
F1@1px exactly.

What the wider radius cannot hide: a missing line leaves the oracle's pixels
with no candidate pixel at any radius (recall falls by its share of the
pixels), and a line moved by a pixel or more is measured from its centres
(``pixel_offset``: oracles.judge.decide.judge_style, oracles.judge.name_faults), not from F1.

Each frame's F1 is computed at every radius up to :attr:`oracles.tolerances.NamingThresholds.max_radius_px`
(only where F1@1px is below 1: at 1 every pixel is within any wider radius),
since the style is read from the whole case, after its frames.
"""

from __future__ import annotations

import math

from ..tolerances import NAMING
from .evidence import Radius
from .metrics import pixel_scores


#: The widest radius computed: oracles.tolerances.NAMING.max_radius_px (3: lines up to 5 px across; its reason there).
#: The radii computed per frame besides F1@1px.
def radii() -> tuple[int, ...]:
    """The radii above 1 px each frame's F1 is computed at: 2 .. NAMING.max_radius_px (read when called)."""
    return tuple(range(2, NAMING.max_radius_px + 1))


def radius_px(read: dict) -> int:
    """The F1 radius (px) for a case's style read (``CaseStyle.classify()``: ``style``, ``width_px``).

    ``aliased``: 1 (F1@1px, as for every 1-px line). ``wide`` or ``antialiased``:
    ``1 + ceil((n - 1) / 2)`` with ``n = round(width_px)`` at least 1, and at least ``band_px`` where the
    read has it (lines read wide by their pixel count, not their median width: 2; module
    docstring), at most :attr:`oracles.tolerances.NamingThresholds.max_radius_px`.
    """
    if read.get("style") == "aliased":
        return 1
    n = max(int(math.floor(float(read.get("width_px") or 0.0) + 0.5)), int(read.get("band_px") or 1), 1)
    return min(1 + math.ceil((n - 1) / 2), NAMING.max_radius_px)


def frame_scores(fp, scores: dict) -> dict:
    """``{radius: F1}`` of one frame for each of :func:`radii` (``fp``: its oracles.judge.frame_pixels.FramePixels,
    ``scores``: its oracles.judge.metrics.pixel_scores at 0 and 1 px)."""
    if scores["f1_1px"] == 1.0:  # every pixel within 1 px: within any wider radius
        return {r: 1.0 for r in radii()}
    wide = pixel_scores(None, None, tols=radii(), pixels=fp)
    return {r: wide[f"f1_{r}px"] for r in radii()}


def radius_read(read: dict, per_frame: list, frames: list, f1_1px: float, worst_frame) -> Radius:
    """The case's F1 radius and its worst frame's F1 there, which oracles.judge.decide holds to ``min_f1_1px``.

    ``read``: the case's style (``CaseStyle.classify()``); ``per_frame``: each frame's :func:`frame_scores`,
    ``frames`` their numbers. At a radius of 1 the F1 is F1@1px itself (``f1_1px``, its ``worst_frame``).
    """
    radius = radius_px(read)
    if radius == 1 or not per_frame:
        return Radius(radius, f1_1px, worst_frame)
    worst = min(range(len(per_frame)), key=lambda i: per_frame[i][radius])  # the first of the lowest
    return Radius(radius, float(per_frame[worst][radius]), frames[worst])
