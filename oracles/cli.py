"""``crosscheck``: judge a projector against OpenCV and pyrender (OSMesa or EGL).

Exit status: 0 when every case is within tolerance, 1 when any case fails or
compared nothing (``vacuous``, unless ``--allow-vacuous``), 2 on usage or input
errors (including libOSMesa missing when pyrender is asked for, and inputs that
would compare nothing: oracles/judge/gate.py).

The candidate is core (in this process, trusted) unless ``--candidate
FILE.py:FUNC`` or ``--candidate-cmd 'COMMAND ARGS'`` (a program in any
language) is given: those run in their own process and are spoken to over
the candidate protocol (docs/protocol.md, oracles/candidates/isolation.py),
each request under ``--candidate-timeout`` seconds, so a candidate that
exits, hangs or crashes fails its cases (exit 1) and never ends the run.
``--candidate-precision float32|float64`` says what it computes in (default:
the dtype it returns; core: ``--dtype``): a float32 candidate's vertices are
held to a bound derived from float32 rounding (oracles/tolerances.py).

``--level vertices`` runs the OpenCV vertex check only (no drawing, no
pyrender); ``--level pixels`` (the default) adds the pyrender pixel check.
``--oracles opencv`` / ``--oracles opencv,pyrender`` is the older spelling of
the same two levels. ``--every K`` checks frames 1, 1+K, ... of the motion;
``--jobs N`` runs the cases in N worker processes (same report as one).

Drawing modes of the core candidate (level pixels): ``--hidden-lines``
(faces hide the lines behind them; pyrender draws them black with a polygon
offset under the lines), ``--cull backface`` (back faces culled, and their
edges when no front face owns them; checked against the oracle's own
front-face test and GL culling) and ``--style shaded`` (core's depth buffer
against pyrender's filled faces: silhouette IoU and depth error within a
derived bound, oracles/tolerances.py). A scene without faces is then compared
as a plain wireframe, or (shaded) checked for its vertices only, with a note.
They need the core candidate and the pixel level: with ``--candidate``,
``--level vertices``, ``--sweep`` or ``--suite``, and ``--hidden-lines`` with
``--style shaded`` (a shaded frame has no lines), they are usage errors.

The report directory also gets ``worst.gif`` (every checked frame of the
worst case: candidate | oracle | diff), ``vertex_error.png`` and
``pixels.png`` (per-frame plots of every case).

``--scene DIR`` (a folder of mesh files) and ``--scene-list FILE`` run a
dataset: one task per mesh, a mesh that cannot be loaded counted and reported
(it fails the run unless ``--allow-load-errors``), one summary
(oracles/datasets/dataset_run.py, docs/datasets.md). ``--executor dask`` runs the
cases or meshes on a Dask cluster: a local one of ``--jobs`` workers, or
``--scheduler tcp://HOST:PORT``'s (oracles/executors.py); same report.

``crosscheck export DIR`` writes a rendering job for any renderer, and
``--candidate-frames DIR`` judges the renderer's own frames of it
(oracles/frames_cli.py, docs/frames.md).

``--sweep`` runs every core setting (dtype x clip x raster) on the scenes and
a large mesh and writes a table and a Pareto plot (oracles/sweep.py); it
exits 1 only when the default setting is out of tolerance. ``--suite
extremes`` runs the numerical-extremes suite (oracles/extremes/) and exits
1 when any case exceeds its derived bound.
"""

from __future__ import annotations

from wirecheck.core.app.startup import interrupts_from_start

interrupts_from_start("crosscheck")  # first: Ctrl-C while the imports below run is one line, no traceback

import math  # noqa: E402
import re
import sys
from concurrent.futures.process import BrokenProcessPool
from datetime import datetime, timezone
from pathlib import Path

from wirecheck.core.app.guard import run_cli  # noqa: E402
from wirecheck.core.errors import InputError, check_not_empty  # noqa: E402
from wirecheck.core.limits import check_candidate_timeout
from wirecheck.core.outputs.output import FrameDir, check_report_dir, claim, json_dumps, release_claims
from wirecheck.core.scene.files import builtin_names, example_names

