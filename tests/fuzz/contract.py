"""Hostile inputs for both CLIs, run in-process, checked against the contract (issue 15).

The contract, for any input:

- exit status 0, 1 or 2 (3, an internal error, is counted apart: a bug);
- on exit 2, exactly one line on stderr; never a traceback;
- nothing left behind: a failed run adds no path anywhere (no temporary, no
  empty folder); a run that succeeds adds paths only under its output folder,
  only with wirecheck's output names, and a complete set (as many frames as
  the report says);
- no file outside the output touched: every file the user had (inputs, decoys
  in the output folder, targets of symbolic links) has the same bytes after.

Inputs are drawn through a ``Pick`` (a seeded ``random.Random`` for the long
run, tests/fuzz/run_fuzz.py; hypothesis's ``data.draw`` for the suite,
tests/test_fuzz.py), so both explore the same space.
"""

from __future__ import annotations

import contextlib
import hashlib
import io
import json
import os
import re
import shutil
import struct
from dataclasses import dataclass, field
from pathlib import Path

NUMBERS = [
    "0",
    "-0",
    "1",
    "-1",
    "2.5",
    "4",
    "-4",
    "60",
    "179.9",
    "180",
    "1e-300",
    "1e308",
    "-1e308",
    "1e-30",
    "nan",
    "inf",
    "-inf",
    "abc",
    "",
    " ",
    "1,2",
    "0x10",
    "1_000",
    "9007199254740993",
]
VECTORS = [
    "1,1,0",
    "0,0,0",
    "1,2,3",
    "0,0,4",
    "1e308,0,0",
    "nan,0,0",
    "1,2",
    "1,2,3,4",
    "a,b,c",
    "",
    ",,",
    "-1e308,1e308,0",
    "1e-300,0,0",
    "0,1,0",
    "3,3,3",
    "inf,0,0",
]
INTS = ["0", "1", "2", "3", "-1", "7", "abc", "1.5", "100001", "100000000000000000000", ""]
SIZES = ["1", "2", "16", "33", "64", "0", "-5", "abc", "16385", "100000", "1e3"]
FORMATS = ["png", "ascii", "gif", "mp4", "png,gif", "png,ascii,gif", "bogus", "", "png,,", "gif,mp4"]

SCENE_TEXTS = [
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n",
    "name tri\nv -1 -1 0\nv 1 -1 0\nv 0 1 0\ne 0 1\ne 1 2\ne 2 0\n",
    "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nf 0 1 2 3\nobject b\nv 0 0 0\nv 0 0 1\ne 0 1\nspin 1 0 0\n"
    "translate 1 0 0\nscale 2\n",
    "object a\nmesh m.obj\nobject b\nmesh m.stl\ntranslate 0 2 0\n",
]
OBJ = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 3 4\nl 1 4\n"
PLY = (
    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
    "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"
)
STL = (
    "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid s\n"
)
OFF = "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"
TOKENS = [
    "v",
    "e",
    "f",
    "name",
    "object",
    "mesh",
    "spin",
    "scale",
    "translate",
    "0",
    "1",
    "2",
    "-1",
    "7",
    "1e308",
    "nan",
    "inf",
    "x" * 250,
    "m.obj",
    "../m.ply",
    "/etc/passwd",
    "a/b",
    ".hidden",
    "#",
    "\t",
    "1" + "0" * 400,
    "é",
    "\x00",
]


class Pick:
    """Draw choices from a seeded ``random.Random``."""

    def __init__(self, rng):
        self.rng = rng

    def choice(self, seq):
        return self.rng.choice(list(seq))

    def integer(self, lo: int, hi: int) -> int:
        return self.rng.randint(lo, hi)

    def chance(self, p: float) -> bool:
        return self.rng.random() < p


class HypothesisPick(Pick):
    """The same draws through hypothesis (shrinks to a minimal failing input)."""

    def __init__(self, data):
        from hypothesis import strategies as st

        self.data, self.st = data, st

    def choice(self, seq):
        return self.data.draw(self.st.sampled_from(list(seq)))

    def integer(self, lo, hi):
        return self.data.draw(self.st.integers(lo, hi))

    def chance(self, p):
        return self.data.draw(self.st.floats(0, 1)) < p


# ---- input files --------------------------------------------------------------------------------


