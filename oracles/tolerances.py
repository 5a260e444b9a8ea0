"""Every tolerance of crosscheck, in one place, each with the reason for its value.

``--tol-px`` overrides VERTEX_TOL_PX, ``--min-f1`` MIN_F1_1PX and
``--min-f1-0px`` MIN_F1_0PX; BALANCE_ALPHA, MAX_IMBALANCE_FRACTION and
MAX_EDGE_COUNT_DIFF are fields of :class:`Tolerances` (below).
"""

from dataclasses import dataclass

#: Max vertex error in pixels between the candidate and cv2.projectPoints, for
#: a float64 candidate (the floor of every vertex bound, below). Both compute
#: in float64: relative error ~ a few eps (2.2e-16) per operation, times ~20
#: operations, times the pixel scale (|x_px| up to ~1e4 for the bundled
#: cases) gives ~1e-11 px. 1e-6 px leaves five orders of margin for that and
#: still catches any real convention error (the smallest, a half-pixel offset,
#: is 0.5 px).
VERTEX_TOL_PX = 1e-6

# ---------------------------------------------------------------- the candidate's precision

#: The precisions a candidate may compute in (declared with
#: ``--candidate-precision``, or inferred from the dtype of what it returns).
PRECISIONS = ("float32", "float64")

#: Machine epsilon (the spacing of floats at 1.0) of each precision.
EPS = {"float32": 2.0**-23, "float64": 2.0**-52}

# A candidate that computes in float32 (glm, PyTorch3D, a GL shader) is off
# from the float64 oracle by its own rounding, which 1e-6 px cannot absorb.
# Its vertex bound is derived from its precision and the scale of the case.
# For a point X seen by a camera at C with depth z, focal length f px (the
# larger of fx, fy) and pixel p = (x, y), u = p - (cx, cy):
#
# - the world-to-camera transform R (X - C) (or V @ [X, 1]) rounds values of
#   size |X| + |C|: an absolute error of a few eps (|X| + |C|) on each camera
#   coordinate, whatever the order of the operations;
# - the perspective divide turns an error dx in x_cam and dz in z into
#   f (dx + |x_cam / z| dz) / z = (f + |u|) (|X| + |C|) eps / z pixels
#   (|x_cam / z| f = |u|); orthographic: s (|X| + |C|) eps, s = px per unit;
# - the viewport (x = (ndc + 1) W/2 - 0.5, or cx + f x/z) rounds values of
#   size |x| + |y| and W + H: (|x| + |y| + W + H) eps.
#
# So each point's error is at most VERTEX_ROUNDINGS eps times its scale
#
#     scale = (f + |u_x| + |u_y|) (|X| + |C|) / z + |x| + |y| + W + H     (perspective)
#     scale = s (|X| + |C|) + |x| + |y| + W + H                             (orthographic)
#
# and a float32 case's bound is VERTEX_ROUNDINGS eps32 max(scale) over its
# visible points and frames (:func:`vertex_scale`, :func:`vertex_bound`), never
# below VERTEX_TOL_PX (``--tol-px``). For float64 that product is ~1e-11 px on
# the bundled cases, so VERTEX_TOL_PX (1e-6) is the bound; for float32 it is ~1e-3 px,
# still three orders below the smallest convention error (0.5 px).
#
# Measured (benchmarks/measure_precision.py: five float32 projectors -- two
# glm-style GL pipelines, DirectXMath's left-handed one, core --dtype float32,
# an OpenCV-style K [R|t] -- on the bundled scenes and the orrery under every
# case camera, 24 frames each): the largest error / (eps scale) of any point
# is 0.74 (glm with P V premultiplied, orrery, narrow_fov; core 0.16, K [R|t]
# 0.18); the largest float32 vertex error 4.6e-4 px, the bounds 1.2e-3 to
# 3.4e-3 px.

#: Roundings of size eps x scale a correct projector may accumulate (see
#: above): 4, 5.4x the largest measured error / (eps scale).
VERTEX_ROUNDINGS = 4.0

#: The near-plane margin of oracles.candidates.draw, in roundings of eps (|X| + |C|): a
#: correct candidate's view depth of X is within this many of the exact depth,
#: so an end moved this far inside [near, far] passes its own depth test.
#: Measured (same run): a float32 glm view depth is off by at most 1.05
#: eps32 (|X| + |C|); 4 leaves ~4x.
DEPTH_ROUNDINGS = 4.0


def vertex_scale(p_world, p_px, camera, matrices=None) -> float:
    """The largest per-point scale of a frame (pixels per unit of relative rounding; formula above).

    Parameters
    ----------
    p_world : (N, 3) array_like
        World points.
    p_px : (N, 2) array_like
        Their pixels by the oracle; NaN rows (clipped points) are left out.
    camera : core.camera.Camera
    matrices : tuple, optional
        ``oracles.references.convert.opencv_matrices(camera)``, when the caller has them
        (built once per case: they cost ~1 ms, as much as OpenCV's projection).

    Returns
    -------
    float, 0.0 when no point is visible.
    """
    import numpy as np

    from .references.convert import opencv_matrices

    p_world = np.asarray(p_world, dtype=np.float64).reshape(-1, 3)
    p_px = np.asarray(p_px, dtype=np.float64).reshape(-1, 2)
    seen = np.isfinite(p_px).all(axis=1)
    if not seen.any():
        return 0.0
    r_cv, t_cv, k = opencv_matrices(camera) if matrices is None else matrices
    x, p = p_world[seen], p_px[seen]
    size = np.linalg.norm(x, axis=1) + float(np.linalg.norm(camera.position))
    reach = np.abs(p - k[:2, 2]).sum(axis=1)
    focal = max(abs(k[0, 0]), abs(k[1, 1]))
    viewport = np.abs(p).sum(axis=1) + camera.width + camera.height
    if camera.projection == "perspective":
        z = x @ r_cv[2] + t_cv[2]
        scale = (focal + reach) * size / z + viewport
    else:
        scale = focal * size + viewport
    return float(np.max(scale))


def vertex_bound(precision: str, scale: float, floor: float = VERTEX_TOL_PX) -> float:
    """A case's vertex bound in pixels: ``max(floor, VERTEX_ROUNDINGS eps scale)``, eps the precision's.

    ``floor`` is ``--tol-px`` (default VERTEX_TOL_PX). For float64 the derived
    term is ~1e-11 px on ordinary scenes, five orders under the default, which
    is then the bound; it exceeds it only where float64 itself cannot do
    better: a mesh 1e3 to 1e5 from the origin seen from close by (the
    specificity dataset, docs/tolerances.md: core and OpenCV then differ by
    1e-6 to 1.2e-5 px, 0.05 to 0.37 of the derived term). A ``--tol-px`` the
    user gives keeps its meaning for a float64 candidate: it is the bound (0
    fails any error).
    """
    if precision == "float64" and float(floor) != VERTEX_TOL_PX:
        return float(floor)
    return max(float(floor), VERTEX_ROUNDINGS * EPS[precision] * float(scale))


# ---------------------------------------------------------------- the unprojector (the way back)

