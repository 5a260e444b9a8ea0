"""A run's outputs: assembled in one temporary folder, moved into place together at the end.

Rules, so that wirecheck never destroys what it did not write and never
leaves a half-written or mixed set:

1. Everything is written into ``<out>/.wirecheck-<unique>.tmp/`` (a unique
   name: no fixed-name probe or backup file in the user's folder). A failure,
   SIGINT or SIGTERM removes it, and removes the folders the run created.
2. An output name that already exists is replaced only when wirecheck wrote
   it: a file listed in ``<out>/.wirecheck-manifest.json`` with the SHA-256
   it had when written (a file edited since is the user's), or a folder whose
   ``.wirecheck-output`` listing names everything in it with its SHA-256
   (core.outputs.owned: a user's note put into ``cube-frames/`` is found). Anything
   else (a user's file, a folder where a file is written or the reverse, an
   empty folder named like an output file, a symlink) is refused with exit 2
   and one line naming it, before the run starts and again before the first
   move, and left as is.
3. The commit is recoverable: the journal ``<out>/.wirecheck-journal.json``
   (the temporary folder's name, the names to move, the new manifest) is
   written before the first move and removed after the manifest. A run killed
   at any point (SIGKILL, the OOM killer) leaves the old set, the new set, or
   a journal; the next run into that folder finishes the moves the journal
   lists before anything else (each move is idempotent: a name still in the
   temporary folder is moved, one already moved is skipped), and removes the
   temporaries of killed runs.
4. One run writes an output folder at a time: ``<out>/.wirecheck-lock`` held
   with ``flock`` (core.outputs.lockfile), released by the kernel when the process
   ends, so neither a dead run nor a reused pid blocks a later run.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import signal
import tempfile
from pathlib import Path

from . import owned
from ..errors import InputError
from .lockfile import Lock, holder
from .owned import MARKER, TAG, sha256

MANIFEST = ".wirecheck-manifest.json"
JOURNAL = ".wirecheck-journal.json"
LOCK = ".wirecheck-lock"
_TMP = re.compile(r"\.wirecheck-[A-Za-z0-9_]+\.tmp")
_TMP_FILE = re.compile(r"\.(wirecheck-manifest|wirecheck-journal)\.json\.[A-Za-z0-9_]+\.tmp")

__all__ = ["MANIFEST", "JOURNAL", "LOCK", "MARKER", "Staging", "check_out", "read_manifest", "sha256"]


def _split(names) -> tuple[list[str], set[str]]:
    """Output names (a folder output is given with a trailing ``/``) and the set of folder names."""
    plain = [n.rstrip("/") for n in names]
    return plain, {n.rstrip("/") for n in names if n.endswith("/")}


def _read_json(path: Path, key: str, option: str) -> dict | None:
    if not path.exists() and not path.is_symlink():
        return None
    try:
        if path.is_symlink() or not path.is_file():
            raise ValueError("not a regular file")
        data = json.loads(path.read_text(encoding="utf-8"))
        if data.get(key) != 1:
            raise ValueError("not ours")
        return data
    except (OSError, ValueError, KeyError, TypeError, AttributeError, UnicodeDecodeError):
        raise InputError(f"{option} {str(path.parent)!r}: {path.name} there was not written by wirecheck: expected "
                         "an output folder of wirecheck's or a new one (nothing was changed; move it away)") from None


def read_manifest(out: Path, option: str) -> dict:
    """``{name: sha256}`` of the files wirecheck wrote in ``out`` ({} when there is no manifest)."""
    data = _read_json(Path(out) / MANIFEST, "wirecheck_manifest", option)
    if data is None:
        return {}
    if not isinstance(data.get("files"), dict):
        raise InputError(f"{option} {str(out)!r}: {MANIFEST} there was not written by wirecheck: expected an "
                         "output folder of wirecheck's or a new one (nothing was changed; move it away)")
    return {str(k): str(v) for k, v in data["files"].items()}


def _read_journal(out: Path, option: str) -> dict | None:
    data = _read_json(Path(out) / JOURNAL, "wirecheck_journal", option)
    if data is None:
        return None
    ok = (isinstance(data.get("tmp"), str) and _TMP.fullmatch(data["tmp"])
          and isinstance(data.get("names"), list) and all(isinstance(n, str) and "/" not in n and n
                                                          and not n.startswith(".") for n in data["names"])
          and isinstance(data.get("manifest"), dict))
    if not ok:
        raise InputError(f"{option} {str(out)!r}: {JOURNAL} there was not written by wirecheck: expected an "
                         "output folder of wirecheck's or a new one (nothing was changed; move it away)")
    return data


def _known(out: Path, option: str) -> dict:
    """``{name: {sha256, ...}}``: the manifest's hashes, and the journal's of a commit a killed run left."""
    known = {name: {digest} for name, digest in read_manifest(out, option).items()}
    journal = _read_journal(out, option)
    for name, digest in (journal or {}).get("manifest", {}).items():
        known.setdefault(str(name), set()).add(str(digest))
    return known


def check_replaceable(out: Path, name: str, known: dict, option: str, folder: bool = False) -> None:
    """InputError unless ``out/name`` is absent or an earlier output of wirecheck's (module docstring, rule 2)."""
    path = Path(out) / name
    if not path.exists() and not path.is_symlink():
        return
    if path.is_symlink():
        kind = "a symbolic link"
    elif path.is_dir():
        if not folder:
            kind = "a directory where wirecheck writes a file"
        else:
            why = owned.ours(path)
            if why is None:
                return
            kind = why
    elif folder:
        kind = "a file where wirecheck writes a folder"
    elif path.is_file() and sha256(path) in known.get(name, ()):
        return
    else:
        kind = "a file not written by wirecheck" if name not in known else "a file changed since wirecheck wrote it"
    raise InputError(f"{option} {str(path)!r} is {kind}: expected a new path or an earlier wirecheck output "
                     "(nothing was changed; move it away first)")


