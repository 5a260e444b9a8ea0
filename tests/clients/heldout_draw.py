"""Held-out renderers of a wirecheck frames job: Pillow, matplotlib, OpenCV, a Wu and a Bresenham line of our own.

Written from the job's camera contract only (``job.json``'s conventions and a
frame's camera JSON), as a renderer's author would: nothing of wirecheck is
imported, neither its projection nor its rasteriser. Two projections, each its
own route to pixels:

- ``project_gl``: ``p_clip = gl_projection @ gl_view @ model_matrix @ [v, 1]``,
  clipped in clip space at near and far (``-w <= z <= w``), then the viewport
  (``x_px = (x_ndc + 1) W / 2 - 0.5``, ``y_px = H - (y_ndc + 1) H / 2 - 0.5``).
- ``project_lookat``: the camera fields (``position``, ``forward``, ``up``,
  ``fov_y_deg`` or ``ortho_height``), a pinhole about ((W-1)/2, (H-1)/2).

Both give segments in pixels (x right, y down, integers at pixel centres).
Each takes the typical mistake it can make: ``half_pixel`` (the viewport
without its -0.5: lines 0.5 px right and down), ``fov_axis="x"`` (the vertical
FOV or ortho height taken as the horizontal one: lines W/H larger),
``aspect=1.03`` (fx 3 % larger than fy: lines wider than they are tall),
``flip_rows=False`` (y up: the image upside down).

The drawers take those segments and the image size and return a uint8 grey
image, white lines on black: Pillow's ``ImageDraw.line`` (width 1-3, and 4x
supersampled), matplotlib's Agg ``Line2D`` (any width, antialiased or not, in
display coordinates: a pixel's centre is at +0.5), OpenCV's ``cv2.line``
(LINE_8, LINE_4, LINE_AA, 4 bits of sub-pixel ends), Xiaolin Wu's antialiased
line and Bresenham's integer line.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from job_files import job_frames

# ---- projections (two routes) ----


def _clip_param(fa, fb, t0, t1):
    """Liang-Barsky for one half-space ``f >= 0`` along ``f(t) = fa + t (fb - fa)``."""
    if fa < 0 and fb < 0:
        return 1.0, 0.0
    if fa < 0:
        t0 = max(t0, fa / (fa - fb))
    elif fb < 0:
        t1 = min(t1, fa / (fa - fb))
    return t0, t1


def project_gl(v, edges, cam, model=True, half_pixel=False):
    """Segments ``(K, 2, 2)`` in pixels by the GL matrices; ``half_pixel``: the viewport without -0.5."""
    w, h = cam["camera"]["width"], cam["camera"]["height"]
    m = np.array(cam["model_matrix"]) if model else np.eye(4)
    pvm = np.array(cam["gl_projection"]) @ np.array(cam["gl_view"]) @ m
    clip = np.c_[v, np.ones(len(v))] @ pvm.T
    shift = 0.0 if half_pixel else 0.5
    out = []
    for i, j in edges:
        a, b = clip[i], clip[j]
        t0, t1 = _clip_param(a[3] + a[2], b[3] + b[2], 0.0, 1.0)  # near: z >= -w
        t0, t1 = _clip_param(a[3] - a[2], b[3] - b[2], t0, t1)  # far: z <= w
        if t0 >= t1:
            continue
        ends = np.array([a + (b - a) * t0, a + (b - a) * t1])
        ndc = ends[:, :2] / ends[:, 3:]
        out.append(np.c_[(ndc[:, 0] + 1) * w / 2 - shift, h - (ndc[:, 1] + 1) * h / 2 - shift])
    return np.array(out).reshape(-1, 2, 2)


def project_lookat(v, edges, cam, model=True, fov_axis="y", flip_rows=True, aspect=1.0):
    """Segments in pixels from the camera fields; ``fov_axis="x"``: the FOV taken as horizontal;
    ``aspect``: fx taken as ``aspect`` fy (non-square pixels where the contract has square ones)."""
    c = cam["camera"]
    w, h = c["width"], c["height"]
    m = np.array(cam["model_matrix"]) if model else np.eye(4)
    p_world = v @ m[:3, :3].T + m[:3, 3]
    fwd = np.array(c["forward"], float)
    fwd /= np.linalg.norm(fwd)
    right = np.cross(fwd, c["up"])
    right /= np.linalg.norm(right)
    up = np.cross(right, fwd)
    rel = p_world - np.array(c["position"])
    p_cam = np.c_[rel @ right, rel @ up, rel @ fwd]  # x right, y up, z depth along forward
    span = h if fov_axis == "y" else w  # the image extent the FOV spans
    ortho = c["projection"] != "perspective"
    scale = span / c["ortho_height"] if ortho else (span / 2) / np.tan(np.radians(c["fov_y_deg"]) / 2)
    cx, cy = (w - 1) / 2, (h - 1) / 2
    out = []
    for i, j in edges:
        a, b = p_cam[i], p_cam[j]
        t0, t1 = _clip_param(a[2] - c["near"], b[2] - c["near"], 0.0, 1.0)
        t0, t1 = _clip_param(c["far"] - a[2], c["far"] - b[2], t0, t1)
        if t0 >= t1:
            continue
        ends = np.array([a + (b - a) * t0, a + (b - a) * t1])
        xy = ends[:, :2] * scale if ortho else ends[:, :2] * scale / ends[:, 2:]
        out.append(np.c_[cx + aspect * xy[:, 0], cy - xy[:, 1] if flip_rows else cy + xy[:, 1]])
    return np.array(out).reshape(-1, 2, 2)


def clip_rect(segs, w, h, margin=4.0):
    """Segments clipped to the image with a margin (float ends kept): drawers need not walk far lines."""
    out = []
    lo, hi = np.array([-margin, -margin]), np.array([w - 1 + margin, h - 1 + margin])
    for a, b in segs:
        t0, t1 = 0.0, 1.0
        for k in range(2):
            t0, t1 = _clip_param(a[k] - lo[k], b[k] - lo[k], t0, t1)
            t0, t1 = _clip_param(hi[k] - a[k], hi[k] - b[k], t0, t1)
        if t0 < t1:
            out.append([a + (b - a) * t0, a + (b - a) * t1])
    return np.array(out).reshape(-1, 2, 2)


# ---- drawers: segments in pixels -> uint8 image ----


def draw_pillow(segs, w, h, width=1):
    """Pillow's aliased line; its integer ends are the pixels the float ends round to (Pillow truncates floats)."""
    from PIL import Image, ImageDraw

    im = Image.new("L", (w, h), 0)
    d = ImageDraw.Draw(im)
    for a, b in clip_rect(segs, w, h):
        d.line([tuple(np.floor(a + 0.5)), tuple(np.floor(b + 0.5))], fill=255, width=width)
    return np.asarray(im).copy()


