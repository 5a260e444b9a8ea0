"""What README.md and docs/*.md show is what the programs do.

- every command sample (a block starting with a ``$`` line, or one marked ``<!-- command: -->``)
  is run and its output compared with the doc (tests/docs_samples.py: times, dates and report
  folders normalised; ``...`` elides lines). One run serves every sample showing the same
  command (the main job is in README.md and docs/crosscheck.md);
- the option tables of docs/renderer.md and docs/crosscheck.md name every option of the
  parsers and no other;
- every code fence is closed, and none is opened inside another.

After a change of output, regenerate the samples: ``python tests/docs_samples.py --update``.
"""

from __future__ import annotations

import re
import sys
import tempfile

import docs_samples as ds
import pytest

SAMPLES = [s for s in ds.all_samples() if s.not_run is None]


@pytest.fixture(scope="module")
def runner():
    r = ds.Runner()
    yield r
    r.close()


def _param(sample):
    marks = [pytest.mark.slow] if sample.slow else []
    return pytest.param(sample, id=sample.where, marks=marks)


def test_the_docs_have_samples_of_each_program():
    # a parser that finds nothing would pass every sample test below: the docs show at least
    # the main job, a fault report, the renderer and the pytest plugin
    commands = " ".join(c.text for s in SAMPLES for c in s.commands)
    for program in ("crosscheck", "renderer", "pytest"):
        assert program in commands
    assert len(SAMPLES) >= 10


@pytest.mark.parametrize("sample", [_param(s) for s in SAMPLES])
def test_sample_is_what_the_program_prints(sample, runner):
    problems = ds.check(sample, runner)
    assert not problems, "\n\n".join(problems)


@pytest.mark.slow
def test_the_readmes_five_line_example_works_as_written_in_a_fresh_project(runner):
    # the README's test file and pytest setting, verbatim, in a folder of their own (nothing installed:
    # this environment's wirecheck), with a correct projector written on the contract only
    blocks = ds.code_blocks(ds.ROOT / "README.md", "Check your own projector in five lines")
    test_file, config = blocks["python"], blocks["toml"]
    assert "from my_package import project" in test_file and "pythonpath" in config
    correct = (ds.ROOT / "tests" / "data" / "user_projector.py").read_text(encoding="utf-8")
    project = {"my_package/__init__.py": correct, "tests/test_x.py": test_file, "pyproject.toml": config}
    # PYTHONSAFEPATH: the current folder is not put on the path, as for the `pytest` script (3.11+)
    pytest = "PYTHONSAFEPATH=1 pytest -q -p no:cacheprovider"
    out = runner.in_project(project, pytest)
    assert out and re.fullmatch(r"1 passed in [\d.]+s", out[-1]), "\n".join(out)
    # the same test fails a principal point at (W/2, H/2), naming the fault: it checks something
    corner = correct + (
        "\n_correct = project\n\n\ndef project(points, camera):\n"
        "    return _correct(points, camera, cx=camera.width / 2, cy=camera.height / 2)\n"
    )
    out = runner.in_project({**project, "my_package/__init__.py": corner}, pytest)
    assert re.fullmatch(r"1 failed in [\d.]+s", out[-1]) and any("pixel_offset(dx=0.5, dy=0.5)" in x for x in out)
    # and without the setting (nor an install) pytest cannot import the package: what the README says
    if sys.version_info < (3, 11):
        return  # no PYTHONSAFEPATH: `python -m` adds the folder
    out = runner.in_project({k: v for k, v in project.items() if k != "pyproject.toml"}, pytest)
    assert any("No module named 'my_package'" in x for x in out), "\n".join(out)


def test_not_run_samples_say_why():
    for s in ds.all_samples():
        if s.not_run is not None:
            assert len(s.not_run) >= 10, f"{s.where}: 'not run' needs a reason"


# -- the comparison itself (hand-made outputs: no program run) --------------------------------


def test_an_edited_number_is_a_difference():
    doc = ["PASS: 21/21 cases, 504 frames", "Level pixels: vertex stage 1.59 ms/frame (11.9 s wall)"]
    run = ["PASS: 21/21 cases, 504 frames", "Level pixels: vertex stage 4.27 ms/frame (42.7 s wall)"]
    assert ds.matches(doc, run)  # times differ: normalised
    assert not ds.matches(["PASS: 20/21 cases, 504 frames", doc[1]], run)  # a count does not
    assert not ds.matches(doc, run + ["Candidate precision: float64"])  # a line more


def test_elision_stands_for_any_lines_and_only_where_it_is():
    run = ["head", "a", "b", "c", "", "FAIL: 0/7", "Report: reports/20261127-042124/report.json"]
    assert ds.matches(["head", "...", "", "FAIL: 0/7", "Report: reports/20261121-193000/report.json"], run)
    assert ds.matches(["head", "a", "b", "c", "...", "FAIL: 0/7", "..."], run)
    assert not ds.matches(["head", "...", "FAIL: 0/6", "..."], run)
    assert not ds.matches(["a", "..."], run)  # the head is compared from the first line


def test_update_keeps_the_shape_of_a_block():
    doc = [
        "scene camera",
        "cube on_axis 1",
        "...",
        "  cube / on_axis: reason",
        "  ...",
        "",
        "FAIL: 0/7 cases",
        "Report: reports/20261121-193000/report.json",
    ]
    run = [
        "scene camera",
        "cube on_axis 1",
        "cube oblique 2",
        "cube wide 3",
        "  cube / on_axis: reason (float64 bound)",
        "  cube / oblique: reason",
        "",
        "FAIL: 0/7 cases",
        "Candidate precision: float64",
        "Report: reports/20261127-042124/report.json",
    ]
    assert ds.reshape(doc, run) == [
        "scene camera",
        "cube on_axis 1",
        "...",
        "  cube / on_axis: reason (float64 bound)",
        "  ...",
        "",
        "FAIL: 0/7 cases",
        "Candidate precision: float64",
        "Report: reports/20261127-042124/report.json",
    ]
    assert ds.matches(ds.reshape(doc, run), run)


