"""Option fields more than one part takes, declared once and mixed into the parts' options.

- :class:`ExaggerationOptions` -- ``exaggeration`` (every part);
- :class:`ColorOptions` -- ``color`` (a :class:`~geoshade.styles.options.ColorStyle`; the
  shorthands ``colormap color_range log reverse solid_color nan_color categorical``);
- :class:`ClusterOptions` -- ``scheduler``, ``distributed``, ``worker_timeout`` (core, grid);
- :class:`ProgressiveOptions` -- ``progressive`` (core, grid);
- :class:`MemoryOptions` -- ``memory``, the RAM budget the memory plan and the drawing keep to
  (core, grid, stacks);
- :class:`SummaryOptions` -- ``summary``, the summary vectors drawn with a time cursor at the
  shown step (grid, iso);
- :data:`STEP`, :data:`PLANE`, :data:`CULL` -- the declarations of ``step``, ``plane`` and
  ``cull``, whose checks need the part's model.

>>> from geoshade.grid.options import GridOptions
>>> issubclass(GridOptions, ClusterOptions), GridOptions.declarations()["scheduler"][0].live
(True, False)
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

import numpy as np

from geoshade.errors import InputError
from geoshade.scheduler import Scheduler
from geoshade.styles.checks import check_exaggeration, check_number, checks, parse_bytes
from geoshade.styles.declare import option
from geoshade.styles.options import ColorStyle, ViewOptions

#: ``step`` of the parts with time steps (grid, iso)
STEP: dict[str, Any] = dict(
    help="report/time step: index (0-based), -1 for the last (the default), R36 for report 36, "
         "or a date YYYY-MM-DD", group="shown", metavar="K", control="step", example=0)
#: ``plane`` of the parts that cut with a plane (grid, stacks)
PLANE: dict[str, Any] = dict(
    help="cutting plane in the model's coordinates (x east, y north, z up): keep "
         "NX·x + NY·y + NZ·z >= D; without D through the model's centre (e.g. 1,0,0 "
         "keeps the eastern half; write --plane=-1,0,0 when the first number is "
         "negative)", group="cut", metavar="NX,NY,NZ[,D]", example="1,0,0")
#: ``cull`` of the rasterising parts (core, grid)
CULL: dict[str, Any] = dict(
    help="skip back faces and hidden voxels (--no-cull draws them too)", form="switch",
    group="method", example=False)


#: exaggerations :func:`auto_exaggeration` picks from
NICE_EXAGGERATIONS = (1, 2, 5, 10, 20, 50, 100, 200)
#: ``exaggeration`` of the parts whose models are maps (grid, stacks): ``auto`` by default
EXAGGERATION: dict[str, Any] = dict(
    help="vertical exaggeration: z multiplied by F (1 = true geometry; auto: a round factor "
         "making a flat model a fifth as tall as wide, said in the subtitle)", group="camera",
    metavar="F|auto", example=3.0, control="number", limits=(0.01, 1000))


def auto_exaggeration(bounds, ratio: float = 0.2) -> float:
    """A round vertical exaggeration that makes a flat model about ``ratio`` as tall as wide:
    the one rule of ``exaggeration="auto"`` in every front end.

    >>> auto_exaggeration([[0, 0, 0], [10000, 8000, 50]])
    20.0
    >>> auto_exaggeration([[0, 0, 0], [10, 10, 10]])
    1.0
    """
    b = np.asarray(bounds, float)
    width, height = float(max(b[1, 0] - b[0, 0], b[1, 1] - b[0, 1])), float(b[1, 2] - b[0, 2])
    if not (height > 0 and width > 0):
        return 1.0
    want = ratio * width / height
    return float(max([n for n in NICE_EXAGGERATIONS if n <= want], default=1))


@dataclass(frozen=True)
class ExaggerationOptions(ViewOptions):
    """exaggeration: vertical exaggeration (z multiplied), 1 = true geometry; ``auto`` (where a
    part declares it) is decided from the model's bounds by :func:`auto_exaggeration`"""

    exaggeration: Any = option(1.0, **EXAGGERATION)

    @staticmethod
    @checks("exaggeration")
    def check_exaggeration(value, model=None):
        if isinstance(value, str) and value.strip().lower() == "auto":
            return "auto"
        return check_exaggeration(value)

    def resolve_exaggeration(self, bounds):
        """These options with ``exaggeration="auto"`` decided for a model of ``bounds``."""
        if self.exaggeration != "auto":
            return self
        return dataclasses.replace(self, exaggeration=auto_exaggeration(bounds))


@dataclass(frozen=True)
class ColorOptions(ViewOptions):
    """color: how values become colours (:class:`ColorStyle`; shorthands ``colormap
    color_range log reverse solid_color nan_color categorical``)"""

    color: ColorStyle = option(factory=ColorStyle, flag=None, group="colour", control="",
                               help="the colour style (set through its shorthands)")


