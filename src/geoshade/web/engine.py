"""The server side of ``geoshade serve`` without any web framework: one GL thread, the shared
models, and one :class:`Tab` per open browser tab.

- **One GL thread** (:class:`GLThread`) owns the OpenGL context: every View is made, changed,
  drawn, picked and released there. The web server's event loop never waits for it.
- **Shared data** (:class:`~geoshade.web.library.Library`): a file is read (and prepared:
  :func:`geoshade.viewer.views.prepare`) once, on a read thread that cannot stall the server;
  every tab that opens it shares the model (and the server's one cluster) and makes only its own
  View (its GPU objects, camera and options).
- **Bounded work per tab**: a tab's panel changes are checked against its panel
  (:func:`geoshade.web.messages.check_set`) and merged while one waits for the GL thread, its
  picture size is merged likewise, and at most :data:`MAX_BACKLOG` of its calls wait for the GL
  thread (a camera move past that is dropped: the next one moves it anyway).
- **Frames are dropped, not queued**: a tab draws at most one frame at a time, and only after
  the browser said it received the last one; camera moves in between only change the camera,
  so the next frame shows the newest one. JPEG while the pointer moves, lossless PNG when it
  stops.
- **Long changes never block the stream**: :meth:`geoshade.render.view.View.jobs` splits a
  change into its CPU half (a worker thread, with progress sent to the browser) and its GL half
  (the GL thread); frames keep coming meanwhile.
"""

from __future__ import annotations

import io
import queue
import re
import sys
import threading
import time
import traceback
from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from PIL import Image

from geoshade.errors import InputError
from geoshade.io.layers.dem import MAX_DRAPE_SIDE
from geoshade.io.volumes.image import probe_image
from geoshade.render.camera import Camera
from geoshade.styles.saved_camera import SavedCamera
from geoshade.viewer.controls import controls, jsonable, settable, to_options
from geoshade.viewer.jobs import JobRunner
from geoshade.viewer.session import Session
from geoshade.viewer.values import control_values
from geoshade.viewer.views import Opening, make_view
from geoshade.web.address import WHERE, restore
from geoshade.web.library import Library
from geoshade.web.messages import MAX_SIDE, MIN_SIDE, check_set
from geoshade.web.plots import core_plots
from geoshade.web.workbench import Workbench

#: JPEG quality of the frames drawn while the camera moves
INTERACTIVE_QUALITY = 80
#: seconds without a camera move after which the lossless frame is drawn
STILL_AFTER_S = 0.25
#: calls of one tab waiting for the GL thread at most (camera moves past it are dropped)
MAX_BACKLOG = 32


#: control characters (but tab and newline) of a text written to the server's terminal
_CONTROL = re.compile(r"[\x00-\x08\x0b-\x1f\x7f-\x9f]")


def print_bug(err: BaseException) -> None:
    r"""A bug's traceback on the server's console, control characters escaped (a file name
    from ``--root`` must not retitle the terminal or write its clipboard).

    >>> import contextlib, io
    >>> buf = io.StringIO()
    >>> with contextlib.redirect_stderr(buf):
    ...     print_bug(ValueError("\x1b]0;owned\x07"))
    >>> buf.getvalue().splitlines()[-1]
    'ValueError: \\x1b]0;owned\\x07'
    """
    text = "".join(traceback.format_exception(err))
    sys.stderr.write(_CONTROL.sub(lambda m: f"\\x{ord(m.group()):02x}", text))
    sys.stderr.flush()


class GLThread:
    """A thread that runs every call given to :meth:`submit` in order; it owns its own GL
    context (:attr:`ctx`, made on this thread at the first call that needs it), so that no
    other thread's context is ever used here."""

    def __init__(self, name: str = "geoshade-gl"):
        self._q: queue.Queue = queue.Queue()
        self._ctx = None
        self._thread = threading.Thread(target=self._run, name=name, daemon=True)
        self._thread.start()

    def _run(self) -> None:
        while True:
            item = self._q.get()
            if item is None:
                return
            fut, fn, args = item
            if not fut.set_running_or_notify_cancel():
                continue
            try:
                fut.set_result(fn(*args))
            except BaseException as err:  # handed to whoever waits on the future
                fut.set_exception(err)

    @property
    def ctx(self):
        """The thread's headless context (call only on this thread)."""
        if threading.current_thread() is not self._thread:
            raise RuntimeError("the GL context belongs to the GL thread")
        if self._ctx is None:
            from geoshade.render.context import create_context

            self._ctx = create_context()
        return self._ctx

    def submit(self, fn: Callable, *args) -> Future:
        fut: Future = Future()
        self._q.put((fut, fn, args))
        return fut

    def stop(self) -> None:
        """Finish the calls given so far, release the context and end the thread."""
        def release():
            if self._ctx is not None:
                self._ctx.release()
                self._ctx = None

        self.submit(release)
        self._q.put(None)
        self._thread.join(timeout=10)


