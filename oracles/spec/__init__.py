"""The spec suite: the specification wirecheck was built from, its test data and critical cases, run.

``crosscheck --suite spec`` (:func:`run_spec`):

- **the test matrix** (matrix.py): scenes A (a unit cube) and B (a pyramid with an
  offset translation) x camera z 3 and 6 x FOV 60 and 90 x 1, 30 and 180 frames:
  24 runs, each a crosscheck case (OpenCV's vertices, pyrender's pixels, faults named);
- **the named checks** (checks.py): the four critical cases (known-point
  projection, rotation invariance, depth monotonicity, clip safety) and three
  edge cases (near-plane depth, behind-camera points, an empty mesh), each
  against values derived by hand in its comments.

The candidate is core or any projector of the contract (``--candidate``,
``--candidate-cmd``). The suite passes only when all 24 runs and all 7 checks
pass, and never on nothing (:func:`suite_verdict`). report.py writes spec.md.
"""

from __future__ import annotations

import time

from ..reports.report import finite_or_null
from .checks import CHECK_NAMES, CRITICAL, run_checks
from .matrix import CAMERA_Z, FOVS, FRAME_COUNTS, RUNS, SCENES, TURNS, run_matrix, spec_cases
from .report import spec_console, spec_markdown

__all__ = [
    "run_spec",
    "suite_verdict",
    "spec_markdown",
    "spec_console",
    "run_checks",
    "run_matrix",
    "spec_cases",
    "CHECK_NAMES",
    "CRITICAL",
    "RUNS",
    "SCENES",
    "CAMERA_Z",
    "FOVS",
    "FRAME_COUNTS",
]


def suite_verdict(runs: list, checks: list) -> tuple[str, list[str]]:
    """``("pass", [])`` only when the whole matrix and every check ran and passed; else ``("fail", why)``.

    A suite that ran fewer runs or checks than the specification has (none at
    all included) compared less than it claims: that is a failure, never a pass.
    """
    why = []
    if len(runs) != RUNS:
        why.append(f"{len(runs)} runs compared: expected the matrix's {RUNS}")
    if [c["name"] for c in checks] != list(CHECK_NAMES):
        why.append(f"{len(checks)} named checks run: expected the {len(CHECK_NAMES)} of the specification")
    failed_runs = [r["run"] for r in runs if r["verdict"] != "pass"]
    failed_checks = [c["name"] for c in checks if c["verdict"] != "pass"]
    if failed_runs:
        why.append(
            f"{len(failed_runs)} runs not passed: {', '.join(failed_runs[:4])}"
            + (", ..." if len(failed_runs) > 4 else "")
        )
    if failed_checks:
        why.append(f"checks failed: {', '.join(failed_checks)}")
    return ("fail" if why else "pass"), why


def run_spec(
    candidate, level: str = "pixels", candidate_name: str = "core", progress=None, precision: str | None = None
) -> dict:
    """The whole suite: ``{"suite", "verdict", "why", "candidate", "level", "oracle_gl", "matrix",
    "summary", "runs", "checks", "timing"}``; only ``"timing"`` varies from run to run.

    ``precision``: the candidate's declared precision (``--candidate-precision``), for the runs' vertex
    bounds and the checks' alike; default: the dtype it returns.
    """
    t0 = time.perf_counter()
    matrix = run_matrix(candidate, level=level, candidate_name=candidate_name, progress=progress, precision=precision)
    t1 = time.perf_counter()
    checks = run_checks(candidate, precision=precision)
    runs = matrix["runs"]
    verdict, why = suite_verdict(runs, checks)
    return finite_or_null(
        {  # JSON-ready: a NaN or overflowing candidate's values are null
            "suite": "spec",
            "verdict": verdict,
            "why": why,
            "candidate": candidate_name,
            "candidate_precision": precision,
            "level": level,
            "oracle_gl": matrix["oracle_gl"],
            "matrix": {
                "scenes": list(SCENES),
                "camera_z": list(CAMERA_Z),
                "fov_deg": list(FOVS),
                "frames": list(FRAME_COUNTS),
                "turns": list(TURNS),
                "runs": RUNS,
            },
            "summary": {
                "runs": len(runs),
                "runs_passed": sum(r["verdict"] == "pass" for r in runs),
                "checks": len(checks),
                "checks_passed": sum(c["verdict"] == "pass" for c in checks),
                "compared": matrix["compared"],
            },
            "runs": runs,
            "checks": checks,
            "timing": {"matrix_s": t1 - t0, "runs_wall_s": matrix["seconds"], "checks_s": time.perf_counter() - t1},
        }
    )
