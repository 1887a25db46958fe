"""The web server of ``geoshade serve``: one page, its script, and one websocket per tab.

Safe by default (the threat model is in ``docs/guide/web.rst``):

- bound to 127.0.0.1; on a loopback address a request must name a loopback host (``Host``), so
  a web site that points its own name at 127.0.0.1 (DNS rebinding) gets nothing;
- every request needs the random token printed at start. The page opened with it is served
  under a path unique to this server (``/s/<random>/``), the token leaves the address at once
  (``history.replaceState``) and the browser keeps instead a cookie that is not the token,
  named with the port, HTTP-only, ``SameSite=Strict`` and scoped to that path: no other port,
  server or site receives it. Pages say ``frame-ancestors 'none'`` and ``X-Frame-Options:
  DENY`` (no other page may frame them) and ``Referrer-Policy: no-referrer``;
- a websocket from another site's page is refused;
- the door (:mod:`geoshade.web.gate`) closes connections that do not show the token within
  :data:`~geoshade.web.gate.HEADER_S` seconds and holds a bounded number of them;
- every message of a page is checked (:mod:`geoshade.web.messages`) and rate-limited; what
  goes back names files as the page knows them (:meth:`Catalog.public`);
- the browser names files only from the :class:`~geoshade.web.catalog.Catalog`, whose checks
  refuse what could block a read; reads run where they cannot stall the server
  (:mod:`geoshade.web.library`); SIGINT and SIGTERM stop it in every state.

Messages from the browser (JSON, :data:`geoshade.web.messages.MESSAGES`): ``open`` (a catalogue
name), ``pointer`` (down/move/up in picture pixels), ``wheel``, ``key``, ``resize``, ``set``
(``{name: value}`` of a panel control), ``ack`` (the last frame is shown), ``screenshot``,
``save_camera``, ``load_camera``, ``unpick`` and ``history`` (a kept pick's table and plot),
``plot_size``, ``timeline`` (a click on the summary plot). To the browser: JSON messages, each
followed by one binary message where it carries data (``frame``: JPEG or PNG; ``download``: a
file; ``summary`` and ``history``: a plot's PNG).
"""

from __future__ import annotations

import asyncio
import contextlib
import hmac
import ipaddress
import json
import os
import re
import secrets
import signal
import sys
import threading
import time
from concurrent.futures import Future, ThreadPoolExecutor
from importlib import resources
from urllib.parse import urlsplit

from geoshade.errors import InputError
from geoshade.web.catalog import Catalog
from geoshade.web.engine import GLThread, Library, Tab, print_bug
from geoshade.web.messages import MAX_MESSAGE, Bucket, limits, parse

#: tabs (websockets) one server holds at most
MAX_TABS = 32
#: messages waiting to go to one page at most (a page that does not read them is closed)
MAX_OUT = 512
#: error lines one page is sent a second at most (the others are counted in the next)
ERRORS_PER_S = 10.0
#: seconds a listing of the files is reused for the next tab
LISTING_S = 2.0
#: seconds the server waits for its tabs, GL thread and cluster when it stops
STOP_S = 5.0
#: headers of every response
HEADERS = {"X-Frame-Options": "DENY", "Referrer-Policy": "no-referrer",
           "X-Content-Type-Options": "nosniff", "Cache-Control": "no-store",
           "Cross-Origin-Opener-Policy": "same-origin",
           "Cross-Origin-Resource-Policy": "same-origin"}
#: hosts a request may name when the server listens on a loopback address
LOOPBACK_NAMES = ("localhost", "127.0.0.1", "::1", "[::1]")
_HOST = re.compile(r"^[A-Za-z0-9.\-\[\]:]{1,255}$")


def _aiohttp():
    try:
        from aiohttp import web
    except ImportError as err:
        raise InputError(f"serve: needs the web extra ({err}); pip install 'geoshade[web]'"
                         ) from None
    return web


def _loopback(host: str) -> bool:
    try:
        return ipaddress.ip_address(host.strip("[]")).is_loopback
    except ValueError:
        return host == "localhost"