from . import tolerances
from .candidates.core_candidate import CoreCandidate, RenderMode
from .candidates.isolation import check_python_spec, external_candidate
from .candidates.subprocess_candidate import closing_started
from .cases import CASE_NAMES
from .cli_options import MAX_JOBS, MAX_SCHEDULER_TIMEOUT_S, build_parser  # noqa: F401 (build_parser: the CLI's parser)
from .config import parse_cli, trust_line
from .datasets.memory_budget import gib_bytes
from .executors import DEFAULT_CONNECT_TIMEOUT_S, ExecutorSpec, check_scheduler_address, dask_failure
from .judge import gate
from .reports.console_run import finish_run
from .reports.junit import check_junit_target
from .reports.progress import TerminalProgress
from .reports.report_option import check_no_report, report_line
from .runner import level_for_oracles, run_crosscheck
from .spec import run_spec, spec_console, spec_markdown
from .tolerances import Tolerances

ORACLES = ("opencv", "pyrender")
#: Options that configure the core candidate, with their defaults.
CORE_OPTIONS = {"dtype": "float64", "clip": "clip", "raster": "exact"}


def _parse(args):
    if args.frames is None:
        args.frames = 12 if args.sweep else 24
    if args.jobs < 1:
        raise InputError(f"--jobs {args.jobs}: expected an integer >= 1")
    if args.jobs > MAX_JOBS:
        raise InputError(f"--jobs {args.jobs}: expected at most {MAX_JOBS} worker processes")
    args.executor_spec = _executor(args)
    args.dataset = _dataset(args)
    level = args.level or "pixels"
    if args.oracles is not None:
        oracles = [o.strip() for o in args.oracles.split(",") if o.strip()]
        if not oracles or any(o not in ORACLES for o in oracles):
            raise InputError(f"--oracles {args.oracles!r}: expected a comma-separated list of {', '.join(ORACLES)}")
        if "opencv" not in oracles:
            raise InputError(f"--oracles {args.oracles!r}: expected opencv among them (vertices are always checked)")
        implied = level_for_oracles(oracles)
        if args.level is not None and args.level != implied:
            raise InputError(
                f"--oracles {args.oracles!r} means --level {implied}, which contradicts "
                f"--level {args.level}: give only --level"
            )
        level = implied
    core_given = [f"--{k}" for k in CORE_OPTIONS if getattr(args, k) is not None]
    external = _external_option(args)
    if args.suite:
        ignored = [
            opt
            for opt, given in (
                ("--scene", args.scene is not None),
                ("--frames", args.frames != 24),
                ("--every", args.every != 1),
                ("--cases", args.cases != ",".join(CASE_NAMES)),
                ("--spin", args.spin != "1,1,0"),
                ("--jobs", args.jobs != 1),
                ("--tol-px", args.tol_px != tolerances.VERTEX_TOL_PX),
                ("--min-f1", args.min_f1 != tolerances.MIN_F1_1PX),
                ("--min-f1-0px", args.min_f1_0px != tolerances.MIN_F1_0PX),
                ("--min-iou", args.min_iou != tolerances.MIN_SILHOUETTE_IOU),
                ("--candidate-precision", args.candidate_precision is not None and args.suite != "spec"),
                ("--allow-vacuous", args.allow_vacuous),
            )
            if given
        ]
        if ignored:
            allowed = (
                "--level, --gl, --run, --report-dir, --candidate, --candidate-cmd or --candidate-precision"
                if args.suite == "spec"
                else "--level, --run or --report-dir"
            )
            raise InputError(
                f"--suite {args.suite} with {', '.join(ignored)}: the suite's cases, frames and "
                f"bounds are fixed (oracles/{args.suite}/); expected only {allowed}"
            )
        if args.suite == "spec" and args.candidate_precision is not None and not external:
            raise InputError(
                f"--suite spec with --candidate-precision {args.candidate_precision} and no --candidate: "
                "core says its own precision: expected --candidate or --candidate-cmd with it"
            )
        if args.suite == "spec" and core_given:
            raise InputError(
                f"--suite spec with {', '.join(core_given)}: the suite judges core in its default "
                "settings, or --candidate/--candidate-cmd: expected no --dtype/--clip/--raster"
            )
    if args.sweep and args.allow_vacuous:
        raise InputError(
            "--sweep with --allow-vacuous: the sweep's cases are the bundled scenes and a large mesh, "
            "which always show something: expected no --allow-vacuous"
        )
    if args.sweep and args.jobs != 1:
        raise InputError(
            f"--sweep with --jobs {args.jobs}: the sweep times every setting on one process so "
            "the times compare; expected no --jobs"
        )
    if (args.sweep or args.suite == "extremes") and (core_given or external):
        what = "--sweep" if args.sweep else f"--suite {args.suite}"
        raise InputError(
            f"{what} with {', '.join(core_given) or '--candidate'}: {what} runs core's settings "
            "itself; expected neither --candidate nor --dtype/--clip/--raster"
        )
    if args.sweep and args.candidate_precision is not None:
        raise InputError(
            f"--sweep with --candidate-precision {args.candidate_precision}: the sweep runs each core "
            "--dtype at its own precision: expected no --candidate-precision"
        )
    if external and core_given:
        raise InputError(
            f"{', '.join(core_given)}: settings of the core candidate, not of {external}: expected them without it"
        )
    mode_given = [
        opt
        for opt, given in (
            ("--style", args.style is not None),
            ("--hidden-lines", args.hidden_lines),
            ("--cull", args.cull is not None),
        )
        if given
    ]
    if mode_given:
        what = ", ".join(mode_given)
        if args.sweep or args.suite:
            raise InputError(
                f"{what} with {'--sweep' if args.sweep else '--suite ' + args.suite}: expected "
                "the drawing options in a plain crosscheck run only"
            )
        if external:
            raise InputError(
                f"{what}: drawing modes of the core candidate; {external} only "
                "projects points: expected them without it"
            )
        if level != "pixels":
            raise InputError(
                f"{what} with --level {level}: faces are drawn and compared at the pixel level "
                "only: expected --level pixels (the default)"
            )
        if args.style == "shaded" and args.hidden_lines:
            raise InputError("--hidden-lines with --style shaded: a shaded frame has no lines: expected one of them")
    mode = RenderMode(style=args.style or "wireframe", hidden_lines=args.hidden_lines, cull=args.cull or "none")
    tol = Tolerances(
        vertex_px=args.tol_px,
        min_f1_1px=args.min_f1,
        min_f1_0px=args.min_f1_0px,
        min_iou=args.min_iou,
        precision=args.candidate_precision,
    )
    if args.suite == "extremes":  # fixed cases and bounds (checked above): nothing of a run's inputs applies
        return level, None, None, mode, tol
    if args.suite == "spec":  # fixed runs and checks; the candidate is core or the one given
        return level, None, _candidate(args, external), mode, tol
    # the library's one check of what a run compares (oracles.judge.gate), in the CLI's option names
    if args.dataset is not None:  # the meshes are read where they are checked (oracles.datasets.dataset_run)
        inputs = gate.run_settings(args.frames, args.every, args.cases, args.spin, tol, names=gate.CLI_NAMES)
    else:
        inputs = gate.run_inputs(args.scene, args.frames, args.every, args.cases, args.spin, tol, names=gate.CLI_NAMES)
    for scene in inputs.scenes:  # read leniently (core.scene.files): one line each, the run goes on
        for note in scene.load_notes:
            print(f"crosscheck: warning: {note}", file=sys.stderr)
    if mode.cull == "backface":
        wound = next((sc for sc in inputs.scenes if sc.faces and sc.winding_note), None)
        if wound is not None:  # as renderer: culling needs one winding; both sides would share the error
            raise InputError(
                f"--cull backface: {wound.source}: {wound.winding_note}: expected faces wound "
                "consistently (counter-clockwise seen from outside)"
            )
    return level, inputs, _candidate(args, external), mode, tol


