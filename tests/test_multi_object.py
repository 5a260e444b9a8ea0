"""Scenes of several objects: the format, world_points, object culling, winding, errors."""

import json
from pathlib import Path

import numpy as np
import pytest
from helpers import run_renderer as run
from numpy.testing import assert_allclose, assert_array_equal
from PIL import Image
from wirecheck.core.errors import InputError
from wirecheck.core.scene.files import SCENE_DIR, builtin_names, example_names, load_scene, parse_scene_text
from wirecheck.core.scene.model import SceneObject, object_matrix, world_points
from wirecheck.core.transforms import Motion

EPS = np.finfo(np.float64).eps


def reference_parse(text):
    """The single-object format as it was before objects: v/e/f lines only (an independent reading)."""
    v, e, f = [], [], []
    for raw in text.splitlines():
        parts = raw.split("#", 1)[0].split()
        if not parts or parts[0] == "name":
            continue
        if parts[0] == "v":
            v.append([float(t) for t in parts[1:]])
        elif parts[0] == "e":
            e.append(tuple(sorted(int(t) for t in parts[1:])))
        elif parts[0] == "f":
            idx = [int(t) for t in parts[1:]]
            f.append(tuple(idx))
            e += [tuple(sorted((idx[k], idx[(k + 1) % len(idx)]))) for k in range(len(idx))]
    return np.array(v, dtype=np.float64).reshape(-1, 3), sorted(set(e)), tuple(f)


# ---- old files are one static object, arrays unchanged ------------------------------------


@pytest.mark.parametrize("name", builtin_names())
def test_builtin_scenes_parse_to_the_same_arrays(name):
    s = load_scene(name)
    v, e, f = reference_parse((SCENE_DIR / f"{name}.scene").read_text())
    assert_array_equal(s.vertices, v)
    assert s.edges.tolist() == [list(p) for p in e]
    assert s.faces == f
    assert s.objects == (SceneObject(name, 0, len(v), Motion((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), 1.0)),)
    assert s.is_single_static


def test_examples_are_not_builtins():
    # crosscheck's default run takes builtin_names(): the multi-object example is not among them
    assert "orrery" in example_names() and "orrery" not in builtin_names()
    s = load_scene("orrery")
    assert s.source == "scenes/examples/orrery.scene"
    assert [o.name for o in s.objects] == ["sun", "planet", "moon"]
    # 8 + 5 + 6 vertices; 12 + 8 + 9 edges; 6 + 5 + 5 faces
    assert (len(s.vertices), len(s.edges), len(s.faces)) == (19, 29, 16)
    assert not s.is_single_static
    assert s.winding_note is None


TWO = """
name two
object a
v 1 0 0
v 0 1 0
e 0 1
object b
translate 3 0 0
spin 0 0 1
scale 2
v 1 0 0
v 0 0 1
v 0 1 0
f 0 1 2
"""


def test_two_objects_concatenated_with_offsets():
    s = parse_scene_text(TWO, "two.scene")
    assert [(o.name, o.vertex_start, o.vertex_stop) for o in s.objects] == [("a", 0, 2), ("b", 2, 5)]
    assert s.objects[1].motion == Motion(turns=(0.0, 0.0, 1.0), offset=(3.0, 0.0, 0.0), scale=2.0)
    assert_array_equal(s.vertices, [[1, 0, 0], [0, 1, 0], [1, 0, 0], [0, 0, 1], [0, 1, 0]])
    # b's local face (0 1 2) is global (2 3 4); its boundary edges join the edge set
    assert s.faces == ((2, 3, 4),)
    assert s.edges.tolist() == [[0, 1], [2, 3], [2, 4], [3, 4]]
    assert s.object_edge_ranges() == [(0, 1), (1, 4)]
    assert s.object_face_ranges() == [(0, 0), (0, 1)]
    # radius bound over every frame: max(|0| + 1*1, |3| + 2*1) = 5
    assert s.radius == 5.0


