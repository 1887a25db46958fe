"""What a grid View computes per cell and per face, on the client or on a cluster's workers
(:mod:`geoshade.grid.distributed`): a property's values, their colour indices, the faces a
fault mode keeps."""

from __future__ import annotations

import numpy as np

from geoshade.compute.grid.filters import Expression, is_expression
from geoshade.grid.lazy import is_lazy
from geoshade.grid.options import step_names
from geoshade.models.names import derived_names, derived_values, properties_at
from geoshade.render.visuals.grid.prepare import color_index


def dynamic_names(grid) -> list[str]:
    """Report-step properties, the derived ones (SOIL) included."""

    return [*step_names(grid), *derived_names(grid)]


def uses_step(grid, name: str | None) -> bool:
    """True when property (or expression) ``name`` changes with the report step."""
    if name is None:
        return False
    dynamic = dynamic_names(grid)
    return name in dynamic or (is_expression(name) and Expression.parse(name).uses(dynamic))


def property_values(grid, name: str, step: int | None, diff: int | None = None):
    """(nx, ny, nz) values of property ``name`` of ``grid`` (see :meth:`GridView.values`): a
    numpy array, or a dask array for a grid out of core; with ``diff`` (a report step), the
    change since it: ``name`` at ``step`` minus ``name`` at ``diff`` (float64).

    >>> from geoshade.compute.grid.synthetic import synthetic_grid
    >>> g = synthetic_grid(4, 4, 3)
    >>> d = property_values(g, "SWAT", 2, diff=0)
    >>> bool(np.allclose(d, g.steps[2]["SWAT"] - g.steps[0]["SWAT"]))
    True
    """
    if diff is not None:
        now, then = property_values(grid, name, step), property_values(grid, name, diff)
        if isinstance(now, np.ndarray):
            return now.astype(np.float64) - then.astype(np.float64)
        return now.astype("f8") - then.astype("f8")   # dask: read chunk by chunk
    if is_expression(name):
        k = step if step is not None else len(grid.steps) - 1
        return Expression.parse(name).values(properties_at(grid, k), grid.dims)
    if name in derived_names(grid):
        return derived_values(grid, name, step if step is not None else len(grid.steps) - 1)
    if name in step_names(grid) and step is not None:
        v = grid.steps[step][name]
    else:
        v = grid.properties[name]
    return v if is_lazy(grid) and not isinstance(v, np.ndarray) else np.asarray(v)


#: values coloured at a time (float64 temporaries of a batch, not of a 1e9 filter's ~5e7 cells)
COLOUR_BATCH = 1 << 22


def colour_indices(style, lo: float, hi: float, gaps: bool, values) -> np.ndarray:
    """uint8 colour indices of ``values`` under the resolved colour ``style`` over
    ``lo..hi``: 0..254 and 255 for no value when ``gaps`` (cells without a value, the style
    neither solid nor an explicit palette), else 0..255; :data:`COLOUR_BATCH` values at a
    time (each index depends on its value alone)."""
    values = np.asarray(values)
    if values.ndim == 1 and values.size > COLOUR_BATCH:
        out = np.empty(values.size, np.uint8)
        for a in range(0, values.size, COLOUR_BATCH):
            out[a:a + COLOUR_BATCH] = colour_indices(style, lo, hi, gaps,
                                                     values[a:a + COLOUR_BATCH])
        return out
    t = style.transform(values)
    tlo, thi = style.transformed_range(lo, hi)
    if gaps:
        return style.nan_index(t, tlo, thi)
    return color_index(t, tlo, thi)


def fault_faces(fs, faults: str) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """``(cells, face, highlight)`` of a face set under the ``faults`` option: ``hide`` drops
    the fault faces whose neighbour is shown, ``highlight`` marks fault and named-fault
    faces (None: no highlight)."""
    cells, face = np.asarray(fs.cells), np.asarray(fs.face)
    fault = np.asarray(fs.fault, bool)
    named = np.asarray(getattr(fs, "fault_id", np.full(face.size, -1))) >= 0
    hl = None
    if faults == "hide":
        keep = ~(fault & np.asarray(fs.neighbour_shown, bool))
        cells, face = cells[keep], face[keep]
    elif faults == "highlight":
        hl = fault | named
    return cells, face, hl


__all__ = ["colour_indices", "dynamic_names", "fault_faces", "property_values", "uses_step"]
