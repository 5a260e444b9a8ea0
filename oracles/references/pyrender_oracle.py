"""Reference wireframe rasterisation with pyrender on OSMesa or EGL.

Edges are drawn as one ``GL_LINES`` primitive, 1 px wide, white on black, with
``RenderFlags.FLAT`` (unlit shader: colour = base colour, no lights needed).
Mesa clips lines against near/far and the image sides, like core's "clip"
mode. Face culling does not apply to lines; the optional faces are drawn black
with a polygon offset so they hide the lines behind them without z-fighting
with the lines on their own boundary (hidden lines). With ``cull=True`` those
occluding faces are single-sided: GL culls the back faces (counter-clockwise in
the window = front, GL's default, which is counter-clockwise seen from outside
in the scene files), so a back face hides nothing.

:meth:`PyrenderOracle.render_faces` draws filled triangles for the shaded
comparison: silhouette and depth, with ``RenderFlags.FLAT`` (no lights: neither
coverage nor depth depends on lighting, and a lit image would depend on
pyrender's PBR model, which is not what core's shading implements). Each
triangle gets its own flat colour, its 24-bit index + 1, so the colour buffer
is a triangle-id image (0: background), used to find occlusion boundaries.
Depth is read from the 24-bit depth buffer directly and made linear here in
float64: pyrender's own linearisation assumes a perspective projection (wrong
for its OrthographicCamera) and runs in float32.

Aliased, whatever the driver: the oracle draws into single-sample buffers, so
a pixel is covered exactly when its centre is (GL's rule) and a line pixel is
0 or 255. On OSMesa pyrender draws into the context's own buffer, which has
no samples. With framebuffer objects (EGL) pyrender allocates 4x multisample
buffers and enables ``GL_MULTISAMPLE`` on every pass; Mesa's llvmpipe and the
NVIDIA driver then both anti-alias lines (coverage 64/128/191). The oracle
re-allocates those buffers with 0 samples (:func:`_single_sample`), and
``GL_MULTISAMPLE`` has no effect without sample buffers (multisample
rasterisation needs ``SAMPLE_BUFFERS`` = 1, GL 4.6 core, 14.3.1). Depth then
comes from the pixel centre too.

The GL platform (OSMesa or EGL, and whether it loads) is oracles.references.gl_platform's;
its names are re-exported here. :meth:`PyrenderOracle.gl_info` reads the
context's ``GL_VENDOR``, ``GL_RENDERER`` and ``GL_VERSION`` for the reports.

pyrender is imported lazily. One :class:`PyrenderOracle` keeps one
``OffscreenRenderer`` and one scene; frames update node poses only (creating
a renderer costs ~100 ms), and its shader programs are compiled once
(oracles.references.pyrender_programs: pyrender's own cache compiled one per frame).

What pyrender receives is re-centred in float64 (it computes in float32):
each mesh is uploaded once as its vertices' offsets from their centre
(convert.centre_of), and the mesh node's pose takes them straight to eye
space with the camera node at the identity (convert.gl_eye_pose), so the GPU
rounds magnitudes of the mesh's size and its distance from the camera, not
of the scene's distance from the world origin. :attr:`PyrenderOracle.last_bound_px`
is the oracle's own error bound for the last frame (oracles.references.oracle_precision).
"""

from __future__ import annotations

import numpy as np
from wirecheck.core.camera import Camera

from .convert import camera_to_pyrender, centre_of, gl_eye_pose
from .gl_platform import GL_PLATFORMS, INSTALL_HINT, GLUnavailable, gl_library_problem, gl_platform, select_gl
from .oracle_precision import drawn_bound_px
from .pyrender_programs import stabilise_program_cache

__all__ = [
    "GLUnavailable",
    "GL_PLATFORMS",
    "gl_platform",
    "select_gl",
    "gl_available",
    "osmesa_available",
    "OracleCache",
    "PyrenderOracle",
    "depth_step",
    "DEPTH_LEVELS",
]


