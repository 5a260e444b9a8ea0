"""The image rule: how a candidate's PNG frame is read as drawn / not drawn pixels.

A frame is drawn where the pixel, as it shows over the rule's black
background, is at least half bright: ``L x A >= 128 x 255`` with ``L`` the
luminance (Pillow's ITU-R 601-2 of the RGB, ``L`` itself for grey) and ``A``
the alpha, both on 8 bits. Every PNG colour type and bit depth is reduced to
those 8 bits exactly, from the file's own samples:

- 1, 2, 4-bit samples are scaled to 0..255 (``v x 255 / (2^d - 1)``: x255,
  x85, x17), as every viewer shows them;
- 16-bit samples are read by their high byte: an 8-bit value ``x`` is
  ``257 x`` in 16 bits, so 8- and 16-bit copies of one image read the same,
  and a 16-bit grey is drawn from 128 x 256 = 32768;
- a palette image takes its entry's colour and alpha (``tRNS``: one alpha
  per entry, 255 beyond the listed ones); an index beyond the palette is refused;
- ``tRNS`` on grey or RGB names one transparent colour, compared with the
  file's samples at their full depth (a 16-bit white, 65535, is transparent;
  65534 is not), so a fully transparent picture reads as blank.

The file is checked before a pixel is decoded: the PNG signature, ``IHDR``
(a size other than the camera's is refused), the colour type and bit depth
pairs the PNG specification allows, ``PLTE``/``tRNS`` lengths, and no
``acTL`` (an animated PNG: which of its frames is the frame?). Every reason is
one :class:`FrameProblem` phrase without control characters.
"""

from __future__ import annotations

import os
import re
import struct
import warnings
from pathlib import Path

import numpy as np
from wirecheck.core.user_files import RefusedFile, open_regular, problem

SIGNATURE = b"\x89PNG\r\n\x1a\n"
#: colour type -> (name, channels, allowed bit depths), from the PNG specification (table 11.1)
COLOUR_TYPES = {
    0: ("grey", 1, (1, 2, 4, 8, 16)),
    2: ("RGB", 3, (8, 16)),
    3: ("palette", 1, (1, 2, 4, 8)),
    4: ("grey + alpha", 2, (8, 16)),
    6: ("RGBA", 4, (8, 16)),
}
#: Chunks read before the first IDAT: a file holding more before its pixels is no frame.
MAX_HEADER_CHUNKS = 1000
_CONTROL = re.compile("[\x00-\x1f\x7f-\x9f]")


class FrameProblem(ValueError):
    """A frame file that is not an image the job asked for: the reason, in a phrase."""


def escape_controls(text: str) -> str:
    """``text`` with control characters (a newline, an ESC) as backslash escapes: one printable line."""
    return _CONTROL.sub(lambda m: m.group().encode("unicode_escape").decode("ascii"), str(text))


def file_problem(path: Path, kind: str = "frame") -> str | None:
    """Why ``path`` is not a file of a job to read, in a phrase (``"missing"``, ``"a FIFO, not a regular file"``,
    its size over ``kind``'s limit); None if it is one.

    Checked before any open (core.user_files): opening a FIFO named like a job's file would block
    the run forever, and a folder or device is no file of a job.
    """
    found = problem(path, kind)
    return None if found is None else escape_controls(found)


def open_frame(path: Path):
    """``path`` opened for reading, as a binary file, when it is a regular file; FrameProblem otherwise.

    The file is opened without blocking and checked through its descriptor
    (core.user_files.open_regular): a frame can be replaced between the job's
    check and its decoding (a renderer still writing, a FIFO put there), and
    opening a FIFO by name would wait for a writer forever. Every read of a
    frame's header and pixels goes through one such file: they see one file,
    whatever happens to the name meanwhile.
    """
    try:
        return open_regular(path, "frame")
    except RefusedFile as exc:
        raise FrameProblem(escape_controls(exc.problem)) from None


def _chunk_name(kind: bytes) -> str:
    return kind.decode("ascii") if re.fullmatch(rb"[A-Za-z]{4}", kind) else repr(kind)[1:]


