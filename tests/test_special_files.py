"""Special files given where wirecheck reads a file (issue 36, item 4): refused in one line, never blocking.

Every file a run reads is opened by core.user_files: a FIFO, a device, a folder, a socket or a file over
its kind's limit (docs/reliability.md, "Files wirecheck reads") is one line on stderr naming the file, what
it is and what was expected, exit 2. Before, ``--config`` given a FIFO, ``/dev/zero`` or ``/dev/urandom``
hung until killed, ``--scene-list`` a FIFO hung, and ``--scene-list /dev/zero`` said "out of memory".

The CLI cases run in a subprocess with a timeout (a hang fails the test, never the suite) and a 4 GB
address-space limit (the old readers of /dev/zero allocated until killed).
"""

import os
import resource
import socket
import subprocess
import sys
from pathlib import Path

import pytest
from helpers import no_block
from wirecheck.core import user_files
from wirecheck.core.user_files import LIMITS, Limit, RefusedFile, open_regular, read_regular
from wirecheck.oracles import cli as crosscheck_cli

ROOT = Path(__file__).resolve().parent.parent
TIMEOUT_S = 60
MiB = 1 << 20


def _limited():
    resource.setrlimit(resource.RLIMIT_AS, (4 << 30, 4 << 30))


def run_cli(program: str, args: list[str], cwd: Path) -> tuple[int | None, str]:
    """``(exit status, stderr)`` of the console script; status None when it ran past TIMEOUT_S (killed)."""
    code = f"import sys; from {program} import main; sys.exit(main(sys.argv[1:]))"
    try:
        done = subprocess.run(
            [sys.executable, "-c", code, *args],
            cwd=cwd,
            capture_output=True,
            text=True,
            timeout=TIMEOUT_S,
            preexec_fn=_limited,
        )
    except subprocess.TimeoutExpired:
        return None, "(killed after 60 s: it blocked)"
    return done.returncode, done.stderr


RENDERER = "wirecheck.core.app.cli"
CROSSCHECK = "wirecheck.oracles.cli"
QUICK = ["--level", "vertices", "--frames", "1", "--cases", "on_axis", "--scene", "cube"]


def _fifo(path: Path) -> Path:
    os.mkfifo(path)
    return path


def _link(target: str):
    def make(path: Path) -> Path:
        path.symlink_to(target)
        return path

    return make


def _sparse(size: int):
    def make(path: Path) -> Path:
        with open(path, "wb") as fh:
            fh.truncate(size)
        return path

    return make


#: (id, program, file name, maker, argv given the file, what the line says)
CASES = [
    (
        "config FIFO",
        CROSSCHECK,
        "w.toml",
        _fifo,
        lambda f: ["--config", str(f), *QUICK],
        "a FIFO, not a regular file: expected a pyproject.toml or settings file",
    ),
    (
        "config /dev/zero",
        CROSSCHECK,
        "w.toml",
        _link("/dev/zero"),
        lambda f: ["--config", str(f), *QUICK],
        "a character device, not a regular file: expected a pyproject.toml or settings file",
    ),
    (
        "config /dev/urandom",
        CROSSCHECK,
        "w.toml",
        _link("/dev/urandom"),
        lambda f: ["--config", str(f), *QUICK],
        "a character device, not a regular file: expected a pyproject.toml or settings file",
    ),
    (
        "config 5 MiB",
        CROSSCHECK,
        "w.toml",
        _sparse(5 * MiB),
        lambda f: ["--config", str(f), *QUICK],
        f"too large ({5 * MiB:,} bytes): expected a pyproject.toml or settings file, a regular file of at most 4 MiB",
    ),
    (
        "pyproject.toml FIFO found",
        CROSSCHECK,
        "pyproject.toml",
        _fifo,
        lambda f: QUICK,
        "pyproject.toml: a FIFO, not a regular file",
    ),
    (
        "scene list FIFO",
        CROSSCHECK,
        "list.txt",
        _fifo,
        lambda f: ["--scene-list", str(f), "--level", "vertices"],
        "a FIFO, not a regular file: expected a scene list (one mesh path a line)",
    ),
    (
        "scene list /dev/zero",
        CROSSCHECK,
        "list.txt",
        _link("/dev/zero"),
        lambda f: ["--scene-list", str(f), "--level", "vertices"],
        "a character device, not a regular file: expected a scene list (one mesh path a line)",
    ),
    (
        "candidate FIFO",
        CROSSCHECK,
        "cand.py",
        _fifo,
        lambda f: ["--candidate", f"{f}:project", *QUICK],
        "a FIFO, not a regular file: expected a candidate's Python file",
    ),
    (
        ".scene 100 GiB",
        RENDERER,
        "big.scene",
        _sparse(100 << 30),
        lambda f: ["--scene", str(f), "--frames", "1"],
        f"too large ({100 << 30:,} bytes): expected a .scene file, a regular file of at most 64 MiB",
    ),
    (
        "mesh /dev/urandom",
        RENDERER,
        "m.obj",
        _link("/dev/urandom"),
        lambda f: ["--scene", str(f), "--frames", "1"],
        "a character device, not a regular file",
    ),
]


