"""One renderer, one reading: what a job's cases say together about the renderer that drew them.

A frames job (``crosscheck --candidate-frames``) is drawn by one renderer: one line style, one raster
rule, one placement of its lines. Each case reads them from its own frames, and a case whose lines cannot
show a property (lines square-on to the pixel grid show no half-pixel move; a few grey pixels make a
binary drawing look antialiased; lines of another rule agree with GL's in one case and not the next) may
read it otherwise than the job's other cases. :func:`read_job` pools the cases' reads into one
:class:`JobRead`, and :func:`differs` says which cases read the renderer otherwise; the frames judge
(oracles.judge.frames_judge.run_frames) judges those again under the job's read, so that every case of a
job gets the same style, the same rule and the same placement:

- **style**: the style most cases read (a tie: none imposed);
- **rule**: the aliased rule most cases read (``gl``, ``rounded``; a tie: none);
- **rule name**: the name most failing cases are given alone of the two that say the pixels follow
  another rule than GL's (``raster_rule``, ``line_pixel_bias``; a tie: ``raster_rule``, the general
  one): one rule that misses GL's gets one name, its own numbers in each case;
- **offset**: the median, per axis, of the centre offsets measured in the cases (at least
  :data:`MIN_OFFSET_CASES` of them): a renderer that moves every line moves them in every case, and the
  median of the cases ignores the one case whose lines cannot show it (or that has a fault of its own).

The pooling never makes a case pass: a case judged again keeps every limit it missed on its own
(oracles.judge.decide), and the job's read only adds what the other cases measured.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import asdict, dataclass

import numpy as np

from .line_style import PLACEMENT_FAULTS  # faults that put the lines elsewhere: their offsets are not pooled

__all__ = ["JobRead", "MIN_OFFSET_CASES", "RULE_NAMES_FAMILY", "read_job", "differs"]

#: The job's offset is the median over at least this many cases' offsets (fewer: a case's own, no pooling).
MIN_OFFSET_CASES = 3

#: The names pixels that follow another rule than GL's get (one per job: :func:`read_job`'s rule name); an
#: end fault (line_end_bias) is a fault of its own, never renamed.
RULE_NAMES_FAMILY = ("raster_rule", "line_pixel_bias")


@dataclass(frozen=True)
class JobRead:
    """The job's read of its renderer, pooled over ``cases`` cases (module docstring); None: not imposed."""

    cases: int
    style: str | None
    rule: str | None
    rule_name: str | None
    offset_px: tuple[float, float] | None
    offset_cases: int

    def as_dict(self) -> dict:
        out = asdict(self)
        if self.offset_px is not None:
            out["offset_px"] = [float(v) for v in self.offset_px]
        return out


def _plurality(values: list) -> str | None:
    """The one most common value (None when there is none, or two share the top count)."""
    top = Counter(values).most_common(2)
    if not top or (len(top) == 2 and top[0][1] == top[1][1]):
        return None
    return top[0][0]


def _rule_name(rec: dict) -> str | None:
    """The case's one line-rule name, where it fails with that name alone."""
    names = [f["name"] for f in rec.get("faults", ())]
    if rec.get("verdict") == "fail" and len(names) == 1 and names[0] in RULE_NAMES_FAMILY:
        return names[0]
    return None


def read_job(records: list[dict]) -> JobRead:
    """The job's read (:class:`JobRead`) from its cases' records (report.json's ``cases``)."""
    styled = [r for r in records if r.get("line_style")]
    styles = [r["line_style"]["style"] for r in styled]
    rules = [r["line_style"]["rule_read"] for r in styled if r["line_style"].get("rule_read") in ("gl", "rounded")]
    named = [n for n in (_rule_name(r) for r in styled) if n is not None]
    offsets = [
        r["line_style"]["geometry"]["offset_px"]
        for r in styled
        if r["line_style"]["geometry"].get("offset_px") is not None
        and not any(f["name"] in PLACEMENT_FAULTS for f in r.get("faults", ()))
    ]
    offset = None
    if len(offsets) >= MIN_OFFSET_CASES:
        med = np.median(np.asarray(offsets, dtype=float), axis=0)
        offset = (float(med[0]), float(med[1]))
    return JobRead(
        cases=len(styled),
        style=_plurality(styles),
        rule=_plurality(rules),
        rule_name=(_plurality(named) or "raster_rule") if len(named) >= 2 else None,
        offset_px=offset,
        offset_cases=len(offsets),
    )


def offset_beyond(job: JobRead, tol_px: float) -> bool:
    """Whether the job's offset is beyond ``tol_px`` on an axis."""
    return job.offset_px is not None and max(abs(job.offset_px[0]), abs(job.offset_px[1])) > tol_px


def differs(rec: dict, job: JobRead) -> bool:
    """Whether the case ``rec`` read its renderer otherwise than the job (and would be judged again)."""
    ls = rec.get("line_style")
    if not ls:
        return False
    names = [f["name"] for f in rec.get("faults", ())]
    if job.style is not None and ls["style"] != job.style:
        return True
    if job.rule is not None and ls.get("rule_read") in ("gl", "rounded") and ls["rule_read"] != job.rule:
        return True
    own = _rule_name(rec)
    if job.rule_name is not None and own is not None and own != job.rule_name:
        return True
    if offset_beyond(job, ls["offset_tol_px"]) and "pixel_offset" not in names:
        return True
    return False
