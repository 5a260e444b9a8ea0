"""Every tolerance of crosscheck, in one place, each with the reason for its value.

``--tol-px`` overrides VERTEX_TOL_PX; ``--min-f1`` overrides MIN_F1_1PX.
"""

#: Max vertex error in pixels between the candidate and cv2.projectPoints.
#: Both compute in float64: relative error ~ a few eps (2.2e-16) per operation,
#: times ~20 operations, times the pixel scale (|x_px| up to ~1e4 for the bundled
#: cases) gives ~1e-11 px. 1e-6 px leaves five orders of margin for that and
#: still catches any real convention error (the smallest, a half-pixel offset,
#: is 0.5 px).
VERTEX_TOL_PX = 1e-6

#: Minimum edge-pixel F1 at 1 px (Chebyshev) against pyrender/OSMesa.
#: Measured over the bundled scenes and cameras (README, "Pixel agreement"):
#: see the README for the measured minimum. Mesa's llvmpipe draws lines as
#: parallelograms with diamond-exit end adjustments; in the middle of a line the
#: pixels agree exactly, a 1-px tolerance absorbs end-pixel and tie differences.
MIN_F1_1PX = 0.99

#: Minimum edge-pixel F1 at 0 px. Exact agreement is limited by end pixels
#: (GL omits an end pixel by the diamond-exit rule; ours draws both) and by
#: rounding ties; set below the measured minimum (README, "Pixel agreement").
MIN_F1_0PX = 0.90

#: Pixel tolerances at which precision/recall/F1 are reported.
PIXEL_TOLS = (0, 1)
