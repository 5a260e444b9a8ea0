"""``crosscheck --unprojector FILE.py:FUNC`` (or ``--unprojector-cmd 'COMMAND'``): an unprojector judged.

Parses nothing of its own: :func:`unprojector_main` takes crosscheck's parsed options
(``--scene``, ``--cases``, ``--frames``, ``--spin``), calls
:func:`oracles.unprojector_api.check_unprojector`, prints one line per case, what to check and
the verdict, and returns the exit status: 0 every case passed, 1 a case failed, 2 an input
error (one line on stderr). No report folder is written.
"""

from __future__ import annotations

import sys

from wirecheck.core.errors import InputError
from wirecheck.core.limits import check_candidate_timeout

from .reports.fault_text import below_table, case_cell
from .unprojector_api import check_unprojector, flat_faults

#: Options of crosscheck that judge something else and cannot go with --unprojector.
OTHER_MODES = ("candidate", "candidate_cmd", "candidate_frames", "sweep", "suite", "junit_xml", "report_dir", "run")

#: The frames per case when --frames is not given.
DEFAULT_FRAMES = 2


def unprojector_main(args) -> int:
    """Judge ``args.unprojector`` on ``args``' scenes and cases; print the table; return the exit status."""
    given = "--unprojector" if args.unprojector is not None else "--unprojector-cmd"
    clash = [f"--{name.replace('_', '-')}" for name in OTHER_MODES if getattr(args, name, None)]
    if args.unprojector is not None and args.unprojector_cmd is not None:
        clash.append("--unprojector-cmd")
    try:
        if clash:
            raise InputError(f"{given} with {', '.join(clash)}: expected {given} alone with "
                             "--scene, --cases, --frames and --spin (it writes no report folder)")
        check_candidate_timeout(args.candidate_timeout, "--candidate-timeout")     # as for --candidate
        report = check_unprojector(args.unprojector, scenes=args.scene,
                                   frames=args.frames if args.frames is not None else DEFAULT_FRAMES,
                                   cases=args.cases, turns=args.spin, cmd=args.unprojector_cmd,
                                   timeout_s=args.candidate_timeout)
    except InputError as exc:
        print(f"crosscheck: error: {exc}", file=sys.stderr)
        return 2
    print("\n".join(report_lines(report)))
    return 0 if report["verdict"] == "pass" else 1


def report_lines(report: dict) -> list[str]:
    """The table (scene, camera, points, max error, error / bound, verdict, faults: a cell of at most 60
    characters, oracles.reports.fault_text), each failing case's reasons, what to check once per fault
    kind, the verdict."""
    rows = [("scene", "camera", "points", "max error", "err/bound", "verdict", "faults")]
    for c in report["cases"]:
        err = "-" if c["max_error"] is None else f"{c['max_error']:.2e}"
        ratio = "-" if c["max_error_ratio"] is None else f"{c['max_error_ratio']:.3g}"
        faults = case_cell(flat_faults(c)) if c["faults"] else ("none" if c["verdict"] == "pass" else "-")
        rows.append((c["scene"], c["camera"], f"{c['points']:,}", err, ratio, c["verdict"], faults))
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]) - 1)]
    lines = ["  ".join(v.ljust(w) for v, w in zip(r[:-1], widths)) + "  " + r[-1] for r in rows]
    for c in report["cases"]:
        if c["verdict"] != "pass":
            lines.append(f"  {c['scene']} / {c['camera']}: " + "; ".join(c["reasons"]))
    lines += below_table([{**c, "faults": flat_faults(c)} for c in report["cases"] if c["verdict"] != "pass"],
                         source="points")
    passed = sum(c["verdict"] == "pass" for c in report["cases"])
    comp = report["compared"]
    lines.append(f"{'PASS' if report['verdict'] == 'pass' else 'FAIL'}: {passed}/{comp['cases']} cases, "
                 f"{comp['frames']} frames, {comp['points']:,} points compared (unprojector {report['candidate']}; "
                 "bound: 16 eps of its precision x each point's scale, at least 1e-06 px at its depth)")
    return lines