@pytest.mark.slow
@pytest.mark.parametrize("program, name, make, argv, needle", [c[1:] for c in CASES], ids=[c[0] for c in CASES])
def test_a_special_file_is_one_line_and_exit_2(tmp_path, program, name, make, argv, needle):
    path = make(tmp_path / name)
    out = tmp_path / "out"
    extra = ["--out", str(out)] if program == RENDERER else ["--report-dir", str(out)]
    rc, err = run_cli(program, [*argv(path), *extra], tmp_path)
    assert rc == 2, err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    assert str(path.name) in err and needle in err, err
    assert not out.exists()


@pytest.mark.slow
def test_the_config_fifo_line_in_full(tmp_path):
    fifo = _fifo(tmp_path / "w.toml")
    rc, err = run_cli(CROSSCHECK, ["--config", str(fifo), *QUICK], tmp_path)
    assert (rc, err) == (
        2,
        f"crosscheck: error: {fifo}: a FIFO, not a regular file: expected a pyproject.toml or "
        "settings file, a regular file of at most 4 MiB (docs/reliability.md)\n",
    )


# ---- core.user_files itself ------------------------------------------------------------------------------


def test_a_regular_file_and_a_link_to_one_are_read(tmp_path):
    (tmp_path / "a.txt").write_bytes(b"abc\n")
    (tmp_path / "l.txt").symlink_to(tmp_path / "a.txt")  # a link in a user's input is normal: followed
    assert read_regular(tmp_path / "a.txt", "config") == read_regular(tmp_path / "l.txt", "config") == b"abc\n"


def _socket(path: Path) -> Path:
    s = socket.socket(socket.AF_UNIX)
    s.bind(str(path))
    s.close()
    return path


@pytest.mark.parametrize(
    "make, problem",
    [
        (_fifo, "a FIFO, not a regular file"),
        (_link("/dev/zero"), "a character device, not a regular file"),
        (_link("/dev/null"), "a character device, not a regular file"),
        (lambda p: (p.mkdir(), p)[1], "a folder, not a regular file"),
        (_socket, "a socket, not a regular file"),
        (lambda p: (p.symlink_to(p.parent / "nowhere"), p)[1], "a broken link"),
        (lambda p: p, "missing"),
        (lambda p: (p.symlink_to(p), p)[1], "unreadable (Too many levels of symbolic links)"),
    ],
    ids=["fifo", "dev-zero", "dev-null", "folder", "socket", "broken-link", "missing", "link-loop"],
)
def test_what_is_refused_and_how_it_is_named(tmp_path, make, problem):
    path = make(tmp_path / "x")
    with no_block(10), pytest.raises(RefusedFile) as info:
        read_regular(path, "scene list")
    assert info.value.problem == problem
    assert str(info.value) == (
        f"{path}: {problem}: expected a scene list (one mesh path a line), a regular file "
        "of at most 64 MiB (docs/reliability.md)"
    )


