"""A run's report dict (report.json) from its cases' records, whichever source drew the candidate's frames.

Both sources of frames end here: a projector whose pixels the harness draws
(oracles.runner.run_crosscheck: level ``vertices`` or ``pixels``) and a
renderer's own frames read from a job (oracles.judge.frames_judge.run_frames:
level ``frames``). What is counted is counted the same way for both: the run's
verdict (oracles.judge.gate.run_verdict), what was compared
(oracles.judge.gate.compared_totals), the summary's counts and extremes (:func:`summary`). What a
source adds is given by its caller: its settings (the drawing mode, the line
rule, the job's outputs), the limits it was held to (:func:`tolerances_field`),
its worst case and its timing.

report.json's keys are written in each source's own order (:data:`KEY_ORDER`,
as each has always written them, so that a report stays the same bytes); a key
a run does not have is left out.
"""

from __future__ import annotations

from . import gate

#: report.json's top-level keys, in the order each source writes them (a run's keys are all in its row).
KEY_ORDER = {
    "projector": (
        "tool",
        "verdict",
        "allow_vacuous",
        "compared",
        "candidate",
        "candidate_settings",
        "level",
        "style",
        "hidden_lines",
        "cull",
        "oracles",
        "oracle_gl",
        "frames",
        "every",
        "frames_checked",
        "motion",
        "tolerances",
        "summary",
        "worst_case",
        "cases",
        "timing",
    ),
    "frames": (
        "tool",
        "verdict",
        "candidate",
        "candidate_settings",
        "level",
        "style",
        "hidden_lines",
        "cull",
        "oracles",
        "oracle_gl",
        "frames",
        "every",
        "frames_checked",
        "motion",
        "tolerances",
        "allow_vacuous",
        "line_rule",
        "compared",
        "outputs",
        "depth_encoding",
        "summary",
        "cases",
        "timing",
    ),
}


def source_of(level: str) -> str:
    """Which source a level's frames come from: ``"frames"`` (a renderer's job), else ``"projector"``."""
    return "frames" if level == "frames" else "projector"


def _extreme(fn, records: list, key: str, sub: str | None = None):
    """``fn`` (min or max) of ``key`` over the records that have it (in ``rec[sub]`` when given), None when
    none does."""
    values = [(r[sub] if sub else r).get(key) for r in records if sub is None or sub in r]
    values = [v for v in values if v is not None]
    return fn(values) if values else None


def summary(records: list, level: str, shaded: bool = False, second_opinion: bool = False) -> dict:
    """The report's ``summary``: the cases counted by verdict, the largest vertex error, the lowest pixel F1;
    ``shaded`` (level pixels): the lowest silhouette IoU and the largest depth errors; ``second_opinion``
    (core beside the oracle, a renderer's frames): core's lowest F1."""
    failed = sum(1 for r in records if r["verdict"] == "fail")
    vacuous = sum(1 for r in records if r["verdict"] == "vacuous")
    out = {
        "cases": len(records),
        "passed": len(records) - failed - vacuous,
        "failed": failed,
        "vacuous": vacuous,
        "max_vertex_error_px": _extreme(max, records, "max_vertex_error_px"),
        "min_pixel_f1_0px": _extreme(min, records, "pixel_f1_0px"),
        "min_pixel_f1_1px": _extreme(min, records, "pixel_f1_1px"),
    }
    if second_opinion:
        out["min_core_f1_0px"] = _extreme(min, records, "f1_0px", "core")
        out["min_core_f1_1px"] = _extreme(min, records, "f1_1px", "core")
    if shaded and level == "pixels":
        out.update(
            {
                "min_silhouette_iou": _extreme(min, records, "silhouette_iou"),
                "max_depth_error": _extreme(max, records, "depth_max_error"),
                "max_depth_error_ratio": _extreme(max, records, "depth_error_ratio"),
            }
        )
    return out


def tolerances_field(tol, level: str, shaded: bool = False, outputs: tuple = ("wireframe",)) -> dict:
    """The report's ``tolerances``: the limits the run's cases were held to.

    A projector's (oracles.tolerances.Tolerances.to_dict, ``shaded``: the shaded limits); a renderer's frames:
    those and the line-geometry limits, the surfaces' where the job asks for depth maps or filled frames
    (``outputs``), and no candidate precision (no vertex is compared).
    """
    if level != "frames":
        return tol.to_dict(shaded=shaded)
    out = {**tol.to_dict(), **tol.lines_dict(), **(tol.surfaces_dict() if tuple(outputs) != ("wireframe",) else {})}
    del out["candidate_precision"]
    return out


def run_report(records: list, level: str, allow_vacuous: bool, fields: dict, shaded: bool = False) -> dict:
    """The run's report dict: ``fields`` (what the source says of itself: candidate, settings, oracles, frames,
    tolerances, cases, timing...) with the verdict, what was compared and the summary counted from ``records``
    (the cases' records, in order), keys in the source's order (:data:`KEY_ORDER`).

    The verdict is oracles.judge.gate.run_verdict's: ``"pass"`` only when something was compared and no case
    failed (a vacuous case fails the run unless ``allow_vacuous``).
    """
    done = gate.compared_totals(records, level)
    counted = {
        "tool": "wirecheck crosscheck",
        "verdict": gate.run_verdict(records, done, level, allow_vacuous),
        "allow_vacuous": allow_vacuous,
        "compared": done,
        "level": level,
        "summary": summary(records, level, shaded=shaded, second_opinion="core" in fields.get("oracles", ())),
        "cases": records,
    }
    merged = {**fields, **counted}
    order = KEY_ORDER[source_of(level)]
    unknown = set(merged) - set(order)
    if unknown:  # a field no source writes: a programming error, never a silent drop
        raise ValueError(f"report fields {sorted(unknown)}: not in the {source_of(level)} report's keys")
    return {key: merged[key] for key in order if key in merged}
