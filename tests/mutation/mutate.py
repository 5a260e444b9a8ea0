"""Mutation testing of core/ and oracles/: a small AST mutator, one mutant at a time.

Each mutant changes one operator or constant in one module (the operators:
``+ -``, ``* /``, ``// /``, ``**`` to ``*``, ``< <=``, ``> >=``, ``== !=``,
``is`` / ``is not``, ``in`` / ``not in``, ``and`` / ``or``, dropping a ``not``
or a unary minus, ``k`` to ``k + 1`` for an int, ``x`` to ``2 x`` (``0.0`` to
``1.0``) for a float), is written into a private copy of the package (the
working tree is never touched), and the module's own tests run against it
(``TARGETS``: test files or ``file::test`` node ids and an optional ``-k``;
``pytest -x -p no:cacheprovider``, time-limited). A mutant is *killed*
when they fail (or time out), *survived* when they pass. Survivors are either
killed by a new test or listed in ``equivalent.json`` with the reason the
change cannot be seen (their id: ``module:line:col:change``).

Why our own mutator rather than mutmut or cosmic-ray: both run every mutant
against a whole configured test command and keep a session database; here each
module has a few relevant test files (seconds, not the 75-s suite), the
machine has 2 shared cores, and ``wirecheck`` is an editable install whose
package folders are mapped by setuptools (``package-dir``), which both tools'
in-place file rewriting would put under the other helpers' feet. The mutator
below is ~200 lines, has no state but its report, and runs in a copy.

    .venv/bin/python tests/mutation/mutate.py [--sample N] [--seed S] [--module core/projector/raster.py ...]
                                             [--only ID ...] [--list] [--report tests/mutation/report.md]

``--sample N``: at most N mutants per module, drawn with ``--seed`` from all
of that module's sites (the same N and seed give the same mutants). Not part
of CI: a full run takes tens of minutes (docs/testing.md has the figures).
"""

from __future__ import annotations

import argparse
import ast
import json
import os
import random
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from itertools import zip_longest
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
HERE = Path(__file__).resolve().parent

#: The image diagnosis's own test files, less test_image_diagnosis.py's module fixture (80 s): its two tests
#: that do not use it (a blank candidate, a case of many frames) are selected by node id.
_IMAGE_TESTS = [
    "tests/test_image_naming.py",
    "tests/test_image_registration.py",
    "tests/test_image_diagnosis_short.py",
    "tests/test_image_diagnosis_thick.py",
    "tests/test_image_diagnosis.py::test_blank_candidate_is_a_depth_flip_only_when_the_backward_view_is_empty",
    "tests/test_image_diagnosis.py::test_a_case_of_many_frames_is_fitted_on_the_points_of_six",
]

