"""The faces backends of :class:`~geoshade.grid.view.GridView`: where a grid's visible faces are
computed, kept and drawn. The View keeps what is the same on every path (options, colour
state, wells, annotations, stats) and owns one backend, chosen when it opens
(:func:`geoshade.grid.view.faces_backend`):

- :class:`MemoryFaces`: a grid in memory; faces from the whole grid
  (:func:`~geoshade.compute.grid_faces.visible_faces`), one GridVisual of the chosen approach;
- :class:`StoreFaces`: a grid out of core (a grid store, dask arrays); faces chunk by chunk on
  the View's scheduler (:func:`~geoshade.compute.grid_chunks.visible_faces_chunked`), the
  drawn faces' corner depths and values gathered from their chunks (approach 3 with faces);
- :class:`~geoshade.grid.distributed.ClusterFaces`: faces computed and drawn on the workers
  of the View's cluster, composited by depth (``distributed=True``).

Each implements :class:`FacesBackend`; the same calls drive all three (tests/gl/
test_grid_backends.py).
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any, Protocol, runtime_checkable

import numpy as np

from geoshade.compute.grid_chunks import (
    GROUP_BATCH,
    face_corner_depths,
    run_tasks,
    shown_mask_lazy,
    visible_faces_chunked,
)
from geoshade.compute.grid_faces import (
    FaceCount,
    _face_set_in_drawing_order,
    _fault_lookup,
    _with_fault_ids,
    visible_faces,
)
from geoshade.compute.grid_geometry import zcorn_quantise, zcorn_quantiser
from geoshade.compute.grid_index_faces import chunk_status, index_faces
from geoshade.grid.cells import colour_indices, fault_faces
from geoshade.grid.geometry import grid_bounds, model_matrix
from geoshade.grid.lazy import array_key, check_options, orientation, store_index_of, values_at
from geoshade.grid.plan import cells_with_faces, check_fits
from geoshade.io.paths import one_line
from geoshade.io.stores.grid_index import DamagedIndexError, GridIndex
from geoshade.render.backend import HoldsVisual
from geoshade.render.visuals.grid.layout import gpu_plan
from geoshade.render.visuals.grid.prepare import cell_numbers

#: the colour index of every cell when no property is shown (the colour map's middle)
UNIFORM_INDEX = 160
#: a grid out of core: up to this many faces, their corner depths are gathered while the faces
#: are prepared (16 bytes a face); more are gathered batch by batch while they are uploaded
LAZY_CORNERS_AHEAD = 1 << 24
#: the options a prepared faces change applies
FACE_OPTIONS = ("filter", "slice", "plane", "faults", "step")


@dataclass
class PreparedFaces:
    """Visible faces built on the CPU for a filter/slice/plane/faults change (see
    :meth:`FacesBackend.prepare`), ready for :meth:`FacesBackend.apply`."""

    changes: dict
    mask: np.ndarray | None
    faces: Any
    cells: np.ndarray
    face: np.ndarray
    highlight: np.ndarray | None
    ms: float
    corners: Any = None                 # (n, 4) corner depths, or corners(sel) (out of core)
    shown: int | None = None            # shown cells (counted once for a grid out of core)


@runtime_checkable
class FacesBackend(Protocol):
    """What a :class:`~geoshade.grid.view.GridView` asks of its faces backend.

    ``view`` is the owning View: the backend reads its grid, options, origin, shading, edge
    style and colour state (:meth:`~geoshade.grid.view.GridView.colour_state`), never its
    private steps.
    """

    #: ``"memory"``, ``"store"`` or ``"cluster"``
    name: str
    #: the GridVisual in this process (None on a cluster: the workers hold theirs)
    visual: Any

    def open(self, prepared: PreparedFaces | None = None) -> None:
        """Build the first faces, colours and GPU objects for the View's options
        (``prepared``: those faces, made already on another thread; a cluster ignores it)."""

    def remake(self) -> None:
        """New GPU objects for a new approach, depth precision or storage (faces kept)."""

    def prepare(self, options) -> PreparedFaces:
        """CPU half of a filter, slice, plane, faults (or filtering step) change: the faces of
        ``options`` (no GL: any thread; errors leave the View as it was)."""

    def apply(self, prepared: PreparedFaces) -> None:
        """GL half: make ``prepared`` the drawn faces (new cells' colours included)."""

    def colours(self, state, palette: np.ndarray) -> None:
        """Colour the drawn cells by the View's colour ``state`` (None: one uniform colour)
        with ``palette``."""

    def drawing_changed(self) -> None:
        """The edge style or back-face culling changed."""

    def draw(self, camera, target, count: bool) -> dict:
        """Draw the faces into ``target`` (the GPU's counts with ``count``)."""

    def stats(self) -> dict:
        """The faces' stats: ``faces approach zcorn_store zcorn_bits zcorn_max_error
        gpu_plan_bytes gpu_breakdown`` (and what the backend adds)."""

    def method(self) -> str:
        """The drawing method, for the stats' ``method``."""

    def notes(self) -> list[tuple[str, type[Warning]]]:
        """Notes to warn about once per draw (workers lost, approximations)."""

    @property
    def gpu_bytes(self) -> int:
        """GPU bytes the faces hold now (on every machine that draws them)."""

    def release(self) -> None:
        """Free the GPU objects (idempotent)."""


def face_depth_code(grid) -> tuple[float, float]:
    """``(z0, scale)`` of the 16-bit depth code of approach 3 with faces: only the drawn
    faces' corners are quantised (no 16-bit copy of ZCORN)."""

    zb = grid_bounds(grid)[:, 2]
    z0, scale = zcorn_quantiser(float(zb[0]), float(zb[1]), 16)[:2]
    return float(z0), float(scale)


def applied(o) -> dict:
    """The options a faces change makes current."""
    return {k: getattr(o, k) for k in FACE_OPTIONS}


class MemoryFaces(HoldsVisual):
    """A grid in memory: faces from the whole grid, one GridVisual (see the module)."""

    name = "memory"

    def __init__(self, view):
        self.view = view
        self.visual: Any = None
        self.edge_style: Any = None

    # --- building --------------------------------------------------------------------------------
    def open(self, prepared: PreparedFaces | None = None) -> None:
        # CPU: the faces, so the plan is known (faces made for other options are made again)
        if prepared is None or prepared.changes != applied(self.view.options):
            prepared = self.prepare(self.view.options)
        self._check_plan(prepared)                   # before any GPU object
        self.remake(faces=False)
        if self.visual.color_cells() is None:  # per cell or node: all cells, before the faces
            self.view.update_colours()
        self.apply(prepared)

    def _check_plan(self, prepared: PreparedFaces) -> None:
        """The chosen approach's GPU bytes for these faces (the View's ``plan_bytes``),
        refused in one line when larger than the ``gpu_memory`` option."""

        v = self.view
        o, g = v.options, v.grid
        drawn = cells_with_faces(prepared.cells, g.dims) if o.approach == 2 else 0
        v.plan_bytes = int(sum(gpu_plan(o.approach, g.dims, len(prepared.face), drawn,
                                        o.zcorn_bits, o.zcorn_store).values()))
        check_fits(v.plan_bytes, o.gpu_memory, o.approach,
                   o.zcorn_store if o.approach == 3 else None, g.name or "grid")

    def _quantised(self):

        o = self.view.options
        if o.approach == 3 and o.zcorn_store == "faces" and o.zcorn_bits == 16:
            return (None, *face_depth_code(self.view.grid), None)
        if o.approach != 1 and o.zcorn_bits == 16:
            return zcorn_quantise(np.asarray(self.view.grid.zcorn), bits=16)
        return None

    def _orientation(self) -> float | None:
        return None   # the visual takes it from the whole grid

    def remake(self, faces: bool = True) -> None:
        from geoshade.render.visuals.grid.visual import EdgeStyle, GridVisual

        v = self.view
        o = v.options
        if self.visual is not None:
            self.visual.release()
            self.visual = None
        t0 = time.perf_counter()
        self.visual = GridVisual(v.ctx, v.grid, v.origin, approach=o.approach,
                                 zcorn_bits=o.zcorn_bits, zcorn_store=o.zcorn_store,
                                 quantised=self._quantised(), palette=v.palette,
                                 smear_faults=o.smear_faults, orientation=self._orientation())
        v.geometry_ms = (time.perf_counter() - t0) * 1000
        self.edge_style = EdgeStyle(mode=o.edges)
        if faces:
            v.update_colours()
            self.apply(self.prepare(o))

    # --- faces -----------------------------------------------------------------------------------
    def prepare(self, options) -> PreparedFaces:

        t0 = time.perf_counter()
        mask = self.view.shown_mask(options)
        fs = visible_faces(self.view.grid, shown=mask)
        return self._prepared(options, mask, fs, t0)

    @staticmethod
    def _prepared(o, mask, fs, t0: float) -> PreparedFaces:
        cells, face, hl = fault_faces(fs, o.faults)
        return PreparedFaces(applied(o), mask, fs, cells, face, hl,
                             (time.perf_counter() - t0) * 1000)

    def apply(self, prepared: PreparedFaces) -> None:
        v = self.view
        t0 = time.perf_counter()
        self.visual.set_faces(prepared.cells, prepared.face, prepared.highlight,
                              corners=prepared.corners)
        self._uploaded(prepared)
        v.shown_cells = prepared.shown
        if self.visual.color_cells() is not None:  # colours of the newly visible cells
            v.update_colours()
        v.ctx.finish()
        v.faces_applied(prepared, (time.perf_counter() - t0) * 1000)

    def _uploaded(self, prepared: PreparedFaces) -> None:
        """The faces are on the GPU (a grid out of core drops their CPU columns here)."""

    # --- colours ---------------------------------------------------------------------------------
    def colours(self, state, palette: np.ndarray) -> None:
        v = self.view
        o, g = v.options, v.grid
        need = self.visual.color_cells()
        if state is None or o.property is None:
            ci = np.full(g.ncells if need is None else need.size, UNIFORM_INDEX, np.uint8)
        else:
            full = v.values(o.property, o.step)
            # the drawn cells' values (a grid store: read only from the chunks holding them)
            vals = (np.asarray(full).ravel(order="F") if need is None
                    else self._values_at(full, need))
            style, lo, hi, gaps = state
            ci = colour_indices(style, lo, hi, gaps, vals)
        if palette.tobytes() != v.palette.tobytes():
            v.palette = palette
            self.visual.set_palette(palette)
        # the colour indices of the cells the GPU holds colours of (``cells``: None = all)
        v.colour_indices = (ci, need)
        self.visual.set_colors(ci, cells=need)
        v.ctx.finish()

    def _values_at(self, full, need: np.ndarray) -> np.ndarray:
        """The values of the cell array ``full`` at the cells ``need`` (ascending numbers)."""
        return values_at(full, need, self.view.grid.dims)

    # --- drawing ---------------------------------------------------------------------------------
    def drawing_changed(self) -> None:
        self.edge_style.mode = self.view.options.edges

    def draw(self, camera, target, count: bool) -> dict:
        v = self.view
        o = v.options
        model = model_matrix(v.grid, v.origin, o.exaggeration)
        # the counting frame draws every face (no back-face cull: the same picture), so
        # faces_drawn is the number of faces the GPU built, equal to the FaceSet's
        out = self.visual.draw(camera, model, v.shading, target.size, self.edge_style,
                               cull=o.cull and not count, count=count)
        return out or {}

    def method(self) -> str:
        vis = self.visual
        return f"approach {vis.approach}" + (f" ({vis.zcorn_store})" if vis.approach == 3
                                             else "")

    def stats(self) -> dict:
        vis = self.visual
        s = {"faces": int(vis.n_faces), "approach": vis.approach,
             "zcorn_store": vis.zcorn_store, "zcorn_bits": vis.zcorn_bits,
             "zcorn_max_error": vis.zcorn_max_error,
             "gpu_plan_bytes": int(sum(vis.plan().values())),
             "gpu_breakdown": vis.cache.breakdown(), "edges": self.edge_style.mode}
        if vis.approach == 1:
            s["node_spread"] = vis.node_spread
            s["smeared_nodes"] = vis.smeared_nodes
        return s

    def notes(self) -> list[tuple[str, type[Warning]]]:
        vis = self.visual
        if vis.approach == 1 and vis.smeared_nodes and self.view.options.smear_faults is None:
            return [(f"approach 1 smeared the faults: the corners meeting at "
                     f"{vis.smeared_nodes} nodes were averaged (up to {vis.node_spread:.4g} "
                     f"apart); approaches 2 and 3 draw them exactly", UserWarning)]
        return []


class StoreFaces(MemoryFaces):
    """A grid out of core (a grid store): the faces, corner depths and face-cell values from
    the store's index where it has one (:mod:`geoshade.io.stores.grid_index`; a filter or slice
    reads only the chunks its statistics cannot decide), else faces chunk by chunk on the
    View's scheduler, only the drawn faces' corners and values read (see the module)."""

    name = "store"

    def __init__(self, view):
        super().__init__(view)
        # what a grid out of core cannot be drawn with: one line, before any work
        check_options(view.grid, view.options)
        self._orient: float | None = None
        self._index: Any = None          # GridIndex, or the one line why there is none
        self._said = False                # the index note is said once
        self._from: dict = {"faces_from": "computed"}

    def _orientation(self) -> float | None:
        """The back-face sign, from a sample of cells read chunk by chunk (once)."""
        if self._orient is None:

            self._orient = float(orientation(self.view.grid))
        return self._orient

    def remake(self, faces: bool = True) -> None:
        check_options(self.view.grid, self.view.options)   # before the old visual goes
        super().remake(faces)

    # --- the index ---------------------------------------------------------------------------
    def index(self) -> GridIndex | None:
        """The store's checked index (opened once), or None (the reason kept for the note)."""
        if self._index is None:
            self._index = store_index_of(self.view.grid)
        return self._index if isinstance(self._index, GridIndex) else None

    def _lost(self, err: Exception) -> None:
        """An index array failed its check: drawn without the index from now on (said once)."""
        self._index, self._said = f"{one_line(err)}; drawn without the index", False

    def prepare(self, options) -> PreparedFaces:
        """The faces of ``options``: from the index (no ZCORN read; a filter or slice computes
        only the chunks its statistics and box cannot decide), else chunk by chunk."""
        check_options(self.view.grid, options)
        idx = self.index()
        if idx is not None:
            try:
                return self._prepare_indexed(options, idx)
            except DamagedIndexError as err:
                self._lost(err)
        return self._prepare_computed(options)

    def _prepare_computed(self, options) -> PreparedFaces:
        """The shown mask as dask blocks, the faces chunk by chunk with a one-cell halo, the
        corner depths of the drawn faces gathered from their ZCORN chunks."""

        v = self.view
        t0 = time.perf_counter()
        mask = shown_mask_lazy(v.grid, options.filter, options.slice, step=options.step)
        fs = visible_faces_chunked(v.grid, shown=mask, progress=v.progress,
                                   scheduler=v.work)   # the View's cluster, kept up
        prepared = self._prepared(options, mask, fs, t0)  # assembled in drawing order
        # only the drawn faces' cells and codes are kept: the other columns go now
        prepared.faces = FaceCount(len(fs), fs.shown)
        del fs
        zcorn, cells, face = v.grid.zcorn, prepared.cells, prepared.face
        if face.size <= LAZY_CORNERS_AHEAD:  # gathered here (a viewer's worker thread)
            prepared.corners = face_corner_depths(zcorn, cells, face)
        else:  # batch by batch while the records are built (no (n, 4) array)
            prepared.corners = lambda sel: face_corner_depths(zcorn, cells[sel], face[sel])
        prepared.shown = prepared.faces.shown  # counted chunk by chunk with the faces
        prepared.ms = (time.perf_counter() - t0) * 1000
        self._from = {"faces_from": "computed"}
        return prepared

    def _prepare_indexed(self, options, idx: GridIndex) -> PreparedFaces:
        g = self.view.grid
        t0 = time.perf_counter()
        mask = shown_mask_lazy(g, options.filter, options.slice, step=options.step)
        def stats(key, t):  # the store's own arrays only (a --param has no statistics)
            arr = g.properties.get(key[6:]) if t is None else g.steps[t].get(key[6:])
            return idx.stats(key, t) if array_key(g, arr) == (key, t) else None

        status = chunk_status(g, idx.nactive, stats, options.filter, options.slice,
                              options.step)
        cells, face, fault, nbs = idx.faces()
        keys, kid = _fault_lookup(g)
        look = None
        # the unfiltered grid (or a filter that keeps every active cell): the stored faces as
        # they are (chunks without an active cell hold no stored face and are "skipped")
        if ((status == 1) | (idx.nactive == 0)).all():
            fs = _with_fault_ids(g, cells, face, fault, nbs, keys, kid)
            fs.shown = int(idx.nactive.sum())
            corners = idx.corners()
            if options.faults == "hide":  # the corners of the faces fault_faces keeps
                corners = corners[~(fs.fault & fs.neighbour_shown)]
            self._from = {"faces_from": "index", "chunks_skipped": 0,
                          "chunks_from_index": int(status.size), "chunks_computed": 0}
        else:
            act = g.actnum
            nb = tuple(len(a) for a in mask.chunks)

            def read_shown(sel):  # wholly selected chunks: ACTNUM only; on the View's cluster
                return run_tasks([(act.blocks[i] != 0) if status[np.ravel_multi_index(i, nb)]
                                  == 1 else mask.blocks[i] for i in sel], self.view.work)

            def chunk_faces(c):
                pos = idx.chunk_positions(c)
                return cells[pos], face[pos], fault[pos], nbs[pos]

            parts, shown, counts = index_faces(g, status, read_shown, chunk_faces,
                                               idx.nactive, progress=self.view.progress)
            # the corner lookup, then the index's face columns go before the assembly; where
            # no chunk is selected wholly every shown chunk's ZCORN is read for the faces the
            # filter uncovers anyway: all corners from there (no lookup of the index's faces)
            look = (self._corner_lookup(idx, status, cells, face) if (status == 1).any()
                    else lambda c, f: face_corner_depths(g.zcorn, c, f))
            del cells, face, fault, nbs, chunk_faces
            fs = _face_set_in_drawing_order(g, parts, keys, kid)
            fs.shown = shown
            corners = None
            self._from = {"faces_from": "index", "chunks_skipped": counts["skipped"],
                          "chunks_from_index": counts["from_index"],
                          "chunks_computed": counts["computed"]}
        prepared = self._prepared(options, mask, fs, t0)
        prepared.faces = FaceCount(len(fs), fs.shown)
        prepared.shown = fs.shown
        del fs
        if look is not None:  # the index's corners where it has the face, else ZCORN's
            pc, pf = prepared.cells, prepared.face
            if pf.size <= LAZY_CORNERS_AHEAD:
                corners = look(pc, pf)
            else:  # batch by batch while the records are built (no (n, 4) array)
                corners = lambda sel: look(pc[sel], pf[sel])   # noqa: E731
        prepared.corners = corners
        prepared.ms = (time.perf_counter() - t0) * 1000
        return prepared

    def _corner_lookup(self, idx: GridIndex, status, cells, face):
        """``look(cells, face) -> (n, 4)`` corner depths: the index's for the faces it holds
        (in the chunks ``status`` selects), ZCORN's — only the chunks holding them — for faces
        a filter or slice uncovered."""
        g = self.view.grid

        def face_keys(c, f):  # one int64 per face: cell number * 6 + direction
            return cell_numbers(c, g.dims) * 6 + f

        pos = [idx.chunk_positions(c) for c in np.flatnonzero(status)]
        ipos = np.concatenate(pos) if pos else np.zeros(0, np.int64)
        ikey = np.empty(ipos.size, np.int64)
        for b0 in range(0, ipos.size, GROUP_BATCH):  # batches: no (n, 3) int64 copy
            p = ipos[b0:b0 + GROUP_BATCH]
            ikey[b0:b0 + p.size] = face_keys(cells[p], face[p])
        order = np.argsort(ikey)
        ikey, ipos = ikey[order], ipos[order]
        del order
        stored = idx.corners() if ikey.size else None

        def look(fcells: np.ndarray, fface: np.ndarray) -> np.ndarray:
            out = np.empty((len(fface), 4), np.float32)
            misses = []
            for b0 in range(0, len(fface), GROUP_BATCH):  # batches: bounded temporaries
                key = face_keys(fcells[b0:b0 + GROUP_BATCH], fface[b0:b0 + GROUP_BATCH])
                at = np.clip(np.searchsorted(ikey, key), 0, max(0, ikey.size - 1))
                hit = ikey[at] == key if ikey.size else np.zeros(key.size, bool)
                if hit.any():
                    out[b0:b0 + key.size][hit] = stored[ipos[at[hit]]]
                misses.append(b0 + np.flatnonzero(~hit))
                del key, at, hit
            miss = np.concatenate(misses) if misses else np.zeros(0, np.int64)
            if miss.size:  # faces a filter or slice uncovered: their ZCORN chunks only
                out[miss] = face_corner_depths(g.zcorn, fcells[miss], fface[miss])
            return out

        return look

    def _values_at(self, full, need: np.ndarray) -> np.ndarray:
        """The face cells' values from the index's cache when ``full`` is one of the store's
        arrays and ``need`` is among the stored face cells (one small read), else read from
        the chunks holding them."""
        idx = self.index()
        key = array_key(self.view.grid, full) if idx is not None else None
        if key is not None:
            try:
                stored = idx.cells
                if need.size == stored.size and np.array_equal(need, stored):
                    self._from["values_from"] = "index"   # the unfiltered faces' cells
                    return idx.values(*key)
                at = np.minimum(np.searchsorted(stored, need), max(0, stored.size - 1))
                hit = stored[at] == need if stored.size else np.zeros(need.size, bool)
                if need.size and hit.mean() >= 0.5:  # mostly stored: the rest from chunks
                    out = np.empty(need.size, idx.values(*key).dtype)
                    out[hit] = idx.values(*key)[at[hit]]
                    if not hit.all():
                        out[~hit] = values_at(full, need[~hit], self.view.grid.dims)
                    self._from["values_from"] = "index" if hit.all() else "index+chunks"
                    return out
            except DamagedIndexError as err:
                self._lost(err)
        self._from["values_from"] = "chunks"
        return super()._values_at(full, need)

    def stats(self) -> dict:
        s = super().stats()
        s.update(self._from)
        s["index"] = "used" if self.index() is not None else (self._index or "none")
        return s

    def notes(self) -> list[tuple[str, type[Warning]]]:
        out = super().notes()
        self.index()
        if isinstance(self._index, str) and self._index and not self._said:
            self._said = True   # once per View
            out.append((self._index, UserWarning))
        return out

    def _uploaded(self, prepared: PreparedFaces) -> None:
        # the faces are on the GPU: their CPU columns go before the colours
        prepared.cells, prepared.face = np.zeros((0, 3), np.int32), np.zeros(0, np.uint8)
        prepared.highlight = prepared.corners = None


__all__ = ["FACE_OPTIONS", "LAZY_CORNERS_AHEAD", "UNIFORM_INDEX", "FacesBackend",
           "MemoryFaces", "PreparedFaces", "StoreFaces", "applied", "face_depth_code"]