# An unprojector maps a pixel p = (u, v) and a depth d along forward to the world point
# X = R^T (p_cv - t) (oracles.references.unproject_reference). Its rounding: u - cx rounds
# values of size |u| + |cx| and the product with d / fx carries that to x_cv; the rotation
# and the translation round values of size |p_cv| + |C| (C the camera position). So each
# world coordinate is off by a few eps times
#
#     scale = |C| + d (1 + (|u| + |cx|) / fx + (|v| + |cy|) / fy)      (perspective)
#     scale = |C| + d + (|u| + |cx| + |v| + |cy|) / s                     (orthographic)
#
# world units (|.| the largest coordinate). UNPROJECT_ROUNDINGS counts them: about seven
# per coordinate (subtract, divide, multiply, three products and two sums of the rotation,
# the translation), on the candidate's side and the reference's: 16. A float32 candidate
# (its answer float32) is held to eps32, a float64 one to eps64; as for vertices, no bound
# is below VERTEX_TOL_PX pixels at the point's depth (``d VERTEX_TOL_PX / f``; orthographic
# ``VERTEX_TOL_PX / s``), so a correct unprojector that inverts the 4x4 GL matrices (worse
# conditioned than K, R, t) is not failed for that.
UNPROJECT_ROUNDINGS = 16.0


def unproject_bound(p_px, depth, camera, precision: str = "float64", floor_px: float = VERTEX_TOL_PX):
    """``(N,)`` world-unit bound on ``|X_candidate - X|`` per point (the derivation above).

    ``p_px`` ``(N, 2)`` pixels, ``depth`` ``(N,)`` depths along forward, ``camera`` the contract's.
    """
    import numpy as np

    p = np.abs(np.asarray(p_px, dtype=np.float64).reshape(-1, 2))
    d = np.abs(np.asarray(depth, dtype=np.float64).reshape(-1))
    k = np.asarray(camera.K, dtype=np.float64)
    fx, fy, cx, cy = k[0, 0], k[1, 1], abs(k[0, 2]), abs(k[1, 2])
    c = float(np.abs(np.asarray(camera.position, dtype=np.float64)).max())
    if camera.projection == "perspective":
        scale = c + d * (1.0 + (p[:, 0] + cx) / fx + (p[:, 1] + cy) / fy)
        floor = floor_px * d / max(fx, fy)
    else:
        scale = c + d + (p[:, 0] + cx + p[:, 1] + cy) / fx
        floor = np.full(d.shape, floor_px / fx)
    return np.maximum(UNPROJECT_ROUNDINGS * EPS[precision] * scale, floor)


#: Minimum edge-pixel F1 at 1 px (Chebyshev) against pyrender/OSMesa.
#: Measured: 1.0 in every one of 1,512 frames (3 scenes x 7 cameras x 72
#: frames) and in 432 frames of four other cameras (README, "Pixel
#: agreement"): a pixel that is not within 1 px of the oracle's line is a real
#: error. 0.999 allows one stray pixel per ~1,000 line pixels, for
#: float32-vs-float64 decisions in the shader that a 1-px tolerance cannot absorb
#: (none seen so far), and catches a half-pixel offset (F1@1 stays 1.0 for that
#: one: the vertex check is what catches it).
MIN_F1_1PX = 0.999

#: Minimum edge-pixel F1 at 1 px in the extremes suite (oracles.extremes), on
#: the frames a case judges (where the frame is well conditioned for a float32
#: GL pipeline). Lower than MIN_F1_1PX: those frames have few, extreme lines,
#: where one stray end pixel weighs more than in ~1,500 ordinary frames.
MIN_F1_1PX_EXTREMES = 0.99

#: Minimum edge-pixel F1 at 0 px. core/projector/raster.py emulates GL's diamond-exit
#: rule, llvmpipe's tie directions and its 1/256 px vertex snap; what is left
#: are decisions within ~1/512 px of a boundary, where llvmpipe decides on
#: float32 vertices and we on float64. Measured minimum over 1,512 frames of
#: the bundled cases: 0.9958 (worst frame of a case; mean 0.9997). 0.98 leaves
#: room for scenes with many short edges (each differing pixel weighs more)
#: and fails a half-pixel offset (F1@0 ~ 0.5).
MIN_F1_0PX = 0.98

# ---------------------------------------------------------------- systematic line-pixel defects

# F1 at a fixed floor cannot see a defect that costs one pixel per line: a
# rasterizer that drops the last pixel of every line keeps F1@1 = 1.0 and F1@0
# at 0.993-0.997, above MIN_F1_0PX. What it cannot hide is *direction*: two
# unbiased renderers (core and llvmpipe, llvmpipe and NVIDIA) differ where a
# pixel centre is within rounding of a decision, and such a pixel goes to
# either side with equal chance, so candidate-only and oracle-only pixels come
# in equal numbers. A dropped (or added) end pixel is one-sided.
#
# Measured (benchmarks/measure_line_gate.py, 24 frames of every case camera;
# pooled per case; "decided" are the one-sided pixels that are not sub-pixel
# ties, oracles.judge.line_ties, which the sign test and the size condition count):
#
# | scenes                         | correct core: one-sided | decided  | max abs net / oracle px | min p |
# |--------------------------------|-------------------------|----------|-------------------------|-------|
# | cube, pyramid, prism (21)      | 179 vs 181              | 2 vs 0   | 3.8e-5                  | 1     |
# | orrery (7)                     | 57 vs 51                | 6 vs 0   | 9.7e-5                  | 0.5   |
# | hidden lines + backface (28)   | 169 vs 165              | 5 vs 0   | 1.3e-4                  | 0.5   |
# | 5 random edge soups (35)       | 664 vs 669              | 14 vs 17 | 4.0e-5                  | 0.25  |
#
# and for the drop-last-pixel mutant (decided pixels): every plain bundled
# case fails (1 vs 3,458 pooled, p <= 2.3e-72 in each case; net -0.31 % to
# -0.79 % of the oracle's pixels); orrery 3 vs 3,378; hidden lines + culling
# 1 vs 5,031, the fewest in one case 0 vs 12 (cube, near_plane: the camera
# inside the cube sees few line ends); random edge soups 1 vs 11,473, 35/35
# fail.
#
# The random-end renderer (tests/raster_mutants.random_ends: each line loses
# or gains one pixel at a random end, q = 0.25 each) is unbiased per line, and
# passes every bundled, orrery and hidden-line case (56/56; decided 718 vs
# 688, 662 vs 698, 1,028 vs 930; smallest p 0.0038, net below 1.2e-3). On
# the random edge soups it fails 5 of 35 cases (3,409 vs 2,296, p down to
# 3e-11): where several lines end at one vertex, a lost end pixel is usually
# still drawn by another line, a gained one beyond the vertex is not, so in
# the image its noise is biased toward extra pixels, and the gate says so.

