"""SIGINT/SIGTERM at a random moment of a renderer run whose mesh reads companion files (issue 25, item 4).

The run is a real process (``python -m``-style, as a user's shell starts it):
the signal may land in the imports, in trimesh's reading of the ``.mtl`` and
its texture (where trimesh catches every exception), in the drawing or in the
commit. The contract: exit 0 with the complete output, or exit 130/143 with
no output folder and the one "interrupted" line; never a traceback, never
another status, never a hang (60 s).
"""

from __future__ import annotations

import signal
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent.parent

OBJ = "mtllib m.mtl\nusemtl x\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 3 4\n"
#: a 1x1 grey PNG, the material's texture
TEXTURE = bytes.fromhex(
    "89504e470d0a1a0a0000000d4948445200000001000000010800000000"
    "3a7e9b550000000a49444154789c63600000000200015e8a1a6c0000000049454e44ae426082"
)


def _before_first_line(err: str) -> bool:
    """True when a KeyboardInterrupt traceback has no frame of core/app/cli.py past its interrupts_from_start line."""
    import re

    start = next(
        n
        for n, line in enumerate((ROOT / "core" / "cli.py").read_text().splitlines(), 1)
        if line.startswith("interrupts_from_start(")
    )
    lines = [int(m) for m in re.findall(r'core/cli\.py", line (\d+)', err)]
    return "KeyboardInterrupt" in err and all(n <= start for n in lines)


def interrupt_one(pick, box: Path, timeout_s: float = 60) -> tuple[int, list[str]]:
    """Run renderer on a textured OBJ in ``box``, signal it after a drawn delay; ``(exit status, problems)``."""
    (box / "a.obj").write_text(OBJ)
    (box / "m.mtl").write_text("newmtl x\nKd 1 1 1\nmap_Kd t.png\n")
    (box / "t.png").write_bytes(TEXTURE)
    sig = pick.choice([signal.SIGINT, signal.SIGTERM])
    delay = pick.integer(0, 3000) / 1000
    out = box / "out"
    renderer = Path(sys.executable).parent / "renderer"  # the console script, as a user starts it
    proc = subprocess.Popen(
        [
            str(renderer),
            "--scene",
            str(box / "a.obj"),
            "--frames",
            str(pick.integer(1, 30)),
            "--width",
            "64",
            "--height",
            "48",
            "--out",
            str(out),
        ],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    time.sleep(delay)
    if proc.poll() is None:
        proc.send_signal(sig)
    try:
        _, err = proc.communicate(timeout=timeout_s)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait()
        return -1, [f"timeout: over {timeout_s:g} s after {signal.Signals(sig).name}"]
    rc, problems = proc.returncode, []
    if "Traceback" in err:
        if _before_first_line(err) and not out.exists():  # no code of wirecheck's ran yet: counted apart
            return rc, ["note: interrupted in Python's own start-up (site, encodings), before wirecheck's first line"]
        problems.append("traceback on stderr (in the run)")
    if rc == 128 + sig and "while starting: nothing written" in err:
        if out.exists():
            problems.append(f"exit {rc} while starting, with an output folder")
    elif rc == 128 + sig:
        if out.exists():
            problems.append(f"exit {rc} with an output folder: {sorted(p.name for p in out.iterdir())[:3]}")
    elif rc == 0:
        if not any(out.glob("a-report.json")):
            problems.append("exit 0 without the report")
    elif rc == -sig and not out.exists():
        problems.append("note: killed by the signal's default action before wirecheck's first line")
    else:
        problems.append(f"exit {rc} after {signal.Signals(sig).name}: {err.strip()[-200:]}")
    return rc, problems
