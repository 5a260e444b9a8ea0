"""Hostile projector programs against the candidate protocol (docs/protocol.md, "misbehaves").

The contract: whatever the program does, a request ends within its timeout
with pixels or one CandidateError naming what the program did and what was
expected; a reply that is not one is never taken for one; no process is left
behind. Faults already covered elsewhere (wrong n, garbage, a death, a hang,
another version, a stderr flood) are in tests/test_candidate_programs.py.
Each program here is a few lines of Python run with ``sys.executable``.
"""

import json
import re
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from helpers import process_runs  # tests/ is on sys.path (rootdir conftest)
from wirecheck.oracles import cli
from wirecheck.oracles.candidates import subprocess_candidate
from wirecheck.oracles.candidates.candidate import CandidateError, call_candidate
from wirecheck.oracles.candidates.subprocess_candidate import SubprocessCandidate
from wirecheck.oracles.cases import cameras_for

CAMERA = cameras_for(1.0)[1].camera
#: reads wirecheck's header; BODY then answers it (or not)
HEAD = "import json, os, signal, struct, sys, time\ni, o = sys.stdin.buffer, sys.stdout.buffer\ni.readline()\n"
HELLO = 'o.write(b"wirecheck-candidate 1\\n"); o.flush()\n'
#: read one whole request: n, then its points
READ = 'n = json.loads(i.readline())["n"]; i.read(24 * n)\n'
#: answer it with (0, 0) for every point
ZEROS = 'o.write(b"{\\"n\\": %d}\\n" % n + bytes(16 * n)); o.flush()\n'
SERVE = "while True:\n    " + READ + "    " + ZEROS


def _candidate(tmp_path, body, timeout_s=5.0) -> SubprocessCandidate:
    path = tmp_path / "prog.py"
    path.write_text(HEAD + body)
    return SubprocessCandidate(argv=(sys.executable, str(path)), timeout_s=timeout_s, label="prog")


def _fault(cand, n=8) -> str:
    """The one-line reason a request of ``n`` points fails with (the program is closed after)."""
    try:
        with pytest.raises(CandidateError) as info:
            call_candidate(cand, np.zeros((n, 3)), CAMERA)
    finally:
        cand.close()
    return str(info.value)


def _wait_for(path: Path) -> None:
    """Until ``path`` (written by the program) is there and not empty: 10 s for a loaded machine."""
    for _ in range(1000):
        if path.exists() and path.read_text():
            return
        time.sleep(0.01)


# ---- the header


@pytest.mark.parametrize(
    "hello,shown",
    [
        (b"wirecheck-candidate 1 \n", r"b'wirecheck-candidate 1 \n'"),
        (b"wirecheck-candidate 1\r\n", r"b'wirecheck-candidate 1\r\n'"),
        (b"\xef\xbb\xbfwirecheck-candidate 1\n", r"b'\xef\xbb\xbfwirecheck-candidate 1\n'"),
    ],
    ids=["trailing_space", "crlf", "bom"],
)
def test_a_header_that_differs_by_a_byte_is_shown_as_written(tmp_path, hello, shown):
    # was "speaks 'wirecheck-candidate 1': this wirecheck speaks 'wirecheck-candidate 1'" (stripped)
    cand = _candidate(tmp_path, f"o.write({hello!r}); o.flush()\n" + SERVE)
    assert _fault(cand) == f"candidate answered the header with {shown}: expected b'wirecheck-candidate 1\\n'"


def test_the_header_twice_is_bytes_outside_a_reply(tmp_path):
    # one write: both lines reach the pipe together (a write under PIPE_BUF is atomic), before any request
    cand = _candidate(tmp_path, 'o.write(b"wirecheck-candidate 1\\n" * 2); o.flush()\n' + SERVE)
    assert _fault(cand) == (
        "candidate wrote 22 bytes outside a reply: b'wirecheck-candidate 1\\n' (on a request of "
        "8 points); it was killed"
    )


def test_json_nested_too_deep_is_garbage_not_a_recursion_error(tmp_path):
    # json raises RecursionError (not ValueError) for ~1,000 nested arrays: it was "candidate raised
    # RecursionError" with the program kept (and, in the header, a program taken as started)
    deep = b"[" * 60_000 + b"\n"  # within MAX_LINE (65,536 bytes)
    reply = _candidate(tmp_path, HELLO + READ + f"o.write({deep!r}); o.flush()\n" + SERVE)
    assert _fault(reply).startswith("candidate wrote garbage instead of a reply: b'[[[[")
    deep_hello = b'{"a":' + deep
    hello = _candidate(tmp_path, f"o.write({deep_hello!r}); o.flush()\n" + SERVE)
    assert _fault(hello).startswith('candidate wrote garbage instead of the header: b\'{"a":[[[[')


