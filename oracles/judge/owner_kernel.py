"""Every drawn pixel's owning segment in one compiled pass: oracles.judge.segment_pixels' pairing, row by row.

The owner of a pixel is the segment nearest its centre within ``radius``
(``hypot`` of the pixel's offset from the segment's nearest point; ties: the
lower index), as oracles.judge.segment_pixels states it. Its numpy pairing lists the
pairs of each segment's rows in chunks and folds them (~25 array passes a
pair: 14.5-16 ms of CPU for the 40,000-60,000 drawn pixels of a 20k-60k face
mesh's frame); this kernel walks the same rows and pairs without arrays of
them, measuring each pair with the same float operations in the same order
(no fused multiply-add, numba's default), so it gives the same owners:

* a segment's rows are those its box grown by ``grow`` spans; in each row, the
  columns its part within ``grow`` of the row reaches (the numpy pairing's
  ``_Segments._spans``, one-row bands): a superset of the pixels within ``radius``;
* a pair is within ``radius`` when ``hypot`` of its offset is; its squared
  distance ``d2`` decides where it is more than :data:`segment_pixels.D2_SLACK`
  (relative) from ``radius^2`` or from the pixel's best pair's ``d2`` so far,
  ``hypot`` elsewhere (segment_pixels' argument: the two then order the pairs alike);
* segments are walked in ascending index, so a pixel's pairs come in ascending
  index and a later pair replaces the best only when strictly nearer.

It is compiled by numba on first use (:func:`available`: ~3 s, then cached beside this
module; importing numba and loading the cache ~0.6 s a process, :func:`setup_seconds`,
left out of the per-frame timings as other one-time set-up is), so oracles.judge.segment_pixels
uses it only for frames of at least :data:`segment_pixels.KERNEL_PIXELS` drawn pixels, and
falls back to its numpy pairing where numba cannot be imported or compile it
(:func:`available`). tests/test_owner_kernel.py holds the two to the same owners.
"""

from __future__ import annotations

import math
import time
import warnings

import numpy as np

_KERNEL = None  # the compiled function, made on first use
_STATE = {"tried": False, "why": None}
_SETUP_S = [0.0]  # seconds this process spent importing numba and compiling or loading the kernel


def available() -> bool:
    """Whether the kernel can be used: numba imports, is not told to run functions uncompiled
    (``NUMBA_DISABLE_JIT``: the pairing would run as Python, ~1,000 times slower than numpy's) and compiles it.
    The first call does that (~0.6 s a process with numba's cache, ~3 s without: :func:`setup_seconds`)."""
    _load()
    return _KERNEL is not None


def why_not() -> str | None:
    """Why the kernel cannot be used (after :func:`available`), None when it can."""
    _load()
    return _STATE["why"]


def setup_seconds() -> float:
    """The seconds this process spent making the kernel ready (numba's import, the compile or the cache's load):
    one-time set-up, which the per-frame timings leave out (oracles.judge.case.CaseFrames.add)."""
    return _SETUP_S[0]


def warm() -> bool:
    """Make the kernel ready now (:func:`available`); whether it is."""
    return available()


def _load() -> None:
    if _STATE["tried"]:
        return
    _STATE["tried"] = True
    t = time.perf_counter()
    try:
        _make()
    finally:
        _SETUP_S[0] += time.perf_counter() - t


def _make() -> None:
    """numba imported, the kernel compiled (or loaded from numba's cache beside this module) on a two-pixel
    input; ``_STATE["why"]`` says why not."""
    global _KERNEL
    try:
        import numba
    except ImportError as exc:  # pragma: no cover - numba is a dependency; a platform without its wheels
        _STATE["why"] = f"numba not importable ({exc})"
        return
    if numba.config.DISABLE_JIT:
        _STATE["why"] = "NUMBA_DISABLE_JIT is set"
        return
    q0 = np.array([[0.0, 0.0]])
    q1 = np.array([[3.0, 1.0]])
    d = q1 - q0
    cols = (q0[:, 0].copy(), q0[:, 1].copy(), d[:, 0].copy(), d[:, 1].copy(), (d * d).sum(axis=1))
    with warnings.catch_warnings():  # a cache that cannot be written is numba's warning, not the run's
        warnings.simplefilter("ignore")
        for cache in (True, False):  # no place to cache it (a read-only install): compiled each process
            try:
                _KERNEL = numba.njit(cache=cache, nogil=True)(_owners)
                owners(np.array([0, 1], np.int64), 4, 2, 1, q0, q1, cols, None, (0.5, 1.0), 1e-6, 2.0**-30, 1e-280)
                _STATE["why"] = None
                return
            except Exception as exc:  # noqa: BLE001 - numba cannot compile here: the numpy pairing stays
                _KERNEL, _STATE["why"] = None, f"numba could not compile it ({type(exc).__name__}: {exc})"


