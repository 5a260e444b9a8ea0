"""Rasterizer mutants for the line gate's tests and its measurement (benchmarks/measure_line_gate.py).

Each has the signature of ``core.projector.raster._line_pixels`` and is patched in its
place (in-process): ``drop_last`` is biased, ``random_ends`` is not.
"""

import numpy as np
from wirecheck.core.projector import raster

_LINE_PIXELS = raster._line_pixels  # the real one, kept before any patch


def _per_segment(p0, p1, w, h, edit):
    """core's exact raster, segment by segment, each segment's pixels (in travel order) passed through ``edit``."""
    rs, cs = [np.zeros(0, np.intp)], [np.zeros(0, np.intp)]
    for m in range(len(p0)):
        rr, cc = _LINE_PIXELS(p0[m : m + 1], p1[m : m + 1], w, h)
        d = p1[m] - p0[m]
        forward = (d[0] if abs(d[0]) > abs(d[1]) else d[1]) >= 0  # pixels come in increasing major order
        if not forward:
            rr, cc = rr[::-1], cc[::-1]
        rr, cc = edit(m, p0[m], rr, cc)
        rs.append(rr)
        cs.append(cc)
    return np.concatenate(rs).astype(np.intp), np.concatenate(cs).astype(np.intp)


def drop_last(p0, p1, w, h):
    """The mutant of issue 16: every line loses its last pixel (in the direction of travel)."""
    return _per_segment(p0, p1, w, h, lambda m, a, rr, cc: (rr[:-1], cc[:-1]))


def random_ends(p0, p1, w, h, q=0.25):
    """An unbiased, Khronos-conforming renderer: a line loses (prob. q) or gains (prob. q) one pixel at a random end.

    The decision is seeded by the segment's start, so frames are deterministic.
    Half the lines differ from the oracle by one end pixel (fewer seen: a
    pixel lost at a shared vertex may be drawn by the next line), ~0.3 % of a
    cube's ~1,500 line pixels a frame: ~40 x the Mesa-vs-NVIDIA difference
    (1 - F1@0 = 7e-5), and every line within +-1 of the oracle's count.
    """

    def edit(m, a, rr, cc):
        if len(rr) < 2:
            return rr, cc
        rng = np.random.default_rng(abs(hash((round(a[0] * 256), round(a[1] * 256)))) % 2**32)
        u, end = rng.random(), rng.integers(2)
        if u < q:  # lose the pixel at this end
            rr, cc = (rr[1:], cc[1:]) if end == 0 else (rr[:-1], cc[:-1])
        elif u < 2 * q:  # gain one: one more step beyond this end
            if end == 0:
                rr, cc = np.r_[2 * rr[0] - rr[1], rr], np.r_[2 * cc[0] - cc[1], cc]
            else:
                rr, cc = np.r_[rr, 2 * rr[-1] - rr[-2]], np.r_[cc, 2 * cc[-1] - cc[-2]]
        keep = (rr >= 0) & (rr < h) & (cc >= 0) & (cc < w)
        return rr[keep], cc[keep]

    return _per_segment(p0, p1, w, h, edit)
