"""The command lines of image candidates: ``crosscheck export DIR`` and ``crosscheck --candidate-frames DIR``.

Both only parse and call :mod:`oracles.candidates.export` / :mod:`oracles.candidates.frames_candidate`;
:mod:`oracles.cli` hands over to them. Exit status as crosscheck's: 0 pass,
1 a case out of tolerance, 2 usage or input errors (one line each).
"""

from __future__ import annotations

import math
import os
import sys
from pathlib import Path

from wirecheck.core.app.cli_help import OneLineParser
from wirecheck.core.errors import InputError
from wirecheck.core.limits import MAX_FRAMES
from wirecheck.core.numbers import plain_float, plain_int
from wirecheck.core.scene.files import builtin_names, load_scene
from wirecheck.core.transforms import Motion

from .cases import ALL_CASE_NAMES, CASE_NAMES
from .reports.console_run import finish_run
from .tolerances import Tolerances


def _fail(message: str) -> int:
    for line in str(message).splitlines():
        print(f"crosscheck: error: {line}", file=sys.stderr)
    return 2


def export_main(argv) -> int:
    """``crosscheck export DIR [--scene S]... [--frames N] [--every K] [--cases A,B] [--spin X,Y,Z] [--phase F]
    [--outputs wireframe,filled,depth] [--depth-format npy|png16|tiff] [--depth-scale S]``."""
    from .candidates.export import check_outputs, write_job

    p = OneLineParser(
        prog="crosscheck export",
        description="write a rendering job (scenes as OBJ, a camera JSON per case and frame, a README) "
        "for any renderer; judge its frames with crosscheck --candidate-frames DIR",
    )
    p.add_argument("dir", help="the job folder to write (new, empty, or an earlier export)")
    p.add_argument("--scene", action="append", default=None, help="scene name or path; repeatable (default: all)")
    p.add_argument("--frames", type=plain_int, default=24, help="frames of the motion (default 24)")
    p.add_argument("--every", type=plain_int, default=1, metavar="K", help="only frames 1, 1+K, ... (default 1)")
    p.add_argument(
        "--cases",
        default=",".join(CASE_NAMES),
        help=f"comma-separated subset of: {', '.join(ALL_CASE_NAMES)} (default: {', '.join(CASE_NAMES)})",
    )
    p.add_argument("--spin", default="1,1,0", metavar="X,Y,Z", help="full turns about X, Y, Z over the frames")
    p.add_argument(
        "--phase",
        type=plain_float,
        default=0.0,
        metavar="F",
        help="move every frame on by F of a frame's step, 0 <= F < 1: frame k at t = (k - 1 + F) / "
        "frames (default 0: crosscheck's own poses; 0.3: no frame of --frames 4 is a quarter turn)",
    )
    p.add_argument(
        "--outputs",
        default="wireframe",
        metavar="LIST",
        help="what the renderer writes per frame, comma-separated: wireframe, filled, depth "
        "(default wireframe; e.g. wireframe,depth or filled,depth)",
    )
    p.add_argument(
        "--depth-format",
        default=None,
        choices=("npy", "png16", "tiff"),
        help="the depth maps' file: npy (float32), png16 (16-bit PNG, --depth-scale values per "
        "world unit) or tiff (32-bit float) (default npy)",
    )
    p.add_argument(
        "--depth-scale",
        type=plain_float,
        default=None,
        metavar="S",
        help="values per world unit of a png16 depth map (default 1000: millimetres per metre)",
    )
    args = p.parse_args(argv)
    try:
        from wirecheck.core.outputs.output import check_outside_scenes, claim

        if not (1 <= args.frames <= MAX_FRAMES and args.every >= 1):
            raise InputError(
                f"--frames {args.frames} --every {args.every}: expected --frames in 1..{MAX_FRAMES:,} "
                "(wirecheck.core.limits, as renderer and crosscheck) and --every >= 1"
            )
        if not 0.0 <= args.phase < 1.0:  # NaN too
            raise InputError(f"--phase {args.phase!r}: expected a number in [0, 1) (a share of a frame's step)")
        cases = [c.strip() for c in args.cases.split(",") if c.strip()]
        bad = [c for c in cases if c not in ALL_CASE_NAMES]
        if bad or not cases:
            raise InputError(
                f"--cases {args.cases!r}: unknown {', '.join(bad) or '(none)'}; "
                f"expected some of {', '.join(ALL_CASE_NAMES)}"
            )
        try:
            spin = tuple(plain_float(x) for x in args.spin.split(","))
        except ValueError:
            spin = ()
        if len(spin) != 3 or not all(math.isfinite(x) for x in spin):
            raise InputError(f"--spin {args.spin!r}: expected three finite numbers X,Y,Z")
        depth_format = args.depth_format or "npy"
        depth_scale = 1000.0 if args.depth_scale is None else args.depth_scale
        outputs = check_outputs(args.outputs, depth_format, depth_scale)
        if args.depth_format is not None and "depth" not in outputs:
            raise InputError(
                f"--depth-format {args.depth_format} with --outputs {args.outputs!r}: expected "
                "--outputs with depth (the format is the depth maps')"
            )
        if args.depth_scale is not None and depth_format != "png16":
            raise InputError(
                f"--depth-scale {args.depth_scale!r} with --depth-format {depth_format}: expected "
                "--depth-format png16 (a scale is a 16-bit PNG's; float maps hold world units)"
            )
        out = Path(args.dir)
        if not out.parent.is_dir():
            raise InputError(f"export {args.dir!r}: its parent folder does not exist")
        if not os.access(out.parent, os.W_OK | os.X_OK):
            raise InputError(f"export {args.dir!r}: {str(out.parent)!r} is not writable: expected a writable folder")
        # a job in the bundled scenes/ would pass for scenes in later runs (as --out and --report-dir there)
        check_outside_scenes(out, "export DIR", "a job folder elsewhere (e.g. job/)")
        claim(out, "export DIR")  # the target first, held to the end: nothing is built for a refused one
        scenes = [load_scene(n) for n in (args.scene or builtin_names())]
        job = write_job(
            out,
            scenes,
            frames=args.frames,
            every=args.every,
            case_names=cases,
            motion=Motion(turns=spin),
            phase=args.phase,
            outputs=outputs,
            depth_format=depth_format,
            depth_scale=depth_scale,
        )
    except InputError as exc:
        return _fail(str(exc))
    except OSError as exc:
        return _fail(f"export {args.dir!r}: cannot write there ({exc})")
    n = len(job["cases"]) * len(job["frame_numbers"])
    asked = "" if outputs == ("wireframe",) else f" ({', '.join(outputs)} each)"
    print(f"Job: {out} ({len(job['cases'])} cases, {n} frames to draw{asked}; see {out / 'README.md'})")
    print(f"Then: crosscheck --candidate-frames {out}")
    return 0


