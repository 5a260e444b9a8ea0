"""What several test modules share: the two CLIs run in-process, and 8-connectivity of pixels."""

from __future__ import annotations

import contextlib
import io
import json


def run_renderer(args, out) -> tuple[int, str, str]:
    """``renderer`` with ``args + --out out``, stdout/stderr captured: ``(rc, stdout, stderr)``."""
    from wirecheck.core.app.cli import main

    o, e = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(o), contextlib.redirect_stderr(e):
        try:
            rc = main(list(args) + ["--out", str(out)])
        except SystemExit as exc:       # argparse usage errors
            rc = exc.code
    return rc, o.getvalue(), e.getvalue()


def run_crosscheck(tmp_path, *args, name="run"):
    """``crosscheck --report-dir tmp_path/name args``: ``(exit code, report.json or None, run dir)``."""
    from wirecheck.oracles import cli

    out = tmp_path / name
    code = cli.main(["--report-dir", str(out), *args])
    report = json.loads((out / "report.json").read_text()) if (out / "report.json").exists() else None
    return code, report, out


def eight_connected(pixels) -> bool:
    """True when the ``(row, col)`` pixels form one 8-connected set (or none)."""
    pixels = set(pixels)
    if not pixels:
        return True
    start = next(iter(pixels))
    seen, stack = {start}, [start]
    while stack:
        r, c = stack.pop()
        for dr in (-1, 0, 1):
            for dc in (-1, 0, 1):
                q = (r + dr, c + dc)
                if q in pixels and q not in seen:
                    seen.add(q)
                    stack.append(q)
    return seen == pixels


def assert_help_states_defaults(parser) -> None:
    """Every option of ``parser`` but -h/--version has help naming its default; no reStructuredText in --help."""
    for action in parser._actions:
        if action.dest not in ("help", "version"):          # -h and --version take no value
            assert action.help and "default" in action.help, action.option_strings
    text = parser.format_help()
    assert "``" not in text and ":func:" not in text and ":mod:" not in text


def blank_job(job):
    """Export a frames job of cube / on_axis, frames 1 and 3 of 4, into ``job`` and fill it with black
    640x480 PNGs (a renderer that drew nothing: judged, it fails); returns ``job``."""
    from PIL import Image

    from wirecheck.oracles import cli

    assert cli.main(["export", str(job), "--scene", "cube", "--cases", "on_axis", "--frames", "4",
                     "--every", "2"]) == 0
    (job / "frames/cube/on_axis").mkdir(parents=True)
    for k in (1, 3):
        Image.new("L", (640, 480)).save(job / f"frames/cube/on_axis/frame_{k:04d}.png")
    return job


def process_runs(pid: int) -> bool:
    """Whether ``/proc`` shows ``pid`` running: False once it has ended, reaped or not (a zombie has ended;
    only its parent's reaping is left). Linux."""
    from pathlib import Path

    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except (FileNotFoundError, ProcessLookupError):
        return False
    return state != "Z"

