"""The command samples in README.md and docs/*.md, found, run and compared with what the program prints.

A *sample* is a code block (fenced, or indented by four spaces) whose first line is a
``$ COMMAND`` line: every ``$`` line in it is run (with ``bash``), and the lines up to the next
``$`` line are that command's expected output. Two HTML comments on the line right before a
block change that:

- ``<!-- not run: REASON -->``: the block is not run (a server, a cluster, another machine); the
  reason is listed by ``--list`` so the choice is visible;
- ``<!-- command: COMMAND -->``: a block of output only (a report excerpt, an error line) is the
  output of COMMAND, which is run and compared in the same way.
- ``<!-- cwd: PATH -->`` (before either, or alone): run in a copy of PATH, a folder of the
  repository (a small user project, for the pytest samples).

``<!-- normalise: numbers -->`` before a block compares every decimal number as a placeholder
(a table of timings).

Commands run in a fresh temporary folder that links ``.venv``, ``tests`` and ``scenes`` of the
checkout (so ``.venv/bin/crosscheck`` and ``tests/data/...`` mean what they mean in a checkout,
and the outputs a command writes do not land in the checkout), with ``.venv/bin`` first on PATH;
the folder's path is printed as ``/home/me/myproj`` (:data:`USER_PROJECT`). A plain
``crosscheck`` or ``renderer`` command runs as its console script's ``main()`` in a fork of
this process, its heavy imports done once (:func:`_run_forked`); ``X >/dev/null; Y`` runs
``Y`` in the folder of ``X``'s own run (:meth:`Runner.output`).

Comparison (:func:`matches`) is line by line after :func:`normalise` (times, dates, report
folder names, ports and rounding-level vertex errors become placeholders: they change on every
run or machine; every other number is compared as printed). A line ``...`` in the doc stands for
any number of lines, so a sample can show the head and the tail of a long output.

Maintainers regenerate the samples from real runs (after output changes) with::

    .venv/bin/python tests/docs_samples.py --update        # rewrite every sample block
    .venv/bin/python tests/docs_samples.py --check         # what the test does, with diffs
    .venv/bin/python tests/docs_samples.py --list          # every sample, run or not

``--update`` keeps each block's shape: its commands, its ``...`` elisions (the lines kept before
and after each elision stay the same in number) and the comment lines before it.
"""

from __future__ import annotations

import difflib
import functools
import os
import re
import shutil
import subprocess
import sys
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
ELISION = "..."
_FENCE = re.compile(r"^(\s*)(```+|~~~+)(.*)$")
_DIRECTIVE = re.compile(r"^\s*<!--\s*(not run|command|cwd|normalise):\s*(.*?)\s*-->\s*$")
#: Seconds one command may take before the sample fails (the longest, the full main job, takes
#: ~25 s on a loaded 2-core machine).
COMMAND_TIMEOUT_S = 300
#: What the docs call the folder a command runs in (the temporary folder is printed as this).
USER_PROJECT = "/home/me/myproj"


@dataclass
class Command:
    """One ``$`` line (or a ``command:`` directive) and the output the doc shows for it."""

    text: str
    expected: list[str]


@dataclass
class Sample:
    """One block of a doc: where it is, its commands, and how it is run."""

    path: Path
    first: int  # 0-based index of the block's first content line
    last: int  # 0-based index one past its last content line
    indent: str  # the prefix every content line carries ("" fenced, "    " indented)
    commands: list[Command]
    not_run: str | None = None
    hidden_command: bool = False  # the command is in a `command:` directive, not in the block
    cwd: str | None = None
    directives: dict = field(default_factory=dict)

    @property
    def where(self) -> str:
        return f"{_rel(self.path)}:{self.first + 1}"

    @property
    def numbers(self) -> bool:
        return self.directives.get("normalise", "").startswith("numbers")

    @property
    def slow(self) -> bool:
        """A crosscheck run at level pixels or a pytest run (seconds each); renderer runs are not."""
        return any(re.search(r"\b(crosscheck|pytest)\b", c.text) for c in self.commands)


def _rel(path: Path) -> str:
    return str(path.relative_to(ROOT)) if path.is_relative_to(ROOT) else str(path)


def doc_files() -> list[Path]:
    return [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]


