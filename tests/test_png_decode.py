"""8-bit grey and RGB frames decoded into the judge's array (png_frame._decode_grey8) against Pillow's own reading.

The reference is the straightforward one: ``np.asarray`` of the frame opened by
Pillow and converted to ``L`` (Pillow's ITU-R 601-2 luminance for RGB). Random
pixels (every value, odd sizes, Pillow's filtered rows and Adam7 interlacing) must read the same to the
bit; a frame Pillow opens as another mode is left to the general path (None).
"""

from __future__ import annotations

import struct
import zlib

import numpy as np
import pytest
from fuzz.png_inputs import chunk, scanlines  # tests/ is on sys.path (rootdir conftest)
from PIL import Image
from wirecheck.oracles.candidates.png_frame import SIGNATURE, _decode_grey8, read_grey

#: Adam7's passes: (x0, y0, dx, dy) of the pixels each holds (PNG specification, 8.2)
ADAM7 = [(0, 0, 8, 8), (4, 0, 8, 8), (0, 4, 4, 8), (2, 0, 4, 4), (0, 2, 2, 4), (1, 0, 2, 2), (0, 1, 1, 2)]


def _adam7_png(pixels: np.ndarray) -> bytes:
    """An interlaced 8-bit PNG (Pillow writes none): each pass's rows as filter-0 scanlines, one IDAT."""
    h, w = pixels.shape[:2]
    colour = 0 if pixels.ndim == 2 else 2
    raw = b""
    for x0, y0, dx, dy in ADAM7:
        sub = pixels[y0::dy, x0::dx]
        if sub.size:
            raw += scanlines([row.reshape(-1).tolist() for row in sub], 8)
    return (
        SIGNATURE
        + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, colour, 0, 0, 1))
        + chunk(b"IDAT", zlib.compress(raw))
        + chunk(b"IEND", b"")
    )


@pytest.mark.parametrize("mode", ["L", "RGB"])
@pytest.mark.parametrize("interlace", [False, True], ids=["plain", "adam7"])
@pytest.mark.parametrize("size", [(1, 1), (13, 7), (640, 480)])
def test_grey8_reads_as_pillow_does(tmp_path, mode, interlace, size):
    rng = np.random.default_rng(size[0] * 7 + interlace)
    w, h = size
    pixels = rng.integers(0, 256, (h, w) if mode == "L" else (h, w, 3), dtype=np.uint8)
    pixels[: h // 2] = 0  # runs of zeros too (filters other than None)
    path = tmp_path / "f.png"
    if interlace:
        path.write_bytes(_adam7_png(pixels))
    else:
        Image.fromarray(pixels, mode).save(path)  # Pillow's adaptive filters: Sub, Up, Paeth rows
    assert Image.open(path).info.get("interlace", 0) == interlace
    want = np.asarray(Image.open(path).convert("L"))
    with open(path, "rb") as fh:
        got = _decode_grey8(fh, w, h)
    assert got.dtype == np.uint8 and got.shape == (h, w) and np.array_equal(got, want)
    assert np.array_equal(read_grey(path, w, h), want)


def test_other_modes_are_left_to_the_general_path(tmp_path):
    path = tmp_path / "f.png"
    Image.fromarray(np.zeros((4, 5, 4), np.uint8), "RGBA").save(path)
    with open(path, "rb") as fh:
        assert _decode_grey8(fh, 5, 4) is None
    Image.fromarray(np.zeros((4, 5), np.uint8), "L").save(path)
    with open(path, "rb") as fh:
        assert _decode_grey8(fh, 4, 5) is None  # not the size asked for