def mutate_text(pick: Pick, text: str) -> str:
    lines = text.splitlines()
    for _ in range(pick.integer(0, 3)):
        op = pick.choice(["drop", "dup", "token", "insert", "swap_number"])
        k = pick.integer(0, max(0, len(lines) - 1)) if lines else 0
        if op == "drop" and lines:
            lines.pop(k)
        elif op == "dup" and lines:
            lines.insert(k, lines[k])
        elif op == "token" and lines:
            parts = lines[k].split() or [""]
            parts[pick.integer(0, len(parts) - 1)] = pick.choice(TOKENS)
            lines[k] = " ".join(parts)
        elif op == "insert":
            lines.insert(k, " ".join(pick.choice(TOKENS) for _ in range(pick.integer(1, 5))))
        elif lines:
            lines[k] = re.sub(r"-?\d+(\.\d+)?", lambda m: pick.choice(NUMBERS + INTS) or "0", lines[k], count=1)
    return "\n".join(lines) + ("\n" if pick.chance(0.9) else "")


def glb_bytes(indices=(0, 1, 2)) -> bytes:
    """A binary glTF: one triangle over 3 vertices with the given indices."""
    import numpy as np

    pos = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.float32).tobytes()
    buf = pos + np.array(indices, np.uint16).tobytes() + b"\0\0"
    gltf = {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "buffers": [{"byteLength": len(buf)}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 36},
            {"buffer": 0, "byteOffset": 36, "byteLength": 6},
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"},
        ],
    }
    j = json.dumps(gltf).encode()
    j += b" " * (-len(j) % 4)
    return (
        struct.pack("<III", 0x46546C67, 2, 28 + len(j) + len(buf))
        + struct.pack("<II", len(j), 0x4E4F534A)
        + j
        + struct.pack("<II", len(buf), 0x004E4942)
        + buf
    )


def mutate_bytes(pick: Pick, data: bytes) -> bytes:
    data = bytearray(data)
    for _ in range(pick.integer(0, 4)):
        op = pick.choice(["flip", "cut", "latin1", "nan"])
        k = pick.integer(0, max(0, len(data) - 1))
        if op == "flip" and data:
            data[k] = pick.integer(0, 255)
        elif op == "cut":
            del data[k:]
        elif op == "latin1":
            data[k:k] = b"\xe9\xff"
        else:
            data[k:k] = b"nan "
    return bytes(data)


def make_scene_arg(pick: Pick, box: Path) -> str:
    """A --scene value: a built-in or bogus name, or a (mutated) file written into ``box/in``."""
    kind = pick.choice(
        ["builtin"] * 3
        + ["bogus", "scene", "scene", "scene", "obj", "ply", "stl", "off", "glb", "long", "companion", "dataset"]
    )
    if kind == "builtin":
        return pick.choice(["cube", "pyramid", "prism", "orrery"])
    if kind == "bogus":
        # every path stays inside box: '..' or '/' made a dataset walk of the whole system temporary folder
        # (another program's FIFO there hung a run); the box's own FIFO stands for them
        value = pick.choice(["nosuch", "", ".", "in/..", "cube.scene", "x" * 300, "a/b", "pipe.obj", "in"])
        if value == "pipe.obj":
            os.mkfifo(box / "in" / value)
            return str(box / "in" / value)
        return str(box / "in" / "..") if value == "in/.." else value
    if kind == "long":
        return str(box / "in" / ("p" * 300)) + ".scene"
    if kind in ("companion", "dataset"):
        return fifo_inputs(pick, box, kind)
    folder = box / "in"
    (folder / "m.obj").write_text(OBJ)
    (folder / "m.stl").write_text(STL)
    if kind == "scene":
        text = mutate_text(pick, pick.choice(SCENE_TEXTS))
        path = folder / pick.choice(["s.scene", "s.txt", f"{'n' * 120}.scene", "s p.scene"])
        path.write_bytes(
            text.encode("utf-8", "surrogatepass") if pick.chance(0.9) else text.encode("latin-1", "replace")
        )
        return str(path)
    if kind == "glb":
        data = glb_bytes(pick.choice([(0, 1, 2), (0, 1, 7), (0, 0, 0), (65535, 1, 2)]))
    else:
        data = {"obj": OBJ, "ply": PLY, "stl": STL, "off": OFF}[kind].encode()
        if pick.chance(0.5):
            data = mutate_text(pick, data.decode()).encode("utf-8", "replace")
    path = folder / f"m{pick.integer(0, 9)}.{kind}"
    path.write_bytes(mutate_bytes(pick, data) if pick.chance(0.4) else data)
    return str(path)


