"""Hostile Python candidates (issue 15): each fails its case with one reason; crosscheck exits 1 with a report.

Every candidate here runs in wirecheck's candidate host (oracles.candidates.candidate_host),
so what it does to its own process never reaches crosscheck's.
"""

import json
import subprocess
import sys
from pathlib import Path

import pytest
from helpers import process_runs  # tests/ is on sys.path (rootdir conftest)
from wirecheck.oracles import cli

ROOT = Path(__file__).parent.parent

#: (name, candidate source, a phrase the case's reason must hold)
HOSTILE = [
    (
        "os_exit_0_in_call",
        "import os\ndef f(p, c):\n    os._exit(0)\n",
        "candidate exited with status 0 during a request of 8 points",
    ),
    (
        "os_exit_0_at_import",
        "import os\nos._exit(0)\ndef f(p, c):\n    return p[:, :2]\n",
        "candidate exited with status 0 at start-up, before answering the protocol header",
    ),
    ("os_exit_3", "import os\ndef f(p, c):\n    os._exit(3)\n", "candidate exited with status 3 during"),
    ("keyboard_interrupt", "def f(p, c):\n    raise KeyboardInterrupt\n", "candidate raised KeyboardInterrupt"),
    ("generator_exit", "def f(p, c):\n    raise GeneratorExit('bye')\n", "candidate raised GeneratorExit: bye"),
    (
        "segfault",
        "import ctypes\ndef f(p, c):\n    ctypes.string_at(0)\n",
        "candidate was killed by signal SIGSEGV during a request of 8 points",
    ),
    (
        "huge_int",
        "def f(p, c):\n    return [[10**400, 0]] * len(p)\n",
        "candidate returned list that is not an array of floats (OverflowError",
    ),
    (
        "array_raises",
        "class A:\n    def __array__(self, *a, **k):\n        raise RuntimeError('no array')\n"
        "def f(p, c):\n    return A()\n",
        "(RuntimeError: no array)",
    ),
    (
        "float_raises",
        "class F:\n    def __float__(self):\n        raise ValueError('no float')\n"
        "def f(p, c):\n    return [[F(), F()] for _ in p]\n",
        "(ValueError: no float)",
    ),
    (
        "complex",
        "import numpy as np\ndef f(p, c):\n    return np.zeros((len(p), 2)) + 1j\n",
        "candidate returned complex numbers (complex128)",
    ),
]


def _crosscheck(tmp_path, source, *extra):
    cand = tmp_path / "hostile.py"
    cand.write_text(source)
    out = tmp_path / "report"
    code = cli.main(
        [
            "--candidate",
            f"{cand}:f",
            "--scene",
            "cube",
            "--cases",
            "on_axis,orthographic",
            "--frames",
            "2",
            "--level",
            "vertices",
            "--report-dir",
            str(out),
            *extra,
        ]
    )
    return code, json.loads((out / "report.json").read_text())


@pytest.mark.parametrize("name,source,reason", HOSTILE, ids=[h[0] for h in HOSTILE])
def test_hostile_candidate_fails_every_case_with_its_reason(tmp_path, capsys, name, source, reason):
    code, report = _crosscheck(tmp_path, source)
    err = capsys.readouterr().err
    assert code == 1 and report["verdict"] == "fail"
    assert report["summary"] == {**report["summary"], "cases": 2, "failed": 2}
    for case in report["cases"]:
        assert len(case["reasons"]) == 1 and case["reasons"][0].startswith("frame 1: ")
        assert reason in case["reasons"][0], case["reasons"]
    assert "Traceback" not in err and "Warning" not in err


