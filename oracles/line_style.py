"""A renderer's line style, read from its frames, and its lines' geometry measured from the image.

The frames path (:mod:`oracles.frames_candidate`) compares a renderer's
frames with pyrender's by edge-pixel F1 at 0 and 1 px. F1@0px holds a
renderer to GL's pixel rule, which only a 1-px aliased line can follow: a
correct renderer that antialiases, draws wider lines, or follows another
aliased rule (Pillow's, TinyGL's) fails it with nothing wrong in its
geometry. This module reads what the frames hold and judges the geometry to
the same standard whatever the style.

Styles (:func:`classify`, from the images alone, pooled over a case's frames):

- ``aliased``: binary pixels (one level), about one pixel across the line;
- ``antialiased``: grey levels (coverage), about one pixel across;
- ``wide``: :data:`WIDE_MIN_PX` or more across (binary or grey), up to ~3 px.

The width is the median coverage across the line over the samples below (a
1-px aliased line 0.71 to 1, a 1-px antialiased line 1, a 3-px line 3); with too
few samples, the drawn coverage per unit length of the lines in the image.

Geometry (:class:`CaseStyle`): each oracle segment (``p0_px``, ``p1_px``,
:func:`oracles.image_diagnose.oracle_segments`, from the job's cameras) is
sampled at every integer step of its major axis; at each step the
intensity-weighted centroid of the image across the line (along the minor
axis, :data:`PROFILE_RADIUS_PX` each side) is the line's centre there. Samples
within :data:`GUARD_PX` of another segment or of the segment's own ends
(junctions: another line's pixels pull the centroid) are dropped. The
centroid's distance from the exact line, along the line's normal, is the
sample's offset; the case's offset ``(dx, dy)`` is the least-squares solution
of ``n . (dx, dy) = offset`` over every sample of every frame. For binary
styles the same measure on a correct drawing of the same lines (core's GL-like
raster for aliased lines; pixel centres within half the width for wide ones)
gives the quantisation bias (lines at one fractional position, a cube
square-on, sit up to half a pixel off in every correct drawing); the offset is
judged against it, as in :func:`oracles.image_diagnose.quantisation_bias`.

Raster rule (aliased lines): the pixels where the candidate and pyrender
differ are counted; one with a pixel of the other side among its 8 neighbours
is "off by one", at an end when within :data:`END_RADIUS_PX` of a segment end,
across the line otherwise.

The verdict (:meth:`CaseStyle.judge`):

- ``aliased`` with ``line_rule="gl"`` (default): F1@0px holds, as before.
  When F1@0px alone fails, the geometry measures right and every differing
  pixel is off by one, the fault is ``raster_rule`` (the shares across the
  line and at the ends), never ``unexplained``.
- ``antialiased`` and ``wide``, or any style with ``line_rule="geometry"``:
  F1@0px is reported, not judged (an antialiased or wide image cannot be held
  to GL's pixel rule); the geometry is judged instead: an offset beyond
  :data:`oracles.image_diagnose.OFFSET_TOL_PX` fails as ``pixel_offset`` with
  the measured ``dx, dy``. F1@1px holds for every style.
"""

from __future__ import annotations

import numpy as np

STYLES = ("aliased", "antialiased", "wide")
LINE_RULES = ("gl", "geometry")