def _directives(lines: list[str], start: int) -> dict:
    """The ``<!-- key: value -->`` lines right above line ``start`` (nearest first wins)."""
    found = {}
    i = start - 1
    while i >= 0 and _DIRECTIVE.match(lines[i]):
        key, value = _DIRECTIVE.match(lines[i]).groups()
        found.setdefault(key, value)
        i -= 1
    return found


def _split_commands(body: list[str]) -> list[Command]:
    commands: list[Command] = []
    for line in body:
        if line.startswith("$ "):
            commands.append(Command(line[2:], []))
        else:
            commands[-1].expected.append(line)
    for c in commands:
        while c.expected and not c.expected[-1].strip():
            c.expected.pop()
    return commands


def unbalanced_fences(path: Path) -> list[str]:
    """One message per fence that is opened and never closed, or closed with another lang tag.

    A line ```` ```python ```` while a block is open is a new opening, not a close: Markdown
    would show it as text, which is how a fence out of balance turns the rest of a page into
    code.
    """
    problems = []
    open_at = None
    for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
        m = _FENCE.match(line)
        if not m:
            continue
        if open_at is None:
            open_at = number
        elif m.group(3).strip():
            problems.append(
                f"{_rel(path)}:{number}: a fence with a language "
                f"({m.group(3).strip()}) inside the block opened at line {open_at}"
            )
            open_at = number
        else:
            open_at = None
    if open_at is not None:
        problems.append(f"{_rel(path)}:{open_at}: fence never closed")
    return problems


def samples(path: Path) -> list[Sample]:
    """Every sample block of ``path``, in order."""
    lines = path.read_text(encoding="utf-8").splitlines()
    out = []
    i = 0
    while i < len(lines):
        m = _FENCE.match(lines[i])
        if m:
            j = i + 1
            while j < len(lines) and not _FENCE.match(lines[j]):
                j += 1
            body = lines[i + 1 : j]
            out += _block(path, lines, i, i + 1, j, "", body)
            i = j + 1
            continue
        if lines[i].startswith("    $ ") and (i == 0 or not lines[i - 1].strip() or _DIRECTIVE.match(lines[i - 1])):
            j = i
            while j < len(lines) and (lines[j].startswith("    ") or not lines[j].strip()):
                j += 1
            while j > i and not lines[j - 1].strip():
                j -= 1
            body = [line[4:] for line in lines[i:j]]
            out += _block(path, lines, i, i, j, "    ", body)
            i = j
            continue
        i += 1
    return out


def _block(path, lines, directive_at, first, last, indent, body) -> list[Sample]:
    found = _directives(lines, directive_at)
    starts_with_command = bool(body) and body[0].startswith("$ ")
    if "command" in found:
        commands = [Command(found["command"], list(body))]
        return [Sample(path, first, last, indent, commands, found.get("not run"), True, found.get("cwd"), found)]
    if not starts_with_command:
        if "not run" in found:
            return [Sample(path, first, last, indent, [], found["not run"], False, found.get("cwd"), found)]
        return []
    return [
        Sample(path, first, last, indent, _split_commands(body), found.get("not run"), False, found.get("cwd"), found)
    ]


def code_blocks(path: Path, heading: str) -> dict[str, str]:
    """The fenced code blocks of ``path``'s section ``heading`` (a ``#`` line's text, up to the next heading),
    by their language tag (``python``, ``toml``; the first block of each), each as its text: a doc's example
    files, which a test writes into a project and runs (tests/test_docs_samples.py)."""
    lines = path.read_text(encoding="utf-8").splitlines()
    start = next(i for i, line in enumerate(lines) if line.lstrip("#").strip() == heading and line.startswith("#"))
    out: dict[str, str] = {}
    i = start + 1
    while i < len(lines) and not lines[i].startswith("#"):
        m = _FENCE.match(lines[i])
        if m:
            j = i + 1
            while j < len(lines) and not _FENCE.match(lines[j]):
                j += 1
            out.setdefault(m.group(3).strip(), "\n".join(lines[i + 1 : j]) + "\n")
            i = j
        i += 1
    return out


def all_samples() -> list[Sample]:
    return [s for p in doc_files() for s in samples(p)]


# -- normalising -----------------------------------------------------------------------------

