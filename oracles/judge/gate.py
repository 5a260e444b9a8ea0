"""A gate never passes on nothing: what a crosscheck run must compare to pass.

Three checks, each made here and nowhere else:

1. **Before the run** (:func:`run_inputs`, called by :func:`oracles.runner.run_crosscheck`
   whoever its caller is, and first by the CLI with its option names): at least
   one scene, one case and one frame; every name known, none twice; ``every``
   no larger than ``frames``; finite tolerances and turns. Anything else is an
   :class:`~core.errors.InputError` (a ``ValueError``): exit 2 in the CLI.
2. **After each case** (:func:`case_verdict`): a case that fails none of its
   tolerances but compared nothing -- no vertex visible to both sides in any
   checked frame or, at level pixels, no pixel drawn by either side -- is
   ``"vacuous"``, not ``"pass"``.
3. **After the run** (:func:`run_verdict`): ``"pass"`` only when no case
   failed, the run compared at least one frame, and -- unless vacuous results
   are allowed (``allow_vacuous`` / ``--allow-vacuous``) -- no case is vacuous
   and the run compared vertices (and pixels, at level pixels; pixels only,
   at level frames: a renderer's frames compare no vertex).

What was compared is counted per case (``record["compared"]``) and for the run
(:func:`compared_totals`, ``report["compared"]``): cases, frames, vertices
(points visible to both sides, summed over frames) and pixels (pixels drawn by
either side, summed over frames; ``None`` at level vertices).
"""

from __future__ import annotations

import dataclasses
import math
import numbers
import os
from dataclasses import dataclass

from wirecheck.core.errors import InputError
from wirecheck.core.limits import MAX_FRAMES, check_turns
from wirecheck.core.scene import files as scene_files
from wirecheck.core.scene.files import builtin_names, load_scene
from wirecheck.core.scene.model import Scene

from ..cases import ALL_CASE_NAMES, CALIBRATED_CASE_NAMES, CASE_NAMES

#: How each input is called in messages: by the Python API, and by the ``crosscheck`` CLI.
API_NAMES = {
    "scenes": "scenes",
    "frames": "frames",
    "every": "every",
    "cases": "cases",
    "turns": "turns",
    "vertex_px": "tol_px",
    "min_f1_1px": "min_f1",
    "min_f1_0px": "min_f1_0px",
    "min_iou": "min_iou",
}
CLI_NAMES = {
    "scenes": "--scene",
    "frames": "--frames",
    "every": "--every",
    "cases": "--cases",
    "turns": "--spin",
    "vertex_px": "--tol-px",
    "min_f1_1px": "--min-f1",
    "min_f1_0px": "--min-f1-0px",
    "min_iou": "--min-iou",
}


@dataclass(frozen=True)
class RunInputs:
    """The validated inputs of a run: what every case shares."""

    scenes: tuple  # of core.scene.model.Scene, distinct names
    frames: int  # >= 1
    every: int  # 1 <= every <= frames
    case_names: tuple  # of ALL_CASE_NAMES, distinct, in that order
    turns: tuple  # three finite floats

    @property
    def frames_checked(self) -> int:
        return len(range(1, self.frames + 1, self.every))


def _integer(value, name: str, low: int) -> int:
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or value < low:
        raise InputError(f"{name} {value!r}: expected an integer >= {low}")
    return int(value)


