"""The cluster bricks backend of the core View (:class:`ClusterBricks`: ``CoreView(volume,
distributed=True, scheduler=...)``) and its worker side (:class:`CoreBricksSpec`,
:class:`CoreBricksProducer`): a core box drawn in bricks on the workers of a dask cluster.

The box is planned into bricks (:func:`geoshade.compute.voxels.bricks.plan_bricks`), the bricks are
assigned to the workers (balanced by voxels, the same bricks on the same workers every frame),
each worker builds its bricks' selection maps from the store itself and keeps them resident in
its own headless context; a frame sends each worker the camera, gets back colour, depth and
rank of its screen footprint and composites them by depth
(:mod:`geoshade.render.distributed`). The picture equals the single-process picture pixel for
pixel (opaque voxels; the tie rule of :mod:`geoshade.compute.composite` reproduces the single
process's drawing order). Occlusion and annotations are applied by this View over the
composite, as in one process.

Every frame's stats carry ``distributed``: bytes moved, the slowest worker and its time, the
compositing time, bricks per worker, workers lost. A worker lost during a frame is reported
(:class:`~geoshade.render.distributed.WorkerLostWarning` naming it) and its bricks are redone
on the others in the same frame.
"""

from __future__ import annotations

import dataclasses
import hashlib
import time
import uuid
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from geoshade.compute.voxels.bricks import (
    ALIGN,
    DEFAULT_TEX_LIMIT,
    BrickedMaps,
    plan_bricks,
    selection_maps_for,
)
from geoshade.core.backends import Look, Selection, model_matrix
from geoshade.core.sources import VolumeSource, roi_fill
from geoshade.models.volume import Box
from geoshade.render.backend import HoldsRenderer
from geoshade.render.distributed.client import (
    DistributedRenderer,
    WorkerLostWarning,
    cleared_color,
    write_target,
)
from geoshade.render.distributed.producer import box_corners
from geoshade.scheduler import SYNCHRONOUS

#: bricks per worker the automatic brick side aims at (balance against per-brick overhead)
BRICKS_PER_WORKER = 4
#: the smallest automatic brick side (one 32-bit word of the bit map along x)
MIN_SIDE = ALIGN[0]


def distributed_brick_side(box: Box, n_workers: int, requested=None,
                           tex_limit: int = DEFAULT_TEX_LIMIT) -> int:
    """The brick side: ``requested`` if given, else the largest power of two from
    :data:`MIN_SIDE` (32) to ``tex_limit`` that gives every worker at least
    :data:`BRICKS_PER_WORKER` bricks (the smallest if none does).

    >>> distributed_brick_side(Box((0, 0, 0), (128, 128, 128)), 2)
    64
    >>> distributed_brick_side(Box((0, 0, 0), (64, 64, 64)), 2)
    32
    >>> distributed_brick_side(Box((0, 0, 0), (2600, 2600, 7360)), 8)
    1024
    """
    if requested not in (None, True):
        return int(requested)
    side = int(tex_limit)
    while side > MIN_SIDE and len(plan_bricks(box, side)) < BRICKS_PER_WORKER * n_workers:
        side //= 2
    return max(side, MIN_SIDE)


def _translate(offset) -> np.ndarray:
    m = np.eye(4)
    m[:3, 3] = offset
    return m


@dataclass
class CoreBricksSpec:
    """How a worker builds the bricks of a core box (picklable; sent once per selection).

    box:      the whole box (the model matrix maps its index space to the world)
    bricks:   every brick of the plan (a worker draws those it is given by index)
    select, color_range: the selection and the values spread over the palette
    palette:  (256, 4) uint8, the client's (so every worker colours alike)
    method, cull, trefoil_mode: the client's resolved drawing method and its options
    shading:  the lighting uniforms (the model matrix comes with each frame: exaggeration)
    data:     a lazy (dask) volume array, sliced per brick on the worker; or None with
    arrays:   brick index -> the brick's values (nz, ny, nx) for in-memory volumes
    """

    box: Box
    bricks: list[Box]
    select: tuple[float, float]
    color_range: tuple[float, float]
    palette: np.ndarray
    method: str
    shading: dict
    cull: bool = True
    trefoil_mode: str = "eye"
    data: Any = None
    arrays: dict = field(default_factory=dict)

    def make(self, ctx) -> CoreBricksProducer:
        return CoreBricksProducer(ctx, self)


