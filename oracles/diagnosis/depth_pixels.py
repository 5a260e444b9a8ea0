"""Where a depth map's pixels look: rows flipped, half a pixel off, K from the horizontal FOV.

A map drawn with a camera mistake shows the right surfaces at the wrong pixels: its pixel
``p`` holds the reference's depth at ``T(p)``. Each mistake is a map ``T``:

    name               T(p)                                  fitted
    mirror_vertical    (x, H - 1 - y)                        -
    mirror_horizontal  (W - 1 - x, y)                        -
    pixel_offset       p + (dx, dy)   (cx = W / 2: -0.5)     dx, dy (Gauss-Newton from the silhouettes' centroids)
    fov_mismatch       c + s (p - c)  (c the principal point) s (from the silhouettes' spread), perspective

The reference is read at ``T(p)`` by bilinear interpolation of ``w`` (``1 / depth`` under
perspective, where it is affine in the pixel coordinates on a plane; depth itself under
orthographic projection) between the four pixel centres around ``T(p)``, used only where the
four show the same face (``faces``: one id per planar face, -1 where none, :data:`UNDECIDED_FACE`
where which face shows is a rounding decision): there the
interpolation is exact. A model explains the map when the candidate's surface lands on the
reference's (at most ``NAMING.depth_outside_max`` of its pixels where all four neighbours show no
surface), at least ``NAMING.depth_interior_min`` of them land inside one face (oracles.tolerances: both
read by depth_faults when it is called), and every one of those is within
the slack of its allowance (oracles.diagnosis.depth_faults).
"""

from __future__ import annotations

import numpy as np

__all__ = ["UNDECIDED_FACE", "pixel_models"]

#: The face id of a pixel that shows a surface whose face is a rounding decision (beside an occlusion edge or a
#: clip plane's line): neither sampled (not inside one face) nor empty (not outside).
UNDECIDED_FACE = -2
#: Gauss-Newton steps of the fitted maps (converged to float rounding in 3 on the bundled cases).
STEPS = 6
#: Pixels a fit uses at most (every k-th of the candidate's surface): 4,000 fix two parameters
#: far below the residuals' scale; the fitted map is then judged on every pixel.
FIT_PIXELS = 4000


def pixel_models(cand, ref, faces, camera):
    """``(name, n_params, params, T)`` for each map, ``T`` taking ``(N, 2)`` pixels ``(x, y)`` to ``(N, 2)``.

    ``cand``, ``ref``: ``(H, W)`` depths, NaN where no surface; ``faces``: ``(H, W)`` int.
    """
    h, w = ref.shape
    yield "mirror_vertical", 0, {}, lambda p: np.column_stack([p[:, 0], h - 1 - p[:, 1]])
    yield "mirror_horizontal", 0, {}, lambda p: np.column_stack([w - 1 - p[:, 0], p[:, 1]])
    c_on, r_on = np.isfinite(cand), np.isfinite(ref)
    if c_on.sum() < 3 or r_on.sum() < 3:
        return
    c_rows_cols, r_rows_cols = np.argwhere(c_on), np.argwhere(r_on)  # once, for every fit below
    cy, cx = c_rows_cols.mean(axis=0)
    ry, rx = r_rows_cols.mean(axis=0)
    d = _fit(
        cand,
        ref,
        faces,
        camera,
        np.array([rx - cx, ry - cy]),
        lambda p, th: p + th,
        lambda p, th: np.broadcast_to(np.eye(2), (len(p), 2, 2)),
        c_rows_cols,
    )
    if d is not None:
        yield "pixel_offset", 2, {"dx": float(d[0]), "dy": float(d[1])}, lambda p, d=d: p + d
    if camera.projection != "perspective":
        return
    k = np.asarray(camera.K, dtype=np.float64)
    c0 = np.array([k[0, 2], k[1, 2]])
    spread_c = np.sqrt(((c_rows_cols[:, ::-1] - c0) ** 2).sum(axis=1).mean())
    spread_r = np.sqrt(((r_rows_cols[:, ::-1] - c0) ** 2).sum(axis=1).mean())
    s = _fit(
        cand,
        ref,
        faces,
        camera,
        np.array([spread_r / spread_c]),
        lambda p, th: c0 + th[0] * (p - c0),
        lambda p, th: (p - c0)[:, :, None],
        c_rows_cols,
    )
    if s is not None:
        scale = float(s[0])
        implied = float(np.degrees(2.0 * np.arctan((camera.height / 2.0) / (k[1, 1] / scale))))
        yield "fov_mismatch", 1, {"scale": scale, "implied_fov_y_deg": implied}, lambda p, s=scale: c0 + s * (p - c0)


