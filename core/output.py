"""Writing frames and reports: PNG (Pillow), ASCII, GIF, JSON; atomic writes.

Every file is written to a temporary name beside its destination and renamed
into place, so an interrupted run never leaves a file that looks complete.
Frames go to a temporary directory that is renamed when the run finishes.
"""

from __future__ import annotations

import json
import os
import shutil
import tempfile
from pathlib import Path

import numpy as np


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def atomic_write_bytes(path: Path, data: bytes) -> None:
    path = Path(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
        os.chmod(tmp, 0o666 & ~_umask())   # mkstemp makes 0600; give the usual mode
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def atomic_write_text(path: Path, text: str) -> None:
    atomic_write_bytes(path, text.encode("utf-8"))


def json_dumps(obj) -> str:
    """Deterministic JSON: keys in insertion order (fixed by the writer), NaN refused."""
    return json.dumps(obj, indent=1, allow_nan=False) + "\n"


def png_bytes(image: np.ndarray) -> bytes:
    """``(H, W)`` uint8 (or ``(H, W, 3)``) to PNG bytes. Row 0 is the top."""
    import io

    from PIL import Image

    buf = io.BytesIO()
    Image.fromarray(np.ascontiguousarray(image)).save(buf, format="PNG", compress_level=6)
    return buf.getvalue()


def ascii_frame(image: np.ndarray, cols: int = 80) -> str:
    """A text picture: '#' where any pixel of a character cell is drawn (>= 128), '.' elsewhere.

    Character cells are about twice as tall as wide, so a cell covers
    ``W / cols`` pixels across and twice that down.
    """
    h, w = image.shape[:2]
    cols = max(1, min(cols, w))
    rows = max(1, min(h, int(round(cols * h / w / 2.0))))
    c_edges = (np.arange(cols) * w) // cols
    r_edges = (np.arange(rows) * h) // rows
    on = (image >= 128).astype(np.int32)         # drawn: 255, or aa coverage >= 1/2
    cells = np.add.reduceat(np.add.reduceat(on, r_edges, axis=0), c_edges, axis=1) > 0
    lines = ["".join("#" if v else "." for v in row) for row in cells]
    return "\n".join(lines) + "\n"


def gif_bytes(images: list[np.ndarray], fps: float = 30.0) -> bytes:
    import io

    from PIL import Image

    frames = [Image.fromarray(np.ascontiguousarray(im)).convert("P") for im in images]
    buf = io.BytesIO()
    if frames:
        frames[0].save(buf, format="GIF", save_all=True, append_images=frames[1:],
                       duration=int(round(1000.0 / fps)), loop=0, optimize=False)
    return buf.getvalue()


#: Every directory wirecheck writes holds this empty file. An existing output
#: directory is replaced only when it holds it (or is empty): a user's own
#: folder or file is never deleted.
MARKER = ".wirecheck-output"


def check_replaceable(path: Path, option: str) -> None:
    """InputError unless ``path`` is absent, an empty directory, or an earlier output of ours."""
    from .errors import InputError

    path = Path(path)
    if not path.exists() and not path.is_symlink():
        return
    if path.is_dir() and not path.is_symlink() and ((path / MARKER).is_file() or not any(path.iterdir())):
        return
    kind = "a directory not written by wirecheck" if path.is_dir() else "a file"
    raise InputError(f"{option} {str(path)!r} is {kind}: expected a new path or an earlier wirecheck "
                     "output (nothing was changed; move it away first)")


class FrameDir:
    """A directory filled under a temporary name, renamed over ``final`` on commit().

    ``final`` may only be absent, empty, or an earlier output (see MARKER).
    """

    def __init__(self, final: Path, option: str = "output"):
        self.final = Path(final)
        self.option = option
        check_replaceable(self.final, option)
        self.tmp = Path(tempfile.mkdtemp(prefix=f".{self.final.name}.", suffix=".tmp", dir=self.final.parent))
        os.chmod(self.tmp, 0o777 & ~_umask())
        (self.tmp / MARKER).write_bytes(b"")

    def write(self, name: str, data: bytes) -> None:
        (self.tmp / name).write_bytes(data)

    def commit(self) -> None:
        check_replaceable(self.final, self.option)   # again: it may have appeared meanwhile
        if self.final.exists():
            old = self.final.with_name(f".{self.final.name}.old")
            if old.exists():
                shutil.rmtree(old)
            os.replace(self.final, old)
            os.replace(self.tmp, self.final)
            shutil.rmtree(old)
        else:
            os.replace(self.tmp, self.final)

    def abort(self) -> None:
        shutil.rmtree(self.tmp, ignore_errors=True)
