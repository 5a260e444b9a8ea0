"""MP4 bytes depend on the frames alone: not on the heap's leftovers, the CPU count or the library version.

x264's macroblock-tree rate control reads heap memory it never wrote (see
core.outputs.output.MP4_OPTIONS), so the bytes of an encode depended on what the
process had freed before it: the same test gave different bytes in a pytest
worker that had run other tests first. glibc's ``mallopt(M_PERTURB, p)``
fills every block malloc hands out with ``p ^ 0xff`` (and every freed block
with ``p``): encoding under several ``p`` makes that dependence show at once
instead of once in a few hundred runs.
"""

import ctypes
import hashlib

import numpy as np
import pytest
from wirecheck.core.outputs.output import MP4_OPTIONS, mp4_bytes

pytest.importorskip("av")

M_PERTURB = -6  # glibc malloc.h


def _mallopt():
    try:
        fn = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError):
        pytest.skip("no glibc mallopt: the heap cannot be filled with a pattern here")
    fn.argtypes, fn.restype = (ctypes.c_int, ctypes.c_int), ctypes.c_int
    return fn


def wireframe_frames(h, w, n, rgb=False):
    """``n`` frames of 12 moving horizontal and 12 vertical lines (a wireframe's kind of picture)."""
    out = []
    for i in range(n):
        im = np.zeros((h, w), np.uint8)
        for k in range(12):
            im[int((h - 1) * (0.5 + 0.45 * np.sin(0.3 * i + k))), w // 10 : w * 9 // 10] = 255
            im[h // 10 : h * 9 // 10, int((w - 1) * (0.5 + 0.45 * np.cos(0.2 * i + 1.7 * k)))] = 255
        out.append(np.stack([im, np.roll(im, 3, axis=1), im // 2], axis=2) if rgb else im)
    return out


@pytest.mark.parametrize("h, w, n, rgb", [(122, 162, 13, False), (62, 82, 13, True)])
def test_mp4_bytes_do_not_depend_on_heap_contents(h, w, n, rgb):
    # Grey and RGB frames where the encoder before the fix (mbtree on) gave 5 different files
    # over these 5 heap patterns (seen failing with MP4_OPTIONS["x264-params"] removed).
    mallopt = _mallopt()
    frames = wireframe_frames(h, w, n, rgb)
    digests = set()
    try:
        for pattern in (0, 1, 0x55, 0xA5, 0xFE):
            assert mallopt(M_PERTURB, pattern) == 1
            digests.add(hashlib.sha256(mp4_bytes(frames)).hexdigest())
    finally:
        mallopt(M_PERTURB, 0)  # back to glibc's default: no filling
    assert len(digests) == 1


def test_mp4_encoder_settings_written_in_the_file():
    # x264 writes the options it ran with into the stream (an SEI message); the container
    # carries no library version string (fflags=+bitexact).
    data = mp4_bytes(wireframe_frames(62, 82, 3))
    start = data.index(b"x264 - core")
    options = data[start : data.index(b"\0", start)].decode("ascii").split(" options: ")[1].split()
    assert {"threads=1", "lookahead_threads=1", "sliced_threads=0", "mbtree=0"} <= set(options)
    assert MP4_OPTIONS["x264-params"] == "mbtree=0"
    assert b"Lavf" not in data
