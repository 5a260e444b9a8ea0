"""Fuzz round 4 (issue 36): special files fed to every file-taking option, hostile numeric flags, viewer requests.

    nice .venv/bin/python benchmarks/fuzz_inputs_round4.py                  # all three surfaces (~5 min, 2 busy cores)
    .venv/bin/python benchmarks/fuzz_inputs_round4.py --surface files      # or flags, viewer
    .venv/bin/python benchmarks/fuzz_inputs_round4.py --json r4.json       # also write the counts as JSON

Surfaces (every input is listed, none drawn at random except the viewer's mutated requests, from --seed):

- files: each kind of special file (a FIFO, /dev/zero, /dev/urandom, /dev/null, a folder, a Unix socket, a
  dangling link, a link loop, a link to a FIFO, a 64 GiB sparse file) in each place a run reads a file:
  ``renderer --scene`` (.scene and the six mesh formats), a .scene's ``mesh`` line, an OBJ's ``mtllib`` and
  ``map_Kd``, a glTF buffer; ``crosscheck --config``, a ``pyproject.toml`` found in the working folder, a
  config's ``scenes`` path, ``--scene-list`` and a line of one, ``--scene DIR`` holding it, ``--scene``
  FILE, ``--candidate FILE.py:f``, ``--candidate-frames`` (the job folder, job.json, a camera, an OBJ, a
  frame); ``crosscheck export`` (its ``--scene`` and its target DIR); and the outputs: ``renderer --out``,
  ``crosscheck --report-dir`` and ``--junit-xml``.
- flags: every numeric option of ``renderer``, ``crosscheck`` and ``crosscheck export`` given each of
  -inf, inf, nan, -nan, -1e5, 1e400, -0, -1, 0, 1e308, 2^63, a Unicode digit, as ``--flag VALUE`` (the
  form argparse alone misreads when VALUE starts with ``-``), and vectors (X,Y,Z) with such members.
- viewer: raw HTTP requests to an in-process viewer server: repeated headers (Host, Origin, lengths,
  types), missing or odd Host values, absolute-form targets, chunked bodies, bad versions, NULs, long
  lines, and random byte mutations of a good request.

Each CLI input runs in-process in a fresh folder under SIGALRM (a run over TIMEOUT_S is a hang, counted),
its stdout and stderr captured, and is checked: exit status in {0, 1, 2}; exit 2 with one stderr line; no
traceback or warning; argparse's "expected one argument" (a negative value read as an option) counted;
every path that was in the folder before unchanged (a special file never opened to hash it); nothing new
after a failure, nothing new outside the output after a success. Each viewer request must get a 4xx or a
200 frame (200 only for requests a browser on the viewer's page could send) within 15 s, nothing on
stderr, and the server must answer the next good request. The counts go to docs/reliability.md
("Round 4: special files and hostile flags").
"""

from __future__ import annotations

import argparse
import collections
import contextlib
import hashlib
import io
import json
import os
import random
import resource
import signal
import socket
import stat
import sys
import tempfile
import time
import warnings
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

TIMEOUT_S = 60
SPARSE_BYTES = 64 << 30
TRIANGLE_OBJ = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"
QUICK = ["--level", "vertices", "--frames", "1", "--cases", "on_axis"]


class Hang(BaseException):
    """SIGALRM in an input that ran past TIMEOUT_S (a BaseException: the CLIs' guards let it through)."""


def _alarm(signum, frame):
    raise Hang()


# ---- special files --------------------------------------------------------------------------------------


def make_special(kind: str, path: Path, spare: Path | None = None) -> None:
    """``path`` made into a special file of ``kind`` (links for the devices: the name keeps its suffix);
    ``spare``: where a link's FIFO goes (default: beside the link)."""
    if kind == "fifo":
        os.mkfifo(path)
    elif kind in ("dev_zero", "dev_urandom", "dev_null"):
        path.symlink_to("/dev/" + kind[4:])
    elif kind == "folder":
        path.mkdir()
    elif kind == "socket":
        s = socket.socket(socket.AF_UNIX)
        s.bind(str(path))
        s.close()  # the socket file stays
    elif kind == "dangling_link":
        path.symlink_to(path.parent / "nowhere")
    elif kind == "link_loop":
        path.symlink_to(path)
    elif kind == "link_to_fifo":
        target = (spare or path.parent) / (path.name + ".fifo-target")
        os.mkfifo(target)
        path.symlink_to(target)
    elif kind == "sparse_64GiB":
        with open(path, "wb") as fh:
            fh.truncate(SPARSE_BYTES)
    else:
        raise ValueError(kind)


