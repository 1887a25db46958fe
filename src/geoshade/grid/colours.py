"""The colour state of a :class:`~geoshade.grid.view.GridView`: what a property, a report step
and a colour style make of the cells' values, the same for every source and drawing.

:meth:`GridColours.plan` turns the options into a :class:`ColourPlan` (the property, the step,
the resolved style with its range and the palette) that a drawing applies to the cells it holds
(:mod:`geoshade.grid.backends`); the range, the log decision, the categories and the count of
cells without a value come from every active cell, so they never depend on the filter or slice.
The colour bar or legend and the colour stats are read from here.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, replace

import numpy as np

from geoshade.compute.grid.cell_values import summarise
from geoshade.errors import where
from geoshade.grid.cells import property_values, uses_step
from geoshade.grid.lazy import count_in, is_lazy, lazy_codes, stored_summary
from geoshade.models.steps import step_label
from geoshade.styles.annotate import ColorBar, Legend
from geoshade.styles.categories import (
    CodeStyle,
    by_name,
    categorical_palette,
    distinct_codes,
    is_categorical,
    legend_entries,
    undefined_codes,
)
from geoshade.styles.units import value_unit


@dataclass(frozen=True)
class ColourPlan:
    """How the cells are coloured: ``property`` at ``step``, ``state`` = ``(style, lo, hi,
    gaps)`` for :func:`~geoshade.grid.cells.colour_indices` (None: one uniform colour) and the
    ``palette`` ((256, 4) uint8)."""

    property: str | None
    step: int | None
    state: tuple | None
    palette: np.ndarray
    #: the report step a difference is taken from (``--diff``), None: the values themselves
    diff: int | None = None


class GridColours:
    """The colour state of one grid (see the module): set by :meth:`plan`, read by the
    annotations (:meth:`key`) and the stats (:meth:`stats`).

    Examples
    --------
    >>> from geoshade.compute.grid.synthetic import synthetic_grid
    >>> from geoshade.grid.options import GridOptions
    >>> g = synthetic_grid(6, 5, 3)
    >>> colours = GridColours(g)
    >>> plan = colours.plan(GridOptions.parse(g, property="PORO"))
    >>> plan.property, colours.range == (plan.state[1], plan.state[2]), plan.palette.shape
    ('PORO', True, (256, 4))
    """

    def __init__(self, grid):
        self.grid = grid
        self.lazy = is_lazy(grid)
        #: the colour bar's range, log and whether the log was chosen automatically
        self.range: tuple[float, float] | None = None
        self.log = self.log_auto = False
        #: a CategoricalPalette while a property is drawn as categories
        self.categories = None
        self.no_value_cells = 0
        #: the colour map drawn (a difference's diverging one where none was chosen)
        self.colormap: str | None = None
        #: the drawn values' min and max of a difference (``--diff``), over the active cells
        self.value_range: tuple[float, float] | None = None
        #: notes of the last plan (shared colours of many codes, the last report step)
        self.notes: list[str] = []
        #: the last plan: how the drawn cells are coloured now
        self.current: ColourPlan | None = None
        self._summaries: dict = {}

    def clear(self) -> None:
        """Forget the remembered summaries (a preview's grid was replaced)."""
        self._summaries.clear()

    def summary(self, name: str, step: int | None, values: np.ndarray, diff=None):
        """:class:`~geoshade.compute.grid.cell_values.ValueSummary` of ``values`` over the active
        cells, remembered per property (and report step where it has them, and the step a
        difference is taken from)."""
        key = (name, step if uses_step(self.grid, name) else None, diff)
        if key not in self._summaries:
            # a grid store's own array: the summary stored at ingest (no pass over it)
            stored = stored_summary(self.grid, values) if self.lazy and diff is None else None
            # a grid store's ACTNUM stays lazy (read chunk by chunk with the property)
            active = self.grid.actnum if self.lazy else self.grid.active
            self._summaries[key] = stored if stored is not None else summarise(values, active)
        return self._summaries[key]

    def plan(self, o) -> ColourPlan:
        """The :class:`ColourPlan` of options ``o``'s property, step and colour style (kept
        as :attr:`current`); sets the colour bar's range, log, categories and the notes."""
        self.current = self._plan(o)
        return self.current

    def _plan(self, o) -> ColourPlan:
        g = self.grid
        self.notes = []
        palette = o.color.palette_rgba()
        self.no_value_cells = 0
        self.value_range = None
        if o.property is None:
            self.range = None
            return ColourPlan(None, o.step, None, palette)
        diff = getattr(o, "diff", None)
        full = property_values(g, o.property, o.step, diff)
        summary = self.summary(o.property, o.step, full, diff)
        if diff is not None:   # a change: diverging, centred on 0, never log nor classes
            style, self.log_auto = diverging(o.color), False
            ext = summary.extremes(False)
            lo, hi = (float(ext[0]), float(ext[1])) if ext.size else (0.0, 0.0)
            self.value_range = (float(lo), float(hi))
            m = max(abs(float(lo)), abs(float(hi))) or 1.0
            lo, hi = style.range if style.range is not None else (-m, m)
            palette = style.palette_rgba()
        else:
            style, self.log_auto = o.color.resolved(o.property, summary.extremes(log=True))
            if style.range is not None:
                lo, hi = style.range
            else:
                lo, hi = style.default_range(summary.extremes(bool(style.log)))
        gaps = summary.gaps(bool(style.log))
        self.categories = None if diff is not None else \
            self._categorical(o.property, o.step, full, style)
        if self.categories is not None:   # one qualitative colour per code (linear index map)
            style, self.log_auto = replace(style, log=False), False
            gaps = summary.gaps(False)
        nan = bool(gaps and style.solid is None and style.palette is None)
        if nan:  # cells without a value get the NaN colour (entry 255), the others 0..254
            palette = style.nan_palette()
            self.no_value_cells = gaps
        if self.categories is not None:
            codes, undef = self.categories, undefined_codes(g.meta)
            if undef and np.isin(codes, undef).any():   # ROFF's -999: cells without a value
                codes = codes[~np.isin(codes, undef)]
                act = g.actnum if self.lazy else g.active
                self.no_value_cells = int(gaps) + count_in(full, act, undef)
                nan, palette = True, style.nan_palette()
                style = CodeStyle(undef)
            self.categories = categorical_palette(codes, nan, o.color.nan_color)
            lo, hi, palette = self.categories.lo, self.categories.hi, self.categories.palette
            if self.categories.shared:
                self.notes.append(f"{o.property}: {self.categories.shared} of its "
                                  f"{codes.size} codes share a colour with another code (too "
                                  "many or too unevenly spread for one palette)")
        self.range = (lo, hi)
        self.log = bool(style.log)
        cmap = getattr(style, "colormap", None)   # a CodeStyle (ROFF's codes) has none
        self.colormap = None if cmap is None else cmap + ("_r" if style.reverse else "")
        if self.no_value_cells:   # counted and said: never drawn in silence
            at = (f" at {step_label(o.step, g.step_dates)}" if uses_step(g, o.property)
                  else "")
            note = (f"{where(g.name)}{o.property}{at}: {self.no_value_cells:,} active cells "
                    "without a value (NaN, or ECLIPSE's undefined value ±1e20 and beyond, in "
                    "the file) are drawn in the no-value colour")
            self.notes.append(note)
            warnings.warn(note, UserWarning, stacklevel=2)
        if uses_step(g, o.property) and o.step == len(g.steps) - 1 and len(g.steps) > 1:
            self.notes.append(f"{o.property} is a report-step property: the last step "
                              f"({step_label(o.step, g.step_dates)}) is shown")
        return ColourPlan(o.property, o.step, (style, float(lo), float(hi), nan), palette, diff)

    def _categorical(self, name: str, step, values, style):
        """The distinct codes of ``name`` over the active cells when it is drawn as categories
        (:func:`geoshade.styles.categories.is_categorical` under the style's ``categorical``;
        an explicit range keeps an automatic choice continuous), else None."""
        if style.solid is not None or style.palette is not None or style.categorical is False \
                or (style.categorical is None and style.range is not None):
            return None
        key = ("codes", name, step if uses_step(self.grid, name) else None)
        if key not in self._summaries:   # a store's: kept at ingest, else one chunked pass
            dtype = values.dtype if hasattr(values, "dtype") else np.asarray(values).dtype
            maybe = np.issubdtype(dtype, np.integer) or style.categorical or by_name(name)
            self._summaries[key] = None if not maybe else (
                lazy_codes(self.grid, values) if self.lazy
                else distinct_codes(values, self.grid.active))
        codes = self._summaries[key]
        if codes is None or not is_categorical(name, values, style.categorical, codes=codes):
            return None
        return codes

    def key(self, o, palette: np.ndarray):
        """The colour bar, or the legend of a property drawn as categories (None: no
        property), of the last plan drawn with ``palette``."""
        g = self.grid
        if o.property is None or self.range is None:
            return None
        if self.categories is not None:   # one entry per code, named where the file names it
            names = (g.meta.get("codes") or {}).get(o.property)
            nan = (tuple(int(x) for x in self.categories.palette[255])
                   if self.no_value_cells else None)   # cells drawn in the no-value colour
            return Legend(o.property, legend_entries(self.categories, names), nan_color=nan)
        lo, hi = self.range
        gaps = self.no_value_cells > 0
        name = o.property if getattr(o, "diff", None) is None else f"Δ{o.property}"
        return ColorBar(name, lo, hi, palette[:255] if gaps else palette,
                        unit=value_unit(g, o.property), log=self.log, auto=self.log_auto,
                        nan_color=o.color.nan_color if gaps else None)

    def stats(self) -> dict:
        """The colour stats: ``categories color_range log log_auto no_value_cells``."""
        return {"value_range": None if self.value_range is None else list(self.value_range),
                "categories": (None if self.categories is None
                               else [float(c) for c in self.categories.codes]),
                "color_range": list(self.range) if self.range else None,
                "log": self.log, "log_auto": self.log_auto,
                "no_value_cells": self.no_value_cells}


#: the colour map a difference is drawn with where the user chose none (blue: less, red: more)
DIVERGING = "RdBu_r"


def diverging(style):
    """``style`` for a difference: linear, not categorical, the diverging colour map unless
    the user chose one (the default viridis is replaced).

    >>> from geoshade.styles.options import ColorStyle
    >>> diverging(ColorStyle()).colormap, diverging(ColorStyle(colormap="magma")).colormap
    ('RdBu', 'magma')
    """
    if style.colormap == "viridis" and not style.reverse and style.solid is None:
        style = style.with_(colormap=DIVERGING)
    return replace(style, log=False, categorical=False)


__all__ = ["DIVERGING", "ColourPlan", "GridColours", "diverging"]
