"""The viewer's HTTP API under hostile requests: any local process or web page can reach it.

Each request is sent byte for byte over a socket to an in-process Server on
port 0 (64x48 frames: cheap). What must hold for every one (core/app/viewer.py's
module docstring, docs/interactive.md "Error answers"): a 4xx with a JSON
``{"error": ...}`` or a valid frame, never a dropped connection, a 500, a
stalled thread or a traceback on the terminal, and the view the next request
sees is the one before the bad request.
"""

import base64
import io
import json
import math
import socket
import threading
import warnings

import pytest
import wirecheck.core.app.viewer_http as viewer_http_mod
from hypothesis import HealthCheck, given
from hypothesis import settings as hsettings
from hypothesis import strategies as st
from numpy.testing import assert_allclose
from PIL import Image
from wirecheck.core.app.cli import build_parser, settings_from_args
from wirecheck.core.app.viewer import FIELDS, MAX_OPS, View, Viewer
from wirecheck.core.app.viewer_http import MAX_BODY_BYTES, Server

W, H = 64, 48
# a few float64 rotations of values ~4 (test_viewer.py's TOL)
TOL = 1e-12


def _settings(tmp_path, *args):
    argv = ["--frames", "6", "--width", str(W), "--height", str(H), "--out", str(tmp_path / "out"), *args]
    return settings_from_args(build_parser().parse_args(argv))


@pytest.fixture
def server(tmp_path):
    srv = Server(Viewer(_settings(tmp_path))).start()
    try:
        yield srv
    finally:
        srv.stop()


def _raw(srv, data: bytes, timeout: float = 5.0):
    """Send ``data``, read to EOF: ``(status, headers dict, body bytes)``; status None if nothing came back."""
    port = srv.httpd.server_address[1]
    with socket.create_connection(("127.0.0.1", port), timeout=timeout) as c:
        try:
            c.sendall(data)
        except OSError:  # refused before the whole request was sent
            pass
        out = b""
        while chunk := c.recv(65536):
            out += chunk
    if not out:
        return None, {}, b""
    head, _, body = out.partition(b"\r\n\r\n")
    lines = head.decode("latin-1").split("\r\n")
    headers = dict(line.split(": ", 1) for line in lines[1:])
    return int(lines[0].split()[1]), headers, body


def _request(srv, method="POST", path="/api/frame", body=b"", headers=None, length="auto"):
    port = srv.httpd.server_address[1]
    h = {"Host": f"127.0.0.1:{port}", "Content-Type": "application/json", "Connection": "close"}
    if length == "auto":
        h["Content-Length"] = str(len(body))
    elif length is not None:
        h["Content-Length"] = length
    h.update(headers or {})
    head = f"{method} {path} HTTP/1.1\r\n" + "".join(f"{k}: {v}\r\n" for k, v in h.items() if v is not None)
    return _raw(srv, head.encode("latin-1") + b"\r\n" + body)


def _post(srv, obj):
    return _request(srv, body=json.dumps(obj).encode())


def _view(srv):
    status, _, body = _request(srv, method="GET", length=None, headers={"Content-Type": None})
    assert status == 200
    return json.loads(body)["view"]


NESTED = b"[" * 30000 + b"]" * 30000  # 60 KB: under MAX_BODY_BYTES, deeper than the recursion limit


