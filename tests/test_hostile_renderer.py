"""The renderer CLI attacked as a hostile user would: each test is one finding, failing before its fix.

Contract (docs/renderer.md, "Safe writes and bad input"): one line on stderr
naming the option, file, line or value and what was expected, exit 2,
nothing written. Tests that already cover the CLI: test_hostile.py,
test_renderer_cli.py, test_output_safety.py, test_fuzz.py.
"""

import json
import os
import tracemalloc

import numpy as np
import pytest
from wirecheck.core.app import cli as renderer_cli
from wirecheck.core.scene.files import SCENE_DIR

SMALL = ["--width", "16", "--height", "8"]  # frames as small as the contract allows: every test stays fast


def render(args, out, capsys):
    try:
        rc = renderer_cli.main([*args, "--out", str(out)])
    except SystemExit as exc:  # argparse's usage errors
        rc = exc.code
    cap = capsys.readouterr()
    return rc, cap.out, cap.err


def assert_refused(rc, err, out, *needles):
    assert rc == 2, err
    assert err.count("\n") == 1 and err.startswith("renderer: error: ") and "Traceback" not in err, err
    for n in needles:
        assert n in err, (n, err)
    assert not os.path.exists(out)  # nothing written, not even the folder


# ---- an option that another makes ineffective is refused, not ignored ------------------------


@pytest.mark.parametrize(
    "args, needle",
    [
        (["--frames", "1", "--port", "5"], "--port 5 without --interactive"),
        (["--frames", "1", "--compare-z", "3,6"], "--compare-z '3,6' without --compare"),
        (["--frames", "1", "--compare-fov", "60,90"], "--compare-fov '60,90' without --compare"),
        (["--frames", "1", "--ortho-height", "3"], "--ortho-height 3.0 with --projection perspective"),
        (["--frames", "1", "--ascii-cols", "40"], "--ascii-cols 40 without ascii in --format"),
        (["--compare", "--frames", "5"], "--frames with --compare"),  # it renders frame 1 only
        (["--compare", "--spin", "0,1,0"], "--spin with --compare"),  # at rest: no spin
        (["--compare", "--fov", "50"], "--fov with --compare"),  # --compare-fov sets them
        (["--compare", "--format", "gif"], "--format with --compare"),
        (["--compare", "--projection", "both"], "--projection both with --compare"),
        (["--interactive", "--frames", "3"], "--out with --interactive"),  # it writes nothing
    ],
)
def test_an_ineffective_option_is_refused(tmp_path, capsys, args, needle):
    out = tmp_path / "out"
    rc, stdout, err = render(args, out, capsys)
    assert stdout == ""
    assert_refused(rc, err, out, needle)


def test_interactive_refuses_output_options_before_serving(capsys):
    rc = renderer_cli.main(["--interactive", "--format", "gif"])
    cap = capsys.readouterr()
    assert (rc, cap.out) == (2, "")  # no "Viewer: http://..." line: nothing was served
    assert (
        cap.err == "renderer: error: --format with --interactive: --interactive does not use it; expected one of them\n"
    )


# ---- --format and --ascii-cols ---------------------------------------------------------------


@pytest.mark.parametrize(
    "value, needle",
    [
        ("png,,gif", "'' is not a format"),
        ("png,", "'' is not a format"),
        ("png,png", "'png' given twice"),
        ("gif, png ,gif", "'gif' given twice"),
        ("PNG", "'PNG' is not a format"),
    ],
)
def test_format_list_with_empty_duplicate_or_unknown_items(tmp_path, capsys, value, needle):
    out = tmp_path / "out"
    rc, _, err = render(["--frames", "1", *SMALL, "--format", value], out, capsys)
    assert_refused(rc, err, out, f"--format {value!r}", needle)


@pytest.mark.parametrize("projection, width", [("perspective", 16), ("both", 2 * 16 + 1)])
def test_ascii_cols_up_to_the_frame_width(tmp_path, capsys, projection, width):
    # the frame is W = 16 wide, or 2W + 1 = 33 with --projection both (docs/renderer.md): one
    # column per pixel is the most; one more used to be clamped to W without a word
    out = tmp_path / "wide"
    rc, _, err = render(
        ["--frames", "1", *SMALL, "--projection", projection, "--format", "ascii", "--ascii-cols", str(width + 1)],
        out,
        capsys,
    )
    assert_refused(rc, err, out, f"--ascii-cols {width + 1}", f"at most the frame's width, {width} pixels")
    out = tmp_path / "ok"
    rc, _, err = render(
        ["--frames", "1", *SMALL, "--projection", projection, "--format", "ascii", "--ascii-cols", str(width)],
        out,
        capsys,
    )
    assert rc == 0, err
    lines = (out / "cube-frames" / "frame_0001.txt").read_text().splitlines()
    # rows = round(cols * H / W / 2) (cells twice as tall as wide) = round(W * 8 / W / 2) = 4
    assert [len(line) for line in lines] == [width] * 4


