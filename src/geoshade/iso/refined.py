"""Isosurfaces over local grid refinements, drawn inside their hosts.

An IsoView of a grid with refinements (ECLIPSE LGRs: :attr:`CornerPointGrid.refinements`)
marches the global cells with the host cells taken out (inactive, so no triangle of the
global surface crosses a refined region) and, in the same picture and with the same camera,
the refined cells of every refinement of the global grid: one IsoView per refinement on the
parent's GL context, over the refinement's own values of the keyword (its INIT/UNRST
sections) at the same level, step and change, coloured on the parent's colour scale.

Each surface is marched on its own cells, as the grid part draws each refinement's cells: at
the border of a refined region the global surface stops at the last global cell centre before
the hosts and the refined surface at the first refined cell centre, so the two do not join
(a gap of up to one host cell, said in the stats). A refinement without the keyword is left
out and named. Triangles are counted over every surface; the mesh of the picture
(:meth:`IsoView.mesh`) holds them all; a pick names the refinement and its local I, J, K.

>>> from geoshade.compute.grid.synthetic import synthetic_grid
>>> from geoshade.iso.api import field_of
>>> field_of(synthetic_grid(4, 3, 2), "poro").grid.refinements
[]
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from geoshade.iso.api import has_quantity
from geoshade.models.field import TriangleMesh
from geoshade.render.pick import in_refinement

#: what every refinement's surface takes from its parent's options as they are
SHARED = ("diff", "caps", "exaggeration", "mesh_cache", "skip_patches", "patch_level")
#: the note of the stats and the docs: the surfaces are marched apart
SEAM_NOTE = ("the global cells and each refinement are marched on their own cells: their "
             "surfaces stop at their last cell centres (a gap of up to one host cell)")


class RefinedSurfaces:
    """The refinements of an IsoView's grid, their surfaces drawn inside their hosts."""

    def __init__(self, parent):
        IsoView = type(parent)   # each refinement's surface is an IsoView of its own cells
        self.parent = parent
        self.views: dict[str, tuple[Any, Any]] = {}
        #: refinements left out, with the reason (no such keyword in their sections)
        self.missing: dict[str, str] = {}
        #: triangles of each refinement's surface in the last counted frame
        self.triangles: dict[str, int] = {}
        grid = parent.field.grid
        keyword = (parent.model.meta or {}).get("keyword") or parent.model.name
        drawn = grid.meta.get("refinements_drawn") or ()
        for r in grid.refinements:
            if r.name not in drawn:   # its host cells are marched with the global cells
                self.missing[r.name] = (
                    f"nested in {r.parent}" if r.parent else
                    f"one cell thick ({'×'.join(map(str, r.dims))} cells): its hosts are "
                    f"marched with the global cells" if min(r.dims) < 2 else
                    f"no {keyword} in its sections: its hosts are marched with the global "
                    f"cells")
                continue
            r = r.placed(grid)
            opts = self._options(r, keyword)
            self.views[r.name] = (r, IsoView(r.grid, ctx=parent.ctx, **opts))
        self._synced = self._state()

    def _options(self, r, keyword) -> dict:
        """A refinement View's options from its parent's."""
        p, o = self.parent, self.parent.options
        out: dict[str, Any] = {k: getattr(o, k) for k in SHARED}
        out.update(keyword=keyword, level=float(p.level), annotations=False, prefetch=False,
                   size=p.size)
        child_steps = r.grid.steps is not None and len(r.grid.steps) == p.nsteps
        out["step"] = p.step if child_steps else None
        if not child_steps:
            out["diff"] = None
        color_by = p.color_by if p.color_by is not None and has_quantity(r.grid, p.color_by) \
            else None
        out["color_by"] = color_by
        color = o.color
        if color_by is not None and p.color_range is not None:   # the parent's colour scale
            color = dataclasses.replace(color, range=tuple(p.color_range))
        out["color"] = color
        return out

    def _state(self) -> tuple:
        p = self.parent
        return (p.options, p.level, None if p.color_range is None else tuple(p.color_range))

    def sync(self) -> None:
        """Follow the parent's options, level and colour range where they changed since the
        last time (called before each frame, mesh and pick: every path of a change)."""
        state = self._state()
        if state == self._synced:
            return
        self._synced = state
        for _, (r, view) in self.views.items():
            opts = self._options(r, view.options.keyword)
            changes = {k: v for k, v in opts.items() if k not in ("annotations", "size")
                       and getattr(view.options, k, None) != v}
            if changes:
                view.update(**changes)

    def draw(self, camera, target, count: bool) -> dict:
        """Draw the refinements' surfaces into the parent's frame; their counts."""
        self.sync()
        out: dict = {}
        for name, (_, view) in self.views.items():
            got = view._frame(camera, target, count) or {}
            if count:
                self.triangles[name] = int(got.get("triangles") or 0)
            for k, v in got.items():
                if isinstance(v, int | float) and not isinstance(v, bool):
                    out[k] = out.get(k, 0) + v
        return out

    def meshes(self) -> list[TriangleMesh]:
        """Each refinement's surface as the GPU emits it (world coordinates)."""
        self.sync()
        return [view.mesh() for _, (_, view) in self.views.items()]

    def picks(self, ray, picker) -> list:
        """The hits of ``ray`` on the refinements' surfaces, named by the refinement, its local
        I, J, K and the host cell."""
        self.sync()
        out = []
        for r, view in self.views.values():
            hit = picker(view, ray)
            if hit is not None:
                out.append(in_refinement(hit, r))
        return out

    def stats(self) -> list[dict]:
        """One entry per refinement: its active cells, triangles (of the last counted frame)
        and host box; the ones left out with the reason."""
        out = [{"name": name, "cells": int(r.grid.nactive), "host_box": r.box_text(),
                "shown": True, "triangles": self.triangles.get(name)}
               for name, (r, _) in self.views.items()]
        out += [{"name": n, "shown": False, "why": why} for n, why in self.missing.items()]
        return out

    def caption(self) -> str:
        """The picture's word on them: ``LGR2 on refined cells; LGR1 on host cells``."""
        drawn = ", ".join(self.views)
        kept = ", ".join(self.missing)
        return "; ".join(x for x in (f"{drawn} on refined cells" if drawn else "",
                                     f"{kept} on host cells" if kept else "") if x)

    @property
    def gpu_bytes(self) -> int:
        return int(sum(getattr(v, "gpu_bytes", 0) for _, v in self.views.values()))

    def release(self) -> None:
        for _, v in self.views.values():
            v.release()
        self.views.clear()


def merged(meshes: list[TriangleMesh], name: str) -> TriangleMesh:
    """One mesh of several (vertices stacked, faces renumbered); values and normals kept
    where every mesh has them.

    >>> a = TriangleMesh(np.eye(3), [[0, 1, 2]])
    >>> m = merged([a, a], "two")
    >>> m.n_vertices, m.n_faces, m.faces[1].tolist()
    (6, 2, [3, 4, 5])
    """
    verts = [np.asarray(m.vertices, np.float64) for m in meshes]
    offsets = np.cumsum([0, *[len(v) for v in verts[:-1]]])
    faces = np.concatenate([np.asarray(m.faces, np.int64).reshape(-1, 3) + off
                            for m, off in zip(meshes, offsets, strict=True)])
    normals = (np.concatenate([m.normals for m in meshes])
               if all(m.normals is not None for m in meshes) else None)
    values = (np.concatenate([m.values for m in meshes])
              if all(m.values is not None for m in meshes) else None)
    return TriangleMesh(np.concatenate(verts), faces, normals=normals, values=values, name=name)


__all__ = ["SEAM_NOTE", "RefinedSurfaces", "merged"]