def test_hang_times_out_and_the_next_case_gets_a_fresh_process(tmp_path, capsys):
    # the first process ever started sleeps; later ones (after the kill) answer correctly
    flag = tmp_path / "started-once"
    source = (
        f"import time, pathlib\nfrom wirecheck.core.projector.projection import project_points\n"
        f"FIRST = not pathlib.Path({str(flag)!r}).exists()\npathlib.Path({str(flag)!r}).touch()\n"
        "def f(p, c):\n    if FIRST:\n        time.sleep(60)\n    return project_points(p, c)\n"
    )
    code, report = _crosscheck(tmp_path, source, "--candidate-timeout", "0.5")
    first, second = report["cases"]
    assert code == 1
    assert first["reasons"] == [
        "frame 1: candidate timed out after 0.5 s on a request of 8 points; it was "
        "killed (and is started again for the next case)"
    ]
    assert second["verdict"] == "pass" and second["max_vertex_error_px"] < 1e-9


@pytest.mark.slow
def test_os_exit_0_as_a_real_process_exits_1_with_a_report(tmp_path):
    cand = tmp_path / "bye.py"
    cand.write_text("import os\ndef f(p, c):\n    os._exit(0)\n")
    # --level vertices: every case fails at its first request, before any pixel is drawn
    # (pixel_f1 is None at either level); the pixel level would only load pyrender for nothing.
    # Two cases: the second one's candidate is a fresh host after the first one's exit (each
    # further case would only start one more Python for the same check)
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "wirecheck.oracles.cli",
            "--candidate",
            f"{cand}:f",
            "--scene",
            "cube",
            "--frames",
            "1",
            "--cases",
            "on_axis,orthographic",
            "--level",
            "vertices",
            "--report-dir",
            str(tmp_path / "r"),
        ],
        capture_output=True,
        text=True,
        cwd=ROOT,
        timeout=300,
    )
    assert proc.returncode == 1 and proc.stderr == ""
    report = json.loads((tmp_path / "r" / "report.json").read_text())
    assert report["summary"]["failed"] == report["summary"]["cases"] == 2
    assert "FAIL: 0/2 cases" in proc.stdout


def test_candidate_stderr_and_prints_go_into_the_report_not_the_protocol(tmp_path):
    source = (
        "import sys\nfrom wirecheck.core.projector.projection import project_points\nprint('loaded')\n"
        "def f(p, c):\n    print('stdout of f')\n    print('stderr of f', file=sys.stderr)\n"
        "    return project_points(p, c)\n"
    )
    code, report = _crosscheck(tmp_path, source)
    assert code == 0
    # frames 1 and 2 of on_axis: one call each (vertex level); the import's print lands in the first case
    assert report["cases"][0]["candidate_stderr"] == "loaded\n" + "stdout of f\nstderr of f\n" * 2
    assert report["cases"][1]["candidate_stderr"] == "stdout of f\nstderr of f\n" * 2
    assert report["candidate_settings"]["isolation"] == "subprocess"


def test_bad_timeout_and_two_candidates_are_usage_errors(tmp_path, capsys):
    assert cli.main(["--candidate-timeout", "0", "--report-dir", str(tmp_path / "a")]) == 2
    assert "--candidate-timeout 0.0: expected a number of seconds > 0" in capsys.readouterr().err
    assert cli.main(["--candidate", "x.py:f", "--candidate-cmd", "true", "--report-dir", str(tmp_path / "b")]) == 2
    assert "expected one candidate" in capsys.readouterr().err


def test_a_candidate_hanging_at_import_fails_every_case_and_is_started_once(tmp_path, monkeypatch):
    from wirecheck.oracles.candidates import subprocess_candidate

    # long enough for the host to reach the file on a loaded machine: it starts in ~0.15 s
    # (test_the_candidate_host_loads_no_oracle_library), ~1 s beside two busy test workers
    monkeypatch.setattr(subprocess_candidate, "MIN_START_TIMEOUT_S", 2.5)
    starts = tmp_path / "starts"
    source = f"import time\nwith open({str(starts)!r}, 'a') as f:\n    f.write('start\\n')\ntime.sleep(60)\n"
    code, report = _crosscheck(tmp_path, source, "--candidate-timeout", "0.3")
    assert code == 1
    for case in report["cases"]:
        assert case["reasons"] == [
            "frame 1: candidate did not answer the protocol header within 2.5 s (start-up); it was killed"
        ]
    assert starts.read_text() == "start\n"  # not started again for the second case


