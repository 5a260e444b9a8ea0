"""A renderer's depth map read from its file: depth along ``forward`` per pixel, NaN where no surface.

Encodings accepted (anything else is refused with one line, InputError):

- ``.npy``: a 2-D float32 (or float64) array, ``(H, W)``, either byte order, depth in world units
  (its header checked before its data is used; never a pickle);
- ``.tif`` / ``.tiff``: a 32-bit float TIFF (Pillow's mode ``"F"``), depth in world units;
- ``.png``: a 16-bit grey PNG (Pillow's mode ``"I;16"``), ``depth = value / scale``;
  ``scale`` 1000 per world unit by default (millimetres when the unit is the metre,
  as in BOP, Open3D and RealSense files; TUM's files use 5000).

0, NaN and +inf mean "no surface". The file is read through core.user_files (kind
``"depth map"``: a regular file of at most 512 MiB). A negative depth, a map of the wrong size or of any
other dtype or mode is refused: depth along ``forward`` is positive in front of the camera
(:mod:`wirecheck.core.conventions`). Row 0 is the top of the picture, as in every image here.

The encoding's own resolution travels with the map (:attr:`DepthMap.step`,
:attr:`DepthMap.rel_step`) so a judge can add it to its bound: a 16-bit PNG holds
depth to ``1 / scale`` (1 mm at scale 1000; a writer that truncates, ``uint16(d * s)``,
is off by up to one step), a float32 value to one float32 ulp, ``eps32 |d|``
(round to nearest: half of it, doubled for the renderer's own last rounding).
"""

from __future__ import annotations

import io
import math
import os
import tokenize
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from wirecheck.core.errors import InputError
from wirecheck.core.user_files import read_regular

__all__ = ["DEFAULT_PNG_SCALE", "DepthMap", "read_depth_map", "depth_from_array"]

#: Values per world unit of a 16-bit PNG depth map unless told otherwise: 1000 (millimetres
#: per metre), as BOP, Open3D and RealSense write them.
DEFAULT_PNG_SCALE = 1000.0

_EPS32 = float(np.finfo(np.float32).eps)
_EPS64 = float(np.finfo(np.float64).eps)
#: A 16-bit PNG's largest value.
_PNG_MAX = 65535.0


@dataclass(frozen=True)
class DepthMap:
    """A depth map as read.

    Attributes
    ----------
    depth : (H, W) ndarray of float64
        Depth along ``forward`` in world units; NaN where the file says "no surface".
    encoding : str
        What the file held: ``"npy float32"``, ``"tiff float32"``, ``"png uint16 / 1000"``...
    step : float
        The encoding's absolute resolution in world units (``1 / scale`` for a PNG, else 0).
    rel_step : float
        Its resolution relative to the depth (float32: ``eps32``; a PNG: 0).
    """

    depth: np.ndarray
    encoding: str
    step: float = 0.0
    rel_step: float = 0.0

    def encoding_bound(self) -> np.ndarray:
        """``(H, W)`` float64: how far the encoding alone may move a depth, ``step + rel_step |d|`` (0 where none)."""
        out = np.abs(self.depth)
        np.fmax(out, 0.0, out=out)  # |d|, 0 where NaN (fmax takes the number)
        out *= self.rel_step
        out += self.step
        return out


def read_depth_map(path, width: int, height: int, scale: float = DEFAULT_PNG_SCALE) -> DepthMap:
    """Read a depth map file (module docstring for the encodings).

    Parameters
    ----------
    path : str or Path
        A ``.npy``, ``.tif``/``.tiff`` or ``.png`` file.
    width, height : int
        The size the map must have (the camera's, >= 1).
    scale : float
        Values per world unit of a 16-bit PNG (finite, > 0, and 65535 / scale finite).

    Returns
    -------
    DepthMap

    Raises
    ------
    InputError
        One line naming the file, what it holds and what was expected: a missing or
        unreadable file, not a regular file or over core.user_files' ``"depth map"`` limit,
        another suffix, dtype or image mode, a wrong size, a negative depth.
    """
    path = Path(path)
    _check_size(width, height)
    if not (
        isinstance(scale, (int, float))
        and not isinstance(scale, bool)
        and math.isfinite(scale)
        and scale > 0
        and math.isfinite(_PNG_MAX / scale)
    ):
        raise InputError(
            f"depth scale {scale!r}: expected a finite number of values per unit > 0 (default 1000) "
            f"with {_PNG_MAX:g} / scale finite"
        )
    suffix = path.suffix.lower()
    if suffix not in (".npy", ".png", ".tif", ".tiff"):
        raise InputError(
            f"{path}: a {suffix or 'suffix-less'} file: expected a depth map as .npy (float32), "
            ".tif (32-bit float) or .png (16-bit)"
        )
    if not os.path.lexists(path):
        raise InputError(f"{path}: no such file: expected a depth map of {width}x{height}")
    data = read_regular(path, "depth map")  # a FIFO, a device, a folder or a huge file: one line, nothing read
    if suffix == ".npy":
        return _npy_map(data, path, width, height)
    from PIL import Image, UnidentifiedImageError

    want = "a 16-bit grey PNG (mode I;16)" if suffix == ".png" else "a 32-bit float TIFF (mode F)"
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error", Image.DecompressionBombWarning)  # its size is checked below
            with Image.open(io.BytesIO(data)) as im:
                mode, fmt, size = im.mode, im.format, im.size
                if (mode, suffix) not in (("I;16", ".png"), ("F", ".tif"), ("F", ".tiff")):
                    raise InputError(f"{path}: a {fmt or 'unknown'} image of mode {mode}: expected {want} depth map")
                if size != (width, height):
                    raise InputError(_shape_text(str(path), size[::-1], width, height))
                values = np.asarray(im)
    except InputError:  # our own line above (InputError is a ValueError): as it is
        raise
    except (
        OSError,
        UnidentifiedImageError,
        ValueError,
        Image.DecompressionBombError,
        Image.DecompressionBombWarning,
    ) as exc:
        raise InputError(
            f"{path}: not a readable image ({' '.join(str(exc).split())[:120]}): expected {want} depth map"
        ) from None
    if suffix == ".png":
        depth = values.astype(np.float64) / float(scale)
        return depth_from_array(depth, width, height, str(path), f"png uint16 / {scale:g}", 1.0 / float(scale), 0.0)
    return depth_from_array(values, width, height, str(path), "tiff float32", 0.0, _EPS32)