def _spare_the_display(platform) -> None:
    """Closing an EGL context leaves the display initialised, for the other oracles.

    pyrender's ``EGLPlatform.delete_context`` ends with ``eglTerminate`` of
    its display, and every context on one device shares that display: closing
    one oracle (an :class:`OracleCache` holds one per image size) would leave
    the others with ``EGL_BAD_DISPLAY``. Here only the context is destroyed;
    the display lives as long as the process. Only this platform instance is
    changed.
    """
    from OpenGL import EGL

    def delete_context():
        if platform._egl_context is not None:
            EGL.eglMakeCurrent(platform._egl_display, EGL.EGL_NO_SURFACE, EGL.EGL_NO_SURFACE, EGL.EGL_NO_CONTEXT)
            EGL.eglDestroyContext(platform._egl_display, platform._egl_context)
            platform._egl_context = None

    platform.delete_context = delete_context


def _single_sample(renderer) -> None:
    """Make pyrender ``renderer``'s offscreen framebuffer single-sample (module docstring).

    pyrender's ``_configure_main_framebuffer`` allocates the colour and depth
    renderbuffers it draws into with 4 samples; after it, they are given
    storage again with 0 samples (the framebuffer keeps them attached), once
    per framebuffer it creates. Only this renderer instance is changed.
    """
    from OpenGL import GL

    configure = renderer._configure_main_framebuffer

    def configure_single_sample():
        configure()
        key = (renderer._main_fb_ms, renderer._main_fb_dims)
        if key == getattr(renderer, "_wirecheck_single_sample", None):
            return
        w, h = renderer._main_fb_dims
        for buffer, fmt in ((renderer._main_cb_ms, GL.GL_RGBA), (renderer._main_db_ms, GL.GL_DEPTH_COMPONENT24)):
            GL.glBindRenderbuffer(GL.GL_RENDERBUFFER, buffer)
            GL.glRenderbufferStorageMultisample(GL.GL_RENDERBUFFER, 0, fmt, w, h)
        renderer._wirecheck_single_sample = key

    renderer._configure_main_framebuffer = configure_single_sample


def _fan(faces) -> np.ndarray:
    """Polygons (index tuples) to triangles ``(T, 3)`` by fanning from vertex 0."""
    tris = [(f[0], f[k], f[k + 1]) for f in faces for k in range(1, len(f) - 1)]
    return np.asarray(tris, dtype=np.uint32).reshape(-1, 3)


def _linear_depth(z_win: np.ndarray, camera: Camera) -> np.ndarray:
    """Window depth in [0, 1] (float64) to camera depth, 0 where nothing was drawn (``z_win == 1``).

    GL maps NDC z in [-1, 1] to the window's [0, 1]. pyrender's projection
    matrices (``IntrinsicsCamera`` / ``OrthographicCamera.get_projection_matrix``)
    give, with ``d`` the camera depth (distance along forward)::

        perspective:   z_win = f (d - n) / ((f - n) d)   ->   d = f n / (f - z_win (f - n))
        orthographic:  z_win = (d - n) / (f - n)         ->   d = n + z_win (f - n)
    """
    n, f = float(camera.near), float(camera.far)
    drawn = z_win < 1.0
    d = np.zeros(z_win.shape, np.float64)
    z = z_win[drawn]
    if camera.projection == "perspective":
        d[drawn] = f * n / (f - z * (f - n))
    else:
        d[drawn] = n + z * (f - n)
    return d


def depth_step(depth, camera: Camera):
    """One step of the 24-bit depth buffer, in camera depth units, at camera depth ``depth``.

    ``dz_win = 1 / (2^24 - 1)``; the derivative of the maps in :func:`_linear_depth`:
    perspective ``d'(z_win) = d^2 (f - n) / (f n)``, orthographic ``f - n``.
    """
    n, f = float(camera.near), float(camera.far)
    depth = np.asarray(depth, dtype=np.float64)
    if camera.projection == "perspective":  # depth**2 * (f - n) / (f * n) / DEPTH_LEVELS, in one array
        step = np.square(depth)
        step *= f - n
        step /= f * n
        step /= DEPTH_LEVELS
        return step
    return np.full(depth.shape, (f - n) / DEPTH_LEVELS)


#: Levels of pyrender's GL_DEPTH_COMPONENT24 buffer: z_win = k / (2^24 - 1).
DEPTH_LEVELS = float(2**24 - 1)


def _id_colours(count: int) -> np.ndarray:
    """``(count, 3)`` uint8: triangle ``i`` as the 24-bit number ``i + 1`` (R high byte)."""
    ids = np.arange(1, count + 1, dtype=np.uint32)
    return np.stack([(ids >> 16) & 255, (ids >> 8) & 255, ids & 255], axis=1).astype(np.uint8)


