"""Hostile input (issue 15): one stderr line and exit 2, exit 3 for a bug, nothing half-written, nothing of the user's touched.

Each test is one finding of the fuzzing that filed the issue.
"""

import json
import os
import shutil
import signal
import subprocess
import sys
import time

import helpers
import numpy as np
import pytest
from fuzz.contract import glb_bytes  # tests/ is on sys.path (rootdir conftest)
from wirecheck.core.app import cli as renderer_cli
from wirecheck.core.app import run as core_run
from wirecheck.core.errors import InputError, one_line
from wirecheck.core.limits import MAX_FACE_VERTICES, MAX_FRAMES, MAX_SIDE
from wirecheck.core.outputs.output import MARKER
from wirecheck.core.outputs.staging import LOCK, MANIFEST
from wirecheck.core.scene.files import SCENE_DIR, parse_scene_text
from wirecheck.oracles import cli as crosscheck_cli


def render(args, out, capsys):
    rc = renderer_cli.main([*args, "--out", str(out)])
    cap = capsys.readouterr()
    return rc, cap.out, cap.err


def assert_one_error_line(rc, err, *needles):
    assert rc == 2, err
    assert (
        err.count("\n") == 1 and err.endswith("\n") and err.startswith(("renderer: error: ", "crosscheck: error: "))
    ), err
    assert "Traceback" not in err and "Warning" not in err
    for n in needles:
        assert n in err, (n, err)


def tree(folder):
    """Every path under ``folder`` (relative), to compare before and after."""
    return sorted(os.path.relpath(os.path.join(d, n), folder) for d, ds, fs in os.walk(folder) for n in ds + fs)


# ---- one error path ----------------------------------------------------------------------------


@pytest.mark.parametrize("value", ["nan", "inf", "-1", "0"])
def test_ortho_height_not_finite_with_perspective(tmp_path, capsys, value):
    rc, _, err = render(["--frames", "2", "--ortho-height", value], tmp_path / "o", capsys)
    assert_one_error_line(rc, err, f"--ortho-height {float(value)}")
    assert not (tmp_path / "o").exists()  # no cube-frames/ left behind (nor the folder)


def test_huge_spin_option(tmp_path, capsys):
    rc, _, err = render(["--frames", "7", "--spin", "1e308,0,0"], tmp_path / "o", capsys)
    assert_one_error_line(rc, err, "--spin 1e+308 0 0", "2^53")


def test_huge_spin_in_scene_file(tmp_path, capsys):
    scene = tmp_path / "s.scene"
    scene.write_text("v 0 0 0\nv 1 0 0\ne 0 1\nspin 1e308 0 0\n")
    rc, _, err = render(["--frames", "7", "--scene", str(scene)], tmp_path / "o", capsys)
    assert_one_error_line(rc, err, f"{scene}:4: spin 1e+308 0 0")


def test_spin_limit_is_2_to_the_53(tmp_path, capsys):
    # 2^53 turns is accepted (every frame at phase 0: an integer), one ulp of 2^53 more is not
    assert render(["--frames", "3", "--spin", f"{2.0**53:.17g},0,0"], tmp_path / "a", capsys)[0] == 0
    rc, _, err = render(["--frames", "3", "--spin", f"{2.0**53 + 2:.17g},0,0"], tmp_path / "b", capsys)
    assert_one_error_line(rc, err, "--spin")


def test_long_scene_name(tmp_path, capsys):
    scene = tmp_path / "s.scene"
    scene.write_text(f"name {'n' * 250}\nv 0 0 0\n")
    rc, _, err = render(["--frames", "1", "--scene", str(scene)], tmp_path / "o", capsys)
    assert_one_error_line(rc, err, "250 characters", "at most 100")
    assert not (tmp_path / "o").exists()


def test_long_scene_path(tmp_path, capsys):
    rc, _, err = render(["--frames", "1", "--scene", str(tmp_path / ("p" * 300)) + ".scene"], tmp_path / "o", capsys)
    assert_one_error_line(rc, err, "File name too long")


def test_long_candidate_path(tmp_path, capsys):
    rc = crosscheck_cli.main(
        [
            "--candidate",
            str(tmp_path / ("c" * 300)) + ".py:f",
            "--scene",
            "cube",
            "--level",
            "vertices",
            "--report-dir",
            str(tmp_path / "r"),
        ]
    )
    assert_one_error_line(rc, capsys.readouterr().err)
    assert not (tmp_path / "r").exists()


def _bad_ply(path):
    path.write_text(
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
        "0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n"
    )


def _bad_glb(path):
    """A binary glTF of one triangle (0, 1, 7) over 3 vertices, written by hand (tests/fuzz/contract.py)."""
    path.write_bytes(glb_bytes((0, 1, 7)))


@pytest.mark.parametrize("make, suffix", [(_bad_ply, ".ply"), (_bad_glb, ".glb")])
def test_face_index_out_of_range_renderer(tmp_path, capsys, make, suffix):
    mesh = tmp_path / f"m{suffix}"
    make(mesh)
    rc, _, err = render(["--frames", "1", "--scene", str(mesh)], tmp_path / "o", capsys)
    assert_one_error_line(rc, err, f"{mesh}: face 0 has vertex index 7: expected 0..2")


