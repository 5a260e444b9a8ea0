"""Fuzz round 5: the spec suite, depth maps, unprojectors, the memory budget and OBJ faces.

    nice .venv/bin/python benchmarks/fuzz_round5.py                   # every surface (a few minutes)
    .venv/bin/python benchmarks/fuzz_round5.py --surface depth        # or spec, unproject, peer, budget, obj
    .venv/bin/python benchmarks/fuzz_round5.py --json r5.json         # also write the counts as JSON

Surfaces (every input is listed; the random ones (depth-map byte mutations) come from --seed):

- spec: ``crosscheck --suite spec --level vertices`` with hostile ``--candidate`` projectors (hangs,
  ``os._exit``, ``sys.exit``, NaN, inf, 1e300, wrong shapes, None, a list, a generator, float16,
  raising on the empty mesh only) and option combinations (``--candidate-precision`` with and without a
  candidate, ``--unprojector``, ``--sweep``, ``--scene``, ``--frames``, ``--candidate-cmd`` garbage).
- unproject: ``crosscheck --unprojector FILE.py:FUNC`` (its own process) and ``check_unprojector(func)``
  (in process, a driver below) with unprojectors that hang, exit, return wrong shapes, NaN, inf,
  float16, lists, None, (N, 2), (N, 4), a generator, strings, complex, huge values; zero points.
- peer: ``crosscheck --unprojector-cmd`` and ``--candidate-cmd`` programs that write garbage, short
  replies, huge length headers, wrong counts, NaN bytes, endless lines, or hang.
- depth: ``read_depth_map`` (a driver below, one file per subprocess) on .npy of every dtype, object
  arrays (a pickle that would write a file when loaded), Fortran order, 0-d/1-d/3-d, huge and truncated
  headers; TIFFs and PNGs of every mode and bit depth; FIFOs, devices, folders, a sparse 64 GiB file;
  negative, NaN, +-inf, subnormal values; wrong sizes; scales 0, -1, inf, NaN, subnormal, huge.
- budget: a dataset run (``crosscheck --scene DIR --level vertices``) with ``--memory-budget`` 0, -1,
  nan, inf, 1e300, tiny, and not a number.
- obj: OBJ files whose faces have 0, 1, 2 indices, negative, zero and out-of-range indices, ``l``
  lines, mixed, through ``crosscheck --scene FILE.obj`` and ``renderer --scene FILE.obj``.

Each input runs in a subprocess in a fresh folder (``in/`` its files, ``out/`` where it may write) under
a timeout (past it: a hang, the process group killed). Counted: inputs; exit statuses; tracebacks (any
``Traceback`` on stderr, or exit 3); hangs; exit 2 without exactly one stderr line; user files touched
(every regular file under ``in/`` hashed before and after; a special file's kind checked, never opened);
leftovers (anything in ``out/`` after an exit other than 0 or 1, or a temporary file after any exit);
passes on nothing (exit 0 from an input that must not pass). The counts go to docs/reliability.md
("Round 5: the spec suite, depth maps and unprojectors").
"""

from __future__ import annotations

import argparse
import collections
import hashlib
import json
import os
import random
import signal
import stat
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PY = sys.executable
CROSSCHECK = [PY, "-m", "wirecheck.oracles.cli"]
RENDERER = [PY, "-m", "wirecheck.core.app.cli"]
TIMEOUT_S = 90
SPARSE_BYTES = 64 << 30
QUICK_UNPROJECT = ["--scene", "cube", "--cases", "on_axis", "--frames", "1"]

# ---- hostile projectors and unprojectors (written into each input's in/ folder) ------------------------

CANDIDATES = """
import os, sys, time
import numpy as np
sys.path.insert(0, TESTS_DATA)
from user_projector import project as _core      # a correct projector written from the contract alone


def _ok(points, camera):
    return _core(points, camera)


def correct(points, camera):
    return _ok(points, camera)
def hang(points, camera):
    time.sleep(3600)
def hard_exit(points, camera):
    os._exit(0)
def sys_exit(points, camera):
    sys.exit(0)
def kill_self(points, camera):
    os.kill(os.getpid(), 9)
def nan(points, camera):
    return np.full((len(points), 2), np.nan)
def inf(points, camera):
    return np.full((len(points), 2), np.inf)
def huge(points, camera):
    return np.full((len(points), 2), 1e300)
def shape_n3(points, camera):
    return np.zeros((len(points), 3))
def shape_2n(points, camera):
    return np.zeros((2, len(points)))
def flat(points, camera):
    return np.zeros(2 * len(points))
def none(points, camera):
    return None
def as_list(points, camera):
    return np.asarray(_ok(points, camera)).tolist()
def generator(points, camera):
    return (row for row in np.asarray(_ok(points, camera)))
def float16(points, camera):
    return np.asarray(_ok(points, camera)).astype(np.float16)
def strings(points, camera):
    return np.full((len(points), 2), "1")
def complex_(points, camera):
    return np.asarray(_ok(points, camera)).astype(complex)
def raises_on_empty(points, camera):
    if len(points) == 0:
        raise ValueError("no points")
    return _ok(points, camera)
def nan_on_empty(points, camera):
    return _ok(points, camera) if len(points) else np.full((1, 2), np.nan)
def prints(points, camera):
    print("x" * 100000)
    return _ok(points, camera)
"""

