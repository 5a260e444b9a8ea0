"""``wirecheck.check_frames`` / ``assert_frames``: a renderer's frames judged from Python, as the CLI judges them.

The verdicts are known from how the frames were drawn: core's own drawing of the job (a correct
renderer: pass), black frames (nothing drawn: fail), core's drawing with the principal point
moved half a pixel right and down (the pixel-corner mistake: pixel_offset, dx = dy = 0.5). The
report written with ``report_dir`` is compared byte for byte with what ``crosscheck
--candidate-frames DIR --report-dir X`` writes, and every refused input with the line the CLI
prints for it. The python block of docs/pytest.md's "A renderer's own frames" is run as written.
"""

from __future__ import annotations

import json
import os
import re
import sys
from pathlib import Path

import pytest
import wirecheck
from helpers import blank_job, fill_job  # tests/ is on sys.path (rootdir conftest)
from PIL import Image
from wirecheck.oracles.cli import main

ROOT = Path(__file__).resolve().parent.parent


def _half_pixel(cam):
    """The camera with its principal point 0.5 px right and down: the pixel-corner convention."""
    fx, fy = cam.focal_xy
    cx, cy = cam.principal_point
    return cam.with_intrinsics(fx, fy, cx + 0.5, cy + 0.5)


@pytest.fixture(scope="module")
def jobs(tmp_path_factory) -> dict:
    """pyramid / oblique_roll (slanted lines: an offset shows in x and y), frames 1 and 4 of 6: drawn by core
    ("good"), by core half a pixel off ("half"), and cube / on_axis in black ("black", tests/helpers.py)."""
    base = tmp_path_factory.mktemp("frames_api")
    out = {}
    for name, camera in (("good", lambda cam: cam), ("half", _half_pixel)):
        out[name] = base / name
        assert (
            main(
                [
                    "export",
                    str(out[name]),
                    "--scene",
                    "pyramid",
                    "--cases",
                    "oblique_roll",
                    "--frames",
                    "6",
                    "--every",
                    "3",
                ]
            )
            == 0
        )
        fill_job(out[name], camera=camera)
    out["black"] = blank_job(base / "black")
    return out


def _cli_error(capsys, *args) -> str:
    """``crosscheck args``' stderr, exit 2 asserted, its ``crosscheck: error: `` prefixes taken off."""
    capsys.readouterr()
    assert main(list(args)) == 2
    err = capsys.readouterr().err.splitlines()
    assert err and all(line.startswith("crosscheck: error: ") for line in err), err
    return "\n".join(line[len("crosscheck: error: ") :] for line in err)


def test_core_drawn_frames_pass(jobs):
    report = wirecheck.assert_frames(jobs["good"])
    (case,) = report["cases"]
    assert report["verdict"] == "pass" and case["verdict"] == "pass" and case["faults"] == []
    # the judge compared both listed frames (1 and 4 of 6), not nothing
    assert report["compared"]["frames"] == 2 and report["compared"]["pixels"] > 0
    assert report["candidate"] == "frames:good" and report["line_rule"] == "any"


def test_black_frames_fail_naming_the_fault(jobs):
    with pytest.raises(AssertionError) as exc:
        wirecheck.assert_frames(jobs["black"])
    text = str(exc.value)
    report = wirecheck.check_frames(jobs["black"])  # the same judge, not raising
    (case,) = report["cases"]
    assert report["verdict"] == "fail" and case["faults"], case
    names = [f["name"] for f in case["faults"]]
    # failure_text's shape: what was compared, the count, the case with its faults, what to check
    assert text.startswith("Compared: level frames")
    assert "1 of 1 crosscheck cases failed for frames:black:" in text
    assert f"cube / on_axis: faults: {names[0]}" in text
    assert f"what to check, {names[0]}:" in text