@dataclass
class Frame:
    """One encoded picture: ``data`` (JPEG or PNG bytes) and what the browser shows with it."""

    data: bytes
    mime: str
    still: bool
    width: int
    height: int
    seq: int
    readout: str = ""
    extra: dict = field(default_factory=dict)


def encode(img: np.ndarray, still: bool) -> tuple[bytes, str]:
    """RGBA ``img`` as lossless PNG (``still``) or JPEG."""

    buf = io.BytesIO()
    if still:
        Image.fromarray(np.ascontiguousarray(img), "RGBA").save(buf, "PNG", compress_level=1)
        return buf.getvalue(), "image/png"
    Image.fromarray(np.ascontiguousarray(img[..., :3]), "RGB").save(
        buf, "JPEG", quality=INTERACTIVE_QUALITY)
    return buf.getvalue(), "image/jpeg"


class Tab:
    """One browser tab: its View (on the GL thread), its camera (:class:`Session`), its frames.

    ``send(message: dict, data: bytes | None)`` delivers a message to the browser; it is called
    from any thread and must be thread-safe. ``call_later(seconds, fn)`` schedules ``fn`` on the
    server's loop.
    """

    def __init__(self, library: Library, gl: GLThread, pool: ThreadPoolExecutor,
                 send: Callable[[dict, bytes | None], None],
                 call_later: Callable[[float, Callable], Any], size=(800, 600),
                 camera: dict | None = None):
        self.library, self.gl, self.pool = library, gl, pool
        self.camera = dict(camera or {})
        self.send, self.call_later = send, call_later
        self.size = (int(size[0]), int(size[1]))
        self.session: Session | None = None
        self.name: str | None = None
        self.kind: str | None = None
        self.seq = 0
        self._lock = threading.Lock()
        self._in_flight = False   # a frame is being drawn or is on its way to the browser
        self._dirty = False       # the picture changed since the last frame was drawn
        self._interactive = False
        self._last_move = 0.0
        self._closed = False
        self._jobs: dict[str, Any] = {}   # key -> the newest job of it not yet applied
        #: the viewers' one job runner: GL halves posted to the GL thread
        self.jobs = JobRunner(post=lambda fn: self.on_gl(lambda s: fn()), state=self._progress,
                              name="geoshade-tab")
        #: option names the browser may change (the panel's), what the View opened with that
        #: a control turns on again (the drape image), the section [axis, fraction, flip]
        self.allowed: set[str] = set()
        self.opened: dict = {}
        self.section: list | None = None
        self.version = 0
        #: the panel the page shows (its controls check every change) and the settings it
        #: shows (a select may send back the value it shows)
        self.panel: list[dict] = []
        self.current: dict = {}
        self._opens = 0            # the newest open wins when reads finish out of order
        self._backlog = 0          # calls of this tab waiting for (or on) the GL thread
        self._changes: dict = {}   # panel changes not yet taken by the GL thread
        self._size: tuple[int, int] | None = None   # a picture size not yet taken
        self._shooting = False     # a screenshot is being made
        #: the camera of the address's view, set once its changes are applied
        self._camera_then: Camera | None = None
        #: the kept picks, a cell's history and the summary plot (a grid's)
        self.bench = Workbench(send, pool, lambda: self.session and self.session.view,
                               self._report, lambda img: encode(img, still=True)[0])

    # --- opening -------------------------------------------------------------------------------
    def open(self, name: str, kind: str | None = None, state: dict | None = None) -> None:
        """Open ``name`` (from the catalogue): read on a worker thread, the View made on the GL
        thread; replaces what the tab showed. ``state``: the view of the page's address
        (:mod:`geoshade.web.address`), applied once the View is made."""
        self.send({"type": "busy", "label": f"opening {name}"}, None)

        def progress(done, total):
            self.send({"type": "progress", "label": f"reading {name}", "done": int(done),
                       "total": int(total)}, None)

        self._opens += 1
        serial = self._opens
        fut = self.library.read(name, kind, progress)
        fut.add_done_callback(lambda f: self._opened(f, name, kind, serial, state))

    def _opened(self, fut: Future, name: str, kind, serial: int, state=None) -> None:
        if fut.exception() is not None:
            self._report(fut)
            return
        self.gl.submit(self._make, fut.result(), name, kind, serial, state).add_done_callback(
            self._report)

    def _make(self, opening: Opening, name: str, kind, serial: int = 0, state=None) -> None:
        if self._closed or serial < self._opens:   # closed, or another file asked for since
            return
        old = self.session
        view = make_view(opening, size=self.size, ctx=self.gl.ctx)
        self.session = Session(view, size=self.size, view_name=self.camera.get("view", "iso"),
                               ortho=bool(self.camera.get("ortho", False)))
        self.name, self.kind = name, view.kind
        if old is not None:
            old.view.release()
        catalog = self.library.catalog
        panel = controls(view, catalog.images() if view.kind == "stacks" else ())
        self.allowed = settable(panel)
        self.panel = panel
        # what the drape and wells check boxes turn on again; a drape picture by its name
        self.opened = {"drape": getattr(view.options, "drape", None),
                       "wells": getattr(view.options, "wells", None),
                       "resolve": self._drape_picture}
        self.section = None
        self._changes.clear()
        self._camera_then = None
        self.bench.reset()
        self.current = self._settings()
        self.send({"type": "opened", "name": name, "kind": view.kind, "panel": panel,
                   "settings": self.current, "values": self._values(),
                   "reads": self.library.reads}, None)
        self._plots(self.session)
        if getattr(view, "loading", False):   # a coarse preview now, the full picture next
            self._start(view.refine_job())
            self.send(self._settings_message(), None)
        if state is not None:
            self._restore(self.session, state)
        self.request(still=True)

    def _restore(self, s: Session, state: dict) -> None:
        """The view of the page's address: its options changed as the panel changes them,
        then its camera; refused in one line (naming the field), the file shown as it opens."""
        try:
            r = restore(state, s.view, self.panel, self.opened, self.library.catalog.public)
            jobs = s.view.jobs(**r.changes) if r.changes else []
        except InputError as err:
            text = str(err) if str(err).startswith(WHERE) else f"{WHERE}: {err}"
            self.send({"type": "error", "text": f"{text} (shown as it opens instead)"}, None)
            return
        if r.spec is not None:   # a named view and angles: framed from there
            s.view_name, s.ortho, s.framed_zoom = r.spec.view, r.spec.ortho, r.spec.zoom
            s.camera = s.view.camera(r.spec.view, azimuth=r.spec.azimuth,
                                     elevation=r.spec.elevation, zoom=r.spec.zoom,
                                     ortho=r.spec.ortho)
            s.framed = True
        elif {"exaggeration", "box"} & set(r.changes):
            s.reframe()
        for job in jobs:
            self._start(job)
        if r.camera is not None:   # the turned camera, once the long changes are applied
            if self._jobs:
                self._camera_then = r.camera
            else:
                s.camera = r.camera
        self.send(self._settings_message(), None)
        self._plots(s)

    def _start(self, job) -> None:
        """Run a long change on the viewers' one job runner: its CPU half on a worker (its
        progress to the page), its GL half on the GL thread after; a newer job of the same key
        supersedes it."""
        self._jobs[job.key] = job
        self.jobs.submit(job, then=lambda: self._applied(job),
                         error=lambda err: self._failed(job, err))

    def _progress(self, label: str, done: int, total: int) -> None:
        if label:
            self.send({"type": "progress", "label": label, "done": int(done),
                       "total": int(total)}, None)

    def _failed(self, job, err: BaseException) -> None:
        if self._jobs.get(job.key) is job:
            del self._jobs[job.key]
        self._camera_then = None
        f: Future = Future()
        f.set_exception(err)
        self._report(f)

    def _applied(self, job) -> None:
        s = self.session
        if self._jobs.get(job.key) is job:
            del self._jobs[job.key]
        if s is None:
            return
        if "box" in job.applies or "exaggeration" in job.applies:
            s.reframe()
        if self._camera_then is not None and not self._jobs:
            s.camera, self._camera_then = self._camera_then, None
        self.send(self._settings_message(), None)
        self._plots(s)
        self.request(still=True)

    def _report(self, fut: Future) -> None:
        err = fut.exception()
        if err is None:
            return
        if isinstance(err, InputError):
            self.send({"type": "error", "text": str(err)}, None)
        else:  # a bug: one line to the browser, the traceback on the server's console

            print_bug(err)
            self.send({"type": "error", "text": f"{type(err).__name__}: {err}"}, None)

    def _settings_message(self) -> dict:
        """The options now and the long changes still running (the page's progress bar), with
        the count of changes applied (``version``, GL thread): every frame drawn after it
        carries that count, so a page knows which frame shows these settings."""
        self.version += 1
        self.current = self._settings()
        return {"type": "settings", "settings": self.current, "values": self._values(),
                "version": self.version, "busy": [j.label for j in self._jobs.values()]}

    def _values(self) -> dict:
        """What each control of the panel shows (:func:`geoshade.viewer.values.
        control_values`): the page sets the I/J/K, range and vector controls from these."""
        s = self.session
        if s is None:
            return {}
        return jsonable(control_values(self.panel, s.view.settings(), self.section))

    def _settings(self) -> dict:

        s = self.session
        if s is None:
            return {}
        settings = s.view.settings()
        out = {k: jsonable(v) for k, v in settings.items()}
        sl = settings.get("slice")
        if isinstance(sl, tuple) and all(isinstance(x, slice) for x in sl):
            out["slice"] = ",".join(f"{ax}={x.start}:{x.stop}"
                                    for ax, x in zip("ijk", sl, strict=False))
        out["view"], out["ortho"] = s.view_name, s.ortho
        o = s.view.options
        if "box" in settings and hasattr(settings["box"], "offset"):
            out["box"] = [*settings["box"].offset, *settings["box"].size]
        if "roi" in settings:
            out["roi"] = None if o.roi is None else o.roi.text()
        if "occlusion" in settings:
            out["occlusion"] = None if o.occlusion is None else bool(o.occlusion)
        if "drape" in settings:
            out["drape"] = settings["drape"] is not None   # on or off: the path stays on the server
        if "plane" in settings:
            out["plane"] = self.section if o.plane is not None else None
        if s.exaggeration is not None:
            out["exaggeration"] = s.exaggeration
        return out

    # --- input ---------------------------------------------------------------------------------
    def on_gl(self, fn: Callable, *args) -> Future:
        """Run ``fn(session, *args)`` on the GL thread (errors go to the browser)."""
        def run():
            try:
                if self.session is None or self._closed:
                    return None
                return fn(self.session, *args)
            finally:
                with self._lock:
                    self._backlog -= 1

        with self._lock:
            self._backlog += 1
        fut = self.gl.submit(run)
        fut.add_done_callback(self._report)
        return fut

    def full(self) -> bool:
        """True while :data:`MAX_BACKLOG` calls of this tab wait for the GL thread."""
        return self._backlog >= MAX_BACKLOG

    def _need_open(self, what: str) -> None:
        if self.session is None:
            raise InputError(f"{what}: no file is open in this tab yet")

    def pointer(self, kind: str, x: float, y: float, button: str = "left") -> None:
        """A pointer event in picture pixels (``down move up``); a move is dropped while the
        tab's backlog is full (the next one moves the camera anyway)."""
        if kind == "move" and self.full():
            return

        def run(s: Session):
            if kind == "down":
                self._camera_then = None   # the user moves it now
                s.press(x, y, button)
            elif kind == "move":
                if s.move(x, y):
                    self._moved()
            elif kind == "up":
                what = s.release(x, y)
                if what == "click":
                    p = s.picked
                    self.send({"type": "pick", "text": s.pick_text,
                               "pick": None if p is None else _plain(p.as_dict())}, None)
                    self.bench.picked(p)
                self.request(still=True)

        self.on_gl(run)

    def wheel(self, notches: float) -> None:
        if not self.full():
            self.on_gl(lambda s: (setattr(self, "_camera_then", None), s.zoom(notches),
                                  self._moved()))

    def key(self, key: str) -> None:
        if self.full():
            return

        def run(s: Session):
            self._camera_then = None
            action = s.key(key)
            if action not in (None, "help", "screenshot"):
                self.send(self._settings_message(), None)
                self.request(still=True)

        self.on_gl(run)

    def resize(self, w: int, h: int) -> None:
        """The picture's size (each side clamped to :data:`~geoshade.web.messages.MIN_SIDE`..
        :data:`~geoshade.web.messages.MAX_SIDE`); sizes asked for while one waits for the GL
        thread are merged: the last one is drawn."""
        size = (min(MAX_SIDE, max(MIN_SIDE, int(w))), min(MAX_SIDE, max(MIN_SIDE, int(h))))
        with self._lock:
            waiting = self._size is not None
            self._size = size
        if waiting:
            return

        def run(s: Session):
            with self._lock:
                size, self._size = self._size, None
            if size is None:
                return
            self.size = size
            s.resize(*size)   # framed again for the size unless the user moved it
            self.request(still=True)

        def before_open(f: Future) -> None:   # no View yet: the size it will open with
            with self._lock:
                if self._size is not None and self.session is None:
                    self.size, self._size = self._size, None

        self.on_gl(run).add_done_callback(before_open)

    def workbench(self, method: str, *args) -> None:
        """A request of the page's tables and plots (``unpick``, ``show_history``,
        :class:`~geoshade.web.workbench.Workbench`), carried out on the GL thread."""
        self._need_open(method.replace("_", " "))
        if not self.full():
            self.on_gl(lambda s: getattr(self.bench, method)(*args))

    def timeline(self, x: float, y: float) -> None:
        """A click at pixel ``(x, y)`` of the summary plot: the step moves to the nearest
        report step with restart data, and a line says which."""
        self._need_open("timeline")
        if self.full():
            return

        def run(s: Session):
            at = self.bench.click(x, y)
            if at is None:
                self.send({"type": "note", "text": "the summary plot: click between its axes "
                           "to go to that date"}, None)
                return
            self.send({"type": "note", "text": at.text}, None)
            if at.index != self.bench.step(s.view):
                self.set({"step": at.index})

        self.on_gl(run)

    def plot_size(self, w: int, h: int) -> None:
        """The size the page shows its plots at (checked by :mod:`geoshade.web.messages`)."""
        if self.session is None:
            self.bench.size = (int(w), int(h))
        elif not self.full():
            self.on_gl(lambda s: self.bench.resize(w, h))

    def _moved(self) -> None:
        """The camera moved: a quick frame now, the lossless one once it rests."""
        self._last_move = time.monotonic()
        self.request(still=False)
        self.call_later(STILL_AFTER_S + 0.02, self._maybe_still)

    def _maybe_still(self) -> None:
        if time.monotonic() - self._last_move >= STILL_AFTER_S:
            self.request(still=True)

    # --- options -------------------------------------------------------------------------------
    def set(self, changes: dict) -> None:
        """Change options by name (the View's :meth:`~geoshade.render.view.View.jobs`): quick
        ones now, long ones on a worker thread with progress, each GL half on the GL thread.

        Checked here first against the tab's panel (:func:`geoshade.web.messages.check_set`);
        changes that arrive while one waits for the GL thread are merged into it."""
        self._need_open("set")
        changes = check_set(changes, self.panel, self.current, self.kind or "")
        with self._lock:
            waiting = bool(self._changes)
            self._changes.update(changes)
        if waiting:
            return

        def run(s: Session):
            with self._lock:
                changes, self._changes = self._changes, {}
            if not changes:
                return
            camera = {k: changes.pop(k) for k in ("view", "ortho", "exaggeration")
                      if k in changes}
            if "view" in camera:
                s.reset(str(camera["view"]))
            if "ortho" in camera:
                s.set_ortho(bool(camera["ortho"]))
            if "exaggeration" in camera:
                s.set_exaggeration(float(camera["exaggeration"]))

            given: dict = {}
            for k, v in changes.items():
                if k not in self.allowed:   # only what the panel shows: never a file option
                    raise InputError(f"set: {k!r} is not a control of this {s.view.kind}'s "
                                     "panel")
                try:   # (a drape picture too big): its line, the other changes go on
                    given.update(to_options(k, v, s.view, self.opened))
                except InputError as err:
                    self.send({"type": "error", "text": str(err)}, None)
            jobs = s.view.jobs(**given) if given else []
            if "plane" in given:
                self.section = changes["plane"]
            if "box" in given:
                s.reframe()
            for job in jobs:
                self._start(job)
            self.send(self._settings_message(), None)
            self._plots(s)
            self.request(still=True)

        self.on_gl(run)

    def _drape_picture(self, name: str):
        """The file of a drape picture the page chose by name: one the catalogue shows, that
        cannot block (:meth:`~geoshade.web.catalog.Catalog.checked`), at most
        :data:`~geoshade.io.layers.dem.MAX_DRAPE_SIDE` pixels a side (read from its header:
        a bigger one is refused before any pixel is read)."""
        path = self.library.catalog.checked(name)
        w, h = probe_image(path)
        if max(w, h) > MAX_DRAPE_SIDE:
            raise InputError(f"drape: {name} is {w}×{h} pixels; the browser drapes pictures of "
                             f"at most {MAX_DRAPE_SIDE}×{MAX_DRAPE_SIDE} (make a smaller copy, "
                             "or give it to serve with --drape)")
        return path

    def _plots(self, s: Session) -> None:
        """A core's histogram and porosity plot (SVG), made on a worker thread and sent; a
        grid's kept picks and plots follow the step (:class:`~geoshade.web.workbench.
        Workbench`)."""
        self.bench.refresh(s.view)
        if s.view.kind != "core":
            return
        view = s.view

        def done(f: Future) -> None:
            if f.exception() is None and not self._closed and self.session is not None \
                    and self.session.view is view:
                self.send({"type": "plots", **f.result()}, None)
            else:
                self._report(f)

        self.pool.submit(core_plots, view).add_done_callback(done)

    # --- frames --------------------------------------------------------------------------------
    def request(self, still: bool) -> None:
        """Ask for a frame (any thread); drawn at once unless one is on its way, then after."""
        with self._lock:
            self._dirty = True
            self._interactive = not still
            if self._in_flight or self._closed:
                return
            self._in_flight = True
        self.gl.submit(self._draw).add_done_callback(self._report)

    def ack(self) -> None:
        """The browser shows the last frame: draw the next one if the picture changed."""
        with self._lock:
            self._in_flight = False
            if not self._dirty or self._closed:
                return
            self._in_flight = True
        self.gl.submit(self._draw).add_done_callback(self._report)

    def _draw(self) -> None:
        s = self.session
        with self._lock:
            interactive = self._interactive
            self._dirty = False
        if s is None or self._closed:
            with self._lock:
                self._in_flight = False
            return
        before = s.pick_text
        try:
            img, _stats = s.draw(interactive=interactive)
        except BaseException:
            with self._lock:
                self._in_flight = False
            raise
        if s.pick_text != before:   # the pick followed an options change: its line too
            p = s.picked
            self.send({"type": "pick", "text": s.pick_text,
                       "pick": None if p is None else _plain(p.as_dict())}, None)
        data, mime = encode(img, still=not interactive)
        self.seq += 1
        meta = {"type": "frame", "mime": mime, "still": not interactive,
                "width": int(img.shape[1]), "height": int(img.shape[0]), "seq": self.seq,
                "readout": s.readout(), "version": self.version}
        if not interactive:  # what drew it, exactly (Camera.from_saved reads it back), and
            # what reopens it (the page's address: geoshade.web.address)
            meta["camera"] = s.camera.saved().as_dict()
            meta["state"] = s.view.state(s.camera)
        self.send(meta, data)

    # --- the rest ------------------------------------------------------------------------------
    def screenshot(self) -> None:
        """Send the current picture as a PNG file to the browser (drawn on the GL thread; one
        at a time: another asked for meanwhile is refused in one line)."""
        self._need_open("screenshot")
        with self._lock:
            if self._shooting:
                raise InputError("screenshot: the last one is still being made")
            self._shooting = True

        def run(s: Session):
            try:
                if s.image is None:
                    s.draw()
                name = f"geoshade-{s.view.kind}-{time.strftime('%Y%m%d-%H%M%S')}.png"
                self.send({"type": "download", "name": name, "mime": "image/png"},
                          encode(s.image, still=True)[0])
            finally:
                self._shooting = False

        self.on_gl(run).add_done_callback(lambda f: setattr(self, "_shooting", False))

    def save_camera(self) -> None:
        """Send the camera as a JSON file (what ``--camera FILE`` and ``Camera.load`` read)."""
        self._need_open("save camera")
        if self.full():
            return

        def run(s: Session):
            self.send({"type": "download", "name": "camera.json", "mime": "application/json"},
                      s.camera.saved().to_json().encode())

        self.on_gl(run)

    def load_camera(self, text: str) -> None:
        self._need_open("load camera")
        saved = SavedCamera.from_json(text, where="camera file")

        def run(s: Session):
            self._camera_then = None
            s.camera = Camera.from_saved(saved)
            self.request(still=True)

        self.on_gl(run)

    def close(self) -> Future:
        """The tab closed: its View's GPU objects are released (on the GL thread)."""
        self._closed = True
        self.jobs.shutdown(wait=False)

        def run():
            if self.session is not None:
                self.session.view.release()

        return self.gl.submit(run)


def _plain(d: dict) -> dict:

    return {k: jsonable(v) for k, v in d.items()}
