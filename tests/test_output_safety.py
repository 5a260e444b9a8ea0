"""Outputs never destroy what wirecheck did not write; reruns replace earlier outputs."""

import pytest

from wirecheck.core import cli as renderer_cli
from wirecheck.core.output import MARKER
from wirecheck.oracles import cli as crosscheck_cli


def test_rerun_replaces_earlier_frames(tmp_path):
    args = ["--frames", "3", "--out", str(tmp_path)]
    assert renderer_cli.main(args) == 0
    assert renderer_cli.main(["--frames", "2", "--out", str(tmp_path)]) == 0
    frames = sorted(p.name for p in (tmp_path / "cube-frames").iterdir() if p.name != MARKER)
    assert frames == ["frame_0001.png", "frame_0002.png"]      # the third is gone: a fresh set


def test_renderer_refuses_a_foreign_frames_dir(tmp_path, capsys):
    mine = tmp_path / "cube-frames"
    mine.mkdir()
    (mine / "notes.txt").write_text("keep")
    assert renderer_cli.main(["--frames", "2", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "not written by wirecheck" in err
    assert (mine / "notes.txt").read_text() == "keep"
    assert not (tmp_path / "cube-report.json").exists()


@pytest.mark.parametrize("make", ["file", "foreign_dir"])
def test_crosscheck_refuses_to_replace_user_paths(tmp_path, capsys, make):
    target = tmp_path / "target"
    if make == "file":
        target.write_text("keep")
    else:
        target.mkdir()
        (target / "important.txt").write_text("keep")
    code = crosscheck_cli.main(["--report-dir", str(target), "--scene", "cube", "--cases", "on_axis",
                                "--frames", "1", "--oracles", "opencv"])
    assert code == 2 and capsys.readouterr().err.count("\n") == 1
    assert (target.read_text() if make == "file" else (target / "important.txt").read_text()) == "keep"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["target"]      # no hidden leftovers


def test_crosscheck_replaces_its_own_earlier_report(tmp_path):
    args = ["--report-dir", str(tmp_path / "r"), "--scene", "cube", "--cases", "on_axis", "--oracles", "opencv"]
    assert crosscheck_cli.main([*args, "--frames", "1"]) == 0
    assert crosscheck_cli.main([*args, "--frames", "2"]) == 0
    assert '"frames": 2' in (tmp_path / "r" / "report.json").read_text()


@pytest.mark.parametrize("run", ["../escape", "a/b", ".hidden"])
def test_run_name_cannot_leave_reports(run, capsys):
    assert crosscheck_cli.main(["--run", run, "--scene", "cube", "--frames", "1"]) == 2
    assert "--run" in capsys.readouterr().err


@pytest.mark.parametrize("text, needle", [
    ("name ../../escape\nv 0 0 0\n", "name '../../escape'"),
    ("name a/b\nv 0 0 0\n", "name 'a/b'"),
])
def test_scene_name_cannot_leave_out_dir(tmp_path, capsys, text, needle):
    scene = tmp_path / "s.scene"
    scene.write_text(text)
    assert renderer_cli.main(["--scene", str(scene), "--frames", "1", "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert f"{scene}:1: {needle}" in err and err.count("\n") == 1


def test_obj_short_vertex_line_names_the_line(tmp_path, capsys):
    obj = tmp_path / "l.obj"
    obj.write_text("v 0 0 0\nv 1 0\nl 1 2\n")
    assert renderer_cli.main(["--scene", str(obj), "--frames", "1", "--out", str(tmp_path / "o")]) == 2
    assert f"{obj}:2: vertex 'v 1 0'" in capsys.readouterr().err


def test_directory_as_scene(tmp_path, capsys):
    assert renderer_cli.main(["--scene", str(tmp_path), "--frames", "1"]) == 2
    assert "is a directory" in capsys.readouterr().err


def test_up_without_camera_pos_is_refused_not_ignored(tmp_path, capsys):
    assert renderer_cli.main(["--frames", "1", "--out", str(tmp_path), "--up", "1,0,0"]) == 2
    assert "--camera-pos" in capsys.readouterr().err


def test_closed_stdout_exits_quietly(tmp_path):
    import subprocess
    import sys

    # `renderer | head -1`: the reader goes away after the first line
    proc = subprocess.Popen([sys.executable, "-m", "wirecheck.core.cli", "--frames", "3", "--out", str(tmp_path)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    proc.stdout.readline()
    proc.stdout.close()
    err = proc.stderr.read().decode()
    proc.wait()
    assert "Traceback" not in err and proc.returncode in (0, 141)   # 0 if it finished before the close
