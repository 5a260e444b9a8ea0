"""A renderer's own frames judged from Python: the twins of :func:`~wirecheck.oracles.api.check_projector`.

    import wirecheck

    def test_my_renderer_draws_the_job():
        wirecheck.assert_frames("build/job")    # AssertionError naming the fault if not

The job is a folder written by ``crosscheck export`` with the renderer's PNGs under ``frames/``
(docs/frames.md). The judge is ``crosscheck --candidate-frames DIR``'s own
(:func:`wirecheck.oracles.judge.frames_judge.run_frames`), with its checks of the job
and of the report folder (:func:`wirecheck.oracles.frames_cli.check_report_outside_job`), so the
report is the one the command line writes.
"""

from __future__ import annotations

from wirecheck.core.errors import InputError
from wirecheck.core.outputs.output import check_report_dir, claim, release_claim

from . import tolerances
from .api import checked_report_dir, raise_unless_pass, short_repr
from .call_args import checked_flag
from .candidates.caller_state import caller_state_kept
from .config import settings_for
from .frames_cli import check_report_outside_job
from .judge import gate
from .judge.line_style import LINE_RULES
from .references.pyrender_oracle import GLUnavailable, gl_available
from .reports.report import write_report

#: check_frames' F1 floors when neither the call nor ``[tool.wirecheck]`` gives them: crosscheck's.
FRAMES_DEFAULTS = {"min_f1": tolerances.MIN_F1_1PX, "min_f1_0px": tolerances.MIN_F1_0PX}


def check_frames(
    job_dir,
    *,
    line_rule: str = "any",
    min_f1: float | None = None,
    min_f1_0px: float | None = None,
    allow_vacuous: bool = False,
    report_dir=None,
    config=None,
) -> dict:
    """Judge the frames a renderer drew for a job against pyrender and core; return the report.

    Parameters
    ----------
    job_dir : str or Path
        A job folder written by ``crosscheck export`` (or
        ``wirecheck.oracles.candidates.export.write_job``), its ``frames/`` drawn.
    line_rule : {"any", "gl", "geometry"}
        ``"any"`` (default) holds aliased 1-px lines to a correct drawing by GL's rule or by the
        rule that rounds the ends to pixel centres (Bresenham, Pillow, ``cv2.line``); ``"gl"`` to
        GL's pixel rule alone (F1@0px); ``"geometry"`` judges where the lines are only
        (``crosscheck --line-rule``).
    min_f1, min_f1_0px : float, optional
        F1 floors at 1 px and 0 px, in [0, 1] (default: those of docs/tolerances.md, as crosscheck's).
    allow_vacuous : bool
        Let a case where neither side drew a pixel pass; by default it fails the report.
    report_dir : str or Path, optional
        Write report.json, report.md and report.html there with their pictures, the bytes
        ``crosscheck --candidate-frames DIR --report-dir REPORT_DIR`` writes (timing aside).
        Default None: nothing is written.
    config : str, Path or False, optional
        The file whose ``[tool.wirecheck]`` fills ``min_f1`` and ``min_f1_0px`` where not given (its
        ``min-f1``, ``min-f1-0px``; default: the nearest ``pyproject.toml`` at or above the working
        directory, as :func:`~wirecheck.oracles.api.check_projector` and ``crosscheck`` read it); False: no file.

    Returns
    -------
    dict
        The report, as written to report.json: ``verdict``, ``cases`` (each with its ``verdict``,
        ``faults`` and ``reasons``), ``compared``, ``summary``.

    Raises
    ------
    ValueError
        (:class:`~wirecheck.core.errors.InputError`) the line crosscheck prints for the same input:
        no job there, a frame missing, of the wrong size or not the job's; a ``line_rule`` other
        than gl or geometry; an F1 floor that is NaN or outside [0, 1]; a ``report_dir`` that is a
        file, the job itself or its ``frames/``, or a folder with files wirecheck did not write.
    TypeError
        ``allow_vacuous`` not a bool, ``report_dir`` not a path, ``job_dir`` not a path.
    RuntimeError
        (:class:`~wirecheck.oracles.references.pyrender_oracle.GLUnavailable`) pyrender's GL
        cannot draw here: one line naming the missing library and its fix.
    """
    import os
    from pathlib import Path

    if isinstance(job_dir, bool) or not isinstance(job_dir, (str, os.PathLike)):
        raise TypeError(f"job_dir {short_repr(job_dir)}: expected a job folder path (str or Path)")
    job_dir = Path(job_dir)
    checked_flag(allow_vacuous, "allow_vacuous")
    if line_rule not in LINE_RULES:
        raise InputError(
            f"line_rule {line_rule!r}: expected one of {', '.join(LINE_RULES)} (any: aliased 1-px "
            "lines held to GL's rule or the rounded ends'; gl: to GL's pixel rule; geometry: where "
            "the lines are only)"
        )
    settings = settings_for(
        {"min_f1": min_f1, "min_f1_0px": min_f1_0px}, config, FRAMES_DEFAULTS
    )  # [tool.wirecheck] beneath
    tol = tolerances.Tolerances(min_f1_1px=settings["min_f1"], min_f1_0px=settings["min_f1_0px"])
    gate.check_tolerances(tol)  # a NaN floor would pass everything
    run_dir = checked_report_dir(report_dir)
    if run_dir is not None:  # before anything is judged, as crosscheck checks it
        check_report_dir(run_dir, "report_dir")
        claim(run_dir, "report_dir")  # held until the report is in place: one run per folder
        try:
            check_report_outside_job(job_dir, run_dir)
        except BaseException:
            release_claim(run_dir)
            raise
    try:
        report, images = _judge(job_dir, tol, allow_vacuous, line_rule)
        if run_dir is not None:
            write_report(run_dir, report, images)
    finally:
        if run_dir is not None:
            release_claim(run_dir)
    return report


def _judge(job_dir, tol, allow_vacuous: bool, line_rule: str) -> tuple[dict, dict]:
    """crosscheck's frames judge on ``job_dir``, after the check that pyrender's GL can draw here."""
    from .judge.frames_judge import run_frames

    with caller_state_kept():  # the caller's globals as they were (PYOPENGL_PLATFORM, ...)
        ok, message = gl_available()
        if not ok:
            raise GLUnavailable(message)
        return run_frames(job_dir, tol=tol, allow_vacuous=allow_vacuous, line_rule=line_rule)


def assert_frames(job_dir, **kwargs) -> dict:
    """:func:`check_frames`, raising AssertionError with the diagnosis unless the verdict is pass.

    Parameters
    ----------
    job_dir : str or Path
        The job folder, its frames drawn.
    **kwargs
        Any keyword of :func:`check_frames`.

    Returns
    -------
    dict
        The report, when every case passed.

    Raises
    ------
    AssertionError
        Naming each failing case, its faults and reasons, and what to check
        (:func:`wirecheck.oracles.api.failure_text`); with ``report_dir``, the report's path last.
    """
    __tracebackhide__ = True  # pytest: the failure points at the caller's line
    return raise_unless_pass(check_frames(job_dir, **kwargs), kwargs.get("report_dir"))
