"""A renderer's line style, read from its frames, and its lines' geometry measured from the image.

The frames path (:mod:`oracles.candidates.frames_candidate`) compares a renderer's
frames with pyrender's by edge-pixel F1 at 0 and 1 px. F1@0px holds a
renderer to GL's pixel rule, which only a 1-px aliased line can follow: a
correct renderer that antialiases, draws wider lines, or follows another
aliased rule (Pillow's, TinyGL's) fails it with nothing wrong in its
geometry. This module reads what the frames hold and judges the geometry to
the same standard whatever the style.

Styles (:func:`classify`, from the images alone, pooled over a case's frames):

- ``aliased``: binary pixels (one level), about one pixel across the line;
- ``antialiased``: grey levels (coverage), about one pixel across;
- ``wide``: :attr:`oracles.tolerances.NamingThresholds.wide_min_px` or more across (binary or grey), up to ~3 px; binary lines drawing
  :attr:`oracles.tolerances.NamingThresholds.wide_pixel_ratio` times the oracle's pixels too (2 px at least).

The width is the median coverage across the line over the samples below (a
1-px aliased line 0.71 to 1, a 1-px antialiased line 1, a 3-px line 3); with too
few samples, the drawn coverage per unit length of the lines in the image.

Geometry (:class:`CaseStyle`, :func:`measure`): each oracle segment
(``p0_px``, ``p1_px``, :func:`oracles.diagnosis.image_diagnose.oracle_segments`, from the
job's cameras) is sampled at every integer step of its major axis; at each
step the intensity-weighted centroid of the image across the line (along the
minor axis, :data:`PROFILE_RADIUS_PX` each side) is the line's centre there.
Windows within :data:`GUARD_PX` of another segment or of the segment's own
ends (junctions: another line's pixels pull the centroid) are dropped. The
centroid's distance from the exact line, along the line's normal, is the
sample's offset. Pooled over every sample of a case's frames:

- ``offset_px``: the least-squares ``(dx, dy)`` of ``n . (dx, dy) = offset``;
- ``warp_px``: how much more an affine map (a scale, rotation or shear about
  the principal point) moves the lines, along their normals, than that
  offset (the 99th percentile over the samples, :meth:`CaseStyle.geometry`).

For binary styles the same measure on a correct drawing of the same lines (core's GL-like raster
for aliased lines; pixel centres within half the width for wide ones) is subtracted: lines at one
fractional position (a cube square-on) sit up to half a pixel off in every correct drawing, as in
:func:`oracles.diagnosis.model_lines.quantisation_bias`; at an exact tie (a band edge on a pixel
centre) either choice reads 0 (:func:`oracles.judge.line_ties.fold_ties`). Lines that the registration
finds mirrored or swapped, or that fill fewer than :attr:`oracles.tolerances.NamingThresholds.min_found_share` of
the windows, are not measured (the centroids would be of stray crossings). Binary lines of an even
width may lean half a pixel either side, edge by edge: where the symmetric band fails them, each
edge's lean is fitted with one offset for the case (:mod:`oracles.judge.even_lean`).

Ends (:func:`oracles.judge.free_ends.measure_ends`): each free end's coverage along its line, where it
falls to half the line's width; the median over a case's free ends is judged
(Tolerances.end_px, past the cap of half the width a renderer may draw).

Raster rule (aliased lines): the pixels where the candidate and pyrender
differ are counted; one with a pixel of the other side among its 8 neighbours
is "off by one", at an end when within :data:`END_RADIUS_PX` of a segment end,
across the line otherwise.

What the read decides (:meth:`CaseStyle.read` returns it; oracles.judge.decide.judge_style holds it to
the tolerances, oracles.judge.name_faults names it):

- ``aliased`` with ``line_rule="gl"`` (default): F1@0px holds, as before.
  When F1@0px alone fails, the lines are measured in place (offset within
  :data:`RULE_OFFSET_MAX_PX`, no warp) and every differing pixel is off by
  one, the fault is ``raster_rule`` (the shares across the line and at the
  ends), never ``unexplained``.
- ``antialiased`` and ``wide``, or any style with ``line_rule="geometry"``:
  F1@0px is reported, not judged (an antialiased or wide image cannot be held
  to GL's pixel rule); the geometry is judged instead: an offset beyond
  :data:`oracles.diagnosis.image_diagnose.OFFSET_TOL_PX` (binary lines, 1 px or wide:
  :data:`RULE_OFFSET_MAX_PX`) fails as ``pixel_offset`` with the measured
  ``dx, dy``, a warp beyond :data:`oracles.diagnosis.image_diagnose.SCALE_TOL_PX` (binary
  lines: half a pixel more) fails too, and so do ends that stop short or run
  on (``line_end_bias``); the registration's offset and scale faults give way
  to the measure's. F1 holds for every style, at the lines' width (oracles.judge.f1_radius).
"""

