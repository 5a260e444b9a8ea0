"""Hostile inputs of ``crosscheck --candidate-frames DIR`` and of dataset runs: one line, exit 2, never a hang.

Each test is a finding of an attack on those inputs (frame PNGs of every
colour type, files that are not regular files, links, hand-edited JSON, scene
lists written on other systems) and failed before its fix. Expected masks are
derived by hand from the image rule (docs/frames.md): a pixel is drawn when its
luminance over the black background, ``L * A / 255``, is at least 128.
"""

from __future__ import annotations

import json
import os
import shutil

import helpers  # tests/ is on sys.path (rootdir conftest)
import numpy as np
import pytest
from helpers import no_block  # tests/ is on sys.path (rootdir conftest)
from PIL import Image
from wirecheck.oracles import cli as crosscheck_cli
from wirecheck.oracles.candidates.frames_candidate import (
    FrameProblem,
    FramesError,
    frame_inputs,
    load_frames,
    load_job,
    read_png,
)


def assert_one_error_line(rc, err, *needles):
    assert rc == 2, err
    assert err.count("\n") == 1 and err.startswith("crosscheck: error: "), err
    assert "Traceback" not in err
    for n in needles:
        assert n in err, (n, err)


# ---- one frame PNG: what is read as drawn ------------------------------------------------------


def _png(tmp_path, array, mode=None, **save):
    path = tmp_path / "f.png"
    Image.fromarray(array, mode).save(path, **save) if mode else Image.fromarray(array).save(path, **save)
    return path


def test_16_bit_grey_is_read_at_its_full_scale(tmp_path):
    """Drawn when the high byte is >= 128, i.e. from 128 * 256 = 32768 (as Pillow reads 16-bit RGB). Before,
    Pillow's conversion clipped 16-bit values to 255, so a background of 256 (0.4 % grey, black to the eye)
    was drawn everywhere."""
    values = np.array([[0, 256, 32767, 32768, 65535]], np.uint16)
    assert read_png(_png(tmp_path, values), 5, 1).tolist() == [[False, False, False, True, True]]


def test_alpha_is_composited_over_the_black_background(tmp_path):
    """White (L = 255) at alpha A shows as 255 * A / 255 = A over black: drawn when A >= 128. Before, alpha was
    dropped: a white image with a transparent background read as drawn everywhere."""
    rgba = np.zeros((1, 5, 4), np.uint8)
    rgba[..., :3] = 255
    rgba[0, :, 3] = [0, 127, 128, 255, 0]
    rgba[0, 4] = [0, 0, 0, 255]  # opaque black: not drawn
    assert read_png(_png(tmp_path, rgba, "RGBA"), 5, 1).tolist() == [[False, False, True, True, False]]
    la = np.array([[[255, 0], [255, 255], [100, 255]]], np.uint8)  # grey 100 < 128 even opaque
    assert read_png(_png(tmp_path, la, "LA"), 3, 1).tolist() == [[False, True, False]]


def test_palette_transparency_counts_as_alpha(tmp_path):
    """Index 1 is white but listed transparent (tRNS): not drawn. Before, it read as drawn."""
    im = Image.new("P", (3, 1))
    im.putpalette([0, 0, 0, 255, 255, 255, 255, 255, 255])
    im.putdata([0, 1, 2])
    path = tmp_path / "p.png"
    im.save(path, transparency=1)
    assert read_png(path, 3, 1).tolist() == [[False, False, True]]


def test_a_transparent_grey_value_counts_as_alpha(tmp_path):
    """Grey PNG with a tRNS grey value (255 transparent): white reads as not drawn, 200 as drawn. The
    opaque grey image has a fast path that must not skip this."""
    path = tmp_path / "lt.png"
    Image.fromarray(np.array([[255, 200, 0]], np.uint8)).save(path, transparency=255)
    assert read_png(path, 3, 1).tolist() == [[False, True, False]]


def test_one_bit_and_opaque_grey_read_as_before(tmp_path):
    """Opaque images keep the plain rule, L >= 128 (the composite is exact at A = 255)."""
    assert read_png(_png(tmp_path, np.array([[False, True]])), 2, 1).tolist() == [[False, True]]
    assert read_png(_png(tmp_path, np.array([[127, 128]], np.uint8)), 2, 1).tolist() == [[False, True]]


@pytest.mark.parametrize("fmt", ["JPEG", "GIF", "BMP", "TIFF"])
def test_another_format_named_png_is_refused(tmp_path, fmt):
    """JPEG is lossy (ringing turns pixels on near a line): the job asks for PNG. Before, any format Pillow
    reads was judged."""
    path = tmp_path / "f.png"
    Image.new("L", (4, 4)).save(path, format=fmt)
    with pytest.raises(FrameProblem, match=f"a {fmt} image: expected a PNG"):
        read_png(path, 4, 4)