UNPROJECTORS = """
import os, sys, time
import numpy as np


def correct(pixels, depth, camera):
    K, R, t = np.asarray(camera.K), np.asarray(camera.R), np.asarray(camera.t)
    x = (pixels[:, 0] - K[0, 2]) / K[0, 0]
    y = (pixels[:, 1] - K[1, 2]) / K[1, 1]
    p_cv = np.stack([x * depth, y * depth, depth], axis=1) if camera.projection == "perspective" else \\
        np.stack([x, y, depth], axis=1)
    return (p_cv - t) @ R


def hang(pixels, depth, camera):
    time.sleep(3600)
def hard_exit(pixels, depth, camera):
    os._exit(0)
def sys_exit(pixels, depth, camera):
    sys.exit(0)
def kill_self(pixels, depth, camera):
    os.kill(os.getpid(), 9)
def nan(pixels, depth, camera):
    return np.full((len(depth), 3), np.nan)
def inf(pixels, depth, camera):
    return np.full((len(depth), 3), np.inf)
def neg_inf(pixels, depth, camera):
    return np.full((len(depth), 3), -np.inf)
def huge(pixels, depth, camera):
    return np.full((len(depth), 3), 1e300)
def nan_one(pixels, depth, camera):
    out = correct(pixels, depth, camera)
    out[0] = np.nan
    return out
def float16(pixels, depth, camera):
    return correct(pixels, depth, camera).astype(np.float16)
def as_list(pixels, depth, camera):
    return correct(pixels, depth, camera).tolist()
def none(pixels, depth, camera):
    return None
def n2(pixels, depth, camera):
    return correct(pixels, depth, camera)[:, :2]
def n4(pixels, depth, camera):
    return np.hstack([correct(pixels, depth, camera), np.ones((len(depth), 1))])
def transposed_shape(pixels, depth, camera):
    return correct(pixels, depth, camera).T
def generator(pixels, depth, camera):
    return (row for row in correct(pixels, depth, camera))
def strings(pixels, depth, camera):
    return np.full((len(depth), 3), "1")
def complex_(pixels, depth, camera):
    return correct(pixels, depth, camera).astype(complex)
def bools(pixels, depth, camera):
    return np.ones((len(depth), 3), dtype=bool)
def ints(pixels, depth, camera):
    return np.rint(correct(pixels, depth, camera)).astype(np.int64)
def int_huge(pixels, depth, camera):
    return np.full((len(depth), 3), 2 ** 62, dtype=np.int64)
def uint64(pixels, depth, camera):
    return np.full((len(depth), 3), 2 ** 64 - 1, dtype=np.uint64)
def zeros(pixels, depth, camera):
    return np.zeros((len(depth), 3))
def scalar(pixels, depth, camera):
    return 1.0
def masked(pixels, depth, camera):
    return np.ma.masked_all((len(depth), 3))
def matrix(pixels, depth, camera):
    return np.matrix(correct(pixels, depth, camera))
def object_array(pixels, depth, camera):
    return correct(pixels, depth, camera).astype(object)
def mutates_input(pixels, depth, camera):
    pixels[:] = np.nan
    depth[:] = -1
    return np.zeros((len(depth), 3))
def prints(pixels, depth, camera):
    print("x" * 100000)
    return correct(pixels, depth, camera)
def raises_base(pixels, depth, camera):
    raise KeyboardInterrupt
def raises_recursion(pixels, depth, camera):
    return raises_recursion(pixels, depth, camera)
def not_callable_two(pixels, camera):
    return pixels
"""

# Unprojectors a correct judge may pass (their answers are right, whatever their container).
UNPROJECT_MAY_PASS = {"correct", "as_list", "ints", "matrix", "object_array", "prints", "generator"}

PEER = r"""
import json, sys, time
import numpy as np
mode = sys.argv[1]
stdin, stdout = sys.stdin.buffer, sys.stdout.buffer
HEADER = b"wirecheck-candidate 1\n"
line = stdin.readline()
if mode == "garbage_header":
    stdout.write(b"\x00\xff garbage\n"); stdout.flush(); time.sleep(5); sys.exit(0)
if mode == "no_newline_header":
    stdout.write(b"w" * (1 << 20)); stdout.flush(); time.sleep(3600)
if mode == "silent":
    time.sleep(3600)
if mode == "exit_at_once":
    sys.exit(3)
stdout.write(HEADER); stdout.flush()
cols = 3
while True:
    line = stdin.readline()
    if not line:
        sys.exit(0)
    req = json.loads(line)
    n = req["n"]
    cols = 3 if req.get("kind") == "unproject" else 2
    rows = stdin.read(n * 24)
    out = np.zeros((n, cols))
    body = out.astype("<f8").tobytes()
    if mode == "garbage_reply":
        stdout.write(b"\x89PNG garbage\n" + body)
    elif mode == "short_reply":
        stdout.write(json.dumps({"n": n}).encode() + b"\n" + body[: len(body) // 2]); stdout.flush(); time.sleep(3600)
    elif mode == "short_then_exit":
        stdout.write(json.dumps({"n": n}).encode() + b"\n" + body[: len(body) // 2]); stdout.flush(); sys.exit(0)
    elif mode == "huge_n":
        stdout.write(b'{"n": 1000000000000000000}\n'); stdout.flush(); time.sleep(3600)
    elif mode == "huge_n_exit":
        stdout.write(b'{"n": 1000000000000000000}\n' + body); stdout.flush(); sys.exit(0)
    elif mode == "negative_n":
        stdout.write(b'{"n": -5}\n')
    elif mode == "float_n":
        stdout.write(json.dumps({"n": n + 0.5}).encode() + b"\n" + body)
    elif mode == "string_n":
        stdout.write(json.dumps({"n": str(n)}).encode() + b"\n" + body)
    elif mode == "bool_n":
        stdout.write(b'{"n": true}\n' + body[:cols * 8])
    elif mode == "wrong_n":
        stdout.write(json.dumps({"n": n + 1}).encode() + b"\n" + body + b"\0" * cols * 8)
    elif mode == "nan_bytes":
        stdout.write(json.dumps({"n": n}).encode() + b"\n" + np.full((n, cols), np.nan).astype("<f8").tobytes())
    elif mode == "endless_line":
        stdout.write(b"{" + b" " * (1 << 22)); stdout.flush(); time.sleep(3600)
    elif mode == "json_list":
        stdout.write(b"[1, 2, 3]\n")
    elif mode == "huge_error":
        stdout.write(json.dumps({"error": "e" * 60000 + "\n\x1b[2J"}).encode() + b"\n")
    elif mode == "error_not_string":
        stdout.write(b'{"error": {"nested": [1, 2]}}\n')
    elif mode == "extra_bytes":
        stdout.write(json.dumps({"n": n}).encode() + b"\n" + body + b"trailing junk\n")
    elif mode == "nan_json":
        stdout.write(b'{"n": NaN}\n')
    elif mode == "deep_json":
        stdout.write(b"[" * 50000 + b"\n")
    elif mode == "exit_mid":
        sys.exit(0)
    elif mode == "stderr_flood":
        sys.stderr.write("noise\n" * 200000); sys.stderr.flush()
        stdout.write(json.dumps({"n": n}).encode() + b"\n" + body)
    stdout.flush()
"""
PEER_MODES = (
    "garbage_header",
    "no_newline_header",
    "silent",
    "exit_at_once",
    "garbage_reply",
    "short_reply",
    "short_then_exit",
    "huge_n",
    "huge_n_exit",
    "negative_n",
    "float_n",
    "string_n",
    "bool_n",
    "wrong_n",
    "nan_bytes",
    "endless_line",
    "json_list",
    "huge_error",
    "error_not_string",
    "extra_bytes",
    "nan_json",
    "deep_json",
    "exit_mid",
    "stderr_flood",
)