from __future__ import annotations

import numpy as np
from wirecheck.core.projector import raster
from wirecheck.core.projector.clipping import clip_to_image

from .. import faults as catalogue
from .. import line_model, tolerances
from ..diagnosis.diagnose import diagnose_lines
from ..diagnosis.image_diagnose import oracle_segments
from ..faults import Fault
from . import coverage_pixels, even_lean, free_ends, line_ties, line_windows
from .case_samples import CaseSamples
from .decide import ROUNDED_RULE_NAME
from .evidence import StyleRead
from .line_profile import GUARD_PX, PROFILE_RADIUS_PX, pooled_offset

STYLES = ("aliased", "antialiased", "wide")
#: ``--line-rule``: ``any`` (the default) holds aliased lines to a correct drawing under GL's rule or under
#: the rounded-ends rule (oracles.line_model); ``gl`` to GL's alone (another rule's correct drawing
#: is ``raster_rule``); ``geometry`` judges the lines' centres only.
LINE_RULES = ("any", "gl", "geometry")
#: What each rule read from the pixels is, for the report and the summary line.
RULE_NAMES = {"gl": "GL's diamond exit", "rounded": ROUNDED_RULE_NAME}

#: A differing pixel this close to a segment end (px) is counted "at the end".
END_RADIUS_PX = 1.5
#: The line's level: this percentile of the drawn pixels' values (robust to a few bright
#: crossings of antialiased lines).
LEVEL_PERCENTILE = 99
#: Samples a case keeps per frame (evenly thinned above): thousands of samples pin the pooled
#: offset far below 0.05 px, and the measure costs about the same whatever the mesh.
MAX_SAMPLES_PER_FRAME = 4000
#: ... and per case: past it every frame's samples are halved, so a case's memory stays bounded
#: whatever its number of frames (the offset is a mean over tens of thousands of samples either way).
MAX_SAMPLES_PER_CASE = 48_000
#: Registration faults that put the lines elsewhere than the oracle's: their centroids are not measured.
PLACEMENT_FAULTS = catalogue.names("orientation")
#: Aliased lines of another rule, and binary wide lines: the largest pooled centre offset (px) that is
#: still "the geometry is right": the default of Tolerances.rule_offset_px (oracles.tolerances).
RULE_OFFSET_MAX_PX = tolerances.RULE_OFFSET_MAX_PX

CAN_SHOW = {
    "aliased": "every pixel: the line rule (GL's or another), the geometry to the pixel, "
    "pixel offsets pooled over the lines",
    "antialiased": "each line's centre to a fraction of a pixel (the coverage centroid): offsets, scale, "
    "missing or extra lines, where free ends stop",
    "wide": "each line's centre to a fraction of a pixel (the centroid across the line): offsets, scale, "
    "missing or extra lines, where free ends stop (beyond the cap)",
}
CANNOT_SHOW = {
    "aliased": "one line's own centre to a fraction of a pixel (a 1-px line is a choice of pixels: offsets "
    "are pooled over the lines)",
    "antialiased": "GL's pixel rule: coverage is not a choice of pixels, so F1@0px is reported, not judged; an "
    "end where lines meet; a line under 0.5 px wide (coverage_pixels: no drawn pixel at a tie)",
    "wide": "GL's pixel rule (F1@0px is reported, not judged); an end pixel where lines meet (the other line's "
    "width covers it); binary: a centre offset under 0.35 px; an even width (2 px), whose lines may lean "
    "half a pixel either side edge by edge: a move all its lines lean against, a half-pixel move "
    "to better than 0.3-0.9 px when the ends are rounded to pixels (oracles.judge.even_lean)",
}


