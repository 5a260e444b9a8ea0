"""core.outputs.output's PNG writer: bilevel frames decoded by two independent readers (Pillow, OpenCV)."""

import io
import struct

import cv2
import numpy as np
import pytest
from PIL import Image
from wirecheck.core.outputs.output import png_bytes


def _line_drawing(h, w, seed):
    rng = np.random.default_rng(seed)
    img = np.zeros((h, w), np.uint8)
    img[rng.random((h, w)) < 0.05] = 255
    return img


@pytest.mark.parametrize("h, w", [(480, 640), (7, 13), (1, 1), (3, 9), (5, 8)])  # widths not a multiple of 8 too
def test_bilevel_frame_is_lossless_for_pillow_and_opencv(h, w):
    img = _line_drawing(h, w, seed=h * 1000 + w)
    data = png_bytes(img)
    # IHDR (PNG spec): width, height, bit depth 1, colour type 0 (greyscale), no interlace
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and data[12:16] == b"IHDR"
    assert struct.unpack(">IIBBBBB", data[16:29]) == (w, h, 1, 0, 0, 0, 0)
    pil = np.asarray(Image.open(io.BytesIO(data)).convert("L"))
    cv = cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_UNCHANGED)
    np.testing.assert_array_equal(pil, img)
    np.testing.assert_array_equal(cv, img)


def test_grey_levels_keep_8_bit_grey():
    img = _line_drawing(20, 30, seed=1)
    img[3, 4] = 128  # one anti-aliased coverage level
    data = png_bytes(img)
    assert struct.unpack(">IIBB", data[16:26]) == (30, 20, 8, 0)
    np.testing.assert_array_equal(np.asarray(Image.open(io.BytesIO(data))), img)


def test_same_frame_same_bytes():
    img = _line_drawing(48, 64, seed=2)
    assert png_bytes(img) == png_bytes(img.copy())
