"""``GridView``: a live view of a corner-point grid coloured by a cell property."""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from geoshade.compute.grid_filter import Expression, is_expression
from geoshade.grid.cells import colour_indices, fault_faces, property_values
from geoshade.grid.geometry import (
    display_bounds,
    frame_points,
    grid_bounds,
    model_matrix,
    world_bounds,
    world_points,
)
from geoshade.grid.lazy import is_lazy, values_at
from geoshade.grid.options import GridOptions, step_names
from geoshade.models.grid import CornerPointGrid
from geoshade.models.steps import step_label
from geoshade.render.view import Job, View, fmt_int

#: the colour index of every cell when no property is shown (the colour map's middle)
UNIFORM_INDEX = 160
#: an integer property with at most this many values is shown with a legend, not a colour bar
CATEGORIES = 24
#: a grid out of core: up to this many faces, their corner depths are gathered while the faces
#: are prepared (16 bytes a face); more are gathered batch by batch while they are uploaded
LAZY_CORNERS_AHEAD = 1 << 24
#: smallest simulation-well pipe radius, as a fraction of a cell's horizontal diagonal
SIM_WELL_CELL_RADIUS = 0.08


def dynamic_names(grid) -> list[str]:
    """Report-step properties, the derived ones (SOIL) included."""
    from geoshade.models.names import derived_names

    return [*step_names(grid), *derived_names(grid)]


@dataclass
class PreparedFaces:
    """Visible faces built on the CPU for a filter/slice/plane/faults change (see
    :meth:`GridView.prepare_faces`), ready for :meth:`GridView.apply_faces`."""

    changes: dict
    mask: np.ndarray
    faces: Any
    cells: np.ndarray
    face: np.ndarray
    highlight: np.ndarray | None
    ms: float
    corners: Any = None                 # (n, 4) corner depths, or corners(sel) (out of core)
    shown: int | None = None            # shown cells (counted once for a grid out of core)