def test_an_animated_png_is_refused(tmp_path):
    """Which of its frames is the frame? Before, the first was judged silently."""
    path = tmp_path / "f.png"
    Image.new("L", (4, 4)).save(path, save_all=True, append_images=[Image.new("L", (4, 4), 255)])
    with pytest.raises(FrameProblem, match="an animated PNG of 2 frames: expected one still image"):
        read_png(path, 4, 4)


# ---- a job on disk -----------------------------------------------------------------------------


@pytest.fixture(scope="module")
def blank_job(tmp_path_factory):
    """cube / on_axis, frames 1 and 3 of 4, black 640x480 PNGs (judged: exit 1, tests/test_hostile.py)."""
    return helpers.blank_job(tmp_path_factory.mktemp("job") / "job")


@pytest.fixture
def job(blank_job, tmp_path):
    d = tmp_path / "job"
    shutil.copytree(blank_job, d)
    return d


def judge(job, tmp_path, capsys):
    with no_block():
        rc = crosscheck_cli.main(["--candidate-frames", str(job), "--report-dir", str(tmp_path / "r")])
    err = capsys.readouterr().err
    assert not (tmp_path / "r").exists()
    return rc, err


FRAME = "frames/cube/on_axis/frame_0001.png"


@pytest.mark.parametrize(
    "make, needle",
    [
        (lambda p: os.mkfifo(p), "a FIFO, not a regular file"),
        (lambda p: p.mkdir(), "a folder, not a regular file"),
        (lambda p: p.symlink_to("/dev/null"), "a character device, not a regular file"),
        (lambda p: p.symlink_to(p.parent / "nowhere.png"), "a broken link"),
    ],
)
def test_a_frame_that_is_not_a_regular_file_is_named_so(job, tmp_path, capsys, make, needle):
    """Before: each read 'missing', which sends the user looking for a file that is there."""
    (job / FRAME).unlink()
    make(job / FRAME)
    rc, err = judge(job, tmp_path, capsys)
    assert_one_error_line(rc, err, f"{job / FRAME}: {needle} (frame 1 of cube / on_axis)")


@pytest.mark.parametrize(
    "rel, needle",
    [
        ("cameras/cube/on_axis/frame_0001.json", "a FIFO, not a regular file: expected the camera"),
        ("scenes/cube.obj", "a FIFO, not a regular file: expected the OBJ"),
        ("job.json", "a FIFO, not a regular file: expected a job folder"),
    ],
)
def test_a_fifo_in_place_of_a_job_file_never_blocks(job, tmp_path, capsys, rel, needle):
    """Before: the run opened the FIFO and waited for a writer forever."""
    (job / rel).unlink()
    os.mkfifo(job / rel)
    rc, err = judge(job, tmp_path, capsys)
    assert_one_error_line(rc, err, f"{job / rel}: {needle}")


def test_frames_folder_that_is_a_link_loop(job, tmp_path, capsys):
    shutil.rmtree(job / "frames")
    (job / "frames").symlink_to(job / "loop")
    (job / "loop").symlink_to(job / "frames")
    rc, err = judge(job, tmp_path, capsys)  # before: "frames: missing"
    assert_one_error_line(rc, err, f"{job / 'frames'}: unreadable (Too many levels of symbolic links)")


def test_frames_under_a_linked_folder_are_found_and_loops_end(job, tmp_path):
    """frames/cube links to the renderer's output folder elsewhere; a link inside it points back up (a loop).
    Before: 'frames: empty' (the walk did not follow links to folders) though every frame opens."""
    shutil.move(job / "frames/cube", tmp_path / "out")
    (job / "frames/cube").symlink_to(tmp_path / "out")
    (tmp_path / "out/on_axis/up").symlink_to(tmp_path / "out")
    frames = load_frames(job, load_job(job))
    assert [k for k, _ in frames[("cube", "on_axis")]] == [1, 3]


def test_the_frames_walk_is_bounded(job, monkeypatch):
    """Links between folders can make a tree of any size (two links to one folder in each of n folders:
    2**n paths); the walk stops at MAX_WALK entries. Here 4 entries are the job's (cube, on_axis, 2 frames):
    the bound at 4 passes, and two links to on_axis (each seen with its 2 frames: 6 more) pass it."""
    from wirecheck.oracles.candidates import frames_candidate

    monkeypatch.setattr(frames_candidate, "MAX_WALK", 4)
    assert len(load_frames(job, load_job(job))[("cube", "on_axis")]) == 2
    for name in ("a", "b"):
        (job / "frames" / name).symlink_to(job / "frames/cube/on_axis")
    with pytest.raises(FramesError, match=r"frames: more than 4 files and folders: expected the job's frames"):
        load_frames(job, load_job(job))