#: The modules mutated, and the tests that judge each: test files or node ids (``file::test``), with an
#: optional -k expression over them all. Only the tests that exercise the module: a mutant costs seconds
#: to a minute, not the whole suite's minutes.
TARGETS = {
    "core/projector/projection.py": (
        ["tests/test_projection.py", "tests/test_conventions.py", "tests/test_core_vs_opencv.py"],
        None,
    ),
    "core/projector/clipping.py": (["tests/test_clipping.py"], None),
    "core/projector/raster.py": (["tests/test_raster.py", "tests/test_raster_modes.py"], None),
    "core/camera.py": (["tests/test_conventions.py", "tests/test_projection.py", "tests/test_scene.py"], None),
    "core/transforms.py": (["tests/test_transforms.py", "tests/test_conventions.py"], None),
    "oracles/judge/metrics.py": (["tests/test_metrics.py", "tests/test_line_gate.py"], None),
    # FramePixels (moved out of metrics) and line_failures (moved into tolerances): the same tests as before
    "oracles/judge/frame_pixels.py": (["tests/test_metrics.py", "tests/test_line_gate.py"], None),
    "oracles/tolerances.py": (["tests/test_line_gate.py", "tests/test_precision.py"], None),
    "oracles/diagnosis/diagnose.py": (["tests/test_diagnosis.py", "tests/test_line_gate.py"], "not decides"),
    "oracles/judge/verdict.py": (
        ["tests/test_line_gate.py", "tests/test_crosscheck.py", "tests/test_crosscheck_styles.py"],
        "decides or note or empty_scene or faceless or visibility or core_case_fields or shaded_summary",
    ),
    "oracles/references/convert.py": (["tests/test_oracle_convert.py"], None),
    "oracles/judge/decide.py": (
        [
            "tests/test_decide_steps.py",
            "tests/test_f1_radius.py::test_the_f1_at_the_radius_alone_decides",
            "tests/test_oracle_far.py",
            "tests/test_frames_judge.py",
            "tests/test_line_gate.py",
        ],
        "steps or radius or oracle or decides or vacuous or line_end_bias or exact",
    ),
    # the pure steps (issue 34): decide and name_faults on hand-made evidence first (seconds), then the paths
    # that collect it: the F1 radius by hand, the oracle's precision limit, dim lines and the visible sets
    "oracles/judge/evidence.py": (["tests/test_decide_steps.py"], None),
    "oracles/judge/name_faults.py": (
        [
            "tests/test_decide_steps.py",
            "tests/test_oracle_far.py",
            "tests/test_frames_dim_lines.py",
            "tests/test_frames_visibility.py",
        ],
        None,
    ),
    # the frames path: its judge (run_frames, judge_case) is exercised by test_frames_judge.py (each threshold
    # deciding on PNG frames) and by the run_frames cases of test_frames_candidate.py (pass, named fault, vacuous)
    "oracles/judge/frames_judge.py": (
        [
            "tests/test_frames_judge.py",
            "tests/test_frames_candidate.py::test_core_frames_pass",
            "tests/test_frames_candidate.py::test_mirrored_frames_fail_and_are_named",
            "tests/test_frames_candidate.py::test_a_case_where_nothing_is_drawn_is_vacuous",
        ],
        None,
    ),
    # the frames read ahead on the GL thread: errors at their own frame, the same report, no thread left
    "oracles/candidates/frame_prefetch.py": (
        [
            "tests/test_frame_prefetch.py",
            "tests/test_frames_candidate.py::test_frames_that_cannot_be_decoded_are_all_listed",
        ],
        None,
    ),
    # the end of every source's case record
    "oracles/judge/record.py": (["tests/test_record.py", "tests/test_oracle_precision_drawn.py"], None),
    # one case loop, one wireframe measurement for every frame source: hand-built frames and a stand-in source
    "oracles/judge/wire_frames.py": (["tests/test_wire_frames.py"], None),
    "oracles/judge/case_loop.py": (["tests/test_case_loop.py"], None),
    "oracles/judge/shaded_frames.py": (["tests/test_shaded_frames.py"], None),
    # one report builder for both sources: counts, summary, keys and their order
    "oracles/judge/run_report.py": (["tests/test_run_report.py", "tests/test_gate.py"], None),
    # the GL thread the frames are read ahead on: every oracle call on it, closed with no thread left
    "oracles/references/gl_thread.py": (["tests/test_frame_prefetch.py"], None),
    "oracles/judge/line_style.py": (["tests/test_line_style.py"], None),
    "oracles/judge/line_windows.py": (["tests/test_line_windows.py", "tests/test_line_style.py"], None),
    # moved out of line_windows, segment_pixels and the registration: the distances and the box clipper
    "oracles/segment_geometry.py": (
        [
            "tests/test_line_windows.py",
            "tests/test_metrics.py",
            "tests/test_line_style.py",
            "tests/test_image_registration.py",
        ],
        None,
    ),
    "oracles/judge/line_profile.py": (["tests/test_line_profile.py", "tests/test_line_style.py"], None),
    "oracles/judge/case_samples.py": (["tests/test_case_samples.py", "tests/test_line_style.py"], None),
    # the even-width lean: its unit tests and 2-px jobs in test_even_width.py, then Pillow's 2-px lines on the
    # held-out slanted job (a correct one passes leaning, one with the half-pixel mistake is pixel_offset)
    "oracles/judge/even_lean.py": (
        [
            "tests/test_even_width.py",
            "tests/test_frames_heldout.py::test_pillow_wide_lines_pass_on_f1_at_their_width[2]",
            "tests/test_frames_heldout.py::test_pillow_2px_half_pixel_is_pixel_offset",
        ],
        None,
    ),
    # the image diagnosis: every test file but the 80-s confusion matrix of test_image_diagnosis.py (its
    # module fixture diagnoses ~100 cases); the short job's matrix and the thick lines cover the same names
    "oracles/diagnosis/image_diagnose.py": (_IMAGE_TESTS, None),
    "oracles/diagnosis/image_naming.py": (_IMAGE_TESTS, None),
    # split out of image_diagnose / image_naming (issue 34's import cycles): the fit and the model's lines
    "oracles/diagnosis/registration.py": (_IMAGE_TESTS, None),
    "oracles/diagnosis/model_lines.py": (_IMAGE_TESTS, None),
    # the aliased rules read and what a fault stands against: its unit tests in test_image_naming.py, then the
    # held-out cases it decides (cv2 LINE_8 on prism / on_axis, the wrong-axis FOV on prism / wide_fov, aspect)
    "oracles/diagnosis/rule_read.py": (
        ["tests/test_image_naming.py", "tests/test_frames_heldout.py"],
        "tie_margin or stands_against or centre_line_is_named or prism_wide_fov or aspect_mistake",
    ),
    # the one model of a drawn line (issue 34): its hand-made cases and the independent rounded-ends drawers
    # (Pillow, cv2.line LINE_8, a textbook Bresenham), then the end tie's deciding test (seconds)
    "oracles/line_model.py": (
        ["tests/test_line_model.py", "tests/test_line_rule.py::test_rounded_end_tie_px_decides"],
        None,
    ),
    # the job's pooled read: hand-written records and evidence first, then the two small held-out jobs
    # (a half-pixel renderer pixel_offset in every case, its correct twin a pass)
    "oracles/judge/job_read.py": (["tests/test_job_read.py"], None),
}