KINDS = (
    "fifo",
    "dev_zero",
    "dev_urandom",
    "dev_null",
    "folder",
    "socket",
    "dangling_link",
    "link_loop",
    "link_to_fifo",
    "sparse_64GiB",
)


def _job(box: Path) -> Path:
    """A small export job (cube, on_axis, 1 frame) in ``box/job``, its frame missing."""
    from wirecheck.oracles.frames_cli import export_main

    with contextlib.redirect_stdout(io.StringIO()):
        assert export_main([str(box / "job"), "--scene", "cube", "--cases", "on_axis", "--frames", "1"]) == 0
    return box / "job"


def _replace(path: Path, kind: str, spare: Path) -> None:
    if path.is_dir() and not path.is_symlink():
        for p in sorted(path.rglob("*"), reverse=True):
            p.rmdir() if p.is_dir() and not p.is_symlink() else p.unlink()
        path.rmdir()
    elif path.exists() or path.is_symlink():
        path.unlink()
    path.parent.mkdir(parents=True, exist_ok=True)
    make_special(kind, path, spare)


def file_inputs():
    """``(name, cli, build)``: build(box, kind) -> argv, with the special file of that kind in place."""
    out = []

    def scene_arg(suffix):
        def build(box, kind):
            make_special(kind, box / f"x{suffix}")
            return ["--scene", str(box / f"x{suffix}")]

        return build

    for suffix in (".scene", ".obj", ".ply", ".stl", ".off", ".glb", ".gltf"):
        out.append((f"renderer --scene X{suffix}", "renderer", scene_arg(suffix)))

    def scene_mesh_line(box, kind):
        make_special(kind, box / "m.obj")
        (box / "s.scene").write_text("mesh m.obj\n")
        return ["--scene", str(box / "s.scene")]

    def obj_mtllib(box, kind):
        make_special(kind, box / "m.mtl")
        (box / "a.obj").write_text("mtllib m.mtl\nusemtl x\n" + TRIANGLE_OBJ)
        return ["--scene", str(box / "a.obj")]

    def obj_texture(box, kind):
        make_special(kind, box / "tex.png")
        (box / "m.mtl").write_text("newmtl x\nKd 1 1 1\nmap_Kd tex.png\n")
        (box / "a.obj").write_text(
            "mtllib m.mtl\nusemtl x\nvt 0 0\nvt 1 0\nvt 0 1\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1 2/2 3/3\n"
        )
        return ["--scene", str(box / "a.obj")]

    def gltf_buffer(box, kind):
        make_special(kind, box / "buf.bin")
        doc = {
            "asset": {"version": "2.0"},
            "buffers": [{"uri": "buf.bin", "byteLength": 36}],
            "bufferViews": [{"buffer": 0, "byteLength": 36}],
            "accessors": [
                {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}
            ],
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
            "nodes": [{"mesh": 0}],
            "scenes": [{"nodes": [0]}],
            "scene": 0,
        }
        (box / "a.gltf").write_text(json.dumps(doc))
        return ["--scene", str(box / "a.gltf")]

    out += [
        ("renderer: a .scene's mesh line", "renderer", scene_mesh_line),
        ("renderer: an OBJ's mtllib", "renderer", obj_mtllib),
        ("renderer: a material's map_Kd", "renderer", obj_texture),
        ("renderer: a glTF buffer", "renderer", gltf_buffer),
    ]

    def config(box, kind):
        make_special(kind, box / "w.toml")
        return ["--config", str(box / "w.toml"), *QUICK, "--scene", "cube"]

    def pyproject(box, kind):
        make_special(kind, box / "pyproject.toml")  # found in the working folder (box)
        return [*QUICK, "--scene", "cube"]

    def config_scene(box, kind):
        make_special(kind, box / "x.scene")
        (box / "w.toml").write_text('[tool.wirecheck]\nscenes = ["x.scene"]\n')
        return ["--config", str(box / "w.toml"), *QUICK]

    def config_candidate(box, kind):
        make_special(kind, box / "cand.py")
        (box / "w.toml").write_text('[tool.wirecheck]\ncandidate = "cand.py:project"\n')
        return ["--config", str(box / "w.toml"), *QUICK, "--scene", "cube"]

    def scene_list(box, kind):
        make_special(kind, box / "list.txt")
        return ["--scene-list", str(box / "list.txt"), *QUICK]

    def scene_list_line(box, kind):
        make_special(kind, box / "m.obj")
        (box / "good.obj").write_text(TRIANGLE_OBJ)
        (box / "list.txt").write_text("m.obj\ngood.obj\n")
        return ["--scene-list", str(box / "list.txt"), "--allow-load-errors", *QUICK]

    def scene_dir(box, kind):
        (box / "ds").mkdir()
        make_special(kind, box / "ds" / "m.obj")
        (box / "ds" / "good.obj").write_text(TRIANGLE_OBJ)
        return ["--scene", str(box / "ds"), "--allow-load-errors", *QUICK]

    def scene_file(box, kind):
        make_special(kind, box / "x.obj")
        return ["--scene", str(box / "x.obj"), *QUICK]

    def candidate(box, kind):
        make_special(kind, box / "cand.py")
        return ["--candidate", f"{box / 'cand.py'}:project", *QUICK, "--scene", "cube"]

    def frames_job_dir(box, kind):
        make_special(kind, box / "job")
        return ["--candidate-frames", str(box / "job")]

    def frames_file(rel):
        def build(box, kind):
            job = _job(box)
            _replace(job / rel, kind, box)  # a link's FIFO outside the job: not a stray file of it
            return ["--candidate-frames", str(job)]

        return build

    out += [
        ("crosscheck --config", "crosscheck", config),
        ("crosscheck: pyproject.toml found", "crosscheck", pyproject),
        ("crosscheck: a config's scenes path", "crosscheck", config_scene),
        ("crosscheck: a config's candidate path", "crosscheck", config_candidate),
        ("crosscheck --scene-list", "crosscheck", scene_list),
        ("crosscheck: a --scene-list line", "crosscheck", scene_list_line),
        ("crosscheck --scene DIR", "crosscheck", scene_dir),
        ("crosscheck --scene X.obj", "crosscheck", scene_file),
        ("crosscheck --candidate FILE.py", "crosscheck", candidate),
        ("crosscheck --candidate-frames DIR", "crosscheck", frames_job_dir),
    ]
    for rel in (
        "job.json",
        "cameras/cube/on_axis/frame_0001.json",
        "scenes/cube.obj",
        "frames/cube/on_axis/frame_0001.png",
    ):
        out.append((f"crosscheck --candidate-frames: {rel}", "crosscheck", frames_file(rel)))

    def export_scene(suffix):
        def build(box, kind):
            make_special(kind, box / f"x{suffix}")
            return [
                "export",
                str(box / "out"),
                "--scene",
                str(box / f"x{suffix}"),
                "--cases",
                "on_axis",
                "--frames",
                "1",
            ]

        return build

    def export_target(box, kind):
        make_special(kind, box / "out")
        return ["export", str(box / "out"), "--scene", "cube", "--cases", "on_axis", "--frames", "1"]

    def renderer_out(box, kind):
        make_special(kind, box / "o")
        return ["--scene", "cube", "--out", str(box / "o")]

    def report_dir(box, kind):
        make_special(kind, box / "r")
        return [*QUICK, "--scene", "cube", "--report-dir", str(box / "r")]

    def junit(box, kind):
        make_special(kind, box / "j.xml")
        return [*QUICK, "--scene", "cube", "--junit-xml", str(box / "j.xml")]

    out += [
        ("renderer --out", "renderer out", renderer_out),
        ("crosscheck --report-dir", "crosscheck out", report_dir),
        ("crosscheck --junit-xml", "crosscheck", junit),
    ]
    out += [
        ("crosscheck export --scene X.scene", "crosscheck", export_scene(".scene")),
        ("crosscheck export --scene X.obj", "crosscheck", export_scene(".obj")),
        ("crosscheck export DIR", "crosscheck", export_target),
    ]
    return out