def test_half_pixel_shift_fails_as_pixel_offset(jobs):
    with pytest.raises(AssertionError) as exc:
        wirecheck.assert_frames(jobs["half"])
    assert "pyramid / oblique_roll: faults: pixel_offset(" in str(exc.value)
    assert "what to check, pixel_offset:" in str(exc.value)
    (case,) = wirecheck.check_frames(jobs["half"])["cases"]
    (fault,) = case["faults"]
    # the injected 0.5 px, recovered from the lines' centres to 0.05 px (the held-out renderers' bound,
    # tests/test_frames_heldout.py)
    assert fault["name"] == "pixel_offset"
    assert fault["dx"] == pytest.approx(0.5, abs=0.05) and fault["dy"] == pytest.approx(0.5, abs=0.05)


@pytest.mark.parametrize("job, rule", [("half", "gl"), ("good", "geometry")])
def test_report_dir_is_the_clis_report_byte_for_byte(jobs, tmp_path, job, rule):
    api_dir, cli_dir = tmp_path / "api", tmp_path / "cli"
    if job == "half":
        with pytest.raises(AssertionError) as exc:
            wirecheck.assert_frames(jobs[job], line_rule=rule, report_dir=api_dir)
        assert str(exc.value).endswith(f"\n  report: {api_dir / 'report.html'}")
    else:
        wirecheck.assert_frames(jobs[job], line_rule=rule, report_dir=api_dir)
    assert main(["--candidate-frames", str(jobs[job]), "--line-rule", rule, "--report-dir", str(cli_dir)]) == (
        1 if job == "half" else 0
    )
    files = sorted(p.relative_to(api_dir) for p in api_dir.rglob("*") if p.is_file())
    assert files == sorted(p.relative_to(cli_dir) for p in cli_dir.rglob("*") if p.is_file())
    assert {Path("report.json"), Path("report.md"), Path("report.html")} <= set(files)
    for rel in files:
        a, c = (api_dir / rel).read_bytes(), (cli_dir / rel).read_bytes()
        if rel == Path("report.json"):  # the judge's wall time: its own field, differs run to run
            a, c = (json.loads(x) for x in (a, c))
            assert a.pop("timing").keys() == c.pop("timing").keys()
            assert a["line_rule"] == rule
        elif rel == Path(".wirecheck-output"):  # the folder's listing of what wirecheck wrote: report.json's hash
            a, c = (json.loads(x) for x in (a, c))  # differs with the time, every other file's is compared
            assert a["files"].pop("report.json") and c["files"].pop("report.json")
        assert a == c, rel


