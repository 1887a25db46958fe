"""The cluster drawing of the grid View (:class:`ClusterFaces`: ``GridView(grid,
distributed=True, scheduler=...)``) and its worker side (:class:`GridPartsProducer`): a
corner-point grid whose faces are computed and drawn on the workers of a ``dask.distributed``
cluster, composited by depth.

The grid is cut into **parts**: ranges of layers ``k0 <= k < k1`` spanning every i and j, made
of whole k-slabs of the faces' drawing order (:func:`geoshade.compute.grid.faces.drawing_slab`)
and, where the store's chunks allow, of whole chunk layers. Each worker computes the visible
faces of its parts chunk by chunk from the grid store itself
(:func:`~geoshade.compute.grid.chunks.visible_faces_chunked` with ``kspan``: the chunks holding
the part's layers and their neighbours' skins), gathers their corner depths and colours, keeps
them in its own headless context (approach 3 with faces, the single process's visual) and,
per frame, returns colour, depth and rank of its screen footprint
(:mod:`geoshade.render.distributed`). A camera change sends a camera; a property or step
switch sends the colour scale (each worker reads its face cells' values); a filter, slice or
fault-mode change has each worker recompute its parts' faces.

**Why the picture equals one process's.** One process draws the faces in drawing order
(k-slab, face code, k, j, i), plain faces before highlighted ones (and by 2^29-cell bucket,
:func:`~geoshade.render.visuals.grid.prepare.draw_ranges`). A part's faces keep that relative
order, and since parts are whole k-slabs in k order, the faces of one draw group are ordered
part by part. Each part is drawn in *pieces*, one per (bucket, highlight) group, with rank
``piece * n_parts + part``: the composite's tie rule (equal depth: lower rank wins) is then
exactly ``GL_LESS`` after one process's drawing order, coplanar fault faces included. A grid
with fewer k-slabs than workers (small grids: one slab is up to 4 M cells) is drawn in as many
parts as it has slabs.
"""

from __future__ import annotations

import itertools
import math
import time
import uuid
from dataclasses import dataclass
from typing import Any

import numpy as np

from geoshade.compute.grid.chunks import face_corner_depths, shown_mask_lazy, visible_faces_chunked
from geoshade.compute.grid.faces import drawing_slab
from geoshade.grid.backends import (
    UNIFORM_INDEX,
    Applied,
    PreparedFaces,
    applied,
    edge_style,
    face_depth_code,
)
from geoshade.grid.cells import colour_indices, dynamic_names, fault_faces, property_values
from geoshade.grid.geometry import model_matrix
from geoshade.grid.lazy import values_at
from geoshade.io.stores.grid_store import open_grid_store
from geoshade.render.backend import HoldsRenderer
from geoshade.render.distributed.client import (
    DistributedRenderer,
    WorkerLostWarning,
    cleared_color,
    write_target,
)
from geoshade.render.distributed.producer import box_corners
from geoshade.render.visuals.grid.layout import A3F_BUCKET_BITS, gpu_plan
from geoshade.scheduler import THREADS

#: parts per worker the default plan aims at
PARTS_PER_WORKER = 2


# --------------------------------------------------------------------------------------------
# the parts
# --------------------------------------------------------------------------------------------
def plan_parts(dims, n_parts: int, chunk_k: int | None = None) -> list[tuple[int, int]]:
    """Layer ranges ``(k0, k1)`` cutting a grid of ``dims`` into at most ``n_parts`` parts of
    whole k-slabs of the drawing order (and whole chunk layers ``chunk_k`` where that still
    gives ``n_parts``), as equal as the units allow.

    >>> plan_parts((2000, 2000, 250), 4, chunk_k=50)
    [(0, 50), (50, 100), (100, 200), (200, 250)]
    >>> plan_parts((1000, 1000, 100), 3)
    [(0, 32), (32, 68), (68, 100)]
    >>> plan_parts((10, 10, 6), 4)   # one k-slab: one part
    [(0, 6)]
    """

    nz = int(dims[2])
    unit = drawing_slab(dims)
    if chunk_k:
        both = unit * int(chunk_k) // math.gcd(unit, int(chunk_k))
        if math.ceil(nz / both) >= n_parts:
            unit = both
    units = math.ceil(nz / unit)
    n = max(1, min(int(n_parts), units))
    cuts = [min(nz, round(i * units / n) * unit) for i in range(n + 1)]
    cuts[-1] = nz
    return [(a, b) for a, b in itertools.pairwise(cuts) if b > a]


