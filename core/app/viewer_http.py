"""The viewer's HTTP server (``renderer --interactive``): requests in, the view's frames out.

Every request is hostile input (module docstring of core.app.viewer): bodies are
capped (:data:`MAX_BODY_BYTES`), a slow client is dropped
(:data:`REQUEST_TIMEOUT_S`), and only requests addressed to
``127.0.0.1:PORT`` or ``localhost:PORT`` from the page's own origin are
served. The view itself, its controls and the frames are
:class:`core.app.viewer.Viewer`'s.
"""

from __future__ import annotations

import json
import math
import sys
import threading
from http import HTTPStatus
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from importlib import resources
from urllib.parse import urlsplit

from .viewer import LazyOverlay, Viewer, short_repr

STATIC = ("index.html", "viewer.js", "viewer.css")
#: Largest request body read, in bytes: MAX_OPS ops of ~60 bytes of JSON each is ~15 KiB; 64 KiB
#: leaves room for long typed values, and no client can make the server allocate more.
MAX_BODY_BYTES = 64 * 1024
#: Seconds a client may take to send its request line, headers or body before its connection is
#: dropped: a local client sends a 1 KiB request in well under a millisecond, so 10 s only ever
#: ends clients that announce more than they send (they would otherwise hold a thread forever).
REQUEST_TIMEOUT_S = 10.0
#: How often the serving loop checks for :meth:`Server.stop` (http.server's default 0.5 s made every
#: stop, and so every test's server, take up to half a second).
POLL_S = 0.05


class RequestError(Exception):
    """A request the server refuses: ``status`` (a 4xx :class:`http.HTTPStatus`) and a one-line message."""

    def __init__(self, status: HTTPStatus, message: str):
        super().__init__(message)
        self.status = status


#: Headers a request may carry once at most: with two Host headers (a valid one, then another) or two
#: lengths, a proxy in front and this server could each read a different one (RFC 9112 3.2, 6.3): 400.
ONE_ONLY = ("Host", "Origin", "Content-Length", "Content-Type")


def _reject_constant(name):
    raise ValueError(f"{name} is not JSON; expected a finite number")


def _finite_float(text):
    v = float(text)
    if not math.isfinite(v):  # 1e400 parses to inf
        raise ValueError(f"number {short_repr(text)} overflows float64; expected a finite number")
    return v


def parse_body(raw: bytes) -> tuple[list, bool]:
    """``(ops, overlay)`` of a POST body; RequestError (400) if it is not ``{"ops": [...], "overlay": bool}``.

    Strict JSON (RFC 8259: no NaN or Infinity, no number beyond float64), UTF-8,
    nesting bounded by Python's recursion limit (deeper is a 400, not a crash).
    Both keys are optional (``ops`` defaults to none, ``overlay`` to false).
    """
    try:
        body = json.loads(raw.decode("utf-8") or "{}", parse_constant=_reject_constant, parse_float=_finite_float)
    except UnicodeDecodeError as exc:
        raise RequestError(
            HTTPStatus.BAD_REQUEST, f"request body: not UTF-8 ({exc.reason} at byte {exc.start})"
        ) from exc
    except RecursionError:
        raise RequestError(HTTPStatus.BAD_REQUEST, "request body: JSON nested too deeply") from None
    except ValueError as exc:  # JSONDecodeError, our constants, int digit limit
        raise RequestError(HTTPStatus.BAD_REQUEST, f"request body: {exc}") from exc
    if not isinstance(body, dict):
        raise RequestError(
            HTTPStatus.BAD_REQUEST,
            f'request body: a JSON {type(body).__name__}; expected an object {{"ops": [...], "overlay": bool}}',
        )
    unknown = sorted(set(body) - {"ops", "overlay"})
    if unknown:
        raise RequestError(
            HTTPStatus.BAD_REQUEST, f"request body: unknown key {short_repr(unknown[0])}; expected ops and overlay"
        )
    ops, overlay = body.get("ops", []), body.get("overlay", False)
    if not isinstance(ops, list):
        raise RequestError(HTTPStatus.BAD_REQUEST, f"request body: ops {short_repr(ops)}: expected a list")
    if not isinstance(overlay, bool):
        raise RequestError(
            HTTPStatus.BAD_REQUEST, f"request body: overlay {short_repr(overlay)}: expected true or false"
        )
    return ops, overlay