def test_the_limit_is_the_largest_size_read(tmp_path):
    # "camera": 1 MiB (core.user_files.LIMITS): 1 MiB is read, one byte more is refused before reading
    _sparse(MiB)(tmp_path / "ok.json")
    _sparse(MiB + 1)(tmp_path / "big.json")
    assert LIMITS["camera"].size == MiB
    assert read_regular(tmp_path / "ok.json", "camera") == bytes(MiB)
    with pytest.raises(RefusedFile, match=r": too large \(1,048,577 bytes\): expected a camera file"):
        read_regular(tmp_path / "big.json", "camera")


def test_a_fifo_swapped_in_after_the_stat_is_refused_through_its_descriptor(tmp_path, monkeypatch):
    """The name is a regular file when looked at, a FIFO when opened: the open does not block (O_NONBLOCK)
    and the descriptor's own fstat refuses it."""
    fifo = _fifo(tmp_path / "f")
    monkeypatch.setattr(user_files, "problem", lambda path, kind: None)  # the stat saw a regular file
    with no_block(10), pytest.raises(RefusedFile, match="a FIFO, not a regular file"):
        open_regular(fifo, "frame")


def test_a_file_that_grows_past_the_limit_while_read_is_refused(monkeypatch):
    # /proc/self/status is a regular file of size 0 whose reads give ~1 KB: "growing" as far as fstat knows
    monkeypatch.setitem(LIMITS, "camera", Limit(10, "a camera file", "test"))
    with pytest.raises(RefusedFile, match=r"too large \(it grew past 10 bytes while read\)"):
        read_regular("/proc/self/status", "camera")


def test_every_kind_has_a_row_in_the_docs_table():
    text = (ROOT / "docs" / "reliability.md").read_text(encoding="utf-8")
    table = text[text.index("### Files wirecheck reads") :]
    rows = {line.split("|")[1].strip(" `"): line for line in table.splitlines() if line.startswith("| `")}
    for kind, limit in LIMITS.items():
        assert f"| {limit.size // MiB:,} MiB |" in rows[kind], (kind, rows.get(kind))


# ---- paths named in a [tool.wirecheck] table -------------------------------------------------------------


def _crosscheck(argv, capsys):
    with no_block(30):
        rc = crosscheck_cli.main(argv)
    return rc, capsys.readouterr().err


@pytest.mark.parametrize("key, name", [("scenes", "loop.scene"), ("candidate", "loop.py")])
def test_a_link_loop_named_by_the_config_is_one_line(tmp_path, capsys, key, name):
    """Before: exit 3, "internal error: RuntimeError: Symlink loop" (Path.resolve on Python 3.11)."""
    (tmp_path / name).symlink_to(tmp_path / name)
    value = f'["{name}"]' if key == "scenes" else f'"{name}:project"'
    (tmp_path / "w.toml").write_text(f"[tool.wirecheck]\n{key} = {value}\n")
    rc, err = _crosscheck(
        [
            "--config",
            str(tmp_path / "w.toml"),
            "--level",
            "vertices",
            "--frames",
            "1",
            "--report-dir",
            str(tmp_path / "rep"),
        ],
        capsys,
    )
    assert rc == 2 and err.count("\n") == 1, err
    assert f"{tmp_path / name}" in err and "Too many levels of symbolic links" in err, err


def test_a_config_candidate_that_is_a_fifo_is_refused_before_the_line_that_says_it_runs(tmp_path, capsys):
    """The settings-trust line ("... chose the Python candidate ...; it runs now") is said only for a candidate
    that will run: before, it came first and the refusal second (two lines for one exit 2)."""
    os.mkfifo(tmp_path / "cand.py")
    (tmp_path / "w.toml").write_text('[tool.wirecheck]\ncandidate = "cand.py:project"\n')
    rc, err = _crosscheck(
        [
            "--config",
            str(tmp_path / "w.toml"),
            "--level",
            "vertices",
            "--frames",
            "1",
            "--scene",
            "cube",
            "--report-dir",
            str(tmp_path / "rep"),
        ],
        capsys,
    )
    assert rc == 2 and err.count("\n") == 1, err
    assert "cand.py': a FIFO, not a regular file: expected a candidate's Python file" in err, err
