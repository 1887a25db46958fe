"""How a :class:`~geoshade.grid.view.GridView` gets its faces, along two axes chosen when it
opens:

- the **source**, where the cells live (:mod:`geoshade.grid.sources`): in memory, a grid store
  with its index, or a grid store computed chunk by chunk (:class:`GridSource`);
- the **drawing**, where the faces are drawn: here, in one GridVisual (:class:`HereFaces`), or on
  the workers of the View's cluster (:class:`~geoshade.grid.distributed.ClusterFaces`,
  ``distributed=True``) (:class:`FacesDrawing`).

A drawing takes the source and the options and *returns* what it prepared
(:class:`PreparedFaces`, CPU, any thread) and what it applied (:class:`Applied`, GL); the View
makes that current. A drawing never holds or writes the View: what it needs of it (the context,
the origin, a frame's shading, the :class:`~geoshade.grid.colours.ColourPlan`) comes as
arguments. The same calls drive every pair (tests/gl/test_backends.py).
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any, Protocol, runtime_checkable

import numpy as np

from geoshade.compute.grid.geometry import zcorn_quantise, zcorn_quantiser
from geoshade.grid.cells import colour_indices, fault_faces, property_values
from geoshade.grid.colours import ColourPlan
from geoshade.grid.geometry import grid_bounds, model_matrix
from geoshade.grid.plan import cells_with_faces, check_fits
from geoshade.io.paths import give_back_freed
from geoshade.render.backend import HoldsVisual
from geoshade.render.visuals.grid.layout import gpu_plan
from geoshade.render.visuals.grid.prepare import StagedFaces

#: the colour index of every cell when no property is shown (the colour map's middle)
UNIFORM_INDEX = 160
#: the options a prepared faces change applies
FACE_OPTIONS = ("filter", "ranges", "slice", "plane", "faults", "step")


@dataclass
class PreparedFaces:
    """Visible faces built on the CPU for a filter/slice/plane/faults change (see
    :meth:`FacesDrawing.prepare`), ready for :meth:`FacesDrawing.apply`."""

    changes: dict
    mask: np.ndarray | None
    faces: Any
    cells: np.ndarray
    face: np.ndarray
    highlight: np.ndarray | None
    ms: float
    corners: Any = None                 # (n, 4) corner depths, or corners(sel) (out of core)
    shown: int | None = None            # shown cells (counted once for a grid out of core)
    staged: Any = None                  # the records built here (StagedFaces; out of core)

    @property
    def n_faces(self) -> int:
        """The faces to draw."""
        return int(self.staged.n) if self.staged is not None else len(self.face)


@dataclass
class Applied:
    """What a drawing made current (:meth:`FacesDrawing.open`, ``remake``, ``apply``): the
    View keeps it.

    changes:  the options the faces were made for (None: no faces applied here)
    mask, faces: the shown cells and the face set (None where the workers hold them)
    shown:    shown cells where counted (None: the mask's count)
    faces_ms: CPU and upload time of the faces
    geometry_ms, plan_bytes: the GPU objects' build time and planned bytes (None: not rebuilt)
    colours:  ``(colour indices, cells)`` uploaded (None: no upload, or on the workers)
    """

    changes: dict | None = None
    mask: Any = None
    faces: Any = None
    shown: int | None = None
    faces_ms: float = 0.0
    geometry_ms: float | None = None
    plan_bytes: int | None = None
    colours: tuple | None = None

    @property
    def n_faceset(self) -> int:
        return 0 if self.faces is None else len(self.faces)


@runtime_checkable
class GridSource(Protocol):
    """Where a grid View's cells live (:mod:`geoshade.grid.sources`)."""

    #: ``"memory"``, ``"indexed store"`` or ``"chunked store"``
    name: str
    grid: Any
    #: the faces' CPU columns go once they are on the GPU (a grid store)
    out_of_core: bool

    def check(self, options) -> None:
        """One line for what this source cannot draw (before any work)."""

    def shown_mask(self, options):
        """(nx, ny, nz) bool of the shown cells of ``options`` (a dask array out of core)."""

    def faces(self, options, stage=None) -> PreparedFaces:
        """The visible faces of ``options``, in drawing order (no GL: any thread)."""

    def values_at(self, full, need: np.ndarray) -> np.ndarray:
        """The values of cell array ``full`` at cell numbers ``need`` (ascending)."""

    def orientation(self) -> float | None:
        """The back-face sign (None: the visual finds it from the whole grid)."""

    def stats(self) -> dict:
        """Where the faces and values came from (``faces_from``, ``index`` ...)."""

    def notes(self) -> list[tuple[str, type[Warning]]]:
        """Notes to warn about once (why an index is not used)."""


@runtime_checkable
class FacesDrawing(Protocol):
    """Where a grid View's faces are drawn: here or on a cluster. Every call takes what it
    needs as arguments and returns what it made; ``plan`` is the View's
    :class:`~geoshade.grid.colours.ColourPlan`."""

    #: ``"here"`` or ``"cluster"``
    name: str
    #: the GridVisual in this process (None on a cluster: the workers hold theirs)
    visual: Any
    #: the palette the drawn faces hold ((256, 4) uint8; None before the first colours)
    palette: Any

    def open(self, options, plan: ColourPlan, prepared: PreparedFaces | None = None) -> Applied:
        """The first GPU objects, colours and faces of ``options`` (``prepared``: those faces,
        made already on another thread)."""

    def remake(self, options, plan: ColourPlan) -> Applied:
        """New GPU objects for a new approach, depth precision or storage."""

    def prepare(self, options) -> PreparedFaces:
        """CPU half of a filter, slice, plane, faults (or filtering step) change (no GL: any
        thread; errors leave the drawing as it was)."""

    def apply(self, prepared: PreparedFaces, plan: ColourPlan) -> Applied:
        """GL half: make ``prepared`` the drawn faces (the new cells' colours included)."""

    def colours(self, options, plan: ColourPlan) -> tuple | None:
        """Colour the drawn cells by ``plan``; the colour indices uploaded (or None)."""

    def drawing_changed(self, options) -> None:
        """The edge style or back-face culling changed."""

    def draw(self, camera, target, count: bool, options, shading: dict) -> dict:
        """Draw the faces into ``target`` lit by ``shading`` (the GPU's counts with
        ``count``)."""

    def stats(self, options) -> dict:
        """The faces' stats: ``faces approach zcorn_store zcorn_bits zcorn_max_error
        gpu_plan_bytes gpu_breakdown edges`` (and what the source or cluster adds)."""

    def method(self) -> str:
        """The drawing method, for the stats' ``method``."""

    def notes(self, options) -> list[tuple[str, type[Warning]]]:
        """Notes to warn about once per draw (workers lost, approximations)."""

    @property
    def gpu_bytes(self) -> int:
        """GPU bytes the faces hold now (on every machine that draws them)."""

    def release(self) -> None:
        """Free the GPU objects (idempotent)."""


# --------------------------------------------------------------------------------------------
# what sources and drawings share
# --------------------------------------------------------------------------------------------
def face_depth_code(grid) -> tuple[float, float]:
    """``(z0, scale)`` of the 16-bit depth code of approach 3 with faces: only the drawn
    faces' corners are quantised (no 16-bit copy of ZCORN)."""

    zb = grid_bounds(grid)[:, 2]
    z0, scale = zcorn_quantiser(float(zb[0]), float(zb[1]), 16)[:2]
    return float(z0), float(scale)


def applied(o) -> dict:
    """The options a faces change makes current."""
    return {k: getattr(o, k) for k in FACE_OPTIONS}


def prepared_faces(o, mask, fs, t0: float) -> PreparedFaces:
    """The faces ``fs`` of options ``o`` (shown cells ``mask``) under its fault mode."""
    cells, face, hl = fault_faces(fs, o.faults)
    return PreparedFaces(applied(o), mask, fs, cells, face, hl,
                         (time.perf_counter() - t0) * 1000)


def cell_colours(grid, plan: ColourPlan, need, values_at) -> np.ndarray:
    """uint8 colour indices of cells ``need`` (None: every cell) under the colour ``plan``
    (no property: one uniform colour); ``values_at(full, need)`` reads the values."""
    if plan.state is None or plan.property is None:
        return np.full(grid.ncells if need is None else need.size, UNIFORM_INDEX, np.uint8)
    full = property_values(grid, plan.property, plan.step, plan.diff)
    vals = np.asarray(full).ravel(order="F") if need is None else values_at(full, need)
    style, lo, hi, gaps = plan.state
    return colour_indices(style, lo, hi, gaps, vals)


def edge_style(mode):
    """The GridVisual's edge style of the ``edges`` option."""
    from geoshade.render.visuals.grid.visual import EdgeStyle

    return EdgeStyle(mode=mode)


# --------------------------------------------------------------------------------------------
# the drawing in this process
# --------------------------------------------------------------------------------------------
class HereFaces(HoldsVisual):
    """Faces drawn in this process: one GridVisual of the options' approach, the faces and
    the values from ``source`` (see the module)."""

    name = "here"

    def __init__(self, ctx, source: GridSource, origin: np.ndarray):
        self.ctx, self.source, self.origin = ctx, source, origin
        self.visual: Any = None
        self.edge_style: Any = None
        self.palette: np.ndarray | None = None   # the palette the visual holds

    @property
    def grid(self):
        return self.source.grid

    # --- building --------------------------------------------------------------------------------
    def open(self, options, plan: ColourPlan, prepared: PreparedFaces | None = None) -> Applied:
        self.source.check(options)
        # CPU: the faces, so the plan is known (faces made for other options are made again)
        if prepared is None or prepared.changes != applied(options):
            prepared = self.prepare(options)
        plan_bytes = self._check_plan(options, prepared)   # before any GPU object
        ms = self._build(options, plan.palette)
        first = self.colours(options, plan) if self.visual.color_cells() is None else None
        out = self.apply(prepared, plan)   # per cell or node: all cells coloured before
        out.geometry_ms, out.plan_bytes = ms, plan_bytes
        out.colours = out.colours or first
        return out

    def _check_plan(self, o, prepared: PreparedFaces) -> int:
        """The chosen approach's GPU bytes for these faces, refused in one line when larger
        than the ``gpu_memory`` option."""
        g = self.grid
        drawn = cells_with_faces(prepared.cells, g.dims) if o.approach == 2 else 0
        plan_bytes = int(sum(gpu_plan(o.approach, g.dims, prepared.n_faces, drawn,
                                      o.zcorn_bits, o.zcorn_store).values()))
        check_fits(plan_bytes, o.gpu_memory, o.approach,
                   o.zcorn_store if o.approach == 3 else None, g.name or "grid")
        return plan_bytes

    def _quantised(self, o):
        if o.approach == 3 and o.zcorn_store == "faces" and o.zcorn_bits == 16:
            return (None, *face_depth_code(self.grid), None)
        if o.approach != 1 and o.zcorn_bits == 16:
            return zcorn_quantise(np.asarray(self.grid.zcorn), bits=16)
        return None

    def _build(self, o, palette: np.ndarray) -> float:
        """A new GridVisual for ``o`` (the old one released); its build time."""
        from geoshade.render.visuals.grid.visual import GridVisual

        self.release()
        t0 = time.perf_counter()
        self.visual = GridVisual(self.ctx, self.grid, self.origin, approach=o.approach,
                                 zcorn_bits=o.zcorn_bits, zcorn_store=o.zcorn_store,
                                 quantised=self._quantised(o), palette=palette,
                                 smear_faults=o.smear_faults,
                                 orientation=self.source.orientation())
        self.palette = palette
        ms = (time.perf_counter() - t0) * 1000
        self.edge_style = edge_style(o.edges)
        return ms

    def remake(self, options, plan: ColourPlan) -> Applied:
        self.source.check(options)   # before the old visual goes
        ms = self._build(options, plan.palette)
        first = self.colours(options, plan)
        out = self.apply(self.prepare(options), plan)
        out.geometry_ms = ms
        out.colours = out.colours or first
        return out

    # --- faces -----------------------------------------------------------------------------------
    def prepare(self, options) -> PreparedFaces:
        self.source.check(options)
        return self.source.faces(options, stage=self._stager(options))

    def _stager(self, o):
        """``stage() -> StagedFaces`` for approach 3 with faces (a source out of core may build
        the records while it makes the faces, a layer at a time), else None."""
        if not (o.approach == 3 and o.zcorn_store == "faces"):
            return None
        q = self._quantised(o)
        quantise = (q[1], q[2]) if q is not None else None
        origin_z = float(self.origin[2])
        return lambda: StagedFaces(self.grid.dims, origin_z, quantise)

    def apply(self, prepared: PreparedFaces, plan: ColourPlan) -> Applied:
        t0 = time.perf_counter()
        if prepared.staged is not None:   # records built with the faces: uploaded, freed
            self.visual.set_staged(prepared.staged)
            prepared.staged = None
            give_back_freed()
        else:
            self.visual.set_faces(prepared.cells, prepared.face, prepared.highlight,
                                  corners=prepared.corners)
        if self.source.out_of_core:   # on the GPU: the CPU columns go before the colours
            prepared.cells, prepared.face = np.zeros((0, 3), np.int32), np.zeros(0, np.uint8)
            prepared.highlight = prepared.corners = None
        colours = None
        if self.visual.color_cells() is not None:  # colours of the newly visible cells
            colours = self.colours(None, plan)
        self.ctx.finish()
        if self.source.out_of_core:   # the colours' temporaries, freed on the heap: returned
            give_back_freed()
        return Applied(prepared.changes, prepared.mask, prepared.faces, prepared.shown,
                       prepared.ms + (time.perf_counter() - t0) * 1000, colours=colours)

    # --- colours ---------------------------------------------------------------------------------
    def colours(self, options, plan: ColourPlan) -> tuple:
        """Upload the colour indices of the cells the GPU holds colours of (``cells``: None =
        all)."""
        palette = plan.palette
        need = self.visual.color_cells()
        ci = cell_colours(self.grid, plan, need, self.source.values_at)
        if self.palette is None or palette.tobytes() != self.palette.tobytes():
            self.palette = palette
            self.visual.set_palette(palette)
        self.visual.set_colors(ci, cells=need)
        self.ctx.finish()
        return ci, need

    # --- drawing ---------------------------------------------------------------------------------
    def drawing_changed(self, options) -> None:
        self.edge_style.mode = options.edges

    def draw(self, camera, target, count: bool, options, shading: dict) -> dict:
        model = model_matrix(self.grid, self.origin, options.exaggeration)
        # the counting frame draws every face (no back-face cull: the same picture), so
        # faces_drawn is the number of faces the GPU built, equal to the FaceSet's
        out = self.visual.draw(camera, model, shading, target.size, self.edge_style,
                               cull=options.cull and not count, count=count)
        return out or {}

    def method(self) -> str:
        vis = self.visual
        return f"approach {vis.approach}" + (f" ({vis.zcorn_store})" if vis.approach == 3
                                             else "")

    def stats(self, options) -> dict:
        vis = self.visual
        s = {"faces": int(vis.n_faces), "approach": vis.approach,
             "zcorn_store": vis.zcorn_store, "zcorn_bits": vis.zcorn_bits,
             "zcorn_max_error": vis.zcorn_max_error,
             "gpu_plan_bytes": int(sum(vis.plan().values())),
             "gpu_breakdown": vis.cache.breakdown(), "edges": self.edge_style.mode}
        if vis.approach == 1:
            s["node_spread"] = vis.node_spread
            s["smeared_nodes"] = vis.smeared_nodes
        s.update(self.source.stats())
        return s

    def notes(self, options) -> list[tuple[str, type[Warning]]]:
        vis = self.visual
        out = []
        if vis.approach == 1 and vis.smeared_nodes and options.smear_faults is None:
            out.append((f"approach 1 smeared the faults: the corners meeting at "
                        f"{vis.smeared_nodes} nodes were averaged (up to "
                        f"{vis.node_spread:.4g} apart); approaches 2 and 3 draw them exactly",
                        UserWarning))
        return [*out, *self.source.notes()]


__all__ = ["FACE_OPTIONS", "UNIFORM_INDEX", "Applied", "FacesDrawing", "GridSource",
           "HereFaces", "PreparedFaces", "applied", "cell_colours", "edge_style",
           "face_depth_code", "prepared_faces"]