def fifo_inputs(pick: Pick, box: Path, kind: str) -> str:
    """A mesh whose companion file (mtllib, map_Kd, a glTF buffer) is a FIFO, or a dataset folder holding such
    meshes, a FIFO named like a mesh and a good mesh. Opening any FIFO here blocks forever (no writer)."""
    folder = box / "in" / ("ds" if kind == "dataset" else "")
    folder.mkdir(exist_ok=True)
    made = []
    for which in (pick.choice(["mtllib", "map_Kd", "gltf"]),) if kind == "companion" else ("mtllib", "gltf", "pipe"):
        if which == "mtllib":
            (folder / "a.obj").write_text("mtllib a.mtl\n" + OBJ)
            os.mkfifo(folder / "a.mtl")
            made.append(folder / "a.obj")
        elif which == "map_Kd":
            (folder / "b.obj").write_text("mtllib b.mtl\nusemtl x\n" + OBJ)
            (folder / "b.mtl").write_text("newmtl x\nmap_Kd b.png\n")
            os.mkfifo(folder / "b.png")
            made.append(folder / "b.obj")
        elif which == "gltf":
            doc = {
                "asset": {"version": "2.0"},
                "buffers": [{"uri": "c.bin", "byteLength": 36}],
                "bufferViews": [{"buffer": 0, "byteLength": 36}],
                "accessors": [
                    {
                        "bufferView": 0,
                        "componentType": 5126,
                        "count": 3,
                        "type": "VEC3",
                        "max": [1, 1, 0],
                        "min": [0, 0, 0],
                    }
                ],
                "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
                "nodes": [{"mesh": 0}],
                "scenes": [{"nodes": [0]}],
                "scene": 0,
            }
            (folder / "c.gltf").write_text(json.dumps(doc))
            os.mkfifo(folder / "c.bin")
            made.append(folder / "c.gltf")
        else:
            os.mkfifo(folder / "pipe.ply")
            (folder / "good.obj").write_text(OBJ)
    return str(folder) if kind == "dataset" else str(made[0])


#: The options whose values name paths a run reads or writes: each must stay inside the input's box.
PATH_OPTIONS = ("--scene", "--scene-list", "--out", "--report-dir")


def outside_box(argv: list[str], box: Path) -> list[str]:
    """The values of PATH_OPTIONS in ``argv`` that name a path outside ``box`` (relative ones from ``box``)."""
    root = os.path.realpath(box)
    bad = []
    for opt, value in zip(argv, argv[1:]):
        if opt in PATH_OPTIONS and value and (os.sep in value or value in (".", "..")):
            where = os.path.realpath(os.path.join(box, value))
            if os.path.commonpath([root, where]) != root:
                bad.append(f"{opt} {value}")
    return bad


# ---- output set-ups: the user's things in and around the output folder ------------------------------

DECOY = b"the user's own bytes\n"


def setup_out(pick: Pick, box: Path, earlier: Path | None) -> str:
    """Create the output folder's starting state in ``box``; return the --out value."""
    out = box / "out"
    kind = pick.choice(
        ["absent"] * 3
        + [
            "empty",
            "decoys",
            "decoys",
            "earlier",
            "earlier",
            "earlier",
            "nested",
            "file",
            "under_file",
            "long",
            "foreign_output",
            "user_in_output",
        ]
    )
    if kind == "absent":
        return str(out)
    if kind == "nested":
        return str(out / "a" / "b")
    if kind == "long":
        return str(box / ("o" * 300))
    if kind == "file":
        out.write_bytes(DECOY)
        return str(out)
    if kind == "under_file":
        out.write_bytes(DECOY)
        return str(out / "sub")
    out.mkdir()
    if kind in ("earlier", "user_in_output") and earlier is not None:
        shutil.copytree(earlier, out, dirs_exist_ok=True, symlinks=True)
    if kind == "user_in_output" and earlier is not None:  # issue 25: the user's file inside a folder of ours
        where = pick.choice(["cube-frames/note.txt", "cube-frames/mine/note.txt", "cube-frames/frame_0099.png"])
        (out / where).parent.mkdir(exist_ok=True)
        (out / where).write_bytes(DECOY)
    if kind in ("decoys", "earlier", "foreign_output"):
        (out / "notes.txt").write_bytes(DECOY)
        old = out / pick.choice([".cube-frames.old", ".pyramid-frames.old", ".r.old"])
        old.mkdir(exist_ok=True)
        (old / "keep.txt").write_bytes(DECOY)
        (box / "target.txt").write_bytes(DECOY)
        link = out / ".wirecheck-write-test"
        if not link.exists():
            os.symlink(box / "target.txt", link)
    if kind == "foreign_output":
        name = pick.choice(
            [
                "cube-report.txt",
                "cube-report.json",
                "cube.gif",
                "cube-frames",
                ".wirecheck-manifest.json",
                ".wirecheck-lock",
                "pyramid-report.json",
                "tri-report.txt",
            ]
        )
        if name == "cube-frames" or pick.chance(0.3):
            (out / name).mkdir(exist_ok=True)
            (out / name / "keep.txt").write_bytes(DECOY)
        else:
            (out / name).write_bytes(DECOY)
    return str(out)