def test_no_report_dir_writes_nothing(jobs, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    before = sorted(p for p in Path(jobs["good"]).rglob("*"))
    wirecheck.check_frames(jobs["good"])
    assert list(tmp_path.iterdir()) == [] and sorted(Path(jobs["good"]).rglob("*")) == before


def test_bad_input_raises_the_clis_line(jobs, tmp_path, capsys):
    missing = tmp_path / "nothing"
    with pytest.raises(ValueError) as exc:
        wirecheck.check_frames(missing)
    assert str(exc.value) == _cli_error(capsys, "--candidate-frames", str(missing))
    assert "not a directory: expected a job folder written by 'crosscheck export'" in str(exc.value)

    undrawn = tmp_path / "undrawn"  # exported, no frame drawn
    assert main(["export", str(undrawn), "--scene", "cube", "--cases", "on_axis", "--frames", "4", "--every", "2"]) == 0
    with pytest.raises(ValueError) as exc:
        wirecheck.check_frames(undrawn)
    assert str(exc.value) == _cli_error(capsys, "--candidate-frames", str(undrawn), "--report-dir", str(tmp_path / "r"))
    assert "frames: empty: expected the renderer's frames" in str(exc.value)
    (undrawn / "frames/cube/on_axis").mkdir(parents=True)  # frame 1 drawn, frame 3 missing
    Image.new("L", (640, 480)).save(undrawn / "frames/cube/on_axis/frame_0001.png")
    with pytest.raises(ValueError) as exc:
        wirecheck.check_frames(undrawn)
    assert str(exc.value) == _cli_error(capsys, "--candidate-frames", str(undrawn))
    assert "frame_0003.png" in str(exc.value) and "frame_0001.png" not in str(exc.value)

    listing = json.loads((undrawn / "job.json").read_text())  # a job that lists no case: compares nothing
    listing["cases"] = []
    (undrawn / "job.json").write_text(json.dumps(listing))
    with pytest.raises(ValueError) as exc:
        wirecheck.check_frames(undrawn)
    assert str(exc.value) == _cli_error(capsys, "--candidate-frames", str(undrawn))
    assert str(exc.value).endswith("job.json: the job lists no frames: nothing to judge")

    # the job and its frames/ hold the renderer's files: refused by the folder check (named as the API names
    # the option, report_dir, as check_projector does), a new folder in frames/ by the job's own check
    for inside, why in (
        (jobs["good"], "is a frames job holding files a renderer wrote"),
        (jobs["good"] / "frames", "a directory not written by wirecheck"),
        (jobs["good"] / "frames" / "rep", "itself or its frames/"),
    ):
        with pytest.raises(ValueError) as exc:
            wirecheck.check_frames(jobs["good"], report_dir=inside)
        cli = _cli_error(capsys, "--candidate-frames", str(jobs["good"]), "--report-dir", str(inside))
        assert str(exc.value) == re.sub(r"^--report-dir ", "report_dir ", cli)
        assert why in str(exc.value)
    assert not (jobs["good"] / "frames" / "rep").exists()

    a_file = tmp_path / "report.txt"
    a_file.write_text("mine\n")
    with pytest.raises(ValueError, match=r"report_dir '.*report\.txt' is a file: expected a folder"):
        wirecheck.check_frames(jobs["good"], report_dir=a_file)
    assert a_file.read_text() == "mine\n"


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"line_rule": "pixels"}, "line_rule 'pixels': expected one of any, gl, geometry"),
        ({"line_rule": None}, "line_rule None: expected one of any, gl, geometry"),
        # a NaN floor would pass everything (no comparison with NaN is true); above 1 nothing passes
        ({"min_f1": float("nan")}, "min_f1 nan: expected a number in [0, 1]"),
        ({"min_f1_0px": 1.5}, "min_f1_0px 1.5: expected a number in [0, 1]"),
    ],
)
def test_bad_arguments_raise_value_error_naming_them(jobs, kwargs, message):
    with pytest.raises(ValueError) as exc:
        wirecheck.check_frames(jobs["good"], **kwargs)
    assert str(exc.value).startswith(message)


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"allow_vacuous": "no"}, "allow_vacuous 'no': expected True or False"),
        ({"report_dir": 3}, "report_dir 3: expected a folder path"),
    ],
)
def test_wrong_kinds_raise_type_error(jobs, kwargs, message):
    with pytest.raises(TypeError, match=re.escape(message)):
        wirecheck.check_frames(jobs["good"], **kwargs)


def _doc_block() -> str:
    """The python block of docs/pytest.md's section "A renderer's own frames"."""
    text = (ROOT / "docs" / "pytest.md").read_text(encoding="utf-8")
    section = text.split("### A renderer's own frames", 1)[1].split("\n### ", 1)[0]
    (block,) = re.findall(r"```python\n(.*?)```", section, flags=re.S)
    return block