@pytest.mark.parametrize(
    "body, length, headers, status, needle",
    [
        (b'{"ops": []}', None, {}, 411, "Content-Length: missing"),
        (b'{"ops": []}', "-1", {}, 400, "Content-Length '-1'"),
        (b'{"ops": []}', "abc", {}, 400, "Content-Length 'abc'"),
        (b'{"ops": []}', "99999999999999", {}, 413, f"at most {MAX_BODY_BYTES} bytes"),
        (b" " * (MAX_BODY_BYTES + 1), "auto", {}, 413, f"at most {MAX_BODY_BYTES} bytes"),
        (b'{"ops": "\xff"}', "auto", {}, 400, "not UTF-8"),
        (b"{not json", "auto", {}, 400, "request body: Expecting property name"),
        (b"[1, 2]", "auto", {}, 400, "a JSON list; expected an object"),
        (NESTED, "auto", {}, 400, "JSON nested too deeply"),
        (b'{"ops": [{"op": "orbit", "dx": NaN, "dy": 0}]}', "auto", {}, 400, "NaN is not JSON"),
        (b'{"ops": [{"op": "dolly", "delta": -Infinity}]}', "auto", {}, 400, "-Infinity is not JSON"),
        (b'{"ops": [{"op": "dolly", "delta": 1e400}]}', "auto", {}, 400, "'1e400' overflows float64"),
        (b'{"ops": {"op": "reset"}}', "auto", {}, 400, "ops {'op': 'reset'}: expected a list"),
        (b'{"ops": [], "overlay": "no"}', "auto", {}, 400, "overlay 'no': expected true or false"),
        (b'{"op": []}', "auto", {}, 400, "unknown key 'op'"),
        (b'{"ops": []}', "auto", {"Content-Type": "text/plain"}, 415, "expected application/json"),
        (b'{"ops": []}', "auto", {"Host": "evil.example:80"}, 403, "Host 'evil.example:80'"),
        (b'{"ops": []}', "auto", {"Host": None}, 403, "Host ''"),
        (b'{"ops": []}', "auto", {"Origin": "http://evil.example"}, 403, "Origin 'http://evil.example'"),
    ],
)
def test_a_bad_request_is_a_4xx_json_error_and_the_view_stays(server, capsys, body, length, headers, status, needle):
    before = json.loads(_post(server, {"ops": [{"op": "orbit", "dx": 10, "dy": 0}]})[2])["view"]
    got, hdrs, resp = _request(server, body=body, length=length, headers=headers)
    assert got == status, resp
    assert hdrs["Content-Type"] == "application/json" and needle in json.loads(resp)["error"]
    assert _view(server) == before  # still serving, nothing applied
    assert capsys.readouterr().err == ""  # no traceback on the terminal


def test_a_body_shorter_than_its_length_is_dropped_after_the_timeout(tmp_path, monkeypatch, capsys):
    # the server waits REQUEST_TIMEOUT_S for the rest; 0.3 s here (set before the handler class is made)
    monkeypatch.setattr(viewer_http_mod, "REQUEST_TIMEOUT_S", 0.3)
    srv = Server(Viewer(_settings(tmp_path))).start()
    try:
        status, _, resp = _request(srv, body=b'{"ops": []}', length="100")
        assert status == 400 and "fewer bytes arrived than Content-Length 100" in json.loads(resp)["error"]
        status, _, _ = _raw(srv, b"GET /api/fr")  # a request line that never ends
        assert status is None  # closed, not held
        assert _view(srv)["frame"] == 1
    finally:
        srv.stop()
    assert capsys.readouterr().err == ""


def test_a_legal_origin_and_localhost_are_served(server):
    port = server.httpd.server_address[1]
    for headers in ({"Host": f"localhost:{port}"}, {"Origin": f"http://127.0.0.1:{port}"}):
        status, _, resp = _request(server, body=b'{"ops": [{"op": "step", "n": 1}]}', headers=headers)
        assert status == 200 and json.loads(resp)["error"] is None
    assert _view(server)["frame"] == 3


