"""A console script's first line: SIGINT/SIGTERM while the CLI is still importing end it with one line.

Kept apart from core.app.guard and free of imports beyond ``os``, ``signal`` and
``sys``: it runs before anything else of the CLI is imported, so the window in
which a Ctrl-C still meets Python's default handler (a KeyboardInterrupt
traceback from inside an import) is only the interpreter's own start-up.
"""

import os
import signal
import sys


def interrupts_from_start(prog: str) -> None:
    """Until core.app.guard.run_cli takes over: SIGINT/SIGTERM end the process at once with one line and 128 + the
    signal (nothing has been written yet), not a KeyboardInterrupt traceback from the middle of an import (numpy,
    trimesh, pyrender take seconds on a busy machine).

    Only in the console script ``prog`` itself (``sys.argv[0]``), in its main thread: a program or a test that
    imports the CLI module keeps its own handlers. run_cli puts Python's defaults back when it ends (its outputs
    may exist by then: "nothing written" would be false).
    """
    import threading

    if os.path.basename(sys.argv[0]) != prog or threading.current_thread() is not threading.main_thread():
        return

    def starting(signum, frame):
        os.write(2, f"{prog}: interrupted by {signal.Signals(signum).name} while starting: nothing written\n".encode())
        os._exit(128 + signum)

    starting.wirecheck_starting = True
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, starting)
