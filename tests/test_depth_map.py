"""oracles.candidates.depth_map: the encodings read, the others refused with one line."""

from __future__ import annotations

import os
import struct
import zlib

import numpy as np
import pytest
from PIL import Image
from wirecheck.core.errors import InputError
from wirecheck.oracles.candidates.depth_map import read_depth_map

EPS32 = float(np.finfo(np.float32).eps)


def test_npy_float32(tmp_path):
    values = np.array([[0.0, 1.5, np.nan], [np.inf, 2.25, 3.0]], dtype=np.float32)
    np.save(tmp_path / "d.npy", values)
    dm = read_depth_map(tmp_path / "d.npy", 3, 2)
    # 0, NaN and inf are "no surface"; the rest exact
    assert np.array_equal(np.isnan(dm.depth), [[True, False, True], [True, False, False]])
    assert dm.depth[0, 1] == 1.5 and dm.depth[1, 1] == 2.25 and dm.depth.dtype == np.float64
    assert (dm.encoding, dm.step, dm.rel_step) == ("npy float32", 0.0, EPS32)
    assert dm.encoding_bound()[1, 2] == pytest.approx(3.0 * EPS32)  # one float32 ulp of depth 3 (2 ulps at 2^1)


def test_png_16bit_scale(tmp_path):
    Image.fromarray(np.array([[0, 1000, 65535]], dtype=np.uint16)).save(tmp_path / "d.png")
    dm = read_depth_map(tmp_path / "d.png", 3, 1)
    assert np.isnan(dm.depth[0, 0]) and dm.depth[0, 1] == 1.0 and dm.depth[0, 2] == 65.535
    assert dm.step == 1e-3 and np.array_equal(dm.encoding_bound(), [[1e-3, 1e-3, 1e-3]])  # 1 mm at 1000 per unit
    dm = read_depth_map(tmp_path / "d.png", 3, 1, scale=5000)  # TUM's scale
    assert dm.depth[0, 1] == 0.2 and dm.step == 2e-4


def test_tiff_float32(tmp_path):
    Image.fromarray(np.array([[0.0, 1.25]], dtype=np.float32)).save(tmp_path / "d.tif")
    dm = read_depth_map(tmp_path / "d.tif", 2, 1)
    assert np.isnan(dm.depth[0, 0]) and dm.depth[0, 1] == 1.25 and dm.encoding == "tiff float32"


@pytest.mark.parametrize(
    "make, expect",
    [
        (lambda p: np.save(p / "d.npy", np.zeros((2, 3), np.uint16)), "a .npy of uint16: expected float32"),
        (lambda p: np.save(p / "d.npy", np.zeros((2, 3), np.float16)), "a .npy of float16: expected float32"),
        (lambda p: np.save(p / "d.npy", np.zeros((3, 2), np.float32)), "expected 3x2"),
        (lambda p: np.save(p / "d.npy", np.zeros((2, 3, 1), np.float32)), "expected 3x2"),
        (
            lambda p: np.save(p / "d.npy", np.array([[1, 1, 1], [1, -0.5, 1]], np.float32)),
            "depth -0.5 at row 1, column 1 (1 negative in all)",
        ),
        (lambda p: np.save(p / "d.npy", np.array([[1, 1, 1], [1, -np.inf, 1]], np.float32)), "depth -inf at row 1"),
        (
            lambda p: Image.fromarray(np.zeros((2, 3), np.uint8)).save(p / "d.png"),
            "a PNG image of mode L: expected a 16-bit grey PNG",
        ),
        (lambda p: Image.fromarray(np.zeros((2, 3, 3), np.uint8)).save(p / "d.png"), "mode RGB"),
        (lambda p: Image.fromarray(np.zeros((2, 3), np.int32)).save(p / "d.tif"), "mode I: expected a 32-bit float"),
        (lambda p: (p / "d.png").write_bytes(b"not a png"), "not a readable image"),
        (lambda p: (p / "d.npy").write_bytes(b"not a npy"), "not a readable .npy"),
        (lambda p: (p / "d.exr").write_bytes(b"x"), "a .exr file: expected a depth map as .npy"),
    ],
)
def test_refused_with_one_line(tmp_path, make, expect):
    make(tmp_path)
    path = next(tmp_path.iterdir())
    with pytest.raises(InputError) as info:
        read_depth_map(path, 3, 2)
    text = str(info.value)
    assert expect in text and str(path) in text and "\n" not in text


def test_missing_file_and_bad_scale(tmp_path):
    with pytest.raises(InputError, match="no such file"):
        read_depth_map(tmp_path / "none.png", 3, 2)
    Image.fromarray(np.zeros((2, 3), np.uint16)).save(tmp_path / "d.png")
    for scale in (0, -1.0, float("nan"), float("inf"), True):
        with pytest.raises(InputError, match="depth scale"):
            read_depth_map(tmp_path / "d.png", 3, 2, scale=scale)


# ---- hostile files (benchmarks/fuzz_round5.py, docs/reliability.md "Round 5") ----------------------------


def _npy_bytes(header: bytes, body: bytes = b"") -> bytes:
    """A version 1.0 .npy file with this header dict text, padded as numpy pads it (to 64 bytes)."""
    magic = b"\x93NUMPY\x01\x00"
    pad = 64 - (len(magic) + 2 + len(header) + 1) % 64
    h = header + b" " * (pad % 64) + b"\n"
    return magic + len(h).to_bytes(2, "little") + h + body