@pytest.mark.parametrize("index", ["2147483650", "4294967297", "99999999999999999999"])
def test_a_face_index_beyond_32_bits_is_not_reported_as_another_number(tmp_path, capsys, index):
    # trimesh stores PLY indices as int32: 2**31 + 2 and 2**32 + 1 are both read as -2**31. The
    # message must not pass that number off as the file's: it says what happened instead.
    mesh = tmp_path / "m.ply"
    mesh.write_text(
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
        f"0 0 0\n1 0 0\n0 1 0\n3 0 1 {index}\n"
    )
    rc, _, err = render(["--frames", "1", "--scene", str(mesh)], tmp_path / "o", capsys)
    assert_one_error_line(rc, err, f"{mesh}: face 0 has a vertex index beyond 32-bit integers")


@pytest.mark.parametrize("level", ["vertices", "pixels"])
@pytest.mark.parametrize("make, suffix", [(_bad_ply, ".ply"), (_bad_glb, ".glb")])
def test_face_index_out_of_range_crosscheck(tmp_path, capsys, make, suffix, level):
    mesh = tmp_path / f"m{suffix}"
    make(mesh)
    rc = crosscheck_cli.main(
        [
            "--scene",
            str(mesh),
            "--level",
            level,
            "--frames",
            "1",
            "--cases",
            "on_axis",
            "--report-dir",
            str(tmp_path / "r"),
        ]
    )
    assert_one_error_line(rc, capsys.readouterr().err, "vertex index 7")
    assert not (tmp_path / "r").exists()


def test_ascii_stl_with_bad_facet_normal_is_quiet(tmp_path, capsys):
    stl = tmp_path / "n.stl"
    stl.write_text(
        "solid x\nfacet normal a b c\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
        "endloop\nendfacet\nendsolid x\n"
    )
    rc, out, err = render(["--frames", "1", "--scene", str(stl)], tmp_path / "o", capsys)
    assert (rc, err) == (0, "")  # trimesh's logged traceback is kept off stderr
    assert "(3 vertices, 3 edges)" in out  # the triangle itself is read: the normals are unused


def test_float32_tiny_fov_is_one_line_without_warnings(tmp_path, capsys):
    rc, _, err = render(["--frames", "1", "--dtype", "float32", "--fov", "1e-300"], tmp_path / "o", capsys)
    assert_one_error_line(rc, err, "--fov 1e-300 with --dtype float32", "overflows float32")


def test_stl_with_nan_vertex_is_one_line(tmp_path, capsys):
    stl = tmp_path / "nan.stl"
    stl.write_text(
        "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 nan\nvertex 1 0 0\nvertex 0 1 0\n"
        "endloop\nendfacet\nendsolid x\n"
    )
    rc, _, err = render(["--frames", "1", "--scene", str(stl)], tmp_path / "o", capsys)
    assert_one_error_line(rc, err, f"{stl}:4: vertex coordinate 'nan': expected a finite number")  # its line


def test_winding_warning_never_precedes_an_error(tmp_path, capsys):
    scene = tmp_path / "w.scene"
    # faces 0-1-2 and 0-1-3 run edge 0->1 the same way (inconsistent winding); vertex 0's pixel
    # x = f * 1e308 / 4 overflows float64 in frame 1
    scene.write_text("v 1e308 0 0\nv 0 1 0\nv 0 0 1\nv 1 1 1\nf 0 1 2\nf 0 1 3\n")
    rc, _, err = render(["--frames", "2", "--scene", str(scene)], tmp_path / "o", capsys)
    assert_one_error_line(rc, err, "projects beyond the float64 range")
    assert not (tmp_path / "o").exists()


def test_winding_warning_still_shown_on_success(tmp_path, capsys):
    scene = tmp_path / "w.scene"
    scene.write_text("v 0 0 0\nv 0 1 0\nv 0 0 1\nv 1 1 1\nf 0 1 2\nf 0 1 3\n")
    rc, _, err = render(["--frames", "1", "--scene", str(scene)], tmp_path / "o", capsys)
    assert rc == 0 and err.startswith("renderer: warning: ") and err.count("\n") == 1


def test_message_with_newlines_is_one_line():
    assert (
        str(InputError("--candidate 'x.py:f': importing x.py failed: ImportError: a\nb\n  c"))
        == "--candidate 'x.py:f': importing x.py failed: ImportError: a | b | c"
    )
    assert one_line("no break") == "no break"


