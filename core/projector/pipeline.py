"""One frame, top to bottom: model -> camera -> clip -> pixels -> raster.

Each line of :func:`render_frame` names the space it produces (see
core.conventions for the spaces). Model to camera is one camera-relative
model-view transform (core.projector.projection explains why: precision in float32 and
far from the origin); world coordinates are never formed per point.

Only what a frame needs is computed. A plain wireframe never touches faces
and has no depth buffer; the clipping stage runs only for the edges with an
end outside [near, far] or off the image. Faces are triangulated and culled only
for ``cull``, ``hidden_lines`` or ``style="shaded"``, and rasterized into a
depth buffer (core.projector.zbuffer) only for the last two.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..camera import Camera
from . import clipping, culling, raster, shading, zbuffer
from .clipping import CLIP_MODES
from .culling import CULL_MODES
from .hidden_lines import SLOPE_FACTOR, line_samples, visible_line_samples
from .projection import LocalPoints, cam_to_px, depth_mask, localize, model_to_cam, resolve_dtype
from .raster import RASTER_MODES
from .shading import STYLES

#: The stages :func:`render_frame` times when given a ``timing`` dict, in pipeline order:
#: transform (model -> camera -> pixels, depth test), faces (triangulate, cull,
#: z-buffer), shading, clip (edges against the frustum and the image), raster
#: (line pixels, with hidden lines their depth test, and painting).
STAGES = ("transform", "faces", "shading", "clip", "raster")


@dataclass(frozen=True)
class Frame:
    """One rendered frame (what :func:`render_frame` returns).

    Attributes
    ----------
    image : (H, W) uint8
        Wireframe: 255 on line pixels (raster "aa": coverage 0..255); with
        ``hidden_lines``, the wireframe minus the hidden line pixels. Style
        "shaded": the shaded image (same array as ``shaded``).
    p_px : (N, 2) float64
        Vertex pixels, NaN where clipped (computed in the run's dtype).
    depth : (N,) float64
        ``z_cam`` of every vertex.
    visible : (N,) bool
        ``near <= depth <= far``.
    clipped_edges : int
        Edges dropped or shortened by near/far (counted over all edges, before
        back-face culling).
    depth_image : (H, W) float64 or None
        The depth buffer of the faces: linear ``z_cam`` of the nearest face at
        each pixel centre, +inf where none. Only with ``hidden_lines`` or style
        "shaded" (None otherwise).
    face_ids : (H, W) int32 or None
        Index (into ``faces``) of the polygon seen at each pixel, -1 where
        none. Computed with ``depth_image``.
    shaded : (H, W) uint8 or None
        Flat-shaded grey levels (core.projector.shading), 0 where no face. Style
        "shaded" only.
    faces_total : int
        Number of polygons given (0 without faces).
    faces_culled : int
        Polygons culled as back faces (``cull="backface"``), 0 otherwise.
    edges_culled : int
        Edges not drawn because every face they belong to was culled.
    hidden_pixels : int
        With ``hidden_lines``: pixels that some edge reaches but only with
        hidden samples, i.e. line pixels suppressed by the faces. 0 otherwise.
    tri_ids : (H, W) int or None
        With ``depth_image``: the (clipped) triangle seen at each pixel, -1
        where none, and ``tri_grad`` its depth gradients: what
        :func:`draw_segments` needs to hide other lines (the axes) behind
        this frame's faces exactly as the frame's own edges are hidden.
    """

    image: np.ndarray
    p_px: np.ndarray
    depth: np.ndarray
    visible: np.ndarray
    clipped_edges: int
    depth_image: np.ndarray | None = None
    face_ids: np.ndarray | None = None
    shaded: np.ndarray | None = None
    faces_total: int = 0
    faces_culled: int = 0
    edges_culled: int = 0
    hidden_pixels: int = 0
    tri_ids: np.ndarray | None = field(default=None, repr=False)
    tri_grad: np.ndarray | None = field(default=None, repr=False)

    @property
    def mask(self) -> np.ndarray:
        """``(H, W) bool``: the drawn pixels (coverage >= 1/2 for raster "aa")."""
        return self.image >= 128

    @property
    def visible_vertices(self) -> int:
        return int(self.visible.sum())

    @property
    def clipped_vertices(self) -> int:
        return int(len(self.visible) - self.visible.sum())

    @property
    def depth_range(self) -> tuple[float, float] | None:
        """(min, max) depth of the visible vertices, None when there are none."""
        if not self.visible.any():
            return None
        d = self.depth[self.visible]
        return float(d.min()), float(d.max())

    @property
    def faces_visible(self) -> int | None:
        """Polygons owning at least one pixel of the depth buffer (None without one)."""
        if self.face_ids is None:
            return None
        ids = self.face_ids[self.face_ids >= 0]
        return int(len(np.unique(ids)))


def render_frame(
    p_model,
    edges: np.ndarray,
    camera: Camera,
    model_matrix: np.ndarray,
    clip_mode: str = "clip",
    *,
    dtype=None,
    raster: str = "exact",
    faces=None,
    cull: str | None = None,
    hidden_lines: bool = False,
    style: str = "wireframe",
    light_dir=None,
    ambient: float = shading.DEFAULT_AMBIENT,
    timing: dict | None = None,
) -> Frame:
    """Project and draw one frame of a mesh's edges (and, optionally, its faces).

    Parameters
    ----------
    p_model : (N, 3) array_like of float, or LocalPoints
        Model-space vertices; or, to skip re-centring and casting on every
        frame, the :class:`~wirecheck.core.projector.projection.LocalPoints` of
        :func:`~wirecheck.core.projector.projection.localize`.
    edges : (E, 2) array_like of int
        Vertex index pairs.
    camera : Camera
    model_matrix : (4, 4) array_like of float
        Model to world, column vectors (``p_world = M @ p_model``).
    clip_mode : {"clip", "endpoint"}
        ``"clip"``: edges are cut at the near and far planes before the
        divide; ``"endpoint"``: an edge with a clipped end is dropped.
    dtype : {"float64", "float32"}, optional
        Precision of every per-point operation of the projection and the
        wireframe (default float64; with ``LocalPoints``, theirs). The face
        stage computes in float64: its decisions are compared with a 24-bit
        depth buffer, where float32 would add noise and no speed.
    raster : {"exact", "fast", "aa"}
        The line rule (:mod:`wirecheck.core.projector.raster`).
    faces : sequence of tuple of int, or (F, k) array_like of int, optional
        Polygons, counter-clockwise seen from outside; triangulated
        internally. Without faces the frame is the plain wireframe.
    cull : {None, "backface"}
        Drop back faces (the rule: :mod:`wirecheck.core.projector.culling`); an edge is
        drawn when one of its faces is kept, or when it belongs to no face.
    hidden_lines : bool
        Do not draw line pixels behind the faces: our own z-buffer, and a
        depth test biased as ``glPolygonOffset(1, 1)``. The bias includes one
        step of a 24-bit buffer over [near, far], so keep [near, far] tight.
    style : {"wireframe", "shaded"}
        ``"shaded"``: the image is flat Lambert-shaded faces, no lines.
    light_dir : (3,) array_like of float, optional
        World direction the light travels (default: from the camera's upper left).
    ambient : float
        Ambient term of the shading, in [0, 1].
    timing : dict, optional
        The seconds of each of :data:`STAGES` this frame ran are added to it
        (consecutive laps). None (the default) reads no clock.

    Returns
    -------
    Frame
        ``image`` (H, W) uint8, ``p_px`` (N, 2) float64 (NaN where clipped),
        ``depth`` (N,), ``visible`` (N,) bool, and the face-stage fields.

    Raises
    ------
    ValueError
        An unknown ``clip_mode``, ``raster``, ``style`` or ``cull``.
    """
    t = _clock() if timing is not None else 0.0
    if clip_mode not in CLIP_MODES:
        raise ValueError(f"clip_mode {clip_mode!r}: expected one of {CLIP_MODES}")
    if raster not in RASTER_MODES:
        raise ValueError(f"raster {raster!r}: expected one of {RASTER_MODES}")
    if style not in STYLES:
        raise ValueError(f"style {style!r}: expected one of {STYLES}")
    if cull not in CULL_MODES:
        raise ValueError(f"cull {cull!r}: expected one of {CULL_MODES}")
    if isinstance(p_model, LocalPoints):
        points = p_model
        if dtype is not None and resolve_dtype(dtype) != points.dtype:
            raise ValueError(f"dtype {dtype!r} differs from the LocalPoints' {points.dtype}")
    else:
        points = localize(p_model, "float64" if dtype is None else dtype)
    n = len(points)
    edges = np.asarray(edges).reshape(-1, 2)
    p_cam = model_to_cam(points, model_matrix, camera)  # camera (model-view, camera-relative)
    visible = depth_mask(p_cam, camera)  # near <= z <= far
    all_visible = bool(visible.all())
    if all_visible:  # the usual case: no gather/scatter
        p_px = cam_to_px(p_cam, camera)  # pixels
    else:
        p_px = np.full((n, 2), np.nan, dtype=p_cam.dtype)
        if visible.any():
            p_px[visible] = cam_to_px(p_cam[visible], camera)  # pixels
    ends_visible = visible[edges[:, 0]] & visible[edges[:, 1]] if len(edges) else np.zeros(0, bool)
    # Depth is affine along an edge, so near/far leave an edge whole exactly when
    # both ends are in [near, far]: every other edge is cut or dropped by them.
    clipped_edges = int(len(edges) - ends_visible.sum())
    t = _lap(timing, "transform", t)

    shaded_style = style == "shaded"
    use_faces = faces is not None and (cull is not None or hidden_lines or shaded_style)
    extra = {}
    if faces is not None:
        extra["faces_total"] = len(faces)
    depth_image = face_ids = tri_face_buf = grad = None
    if use_faces:
        fs = _faces_stage(p_cam, faces, camera, model_matrix, cull, hidden_lines or shaded_style)
        extra.update(faces_culled=fs["faces_culled"])
        if cull is not None and len(edges):
            keep_edge = _edges_of_kept_faces(edges, faces, fs["face_kept"], n)
            extra["edges_culled"] = int(len(edges) - keep_edge.sum())
            edges = edges[keep_edge]
            ends_visible = ends_visible[keep_edge]
        depth_image, face_ids = fs.get("depth"), fs.get("face_ids")
        tri_face_buf, grad = fs.get("tri_buf"), fs.get("grad")
        if tri_face_buf is not None:
            extra.update(tri_ids=tri_face_buf, tri_grad=grad)
    elif hidden_lines or shaded_style:  # no faces: an empty depth buffer
        depth_image = np.full((camera.height, camera.width), np.inf)
        face_ids = np.full((camera.height, camera.width), -1, dtype=np.int32)
    if depth_image is not None:
        extra.update(depth_image=depth_image, face_ids=face_ids)
    t = _lap(timing, "faces", t)

    if shaded_style:
        normals = fs["normals_world"] if use_faces else np.zeros((0, 3))
        light = shading.default_light_dir(camera) if light_dir is None else light_dir
        image = shading.shade(face_ids, normals, light, ambient)  # shaded
        extra["shaded"] = image
        _lap(timing, "shading", t)
        return Frame(
            image=image,
            p_px=p_px.astype(np.float64, copy=False),
            depth=p_cam[:, 2].astype(np.float64),
            visible=visible,
            clipped_edges=clipped_edges,
            **extra,
        )

    image = np.zeros((camera.height, camera.width), dtype=np.uint8)
    if len(edges):
        inside = visible & _inside_image(p_px, camera)  # per vertex: in depth range, on the image
        # Only edges with an end outside need clipping; the rest are drawn
        # straight from the vertex pixels (np.take gathers rows of an (N, 2)
        # array ~10x faster than p_px[idx]). Usually that is every edge.
        direct = inside[edges[:, 0]] & inside[edges[:, 1]]
        d_edges = edges if direct.all() else edges[direct]
        seg0_px = np.take(p_px, d_edges[:, 0], axis=0)
        seg1_px = np.take(p_px, d_edges[:, 1], axis=0)
        if hidden_lines:
            ends = (seg0_px, seg1_px, p_cam[d_edges[:, 0], 2], p_cam[d_edges[:, 1], 2])
        if not direct.all():
            c_edges = edges[~direct]
            if clip_mode == "endpoint":
                c_edges = c_edges[ends_visible[~direct]]  # drop edges with a failing end
            # camera (clipped to the frustum), pixels, and pixels cut to the image
            seg_cam, seg_px, on, c0_px, c1_px = clipping.clip_edges(p_cam[c_edges], camera)
            seg0_px = np.concatenate([seg0_px, c0_px])
            seg1_px = np.concatenate([seg1_px, c1_px])
            if hidden_lines:
                ends = tuple(
                    np.concatenate([a, b])
                    for a, b in zip(ends, (seg_px[on, 0], seg_px[on, 1], seg_cam[on, 0, 2], seg_cam[on, 1, 2]))
                )
        t = _lap(timing, "clip", t)
        if hidden_lines and tri_face_buf is not None and (tri_face_buf >= 0).any():
            extra["hidden_pixels"] = _paint_visible(
                image, seg0_px, seg1_px, ends, raster, depth_image, tri_face_buf, grad, camera
            )
        else:
            _paint(image, seg0_px, seg1_px, raster)  # painted
        _lap(timing, "raster", t)
    return Frame(
        image=image,
        p_px=p_px.astype(np.float64, copy=False),
        depth=p_cam[:, 2].astype(np.float64),
        visible=visible,
        clipped_edges=clipped_edges,
        **extra,
    )


_clock = time.perf_counter


def _lap(timing: dict | None, stage: str, t0: float) -> float:
    """Add the seconds since ``t0`` to ``timing[stage]`` and return the clock (0.0 when timing is None)."""
    if timing is None:
        return 0.0
    t = _clock()
    timing[stage] = timing.get(stage, 0.0) + (t - t0)
    return t


def _faces_stage(p_cam, faces, camera: Camera, model_matrix, cull, need_depth: bool) -> dict:
    """Triangulate, cull and (if ``need_depth``) depth-buffer the faces."""
    tris, tri_face = culling.fan_triangles(faces)
    n_faces = len(faces)
    n = len(p_cam)
    if len(tris) and (tris.min() < 0 or tris.max() >= n):
        bad = int(tris.max()) if tris.max() >= n else int(tris.min())
        raise ValueError(f"faces: vertex index {bad} out of range for {n} vertices")
    tri_cam = p_cam.astype(np.float64, copy=False)[tris]  # camera, (T, 3, 3)
    # the sign of the determinant from slogdet: det() of a scale of 1e-110 underflows to -0.0
    mirrored = bool(np.linalg.slogdet(np.asarray(model_matrix, dtype=np.float64)[:3, :3])[0] < 0)
    out = {"faces_culled": 0, "face_kept": None}
    if cull == "backface":
        keep_tri = culling.backface_keep(tri_cam, camera.projection, mirrored=mirrored)
        face_kept = np.zeros(n_faces, dtype=bool)
        face_kept[tri_face[keep_tri]] = True
        has_tri = np.bincount(tri_face, minlength=n_faces) > 0
        out["faces_culled"] = int((has_tri & ~face_kept).sum())
        out["face_kept"] = face_kept
        kept_idx = np.flatnonzero(keep_tri)
    else:
        kept_idx = np.flatnonzero(~culling.degenerate(tri_cam))  # zero-area faces cover nothing
    if not need_depth:
        return out
    # Outward normals (for shading): sum of fan cross products = the polygon's
    # area vector (Newell). In camera space the cross product is -R n_world
    # (core.projector.culling), so n_world = -R^T n_cc; a mirroring model flips it again.
    n_cc = np.zeros((n_faces, 3))
    if len(tris):
        np.add.at(n_cc, tri_face, culling.triangle_cross_cam(tri_cam))
    r_cam = np.stack([camera.right, camera.up, camera.forward])
    out["normals_world"] = (-1.0 if not mirrored else 1.0) * (n_cc @ r_cam)
    tri_px, tri_z, src = zbuffer.project_triangles(tri_cam[kept_idx], camera)  # pixels (clipped)
    depth, tri_buf = zbuffer.rasterize_triangles(
        tri_px, tri_z, camera.width, camera.height, camera.projection
    )  # depth buffer
    poly_of = tri_face[kept_idx][src]  # clipped tri -> polygon
    out["depth"] = depth
    out["tri_buf"] = tri_buf
    if len(poly_of):
        out["face_ids"] = np.where(tri_buf >= 0, poly_of[np.maximum(tri_buf, 0)], -1).astype(np.int32)
    else:  # every face culled or clipped away: nothing covered
        out["face_ids"] = np.full(tri_buf.shape, -1, dtype=np.int32)
    out["grad"] = zbuffer.triangle_gradients(tri_px, tri_z, camera.projection)
    return out


def _edges_of_kept_faces(edges: np.ndarray, faces, face_kept: np.ndarray, n: int) -> np.ndarray:
    """``(E,) bool``: edges of at least one kept face, or of no face at all."""
    i, j, owner, _ = culling.directed_edges(faces)
    if len(i) == 0:
        return np.ones(len(edges), dtype=bool)
    lo, hi = np.minimum(i, j), np.maximum(i, j)
    key = lo * (n + 1) + hi
    e = np.sort(edges.astype(np.int64), axis=1)
    ekey = e[:, 0] * (n + 1) + e[:, 1]
    in_face = np.isin(ekey, key)
    in_kept = np.isin(ekey, key[face_kept[owner]])
    return in_kept | ~in_face


def _paint_visible(image, seg0_px, seg1_px, ends, mode, depth, tri_buf, grad, camera) -> int:
    """Paint the line pixels not hidden by the depth buffer; return the number of hidden pixels."""
    h, w = image.shape
    seg, rr, cc, weight = line_samples(seg0_px, seg1_px, w, h, mode)
    vis = visible_line_samples(seg, rr, cc, *ends, depth, tri_buf, grad, camera, SLOPE_FACTOR[mode])
    all_px = np.unique(rr * w + cc)
    shown = np.unique(rr[vis] * w + cc[vis])
    if mode == "aa":
        if vis.all():
            _paint(image, seg0_px, seg1_px, mode)  # bit-identical to the plain wireframe
        else:
            image[...] = raster.paint_aa(rr[vis], cc[vis], weight[vis], w, h)
    else:
        image.reshape(-1)[shown] = 255
    return int(len(all_px) - len(shown))


def _paint(image: np.ndarray, seg0_px: np.ndarray, seg1_px: np.ndarray, mode: str) -> None:
    h, w = image.shape
    if mode in ("exact", "fast"):
        fn = raster.line_pixels if mode == "exact" else raster.line_pixels_fast
        rr, cc = fn(seg0_px, seg1_px, w, h)
        flat = rr * w
        flat += cc
        image.reshape(-1)[flat] = 255  # a view (image is a fresh np.zeros); half the time of image[rr, cc]
    else:
        rr, cc, weight = raster.line_coverage_aa(seg0_px, seg1_px, w, h)
        image[...] = raster.paint_aa(rr, cc, weight, w, h)


def draw_segments(
    seg_cam: np.ndarray, camera: Camera, raster: str = "exact", occluders: Frame | None = None
) -> np.ndarray:
    """``(H, W) uint8``: camera-space segments ``(M, 2, 3)`` clipped and drawn as edges are.

    With ``occluders`` (a Frame rendered with ``hidden_lines`` or style
    "shaded" through the same camera), line pixels behind its faces are not
    drawn: the same depth test and bias as the frame's own hidden lines
    (core.projector.zbuffer). Used for the axes, which are drawn over the picture.
    """
    if raster not in RASTER_MODES:
        raise ValueError(f"raster {raster!r}: expected one of {RASTER_MODES}")
    seg_cam = np.asarray(seg_cam, dtype=np.float64).reshape(-1, 2, 3)
    image = np.zeros((camera.height, camera.width), dtype=np.uint8)
    seg_cam, seg_px, on, c0_px, c1_px = clipping.clip_edges(seg_cam, camera)
    if len(seg_cam) == 0:
        return image
    tri = None if occluders is None else occluders.tri_ids
    if tri is not None and (tri >= 0).any():
        ends = (seg_px[on, 0], seg_px[on, 1], seg_cam[on, 0, 2], seg_cam[on, 1, 2])
        _paint_visible(image, c0_px, c1_px, ends, raster, occluders.depth_image, tri, occluders.tri_grad, camera)
    else:
        _paint(image, c0_px, c1_px, raster)
    return image


def _inside_image(p_px: np.ndarray, camera: Camera) -> np.ndarray:
    x, y = p_px[:, 0], p_px[:, 1]
    return (x >= -0.5) & (x <= camera.width - 0.5) & (y >= -0.5) & (y <= camera.height - 0.5)
