"""Shared test hooks: sections appended to the terminal summary.

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