class CoreBricksProducer:
    """The bricks of a core box one worker holds, each with its own maps and visual."""

    def __init__(self, ctx, spec: CoreBricksSpec):
        self.ctx, self.spec = ctx, spec
        self.visuals: dict[int, Any] = {}
        self.counts: dict[int, int] = {}

    def _maps(self, i: int, spec: CoreBricksSpec):
        b = self.spec.bricks[i]
        lo, hi = self.spec.select
        clo, chi = self.spec.color_range
        if i in spec.arrays:
            return selection_maps_for(spec.arrays[i], Box((0, 0, 0), b.size), lo, hi, clo, chi)
        if spec.data is None:
            raise ValueError(f"brick {i}: the spec carries neither its values nor the volume")
        # one thread per worker: the slabs of this brick are read here, one after another
        return selection_maps_for(spec.data, b, lo, hi, clo, chi, scheduler=SYNCHRONOUS)

    def _visual(self, maps):
        s = self.spec
        if s.method == "raycast":
            from geoshade.render.visuals.raycast.visual import RaycastVisual

            return RaycastVisual(self.ctx, maps, s.palette)
        from geoshade.render.visuals.voxels.visual import VoxelVisual

        return VoxelVisual(self.ctx, maps, s.palette, method=s.method, cull=s.cull,
                           trefoil_mode=s.trefoil_mode)

    def add(self, parts, spec: CoreBricksSpec | None = None) -> dict:
        spec = spec or self.spec
        out = {}
        for i in parts:
            i = int(i)
            if i not in self.visuals:
                maps = self._maps(i, spec)
                self.visuals[i] = self._visual(maps)
                self.counts[i] = int(maps.count)
                del maps
            out[i] = {"count": self.counts[i], "gpu_bytes": int(self.visuals[i].gpu_bytes)}
        self.ctx.finish()
        return out

    def remove(self, parts) -> None:
        for i in parts:
            vis = self.visuals.pop(int(i), None)
            self.counts.pop(int(i), None)
            if vis is not None:
                vis.release()

    def held(self) -> list[int]:
        return sorted(self.visuals)

    def corners(self, part: int, model) -> np.ndarray:
        b = self.spec.bricks[part]
        rel = np.subtract(b.offset, self.spec.box.offset)
        return box_corners(rel, rel + np.asarray(b.size), model)

    def draw(self, part: int, camera, model, count: bool = False, size=None,
             piece: int = 0) -> dict:
        """As :meth:`geoshade.render.visuals.bricked.BrickedVisual.draw` draws one brick."""
        from geoshade.render.visuals.raycast.visual import RaycastVisual

        s = self.spec
        vis = self.visuals[part]
        rel = tuple(int(v) for v in np.subtract(s.bricks[part].offset, s.box.offset))
        model = np.asarray(model, float)
        if isinstance(vis, RaycastVisual):
            return vis.draw(camera, model, s.shading, count=count, brick_offset=rel) or {}
        return vis.draw(camera, model @ _translate(rel), s.shading, count=count) or {}

    @property
    def gpu_bytes(self) -> int:
        return int(sum(v.gpu_bytes for v in self.visuals.values()))

    def release(self) -> None:
        self.remove(list(self.visuals))