# ---- the reply line


@pytest.mark.parametrize(
    "line,reason",
    [
        # json.loads keeps the last of a key twice, other parsers the first: ambiguous, so garbage
        (
            b'{"n": 9, "n": 8}',
            "wrote b'{\"n\": 9, \"n\": 8}\\n' instead of a reply: the key 'n' twice (expected each key once)",
        ),
        (
            b'{"n": 8, "points": 8}',
            "wrote the reply b'{\"n\": 8, \"points\": 8}\\n': the key 'points' is not one of a reply's (n, precision)",
        ),
        (b'{"n": ' + b"9" * 4000 + b"}", "answered 999999999999999999999999... points to a request of 8: expected 8"),
        (b'{"n": -8}', "answered -8 points to a request of 8: expected 8"),
    ],
    ids=["duplicate_key", "extra_key", "huge_n", "negative_n"],
)
def test_a_reply_line_that_is_not_exactly_a_reply_kills_the_program(tmp_path, line, reason):
    reply = line + b"\n" + bytes(128)
    cand = _candidate(tmp_path, HELLO + READ + f"o.write({reply!r}); o.flush()\n" + SERVE)
    assert _fault(cand) == f"candidate {reason} (on a request of 8 points); it was killed"


def test_a_program_that_echoes_the_request_does_not_pass_for_a_reply(tmp_path):
    # `cat` answers {"request": 1, "n": 8, "camera": ...} and the points: n matched, and this passed
    # (exec'ing another program mid-run: the pipes carry on to it)
    cand = _candidate(tmp_path, HELLO + 'os.execvp("cat", ["cat"])\n')
    assert _fault(cand).startswith('candidate wrote the reply b\'{"request":1,"n":8,"camera":')


def test_bytes_written_before_a_request_are_not_its_reply(tmp_path):
    # a reply to a request never sent: it sat in the pipe and was taken for the next request's reply
    written = tmp_path / "written"
    early = "time.sleep(0.05)\nn = 8\n" + ZEROS + f"open({str(written)!r}, 'w').write('1')\n"
    cand = _candidate(tmp_path, HELLO + early + SERVE)
    cand.start()  # reads the header; the early reply follows it 0.05 s later
    _wait_for(written)
    assert _fault(cand) == (
        "candidate wrote 137 bytes outside a reply: "
        + repr(b'{"n": 8}\n' + bytes(51))
        + "... (on a request of 8 points); it was killed"
    )


def test_an_error_reply_reaches_the_console_as_one_printable_line(tmp_path):
    # an error text is the program's: its escape sequences went raw to the console (and the report)
    error = json.dumps({"error": "bad\x1b[2K\x1b[1Gcamera\x00\x07\nx"}).encode() + b"\n"
    cand = _candidate(tmp_path, HELLO + "while True:\n    " + READ + f"    o.write({error!r}); o.flush()\n")
    assert _fault(cand) == "candidate reported an error: bad\\x1b[2K\\x1b[1Gcamera\\x00\\x07 x"


# ---- the payload


def test_payload_values_arrive_bit_for_bit_and_an_infinity_fails(tmp_path):
    # -0.0, the smallest denormal and NaN for a clipped point are valid answers, passed through exactly; an
    # infinity is the contract's fault
    values = [-0.0, 5e-324, np.nan, np.nan, 1e308, -2.5]
    texts = [str(v) for v in values]  # 'nan' and '5e-324' through float(), exactly
    body = (
        HELLO
        + READ
        + f'o.write(b"{{\\"n\\": 3}}\\n" + struct.pack("<6d", *map(float, {texts!r}))); o.flush()\n'
        + SERVE
    )
    cand = _candidate(tmp_path, body)
    got = call_candidate(cand, np.zeros((3, 3)), CAMERA)
    cand.close()
    assert got.tobytes() == np.array(values, dtype="<f8").tobytes()
    half = _candidate(
        tmp_path,
        HELLO + READ + 'o.write(b"{\\"n\\": 1}\\n" + struct.pack("<2d", float("nan"), '
        'float("inf"))); o.flush()\n' + SERVE,
    )
    assert _fault(half, 1) == (
        "candidate returned [nan, inf] for point 0 [0.0, 0.0, 0.0]: expected finite pixel "
        "coordinates, or NaN for a clipped point"
    )


# ---- timing and pipes


