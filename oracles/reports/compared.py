"""The first line of every result: what a run compared (level, frames, cases).

crosscheck and the Python API answer "is my projector right?" with different defaults
(crosscheck: pixels over 24 frames; ``check_projector`` and the fixture: vertices over 8), so
a green test and a red crosscheck can both be right. Every result starts with this line so
the difference is visible where the verdict is read: the CLI's output, the AssertionError of
``assert_projector`` and the fixture's failure (docs/pytest.md).
"""

from __future__ import annotations

from .fault_text import below_table

_LEVEL = {"vertices": "vertices (OpenCV)", "pixels": "pixels (OpenCV and pyrender)",
          "frames": "frames (a renderer's PNGs against pyrender; core's beside it)"}


def _n(count: int, word: str, plural: str | None = None) -> str:
    return f"{count:,} {word if count == 1 else (plural or word + 's')}"


def what_text(report: dict) -> str:
    """E.g. ``Compared: level pixels (OpenCV and pyrender), 24 frames per case, 21 cases (3 scenes x 7 cameras)``.

    From the report's ``level`` (or ``oracles``), ``frames``, ``every`` and its cases.
    """
    level = report.get("level") or ("pixels" if "pyrender" in report.get("oracles", ()) else "vertices")
    frames = report.get("frames")
    every = report.get("every", 1) or 1
    per_case = _n(frames, "frame") + " per case" if frames is not None else "frames"
    if every > 1 and frames is not None:
        per_case += f" (1 in {every} checked)"
    cases = report.get("cases", [])
    scenes = len({c["scene"] for c in cases})
    cameras = len({c["camera"] for c in cases})
    what = _LEVEL.get(level, level)
    outputs = report.get("outputs")
    if level == "frames" and outputs:           # a job asking for filled frames or depth maps
        named = {"wireframe": "wireframes", "filled": "filled frames", "depth": "depth maps"}
        what = (f"frames (a renderer's {', '.join(named[o] for o in outputs)} against pyrender"
                + ("; core's wireframes beside it)" if "wireframe" in outputs else ")"))
    return (f"Compared: level {what}, {per_case}, {_n(len(cases), 'case')} "
            f"({_n(scenes, 'scene')} x {_n(cameras, 'camera')})")


def hint_lines(report: dict, failing: list) -> list[str]:
    """``  what to check, NAME: HINT`` once per distinct hint of the faults in ``failing`` cases, then
    ``  note, NAME: TEXT`` once per fault kind (oracles.reports.fault_text.below_table)."""
    return below_table(failing, report.get("level") == "frames")


#: Reasons the CLI prints per failing case; the rest are in report.md (a line a reader can take in).
CLI_REASONS = 2


def reason_text(reasons: list[str], keep: int = CLI_REASONS) -> str:
    """The first ``keep`` reasons of a case joined by ``; ``, and how many more report.md has."""
    shown = "; ".join(reasons[:keep])
    more = len(reasons) - keep
    return shown + (f"; +{more} more in report.md" if more > 0 else "")