#: The sign test on a case's pooled one-sided pixels. Under H0 (an unbiased
#: renderer) each differing pixel is candidate-only with p = 1/2, and the
#: two-sided p-value is ``2 P(X <= min(k, n - k))``, X ~ Binomial(n, 1/2)
#: (oracles.judge.metrics.sign_test_p). alpha = 1e-3: a case fails the test with
#: 11 one-sided pixels all on one side (2 x 2^-11 = 9.8e-4), which is what
#: the drop-last mutant leaves in the hardest case measured (hidden lines +
#: back-face culling, cube, near_plane: 0 vs 12, p = 4.9e-4; at alpha 1e-4 it
#: passed). By chance alone an unbiased candidate fails the sign test in at
#: most 21 x 1e-3 = 2 % of 21-case runs (Bonferroni), and then must also meet
#: the size condition below, which noise of the measured size never does; the
#: correct core's smallest p is 0.25, the random-end noise's 0.0038 on the
#: bundled scenes, the mutant's at most 4.9e-4 (2.3e-72 or smaller on the
#: plain bundled cases).
BALANCE_ALPHA = 1e-3

#: ... and the imbalance must be large enough to matter: the net one-sided
#: pixels (candidate-only minus oracle-only) more than this fraction of the
#: oracle's line pixels, pooled over the case. 1e-3 (one net pixel per 1,000,
#: the scale MIN_F1_1PX allows for stray pixels) is 7x the largest net
#: measured on the correct core (1.3e-4, hidden lines + culling) and 3x below the
#: smallest the mutant makes (3.1e-3, pyramid near_plane). The size condition
#: is what keeps a noisy but unbiased candidate passing: at the Mesa-vs-NVIDIA
#: level (F1@0 0.99993 over 504 frames, 7e-5 of pixels differing) the whole
#: difference is below 1e-3, whatever its direction; a candidate with 40x
#: that noise at line ends, unbiased per line (tests/raster_mutants.random_ends),
#: passes the bundled scenes (see above for where it does not).
MAX_IMBALANCE_FRACTION = 1e-3

#: Per-edge pixel counts (Khronos' criterion: a line's pixel count within +-1
#: of the reference's). Without rendering each line singly, an edge's count is
#: the number of distinct major-axis coordinates among the drawn pixels nearest
#: to its segment (within 1 px; oracles.judge.metrics.edge_counts): a tie decided
#: across the line does not change it, a pixel more or less at an end does.
#: Where lines meet or cross, pixels are shared out by distance, and a tie
#: pixel that moves across the line can move to a neighbour's share: one more
#: pixel either way at each end. Measured over all 91 cases above: correct
#: core at most 1 on the bundled scenes, the orrery and the hidden-line mode,
#: 2 on the random edge soups (many crossings); unbiased one-end-per-line
#: noise (random_ends) 2; the drop-last mutant 2. 3 (one above the largest
#: measured) fails a line drawn 2 px short at both ends, a gap of 4 pixels, a
#: missing or an extra line; the 1-px end bias is the balance test's to find.
MAX_EDGE_COUNT_DIFF = 3

# Sub-pixel ties (oracles.judge.line_ties). A one-sided pixel beside a row (column)
# where its segment crosses within the oracle's sub-pixel precision of the
# boundary between two pixels is decided by how the ends were rounded, not by
# the line: it is counted as a tie (``subpixel_ties``) and left out of the
# sign test and the size condition above (found on a generated 24-sided
# cylinder seen along its axis: a cap's spoke and a side edge overlap, cross
# a row 0.0007 px from the half pixel, and Mesa puts one on each side; 8
# oracle-only pixels a frame, none the other way, p = 3e-5).
#
# How far can a GL rasterizer move an end before it decides? Per coordinate:
#
# - the snap to its sub-pixel grid, 2^-SUBPIXEL_BITS px: at most half a step.
#   GL only requires SUBPIXEL_BITS >= 4; the oracle, Mesa's llvmpipe, uses 8
#   (FIXED_ORDER 8; core.projector.raster emulates it): 2^-9 px;
# - the float32 rounding of the window coordinates before the snap: at most
#   VERTEX_ROUNDINGS eps32 scale (above), <= 2^-9 px while scale <= 4,096 px,
#   and 4x the largest float32 vertex error measured (4.6e-4 px).
#
# So each end is within TIE_END_PX = 2^-9 + 2^-9 = 2^-8 px of the exact one.
# Where a segment of minor/major slope |m| <= 1 crosses a row between its
# ends, an end moved by (e_x, e_y) moves the line across the row by
# e_x - m e_y (|.| <= (1 + |m|) TIE_END_PX), and the crossing is a weighted
# mean of the two ends' moves: within (1 + |m|) TIE_END_PX <= 2^-7 px of the
# exact crossing. Farther from the boundary the oracle decides as the exact
# line does; closer, its answer is not the line's, and a candidate that
# differs there is not wrong. 8 bits, not the spec's 4: the oracle's own
# precision is what makes its answer undecided; a candidate that snaps coarser
# differs from it outside this zone too, at random, which the sign test
# already takes (a wider zone, (1 + |m|) 2^-5, would excuse 1 in 8 crossings).
# A scale above 4,096 px (a float32 rounding above 2^-9) makes the zone
# narrower than the oracle's real one: a tie may then count as decided (a
# false alarm, never a hidden fault). A tie moves no pixel between major
# coordinates, so the per-edge counts need no such rule.
#
# What it cannot hide: a pixel is a tie only where the crossing is within
# 2^-7 px of the half pixel (at most 2 x 2^-7 = 1/64 of a line's rows) and
# the image without it drew the pixel across that boundary (a pixel lost or
# added with no partner stays decided): a line shifted by 1 px or drawn 1 px
# thicker keeps at least 63/64 of its one-sided pixels in the test.
#
# A line's end pixel is decided by the end, not by a crossing: with the end E
# on its diamond's exit side, the pixel P is drawn exactly when |E - P|_1 >=
# 1/2, and an end moved by TIE_END_PX per coordinate moves |E - P|_1 by at
# most 2 TIE_END_PX = 2^-7. Closer to 1/2 than that, P is a tie too
# (oracles.judge.line_ties.tie_ends), whichever image drew it; an end falls
# there for about 4 TIE_END_PX = 1/64 of line ends, so a line short or long at
# every end keeps the rest in the test.

#: Sub-pixel bits of the oracle's rasterizer (Mesa llvmpipe; the GL minimum is 4).
SUBPIXEL_BITS = 8

#: How far a renderer may move a segment's end before deciding, per coordinate (px): the snap's
#: half step 2^-(SUBPIXEL_BITS + 1) plus 2^-9 of float32 rounding (derivation above).
TIE_END_PX = 2.0 ** -(SUBPIXEL_BITS + 1) + 2.0**-9

#: The pyrender oracle's own error bound (oracles.references.oracle_precision: its float32 window
#: coordinates' distance from exact, per drawn segment) up to which a case's pixels are judged: the
#: float32 share (2^-9 px) of TIE_END_PX, which the line gate's sub-pixel ties assume of the oracle. Past
#: it the pixels say nothing of the candidate: the case is judged on its vertices alone (``oracle_precision``,
#: ``vacuous`` unless they fail; oracles.judge.decide). Measured bound on the bundled scenes and the orrery,
#: also 1e5 from the origin: 1.6e-4 to 1.2e-3 px (docs/tolerances.md).
ORACLE_LIMIT_PX = 2.0**-9

#: Pixel tolerances at which precision/recall/F1 are reported.
PIXEL_TOLS = (0, 1)

# ---------------------------------------------------------------- hidden lines, shaded, culling