# ---- drivers run in the input's subprocess ------------------------------------------------------------


def depth_driver(path: str, width: int, height: int, scale) -> int:
    """read_depth_map on one file: 0 and a summary, 2 and one line (InputError), 4 an invalid map accepted."""
    import numpy as np
    from wirecheck.core.errors import InputError
    from wirecheck.oracles.candidates.depth_map import read_depth_map

    kwargs = {} if scale == "s:default" else {"scale": json.loads(scale[2:])}
    try:
        m = read_depth_map(path, width, height, **kwargs)
    except InputError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    d = m.depth
    ok = (
        isinstance(d, np.ndarray)
        and d.dtype == np.float64
        and d.shape == (height, width)
        and bool(np.all(np.isnan(d) | (np.isfinite(d) & (d > 0))))
        and all(isinstance(v, float) and np.isfinite(v) and v >= 0 for v in (m.step, m.rel_step))
        and bool(np.all(np.isfinite(m.encoding_bound())))
    )
    print(f"read {m.encoding}: {int(np.isfinite(d).sum())} surface pixels, step {m.step!r}, rel {m.rel_step!r}")
    if not ok:
        print(
            f"invalid map accepted: dtype {d.dtype}, shape {d.shape}, min {np.nanmin(d) if np.isfinite(d).any() else None}, "
            f"step {m.step!r}, rel_step {m.rel_step!r}",
            file=sys.stderr,
        )
        return 4
    return 0


def unproject_api_driver(file: str, func: str) -> int:
    """check_unprojector(FUNC) in process on the cube, on_axis, 1 frame: 0 pass, 1 fail, 2 InputError."""
    import importlib.util

    from wirecheck.core.errors import InputError
    from wirecheck.oracles.unprojector_api import check_unprojector

    spec = importlib.util.spec_from_file_location("hostile_unprojectors", file)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    scenes = ["cube"] if func != "ZERO_POINTS" else [str(Path(file).with_name("wire.scene"))]
    target = getattr(mod, "correct" if func == "ZERO_POINTS" else func)
    try:
        report = check_unprojector(target, scenes=scenes, cases=["on_axis"], frames=1)
    except InputError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    print(report["verdict"], report["compared"])
    return 0 if report["verdict"] == "pass" else 1


# ---- inputs ---------------------------------------------------------------------------------------------


class Input:
    """One hostile input: argv built in its box, whether exit 0 is allowed, its timeout."""

    def __init__(self, surface, name, build, may_pass=False, timeout=TIMEOUT_S, must_pass=False):
        self.surface, self.name, self.build, self.may_pass, self.timeout = surface, name, build, may_pass, timeout
        self.must_pass = must_pass  # a correct candidate in another container: failing it is a bug


def spec_inputs():
    out = []
    base = ["--suite", "spec", "--level", "vertices"]

    def cand(func, extra=()):
        def build(box):
            (box / "in" / "cands.py").write_text(CANDIDATES.replace("TESTS_DATA", repr(str(ROOT / "tests" / "data"))))
            wait = "0.5" if func == "hang" else "10"  # a correct one's first request waits for its start-up
            return (
                CROSSCHECK
                + base
                + [
                    "--candidate",
                    f"{box / 'in' / 'cands.py'}:{func}",
                    "--candidate-timeout",
                    wait,
                    "--report-dir",
                    str(box / "out" / "rep"),
                ]
                + list(extra)
            )

        return build

    for func in (
        "correct",
        "hang",
        "hard_exit",
        "sys_exit",
        "kill_self",
        "nan",
        "inf",
        "huge",
        "shape_n3",
        "shape_2n",
        "flat",
        "none",
        "as_list",
        "generator",
        "float16",
        "strings",
        "complex_",
        "raises_on_empty",
        "nan_on_empty",
        "prints",
    ):
        ok = func in ("correct", "as_list", "prints")
        out.append(
            Input(
                "spec",
                f"--candidate {func}",
                cand(func),
                may_pass=ok,
                must_pass=ok,
                timeout=120 if func == "hang" else TIMEOUT_S,
            )
        )
    for prec in ("float32", "float64"):
        out.append(
            Input(
                "spec",
                f"--candidate float16 --candidate-precision {prec}",
                cand("float16", ["--candidate-precision", prec]),
            )
        )
        out.append(
            Input(
                "spec",
                f"--candidate correct --candidate-precision {prec}",
                cand("correct", ["--candidate-precision", prec]),
                may_pass=True,
                must_pass=True,
            )
        )

    def combo(extra, with_cand=False):
        def build(box):
            (box / "in" / "cands.py").write_text(CANDIDATES.replace("TESTS_DATA", repr(str(ROOT / "tests" / "data"))))
            (box / "in" / "unp.py").write_text(UNPROJECTORS)
            argv = CROSSCHECK + base + ["--report-dir", str(box / "out" / "rep")]
            if with_cand:
                argv += ["--candidate", f"{box / 'in' / 'cands.py'}:correct"]
            return argv + [a.replace("IN", str(box / "in")) for a in extra]

        return build

    combos = [
        ["--candidate-precision", "float32"],
        ["--candidate-precision", "float16"],
        ["--candidate-precision", ""],
        ["--unprojector", "IN/unp.py:correct"],
        ["--unprojector-cmd", "true"],
        ["--sweep"],
        ["--scene", "cube"],
        ["--frames", "0"],
        ["--frames", "3"],
        ["--cases", "on_axis"],
        ["--candidate-frames", "IN"],
        ["--candidate-cmd", "IN/nothing-here"],
        ["--candidate-cmd", "'unbalanced"],
        ["--candidate-cmd", ""],
        ["--candidate-cmd", "false"],
        ["--candidate", "IN/cands.py:missing"],
        ["--candidate", "IN/cands.py"],
        ["--candidate", "IN/cands.py:correct", "--candidate-cmd", "true"],
        ["--no-report"],
        ["--run", "../../escape"],
        ["--memory-budget", "1"],
        ["--every", "0"],
        ["--oracles", "nothing"],
        ["--candidate-timeout", "0"],
        ["--candidate-timeout", "nan"],
        ["--candidate-timeout", "-1"],
        ["--suite", "spec"],
        ["--allow-vacuous"],
        ["--level", "pixels", "--gl", "nonsense"],
    ]
    for extra in combos:
        out.append(Input("spec", "spec " + " ".join(extra), combo(extra), may_pass=True))  # core: a real pass
    for mode in ("silent", "garbage_reply", "exit_at_once", "nan_bytes", "huge_n", "short_then_exit"):

        def build(box, mode=mode):
            (box / "in" / "peer.py").write_text(PEER)
            return (
                CROSSCHECK
                + base
                + [
                    "--candidate-cmd",
                    f"{PY} {box / 'in' / 'peer.py'} {mode}",
                    "--candidate-timeout",
                    "0.5",
                    "--report-dir",
                    str(box / "out" / "rep"),
                ]
            )

        out.append(Input("spec", f"--candidate-cmd peer {mode}", build, timeout=120))
    out.append(
        Input(
            "spec",
            "spec --candidate correct --candidate-precision float32 --candidate-cmd true",
            combo(["--candidate-cmd", "true"], with_cand=True),
            may_pass=True,
        )
    )
    return out


