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
   temporaries of killed runs. A journal is trusted only when it is a regular
   file with one link, names only outputs of the run reading it and a tagged
   temporary folder of ours; anything else is refused (exit 2, left in place,
   the message says how to clear it).
4. One run writes an output folder at a time: ``<out>/.wirecheck-lock`` held
   with ``flock`` (core.outputs.lockfile) from the run's start to its end,
   released by the kernel when the process ends, so neither a dead run nor a
   reused pid blocks a later run.
5. No window between check and removal: a name in place is first moved aside
   into the temporary folder (``.old-NAME``), the new one moved in with
   ``RENAME_NOREPLACE`` (what appeared there meanwhile is never replaced),
   and only then is the old one removed, by its hashes (core.outputs.owned.retire).
   A file the user wrote or edited during the commit is moved back beside the
   new outputs, and the run says so in one line and exits 2 (the new set is
   in place and complete).
"""

from __future__ import annotations

import json
import os
import re
import signal
import stat
import tempfile
from pathlib import Path

from ..errors import InputError
from . import owned
from .lockfile import Lock, holder
from .owned import MARKER, TAG, is_dir_here, is_regular, read_regular, remove_tree, retire, sha256

MANIFEST = ".wirecheck-manifest.json"
JOURNAL = ".wirecheck-journal.json"
LOCK = ".wirecheck-lock"
_TMP = re.compile(r"\.wirecheck-[A-Za-z0-9_]+\.tmp")
_TMP_FILE = re.compile(r"\.(wirecheck-manifest|wirecheck-journal)\.json\.[A-Za-z0-9_]+\.tmp")
_HEX64 = re.compile(r"[0-9a-f]{64}")
#: The largest manifest or journal read (a run writes a few names: 1 MB is thousands of them).
MAX_JSON_BYTES = 1 << 20

__all__ = ["MANIFEST", "JOURNAL", "LOCK", "MARKER", "Staging", "check_out", "read_manifest", "sha256"]


def _split(names) -> tuple[list[str], set[str]]:
    """Output names (a folder output is given with a trailing ``/``) and the set of folder names."""
    plain = [n.rstrip("/") for n in names]
    return plain, {n.rstrip("/") for n in names if n.endswith("/")}


def _read_json(path: Path, key: str, option: str) -> dict | None:
    if not os.path.lexists(path):
        return None
    try:
        data = json.loads(read_regular(path, MAX_JSON_BYTES).decode("utf-8"))
        if data.get(key) != 1:
            raise ValueError("not ours")
        return data
    except (OSError, ValueError, KeyError, TypeError, AttributeError, UnicodeDecodeError):
        raise InputError(
            f"{option} {str(path.parent)!r}: {path.name} there was not written by wirecheck: expected "
            "an output folder of wirecheck's or a new one (nothing was changed; move it away)"
        ) from None


def read_manifest(out: Path, option: str) -> dict:
    """``{name: sha256}`` of the files wirecheck wrote in ``out`` ({} when there is no manifest)."""
    data = _read_json(Path(out) / MANIFEST, "wirecheck_manifest", option)
    if data is None:
        return {}
    if not isinstance(data.get("files"), dict):
        raise InputError(
            f"{option} {str(out)!r}: {MANIFEST} there was not written by wirecheck: expected an "
            "output folder of wirecheck's or a new one (nothing was changed; move it away)"
        )
    return {str(k): str(v) for k, v in data["files"].items()}


def _journal_fault(data, out: Path, names) -> str | None:
    """Why ``data`` is not a journal this run may finish (module docstring, rule 3); None when it is."""
    if not isinstance(data, dict) or data.get("wirecheck_journal") != 1:
        return "not a journal of wirecheck's"
    tmp, listed, folders, manifest = (data.get(k) for k in ("tmp", "names", "folders", "manifest"))
    if not (isinstance(tmp, str) and _TMP.fullmatch(tmp)):
        return "its temporary folder is not named .wirecheck-<unique>.tmp"
    if not (
        isinstance(listed, list)
        and all(isinstance(n, str) and n and "/" not in n and not n.startswith(".") for n in listed)
    ):
        return "'names' is not a list of output names"
    other = next((n for n in listed if names is not None and n not in names), None)
    if other is not None:
        return f"it names {other!r}, not an output of this run"
    if not (isinstance(folders, list) and all(isinstance(f, str) and f in listed for f in folders)):
        return "'folders' is not a list of the names it moves"
    if not (
        isinstance(manifest, dict)
        and all(
            isinstance(k, str) and k and "/" not in k and isinstance(v, str) and _HEX64.fullmatch(v)
            for k, v in manifest.items()
        )
    ):
        return "'manifest' is not a list of names and SHA-256 hashes"
    if not is_dir_here(out / tmp):
        return f"its temporary folder {tmp} is not there"
    if not is_regular(out / tmp / TAG):
        return f"its temporary folder {tmp} is not one of wirecheck's (no {TAG} in it)"
    return None


def _read_journal(out: Path, option: str, names=None) -> dict | None:
    """The journal a killed run left in ``out`` (None: none); InputError unless this run may finish it."""
    path = Path(out) / JOURNAL
    if not os.path.lexists(path):
        return None
    try:
        data = json.loads(read_regular(path, MAX_JSON_BYTES).decode("utf-8"))
        why = _journal_fault(data, Path(out), names)
    except ValueError as exc:  # not readable, not UTF-8, not JSON
        why = str(exc) if str(exc)[:2] in ("a ", "no") else "not a journal of wirecheck's"
    if why is not None:
        raise InputError(
            f"{option} {str(out)!r}: {JOURNAL} there cannot be finished ({why}): nothing was "
            "changed; expected a journal naming only this run's outputs and its own temporary "
            "folder (rerun the command that was stopped there to finish its commit, or delete "
            f"{str(path)!r} if no wirecheck run was stopped there)"
        )
    return data


def _known(out: Path, option: str, names=None) -> dict:
    """``{name: {sha256, ...}}``: the manifest's hashes, and the journal's of a commit a killed run left."""
    known = {name: {digest} for name, digest in read_manifest(out, option).items()}
    journal = _read_journal(out, option, names)
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
    raise InputError(
        f"{option} {str(path)!r} is {kind}: expected a new path or an earlier wirecheck output "
        "(nothing was changed; move it away first)"
    )


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
        known = _known(out, option, names)
        for name in names:
            check_replaceable(out, name, known, option, name in folders)
    except InputError:
        if not _locked:
            _refuse_if_locked(out, option)  # another run moving its outputs in: say that instead
        raise


def _refuse_if_locked(out: Path, option: str) -> None:
    who = holder(out / LOCK)
    if who is not None:
        raise InputError(
            f"{option} {str(out)!r} is being written by another wirecheck run"
            f"{f' ({who})' if who else ''}: expected one run per output folder at a time; "
            "wait for it or use another --out"
        )


def _write_json(path: Path, obj: dict, option: str | None = None) -> None:
    """``path`` written whole under a temporary name, then renamed into place (a counted move, core.outputs.owned).

    With ``option`` (the journal) nothing at ``path`` is replaced: InputError if a file appeared there since
    the check."""
    fd, tmp = tempfile.mkstemp(prefix=f"{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            fh.write(json.dumps(obj, indent=1, sort_keys=True) + "\n")
        if option is None:
            owned.rename(tmp, path)
        elif not owned.rename_noreplace(tmp, path):
            raise InputError(
                f"{option} {str(path)!r} appeared while wirecheck was about to move its outputs in: "
                "it was kept and nothing was moved; expected no writes into an output folder during "
                "a run (move it away and run again)"
            )
    except BaseException:
        if os.path.lexists(tmp):
            os.unlink(tmp)
        raise


def _move_in(out: Path, tmp: Path, names, option: str) -> None:
    """Move each staged name from ``tmp`` into ``out``; a name no longer in ``tmp`` was moved already.

    What is at the name goes aside first (``tmp/.old-NAME``: removed later by its hashes, rule 5); the new
    one never replaces what may have appeared there since (``RENAME_NOREPLACE``).
    """
    for name in names:
        src, dst = tmp / name, out / name
        if not os.path.lexists(src):
            continue
        if os.path.lexists(dst) and not os.path.lexists(tmp / f".old-{name}"):
            owned.rename(dst, tmp / f".old-{name}")
        if not owned.rename_noreplace(src, dst):
            raise InputError(
                f"{option} {str(dst)!r} appeared while wirecheck moved its outputs in: it was kept; "
                f"expected no writes into {str(out)!r} during a run (move it away and run again to "
                "finish the commit)"
            )


def _retire_file(old: Path, live: Path, known: set) -> list[str]:
    """Remove the old output file ``old`` (moved aside from ``live``) if its bytes are known; else keep it
    beside ``live`` (``NAME.kept``, ...) and return that name."""
    try:
        fd = os.open(old, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK | os.O_CLOEXEC)
    except OSError:
        fd = None
    if fd is not None:
        try:
            st = os.fstat(fd)
            ours = (
                stat.S_ISREG(st.st_mode)
                and st.st_nlink == 1
                and owned.hash_fd(fd) in known
                and os.path.samestat(st, os.lstat(old))
            )
        finally:
            os.close(fd)
        if ours:
            os.unlink(old)
            return []
    n, free = 1, live.with_name(live.name + ".kept")
    while not owned.rename_noreplace(old, free):
        n += 1
        free = live.with_name(f"{live.name}.kept{n}")
    return [free.name]


def _retire(out: Path, tmp: Path, names, folders, known: dict) -> list[str]:
    """Remove the old outputs moved aside into ``tmp`` by their hashes (rule 5); the user's kept, named."""
    kept = []
    for name in names:
        old = tmp / f".old-{name}"
        if not os.path.lexists(old):
            continue
        if name in folders and is_dir_here(old):
            kept += retire(old, out / name)
        else:
            kept += _retire_file(old, out / name, known.get(name, set()))
    return kept