# ---- argv --------------------------------------------------------------------------------------------

#: option -> (ordinary values, hostile values); None for a flag. A drawn option takes an ordinary value
#: 70 % of the time, so that most runs get past the parser and write outputs.
RENDERER_OPTIONS = {
    "--frames": (["1", "2", "3"], INTS),
    "--camera-z": (["4", "-4", "2.5", "0.5"], NUMBERS),
    "--camera-pos": (["0,0,4", "3,3,3", "0,1,0"], VECTORS),
    "--look-at": (["0,0,0", "1,2,3"], VECTORS),
    "--up": (["0,1,0", "1,0,0"], VECTORS),
    "--fov": (["60", "1", "179.9", "1e-30"], NUMBERS),
    "--near": (["0.1", "1", "3.5"], NUMBERS),
    "--far": (["100", "4", "1e308"], NUMBERS),
    "--width": (["16", "33", "64"], SIZES),
    "--height": (["16", "24", "48"], SIZES),
    "--projection": (["perspective", "orthographic", "both"], ["fisheye", ""]),
    "--ortho-height": (["4", "0.5", "1e-30"], NUMBERS),
    "--spin": (["1,1,0", "0,0,0", "1e15,0,0"], VECTORS),
    "--translate": (["0,0,0", "0,0,3.5", "1e300,0,0"], VECTORS),
    "--scale": (["1", "-1", "2", "1e-300"], NUMBERS),
    "--clip": (["clip", "endpoint"], ["x"]),
    "--dtype": (["float64", "float32"], ["float16"]),
    "--raster": (["exact", "fast", "aa"], ["x"]),
    "--cull": (["none", "backface"], ["x"]),
    "--style": (["wireframe", "shaded"], ["x"]),
    "--light": (["1,-1,-1", "0,0,1e-300"], VECTORS),
    "--format": (["png", "ascii", "gif", "mp4", "png,gif", "png,ascii,gif"], ["bogus", "", "png,,", "gif,x"]),
    "--ascii-cols": (["80", "1", "7"], INTS),
    "--axes": None,
    "--hidden-lines": None,
    "--verbose": None,
    "--object-culling": None,
    "--no-object-culling": None,
    "--plots": None,
    "--bogus": None,
    "--help": None,
    "--profile": None,
    "--compare": None,
    "--trace-vertex": (["0", "3"], INTS),
}
CROSSCHECK_OPTIONS = {
    "--frames": (["1", "2"], INTS),
    "--cases": (["on_axis", "near_plane", "on_axis,wide_fov"], ["x", "", ",,", "oblique"]),
    "--level": (["vertices"], ["x", ""]),
    "--oracles": (["opencv"], ["pyrender", "x", ""]),
    "--every": (["1", "2"], INTS),
    "--jobs": (["1"], ["0", "-1", "x"]),
    "--dtype": (["float64", "float32"], ["x"]),
    "--clip": (["clip", "endpoint"], ["x"]),
    "--raster": (["exact", "fast", "aa"], ["x"]),
    "--style": ([], ["wireframe", "shaded", "x"]),
    "--hidden-lines": None,
    "--cull": ([], ["none", "backface", "x"]),
    "--spin": (["1,1,0", "0,0,0", "1e15,0,0"], VECTORS),
    "--tol-px": (["0.5", "0", "1e308"], NUMBERS),
    "--min-f1": (["0.9", "0", "1"], NUMBERS),
    "--min-f1-0px": (["0.5", "1"], NUMBERS),
    "--min-iou": (["0.9"], NUMBERS),
    "--suite": ([], ["x"]),
    "--run": (["r1", "r.2"], ["../escape", ".hidden", "a/b", "x" * 300, ""]),
    "--bogus": None,
}