# ---- the contract ---------------------------------------------------------------------------------------


def snapshot(box: Path) -> dict:
    """Every path under ``box``: its kind and, for a regular file up to 16 MiB, its SHA-256 (nothing else opened)."""
    snap = {}
    for dirpath, dirnames, filenames in os.walk(box):
        for n in dirnames + filenames:
            p = Path(dirpath) / n
            st = os.lstat(p)
            rel = str(p.relative_to(box))
            if stat.S_ISLNK(st.st_mode):
                snap[rel] = ("link", os.readlink(p))
            elif stat.S_ISDIR(st.st_mode):
                snap[rel] = ("dir", None)
            elif not stat.S_ISREG(st.st_mode):
                snap[rel] = ("special", stat.S_IFMT(st.st_mode))
            elif st.st_size > (16 << 20):
                snap[rel] = ("big", st.st_size, st.st_mtime_ns)
            else:
                snap[rel] = ("file", hashlib.sha256(p.read_bytes()).hexdigest())
    return snap


def run_one(main, argv: list[str], box: Path, output: Path | None) -> dict:
    """``main(argv)`` in ``box`` under the alarm; the outcome and the contract's findings."""
    before = snapshot(box)
    out, err = io.StringIO(), io.StringIO()
    cwd = os.getcwd()
    os.chdir(box)
    t0 = time.perf_counter()
    signal.alarm(TIMEOUT_S)
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                rc = main(argv)
            except SystemExit as exc:  # argparse
                rc = exc.code if isinstance(exc.code, int) else 2
    except Hang:
        rc = None
    finally:
        signal.alarm(0)
        os.chdir(cwd)
    seconds = time.perf_counter() - t0
    stderr = err.getvalue()
    found = []
    if rc is None:
        found.append("hangs")
    elif rc == 3:
        found.append("internal errors (exit 3)")
    elif rc not in (0, 1, 2):
        found.append("odd exits")
    if rc == 2 and stderr.count("\n") != 1:
        found.append("exit 2 without one stderr line")
    if "Traceback" in stderr or "Warning:" in stderr:
        found.append("tracebacks")
    if "expected one argument" in stderr:
        found.append("a negative value read as an option")
    after = snapshot(box)
    if any(
        p not in after or after[p] != before[p]
        for p in before
        if before[p][0] != "dir" and not (rc in (0, 1) and output is not None and _under(box / p, output))
    ):
        found.append("user files touched")
    new = [p for p in after if p not in before]
    if rc not in (0, 1) and new:
        found.append("leftovers")
    elif new and (output is None or any(not (_under(box / p, output) or _under(output, box / p)) for p in new)):
        found.append("leftovers")
    return {"rc": rc, "seconds": round(seconds, 2), "stderr": stderr[-300:], "found": found}


