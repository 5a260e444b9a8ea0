"""Faults as people read them: a table cell per case, the full record rounded, and the notes and
hints printed once per fault kind below the table.

A cell (:func:`cell`) is a fault's name and the one or two numbers its catalogue entry shows
(oracles.faults: ``pixel_offset(dx=0.5, dy=0.5)``, ``fov_mismatch(fov=81.23)``, ``raster_rule``),
at most :data:`CELL_MAX` characters, and so is a case's cell (:func:`case_cell`). What a fault
says in words (its ``hint``, its ``note``) is printed once per fault kind under the table
(:func:`hints`, :func:`notes`), not in every row; the whole record, every field at full
precision, stays in report.json, and report.md lists it rounded (:func:`full_text`).
"""

from __future__ import annotations

from typing import Iterable

from ..faults import Fault, ordered
from .fmt import distinct

#: The longest cell, a fault's or a case's (characters).
CELL_MAX = 60
#: The smallest rotation an ``unexplained`` cell names (degrees): 0.01 deg moves a point 500 px from the
#: centre by 0.09 px, so a fit's float noise (1e-15 deg) or a rotation that small is no part of what is
#: wrong; the record keeps ``rotation_deg`` whatever it is.
ROTATION_SHOWN_DEG = 0.01
#: Significant digits of a number in report.md's full record (a 16-digit matrix entry is 4).
FULL_DIGITS = 4


def fault_nominals(camera: dict | None) -> dict:
    """The value each fault field would have without the fault (``camera``: a record's ``camera_spec``)."""
    out = {"scale": 1.0, "scale_x": 1.0, "scale_y": 1.0, "dx": 0.0, "dy": 0.0}
    if camera:
        out.update(implied_aspect=camera["width"] / camera["height"], implied_fov_deg=camera["fov_y_deg"],
                   implied_ortho_height=camera["ortho_height"])
        lens = list(camera.get("distortion") or []) + [0.0] * 8            # k1, k2, p1, p2, k3, ...
        out.update(k1=lens[0], k2=lens[1], p1=lens[2], p2=lens[3], k3=lens[4])
    return out


def _param(value: float, nominal: float | None) -> str:
    """A fault's number: digits until it differs from ``nominal``, unless it differs by float64 rounding
    only (64 eps relative: ``scale_y=0.9999999999999998`` is ``scale_y=1``)."""
    if nominal is not None and abs(value - nominal) <= 64 * 2.0 ** -52 * max(abs(value), abs(nominal)):
        return distinct(value)
    return distinct(value, nominal)


def _value(value, nominal: float | None, digits: int | None = None) -> str:
    """A field as text: a float by :func:`_param` (``digits``: that many significant digits instead), a list
    of such each so (a per-axis ``scale=[0.622, 0.8]``, a matrix), strings of a list joined by ``or``,
    anything else as it is."""
    if isinstance(value, float):
        return f"{value:.{digits}g}" if digits else _param(value, nominal)
    if isinstance(value, (list, tuple)) and value:
        if all(isinstance(v, str) for v in value):
            return " or ".join(value)
        if all(isinstance(v, (float, int, list, tuple)) and not isinstance(v, bool) for v in value):
            return "[" + ", ".join(_value(v, nominal, digits) for v in value) + "]"
    return f"{value}"


def _unexplained(params: dict) -> str:
    """What an ``unexplained`` is, in a few words: which of its kinds, and its residual."""
    def n(key):
        return params.get(key)

    if n("line_level") is not None:
        return f"lines at level {n('line_level')} of 255, none drawn"
    if n("candidate_pixels") == 0:
        return "nothing drawn"
    if n("candidate_only_px") is not None:
        return f"drawn sets differ: {n('candidate_only_px')} / {n('oracle_only_px')} px one-sided"
    if n("underdetermined"):
        return "too few points to fit" + (f", residual {n('residual_px'):.3g} px" if n("residual_px") else "")
    if n("hint") and n("candidate_only") is not None:          # the visibility advice: the pixels agree
        return f"visible sets differ: {n('candidate_only')} / {n('oracle_only')} points one-sided"
    parts = []
    if isinstance(n("residual_px"), (int, float)):
        parts.append(f"residual {n('residual_px'):.3g} px")
    if isinstance(n("rotation_deg"), (int, float)) and abs(n("rotation_deg")) >= ROTATION_SHOWN_DEG:
        parts.append(f"rotated {n('rotation_deg'):.3g} deg")
    return ", ".join(parts)


