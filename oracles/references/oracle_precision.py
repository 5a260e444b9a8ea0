"""The pyrender oracle's own error bound, and a case that asks for more than the oracle can give.

pyrender draws in float32 (``P V M p`` in its vertex shader). The oracle
hands it coordinates it can hold (oracles.references.convert.gl_eye_pose): each vertex
as its offset ``q`` from the mesh's centre, rounded to float32 once per mesh,
and the mesh node's pose taking ``q`` straight to eye space, computed in
float64 with the camera at the origin. What the GPU then rounds is of the
size of the mesh (``rho = |M_lin|_2 max|q|``) and of the centre's eye
coordinates ``t``, never of the scene's distance from the world origin.

The bound (per frame, :func:`frame_bound_px`), with ``u = 2^-24`` (float32's
unit roundoff):

- every eye coordinate ``e_j`` of a drawn point (a vertex, or a point of a
  segment between two, clipped ones included) is a sum of terms of total
  magnitude at most ``mag_j = |t_j| + rho``;
- the clip coordinates ``c = P e`` then carry at most ``k u (|P| [mag, 1])``
  of absolute error, counting the roundings the shader's ``P * V * M *
  inst_m * vec4(q, 1)`` makes (left to right; ``V`` and ``inst_m`` are the
  identity, so ``P V`` and ``* inst_m`` are exact): for ``c_x`` and ``c_y``
  (:data:`CLIP_XY_ROUNDINGS`, 10) the float32 rounding of ``q`` (1), of the
  pose (1) and of ``P`` (1), the ``(P V) M`` product (a row of ``P`` has at
  most two non-zero entries: 2), its product with ``(q, 1)`` (a 4-term sum:
  4) and GL's clip-space interpolation of a clipped end (1); for ``c_w =
  -e_z`` (:data:`CLIP_W_ROUNDINGS`, 7) the same less ``P`` and the ``(P V)
  M`` product, whose row is ``-1`` times the pose's (exact);
- the divide and the viewport: ``x_win = (c_x / c_w + 1) W / 2`` moves by
  ``(W / 2) (dc_x + |x_ndc| dc_w) / c_w``, with ``|x_ndc| <= 1`` for what
  lands in the image and ``c_w`` at least the depth ``w_lo = max(near,
  d_centre - rho)`` of the nearest drawn point (orthographic: ``c_w = 1``
  exactly), plus :data:`VIEWPORT_ROUNDINGS` ``u W`` for the divide (``u
  W / 2``) and the scale and offset (``u W``): 2.

That is :func:`frame_bound_px`, from the mesh's radius alone: every drawn
point is taken as large as the largest and as near as the bounding sphere
(or the near plane) allows. The oracle itself takes :func:`drawn_bound_px`,
the same roundings counted per drawn segment, from what that segment's ends
are: each end's own magnitudes ``mag_j`` (``sum_k |M_jk| |q_k| + |t_j|``, at
most ``|t_j| + rho`` by Cauchy-Schwarz) through ``P`` to its window error
times its depth (the larger of the two ends'), over the depth of the
segment's nearest drawn point, ``max(near, min(w_a, w_b))`` (a point of a segment is a convex combination of its ends,
in eye space and, after clipping, in clip space: its depth is at least the
smaller end's; a clipped end lies on the near plane, at depth ``near``
exactly, or on a side or far plane, between its ends' depths). Where the
rasterized line is drawn between its window-space ends, its every pixel is
decided by those ends: the largest end error is the segment's. A segment
wholly behind the near plane (both ends nearer than ``near`` by more than
the rounding of their depths) is not drawn and not counted. So a mesh whose
bounding sphere reaches the near plane but whose edges do not (a cone seen
close by a wide camera) is bounded by its edges' own depths, not the near
plane's; only an edge that GL really clips there divides by ``near``.

The case's bound is the largest over its frames (the record's
``oracle_bound_px``). The line gate's tie zone assumes the oracle's window
coordinates within ``2^-9`` px of exact (the float32 share of
oracles.tolerances.TIE_END_PX); a case whose bound exceeds
``Tolerances.oracle_limit_px`` (oracles.tolerances) asks for more than the oracle can give, and its
pixels are not judged: :func:`oracles.judge.decide.decide` makes it an
``oracle_precision`` case that fails the run without blaming the candidate.
On the bundled scenes the bound is ~1e-4 to 1e-3 px, wherever the scene is
put; before the re-centring a mesh 1e5 from the origin moved the oracle's
lines by up to 78 px.
"""

from __future__ import annotations

import numpy as np

from .convert import camera_to_gl

__all__ = [
    "U32",
    "CLIP_XY_ROUNDINGS",
    "CLIP_W_ROUNDINGS",
    "VIEWPORT_ROUNDINGS",
    "mesh_radius",
    "frame_bound_px",
    "drawn_bound_px",
]

#: float32's unit roundoff (half its epsilon): one rounding moves a value v by at most U32 |v|.
U32 = 2.0**-24

#: Roundings of the magnitude of clip x and y (module docstring: 1 + 1 + 1 + 2 + 4 + 1).
CLIP_XY_ROUNDINGS = 10

#: Roundings of the magnitude of clip w (module docstring: 1 + 1 + 4 + 1).
CLIP_W_ROUNDINGS = 7

#: Roundings of the window size W (module docstring: the divide 1/2, the scale and offset 1; 2 kept).
VIEWPORT_ROUNDINGS = 2


