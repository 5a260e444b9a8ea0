"""One case's record: its measurements merged (worst of each), its failure reasons, its JSON result."""

from __future__ import annotations

import math

import numpy as np
from wirecheck.core.projector.projection import DTYPES

from ..tolerances import MIN_F1_1PX_EXTREMES
from .measure import within

#: The stats a record keeps, as :func:`measure.measure` names them.
STATS_KEYS = ("float64", "float32", "opencv", "pp_float64", "pp_float32")


def json_float(v):
    """JSON-able float: None for NaN / None, the strings "inf" / "-inf" for infinities."""
    if v is None:
        return None
    v = float(v)
    if math.isnan(v):
        return None
    return v if math.isfinite(v) else ("inf" if v > 0 else "-inf")  # strict JSON has no inf


def jsonable(x):
    """``x`` with numpy scalars as Python ones and floats through :func:`json_float`."""
    if isinstance(x, dict):
        return {str(k): jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [jsonable(v) for v in x]
    if isinstance(x, (bool, np.bool_)):
        return bool(x)
    if isinstance(x, (int, np.integer)):
        return int(x)
    if isinstance(x, (float, np.floating)):
        return json_float(x)
    return x


def public(stats: dict | None) -> dict | None:
    """A stats dict with JSON-able floats."""
    if stats is None:
        return None
    return {k: (json_float(v) if isinstance(v, (float, np.floating)) else v) for k, v in stats.items()}


def merge(a: dict | None, b: dict) -> dict:
    """Two stats dicts of the same dtype as one (worst of both)."""
    if a is None:
        return dict(b)
    out = dict(a)
    for k in ("points", "compared", "visible_mismatch", "visible_mismatch_outside_band"):
        out[k] = a[k] + b[k]
    if b["max_error_px"] is not None and (a["max_error_px"] is None or b["max_error_px"] > a["max_error_px"]):
        out["max_error_px"], out["bound_px"] = b["max_error_px"], b["bound_px"]
    if b["max_ratio"] is not None and (a["max_ratio"] is None or b["max_ratio"] > a["max_ratio"]):
        out["max_ratio"] = b["max_ratio"]
    if "vs_opencv_px" in a or "vs_opencv_px" in b:
        vals = [v for v in (a.get("vs_opencv_px"), b.get("vs_opencv_px")) if v is not None]
        out["vs_opencv_px"] = max(vals) if vals else None
    return out


class CaseRecord:
    """Accumulates one case's measurements, details and failure reasons."""

    def __init__(self, name: str):
        self.name = name
        self.stats = dict.fromkeys(STATS_KEYS)
        self.extra = {}
        self.reasons = []
        self.pyrender_note = None
        self.pyrender_parts = {}

    def add(self, m: dict, *, label=""):
        """Merge one :func:`measure.measure` result; fail on any point outside its bound."""
        for k in self.stats:
            self.stats[k] = merge(self.stats[k], m[k])
        for dt in DTYPES + tuple("pp_" + d for d in DTYPES):
            s = m[dt]
            if not within(s):
                self.fail(
                    f"{label}{dt.replace('pp_', 'project_points ')}: error {s['max_error_px']:.3g} px "
                    f"exceeds its bound "
                    f"(max error/bound {s['max_ratio']:.3g})"
                )
            if s["visible_mismatch_outside_band"]:
                self.fail(
                    f"{label}{dt.replace('pp_', 'project_points ')}: "
                    f"{s['visible_mismatch_outside_band']} points visible/clipped unlike "
                    f"the reference, farther than rounding from near/far"
                )
        if not within(m["opencv"]):
            self.fail(
                f"{label}reference and OpenCV disagree beyond OpenCV's bound "
                f"(ratio {m['opencv']['max_ratio']:.3g}): check the reference"
            )

    def check(self, ok: bool, reason: str):
        if not ok:
            self.fail(reason)

    def fail(self, reason: str):
        self.reasons.append(reason)

    def add_pyrender(self, label: str, scores, note, *, judged: bool):
        """Record one pyrender frame's scores; a judged one fails below MIN_F1_1PX_EXTREMES."""
        if scores is None:
            self.pyrender_note = note
            return
        self.pyrender_parts[label] = dict(scores, judged=judged)
        if judged and scores["f1_1px"] < MIN_F1_1PX_EXTREMES:
            self.fail(f"pyrender {label}: F1@1px {scores['f1_1px']:.4f} < {MIN_F1_1PX_EXTREMES}")

    def result(self, description: str, bound_derivation: str) -> dict:
        """The case's JSON-able result."""
        pyr = None
        if self.pyrender_parts:
            parts = self.pyrender_parts
            pyr = {
                "f1_0px": min(p["f1_0px"] for p in parts.values()),
                "f1_1px": min(p["f1_1px"] for p in parts.values()),
                "frames": parts,
            }
            judged = [p for p in parts.values() if p["judged"]]
            pyr["f1_1px_judged"] = min(p["f1_1px"] for p in judged) if judged else None
        return {
            "name": self.name,
            "description": description,
            "bound_derivation": bound_derivation,
            "float64": public(self.stats["float64"]),
            "float32": public(self.stats["float32"]),
            "opencv": public(self.stats["opencv"]),
            "project_points": {dt: public(self.stats["pp_" + dt]) for dt in DTYPES}
            if self.stats["pp_float64"] is not None
            else None,
            "pyrender": pyr,
            "pyrender_note": self.pyrender_note,
            "details": jsonable(self.extra),
            "verdict": "fail" if self.reasons else "pass",
            "reasons": list(self.reasons),
        }