def test_update_then_check_round_trips(tmp_path):
    doc = tmp_path / "page.md"
    doc.write_text(
        "Intro\n\n```\n$ printf 'a\\nb\\nc\\nd\\n'\na\n...\nd\nold line\n```\n\n"
        "    $ echo 'took 1.5 s'\n    took 9.9 s\n",
        encoding="utf-8",
    )
    runner = ds.Runner()
    try:
        (first, second) = ds.samples(doc)
        assert ds.check(first, runner)  # "old line" is not printed
        assert not ds.check(second, runner)  # a time: normalised
        ds.update([doc], runner)
        assert doc.read_text(encoding="utf-8") == (
            "Intro\n\n```\n$ printf 'a\\nb\\nc\\nd\\n'\na\n...\nd\n```\n\n    $ echo 'took 1.5 s'\n    took 1.5 s\n"
        )
        assert not any(ds.check(s, runner) for s in ds.samples(doc))
    finally:
        runner.close()


# -- option tables --------------------------------------------------------------------------


def _table_options(path):
    """Every ``--option`` in the first column of the Markdown tables of ``path``."""
    found = set()
    for line in path.read_text(encoding="utf-8").splitlines():
        if line.startswith("|"):
            first = re.split(r"(?<!\\)\|", line)[1]
            found |= set(re.findall(r"--[a-z][a-z0-9-]*", first))
    return found


def _parser_options(parser):
    return {s for a in parser._actions for s in a.option_strings if s.startswith("--") and s != "--help"}


@pytest.mark.parametrize("program", ["renderer", "crosscheck"])
def test_option_table_is_the_parser(program):
    if program == "renderer":
        from wirecheck.core.app.cli import build_parser
    else:
        from wirecheck.oracles.cli import build_parser
    documented = _table_options(ds.ROOT / "docs" / f"{program}.md")
    real = _parser_options(build_parser())
    assert "--version" in real and len(real) > 20  # the parser was read
    assert not real - documented, f"options of {program} missing from docs/{program}.md's table"
    assert not documented - real, f"docs/{program}.md documents options {program} does not have"


# -- fences ---------------------------------------------------------------------------------


@pytest.mark.parametrize("path", ds.doc_files(), ids=lambda p: p.name)
def test_fences_are_balanced(path):
    assert ds.unbalanced_fences(path) == []


def test_an_unbalanced_fence_is_found(tmp_path):
    page = tmp_path / "p.md"
    # crosscheck.md's old mistake: a report excerpt left open, so a heading became code and the
    # next ```python closed it
    page.write_text("```\nreport excerpt\n\n## Heading\n\n```python\ncode\n```\n", encoding="utf-8")
    assert [m.split(": ", 1)[0][-6:] for m in ds.unbalanced_fences(page)] == ["p.md:6"]
    page.write_text("text\n```\ncode\n", encoding="utf-8")
    assert [m.split(": ", 1)[0][-6:] for m in ds.unbalanced_fences(page)] == ["p.md:2"]


def test_every_cwd_directive_names_a_folder_of_the_repository():
    folders = {s.cwd for s in ds.all_samples() if s.cwd}
    assert folders, "the pytest and renderer samples run in folders of their own"
    for folder in folders:
        assert (ds.ROOT / folder).is_dir() and not folder.startswith(("/", "..")), folder


# -- running: a fork of this process prints what a new process prints -------------------------

FORKED = [
    "renderer --scene cube --frames 2 --camera-z 4.0 --trace-vertex 6 --trace-frames 1",  # stdout
    "renderer --camera-pos 0,4,0",  # one stderr line, exit 2
    "crosscheck --scene cube --level vertices --frames 1 --cases on_axis --no-report",
]


@pytest.mark.parametrize("command", FORKED)
def test_a_forked_command_prints_what_bash_running_it_prints(command, tmp_path):
    assert ds._PLAIN_CLI.match(command)
    env = ds.Runner._env()
    forked = ds._run_forked(command.split()[0], command.split()[1:], str(tmp_path), env)
    bash = ds.Runner._run_bash(command, str(tmp_path), env)
    assert forked and ds.matches(bash, forked)  # times normalised, every other character the same


def test_a_report_excerpt_reads_the_folder_of_the_run_it_follows():
    runner = ds.Runner()
    try:
        first = "renderer --scene cube --frames 2 --camera-z 4.0"
        shown = runner.output(first)
        listing = runner.output(f"{first} >/dev/null; ls -A | sort")
        again = runner._run_bash(
            f"{first} >/dev/null; ls -A | sort", tempfile.mkdtemp(dir=runner._dirs[0]), runner._env()
        )
    finally:
        runner.close()
    assert shown and len(runner._cache) == 2 and len(runner._folders) == 1  # the renderer ran once
    # what the renderer wrote, as a run of the whole line in an empty folder lists it (less the links)
    assert [n for n in listing if n not in (".venv", "scenes", "tests")] == again and again


def test_a_forked_command_past_its_time_is_killed(tmp_path, monkeypatch):
    # 180 frames of the cube take ~0.3 s of CPU here (seconds on a loaded machine); 0.01 s is far less
    monkeypatch.setattr(ds, "COMMAND_TIMEOUT_S", 0.01)
    with pytest.raises(ds.subprocess.TimeoutExpired):
        ds._run_forked("renderer", ["--scene", "cube", "--frames", "180"], str(tmp_path), ds.Runner._env())
