"""A plan before loading: what a file holds (from its header alone), what this machine has, and
the routes a picture can take, each with its memory.

Three pieces, used by every part (:mod:`geoshade.grid.plan`, :mod:`geoshade.core.plan`,
:mod:`geoshade.stacks.plan`; :func:`geoshade.api.plan` puts them together):

- :class:`Header`: what a file declares — cells, voxels or columns, dtype, active cells, a
  store's levels and coarse level — read by the ``header`` function of its row of
  :mod:`geoshade.io.formats` (:func:`read_header`), never its arrays;
- :class:`Machine`: the memory this process may hold (``MemAvailable`` and a cgroup limit, a
  ``--memory`` budget), its address-space limit (``ulimit -v``, ``RLIMIT_AS``) and the GPU's
  memory;
- :class:`Route` and :class:`Plan`: each way of drawing the picture (in memory, from a store, a
  store's coarse level, bricks, a cluster) with its peak resident memory (RSS), peak address
  space and GPU bytes; the plan takes the first route that is ready and fits, says so in one
  line, or refuses in one line with the figures and the route to take.

The figures are estimates of a whole ``render`` process (Python, the libraries, the software
renderer and the data), calibrated against measured peaks (docs/NOTES.md, "Memory plan"); the
parts say their tolerance.

>>> r = Route("memory", "in memory", ram=3 << 30, vm=4 << 30, gpu=None)
>>> p = Plan(Header("g.EGRID", "eclipse", "grid", (100, 100, 10)), Machine(2 << 30, "--memory"),
...          [r, Route("store", "from a store", ram=1 << 30, vm=2 << 30, gpu=None, ready=False,
...                    how="geoshade grid ingest g.EGRID -o g.zarr")])
>>> p.chosen is None
True
>>> print(p.refusal().replace("; ", ";\\n").replace(": drawing", ":\\ndrawing"))
g.EGRID (100×100×10 cells):
drawing it in memory needs ~3.0 GiB of memory, more than the 2.0 GiB --memory allows;
~1.0 GiB from a store: geoshade grid ingest g.EGRID -o g.zarr
"""

from __future__ import annotations

import inspect
import math
import os
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from geoshade.io import formats
from geoshade.io.paths import cgroup_free, status_bytes

try:
    import resource
except ImportError:  # pragma: no cover - not on Windows
    resource = None  # type: ignore[assignment]

GIB = 1 << 30
MIB = 1 << 20


# --------------------------------------------------------------------------------------------
# what a file declares
# --------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Header:
    """What a file declares about its data, read without its arrays.

    path:       str              the file or store
    format:     str              its row of :mod:`geoshade.io.formats`
    kind:       str              ``volume``, ``volume-store``, ``grid``, ``grid-store``,
                                 ``stacks`` or ``layers`` (a voxel model made into stacks)
    shape:      tuple of int     voxels or cells ``(nx, ny, nz)``; a stack model's columns
                                 ``(nx, ny)``
    dtype:      str              a volume's values (``uint8``), else ""
    file_bytes: int              bytes of the file (a store: of its arrays as stored, or 0)
    nactive:    int or None      a grid's active cells where cheap to count
    arrays:     int              cell arrays beside a grid's geometry (properties, step arrays)
    intervals:  int or None      a stack model's intervals
    levels:     tuple            a volume store's level shapes ``(nx, ny, nz)``, finest first
    faces:      int or None      a grid store's indexed visible faces
    coarse:     dict or None     a grid store's coarse level: ``factor``, ``dims``, ``faces``
    storage:    str              how the reader holds a volume: ``mapped`` (file pages: raw,
                                 .npy), ``lazy`` (read by blocks: stores, HDF5) or ``held``
    hints:      dict             the reading hints the header was read with (shape, dtype ...)
    notes:      tuple of str     what the header could not say (``active cells not counted``)
    """

    path: str
    format: str
    kind: str
    shape: tuple[int, ...]
    dtype: str = ""
    file_bytes: int = 0
    nactive: int | None = None
    arrays: int = 0
    intervals: int | None = None
    levels: tuple = ()
    faces: int | None = None
    coarse: dict | None = None
    storage: str = "held"
    hints: dict = field(default_factory=dict)
    notes: tuple[str, ...] = ()

    @property
    def count(self) -> int:
        """Cells, voxels or columns: the product of ``shape``."""
        return math.prod(int(n) for n in self.shape)

    @property
    def name(self) -> str:
        return Path(self.path).name

    @property
    def itemsize(self) -> int:
        """Bytes of one value of a volume (1 where no dtype is known)."""
        try:
            return np.dtype(self.dtype).itemsize if self.dtype else 1
        except TypeError:
            return 1

    def size_text(self) -> str:
        """``400×200×50 cells``, ``512×512×512 uint8 voxels``, ``2048×2048 columns``."""
        dims = "×".join(str(int(n)) for n in self.shape)
        if self.kind.startswith("grid"):
            return f"{dims} cells"
        if self.kind == "stacks":
            return f"{dims} columns" + (f", {self.intervals:,} intervals"
                                        if self.intervals is not None else "")
        return f"{dims} {self.dtype + ' ' if self.dtype else ''}voxels"

    def to_dict(self) -> dict:
        return {"path": self.path, "format": self.format, "kind": self.kind,
                "shape": list(self.shape), "dtype": self.dtype, "file_bytes": self.file_bytes,
                "nactive": self.nactive, "arrays": self.arrays, "intervals": self.intervals,
                "levels": [list(v) for v in self.levels], "faces": self.faces,
                "coarse": self.coarse, "storage": self.storage,
                "notes": list(self.notes)}


