"""Draws a big box as bricks, each with its own selection maps and visual.

The bricks are planned by :mod:`geoshade.compute.voxels.bricks`; each brick's maps come from
:func:`geoshade.compute.voxels.bricks.selection_maps_for` (from the lazy volume, bit for bit the
maps
of that brick) and its visual from a factory the View passes in. Every brick is drawn with the
model matrix of the whole box (the ray caster with the brick's offset: the same rays as the
unbricked box, so the picture is exactly the unbricked one); the depth test composes them.
"""

from __future__ import annotations

import time

import numpy as np

from geoshade.compute.voxels.bricks import (
    DEFAULT_TEX_LIMIT,
    HOST_CACHE_BYTES,
    BrickedMaps,
    check_resident,
    largest_box,
    plan_bricks,
    resident,
    selection_maps_for,
)
from geoshade.io.paths import mem_available
from geoshade.models.volume import Box


def tex_limit(ctx) -> int:
    """The context's 3D-texture limit per axis."""
    return int(ctx.info.get("GL_MAX_3D_TEXTURE_SIZE", DEFAULT_TEX_LIMIT) or DEFAULT_TEX_LIMIT)


def gpu_budget(ctx, gpu_memory_limit=None) -> int | None:
    """Bytes the bricks may use on the GPU: the given limit, else what the driver reports free;
    None when unknown (a software renderer's "GPU memory" is host memory: then half of the
    host's available memory)."""
    from geoshade.render.context import gpu_memory_bytes, is_software

    if gpu_memory_limit:
        return int(gpu_memory_limit)
    free = gpu_memory_bytes(ctx)
    if free is not None:
        return int(free)
    if is_software(ctx):
        avail = mem_available()   # the renderer's memory is this machine's
        return None if avail is None else avail // 2
    return None


def _translate(offset) -> np.ndarray:
    m = np.eye(4)
    m[:3, 3] = offset
    return m


