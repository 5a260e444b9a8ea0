"""Mesh datasets: ``crosscheck --scene DIR`` / ``--scene-list FILE``, load errors, the summary, executors."""

import io
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest
from helpers import process_runs, run_crosscheck
from wirecheck.core.errors import InputError
from wirecheck.oracles import cli
from wirecheck.oracles.datasets.dataset import dataset_entries, read_list, walk_folder
from wirecheck.oracles.datasets.dataset_report import DatasetProgress


def run(tmp_path, *args, name="run"):
    return run_crosscheck(tmp_path, *map(str, args), name=name)


DATA = Path(__file__).parent / "data"
FAULTY = DATA / "faulty_projectors.py"
#: two cameras, two frames: each case still compares vertices and pixels, the run stays ~1 s a mesh set
FAST = ("--frames", "2", "--cases", "on_axis,orthographic")


def _mesh_folder(root: Path) -> Path:
    """box.obj (8 vertices, radius 0.87), sub/ico.ply (radius 2), cyl.stl (radius ~2.1), broken.obj (unreadable).

    Origin-centred primitives: the case cameras look at the origin.
    """
    import trimesh

    root.mkdir()
    (root / "sub").mkdir()
    trimesh.creation.box(extents=(1, 1, 1)).export(root / "box.obj")
    trimesh.creation.icosphere(subdivisions=1, radius=2.0).export(root / "sub" / "ico.ply")
    trimesh.creation.cylinder(radius=2.0, height=1.0, sections=12).export(root / "cyl.stl")
    (root / "broken.obj").write_text("v 1 2\n")  # a vertex of two coordinates
    (root / "notes.txt").write_text("not a mesh\n")
    return root


@pytest.fixture(scope="module")
def meshes(tmp_path_factory) -> Path:
    return _mesh_folder(tmp_path_factory.mktemp("dataset") / "meshes")


def _cli(argv) -> tuple[int, str, str]:
    """``crosscheck argv`` in this process: ``(code, stdout, stderr)``."""
    import contextlib

    o, e = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(o), contextlib.redirect_stderr(e):
        code = cli.main([str(a) for a in argv])
    return code, o.getvalue(), e.getvalue()


# ---------------------------------------------------------------- finding the meshes


def test_walk_is_recursive_sorted_and_counts_other_files(meshes):
    entries, other = walk_folder(meshes)
    assert [e.name for e in entries] == ["box.obj", "broken.obj", "cyl.stl", "sub/ico.ply"]
    assert other == 1  # notes.txt
    assert all(Path(e.path).is_absolute() and e.error is None for e in entries)


def test_link_loops_end_and_a_folder_is_walked_once(tmp_path):
    (tmp_path / "a").mkdir()
    (tmp_path / "a" / "m.obj").write_text("v 0 0 0\n")
    os.symlink("..", tmp_path / "a" / "up")  # a loop back to the root
    os.symlink(tmp_path / "a", tmp_path / "b")  # a second way into a/
    entries, _ = walk_folder(tmp_path)
    assert [e.name for e in entries] == ["a/m.obj"]  # 'a' sorts before 'b': b/ is the repeat


def test_an_unreadable_folder_is_an_entry_that_fails_to_load(tmp_path, monkeypatch):
    (tmp_path / "ok").mkdir()
    (tmp_path / "ok" / "m.obj").write_text("v 0 0 0\n")
    (tmp_path / "locked").mkdir()
    real = os.scandir

    def scandir(path):  # root reads every folder: refuse one the way a chmod 000 folder would
        if Path(path).name == "locked":
            raise PermissionError(13, "Permission denied")
        return real(path)

    monkeypatch.setattr(os, "scandir", scandir)
    entries, _ = walk_folder(tmp_path)
    assert [(e.name, e.error) for e in entries] == [
        ("locked", "folder could not be read: Permission denied"),
        ("ok/m.obj", None),
    ]


def test_several_folders_name_their_meshes_by_folder(tmp_path):
    for d in ("x", "y"):
        (tmp_path / d).mkdir()
        (tmp_path / d / "0001.obj").write_text("v 0 0 0\n")
    ds = dataset_entries([tmp_path / "y", tmp_path / "x"])
    assert [e.name for e in ds.entries] == [f"{tmp_path}/x/0001.obj", f"{tmp_path}/y/0001.obj"]


