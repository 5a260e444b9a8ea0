"""The faults of a case, named once from its evidence and its verdict, by one precedence table.

:func:`name_faults` is a pure function of the case's frozen evidence (oracles.judge.evidence.CaseEvidence),
its verdict (oracles.judge.decide.decide) and the tolerances; it returns :class:`oracles.faults.Fault`
records of the catalogue (oracles/faults.py). :data:`PRECEDENCE` lists its steps in the order they apply,
each with the families or names it wins over and why; a later step wins over what the earlier ones named.
Which names a step replaces is asked of the catalogue by family (oracles.faults.names), here and nowhere else.
"""

from __future__ import annotations

from dataclasses import dataclass

from .. import faults as catalogue
from ..diagnosis.diagnose import line_pixel_fields
from ..diagnosis.image_visibility import visibility_names
from ..faults import Fault
from ..tolerances import NAMING, Tolerances
from .decide import ROUNDED_RULE_NAME, RULE_FAULTS, Verdict, depth_map_reasons, filled_reasons
from .evidence import CaseEvidence
from .job_read import RULE_NAMES_FAMILY

__all__ = ["Precedence", "PRECEDENCE", "name_faults", "wants_visibility"]


@dataclass(frozen=True)
class Precedence:
    """One step of the naming: what it names (``step``), the names it replaces (``wins_over``: families of
    oracles.faults.FAMILIES or names), and why."""

    step: str
    wins_over: tuple[str, ...]
    why: str


#: The precedence of the names, first to last (each step may replace what the earlier ones named).
PRECEDENCE = (
    Precedence(
        "diagnosis",
        ("line_count",),
        "the faults named from the vertices or the images win over the line faults of GL's pixel counts "
        "(line_end_bias, line_pixel_bias), which are named only when the geometry agrees",
    ),
    Precedence(
        "line_centres",
        ("line_count", "scale", "offset", "unexplained"),
        "on lines no pixel rule holds (antialiased, wide, --line-rule geometry), GL's counts name nothing; "
        "where the centres were measured they are finer than the registration over thick pixels: its "
        "offset (and, unless the centres are warped, its scale) gives way to the centres' pixel_offset, "
        "which also replaces unexplained, and ends beyond their bound add line_end_bias",
    ),
    Precedence(
        "line_rule",
        ("unexplained", "offset", "line_count", "line_rule"),
        "aliased pixels that are a correct drawing by another rule are that rule's, not a camera fault: "
        "raster_rule (rounded ends under --line-rule gl, or GL-placed lines of another rule), or the "
        "rounded-ends rule's own line fault where its pixels are biased (--line-rule any)",
    ),
    Precedence(
        "job_read",
        ("unexplained", "offset", "line_count", "raster_rule"),
        "one renderer draws every case of a frames job (oracles.judge.job_read): where the job's pooled offset "
        "misses the bound, the case's lines are moved too (pixel_offset, the job's numbers, replacing what "
        "the other rule or nothing named); a case named alone by the other of raster_rule and "
        "line_pixel_bias than most of the job's failing cases gets the job's name, with its own numbers",
    ),
    Precedence(
        "dim_lines",
        tuple(catalogue.FAMILIES),
        "lines under the 128 level drew nothing by the rule: unexplained with their level replaces every "
        "name the images gave (a camera looking backward would be the wrong advice)",
    ),
    Precedence(
        "surfaces",
        (),
        "a renderer's depth maps and filled frames whose limits are missed add the faults their values "
        "(oracles.diagnosis.depth_faults) and silhouettes (oracles.diagnosis.silhouette_faults) name, "
        "each name once (the depth maps' reading first); the lines' names stand beside them",
    ),
    Precedence(
        "unexplained",
        ("unexplained",),
        "a failing case that no step named (and no candidate error explains) is unexplained, never "
        "'no fault'; a passing case has nothing to explain: an unexplained the diagnosis gave goes",
    ),
    Precedence(
        "visibility",
        ("unexplained", "line_pixel_bias"),
        "where the images fit the oracle's lines (nothing named from them) and the case fails, an "
        "unexplained, or a line_pixel_bias made of whole pieces of line, becomes the visible sets that "
        "differ",
    ),
    Precedence(
        "oracle_precision",
        ("line_count",),
        "past the oracle's precision limit its pixels say nothing of the candidate: every name read from "
        "the drawn lines (source 'pixels' in the catalogue) goes",
    ),
)


