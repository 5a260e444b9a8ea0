"""A GL-style projector as a glm user writes it, in float32 like glm's default ``vec3``/``mat4``.

glm 0.9.9 ``lookAtRH``, ``perspectiveRH_NO``, ``orthoRH_NO`` and ``projectNO``
(glm/ext/matrix_clip_space.inl, matrix_transform.inl, matrix_projection.inl),
written as row-major math matrices acting on column vectors (glm stores them
column-major; the maths is the same)::

    lookAtRH:  rows  s, u, -f  with  f = normalize(center - eye),
               s = normalize(f x up), u = s x f; translation -dot(row, eye)
    perspectiveRH_NO: [1/(aspect tan), 0, 0, 0], [0, 1/tan, 0, 0],
               [0, 0, -(far+near)/(far-near), -2 far near/(far-near)], [0, 0, -1, 0]
    projectNO: ndc = clip / w;  win = (ndc * 0.5 + 0.5) * viewport size + viewport origin

``projectNO`` returns window coordinates: y up from the bottom edge, pixel
centres at +0.5. ``project_naive`` returns them as they come, which is what a
newcomer does (a vertical mirror and a half-pixel offset against the contract);
``project`` converts them: ``x_px = win_x - 0.5``, ``y_px = H - win_y - 0.5``.
Clipping is GL's: a point is kept when ``-w <= z_clip <= w``, in float32.
"""

import numpy as np

F = np.float32


def _normalize(v):
    return v / np.sqrt(np.sum(v * v), dtype=F)


def look_at_rh(eye, center, up):
    f = _normalize(center - eye)
    s = _normalize(np.cross(f, up))
    u = np.cross(s, f)
    m = np.eye(4, dtype=F)
    m[0, :3], m[1, :3], m[2, :3] = s, u, -f
    m[0, 3], m[1, 3], m[2, 3] = -s @ eye, -u @ eye, f @ eye
    return m


def perspective_rh_no(fovy_rad, aspect, near, far):
    t = np.tan(F(fovy_rad) / F(2))
    m = np.zeros((4, 4), dtype=F)
    m[0, 0] = F(1) / (F(aspect) * t)
    m[1, 1] = F(1) / t
    m[2, 2] = -(F(far) + F(near)) / (F(far) - F(near))
    m[2, 3] = -(F(2) * F(far) * F(near)) / (F(far) - F(near))
    m[3, 2] = F(-1)
    return m


def ortho_rh_no(left, right, bottom, top, near, far):
    m = np.eye(4, dtype=F)
    m[0, 0] = F(2) / (F(right) - F(left))
    m[1, 1] = F(2) / (F(top) - F(bottom))
    m[2, 2] = -F(2) / (F(far) - F(near))
    m[0, 3] = -(F(right) + F(left)) / (F(right) - F(left))
    m[1, 3] = -(F(top) + F(bottom)) / (F(top) - F(bottom))
    m[2, 3] = -(F(far) + F(near)) / (F(far) - F(near))
    return m


def _window(points, camera):
    eye = np.asarray(camera.position, dtype=F)
    center = eye + np.asarray(camera.forward, dtype=F)
    view = look_at_rh(eye, center, np.asarray(camera.up, dtype=F))
    w, h = camera.width, camera.height
    if camera.projection == "perspective":
        proj = perspective_rh_no(np.radians(camera.fov_y_deg), w / h, camera.near, camera.far)
    else:
        half_h = camera.ortho_height / 2
        half_w = half_h * w / h
        proj = ortho_rh_no(-half_w, half_w, -half_h, half_h, camera.near, camera.far)
    p = np.concatenate([np.asarray(points, dtype=F), np.ones((len(points), 1), dtype=F)], axis=1)
    clip = p @ (proj @ view).T
    with np.errstate(divide="ignore", invalid="ignore"):
        ndc = clip[:, :3] / clip[:, 3:4]
    win = (ndc[:, :2] * F(0.5) + F(0.5)) * np.array([w, h], dtype=F)
    inside = (clip[:, 3] > 0) & (np.abs(clip[:, 2]) <= clip[:, 3])
    win[~inside] = np.nan
    return win


def project_naive(points, camera):
    """glm's window coordinates returned as pixels (y up, centres at +0.5)."""
    return _window(points, camera)


def project(points, camera):
    """glm's window coordinates converted to the contract's pixels."""
    win = _window(points, camera)
    return np.stack([win[:, 0] - F(0.5), F(camera.height) - win[:, 1] - F(0.5)], axis=1)
