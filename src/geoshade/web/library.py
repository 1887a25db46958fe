"""The data ``geoshade serve`` shares between its tabs: each file read once, one cluster.

- **Reads that cannot stall the server.** A file is read (and prepared:
  :func:`geoshade.viewer.views.prepare`) on a daemon thread of its own, after
  :meth:`~geoshade.web.catalog.Catalog.checked` refused what could block (a FIFO, a device, a
  store holding one). A second tab opening a file being read waits for that read and takes no
  thread. At most :data:`MAX_READS` reads run at once; one still running after
  :data:`SLOW_READ_S` seconds (a slow disk, a file that blocks) stops counting, so it never
  keeps other files from opening, and being a daemon thread it never keeps the server from
  stopping.
- **One cluster per server.** Where the settings name a cluster (``--scheduler local:2`` or an
  address), the server holds one :class:`~geoshade.scheduler.SchedulerSession`: it starts (or
  connects) on the first file that needs it, every tab's View uses its client, and
  :meth:`Library.close` closes it when the server stops (a View never closes a client it was
  given).
- **Bounded.** At most :data:`MAX_WAITING` reads wait to start, and the last :data:`MAX_KEPT`
  files read are kept for the next tab (a tab's View keeps the model it shows).

>>> import tempfile, pathlib, numpy as np
>>> from geoshade.web.catalog import Catalog
>>> d = pathlib.Path(tempfile.mkdtemp()); np.save(d / "v.npy", np.zeros((8, 8, 8), np.uint8))
>>> lib = Library(Catalog([d / "v.npy"]))
>>> lib.read("v.npy").result(60).cls.kind, lib.reads
('core', 1)
>>> lib.close()
"""

from __future__ import annotations

import threading
from collections import OrderedDict
from collections.abc import Callable
from concurrent.futures import Future

from geoshade.api import view_class, view_kind
from geoshade.errors import InputError
from geoshade.scheduler import Scheduler, SchedulerSession
from geoshade.viewer.views import Opening, load_model, prepare
from geoshade.web.catalog import Catalog

#: reads running at once (counted)
MAX_READS = 2
#: reads waiting to start at most (more: refused in one line)
MAX_WAITING = 16
#: prepared files kept for the next tab at most, the last used ones (a View keeps its own)
MAX_KEPT = 8
#: seconds after which a read still running stops counting against :data:`MAX_READS`
SLOW_READ_S = 10.0