_NORMALISE = [
    (re.compile(r"reports/\d{8}-\d{6}(?:-\d+)?"), "reports/<time>"),
    (re.compile(r"\d{4}-\d{2}-\d{2}[T ]\d{2}:\d{2}(?::\d{2}(?:\.\d+)?)?(?:Z|[+-]\d{2}:?\d{2})?"), "<date>"),
    (re.compile(r"127\.0\.0\.1:\d+"), "127.0.0.1:<port>"),
    # durations: "1.59 ms/frame", "11.9 s wall", "in 6.38s", "(0:00:03)"
    (re.compile(r"(?<![\w.])\d[\d,]*(?:\.\d+)?\s?(ms|s|min)\b"), r"<t>\1"),
    # rounding-level errors (float64 noise: the bits vary with the BLAS and the CPU)
    (re.compile(r"(?<![\w.])\d\.\d+e-(?:1[0-9]|[2-9][0-9])\b"), "<tiny>"),
]


_DECIMAL = re.compile(r"(?<![\w.])\d[\d,]*\.\d+")


def normalise(line: str, numbers: bool = False) -> str:
    """``line`` with what varies from run to run replaced by placeholders, trailing blanks dropped.

    ``numbers``: every decimal number too (a table of timings: ``<!-- normalise: numbers -->``).
    """
    for pattern, repl in _NORMALISE:
        line = pattern.sub(repl, line)
    if numbers:  # and the columns' widths, which follow the numbers'
        line = re.sub(r"\s+", " ", _DECIMAL.sub("<n>", line))
    return line.rstrip()


def matches(expected: list[str], actual: list[str], numbers: bool = False) -> bool:
    """Whether ``actual`` is ``expected`` after :func:`normalise`, each ``...`` line any run of lines."""
    exp = [ELISION if e.strip() == ELISION else normalise(e, numbers) for e in expected]
    act = [normalise(a, numbers) for a in actual]
    # memoised two-pointer match with the elision as a wildcard over whole lines

    @functools.cache
    def ok(i: int, j: int) -> bool:
        if i == len(exp):
            return j == len(act)
        if exp[i] == ELISION:
            return any(ok(i + 1, k) for k in range(j, len(act) + 1))
        return j < len(act) and exp[i] == act[j] and ok(i + 1, j + 1)

    return ok(0, 0)


def diff(expected: list[str], actual: list[str], numbers: bool = False) -> str:
    return "\n".join(
        difflib.unified_diff(
            [normalise(e, numbers) for e in expected],
            [normalise(a, numbers) for a in actual],
            "doc",
            "program",
            lineterm="",
            n=2,
        )
    )


# -- running ---------------------------------------------------------------------------------