def _finish(out: Path, journal: dict, option: str, check: bool = True, known: dict | None = None) -> None:
    """Complete the commit ``journal`` describes (rules 3, 5): moves, old outputs removed by their hashes,
    manifest, journal removed, temporaries. InputError at the end if a user's file was kept.

    ``check``: first check every target again (a killed run's journal: the user may have been there since).
    ``known``: the hashes of the outputs in place before the commit (default: read now).
    """
    tmp = out / journal["tmp"]
    names, folders = journal["names"], set(journal.get("folders", []))
    if known is None:
        known = _known(out, option)
    if check and is_dir_here(tmp):
        for name in names:
            if os.path.lexists(tmp / name):
                check_replaceable(out, name, known, option, name in folders)
    kept = []
    if is_dir_here(tmp):
        _move_in(out, tmp, names, option)
        kept = _retire(out, tmp, names, folders, known)
    _write_json(out / MANIFEST, {"wirecheck_manifest": 1, "files": journal["manifest"]})
    (out / JOURNAL).unlink()
    remove_tree(tmp)
    if kept:
        raise InputError(
            f"{option} {str(out)!r}: {', '.join(kept[:3])}{' ...' if len(kept) > 3 else ''} "
            f"({len(kept)} file{'s' if len(kept) > 1 else ''}) written or changed during the commit: "
            "kept beside the new outputs, which are in place; expected no writes into an output "
            "folder while wirecheck replaces it (move them away before the next run)"
        )


