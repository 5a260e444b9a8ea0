"""The caller's process-wide state, kept across a call into wirecheck's Python API.

A check imports scipy, OpenCV, matplotlib and (at level pixels) pyrender,
and those imports change globals that belong to the caller: scipy adds
warning filters, ``import cv2`` prepends to ``LD_LIBRARY_PATH`` in
``os.environ``, the pyrender oracle sets ``PYOPENGL_PLATFORM``. A user's test
suite must run the same after ``check_projector`` as before it, so
:func:`caller_state_kept` puts back what a call changed: the warning filters,
numpy's error state and print options, ``os.environ``, ``sys.path``, the
current directory, the root logger's level and handlers and
``logging.disable``, the Python-level signal handlers, and
``sys.dont_write_bytecode``. What the imports *are* stays (modules are
imported once per process); only the settings go back.
"""

from __future__ import annotations

import contextlib
import logging
import os
import signal
import sys
import threading
import warnings


def _signal_handlers() -> dict:
    """The handlers Python can put back (``getsignal`` is None for ones installed outside Python)."""
    out = {}
    for sig in signal.valid_signals():
        try:
            handler = signal.getsignal(sig)
        except (ValueError, OSError):
            continue
        if handler is not None:
            out[sig] = handler
    return out


def _restore_environ(before: dict) -> None:
    for key in [k for k in os.environ if k not in before]:
        del os.environ[key]
    for key, value in before.items():
        if os.environ.get(key) != value:
            os.environ[key] = value


@contextlib.contextmanager
def caller_state_kept():
    """Run the body, then put the caller's globals back as they were (module docstring)."""
    import numpy as np

    environ, path, cwd = dict(os.environ), list(sys.path), os.getcwd()
    root = logging.getLogger()
    log_level, log_handlers, log_disable = root.level, list(root.handlers), logging.root.manager.disable
    bytecode = sys.dont_write_bytecode
    main_thread = threading.current_thread() is threading.main_thread()
    handlers = _signal_handlers() if main_thread else {}
    try:
        with warnings.catch_warnings(), np.errstate(), np.printoptions():
            yield
    finally:
        _restore_environ(environ)
        sys.path[:] = path
        if os.getcwd() != cwd:
            with contextlib.suppress(OSError):
                os.chdir(cwd)
        root.setLevel(log_level)
        root.handlers[:] = log_handlers
        logging.disable(log_disable)
        sys.dont_write_bytecode = bytecode
        if main_thread:
            for sig, handler in handlers.items():
                if signal.getsignal(sig) is not handler:
                    with contextlib.suppress(ValueError, OSError, TypeError):
                        signal.signal(sig, handler)
