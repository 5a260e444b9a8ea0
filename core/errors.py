"""The one exception type for bad input, and quieting the libraries that would print around it.

CLIs turn an :class:`InputError` into one stderr line, exit 2 (core.app.guard).
"""

from __future__ import annotations

import contextlib
import logging
import re
import warnings


class InputError(ValueError):
    """Bad user input: a scene file, an argument, a camera.

    The message is one line that says which file (or option), which line, which
    value and what was expected. Text from elsewhere (a library's message with
    newlines in it) is joined onto that line by :func:`one_line`.
    """

    def __str__(self) -> str:
        return one_line(super().__str__())


def one_line(text) -> str:
    """``text`` with every line break (and the blanks around it) replaced by ``" | "``."""
    return re.sub(r"\s*[\r\n]+\s*", " | ", str(text).strip())


@contextlib.contextmanager
def quiet_libraries(loggers=("trimesh",)):
    """Keep third-party chatter off stderr while the block runs; yields the captured messages.

    Python warnings (numpy's RuntimeWarning on overflow in a cast, trimesh's)
    and records of the named loggers (trimesh logs a full traceback when an
    ASCII STL's ``facet normal`` does not parse, then carries on without the
    normals, which nothing here uses) are collected instead of printed. They
    are harmless by then: every input they come from is validated after the
    library call (finite vertices, face indices in range), and that check is
    what the user sees. Yields a list of one-line strings, for a log.
    """
    messages: list[str] = []

    class _Collect(logging.Handler):
        def emit(self, record):
            messages.append(one_line(f"{record.name}: {record.getMessage()}"))

    handler = _Collect(level=logging.DEBUG)
    saved = []
    for name in loggers:
        log = logging.getLogger(name)
        saved.append((log, log.propagate))
        log.addHandler(handler)
        log.propagate = False
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            yield messages
        messages += [one_line(f"{w.category.__name__}: {w.message} ({w.filename}:{w.lineno})") for w in caught]
    finally:
        for log, propagate in saved:
            log.removeHandler(handler)
            log.propagate = propagate


def check_not_empty(options) -> None:
    """InputError for the first ``(option, value)`` whose value is ``''`` (or a list holding ``''``).

    An empty value (an unset shell variable in ``--out "$DIR"``) would
    otherwise mean the working directory (``Path('')`` is ``.``) or the
    option's default, silently.
    """
    for option, value in options:
        if value == "" or (isinstance(value, list) and "" in value):
            raise InputError(
                f"{option} '': expected a name or path (an empty value, often an unset shell "
                "variable, would silently mean the working directory or the default)"
            )
