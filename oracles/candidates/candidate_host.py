"""Run a Python candidate in its own process, speaking the candidate protocol (oracles.candidates.protocol).

    python -m wirecheck.oracles.candidates.candidate_host FILE.py:FUNC      (or MODULE:FUNC)

crosscheck starts this for ``--candidate``, so a Python projector is judged
by the same code as a C or JavaScript program: whatever it does (``os._exit``,
a hang, a crash in a C extension, KeyboardInterrupt) ends this process or one
request, never crosscheck. Each request's camera is rebuilt as the contract's
:class:`core.camera.Camera` with the exact vectors sent; the answer is checked
by :func:`oracles.candidates.candidate.call_candidate` here, so its messages are the
in-process ones. The candidate's own ``print`` goes to stderr (file
descriptor 1 is moved there), which keeps stdout for the protocol.
"""

from __future__ import annotations

import os
import sys

from wirecheck.core.errors import InputError


def _camera(msg: dict):
    """The contract's Camera with exactly the vectors of the message (no re-normalising)."""
    import numpy as np
    from wirecheck.core.camera import Camera

    vec = {k: np.array(msg[k], dtype=np.float64) for k in ("position", "forward", "up", "right")}
    cam = Camera(
        position=vec["position"],
        forward=vec["forward"],
        up=vec["up"],
        fov_y_deg=msg["fov_y_deg"],
        width=msg["width"],
        height=msg["height"],
        near=msg["near"],
        far=msg["far"],
        projection=msg["projection"],
        ortho_height=msg["ortho_height"],
        intrinsics=msg.get("intrinsics"),
        distortion=msg.get("distortion"),
    )
    for k, v in vec.items():
        v.setflags(write=False)
        object.__setattr__(cam, k, v)
    return cam


def _read_exact(stream, n: int) -> bytes:
    data = stream.read(n)
    if data is None or len(data) != n:
        raise EOFError(f"expected {n} bytes of points, got {0 if data is None else len(data)}")
    return data


def serve(spec: str, stdin, stdout, unproject: bool = False) -> int:
    """Answer requests on ``stdin``/``stdout`` (binary streams) until stdin closes.

    ``unproject``: ``spec`` is an unprojector ``FUNC(pixels, depth, camera)``, answering requests of
    kind ``unproject`` (docs/protocol.md).
    """
    from . import protocol

    def send(data: bytes) -> None:
        stdout.write(data)
        stdout.flush()

    if stdin.readline() != protocol.HEADER:
        send(protocol.encode_error(f"expected the header {protocol.HEADER!r}"))
        return 2
    try:
        from .candidate import load_candidate

        func = load_candidate(spec, "unprojector", ("pixels", "depth", "camera")) if unproject else load_candidate(spec)
    except InputError as exc:
        send(protocol.encode_error(str(exc)))
        return 0
    except BaseException as exc:  # KeyboardInterrupt, GeneratorExit at import: refuse, in one line
        send(protocol.encode_error(f"--candidate {spec!r}: importing failed: {type(exc).__name__}: {exc}"))
        return 0
    send(protocol.HEADER)
    return serve_loaded(func, stdin, send)


def serve_loaded(func, stdin, send) -> int:
    """The request loop over a loaded candidate ``func`` (after the header is answered)."""
    from . import protocol
    from .candidate import CandidateError, call_candidate_precision

    camera_key = camera = None
    while True:
        line = stdin.readline()
        if not line:
            return 0
        request = protocol.parse_line(line, "a request")
        n = int(request["n"])
        p_world = protocol.decode_points(_read_exact(stdin, n * protocol.REQUEST_POINT_BYTES), 3)
        key = line[line.find(b'"camera"') :]
        if key != camera_key:  # the same camera for a case's requests: built once
            camera_key, camera = key, _camera(request["camera"])
        if request.get("kind") == "unproject":
            send(_unprojected(func, p_world, camera))
            continue
        try:
            p_px, precision = call_candidate_precision(func, p_world, camera)
        except CandidateError as exc:
            send(protocol.encode_error(str(exc)))
            continue
        except BaseException as exc:  # KeyboardInterrupt, GeneratorExit: this request fails
            send(protocol.encode_error(f"candidate raised {type(exc).__name__}: {exc}"))
            continue
        send(protocol.encode_reply(p_px, precision))  # the dtype the function returned, for the harness


def _unprojected(func, rows, camera) -> bytes:
    """The reply to an unproject request: ``func(pixels, depth, camera)``'s ``(N, 3)`` points, or an error line."""
    import numpy as np

    from . import protocol
    from .candidate import returned_precision

    try:
        out = func(rows[:, :2].copy(), rows[:, 2].copy(), camera)
        arr = np.asarray(out)
        if arr.dtype.kind not in "fiu" or arr.shape != (len(rows), 3):
            return protocol.encode_error(
                f"returned {type(out).__name__} of shape {getattr(arr, 'shape', None)} and "
                f"dtype {arr.dtype}: expected an ({len(rows)}, 3) float array"
            )
        return protocol.encode_reply(arr.astype(np.float64), returned_precision(out), columns=3)
    except BaseException as exc:  # SystemExit, KeyboardInterrupt too: this request fails
        return protocol.encode_error(f"{type(exc).__name__}: {' '.join(str(exc).split())[:200]}")


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    unproject = argv[:1] == ["--unproject"]
    if unproject:
        argv = argv[1:]
    if len(argv) != 1:
        print(
            "usage: python -m wirecheck.oracles.candidates.candidate_host [--unproject] FILE.py:FUNC|MODULE:FUNC",
            file=sys.stderr,
        )
        return 2
    # this process is wirecheck's: nothing the candidate imports, at start-up or inside a call,
    # leaves a __pycache__ folder in the user's folders
    sys.dont_write_bytecode = True
    extra = os.environ.get("WIRECHECK_HOST_PATH")
    if extra:
        sys.path[:0] = [p for p in extra.split(os.pathsep) if p]
    # the protocol keeps the real stdout; the candidate's prints (Python or C) go to stderr
    protocol_out = os.fdopen(os.dup(1), "wb")  # buffered: a raw write may be partial
    os.dup2(2, 1)
    sys.stdout = sys.stderr
    return serve(argv[0], sys.stdin.buffer, protocol_out, unproject)


if __name__ == "__main__":
    sys.exit(main())