def _segments(p_model, edges, camera, m) -> np.ndarray:
    p_world = np.asarray(p_model, dtype=np.float64) @ m[:3, :3].T + m[:3, 3]
    return oracle_segments(p_world, edges, camera)


def windows(segs: np.ndarray, shape) -> dict:
    """Where :func:`measure` looks along the oracle's segments, clear of junctions: the image's part of it.

    Depends on the segments and the image size only, so one frame's windows
    serve every image measured on its lines (the candidate's, a reference
    drawing's). Along each segment long enough, at every integer step of its
    major axis :data:`GUARD_PX` clear of its ends and inside the image, a
    window across it (:data:`PROFILE_RADIUS_PX` each side); segment by segment,
    each in ascending steps (oracles.judge.line_windows.windows: ``flat``,
    ``minor``, ``exact``, ``across``, and ``normal``, ``segment``, ``point`` as
    :func:`measure` returns them).
    """
    return line_windows.windows(segs, shape, PROFILE_RADIUS_PX, GUARD_PX)


def measure(
    cov: np.ndarray, segs: np.ndarray, limit: int = MAX_SAMPLES_PER_FRAME, wins: dict | None = None, level: float = 1.0
) -> dict:
    """The centroid samples of one frame (module docstring), as a dict of arrays of ``M`` samples.

    ``cov / level``: ``(H, W)`` coverage (0 background, 1 a fully drawn pixel;
    ``cov`` may be the grey levels and ``level`` the line's, so that only the
    windows' pixels are divided); ``segs``: ``(K, 2, 2)`` the oracle's segments
    in pixels; ``wins``: their :func:`windows`, when the caller has them.
    ``offset`` is the measured centre minus the exact line along the unit
    ``normal``, at ``point`` on the exact line; ``width`` the coverage across
    the line there (px, perpendicular to the line); ``segment`` its segment.
    ``windows``: the windows looked at (clear of junctions); ``found``: those
    that held a line (``M`` of them kept, at most ``limit``).
    """
    r = PROFILE_RADIUS_PX
    wins = windows(segs, np.shape(cov)) if wins is None else wins
    g = np.reshape(cov, -1)[wins["flat"]] / level
    mass = g.sum(axis=1)
    centroid = (g * wins["minor"]).sum(axis=1) / np.maximum(mass, 1e-300)
    # a shift s along the normal moves the line's minor coordinate by s / |normal[minor]|
    out = {
        "normal": wins["normal"],
        "offset": (centroid - wins["exact"]) * wins["across"],
        "width": mass * np.abs(wins["across"]),  # a column crosses the line at 1 / |n_minor|
        "segment": wins["segment"],
        "point": wins["point"],
        "mass": mass,
    }
    windows_n = len(out["offset"])
    # a line is there (half a pixel's coverage), and its centroid is not at the window's edge (another line's)
    keep = np.flatnonzero((out["mass"] >= tolerances.NAMING.profile_min_mass) & (np.abs(out["offset"]) <= r - 0.5))
    found = len(keep)
    if found > limit:  # evenly thinned: one gather of each field
        keep = keep[np.linspace(0, found - 1, limit).round().astype(int)]
    out = {k: v[keep] for k, v in out.items()}
    out["windows"], out["found"] = windows_n, found
    return out


def fit_lines(normal: np.ndarray, offset: np.ndarray, point: np.ndarray, centre: np.ndarray):
    """The map that moves the exact lines onto the measured centres: ``(d (2,), m (2, 2)) or None``.

    Least squares of ``n . (d + m (p - centre)) = offset``: ``d`` the offset at
    the principal point, ``m`` the scale, rotation and shear (``A - I``). None
    when the samples cannot fix the six numbers (too few, or lines of too few
    directions and places).
    """
    if len(offset) < tolerances.NAMING.profile_min_samples:
        return None
    q = point - centre
    design = np.column_stack([normal, normal[:, :1] * q, normal[:, 1:] * q])  # d_x, d_y, m_xx, m_xy, m_yx, m_yy
    scale = np.maximum(np.abs(design).max(axis=0), 1e-12)
    sv = np.linalg.svd(design / scale, compute_uv=False)
    if sv[-1] < 1e-3 * sv[0]:
        return None
    x, *_ = np.linalg.lstsq(design / scale, offset, rcond=None)
    x = x / scale
    return x[:2], x[2:].reshape(2, 2)


