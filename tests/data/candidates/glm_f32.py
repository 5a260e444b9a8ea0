"""A glm-style projector in float32, written against the candidate contract only (no wirecheck imports).

What a C++ user of glm writes, in numpy: ``lookAtRH``, ``perspectiveRH_NO``
(or ``orthoRH_NO``), ``clip = P @ V @ [p, 1]``, the divide by ``w`` and the
viewport, every value a float32 (glm's ``vec3``/``mat4``). The near/far test
is on the float32 view depth ``-z_view``, as a hand-written projector does it.

- :func:`project`: correct (the project's pixel convention, core/conventions.py).
- :func:`project_webgl`: ``gl_FragCoord``-style pixels (corner origin, y up):
  a vertical mirror and a half-pixel offset on both axes.
- :func:`project_f64_view`: the same arithmetic in float32, returned as float64
  (what a float32 program gives through a float64 interface).
"""

import numpy as np

F32 = np.float32


def _normalize(v):
    return v / np.sqrt(np.sum(v * v, dtype=F32), dtype=F32)


def look_at_rh(eye, center, up):
    """glm::lookAtRH: rows s, u, -f; translation -(s.eye, u.eye, -f.eye)."""
    f = _normalize(center - eye)
    s = _normalize(np.cross(f, up).astype(F32))
    u = np.cross(s, f).astype(F32)
    m = np.eye(4, dtype=F32)
    m[0, :3], m[1, :3], m[2, :3] = s, u, -f
    m[0, 3], m[1, 3], m[2, 3] = -np.dot(s, eye), -np.dot(u, eye), np.dot(f, eye)
    return m


def perspective_rh_no(fovy_rad, aspect, z_near, z_far):
    """glm::perspectiveRH_NO (NDC z in [-1, 1])."""
    t = F32(np.tan(F32(fovy_rad) / F32(2)))
    m = np.zeros((4, 4), dtype=F32)
    m[0, 0] = F32(1) / (F32(aspect) * t)
    m[1, 1] = F32(1) / t
    m[2, 2] = -(F32(z_far) + F32(z_near)) / (F32(z_far) - F32(z_near))
    m[3, 2] = F32(-1)
    m[2, 3] = -(F32(2) * F32(z_far) * F32(z_near)) / (F32(z_far) - F32(z_near))
    return m


def ortho_rh_no(left, right, bottom, top, z_near, z_far):
    """glm::orthoRH_NO."""
    m = np.eye(4, dtype=F32)
    m[0, 0] = F32(2) / (F32(right) - F32(left))
    m[1, 1] = F32(2) / (F32(top) - F32(bottom))
    m[2, 2] = -F32(2) / (F32(z_far) - F32(z_near))
    m[0, 3] = -(F32(right) + F32(left)) / (F32(right) - F32(left))
    m[1, 3] = -(F32(top) + F32(bottom)) / (F32(top) - F32(bottom))
    m[2, 3] = -(F32(z_far) + F32(z_near)) / (F32(z_far) - F32(z_near))
    return m


def _ndc(points, camera):
    """``(ndc (N, 3), visible (N,))``, all float32."""
    eye = np.asarray(camera.position, dtype=F32)
    view = look_at_rh(eye, eye + np.asarray(camera.forward, dtype=F32), np.asarray(camera.up, dtype=F32))
    w, h = camera.width, camera.height
    aspect = F32(w) / F32(h)
    if camera.projection == "perspective":
        proj = perspective_rh_no(np.radians(F32(camera.fov_y_deg)), aspect, camera.near, camera.far)
    else:
        half_h = F32(camera.ortho_height) / F32(2)
        proj = ortho_rh_no(-half_h * aspect, half_h * aspect, -half_h, half_h, camera.near, camera.far)
    p = np.asarray(points, dtype=F32)
    p_h = np.concatenate([p, np.ones((len(p), 1), F32)], axis=1)
    p_view = p_h @ view.T
    depth = -p_view[:, 2]
    visible = (depth >= F32(camera.near)) & (depth <= F32(camera.far))
    clip = p_view @ proj.T
    w_clip = clip[:, 3:4] if camera.projection == "perspective" else np.ones((len(p), 1), F32)
    return clip[:, :3] / np.where(w_clip == 0, F32(1), w_clip), visible


def project(points, camera):
    """Correct, in float32: ``x = (ndc_x + 1) W/2 - 0.5``, ``y = (1 - ndc_y) H/2 - 0.5``."""
    ndc, visible = _ndc(points, camera)
    w, h = F32(camera.width), F32(camera.height)
    out = np.stack([(ndc[:, 0] + F32(1)) * w / F32(2) - F32(0.5), (F32(1) - ndc[:, 1]) * h / F32(2) - F32(0.5)], axis=1)
    out[~visible] = np.nan
    return out


def project_webgl(points, camera):
    """``gl_FragCoord``-style: ``x = (ndc_x + 1) W/2``, ``y = (ndc_y + 1) H/2`` (corner origin, y up)."""
    ndc, visible = _ndc(points, camera)
    w, h = F32(camera.width), F32(camera.height)
    out = np.stack([(ndc[:, 0] + F32(1)) * w / F32(2), (ndc[:, 1] + F32(1)) * h / F32(2)], axis=1)
    out[~visible] = np.nan
    return out


def project_f64_view(points, camera):
    """:func:`project`, returned as float64: the values of a float32 computation behind a float64 interface."""
    return project(points, camera).astype(np.float64)
