"""``DistributedCoreView``: a core box drawn in bricks on the workers of a dask cluster.

The box is planned into bricks (:func:`geoshade.compute.bricks.plan_bricks`), the bricks are
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

import numpy as np

from geoshade.compute.bricks import ALIGN, DEFAULT_TEX_LIMIT, BrickedMaps, is_dask, plan_bricks
from geoshade.core.options import DistributedCoreOptions
from geoshade.core.view import CoreView, Prepared, model_matrix, selection_source
from geoshade.models.volume import Box
from geoshade.render.distributed.view import ClusterDrawing

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


def _values(data, brick: Box) -> np.ndarray:
    """The values of ``brick`` of an in-memory volume (a masked one is a dask array over
    it: computed here, brick by brick)."""
    sub = data[brick.slices()]
    return np.asarray(sub.compute(scheduler="synchronous") if is_dask(sub) else sub)


class _Bricks:
    """The View's handle on the current scene on the workers (what ``self.visual`` is)."""

    def __init__(self, renderer, key: str, bricks: list[Box], side: int, counts: list[int],
                 load_ms: float):
        self.renderer, self.key, self.bricks, self.side = renderer, key, bricks, side
        self.counts, self.load_ms = counts, load_ms
        self.released = False

    @property
    def gpu_bytes(self) -> int:
        return 0 if self.released else self.renderer.gpu_bytes

    @property
    def extra_stats(self) -> dict:
        r = self.renderer
        return {"bricks": len(self.bricks), "brick_side": self.side,
                "brick_mode": "distributed",
                "worker_gpu_bytes": dict(r.gpu_bytes_by_worker),
                "workers": [w for w in r.workers if w in r.actors],
                "worker_renderers": dict(r.renderers)}

    def release(self) -> None:
        if not self.released:
            self.renderer.release_scene(self.key)
        self.released = True


class DistributedCoreView(ClusterDrawing, CoreView):
    """A :class:`~geoshade.core.CoreView` drawn on a ``dask.distributed`` cluster.

    Options: those of :class:`~geoshade.core.options.DistributedCoreOptions`: every core
    option, ``scheduler`` (required: ``tcp://HOST:8786``, ``local:N`` or a Client),
    ``bricks`` (the brick side; default: at least four bricks per worker) and
    ``worker_timeout``.

    Examples
    --------
    >>> import geoshade
    >>> from distributed import Client                                   # doctest: +SKIP
    >>> client = Client(n_workers=2, threads_per_worker=1)              # doctest: +SKIP
    >>> vol = geoshade.synthetic_core(64)
    >>> with DistributedCoreView(vol, scheduler=client, select=(0, 9000),
    ...                          size=(128, 128)) as view:              # doctest: +SKIP
    ...     img, stats = view.draw()
    >>> stats["distributed"]["bricks_per_worker"]                        # doctest: +SKIP
    {'tcp://127.0.0.1:40001': 4, 'tcp://127.0.0.1:40003': 4}
    """

    Options = DistributedCoreOptions
    options: DistributedCoreOptions
    part_word = "bricks"

    @classmethod
    def prepare_open(cls, model, progress=None, **options):
        """Nothing to build on the client: the workers build their bricks' maps."""
        model = cls.coerce(model, options, progress)
        DistributedCoreOptions.parse(model, **options)
        return model, {}

    def _setup(self) -> None:
        from geoshade.render.distributed.client import DistributedRenderer

        self._token = uuid.uuid4().hex[:12]
        self._frame_stats: dict = {}
        # the View's cluster (porosity and other dask work of this View run on it too)
        self._renderer = DistributedRenderer(self.work, timeout=self.options.worker_timeout)
        try:
            super()._setup()
        except BaseException:
            self._renderer.close()
            raise

    # --- the scene on the workers --------------------------------------------------------------
    def _bricking(self, box: Box):
        n = max(1, len(self._renderer.workers))
        return distributed_brick_side(box, n, self.options.bricks), None

    def _is_bricked(self) -> bool:
        return True   # a palette change rebuilds the scene (the workers hold the palette)

    def _scene_key(self, box: Box, side: int) -> str:
        o = self.options
        roi = None if o.roi is None else (id(o.roi), self._fill(o))
        h = hashlib.sha1(repr((box.offset, box.size, o.select, tuple(o.color_range()), side,
                               self.method, o.cull, o.trefoil_mode, roi)).encode())
        h.update(np.ascontiguousarray(self.palette).tobytes())
        return f"{self._token}-{h.hexdigest()[:16]}"

    def _rebuild(self, prepared: Prepared | None = None) -> None:
        from geoshade.render.distributed.producer import CoreBricksSpec

        o = self.options
        box, (lo, hi), crange = o.box, o.select, tuple(o.color_range())
        side = self._bricking(box)[0]
        bricks = plan_bricks(box, side)
        key = self._scene_key(box, side)
        if isinstance(self.visual, _Bricks) and self.visual.key == key and \
                not self.visual.released:
            return
        data = selection_source(self.volume, o)   # the volume's values, or masked by the ROI
        lazy = is_dask(self.volume.data)
        base = CoreBricksSpec(box=box, bricks=bricks, select=(float(lo), float(hi)),
                              color_range=(float(crange[0]), float(crange[1])),
                              palette=np.asarray(self.palette, np.uint8), method=self.method,
                              shading=dict(self.shading), cull=o.cull,
                              trefoil_mode=o.trefoil_mode, data=data if lazy else None)

        def make_spec(parts: list[int]) -> CoreBricksSpec:
            if lazy:
                return base
            # an in-memory volume: each worker gets its bricks' values once
            return dataclasses.replace(base, arrays={int(i): _values(data, bricks[int(i)])
                                                     for i in parts})

        rel = np.array([np.subtract(b.offset, box.offset) for b in bricks], float)
        sizes = np.array([b.size for b in bricks], float)
        cells = np.floor(rel / float(side)).astype(np.int64)
        t0 = time.perf_counter()
        info = self._renderer.load(key, make_spec, [b.nvoxels for b in bricks], cells,
                                   rel + sizes / 2, model_matrix(self.volume, box,
                                                                 o.exaggeration))
        load_ms = (time.perf_counter() - t0) * 1000
        counts = [int(info[i]["count"]) for i in range(len(bricks))]
        if self.visual is not None:
            self.visual.released = True   # the renderer released the old scene on load()
        self.visual = _Bricks(self._renderer, key, bricks, side, counts, load_ms)
        self.maps = BrickedMaps(count=sum(counts), shape_xyz=box.size, box=box,
                                bricks=list(bricks), counts=counts)
        self.prepare_ms, self.upload_ms = load_ms, 0.0

    def _release_visual(self) -> None:
        if self.visual is not None:
            self.visual.release()
            self.visual = None

    # --- drawing -------------------------------------------------------------------------------
    def _frame(self, camera, target, count: bool) -> dict:
        o = self.options
        return self._composite_frame(camera, target, count,
                                     model_matrix(self.volume, o.box, o.exaggeration))

    def method_name(self) -> str:
        return self.method

    def _stats(self, counts: dict) -> dict:
        st = super()._stats(counts)
        st["distributed"] = {**self._frame_stats, "load_ms": round(self.visual.load_ms, 3)}
        return st


__all__ = ["BRICKS_PER_WORKER", "MIN_SIDE", "DistributedCoreView", "distributed_brick_side"]