def draw_pillow_supersampled(segs, w, h, ss=4):
    """Pillow at ``ss`` x the size, a line ``ss`` sub-pixels wide, box-filtered down: antialiased 1 px."""
    from PIL import Image, ImageDraw

    im = Image.new("L", (w * ss, h * ss), 0)
    d = ImageDraw.Draw(im)
    for a, b in clip_rect(segs, w, h):
        qa, qb = (a + 0.5) * ss - 0.5, (b + 0.5) * ss - 0.5  # pixel centres in sub-pixels
        d.line([tuple(np.floor(qa + 0.5)), tuple(np.floor(qb + 0.5))], fill=255, width=ss)
    big = np.asarray(im).astype(float).reshape(h, ss, w, ss)
    return np.floor(big.mean(axis=(1, 3)) + 0.5).astype(np.uint8)


def draw_matplotlib(segs, w, h, linewidth_px=1.0, antialiased=True, half_pixel=False):
    """One Agg ``Line2D`` (NaN between segments) in display pixels: x + 0.5, H - y - 0.5 (y up in display)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D
    from matplotlib.transforms import IdentityTransform

    dpi = 72.0  # 1 point = 1 pixel
    fig = Figure(figsize=(w / dpi, h / dpi), dpi=dpi, facecolor="black")
    canvas = FigureCanvasAgg(fig)
    segs = clip_rect(segs, w, h)
    s = 0.0 if half_pixel else 0.5
    xs = np.c_[segs[:, :, 0] + s, np.full(len(segs), np.nan)].ravel()
    ys = np.c_[h - segs[:, :, 1] - s, np.full(len(segs), np.nan)].ravel()
    fig.add_artist(
        Line2D(
            xs,
            ys,
            transform=IdentityTransform(),
            color="white",
            linewidth=linewidth_px,
            antialiased=antialiased,
            solid_capstyle="butt",
            snap=False,
        )
    )
    canvas.draw()
    rgba = np.asarray(canvas.buffer_rgba())
    assert rgba.shape[:2] == (h, w), rgba.shape
    return rgba[:, :, 0].copy()


def draw_cv2(segs, w, h, line_type="LINE_8", shift=4):
    """OpenCV's ``cv2.line``, ends in fixed point (``shift`` fractional bits: integers are pixel centres)."""
    import cv2

    img = np.zeros((h, w), np.uint8)
    f = 1 << shift
    for a, b in clip_rect(segs, w, h):
        pa, pb = (tuple(int(x) for x in np.floor(p * f + 0.5)) for p in (a, b))
        cv2.line(img, pa, pb, 255, 1, getattr(cv2, line_type), shift)
    return img


