"""The candidate protocol, version 1: wirecheck and a projector program over a pipe.

Documented for authors in docs/protocol.md; this module is the one place that
encodes and decodes it. The program reads its stdin and writes its stdout;
everything is bytes, lines end with ``\\n``, arrays are little-endian float64::

    wirecheck -> program   b"wirecheck-candidate 1\\n"                 (once)
    program -> wirecheck   b"wirecheck-candidate 1\\n"                 (once; or a JSON line
                                                                        {"error": "..."} and exit)
    then, per request:
    wirecheck -> program   {"request": k, "n": N, "camera": {...}}\\n  then N*3 float64 (x, y, z rows)
    program -> wirecheck   {"n": N}\\n                                 then N*2 float64 (x_px, y_px rows;
                                                                        NaN, NaN for a clipped point)
                       or  {"error": "one line"}\\n                     (the request fails, the run goes on)

    an unprojector's request (``"kind": "unproject"``; a request without ``kind`` projects):
    wirecheck -> program   {"request": k, "kind": "unproject", "n": N, "camera": {...}}\\n
                           then N*3 float64 (x_px, y_px, depth along forward rows)
    program -> wirecheck   {"n": N}\\n then N*3 float64 (the world points' x, y, z rows)

wirecheck closes the program's stdin when it is done; the program then exits.
The camera object holds every field of the Python contract (oracles.candidates.candidate)
and the same camera as matrices, built on the oracle side (oracles.references.convert):
OpenCV's ``K``, ``R``, ``t`` and OpenGL's ``view_matrix`` and
``projection_matrix`` (row-major nested lists, column-vector convention);
``intrinsics`` (``[fx, fy, cx, cy]``) and ``distortion`` (OpenCV's
``distCoeffs``) are ``null`` unless the camera is calibrated / has a lens.
"""

from __future__ import annotations

import json
import math
import re

import numpy as np

from ..references.convert import camera_to_gl, opencv_matrices

#: The protocol version this wirecheck speaks.
VERSION = 1
#: The first line each side writes.
HEADER = f"wirecheck-candidate {VERSION}\n".encode()
#: Longest JSON line either side may write (a camera is ~1.5 KB); a longer one is garbage.
MAX_LINE = 1 << 16
#: Bytes per point in a request and in a reply.
REQUEST_POINT_BYTES = 3 * 8
REPLY_POINT_BYTES = 2 * 8
#: The wire's float type: little-endian float64 on every platform.
WIRE_DTYPE = np.dtype("<f8")


class ProtocolError(ValueError):
    """The other side wrote something outside the protocol."""


def _json_number(x: float):
    """A float for JSON: finite values exactly (repr round-trips), else None."""
    x = float(x)
    return x if math.isfinite(x) else None


def camera_message(camera) -> dict:
    """The request's ``camera`` object for a camera of the Python contract."""
    r_cv, t_cv, k = opencv_matrices(camera)
    view, proj = camera_to_gl(camera)

    def rows(m):
        return [[_json_number(v) for v in row] for row in np.asarray(m)]

    def vec(v):
        return [_json_number(x) for x in np.asarray(v, dtype=np.float64).reshape(-1)]

    return {
        "position": vec(camera.position),
        "forward": vec(camera.forward),
        "up": vec(camera.up),
        "right": vec(camera.right),
        "fov_y_deg": _json_number(camera.fov_y_deg),
        "width": int(camera.width),
        "height": int(camera.height),
        "near": _json_number(camera.near),
        "far": _json_number(camera.far),
        "projection": camera.projection,
        "ortho_height": _json_number(camera.ortho_height),
        "intrinsics": None if camera.intrinsics is None else vec(camera.intrinsics),
        "distortion": None if camera.distortion is None else vec(camera.distortion),
        "K": rows(k),
        "R": rows(r_cv),
        "t": vec(t_cv),
        "view_matrix": rows(view),
        "projection_matrix": rows(proj),
    }


def camera_text(camera) -> str:
    """The request's ``camera`` object as JSON text (built once per camera by the caller)."""
    return json.dumps(camera_message(camera), separators=(",", ":"), allow_nan=False)


def encode_request(request_id: int, p_world: np.ndarray, camera_json: str, kind: str | None = None) -> bytearray:
    """One request: the JSON line (``camera_json`` from :func:`camera_text`) and the points, ``(N, 3)`` float64.

    ``kind="unproject"``: an unprojector's request, its rows ``(x_px, y_px, depth)``.
    """
    p_world = np.ascontiguousarray(p_world, dtype=WIRE_DTYPE).reshape(-1, 3)
    kind_key = f'"kind":"{kind}",' if kind is not None else ""
    line = f'{{"request":{int(request_id)},{kind_key}"n":{len(p_world)},"camera":{camera_json}}}\n'
    out = bytearray(line.encode())
    if len(p_world):  # N = 0: the line alone (a view of no bytes cannot be cast)
        out += memoryview(p_world).cast("B")  # one copy of the points, not two
    return out


def encode_reply(p_px: np.ndarray, precision: str = "float64", columns: int = 2) -> bytes:
    """One reply: ``{"n": N}`` (with ``"precision": "float32"`` for a float32 answer) and the pixels, float64
    (``columns=3``: an unprojector's world points)."""
    p_px = np.ascontiguousarray(p_px, dtype=WIRE_DTYPE).reshape(-1, columns)
    head = {"n": len(p_px), **({"precision": precision} if precision != "float64" else {})}
    return json.dumps(head).encode() + b"\n" + p_px.tobytes()


