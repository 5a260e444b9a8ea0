"""crosscheck --hidden-lines, --cull backface, --style shaded and scenes of several objects.

Every bound below is the derived one of oracles/tolerances.py (the numbers in
comments are measured, core against pyrender/OSMesa on this machine's llvmpipe).
"""

import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
from helpers import run_crosscheck as run
from wirecheck.core.scene.frames import SceneRenderer
from wirecheck.oracles import cli, tolerances
from wirecheck.oracles.candidates.core_candidate import CoreCandidate, RenderMode
from wirecheck.oracles.runner import run_crosscheck

ROOT = Path(__file__).resolve().parent.parent
USER = ROOT / "tests" / "data" / "user_projector.py"


@pytest.fixture(scope="module")
def icosphere(tmp_path_factory):
    """An icosphere (subdivision 2: 162 vertices, 320 triangles) as an .obj file."""
    trimesh = pytest.importorskip("trimesh")
    path = tmp_path_factory.mktemp("mesh") / "icosphere.obj"
    trimesh.creation.icosphere(2).export(str(path))
    return path


def _load(name_or_path):
    from wirecheck.core.scene.files import load_scene

    return load_scene(str(name_or_path))


# ---------------------------------------------------------------- shaded


def _shaded_frame(iou, union, depth_px, depth_max, depth_mean, bound, faces=0, faces_inside=0):
    return {
        "silhouette_iou": iou,
        "silhouette_union_px": union,
        "silhouette_mismatch_inside": 0,
        "depth_pixels": depth_px,
        "depth_max_error": depth_max,
        "depth_mean_error": depth_mean,
        "depth_error_bound": bound,
        "depth_error_ratio": None if depth_max is None else depth_max / bound,
        "face_disagreements": faces,
        "face_disagreements_inside": faces_inside,
    }


def test_shaded_summary_pools_the_frames():
    from wirecheck.oracles.judge.verdict import shaded_summary

    # no shaded frame: nothing compared, so nothing disagrees (zeros, no depth, no IoU)
    empty = shaded_summary([], None)
    assert (empty["face_disagreements"], empty["face_disagreements_inside"], empty["depth_pixels"]) == (0, 0, 0)
    assert empty["silhouette_iou"] is None and empty["depth_max_error"] is None
    # three frames by hand: frame 3 has no depth compared (None); frames 1 and 2 tie on the depth error
    # ratio (0.5 = 1e-3 / 2e-3 = 2e-3 / 4e-3), so the worst depth frame is the first of them, 1, as the
    # worst vertex and pixel frames are; the mean depth error is per pixel over both frames:
    # (10 x 1e-4 + 30 x 5e-4) / 40 = 4e-4; the gated IoU leaves out frame 2 (union 100 < MIN_IOU_UNION_PX)
    frames = [
        (1, _shaded_frame(0.98, 900, 10, 1e-3, 1e-4, 2e-3, faces=4, faces_inside=1)),
        (2, _shaded_frame(0.50, 100, 30, 2e-3, 5e-4, 4e-3, faces=2)),
        (3, _shaded_frame(0.97, 800, 0, None, None, 1e-3)),
    ]
    out = shaded_summary(frames, ((0.9, 0.9), 2))
    assert out["depth_worst_frame"] == 1 and out["depth_error_ratio"] == pytest.approx(0.5, rel=1e-12)
    assert out["depth_max_error"] == pytest.approx(2e-3, rel=1e-12)  # the largest error, frame 2's
    assert out["depth_error_bound"] == pytest.approx(4e-3, rel=1e-12)  # and its own bound
    assert out["depth_mean_error"] == pytest.approx(4e-4, rel=1e-12) and out["depth_pixels"] == 40
    assert out["silhouette_iou"] == 0.50 and out["silhouette_iou_gated"] == 0.97
    assert (out["face_disagreements"], out["face_disagreements_inside"]) == (6, 1)
    assert out["worst_pixel_frame"] == 2