def owners(
    stacked: np.ndarray,
    width: int,
    height: int,
    frames: int,
    q0: np.ndarray,
    q1: np.ndarray,
    cols: tuple,
    frame: np.ndarray | None,
    radii: tuple,
    grow_px: float,
    slack: float,
    tiny: float,
) -> np.ndarray:
    """``(P,)`` int64: the owning segment of each pixel of ``stacked`` (ascending stacked flat indices of
    ``frames`` frames of ``height`` rows, segment_pixels._Pixels), -1 where none is within ``radius``.

    ``q0, q1`` ``(S, 2)``: the segments' clipped ends; ``cols``: ``(qx, qy, dx, dy, dd)`` as
    segment_pixels._Segments holds them; ``frame``: each segment's frame (None: all of frame 0);
    ``radii``: ascending, the last the pairing's radius; each pixel is paired within the first of them
    that holds a pair of it (its nearest segment is among those pairs: ties included, every segment as
    near is); ``grow_px``: how far past a radius the rows and columns listed reach; ``slack``, ``tiny``:
    segment_pixels.D2_SLACK and D2_TINY. :func:`available` must be True.
    """
    qx, qy, dx, dy, dd = cols
    seg_frame = np.zeros(1, np.int64) if frame is None else np.ascontiguousarray(frame, np.int64)
    if len(stacked):  # every pixel's and every segment's frame is one of the stacked rows
        frames = max(int(frames), int(stacked[-1]) // (width * height) + 1)
    if frame is not None and len(seg_frame):
        frames = max(int(frames), int(seg_frame.max()) + 1)
    out = np.full(len(stacked), -1, np.int64)
    _KERNEL(
        np.ascontiguousarray(stacked, np.int64),
        int(width),
        int(height),
        int(frames),
        np.ascontiguousarray(q0[:, 1]),
        np.ascontiguousarray(q1[:, 1]),
        qx,
        qy,
        dx,
        dy,
        dd,
        seg_frame,
        frame is not None,
        np.asarray(radii, np.float64),
        float(grow_px),
        float(slack),
        float(tiny),
        out,
    )
    return out


def _owners(
    stacked,
    width,
    height,
    frames,
    q0y,
    q1y,
    qx,
    qy,
    dx,
    dy,
    dd,
    seg_frame,
    per_segment,
    radii,
    grow_px,
    slack,
    tiny,
    out,
):  # pragma: no cover - compiled by numba
    """:func:`owners`' loop (module docstring): ``out`` filled in place, within each of ``radii`` in turn (the
    last the pairing's radius) for the pixels still without an owner."""
    n_px = len(stacked)
    best_d2 = np.empty(n_px)  # the squared distance of each pixel's best pair so far (its segment: out)
    # each stacked pixel's place in ``stacked`` (-1: not drawn, or owned at a smaller radius), int32
    at = np.full(frames * height * width, -1, np.int32)
    cell = 8
    nx, ny = (width + cell - 1) // cell, (height + cell - 1) // cell
    table = np.zeros((frames, ny + 1, nx + 1), np.int32)  # the pixels left, counted by cells (summed-area)
    for level in range(len(radii)):
        radius = radii[level]
        grow = radius + grow_px
        pending = 0
        for i in range(n_px):
            if out[i] < 0:
                at[stacked[i]] = i
                pending += 1
            else:
                at[stacked[i]] = -1
        if pending == 0:
            break
        # fewer pixels left than segments: a segment is first tested against the cells holding them
        boxed = pending < len(qx)
        if boxed:
            table[:] = 0
            for i in range(n_px):
                if out[i] < 0:
                    f, rest = divmod(stacked[i], width * height)
                    y, x = divmod(rest, width)
                    table[f, y // cell + 1, x // cell + 1] += 1
            for f in range(frames):
                for y in range(1, ny + 1):
                    for x in range(1, nx + 1):
                        table[f, y, x] += table[f, y - 1, x] + table[f, y, x - 1] - table[f, y - 1, x - 1]
        r2 = radius * radius
        r2_hi = r2 * (1 + slack)
        r2_lo = r2 * (1 - slack)
        for s in range(len(qx)):
            f = seg_frame[s] if per_segment else 0
            sx, sy, sdx, sdy, sdd = qx[s], qy[s], dx[s], dy[s], dd[s]
            inv_dy = 1.0 / sdy if sdy != 0.0 else 0.0
            y_lo = min(q0y[s], q1y[s])
            y_hi = max(q0y[s], q1y[s])
            row_lo = max(np.ceil(y_lo - grow), 0.0)
            row_hi = min(np.floor(y_hi + grow), height - 1.0)
            if row_lo > row_hi:
                continue
            if boxed:  # no pixel left in the cells of the segment's grown box: nothing to pair
                x_lo = min(sx, sx + sdx)  # the box of its clipped ends (qx + dx: within rounding of the end,
                x_hi = max(sx, sx + sdx)  # which the whole cells' margin covers)
                c0 = int(min(max(np.floor((x_lo - grow) / cell), 0.0), nx))
                c1 = int(min(max(np.floor((x_hi + grow) / cell) + 1, 0.0), nx))
                r0 = int(row_lo) // cell
                r1 = int(row_hi) // cell + 1
                if c1 <= c0 or table[f, r1, c1] - table[f, r0, c1] - table[f, r1, c0] + table[f, r0, c0] == 0:
                    continue
            for row in range(int(row_lo), int(row_hi) + 1):
                # the columns of the segment's part within grow of the row (segment_pixels._Segments._spans)
                if sdy == 0.0:
                    t_lo, t_hi = 0.0, 1.0
                else:  # by the reciprocal: within ~1e-13 px of the quotient, far inside grow's GROW_PX margin
                    rel = (row - grow) - sy
                    ta = rel * inv_dy
                    tb = (rel + 2 * grow) * inv_dy
                    t_lo, t_hi = min(ta, tb), max(ta, tb)
                xa = min(max(t_lo, 0.0), 1.0) * sdx + sx
                xb = min(max(t_hi, 0.0), 1.0) * sdx + sx
                c_lo = min(max(np.ceil(min(xa, xb) - grow), 0.0), float(width))
                c_hi = min(max(np.floor(max(xa, xb) + grow), -1.0), width - 1.0)
                if c_lo > c_hi:
                    continue
                base = (row + f * height) * width
                y = float(row)
                for col in range(int(c_lo), int(c_hi) + 1):
                    k = at[base + col]
                    if k < 0:
                        continue
                    x = float(col)
                    # the point of the segment nearest the pixel centre (segment_pixels._Segments._offsets)
                    ex = x - sx
                    ey = y - sy
                    u = ex * sdx + ey * sdy
                    if sdd == 0.0:
                        u = 0.0
                    else:
                        u = u / sdd
                    u = min(max(u, 0.0), 1.0)
                    ex = ex - u * sdx
                    ey = ey - u * sdy
                    d2 = ex * ex + ey * ey
                    if d2 > r2_hi or (d2 >= r2_lo and math.hypot(ex, ey) > radius):
                        continue
                    if out[k] < 0:
                        out[k], best_d2[k] = s, d2
                        continue
                    bd2 = best_d2[k]
                    if d2 > bd2 * (1 + slack) + tiny:  # farther by its distance too
                        continue
                    if bd2 > d2 * (1 + slack) + tiny:  # nearer
                        out[k], best_d2[k] = s, d2
                        continue
                    # as near as d2 can tell: the distances decide (the best's offsets measured again, the same
                    # floats), a tie keeps the lower index
                    b = out[k]
                    bx = x - qx[b]
                    by = y - qy[b]
                    ub = bx * dx[b] + by * dy[b]
                    if dd[b] == 0.0:
                        ub = 0.0
                    else:
                        ub = ub / dd[b]
                    ub = min(max(ub, 0.0), 1.0)
                    if math.hypot(ex, ey) < math.hypot(bx - ub * dx[b], by - ub * dy[b]):
                        out[k], best_d2[k] = s, d2
