"""Name what is wrong with a renderer from its images alone.

``diagnose_images(cand_images, oracle_segments, camera, flipped_segments=None) -> list[dict]``

The same fault names as the vertex diagnosis (:mod:`oracles.diagnosis.diagnose`, whose
module docstring defines them and the conventions of their fields), found
without the candidate's vertices: the candidate's drawn pixels are
*registered* to the oracle's lines.

Inputs, per frame of one case: the candidate's image (``(H, W)`` bool, drawn
pixels True) and the oracle's line segments in pixels (``(K, 2, 2)``:
depth-clipped in world space, projected by OpenCV, not clipped to the image;
:func:`oracle_segments`). The segments are the exact lines a correct renderer
would draw, so distances to them are sub-pixel, not quantised by a second
rasteriser.

Method
======
1. **Family.** In coordinates centred on the principal point (``u = x - cx``,
   ``v = y - cy``), the candidate's line pixels ``c`` are modelled as
   ``c = d * (P @ o) + b`` for a point ``o`` on the oracle's lines: ``P`` one of
   the 8 signed axis permutations (identity, the mirrors, the flip, the swap and
   the swap with each mirror), ``d`` a positive scale per axis, ``b`` an offset.
   This is exactly the family :mod:`oracles.diagnosis.diagnose` reads its faults from.
2. **Registration.** For each ``P``, from two starts (``d = 1, b = 0``; and
   per-axis mean and spread of the two pixel sets), iterate (ICP): pair every
   candidate pixel with the nearest point of the oracle's segments (mapped back
   through the current ``d, P, b``), and every oracle sample (points every
   :data:`SAMPLE_STEP_PX` along the segments) mapped into the candidate image
   with the nearest candidate pixel (``scipy.ndimage.distance_transform_edt``'s
   indices); drop pairs farther than :data:`PAIR_CAP_PX`; refit ``d, b`` per axis
   by least squares (linear in ``d_i, b_i`` for fixed ``P``). Both directions
   are needed: pixels-to-lines alone is minimised by shrinking the candidate
   onto a line, lines-to-pixels alone by a candidate that draws everywhere.
   All frames of a case are pooled into one fit, so the sub-pixel offset is
   averaged over every line pixel of the case.
3. **Residual and confidence.** The cost is the mean of the two directions'
   mean distances, each capped at :data:`PAIR_CAP_PX` (a point with no partner
   within the cap counts as the cap). The best ``P`` is the one of least cost;
   ``residual_px`` is its cost. A named fault's ``confidence`` is ``1 - cost /
   cost without it`` (:mod:`oracles.diagnosis.image_naming`); ``unexplained``'s is ``1 -
   best / second`` against the best *other* permutation.
4. **Depth flip.** A renderer that looks backward draws what a camera with its
   forward negated sees: ``flipped_segments``. When the candidate registers to
   those better than to the oracle's own, the answer is ``depth_flip`` alone
   (as in the vertex diagnosis). A candidate that draws nothing where the
   oracle draws lines, while the backward camera also sees nothing, is the
   image of "clips everything the oracle shows": ``depth_flip`` too.
5. **Faults.** With ``residual_px <= RESIDUAL_MAX_PX`` the faults are read off
   ``P``, ``d`` and ``b`` as in :mod:`oracles.diagnosis.diagnose` (step 4 there), with the
   pixel tolerances :data:`SCALE_TOL_PX` (a scale's largest effect on a drawn
   pixel) and :data:`OFFSET_TOL_PX`; otherwise the answer is ``unexplained``
   (a rotation, a shear, a 3D error: nothing of the family draws these pixels), or, when
   the identity fits and only the drawn sets differ, the visibility advice (:mod:`.image_visibility`).

Every fault carries ``confidence`` and ``residual_px``; ``pixel_offset`` is
given to sub-pixel (``dx, dy``), ``fov_mismatch`` with ``implied_fov_deg`` (or
``implied_ortho_height``), ``aspect_mismatch`` with ``implied_aspect``.
An offset is compared with the offset the same fit finds for a correct
aliased drawing of the fitted model's lines (the oracle's, scaled and mirrored
as fitted: :func:`quantisation_bias`), which is also given as
``uncertainty_px``: lines all at one fractional pixel position (a cube
square-on to a nearly orthographic camera) cannot show an offset below it.
Two permutations that fit equally well are ``ambiguous``; each fault's
confidence measures that fault; a fit that no start explains is restarted
from the scales convention mistakes give (:mod:`oracles.diagnosis.image_naming`).

Limits (measured in tests/test_image_diagnosis.py, stated in docs/frames.md):
the images must show enough line to fit (:data:`MIN_PIXELS` drawn pixels in a
case), the fault must move lines by more than the tolerances above, and a
scale below ~0.5 or above ~2 may not be recovered from the unit start.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..judge import tolerances as _tolerances
from .image_naming import name_faults, quantisation_bias, restart_scales, rotation_deg, rule_off_diagonal
from .image_visibility import in_place, visibility_fault

__all__ = ["diagnose_images", "oracle_segments", "flipped_camera", "PERMUTATIONS"]

#: Oracle lines are sampled this often (px) for the lines-to-pixels direction:
#: half a pixel, so every pixel a line crosses gets a sample.
SAMPLE_STEP_PX = 0.5
#: Pairs farther apart than this (px) are outliers (another line, a clipped
#: part), not a correspondence; it also bounds each point's cost. 8 px is well
#: above every in-family error the start leaves after the moment match (< 3 px
#: measured) and below the spacing of most distinct lines.
PAIR_CAP_PX = 8.0
#: A case needs this many drawn candidate pixels to be fitted (a 4-parameter
#: fit per axis pair is determined far earlier; 50 keeps stray pixels out).
MIN_PIXELS = 50
#: Points per frame and direction used in the fit (evenly subsampled above):
#: enough for a sub-pixel mean, few enough for a fast fit.
MAX_POINTS_PER_FRAME = 600
#: ... and per case: a case of more frames is fitted on fewer points of each
#: (six frames keep all 600), so a diagnosis costs about the same whatever the
#: number of frames: the offset is a mean over thousands of points either way.
MAX_POINTS_PER_CASE = 3600
#: ICP iterations of the final fit (converges in < 15 on the tests' cameras).
ITERATIONS = 30
#: Each permutation and start is first fitted this long on :data:`SCREEN_POINTS_PER_FRAME`
#: points; only the best two permutations are fitted to the end.
SCREEN_ITERATIONS = 6
SCREEN_POINTS_PER_FRAME = 250
SCREEN_POINTS_PER_CASE = 1500
#: A correct 1-px aliased renderer sits ~0.3 px from the exact lines (pixel
#: centres are within 0.5 px of a line across its minor axis); an anti-aliased
#: or 2-px-wide one ~0.5 px. A fit worse than this is no member of the family.
RESIDUAL_MAX_PX = 0.85
#: A permutation is named only when it fits this much better (relative cost)
#: than none: a symmetric picture (a cube seen along an axis, an orthographic
#: view of a centrally symmetric scene) fits several equally well (measured
#: relative differences below 1e-2), and then no mirror can be seen.
AMBIGUOUS_RATIO = 0.05
#: A scale is a fault when it moves some drawn pixel by more than this (px): the default of
#: Tolerances.scale_px (oracles.judge.tolerances, with its derivation).
SCALE_TOL_PX = _tolerances.SCALE_TOL_PX
#: The free affine fit's off-diagonal terms (rotation, shear) are a fault when
#: they move a pixel by more than this: <= 0.04 px on a correct renderer,
#: 0.77-1.17 px for a 0.5 degree roll (measured on the tests' cameras).
ROTATION_TOL_PX = 0.3
#: An offset is a fault when it exceeds this (px): the default of Tolerances.offset_px.
OFFSET_TOL_PX = _tolerances.OFFSET_TOL_PX
#: The fit pairs a case's candidate pixels with their frame's segments in one
#: array of (pixels x most segments in a frame) up to this many elements (a
#: few tens of MB); more (a dense mesh) are paired frame by frame.
STACK_LIMIT = 1 << 20


def _perm(swap: bool, sx: int, sy: int) -> np.ndarray:
    base = np.array([[0, 1], [1, 0]]) if swap else np.eye(2, dtype=int)
    return np.diag([sx, sy]) @ base


#: The 8 signed axis permutations ``P`` (``c = d * (P @ o) + b``), with the names they mean.
PERMUTATIONS = {
    (): _perm(False, 1, 1),
    ("mirror_horizontal",): _perm(False, -1, 1),
    ("mirror_vertical",): _perm(False, 1, -1),
    ("axis_flip",): _perm(False, -1, -1),
    ("axis_swap",): _perm(True, 1, 1),
    ("axis_swap", "mirror_horizontal"): _perm(True, -1, 1),
    ("axis_swap", "mirror_vertical"): _perm(True, 1, -1),
    ("axis_swap", "axis_flip"): _perm(True, -1, -1),
}


# ---------------------------------------------------------------- the oracle's lines

def oracle_segments(p_world: np.ndarray, edges: np.ndarray, camera) -> np.ndarray:
    """The lines a correct renderer draws: ``(K, 2, 2)`` pixel segment ends.

    Edges clipped to depth [near, far] in world space (:func:`oracles.candidates.draw.clip_depth`)
    and projected by OpenCV (:func:`oracles.references.opencv_oracle.project`); not clipped
    to the image.
    """
    from ..references import opencv_oracle
    from ..candidates.draw import clip_depth

    edges = np.asarray(edges, dtype=np.intp).reshape(-1, 2)
    if len(edges) == 0:
        return np.zeros((0, 2, 2))
    p_world = np.asarray(p_world, dtype=np.float64)
    _, ends = clip_depth(p_world[edges[:, 0]], p_world[edges[:, 1]], camera)
    if len(ends) == 0:
        return np.zeros((0, 2, 2))
    px = opencv_oracle.project(ends.reshape(-1, 3), camera).reshape(-1, 2, 2)
    return px[np.isfinite(px).all(axis=(1, 2))]


def flipped_camera(camera):
    """The camera looking backward (forward negated, up kept): what a depth-flipped renderer draws."""
    from wirecheck.core.camera import Camera

    return Camera(position=camera.position, forward=-np.asarray(camera.forward), up=camera.up,
                  fov_y_deg=camera.fov_y_deg, width=camera.width, height=camera.height, near=camera.near,
                  far=camera.far, projection=camera.projection, ortho_height=camera.ortho_height,
                  intrinsics=getattr(camera, "intrinsics", None))


# ---------------------------------------------------------------- geometry helpers

def _nearest_on_segments(q: np.ndarray, a: np.ndarray, b: np.ndarray):
    """For points ``q (N, 2)``: the nearest point on segments ``a -> b (K, 2)``, its distance and segment."""
    out = np.empty_like(q)
    dist = np.empty(len(q))
    which = np.empty(len(q), dtype=np.intp)
    ab = b - a
    len2 = np.maximum(ab[:, 0] * ab[:, 0] + ab[:, 1] * ab[:, 1], 1e-300)
    step = max(1, 2_000_000 // max(len(a), 1))
    for k in range(0, len(q), step):
        qx, qy = q[k:k + step, 0:1], q[k:k + step, 1:2]          # (n, 1): against every segment at once
        t = np.clip(((qx - a[:, 0]) * ab[:, 0] + (qy - a[:, 1]) * ab[:, 1]) / len2, 0.0, 1.0)
        fx, fy = a[:, 0] + t * ab[:, 0], a[:, 1] + t * ab[:, 1]
        dx, dy = fx - qx, fy - qy
        d2 = dx * dx + dy * dy
        j = np.argmin(d2, axis=1)
        rows = np.arange(len(qx))
        out[k:k + step, 0], out[k:k + step, 1] = fx[rows, j], fy[rows, j]
        dist[k:k + step] = np.sqrt(d2[rows, j])
        which[k:k + step] = j
    return out, dist, which


def _unit(v: np.ndarray) -> np.ndarray:
    n = np.hypot(v[:, 0], v[:, 1])
    return v / np.where(n > 0, n, 1.0)[:, None]


def _samples(segs: np.ndarray, width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
    """Points every SAMPLE_STEP_PX along the segments, within the image grown by half its size per side,
    and the unit tangent of their segment: ``((M, 2), (M, 2))``."""
    from wirecheck.core.projector.clipping import clip_to_image

    if len(segs) == 0:
        return np.zeros((0, 2)), np.zeros((0, 2))
    shift = np.array([width / 2.0, height / 2.0])
    _, q0, q1 = clip_to_image(segs[:, 0] + shift, segs[:, 1] + shift, 2 * width, 2 * height)
    q0, q1 = q0 - shift, q1 - shift
    n = np.maximum(1, np.ceil(np.hypot(*(q1 - q0).T) / SAMPLE_STEP_PX).astype(int))
    pts = [q0[i] + (q1[i] - q0[i]) * np.linspace(0.0, 1.0, n[i] + 1)[:, None] for i in range(len(q0))]
    if not pts:
        return np.zeros((0, 2)), np.zeros((0, 2))
    tangent = np.repeat(_unit(q1 - q0), n + 1, axis=0)
    return np.concatenate(pts), tangent


def _thin(points: np.ndarray, limit: int) -> np.ndarray:
    if len(points) <= limit:
        return points
    return points[np.linspace(0, len(points) - 1, limit).round().astype(int)]


def _normals(tangent_u: np.ndarray, a: np.ndarray) -> np.ndarray:
    """Unit normals, in the candidate image, of oracle lines with tangents ``tangent_u`` (u space) mapped by ``a``."""
    t = tangent_u @ a.T
    return _unit(np.stack([-t[:, 1], t[:, 0]], axis=1))


@dataclass
class _Frame:
    """One frame, centred on the principal point: the candidate's pixels and the oracle's lines."""

    cand: np.ndarray        # (N, 2) candidate pixel centres (subsampled)
    nearest: np.ndarray     # (H * W,) int32 flat index (row * W + col) of each pixel's nearest candidate pixel
    seg_a: np.ndarray       # (K, 2) oracle segment starts
    seg_b: np.ndarray       # (K, 2) and ends
    samples: np.ndarray     # (M, 2) points along the oracle's segments (subsampled)
    sample_tangents: np.ndarray   # (M, 2) unit tangent of each sample's segment
    seg_tangents: np.ndarray      # (K, 2) unit tangent of each segment


class _Registration:
    """The pooled frames of one case and the ICP fit of ``c = A (P o) + b`` (``A`` diagonal or affine).

    The frames are stacked once: every candidate pixel beside its own frame's
    segments (padded to the longest frame, :data:`STACK_LIMIT` elements at
    most; above it frame by frame), every oracle sample beside its frame's
    nearest-pixel map; an ICP step is then a few array operations, not a few
    per frame.
    """

    def __init__(self, frames: list[_Frame], width: int, height: int, centre: np.ndarray):
        self.frames = frames
        self.w, self.h = width, height
        self.centre = centre
        fwd = [f for f in frames if len(f.cand) and len(f.seg_a)]
        self._fwd_frames = fwd
        self._cand = np.concatenate([f.cand for f in fwd]) if fwd else np.zeros((0, 2))
        k_max = max((len(f.seg_a) for f in fwd), default=0)
        self._stacked = len(self._cand) * k_max <= STACK_LIMIT
        if self._stacked and fwd:
            counts = [len(f.cand) for f in fwd]
            seg_a = np.zeros((len(fwd), k_max, 2))
            ab = np.zeros((len(fwd), k_max, 2))
            tangents = np.zeros((len(fwd), k_max, 2))
            pad = np.ones((len(fwd), k_max), bool)
            for i, f in enumerate(fwd):
                k = len(f.seg_a)
                seg_a[i, :k], ab[i, :k], tangents[i, :k], pad[i, :k] = f.seg_a, f.seg_b - f.seg_a, f.seg_tangents, False
            frame = np.repeat(np.arange(len(fwd)), counts)
            # (N, K) each, contiguous: the ICP step's arithmetic runs on whole arrays
            self._ax, self._ay = seg_a[frame, :, 0], seg_a[frame, :, 1]
            self._abx, self._aby = ab[frame, :, 0], ab[frame, :, 1]
            self._len2 = np.maximum(self._abx * self._abx + self._aby * self._aby, 1e-300)
            self._seg_tangents, self._pad = tangents[frame], pad[frame]
        rev = [f for f in frames if len(f.samples) and len(f.cand)]
        self._rev_frames = rev
        self._samples = np.concatenate([f.samples for f in rev]) if rev else np.zeros((0, 2))
        self._sample_tangents = np.concatenate([f.sample_tangents for f in rev]) if rev else np.zeros((0, 2))
        self._rev_bounds = np.cumsum([0] + [len(f.samples) for f in rev])

    def _forward(self, q: np.ndarray):
        """Nearest oracle line point of each candidate pixel mapped to ``q`` (o space), its frame's lines
        only: ``(foot (N, 2), segment tangent (N, 2))``."""
        if not self._stacked:
            feet, tangents, start = [], [], 0
            for f in self._fwd_frames:
                foot, _, j = _nearest_on_segments(q[start:start + len(f.cand)], f.seg_a, f.seg_b)
                feet.append(foot)
                tangents.append(f.seg_tangents[j])
                start += len(f.cand)
            return np.concatenate(feet), np.concatenate(tangents)
        qx, qy = q[:, 0:1], q[:, 1:2]
        t = (qx - self._ax) * self._abx                    # the projection onto each segment, clipped
        t += (qy - self._ay) * self._aby
        t /= self._len2
        np.clip(t, 0.0, 1.0, out=t)
        dx = t * self._abx
        dx += self._ax
        dx -= qx
        dy = t * self._aby
        dy += self._ay
        dy -= qy
        dx *= dx
        dy *= dy
        dx += dy                                           # squared distance to each segment
        dx[self._pad] = np.inf
        j = np.argmin(dx, axis=1)
        rows = np.arange(len(q))
        tj = t[rows, j]
        foot = np.stack([self._ax[rows, j] + tj * self._abx[rows, j], self._ay[rows, j] + tj * self._aby[rows, j]],
                        axis=1)
        return foot, self._seg_tangents[rows, j]

    def pairs(self, p: np.ndarray, a: np.ndarray, b: np.ndarray):
        """Correspondences ``(u, c, dist, tangent_u, n_fwd, n_rev)`` for ``c ~ a @ u + b``, ``u = P o``.

        The first ``n_fwd`` pair candidate pixels with their nearest oracle
        line point (on their own frame's lines), the rest oracle samples with
        their frame's nearest candidate pixel; ``tangent_u`` is the oracle
        line's direction at ``u``.
        """
        us, cs, dists, ts = [], [], [], []
        back = p.T @ np.linalg.inv(a)                      # c -> o (a signed permutation's inverse is P.T)
        if len(self._cand):                                # candidate pixels -> nearest oracle line point
            foot, tangent = self._forward((self._cand - b) @ back.T)
            u = foot @ p.T
            us.append(u); cs.append(self._cand); ts.append(tangent @ p.T)
            dists.append(np.hypot(*(u @ a.T + b - self._cand).T))
        n_fwd = len(self._cand)
        n_rev = 0
        if len(self._samples):                             # oracle samples -> nearest candidate pixel
            t = self._samples @ (a @ p).T + (b + self.centre)
            col, row = np.rint(t[:, 0]), np.rint(t[:, 1])
            inside = np.flatnonzero((col >= 0) & (col < self.w) & (row >= 0) & (row < self.h))
            if len(inside):
                flat = (row[inside] * self.w + col[inside]).astype(np.int64)
                near = np.empty(len(inside), dtype=np.int64)
                bounds = np.searchsorted(inside, self._rev_bounds)
                for f, lo, hi in zip(self._rev_frames, bounds[:-1], bounds[1:]):
                    near[lo:hi] = f.nearest[flat[lo:hi]]
                c = np.empty((len(inside), 2))
                c[:, 1], c[:, 0] = np.divmod(near, self.w)
                c -= self.centre
                us.append(self._samples[inside] @ p.T)
                cs.append(c)
                ts.append(self._sample_tangents[inside] @ p.T)
                d = t[inside]
                d -= self.centre
                d -= c
                dists.append(np.hypot(d[:, 0], d[:, 1]))
                n_rev = len(inside)
        if not us:
            return np.zeros((0, 2)), np.zeros((0, 2)), np.zeros(0), np.zeros((0, 2)), 0, 0
        return (np.concatenate(us), np.concatenate(cs), np.concatenate(dists), np.concatenate(ts),
                n_fwd, n_rev)

    def cost(self, p, a, b) -> float:
        """Mean capped distance, the two directions weighted equally; the cap when a direction is empty."""
        _u, _c, dist, _t, n_fwd, n_rev = self.pairs(p, a, b)
        capped = np.minimum(dist, PAIR_CAP_PX)
        fwd = capped[:n_fwd].mean() if n_fwd else PAIR_CAP_PX
        rev = capped[n_fwd:].mean() if n_rev else PAIR_CAP_PX
        return float(0.5 * (fwd + rev))

    def matched(self, p, a, b) -> float:
        """Mean distance of the pairs within the cap, the two directions weighted equally (0 with none)."""
        _u, _c, dist, _t, n_fwd, _n_rev = self.pairs(p, a, b)
        means = [d[d < PAIR_CAP_PX].mean() for d in (dist[:n_fwd], dist[n_fwd:]) if (d < PAIR_CAP_PX).any()]
        return float(np.mean(means)) if means else 0.0

    def fit(self, p: np.ndarray, a: np.ndarray, b: np.ndarray, iterations: int = ITERATIONS,
            affine: bool = False):
        """ICP from ``(a, b)``: ``(a, b, cost)``; ``a`` stays diagonal unless ``affine``."""
        a, b = np.array(a, dtype=float), np.array(b, dtype=float)
        for _ in range(iterations):
            u, c, dist, tangent, _, _ = self.pairs(p, a, b)
            keep = dist < PAIR_CAP_PX
            if keep.sum() < 6:
                break
            u, c, n = u[keep], c[keep], _normals(tangent[keep], a)
            # point to line: n . (a @ u + b - c) = 0, linear in a and b for fixed normals
            if affine:
                design = np.column_stack([n[:, 0] * u[:, 0], n[:, 0] * u[:, 1], n[:, 1] * u[:, 0],
                                          n[:, 1] * u[:, 1], n[:, 0], n[:, 1]])
            else:
                design = np.column_stack([n[:, 0] * u[:, 0], n[:, 1] * u[:, 1], n[:, 0], n[:, 1]])
            x, *_ = np.linalg.lstsq(design, (n * c).sum(axis=1), rcond=None)
            new_a = x[:4].reshape(2, 2) if affine else np.diag(x[:2])
            new_b = x[-2:]
            if not affine and np.any(x[:2] <= 0):
                break
            if abs(np.linalg.det(new_a)) < 1e-6:
                break
            moved = np.max(np.abs(new_a - a)) * max(self.w, self.h) + np.max(np.abs(new_b - b))
            a, b = new_a, new_b
            if moved < 1e-3:
                break
        return a, b, self.cost(p, a, b)

    def moment_start(self, p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Per-axis scale and offset matching the mean and spread of the two point sets."""
        cand = np.concatenate([f.cand for f in self.frames])
        orac = np.concatenate([f.samples for f in self.frames]) @ p.T
        sc, so = cand.std(axis=0), orac.std(axis=0)
        d = np.clip(np.where(so > 0, sc / np.where(so > 0, so, 1.0), 1.0), 0.25, 4.0)
        return np.diag(d), cand.mean(axis=0) - d * orac.mean(axis=0)


def _register(coarse: _Registration, fine: _Registration):
    """Every permutation screened on ``coarse``; the best two refined on ``fine``: ``[(cost, names, P, a, b)]``."""
    screened = []
    for names, p in PERMUTATIONS.items():
        for a0, b0 in ((np.eye(2), np.zeros(2)), coarse.moment_start(p)):
            a, b, cost = coarse.fit(p, a0, b0, iterations=SCREEN_ITERATIONS)
            screened.append((cost, names, p, a, b))
    best = {}
    for cost, names, p, a, b in sorted(screened, key=lambda r: r[0]):
        best.setdefault(names, (cost, names, p, a, b))
    top = list(best.values())[:2]
    if () not in [names for _c, names, *_ in top]:
        top.append(best[()])                           # no permutation is always a contender
    out = []
    for _cost, names, p, a, b in top:
        a, b, cost = fine.fit(p, a, b)
        out.append((cost, names, p, a, b))
    return sorted(out, key=lambda r: r[0])


def _frames(cand_images, segments, camera, limit: int = MAX_POINTS_PER_FRAME, nearest=None) -> list[_Frame]:
    """``nearest``: the ``_Frame.nearest`` of earlier frames of the same images, reused (it does not depend
    on ``limit`` or the lines), instead of a distance transform per image."""
    cx, cy = camera.principal_point
    centre = np.array([cx, cy])
    out = []
    for i, (img, segs) in enumerate(zip(cand_images, segments)):
        img = np.asarray(img, bool)
        if img.shape != (camera.height, camera.width):
            raise ValueError(f"image shape {img.shape}: expected ({camera.height}, {camera.width})")
        segs = np.asarray(segs, dtype=np.float64).reshape(-1, 2, 2)
        rr, cc = np.nonzero(img)
        cand = _thin(np.stack([cc, rr], axis=1).astype(np.float64) - centre, limit)
        if nearest is not None:
            near = nearest[i]
        elif len(cand):
            near = _nearest_pixel_map(img, rr, cc)
        else:
            near = None
        samples, tangents = _samples(segs, camera.width, camera.height)
        keep = np.unique(np.linspace(0, len(samples) - 1, min(limit, len(samples))).round().astype(int))
        out.append(_Frame(cand=cand, nearest=near, seg_a=segs[:, 0] - centre, seg_b=segs[:, 1] - centre,
                          samples=samples[keep] - centre, sample_tangents=tangents[keep],
                          seg_tangents=_unit(segs[:, 1] - segs[:, 0])))
    return out


def _nearest_pixel_map(img: np.ndarray, rr: np.ndarray, cc: np.ndarray) -> np.ndarray:
    """``(H * W,)`` flat index (``row * W + col``) of a drawn pixel nearest to each pixel of ``img``.

    Exact wherever a drawn pixel lies within :data:`PAIR_CAP_PX` + 1 px; the
    distance transform runs on the drawn pixels' bounding box grown by that much
    only (a wireframe fills a fifth of a 640x480 frame, median of the bundled
    cases: 2.2x faster). A pixel outside it gets some drawn pixel, farther than
    the cap from any sample rounded to it (a pair the fit drops and the cost
    caps, whichever pixel it is). ``rr, cc``: the drawn pixels (``np.nonzero``).
    """
    from scipy.ndimage import distance_transform_edt

    h, w = img.shape
    m = int(math.ceil(PAIR_CAP_PX)) + 1          # > the cap + a rounded sample's 0.71 px from its pixel
    r0, r1 = max(int(rr.min()) - m, 0), min(int(rr.max()) + m + 1, h)
    c0, c1 = max(int(cc.min()) - m, 0), min(int(cc.max()) + m + 1, w)
    rows, cols = distance_transform_edt(~img[r0:r1, c0:c1], return_distances=False, return_indices=True)
    flat_type = np.int32 if img.size < 2 ** 31 else np.int64
    near = np.full((h, w), int(rr[0]) * w + int(cc[0]), dtype=flat_type)
    near[r0:r1, c0:c1] = (rows.astype(flat_type, copy=False) + r0) * w + (cols + c0)
    return near.ravel()


def _points_per_frame(n_frames: int, per_case: int, per_frame: int) -> int:
    """Points a frame contributes when a case of ``n_frames`` frames may use ``per_case`` (at most ``per_frame``)."""
    return max(1, min(per_frame, per_case // max(n_frames, 1)))


def _in_image(segments, camera) -> int:
    """Oracle samples inside the image, over all frames (is there anything to draw?)."""
    n = 0
    for segs in segments:
        s, _ = _samples(np.asarray(segs, dtype=np.float64).reshape(-1, 2, 2), camera.width, camera.height)
        n += int(((s[:, 0] >= -0.5) & (s[:, 0] <= camera.width - 0.5)
                  & (s[:, 1] >= -0.5) & (s[:, 1] <= camera.height - 0.5)).sum())
    return n


def diagnose_images(cand_images, oracle_segs, camera, flipped_segs=None, tol=None) -> list[dict]:
    """Name the faults of a renderer from its frames; ``[]`` when its lines are the oracle's.

    Parameters
    ----------
    cand_images : sequence of (H, W) bool ndarray
        The candidate's frames of one case (drawn pixels True).
    oracle_segs : sequence of (K, 2, 2) ndarray
        The oracle's line segments of the same frames (:func:`oracle_segments`).
    camera : core.camera.Camera
        The case's camera (principal point, FOV or ortho height, size).
    flipped_segs : sequence of (K, 2, 2) ndarray, optional
        The lines seen by :func:`flipped_camera`; without them ``depth_flip``
        is not considered.
    tol : oracles.judge.tolerances.Tolerances, optional
        Its ``scale_px`` and ``offset_px`` name a scale and an offset (default
        :data:`SCALE_TOL_PX`, :data:`OFFSET_TOL_PX`).

    Returns
    -------
    list of dict, primary fault first (precedence: oracles.faults);
    every fault has ``confidence`` and ``residual_px``.
    """
    scale_tol = SCALE_TOL_PX if tol is None else tol.scale_px
    offset_tol = OFFSET_TOL_PX if tol is None else tol.offset_px
    cand_images = list(cand_images)
    oracle_segs = list(oracle_segs)
    if len(cand_images) != len(oracle_segs):
        raise ValueError(f"{len(cand_images)} images but {len(oracle_segs)} frames of oracle lines")
    cx, cy = camera.principal_point
    centre = np.array([cx, cy])
    drawn = sum(int(np.count_nonzero(i)) for i in cand_images)
    oracle_drawn = _in_image(oracle_segs, camera)
    flipped_drawn = _in_image(flipped_segs, camera) if flipped_segs is not None else None
    if drawn == 0 and oracle_drawn == 0:
        return []
    if drawn == 0:
        if flipped_drawn == 0:
            return [{"name": "depth_flip", "confidence": 0.5, "residual_px": 0.0, "candidate_pixels": 0,
                     "note": "the candidate drew nothing where the oracle draws lines; a camera looking "
                             "backward sees nothing here either"}]
        return [{"name": "unexplained", "confidence": 1.0, "residual_px": PAIR_CAP_PX, "candidate_pixels": 0,
                 "note": "the candidate drew nothing where the oracle draws lines"}]
    if drawn < MIN_PIXELS:
        return [{"name": "unexplained", "confidence": 0.0, "residual_px": None, "candidate_pixels": drawn,
                 "underdetermined": True,
                 "note": f"only {drawn} drawn pixels: expected at least {MIN_PIXELS} to register"}]

    limit = _points_per_frame(len(cand_images), MAX_POINTS_PER_CASE, MAX_POINTS_PER_FRAME)
    screen = _points_per_frame(len(cand_images), SCREEN_POINTS_PER_CASE, SCREEN_POINTS_PER_FRAME)
    frames = _frames(cand_images, oracle_segs, camera, limit)
    nearest = [f.nearest for f in frames]                  # one distance transform per image
    fine = _Registration(frames, camera.width, camera.height, centre)
    coarse = _Registration(_frames(cand_images, oracle_segs, camera, screen, nearest),
                           camera.width, camera.height, centre)
    ranked = _register(coarse, fine)
    if ranked[0][0] > RESIDUAL_MAX_PX:               # no member fits from the usual starts: a large scale?
        ranked = restart_scales(coarse, fine, ranked, camera)
    plain = next(r for r in ranked if r[1] == ())
    if plain[0] <= ranked[0][0] * (1.0 + AMBIGUOUS_RATIO):
        ranked = [plain] + [r for r in ranked if r is not plain]     # a symmetric picture: no permutation
    cost, names, p, a, b = ranked[0]
    second = ranked[1][0] if len(ranked) > 1 else PAIR_CAP_PX
    confidence = float(max(0.0, 1.0 - cost / second)) if second > 0 else 0.0

    if flipped_segs is not None and flipped_drawn:
        back = _Registration(_frames(cand_images, flipped_segs, camera, limit, nearest), camera.width,
                             camera.height, centre)
        b_cost = back.cost(np.eye(2), np.eye(2), np.zeros(2))
        if b_cost < cost and b_cost <= RESIDUAL_MAX_PX:
            return [{"name": "depth_flip", "confidence": float(max(0.0, 1.0 - b_cost / cost)),
                     "residual_px": b_cost, "residual_unflipped_px": cost}]

    # the named model against a free affine map: a rotation or shear the family cannot draw
    reach = np.max(np.abs(np.concatenate([f.samples for f in frames]) @ p.T), axis=0)
    reach = np.minimum(reach, [camera.width / 2.0, camera.height / 2.0])   # the part an image can show
    a_free, b_free, cost_free = fine.fit(p, a, b, affine=True)
    off_diagonal = max(abs(a_free[0, 1]) * reach[1], abs(a_free[1, 0]) * reach[0])
    if cost <= RESIDUAL_MAX_PX and off_diagonal > ROTATION_TOL_PX:     # another aliased rule's own shear?
        off_diagonal = rule_off_diagonal(cand_images, oracle_segs, camera, (p, a, b), a_free, reach, off_diagonal)
    if cost > RESIDUAL_MAX_PX or off_diagonal > ROTATION_TOL_PX:
        fault = {"name": "unexplained", "confidence": confidence, "residual_px": cost,
                 "best_family": list(names) or ["none"],
                 "scale": np.diag(a).tolist(), "offset": b.tolist(), "affine": a_free.tolist(),
                 "affine_residual_px": cost_free, "off_diagonal_px": float(off_diagonal),
                 "rotation_deg": rotation_deg(a_free)}
        matched = fine.matched(p, a, b)         # the lines in place, only the drawn sets differ?
        if in_place(names, np.diag(a), b, off_diagonal, reach, matched,
                    (scale_tol, offset_tol, ROTATION_TOL_PX, RESIDUAL_MAX_PX)):
            fault = visibility_fault(fault, cand_images, oracle_segs, camera, matched)
        return [fault]
    return name_faults(fine, ranked, plain, camera, oracle_segs, reach, quantisation_bias, scale_tol,
                       offset_tol, AMBIGUOUS_RATIO, cost, cand_images)
