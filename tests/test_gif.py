"""The streaming GIF writer (core/outputs/gif.py), decoded by Pillow: the reference reader."""

import io

import numpy as np
from PIL import Image, ImageSequence
from wirecheck.core.outputs.gif import GifWriter, gif_bytes


def decoded(data: bytes):
    """Every frame as Pillow composes it (RGB, so palettes do not matter), and each frame's duration."""
    with Image.open(io.BytesIO(data)) as g:
        frames = [np.asarray(f.convert("RGB")) for f in ImageSequence.Iterator(g)]
        g.seek(0)
        durations = []
        for k in range(g.n_frames):
            g.seek(k)
            durations.append(g.info["duration"])
    return frames, durations


def moving_square(n, h=40, w=50, rgb=False):
    out = []
    for k in range(n):
        im = np.zeros((h, w), np.uint8)
        im[5 + k : 15 + k, 10 + 2 * k : 22 + 2 * k] = 255
        im[0, 0] = 128  # a grey that must survive the palette
        out.append(np.stack([im, im // 2, 255 - im], axis=2) if rgb else im)
    return out


def test_grey_frames_decode_exactly():
    images = moving_square(6)
    frames, durations = decoded(gif_bytes(images, fps=30))
    assert len(frames) == 6
    for got, want in zip(frames, images):
        np.testing.assert_array_equal(got[:, :, 0], want)  # grey: R = G = B = the value
        np.testing.assert_array_equal(got[:, :, 2], want)
    assert durations == [30] * 6  # int(33 ms / 10) = 3 hundredths, as Pillow writes 30 fps


def test_rgb_frames_decode_exactly():
    images = moving_square(4, rgb=True)  # 4 exact colours per frame: the adaptive palette holds them
    frames, _ = decoded(gif_bytes(images))
    assert len(frames) == 4
    for got, want in zip(frames, images):
        np.testing.assert_array_equal(got, want)


def test_equal_neighbours_merge_with_summed_delay():
    a, b = moving_square(2)
    frames, durations = decoded(gif_bytes([a, a, a, b, b]))
    assert len(frames) == 2
    assert durations == [90, 60]  # int(3 x 33 / 10) = 9, int(2 x 33 / 10) = 6 hundredths
    np.testing.assert_array_equal(frames[1][:, :, 0], b)


def test_later_frames_are_cropped_to_what_changed():
    images = moving_square(3)
    data = gif_bytes(images)
    with Image.open(io.BytesIO(data)) as g:
        g.seek(1)
        # frame 1 differs from frame 0 in rows 5..15 and columns 10..23 (the square moved by 1, 2 px)
        assert g.dispose_extent == (10, 5, 24, 16)


def test_memory_is_one_frame_not_all(tmp_path):
    """The writer keeps the previous frame only: nothing grows with the frame count."""
    with open(tmp_path / "a.gif", "wb") as fh:
        w = GifWriter(fh)
        for im in moving_square(10):
            w.add(im)
        assert w.pending is not None and w.prev.shape == (40, 50)
        assert not any(isinstance(v, list) for v in vars(w).values())
        w.close()
    assert len(decoded((tmp_path / "a.gif").read_bytes())[0]) == 10


def test_deterministic():
    images = moving_square(5, rgb=True)
    assert gif_bytes(images) == gif_bytes(images)
