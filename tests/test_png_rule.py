"""The image rule on hand-built PNGs: every colour type and bit depth, tRNS, alpha, animation (issue 25, item 8).

The PNGs are written byte by byte (signature, chunks with their CRC, filter-0 scanlines packed at the
file's bit depth: tests/fuzz/png_inputs.py's chunk and scanlines), not by Pillow, so each file is
exactly the case it names. The expected pixels are derived by hand from the rule
(oracles/candidates/png_frame.py): drawn where L x A >= 128 x 255 with the samples on 8 bits (1/2/4-bit
scaled by 255, 85, 17; 16-bit by their high byte) and a tRNS colour transparent at the file's full
depth.
"""

from __future__ import annotations

import re
import shutil
import struct
import zlib

import helpers
import pytest
from fuzz.png_inputs import chunk, scanlines  # tests/ is on sys.path (rootdir conftest)
from wirecheck.oracles import cli as crosscheck_cli
from wirecheck.oracles.candidates.png_frame import FrameProblem, read_png


def png(
    samples, colour: int, depth: int, width: int, plte=None, trns: bytes | None = None, before_idat: bytes = b""
) -> bytes:
    height = len(samples)
    out = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, depth, colour, 0, 0, 0))
    if plte is not None:
        out += chunk(b"PLTE", bytes(v for rgb in plte for v in rgb))
    if trns is not None:
        out += chunk(b"tRNS", trns)
    return out + before_idat + chunk(b"IDAT", zlib.compress(scanlines(samples, depth))) + chunk(b"IEND", b"")


def grey_key(v: int) -> bytes:
    return struct.pack(">H", v)


def rgb_key(r: int, g: int, b: int) -> bytes:
    return struct.pack(">HHH", r, g, b)


F, T = False, True
W16 = 65535
#: name -> (samples of one row, flattened channels), colour type, depth, width, PLTE, tRNS, expected row
CASES = {
    # grey: 1-bit 0/1 -> 0/255; 2-bit x85: 0 85 170 255; 4-bit x17: 7 -> 119 (< 128), 8 -> 136 (>= 128)
    "L1": ([0, 1], 0, 1, 2, None, None, [F, T]),
    "L1 tRNS 1": ([0, 1], 0, 1, 2, None, grey_key(1), [F, F]),
    "L2": ([0, 1, 2, 3], 0, 2, 4, None, None, [F, F, T, T]),
    "L2 tRNS 3": ([0, 1, 2, 3], 0, 2, 4, None, grey_key(3), [F, F, T, F]),
    "L4": ([0, 7, 8, 15], 0, 4, 4, None, None, [F, F, T, T]),
    "L4 tRNS 8": ([0, 7, 8, 15], 0, 4, 4, None, grey_key(8), [F, F, F, T]),
    "L8": ([0, 127, 128, 255], 0, 8, 4, None, None, [F, F, T, T]),
    "L8 tRNS 255": ([0, 127, 128, 255], 0, 8, 4, None, grey_key(255), [F, F, T, F]),
    # 16-bit grey: high byte >= 128 from 32768; tRNS compares all 16 bits (65534 is not 65535)
    "L16": ([0, 32767, 32768, W16], 0, 16, 4, None, None, [F, F, T, T]),
    "L16 tRNS white": ([0, 32768, W16 - 1, W16], 0, 16, 4, None, grey_key(W16), [F, T, T, F]),
    "L16 white, tRNS white": ([W16] * 4, 0, 16, 4, None, grey_key(W16), [F] * 4),  # the picture
    # grey + alpha: 255 x A >= 128 x 255 iff A >= 128; a grey of 127 never (127 x 255 < 128 x 255)
    "LA8": ([255, 127, 255, 128, 127, 255, 128, 255], 4, 8, 4, None, None, [F, T, F, T]),
    "LA16": ([W16, 127 * 257, W16, 32768, 32767, W16, 32768, W16], 4, 16, 4, None, None, [F, T, F, T]),
    # RGB: white L=255, red L = 0.299 x 255 = 76 (< 128), green L = 0.587 x 255 = 150 (>= 128), black 0
    "RGB8": ([255, 255, 255, 255, 0, 0, 0, 255, 0, 0, 0, 0], 2, 8, 4, None, None, [T, F, T, F]),
    "RGB8 tRNS white": (
        [255, 255, 255, 255, 0, 0, 0, 255, 0, 0, 0, 0],
        2,
        8,
        4,
        None,
        rgb_key(255, 255, 255),
        [F, F, T, F],
    ),
    "RGB16": ([W16, W16, W16, 32767, 32767, 32767, 0, W16, 0, W16, 0, 0], 2, 16, 4, None, None, [T, F, T, F]),
    # 16-bit RGB tRNS: only the exact 16-bit triple is transparent; one differing low byte is opaque white
    "RGB16 tRNS white": (
        [W16, W16, W16, W16, W16, W16 - 1, 0, W16, 0, W16 - 256, W16, W16],
        2,
        16,
        4,
        None,
        rgb_key(W16, W16, W16),
        [F, T, T, T],
    ),
    # RGBA: white at alpha 128 drawn, 127 not; opaque green drawn, opaque red not
    "RGBA8": (
        [255, 255, 255, 128, 255, 255, 255, 127, 0, 255, 0, 255, 255, 0, 0, 255],
        6,
        8,
        4,
        None,
        None,
        [T, F, T, F],
    ),
    "RGBA16": (
        [W16, W16, W16, 32768, W16, W16, W16, 32767, 0, W16, 0, W16, W16, 0, 0, W16],
        6,
        16,
        4,
        None,
        None,
        [T, F, T, F],
    ),
    # palette: colour by entry; tRNS gives entries' alphas (255 beyond those listed)
    "P1": ([0, 1], 3, 1, 2, [(0, 0, 0), (255, 255, 255)], None, [F, T]),
    "P1 tRNS": ([0, 1], 3, 1, 2, [(0, 0, 0), (255, 255, 255)], bytes([255, 0]), [F, F]),
    "P2": ([0, 1, 2, 3], 3, 2, 4, [(0, 0, 0), (255, 255, 255), (0, 255, 0), (255, 0, 0)], None, [F, T, T, F]),
    "P2 tRNS": (
        [0, 1, 2, 3],
        3,
        2,
        4,
        [(0, 0, 0), (255, 255, 255), (0, 255, 0), (255, 0, 0)],
        bytes([0, 127]),
        [F, F, T, F],
    ),
    "P4": (
        [0, 1, 15, 2],
        3,
        4,
        4,
        [(0, 0, 0), (255, 255, 255)] + [(0, 0, 0)] * 13 + [(255, 255, 255)],
        None,
        [F, T, T, F],
    ),
    "P4 tRNS": (
        [0, 1, 15, 2],
        3,
        4,
        4,
        [(0, 0, 0), (255, 255, 255)] + [(0, 0, 0)] * 13 + [(255, 255, 255)],
        bytes([255, 128]),
        [F, T, T, F],
    ),
    "P8": (
        [0, 1, 200, 2],
        3,
        8,
        4,
        [(0, 0, 0), (255, 255, 255), (0, 255, 0)] + [(255, 255, 255)] * 198,
        None,
        [F, T, T, T],
    ),
    "P8 tRNS": (
        [0, 1, 200, 2],
        3,
        8,
        4,
        [(0, 0, 0), (255, 255, 255), (0, 255, 0)] + [(255, 255, 255)] * 198,
        bytes([0, 0, 128]),
        [F, F, T, F],
    ),  # green (L 150) at alpha 128: 150 x 128 < 128 x 255
}