def test_shaded_cube_and_icosphere_pass_perspective_and_orthographic(tmp_path, icosphere):
    code, report, out = run(
        tmp_path,
        "--style",
        "shaded",
        "--scene",
        "cube",
        "--scene",
        str(icosphere),
        "--frames",
        "4",
        "--cases",
        "oblique_roll,orthographic",
    )
    assert code == 0, [c["reasons"] for c in report["cases"]]
    assert (report["style"], report["hidden_lines"], report["cull"]) == ("shaded", False, "none")
    assert report["tolerances"]["min_silhouette_iou"] == tolerances.MIN_SILHOUETTE_IOU
    assert [(c["scene"], c["camera"]) for c in report["cases"]] == [
        ("cube", "oblique_roll"),
        ("cube", "orthographic"),
        ("icosphere", "oblique_roll"),
        ("icosphere", "orthographic"),
    ]
    for case in report["cases"]:
        # IoU: measured 1.0 in all but 12 of 504 frames (min 0.99982); bound 0.995 (tolerances.py)
        assert case["silhouette_iou"] >= tolerances.MIN_SILHOUETTE_IOU
        # depth: per pixel |z_core - z_pyrender| <= 4 steps + slope/256 + 16 eps32 z;
        # measured up to 0.48 of it (tolerances.py)
        assert case["depth_error_ratio"] <= 1.0
        assert case["depth_max_error"] <= case["depth_error_bound"]
        # the comparison is not vacuous: thousands of interior pixels a frame
        assert case["depth_pixels"] > 4 * 5000
        assert case["pixel_f1_0px"] is None and case["max_vertex_error_px"] < 1e-9
        # every checked frame (4) carries its own shaded scores, each a real comparison
        assert [f["frame"] for f in case["per_frame"]] == [1, 2, 3, 4]
        for f in case["per_frame"]:
            assert set(f) >= {"silhouette_iou", "depth_max_error", "depth_error_ratio"}
            assert f["silhouette_iou"] >= tolerances.MIN_SILHOUETTE_IOU and 0.0 <= f["depth_error_ratio"] <= 1.0
            assert f["depth_pixels"] > 5000
    ortho = report["cases"][1]
    assert ortho["camera_spec"]["projection"] == "orthographic"
    # orthographic: window depth is linear, one 24-bit step is (far - near) / (2^24 - 1) =
    # 9.9 r / 16777215 ~ 1e-6 for the cube (r = sqrt 3): errors stay at a few 1e-5 at most
    assert ortho["depth_max_error"] < 1e-4
    md = (out / "report.md").read_text()
    assert "Drawing: style = shaded, hidden_lines = false, cull = none" in md
    assert "| scene | camera | max vertex err (px) | silhouette IoU |" in md


@dataclass(frozen=True)
class DeeperCore(CoreCandidate):
    """A fault: the shaded depth is 1% too large."""

    def shade(self, *args):
        return 1.01 * super().shade(*args)


@dataclass(frozen=True)
class MirroredCore(CoreCandidate):
    """A fault: the shaded image is mirrored left-right."""

    def shade(self, *args):
        return super().shade(*args)[:, ::-1]


def test_injected_shading_faults_are_caught():
    cube = _load("cube")
    shaded = RenderMode(style="shaded")
    report, _ = run_crosscheck(
        [cube], DeeperCore(), frames=3, case_names=["oblique_roll", "orthographic"], mode=shaded, animation=False
    )
    for case in report["cases"]:
        assert case["verdict"] == "fail" and "depth error" in " ".join(case["reasons"])
        # 0.01 z against a bound of ~1e-4 at z ~ 5 (a few 24-bit steps of ~1e-5 plus the slope term):
        # hundreds of times over; 10 is a safe floor
        assert case["depth_error_ratio"] > 10
        assert case["silhouette_iou"] >= tolerances.MIN_SILHOUETTE_IOU  # the silhouette is right
    report, _ = run_crosscheck(
        [cube], MirroredCore(), frames=3, case_names=["oblique_roll"], mode=shaded, animation=False
    )
    case = report["cases"][0]
    assert case["verdict"] == "fail"
    reasons = " ".join(case["reasons"])
    assert case["silhouette_iou"] < tolerances.MIN_SILHOUETTE_IOU and "silhouette IoU" in reasons
    # a mirror misplaces whole regions, not boundary pixels
    assert case["silhouette_mismatch_inside"] > 1000 and "inside its silhouette" in reasons