#: The keys a reply line may hold (an error reply: ``error``, and others are ignored).
REPLY_KEYS = ("n", "precision")
#: The values a reply's optional ``precision`` may take (oracles.tolerances.PRECISIONS).
REPLY_PRECISIONS = ("float32", "float64")


def reply_precision(line: bytes) -> str:
    """The precision a reply line declares (``"float64"`` when it says none); ProtocolError for another value."""
    obj = parse_line(line, "a reply")
    precision = obj.get("precision", "float64")
    if precision not in REPLY_PRECISIONS:
        raise ProtocolError(
            f'wrote the reply {shown(line)}: expected "precision" to be one of {", ".join(REPLY_PRECISIONS)}'
        )
    return precision


def encode_error(message: str) -> bytes:
    """A reply (or a hello) that refuses: one line of text."""
    return json.dumps({"error": " ".join(str(message).split())}).encode() + b"\n"


def error_text(value) -> str:
    """A program's ``{"error": ...}`` as one line for the console and the report: whitespace runs made one
    space, other control characters (a terminal's escape sequences, NUL) escaped, at most 500 characters."""
    text = " ".join(str(value).split())
    return "".join(c if c.isprintable() else repr(c)[1:-1] for c in text)[:500]


def shown(data: bytes, limit: int = 60) -> str:
    """Bytes as a short repr for an error line."""
    return repr(data[:limit]) + ("..." if len(data) > limit else "")


class _DuplicateKey(ValueError):
    pass


def _unique_keys(pairs) -> dict:
    """``object_pairs_hook``: a key twice is ambiguous (parsers keep the first or the last), so garbage."""
    obj = dict(pairs)
    if len(obj) != len(pairs):
        seen = set()
        raise _DuplicateKey(next(k for k, _ in pairs if k in seen or seen.add(k)))
    return obj


def parse_line(line: bytes, what: str) -> dict:
    """A JSON object line; ProtocolError naming ``what`` otherwise (a key twice included)."""
    try:
        obj = json.loads(line.decode("utf-8"), object_pairs_hook=_unique_keys)
    except _DuplicateKey as exc:
        raise ProtocolError(
            f"wrote {shown(line)} instead of {what}: the key {shown(str(exc))} twice (expected each key once)"
        ) from None
    except (UnicodeDecodeError, ValueError, RecursionError):  # RecursionError: arrays nested too deep
        raise ProtocolError(f"wrote garbage instead of {what}: {shown(line)} (expected one JSON line)") from None
    if not isinstance(obj, dict):
        raise ProtocolError(f"wrote {shown(line)} instead of {what}: expected a JSON object")
    return obj


def reply_length(line: bytes, n_expected: int, columns: int = 2) -> int:
    """Payload bytes that follow a reply's JSON line; ProtocolError for garbage or a wrong size.

    An ``{"error": ...}`` reply raises :class:`CandidateReportedError`.
    """
    obj = parse_line(line, "a reply")
    if "error" in obj:
        raise CandidateReportedError(error_text(obj["error"]))
    unknown = sorted(set(obj) - set(REPLY_KEYS))
    if unknown:  # an echo of the request ({"request":..,"n":N,...}) must not pass for a reply
        raise ProtocolError(
            f"wrote the reply {shown(line)}: the key {shown(unknown[0], 30)} is not one of a "
            f"reply's ({', '.join(REPLY_KEYS)})"
        )
    n = obj.get("n")
    if not isinstance(n, int) or isinstance(n, bool):
        raise ProtocolError(f'wrote the reply {shown(line)}: expected {{"n": {n_expected}}} or {{"error": ...}}')
    if n != n_expected:
        digits = str(n)  # a reply line holds up to MAX_LINE digits: the reason shows the first 24
        digits = digits if len(digits) <= 24 else digits[:24] + "..."
        raise ProtocolError(f"answered {digits} points to a request of {n_expected}: expected {n_expected}")
    return n * columns * 8


def decode_points(payload, columns: int) -> np.ndarray:
    """``(N, columns)`` float64 from the wire (a copy, in native byte order); ``payload``: any buffer."""
    return np.frombuffer(payload, dtype=WIRE_DTYPE).reshape(-1, columns).astype(np.float64)


class CandidateReportedError(RuntimeError):
    """The program answered a request with ``{"error": ...}``."""


def check_hello(line: bytes) -> None:
    """The program's first line: the header, or ``{"error": ...}`` (:class:`CandidateReportedError`)."""
    if line == HEADER:
        return
    if line.startswith(b"{"):
        obj = parse_line(line, "the header")
        if "error" in obj:
            raise CandidateReportedError(error_text(obj["error"]))
    if re.fullmatch(rb"wirecheck-candidate [0-9]{1,9}\n", line):  # another version, byte for byte
        raise ProtocolError(f"speaks {line.decode().strip()!r}: this wirecheck speaks {HEADER.decode().strip()!r}")
    raise ProtocolError(f"answered the header with {shown(line)}: expected {HEADER!r}")