def _recover(out: Path, option: str, names=None) -> None:
    """Under the lock: finish a killed run's commit, remove killed runs' temporaries (rule 3)."""
    journal = _read_journal(out, option, names)
    if journal is not None:
        _finish(out, journal, option)
    for entry in os.scandir(out):
        if entry.is_dir(follow_symlinks=False) and _TMP.fullmatch(entry.name):
            if is_regular(os.path.join(entry.path, TAG)):
                remove_tree(entry.path)
            else:
                try:
                    os.rmdir(entry.path)  # killed between its creation and its tag: empty
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
            _recover(self.out, option, self.names)
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
            except FileExistsError:  # another run made it meanwhile: not ours to remove
                continue
            self.created.append(folder)

    def path(self, name: str) -> Path:
        """Where to write output ``name`` (inside the temporary folder)."""
        return self.tmp / name

    def commit(self) -> None:
        """Check every target, then move every staged output into place under a journal (rule 3)."""
        blocked = {signal.SIGINT, signal.SIGTERM}
        signal.pthread_sigmask(signal.SIG_BLOCK, blocked)  # the moves finish together: no mixed set
        try:
            known = _known(self.out, self.option, self.names)
            manifest = read_manifest(self.out, self.option)
            staged = [n for n in self.names if os.path.lexists(self.tmp / n)]
            for name in staged:  # every target, before the first move
                check_replaceable(self.out, name, known, self.option, name in self.folders)
            owned.step()  # checked: what is removed is checked again after the moves (rule 5)
            for name in staged:
                if name in self.folders:
                    owned.seal(self.tmp / name)
                    manifest.pop(name, None)
                else:
                    manifest[name] = sha256(self.tmp / name)
            journal = {
                "wirecheck_journal": 1,
                "tmp": self.tmp.name,
                "names": staged,
                "folders": sorted(self.folders & set(staged)),
                "manifest": manifest,
            }
            _write_json(self.out / JOURNAL, journal, self.option)
            self._journaled = True  # from here on the next run can finish it: keep the temporaries
            _finish(self.out, journal, self.option, check=False, known=known)
            self.tmp = None
            self.created = []  # the outputs live there now
        finally:
            self.abort()
            signal.pthread_sigmask(signal.SIG_UNBLOCK, blocked)  # a pending signal is raised here

    def abort(self) -> None:
        """Remove the temporaries (unless a journal names them), the lock, and the folders this run created."""
        if self.tmp is not None and not self._journaled:
            remove_tree(self.tmp)
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