def unproject_inputs():
    out = []
    funcs = (
        "correct",
        "hang",
        "hard_exit",
        "sys_exit",
        "kill_self",
        "nan",
        "inf",
        "neg_inf",
        "huge",
        "nan_one",
        "float16",
        "as_list",
        "none",
        "n2",
        "n4",
        "transposed_shape",
        "generator",
        "strings",
        "complex_",
        "bools",
        "ints",
        "int_huge",
        "uint64",
        "zeros",
        "scalar",
        "masked",
        "matrix",
        "object_array",
        "mutates_input",
        "prints",
        "raises_base",
        "raises_recursion",
        "not_callable_two",
    )

    def cli(func):
        def build(box):
            (box / "in" / "unp.py").write_text(UNPROJECTORS)
            return (
                CROSSCHECK
                + ["--unprojector", f"{box / 'in' / 'unp.py'}:{func}", "--candidate-timeout", "2"]
                + QUICK_UNPROJECT
            )

        return build

    def api(func):
        def build(box):
            (box / "in" / "unp.py").write_text(UNPROJECTORS)
            (box / "in" / "wire.scene").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\ne 0 1\ne 1 2\n")
            return [PY, __file__, "--unproject-api", str(box / "in" / "unp.py"), func]

        return build

    for func in funcs:
        # ints: rounded world points, wrong; the API in process has no timeout for a callable: skip hang there
        may = func in UNPROJECT_MAY_PASS and func != "ints"
        must = func in ("correct", "as_list", "matrix", "prints")
        out.append(Input("unproject", f"--unprojector {func}", cli(func), may_pass=may, must_pass=must))
        if func not in ("hang", "hard_exit", "kill_self", "raises_base"):  # in process: they end the caller, by design
            out.append(Input("unproject", f"check_unprojector({func})", api(func), may_pass=may, must_pass=must))
    out.append(Input("unproject", "check_unprojector zero points (a wireframe scene)", api("ZERO_POINTS")))

    def zero_cli(box):
        (box / "in" / "unp.py").write_text(UNPROJECTORS)
        (box / "in" / "wire.scene").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\ne 0 1\ne 1 2\n")
        return CROSSCHECK + [
            "--unprojector",
            f"{box / 'in' / 'unp.py'}:correct",
            "--scene",
            str(box / "in" / "wire.scene"),
            "--cases",
            "on_axis",
            "--frames",
            "1",
        ]

    out.append(Input("unproject", "--unprojector zero points (a wireframe scene)", zero_cli))
    for extra in (
        ["--frames", "0"],
        ["--cases", ""],
        ["--cases", "nonsense"],
        ["--spin", "nan,0,0"],
        ["--spin", "1e308,1e308,1e308"],
        ["--scene", "nonexistent"],
        ["--sweep"],
        ["--suite", "spec"],
        ["--junit-xml", "OUT/j.xml"],
        ["--candidate-timeout", "0"],
        ["--unprojector-cmd", "true"],
    ):

        def build(box, extra=extra):
            (box / "in" / "unp.py").write_text(UNPROJECTORS)
            return (
                CROSSCHECK
                + ["--unprojector", f"{box / 'in' / 'unp.py'}:correct", "--scene", "cube", "--cases", "on_axis"]
                + [a.replace("OUT", str(box / "out")) for a in extra]
            )

        out.append(
            Input(
                "unproject",
                "--unprojector correct " + " ".join(extra),
                build,
                may_pass=extra[0] in ("--spin",) and extra[1].startswith("1e"),
            )
        )
    return out


def peer_inputs():
    out = []
    for mode in PEER_MODES:
        for flag in ("--unprojector-cmd", "--candidate-cmd"):

            def build(box, mode=mode, flag=flag):
                (box / "in" / "peer.py").write_text(PEER)
                cmd = f"{PY} {box / 'in' / 'peer.py'} {mode}"
                if flag == "--unprojector-cmd":
                    return CROSSCHECK + [flag, cmd, "--candidate-timeout", "2"] + QUICK_UNPROJECT
                return CROSSCHECK + [
                    flag,
                    cmd,
                    "--candidate-timeout",
                    "2",
                    "--level",
                    "vertices",
                    "--scene",
                    "cube",
                    "--cases",
                    "on_axis",
                    "--frames",
                    "1",
                    "--report-dir",
                    str(box / "out" / "rep"),
                ]

            out.append(Input("peer", f"{flag} peer {mode}", build))
    return out


def _npy(path: Path, header: bytes, body: bytes = b"", version=(1, 0)):
    magic = b"\x93NUMPY" + bytes(version)
    pad = 64 - (len(magic) + 2 + len(header) + 1) % 64
    h = header + b" " * (pad % 64) + b"\n"
    path.write_bytes(magic + len(h).to_bytes(2, "little") + h + body)