def _delete_renderer(renderer) -> None:
    """``OffscreenRenderer.delete()`` without its closing ``gc.collect()``.

    The GL objects are freed and the context destroyed as pyrender does; the
    full garbage collection it ends with took ~0.1 s in a process holding a
    test suite's objects (68 collections, 6.5 s in four test files), for every
    crosscheck run in such a process. Python's own collector still runs. A
    pyrender without these attributes gets its own ``delete()``.
    """
    platform, inner = getattr(renderer, "_platform", None), getattr(renderer, "_renderer", None)
    if platform is None or inner is None or not hasattr(platform, "delete_context"):
        renderer.delete()
        return
    platform.make_current()
    inner.delete()
    platform.delete_context()
    renderer._renderer = None
    renderer._platform = None


class PyrenderOracle:
    """A reusable pyrender wireframe renderer of fixed size, on :func:`gl_platform`.

    Parameters
    ----------
    width, height : int
        Image size; cameras passed to :meth:`render` must match it.

    Use as a context manager, or call :meth:`close`.
    """

    def __init__(self, width: int, height: int):
        self.platform = gl_platform()
        import pyrender

        self._pr = pyrender
        self.width, self.height = int(width), int(height)
        self._renderer = pyrender.OffscreenRenderer(self.width, self.height)
        _single_sample(self._renderer._renderer)
        stabilise_program_cache(self._renderer._renderer)  # one program per shader, not per frame
        if self.platform == "egl":
            _spare_the_display(self._renderer._platform)
        self._gl_info = None
        self._scene = pyrender.Scene(bg_color=[0.0, 0.0, 0.0, 1.0], ambient_light=[0.0, 0.0, 0.0])
        self._mesh_node = None
        self._mesh_key = None
        self._mesh_faces = None
        self._mesh_centre = np.zeros(3)  # of the uploaded vertices (float64)
        self._mesh_q, self._mesh_segments = np.zeros((0, 3)), np.zeros((0, 2), np.int64)  # what GL draws
        self._bound_of = None  # drawn_bound_px's arguments for the last frame drawn (last_bound_px)
        self._last_bound_px = 0.0
        self._cam_node = None
        self._cam_key = None
        # render_faces: a scene of its own, so that alternating with render() rebuilds nothing
        self._fscene = pyrender.Scene(bg_color=[0.0, 0.0, 0.0, 1.0], ambient_light=[0.0, 0.0, 0.0])
        self._fmesh_node = None
        self._fmesh_key = None
        self._fmesh_centre = np.zeros(3)
        self._fmesh_q, self._fmesh_segments = np.zeros((0, 3)), np.zeros((0, 2), np.int64)
        self._fcam_node = None
        self._fcam_key = None

    # ---- lifetime ------------------------------------------------------
    def close(self) -> None:
        if self._renderer is not None:
            _delete_renderer(self._renderer)
            self._renderer = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def gl_info(self) -> dict:
        """The GL that draws this oracle's frames, read from its context (once).

        ``{"platform", "vendor", "renderer", "version", "samples"}``: the
        ``PYOPENGL_PLATFORM``, ``glGetString`` of ``GL_VENDOR``,
        ``GL_RENDERER`` and ``GL_VERSION``, and ``GL_SAMPLES`` of the
        framebuffer pyrender draws into (0: aliased, module docstring).
        """
        if self._gl_info is None:
            from OpenGL import GL

            if self._renderer is None:
                raise RuntimeError("PyrenderOracle is closed")
            platform = self._renderer._platform
            platform.make_current()
            try:
                strings = {
                    key: GL.glGetString(name).decode("utf-8", "replace")
                    for key, name in (
                        ("vendor", GL.GL_VENDOR),
                        ("renderer", GL.GL_RENDERER),
                        ("version", GL.GL_VERSION),
                    )
                }
                draw_fb = 0
                if platform.supports_framebuffers():
                    self._renderer._renderer._configure_main_framebuffer()
                    draw_fb = self._renderer._renderer._main_fb_ms
                GL.glBindFramebuffer(GL.GL_DRAW_FRAMEBUFFER, draw_fb)
                samples = int(GL.glGetIntegerv(GL.GL_SAMPLES))
            finally:
                platform.make_uncurrent()
            self._gl_info = {"platform": self.platform, **strings, "samples": samples}
        return dict(self._gl_info)

    # ---- scene updates -------------------------------------------------
    def _set_mesh(self, vertices: np.ndarray, edges: np.ndarray, faces, cull: bool = False) -> None:
        # faces are compared by identity (a scene's faces are an immutable tuple, the same
        # object every frame): turning 100k polygons into a key costs more than a frame
        key = (vertices.tobytes(), edges.tobytes(), cull)
        if key == self._mesh_key and faces is self._mesh_faces and (faces is None or isinstance(faces, tuple)):
            return
        self._mesh_faces = faces
        if self._mesh_node is not None:
            self._scene.remove_node(self._mesh_node)
            self._mesh_node = None
        self._mesh_key = key
        pr = self._pr
        prims = []
        # re-centred in float64 before the float32 upload (convert.gl_eye_pose): one upload per mesh
        self._mesh_centre = centre_of(vertices)
        positions = (vertices - self._mesh_centre).astype(np.float32)
        self._mesh_q = positions.astype(np.float64)
        tris = _fan(faces) if faces is not None and len(faces) else np.zeros((0, 3), np.uint32)
        t = tris.astype(np.int64)  # the occluding faces decide which line pixels are hidden: theirs too
        self._mesh_segments = np.concatenate([edges, t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]])
        if len(edges):
            white = pr.MetallicRoughnessMaterial(baseColorFactor=[1.0, 1.0, 1.0, 1.0])
            prims.append(
                pr.Primitive(
                    positions=positions, indices=edges.astype(np.uint32), mode=pr.constants.GLTF.LINES, material=white
                )
            )
        if len(tris):
            black = pr.MetallicRoughnessMaterial(baseColorFactor=[0.0, 0.0, 0.0, 1.0], doubleSided=not cull)
            prims.append(
                pr.Primitive(positions=positions, indices=tris, mode=pr.constants.GLTF.TRIANGLES, material=black)
            )
        if prims:
            self._mesh_node = self._scene.add(pr.Mesh(prims))

    @property
    def last_bound_px(self) -> float:
        """oracle_precision.drawn_bound_px of the last frame drawn (0 when nothing was drawn): worked out when
        first asked for (a depth reference never asks: 0.19 s a frame on a 20k-face mesh), from the
        camera, pose and geometry of that frame, which a later frame does not change (each is replaced,
        never edited in place)."""
        if self._bound_of is not None:
            self._last_bound_px = drawn_bound_px(*self._bound_of)
            self._bound_of = None
        return self._last_bound_px

    def _set_camera(self, camera: Camera, faces_scene: bool = False) -> None:
        if (camera.width, camera.height) != (self.width, self.height):
            raise ValueError(
                f"camera size {camera.width}x{camera.height}: this oracle renders {self.width}x{self.height}"
            )
        scene, node_attr, key_attr = (
            (self._fscene, "_fcam_node", "_fcam_key") if faces_scene else (self._scene, "_cam_node", "_cam_key")
        )
        # the camera node stays at the identity: the mesh node's pose takes its vertices to eye space
        # (convert.gl_eye_pose), so the camera's position never reaches float32
        key = (camera.projection, camera.fov_y_deg, camera.ortho_height, camera.near, camera.far, camera.intrinsics)
        if key != getattr(self, key_attr):
            _pose, cam = camera_to_pyrender(camera)
            if getattr(self, node_attr) is not None:
                scene.remove_node(getattr(self, node_attr))
            setattr(self, node_attr, scene.add(cam, pose=np.eye(4)))
            setattr(self, key_attr, key)

    def _set_faces(self, vertices: np.ndarray, triangles: np.ndarray, cull: bool) -> None:
        key = (vertices.tobytes(), triangles.tobytes(), cull)
        if key == self._fmesh_key:
            return
        if self._fmesh_node is not None:
            self._fscene.remove_node(self._fmesh_node)
            self._fmesh_node = None
        self._fmesh_key = key
        if len(triangles) == 0:
            return
        pr = self._pr
        # every triangle its own three vertices, all of its id colour: the flat
        # shader multiplies the (white) base colour by the interpolated vertex
        # colour, which is then constant over the triangle
        self._fmesh_centre = centre_of(vertices)
        centred = vertices - self._fmesh_centre
        positions = centred[triangles.reshape(-1)].astype(np.float32)
        self._fmesh_q = positions.astype(np.float64)
        corner = np.arange(len(positions), dtype=np.int64).reshape(-1, 3)  # each triangle's three edges
        self._fmesh_segments = np.concatenate([corner[:, [0, 1]], corner[:, [1, 2]], corner[:, [2, 0]]])
        colours = np.repeat(_id_colours(len(triangles)), 3, axis=0)
        colours = np.concatenate([colours, np.full((len(colours), 1), 255, np.uint8)], axis=1)
        white = pr.MetallicRoughnessMaterial(baseColorFactor=[1.0, 1.0, 1.0, 1.0], doubleSided=not cull)
        prim = pr.Primitive(
            positions=positions,
            color_0=colours,
            indices=np.arange(len(positions), dtype=np.uint32).reshape(-1, 3),
            mode=pr.constants.GLTF.TRIANGLES,
            material=white,
        )
        self._fmesh_node = self._fscene.add(pr.Mesh([prim]))

    # ---- rendering -----------------------------------------------------
    def render(
        self,
        vertices: np.ndarray,
        edges: np.ndarray,
        camera: Camera,
        model_matrix: np.ndarray | None = None,
        faces=None,
        cull: bool = False,
        depth: bool = True,
    ) -> tuple[np.ndarray, np.ndarray | None]:
        """Render a wireframe.

        Parameters
        ----------
        vertices : (N, 3) array_like
            ``p_model`` (with ``model_matrix``) or ``p_world`` (without).
        edges : (E, 2) array_like of int
        camera : Camera
            Its size must be this oracle's size.
        model_matrix : (4, 4) array_like, optional
            Pose of the mesh node; identity when None.
        faces : sequence of index tuples, optional
            Polygons drawn black (occluders); None draws every line.
        cull : bool
            Occluding faces single-sided: back faces (clockwise in the window)
            are culled by GL and hide nothing.
        depth : bool
            Read the depth buffer back too. False: only the colour buffer's
            red channel is read (:meth:`_read_line_mask`: the same mask,
            without pyrender's depth read and float32 linearisation, about
            half of a 640x480 frame's time on llvmpipe).

        Returns
        -------
        colour_mask : (H, W) ndarray of bool, True on line pixels, row 0 on top.
        depth : (H, W) ndarray of float32, camera depth (distance along
            ``forward``) of the nearest fragment, 0 where nothing was drawn
            (pyrender's convention); None when ``depth`` is False.
        """
        if self._renderer is None:
            raise RuntimeError("PyrenderOracle is closed")
        pr = self._pr
        vertices = np.ascontiguousarray(vertices, dtype=np.float64).reshape(-1, 3)
        edges = np.ascontiguousarray(edges, dtype=np.int64).reshape(-1, 2)
        self._set_mesh(vertices, edges, faces, bool(cull))
        self._set_camera(camera)
        self._bound_of, self._last_bound_px = None, 0.0
        if self._mesh_node is not None:
            pose = gl_eye_pose(camera, model_matrix, self._mesh_centre)
            self._scene.set_pose(self._mesh_node, pose)
            self._bound_of = (camera, pose, self._mesh_q, self._mesh_segments)
        if faces is not None and len(faces):
            self._polygon_offset()
        if not depth:
            return self._read_line_mask(), None
        colour, z = self._renderer.render(self._scene, pr.RenderFlags.FLAT)
        return colour[:, :, 0] > 127, np.ascontiguousarray(z, dtype=np.float32)

    def _read_line_mask(self) -> np.ndarray:
        """Draw the wireframe scene as ``OffscreenRenderer.render`` does and read back only its red channel.

        The mask is ``red > 127``, row 0 on top, as :meth:`render`'s with depth:
        GL_RED of the same 8-bit buffer is the red byte pyrender's GL_RGB read
        gives. On OSMesa pyrender draws into the context's own buffer (read
        from ``GL_FRONT`` of framebuffer 0, as its ``read_color_buf``); with
        framebuffer objects its draw framebuffer (single-sample here,
        :func:`_single_sample`, so it may be read) is read directly, with no
        blit to the resolve framebuffer and no depth read. PyOpenGL's
        ``glReadPixels`` packs rows tightly (``GL_PACK_ALIGNMENT`` 1).
        """
        from OpenGL import GL

        pr, off = self._pr, self._renderer
        inner, platform = off._renderer, off._platform
        platform.make_current()
        try:
            inner.viewport_width, inner.viewport_height = off.viewport_width, off.viewport_height
            inner.point_size = off.point_size
            if platform.supports_framebuffers():
                # pyrender's offscreen pass ends by reading colour and depth: here it reads nothing
                inner._read_main_framebuffer = lambda scene, flags: None
                try:
                    inner.render(self._scene, pr.RenderFlags.FLAT | pr.RenderFlags.OFFSCREEN)
                finally:
                    del inner._read_main_framebuffer
                GL.glBindFramebuffer(GL.GL_READ_FRAMEBUFFER, inner._main_fb_ms)
            else:
                inner.render(self._scene, pr.RenderFlags.FLAT)
                GL.glBindFramebuffer(GL.GL_READ_FRAMEBUFFER, 0)
                GL.glReadBuffer(GL.GL_FRONT)
            red = GL.glReadPixels(0, 0, self.width, self.height, GL.GL_RED, GL.GL_UNSIGNED_BYTE)
        finally:
            platform.make_uncurrent()
        return np.frombuffer(red, dtype=np.uint8).reshape(self.height, self.width)[::-1] > 127

    def render_faces(
        self,
        vertices: np.ndarray,
        triangles: np.ndarray,
        camera: Camera,
        model_matrix: np.ndarray | None = None,
        cull: bool = False,
        with_ids: bool = False,
    ):
        """Render filled triangles: coverage and linear camera depth (and triangle ids).

        ``vertices``, ``camera`` and ``model_matrix`` as in :meth:`render`;
        ``triangles`` is ``(T, 3)`` int. ``cull``: GL back-face culling
        (pyrender's default for a material that is not ``doubleSided``;
        counter-clockwise in the window is front). ``with_ids``: also return
        the triangle-id image.

        Returns
        -------
        covered : (H, W) bool, True where some triangle covers the pixel centre.
        depth : (H, W) float64, camera depth of the nearest triangle (distance
            along ``forward``), 0 where nothing was drawn; from the 24-bit
            depth buffer (:func:`depth_step` is its resolution).
        ids : (H, W) int64, only with ``with_ids``: index of the triangle seen
            at each pixel, -1 where none.
        """
        if self._renderer is None:
            raise RuntimeError("PyrenderOracle is closed")
        pr = self._pr
        vertices = np.ascontiguousarray(vertices, dtype=np.float64).reshape(-1, 3)
        triangles = np.ascontiguousarray(triangles, dtype=np.int64).reshape(-1, 3)
        if with_ids and len(triangles) >= 2**24 - 1:
            raise ValueError(f"{len(triangles)} triangles: the id image holds at most 2^24 - 2")
        self._set_faces(vertices, triangles, bool(cull))
        self._set_camera(camera, faces_scene=True)
        self._bound_of, self._last_bound_px = None, 0.0
        if self._fmesh_node is not None:
            pose = gl_eye_pose(camera, model_matrix, self._fmesh_centre)
            self._fscene.set_pose(self._fmesh_node, pose)
            self._bound_of = (camera, pose, self._fmesh_q, self._fmesh_segments)
        self._no_polygon_offset()
        colour, _pyrender_depth = self._renderer.render(self._fscene, pr.RenderFlags.FLAT)
        z_win = self._read_window_depth()
        depth = _linear_depth(z_win, camera)
        covered = z_win < 1.0
        if not with_ids:
            return covered, depth
        c = colour.astype(np.int64)
        ids = ((c[:, :, 0] << 16) | (c[:, :, 1] << 8) | c[:, :, 2]) - 1
        if ids.max(initial=-1) >= len(triangles) or ((ids >= 0) != covered).any():
            raise RuntimeError(
                "pyrender's triangle-id colours came back altered (expected flat, unlit, "
                "exact 8-bit colours): cannot find occlusion boundaries"
            )
        return covered, depth, ids

    def _read_window_depth(self) -> np.ndarray:
        """The last render's depth buffer as window depth in [0, 1], float64, row 0 on top.

        Read as GL_UNSIGNED_INT (exact: the 24-bit value ``k`` in the high
        bits, ``z_win = k / (2^24 - 1)``) from where pyrender rendered: on
        OSMesa (no framebuffer objects) the default framebuffer's front buffer,
        as pyrender's ``read_depth_buf`` does, else its resolved main
        framebuffer. pyrender's own depth image is not used: its linearisation
        assumes a perspective projection and runs in float32.
        """
        from OpenGL import GL

        platform = self._renderer._platform
        platform.make_current()
        try:
            if platform.supports_framebuffers():
                GL.glBindFramebuffer(GL.GL_READ_FRAMEBUFFER, self._renderer._renderer._main_fb)
            else:
                GL.glBindFramebuffer(GL.GL_READ_FRAMEBUFFER, 0)
                GL.glReadBuffer(GL.GL_FRONT)
            buf = GL.glReadPixels(0, 0, self.width, self.height, GL.GL_DEPTH_COMPONENT, GL.GL_UNSIGNED_INT)
        finally:
            platform.make_uncurrent()
        raw = np.frombuffer(buf, dtype=np.uint32).reshape(self.height, self.width)[::-1]
        return (raw >> 8).astype(np.float64) / DEPTH_LEVELS

    def _no_polygon_offset(self) -> None:
        from OpenGL import GL

        self._renderer._platform.make_current()
        GL.glDisable(GL.GL_POLYGON_OFFSET_FILL)

    def _polygon_offset(self) -> None:
        # pyrender never touches GL_POLYGON_OFFSET_FILL, so set it on our
        # context: faces are pushed back by ~1 depth unit and lines on their
        # boundary win the GL_LESS depth test.
        from OpenGL import GL

        self._renderer._platform.make_current()
        GL.glEnable(GL.GL_POLYGON_OFFSET_FILL)
        GL.glPolygonOffset(1.0, 1.0)


