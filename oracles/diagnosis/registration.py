"""A renderer's drawn pixels registered to the oracle's lines: the points sampled from each frame
(:func:`frame_samples`), the correspondences and the fit of ``c = d * (P @ o) + b`` (:class:`Registration`).

Its own module because the fit (oracles.diagnosis.image_diagnose), its naming
(oracles.diagnosis.image_naming) and the rule read (oracles.diagnosis.rule_read) all register.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from wirecheck.core.projector.clipping import clip_to_image

from ..segment_geometry import nearest_on_segments

__all__ = ["PERMUTATIONS", "Registration", "frame_samples", "points_per_frame", "register", "segments_in_image"]


#: Oracle lines are sampled this often (px) for the lines-to-pixels direction:
#: half a pixel, so every pixel a line crosses gets a sample.
SAMPLE_STEP_PX = 0.5


#: Pairs farther apart than this (px) are outliers (another line, a clipped
#: part), not a correspondence; it also bounds each point's cost. 8 px is well
#: above every in-family error the start leaves after the moment match (< 3 px
#: measured) and below the spacing of most distinct lines.
PAIR_CAP_PX = 8.0


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


def _unit(v: np.ndarray) -> np.ndarray:
    n = np.hypot(v[:, 0], v[:, 1])
    return v / np.where(n > 0, n, 1.0)[:, None]


def _samples(segs: np.ndarray, width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
    """Points every SAMPLE_STEP_PX along the segments, within the image grown by half its size per side,
    and the unit tangent of their segment: ``((M, 2), (M, 2))``."""
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

    cand: np.ndarray  # (N, 2) candidate pixel centres (subsampled)
    nearest: np.ndarray  # (H * W,) int32 flat index (row * W + col) of each pixel's nearest candidate pixel
    seg_a: np.ndarray  # (K, 2) oracle segment starts
    seg_b: np.ndarray  # (K, 2) and ends
    samples: np.ndarray  # (M, 2) points along the oracle's segments (subsampled)
    sample_tangents: np.ndarray  # (M, 2) unit tangent of each sample's segment
    seg_tangents: np.ndarray  # (K, 2) unit tangent of each segment


class Registration:
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
                foot, _, j = nearest_on_segments(q[start : start + len(f.cand)], f.seg_a, f.seg_b)
                feet.append(foot)
                tangents.append(f.seg_tangents[j])
                start += len(f.cand)
            return np.concatenate(feet), np.concatenate(tangents)
        qx, qy = q[:, 0:1], q[:, 1:2]
        t = (qx - self._ax) * self._abx  # the projection onto each segment, clipped
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
        dx += dy  # squared distance to each segment
        dx[self._pad] = np.inf
        j = np.argmin(dx, axis=1)
        rows = np.arange(len(q))
        tj = t[rows, j]
        foot = np.stack(
            [self._ax[rows, j] + tj * self._abx[rows, j], self._ay[rows, j] + tj * self._aby[rows, j]], axis=1
        )
        return foot, self._seg_tangents[rows, j]

    def pairs(self, p: np.ndarray, a: np.ndarray, b: np.ndarray):
        """Correspondences ``(u, c, dist, tangent_u, n_fwd, n_rev)`` for ``c ~ a @ u + b``, ``u = P o``.

        The first ``n_fwd`` pair candidate pixels with their nearest oracle
        line point (on their own frame's lines), the rest oracle samples with
        their frame's nearest candidate pixel; ``tangent_u`` is the oracle
        line's direction at ``u``.
        """
        us, cs, dists, ts = [], [], [], []
        back = p.T @ np.linalg.inv(a)  # c -> o (a signed permutation's inverse is P.T)
        if len(self._cand):  # candidate pixels -> nearest oracle line point
            foot, tangent = self._forward((self._cand - b) @ back.T)
            u = foot @ p.T
            us.append(u)
            cs.append(self._cand)
            ts.append(tangent @ p.T)
            dists.append(np.hypot(*(u @ a.T + b - self._cand).T))
        n_fwd = len(self._cand)
        n_rev = 0
        if len(self._samples):  # oracle samples -> nearest candidate pixel
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
        return (np.concatenate(us), np.concatenate(cs), np.concatenate(dists), np.concatenate(ts), n_fwd, n_rev)

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

    def fit(self, p: np.ndarray, a: np.ndarray, b: np.ndarray, iterations: int = ITERATIONS, affine: bool = False):
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
                design = np.column_stack(
                    [n[:, 0] * u[:, 0], n[:, 0] * u[:, 1], n[:, 1] * u[:, 0], n[:, 1] * u[:, 1], n[:, 0], n[:, 1]]
                )
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


def register(coarse: Registration, fine: Registration):
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
        top.append(best[()])  # no permutation is always a contender
    out = []
    for _cost, names, p, a, b in top:
        a, b, cost = fine.fit(p, a, b)
        out.append((cost, names, p, a, b))
    return sorted(out, key=lambda r: r[0])


def frame_samples(cand_images, segments, camera, limit: int = MAX_POINTS_PER_FRAME, nearest=None) -> list[_Frame]:
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
        out.append(
            _Frame(
                cand=cand,
                nearest=near,
                seg_a=segs[:, 0] - centre,
                seg_b=segs[:, 1] - centre,
                samples=samples[keep] - centre,
                sample_tangents=tangents[keep],
                seg_tangents=_unit(segs[:, 1] - segs[:, 0]),
            )
        )
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
    m = int(math.ceil(PAIR_CAP_PX)) + 1  # > the cap + a rounded sample's 0.71 px from its pixel
    r0, r1 = max(int(rr.min()) - m, 0), min(int(rr.max()) + m + 1, h)
    c0, c1 = max(int(cc.min()) - m, 0), min(int(cc.max()) + m + 1, w)
    rows, cols = distance_transform_edt(~img[r0:r1, c0:c1], return_distances=False, return_indices=True)
    flat_type = np.int32 if img.size < 2**31 else np.int64
    near = np.full((h, w), int(rr[0]) * w + int(cc[0]), dtype=flat_type)
    near[r0:r1, c0:c1] = (rows.astype(flat_type, copy=False) + r0) * w + (cols + c0)
    return near.ravel()


def points_per_frame(n_frames: int, per_case: int, per_frame: int) -> int:
    """Points a frame contributes when a case of ``n_frames`` frames may use ``per_case`` (at most ``per_frame``)."""
    return max(1, min(per_frame, per_case // max(n_frames, 1)))


def segments_in_image(segments, camera) -> int:
    """Oracle samples inside the image, over all frames (is there anything to draw?)."""
    n = 0
    for segs in segments:
        s, _ = _samples(np.asarray(segs, dtype=np.float64).reshape(-1, 2, 2), camera.width, camera.height)
        n += int(
            (
                (s[:, 0] >= -0.5)
                & (s[:, 0] <= camera.width - 0.5)
                & (s[:, 1] >= -0.5)
                & (s[:, 1] <= camera.height - 0.5)
            ).sum()
        )
    return n
