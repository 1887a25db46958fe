"""``GridView``: a live view of a corner-point grid coloured by a cell property."""

from __future__ import annotations

import dataclasses
import time
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from geoshade.compute.cell_values import summarise
from geoshade.compute.grid_coarse import coarse_grid, faults_inside_blocks, merged_cells
from geoshade.compute.grid_filter import Expression, is_expression
from geoshade.compute.grid_geometry import cell_centres
from geoshade.compute.synthetic_grid import synthetic_grid
from geoshade.grid.backends import FacesBackend, MemoryFaces, PreparedFaces, StoreFaces
from geoshade.grid.cells import dynamic_names, property_values
from geoshade.grid.distributed import ClusterFaces
from geoshade.grid.geometry import (
    HEAD_LIFT,
    HEAD_LIFT_MIN,
    SHUT_COLOR,
    SIM_WELL_COLORS,
    demo_wells,
    display_bounds,
    frame_points,
    sim_well_shapes,
    world_bounds,
    world_points,
)
from geoshade.grid.lazy import count_in, is_lazy, lazy_codes, stored_summary
from geoshade.grid.lod import preview_factor, read_coarse_level
from geoshade.grid.options import GridOptions
from geoshade.io.stores.grid_index import GridIndex, open_index
from geoshade.models.grid import CornerPointGrid
from geoshade.models.names import derived_names, properties_at
from geoshade.models.steps import step_caption, step_label
from geoshade.models.wells import DeckWell, well_type
from geoshade.render.progressive import (
    REFINE_LABEL,
    Preview,
    Progressive,
    preview_note,
)
from geoshade.render.view import Job, View, cluster_readout, cluster_summary, fmt_int
from geoshade.styles.annotate import (
    ColorBar,
    Label,
    Legend,
    exaggeration_text,
    font_px,
    join_subtitle,
)
from geoshade.styles.categories import (
    CodeStyle,
    by_name,
    categorical_palette,
    distinct_codes,
    is_categorical,
    legend_entries,
    undefined_codes,
)
from geoshade.styles.labels import first_inside, place_labels
from geoshade.styles.shading import shading_uniforms
from geoshade.styles.units import case_unit_system, length_unit, value_unit

#: smallest simulation-well pipe radius, as a fraction of a cell's horizontal diagonal
SIM_WELL_CELL_RADIUS = 0.08


def faces_backend(view) -> FacesBackend:
    """The faces backend of ``view``'s model and options: on the cluster with
    ``distributed``, out of core for a grid store, else in memory."""
    if view.options.distributed:

        return ClusterFaces(view)
    return StoreFaces(view) if is_lazy(view.grid) else MemoryFaces(view)