@pytest.mark.parametrize("draws", ["core", "black"])
def test_the_docs_example_runs(tmp_path, monkeypatch, draws):
    # my_renderer: core's drawing of the job (tests/helpers.py fill_job), or black frames
    work = tmp_path / "work"
    work.mkdir()
    draw = (
        "helpers.fill_job(job)"
        if draws == "core"
        else (
            "from PIL import Image\n"
            "for c in json.loads((job / 'job.json').read_text())['cases']:\n"
            "    for rel in c['frames']:\n"
            "        (job / rel).parent.mkdir(parents=True, exist_ok=True)\n"
            "        Image.new('L', (c['width'], c['height'])).save(job / rel)\n"
        )
    )
    renderer = work / "my_renderer"
    renderer.write_text(
        f"#!{sys.executable}\nimport json, sys\nfrom pathlib import Path\n"
        f"sys.path.insert(0, {str(ROOT / 'tests')!r})\nimport helpers\n"
        f"job = Path(sys.argv[1])\n{draw}\n"
    )
    renderer.chmod(0o755)
    monkeypatch.chdir(work)
    monkeypatch.setenv("PATH", f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}")
    scope: dict = {}
    exec(compile(_doc_block(), "docs/pytest.md", "exec"), scope)
    if draws == "core":
        scope["test_my_renderer_draws_the_job"](tmp_path)
        assert json.loads((tmp_path / "frames-report" / "report.json").read_text())["verdict"] == "pass"
    else:
        with pytest.raises(AssertionError, match=r"cube / on_axis: faults: \w+"):
            scope["test_my_renderer_draws_the_job"](tmp_path)
    assert (tmp_path / "frames-report" / "report.html").is_file()


def test_the_config_table_sets_the_floors_as_for_the_cli(jobs, tmp_path, monkeypatch):
    # [tool.wirecheck] min-f1 = 0.5, min-f1-0px = 0.25 in the nearest pyproject.toml: the run's tolerances
    # (report.json) say so, as crosscheck --candidate-frames reads the same table; config=False reads no file
    # (the defaults 0.999, 0.98 of docs/tolerances.md), a keyword wins over the table (as check_projector's
    # settings), and a bad value is the line crosscheck prints
    (tmp_path / "pyproject.toml").write_text("[tool.wirecheck]\nmin-f1 = 0.5\nmin-f1-0px = 0.25\n")
    monkeypatch.chdir(tmp_path)
    tols = wirecheck.check_frames(jobs["good"])["tolerances"]
    assert (tols["min_pixel_f1_1px"], tols["min_pixel_f1_0px"]) == (0.5, 0.25)
    none = wirecheck.check_frames(jobs["good"], config=False)["tolerances"]
    assert (none["min_pixel_f1_1px"], none["min_pixel_f1_0px"]) == (0.999, 0.98)
    given = wirecheck.check_frames(jobs["good"], min_f1_0px=0.75)["tolerances"]
    assert (given["min_pixel_f1_1px"], given["min_pixel_f1_0px"]) == (0.5, 0.75)
    cli = tmp_path / "rep"
    assert main(["--candidate-frames", str(jobs["good"]), "--report-dir", str(cli)]) == 0
    rep = json.loads((cli / "report.json").read_text())["tolerances"]
    assert (rep["min_pixel_f1_1px"], rep["min_pixel_f1_0px"]) == (0.5, 0.25)
    (tmp_path / "bad.toml").write_text("[tool.wirecheck]\nmin-f1 = 2\n")
    with pytest.raises(ValueError, match=r"bad.toml: \[tool.wirecheck\] min-f1 = 2: expected a number in \[0, 1\]"):
        wirecheck.check_frames(jobs["good"], config=tmp_path / "bad.toml")


def test_the_frames_cli_lists_each_failing_case_as_the_projector_cli_does(jobs, tmp_path, capsys):
    # one way of printing a failing case on both paths: its first two reasons and how many more report.md has
    # (oracles.reports.compared.reason_text, tested by hand in test_fault_text); the black job fails with more
    # than two reasons, each listed in report.json
    from wirecheck.oracles.reports.compared import reason_text

    capsys.readouterr()
    assert main(["--candidate-frames", str(jobs["black"]), "--report-dir", str(tmp_path / "rep")]) == 1
    out = capsys.readouterr().out
    (case,) = json.loads((tmp_path / "rep" / "report.json").read_text())["cases"]
    assert len(case["reasons"]) > 2, case["reasons"]
    line = f"  {case['scene']} / {case['camera']}: " + reason_text(case["reasons"])
    assert line in out.splitlines() and line.endswith(f"+{len(case['reasons']) - 2} more in report.md")
