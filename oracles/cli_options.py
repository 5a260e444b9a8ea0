"""``crosscheck``'s options: the argument parser of oracles.cli (its defaults, limits and help).

The docs' option table (docs/crosscheck.md) is checked against this parser
(tests/test_docs_samples.py).
"""

from __future__ import annotations

import argparse

from wirecheck.core.app.cli_help import CROSSCHECK_EXAMPLES, OneLineParser
from wirecheck.core.app.guard import VersionAction
from wirecheck.core.numbers import plain_float, plain_int

from . import tolerances
from .candidates.core_candidate import CoreCandidate, RenderMode
from .candidates.subprocess_candidate import DEFAULT_TIMEOUT_S
from .cases import ALL_CASE_NAMES, CASE_NAMES
from .executors import DEFAULT_CONNECT_TIMEOUT_S, EXECUTORS
from .runner import LEVELS

#: The first line of ``crosscheck --help``.
DESCRIPTION = "crosscheck: judge a projector against OpenCV and pyrender (OSMesa or EGL)."


#: Most worker processes --jobs may ask for, on this machine or a local Dask cluster.
MAX_JOBS = 256
#: Longest --scheduler-timeout: 1e308 s waited for ever on an address where no scheduler runs.
MAX_SCHEDULER_TIMEOUT_S = 3600.0