def test_world_points_hand_derived():
    s = parse_scene_text(TWO, "two.scene")
    # frame 2 of 4: t = 1/4. Object b: one turn about Z over the run -> a quarter turn,
    # Rz(90) (x, y, z) -> (-y, x, z); then scale 2, offset (3, 0, 0):
    #   (1,0,0) -> 2*(0,1,0) + (3,0,0) = (3, 2, 0);  (0,0,1) -> (3, 0, 2);  (0,1,0) -> 2*(-1,0,0) + 3 = (1, 0, 0)
    # (the scale applies before the rotation: T Rz S). Object a does not move.
    still = Motion(turns=(0.0, 0.0, 0.0))
    p = world_points(s, still, 2, 4)
    # cos(pi/2) = 6e-17, products with 2 and sums with 3: a few eps of 3
    assert_allclose(p, [[1, 0, 0], [0, 1, 0], [3, 2, 0], [3, 0, 2], [1, 0, 0]], rtol=0, atol=4 * EPS * 3)
    # Now the run turns a quarter about Y (turns 0,1,0 at t = 1/4) after the objects' own
    # motion: Ry(90) (x, y, z) -> (z, y, -x). M_run @ M_o:
    #   a: (1,0,0) -> (0,0,-1), (0,1,0) -> (0,1,0); b: (3,2,0) -> (0,2,-3), (3,0,2) -> (2,0,-3), (1,0,0) -> (0,0,-1)
    # (the other order, M_o @ M_run, would put b's first vertex at Rz Ry (1,0,0)*2 + (3,0,0) = (3,0,-2)).
    run_motion = Motion(turns=(0.0, 1.0, 0.0))
    p = world_points(s, run_motion, 2, 4)
    want = [[0, 0, -1], [0, 1, 0], [0, 2, -3], [2, 0, -3], [0, 0, -1]]
    assert_allclose(p, want, rtol=0, atol=8 * EPS * 3)
    assert_allclose(
        object_matrix(s.objects[1], run_motion, 2, 4),
        run_motion.frame_matrix(2, 4) @ s.objects[1].motion.frame_matrix(2, 4),
        rtol=0,
        atol=0,
    )
    # frame 1 is the rest pose of everything: only b's scale and offset apply
    assert_array_equal(world_points(s, run_motion, 1, 4), [[1, 0, 0], [0, 1, 0], [5, 0, 0], [3, 0, 2], [3, 2, 0]])


def test_implicit_object_before_the_first_object_line():
    text = "name thing\nv 0 0 0\nv 1 0 0\ne 0 1\nobject extra\ntranslate 0 5 0\nv 0 0 0\nv 0 0 1\ne 0 1\n"
    s = parse_scene_text(text, "t.scene")
    assert [(o.name, o.vertex_start, o.vertex_stop) for o in s.objects] == [("thing", 0, 2), ("extra", 2, 4)]
    assert s.edges.tolist() == [[0, 1], [2, 3]]
    # a lone 'translate' on an old-style file makes it one object that moves
    s2 = parse_scene_text("v 0 0 0\nv 1 0 0\ne 0 1\ntranslate 1 2 3\n", "m.scene")
    assert len(s2.objects) == 1 and not s2.is_single_static
    assert_array_equal(world_points(s2, Motion(turns=(0, 0, 0)), 1, 1), [[1, 2, 3], [2, 2, 3]])