def test_scene_list_comments_blank_lines_and_relative_paths(tmp_path, meshes):
    lst = tmp_path / "lists" / "set.txt"
    lst.parent.mkdir()
    lst.write_text(
        f"# chosen meshes\n\n  {os.path.relpath(meshes / 'box.obj', lst.parent)}  \n"
        f"{meshes / 'sub' / 'ico.ply'}\n   # indented comment\nmissing.obj\n"
    )
    entries = read_list(lst)
    assert [Path(e.path) for e in entries] == [
        meshes / "box.obj",
        meshes / "sub" / "ico.ply",
        lst.parent / "missing.obj",
    ]
    assert entries[0].name == os.path.relpath(meshes / "box.obj", lst.parent)  # as written


@pytest.mark.parametrize(
    "text, message",
    [
        ("a.obj\nb.png\n", "set.txt:2: 'b.png': expected a mesh file ending in .obj"),
        ("a.obj\n./a.obj\n", "set.txt:2: './a.obj': listed twice (line 1)"),
        ("chairs/\n", "set.txt:1: 'chairs/': expected a mesh file"),
    ],
)
def test_scene_list_bad_lines_name_file_and_line(tmp_path, text, message):
    (tmp_path / "set.txt").write_text(text)
    with pytest.raises(InputError, match=None) as info:
        read_list(tmp_path / "set.txt")
    assert message in str(info.value)


# ---------------------------------------------------------------- inputs that compare nothing: exit 2


def _empty_list(tmp_path):
    p = tmp_path / "empty.txt"
    p.write_text("# only a comment\n\n")
    return ["--scene-list", p]


def _no_meshes(tmp_path):
    (tmp_path / "d").mkdir()
    (tmp_path / "d" / "a.fbx").write_text("x")
    return ["--scene", tmp_path / "d"]


def _none_loads(tmp_path):
    (tmp_path / "d").mkdir()
    (tmp_path / "d" / "a.obj").write_text("v 1 2\n")
    (tmp_path / "d" / "b.ply").write_text("not a ply\n")
    return ["--scene", tmp_path / "d"]


def _only_distorted(tmp_path):
    (tmp_path / "d").mkdir()
    (tmp_path / "d" / "a.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    return ["--scene", tmp_path / "d", "--cases", "distorted"]


def _empty_folder(tmp_path):
    (tmp_path / "d").mkdir()
    return ["--scene", tmp_path / "d"]


@pytest.mark.parametrize(
    "make, message",
    [
        (_empty_folder, "no mesh files in this folder (looked for .obj .ply .stl .off .glb .gltf; 0 other files)"),
        (_no_meshes, "no mesh files in this folder (looked for .obj .ply .stl .off .glb .gltf; 1 other files)"),
        (_empty_list, "no paths in this list (only blank lines and comments): nothing to check"),
        (_only_distorted, "cases distorted at level pixels: lens distortion: their pixels are not compared"),
        (_none_loads, "none of the 2 meshes could be loaded (first: a.obj: line 1: vertex 'v 1 2'"),
        (lambda t: ["--scene", "cube", "--scene", t], "--scene 'cube' with a dataset"),
        (lambda t: ["--scene-list", t / "nope.txt"], "nope.txt: missing: expected a scene list (one mesh path a line)"),
        (lambda t: ["--allow-load-errors"], "--allow-load-errors without a dataset"),
        (lambda t: ["--scene", t, "--sweep"], "with --sweep: expected a plain crosscheck run over the meshes"),
        (lambda t: ["--scene", t, "--scheduler", "localhost:8786"], "--scheduler 'localhost:8786': expected tcp://"),
        (lambda t: ["--scene", t, "--scheduler", "tcp://127.0.0.1:99999"], "expected tcp://HOST:PORT"),
        (lambda t: ["--scene", t, "--scheduler", "tcp://127.0.0.1:8786", "--jobs", "2"], "expected no --jobs"),
        (
            lambda t: ["--scene", t, "--executor", "local", "--scheduler", "tcp://127.0.0.1:8786"],
            "expected --executor dask",
        ),
        (lambda t: ["--scene", t, "--executor", "dask", "--scheduler-timeout", "3"], "3 without --scheduler"),
        (
            lambda t: ["--scene", t, "--scheduler", "tcp://127.0.0.1:8786", "--scheduler-timeout", "nan"],
            "--scheduler-timeout nan: expected a number of seconds > 0",
        ),
    ],
)
def test_errors_are_one_line_exit_2_and_write_nothing(tmp_path, make, message):
    args = make(tmp_path)
    out = tmp_path / "report"
    code, stdout, stderr = _cli(["--report-dir", out, *FAST, *args])
    assert code == 2
    assert stderr.count("\n") == 1 and stderr.startswith("crosscheck: error: ") and message in stderr, stderr
    assert "Traceback" not in stderr and stdout == ""
    assert not out.exists()


def _free_port() -> int:
    import socket

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_a_bundled_name_wins_over_a_folder_of_that_name(tmp_path, monkeypatch):
    (tmp_path / "cube").mkdir()  # a folder named like the bundled scene, in the working directory
    monkeypatch.chdir(tmp_path)
    code, report, _ = run(tmp_path, "--scene", "cube", "--level", "vertices", *FAST)
    assert code == 0 and "meshes" not in report and {c["scene"] for c in report["cases"]} == {"cube"}


def test_unreachable_scheduler_is_one_line_within_the_timeout(meshes, tmp_path):
    port = _free_port()  # nothing listens there once the socket is closed
    t0 = time.monotonic()
    # --level vertices: the run ends at connecting, before any mesh; the pixel level would only make
    # the process import pyrender and open OSMesa first (~0.7 s of CPU)
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "wirecheck.oracles.cli",
            "--scene",
            str(meshes),
            *FAST,
            "--level",
            "vertices",
            "--scheduler",
            f"tcp://127.0.0.1:{port}",
            "--scheduler-timeout",
            "1",
            "--report-dir",
            str(tmp_path / "r"),
        ],
        capture_output=True,
        text=True,
        timeout=120,
    )
    elapsed = time.monotonic() - t0
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr == (
        f"crosscheck: error: --scheduler tcp://127.0.0.1:{port}: no Dask scheduler answered "
        "within 1 s (OSError): expected a running 'dask scheduler' at that address\n"
    )
    assert proc.stdout == "" and not (tmp_path / "r").exists()
    # bounded, not a speed target: the 1 s wait plus importing wirecheck and Dask (~3 s here on a busy
    # 2-core machine); Dask's default connect timeout is 30 s, so waiting that long fails this
    assert elapsed < 25


