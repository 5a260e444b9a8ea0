"""Where a frame's one-sided line pixels lie along the oracle's segments, and which are sub-pixel ties.

Each pixel drawn by one image only is given to its nearest segment and
placed: a sub-pixel ``tie`` of that segment (oracles.judge.line_ties: a crossing or an
end within the oracle's precision of the pixel's edge), else at its
``start`` or ``end`` (within ``NAMING.end_reach_px`` of that point, oracles.tolerances), in the
``middle``, or ``stray`` (no segment within reach). The line gate's balance
test and its fault names read the decided places (oracles.judge.metrics,
oracles.diagnosis.diagnose).

The ties found here are what every line criterion leaves undecided: the
balance test leaves them out, and :func:`resolve_ties` gives the candidate
the oracle's value at each of them, so that F1@0px and the per-edge counts
(oracles.judge.metrics.line_scores) are taken on the decided pixels only. A tie
pixel and its partner across the line are then drawn alike by both images,
so no edge's count can move by one image taking the pixel on one side of a
tie and the other the pixel on the other side (possibly nearer another
edge, at a vertex where the lines meet).
"""

from __future__ import annotations

import numpy as np

from ..tolerances import NAMING
from . import line_ties
from .frame_pixels import FramePixels
from .segment_pixels import nearest_segments

#: The places of :func:`end_attribution`, ``tie`` last.
PLACES = ("start", "end", "middle", "stray", "tie")


def end_attribution(cand: np.ndarray, oracle: np.ndarray, p0_px: np.ndarray, p1_px: np.ndarray) -> dict:
    """Where the one-sided pixels lie along the oracle's segments: at the start, at the end, or between.

    Each candidate-only and oracle-only pixel is given to its nearest segment
    (``p0_px[m] -> p1_px[m]``, the edge's first vertex to its second, clipped
    to the near plane, then to the image's edges ``[-1/2, W - 1/2] x [-1/2,
    H - 1/2]``, where a line leaving the picture ends); it is at the ``start`` (``end``) when within
    ``NAMING.end_reach_px`` of that segment's first (last) point, else ``middle``
    (also: within reach of both ends of a very short segment, or more than
    1.5 px from every segment: ``stray``), or, before any of those, a
    sub-pixel ``tie`` of its nearest segment (oracles.judge.line_ties: the line
    crosses beside it within the oracle's precision of the pixel's edge, and
    the other image drew the pixel across that edge; or an end of the segment,
    not one made by the image's border, lies within that precision of where
    the segment leaves the pixel's diamond). Returns
    ``{place: [candidate_only, oracle_only]}``.
    """
    return frames_end_places([(FramePixels(cand, oracle), p0_px, p1_px)])[0]


def frames_end_places(frames, tie_pixels: list | None = None) -> list[dict]:
    """:func:`end_attribution` of several frames of one size (``[(FramePixels, p0_px, p1_px)]``), in one pass,
    with the sub-pixel ties apart (``"tie"``).

    ``tie_pixels``: a list to which, for each frame, ``(candidate_only,
    oracle_only)`` is appended: the flat indices ``y W + x`` of the tie
    pixels on each side, ascending (what :func:`resolve_ties` takes).
    """
    out = [{k: [0, 0] for k in PLACES} for _ in frames]
    found = [[np.zeros(0, np.int64), np.zeros(0, np.int64)] for _ in frames]
    if tie_pixels is not None:
        tie_pixels.extend(found)
    if not frames:
        return out
    h, w = frames[0][0].shape
    box = ((-0.5, -0.5), (w - 0.5, h - 0.5))  # where a line leaving the picture ends
    n = len(frames)
    only = [[fp.only()[side] for fp, _, _ in frames] for side in (0, 1)]
    sides = [side for side in (0, 1) if sum(len(o) for o in only[side])]
    if sides:  # each pixel's nearest segment within reach (the segments near it only), both sides at once
        owners, q0, q1, frames_of = nearest_segments(
            [(p0, p1, o) for side in sides for (_, p0, p1), o in zip(frames, only[side])],
            w,
            h,
            NAMING.end_reach_px,
            box,
        )
    start = 0
    for i, side in enumerate(sides):
        stop = start + sum(len(o) for o in only[side])
        owner, frame = owners[start:stop], frames_of[start:stop] - i * n  # this side's pixels, in its frames
        start = stop
        pix = np.concatenate(only[side])
        near = owner >= 0
        m, f = owner[near], frame[near]
        c = np.column_stack([pix[near] % w, pix[near] // w]).astype(np.float64)
        tie, partner = line_ties.tie_crossings(c, q0[m], q1[m])
        if tie.any():  # a crossing tie needs its partner pixel drawn by the other image
            other = [fp.cand_idx if side == 1 else fp.oracle_idx for fp, _, _ in frames]
            drawn = np.concatenate([o + k * h * w for k, o in enumerate(other)])  # ascending: frame after frame
            tie &= line_ties.partner_drawn(partner, f, (h, w), drawn)
        tie |= line_ties.tie_ends(c, q0[m], q1[m], box)  # an end within the oracle's precision of its exit
        if tie.any():
            tied, tied_frame = pix[near][tie], f[tie]
            for k in np.unique(tied_frame):
                found[k][side] = np.sort(tied[tied_frame == k]).astype(np.int64)
        to_start = np.hypot(*(c - q0[m]).T) <= NAMING.end_reach_px
        to_end = np.hypot(*(c - q1[m]).T) <= NAMING.end_reach_px
        place = {
            "tie": tie,
            "start": ~tie & to_start & ~to_end,
            "end": ~tie & to_end & ~to_start,
            "middle": ~tie & (to_start == to_end),
        }
        for name, hit in place.items():
            for k, v in enumerate(np.bincount(f[hit], minlength=n)):
                out[k][name][side] += int(v)
        for k, v in enumerate(np.bincount(frame[~near], minlength=n)):
            out[k]["stray"][side] += int(v)
    return out


def resolve_ties(fp, ties: tuple):
    """The frame's pixels (oracles.judge.frame_pixels.FramePixels) with the candidate given the oracle's value at its ties.

    ``ties``: ``(candidate_only, oracle_only)`` flat indices of the tie pixels
    (:func:`frames_end_places`' ``tie_pixels``). The candidate's tie pixels the
    oracle did not draw are taken out, and the oracle's tie pixels the
    candidate did not draw are put in: both images then agree at every tie,
    and differ at the decided pixels only. ``fp`` itself when there is no tie.
    """
    cand_ties, oracle_ties = ties
    if not len(cand_ties) and not len(oracle_ties):
        return fp
    swapped = fp.exchanged(cand_ties, oracle_ties)  # ties found by frames_end_places: a merge
    if swapped is not None:
        return swapped
    kept = fp.cand_idx[~np.isin(fp.cand_idx, cand_ties, assume_unique=True)]
    cand_idx = np.union1d(kept, oracle_ties).astype(fp.cand_idx.dtype)
    return FramePixels.from_indices(fp.shape, cand_idx, fp.oracle_idx)
