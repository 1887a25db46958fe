"""Where a :class:`~geoshade.grid.view.GridView`'s cells live: the *source* of its faces and
values (:class:`~geoshade.grid.backends.GridSource`), chosen when the View opens
(:func:`open_source`):

- :class:`MemorySource`: a grid in memory; faces from the whole grid
  (:func:`~geoshade.compute.grid.faces.visible_faces`);
- :class:`IndexedStore`: a grid store with its index (:mod:`geoshade.io.stores.grid_index`):
  the faces, corner depths and face-cell values from the index; a filter or slice computes
  only the chunks its statistics cannot decide (on the View's scheduler). An index that fails
  its check while in use is said once and the store is drawn as a :class:`ChunkedStore`;
- :class:`ChunkedStore`: a grid store without an index: faces chunk by chunk on the View's
  scheduler (:func:`~geoshade.compute.grid.chunks.visible_faces_chunked`), only the drawn faces'
  corners and values read.

A grid store is drawn with approach 3 and its faces' corners only (``check``). Every source is
drawn here or on a cluster alike (:mod:`geoshade.grid.backends`).
"""

from __future__ import annotations

import time
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import numpy as np

from geoshade.compute.grid.chunks import (
    block_reader,
    chunk_source,
    face_corner_depths,
    run_tasks,
    shown_block_reader,
    shown_mask_lazy,
    visible_faces_chunked,
)
from geoshade.compute.grid.faces import (
    FaceCount,
    _face_set_in_drawing_order,
    _fault_lookup,
    _with_fault_ids,
    visible_faces,
)
from geoshade.compute.grid.geometry import cell_centres
from geoshade.compute.grid.index_faces import IndexFaces, chunk_status
from geoshade.grid.backends import PreparedFaces, applied, prepared_faces
from geoshade.grid.cells import fault_faces
from geoshade.grid.lazy import (
    array_key,
    check_options,
    is_lazy,
    orientation,
    store_index_of,
    values_at,
)
from geoshade.io.paths import give_back_freed, map_big_allocations, one_line
from geoshade.io.stores.grid_index import DamagedIndexError, GridIndex
from geoshade.models.names import properties_at
from geoshade.scheduler import Scheduler

#: a grid out of core: up to this many faces, their corner depths are gathered while the faces
#: are prepared (16 bytes a face); more are gathered batch by batch while they are uploaded
LAZY_CORNERS_AHEAD = 1 << 24


def _mostly_stored(stored: np.ndarray, need: np.ndarray, sample: int = 4096) -> bool:
    """Whether a sample of the cells ``need`` (sorted) finds at least 40 % of them among the
    index's ``stored`` face cells (a filter that shows cells inside the grid finds few): the
    whole lookup is made only then."""
    if not (stored.size and need.size):
        return False
    few = need[np.linspace(0, need.size - 1, min(sample, need.size)).astype(np.int64)]
    at = np.minimum(np.searchsorted(stored, few), stored.size - 1)
    return bool((stored[at] == few).mean() >= 0.4)


def open_source(grid, work=None, progress=None):
    """The source of ``grid``: in memory, a grid store with its checked index, or a grid store
    computed chunk by chunk (``work``: the View's scheduler session; ``progress``: its
    callback)."""
    if not is_lazy(grid):
        return MemorySource(grid)
    map_big_allocations()   # the layers' freed arrays given back, not kept on the heaps
    idx = store_index_of(grid)
    if isinstance(idx, GridIndex):
        return IndexedStore(grid, idx, work, progress)
    return ChunkedStore(grid, work, progress, reason=idx)


def _corners_of(look, cells: np.ndarray, face: np.ndarray):
    """The corner depths of the faces ``(cells, face)`` by ``look``: gathered now, or batch
    by batch while the records are built (no (n, 4) array) beyond
    :data:`LAZY_CORNERS_AHEAD` faces."""
    if face.size <= LAZY_CORNERS_AHEAD:
        return look(cells, face)
    return lambda sel: look(cells[sel], face[sel])


