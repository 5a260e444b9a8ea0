"""``<scene>-plots.png``: a run's per-frame diagnostics against frame number (matplotlib, Agg).

Two panels sharing the frame axis:

1. depth: the band between the smallest and largest depth (``z_cam``) of the
   visible vertices of each frame (frames with no visible vertex leave a gap);
2. counts: clipped vertices and clipped edges per frame, plus culled faces
   (``--cull backface``), hidden pixels (``--hidden-lines``, on a right-hand
   axis: they are in the thousands) and culled objects (scenes of several
   objects) when the run has them.

The figure is built with matplotlib's object API (``matplotlib.figure.Figure``
rendered by Agg), never pyplot, so no global backend or state is touched. The
PNG bytes are deterministic: fixed size and dpi, and no "Software" text chunk
(the only varying metadata matplotlib writes).

Only drawing plots uses matplotlib: frames are drawn by core's own rasterizer.
"""

from __future__ import annotations

import io

import numpy as np

#: Figure size in inches at DPI: 900 x 650 pixels.
FIGSIZE = (9.0, 6.5)
DPI = 100
#: Legends in a row above their panel, off the data.
_LEGEND = dict(loc="lower left", bbox_to_anchor=(0.0, 1.0), ncol=3, fontsize=8, frameon=False, borderaxespad=0.2)


def plot_png(records: list[dict], title: str) -> bytes:
    """PNG bytes of the per-frame diagnostics ``records`` (the report's ``frames`` list)."""
    from matplotlib.figure import Figure

    k = np.asarray([r["frame"] for r in records], dtype=np.float64)
    lo = np.asarray([np.nan if r["min_depth"] is None else r["min_depth"] for r in records], dtype=np.float64)
    hi = np.asarray([np.nan if r["max_depth"] is None else r["max_depth"] for r in records], dtype=np.float64)

    fig = Figure(figsize=FIGSIZE, dpi=DPI)
    ax_d, ax_c = fig.subplots(2, 1, sharex=True)
    seen = np.isfinite(lo)
    if seen.any():
        ax_d.fill_between(k, lo, hi, where=seen, color="tab:blue", alpha=0.3, linewidth=0, label="visible depth range")
        ax_d.plot(k, lo, color="tab:blue", lw=1.0, label="min depth")
        ax_d.plot(k, hi, color="tab:blue", lw=1.0, ls="--", label="max depth")
        ax_d.legend(**_LEGEND)
    else:
        ax_d.text(0.5, 0.5, "no visible vertex in any frame", ha="center", va="center", transform=ax_d.transAxes)
    ax_d.set_ylabel("depth z_cam (world units)")
    ax_d.grid(True, alpha=0.3)

    series = [("clipped", "clipped vertices", "tab:red", "-"), ("clipped_edges", "clipped edges", "tab:orange", "--")]
    if any("faces_culled" in r for r in records):
        series.append(("faces_culled", "culled faces (back-facing)", "tab:green", "-"))
    if any("objects_culled" in r for r in records):
        series.append(("objects_culled", "culled objects (outside the frustum)", "tab:purple", ":"))
    for key, label, colour, ls in series:
        ax_c.plot(
            k, [r.get(key, 0) or 0 for r in records], color=colour, ls=ls, lw=1.2, drawstyle="steps-mid", label=label
        )
    handles, labels = ax_c.get_legend_handles_labels()
    if any("hidden_pixels" in r for r in records):
        ax_h = ax_c.twinx()
        (line,) = ax_h.plot(
            k,
            [r.get("hidden_pixels", 0) or 0 for r in records],
            color="tab:gray",
            lw=1.0,
            label="hidden pixels (right axis)",
        )
        ax_h.set_ylabel("hidden pixels")
        ax_h.set_ylim(bottom=0)
        handles.append(line)
        labels.append(line.get_label())
    ax_c.legend(handles, labels, **_LEGEND)
    ax_c.set_ylabel("count per frame")
    ax_c.set_xlabel("frame")
    ax_c.grid(True, alpha=0.3)
    from matplotlib.ticker import MaxNLocator

    ax_c.yaxis.set_major_locator(MaxNLocator(integer=True))  # counts are whole numbers
    top = max((r.get(key, 0) or 0 for r in records for key, *_ in series), default=0)
    ax_c.set_ylim(0, max(1, top * 1.05))  # all zero: show 0..1, not 0..0.05
    if len(k):
        ax_c.set_xlim(k[0] - 0.5, k[-1] + 0.5)
    fig.suptitle(title)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", metadata={"Software": None})
    return buf.getvalue()