def _under(path: Path, folder: Path) -> bool:
    return path == folder or folder in path.parents


def _tally(results: list[dict]) -> dict:
    codes = collections.Counter("hang" if r["rc"] is None else r["rc"] for r in results)
    found = collections.Counter(f for r in results for f in set(r["found"]))
    return {
        "inputs": len(results),
        "exit_codes": {str(k): v for k, v in sorted(codes.items(), key=str)},
        "findings": dict(found),
        "slowest_s": max((r["seconds"] for r in results), default=0),
        "examples": [r for r in results if r["found"]][:10],
    }


def fuzz_files() -> dict:
    from wirecheck.core.app import cli as renderer
    from wirecheck.oracles import cli as crosscheck

    results = []
    for name, cli, build in file_inputs():
        for kind in KINDS:
            with tempfile.TemporaryDirectory(prefix="wirecheck-r4-") as d:
                box = Path(d)
                argv = build(box, kind)
                if cli == "renderer out":  # the special file is the output folder
                    argv += ["--frames", "1", "--width", "32", "--height", "24"]
                    output = box / "o"
                elif cli == "crosscheck out":
                    output = box / "r"
                elif cli == "renderer":
                    argv += ["--frames", "1", "--width", "32", "--height", "24", "--out", str(box / "rout")]
                    output = box / "rout"
                elif argv[0] == "export":
                    output = Path(argv[1])
                else:
                    argv += ["--report-dir", str(box / "rep")]
                    output = box / "rep"
                r = run_one(renderer.main if cli.startswith("renderer") else crosscheck.main, argv, box, output)
                r.update(input=f"{name} <- {kind}", argv=argv)
                results.append(r)
                print(
                    f"  {r['rc']} {r['seconds']:6.2f}s {name} <- {kind}: {r['stderr'].strip()[:150]}",
                    file=sys.stderr,
                    flush=True,
                )
    return _tally(results) | {"surface": "files", "special kinds": len(KINDS), "places": len(file_inputs())}