def resolve_scenes(scenes, names: dict = API_NAMES) -> tuple:
    """Scene objects from names, paths or :class:`~core.scene.model.Scene` objects; ``None``: every bundled scene.

    InputError when there is none (an empty list, or no bundled scene found)
    or two share a name (the report names cases by scene).
    """
    if scenes is None:
        bundled = builtin_names()
        if not bundled:
            raise InputError(
                f"no bundled scenes found in {scene_files.SCENE_DIR}: the installation is incomplete "
                f"(expected scenes/*.scene); name a scene file with {names['scenes']}"
            )
        scenes = bundled
    elif isinstance(scenes, (str, os.PathLike, Scene)):
        scenes = [scenes]
    given = _listed(scenes, names["scenes"], "a scene name, a path or a Scene, or a list of them")
    odd = [s for s in given if not isinstance(s, (str, os.PathLike, Scene))]
    if odd:
        raise InputError(
            f"{names['scenes']}: {odd[0]!r} ({type(odd[0]).__name__}): expected a scene name, a path or a Scene"
        )
    out = tuple(s if isinstance(s, Scene) else load_scene(os.fspath(s)) for s in given)
    if not out:
        raise InputError(
            f"{names['scenes']}: no scene given: expected at least one scene (or none at all for every bundled scene)"
        )
    seen = {}
    for s in out:
        if s.name in seen:
            raise InputError(
                f"{names['scenes']}: two scenes named {s.name!r} ({seen[s.name] or '?'}, "
                f"{s.source or '?'}): expected each scene once"
            )
        seen[s.name] = s.source
    return out


def _listed(values, name: str, expected: str) -> list:
    """``list(values)``, or InputError naming ``name`` when it is not a collection (``scenes=42``)."""
    if isinstance(values, (bytes, dict)) or not hasattr(values, "__iter__"):
        raise InputError(f"{name} {values!r}: expected {expected}")
    return list(values)


#: Names for groups of cases, usable among case names: ``--cases default,calibrated``.
CASE_GROUPS = {"default": CASE_NAMES, "calibrated": CALIBRATED_CASE_NAMES, "all": ALL_CASE_NAMES}


def resolve_cases(cases, names: dict = API_NAMES) -> tuple:
    """Case names from a list or a comma-separated string (``None``: the default set), in ALL_CASE_NAMES order.

    A group name (:data:`CASE_GROUPS`) stands for its cases.
    """
    name = names["cases"]
    if cases is None:
        return CASE_NAMES
    given = (
        [c.strip() for c in cases.split(",") if c.strip()]
        if isinstance(cases, str)
        else _listed(cases, name, "a list of case names or a comma-separated string")
    )
    given = [member for c in given for member in (CASE_GROUPS.get(c, (c,)) if isinstance(c, str) else (c,))]
    bad = [c for c in given if not isinstance(c, str) or c not in ALL_CASE_NAMES]
    if bad or not given:
        raise InputError(
            f"{name} {cases!r}: {'unknown ' + ', '.join(map(repr, bad)) if bad else 'no case named'}; "
            f"expected some of {', '.join(ALL_CASE_NAMES)} or a group: {', '.join(CASE_GROUPS)}"
        )
    twice = sorted({c for c in given if given.count(c) > 1})
    if twice:
        raise InputError(f"{name} {cases!r}: {', '.join(twice)} given twice: expected each case once")
    return tuple(c for c in ALL_CASE_NAMES if c in given)


def check_tolerances(tol, names: dict = API_NAMES) -> None:
    """A NaN tolerance would pass everything (no comparison with NaN is true): InputError."""
    v = tol.vertex_px
    if isinstance(v, bool) or not (isinstance(v, numbers.Real) and math.isfinite(v) and v >= 0):
        raise InputError(f"{names['vertex_px']} {v!r}: expected a finite number >= 0 (pixels)")
    for field in ("min_f1_1px", "min_f1_0px", "min_iou"):
        v = getattr(tol, field)
        if isinstance(v, bool) or not (isinstance(v, numbers.Real) and 0.0 <= v <= 1.0):
            raise InputError(f"{names[field]} {v!r}: expected a number in [0, 1]")


def run_inputs(
    scenes, frames, every=1, cases=None, turns=(1.0, 1.0, 0.0), tol=None, names: dict = API_NAMES
) -> RunInputs:
    """Validate what a run compares, or raise InputError naming the input as ``names`` spells it.

    ``cases`` and ``turns`` may be comma-separated strings (as the CLI takes
    them). The cheap checks come first; scenes may be files to read.
    """
    settings = run_settings(frames, every, cases, turns, tol, names)
    return dataclasses.replace(settings, scenes=resolve_scenes(scenes, names))


