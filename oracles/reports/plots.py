"""Figures of a crosscheck report: per-frame error plots (matplotlib Agg) and worst.gif (Pillow).

Same report in, same bytes out: the PNGs are written without the
"Software" metadata (matplotlib's version would otherwise be stamped in) and
without a date; the GIF has a fixed palette and frame delay. One figure holds
every case (one line each), so a report costs two or three figures, not one
per case.
"""

from __future__ import annotations

import io
import math

import numpy as np

from ..judge.metrics import DIFF_COLOURS

#: Vertex errors of exactly 0 cannot be shown on a log axis: they are drawn at this value.
ZERO_FLOOR_PX = 1e-16

#: worst.gif: palette indices.
_BLACK, _WHITE, _CAND, _ORAC, _SEP, _BAR = range(6)
_PALETTE = [(0, 0, 0), (255, 255, 255), DIFF_COLOURS["candidate_only"], DIFF_COLOURS["oracle_only"],
            (128, 128, 128), (90, 90, 90)]
#: worst.gif: delay per frame (ms) and the height of the progress strip under the panels (px).
GIF_FRAME_MS = 120
STRIP_PX = 3
#: A log axis spanning more decades than this has ticks and labels at powers of ten only.
MINOR_TICKS_MAX_DECADES = 2.0


def new_figure(rows: int):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(10, 3.2 * rows), dpi=100)
    FigureCanvasAgg(fig)
    return fig


def figure_png(fig) -> bytes:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", metadata={"Software": None})
    return buf.getvalue()