#: The line faults of one-sided pixel counts (line_end_bias, line_pixel_bias).
COUNT_FAULTS = catalogue.names("line_count")


def _diagnosis(faults, ev: CaseEvidence, verdict: Verdict, tol) -> list[Fault]:
    return list(ev.diagnosed)


def _line_centres(faults, ev: CaseEvidence, verdict: Verdict, tol) -> list[Fault]:
    s, j = ev.style, verdict.style
    if s is None or j is None or s.by_rule:
        return faults
    faults = [f for f in faults if f.name not in COUNT_FAULTS]  # GL's counts: no rule holds these lines
    if not s.placed:
        return faults
    measured = catalogue.names("scale", "offset")
    faults = [f for f in faults if f.name not in measured or j.warped and f.name != "pixel_offset"]
    geo, d = s.geometry, s.offset_px
    if j.moved and not j.job_moved:  # (the job's offset: the job_read step names it)
        faults = [f for f in faults if f.name != "unexplained"]
        faults.append(
            Fault(
                "pixel_offset",
                {
                    "dx": d[0],
                    "dy": d[1],
                    "uncertainty_px": float(max(abs(v) for v in geo["bias_px"])),
                    "confidence": 1.0,
                    "residual_px": None,
                    "measured_by": "line centroids",
                },
            )
        )
    if j.end_out:
        end, n = geo["end_px"], geo["ends_measured"]
        short = end < 0
        faults.append(
            Fault(
                "line_end_bias",
                {
                    "end_px": end,
                    "ends_measured": n,
                    "confidence": 1.0,
                    "residual_px": None,
                    "measured_by": "line ends",
                    "note": f"the lines {'stop' if short else 'run on'} {abs(end):.2f} px "
                    f"{'before' if short else 'past'} their ends (median of "
                    f"{n} free ends; a cap may add half the width)",
                },
            )
        )
    return faults


def _line_rule(faults, ev: CaseEvidence, verdict: Verdict, tol) -> list[Fault]:
    s, j = ev.style, verdict.style
    if s is None or j is None:
        return faults
    d = s.offset_px
    if j.rounded_case == "correct":
        faults = [f for f in faults if f.name not in RULE_FAULTS]
        if s.line_rule == "gl":
            faults.append(
                Fault(
                    "raster_rule",
                    {
                        **s.raster_shares,
                        "confidence": 1.0,
                        "offset_px": [d[0], d[1]],
                        "residual_px": None,
                        "rule": "rounded",
                        "note": f"the lines are a correct drawing by another rule ({ROUNDED_RULE_NAME}), "
                        "not GL's: check the line rasteriser, not the camera; without --line-rule "
                        "gl such lines pass",
                    },
                )
            )
    elif j.rounded_case == "biased":
        gives_way = COUNT_FAULTS + ("unexplained", "raster_rule")
        if s.rounded_faults and all(f.name in gives_way for f in faults):
            faults = [f for f in faults if f.name not in gives_way] + list(s.rounded_faults)
    elif (
        s.by_rule
        and j.only_gl
        and s.placed
        and not j.moved
        and not j.warped
        and s.raster["farther"] == 0
        and any(r.startswith("pixel F1@0px") for r in j.gl_reasons)
    ):
        other_rule = catalogue.names("unexplained", "offset", "line_count")
        if all(f.name in other_rule for f in faults):
            off = max(abs(d[0]), abs(d[1]))
            faults = [f for f in faults if f.name not in other_rule]
            faults.append(
                Fault(
                    "raster_rule",
                    {
                        **s.raster_shares,
                        "confidence": 1.0,
                        "offset_px": [d[0], d[1]],
                        "residual_px": None,
                        "note": f"the lines are where the oracle's are (centres within {off:.2f} px) but "
                        "their pixels follow another line rule than GL's: check the line "
                        "rasteriser (its rule across the line and at the ends), not the camera; "
                        "--line-rule geometry judges the geometry only",
                    },
                )
            )
    return catalogue.ordered(faults)