# ---- numeric flags --------------------------------------------------------------------------------------

SCALARS = ["-inf", "inf", "nan", "-nan", "-1e5", "1e400", "-0", "-1", "0", "1e308", str(2**63), "\u0664"]
VECTORS = ["-inf,0,0", "nan,1,1", "-1e5,0,0", "1e400,0,0", "-1,-2,-3", "-0,-0,-0", "1,2", "-1,2,3,4"]

RENDERER_SCALAR = [
    "--frames",
    "--camera-z",
    "--fov",
    "--near",
    "--far",
    "--width",
    "--height",
    "--ortho-height",
    "--scale",
    "--ascii-cols",
    "--trace-vertex",
    "--port",
]
RENDERER_VECTOR = [
    "--camera-pos",
    "--look-at",
    "--up",
    "--spin",
    "--translate",
    "--light",
    "--intrinsics",
    "--distortion",
    "--trace-frames",
    "--compare-z",
    "--compare-fov",
]
CROSSCHECK_SCALAR = [
    "--frames",
    "--candidate-timeout",
    "--every",
    "--jobs",
    "--scheduler-timeout",
    "--tol-px",
    "--min-f1",
    "--min-f1-0px",
    "--min-iou",
]
CROSSCHECK_VECTOR = ["--spin"]
EXPORT_SCALAR = ["--frames", "--every", "--phase"]
EXPORT_VECTOR = ["--spin"]

#: what a flag needs beside it to be read at all
NEEDS = {
    "--ortho-height": ["--projection", "orthographic"],
    "--look-at": ["--camera-pos", "3,2,4"],
    "--up": ["--camera-pos", "3,2,4"],
    "--light": ["--style", "shaded"],
    "--trace-frames": ["--trace-vertex", "0"],
    "--compare-z": ["--compare"],
    "--compare-fov": ["--compare"],
    "--port": ["--interactive"],
    "--min-iou": ["--level", "pixels"],
    "--min-f1": ["--level", "pixels"],
    "--min-f1-0px": ["--level", "pixels"],
    "--scheduler-timeout": ["--executor", "dask"],
    "--candidate-timeout": ["--candidate-cmd", "true"],
}


def flag_inputs():
    """``(cli, flag, value)`` for every numeric flag and hostile value."""
    out = []
    for cli, scalars, vectors in (
        ("renderer", RENDERER_SCALAR, RENDERER_VECTOR),
        ("crosscheck", CROSSCHECK_SCALAR, CROSSCHECK_VECTOR),
        ("export", EXPORT_SCALAR, EXPORT_VECTOR),
    ):
        out += [(cli, f, v) for f in scalars for v in SCALARS]
        out += [(cli, f, v) for f in vectors for v in VECTORS + ["-inf", "nan"]]
    return out


def fuzz_flags() -> dict:
    from wirecheck.core.app import cli as renderer
    from wirecheck.oracles import cli as crosscheck

    results = []
    for cli, flag, value in flag_inputs():
        with tempfile.TemporaryDirectory(prefix="wirecheck-r4-") as d:
            box = Path(d)
            extra = NEEDS.get(flag, [])
            if cli == "renderer":
                if flag == "--port" and value in ("0", "-0"):
                    continue  # a real viewer serving until killed
                argv = [
                    "--scene",
                    "cube",
                    "--frames",
                    "1",
                    "--width",
                    "32",
                    "--height",
                    "24",
                    "--format",
                    "png",
                    "--out",
                    str(box / "out"),
                    *extra,
                    flag,
                    value,
                ]
                main, output = renderer.main, box / "out"
            elif cli == "crosscheck":
                argv = ["--scene", "cube", *QUICK, "--report-dir", str(box / "rep"), *extra, flag, value]
                main, output = crosscheck.main, box / "rep"
            else:
                argv = [
                    "export",
                    str(box / "job"),
                    "--scene",
                    "cube",
                    "--cases",
                    "on_axis",
                    "--frames",
                    "1",
                    flag,
                    value,
                ]
                main, output = crosscheck.main, box / "job"
            r = run_one(main, argv, box, output)
            r.update(input=f"{cli} {flag} {value}", argv=argv)
            results.append(r)
            print(
                f"  {r['rc']} {r['seconds']:6.2f}s {cli} {flag} {value}: {r['stderr'].strip()[:150]}",
                file=sys.stderr,
                flush=True,
            )
    return _tally(results) | {"surface": "flags"}