def depth_inputs(seed: int):
    import numpy as np
    from PIL import Image

    W, H = 8, 6
    out = []

    def add(name, make, may_pass=False, size=(W, H), scale="default"):
        def build(box):
            path = make(box / "in")
            return [PY, __file__, "--depth-one", str(path), str(size[0]), str(size[1]), "s:" + scale]

        out.append(Input("depth", name, build, may_pass=may_pass, timeout=60))

    good = np.linspace(0.5, 3.0, W * H).reshape(H, W)

    def npy_of(arr, name="d.npy", **kw):
        def make(d):
            np.save(d / name, arr, **kw)
            return d / name

        return make

    for dt in (
        "float32",
        "float64",
        "float16",
        "longdouble",
        "int8",
        "uint8",
        "int16",
        "uint16",
        "int32",
        "uint32",
        "int64",
        "uint64",
        "bool",
        "complex64",
        "complex128",
        ">f4",
        ">f8",
        "<f4",
        "U3",
        "S3",
        "m8[s]",
        "M8[s]",
        "V8",
        [("a", "<f4"), ("b", "<f4")],
    ):
        dname = dt if isinstance(dt, str) else "structured"
        try:
            arr = good.astype(dt)
        except (TypeError, ValueError):
            arr = np.zeros((H, W), dtype=dt)
        add(f".npy {dname}", npy_of(arr), may_pass=dname in ("float32", "float64", "<f4", ">f4", ">f8"))
    add(".npy fortran float32", npy_of(np.asfortranarray(good.astype(np.float32))), may_pass=True)
    add(".npy 0-d", npy_of(np.float32(1.0)))
    add(".npy 1-d", npy_of(good.ravel().astype(np.float32)))
    add(".npy 3-d", npy_of(good.astype(np.float32)[None]))
    add(".npy (H, W, 1)", npy_of(good.astype(np.float32)[..., None]))
    add(".npy transposed (W, H)", npy_of(good.T.astype(np.float32).copy()))
    add(".npy empty (0, 0)", npy_of(np.zeros((0, 0), np.float32)), size=(0, 0))
    add(".npy zero width asked", npy_of(np.zeros((6, 0), np.float32)), size=(0, 6))

    def pickle_bomb(d):
        marker = d.parent / "out" / "PWNED"

        class Evil:
            def __reduce__(self):
                return (open, (str(marker), "w"))

        arr = np.empty((H, W), dtype=object)
        arr[0, 0] = Evil()
        with open(d / "d.npy", "wb") as fh:
            np.lib.format.write_array(fh, arr, allow_pickle=True)
        return d / "d.npy"

    add(".npy object array (a pickle that writes a file)", pickle_bomb)
    add(".npy object array of floats", npy_of(good.astype(object), allow_pickle=True))
    for name, header, body in [
        ("truncated body", b"{'descr': '<f4', 'fortran_order': False, 'shape': (6, 8), }", b"\0" * 17),
        (
            "header claims 2^40 x 2^40",
            b"{'descr': '<f4', 'fortran_order': False, 'shape': (1099511627776, 1099511627776), }",
            b"",
        ),
        (
            "header claims (6, 8) of 2^40-byte void",
            b"{'descr': '|V1099511627776', 'fortran_order': False, 'shape': (6, 8), }",
            b"",
        ),
        ("negative shape", b"{'descr': '<f4', 'fortran_order': False, 'shape': (-6, -8), }", b""),
        ("header not a dict", b"[1, 2, 3]", b""),
        ("header code", b"__import__('os').system('touch PWNED2')", b""),
        ("header huge ints", b"{'descr': '<f4', 'fortran_order': False, 'shape': (" + b"9" * 4000 + b", 8), }", b""),
        ("descr object", b"{'descr': '|O', 'fortran_order': False, 'shape': (6, 8), }", b"\x80\x04N."),
        ("fortran not bool", b"{'descr': '<f4', 'fortran_order': 'yes', 'shape': (6, 8), }", b"\0" * 192),
        ("extra key", b"{'descr': '<f4', 'fortran_order': False, 'shape': (6, 8), 'x': 1}", b"\0" * 192),
        ("float shape", b"{'descr': '<f4', 'fortran_order': False, 'shape': (6.0, 8.0), }", b"\0" * 192),
    ]:

        def make(d, header=header, body=body):
            _npy(d / "d.npy", header, body)
            return d / "d.npy"

        add(f".npy {name}", make)

    def big_header(d):  # version 2: a 4-byte header length of 2^31
        (d / "d.npy").write_bytes(b"\x93NUMPY\x02\x00" + (2**31).to_bytes(4, "little") + b"{")
        return d / "d.npy"

    add(".npy header length 2^31 (v2)", big_header)

    def not_npy(d):
        (d / "d.npy").write_bytes(b"\x93NUMPX" + b"\0" * 100)
        return d / "d.npy"

    add(".npy bad magic", not_npy)

    def empty_file(d, suffix):
        def make(dd):
            (dd / f"d{suffix}").write_bytes(b"")
            return dd / f"d{suffix}"

        return make

    for suffix in (".npy", ".png", ".tif"):
        add(f"empty {suffix}", empty_file(None, suffix))

    rng = random.Random(seed)
    valid_npy = None

    def mutated(k):
        def make(d):
            import io

            buf = io.BytesIO()
            np.save(buf, good.astype(np.float32))
            data = bytearray(buf.getvalue())
            r = random.Random(seed * 1000 + k)
            for _ in range(r.randint(1, 6)):
                i = r.randrange(0, 128)  # the magic and the header
                data[i] = r.randrange(256)
            (d / "d.npy").write_bytes(bytes(data))
            return d / "d.npy"

        return make

    for k in range(12):
        add(f".npy header mutation {k} (seed {seed})", mutated(k), may_pass=True)  # may still be a valid map
    del rng, valid_npy

    # values
    for name, val in (
        ("negative", -1.0),
        ("nan", np.nan),
        ("+inf", np.inf),
        ("-inf", -np.inf),
        ("subnormal", 1e-310),
        ("float32 subnormal", 1e-40),
        ("-0.0", -0.0),
        ("1e38", 1e38),
        ("float64 1e300", 1e300),
    ):
        arr = good.copy()
        arr[2, 3] = val
        dt = np.float32 if name in ("float32 subnormal", "1e38") else np.float64
        add(
            f".npy value {name}",
            npy_of(arr.astype(dt)),
            may_pass=name in ("nan", "+inf", "subnormal", "float32 subnormal", "-0.0", "1e38", "float64 1e300"),
        )
    add(".npy all NaN", npy_of(np.full((H, W), np.nan, np.float32)), may_pass=True)
    add(".npy wrong size", npy_of(good.astype(np.float32)), size=(W + 1, H))
    add(".npy huge size asked", npy_of(good.astype(np.float32)), size=(2**31, 2**31))
    add(".npy negative size asked", npy_of(good.astype(np.float32)), size=(-8, -6))

    # images
    def img(mode, suffix, arr=None, **save):
        def make(d):
            if mode == "F":
                im = Image.fromarray(good.astype(np.float32))
            elif mode in ("I;16", "I;16B", "I;16L"):
                im = Image.fromarray((good * 1000).astype(np.uint16))
                if mode != "I;16":
                    im = im.convert(mode)
            elif mode == "I":
                im = Image.fromarray((good * 1000).astype(np.int32))
            elif mode == "1":
                im = Image.new("1", (W, H), 1)
            elif mode == "P":
                im = Image.new("P", (W, H), 3)
            else:
                im = Image.new(mode, (W, H))
            im.save(d / f"d{suffix}", **save)
            return d / f"d{suffix}"

        return make

    for mode in ("F", "I", "I;16", "L", "LA", "P", "PA", "RGB", "RGBA", "CMYK", "1", "YCbCr", "LAB", "HSV", "I;16B"):
        for suffix in (".tif", ".png"):
            ok = (mode, suffix) in (("F", ".tif"), ("I;16", ".png"), ("I;16B", ".png"))  # a PNG is big-endian

            def safe(d, mode=mode, suffix=suffix):
                try:
                    return img(mode, suffix)(d)
                except (OSError, ValueError, KeyError):  # Pillow cannot write it: write a stub
                    p = d / f"d{suffix}"
                    p.write_bytes(b"")
                    return p

            add(f"{suffix} mode {mode}", safe, may_pass=ok)
    for comp in ("tiff_lzw", "tiff_deflate", "packbits", "tiff_adobe_deflate"):
        add(f".tif F {comp}", img("F", ".tif", compression=comp), may_pass=True)

    def png_raw(bit_depth, color_type, palette=False, w=W, h=H, trunc=False, idat=None):
        """A PNG written by hand (any bit depth and colour type, valid or not)."""
        import struct
        import zlib

        def chunk(t, data):
            return struct.pack(">I", len(data)) + t + data + struct.pack(">I", zlib.crc32(t + data) & 0xFFFFFFFF)

        def make(d):
            channels = {0: 1, 2: 3, 3: 1, 4: 2, 6: 4}.get(color_type, 1)
            row = (w * channels * bit_depth + 7) // 8
            raw = (
                idat
                if idat is not None
                else b"".join(b"\0" + bytes(range(row))[:row].ljust(row, b"\1") for _ in range(h))
            )
            data = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, bit_depth, color_type, 0, 0, 0))
            if palette:
                data += chunk(b"PLTE", bytes(range(48)))
            data += chunk(b"IDAT", zlib.compress(raw))
            if not trunc:
                data += chunk(b"IEND", b"")
            else:
                data = data[: len(data) - 9]
            (d / "d.png").write_bytes(data)
            return d / "d.png"

        return make

    for bd, ct in (
        (1, 0),
        (2, 0),
        (4, 0),
        (8, 0),
        (16, 0),
        (16, 2),
        (16, 4),
        (16, 6),
        (8, 3),
        (4, 3),
        (16, 3),
        (3, 0),
        (0, 0),
        (32, 0),
        (16, 1),
        (16, 5),
    ):
        add(
            f".png hand-written bit depth {bd} colour type {ct}",
            png_raw(bd, ct, palette=ct == 3),
            may_pass=(bd, ct) == (16, 0),
        )
    add(".png 16-bit truncated", png_raw(16, 0, trunc=True))
    add(".png 16-bit IDAT short", png_raw(16, 0, idat=b"\0\1\2"))
    add(".png 16-bit 2^31 x 1", png_raw(16, 0, w=2**31 - 1, h=1, idat=b"\0"))
    add(".png 16-bit 100000 x 100000 (decompression bomb)", png_raw(16, 0, w=100000, h=100000, idat=b"\0"))
    add(".png 16-bit 0 x 0", png_raw(16, 0, w=0, h=0, idat=b""))
    add(
        ".png 16-bit values all zero",
        png_raw(16, 0, idat=b"".join(b"\0" + b"\0" * 16 for _ in range(H))),
        may_pass=True,
    )
    for name, scale in (
        ("0", "0"),
        ("-1", "-1"),
        ("inf", "Infinity"),
        ("nan", "NaN"),
        ("-inf", "-Infinity"),
        ("1e-320 (subnormal)", "1e-320"),
        ("1e-300", "1e-300"),
        ("1e308", "1e308"),
        ("true", "true"),
        ("string", '"1000"'),
        ("list", "[1000]"),
        ("null", "null"),
        ("2^70", str(2**70)),
        ("5000", "5000"),
    ):
        add(
            f".png scale {name}", img("I;16", ".png"), scale=scale, may_pass=name in ("5000", "1e308", "2^70", "1e-300")
        )
        if name in ("0", "nan", "1e-320 (subnormal)"):
            add(f".npy scale {name}", npy_of(good.astype(np.float32)), scale=scale)

    # special files
    def special(kind, suffix):
        def make(d):
            p = d / f"d{suffix}"
            if kind == "fifo":
                os.mkfifo(p)
            elif kind.startswith("dev_"):
                p.symlink_to("/dev/" + kind[4:])
            elif kind == "folder":
                p.mkdir()
            elif kind == "sparse_64GiB":
                with open(p, "wb") as fh:
                    fh.truncate(SPARSE_BYTES)
            elif kind == "link_loop":
                p.symlink_to(p)
            elif kind == "dangling":
                p.symlink_to(d / "nowhere")
            elif kind == "missing":
                pass
            elif kind == "unreadable":
                np.save(p, good.astype(np.float32)) if suffix == ".npy" else img("I;16", ".png")(d)
                os.chmod(p if suffix == ".npy" else d / "d.png", 0)
            return p

        return make

    for kind in (
        "fifo",
        "dev_zero",
        "dev_urandom",
        "dev_null",
        "folder",
        "sparse_64GiB",
        "link_loop",
        "dangling",
        "missing",
        "unreadable",
    ):
        for suffix in (".npy", ".png", ".tif"):
            if kind == "unreadable" and suffix == ".tif":
                continue
            add(f"{suffix} {kind}", special(kind, suffix), may_pass=kind == "unreadable" and os.geteuid() == 0)

    def sparse_npy_valid_header(d):  # a real header, then 64 GiB of holes
        p = d / "d.npy"
        _npy(p, b"{'descr': '<f4', 'fortran_order': False, 'shape': (131072, 131072), }")
        with open(p, "r+b") as fh:
            fh.truncate(SPARSE_BYTES + 128)
        return p

    add(".npy sparse 64 GiB with a valid header", sparse_npy_valid_header, size=(131072, 131072))
    add(".npy sparse 64 GiB header, small size asked", sparse_npy_valid_header)
    for suffix in (".exr", ".jpg", "", ".NPY", ".npy.gz"):

        def make(d, suffix=suffix):
            p = d / f"d{suffix}" if suffix else d / "d"
            np.save(d / "x.npy", good.astype(np.float32))
            os.replace(d / "x.npy", p)
            return p

        add(f"suffix '{suffix}'", make, may_pass=suffix == ".NPY")
    return out