LAZY = "def f(p, c):\n    import helper\n    return helper.g(p)\n"  # imports its sibling inside a call


RUNS, IMPORT_FAILS = "def f(p, c):\n    return p[:, :2] * 0.0\n", "raise ImportError('at import')\n"


@pytest.mark.parametrize(
    "isolated,source,code",
    [
        (True, RUNS, 1),
        (True, IMPORT_FAILS, 2),
        (True, LAZY, 1),
        (False, RUNS, 1),
        (False, IMPORT_FAILS, 2),
    ],
    ids=["host-runs", "host-import_fails", "host-imports_in_a_call", "in_process-runs", "in_process-import_fails"],
)
def test_the_candidates_folder_gets_no_bytecode_files(tmp_path, monkeypatch, isolated, source, code):
    # Python writes __pycache__/NAME.cpython-3X.pyc beside a module it imports unless told not to;
    # the candidate's folder is the user's, and wirecheck changes nothing it did not write. With
    # bytecode writing on, in this process and in the host it starts (found by tests/test_fuzz.py
    # where PYTHONDONTWRITEBYTECODE was unset). In this process (isolate=False): the next test.
    from wirecheck.oracles import api

    monkeypatch.delenv("PYTHONDONTWRITEBYTECODE", raising=False)
    monkeypatch.setattr(sys, "dont_write_bytecode", False)
    folder = tmp_path / "user"
    folder.mkdir()
    (folder / "proj.py").write_text(source)
    (folder / "helper.py").write_text("def g(p):\n    return p[:, :2] * 0.0\n")
    if isolated:
        got = cli.main(
            [
                "--candidate",
                f"{folder / 'proj.py'}:f",
                "--scene",
                "cube",
                "--cases",
                "on_axis",
                "--frames",
                "1",
                "--level",
                "vertices",
                "--report-dir",
                str(tmp_path / "rep"),
            ]
        )
        assert got == code
    elif code == 2:
        with pytest.raises(Exception, match="at import"):
            api.check_projector(f"{folder / 'proj.py'}:f", scenes=["cube"], cases=["on_axis"], frames=1, isolate=False)
    else:
        report = api.check_projector(
            f"{folder / 'proj.py'}:f", scenes=["cube"], cases=["on_axis"], frames=1, isolate=False
        )
        assert report["verdict"] == "fail"
    assert sorted(p.name for p in folder.rglob("*")) == ["helper.py", "proj.py"]
    assert sys.dont_write_bytecode is False  # set back after the import


def test_an_in_process_candidate_leaves_the_callers_imports_as_they_were(tmp_path, monkeypatch):
    # isolate=False: a FILE.py candidate's folder is importable while wirecheck imports and calls it
    # (a sibling imported inside a call is found), and gets no __pycache__ from that import. After
    # the check sys.path is the caller's again: left first there, the candidate's helper.py or
    # utils.py would shadow the caller's modules of those names for the rest of its test run.
    import uuid

    from wirecheck.oracles import api

    monkeypatch.delenv("PYTHONDONTWRITEBYTECODE", raising=False)
    monkeypatch.setattr(sys, "dont_write_bytecode", False)
    monkeypatch.setattr(sys, "path", list(sys.path))
    path_before = list(sys.path)
    sibling = f"sibling_{uuid.uuid4().hex}"  # not yet in sys.modules: really imported here
    folder = tmp_path / "user"
    folder.mkdir()
    (folder / "proj.py").write_text(f"def f(p, c):\n    import {sibling}\n    return {sibling}.g(p, c)\n")
    (folder / f"{sibling}.py").write_text(
        "from wirecheck.core.projector.projection import project_points\n"
        "def g(p, c):\n    return project_points(p, c)\n"
    )
    try:
        report = api.check_projector(
            f"{folder / 'proj.py'}:f", scenes=["cube"], cases=["on_axis"], frames=1, isolate=False
        )
    finally:
        sys.modules.pop(sibling, None)
    assert report["verdict"] == "pass"  # core's projection, reached through the sibling
    assert sorted(p.name for p in folder.rglob("*")) == sorted(["proj.py", f"{sibling}.py"])
    assert sys.path == path_before and sys.dont_write_bytecode is False