class BrickedVisual:
    """A box drawn as bricks.

    Parameters
    ----------
    ctx : moderngl.Context
    volume : VoxelVolume
        Usually lazy (dask); each brick's maps are built from it when needed.
    box : Box
    lo, hi : float
        Selection range; ``color_range`` the colour range (default the selection range).
    make_visual : callable(maps) -> visual
        Builds one brick's visual.
    brick_side : int
    budget : int or None
        GPU bytes the bricks may use; None: unknown (assume resident fits).
    scheduler : optional
        Where the maps are built (see :func:`geoshade.compute.voxels.lazy.selection_maps`).

    Attributes
    ----------
    gpu_bytes : int
        Peak bytes on the GPU at one time (all bricks when resident, the largest when streamed).
    """

    def __init__(self, ctx, volume, box: Box, lo: float, hi: float, color_range,
                 make_visual, brick_side: int, budget: int | None, scheduler=None,
                 progress=None, host_cache_bytes: int = HOST_CACHE_BYTES, method: str = "raycast"):
        self.ctx, self.volume, self.box = ctx, volume, box
        self.make_visual, self.scheduler, self.progress = make_visual, scheduler, progress
        self.method, self.budget, self.brick_side = method, budget, int(brick_side)
        self.host_cache_bytes = int(host_cache_bytes)
        # all resident: their host memory is checked before the first is built (SIGSEGV)
        check_resident(box, self.brick_side, method, budget, mem_available())
        self.bricks = plan_bricks(box, self.brick_side)
        self.resident = resident(box, self.brick_side, method, budget)
        self.visuals: list = []
        self.stream_visual = None
        self.host_maps: dict[int, object] = {}
        self.peak_bytes = 0
        self.rebuilds = 0
        self.set_range(lo, hi, color_range)

    def _maps(self, i: int):
        m = self.host_maps.get(i)
        if m is not None:
            return m
        b = self.bricks[i]
        clo, chi = self.color_range
        m = selection_maps_for(self.volume.data, b, self.lo, self.hi, clo, chi,
                               scheduler=self.scheduler)
        self.rebuilds += 1
        nbytes = m.bits.nbytes + m.color.nbytes + m.bricks.nbytes + m.patch_bits.nbytes
        if self._cached_bytes() + nbytes <= self.host_cache_bytes:
            self.host_maps[i] = m
        return m

    def _cached_bytes(self) -> int:
        return sum(m.bits.nbytes + m.color.nbytes + m.bricks.nbytes + m.patch_bits.nbytes
                   for m in self.host_maps.values())

    def set_range(self, lo: float, hi: float, color_range=None) -> BrickedMaps:
        """Build (resident: and upload) every brick's maps for a new range."""
        self.lo, self.hi = float(lo), float(hi)
        self.color_range = tuple(color_range) if color_range is not None else (self.lo, self.hi)
        self.host_maps.clear()
        self._release_visuals()
        counts = []
        t0 = time.perf_counter()
        upload = 0.0
        for i in range(len(self.bricks)):
            m = self._maps(i)
            counts.append(int(m.count))
            if self.resident:
                t1 = time.perf_counter()
                self.visuals.append(self.make_visual(m))
                upload += time.perf_counter() - t1
                self.host_maps.pop(i, None)  # the GPU holds it now
            if self.progress is not None:
                self.progress(i + 1, len(self.bricks))
            del m
        if self.resident:
            self.peak_bytes = sum(v.gpu_bytes for v in self.visuals)
        self.prepare_ms = (time.perf_counter() - t0 - upload) * 1000
        self.upload_ms = upload * 1000
        self.maps = BrickedMaps(count=sum(counts), shape_xyz=self.box.size, box=self.box,
                                bricks=list(self.bricks), counts=counts)
        return self.maps

    @property
    def gpu_bytes(self) -> int:
        return int(self.peak_bytes) if (self.visuals or self.stream_visual) else 0

    @property
    def extra_stats(self) -> dict:
        return {"bricks": len(self.bricks), "brick_side": self.brick_side,
                "brick_mode": "resident" if self.resident else "streamed",
                "brick_map_rebuilds": self.rebuilds,
                "gpu_budget_bytes": self.budget,
                "largest_box": largest_box(self.method, self.budget, tex_limit(self.ctx))}

    def _order(self, camera, model) -> list[int]:
        """Bricks front to back (nearest centre first)."""
        centres = np.array([[o + s / 2 for o, s in zip(np.subtract(b.offset, self.box.offset),
                                                         b.size, strict=True)]
                            for b in self.bricks])
        world = (np.c_[centres, np.ones(len(centres))] @ np.asarray(model).T)[:, :3]
        return list(np.argsort(np.linalg.norm(world - camera.eye, axis=1), kind="stable"))

    def draw(self, camera, model, shading, count: bool = False) -> dict:
        """Draw every brick with ``model`` (the whole box's matrix) shifted by its offset."""
        from geoshade.render.visuals.raycast.visual import RaycastVisual

        total = {"voxels_drawn": 0, "triangles": 0}
        got_counts = False
        for i in self._order(camera, model):
            b = self.bricks[i]
            rel = np.subtract(b.offset, self.box.offset)
            m = np.asarray(model, float) @ _translate(rel)
            if self.resident:
                vis = self.visuals[i]
            else:
                maps = self._maps(i)
                if self.stream_visual is None:
                    self.stream_visual = self.make_visual(maps)
                else:
                    self.stream_visual.upload(maps)
                vis = self.stream_visual
                self.peak_bytes = max(self.peak_bytes, vis.gpu_bytes)
            if isinstance(vis, RaycastVisual):  # same rays as the whole box: exact picture
                res = vis.draw(camera, model, shading, count=count, brick_offset=tuple(rel))
            else:
                res = vis.draw(camera, m, shading, count=count)
            if count and res:
                got_counts = True
                for k in total:
                    total[k] += int(res.get(k) or 0)
        return total if (count and got_counts) else {}

    def _release_visuals(self) -> None:
        for v in self.visuals:
            v.release()
        self.visuals = []
        if self.stream_visual is not None:
            self.stream_visual.release()
            self.stream_visual = None

    def release(self) -> None:
        self._release_visuals()
        self.host_maps.clear()


__all__ = ["BrickedVisual", "gpu_budget", "tex_limit"]
