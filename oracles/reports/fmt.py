"""Numbers printed with enough digits to tell them from the value they are compared with.

``implied_aspect=1.333`` for 1.33264 on a 4:3 image reads as "no fault", and
"error 1e-06 px > 1e-06 px" as no excess. :func:`distinct` adds significant
digits until the printed value differs from the printed reference. Reports
(report.json) keep full precision; this is for text only.
"""

from __future__ import annotations

import math


def distinct(value: float, reference: float | None = None, digits: int = 4) -> str:
    """``value`` with at least ``digits`` significant digits, and more until it prints unlike ``reference``.

    >>> distinct(1.33264, 4 / 3)
    '1.3326'
    >>> distinct(1.3333334, 4 / 3)
    '1.3333334'
    >>> distinct(1.0000004e-06, 1e-06)
    '1.0000004e-06'
    >>> distinct(2.5)
    '2.5'
    """
    value = float(value)
    if reference is None or not math.isfinite(value) or value == reference:
        return f"{value:.{digits}g}"
    for n in range(digits, 18):
        text = f"{value:.{n}g}"
        if text != f"{float(reference):.{n}g}":
            return text
    return repr(value)


def short_repr(value) -> str:
    """``repr(value)`` on one line, at most 80 characters (an argument named in an error message)."""
    text = " ".join(repr(value).split())
    return text if len(text) <= 80 else text[:77] + "..."
