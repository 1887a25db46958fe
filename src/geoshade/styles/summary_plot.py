"""The summary plot: vectors against time with a time cursor, drawn with matplotlib's Agg canvas
(no pyplot, no GUI backend), for ``geoshade summary``, the strip under an animation and the
viewers' plot beside the 3D view.

:class:`SummaryPlot` draws the curves once (dates on x, one y axis per unit -- a second unit on
the right, three or more units one panel each -- SMSPEC's units on the axes, a legend) and keeps
that picture; moving the cursor (:meth:`SummaryPlot.draw` with another date) restores it and
draws only the cursor line, its date and the markers of the nearest report step, so a viewer can
follow the step (a few ms a move). :func:`step_at` turns a date clicked on the plot
(:meth:`SummaryPlot.date_at` turns a pixel into a date) into the nearest report step that has
restart data, and says so.

>>> import numpy as np, datetime
>>> from geoshade.models.summary_vectors import SummaryTable, SummaryVector
>>> t = SummaryTable(np.arange(1.0, 61.0), np.stack([np.linspace(0, 100, 60),
...                  np.linspace(300, 250, 60)], 1).astype(np.float32),
...                  [SummaryVector("FOPR", "FOPR", "field", "SM3/DAY"),
...                   SummaryVector("FPR", "FPR", "field", "BARSA")], datetime.datetime(2000, 1, 1))
>>> plot = SummaryPlot(t, size=(480, 300))
>>> img = plot.draw("2000-01-20")
>>> img.shape, [a["unit"] for a in plot.layout["axes"]], plot.layout["cursor"]["report"]
((300, 480, 4), ['SM3/DAY', 'BARSA'], 19)
>>> step_at(None, "2000-01-10", ["2000-01-01", "2000-02-01"]).index
0
"""

from __future__ import annotations

import datetime
import math
from collections.abc import Sequence
from dataclasses import dataclass

import matplotlib.dates as mdates
import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.text import Text

from geoshade.errors import InputError, terminal_safe
from geoshade.models.summary_vectors import SummaryTable

#: the cursor's colour (the curves use matplotlib's tab10/tab20, never black)
CURSOR_COLOR = "#111111"
#: a panel of the stacked layout needs at least this many pixels of height
MIN_PANEL_PX = 70
#: below this height the plot is a strip: no title, smaller text
STRIP_PX = 260


def _datetime(x, where: str = "date") -> datetime.datetime:
    """A date given as text (ISO, with or without the time), date, datetime, numpy datetime64
    or a matplotlib date number (what a click on the plot gives)."""
    if isinstance(x, datetime.datetime):
        return x.replace(tzinfo=None)
    if isinstance(x, datetime.date):
        return datetime.datetime(x.year, x.month, x.day)
    if isinstance(x, np.datetime64):
        return datetime.datetime.fromisoformat(str(x.astype("datetime64[s]")))
    if isinstance(x, int | float | np.integer | np.floating) and not isinstance(x, bool):
        if not math.isfinite(float(x)):
            raise InputError(f"{where}: {x} is not a date")
        return mdates.num2date(float(x)).replace(tzinfo=None)
    try:
        return datetime.datetime.fromisoformat(str(x).strip())
    except ValueError:
        raise InputError(f"{where}: {x!r} is not a date; expected YYYY-MM-DD or "
                         "YYYY-MM-DDTHH:MM[:SS]") from None


def _iso(d: datetime.datetime) -> str:
    return d.isoformat(timespec="seconds")


def _show(d: datetime.datetime) -> str:
    """``2001-03-01`` at midnight, else ``2001-03-01 06:00`` (seconds where there are some)."""
    if d.time() == datetime.time(0):
        return d.date().isoformat()
    return d.isoformat(sep=" ", timespec="seconds" if d.second else "minutes")


@dataclass(frozen=True)
class StepAt:
    """The report step a date leads to (:func:`step_at`).

    index:   int         index of the step among the dates given (the viewer's step)
    report:  int or None its report number, where known
    date:    str         its date (ISO)
    clicked: str         the date asked for (ISO)
    exact:   bool        whether the step is at that date
    text:    str         one line saying so, for a status bar
    """

    index: int
    report: int | None
    date: str
    clicked: str
    exact: bool
    text: str