def read_header(fh) -> dict:
    """The chunks before the first IDAT: ``{width, height, depth, colour, palette, trns}``; FrameProblem otherwise."""
    head = fh.read(8)
    if head != SIGNATURE:
        raise FrameProblem("not a PNG")  # named by the caller (another format, or none)
    info = {"palette": None, "trns": None}
    for n in range(MAX_HEADER_CHUNKS):
        raw = fh.read(8)
        if len(raw) < 8:
            raise FrameProblem("truncated before its image data: expected IDAT chunks")
        length, kind = struct.unpack(">I4s", raw)
        name = _chunk_name(kind)
        if length > 2**31 - 1:
            raise FrameProblem(f"chunk {name} of {length} bytes: expected at most 2^31 - 1 (a damaged file)")
        if n == 0 and kind != b"IHDR":
            raise FrameProblem(f"first chunk {name}: expected IHDR")
        if kind == b"IDAT":
            break
        if kind in (b"IHDR", b"PLTE", b"tRNS", b"acTL"):
            data = fh.read(length)
            if len(data) < length:
                raise FrameProblem(f"truncated in its {name} chunk")
            fh.seek(4, os.SEEK_CUR)  # the CRC: Pillow checks it when it decodes
        else:
            if kind[:1].isupper() and kind not in (b"IEND",):
                raise FrameProblem(
                    f"an unknown critical chunk {name} before the image data: expected IHDR, "
                    "PLTE, tRNS or ancillary chunks (a damaged file or another format)"
                )
            fh.seek(length + 4, os.SEEK_CUR)
            continue
        if kind == b"IHDR":
            if length != 13:
                raise FrameProblem(f"IHDR of {length} bytes: expected 13")
            w, h, depth, colour, compression, filtering, interlace = struct.unpack(">IIBBBBB", data)
            if colour not in COLOUR_TYPES or depth not in COLOUR_TYPES[colour][2]:
                allowed = "; ".join(f"{c} ({v[0]}): {', '.join(map(str, v[2]))}" for c, v in COLOUR_TYPES.items())
                raise FrameProblem(
                    f"colour type {colour} with bit depth {depth}: expected one the PNG "
                    f"specification allows ({allowed})"
                )
            if (compression, filtering) != (0, 0) or interlace not in (0, 1):
                raise FrameProblem(
                    f"IHDR compression {compression}, filter {filtering}, interlace {interlace}: "
                    "expected 0, 0 and 0 or 1"
                )
            info.update(width=w, height=h, depth=depth, colour=colour)
        elif kind == b"acTL":
            frames = struct.unpack(">I", data[:4])[0] if length >= 4 else 0
            raise FrameProblem(
                f"an animated PNG of {frames} frame{'' if frames == 1 else 's'}: expected one still "
                "image (it has an acTL chunk)"
            )
        elif kind == b"PLTE":
            if length % 3 or not 3 <= length <= 768:
                raise FrameProblem(f"PLTE of {length} bytes: expected 1 to 256 RGB entries (3 bytes each)")
            info["palette"] = np.frombuffer(data, np.uint8).reshape(-1, 3)
        else:
            info["trns"] = data
    else:
        raise FrameProblem(f"more than {MAX_HEADER_CHUNKS} chunks before its image data: expected a frame")
    colour, depth = info["colour"], info["depth"]
    if colour == 3:
        if info["palette"] is None:
            raise FrameProblem("a palette image without a PLTE chunk")
        if len(info["palette"]) > 2**depth:
            raise FrameProblem(
                f"a palette of {len(info['palette'])} entries for {depth}-bit indices: expected at most {2**depth}"
            )
    trns = info["trns"]
    if trns is not None:
        expected = {0: 2, 2: 6}.get(colour)
        if colour in (4, 6):
            raise FrameProblem(f"a tRNS chunk in a {COLOUR_TYPES[colour][0]} image: expected none (it has alpha)")
        if colour == 3 and len(trns) > len(info["palette"]):
            raise FrameProblem(
                f"tRNS of {len(trns)} alphas for a palette of {len(info['palette'])} entries: "
                "expected at most one per entry"
            )
        if expected is not None and len(trns) != expected:
            raise FrameProblem(f"tRNS of {len(trns)} bytes in a {COLOUR_TYPES[colour][0]} image: expected {expected}")
    return info


def _other_format(fh) -> str:
    from PIL import Image

    try:
        fh.seek(0)
        with Image.open(fh) as im:
            return f"a {escape_controls(im.format)} image: expected a PNG"
    except Exception:  # noqa: BLE001 - Pillow's many ways to say "not an image"
        return "unreadable as PNG (no PNG signature, nor another image format): expected a PNG"


