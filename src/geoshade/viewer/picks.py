"""Picks kept as ResInsight keeps them (no GUI toolkit): every picked grid cell in a list, the
chosen one's properties at the shown report step as a table, and one report-step property of
that cell over every step as a plot with the shown step marked.

The desktop viewer (:mod:`geoshade.viewer.panels.picks`) and the notebook widget
(:meth:`GeoshadeWidget.workbench <geoshade.viewer.notebook.widget_class>`) show the same
:class:`Picks`; what a cell holds comes from :mod:`geoshade.grid.history` (only its values are
read), so nothing here re-implements the grid.

>>> from geoshade.compute.grid.synthetic import synthetic_grid
>>> from geoshade.viewer.views import open_view
>>> view = open_view(synthetic_grid(4, 3, 2), size=(64, 48), property="SWAT", step=1)
>>> picks = Picks(view)
>>> picks.add_cell((1, 2, 0)), picks.labels()
(True, ['I=2 J=3 K=1'])
>>> [r["name"] for r in picks.table()][:2], picks.caption()
(['PORO', 'PERMX'], 'cell I=2 J=3 K=1 at 2000-02-01')
>>> picks.history_name
'SWAT'
>>> view.release()
"""

from __future__ import annotations

import html
import math
from typing import Any

import numpy as np

from geoshade.errors import InputError
from geoshade.grid.history import cell_history, cell_table, history_plot
from geoshade.models.names import derived_names, grid_property, step_names
from geoshade.models.steps import step_name

#: picks kept at most (the oldest goes first)
MAX_PICKS = 32
#: the history plot's size in pixels
HISTORY_SIZE = (420, 250)


def cell_label(ijk) -> str:
    """``I=3 J=5 K=2``: a 0-based cell as ECLIPSE counts it (1-based).

    >>> cell_label((2, 4, 1))
    'I=3 J=5 K=2'
    """
    i, j, k = (int(v) for v in ijk)
    return f"I={i + 1} J={j + 1} K={k + 1}"


def value_text(value: Any) -> str:
    """A cell's value as the table shows it: six significant digits, whole numbers as they
    are, "no value" where the cell has none (inactive, undefined).

    >>> [value_text(v) for v in (0.123456789, 3, None, 2.5e7)]
    ['0.123457', '3', 'no value', '2.5e+07']
    """
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "no value"
    if isinstance(value, bool | int | np.integer):
        return str(int(value))
    return f"{float(value):.6g}"


