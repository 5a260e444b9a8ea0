"""The top-level API: every exported name imports, is documented with numpydoc sections, and its examples run."""

import doctest
import inspect

import pytest
import wirecheck
from wirecheck.core import camera
from wirecheck.core.projector import projection

EXPORTED = [n for n in wirecheck.__all__ if n != "__version__"]


def test_the_names_a_user_guesses_are_exported():
    guessed = {"check_projector", "assert_projector", "Camera", "look_at", "load_scene", "render_frame"}
    assert guessed <= set(EXPORTED)
    assert {n for n in EXPORTED if not hasattr(wirecheck, n)} == set()


@pytest.mark.parametrize("name", EXPORTED)
def test_exported_names_have_numpydoc_sections(name):
    obj = getattr(wirecheck, name)
    if name == "InputError":
        assert inspect.getdoc(obj)
        return
    doc = inspect.getdoc(obj) or ""
    # numpydoc: Parameters for what a user calls or builds, Attributes for a returned record
    assert "Parameters\n----------" in doc or (inspect.isclass(obj) and "Attributes\n----------" in doc), name
    if inspect.isfunction(obj):
        assert "Returns\n-------" in doc, name


@pytest.mark.parametrize("module", [camera, projection], ids=lambda m: m.__name__)
def test_docstring_examples_run(module):
    result = doctest.testmod(module)
    assert result.attempted > 0 and result.failed == 0  # attempted: a module without examples fails


def test_version_is_the_installed_distributions():
    from importlib.metadata import version

    assert wirecheck.__version__ == version("wirecheck")


@pytest.mark.parametrize("main_module", ["wirecheck.core.app.cli", "wirecheck.oracles.cli"])
def test_version_option(main_module, capsys):
    from importlib import import_module
    from importlib.metadata import version

    with pytest.raises(SystemExit) as exc:
        import_module(main_module).main(["--version"])
    assert exc.value.code == 0
    assert capsys.readouterr().out.strip().endswith(f"(wirecheck) {version('wirecheck')}")


def test_every_crosscheck_option_has_help_with_its_default_and_no_markup():
    from helpers import assert_help_states_defaults
    from wirecheck.oracles.cli import build_parser

    assert_help_states_defaults(build_parser())