def _reference(segs: np.ndarray, shape, width_px: float, clipped=None, drawn: int = 0) -> np.ndarray:
    """A correct binary drawing of ``segs``: core's raster (1 px), or a band centred on them holding the
    candidate's ``drawn`` pixels (oracles.line_model.band_holding; ``drawn`` 0: the width rounded).

    ``clipped``: ``clip_to_image(segs[:, 0], segs[:, 1], W, H)`` of this ``shape``, when the caller has it.
    """
    h, w = shape
    if len(segs) == 0:
        return np.zeros(shape, bool)
    if width_px < tolerances.NAMING.wide_min_px:
        img = np.zeros(shape, bool)
        _, q0, q1 = clip_to_image(segs[:, 0], segs[:, 1], w, h) if clipped is None else clipped
        rr, cc = raster.line_pixels(q0, q1, w, h)
        img[rr, cc] = True
        return img
    return line_model.band_holding(segs, shape, drawn, width_px)


def _off_by_one(fp, ends: np.ndarray) -> dict:
    """Pixels where the candidate and the oracle differ (``fp``: the frame's
    oracles.judge.frame_pixels.FramePixels), counted by where they are (module docstring)."""
    h, w = fp.shape
    c_only, o_only = fp.only()
    flat = np.concatenate([c_only, o_only])
    rr, cc = np.divmod(flat, w)
    extra = np.arange(len(flat)) < len(c_only)  # a candidate-only pixel: look in the oracle's, else in the candidate's
    # a pixel of the other side among the 8 neighbours: every neighbour looked up at once
    dy, dx = np.array([-1, -1, -1, 0, 0, 1, 1, 1]), np.array([-1, 0, 1, -1, 1, -1, 0, 1])
    y, x = rr[:, None] + dy, cc[:, None] + dx
    inside = (y >= 0) & (y < h) & (x >= 0) & (x < w)
    near = y * w + x
    hit = np.zeros(near.shape, bool)
    hit[extra] = fp.has(near[extra], of_candidate=False)
    hit[~extra] = fp.has(near[~extra], of_candidate=True)
    off1 = (hit & inside).any(axis=1)
    at_end = np.zeros(len(rr), bool)
    if len(rr) and len(ends):
        q = np.stack([cc, rr], axis=1).astype(float)
        for k in range(0, len(q), 4096):
            d = np.hypot(q[k : k + 4096, None, 0] - ends[None, :, 0], q[k : k + 4096, None, 1] - ends[None, :, 1])
            at_end[k : k + 4096] = d.min(axis=1) <= END_RADIUS_PX
    return {
        "oracle_pixels": int(len(fp.oracle_idx)),
        "differing": int(len(rr)),
        "off_by_one_across": int((off1 & ~at_end).sum()),
        "off_by_one_at_ends": int((off1 & at_end).sum()),
        "farther": int((~off1).sum()),
    }