#: Hidden lines (``--hidden-lines``, and ``--cull backface``) are judged with the
#: same F1 minimums as plain wireframes (MIN_F1_1PX, MIN_F1_0PX). pyrender draws
#: the faces black with glPolygonOffset(1, 1) under the lines; core hides a
#: line pixel behind its depth buffer with the linear-depth image of the same
#: offset (core.projector.zbuffer). Measured, core against pyrender, 24 frames of each
#: of the 7 cameras: F1@1 = 1.0 everywhere; F1@0 >= 0.9956 (cube), 0.9984
#: (icosphere(2)), 0.9961 (scenes/examples/orrery, three moving objects), as
#: good as the plain wireframe (min 0.9958), so no looser bound is needed (a
#: line pixel kept or lost at an occluding face's edge is within 1 px of the
#: oracle's, which F1@1 absorbs).

#: Minimum silhouette IoU (``--style shaded``): covered pixels of the
#: candidate's depth buffer (finite) against pyrender's (depth buffer < 1).
#: Both cover a pixel when its centre is inside a triangle after snapping the
#: vertices to 1/256 px (llvmpipe; core.projector.zbuffer emulates it), so the only
#: differences are centres within float rounding of an edge. Measured, 24
#: frames x 7 cameras: cube 8 of 168 frames below 1.0, min 0.99997;
#: icosphere(2) 1 of 168, min 0.99999; orrery (three objects) 3 of 168, min
#: 0.99982. A float64 ray-casting reference without the snap measured min
#: 0.99963. 0.995 leaves room for smaller silhouettes
#: (fewer pixels per boundary pixel, several objects) and still fails a
#: mirrored silhouette and a half-pixel shift of a 200-px silhouette (every
#: boundary pixel flips with probability 1/2: IoU ~ 1 - P/2A ~ 0.99).
MIN_SILHOUETTE_IOU = 0.995

#: IoU is a ratio of areas: for a silhouette of a few pixels one boundary
#: decision moves it by a large fraction (a zero-area face that GL's float32
#: noise turns into 1 px while core draws none scores IoU 0). Below this union,
#: in pixels, the IoU gate is not applied; the silhouettes must still differ
#: only on their boundaries (metrics.shaded_scores' silhouette_mismatch_inside
#: = 0, applied at every size). 400 px = a 20 x 20 silhouette, whose ~80
#: boundary pixels are 20 % of its area.
MIN_IOU_UNION_PX = 400

# ---- Filled frames under GL's fill rule (oracles.references.fill_rule, oracles.judge.silhouette)
#
# The reference covers a pixel when its centre is inside a triangle, computed exactly in
# float64; a renderer first moves each vertex, per coordinate, by its snap to the sub-pixel
# grid and its float32 rounding: at most TIE_END_PX (above: 2^-9 + 2^-9 px while the frame's
# scale is at most 4,096 px; GL's minimum of 4 sub-pixel bits would be 2^-5, see below). A
# vertex moved by at most TIE_END_PX per coordinate moves by at most sqrt(2) TIE_END_PX, and
# every point of an edge, a weighted mean of its ends, by at most as much: a centre farther
# than that from every edge the renderer could move is decided as the reference decides it.
# Centres within it of an open edge (the silhouette's contour, a mesh border, a near-plane
# cut; not an edge that triangles on both its sides share, whose shared ends move together)
# are ties, where either answer is correct.
#
# So a correct rasteriser (float32 vertices, >= 8 sub-pixel bits, GL's fill rule) differs
# from the reference only at ties, and any decided disagreement is an error: the longest run
# of decided disagreements allowed (the largest 8-connected set of pixels missing or added,
# oracles.judge.silhouette) is 0. The run is what is reported: a one-pixel band missing along
# an edge of L px is a run of about L, which IoU hides on a large silhouette (IoU = 1 - L/A:
# 0.9967 for one edge of a 300 x 300 square, above MIN_SILHOUETTE_IOU). A renderer with
# coarser snapping (GL allows 4 sub-pixel bits: a vertex may move by 1/32 px) flips centres
# up to ~0.05 px from an edge, isolated pixels and runs along near-axis-aligned edges: loosen
# max_silhouette_run_px for it. Scales above 4,096 px make the float32 term larger than 2^-9:
# with FILL_TIE_PX a centre may then count as decided where a renderer is undecided (a false
# alarm, never a hidden fault); fill_tie_bound(vertex_scale(...)) widens the zone for such a frame.

#: How far a renderer may move a vertex before deciding coverage (px, Euclidean; derivation above).
FILL_TIE_PX = 2.0**0.5 * TIE_END_PX
#: The largest 8-connected set of decided pixels missing or added that passes (derivation above).
MAX_SILHOUETTE_RUN_PX = 0


def fill_tie_bound(scale: float) -> float:
    """The tie distance (px) for a frame of ``scale`` (:func:`vertex_scale`): FILL_TIE_PX up to 4,096 px.

    ``sqrt(2) (2^-(SUBPIXEL_BITS + 1) + max(2^-9, VERTEX_ROUNDINGS eps32 scale))``: the snap's half
    step and the float32 rounding of a vertex at that scale, never below the 2^-9 that FILL_TIE_PX
    assumes (derivation above).
    """
    rounding = max(2.0**-9, VERTEX_ROUNDINGS * EPS["float32"] * float(scale))
    return 2.0**0.5 * (2.0 ** -(SUBPIXEL_BITS + 1) + rounding)


#: The shaded depth comparison: |z_candidate - z_pyrender| at a pixel covered
#: by both and not on either silhouette (eroded by 1 px) nor beside an occlusion
#: boundary (oracles.judge.metrics.occlusion_boundary) must be at most
#:
#:     bound(z) = DEPTH_STEPS * step(z) + DEPTH_SNAP_PX * slope + DEPTH_EPS32 * eps32 * z
#:
#: with z pyrender's depth at the pixel (linear camera depth, made linear in
#: float64 from the 24-bit buffer by oracles.references.pyrender_oracle: compare like with
#: like) and
#:
#: - ``step(z)``: one level of the 24-bit depth buffer in camera depth,
#:   ``z^2 (far - near) / (far near (2^24 - 1))`` for perspective (window depth
#:   ``f (z - n) / ((f - n) z)`` is non-linear in z) and ``(far - near) /
#:   (2^24 - 1)`` for orthographic (window depth ``(z - n) / (f - n)`` is linear,
#:   so the step is the same at every depth). DEPTH_STEPS = 4: one for the
#:   conversion to 24 bits, up to three for llvmpipe's float32 evaluation of the
#:   window-depth plane at the pixel (window depth is < 1, where one float32 ulp,
#:   2^-24, is one level);
#: - ``slope``: the largest change of pyrender's depth to a 4-neighbour of the
#:   pixel (depth per pixel). llvmpipe snaps x and y to 1/256 px, moving the
#:   depth plane by up to 1/512 px along each axis: |dz/dx|/512 + |dz/dy|/512 <=
#:   slope / 256, so DEPTH_SNAP_PX = 1/256. This term dominates on faces seen
#:   at a grazing angle (up to ~100 levels measured on the near_plane camera);
#: - ``DEPTH_EPS32 * eps32 * z``: float32 geometry in GL (positions, model,
#:   view and projection matrices, the divide): about 8 roundings of values of
#:   size ~z, each <= eps32/2 relative, doubled: 16.
#:
#: Measured, core against pyrender (cube, icosphere(2), orrery; 7 cameras x
#: 24 frames): the largest error / bound(z) is 0.48 (icosphere, non_square);
#: without the slope term it would be 8.5 (cube, near_plane, 12 frames). A
#: candidate whose depth is 1% too large (1.01 z) measured error / bound up to
#: 820 (perspective) and 1700 (orthographic) on the cube.
DEPTH_STEPS = 4.0
DEPTH_SNAP_PX = 1.0 / 256.0
DEPTH_EPS32 = 16.0