class GridView(View[GridOptions]):
    """A live view of one corner-point grid; only what changed is redone.

    - ``property``/``step``/``color``: new per-cell colour indices, written into the existing
      colour object (the geometry is not touched); a new step re-filters only when the filter
      names a report-step property (in any case);
    - ``filter``/``slice``/``plane``/``faults``: new visible faces from the grid in memory
      (nothing is read again), built by :meth:`prepare_faces` (any thread) and uploaded by
      :meth:`apply_faces`;
    - ``exaggeration`` and a new camera: just draw again.

    Options: see :class:`~geoshade.grid.options.GridOptions`.

    Examples
    --------
    >>> from geoshade.compute.synthetic_grid import synthetic_grid
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

    options: GridOptions
    visual: Any
    wells_visual: Any
    sim_wells_visual: Any
    sim_shapes: Any
    faces: Any
    _mask: Any
    _centres: Any

    @classmethod
    def demo(cls):
        from geoshade.compute.synthetic_grid import synthetic_grid
        from geoshade.grid.geometry import demo_wells

        grid = synthetic_grid(24, 18, 8, seed=3)
        grid.meta["wells"] = demo_wells(grid)
        return grid, {"property": "PORO", "edges": True, "exaggeration": 5.0,
                      "wells": grid.meta["wells"]}

    # --- set-up ----------------------------------------------------------------------------------
    def _setup(self) -> None:
        self._init_state()
        prepared = self.prepare_faces()  # CPU: the faces, so the plan is known before GL
        self._check_plan(prepared)
        self._make_visual()
        if self.visual.color_cells() is None:  # per cell or node: all cells, before the faces
            self._update_colors()
        self.apply_faces(prepared)
        self._make_wells()
        self._make_sim_wells()

    def _init_state(self) -> None:
        """The View's state before any face or GPU object (shared with the distributed grid)."""
        from geoshade.styles.shading import shading_uniforms

        self.grid = self.model
        self.lazy = is_lazy(self.grid)
        if self.lazy:  # what a grid out of core cannot be drawn with: one line, before work
            from geoshade.grid.lazy import check_options

            check_options(self.grid, self.options)
        self.shading = shading_uniforms()
        self.palette = self.options.color.palette_rgba()
        self.origin = display_bounds(self.grid).mean(axis=0)
        self.visual = None
        self.wells_visual = self.sim_wells_visual = self.sim_shapes = None
        self._centres = None
        self._mask = None
        self._shown: int | None = None
        self._summaries: dict = {}
        self.faces = None
        self.n_faceset = 0
        self.colors_ms = self.faces_ms = 0.0
        self.color_range: tuple[float, float] | None = None
        self.color_log = self.log_auto = False
        self.no_value_cells = 0
        self.notes: list[str] = []

    def _check_plan(self, prepared) -> None:
        """The chosen approach's GPU bytes for these faces (``plan_bytes``), refused in one
        line when larger than the ``gpu_memory`` option — before any GPU object exists."""
        from geoshade.grid.plan import cells_with_faces, check_fits
        from geoshade.render.visuals.grid.layout import gpu_plan

        o = self.options
        drawn = cells_with_faces(prepared.cells, self.grid.dims) if o.approach == 2 else 0
        self.plan_bytes = int(sum(gpu_plan(o.approach, self.grid.dims, len(prepared.face),
                                           drawn, o.zcorn_bits, o.zcorn_store).values()))
        check_fits(self.plan_bytes, o.gpu_memory, o.approach,
                   o.zcorn_store if o.approach == 3 else None,
                   self.grid.name or "grid")

    def _make_visual(self) -> None:
        from geoshade.compute.grid_geometry import zcorn_quantise
        from geoshade.render.visuals.grid.visual import EdgeStyle, GridVisual

        o = self.options
        if self.visual is not None:
            self.visual.release()
            self.visual = None
        t0 = time.perf_counter()
        quantised = None
        if o.approach == 3 and o.zcorn_store == "faces" and o.zcorn_bits == 16:
            quantised = (None, *self._face_depth_code(), None)
        elif o.approach != 1 and o.zcorn_bits == 16:
            quantised = zcorn_quantise(np.asarray(self.grid.zcorn), bits=16)
        self.visual = GridVisual(self.ctx, self.grid, self.origin, approach=o.approach,
                                 zcorn_bits=o.zcorn_bits, zcorn_store=o.zcorn_store,
                                 quantised=quantised, palette=self.palette,
                                 smear_faults=o.smear_faults, orientation=self._orientation())
        self.geometry_ms = (time.perf_counter() - t0) * 1000
        self.edge_style = EdgeStyle(mode=o.edges)

    def _face_depth_code(self) -> tuple[float, float]:
        """``(z0, scale)`` of the 16-bit depth code of approach 3 with faces: only the drawn
        faces' corners are quantised (no 16-bit copy of ZCORN)."""
        from geoshade.compute.grid_geometry import zcorn_quantiser

        zb = grid_bounds(self.grid)[:, 2]
        z0, scale = zcorn_quantiser(float(zb[0]), float(zb[1]), 16)[:2]
        return float(z0), float(scale)

    def _orientation(self) -> float | None:
        """The back-face sign of a grid out of core, from a sample of cells read chunk by chunk;
        None for a grid in memory (the visual takes it from the whole grid)."""
        if not self.lazy:
            return None
        from geoshade.grid.lazy import orientation

        return float(orientation(self.grid))

    # --- colours ---------------------------------------------------------------------------------
    def property_names(self) -> list[str]:
        """The properties the grid can be coloured by (derived ones such as SOIL included)."""
        from geoshade.models.names import derived_names

        return [*self.grid.property_names(), *derived_names(self.grid)]

    @property
    def nsteps(self) -> int:
        return len(self.grid.steps)

    def values(self, name: str, step: int | None) -> np.ndarray:
        """(nx, ny, nz) values of property ``name`` (at report ``step`` when it has steps;
        SOIL = 1 - SWAT - SGAS where the case has no SOIL), or of an expression over the
        properties (``"log10(PERMX)"``; undefined results are NaN)."""
        return property_values(self.grid, name, step)

    def uses_step(self, name: str | None) -> bool:
        """True when property (or expression) ``name`` changes with the report step."""
        if name is None:
            return False
        dynamic = dynamic_names(self.grid)
        return name in dynamic or (is_expression(name) and Expression.parse(name).uses(dynamic))

    def _summary(self, name: str, step: int | None, values: np.ndarray):
        """:class:`~geoshade.compute.cell_values.ValueSummary` of ``values`` over the active
        cells, remembered per property (and report step where it has them)."""
        from geoshade.compute.cell_values import summarise

        key = (name, step if self.uses_step(name) else None)
        if key not in self._summaries:
            # a grid store's own array: the summary stored at ingest (no pass over it)
            stored = None
            if self.lazy:
                from geoshade.grid.lazy import stored_summary

                stored = stored_summary(self.grid, values)
            # a grid store's ACTNUM stays lazy (read chunk by chunk with the property)
            active = self.grid.actnum if self.lazy else self.grid.active
            self._summaries[key] = stored if stored is not None else summarise(values, active)
        return self._summaries[key]

    def _update_colors(self) -> None:
        """Colour indices of the options' property/step/colour style for the cells the GPU
        holds colours of (those with a visible face, for approaches 2 and 3 with faces),
        uploaded (colour only).  The range, the log decision and the count of cells without a
        value come from every active cell (:meth:`_summary`), so they never depend on the
        filter or slice."""

        o, g = self.options, self.grid
        t0 = time.perf_counter()
        need = self.visual.color_cells()
        state, palette = self._colour_state()
        if state is None or o.property is None:
            ci = np.full(g.ncells if need is None else need.size, UNIFORM_INDEX, np.uint8)
        else:
            full = self.values(o.property, o.step)
            # the drawn cells' values (a grid store: read only from the chunks holding them)
            v = (np.asarray(full).ravel(order="F") if need is None
                 else values_at(full, need, g.dims))
            style, lo, hi, gaps = state
            ci = colour_indices(style, lo, hi, gaps, v)
        if palette.tobytes() != self.palette.tobytes():
            self.palette = palette
            self.visual.set_palette(palette)
        # the colour indices of the cells the GPU holds colours of (``cells``: None = all)
        self.colour_indices = (ci, need)
        self.visual.set_colors(ci, cells=need)
        self.ctx.finish()
        self.colors_ms = (time.perf_counter() - t0) * 1000

    def _colour_state(self) -> tuple[tuple | None, np.ndarray]:
        """``((style, lo, hi, gaps) or None, palette)`` of the options' property/step/colour:
        what :func:`colour_indices` needs besides the values (None: no property, one uniform
        colour), and the palette; sets the colour bar's range, log and the notes."""
        o, g = self.options, self.grid
        self.notes = []
        palette = o.color.palette_rgba()
        self.no_value_cells = 0
        if o.property is None:
            self.color_range = None
            return None, palette
        full = self.values(o.property, o.step)
        summary = self._summary(o.property, o.step, full)
        style, self.log_auto = o.color.resolved(o.property, summary.extremes(log=True))
        if style.range is not None:
            lo, hi = style.range
        else:
            lo, hi = style.default_range(summary.extremes(bool(style.log)))
        gaps = summary.gaps(bool(style.log))
        nan = bool(gaps and style.solid is None and style.palette is None)
        if nan:  # cells without a value get the NaN colour (entry 255), the others 0..254
            palette = style.nan_palette()
            self.no_value_cells = gaps
        self.color_range = (lo, hi)
        self.color_log = bool(style.log)
        if self.uses_step(o.property) and o.step == len(g.steps) - 1 and len(g.steps) > 1:
            self.notes.append(f"{o.property} is a report-step property: the last step "
                              f"({step_label(o.step, g.step_dates)}) is shown")
        return (style, float(lo), float(hi), nan), palette

    # --- faces -----------------------------------------------------------------------------------
    def filter_properties(self, options: GridOptions | None = None):
        """Static properties and those of the current report step, read only when the filter
        names them (report steps may be lazy mappings over the UNRST file)."""
        o = options or self.options
        return self._properties_at(o.step or 0)

    def _properties_at(self, k: int):
        """Static, report-step ``k`` and derived properties: one mapping whose values are read
        (or computed) only when looked up (:func:`geoshade.models.names.properties_at`)."""
        from geoshade.models.names import properties_at

        return properties_at(self.grid, k)

    def shown_mask(self, options: GridOptions | None = None) -> np.ndarray:
        """(nx, ny, nz) bool: active cells inside the slice, passing the filter and on the kept
        side of the plane of ``options`` (default: the current ones)."""
        from geoshade.compute.grid_geometry import cell_centres

        g, o = self.grid, options or self.options
        mask = g.active.copy()
        box = np.zeros(g.dims, bool)
        box[o.slice] = True
        mask &= box
        if o.filter is not None:
            mask &= np.asarray(o.filter.mask(self.filter_properties(o), g.dims), bool)
        if o.plane is not None:
            if self._centres is None:
                c = np.asarray(cell_centres(g), np.float64).reshape(*g.dims, 3)
                t = g.map_transform()
                xy = c[..., :2] @ t[:2, :2].T + t[:2, 2]
                self._centres = np.concatenate([xy, -c[..., 2:]], axis=-1)  # z up
            mask &= o.plane.keeps(self._centres.reshape(-1, 3)).reshape(g.dims)
        return mask

    def prepare_faces(self, **changes) -> PreparedFaces:
        """CPU half of a change of ``filter``, ``slice``, ``plane`` or ``faults``: the cells
        shown and their visible faces, from the grid in memory. No GL: safe on a worker thread
        (a viewer keeps its window alive this way); errors leave the view as it was."""
        from geoshade.compute.grid_faces import visible_faces

        t0 = time.perf_counter()
        o = self.options.replace(self.grid, **changes)
        if self.lazy:
            return self._prepare_lazy(o, t0)
        mask = self.shown_mask(o)
        fs = visible_faces(self.grid, shown=mask)
        return self._prepared(o, mask, fs, t0)

    def _prepare_lazy(self, o: GridOptions, t0: float) -> PreparedFaces:
        """:meth:`prepare_faces` of a grid out of core: the shown mask as dask blocks, the
        faces chunk by chunk with a one-cell halo, the corner depths of the drawn faces
        gathered from their ZCORN chunks (:mod:`geoshade.grid.lazy`)."""
        from geoshade.compute.grid_chunks import (
            face_corner_depths,
            shown_mask_lazy,
            visible_faces_chunked,
        )
        from geoshade.compute.grid_faces import FaceCount
        from geoshade.grid.lazy import check_options

        check_options(self.grid, o)
        mask = shown_mask_lazy(self.grid, o.filter, o.slice, step=o.step)
        fs = visible_faces_chunked(self.grid, shown=mask, progress=self.progress,
                                   scheduler=self.work)   # the View's cluster, kept up
        prepared = self._prepared(o, mask, fs, t0)  # assembled in drawing order
        # only the drawn faces' cells and codes are kept: the other columns go now
        prepared.faces = FaceCount(len(fs), fs.shown)
        del fs
        zcorn, cells, face = self.grid.zcorn, prepared.cells, prepared.face
        if face.size <= LAZY_CORNERS_AHEAD:  # gathered here (a viewer's worker thread)
            prepared.corners = face_corner_depths(zcorn, cells, face)
        else:  # batch by batch while the records are built (no (n, 4) array)
            prepared.corners = lambda sel: face_corner_depths(zcorn, cells[sel], face[sel])
        prepared.shown = prepared.faces.shown  # counted chunk by chunk with the faces
        prepared.ms = (time.perf_counter() - t0) * 1000
        return prepared

    def _prepared(self, o: GridOptions, mask, fs, t0: float) -> PreparedFaces:
        cells, face, hl = fault_faces(fs, o.faults)
        applied = {k: getattr(o, k) for k in ("filter", "slice", "plane", "faults", "step")}
        return PreparedFaces(applied, mask, fs, cells, face, hl,
                             (time.perf_counter() - t0) * 1000)

    def apply_faces(self, prepared: PreparedFaces) -> None:
        """GL half: upload the faces of :meth:`prepare_faces` and make its options current."""
        t0 = time.perf_counter()
        self.visual.set_faces(prepared.cells, prepared.face, prepared.highlight,
                              corners=prepared.corners)
        if self.lazy:  # the faces are on the GPU: their CPU columns go before the colours
            prepared.cells, prepared.face = np.zeros((0, 3), np.int32), np.zeros(0, np.uint8)
            prepared.highlight = prepared.corners = None
        self._shown = prepared.shown
        if self.visual.color_cells() is not None:  # colours of the newly visible cells
            self._update_colors()
        self.ctx.finish()
        self._set(**{k: v for k, v in prepared.changes.items() if k != "step"})
        self._mask, self.faces = prepared.mask, prepared.faces
        self.n_faceset = len(prepared.faces)
        self.faces_ms = prepared.ms + (time.perf_counter() - t0) * 1000

    def faces_job(self, **changes) -> Job:
        """A :class:`Job` for new visible faces (a 1e8-cell grid takes seconds)."""
        return Job("grid-faces", "visible faces",
                   lambda progress: self.prepare_faces(**changes), self.apply_faces,
                   applies={k: v for k, v in changes.items() if k != "step"})

    # --- wells ---------------------------------------------------------------------------------
    def _well_radius(self) -> float:
        """The tube radius (world units): the option's, else 0.4 % of the grid's diagonal."""
        o = self.options
        wb = world_bounds(self.grid, o.exaggeration)
        self._wells_origin = wb.mean(axis=0)
        return (o.well_radius if o.well_radius is not None
                else 0.004 * float(np.linalg.norm(wb[1] - wb[0])))

    def _make_wells(self) -> None:
        from geoshade.render.visuals.wells.visual import WellsVisual

        o = self.options
        if self.wells_visual is not None:
            self.wells_visual.release()
            self.wells_visual = None
        if not o.wells:
            return
        exag = o.exaggeration
        r = self._well_radius()
        paths = [world_points(self.grid, w.points, exag, o.wells_coords) - self._wells_origin
                 for w in o.wells]
        markers = [world_points(self.grid, w.markers, exag, o.wells_coords)
                   - self._wells_origin for w in o.wells if len(w.markers)]
        self.wells_visual = WellsVisual(self.ctx, paths, markers, radius=r)

    def has_sim_wells(self) -> bool:
        """True when the case's restart file has simulation wells (at some report step)."""
        from geoshade.io.grids.restart_wells import has_restart_wells

        return bool(self.grid.steps) and has_restart_wells(self.grid)

    def sim_wells(self):
        """The simulation wells of the shown report step
        (:class:`~geoshade.models.wells.SimWells`, read from the restart file on first use), or
        None when the case has none."""
        from geoshade.io.grids.restart_wells import restart_wells

        index = restart_wells(self.grid) if self.options.step is not None else None
        return None if index is None or not len(index) else index[self.options.step]

    def _make_sim_wells(self) -> None:
        """The pipes of the simulation wells of the shown step (IWEL/ICON/ZWEL of that step
        only are read)."""
        from geoshade.grid.geometry import sim_well_shapes
        from geoshade.render.visuals.wells.visual import WellsVisual

        o = self.options
        if self.sim_wells_visual is not None:
            self.sim_wells_visual.release()
        self.sim_wells_visual = self.sim_shapes = None
        wells = self.sim_wells() if o.sim_wells else None
        if wells is None:
            return
        shapes = sim_well_shapes(self.grid, wells, o.exaggeration)
        r = self._well_radius()
        if o.well_radius is None:  # at least a tenth of a cell: pipes read on coarse grids
            b = display_bounds(self.grid)
            nx, ny, _ = self.grid.dims
            r = max(r, SIM_WELL_CELL_RADIUS * float(np.hypot(*(b[1, :2] - b[0, :2])))
                    / float(np.hypot(nx, ny)))
        origin = self._wells_origin
        self.sim_shapes = shapes
        if shapes.paths:
            self.sim_wells_visual = WellsVisual(
                self.ctx, [p - origin for p in shapes.paths],
                [m - origin for m in shapes.markers], radius=r,
                path_colors=shapes.path_colors, marker_colors=shapes.marker_colors)

    # --- changes ---------------------------------------------------------------------------------
    def _apply_options(self, new: GridOptions, changed: set[str]) -> list[Job]:
        import dataclasses

        old = self.options
        faces = {k for k in ("filter", "slice", "plane", "faults") if k in changed}
        step_refilter = ("step" in changed and new.step != old.step and new.filter is not None
                         and new.filter.uses(dynamic_names(self.grid)))
        # what the faces job applies stays as it is until the job is applied
        self.options = dataclasses.replace(new, **{k: getattr(old, k) for k in faces})
        if {"approach", "zcorn_bits", "zcorn_store", "smear_faults"} & changed:
            self._make_visual()
            self._update_colors()
            self.apply_faces(self.prepare_faces())
        else:
            # a new step changes the colours only of a report-step property (or expression)
            if {"property", "color"} & changed or (
                    "step" in changed and self.uses_step(new.property)):
                self._update_colors()
            if "edges" in changed:
                self.edge_style.mode = new.edges
        if {"wells", "wells_coords", "well_radius", "exaggeration"} & changed:
            self._make_wells()
        if {"sim_wells", "step", "well_radius", "exaggeration"} & changed:
            self._make_sim_wells()
        if faces or step_refilter:
            return [self.faces_job(**{k: getattr(new, k) for k in faces | {"step"}})]
        return []

    # old names, kept: they go through update()
    def set_property(self, name=None, step=None, color_range=None) -> None:
        changes = {"property": name, "step": step}
        if color_range is not None:
            changes["color_range"] = color_range
        self.update(**changes)

    def set_step(self, step) -> None:
        self.update(step=step)

    def set_filter(self, expr) -> None:
        self.update(filter=expr or None)

    def set_slice(self, spec) -> None:
        self.update(slice=spec)

    def set_plane(self, plane) -> None:
        self.update(plane=plane)

    def set_faults(self, mode: str) -> None:
        self.update(faults=mode)

    def set_edges(self, edges) -> None:
        self.update(edges=edges)

    def set_wells(self, wells, coords: str = "grid", radius=None) -> None:
        self.update(wells=wells, wells_coords=coords, well_radius=radius)

    def set_colormap(self, name: str = "viridis", palette=None) -> None:
        self.update(color=self.options.color.with_(colormap=name, palette=palette))

    # --- drawing ---------------------------------------------------------------------------------
    def bounds(self) -> np.ndarray:
        return world_bounds(self.grid, self.options.exaggeration)

    def frame_points(self) -> np.ndarray:
        return frame_points(self.grid, self.options.exaggeration)

    def _frame(self, camera, target, count: bool) -> dict:
        o = self.options
        model = model_matrix(self.grid, self.origin, o.exaggeration)
        # the counting frame draws every face (no back-face cull: the same picture), so
        # faces_drawn is the number of faces the GPU built, equal to the FaceSet's
        out = self.visual.draw(camera, model, self.shading, target.size, self.edge_style,
                               cull=o.cull and not count, count=count)
        wm = np.eye(4)
        wm[:3, 3] = getattr(self, "_wells_origin", 0.0)
        for wells in (self.wells_visual, self.sim_wells_visual):
            if wells is not None:
                wells.draw(camera, wm, self.shading, fbo=target.fbo, xray=o.well_xray)
        return out or {}

    def method_name(self) -> str:
        vis = self.visual
        return f"approach {vis.approach}" + (f" ({vis.zcorn_store})" if vis.approach == 3
                                             else "")

    def _stats(self, counts: dict) -> dict:
        from geoshade.styles.units import case_unit_system, value_unit

        g, o, vis = self.grid, self.options, self.visual
        s = {
            "cells": int(g.ncells), "active_cells": int(g.nactive),
            "shown_cells": (int(np.count_nonzero(self._mask)) if self._shown is None
                            else self._shown),
            "faces": int(vis.n_faces), "faceset_faces": self.n_faceset,
            "faces_drawn": counts.get("faces_drawn"), "triangles": counts.get("triangles"),
            "approach": vis.approach, "zcorn_store": vis.zcorn_store,
            "zcorn_bits": vis.zcorn_bits, "zcorn_max_error": vis.zcorn_max_error,
            "gpu_memory": o.gpu_memory, "gpu_plan_bytes": int(sum(vis.plan().values())),
            "property": o.property, "step": o.step,
            "unit": value_unit(g, o.property), "unit_system": case_unit_system(g),
            "step_label": None if o.step is None else step_label(
                o.step, g.step_dates, g.meta.get("unrst_seqnum") or ()),
            "step_date": (g.step_dates[o.step] if o.step is not None
                          and len(g.step_dates) > o.step else None),
            "color_range": list(self.color_range) if self.color_range else None,
            "log": self.color_log, "log_auto": self.log_auto, "colormap": o.color.colormap,
            "no_value_cells": self.no_value_cells,
            "inverted_cells": int(g.meta.get("inverted_cells") or 0),
            "filter": None if o.filter is None else str(o.filter),
            "plane": None if o.plane is None else o.plane.text(),
            "faults": o.faults, "edges": self.edge_style.mode, "cull": o.cull,
            "exaggeration": o.exaggeration, "gpu_breakdown": vis.cache.breakdown(),
            "geometry_ms": round(self.geometry_ms, 3), "faces_ms": round(self.faces_ms, 3),
            "colors_ms": round(self.colors_ms, 3),
        }
        if vis.approach == 1:
            s["node_spread"] = vis.node_spread
            s["smeared_nodes"] = vis.smeared_nodes
        if self.wells_visual is not None:
            s["wells"] = self.wells_visual.n_wells
            s["well_segments"] = self.wells_visual.n_segments
        if o.sim_wells:
            sh = self.sim_shapes
            s["sim_wells"] = len(sh.names) if sh is not None else 0
            s["sim_wells_open"] = sh.open_wells if sh is not None else 0
            s["sim_well_completions"] = sh.completions if sh is not None else 0
            s["sim_well_open_completions"] = sh.open_completions if sh is not None else 0
            s["sim_well_names"] = list(sh.names) if sh is not None else []
        if self.notes:
            s["notes"] = list(dict.fromkeys(self.notes))
        return s

    # --- annotations -----------------------------------------------------------------------------
    def annotations(self, camera, stats: dict, size=None):
        """The base annotations plus the names of the simulation wells at their heads."""
        import dataclasses

        ann = super().annotations(camera, stats, size)
        labels = self.well_labels(camera, size or self.size)
        return dataclasses.replace(ann, labels=tuple(labels)) if labels else ann

    def well_labels(self, camera, size) -> list:
        """:class:`~geoshade.styles.annotate.Label` s of the shown simulation wells: the name
        (with "(shut)" for a shut well) at the pixel of its head, in the well's colour
        darkened; heads behind the camera are left out."""
        from geoshade.grid.geometry import SHUT_COLOR, SIM_WELL_COLORS
        from geoshade.styles.annotate import Label

        sh = self.sim_shapes
        if sh is None or not len(sh.names):
            return []
        w, h = size
        cam = camera.with_aspect(w / h)
        p = np.column_stack([sh.heads, np.ones(len(sh.heads))])
        clip = p @ (cam.projection_matrix() @ cam.view_matrix()).T
        out = []
        wells = self.sim_wells()
        for n, name in enumerate(sh.names):   # wells
            if clip[n, 3] <= 0:
                continue
            x = (clip[n, 0] / clip[n, 3] + 1) * 0.5 * w
            y = (1 - clip[n, 1] / clip[n, 3]) * 0.5 * h
            well = wells.wells[n] if wells is not None else None
            shut = well is not None and not well.open
            rgb = SHUT_COLOR if shut else SIM_WELL_COLORS.get(
                well.type if well is not None else "unknown", SIM_WELL_COLORS["unknown"])
            out.append(Label(f"{name} (shut)" if shut else name, float(x), float(y),
                             tuple(0.7 * v for v in rgb)))
        return out

    def _title(self, stats: dict) -> tuple[str, str]:
        from pathlib import Path

        name = Path(self.grid.name).name if self.grid.name else "corner-point grid"
        if self.grid.meta.get("index_space"):   # no geometry in the deck: unit cells
            name += " (IJK index space)"
        prop = self.options.property or "cells"
        filt = f" · {self.options.filter}" if self.options.filter is not None else ""
        from geoshade.models.steps import step_caption

        g, o = self.grid, self.options
        dynamic = dynamic_names(g)
        uses_step = (self.uses_step(o.property) or (o.filter is not None and o.filter.uses(dynamic))
                     or self.sim_shapes is not None)
        step = "" if o.step is None or not uses_step else step_caption(
            o.step, self.nsteps, g.step_dates, g.meta.get("unrst_seqnum") or ())
        return f"{name} — {prop}{filt}", step

    def _color_key(self, stats: dict):
        from geoshade.styles.annotate import ColorBar, Legend
        from geoshade.styles.units import value_unit

        o, g = self.options, self.grid
        if o.property is None or self.color_range is None:
            return None
        values = self.values(o.property, o.step)
        if np.issubdtype(values.dtype, np.integer) and o.color.range is None:
            codes = np.unique(np.asarray(values)[g.active])
            if 0 < codes.size <= CATEGORIES:
                from geoshade.render.visuals.grid.prepare import color_index

                idx = color_index(codes.astype(np.float64), *self.color_range)
                return Legend(o.property, tuple((str(int(c)), tuple(int(x) for x in
                                                                     self.palette[i]))
                                                for c, i in zip(codes, idx, strict=True)))
        lo, hi = self.color_range
        gaps = self.no_value_cells > 0
        return ColorBar(o.property, lo, hi, self.palette[:255] if gaps else self.palette,
                        unit=value_unit(g, o.property),
                        log=self.color_log, auto=self.log_auto,
                        nan_color=o.color.nan_color if gaps else None)

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
        from geoshade.styles.units import length_unit

        if self.grid.meta.get("index_space"):
            return "cells"
        return length_unit(self.grid.units) or "m"

    def _notes(self, stats: dict) -> list[tuple[str, type[Warning]]]:
        vis = self.visual
        if vis.approach == 1 and vis.smeared_nodes and self.options.smear_faults is None:
            return [(f"approach 1 smeared the faults: the corners meeting at "
                     f"{vis.smeared_nodes} nodes were averaged (up to {vis.node_spread:.4g} "
                     f"apart); approaches 2 and 3 draw them exactly", UserWarning)]
        return []

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
                f"{'…' if drawn is None else fmt_int(drawn)} faces{wells}")

    def summary(self, stats: dict) -> str:
        prop = stats["property"] or "no property"
        step = "" if stats["step"] is None else f" {stats['step_label']}"
        return (f"{stats['width']}x{stats['height']} {stats['method']}, {prop}{step}, "
                f"{stats['shown_cells']} of {stats['active_cells']} active cells shown, "
                f"{stats['faces_drawn']} faces, {stats['frame_ms']:.1f} ms/frame, "
                f"{stats['gpu_bytes'] / 2**20:.2f} MiB on the GPU")

    # --- lifetime --------------------------------------------------------------------------------
    def _gpu_objects(self) -> list:
        return [o for o in (getattr(self, "visual", None), getattr(self, "wells_visual", None),
                            getattr(self, "sim_wells_visual", None)) if o is not None]

    def _release_part(self) -> None:
        self.visual = self.wells_visual = self.sim_wells_visual = None


__all__ = ["GridView", "PreparedFaces"]
