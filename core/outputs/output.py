"""Writing frames and reports: PNG and GIF (Pillow), MP4 (PyAV), ASCII, JSON; atomic writes.

Every file is written to a temporary name beside its destination and renamed
into place, so an interrupted run never leaves a file that looks complete.
Frames go to a temporary directory that is renamed when the run finishes.
"""

from __future__ import annotations

import io
import json
import os
import struct
import tempfile
import zlib
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..scene import files as scene_files
from ..scene.files import MESH_SUFFIXES, NATIVE_SUFFIX
from . import owned
from .gif import gif_bytes as encode
from .lockfile import Lock
from .owned import (
    MARKER,
    TAG,
    exchange,
    is_leftover,
    is_regular,
    listing,
    ours,
    remove_tree,
    rename,
    rename_noreplace,
    retire,
    step,
)
from .owned import TAG as _TAG


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
        os.chmod(tmp, 0o666 & ~_umask())  # mkstemp makes 0600; give the usual mode
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def write_file(path, data: bytes) -> None:
    """``Path(path).write_bytes(data)`` in three system calls (no buffered file object: ~25 us less a file)."""
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC | getattr(os, "O_BINARY", 0), 0o666)
    try:
        write_all(fd, data)
    finally:
        os.close(fd)


def write_all(fd: int, data: bytes) -> None:
    """Every byte of ``data`` to the file descriptor ``fd`` (``os.write`` may write fewer)."""
    view = memoryview(data)
    while view:
        view = view[os.write(fd, view) :]


def atomic_write_text(path: Path, text: str) -> None:
    atomic_write_bytes(path, text.encode("utf-8"))


def json_dumps(obj) -> str:
    """Deterministic JSON: keys in insertion order (fixed by the writer), NaN refused."""
    return json.dumps(obj, indent=1, allow_nan=False) + "\n"


def png_bytes(image: np.ndarray) -> bytes:
    """``(H, W)`` uint8 (or ``(H, W, 3)``) to PNG bytes. Row 0 is the top.

    A grey image whose pixels are all 0 or 255 (every wireframe drawn with the
    ``exact`` or ``fast`` raster) is written bilevel (:func:`bilevel_png_bytes`):
    lossless, and 8 times less data to compress than 8-bit grey. Anything else
    (``aa`` coverage, shading, RGB axes) goes through Pillow at zlib level 6.
    """
    if is_bilevel(image):
        return bilevel_png_bytes(image)
    from PIL import Image

    buf = io.BytesIO()
    Image.fromarray(np.ascontiguousarray(image)).save(buf, format="PNG", compress_level=6)
    return buf.getvalue()


def is_bilevel(image: np.ndarray) -> bool:
    """Whether ``image`` is ``(H, W)`` uint8 with every pixel 0 or 255 (:func:`png_bytes` writes it bilevel)."""
    # v - 1 (mod 256) is 255 or 254 exactly for v in {0, 255}: one subtraction and a min
    return image.ndim == 2 and image.dtype == np.uint8 and (image.size == 0 or (image - np.uint8(1)).min() >= 254)


#: zlib level of bilevel frames: level 1 is ~3x quicker than 6 on a line drawing
#: for ~40 % more bytes (3.7 against 2.6 KB for a 640x480 frame of 12 edges).
BILEVEL_ZLIB_LEVEL = 1


def bilevel_png_bytes(image: np.ndarray) -> bytes:
    """``(H, W)`` image to a 1-bit greyscale PNG: white where ``image >= 128``, black elsewhere.

    Written here (PNG signature, IHDR, one IDAT, IEND; filter type 0 on every
    row) because Pillow's encoder spends most of its time on the 8-bit rows.
    Readers see 0/1 samples of bit depth 1 (Pillow opens it as mode ``"1"``;
    ``.convert("L")`` gives 0/255; OpenCV's ``imread`` gives 0/255).
    """
    h, w = image.shape
    return bilevel_png_from_rows(bilevel_rows(image), w, h)