# --------------------------------------------------------------------------------------------
# the backend
# --------------------------------------------------------------------------------------------
class ClusterBricks(HoldsRenderer):
    """The box's bricks of a :class:`~geoshade.core.CoreView` with ``distributed=True``, built
    and drawn on the workers of the View's cluster, composited by depth (see the module's
    description); a :class:`~geoshade.core.backends.BricksDrawing` of either source (``work``:
    the View's scheduler session, its cluster; ``shading``: the lighting the workers draw
    with, a frame's replacing it for the next scene).

    Examples
    --------
    >>> import geoshade
    >>> vol = geoshade.synthetic_core(64)
    >>> with geoshade.view(vol, distributed=True, scheduler="local:2", select=(0, 9000),
    ...                    size=(128, 128)) as view:                    # doctest: +SKIP
    ...     img, stats = view.draw()
    >>> view.drawing.name, stats["distributed"]["bricks_per_worker"]     # doctest: +SKIP
    ('cluster', {'tcp://127.0.0.1:40001': 4, 'tcp://127.0.0.1:40003': 4})
    """

    name = "cluster"
    visual = None   # the workers hold the visuals

    def __init__(self, work, source: VolumeSource, shading: dict):
        self.work, self.source, self.shading = work, source, shading
        self.renderer: Any = None
        self.token = uuid.uuid4().hex[:12]
        self.key: str | None = None
        self.bricks: list[Box] = []
        self.side = 0
        self.load_ms = 0.0
        self.frame_stats: dict = {}
        self.selection: Selection | None = None

    def _renderer(self, options):
        """The renderer on the View's cluster (made on first use; the View closes the
        cluster)."""
        if self.renderer is None:
            self.renderer = DistributedRenderer(self.work, timeout=options.worker_timeout)
        return self.renderer

    def prepare(self, options, progress=None):
        return None   # the workers build their bricks' maps

    def _scene_key(self, o, look: Look, side: int) -> str:
        box = o.box
        roi = None if o.roi is None else (id(o.roi), roi_fill(self.source.volume, o))
        h = hashlib.sha1(repr((box.offset, box.size, o.select, tuple(o.color_range()), side,
                               look.method, o.cull, o.trefoil_mode, roi)).encode())
        h.update(np.ascontiguousarray(look.palette).tobytes())
        return f"{self.token}-{h.hexdigest()[:16]}"

    def apply(self, options, prepared, look: Look) -> Selection | None:
        o, src = options, self.source
        r = self._renderer(o)
        box, (lo, hi), crange = o.box, o.select, tuple(o.color_range())
        side = distributed_brick_side(box, max(1, len(r.workers)), o.bricks)
        bricks = plan_bricks(box, side)
        key = self._scene_key(o, look, side)
        if key == self.key and r.scene is not None:
            return self.selection
        data = src.data(o)   # the volume's values, or masked by the ROI
        lazy = src.workers_read
        base = CoreBricksSpec(box=box, bricks=bricks, select=(float(lo), float(hi)),
                              color_range=(float(crange[0]), float(crange[1])),
                              palette=np.asarray(look.palette, np.uint8), method=look.method,
                              shading=dict(self.shading), cull=o.cull,
                              trefoil_mode=o.trefoil_mode, data=data if lazy else None)

        def make_spec(parts: list[int]) -> CoreBricksSpec:
            if lazy:
                return base
            # an in-memory volume: each worker gets its bricks' values once
            return dataclasses.replace(base, arrays={
                int(i): src.brick_values(data, bricks[int(i)]) for i in parts})

        rel = np.array([np.subtract(b.offset, box.offset) for b in bricks], float)
        sizes = np.array([b.size for b in bricks], float)
        cells = np.floor(rel / float(side)).astype(np.int64)
        t0 = time.perf_counter()
        info = r.load(key, make_spec, [b.nvoxels for b in bricks], cells, rel + sizes / 2,
                      model_matrix(src.volume, box, o.exaggeration))   # the old scene goes
        self.load_ms = (time.perf_counter() - t0) * 1000
        counts = [int(info[i]["count"]) for i in range(len(bricks))]
        self.key, self.bricks, self.side = key, bricks, side
        self.selection = Selection(BrickedMaps(count=sum(counts), shape_xyz=box.size, box=box,
                                               bricks=list(bricks), counts=counts),
                                   self.load_ms, 0.0)
        return self.selection

    def colours(self, options, look: Look) -> Selection | None:
        return self.apply(options, None, look)   # the workers hold the palette: a new scene

    def remake(self, options, look: Look) -> Selection | None:
        return self.apply(options, None, look)   # the method is part of the scene

    def draw(self, camera, target, count: bool, options, shading: dict) -> dict:
        self.shading = shading   # sent with the next scene
        color, depth, st = self.renderer.frame(
            camera, target.size, count=count, background=cleared_color(target),
            model=model_matrix(self.source.volume, options.box, options.exaggeration))
        t0 = time.perf_counter()
        write_target(target, color, depth)   # occlusion passes read it
        st["write_ms"] = round((time.perf_counter() - t0) * 1000, 3)
        counts = dict(st.pop("counts", {})) if count else {}
        self.frame_stats = st
        return counts

    def stats(self) -> dict:
        r = self.renderer
        return {"bricks": len(self.bricks), "brick_side": self.side,
                "brick_mode": "distributed",
                "worker_gpu_bytes": dict(r.gpu_bytes_by_worker),
                "workers": [w for w in r.workers if w in r.actors],
                "worker_renderers": dict(r.renderers),
                "distributed": {**self.frame_stats, "load_ms": round(self.load_ms, 3)}}

    def notes(self) -> list[tuple[str, type[Warning]]]:
        if self.renderer is None:
            return []
        return [(m, WorkerLostWarning) for m in self.renderer.take_events()]

    def release(self) -> None:
        """Free the workers' GPU objects and actors (the View closes its cluster)."""
        super().release()
        self.key = None


__all__ = ["BRICKS_PER_WORKER", "MIN_SIDE", "ClusterBricks", "CoreBricksProducer",
           "CoreBricksSpec", "distributed_brick_side"]