class CaseStyle:
    """One case's frames read for style and geometry, frame by frame; then the case judged.

    ``frame`` is called once per frame with the candidate's grey image (it
    returns the bool pixels the F1 scores compare: drawn where >= 128, the
    rule of docs/frames.md, and on grey levels a thin line's ridge, oracles.judge.coverage_pixels),
    then ``count_rule`` with those pixels and the oracle's; ``judge`` once, after the F1 reasons are known.
    Only sums and samples (at most :data:`MAX_SAMPLES_PER_CASE`) are kept between frames, never an image.
    """

    def __init__(self, line_rule: str = "any", job: dict | None = None):
        if line_rule not in LINE_RULES:
            raise ValueError(f"line rule {line_rule!r}: expected one of {', '.join(LINE_RULES)}")
        self.line_rule = line_rule
        self.job = job  # the job's read imposed on the case (oracles.judge.job_read.JobRead.as_dict), or None
        self.hist = np.zeros(256, np.int64)
        self.length_px = 0.0
        self.samples = CaseSamples()  # measure() of each frame
        self.ends = []  # measure_ends() of each frame
        self.raster = {
            "oracle_pixels": 0,
            "differing": 0,
            "off_by_one_across": 0,
            "off_by_one_at_ends": 0,
            "farther": 0,
        }
        self.reference = CaseSamples()  # measure() of a correct binary drawing of each binary frame
        self._kept = 0  # samples in self.samples and self.reference
        self.drawn_px = np.zeros(2, np.int64)  # binary frames: the candidate's drawn pixels, the oracle's
        self.centre = np.zeros(2)

    def frame(self, grey: np.ndarray, orac: np.ndarray, p_model, edges, camera, m, segs=None) -> np.ndarray:
        """Read one frame (``grey`` ``(H, W)`` uint8, ``orac`` pyrender's bool pixels); the pixels compared.

        ``segs``: the frame's oracle segments (:func:`oracles.diagnosis.image_diagnose.oracle_segments`
        of ``p_model`` moved by ``m``), when the caller has them.
        """
        out = np.zeros(np.size(grey), bool)
        out[self.frame_flat(grey, orac, p_model, edges, camera, m, segs)] = True
        return out.reshape(np.shape(grey))

    def frame_flat(self, grey: np.ndarray, orac: np.ndarray, p_model, edges, camera, m, segs=None) -> np.ndarray:
        """:meth:`frame`'s pixels as ascending flat indices ``y W + x`` (the frames judge keeps no image)."""
        grey = np.asarray(grey)
        binary_input = grey.dtype == bool
        if binary_input:
            grey = grey.astype(np.uint8) * 255
        segs = _segments(p_model, edges, camera, m) if segs is None else segs
        self.centre = np.array(camera.principal_point, dtype=float)
        nonzero = np.flatnonzero(grey > 0)  # (numpy finds a bool array's nonzero faster than uint8's)
        drawn = grey.reshape(-1)[nonzero]
        # drawn where >= 128 (a bool image compares its True with 128: nothing)
        cand = nonzero[:0] if binary_input else nonzero[drawn >= 128]
        self.hist += np.bincount(drawn, minlength=256)[:256]
        self.hist[0] += grey.size - len(drawn)
        clipped = None
        if len(segs):
            clipped = clip_to_image(segs[:, 0], segs[:, 1], camera.width, camera.height)
            _, q0, q1 = clipped
            self.length_px += float(np.hypot(*(q1 - q0).T).sum())
        level = max(int(drawn.max()) if len(drawn) else 0, 1)  # the frame's line level is 1
        wins = windows(segs, grey.shape)  # the same windows for the candidate and the reference
        got = measure(grey, segs, wins=wins, level=level)
        got["edge"] = got["segment"] + len(self.samples) * (len(segs) + 1)  # one key per frame and segment
        self.ends.append(free_ends.measure_ends(grey, segs, level=level))
        if (
            not len(drawn)
            or np.mean((drawn > drawn.max() / 8.0) & (drawn < drawn.max() * 7.0 / 8.0))
            > tolerances.NAMING.grey_share_max
        ):
            cand = np.flatnonzero(coverage_pixels.drawn(grey))  # grey levels: a thin line's ridge is drawn too
        else:
            self.drawn_px += (len(cand), int(np.count_nonzero(orac)))  # binary: pixels drawn, the oracle's
            width = float(np.median(got["width"])) if len(got["width"]) else 1.0  # this frame's width
            same = grey.shape == (camera.height, camera.width)  # the clipping above is the reference's
            ref = measure(
                _reference(segs, grey.shape, width, clipped if same else None, drawn=len(cand)), segs, wins=wins
            )
            for x in (got, ref):  # an exact tie: either choice is right (line_ties)
                line_ties.fold_ties(x, round(width) if width >= tolerances.NAMING.wide_min_px else 1, segs=segs)
            self.reference.add(ref)
            self._kept += len(ref["offset"])
        self.samples.add(got)  # its ties folded (binary frames)
        self._kept += len(got["offset"])
        if self._kept > MAX_SAMPLES_PER_CASE:  # every frame's samples halved (case_samples)
            self.samples.halve()
            self.reference.halve()
            self._kept = self.samples.kept + self.reference.kept
        return cand

    def count_rule(self, fp, segs: np.ndarray) -> None:
        """Count one frame's differing pixels by where they lie (the raster rule's shares; :func:`_off_by_one`):
        ``fp`` the frame's oracles.judge.frame_pixels.FramePixels of the pixels :meth:`frame` returned and pyrender's."""
        counts = _off_by_one(fp, np.asarray(segs, dtype=np.float64).reshape(-1, 2))
        self.raster = {k: v + counts[k] for k, v in self.raster.items()}

    # ---- reading the case

    def _pooled(self, key: str, samples=None) -> np.ndarray:
        return (self.samples if samples is None else samples).pooled(key)

    def classify(self) -> dict:
        """``{"style", "width_px", "grey_share", "level"}`` from the pooled histogram and the samples' widths."""
        drawn = self.hist[1:]
        n = int(drawn.sum())
        if n == 0:
            return {
                "style": "aliased",
                "width_px": 0.0,
                "grey_share": 0.0,
                "level": 0,
                "coverage_steps": 1,
                "band_px": 1,
                "pixel_ratio": 0.0,
            }
        cum = np.cumsum(drawn)
        level = int(np.searchsorted(cum, LEVEL_PERCENTILE / 100.0 * n)) + 1
        values = np.arange(1, 256)
        grey = drawn[(values > level / 8.0) & (values < level * 7.0 / 8.0)].sum()
        widths = self._pooled("width")
        # across the free parts of the lines: no junction or crossing
        if len(widths) >= tolerances.NAMING.profile_min_samples:
            width = float(np.median(widths))
        else:  # too little free line: all coverage over the lines' length
            coverage = float((np.minimum(values / level, 1.0) * drawn).sum())
            width = coverage / self.length_px if self.length_px > 0 else 0.0
        grey_share = float(grey) / n
        style = (
            "wide"
            if width >= tolerances.NAMING.wide_min_px
            else "antialiased"
            if grey_share > tolerances.NAMING.grey_share_max
            else "aliased"
        )
        ratio = float(self.drawn_px[0] / self.drawn_px[1]) if self.drawn_px[1] else 0.0
        band = max(int(np.floor(width + 0.5)), 1)
        if style == "aliased" and ratio >= tolerances.NAMING.wide_pixel_ratio:  # no 1-px line draws this many
            style, band = "wide", 2
        # coverage in few levels (4x MSAA: 0, 1/4, ... 1) moves a centroid by up to half a level's step on
        # lines that all sit at one fractional position; that half step is added to the offset's tolerance
        steps = max(int((drawn >= tolerances.NAMING.level_share_min * n).sum()), 1)
        return {
            "style": style,
            "width_px": round(width, 3),
            "grey_share": round(grey_share, 4),
            "level": level,
            "coverage_steps": steps,
            "band_px": band,
            "pixel_ratio": round(ratio, 3),
        }

    def _fit(self, samples):
        """``(d (2,), affine)`` over ``samples``: ``d`` the pooled offset (:func:`pooled_offset`), ``affine``
        the ``(d, m)`` of :func:`fit_lines` (None when not fixed); None with too few samples."""
        normal, offset = self._pooled("normal", samples).reshape(-1, 2), self._pooled("offset", samples)
        point = self._pooled("point", samples).reshape(-1, 2)
        if len(offset) < tolerances.NAMING.profile_min_samples:
            return None
        d, _ = pooled_offset(normal, offset)
        return d, fit_lines(normal, offset, point, self.centre)

    def geometry(self, read: dict, tol=None) -> dict:
        """Where the case's lines are against the oracle's (module docstring), less what a correct drawing shows.

        ``offset_px``: the pooled offset. ``warp_px``: how far, along the lines' normals, a scale, rotation
        or shear moves them beyond that offset: the 99th percentile over the samples of the affine fit's
        value there less the offset's (fitted values, not the map's parameters: lines of few directions
        fix the values where the lines are, not the map everywhere).
        """
        windows, found = self.samples.counts["windows"], self.samples.counts["found"]
        n = len(self._pooled("offset"))
        ends = np.concatenate(self.ends) if self.ends else np.zeros(0)
        geo = {
            "samples": n,
            "windows": windows,
            "found_share": found / windows if windows else 0.0,
            "offset_px": None,
            "bias_px": None,
            "warp_px": None,
            "ends_measured": int(len(ends)),
            "end_px": float(np.median(ends)) if len(ends) else None,
        }
        fit = self._fit(self.samples)
        if fit is None:
            return geo
        d, affine = fit
        ref_d, ref_affine = np.zeros(2), None
        if (
            read["grey_share"] <= tolerances.NAMING.grey_share_max
        ):  # binary: quantised; the same measure on a correct drawing
            ref = self._fit(self.reference) if len(self.reference) == len(self.samples) else None
            if ref is not None:
                ref_d, ref_affine = ref
        normal, point = self._pooled("normal").reshape(-1, 2), self._pooled("point").reshape(-1, 2)

        def fitted(aff, const):
            if aff is None:
                return np.zeros(len(normal))
            return (normal * (aff[0] + (point - self.centre) @ aff[1].T - const)).sum(axis=1)

        warp = np.abs(fitted(affine, d) - fitted(ref_affine, ref_d))
        lean = (
            even_lean.fit(normal, self._pooled("offset"), point, self._pooled("edge"), read["band_px"])
            if read["grey_share"] <= tolerances.NAMING.grey_share_max
            and read["style"] == "wide"
            and read["band_px"] % 2 == 0
            else None
        )
        if lean is not None:  # an even band: each edge's lean chosen (even_lean)
            tol = tolerances.Tolerances() if tol is None else tol
            held = np.max(np.abs(d - ref_d)) <= tol.rule_offset_px and (
                affine is None or np.percentile(warp, 99) <= tol.scale_px + tolerances.NAMING.binary_warp_px
            )  # decide's bounds
            geo["lean"] = {**{k: lean[k] for k in even_lean.REPORTED}, "used": bool(lean["leaning"] and not held)}
            if geo["lean"]["used"]:  # the lean explains what the symmetric band cannot
                d, ref_d, affine = lean["offset"], np.zeros(2), fit_lines(normal, lean["corrected"], point, self.centre)
                warp = np.abs(fitted(affine, d))
        geo.update(
            offset_px=[float(v) for v in d - ref_d],
            bias_px=[float(v) for v in ref_d],
            warp_px=float(np.percentile(warp, 99)) if affine is not None else 0.0,
        )
        return geo

    def read(self, diagnosed, tol=None, rounded=None) -> StyleRead:
        """The case's lines read (:class:`oracles.judge.evidence.StyleRead`): their style, geometry, raster
        counts and, for aliased lines, the same pixels against the rounded-ends rule; nothing judged here
        (oracles.judge.decide.judge_style holds them to the tolerances, oracles.judge.name_faults names them).

        ``diagnosed``: what the diagnosis named (oracles.faults.Fault records): lines it finds mirrored or
        swapped are not measured (a centroid of what lies near the oracle's lines would be of stray
        crossings). ``rounded``: the pixels against a correct drawing by the rounded-ends rule
        (``{"pixel_f1_0px", "lines"}``: the worst frame's F1@0px and the pooled line fields, its ties left
        out; oracles.line_model), None when not drawn.
        """
        tol = tolerances.Tolerances() if tol is None else tol
        read = self.classify()
        job_style = (self.job or {}).get("style")
        if job_style is not None and job_style != read["style"]:  # one renderer, one style (job_read)
            read = {**read, "style": job_style, "style_alone": read["style"]}
        geo = self.geometry(read, tol)
        placed = (
            geo["offset_px"] is not None
            and geo["found_share"] >= tolerances.NAMING.min_found_share
            and not any(f.name in PLACEMENT_FAULTS for f in diagnosed)
        )
        by_rule = read["style"] == "aliased" and self.line_rule in ("gl", "any")
        rounded_faults = (
            tuple(Fault.of(f) for f in diagnose_lines(rounded["lines"], tol)) if by_rule and rounded is not None else ()
        )
        return StyleRead(self.line_rule, read, geo, dict(self.raster), rounded, rounded_faults, placed, self.job)