def check_out(out: Path, names, option: str = "--out", _locked: bool = False) -> None:
    """Check, without writing anything, that a run can write ``names`` into ``out`` (folders end in ``/``)."""
    out = Path(out)
    names, folders = _split(names)
    if out.is_symlink() and not out.is_dir():
        raise InputError(f"{option} {str(out)!r} is a broken symbolic link: expected a directory")
    if out.exists() and not out.is_dir():
        raise InputError(f"{option} {str(out)!r} is a file: expected a directory")
    if not out.exists():
        parent = out.parent
        while not parent.exists() and parent != parent.parent:
            parent = parent.parent
        if not parent.is_dir():
            raise InputError(f"{option} {str(out)!r}: {str(parent)!r} is a file: expected a directory path")
        if not os.access(parent, os.W_OK | os.X_OK):
            raise InputError(f"{option} {str(out)!r}: {str(parent)!r} is not writable: expected a writable folder")
        return
    if not os.access(out, os.W_OK | os.X_OK):
        raise InputError(f"{option} {str(out)!r} is not writable: expected a writable directory")
    if not _locked:
        _refuse_if_locked(out, option)
    try:
        known = _known(out, option)
        for name in names:
            check_replaceable(out, name, known, option, name in folders)
    except InputError:
        if not _locked:
            _refuse_if_locked(out, option)     # another run moving its outputs in: say that instead
        raise


def _refuse_if_locked(out: Path, option: str) -> None:
    who = holder(out / LOCK)
    if who is not None:
        raise InputError(f"{option} {str(out)!r} is being written by another wirecheck run"
                         f"{f' ({who})' if who else ''}: expected one run per output folder at a time; "
                         "wait for it or use another --out")