def test_faceless_scene_is_noted_and_vacuous_when_shaded(tmp_path):
    wire = tmp_path / "wire.scene"  # the pyramid's edges, without faces
    wire.write_text(
        "v -1 -1 -1\nv 1 -1 -1\nv 1 -1 1\nv -1 -1 1\nv 0 1 0\ne 0 1\ne 1 2\ne 2 3\ne 3 0\ne 0 4\ne 1 4\ne 2 4\ne 3 4\n"
    )
    # shaded, no faces: nothing is shaded on either side, so the pixel level compared nothing (oracles.judge.gate)
    code, report, out = run(tmp_path, "--style", "shaded", "--scene", str(wire), "--frames", "2", "--cases", "on_axis")
    case = report["cases"][0]
    assert code == 1 and case["verdict"] == "vacuous" and case["compared"]["pixels"] == 0
    assert "nothing compared at level pixels" in case["reasons"][0]
    assert case["note"] == "no faces: nothing to shade; only the vertices were checked"
    assert case["silhouette_iou"] is None and case["max_vertex_error_px"] < 1e-9
    code, report, out = run(
        tmp_path,
        "--style",
        "shaded",
        "--scene",
        str(wire),
        "--frames",
        "2",
        "--cases",
        "on_axis",
        "--allow-vacuous",
        name="allowed",
    )
    assert code == 0 and report["verdict"] == "pass" and report["cases"][0]["verdict"] == "vacuous"
    code, report, _ = run(
        tmp_path, "--hidden-lines", "--scene", str(wire), "--frames", "2", "--cases", "on_axis", name="hidden"
    )
    case = report["cases"][0]
    assert code == 0 and case["hidden_lines"] is False and case["pixel_f1_1px"] == 1.0
    assert case["note"].startswith("no faces: nothing hides or culls a line")


# ---------------------------------------------------------------- hidden lines and culling


@dataclass(frozen=True)
class SeeThroughCore(CoreCandidate):
    """A fault: asked for hidden lines, draws every line."""

    def draw_mode(self, points, edges, camera, model_matrix, faces, mode):
        return self.draw(points, edges, camera, model_matrix)


@dataclass(frozen=True)
class InsideOutCore(CoreCandidate):
    """A fault: the faces' winding reversed, so culling keeps the back faces."""

    def draw_mode(self, points, edges, camera, model_matrix, faces, mode):
        flipped = tuple(tuple(reversed(f)) for f in faces)
        return super().draw_mode(points, edges, camera, model_matrix, flipped, mode)


def test_core_case_fields_hidden_lines_only_where_asked_and_precision_from_dtype():
    # a case says whether faces hid its lines ("hidden_lines") only when it drew lines with hidden-line
    # removal asked for: a plain wireframe of the cube (which has faces) hides nothing and says nothing
    plain, _ = run_crosscheck([_load("cube")], CoreCandidate(), frames=2, case_names=["on_axis"], animation=False)
    hidden, _ = run_crosscheck(
        [_load("cube")],
        CoreCandidate(),
        frames=2,
        case_names=["on_axis"],
        animation=False,
        mode=RenderMode(hidden_lines=True),
    )
    assert plain["verdict"] == hidden["verdict"] == "pass"
    assert "hidden_lines" not in plain["cases"][0] and hidden["cases"][0]["hidden_lines"] is True
    # and a wireframe has no shaded fields (regions, faces, depth): no face was filled to compare them
    assert not {"silhouette_iou", "depth_max_error", "face_disagreements"} & (
        set(plain["cases"][0]) | set(hidden["cases"][0])
    )
    # core, no precision declared: judged at its own --dtype (float64 by default), and the report says so
    assert plain["cases"][0]["precision"] == {"judged_as": "float64", "source": "core --dtype", "returned": ["float64"]}


