"""tests/mutation/mutate.py refuses a run over nothing instead of writing "Score: nan%" (issue 25, item 11), and its
TARGETS name modules and tests that exist."""

import hashlib
import importlib.util
import sys
from pathlib import Path

MUTATION = Path(__file__).resolve().parent / "mutation"


def _mutate():
    spec = importlib.util.spec_from_file_location("mutate_tool", MUTATION / "mutate.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # its dataclasses look their module up there
    spec.loader.exec_module(module)
    return module


def test_only_with_an_unknown_id_is_exit_2_and_writes_nothing(tmp_path, capsys):
    committed = hashlib.sha256((MUTATION / "report.md").read_bytes()).hexdigest()
    report = tmp_path / "report.md"
    rc = _mutate().main(
        [
            "--module",
            "core/projector/clipping.py",
            "--only",
            "core/projector/clipping.py:1:1:nosuch",
            "--report",
            str(report),
        ]
    )
    err = capsys.readouterr().err
    assert rc == 2 and err == (
        "mutate: error: --only 'core/projector/clipping.py:1:1:nosuch': no mutant of core/projector/clipping.py "
        "has this id: expected one that --list prints (MODULE:LINE:COL:CHANGE)\n"
    )
    assert not report.exists()
    assert hashlib.sha256((MUTATION / "report.md").read_bytes()).hexdigest() == committed


def test_only_with_known_ids_still_chooses_them(capsys):
    """The check above refuses only what matches nothing: an id --list prints is chosen (listed, not run)."""
    mutate = _mutate()
    first = mutate.sites("core/projector/clipping.py")[0].id
    rc = mutate.main(["--module", "core/projector/clipping.py", "--only", first, "--list"])
    assert rc == 0 and capsys.readouterr().out.splitlines()[-1] == first


def test_a_sample_of_zero_is_exit_2(tmp_path, capsys):
    rc = _mutate().main(["--module", "core/projector/clipping.py", "--sample", "0", "--report", str(tmp_path / "r.md")])
    assert rc == 2 and "no mutant chosen" in capsys.readouterr().err and not (tmp_path / "r.md").exists()


def test_the_mutant_ids_in_the_docs_name_mutants_that_exist():
    # docs/testing.md shows `mutate.py --only 'ID'`; ids move with the code (module:line:column:change),
    # and an id matching nothing is an error: each one shown must be a site of today's code
    import re

    shown = re.findall(r"--only '([^']+)'", (MUTATION.parent.parent / "docs" / "testing.md").read_text())
    assert shown  # the page was read
    mutate = _mutate()
    for mutant in shown:
        module = mutant.split(":")[0]
        assert mutant in {s.id for s in mutate.sites(module)}, mutant


def test_every_target_names_a_module_and_tests_that_exist():
    # a mutant run against a test path or node id that no longer exists would be "killed" by pytest's
    # collection error (exit 4), not by a test: every module, test file and ``file::test`` must exist
    root = MUTATION.parent.parent
    for module, (tests, _k) in _mutate().TARGETS.items():
        assert (root / module).is_file(), module
        for entry in tests:
            path, _, name = entry.partition("::")
            assert (root / path).is_file(), (module, entry)
            base, _, param = name.partition("[")
            assert not name or f"def {base}(" in (root / path).read_text(), (module, entry)
            if param:  # a parametrised node id: the parameter's id must be collected too
                import subprocess
                import sys

                collected = subprocess.run(
                    [sys.executable, "-m", "pytest", "--collect-only", "-q", "-p", "no:cacheprovider", entry],
                    cwd=root,
                    capture_output=True,
                    text=True,
                    timeout=300,
                )
                assert collected.returncode == 0, (module, entry, collected.stdout[-500:])
