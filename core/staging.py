"""A run's outputs: assembled in one temporary folder, moved into place together at the end.

Rules, so that wirecheck never destroys what it did not write and never
leaves a half-written set:

1. Everything is written into ``<out>/.wirecheck-<unique>.tmp/`` (a unique
   name: no fixed-name probe or backup file in the user's folder). A failure,
   SIGINT or SIGTERM removes it, and removes the folders the run created.
2. An output name that already exists is replaced only when wirecheck wrote
   it: a file listed in ``<out>/.wirecheck-manifest.json`` with the SHA-256
   it had when written (a file edited since is the user's), or a folder that
   holds the ``.wirecheck-output`` marker (core.output.MARKER). Anything else
   (a user's file, a folder, a symlink) is refused with exit 2 and left as is.
3. One run writes an output folder at a time: ``<out>/.wirecheck-lock``,
   created exclusively and holding the writer's pid, is removed at the end; a
   second run refuses cleanly (a lock whose process is gone is taken over).
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import signal
import tempfile
from pathlib import Path

from .errors import InputError
from .output import MARKER, atomic_write_text

MANIFEST = ".wirecheck-manifest.json"
LOCK = ".wirecheck-lock"
_LOCK_PREFIX = "wirecheck lock pid "


def sha256(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def read_manifest(out: Path, option: str) -> dict:
    """``{name: sha256}`` of the files wirecheck wrote in ``out`` ({} when there is no manifest)."""
    path = Path(out) / MANIFEST
    if not path.exists() and not path.is_symlink():
        return {}
    try:
        if path.is_symlink() or not path.is_file():
            raise ValueError("not a regular file")
        data = json.loads(path.read_text(encoding="utf-8"))
        files = data["files"]
        if data.get("wirecheck_manifest") != 1 or not isinstance(files, dict):
            raise ValueError("not a wirecheck manifest")
        return {str(k): str(v) for k, v in files.items()}
    except (OSError, ValueError, KeyError, TypeError, UnicodeDecodeError):
        raise InputError(f"{option} {str(out)!r}: {MANIFEST} there was not written by wirecheck: expected "
                         "an output folder of wirecheck's or a new one (nothing was changed; move it away)") from None


def check_replaceable(out: Path, name: str, manifest: dict, option: str) -> None:
    """InputError unless ``out/name`` is absent or an earlier output of wirecheck's (module docstring, rule 2)."""
    path = Path(out) / name
    if not path.exists() and not path.is_symlink():
        return
    if path.is_symlink():
        kind = "a symbolic link"
    elif path.is_dir():
        if (path / MARKER).is_file() or not any(path.iterdir()):
            return
        kind = "a directory not written by wirecheck"
    elif path.is_file() and manifest.get(name) == sha256(path):
        return
    else:
        kind = "a file not written by wirecheck" if name not in manifest else "a file changed since wirecheck wrote it"
    raise InputError(f"{option} {str(path)!r} is {kind}: expected a new path or an earlier wirecheck output "
                     "(nothing was changed; move it away first)")


def check_out(out: Path, names, option: str = "--out") -> None:
    """Check, without writing anything, that a run can write ``names`` into ``out``."""
    out = Path(out)
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
    _refuse_if_locked(out / LOCK, option)
    try:
        manifest = read_manifest(out, option)
        for name in names:
            check_replaceable(out, name, manifest, option)
    except InputError:
        _refuse_if_locked(out / LOCK, option)     # another run moving its outputs in: say that instead
        raise


def _refuse_if_locked(lock: Path, option: str) -> None:
    holder = _holder(lock)
    if holder is not None and holder != os.getpid() and _alive(holder):
        raise InputError(f"{option} {str(lock.parent)!r} is being written by another wirecheck run "
                         f"(process {holder}): expected one run per output folder at a time; "
                         "wait for it or use another --out")