@pytest.mark.parametrize("name", CASES)
def test_every_colour_type_and_depth(tmp_path, name):
    row, colour, depth, width, plte, trns, expected = CASES[name]
    path = tmp_path / "f.png"
    path.write_bytes(png([row, row], colour, depth, width, plte, trns))
    assert read_png(path, width, 2).tolist() == [expected, expected]


def test_a_fully_transparent_picture_reads_as_blank(tmp_path):
    """16-bit white everywhere, tRNS white: nothing shows over the black background (before: all drawn)."""
    path = tmp_path / "f.png"
    path.write_bytes(png([[W16] * 8] * 6, 0, 16, 8, trns=grey_key(W16)))
    assert not read_png(path, 8, 6).any()


@pytest.mark.parametrize("frames", [1, 2])
def test_an_animated_png_is_refused_by_its_actl(tmp_path, frames):
    """acTL (APNG) before the image: refused whatever its frame count (a 1-frame APNG still shows a default image
    that may not be the frame). Before, only Pillow's frame count was looked at."""
    path = tmp_path / "f.png"
    path.write_bytes(png([[0, 255]], 0, 8, 2, before_idat=chunk(b"acTL", struct.pack(">II", frames, 0))))
    with pytest.raises(FrameProblem) as info:
        read_png(path, 2, 1)
    plural = "frame" if frames == 1 else "frames"
    assert str(info.value) == f"an animated PNG of {frames} {plural}: expected one still image (it has an acTL chunk)"


@pytest.mark.parametrize(
    "build, needle",
    [
        (lambda: png([[0, 5]], 3, 8, 2, plte=[(0, 0, 0), (9, 9, 9)]), "palette index 5 beyond its 2 entries"),
        (lambda: png([[0, 1]], 3, 8, 2), "a palette image without a PLTE chunk"),
        (lambda: png([[0, 1]], 0, 8, 2, trns=b"\0"), "tRNS of 1 bytes in a grey image: expected 2"),
        (lambda: png([[0, 1, 0, 1]], 4, 8, 2, trns=grey_key(1)), "a tRNS chunk in a grey + alpha image"),
        (lambda: png([[0, 1]], 2, 4, 2), "colour type 2 with bit depth 4: expected one the PNG specification allows"),
        (lambda: png([[0, 1]], 0, 8, 2, before_idat=chunk(b"ZZ\x1bZ", b"")), "unknown critical chunk"),
    ],
)
def test_malformed_pngs_are_one_phrase(tmp_path, build, needle):
    path = tmp_path / "f.png"
    path.write_bytes(build())
    with pytest.raises(FrameProblem, match=re.escape(needle)) as info:
        read_png(path, 2, 1)
    assert not any(ord(c) < 32 or 127 <= ord(c) < 160 for c in str(info.value)), str(info.value)


def test_frame_errors_never_print_control_characters(tmp_path, capsys):
    """A file under frames/ whose name holds an ESC and a newline is named with escapes in the one error line
    per problem (before: the raw ESC drove the terminal, the newline split the line)."""
    job = helpers.blank_job(tmp_path / "job")
    shutil.copy(job / "frames/cube/on_axis/frame_0001.png", job / "frames/cube/on_axis/x\x1b[2J\ny.png")
    rc = crosscheck_cli.main(["--candidate-frames", str(job), "--report-dir", str(tmp_path / "r")])
    err = capsys.readouterr().err
    assert rc == 2 and "x\\x1b[2J\\ny.png: not a frame of this job" in err, err
    assert "\x1b" not in err and err.count("\n") == 1, err
    assert not (tmp_path / "r").exists()