@pytest.mark.parametrize(
    "ops, needle",
    [
        ([{"op": "orbit", "dx": 10**400, "dy": 0}], "dx 1000000000000"),  # int beyond float64
        ([{"op": "orbit", "dx": True, "dy": 0}], "dx True: expected a finite number"),
        ([{"op": "set", "field": ["fov"], "value": 1}], "field ['fov']"),  # unhashable
        ([{"op": "dolly", "delta": 1e6}], "dolly 1000000.0"),  # exp(1000): overflow
        ([{"op": "dolly", "delta": -1e6}], "dolly -1000000.0"),  # exp(-1000) = 0: zero distance
        # distance 4 e^700 ~ 4e304, a pixel ~ 1e303: a pan of 1e10 px overflows to inf
        ([{"op": "dolly", "delta": 7e5}, {"op": "pan", "dx": 1e10, "dy": 0}], "leave the float64 range"),
        # a pan to ~1e306: the 4 units between camera and look-at point are below the spacing of floats there
        ([{"op": "pan", "dx": 1e308, "dy": 1e308}], "expected a point different from look-at"),
        ([{"op": "set", "field": "fov", "value": 0}], "camera fov 0.0"),
        ([{"op": "set", "field": "fov", "value": 180}], "camera fov 180.0"),
        ([{"op": "set", "field": "near", "value": 0}], "camera near 0.0"),
        ([{"op": "set", "field": "far", "value": "inf"}], "far 'inf': expected a finite number"),
        ([{"op": "step", "n": 10**30}, {"op": "set", "field": "fov", "value": None}], "fov None"),
        ([{"op": "reset"}] * (MAX_OPS + 1), f"{MAX_OPS + 1} in one request; expected at most {MAX_OPS}"),
    ],
)
def test_a_bad_op_is_an_error_with_the_last_good_frame(server, capsys, ops, needle):
    before = json.loads(_post(server, {"ops": [{"op": "orbit", "dx": 10, "dy": 0}]})[2])
    status, _, resp = _post(server, {"ops": ops})
    out = json.loads(resp)
    assert status == 200 and needle in out["error"], out["error"]
    # one line, bounded whatever was sent (echoes are cut to 60 characters; a camera message
    # prints two 3-vectors of up to 24 characters a coordinate)
    assert "\n" not in out["error"] and len(out["error"]) < 400
    assert out["view"] == before["view"] and out["image"] == before["image"]
    assert capsys.readouterr().err == ""


def test_max_ops_ops_are_applied(server):
    # MAX_OPS orbits of -2 px (1 deg) each: the camera at (0, 0, 4) turns MAX_OPS deg about +Y
    status, _, resp = _post(server, {"ops": [{"op": "orbit", "dx": -2, "dy": 0}] * MAX_OPS})
    a = math.radians(MAX_OPS)
    assert status == 200 and json.loads(resp)["error"] is None
    assert_allclose(json.loads(resp)["view"]["position"], (4 * math.sin(a), 0.0, 4 * math.cos(a)), atol=1e-10)


@pytest.mark.parametrize(
    "method, path, status, needle",
    [
        ("GET", "/../../etc/passwd", 404, "no such path '/../../etc/passwd'"),
        ("GET", "/%2e%2e/viewer.js", 404, "no such path '/%2e%2e/viewer.js'"),
        ("GET", "/core/viewer.py", 404, "no such path"),
        ("GET", "/" + "a" * 70000, 414, "Request-URI Too Long"),
        ("HEAD", "/", 405, ""),
        ("PUT", "/api/frame", 405, "method PUT: expected GET or POST"),
        ("DELETE", "/index.html", 405, "method DELETE"),
        ("OPTIONS", "/api/frame", 405, "method OPTIONS"),  # no CORS preflight answer: cross-site JSON POSTs stop here
        ("BREW", "/", 501, "Unsupported method ('BREW')"),
    ],
)
def test_paths_and_methods(server, capsys, method, path, status, needle):
    got, hdrs, resp = _request(server, method=method, path=path, length=None)
    assert got == status
    if method == "HEAD":
        assert resp == b""
    else:
        assert hdrs["Content-Type"] == "application/json" and needle in json.loads(resp)["error"]
    if status == 405:
        assert hdrs["Allow"] == "GET, POST"
    assert _view(server)["frame"] == 1
    assert capsys.readouterr().err == ""


def test_a_query_string_is_ignored(server):
    status, hdrs, resp = _request(server, method="GET", path="/viewer.js?v=2", length=None)
    assert status == 200 and hdrs["Content-Type"].startswith("text/javascript") and b"addEventListener" in resp
    status, _, resp = _request(server, path="/api/frame?t=1", body=b'{"ops": [{"op": "step", "n": 2}]}')
    assert status == 200 and json.loads(resp)["view"]["frame"] == 3


