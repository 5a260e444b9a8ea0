"""Largest inputs the renderer accepts, each with the reason for its value.

A limit turns an input that would exhaust memory, time or the file system
into one clear line (exit 2) before any work starts.
"""

from __future__ import annotations

import math

from .errors import InputError

#: Frames of one run. At 30 fps, 100,000 frames are 55 minutes of animation;
#: the report keeps one record per frame in memory and on disk (about 0.2 KB
#: for a small scene, ~1 KB per 20 vertices: a run of 10^5 frames of a cube is
#: a 40 MB JSON). Larger runs are several runs (--frames and --spin together).
MAX_FRAMES = 100_000

#: Largest image width or height, in pixels, of one camera: 16384 is the
#: largest viewport most OpenGL drivers (Mesa's included) render, so the
#: pyrender oracle can draw any frame the renderer can.
MAX_SIDE = 16384
#: Largest image area of one camera (2^25 = 33.5 million pixels, e.g.
#: 8192 x 4096). --hidden-lines and --style shaded need about 28 bytes per
#: pixel (depth buffer, face ids, masks; measured: 3000 x 3000 peaks 226 MB
#: above 1000 x 1000), so the largest frame stays under 1 GB of memory.
MAX_PIXELS = 2**25

#: Largest seconds a candidate's request may take (crosscheck --candidate-timeout, [tool.wirecheck],
#: check_projector's timeout_s): one day. The wait is a ``poll`` whose timeout, in milliseconds, is a C int
#: (at most 2^31 - 1 ms, 24.8 days: beyond it Python raises OverflowError); no request needs a day.
MAX_CANDIDATE_TIMEOUT_S = 86_400.0

#: Largest |turns| of a spin. Beyond 2^53 a float64 holds no fraction of a
#: turn (every frame would be at phase 0), and (frame - 1) * turns must stay
#: finite for the phase computation (core.transforms.Motion.frame_matrix).
MAX_TURNS = 2.0**53

#: Largest number of vertices of one polygon (a ``f`` line of a .scene).
#: Larger polygons are a mesh: give it as a mesh file (triangulated faces).
MAX_FACE_VERTICES = 1000

#: Longest scene name, in characters: it names output files
#: (``<name>-vertices_px-orthographic.npy`` adds 29 characters, a temporary
#: name ~15 more) and a file name has at most 255 bytes.
MAX_NAME = 100


def check_image_size(width: int, height: int, option: str, sides: int = 1) -> None:
    """InputError unless ``width`` x ``height`` is within MAX_SIDE and MAX_PIXELS."""
    if width < 1 or height < 1:
        raise InputError(f"{option} {width}x{height}: expected positive integers")
    if width > MAX_SIDE or height > MAX_SIDE:
        raise InputError(
            f"{option} {width}x{height}: expected at most {MAX_SIDE} pixels a side "
            "(the largest viewport OpenGL drivers render; wirecheck.core.limits)"
        )
    if width * height > MAX_PIXELS:
        raise InputError(
            f"{option} {width}x{height}: {width * height:,} pixels: expected at most "
            f"{MAX_PIXELS:,} (about 1 GB of buffers with --hidden-lines; wirecheck.core.limits)"
        )


def check_turns(turns, what: str) -> tuple:
    """``turns`` unchanged; InputError naming ``what`` when one is not finite or exceeds MAX_TURNS."""
    for t in turns:
        if not (math.isfinite(t) and abs(t) <= MAX_TURNS):
            raise InputError(
                f"{what} {' '.join(f'{v:g}' for v in turns)}: expected turns with |t| <= 2^53 "
                "(a float64 holds no fraction of a turn beyond; wirecheck.core.limits)"
            )
    return tuple(turns)


def check_candidate_timeout(seconds: float, option: str) -> None:
    """InputError unless ``seconds`` is finite, > 0 and at most MAX_CANDIDATE_TIMEOUT_S."""
    if not (math.isfinite(seconds) and 0 < seconds <= MAX_CANDIDATE_TIMEOUT_S):
        raise InputError(
            f"{option} {seconds}: expected a number of seconds > 0 and at most "
            f"{MAX_CANDIDATE_TIMEOUT_S:.0f} (one day; wirecheck.core.limits)"
        )
