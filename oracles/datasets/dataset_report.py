"""A dataset run's outputs: the progress bar, the summary on stdout, report.json and report.md.

The report folder is written whole or not at all (core.outputs.output.FrameDir). It
holds no images: a dataset's worst case is named, and ``crosscheck --scene
FILE --cases CAMERA`` on that one mesh gives its frames, GIF and plots.
"""

from __future__ import annotations

from pathlib import Path

from wirecheck.core.outputs.output import FrameDir, json_dumps

from ..reports.report import finite_or_null

#: Not-passing meshes listed by name on stdout (report.md and report.json list them all).
CONSOLE_LIST = 20


class DatasetProgress:
    """A tqdm bar of meshes on ``stream`` while it is a terminal; nothing otherwise (logs and CI stay the same)."""

    def __init__(self, stream):
        self.stream = stream
        isatty = getattr(stream, "isatty", None)
        self.active = bool(isatty and isatty())
        self.bar = None

    def update(self, done: int, total: int) -> None:
        if not self.active:
            return
        if self.bar is None:
            from tqdm import tqdm

            self.bar = tqdm(
                total=total, file=self.stream, unit="mesh", desc="crosscheck", leave=False, dynamic_ncols=True
            )
        self.bar.n = done
        self.bar.refresh()

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()
            self.bar = None


def _num(v, fmt: str) -> str:
    return "-" if v is None else format(v, fmt)


def case_line(case: dict) -> str:
    """``mesh / camera: verdict, F1@1px .., vertex .. px; faults`` for one case of the summary."""
    parts = [case["verdict"]]
    if case.get("silhouette_iou") is not None:
        parts.append(f"IoU {_num(case.get('silhouette_iou'), '.4f')}")
    elif "pixel_f1_1px" in case:
        parts.append(f"F1@1px {_num(case.get('pixel_f1_1px'), '.4f')}")
    parts.append(f"vertex {_num(case.get('max_vertex_error_px'), '.3g')} px")
    faults = ", ".join(f["name"] for f in case.get("faults", []))
    return f"{case['scene']} / {case['camera']}: " + ", ".join(parts) + (f"; faults: {faults}" if faults else "")


def headline(report: dict) -> str:
    """``PASS: 197/200 meshes passed (3 could not be loaded), 1,379 cases, ...``."""
    s = report["summary"]
    extra = []
    if s["failed"]:
        extra.append(f"{s['failed']} failed")
    if s["vacuous"]:
        extra.append(f"{s['vacuous']} compared nothing")
    if s["load_errors"]:
        allowed = ", allowed" if report.get("allow_load_errors") else ""
        extra.append(f"{s['load_errors']} could not be loaded{allowed}")
    c = report["compared"]
    return (
        f"{report['verdict'].upper()}: {s['passed']}/{s['meshes']} meshes passed"
        + (f" ({'; '.join(extra)})" if extra else "")
        + f"; {s['cases']:,} cases, {c['frames']:,} frames compared ({len(report['cameras'])} cameras x "
        f"{report['frames_checked']} frames per mesh)"
    )


def timing_text(report: dict) -> str:
    t = report["timing"]
    where = t["executor"] + (f" {t['scheduler']}" if t.get("scheduler") else f", {t['workers'] or 1} process(es)")
    rate = _num(t.get("meshes_per_s"), ".2f")
    return (
        f"Timing: {_num(t.get('wall_s'), '.1f')} s ({_num(t.get('startup_s'), '.1f')} s starting workers), {rate} meshes/s "
        f"({where})"
    )