def sample(ref, faces, camera, q):
    """The reference at pixels ``q`` ``(N, 2)``: ``(depth (N,), inside (N,) bool, outside (N,) bool, grad_w (N, 2))``.

    ``inside``: the four neighbours show one face (the value is exact); ``outside``: none of them
    shows a surface (or ``q`` is off the image); ``grad_w``: the gradient of ``w`` there.
    """
    h, w = ref.shape
    x0 = np.floor(q[:, 0]).astype(np.int64)
    y0 = np.floor(q[:, 1]).astype(np.int64)
    on_image = (x0 >= 0) & (y0 >= 0) & (x0 + 1 < w) & (y0 + 1 < h)
    xs, ys = np.clip(x0, 0, w - 2), np.clip(y0, 0, h - 2)
    i00, i10, i01, i11 = faces[ys, xs], faces[ys, xs + 1], faces[ys + 1, xs], faces[ys + 1, xs + 1]
    inside = on_image & (i00 >= 0) & (i10 == i00) & (i01 == i00) & (i11 == i00)
    # no surface at any of the four (-1); an undecided pixel (-2: a surface, which one a rounding decision) is
    # neither inside nor outside
    outside = ~on_image | ((i00 == -1) & (i10 == -1) & (i01 == -1) & (i11 == -1))
    persp = camera.projection == "perspective"
    with np.errstate(divide="ignore", invalid="ignore"):
        # the four neighbours' w, taken from ``ref`` at those pixels only (not 1 / ref over the whole image)
        w00, w10, w01, w11 = ref[ys, xs], ref[ys, xs + 1], ref[ys + 1, xs], ref[ys + 1, xs + 1]
        if persp:
            w00, w10, w01, w11 = 1.0 / w00, 1.0 / w10, 1.0 / w01, 1.0 / w11
        fx, fy = q[:, 0] - xs, q[:, 1] - ys
        top, bottom = w00 + fx * (w10 - w00), w01 + fx * (w11 - w01)
        val = top + fy * (bottom - top)
        grad = np.column_stack([(w10 - w00) + fy * ((w11 - w01) - (w10 - w00)), bottom - top])
        depth = 1.0 / val if persp else val
    inside &= np.isfinite(depth)
    return np.where(inside, depth, np.nan), inside, outside, grad


def _fit(cand, ref, faces, camera, theta, transform, jac_p, c_rows_cols):
    """Gauss-Newton on ``w_cand(p) = w_ref(T(p; theta))`` over the pixels landing inside one face
    (``c_rows_cols``: ``np.argwhere`` of the candidate's surface pixels)."""
    pts = c_rows_cols[:, ::-1].astype(np.float64)
    pts = pts[:: max(1, len(pts) // FIT_PIXELS)]
    persp = camera.projection == "perspective"
    wc = (
        1.0 / cand[pts[:, 1].astype(int), pts[:, 0].astype(int)]
        if persp
        else cand[pts[:, 1].astype(int), pts[:, 0].astype(int)]
    )
    theta = np.asarray(theta, dtype=np.float64)
    for _ in range(STEPS):
        if not np.all(np.isfinite(theta)):
            return None
        depth, inside, _outside, grad = sample(ref, faces, camera, transform(pts, theta))
        if inside.sum() < len(theta) + 1:
            return None
        wr = 1.0 / depth[inside] if persp else depth[inside]
        res = wc[inside] - wr
        jac = np.einsum("ni,nij->nj", grad[inside], jac_p(pts[inside], theta))
        step, *_ = np.linalg.lstsq(jac, res, rcond=None)
        theta = theta + step
    return theta