def _candidate(args, external: str | None):
    """The run's candidate: the program of ``--candidate``/``--candidate-cmd``, started, or core in its settings."""
    if external:
        if getattr(args, "candidate_from", None) is not None:  # before the program runs (docs/pytest.md)
            if args.candidate is not None:
                check_python_spec(args.candidate)  # a file that is refused runs nothing: no line saying it runs
            print(trust_line(*args.candidate_from), file=sys.stderr, flush=True)
        return external_candidate(args.candidate, args.candidate_cmd, args.candidate_timeout)
    return CoreCandidate(**{k: getattr(args, k) or v for k, v in CORE_OPTIONS.items()})


def _executor(args) -> ExecutorSpec:
    """The executor of ``--executor``, ``--jobs``, ``--scheduler``; InputError for a contradiction."""
    kind = args.executor or ("dask" if args.scheduler is not None else "local")
    if args.scheduler is not None:
        if kind != "dask":
            raise InputError(
                f"--scheduler {args.scheduler!r} with --executor {kind}: a scheduler is Dask's: "
                "expected --executor dask (or no --executor)"
            )
        if args.jobs != 1:
            raise InputError(
                f"--jobs {args.jobs} with --scheduler: the cluster's workers are those started with "
                "'dask worker': expected no --jobs"
            )
        check_scheduler_address(args.scheduler)
    if not (math.isfinite(args.scheduler_timeout) and 0 < args.scheduler_timeout <= MAX_SCHEDULER_TIMEOUT_S):
        raise InputError(
            f"--scheduler-timeout {args.scheduler_timeout:g}: expected a number of seconds > 0 and "
            f"<= {MAX_SCHEDULER_TIMEOUT_S:g}"
        )
    if args.scheduler is None and args.scheduler_timeout != DEFAULT_CONNECT_TIMEOUT_S:
        raise InputError(
            f"--scheduler-timeout {args.scheduler_timeout:g} without --scheduler: it bounds reaching "
            "a cluster's scheduler: expected --scheduler tcp://HOST:PORT"
        )
    if kind == "dask" and (args.sweep or args.suite or args.candidate_frames is not None):
        what = "--sweep" if args.sweep else f"--suite {args.suite}" if args.suite else "--candidate-frames"
        raise InputError(f"--executor dask with {what}: expected it in a plain crosscheck run or a dataset run")
    return ExecutorSpec(kind=kind, jobs=args.jobs, scheduler=args.scheduler, connect_timeout_s=args.scheduler_timeout)