# ---------------------------------------------------------------- the summary, against hand-known outcomes


def test_load_errors_are_counted_and_fail_the_run_unless_allowed(meshes, tmp_path):
    code, report, out = run(tmp_path, "--scene", meshes, *FAST)
    assert code == 1 and report["verdict"] == "fail"
    s = report["summary"]
    assert (s["meshes"], s["passed"], s["failed"], s["vacuous"], s["load_errors"]) == (4, 3, 0, 0, 1)
    assert s["cases"] == 3 * 2 and s["cases_failed"] == 0 and s["faults"] == []
    assert s["errors"] == [{"mesh": "broken.obj", "error": "line 1: vertex 'v 1 2': expected 'v X Y Z' (3 numbers)"}]
    assert [m["mesh"] for m in report["meshes"]] == ["box.obj", "broken.obj", "cyl.stl", "sub/ico.ply"]
    box = report["meshes"][0]
    # a triangulated box: 8 corners, 12 cube edges + 6 face diagonals
    assert (box["vertices"], box["edges"], box["faces"]) == (8, 18, 12)
    assert report["dataset"] == {"sources": [str(meshes)], "meshes": 4, "other_files": 1}

    code, report, _ = run(tmp_path, "--scene", meshes, *FAST, "--allow-load-errors", name="allowed")
    assert code == 0 and report["verdict"] == "pass" and report["summary"]["load_errors"] == 1


def test_summary_counts_faults_and_ranks_worst_cases(meshes, tmp_path, monkeypatch, capsys):
    monkeypatch.syspath_prepend(str(DATA))
    code, report, out = run(
        tmp_path, "--scene", meshes, *FAST, "--allow-load-errors", "--candidate", f"{FAULTY}:offset_when_large"
    )
    assert code == 1
    s = report["summary"]
    # the box (radius 0.87) is projected right; the icosphere and the cylinder (radius >= 2) half a pixel off
    assert (s["meshes"], s["passed"], s["failed"], s["load_errors"]) == (4, 1, 2, 1)
    assert s["cases"] == 6 and s["cases_failed"] == 4
    assert s["faults"] == [{"fault": "pixel_offset", "cases": 4, "meshes": 2}]
    assert {(c["scene"], c["camera"]) for c in s["worst_cases"][:4]} == {
        (m, cam) for m in ("cyl.stl", "sub/ico.ply") for cam in ("on_axis", "orthographic")
    }
    assert [c["verdict"] for c in s["worst_cases"]] == ["fail"] * 4 + ["pass"] * 2
    stdout = capsys.readouterr().out
    assert "Faults: pixel_offset 4 cases (2 meshes)" in stdout
    assert "FAIL: 1/4 meshes passed (2 failed; 1 could not be loaded, allowed)" in stdout
    md = (out / "report.md").read_text()
    assert "| cyl.stl | fail | on_axis, orthographic |" in md and "| broken.obj | line 1:" in md


