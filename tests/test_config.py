"""[tool.wirecheck] (oracles/config.py): validation, discovery, and crosscheck's precedence over it."""

import json
from pathlib import Path

import pytest
from wirecheck.core.errors import InputError
from wirecheck.oracles import cli
from wirecheck.oracles.config import find_pyproject, load_config

DATA = Path(__file__).parent / "data"


def _project(tmp_path, table: str, header: str = "[tool.wirecheck]\n") -> Path:
    path = tmp_path / "pyproject.toml"
    path.write_text("[project]\nname = 'users-project'\n\n" + header + table)
    return path


def test_values_are_read_and_paths_resolved_against_the_file(tmp_path):
    (tmp_path / "scenes").mkdir()
    (tmp_path / "scenes" / "arm.scene").write_text("v 0 0 0\n")
    path = _project(
        tmp_path,
        'candidate = "src/proj.py:project"\nscenes = ["cube", "scenes/arm.scene"]\n'
        'cases = ["on_axis"]\nframes = 3\noracles = ["opencv"]\ntol-px = 0.5\n'
        "min-f1 = 0.9\nmin-f1-0px = 0.8\nspin = [0, 1, 0.5]\n",
    )
    config = load_config(start=tmp_path / "deeper" / "still")  # found by walking up
    assert config.path == path
    assert config.values == {
        "candidate": f"{tmp_path.resolve() / 'src' / 'proj.py'}:project",
        "scenes": ["cube", str(tmp_path.resolve() / "scenes" / "arm.scene")],
        "cases": ["on_axis"],
        "frames": 3,
        "level": "vertices",
        "tol-px": 0.5,
        "min-f1": 0.9,
        "min-f1-0px": 0.8,
        "spin": (0.0, 1.0, 0.5),
    }
    assert config.api_kwargs() == {
        "scenes": config.values["scenes"],
        "cases": ["on_axis"],
        "frames": 3,
        "tol_px": 0.5,
        "min_f1": 0.9,
        "min_f1_0px": 0.8,
        "turns": (0.0, 1.0, 0.5),
        "oracles": ("opencv",),
    }


