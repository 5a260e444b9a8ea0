"""report.json and report.md of an unprojector's check (``crosscheck --unprojector``, ``check_unprojector``).

The folder is written as a projector run's (oracles.reports.report): filled under a temporary
name and put in place whole (core.outputs.output.FrameDir), never over a folder wirecheck did not
write. Timings live only under report.json's top-level ``"timing"``; everything else, report.md
included, is the same on every run of the same inputs.
"""

from __future__ import annotations

from pathlib import Path

from wirecheck.core.outputs.output import FrameDir, json_dumps

from ..tolerances import UNPROJECT_ROUNDINGS, VERTEX_TOL_PX
from .fault_text import FULL_DIGITS, below_table, case_cell, full_text, hints, notes
from .report import finite_or_null

#: What each point is held to (oracles.tolerances.unproject_bound), in words.
BOUND_TEXT = (f"{UNPROJECT_ROUNDINGS:g} eps of its precision x each point's scale, "
              f"at least {VERTEX_TOL_PX:g} px at its depth")

HEADER = ("scene", "camera", "points", "max error", "err/bound", "verdict", "faults")


def flat_faults(case: dict) -> list[dict]:
    """A case record's faults in the catalogue's record form (``{"name": ..., **params}``), as
    oracles.reports.fault_text reads them."""
    return [{"name": f["name"], **f["params"]} for f in case["faults"]]


def failing(report: dict) -> list[dict]:
    """The cases that did not pass, their faults in record form (:func:`flat_faults`)."""
    return [{**c, "faults": flat_faults(c)} for c in report["cases"] if c["verdict"] != "pass"]


def table_rows(report: dict) -> list[tuple[str, ...]]:
    """One row per case under :data:`HEADER`: points, max error (world units), error / bound, verdict and
    the faults as a cell of at most 60 characters (oracles.reports.fault_text)."""
    rows = []
    for c in report["cases"]:
        err = "-" if c["max_error"] is None else f"{c['max_error']:.2e}"
        ratio = "-" if c["max_error_ratio"] is None else f"{c['max_error_ratio']:.3g}"
        faults = case_cell(flat_faults(c)) if c["faults"] else ("none" if c["verdict"] == "pass" else "-")
        rows.append((c["scene"], c["camera"], f"{c['points']:,}", err, ratio, c["verdict"], faults))
    return rows


def verdict_line(report: dict) -> str:
    """``PASS: 7/7 cases, 7 frames, 8,615 points compared (unprojector ...; bound: ...)``."""
    passed = sum(c["verdict"] == "pass" for c in report["cases"])
    comp = report["compared"]
    return (f"{report['verdict'].upper()}: {passed}/{comp['cases']} cases, {comp['frames']} frames, "
            f"{comp['points']:,} points compared (unprojector {report['candidate']}; bound: {BOUND_TEXT})")


def markdown(report: dict) -> str:
    """report.md: what was checked, the table, why cases failed (every fault field, rounded), what to check
    once per fault kind, the notes; no timings."""
    run = f" ({report['run']})" if report.get("run") else ""
    settings = report["settings"]
    turns = ", ".join(f"{t:g}" for t in settings["turns"])
    out = [f"# crosscheck unprojector report{run}: {report['verdict'].upper()}", "",
           f"Unprojector: `{report['candidate']}`. Reference: the exact inverse of the conventions from K, R, t "
           "(wirecheck.oracles.references.unproject_reference; OpenCV's undistortPointsIter for a lens).", "",
           f"Checked: scenes {', '.join(settings['scenes'])}; cameras {', '.join(settings['cases'])}; "
           f"{settings['frames']} frame(s) of the scenes' spin (turns {turns}) per case; the visible surface "
           f"points of each frame, one every {settings['stride']} px each way.", "",
           f"Bound: {BOUND_TEXT} (oracles.tolerances.unproject_bound).", "",
           verdict_line(report) + ".", "",
           "| " + " | ".join(HEADER) + " |", "|" + "---|" * len(HEADER)]
    out += ["| " + " | ".join(r) + " |" for r in table_rows(report)]
    bad = failing(report)
    if bad:
        out += ["", "## Why cases failed", ""]
        for c in bad:
            out.append(f"- **{c['scene']} / {c['camera']}**: " + "; ".join(c["reasons"]))
            if c["faults"]:                      # every field, rounded (report.json keeps every digit)
                out.append(f"  - faults: {full_text(c['faults'], None, FULL_DIGITS)}")
        named = hints((f for c in bad for f in c["faults"]), source="points")
        if named:
            out += ["", "## What to check", ""] + [f"- `{n}`: {h}" for n, h in named]
        shown = notes(bad)
        if shown:
            out += ["", "## Notes", ""] + [f"- {n}: {t}" for n, t in shown]
    out += ["", "Conventions: see `wirecheck.core.conventions`. The time per frame of each case is under "
            "`\"timing\"` in `report.json` (kept out of this file so that it is the same on every run).", ""]
    return "\n".join(out)


def console_lines(report: dict) -> list[str]:
    """The table as crosscheck prints it, each failing case's reasons, what to check once per fault kind,
    the verdict line."""
    rows = [HEADER, *table_rows(report)]
    widths = [max(len(r[i]) for r in rows) for i in range(len(HEADER) - 1)]
    lines = ["  ".join(v.ljust(w) for v, w in zip(r[:-1], widths)) + "  " + r[-1] for r in rows]
    bad = failing(report)
    lines += [f"  {c['scene']} / {c['camera']}: " + "; ".join(c["reasons"]) for c in bad]
    lines += below_table(bad, source="points")
    lines.append(verdict_line(report))
    return lines


def write_unprojector_report(run_dir: Path, report: dict, option: str = "--report-dir") -> Path:
    """Write report.json and report.md to ``run_dir`` at once (FrameDir); InputError (exit 2) when
    ``run_dir`` holds anything wirecheck did not write, OSError when it cannot be written."""
    run_dir = Path(run_dir)
    run_dir.parent.mkdir(parents=True, exist_ok=True)
    out = FrameDir(run_dir, option)
    try:
        report = finite_or_null(report)         # an overflowing candidate's inf: null (JSON has no inf)
        out.write("report.json", json_dumps(report).encode())
        # a name from a non-UTF-8 file name holds its bytes as lone surrogates: written as \udcff escapes
        out.write("report.md", markdown(report).encode("utf-8", "backslashreplace"))
        out.commit()
    except BaseException:
        out.abort()
        raise
    return run_dir