def step_at(source, x, restart_dates: Sequence | None = None,
            reports: Sequence[int] | None = None) -> StepAt:
    """The report step with restart data nearest to date ``x`` (a click on the plot).

    Parameters
    ----------
    source : SummaryTable, a grid or field with ``step_dates``, or None
        Where the report steps come from when ``restart_dates`` is not given: a grid's (or a
        field's) ``step_dates`` and its ``meta["unrst_seqnum"]`` report numbers -- the steps a
        3D view can show -- or a summary table's report steps.
    x : date, datetime, str, numpy.datetime64 or float
        The date (a float is a matplotlib date number, as a click event's ``xdata``).
    restart_dates : sequence, optional
        The dates of the steps with restart data ("" where unknown: never chosen).
    reports : sequence of int, optional
        Their report numbers.

    Examples
    --------
    >>> s = step_at(None, "2001-02-20T12:00", ["2001-01-01", "2001-02-01", "2001-03-01"],
    ...             [0, 1, 2])
    >>> s.index, s.report, s.text
    (2, 2, '2001-02-20 12:00: step 2 (report 2, 2001-03-01), the nearest report step with \
restart data')
    """
    if restart_dates is None:
        if isinstance(source, SummaryTable):
            reps, dates = source.report_steps()
            restart_dates, reports = [str(d) for d in dates], [int(r) for r in reps]
        elif source is not None and hasattr(source, "step_dates"):
            restart_dates = list(source.step_dates)
            seq = (getattr(source, "meta", None) or {}).get("unrst_seqnum")
            reports = list(seq) if seq is not None and len(seq) == len(restart_dates) else None
        else:
            raise InputError("step_at: no report steps; give restart_dates or a summary table, "
                             "grid or field")
    known = [(k, _datetime(d, "restart date")) for k, d in enumerate(restart_dates) if str(d)]
    if not known:
        raise InputError("step_at: no report step with a date (restart data); nothing to move "
                         "to")
    when = _datetime(x)
    k, d = min(known, key=lambda kd: (abs((kd[1] - when).total_seconds()), kd[0]))
    report = None if reports is None else int(reports[k])
    exact = d == when
    name = f"step {k} (report {report}, {_show(d)})" if report is not None else \
        f"step {k} ({_show(d)})"
    text = f"{_show(when)}: {name}" + ("" if exact else
                                      ", the nearest report step with restart data")
    return StepAt(k, report, _iso(d), _iso(when), exact, text)