class Server:
    """The app's shared state: catalogue, shared models, the GL thread, the open tabs.

    Parameters
    ----------
    catalog : Catalog
    token : str, optional
        Default: a random one (``secrets.token_urlsafe``).
    size : (w, h)
        The picture size a tab starts with (the page then asks for the size it shows).
    settings : dict
        Options every View is opened with, those its part takes (``select``, ``property``,
        ``distributed``, ``scheduler`` ...; a cluster is started once, for every tab).
    kind : str, optional
        The part every file is opened with.
    hints : dict
        :func:`geoshade.load` hints for every file (``shape``, ``dtype``, ``skip_missing`` ...).
    camera : dict
        ``{"view": name, "ortho": bool}``: where each tab's camera starts.
    host : str
        The address listened on (a loopback one: requests must name a loopback host).
    """

    def __init__(self, catalog: Catalog, token: str | None = None, size=(800, 600),
                 settings: dict | None = None, kind: str | None = None,
                 hints: dict | None = None, camera: dict | None = None,
                 host: str = "127.0.0.1"):
        self.catalog = catalog
        self.token = token or secrets.token_urlsafe(24)
        #: the page's path, unique to this server, and the cookie the browser keeps there
        self.base = f"/s/{secrets.token_urlsafe(16)}/"
        self.cookie_value = secrets.token_urlsafe(32)
        self.cookie_name = "geoshade"
        self.size = size
        self.camera = dict(camera or {})
        self.library = Library(catalog, settings, hints)
        self.gl = GLThread()
        self.pool = ThreadPoolExecutor(2, thread_name_prefix="geoshade-cpu")
        self.tabs: dict[Tab, object] = {}
        self.kind = kind
        self.loopback = _loopback(host)
        self.gate = None
        self._listing: tuple[float, list[str]] = (-LISTING_S, [])

    def bound(self, port: int) -> None:
        """The port is known: the cookie is named with it (two servers keep two cookies)."""
        self.cookie_name = f"geoshade_{port}"

    # --- requests ------------------------------------------------------------------------------
    def allowed(self, request) -> bool:
        """The request shows the token (``?token=``) or the cookie of this server's page."""
        given = request.query.get("token")
        if given is not None:
            return hmac.compare_digest(given.encode(), self.token.encode())
        cookie = request.cookies.get(self.cookie_name)
        return cookie is not None and request.path.startswith(self.base) and \
            hmac.compare_digest(cookie.encode(), self.cookie_value.encode())

    def host_ok(self, request) -> bool:
        """On a loopback address only loopback names: no DNS-rebound site's name."""
        if not self.loopback:
            return True
        host = request.host or ""
        name = host.rsplit(":", 1)[0] if not host.endswith("]") else host
        return name in LOOPBACK_NAMES

    def app(self):
        web = _aiohttp()

        def refuse(status: int, text: str):
            return web.Response(status=status, text=f"geoshade serve: {text}\n",
                                headers={**HEADERS, "Connection": "close"})

        @web.middleware
        async def guard(request, handler):
            if not self.host_ok(request):
                return refuse(403, "this server answers to 127.0.0.1 and localhost only")
            if not self.allowed(request):
                return refuse(403, "open the address with its token (printed when the server "
                                   "started)")
            origin = request.headers.get("Origin")
            if origin and urlsplit(origin).netloc != request.host:
                return refuse(403, "cross-site request")
            if self.gate is not None:
                self.gate.trust(request.protocol)
            response = await handler(request)
            if not response.prepared:   # a websocket's headers went with its handshake
                response.headers.update(HEADERS)
            return response

        app = web.Application(middlewares=[guard], client_max_size=MAX_MESSAGE)
        app.router.add_get("/", self.page)
        app.router.add_get(self.base, self.page)
        app.router.add_get(self.base + "static/{name}", self.static)
        app.router.add_get(self.base + "ws", self.websocket)
        app.router.add_get("/ws", self.websocket)   # scripts: /ws?token=...
        app.router.add_get("/favicon.ico", lambda request: web.Response(status=204))
        app.on_shutdown.append(self._shutdown)
        return app

    def _csp(self, request) -> str:
        host = request.host if _HOST.match(request.host or "") else ""
        ws = f" ws://{host} wss://{host}" if host else ""
        return ("default-src 'none'; script-src 'self'; style-src 'self'; "
                f"img-src 'self' blob: data:; connect-src 'self' blob:{ws}; "
                "frame-ancestors 'none'; base-uri 'self'; form-action 'none'")

    async def page(self, request):
        web = _aiohttp()
        text = resources.files("geoshade.web").joinpath("static/index.html").read_text()
        text = text.replace("<head>", f'<head>\n<base href="{self.base}">', 1)
        response = web.Response(text=text, content_type="text/html",
                                headers={"Content-Security-Policy": self._csp(request)})
        response.set_cookie(self.cookie_name, self.cookie_value, path=self.base,
                            httponly=True, samesite="Strict")
        return response

    async def static(self, request):
        web = _aiohttp()
        name = request.match_info["name"]
        kinds = {"app.css": "text/css", **{f"{n}.js": "application/javascript" for n in
                                            ("app", "address", "cuts", "panel", "workbench")}}
        if name not in kinds:  # a fixed list: no name from the browser reaches a path
            raise web.HTTPNotFound()
        text = resources.files("geoshade.web").joinpath(f"static/{name}").read_text()
        return web.Response(text=text, content_type=kinds[name])

    async def websocket(self, request):
        web = _aiohttp()
        if len(self.tabs) >= MAX_TABS:
            return web.Response(status=503, text=f"geoshade serve: {MAX_TABS} tabs are open; "
                                                 "close one first\n")
        # up to 4x the limit is read and refused in one line; beyond, aiohttp closes the socket
        ws = web.WebSocketResponse(max_msg_size=4 * MAX_MESSAGE, heartbeat=30)
        await ws.prepare(request)
        loop = asyncio.get_running_loop()
        out: asyncio.Queue = asyncio.Queue()
        overflow = asyncio.Event()

        def put(item) -> None:
            if out.qsize() >= MAX_OUT:
                overflow.set()   # the page does not read what it is sent: it is closed
            else:
                out.put_nowait(item)

        def send(msg: dict, data: bytes | None) -> None:
            loop.call_soon_threadsafe(put, (self.catalog.public(msg), data))

        def call_later(seconds: float, fn) -> None:
            loop.call_soon_threadsafe(loop.call_later, seconds, fn)

        tab = Tab(self.library, self.gl, self.pool, send, call_later, self.size,
                  camera=self.camera)
        self.tabs[tab] = ws
        sender = asyncio.create_task(self._sender(ws, out, overflow))
        limiter, errors = Bucket(), _Errors(send)
        try:
            files = await self._files()
            send({"type": "hello", "files": files, "limits": limits()}, None)
            async for m in ws:
                if m.type != web.WSMsgType.TEXT:
                    if m.type == web.WSMsgType.BINARY:
                        errors.line("message: expected JSON text, got binary data")
                    continue
                if not limiter.take():
                    errors.dropped(limiter.dropped)
                    continue
                try:
                    self.handle(tab, parse(m.data))
                except InputError as err:
                    errors.line(str(err))
                except Exception as err:   # a bug: one line to the page, the rest here
                    print_bug(err)
                    errors.line(f"{type(err).__name__}: {err}")
        finally:
            sender.cancel()
            self.tabs.pop(tab, None)
            with contextlib.suppress(Exception):
                await asyncio.wait_for(asyncio.wrap_future(tab.close()), STOP_S)
        return ws

    async def _files(self) -> list[str]:
        """The catalogue's names, listed on a worker thread at most once every
        :data:`LISTING_S` seconds (tabs opened in a loop do not walk the root each time)."""
        stamp, files = self._listing
        if time.monotonic() - stamp >= LISTING_S:
            files = await asyncio.get_running_loop().run_in_executor(self.pool,
                                                                     self.catalog.names)
            self._listing = (time.monotonic(), files)
        return files

    @staticmethod
    async def _sender(ws, out: asyncio.Queue, overflow: asyncio.Event) -> None:
        with contextlib.suppress(ConnectionError, asyncio.CancelledError, RuntimeError):
            while not overflow.is_set():
                msg, data = await out.get()
                if msg["type"] == "progress" and not out.empty():
                    continue   # a newer message waits: this progress is stale
                await ws.send_str(json.dumps(msg))
                if data is not None:
                    await ws.send_bytes(data)
            await ws.close(code=1008, message=b"the page does not read what it is sent")

    def handle(self, tab: Tab, m: dict) -> None:
        """One message of the browser, checked by :func:`geoshade.web.messages.parse`."""
        t = m["t"]
        if t == "ack":
            tab.ack()
        elif t == "pointer":
            tab.pointer(m["kind"], float(m["x"]), float(m["y"]), m.get("button", "left"))
        elif t == "wheel":
            tab.wheel(float(m["notches"]))
        elif t == "key":
            tab.key(m["key"])
        elif t == "resize":
            tab.resize(m["w"], m["h"])
        elif t == "set":
            tab.set(dict(m["values"]))
        elif t == "open":
            name = m["name"]
            self.catalog.check(name)  # refused here unless it is in the catalogue
            kind = None if self.catalog.demo_kind(name) else (m.get("as") or self.kind)
            tab.open(name, kind, m.get("state"))
        elif t == "unpick":
            tab.workbench("unpick", m["cell"])
        elif t == "history":
            tab.workbench("show_history", m["cell"], m["name"])
        elif t == "plot_size":
            tab.plot_size(m["w"], m["h"])
        elif t == "timeline":
            tab.timeline(m["x"], m["y"])
        elif t == "screenshot":
            tab.screenshot()
        elif t == "save_camera":
            tab.save_camera()
        elif t == "load_camera":
            tab.load_camera(m["text"])

    async def _shutdown(self, app) -> None:
        """Close every tab (its page told why), then the GL thread and the cluster, all at
        once, waited for at most :data:`STOP_S` seconds each step."""
        async def goodbye(ws) -> None:
            with contextlib.suppress(Exception):
                await ws.send_str(json.dumps({"type": "error", "text": "the server stopped"}))
                await ws.close(code=1001, message=b"server stopped")

        tabs = list(self.tabs.items())
        closing = [goodbye(ws) for _, ws in tabs] + \
            [asyncio.wrap_future(tab.close()) for tab, _ in tabs]
        if closing:
            await asyncio.wait([asyncio.ensure_future(c) for c in closing], timeout=STOP_S)
        self.pool.shutdown(wait=False, cancel_futures=True)
        stops = [asyncio.wrap_future(_daemon(f)) for f in (self.gl.stop, self.library.close)]
        await asyncio.wait(stops, timeout=STOP_S)   # on daemon threads: never held