def test_hidden_lines_cube_from_an_oblique_camera(tmp_path):
    code, report, out = run(
        tmp_path, "--hidden-lines", "--scene", "cube", "--frames", "4", "--cases", "oblique_roll,orthographic"
    )
    assert code == 0, [c["reasons"] for c in report["cases"]]
    assert report["hidden_lines"] is True and report["style"] == "wireframe"
    for case in report["cases"]:
        assert case["hidden_lines"] is True
        # same minimums as plain wireframes; measured F1@1 = 1.0, F1@0 >= 0.9956 (tolerances.py)
        assert case["pixel_f1_1px"] >= tolerances.MIN_F1_1PX
        assert case["pixel_f1_0px"] >= tolerances.MIN_F1_0PX
    assert "hidden_lines = true" in (out / "report.md").read_text()
    # the oracle really hides lines: drawing all of them fails (from an oblique camera
    # 3 of the 12 edges of the cube are hidden in most frames)
    report, _ = run_crosscheck(
        [_load("cube")],
        SeeThroughCore(),
        frames=4,
        case_names=["oblique_roll"],
        mode=RenderMode(hidden_lines=True),
        animation=False,
    )
    assert report["cases"][0]["verdict"] == "fail"
    assert report["cases"][0]["pixel_f1_1px"] < 0.95


def test_culling_a_closed_mesh_changes_nothing_visible(icosphere):
    scenes = [_load("cube"), _load(icosphere)]
    cases = ["oblique_roll", "orthographic"]
    hidden, _ = run_crosscheck(
        scenes, CoreCandidate(), frames=3, case_names=cases, mode=RenderMode(hidden_lines=True), animation=False
    )
    culled, _ = run_crosscheck(
        scenes,
        CoreCandidate(),
        frames=3,
        case_names=cases,
        mode=RenderMode(hidden_lines=True, cull="backface"),
        animation=False,
    )
    assert hidden["verdict"] == culled["verdict"] == "pass"
    assert culled["cull"] == "backface"
    for a, b in zip(hidden["cases"], culled["cases"], strict=True):
        # closed meshes: back faces are behind front faces, so the culled hidden-line
        # picture is the hidden-line picture (the oracle's GL culling and its own
        # front-face test pick the same edges)
        assert b["pixel_f1_1px"] >= tolerances.MIN_F1_1PX and b["pixel_f1_0px"] >= tolerances.MIN_F1_0PX
        assert abs(a["pixel_f1_0px"] - b["pixel_f1_0px"]) < 0.005
    # culling without hidden lines: only edges of front faces are drawn, judged the same way
    wire, _ = run_crosscheck(
        scenes, CoreCandidate(), frames=3, case_names=cases, mode=RenderMode(cull="backface"), animation=False
    )
    assert wire["verdict"] == "pass"
    # a wrong front-face rule is caught
    bad, _ = run_crosscheck(
        scenes[:1],
        InsideOutCore(),
        frames=3,
        case_names=["oblique_roll"],
        mode=RenderMode(cull="backface"),
        animation=False,
    )
    assert bad["cases"][0]["verdict"] == "fail" and bad["cases"][0]["pixel_f1_1px"] < 0.9


# ---------------------------------------------------------------- several objects

TWO_OBJECTS = """\
# two cubes with different spins
name pair
object left
translate -1.5 0 0
scale 0.5
spin 0 1 0
v -1 -1 -1
v  1 -1 -1
v  1  1 -1
v -1  1 -1
v -1 -1  1
v  1 -1  1
v  1  1  1
v -1  1  1
f 0 3 2 1
f 4 5 6 7
f 0 1 5 4
f 3 7 6 2
f 0 4 7 3
f 1 2 6 5
object right
translate 1.5 0.2 0
scale 0.7
spin 2 0 1
v -1 -1 -1
v  1 -1 -1
v  1  1 -1
v -1  1 -1
v -1 -1  1
v  1 -1  1
v  1  1  1
v -1  1  1
f 0 3 2 1
f 4 5 6 7
f 0 1 5 4
f 3 7 6 2
f 0 4 7 3
f 1 2 6 5
"""


class RunFirstFrames(SceneRenderer):
    """A fault: the run's motion applied before each object's own (M_o @ M_run)."""

    def world_points(self, k):
        from wirecheck.core.transforms import apply

        scene = self.scene
        out = np.empty((len(scene.vertices), 3))
        m_run = self.motion.frame_matrix(k, self.frames)
        for o in scene.objects:
            rows = slice(o.vertex_start, o.vertex_stop)
            out[rows] = apply(o.motion.frame_matrix(k, self.frames) @ m_run, scene.vertices[rows])
        return out