class GridView(Progressive, View[GridOptions]):
    """A live view of one corner-point grid; only what changed is redone.

    - ``property``/``step``/``color``: new per-cell colour indices, written into the existing
      colour object (the geometry is not touched); a new step re-filters only when the filter
      names a report-step property (in any case);
    - ``filter``/``slice``/``plane``/``faults``: new visible faces, built by
      :meth:`prepare_faces` (any thread) and uploaded by :meth:`apply_faces`;
    - ``exaggeration`` and a new camera: just draw again.

    Where the faces are computed, kept and drawn is the View's *faces backend*
    (:mod:`geoshade.grid.backends`), chosen when it opens: in memory, a grid store (out of
    core, on the View's ``scheduler``) or, with ``distributed=True``, the workers of the
    ``scheduler``'s cluster (:class:`~geoshade.grid.distributed.ClusterFaces`). The View keeps
    the options, the colour state, the wells, the annotations and the stats.

    Options: see :class:`~geoshade.grid.options.GridOptions`. With ``progressive=True`` the
    coarse level of detail (a grid store's stored one, or a big grid's merged in memory) is
    drawn first (:mod:`geoshade.render.progressive`; :meth:`refine_job` builds the faces).

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
    backend: FacesBackend
    wells_visual: Any
    sim_wells_visual: Any
    sim_shapes: Any
    faces: Any
    _mask: Any
    _centres: Any

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
            self._open_full(faces_backend(self))   # in memory, a grid store or a cluster

    def _open_full(self, backend: FacesBackend, prepared: PreparedFaces | None = None) -> None:
        """Open ``backend`` (its first faces ``prepared`` on another thread, or None), the
        wells."""
        self.backend = backend
        backend.open(prepared)   # the refine job's faces, when it made them
        self._make_wells()
        self._make_sim_wells()

    # --- progressive: the coarse level of detail first --------------------------------------
    def _open_preview(self) -> Preview | None:
        """A preview View of the coarse level of detail (a grid store's stored level; a grid
        in memory merged by :func:`~geoshade.grid.lod.preview_factor`), with this View's
        options, colour range and framing; None where there is none to draw (a note says
        how a store gets one)."""
        g, o = self.grid, self.options
        if self.lazy:
            store = g.meta.get("store")
            # a level with its own index is drawn from it, out of core (no faces computed);
            # one without (written before levels had one) is read into memory
            coarse = read_coarse_level(store, g.dims, lazy=True) if store else None
            if coarse is not None and not isinstance(open_index(coarse), GridIndex):
                coarse = read_coarse_level(store, g.dims)
            if coarse is None:
                self._no_preview = ("progressive: no coarse level in the store, the full "
                                    "picture only (add one: 'geoshade grid ingest --coarse auto "
                                    f"{store}')")
                return None
        else:
            f = preview_factor(g.ncells)
            if f is None:
                return None
            coarse = coarse_grid(g, f)
        f = int(coarse.meta["lod"]["factor"])
        self._colour_state()   # the full grid's colour range, log and categories
        color = o.color
        if self.categories is None and self.color_range is not None and color.range is None:
            color = color.with_(range=self.color_range, log=self.color_log)
        sl = tuple(slice(s.start // f, -(-s.stop // f)) for s in o.slice)
        note = preview_note(f"cells {f}×{f}×{f}", f)
        if faults_inside_blocks(g.faults, g.dims, f):   # their throw is smoothed away
            note += " · faults inside merged cells smoothed"
        view = GridView(coarse, ctx=self.ctx, options=o, progressive=False, scheduler=None,
                        distributed=False, parts=None, sim_wells=False, slice=sl, color=color)
        view.preview_note = note
        return Preview(view, 1, f, note, lambda c: merged_cells(c, f, g.dims))

    def refine_job(self) -> Job:
        """A :class:`Job`: the full grid's faces (CPU half, any thread), then its GPU objects
        and wells; the preview is released when it is applied."""
        return Job(self.refine_key(), REFINE_LABEL, self._refine_faces, self._apply_refined)

    def _refine_faces(self, progress=None):
        backend = faces_backend(self)
        local = isinstance(backend, MemoryFaces)   # a cluster prepares on its workers
        return backend, (backend.prepare(self.options) if local else None)

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
        self.backend = None   # type: ignore[assignment]
        self.wells_visual = self.sim_wells_visual = self.sim_shapes = None
        self._centres = None
        self._mask = None
        self.shown_cells: int | None = None
        self._summaries: dict = {}
        self.faces = None
        self.n_faceset = 0
        self.plan_bytes = 0
        self.colors_ms = self.faces_ms = self.geometry_ms = 0.0
        self.color_range: tuple[float, float] | None = None
        self.color_log = self.log_auto = False
        self.categories = None   # a CategoricalPalette while a property is drawn as categories
        self.no_value_cells = 0
        self.notes: list[str] = []

    @property
    def visual(self):
        """The GridVisual of a backend that draws in this process (None on a cluster)."""
        return None if self.backend is None else self.backend.visual

    # --- colours ---------------------------------------------------------------------------------
    def property_names(self) -> list[str]:
        """The properties the grid can be coloured by (derived ones such as SOIL included)."""

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

        key = (name, step if self.uses_step(name) else None)
        if key not in self._summaries:
            # a grid store's own array: the summary stored at ingest (no pass over it)
            stored = None
            if self.lazy:

                stored = stored_summary(self.grid, values)
            # a grid store's ACTNUM stays lazy (read chunk by chunk with the property)
            active = self.grid.actnum if self.lazy else self.grid.active
            self._summaries[key] = stored if stored is not None else summarise(values, active)
        return self._summaries[key]

    def update_colours(self) -> None:
        """Colour the drawn cells by the options' property/step/colour style (the backend
        uploads colour only).  The range, the log decision and the count of cells without a
        value come from every active cell (:meth:`_summary`), so they never depend on the
        filter or slice."""
        t0 = time.perf_counter()
        state, palette = self._colour_state()
        self.backend.colours(state, palette)
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
        self.categories = self._categorical(o.property, o.step, full, style)
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
        self.color_range = (lo, hi)
        self.color_log = bool(style.log)
        if self.uses_step(o.property) and o.step == len(g.steps) - 1 and len(g.steps) > 1:
            self.notes.append(f"{o.property} is a report-step property: the last step "
                              f"({step_label(o.step, g.step_dates)}) is shown")
        return (style, float(lo), float(hi), nan), palette

    def _categorical(self, name: str, step, values, style):
        """The distinct codes of ``name`` over the active cells when it is drawn as categories
        (:func:`geoshade.styles.categories.is_categorical` under the style's ``categorical``;
        an explicit range keeps an automatic choice continuous), else None."""

        if style.solid is not None or style.palette is not None or style.categorical is False \
                or (style.categorical is None and style.range is not None):
            return None
        key = ("codes", name, step if self.uses_step(name) else None)
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

    # --- faces -----------------------------------------------------------------------------------
    def filter_properties(self, options: GridOptions | None = None):
        """Static properties and those of the current report step, read only when the filter
        names them (report steps may be lazy mappings over the UNRST file)."""
        o = options or self.options
        return self._properties_at(o.step or 0)

    def _properties_at(self, k: int):
        """Static, report-step ``k`` and derived properties: one mapping whose values are read
        (or computed) only when looked up (:func:`geoshade.models.names.properties_at`)."""

        return properties_at(self.grid, k)

    def shown_mask(self, options: GridOptions | None = None) -> np.ndarray:
        """(nx, ny, nz) bool: active cells inside the slice, passing the filter and on the kept
        side of the plane of ``options`` (default: the current ones)."""

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
        shown and their visible faces, by the View's backend. No GL: safe on a worker thread
        (a viewer keeps its window alive this way); errors leave the view as it was."""
        return self.backend.prepare(self.options.replace(self.grid, **changes))

    def apply_faces(self, prepared: PreparedFaces) -> None:
        """GL half: upload the faces of :meth:`prepare_faces` and make its options current."""
        self.backend.apply(prepared)

    def faces_applied(self, prepared: PreparedFaces, ms: float) -> None:
        """What the backend calls once ``prepared`` is drawn (``ms``: the upload's time): its
        options become current."""
        self._set(**{k: v for k, v in prepared.changes.items() if k != "step"})
        self._mask, self.faces = prepared.mask, prepared.faces
        self.n_faceset = 0 if prepared.faces is None else len(prepared.faces)
        self.faces_ms = prepared.ms + ms

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
        """Named pipes of the deck's or files' wells (:class:`~geoshade.models.WellPath`),
        coloured by type as simulation wells are (a deck's WCONPROD/WCONINJE; a trajectory
        file's wells are ``unknown``); completion markers in the well's colour (grey when
        shut), other markers (a file's MARKER lines) orange."""
        from geoshade.render.visuals.wells.visual import MARKER_COLOR, WellsVisual

        o = self.options
        if self.wells_visual is not None:
            self.wells_visual.release()
            self.wells_visual = None
        self._well_paths, self._well_names, self._well_rgb = [], [], []
        if not o.wells:
            return
        exag = o.exaggeration
        r = self._well_radius()
        world = [world_points(self.grid, self._well_points(w), exag, o.wells_coords)
                 for w in o.wells]
        colors = [SIM_WELL_COLORS.get(well_type(w), SIM_WELL_COLORS["unknown"])
                  for w in o.wells]
        markers, mcolors = [], []
        for w, rgb in zip(o.wells, colors, strict=True):   # wells, not points
            if not len(w.markers):
                continue
            markers.append(world_points(self.grid, w.markers, exag, o.wells_coords)
                           - self._wells_origin)
            state = getattr(w, "cell_open", None)
            mcolors.append(np.tile(MARKER_COLOR, (len(w.markers), 1)) if state is None
                           else np.where(np.asarray(state, bool)[:, None], rgb, SHUT_COLOR))
        self._well_paths = world
        self._well_names = [str(w.name) for w in o.wells]
        self._well_rgb = colors
        self.wells_visual = WellsVisual(self.ctx, [p - self._wells_origin for p in world],
                                        markers, radius=r, path_colors=colors,
                                        marker_colors=mcolors or None)

    def _well_points(self, well) -> np.ndarray:
        """A well's trajectory; a deck well's starts at a head above the grid's top, where a
        simulation well's head is (:func:`geoshade.grid.geometry.sim_well_shapes`)."""

        if not isinstance(well, DeckWell) or self.options.wells_coords != "grid":
            return well.points
        b = display_bounds(self.grid)
        lift = max(HEAD_LIFT * float(b[1, 2] - b[0, 2]),
                   HEAD_LIFT_MIN * float(np.hypot(*(b[1, :2] - b[0, :2])))
                   / max(float(self.options.exaggeration), 1e-9))
        p = well.points
        return np.vstack([[p[0, 0], p[0, 1], b[0, 2] - lift], p])

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

        if self.preview is not None:   # loading: a new preview now, a new full build after
            self.options = new
            if changed <= {"camera", "size", "background", "transparent", "annotations"}:
                return []
            self._drop_preview()
            self._summaries.clear()
            self.preview = self._open_preview()
            return [self.refine_job()]
        old = self.options
        faces = {k for k in ("filter", "slice", "plane", "faults") if k in changed}
        step_refilter = ("step" in changed and new.step != old.step and new.filter is not None
                         and new.filter.uses(dynamic_names(self.grid)))
        # what the faces job applies stays as it is until the job is applied
        self.options = dataclasses.replace(new, **{k: getattr(old, k) for k in faces})
        if {"approach", "zcorn_bits", "zcorn_store", "smear_faults"} & changed:
            self.backend.remake()   # new GPU objects, colours and faces
        else:
            # a new step changes the colours only of a report-step property (or expression)
            if {"property", "color"} & changed or (
                    "step" in changed and self.uses_step(new.property)):
                self.update_colours()
            if {"edges", "cull"} & changed:
                self.backend.drawing_changed()
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
        out = self.backend.draw(camera, target, count)
        wm = np.eye(4)
        wm[:3, 3] = getattr(self, "_wells_origin", 0.0)
        for wells in (self.wells_visual, self.sim_wells_visual):
            if wells is not None:
                wells.draw(camera, wm, self.shading, fbo=target.fbo, xray=o.well_xray)
        return out or {}

    def method_name(self) -> str:
        return self.backend.method()

    def _stats(self, counts: dict) -> dict:

        g, o = self.grid, self.options
        s = {
            "cells": int(g.ncells), "active_cells": int(g.nactive),
            "shown_cells": (int(np.count_nonzero(self._mask)) if self.shown_cells is None
                            else self.shown_cells),
            "faceset_faces": self.n_faceset,
            "faces_drawn": counts.get("faces_drawn"), "triangles": counts.get("triangles"),
            "gpu_memory": o.gpu_memory,
            "property": o.property, "step": o.step,
            "unit": value_unit(g, o.property), "unit_system": case_unit_system(g),
            "categories": (None if self.categories is None
                           else [float(c) for c in self.categories.codes]),
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
            "faults": o.faults, "cull": o.cull, "exaggeration": o.exaggeration,
            "geometry_ms": round(self.geometry_ms, 3), "faces_ms": round(self.faces_ms, 3),
            "colors_ms": round(self.colors_ms, 3),
        }
        s.update(self.backend.stats())   # faces, approach, depth code, GPU plan and breakdown
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

    def well_labels(self, camera, size) -> list:
        """:class:`~geoshade.styles.annotate.Label` s of the shown wells, before placement
        (:func:`geoshade.styles.labels.place_labels` moves or hides colliding ones): each
        simulation well's name (with "(shut)" for a shut well), then each deck or file well's,
        at its head's pixel, or where its pipe comes into the picture when the head is outside
        (:func:`geoshade.styles.labels.first_inside`), in the well's colour darkened; wells
        whose pipe is nowhere in the picture are left out."""

        sh = self.sim_shapes
        wells = self.sim_wells() if sh is not None and len(sh.names) else None
        items = []   # (name, world path from the head, rgb)
        if sh is not None:
            for n, name in enumerate(sh.names):   # wells
                well = wells.wells[n] if wells is not None else None
                shut = well is not None and not well.open
                rgb = SHUT_COLOR if shut else SIM_WELL_COLORS.get(
                    well.type if well is not None else "unknown", SIM_WELL_COLORS["unknown"])
                items.append((f"{name} (shut)" if shut else name, sh.paths[n], rgb))
        if self.wells_visual is not None:
            items += list(zip(self._well_names, self._well_paths, self._well_rgb, strict=True))
        if not items:
            return []
        w, h = size
        cam = camera.with_aspect(w / h)
        m = cam.projection_matrix() @ cam.view_matrix()
        rect = (0.0, 2.0 * font_px(h), w - 1.0, h - 1.0)   # room for the name above the point
        out = []
        for name, path, rgb in items:   # wells
            clip = np.column_stack([path, np.ones(len(path))]) @ m.T
            with np.errstate(divide="ignore", invalid="ignore"):
                px = np.column_stack([(clip[:, 0] / clip[:, 3] + 1) * 0.5 * w,
                                      (1 - clip[:, 1] / clip[:, 3]) * 0.5 * h])
            px[clip[:, 3] <= 0] = np.nan   # behind the camera
            at = first_inside(px, rect)
            if at is not None:
                out.append(Label(name, at[0], at[1], tuple(0.7 * v for v in rgb)))
        return out

    def _title(self, stats: dict) -> tuple[str, str]:

        name = Path(self.grid.name).name if self.grid.name else "corner-point grid"
        if self.grid.meta.get("index_space"):   # no geometry in the deck: unit cells
            name += " (IJK index space)"
        prop = self.options.property or "cells"
        filt = f" · {self.options.filter}" if self.options.filter is not None else ""

        g, o = self.grid, self.options
        dynamic = dynamic_names(g)

        # the step only where the colours or the cells shown change with it (a static
        # property is titled without it, also when restart wells are drawn)
        uses_step = self.uses_step(o.property) or (o.filter is not None and
                                                   o.filter.uses(dynamic))
        step = "" if o.step is None or not uses_step else step_caption(
            o.step, self.nsteps, g.step_dates, g.meta.get("unrst_seqnum") or ())
        return f"{name} — {prop}{filt}", self._preview_subtitle(
            join_subtitle(step, exaggeration_text(o.exaggeration)))

    def _color_key(self, stats: dict):

        o, g = self.options, self.grid
        if o.property is None or self.color_range is None:
            return None
        if self.categories is not None:   # one entry per code, named where the file names it

            names = (g.meta.get("codes") or {}).get(o.property)
            nan = (tuple(int(x) for x in self.categories.palette[255])
                   if self.no_value_cells else None)   # cells drawn in the no-value colour
            return Legend(o.property, legend_entries(self.categories, names), nan_color=nan)
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

        if self.grid.meta.get("index_space"):
            return "cells"
        return length_unit(self.grid.units) or "m"

    def _notes(self, stats: dict) -> list[tuple[str, type[Warning]]]:
        none = getattr(self, "_no_preview", "")
        return [*self.backend.notes(), *([(none, UserWarning)] if none else [])]

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
        return [o for o in (getattr(self, "backend", None), getattr(self, "wells_visual", None),
                            getattr(self, "sim_wells_visual", None),
                            preview.view if preview is not None else None) if o is not None]

    def _release_part(self) -> None:
        self.backend = self.wells_visual = self.sim_wells_visual = None   # type: ignore
        self.preview = None


__all__ = ["GridView", "PreparedFaces"]