def read_header(path, **hints) -> Header | None:
    """The :class:`Header` of ``path`` from its row's ``header`` function, or None where the row
    has none (the plan then knows nothing before loading) or the name is no known kind.

    Hints the header function does not take are ignored; a header that cannot be read (damaged,
    a FIFO, a kind the function does not know) gives None: the reader then says what is wrong
    in its own line.

    Examples
    --------
    >>> import numpy as np, tempfile, os
    >>> f = os.path.join(tempfile.mkdtemp(), "v.npy")
    >>> np.save(f, np.zeros((4, 5, 6), np.uint16))
    >>> h = read_header(f)
    >>> h.kind, h.shape, h.dtype, h.storage
    ('volume', (6, 5, 4), 'uint16', 'mapped')
    """
    fmt = formats.find(path)
    if fmt is None or not fmt.header:
        return None
    fn = formats.resolve(fmt.header)
    names = inspect.signature(fn).parameters
    kw = {k: v for k, v in hints.items() if k in names and v is not None}
    try:
        h = fn(path, **kw)
        if h is not None and h.dtype:
            np.dtype(h.dtype)   # a type the metadata names but numpy has not: damaged
        return h
    except Exception:   # damaged, or a library that cannot read it: no plan; the reader then
        return None     # says what is wrong in its own line (its words, its missing extra)


# --------------------------------------------------------------------------------------------
# what this machine has
# --------------------------------------------------------------------------------------------
def address_space_limit() -> int | None:
    """The soft ``RLIMIT_AS`` (``ulimit -v``) in bytes, None when unlimited.

    >>> address_space_limit() is None or address_space_limit() > 0
    True
    """
    if resource is None:  # pragma: no cover
        return None
    try:
        soft = resource.getrlimit(resource.RLIMIT_AS)[0]
    except (AttributeError, OSError, ValueError):  # pragma: no cover
        return None
    return None if soft == resource.RLIM_INFINITY or soft < 0 else int(soft)