PER_MUTANT_TIMEOUT_S = 300

_BINOPS = {
    ast.Add: ast.Sub,
    ast.Sub: ast.Add,
    ast.Mult: ast.Div,
    ast.Div: ast.Mult,
    ast.FloorDiv: ast.Div,
    ast.Pow: ast.Mult,
}
_CMPOPS = {
    ast.Lt: ast.LtE,
    ast.LtE: ast.Lt,
    ast.Gt: ast.GtE,
    ast.GtE: ast.Gt,
    ast.Eq: ast.NotEq,
    ast.NotEq: ast.Eq,
    ast.Is: ast.IsNot,
    ast.IsNot: ast.Is,
    ast.In: ast.NotIn,
    ast.NotIn: ast.In,
}
_SYMBOL = {
    ast.Add: "+",
    ast.Sub: "-",
    ast.Mult: "*",
    ast.Div: "/",
    ast.FloorDiv: "//",
    ast.Pow: "**",
    ast.Lt: "<",
    ast.LtE: "<=",
    ast.Gt: ">",
    ast.GtE: ">=",
    ast.Eq: "==",
    ast.NotEq: "!=",
    ast.Is: "is",
    ast.IsNot: "is not",
    ast.In: "in",
    ast.NotIn: "not in",
    ast.And: "and",
    ast.Or: "or",
}


@dataclass(frozen=True)
class Site:
    """One mutation: the ``index``-th site of its module in walk order."""

    module: str
    index: int
    line: int
    col: int
    change: str

    @property
    def id(self) -> str:
        return f"{self.module}:{self.line}:{self.col}:{self.change}"


def _docstring_nodes(tree) -> set:
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)) and node.body:
            first = node.body[0]
            if isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant):
                out.add(id(first.value))
    return out


class _Mutator(ast.NodeTransformer):
    """Walks a module; lists its sites, or applies the one numbered ``target``."""

    def __init__(self, module: str, line_range, target: int | None = None):
        self.module, self.range, self.target = module, line_range, target
        self.sites: list[Site] = []
        self.skip: set = set()

    def _site(self, node, change: str) -> bool:
        """Record a site; True when it is the one to apply."""
        if self.range and not (self.range[0] <= node.lineno <= self.range[1]):
            return False
        self.sites.append(Site(self.module, len(self.sites), node.lineno, node.col_offset, change))
        return self.target == len(self.sites) - 1

    def visit_Module(self, node):
        self.skip = _docstring_nodes(node)
        return self.generic_visit(node)

    def visit_BinOp(self, node):
        self.generic_visit(node)
        new = _BINOPS.get(type(node.op))
        if new and self._site(node, f"{_SYMBOL[type(node.op)]}->{_SYMBOL[new]}"):
            node.op = new()
        return node

    def visit_AugAssign(self, node):
        self.generic_visit(node)
        new = _BINOPS.get(type(node.op))
        if new and self._site(node, f"{_SYMBOL[type(node.op)]}=->{_SYMBOL[new]}="):
            node.op = new()
        return node

    def visit_Compare(self, node):
        self.generic_visit(node)
        for i, op in enumerate(node.ops):
            new = _CMPOPS.get(type(op))
            if new and self._site(node, f"{_SYMBOL[type(op)]}->{_SYMBOL[new]}#{i}"):
                node.ops[i] = new()
        return node

    def visit_BoolOp(self, node):
        self.generic_visit(node)
        new = ast.Or if isinstance(node.op, ast.And) else ast.And
        if self._site(node, f"{_SYMBOL[type(node.op)]}->{_SYMBOL[new]}"):
            node.op = new()
        return node

    def visit_UnaryOp(self, node):
        self.generic_visit(node)
        if isinstance(node.op, (ast.Not, ast.USub)):
            name = "not" if isinstance(node.op, ast.Not) else "-"
            if self._site(node, f"drop {name}"):
                return node.operand
        return node

    def visit_Constant(self, node):
        v = node.value
        if id(node) in self.skip or isinstance(v, bool) or not isinstance(v, (int, float)):
            return node
        new = v + 1 if isinstance(v, int) else (2.0 * v if v != 0 else 1.0)
        if self._site(node, f"{v!r}->{new!r}"):
            return ast.copy_location(ast.Constant(new), node)
        return node

    # annotations and default "dtype" strings are not behaviour: do not descend into annotations
    def visit_arg(self, node):
        return node

    def visit_AnnAssign(self, node):
        if node.value is not None:
            node.value = self.visit(node.value)
        return node