def test_a_failed_case_ranks_worse_than_any_pass_whatever_its_f1():
    from wirecheck.oracles.datasets.dataset_run import worst_cases

    def case(mesh, verdict, f1):
        return {
            "scene": mesh,
            "camera": "on_axis",
            "verdict": verdict,
            "pixel_f1_1px": f1,
            "pixel_f1_0px": f1,
            "max_vertex_error_px": 0.0,
            "faults": [],
            "reasons": [],
            "compared": {"frames": 2},
        }

    meshes = [
        {"mesh": m, "cases": [case(m, v, f1)]}
        for m, v, f1 in [("a", "pass", 0.97), ("b", "fail", 1.0), ("c", "pass", 0.99), ("d", "vacuous", 1.0)]
    ]
    # b failed on a reason its F1 does not show (e.g. one-sided pixels): it is the worst
    assert [c["scene"] for c in worst_cases(meshes, n=3)] == ["b", "d", "a"]


def test_a_scene_list_with_a_missing_file_reports_it(meshes, tmp_path):
    lst = tmp_path / "set.txt"
    lst.write_text(f"{meshes / 'box.obj'}\ngone.obj\n")
    code, report, _ = run(tmp_path, "--scene-list", lst, *FAST)
    assert code == 1
    assert report["summary"]["errors"] == [{"mesh": "gone.obj", "error": "file not found"}]
    assert report["summary"]["passed"] == 1


# ---------------------------------------------------------------- same bytes wherever it ran


def _without_timing(out: Path) -> dict:
    report = json.loads((out / "report.json").read_text())
    report.pop("timing")
    return report


@pytest.fixture(scope="module")
def dask_scheduler() -> str:
    """The address of a Dask ``LocalCluster`` of 2 worker processes on 127.0.0.1, shared by this file's runs.

    Starting a cluster (a nanny and a worker process per worker, each importing
    distributed, then wirecheck and pyrender on its first task) costs ~6 s of CPU;
    the runs below reach this one with ``--scheduler``, as a user reaches theirs.
    The cluster ``crosscheck --executor dask`` starts itself without ``--scheduler``
    has its own test (test_the_default_dask_executor_starts_its_own_local_cluster).
    """
    import logging

    from distributed import LocalCluster
    from wirecheck.oracles.executors import _environ_kept

    # the nanny leaves OPENBLAS_NUM_THREADS=1 & co. in this process's environment, for every later
    # test's subprocess (oracles.executors._environ_kept): put back once the workers have started
    with _environ_kept():
        cluster = LocalCluster(
            n_workers=2,
            threads_per_worker=1,
            processes=True,
            host="127.0.0.1",
            dashboard_address=None,
            silence_logs=logging.CRITICAL,
        )
    with cluster:
        yield cluster.scheduler_address


@pytest.mark.slow
def test_report_is_the_same_for_jobs_1_jobs_2_and_a_dask_cluster(meshes, tmp_path, dask_scheduler):
    runs = {
        "one": ["--jobs", "1"],
        "two": ["--jobs", "2"],
        "dask": ["--executor", "dask", "--scheduler", dask_scheduler],
    }
    reports = {}
    for name, extra in runs.items():
        code, report, out = run(tmp_path, "--scene", meshes, *FAST, *extra, name=name)
        assert code == 1  # broken.obj
        reports[name] = (_without_timing(out), (out / "report.md").read_bytes())
        assert report["timing"]["executor"] == ("dask" if name == "dask" else "local")
    timing = json.loads((tmp_path / "dask" / "report.json").read_text())["timing"]
    assert (timing["workers"], timing["scheduler"]) == (2, dask_scheduler)
    assert reports["one"] == reports["two"] == reports["dask"]
    assert reports["one"][0]["summary"]["passed"] == 3  # and they compared something


@pytest.mark.slow
def test_a_plain_run_on_a_dask_cluster_gives_the_report_of_jobs_1(tmp_path, dask_scheduler):
    args = ("--scene", "cube", "--scene", "pyramid", *FAST)
    code1, r1, out1 = run(tmp_path, *args, name="one")
    code2, r2, out2 = run(tmp_path, *args, "--executor", "dask", "--scheduler", dask_scheduler, name="dask")
    assert code1 == code2 == 0
    assert (r2["timing"]["executor"], r2["timing"]["workers"]) == ("dask", 2)
    assert _without_timing(out1) == _without_timing(out2)
    assert (out1 / "report.md").read_bytes() == (out2 / "report.md").read_bytes()