class SummaryPlot:
    """Vectors of a summary table against time, with a time cursor that moves cheaply.

    Parameters
    ----------
    table : SummaryTable
    vectors : list of str, optional
        Names or wildcards (``WOPR:*``); default every vector of ``table``.
    size : (int, int)
        Width and height in pixels. Below :data:`STRIP_PX` high the plot is a strip (no title),
        for the strip under an animation.
    title : str, optional
        Default: the case's name and unit system.
    report_dates, reports : sequence, optional
        The report steps the cursor's markers go to (the steps with restart data a viewer
        shows); default the table's report steps.

    Attributes
    ----------
    layout : dict
        What is where (pixels, row 0 at the top): ``size``, ``axes`` (unit, side, vectors,
        ``ylim``, ``bbox``), ``xlim`` (ISO dates), ``legend`` and, after a draw with a cursor,
        ``cursor`` (``date``, ``x_px``, ``report``, ``report_date``).
    """

    def __init__(self, table: SummaryTable, vectors: Sequence[str] | None = None,
                 size: tuple[int, int] = (960, 540), title: str | None = None,
                 report_dates: Sequence | None = None, reports: Sequence[int] | None = None,
                 dpi: int = 100):
        if not isinstance(table, SummaryTable):
            raise InputError(f"summary plot: expected a SummaryTable, got {type(table).__name__}")
        w, h = (int(size[0]), int(size[1]))
        if w < 200 or h < 100:
            raise InputError(f"summary plot: size {w}x{h} is too small; expected at least "
                             "200x100 pixels")
        self.table = table if vectors is None else table.select(vectors)
        if not self.table.vectors:
            raise InputError(f"{table.name}: summary plot: no vector to draw")
        if not self.table.nsteps:
            raise InputError(f"{table.name}: summary plot: no ministep to draw")
        self.size = (w, h)
        units: dict[str, list[int]] = {}
        for i, v in enumerate(self.table.vectors):
            units.setdefault(v.unit_label(), []).append(i)
        self.units = units
        stacked = len(units) > 2
        if stacked and h / len(units) < MIN_PANEL_PX:
            raise InputError(f"summary plot: {len(units)} units ({', '.join(units)}) need "
                             f"{MIN_PANEL_PX} pixels of height each, the plot is {h}; choose "
                             "vectors of fewer units or a taller plot")
        if report_dates is None:
            reps, dates = self.table.report_steps()
            report_dates, reports = list(dates), list(reps)
        self._report_x = np.array([mdates.date2num(_datetime(d, "report date"))
                                   for d in report_dates if str(d)], np.float64)
        self._report_n = (None if reports is None else
                          [int(r) for r, d in zip(reports, report_dates, strict=True) if str(d)])
        self._x = mdates.date2num(self.table.dates.astype("datetime64[us]").astype(object))
        self._x = np.asarray(self._x, np.float64)
        strip = h < STRIP_PX
        pt = float(np.clip(min(h / 48.0, w / 80.0), 7.0, 10.0))
        self.fig = Figure(figsize=(w / dpi, h / dpi), dpi=dpi, layout="constrained")
        self.canvas = FigureCanvasAgg(self.fig)
        self.fig.get_layout_engine().set(w_pad=4 / dpi, h_pad=4 / dpi, hspace=0.02)
        colors = _colors(len(self.table.vectors))
        self.axes = list(np.atleast_1d(self.fig.subplots(len(units) if stacked else 1, 1,
                                                         sharex=True, squeeze=False)[:, 0]))
        if not stacked and len(units) == 2:
            self.axes.append(self.axes[0].twinx())
        self._lines: list = []
        self._side: list[str] = []
        start = mdates.date2num(self.table.start)
        for a, (unit, cols) in enumerate(units.items()):
            ax = self.axes[a]
            right = not stacked and a == 1
            for c in cols:
                v = self.table.vectors[c]
                label = f"{v.key} [{unit}]" if len(units) == 2 else v.key
                line, = ax.plot(self._x, self.table.values[:, c], color=colors[c], lw=1.5,
                                ls="--" if right else "-", label=label)
                self._lines.append((ax, c, line))
            ax.set_ylabel(unit + (" (dashed)" if right else ""), fontsize=pt)
            ax.tick_params(labelsize=pt * 0.9)
            if not right:
                ax.grid(True, lw=0.4, alpha=0.5)
            self._side.append("right" if right else "left")
        x0, x1 = min(start, self._x[0]), self._x[-1]
        if x1 <= x0:
            x1 = x0 + 1.0
        bottom = self.axes[len(units) - 1 if stacked else 0]
        bottom.set_xlim(x0, x1)
        loc = mdates.AutoDateLocator(minticks=2, maxticks=max(5, w // 100))
        bottom.xaxis.set_major_locator(loc)
        bottom.xaxis.set_major_formatter(mdates.ConciseDateFormatter(loc))
        for ax in self.axes[:len(units) - 1] if stacked else []:
            ax.tick_params(labelbottom=False)
        legends = []
        if stacked:
            for ax in self.axes:
                legends.append(ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0),
                                         fontsize=pt * 0.85, frameon=False, borderaxespad=0))
        else:
            handles = [ln for _, _, ln in self._lines]
            legends.append(self.fig.legend(handles=handles, loc="outside right upper",
                                           fontsize=pt * 0.85, frameon=False))
        self._legends = legends
        if not strip:
            name = title if title is not None else _title(self.table)
            self.fig.suptitle(name, fontsize=pt * 1.1)
        # the cursor: a line on every panel, its date on the top one, markers at the report step
        self._cursor = [ax.axvline(x0, color=CURSOR_COLOR, lw=1.2, animated=True)
                        for ax in self.axes[:len(units)]]
        self._label = self.axes[0].annotate(
            "", xy=(x0, 1.0), xycoords=("data", "axes fraction"), xytext=(3, -3),
            textcoords="offset points", va="top", ha="left", fontsize=pt * 0.85,
            color=CURSOR_COLOR, animated=True,
            bbox={"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none", "alpha": 0.8})
        self._markers = [ax.plot([], [], "o", color=line.get_color(), ms=5, mec="white",
                                 mew=0.8, animated=True)[0] for ax, _, line in self._lines]
        for text in self.fig.findobj(Text):  # names and units from files: never mathtext, and
            text.set_parse_math(False)        # their control characters shown escaped
            text.set_text(terminal_safe(text.get_text()))
        self.canvas.draw()
        self._background = self.canvas.copy_from_bbox(self.fig.bbox)
        self.layout = self._layout()

    # --- drawing -------------------------------------------------------------------------------
    def draw(self, at=None) -> np.ndarray:
        """The picture, ``(h, w, 4) uint8`` RGBA, with the cursor at date ``at`` (None: none);
        only the cursor is redrawn over the kept curves."""
        self.canvas.restore_region(self._background)
        self.layout.pop("cursor", None)
        if at is not None:
            when = _datetime(at, "cursor")
            x = float(mdates.date2num(when))
            for line in self._cursor:
                line.set_xdata([x, x])
                line.axes.draw_artist(line)
            text = _show(when)
            cursor = {"date": _iso(when), "x_px": self._px(x)}
            if self._report_x.size:
                k = int(np.argmin(np.abs(self._report_x - x)))
                xr = float(self._report_x[k])
                for (ax, c, _), m in zip(self._lines, self._markers, strict=True):
                    m.set_data([xr], [float(np.interp(xr, self._x,
                                                      self.table.values[:, c]))])
                    ax.draw_artist(m)
                rep = None if self._report_n is None else self._report_n[k]
                cursor.update(report=rep, report_date=_iso(mdates.num2date(xr).replace(
                    tzinfo=None)), report_x_px=self._px(xr))
                rdate = mdates.num2date(xr).replace(tzinfo=None)
                if rep is not None or abs(xr - x) > 1e-6:
                    text += f"  report {rep}" if rep is not None else "  report step"
                    if abs(xr - x) > 1e-6:
                        text += f" ({_show(rdate)})"
            self._label.xy = (x, 1.0)
            lo, hi = self.axes[0].get_xlim()
            right = x > (lo + hi) / 2  # the date on the side of the cursor with room for it
            self._label.set_horizontalalignment("right" if right else "left")
            self._label.set_position((-3 if right else 3, -3))
            self._label.set_text(text)
            self.axes[0].draw_artist(self._label)
            self.layout["cursor"] = cursor
        return np.asarray(self.canvas.buffer_rgba()).copy()

    def date_at(self, px: float, py: float) -> datetime.datetime | None:
        """The date under pixel ``(px, py)`` of the picture (origin top-left, as in the image
        array), or None outside the plot's panels: what a click on the plot means."""
        h = self.size[1]
        for ax in self.axes:
            x0, y0, x1, y1 = ax.bbox.extents
            if x0 <= px <= x1 and y0 <= h - py <= y1:
                x, _ = ax.transData.inverted().transform((px, h - py))
                return mdates.num2date(x).replace(tzinfo=None)
        return None

    def close(self) -> None:
        """Let the figure go (it holds the canvas and the kept picture)."""
        self.fig.clear()
        self._background = None

    # --- layout --------------------------------------------------------------------------------
    def _px(self, x: float) -> float:
        return float(self.axes[0].transData.transform((x, 0.0))[0])

    def _layout(self) -> dict:
        h = self.size[1]

        def box(bb) -> list[float]:
            return [round(float(v), 1) for v in (bb.x0, h - bb.y1, bb.x1, h - bb.y0)]

        axes = []
        units = list(self.units)
        for a, ax in enumerate(self.axes):
            axes.append({"unit": units[a], "side": self._side[a],
                         "vectors": [self.table.vectors[c].key for c in self.units[units[a]]],
                         "ylim": [float(v) for v in ax.get_ylim()], "bbox": box(ax.bbox),
                         "label": ax.get_ylabel()})
        x0, x1 = self.axes[0].get_xlim()
        r = self.canvas.get_renderer()
        legend = [{"texts": [t.get_text() for t in lg.get_texts()],
                   "bbox": box(lg.get_window_extent(r))} for lg in self._legends]
        return {"size": list(self.size), "axes": axes, "legend": legend,
                "xlim": [_iso(mdates.num2date(x0).replace(tzinfo=None)),
                         _iso(mdates.num2date(x1).replace(tzinfo=None))],
                "title": self.fig.get_suptitle()}


