"""A calibrated-camera projector as robotics and vision code writes it: K, R, t and a lens.

OpenCV's pinhole model with Brown-Conrady distortion (the documentation of
``cv2.projectPoints`` / "Camera Calibration and 3D Reconstruction")::

    [x, y, z] = R X + t,   x' = x / z,  y' = y / z,   r^2 = x'^2 + y'^2
    radial    = (1 + k1 r^2 + k2 r^4 + k3 r^6) / (1 + k4 r^2 + k5 r^4 + k6 r^6)
    x'' = x' radial + 2 p1 x' y' + p2 (r^2 + 2 x'^2)
    y'' = y' radial + p1 (r^2 + 2 y'^2) + 2 p2 x' y'
    u = fx x'' + cx,   v = fy y'' + cy

written out by hand in numpy, as code that cannot depend on OpenCV does
(an embedded target, a shader). ``project`` follows it; ``project_no_lens``
stops at ``x', y'`` (the lens forgotten), ``project_k1_sign`` has the sign of
k1 flipped (a barrel lens taken for a pincushion). Perspective only.
"""

import numpy as np


def _distort(xn, yn, coeffs):
    k = np.zeros(8)
    k[: len(coeffs)] = coeffs
    k1, k2, p1, p2, k3, k4, k5, k6 = k
    r2 = xn * xn + yn * yn
    radial = (1 + r2 * (k1 + r2 * (k2 + r2 * k3))) / (1 + r2 * (k4 + r2 * (k5 + r2 * k6)))
    xd = xn * radial + 2 * p1 * xn * yn + p2 * (r2 + 2 * xn * xn)
    yd = yn * radial + p1 * (r2 + 2 * yn * yn) + 2 * p2 * xn * yn
    return xd, yd


def _project(points, camera, lens):
    K, R, t = camera.K, camera.R, camera.t
    p_cv = np.asarray(points, float) @ R.T + t
    z = p_cv[:, 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        xn, yn = p_cv[:, 0] / z, p_cv[:, 1] / z
    coeffs = lens(camera.distortion)
    if coeffs is not None:
        xn, yn = _distort(xn, yn, coeffs)
    px = np.stack([K[0, 0] * xn + K[0, 2], K[1, 1] * yn + K[1, 2]], axis=1)
    px[(z < camera.near) | (z > camera.far)] = np.nan
    return px


def project(points, camera):
    return _project(points, camera, lambda d: d)


def project_no_lens(points, camera):
    return _project(points, camera, lambda d: None)


def project_k1_sign(points, camera):
    def flipped(d):
        if d is None:
            return None
        d = list(d)
        d[0] = -d[0]
        return d

    return _project(points, camera, flipped)