def run_settings(frames, every=1, cases=None, turns=(1.0, 1.0, 0.0), tol=None, names: dict = API_NAMES) -> RunInputs:
    """:func:`run_inputs` without the scenes (``scenes=()``): a dataset's meshes are checked as they load."""
    frames = _integer(frames, names["frames"], 1)
    if frames > MAX_FRAMES:
        raise InputError(
            f"{names['frames']} {frames}: expected an integer in 1..{MAX_FRAMES:,} (wirecheck.core.limits)"
        )
    every = _integer(every, names["every"], 1)
    if every > frames:
        raise InputError(
            f"{names['every']} {every} with {names['frames']} {frames}: only frame 1 would be "
            f"checked: expected {names['every']} <= {names['frames']}"
        )
    given = turns
    try:
        turns = tuple(float(x) for x in (turns.split(",") if isinstance(turns, str) else turns))
    except (TypeError, ValueError):
        turns = ()
    if len(turns) != 3 or not all(math.isfinite(x) for x in turns):
        raise InputError(f"{names['turns']} {given!r}: expected three finite numbers X,Y,Z")
    check_turns(turns, names["turns"])
    if tol is not None:
        check_tolerances(tol, names)
    return RunInputs(scenes=(), frames=frames, every=every, case_names=resolve_cases(cases, names), turns=turns)


# ---------------------------------------------------------------- verdicts


def _frames(n: int) -> str:
    return "the one checked frame" if n == 1 else f"any of the {n} checked frames"


def vacuous_reason(compared: dict, level: str, points: int | None = None) -> str | None:
    """Why a case compared nothing (None when it compared something at every level it ran).

    ``points``: the scene's vertex count, to say why no vertex was compared. ``level``:
    ``"vertices"``, ``"pixels"`` (both compared) or ``"frames"`` (a renderer's
    frames, oracles.judge.frames_judge: pixels only).
    """
    frames = compared["frames"]
    if frames == 0:
        return "nothing compared: no frame was checked"
    if level == "frames":  # a renderer's frames: pixels only, no vertex is compared
        if not compared["pixels"]:
            return f"vacuous: neither side drew a pixel in {_frames(frames)}: nothing compared"
        return None
    if compared["vertices"] == 0 and points == 0:
        return "vacuous: the scene has no vertices: nothing compared"
    if compared["vertices"] == 0:
        return (
            f"vacuous: no vertex visible to both sides in {_frames(frames)} "
            "(every point clipped by both): nothing compared"
        )
    if level == "pixels" and not compared["pixels"]:
        return f"vacuous: neither side drew a pixel in {_frames(frames)}: nothing compared at level pixels"
    return None


def case_verdict(compared: dict, reasons: list, level: str, points: int | None = None) -> tuple[str, list]:
    """``("fail", reasons)``, ``("vacuous", [why])`` or ``("pass", [])``."""
    if reasons:
        return "fail", list(reasons)
    why = vacuous_reason(compared, level, points)
    return ("vacuous", [why]) if why else ("pass", [])


def compared_totals(records: list, level: str) -> dict:
    """What a run compared: cases that compared something, and frames, vertices, pixels over all cases (pixels
    None at level vertices)."""
    counts = [r["compared"] for r in records]
    return {
        "cases": sum(1 for r, c in zip(records, counts) if r["verdict"] != "vacuous" and c["frames"]),
        "frames": sum(c["frames"] for c in counts),
        "vertices": sum(c["vertices"] for c in counts),
        "pixels": sum(c["pixels"] or 0 for c in counts) if level in ("pixels", "frames") else None,
    }


def run_verdict(records: list, compared: dict, level: str, allow_vacuous: bool = False) -> str:
    """``"pass"`` only when the run compared something and no case failed (module docstring)."""
    if not records or compared["frames"] == 0 or any(r["verdict"] == "fail" for r in records):
        return "fail"
    if not allow_vacuous and (
        any(r["verdict"] == "vacuous" for r in records)
        or (level != "frames" and compared["vertices"] == 0)
        or (level in ("pixels", "frames") and not compared["pixels"])
    ):
        return "fail"
    return "pass"
