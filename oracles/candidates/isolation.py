"""Which candidate runs where, built from what a user gave (CLI options, API arguments).

- core (the default candidate) is trusted: it runs in crosscheck's process.
- ``--candidate FILE.py:FUNC`` / ``"FILE.py:FUNC"``: the candidate host in its
  own process (oracles.candidates.candidate_host).
- ``--candidate-cmd 'COMMAND ARGS'`` / ``cmd=``: the program, in its own process.
- an API callable: in the candidate host when another process can import it
  (:func:`importable_spec`), else (a lambda, a closure) in a forked copy of
  the caller's process (POSIX); in the caller's process only with
  ``isolate=False`` (docs/protocol.md).

Every isolated candidate is started here once, so that a program that cannot
start or refuses to is a usage error (exit 2) before any case runs.
"""

from __future__ import annotations

import sys

from wirecheck.core.errors import InputError
from wirecheck.core.user_files import expected, problem

from .candidate import CandidateError, load_candidate
from .subprocess_candidate import DEFAULT_TIMEOUT_S, CandidateStartRefused, SubprocessCandidate


def check_python_spec(spec: str, option: str = "--candidate") -> None:
    """Usage errors of a ``FILE.py:FUNC`` / ``MODULE:FUNC`` spec found without importing it (InputError)."""

    if ":" not in spec:
        raise InputError(f"{option} {spec!r}: expected FILE.py:FUNC or MODULE:FUNC")
    target = spec.rsplit(":", 1)[0]
    if target.endswith(".py") or "/" in target:
        refused = problem(target, "candidate")  # stat only: a FIFO is never opened
        if refused == "missing":
            raise InputError(f"{option} {spec!r}: file {target!r} not found")
        if refused is not None:  # a FIFO, a device, a folder; a name too long for the file system
            raise InputError(f"{option} {spec!r}: file {target[:80]!r}: {refused}: expected {expected('candidate')}")


def importable_spec(func) -> str | None:
    """``MODULE:NAME`` if ``func`` is a module-level function another process can import, else None."""
    module, name = getattr(func, "__module__", None), getattr(func, "__name__", None)
    if not module or module == "__main__" or not name or getattr(func, "__qualname__", None) != name:
        return None
    mod = sys.modules.get(module)
    if mod is None or getattr(mod, name, None) is not func or not getattr(mod, "__file__", None):
        return None
    return f"{module}:{name}"


def started(candidate: SubprocessCandidate, option: str):
    """Start ``candidate`` now: InputError (a usage error) when it cannot start or refuses to.

    A program that dies, hangs or writes garbage at start-up is *not* a usage
    error: it is returned, and every case then fails with that reason.
    """
    try:
        candidate.start()
    except CandidateStartRefused as exc:
        candidate.close()
        text = str(exc)
        raise InputError(text if text.startswith(option) else f"{option} {candidate.name!r}: {text}") from None
    except CandidateError:
        pass
    return candidate


def external_candidate(
    spec: str | None = None, command: str | None = None, timeout_s: float = DEFAULT_TIMEOUT_S
) -> SubprocessCandidate:
    """The isolated candidate for ``--candidate SPEC`` or ``--candidate-cmd COMMAND``, started (see :func:`started`)."""
    if spec is not None:
        check_python_spec(spec)
        return started(SubprocessCandidate.python(spec, timeout_s), "--candidate")
    try:
        candidate = SubprocessCandidate.from_command(command, timeout_s)
    except ValueError as exc:
        raise InputError(f"--candidate-cmd {exc}") from None
    return started(candidate, "--candidate-cmd")


def api_candidate(func=None, cmd=None, timeout_s: float = DEFAULT_TIMEOUT_S, isolate: bool | None = None):
    """``(name, candidate)`` for the Python API (oracles.api; its docstring states the isolation rules)."""
    if (func is None) == (cmd is None):
        raise ValueError("expected a candidate: func or cmd, not both")
    if cmd is not None:
        if isolate is False:
            raise ValueError("isolate=False with cmd: a program always runs in its own process")
        try:
            candidate = (
                SubprocessCandidate.from_command(cmd, timeout_s)
                if isinstance(cmd, str)
                else SubprocessCandidate(argv=tuple(cmd), timeout_s=timeout_s)
            )
        except ValueError as exc:
            raise InputError(f"cmd {exc}") from None
        return candidate.name, started(candidate, "cmd")
    if isinstance(func, str):
        if isolate is False:
            return func, load_candidate(func)
        check_python_spec(func)
        return func, started(SubprocessCandidate.python(func, timeout_s), "--candidate")
    name = getattr(func, "__qualname__", repr(func))
    if isolate is False:
        return name, func
    spec = importable_spec(func)
    if spec is None:
        import os

        if not hasattr(os, "fork"):
            if isolate:
                raise ValueError(
                    f"isolate=True: {name} cannot be imported by another process (expected a "
                    "module-level function of an importable module) and this system cannot fork"
                )
            return name, func
        return name, started(SubprocessCandidate.fork(func, timeout_s, label=name), "func")
    path = tuple(p for p in sys.path if isinstance(p, str))
    return name, started(SubprocessCandidate.python(spec, timeout_s, pythonpath=path, label=name), "--candidate")