@dataclass(frozen=True)
class ClusterOptions(ViewOptions):
    """scheduler: where the View's dask work runs (:class:`~geoshade.scheduler.Scheduler`:
    threads here by default, ``local:N``, an address or a Client); distributed: draw on that
    cluster, composited by depth; worker_timeout: seconds a worker may take for one call"""

    scheduler: Any = option(
        None, live=False, group="cluster", metavar="ADDRESS", control="",
        help="where the dask work runs: threads here (the default), sync, processes, local:N "
             "(N local worker processes) or a running scheduler's address (tls://HOST:8786, "
             "tcp://HOST:8786). Trust: local:N uses TLS with throw-away certificates and no "
             "dashboard; a scheduler at an address can run code here, so prefer tls:// "
             "(certificates from dask's config distributed.comm.tls.*)")
    distributed: bool = option(
        False, live=False, form="switch", group="cluster", control="",
        help="draw on the --scheduler cluster: the parts stay on the workers' GPUs, each "
             "returns colour and depth of its part of the picture, composited by depth (the "
             "same picture as one process)")
    worker_timeout: float = option(
        300.0, live=False, group="cluster", metavar="S", control="",
        help="--distributed: seconds a worker may take for one call before it is taken as "
             "lost and its parts are redone elsewhere (300)")

    @staticmethod
    @checks("scheduler")
    def check_scheduler(value, model=None):
        return None if value is None else Scheduler.parse(value)

    @staticmethod
    @checks("worker_timeout")
    def check_worker_timeout(value, model=None):
        return check_number(value, "worker_timeout (seconds)", positive=True)


@dataclass(frozen=True)
class ProgressiveOptions(ViewOptions):
    """progressive: a picture at once, a coarse preview first, then the full picture"""

    progressive: bool = option(
        False, live=False, form="switch", group="cluster", control="",
        help="a picture at once: a coarse preview first (a store's overview level or a "
             "grid's coarse level; render writes it as OUT.coarse.png), then the full picture")


@dataclass(frozen=True)
class MemoryOptions(ViewOptions):
    """memory: the resident memory (RAM) the picture may use in all, in bytes (``"8G"``); the
    plan made before loading (:func:`geoshade.api.plan`) takes the first route that fits it
    (in memory, from a store, bricks, a coarse level) or refuses in one line, and the drawing
    keeps its caches within it"""

    memory: int | None = option(
        None, live=False, group="cluster", metavar="SIZE", control="", example="8G",
        help="the RAM the picture may use (8G, 512M, bytes; default: what this machine has "
             "available): the plan made before loading takes the first route that fits it (in "
             "memory, from a store, in bricks, a store's coarse level), says it on stderr and "
             "in the stats, or stops with one line giving the figures and the route to take")

    @staticmethod
    @checks("memory")
    def check_memory(value, model=None):
        return None if value is None else parse_bytes(value, "memory")


def summary_names(value, where: str = "summary") -> tuple[str, ...] | None:
    """``summary``'s vectors: names or wildcards, as a list or comma-separated text (None, "" or
    an empty list: none).

    >>> summary_names("FOPR, WBHP:*"), summary_names(["FPR"]), summary_names("")
    (('FOPR', 'WBHP:*'), ('FPR',), None)
    """
    if value is None:
        return None
    items = value.split(",") if isinstance(value, str) else value
    if not isinstance(items, list | tuple):
        raise InputError(f"{where}: expected vector names such as FOPR or WBHP:PROD, got "
                         f"{value!r}")
    names = []
    for it in items:
        for n in (it.split(",") if isinstance(it, str) else [it]):
            if not isinstance(n, str):
                raise InputError(f"{where}: expected vector names such as FOPR or WBHP:PROD, "
                                 f"got {n!r}")
            if n.strip() and n.strip() not in names:
                names.append(n.strip())
    return tuple(names) or None


@dataclass(frozen=True)
class SummaryOptions(ViewOptions):
    """summary: summary vectors of the case (``FOPR``, ``WBHP:PROD``, wildcards ``WOPR:*``)
    drawn against time with a cursor at the shown step: a strip under the picture of
    ``render`` and ``animate``, a plot beside the 3D view in the viewers (a click on it moves
    the step)"""

    summary: tuple[str, ...] | None = option(
        None, form="append", group="shown", metavar="VECTOR", control="vectors",
        help="a summary vector of the case (FOPR, WBHP:PROD, wildcards as 'WOPR:*'; repeat "
             "for several) drawn against time with a cursor at the shown step: a strip under "
             "the picture, a plot beside the viewers' 3D view")

    @staticmethod
    @checks("summary")
    def check_summary(value, model=None):
        return summary_names(value)


__all__ = [
    "CULL",
    "EXAGGERATION",
    "NICE_EXAGGERATIONS",
    "PLANE",
    "STEP",
    "ClusterOptions",
    "ColorOptions",
    "ExaggerationOptions",
    "MemoryOptions",
    "ProgressiveOptions",
    "SummaryOptions",
    "auto_exaggeration",
    "summary_names",
]
