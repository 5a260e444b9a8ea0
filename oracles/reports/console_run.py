"""What crosscheck does once a run of any frame source is judged: the report folder and JUnit file
written, then the lines printed, the same sections for a projector (core included) and for a
renderer's frames (``--candidate-frames``); the exit status.

The lines, in order: what was compared (oracles.reports.compared.what_text), the table
(report.console_table), the line styles read (a job's frames: oracles.judge.line_style.summary_lines),
each failing case's first reasons, the notes of passing cases (once per text), what to check once per
fault kind (hint_lines), the verdict with the limits the cases were held to (:func:`verdict_line`),
the candidate's precision and the timing (where a projector was called: a job's frames have neither),
and where the report is (report_option.report_line). A section with nothing to say prints nothing, so
a source's lines are the sections it has.
"""

from __future__ import annotations

import sys
from pathlib import Path

from wirecheck.core.errors import InputError

from ..judge.line_style import summary_lines
from .compared import hint_lines, reason_text, what_text
from .junit import write_junit
from .report import compared_text, console_table, precision_text, timing_line, vacuous_text, write_report
from .report_option import report_line
from .wall import process_age_s

__all__ = ["finish_run", "run_lines", "verdict_line"]


def finish_run(args, run_dir: Path, report: dict, images: dict, tol) -> int:
    """Write ``report`` (and ``images``, its pictures) to ``run_dir`` unless ``--no-report``, the JUnit file
    where ``--junit-xml`` asks, print :func:`run_lines`; return the exit status (0 pass, 1 fail, 2 a write
    that failed: one line on stderr)."""
    try:
        if not args.no_report:
            run_dir.parent.mkdir(parents=True, exist_ok=True)  # only now: a failed run leaves no folder
            write_report(run_dir, report, images)
    except InputError as exc:
        return _error(str(exc))
    except OSError as exc:
        return _error(f"writing {str(run_dir)!r} failed: {exc}")
    if args.junit_xml:
        try:
            write_junit(Path(args.junit_xml), report)
        except InputError as exc:
            return _error(str(exc))
        except OSError as exc:
            return _error(f"--junit-xml {args.junit_xml!r}: writing failed: {exc}")
    print("\n".join(run_lines(report, tol)))
    print(report_line(args, run_dir, "report.json", "report.md, report.html"))
    return 0 if report["verdict"] == "pass" else 1


def run_lines(report: dict, tol) -> list[str]:
    """The lines printed for a judged run (module docstring), without the report's place."""
    records = report["cases"]
    failing = [r for r in records if r["verdict"] != "pass"]  # failed, or vacuous (compared nothing)
    lines = [what_text(report), console_table(records), *summary_lines(records)]
    lines += [f"  {r['scene']} / {r['camera']}: " + reason_text(r["reasons"]) for r in failing]
    notes: dict = {}  # a passing case's note, once per text: its cases named together
    for r in records:
        if r["verdict"] == "pass" and r.get("note"):
            notes.setdefault(r["note"], []).append(f"{r['scene']} / {r['camera']}")
    lines += [f"  {', '.join(where)}: {note}" for note, where in notes.items()]
    lines += hint_lines(report, failing)
    lines.append("\n" + verdict_line(report, tol))
    if report.get("level") != "frames":  # a projector was called: what it computed in, and its time
        if precision_text(report):
            lines.append(f"Candidate precision: {precision_text(report)}")
        lines.append(timing_line(report)[:-1] + f"; {process_age_s():.1f} s in all, with start-up and the report)")
    return lines


def verdict_line(report: dict, tol) -> str:
    """The run's verdict and the limits its cases were held to: a projector's vertex bound and its pixel
    or shaded limits; a job's limits for each output it asked for, and the lowest F1 against core."""
    if report.get("level") != "frames":
        return _projector_verdict(report, tol)
    return _frames_verdict(report, tol)


def _projector_verdict(report: dict, tol) -> str:
    s = report["summary"]
    limits = (
        f"silhouette IoU >= {tol.min_iou}, depth error <= its bound"
        if report.get("style") == "shaded"
        else f"F1@1px >= {tol.min_f1_1px}, F1@0px >= {tol.min_f1_0px}"
    )
    vacuous = vacuous_text(report)
    return (
        f"{report['verdict'].upper()}: {s['passed']}/{s['cases']} cases, {compared_text(report)} "
        f"(vertex <= {_vertex_limit(report, tol)}, {limits})" + (f"; {vacuous}" if vacuous else "")
    )


def _vertex_limit(report: dict, tol) -> str:
    """``1e-06 px``, or, when a case's precision raised it, where to find the bounds."""
    bounds = {c.get("vertex_bound_px", tol.vertex_px) for c in report["cases"]}
    return f"{tol.vertex_px:g} px" if bounds <= {tol.vertex_px} else "the bound of the candidate's precision"


def _error(text: str) -> int:
    print(f"crosscheck: error: {text}", file=sys.stderr)
    return 2
def _frames_verdict(report: dict, tol) -> str:
    """A job's verdict line: the limits of each output it asked for; the lowest F1 against core ('-' when not a number)."""
    s = report["summary"]

    def f1(v) -> str:
        return "-" if v is None else f"{v:.4f}"

    outputs = report.get("outputs", ["wireframe"])
    limits = (
        [f"F1@1px >= {tol.min_f1_1px}, {f1_0px_clause(report['cases'], tol.min_f1_0px)}"]
        if "wireframe" in outputs
        else []
    )
    limits += (
        [f"filled IoU >= {tol.min_iou}, runs of decided pixels missing or added <= {tol.max_silhouette_run_px}"]
        if "filled" in outputs
        else []
    )
    limits += (
        [
            f"depth error <= {tol.max_depth_error_ratio:g} x its bound, holes <= {tol.max_surface_holes_px}, "
            f"extra <= {tol.max_surface_extra_px} px away from the silhouette's boundary"
        ]
        if "depth" in outputs
        else []
    )
    core = (
        f"; against core: F1@0px >= {f1(s['min_core_f1_0px'])}, F1@1px >= {f1(s['min_core_f1_1px'])}"
        if "wireframe" in outputs
        else ""
    )
    return (
        f"{report['verdict'].upper()}: {s['passed']}/{s['cases']} cases within tolerance against pyrender "
        f"({', '.join(limits)}){core}"
    )


def f1_0px_clause(cases: list, min_f1_0px: float) -> str:
    """The verdict line's F1@0px threshold, said only of the cases it judged: aliased lines held to a pixel
    rule (``--line-rule any``: GL's or the rounded ends' read; ``gl``); antialiased and wide lines, and
    ``--line-rule geometry``, report F1@0px only."""
    held = [
        c
        for c in cases
        if not c.get("line_style")
        or (c["line_style"]["style"] == "aliased" and c["line_style"]["line_rule"] in ("gl", "any"))
    ]
    rounded = sum(1 for c in held if (c.get("line_style") or {}).get("rule_read") == "rounded")
    which = "GL's pixel rule" if not rounded else f"a pixel rule (GL's, or the rounded ends' in {rounded})"
    if len(held) == len(cases) and not rounded:
        return f"F1@0px >= {min_f1_0px}"
    if not held:
        return "F1@0px reported, not judged: no case is held to GL's pixel rule"
    return f"F1@0px >= {min_f1_0px} in the {len(held)} case{'s' if len(held) != 1 else ''} held to {which}"
