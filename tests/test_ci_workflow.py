"""docs/ci-workflow.md: the GitHub Actions workflow parses, and the commands it runs work.

The YAML block is read from the page; its pytest and crosscheck steps are run
as written (options and all) on a small user project whose [tool.wirecheck]
names a correct or a mirrored projector, and the files its upload step keeps
must be the ones those commands wrote.
"""

import re
import shlex
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

yaml = pytest.importorskip("yaml")

ROOT = Path(__file__).resolve().parent.parent
DATA = Path(__file__).parent / "data"


def workflow() -> dict:
    text = (ROOT / "docs" / "ci-workflow.md").read_text(encoding="utf-8")
    blocks = re.findall(r"^```yaml\n(.*?)^```", text, flags=re.S | re.M)
    assert len(blocks) == 1, f"expected one yaml block in docs/ci-workflow.md, found {len(blocks)}"
    return yaml.safe_load(blocks[0])


def commands(step: dict) -> list[list[str]]:
    """A step's shell commands (lines joined by && split apart, comments dropped), as argv lists."""
    out = []
    for line in step.get("run", "").splitlines():
        for part in line.split("&&"):
            argv = shlex.split(part, comments=True)
            if argv:
                out.append(argv)
    return out


def steps() -> list[dict]:
    jobs = workflow()["jobs"]
    assert len(jobs) == 1
    return next(iter(jobs.values()))["steps"]


def step_running(program: list[str]) -> list[str]:
    found = [argv for s in steps() for argv in commands(s) if argv[: len(program)] == program]
    assert len(found) == 1, f"expected one step running {' '.join(program)}, found {found}"
    return found[0]


def test_structure_triggers_python_and_set_up():
    wf = workflow()
    on = wf.get("on", wf.get(True))  # YAML 1.1 reads a bare `on` key as True
    assert set(on) == {"push", "pull_request"}
    uses = [s["uses"].split("@")[0] for s in steps() if "uses" in s]
    assert uses == ["actions/checkout", "actions/setup-python", "actions/upload-artifact"]
    python = next(s for s in steps() if s.get("uses", "").startswith("actions/setup-python"))["with"]
    major, minor = map(int, python["python-version"].split("."))
    assert (major, minor) >= (3, 10)  # pyproject.toml: requires-python >= 3.10
    assert step_running(["sudo", "apt-get", "install"]) == ["sudo", "apt-get", "install", "-y", "libosmesa6"]
    install = step_running(["python", "-m", "pip", "install", "$WIRECHECK"])
    assert any(a.startswith("pytest") for a in install)
    assert wf["env"]["WIRECHECK"].startswith("wirecheck @ ")


def _user_project(pytester, projector: str):
    pytester.makepyfile(
        user_projector=(DATA / "user_projector.py").read_text()
        + "\n\ndef mirrored(points, camera):\n    px = project(points, camera)\n"
        "    px[:, 0] = (camera.width - 1) - px[:, 0]\n    return px\n"
    )
    pytester.makepyprojecttoml(
        f'[tool.wirecheck]\ncandidate = "user_projector.py:{projector}"\n'
        'scenes = ["cube"]\ncases = ["on_axis", "orthographic"]\nframes = 2\n'
    )
    pytester.makepyfile(test_user="def test_projector(wirecheck):\n    wirecheck()\n")
    pytester.syspathinsert()


@pytest.mark.parametrize("projector, code", [("project", 0), ("mirrored", 1)])
def test_the_steps_commands_run_and_write_what_the_upload_keeps(pytester, projector, code):
    from wirecheck.oracles import cli

    _user_project(pytester, projector)
    run_pytest = step_running(["python", "-m", "pytest"])
    result = pytester.runpytest(*run_pytest[3:])
    assert result.ret == code
    run_crosscheck = step_running(["crosscheck"])
    assert cli.main(run_crosscheck[1:]) == code
    junit = ET.parse(pytester.path / run_crosscheck[run_crosscheck.index("--junit-xml") + 1]).getroot()
    assert (junit.get("tests"), junit.get("failures")) == ("2", "0" if code == 0 else "2")  # cube x 2 cameras
    upload = next(s for s in steps() if s.get("uses", "").startswith("actions/upload-artifact"))
    kept = [p for p in upload["with"]["path"].split() if p]
    written = [p for p in kept if (pytester.path / p).exists()]
    # the reports of failing checks exist only when a check failed; everything else always
    assert sorted(kept) == sorted(written + ([] if code else ["wirecheck-reports/"]))
    if code:
        assert "mirror_horizontal" in result.stdout.str()
        assert any((pytester.path / "wirecheck-reports").iterdir())