# ---- --out -----------------------------------------------------------------------------------


@pytest.mark.parametrize("where", [".", "sub"])
def test_out_in_the_scenes_folder_is_refused(capsys, where):
    before = sorted(os.listdir(SCENE_DIR))
    out = SCENE_DIR / where
    rc = renderer_cli.main(["--frames", "1", *SMALL, "--out", str(out)])
    err = capsys.readouterr().err
    assert rc == 2 and err.count("\n") == 1 and "is inside the scenes folder" in err, err
    assert sorted(os.listdir(SCENE_DIR)) == before  # no cube-frames/ or report beside the bundled scenes


# ---- numbers: what another reader of the same text would read ---------------------------------


@pytest.mark.parametrize(
    "args, needle",
    [
        (["--frames", "\u0664"], "argument --frames: invalid int value: '\u0664'"),  # ARABIC-INDIC DIGIT FOUR
        (["--frames", "4_0"], "argument --frames: invalid int value: '4_0'"),
        (["--frames", "1", "--fov", "6_0"], "argument --fov: invalid float value: '6_0'"),
        (["--frames", "1", "--spin", "1_0,0,0"], "--spin '1_0,0,0'"),
    ],
)
def test_underscores_and_non_ascii_digits_in_options(tmp_path, capsys, args, needle):
    out = tmp_path / "out"
    rc, _, err = render(args, out, capsys)
    assert_refused(rc, err, out, needle)


@pytest.mark.parametrize(
    "line, token", [("v 1_0 0 0", "'1_0'"), ("v \u0664 0 0", "'\u0664'"), ("v 0 0 0\nv 1 0 0\ne 0 0_1", "'0_1'")]
)
def test_underscores_and_non_ascii_digits_in_a_scene_file(tmp_path, capsys, line, token):
    scene = tmp_path / "n.scene"
    scene.write_text(line + "\n", encoding="utf-8")
    out = tmp_path / "out"
    rc, _, err = render(["--frames", "1", *SMALL, "--scene", str(scene)], out, capsys)
    assert_refused(rc, err, out, f"n.scene:{line.count(chr(10)) + 1}:", token, "expected")


# ---- .scene text -----------------------------------------------------------------------------


def scene_counts(out):
    s = json.loads((out / "t-report.json").read_text())["scene"]
    return s["vertices"], s["edges"]


def test_a_scene_with_a_bom_and_crlf_is_read(tmp_path, capsys):
    scene = tmp_path / "t.scene"
    scene.write_bytes(b"\xef\xbb\xbfv 0 0 0\r\nv 1 0 0\r\ne 0 1\r\n")  # Notepad's UTF-8
    rc, _, err = render(["--frames", "1", *SMALL, "--scene", str(scene)], tmp_path / "out", capsys)
    assert rc == 0, err
    assert scene_counts(tmp_path / "out") == (2, 1)


@pytest.mark.parametrize("separator", ["\u2028", "\x85", "\x0c", "\x1c", "\x1e"])
def test_a_line_ends_only_at_newline(tmp_path, capsys, separator):
    # str.splitlines() ends a line at these too: the rest of the comment became an edge
    scene = tmp_path / "t.scene"
    scene.write_text(f"v 0 0 0\nv 1 0 0\nv 0 1 0\n# see{separator}e 0 2\ne 0 1\n", encoding="utf-8")
    rc, _, err = render(["--frames", "1", *SMALL, "--scene", str(scene)], tmp_path / "out", capsys)
    assert rc == 0, err
    assert scene_counts(tmp_path / "out") == (3, 1)


def test_error_line_numbers_count_newlines_as_editors_do(tmp_path, capsys):
    scene = tmp_path / "t.scene"
    scene.write_text("# page one\x0cpage two\nv 1 zz 0\n", encoding="utf-8")
    out = tmp_path / "out"
    rc, _, err = render(["--frames", "1", "--scene", str(scene)], out, capsys)
    assert_refused(rc, err, out, "t.scene:2: vertex coordinate 'zz'")