@dataclass
class GridPartsSpec:
    """How a worker builds and colours its parts of a grid (picklable; sent with each change).

    store:   the grid store's path, opened on the worker; or None with
    grid:    the grid itself (an in-memory grid travels whole, with the first load only: for
             small grids and tests)
    parts:   every part's layer range ``(k0, k1)``
    geometry: ``(filter, slice, step, faults, zcorn_bits)``: what the parts' faces and their
             GPU records depend on (``step`` only when the filter names a report-step
             property)
    colour:  ``(property, step, state)`` of the client's
             :class:`~geoshade.grid.colours.ColourPlan` (state None: one uniform colour)
    origin, zquant, zcorn_bits, orientation: the client's GridVisual set-up (the same GPU
             coordinates, 16-bit depth code and back-face sign on every worker; orientation
             None: an in-memory grid's, which each worker's visual finds from the grid)
    palette, edges, cull, shading: drawing state
    """

    store: str | None
    grid: Any
    parts: list
    geometry: tuple
    colour: tuple
    origin: np.ndarray
    zquant: tuple | None
    zcorn_bits: int
    orientation: float | None
    palette: np.ndarray
    edges: Any
    cull: bool
    shading: dict

    def make(self, ctx) -> GridPartsProducer:
        return GridPartsProducer(ctx, self)


@dataclass
class _Part:
    visual: Any
    geometry: tuple
    colour: Any
    box: np.ndarray            # (2, 3) local GPU coordinates of the part's faces
    info: dict
    palette: bytes = b""       # the palette the visual holds


def _pillars_box(coord, z0: float, z1: float) -> tuple[np.ndarray, np.ndarray]:
    """(lo, hi) of x, y over every pillar at depths ``z0`` and ``z1`` (straight pillars: the
    points between lie between) and at the pillars' ends."""
    c = np.asarray(coord, np.float64).reshape(-1, 6)
    dz = c[:, 5] - c[:, 2]
    flat = np.abs(dz) < 1e-12
    pts = [c[:, 0:2], c[:, 3:5]]
    for z in (z0, z1):
        t = np.where(flat, 0.0, (z - c[:, 2]) / np.where(flat, 1.0, dz))
        pts.append(c[:, 0:2] + t[:, None] * (c[:, 3:5] - c[:, 0:2]))
    allp = np.concatenate(pts)
    return allp.min(axis=0), allp.max(axis=0)


