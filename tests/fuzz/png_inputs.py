"""Hostile PNG frames for the image rule (oracles/candidates/png_frame.py), and the contract read_png keeps on each.

A draw starts from a valid PNG of a random colour type and bit depth (with or
without PLTE and tRNS, written byte by byte), then damages it: flipped bytes,
a cut, a chunk added before the image data (acTL, an unknown critical chunk, a
second IHDR, a huge length), a wrong size in IHDR. The contract: ``read_png``
returns an ``(H, W)`` bool array of the camera's size, or raises
``FrameProblem`` whose message is one printable line; no other exception, no
control character, no hang.
"""

from __future__ import annotations

import re
import struct
import zlib

#: colour type -> bit depths the PNG specification allows
DEPTHS = {0: (1, 2, 4, 8, 16), 2: (8, 16), 3: (1, 2, 4, 8), 4: (8, 16), 6: (8, 16)}
CHANNELS = {0: 1, 2: 3, 3: 1, 4: 2, 6: 4}
_CONTROL = re.compile("[\x00-\x1f\x7f-\x9f]")


def chunk(kind: bytes, data: bytes) -> bytes:
    """A PNG chunk: length, type, data and the CRC of type and data."""
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))


def scanlines(rows, depth: int) -> bytes:
    """Rows of samples (each row: width x channels integers) as filter-0 scanlines at ``depth`` bits."""
    out = b""
    for row in rows:
        if depth == 16:
            data = b"".join(struct.pack(">H", v) for v in row)
        elif depth == 8:
            data = bytes(row)
        else:  # pack most significant bits first, pad the last byte
            bits = "".join(format(v, f"0{depth}b") for v in row)
            bits += "0" * (-len(bits) % 8)
            data = bytes(int(bits[i : i + 8], 2) for i in range(0, len(bits), 8))
        out += b"\0" + data
    return out


def hostile_png(pick, width: int, height: int) -> bytes:
    """A PNG of ``width`` x ``height`` (as the camera asks), valid or damaged as ``pick`` draws."""
    colour = pick.choice(sorted(DEPTHS))
    depth = pick.choice(DEPTHS[colour])
    top = 2**depth - 1
    n_palette = pick.integer(1, min(256, top + 1)) if colour == 3 else 0
    high = n_palette - 1 if colour == 3 else top
    rows = [
        [pick.choice([0, high, high // 2, pick.integer(0, high)]) for _ in range(width * CHANNELS[colour])]
        for _ in range(height)
    ]
    w, h = (width, height) if pick.chance(0.9) else (pick.integer(1, 3 * width), pick.integer(1, 3 * height))
    head = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, depth, colour, 0, 0, 0))
    body = b""
    if colour == 3:
        body += chunk(b"PLTE", bytes(pick.integer(0, 255) for _ in range(3 * n_palette)))
    if pick.chance(0.4):
        if colour == 0:
            body += chunk(b"tRNS", struct.pack(">H", pick.choice([0, top, pick.integer(0, 65535)])))
        elif colour == 2:
            body += chunk(b"tRNS", struct.pack(">HHH", *(pick.choice([0, top]) for _ in range(3))))
        elif colour == 3:
            body += chunk(b"tRNS", bytes(pick.integer(0, 255) for _ in range(pick.integer(0, n_palette))))
        else:
            body += chunk(b"tRNS", b"\0\0")  # not allowed with alpha
    if pick.chance(0.15):
        body += pick.choice(
            [
                chunk(b"acTL", struct.pack(">II", pick.integer(0, 3), 0)),
                chunk(b"zzZz", b"\x1b[2J"),
                chunk(b"XYZW", b"\n"),
                chunk(b"IHDR", b"\0" * 13),
                struct.pack(">I", 0xFFFFFFF0) + b"tEXt",
                chunk(b"tEXt", b"a\0\x1b\n"),
            ]
        )
    data = head + body + chunk(b"IDAT", zlib.compress(scanlines(rows, depth))) + chunk(b"IEND", b"")
    if pick.chance(0.3):
        data = bytearray(data)
        for _ in range(pick.integer(1, 4)):
            k = pick.integer(0, len(data) - 1)
            op = pick.choice(["flip", "cut", "insert"])
            if op == "flip":
                data[k] = pick.integer(0, 255)
            elif op == "cut":
                del data[k:]
                break
            else:
                data[k:k] = bytes([pick.integer(0, 255)])
        data = bytes(data)
    return data


def check_png(read_png, FrameProblem, path, width: int, height: int) -> list[str]:
    """The contract's problems with ``read_png(path, width, height)`` (empty: kept)."""
    try:
        image = read_png(path, width, height)
    except FrameProblem as exc:
        text = str(exc)
        return [f"control character in {text!r}"] if _CONTROL.search(text) or not text else []
    except Exception as exc:  # noqa: BLE001 - the finding
        return [f"traceback: {type(exc).__name__}: {exc}"[:300]]
    if getattr(image, "shape", None) != (height, width) or image.dtype != bool:
        return [
            f"read as {getattr(image, 'shape', None)} {getattr(image, 'dtype', None)}: expected ({height}, "
            f"{width}) bool"
        ]
    return []
