"""Outputs never destroy what wirecheck did not write; reruns replace earlier outputs."""

from pathlib import Path

import pytest
from wirecheck.core.app import cli as renderer_cli
from wirecheck.core.outputs.output import MARKER
from wirecheck.oracles import cli as crosscheck_cli


def test_rerun_replaces_earlier_frames(tmp_path):
    args = ["--frames", "3", "--out", str(tmp_path)]
    assert renderer_cli.main(args) == 0
    assert renderer_cli.main(["--frames", "2", "--out", str(tmp_path)]) == 0
    frames = sorted(p.name for p in (tmp_path / "cube-frames").iterdir() if p.name != MARKER)
    assert frames == ["frame_0001.png", "frame_0002.png"]  # the third is gone: a fresh set


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
    code = crosscheck_cli.main(
        ["--report-dir", str(target), "--scene", "cube", "--cases", "on_axis", "--frames", "1", "--oracles", "opencv"]
    )
    assert code == 2 and capsys.readouterr().err.count("\n") == 1
    assert (target.read_text() if make == "file" else (target / "important.txt").read_text()) == "keep"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["target"]  # no hidden leftovers


def test_crosscheck_replaces_its_own_earlier_report(tmp_path):
    args = ["--report-dir", str(tmp_path / "r"), "--scene", "cube", "--cases", "on_axis", "--oracles", "opencv"]
    assert crosscheck_cli.main([*args, "--frames", "1"]) == 0
    assert crosscheck_cli.main([*args, "--frames", "2"]) == 0
    assert '"frames": 2' in (tmp_path / "r" / "report.json").read_text()


@pytest.mark.parametrize("run", ["../escape", "a/b", ".hidden"])
def test_run_name_cannot_leave_reports(run, capsys):
    assert crosscheck_cli.main(["--run", run, "--scene", "cube", "--frames", "1"]) == 2
    assert "--run" in capsys.readouterr().err