@pytest.mark.parametrize("how", ["cli", "api_file", "api_callable", "api_cmd"])
def test_a_candidates_process_ends_with_its_run(tmp_path, how):
    # a process making many runs (a user's pytest) must not keep an idle candidate process per
    # run: each run's program (host, fork or command) has ended and been reaped when it returns
    import os

    from wirecheck.oracles import api

    pids = tmp_path / "pids"
    source = (
        f"import os\nwith open({str(pids)!r}, 'a') as fh:\n    fh.write(f'{{os.getpid()}}\\n')\n"
        "def f(p, c):\n    return p[:, :2] * 0.0\n"
    )
    cand = tmp_path / "proj.py"
    cand.write_text(source)
    args = dict(scenes=["cube"], cases=["on_axis"], frames=1)
    if how == "cli":
        assert (
            cli.main(
                [
                    "--candidate",
                    f"{cand}:f",
                    "--scene",
                    "cube",
                    "--cases",
                    "on_axis",
                    "--frames",
                    "1",
                    "--level",
                    "vertices",
                    "--report-dir",
                    str(tmp_path / "rep"),
                ]
            )
            == 1
        )
    elif how == "api_file":
        assert api.check_projector(f"{cand}:f", **args)["verdict"] == "fail"
    elif how == "api_callable":

        def closure(p, c):  # not importable by another process: run in a fork
            pids.open("a").write(f"{os.getpid()}\n")
            return p[:, :2] * 0.0

        assert api.check_projector(closure, **args)["verdict"] == "fail"
    else:
        assert (
            api.check_projector(
                cmd=[sys.executable, "-m", "wirecheck.oracles.candidates.candidate_host", f"{cand}:f"], **args
            )["verdict"]
            == "fail"
        )
    started = {int(x) for x in pids.read_text().split()} - {os.getpid()}
    assert len(started) == 1, started  # one program, started once for the run
    assert not process_runs(started.pop())


@pytest.mark.parametrize("how", ["cmd_shell", "fork_child"])
def test_what_a_candidate_started_ends_with_its_run(tmp_path, how):
    # a program may start processes of its own (a shell's background job, a helper): they are in
    # its process group and end with the run, though the program itself exits cleanly on EOF
    import os

    from wirecheck.oracles import api

    pid_file = tmp_path / "child.pid"
    cand = tmp_path / "proj.py"
    cand.write_text("def f(p, c):\n    return p[:, :2] * 0.0\n")
    args = dict(scenes=["cube"], cases=["on_axis"], frames=1)
    if how == "cmd_shell":
        cmd = (
            f"sleep 300 & echo $! > {pid_file}; "
            f"exec {sys.executable} -m wirecheck.oracles.candidates.candidate_host {cand}:f"
        )
        assert api.check_projector(cmd=["sh", "-c", cmd], **args)["verdict"] == "fail"
    else:

        def closure(p, c):  # run in a fork; starts a child there, once
            import subprocess

            if not pid_file.exists():
                pid_file.write_text(str(subprocess.Popen(["sleep", "300"]).pid))
            return p[:, :2] * 0.0

        assert api.check_projector(closure, **args)["verdict"] == "fail"
    child = int(pid_file.read_text())
    assert child != os.getpid() and not process_runs(child)