#: The shaded depth bound, as stated in the report.
DEPTH_BOUND_TEXT = (
    f"per pixel, {DEPTH_STEPS:g} depth-buffer steps + slope/{1 / DEPTH_SNAP_PX:g} + {DEPTH_EPS32:g} eps32 z"
)


# ---- A renderer's depth maps and filled frames (crosscheck export --outputs ...,depth,filled), judged by the
# frames judge (oracles.judge.depth_frames, oracles.judge.filled_frames) against pyrender's faces.

#: A depth map's value at a pixel where both it and the reference show a decided surface must lie within
#: this many allowances of the reference's, the allowance being the reference's per-pixel bound (DEPTH_STEPS
#: above: the 24-bit buffer, llvmpipe's snapping, float32 geometry) plus the map's encoding step (one
#: float32 ulp, or 1 / scale for a 16-bit PNG: oracles.candidates.depth_map). The bound is already a worst
#: case (core's depth against pyrender's measured 0.59 of it at most, docs/depth.md), so 1: the depth
#: diagnosis' own pass rule (oracles.diagnosis.depth_faults).
MAX_DEPTH_ERROR_RATIO = 1.0
#: Reference surface a depth map leaves empty (holes), and surface it shows where the reference has none
#: (extra), counted away from the reference silhouette's boundary: a pixel whose eight neighbours are all
#: covered (all uncovered) by the reference has its centre more than half a pixel from any silhouette
#: edge, far beyond the 1/256 px snapping that decides a boundary pixel (MIN_SILHOUETTE_IOU's derivation),
#: so a correct renderer leaves none: 0. Core's depth buffer, drawn from a job's own files, measured 0 and
#: 0 (tests/test_depth_jobs.py). (Filled frames are held to the fill rule's decided pixels instead:
#: MAX_SILHOUETTE_RUN_PX below.)
MAX_SURFACE_HOLES_PX = 0
MAX_SURFACE_EXTRA_PX = 0
#: A filled frame of several objects: decided pixels whose grey level reads as another object than the
#: fill rule's nearest (oracles.judge.filled_frames.object_id_misses). The reference leaves out the pixels
#: where two objects' depths are within their depth bounds (fill_rule.ID_TIE: either is correct) and the
#: coverage ties, so a correct renderer shows the reference's object everywhere else: 0 (measured: pyrender's
#: ids equal the reference's at every decided pixel of 3 views of 3 overlapping objects, tests/test_fill_rule.py).
MAX_OBJECT_ID_PX = 0


# ---- The geometry of a renderer's lines, measured from its frames (oracles.judge.line_style,
# oracles.diagnosis.image_diagnose): thresholds that decide a verdict or a name on the frames path.
# They were module constants of those modules; they are Tolerances' fields so a run can set them.

#: An offset is a fault when it exceeds this (px): the image registration's pooled offset on a correct
#: renderer stays within ~0.05 px (measured, five cameras, 1 px / anti-aliased / 2-px lines), the line
#: centres' within 0.03 px on anti-aliased lines; a half-pixel convention measures 0.46-0.52. So 0.2, four
#: times the correct spread and under half the smallest half-pixel reading, parts them. Anti-aliased lines
#: whose coverage comes in few levels add half a level's step (line_style: 4x MSAA, 0.2 + 0.125).
OFFSET_TOL_PX = 0.2
#: A scale (or a rotation, shear: the line centres' warp) is a fault when it moves some drawn pixel by more
#: than this (px): a correct renderer's pooled scale is within 5e-4 of 1 (<= 0.05 px at ~130 px reach), a
#: 0.8 FOV factor moves lines by tens of px; lines scaled so that the farthest end moves 0.8 px measure
#: 0.75-0.8. Binary lines, quantised line by line, add half a pixel (line_style, rule_read).
SCALE_TOL_PX = 0.5
#: Binary lines of another aliased rule than GL's, or binary wide lines: the largest pooled centre offset
#: (px) that is still "the geometry is right". A rule that snaps the ends to pixel centres moves each line
#: by up to half a pixel: pooled 0.00-0.27 px over the bundled scenes and cases (Pillow, Bresenham;
#: LINE_8 0.34 on pyramid / near_plane), where a half-pixel offset measures 0.45-0.52. 0.35 parts them.
RULE_OFFSET_MAX_PX = 0.35
#: Free line ends (oracles.judge.free_ends): the median end, where the coverage along the line falls to
#: half its width, must lie within -this and half the width + this (px) of the segments' ends: a butt end
#: measures 0, a cap up to half the width; a dropped end pixel measures -0.54 to -0.73, an added one 1.25
#: to 1.51. Half a pixel parts them.
END_TOL_PX = 0.5
#: The rounded-ends rule (oracles.line_model, "rounded"): how close to a half pixel (per axis, px)
#: an end may round either way (the pixels between those roundings are ties, left out of the comparison).
#: Half a step of OpenCV's cv2.line fixed point (shift=4: 1/16 px), the coarsest grid among the
#: rounded-ends renderers tried; an end falls that close for 1/16 of ends on an axis, so a dropped end pixel
#: is still decided at the other ends.
ROUNDED_END_TIE_PX = 1.0 / 32.0
#: A renderer's aliased pixels are read as a correct drawing by another rule of the line model
#: (oracles.line_model, "rounded") only where their F1@0px against that rule's drawing is at least
#: this (or the run's F1@0px floor, if higher): measured 0.999-1.000 in every case of Pillow, Bresenham and
#: cv2 LINE_8 (21 bundled cases each); GL's own pixels with each line's last pixel dropped measure 0.83-0.92
#: against it. Without it a run with --min-f1-0px 0 would read any drawing whose one-sided pixels balance
#: against the rounded ends' as theirs. 0.98, GL's own F1@0px bound.
RULE_F1_0PX = 0.98


