"""Shared fixtures (pyrender on OSMesa) and hooks (sections appended to the terminal summary).

Helpers that are plain functions (running the CLIs, 8-connectivity) are in
tests/helpers.py.

A test asks for the ``summary_section`` fixture and calls it with a title and a
block of text; after the run, ``pytest_terminal_summary`` prints each block as
its own section, so it appears in the plain ``python -m pytest -q`` output (no
``-s`` or ``-rA`` needed). Used by tests/test_diagnosis.py for its confusion
matrix. The block travels in the test's report (``user_properties``), so it is
printed under pytest-xdist too, where tests run in worker processes.

Sharing expensive set-up (pyrender contexts, crosscheck runs) and keeping the
suite fast: docs/testing.md.
"""

from __future__ import annotations

import os
from collections import Counter

import pytest

# The suite runs as two xdist workers on two cores (the README's -n 2): OpenBLAS threads in
# every process it starts (workers, CLIs, candidate hosts, pools) only spin against the other
# worker. Set here, in the controller, before the workers start (they and their children
# inherit it); measured on this 2-core machine: 239 -> 197 s of CPU, 151 -> 122 s wall.
# Tests of the threads themselves start their interpreter without it
# (tests/test_renderer_imports.py). A value set outside is kept.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

# tests/data/docs_project is a user's project (docs/pytest.md's samples run pytest inside a copy
# of it, tests/docs_samples.py); its tests are not this suite's.
collect_ignore = ["data/docs_project"]

# pytester's in-process runs (tests/test_pytest_plugin.py) unload every module first imported
# inside them; numpy's C extensions cannot be loaded twice in one process, so numpy (and its
# numpy.fft, imported by the libraries a check loads) is loaded here, after the line above,
# before the first such run, whichever file runs first or alone.
import numpy.fft  # noqa: E402, F401

# tests/test_pytest_plugin.py runs a user's pytest on a small project
pytest_plugins = ["pytester"]

_SECTION = "wirecheck_summary_section"  # the user_properties key of a summary block
_SECTIONS: list[tuple[str, str]] = []  # gathered in the process that prints the summary


@pytest.fixture
def summary_section(request):
    """``summary_section(title, text)``: print ``text`` under ``title`` at the end of the run."""

    def add(title: str, text: str) -> None:
        request.node.user_properties.append((_SECTION, (title, text)))

    return add


def pytest_runtest_logreport(report):
    # called for every test's report in the main process (xdist forwards the workers' reports)
    if report.when == "call":
        _SECTIONS.extend(tuple(value) for key, value in report.user_properties if key == _SECTION)


def pytest_terminal_summary(terminalreporter, exitstatus, config):
    for title, text in _SECTIONS:
        terminalreporter.write_sep("-", title)
        for line in text.splitlines():
            terminalreporter.write_line(line)


@pytest.fixture(scope="session")
def pyrender_renderer():
    """A 640x480 ``pyrender.OffscreenRenderer`` on OSMesa, one per test process (skips the test where OSMesa is missing).

    Shared by every test that asks: render into a ``pyrender.Scene`` of your own
    and leave the renderer as you found it (no ``delete``, no viewport change).
    """
    from wirecheck.oracles.references.pyrender_oracle import osmesa_available

    ok, msg = osmesa_available()
    if not ok:
        pytest.skip(msg)
    import pyrender

    r = pyrender.OffscreenRenderer(640, 480)
    yield r
    r.delete()


@pytest.fixture(scope="session")
def oracle():
    """A 640x480 :class:`PyrenderOracle`, one per test process (skips the test where OSMesa is missing).

    Shared by every test that asks (it keeps no state between calls that a
    later call does not set again); do not close it.
    """
    from wirecheck.oracles.references.pyrender_oracle import PyrenderOracle, osmesa_available

    ok, msg = osmesa_available()
    if not ok:
        pytest.skip(msg)
    with PyrenderOracle(640, 480) as o:
        yield o


def pytest_collection_modifyitems(config, items):
    """Test files holding ``slow`` tests run first, the most slow tests first (stable order otherwise).

    With ``-n 2 --dist loadfile`` each file runs whole on one worker, and
    xdist hands out files in this order (pyproject's ``--no-loadscope-reorder``
    keeps xdist from reordering by test count instead): starting the longest
    files first and ending on short ones keeps one worker from being left alone
    with a long file while the other is idle. The count of slow tests is the
    cost estimate (tests/test_image_diagnosis.py, all slow, the longest, first).
    """
    slow = Counter(item.path for item in items if item.get_closest_marker("slow"))
    items.sort(key=lambda item: -slow[item.path])