@dataclass(frozen=True)
class Machine:
    """The memory a picture may use here.

    ram:           int or None   bytes of resident memory this process may reach in all (what
                                 it holds now plus ``MemAvailable``, less under a cgroup limit
                                 or a ``--memory`` budget); None: unknown
    ram_source:    str           what bounds it (``MemAvailable``, ``cgroup memory.max``,
                                 ``--memory``)
    address_space: int or None   ``RLIMIT_AS`` (``ulimit -v``): the process's mappings in all
    gpu:           int or None   bytes of GPU memory (``--gpu-memory``, ``nvidia-smi``); None:
                                 unknown (a software renderer draws from ``ram``)
    gpu_source:    str
    """

    ram: int | None
    ram_source: str = ""
    address_space: int | None = None
    gpu: int | None = None
    gpu_source: str = ""

    @classmethod
    def here(cls, memory: int | None = None, gpu: int | None = None,
             gpu_source: str = "") -> Machine:
        """This process's figures now; ``memory`` (bytes) caps the resident memory.

        >>> Machine.here(memory=1 << 30).ram <= 1 << 30
        True
        """
        rss = status_bytes("VmRSS") or 0
        avail, source = status_bytes("MemAvailable", "/proc/meminfo"), "MemAvailable"
        cg = cgroup_free()
        if cg is not None and (avail is None or cg < avail):
            avail, source = cg, "cgroup memory.max"
        ram = None if avail is None else rss + avail
        if memory is not None and (ram is None or int(memory) < ram):
            ram, source = int(memory), "--memory"
        return cls(ram, source, address_space_limit(), gpu, gpu_source)

    def to_dict(self) -> dict:
        return {"ram": self.ram, "ram_source": self.ram_source,
                "address_space": self.address_space, "gpu": self.gpu,
                "gpu_source": self.gpu_source}


# --------------------------------------------------------------------------------------------
# routes and the plan
# --------------------------------------------------------------------------------------------
def size_text(n: float | None) -> str:
    """``1.3 GiB``, ``512 MiB`` (or ``?``).

    >>> size_text(1.3 * 2**30), size_text(5 * 2**20), size_text(None), size_text(3 * 2**50)
    ('1.3 GiB', '5 MiB', '?', '3.0 PiB')
    """
    if n is None:
        return "?"
    if n >= 1024 * GIB:
        for unit, scale in (("PiB", 2**50), ("TiB", 2**40)):
            if n >= scale or unit == "TiB":
                return f"{n / scale:,.1f} {unit}"
    return f"{n / GIB:.1f} GiB" if n >= GIB else f"{max(n, 0) / MIB:.0f} MiB"


@dataclass
class Route:
    """One way of drawing the picture, with its memory.

    name:    str             ``memory``, ``store``, ``coarse``, ``bricks``, ``level``,
                             ``cluster``
    title:   str             for lines: ``in memory``, ``from a store``
    ram:     int             peak resident bytes of the process (estimate)
    vm:      int             peak address space of the process (estimate)
    gpu:     int or None     bytes of its GPU objects (None: not estimated)
    ready:   bool            drawable from this input now; else ``how`` makes it so
    how:     str             the command or flags that take it (``geoshade grid ingest ...``)
    reduced: str             what the picture leaves out (``coarse level: cells merged 4×4×4``);
                             "" for the whole data at full resolution
    options: dict            options this route draws with (a bricks route's ``gpu_memory``)
    load:    callable        reads the model for this route; None: the command's own reader
    adapt:   callable        ``adapt(model) -> model`` after reading (a mapped file read by
                             blocks instead); None: the model as read
    gpu_binding: bool        False where the View keeps within the GPU's memory itself (the
                             core bricks a box beyond it): its GPU bytes are shown, not judged
    note:    str             how it draws (``bricks of up to 256³ within 512 MiB``)
    fits:    bool or None    set by :class:`Plan`
    why:     str             why it does not fit (set by :class:`Plan`)
    """

    name: str
    title: str
    ram: int
    vm: int
    gpu: int | None
    ready: bool = True
    how: str = ""
    reduced: str = ""
    options: dict = field(default_factory=dict)
    load: Callable[[], Any] | None = None
    adapt: Callable[[Any], Any] | None = None
    gpu_binding: bool = True
    note: str = ""
    fits: bool | None = None
    why: str = ""

    def figures(self) -> str:
        """``~1.3 GiB RAM, 12 MiB GPU``."""
        gpu = f", {size_text(self.gpu)} GPU" if self.gpu is not None else ""
        return f"~{size_text(self.ram)} RAM{gpu}"

    def to_dict(self) -> dict:
        return {"name": self.name, "title": self.title, "ram": int(self.ram),
                "address_space": int(self.vm), "gpu": self.gpu, "ready": self.ready,
                "how": self.how, "reduced": self.reduced, "note": self.note, "fits": self.fits,
                "why": self.why, "options": {k: v for k, v in self.options.items()}}