class Runner:
    """Runs commands in one temporary folder each, remembering outputs (one run serves every
    sample that shows the same command in the same folder)."""

    def __init__(self):
        self._cache: dict[tuple, list[str]] = {}
        self._folders: dict[tuple, str] = {}
        self._dirs: list[str] = []

    def output(self, command: str, cwd: str | None = None) -> list[str]:
        """What ``command`` prints (stdout and stderr), run in ``cwd``'s copy.

        ``X >/dev/null; Y`` with ``X`` a plain console-script command (:data:`_PLAIN_CLI`) runs
        ``Y`` in the folder where ``X`` ran for its own sample (or runs ``X`` there first): a
        report excerpt reads the report of the run the doc shows instead of running it again.
        ``X``'s output is dropped, as ``>/dev/null`` drops it; a sample of ``X`` itself compares
        all of it."""
        key = (command, cwd)
        if key not in self._cache:
            after = _AFTER.match(command)
            if after and _PLAIN_CLI.match(after.group(1)):
                first = after.group(1)
                self.output(first, cwd)
                work = self._folders[(first, cwd)]
                self._cache[key] = _shown(self._run_bash(after.group(2), work, self._env()), work)
            else:
                self._cache[key] = self._run(command, cwd)
        return self._cache[key]

    @staticmethod
    def _env() -> dict:
        env = dict(os.environ)
        env["PATH"] = f"{ROOT / '.venv' / 'bin'}{os.pathsep}{env.get('PATH', '')}"
        env["COLUMNS"] = "80"  # argparse and pytest wrap to the terminal's width
        env.pop("PYTEST_ADDOPTS", None)
        env.pop("PYTEST_XDIST_WORKER", None)
        for name in ("CI", "BUILD_NUMBER"):  # pytest prints its summary lines whole under CI: a user's terminal
            env.pop(name, None)
        env["PYTHONDONTWRITEBYTECODE"] = "1"
        return env

    def _run(self, command: str, cwd: str | None) -> list[str]:
        work = tempfile.mkdtemp(prefix="wirecheck-docs-")
        self._dirs.append(work)
        self._folders[(command, cwd)] = work
        if cwd:
            shutil.copytree(
                ROOT / cwd, work, dirs_exist_ok=True, ignore=shutil.ignore_patterns("__pycache__", ".pytest_cache")
            )
        for name in (".venv", "tests", "scenes"):
            if not os.path.exists(os.path.join(work, name)):
                os.symlink(ROOT / name, os.path.join(work, name))
        env = self._env()
        plain = _PLAIN_CLI.match(command)
        if plain and "OpenGL" not in sys.modules:
            return _shown(_run_forked(plain.group(1), command.split()[1:], work, env), work)
        return _shown(self._run_bash(command, work, env), work)

    @staticmethod
    def _run_bash(command: str, work: str, env: dict) -> list[str]:
        # `pytest` is the environment's (the venv has no pytest script of its own)
        script = f'pytest() {{ "{ROOT / ".venv" / "bin" / "python"}" -m pytest "$@"; }}\n{command}'
        done = subprocess.run(
            ["bash", "-c", script],
            cwd=work,
            env=env,
            stdin=subprocess.DEVNULL,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            timeout=COMMAND_TIMEOUT_S,
            text=True,
        )
        return done.stdout.splitlines()

    def in_project(self, files: dict[str, str], command: str) -> list[str]:
        """What ``command`` prints in a fresh folder holding only ``files`` (``{relative path: text}``): a new
        user's project, which finds wirecheck in this environment and nothing of the checkout (no links)."""
        work = tempfile.mkdtemp(prefix="wirecheck-project-")
        self._dirs.append(work)
        for rel, text in files.items():
            path = Path(work) / rel
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(text, encoding="utf-8")
        return _shown(self._run_bash(command, work, self._env()), work)

    def close(self):
        for d in self._dirs:
            shutil.rmtree(d, ignore_errors=True)
        self._dirs.clear()


def _shown(lines: list[str], work: str) -> list[str]:
    """``lines`` as the doc shows them: the folder is the doc's user project (pytest.md:
    /home/me/myproj), no blank lines at the end."""
    lines = [line.replace(os.path.realpath(work), USER_PROJECT).replace(work, USER_PROJECT) for line in lines]
    while lines and not lines[-1].strip():
        lines.pop()
    return lines


#: ``X >/dev/null; Y``: Y reads what X wrote (Runner.output).
_AFTER = re.compile(r"^(.*?) >/dev/null; (.*)$")
#: A command that is one of the console scripts with plain words for arguments (no quoting, pipe,
#: redirection or second command): it runs as the script's ``main()`` in a fork of this process
#: (:func:`_run_forked`), not through bash and a new interpreter.
_PLAIN_CLI = re.compile(r"^(?:\.venv/bin/)?(crosscheck|renderer)(?: [A-Za-z0-9_./:,=+-]+)*$")
_MAINS = {"crosscheck": "wirecheck.oracles.cli", "renderer": "wirecheck.core.app.cli"}
#: Imported once here before the first fork, so that no run pays for them again; none of them
#: loads OpenGL (a fork must pick its GL platform itself, as a new process does).
_WARM = (
    "numpy",
    "scipy.spatial.transform",
    "cv2",
    "matplotlib.figure",
    "matplotlib.backends.backend_agg",
    "PIL.Image",
    *_MAINS.values(),
)


def _warm_up() -> None:
    import importlib

    environ = dict(os.environ)
    try:
        for name in _WARM:
            importlib.import_module(name)
    finally:  # cv2's import adds to LD_LIBRARY_PATH: this process's is kept
        for name in set(os.environ) - set(environ):
            del os.environ[name]
        for name, value in environ.items():
            if os.environ.get(name) != value:
                os.environ[name] = value