def _options(pick: Pick, table: dict, rare: set[str]) -> list[str]:
    argv = []
    for _ in range(pick.integer(0, 3)):
        opt = pick.choice(table)
        if opt in rare and not pick.chance(0.03):
            continue
        if table[opt] is None:
            argv.append(opt)
            continue
        ordinary, hostile = table[opt]
        argv += [opt, pick.choice(ordinary) if ordinary and pick.chance(0.7) else pick.choice(hostile)]
    return argv


def renderer_argv(pick: Pick, box: Path, earlier: Path | None) -> list[str]:
    argv = [
        "--frames",
        pick.choice(["1", "2", "3"]),
        "--width",
        pick.choice(["16", "33", "64"]),
        "--height",
        pick.choice(["16", "24", "48"]),
    ]
    argv += _options(pick, RENDERER_OPTIONS, rare={"--plots", "--help", "--bogus", "--compare"})
    if pick.chance(0.8):
        argv += ["--scene", make_scene_arg(pick, box)]
    if pick.chance(0.95):
        argv += ["--out", setup_out(pick, box, earlier)]
    return argv


def crosscheck_argv(pick: Pick, box: Path, earlier: Path | None) -> list[str]:
    argv = [
        "--frames",
        pick.choice(["1", "2"]),
        "--cases",
        pick.choice(["on_axis", "oblique_roll", "orthographic"]),
        "--level",
        "vertices" if pick.chance(0.99) else "pixels",
    ]  # pixels: pyrender, ~1 s a case
    argv += _options(pick, CROSSCHECK_OPTIONS, rare={"--suite", "--bogus", "--hidden-lines"})
    if pick.chance(0.9):
        argv += ["--scene", make_scene_arg(pick, box)]
    if pick.chance(0.15):
        argv += [
            "--candidate",
            pick.choice(
                [
                    f"{Path(__file__).resolve().parent.parent}/data/user_projector.py:project",
                    f"{Path(__file__).resolve().parent.parent}/data/user_projector.py:project_corner",
                    f"{Path(__file__).resolve().parent.parent}/data/user_projector.py:nosuch",
                    "nosuch.py:f",
                    "numpy:zeros",
                    "os:getcwd",
                    ":",
                    "x" * 300 + ".py:f",
                    str(_import_error_candidate(box)),
                ]
            ),
        ]
    if pick.chance(0.8):
        where = setup_out(pick, box, earlier)
        argv += ["--report-dir", where if pick.chance(0.95) else str(box / "in" / "evil.scene")]
    return argv


def _import_error_candidate(box: Path) -> str:
    path = box / "in" / "cand.py"
    path.write_text("raise ImportError('line one\\nline two')\n")
    return f"{path}:f"


# ---- the contract ------------------------------------------------------------------------------------


@dataclass
class Outcome:
    rc: int
    stdout: str
    stderr: str
    problems: list[str] = field(default_factory=list)


def snapshot(box: Path) -> dict:
    """Every path under ``box``: (kind, sha256 of a file's bytes or a link's target)."""
    snap = {}
    for dirpath, dirnames, filenames in os.walk(box):
        for n in dirnames + filenames:
            p = Path(dirpath) / n
            rel = str(p.relative_to(box))
            if p.is_symlink():
                snap[rel] = ("link", os.readlink(p))
            elif p.is_dir():
                snap[rel] = ("dir", None)
            elif not p.is_file():  # a FIFO: never opened (no writer: open blocks forever)
                snap[rel] = ("fifo", None)
            else:
                snap[rel] = ("file", hashlib.sha256(p.read_bytes()).hexdigest())
    return snap


OUTPUT_NAME = re.compile(
    r"(.+-frames(/(frame_\d{4,}\.(png|txt)|\.wirecheck-output))?|.+-report\.(json|txt)|"
    r".+\.(gif|mp4)|.+-plots\.png|.+-compare\.(png|json|txt)|.+-vertices_px(-orthographic)?\.npy|\.wirecheck-manifest\.json)"
)
REPORT_NAME = re.compile(
    r"(report\.(json|md|html)|worst\.gif|vertex_error\.png|worst_points\.png|pixels\.png|img(/.*)?|"
    r"\.wirecheck-output|sweep\..*|extremes\..*)"
)