def mesh_radius(centred) -> float:
    """The largest Euclidean norm of the finite rows of ``centred`` (vertices minus their centre), float64."""
    v = np.asarray(centred, dtype=np.float64).reshape(-1, 3)
    v = v[np.isfinite(v).all(axis=1)]
    return float(np.sqrt((v * v).sum(axis=1)).max()) if len(v) else 0.0


def frame_bound_px(camera, eye_pose, radius: float) -> float:
    """The oracle's own error in pixels for one frame (module docstring), from what pyrender receives.

    Parameters
    ----------
    camera : Camera
    eye_pose : (4, 4) float64, centred model coordinates to GL eye (oracles.references.convert.gl_eye_pose).
    radius : float, the largest ``|q|`` of the uploaded vertices (:func:`mesh_radius`).
    """
    a = np.asarray(eye_pose, dtype=np.float64)
    _view, proj = camera_to_gl(camera)
    with np.errstate(over="ignore", invalid="ignore"):  # an overflow is no bound: inf below
        rho = float(np.linalg.norm(a[:3, :3], 2)) * float(radius)
        mag = np.abs(a[:3, 3]) + rho  # |e_j| and its terms, every drawn point
        m_clip = np.abs(proj[:, :3]) @ mag + np.abs(proj[:, 3])  # magnitude of each clip coordinate's terms
        w_term = CLIP_W_ROUNDINGS * m_clip[3] if camera.projection == "perspective" else 0.0  # ortho: c_w = 1
        w_lo = max(float(camera.near), -float(a[2, 3]) - rho) if camera.projection == "perspective" else 1.0
        bx = U32 * (camera.width / 2.0) * (CLIP_XY_ROUNDINGS * m_clip[0] + w_term) / w_lo
        by = U32 * (camera.height / 2.0) * (CLIP_XY_ROUNDINGS * m_clip[1] + w_term) / w_lo
        bx += VIEWPORT_ROUNDINGS * U32 * camera.width
        by += VIEWPORT_ROUNDINGS * U32 * camera.height
    both = np.array([bx, by], dtype=np.float64)
    return float(both.max()) if np.isfinite(both).all() else float("inf")  # no finite bound: none at all


def drawn_bound_px(camera, eye_pose, q_model, segments) -> float:
    """The oracle's own error in pixels for one frame, per drawn segment (module docstring), its largest.

    Never above :func:`frame_bound_px` of the same mesh: each segment's magnitudes and depth are
    its own ends', where that takes the whole mesh's worst.

    Parameters
    ----------
    camera : Camera
    eye_pose : (4, 4) float64, centred model coordinates to GL eye (oracles.references.convert.gl_eye_pose).
    q_model : (N, 3) the uploaded vertices (the float32 offsets from the mesh's centre), as float64.
    segments : (E, 2) int, the vertex indices of each drawn segment (a triangle's three edges for faces).
    """
    a = np.asarray(eye_pose, dtype=np.float64)
    q = np.asarray(q_model, dtype=np.float64).reshape(-1, 3)
    seg = np.asarray(segments, dtype=np.int64).reshape(-1, 2)
    _view, proj = camera_to_gl(camera)
    perspective = camera.projection == "perspective"
    viewport = VIEWPORT_ROUNDINGS * U32 * max(camera.width, camera.height)  # the divide, scale and offset
    if not len(seg):
        return float(viewport)
    with np.errstate(over="ignore", invalid="ignore"):
        lin, t = a[:3, :3], a[:3, 3]
        term = np.abs(q) @ np.abs(lin).T + np.abs(t)  # (N, 3): magnitude of each e_j's terms
        m_clip = term @ np.abs(proj[:, :3]).T + np.abs(proj[:, 3])  # (N, 4): each clip coordinate's terms
        w_term = CLIP_W_ROUNDINGS * m_clip[:, 3] if perspective else 0.0  # orthographic: c_w = 1 exactly
        # each vertex's error in the window times its depth (x and y, the larger): a segment's drawn
        # points (its clipped ends too) are convex combinations of its ends, within the larger end's
        num = np.maximum(
            (camera.width / 2.0) * (CLIP_XY_ROUNDINGS * m_clip[:, 0] + w_term),
            (camera.height / 2.0) * (CLIP_XY_ROUNDINGS * m_clip[:, 1] + w_term),
        )
        num_seg = np.maximum(num[seg[:, 0]], num[seg[:, 1]])
        if perspective:
            depth = -(q @ lin[2] + t[2])  # (N,): w = -e_z, float64
            w_a, w_b = depth[seg[:, 0]], depth[seg[:, 1]]
            # behind near by more than the rounding of its depth (2 x its clip w's): GL draws nothing of it
            reach = 2 * CLIP_W_ROUNDINGS * U32 * m_clip[:, 3]
            drawn = np.maximum(w_a + reach[seg[:, 0]], w_b + reach[seg[:, 1]]) >= camera.near
            w_lo = np.maximum(float(camera.near), np.minimum(w_a, w_b))
            num_seg, w_lo = num_seg[drawn], w_lo[drawn]
        else:
            w_lo = 1.0
        both = U32 * num_seg / w_lo
    if not np.isfinite(num).all() or not np.isfinite(both).all():
        return float("inf")  # no finite bound: none at all
    return float(both.max(initial=0.0)) + viewport