def test_the_timeout_is_per_request_not_per_read(tmp_path):
    # the 137-byte reply comes one byte every 0.1 s: each read is well within the 0.5 s timeout, the
    # whole takes 13.7 s; per request, the call ends after 0.5 s (bound: 0.5 s + a kill + slack, 5 s)
    body = (
        HELLO + READ + 'r = b"{\\"n\\": 8}\\n" + bytes(128)\nfor b in r:\n    o.write(bytes([b])); o.flush(); '
        "time.sleep(0.1)\n"
    )
    t = time.monotonic()
    reason = _fault(_candidate(tmp_path, body, timeout_s=0.5))
    assert time.monotonic() - t < 5.0
    # and the reason says how far the reply got: its line (9 bytes) was done or not
    head, got = re.fullmatch(
        r"candidate timed out after 0\.5 s on a request of 8 points \((.*?)(\d+)(?: of 137)? "
        r"bytes(?: and no newline)?\); it was killed \(and is started again for the next case\)",
        reason,
    ).groups()
    assert head in ("its reply line had ", "its reply had ") and 1 <= int(got) < 137


@pytest.mark.parametrize("fd,pipe", [(1, "stdout"), (0, "stdin")])
def test_a_program_that_closes_a_pipe_and_lives_on_ends_within_the_timeout(tmp_path, monkeypatch, fd, pipe):
    # was: the exit grace (2 s; 30 s here, so that the bound below separates the two) past a 0.3 s
    # timeout, and "closed its stdout" for a closed stdin too
    monkeypatch.setattr(subprocess_candidate, "_EXIT_GRACE_S", 30.0)
    # stdin is closed before the header is answered, so the request finds it closed (not in a race)
    closing = f"os.close({fd})\n"
    body = (closing + HELLO if fd == 0 else HELLO + closing) + "time.sleep(60)\n"
    cand = _candidate(tmp_path, body, timeout_s=0.3)
    cand.start()
    t = time.monotonic()
    reason = _fault(cand)
    assert reason == f"candidate closed its {pipe} but went on running (it was killed) during a request of 8 points"
    assert time.monotonic() - t < 10  # 0.3 s, a kill, slack for a loaded machine (was >= 30 s)


@pytest.mark.parametrize("answer", [ZEROS, 'o.write(b\'{"error": "no"}\\n\'); o.flush()\n'], ids=["reply", "error"])
def test_a_reply_before_the_request_is_read_fails_at_once(tmp_path, answer):
    # reads the request line, not its 24 MB of points, and answers: a reply was a timeout (the harness
    # waited to write the rest), an error reply kept the program with the rest of the request unsent
    # (it would read the next request's bytes as these points); now the protocol fault, at once
    body = HELLO + 'n = json.loads(i.readline())["n"]\n' + answer + "time.sleep(60)\n"
    t = time.monotonic()
    reason = _fault(_candidate(tmp_path, body, timeout_s=30), n=1_000_000)
    assert reason.startswith("candidate answered before reading the whole request (")
    assert reason.endswith(
        " bytes had reached its stdin): expected the reply after the request (on a request "
        "of 1000000 points); it was killed"
    )
    assert time.monotonic() - t < 10  # far below the 30 s timeout it used to take


def test_a_program_that_reads_nothing_times_out_without_a_deadlock(tmp_path):
    # 24 MB to a program that never reads: the write waits on the full pipe within the deadline, and
    # the reason says how much of the request got into the pipe (its size: 64 KB to 1 MB)
    reason = _fault(_candidate(tmp_path, HELLO + "time.sleep(60)\n", timeout_s=0.3), n=1_000_000)
    sent, total = map(
        int,
        re.fullmatch(
            r"candidate timed out after 0\.3 s on a request of 1000000 points \((\d+) of the request's (\d+) bytes had "
            r"reached its stdin\); it was killed \(and is started again for the next case\)",
            reason,
        ).groups(),
    )
    assert 24_000_000 < total < 24_010_000 and 1 << 16 <= sent <= 1 << 21


