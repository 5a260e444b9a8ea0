"""Reference wireframe rasterisation with pyrender on OSMesa (Mesa llvmpipe).

Edges are drawn as one ``GL_LINES`` primitive, 1 px wide, white on black, with
``RenderFlags.FLAT`` (unlit shader: colour = base colour, no lights needed).
Mesa clips lines against near/far and the image sides, like core's "clip"
mode. Face culling does not apply to lines; the optional faces are drawn black
with a polygon offset so they hide the lines behind them without z-fighting
with the lines on their own boundary.

pyrender is imported lazily, after ``PYOPENGL_PLATFORM`` defaults to
``osmesa``. One :class:`PyrenderOracle` keeps one ``OffscreenRenderer`` and one
scene; frames update node poses only (creating a renderer costs ~100 ms).
"""

from __future__ import annotations

import os

import numpy as np

from core.camera import Camera

from .convert import camera_to_pyrender

__all__ = ["osmesa_available", "PyrenderOracle"]

_INSTALL_HINT = "apt-get install -y libosmesa6"


def osmesa_available() -> tuple[bool, str]:
    """Whether pyrender can render offscreen with OSMesa here.

    Returns
    -------
    ok : bool
    message : str, one line; with an install hint when libOSMesa cannot load.
    """
    os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa")
    platform = os.environ["PYOPENGL_PLATFORM"]
    if platform != "osmesa":
        return False, f"PYOPENGL_PLATFORM={platform!r}; the pyrender oracle needs 'osmesa'"
    try:
        from OpenGL import osmesa
        osmesa.OSMesaCreateContextAttribs  # noqa: B018 - raises if the symbol is missing
    except Exception as exc:  # ImportError, OSError, AttributeError, NullFunctionError
        return False, (f"libOSMesa cannot be loaded ({type(exc).__name__}: {exc}); "
                       f"install it with: {_INSTALL_HINT}")
    try:
        import pyrender  # noqa: F401
    except Exception as exc:
        return False, f"pyrender cannot be imported ({type(exc).__name__}: {exc}); pip install pyrender2"
    return True, "OSMesa available"


def _fan(faces) -> np.ndarray:
    """Polygons (index tuples) to triangles ``(T, 3)`` by fanning from vertex 0."""
    tris = [(f[0], f[k], f[k + 1]) for f in faces for k in range(1, len(f) - 1)]
    return np.asarray(tris, dtype=np.uint32).reshape(-1, 3)


class PyrenderOracle:
    """A reusable pyrender/OSMesa wireframe renderer of fixed size.

    Parameters
    ----------
    width, height : int
        Image size; cameras passed to :meth:`render` must match it.

    Use as a context manager, or call :meth:`close`.
    """

    def __init__(self, width: int, height: int):
        os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa")
        import pyrender
        self._pr = pyrender
        self.width, self.height = int(width), int(height)
        self._renderer = pyrender.OffscreenRenderer(self.width, self.height)
        self._scene = pyrender.Scene(bg_color=[0.0, 0.0, 0.0, 1.0], ambient_light=[0.0, 0.0, 0.0])
        self._mesh_node = None
        self._mesh_key = None
        self._cam_node = None
        self._cam_key = None

    # ---- lifetime ------------------------------------------------------
    def close(self) -> None:
        if self._renderer is not None:
            self._renderer.delete()
            self._renderer = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    # ---- scene updates -------------------------------------------------
    def _set_mesh(self, vertices: np.ndarray, edges: np.ndarray, faces) -> None:
        key = (vertices.tobytes(), edges.tobytes(), None if faces is None else tuple(map(tuple, faces)))
        if key == self._mesh_key:
            return
        if self._mesh_node is not None:
            self._scene.remove_node(self._mesh_node)
            self._mesh_node = None
        self._mesh_key = key
        pr = self._pr
        prims = []
        positions = vertices.astype(np.float32)
        if len(edges):
            white = pr.MetallicRoughnessMaterial(baseColorFactor=[1.0, 1.0, 1.0, 1.0])
            prims.append(pr.Primitive(positions=positions, indices=edges.astype(np.uint32),
                                      mode=pr.constants.GLTF.LINES, material=white))
        if faces is not None and len(faces):
            black = pr.MetallicRoughnessMaterial(baseColorFactor=[0.0, 0.0, 0.0, 1.0], doubleSided=True)
            prims.append(pr.Primitive(positions=positions, indices=_fan(faces),
                                      mode=pr.constants.GLTF.TRIANGLES, material=black))
        if prims:
            self._mesh_node = self._scene.add(pr.Mesh(prims))

    def _set_camera(self, camera: Camera) -> None:
        if (camera.width, camera.height) != (self.width, self.height):
            raise ValueError(f"camera size {camera.width}x{camera.height}: this oracle renders "
                             f"{self.width}x{self.height}")
        pose, cam = camera_to_pyrender(camera)
        key = (camera.projection, camera.fov_y_deg, camera.ortho_height, camera.near, camera.far)
        if key != self._cam_key:
            if self._cam_node is not None:
                self._scene.remove_node(self._cam_node)
            self._cam_node = self._scene.add(cam, pose=pose)
            self._cam_key = key
        else:
            self._scene.set_pose(self._cam_node, pose)

    # ---- rendering -----------------------------------------------------
    def render(self, vertices: np.ndarray, edges: np.ndarray, camera: Camera,
               model_matrix: np.ndarray | None = None, faces=None
               ) -> tuple[np.ndarray, np.ndarray]:
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

        Returns
        -------
        colour_mask : (H, W) ndarray of bool, True on line pixels, row 0 on top.
        depth : (H, W) ndarray of float32, camera depth (distance along
            ``forward``) of the nearest fragment, 0 where nothing was drawn
            (pyrender's convention).
        """
        if self._renderer is None:
            raise RuntimeError("PyrenderOracle is closed")
        pr = self._pr
        vertices = np.ascontiguousarray(vertices, dtype=np.float64).reshape(-1, 3)
        edges = np.ascontiguousarray(edges, dtype=np.int64).reshape(-1, 2)
        self._set_mesh(vertices, edges, faces)
        self._set_camera(camera)
        if self._mesh_node is not None:
            pose = np.eye(4) if model_matrix is None else np.asarray(model_matrix, dtype=np.float64)
            self._scene.set_pose(self._mesh_node, pose)
        if faces is not None and len(faces):
            self._polygon_offset()
        colour, depth = self._renderer.render(self._scene, pr.RenderFlags.FLAT)
        return colour[:, :, 0] > 127, np.ascontiguousarray(depth, dtype=np.float32)

    def _polygon_offset(self) -> None:
        # pyrender never touches GL_POLYGON_OFFSET_FILL, so set it on our
        # context: faces are pushed back by ~1 depth unit and lines on their
        # boundary win the GL_LESS depth test.
        from OpenGL import GL
        self._renderer._platform.make_current()
        GL.glEnable(GL.GL_POLYGON_OFFSET_FILL)
        GL.glPolygonOffset(1.0, 1.0)