def _run_forked(program: str, args: list[str], work: str, env: dict) -> list[str]:
    """``program ARGS`` as its console script would run it, in a fork of this process with the
    heavy imports done (the samples' CPU time was mostly interpreters starting and importing).

    What the command sees is a new process's: its own folder, environment, stdin /dev/null,
    stdout and stderr one pipe (as ``bash -c CMD 2>&1``: stdout block-buffered, stderr
    line-buffered), ``sys.argv``, default signal handlers, no inherited ``atexit`` handler;
    its exit status is not compared (neither is a subprocess's)."""
    import atexit
    import importlib
    import io
    import signal

    _warm_up()
    read_end, write_end = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child: never returns
        code = 3
        try:
            os.close(read_end)
            os.dup2(write_end, 1)
            os.dup2(write_end, 2)
            os.close(write_end)
            os.dup2(os.open(os.devnull, os.O_RDONLY), 0)
            os.chdir(work)
            os.environ.clear()
            os.environ.update(env)
            for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGPIPE):
                signal.signal(sig, signal.default_int_handler if sig == signal.SIGINT else signal.SIG_DFL)
            sys.stdin = open(0, closefd=False)
            sys.stdout = io.TextIOWrapper(open(1, "wb", closefd=False), encoding="utf-8")
            sys.stderr = io.TextIOWrapper(
                open(2, "wb", closefd=False), encoding="utf-8", errors="backslashreplace", line_buffering=True
            )
            sys.__stdin__, sys.__stdout__, sys.__stderr__ = sys.stdin, sys.stdout, sys.stderr
            sys.argv = [str(ROOT / ".venv" / "bin" / program), *args]
            atexit._clear()  # this process's handlers are not the program's
            module = importlib.import_module(_MAINS[program])
            candidates = sys.modules.get("wirecheck.oracles.candidates.subprocess_candidate")
            if candidates is not None:  # its handler was registered before the fork
                atexit.register(candidates._close_all)
            try:
                code = module.main()
            except SystemExit as exc:
                code = exc.code
            atexit._run_exitfuncs()
            sys.stdout.flush()
            sys.stderr.flush()
        except BaseException:  # noqa: BLE001 - shown as the run's output
            import traceback

            traceback.print_exc()
            sys.stderr.flush()
        finally:
            os._exit(code if isinstance(code, int) else 1)
    os.close(write_end)
    import select
    import time

    chunks, deadline = [], time.monotonic() + COMMAND_TIMEOUT_S
    with open(read_end, "rb", buffering=0) as pipe:
        while True:  # as subprocess.run(timeout=...): a hung run is an error
            ready, _, _ = select.select([pipe], [], [], max(0.0, deadline - time.monotonic()))
            if not ready:
                os.kill(pid, signal.SIGKILL)
                os.waitpid(pid, 0)
                raise subprocess.TimeoutExpired([program, *args], COMMAND_TIMEOUT_S)
            chunk = pipe.read(65536)
            if not chunk:
                break
            chunks.append(chunk)
    os.waitpid(pid, 0)
    return b"".join(chunks).decode("utf-8", "replace").splitlines()


def check(sample: Sample, runner: Runner) -> list[str]:
    """One message (with a diff) per command of ``sample`` whose output is not what the doc shows."""
    problems = []
    for c in sample.commands:
        actual = runner.output(c.text, sample.cwd)
        if not matches(c.expected, actual, sample.numbers):
            problems.append(
                f"{sample.where}: `$ {c.text}` prints something else than the doc "
                f"(regenerate: python tests/docs_samples.py --update)\n"
                f"{diff(c.expected, actual, sample.numbers)}"
            )
    return problems


# -- regenerating ----------------------------------------------------------------------------


def reshape(expected: list[str], actual: list[str], numbers: bool = False) -> list[str]:
    """``actual`` cut to the shape of ``expected``: each ``...`` of the doc kept, with as many
    real lines before and after it as the doc shows; lines the doc shows are replaced by the
    program's (new lines the program prints between them are added)."""
    if matches(expected, actual, numbers):
        # align exactly and take the program's text for every line the doc shows
        return _aligned(expected, actual, numbers)
    segments, current, elisions = [], [], []
    for e in expected:
        if e.strip() == ELISION:
            elisions.append(e)
            segments.append(current)
            current = []
        else:
            current.append(e)
    segments.append(current)
    if len(segments) == 1:
        return list(actual)
    # each segment of the doc is located in the program's output by matching its lines one by
    # one (in order, most similar first); it becomes the span from its first matched line to
    # its last (so lines the program added inside it are kept); the first segment starts at
    # the top, the last ends at the bottom
    spans, pos = [], 0
    for k, segment in enumerate(segments):
        hits = []
        for line in segment:
            hit = _most_similar(line, actual, pos, numbers)
            if hit is not None:
                hits.append(hit)
                pos = hit + 1
        lo = 0 if k == 0 else (hits[0] if hits else pos)
        hi = len(actual) if k == len(segments) - 1 else (hits[-1] + 1 if hits else lo)
        if spans:
            lo = max(lo, spans[-1][1])
        spans.append((lo, max(lo, hi)))
        pos = max(pos, hi)
    out: list[str] = []
    for k, (lo, hi) in enumerate(spans):
        if k and lo > spans[k - 1][1]:  # something is hidden here: keep the elision
            out.append(elisions[k - 1])
        out += actual[lo:hi]
    return out