_EGL_CHECKED: dict[str, tuple[bool, str]] = {}


def gl_available() -> tuple[bool, str]:
    """Whether pyrender can render offscreen here on :func:`gl_platform`.

    OSMesa: libOSMesa loads. EGL: a 1x1 context can be created and made
    current (the only reliable test: libEGL may load with no usable device),
    checked once per process.

    Returns
    -------
    ok : bool
    message : str, one line; with an install hint when the library cannot load.
    """
    platform = gl_platform()
    problem = gl_library_problem(platform)
    if problem is not None:
        return False, problem
    if platform == "osmesa":
        return True, "OSMesa available"
    if platform not in _EGL_CHECKED:
        try:
            PyrenderOracle(1, 1).close()
            _EGL_CHECKED[platform] = (True, "EGL available")
        except Exception as exc:  # RuntimeError, OSError, ImportError, GLError: no usable EGL
            msg = " ".join(f"{type(exc).__name__}: {exc}".split())[:300]
            _EGL_CHECKED[platform] = (
                False,
                f"no EGL context can be created ({msg}); install it with: {INSTALL_HINT['egl']}",
            )
    return _EGL_CHECKED[platform]


def osmesa_available() -> tuple[bool, str]:
    """:func:`gl_available` (the older name, from when OSMesa was the only platform)."""
    return gl_available()


class OracleCache:
    """One :class:`PyrenderOracle` per image size, created on first use and closed together.

    Each oracle owns an OpenGL context sized to its image, so callers that
    render several cameras keep one per ``(width, height)``.
    """

    def __init__(self):
        self._by_size: dict[tuple[int, int], PyrenderOracle] = {}

    def get(self, width: int, height: int) -> PyrenderOracle:
        """The oracle for images of ``width`` x ``height`` pixels (created if new)."""
        key = (int(width), int(height))
        if key not in self._by_size:
            self._by_size[key] = PyrenderOracle(*key)
        return self._by_size[key]

    def __contains__(self, size) -> bool:
        return tuple(size) in self._by_size

    def gl_info(self) -> dict | None:
        """:meth:`PyrenderOracle.gl_info` of the first oracle made (one driver per process); None before any."""
        first = next(iter(self._by_size.values()), None)
        return None if first is None else first.gl_info()

    def close(self) -> None:
        """Release every context; the cache may be used again afterwards."""
        oracles, self._by_size = self._by_size, {}
        for oracle in oracles.values():
            oracle.close()
