"""A Direct3D-style projector, left-handed, as DirectXMath writes it (float32).

DirectXMath ``XMMatrixLookAtLH``, ``XMMatrixPerspectiveFovLH``,
``XMMatrixOrthographicLH`` (DirectXMathMatrix.inl) use row vectors
(``p' = p M``); written here as column-vector maths (the transposes)::

    LookAtLH: z = normalize(focus - eye), x = normalize(up x z), y = z x x
              rows x, y, z, translation -dot(row, eye)
    PerspectiveFovLH: h = 1 / tan(fovY / 2), w = h / aspect, r = far / (far - near)
              [w, 0, 0, 0], [0, h, 0, 0], [0, 0, r, -r near], [0, 0, 1, 0]
    viewport: x = (ndc_x + 1) W / 2,  y = (1 - ndc_y) H / 2,  depth ndc_z in [0, 1]

Direct3D 10+ puts pixel centres at +0.5, so ``x_px = x - 0.5``, ``y_px = y - 0.5``.
wirecheck's world is right-handed. ``project_naive`` feeds it to the LH
functions unchanged (x = up x z points left in a right-handed world: the
picture comes out mirrored left-right). ``project`` converts the world to
left-handed first by negating z of every point and of the camera's vectors,
which is what D3D samples do with right-handed assets.
"""

import numpy as np

F = np.float32


def _normalize(v):
    return v / np.sqrt(np.sum(v * v), dtype=F)


def look_at_lh(eye, focus, up):
    z = _normalize(focus - eye)
    x = _normalize(np.cross(up, z))
    y = np.cross(z, x)
    m = np.eye(4, dtype=F)
    m[0, :3], m[1, :3], m[2, :3] = x, y, z
    m[0, 3], m[1, 3], m[2, 3] = -x @ eye, -y @ eye, -z @ eye
    return m


def perspective_fov_lh(fov_y_rad, aspect, near, far):
    h = F(1) / np.tan(F(fov_y_rad) / F(2))
    r = F(far) / (F(far) - F(near))
    m = np.zeros((4, 4), dtype=F)
    m[0, 0], m[1, 1] = h / F(aspect), h
    m[2, 2], m[2, 3] = r, -r * F(near)
    m[3, 2] = F(1)
    return m


def orthographic_lh(view_w, view_h, near, far):
    r = F(1) / (F(far) - F(near))
    m = np.eye(4, dtype=F)
    m[0, 0], m[1, 1] = F(2) / F(view_w), F(2) / F(view_h)
    m[2, 2], m[2, 3] = r, -r * F(near)
    return m


def _project(points, camera, flip_z):
    s = np.array([1, 1, -1 if flip_z else 1], dtype=F)
    eye = np.asarray(camera.position, dtype=F) * s
    focus = eye + np.asarray(camera.forward, dtype=F) * s
    up = np.asarray(camera.up, dtype=F) * s
    w, h = camera.width, camera.height
    view = look_at_lh(eye, focus, up)
    if camera.projection == "perspective":
        proj = perspective_fov_lh(np.radians(camera.fov_y_deg), w / h, camera.near, camera.far)
    else:
        proj = orthographic_lh(camera.ortho_height * w / h, camera.ortho_height, camera.near, camera.far)
    p = np.asarray(points, dtype=F) * s
    p = np.concatenate([p, np.ones((len(p), 1), dtype=F)], axis=1)
    clip = p @ (proj @ view).T
    with np.errstate(divide="ignore", invalid="ignore"):
        ndc = clip[:, :3] / clip[:, 3:4]
    px = np.stack([(ndc[:, 0] + F(1)) * F(w / 2) - F(0.5), (F(1) - ndc[:, 1]) * F(h / 2) - F(0.5)], axis=1)
    inside = (clip[:, 3] > 0) & (clip[:, 2] >= 0) & (clip[:, 2] <= clip[:, 3])
    px[~inside] = np.nan
    return px


def project_naive(points, camera):
    """The right-handed world fed to left-handed functions as it is."""
    return _project(points, camera, flip_z=False)


def project(points, camera):
    """The world converted to left-handed (z negated) before the LH functions."""
    return _project(points, camera, flip_z=True)