class MemorySource:
    """A grid in memory (see the module)."""

    name = "memory"
    out_of_core = False

    def __init__(self, grid):
        self.grid = grid
        self._centres: Any = None

    def check(self, options) -> None:
        return None   # every approach

    def shown_mask(self, options) -> np.ndarray:
        """(nx, ny, nz) bool: active cells inside the slice, passing the filter and on the
        kept side of the plane of ``options``."""
        g, o = self.grid, options
        mask = g.active.copy()
        box = np.zeros(g.dims, bool)
        box[o.slice] = True
        mask &= box
        shown = o.cells_filter()   # the filter and the ranges
        if shown is not None:   # static and the step's properties, read when named
            mask &= np.asarray(shown.mask(properties_at(g, o.step or 0), g.dims), bool)
        if o.plane is not None:
            if self._centres is None:
                c = np.asarray(cell_centres(g), np.float64).reshape(*g.dims, 3)
                t = g.map_transform()
                xy = c[..., :2] @ t[:2, :2].T + t[:2, 2]
                self._centres = np.concatenate([xy, -c[..., 2:]], axis=-1)  # z up
            mask &= o.plane.keeps(self._centres.reshape(-1, 3)).reshape(g.dims)
        return mask

    def faces(self, options, stage=None) -> PreparedFaces:
        t0 = time.perf_counter()
        mask = self.shown_mask(options)
        return prepared_faces(options, mask, visible_faces(self.grid, shown=mask), t0)

    def values_at(self, full, need: np.ndarray) -> np.ndarray:
        return values_at(full, need, self.grid.dims)

    def orientation(self) -> float | None:
        return None   # the visual takes it from the whole grid

    def stats(self) -> dict:
        return {}

    def notes(self) -> list[tuple[str, type[Warning]]]:
        return []


class ChunkedStore:
    """A grid store drawn without an index (see the module); ``reason``: why there is none
    (said once)."""

    name = "chunked store"
    out_of_core = True

    def __init__(self, grid, work=None, progress=None, reason: str = ""):
        self.grid, self.work, self.progress = grid, work, progress
        self.reason = reason
        self._said = False
        self._orient: float | None = None
        self.came_from: dict = {"faces_from": "computed"}

    def check(self, options) -> None:
        check_options(self.grid, options)

    def shown_mask(self, options):
        return shown_mask_lazy(self.grid, options.cells_filter(), options.slice,
                               step=options.step)

    def faces(self, options, stage=None) -> PreparedFaces:
        """The shown mask as dask blocks, the faces chunk by chunk with a one-cell halo, the
        corner depths of the drawn faces gathered from their ZCORN chunks."""
        t0 = time.perf_counter()
        g = self.grid
        mask = self.shown_mask(options)
        fs = visible_faces_chunked(g, shown=mask, progress=self.progress,
                                   scheduler=self.work)   # the View's cluster, kept up
        prepared = prepared_faces(options, mask, fs, t0)  # assembled in drawing order
        # only the drawn faces' cells and codes are kept: the other columns go now
        prepared.faces = FaceCount(len(fs), fs.shown)
        del fs
        zcorn = g.zcorn
        prepared.corners = _corners_of(lambda c, f: face_corner_depths(zcorn, c, f),
                                       prepared.cells, prepared.face)
        prepared.shown = prepared.faces.shown  # counted chunk by chunk with the faces
        prepared.ms = (time.perf_counter() - t0) * 1000
        self.came_from = {"faces_from": "computed"}
        return prepared

    def values_at(self, full, need: np.ndarray) -> np.ndarray:
        self.came_from["values_from"] = "chunks"
        return values_at(full, need, self.grid.dims)

    def orientation(self) -> float | None:
        """The back-face sign, from a sample of cells read chunk by chunk (once)."""
        if self._orient is None:
            self._orient = float(orientation(self.grid))
        return self._orient

    def stats(self) -> dict:
        return {**self.came_from, "index": self.reason or "none"}

    def notes(self) -> list[tuple[str, type[Warning]]]:
        if self.reason and not self._said:
            self._said = True   # once per View
            return [(self.reason, UserWarning)]
        return []


