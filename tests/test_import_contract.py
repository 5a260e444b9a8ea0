"""The import contract (pyproject.toml's [tool.importlinter], docs/layout.md "Layers"): it holds on this tree,
and it breaks on copies of the tree with an upward import, a cycle or a private name added.

lint-imports (import-linter, dev extras) checks the layers, core's independence of the oracles and the
absence of cycles; the private names and the cycle count are benchmarks/import_graph.py's own checks.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

import import_graph  # noqa: E402

LINT_IMPORTS = Path(sys.executable).parent / "lint-imports"
CONTRACTS = 4  # pyproject.toml: core forbidden, core layers, oracles layers, acyclic siblings


def _lint(tree: Path) -> subprocess.CompletedProcess:
    """lint-imports on the copy ``tree``/wirecheck (its own pyproject.toml), imported from there."""
    assert LINT_IMPORTS.exists(), f"{LINT_IMPORTS}: import-linter is a dev dependency (pip install -e '.[dev]')"
    env = dict(os.environ, PYTHONPATH=str(tree))
    return subprocess.run(
        [str(LINT_IMPORTS), "--no-cache"], cwd=tree, env=env, capture_output=True, text=True, timeout=300
    )


@pytest.fixture
def copy(tmp_path) -> Path:
    """The package's source copied to ``tmp_path/wirecheck`` (with pyproject.toml beside it); returns tmp_path."""
    pkg = tmp_path / "wirecheck"
    pkg.mkdir()
    shutil.copy(ROOT / "__init__.py", pkg / "__init__.py")
    for folder in ("core", "oracles"):
        shutil.copytree(ROOT / folder, pkg / folder, ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copy(ROOT / "pyproject.toml", tmp_path / "pyproject.toml")
    return tmp_path


def _append(path: Path, text: str) -> None:
    path.write_text(path.read_text() + "\n\n" + text + "\n")


def test_the_contract_holds_on_this_tree():
    done = subprocess.run([str(LINT_IMPORTS), "--no-cache"], cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stdout + done.stderr
    assert f"Contracts: {CONTRACTS} kept, 0 broken." in done.stdout  # every contract was read and checked


def test_an_unmodified_copy_keeps_the_contract(copy):
    done = _lint(copy)
    assert done.returncode == 0, done.stdout + done.stderr
    assert f"Contracts: {CONTRACTS} kept, 0 broken." in done.stdout


# Each: the file given a new import, the import, the contract it breaks, the link lint-imports reports.
UPWARD = [
    (
        "oracles/references/convert.py",
        "from wirecheck.oracles import cli  # noqa: F401",
        "oracles' layers",
        "wirecheck.oracles.references.convert -> wirecheck.oracles.cli",
    ),
    # inside a function: grimp reads imports in function bodies too, so a lazy import is no way around it
    (
        "oracles/diagnosis/diagnose.py",
        "def _late():\n    from ..judge import verdict  # noqa: F401",
        "oracles' layers",
        "wirecheck.oracles.diagnosis.diagnose -> wirecheck.oracles.judge.verdict",
    ),
    (
        "core/projector/raster.py",
        "def _late():\n    from wirecheck.oracles import api  # noqa: F401",
        "core never imports the oracles",
        "wirecheck.core.projector.raster -> wirecheck.oracles.api",
    ),
    (
        "core/camera.py",
        "from .app import cli  # noqa: F401",
        "core's layers",
        "wirecheck.core.camera -> wirecheck.core.app.cli",
    ),
]


@pytest.mark.parametrize(
    "rel, line, contract, link",
    UPWARD,
    ids=["references_to_cli", "diagnosis_to_judge_in_a_function", "core_to_oracles", "camera_to_app"],
)
def test_an_upward_import_breaks_the_contract(copy, rel, line, contract, link):
    _append(copy / "wirecheck" / rel, line)
    done = _lint(copy)
    assert done.returncode == 1, done.stdout + done.stderr
    assert "BROKEN" in done.stdout and ", 0 broken." not in done.stdout, done.stdout
    broken = done.stdout[done.stdout.index("Broken contracts") :]  # an upward import also closes a cycle: both named
    assert contract in broken and link in broken, broken


def test_a_cycle_breaks_the_contract_and_is_counted(copy):
    # faces imports convert; convert importing faces closes a cycle inside one layer (references), which
    # only the acyclic contract sees
    _append(copy / "wirecheck" / "oracles/references/convert.py", "def _late():\n    from . import faces  # noqa: F401")
    done = _lint(copy)
    assert done.returncode == 1 and "no import cycles" in done.stdout[done.stdout.index("Broken contracts") :], (
        done.stdout
    )
    assert import_graph.import_cycles(copy / "wirecheck")["cycles"] == [
        ["wirecheck.oracles.references.convert", "wirecheck.oracles.references.faces"]
    ]


def test_this_tree_has_no_import_cycle():
    graph = import_graph.import_cycles(ROOT)
    assert graph["modules"] > 100  # the graph was built from the package, not an empty folder
    assert graph["cycles"] == []


def test_no_module_takes_another_modules_private_name():
    assert import_graph.package_files(ROOT)[1:]  # core/ and oracles/ were found
    assert import_graph.private_name_uses(ROOT) == []


def test_a_private_name_is_found_imported_or_read(copy):
    pkg = copy / "wirecheck"
    _append(pkg / "oracles/frames_api.py", "def _late():\n    from .api import _private_thing  # noqa: F401")
    _append(pkg / "core/projector/pipeline.py", "def _late():\n    return culling._fan")
    uses = import_graph.private_name_uses(pkg)
    assert len(uses) == 2
    assert uses[0].startswith("core/projector/pipeline.py:") and uses[0].endswith(": culling._fan")
    assert uses[1].startswith("oracles/frames_api.py:") and uses[1].endswith("from .api import _private_thing")


#: The imports of the package's own modules left inside functions, ``(file, module as written)``: each a lazy
#: load that keeps a light path light. Any other belongs at the top of its module (docs/layout.md, "Layers").
LAZY = {
    # loaded by every pytest session where wirecheck is installed: no numpy, OpenCV or report code until a test asks
    ("oracles/pytest_plugin.py", ".config"),
    ("oracles/pytest_plugin.py", ".api"),
    ("oracles/pytest_plugin.py", ".reports.report"),
    ("oracles/pytest_plugin.py", ".references.pyrender_oracle"),
    # the candidate's own child process: it loads what the candidate needs, not numpy before the candidate does
    ("oracles/candidates/candidate_host.py", "wirecheck.core.camera"),
    ("oracles/candidates/candidate_host.py", "."),
    ("oracles/candidates/candidate_host.py", ".candidate"),
    # [tool.wirecheck] is read by the plugin and the CLIs before anything heavy: the names it checks come late
    ("oracles/config.py", ".runner"),
    ("oracles/config.py", "wirecheck.core.scene.files"),
    ("oracles/config.py", ".cases"),
    ("oracles/config.py", ".datasets.dataset"),
    ("oracles/api.py", ".config"),  # tomllib, only when a config is read
    # paths of the CLIs a run takes only when asked: the viewer's HTTP server, the sweep, export and JUnit
    # (crosscheck's subcommands: ~100 ms of its start, measured with -X importtime, for paths taken when asked;
    # pyrender_oracle: the GL platform is chosen first)
    ("core/app/cli.py", ".viewer_http"),
    ("oracles/cli.py", ".sweep"),
    ("oracles/cli.py", ".extremes"),
    ("oracles/cli.py", ".datasets.dataset"),
    ("oracles/cli.py", ".datasets.dataset_report"),
    ("oracles/cli.py", ".datasets.dataset_run"),
    ("oracles/cli.py", ".frames_cli"),
    ("oracles/cli.py", ".references.pyrender_oracle"),
    ("oracles/cli.py", ".unprojector_cli"),
    ("oracles/frames_cli.py", ".candidates.export"),
    ("oracles/frames_cli.py", "wirecheck.core.outputs.output"),
    ("oracles/frames_cli.py", ".judge.frames_judge"),
    ("oracles/frames_cli.py", ".reports.report"),
    ("oracles/frames_cli.py", ".config"),
    ("oracles/frames_cli.py", ".reports.junit"),
    ("oracles/frames_api.py", ".judge.frames_judge"),  # its reading-ahead thread pool, on a call
    ("oracles/candidates/job_as_exported.py", ".export"),  # PNG writing (zlib), on a job check
    ("oracles/runner.py", ".candidates.subprocess_candidate"),  # subprocess, in the workers only
    ("oracles/tolerances.py", ".references.convert"),  # OpenCV and scipy, for the vertex bound only
}


def test_imports_inside_functions_are_only_the_lazy_ones():
    found = {(i.file, i.module) for i in import_graph.internal_imports(ROOT) if i.in_function}
    assert found, "no import inside a function found: the scan did not run"  # today's lazy ones exist
    assert found <= LAZY, sorted(found - LAZY)
