"""A line's profile across it: the window a sample is taken in and the offset pooled from a case's samples
(:func:`pooled_offset`). The coverage a sample needs and the samples a case needs are
:attr:`oracles.tolerances.NamingThresholds.profile_min_mass` and ``profile_min_samples``.

Its own module because the line style (oracles.judge.line_style), the even-width lean
(oracles.judge.even_lean) and the free ends (oracles.judge.free_ends) all measure with them.
"""

from __future__ import annotations

import numpy as np

from ..tolerances import NAMING

#: Half the window across a line in which its centroid is taken (px): a 3-px line's half width
#: (1.5) plus an antialiased fringe (1) plus a pixel of slack for a half-pixel offset.
PROFILE_RADIUS_PX = 3


#: A sample is dropped when another segment, or its own segment's end, is this close (px):
#: the window plus half a pixel, so no other line's pixel enters it.
GUARD_PX = PROFILE_RADIUS_PX + 1.5


def pooled_offset(normal: np.ndarray, offset: np.ndarray):
    """``(d (2,), determined (2,) bool)``: the least-squares ``d`` with ``n . d = offset``.

    A component the normals do not constrain (every line parallel to it, e.g.
    only horizontal lines say nothing of ``dx``) is 0 and not determined; so
    is each with fewer than ``NAMING.profile_min_samples`` samples
    (oracles.tolerances, read when called).
    """
    if len(offset) < NAMING.profile_min_samples:
        return np.zeros(2), np.zeros(2, bool)
    nn = normal.T @ normal
    determined = np.diag(nn) >= 0.05 * len(offset)  # >= 5 % of the samples' weight on that axis
    d = np.zeros(2)
    idx = np.flatnonzero(determined)
    if len(idx):
        sol, *_ = np.linalg.lstsq(normal[:, idx], offset, rcond=None)
        d[idx] = sol
    return d, determined