def test_concurrent_requests_get_consistent_frames(tmp_path):
    """N threads post a 1-degree orbit at once: each answer is one of the N states, and its image is that state's frame.

    Orbits about the fixed +Y axis commute, so whatever the order, the k-th
    request applied sees the camera turned k degrees: the N answers must be
    exactly k = 1..N, each with the frame of its own view (no torn state).
    """
    n = 12
    s = _settings(tmp_path)
    srv = Server(Viewer(s)).start()
    barrier = threading.Barrier(n)
    answers, errors = [], []

    def client():
        try:
            barrier.wait()
            answers.append(json.loads(_post(srv, {"ops": [{"op": "orbit", "dx": -2, "dy": 0}]})[2]))
        except Exception as exc:  # collected: an assert in a thread would be lost
            errors.append(exc)

    threads = [threading.Thread(target=client) for _ in range(n)]
    try:
        for t in threads:
            t.start()
        for t in threads:
            t.join(30)
    finally:
        srv.stop()
    assert errors == [] and len(answers) == n
    ref = Viewer(s)
    degrees = []
    for a in answers:
        assert a["error"] is None
        x, _, z = a["view"]["position"]
        k = math.degrees(math.atan2(x, z))
        degrees.append(round(k))
        assert abs(k - round(k)) < 1e-9  # whole degrees: k orbits, not a torn mix
        png, _, _ = ref.frame_png(
            View(
                **{
                    **a["view"],
                    "position": tuple(a["view"]["position"]),
                    "target": tuple(a["view"]["target"]),
                    "up": tuple(a["view"]["up"]),
                }
            )
        )
        assert base64.b64decode(a["image"]) == png  # the frame is the view's own
    assert sorted(degrees) == list(range(1, n + 1))


_num = st.one_of(
    st.floats(),
    st.integers(),
    st.booleans(),
    st.none(),
    st.text(max_size=6),
    st.sampled_from([1e-300, 5e-324, 1e300, 180, 179.99999999999997, "1e400", "nan", [], {}]),
)
_op = st.one_of(
    st.fixed_dictionaries({"op": st.sampled_from(["orbit", "pan"]), "dx": _num, "dy": _num}),
    st.fixed_dictionaries({"op": st.just("dolly"), "delta": _num}),
    st.fixed_dictionaries(
        {
            "op": st.just("set"),
            "field": st.one_of(st.sampled_from(list(FIELDS)), _num),
            "value": st.one_of(_num, st.sampled_from(["orthographic", "shaded", True, False])),
        }
    ),
    st.fixed_dictionaries({"op": st.just("step"), "n": _num}),
    st.just({"op": "reset"}),
    _num,
    st.fixed_dictionaries({"op": _num}),
)


def test_any_ops_give_a_frame_or_an_error_with_the_view_kept(tmp_path):
    """Hypothesis over hostile op lists, on one Viewer whose state carries from example to example.

    Every answer is a 64x48 PNG; an error leaves the view as it was; no numpy
    warning (an overflow, a NaN) is raised on the way.
    """
    viewer = Viewer(_settings(tmp_path, "--scene", "prism"))

    @hsettings(max_examples=60, deadline=None, database=None, suppress_health_check=list(HealthCheck))
    @given(st.lists(_op, max_size=5))
    def check(ops):
        before = viewer.view
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            resp = viewer.respond(ops)
        assert Image.open(io.BytesIO(base64.b64decode(resp["image"]))).size == (W, H)
        if resp["error"] is not None:
            assert viewer.view == before

    check()


def test_an_internal_failure_is_one_line_on_stderr_and_the_server_goes_on(server, capsys, monkeypatch):
    calls = []

    def broken(v, timing=None):
        calls.append(v)
        raise RuntimeError("simulated bug")

    monkeypatch.setattr(server.viewer, "frame_png", broken)
    status, _, _ = _post(server, {"ops": []})
    assert status is None and len(calls) == 1  # the connection closed, unanswered
    err = capsys.readouterr().err
    assert err == "renderer: viewer: request from 127.0.0.1 failed: RuntimeError: simulated bug\n"
    monkeypatch.undo()
    assert _view(server)["frame"] == 1  # and the next request is served