def budget_inputs():
    out = []
    obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n"
    for val in (
        "0",
        "-1",
        "nan",
        "-nan",
        "inf",
        "-inf",
        "1e300",
        "1e-300",
        "5e-324",
        "1e-9",
        "0.5",
        "abc",
        "",
        "1e400",
        "0x10",
        "1_0",
        "١",
        "2",
        "-0",
    ):

        def build(box, val=val):
            (box / "in" / "ds").mkdir()
            (box / "in" / "ds" / "a.obj").write_text(obj)
            return CROSSCHECK + [
                "--scene",
                str(box / "in" / "ds"),
                "--level",
                "vertices",
                "--frames",
                "1",
                "--cases",
                "on_axis",
                "--report-dir",
                str(box / "out" / "rep"),
                "--memory-budget",
                val,
            ]

        out.append(Input("budget", f"--memory-budget {val!r}", build, may_pass=val in ("1e300", "2", "0.5", "inf")))
    for extra in (["--scene", "cube"], []):

        def build(box, extra=extra):
            return (
                CROSSCHECK
                + extra
                + [
                    "--level",
                    "vertices",
                    "--frames",
                    "1",
                    "--cases",
                    "on_axis",
                    "--report-dir",
                    str(box / "out" / "rep"),
                    "--memory-budget",
                    "1",
                ]
            )

        out.append(Input("budget", "--memory-budget without a dataset " + " ".join(extra), build))

    def empty_ds(box):
        (box / "in" / "ds").mkdir()
        return CROSSCHECK + [
            "--scene",
            str(box / "in" / "ds"),
            "--level",
            "vertices",
            "--report-dir",
            str(box / "out" / "rep"),
            "--memory-budget",
            "1",
        ]

    out.append(Input("budget", "--memory-budget 1 on an empty folder", empty_ds))

    def all_over(box):
        (box / "in" / "ds").mkdir()
        (box / "in" / "ds" / "a.obj").write_text(obj)
        (box / "in" / "ds" / "b.obj").write_text(obj)
        return CROSSCHECK + [
            "--scene",
            str(box / "in" / "ds"),
            "--level",
            "vertices",
            "--frames",
            "1",
            "--cases",
            "on_axis",
            "--report-dir",
            str(box / "out" / "rep"),
            "--memory-budget",
            "1e-6",
            "--allow-load-errors",
        ]

    out.append(Input("budget", "--memory-budget 1e-6 --allow-load-errors: every mesh over it", all_over))
    return out


