"""A case's line-measure samples, frame after frame, kept as one array per field (oracles.judge.line_style).

Each frame's :func:`oracles.judge.line_style.measure` gives arrays of its
samples (``offset``, ``normal``, ``point``, ...) and two counts (``windows``,
``found``). A case keeps them all in frame order, and past its cap thins every
frame to every other sample (:meth:`CaseSamples.halve`), so that its memory is
bounded whatever its number of frames. Kept as one array per field, a halving
is one mask over those arrays (which samples are at an even place within their
frame), not a copy per frame: with per-frame objects its cost grew with the
case's frames, and a long case halves often.
"""

from __future__ import annotations

import numpy as np

#: The per-frame counts of measure(): summed, never thinned.
COUNTS = ("windows", "found")


class CaseSamples:
    """The samples of a case's frames, in frame order: what :meth:`pooled` concatenates.

    Frames added since the last halving wait in a list (an append costs
    nothing); a halving joins them to the kept arrays, then keeps each frame's
    samples at even places ``0, 2, 4, ...`` within it, as ``v[::2]`` would
    frame by frame (a frame of one sample keeps it).
    """

    def __init__(self):
        self.frames = 0  # frames added
        self.counts = dict.fromkeys(COUNTS, 0)
        self._cols = None  # field -> one array of the joined frames' samples
        self._lens = np.zeros(0, np.intp)  # samples of each joined frame
        self._new = []  # frames added since, as measure() gave them

    def __len__(self) -> int:
        return self.frames

    def add(self, samples: dict) -> None:
        """One frame's samples (the arrays are kept, not copied: the caller makes no other use of them)."""
        for key in COUNTS:
            self.counts[key] += samples.get(key, 0)
        self._new.append({k: v for k, v in samples.items() if k not in COUNTS})
        self.frames += 1

    @property
    def kept(self) -> int:
        """How many samples are kept, over every frame."""
        return int(self._lens.sum()) + sum(len(x["offset"]) for x in self._new)

    def _join(self) -> None:
        if not self._new:
            return
        parts = ([self._cols] if self._cols is not None else []) + self._new
        self._cols = {k: np.concatenate([x[k] for x in parts]) for k in parts[0]}
        self._lens = np.concatenate([self._lens, [len(x["offset"]) for x in self._new]]).astype(np.intp)
        self._new = []

    def halve(self) -> None:
        """Every frame down to its samples at even places within it (each kept array a copy: no view keeps
        the larger one alive)."""
        self._join()
        if self._cols is None:
            return
        starts = np.cumsum(self._lens) - self._lens
        place = np.arange(int(self._lens.sum())) - np.repeat(starts, self._lens)
        keep = place % 2 == 0
        self._cols = {k: v[keep] for k, v in self._cols.items()}
        self._lens = (self._lens + 1) // 2

    def pooled(self, key: str) -> np.ndarray:
        """Field ``key`` of every kept sample, in frame order; ``zeros(0)`` when no frame was added."""
        if not self.frames:
            return np.zeros(0)
        parts = ([self._cols[key]] if self._cols is not None else []) + [x[key] for x in self._new]
        return np.concatenate(parts)

    def arrays(self) -> list:
        """Every array held (for a test of what memory the samples keep)."""
        return ([] if self._cols is None else list(self._cols.values())) + [
            v for x in self._new for v in x.values() if isinstance(v, np.ndarray)
        ]