def _decode(fh, rawmode: str | None = None):
    """Pillow's decoding of the pixels of the open file ``fh`` (:func:`open_frame`); with ``rawmode``, the
    image's samples unpacked that way instead."""
    from PIL import Image

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", Image.DecompressionBombWarning)  # the size is checked before
        fh.seek(0)
        with Image.open(fh) as im:
            if rawmode is not None:
                tiles = []
                for t in im.tile:
                    if not (t.codec_name == "zip" and (isinstance(t.args, str) or isinstance(t.args, tuple))):
                        raise FrameProblem("a 16-bit RGB image with tRNS that this Pillow cannot read exactly")
                    args = rawmode if isinstance(t.args, str) else (rawmode, *t.args[1:])
                    tiles.append(t._replace(args=args))
                im.tile = tiles
            im.load()
            return im.mode, np.asarray(im)


def _decode_grey8(fh, width: int, height: int) -> np.ndarray | None:
    """An 8-bit grey or RGB frame's luminance ``(H, W)`` uint8 from the open file ``fh`` (:func:`open_frame`),
    Pillow's decoding and Pillow's RGB -> L (:func:`_luminance`'s); None when Pillow opens it as another
    mode or size (the general path reads it).

    Pillow decodes an ``L`` frame straight into the array that is returned, and
    an ``RGB`` frame's ``L`` is copied into it (``map_buffer``: Pillow's image
    memory is the array's): the same pixels as ``np.asarray`` of the decoded
    image, without its byte-string copies.
    """
    from PIL import Image

    map_buffer = getattr(Image.core, "map_buffer", None)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", Image.DecompressionBombWarning)  # the size is checked before
        fh.seek(0)
        with Image.open(fh) as im:
            if im.mode not in ("L", "RGB") or im.size != (width, height):
                return None
            if map_buffer is None:  # a Pillow without it: copied out
                im.load()
                return (
                    np.array(im, np.uint8) if im.mode == "L" else _luminance(np.asarray(im)[..., :3]).astype(np.uint8)
                )
            out = np.empty((height, width), np.uint8)
            target = map_buffer(out, (width, height), "raw", 0, ("L", 0, 1))
            if im.mode == "L":
                im.im = target  # decoded into ``out``
                im.load()
            else:
                im.load()
                target.paste(im.convert("L").im, (0, 0, width, height))
            return out