OBJ_BODIES = {
    "f with 0 indices": "v 0 0 0\nv 1 0 0\nv 0 1 0\nf\n",
    "f with 1 index": "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1\n",
    "f with 2 indices": "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n",
    "f with index 0": "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n",
    "f with negative indices (valid)": "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -3\n",
    "f with negative out of range": "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -9\n",
    "f with out-of-range index": "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99\n",
    "f with 2^63": "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9223372036854775808\n",
    "f with non-number": "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n",
    "f 1/1/1 style": "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\nf 1/1/1 2/1/1 3/1/1\n",
    "f with empty slashes": "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1// 2// //\n",
    "f repeated index": "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 1 1\n",
    "only l lines": "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\nl 2 3\n",
    "l with 1 index": "v 0 0 0\nv 1 0 0\nl 1\n",
    "l with out-of-range": "v 0 0 0\nv 1 0 0\nl 1 9\n",
    "l with index 0": "v 0 0 0\nv 1 0 0\nl 0 1\n",
    "l negative": "v 0 0 0\nv 1 0 0\nl -1 -2\n",
    "mixed f and l": "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nl 3 4\n",
    "mixed good f and f with 2": "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 3 4\n",
    "no vertices, a face": "f 1 2 3\n",
    "vertices only": "v 0 0 0\nv 1 0 0\nv 0 1 0\n",
    "empty": "",
    "v with nan": "v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    "v with inf": "v inf 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    "v with 2 coordinates": "v 0 0\nv 1 0\nv 0 1\nf 1 2 3\n",
    "v 1e308": "v 1e308 0 0\nv -1e308 0 0\nv 0 1e308 0\nf 1 2 3\n",
    "degenerate face (all same point)": "v 0 0 0\nv 0 0 0\nv 0 0 0\nf 1 2 3\n",
    "f with 10000 indices": "".join(f"v {i} {i % 7} 0\n" for i in range(10000))
    + "f "
    + " ".join(str(i + 1) for i in range(10000))
    + "\n",
    "NUL bytes": "v 0 0 0\nv 1 0 0\x00\nv 0 1 0\nf 1 2 3\n",
    "not UTF-8": "v 0 0 0\nv 1 0 0\nv 0 1 0\n\xff\xfe\nf 1 2 3\n",
    "p points only": "v 0 0 0\nv 1 0 0\np 1 2\n",
}
# Meshes a run at level vertices may pass: their vertices are compared (a mesh without edges fails at
# level pixels as vacuous); and the renderer draws what there is.
OBJ_MAY_NOT_PASS = {"empty", "no vertices, a face", "v with nan", "v with inf", "v with 2 coordinates"}


def obj_inputs():
    out = []
    for name, body in OBJ_BODIES.items():
        for tool in ("crosscheck", "renderer"):

            def build(box, body=body, tool=tool):
                p = box / "in" / "m.obj"
                p.write_bytes(body.encode("utf-8", "surrogateescape") if "\xff" not in body else body.encode("latin-1"))
                if tool == "crosscheck":
                    return CROSSCHECK + [
                        "--scene",
                        str(p),
                        "--level",
                        "vertices",
                        "--frames",
                        "1",
                        "--cases",
                        "on_axis",
                        "--report-dir",
                        str(box / "out" / "rep"),
                    ]
                return RENDERER + [
                    "--scene",
                    str(p),
                    "--frames",
                    "1",
                    "--width",
                    "64",
                    "--height",
                    "48",
                    "--out",
                    str(box / "out" / "f.png"),
                ]

            out.append(
                Input("obj", f"{tool} {name}", build, may_pass=name not in OBJ_MAY_NOT_PASS or tool == "renderer")
            )
    return out


SURFACES = {
    "spec": spec_inputs,
    "unproject": unproject_inputs,
    "peer": peer_inputs,
    "depth": depth_inputs,
    "budget": budget_inputs,
    "obj": obj_inputs,
}


# ---- running and checking -------------------------------------------------------------------------------


