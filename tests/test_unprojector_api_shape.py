"""check_unprojector's keywords have the shape of check_projector's and check_frames' (issue 34: one API shape):
``allow_vacuous`` (a case that compares nothing fails by default), ``config`` (``[tool.wirecheck]`` fills what
the call leaves), ``timeout_s`` checked as for a projector; and ``crosscheck --unprojector --allow-vacuous``.

The unprojector is tests/data/unprojectors.py's correct one (written from K, R, t; its answers are checked
against the exact inverse in tests/test_unprojector.py), so each verdict here is decided by the keyword alone.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
from wirecheck import check_unprojector
from wirecheck.core.errors import InputError
from wirecheck.core.scene.files import load_scene
from wirecheck.core.scene.model import Scene

sys.path.insert(0, str(Path(__file__).parent / "data"))
import unprojectors as U  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SPEC = "tests/data/unprojectors.py"


def bare_cube() -> Scene:
    """The cube's vertices and edges without faces: a wireframe has no surface to sample, so every case of it
    compares no point (its verdict "vacuous")."""
    cube = load_scene("cube")
    return Scene(name="bare", vertices=cube.vertices, edges=cube.edges)


def test_a_vacuous_case_fails_the_run_unless_allowed():
    scenes = [load_scene("cube"), bare_cube()]
    report = check_unprojector(U.correct, scenes=scenes, cases=["on_axis"], frames=1, config=False)
    assert [(c["scene"], c["verdict"]) for c in report["cases"]] == [("cube", "pass"), ("bare", "vacuous")]
    assert report["verdict"] == "fail" and report["settings"]["allow_vacuous"] is False
    allowed = check_unprojector(U.correct, scenes=scenes, cases=["on_axis"], frames=1, allow_vacuous=True, config=False)
    assert [c["verdict"] for c in allowed["cases"]] == ["pass", "vacuous"]
    assert allowed["verdict"] == "pass" and allowed["settings"]["allow_vacuous"] is True
    # a failing case is not excused by the flag: the rows-flipped unprojector still fails the run
    flipped = check_unprojector(
        U.rows_flipped, scenes=scenes, cases=["on_axis"], frames=1, allow_vacuous=True, config=False
    )
    assert flipped["verdict"] == "fail"
    # a run that compares no point at all is an error whatever the flag says (a gate never passes on nothing)
    with pytest.raises(InputError, match="compares nothing is no pass"):
        check_unprojector(U.correct, scenes=[bare_cube()], frames=1, allow_vacuous=True, config=False)


@pytest.mark.parametrize("flag", ["no", 1, None])
def test_allow_vacuous_is_a_bool(flag):
    # "no" is truthy: taken as True it would let a case that compared nothing pass
    with pytest.raises(TypeError, match="allow_vacuous .*expected True or False"):
        check_unprojector(U.correct, scenes=["cube"], frames=1, allow_vacuous=flag, config=False)


@pytest.mark.parametrize(
    "value, error",
    [(0, ValueError), (-1.0, ValueError), (float("nan"), ValueError), ("10", TypeError), (True, TypeError)],
)
def test_timeout_s_checked_as_for_a_projector(value, error):
    with pytest.raises(error, match="timeout_s"):
        check_unprojector(f"{SPEC}:correct", scenes=["cube"], frames=1, timeout_s=value, config=False)


def test_config_fills_what_the_call_leaves(tmp_path):
    config = tmp_path / "pyproject.toml"
    config.write_text(
        '[tool.wirecheck]\nscenes = ["pyramid"]\ncases = ["on_axis", "wide_fov"]\nframes = 3\nspin = [0.0, 0.5, 0.0]\n'
    )
    report = check_unprojector(U.correct, config=config)
    assert report["settings"] == {
        "scenes": ["pyramid"],
        "cases": ["on_axis", "wide_fov"],
        "frames": 3,
        "turns": [0.0, 0.5, 0.0],
        "stride": 8,
        "allow_vacuous": False,
    }
    assert report["verdict"] == "pass" and report["compared"] == {
        "cases": 2,
        "frames": 6,
        "points": report["compared"]["points"],
    }
    # what the call gives wins over the table; config=False reads no table (the defaults: 2 frames, 1,1,0)
    given = check_unprojector(U.correct, frames=1, cases=["on_axis"], config=config)
    assert given["settings"]["frames"] == 1 and given["settings"]["cases"] == ["on_axis"]
    assert given["settings"]["scenes"] == ["pyramid"]
    plain = check_unprojector(U.correct, scenes=["cube"], cases=["on_axis"], config=False)
    assert plain["settings"]["frames"] == 2 and plain["settings"]["turns"] == [1.0, 1.0, 0.0]


def test_a_bad_table_is_one_input_error(tmp_path):
    config = tmp_path / "pyproject.toml"
    config.write_text("[tool.wirecheck]\nframes = 0\n")
    with pytest.raises(InputError, match=r"frames = 0: expected an integer >= 1"):
        check_unprojector(U.correct, config=config)


def test_cli_allow_vacuous(tmp_path):
    bare = tmp_path / "bare.scene"
    bare.write_text(
        "name bare\n"
        + "".join(f"v {x} {y} {z}\n" for x in (-1, 1) for y in (-1, 1) for z in (-1, 1))
        + "e 0 1\ne 0 2\ne 0 4\n"
    )

    def crosscheck(*extra):
        return subprocess.run(
            [sys.executable, "-m", "wirecheck.oracles.cli", "--unprojector", f"{SPEC}:correct", "--scene", "cube"]
            + ["--scene", str(bare), "--cases", "on_axis", "--frames", "1", "--no-report", *extra],
            cwd=ROOT,
            capture_output=True,
            text=True,
        )

    strict, allowed = crosscheck(), crosscheck("--allow-vacuous")
    assert strict.returncode == 1 and "FAIL: 1/2 cases" in strict.stdout, (strict.stdout, strict.stderr)
    assert allowed.returncode == 0 and "PASS" in allowed.stdout, (allowed.stdout, allowed.stderr)
