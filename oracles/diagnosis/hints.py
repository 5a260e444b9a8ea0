"""What to check for each fault name: :data:`FAULT_HINTS`, one line each, printed under a report's table.

Its own module, below the naming (oracles.diagnosis.image_naming) and the reports
(oracles.reports.report), which both read it.
"""


#: What to check for each fault: one line each, for people reading the report.
FAULT_HINTS = {
    "mirror_horizontal": "left and right are exchanged: check right = forward x up (not up x forward) "
                         "and x_px = cx + f x / z",
    "mirror_vertical": "the picture is upside down: pixel y grows downward, so y_px = cy - f y / z",
    "axis_flip": "the picture is turned 180 degrees: x and y are both negated (e.g. right and up "
                 "both negated in the world-to-camera rotation)",
    "axis_swap": "x and y are exchanged: return columns [x, y], not [row, col]",
    "fov_mismatch": "the focal length is off: f = (H / 2) / tan(fov_y / 2) with the vertical FOV in "
                    "radians; implied_fov_deg is the FOV that was used",
    "aspect_mismatch": "x and y are scaled differently: use one focal length for both axes (square "
                       "pixels); implied_aspect is the width/height ratio that was used",
    "pixel_offset": "a constant shift: integer pixel coordinates are pixel centres and the principal "
                    "point is ((W - 1) / 2, (H - 1) / 2); 0.5 is the pixel-corner convention",
    "distortion_mismatch": "the lens distortion differs from the camera's (kind: ignored, k1's sign, or a "
                           "coefficient's size): apply OpenCV's model to x/z, y/z with y down, before K: "
                           "r2 = x^2 + y^2, x (1 + k1 r2 + k2 r2^2 + k3 r2^3) + 2 p1 x y + p2 (r2 + 2 x^2)",
    "line_end_bias": "the vertices agree but the lines lose (or gain) pixels at one end: check the "
                     "rasterizer's end rule (GL diamond exit: the start pixel is drawn when the start point "
                     "is inside its diamond, the end pixel is not drawn when the end point is inside its own)",
    "line_pixel_bias": "the vertices agree but the candidate draws systematically more (or fewer) line pixels "
                       "than the oracle along the lines: check the line width (1 px) and the rounding of the "
                       "minor coordinate (nearest pixel centre)",
    "raster_rule": "the lines are where the oracle's are but their pixels follow another aliased line rule than "
                   "GL's (Pillow's, TinyGL's: ends snapped to pixel centres, another choice across the line): check "
                   "the line rasteriser, not the camera; --line-rule geometry judges the geometry only",
    "precision_limited": "the error is the size of float32 rounding, not a convention error: compute in "
                         "float64 or declare float32 (--candidate-precision float32)",
    "depth_flip": "the camera looks backward: depth must be positive in front, z = forward . (p - position)",
    "clipping_plane": "the points kept differ from near <= z <= far (z = forward . (p - position)): kind and "
                      "near_fit/far_fit say where the candidate clips (z_positive: at z > 0, not near; "
                      "float32_near: near rounded to float32; none: never; swapped: near and far exchanged)",
    "ambiguous": "the images fit two faults equally well (a symmetric view cannot tell them apart): "
                 "check both, see alternatives",
    "unexplained": "not a simple image-space fault: check the rotation order, a transposed "
                   "world-to-camera matrix, the up vector (roll) and the near/far test",
}