@pytest.mark.parametrize(
    "text, needle",
    [
        ("name ../../escape\nv 0 0 0\n", "name '../../escape'"),
        ("name a/b\nv 0 0 0\n", "name 'a/b'"),
    ],
)
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
    proc = subprocess.Popen(
        [sys.executable, "-m", "wirecheck.core.app.cli", "--frames", "3", "--out", str(tmp_path)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    proc.stdout.readline()
    proc.stdout.close()
    err = proc.stderr.read().decode()
    proc.wait()
    assert "Traceback" not in err and proc.returncode in (0, 141)  # 0 if it finished before the close


# ---- a user's file inside a folder wirecheck wrote (issue 25, item 1) ----------------------------------


def _snapshot(folder):
    """Every path under ``folder`` with its bytes (None for a folder, the target for a link)."""
    import os

    out = {}
    for d, ds, fs in os.walk(folder):
        for n in ds + fs:
            p = os.path.join(d, n)
            rel = os.path.relpath(p, folder)
            out[rel] = os.readlink(p) if os.path.islink(p) else None if os.path.isdir(p) else open(p, "rb").read()
    return out


def _render_out(out):
    return renderer_cli.main(["--frames", "2", "--width", "64", "--height", "48", "--out", str(out)])


def _report(rep):
    return crosscheck_cli.main(
        ["--report-dir", str(rep), "--scene", "cube", "--cases", "on_axis", "--frames", "1", "--oracles", "opencv"]
    )


def _export(job):
    return crosscheck_cli.main(["export", str(job), "--scene", "cube", "--cases", "on_axis", "--frames", "2"])


def _unprojector_report(rep):
    spec = Path(__file__).parent / "data" / "unprojectors.py"
    return crosscheck_cli.main(
        [
            "--unprojector",
            f"{spec}:correct",
            "--report-dir",
            str(rep),
            "--scene",
            "cube",
            "--cases",
            "on_axis",
            "--frames",
            "1",
        ]
    )


#: (the command, the folder of ours it wrote, where in it the user's things go)
KINDS = {
    "renderer": (_render_out, "cube-frames"),
    "report": (_report, "."),
    "export": (_export, "."),
    "unprojector_report": (_unprojector_report, "."),
}


def _plant(folder, how):
    """Put the user's thing ``how`` into the folder of ours; its name (relative to ``folder``) for the message."""
    import os

    if how == "file":
        (folder / "analysis.md").write_text("my notes")
        return "analysis.md"
    if how == "nested":  # into a sub-folder wirecheck made (a report's img/, a job's cameras/)
        sub = next((p for p in sorted(folder.rglob("*")) if p.is_dir() and not p.name.startswith(".")), folder)
        (sub / "render.sh").write_text("#!/bin/sh\n")
        return str((sub / "render.sh").relative_to(folder))
    if how == "edited":  # a file of ours, changed since: the user's now
        mine = next(p for p in sorted(folder.rglob("*")) if p.is_file() and not p.name.startswith("."))
        mine.write_bytes(mine.read_bytes() + b"edited")
        return str(mine.relative_to(folder))
    if how == "folder":
        (folder / "mine").mkdir()
        return "mine/"
    if how == "link":
        os.symlink("/etc/hostname", folder / "link")
        return "link"
    raise AssertionError(how)


@pytest.mark.parametrize("how", ["file", "nested", "edited", "folder", "link"])
@pytest.mark.parametrize("kind", sorted(KINDS))
def test_a_users_thing_inside_a_folder_of_ours_is_never_touched(tmp_path, capsys, kind, how):
    """Before (issue 25): the folder carried the marker, so a rerun replaced it whole, deleting the user's
    file with exit 0. Now the rerun refuses with one line naming it, and nothing under the target changes."""
    command, sub = KINDS[kind]
    target = tmp_path / "t"
    assert command(target) == 0
    name = _plant(target / sub, how)
    before = _snapshot(tmp_path)
    capsys.readouterr()
    assert command(target) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    assert name.rstrip("/") in err and "nothing was changed" in err, err
    assert _snapshot(tmp_path) == before  # every byte, every name: no leftovers either


@pytest.mark.parametrize("kind", sorted(KINDS))
def test_a_rerun_over_our_own_folder_still_replaces_it(tmp_path, kind):
    """The listing holds every file of ours: an untouched earlier output is replaced, not refused."""
    command, sub = KINDS[kind]
    target = tmp_path / "t"
    assert command(target) == 0
    first = _snapshot(target)
    assert command(target) == 0
    assert sorted(_snapshot(target)) == sorted(first)
    assert [p.name for p in tmp_path.iterdir()] == ["t"]  # no temporaries, no lock left beside it


def test_a_legacy_empty_marker_lists_nothing(tmp_path, capsys):
    """A folder with the empty marker of an earlier wirecheck and other files: whose they are is unknown, so
    it is refused (the earlier rule replaced it whole)."""
    (tmp_path / "cube-frames").mkdir()
    (tmp_path / "cube-frames" / MARKER).write_bytes(b"")
    (tmp_path / "cube-frames" / "frame_0001.png").write_bytes(b"not known to be ours")
    assert _render_out(tmp_path) == 2
    assert "frame_0001.png (a file not written by wirecheck)" in capsys.readouterr().err
    assert (tmp_path / "cube-frames" / "frame_0001.png").read_bytes() == b"not known to be ours"


@pytest.mark.parametrize("name", ["cube-report.json", "cube-report.txt"])
def test_an_empty_folder_named_like_an_output_file_is_refused_up_front(tmp_path, capsys, name):
    """Before (issue 25): it passed the check, and the commit failed after cube-frames/ was moved in,
    leaving a mixed set that wedged every later run. Now: one line, nothing moved, and once the user's
    folder is gone the next run succeeds."""
    assert _render_out(tmp_path) == 0
    (tmp_path / name).unlink()
    (tmp_path / name).mkdir()
    before = _snapshot(tmp_path)
    capsys.readouterr()
    assert renderer_cli.main(["--frames", "3", "--width", "64", "--height", "48", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"{name}' is a directory where wirecheck writes a file" in err, err
    assert _snapshot(tmp_path) == before
    (tmp_path / name).rmdir()
    assert _render_out(tmp_path) == 0


def test_a_users_file_beside_the_outputs_survives_every_rerun(tmp_path):
    """--out is the user's folder: their files there are never in the set wirecheck moves."""
    (tmp_path / "notes.txt").write_text("keep")
    for _ in range(3):
        assert _render_out(tmp_path) == 0
    assert (tmp_path / "notes.txt").read_text() == "keep"