class Library:
    """The models of the catalogue's files, read and prepared once and shared by every tab.

    Parameters
    ----------
    catalog : Catalog
    settings : dict
        Options every View is opened with (each part takes its own); a ``scheduler`` that is a
        cluster is started once, here, for every tab.
    hints : dict
        :func:`geoshade.load` hints for every file.
    """

    def __init__(self, catalog: Catalog, settings: dict | None = None,
                 hints: dict | None = None):
        self.catalog = catalog
        self.settings = dict(settings or {})
        self.hints = dict(hints or {})
        self._openings: OrderedDict[tuple[str, str | None], Opening] = OrderedDict()
        self._reading: dict[tuple[str, str | None], Future] = {}
        self._listeners: dict[tuple[str, str | None], list[Callable]] = {}
        self._waiting: list[tuple[str, str | None]] = []
        self._counted = 0
        self._lock = threading.Lock()
        scheduler = self.settings.get("scheduler")
        #: the server's cluster (None: dask's threads or a local scheduler name)
        self.work: SchedulerSession | None = None
        if scheduler is not None and Scheduler.parse(scheduler).is_cluster:
            self.work = SchedulerSession(scheduler)
        self._work_lock = threading.Lock()
        self._closed = False
        #: how many times a file was read (tabs opening a loaded file read nothing)
        self.reads = 0

    # --- reading -------------------------------------------------------------------------------
    def read(self, name: str, kind: str | None = None, progress=None) -> Future:
        """A future of the prepared model of ``name`` read as ``kind``: done at once when it
        was read before, the running read's when it is being read, else a new read (queued
        while :data:`MAX_READS` run). ``progress(done, total)`` hears that read's progress."""
        key = (name, kind)
        with self._lock:
            plain = self._openings.get((name, None))
            if kind is not None and plain is not None and plain.cls.kind == kind:
                key = (name, None)   # read as its own part already (a shared view names it)
            if key in self._openings:
                self._openings.move_to_end(key)
                done: Future = Future()
                done.set_result(self._openings[key])
                return done
            fut = self._reading.get(key)
            if fut is None and len(self._waiting) >= MAX_WAITING:
                raise InputError(f"open: {MAX_WAITING} files are waiting to be read; open "
                                 f"{name} once they are")
            if progress is not None:
                self._listeners.setdefault(key, []).append(progress)
            if fut is None:
                fut = self._reading[key] = Future()
                self._waiting.append(key)
                self._pump()
            return fut

    def opening(self, name: str, kind: str | None = None, progress=None) -> Opening:
        """:meth:`read`, waited for (any thread but the event loop's)."""
        return self.read(name, kind, progress).result()

    def _pump(self) -> None:
        """Start the waiting reads while fewer than :data:`MAX_READS` count (lock held)."""
        while self._waiting and self._counted < MAX_READS and not self._closed:
            key = self._waiting.pop(0)
            self._counted += 1
            counted = [True]
            timer = threading.Timer(SLOW_READ_S, self._uncount, (counted,))
            timer.daemon = True
            thread = threading.Thread(target=self._run, args=(key, counted, timer),
                                      name=f"geoshade-read {key[0][:40]}", daemon=True)
            timer.start()
            thread.start()

    def _uncount(self, counted: list) -> None:
        with self._lock:
            if counted[0]:
                counted[0] = False
                self._counted -= 1
                self._pump()

    def _run(self, key, counted: list, timer: threading.Timer) -> None:
        fut = self._reading[key]

        def progress(done, total):
            for listen in list(self._listeners.get(key, ())):
                listen(done, total)

        try:
            opening = self._prepare(key[0], key[1], progress)
        except BaseException as err:
            with self._lock:
                self._reading.pop(key, None)
                self._listeners.pop(key, None)
            fut.set_exception(err)
        else:
            with self._lock:
                self._openings[key] = opening
                while len(self._openings) > MAX_KEPT:   # the least recently used goes
                    self._openings.popitem(last=False)
                self._reading.pop(key, None)
                self._listeners.pop(key, None)
                self.reads += 1
            fut.set_result(opening)
        finally:
            timer.cancel()
            self._uncount(counted)

    def _prepare(self, name: str, kind: str | None, progress) -> Opening:
        demo = self.catalog.demo_kind(name)
        if demo is not None:   # the part's synthetic data with its demo options
            model, options = view_class(demo).demo()
            return prepare(model, demo, None, progress, **{**options,
                                                          **self.settings_for(demo)})
        path = self.catalog.checked(name)   # nothing that blocks is read
        model = load_model(str(path), kind, self.hints)
        return prepare(model, kind, None, progress,
                       **self.settings_for(view_kind(model, kind)))

    def settings_for(self, kind: str) -> dict:
        """The server's settings that part ``kind`` takes (``--select`` is the core's, ...);
        a cluster is the server's one client (started here on first use: a read thread)."""
        names = set(view_class(kind).Options.names())
        out = {k: v for k, v in self.settings.items() if k in names}
        if "scheduler" in out and self.work is not None:
            with self._work_lock:
                out["scheduler"] = self.work.client()
        return out

    def loaded(self) -> list[str]:
        return [n for n, _ in self._openings]

    def close(self) -> None:
        """Stop starting reads and close the server's cluster (if one was started here)."""
        with self._lock:
            self._closed = True
            self._waiting.clear()
        if self.work is not None:
            with self._work_lock:
                self.work.close()


__all__ = ["MAX_KEPT", "MAX_READS", "MAX_WAITING", "SLOW_READ_S", "Library"]