@dataclass
class Tolerances:
    """The limits a run judges with (defaults: the values above; the CLI's --tol-px, --min-f1, ... override them).

    ``vertex_px`` is the floor of each case's vertex bound (:func:`vertex_bound`);
    ``precision`` the candidate's declared precision (``--candidate-precision``),
    None to infer it from the candidate's answers (oracles.candidates.candidate.case_precision).
    """

    vertex_px: float = VERTEX_TOL_PX
    min_f1_1px: float = MIN_F1_1PX
    min_f1_0px: float = MIN_F1_0PX
    min_iou: float = MIN_SILHOUETTE_IOU
    balance_alpha: float = BALANCE_ALPHA
    max_imbalance: float = MAX_IMBALANCE_FRACTION
    max_edge_count_diff: int = MAX_EDGE_COUNT_DIFF
    precision: str | None = None
    offset_px: float = OFFSET_TOL_PX
    scale_px: float = SCALE_TOL_PX
    rule_offset_px: float = RULE_OFFSET_MAX_PX
    end_px: float = END_TOL_PX
    rounded_end_tie_px: float = ROUNDED_END_TIE_PX
    rule_f1_0px: float = RULE_F1_0PX
    max_depth_error_ratio: float = MAX_DEPTH_ERROR_RATIO
    max_surface_holes_px: int = MAX_SURFACE_HOLES_PX
    max_surface_extra_px: int = MAX_SURFACE_EXTRA_PX
    max_object_id_px: int = MAX_OBJECT_ID_PX
    fill_tie_px: float = FILL_TIE_PX
    max_silhouette_run_px: int = MAX_SILHOUETTE_RUN_PX
    oracle_limit_px: float = ORACLE_LIMIT_PX

    def __post_init__(self):
        if self.precision is not None and self.precision not in PRECISIONS:
            raise ValueError(
                f"precision {self.precision!r}: expected one of {', '.join(PRECISIONS)} (or None: "
                "inferred from the candidate's answers)"
            )

    def to_dict(self, shaded: bool = False) -> dict:
        """The report's ``tolerances`` field."""
        if shaded:
            return {
                "vertex_error_px": self.vertex_px,
                "candidate_precision": self.precision,
                "min_silhouette_iou": self.min_iou,
                "depth_error": DEPTH_BOUND_TEXT,
            }
        return {
            "vertex_error_px": self.vertex_px,
            "candidate_precision": self.precision,
            "min_pixel_f1_1px": self.min_f1_1px,
            "min_pixel_f1_0px": self.min_f1_0px,
            "balance_alpha": self.balance_alpha,
            "max_imbalance_fraction": self.max_imbalance,
            "max_edge_count_diff": self.max_edge_count_diff,
        }

    def surfaces_dict(self) -> dict:
        """The limits of a job's depth maps and filled frames, as the report's ``tolerances`` adds them."""
        return {
            "max_depth_error_ratio": self.max_depth_error_ratio,
            "depth_error": DEPTH_BOUND_TEXT + " + the map's encoding step",
            "max_surface_holes_px": self.max_surface_holes_px,
            "max_surface_extra_px": self.max_surface_extra_px,
            "min_silhouette_iou": self.min_iou,
            "min_iou_union_px": MIN_IOU_UNION_PX,
            "fill_tie_px": self.fill_tie_px,
            "max_silhouette_run_px": self.max_silhouette_run_px,
            "max_object_id_px": self.max_object_id_px,
        }

    def lines_dict(self) -> dict:
        """The frames path's line-geometry limits, as the report's ``tolerances`` adds them."""
        return {
            "offset_px": self.offset_px,
            "scale_px": self.scale_px,
            "rule_offset_px": self.rule_offset_px,
            "end_px": self.end_px,
            "rounded_end_tie_px": self.rounded_end_tie_px,
            "rule_f1_0px": self.rule_f1_0px,
        }


