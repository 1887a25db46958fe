"""The wells a :class:`~geoshade.grid.view.GridView` draws over its faces, the same for every
source and drawing: the deck's or files' wells (:class:`~geoshade.models.WellPath`, option
``wells``) and the simulation wells of the shown report step (option ``sim_wells``), as pipes
with completion markers, and their names at their heads (:meth:`GridWells.labels`)."""

from __future__ import annotations

from typing import Any

import numpy as np

from geoshade.grid.geometry import (
    HEAD_LIFT,
    HEAD_LIFT_MIN,
    SHUT_COLOR,
    SIM_WELL_COLORS,
    display_bounds,
    sim_well_shapes,
    world_bounds,
    world_points,
)
from geoshade.models.wells import DeckWell, well_type
from geoshade.styles.annotate import Label, font_px
from geoshade.styles.labels import first_inside

#: smallest simulation-well pipe radius, as a fraction of a cell's horizontal diagonal
SIM_WELL_CELL_RADIUS = 0.08


class GridWells:
    """The well pipes of one grid in the context ``ctx``: :meth:`make` (the options' wells),
    :meth:`make_sim` (the simulation wells of the options' step), :meth:`draw`,
    :meth:`stats`, :meth:`labels`; ``gpu_bytes`` and :meth:`release` as a visual's.

    Examples
    --------
    >>> from geoshade.compute.grid.synthetic import synthetic_grid
    >>> wells = GridWells(None, synthetic_grid(4, 3, 2))
    >>> wells.has_sim(), wells.gpu_bytes
    (False, 0)
    """

    def __init__(self, ctx, grid):
        self.ctx, self.grid = ctx, grid
        #: the options' wells and the simulation wells (None without)
        self.visual: Any = None
        self.sim_visual: Any = None
        #: the simulation wells' pipes (:func:`~geoshade.grid.geometry.sim_well_shapes`)
        self.sim_shapes: Any = None
        self.origin: Any = 0.0
        self.paths: list = []
        self.names: list[str] = []
        self.rgb: list = []

    def radius(self, o) -> float:
        """The tube radius (world units): the option's, else 0.4 % of the grid's diagonal."""
        wb = world_bounds(self.grid, o.exaggeration)
        self.origin = wb.mean(axis=0)
        return (o.well_radius if o.well_radius is not None
                else 0.004 * float(np.linalg.norm(wb[1] - wb[0])))

    def make(self, o) -> None:
        """Named pipes of the deck's or files' wells (:class:`~geoshade.models.WellPath`),
        coloured by type as simulation wells are (a deck's WCONPROD/WCONINJE; a trajectory
        file's wells are ``unknown``); completion markers in the well's colour (grey when
        shut), other markers (a file's MARKER lines) orange."""
        from geoshade.render.visuals.wells.visual import MARKER_COLOR, WellsVisual

        if self.visual is not None:
            self.visual.release()
            self.visual = None
        self.paths, self.names, self.rgb = [], [], []
        if not o.wells:
            return
        exag = o.exaggeration
        r = self.radius(o)
        world = [world_points(self.grid, self.points(w, o), exag, o.wells_coords)
                 for w in o.wells]
        colors = [SIM_WELL_COLORS.get(well_type(w), SIM_WELL_COLORS["unknown"])
                  for w in o.wells]
        markers, mcolors = [], []
        for w, rgb in zip(o.wells, colors, strict=True):   # wells, not points
            if not len(w.markers):
                continue
            markers.append(world_points(self.grid, w.markers, exag, o.wells_coords)
                           - self.origin)
            state = getattr(w, "cell_open", None)
            mcolors.append(np.tile(MARKER_COLOR, (len(w.markers), 1)) if state is None
                           else np.where(np.asarray(state, bool)[:, None], rgb, SHUT_COLOR))
        self.paths, self.names, self.rgb = world, [str(w.name) for w in o.wells], colors
        self.visual = WellsVisual(self.ctx, [p - self.origin for p in world], markers,
                                  radius=r, path_colors=colors, marker_colors=mcolors or None)

    def points(self, well, o) -> np.ndarray:
        """A well's trajectory; a deck well's starts at a head above the grid's top, where a
        simulation well's head is (:func:`geoshade.grid.geometry.sim_well_shapes`)."""
        if not isinstance(well, DeckWell) or o.wells_coords != "grid":
            return well.points
        b = display_bounds(self.grid)
        lift = max(HEAD_LIFT * float(b[1, 2] - b[0, 2]),
                   HEAD_LIFT_MIN * float(np.hypot(*(b[1, :2] - b[0, :2])))
                   / max(float(o.exaggeration), 1e-9))
        p = well.points
        return np.vstack([[p[0, 0], p[0, 1], b[0, 2] - lift], p])

    def has_sim(self) -> bool:
        """True when the case's restart file has simulation wells (at some report step)."""
        from geoshade.io.grids.restart_wells import has_restart_wells

        return bool(self.grid.steps) and has_restart_wells(self.grid)

    def sim(self, step: int | None):
        """The simulation wells of report ``step`` (:class:`~geoshade.models.wells.SimWells`,
        read from the restart file on first use), or None when the case has none."""
        from geoshade.io.grids.restart_wells import restart_wells

        index = restart_wells(self.grid) if step is not None else None
        return None if index is None or not len(index) else index[step]

    def make_sim(self, o) -> None:
        """The pipes of the simulation wells of the options' step (IWEL/ICON/ZWEL of that
        step only are read)."""
        from geoshade.render.visuals.wells.visual import WellsVisual

        if self.sim_visual is not None:
            self.sim_visual.release()
        self.sim_visual = self.sim_shapes = None
        wells = self.sim(o.step) if o.sim_wells else None
        if wells is None:
            return
        shapes = sim_well_shapes(self.grid, wells, o.exaggeration)
        r = self.radius(o)
        if o.well_radius is None:  # at least a tenth of a cell: pipes read on coarse grids
            b = display_bounds(self.grid)
            nx, ny, _ = self.grid.dims
            r = max(r, SIM_WELL_CELL_RADIUS * float(np.hypot(*(b[1, :2] - b[0, :2])))
                    / float(np.hypot(nx, ny)))
        self.sim_shapes = shapes
        if shapes.paths:
            self.sim_visual = WellsVisual(
                self.ctx, [p - self.origin for p in shapes.paths],
                [m - self.origin for m in shapes.markers], radius=r,
                path_colors=shapes.path_colors, marker_colors=shapes.marker_colors)

    def draw(self, camera, target, shading: dict, o) -> None:
        """Draw the pipes over the faces in ``target`` (x-ray with ``well_xray``)."""
        wm = np.eye(4)
        wm[:3, 3] = self.origin
        for wells in (self.visual, self.sim_visual):
            if wells is not None:
                wells.draw(camera, wm, shading, fbo=target.fbo, xray=o.well_xray)

    def stats(self, o) -> dict:
        """``wells well_segments`` and, with ``sim_wells``, the simulation wells' counts."""
        s: dict = {}
        if self.visual is not None:
            s["wells"] = self.visual.n_wells
            s["well_segments"] = self.visual.n_segments
        if o.sim_wells:
            sh = self.sim_shapes
            s["sim_wells"] = len(sh.names) if sh is not None else 0
            s["sim_wells_open"] = sh.open_wells if sh is not None else 0
            s["sim_well_completions"] = sh.completions if sh is not None else 0
            s["sim_well_open_completions"] = sh.open_completions if sh is not None else 0
            s["sim_well_names"] = list(sh.names) if sh is not None else []
        return s

    def labels(self, camera, size, step: int | None) -> list:
        """:class:`~geoshade.styles.annotate.Label` s of the shown wells, before placement
        (:func:`geoshade.styles.labels.place_labels` moves or hides colliding ones): each
        simulation well's name (with "(shut)" for a shut well), then each deck or file well's,
        at its head's pixel, or where its pipe comes into the picture when the head is outside
        (:func:`geoshade.styles.labels.first_inside`), in the well's colour darkened; wells
        whose pipe is nowhere in the picture are left out."""
        sh = self.sim_shapes
        wells = self.sim(step) if sh is not None and len(sh.names) else None
        items = []   # (name, world path from the head, rgb)
        if sh is not None:
            for n, name in enumerate(sh.names):   # wells
                well = wells.wells[n] if wells is not None else None
                shut = well is not None and not well.open
                rgb = SHUT_COLOR if shut else SIM_WELL_COLORS.get(
                    well.type if well is not None else "unknown", SIM_WELL_COLORS["unknown"])
                items.append((f"{name} (shut)" if shut else name, sh.paths[n], rgb))
        if self.visual is not None:
            items += list(zip(self.names, self.paths, self.rgb, strict=True))
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

    @property
    def gpu_bytes(self) -> int:
        return int(sum(v.gpu_bytes for v in (self.visual, self.sim_visual) if v is not None))

    def release(self) -> None:
        """Free the pipes' GPU objects (idempotent)."""
        for v in (self.visual, self.sim_visual):
            if v is not None:
                v.release()
        self.visual = self.sim_visual = None


__all__ = ["SIM_WELL_CELL_RADIUS", "GridWells"]
