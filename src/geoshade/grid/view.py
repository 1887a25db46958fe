"""``GridView``: a live view of a corner-point grid coloured by a cell property."""

from __future__ import annotations

import dataclasses
import time
from pathlib import Path
from typing import Any

import numpy as np

from geoshade.compute.grid.coarse import faults_inside_blocks, merged_cells
from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.grid.backends import Applied, FacesDrawing, GridSource, HereFaces, PreparedFaces
from geoshade.grid.cells import dynamic_names, property_values, uses_step
from geoshade.grid.colours import GridColours
from geoshade.grid.distributed import ClusterFaces
from geoshade.grid.geometry import (
    demo_wells,
    display_bounds,
    frame_points,
    plane_box,
    world_bounds,
)
from geoshade.grid.lazy import is_lazy
from geoshade.grid.lod import coarse_level
from geoshade.grid.options import GridOptions
from geoshade.grid.refined import RefinedCells, hide_hosts
from geoshade.grid.sources import open_source
from geoshade.grid.wells import GridWells
from geoshade.models.grid import CornerPointGrid
from geoshade.models.names import derived_names
from geoshade.models.steps import step_caption, step_label, step_name
from geoshade.render.progressive import REFINE_LABEL, Preview, Progressive, preview_note
from geoshade.render.view import Job, View, cluster_readout, cluster_summary, fmt_int
from geoshade.styles.annotate import exaggeration_text, join_subtitle
from geoshade.styles.labels import place_labels
from geoshade.styles.options import Plane
from geoshade.styles.shading import shading_uniforms
from geoshade.styles.units import case_unit_system, length_unit, value_unit