def test_mesh_object_relative_to_the_scene_file(tmp_path):
    (tmp_path / "meshes").mkdir()
    (tmp_path / "meshes" / "tri.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    scene = tmp_path / "m.scene"
    scene.write_text("object first\nv 5 5 5\nv 6 6 6\ne 0 1\nobject tri\nmesh meshes/tri.obj\ntranslate 0 0 -1\n")
    s = load_scene(str(scene))
    assert_array_equal(s.vertices, [[5, 5, 5], [6, 6, 6], [0, 0, 0], [1, 0, 0], [0, 1, 0]])
    assert s.faces == ((2, 3, 4),)
    assert s.edges.tolist() == [[0, 1], [2, 3], [2, 4], [3, 4]]
    assert s.objects[1].motion.offset == (0.0, 0.0, -1.0)


# ---- bad object files: one line, file:line, the value --------------------------------------

BAD = [
    ("unknown keyword", "object a\nv 0 0 0\nrotate 1 0 0\n", 3, "'rotate'"),
    (
        "index out of range within an object",
        "object a\nv 0 0 0\nv 1 0 0\nobject b\nv 0 0 0\nv 1 1 1\ne 0 2\n",
        7,
        "index 2",
    ),
    ("duplicate object name", "object a\nv 0 0 0\nobject b\nobject a\n", 4, "'a'"),
    ("name clash with the implicit object", "name s\nv 0 0 0\nobject s\nv 1 1 1\n", 3, "'s'"),
    ("non-finite translate", "object a\ntranslate 0 inf 0\n", 2, "'inf'"),
    ("non-finite spin", "object a\nspin nan 0 0\n", 2, "'nan'"),
    ("non-finite scale", "object a\nscale -Infinity\n", 2, "'-Infinity'"),
    ("zero scale", "object a\nscale 0\n", 2, "'0'"),
    ("short translate", "object a\ntranslate 1 2\n", 2, "translate '1 2'"),
    ("two translates", "object a\ntranslate 1 2 3\ntranslate 1 2 3\n", 3, "'translate'"),
    ("mesh file missing", "object a\nmesh nothere.obj\n", 2, "'nothere.obj'"),
    ("mesh with a wrong suffix", "object a\nmesh x.txt\n", 2, "'x.txt'"),
    ("v after mesh", "object a\nmesh m.obj\nv 0 0 0\n", 3, "'v 0 0 0'"),
    ("bad object name", "object a/b\n", 1, "'a/b'"),
]


@pytest.mark.parametrize("text,lineno,value", [b[1:] for b in BAD], ids=[b[0] for b in BAD])
def test_bad_object_file(tmp_path, text, lineno, value):
    (tmp_path / "m.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    p = tmp_path / "bad.scene"
    p.write_text(text)
    with pytest.raises(InputError) as info:
        load_scene(str(p))
    msg = str(info.value)
    assert msg.startswith(f"{p}:{lineno}: "), msg
    assert value in msg and "expected" in msg and "\n" not in msg


def test_bad_mesh_inside_a_scene_names_both_files(tmp_path):
    (tmp_path / "broken.obj").write_text("v 0 0 0\nv 1 zz 0\n")
    p = tmp_path / "s.scene"
    p.write_text("object a\nmesh broken.obj\n")
    with pytest.raises(InputError) as info:
        load_scene(str(p))
    msg = str(info.value)
    assert msg.startswith(f"{p}:2: mesh 'broken.obj': ") and "broken.obj:2:" in msg and "'zz'" in msg


def test_bad_object_file_through_the_cli(tmp_path):
    p = tmp_path / "bad.scene"
    p.write_text("object a\nv 0 0 0\nobject a\n")
    rc, out, err = run(["--scene", str(p), "--frames", "1"], tmp_path / "out")
    assert (rc, out) == (2, "")
    assert (
        err
        == f"renderer: error: {p}:3: object 'a': expected a new name (line 1 already starts an object of that name)\n"
    )


# ---- the renderer with several objects ------------------------------------------------------

CUBE_FACES = "f 0 3 2 1\nf 4 5 6 7\nf 0 1 5 4\nf 3 7 6 2\nf 0 4 7 3\nf 1 2 6 5\n"
CUBE_V = "".join(f"v {x} {y} {z}\n" for z in (-1, 1) for x, y in ((-1, -1), (1, -1), (1, 1), (-1, 1)))


def culling_scene(tmp_path):
    """Three unit cubes: one at the origin, one behind the camera, one far off to the side."""
    text = "name three\n"
    for name, offset in (("front", "0 0 0"), ("behind", "0 0 10"), ("aside", "40 0 0")):
        text += f"object {name}\ntranslate {offset}\nspin 0 1 0\n{CUBE_V}{CUBE_FACES}"
    p = tmp_path / "three.scene"
    p.write_text(text)
    return p


@pytest.mark.parametrize("extra", [[], ["--cull", "backface", "--hidden-lines"]], ids=["wireframe", "cull+hidden"])
def test_object_culling_counts_and_never_changes_the_picture(tmp_path, extra):
    scene = culling_scene(tmp_path)
    # camera at z = 4 looking down -Z, fov 60, 160x120: the cube 'behind' (centre z = 10, bounding
    # radius sqrt 3) is entirely behind the near plane (z_cam = 4 - 10 +- 1.74 < 0.1); 'aside' at
    # x = 40, depth 4: the image's right edge is at x = 4 tan(30) 4/3 = 3.08, so it is outside the
    # right plane by far more than its radius. Only 'front' can be drawn.
    args = [
        "--scene",
        str(scene),
        "--frames",
        "3",
        "--camera-z",
        "4",
        "--width",
        "160",
        "--height",
        "120",
        "--spin",
        "0,0,0",
        "--format",
        "png,ascii",
    ] + extra
    rc1, out1, err1 = run(args, tmp_path / "on")
    rc2, out2, err2 = run(args + ["--no-object-culling"], tmp_path / "off")
    assert (rc1, err1, rc2, err2) == (0, "", 0, "")
    assert "objects_culled=2" in out1 and "objects_culled" not in out2
    on = json.loads((tmp_path / "on" / "three-report.json").read_text())
    off = json.loads((tmp_path / "off" / "three-report.json").read_text())
    for a, b in zip(on["frames"], off["frames"]):
        assert a.pop("objects_culled") == 2 and b.pop("objects_culled") is None
        if extra:
            # back faces are counted among the faces the pipeline gets: without object culling
            # also those of the 2 far cubes (at most 2 x 6 more)
            fa, fb = a.pop("faces_culled"), b.pop("faces_culled")
            assert fa <= fb <= fa + 12
            assert a["faces_total"] == 18
        assert a == b  # every other count (and vertex pixel) is the same
        # 'behind' has 8 vertices at depth < near; its 12 edges are all clipped
        assert (a["clipped"], a["clipped_edges"]) == (8, 12)
    assert on["summary"]["objects_culled"] == 6
    for k in (1, 2, 3):
        im_on = np.asarray(Image.open(tmp_path / "on" / "three-frames" / f"frame_{k:04d}.png").convert("L"))
        im_off = np.asarray(Image.open(tmp_path / "off" / "three-frames" / f"frame_{k:04d}.png").convert("L"))
        assert_array_equal(im_on, im_off)
        assert im_on.any()
        txt = f"frame_{k:04d}.txt"
        assert (tmp_path / "on" / "three-frames" / txt).read_bytes() == (
            tmp_path / "off" / "three-frames" / txt
        ).read_bytes()


def test_multi_object_frame_matches_world_points(tmp_path):
    # The renderer draws world_points with the identity: the JSON vertex pixels must be
    # the projection of each object's M_run(t) @ M_o(t) -- here built independently of
    # core, by scipy (oracles.references.faces) and projected by cv2.projectPoints. Two float64
    # pipelines: ~20 roundings of values <= 640 px, ~3e-12; 1e-9 px leaves margin.
    from wirecheck.core.camera import camera_z
    from wirecheck.oracles.references import faces as oface
    from wirecheck.oracles.references import opencv_oracle

    rc, _, err = run(["--scene", "orrery", "--frames", "4", "--camera-z", "8", "--spin", "0,1,0"], tmp_path)
    assert (rc, err) == (0, "")
    rep = json.loads((tmp_path / "orrery-report.json").read_text())
    s = load_scene("orrery")
    cam = camera_z(8.0, fov_y_deg=60.0, width=640, height=480)
    for k in (1, 3):
        p_world = oface.world_points(s, oface.object_matrices(s, (0.0, 1.0, 0.0), (k - 1) / 4))
        want = opencv_oracle.project(p_world, cam)
        assert_allclose(np.array(rep["frames"][k - 1]["vertices_px"], dtype=float), want, rtol=0, atol=1e-9)
    assert [o["name"] for o in rep["scene"]["objects"]] == ["sun", "planet", "moon"]


# ---- winding and faces ---------------------------------------------------------------------

BAD_WINDING = CUBE_V + CUBE_FACES.replace("f 1 2 6 5", "f 5 6 2 1")  # one face flipped


def test_inconsistent_winding_warns_and_refuses_backface_culling(tmp_path):
    p = tmp_path / "flip.scene"
    p.write_text(BAD_WINDING)
    s = load_scene(str(p))
    assert s.winding_note is not None and "\n" not in s.winding_note
    rc, out, err = run(["--scene", str(p), "--frames", "1"], tmp_path / "a")
    assert rc == 0 and err == f"renderer: warning: {p}: {s.winding_note}\n"
    rc, out, err = run(["--scene", str(p), "--frames", "1", "--cull", "backface"], tmp_path / "b")
    assert (rc, out) == (2, "") and len(err.splitlines()) == 1
    assert err.startswith("renderer: error: --cull backface: ") and s.winding_note in err
    assert not (tmp_path / "b").exists()


@pytest.mark.parametrize("flag", [["--hidden-lines"], ["--style", "shaded"], ["--cull", "backface"]])
def test_face_options_need_faces(tmp_path, flag):
    wire = tmp_path / "wire.scene"  # edges only: a wireframe with no faces
    wire.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\ne 0 1\ne 1 2\n")
    rc, out, err = run(["--scene", str(wire), "--frames", "1"] + flag, tmp_path / "o")
    assert (rc, out) == (2, "")
    assert err.startswith("renderer: error: ") and "has no faces" in err and len(err.splitlines()) == 1


def test_light_needs_shaded(tmp_path):
    rc, out, err = run(["--frames", "1", "--light", "1,0,0"], tmp_path / "o")
    assert (rc, out) == (2, "") and "--light '1,0,0' without --style shaded" in err


def test_cull_and_hidden_lines_fields(tmp_path):
    # The cube at rest, perspective camera at (0, 0, 4): a face is front-facing when the camera
    # is on the outer side of its plane. Front (z = +1, camera z 4 > 1): kept. Back (z = -1):
    # culled. Side x = +1: the camera's x = 0 < 1, inner side: culled; likewise the other 3
    # sides. So 6 faces, 5 culled.
    rc, out, err = run(
        ["--scene", "cube", "--frames", "1", "--spin", "0,0,0", "--cull", "backface", "--hidden-lines"], tmp_path
    )
    assert (rc, err) == (0, "")
    fr = json.loads((tmp_path / "cube-report.json").read_text())["frames"][0]
    assert (fr["faces_total"], fr["faces_culled"]) == (6, 5)
    # Edges are drawn only when one of their faces is kept: the front square's 4 edges. Nothing
    # is in front of the front face, so no line pixel is hidden.
    assert fr["hidden_pixels"] == 0
    assert "faces_culled=5" in out


def test_mirrored_object_is_culled_like_its_oracle(tmp_path, capsys):
    # Object "b" has scale -1 (determinant -1): its counter-clockwise faces turn
    # clockwise in the world. core draws multi-object scenes from world points
    # with an identity matrix, so core.scene.model.oriented_faces re-winds them; without
    # that, back-face culling would keep b's back faces and crosscheck (which
    # judges front faces from the geometry, oracles/references/faces.py) would fail.
    from wirecheck.oracles.cli import main

    cube = (Path(__file__).resolve().parent.parent / "scenes" / "cube.scene").read_text()
    body = "\n".join(line for line in cube.splitlines() if line.split("#")[0].strip().startswith(("v", "f")))
    text = (
        f"object a\ntranslate -1.5 0 0\nscale 0.5\n{body}\n"
        f"object b\ntranslate 1.5 0 0\nscale -0.5\nspin 0 1 0\n{body}\n"
    )
    path = tmp_path / "mirror.scene"
    path.write_text(text)
    from wirecheck.core.scene.files import load_scene
    from wirecheck.core.scene.model import oriented_faces
    from wirecheck.core.transforms import Motion

    scene = load_scene(str(path))
    faces = oriented_faces(scene, Motion())
    n_a = len(scene.faces) // 2
    assert faces[:n_a] == scene.faces[:n_a]  # a: unchanged
    assert faces[n_a:] == tuple(tuple(reversed(f)) for f in scene.faces[n_a:])  # b: re-wound
    rc = main(
        [
            "--scene",
            str(path),
            "--cases",
            "on_axis,oblique_roll",
            "--frames",
            "3",
            "--cull",
            "backface",
            "--hidden-lines",
            "--report-dir",
            str(tmp_path / "rep"),
        ]
    )
    assert rc == 0, capsys.readouterr().out
