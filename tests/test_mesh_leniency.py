"""Real assets load: OBJ faces of fewer than three indices (core.scene.files), read leniently and said once."""

from __future__ import annotations

import contextlib
import io
import json

import pytest
from wirecheck.core.errors import InputError
from wirecheck.core.scene.files import load_scene
from wirecheck.oracles import cli

#: A tetrahedron's four corners, two triangles, then (line 7, 9) two faces of two indices and (line 8)
#: one of one index, as in a simulator's asset: 'f 54982 54987' among triangles.
TETRA = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 3 4\nf 2 4\nf 4\nf -3/1 -1/1\n"


def _cli(argv) -> tuple[int, str, str]:
    o, e = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(o), contextlib.redirect_stderr(e):
        code = cli.main([str(a) for a in argv])
    return code, o.getvalue(), e.getvalue()


def test_two_index_faces_are_edges_one_index_faces_are_skipped(tmp_path):
    mesh = tmp_path / "asset.obj"
    mesh.write_text(TETRA)
    scene = load_scene(str(mesh))
    assert scene.faces == ((0, 1, 2), (0, 2, 3))  # the triangles as written (0-based)
    # the triangles' 5 edges (0-1 1-2 0-2 2-3 0-3) and the two 2-index faces: 2-4 -> (1, 3); at line 9, after
    # 4 vertices, -3 is vertex 2 and -1 vertex 4 -> (1, 3) again: one edge
    assert scene.edges.tolist() == [[0, 1], [0, 2], [0, 3], [1, 2], [1, 3], [2, 3]]
    assert scene.load_notes == (
        f"{mesh}:7: 3 faces with fewer than 3 vertex indices (first 'f 2 4'): "
        "2 of two read as edges; 1 of one skipped (a point draws nothing)",
    )


def test_a_mesh_of_triangles_only_has_no_note(tmp_path):
    mesh = tmp_path / "t.obj"
    mesh.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    assert load_scene(str(mesh)).load_notes == ()


@pytest.mark.parametrize(
    "face, needle",
    [
        ("f 2 9", "t.obj:4: face index '9': expected 1..3 (the file has 3 vertices)"),  # beyond the vertices
        ("f 2 x", "t.obj:4: face index 'x': expected an integer"),
        ("f", "t.obj:4: face 'f': expected vertex indices"),  # no meaning to give
    ],
)
def test_a_short_face_that_cannot_be_read_is_still_refused(tmp_path, face, needle):
    mesh = tmp_path / "t.obj"
    mesh.write_text(f"v 0 0 0\nv 1 0 0\nv 0 1 0\n{face}\nf 1 2 3\n")
    with pytest.raises(InputError) as exc:
        load_scene(str(mesh))
    assert needle in str(exc.value) and "\n" not in str(exc.value)


def test_crosscheck_warns_once_and_judges_the_rest(tmp_path):
    mesh = tmp_path / "asset.obj"
    mesh.write_text(TETRA)
    code, out, err = _cli(["--scene", mesh, "--frames", "1", "--cases", "on_axis", "--report-dir", tmp_path / "r"])
    assert code == 0, err
    warnings = [line for line in err.splitlines() if "warning" in line]
    assert warnings == [
        f"crosscheck: warning: {mesh}:7: 3 faces with fewer than 3 vertex indices (first "
        "'f 2 4'): 2 of two read as edges; 1 of one skipped (a point draws nothing)"
    ]
    report = json.loads((tmp_path / "r" / "report.json").read_text())
    case = report["cases"][0]
    assert report["verdict"] == "pass" and case["verdict"] == "pass"
    assert case["compared"]["frames"] == 1 and case["lines"]["lines_compared"] > 0


def test_a_dataset_report_says_which_mesh_was_read_leniently(tmp_path):
    folder = tmp_path / "meshes"
    folder.mkdir()
    (folder / "asset.obj").write_text(TETRA)
    code, out, err = _cli(["--scene", folder, "--frames", "1", "--cases", "on_axis", "--report-dir", tmp_path / "r"])
    assert code == 0, err
    report = json.loads((tmp_path / "r" / "report.json").read_text())
    note = (
        "asset.obj:7: 3 faces with fewer than 3 vertex indices (first 'f 2 4'): 2 of two read as edges; "
        "1 of one skipped (a point draws nothing)"
    )
    assert report["summary"]["warnings"] == [{"mesh": "asset.obj", "warning": note}]
    assert report["meshes"][0]["verdict"] == "pass" and report["meshes"][0]["edges"] == 6
    assert f"asset.obj: {note}" in out  # the console summary
    assert f"| asset.obj | {note} |" in (tmp_path / "r" / "report.md").read_text()


def test_renderer_warns_once_and_draws_the_edges(tmp_path, capsys):
    from wirecheck.core.app import cli as renderer_cli

    mesh = tmp_path / "asset.obj"
    mesh.write_text(TETRA)
    out = tmp_path / "out"
    rc = renderer_cli.main(["--scene", str(mesh), "--frames", "1", "--width", "16", "--height", "8", "--out", str(out)])
    err = capsys.readouterr().err
    assert rc == 0, err
    assert [line for line in err.splitlines() if "warning" in line] == [
        f"renderer: warning: {mesh}:7: 3 faces with fewer than 3 vertex indices (first 'f 2 4'): 2 of two read "
        "as edges; 1 of one skipped (a point draws nothing)"
    ]
    assert json.loads((out / "asset-report.json").read_text())["scene"]["edges"] == 6
