"""The reference depth of a scene frame: pyrender's depth along ``forward`` per pixel, and its bound.

pyrender draws the frame's faces filled into single-sample buffers
(:meth:`oracles.references.pyrender_oracle.PyrenderOracle.render_faces`); its 24-bit depth
buffer is read and made linear in float64 there, perspective and orthographic alike. The
per-pixel bound is :func:`oracles.judge.metrics.depth_bound` (derived in
oracles.tolerances: four 24-bit steps, the depth slope over llvmpipe's 1/256 px
snapping, float32 geometry). Pixels next to an occlusion boundary (a triangle in front of
another it shares no vertex with: :func:`oracles.judge.metrics.occlusion_boundary`) show
either surface by each renderer's rounding; their depth is not compared
(:attr:`ReferenceDepth.undecided`), as in the shaded comparison; nor is the depth of the
pixels within one pixel of the near or far plane's clip line (a surface at depth within one
pixel's depth change of the plane): whether their centre is clipped is the same kind of
rounding decision (measured: prism, near_plane case, 3 pixels where core shows the clipped
face at the near plane and pyrender the face behind it). The frame's geometry is the oracle side's own
(oracles.references.faces, scipy matrices), not core's.

A candidate's encoding adds its own step (oracles.candidates.depth_map.DepthMap.encoding_bound);
oracles.diagnosis.depth_faults judges and names against both.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from wirecheck.core.scene.model import Scene
from wirecheck.core.transforms import Motion

from ..cases import Case, case_motion
from ..diagnosis.depth_pixels import UNDECIDED_FACE
from ..references import faces as oface
from .metrics import depth_bound, depth_slope, occlusion_boundary

__all__ = ["ReferenceDepth", "from_render", "reference_depth"]


@dataclass(frozen=True)
class ReferenceDepth:
    """One frame's reference depth.

    Attributes
    ----------
    depth : (H, W) ndarray of float64
        Depth along ``forward`` (world units), NaN where no face covers the pixel centre.
    covered : (H, W) ndarray of bool
    undecided : (H, W) ndarray of bool
        Covered pixels beside an occlusion boundary: which surface they show is a rounding decision.
    bound : (H, W) ndarray of float64
        How far a correct depth may be from ``depth`` at each covered pixel.
    faces : (H, W) ndarray of int64
        The triangle each pixel shows (-1: none): planar faces, for the mistakes that move
        pixels (oracles.diagnosis.depth_pixels).
    """

    depth: np.ndarray
    covered: np.ndarray
    undecided: np.ndarray
    bound: np.ndarray
    faces: np.ndarray

    def compared_depth(self) -> np.ndarray:
        """``(H, W)`` float64: :attr:`depth` with NaN at the undecided pixels too (what a depth map is judged on)."""
        out = self.depth.copy()  # np.where(undecided, nan, depth), in half the time
        np.copyto(out, np.nan, where=self.undecided)
        return out

    def compared_faces(self) -> np.ndarray:
        """``(H, W)``: :attr:`faces` with :data:`UNDECIDED_FACE` (-2) at the undecided pixels: a surface is there,
        which one is a rounding decision (oracles.diagnosis.depth_pixels neither samples it nor counts a pixel
        landing there as landing on nothing)."""
        return np.where(self.undecided, UNDECIDED_FACE, self.faces)


def reference_depth(oracle, scene: Scene, case: Case, motion: Motion, k: int, frames: int) -> ReferenceDepth:
    """Frame ``k`` (1-based, of ``frames``) of ``scene`` under ``motion``, through ``case``'s camera.

    Parameters
    ----------
    oracle : oracles.references.pyrender_oracle.PyrenderOracle
        Of the camera's image size.
    scene : Scene
        With faces (a wireframe has no depth: ValueError).
    case : Case
        The camera and the pivot the run turns about (oracles.cases.case_motion).
    motion : Motion
        The run's motion.
    k, frames : int

    Returns
    -------
    ReferenceDepth
    """
    if not scene.faces:
        raise ValueError(f"scene {scene.name!r} has no faces: a wireframe has no depth map")
    cam = case.camera
    p_world, matrices, pr_vertices, pr_pose = oface.frame_geometry(scene, case_motion(motion, case), (k - 1) / frames)
    tris, _owner = oface.fan(scene.faces)
    triangles = oface.gl_triangles(tris, oface.mirrored_vertices(scene, matrices))
    covered, depth, ids = oracle.render_faces(pr_vertices, triangles, cam, model_matrix=pr_pose, with_ids=True)
    return from_render(covered, depth, ids, tris, cam)


def from_render(covered: np.ndarray, depth: np.ndarray, ids: np.ndarray, tris: np.ndarray, camera) -> ReferenceDepth:
    """The :class:`ReferenceDepth` of pyrender's drawing of a frame's faces (``render_faces(..., with_ids=True)``
    of the fan triangles ``tris``, (T, 3) vertex indices, through ``camera``): its bound and undecided pixels.
    ``ids`` is -1 exactly where nothing is covered (render_faces refuses any other drawing): the reference's
    :attr:`~ReferenceDepth.faces` as they are."""
    box = _box(covered)
    slope = depth_slope(depth, covered, box) if box is not None else np.zeros(covered.shape)
    bound = _covered_bound(depth, covered, camera, slope, box)
    undecided = _beside_clip_planes(depth, covered, camera, slope, box)
    if box is not None:  # pyrender's ids are shown exactly where it covers: their box is covered's
        undecided |= occlusion_boundary(ids, tris, box)
    undecided &= covered
    ref_depth = np.full(covered.shape, np.nan)  # np.where(covered, depth, nan), in half the time
    np.copyto(ref_depth, depth, where=covered)
    return ReferenceDepth(
        depth=ref_depth,
        covered=covered,
        undecided=undecided,
        bound=bound,
        faces=ids,
    )


def _box(covered: np.ndarray):
    """The covered pixels' bounding box (two slices), None when none is covered."""
    rows, cols = np.flatnonzero(covered.any(axis=1)), np.flatnonzero(covered.any(axis=0))
    return np.s_[rows[0] : rows[-1] + 1, cols[0] : cols[-1] + 1] if len(rows) else None


