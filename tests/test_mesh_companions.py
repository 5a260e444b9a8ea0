"""Mesh loading never blocks on a companion file, and interrupts during trimesh's reading end the run (issue 25, 4-5).

A FIFO with no writer blocks ``open()`` forever: every test that could open one runs under an
alarm (in-process) or a subprocess timeout, so a regression fails the test instead of hanging the suite.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from helpers import no_block, run_renderer
from wirecheck.core.errors import InputError
from wirecheck.core.scene import mesh_companions
from wirecheck.core.scene.files import load_mesh_file
from wirecheck.oracles.datasets.dataset import dataset_entries

TRIANGLE = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"
ROOT = Path(__file__).resolve().parent.parent
CLI = {"renderer": "wirecheck.core.app.cli", "crosscheck": "wirecheck.oracles.cli"}


def _gltf(folder: Path, uri: str) -> Path:
    """A one-triangle glTF whose buffer is the file ``uri`` (36 bytes: 3 float32 vertices)."""
    doc = {
        "asset": {"version": "2.0"},
        "buffers": [{"uri": uri, "byteLength": 36}],
        "bufferViews": [{"buffer": 0, "byteLength": 36}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "max": [1, 1, 0], "min": [0, 0, 0]}
        ],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "nodes": [{"mesh": 0}],
        "scenes": [{"nodes": [0]}],
        "scene": 0,
    }
    path = folder / "m.gltf"
    path.write_text(json.dumps(doc))
    return path


def _mtllib_fifo(folder: Path) -> tuple[Path, str]:
    (folder / "a.obj").write_text("mtllib m.mtl\n" + TRIANGLE)
    os.mkfifo(folder / "m.mtl")
    return folder / "a.obj", "m.mtl"


def _texture_fifo(folder: Path) -> tuple[Path, str]:
    (folder / "b.obj").write_text("mtllib t.mtl\nusemtl x\n" + TRIANGLE)
    (folder / "t.mtl").write_text("newmtl x\nKd 1 0 0\nmap_Kd tex.png\n")
    os.mkfifo(folder / "tex.png")
    return folder / "b.obj", "tex.png"


def _buffer_fifo(folder: Path) -> tuple[Path, str]:
    os.mkfifo(folder / "buf.bin")
    return _gltf(folder, "buf.bin"), "buf.bin"


COMPANIONS = {"mtllib": _mtllib_fifo, "map_Kd": _texture_fifo, "gltf_buffer": _buffer_fifo}


@pytest.mark.parametrize("kind", COMPANIONS)
def test_a_fifo_companion_is_refused_by_name_never_opened(tmp_path, kind):
    mesh, companion = COMPANIONS[kind](tmp_path)
    with no_block(10), pytest.raises(InputError) as info:
        load_mesh_file(mesh)
    assert str(info.value) == (
        f"{mesh}: the file it names {companion!r} ({tmp_path / companion}): a FIFO, not a "
        "regular file: expected a file a mesh names (mtllib, texture, glTF buffer), a regular "
        "file of at most 2,048 MiB (docs/reliability.md)"
    )


def test_regular_companions_are_still_read(tmp_path):
    """The refusing resolver reads what trimesh's own reads: a glTF's buffer file gives its 3 vertices."""
    import numpy as np

    vertices = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], dtype="<f4")
    (tmp_path / "buf.bin").write_bytes(vertices.tobytes())
    scene = load_mesh_file(_gltf(tmp_path, "buf.bin"))
    assert scene.vertices.tolist() == vertices.tolist()


def test_a_companion_that_is_a_link_to_a_device_is_refused(tmp_path):
    """A link inside the mesh's folder to /dev/zero (an endless read) leaves the folder: trimesh's confinement
    refuses it before our check; the mesh loads without it, as with any missing material."""
    (tmp_path / "a.obj").write_text("mtllib z.mtl\n" + TRIANGLE)
    (tmp_path / "z.mtl").symlink_to("/dev/zero")
    with no_block(10):
        assert len(load_mesh_file(tmp_path / "a.obj").vertices) == 3


def test_renderer_refuses_a_fifo_companion_in_one_line(tmp_path):
    mesh, companion = _mtllib_fifo(tmp_path)
    with no_block(10):
        rc, _, err = run_renderer(["--scene", str(mesh), "--frames", "1"], tmp_path / "out")
    assert rc == 2 and err.count("\n") == 1 and f"the file it names {companion!r}" in err, err
    assert not (tmp_path / "out").exists()


def _cli(name, args, timeout=120, **kw):
    return subprocess.run(
        [sys.executable, "-c", f"import sys; from {CLI[name]} import main; sys.exit(main())", *args],
        capture_output=True,
        text=True,
        timeout=timeout,
        cwd=ROOT,
        **kw,
    )


def test_dataset_run_skips_fifos_and_reports_fifo_companions(tmp_path):
    """crosscheck --scene DIR: a FIFO named like a mesh is skipped with one line; a mesh whose mtllib is a
    FIFO is a load error naming it; the good mesh is checked. A subprocess with a timeout: a hang fails."""
    data = tmp_path / "data"
    data.mkdir()
    (data / "good.obj").write_text(TRIANGLE + "v 0 0 1\nf 1 3 4\n")
    _mtllib_fifo(data)
    os.mkfifo(data / "pipe.obj")
    proc = _cli(
        "crosscheck",
        [
            "--scene",
            str(data),
            "--level",
            "vertices",
            "--frames",
            "1",
            "--cases",
            "on_axis",
            "--allow-load-errors",
            "--report-dir",
            str(tmp_path / "rep"),
        ],
    )
    assert proc.returncode == 0, proc.stderr
    assert (
        "crosscheck: skipped 1 mesh-named file(s) that are not regular files, never opened: pipe.obj (a FIFO)"
    ) in proc.stderr.splitlines()
    report = json.loads((tmp_path / "rep" / "report.json").read_text())
    assert report["dataset"]["skipped"] == ["pipe.obj (a FIFO)"]
    verdicts = {m["mesh"]: m["verdict"] for m in report["meshes"]}
    assert verdicts == {"a.obj": "error", "good.obj": "pass"}
    error = next(m["error"] for m in report["meshes"] if m["mesh"] == "a.obj")
    assert "the file it names 'm.mtl'" in error and "a FIFO, not a regular file" in error, error


def test_dataset_walk_skips_non_regular_mesh_names_with_stat_only(tmp_path):
    (tmp_path / "a.obj").write_text(TRIANGLE)
    os.mkfifo(tmp_path / "p.obj")
    (tmp_path / "n.ply").symlink_to("/dev/null")  # a character device, through a link
    os.mkfifo(tmp_path / "other.txt")  # not mesh-named: counted as another file, as before
    with no_block(10):
        ds = dataset_entries([tmp_path])
    assert [e.name for e in ds.entries] == ["a.obj"]
    assert ds.skipped == (("n.ply", "a character device"), ("p.obj", "a FIFO"))
    assert ds.other_files == 1


def test_a_folder_of_only_fifos_is_nothing_to_check(tmp_path):
    os.mkfifo(tmp_path / "p.obj")
    with (
        no_block(10),
        pytest.raises(
            InputError,
            match=r"no mesh files in this folder .*1 mesh-named files that "
            r"are not regular files\): nothing to check",
        ),
    ):
        dataset_entries([tmp_path])


# ---- interrupts while trimesh reads: trimesh catches BaseException around material loading ----------


@pytest.mark.parametrize("sig, code", [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_a_signal_while_trimesh_reads_a_companion_ends_the_run(tmp_path, monkeypatch, sig, code):
    """The signal arrives inside trimesh's try/except BaseException (reading the .mtl): before, the run went
    on, wrote its outputs and exited 0."""
    (tmp_path / "a.obj").write_text("mtllib m.mtl\n" + TRIANGLE)
    (tmp_path / "m.mtl").write_text("newmtl x\nKd 1 0 0\n")
    real = mesh_companions.read_companion

    def read_and_signal(path):
        os.kill(os.getpid(), sig)  # delivered at the next bytecode: inside trimesh's handler
        return real(path)

    monkeypatch.setattr(mesh_companions, "read_companion", read_and_signal)
    rc, _, err = run_renderer(["--scene", str(tmp_path / "a.obj"), "--frames", "1"], tmp_path / "out")
    assert rc == code, err
    assert err == (
        f"renderer: interrupted by {signal.Signals(sig).name}: temporary files removed, "
        "earlier outputs left as they were\n"
    )
    assert not (tmp_path / "out").exists()


def test_sigint_from_outside_during_a_load_ends_the_run(tmp_path):
    """A real Ctrl-C from another process while trimesh waits in a companion read (made slow here: the
    read announces itself, then sleeps) ends the run with 130 and no outputs."""
    (tmp_path / "a.obj").write_text("mtllib m.mtl\n" + TRIANGLE)
    (tmp_path / "m.mtl").write_text("newmtl x\n")
    code = (
        "import sys, time\n"
        "from wirecheck.core.scene import mesh_companions as mc\n"
        "def slow(path):\n"
        "    print('reading', flush=True); time.sleep(60)\n"
        "mc.read_companion = slow\n"
        "from wirecheck.core.app.cli import main\n"
        f"sys.exit(main(['--scene', {str(tmp_path / 'a.obj')!r}, '--frames', '1', "
        f"'--out', {str(tmp_path / 'out')!r}]))\n"
    )
    proc = subprocess.Popen(
        [sys.executable, "-c", code], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=ROOT
    )
    try:
        assert proc.stdout.readline() == "reading\n"
        t0 = time.monotonic()
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 130, err
    assert time.monotonic() - t0 < 30 and "interrupted by SIGINT" in err
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize(
    "prog, module, sig, code",
    [
        ("renderer", "wirecheck.core.app.cli", signal.SIGINT, 130),
        ("crosscheck", "wirecheck.oracles.cli", signal.SIGTERM, 143),
    ],
)
def test_a_signal_while_the_cli_is_still_starting_is_one_line(prog, module, sig, code):
    """Between the CLI module's first line and its guard (the imports of numpy, trimesh, pyrender: seconds on a
    busy machine) a Ctrl-C printed a KeyboardInterrupt traceback. The console script's name turns the early
    handler on; the signal is sent where the imports have just finished, before main() runs."""
    script = (
        f"import os, signal, sys, time\nsys.argv[0] = '/venv/bin/{prog}'\nimport {module}\n"
        f"os.kill(os.getpid(), {int(sig)})\ntime.sleep(30)\nprint('not ended')\n"
    )
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120, cwd=ROOT)
    assert (proc.returncode, proc.stdout) == (code, "")
    assert proc.stderr == f"{prog}: interrupted by {signal.Signals(sig).name} while starting: nothing written\n"


def test_importing_the_cli_elsewhere_keeps_the_handlers():
    """A program (here pytest) that imports the CLI modules keeps its own SIGINT/SIGTERM handlers."""
    import wirecheck.core.app.cli  # noqa: F401
    import wirecheck.oracles.cli  # noqa: F401

    for sig in (signal.SIGINT, signal.SIGTERM):
        assert not getattr(signal.getsignal(sig), "wirecheck_starting", False)
