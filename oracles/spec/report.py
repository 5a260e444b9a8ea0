"""The spec suite's console text and spec.md, from the result of ``run_spec``."""

from __future__ import annotations

from ..reports.compared import reason_text
from ..reports.fault_text import case_cell, hints
from ..reports.report import console_table, gl_text


def _run_rows(result: dict) -> list[dict]:
    """The runs as crosscheck table rows: the camera cell says the distance, FOV and frame count."""
    return [
        {**r, "camera": f"{r['camera']}, {r['frames']} frame{'' if r['frames'] == 1 else 's'}"} for r in result["runs"]
    ]


def _err(v) -> str:
    return "-" if v is None else f"{v:.2g}"


def check_rows(result: dict) -> list[list[str]]:
    """``[check, kind, error px, bound px, verdict, faults]`` per named check."""
    return [
        [c["name"], c["kind"], _err(c["error_px"]), _err(c["bound_px"]), c["verdict"], case_cell(c["faults"])]
        for c in result["checks"]
    ]


def _table(rows: list[list[str]]) -> str:
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]) - 1)]
    return "\n".join("  ".join(r[i].ljust(widths[i]) for i in range(len(widths))) + "  " + r[-1] for r in rows)


def _headline(result: dict) -> str:
    m = result["matrix"]
    level = "OpenCV and pyrender" if result["level"] == "pixels" else "OpenCV (level vertices)"
    return (
        f"Spec suite: {len(m['scenes'])} scenes x camera z {', '.join(f'{z:g}' for z in m['camera_z'])} x "
        f"FOV {', '.join(f'{f:g}' for f in m['fov_deg'])} x {', '.join(map(str, m['frames']))} frames = "
        f"{m['runs']} runs against {level}, and {len(result['checks'])} named checks; "
        f"candidate {result['candidate']}"
    )


def _verdict_line(result: dict) -> str:
    s = result["summary"]
    c = s["compared"]
    pixels = f", {c['pixels']:,} pixels" if c.get("pixels") is not None else ""
    line = (
        f"{result['verdict'].upper()}: {s['runs_passed']}/{s['runs']} runs ({c['frames']:,} frames, "
        f"{c['vertices']:,} vertices{pixels} compared), {s['checks_passed']}/{s['checks']} named checks"
    )
    return line + (f" ({'; '.join(result['why'])})" if result["why"] else "")


def spec_console(result: dict) -> list[str]:
    """What ``crosscheck --suite spec`` prints: the runs' table, the checks' table, reasons, the verdict."""
    runs = _run_rows(result)
    lines = [_headline(result), console_table(runs), ""]
    lines.append(_table([["check", "kind", "error px", "bound px", "verdict", "faults"]] + check_rows(result)))
    for r in runs:
        if r["verdict"] != "pass":
            lines.append(f"  {r['scene']} / {r['camera']}: " + reason_text(r["reasons"]))
    for c in result["checks"]:
        if c["verdict"] != "pass":
            lines.append(f"  {c['name']}: " + reason_text(c["reasons"]))
    faults = [f for r in result["runs"] for f in r["faults"]] + [f for c in result["checks"] for f in c["faults"]]
    lines += [f"  what to check, {n}: {h}" for n, h in hints(faults)]
    lines += ["", _verdict_line(result)]
    return lines


def spec_markdown(result: dict) -> str:
    """spec.md: the matrix, the runs, each check with what it proves, expected values and reasons."""
    m = result["matrix"]
    lines = [
        f"## Spec suite: {result['verdict'].upper()}",
        "",
        f"Candidate: {result['candidate']}"
        + (f" (declared {result['candidate_precision']})" if result.get("candidate_precision") else "")
        + f". Level: {result['level']}.",
        *([f"Oracle GL: {gl_text(result)}."] if gl_text(result) else []),
        "",
        f"Matrix: scenes {', '.join(m['scenes'])} x camera z {', '.join(f'{z:g}' for z in m['camera_z'])} "
        f"(at (0, 0, z) looking at the origin) x FOV {', '.join(f'{f:g}' for f in m['fov_deg'])} x "
        f"{', '.join(map(str, m['frames']))} frames, turning {m['turns'][0]:g} about X and "
        f"{m['turns'][1]:g} about Y: {m['runs']} runs.",
        "",
        "### Runs",
        "",
        "| run | max vertex err px | F1@0px | F1@1px | verdict | faults |",
        "| --- | --- | --- | --- | --- | --- |",
    ]
    for r in result["runs"]:
        f0, f1 = r.get("pixel_f1_0px"), r.get("pixel_f1_1px")
        lines.append(
            f"| {r['run']} | {_err(r.get('max_vertex_error_px'))} | "
            f"{'-' if f0 is None else f'{f0:.4f}'} | {'-' if f1 is None else f'{f1:.4f}'} | "
            f"{r['verdict']} | {case_cell(r['faults'])} |"
        )
    lines += [
        "",
        "### Named checks",
        "",
        "| check | kind | error px | bound px | verdict | faults |",
        "| --- | --- | --- | --- | --- | --- |",
    ]
    lines += [f"| {' | '.join(row)} |" for row in check_rows(result)]
    lines.append("")
    for c in result["checks"]:
        lines.append(f"- **{c['name']}** ({c['kind']}): {c['proves']}.")
        for r in c["reasons"]:
            lines.append(f"  - FAIL: {r}")
    failing = [r for r in result["runs"] if r["verdict"] != "pass"]
    if failing:
        lines += ["", "### Runs not passed", ""]
        lines += [f"- {r['run']}: {'; '.join(r['reasons'])}" for r in failing]
    what = hints([f for r in result["runs"] for f in r["faults"]] + [f for c in result["checks"] for f in c["faults"]])
    if what:
        lines += ["", "## What to check", ""] + [f"- `{n}`: {h}" for n, h in what]
    lines += ["", _verdict_line(result)]
    return "\n".join(lines) + "\n"
