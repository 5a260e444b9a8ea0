"""Shared fixtures (pyrender on OSMesa) and hooks (sections appended to the terminal summary).

Helpers that are plain functions (running the CLIs, 8-connectivity) are in
tests/helpers.py.

A test asks for the ``summary_section`` fixture and calls it with a title and a
block of text; after the run, ``pytest_terminal_summary`` prints each block as
its own section, so it appears in the plain ``python -m pytest -q`` output (no
``-s`` or ``-rA`` needed). Used by tests/test_diagnosis.py for its confusion
matrix.
"""

from __future__ import annotations

import pytest

# tests/test_pytest_plugin.py runs a user's pytest on a small project
pytest_plugins = ["pytester"]

_SECTIONS = pytest.StashKey[list]()


@pytest.fixture
def summary_section(request):
    """``summary_section(title, text)``: print ``text`` under ``title`` at the end of the run."""
    sections = request.config.stash.setdefault(_SECTIONS, [])

    def add(title: str, text: str) -> None:
        sections.append((title, text))

    return add


def pytest_terminal_summary(terminalreporter, exitstatus, config):
    for title, text in config.stash.get(_SECTIONS, []):
        terminalreporter.write_sep("-", title)
        for line in text.splitlines():
            terminalreporter.write_line(line)


@pytest.fixture(scope="module")
def pyrender_renderer():
    """A 640x480 ``pyrender.OffscreenRenderer`` on OSMesa (skips the test where OSMesa is missing)."""
    from wirecheck.oracles.pyrender_oracle import osmesa_available

    ok, msg = osmesa_available()
    if not ok:
        pytest.skip(msg)
    import pyrender

    r = pyrender.OffscreenRenderer(640, 480)
    yield r
    r.delete()


@pytest.fixture(scope="module")
def oracle():
    """A 640x480 :class:`PyrenderOracle` (skips the test where OSMesa is missing)."""
    from wirecheck.oracles.pyrender_oracle import PyrenderOracle, osmesa_available

    ok, msg = osmesa_available()
    if not ok:
        pytest.skip(msg)
    with PyrenderOracle(640, 480) as o:
        yield o