def cell(fault: dict, camera: dict | None = None, fields: int = 2) -> str:
    """``name(label=value, ...)`` with up to ``fields`` of the catalogue's shown fields the fault has,
    each number with enough digits to differ from its nominal value (oracles.reports.fmt); fewer fields
    when that is longer than :data:`CELL_MAX`."""
    f = Fault.of(fault)
    if f.name == "unexplained":
        what = _unexplained(dict(f.params)) if fields else ""
        text = f"unexplained({what})" if what else "unexplained"
        return text if len(text) <= CELL_MAX else "unexplained"
    nominal = fault_nominals(camera)
    parts = [(f"{label}=" if label else "") + _value(value, nominal.get(key)) for key, label, value in f.shown(fields)]
    text = f"{f.name}({', '.join(parts)})" if parts else f.name
    if len(text) > CELL_MAX and fields:
        return cell(fault, camera, fields - 1)
    return text


def case_cell(faults: list[dict], camera: dict | None = None) -> str:
    """A case's faults for a table: each one's :func:`cell`, joined by ``; `` (``none`` without any), within
    :data:`CELL_MAX`: the numbers of the last faults are dropped first, then the last names (``+2 more``)."""
    if not faults:
        return "none"
    fields = [2] * len(faults)
    for i in reversed(range(len(faults))):
        text = "; ".join(cell(f, camera, k) for f, k in zip(faults, fields))
        if len(text) <= CELL_MAX:
            return text
        fields[i] = 0
    names = [f["name"] for f in faults]
    for shown in range(len(names), 0, -1):
        text = "; ".join(names[:shown]) + (f" +{len(names) - shown} more" if shown < len(names) else "")
        if len(text) <= CELL_MAX:
            return text
    return names[0][:CELL_MAX]


def full_text(faults: list[dict], camera: dict | None = None, digits: int | None = None) -> str:
    """Every field of each fault in one line, but its words (``hint``, ``note``: :func:`hints`, :func:`notes`);
    ``digits``: that many significant digits per number (report.md), else enough to differ from the nominal."""
    if not faults:
        return "none"
    nominal = fault_nominals(camera)
    parts = []
    for f in faults:
        extra = ", ".join(f"{k}={_value(v, nominal.get(k), digits)}"
                          for k, v in f.items() if k not in ("name", "hint", "note") and v is not None)
        parts.append(f"{f['name']}({extra})" if extra else f["name"])
    return "; ".join(parts)


def hints(faults: Iterable[dict], frames: bool = False) -> list[tuple[str, str]]:
    """``(name, what to check)`` once per distinct hint of ``faults``, in precedence order: a fault's own
    ``hint`` (set where its values say more, e.g. a FOV scale of W/H) or its name's; ``frames``: a
    renderer's own frames, each name's ``frames_hint`` added."""
    seen = {}
    for f in ordered(Fault.of(x) for x in faults):
        hint = f.hint + (f"; {f.kind.frames_hint}" if frames and f.kind.frames_hint else "")
        seen.setdefault((f.name, hint), None)
    return list(seen)


def notes(cases: list[dict]) -> list[tuple[str, str]]:
    """``(name, text)`` once per fault kind with a ``note`` among ``cases``' faults, in precedence order:
    the note itself when every case's is the same, else the first case's, saying whose it is and how many
    cases have one (each case's note is in report.json)."""
    by: dict[str, list[tuple[dict, str]]] = {}
    for c in cases:
        for f in ordered(Fault.of(x) for x in c.get("faults") or []):
            if f.note:
                by.setdefault(f.name, []).append((c, f.note))
    out = []
    for name in sorted(by, key=lambda n: Fault(n).precedence):
        rows = by[name]
        count = f"{len(rows)} cases" if len(rows) > 1 else ""
        if len({text for _, text in rows}) == 1:
            out.append((name, rows[0][1] + (f" ({count})" if count else "")))
        else:
            first = rows[0][0]
            out.append((name, f"{rows[0][1]} ({first['scene']} / {first['camera']}; {count} in all, "
                              "each one's note in report.json)"))
    return out


def below_table(failing: list[dict], frames: bool = False) -> list[str]:
    """The lines under a table (the console's, an AssertionError's): what to check once per fault hint of
    the ``failing`` cases, then each fault kind's note once."""
    return ([f"  what to check, {n}: {h}" for n, h in hints((f for c in failing for f in c["faults"]), frames)]
            + [f"  note, {n}: {t}" for n, t in notes(failing)])
