"""How long this process has run, start-up included: the wall time a user measures with ``time``.

The runner's ``wall_s`` times the cases only; interpreter start-up, imports (OpenCV, pyrender,
scipy: seconds) and writing the report come on top, so the CLI prints both.
"""

from __future__ import annotations

import os
import time

_IMPORTED = time.monotonic()


def process_age_s() -> float:
    """Seconds since this process started (Linux: /proc; elsewhere: since this module was imported)."""
    try:
        with open("/proc/self/stat") as fh:
            after_name = fh.read().rsplit(")", 1)[1].split()
        start_ticks = int(after_name[19])                 # field 22, starttime, in clock ticks after boot
        with open("/proc/uptime") as fh:
            uptime_s = float(fh.read().split()[0])
        age = uptime_s - start_ticks / os.sysconf("SC_CLK_TCK")
        if age >= 0:
            return age
    except (OSError, ValueError, IndexError):
        pass
    return time.monotonic() - _IMPORTED
