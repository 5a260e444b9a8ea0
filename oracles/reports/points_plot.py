"""worst_points.png: a vertex-level run's worst frame, the candidate's points over OpenCV's.

At level vertices nothing is drawn, so the report's picture of the worst case
is its points: OpenCV's (the oracle) as circles, the candidate's as crosses,
both in pixel space (x right, y down, the image's frame outlined), and the
worst vertex ringed, joined to where the candidate put it, its error in the
title. A cross inside its circle is a vertex the two agree on at this scale.
Same points in, same bytes out (oracles.reports.plots: no "Software" stamp, no
date).
"""

from __future__ import annotations

import numpy as np

from ..judge.metrics import DIFF_COLOURS
from .plots import new_figure, figure_png

#: The plot shows the image and OpenCV's points, with this share of the span as margin; a
#: candidate point far outside (a broken projector's 1e30) is left out rather than shrinking the rest.
MARGIN = 0.05


def _rgb(name: str) -> tuple:
    return tuple(v / 255 for v in DIFF_COLOURS[name])


def _limits(size: tuple, oracle: np.ndarray) -> tuple[tuple, tuple]:
    """(x0, x1), (y0, y1): the image ``[0, W] x [0, H]`` and OpenCV's finite points, with a margin."""
    w, h = size
    shown = oracle[np.isfinite(oracle).all(axis=1)]
    lo = np.minimum([0.0, 0.0], shown.min(axis=0)) if len(shown) else np.array([0.0, 0.0])
    hi = np.maximum([w, h], shown.max(axis=0)) if len(shown) else np.array([w, h], float)
    pad = MARGIN * (hi - lo)
    return (lo[0] - pad[0], hi[0] + pad[0]), (lo[1] - pad[1], hi[1] + pad[1])


def points_png(points: dict) -> bytes:
    """``points`` (oracles.judge.case.worst_points): the frame's points of both sides as a PNG."""
    from matplotlib.patches import Rectangle

    cand, orac = np.asarray(points["candidate"], float), np.asarray(points["oracle"], float)
    w, h = points["size"]
    fig = new_figure(2)                              # 10 x 6.4 in: a 4:3 image with its title and legend
    ax = fig.add_subplot(1, 1, 1)
    ax.add_patch(Rectangle((0, 0), w, h, fill=False, edgecolor="#888", linewidth=1, linestyle="--"))
    o_ok, c_ok = np.isfinite(orac).all(axis=1), np.isfinite(cand).all(axis=1)
    ax.scatter(orac[o_ok, 0], orac[o_ok, 1], s=36, facecolors="none", edgecolors=[_rgb("oracle_only")],
               linewidths=1, label=f"OpenCV ({int(o_ok.sum())} points)")
    ax.scatter(cand[c_ok, 0], cand[c_ok, 1], s=28, marker="x", c=[_rgb("candidate_only")], linewidths=1,
               label=f"candidate ({int(c_ok.sum())} points)")
    i = points["vertex"]
    if i is not None and o_ok[i]:
        ax.scatter([orac[i, 0]], [orac[i, 1]], s=400, facecolors="none", edgecolors="black", linewidths=1.5,
                   label=f"worst vertex ({i})")
        if c_ok[i]:
            ax.plot([orac[i, 0], cand[i, 0]], [orac[i, 1], cand[i, 1]], color="black", linewidth=1)
    (x0, x1), (y0, y1) = _limits((w, h), orac)
    ax.set_xlim(x0, x1)
    ax.set_ylim(y1, y0)                           # pixel rows grow downwards
    ax.set_aspect("equal")
    ax.set_xlabel("x (px)")
    ax.set_ylabel("y (px)")
    err = points["error_px"]
    err_text = "not compared" if err is None else f"off by {err:.3g} px"
    ax.set_title(f"{points['scene']} / {points['camera']}, frame {points['frame']}: worst vertex {i} {err_text}\n"
                 "candidate (x) over OpenCV (o), the worst vertex ringed; dashed: the image", fontsize=10)
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, frameon=False)
    ax.grid(True, alpha=0.2)
    fig.tight_layout()
    return figure_png(fig)