def test_candidate_import_error_with_newline(tmp_path, capsys):
    cand = tmp_path / "cand.py"
    cand.write_text("raise ImportError('first line\\nsecond line')\n")
    crosscheck_cli.main(
        [
            "--candidate",
            f"{cand}:f",
            "--scene",
            "cube",
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
    err = capsys.readouterr().err
    assert "Traceback" not in err
    if err:  # refused at load: one line holding both lines of the message
        assert err.count("\n") == 1 and "first line | second line" in err


def test_non_utf8_mesh_files_are_read(tmp_path, capsys):
    obj = tmp_path / "latin.obj"
    obj.write_bytes("# caf\xe9 (Latin-1)\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n".encode("latin-1"))
    rc, out, err = render(["--frames", "1", "--scene", str(obj)], tmp_path / "o", capsys)
    assert (rc, err) == (0, "") and "(3 vertices, 3 edges)" in out
    stl = tmp_path / "latin.stl"
    stl.write_bytes(
        "solid caf\xe9\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
        "endloop\nendfacet\nendsolid caf\xe9\n".encode("latin-1")
    )
    rc, out, err = render(["--frames", "1", "--scene", str(stl)], tmp_path / "o2", capsys)
    assert "charset_normalizer" not in err and "Traceback" not in err
    assert (rc, err) == (0, "") and "(3 vertices, 3 edges)" in out


# ---- limits --------------------------------------------------------------------------------------


def test_image_size_limit(tmp_path, capsys):
    rc, _, err = render(["--width", "100000", "--height", "100000"], tmp_path / "o", capsys)
    assert_one_error_line(rc, err, f"at most {MAX_SIDE} pixels a side")
    rc, _, err = render(["--width", "16384", "--height", "16384"], tmp_path / "o", capsys)
    assert_one_error_line(rc, err, "268,435,456 pixels", "at most 33,554,432")


def test_frame_count_limit(tmp_path, capsys):
    rc, _, err = render(["--frames", "100000000000000000000"], tmp_path / "o", capsys)
    assert_one_error_line(rc, err, f"1..{MAX_FRAMES:,}")


def test_polygon_size_limit(tmp_path):
    n = MAX_FACE_VERTICES + 1
    text = "".join(f"v {np.cos(t)} {np.sin(t)} 0\n" for t in np.linspace(0, 6, n)) + "f " + " ".join(map(str, range(n)))
    with pytest.raises(InputError, match=f"s.scene:{n + 1}: face of {n} indices: expected at most"):
        parse_scene_text(text, "s.scene")
    parse_scene_text(text.rsplit(" ", 1)[0], "s.scene")  # MAX_FACE_VERTICES indices: accepted


# ---- the guard: a bug is exit 3 and a log, never a traceback -----------------------------------


def test_internal_error_renderer(tmp_path, capsys, monkeypatch):
    def boom(*a, **k):
        return 1 / 0

    monkeypatch.setattr(renderer_cli, "render_run", boom)
    rc, _, err = render(["--frames", "1"], tmp_path / "o", capsys)
    assert rc == 3 and err.count("\n") == 1 and "Traceback" not in err
    assert err.startswith("renderer: internal error: ZeroDivisionError: division by zero")
    log = err.split("the traceback is in ")[1].split(";")[0]
    text = open(log).read()
    os.unlink(log)
    assert "Traceback (most recent call last)" in text and "in boom" in text


def test_internal_error_crosscheck(tmp_path, capsys, monkeypatch):
    def boom(*a, **k):
        raise KeyError("x")

    monkeypatch.setattr(crosscheck_cli, "run_crosscheck", boom)
    rc = crosscheck_cli.main(["--scene", "cube", "--level", "vertices", "--report-dir", str(tmp_path / "r")])
    err = capsys.readouterr().err
    assert rc == 3 and err.count("\n") == 1 and err.startswith("crosscheck: internal error: KeyError")
    os.unlink(err.split("the traceback is in ")[1].split(";")[0])


# ---- never destroy what wirecheck did not write -------------------------------------------------


def test_user_folder_named_like_the_old_backup_survives(tmp_path, capsys):
    out = tmp_path / "out"
    assert render(["--frames", "2"], out, capsys)[0] == 0
    mine = out / ".cube-frames.old"
    mine.mkdir()
    (mine / "keep.txt").write_text("mine")
    assert render(["--frames", "3"], out, capsys)[0] == 0
    assert (mine / "keep.txt").read_text() == "mine"
    assert len([n for n in os.listdir(out / "cube-frames") if n != MARKER]) == 3


def test_write_test_symlink_and_file_survive(tmp_path, capsys):
    out = tmp_path / "out"
    out.mkdir()
    target = tmp_path / "precious.txt"
    target.write_text("data")
    os.symlink(target, out / ".wirecheck-write-test")
    assert render(["--frames", "1"], out, capsys)[0] == 0
    assert target.read_text() == "data" and (out / ".wirecheck-write-test").is_symlink()


@pytest.mark.parametrize("name", ["cube-report.txt", "cube-report.json", "cube.gif"])
def test_users_file_with_an_output_name_is_refused(tmp_path, capsys, name):
    out = tmp_path / "out"
    out.mkdir()
    (out / name).write_text("mine")
    rc, _, err = render(["--frames", "1", "--format", "png,gif"], out, capsys)
    assert_one_error_line(rc, err, name, "not written by wirecheck")
    assert (out / name).read_text() == "mine" and tree(out) == [name]


def test_output_edited_by_the_user_is_refused(tmp_path, capsys):
    out = tmp_path / "out"
    assert render(["--frames", "1"], out, capsys)[0] == 0
    (out / "cube-report.txt").write_text("my notes")
    rc, _, err = render(["--frames", "1"], out, capsys)
    assert_one_error_line(rc, err, "changed since wirecheck wrote it")
    assert (out / "cube-report.txt").read_text() == "my notes"


def test_users_manifest_file_is_refused(tmp_path, capsys):
    out = tmp_path / "out"
    out.mkdir()
    (out / MANIFEST).write_text("my own json")
    rc, _, err = render(["--frames", "1"], out, capsys)
    assert_one_error_line(rc, err, "not written by wirecheck")
    assert tree(out) == [MANIFEST]


def test_symlink_with_an_output_name_is_refused(tmp_path, capsys):
    out = tmp_path / "out"
    out.mkdir()
    target = tmp_path / "t.json"
    target.write_text("{}")
    os.symlink(target, out / "cube-report.json")
    rc, _, err = render(["--frames", "1"], out, capsys)
    assert_one_error_line(rc, err, "symbolic link")
    assert target.read_text() == "{}"


def test_report_json_as_a_directory_leaves_nothing(tmp_path, capsys):
    out = tmp_path / "out"
    (out / "cube-report.json").mkdir(parents=True)
    (out / "cube-report.json" / "x").write_text("mine")
    rc, _, err = render(["--frames", "2", "--format", "png,gif"], out, capsys)
    assert_one_error_line(rc, err, "cube-report.json")
    assert tree(out) == ["cube-report.json", "cube-report.json/x"]  # no cube-frames/, no cube.gif


def test_failed_run_removes_the_folders_it_created(tmp_path, capsys, monkeypatch):
    real = core_run._check_overflow

    def fail_in_frame_3(s, frame, k):
        if k == 3:
            raise InputError("stop")
        real(s, frame, k)

    monkeypatch.setattr(core_run, "_check_overflow", fail_in_frame_3)
    rc, _, _ = render(["--frames", "5", "--format", "png,gif,mp4"], tmp_path / "a" / "b", capsys)
    assert rc == 2 and tree(tmp_path) == []  # a/ and a/b/ were the run's: gone
    (tmp_path / "kept").mkdir()
    rc, _, _ = render(["--frames", "5", "--format", "png,gif,mp4"], tmp_path / "kept", capsys)
    assert rc == 2 and tree(tmp_path) == ["kept"]  # the user's folder stays, empty


@pytest.mark.parametrize("where", ["in_scenes", "named_like_a_scene"])
def test_report_dir_never_shadows_a_scene(tmp_path, capsys, where):
    target = SCENE_DIR / "evil.scene" if where == "in_scenes" else tmp_path / "evil.scene"
    rc = crosscheck_cli.main(
        ["--report-dir", str(target), "--scene", "cube", "--level", "vertices", "--frames", "1", "--cases", "on_axis"]
    )
    assert_one_error_line(rc, capsys.readouterr().err, "--report-dir")
    assert not target.exists()


def test_failed_crosscheck_creates_no_report_parent(tmp_path, capsys):
    rc = crosscheck_cli.main(["--report-dir", str(tmp_path / "a" / "r"), "--scene", "nosuch", "--level", "vertices"])
    assert rc == 2 and tree(tmp_path) == []


# ---- one writer at a time ------------------------------------------------------------------------

_HOLD = (
    "import fcntl, os, sys, time\n"
    "fd = os.open(sys.argv[1], os.O_RDWR | os.O_CREAT)\n"
    "fcntl.flock(fd, fcntl.LOCK_EX)\n"
    "os.write(fd, b'wirecheck lock pid %d\\n' % os.getpid())\n"
    "print('held', flush=True)\n"
    "time.sleep(60)\n"
)


def test_a_held_lock_is_refused_until_its_process_dies(tmp_path, capsys):
    """A live run's lock refuses a second run; SIGKILL of the holder frees it at once (the kernel drops flock)."""
    out = tmp_path / "out"
    out.mkdir()
    holder = subprocess.Popen([sys.executable, "-c", _HOLD, str(out / LOCK)], stdout=subprocess.PIPE)
    try:
        assert holder.stdout.readline() == b"held\n"
        rc, _, err = render(["--frames", "1"], out, capsys)
        assert_one_error_line(rc, err, f"being written by another wirecheck run (process {holder.pid})")
        assert not (out / "cube-report.json").exists()
    finally:
        holder.kill()
        holder.wait()
        holder.stdout.close()
    assert render(["--frames", "1"], out, capsys)[0] == 0  # killed: no lock left to block
    assert not (out / LOCK).exists()


@pytest.mark.parametrize("who", ["dead", "reused_by_sleep"])
def test_a_lock_file_whose_pid_is_gone_or_reused_never_blocks(tmp_path, capsys, who):
    """Issue 25: a pid-file lock blocked forever once its pid was reused (a `sleep`). An flock is the process's
    own: a file naming a dead pid, or a live unrelated one, holds no lock."""
    out = tmp_path / "out"
    out.mkdir()
    other = subprocess.Popen(["sleep", "60"])
    try:
        if who == "dead":
            other.kill()
            other.wait()
        (out / LOCK).write_text(f"wirecheck lock pid {other.pid}\n")
        assert render(["--frames", "1"], out, capsys)[0] == 0
        assert (out / "cube-report.json").is_file() and not (out / LOCK).exists()
    finally:
        other.kill()
        other.wait()


def test_users_file_named_like_the_lock_is_refused(tmp_path, capsys):
    out = tmp_path / "out"
    out.mkdir()
    (out / LOCK).write_text("mine")
    rc, _, err = render(["--frames", "1"], out, capsys)
    assert_one_error_line(rc, err, "not written by wirecheck")
    assert (out / LOCK).read_text() == "mine"


def test_two_renderers_on_one_out_never_mix(tmp_path):
    """Pairs of runs of different lengths at once: each exits 0 or refuses (2, the lock); the set is one run's."""
    out = tmp_path / "out"
    cmd = [sys.executable, "-m", "wirecheck.core.app.cli", "--width", "64", "--height", "48", "--out", str(out)]
    for pair in range(4):
        procs = [
            subprocess.Popen([*cmd, "--frames", str(n)], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
            for n in (20 + pair, 27 + pair)
        ]
        results = [(p.wait(), p.stderr.read().decode()) for p in procs]
        for p in procs:
            p.stdout.close()
            p.stderr.close()
        for rc, err in results:
            assert rc == 0 or (rc == 2 and "being written by another wirecheck run" in err), err
        assert any(rc == 0 for rc, _ in results)
        frames = len([n for n in os.listdir(out / "cube-frames") if n != MARKER])
        report = json.loads((out / "cube-report.json").read_text())
        assert frames == report["summary"]["frames"]
        assert [n for n in os.listdir(out) if n.endswith(".tmp") or n == LOCK] == []


# ---- killed: nothing half-written ------------------------------------------------------------------


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT])
def test_killed_run_leaves_nothing(tmp_path, sig):
    out = tmp_path / "out"
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "wirecheck.core.app.cli",
            "--frames",
            "2000",
            "--verbose",
            "--format",
            "png,gif",
            "--out",
            str(out),
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    for _ in range(3):
        proc.stdout.readline()  # "Scene: ...", frames 1 and 2: it is writing
    proc.send_signal(sig)
    err = proc.communicate(timeout=60)[1].decode()
    assert proc.returncode == 128 + sig and "Traceback" not in err and err.count("\n") == 1
    assert not out.exists()  # the run created out/: removed with its temporaries


def test_killed_rerun_keeps_the_earlier_output(tmp_path):
    out = tmp_path / "out"
    assert (
        subprocess.run(
            [sys.executable, "-m", "wirecheck.core.app.cli", "--frames", "2", "--out", str(out)], capture_output=True
        ).returncode
        == 0
    )
    before = {n: (out / n).read_bytes() for n in ("cube-report.json", "cube-report.txt")}
    proc = subprocess.Popen(
        [sys.executable, "-m", "wirecheck.core.app.cli", "--frames", "2000", "--verbose", "--out", str(out)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    for _ in range(3):
        proc.stdout.readline()
    time.sleep(0.2)
    proc.terminate()
    proc.communicate(timeout=60)
    assert proc.returncode == 143
    assert {n: (out / n).read_bytes() for n in before} == before
    assert sorted(os.listdir(out)) == [MANIFEST, "cube-frames", "cube-report.json", "cube-report.txt"]


def test_api_mesh_loading_is_quiet_too(tmp_path):
    """load_scene (the API, no CLI guard around it) keeps trimesh's logged traceback off stderr.

    In a fresh interpreter: pytest's own log capture would hide the traceback.
    """
    stl = tmp_path / "n.stl"
    stl.write_text(
        "solid x\nfacet normal a b c\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
        "endloop\nendfacet\nendsolid x\n"
    )
    proc = subprocess.run(
        [
            sys.executable,
            "-c",
            "import sys; from wirecheck import load_scene; print(len(load_scene(sys.argv[1]).vertices))",
            str(stl),
        ],
        capture_output=True,
        text=True,
    )
    assert (proc.stdout, proc.stderr) == ("3\n", "")


@pytest.mark.slow
def test_crosscheck_users_old_folder_survives_a_report_replace(tmp_path, capsys):
    args = [
        "--report-dir",
        str(tmp_path / "r"),
        "--scene",
        "cube",
        "--cases",
        "on_axis",
        "--level",
        "vertices",
        "--frames",
        "1",
    ]
    assert crosscheck_cli.main(args) == 0
    mine = tmp_path / ".r.old"
    mine.mkdir()
    (mine / "keep.txt").write_text("mine")
    assert crosscheck_cli.main(args) == 0
    assert (mine / "keep.txt").read_text() == "mine"
    assert sorted(p.name for p in tmp_path.iterdir()) == [".r.old", "r"]  # no other leftovers


def test_settings_line_from_the_config_never_precedes_an_error(tmp_path, capsys, monkeypatch):
    (tmp_path / "pyproject.toml").write_text('[tool.wirecheck]\nframes = 3\nlevel = "vertices"\n')
    monkeypatch.chdir(tmp_path)
    rc = crosscheck_cli.main(["--scene", "nosuch", "--report-dir", str(tmp_path / "r")])
    assert_one_error_line(rc, capsys.readouterr().err, "--scene 'nosuch'")


def test_trace_with_a_far_plane_near_the_float64_limit(tmp_path, capsys):
    """GL's clip z row holds 2 f n / (n - f): with far 1e308 it overflows; the trace says so (null in JSON)."""
    rc, out, err = render(["--frames", "1", "--trace-vertex", "0", "--far", "1e308"], tmp_path / "o", capsys)
    assert (rc, err) == (0, "")
    trace = json.loads((tmp_path / "o" / "cube-report.json").read_text())["trace"][0]
    assert trace["clip"][2] is None and trace["clip"][3] == trace["depth"]  # w = z_cam, finite
    assert "overflow" in out


def test_crosscheck_frame_count_limit(tmp_path, capsys):
    rc = crosscheck_cli.main(
        [
            "--frames",
            "100000000000000000000",
            "--scene",
            "cube",
            "--level",
            "vertices",
            "--report-dir",
            str(tmp_path / "r"),
        ]
    )
    assert_one_error_line(rc, capsys.readouterr().err, f"1..{MAX_FRAMES:,}")


def test_run_under_report_dir_never_creates_a_scene_named_folder(tmp_path, capsys):
    target = tmp_path / "evil.scene"
    rc = crosscheck_cli.main(
        [
            "--report-dir",
            str(target),
            "--run",
            "r1",
            "--scene",
            "cube",
            "--level",
            "vertices",
            "--frames",
            "1",
            "--cases",
            "on_axis",
        ]
    )
    assert_one_error_line(rc, capsys.readouterr().err, "evil.scene")
    assert not target.exists()


def test_run_name_too_long_leaves_no_reports_folder(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    rc = crosscheck_cli.main(
        ["--run", "x" * 300, "--scene", "cube", "--level", "vertices", "--frames", "1", "--cases", "on_axis"]
    )
    assert_one_error_line(rc, capsys.readouterr().err, "300 characters")
    assert tree(tmp_path) == []


# ---- a mesh file named on the command line: unparsable is a usage error, empty says so ------------

PLY_HEAD = (
    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
    "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
)
ASCII_STL = (
    "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid s\n"
)


def _binary_stl(count: int, triangles: int) -> bytes:
    """A binary STL whose header declares ``count`` triangles and that holds ``triangles`` (zeros) of 50 bytes."""
    return b"\0" * 80 + count.to_bytes(4, "little") + b"\0" * (50 * triangles)


def crosscheck_file(path, tmp_path, capsys, *extra):
    """crosscheck --scene PATH at level vertices, one frame, one case: (rc, stdout, stderr)."""
    rc = crosscheck_cli.main(
        [
            "--scene",
            str(path),
            "--level",
            "vertices",
            "--frames",
            "1",
            "--cases",
            "on_axis",
            "--report-dir",
            str(tmp_path / "r"),
            *extra,
        ]
    )
    cap = capsys.readouterr()
    return rc, cap.out, cap.err


@pytest.mark.parametrize(
    "name, data, needle",
    [
        # binary data renamed .obj: before, an empty scene, exit 1 'vacuous' with nothing on stderr
        ("garbage.obj", b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR\xff\xfe", "garbage.obj:1: "),
        ("faces_only.obj", b"f 1 2 3\n", "faces_only.obj:1: face index '3': the file has no vertices"),
        (
            "negative.obj",
            b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n",
            "negative.obj:4: face index '-4': expected a 1-based index or -1..-3",
        ),
        (
            "zero.obj",
            b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n",
            "zero.obj:4: face index '0': expected a 1-based index or -1..-3",
        ),
        ("huge.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99999999999999999999\n", "huge.obj:4: face index '9999"),
        ("empty.stl", b"", "empty.stl: 0 bytes: expected a binary STL"),
        (
            "truncated.stl",
            _binary_stl(5, 2),
            "truncated.stl: 184 bytes, its header declares 5 triangles: expected 84 + 50 x 5 = 334 bytes",
        ),
        ("billion.stl", _binary_stl(10**9, 1), "billion.stl: 134 bytes, its header declares 1000000000 triangles"),
        ("cut.stl", ASCII_STL[:64].encode(), "cut.stl:5: the file ends inside a facet"),  # after 2 vertices
        ("cut_vertex.stl", ASCII_STL[:70].encode(), "cut_vertex.stl:6: 'vertex': expected 'vertex X Y Z'"),
        ("noend.stl", ASCII_STL[: -len("endsolid s\n")].encode(), "noend.stl:8: the file ends without endsolid"),
        (
            "foreign.stl",
            b"solid s\nfacet normal 0 0 1\nbogus line\n",
            "foreign.stl:3: 'bogus line': expected an ASCII STL",
        ),
        ("two.stl", ASCII_STL.replace("vertex 0 1 0\n", "").encode(), "two.stl:7: endfacet after 2 vertices"),
        # before: read as 3 vertices without faces, as no vertices, as no faces; the rest without a line
        ("header.off", b"NOTOFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n", "header.off:1: 'NOTOFF': expected the header 'OFF'"),
        ("negative.off", b"OFF\n-3 0 0\n", "negative.off:2: counts '-3 0 0': expected 'VERTICES FACES EDGES'"),
        (
            "noface.off",
            b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n",
            "noface.off:2: 3 vertices and 1 faces declared, 3 lines follow: expected a complete file",
        ),
        ("index.off", b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 9\n", "index.off:6: face '3 0 1 9': expected"),
        ("empty.off", b"", "empty.off:1: '(empty)': expected the header 'OFF'"),
        # before: "could not be read as GLTF: FileNotFoundError: model.gltf", naming a file that is not there
        ("broken.gltf", b'{"asset": ', "broken.gltf:1:11: not JSON (Expecting value): expected glTF JSON"),
        ("array.gltf", b"[1, 2]", "array.gltf: a JSON list: expected a glTF object"),
        (
            "few_vertices.ply",
            (PLY_HEAD + "0 0 0\n1 0 0\n").encode(),
            "few_vertices.ply:3: 'element vertex 3', but 2 vertices were read",
        ),
        (
            "few_faces.ply",
            (PLY_HEAD + "0 0 0\n1 0 0\n0 1 0\n3 0 1\n").encode(),  # a short row: trimesh drops it
            "few_faces.ply:7: 'element face 1', but 0 faces were read",
        ),
    ],
)
def test_unparsable_mesh_file_is_a_usage_error(tmp_path, capsys, name, data, needle):
    mesh = tmp_path / name
    mesh.write_bytes(data)
    rc, out, err = crosscheck_file(mesh, tmp_path, capsys)
    assert_one_error_line(rc, err, f"{tmp_path}/{needle}")
    assert out == "" and not (tmp_path / "r").exists()  # no report of a run that never started


@pytest.mark.parametrize(
    "name, text",
    [
        ("empty.obj", ""),
        ("groups.obj", "# exported\no thing\ng part\n"),
        ("empty.stl", "solid s\nendsolid s\n"),
        ("empty.scene", "# none\n"),
    ],
)
def test_valid_empty_file_is_vacuous_and_says_so_on_stderr(tmp_path, capsys, name, text):
    mesh = tmp_path / name
    mesh.write_text(text)
    stem = name.split(".")[0]
    line = f"crosscheck: {mesh}: no vertices: every case of scene {stem!r} compares nothing (vacuous: %s)\n"
    rc, _, err = crosscheck_file(mesh, tmp_path, capsys)
    assert (rc, err) == (1, line % "the run fails")  # a gate never passes on nothing
    rc, _, err = crosscheck_file(mesh, tmp_path, capsys, "--allow-vacuous", "--run", "allowed")
    assert (rc, err) == (0, line % "allowed by --allow-vacuous")


def test_loadable_meshes_are_still_read(tmp_path, capsys):
    """The checks above refuse nothing valid: a quad PLY (split into 2 triangles), negative OBJ indices,
    a binary STL whose header starts with 'solid', an OFF quad with its counts on the header line and a colour."""
    (tmp_path / "quad.ply").write_text(
        PLY_HEAD.replace("vertex 3", "vertex 4") + "0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n"
    )
    (tmp_path / "rel.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\n")
    (tmp_path / "c.off").write_text("# a comment\nOFF 4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3 255 0 0\n")
    tri = np.array([[0, 0, 1], [0, 0, 0], [1, 0, 0], [0, 1, 0]], "<f4").tobytes() + b"\0\0"
    (tmp_path / "b.stl").write_bytes(b"solid but binary".ljust(80, b" ") + (1).to_bytes(4, "little") + tri)
    for name, counts in (
        ("quad.ply", "(4 vertices, 5 edges)"),
        ("rel.obj", "(3 vertices, 3 edges)"),
        ("b.stl", "(3 vertices, 3 edges)"),
        ("c.off", "(4 vertices, 5 edges)"),
    ):
        rc, out, err = render(
            ["--frames", "1", "--scene", str(tmp_path / name)], tmp_path / name.replace(".", "_"), capsys
        )
        assert (rc, err) == (0, "") and counts in out, name


# ---- option values that would silently mean something else --------------------------------------


@pytest.mark.parametrize(
    "option", ["--scene", "--scene-list", "--report-dir", "--junit-xml", "--config", "--candidate-frames"]
)
def test_empty_path_option_is_a_usage_error(tmp_path, capsys, monkeypatch, option):
    # before: --scene '' ran the working directory as a dataset, --junit-xml '' wrote no XML,
    # --report-dir '' / --config '' fell back to their defaults
    monkeypatch.chdir(tmp_path)
    (tmp_path / "kept.obj").write_text("v 0 0 0\n")
    rc = crosscheck_cli.main(["--level", "vertices", "--frames", "1", "--cases", "on_axis", option, ""])
    assert_one_error_line(rc, capsys.readouterr().err, f"{option} '': expected a name or path")
    assert tree(tmp_path) == ["kept.obj"]


def test_renderer_empty_out_is_a_usage_error(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)  # before: frames and reports written into the working directory
    rc = renderer_cli.main(["--frames", "1", "--format", "ascii", "--out", ""])
    assert_one_error_line(rc, capsys.readouterr().err, "renderer: error: --out '': expected a name or path")
    assert tree(tmp_path) == []


def test_report_dir_through_a_symlink_loop_is_a_usage_error(tmp_path, capsys):
    (tmp_path / "a").symlink_to(tmp_path / "b")
    (tmp_path / "b").symlink_to(tmp_path / "a")
    rc = crosscheck_cli.main(
        ["--level", "vertices", "--frames", "1", "--cases", "on_axis", "--report-dir", str(tmp_path / "a")]
    )
    assert_one_error_line(rc, capsys.readouterr().err, f"--report-dir '{tmp_path}/a': Symlink loop")  # was exit 3


def test_scene_symlink_loop_and_fifo_are_named(tmp_path, capsys):
    (tmp_path / "a.obj").symlink_to(tmp_path / "b.obj")
    (tmp_path / "b.obj").symlink_to(tmp_path / "a.obj")
    os.mkfifo(tmp_path / "f.obj")
    for name, needle in (
        ("a.obj", "Too many levels of symbolic links"),
        ("f.obj", "a FIFO, not a regular file"),
        ("missing.obj", "file not found"),
    ):  # before: 'file not found' for all three
        rc, _, err = render(["--frames", "1", "--scene", str(tmp_path / name)], tmp_path / "o", capsys)
        assert_one_error_line(rc, err, f"--scene '{tmp_path / name}': {needle}")


# ---- a frames job (crosscheck export DIR) edited or damaged by hand --------------------------------


@pytest.fixture(scope="module")
def blank_job(tmp_path_factory):
    """A job of cube / on_axis, frames 1 and 3 of 4, with black PNGs at the camera's size (640x480)."""
    return helpers.blank_job(tmp_path_factory.mktemp("job") / "job")


def _set(*path_value):
    *path, value = path_value

    def edit(job):
        node = job
        for key in path[:-1]:
            node = node[key]
        node[path[-1]] = value

    return edit


@pytest.mark.parametrize(
    "edit, needle",
    [
        # before: exit 3 (a traceback in a log) for these three ...
        (_set("every", 0), "job.json: every 0: expected an integer in 1..frames (4)"),
        (_set("scenes", []), "job.json: scenes: expected a list of the job's scenes"),
        (_set("cases", 0, "scene", "sphere"), "job.json: case 'sphere' / 'on_axis': expected a scene of 'scenes'"),
        # ... and exit 1 with the value copied into the report, or the file read from elsewhere, for these
        (_set("frames", "x"), "job.json: frames 'x': expected an integer in 1..100000"),
        (_set("frames", True), "job.json: frames True: expected an integer"),
        (_set("frame_numbers", []), "job.json: frame_numbers []: expected 1, 1+every, ... up to frames"),
        (_set("motion", "turns", [float("nan"), 0, 0]), "job.json: motion.turns [nan, 0, 0]: expected three finite"),
        (_set("style", "shaded"), "job.json: style 'shaded': expected 'wireframe'"),
        (_set("scenes", 0, "obj", "/etc/passwd"), "job.json: scene 'cube': space 'model', obj '/etc/passwd': expected"),
        (_set("cases", 0, "width", 0), "job.json: case cube / on_axis: width x height 0x480: expected positive"),
        (
            _set("cases", 0, "frames", ["../../x.png", "frames/cube/on_axis/frame_0003.png"]),
            "job.json: case cube / on_axis: frames ['../../x.png'",
        ),
    ],
)
def test_edited_job_json_is_one_line_exit_2(blank_job, tmp_path, capsys, edit, needle):
    job_dir = tmp_path / "job"
    shutil.copytree(blank_job, job_dir)
    job = json.loads((job_dir / "job.json").read_text())
    edit(job)
    (job_dir / "job.json").write_text(json.dumps(job))
    rc = crosscheck_cli.main(["--candidate-frames", str(job_dir), "--report-dir", str(tmp_path / "r")])
    assert_one_error_line(rc, capsys.readouterr().err, f"{job_dir}/{needle}", "(export the job again)")
    assert not (tmp_path / "r").exists()


@pytest.mark.parametrize(
    "rel, data, needle",
    [
        # before: exit 3 for each (UnicodeDecodeError, JSONDecodeError, KeyError), exit 1 for the empty OBJ
        ("scenes/cube.obj", b"\xff\0garbage", "scenes/cube.obj: unreadable ('utf-8' codec"),
        ("scenes/cube.obj", b"", "scenes/cube.obj: 0 vertices, 0 edges: expected 8 and 12"),
        (
            "scenes/cube.obj",
            b"v 0 0 0\nl 1 2\n",
            "scenes/cube.obj:2: 'l 1 2': expected 'v X Y Z' (finite) or 'l I J' (1..1)",
        ),
        ("scenes/cube.obj", b"v 0 nan 0\n", "scenes/cube.obj:1: 'v 0 nan 0': expected 'v X Y Z' (finite)"),
        (
            "cameras/cube/on_axis/frame_0001.json",
            b"{",
            "cameras/cube/on_axis/frame_0001.json: unreadable (JSONDecodeError: ",
        ),
        (
            "cameras/cube/on_axis/frame_0001.json",
            b"{}",
            "cameras/cube/on_axis/frame_0001.json: unreadable (KeyError: no 'camera')",
        ),
        (
            "cameras/cube/on_axis/frame_0001.json",
            b'{"camera": {"width": 3}}',
            "cameras/cube/on_axis/frame_0001.json: camera: no 'position': expected position, forward, ",
        ),
    ],
)
def test_damaged_job_file_is_one_line_exit_2(blank_job, tmp_path, capsys, rel, data, needle):
    job_dir = tmp_path / "job"
    shutil.copytree(blank_job, job_dir)
    (job_dir / rel).write_bytes(data)
    rc = crosscheck_cli.main(["--candidate-frames", str(job_dir), "--report-dir", str(tmp_path / "r")])
    assert_one_error_line(rc, capsys.readouterr().err, f"{job_dir}/{needle}")
    assert not (tmp_path / "r").exists()


def test_the_blank_job_itself_is_judged(blank_job, tmp_path, capsys):
    """The set-up above is a valid job: unedited, its black frames are judged (vacuous? no: the oracle draws
    the cube, so every case fails), exit 1, nothing on stderr."""
    rc = crosscheck_cli.main(["--candidate-frames", str(blank_job), "--report-dir", str(tmp_path / "r")])
    cap = capsys.readouterr()
    assert (rc, cap.err) == (1, "") and "pixel F1@1px 0.0000 < 0.999" in cap.out


def test_scene_at_a_non_utf8_path_is_rendered(tmp_path, capsys):
    """Linux paths are bytes: b'm\\xfe.obj' reaches Python as 'm\\udcfe.obj', which UTF-8 cannot encode.
    Before, the summary's 'from PATH' line ended the run with exit 3; it is written with a backslash escape."""
    mesh = tmp_path / os.fsdecode(b"m\xfe.obj")
    mesh.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    rc, out, err = render(["--frames", "1", "--scene", str(mesh)], tmp_path / "o", capsys)
    assert (rc, err) == (0, "") and "(3 vertices, 3 edges)" in out
    first = (tmp_path / "o" / "m_-report.txt").read_text(encoding="utf-8").splitlines()[0]
    assert first == f"Scene: m_ (3 vertices, 3 edges) from {tmp_path}/m\\udcfe.obj"
