"""``crosscheck --unprojector FILE.py:FUNC`` (or ``--unprojector-cmd 'COMMAND'``): an unprojector judged.

Parses nothing of its own: :func:`unprojector_main` takes crosscheck's parsed options
(``--scene``, ``--cases``, ``--frames``, ``--spin``, ``--allow-vacuous``, ``--report-dir``, ``--run``, ``--no-report``)
and the report folder they name, calls :func:`oracles.unprojector_api.check_unprojector`, writes
report.json and report.md there (oracles.reports.unprojector_report; ``reports/<UTC time>/`` by
default, none with ``--no-report``), prints one line per case, what to check and the verdict, and
returns the exit status: 0 every case passed, 1 a case failed, 2 an input error (one line on stderr;
a report folder that holds anything wirecheck did not write is one, and nothing of it is changed).
"""

from __future__ import annotations

import sys
from pathlib import Path

from wirecheck.core.errors import InputError
from wirecheck.core.limits import check_candidate_timeout
from wirecheck.core.outputs.output import check_report_dir, claim

from .reports.report_option import report_line
from .reports.unprojector_report import console_lines, write_unprojector_report
from .unprojector_api import check_unprojector

#: Options of crosscheck that judge something else and cannot go with --unprojector.
OTHER_MODES = ("candidate", "candidate_cmd", "candidate_frames", "sweep", "suite", "junit_xml")


def unprojector_main(args, run_dir: Path, run_option: str) -> int:
    """Judge ``args.unprojector`` on ``args``' scenes and cases; write the report folder ``run_dir`` (named by
    ``run_option`` in errors) unless ``--no-report``; print the table; return the exit status."""
    given = "--unprojector" if args.unprojector is not None else "--unprojector-cmd"
    clash = [f"--{name.replace('_', '-')}" for name in OTHER_MODES if getattr(args, name, None)]
    if args.unprojector is not None and args.unprojector_cmd is not None:
        clash.append("--unprojector-cmd")
    try:
        if clash:
            raise InputError(
                f"{given} with {', '.join(clash)}: expected {given} alone with --scene, --cases, "
                "--frames, --spin, --allow-vacuous and the report folder's --report-dir, --run or --no-report"
            )
        check_candidate_timeout(args.candidate_timeout, "--candidate-timeout")  # as for --candidate
        if not args.no_report:
            check_report_dir(run_dir, run_option)
            claim(run_dir, run_option)  # held until the report is in place: one run per folder
        report = check_unprojector(
            args.unprojector,
            scenes=args.scene,
            frames=args.frames,  # None: the API's default (UNPROJECT_DEFAULTS, 2 frames)
            cases=args.cases,
            turns=args.spin,
            allow_vacuous=args.allow_vacuous,
            cmd=args.unprojector_cmd,
            timeout_s=args.candidate_timeout,
            config=False,  # [tool.wirecheck] is in args already (oracles.config.parse_cli)
        )
        if not args.no_report:
            write_unprojector_report(run_dir, {"run": args.run, **report}, run_option)
    except InputError as exc:
        print(f"crosscheck: error: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:
        print(
            f"crosscheck: error: {run_option} {str(run_dir)!r}: cannot write there ({exc}): "
            "expected a writable directory",
            file=sys.stderr,
        )
        return 2
    print("\n".join(console_lines(report)))
    print(report_line(args, run_dir, "report.md", "report.json"))
    return 0 if report["verdict"] == "pass" else 1