class GridView(Progressive, View[GridOptions]):
    """A live view of one corner-point grid; only what changed is redone.

    - ``property``/``step``/``color``: new per-cell colour indices, written into the existing
      colour object (the geometry is not touched); a new step re-filters only when the filter
      names a report-step property (in any case);
    - ``filter``/``slice``/``plane``/``faults``: new visible faces, built by
      :meth:`prepare_faces` (any thread) and uploaded by :meth:`apply_faces`;
    - ``exaggeration`` and a new camera: just draw again.

    The View *uses* a ``source`` (:mod:`geoshade.grid.sources`: memory, indexed or chunked
    store) and a ``drawing`` (:mod:`geoshade.grid.backends`: here, or on the ``scheduler``'s
    cluster with ``distributed=True``) chosen at open; a drawing returns what it prepared. The
    View keeps the options, ``colours`` (:mod:`geoshade.grid.colours`), ``wells``
    (:mod:`geoshade.grid.wells`), the annotations and the stats. Options: see
    :class:`~geoshade.grid.options.GridOptions`; ``progressive=True`` draws the coarse level
    of detail first (:mod:`geoshade.render.progressive`).

    Examples
    --------
    >>> from geoshade.compute.grid.synthetic import synthetic_grid
    >>> view = GridView(synthetic_grid(8, 6, 4), property="PORO", size=(64, 48))
    >>> geometry = view.visual.cache.get("coord")
    >>> view.update(property="permx")                # colour data only, any case
    >>> view.visual.cache.get("coord") is geometry
    True
    >>> img, stats = view.draw()
    >>> view.release()
    >>> stats["property"], img.shape, view.gpu_bytes
    ('PERMX', (48, 64, 4), 0)
    """

    kind = "grid"
    title = "reservoir grid"
    Options = GridOptions
    model_types = (CornerPointGrid,)
    has_exaggeration = True
    #: a counted picture of one frame is that frame: the counting frame draws every face (no
    #: back-face cull) and is the picture (:meth:`pick` looks through it), so no culled frame
    #: is drawn before it; its ``frame_ms`` is that frame's (a first picture of 3.7 M faces:
    #: one llvmpipe frame of ~1.8 s instead of ~1.1 + 1.8 s)
    count_in_frame = True

    options: GridOptions
    source: GridSource
    drawing: FacesDrawing   # None while a preview is drawn, and after release()
    colours: GridColours
    wells: GridWells
    palette: np.ndarray
    colour_indices: Any
    shown_cells: int | None
    plan_bytes: int
    geometry_ms: float
    faces: Any
    _mask: Any

    @classmethod
    def coerce(cls, model, options: dict, progress=None):
        """The grid, showing the medium ``options["medium"]`` asks for (a dual-porosity or
        dual-permeability case's matrix or fracture)."""
        model = super().coerce(model, options, progress)
        medium = options.get("medium")
        # refinements: their host cells hidden, their own cells drawn (grid/refined.py)
        return hide_hosts(model.select_medium(medium) if medium else model)

    @classmethod
    def demo(cls):

        grid = synthetic_grid(24, 18, 8, seed=3)
        grid.meta["wells"] = demo_wells(grid)
        return grid, {"property": "PORO", "edges": True, "exaggeration": 5.0,
                      "wells": grid.meta["wells"]}

    # --- set-up ----------------------------------------------------------------------------------
    def _setup(self) -> None:
        self._init_state()
        self.preview = self._open_preview() if self.options.progressive else None
        if self.preview is None:
            self._open_full(self._drawing())
        self.refined = RefinedCells(self) if self.grid.refinements else None

    def _drawing(self) -> FacesDrawing:
        """A new drawing: on the View's cluster with ``distributed``, else here."""
        if self.options.distributed:
            return ClusterFaces(self.work, self.source, self.origin, self.shading)
        return HereFaces(self.ctx, self.source, self.origin)

    def _open_full(self, drawing: FacesDrawing, prepared: PreparedFaces | None = None) -> None:
        """Open ``drawing`` (its first faces ``prepared`` on another thread, or None), wells."""
        self.drawing = drawing
        t0 = time.perf_counter()
        plan = self.colours.plan(self.options)
        self.colors_ms = (time.perf_counter() - t0) * 1000
        self._applied(drawing.open(self.options, plan, prepared))   # the refine job's faces
        self.wells.make(self.options)
        self.wells.make_sim(self.options)

    def _applied(self, out: Applied) -> None:
        """Make what the drawing applied current (its faces' options, mask, counts, times)."""
        if out.changes is not None:
            self._set(**{k: v for k, v in out.changes.items() if k != "step"})
            self.faces_ms = out.faces_ms
        self._mask, self.faces, self.n_faceset = out.mask, out.faces, out.n_faceset
        self.shown_cells, self.palette = out.shown, self.drawing.palette
        self.geometry_ms = self.geometry_ms if out.geometry_ms is None else out.geometry_ms
        self.plan_bytes = self.plan_bytes if out.plan_bytes is None else out.plan_bytes
        self.colour_indices = self.colour_indices if out.colours is None else out.colours

    # --- progressive: the coarse level of detail first --------------------------------------
    def _open_preview(self) -> Preview | None:
        """A preview View of :func:`~geoshade.grid.lod.coarse_level` with this View's
        options, colour range and framing; None where there is none to draw."""
        g, o = self.grid, self.options
        coarse, self._no_preview = coarse_level(g)
        if coarse is None:
            return None
        f = int(coarse.meta["lod"]["factor"])
        c = self.colours
        c.plan(o)   # the full grid's colour range, log and categories
        color = o.color
        if c.categories is None and c.range is not None and color.range is None:
            color = color.with_(range=c.range, log=c.log)
        sl = tuple(slice(s.start // f, -(-s.stop // f)) for s in o.slice)
        note = preview_note(f"cells {f}×{f}×{f}", f)
        if faults_inside_blocks(g.faults, g.dims, f):   # their throw is smoothed away
            note += " · faults inside merged cells smoothed"
        view = GridView(coarse, ctx=self.ctx, options=o, progressive=False, scheduler=None,
                        distributed=False, parts=None, sim_wells=False, slice=sl, color=color)
        view.preview_note = note
        return Preview(view, 1, f, note, lambda cell: merged_cells(cell, f, g.dims))

    def refine_job(self) -> Job:
        """A :class:`Job`: the full grid's faces (CPU half, any thread), then its GPU objects
        and wells; the preview is released when it is applied."""
        return Job(self.refine_key(), REFINE_LABEL, self._refine_faces, self._apply_refined)

    def _refine_faces(self, progress=None):
        drawing = self._drawing()
        here = isinstance(drawing, HereFaces)   # a cluster prepares on its workers
        return drawing, (drawing.prepare(self.options) if here else None)

    def _apply_refined(self, result) -> None:
        self._drop_preview()
        self._open_full(*result)

    def _init_state(self) -> None:
        """The View's state before any face or GPU object."""
        self.grid = self.model
        self.lazy = is_lazy(self.grid)
        self.shading = shading_uniforms()
        self.palette = self.options.color.palette_rgba()
        self.origin = display_bounds(self.grid).mean(axis=0)
        self.source = open_source(self.grid, self.work, self.progress)
        self.drawing = None   # type: ignore[assignment]
        self.colours = GridColours(self.grid)
        self.wells = GridWells(self.ctx, self.grid)
        self._ranges: dict = {}   # property_ranges by step
        self._mask = self.faces = self.colour_indices = None
        self.shown_cells, self.n_faceset, self.plan_bytes = None, 0, 0
        self.colors_ms = self.faces_ms = self.geometry_ms = 0.0

    @property
    def visual(self):
        """The GridVisual of a drawing in this process (None on a cluster)."""
        return None if self.drawing is None else self.drawing.visual

    # --- colours ---------------------------------------------------------------------------------
    def property_names(self) -> list[str]:
        """The properties the grid can be coloured by (derived ones such as SOIL included)."""
        return [*self.grid.property_names(), *derived_names(self.grid)]

    @property
    def nsteps(self) -> int:
        return len(self.grid.steps)

    def section_plane(self, axis: str, fraction: float, flip: bool = False) -> Plane:
        """The plane across ``axis`` (x east, y north, z up) at ``fraction`` of the active
        cells' box, keeping the near side (the far side with ``flip``): the section control."""
        return Plane.across(plane_box(self.grid), axis, fraction, flip)

    def property_ranges(self) -> dict[str, tuple[float, float]]:
        """``{name: (min, max)}`` of the finite values on the active cells at the shown step,
        of every property held in memory (a store's are read chunk by chunk: none here): the
        range sliders. Remembered per step."""
        step = self.options.step
        if step not in self._ranges:
            g, out = self.grid, {}
            active = np.asarray(g.active, bool)
            for name in self.property_names():
                arr = (g.steps[step or 0].get(name) if g.steps else None) if \
                    name not in g.properties else g.properties[name]
                if not isinstance(arr, np.ndarray) or arr.shape != active.shape:
                    continue
                v = arr[active]
                v = v[np.isfinite(v)] if v.dtype.kind == "f" else v
                if v.size:
                    out[name] = (float(v.min()), float(v.max()))
            self._ranges[step] = out
        return self._ranges[step]

    def values(self, name: str, step: int | None) -> np.ndarray:
        """(nx, ny, nz) values of property or expression ``name`` at report ``step``
        (:func:`~geoshade.grid.cells.property_values`); of the property drawn as a difference
        (``diff``), the change drawn."""
        o = self.options
        return property_values(self.grid, name, step, o.diff if name == o.property else None)

    def uses_step(self, name: str | None) -> bool:
        """True when property (or expression) ``name`` changes with the report step."""
        return uses_step(self.grid, name)

    def update_colours(self) -> None:
        """Colour the drawn cells by the options' colours (the drawing uploads colour only)."""
        t0 = time.perf_counter()
        plan = self.colours.plan(self.options)
        ci = self.drawing.colours(self.options, plan)
        self.colour_indices = ci if ci is not None else self.colour_indices
        self.palette = self.drawing.palette
        self.colors_ms = (time.perf_counter() - t0) * 1000

    # --- faces -----------------------------------------------------------------------------------
    def shown_mask(self, options: GridOptions | None = None):
        """(nx, ny, nz) bool: active cells inside the slice, passing the filter and on the kept
        side of the plane of ``options`` (default: the current ones; a dask array for a grid
        store)."""
        return self.source.shown_mask(options or self.options)

    def prepare_faces(self, **changes) -> PreparedFaces:
        """CPU half of a change of ``filter``, ``slice``, ``plane`` or ``faults``: the cells
        shown and their visible faces, by the View's drawing. No GL: safe on a worker thread
        (a viewer keeps its window alive this way); errors leave the view as it was."""
        return self.drawing.prepare(self.options.replace(self.grid, **changes))

    def apply_faces(self, prepared: PreparedFaces) -> None:
        """GL half: upload the faces of :meth:`prepare_faces` and make its options current."""
        assert self.colours.current is not None, "faces applied before the View opened"
        self._applied(self.drawing.apply(prepared, self.colours.current))

    def faces_job(self, **changes) -> Job:
        """A :class:`Job` for new visible faces (a 1e8-cell grid takes seconds)."""
        return Job("grid-faces", "visible faces",
                   lambda progress: self.prepare_faces(**changes), self.apply_faces,
                   applies={k: v for k, v in changes.items() if k != "step"})

    # --- wells -----------------------------------------------------------------------------------
    def has_sim_wells(self) -> bool:
        """True when the case's restart file has simulation wells (at some report step)."""
        return self.wells.has_sim()

    def well_labels(self, camera, size) -> list:
        """The shown wells' names (:meth:`~geoshade.grid.wells.GridWells.labels`)."""
        return self.wells.labels(camera, size, self.options.step)

    # --- changes ---------------------------------------------------------------------------------
    def _apply_options(self, new: GridOptions, changed: set[str]) -> list[Job]:

        if self.preview is not None:   # loading: a new preview now, a new full build after
            self.options = new
            if changed <= {"camera", "size", "background", "transparent", "annotations"}:
                return []
            self._drop_preview()
            self.colours.clear()
            self.preview = self._open_preview()
            return [self.refine_job()]
        old = self.options
        faces = {k for k in ("filter", "ranges", "slice", "plane", "faults") if k in changed}
        shown = new.cells_filter()
        step_refilter = ("step" in changed and new.step != old.step and shown is not None
                         and shown.uses(dynamic_names(self.grid)))
        # what the faces job applies stays as it is until the job is applied
        self.options = dataclasses.replace(new, **{k: getattr(old, k) for k in faces})
        if {"approach", "zcorn_bits", "zcorn_store", "smear_faults"} & changed:
            # new GPU objects, colours and faces
            self._applied(self.drawing.remake(self.options, self.colours.plan(self.options)))
        else:
            # a new step changes the colours only of a report-step property (or expression)
            if {"property", "color", "diff"} & changed or (
                    "step" in changed and self.uses_step(new.property)):
                self.update_colours()
            if {"edges", "cull"} & changed:
                self.drawing.drawing_changed(self.options)
        if {"wells", "wells_coords", "well_radius", "exaggeration"} & changed:
            self.wells.make(self.options)
        if {"sim_wells", "step", "well_radius", "exaggeration"} & changed:
            self.wells.make_sim(self.options)
        if faces or step_refilter:
            return [self.faces_job(**{k: getattr(new, k) for k in faces | {"step"}})]
        return []

    # --- drawing ---------------------------------------------------------------------------------
    def bounds(self) -> np.ndarray:
        return world_bounds(self.grid, self.options.exaggeration)

    def frame_points(self) -> np.ndarray:
        return frame_points(self.grid, self.options.exaggeration)

    def _frame(self, camera, target, count: bool) -> dict:
        out = self.drawing.draw(camera, target, count, self.options, self.shading) or {}
        if self.refined is not None and self.preview is None:   # refined cells in their hosts
            more = self.refined.draw(camera, target, count)
            out = {**out, **{k: out.get(k, 0) + v for k, v in more.items()}}
        self.wells.draw(camera, target, self.shading, self.options)
        return out

    def method_name(self) -> str:
        return self.drawing.method()

    def _stats(self, counts: dict) -> dict:
        g, o = self.grid, self.options
        s = {
            "cells": int(g.ncells), "active_cells": int(g.nactive),
            "shown_cells": (int(np.count_nonzero(self._mask)) if self.shown_cells is None
                            else self.shown_cells),
            "faceset_faces": self.n_faceset,
            "faces_drawn": counts.get("faces_drawn"), "triangles": counts.get("triangles"),
            "gpu_memory": o.gpu_memory, "property": o.property, "step": o.step,
            "unit": value_unit(g, o.property), "unit_system": case_unit_system(g),
            "step_label": None if o.step is None else step_label(
                o.step, g.step_dates, g.meta.get("unrst_seqnum") or ()),
            "step_date": (g.step_dates[o.step] if o.step is not None
                          and len(g.step_dates) > o.step else None),
            **self.colours.stats(), "colormap": self.colours.colormap or o.color.colormap,
            "diff": None if o.diff is None else {
                "step": o.step, "from": o.diff,
                "dates": [g.step_dates[k] if len(g.step_dates) > k else None
                          for k in (o.step, o.diff)]},
            "inverted_cells": int(g.meta.get("inverted_cells") or 0),
            "filter": None if o.filter is None else str(o.filter),
            "ranges": None if o.ranges is None else o.ranges.as_dict(),
            "plane": None if o.plane is None else o.plane.text(),
            "faults": o.faults, "cull": o.cull, "exaggeration": o.exaggeration,
            "geometry_ms": round(self.geometry_ms, 3), "faces_ms": round(self.faces_ms, 3),
            "colors_ms": round(self.colors_ms, 3),
        }
        drawn = self.drawing.stats(o)   # faces, approach, depth code, GPU plan, cluster
        notes = [*self.colours.notes, *drawn.pop("notes", [])]
        s.update(drawn)
        s.update(self.wells.stats(o))
        if self.refined is not None:
            s["refinements"] = self.refined.stats()
        if notes:
            s["notes"] = list(dict.fromkeys(notes))
        return s

    # --- annotations -----------------------------------------------------------------------------
    def annotations(self, camera, stats: dict, size=None):
        """The base annotations plus the names of the wells at their heads."""
        ann = super().annotations(camera, stats, size)
        labels = self.well_labels(camera, size or self.size)
        if not labels:
            return ann
        placed = place_labels(labels, size or self.size)   # moved or hidden: no overlap
        stats["well_labels"] = len(placed.labels)
        stats["well_labels_moved"] = placed.moved
        stats["well_labels_hidden"] = len(placed.hidden)
        return dataclasses.replace(ann, labels=placed.labels, subtitle=join_subtitle(
            ann.subtitle, placed.note("well labels")))

    def _title(self, stats: dict) -> tuple[str, str]:
        g, o = self.grid, self.options
        name = Path(g.name).name if g.name else "corner-point grid"
        if g.media:   # a dual-porosity/permeability case: which medium is shown
            name += f" ({g.medium})"
        if g.meta.get("index_space"):   # no geometry in the deck: unit cells
            name += " (IJK index space)"
        prop = o.property or "cells"
        if o.diff is not None and o.property is not None:   # a change: both steps named
            dates, reports = g.step_dates, g.meta.get("unrst_seqnum") or ()
            prop = (f"{o.property} change, {step_name(o.step, dates, reports)} − "
                    f"{step_name(o.diff, dates, reports)}")
        filt = "".join(f" · {c}" for c in (o.filter, o.ranges and o.ranges.caption()) if c)
        # the step only where the colours or the cells shown change with it (a static
        # property is titled without it, also when restart wells are drawn)
        cells = o.cells_filter()
        shown_by_step = self.uses_step(o.property) or (
            cells is not None and cells.uses(dynamic_names(g)))
        step = "" if o.step is None or not shown_by_step else step_caption(
            o.step, self.nsteps, g.step_dates, g.meta.get("unrst_seqnum") or ())
        gaps = self.colours.no_value_cells
        return f"{name} — {prop}{filt}", self._preview_subtitle(join_subtitle(
            step, exaggeration_text(o.exaggeration),
            f"{gaps:,} cells without a value" if gaps else ""))

    def _color_key(self, stats: dict):
        return self.colours.key(self.options, self.palette)

    def _triad(self):
        if self.options.triad != "ijk" and not self.grid.meta.get("index_space"):
            return ("E", "N", "Up"), None
        g = self.grid
        c = np.asarray(g.coord, float)
        t = g.map_transform()
        top = c[..., :3]

        def world(d):
            return np.array([*(t[:2, :2] @ d[:2]), -d[2] * self.options.exaggeration])

        i = world(top[-1, 0] - top[0, 0])
        j = world(top[0, -1] - top[0, 0])
        return ("I", "J", "K"), np.stack([i, j, np.array([0.0, 0.0, -1.0])])

    def _length_unit(self) -> str:
        if self.grid.meta.get("index_space"):
            return "cells"
        return length_unit(self.grid.units) or "m"

    def _notes(self, stats: dict) -> list[tuple[str, type[Warning]]]:
        none = getattr(self, "_no_preview", "")   # set by a progressive View
        return [*self.drawing.notes(self.options), *([(none, UserWarning)] if none else [])]

    def _empty_reason(self, stats: dict) -> str | None:
        if stats["faces"]:
            return None
        return "empty view: no cell passes the filter, slice and plane"

    def readout(self, stats: dict) -> str:
        prop = stats.get("property") or "no property"
        step = "" if stats.get("step") is None else f" {stats.get('step_label')}"
        drawn = stats.get("faces_drawn")
        wells = f" · {stats['wells']} wells" if stats.get("wells") else ""
        if stats.get("sim_wells"):
            wells += f" · {stats['sim_wells']} sim wells ({stats['sim_wells_open']} open)"
        return (f"{prop}{step} · {fmt_int(stats.get('shown_cells'))} of "
                f"{fmt_int(stats.get('active_cells'))} cells · "
                f"{'…' if drawn is None else fmt_int(drawn)} faces{wells}"
                + cluster_readout(stats))

    def summary(self, stats: dict) -> str:
        prop = stats["property"] or "no property"
        step = "" if stats["step"] is None else f" {stats['step_label']}"
        return (f"{stats['width']}x{stats['height']} {stats['method']}, {prop}{step}, "
                f"{stats['shown_cells']} of {stats['active_cells']} active cells shown, "
                f"{stats['faces_drawn']} faces, {stats['frame_ms']:.1f} ms/frame, "
                f"{stats['gpu_bytes'] / 2**20:.2f} MiB on the GPU"
                + cluster_summary(stats, "parts"))

    # --- lifetime --------------------------------------------------------------------------------
    def _gpu_objects(self) -> list:
        preview = getattr(self, "preview", None)
        return [o for o in (getattr(self, "drawing", None), getattr(self, "wells", None),
                            getattr(self, "refined", None),
                            preview.view if preview is not None else None) if o is not None]

    def _release_part(self) -> None:
        self.drawing = None   # type: ignore[assignment]
        self.preview = None


__all__ = ["GridView", "PreparedFaces"]