def _dataset(args):
    """The dataset of ``--scene DIR`` / ``--scene-list FILE`` (oracles.datasets.dataset), or None for a plain run."""
    scenes = args.scene or []
    named = set(builtin_names() + example_names())  # a bundled name wins over a folder of that name
    folders = [s for s in scenes if s not in named and Path(s).is_dir()]
    if not folders and not args.scene_list:
        if args.allow_load_errors:
            raise InputError("--allow-load-errors without a dataset: expected --scene DIR or --scene-list FILE")
        if args.memory_budget is not None:
            raise InputError("--memory-budget without a dataset: expected --scene DIR or --scene-list FILE")
        return None
    if len(folders) != len(scenes):
        other = next(s for s in scenes if s not in folders)
        raise InputError(
            f"--scene {other!r} with a dataset (--scene DIR or --scene-list): expected only folders "
            "and lists (put single mesh files in a --scene-list)"
        )
    other = [
        opt
        for opt, given in (
            ("--sweep", args.sweep),
            ("--suite", args.suite),
            ("--candidate-frames", args.candidate_frames is not None),
            ("--junit-xml", args.junit_xml is not None),
        )
        if given
    ]
    if other:
        raise InputError(
            f"a dataset (--scene DIR or --scene-list) with {', '.join(other)}: expected a plain "
            "crosscheck run over the meshes"
        )
    from .datasets.dataset import dataset_entries  # --scene DIR / --scene-list only

    return dataset_entries(folders, args.scene_list or [])


