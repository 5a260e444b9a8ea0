"""The extremes suite: core at the edges of its input space, against derived error bounds.

Each case (cases.py) runs core (``core.projector.pipeline.render_frame`` and
``core.projector.projection.project_points``) in float64 and float32 and compares it with

- an **extended-precision reference** (reference.py): ``core.conventions`` in
  ``np.longdouble``, none of core's functions;
- **OpenCV** (``oracles.references.opencv_oracle.project``, float64 ``cv2.projectPoints``),
  whose own error against the reference is reported and checked against its
  own bound. OpenCV is not camera-relative, so far from the origin it is the
  less accurate of the two: its error is information;
- **pyrender/OSMesa** (optional): the F1 of the drawn frame.

Every point's error must be within its own bound (bounds.py, each derivation in
its function's docstring); measure.py does the comparing, record.py keeps one
case's outcome, report.py writes the Markdown. Results are JSON-able and
deterministic except the ``"timing"`` key.

Input validation at the same extremes (up parallel to forward, NaN / inf in
camera arguments and scene files) is tested with the renderer CLI
(tests/test_renderer_cli.py).
"""

from __future__ import annotations

import time

from .bounds import DERIVED, EPS, EPS32, EPS64, SAFETY, camera_error, derivation, opencv_camera_error, pixel_bound
from .cases import CASES
from .measure import Pyrender
from .record import CaseRecord
from .reference import (
    LD,
    REFERENCE_EPS,
    REFERENCE_EXTENDED,
    reference_basis,
    reference_focal,
    reference_project,
    reference_world,
)
from .report import extremes_markdown

__all__ = [
    "EXTREME_CASES",
    "run_case",
    "run_extremes",
    "extremes_markdown",
    "reference_project",
    "reference_basis",
    "reference_focal",
    "reference_world",
    "camera_error",
    "pixel_bound",
    "opencv_camera_error",
    "SAFETY",
    "EPS",
    "EPS32",
    "EPS64",
    "LD",
    "REFERENCE_EPS",
    "REFERENCE_EXTENDED",
]

_BY_NAME = {case.__name__: case for case in CASES}

#: The case names, in suite order.
EXTREME_CASES = tuple(_BY_NAME)


def _description(case) -> str:
    """The first paragraph of the case's docstring, on one line, without its final period."""
    first = case.__doc__.strip().split("\n\n")[0]
    return " ".join(line.strip() for line in first.splitlines()).removesuffix(".")


def _run(name: str, pr: Pyrender) -> dict:
    case = _BY_NAME[name]
    description, bound = _description(case), derivation(case)
    record = CaseRecord(name)
    try:
        case(record, pr)
    except Exception as exc:  # a crash in core is a failed case, reported, not a crashed suite
        record = CaseRecord(name)
        record.fail(f"crashed: {type(exc).__name__}: {exc}")
    return record.result(description, bound)


def run_case(name: str, pyrender: bool = True) -> dict:
    """One case by name (see :data:`EXTREME_CASES`); its own pyrender oracles, closed after."""
    if name not in _BY_NAME:
        raise ValueError(f"case {name!r}: expected one of {', '.join(EXTREME_CASES)}")
    pr = Pyrender(pyrender)
    try:
        return _run(name, pr)
    finally:
        pr.close()


def run_extremes(pyrender: bool = True) -> dict:
    """Every case: ``{"suite", "verdict", "pyrender", "reference", "bounds", "cases", "timing"}``.

    ``"bounds"`` maps each bound function's name to its derivation; only
    ``"timing"`` varies from run to run.
    """
    pr = Pyrender(pyrender)
    cases, seconds = [], {}
    t_all = time.perf_counter()
    try:
        for name in EXTREME_CASES:
            t0 = time.perf_counter()
            cases.append(_run(name, pr))
            seconds[name] = time.perf_counter() - t0
    finally:
        pr.close()
    return {
        "suite": "extremes",
        "verdict": "pass" if all(c["verdict"] == "pass" for c in cases) else "fail",
        "pyrender": pr.enabled,
        "oracle_gl": pr.gl,
        "reference": {"dtype": "longdouble", "eps": REFERENCE_EPS, "extended": REFERENCE_EXTENDED},
        "bounds": {f.__name__: derivation(f) for f in DERIVED},
        "cases": cases,
        "timing": {"total_seconds": time.perf_counter() - t_all, "case_seconds": seconds},
    }