def bilevel_rows(image: np.ndarray) -> bytes:
    """The scanlines of :func:`bilevel_png_bytes`: per row, filter byte 0 then the row's bits packed.

    ``(H, W)`` image in, ``H * (ceil(W / 8) + 1)`` bytes out (what IDAT compresses).
    """
    h, w = image.shape
    rows = np.zeros((h, (w + 7) // 8 + 1), np.uint8)  # column 0: the row's filter byte (0, None)
    on = image >= 128
    # most significant bit = leftmost pixel; rows of whole bytes pack as one run (~3x quicker than axis=1)
    rows[:, 1:] = np.packbits(on.reshape(-1)).reshape(h, w // 8) if w % 8 == 0 else np.packbits(on, axis=1)
    return rows.tobytes()


def bilevel_png_from_rows(rows: bytes, width: int, height: int) -> bytes:
    """The 1-bit greyscale PNG of :func:`bilevel_rows`' scanlines of a ``width x height`` image."""
    header = struct.pack(">IIBBBBB", width, height, 1, 0, 0, 0, 0)  # bit depth 1, colour type 0 (grey)
    return (
        b"\x89PNG\r\n\x1a\n"
        + _png_chunk(b"IHDR", header)
        + _png_chunk(b"IDAT", zlib.compress(rows, BILEVEL_ZLIB_LEVEL))
        + _png_chunk(b"IEND", b"")
    )


def _png_chunk(kind: bytes, data: bytes) -> bytes:
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))


def ascii_frame(image: np.ndarray, cols: int = 80) -> str:
    """A text picture: '#' where any pixel of a character cell is drawn (>= 128), '.' elsewhere.

    Character cells are about twice as tall as wide, so a cell covers
    ``W / cols`` pixels across and twice that down.
    """
    if image.ndim == 3:  # RGB (--axes): a cell is drawn when any channel is
        image = np.maximum(np.maximum(image[:, :, 0], image[:, :, 1]), image[:, :, 2])
    h, w = image.shape[:2]
    cols = max(1, min(cols, w))
    rows = max(1, min(h, int(round(cols * h / w / 2.0))))
    c_edges = (np.arange(cols) * w) // cols
    r_edges = (np.arange(rows) * h) // rows
    on = (image >= 128).astype(np.int32)  # drawn: 255, or aa coverage >= 1/2
    cells = np.add.reduceat(np.add.reduceat(on, r_edges, axis=0), c_edges, axis=1) > 0
    lines = ["".join("#" if v else "." for v in row) for row in cells]
    return "\n".join(lines) + "\n"


def gif_bytes(images, fps: float = 30.0, progress=None) -> bytes:
    """An animated GIF of ``images`` as bytes (core.outputs.gif, which also streams to a file)."""
    return encode(images, fps, progress)


#: MP4 settings: H.264 (libx264) in yuv420p, constant quality (CRF 18: lines
#: stay sharp). "veryfast": about 30 % faster than "medium" for 8 % larger files.
#:
#: Same frames, same bytes, whatever the process did before:
#:
#: - ``mbtree=0``: x264's macroblock-tree rate control reads heap memory it
#:   never wrote (this x264 build, core 165), so its bits depend on what the
#:   process freed earlier: the same frames encoded twice in one process, or
#:   in processes run with different ``MALLOC_PERTURB_``, gave up to 6
#:   different files. With ``mbtree=0`` every run gives one file (58 sizes and
#:   frame counts, 6 heap patterns; tests/test_mp4_determinism.py). Measured on
#:   90 frames of the cube at 640x480: files 14 % larger, decoded error lower
#:   (mean 0.06 against 0.09 grey levels), encoding 20 % less CPU time.
#: - one thread in x264 and in swscale (the yuv420p conversion), never a
#:   count taken from the CPUs: x264's frame threads change its decisions.
#: - ``fflags=+bitexact``: no library version string in the container (no
#:   creation time is written either: FFmpeg writes 0 unless told one).
MP4_CODEC = "libx264"
MP4_OPTIONS = {"crf": "18", "preset": "veryfast", "tune": "animation", "x264-params": "mbtree=0"}
MP4_CONTAINER_OPTIONS = {"fflags": "+bitexact"}


def pad_even(image: np.ndarray) -> np.ndarray:
    """Pad an image with black at the bottom/right to even width and height (yuv420p needs them).

    Padding, not scaling: every pixel keeps its value and position.
    """
    h, w = image.shape[:2]
    if h % 2 == 0 and w % 2 == 0:
        return image
    pad = [(0, h % 2), (0, w % 2)] + [(0, 0)] * (image.ndim - 2)
    return np.pad(image, pad)


class Mp4Writer:
    """Encode frames one at a time into an H.264 MP4 (PyAV), atomically.

    ``target`` is a path (written under a temporary name beside it and renamed
    over it by :meth:`commit`; :meth:`abort` removes it) or a binary file
    object (written in place). Frames are grey ``(H, W)`` or RGB ``(H, W, 3)``
    uint8, all the same size; an odd width or height is padded by one black
    row/column (:func:`pad_even`), never scaled. PyAV ships its own FFmpeg
    libraries: no system ffmpeg is needed.
    """

    def __init__(self, target, fps: int = 30):
        import av

        self._av = av
        self.final = None
        if isinstance(target, (str, os.PathLike)):
            self.final = Path(target)
            fd, self.tmp = tempfile.mkstemp(prefix=f".{self.final.name}.", suffix=".tmp", dir=self.final.parent)
            os.close(fd)
            target = self.tmp
        self.container = av.open(target, mode="w", format="mp4", options=dict(MP4_CONTAINER_OPTIONS))
        self.fps = int(fps)
        self.stream = None
        self.frames = 0

    def add(self, image: np.ndarray) -> None:
        im = pad_even(np.ascontiguousarray(image))
        if self.stream is None:
            st = self.container.add_stream(MP4_CODEC, rate=self.fps, options=dict(MP4_OPTIONS))
            st.width, st.height = im.shape[1], im.shape[0]
            st.pix_fmt = "yuv420p"
            st.codec_context.thread_count = 1  # deterministic bytes (MP4_OPTIONS)
            st.codec_context.thread_type = "NONE"
            self.stream, self.size = st, im.shape[:2]
        if im.shape[:2] != self.size:
            raise ValueError(f"mp4 frame of size {im.shape[:2]}: expected {self.size} like the first")
        frame = self._av.VideoFrame.from_ndarray(im, format="rgb24" if im.ndim == 3 else "gray")
        for packet in self.stream.encode(frame.reformat(format="yuv420p", threads=1)):
            self.container.mux(packet)
        self.frames += 1

    def _close(self) -> None:
        if self.stream is not None:
            for packet in self.stream.encode(None):
                self.container.mux(packet)
            self.stream = None
        self.container.close()

    def commit(self) -> None:
        self._close()
        if self.final is not None:
            os.chmod(self.tmp, 0o666 & ~_umask())
            os.replace(self.tmp, self.final)

    def abort(self) -> None:
        try:
            self.container.close()
        except Exception:  # noqa: BLE001 - cleaning up after another error
            pass
        if self.final is not None and os.path.exists(self.tmp):
            os.unlink(self.tmp)


def mp4_bytes(images: list[np.ndarray], fps: int = 30) -> bytes:
    """The MP4 of ``images`` as bytes (:class:`Mp4Writer` into memory)."""
    buf = io.BytesIO()
    writer = Mp4Writer(buf, fps)
    for im in images:
        writer.add(im)
    writer.commit()
    return buf.getvalue()


#: Every directory wirecheck writes holds this file: the listing of what it wrote there (core.outputs.owned).
#: An existing output directory is replaced only when everything in it is listed (or it is empty): a
#: user's own folder, or a user's file put into a folder of ours, is never deleted.


def _users_frames(path: Path) -> str | None:
    """The first entry of a frames job's ``frames/`` (``crosscheck export``), which the user's renderer fills; None if none.

    The job is an output of ours, but what its ``frames/`` holds is not: the
    job is not replaced while that folder holds anything.
    """
    frames = path / "frames"
    if not ((path / "job.json").is_file() and frames.is_dir() and not frames.is_symlink()):
        return "frames (a link)" if frames.is_symlink() else None
    with os.scandir(frames) as it:
        first = next(it, None)
    return None if first is None else f"frames/{first.name}"


def check_replaceable(path: Path, option: str) -> None:
    """InputError unless ``path`` is absent, an empty directory, or an earlier output folder of ours.

    Everything in an earlier output must be what wirecheck wrote there (its
    listing, core.outputs.owned): a user's file inside it is named and nothing is
    replaced. A frames job whose ``frames/`` the renderer has filled says so (:func:`_users_frames`).
    """
    path = Path(path)
    if path.is_dir() and not path.is_symlink() and is_regular(path / MARKER):
        drawn = _users_frames(path)
        if drawn is not None:
            raise InputError(
                f"{option} {str(path)!r} is a frames job holding files a renderer wrote ({drawn}): "
                "expected a new path or an earlier wirecheck output (nothing was changed; "
                "move the frames away first)"
            )
    why = ours(path)
    if why is None:
        return
    raise InputError(
        f"{option} {str(path)!r} is {why}: expected a new path or an earlier wirecheck "
        "output (nothing was changed; move it away first)"
    )


def check_outside_scenes(path: Path, option: str, expected: str) -> None:
    """InputError when ``path`` is the bundled scenes folder or inside it: outputs there would pass for
    scenes in later runs. ``expected``: what to give instead, for the message."""
    try:
        resolved = Path(path).resolve()
    except (RuntimeError, OSError) as exc:  # a symbolic link loop: Python 3.11 raises RuntimeError
        raise InputError(f"{option} {str(path)!r}: {exc}: expected a folder path") from None
    scenes = scene_files.SCENE_DIR
    if resolved == scenes or scenes in resolved.parents:
        raise InputError(f"{option} {str(path)!r} is inside the scenes folder {str(scenes)!r}: expected {expected}")


def check_report_dir(path: Path, option: str) -> None:
    """InputError when a report folder at ``path`` could not be written or would pass for a scene.

    A folder in the bundled ``scenes/`` (or named ``*.scene``, ``*.obj``, ...)
    would be picked up as a scene by later runs (``crosscheck`` runs every
    ``scenes/*.scene``). Nothing is created here: the caller creates the
    parents only when it writes the report, so a failed run leaves no folder.
    """
    path = Path(path)
    long = next((part for part in path.parts if len(os.fsencode(part)) > 255), None)
    if long is not None:
        raise InputError(
            f"{option} {str(path)[:60]!r}...: a name of {len(long)} characters: expected at most 255 "
            "bytes per folder name"
        )
    parent = path.parent
    while not parent.exists() and not parent.is_symlink() and parent != parent.parent:
        parent = parent.parent
    created = path.relative_to(parent).parts  # the folders a report would create
    named = next((p for p in created if Path(p).suffix.lower() in (NATIVE_SUFFIX, ".txt", *MESH_SUFFIXES)), None)
    if named is not None:
        raise InputError(
            f"{option} {str(path)!r}: a folder named like a scene file ({named}) would be "
            "taken for a scene by later runs: expected another name"
        )
    check_outside_scenes(path, option, "a report folder elsewhere (reports/ by default)")
    if not parent.is_dir():
        raise InputError(f"{option} {str(path)!r}: {str(parent)!r} is not a directory: expected a folder path")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise InputError(f"{option} {str(path)!r}: {str(parent)!r} is not writable: expected a writable folder")


#: The targets this process holds from its start (:func:`claim`): ``{absolute path: (Lock, folders created)}``.
_claims: dict = {}


def _lock_path(final: Path) -> Path:
    return final.parent / f".{final.name}.wirecheck-lock"


def claim(final: Path, option: str) -> None:
    """Hold the lock of the output folder ``final`` from now until its :class:`FrameDir` commits or aborts
    (or :func:`release_claim`): one run owns its target from its start to its end, and a second run into
    it is refused at once, whichever takes longer. Creates the missing parents (removed again on release
    while empty), then checks ``final`` (:func:`check_replaceable`)."""

    final = Path(final)
    key = os.path.abspath(final)
    if key in _claims:
        return
    created, p = [], final.parent
    while not os.path.lexists(p) and p != p.parent:
        created.append(p)
        p = p.parent
    made = []
    try:
        for folder in reversed(created):
            try:
                folder.mkdir()
            except FileExistsError:
                continue
            made.append(folder)
        _claims[key] = (Lock(_lock_path(final), option, str(final)), made)
    except BaseException:
        for folder in reversed(made):
            _rmdir_quiet(folder)
        raise
    try:
        check_replaceable(final, option)
    except BaseException:
        release_claim(final)
        raise


def _rmdir_quiet(folder: Path) -> None:
    try:
        folder.rmdir()
    except OSError:
        pass


def release_claim(final: Path) -> None:
    """Give back :func:`claim`'s lock of ``final`` (nothing when not held); remove the parents it created
    if they are empty."""
    lock, made = _claims.pop(os.path.abspath(final), (None, []))
    if lock is not None:
        lock.release()
    for folder in reversed(made):
        _rmdir_quiet(folder)


def release_claims() -> None:
    """Give back every target this process claimed (the end of a command)."""
    for key in list(_claims):
        release_claim(Path(key))


class FrameDir:
    """A directory filled under a temporary name, then put in place of ``final`` by commit().

    ``final`` may only be absent, empty, or an earlier output whose listing
    names everything in it (:func:`check_replaceable`). One run writes a
    given ``final`` at a time (a lock beside it, core.outputs.lockfile): the
    lock :func:`claim` took at the run's start, else one taken here. The commit
    is one step where Linux allows: the new folder and the old one swap
    places (``renameat2(RENAME_EXCHANGE)``), so a run killed at any moment
    leaves the old folder or the new one; the temporaries a killed run left
    beside ``final`` (``.<name>.<unique>.tmp``, marked by core.outputs.owned.TAG)
    are removed by the next run that writes ``final``. The old folder is
    removed after the swap, by its listing (core.outputs.owned.retire): a
    file the user wrote into it during the commit is moved into the new one,
    and :meth:`commit` says so (InputError, exit 2) once the new folder is in place.
    """

    def __init__(self, final: Path, option: str = "output"):
        self.final = Path(final)
        self.option = option
        self.tmp = None
        self.kept = []
        held = _claims.get(os.path.abspath(self.final))
        self._claimed = held is not None
        if held is None:
            check_replaceable(self.final, option)
        self._lock = held[0] if held is not None else Lock(_lock_path(self.final), option, str(self.final))
        try:
            self._remove_leftovers()
            check_replaceable(self.final, option)  # again, under the lock
            self.tmp = Path(tempfile.mkdtemp(prefix=f".{self.final.name}.", suffix=".tmp", dir=self.final.parent))
            (self.tmp / _TAG).write_bytes(b"")
            os.chmod(self.tmp, 0o777 & ~_umask())
            (self.tmp / MARKER).write_bytes(b"")
        except BaseException:
            self.abort()
            raise

    def _remove_leftovers(self) -> None:
        """Remove the temporaries of killed runs for this ``final`` (ours alone: no live run holds the lock)."""
        prefix = f".{self.final.name}."
        for entry in os.scandir(self.final.parent):
            unique = entry.name[len(prefix) : -len(".tmp")]
            if not (
                entry.name.startswith(prefix)
                and entry.name.endswith(".tmp")
                and len(unique) == 8
                and unique.replace("_", "").isalnum()
                and entry.is_dir(follow_symlinks=False)
            ):
                continue
            if is_regular(Path(entry.path) / TAG):
                if is_leftover(Path(entry.path)):
                    remove_tree(entry.path)  # being filled when its run was killed: all ours
            elif listing(Path(entry.path)) is not None:
                # an old folder swapped out by a run killed before removing it: by its listing; what the user
                # wrote into it meanwhile goes into the folder in place (core.outputs.owned.retire)
                self.kept += retire(Path(entry.path), self.final)

    def write(self, name: str, data: bytes) -> None:
        (self.tmp / name).write_bytes(data)

    def commit(self) -> None:
        """Swap the new folder in, then remove the old one by its listing; InputError (after the swap) when
        a file the user wrote meanwhile was kept (class docstring)."""
        check_replaceable(self.final, self.option)  # again: it may have changed meanwhile
        step()  # checked: the old folder is checked again after the swap
        owned.seal(self.tmp)  # read off its module: tests pause a commit there
        os.unlink(self.tmp / _TAG)  # sealed: its listing marks it as ours from here on
        kept = self.kept
        if os.path.lexists(self.final) and exchange(self.tmp, self.final):
            swapped, self.tmp = self.tmp, None  # it holds the old folder now: never removed whole
            kept += retire(swapped, self.final)
        elif os.path.lexists(self.final):
            # no exchange here: the old set moves into a new, uniquely named temporary first
            old = Path(tempfile.mkdtemp(prefix=f".{self.final.name}.", suffix=".tmp", dir=self.final.parent))
            (old / _TAG).write_bytes(b"")
            rename(self.final, old / "old")
            if rename_noreplace(self.tmp, self.final):
                self.tmp = None
                kept += retire(old / "old", self.final)
                os.unlink(old / _TAG)
                _rmdir_quiet(old)
            else:  # a folder appeared in its place meanwhile: both stay
                kept += [self.final.name, str(old.relative_to(self.final.parent))]
        elif rename_noreplace(self.tmp, self.final):
            self.tmp = None
        else:
            kept += [self.final.name]  # a folder appeared in its place meanwhile: it stays
        self.abort()
        if kept:
            raise InputError(
                f"{self.option} {str(self.final)!r}: {', '.join(kept[:3])}"
                f"{' ...' if len(kept) > 3 else ''} written or changed during the commit: kept "
                "(nothing of it was removed); expected no writes into an output folder while "
                "wirecheck replaces it (move them away before the next run)"
            )

    def abort(self) -> None:
        if self.tmp is not None:
            remove_tree(self.tmp)
            self.tmp = None
        if self._lock is not None:
            if self._claimed:
                release_claim(self.final)
            else:
                self._lock.release()
            self._lock = None