def _run_dir(args) -> tuple[Path, str]:
    """The report folder: DIR/RUN, DIR alone, or reports/RUN; and the option to name in errors."""
    run = (
        args.run
        if args.run is not None
        else (None if args.report_dir else datetime.now(timezone.utc).strftime("%Y%m%d-%H%M%S"))
    )
    if run is not None and not re.fullmatch(r"[A-Za-z0-9_][A-Za-z0-9_.-]*", run):
        raise InputError(
            f"--run {run!r}: expected a name of letters, digits, '_', '.', '-' (no '/', not starting with '.')"
        )
    if args.report_dir:
        return (Path(args.report_dir) / run, "--run") if run is not None else (Path(args.report_dir), "--report-dir")
    return Path("reports") / run, "--run"


def _error(text: str) -> int:
    """Print ``crosscheck: error: text`` on stderr; the exit status of a usage error (2)."""
    print(f"crosscheck: error: {text}", file=sys.stderr)
    return 2


def _external_option(args) -> str | None:
    """``--candidate 'X'`` or ``--candidate-cmd 'X'`` as given (None: core); InputError for both or a bad timeout."""
    if args.candidate is not None and args.candidate_cmd is not None:
        raise InputError(
            f"--candidate {args.candidate!r} with --candidate-cmd {args.candidate_cmd!r}: expected one candidate"
        )
    check_candidate_timeout(args.candidate_timeout, "--candidate-timeout")
    if args.candidate is not None:  # '' too: an empty candidate is an error, never core
        return f"--candidate {args.candidate!r}"
    return f"--candidate-cmd {args.candidate_cmd!r}" if args.candidate_cmd is not None else None


def main(argv=None) -> int:
    with closing_started():  # the run's candidate program ends with the run
        try:
            return run_cli("crosscheck", _main, argv)  # one line on stderr whatever happens (core/app/guard.py)
        finally:
            release_claims()  # the report folder or job this run held from its start


def _main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    if argv[:1] == ["export"]:  # crosscheck export DIR: a job for image candidates
        from .frames_cli import export_main

        return export_main(argv[1:])
    try:
        args, config, applied = parse_cli(build_parser(), argv)
        args.candidate_from = next(
            ((config.path, key, config.values[key]) for key in ("candidate", "candidate-cmd") if key in applied), None
        )
        check_not_empty(
            (f"--{d.replace('_', '-')}", getattr(args, d))
            for d in ("scene", "scene_list", "candidate_frames", "report_dir", "junit_xml", "config")
        )
        if args.unprojector is not None or args.unprojector_cmd is not None:  # the way back: its own report
            from .unprojector_cli import unprojector_main

            check_no_report(args)
            return unprojector_main(args, *_run_dir(args))
        if args.junit_xml and (args.sweep or args.suite):
            raise InputError(
                f"--junit-xml with {'--sweep' if args.sweep else '--suite ' + args.suite}: "
                "expected it in a plain crosscheck run (one test case per scene x camera)"
            )
        if args.junit_xml:
            check_junit_target(Path(args.junit_xml))
        check_no_report(args)
        level, inputs, candidate, mode, tol = _parse(args)
        run_dir, run_option = _run_dir(args)
    except InputError as exc:
        return _error(str(exc))
    if applied:  # after the checks: on a usage error the error is the only line
        print(f"crosscheck: settings from {config.path} [tool.wirecheck]: {', '.join(applied)}", file=sys.stderr)
    if level == "pixels":
        from .references.pyrender_oracle import gl_available, select_gl  # GL chosen before PyOpenGL is imported

        try:
            select_gl(args.gl)
        except InputError as exc:
            return _error(str(exc))
        ok, message = gl_available()
        if not ok:
            return _error(f"{message} (or run with --level vertices)")
    elif args.gl is not None:
        return _error(f"--gl {args.gl} with --level {level}: nothing is drawn at that level; expected no --gl")
    try:
        if not args.no_report:
            check_report_dir(run_dir, run_option)
            claim(run_dir, run_option)  # held until the report is in place: one run per folder
    except InputError as exc:
        return _error(str(exc))
    except OSError as exc:
        return _error(f"--report-dir {str(run_dir)!r}: cannot write there ({exc}): expected a writable directory")

    if args.line_rule is not None and args.candidate_frames is None:
        return _error(
            f"--line-rule {args.line_rule} without --candidate-frames: a projector's lines are drawn by "
            "the harness (GL's rule); expected --line-rule only with --candidate-frames DIR"
        )
    if args.candidate_frames is not None:
        from .frames_cli import frames_main

        return frames_main(args, run_dir, from_config=set(applied))
    if getattr(args, "dataset", None) is not None:
        return _dataset_main(args, level, inputs, candidate, mode, tol, run_dir)
    if args.sweep:
        return _sweep(args, inputs, level, tol, run_dir)
    if args.suite == "spec":
        return _spec_suite(args, candidate, level, run_dir)
    if args.suite:
        return _suite(level, run_dir)
    for scene in inputs.scenes:  # a valid file with nothing in it: said once here, not only in the table
        if len(scene.vertices) == 0:
            print(
                f"crosscheck: {scene.source}: no vertices: every case of scene {scene.name!r} compares nothing "
                f"(vacuous: {'allowed by --allow-vacuous' if args.allow_vacuous else 'the run fails'})",
                file=sys.stderr,
            )
    progress = TerminalProgress(sys.stderr)
    # an external candidate runs in its own process already (oracles.candidates.isolation): no worker needed
    result, status = _run_guarded(
        args,
        progress,
        lambda: run_crosscheck(
            inputs.scenes,
            candidate,
            frames=inputs.frames,
            case_names=inputs.case_names,
            level=level,
            turns=inputs.turns,
            tol=tol,
            every=inputs.every,
            jobs=args.jobs,
            candidate_name=candidate.name,
            mode=mode,
            allow_vacuous=args.allow_vacuous,
            progress=progress.update if progress.active else None,
            executor=args.executor_spec,
        ),
    )
    if status is not None:
        return status
    report, images = result
    return finish_run(args, run_dir, {"run": args.run, **report}, images, tol)


