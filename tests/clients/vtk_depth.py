"""A depth map rendered as a VTK user would: an offscreen vtkRenderWindow, its z-buffer read back.

``python vtk_depth.py DIR``: for each ``DIR/NAME.npz`` (``p_world``, ``triangles`` and the
camera's ``position``, ``forward``, ``up``, ``fov_y_deg``, ``ortho_height``, ``width``,
``height``, ``near``, ``far``, ``projection``) writes ``DIR/NAME.LABEL.npy`` for each label of
``MISTAKES``. Run in its own process, as a renderer is: its GL context never shares a process
with the pyrender oracle's.

``render_depth(p_world, triangles, camera, mistake=None) -> (H, W) float32``: the triangles as
a vtkPolyData of polygon cells, unlit, in a renderer whose vtkCamera is set from the contract's
camera: position, focal point = position + forward, view up, ``SetViewAngle(fov_y_deg)`` (VTK's
view angle is vertical by default), ``SetClippingRange(near, far)``; orthographic cameras as a
parallel projection with ``SetParallelScale`` half the ortho height. The principal point is the
image centre in every bundled case, as VTK's is. The window is offscreen, of the camera's size,
without multisampling (EGL or OSMesa where there is no display). ``vtkWindowToImageFilter`` with
``SetInputBufferTypeToZBuffer`` reads the window depth ``z_win`` in [0, 1] (1: nothing drawn),
made linear from the camera's clipping range as read back (perspective
``d = 2 f n / ((f + n) - z_ndc (f - n))`` with ``z_ndc = 2 z_win - 1``; parallel
``d = n + z_win (f - n)``), 0 where nothing was drawn, and the rows flipped: VTK's row 0 is the
bottom. Only numpy and vtk: nothing of wirecheck.

``mistake``: ``"zbuffer"`` stores the window depth as read (the classic), ``"no_flip"`` keeps
VTK's bottom-up rows, ``"horizontal_fov"`` sets ``SetUseHorizontalViewAngle(1)`` with the same
angle (the vertical FOV given as the horizontal one; a parallel projection has no view angle).
"""

from __future__ import annotations

import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np

_WINDOWS = {}  # (w, h): (window, renderer, grab)


def _window(w: int, h: int):
    import vtk

    if (w, h) not in _WINDOWS:
        win = vtk.vtkRenderWindow()
        win.SetOffScreenRendering(1)
        win.SetMultiSamples(0)
        win.SetSize(w, h)
        ren = vtk.vtkRenderer()
        ren.SetBackground(0.0, 0.0, 0.0)
        win.AddRenderer(ren)
        grab = vtk.vtkWindowToImageFilter()
        grab.SetInput(win)
        grab.SetInputBufferTypeToZBuffer()
        grab.ReadFrontBufferOff()
        _WINDOWS[w, h] = (win, ren, grab)
    return _WINDOWS[w, h]


def poly_faces(p_world: np.ndarray, triangles: np.ndarray):
    """A vtkPolyData of the points and one triangle cell per row of ``triangles``."""
    import vtk
    from vtk.util.numpy_support import numpy_to_vtk

    points = vtk.vtkPoints()
    points.SetData(numpy_to_vtk(np.ascontiguousarray(p_world, dtype=np.float64), deep=True))
    polys = vtk.vtkCellArray()
    for i, j, k in np.asarray(triangles).tolist():
        polys.InsertNextCell(3, (i, j, k))
    poly = vtk.vtkPolyData()
    poly.SetPoints(points)
    poly.SetPolys(polys)
    return poly


def set_camera(camera, cam, mistake: str | None) -> None:
    """Pose and lens of a vtkCamera from the contract's camera fields."""
    pos = np.asarray(cam.position, dtype=float)
    camera.SetPosition(*pos)
    camera.SetFocalPoint(*(pos + np.asarray(cam.forward, dtype=float)))
    camera.SetViewUp(*np.asarray(cam.up, dtype=float))
    camera.SetClippingRange(cam.near, cam.far)
    if cam.projection == "orthographic":
        camera.ParallelProjectionOn()
        camera.SetParallelScale(cam.ortho_height / 2.0)  # VTK's scale: half the height
    else:
        camera.ParallelProjectionOff()
        camera.SetViewAngle(cam.fov_y_deg)  # vertical unless told otherwise
        camera.SetUseHorizontalViewAngle(1 if mistake == "horizontal_fov" else 0)


def render_depth(p_world, triangles, camera, mistake=None) -> np.ndarray:
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy

    w, h = camera.width, camera.height
    win, ren, grab = _window(w, h)
    mapper = vtk.vtkPolyDataMapper()
    mapper.SetInputData(poly_faces(p_world, triangles))
    actor = vtk.vtkActor()
    actor.SetMapper(mapper)
    actor.GetProperty().LightingOff()
    ren.RemoveAllViewProps()
    ren.AddActor(actor)
    vcam = ren.GetActiveCamera()
    set_camera(vcam, camera, mistake)
    win.Render()
    grab.Modified()
    grab.Update()
    out = grab.GetOutput()
    gw, gh, _ = out.GetDimensions()
    z_win = vtk_to_numpy(out.GetPointData().GetScalars()).reshape(gh, gw).astype(np.float64)
    drawn = z_win < 1.0
    n, f = vcam.GetClippingRange()  # what the camera drew with
    if mistake == "zbuffer":
        depth = np.where(drawn, z_win, 0.0)
    elif vcam.GetParallelProjection():
        depth = np.where(drawn, n + z_win * (f - n), 0.0)
    else:
        depth = np.where(drawn, 2.0 * f * n / ((f + n) - (2.0 * z_win - 1.0) * (f - n)), 0.0)
    if mistake != "no_flip":
        depth = depth[::-1]  # VTK's rows run bottom up
    return depth.astype(np.float32)


MISTAKES = {"correct": None, "zbuffer": "zbuffer", "no_flip": "no_flip", "horizontal_fov": "horizontal_fov"}
FIELDS = ("position", "forward", "up", "fov_y_deg", "ortho_height", "near", "far")


def main(argv=None) -> int:
    folder = Path((sys.argv[1:] if argv is None else argv)[0])
    for request in sorted(folder.glob("*.npz")):
        with np.load(request) as data:
            camera = SimpleNamespace(
                width=int(data["width"]),
                height=int(data["height"]),
                projection=str(data["projection"]),
                **{k: (data[k] if data[k].ndim else float(data[k])) for k in FIELDS},
            )
            for label, mistake in MISTAKES.items():
                np.save(
                    folder / f"{request.stem}.{label}.npy",
                    render_depth(data["p_world"], data["triangles"], camera, mistake),
                )
    return 0


if __name__ == "__main__":
    sys.exit(main())