def _title(table: SummaryTable) -> str:
    name = str(table.name).replace("\\", "/").rsplit("/", 1)[-1]
    stem = name.rsplit(".", 1)[0] if "." in name else name
    units = f" ({table.unit_system} units)" if table.unit_system else ""
    return f"{stem or 'summary'}{units}"


def _colors(n: int) -> list:
    import matplotlib  # the colormaps registry (matplotlib is loaded at this module's top)

    if n <= 10:
        return [matplotlib.colormaps["tab10"](i) for i in range(n)]
    cmap = matplotlib.colormaps["tab20"]  # its dark colours first, then the light ones
    order = [*range(0, 20, 2), *range(1, 20, 2)]
    return [cmap(order[i % 20]) for i in range(n)]


def summary_plot(table: SummaryTable, vectors: Sequence[str] | None = None, at=None,
                 **options) -> tuple[np.ndarray, dict]:
    """One picture of ``vectors`` (see :class:`SummaryPlot` for ``options``) with the cursor at
    ``at``: ``(rgba, layout)``.

    Examples
    --------
    >>> import numpy as np, datetime
    >>> from geoshade.models.summary_vectors import SummaryTable, SummaryVector
    >>> t = SummaryTable([1.0, 2.0], np.ones((2, 1), np.float32),
    ...                  [SummaryVector("FPR", "FPR", "field", "PSIA")],
    ...                  datetime.datetime(2000, 1, 1))
    >>> img, layout = summary_plot(t, at="2000-01-02", size=(320, 200))
    >>> img.shape, layout["axes"][0]["label"], layout["cursor"]["date"]
    ((200, 320, 4), 'PSIA', '2000-01-02T00:00:00')
    """
    plot = SummaryPlot(table, vectors, **options)
    try:
        img = plot.draw(at)
        return img, dict(plot.layout)
    finally:
        plot.close()


__all__ = ["CURSOR_COLOR", "StepAt", "SummaryPlot", "step_at", "summary_plot"]