class GridPartsProducer:
    """The parts of a grid one worker holds: their faces, corners and colours in one
    :class:`~geoshade.render.visuals.grid.visual.GridVisual` each (a tile producer of
    :mod:`geoshade.render.distributed.producer`)."""

    def __init__(self, ctx, spec: GridPartsSpec):
        self.ctx, self.spec = ctx, spec
        if spec.store is not None:
            self.grid = open_grid_store(spec.store)
        elif spec.grid is not None:
            self.grid = spec.grid
        else:
            raise ValueError("grid parts: the spec carries neither a store nor the grid")
        self.parts: dict[int, _Part] = {}

    # --- building ------------------------------------------------------------------------------
    def _faces(self, p: int, spec: GridPartsSpec):

        flt, slc, step, faults, _ = spec.geometry
        g = self.grid
        mask = shown_mask_lazy(g, flt, slc, step=step)
        # in the drawing order (k-slab, face code, k, j, i) already
        fs = visible_faces_chunked(g, shown=mask, scheduler=THREADS, kspan=spec.parts[p])
        cells, face, hl = fault_faces(fs, faults)
        corners = face_corner_depths(g.zcorn, cells, face)
        return fs, cells, face, hl, corners

    def _build(self, p: int, spec: GridPartsSpec) -> _Part:
        from geoshade.render.visuals.grid.visual import GridVisual

        t0 = time.perf_counter()
        fs, cells, face, hl, corners = self._faces(p, spec)
        faces_ms = (time.perf_counter() - t0) * 1000
        quantised = None if spec.zquant is None else (None, *spec.zquant, None)
        vis = GridVisual(self.ctx, self.grid, spec.origin, approach=3,
                         zcorn_bits=spec.zcorn_bits, zcorn_store="faces", quantised=quantised,
                         palette=spec.palette, orientation=spec.orientation)
        vis.set_faces(cells, face, hl, corners=corners)
        if corners.size:
            z0, z1 = float(np.nanmin(corners)), float(np.nanmax(corners))
            lo, hi = _pillars_box(self.grid.coord, z0, z1)
            box = np.array([[lo[0], lo[1], z0], [hi[0], hi[1], z1]]) - spec.origin
        else:
            box = np.zeros((0, 3))
        info = {"count": int(fs.shown), "faces": int(vis.n_faces), "faceset": len(fs),
                "faces_ms": round(faces_ms, 3), "zcorn_max_error": float(vis.zcorn_max_error)}
        return _Part(vis, spec.geometry, None, box, info,
                     np.asarray(spec.palette, np.uint8).tobytes())

    def _colour(self, part: _Part, spec: GridPartsSpec) -> None:
        t0 = time.perf_counter()
        vis = part.visual
        need = vis.color_cells()
        name, step, state, diff = spec.colour
        if state is None or need is None or not need.size:
            ci = np.full(0 if need is None else need.size, UNIFORM_INDEX, np.uint8)
        else:
            v = values_at(property_values(self.grid, name, step, diff), need, self.grid.dims)
            style, lo, hi, gaps = state
            ci = colour_indices(style, lo, hi, gaps, v)
        if need is not None:
            vis.set_colors(ci, cells=need)
        part.colour = spec.colour
        part.info["colors_ms"] = round((time.perf_counter() - t0) * 1000, 3)

    def add(self, parts, spec: GridPartsSpec | None = None) -> dict:
        spec = spec or self.spec
        self.spec = spec
        out = {}
        for p in (int(v) for v in parts):
            part = self.parts.get(p)
            if part is None or part.geometry != spec.geometry:
                if part is not None:
                    part.visual.release()
                part = self.parts[p] = self._build(p, spec)
            if part.colour != spec.colour:   # None before the first colouring
                self._colour(part, spec)
            palette = np.asarray(spec.palette, np.uint8).tobytes()
            if part.palette != palette:
                part.visual.set_palette(spec.palette)
                part.palette = palette
            out[p] = {**part.info, "gpu_bytes": int(part.visual.gpu_bytes),
                      "pieces": self.pieces(p)}
        self.ctx.finish()
        return out

    def remove(self, parts) -> None:
        for p in parts:
            part = self.parts.pop(int(p), None)
            if part is not None:
                part.visual.release()

    def held(self) -> list[int]:
        return sorted(self.parts)

    # --- drawing -------------------------------------------------------------------------------
    def pieces(self, part: int) -> list[int]:
        """The (bucket, highlight) groups of the part's faces, as ``2 * bucket + highlight``."""
        return sorted({2 * int(g) + int(h) for _, _, g, h in self.parts[part].visual.ranges})

    def corners(self, part: int, model) -> np.ndarray | None:
        box = self.parts[part].box
        return box_corners(box[0], box[1], model) if len(box) else None

    def draw(self, part: int, camera, model, count: bool = False, size=None,
             piece: int = 0) -> dict:
        """As the single-process GridView draws its faces: only the piece's draw ranges."""
        s = self.spec
        vis = self.parts[part].visual
        return vis.draw(camera, model, s.shading, size, s.edges, cull=s.cull and not count,
                        count=count, piece=piece) or {}

    @property
    def gpu_bytes(self) -> int:
        return int(sum(p.visual.gpu_bytes for p in self.parts.values()))

    def release(self) -> None:
        self.remove(list(self.parts))


