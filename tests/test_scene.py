"""core.scene.model: built-in scenes, the text format and its errors, mesh files via trimesh."""

import numpy as np
import pytest
from numpy.testing import assert_array_equal
from wirecheck.core.errors import InputError
from wirecheck.core.scene.files import builtin_names, load_scene, parse_scene_text
from wirecheck.core.scene.model import unique_edges

CUBE_CORNERS = [[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1], [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]]


@pytest.mark.parametrize("name,n_v,n_e", [("cube", 8, 12), ("pyramid", 5, 8), ("prism", 6, 9)])
def test_builtin_counts(name, n_v, n_e):
    s = load_scene(name)
    assert s.name == name
    assert s.vertices.shape == (n_v, 3) and s.edges.shape == (n_e, 2)
    assert s.source == f"scenes/{name}.scene"


def test_builtin_names():
    assert builtin_names() == ["cube", "prism", "pyramid"]


def test_cube_geometry():
    s = load_scene("cube")
    assert_array_equal(s.vertices, CUBE_CORNERS)
    # every cube edge joins two corners differing in exactly one coordinate (length 2)
    lengths = np.linalg.norm(s.vertices[s.edges[:, 0]] - s.vertices[s.edges[:, 1]], axis=1)
    assert_array_equal(lengths, np.full(12, 2.0))
    assert len(s.faces) == 6


def test_pyramid_and_prism_geometry():
    p = load_scene("pyramid")
    assert_array_equal(p.vertices[4], [0, 1, 0])  # apex
    assert sorted(map(tuple, p.edges.tolist())) == [(0, 1), (0, 3), (0, 4), (1, 2), (1, 4), (2, 3), (2, 4), (3, 4)]
    q = load_scene("prism")
    # circumradius 1 triangle at z = -1 and z = +1: |(x, y)| = 1 for all 6 vertices
    # (sqrt(3)/2 written to 16 digits: error ~ 1e-16 relative)
    np.testing.assert_allclose(np.hypot(q.vertices[:, 0], q.vertices[:, 1]), 1.0, rtol=0, atol=4e-16)
    assert_array_equal(np.sort(q.vertices[:, 2]), [-1, -1, -1, 1, 1, 1])


def test_text_format_comments_faces_and_dedup():
    text = """
    # a comment line
    name tri          # trailing comment
    v 0 0 0
    v 1 0 0
    v 0 1 0
    e 1 0             # reversed: stored as (0, 1)
    e 0 1             # duplicate
    f 0 1 2           # adds (0,1) (1,2) (0,2)
    """
    s = parse_scene_text(text, "mem.scene")
    assert s.name == "tri"
    assert_array_equal(s.edges, [[0, 1], [0, 2], [1, 2]])
    assert s.faces == ((0, 1, 2),)


def test_name_defaults_to_file_stem(tmp_path):
    p = tmp_path / "thing.scene"
    p.write_text("v 0 0 0\nv 1 1 1\ne 0 1\n")
    s = load_scene(str(p))
    assert s.name == "thing" and s.edges.tolist() == [[0, 1]]


def test_unique_edges_drops_self_loops_and_sorts():
    assert_array_equal(unique_edges([[2, 1], [1, 2], [3, 3], [0, 4]]), [[0, 4], [1, 2]])
    assert unique_edges(np.zeros((0, 2))).shape == (0, 2)


def test_empty_scene_file(tmp_path):
    p = tmp_path / "empty.scene"
    p.write_text("# nothing here\n\n")
    s = load_scene(str(p))
    assert s.vertices.shape == (0, 3) and s.edges.shape == (0, 2)
    assert s.radius == 0.0


def test_zero_byte_scene_file(tmp_path):
    p = tmp_path / "zero.scene"
    p.write_bytes(b"")
    s = load_scene(str(p))
    assert s.vertices.shape == (0, 3) and s.edges.shape == (0, 2)


# ---- parse errors: path, line number and the offending value in one message ------------

BAD = [
    # (id, text, line number, offending value as it must appear in the message)
    ("bad number", "v 0 0 0\nv 1 x2 3\n", 2, "x2"),
    ("wrong field count", "v 0 0 0\n\nv 1 2\n", 3, "v 1 2"),
    ("too many fields", "v 0 0 0 9\n", 1, "v 0 0 0 9"),
    ("edge index out of range", "v 0 0 0\nv 1 0 0\ne 0 7\n", 3, "index 7"),
    ("negative edge index", "v 0 0 0\nv 1 0 0\ne -1 0\n", 3, "index -1"),
    ("non-integer edge index", "v 0 0 0\nv 1 0 0\ne 0 1.5\n", 3, "1.5"),
    ("face index out of range", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 3\n", 4, "index 3"),
    ("short face", "v 0 0 0\nv 1 0 0\nf 0 1\n", 3, "f 0 1"),
    ("NaN", "# c\nv nan 0 0\n", 2, "nan"),
    ("Inf", "v 0 0 0\nv 0 inf 0\n", 2, "inf"),
    ("-Inf", "v 0 0 -Infinity\n", 1, "-Infinity"),
    ("unknown tag", "v 0 0 0\nx 1 2\n", 2, "'x'"),
    ("edge before its vertex", "v 0 0 0\ne 0 1\nv 1 0 0\n", 2, "index 1"),
]


@pytest.mark.parametrize("text,lineno,value", [b[1:] for b in BAD], ids=[b[0] for b in BAD])
def test_parse_error_names_path_line_and_value(tmp_path, text, lineno, value):
    p = tmp_path / "bad.scene"
    p.write_text(text)
    with pytest.raises(InputError) as info:
        load_scene(str(p))
    msg = str(info.value)
    assert f"{p}:{lineno}:" in msg
    assert value in msg
    assert "\n" not in msg


def test_unknown_builtin_and_missing_file(tmp_path):
    with pytest.raises(InputError, match="nosuchscene"):
        load_scene("nosuchscene")
    missing = str(tmp_path / "missing.scene")
    with pytest.raises(InputError, match="file not found"):
        load_scene(missing)


def test_unknown_suffix(tmp_path):
    p = tmp_path / "x.abc"
    p.write_text("v 0 0 0\n")
    with pytest.raises(InputError, match=r"\.abc"):
        load_scene(str(p))


def test_scene_arrays_are_read_only():
    s = load_scene("cube")
    with pytest.raises(ValueError):
        s.vertices[0, 0] = 5.0


# ---- mesh files ------------------------------------------------------------------------


def test_obj_line_elements_become_edges(tmp_path):
    p = tmp_path / "lines.obj"
    # l 1 2 3 -> (0,1) (1,2); l -1 -4 -> relative: last vertex (3) to first (0)
    p.write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nl 1 2 3\nl -1 -4\n")
    s = load_scene(str(p))
    assert s.name == "lines"
    assert_array_equal(s.vertices, [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]])
    assert_array_equal(s.edges, [[0, 1], [0, 3], [1, 2]])