@dataclass(frozen=True)
class NamingThresholds:
    """The thresholds that decide a verdict or a name but are not a run's to set (no CLI option), each with
    its reason: read by oracles.judge.decide and oracles.judge.name_faults (the frames path), by the image
    diagnosis (oracles.diagnosis.image_diagnose, image_naming, image_visibility, rule_read) and by the vertex
    diagnosis (oracles.diagnosis.diagnose, clip_planes), the unprojector's (unproject_faults) and the
    line measures (oracles.judge.even_lean, line_ends, coverage_pixels, line_profile), by the depth maps'
    pixel maps (oracles.diagnosis.depth_faults) and the filled frames' silhouettes (silhouette_faults). They were
    module constants of line_style, free_ends, f1_radius, dim_lines, image_visibility, image_diagnose, rule_read,
    diagnose, clip_planes, unproject_faults, even_lean, line_ends, coverage_pixels, line_profile, depth_pixels and
    silhouette_faults; their values are unchanged.
    """

    #: A pixel counts as drawn from this coverage (luminance x alpha / 255) up: docs/frames.md's rule
    #: (oracles.candidates.png_frame). Lines whose level is above 0 and under it drew nothing by the rule:
    #: named ``unexplained`` (dim lines), not the image diagnosis' ``depth_flip``.
    drawn_level: int = 128
    #: A case's lines are binary (aliased) when at most this share of the drawn pixels is an intermediate grey
    #: (between 1/8 and 7/8 of the level): antialiased lines have a third or more (4x4 supersampled 1-px
    #: lines measured 0.6-0.8). Binary lines are held to ``rule_offset_px`` and a warp half a pixel looser.
    grey_share_max: float = 0.05
    #: Binary lines are quantised line by line (up to half a pixel each, which a reference drawing matches
    #: only for its own rule): their warp is held to ``Tolerances.scale_px`` plus this half pixel (px).
    binary_warp_px: float = 0.5
    #: The line centres are measured (and may name ``pixel_offset``) only where at least this share of the
    #: windows along the oracle's lines holds a line: a correct renderer nearly all, lines mirrored or
    #: scaled away few.
    min_found_share: float = 0.5
    #: Free ends a case must have measured for their median to be judged (one stray end cannot decide).
    min_ends: int = 4
    #: A grey value is one of the lines' coverage levels when at least this share of the drawn pixels has it
    #: (line_style): coverage in few levels (4x MSAA: 0, 1/4, ... 1) moves a centroid by up to half a level's
    #: step, which grey lines' offset bound adds (offset_px + 0.5 / levels).
    level_share_min: float = 0.002
    #: Coverage across a line (px) from which it is ``wide`` (line_style): a 1-px aliased line has at most
    #: sqrt(2) = 1.41 pixels per unit length (diagonal), a 2-px line 2; 1.75 parts them. Wide lines are
    #: judged by their centres and F1 at their radius, not by GL's pixel rule.
    wide_min_px: float = 1.75
    #: Binary lines drawing this many pixels per pixel of the oracle's 1-px lines are wide whatever the median
    #: across them (line_style, even_lean): a 1-px line of any aliased rule draws one pixel per step of its
    #: major axis (the ratio 1, give or take its ends); Pillow's width 2 measured 1.85-2.1 on the bundled job.
    wide_pixel_ratio: float = 1.5
    #: The widest F1 radius (px, oracles.judge.f1_radius): lines up to 5 px across (1 + ceil((5 - 1) / 2) = 3).
    #: A wider line is still held to 3 px (its outer pixels count against it: a stricter F1, never a looser one).
    max_radius_px: int = 3
    #: A ``line_pixel_bias`` whose one-sided pixels are mostly whole pieces of line is a visibility
    #: difference: at least this share of its decided one-sided pixels (per frame) lie farther than 1 px from
    #: the other side (a line drawn too thick or too thin never leaves a pixel that far).
    visibility_share: float = 0.5
    #: A pixel is on one side only (image_visibility's set difference: ``candidate_only_px``,
    #: ``oracle_only_px``) when the other side has no pixel within this distance (px): F1@1px's tolerance,
    #: so the sets counted are the pixels F1@1px counts against the candidate.
    near_px: float = 1.0

    # ---- the image diagnosis: a case's frames registered to the oracle's lines (oracles.diagnosis.image_diagnose)

    #: A case needs this many drawn candidate pixels to be registered; fewer are named ``unexplained``
    #: (``underdetermined``). The fit (a scale and an offset per axis, for each signed permutation) is
    #: determined by a handful of points; 50 keeps a few stray pixels from being read as a picture.
    min_registered_px: int = 50
    #: The registration's cost (px: the mean of its two directions' mean distances) above which no member
    #: of the family (mirrors, swaps, per-axis scale, offset) draws the pixels: ``unexplained`` (or the
    #: visibility advice), and the scale restarts are tried. Measured (docs/frames.md, "Limits, measured"):
    #: correct 1-px aliased lines 0.30-0.33 px (pixel centres lie within 0.5 px of a line across its minor
    #: axis), anti-aliased 0.41-0.43, 2-px wide 0.44; a transposed rotation 1.2-4.8. 0.85 is ~2x the
    #: largest correct cost and under the smallest of a rotation the family cannot draw.
    residual_max_px: float = 0.85
    #: A permutation other than the identity is named only when the identity's cost exceeds its cost by
    #: more than this share, and two permutations within this share of each other are ``ambiguous``
    #: (image_naming): a symmetric picture (a cube seen along an axis, an orthographic view of a centrally
    #: symmetric scene) fits several with relative differences below 1e-2 (measured); 0.05 is 5x that.
    ambiguous_ratio: float = 0.05
    #: The free affine fit's off-diagonal terms (a rotation, a shear) are ``unexplained`` when they move
    #: some pixel by more than this (px): <= 0.04 px on a correct renderer, 0.77-1.17 px for a 0.5 degree
    #: roll (measured on tests/test_image_diagnosis.py's cameras); 0.3 is 7x the first and under half
    #: the second.
    rotation_px: float = 0.3
    #: How far (px) a rule that rounds each end to a pixel centre may put a line's farthest end, along each
    #: axis, from where its scale puts it: half a pixel, the rounding (oracles.diagnosis.rule_read). Under
    #: that rule a scale is named only when it moves a pixel by more than ``Tolerances.scale_px`` plus
    #: this. Measured: a correct LINE_8 on prism / on_axis fits an aspect of 0.53 px at 111 px reach (named
    #: without it); the wrong-axis FOV drawn by Bresenham 0.6-0.73 px; a 3 % aspect mistake 3 px or more.
    rounded_end_px: float = 0.5
    #: Both aliased rules (GL's, ends rounded) are read when the farther rule's registration cost is within
    #: this share of the closer one's (oracles.diagnosis.rule_read): correct rounded-ends renderers fit
    #: GL's lines closer on 4-5 of 21 cases by up to 30 % of the cost (LINE_8, pyramid / non_square:
    #: 0.374 against 0.485); 1/3 is above that largest misread.
    rule_tie: float = 1.0 / 3.0

    # ---- the vertex diagnosis (oracles.diagnosis.diagnose): the candidate's pixels against OpenCV's

    #: ``depth_flip`` when the candidate's and the oracle's visible sets nearly miss each other: at most
    #: this share of their union in common. A depth flip makes them disjoint exactly when near > 0 (no
    #: point has both z >= near and -z >= near); 1 % allows a candidate that also differs at the near/far
    #: boundary or an orthographic [near, far] reaching slightly behind the camera, while a real near/far
    #: error changes only the few points close to a plane and keeps far more than 1 % in common.
    depth_flip_max_overlap: float = 0.01
    #: The common points must span 2D for a linear map to be fitted: the smaller singular value of the
    #: centred points at least this share of the larger (else only a constant offset is read).
    #: Collinear points give ~1e-16 (float noise); 1e-6 keeps the fit's condition number <= 1e6, so
    #: float64 noise moves the fitted map by < 1e-10 relative, far below any fault.
    degenerate_ratio: float = 1e-6
    #: Float32 roundings of size eps32 a float64 projector's constant may carry into the fitted map
    #: (a scale or offset within them is ``precision_limited``, not a fault): a float32 focal length,
    #: aspect or GL matrix entry is off by <= 0.5 eps32 relative, and a scale composes two such constants
    #: (fx from f and the aspect): 1 eps32; 2 leaves 2x.
    constant_roundings: float = 2.0
    #: A line end is named in ``line_end_bias`` when its net one-sided pixels are at least this many per
    #: line (oracles.diagnosis.diagnose.diagnose_lines): a quarter pixel on average, far above what an
    #: unbiased rasterizer leaves (one-sided pixels at ends of both signs cancel), far below the one pixel
    #: a line that drops (adds) its end pixel leaves.
    line_end_min_px: float = 0.25

    # ---- the candidate's own clipping planes, probed (oracles.diagnosis.clip_planes; oracles.spec.checks)

    #: A fitted plane within this relative distance of the camera's is the camera's (no
    #: ``clipping_plane``): float64 rounding of a depth test is a few eps64 (1e-15), the probe's own
    #: bracket ~1e-11 relative; 1e-9 sits between them and far below float32's rounding of a plane (6e-8).
    plane_rel_tol: float = 1e-9
    #: A plane off by at most this many eps32 (relative; the far plane also times far/near, the
    #: conditioning of a GL matrix's depth row) is float32 rounding (``float32_near``/``float32_far``, and
    #: the slack the drawn ends are given), not a wrong plane: one rounding of near is 0.5 eps32, a float32
    #: GL matrix's A and B each add one (measured on PyGLM-style matrices: <= 1.1 eps32 near).
    float32_plane_roundings: float = 4.0

    # ---- an unprojector's points (oracles.diagnosis.unproject_faults)

    #: A mistaken inverse explains the candidate when every point is within this many of its bounds: the
    #: mistake's parameters are medians of reprojected points, each within its own bound, so they move the
    #: model by up to about one bound; doubled for the two sides' roundings: 4.
    unproject_fit_slack: float = 4.0

    # ---- binary lines of an even width (oracles.judge.even_lean): which band each edge is measured against

    #: The leaning bands replace the symmetric one when they lower the mean square residual of the edges'
    #: means by this (px^2): the square of a quarter pixel (what a leaning edge, 0.5 px on the minor axis
    #: times |n_minor| >= 0.71, leaves under the symmetric band is at least 0.35 px), for a quarter of the
    #: edges. Measured: Pillow 2 px 0.12-0.30 symmetric against 0.02-0.05 leaning; symmetric 2-px bands,
    #: moved or not, 0.000-0.001 against 0.000-0.016.
    lean_gain_px2: float = 0.25 * 0.25**2
    #: Cases with at most this many edges' worth of samples (their effective number) cannot test the
    #: symmetric band: its offset (two numbers) fits two edges exactly and leaves a third one number to
    #: check, so the leaning fit (the smaller offset, by the lean's ambiguity) is used there.
    max_untested_edges: float = 3.0
    #: Least samples of an edge for its mean to count in the fit (fewer: the edge's mean is noise, and the
    #: edge keeps the symmetric band).
    min_edge_samples: int = 5

    # ---- a case's one-sided line pixels (oracles.judge.line_ends)

    #: A one-sided pixel within this distance (px) of a segment's start or end counts as at that end
    #: (``line_end_bias`` reads the ends' counts), and one farther than it from every segment is ``stray``:
    #: a pixel beside an end pixel (diagonal: sqrt(2) = 1.41 px) is still that end's; 1.5 keeps the next
    #: pixel along the line (2 px) in the ``middle``.
    end_reach_px: float = 1.5

    # ---- antialiased frames (oracles.judge.coverage_pixels)

    #: The thinnest antialiased line whose every row (column) keeps a drawn pixel (px): a pixel under the
    #: drawn level is drawn too where it is a ridge across a line holding at least half this width's
    #: coverage (a line <= 1 px wide splits its coverage across a row between at most two pixels, the larger
    #: holding at least half of it). Thinner lines (coverage under a quarter where they fall between two
    #: pixels) cannot be read; a 1-px line between two pixels (127 | 127) is read.
    ridge_min_width_px: float = 0.5

    # ---- a line's profile across it (oracles.judge.line_profile: line_style, even_lean, free_ends)

    #: A window across a line is a sample of it (line_style.measure), and a free end's inner window holds a
    #: line (free_ends), from this much coverage on (in units of a fully covered pixel): half a pixel's worth.
    #: A drawn line of any rule or width puts at least one pixel's coverage in each window across it (a 1-px
    #: line one pixel per step of its major axis), so a line that is there is a sample; a missing line is no
    #: sample (F1 fails on it), and a stray half-covered pixel's worth is not read as a line.
    profile_min_mass: float = 0.5
    #: A case's line geometry (the pooled offset, the fitted warp, the width across free lines, the lean of
    #: even-width lines) is measured only from this many samples (line_profile.pooled_offset,
    #: line_style.fit_lines, even_lean.fit): the fit has up to six numbers (an offset, a 2 x 2 warp), so 20
    #: leaves over three samples a number; fewer is too little free line, and the geometry is not measured
    #: (the pixel criteria still judge the case).
    profile_min_samples: int = 20

    # ---- a depth map's pixel maps (oracles.diagnosis.depth_pixels, read by depth_faults)

    #: A pixel map (flip, offset, scale) keeps the surfaces together while at most this share of the
    #: candidate's surface pixels lands where the reference shows nothing (all four neighbours empty).
    #: Measured, each pixel mistake under its own map: at most 0.32 % (prism, near_plane: the near plane's clip
    #: line); 1 % leaves 3x. This share does not tell the maps apart (a fitted scale can shrink any surface
    #: inside another): the residuals do.
    depth_outside_max: float = 0.01
    #: ... and at least this share of them lands inside one face, for the residuals to speak for the map (a
    #: few-pixel sliver cannot name a fault): half (measured under the right map: 95 % at least).
    depth_interior_min: float = 0.5
    #: A value model of a depth map (oracles.diagnosis.depth_faults) explains it when every residual is within
    #: this many allowances. A parameter fitted (a median) from pixels that each sit within their own bound
    #: moves the model by up to one bound at another pixel; doubled for the rounding of the stored value
    #: against the model's float64 one: 4. Measured over core's maps with one mistake each (3 scenes x 7 cases,
    #: tests/test_depth_faults.py): the named model's worst residual is 0.50 allowances (a float16 map; 0.09
    #: for the others), the nearest wrong model's 19 (depth_offset on a float16 map).
    depth_fit_slack: float = 4.0
    #: Values of a stored depth-buffer encoding (window [0, 1], NDC [-1, 1]) lie within 1 + this of the range:
    #: float32 rounding of values of size 1 (eps32 = 1.2e-7), with room to spare.
    depth_encoding_margin: float = 1e-6
    #: A depth map's quantisation steps are whole multiples of its least gap to this relative tolerance: the
    #: rescaled levels of an 8-bit map (n + k (f - n) / 255) carry float32 rounding of ~1e-7 of their size;
    #: 1e-3 leaves the gaps of a float32 map of a smooth surface (no common step) out.
    depth_step_tolerance: float = 1e-3

    # ---- a filled frame's silhouette (oracles.diagnosis.silhouette_faults)

    #: A camera mistake's model explains the frames when its misses (decided pixels where its silhouette and
    #: the candidate's differ) are at most this share of the reference's boundary pixels. A fitted parameter
    #: off by ``e`` px (of its move at the silhouette's edge) flips the decided centres within ``e`` of an edge:
    #: ~``e`` per boundary pixel (one centre per pixel of edge length, each within ``e`` with probability
    #: ``e``). The polished fit ends on steps of 0.01 px, so 0.05 leaves 5x; the smallest mistake of the
    #: family, half a pixel, misses ~0.5 per boundary pixel under the identity. Measured
    #: (tests/test_silhouette_faults.py, 3 scenes x 7 cases): the named model's worst ratio 0.0063, the
    #: nearest model of another name 0.285 (a scale per axis about ``c`` imitating the pyramid's half-pixel
    #: shift at wide_fov, where it is small).
    silhouette_allowance: float = 0.05
    #: A fitted model's parameters are polished on its misses (coordinate descent, down to 0.01 px steps)
    #: when the moments' fit misses at most this many allowances (``silhouette_allowance`` x the boundary
    #: pixels): near enough to explain once polished (measured: offsets of silhouettes cut by the image's
    #: border, whose moments are biased, miss up to 1.4 allowances before), while a wrong model (>= 5.7
    #: allowances measured) costs no further pass.
    silhouette_polish_below: float = 2.0