# --------------------------------------------------------------------------------------------
# the drawing
# --------------------------------------------------------------------------------------------
class ClusterFaces(HoldsRenderer):
    """The faces of a :class:`~geoshade.grid.GridView` with ``distributed=True``, computed and
    drawn on the workers of the View's cluster (see the module's description); a
    :class:`~geoshade.grid.backends.FacesDrawing` of any source.

    ``work`` is the View's scheduler session (its cluster), ``shading`` the lighting the
    workers draw with (a frame's replaces it for the next load), ``source`` the grid's source: a
    grid store is opened by each worker, which reads only its parts' chunks; an in-memory grid
    is sent whole to every worker.

    Examples
    --------
    >>> grid = geoshade.load("case.zarr")                                # doctest: +SKIP
    >>> with GridView(grid, distributed=True, scheduler="local:2", property="PORO") as view:
    ...     img, stats = view.draw()                                     # doctest: +SKIP
    >>> view.drawing.name, stats["distributed"]["bricks_per_worker"]     # doctest: +SKIP
    """

    name = "cluster"
    visual = None   # the workers hold the visuals

    def __init__(self, work, source, origin: np.ndarray, shading: dict):
        self.work, self.source, self.origin, self.shading = work, source, origin, shading
        self.renderer: Any = None
        self.frame_stats: dict = {}
        self.key = f"grid-{uuid.uuid4().hex[:12]}"
        self.parts: list[tuple[int, int]] = []
        self.parts_note: str | None = None
        self._parts_warned = False
        self._grid_sent = False
        self._zquant: tuple | None = None
        self._orient: float | None = None
        self._colour: tuple = (None, None, None, None)
        self.palette: Any = None
        self.edge_style: Any = None
        self.counts: dict = {}

    @property
    def grid(self):
        return self.source.grid

    # --- building --------------------------------------------------------------------------------
    def open(self, options, plan, prepared=None) -> Applied:   # the workers make their faces
        o, g = options, self.grid
        # the View's cluster (one for its life: the View's release() closes what it started)
        self.renderer = DistributedRenderer(self.work, timeout=o.worker_timeout)
        t0 = time.perf_counter()
        self._depth_code(o)
        # None in memory: each worker's visual finds it from the whole grid
        self._orient = self.source.orientation()
        n_workers = max(1, len(self.renderer.workers))
        chunks = g.meta.get("chunks") if isinstance(g.meta, dict) else None
        asked = o.parts or PARTS_PER_WORKER * n_workers
        self.parts = plan_parts(g.dims, asked, chunks[2] if chunks else None)
        if len(self.parts) < asked:
            nx, ny, nz = g.dims
            self.parts_note = (
                f"{g.name or 'grid'}: drawn in {len(self.parts)} part(s), not {asked}: a part "
                f"is whole k-slabs of the faces' drawing order ({drawing_slab(g.dims)} layers "
                f"of {nx}×{ny} cells; the grid has {nz}), so that the picture is exactly one "
                "process's")
        ms = (time.perf_counter() - t0) * 1000
        self.edge_style = edge_style(o.edges)
        self.colours(o, plan)   # the colour state, pushed with the first load
        return Applied(shown=self._shown(), geometry_ms=ms)

    def _depth_code(self, o) -> None:
        """The 16-bit depth code the workers' visuals use (part of the parts' geometry)."""
        self._zquant = face_depth_code(self.grid) if o.zcorn_bits == 16 else None

    def remake(self, options, plan) -> Applied:
        """A new depth precision (approach and storage stay: the options refuse others): the
        workers rebuild their parts with it."""
        self._depth_code(options)
        self.colours(options, plan)
        return Applied(shown=self._shown())

    # --- the scene on the workers ----------------------------------------------------------------
    def _geometry(self, o) -> tuple:
        cells = o.cells_filter()   # the filter and the ranges
        uses_step = cells is not None and cells.uses(dynamic_names(self.grid))
        return (None if cells is None else str(cells), o.slice,
                o.step if uses_step else None, o.faults, o.zcorn_bits)

    def _spec(self, o, parts: list[int]) -> GridPartsSpec:
        g = self.grid
        store = g.meta.get("store") if self.source.out_of_core else None
        # an in-memory grid travels with the first load only (the workers keep it)
        return GridPartsSpec(
            store=store, grid=None if store or self._grid_sent else g, parts=list(self.parts),
            geometry=self._geometry(o), colour=self._colour, origin=np.asarray(self.origin),
            zquant=self._zquant, zcorn_bits=o.zcorn_bits, orientation=self._orient,
            palette=np.asarray(self.palette, np.uint8), edges=self.edge_style, cull=o.cull,
            shading=dict(self.shading))

    def _push(self, o) -> float:
        """Send the state of options ``o`` to the workers (they redo only what changed); the
        milliseconds taken."""
        g = self.grid
        t0 = time.perf_counter()
        n = len(self.parts)
        sizes = np.array([(k1 - k0) for k0, k1 in self.parts], float)
        nx, ny, _nz = g.dims
        buckets = max(1, math.ceil(g.ncells / (1 << A3F_BUCKET_BITS)))
        centres = np.array([[nx / 2, ny / 2, (k0 + k1) / 2] for k0, k1 in self.parts])
        cells = np.c_[np.zeros((n, 2), np.int64), np.arange(n)]
        self.counts = self.renderer.load(
            self.key, lambda parts: self._spec(o, parts), sizes * nx * ny, cells, centres,
            model_matrix(g, self.origin, o.exaggeration), order="index", pieces=2 * buckets)
        self._grid_sent = True
        return (time.perf_counter() - t0) * 1000

    def _shown(self) -> int:
        return int(sum(c.get("count", 0) for c in self.counts.values()))

    # --- faces and colours -----------------------------------------------------------------------
    def prepare(self, options) -> PreparedFaces:
        """The workers compute the new faces of their parts (no GL here: any thread)."""
        ms = self._push(options)
        return PreparedFaces(applied(options), None, None, np.zeros((0, 3), np.int32),
                             np.zeros(0, np.int8), None, ms, shown=self._shown())

    def apply(self, prepared: PreparedFaces, plan) -> Applied:
        return Applied(prepared.changes, None, None, prepared.shown, prepared.ms)

    def colours(self, options, plan) -> None:
        self.palette = plan.palette
        self._colour = (plan.property, plan.step, plan.state, plan.diff)
        self._push(options)

    def drawing_changed(self, options) -> None:
        self.edge_style = edge_style(options.edges)
        self._push(options)

    # --- drawing ---------------------------------------------------------------------------------
    def draw(self, camera, target, count: bool, options, shading: dict) -> dict:
        self.shading = shading   # sent with the next load
        color, depth, st = self.renderer.frame(
            camera, target.size, count=count, background=cleared_color(target),
            model=model_matrix(self.grid, self.origin, options.exaggeration))
        t0 = time.perf_counter()
        write_target(target, color, depth)   # colour and depth: wells are drawn over it
        st["write_ms"] = round((time.perf_counter() - t0) * 1000, 3)
        st["parts"] = [list(p) for p in self.parts]
        counts = dict(st.pop("counts", {})) if count else {}
        self.frame_stats = st
        target.fbo.use()
        return counts

    def method(self) -> str:
        return "approach 3 (faces), distributed"

    def stats(self, options) -> dict:
        o, r, info = options, self.renderer, self.counts
        n_faces = int(sum(c.get("faces", 0) for c in info.values()))
        return {
            "shown_cells": self._shown(),
            "faceset_faces": int(sum(c.get("faceset", 0) for c in info.values())),
            "faces": n_faces, "approach": 3, "zcorn_store": "faces",
            "zcorn_bits": o.zcorn_bits,
            "zcorn_max_error": float(max((c.get("zcorn_max_error", 0.0)
                                          for c in info.values()), default=0.0)),
            "gpu_plan_bytes": int(sum(gpu_plan(3, self.grid.dims, n_faces, 0,
                                               o.zcorn_bits, "faces").values())),
            "gpu_breakdown": {f"worker {w}": int(b) for w, b in r.gpu_bytes_by_worker.items()},
            "edges": self.edge_style.mode,
            "distributed": {**self.frame_stats, "load_ms": round(r.load_ms, 3),
                            "worker_gpu_bytes": dict(r.gpu_bytes_by_worker),
                            "worker_renderers": dict(r.renderers)},
            "notes": [self.parts_note] if self.parts_note else []}

    def notes(self, options) -> list[tuple[str, type[Warning]]]:
        out: list[tuple[str, type[Warning]]] = [
            (m, WorkerLostWarning) for m in self.renderer.take_events()]
        if self.parts_note and not self._parts_warned:   # once per View
            self._parts_warned = True
            out.append((self.parts_note, UserWarning))
        return out


__all__ = ["PARTS_PER_WORKER", "ClusterFaces", "GridPartsProducer", "GridPartsSpec",
           "plan_parts"]