#: crosscheck options that mean nothing for a renderer's frames (the job fixes scenes, cases and frames).
_NOT_WITH_FRAMES = (
    "scene",
    "candidate",
    "level",
    "oracles",
    "dtype",
    "clip",
    "raster",
    "style",
    "cull",
    "sweep",
    "suite",
    "candidate_precision",
)


def frames_main(args, run_dir: Path, from_config=frozenset()) -> int:
    """``crosscheck --candidate-frames DIR`` after :func:`oracles.cli.build_parser` parsed it.

    ``from_config``: the ``[tool.wirecheck]`` keys that set ``args`` (not the
    command line): the project's settings for projector checks, which a job's
    frames do not use, so they are not usage errors here.
    """
    from .config import CLI_DESTS
    from .judge.frames_judge import run_frames

    skip = {CLI_DESTS[k] for k in from_config if k in CLI_DESTS}
    given = [f"--{k.replace('_', '-')}" for k in _NOT_WITH_FRAMES if getattr(args, k, None) and k not in skip]
    given += ["--hidden-lines"] if args.hidden_lines else []
    given += ["--cases"] if args.cases != ",".join(CASE_NAMES) and "cases" not in skip else []
    given += ["--spin"] if args.spin != "1,1,0" and "spin" not in skip else []
    given += [
        f"--{k}"
        for k, default in (("frames", 24), ("every", 1), ("jobs", 1))
        if getattr(args, k) != default and k not in skip
    ]
    if given:
        return _fail(
            f"--candidate-frames with {', '.join(given)}: the job fixes scenes, cases and frames, and "
            "its frames are drawn already: expected only --tol-px, --min-f1, --min-f1-0px, --run or --report-dir"
        )
    job_dir = Path(args.candidate_frames)
    tol = Tolerances(min_f1_1px=args.min_f1, min_f1_0px=args.min_f1_0px)
    try:
        check_report_outside_job(job_dir, run_dir)
        report, images = run_frames(
            job_dir, tol=tol, allow_vacuous=args.allow_vacuous, line_rule=args.line_rule or "any"
        )
    except InputError as exc:
        return _fail(str(exc))
    return finish_run(args, run_dir, report, images, tol)


def check_report_outside_job(job_dir: Path, run_dir: Path) -> None:
    """InputError when the report folder ``run_dir`` is the job folder itself or its ``frames/`` (or in it).

    Those hold the renderer's files, which a later judgement reads: never written. A report
    elsewhere in the job (``reports/`` when run from inside it) is harmless. Shared by
    ``crosscheck --candidate-frames`` and :func:`wirecheck.oracles.frames_api.check_frames`.
    """
    job_dir, run_dir = Path(job_dir), Path(run_dir)
    # os.path.realpath: unlike Path.resolve() in 3.11, no RuntimeError for a link loop (judged later)
    job_real, frames_real, run_real = (Path(os.path.realpath(p)) for p in (job_dir, job_dir / "frames", run_dir))
    if (
        run_real == job_real
        or job_real in run_real.parents
        and (run_real == frames_real or frames_real in run_real.parents)
    ):
        raise InputError(
            f"report folder {str(run_dir)!r}: the job {str(job_dir)!r} itself or its frames/ "
            "(the renderer's files, only read): expected a report folder outside them"
        )