#: The one naming-thresholds record (oracles.judge.decide, oracles.judge.name_faults, the diagnosis).
NAMING = NamingThresholds()


def line_failures(lines: dict, tol) -> list[str]:
    """Why a case's pooled line fields (oracles.judge.metrics.line_summary) fail ``tol``; [] if they pass.

    The balance fails when the sign test rejects symmetry (p < ``tol.balance_alpha``)
    *and* the net imbalance is more than ``tol.max_imbalance`` of the oracle's
    pixels, both over the decided one-sided pixels (sub-pixel ties left out,
    oracles.judge.metrics.balance_scores); the counts fail when some edge in some frame has more than
    ``tol.max_edge_count_diff`` pixels more or fewer than the oracle's.
    """
    out = []
    frac, p = lines["imbalance_fraction"], lines["balance_p_value"]
    if p < tol.balance_alpha and abs(frac) > tol.max_imbalance:
        tc, to = lines["subpixel_ties"]
        ties = f" (and {tc} + {to} sub-pixel ties, left out)" if tc + to else ""
        out.append(
            f"one-sided pixels unbalanced: {lines['candidate_only'] - tc} candidate-only vs "
            f"{lines['oracle_only'] - to} oracle-only{ties}, net {frac:+.3%} of the oracle's pixels "
            f"(> {tol.max_imbalance:.3%}; sign test p = {p:.2g} < {tol.balance_alpha:g})"
        )
    if lines["edge_count_max_diff"] > tol.max_edge_count_diff:
        w = lines["edge_count_worst"]
        out.append(
            f"edge {w['edge']} has {w['diff']:+d} pixels against the oracle's count "
            f"(allowed +-{tol.max_edge_count_diff}; frame {w['frame']})"
        )
    return out