#: Half the window across a line in which its centroid is taken (px): a 3-px line's half width
#: (1.5) plus an antialiased fringe (1) plus a pixel of slack for a half-pixel offset.
PROFILE_RADIUS_PX = 3
#: A sample is dropped when another segment, or its own segment's end, is this close (px):
#: the window plus half a pixel, so no other line's pixel enters it.
GUARD_PX = PROFILE_RADIUS_PX + 1.5
#: A differing pixel this close to a segment end (px) is counted "at the end".
END_RADIUS_PX = 1.5
#: Coverage per unit length from which a line is ``wide``: a 1-px aliased line has at most
#: sqrt(2) = 1.41 pixels per unit length (diagonal), a 2-px line 2.
WIDE_MIN_PX = 1.75
#: A case is binary (aliased) when at most this share of its drawn pixels is an intermediate
#: grey (between 1/8 and 7/8 of the line's level): antialiased lines have a third or more
#: (measured: 4x4 supersampled 1-px lines 0.6-0.8).
GREY_SHARE_MAX = 0.05
#: The line's level: this percentile of the drawn pixels' values (robust to a few bright
#: crossings of antialiased lines).
LEVEL_PERCENTILE = 99
#: A sample's window must hold this much coverage (in units of a fully covered pixel) to be a
#: sample of the line: half a pixel's worth, so a missing line is no sample (F1 fails on it).
MIN_MASS = 0.5
#: Samples a case keeps per frame (evenly thinned above): thousands of samples pin the pooled
#: offset far below 0.05 px, and the measure costs about the same whatever the mesh.
MAX_SAMPLES_PER_FRAME = 4000
#: Fewer samples than this in a case: the geometry is not measured (too little free line).
MIN_SAMPLES = 20
#: Aliased lines of another rule: the largest pooled centre offset (px) that is still "the geometry is
#: right". A rule that snaps the ends to pixel centres (Pillow's ImageDraw.line, TinyGL) moves each line
#: by up to half a pixel; pooled over a case's lines measured 0.00-0.27 px on the bundled scenes and
#: cases (Pillow), where a half-pixel offset measures 0.50. So an aliased image of another rule cannot
#: show an offset below this; the registration's pixel_offset (image_diagnose) is kept above it.
RULE_OFFSET_MAX_PX = 0.35

CAN_SHOW = {
    "aliased": "every pixel: the line rule (GL's or another), the geometry to the pixel, "
               "pixel offsets pooled over the lines",
    "antialiased": "each line's centre to a fraction of a pixel (the coverage centroid): offsets, "
                   "missing or extra lines",
    "wide": "each line's centre to a fraction of a pixel (the centroid across the line): offsets, "
            "missing or extra lines",
}
CANNOT_SHOW = {
    "aliased": "nothing the other styles show",
    "antialiased": "GL's pixel rule: coverage is not a choice of pixels, so F1@0px is reported, "
                   "not judged",
    "wide": "GL's pixel rule (F1@0px is reported, not judged); an end pixel where lines meet (the other "
            "line's width covers it)",
}


def _segments(p_model, edges, camera, m) -> np.ndarray:
    from .image_diagnose import oracle_segments

    p_world = np.asarray(p_model, dtype=np.float64) @ m[:3, :3].T + m[:3, 3]
    return oracle_segments(p_world, edges, camera)