def sites(module: str) -> list[Site]:
    source = (ROOT / module).read_text()
    m = _Mutator(module, None)
    m.visit(ast.parse(source))
    return m.sites


def mutant_source(site: Site) -> str:
    source = (ROOT / site.module).read_text()
    m = _Mutator(site.module, None, target=site.index)
    tree = m.visit(ast.parse(source))
    ast.fix_missing_locations(tree)
    return ast.unparse(tree)


def _copy_tree(dest: Path) -> Path:
    """The package as ``dest/wirecheck`` (root __init__, core, oracles, scenes, tests, pyproject)."""
    pkg = dest / "wirecheck"
    pkg.mkdir(parents=True)
    ignore = shutil.ignore_patterns("__pycache__", "*.pyc")
    for name in ("core", "oracles", "scenes", "tests"):
        shutil.copytree(ROOT / name, pkg / name, ignore=ignore)
    for name in ("__init__.py", "pyproject.toml"):
        shutil.copy2(ROOT / name, pkg / name)
    return pkg


def run_mutant(site: Site, pkg: Path) -> tuple[str, float]:
    """``("killed" | "survived" | "timeout", seconds)`` for one mutant, in the copy at ``pkg``."""
    tests, k = TARGETS[site.module]
    target = pkg / site.module
    original = target.read_text()
    target.write_text(mutant_source(site))
    env = {
        **os.environ,
        "PYTHONPATH": str(pkg.parent),
        "PYTHONDONTWRITEBYTECODE": "1",
        "PYOPENGL_PLATFORM": os.environ.get("PYOPENGL_PLATFORM", "osmesa"),
    }
    cmd = [sys.executable, "-m", "pytest", "-x", "-q", "-p", "no:cacheprovider", *tests] + (["-k", k] if k else [])
    t0 = time.perf_counter()
    try:
        rc = subprocess.run(
            cmd, cwd=pkg, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, timeout=PER_MUTANT_TIMEOUT_S
        ).returncode
        verdict = "survived" if rc == 0 else "killed"
    except subprocess.TimeoutExpired:
        verdict = "timeout"
    finally:
        target.write_text(original)
    return verdict, time.perf_counter() - t0