def style_record(s: StyleRead, j, radius_px: int) -> dict:
    """A case's ``line_style`` field (report.json): the style read ``s`` and its judgement ``j``
    (oracles.judge.decide.StyleJudgement), with what the style can and cannot show and the F1 radius."""
    by_rule = s.by_rule
    out = {
        **s.read,
        "line_rule": s.line_rule,
        "judged_by": "GL's pixel rule (F1@0px) and the geometry"
        if by_rule
        else "the geometry (line centres); F1@0px is reported, not judged",
        "can_show": CAN_SHOW[s.style],
        "cannot_show": CANNOT_SHOW[s.style],
        "offset_tol_px": j.offset_tol_px,
        "geometry": dict(s.geometry),
    }
    if by_rule and s.line_rule == "any":
        out["judged_by"] = "a correct drawing by GL's rule or by the rounded-ends rule (F1@0px) and the geometry"
    out["warp_tol_px"] = j.warp_tol_px
    if s.raster_shares:
        out["raster_rule"] = s.raster_shares
    if by_rule:
        out["rule_read"] = j.rule_read
        if s.rounded is not None:
            out["rounded_rule"] = {
                "pixel_f1_0px": s.rounded["pixel_f1_0px"],
                "failures": list(j.rounded_failures),
                "lines": {
                    k: s.rounded["lines"][k] for k in ("candidate_only", "oracle_only", "subpixel_ties", "imbalance")
                },
            }
    out.update(pixel_rule=j.pixel_rule, failures=list(j.failures), f1_radius_px=radius_px)
    if s.job is not None:
        out["job_read"] = dict(s.job)
    return out


