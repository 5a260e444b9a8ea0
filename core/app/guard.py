"""The CLIs' top-level guard: whatever happens, one line on stderr and an exit status that means it.

=====  ==================================================================
exit   meaning
=====  ==================================================================
0      done (crosscheck: every case within tolerance)
1      crosscheck: a case failed
2      bad input or an unusable environment: one line naming the option,
       file (and line) and value (:class:`core.errors.InputError`, or an
       ``OSError`` on a path: a name too long, no space, no permission)
3      a bug in wirecheck: one line pointing to a log file (in the system
       temporary folder, a unique name) that holds the traceback
130    interrupted (SIGINT), 143 terminated (SIGTERM): temporaries removed
141    stdout closed by the reader (``renderer | head``)
=====  ==================================================================

Library warnings and third-party log records are kept off stderr while the
command runs (:func:`core.errors.quiet_libraries`); they go to the log of an
internal error.
"""

from __future__ import annotations

import argparse
import errno
import os
import signal
import sys
import tempfile
import traceback

import wirecheck

from ..errors import InputError, one_line, quiet_libraries

EXIT_USAGE = 2
EXIT_INTERNAL = 3


class Interrupted(KeyboardInterrupt):
    """SIGINT or SIGTERM arrived: unwinds as a KeyboardInterrupt, so every ``finally`` cleans up.

    (A KeyboardInterrupt, so code that stops on Ctrl-C, the interactive viewer's server, stops on
    SIGTERM the same way.)
    """

    def __init__(self, signum: int):
        super().__init__(signal.Signals(signum).name)
        self.signum = signum


def _raise_interrupted(signum, frame):
    raise Interrupted(signum)


def error_line(prog: str, exc: BaseException) -> str | None:
    """The one stderr line for an error the user can act on, or None for a bug."""
    if isinstance(exc, InputError):
        return f"{prog}: error: {exc}"
    if isinstance(exc, MemoryError):
        return f"{prog}: error: out of memory: expected smaller --width/--height, fewer vertices or frames"
    if isinstance(exc, OSError) and exc.errno is not None and exc.errno != errno.EPIPE:
        where = f"{exc.filename!s}: " if exc.filename is not None else ""
        if exc.errno == errno.ENAMETOOLONG and exc.filename is not None:
            where = f"{str(exc.filename)[:60]}... ({len(str(exc.filename))} characters): "
        return f"{prog}: error: {one_line(where + (exc.strerror or str(exc)))}: expected a usable path"
    return None


def run_cli(prog: str, body, argv=None) -> int:
    """``body(argv) -> int`` under the guard (module docstring); returns the exit status.

    ``SystemExit`` (argparse's ``--help`` and usage errors) passes through.
    """
    handlers = {}
    if _main_thread():
        for sig in (signal.SIGTERM, signal.SIGINT):
            handlers[sig] = signal.signal(sig, _raise_interrupted)
    messages: list[str] = []
    try:
        with quiet_libraries() as messages:
            return body(argv)
    except Interrupted as exc:
        print(
            f"{prog}: interrupted by {exc}: temporary files removed, earlier outputs left as they were", file=sys.stderr
        )
        return 128 + exc.signum
    except KeyboardInterrupt:
        print(f"{prog}: interrupted: temporary files removed, earlier outputs left as they were", file=sys.stderr)
        return 128 + signal.SIGINT
    except BrokenPipeError:
        # stdout was closed (e.g. `renderer | head`): stop quietly, as a SIGPIPE would
        try:
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        except (OSError, ValueError):
            pass
        return 141
    except Exception as exc:  # noqa: BLE001 - the guard: nothing gets past as a traceback
        line = error_line(prog, exc)
        if line is not None:
            print(line, file=sys.stderr)
            return EXIT_USAGE
        log = write_log(prog, exc, messages)
        print(
            f"{prog}: internal error: {type(exc).__name__}: {one_line(exc)[:200]} (a bug in wirecheck, "
            f"not in your input; the traceback is in {log}; please report it)",
            file=sys.stderr,
        )
        return EXIT_INTERNAL
    finally:
        for sig, old in handlers.items():  # interrupts_from_start's exit is over once the run has been
            if getattr(old, "wirecheck_starting", False):  # (outputs may exist)
                old = signal.default_int_handler if sig == signal.SIGINT else signal.SIG_DFL
            signal.signal(sig, old)


def write_log(prog: str, exc: BaseException, messages=()) -> str:
    """Write ``exc``'s traceback (and the captured library messages) to a new file; its path."""
    fd, path = tempfile.mkstemp(prefix=f"wirecheck-{prog}-", suffix=".log")
    with os.fdopen(fd, "w", encoding="utf-8", errors="replace") as fh:
        fh.write(f"{prog} {' '.join(sys.argv[1:])}\n\n")
        fh.write("".join(traceback.format_exception(exc)))
        if messages:
            fh.write("\nLibrary messages captured during the run:\n" + "\n".join(messages) + "\n")
    return path


def _main_thread() -> bool:
    import threading

    return threading.current_thread() is threading.main_thread()


class VersionAction(argparse._VersionAction):
    """``--version`` whose ``version`` has ``{}`` for the installed version, looked up only when asked.

    The lookup (``importlib.metadata``) costs ~25 ms, which every run of a CLI
    would otherwise pay while building its parser.
    """

    def __call__(self, parser, namespace, values, option_string=None):
        self.version = self.version.format(wirecheck.__version__)
        super().__call__(parser, namespace, values, option_string)
