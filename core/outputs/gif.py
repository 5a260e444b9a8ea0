"""Animated GIF written as a stream: memory flat in the number of frames.

Pillow's ``save_all`` holds every frame until the end (4.3 GB at 5,000
frames of 640x480). Here each frame is LZW-coded on its own by Pillow's C
encoder (a one-frame GIF in memory) and its image block is copied into the
output file at once, behind a header written here (GIF89a, looping). Only
the previous frame is kept, for two savings Pillow also makes:

- a frame equal to the previous one is not written: its delay is added to the
  previous frame's (a scene that does not move gives a one-frame GIF of the
  same duration);
- a frame is cropped to the box where it differs from the previous one and
  drawn over it (disposal 1, "do not dispose").

Each frame carries its own colour table (the one Pillow chose: grey frames a
grey ramp; RGB frames an adaptive palette without dithering), so the bytes
are deterministic. Delays are in 1/100 s: ``int(ms / 10)`` per run of equal
frames, as Pillow writes them.
"""

from __future__ import annotations

import io
import struct

import numpy as np

_LOOP_FOREVER = b"\x21\xff\x0bNETSCAPE2.0\x03\x01\x00\x00\x00"


class GifWriter:
    """Append frames (``(H, W)`` or ``(H, W, 3)`` uint8, all one size) to an open binary file.

    ``progress()`` is called once per frame added.
    """

    def __init__(self, fh, fps: float = 30.0, progress=None):
        self.fh, self.ms = fh, int(round(1000.0 / fps))
        self.tick = progress or (lambda: None)
        self.prev = None  # the last distinct frame
        self.pending = None  # (descriptor + data bytes) of prev, written when its delay is known
        self.pending_ms = 0
        self.frames_written = 0

    def add(self, image: np.ndarray) -> None:
        image = np.ascontiguousarray(image)
        if self.prev is None:
            h, w = image.shape[:2]
            self.fh.write(b"GIF89a" + struct.pack("<HHBBB", w, h, 0, 0, 0) + _LOOP_FOREVER)
            self.size = image.shape
            box = (0, 0, h, w)
        else:
            if image.shape != self.size:
                raise ValueError(f"gif frame of shape {image.shape}: expected {self.size} like the first")
            diff = image != self.prev
            if diff.ndim == 3:
                diff = diff.any(axis=2)
            rows, cols = np.flatnonzero(diff.any(axis=1)), np.flatnonzero(diff.any(axis=0))
            if len(rows) == 0:
                self.pending_ms += self.ms
                self.tick()
                return
            box = (int(rows[0]), int(cols[0]), int(rows[-1]) + 1, int(cols[-1]) + 1)
        self._flush()
        top, left, bottom, right = box
        self.pending = _image_block(image[top:bottom, left:right], left, top)
        self.pending_ms = self.ms
        self.prev = image.copy()
        self.tick()

    def _flush(self) -> None:
        if self.pending is None:
            return
        delay = int(self.pending_ms / 10)
        # graphic control extension: disposal 1 (keep the frame; the next is drawn over it), the delay
        self.fh.write(b"\x21\xf9\x04" + struct.pack("<BHB", 1 << 2, delay, 0) + b"\x00")
        self.fh.write(self.pending)
        self.pending = None
        self.frames_written += 1

    def close(self) -> None:
        """Write the last frame and the trailer (a GIF needs at least one frame)."""
        if self.prev is None:
            raise ValueError("a GIF needs at least one frame")
        self._flush()
        self.fh.write(b"\x3b")


def _image_block(image: np.ndarray, left: int, top: int) -> bytes:
    """Image descriptor, local colour table and LZW data of ``image`` placed at (left, top)."""
    from PIL import Image

    pic = Image.fromarray(image)
    if pic.mode == "RGB":
        pic = pic.convert("P", palette=Image.Palette.ADAPTIVE, colors=256, dither=Image.Dither.NONE)
    else:
        pic = pic.convert("P")
    buf = io.BytesIO()
    pic.save(buf, format="GIF", optimize=False, interlace=False)
    table, bits, data = _single_frame_parts(buf.getvalue())
    h, w = image.shape[:2]
    return b"\x2c" + struct.pack("<HHHHB", left, top, w, h, 0x80 | bits) + table + data


def _single_frame_parts(gif: bytes) -> tuple[bytes, int, bytes]:
    """(colour table, its size bits, LZW data with its sub-blocks) of a one-frame GIF."""
    packed = gif[10]
    pos, table, bits = 13, b"", 0
    if packed & 0x80:
        bits = packed & 7
        table = gif[pos : pos + 3 * 2 ** (bits + 1)]
        pos += len(table)
    while gif[pos] == 0x21:  # extensions: skip their sub-blocks
        pos += 2
        while gif[pos]:
            pos += gif[pos] + 1
        pos += 1
    if gif[pos] != 0x2C:
        raise ValueError("unexpected block in Pillow's GIF")
    ipacked = gif[pos + 9]
    pos += 10
    if ipacked & 0x80:  # a local table overrides the global one
        bits = ipacked & 7
        table = gif[pos : pos + 3 * 2 ** (bits + 1)]
        pos += len(table)
    start = pos
    pos += 1  # LZW minimum code size
    while gif[pos]:
        pos += gif[pos] + 1
    return table, bits, gif[start : pos + 1]


def gif_bytes(images, fps: float = 30.0, progress=None) -> bytes:
    """The GIF of ``images`` (an iterable of frames) as bytes (:class:`GifWriter` into memory)."""
    buf = io.BytesIO()
    writer = GifWriter(buf, fps, progress)
    for im in images:
        writer.add(im)
    if writer.prev is not None:
        writer.close()
    return buf.getvalue()
