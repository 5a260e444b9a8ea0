"""One progress line for a terminal: cases and frames done, cleared when the run ends.

Nothing is written when the stream is not a terminal (a log, a pipe, CI), so
captured output stays the same whatever the run's speed.
"""

from __future__ import annotations


class TerminalProgress:
    """``update(cases_done, cases, frames_done, frames)`` rewrites one line on ``stream``; ``close()`` clears it.

    The signature is that of ``progress`` in :func:`oracles.runner.run_crosscheck`.
    """

    def __init__(self, stream, prefix: str = "crosscheck"):
        self.stream = stream
        self.prefix = prefix
        isatty = getattr(stream, "isatty", None)
        self.active = bool(isatty and isatty())
        self.width = 0            # length of the line on screen, to clear it

    def update(self, cases_done: int, cases: int, frames_done: int, frames: int) -> None:
        if not self.active:
            return
        line = f"{self.prefix}: {cases_done}/{cases} cases, {frames_done:,}/{frames:,} frames"
        self.stream.write("\r" + line.ljust(self.width))
        self.stream.flush()
        self.width = max(self.width, len(line))

    def close(self) -> None:
        """Blank the line and return the cursor to its start (nothing if nothing was written)."""
        if self.active and self.width:
            self.stream.write("\r" + " " * self.width + "\r")
            self.stream.flush()
        self.width = 0
