"""A renderer of a wirecheck frames job written as a VTK user would: an offscreen vtkRenderWindow.

``python vtk_frames.py JOB [--mistake horizontal_fov|no_flip]``

For every case and frame listed in ``JOB/job.json`` it builds a vtkPolyData
of the OBJ's edges (one line cell per edge), an actor of it (white, 1 px, no
lighting: ambient 1, diffuse 0) posed by the camera JSON's ``model_matrix``
as the actor's user matrix, and a vtkCamera from the camera's fields:
position, focal point = position + forward, view up, ``SetViewAngle(fov_y_deg)``
(VTK's view angle is vertical by default), clipping range (near, far);
orthographic cameras as parallel projection with ``SetParallelScale`` half
the ortho height. The principal point is the image centre in every bundled
case (VTK's too); a job with intrinsics off centre would need
``SetWindowCenter``, not done here. The window is offscreen, of the camera's
size, without multisampling (VTK falls back to EGL or OSMesa where there is
no display); ``vtkWindowToImageFilter`` reads it back bottom row first, so
the rows are flipped before Pillow writes the PNG. Only numpy, vtk, Pillow
and the job's files: nothing of wirecheck.

Typical mistakes, one per run:

- ``horizontal_fov``: ``SetUseHorizontalViewAngle(1)`` with the same angle
  (the vertical FOV given as the horizontal one);
- ``no_flip``: the rows written as VTK reads them, bottom first.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
from job_files import job_frames

MISTAKES = ("horizontal_fov", "no_flip")


def poly_lines(p_model: np.ndarray, edges: np.ndarray):
    """A vtkPolyData of the points and one two-point line cell per edge."""
    import vtk
    from vtk.util.numpy_support import numpy_to_vtk

    points = vtk.vtkPoints()
    points.SetData(numpy_to_vtk(np.ascontiguousarray(p_model, dtype=np.float64), deep=True))
    lines = vtk.vtkCellArray()
    for i, j in edges:
        lines.InsertNextCell(2)
        lines.InsertCellPoint(int(i))
        lines.InsertCellPoint(int(j))
    poly = vtk.vtkPolyData()
    poly.SetPoints(points)
    poly.SetLines(lines)
    return poly


def set_camera(camera, cam: dict, mistake: str | None) -> None:
    """Pose and lens of a vtkCamera from the job's camera fields."""
    pos = np.array(cam["position"], dtype=float)
    camera.SetPosition(*pos)
    camera.SetFocalPoint(*(pos + np.array(cam["forward"], dtype=float)))
    camera.SetViewUp(*cam["up"])
    camera.SetClippingRange(cam["near"], cam["far"])
    if cam["projection"] == "orthographic":
        camera.ParallelProjectionOn()
        camera.SetParallelScale(cam["ortho_height"] / 2.0)  # VTK's scale: half the height
    else:
        camera.ParallelProjectionOff()
        camera.SetViewAngle(cam["fov_y_deg"])  # vertical unless told otherwise
        camera.SetUseHorizontalViewAngle(1 if mistake == "horizontal_fov" else 0)


def main(argv=None) -> int:
    import vtk
    from PIL import Image
    from vtk.util.numpy_support import vtk_to_numpy

    ap = argparse.ArgumentParser()
    ap.add_argument("job")
    ap.add_argument("--mistake", choices=MISTAKES)
    args = ap.parse_args(argv)
    windows = {}  # (w, h): (window, renderer, reader)
    for c, png, v, e, cam_json, model in job_frames(Path(args.job)):
        cam = cam_json["camera"]
        w, h = cam["width"], cam["height"]
        if (w, h) not in windows:
            win = vtk.vtkRenderWindow()
            win.SetOffScreenRendering(1)
            win.SetMultiSamples(0)
            win.SetSize(w, h)
            ren = vtk.vtkRenderer()
            ren.SetBackground(0.0, 0.0, 0.0)
            win.AddRenderer(ren)
            grab = vtk.vtkWindowToImageFilter()
            grab.SetInput(win)
            grab.SetInputBufferTypeToRGB()
            grab.ReadFrontBufferOff()
            windows[w, h] = (win, ren, grab)
        win, ren, grab = windows[w, h]
        mapper = vtk.vtkPolyDataMapper()
        mapper.SetInputData(poly_lines(v, e))
        actor = vtk.vtkActor()
        actor.SetMapper(mapper)
        prop = actor.GetProperty()
        prop.SetColor(1.0, 1.0, 1.0)
        prop.SetLineWidth(1.0)
        prop.LightingOff()
        prop.SetAmbient(1.0)
        prop.SetDiffuse(0.0)
        prop.SetSpecular(0.0)
        if model:
            m = vtk.vtkMatrix4x4()
            m.DeepCopy(np.asarray(cam_json["model_matrix"], dtype=float).ravel().tolist())  # row-major
            actor.SetUserMatrix(m)
        ren.RemoveAllViewProps()
        ren.AddActor(actor)
        set_camera(ren.GetActiveCamera(), cam, args.mistake)
        win.Render()
        grab.Modified()
        grab.Update()
        out = grab.GetOutput()
        gw, gh, _ = out.GetDimensions()
        rgb = vtk_to_numpy(out.GetPointData().GetScalars()).reshape(gh, gw, -1)[:, :, :3]
        img = rgb if args.mistake == "no_flip" else rgb[::-1]  # VTK's rows run bottom up
        png.parent.mkdir(parents=True, exist_ok=True)
        Image.fromarray(np.ascontiguousarray(img, dtype=np.uint8)).save(png)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