def console_summary(report: dict) -> str:
    """The lines printed after a dataset run: load errors, failing meshes, worst cases, faults, verdict."""
    s = report["summary"]
    lines = []
    if s["errors"]:
        lines.append(f"Could not be loaded ({len(s['errors'])}):")
        lines += [f"  {e['mesh']}: {e['error']}" for e in s["errors"][:CONSOLE_LIST]]
        if len(s["errors"]) > CONSOLE_LIST:
            lines.append(f"  ... and {len(s['errors']) - CONSOLE_LIST} more (report.md)")
    if s.get("warnings"):
        lines.append(f"Read leniently ({len(s['warnings'])}):")
        lines += [f"  {w['mesh']}: {w['warning']}" for w in s["warnings"][:CONSOLE_LIST]]
        if len(s["warnings"]) > CONSOLE_LIST:
            lines.append(f"  ... and {len(s['warnings']) - CONSOLE_LIST} more (report.md)")
    bad = [m for m in report["meshes"] if m["verdict"] in ("fail", "vacuous")]
    if bad:
        lines.append(f"Not passed ({len(bad)}):")
        for m in bad[:CONSOLE_LIST]:
            cams = [c["camera"] for c in m["cases"] if c["verdict"] != "pass"]
            lines.append(f"  {m['mesh']}: {m['verdict']} ({len(cams)}/{len(m['cases'])} cases: {', '.join(cams)})")
        if len(bad) > CONSOLE_LIST:
            lines.append(f"  ... and {len(bad) - CONSOLE_LIST} more (report.md)")
    if s["worst_cases"]:
        lines.append("Worst cases:")
        lines += [f"  {case_line(c)}" for c in s["worst_cases"]]
    if s["faults"]:
        lines.append(
            "Faults: " + ", ".join(f"{f['fault']} {f['cases']} cases ({f['meshes']} meshes)" for f in s["faults"])
        )
    lines += ["", headline(report), timing_text(report)]
    return "\n".join(lines)


def markdown(report: dict) -> str:
    """report.md: the headline, load errors, every mesh not passed, the worst cases and the faults."""
    s = report["summary"]
    out = [
        f"# crosscheck dataset: {report.get('run') or ''}".rstrip(),
        "",
        headline(report),
        "",
        f"Candidate: `{report['candidate']}`; level {report['level']}; sources: "
        + ", ".join(f"`{src}`" for src in report["dataset"]["sources"]),
        "",
    ]
    if s["errors"]:
        out += ["## Could not be loaded", "", "| mesh | error |", "| --- | --- |"]
        out += [f"| {e['mesh']} | {e['error'].replace('|', '/')} |" for e in s["errors"]] + [""]
    if s.get("warnings"):
        out += ["## Read leniently", "", "| mesh | warning |", "| --- | --- |"]
        out += [f"| {w['mesh']} | {w['warning'].replace('|', '/')} |" for w in s["warnings"]] + [""]
    bad = [m for m in report["meshes"] if m["verdict"] in ("fail", "vacuous")]
    if bad:
        out += ["## Not passed", "", "| mesh | verdict | cases not passed |", "| --- | --- | --- |"]
        out += [
            f"| {m['mesh']} | {m['verdict']} | "
            + ", ".join(c["camera"] for c in m["cases"] if c["verdict"] != "pass")
            + " |"
            for m in bad
        ] + [""]
    if s["worst_cases"]:
        out += ["## Worst cases", ""] + [f"- {case_line(c)}" for c in s["worst_cases"]] + [""]
    if s["faults"]:
        out += ["## Faults", "", "| fault | cases | meshes |", "| --- | --- | --- |"]
        out += [f"| {f['fault']} | {f['cases']} | {f['meshes']} |" for f in s["faults"]] + [""]
    return "\n".join(out)


def write_dataset_report(run_dir: Path, report: dict) -> Path:
    """report.json and report.md into ``run_dir``, atomically (nothing there unless both are written)."""
    run_dir = Path(run_dir)
    run_dir.parent.mkdir(parents=True, exist_ok=True)
    out = FrameDir(run_dir, "--report-dir")
    try:
        report = finite_or_null(report)
        out.write("report.json", json_dumps(report).encode())
        out.write("report.md", markdown(report).encode())
        out.commit()
    except BaseException:
        out.abort()
        raise
    return run_dir