def _daemon(fn) -> Future:
    """``fn()`` on a daemon thread of its own: a call that never returns keeps nothing."""
    fut: Future = Future()

    def run():
        try:
            fut.set_result(fn())
        except BaseException as err:
            fut.set_exception(err)

    threading.Thread(target=run, name="geoshade-stop", daemon=True).start()
    return fut


class _Errors:
    """Error lines to one page: at most :data:`ERRORS_PER_S` a second; the rest are counted
    and said in the next line."""

    def __init__(self, send):
        self.send = send
        self.bucket = Bucket(ERRORS_PER_S, int(2 * ERRORS_PER_S))
        self.reported = 0
        self.last_drop = 0.0

    def line(self, text: str) -> None:
        if self.bucket.take():
            more = self.bucket.dropped - self.reported
            self.reported = self.bucket.dropped
            suffix = f" (and {more:,} more errors not shown)" if more else ""
            self.send({"type": "error", "text": text + suffix}, None)

    def dropped(self, count: int) -> None:
        """Messages over the rate: said at most once a second."""
        now = time.monotonic()
        if now - self.last_drop >= 1.0:
            self.last_drop = now
            self.line(f"too many messages from this page: {count:,} dropped so far (at most "
                      f"{limits()['rate']:g} a second)")


def serve(paths=(), root=None, host: str = "127.0.0.1", port: int = 0, size=(800, 600),
          settings: dict | None = None, token: str | None = None, kind: str | None = None,
          out=None, hints: dict | None = None, camera: dict | None = None,
          demo: bool | str = False) -> None:
    """Serve ``paths`` (and the files under ``root``) to browsers until SIGINT or SIGTERM.

    Prints ``geoshade serve: http://HOST:PORT/?token=...`` once listening (``port=0``: a free
    port). Only ``host`` is listened on (default: this machine only).

    Parameters
    ----------
    paths : list of path
        Files or stores to show (each must exist).
    root : path, optional
        A folder whose files may be opened too.
    host, port : where to listen.
    size : (w, h) picture size before the page says its own.
    settings : dict
        Options every View is opened with (each file takes those of its part).
    token : str, optional
        Default: random.
    kind : {'core', 'grid', 'iso', 'stacks'}, optional
        The part every file is opened with (default: by what it is).
    out : file, optional
        Where the address is printed (default: standard output).
    hints : dict
        :func:`geoshade.load` hints for every file opened (``shape``, ``dtype`` ...).
    camera : dict
        ``{"view": name, "ortho": bool}``: where each tab's camera starts.
    demo : bool or str
        Also list the built-in synthetic data of every part (``demo/core`` ...; a part's
        name: that one first, and opened first).
    """
    _aiohttp()
    from geoshade.web.gate import Gate, GatedRunner, budget, raise_fd_limit

    raise_fd_limit()
    server = Server(Catalog(paths, root, demo), token=token, size=size, settings=settings,
                    kind=kind, hints=hints, camera=camera, host=host)
    out = out or sys.stdout

    async def main():
        loop = asyncio.get_running_loop()
        stop = asyncio.Event()
        for sig in (signal.SIGINT, signal.SIGTERM):
            loop.add_signal_handler(sig, _stopping, stop)
        server.gate = Gate(max_connections=budget())
        runner = GatedRunner(server.app(), server.gate, shutdown_timeout=2.0,
                             handle_signals=False, access_log=None)
        await runner.setup()
        web = _aiohttp()
        site = web.TCPSite(runner, host, port)
        try:
            await site.start()
        except OSError as err:
            await runner.cleanup()
            raise InputError(f"serve: cannot listen on {host}:{port} ({err.strerror})") from None
        bound = runner.addresses[0][1] if runner.addresses else port
        server.bound(bound)
        shown = f"[{host}]" if ":" in host else host
        print(f"geoshade serve: http://{shown}:{bound}/?token={server.token}", file=out,
              flush=True)
        try:
            await stop.wait()
        finally:
            with contextlib.suppress(Exception):
                await asyncio.wait_for(runner.cleanup(), 3 * STOP_S)

    try:
        asyncio.run(main())
    except KeyboardInterrupt:   # before the loop took the signals
        pass
    _leave()


def _stopping(stop: asyncio.Event) -> None:
    """SIGINT or SIGTERM: stop cleanly; a second one stops at once."""
    if stop.is_set():
        os._exit(130)
    print("geoshade serve: stopping", file=sys.stderr, flush=True)
    stop.set()


def _leave(wait_s: float = 2.0) -> None:
    """After a clean stop: a thread still held by the operating system (a read that never
    returns) must not keep the process: it exits without waiting for it."""
    t0 = time.monotonic()
    for t in threading.enumerate():
        if t is threading.main_thread() or t.daemon:
            continue
        t.join(max(0.0, wait_s - (time.monotonic() - t0)))
    if any(t.is_alive() and not t.daemon for t in threading.enumerate()
           if t is not threading.main_thread()):
        print("geoshade serve: stopped (a read still blocked was left behind)",
              file=sys.stderr, flush=True)
        sys.stdout.flush()
        os._exit(0)