def _run_guarded(args, progress, run):
    """``(run(), None)``, or ``(None, exit status)`` with its failure as one error line; closes ``progress``.

    A bad input, a dead worker process and (on Dask) a failed task or cluster
    are the user's to fix; anything else on the local executor is a bug and
    propagates (core.app.guard logs it).
    """
    try:
        return run(), None
    except InputError as exc:
        return None, _error(str(exc))
    except BrokenProcessPool as exc:
        return None, _error(f"a worker process died ({exc}); try --jobs 1")
    except Exception as exc:
        if args.executor_spec.kind != "dask":
            raise
        return None, _error(dask_failure(exc))
    finally:
        progress.close()


def _memory_budget(gib: float | None):
    """``--memory-budget GIB`` in bytes ("auto" when not given); InputError unless a number of GiB > 0."""
    if gib is None:
        return "auto"
    if not (math.isfinite(gib) and gib > 0):
        raise InputError(f"--memory-budget {gib:g}: expected a number of GiB > 0")
    return gib_bytes(gib)  # exact: 1e300 GiB is a budget too large to matter, not inf


def _dataset_main(args, level, inputs, candidate, mode, tol, run_dir) -> int:
    """A dataset run (oracles.datasets.dataset_run): progress, the report, the summary on stdout."""
    from .datasets.dataset_report import DatasetProgress, console_summary, write_dataset_report
    from .datasets.dataset_run import run_dataset

    progress = DatasetProgress(sys.stderr)
    report, status = _run_guarded(
        args,
        progress,
        lambda: run_dataset(
            args.dataset,
            candidate,
            frames=inputs.frames,
            case_names=inputs.case_names,
            turns=inputs.turns,
            tol=tol,
            level=level,
            every=inputs.every,
            mode=mode,
            candidate_name=candidate.name,
            allow_vacuous=args.allow_vacuous,
            allow_load_errors=args.allow_load_errors,
            executor=args.executor_spec,
            memory_budget=_memory_budget(args.memory_budget),
            progress=progress.update if progress.active else None,
        ),
    )
    if status is not None:
        return status
    if args.dataset.skipped_line() is not None:  # FIFOs, devices: never opened (oracles.datasets.dataset)
        print(f"crosscheck: {args.dataset.skipped_line()}", file=sys.stderr)
    report = {"run": args.run, **report}
    try:
        if not args.no_report:
            write_dataset_report(run_dir, report)
    except OSError as exc:
        return _error(f"writing {str(run_dir)!r} failed: {exc}")
    print(console_summary(report))
    print(report_line(args, run_dir, "report.json", "report.md"))
    return 0 if report["verdict"] == "pass" else 1