def _edit_job(job, edit):
    data = json.loads((job / "job.json").read_text())
    edit(data)
    (job / "job.json").write_text(json.dumps(data))


def test_a_case_listed_twice_is_refused(job, tmp_path, capsys):
    """Before: judged twice and counted twice ('PASS: 2/2 cases')."""
    _edit_job(job, lambda d: d["cases"].append(d["cases"][0]))
    rc, err = judge(job, tmp_path, capsys)
    assert_one_error_line(rc, err, "job.json: case cube / on_axis: listed twice: expected each case once")


def test_job_size_edited_to_fit_the_frames_is_refused(job, tmp_path, capsys):
    """job.json says 320 wide, the camera 640; frames cut to 320 pass the size check. Before: exit 3
    ('image shapes differ') when the oracle's 640-wide frame met them."""
    _edit_job(job, lambda d: d["cases"][0].update(width=320))
    for k in (1, 3):
        Image.new("L", (320, 480)).save(job / f"frames/cube/on_axis/frame_{k:04d}.png")
    rc, err = judge(job, tmp_path, capsys)
    assert_one_error_line(rc, err, "cameras/cube/on_axis/frame_0001.json: camera 640x480: expected 320x480")


def test_a_camera_width_beyond_64_bits_is_one_line(job, tmp_path, capsys):
    """Before: exit 3 (OverflowError: Python int too large to convert to C long) when GL was asked for it."""
    path = job / "cameras/cube/on_axis/frame_0001.json"
    cam = json.loads(path.read_text())
    cam["camera"]["width"] = 10**400
    path.write_text(json.dumps(cam))
    rc, err = judge(job, tmp_path, capsys)
    assert_one_error_line(rc, err, f"{path}: camera 1{'0' * 39}...: expected 640x480 (job.json's size")


def test_a_key_given_twice_is_refused_and_a_bom_is_read(job, tmp_path, capsys):
    """JSON keeps the last of two equal keys, silently: an edit above the original would be ignored."""
    text = (job / "job.json").read_text()
    (job / "job.json").write_text('{"every": 1,' + text.lstrip()[1:])
    rc, err = judge(job, tmp_path, capsys)
    assert_one_error_line(rc, err, "job.json: unreadable (key 'every' given twice)")
    (job / "job.json").write_bytes(b"\xef\xbb\xbf" + text.encode())  # a Windows editor's BOM
    assert load_job(job)["every"] == 2  # before: "Unexpected UTF-8 BOM"


def test_frame_inputs_of_the_blank_job_are_as_exported(blank_job):
    """The fixtures above are a valid job: its camera is the 640x480 of job.json (the check does not misfire)."""
    job = load_job(blank_job)
    _p, _e, camera, m = frame_inputs(blank_job, job, "cube", "on_axis", 3)
    assert (camera.width, camera.height) == (640, 480) and m.shape == (4, 4)
    with pytest.raises(FramesError):
        frame_inputs(blank_job, {**job, "cases": [{**job["cases"][0], "height": 479}]}, "cube", "on_axis", 3)


# ---- the job is read, never written ------------------------------------------------------------


def _tree(folder):
    return sorted((str(p.relative_to(folder)), p.is_file() and p.read_bytes()) for p in folder.rglob("*"))


@pytest.mark.parametrize(
    "argv",
    [
        lambda job, tmp: ["--candidate-frames", str(job), "--report-dir", str(job)],
        lambda job, tmp: ["--level", "vertices", "--frames", "1", "--cases", "on_axis", "--report-dir", str(job)],
        lambda job, tmp: ["export", str(job), "--scene", "cube", "--cases", "on_axis"],
    ],
)
def test_a_job_with_drawn_frames_is_never_replaced(job, tmp_path, capsys, argv):
    """The job carries wirecheck's output marker (export wrote it), but frames/ holds the renderer's files.
    Before: each command replaced the whole job by its own output, deleting the renderer's frames."""
    before = _tree(job)
    rc = crosscheck_cli.main(argv(job, tmp_path))
    assert_one_error_line(
        rc, capsys.readouterr().err, f"'{job}' is a frames job holding files a renderer wrote (frames/cube)"
    )
    assert _tree(job) == before


def test_a_report_in_the_frames_folder_is_refused(job, tmp_path, capsys, monkeypatch):
    """Before: written there (exit 0), which made the next judgement fail ('not a frame of this job').
    A report elsewhere in the job (reports/RUN when run from inside it) is harmless and still written."""
    before = _tree(job)
    rc = crosscheck_cli.main(["--candidate-frames", str(job), "--report-dir", str(job / "frames/new")])
    assert_one_error_line(
        rc, capsys.readouterr().err, f"report folder '{job / 'frames/new'}': the job '{job}' itself or its frames/"
    )
    assert _tree(job) == before
    monkeypatch.chdir(job)
    assert crosscheck_cli.main(["--candidate-frames", ".", "--run", "r"]) == 1  # black frames: a fail
    assert (job / "reports/r/report.json").is_file()


