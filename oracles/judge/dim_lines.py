"""Frames whose lines are all too dim to count as drawn: said so, not read as a camera looking backward.

A frame's pixel is drawn when its coverage (luminance x alpha / 255) is at
least 128 (oracles.candidates.png_frame). A renderer that draws its lines in a
grey colour or at half alpha (level 127 or less) draws no pixel by that rule:
its case fails on nothing drawn, and the image diagnosis, which sees only the
drawn pixels, names that ``depth_flip`` ("a camera looking backward sees
nothing here either"), which sends the user to the camera. The line style
reader (oracles.judge.line_style) has the level the lines were drawn at; when
every frame of a case drew nothing by the rule but its lines have a level,
the case's fault is ``unexplained`` with that level and a hint that says what
to change (the colour), instead of the image diagnosis' guess.
"""

from __future__ import annotations

from .. import faults as catalogue

#: The coverage from which a pixel counts as drawn (oracles.candidates.png_frame.read_png).
DRAWN_LEVEL = 128


def name_dim_lines(faults: list, line_style: dict | None, per_frame: list) -> list:
    """``faults``, or the dim-lines fault when no frame drew a pixel by the rule and the lines' level
    (``line_style["level"]``, of the pixels the frames hold) is above 0 and under :data:`DRAWN_LEVEL`."""
    level = int((line_style or {}).get("level") or 0)
    if not 0 < level < DRAWN_LEVEL or any(f.get("candidate_pixels") for f in per_frame):
        return faults
    return [{"name": "unexplained", "line_level": level,
             "hint": catalogue.hint_text("unexplained", "dim_lines", level=level, drawn=DRAWN_LEVEL)}]
