"""An unprojector program over the candidate protocol (docs/protocol.md, requests of kind ``unproject``).

Written from the protocol's text alone, numpy and the standard library: it reads the camera's
``K``, ``R``, ``t`` from each request and answers ``X = R^T (p_cv - t)``. ``--mistake rows_flipped``
flips the rows first (the classic y-up mistake); ``--mistake error`` answers every request with
an error line. Run as ``python tests/clients/unproject_client.py [--mistake NAME]``.
"""

import json
import sys

import numpy as np

HEADER = b"wirecheck-candidate 1\n"


def read_exact(stream, n):
    data = stream.read(n)
    if len(data) != n:
        sys.exit(0)
    return data


def unproject(rows, camera, mistake):
    k, r, t = np.array(camera["K"]), np.array(camera["R"]), np.array(camera["t"])
    u, v, d = rows[:, 0], rows[:, 1], rows[:, 2]
    if mistake == "rows_flipped":
        v = camera["height"] - 1 - v
    x = (u - k[0, 2]) / k[0, 0]
    y = (v - k[1, 2]) / k[1, 1]
    if camera["projection"] == "perspective":
        p_cv = np.stack([x * d, y * d, d], axis=1)
    else:
        p_cv = np.stack([x, y, d], axis=1)
    return (p_cv - t) @ r


def main():
    mistake = sys.argv[2] if len(sys.argv) > 2 and sys.argv[1] == "--mistake" else None
    stdin, stdout = sys.stdin.buffer, sys.stdout.buffer
    if stdin.readline() != HEADER:
        stdout.write(b'{"error": "expected the version 1 header"}\n')
        return
    stdout.write(HEADER)
    stdout.flush()
    while True:
        line = stdin.readline()
        if not line:
            return
        request = json.loads(line)
        n = request["n"]
        rows = np.frombuffer(read_exact(stdin, n * 24), dtype="<f8").reshape(n, 3)
        if request.get("kind") != "unproject" or mistake == "error":
            stdout.write(
                b'{"error": "this program only unprojects"}\n'
                if mistake != "error"
                else b'{"error": "refused on purpose"}\n'
            )
        else:
            out = unproject(rows, request["camera"], mistake)
            stdout.write(json.dumps({"n": n}).encode() + b"\n" + np.ascontiguousarray(out, dtype="<f8").tobytes())
        stdout.flush()


if __name__ == "__main__":
    main()
