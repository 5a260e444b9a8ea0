"""Every tolerance of crosscheck, in one place, each with the reason for its value.

``--tol-px`` overrides VERTEX_TOL_PX, ``--min-f1`` MIN_F1_1PX and
``--min-f1-0px`` MIN_F1_0PX.
"""

#: Max vertex error in pixels between the candidate and cv2.projectPoints.
#: Both compute in float64: relative error ~ a few eps (2.2e-16) per operation,
#: times ~20 operations, times the pixel scale (|x_px| up to ~1e4 for the bundled
#: cases) gives ~1e-11 px. 1e-6 px leaves five orders of margin for that and
#: still catches any real convention error (the smallest, a half-pixel offset,
#: is 0.5 px).
VERTEX_TOL_PX = 1e-6

#: Minimum edge-pixel F1 at 1 px (Chebyshev) against pyrender/OSMesa.
#: Measured: 1.0 in every one of 1,512 frames (3 scenes x 7 cameras x 72
#: frames) and in 432 frames of four other cameras (README, "Pixel
#: agreement"): a pixel that is not within 1 px of the oracle's line is a real
#: error. 0.999 allows one stray pixel per ~1,000 line pixels, for
#: float32-vs-float64 decisions in the shader that a 1-px tolerance cannot absorb
#: (none seen so far), and catches a half-pixel offset (F1@1 stays 1.0 for that
#: one: the vertex check is what catches it).
MIN_F1_1PX = 0.999

#: Minimum edge-pixel F1 at 0 px. core/raster.py emulates GL's diamond-exit
#: rule, llvmpipe's tie directions and its 1/256 px vertex snap; what is left
#: are decisions within ~1/512 px of a boundary, where llvmpipe decides on
#: float32 vertices and we on float64. Measured minimum over 1,512 frames of
#: the bundled cases: 0.9958 (worst frame of a case; mean 0.9997). 0.98 leaves
#: room for scenes with many short edges (each differing pixel weighs more)
#: and fails a half-pixel offset (F1@0 ~ 0.5).
MIN_F1_0PX = 0.98

#: Pixel tolerances at which precision/recall/F1 are reported.
PIXEL_TOLS = (0, 1)
