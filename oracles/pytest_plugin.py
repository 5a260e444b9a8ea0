"""The pytest plugin (entry point ``pytest11``): check a projector in a project's own tests.

::

    def test_my_projector(wirecheck):
        wirecheck(my_project)      # my_project(p_world (N, 3), camera) -> p_px (N, 2)

The ``wirecheck`` fixture is callable (:class:`Check`): ``wirecheck(projector=None, **settings)``
runs :func:`wirecheck.oracles.api.check_projector` and returns its report
dict; when a case fails, the test fails with the diagnosis (faults, reasons,
what to check) and a traceback that ends at the test's own line: the
harness's frames are hidden (``__tracebackhide__``). ``projector`` is a
callable or a ``"FILE.py:FUNC"`` string, or ``cmd="PROGRAM ARGS"`` a program
(docs/protocol.md); without either, the ``candidate`` or ``candidate-cmd`` of
``[tool.wirecheck]``.

Settings, the first given wins: the call's keywords (those of
``check_projector``), the command line (``--wirecheck-frames N``,
``--wirecheck-level vertices|pixels``), ``[tool.wirecheck]`` in the
nearest ``pyproject.toml`` at or above pytest's rootdir, or
``--wirecheck-config FILE`` (oracles.config), then ``check_projector``'s
defaults. A bad table is a pytest usage error before any test runs.

``--wirecheck-report DIR`` writes report.json, report.md and report.html
(oracles.reports.report, with crosscheck's pictures: worst_points.png at level vertices, the
worst frames and worst.gif at level pixels) of every failing check to ``DIR/<test id>`` (``-2``, ``-3``
for a test's later checks); the terminal summary counts them, under
pytest-xdist too (each test's ``user_properties`` carries its folder as
``wirecheck_report``, which pytest's ``--junitxml`` also lists).

Nothing heavy is imported until the fixture is called: the plugin loads in
every pytest run of an environment where wirecheck is installed.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from wirecheck.core.errors import InputError

_SETTINGS = pytest.StashKey[dict]()
_CANDIDATE = pytest.StashKey[object]()
_CMD = pytest.StashKey[object]()


def pytest_addoption(parser):
    group = parser.getgroup("wirecheck", "wirecheck: crosscheck a projector (the wirecheck fixture)")
    group.addoption(
        "--wirecheck-report",
        metavar="DIR",
        default=None,
        help="write the report (report.json, report.md, report.html) of every failing wirecheck "
        "check to DIR/<test id> (default: no reports)",
    )
    group.addoption(
        "--wirecheck-frames",
        metavar="N",
        type=int,
        default=None,
        help="frames per case, over [tool.wirecheck] frames (default: the table's, else 8)",
    )
    group.addoption(
        "--wirecheck-level",
        choices=("vertices", "pixels"),
        default=None,
        help="vertices: OpenCV only; pixels: OpenCV and pyrender (default: the table's, else vertices)",
    )
    group.addoption(
        "--wirecheck-config",
        metavar="FILE",
        default=None,
        help="read [tool.wirecheck] from FILE (default: the nearest pyproject.toml at or above the rootdir)",
    )


def pytest_configure(config):
    from .config import load_config

    opt = config.option
    try:
        explicit = getattr(opt, "wirecheck_config", None)
        table = load_config(Path(explicit) if explicit else None, start=config.rootpath)
        settings = table.api_kwargs()
        if opt.wirecheck_frames is not None:
            if opt.wirecheck_frames < 1:
                raise InputError(f"--wirecheck-frames {opt.wirecheck_frames}: expected an integer >= 1")
            settings["frames"] = opt.wirecheck_frames
        if opt.wirecheck_level is not None:
            settings["oracles"] = ("opencv",) if opt.wirecheck_level == "vertices" else ("opencv", "pyrender")
        report = opt.wirecheck_report
        if report is not None and (Path(report).exists() and not Path(report).is_dir()):
            raise InputError(f"--wirecheck-report {report!r} is not a directory: expected a folder for the reports")
    except InputError as exc:
        raise pytest.UsageError(f"wirecheck: {exc}") from None
    config.stash[_SETTINGS] = settings
    config.stash[_CANDIDATE] = table.values.get("candidate")
    config.stash[_CMD] = table.values.get("candidate-cmd")


def report_name(nodeid: str) -> str:
    """A folder name for a test id: its letters, digits, ``_``, ``.`` and ``-`` (any run of other
    characters made ``_``, at most 120 characters kept), then ``-`` and the first 8 hex digits of the
    SHA-1 of the whole id.

    The hash makes the name one-to-one with the id, whatever characters two ids differ in
    (``test[a/b]``, ``test[a::b]``, ``test[a]b]`` and ``test[a b]`` are all ``test_a_b`` before it),
    keeps it under a file name's 255 bytes, and never ends like a later check's ``-2``.
    """
    import hashlib

    name = re.sub(r"[^A-Za-z0-9_.-]+", "_", nodeid).strip("._-")[:120] or "test"
    return name + "-" + hashlib.sha1(nodeid.encode("utf-8", "surrogatepass")).hexdigest()[:8]


def _write(config, node, index: int, report: dict, images: dict) -> str:
    """Write the report of a failing check, with its pictures (``images`` from
    :func:`wirecheck.oracles.api.run_check`: the worst frames, or worst_points.png at level
    vertices, as crosscheck's own reports); the line to add to the failure message.

    The folder is also the test's ``user_properties`` entry ``wirecheck_report``:
    it reaches the terminal summary from pytest-xdist workers, and pytest's own
    ``--junitxml`` as a property of the test.
    """
    nodeid = node.nodeid
    from .reports.report import write_report

    root = Path(config.option.wirecheck_report)
    run_dir = root / (report_name(nodeid) + (f"-{index}" if index > 1 else ""))
    try:
        root.mkdir(parents=True, exist_ok=True)
        write_report(run_dir, report, images)
    except (InputError, OSError) as exc:
        return f"  report not written: {exc}"
    node.user_properties.append(("wirecheck_report", str(run_dir)))
    return f"  report: {run_dir / 'report.html'}"


class Check:
    """The ``wirecheck`` fixture's value: ``check(projector=None, **settings) -> report``.

    Crosschecks ``projector`` and fails the test with the diagnosis when a case
    fails. ``settings`` are keywords of
    :func:`wirecheck.oracles.api.check_projector` (scenes, cases, frames,
    oracles, tol_px, min_f1, min_f1_0px, turns, precision, report_dir); they win over the
    ``--wirecheck-*`` options and ``[tool.wirecheck]``.
    """

    def __init__(self, config, node):
        self._config = config
        self._node = node
        self._nodeid = node.nodeid
        self._calls = 0

    def __repr__(self) -> str:
        return f"<wirecheck fixture of {self._nodeid}>"

    def __call__(self, projector=None, **settings) -> dict:
        __tracebackhide__ = True
        from .api import failure_text, run_check

        config = self._config
        projector = projector if projector is not None else config.stash[_CANDIDATE]
        if projector is None and "cmd" not in settings and config.stash[_CMD] is not None:
            settings = {"cmd": config.stash[_CMD], **settings}  # the table's program
        if projector is None and "cmd" not in settings:
            pytest.fail(
                'wirecheck(): no projector: expected wirecheck(func) or candidate = "FILE.py:FUNC" in [tool.wirecheck]',
                pytrace=False,
            )
        self._calls += 1
        error, trace = None, True
        try:
            from .api import checked_report_dir

            settings = dict(settings)
            run_dir = checked_report_dir(settings.pop("report_dir", None))  # check_projector's: written pass or fail
            # the table was read at start-up (rootdir or --wirecheck-config): not again from the cwd
            report, images = run_check(projector, **{"config": False, **config.stash[_SETTINGS], **settings})
            if run_dir is not None:
                from .reports.report import write_report

                write_report(run_dir, report, images)
        except (ValueError, TypeError) as exc:  # InputError is a ValueError: a bad setting or projector spec
            error = f"wirecheck: {type(exc).__name__}: {exc}"
        except RuntimeError as exc:
            from .references.pyrender_oracle import GLUnavailable

            if not isinstance(exc, GLUnavailable):
                raise
            error, trace = f"wirecheck: {exc}", False  # the missing GL library and its fix: one line
        if error is not None:  # outside the except: no chained harness traceback
            pytest.fail(error, pytrace=trace)
        text = failure_text(report)
        if text is not None:
            if run_dir is not None:
                text += f"\n  report: {run_dir / 'report.html'}"
            if config.option.wirecheck_report is not None:
                text += "\n" + _write(config, self._node, self._calls, report, images)
            pytest.fail(text)
        return report


@pytest.fixture
def wirecheck(request) -> Check:
    """``wirecheck(projector=None, **settings) -> report``: crosscheck ``projector``, failing the test on a fault.

    See :class:`Check`.
    """
    return Check(request.config, request.node)


def pytest_terminal_summary(terminalreporter, exitstatus, config):
    # from the tests' reports, not this process's state: under pytest-xdist the checks ran in workers
    written = sorted(
        {
            value
            for reports in terminalreporter.stats.values()
            for r in reports
            for name, value in getattr(r, "user_properties", ())
            if name == "wirecheck_report"
        }
    )
    if written:
        terminalreporter.write_sep("-", "wirecheck")
        terminalreporter.write_line(
            f"{len(written)} report(s) of failing checks under {config.option.wirecheck_report}"
        )