#: What numpy's .npy header parser may raise on a hostile header (it evaluates a Python literal).
_NPY_HEADER_ERRORS = (
    ValueError,
    SyntaxError,
    TypeError,
    OverflowError,
    MemoryError,
    RecursionError,
    EOFError,
    tokenize.TokenError,
)


def _npy_map(data: bytes, path: Path, width: int, height: int) -> DepthMap:
    """A ``.npy`` file's bytes as a depth map: its header checked (a float dtype, the camera's shape)
    before any of its body is used; no pickle, whatever the header says."""

    def refuse(why: str):
        raise InputError(
            f"{path}: not a readable .npy file ({' '.join(why.split())[:120]}): expected a 2-D float32 array"
        )

    fh = io.BytesIO(data)
    try:
        version = np.lib.format.read_magic(fh)
        if version not in ((1, 0), (2, 0)):
            refuse(f"format version {version[0]}.{version[1]}, expected 1.0 or 2.0")
        read_header = np.lib.format.read_array_header_1_0 if version == (1, 0) else np.lib.format.read_array_header_2_0
        shape, fortran, dtype = read_header(fh)
    except InputError:  # refuse()'s own line (InputError is a ValueError): as it is
        raise
    except _NPY_HEADER_ERRORS as exc:
        refuse(str(exc) or type(exc).__name__)
    if dtype.kind != "f" or dtype.itemsize not in (4, 8):
        raise InputError(
            f"{path}: a .npy of {dtype}: expected float32 depth in world units "
            "(a 16-bit map belongs in a .png with a scale)"
        )
    if tuple(shape) != (height, width):
        raise InputError(_shape_text(str(path), tuple(shape), width, height))
    start, need = fh.tell(), height * width * dtype.itemsize
    if len(data) - start < need:
        refuse(f"{len(data) - start} bytes of data after the header, expected {need} for {width}x{height} of {dtype}")
    values = np.frombuffer(data, dtype=dtype, count=height * width, offset=start)
    values = values.reshape((height, width), order="F" if fortran else "C")
    native = np.float32 if dtype.itemsize == 4 else np.float64
    encoding, rel = f"npy {np.dtype(native)}", (_EPS32 if dtype.itemsize == 4 else _EPS64)
    # (a native-order array as it is: depth_from_array copies it to float64)
    return depth_from_array(values.astype(native, copy=False), width, height, str(path), encoding, 0.0, rel)


def _check_size(width, height) -> None:
    for name, v in (("width", width), ("height", height)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < 1:
            raise InputError(f"depth map {name} {v!r}: expected an integer >= 1 (the camera's)")


def _shape_text(name: str, shape: tuple, width: int, height: int) -> str:
    return (
        f"{name}: a depth map of shape {shape} ({'x'.join(map(str, shape[::-1]))}): "
        f"expected {width}x{height} (height {height} rows, width {width} columns)"
    )


def depth_from_array(
    values,
    width: int,
    height: int,
    name: str = "depth map",
    encoding: str = "array",
    step: float = 0.0,
    rel_step: float = 0.0,
) -> DepthMap:
    """An ``(H, W)`` array of depths as a :class:`DepthMap`: 0 and non-finite values become NaN.

    Raises InputError (naming ``name``) for another shape or a negative depth.
    """
    _check_size(width, height)
    values = np.asarray(values)
    if values.shape != (height, width):
        raise InputError(_shape_text(name, values.shape, width, height))
    depth = values.astype(np.float64)
    with np.errstate(invalid="ignore"):
        negative = depth < 0
    if negative.any():
        r, c = (int(i) for i in np.argwhere(negative)[0])
        raise InputError(
            f"{name}: depth {float(depth[r, c])!r} at row {r}, column {c} ({int(negative.sum())} negative "
            "in all): expected depth along forward >= 0 (0, NaN or +inf: no surface)"
        )
    depth[~np.isfinite(depth) | (depth == 0)] = np.nan
    return DepthMap(depth=depth, encoding=encoding, step=float(step), rel_step=float(rel_step))