# ---- viewer requests ------------------------------------------------------------------------------------


def viewer_requests(port: int, rng: random.Random) -> list[tuple[str, bytes, bool]]:
    """``(name, raw request, may_be_200)``: may_be_200 for what the viewer's own page could send."""
    own, other = f"127.0.0.1:{port}", f"localhost:{port}"
    body = b'{"ops": [{"op": "orbit", "dx": 5, "dy": 0}]}'

    def post(headers, data=body, target="/api/frame", version="HTTP/1.1"):
        head = f"POST {target} {version}\r\n" + "".join(f"{k}: {v}\r\n" for k, v in headers)
        return head.encode("latin-1") + b"\r\n" + data

    good = [
        ("Host", own),
        ("Content-Type", "application/json"),
        ("Content-Length", str(len(body))),
        ("Connection", "close"),
    ]
    out = [
        ("good POST", post(good), True),
        ("good GET", f"GET /api/frame HTTP/1.1\r\nHost: {own}\r\nConnection: close\r\n\r\n".encode(), True),
    ]
    for name in ("Host", "Origin", "Content-Type", "Content-Length"):
        value = {
            "Host": own,
            "Origin": f"http://{own}",
            "Content-Type": "application/json",
            "Content-Length": str(len(body)),
        }[name]
        for second in (value, "evil.example:80", other if name == "Host" else "0"):
            headers = [h for h in good if h[0] != name] + [(name, value), (name, second)]
            out.append((f"two {name} ({value}, {second})", post(headers), False))
            headers = [h for h in good if h[0] != name] + [(name, value), (name.lower(), second)]
            out.append((f"two {name}, the second lower-case", post(headers), False))
    for host in (
        "",
        " ",
        f"{own} ",
        f"{own}.",
        f"127.0.0.1.:{port}",
        f"{own}@evil",
        "127.0.0.1",
        f"[::1]:{port}",
        f"127.0.0.1:{port + 1}",
        "evil.example",
        own.upper(),
        f"0x7f000001:{port}",
        f"{own}\x00evil",
        f"127.0.0.1:0{port}",
    ):
        headers = [h for h in good if h[0] != "Host"] + [("Host", host)]
        out.append((f"Host {host!r}", post(headers), host in (own, own.upper())))
    out += [
        ("no Host", post([h for h in good if h[0] != "Host"]), False),
        ("absolute-form target", post(good, target="http://evil.example/api/frame"), False),
        (
            "chunked body",
            post(
                [h for h in good if h[0] != "Content-Length"] + [("Transfer-Encoding", "chunked")],
                data=b"%x\r\n" % len(body) + body + b"\r\n0\r\n\r\n",
            ),
            False,
        ),
        ("length and chunked", post(good + [("Transfer-Encoding", "chunked")]), False),
        ("HTTP/0.9", b"GET /api/frame\r\n\r\n", False),
        ("HTTP/2.0 line", post(good, version="HTTP/2.0"), False),
        ("a NUL in the target", post(good, target="/api/frame\x00x"), False),
        ("a 70 KB target", post(good, target="/" + "a" * 70_000), False),
        ("200 headers", post(good + [(f"X-{i}", "y") for i in range(200)]), False),
        ("a header line without a colon", post(good + [("X", "y")]).replace(b"X: y", b"X y"), False),
        ("negative length", post([h for h in good if h[0] != "Content-Length"] + [("Content-Length", "-5")]), False),
        ("length +5", post([h for h in good if h[0] != "Content-Length"] + [("Content-Length", "+5")]), False),
        ("Origin null", post(good + [("Origin", "null")]), False),
    ]
    for i in range(60):  # random byte mutations of the good POST
        raw = bytearray(post(good))
        for _ in range(rng.randint(1, 4)):
            k = rng.randrange(len(raw))
            op = rng.choice("flip insert delete")
            if op == "flip":
                raw[k] = rng.randrange(256)
            elif op == "insert":
                raw[k:k] = bytes([rng.randrange(256)])
            else:
                del raw[k]
        out.append((f"mutated {i}", bytes(raw), True))  # a mutation may leave a valid request (or a typo'd value)
    return out