def test_the_candidate_host_loads_no_oracle_library(tmp_path):
    # The host starts once per run (per worker): what it imports is start-up time of every
    # isolated candidate. It decodes requests and encodes replies: no scipy (convert's Rotation,
    # ~0.3 s of a 0.4 s start), OpenCV, pyrender, trimesh or matplotlib. The candidate records
    # the modules of the process it is called in.
    seen = tmp_path / "modules.json"
    cand = tmp_path / "proj.py"
    cand.write_text(
        f"import json, sys\ndef f(p, c):\n    with open({str(seen)!r}, 'w') as fh:\n"
        "        json.dump(sorted(sys.modules), fh)\n    return p[:, :2] * 0.0\n"
    )
    assert (
        cli.main(
            [
                "--candidate",
                f"{cand}:f",
                "--scene",
                "cube",
                "--cases",
                "on_axis",
                "--frames",
                "1",
                "--level",
                "vertices",
                "--report-dir",
                str(tmp_path / "rep"),
            ]
        )
        == 1
    )
    modules = json.loads(seen.read_text())
    heavy = ("scipy", "cv2", "pyrender", "trimesh", "matplotlib", "OpenGL")
    assert [m for m in modules if m.split(".")[0] in heavy] == []
    assert "wirecheck.oracles.candidates.protocol" in modules and "numpy" in modules  # the host's own modules are seen


def test_a_forked_candidates_imports_write_no_bytecode_files(tmp_path, monkeypatch):
    # a closure runs in a fork of this process (wirecheck's child, as the host): what it imports
    # there leaves no __pycache__ beside the imported module
    from wirecheck.oracles import api

    monkeypatch.setattr(sys, "dont_write_bytecode", False)
    folder = tmp_path / "user"
    folder.mkdir()
    (folder / "fork_helper.py").write_text("def g(p):\n    return p[:, :2] * 0.0\n")

    def closure(p, c):
        sys.path.insert(0, str(folder))
        import fork_helper

        return fork_helper.g(p)

    assert api.check_projector(closure, scenes=["cube"], cases=["on_axis"], frames=1)["verdict"] == "fail"
    assert "fork_helper" not in sys.modules  # imported in the child only
    assert sorted(p.name for p in folder.rglob("*")) == ["fork_helper.py"]


@pytest.mark.slow
@pytest.mark.parametrize("sig", ["SIGINT"])  # SIGTERM takes the same path (core.app.guard: both unwind alike)
def test_an_interrupted_run_with_workers_does_not_wait_for_hung_candidates(tmp_path, sig):
    # Both workers' candidates hang in a call (each writes its pid first); the run gets SIGINT
    # (sent to crosscheck's process only, as a CI runner's cancel does). The pool's own
    # shutdown would wait out the 60 s request timeout; the run ends at once instead (20 s: a
    # third of it, far above a loaded machine's seconds), with 130 / 143, and no candidate left.
    import signal
    import time

    called = tmp_path / "called"
    called.mkdir()
    cand = tmp_path / "hang.py"
    cand.write_text(
        f"import os, time\ndef f(p, c):\n    open(os.path.join({str(called)!r}, str(os.getpid())), 'w').close()\n"
        "    time.sleep(600)\n"
    )
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "wirecheck.oracles.cli",
            "--candidate",
            f"{cand}:f",
            "--scene",
            "cube",
            "--cases",
            "on_axis,orthographic",
            "--frames",
            "1",
            "--level",
            "vertices",
            "--jobs",
            "2",
            "--candidate-timeout",
            "60",
            "--report-dir",
            str(tmp_path / "rep"),
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    deadline = time.monotonic() + 60
    while len(list(called.iterdir())) < 2 and time.monotonic() < deadline and proc.poll() is None:
        time.sleep(0.05)
    hosts = [int(p.name) for p in called.iterdir()]
    assert len(hosts) == 2, proc.poll()  # both workers are inside a hung call
    t0 = time.monotonic()
    proc.send_signal(getattr(signal, sig))
    _out, err = proc.communicate(timeout=60)
    assert time.monotonic() - t0 < 20, err
    assert proc.returncode == 128 + getattr(signal, sig) and "Traceback" not in err
    deadline = time.monotonic() + 5  # the hosts die with their workers (SIGKILL)
    while any(process_runs(pid) for pid in hosts) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not any(process_runs(pid) for pid in hosts)
    assert not (tmp_path / "rep").exists()