def run_cli(main, argv: list[str], box: Path, cli: str) -> Outcome:
    """Run ``main(argv)`` in ``box`` (the current folder during the call) and check the contract."""
    before = snapshot(box)
    outside = outside_box(argv, box)
    out, err = io.StringIO(), io.StringIO()
    cwd = os.getcwd()
    os.chdir(box)
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                rc = main(argv)
            except SystemExit as exc:  # argparse: --help (0) and usage errors (2)
                rc = exc.code if isinstance(exc.code, int) else 2
    finally:
        os.chdir(cwd)
    o = Outcome(rc, out.getvalue(), err.getvalue())
    o.problems += [f"input outside its folder: {v}" for v in outside]
    after = snapshot(box)
    if rc not in (0, 1, 2):
        o.problems.append(f"exit {rc}")
    if rc == 2 and o.stderr.count("\n") != 1:
        o.problems.append(f"{o.stderr.count(chr(10))} stderr lines on exit 2")
    if "Traceback" in o.stderr or "Warning:" in o.stderr:
        o.problems.append("traceback or warning on stderr")
    changed = [p for p in before if p in after and before[p] != after[p] and before[p][0] != "dir"]
    gone = [p for p in before if p not in after]
    new = [p for p in after if p not in before]
    output_root = _output_root(argv, box, cli, o.stdout)
    for p in changed + gone:
        decoy = before[p] == ("file", hashlib.sha256(DECOY).hexdigest())  # the user's, whatever its name
        if (
            rc in (0, 1)
            and output_root is not None
            and _inside(box / p, output_root)
            and not decoy
            and _is_output(p, box, output_root, cli, before)
        ):
            continue  # an earlier output of wirecheck's, replaced
        o.problems.append(f"user file touched: {p}")
    if rc not in (0, 1) and new:
        o.problems.append(f"left behind after exit {rc}: {sorted(new)[:3]}")
    elif rc in (0, 1):
        for p in new:
            if output_root is None or not (_inside(box / p, output_root) or _inside(output_root, box / p)):
                o.problems.append(f"written outside the output: {p}")
            elif _inside(box / p, output_root) and not _is_output(p, box, output_root, cli, before):
                o.problems.append(f"stray file in the output: {p}")
        if cli == "renderer" and rc == 0 and output_root is not None and new:  # (--help: rc 0, nothing new)
            o.problems += _partial(output_root, [box / p for p in new], [box / p for p in new + changed])
    return o


def _inside(path: Path, folder: Path) -> bool:
    try:
        path.resolve().relative_to(folder.resolve())
        return True
    except ValueError:
        return False


def _output_root(argv, box: Path, cli: str, stdout: str) -> Path | None:
    flag = "--out" if cli == "renderer" else "--report-dir"
    if flag in argv and argv.index(flag) + 1 < len(argv):
        root = box / argv[len(argv) - 1 - argv[::-1].index(flag) + 1]
        if cli == "crosscheck" and "--run" in argv:  # --run with --report-dir: DIR/RUN
            return root / argv[len(argv) - 1 - argv[::-1].index("--run") + 1]
        return root
    if cli == "renderer":
        return box / "output"
    m = re.search(r"Report: (\S+?)/(report\.json|sweep\.md|extremes\.md)", stdout)
    return box / m.group(1) if m else box / "reports"


def _is_output(rel: str, box: Path, root: Path, cli: str, before: dict) -> bool:
    sub = os.path.relpath(box / rel, root)
    if sub == ".":
        return True
    if cli == "renderer":
        return bool(OUTPUT_NAME.fullmatch(sub))
    return sub == "." or bool(REPORT_NAME.fullmatch(sub))


def _partial(root: Path, new: list[Path], written: list[Path]) -> list[str]:
    """A renderer output folder whose frames and report (both written by this run) disagree."""
    problems = []
    for rep in root.glob("*-report.json"):
        if rep not in written:
            continue
        frames = json.loads(rep.read_text())["summary"]["frames"]
        fdir = root / rep.name.replace("-report.json", "-frames")
        if fdir.is_dir() and any(fdir in p.parents for p in new):
            n = len({p.stem for p in fdir.iterdir() if p.name.startswith("frame_")})
            if n and n != frames:
                problems.append(f"partial output: {n} frames beside a report of {frames}")
    return problems