def _send(port: int, data: bytes, timeout: float = 15.0):
    with socket.create_connection(("127.0.0.1", port), timeout=timeout) as c:
        try:
            c.sendall(data)
            c.shutdown(socket.SHUT_WR)
        except OSError:
            pass
        got = b""
        try:
            while chunk := c.recv(65536):
                got += chunk
        except ConnectionResetError:
            pass
    first = got.split(b"\r\n", 1)[0].split()
    return int(first[1]) if len(first) > 1 and first[1].isdigit() else None


def fuzz_viewer(seed: int) -> dict:
    from wirecheck.core.app.cli import build_parser, settings_from_args
    from wirecheck.core.app.viewer import Viewer
    from wirecheck.core.app.viewer_http import Server

    codes, found, examples = collections.Counter(), collections.Counter(), []
    with tempfile.TemporaryDirectory(prefix="wirecheck-r4-") as d:
        settings = settings_from_args(
            build_parser().parse_args(
                ["--frames", "6", "--width", "64", "--height", "48", "--out", str(Path(d) / "out")]
            )
        )
        err = io.StringIO()
        with contextlib.redirect_stderr(err):
            srv = Server(Viewer(settings)).start()
            port = srv.httpd.server_address[1]
            good = f"GET /api/frame HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nConnection: close\r\n\r\n".encode()
            requests = viewer_requests(port, random.Random(seed))
            try:
                for name, raw, may_be_200 in requests:
                    problems = []
                    try:
                        status = _send(port, raw)
                    except TimeoutError:
                        status, problems = "hang", ["hangs"]
                    codes[status] += 1
                    if status is None:
                        problems.append("answers without a status line")
                    if status == 200 and not may_be_200:
                        problems.append("200 to a hostile request")
                    if isinstance(status, int) and status >= 500 and status not in (501, 505):  # http.server's own
                        problems.append("5xx")
                    if _send(port, good) != 200:
                        problems.append("server stopped answering")
                    if err.getvalue():
                        problems.append("tracebacks")
                        err.seek(0)
                        err.truncate()
                    for p in problems:
                        found[p] += 1
                    if problems and len(examples) < 10:
                        examples.append({"input": name, "status": status, "found": problems})
            finally:
                srv.stop()
    return {
        "surface": "viewer",
        "inputs": len(requests),
        "statuses": {str(k): v for k, v in sorted(codes.items(), key=str)},
        "findings": dict(found),
        "examples": examples,
    }


def main(argv=None) -> int:
    global TIMEOUT_S
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--surface", choices=("files", "flags", "viewer", "all"), default="all")
    p.add_argument("--seed", type=int, default=36)
    p.add_argument("--json", default=None, help="also write the counts here")
    p.add_argument("--timeout", type=int, default=TIMEOUT_S, help="seconds an input may run (default 60)")
    p.add_argument(
        "--memory-gb",
        type=float,
        default=8.0,
        help="address-space limit of this process (default 8: a reader of /dev/zero fails, not the machine)",
    )
    a = p.parse_args(argv)
    TIMEOUT_S = a.timeout
    limit = int(a.memory_gb * (1 << 30))
    resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    warnings.simplefilter("ignore")
    os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa")
    signal.signal(signal.SIGALRM, _alarm)
    results = []
    t0 = time.perf_counter()
    for surface in ("files", "flags", "viewer") if a.surface == "all" else (a.surface,):
        t = time.perf_counter()
        r = fuzz_files() if surface == "files" else fuzz_flags() if surface == "flags" else fuzz_viewer(a.seed)
        r["seconds"] = round(time.perf_counter() - t)
        results.append(r)
    for r in results:
        print(json.dumps({k: v for k, v in r.items() if k != "examples"}))
        for ex in r["examples"][:5]:
            print("  e.g.", json.dumps(ex)[:400])
    print(f"wall {time.perf_counter() - t0:.0f} s")
    if a.json:
        Path(a.json).write_text(json.dumps(results, indent=1) + "\n")
    return 1 if any(r["findings"] for r in results) else 0


if __name__ == "__main__":
    sys.exit(main())