def test_a_line_of_100_mb_without_a_newline_is_cut_at_the_line_limit(tmp_path):
    # memory stays bounded: the harness reads at most MAX_LINE + one 1 MB chunk before it gives up
    body = HELLO + READ + 'for _ in range(100):\n    o.write(b"x" * (1 << 20))\no.flush()\n'
    assert _fault(_candidate(tmp_path, body)) == (
        "candidate wrote " + repr(b"x" * 60) + "... with no newline in its first 65536 bytes: expected a JSON "
        "line (on a request of 8 points); it was killed"
    )


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_sigstop_on_itself_is_a_timeout_and_the_process_ends(tmp_path):
    pid_file = tmp_path / "pid"
    body = (
        f"open({str(pid_file)!r}, 'w').write(str(os.getpid()))\n"
        + HELLO
        + READ
        + "os.kill(os.getpid(), signal.SIGSTOP)\n"
        + ZEROS
    )
    assert _fault(_candidate(tmp_path, body, timeout_s=0.3)).startswith("candidate timed out after 0.3 s")
    assert not process_runs(int(pid_file.read_text()))


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_a_process_started_in_a_session_of_its_own_ends_with_the_program(tmp_path):
    # forks, the child calls setsid (out of the program's process group) and keeps the pipes: it
    # outlived the run; it holds the program's stdout, so it is the program's and is killed with it
    pid_file = tmp_path / "orphan"
    body = (
        HELLO
        + (
            f"if os.fork() == 0:\n    os.setsid(); open({str(pid_file)!r}, 'w').write(str(os.getpid()))\n"
            "    time.sleep(300)\n"
        )
        + SERVE
    )
    cand = _candidate(tmp_path, body)
    assert call_candidate(cand, np.zeros((8, 3)), CAMERA).tolist() == [[0.0, 0.0]] * 8
    _wait_for(pid_file)  # the child writes its pid soon after the fork
    orphan = int(pid_file.read_text())
    assert process_runs(orphan)
    cand.close()
    assert not process_runs(orphan)


# ---- through crosscheck: exit 1, every case failing with the one reason, no traceback


def test_crosscheck_fails_every_case_of_a_program_that_closes_its_stdout(tmp_path, capsys):
    path = tmp_path / "prog.py"
    path.write_text(HEAD + HELLO + "os.close(1); time.sleep(60)\n")
    out = tmp_path / "r"
    code = cli.main(
        [
            "--candidate-cmd",
            f"{sys.executable} {path}",
            "--scene",
            "cube",
            "--cases",
            "on_axis,orthographic",
            "--frames",
            "2",
            "--level",
            "vertices",
            "--candidate-timeout",
            "0.3",
            "--report-dir",
            str(out),
        ]
    )
    report = json.loads((out / "report.json").read_text())
    assert code == 1 and report["summary"]["failed"] == 2 and "Traceback" not in capsys.readouterr().err
    for case in report["cases"]:
        assert case["reasons"] == [
            "frame 1: candidate closed its stdout but went on running (it was killed) during a request of 8 points"
        ]


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_a_program_whose_parent_exits_leaving_a_silent_child_times_out_and_the_child_ends(tmp_path):
    # the child keeps the pipes open (no EOF for wirecheck) and never answers: a timeout, and the
    # child (still in the program's group) is killed with it
    pid_file = tmp_path / "child"
    # the parent writes the child's pid before it answers the header, then exits
    body = (
        f"child = os.fork()\nif child:\n    open({str(pid_file)!r}, 'w').write(str(child))\n    "
        + HELLO
        + "    os._exit(0)\ntime.sleep(300)\n"
    )
    assert _fault(_candidate(tmp_path, body, timeout_s=0.3)).startswith("candidate timed out after 0.3 s")
    assert not process_runs(int(pid_file.read_text()))


def test_check_projector_cmd_fails_a_program_that_echoes_its_requests(tmp_path):
    from wirecheck.oracles import api

    report = api.check_projector(
        cmd=["sh", "-c", "read h; echo 'wirecheck-candidate 1'; exec cat"], scenes=["cube"], cases=["on_axis"], frames=1
    )
    assert report["verdict"] == "fail" and report["summary"]["failed"] == 1
    (reason,) = report["cases"][0]["reasons"]
    assert reason.startswith('frame 1: candidate wrote the reply b\'{"request":1,"n":8,"camera":')
    assert reason.endswith(
        "the key 'camera' is not one of a reply's (n, precision) (on a request of 8 points); it was killed"
    )


def test_a_forked_candidate_does_not_hold_another_programs_stdin_open(tmp_path):
    # a fork inherited this process's end of every live program's stdin: closing that program then
    # gave it no EOF, so it was killed after the 2 s grace instead of exiting (its marker unwritten)
    marker = tmp_path / "eof"
    first = SubprocessCandidate(
        argv=("sh", "-c", f"read h; echo 'wirecheck-candidate 1'; cat > /dev/null; echo eof > {marker}")
    )
    first.start()
    forked = SubprocessCandidate.fork(lambda p, c: p[:, :2] * 0.0, label="lambda")
    forked.start()
    try:
        first.close()
        assert marker.read_text() == "eof\n"
    finally:
        forked.close()
