"""The long fuzz run: N hostile inputs per CLI, in-process, checked against the contract (contract.py).

    nice .venv/bin/python tests/fuzz/run_fuzz.py --inputs 10000          # both CLIs (~40 min on 2 busy cores)
    .venv/bin/python tests/fuzz/run_fuzz.py --inputs 200 --cli renderer  # a quick look
    .venv/bin/python tests/fuzz/run_fuzz.py --inputs 5000 --cli png      # damaged PNG frames (png_inputs.py)
    .venv/bin/python tests/fuzz/run_fuzz.py --inputs 100 --cli interrupt # signals at random moments (interrupts.py)

Prints, per CLI, the inputs run, the exit codes seen and the four counts the
contract needs at 0 (tracebacks, exit codes outside {0, 1, 2, 3}, partial
outputs or leftovers, user files touched), plus the first few violations with
their argv to reproduce them. Deterministic for a given --seed. The counts
are recorded in docs/reliability.md.
"""

from __future__ import annotations

import argparse
import collections
import json
import os
import random
import signal
import sys
import tempfile
import time
import warnings
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from fuzz.contract import Outcome, Pick, crosscheck_argv, renderer_argv, run_cli  # noqa: E402


def category(problem: str) -> str:
    if problem.startswith("traceback"):
        return "tracebacks"
    if problem.startswith("timeout"):
        return "timeouts"
    if problem.startswith("exit "):
        return "exit codes outside {0, 1, 2, 3}" if problem != "exit 3" else "internal errors (exit 3)"
    if problem.startswith("user file"):
        return "user files touched"
    if problem.startswith("input outside"):
        return "inputs outside their folder"
    if "stderr lines" in problem:
        return "exit 2 without exactly one stderr line"
    return "partial outputs or leftovers"


#: An input that runs longer than this is a finding (a missing limit): it is stopped and counted.
TIMEOUT_S = 60


class FuzzTimeout(BaseException):
    """Raised by SIGALRM in the input that ran too long (a BaseException: the CLIs' guard lets it through)."""


def _timeout(signum, frame):
    raise FuzzTimeout()


def fuzz(cli: str, n: int, seed: int, earlier: Path, log, start: int = 0) -> dict:
    from wirecheck.core.app import cli as renderer
    from wirecheck.oracles import cli as crosscheck

    main = renderer.main if cli == "renderer" else crosscheck.main
    make = renderer_argv if cli == "renderer" else crosscheck_argv
    codes, problems, examples = collections.Counter(), collections.Counter(), []
    t0 = time.perf_counter()
    signal.signal(signal.SIGALRM, _timeout)
    for i in range(start, start + n):
        pick = Pick(random.Random(f"{seed}-{cli}-{i}"))
        with tempfile.TemporaryDirectory(prefix="wirecheck-fuzz-") as d:
            box = Path(d)
            (box / "in").mkdir()
            argv = make(pick, box, earlier)
            signal.alarm(TIMEOUT_S)
            try:
                outcome = run_cli(main, argv, box, cli)
            except FuzzTimeout:
                outcome = Outcome(-1, "", "", [f"timeout: over {TIMEOUT_S} s"])
            finally:
                signal.alarm(0)
        codes[outcome.rc] += 1
        for p in set(category(p) for p in outcome.problems):
            problems[p] += 1
        if outcome.problems and len(examples) < 20:
            examples.append(
                {
                    "input": i,
                    "argv": argv,
                    "rc": outcome.rc,
                    "problems": outcome.problems,
                    "stderr": outcome.stderr[-500:],
                }
            )
        if (i + 1 - start) % 500 == 0:
            print(
                f"{cli}: {i + 1 - start}/{n} ({time.perf_counter() - t0:.0f} s) exits {dict(sorted(codes.items()))} "
                f"problems {dict(problems)}",
                file=log,
                flush=True,
            )
    return {
        "cli": cli,
        "inputs": n,
        "seconds": round(time.perf_counter() - t0),
        "exit_codes": dict(sorted(codes.items())),
        "tracebacks": problems["tracebacks"],
        "exit codes outside {0, 1, 2, 3}": problems["exit codes outside {0, 1, 2, 3}"],
        "partial outputs or leftovers": problems["partial outputs or leftovers"],
        "user files touched": problems["user files touched"],
        "internal errors (exit 3)": problems["internal errors (exit 3)"],
        "exit 2 without exactly one stderr line": problems["exit 2 without exactly one stderr line"],
        "timeouts": problems["timeouts"],
        "inputs outside their folder": problems["inputs outside their folder"],
        "examples": examples,
    }


