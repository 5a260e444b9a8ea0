"""Projector programs over the candidate protocol (docs/protocol.md): the C and three.js clients, and faults.

The reference clients live in tests/clients/ (``bash tests/clients/setup.sh``
installs cc, node and three). Locally a test skips when one is missing; CI
sets ``WIRECHECK_REQUIRE_CLIENTS=1`` (.ci/run), where a missing one fails.
"""

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from helpers import process_runs  # tests/ is on sys.path (rootdir conftest)
from wirecheck.oracles import cli
from wirecheck.oracles.candidates.subprocess_candidate import SubprocessCandidate
from wirecheck.oracles.cases import cameras_for
from wirecheck.oracles.references import opencv_oracle

CLIENTS = Path(__file__).parent / "clients"
THREE = CLIENTS / "three"
REQUIRED = os.environ.get("WIRECHECK_REQUIRE_CLIENTS") == "1"


def _missing(why):
    if REQUIRED:
        pytest.fail(f"{why} (WIRECHECK_REQUIRE_CLIENTS=1: tests/clients/setup.sh should have provided it)")
    pytest.skip(why)


@pytest.fixture(scope="module")
def c_client(tmp_path_factory):
    cc = shutil.which("cc")
    if cc is None:
        _missing("no C compiler (cc)")
    exe = tmp_path_factory.mktemp("c") / "candidate"
    subprocess.run([cc, "-O2", "-Wall", "-Werror", "-o", str(exe), str(CLIENTS / "candidate.c"), "-lm"], check=True)
    return str(exe)


@pytest.fixture(scope="module")
def node_client():
    node = shutil.which("node")
    if node is None:
        _missing("no node")
    if not (THREE / "node_modules" / "three" / "package.json").is_file():
        _missing("three is not installed: run bash tests/clients/setup.sh")
    return f"{node} {THREE / 'candidate.mjs'}"


def _points():
    """Points around the unit scene: inside, behind every case camera, beyond near and far."""
    rng = np.random.default_rng(11)
    return np.concatenate([rng.uniform(-2, 2, (1500, 3)), rng.uniform(-40, 40, (500, 3))])


def test_c_client_pixels_equal_opencv(c_client):
    cand = SubprocessCandidate.from_command(c_client)
    p_world = _points()
    near_scene = np.abs(p_world).max(axis=1) <= 2
    for case in cameras_for(1.0):
        cam = case.camera
        got = cand(p_world, cam)
        ref = opencv_oracle.project(p_world, cam)
        clipped = np.isnan(ref[:, 0])
        assert (np.isnan(got[:, 0]) == clipped).all() and 0 < clipped.sum() < len(p_world), case.name
        # Both sides are float64 from the same R, t, K (OpenCV rebuilds R from rvec). ~10 roundings of
        # eps = 2.2e-16, amplified by the cancellation |p_world| / depth (<= 40 / 0.1 = 400 here):
        # relative error <= 10 eps 400 < 1e-12 of the pixel coordinate.
        err = np.abs(got - ref).max(axis=1)
        size = np.maximum(np.abs(ref).max(axis=1), 1.0)
        assert (err[~clipped] <= 1e-12 * size[~clipped]).all(), case.name
        # Scene points (|x| <= 2, depth >= 0.1: amplification <= 35) landing within one image size of
        # the frame (|p_px| <= 2e3): 10 eps 35 2e3 = 1.5e-10 px, so 1e-9 px holds.
        framed = (
            ~clipped
            & near_scene
            & (np.abs(ref[:, 0] - cam.width / 2) <= 1.5 * cam.width)
            & (np.abs(ref[:, 1] - cam.height / 2) <= 1.5 * cam.height)
        )
        assert framed.sum() > 500 and err[framed].max() <= 1e-9, (case.name, err[framed].max())
    cand.close()


def test_c_client_passes_crosscheck_at_the_pixel_level(c_client, tmp_path):
    out = tmp_path / "r"
    assert (
        cli.main(
            [
                "--candidate-cmd",
                c_client,
                "--scene",
                "cube",
                "--scene",
                "pyramid",
                "--frames",
                "2",
                "--report-dir",
                str(out),
            ]
        )
        == 0
    )
    report = json.loads((out / "report.json").read_text())
    assert report["summary"]["passed"] == report["summary"]["cases"] == 14
    assert report["summary"]["max_vertex_error_px"] < 1e-9  # as above
    assert report["summary"]["min_pixel_f1_1px"] >= 0.999
    assert report["candidate_settings"] == {
        "isolation": "subprocess",
        "protocol": 1,
        "command": [c_client],
        "timeout_s": 10.0,
    }