def _covered_bound(depth: np.ndarray, covered: np.ndarray, camera, slope: np.ndarray, box) -> np.ndarray:
    """:func:`oracles.judge.metrics.depth_bound` taken over the covered pixels' bounding box ``box``; outside
    it, where pyrender's depth is 0 (``render_faces``: nothing drawn) and ``slope`` 0, the bound of depth 0
    (0 under perspective, four 24-bit steps under orthographic). Only covered pixels' bounds are ever read."""
    zero = np.zeros((1, 1))
    bound = np.full(covered.shape, depth_bound(zero, zero.astype(bool), camera, zero)[0, 0])
    if box is not None:
        bound[box] = depth_bound(depth[box], covered[box], camera, slope[box])
    return bound


def _beside_clip_planes(depth: np.ndarray, covered: np.ndarray, camera, slope: np.ndarray, box) -> np.ndarray:
    """Pixels within one pixel (8 neighbours) of one whose depth is within its depth slope (``slope``,
    oracles.judge.metrics.depth_slope) of near or far; ``box``: the covered pixels' bounding box (:func:`_box`)."""
    at_plane = np.zeros(covered.shape, bool)
    if box is None:
        return at_plane
    d, s = depth[box], slope[box]
    with np.errstate(invalid="ignore"):
        at_plane[box] = covered[box] & ((np.abs(d - camera.near) <= s) | (np.abs(d - camera.far) <= s))
    if not at_plane.any():  # most frames: no surface at a clip plane
        return at_plane
    out = at_plane.copy()
    h, w = at_plane.shape
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            src = at_plane[max(dy, 0) : h + min(dy, 0), max(dx, 0) : w + min(dx, 0)]
            out[max(-dy, 0) : h + min(-dy, 0), max(-dx, 0) : w + min(-dx, 0)] |= src
    return out
