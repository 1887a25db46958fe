"""A grid tab's plots and tables beside its picture, as ResInsight shows them: the cells kept
from picks (every property of each at the shown report step, :func:`geoshade.grid.history.
cell_table`), one kept cell's property over every step (:func:`~geoshade.grid.history.
cell_history`, drawn by :func:`~geoshade.grid.history.history_plot` with a marker at the shown
step) and the case's summary vectors with one time cursor (:class:`geoshade.viewer.timeline.
Timeline`: moving the step moves the cursor; a click on the plot moves the step).

Everything here reads the model, never GL: tables and plots are made on the server's worker
threads and sent when done, and only while the tab still shows that View (a late one is
dropped). What the page sends is checked by :mod:`geoshade.web.messages` first; the state kept
is bounded (:data:`MAX_CELLS` cells, one history, one plot size).
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor
from typing import Any

import numpy as np

from geoshade.errors import InputError
from geoshade.grid.history import cell_history, cell_table, history_plot
from geoshade.styles.summary_plot import StepAt
from geoshade.viewer.controls import jsonable
from geoshade.viewer.picks import cell_label
from geoshade.viewer.timeline import Timeline

#: picked cells a tab keeps at most (the oldest goes first)
MAX_CELLS = 16
#: the plots' size until the page says its own (pixels)
PLOT_SIZE = (480, 260)


class Workbench:
    """The kept picks, the cell history and the summary plot of one tab.

    ``send(message, data)`` delivers to the page (any thread); ``pool`` runs the reads and
    plots; ``current()`` gives the View the tab shows now (None: none). Every method is called
    on the tab's GL thread (the View is not changed meanwhile); the work goes to the pool.
    """

    def __init__(self, send: Callable[[dict, bytes | None], None], pool: ThreadPoolExecutor,
                 current: Callable[[], Any], report: Callable[[Future], None],
                 encode: Callable[[np.ndarray], bytes]):
        self.send, self.pool, self.current = send, pool, current
        self.report, self.encode = report, encode
        self.cells: list[tuple[int, int, int]] = []
        #: (cell, property) of the history shown, and its values once read
        self.history: tuple[tuple[int, int, int], str] | None = None
        self._history_data: dict | None = None
        self.size = PLOT_SIZE
        self._lock = threading.Lock()
        self._shown: tuple | None = None   # (view id, step) the tables were last sent for
        #: the summary plot of the View shown (made on first use) and what it last showed
        self.timeline: Timeline | None = None
        self._summary: tuple | None = None

    # --- what the tab shows ------------------------------------------------------------------
    @staticmethod
    def applies(view) -> bool:
        """Whether ``view`` shows cells with properties (a grid's)."""
        return view is not None and view.kind == "grid" and hasattr(view.model, "properties")

    def reset(self) -> None:
        """Another file opened: nothing is kept."""
        self.cells.clear()
        self.history, self._history_data, self._shown = None, None, None
        with self._lock:
            if self.timeline is not None:
                self.timeline.close()
            self.timeline, self._summary = None, None

    @staticmethod
    def step(view) -> int | None:
        st = getattr(view.options, "step", None)
        return None if st is None else int(st)

    def _later(self, view, fn: Callable[[], tuple[dict, bytes | None] | None],
               wanted: Callable[[], bool] = lambda: True) -> None:
        """``fn()`` on the pool; its message sent while the tab still shows ``view`` and
        ``wanted()`` holds (a plot asked for since, or forgotten, is not sent late)."""
        def done(f: Future) -> None:
            if f.exception() is not None:
                self.report(f)
            elif f.result() is not None and self.current() is view and wanted():
                self.send(*f.result())

        self.pool.submit(fn).add_done_callback(done)

    # --- picks ---------------------------------------------------------------------------------
    def picked(self, pick) -> None:
        """A click picked ``pick`` (:class:`geoshade.render.pick.Pick`): a grid cell is kept
        (first in the list) and the tables sent."""
        view = self.current()
        if pick is None or pick.kind != "grid" or not self.applies(view):
            return
        ijk = tuple(int(v) for v in pick.index[:3])
        if ijk in self.cells:
            self.cells.remove(ijk)
        self.cells.insert(0, ijk)
        del self.cells[MAX_CELLS:]
        self.send_cells(view)

    def unpick(self, ijk) -> None:
        """Forget a kept cell (and its history plot)."""
        ijk = tuple(int(v) for v in ijk)
        if ijk not in self.cells:
            raise InputError(f"unpick: {cell_label(ijk)} is not among the kept cells")
        self.cells.remove(ijk)
        if self.history is not None and self.history[0] == ijk:
            self.history, self._history_data = None, None
            self.send({"type": "history", "cell": None}, None)
        view = self.current()
        if view is not None:
            self.send_cells(view)

    def send_cells(self, view) -> None:
        """Every kept cell's properties at the shown step (read on the pool)."""
        cells, step = list(self.cells), self.step(view)
        grid = view.model
        self._shown = (id(view), step)

        def run():
            out = []
            for ijk in cells:
                rows = [{k: jsonable(v) for k, v in r.items()}
                        for r in cell_table(grid, ijk, step)]
                out.append({"cell": list(ijk), "label": cell_label(ijk), "rows": rows})
            names = [r["name"] for r in (out[0]["rows"] if out else []) if r["step"] is not None]
            return {"type": "cells", "cells": out, "step": step, "history_names": names}, None

        self._later(view, run)

    # --- a cell's history ----------------------------------------------------------------------
    def show_history(self, ijk, name: str | None) -> None:
        """Plot property ``name`` of kept cell ``ijk`` over the steps (None: no plot)."""
        view = self.current()
        if ijk is None or not name:
            self.history, self._history_data = None, None
            self.send({"type": "history", "cell": None}, None)
            return
        ijk = tuple(int(v) for v in ijk)
        if ijk not in self.cells:
            raise InputError(f"history: {cell_label(ijk)} is not among the kept cells; pick "
                             "it first")
        if not self.applies(view) or not view.model.steps:
            raise InputError("history: this grid has no report steps")
        self.history, self._history_data = (ijk, str(name)), None
        self.send_history(view)

    def send_history(self, view) -> None:
        if self.history is None:
            return
        key = self.history
        (ijk, name), step, size = key, self.step(view), self.size
        grid, cached = view.model, self._history_data

        def run():
            h = cached if cached is not None else cell_history(grid, ijk, name)
            if self.history == key:   # (another cell or property asked for since: not kept)
                self._history_data = h
            png = self.encode(history_plot(h, size=size, cursor=step))
            return {"type": "history", "image": True, "cell": list(ijk),
                    "label": cell_label(ijk),
                    "name": h["name"], "unit": h["unit"], "step": step,
                    "dates": [str(d) for d in h["dates"]], "values": jsonable(h["values"]),
                    "width": size[0], "height": size[1]}, png

        self._later(view, run, lambda: self.history == key)

    # --- the summary plot ----------------------------------------------------------------------
    def send_summary(self, view) -> None:
        """The View's ``summary`` vectors with the cursor at the shown step, drawn on the pool
        when the vectors, the step or the size changed (no vector: the page hides the plot)."""
        vectors = tuple(getattr(view.options, "summary", None) or ())
        step, size = self.step(view), self.size
        key = (id(view), vectors, step, size)
        if key == self._summary:
            return
        self._summary = key
        if not vectors:
            self.send({"type": "summary"}, None)
            return
        if self.timeline is None or self.timeline.view is not view:
            self.timeline = Timeline(view)
        timeline = self.timeline

        def run():
            with self._lock:   # the curves are drawn once, then only the cursor moves
                img = timeline.image(size)
                layout = jsonable(timeline.layout)
            if img is None:
                return {"type": "summary"}, None
            return {"type": "summary", "image": True, "vectors": list(vectors), "step": step,
                    "layout": layout, "width": size[0], "height": size[1]}, self.encode(img)

        self._later(view, run, lambda: self._summary == key)

    def click(self, x: float, y: float) -> StepAt | None:
        """The report step a click at pixel ``(x, y)`` of the summary plot leads to (the
        nearest with restart data; None: outside the curves' axes, or no plot shown)."""
        with self._lock:
            if self.timeline is None or self.timeline.view is not self.current():
                return None
            return self.timeline.click(x, y)

    # --- the tab changed -----------------------------------------------------------------------
    def resize(self, w: int, h: int) -> None:
        """The page shows plots at ``w`` × ``h`` pixels: the shown ones are drawn again."""
        self.size = (int(w), int(h))
        view = self.current()
        if self.applies(view):
            self.send_history(view)
            self.send_summary(view)

    def refresh(self, view) -> None:
        """The options changed: a new step gives new tables and moves the cursors."""
        if not self.applies(view):
            return
        if self._shown != (id(view), self.step(view)):
            if self.cells:
                self.send_cells(view)
            self.send_history(view)
            self._shown = (id(view), self.step(view))
        self.send_summary(view)


__all__ = ["MAX_CELLS", "PLOT_SIZE", "Workbench"]