@pytest.mark.parametrize(
    "text, what",
    [
        ("v 0 0 " + "1" * 1_000_000 + " 2\n", "vertex 'v 0 0 1111"),  # a line of 4 fields
        ("v 0 0 x" + "1" * 1_000_000 + "\n", "vertex coordinate 'x111"),  # one token of 1 MB
        ("q" * 1_000_000 + "\n", "'qqqq"),  # an unknown tag of 1 MB
    ],
)
def test_a_huge_line_is_named_not_echoed(tmp_path, capsys, text, what):
    scene = tmp_path / "t.scene"
    scene.write_text(text)
    out = tmp_path / "out"
    rc, _, err = render(["--frames", "1", "--scene", str(scene)], out, capsys)
    assert_refused(rc, err, out, "t.scene:1:", what, "characters)")
    assert len(err) < 400  # the first 60 characters and the length, not 1 MB


# ---- OBJ -------------------------------------------------------------------------------------


# a face of two indices is an edge, said in one warning line (tests/test_mesh_leniency.py)
@pytest.mark.parametrize(
    "element, needle",
    [
        ("l 1", "obj:4: line element 'l 1': expected 2 or more vertex indices"),  # drew nothing
        ("f", "obj:4: face 'f': expected vertex indices"),
    ],
)
def test_obj_elements_too_short_to_draw_are_refused(tmp_path, capsys, element, needle):
    mesh = tmp_path / "m.obj"
    mesh.write_text(f"v 0 0 0\nv 1 0 0\nv 0 1 0\n{element}\n")
    out = tmp_path / "out"
    rc, _, err = render(["--frames", "1", "--scene", str(mesh)], out, capsys)
    assert_refused(rc, err, out, needle)


def test_obj_negative_indices_with_slash_forms_are_read(tmp_path, capsys):
    # -1 is the last vertex read so far (the OBJ spec); trimesh failed on 'f -3//1 ...' (IndexError: exit 2)
    mesh = tmp_path / "t.obj"
    mesh.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvt 0 0\nf -3//1 -2//1 -1//1\nv 0 0 1\nl 4/1 -4/1\n")
    rc, _, err = render(["--frames", "1", *SMALL, "--scene", str(mesh)], tmp_path / "out", capsys)
    assert rc == 0, err
    assert scene_counts(tmp_path / "out") == (4, 4)  # the triangle's 3 edges and 4-1


def test_obj_negative_indices_count_back_from_this_line_not_the_end_of_the_file(tmp_path):
    from wirecheck.core.scene.files import load_scene

    # 'f -3 -2 -1' after three vertices is vertices 1 2 3 (0-based 0 1 2), whatever follows;
    # trimesh counted back from the file's 4 vertices and drew the face (1, 2, 3) instead
    mesh = tmp_path / "late.obj"
    mesh.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\nv 5 5 -5\nf 1/1 -1/1 2/1\nvt 0 0\n")
    scene = load_scene(str(mesh))
    assert scene.faces == ((0, 1, 2), (0, 3, 1))
    assert scene.vertices.tolist() == [[0, 0, 0], [1, 0, 0], [0, 1, 0], [5, 5, -5]]


# ---- the vertices_px sidecar is written as frames come ---------------------------------------


def test_sidecar_is_not_held_in_memory(tmp_path, capsys):
    # 12,000 vertices (above SIDECAR_VERTICES = 10,000) x 40 frames x 2 float64 = 7.68 MB of
    # pixel coordinates. Stacking them (the old code: a list of frames, then np.stack) peaks at
    # 2 x 7.68 MB; written frame by frame the run never holds more than a few frames' 192 KB.
    # Bound: half the sidecar, far from both.
    rng = np.random.default_rng(7)
    scene = tmp_path / "t.scene"
    scene.write_text("".join(f"v {x:.4f} {y:.4f} {z:.4f}\n" for x, y, z in rng.uniform(-1, 1, (12_000, 3))))
    size = 40 * 12_000 * 2 * 8
    tracemalloc.start()
    try:
        rc, _, err = render(
            ["--frames", "40", *SMALL, "--format", "ascii", "--ascii-cols", "16", "--scene", str(scene)],
            tmp_path / "out",
            capsys,
        )
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert rc == 0, err
    assert peak < size / 2, (peak, size)
    data = np.load(tmp_path / "out" / "t-vertices_px.npy")
    assert data.shape == (40, 12_000, 2) and data.dtype == np.float64
    raw = (tmp_path / "out" / "t-vertices_px.npy").read_bytes()
    assert raw[:10] == b"\x93NUMPY\x01\x00" + len(raw[10 : raw.index(b"\n") + 1]).to_bytes(2, "little")