def summary_lines(cases: list) -> list[str]:
    """One line per line style read in a run's cases (``line_style`` of each): the style, the cases
    and widths, how they were judged and what the style cannot show. Empty when no case has one."""
    by = {}
    for c in cases:
        ls = c.get("line_style")
        if ls:
            by.setdefault((ls["style"], ls["line_rule"]), []).append(ls)
    out = []
    for (style, rule), rows in sorted(by.items()):
        widths = [r["width_px"] for r in rows if r["width_px"] is not None]  # None: not finite, null in report.json
        radius = max(r.get("f1_radius_px", 1) for r in rows)  # f1_radius
        wide = f"{min(widths):.2f}-{max(widths):.2f} px wide" if widths else "width -"
        out.append(
            f"Line style read: {style} ({len(rows)} case{'s' if len(rows) != 1 else ''}, "
            f"{wide}, --line-rule {rule}): judged by {rows[0]['judged_by']}"
            f"{f'; F1 at up to {radius} px (the width)' if radius > 1 else ''}; cannot show {CANNOT_SHOW[style]}"
        )
    read = [
        c
        for c in cases
        if (c.get("line_style") or {}).get("rule_read") == "rounded"
        and c["line_style"]["line_rule"] == "any"
        and c.get("verdict") == "pass"
    ]
    if read:
        out.append(
            f"Line rule read: {RULE_NAMES['rounded']} in {len(read)} case{'s' if len(read) != 1 else ''}, "
            "a correct drawing by that rule; --line-rule gl holds them to GL's"
        )
    pooled = [c for c in cases if (c.get("line_style") or {}).get("job_read")]
    if pooled:  # oracles.judge.job_read: the cases that read the renderer otherwise, judged again
        job = pooled[0]["line_style"]["job_read"]
        parts = [f"{k} {job[k]}" for k in ("style", "rule", "rule_name") if job.get(k)]
        if job.get("offset_px") is not None:
            parts.append(f"offset ({job['offset_px'][0]:.2f}, {job['offset_px'][1]:.2f}) px")
        n = len(pooled)
        out.append(
            f"One renderer, one reading: {n} case{'s' if n != 1 else ''} read the renderer otherwise than the "
            f"job's {job['cases']} cases together and {'were' if n != 1 else 'was'} judged again under the "
            f"job's read ({', '.join(parts)})"
        )
    return out