def build_parser() -> argparse.ArgumentParser:
    p = OneLineParser(
        prog="crosscheck",
        description=DESCRIPTION,
        epilog=CROSSCHECK_EXAMPLES,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "--version",
        action=VersionAction,
        version="%(prog)s (wirecheck) {}",
        help="print the installed wirecheck version and exit",
    )
    p.add_argument(
        "--scene",
        action="append",
        default=None,
        help="scene name or path, or a folder of mesh files (a dataset, walked recursively); "
        "repeatable (default: every scene in scenes/)",
    )
    p.add_argument(
        "--scene-list",
        action="append",
        default=None,
        metavar="FILE",
        help="a dataset: mesh file paths, one per line ('#' comments, blank lines; relative to FILE's "
        "folder); repeatable (default: none)",
    )
    p.add_argument(
        "--allow-load-errors",
        action="store_true",
        default=False,
        help="dataset runs: a mesh that cannot be loaded is reported and counted but does not fail "
        "the run (default: it fails the run)",
    )
    p.add_argument(
        "--memory-budget",
        type=plain_float,
        default=None,
        metavar="GIB",
        help="dataset runs: GiB one mesh may need to be checked; a mesh estimated over it is a load "
        "error, and the run goes on (default: half the machine's memory, shared by --jobs)",
    )
    p.add_argument(
        "--frames",
        type=plain_int,
        default=None,
        help="frames of the scene's motion per case (default 24; 12 with --sweep)",
    )
    p.add_argument(
        "--cases",
        default=",".join(CASE_NAMES),
        help=f"comma-separated subset of: {', '.join(ALL_CASE_NAMES)} "
        f"or the groups default, calibrated, all "
        f"(default: {', '.join(CASE_NAMES)}; the calibrated ones run when named)",
    )
    p.add_argument(
        "--candidate",
        default=None,
        metavar="FILE.py:FUNC|MODULE:FUNC",
        help="the projector to judge (default: core/); run in its own process",
    )
    p.add_argument(
        "--candidate-cmd",
        default=None,
        metavar="'COMMAND ARGS'",
        help="a projector program in any language, spoken to over stdin/stdout (docs/protocol.md) (default: none)",
    )
    p.add_argument(
        "--candidate-timeout",
        type=plain_float,
        default=DEFAULT_TIMEOUT_S,
        metavar="SECONDS",
        help=f"seconds each request to --candidate/--candidate-cmd may take (default {DEFAULT_TIMEOUT_S:g})",
    )
    p.add_argument(
        "--candidate-precision",
        choices=tolerances.PRECISIONS,
        default=None,
        help="what the candidate computes in; its vertex bound is derived from it (wirecheck.oracles.tolerances) "
        "(default: from the dtype it returns, float64 over the protocol unless its replies say "
        "float32; core: --dtype)",
    )
    p.add_argument(
        "--unprojector",
        default=None,
        metavar="FILE.py:FUNC|MODULE:FUNC",
        help="judge an unprojector FUNC(pixels, depth, camera) -> world points against the exact "
        "inverse of the conventions (docs/depth.md); with --scene, --cases, --frames (2), --spin; "
        "no report folder (default: none)",
    )
    p.add_argument(
        "--unprojector-cmd",
        default=None,
        metavar="'COMMAND ARGS'",
        help="an unprojector program in any language, over the candidate protocol's unproject requests "
        "(docs/protocol.md); each request under --candidate-timeout (default: none)",
    )
    p.add_argument(
        "--candidate-frames",
        default=None,
        metavar="DIR",
        help="judge a renderer's own PNG frames of a job written by 'crosscheck export DIR' "
        "(docs/frames.md) (default: none)",
    )
    p.add_argument(
        "--line-rule",
        choices=("any", "gl", "geometry"),
        default=None,
        help="--candidate-frames: any holds aliased 1-px lines to a correct drawing by GL's rule or by "
        "the rule that rounds the ends to pixel centres (Bresenham, Pillow, cv2.line); gl to GL's "
        "pixel rule alone (F1@0px); geometry judges where the lines are only (antialiased and wide "
        "lines always are) (default: any)",
    )
    p.add_argument(
        "--level",
        choices=LEVELS,
        default=None,
        help="vertices: OpenCV vertex check only (no drawing, no pyrender); "
        "pixels: vertices and pyrender pixels (default)",
    )
    p.add_argument(
        "--oracles",
        default=None,
        help="older spelling of --level: 'opencv' = vertices, 'opencv,pyrender' = pixels (default: from --level)",
    )
    p.add_argument(
        "--gl",
        choices=("osmesa", "egl"),
        default=None,
        help="the OpenGL platform pyrender draws on (level pixels): osmesa, or egl (Mesa's on the CPU, "
        "or a GPU's driver) (default: $PYOPENGL_PLATFORM, else osmesa)",
    )
    p.add_argument(
        "--every",
        type=plain_int,
        default=1,
        metavar="K",
        help="check frames 1, 1+K, 1+2K, ... of the motion (default 1: every frame)",
    )
    p.add_argument(
        "--jobs",
        type=plain_int,
        default=1,
        metavar="N",
        help="run the cases in N worker processes (default 1; same report for any N)",
    )
    p.add_argument(
        "--executor",
        choices=EXECUTORS,
        default=None,
        help="local: this process or --jobs worker processes; dask: Dask distributed, a local "
        "cluster of --jobs workers on 127.0.0.1 or --scheduler's cluster (default local)",
    )
    p.add_argument(
        "--scheduler",
        default=None,
        metavar="tcp://HOST:PORT",
        help="the Dask scheduler of a cluster (docs/datasets.md); implies --executor dask "
        "(default: none, a local cluster)",
    )
    p.add_argument(
        "--scheduler-timeout",
        type=plain_float,
        default=DEFAULT_CONNECT_TIMEOUT_S,
        metavar="SECONDS",
        help=f"seconds to reach --scheduler and see a worker (default {DEFAULT_CONNECT_TIMEOUT_S:g})",
    )
    p.add_argument(
        "--dtype",
        choices=CoreCandidate.DTYPES,
        default=None,
        help="core candidate only: floating-point type of the pipeline (default float64)",
    )
    p.add_argument(
        "--clip",
        choices=CoreCandidate.CLIPS,
        default=None,
        help="core candidate only: near/far handling of edges (default clip)",
    )
    p.add_argument(
        "--raster",
        choices=CoreCandidate.RASTERS,
        default=None,
        help="core candidate only: line rasterizer (default exact; aa: drawn where >= 128)",
    )
    p.add_argument(
        "--style",
        choices=RenderMode.STYLES,
        default=None,
        help="core candidate, level pixels: wireframe (default), or shaded: core's depth buffer against "
        "pyrender's filled faces (silhouette IoU and depth error)",
    )
    p.add_argument(
        "--hidden-lines",
        action="store_true",
        default=False,
        help="core candidate, level pixels: the scene's faces hide the lines behind them "
        "(pyrender: faces black with glPolygonOffset(1, 1), lines on top) (default: off)",
    )
    p.add_argument(
        "--cull",
        choices=RenderMode.CULLS,
        default=None,
        help="core candidate, level pixels: backface culls back faces and the edges only they own (default none)",
    )
    p.add_argument(
        "--spin", default="1,1,0", metavar="X,Y,Z", help="full turns about X, Y, Z over the frames (default 1,1,0)"
    )
    p.add_argument(
        "--tol-px",
        type=plain_float,
        default=tolerances.VERTEX_TOL_PX,
        help=f"max vertex error in px (default {tolerances.VERTEX_TOL_PX})",
    )
    p.add_argument(
        "--min-f1",
        type=plain_float,
        default=tolerances.MIN_F1_1PX,
        help=f"min edge-pixel F1 at 1 px (default {tolerances.MIN_F1_1PX})",
    )
    p.add_argument(
        "--min-f1-0px",
        type=plain_float,
        default=tolerances.MIN_F1_0PX,
        help=f"min edge-pixel F1 at 0 px (default {tolerances.MIN_F1_0PX})",
    )
    p.add_argument(
        "--min-iou",
        type=plain_float,
        default=tolerances.MIN_SILHOUETTE_IOU,
        help=f"--style shaded: min silhouette IoU (default {tolerances.MIN_SILHOUETTE_IOU})",
    )
    mode = p.add_mutually_exclusive_group()
    mode.add_argument(
        "--sweep",
        action="store_true",
        help="every --dtype x --clip x --raster setting of core on the scenes and a large mesh: "
        "table and Pareto plot of time per frame against accuracy (default: off)",
    )
    mode.add_argument(
        "--suite",
        choices=("extremes", "spec"),
        default=None,
        help="extremes: near plane, tiny/huge FOV, extreme aspect, far from the origin, "
        "1,000,000-frame periodicity, degenerate and non-finite inputs; spec: the "
        "specification's 24-run test matrix and its 7 named checks, of core or --candidate "
        "(docs/spec-suite.md) (default: none)",
    )
    p.add_argument(
        "--allow-vacuous",
        action="store_true",
        default=False,
        help="a case that compared nothing (every point clipped, nothing drawn) does not fail the run "
        "(default: it does)",
    )
    p.add_argument(
        "--no-report",
        action="store_true",
        default=False,
        help="write no report folder: the table and the verdict are printed only (--junit-xml is still "
        "written); not with --report-dir, --run, --sweep, --suite, --candidate-frames "
        "(default: the report is written to reports/RUN)",
    )
    p.add_argument(
        "--report-dir", default=None, help="where to write the report: DIR, or DIR/RUN with --run (default reports/RUN)"
    )
    p.add_argument(
        "--run",
        default=None,
        help="run name: the report folder's name, also in report.json (default: UTC time, YYYYmmdd-HHMMSS)",
    )
    p.add_argument(
        "--junit-xml",
        default=None,
        metavar="FILE",
        help="also write JUnit XML: one test case per scene x camera, faults and reasons as the "
        "failure message (default: none)",
    )
    p.add_argument(
        "--config",
        default=None,
        metavar="FILE",
        help="read [tool.wirecheck] from FILE (default: the nearest pyproject.toml at or above the "
        "working directory); options given here override it",
    )
    return p
