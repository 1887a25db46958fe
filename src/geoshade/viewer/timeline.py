"""The summary plot beside a viewer's 3D view: one time cursor for the picture and the curves.

A :class:`Timeline` belongs to one open View of a case with summary files (SMSPEC and UNSMRY
beside its grid or restart file). It draws the vectors of the View's ``summary`` option against
time (:class:`~geoshade.styles.summary_plot.SummaryPlot`: dates on x, SMSPEC's units on the y
axes, a legend) with the cursor at the date of the shown report step, and turns a click on the
plot into the nearest report step with restart data (:func:`~geoshade.styles.summary_plot.
step_at`), said in one line. The Qt window, the notebook and the browser each show its picture
and send it their clicks; none of them draws curves of its own.

The curves are drawn once per choice of vectors and size; moving the cursor (a new step)
redraws only the cursor (a few ms).

>>> import geoshade
>>> from geoshade.compute.grid.synthetic import synthetic_grid
>>> with geoshade.view(synthetic_grid(4, 3, 2), size=(32, 24)) as v:
...     Timeline(v).available
False
"""

from __future__ import annotations

from typing import Any

import numpy as np

from geoshade.errors import InputError
from geoshade.io.grids.summary import case_spec, read_summary
from geoshade.models.steps import dated_steps
from geoshade.styles.summary_plot import StepAt, SummaryPlot, step_at


def _dates_of(view) -> list[str]:
    return dated_steps(view.model)[0]


def _reports_of(view) -> list[int] | None:
    return dated_steps(view.model)[1]


class Timeline:
    """The summary plot of ``view`` (see the module).

    Attributes
    ----------
    available : bool
        The case has summary files and its report steps have dates (the cursor follows dates).
    layout : dict
        The last picture's layout (:attr:`SummaryPlot.layout`): axes, ``cursor`` (``date``,
        ``report``, ``report_date``, pixels) -- empty before the first picture.
    """

    def __init__(self, view):
        self.view = view
        self.layout: dict[str, Any] = {}
        self._plot: SummaryPlot | None = None
        self._key: tuple | None = None
        self._why: str | None = None
        try:
            self.keys = tuple(case_spec(view.model).keys)
        except InputError as err:
            self.keys, self._why = (), str(err)
        dates = _dates_of(view)
        if self.keys and not any(dates):
            self._why = "summary: the report steps have no dates; the cursor follows dates"

    @property
    def available(self) -> bool:
        return bool(self.keys) and self._why is None

    def why_not(self) -> str | None:
        """One line saying why the case has no plot (None: it has one)."""
        return None if self.available else (self._why or "summary: no summary vectors")

    def _source(self):
        meta = getattr(self.view.model, "meta", None) or {}
        return meta.get("source") or getattr(self.view.model, "source", None)

    def plot(self, size: tuple[int, int]) -> SummaryPlot | None:
        """The plot of the View's ``summary`` vectors at ``size`` (None: no vector chosen),
        drawn anew only when the vectors or the size change."""
        vectors = tuple(getattr(self.view.options, "summary", None) or ())
        if not vectors:
            self.close()
            return None
        if not self.available:
            raise InputError(self.why_not() or "summary: no summary")
        key = (vectors, (int(size[0]), int(size[1])))
        if key != self._key:
            self.close()
            table = read_summary(self._source(), list(vectors))
            dates = _dates_of(self.view)
            self._plot = SummaryPlot(table, list(vectors), size=key[1], report_dates=dates,
                                     reports=_reports_of(self.view))
            self._key = key
        return self._plot

    def step_date(self) -> str | None:
        """The date of the shown report step (None: it has none)."""
        dates = _dates_of(self.view)
        step = getattr(self.view.options, "step", None)
        if step is None or not (0 <= int(step) < len(dates)):
            return None
        return dates[int(step)] or None

    def image(self, size: tuple[int, int] = (480, 300)) -> np.ndarray | None:
        """``(h, w, 4) uint8`` RGBA: the chosen vectors with the cursor at the shown step's
        date (None: no vector chosen)."""
        plot = self.plot(size)
        if plot is None:
            self.layout = {}
            return None
        img = plot.draw(self.step_date())
        self.layout = plot.layout
        return img

    def click(self, px: float, py: float) -> StepAt | None:
        """The report step a click at pixel ``(px, py)`` of the last picture leads to: the
        nearest one with restart data (``.index`` is the View's step, ``.text`` says it);
        None outside the plot's panels or before a picture."""
        if self._plot is None:
            return None
        when = self._plot.date_at(float(px), float(py))
        if when is None:
            return None
        return step_at(None, when, _dates_of(self.view), _reports_of(self.view))

    def close(self) -> None:
        """Let the plot go (its figure holds the kept picture)."""
        if self._plot is not None:
            self._plot.close()
        self._plot, self._key = None, None


__all__ = ["Timeline"]
