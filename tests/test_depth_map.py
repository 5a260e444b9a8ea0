"""oracles.candidates.depth_map: the encodings read, the others refused with one line."""

from __future__ import annotations

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
    assert dm.encoding_bound()[1, 2] == pytest.approx(3.0 * EPS32)       # one float32 ulp of depth 3 (2 ulps at 2^1)


def test_png_16bit_scale(tmp_path):
    Image.fromarray(np.array([[0, 1000, 65535]], dtype=np.uint16)).save(tmp_path / "d.png")
    dm = read_depth_map(tmp_path / "d.png", 3, 1)
    assert np.isnan(dm.depth[0, 0]) and dm.depth[0, 1] == 1.0 and dm.depth[0, 2] == 65.535
    assert dm.step == 1e-3 and np.array_equal(dm.encoding_bound(), [[1e-3, 1e-3, 1e-3]])   # 1 mm at 1000 per unit
    dm = read_depth_map(tmp_path / "d.png", 3, 1, scale=5000)                           # TUM's scale
    assert dm.depth[0, 1] == 0.2 and dm.step == 2e-4


def test_tiff_float32(tmp_path):
    Image.fromarray(np.array([[0.0, 1.25]], dtype=np.float32)).save(tmp_path / "d.tif")
    dm = read_depth_map(tmp_path / "d.tif", 2, 1)
    assert np.isnan(dm.depth[0, 0]) and dm.depth[0, 1] == 1.25 and dm.encoding == "tiff float32"


@pytest.mark.parametrize("make, expect", [
    (lambda p: np.save(p / "d.npy", np.zeros((2, 3), np.uint16)), "a .npy of uint16: expected float32"),
    (lambda p: np.save(p / "d.npy", np.zeros((2, 3), np.float16)), "a .npy of float16: expected float32"),
    (lambda p: np.save(p / "d.npy", np.zeros((3, 2), np.float32)), "expected 3x2"),
    (lambda p: np.save(p / "d.npy", np.zeros((2, 3, 1), np.float32)), "expected 3x2"),
    (lambda p: np.save(p / "d.npy", np.array([[1, 1, 1], [1, -0.5, 1]], np.float32)),
     "depth -0.5 at row 1, column 1 (1 negative in all)"),
    (lambda p: np.save(p / "d.npy", np.array([[1, 1, 1], [1, -np.inf, 1]], np.float32)), "depth -inf at row 1"),
    (lambda p: Image.fromarray(np.zeros((2, 3), np.uint8)).save(p / "d.png"), "a PNG image of mode L: expected a "
                                                                               "16-bit grey PNG"),
    (lambda p: Image.fromarray(np.zeros((2, 3, 3), np.uint8)).save(p / "d.png"), "mode RGB"),
    (lambda p: Image.fromarray(np.zeros((2, 3), np.int32)).save(p / "d.tif"), "mode I: expected a 32-bit float"),
    (lambda p: (p / "d.png").write_bytes(b"not a png"), "not a readable image"),
    (lambda p: (p / "d.npy").write_bytes(b"not a npy"), "not a readable .npy"),
    (lambda p: (p / "d.exr").write_bytes(b"x"), "a .exr file: expected a depth map as .npy"),
])
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