def test_obj_faces_and_lines_together(tmp_path):
    p = tmp_path / "mixed.obj"
    # a triangle (edges 01 12 02) plus a line element from vertex 3 to vertex 4
    p.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 5 5 5\nv 6 6 6\nf 1 2 3\nl 4 5\n")
    s = load_scene(str(p))
    assert s.vertices.shape == (5, 3)
    assert_array_equal(s.edges, [[0, 1], [0, 2], [1, 2], [3, 4]])


def test_obj_bad_line_index(tmp_path):
    p = tmp_path / "bad.obj"
    p.write_text("v 0 0 0\nv 1 0 0\nl 1 9\n")
    with pytest.raises(InputError) as info:
        load_scene(str(p))
    assert f"{p}:3:" in str(info.value) and "'9'" in str(info.value)


def _face_edge_set(faces):
    return {tuple(sorted((int(f[k]), int(f[(k + 1) % len(f)])))) for f in faces for k in range(len(f))}


def test_ply_written_by_trimesh_round_trips(tmp_path):
    trimesh = pytest.importorskip("trimesh")
    box = trimesh.creation.box(extents=(2, 2, 2))
    p = tmp_path / "box.ply"
    box.export(p)
    s = load_scene(str(p))
    # indexed PLY keeps the 8 shared corners; 12 triangles have 12 cube edges plus one
    # diagonal per face (6): 18 unique edges
    assert s.vertices.shape == (8, 3) and s.edges.shape == (18, 2)
    assert_array_equal(s.vertices, box.vertices)
    assert set(map(tuple, s.edges.tolist())) == _face_edge_set(box.faces)
    assert len(s.faces) == 12


def test_stl_written_by_trimesh_round_trips(tmp_path):
    trimesh = pytest.importorskip("trimesh")
    box = trimesh.creation.box(extents=(2, 2, 2))
    p = tmp_path / "box.stl"
    box.export(p)
    s = load_scene(str(p))
    # STL stores each triangle's 3 corners on their own (36 here); the loader merges
    # equal positions, giving the box's 8 corners, and the unique edges of its 12
    # triangles: 12 cube edges + 6 face diagonals = 18 (trimesh's edges_unique agrees)
    assert s.vertices.shape == (8, 3) and s.edges.shape == (18, 2)
    assert set(map(tuple, np.unique(np.abs(s.vertices), axis=0).tolist())) == {(1.0, 1.0, 1.0)}


def test_corrupt_mesh_file_is_input_error(tmp_path):
    p = tmp_path / "junk.ply"
    p.write_bytes(b"this is not a ply file\x00\x01")
    with pytest.raises(InputError) as info:
        load_scene(str(p))
    assert str(p) in str(info.value)


# ---- objects (tests/test_multi_object.py has the rest) -----------------------------------


def test_example_scene_by_name_and_in_the_unknown_message():
    s = load_scene("orrery")
    assert s.source == "scenes/examples/orrery.scene" and len(s.objects) == 3
    with pytest.raises(InputError, match="orrery"):
        load_scene("nosuchscene")


def test_single_object_scene_keeps_its_arrays_and_one_static_object():
    s = parse_scene_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", "t.scene")
    assert len(s.objects) == 1 and s.is_single_static
    o = s.objects[0]
    assert (o.name, o.vertex_start, o.vertex_stop) == ("t", 0, 3)
    assert o.motion.turns == (0.0, 0.0, 0.0) and o.motion.offset == (0.0, 0.0, 0.0) and o.motion.scale == 1.0
    assert_array_equal(s.edges, [[0, 1], [0, 2], [1, 2]])


def test_vectorised_edge_helpers_equal_their_plain_definitions():
    # unique_edges: sort each pair, drop self-loops, np.unique(axis=0) (the definition);
    # face_edges on an (F, k) array: the same pairs, in the same order, as on lists.
    from wirecheck.core.scene.model import face_edges, unique_edges

    rng = np.random.default_rng(3)
    for n in (1, 7, 5000):
        e = rng.integers(0, n, size=(4 * n, 2))
        s = np.sort(e, axis=1)
        expected = np.unique(s[s[:, 0] != s[:, 1]], axis=0).reshape(-1, 2)
        np.testing.assert_array_equal(unique_edges(e), expected)
        faces = rng.integers(0, n, size=(n, 4))
        np.testing.assert_array_equal(face_edges(faces), face_edges(faces.tolist()))