class Picks:
    """The cells picked on a grid View, the chosen one (:attr:`current`) and the property
    whose history is plotted (:attr:`history_name`).

    Parameters
    ----------
    view : GridView
        The View the cells were picked on; its shown report step is the table's and the
        plot's cursor.
    """

    def __init__(self, view):
        self.view = view
        self.cells: list[tuple[int, int, int]] = []
        #: the index of the chosen pick (None: none)
        self.current: int | None = None
        self._history_name: str | None = None
        self._histories: dict[tuple, dict] = {}

    # --- what applies ---------------------------------------------------------------------------
    @property
    def applies(self) -> bool:
        """Whether the View is a grid (only a grid's picks are cells)."""
        return self.view.kind == "grid"

    @property
    def grid(self):
        return self.view.model

    def step(self) -> int | None:
        """The shown report step (None: the grid has none)."""
        if not self.grid.steps:
            return None
        s = self.view.options.step
        return len(self.grid.steps) - 1 if s is None else int(s)

    def history_names(self) -> list[str]:
        """The properties a cell has a history of: the report-step ones, then the derived ones
        (SOIL); empty without report steps."""
        if not self.applies or len(self.grid.steps) < 1:
            return []
        return [*step_names(self.grid), *derived_names(self.grid)]

    # --- the list -------------------------------------------------------------------------------
    def add(self, pick) -> bool:
        """Keep a :class:`~geoshade.render.pick.Pick` of a grid cell (another kind, or None,
        keeps nothing); it becomes the chosen one. True when kept."""
        if pick is None or pick.kind != "grid" or not self.applies:
            return False
        return self.add_cell(pick.index[:3])

    def add_cell(self, ijk) -> bool:
        """Keep cell ``ijk`` (0-based); picked again, it moves to the end of the list."""
        cell = tuple(int(v) for v in ijk)
        cell_table(self.grid, cell, self.step())   # outside the grid: one line, nothing kept
        if cell in self.cells:
            self.cells.remove(cell)
        self.cells.append(cell)
        del self.cells[:-MAX_PICKS]
        self.current = len(self.cells) - 1
        return True

    def remove(self, index: int | None = None) -> None:
        """Forget pick ``index`` (default: the chosen one)."""
        index = self.current if index is None else int(index)
        if index is None or not 0 <= index < len(self.cells):
            return
        del self.cells[index]
        self.current = min(index, len(self.cells) - 1) if self.cells else None

    def clear(self) -> None:
        self.cells.clear()
        self.current = None

    def choose(self, index: int) -> None:
        if not 0 <= int(index) < len(self.cells):
            raise InputError(f"pick: there are {len(self.cells)} picks; no pick {index}")
        self.current = int(index)

    def labels(self) -> list[str]:
        return [cell_label(c) for c in self.cells]

    def cell(self, index: int | None = None) -> tuple[int, int, int] | None:
        index = self.current if index is None else index
        return self.cells[index] if index is not None and 0 <= index < len(self.cells) \
            else None

    # --- the table ------------------------------------------------------------------------------
    def caption(self, index: int | None = None) -> str:
        """``cell I=3 J=5 K=2 at 2001-03-01`` (the step by its date, else its number)."""
        cell = self.cell(index)
        if cell is None:
            return "no cell picked: left-click the grid"
        k = self.step()
        if k is None:
            return f"cell {cell_label(cell)}"
        return f"cell {cell_label(cell)} at {step_name(k, self.grid.step_dates)}"

    def table(self, index: int | None = None) -> list[dict]:
        """Every property of the chosen cell at the shown step
        (:func:`~geoshade.grid.history.cell_table`); empty without a pick."""
        cell = self.cell(index)
        return [] if cell is None else cell_table(self.grid, cell, self.step())

    def rows(self, index: int | None = None) -> list[tuple[str, str, str]]:
        """The table as text: (property, value, unit) per row."""
        return [(r["name"], value_text(r["value"]), r.get("unit") or "")
                for r in self.table(index)]

    def html(self, index: int | None = None) -> str:
        """The table as an HTML table (the notebook shows it), its caption above."""
        cap = html.escape(self.caption(index))
        body = "".join(
            f"<tr><td>{html.escape(n)}</td><td style='text-align:right'>{html.escape(v)}</td>"
            f"<td>{html.escape(u)}</td></tr>" for n, v, u in self.rows(index))
        head = "<tr><th>property</th><th>value</th><th>unit</th></tr>" if body else ""
        return (f"<div><b>{cap}</b><table style='font-size:90%'>{head}{body}</table></div>")

    # --- the history ----------------------------------------------------------------------------
    @property
    def history_name(self) -> str | None:
        """The property whose history is plotted: the one chosen, else the shown property where
        it changes with the step, else the first report-step property."""
        names = self.history_names()
        if self._history_name in names:
            return self._history_name
        shown = grid_property(self.grid, self.view.options.property) \
            if isinstance(self.view.options.property, str) else None
        if shown in names:
            return shown
        return names[0] if names else None

    @history_name.setter
    def history_name(self, name: str) -> None:
        names = self.history_names()
        resolved = grid_property(self.grid, name) if name is not None else None
        if resolved not in names:
            raise InputError(f"history: {name} is not a report-step property of "
                             f"{self.grid.name or 'the grid'}; choose one of "
                             f"{', '.join(names) or '(none: no report steps)'}")
        self._history_name = resolved

    def history(self, index: int | None = None) -> dict | None:
        """The chosen cell's :attr:`history_name` over the steps (read once, then kept)."""
        cell, name = self.cell(index), self.history_name
        if cell is None or name is None:
            return None
        key = (cell, name)
        if key not in self._histories:
            self._histories[key] = cell_history(self.grid, cell, name)
        return self._histories[key]

    def history_image(self, size=HISTORY_SIZE, index: int | None = None) -> np.ndarray | None:
        """The history plot (:func:`~geoshade.grid.history.history_plot`), the shown step
        marked: (h, w, 4) uint8, None without a pick or report steps."""
        h = self.history(index)
        if h is None:
            return None
        return history_plot(h, size=(int(size[0]), int(size[1])), cursor=self.step())


__all__ = ["HISTORY_SIZE", "MAX_PICKS", "Picks", "cell_label", "value_text"]
