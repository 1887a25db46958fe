"""Picking in the reservoir-grid view: the first shown cell along a pixel's ray.

The ray is taken into the grid's own coordinates (x, y, depth: MAPAXES and the exaggeration
undone) and tested against the faces the view draws: the visible faces (boundary, against a cell
not shown, or a fault) of the cells it shows now (active, inside the slice, passing the filter,
on the kept side of the plane: ``GridView._mask``), without the fault faces it hides
(``faults="hide"``) and, where the picture culled back faces (a frame drawn without the counting
pass), without those; each split along the diagonal the renderer uses
(:data:`geoshade.render.visuals.grid.layout.FACE_CORNERS`). Only the columns whose boxes the ray
crosses are read, nearest first, until a hit is nearer than the next column
(:func:`geoshade.compute.pick.grid_ray_hit`): a 1e8-cell grid is not copied.
"""

from __future__ import annotations

import weakref
from collections.abc import Mapping

import numpy as np

from geoshade.compute.grid.filters import Expression, is_expression
from geoshade.compute.pick import Ray, column_boxes, grid_ray_hit
from geoshade.grid.geometry import model_matrix
from geoshade.models.names import derived_names, derived_values, properties_at
from geoshade.models.steps import step_label
from geoshade.render.pick import Pick, nearest_with_refinements, register_picker
from geoshade.render.visuals.grid.layout import FACE_CORNER_TABLE
from geoshade.styles.categories import undefined_codes
from geoshade.styles.units import value_unit

#: per view: what a pick reuses (depth range, column boxes)
_CACHE: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _geometry(view):
    """(depth range, column boxes) of the view's grid, made once per grid."""
    g = view.grid
    entry = _CACHE.setdefault(view, {})
    key = (id(g.coord), id(g.zcorn))
    if entry.get("geometry", (None,))[0] != key:
        depth = g.bounds()[:, 2]
        entry["geometry"] = (key, depth, column_boxes(np.asarray(g.coord), depth))
    _, depth, boxes = entry["geometry"]
    return depth, boxes


class _OneCell(Mapping):
    """The properties of one cell, as (1, 1, 1) arrays read when looked up."""

    def __init__(self, properties, cell):
        self._p, (self._i, self._j, self._k) = properties, cell

    def __getitem__(self, name):
        i, j, k = self._i, self._j, self._k
        return np.asarray(self._p[name])[i:i + 1, j:j + 1, k:k + 1]

    def __iter__(self):
        return iter(self._p)

    def __len__(self) -> int:
        return len(self._p)


def cell_value(view, i: int, j: int, k: int):
    """The value of the shown property (or expression) in cell (i, j, k), or None; only that
    cell is read or computed (a derived SOIL or an expression too)."""

    o, g = view.options, view.grid
    name = o.property
    if name is None:
        return None
    step = o.step if o.step is not None else len(g.steps) - 1
    derived = derived_names(g)
    if is_expression(name):
        one = _OneCell(properties_at(g, step), (i, j, k))
        v = Expression.parse(name).values(one, (1, 1, 1))[0, 0, 0]
    elif name in derived:  # SOIL = 1 - SWAT - SGAS, of this cell only
        v = derived_values(g, name, step, (i, j, k))
    else:
        v = np.asarray(view.values(name, o.step))[i, j, k]
    return v.item() if isinstance(v, np.generic) else v


@register_picker("grid")
def pick_grid(view, ray: Ray) -> Pick | None:
    """The cell a GridView shows along ``ray`` (display world), or None; a refined cell of a
    local grid refinement where it is the nearer (named by its LGR and local I, J, K)."""
    return nearest_with_refinements(view, ray, _pick_cells)


def _pick_cells(view, ray: Ray) -> Pick | None:
    g, o = view.grid, view.options
    if view._mask is None:
        return None
    to_grid = np.linalg.inv(model_matrix(g, np.zeros(3), o.exaggeration))
    local = ray.transformed(to_grid)  # x, y, depth of the grid
    depth_range, boxes = _geometry(view)
    hit = grid_ray_hit(g.coord, g.zcorn, view._mask, local, FACE_CORNER_TABLE, depth_range,
                       hide_faults=o.faults == "hide", boxes=boxes, cull=_cull(view))
    if hit is None:
        return None
    i, j, k = hit.cell
    x, y, depth = (float(v) for v in hit.point)
    t = g.map_transform()
    mx, my = t[:2, :2] @ np.array([x, y]) + t[:2, 2]
    label = f"I={i + 1} J={j + 1} K={k + 1}"
    extra: tuple[tuple[str, str], ...] = ()
    if o.property is not None and view.uses_step(o.property) and o.step is not None:

        extra = (("step", step_label(o.step, g.step_dates,
                                     g.meta.get("unrst_seqnum") or ())),)
    value = cell_value(view, i, j, k)
    extra = _class_name(view, value) + extra
    return Pick("grid", (i, j, k), (float(mx), float(my), -depth), depth,
                value, o.property or "", unit=_unit(view),
                label=label, ijk_label=label, length_unit=view._length_unit(), extra=extra,
                t=hit.t)


def _cull(view) -> float:
    """The grid's orientation where the picture culled back faces (a frame drawn without the
    counting pass, with ``cull`` on), else 0: the counting frame draws every face."""
    last = getattr(view, "_last_frame", None)
    counted = True if last is None else bool(last[2])
    if not view.options.cull or counted:
        return 0.0
    return float(getattr(view.visual, "orientation", 0.0) or 0.0)


def _class_name(view, value) -> tuple[tuple[str, str], ...]:
    """``(("class", name),)`` where a categorical property's code has a name in the file (ROFF
    codes), ``(("class", "no value"),)`` for an undefined code; else ()."""
    cats = view.colours.categories
    if cats is None or value is None:
        return ()

    try:
        v = float(value)
    except (TypeError, ValueError):
        return ()
    if v in undefined_codes(view.grid.meta):
        return (("class", "no value"),)
    names = (view.grid.meta.get("codes") or {}).get(view.options.property) or {}
    name = names.get(int(v)) if v.is_integer() else None
    return (("class", str(name)),) if name else ()


def _unit(view) -> str:

    return value_unit(view.grid, view.options.property)


__all__ = ["cell_value", "pick_grid"]