def test_c_client_in_worker_processes_gives_the_same_report(c_client, tmp_path):
    reports = []
    for jobs in ("1", "2"):
        out = tmp_path / jobs
        assert (
            cli.main(
                [
                    "--candidate-cmd",
                    c_client,
                    "--scene",
                    "prism",
                    "--frames",
                    "2",
                    "--level",
                    "vertices",
                    "--jobs",
                    jobs,
                    "--report-dir",
                    str(out),
                ]
            )
            == 0
        )
        reports.append(json.loads((out / "report.json").read_text()))
    assert [c["per_frame"] for c in reports[0]["cases"]] == [c["per_frame"] for c in reports[1]["cases"]]


def test_three_js_client_passes_crosscheck(node_client, tmp_path):
    out = tmp_path / "r"
    assert (
        cli.main(
            [
                "--candidate-cmd",
                node_client,
                "--scene",
                "cube",
                "--scene",
                "prism",
                "--frames",
                "2",
                "--report-dir",
                str(out),
            ]
        )
        == 0
    )
    report = json.loads((out / "report.json").read_text())
    assert report["summary"]["passed"] == report["summary"]["cases"] == 14
    # three.js composes float64 matrices through a quaternion: ~1e-13 px measured; the gate is 1e-6
    assert report["summary"]["max_vertex_error_px"] < 1e-9
    assert report["summary"]["min_pixel_f1_1px"] >= 0.999


#: three.js's own pixel conventions and the faults derived by hand (tests/clients/three/candidate.mjs):
#: ours x = (ndc_x + 1) W/2 - 1/2, y = (1 - ndc_y) H/2 - 1/2.
#: "docs": x + 1/2, y + 1/2                 -> pixel_offset(dx=0.5, dy=0.5) and nothing else.
#: "webgl": x + 1/2, H - 1/2 - y; centred on cy = (H-1)/2 that is v -> -v + 1/2
#:                                          -> mirror_vertical, then pixel_offset(dx=0.5, dy=0.5).
THREE_FAULTS = {"docs": ["pixel_offset"], "webgl": ["mirror_vertical", "pixel_offset"]}


@pytest.mark.parametrize("convention", sorted(THREE_FAULTS))
def test_three_js_pixel_conventions_are_named(node_client, tmp_path, convention):
    out = tmp_path / "r"
    assert (
        cli.main(
            [
                "--candidate-cmd",
                f"{node_client} --pixels {convention}",
                "--frames",
                "2",
                "--level",
                "vertices",
                "--report-dir",
                str(out),
            ]
        )
        == 1
    )
    report = json.loads((out / "report.json").read_text())
    assert len(report["cases"]) == 21 and report["summary"]["failed"] == 21
    for case in report["cases"]:
        assert [f["name"] for f in case["faults"]] == THREE_FAULTS[convention], (case["scene"], case["camera"])
        offset = case["faults"][-1]
        # the offset is exact in binary (0.5) up to rounding of coordinates < 2e3 px: 1e-9 px
        assert abs(offset["dx"] - 0.5) < 1e-9 and abs(offset["dy"] - 0.5) < 1e-9
    if convention == "docs":  # a pure half-pixel shift: sqrt(0.5^2 + 0.5^2) px everywhere
        assert abs(report["summary"]["max_vertex_error_px"] - 0.5**0.5) < 1e-9


# ---- protocol faults, with tiny Python programs as the "other language"

PROGRAM_HEAD = """import json, struct, sys
i, o = sys.stdin.buffer, sys.stdout.buffer
assert i.readline() == b"wirecheck-candidate 1\\n"
"""
#: answer each request with (0, 0) pixels for its n points; BODY may change that
PROGRAM_LOOP = """o.write(b"wirecheck-candidate 1\\n"); o.flush()
k = 0
while True:
    line = i.readline()
    if not line:
        break
    n = json.loads(line)["n"]; i.read(24 * n); k += 1
    {body}
    o.write(json.dumps({{"n": n}}).encode() + b"\\n" + b"\\0" * (16 * n)); o.flush()
"""


def _program(tmp_path, body="pass", head=""):
    path = tmp_path / "prog.py"
    path.write_text(PROGRAM_HEAD + head + PROGRAM_LOOP.format(body=body))
    return f"{sys.executable} {path}"


