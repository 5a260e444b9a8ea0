"""Fuzz round 4 (issue 36): the commit window, planted locks, journals and markers, two runs at once, kill -9.

Every input is one or two real processes (the ``renderer`` and ``crosscheck`` modules run with
``python -m``), each with a 60 s timeout, in a fresh folder holding a user's file (``thesis.tex``)
beside the output folder. Per input the contract is checked:

- exit status 0 or 2 (1 never applies: the candidate is core); exit 2 with exactly one stderr line;
- no traceback; no hang (a run over 60 s is killed and counted);
- no user file touched: the user's file, anything planted, and anything written during a commit is still
  there with its bytes (a file written during the commit may be moved into the new folder, or beside a
  file of the same name as ``NAME.kept``, and the run must say so);
- no leftovers: after the run (and, for kills, after the rerun), nothing of wirecheck's but the outputs:
  no ``*.tmp``, no lock, no journal (except the journal a commit leaves when a user's folder took the
  place of the new one: it is said on stderr, and counted apart).

Surfaces (counts per surface in the printed table; docs/reliability.md, round 4):

1. ``locks``: a file of each kind planted at the lock's name of the renderer's ``--out``, a report folder
   and an export job: empty file, hard link to the user's file, symlink to it, dangling symlink, FIFO,
   directory, socket, foreign content, an 8 MB file, a lock of ours naming a dead pid (must run: 0).
2. ``journals``: a ``.wirecheck-journal.json`` in ``--out`` of each kind: FIFO, symlink, hard link,
   empty, not JSON, 2 MB, naming the user's file (with its true hash and a tagged temporary holding a
   replacement), an untagged user folder as its temporary, ``folders`` an integer, ``names`` a string,
   a temporary outside ``--out``, a bad hash.
3. ``markers``: the ``.wirecheck-output`` of an earlier ``cube-frames/`` replaced by each kind: FIFO,
   symlink, hard link, directory, 70 MB, foreign JSON, a listing naming a folder 1,100 deep.
4. ``window``: a rerun paused at a random step of its commit (WIRECHECK_PAUSE_AT_STEP) while the "user"
   writes a note into the output folder, edits an output file, or makes a sub-folder with a file.
5. ``concurrency``: two runs into one target with random lengths, the second (B, 1 frame) started 0-2 s
   after the first (A): each exits 0 or 2 naming the other; a finding when both exit 0 although the lock
   file named A's pid before B started and A was still running when B ended (A held the target through
   B's whole run: B must be refused). Both may exit 0 one after the other: B, quicker to start, took the
   target first and was done before A took it, or A was done before B took it. Also measured: the
   share of run A's life (process start to end) during which the lock file named A: a lock that
   covers only the write covers a sliver of the run; one held from the start covers all but the
   interpreter's start-up.
6. ``kills``: kill -9 after rename k of a rerun's commit (every k), then a plain rerun: exit 0, a
   consistent set, no leftovers.

Usage (seed 36 unless told; ``--quick`` takes a tenth of the random inputs)::

    nice .venv/bin/python benchmarks/fuzz_disk.py [--seed 36] [--quick]
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import random
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
from collections import Counter
from pathlib import Path

PY = sys.executable
RENDER = [PY, "-m", "wirecheck.core.app.cli", "--width", "32", "--height", "24"]
CROSS = [PY, "-m", "wirecheck.oracles.cli"]
TIMEOUT_S = 60
USERS = b"\\documentclass{article} the user's thesis\n"
LOCK, JOURNAL, MARKER, TAG = ".wirecheck-lock", ".wirecheck-journal.json", ".wirecheck-output", ".wirecheck-staging"


def env(**extra):
    e = {k: v for k, v in os.environ.items() if not k.startswith("WIRECHECK_")}
    e.update({k: str(v) for k, v in extra.items()})
    return e


def run(argv, **extra):
    """(rc, stderr, seconds); rc "hang" when killed at the timeout."""
    t0 = time.monotonic()
    try:
        p = subprocess.run(argv, capture_output=True, text=True, timeout=TIMEOUT_S, env=env(**extra))
        return p.returncode, p.stderr, time.monotonic() - t0
    except subprocess.TimeoutExpired as exc:
        return "hang", (exc.stderr or b"").decode(errors="replace") if isinstance(exc.stderr, bytes) else "", TIMEOUT_S


def target_argv(kind, box, frames):
    if kind == "renderer":
        return [*RENDER, "--frames", str(frames), "--out", str(box / "out")], box / "out", box / "out" / LOCK
    if kind == "report":
        return (
            [
                *CROSS,
                "--report-dir",
                str(box / "r"),
                "--scene",
                "cube",
                "--cases",
                "on_axis",
                "--oracles",
                "opencv",
                "--frames",
                str(frames),
            ],
            box / "r",
            box / ".r.wirecheck-lock",
        )
    return (
        [*CROSS, "export", str(box / "j"), "--scene", "cube", "--cases", "on_axis", "--frames", str(frames)],
        box / "j",
        box / ".j.wirecheck-lock",
    )


def snapshot(box):
    """{relative path: (kind, bytes hash)} of everything under ``box`` (links not followed)."""
    out = {}
    for dirpath, dirnames, filenames in os.walk(box):
        for name in dirnames + filenames:
            p = os.path.join(dirpath, name)
            st = os.lstat(p)
            rel = os.path.relpath(p, box)
            if os.path.islink(p):
                out[rel] = ("link", os.readlink(p))
            elif os.path.isfile(p):
                if st.st_size > (16 << 20):
                    out[rel] = ("file", st.st_size, st.st_ino)
                else:
                    with open(p, "rb") as fh:
                        out[rel] = ("file", hashlib.sha256(fh.read()).hexdigest())
            elif os.path.isdir(p):
                out[rel] = ("dir",)
            else:
                out[rel] = ("special", st.st_mode)
    return out


def leftovers(box):
    found = []
    for dirpath, dirnames, filenames in os.walk(box):
        for name in dirnames + filenames:
            if name.endswith(".tmp") or name in (JOURNAL,) or name.endswith("wirecheck-lock"):
                found.append(os.path.relpath(os.path.join(dirpath, name), box))
    return found


class Tally:
    def __init__(self):
        self.rows = {}

    def add(self, surface, rc, err, touched=0, left=0, note=None):
        row = self.rows.setdefault(surface, Counter())
        row["inputs"] += 1
        row[f"exit {rc}"] += 1
        row["tracebacks"] += "Traceback" in (err or "")
        row["hangs"] += rc == "hang"
        row["odd exits"] += rc not in (0, 2, "hang")
        row["exit 2 not one line"] += rc == 2 and (err or "").count("\n") != 1
        row["user files touched"] += touched
        row["leftovers"] += left
        if note:
            row[note] += 1
        if (
            touched
            or left
            or rc not in (0, 2)
            or "Traceback" in (err or "")
            or (rc == 2 and (err or "").count("\n") != 1)
        ):
            print(
                f"  FINDING {surface}: rc={rc} touched={touched} left={left}: {(err or '').strip()[:300]}",
                file=sys.stderr,
            )


def plant(path, kind, user):
    if kind == "empty":
        path.write_bytes(b"")
    elif kind == "hard_link":
        os.link(user, path)
    elif kind == "symlink":
        os.symlink(user, path)
    elif kind == "dangling":
        os.symlink(path.parent / "nowhere", path)
    elif kind == "fifo":
        os.mkfifo(path)
    elif kind == "directory":
        path.mkdir()
        (path / "inside.txt").write_bytes(b"the user's")
    elif kind == "socket":
        s = socket.socket(socket.AF_UNIX)
        s.bind(str(path))
        return s
    elif kind == "foreign":
        path.write_bytes(b"my own notes\n")
    elif kind == "huge":
        with open(path, "wb") as fh:
            fh.truncate(8 << 20)
    return None


def surface_locks(tally, work):
    kinds = ["empty", "hard_link", "symlink", "dangling", "fifo", "directory", "socket", "foreign", "huge", "stale"]
    for target in ("renderer", "report", "export"):
        for kind in kinds:
            box = Path(tempfile.mkdtemp(dir=work))
            user = box / "thesis.tex"
            user.write_bytes(USERS)
            argv, out, lock = target_argv(target, box, 1)
            if target == "renderer":
                out.mkdir()
            sock = None
            if kind == "stale":
                dead = subprocess.Popen(["true"])
                dead.wait()
                lock.write_text(f"wirecheck lock pid {dead.pid}\n")
            else:
                sock = plant(lock, kind, user)
            before = snapshot(box)
            rc, err, _ = run(argv)
            if sock is not None:
                sock.close()
            after = snapshot(box)
            touched = sum(
                1
                for k, v in before.items()
                if after.get(k) != v and not (kind == "stale" and k == str(lock.relative_to(box)))
            )
            expected = 0 if kind == "stale" else 2
            left = int(kind == "stale" and bool(leftovers(box)))
            tally.add("locks", rc, err, touched, left, None if rc == expected else "unexpected exit")
            shutil.rmtree(box, ignore_errors=True)


def surface_journals(tally, work):
    kinds = [
        "fifo",
        "symlink",
        "hard_link",
        "empty",
        "not_json",
        "huge",
        "users_file",
        "untagged_tmp",
        "folders_int",
        "names_str",
        "tmp_outside",
        "bad_hash",
    ]
    for kind in kinds:
        box = Path(tempfile.mkdtemp(dir=work))
        user = box / "thesis.tex"
        user.write_bytes(USERS)
        out = box / "out"
        out.mkdir()
        (out / "thesis.tex").write_bytes(USERS)
        path = out / JOURNAL
        base = {
            "wirecheck_journal": 1,
            "tmp": ".wirecheck-abc123.tmp",
            "names": ["cube-report.txt"],
            "folders": [],
            "manifest": {},
        }
        tmp = out / base["tmp"]
        if kind in ("users_file", "folders_int", "names_str", "tmp_outside", "bad_hash"):
            tmp.mkdir()
            (tmp / TAG).write_bytes(b"")
        if kind in ("fifo", "symlink", "hard_link", "empty", "huge"):
            plant(path, kind, user)
        elif kind == "not_json":
            path.write_bytes(b"\xff{not json")
        else:
            data = dict(base)
            if kind == "users_file":
                (tmp / "thesis.tex").write_bytes(b"replaced\n")
                data.update(names=["thesis.tex"], manifest={"thesis.tex": hashlib.sha256(USERS).hexdigest()})
            elif kind == "untagged_tmp":
                users = out / ".wirecheck-mydata.tmp"
                users.mkdir()
                (users / "data.csv").write_bytes(b"1,2\n")
                data.update(tmp=users.name)
            elif kind == "folders_int":
                data.update(folders=5)
            elif kind == "names_str":
                data.update(names="cube-report.txt")
            elif kind == "tmp_outside":
                data.update(tmp="../elsewhere")
            else:
                data.update(manifest={"cube-report.txt": "xyz"})
            path.write_text(json.dumps(data))
        before = snapshot(box)
        rc, err, _ = run([*RENDER, "--frames", "1", "--out", str(out)])
        after = snapshot(box)
        touched = sum(1 for k, v in before.items() if after.get(k) != v)
        ok = rc == 2 and JOURNAL in err
        tally.add("journals", rc, err, touched, 0, None if ok else "unexpected exit")
        shutil.rmtree(box, ignore_errors=True)


def surface_markers(tally, work):
    for kind in ("fifo", "symlink", "hard_link", "directory", "huge", "foreign", "deep_user"):
        box = Path(tempfile.mkdtemp(dir=work))
        user = box / "thesis.tex"
        user.write_bytes(USERS)
        out = box / "out"
        rc, err, _ = run([*RENDER, "--frames", "1", "--out", str(out)])
        assert rc == 0, err
        marker = out / "cube-frames" / MARKER
        if kind == "deep_user":
            listing = json.loads(marker.read_text())
            rel, p = "", out / "cube-frames"
            for _ in range(1100):
                rel, p = (f"{rel}/d" if rel else "d"), p / "d"
                os.mkdir(p)
                listing["folders"].append(rel)
            (p / "note.txt").write_bytes(b"the user's")
            marker.write_text(json.dumps(listing))
        else:
            os.unlink(marker)
            if kind == "huge":
                with open(marker, "wb") as fh:
                    fh.truncate(70 << 20)
            elif kind == "foreign":
                marker.write_text(json.dumps({"kind": "something else", "files": {}, "folders": []}))
            else:
                plant(marker, kind, user)
        before = snapshot(box) if kind != "deep_user" else None
        rc, err, _ = run([*RENDER, "--frames", "1", "--out", str(out)])
        touched = 0
        if kind == "deep_user":
            touched = int(not (p / "note.txt").is_file())
            while p != out / "cube-frames":  # iterative clean-up (shutil.rmtree recurses on 3.11)
                for name in os.listdir(p):
                    if not (p / name).is_dir():
                        os.unlink(p / name)
                os.rmdir(p)
                p = p.parent
        else:
            after = snapshot(box)
            touched = sum(1 for k, v in before.items() if after.get(k) != v)
        tally.add("markers", rc, err, touched, 0, None if rc == 2 else "unexpected exit")
        shutil.rmtree(box, ignore_errors=True)


# steps of a rerun's commit (core.outputs.owned.step): renderer png over an earlier set: 9; FrameDir: 2
STEPS = {"renderer": 9, "report": 2, "export": 2}


def surface_window(tally, work, rng, n):
    for _ in range(n):
        target = rng.choice(["renderer", "renderer", "report", "export"])
        step = rng.randint(1, STEPS[target] + 1)
        action = rng.choice(["note", "edit", "subfolder"])
        box = Path(tempfile.mkdtemp(dir=work))
        (box / "thesis.tex").write_bytes(USERS)
        argv, out, _ = target_argv(target, box, 1)
        if target == "renderer":
            argv = [*argv, "--format", "png"]
        rc, err, _ = run(argv)
        assert rc == 0, err
        folder = out / "cube-frames" if target == "renderer" else out
        argv2 = [a if a != "1" or argv[i - 1] != "--frames" else "2" for i, a in enumerate(argv)]
        pause = box / "pause"
        proc = subprocess.Popen(
            argv2,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            env=env(WIRECHECK_PAUSE_AT_STEP=step, WIRECHECK_PAUSE_FILE=pause),
        )
        written = None
        deadline = time.monotonic() + TIMEOUT_S
        while proc.poll() is None and time.monotonic() < deadline:
            if pause.exists():
                folder.mkdir(parents=True, exist_ok=True)
                if action == "note":
                    written = ("note.txt", b"a note")
                elif action == "edit":
                    name = (
                        "frame_0001.png"
                        if target == "renderer"
                        else ("report.md" if target == "report" else "README.md")
                    )
                    written = (name, b"edited by the user")
                else:
                    (folder / "mine").mkdir(exist_ok=True)
                    written = ("mine/a.txt", b"in a sub-folder")
                (folder / written[0]).write_bytes(written[1])
                pause.unlink()
                break
            time.sleep(0.01)
        try:
            err = proc.communicate(timeout=TIMEOUT_S)[1].decode()
            rc = proc.returncode
        except subprocess.TimeoutExpired:
            proc.kill()
            err, rc = proc.communicate()[1].decode(), "hang"
        touched = 0
        note = "not paused (past the last step)" if written is None else None
        if written is not None:
            rel, data = written
            places = [folder / rel, folder / (rel + ".kept")] + [folder / (rel + f".kept{k}") for k in range(2, 5)]
            touched = int(not any(p.is_file() and p.read_bytes() == data for p in places))
        left = leftovers(box)
        journal_waits = [x for x in left if x.endswith(JOURNAL)] and "appeared" in err
        if journal_waits:
            note = "journal kept: a user's folder took the new one's place (said)"
            left = []
        tally.add("window", rc, err, touched, int(bool(left)), note)
        shutil.rmtree(box, ignore_errors=True)


def surface_concurrency(tally, work, rng, n):
    for _ in range(n):
        target = rng.choice(["renderer", "report", "export"])
        long_frames = rng.choice([200, 800, 2000]) if target != "export" else rng.choice([50, 200])
        delay = rng.uniform(0.0, 2.0)
        box = Path(tempfile.mkdtemp(dir=work))
        a_argv, out, lock = target_argv(target, box, long_frames)
        b_argv, _, _ = target_argv(target, box, 1)
        a_start = time.monotonic()
        a = subprocess.Popen(a_argv, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, env=env())
        seen = []  # when the lock file named A's pid (sampled every 5 ms)
        stop = threading.Event()

        def watch():
            while not stop.is_set():
                try:
                    if lock.read_text() == f"wirecheck lock pid {a.pid}\n":
                        seen.append(time.monotonic())
                except OSError:
                    pass
                time.sleep(0.005)

        watcher = threading.Thread(target=watch, daemon=True)
        watcher.start()
        time.sleep(delay)
        held_by_a = bool(seen)  # A's pid read from the lock file before B started: A held the target
        rc_b, err_b, b_s = run(b_argv)
        a_alive = a.poll() is None  # A still running when B ended: A held the target all through B's run
        try:
            err_a = a.communicate(timeout=TIMEOUT_S * 3)[1].decode()
            rc_a = a.returncode
        except subprocess.TimeoutExpired:
            a.kill()
            err_a, rc_a = a.communicate()[1].decode(), "hang"
        a_end = time.monotonic()
        stop.set()
        watcher.join()
        if rc_a == 0 and seen:  # the share of A's run (process start to end) its lock covered
            COVERAGE.setdefault(target, []).append((a_end - seen[0]) / (a_end - a_start))
        both = rc_a == 0 and rc_b == 0
        note = None
        if both and held_by_a and a_alive:
            note = "both committed, B started while A held the target"
            print(f"  FINDING concurrency {target}: {note}", file=sys.stderr)
        elif both:
            note = "both exit 0, one after the other"
        elif rc_b == 2 and held_by_a:
            note = "B refused while A held the target"
        tally.add("concurrency", rc_a, err_a, 0, int(bool(leftovers(box))))
        tally.add("concurrency", rc_b, err_b, 0, 0, note)
        shutil.rmtree(box, ignore_errors=True)


#: {target: [share of run A's lifetime during which the lock file named A, ...]} (surface 5)
COVERAGE: dict = {}


KILL_RENAMES = {"renderer": 10, "report": 1, "export": 1}  # of a rerun's commit: tests/test_commit_kill.py


def surface_kills(tally, work):
    for target, renames in KILL_RENAMES.items():
        for k in range(1, renames + 2):
            box = Path(tempfile.mkdtemp(dir=work))
            (box / "thesis.tex").write_bytes(USERS)
            argv, out, _ = target_argv(target, box, 1)
            if target == "renderer":
                argv = [*argv, "--format", "png,gif"]
            rc, err, _ = run(argv)
            assert rc == 0, err
            argv2 = [a if a != "1" or argv[i - 1] != "--frames" else "2" for i, a in enumerate(argv)]
            rc_k, err_k, _ = run(argv2, WIRECHECK_KILL_AFTER_RENAME=k)
            want = -signal.SIGKILL if k <= renames else 0
            argv3 = [a if a != "1" or argv[i - 1] != "--frames" else "3" for i, a in enumerate(argv)]
            rc, err, _ = run(argv3)
            consistent = rc == 0 and _consistent(target, out, 3)
            touched = int((box / "thesis.tex").read_bytes() != USERS)
            tally.add(
                "kills",
                rc,
                err,
                touched,
                int(bool(leftovers(box))),
                None if consistent and rc_k == want else "inconsistent after the rerun",
            )
            shutil.rmtree(box, ignore_errors=True)


def _consistent(target, out, frames):
    from wirecheck.core.outputs.owned import foreign

    if target == "renderer":
        report = json.loads((out / "cube-report.json").read_text())
        pngs = [n for n in os.listdir(out / "cube-frames") if n.endswith(".png")]
        manifest = json.loads((out / ".wirecheck-manifest.json").read_text())["files"]
        hashes = all(hashlib.sha256((out / n).read_bytes()).hexdigest() == h for n, h in manifest.items())
        return report["summary"]["frames"] == len(pngs) == frames and hashes and foreign(out / "cube-frames") is None
    if target == "report":
        return json.loads((out / "report.json").read_text())["frames"] == frames and foreign(out) is None
    cases = json.loads((out / "job.json").read_text())["cases"]
    return {len(c["frames"]) for c in cases} == {frames} and foreign(out) is None


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--seed", type=int, default=36)
    p.add_argument("--quick", action="store_true", help="a tenth of the random inputs")
    p.add_argument("--only", default=None, help="comma-separated surfaces")
    args = p.parse_args(argv)
    rng = random.Random(args.seed)
    scale = 0.1 if args.quick else 1.0
    tally = Tally()
    only = set(args.only.split(",")) if args.only else None
    t0 = time.monotonic()
    with tempfile.TemporaryDirectory(prefix="fuzz_disk.") as work:
        work = Path(work)
        surfaces = [
            ("locks", lambda: surface_locks(tally, work)),
            ("journals", lambda: surface_journals(tally, work)),
            ("markers", lambda: surface_markers(tally, work)),
            ("window", lambda: surface_window(tally, work, rng, max(4, int(60 * scale)))),
            ("concurrency", lambda: surface_concurrency(tally, work, rng, max(2, int(30 * scale)))),
            ("kills", lambda: surface_kills(tally, work)),
        ]
        for name, go in surfaces:
            if only is None or name in only:
                s0 = time.monotonic()
                go()
                print(f"{name}: {dict(tally.rows.get(name, {}))} ({time.monotonic() - s0:.0f} s)", file=sys.stderr)
    coverage = {
        t: {"runs": len(v), "median": round(sorted(v)[len(v) // 2], 3), "min": round(min(v), 3)}
        for t, v in COVERAGE.items()
    }
    print(
        json.dumps(
            {
                "seed": args.seed,
                "wall_s": round(time.monotonic() - t0),
                "surfaces": tally.rows,
                "lock_coverage_of_run_a": coverage,
            },
            indent=1,
            default=dict,
        )
    )
    bad = sum(
        row[k]
        for row in tally.rows.values()
        for k in (
            "tracebacks",
            "hangs",
            "odd exits",
            "exit 2 not one line",
            "user files touched",
            "leftovers",
            "unexpected exit",
            "both committed, B started while A held the target",
            "inconsistent after the rerun",
        )
    )
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