def draw_wu(segs, w, h):
    """Xiaolin Wu's antialiased line: per major-axis step, coverage split between the two pixels it straddles."""
    cov = np.zeros((h, w))
    for a, b in clip_rect(segs, w, h):
        steep = abs(b[1] - a[1]) > abs(b[0] - a[0])
        (x0, y0), (x1, y1) = (a[::-1], b[::-1]) if steep else (a, b)
        if x0 > x1:
            x0, x1, y0, y1 = x1, x0, y1, y0
        grad = (y1 - y0) / (x1 - x0) if x1 > x0 else 0.0
        xa, xb = int(np.floor(x0 + 0.5)), int(np.floor(x1 + 0.5))
        xs = np.arange(xa, xb + 1)
        ys = y0 + grad * (xs - x0)
        # the share of each column [x - 0.5, x + 0.5] the segment covers (the ends' columns partly)
        span = np.clip(np.minimum(xs + 0.5, x1) - np.maximum(xs - 0.5, x0), 0.0, 1.0)
        if xa == xb:
            span = np.array([max(x1 - x0, 0.0)])
        yi = np.floor(ys).astype(int)
        fr = ys - yi
        for yy, ww in ((yi, (1 - fr) * span), (yi + 1, fr * span)):
            cols, rows = (yy, xs) if steep else (xs, yy)
            ok = (cols >= 0) & (cols < w) & (rows >= 0) & (rows < h)
            np.maximum.at(cov, (rows[ok], cols[ok]), ww[ok])
    return np.floor(cov * 255 + 0.5).astype(np.uint8)


def draw_bresenham(segs, w, h):
    """Bresenham's integer line between the pixels the ends round to (all octants)."""
    img = np.zeros((h, w), np.uint8)
    for a, b in clip_rect(segs, w, h):
        x0, y0 = (int(v) for v in np.floor(a + 0.5))
        x1, y1 = (int(v) for v in np.floor(b + 0.5))
        dx, dy = abs(x1 - x0), -abs(y1 - y0)
        sx, sy = (1 if x1 > x0 else -1), (1 if y1 > y0 else -1)
        err = dx + dy
        while True:
            if 0 <= x0 < w and 0 <= y0 < h:
                img[y0, x0] = 255
            if x0 == x1 and y0 == y1:
                break
            e2 = 2 * err
            if e2 >= dy:
                err += dy
                x0 += sx
            if e2 <= dx:
                err += dx
                y0 += sy
    return img


def render(job_dir: Path, draw, project=project_gl, **mistake) -> None:
    """Every listed frame of the job drawn by ``draw(segs, w, h)`` from ``project(..., **mistake)``, as PNG."""
    from PIL import Image

    for _case, png, v, e, cam, model in job_frames(job_dir):
        w, h = cam["camera"]["width"], cam["camera"]["height"]
        segs = project(v, e, cam, model=model, **mistake)
        png.parent.mkdir(parents=True, exist_ok=True)
        Image.fromarray(draw(segs, w, h)).save(png)
