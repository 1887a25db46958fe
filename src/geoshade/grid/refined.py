"""Local grid refinements drawn inside their hosts, as ResInsight draws them.

A grid with refinements (ECLIPSE LGRs: :attr:`CornerPointGrid.refinements`) is shown as its
global cells with the host cells hidden (:func:`hide_hosts`) and, in the same picture, the
refined cells of every refinement of the global grid. :class:`RefinedCells` keeps one
:class:`~geoshade.grid.view.GridView` per refinement on the parent's GL context and draws them
in the parent's frame with its camera: the same property and report step (the refinement's own
values, from its INIT/UNRST sections), on the parent's colour scale, with the parent's filter
(where the refinement has the properties it names), IJK slice (the refined cells whose host
cell is in it) and cutting plane. Picks name the refinement and its local I, J, K.

>>> from geoshade.compute.grid.synthetic import synthetic_grid
>>> g = synthetic_grid(4, 3, 2)
>>> hide_hosts(g) is g        # no refinement: the grid as it is
True
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from geoshade.models.grid import CornerPointGrid
from geoshade.render.pick import in_refinement

#: options a refinement's View takes from its parent's as they are
SHARED = ("step", "diff", "plane", "faults", "edges", "cull", "exaggeration", "zcorn_bits",
          "size")


def hide_hosts(grid: CornerPointGrid) -> CornerPointGrid:
    """``grid`` with the host cells of its refinements inactive (their refined cells are drawn
    instead); the grid itself when it has none (or they are hidden already)."""
    return grid.hosts_hidden()


def refined_slice(r, box) -> str | bool | None:
    """The IJK box of refinement ``r``'s cells whose host cell lies in the parent's slice
    ``box`` (``(slice, slice, slice)``): None (all of them), a box text, or False (none)."""
    if box is None:
        return None
    host = np.unravel_index(r.hostnum, _parent_dims(r), order="F")
    inside = np.ones(r.dims, bool)
    for axis, sl in enumerate(box):
        lo, hi = sl.start or 0, sl.stop
        inside &= (host[axis] >= lo) & (hi is None or host[axis] < hi)
    if inside.all():
        return None
    if not inside.any():
        return False
    idx = np.nonzero(inside)
    return ",".join(f"{a}={int(v.min())}:{int(v.max()) + 1}" for a, v in zip("ijk", idx,
                                                                        strict=True))


def _parent_dims(r) -> tuple[int, int, int]:
    return r.grid.meta["parent_dims"]


class RefinedCells:
    """The refinements of a GridView's grid, drawn inside their hosts (see the module)."""

    def __init__(self, parent):
        GridView = type(parent)   # the refinements are drawn by Views of the parent's class
        self.parent = parent
        self.views: dict[str, Any] = {}
        self.shown: dict[str, bool] = {}
        grid = parent.grid
        for r in grid.refinements:
            if r.parent:   # nested refinements: drawn within their parent refinement (later)
                continue
            r = r.placed(grid)   # placed, named and measured as its parent is
            child = r.grid
            opts, shown = self._options(r, parent.options)
            self.views[r.name] = (r, GridView(child, ctx=parent.ctx, **opts))
            self.shown[r.name] = shown
        self._synced = self._state()

    def _options(self, r, o) -> tuple[dict, bool]:
        """A refinement View's options from its parent's ``o`` (and whether it is shown)."""
        g = r.grid
        names = {*g.property_names()}
        out: dict[str, Any] = {k: getattr(o, k) for k in SHARED}
        out.update(annotations=False, sim_wells=False, deck_wells=False, wells=False,
                   approach=3, triad=o.triad)
        out["step"] = o.step if g.steps else None
        out["diff"] = o.diff if g.steps else None
        prop = o.property if o.property in names else None
        out["property"] = prop if prop is not None else "none"
        if prop is None:
            out["diff"] = None
        c = self.parent.colours
        if prop is not None and c.range is not None:   # the parent's colour scale
            out["color"] = dataclasses.replace(
                o.color, range=tuple(c.range), log=c.log,
                colormap=(c.colormap or o.color.colormap).removesuffix("_r"),
                reverse=bool((c.colormap or "").endswith("_r")) or o.color.reverse,
                categorical=c.categories is not None)
        shown = True
        cells = o.cells_filter()
        if cells is not None:   # drawn where the refinement has what the filter names
            upper = {n.upper() for n in names}
            shown = all(n.upper() in upper for n in cells.names)
            out["filter"] = str(cells) if shown else None
        sl = refined_slice(r, o.slice)
        if sl is False:
            shown = False
        else:
            out["slice"] = sl
        return out, shown

    def _state(self) -> tuple:
        c = self.parent.colours
        return (self.parent.options, c.range, c.colormap, c.log)

    def sync(self) -> None:
        """Follow the parent's options and colour scale where they changed since the last
        time (called before each frame and pick: every path of a change is followed)."""
        state = self._state()
        if state == getattr(self, "_synced", None):
            return
        self._synced = state
        for name, (r, view) in self.views.items():
            opts, shown = self._options(r, self.parent.options)
            changes = {k: v for k, v in opts.items() if k not in ("annotations", "approach")}
            view.update(**changes)
            self.shown[name] = shown

    def draw(self, camera, target, count: bool) -> dict:
        """Draw the shown refinements into the parent's frame; their counts added."""
        self.sync()
        out: dict = {}
        for name, (_, view) in self.views.items():
            if not self.shown[name]:
                continue
            got = view._frame(camera, target, count) or {}
            for k, v in got.items():
                if isinstance(v, int | float) and not isinstance(v, bool):
                    out[k] = out.get(k, 0) + v
        return out

    def picks(self, ray, picker) -> list:
        """The hits of ``ray`` (display world) in the shown refinements, by ``picker(view,
        ray)`` (the grid's), each named by its refinement, its local I, J, K and its host."""
        self.sync()
        out = []
        for name, (r, view) in self.views.items():
            hit = picker(view, ray) if self.shown[name] else None
            if hit is not None:
                out.append(in_refinement(hit, r))
        return out

    def stats(self) -> list[dict]:
        return [{"name": name, "cells": int(r.grid.nactive), "shown": self.shown[name],
                 "host_box": r.box_text()} for name, (r, _) in self.views.items()]

    @property
    def gpu_bytes(self) -> int:
        return int(sum(v.gpu_bytes for _, v in self.views.values()))

    def release(self) -> None:
        for _, v in self.views.values():
            v.release()
        self.views.clear()


__all__ = ["RefinedCells", "hide_hosts", "refined_slice"]