def _write_json(path: Path, obj: dict) -> None:
    """``path`` written whole under a temporary name, then renamed into place (a counted move, core.outputs.owned)."""
    fd, tmp = tempfile.mkstemp(prefix=f"{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            fh.write(json.dumps(obj, indent=1, sort_keys=True) + "\n")
        owned.rename(tmp, path)
    except BaseException:
        if os.path.lexists(tmp):
            os.unlink(tmp)
        raise


def _move_in(out: Path, tmp: Path, names, folders) -> None:
    """Move each staged name from ``tmp`` into ``out``; a name no longer in ``tmp`` was moved already."""
    for name in names:
        src, dst = tmp / name, out / name
        if not os.path.lexists(src):
            continue
        if name in folders:
            if os.path.lexists(dst):          # the old folder goes with the temporaries (a unique name there)
                owned.rename(dst, Path(tempfile.mkdtemp(prefix=f".old-{name}.", dir=tmp)) / name)
            owned.rename(src, dst)
        else:
            owned.rename(src, dst)


def _finish(out: Path, journal: dict, option: str, check: bool = True) -> None:
    """Complete the commit ``journal`` describes (rule 3): moves, manifest, journal removed, temporaries.

    ``check``: first check every target again (a killed run's journal: the user may have been there since).
    """
    tmp = out / journal["tmp"]
    names, folders = journal["names"], set(journal.get("folders", []))
    if check and tmp.is_dir() and not tmp.is_symlink():
        known = _known(out, option)
        for name in names:
            if os.path.lexists(tmp / name):
                check_replaceable(out, name, known, option, name in folders)
    if tmp.is_dir() and not tmp.is_symlink():
        _move_in(out, tmp, names, folders)
    _write_json(out / MANIFEST, {"wirecheck_manifest": 1, "files": journal["manifest"]})
    (out / JOURNAL).unlink()
    shutil.rmtree(tmp, ignore_errors=True)


def _recover(out: Path, option: str) -> None:
    """Under the lock: finish a killed run's commit, remove killed runs' temporaries (rule 3)."""
    journal = _read_journal(out, option)
    if journal is not None:
        _finish(out, journal, option)
    for entry in os.scandir(out):
        if entry.is_dir(follow_symlinks=False) and _TMP.fullmatch(entry.name):
            if os.path.lexists(os.path.join(entry.path, TAG)):
                shutil.rmtree(entry.path, ignore_errors=True)
            else:
                try:
                    os.rmdir(entry.path)      # killed between its creation and its tag: empty
                except OSError:
                    pass
        elif entry.is_file(follow_symlinks=False) and _TMP_FILE.fullmatch(entry.name):
            os.unlink(entry.path)


class Staging:
    """The temporary folder of one run in ``out`` and the move of its contents into place.

    ``names`` are the output names the run may write (files, or folders given
    with a trailing ``/``). Use :meth:`path` to write, then :meth:`commit`; on
    any exception call :meth:`abort` (both release the lock).
    """

    def __init__(self, out: Path, names, option: str = "--out"):
        self.out, self.option = Path(out), option
        self.names, self.folders = _split(names)
        self.created: list[Path] = []
        self.tmp = None
        self._lock = None
        self._journaled = False
        try:
            self._make_out()
            self._lock = Lock(self.out / LOCK, option, str(self.out))
            _recover(self.out, option)
            check_out(self.out, list(names), option, _locked=True)
            self.tmp = Path(tempfile.mkdtemp(prefix=".wirecheck-", suffix=".tmp", dir=self.out))
            (self.tmp / TAG).write_bytes(b"")
        except BaseException:
            self.abort()
            raise

    def _make_out(self) -> None:
        missing = []
        p = self.out
        while not p.exists() and not p.is_symlink() and p != p.parent:
            missing.append(p)
            p = p.parent
        for folder in reversed(missing):
            try:
                folder.mkdir()
            except FileExistsError:      # another run made it meanwhile: not ours to remove
                continue
            self.created.append(folder)

    def path(self, name: str) -> Path:
        """Where to write output ``name`` (inside the temporary folder)."""
        return self.tmp / name

    def commit(self) -> None:
        """Check every target, then move every staged output into place under a journal (rule 3)."""
        blocked = {signal.SIGINT, signal.SIGTERM}
        signal.pthread_sigmask(signal.SIG_BLOCK, blocked)    # the moves finish together: no mixed set
        try:
            known = _known(self.out, self.option)
            manifest = read_manifest(self.out, self.option)
            staged = [n for n in self.names if os.path.lexists(self.tmp / n)]
            for name in staged:              # every target, before the first move
                check_replaceable(self.out, name, known, self.option, name in self.folders)
            for name in staged:
                if name in self.folders:
                    owned.seal(self.tmp / name)
                    manifest.pop(name, None)
                else:
                    manifest[name] = sha256(self.tmp / name)
            journal = {"wirecheck_journal": 1, "tmp": self.tmp.name, "names": staged,
                       "folders": sorted(self.folders & set(staged)), "manifest": manifest}
            _write_json(self.out / JOURNAL, journal)
            self._journaled = True           # from here on the next run can finish it: keep the temporaries
            _finish(self.out, journal, self.option, check=False)
            self.tmp = None
            self.created = []                # the outputs live there now
        finally:
            self.abort()
            signal.pthread_sigmask(signal.SIG_UNBLOCK, blocked)     # a pending signal is raised here

    def abort(self) -> None:
        """Remove the temporaries (unless a journal names them), the lock, and the folders this run created."""
        if self.tmp is not None and not self._journaled:
            shutil.rmtree(self.tmp, ignore_errors=True)
        self.tmp = None
        if self._lock is not None:
            self._lock.release()
            self._lock = None
        if self._journaled:
            self.created = []
        for folder in reversed(self.created):
            try:
                folder.rmdir()
            except OSError:
                break
        self.created = []
