"""A float64 GL projector whose projection matrix went through float32, as PyGLM code builds it.

PyGLM's ``glm.perspective`` returns a float32 ``mat4``; ``glm.dmat4(...)`` of it computes in float64
but keeps the float32 rounding of every entry. The clip test is GL's (``-w <= z_clip <= w``), so its
near plane is the rounded matrix's, ``near (1 + ~1e-8)``, and its far plane likewise. Written against
the contract only (no wirecheck imports).
"""

import numpy as np


def _view(camera):
    f = np.asarray(camera.forward, float)
    f = f / np.linalg.norm(f)
    s = np.cross(f, camera.up)
    s = s / np.linalg.norm(s)
    u = np.cross(s, f)
    eye = np.asarray(camera.position, float)
    m = np.eye(4)
    m[0, :3], m[1, :3], m[2, :3] = s, u, -f
    m[:3, 3] = -m[:3, :3] @ eye
    return m


def _perspective(camera, dtype):
    """glm's perspectiveRH_NO computed in ``dtype`` from arguments converted to ``dtype`` (as PyGLM does)."""
    one, two = dtype(1), dtype(2)
    t = np.tan(dtype(np.radians(camera.fov_y_deg)) / two)
    n, f = dtype(camera.near), dtype(camera.far)
    m = np.zeros((4, 4), dtype=dtype)
    m[0, 0] = one / (dtype(camera.width / camera.height) * t)
    m[1, 1] = one / t
    m[2, 2] = -(f + n) / (f - n)
    m[2, 3] = -(two * f * n) / (f - n)
    m[3, 2] = -one
    return m.astype(np.float64)


def _project(points, camera, dtype):
    p = np.column_stack([np.asarray(points, float), np.ones(len(points))])
    clip = p @ (_perspective(camera, dtype) @ _view(camera)).T
    w = clip[:, 3]
    keep = (clip[:, 2] >= -w) & (clip[:, 2] <= w) & (w > 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        ndc = clip[:, :2] / w[:, None]
    x = (ndc[:, 0] + 1.0) * camera.width / 2.0 - 0.5
    y = (1.0 - ndc[:, 1]) * camera.height / 2.0 - 0.5
    out = np.column_stack([x, y])
    out[~keep] = np.nan
    return out


def project(points, camera):
    """float64 arithmetic, float32-rounded projection matrix (the PyGLM way)."""
    return _project(points, camera, np.float32)


def project_exact(points, camera):
    """The same, with a float64 matrix: the control."""
    return _project(points, camera, np.float64)
