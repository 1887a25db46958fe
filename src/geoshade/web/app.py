"""The web server of ``geoshade serve``: one page, its script, and one websocket per tab.

Safe by default: bound to 127.0.0.1, every request needs the random token printed at start (in
the URL, then in a same-site cookie), a websocket from another site's page is refused, and the
browser names files only from the :class:`~geoshade.web.catalog.Catalog`.

Messages from the browser (JSON): ``open`` (a catalogue name), ``pointer`` (down/move/up in
picture pixels), ``wheel``, ``key``, ``resize``, ``set`` (``{name: value}`` of a panel
control), ``ack`` (the last frame is shown), ``screenshot``, ``save_camera``,
``load_camera``. To the browser: JSON messages, each followed by one binary message where it
carries data (``frame``: JPEG or PNG; ``download``: a file).
"""

from __future__ import annotations

import asyncio
import contextlib
import hmac
import json
import secrets
import sys
from concurrent.futures import ThreadPoolExecutor
from importlib import resources
from urllib.parse import urlsplit

from geoshade.errors import InputError
from geoshade.web.catalog import Catalog
from geoshade.web.engine import GLThread, Library, Tab

#: the cookie that carries the token after the first request
COOKIE = "geoshade_token"
#: the largest message a browser may send (a camera file)
MAX_MESSAGE = 1 << 20