def test_settings_without_a_level_import_no_runner(tmp_path):
    # the pytest plugin reads the table at every pytest start (pytest_configure), used or not: the
    # runner (scipy, trimesh; ~0.7 s) is imported only for a level. A fresh process: this one has it
    import subprocess
    import sys

    _project(tmp_path, "frames = 3\n")
    code = (
        "import sys; from pathlib import Path; from wirecheck.oracles.config import load_config; "
        f"kw = load_config(start=Path({str(tmp_path)!r})).api_kwargs(); "
        "print(kw, sorted(m for m in ('wirecheck.oracles.runner', 'scipy') if m in sys.modules))"
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout == "{'frames': 3} []\n"


def test_nearest_pyproject_wins_and_one_without_the_table_means_no_settings(tmp_path):
    _project(tmp_path, "frames = 3\n")
    inner = tmp_path / "sub"
    inner.mkdir()
    (inner / "pyproject.toml").write_text("[project]\nname = 'inner'\n")
    assert find_pyproject(inner / "a" / "b") == inner / "pyproject.toml"
    assert load_config(start=inner).values == {}  # the nearest file marks the project: no table there
    assert load_config(start=tmp_path).values == {"frames": 3}


@pytest.mark.parametrize(
    "table, needle",
    [
        ("frame = 3\n", "unknown key 'frame' (did you mean 'frames'?)"),
        ("frames = 0\n", "frames = 0: expected an integer >= 1"),
        ("frames = -3\n", "frames = -3: expected an integer >= 1"),
        ("frames = true\n", "frames = True: expected an integer >= 1"),  # a bool is not a count
        ("frames = 2.5\n", "frames = 2.5: expected an integer >= 1"),
        ('frames = "8"\n', "frames = '8': expected an integer >= 1"),
        ("cases = []\n", "cases = []: expected a non-empty list"),
        ('cases = ["on_axiz"]\n', "'on_axiz' unknown"),
        ('cases = [""]\n', "cases = ['']: expected a non-empty list"),
        ('cases = "on_axis"\n', "cases = 'on_axis': expected a non-empty list"),
        ("scenes = []\n", "scenes = []: expected a non-empty list"),
        ('scenes = ["cub"]\n', "'cub' is neither"),
        ('scenes = ["missing.scene"]\n', "is not a file"),
        ('level = "pixel"\n', "level = 'pixel': expected 'vertices' or 'pixels'"),
        ('oracles = ["pyrender"]\n', "oracles = ['pyrender']: expected a list of 'opencv' and 'pyrender'"),
        ("oracles = []\n", "oracles = []: expected"),
        ('level = "pixels"\noracles = ["opencv"]\n', "both level and oracles"),
        ("tol-px = -1\n", "tol-px = -1: expected a number >= 0"),
        ("tol-px = nan\n", "tol-px = nan: expected a number >= 0"),
        ("min-f1 = 1.5\n", "min-f1 = 1.5: expected a number in [0, 1]"),
        ("spin = [1, 1]\n", "spin = [1, 1]: expected a list of three finite numbers"),
        ('candidate = "proj.py"\n', "candidate = 'proj.py': expected a string FILE.py:FUNC"),
    ],
)
def test_bad_values_name_the_file_key_and_value(tmp_path, table, needle):
    path = _project(tmp_path, table)
    with pytest.raises(InputError) as info:
        load_config(start=tmp_path)
    text = str(info.value)
    assert text.startswith(f"{path}: ") and needle in text and "\n" not in text


def test_broken_toml_and_explicit_files(tmp_path):
    path = tmp_path / "pyproject.toml"
    path.write_text("[tool.wirecheck\nframes = 3\n")
    with pytest.raises(InputError, match=r"not valid TOML"):
        load_config(start=tmp_path)
    with pytest.raises(InputError, match=r"file not found"):
        load_config(tmp_path / "nope.toml")
    other = tmp_path / "other.toml"
    other.write_text("[tool.black]\nline-length = 99\n")
    with pytest.raises(InputError, match=r"no \[tool.wirecheck\] table"):  # named by the user: must hold it
        load_config(other)


def _cli(tmp_path, monkeypatch, *args):
    monkeypatch.chdir(tmp_path)
    code = cli.main(["--report-dir", str(tmp_path / "out"), *args])
    report = json.loads((tmp_path / "out" / "report.json").read_text()) if code in (0, 1) else None
    return code, report


def test_crosscheck_takes_the_table_as_defaults_and_options_override_it(tmp_path, monkeypatch, capsys):
    _project(
        tmp_path,
        'scenes = ["pyramid"]\ncases = ["on_axis", "orthographic"]\nframes = 3\nlevel = "vertices"\nspin = [0, 1, 0]\n',
    )
    code, report = _cli(tmp_path, monkeypatch)
    assert code == 0
    assert (
        [(c["scene"], c["camera"]) for c in report["cases"]] == [("pyramid", "on_axis"), ("pyramid", "orthographic")]
        and report["frames"] == 3
        and report["level"] == "vertices"
        and report["motion"]["turns"] == [0, 1, 0]
    )
    assert "settings from" in capsys.readouterr().err
    code, report = _cli(
        tmp_path, monkeypatch, "--frames", "2", "--scene", "cube", "--cases", "near_plane", "--oracles", "opencv"
    )
    assert code == 0
    assert [(c["scene"], c["camera"]) for c in report["cases"]] == [("cube", "near_plane")] and report["frames"] == 2


def test_crosscheck_candidate_from_the_table_is_judged(tmp_path, monkeypatch):
    (tmp_path / "proj.py").write_text(
        (DATA / "user_projector.py").read_text()
        + "\n\ndef flipped(points, camera):\n    px = project(points, camera)\n"
        "    px[:, 1] = (camera.height - 1) - px[:, 1]\n    return px\n"
    )
    _project(
        tmp_path,
        'candidate = "proj.py:flipped"\nscenes = ["cube"]\ncases = ["on_axis"]\nframes = 2\nlevel = "vertices"\n',
    )
    code, report = _cli(tmp_path, monkeypatch)
    assert code == 1 and report["cases"][0]["faults"][0]["name"] == "mirror_vertical"
    code, report = _cli(tmp_path, monkeypatch, "--candidate", "proj.py:project")  # the option wins
    assert code == 0 and report["summary"]["cases"] == 1


def test_crosscheck_bad_table_is_exit_2_with_one_line(tmp_path, monkeypatch, capsys):
    path = _project(tmp_path, "cases = []\n")
    code, _ = _cli(tmp_path, monkeypatch, "--level", "vertices")
    err = capsys.readouterr().err
    assert (
        code == 2
        and err
        == f"crosscheck: error: {path}: [tool.wirecheck] cases = []: expected a non-empty "
        "list of some of on_axis, oblique_roll, near_plane, wide_fov, narrow_fov, "
        "non_square, orthographic, off_centre, non_square_pixels, distorted\n"
    )
    assert not (tmp_path / "out").exists()


def test_crosscheck_config_option_names_the_file(tmp_path, monkeypatch, capsys):
    other = tmp_path / "ci.toml"
    other.write_text('[tool.wirecheck]\nscenes = ["prism"]\ncases = ["wide_fov"]\nframes = 2\nlevel = "vertices"\n')
    code, report = _cli(tmp_path, monkeypatch, "--config", str(other))
    assert code == 0 and [(c["scene"], c["camera"]) for c in report["cases"]] == [("prism", "wide_fov")]
    code, _ = _cli(tmp_path, monkeypatch, "--config", str(tmp_path / "missing.toml"))
    assert code == 2 and "missing.toml: file not found" in capsys.readouterr().err


def test_suite_and_sweep_leave_the_table_alone(tmp_path, monkeypatch):
    from wirecheck.oracles.cases import CASE_NAMES
    from wirecheck.oracles.config import parse_cli

    _project(tmp_path, 'candidate = "proj.py:project"\ncases = ["on_axis"]\nframes = 3\n')
    monkeypatch.chdir(tmp_path)
    args, _, applied = parse_cli(cli.build_parser(), ["--suite", "extremes"])  # the suite's cases are fixed
    assert applied == [] and args.frames is None and args.cases == ",".join(CASE_NAMES) and args.candidate is None
    args, _, applied = parse_cli(cli.build_parser(), ["--sweep"])  # the sweep runs core
    assert applied == ["cases", "frames"] and args.candidate is None and args.frames == 3


def test_a_program_chosen_by_the_table_is_named_before_it_runs(tmp_path, monkeypatch, capsys):
    """The trust model (docs/pytest.md, 'Whose settings run'): a [tool.wirecheck] table is trusted as pytest trusts
    a conftest.py, and crosscheck says which file chose which program on stderr before starting it. Here the start
    is intercepted: what stderr held at that moment is the one line naming both."""
    path = _project(
        tmp_path, 'candidate-cmd = "./evil --flag"\nscenes = ["cube"]\ncases = ["on_axis"]\nlevel = "vertices"\n'
    )
    seen = []

    def intercept(spec, command, timeout_s):
        seen.append((command, capsys.readouterr().err))
        raise InputError("intercepted before the program started")

    monkeypatch.setattr(cli, "external_candidate", intercept)
    code, _ = _cli(tmp_path, monkeypatch)
    assert code == 2 and seen == [
        (
            "./evil --flag",
            (
                f"crosscheck: {path} [tool.wirecheck] chose the program: candidate-cmd = './evil --flag'; it runs now "
                "with your permissions (as pytest runs a conftest.py): give --candidate, --candidate-cmd or --config FILE "
                "to choose otherwise\n"
            ),
        )
    ]
    seen.clear()
    capsys.readouterr()
    code, _ = _cli(tmp_path, monkeypatch, "--candidate-cmd", "./mine")  # the user's own choice: no line
    assert code == 2 and seen == [("./mine", "")]


def test_a_python_candidate_chosen_by_the_table_is_named_too(tmp_path, monkeypatch, capsys):
    (tmp_path / "proj.py").write_text((DATA / "user_projector.py").read_text())
    path = _project(
        tmp_path,
        'candidate = "proj.py:project"\nscenes = ["cube"]\ncases = ["on_axis"]\nframes = 2\nlevel = "vertices"\n',
    )
    code, _ = _cli(tmp_path, monkeypatch)
    lines = capsys.readouterr().err.splitlines()
    assert code == 0
    assert lines[0] == (
        f"crosscheck: {path} [tool.wirecheck] chose the Python candidate (its file is imported and "
        f"run): candidate = '{tmp_path / 'proj.py'}:project'; it runs now with your permissions (as "
        "pytest runs a conftest.py): give --candidate, --candidate-cmd or --config FILE to choose "
        "otherwise"
    ), lines