@pytest.mark.parametrize("method", ["GET", "POST"])
@pytest.mark.parametrize("second", ["evil.example:80", "OWN", "localhost:OWN_PORT"])
def test_a_request_with_two_host_headers_is_refused(server, capsys, method, second):
    """A valid Host, then another (evil, the same one again, the other valid name): 400, which one counts is not
    guessed. Before: 200 with the frame (http.server reads the first Host only)."""
    port = server.httpd.server_address[1]
    own = f"127.0.0.1:{port}"
    second = {"OWN": own}.get(second, second.replace("OWN_PORT", str(port)))
    body = b'{"ops": []}' if method == "POST" else b""
    length = f"Content-Length: {len(body)}\r\n" if method == "POST" else ""
    head = (
        f"{method} /api/frame HTTP/1.1\r\nHost: {own}\r\nHost: {second}\r\nContent-Type: application/json\r\n"
        f"{length}Connection: close\r\n\r\n"
    )
    got, hdrs, resp = _raw(server, head.encode("latin-1") + body)
    assert got == 400, resp
    assert json.loads(resp)["error"] == "Host given 2 times: expected one"
    assert capsys.readouterr().err == ""


def test_a_post_with_two_lengths_is_refused(server):
    port = server.httpd.server_address[1]
    body = b'{"ops": []}'
    head = (
        f"POST /api/frame HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nContent-Type: application/json\r\n"
        f"Content-Length: {len(body)}\r\nContent-Length: 0\r\nConnection: close\r\n\r\n"
    )
    got, _, resp = _raw(server, head.encode("latin-1") + body)
    assert (got, json.loads(resp)["error"]) == (400, "Content-Length given 2 times: expected one")


@pytest.mark.parametrize(
    "name, request_text, needle",
    [
        # an absolute-form target names another server, whatever the Host says (RFC 9112 3.2.2): before, 200
        (
            "absolute target",
            "POST http://evil.example/api/frame HTTP/1.1\r\nHost: {own}\r\n{body_headers}",
            "request target 'http://evil.example/api/frame': expected a path starting with /",
        ),
        # a length and a chunked encoding: a proxy may frame the body by one, this server by the other: before, 200
        (
            "length and chunked",
            "POST /api/frame HTTP/1.1\r\nHost: {own}\r\nTransfer-Encoding: chunked\r\n{body_headers}",
            "Transfer-Encoding 'chunked': expected a body of Content-Length bytes",
        ),
        # a header line without a colon ends http.server's header parsing, silently: before, 200
        (
            "line without colon",
            "POST /api/frame HTTP/1.1\r\nHost: {own}\r\n{body_headers_no_end}X y\r\n\r\n",
            "a malformed header line",
        ),
    ],
    ids=["absolute-target", "length-and-chunked", "line-without-colon"],
)
def test_requests_two_parsers_read_differently_are_refused(server, name, request_text, needle):
    port = server.httpd.server_address[1]
    body = b'{"ops": []}'
    rest = f"Content-Type: application/json\r\nContent-Length: {len(body)}\r\nConnection: close\r\n"
    text = request_text.format(own=f"127.0.0.1:{port}", body_headers=rest + "\r\n", body_headers_no_end=rest)
    got, _, resp = _raw(server, text.encode("latin-1") + body)
    assert got == 400 and needle in json.loads(resp)["error"], (got, resp)


@pytest.mark.parametrize(
    "line, status",
    [
        (b"GET /api/frame\r\n\r\n", 403),  # HTTP/0.9: served as 1.0, then refused for its missing Host
        (b"POST /api/frame TTP/1.1\r\n\r\n", 400),  # a bad version: http.server's own 400
    ],
    ids=["http-0.9", "bad-version"],
)
def test_a_malformed_request_line_gets_a_status_line(server, line, status):
    """Before, http.server answered a request line it could not parse as HTTP/0.9 would: the body alone,
    no status line (a client read nothing it could name)."""
    got, hdrs, resp = _raw(server, line)
    assert got == status and hdrs["Content-Type"] == "application/json", resp