def _seg_distance(q: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``(N, K)`` distance of points ``q (N, 2)`` to segments ``a -> b (K, 2)``."""
    ab = b - a
    len2 = np.maximum((ab * ab).sum(axis=1), 1e-300)
    t = np.clip(((q[:, None, :] - a[None]) * ab[None]).sum(axis=2) / len2, 0.0, 1.0)
    foot = a[None] + t[..., None] * ab[None]
    return np.hypot(*(foot - q[:, None, :]).transpose(2, 0, 1))


def measure(cov: np.ndarray, segs: np.ndarray, limit: int = MAX_SAMPLES_PER_FRAME):
    """The centroid samples of one frame: ``(normal (M, 2), offset (M,), segment (M,), width (M,))``.

    ``cov``: ``(H, W)`` float coverage (0 background, 1 a fully drawn pixel);
    ``segs``: ``(K, 2, 2)`` the oracle's segments in pixels. ``offset`` is the
    measured centre minus the exact line, along the unit ``normal``; ``width``
    the coverage across the line there (px, perpendicular to the line).
    """
    h, w = cov.shape
    r = PROFILE_RADIUS_PX
    segs = np.asarray(segs, dtype=np.float64).reshape(-1, 2, 2)
    normals, offsets, which, points, widths = [], [], [], [], []
    for i, (a, b) in enumerate(segs):
        d = b - a
        length = float(np.hypot(*d))
        if length < 2 * GUARD_PX + 1:
            continue
        major = 0 if abs(d[0]) >= abs(d[1]) else 1
        lo, hi = sorted((a[major], b[major]))
        guard = GUARD_PX * abs(d[major]) / length            # GUARD_PX along the line, on the major axis
        extent = w if major == 0 else h
        pos = np.arange(max(np.ceil(lo + guard), 0), min(np.floor(hi - guard), extent - 1) + 1)
        if len(pos) == 0:
            continue
        minor_exact = a[1 - major] + (pos - a[major]) * d[1 - major] / d[major]
        centre = np.rint(minor_exact)
        minor_extent = h if major == 0 else w
        inside = (centre - r >= 0) & (centre + r <= minor_extent - 1)
        pos, minor_exact, centre = pos[inside], minor_exact[inside], centre[inside]
        if len(pos) == 0:
            continue
        win = centre[:, None] + np.arange(-r, r + 1)[None]            # (n, 2r + 1) minor coordinates
        cols = np.broadcast_to(pos[:, None], win.shape)
        rows_i, cols_i = (win, cols) if major == 0 else (cols, win)
        g = cov[rows_i.astype(np.intp), cols_i.astype(np.intp)]
        mass = g.sum(axis=1)
        ok = mass >= MIN_MASS
        if not ok.any():
            continue
        centroid = (g[ok] * win[ok]).sum(axis=1) / mass[ok]
        resid_minor = centroid - minor_exact[ok]                      # along the minor axis
        unit = d / length
        normal = np.array([-unit[1], unit[0]])
        # a shift s along the normal moves the line's minor coordinate by s / |normal[minor]|
        offsets.append(resid_minor * normal[1 - major])
        widths.append(mass[ok] * abs(normal[1 - major]))        # a column crosses the line at 1 / |n_minor|
        normals.append(np.repeat(normal[None], ok.sum(), axis=0))
        which.append(np.full(ok.sum(), i))
        pt = np.empty((ok.sum(), 2))
        pt[:, major], pt[:, 1 - major] = pos[ok], minor_exact[ok]
        points.append(pt)
    if not offsets:
        return np.zeros((0, 2)), np.zeros(0), np.zeros(0, np.intp), np.zeros(0)
    normal, offset, seg, pt, width = (np.concatenate(normals), np.concatenate(offsets), np.concatenate(which),
                                      np.concatenate(points), np.concatenate(widths))
    if len(segs) > 1:                                   # drop samples near another segment (a junction, a crossing)
        keep = np.ones(len(pt), bool)
        for k in range(0, len(pt), 2048):
            dist = _seg_distance(pt[k:k + 2048], segs[:, 0], segs[:, 1])
            dist[np.arange(len(dist)), seg[k:k + 2048]] = np.inf
            keep[k:k + 2048] = dist.min(axis=1) > GUARD_PX
        normal, offset, seg, width = normal[keep], offset[keep], seg[keep], width[keep]
    keep = np.abs(offset) <= r - 0.5                    # a centroid at the window's edge is another line's
    normal, offset, seg, width = normal[keep], offset[keep], seg[keep], width[keep]
    if len(offset) > limit:
        idx = np.linspace(0, len(offset) - 1, limit).round().astype(int)
        normal, offset, seg, width = normal[idx], offset[idx], seg[idx], width[idx]
    return normal, offset, seg, width


def pooled_offset(normal: np.ndarray, offset: np.ndarray):
    """``(d (2,), determined (2,) bool)``: the least-squares ``d`` with ``n . d = offset``.

    A component the normals do not constrain (every line parallel to it, e.g.
    only horizontal lines say nothing of ``dx``) is 0 and not determined.
    """
    if len(offset) < MIN_SAMPLES:
        return np.zeros(2), np.zeros(2, bool)
    nn = normal.T @ normal
    determined = np.diag(nn) >= 0.05 * len(offset)     # >= 5 % of the samples' weight on that axis
    d = np.zeros(2)
    idx = np.flatnonzero(determined)
    if len(idx):
        sol, *_ = np.linalg.lstsq(normal[:, idx], offset, rcond=None)
        d[idx] = sol
    return d, determined


def _reference(segs: np.ndarray, shape, width_px: float) -> np.ndarray:
    """A correct binary drawing of ``segs``: core's raster (1 px) or pixel centres within half the width."""
    from wirecheck.core.clipping import clip_to_image
    from wirecheck.core.raster import line_pixels

    h, w = shape
    img = np.zeros(shape, bool)
    if len(segs) == 0:
        return img
    if width_px < WIDE_MIN_PX:
        _, q0, q1 = clip_to_image(segs[:, 0], segs[:, 1], w, h)
        rr, cc = line_pixels(q0, q1, w, h)
        img[rr, cc] = True
        return img
    half = round(width_px) / 2.0
    for a, b in segs:
        lo = np.maximum(np.floor(np.minimum(a, b) - half), 0).astype(int)
        hi = np.minimum(np.ceil(np.maximum(a, b) + half), [w - 1, h - 1]).astype(int)
        if np.any(hi < lo):
            continue
        yy, xx = np.mgrid[lo[1]:hi[1] + 1, lo[0]:hi[0] + 1]
        q = np.stack([xx.ravel(), yy.ravel()], axis=1).astype(float)
        near = _seg_distance(q, a[None], b[None])[:, 0] <= half
        img[yy.ravel()[near], xx.ravel()[near]] = True
    return img


def _off_by_one(cand: np.ndarray, orac: np.ndarray, ends: np.ndarray) -> dict:
    """Pixels where ``cand`` and ``orac`` differ, counted by where they are (module docstring)."""
    from scipy.ndimage import binary_dilation

    eight = np.ones((3, 3), bool)
    extra, missing = cand & ~orac, orac & ~cand
    near_other = (extra & binary_dilation(orac, eight)) | (missing & binary_dilation(cand, eight))
    rr, cc = np.nonzero(extra | missing)
    at_end = np.zeros(len(rr), bool)
    if len(rr) and len(ends):
        q = np.stack([cc, rr], axis=1).astype(float)
        for k in range(0, len(q), 4096):
            d = np.hypot(q[k:k + 4096, None, 0] - ends[None, :, 0], q[k:k + 4096, None, 1] - ends[None, :, 1])
            at_end[k:k + 4096] = d.min(axis=1) <= END_RADIUS_PX
    off1 = near_other[rr, cc]
    return {"oracle_pixels": int(orac.sum()), "differing": int(len(rr)),
            "off_by_one_across": int((off1 & ~at_end).sum()), "off_by_one_at_ends": int((off1 & at_end).sum()),
            "farther": int((~off1).sum())}


class CaseStyle:
    """One case's frames read for style and geometry, frame by frame; then the case judged.

    ``frame`` is called once per frame with the candidate's grey image (it
    returns the bool pixels the F1 scores compare: drawn where >= 128, the
    rule of docs/frames.md); ``judge`` once, after the F1 reasons are known.
    Only sums and samples are kept between frames, never an image.
    """

    def __init__(self, line_rule: str = "gl"):
        if line_rule not in LINE_RULES:
            raise ValueError(f"line rule {line_rule!r}: expected one of {', '.join(LINE_RULES)}")
        self.line_rule = line_rule
        self.hist = np.zeros(256, np.int64)
        self.length_px = 0.0
        self.samples = []                       # (normal, offset) per frame, coverage-normalised later
        self.raster = {"oracle_pixels": 0, "differing": 0, "off_by_one_across": 0, "off_by_one_at_ends": 0,
                       "farther": 0}
        self._frames = []                       # (segs, binary samples of the reference) per frame

    def frame(self, grey: np.ndarray, orac: np.ndarray, p_model, edges, camera, m) -> np.ndarray:
        """Read one frame (``grey`` ``(H, W)`` uint8, ``orac`` pyrender's bool pixels); the pixels compared."""
        from wirecheck.core.clipping import clip_to_image

        grey = np.asarray(grey)
        cand = grey >= 128
        if grey.dtype == bool:
            grey = grey.astype(np.uint8) * 255
        segs = _segments(p_model, edges, camera, m)
        self.hist += np.bincount(grey.ravel(), minlength=256)[:256]
        if len(segs):
            _, q0, q1 = clip_to_image(segs[:, 0], segs[:, 1], camera.width, camera.height)
            self.length_px += float(np.hypot(*(q1 - q0).T).sum())
        level = max(int(grey.max()), 1)
        normal, offset, _, width = measure(grey / level, segs)
        self.samples.append((normal, offset, width))
        self._frames.append((segs, grey.shape))
        counts = _off_by_one(cand, orac, segs.reshape(-1, 2))
        self.raster = {k: v + counts[k] for k, v in self.raster.items()}
        return cand

    # ---- reading the case

    def classify(self) -> dict:
        """``{"style", "width_px", "grey_share", "level"}`` from the pooled histogram and the samples' widths."""
        drawn = self.hist[1:]
        n = int(drawn.sum())
        if n == 0:
            return {"style": "aliased", "width_px": 0.0, "grey_share": 0.0, "level": 0}
        cum = np.cumsum(drawn)
        level = int(np.searchsorted(cum, LEVEL_PERCENTILE / 100.0 * n)) + 1
        values = np.arange(1, 256)
        grey = drawn[(values > level / 8.0) & (values < level * 7.0 / 8.0)].sum()
        widths = np.concatenate([x[2] for x in self.samples]) if self.samples else np.zeros(0)
        if len(widths) >= MIN_SAMPLES:          # across the free parts of the lines: no junction or crossing
            width = float(np.median(widths))
        else:                                   # too little free line: all coverage over the lines' length
            coverage = float((np.minimum(values / level, 1.0) * drawn).sum())
            width = coverage / self.length_px if self.length_px > 0 else 0.0
        grey_share = float(grey) / n
        style = "wide" if width >= WIDE_MIN_PX else "antialiased" if grey_share > GREY_SHARE_MAX else "aliased"
        return {"style": style, "width_px": round(width, 3), "grey_share": round(grey_share, 4), "level": level}

    def geometry(self, read: dict) -> dict:
        """The pooled offset of the case's lines, and the bias a correct drawing of this style shows."""
        normal = np.concatenate([s[0] for s in self.samples]) if self.samples else np.zeros((0, 2))
        offset = np.concatenate([s[1] for s in self.samples]) if self.samples else np.zeros(0)
        d, determined = pooled_offset(normal, offset)
        bias = np.zeros(2)
        binary = read["grey_share"] <= GREY_SHARE_MAX
        if binary and determined.any():
            rn, ro = [], []
            for segs, shape in self._frames:
                n_ref, o_ref, _, _ = measure(_reference(segs, shape, read["width_px"]).astype(float), segs)
                rn.append(n_ref)
                ro.append(o_ref)
            bias, _ = pooled_offset(np.concatenate(rn), np.concatenate(ro))
        return {"samples": int(len(offset)), "offset_px": [float(d[0]), float(d[1])],
                "determined": [bool(determined[0]), bool(determined[1])],
                "bias_px": [float(bias[0]), float(bias[1])],
                "spread_px": float(np.std(offset)) if len(offset) else None}

    def judge(self, rec: dict, reasons: list, tol) -> list:
        """The case's reasons with the style's judgement joined; ``rec`` gains ``line_style`` and faults.

        ``reasons``: the F1 reasons (each starting "pixel F1@1px" or "pixel F1@0px").
        """
        from .diagnose import FAULT_ORDER
        from .image_diagnose import OFFSET_TOL_PX

        read = self.classify()
        geo = self.geometry(read)
        style = read["style"]
        by_rule = style == "aliased" and self.line_rule == "gl"
        d, bias = np.array(geo["offset_px"]), np.array(geo["bias_px"])
        measured = geo["samples"] >= MIN_SAMPLES
        off = float(np.max(np.abs(d - bias)))
        aliased = style == "aliased"
        tol_px = RULE_OFFSET_MAX_PX if aliased else OFFSET_TOL_PX
        out = {**read, "line_rule": self.line_rule,
               "judged_by": "GL's pixel rule (F1@0px) and the geometry" if by_rule else
                            "the geometry (line centres); F1@0px is reported, not judged",
               "can_show": CAN_SHOW[style], "cannot_show": CANNOT_SHOW[style], "offset_tol_px": tol_px,
               "geometry": geo}
        reasons = list(reasons)
        faults = list(rec.get("faults") or [])
        f0 = [r for r in reasons if r.startswith("pixel F1@0px")]
        if not by_rule:
            reasons = [r for r in reasons if r not in f0]
        # lines the registration finds mirrored, swapped or scaled are not where the oracle's are: a centroid
        # of what lies near the oracle's lines then measures stray crossings, not an offset
        placed = all(f["name"] in ("pixel_offset", "unexplained") for f in faults)
        measured = measured and placed
        if measured and off > tol_px and not aliased:
            # the measured offset replaces the registration's (pooled over thick pixels, ~0.06 px off)
            faults = [f for f in faults if f["name"] not in ("pixel_offset", "unexplained")]
            faults.append({"name": "pixel_offset", "dx": float(d[0] - bias[0]), "dy": float(d[1] - bias[1]),
                           "uncertainty_px": float(np.max(np.abs(bias))), "confidence": 1.0,
                           "residual_px": geo["spread_px"], "measured_by": "line centroids"})
        if measured and off > tol_px and not by_rule:
            reasons.append(f"line centres offset by ({d[0] - bias[0]:.2f}, {d[1] - bias[1]:.2f}) px "
                           f"> {tol_px} ({style} lines, {geo['samples']} samples)")
        rs = self.raster
        if aliased and rs["differing"]:
            out["raster_rule"] = {
                "share_off_by_one_across": rs["off_by_one_across"] / max(rs["oracle_pixels"], 1),
                "share_off_by_one_at_ends": rs["off_by_one_at_ends"] / max(rs["oracle_pixels"], 1),
                "share_farther": rs["farther"] / max(rs["oracle_pixels"], 1)}
        geometry_right = measured and off <= tol_px
        if aliased and not by_rule and geometry_right:      # the geometry only: within the rule's snap
            faults = [f for f in faults if f["name"] != "pixel_offset"]
        if by_rule and f0 and len(f0) == len(reasons) and geometry_right and rs["farther"] == 0:
            faults = [f for f in faults if f["name"] not in ("unexplained", "pixel_offset")]
            faults.append({"name": "raster_rule", **out["raster_rule"], "confidence": 1.0,
                           "offset_px": [float(d[0] - bias[0]), float(d[1] - bias[1])],
                           "residual_px": geo["spread_px"],
                           "note": f"the lines are where the oracle's are (centres within {off:.2f} px) but "
                                   "their pixels follow another line rule than GL's: check the line "
                                   "rasteriser (its rule across the line and at the ends), not the camera; "
                                   "--line-rule geometry judges the geometry only"})
        rec["faults"] = sorted(faults, key=lambda f: FAULT_ORDER.index(f["name"]))
        rec["line_style"] = out
        return reasons