def _refused(path, *args, **kwargs) -> str:
    with pytest.raises(InputError) as info:
        read_depth_map(path, *args, **kwargs)
    text = str(info.value)
    assert "\n" not in text
    return text


@pytest.mark.parametrize(
    "header, body, expect",
    [
        # numpy's header parser: OverflowError computing the count of a shape of a 4,000-digit number
        (b"{'descr': '<f4', 'fortran_order': False, 'shape': (" + b"9" * 4000 + b", 8), }", b"", "expected 8x6"),
        # tokenize.TokenError from an unclosed bracket (found by a random byte of the header, seed 5)
        (b"{'descr': '<f4', 'fortran_order': False, 'shape': ((6, 8), }", b"\0" * 192, "not a readable .npy"),
        # a body shorter than the header's shape
        (
            b"{'descr': '<f4', 'fortran_order': False, 'shape': (6, 8), }",
            b"\0" * 17,
            "17 bytes of data after the header",
        ),
        # an object array's header: refused by its dtype, the pickle after it never loaded
        (b"{'descr': '|O', 'fortran_order': False, 'shape': (6, 8), }", b"\x80\x04N.", "a .npy of object"),
    ],
)
def test_hostile_npy_header_is_one_line(tmp_path, header, body, expect):
    (tmp_path / "d.npy").write_bytes(_npy_bytes(header, body))
    assert expect in _refused(tmp_path / "d.npy", 8, 6)


def test_sparse_npy_is_refused_before_reading(tmp_path):
    # a valid header for 131072 x 131072 float32, then 64 GiB of holes: np.load asked for 64 GiB
    # (numpy's _ArrayMemoryError); the file is over the "depth map" limit (512 MiB), nothing read
    path = tmp_path / "d.npy"
    path.write_bytes(_npy_bytes(b"{'descr': '<f4', 'fortran_order': False, 'shape': (131072, 131072), }"))
    with open(path, "r+b") as fh:
        fh.truncate(64 << 30)
    assert "too large (68,719,476,736 bytes)" in _refused(path, 131072, 131072)


def test_fifo_is_refused_by_kind(tmp_path):
    os.mkfifo(tmp_path / "d.npy")
    assert "a FIFO, not a regular file" in _refused(tmp_path / "d.npy", 8, 6)


def test_png_decompression_bomb_is_one_line(tmp_path):
    # a 16-bit grey PNG whose header says 100,000 x 100,000 (Pillow's DecompressionBombError, a traceback)
    ihdr = struct.pack(">IIBBBBB", 100_000, 100_000, 16, 0, 0, 0, 0)

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    (tmp_path / "d.png").write_bytes(
        b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(b"\0")) + chunk(b"IEND", b"")
    )
    assert "not a readable image" in _refused(tmp_path / "d.png", 8, 6)


def test_image_of_another_size_is_refused_before_decoding(tmp_path):
    Image.fromarray(np.zeros((4, 5), np.float32)).save(tmp_path / "d.tif")
    assert "a depth map of shape (4, 5) (5x4): expected 3x2" in _refused(tmp_path / "d.tif", 3, 2)


def test_scale_whose_step_overflows_is_refused(tmp_path):
    # scale 1e-320 (subnormal): 1 / scale is inf and every depth value / scale inf, read as "no surface":
    # a whole map silently empty. 65535 / scale must be finite.
    Image.fromarray(np.full((2, 3), 1000, np.uint16)).save(tmp_path / "d.png")
    assert "depth scale 1e-320" in _refused(tmp_path / "d.png", 3, 2, scale=1e-320)
    assert read_depth_map(tmp_path / "d.png", 3, 2, scale=1e-300).depth[0, 0] == 1000 / 1e-300  # finite: read


@pytest.mark.parametrize("width, height", [(0, 0), (0, 6), (-8, -6), (8.0, 6), (True, 6)])
def test_size_asked_must_be_positive_integers(tmp_path, width, height):
    # a (0, 0) array was read as a map of 0x0: nothing to compare, accepted
    np.save(tmp_path / "d.npy", np.zeros((0, 0), np.float32))
    assert "expected an integer >= 1" in _refused(tmp_path / "d.npy", width, height)


def test_big_endian_and_fortran_float32_are_float32(tmp_path):
    # '>f4' is float32 in another byte order (numpy writes it so on a big-endian machine): read, not refused
    values = np.arange(1, 7, dtype=np.float32).reshape(2, 3)
    np.save(tmp_path / "b.npy", values.astype(">f4"))
    np.save(tmp_path / "f.npy", np.asfortranarray(values))
    for name in ("b.npy", "f.npy"):
        dm = read_depth_map(tmp_path / name, 3, 2)
        assert np.array_equal(dm.depth, values) and dm.encoding == "npy float32" and dm.rel_step == EPS32


def test_npy_of_an_unknown_version_says_so_once(tmp_path):
    # a .npy whose magic says version 3.0: refused by the reader's own version check, whose line is the
    # one the user reads (not wrapped again as "not a readable .npy file (...: not a readable .npy ...)"
    # and cut: InputError is a ValueError, which the header parser's handler also catches)
    data = bytearray(_npy_bytes(b"{'descr': '<f4', 'fortran_order': False, 'shape': (6, 8), }", b"\0" * 192))
    data[6:8] = b"\x03\x00"
    (tmp_path / "d.npy").write_bytes(bytes(data))
    text = _refused(tmp_path / "d.npy", 8, 6)
    assert "format version 3.0, expected 1.0 or 2.0" in text and text.count("not a readable .npy") == 1, text
