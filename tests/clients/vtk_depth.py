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
angle (the vertical FOV given as the horizontal one; a parallel projection has no view angle),
``"range"`` stores each pixel's distance from the camera's position to its point, the z-buffer
unprojected through the inverse of ``GetCompositeProjectionTransformMatrix`` (the distance along
the ray where depth along forward was asked; the same unprojection, dotted with the direction of
projection, gives the depth).

``python vtk_depth.py --job JOB [--mistake NAME]``: an exported job (``crosscheck export JOB
--outputs filled,depth``) rendered as its README asks, read as a user reads it
(tests/clients/job_files.py: job.json, the OBJ's ``f`` faces, each frame's camera JSON,
``p_world = model_matrix @ [v, 1]``), the vtkCamera from the camera JSON's ``camera`` fields; each
filled frame from the RGB buffer (the cells coloured by grey level ``1 + object``: one id per
object, the scene's ``objects``; unlit), each depth map from the z-buffer, written in job.json's
``depth_encoding``; ``--mistake`` applied to every frame.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
from job_files import job_surfaces, write_depth

_WINDOWS = {}  # (w, h): (window, renderer, z-buffer grab, RGB grab)


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
        rgb = vtk.vtkWindowToImageFilter()
        rgb.SetInput(win)
        rgb.SetInputBufferTypeToRGB()
        rgb.ReadFrontBufferOff()
        _WINDOWS[w, h] = (win, ren, grab, rgb)
    return _WINDOWS[w, h]


def poly_faces(p_world: np.ndarray, triangles: np.ndarray, levels=None):
    """A vtkPolyData of the points and one triangle cell per row of ``triangles``; ``levels``: each cell's
    grey level (1 to 255) as its RGB colour."""
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
    if levels is not None:
        colours = numpy_to_vtk(np.repeat(np.asarray(levels, dtype=np.uint8)[:, None], 3, axis=1), deep=True)
        poly.GetCellData().SetScalars(colours)
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


def render(p_world, triangles, camera, mistake=None, levels=None) -> tuple[np.ndarray, np.ndarray]:
    """``(depth (H, W) float32, filled (H, W) uint8)``: the depth map (module docstring) and the RGB
    buffer's grey levels, ``levels[i]`` (1 to 255; 255 when None) where triangle ``i`` is nearest, 0 where
    nothing was drawn; ``mistake`` applied to both (a mistake of the values to the depth map alone)."""
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy

    w, h = camera.width, camera.height
    win, ren, grab, rgb = _window(w, h)
    triangles = np.asarray(triangles).reshape(-1, 3)
    mapper = vtk.vtkPolyDataMapper()
    mapper.SetInputData(poly_faces(p_world, triangles, np.full(len(triangles), 255) if levels is None else levels))
    mapper.SetColorModeToDirectScalars()  # the cells' RGB as they are, no lookup table
    mapper.SetScalarModeToUseCellData()
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
    rgb.Modified()
    rgb.Update()
    filled = vtk_to_numpy(rgb.GetOutput().GetPointData().GetScalars()).reshape(gh, gw, -1)[:, :, 0]
    drawn = z_win < 1.0
    n, f = vcam.GetClippingRange()  # what the camera drew with
    if mistake == "zbuffer":
        depth = np.where(drawn, z_win, 0.0)
    elif mistake == "range":
        depth = np.where(drawn, _distance_from_eye(vcam, z_win, w, h), 0.0)
    elif vcam.GetParallelProjection():
        depth = np.where(drawn, n + z_win * (f - n), 0.0)
    else:
        depth = np.where(drawn, 2.0 * f * n / ((f + n) - (2.0 * z_win - 1.0) * (f - n)), 0.0)
    if mistake != "no_flip":  # VTK's rows run bottom up
        depth, filled = depth[::-1], filled[::-1]
    return depth.astype(np.float32), np.ascontiguousarray(filled, dtype=np.uint8)


def _distance_from_eye(vcam, z_win: np.ndarray, w: int, h: int) -> np.ndarray:
    """Each pixel's point, unprojected from its window depth through the camera's composite projection
    (NDC ``x = (2 i + 1) / W - 1``, rows bottom up as read), its distance from the camera's position."""
    m = vcam.GetCompositeProjectionTransformMatrix(w / h, -1.0, 1.0)
    inv = np.linalg.inv(np.array([[m.GetElement(i, j) for j in range(4)] for i in range(4)]))
    rows, cols = np.mgrid[0:h, 0:w]
    ndc = np.stack([(2 * cols + 1) / w - 1, (2 * rows + 1) / h - 1, 2 * z_win - 1, np.ones_like(z_win)], axis=-1)
    p = ndc @ inv.T
    p_world = p[..., :3] / p[..., 3:]
    return np.linalg.norm(p_world - np.asarray(vcam.GetPosition()), axis=-1)


def render_depth(p_world, triangles, camera, mistake=None) -> np.ndarray:
    return render(p_world, triangles, camera, mistake)[0]


#: The npz mode's maps, label: mistake (``"range"`` is the job mode's alone).
MISTAKES = {"correct": None, "zbuffer": "zbuffer", "no_flip": "no_flip", "horizontal_fov": "horizontal_fov"}
FIELDS = ("position", "forward", "up", "fov_y_deg", "ortho_height", "near", "far")


def render_job(job_dir: Path, mistake=None) -> None:
    """Every filled frame and depth map the exported job at ``job_dir`` lists (module docstring)."""
    from PIL import Image

    encoding = json.loads((job_dir / "job.json").read_text()).get("depth_encoding")
    for c, cam_json, p_world, triangles, objects, files in job_surfaces(job_dir):
        cam = cam_json["camera"]
        camera = SimpleNamespace(**{k: cam[k] for k in FIELDS + ("width", "height", "projection")})
        depth, filled = render(p_world, triangles, camera, mistake, levels=1 + objects)
        if files["filled"] is not None:
            files["filled"].parent.mkdir(parents=True, exist_ok=True)
            Image.fromarray(filled).save(files["filled"])
        if files["depth"] is not None:
            write_depth(files["depth"], depth, encoding)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("folder", type=Path)
    ap.add_argument("--job", action="store_true", help="the folder is an exported job (module docstring)")
    ap.add_argument("--mistake", choices=("zbuffer", "no_flip", "horizontal_fov", "range"), help="with --job")
    args = ap.parse_args(argv)
    if args.job:
        render_job(args.folder, args.mistake)
        return 0
    for request in sorted(args.folder.glob("*.npz")):
        with np.load(request) as data:
            camera = SimpleNamespace(
                width=int(data["width"]),
                height=int(data["height"]),
                projection=str(data["projection"]),
                **{k: (data[k] if data[k].ndim else float(data[k])) for k in FIELDS},
            )
            for label, mistake in MISTAKES.items():
                np.save(
                    args.folder / f"{request.stem}.{label}.npy",
                    render_depth(data["p_world"], data["triangles"], camera, mistake),
                )
    return 0


if __name__ == "__main__":
    sys.exit(main())
