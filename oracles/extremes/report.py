"""The extremes suite's Markdown report, from the result of ``run_extremes``."""

from __future__ import annotations

from ..reports.report import gl_text


def _fmt(v, digits=2):
    if v is None:
        return "-"
    return v if isinstance(v, str) else f"{v:.{digits}g}"  # "inf" (record.json_float) as is


def _pyrender_cell(pyr) -> str:
    if pyr is None:
        return "-"
    if pyr.get("f1_1px_judged") is None:
        return f"{pyr['f1_1px']:.3f} (info)"
    txt = f"{pyr['f1_1px_judged']:.3f}"
    if pyr["f1_1px"] < pyr["f1_1px_judged"]:
        txt += f" (info frames: {pyr['f1_1px']:.3f})"
    return txt


def _case_lines(c: dict) -> list[str]:
    lines = [f"- **{c['name']}**: {c['description']}. Bound: {c['bound_derivation']}"]
    pp = c.get("project_points")
    if pp:
        lines.append(
            f"  (project_points, the world path: float64 {_fmt(pp['float64']['max_error_px'])} px, "
            f"float32 {_fmt(pp['float32']['max_error_px'])} px, bound "
            f"{_fmt(pp['float32']['bound_px'])} px)"
        )
    if c["pyrender_note"]:
        lines.append(f"  (pyrender: {c['pyrender_note']})")
    for r in c["reasons"]:
        lines.append(f"  - FAIL: {r}")
    return lines


def _bound_lines(bounds: dict) -> list[str]:
    lines = [
        "",
        "### Bounds",
        "",
        "Derivations (wirecheck.oracles.extremes.bounds, each function's docstring): u = eps / 2 is the unit "
        "roundoff of the run's dtype, eps64 float64's eps.",
        "",
    ]
    for name, text in bounds.items():
        first, *rest = text.split("\n\n")
        lines.append(f"- **{name}**: {first}")
        for p in rest:
            lines += ["", f"  {p}"]
    return lines


def extremes_markdown(result: dict) -> str:
    """A Markdown table of the cases, one line per case on what it checks and its bound, the derivations."""
    lines = [
        f"## Extremes suite: {result['verdict'].upper()}",
        "",
        *([f"Oracle GL: {gl_text(result)}.", ""] if gl_text(result) else []),
        "| case | float64 error px | bound px | float32 error px | bound px | pyrender F1@1 | verdict |",
        "| --- | --- | --- | --- | --- | --- | --- |",
    ]
    for c in result["cases"]:
        f64, f32 = c["float64"] or {}, c["float32"] or {}
        lines.append(
            f"| {c['name']} | {_fmt(f64.get('max_error_px'))} | {_fmt(f64.get('bound_px'))} | "
            f"{_fmt(f32.get('max_error_px'))} | {_fmt(f32.get('bound_px'))} | "
            f"{_pyrender_cell(c['pyrender'])} | {c['verdict']} |"
        )
    lines += [
        "",
        "Bound px is the bound at the point of the largest error (every point's error must be "
        "within its own bound). pyrender F1@1: the smallest over the frames a case judges; "
        "(info) frames are reported, not judged. "
        "Errors are against a long-double reference computed from wirecheck.core.conventions.",
        "",
    ]
    for c in result["cases"]:
        lines += _case_lines(c)
    lines += _bound_lines(result["bounds"])
    return "\n".join(lines) + "\n"