def test_an_exported_job_not_yet_drawn_is_still_exported_again(job, capsys):
    """The refusal above needs drawn frames: an earlier export with an empty frames/ is replaced, as documented."""
    shutil.rmtree(job / "frames")
    (job / "frames").mkdir()
    assert crosscheck_cli.main(["export", str(job), "--scene", "pyramid", "--cases", "on_axis", "--frames", "1"]) == 0
    assert [s["name"] for s in load_job(job)["scenes"]] == ["pyramid"]


# ---- datasets: --scene DIR, --scene-list FILE ---------------------------------------------------

TRI = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"


def test_a_scene_list_with_a_bom_and_crlf_lines(tmp_path):
    """A list saved by a Windows editor. Before: line 1 named '\\ufeffa.obj' (file not found)."""
    from wirecheck.oracles.datasets.dataset import read_list

    (tmp_path / "a.obj").write_text(TRI)
    (tmp_path / "b.obj").write_text(TRI)
    (tmp_path / "set.txt").write_bytes(b"\xef\xbb\xbfa.obj\r\n\r\n  # comment\r\nb.obj\r\n")
    entries = read_list(tmp_path / "set.txt")
    assert [(e.name, e.path) for e in entries] == [
        ("a.obj", str(tmp_path / "a.obj")),
        ("b.obj", str(tmp_path / "b.obj")),
    ]


def test_a_mesh_listed_again_through_a_link_is_refused(tmp_path):
    """Before: checked and counted twice (PASS: 2/2 meshes for one mesh)."""
    from wirecheck.core.errors import InputError
    from wirecheck.oracles.datasets.dataset import read_list

    (tmp_path / "a.obj").write_text(TRI)
    (tmp_path / "b.obj").symlink_to(tmp_path / "a.obj")
    (tmp_path / "set.txt").write_text("a.obj\nb.obj\n")
    with pytest.raises(InputError, match=r"set.txt:2: 'b.obj': listed twice \(line 1, through a link\)"):
        read_list(tmp_path / "set.txt")


def test_control_characters_in_mesh_names_are_escaped(tmp_path, capsys):
    """Linux file names may hold a newline, a tab or an ESC. Before, they went raw into stdout and the reports:
    a name split a summary line in two, and '\\x1b[31m' recoloured the user's terminal."""
    (tmp_path / "d").mkdir()
    (tmp_path / "d/a\nb.obj").write_text("v 1\n")  # unreadable: named in 'Could not be loaded'
    (tmp_path / "d/ok.obj").write_text(TRI)
    (tmp_path / "d/c\x1b[31m.obj").write_text(TRI)
    rc = crosscheck_cli.main(
        [
            "--scene",
            str(tmp_path / "d"),
            "--level",
            "vertices",
            "--frames",
            "1",
            "--cases",
            "on_axis",
            "--report-dir",
            str(tmp_path / "r"),
        ]
    )
    out = capsys.readouterr().out
    assert rc == 1 and "\x1b" not in out
    assert "  a\\nb.obj: line 1: vertex 'v 1': expected 'v X Y Z' (3 numbers)\n" in out  # path stripped
    assert "  c\\x1b[31m.obj / on_axis: pass" in out
    report = json.loads((tmp_path / "r" / "report.json").read_text())
    assert sorted(m["mesh"] for m in report["meshes"]) == ["a\\nb.obj", "c\\x1b[31m.obj", "ok.obj"]


# ---- [tool.wirecheck] in pyproject.toml --------------------------------------------------------


def test_pyproject_nested_too_deep_is_one_line(tmp_path):
    """Before: exit 3 (RecursionError from tomllib)."""
    from wirecheck.core.errors import InputError
    from wirecheck.oracles.config import load_config

    (tmp_path / "pyproject.toml").write_text("[tool.wirecheck]\nframes = " + "[" * 50000 + "]" * 50000 + "\n")
    with pytest.raises(InputError, match="pyproject.toml: not valid TOML here: arrays or tables nested too deep"):
        load_config(start=tmp_path)


def test_pyproject_with_a_bom_is_read(tmp_path):
    """Before: 'not valid TOML: Invalid statement (at line 1, column 1)'."""
    from wirecheck.oracles.config import load_config

    (tmp_path / "pyproject.toml").write_bytes(b"\xef\xbb\xbf[tool.wirecheck]\nframes = 2\n")
    assert load_config(start=tmp_path).values["frames"] == 2