def _handler(viewer: Viewer):
    class Handler(BaseHTTPRequestHandler):
        server_version = "wirecheck-viewer"
        timeout = REQUEST_TIMEOUT_S  # socket timeout: a stalled client frees its thread

        #: a malformed request line is answered with a status line too (http.server's default, HTTP/0.9, has none)
        default_request_version = "HTTP/1.0"

        def log_message(self, fmt, *args):  # quiet: the terminal shows only the URL
            pass

        def _send(self, code: int, body: bytes, ctype: str, headers=()) -> None:
            try:
                self.send_response(code)
                self.send_header("Content-Type", ctype)
                self.send_header("Content-Length", str(len(body)))
                self.send_header("Cache-Control", "no-store")
                for k, val in headers:
                    self.send_header(k, val)
                self.end_headers()
                if self.command != "HEAD":
                    self.wfile.write(body)
            except (ConnectionError, TimeoutError):  # the client went away: nobody to answer
                self.close_connection = True

        def _json(self, obj, code=200, headers=()):
            self._send(code, json.dumps(obj, allow_nan=False).encode(), "application/json", headers)

        def send_error(self, code, message=None, explain=None):
            """http.server's own refusals (bad request line, 414, 431, unknown method) as JSON too."""
            self.close_connection = True
            self._json({"error": message or HTTPStatus(code).phrase}, code)

        def _refuse(self, exc: RequestError, headers=()):
            self.close_connection = True  # the unread rest of a refused body must not be parsed
            self._json({"error": str(exc)}, exc.status, headers)

        def _check_origin(self) -> None:
            """403 unless the request names this server (Host) and, if it says, comes from its page (Origin);
            400 for a request two parsers could read differently (a target that is not a path, a malformed
            header line, a header of ONE_ONLY given twice, a Transfer-Encoding).

            A page on another site can reach 127.0.0.1 through DNS rebinding (its
            own name resolving to 127.0.0.1: the Host header still says its name)
            or post to it directly (the Origin header says its site).
            """
            if not self.path.startswith("/"):  # absolute-form (http://other.site/...) names another server
                raise RequestError(
                    HTTPStatus.BAD_REQUEST, f"request target {short_repr(self.path)}: expected a path starting with /"
                )
            if self.headers.defects:  # a header line without a colon: the headers after it were dropped
                raise RequestError(HTTPStatus.BAD_REQUEST, "a malformed header line: expected 'Name: value' lines")
            for name in ONE_ONLY:  # which one counts? a proxy and this server may read different ones
                count = len(self.headers.get_all(name) or ())
                if count > 1:
                    raise RequestError(HTTPStatus.BAD_REQUEST, f"{name} given {count} times: expected one")
            if self.headers.get("Transfer-Encoding") is not None:  # with a Content-Length: request smuggling
                raise RequestError(
                    HTTPStatus.BAD_REQUEST,
                    f"Transfer-Encoding {short_repr(self.headers['Transfer-Encoding'])}: "
                    "expected a body of Content-Length bytes",
                )
            port = self.server.server_address[1]
            hosts = (f"127.0.0.1:{port}", f"localhost:{port}")
            host = (self.headers.get("Host") or "").lower()
            if host not in hosts:
                raise RequestError(HTTPStatus.FORBIDDEN, f"Host {short_repr(host)}: expected {' or '.join(hosts)}")
            origin = self.headers.get("Origin")
            if origin is not None and origin.lower() not in tuple(f"http://{h}" for h in hosts):
                raise RequestError(HTTPStatus.FORBIDDEN, f"Origin {short_repr(origin)}: expected this viewer's page")

        def _path(self) -> str:
            path = urlsplit(self.path).path  # the query string, if any, is ignored
            return "/index.html" if path == "/" else path

        def do_GET(self):
            try:
                self._check_origin()
            except RequestError as exc:
                return self._refuse(exc)
            path = self._path()
            name = path[1:]
            if name in STATIC:
                ctype = {"html": "text/html", "js": "text/javascript", "css": "text/css"}[name.rsplit(".", 1)[1]]
                body = resources.files("wirecheck.core.app").joinpath("viewer_static", name).read_bytes()
                self._send(200, body, ctype + "; charset=utf-8")
            elif path == "/api/frame":
                self._json(viewer.respond())
            else:
                self._json({"error": f"no such path {short_repr(path)}"}, 404)

        def do_POST(self):
            try:
                self._check_origin()
                if self._path() != "/api/frame":
                    raise RequestError(HTTPStatus.NOT_FOUND, f"no such path {short_repr(self._path())}")
                ops, overlay = parse_body(self._read_body())
            except RequestError as exc:
                return self._refuse(exc)
            self._json(viewer.respond(ops, overlay))

        def _read_body(self) -> bytes:
            """The body, at most MAX_BODY_BYTES; RequestError for a missing, bad or too large length, or a stall."""
            ctype = (self.headers.get("Content-Type") or "").split(";")[0].strip().lower()
            if ctype != "application/json":  # a cross-site form or text/plain post cannot say this
                raise RequestError(
                    HTTPStatus.UNSUPPORTED_MEDIA_TYPE, f"Content-Type {short_repr(ctype)}: expected application/json"
                )
            text = self.headers.get("Content-Length")
            if text is None:
                raise RequestError(HTTPStatus.LENGTH_REQUIRED, "Content-Length: missing; expected the body's size")
            if not (text.isascii() and text.isdigit() and len(text) <= 20):
                raise RequestError(HTTPStatus.BAD_REQUEST, f"Content-Length {short_repr(text)}: expected bytes >= 0")
            n = int(text)
            if n > MAX_BODY_BYTES:
                raise RequestError(
                    HTTPStatus.REQUEST_ENTITY_TOO_LARGE, f"Content-Length {n}: expected at most {MAX_BODY_BYTES} bytes"
                )
            try:
                raw = self.rfile.read(n)
            except (ConnectionError, TimeoutError):  # the socket timeout: REQUEST_TIMEOUT_S
                raw = b""
            if len(raw) != n:
                raise RequestError(
                    HTTPStatus.BAD_REQUEST,
                    f"request body: fewer bytes arrived than Content-Length {n} within {REQUEST_TIMEOUT_S:g} s",
                )
            return raw

        def _no_method(self):
            self._refuse(
                RequestError(HTTPStatus.METHOD_NOT_ALLOWED, f"method {self.command}: expected GET or POST"),
                headers=(("Allow", "GET, POST"),),
            )

        do_HEAD = do_PUT = do_DELETE = do_PATCH = do_OPTIONS = _no_method

    return Handler