def fuzz_png(n: int, seed: int, start: int = 0) -> dict:
    """``n`` damaged PNG frames through read_png (tests/fuzz/png_inputs.py): outcomes and problems by kind."""
    from wirecheck.oracles.candidates.png_frame import FrameProblem, read_png

    from fuzz.png_inputs import check_png, hostile_png

    outcomes, problems, examples = collections.Counter(), collections.Counter(), []
    t0 = time.perf_counter()
    signal.signal(signal.SIGALRM, _timeout)
    with tempfile.TemporaryDirectory(prefix="wirecheck-fuzz-png-") as d:
        path = Path(d) / "frame.png"
        for i in range(start, start + n):
            pick = Pick(random.Random(f"{seed}-png-{i}"))
            width, height = pick.integer(1, 9), pick.integer(1, 5)
            path.write_bytes(hostile_png(pick, width, height))
            signal.alarm(TIMEOUT_S)
            try:
                found = check_png(read_png, FrameProblem, path, width, height)
                try:
                    read_png(path, width, height)
                    outcomes["read"] += 1
                except Exception:  # noqa: BLE001 - counted: FrameProblem or the traceback found above
                    outcomes["refused"] += 1
            except FuzzTimeout:
                found = [f"timeout: over {TIMEOUT_S} s"]
            finally:
                signal.alarm(0)
            for p in found:
                problems[p.split(":")[0]] += 1
            if found and len(examples) < 10:
                examples.append({"input": i, "problems": found})
    return {
        "surface": "png",
        "inputs": n,
        "seconds": round(time.perf_counter() - t0),
        "outcomes": dict(outcomes),
        "problems": dict(problems),
        "examples": examples,
    }


def fuzz_interrupts(n: int, seed: int, start: int = 0) -> dict:
    """``n`` renderer processes signalled at random moments (tests/fuzz/interrupts.py)."""
    from fuzz.interrupts import interrupt_one

    codes, problems, notes, examples = collections.Counter(), collections.Counter(), collections.Counter(), []
    t0 = time.perf_counter()
    for i in range(start, start + n):
        with tempfile.TemporaryDirectory(prefix="wirecheck-fuzz-sig-") as d:
            rc, found = interrupt_one(Pick(random.Random(f"{seed}-interrupt-{i}")), Path(d))
        codes[rc] += 1
        for p in found:
            (notes if p.startswith("note: ") else problems)[
                p.split(":")[0] if not p.startswith("note: ") else p[6:]
            ] += 1
        if any(not p.startswith("note: ") for p in found) and len(examples) < 10:
            examples.append({"input": i, "rc": rc, "problems": found})
    return {
        "surface": "interrupt",
        "inputs": n,
        "seconds": round(time.perf_counter() - t0),
        "exit_codes": dict(sorted(codes.items())),
        "problems": dict(problems),
        "notes": dict(notes),
        "examples": examples,
    }


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--inputs", type=int, default=10_000, help="inputs per CLI (default 10000)")
    p.add_argument(
        "--cli",
        choices=("renderer", "crosscheck", "both", "png", "interrupt"),
        default="both",
        help="png: damaged PNG frames for the image rule; interrupt: SIGINT/SIGTERM at random moments "
        "of renderer processes reading a textured OBJ",
    )
    p.add_argument("--seed", type=int, default=15)
    p.add_argument("--start", type=int, default=0, help="first input's index (split a run over processes)")
    p.add_argument("--json", default=None, help="also write the results here")
    a = p.parse_args(argv)
    warnings.simplefilter("ignore")  # the CLIs capture their own; the harness's are not the contract's
    os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa")
    from wirecheck.core.app import cli as renderer

    if a.cli in ("png", "interrupt"):
        r = (fuzz_png if a.cli == "png" else fuzz_interrupts)(a.inputs, a.seed, a.start)
        print(json.dumps(r, indent=1))
        if a.json:
            Path(a.json).write_text(json.dumps([r], indent=1) + "\n")
        return 1 if r["problems"] else 0
    results = []
    with tempfile.TemporaryDirectory(prefix="wirecheck-fuzz-earlier-") as d:
        earlier = Path(d) / "out"
        assert (
            renderer.main(
                ["--frames", "2", "--width", "32", "--height", "24", "--format", "png,gif", "--out", str(earlier)]
            )
            == 0
        )
        for cli in ("renderer", "crosscheck") if a.cli == "both" else (a.cli,):
            results.append(fuzz(cli, a.inputs, a.seed, earlier, sys.stderr, a.start))
    for r in results:
        print(f"{r['cli']}: {r['inputs']} inputs in {r['seconds']} s; exit codes {r['exit_codes']}")
        for key in (
            "tracebacks",
            "exit codes outside {0, 1, 2, 3}",
            "partial outputs or leftovers",
            "user files touched",
            "internal errors (exit 3)",
            "exit 2 without exactly one stderr line",
            "timeouts",
            "inputs outside their folder",
        ):
            print(f"  {key}: {r[key]}")
        for ex in r["examples"][:5]:
            print(f"  e.g. input {ex['input']}: exit {ex['rc']} {ex['problems']}: {ex['argv']}")
    if a.json:
        Path(a.json).write_text(json.dumps(results, indent=1) + "\n")
    bad = sum(
        r[k]
        for r in results
        for k in (
            "tracebacks",
            "exit codes outside {0, 1, 2, 3}",
            "partial outputs or leftovers",
            "user files touched",
            "timeouts",
            "inputs outside their folder",
        )
    )
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