def _check_copy_is_imported(pkg: Path) -> None:
    """The tests must import the copy, not the editable install of the working tree."""
    env = {**os.environ, "PYTHONPATH": str(pkg.parent), "PYTHONDONTWRITEBYTECODE": "1"}
    out = subprocess.run(
        [sys.executable, "-c", "import wirecheck.core.projector.raster as r; print(r.__file__)"],
        cwd=pkg,
        env=env,
        capture_output=True,
        text=True,
        check=True,
    ).stdout.strip()
    if not out.startswith(str(pkg)):
        raise SystemExit(f"mutate: the copy is not what gets imported ({out})")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sample", type=int, default=None, help="at most N mutants per module (default: all)")
    ap.add_argument("--seed", type=int, default=16)
    ap.add_argument("--module", action="append", default=None, choices=sorted(TARGETS))
    ap.add_argument("--only", action="append", default=None, help="run just these mutant ids")
    ap.add_argument("--list", action="store_true", help="list the sites and exit")
    ap.add_argument("--report", default=str(HERE / "report.md"))
    args = ap.parse_args(argv)
    modules = args.module or list(TARGETS)
    chosen: list[Site] = []
    for module in modules:
        all_sites = sites(module)
        pick = (
            all_sites
            if args.sample is None or args.sample >= len(all_sites)
            else sorted(random.Random(f"{args.seed}:{module}").sample(all_sites, args.sample), key=lambda s: s.index)
        )
        chosen += pick
        print(f"{module}: {len(all_sites)} sites, {len(pick)} chosen", flush=True)
    if args.only:
        chosen = [s for m in modules for s in sites(m) if s.id in set(args.only)]
        unknown = [i for i in args.only if i not in {s.id for s in chosen}]
        if unknown:  # a score over nothing would overwrite the report with "Score: nan%"
            print(
                f"mutate: error: --only {unknown[0]!r}: no mutant of {', '.join(modules)} has this id: expected "
                "one that --list prints (MODULE:LINE:COL:CHANGE)",
                file=sys.stderr,
            )
            return 2
    if not chosen:
        print(
            "mutate: error: no mutant chosen: expected --sample N >= 1 or a module with mutation sites", file=sys.stderr
        )
        return 2
    # round robin over the modules: a run stopped early has looked at each of them
    by_module = [[s for s in chosen if s.module == m] for m in modules]
    chosen = [s for row in zip_longest(*by_module) for s in row if s is not None]
    if args.list:
        for s in chosen:
            print(s.id)
        return 0
    equivalent = json.loads((HERE / "equivalent.json").read_text()) if (HERE / "equivalent.json").exists() else {}
    results = []
    with tempfile.TemporaryDirectory(prefix="wirecheck-mutants-") as tmp:
        pkg = _copy_tree(Path(tmp))
        _check_copy_is_imported(pkg)
        for n, site in enumerate(chosen, 1):
            verdict, seconds = run_mutant(site, pkg)
            if verdict == "survived" and site.id in equivalent:
                verdict = "equivalent"
            results.append((site, verdict, seconds))
            print(f"[{n}/{len(chosen)}] {verdict:10s} {seconds:5.1f}s {site.id}", flush=True)
    if not any(r != "equivalent" for _, r, _ in results):
        print(
            f"mutate: error: all {len(results)} chosen mutants are listed as equivalent: no score to report; "
            f"{args.report} left as it was",
            file=sys.stderr,
        )
        return 2
    write_report(Path(args.report), results, equivalent, args)
    return 0


def write_report(path: Path, results, equivalent: dict, args) -> None:
    counts = {v: sum(1 for _, r, _ in results if r == v) for v in ("killed", "timeout", "survived", "equivalent")}
    judged = counts["killed"] + counts["timeout"] + counts["survived"]
    score = (counts["killed"] + counts["timeout"]) / judged if judged else float("nan")
    lines = [
        "# Mutation report",
        "",
        f"Command: `.venv/bin/python tests/mutation/mutate.py"
        f"{f' --sample {args.sample}' if args.sample else ''}{'' if args.only else f' --seed {args.seed}'}"
        f"{''.join(f' --module {m}' for m in args.module or [])}"
        f"{''.join(f' --only {i}' for i in args.only or [])}"
        f"{'' if Path(args.report) == HERE / 'report.md' else f' --report {args.report}'}`",
        "",
        f"Mutants: {len(results)}; killed {counts['killed']} (+{counts['timeout']} by time-out), "
        f"survived {counts['survived']}, equivalent {counts['equivalent']}. "
        f"**Score: {score:.1%}** of the non-equivalent mutants killed.",
        "",
        "| module | mutants | killed | survived | equivalent |",
        "|---|---|---|---|---|",
    ]
    for module in dict.fromkeys(s.module for s, _, _ in results):
        rows = [r for s, r, _ in results if s.module == module]
        lines.append(
            f"| {module} | {len(rows)} | {sum(r in ('killed', 'timeout') for r in rows)} | "
            f"{rows.count('survived')} | {rows.count('equivalent')} |"
        )
    lines += ["", "## Survivors", ""]
    lines += [f"- `{s.id}`" for s, r, _ in results if r == "survived"] or ["(none)"]
    lines += ["", "## Equivalent (tests/mutation/equivalent.json)", ""]
    lines += [f"- `{s.id}`: {equivalent[s.id]}" for s, r, _ in results if r == "equivalent"] or ["(none)"]
    lines += ["", "## Killed", ""]
    lines += [f"- `{s.id}` ({sec:.0f} s)" for s, r, sec in results if r in ("killed", "timeout")]
    path.write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    raise SystemExit(main())