@dataclass(frozen=True)
class RunFirstCore(CoreCandidate):
    """core with :class:`RunFirstFrames` setting up its frames."""

    def scene_frames(self, scene, motion, frames):
        return RunFirstFrames(scene, motion, frames, clip=self.clip, dtype=self.dtype, raster=self.raster)


def test_two_objects_with_their_own_spins_pass_at_level_pixels(tmp_path):
    path = tmp_path / "pair.scene"
    path.write_text(TWO_OBJECTS)
    scene = _load(path)
    assert len(scene.objects) == 2 and not scene.is_single_static
    code, report, _ = run(tmp_path, "--scene", str(path), "--frames", "4", "--cases", "oblique_roll,orthographic")
    assert code == 0, [c["reasons"] for c in report["cases"]]
    for case in report["cases"]:
        # world points: core.scene.model.world_points against scipy's M_run @ M_o, both float64
        assert case["max_vertex_error_px"] < 1e-9
        assert case["pixel_f1_1px"] >= tolerances.MIN_F1_1PX
    for mode in (RenderMode(hidden_lines=True), RenderMode(style="shaded")):
        rep, _ = run_crosscheck(
            [scene], CoreCandidate(), frames=3, case_names=["oblique_roll"], mode=mode, animation=False
        )
        assert rep["verdict"] == "pass", rep["cases"][0]["reasons"]
    # composing the motions in the wrong order is caught by the vertex check
    bad, _ = run_crosscheck([scene], RunFirstCore(), frames=4, case_names=["oblique_roll"], level="vertices")
    assert bad["cases"][0]["verdict"] == "fail" and bad["cases"][0]["max_vertex_error_px"] > 1.0


def test_one_static_object_keeps_the_single_object_path(tmp_path):
    # an explicit 'object' with no motion is the single-object scene: same records
    path = tmp_path / "cube1.scene"
    path.write_text((ROOT / "scenes" / "cube.scene").read_text().replace("name cube\n", "name cube\nobject cube\n"))
    one = _load(path)
    assert one.is_single_static
    args = dict(frames=3, case_names=["oblique_roll"], level="vertices")
    a, _ = run_crosscheck([_load("cube")], CoreCandidate(), **args)
    b, _ = run_crosscheck([one], CoreCandidate(), **args)
    assert a["cases"][0]["per_frame"] == b["cases"][0]["per_frame"]


# ---------------------------------------------------------------- options and workers


@pytest.mark.parametrize(
    "args, needle",
    [
        (["--style", "shaded", "--level", "vertices"], "--level vertices"),
        (["--hidden-lines", "--oracles", "opencv"], "--level vertices"),
        (["--style", "shaded", "--hidden-lines"], "a shaded frame has no lines"),
        (["--cull", "backface", "--candidate", f"{USER}:project"], "only projects points"),
        (["--hidden-lines", "--sweep"], "--sweep"),
        (["--style", "flat"], "--style"),
        (["--cull", "front"], "--cull"),
        (["--min-iou", "1.5"], "--min-iou"),
    ],
)
def test_bad_drawing_options_exit_2_with_one_line(tmp_path, capsys, args, needle):
    try:
        code = cli.main(["--report-dir", str(tmp_path / "r"), "--scene", "cube", *args])
    except SystemExit as exc:  # argparse choices
        code = exc.code
    err = capsys.readouterr().err
    assert code == 2
    assert err.count("\n") == 1 and needle in err and "Traceback" not in err, err
    assert not (tmp_path / "r").exists()


def test_run_crosscheck_refuses_modes_it_cannot_check():
    with pytest.raises(ValueError, match="level pixels"):
        run_crosscheck([_load("cube")], CoreCandidate(), frames=1, level="vertices", mode=RenderMode(style="shaded"))
    with pytest.raises(ValueError, match="only the core candidate"):
        run_crosscheck([_load("cube")], lambda p, c: p[:, :2], frames=1, mode=RenderMode(hidden_lines=True))
    with pytest.raises(ValueError):
        RenderMode(style="shaded", hidden_lines=True)


