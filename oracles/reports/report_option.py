"""``--no-report``: a run that prints its table and verdict and writes no report folder.

A plain run writes ``reports/<UTC time>/`` in the working directory by
default; the console's ``Report:`` line says so and names the option that
turns it off. The options that only name or shape the report folder
(``--report-dir``, ``--run``) and the runs whose product is the folder itself
(``--sweep``, ``--suite``) are refused with it; a frames job
(``--candidate-frames``) is judged as any run is: its table, verdict and exit
status, no folder;
``--junit-xml`` is a file of its own and is still written.
"""

from __future__ import annotations

import os
from pathlib import Path

from wirecheck.core.errors import InputError

from .fmt import short_repr


def check_no_report(args) -> None:
    """InputError (one line, exit 2) for ``--no-report`` with an option that needs the report folder."""
    if not args.no_report:
        return
    clash = [opt for opt, given in (("--report-dir", args.report_dir is not None), ("--run", args.run is not None),
                                    ("--sweep", args.sweep), ("--suite", args.suite is not None)) if given]
    if clash:
        raise InputError(f"--no-report with {', '.join(clash)}: --no-report writes no report folder; expected "
                         "one or the other (--junit-xml is still written with --no-report)")


def report_line(args, run_dir: Path, main: str, also: str) -> str:
    """The console's last line: where the report is, or that none was written.

    The default folder (no ``--report-dir``, no ``--run``) is one the user did
    not ask for: the line names ``--no-report``, which turns it off.
    """
    if args.no_report:
        return "Report: none written (--no-report)"
    where = f"Report: {run_dir / main} (also {also}"
    if args.report_dir is None and args.run is None:
        return where + "; --no-report writes none)"
    return where + ")"


def checked_report_dir(report_dir):
    """``report_dir`` as a Path (None: none), checked before anything runs: TypeError for a non-path,
    ValueError (InputError) for a path that is a file (the API's ``report_dir=``: check_projector's,
    check_frames', check_unprojector's)."""
    if report_dir is None:
        return None
    if isinstance(report_dir, bool) or not isinstance(report_dir, (str, os.PathLike)):
        raise TypeError(f"report_dir {short_repr(report_dir)}: expected a folder path (str or Path), or None")
    path = Path(report_dir)
    if path.exists() and not path.is_dir():
        raise InputError(f"report_dir {str(path)!r} is a file: expected a folder for the report")
    return path
