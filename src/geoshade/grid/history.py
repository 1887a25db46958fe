"""What a picked cell holds, as ResInsight's result info and cell plots show it: every property
of the cell at the shown report step (:func:`cell_table`), and one property of the cell over
every step (:func:`cell_history`, drawn by :func:`history_plot`). Only the cell's values are
read: a restart step's array is read lazily, one value of each.

>>> from geoshade.compute.grid.synthetic import synthetic_grid
>>> g = synthetic_grid(4, 3, 2)
>>> rows = cell_table(g, (1, 2, 0), step=1)
>>> [r["name"] for r in rows][:3]
['PORO', 'PERMX', 'NTG']
>>> h = cell_history(g, (1, 2, 0), "SWAT")
>>> len(h["values"]) == len(g.steps), h["unit"]
(True, 'fraction')
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from geoshade.errors import InputError
from geoshade.models.names import derived_names, derived_values, grid_property, step_names
from geoshade.styles.units import value_unit


def _cell(grid, ijk) -> tuple[int, int, int]:
    try:
        i, j, k = (int(v) for v in ijk)
    except (TypeError, ValueError):
        raise InputError(f"cell: expected (i, j, k), got {ijk!r}") from None
    nx, ny, nz = grid.dims
    if not (0 <= i < nx and 0 <= j < ny and 0 <= k < nz):
        raise InputError(f"cell: I={i + 1} J={j + 1} K={k + 1} is outside the grid's "
                         f"{nx}×{ny}×{nz} cells")
    return i, j, k


def _value(arr, ijk) -> float | None:
    v = np.asarray(arr[ijk] if ijk else arr)
    v = v.item() if v.ndim == 0 else float(v.ravel()[0])
    return None if isinstance(v, float) and not np.isfinite(v) else v


def cell_table(grid, ijk, step: int | None = None) -> list[dict]:
    """Every property of cell ``ijk`` (0-based i, j, k): the static ones, then those of report
    ``step`` (default: the last) and the derived ones (SOIL), each ``{"name", "value",
    "unit", "step"}`` (``step`` None for a static property)."""
    ijk = _cell(grid, ijk)
    rows = [{"name": n, "value": _value(grid.properties[n], ijk), "unit": value_unit(grid, n),
             "step": None} for n in grid.properties]
    if grid.steps:
        k = len(grid.steps) - 1 if step is None else int(step)
        rows += [{"name": n, "value": _value(grid.steps[k][n], ijk),
                  "unit": value_unit(grid, n), "step": k} for n in step_names(grid)
                 if n in grid.steps[k]]
        rows += [{"name": n, "value": _value(derived_values(grid, n, k, ijk), ()),
                  "unit": value_unit(grid, n), "step": k} for n in derived_names(grid)]
    return rows


def cell_history(grid, ijk, name: str) -> dict:
    """Property ``name`` (a report-step or derived one; any case) of cell ``ijk`` at every
    report step: ``{"name", "unit", "cell", "steps", "dates", "values"}``."""
    ijk = _cell(grid, ijk)
    name = grid_property(grid, name)
    if name not in step_names(grid) and name not in derived_names(grid):
        raise InputError(f"history: {name} does not change with the report step; a history "
                         "is of a report-step property such as SWAT or PRESSURE")
    values = [_value(derived_values(grid, name, k, ijk), ()) if name in derived_names(grid)
              else _value(grid.steps[k][name], ijk) for k in range(len(grid.steps))]
    dates = list(grid.step_dates) if len(grid.step_dates) == len(grid.steps) else []
    return {"name": name, "unit": value_unit(grid, name), "cell": ijk,
            "steps": list(range(len(grid.steps))), "dates": dates, "values": values}


def history_plot(history: dict, path=None, size=(640, 360), cursor: int | None = None):
    """A cell history (:func:`cell_history`) as a line plot over the dates (or the steps),
    the unit on the y axis, a marker at step ``cursor``: written to ``path`` (PNG) or returned
    as an (h, w, 4) uint8 picture."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    w, h = size
    fig = Figure(figsize=(w / 100, h / 100), dpi=100)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    x = (np.array(history["dates"], dtype="datetime64[s]").astype(object) if history["dates"]
         else history["steps"])
    y = np.array([np.nan if v is None else v for v in history["values"]], float)
    ax.plot(x, y, marker="o", ms=3, lw=1.5, color="tab:blue")
    if cursor is not None and 0 <= cursor < len(y):
        ax.axvline(x[cursor], color="black", lw=1)
        ax.plot([x[cursor]], [y[cursor]], "o", color="black", ms=6)
    i, j, k = history["cell"]
    ax.set_title(f"{history['name']} of cell I={i + 1} J={j + 1} K={k + 1}", fontsize=10)
    ax.set_ylabel(f"{history['name']} [{history['unit']}]" if history["unit"]
                  else history["name"])
    ax.set_xlabel("date" if history["dates"] else "report step")
    ax.grid(True, alpha=0.3)
    fig.autofmt_xdate()
    fig.tight_layout()
    if path is not None:
        fig.savefig(Path(path), dpi=100)
        return None
    fig.canvas.draw()
    return np.asarray(fig.canvas.buffer_rgba()).copy()


__all__ = ["cell_history", "cell_table", "history_plot"]