def _aiohttp():
    try:
        from aiohttp import web
    except ImportError as err:
        raise InputError(f"serve: needs the web extra ({err}); pip install 'geoshade[web]'"
                         ) from None
    return web


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
        ``distributed``, ``scheduler`` ...).
    kind : str, optional
        The part every file is opened with.
    hints : dict
        :func:`geoshade.load` hints for every file (``shape``, ``dtype``, ``skip_missing`` ...).
    camera : dict
        ``{"view": name, "ortho": bool}``: where each tab's camera starts.
    """

    def __init__(self, catalog: Catalog, token: str | None = None, size=(800, 600),
                 settings: dict | None = None, kind: str | None = None,
                 hints: dict | None = None, camera: dict | None = None):
        self.catalog = catalog
        self.token = token or secrets.token_urlsafe(24)
        self.size = size
        self.camera = dict(camera or {})
        self.library = Library(catalog, settings, hints)
        self.gl = GLThread()
        self.pool = ThreadPoolExecutor(2, thread_name_prefix="geoshade-cpu")
        self.tabs: set[Tab] = set()
        self.kind = kind

    # --- requests ------------------------------------------------------------------------------
    def allowed(self, request) -> bool:
        given = request.query.get("token") or request.cookies.get(COOKIE) or ""
        return hmac.compare_digest(given.encode(), self.token.encode())

    def app(self):
        web = _aiohttp()

        @web.middleware
        async def guard(request, handler):
            if not self.allowed(request):
                return web.Response(status=403, text="geoshade serve: open the address with "
                                    "its token (printed when the server started)\n")
            origin = request.headers.get("Origin")
            if origin and urlsplit(origin).netloc != request.host:
                return web.Response(status=403, text="geoshade serve: cross-site request\n")
            response = await handler(request)
            if request.query.get("token"):
                response.set_cookie(COOKIE, self.token, httponly=True, samesite="Strict")
            return response

        app = web.Application(middlewares=[guard])
        app.router.add_get("/", self.page)
        app.router.add_get("/static/{name}", self.static)
        app.router.add_get("/ws", self.websocket)
        app.router.add_get("/favicon.ico", lambda request: web.Response(status=204))
        app.on_shutdown.append(self._shutdown)
        return app

    async def page(self, request):
        web = _aiohttp()
        text = resources.files("geoshade.web").joinpath("static/index.html").read_text()
        return web.Response(text=text, content_type="text/html",
                            headers={"Cache-Control": "no-store"})

    async def static(self, request):
        web = _aiohttp()
        name = request.match_info["name"]
        kinds = {"app.js": "application/javascript", "app.css": "text/css"}
        if name not in kinds:  # a fixed list: no name from the browser reaches a path
            raise web.HTTPNotFound()
        text = resources.files("geoshade.web").joinpath(f"static/{name}").read_text()
        return web.Response(text=text, content_type=kinds[name])

    async def websocket(self, request):
        web = _aiohttp()
        ws = web.WebSocketResponse(max_msg_size=MAX_MESSAGE, heartbeat=30)
        await ws.prepare(request)
        loop = asyncio.get_running_loop()
        out: asyncio.Queue = asyncio.Queue()

        def send(msg: dict, data: bytes | None) -> None:
            loop.call_soon_threadsafe(out.put_nowait, (msg, data))

        def call_later(seconds: float, fn) -> None:
            loop.call_soon_threadsafe(loop.call_later, seconds, fn)

        tab = Tab(self.library, self.gl, self.pool, send, call_later, self.size,
                  camera=self.camera)
        self.tabs.add(tab)
        sender = asyncio.create_task(self._sender(ws, out))
        send({"type": "hello", "files": self.catalog.names()}, None)
        try:
            async for m in ws:
                if m.type != web.WSMsgType.TEXT:
                    continue
                try:
                    self.handle(tab, json.loads(m.data))
                except (InputError, ValueError, TypeError, KeyError) as err:
                    send({"type": "error", "text": str(err)}, None)
        finally:
            sender.cancel()
            self.tabs.discard(tab)
            await asyncio.wrap_future(tab.close())
        return ws

    @staticmethod
    async def _sender(ws, out: asyncio.Queue) -> None:
        with contextlib.suppress(ConnectionError, asyncio.CancelledError, RuntimeError):
            while True:
                msg, data = await out.get()
                if msg["type"] == "progress" and not out.empty():
                    continue   # a newer message waits: this progress is stale
                await ws.send_str(json.dumps(msg))
                if data is not None:
                    await ws.send_bytes(data)

    def handle(self, tab: Tab, m: dict) -> None:
        """One message of the browser."""
        t = m.get("t")
        if t == "ack":
            tab.ack()
        elif t == "pointer":
            tab.pointer(str(m["kind"]), float(m["x"]), float(m["y"]), str(m.get("button",
                                                                               "left")))
        elif t == "wheel":
            tab.wheel(float(m["notches"]))
        elif t == "key":
            tab.key(str(m["key"])[:16])
        elif t == "resize":
            tab.resize(int(m["w"]), int(m["h"]))
        elif t == "set":
            tab.set(dict(m["values"]))
        elif t == "open":
            name = str(m["name"])
            self.catalog.check(name)  # refused here unless it is in the catalogue
            kind = None if self.catalog.demo_kind(name) else (m.get("as") or self.kind)
            tab.open(name, None if kind is None else str(kind))
        elif t == "screenshot":
            tab.screenshot()
        elif t == "save_camera":
            tab.save_camera()
        elif t == "load_camera":
            tab.load_camera(str(m["text"]))
        else:
            raise ValueError(f"unknown message {t!r}")

    async def _shutdown(self, app) -> None:
        for tab in list(self.tabs):
            await asyncio.wrap_future(tab.close())
        self.pool.shutdown(wait=False, cancel_futures=True)
        self.gl.stop()


def serve(paths=(), root=None, host: str = "127.0.0.1", port: int = 0, size=(800, 600),
          settings: dict | None = None, token: str | None = None, kind: str | None = None,
          out=None, hints: dict | None = None, camera: dict | None = None,
          demo: bool | str = False) -> None:
    """Serve ``paths`` (and the files under ``root``) to browsers until interrupted.

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
    web = _aiohttp()
    server = Server(Catalog(paths, root, demo), token=token, size=size, settings=settings,
                    kind=kind, hints=hints, camera=camera)
    out = out or sys.stdout

    async def main():
        runner = web.AppRunner(server.app(), handle_signals=True)
        await runner.setup()
        site = web.TCPSite(runner, host, port)
        try:
            await site.start()
        except OSError as err:
            raise InputError(f"serve: cannot listen on {host}:{port} ({err.strerror})") from None
        bound = runner.addresses[0][1] if runner.addresses else port
        shown = f"[{host}]" if ":" in host else host
        print(f"geoshade serve: http://{shown}:{bound}/?token={server.token}", file=out,
              flush=True)
        try:
            await asyncio.Event().wait()
        finally:
            await runner.cleanup()

    with contextlib.suppress(KeyboardInterrupt):
        asyncio.run(main())
