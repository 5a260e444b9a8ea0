"""A renderer of a wirecheck frames job written as a matplotlib user would: Agg, antialiased, any line width.

``python matplotlib_frames.py JOB [--linewidth PX] [--mirror-y]``

For every case and frame listed in ``JOB/job.json`` it reads the OBJ and the
frame's camera JSON, projects with OpenCV's ``K``, ``R``, ``t_cv`` (its own
code: ``p_cv = R p_world + t``, ``[u, v, 1] ~ K p_cv``; ``K`` affine for an
orthographic camera), clips each edge to depth [near, far] in camera space,
and draws the segments white on black with a ``LineCollection`` on axes that
fill a figure of the camera's size (x from -0.5 to W - 0.5, y from H - 0.5 at
the bottom to -0.5 at the top: pixel centres at integers, y down). Only
numpy, matplotlib and the job's files: nothing of wirecheck.

``--mirror-y`` is a typical mistake: y up (``ylim(-0.5, H - 0.5)``), the image
upside down.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
from job_files import job_frames


def segments(p_world, edges, cam):
    """Edges clipped to depth [near, far] in OpenCV camera space, projected: ``(K, 2, 2)`` pixels."""
    k, r, t = np.array(cam["K"]), np.array(cam["R"]), np.array(cam["t_cv"])
    near, far = cam["camera"]["near"], cam["camera"]["far"]
    ortho = cam["camera"]["projection"] != "perspective"
    p_cv = p_world @ r.T + t
    out = []
    for i, j in edges:
        a, b = p_cv[i], p_cv[j]
        t0, t1 = 0.0, 1.0
        for plane, sign in ((near, 1.0), (far, -1.0)):  # keep sign * (z - plane) >= 0
            fa, fb = sign * (a[2] - plane), sign * (b[2] - plane)
            if fa < 0 and fb < 0:
                t0, t1 = 1.0, 0.0
            elif fa < 0:
                t0 = max(t0, fa / (fa - fb))
            elif fb < 0:
                t1 = min(t1, fa / (fa - fb))
        if t0 >= t1:
            continue
        ends = np.array([a + (b - a) * t0, a + (b - a) * t1])
        if ortho:
            px = ends[:, :2] @ k[:2, :2].T + k[:2, 2]
        else:
            uvw = ends @ k.T
            px = uvw[:, :2] / uvw[:, 2:]
        out.append(px)
    return np.array(out).reshape(-1, 2, 2)


def draw(segs, width, height, linewidth_px, mirror_y, path):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.collections import LineCollection
    from matplotlib.figure import Figure

    dpi = 100
    fig = Figure(figsize=(width / dpi, height / dpi), dpi=dpi, facecolor="black")
    FigureCanvasAgg(fig)
    ax = fig.add_axes([0, 0, 1, 1])
    ax.set_facecolor("black")
    ax.set_axis_off()
    ax.set_xlim(-0.5, width - 0.5)
    ax.set_ylim((-0.5, height - 0.5) if mirror_y else (height - 0.5, -0.5))
    ax.add_collection(
        LineCollection(
            segs, colors="white", linewidths=linewidth_px * 72.0 / dpi, antialiaseds=True, capstyle="butt", snap=False
        )
    )
    fig.savefig(path, dpi=dpi, facecolor="black")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("job")
    ap.add_argument("--linewidth", type=float, default=1.0, help="line width in pixels")
    ap.add_argument("--mirror-y", action="store_true")
    args = ap.parse_args(argv)
    job_dir = Path(args.job)
    for c, png, v, e, cam, model in job_frames(job_dir):
        m = np.array(cam["model_matrix"])
        p_world = v @ m[:3, :3].T + m[:3, 3] if model else v
        png.parent.mkdir(parents=True, exist_ok=True)
        draw(segments(p_world, e, cam), c["width"], c["height"], args.linewidth, args.mirror_y, png)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