def _run(tmp_path, command, *extra):
    out = tmp_path / "r"
    code = cli.main(
        [
            "--candidate-cmd",
            command,
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
    report = json.loads((out / "report.json").read_text()) if (out / "report.json").exists() else None
    return code, report


@pytest.mark.parametrize(
    "body,head,reason",
    [
        (
            "n += 1",
            "",
            "candidate answered 9 points to a request of 8: expected 8 (on a request of 8 points); it was killed",
        ),
        (
            'o.write(b"hello\\n"); o.flush(); continue',
            "",
            "candidate wrote garbage instead of a reply: b'hello\\n' (expected one JSON line) (on a request of 8 points); "
            "it was killed",
        ),
        (
            'o.write(b"{\\"error\\": \\"no camera for me\\"}\\n"); o.flush(); continue',
            "",
            "candidate reported an error: no camera for me",
        ),
        (
            'sys.stderr.write("dying now\\n"); sys.stderr.flush(); sys.exit(7)',
            "",
            "candidate exited with status 7 during a request of 8 points; its stderr ends: 'dying now'",
        ),
        (
            "pass",
            'o.write(b"hi\\n"); o.flush()\n',
            "candidate answered the header with b'hi\\n': expected b'wirecheck-candidate 1\\n'",
        ),
        (
            "pass",
            'o.write(b"wirecheck-candidate 2\\n"); o.flush()\n',
            "candidate speaks 'wirecheck-candidate 2': this wirecheck speaks 'wirecheck-candidate 1'",
        ),
    ],
    ids=["wrong_size", "garbage", "error_reply", "dies", "garbage_header", "other_version"],
)
def test_program_fault_fails_every_case_with_one_line(tmp_path, body, head, reason):
    code, report = _run(tmp_path, _program(tmp_path, body, head))
    assert code == 1 and report["summary"]["failed"] == 2
    for case in report["cases"]:
        assert case["reasons"] == [f"frame 1: {reason}"]


def test_a_program_that_hangs_is_killed_after_the_timeout(tmp_path):
    code, report = _run(tmp_path, _program(tmp_path, "import time; time.sleep(60)"), "--candidate-timeout", "0.3")
    assert code == 1
    assert report["cases"][0]["reasons"] == [
        "frame 1: candidate timed out after 0.3 s on a request of 8 points; "
        "it was killed (and is started again for the next case)"
    ]


def test_an_error_reply_keeps_the_program_and_its_stderr_goes_to_the_report(tmp_path):
    # the program says when it starts; after an error reply it is not restarted
    body = 'sys.stderr.write(f"request {k}\\n"); sys.stderr.flush()\n    if k == 1: o.write(b"{\\"error\\": \\"x\\"}\\n"); o.flush(); continue'
    code, report = _run(tmp_path, _program(tmp_path, body, 'sys.stderr.write("started\\n"); sys.stderr.flush()\n'))
    first, second = report["cases"]
    assert code == 1 and first["reasons"] == ["frame 1: candidate reported an error: x"]
    assert first["candidate_stderr"] == "started\nrequest 1\n"
    assert second["candidate_stderr"] == "request 2\nrequest 3\n"  # same process: two frames, no restart


def test_a_program_that_cannot_start_or_refuses_is_a_usage_error(tmp_path, capsys):
    code, _ = _run(tmp_path, str(tmp_path / "no-such-program"))
    assert code == 2
    assert "--candidate-cmd '" in (err := capsys.readouterr().err) and "No such file or directory" in err
    refuse = tmp_path / "refuse.py"
    refuse.write_text('import sys\nsys.stdin.readline()\nprint(\'{"error": "needs a GPU"}\', flush=True)\n')
    code, _ = _run(tmp_path, f"{sys.executable} {refuse}")
    assert code == 2
    assert capsys.readouterr().err.strip().endswith("candidate refused to start: needs a GPU")


def test_a_million_points_round_trip(c_client):
    # the protocol carries 24 MB in and 16 MB out per request (full duplex: no pipe deadlock)
    cand = SubprocessCandidate.from_command(c_client)
    camera = cameras_for(1.0)[1].camera
    p_world = np.random.default_rng(3).uniform(-1, 1, (1_000_000, 3))
    got = cand(p_world, camera)
    ref = opencv_oracle.project(p_world, camera)
    assert np.array_equal(np.isnan(got), np.isnan(ref))
    # points of the scene (|x| <= 1, depth >= 0.1): 10 eps 17 |p_px| relative, as in test_c_client_pixels_equal_opencv
    assert np.nanmax(np.abs(got - ref) / np.maximum(np.abs(ref), 1.0)) <= 1e-12
    cand.close()


def test_an_empty_command_is_a_usage_error_never_core(tmp_path, capsys):
    for option in ("--candidate-cmd", "--candidate"):
        assert cli.main([option, "  ", "--report-dir", str(tmp_path / "r")]) == 2
        assert capsys.readouterr().err.startswith(f"crosscheck: error: {option} '  ': expected ")
    assert not (tmp_path / "r").exists()


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="PR_SET_PDEATHSIG is Linux's")
def test_a_hung_program_does_not_outlive_a_killed_crosscheck(tmp_path):
    import signal
    import time

    pid_file = tmp_path / "pid"
    prog = tmp_path / "hang.py"
    prog.write_text(
        "import os, sys, time\nsys.stdin.buffer.readline()\n"
        f"open({str(pid_file)!r}, 'w').write(str(os.getpid()))\n"
        "sys.stdout.buffer.write(b'wirecheck-candidate 1\\n'); sys.stdout.flush()\ntime.sleep(600)\n"
    )
    parent = subprocess.Popen(
        [
            sys.executable,
            "-c",
            "import sys\nfrom wirecheck.oracles.candidates.subprocess_candidate import SubprocessCandidate\n"
            f"SubprocessCandidate(argv=(sys.executable, {str(prog)!r})).start()\n"
            "print('ready', flush=True)\nimport time; time.sleep(600)\n",
        ],
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert parent.stdout.readline() == "ready\n"
        pid = int(pid_file.read_text())
        assert process_runs(pid)
        parent.send_signal(signal.SIGKILL)  # no atexit, no cleanup: only the death signal can act
        parent.wait()
        for _ in range(100):  # the kernel delivers it at once; allow 5 s on a loaded machine
            if not process_runs(pid):
                break
            time.sleep(0.05)
        assert not process_runs(pid)
    finally:
        parent.kill()


def test_a_flood_on_stderr_keeps_its_last_64_kb(tmp_path):
    # 50 MB before the first reply: the pipe is drained while waiting, only the tail is kept (no disk)
    body = 'if k == 1: sys.stderr.buffer.write(b"y" + b"x" * (50 << 20)); sys.stderr.flush()'
    code, report = _run(tmp_path, _program(tmp_path, body))
    first = report["cases"][0]
    # the program answers (0, 0) for every point: a failing case, but a complete answer
    assert code == 1 and first["frames_checked"] == 2
    total = 1 + (50 << 20)
    assert first["candidate_stderr"] == f"[... {total - 65536} bytes before]\n" + "x" * 65536
    assert "candidate_stderr" not in report["cases"][1]


# ---- [tool.wirecheck] and the pytest plugin


def test_table_candidate_cmd_runs_and_a_command_line_candidate_replaces_the_tables(c_client, tmp_path, capsys):
    table = tmp_path / "pyproject.toml"
    table.write_text(
        f'[tool.wirecheck]\ncandidate-cmd = "{c_client}"\ncandidate-timeout = 5\n'
        'scenes = ["cube"]\ncases = ["on_axis"]\nframes = 2\nlevel = "vertices"\n'
    )
    out = tmp_path / "r"
    assert cli.main(["--config", str(table), "--report-dir", str(out)]) == 0
    report = json.loads((out / "report.json").read_text())
    assert report["candidate"] == c_client and report["candidate_settings"]["timeout_s"] == 5.0
    # the command line's --candidate (mirrored: fails) wins over the table's program
    mirrored = tmp_path / "mirrored.py"
    mirrored.write_text(
        "from wirecheck.core.projector.projection import project_points\n"
        "def f(p, c):\n    px = project_points(p, c)\n    px[:, 0] = c.width - 1 - px[:, 0]\n"
        "    return px\n"
    )
    assert cli.main(["--config", str(table), "--candidate", f"{mirrored}:f", "--report-dir", str(tmp_path / "m")]) == 1
    report = json.loads((tmp_path / "m" / "report.json").read_text())
    assert report["cases"][0]["faults"][0]["name"] == "mirror_horizontal"
    table.write_text(f'[tool.wirecheck]\ncandidate-cmd = "{c_client}"\ncandidate = "x.py:f"\n')
    capsys.readouterr()
    assert cli.main(["--config", str(table), "--report-dir", str(tmp_path / "b")]) == 2
    assert "both candidate and candidate-cmd: expected one of them" in capsys.readouterr().err


def test_the_pytest_fixture_judges_a_program(c_client, pytester):
    pytester.makepyprojecttoml(
        f'[tool.wirecheck]\ncandidate-cmd = "{c_client}"\nscenes = ["cube"]\nframes = 2\nlevel = "vertices"\n'
    )
    pytester.makepyfile(
        test_user=f"""
def test_table_program(wirecheck):
    report = wirecheck()                     # the table's candidate-cmd
    assert report["candidate"] == {c_client!r} and report["summary"]["passed"] == 7


def test_call_program(wirecheck):
    report = wirecheck(cmd={c_client!r}, cases=["orthographic"])
    assert report["summary"]["max_vertex_error_px"] < 1e-9
"""
    )
    pytester.runpytest().assert_outcomes(passed=2)