def _sweep(args, inputs, level, tol, run_dir) -> int:
    from .sweep import default_failures, large_mesh, markdown_table, run_sweep, write_sweep

    def progress(text):
        print(f"  {text}", file=sys.stderr, flush=True)

    print(
        f"Sweep: 12 settings x {len(inputs.scenes)} scenes + a large mesh x {len(inputs.case_names)} cameras, "
        f"{inputs.frames_checked} frames each",
        file=sys.stderr,
    )
    try:
        run_dir.parent.mkdir(parents=True, exist_ok=True)
        result = run_sweep(
            list(inputs.scenes),
            frames=inputs.frames,
            every=inputs.every,
            case_names=list(inputs.case_names),
            turns=inputs.turns,
            large=large_mesh(),
            pyrender=level == "pixels",
            progress=progress,
        )
        write_sweep(run_dir, result)
    except InputError as exc:
        return _error(str(exc))
    except OSError as exc:
        return _error(f"writing {str(run_dir)!r} failed: {exc}")
    print(markdown_table(result))
    reasons = default_failures(result, tol.vertex_px, tol.min_f1_1px, tol.min_f1_0px)
    if reasons:
        print("FAIL: the default setting float64/clip/exact is out of tolerance: " + "; ".join(reasons))
    else:
        print("PASS: the default setting float64/clip/exact is within tolerance; the others are trade-offs")
    print(f"Report: {run_dir / 'sweep.md'} (also sweep.json, sweep.html, sweep.png)")
    return 1 if reasons else 0


def _suite(level, run_dir) -> int:
    from .extremes import extremes_markdown, run_extremes  # --suite extremes only

    result = run_extremes(pyrender=level == "pixels")
    md = extremes_markdown(result)
    try:
        run_dir.parent.mkdir(parents=True, exist_ok=True)
        out = FrameDir(run_dir, "--report-dir")
        try:
            out.write("extremes.json", json_dumps(result).encode())
            out.write("extremes.md", md.encode())
            out.commit()
        except BaseException:
            out.abort()
            raise
    except OSError as exc:
        return _error(f"writing {str(run_dir)!r} failed: {exc}")
    print(md.split("\n\n- **", 1)[0].rstrip())  # the table; derivations and notes are in extremes.md
    print(f"(the bounds' derivations and each case's notes: {run_dir / 'extremes.md'})\n")
    failed = [c["name"] for c in result["cases"] if c["verdict"] != "pass"]
    print(
        f"{result['verdict'].upper()}: {len(result['cases']) - len(failed)}/{len(result['cases'])} extreme cases "
        "within their derived bounds" + (f" (failed: {', '.join(failed)})" if failed else "")
    )
    print(f"Report: {run_dir / 'extremes.md'} (also extremes.json)")
    return 1 if failed else 0


def _spec_suite(args, candidate, level, run_dir) -> int:
    """``--suite spec`` (oracles.spec): the 24 runs and 7 named checks; spec.json and spec.md; exit 0 or 1."""
    result, status = _run_guarded(
        args,
        TerminalProgress(None),
        lambda: run_spec(candidate, level=level, candidate_name=candidate.name, precision=args.candidate_precision),
    )
    if status is not None:
        return status
    result = {"run": args.run, **result}
    try:
        run_dir.parent.mkdir(parents=True, exist_ok=True)  # only now: a failed run leaves no folder
        out = FrameDir(run_dir, "--report-dir")
        try:
            out.write("spec.json", json_dumps(result).encode())
            out.write("spec.md", spec_markdown(result).encode())
            out.commit()
        except BaseException:
            out.abort()
            raise
    except OSError as exc:
        return _error(f"writing {str(run_dir)!r} failed: {exc}")
    print("\n".join(spec_console(result)))
    print(f"Report: {run_dir / 'spec.md'} (also spec.json)")
    return 0 if result["verdict"] == "pass" else 1


if __name__ == "__main__":
    sys.exit(main())