class Staging:
    """The temporary folder of one run in ``out`` and the move of its contents into place.

    ``names`` are the output names the run may write (files, or folders
    holding MARKER). Use :meth:`path` to write, then :meth:`commit`; on any
    exception call :meth:`abort` (both release the lock).
    """

    def __init__(self, out: Path, names, option: str = "--out"):
        self.out, self.names, self.option = Path(out), list(names), option
        self.created: list[Path] = []
        self.tmp = None
        self._lock = None
        try:
            self._make_out()
            self._lock = _acquire(self.out / LOCK, option)
            check_out(self.out, self.names, option)
            self.tmp = Path(tempfile.mkdtemp(prefix=".wirecheck-", suffix=".tmp", dir=self.out))
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
        """Move every staged output into place, record it in the manifest, remove the temporaries."""
        blocked = {signal.SIGINT, signal.SIGTERM}
        signal.pthread_sigmask(signal.SIG_BLOCK, blocked)    # the moves finish together: no mixed set
        try:
            manifest = read_manifest(self.out, self.option)
            staged = [n for n in self.names if (self.tmp / n).exists()]
            for name in staged:
                check_replaceable(self.out, name, manifest, self.option)
            for name in staged:
                src, dst = self.tmp / name, self.out / name
                if src.is_dir():
                    if dst.exists():
                        os.replace(dst, self.tmp / f".old-{name}")  # the old set goes with the temporaries
                    os.replace(src, dst)
                    manifest.pop(name, None)
                else:
                    digest = sha256(src)
                    os.replace(src, dst)
                    manifest[name] = digest
            atomic_write_text(self.out / MANIFEST, json.dumps({"wirecheck_manifest": 1, "files": manifest},
                                                              indent=1, sort_keys=True) + "\n")
            self.created = []          # the outputs live there now
        finally:
            self.abort()
            signal.pthread_sigmask(signal.SIG_UNBLOCK, blocked)     # a pending signal is raised here

    def abort(self) -> None:
        """Remove the temporaries, the lock, and the folders this run created (when empty)."""
        if self.tmp is not None:
            shutil.rmtree(self.tmp, ignore_errors=True)
            self.tmp = None
        if self._lock is not None:
            _release(self._lock)
            self._lock = None
        for folder in reversed(self.created):
            try:
                folder.rmdir()
            except OSError:
                break
        self.created = []


def _acquire(path: Path, option: str) -> Path:
    """Create the lock file exclusively with our pid; take over one whose process is gone."""
    # written under a unique name, then hard-linked to LOCK: it appears with its content, atomically,
    # and link() never follows or replaces whatever is at LOCK
    fd, tmp = tempfile.mkstemp(prefix=".wirecheck-lock-", suffix=".tmp", dir=path.parent)
    with os.fdopen(fd, "w") as fh:
        fh.write(f"{_LOCK_PREFIX}{os.getpid()}\n")
    try:
        return _link_lock(tmp, path, option)
    finally:
        os.unlink(tmp)


def _link_lock(tmp: str, path: Path, option: str) -> Path:
    for _ in range(2):
        try:
            os.link(tmp, path)
        except FileExistsError:
            holder = _holder(path)
            if holder is None:
                raise InputError(f"{option} {str(path.parent)!r}: {path.name} there was not written by wirecheck: "
                                 "expected a wirecheck output folder or a new one (nothing was changed)") from None
            _refuse_if_locked(path, option)
            try:
                path.unlink()            # stale: its process is gone
            except FileNotFoundError:
                pass
            continue
        return path
    raise InputError(f"{option} {str(path.parent)!r}: could not take {path.name}: expected one run at a time")


def _holder(path: Path) -> int | None:
    """The pid in a wirecheck lock file, or None when it is not one."""
    try:
        if path.is_symlink() or not path.is_file() or path.stat().st_size > 100:
            return None
        text = path.read_text(encoding="ascii")
    except (OSError, UnicodeDecodeError):
        return None
    if text.startswith(_LOCK_PREFIX) and text[len(_LOCK_PREFIX):].strip().isdigit():
        return int(text[len(_LOCK_PREFIX):])
    return None


def _alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def _release(path: Path) -> None:
    if _holder(path) == os.getpid():
        try:
            path.unlink()
        except FileNotFoundError:
            pass