class IndexedStore:
    """A grid store drawn from its index (see the module); drawn as its :class:`ChunkedStore`
    once the index fails a check."""

    name = "indexed store"
    out_of_core = True

    def __init__(self, grid, index: GridIndex, work=None, progress=None):
        self.grid, self.work, self.progress = grid, work, progress
        self.index: GridIndex | None = index
        self.chunked = ChunkedStore(grid, work, progress)   # without the index
        self.came_from: dict = {"faces_from": "computed"}

    def _lost(self, err: Exception) -> None:
        """An index array failed its check: drawn without the index from now on (said once)."""
        self.index = None
        self.chunked.reason = f"{one_line(err)}; drawn without the index"
        self.chunked.came_from = dict(self.came_from)

    def check(self, options) -> None:
        check_options(self.grid, options)

    def shown_mask(self, options):
        return self.chunked.shown_mask(options)

    def orientation(self) -> float | None:
        return self.chunked.orientation()   # the index keeps it

    def faces(self, options, stage=None) -> PreparedFaces:
        """The faces of ``options`` from the index (no ZCORN read; a filter or slice computes
        only the chunks its statistics and box cannot decide); with ``stage`` (``stage() ->
        StagedFaces``), a filter's or slice's faces built into GPU records a layer at a
        time."""
        if self.index is not None:
            try:
                return self._faces(options, self.index, stage)
            except DamagedIndexError as err:
                self._lost(err)
        return self.chunked.faces(options)

    def _faces(self, options, idx: GridIndex, stage=None) -> PreparedFaces:
        g = self.grid
        t0 = time.perf_counter()
        mask = self.shown_mask(options)

        def stats(key, t):  # the store's own arrays only (a --param has no statistics)
            arr = g.properties.get(key[6:]) if t is None else g.steps[t].get(key[6:])
            return idx.stats(key, t) if array_key(g, arr) == (key, t) else None

        status = chunk_status(g, idx.nactive, stats, options.cells_filter(), options.slice,
                              options.step)
        cells, face, fault, nbs = idx.faces()
        keys, kid = _fault_lookup(g)
        # the unfiltered grid (or a filter that keeps every active cell): the stored faces as
        # they are (chunks without an active cell hold no stored face and are "skipped")
        if ((status == 1) | (idx.nactive == 0)).all():
            fs = _with_fault_ids(g, cells, face, fault, nbs, keys, kid)
            fs.shown = int(idx.nactive.sum())
            corners = idx.corners()
            if options.faults == "hide":  # the corners of the faces fault_faces keeps
                corners = corners[~(fs.fault & fs.neighbour_shown)]
            came = {"faces_from": "index", "chunks_skipped": 0,
                    "chunks_from_index": int(status.size), "chunks_computed": 0}
        else:
            act = g.actnum
            nb = tuple(len(a) for a in mask.chunks)

            if Scheduler.parse(self.work).in_place:   # here: each chunk read, no dask graph
                shown_of = shown_block_reader(g, options.cells_filter(), options.slice,
                                              options.step)
                act_of = block_reader(act) if chunk_source(act) is not None else None

                def one_shown(i):  # wholly selected chunks: ACTNUM only
                    whole = status[np.ravel_multi_index(i, nb)] == 1
                    return (act_of(i) != 0) if whole and act_of is not None else shown_of(i)

                def read_shown(sel):
                    with ThreadPoolExecutor(2) as pool:
                        return list(pool.map(one_shown, sel))
            else:
                def read_shown(sel):  # wholly selected chunks: ACTNUM only; on the cluster
                    return run_tasks([(act.blocks[i] != 0) if status[np.ravel_multi_index(
                        i, nb)] == 1 else mask.blocks[i] for i in sel], self.work)

            def chunk_faces(c):
                pos = idx.chunk_positions(c)
                return cells[pos], face[pos], fault[pos], nbs[pos]

            stored = idx.corners() if (status == 1).any() else None
            zcorn_block = block_reader(g.zcorn)   # ZCORN, read where the faces are made

            def chunk_corners(c):
                return stored[idx.chunk_positions(c)]

            # each chunk's faces with their corners (the index's where it keeps the chunk's
            # faces, else the chunk's ZCORN block, read once), then in drawing order
            made = IndexFaces(g, status, read_shown, chunk_faces, idx.nactive,
                              progress=self.progress, zcorn_block=zcorn_block,
                              chunk_corners=chunk_corners)
            counts = made.counts
            came = {"faces_from": "index", "chunks_skipped": counts["skipped"],
                    "chunks_from_index": counts["from_index"],
                    "chunks_computed": counts["computed"], "staged": stage is not None}
            if stage is not None:   # a layer of chunks at a time, straight into GPU records
                prepared = self._staged(options, mask, made, stage(), keys, kid, t0)
                self.came_from = came
                return prepared
            parts, shown = made.parts()
            del cells, face, fault, nbs, chunk_faces, stored, made
            fs, corners = _face_set_in_drawing_order(g, parts, keys, kid, with_corners=True)
            fs.shown = shown
            if options.faults == "hide":  # the corners of the faces fault_faces keeps
                corners = corners[~(fs.fault & fs.neighbour_shown)]
        prepared = prepared_faces(options, mask, fs, t0)
        prepared.faces = FaceCount(len(fs), fs.shown)
        prepared.shown = fs.shown
        del fs
        prepared.corners = corners
        prepared.ms = (time.perf_counter() - t0) * 1000
        self.came_from = came
        return prepared

    def _staged(self, options, mask, made, staged, keys, kid, t0: float) -> PreparedFaces:
        """The faces of a filter or slice made a layer of chunks at a time (whole k-slabs of
        the drawing order, top down), each layer assembled in drawing order and built into
        GPU records (:class:`~geoshade.render.visuals.grid.prepare.StagedFaces`) while the
        next layer's chunks are read: the faces' columns and corners of two layers are held,
        not of all (89.5 M faces at 1e9: ~3 GB less)."""
        nfaces = shown = 0
        layers = made.layers()
        with ThreadPoolExecutor(1) as ahead:   # the next layer's chunks read meanwhile
            nxt = ahead.submit(made.parts, layers[0]) if layers else None
            for at in range(len(layers)):
                parts, n = nxt.result()
                nxt = ahead.submit(made.parts, layers[at + 1]) if at + 1 < len(layers) \
                    else None
                shown += n
                nfaces += self._stage_layer(options, parts, staged, keys, kid)
                del parts
                give_back_freed()   # the layer's temporaries, freed on threads' arenas
        prepared = PreparedFaces(applied(options), mask, FaceCount(nfaces, shown),
                                 np.zeros((0, 3), np.int32), np.zeros(0, np.uint8), None,
                                 (time.perf_counter() - t0) * 1000, shown=shown, staged=staged)
        return prepared

    def _stage_layer(self, options, parts, staged, keys, kid) -> int:
        """One layer's parts in drawing order, staged as GPU records; its faces."""
        g = self.grid
        if not parts:
            return 0
        fs, corners = _face_set_in_drawing_order(g, parts, keys, kid, with_corners=True,
                                                 in_i_order=True)   # IndexFaces.layers' order
        del parts
        nfaces = len(fs)
        cells, face, hl = fault_faces(fs, options.faults)
        if options.faults == "hide":  # the corners of the faces fault_faces keeps
            corners = corners[~(fs.fault & fs.neighbour_shown)]
        del fs
        staged.add(cells, face, hl, corners)
        return nfaces

    def values_at(self, full, need: np.ndarray) -> np.ndarray:
        """The face cells' values from the index's cache when ``full`` is one of the store's
        arrays and ``need`` is among the stored face cells (one small read), else read from
        the chunks holding them."""
        idx = self.index
        if idx is None:
            return self.chunked.values_at(full, need)
        key = array_key(self.grid, full)
        if key is not None:
            try:
                stored = idx.cells
                if need.size == stored.size and np.array_equal(need, stored):
                    self.came_from["values_from"] = "index"   # the unfiltered faces' cells
                    return idx.values(*key)
                if not _mostly_stored(stored, need):  # a filter's cells: from the chunks
                    self.came_from["values_from"] = "chunks"
                    return values_at(full, need, self.grid.dims)
                at = np.minimum(np.searchsorted(stored, need), max(0, stored.size - 1))
                hit = stored[at] == need if stored.size else np.zeros(need.size, bool)
                if need.size and hit.mean() >= 0.5:  # mostly stored: the rest from chunks
                    out = np.empty(need.size, idx.values(*key).dtype)
                    out[hit] = idx.values(*key)[at[hit]]
                    if not hit.all():
                        out[~hit] = values_at(full, need[~hit], self.grid.dims)
                    self.came_from["values_from"] = "index" if hit.all() else "index+chunks"
                    return out
            except DamagedIndexError as err:
                self._lost(err)
                return self.chunked.values_at(full, need)
        self.came_from["values_from"] = "chunks"
        return values_at(full, need, self.grid.dims)

    def stats(self) -> dict:
        if self.index is None:
            return self.chunked.stats()
        return {**self.came_from, "index": "used"}

    def notes(self) -> list[tuple[str, type[Warning]]]:
        return [] if self.index is not None else self.chunked.notes()


__all__ = ["LAZY_CORNERS_AHEAD", "ChunkedStore", "IndexedStore", "MemorySource",
           "open_source"]