def _most_similar(line: str, actual: list[str], lo: int, numbers: bool) -> int | None:
    """Index in ``actual[lo:]`` of the line most like ``line`` (None below 60 % alike)."""
    want = normalise(line, numbers)
    best, best_score = None, 0.6
    for k in range(lo, len(actual)):
        have = normalise(actual[k], numbers)
        if have == want:
            return k
        # a line usually changes at its end (a clause added): the common start weighs half
        prefix = len(os.path.commonprefix([want, have])) / max(len(want), 1)
        score = 0.5 * prefix + 0.5 * difflib.SequenceMatcher(None, want, have).ratio()
        if score > best_score:
            best, best_score = k, score
    return best


def _aligned(expected, actual, numbers=False):
    exp = [ELISION if e.strip() == ELISION else e for e in expected]
    out = []
    i = j = 0

    def ok(i, j):
        return matches(expected[i:], actual[j:], numbers)

    while i < len(exp):
        if exp[i] == ELISION:
            k = j
            while not ok(i + 1, k):
                k += 1
            out.append(expected[i])
            i, j = i + 1, k
        else:
            out.append(actual[j])
            i, j = i + 1, j + 1
    return out


def update(paths: list[Path] | None = None, runner: Runner | None = None) -> list[str]:
    """Rewrite every runnable sample block from real runs; return what changed (``path:line``)."""
    runner = runner or Runner()
    changed = []
    for path in paths or doc_files():
        lines = path.read_text(encoding="utf-8").splitlines()
        blocks = [s for s in samples(path) if s.not_run is None and s.commands]
        for s in reversed(blocks):  # from the bottom, so line numbers stay valid
            body = []
            for c in s.commands:
                new = reshape(c.expected, runner.output(c.text, s.cwd), s.numbers)
                if not s.hidden_command:
                    body.append(f"$ {c.text}")
                body += new
                if c is not s.commands[-1]:
                    body.append("")
            new_lines = [(s.indent + b) if b else "" for b in body]
            if new_lines != lines[s.first : s.last]:
                lines[s.first : s.last] = new_lines
                changed.append(s.where)
        text = "\n".join(lines) + "\n"
        if text != path.read_text(encoding="utf-8"):
            path.write_text(text, encoding="utf-8")
    return changed


def main(argv=None) -> int:
    import argparse

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    mode = parser.add_mutually_exclusive_group(required=True)
    mode.add_argument("--update", action="store_true", help="rewrite the sample blocks from real runs")
    mode.add_argument("--check", action="store_true", help="compare, print every difference")
    mode.add_argument("--list", action="store_true", help="list every sample and how it is treated")
    parser.add_argument("files", nargs="*", type=Path, help="docs to treat (all)")
    args = parser.parse_args(argv)
    paths = [p.resolve() for p in args.files] or doc_files()
    runner = Runner()
    try:
        if args.list:
            for p in paths:
                for s in samples(p):
                    what = f"not run: {s.not_run}" if s.not_run else " ; ".join(c.text for c in s.commands)
                    print(f"{s.where}: {what}")
            return 0
        if args.update:
            for where in update(paths, runner):
                print(f"updated {where}")
            return 0
        problems = [m for p in paths for s in samples(p) if s.not_run is None for m in check(s, runner)]
        problems += [m for p in paths for m in unbalanced_fences(p)]
        print("\n\n".join(problems) or "every sample agrees")
        return 1 if problems else 0
    finally:
        runner.close()


if __name__ == "__main__":
    sys.exit(main())
