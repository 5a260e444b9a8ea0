"""VTK judged by its own frames: a VTK user's offscreen render of an exported job, end to end.

``tests/clients/vtk_frames.py`` draws the job as a VTK user would (a vtkCamera
from the job's camera fields: position, focal point, view up, vertical view
angle, clipping range, parallel scale; the model matrix as the actor's user
matrix; an offscreen window without multisampling, its rows flipped), and
``crosscheck --candidate-frames`` judges the PNGs. A correct set-up passes;
each typical mistake is named from the images alone:

- the vertical FOV given as VTK's horizontal view angle
  (``SetUseHorizontalViewAngle(1)``): ``fov_mismatch`` on perspective cases;
  a parallel projection has no view angle, so the orthographic case passes;
- no row flip on read-back: ``mirror_vertical`` (``ambiguous`` between the two
  mirrors where the view is centrally symmetric: the cube, orthographic).

The full job (21 cases) is measured by benchmarks/measure_vtk_frames.py (docs/frames.md, "VTK, measured").
Needs vtk (dev extras) and an offscreen GL (EGL or OSMesa); skipped without them unless
WIRECHECK_REQUIRE_EGL=1 (.ci/run), where that is a failure.
"""

from __future__ import annotations

import math
from pathlib import Path

import helpers  # tests/ is on sys.path (rootdir conftest)
import pytest
from wirecheck.oracles.cli import main

pytestmark = pytest.mark.slow  # three renderer runs and three judgements

SCRIPT = Path(__file__).parent / "clients" / "vtk_frames.py"
# cube and pyramid, three cases (4:3 oblique with roll, portrait 2:3, orthographic), frames 1 and 4 of 6
ARGS = [
    "--scene",
    "cube",
    "--scene",
    "pyramid",
    "--cases",
    "oblique_roll,non_square,orthographic",
    "--frames",
    "6",
    "--every",
    "3",
]
PROBE = (
    "import vtk; w = vtk.vtkRenderWindow(); w.SetOffScreenRendering(1); w.SetSize(8, 8); "
    "w.AddRenderer(vtk.vtkRenderer()); w.Render()"
)


@pytest.fixture(scope="module")
def job_dir(tmp_path_factory) -> Path:
    helpers.require_renderer(PROBE, "VTK offscreen")
    path = tmp_path_factory.mktemp("vtk") / "job"
    assert main(["export", str(path)] + ARGS) == 0
    return path


def _render_and_judge(job_dir: Path, tmp_path: Path, *mistake: str) -> tuple[int, dict]:
    return helpers.draw_and_judge(SCRIPT, job_dir, tmp_path, *mistake)


def _by_case(report: dict) -> dict:
    return {(c["scene"], c["camera"]): c for c in report["cases"]}


def test_vtk_correct_setup_passes(job_dir, tmp_path, capsys):
    rc, report = _render_and_judge(job_dir, tmp_path)
    assert rc == 0, capsys.readouterr().out
    for key, c in _by_case(report).items():
        assert c["verdict"] == "pass" and c["faults"] == [], (key, c["faults"])
        assert c["line_style"]["style"] == "aliased", key
        # VTK's lines on Mesa pick the oracle's pixels (pyrender, also Mesa): every drawn pixel next to an
        # oracle line pixel and back (1 px), and at 0 px within the default gate of 0.98 (measured
        # 0.9991-1.0 over the 21 cases of the bundled job, benchmarks/measure_vtk_frames.py)
        assert c["pixel_f1_1px"] == 1.0, key
        assert c["pixel_f1_0px"] >= 0.98, (key, c["pixel_f1_0px"])


def test_vtk_horizontal_view_angle_is_a_fov_mismatch(job_dir, tmp_path):
    rc, report = _render_and_judge(job_dir, tmp_path, "--mistake", "horizontal_fov")
    assert rc == 1
    for key, c in _by_case(report).items():
        if key[1] == "orthographic":  # parallel projection: VTK's view angle is not used
            assert c["verdict"] == "pass", (key, c["faults"])
            continue
        assert c["verdict"] == "fail" and [f["name"] for f in c["faults"]] == ["fov_mismatch"], (key, c["faults"])
        spec = c["camera_spec"]
        # the angle taken as horizontal: tan(v/2) = tan(fov/2) H / W, the FOV the image implies (to 0.5 deg,
        # a 1 % scale at these FOVs, far inside the 25-50 % of the mistake)
        expected = math.degrees(
            2 * math.atan(math.tan(math.radians(spec["fov_y_deg"]) / 2) * spec["height"] / spec["width"])
        )
        assert c["faults"][0]["implied_fov_deg"] == pytest.approx(expected, abs=0.5), (key, c["faults"][0])


def test_vtk_without_the_row_flip_is_a_vertical_mirror(job_dir, tmp_path):
    rc, report = _render_and_judge(job_dir, tmp_path, "--mistake", "no_flip")
    assert rc == 1
    by = _by_case(report)
    # the cube seen orthographically is centrally symmetric: an up-down mirror is also a left-right one
    symmetric = by.pop(("cube", "orthographic"))
    assert [f["name"] for f in symmetric["faults"]] == ["ambiguous"], symmetric["faults"]
    assert sorted(symmetric["faults"][0]["alternatives"]) == ["mirror_horizontal", "mirror_vertical"]
    for key, c in by.items():
        assert c["verdict"] == "fail" and [f["name"] for f in c["faults"]] == ["mirror_vertical"], (key, c["faults"])
