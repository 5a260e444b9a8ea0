"""The conventions of wirecheck, stated once. Everything else refers here.

Spaces and their names
======================
A value's name says which space it lives in::

    p_model  (N, 3)  scene file coordinates
    p_world  (N, 3)  after the frame's model matrix
    p_cam    (N, 3)  camera space
    p_px     (N, 2)  pixel space (NaN rows for clipped points)

World space
-----------
Right-handed, as in pyrender, trimesh, glTF and OpenCV. A camera is given by
``position``, ``forward`` (the view direction) and ``up`` (toward the top of
the image), and ``right = forward x up``::

            +Y (up)
             |
             |
             +------ +X (right)        camera at (0, 0, D) looking at the
            /                          origin with up +Y: forward = -Z,
           /                           right = (-Z) x (+Y) = +X, so +X shows
         +Z (toward the viewer)        on the right and +Y shows up.

Camera space
------------
x right, y up, z forward (along the view direction). Depth is ``z``: positive
in front of the camera. The rows of the rotation ``world_to_cam`` are
``right, up, forward``; ``p_cam = R (p_world - position)``.
(This basis is left-handed: right x up = -forward. It is exactly OpenCV's camera
space with y negated; see ``oracles/references/convert.py``.)

Pixel space
-----------
x right (columns), y down (rows), origin at the top-left pixel, and **integer
coordinates are pixel centres** (OpenCV's convention): pixel (0, 0) covers
[-0.5, 0.5] x [-0.5, 0.5]; the image spans [-0.5, W - 0.5] x [-0.5, H - 0.5].
A centred camera's principal point is ``cx = (W - 1) / 2``, ``cy = (H - 1) / 2``.
Image arrays are indexed ``img[row, col] = img[y, x]``. Nothing flips y later:
row 0 is the top of the picture in the PNG, the ASCII frame and every oracle.

Field of view
-------------
``fov_y_deg`` is the full **vertical** field of view, measured edge to edge of
the image (top edge of row 0 to bottom edge of row H - 1)::

    f_px = (H / 2) / tan(fov_y / 2)

The same focal length is used for x (square pixels), so the horizontal FOV
follows from the aspect: ``tan(fov_x / 2) = (W / H) tan(fov_y / 2)``.
(The seed's ``d = 0.5 * width * tan(theta / 2)`` multiplies where it should
divide, and uses the width; it is not used here.)

Projection
----------
Perspective::

    x_px = cx + f_px * x_cam / z_cam
    y_px = cy - f_px * y_cam / z_cam          (minus: camera y is up, pixel y down)

Orthographic, with ``ortho_height`` world units visible vertically::

    s = H / ortho_height                       (pixels per world unit)
    x_px = cx + s * x_cam,   y_px = cy - s * y_cam

Calibrated cameras
------------------
A perspective camera may instead be given by its intrinsics ``fx, fy, cx,
cy`` in pixels (``Camera.intrinsics``; OpenCV's ``K = [[fx, 0, cx], [0, fy,
cy], [0, 0, 1]]``, no skew), with ``cx, cy`` in the same pixel-centre
coordinates as above (a centred camera has ``cx = (W - 1) / 2``)::

    x_px = cx + fx * x_cam / z_cam
    y_px = cy - fy * y_cam / z_cam

``fx`` scales image x (columns), ``fy`` image y (rows). A FOV camera is the
special case ``fx = fy = f_px``, ``(cx, cy)`` centred; a calibrated camera's
``fov_y_deg`` is the one ``fy`` implies, ``2 atan((H / 2) / fy)``.

Lens distortion
---------------
Optional OpenCV coefficients ``(k1, k2, p1, p2[, k3[, k4, k5, k6]])``
(``Camera.distortion``, perspective only) act on the ideal normalised
coordinates in **OpenCV's axes, y down**: ``x_n = x_cam / z_cam``, ``y_n =
-y_cam / z_cam``; then ``x_px = cx + fx x_d``, ``y_px = cy + fy y_d`` with
``(x_d, y_d)`` from ``core.projector.distortion`` (OpenCV's formula, so ``p1, p2`` and
OpenCV's ``projectPoints`` agree in sign). Only vertices are distorted: edges
are clipped against the undistorted frustum and drawn straight between
distorted ends, so frames of a distorted camera are not pixel-compared.

A point is *visible* when ``near <= z_cam <= far`` (both projections), and
*clipped* otherwise; clipped points get NaN pixel coordinates. Points outside
the image but inside [near, far] are visible (they have finite, off-image pixel
coordinates). Clipping against near/far happens in camera space, **before** the
divide: no point with ``z_cam < near`` is ever divided by.

Matrix convention
-----------------
Column vectors and 4x4 homogeneous matrices: ``p' = M @ p``. A composite
``M = A @ B`` applies ``B`` first, then ``A``. Arrays of points are row-stacked
``(N, 3)``, so the code computes ``p @ M[:3, :3].T + M[:3, 3]``; this is the
same thing, not a row-vector convention. ``compose(A, B, C) == A @ B @ C``
(C first). The model matrix of a frame is ``T @ R_z @ R_y @ R_x @ S``: scale,
then rotate about X, then Y, then Z (all about the model origin), then
translate. A motion with a pivot ``c`` (crosscheck's framing, oracles.cases)
scales and turns about ``c`` instead: ``T(offset + c) @ R_z @ R_y @ R_x @ S @ T(-c)``.

Rotations are right-handed (counter-clockwise when the axis points at the
viewer): ``rotate_z(90 deg)`` maps +X to +Y.

Motion and time
---------------
Frame ``k`` of ``n`` (1-based) has time ``t = (k - 1) / n`` in [0, 1). Its model
matrix is computed from ``t`` directly, never accumulated: frame 1 is the rest
pose, and a whole number of turns over the run returns to frame 1 exactly.
"""

from __future__ import annotations

__all__ = ["PIXEL_CENTRE_OFFSET", "focal_px", "principal_point"]

#: Integer pixel coordinates are pixel centres; GL window coordinates put pixel
#: centres at half-integers, so ``x_gl = x_px + PIXEL_CENTRE_OFFSET``.
PIXEL_CENTRE_OFFSET = 0.5


def focal_px(fov_y_deg: float, height: int) -> float:
    """Focal length in pixels for a full vertical FOV measured edge to edge."""
    import math

    return (height / 2.0) / math.tan(math.radians(fov_y_deg) / 2.0)


def principal_point(width: int, height: int) -> tuple[float, float]:
    """Principal point of a centred camera, in pixel-centre coordinates."""
    return ((width - 1) / 2.0, (height - 1) / 2.0)
