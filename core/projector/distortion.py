"""Lens distortion, OpenCV's model: ideal normalised coordinates to distorted ones.

A distorted camera projects in three steps (core.conventions, "Lens
distortion"): camera space to *ideal normalised* coordinates in OpenCV's
axes (x right, y down, on the plane z = 1), then :func:`distort`, then the
intrinsics to pixels::

    x_n = x_cam / z_cam,      y_n = -y_cam / z_cam          (y down, as OpenCV)
    x_d, y_d = distort(x_n, y_n)
    x_px = cx + fx x_d,       y_px = cy + fy y_d

:func:`distort` is OpenCV's ``projectPoints`` model (its documentation,
"Camera Calibration and 3D Reconstruction"), written from the formula::

    r2 = x_n^2 + y_n^2
    radial = (1 + k1 r2 + k2 r2^2 + k3 r2^3) / (1 + k4 r2 + k5 r2^2 + k6 r2^3)
    x_d = x_n radial + 2 p1 x_n y_n + p2 (r2 + 2 x_n^2)
    y_d = y_n radial + p1 (r2 + 2 y_n^2) + 2 p2 x_n y_n

The model is a polynomial fitted inside the image: far outside it (large
``r2``) it may fold back (k1 < 0) or blow up; nothing here pretends otherwise.
Only the vertices are distorted: straight edges stay straight when drawn (as
in GL), so frames of a distorted camera are not compared at the pixel level.
"""

from __future__ import annotations

import numpy as np

__all__ = ["distort"]


def distort(p_n: np.ndarray, coefficients: tuple) -> np.ndarray:
    """``(N, 2)`` ideal normalised coordinates (x right, y down) to distorted ones.

    Parameters
    ----------
    p_n : (N, 2) ndarray of float
        ``(x_cam / z_cam, -y_cam / z_cam)``.
    coefficients : tuple of float
        4, 5 or 8 numbers, as :func:`core.camera.check_coefficients` returns them.

    Returns
    -------
    p_d : (N, 2) ndarray, ``p_n``'s dtype.

    Examples
    --------
    >>> distort(np.array([[0.5, 0.0]]), (0.1, 0.0, 0.0, 0.0)).tolist()   # 0.5 (1 + 0.1 * 0.25)
    [[0.5125, 0.0]]
    """
    t = p_n.dtype.type
    k1, k2, p1, p2, k3, k4, k5, k6 = (t(v) for v in tuple(coefficients) + (0.0,) * (8 - len(coefficients)))
    x, y = p_n[:, 0], p_n[:, 1]
    r2 = x * x + y * y
    radial = t(1) + r2 * (k1 + r2 * (k2 + r2 * k3))
    if len(coefficients) == 8:
        radial = radial / (t(1) + r2 * (k4 + r2 * (k5 + r2 * k6)))
    xy = x * y
    out = np.empty_like(p_n)
    out[:, 0] = x * radial + t(2) * p1 * xy + p2 * (r2 + t(2) * x * x)
    out[:, 1] = y * radial + p1 * (r2 + t(2) * y * y) + t(2) * p2 * xy
    return out