class _HTTPServer(ThreadingHTTPServer):
    daemon_threads = True

    def handle_error(self, request, client_address):
        """A request that failed past the handler's checks: one line on stderr, not a traceback."""
        exc = sys.exc_info()[1]
        print(
            f"renderer: viewer: request from {client_address[0]} failed: {type(exc).__name__}: {exc}", file=sys.stderr
        )


class Server:
    """A running viewer server (a thread serving ``ThreadingHTTPServer``); :meth:`stop` ends it."""

    def __init__(self, viewer: Viewer, port: int = 0, host: str = "127.0.0.1"):
        self.httpd = _HTTPServer((host, port), _handler(viewer))
        self.viewer = viewer
        self.thread = threading.Thread(
            target=self.httpd.serve_forever, kwargs={"poll_interval": POLL_S}, name="wirecheck-viewer", daemon=True
        )

    @property
    def url(self) -> str:
        host, port = self.httpd.server_address[:2]
        return f"http://{host}:{port}/"

    def start(self) -> Server:
        self.thread.start()
        return self

    def stop(self) -> None:
        self.httpd.shutdown()
        self.httpd.server_close()
        self.thread.join()
        close = getattr(self.viewer.overlay, "close", None)
        if close is not None:
            close()


def main_interactive(s, port: int = 0) -> int:
    """Serve until Ctrl-C; print the URL. Returns the exit status."""
    if not 0 <= port <= 65535:
        print(f"renderer: error: --port {port}: expected 0 (a free port) to 65535", file=sys.stderr)
        return 2
    try:
        server = Server(Viewer(s, overlay=LazyOverlay()), port)
    except OSError as exc:
        print(f"renderer: error: --port {port}: cannot listen on 127.0.0.1 ({exc.strerror or exc})", file=sys.stderr)
        return 2
    print(f"Viewer: {server.url}  (Ctrl-C stops it)", flush=True)
    server.start()
    try:
        while server.thread.is_alive():
            server.thread.join(0.2)
    except KeyboardInterrupt:
        pass
    finally:
        server.stop()
    print("Viewer stopped.", flush=True)
    return 0