#: a route fits when its estimates and this share more fit: the spread of the estimates
#: against measured peaks (the parts' calibration tables: within 10 % but two runs at 21 %)
MARGIN = 1.1


def judge(route: Route, machine: Machine) -> Route:
    """``route`` with ``fits`` and ``why`` set for ``machine`` (None where nothing is known);
    it fits when its figures times :data:`MARGIN` do."""
    whys = []
    known = False
    if machine.ram is not None:
        known = True
        if route.ram * MARGIN > machine.ram:
            whys.append(f"~{size_text(route.ram)} of memory, more than the "
                        f"{size_text(machine.ram)} {_allows(machine.ram_source)}")
    if machine.address_space is not None:
        known = True
        if route.vm * MARGIN > machine.address_space:
            whys.append(f"~{size_text(route.vm)} of address space, more than the "
                        f"{size_text(machine.address_space)} ulimit -v (RLIMIT_AS) allows "
                        "(raise the limit)")
    if machine.gpu is not None and route.gpu is not None and route.gpu_binding:
        known = True
        if route.gpu * MARGIN > machine.gpu:
            whys.append(f"~{size_text(route.gpu)} of GPU memory, more than the "
                        f"{size_text(machine.gpu)} {_allows(machine.gpu_source)}")
    return replace(route, fits=(not whys) if known else None, why="; ".join(whys))


def _allows(source: str) -> str:
    if source.startswith("--"):
        return f"{source} allows"
    return f"available ({source})" if source else "available"


#: the order routes are preferred in when several are ready and fit: the whole data at full
#: resolution first (in memory before out of core), then what is reduced
PREFERENCE = ("memory", "store", "bricks", "cluster", "coarse", "level")


