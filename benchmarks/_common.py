"""What the benchmarks share: the machine they ran on, and their tables on stdout."""

from __future__ import annotations

import json
import os
import platform
from pathlib import Path


def loadavg() -> list[str] | None:
    """The 1, 5 and 15 minute load averages (None where /proc/loadavg is missing)."""
    try:
        with open("/proc/loadavg") as fh:
            return fh.read().split()[:3]
    except OSError:
        return None


def machine_info(**extra) -> dict:
    """CPU, memory, platform and library versions, the load at the start, and ``extra`` fields."""
    import cv2
    import numpy as np
    import trimesh

    cpu_model = platform.processor() or ""
    try:
        with open("/proc/cpuinfo") as fh:
            for line in fh:
                if line.startswith("model name"):
                    cpu_model = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    try:
        usable = len(os.sched_getaffinity(0))
    except AttributeError:
        usable = os.cpu_count()
    try:
        with open("/proc/meminfo") as fh:
            mem_total = int(fh.readline().split()[1]) / 2**20
    except (OSError, ValueError, IndexError):
        mem_total = None
    return {
        "cpu_model": cpu_model,
        "cpu_count": os.cpu_count(),
        "cpus_usable": usable,
        "mem_total_gib": mem_total,
        "platform": platform.platform(),
        "python": platform.python_version(),
        "numpy": np.__version__,
        "cv2": cv2.__version__,
        "cv2_threads": cv2.getNumThreads(),
        "trimesh": trimesh.__version__,
        "loadavg_start": loadavg(),
        **extra,
    }


def print_machine(title: str, info: dict, libraries: str | None = None) -> None:
    """The benchmark's title and three lines about the machine (``libraries`` replaces the default line)."""
    ram = f"RAM {info['mem_total_gib']:.1f} GiB" if info.get("mem_total_gib") else "RAM ?"
    print(title)
    print(
        f"  cpu: {info['cpu_model'] or '?'}; cpu_count={info['cpu_count']}, usable={info['cpus_usable']}, "
        f"{ram}; load average at start {' '.join(info['loadavg_start'] or [])}"
    )
    print(
        "  "
        + (
            libraries
            or f"python {info['python']}, numpy {info['numpy']}, cv2 {info['cv2']} "
            f"(threads {info['cv2_threads']}), trimesh {info['trimesh']}"
        )
    )
    print(f"  {info['platform']}")


def print_end(info: dict, t_start: float) -> float:
    """Record the load at the end in ``info``, print it with the total time; return that time (s)."""
    import time

    elapsed = time.perf_counter() - t_start
    info["loadavg_end"] = loadavg()
    print(f"\nload average at end {' '.join(info['loadavg_end'] or [])}; total benchmark time {elapsed:.1f} s")
    return elapsed


def print_table(title: str | None, header: str, rows) -> None:
    """``title``, ``header``, a rule as wide as the header, then each row (an empty line after)."""
    if title:
        print(title)
    print(header)
    print("-" * len(header))
    for row in rows:
        print(row)
    print()


def fmt_ms(x) -> str:
    """Milliseconds with about 3 significant digits ("-" for None)."""
    if x is None:
        return "-"
    return f"{x:.4f}" if x < 0.1 else f"{x:.3f}" if x < 10 else f"{x:.1f}"


def write_json(path, **payload) -> None:
    """``payload`` (keyword order kept) as indented JSON at ``path`` (folders made as needed), and a line saying so."""
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    Path(path).write_text(json.dumps(payload, indent=2, default=str) + "\n")
    print(f"wrote {path}")


def verdict(ok: bool, miss: str = "FAIL") -> str:
    """ "PASS", or ``miss`` for a target not met."""
    return "PASS" if ok else miss