def snapshot(folder: Path) -> dict:
    """Every path under ``folder``: a regular file's SHA-256, else its kind (a special file is never opened)."""
    out = {}
    for p in sorted(folder.rglob("*")):
        try:
            st = p.lstat()
        except OSError:
            continue
        if stat.S_ISREG(st.st_mode):
            try:
                out[str(p)] = (
                    hashlib.sha256(p.read_bytes()).hexdigest()
                    if st.st_size < (1 << 26)
                    else f"size {st.st_size} mtime {st.st_mtime_ns}"
                )
            except OSError:
                out[str(p)] = f"unreadable {st.st_mtime_ns}"
        else:
            out[str(p)] = f"mode {stat.S_IFMT(st.st_mode)} {os.readlink(p) if stat.S_ISLNK(st.st_mode) else ''}"
    return out


def run_one(inp: Input, work: Path) -> dict:
    box = Path(tempfile.mkdtemp(prefix=f"{inp.surface}-", dir=work))
    (box / "in").mkdir()
    (box / "out").mkdir()
    argv = inp.build(box)
    before = snapshot(box / "in")
    env = dict(os.environ, PYTHONWARNINGS="default")
    t0 = time.monotonic()
    proc = subprocess.Popen(
        argv,
        cwd=box / "in",
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        stdin=subprocess.DEVNULL,
        env=env,
        start_new_session=True,
    )
    try:
        stdout, stderr = proc.communicate(timeout=inp.timeout)
        rc = proc.returncode
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        stdout, stderr = proc.communicate()
        rc = "hang"
    wall = time.monotonic() - t0
    after = snapshot(box / "in")
    err = stderr.decode("utf-8", "replace")
    lines = [ln for ln in err.splitlines() if ln.strip()]
    touched = sorted(k for k in before if after.get(k) != before[k])
    leftovers = []
    for p in sorted((box / "out").rglob("*")):
        if (
            rc not in (0, 1)
            or ".tmp" in p.name
            or p.name == "PWNED"
            or (p.name.startswith(".") and not p.name.startswith(".wirecheck"))
        ):  # an output folder's own marker
            leftovers.append(str(p.relative_to(box)))
    for p in (box / "in").rglob("*"):
        if (
            str(p) not in before
            and p.name not in ("__pycache__",)
            and "__pycache__" not in str(p)
            and not str(p.relative_to(box / "in")).startswith("reports")
        ):
            leftovers.append(str(p.relative_to(box)))
    rec = {
        "surface": inp.surface,
        "name": inp.name,
        "rc": rc,
        "wall_s": round(wall, 2),
        "traceback": "Traceback" in err or rc == 3,
        "hang": rc == "hang",
        "not_one_line": rc == 2 and len(lines) != 1,
        "touched": touched,
        "leftovers": leftovers,
        "pass_on_nothing": rc == 0 and not inp.may_pass,
        "bad_result": rc == 4,
        "correct_failed": inp.must_pass and rc != 0,
        "stderr": err[-600:] if (rc not in (0, 1) or "Traceback" in err) else err[-200:],
        "stdout_tail": stdout.decode("utf-8", "replace")[-300:],
    }
    rec["problem"] = bool(
        rec["traceback"]
        or rec["hang"]
        or rec["not_one_line"]
        or touched
        or leftovers
        or rec["pass_on_nothing"]
        or rec["bad_result"]
        or rec["correct_failed"]
        or rc not in (0, 1, 2)
    )
    return rec


def summary(records: list[dict]) -> dict:
    out = {}
    for surface in dict.fromkeys(r["surface"] for r in records):
        rs = [r for r in records if r["surface"] == surface]
        out[surface] = {
            "inputs": len(rs),
            "outcomes": dict(sorted(collections.Counter(str(r["rc"]) for r in rs).items())),
            "hangs": sum(r["hang"] for r in rs),
            "tracebacks": sum(r["traceback"] for r in rs),
            "exit 2 without one stderr line": sum(r["not_one_line"] for r in rs),
            "user files touched": sum(bool(r["touched"]) for r in rs),
            "leftovers": sum(bool(r["leftovers"]) for r in rs),
            "passes on nothing": sum(r["pass_on_nothing"] for r in rs),
            "invalid maps accepted": sum(r["bad_result"] for r in rs),
            "correct candidates failed": sum(r.get("correct_failed", False) for r in rs),
            "wall_s": round(sum(r["wall_s"] for r in rs), 1),
        }
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--surface", action="append", choices=sorted(SURFACES))
    ap.add_argument("--seed", type=int, default=5)
    ap.add_argument("--only", help="run the inputs whose name contains this")
    ap.add_argument("--json", help="write every record and the counts here")
    ap.add_argument("--depth-one", nargs=4, help=argparse.SUPPRESS)
    ap.add_argument("--unproject-api", nargs=2, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.depth_one:
        path, w, h, scale = args.depth_one
        return depth_driver(path, int(w), int(h), scale)
    if args.unproject_api:
        return unproject_api_driver(*args.unproject_api)
    surfaces = args.surface or list(SURFACES)
    inputs = []
    for s in surfaces:
        inputs += SURFACES[s](args.seed) if s == "depth" else SURFACES[s]()
    if args.only:
        inputs = [i for i in inputs if args.only in i.name]
    records = []
    with tempfile.TemporaryDirectory(prefix="fuzz5-") as work:
        for k, inp in enumerate(inputs, 1):
            rec = run_one(inp, Path(work))
            records.append(rec)
            if rec["problem"]:
                print(
                    f"[{k}/{len(inputs)}] PROBLEM {inp.surface}: {inp.name}: rc {rec['rc']}: "
                    f"{' | '.join(rec['stderr'].strip().splitlines()[-3:])[:400]}"
                    f"{' touched ' + str(rec['touched']) if rec['touched'] else ''}"
                    f"{' leftovers ' + str(rec['leftovers'][:3]) if rec['leftovers'] else ''}",
                    flush=True,
                )
        for root, dirs, _ in os.walk(work):  # the unreadable inputs, made removable
            for d in dirs:
                os.chmod(os.path.join(root, d), 0o755)
            for f in os.listdir(root):
                p = os.path.join(root, f)
                if os.path.isfile(p) and not os.path.islink(p):
                    os.chmod(p, 0o644)
    counts = summary(records)
    print(json.dumps(counts, indent=1))
    if args.json:
        Path(args.json).write_text(json.dumps({"seed": args.seed, "counts": counts, "records": records}, indent=1))
    return 1 if any(r["problem"] for r in records) else 0


if __name__ == "__main__":
    sys.exit(main())