def _samples(fh, info: dict) -> tuple[np.ndarray, np.ndarray | None]:
    """``(samples, alpha8)``: the file's samples at full depth ((H, W) grey/index or (H, W, 3) RGB; for grey +
    alpha and RGBA their 8-bit reduction) and the 8-bit alpha of the types that carry one (None otherwise)."""
    colour, depth = info["colour"], info["depth"]
    mode, pixels = _decode(fh)
    if colour == 0:
        if depth == 1:
            return pixels.astype(np.uint16), None
        if depth in (2, 4):
            scale = 255 // (2**depth - 1)  # Pillow unpacks 2/4-bit grey scaled to 0..255
            return (pixels // scale).astype(np.uint16), None
        return pixels.astype(np.uint16), None  # 8 bits (L), 16 bits (I;16: the full samples)
    if colour == 3:
        return pixels.astype(np.uint16), None  # palette indices (P)
    if colour == 2:
        rgb = pixels[..., :3].astype(np.uint16)
        if depth == 16:  # Pillow keeps the high bytes; tRNS needs the low ones
            rgb = rgb << 8
            if info["trns"] is not None:
                rgb |= _decode(fh, "RGB;16L")[1][..., :3].astype(np.uint16)
        return rgb, None
    # grey + alpha, RGBA: Pillow's 8-bit reduction (the high byte of 16-bit samples); 16-bit grey + alpha
    # comes as RGBA with the grey in R, G and B (its luminance is that grey: Pillow's weights sum to 1)
    if mode == "LA":
        return pixels[..., 0], pixels[..., 1].astype(np.uint16)
    if mode != "RGBA":
        raise FrameProblem(f"a {COLOUR_TYPES[colour][0]} PNG decoded by Pillow as {mode}: expected LA or RGBA")
    return pixels[..., :3], pixels[..., 3].astype(np.uint16)


def _to8(samples: np.ndarray, depth: int) -> np.ndarray:
    """Samples of ``depth`` bits on 8 bits: low depths scaled up exactly, 16 bits by their high byte."""
    if depth == 16:
        return (samples >> 8).astype(np.uint8)
    return (samples.astype(np.uint16) * (255 // (2**depth - 1))).astype(np.uint8)


def _luminance(rgb8: np.ndarray) -> np.ndarray:
    """Pillow's RGB -> L (ITU-R 601-2), the luminance the rule has always used."""
    from PIL import Image

    return np.asarray(Image.fromarray(np.ascontiguousarray(rgb8, dtype=np.uint8), "RGB").convert("L"), dtype=np.uint16)


def read_png(path: Path, width: int, height: int) -> np.ndarray:
    """``(H, W)`` bool: drawn where ``L x A >= 128 x 255`` (module docstring); FrameProblem otherwise."""
    return read_grey(path, width, height) >= 128


def check_png(path: Path, width: int, height: int) -> dict:
    """The checks of :func:`read_grey` made before a pixel is decoded (signature, chunks, the camera's size):
    the header's ``{width, height, depth, colour, palette, trns}``; FrameProblem otherwise."""
    with open_frame(path) as fh:
        return _check_header(fh, width, height)


def _check_header(fh, width: int, height: int) -> dict:
    """:func:`check_png` on the open file ``fh``."""
    try:
        info = read_header(fh)
    except FrameProblem as exc:
        if str(exc) == "not a PNG":
            raise FrameProblem(_other_format(fh)) from None
        raise
    if (info["width"], info["height"]) != (width, height):
        raise FrameProblem(f"size {info['width']}x{info['height']}: expected {width}x{height} (the camera's)")
    return info


def read_grey(path: Path, width: int, height: int) -> np.ndarray:
    """``(H, W)`` uint8: each pixel's luminance over black, ``floor(L x A / 255)``; FrameProblem otherwise.

    Rounded down, a value is >= 128 exactly where ``L x A >= 128 x 255``: the
    drawn pixels of the rule (:func:`read_png`). The grey levels are the
    coverage of anti-aliased lines (oracles.judge.line_style). One still PNG of the
    camera's size is expected. The size is checked before any pixel is decoded
    (a huge image costs nothing).
    """
    with open_frame(path) as fh:  # one file for the header and the pixels
        info = _check_header(fh, width, height)
        return _grey(fh, info, width, height)


def _grey(fh, info: dict, width: int, height: int) -> np.ndarray:
    """:func:`read_grey`'s pixels from the open file ``fh`` whose header ``info`` was checked."""
    colour, depth, trns = info["colour"], info["depth"], info["trns"]
    try:
        if trns is None and depth == 8 and colour in (0, 2):  # 8-bit grey or RGB, opaque: the samples' L
            grey = _decode_grey8(fh, width, height)
            if grey is not None:
                return grey
        samples, alpha8 = _samples(fh, info)
    except FrameProblem:
        raise
    except Exception as exc:  # noqa: BLE001 - a damaged stream (CRC, zlib, truncated): Pillow's message
        raise FrameProblem(f"unreadable as PNG ({type(exc).__name__}: {escape_controls(exc)[:200]})") from None
    if samples.shape[:2] != (height, width):
        raise FrameProblem(f"decoded to {samples.shape[1]}x{samples.shape[0]}: expected {width}x{height}")
    if colour == 3:
        palette, n = info["palette"], len(info["palette"])
        if int(samples.max(initial=0)) >= n:
            raise FrameProblem(f"palette index {int(samples.max())} beyond its {n} entries: expected 0..{n - 1}")
        alphas = np.full(n, 255, np.uint16)
        if trns is not None:
            alphas[: len(trns)] = np.frombuffer(trns, np.uint8)
        grey = _luminance(palette[samples])
        alpha = alphas[samples]
    elif colour in (0, 2):
        grey = _to8(samples, depth).astype(np.uint16) if colour == 0 else _luminance(_to8(samples, depth))
        alpha = np.full(samples.shape[:2], 255, np.uint16)
        if trns is not None:  # one transparent colour, at the samples' full depth
            key = np.array(struct.unpack(">" + "H" * (len(trns) // 2), trns), np.uint16)
            hit = samples == key[0] if colour == 0 else np.all(samples == key, axis=-1)
            alpha[hit] = 0
    else:
        grey = samples.astype(np.uint16) if samples.ndim == 2 else _luminance(samples)
        alpha = alpha8
    return (grey.astype(np.uint32) * alpha // 255).astype(np.uint8)  # 0 where transparent