@dataclass
class Plan:
    """Every route for one picture of one file on this machine, and the one taken.

    ``chosen`` is the first route (in :data:`PREFERENCE` order) that is ready and fits (or
    whose fit is unknown); None when none does: :meth:`refusal` is the one line to say.
    ``forced``: a route the user asked for by name (taken if it fits, else refused);
    ``hint``: what else the user can do, said at the end of a refusal (``give a --box``).
    """

    header: Header
    machine: Machine
    routes: list[Route]
    forced: str | None = None
    hint: str = ""
    chosen: Route | None = field(init=False, default=None)

    def __post_init__(self):
        self.routes = [judge(r, self.machine) for r in self.routes]
        order = sorted(self.routes, key=lambda r: PREFERENCE.index(r.name)
                       if r.name in PREFERENCE else len(PREFERENCE))
        for r in order:
            if r.ready and r.fits is not False and (self.forced is None
                                                    or r.name == self.forced):
                self.chosen = r
                break

    def route(self, name: str) -> Route | None:
        return next((r for r in self.routes if r.name == name), None)

    @property
    def first(self) -> Route:
        """The route the data would take without a plan (the first listed: in memory)."""
        return self.routes[0]

    def line(self) -> str:
        """The plan in one line, said on stderr before the work.

        ``g.EGRID (4,000,000 cells): needs ~5.2 GiB in memory; ~1.3 GiB from a store: geoshade
        grid ingest ...; drawing from the store's coarse level (cells merged 4×4×4)``
        """
        first = self.first
        why = f" ({first.why})" if first.fits is False and first.why else ""
        parts = [f"{self.header.name} ({self.header.size_text()}): needs ~"
                 f"{size_text(first.ram)} {first.title}{why}"]
        for r in self.routes[1:]:
            if r is self.chosen or r.name == "cluster":
                continue
            parts.append(f"~{size_text(r.ram)} {r.title}" + (f": {r.how}" if r.how and
                                                              not r.ready else ""))
        head = "; ".join(parts)
        if self.chosen is None:
            return head + "; nothing fits"
        if self.chosen is first:
            return head + f"; drawing {first.title}"
        red = f" ({self.chosen.reduced})" if self.chosen.reduced else ""
        return head + f"; drawing {self.chosen.title}{red}, ~{size_text(self.chosen.ram)}"

    def refusal(self) -> str:
        """One line: what the picture needs, what is available, and the route to take (the
        routes that fit first; else every other route with its figure)."""
        first = self.first
        name = f"{self.header.name} ({self.header.size_text()})"
        if self.forced:
            r = self.route(self.forced)
            head = f"{name}: {self.forced}: " + (f"needs {r.why}" if r is not None and r.why
                                                 else "not ready (see geoshade info)")
        elif first.fits is False:
            what = first.title if first.title.startswith("the ") else "it " + first.title
            head = f"{name}: drawing {what} needs {first.why}"
        else:
            head = f"{name}: {first.title} is not possible here"
        others = [r for r in self.routes if r is not first and r.name != self.forced]
        fit = [r for r in others if r.fits is not False]
        hint = f"; {self.hint}" if self.hint else ""
        if fit or others:
            groups: dict[str, list[str]] = {}
            for r in fit or others:
                groups.setdefault(r.how, []).append(f"~{size_text(r.ram)} {r.title}")
            text = "; ".join(", ".join(v) + (f": {k}" if k else "") for k, v in groups.items())
            return head + ("; " if fit else "; no other route fits either: ") + text + hint
        return head + (f"; it is drawn {first.title} only: give it ~"
                       f"{size_text(first.ram * MARGIN)} (a larger --memory or ulimit -v, or a "
                       "machine with more memory)") + hint

    def stats(self) -> dict:
        """What the picture's stats JSON says of the plan: the route, what it reduced, its
        estimate and the machine's figures."""
        c = self.chosen
        return {"route": None if c is None else c.name,
                "title": None if c is None else c.title,
                "reduced": "" if c is None else c.reduced,
                "estimate": None if c is None else {"ram": int(c.ram), "address_space":
                                                    int(c.vm), "gpu": c.gpu},
                "machine": self.machine.to_dict()}

    def to_dict(self) -> dict:
        return {"header": self.header.to_dict(), "machine": self.machine.to_dict(),
                "routes": [r.to_dict() for r in self.routes],
                "chosen": None if self.chosen is None else self.chosen.name,
                "line": self.line()}

    def text(self) -> str:
        """The plan as ``geoshade info`` prints it: one row per route."""
        m = self.machine
        have = [f"memory {size_text(m.ram)} ({m.ram_source})" if m.ram is not None else
                "memory unknown"]
        if m.address_space is not None:
            have.append(f"ulimit -v {size_text(m.address_space)}")
        have.append(f"GPU {size_text(m.gpu)}" + (f" ({m.gpu_source})" if m.gpu_source else "")
                    if m.gpu is not None else "GPU unknown (a software renderer draws from "
                                              "memory)")
        lines = [f"plan     {self.header.size_text()}; here: {', '.join(have)}",
                 "  route                                  RAM  addr.space      GPU  fits",
                 ]
        for r in self.routes:
            fits = {True: "yes", False: "NO", None: "?"}[r.fits]
            mark = "*" if r is self.chosen else " "
            lines.append(f" {mark}{r.title[:36]:<36} {size_text(r.ram):>8} {size_text(r.vm):>10}"
                         f" {size_text(r.gpu) if r.gpu is not None else '-':>8}  {fits}")
            tail = [t for t in (r.reduced, r.how if not r.ready else "") if t]
            if tail:
                lines.append(f"    {'; '.join(tail)}")
        if self.header.notes:
            lines.append("  note     " + "; ".join(self.header.notes))
        return "\n".join(lines)


def cpu_count() -> int:
    """Cores this process may use (its affinity), at least 1."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):  # pragma: no cover
        return max(1, os.cpu_count() or 1)


__all__ = ["GIB", "MARGIN", "MIB", "PREFERENCE", "Header", "Machine", "Plan", "Route",
           "address_space_limit", "cpu_count", "judge", "read_header", "size_text"]