@pytest.mark.slow
def test_a_clusters_workers_keep_no_idle_program_per_earlier_candidate(tmp_path, dask_scheduler):
    # A cluster's workers outlive the runs they serve. Three runs of three candidates (each host
    # records its pid when it starts): without the bound, every host started would still be
    # running after the runs, idle (3 or more); with it, each of the 2 workers keeps at most
    # the program of the last run it served.
    pids = tmp_path / "pids"
    for k in range(3):
        cand = tmp_path / f"cand{k}.py"
        cand.write_text(
            f"import os\nwith open({str(pids)!r}, 'a') as fh:\n    fh.write(f'{{os.getpid()}}\\n')\n"
            "from wirecheck.core.projector.projection import project_points as f\n"
        )
        code, report, _ = run(
            tmp_path,
            "--candidate",
            f"{cand}:f",
            "--scene",
            "cube",
            *FAST,
            "--level",
            "vertices",
            "--executor",
            "dask",
            "--scheduler",
            dask_scheduler,
            name=f"r{k}",
        )
        assert code == 0 and report["summary"]["passed"] == 2
    started = [int(x) for x in pids.read_text().split()]
    assert len(set(started)) >= 3  # each run started its own program
    assert sum(process_runs(pid) for pid in set(started)) <= 2


@pytest.mark.slow
def test_the_default_dask_executor_starts_its_own_local_cluster(tmp_path, monkeypatch):
    # no --scheduler: crosscheck starts a LocalCluster of --jobs workers but no more than the tasks
    # (here one: a second worker would only import wirecheck for nothing), runs on it and closes it
    args = ("--scene", "cube", "--frames", "2", "--cases", "oblique_roll")
    code1, r1, out1 = run(tmp_path, *args, name="one")
    # Dask's nanny sets these in the starting process for its workers: crosscheck puts them back
    monkeypatch.setenv("OMP_NUM_THREADS", "3")
    monkeypatch.delenv("OPENBLAS_NUM_THREADS", raising=False)
    code2, r2, out2 = run(tmp_path, *args, "--executor", "dask", "--jobs", "2", name="dask")
    assert (os.environ.get("OMP_NUM_THREADS"), os.environ.get("OPENBLAS_NUM_THREADS")) == ("3", None)
    assert code1 == code2 == 0
    assert (r2["timing"]["executor"], r2["timing"]["workers"]) == ("dask", 1)
    assert _without_timing(out1) == _without_timing(out2)
    assert (out1 / "report.md").read_bytes() == (out2 / "report.md").read_bytes()


# ---------------------------------------------------------------- progress


class _Tty(io.StringIO):
    def isatty(self):
        return True


def test_progress_bar_on_a_terminal_only():
    tty = _Tty()
    bar = DatasetProgress(tty)
    assert bar.active
    bar.update(0, 3)
    bar.update(2, 3)
    bar.close()
    assert "2/3" in tty.getvalue() and "mesh" in tty.getvalue()

    log = io.StringIO()
    bar = DatasetProgress(log)
    bar.update(0, 3)
    bar.update(3, 3)
    bar.close()
    assert not bar.active and log.getvalue() == ""


def test_cli_progress_is_off_when_stderr_is_not_a_terminal(meshes, tmp_path):
    code, stdout, stderr = _cli(["--report-dir", tmp_path / "r", "--scene", meshes, *FAST, "--allow-load-errors"])
    assert code == 0 and stderr == "" and "PASS: 3/4 meshes passed" in stdout


def test_a_deep_folder_is_walked_without_recursion(tmp_path):
    # deeper than the recursion limit allows a recursive walk: the limit is lowered to 100 frames above
    # this one (not the folder made deeper than 1000: shutil.rmtree, and so pytest's clean-up, recurse)
    depth = 0
    frame = sys._getframe()
    while frame is not None:
        depth, frame = depth + 1, frame.f_back
    deep = tmp_path
    for _ in range(200):
        deep = deep / "d"
        deep.mkdir()
    (deep / "m.obj").write_text("v 0 0 0\n")
    limit = sys.getrecursionlimit()
    sys.setrecursionlimit(depth + 100)
    try:
        entries, _ = walk_folder(tmp_path)
    finally:
        sys.setrecursionlimit(limit)
    assert [e.name for e in entries] == ["/".join(["d"] * 200) + "/m.obj"]