@pytest.mark.slow
def test_workers_get_the_drawing_mode(tmp_path):
    args = (
        "--style",
        "shaded",
        "--cull",
        "backface",
        "--scene",
        "cube",
        "--frames",
        "2",
        "--cases",
        "on_axis,oblique_roll",
    )
    code1, r1, out1 = run(tmp_path, *args, name="j1")
    code2, r2, out2 = run(tmp_path, *args, "--jobs", "2", name="j2")
    assert code1 == code2 == 0 and r2["timing"]["workers"] == 2
    assert r2["cull"] == "backface" and r2["cases"][0]["silhouette_iou"] is not None
    r1.pop("timing")
    r2.pop("timing")
    assert r1 == r2
    for name in ("report.md", "worst.gif", "vertex_error.png", "pixels.png"):
        assert (out1 / name).read_bytes() == (out2 / name).read_bytes(), name


def test_pyrender_depth_is_linear_camera_depth_in_both_projections():
    """The oracle's own depth: a plane at known depth, perspective and orthographic."""
    from wirecheck.core.camera import camera_z
    from wirecheck.oracles.references.pyrender_oracle import PyrenderOracle, depth_step

    quad = np.array([[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [1.0, 1.0, 0.0], [-1.0, 1.0, 0.0]])
    tris = np.array([[0, 1, 2], [0, 2, 3]])
    for cam in (
        camera_z(4.0, fov_y_deg=60, width=160, height=120, near=0.5, far=20.0),
        camera_z(4.0, projection="orthographic", ortho_height=3.0, width=160, height=120, near=0.5, far=20.0),
    ):
        with PyrenderOracle(cam.width, cam.height) as pr:
            covered, depth, ids = pr.render_faces(quad, tris, cam, with_ids=True)
            assert covered.sum() > 1000 and set(np.unique(ids)) <= {-1, 0, 1}
            # the plane z = 0 is at depth 4: within one 24-bit step plus float32 rounding
            err = np.abs(depth[covered] - 4.0).max()
            assert err <= float(depth_step(4.0, cam)) + 8 * np.finfo(np.float32).eps * 4.0, (cam.projection, err)
            assert (depth[~covered] == 0).all()
            # culling: the quad is counter-clockwise seen from +z, the camera's side: kept;
            # reversed, it is a back face and GL culls it
            assert pr.render_faces(quad, tris[:, ::-1], cam, cull=True)[0].sum() == 0
            assert pr.render_faces(quad, tris, cam, cull=True)[0].sum() == covered.sum()


if __name__ == "__main__":
    sys.exit(pytest.main([__file__, "-q"]))


def test_occlusion_boundary_and_interior_by_hand():
    from wirecheck.oracles.judge.metrics import interior, occlusion_boundary, shaded_scores

    # triangles 0 and 1 share vertices (one surface), 2 shares none (another object)
    tris = np.array([[0, 1, 2], [1, 2, 3], [10, 11, 12]])
    ids = np.array([[0, 0, 1, 1, 2, 2], [0, 0, 1, 1, 2, 2], [-1, -1, -1, -1, -1, -1]])
    b = occlusion_boundary(ids, tris)
    # only the 1|2 seam (columns 3 and 4), on both sides; the 0|1 seam is continuous
    assert b.tolist() == [[False, False, False, True, True, False]] * 2 + [[False] * 6]
    cov = ids >= 0
    # erosion: neighbours outside the image count as covered, the empty row does not
    assert interior(cov).tolist() == [[True] * 6, [False] * 6, [False] * 6]
    depth = np.where(cov, 2.0, np.inf)
    s = shaded_scores(depth, cov, np.where(cov, 2.0 + 1e-3, 0.0), np.full(ids.shape, 1e-2), exclude=b)
    assert s["silhouette_iou"] == 1.0 and s["depth_pixels"] == 4  # row 0 minus the seam
    assert s["depth_max_error"] == pytest.approx(1e-3) and s["depth_error_ratio"] == pytest.approx(0.1)
    assert shaded_scores(np.full((2, 2), np.inf), np.zeros((2, 2), bool), np.zeros((2, 2)))["silhouette_iou"] == 1.0