def _styles(n: int):
    """Distinct (colour, linestyle) pairs for ``n`` lines: tab10 colours, then other line styles."""
    from matplotlib import colormaps

    colours = colormaps["tab10"].colors
    dashes = ("-", "--", ":", "-.")
    return [(colours[i % 10], dashes[(i // 10) % 4]) for i in range(n)]


def _series(case: dict, key: str):
    frames = [f["frame"] for f in case.get("per_frame", [])]
    values = [f.get(key) for f in case.get("per_frame", [])]
    return frames, values


_SUPERSCRIPT = str.maketrans("-0123456789", "\u207b\u2070\u00b9\u00b2\u00b3\u2074\u2075\u2076\u2077\u2078\u2079")


def _decade_label(value: float, _pos=None) -> str:
    """``10⁻⁶`` for a power of ten, in plain Unicode (DejaVu Sans has the superscripts); '' otherwise."""
    if not value > 0:
        return ""
    e = round(math.log10(value))
    return "10" + str(e).translate(_SUPERSCRIPT) if math.isclose(value, 10.0 ** e) else ""


def _log_y(ax) -> None:
    """Log y axis labelled at powers of ten. Over more than :data:`MINOR_TICKS_MAX_DECADES`
    decades the unlabelled minor ticks are left out (a figure's cost was mostly their tick
    objects and the mathtext of the default labels, re-parsed for every figure)."""
    from matplotlib.ticker import FuncFormatter, NullLocator

    ax.set_yscale("log")
    lo, hi = ax.get_ylim()
    if hi > lo > 0 and math.log10(hi / lo) > MINOR_TICKS_MAX_DECADES:
        ax.yaxis.set_major_formatter(FuncFormatter(_decade_label))
        ax.yaxis.set_minor_locator(NullLocator())


def _legend(ax, n: int) -> None:
    if n:
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=7, frameon=False,
                  ncol=1 if n <= 16 else 2)


def vertex_error_png(report: dict) -> bytes | None:
    """Per-frame max vertex error of every case, log scale, with the tolerance; None without frames."""
    from matplotlib.ticker import MaxNLocator

    cases = [c for c in report["cases"] if c.get("per_frame")]
    if not any(f.get("max_vertex_error_px") is not None for c in cases for f in c["per_frame"]):
        return None                 # no vertex compared (a renderer's frames): no figure of nothing
    fig = new_figure(1)
    ax = fig.add_subplot(1, 1, 1)
    for case, (colour, dash) in zip(cases, _styles(len(cases))):
        frames, values = _series(case, "max_vertex_error_px")
        y = [np.nan if v is None else max(v, ZERO_FLOOR_PX) for v in values]
        ax.plot(frames, y, dash, color=colour, marker=".", markersize=3, linewidth=1,
                label=f"{case['scene']} / {case['camera']}")
    tol = report["tolerances"]["vertex_error_px"]
    if tol is not None and tol > 0:     # a tolerance of 0 has no place on a log axis; None: inf in report.json
        ax.axhline(tol, color="#b00", linewidth=1, linestyle="--")
        ax.text(1.0, tol, f" tolerance {tol:g} px", color="#b00", fontsize=7, va="bottom", ha="right",
                transform=ax.get_yaxis_transform())
    _log_y(ax)
    ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    ax.set_xlabel("frame")
    ax.set_ylabel("max vertex error (px)")
    ax.set_title(f"Vertex error against OpenCV, per frame (0 drawn at {ZERO_FLOOR_PX:g})", fontsize=10)
    ax.grid(True, which="major", alpha=0.3)
    _legend(ax, len(cases))
    fig.tight_layout()
    return figure_png(fig)


def pixel_png(report: dict) -> bytes | None:
    """Per-frame F1@0px of every case (wireframes), or silhouette IoU and depth error / bound (shaded)."""
    from matplotlib.ticker import MaxNLocator

    if report.get("level") == "vertices":
        return None
    cases = [c for c in report["cases"] if c.get("per_frame")]
    shaded = report.get("style") == "shaded"
    panels = ([("silhouette_iou", "silhouette IoU", report["tolerances"].get("min_silhouette_iou"), False),
               ("depth_error_ratio", "depth error / bound", 1.0, True)] if shaded
              else [("f1_0px", "F1@0px", report["tolerances"].get("min_pixel_f1_0px"), False)])
    if not any(f.get(panels[0][0]) is not None for c in cases for f in c["per_frame"]):
        return None
    fig = new_figure(len(panels))
    styles = _styles(len(cases))
    for row, (key, label, limit, log) in enumerate(panels):
        ax = fig.add_subplot(len(panels), 1, row + 1)
        for case, (colour, dash) in zip(cases, styles):
            frames, values = _series(case, key)
            y = [np.nan if v is None else (max(v, 1e-6) if log else v) for v in values]
            ax.plot(frames, y, dash, color=colour, marker=".", markersize=3, linewidth=1,
                    label=f"{case['scene']} / {case['camera']}")
        if limit is not None and (limit > 0 or not log):
            ax.axhline(limit, color="#b00", linewidth=1, linestyle="--")
            ax.text(1.0, limit, f" limit {limit:g}", color="#b00", fontsize=7, va="bottom", ha="right",
                    transform=ax.get_yaxis_transform())
        if log:
            _log_y(ax)
        ax.xaxis.set_major_locator(MaxNLocator(integer=True))
        ax.set_xlabel("frame")
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
        if row == 0:
            ax.set_title(f"{label} against pyrender, per frame", fontsize=10)
            _legend(ax, len(cases))
    fig.tight_layout()
    return figure_png(fig)


def _panel_indices(cand: np.ndarray, orac: np.ndarray) -> np.ndarray:
    """``(H, 3W + 2)`` palette indices: candidate | oracle | diff, 1-px grey separators."""
    h, w = cand.shape
    out = np.full((h, 3 * w + 2), _SEP, np.uint8)
    out[:, :w] = np.where(cand, _WHITE, _BLACK)
    out[:, w + 1:2 * w + 1] = np.where(orac, _WHITE, _BLACK)
    diff = np.full((h, w), _BLACK, np.uint8)
    diff[cand & orac] = _WHITE
    diff[cand & ~orac] = _CAND
    diff[~cand & orac] = _ORAC
    out[:, 2 * w + 2:] = diff
    return out


def worst_gif(animation: dict) -> bytes:
    """Every checked frame of a case as candidate | oracle | diff (oracles.judge.metrics.diff_image colours).

    The frame is ``3W + 2`` px wide (1-px grey separators) and ``H + STRIP_PX``
    high: under the panels, a grey row and a progress bar of the frame's place
    in the run. The bar makes every frame differ from the one before (Pillow
    would otherwise merge identical frames into one), so the GIF has exactly
    one frame per checked frame.
    """
    from PIL import Image

    cands, oracs = animation["candidate"], animation["oracle"]
    n = len(cands)
    h, w = cands[0].shape
    width = 3 * w + 2
    palette = [v for rgb in _PALETTE for v in rgb]
    pictures = []
    for i, (c, o) in enumerate(zip(cands, oracs)):
        idx = np.full((h + STRIP_PX, width), _BAR, np.uint8)
        idx[:h] = _panel_indices(np.asarray(c, bool), np.asarray(o, bool))
        idx[h] = _SEP
        filled = max(1, round(width * (i + 1) / n))
        idx[h + 1:, :filled] = _WHITE
        if i and filled == max(1, round(width * i / n)):
            idx[h + 1:, filled - 1] = _SEP if i % 2 else _BAR      # more frames than columns: still differ
        pic = Image.frombytes("P", (width, h + STRIP_PX), np.ascontiguousarray(idx).tobytes())
        pic.putpalette(palette)
        pictures.append(pic)
    buf = io.BytesIO()
    pictures[0].save(buf, format="GIF", save_all=True, append_images=pictures[1:], duration=GIF_FRAME_MS,
                     loop=0, optimize=False)
    return buf.getvalue()