def _job_read(faults, ev: CaseEvidence, verdict: Verdict, tol) -> list[Fault]:
    s, j = ev.style, verdict.style
    if s is None or j is None or s.job is None:
        return faults
    job = s.job
    if j.job_moved and not any(f.name == "pixel_offset" for f in faults):
        replaced = catalogue.names("unexplained", "offset", "line_count") + ("raster_rule",)
        dx, dy = job["offset_px"]
        faults = [f for f in faults if f.name not in replaced] + [
            Fault(
                "pixel_offset",
                {
                    "dx": float(dx),
                    "dy": float(dy),
                    "uncertainty_px": None,
                    "confidence": 1.0,
                    "residual_px": None,
                    "measured_by": f"the job's line centroids (median of {job['offset_cases']} cases)",
                },
            )
        ]
    name = job.get("rule_name")
    if (
        name in RULE_NAMES_FAMILY
        and len(faults) == 1
        and faults[0].name in RULE_NAMES_FAMILY
        and faults[0].name != name
    ):
        if name == "raster_rule":
            d = s.offset_px
            fields = {**s.raster_shares, "confidence": 1.0, "offset_px": [d[0], d[1]], "residual_px": None}
        else:
            fields = line_pixel_fields(dict(ev.lines or {}))
        faults = [Fault(name, {**fields, "read_from": "the job's failing cases (one renderer, one rule)"})]
    return catalogue.ordered(faults)


def _dim_lines(faults, ev: CaseEvidence, verdict: Verdict, tol) -> list[Fault]:
    if ev.style is None:
        return faults
    level = int(ev.style.read.get("level") or 0)
    if not 0 < level < NAMING.drawn_level or ev.drew_pixels:
        return faults
    return [
        Fault(
            "unexplained",
            {
                "line_level": level,
                "hint": catalogue.hint_text("unexplained", "dim_lines", level=level, drawn=NAMING.drawn_level),
            },
        )
    ]


def _surfaces(faults, ev: CaseEvidence, verdict: Verdict, tol) -> list[Fault]:
    out = list(faults)
    # one name per fault: a camera mistake that moves pixels (rows flipped, half a pixel) is read from the
    # depth maps and from the silhouettes alike; the first reading stands (the depth maps' values, then the
    # silhouettes'), the other says nothing more
    if ev.depth_map is not None and depth_map_reasons(ev.depth_map, tol):
        out += [f for f in ev.depth_faults if f.name not in {g.name for g in out}]
    if ev.filled is not None and filled_reasons(ev.filled, tol):
        out += [f for f in ev.filled_faults if f.name not in {g.name for g in out}]
    return out


def _unexplained(faults, ev: CaseEvidence, verdict: Verdict, tol) -> list[Fault]:
    if verdict.verdict == "pass":
        return [f for f in faults if f.name != "unexplained"]
    why = verdict.reasons if verdict.set_aside is None else verdict.set_aside
    if why and not ev.error and not faults:
        return [Fault("unexplained")]
    return faults


def _visibility(faults, ev: CaseEvidence, verdict: Verdict, tol) -> list[Fault]:
    v = ev.visibility
    if v is None or not wants_visibility(faults, ev, verdict):
        return faults
    named = visibility_names(
        [f.as_dict() for f in faults],
        (v.candidate_only_px, v.oracle_only_px),
        v.frames_diagnosed,
        v.frames_checked,
        NAMING.visibility_share,
    )
    return [Fault.of(f) for f in named]


def _oracle_precision(faults, ev: CaseEvidence, verdict: Verdict, tol) -> list[Fault]:
    if verdict.set_aside is None:
        return faults
    return [f for f in faults if f.kind.source != "pixels"]


_STEPS = {
    "diagnosis": _diagnosis,
    "line_centres": _line_centres,
    "line_rule": _line_rule,
    "job_read": _job_read,
    "dim_lines": _dim_lines,
    "surfaces": _surfaces,
    "unexplained": _unexplained,
    "visibility": _visibility,
    "oracle_precision": _oracle_precision,
}


def wants_visibility(faults, ev: CaseEvidence, verdict: Verdict) -> bool:
    """Whether the visibility step would read the visible sets (``ev.visibility``, measured only then): the
    case fails, nothing was named from the images, and its one name is unexplained or line_pixel_bias."""
    return (
        verdict.verdict == "fail"
        and not ev.image_faults
        and len(faults) == 1
        and faults[0].name in ("unexplained", "line_pixel_bias")
    )


def name_faults(ev: CaseEvidence, verdict: Verdict, tol: Tolerances) -> tuple[Fault, ...]:
    """The case's faults, by :data:`PRECEDENCE`'s steps in order, each given what the earlier ones named."""
    faults: list[Fault] = []
    for rule in PRECEDENCE:
        faults = _STEPS[rule.step](faults, ev, verdict, tol)
    return tuple(faults)
