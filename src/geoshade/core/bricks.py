"""Boxes larger than the GPU allows: bricked rendering, streamed from a lazy volume; overviews.

A box is split into *bricks* (:func:`plan_bricks`) no larger than the 3D-texture limit per axis
(2048 on most GPUs) and small enough for the GPU memory.  Each brick has its own selection maps
(bit map, patch/brick occupancy, colour index map), built from the lazy volume with
:func:`geoshade.compute.lazy.selection_maps` (bit for bit the in-memory maps of that brick), and
its own visual.  All bricks are drawn with the model matrix of the whole box shifted by the
brick's offset; the ray caster (and every rasterised method) writes depth, so the depth test
composes the bricks into the picture of the unbricked box.

Two modes:

- *resident*: all bricks' textures fit the GPU budget at once; each is built and uploaded once,
  a frame draws them all (a new range rebuilds them);
- *streamed*: they do not fit; one visual is re-uploaded brick after brick in every frame.  The
  bricks' maps are kept in host memory up to ``host_cache_bytes`` and rebuilt from the lazy
  volume beyond that, so neither the GPU nor the host ever holds the whole box.

Hook into :class:`~geoshade.core.api.CoreView`: ``CoreView._rebuild`` first calls
:func:`maybe_bricked`, which takes over when the box needs bricks (``bricks=None`` auto: larger
than the texture limit or the GPU memory; ``bricks=N``: bricks of at most N voxels per side;
``bricks=False``: never) or when a dask ``scheduler`` is given (maps built on that cluster).

Overviews: :func:`overview_level` picks the finest pyramid level of an ingested store
(:func:`geoshade.io.ingest.ingest`) whose whole volume fits, :func:`render_overview` renders it;
then render a box of level 0 at full resolution with :func:`geoshade.core.render`.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from geoshade.compute.bitmaps import gpu_bytes_estimate
from geoshade.errors import GPUMemoryError, InputError
from geoshade.models.volume import Box, VoxelVolume

#: the 3D-texture limit assumed when the context does not say
DEFAULT_TEX_LIMIT = 2048
#: brick sides are multiples of these along (x, y, z): 32-bit words along x, 8³ occupancy bricks
ALIGN = (32, 8, 8)
#: fraction of the GPU memory budget the resident bricks may use (the unbricked check uses all)
RESIDENT_FRACTION = 1.0
#: host bytes of brick maps kept between frames in streamed mode (default)
HOST_CACHE_BYTES = 2 << 30
#: smallest brick side chosen automatically; a GPU budget that cannot hold a few such bricks
#: is reported as too small instead of being bricked
MIN_BRICK = 64
#: selected fraction assumed for methods whose GPU memory depends on the count (gs, cubes)
COUNT_GUESS = 0.5


# --------------------------------------------------------------------------------------------
# planning
# --------------------------------------------------------------------------------------------
def _split(n: int, max_side: int, align: int) -> list[tuple[int, int]]:
    """(offset, size) pieces of ``n`` voxels, each <= max_side, all but the last aligned."""
    side = max(align, max_side // align * align) if max_side >= align else max_side
    pieces = max(1, -(-n // side))
    # equal pieces rounded up to the alignment (fewer, better balanced bricks)
    step = -(-n // pieces)
    step = min(side, -(-step // align) * align) if max_side >= align else step
    return [(o, min(step, n - o)) for o in range(0, n, step)]


def plan_bricks(box: Box, max_side) -> list[Box]:
    """Split ``box`` into bricks of at most ``max_side`` voxels per axis (x, y, z).

    Brick offsets (relative to the box) are multiples of 32 along x and 8 along y and z when
    ``max_side`` allows, so words of the bit map and 8³ occupancy bricks never straddle two
    bricks.  Bricks are returned in x-fastest order, in the volume's coordinates.

    Examples
    --------
    >>> bs = plan_bricks(Box((10, 0, 0), (100, 40, 17)), 64)
    >>> [(b.offset, b.size) for b in bs][:2]
    [((10, 0, 0), (64, 40, 17)), ((74, 0, 0), (36, 40, 17))]
    >>> len(plan_bricks(Box((0, 0, 0), (4096, 4096, 7000)), 2048))
    16
    """
    ms = (max_side,) * 3 if np.isscalar(max_side) else tuple(max_side)
    if min(int(m) for m in ms) < 1:
        raise InputError(f"bricks: the brick side must be >= 1, got {max_side!r}")
    parts = [_split(n, int(m), a) for n, m, a in zip(box.size, ms, ALIGN, strict=True)]
    out = []
    for oz, sz in parts[2]:
        for oy, sy in parts[1]:
            for ox, sx in parts[0]:
                off = (box.offset[0] + ox, box.offset[1] + oy, box.offset[2] + oz)
                out.append(Box(off, (sx, sy, sz)))
    return out


def _tex_limit(ctx) -> int:
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
        avail = _host_available()
        return None if avail is None else avail // 2
    return None


def _host_available() -> int | None:
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        return None
    return None


def _estimate(size, method: str) -> int:
    size = tuple(int(v) for v in size)
    n = math.prod(size)
    return gpu_bytes_estimate(size, method, int(n * COUNT_GUESS))


def largest_box(method: str, budget: float | None, tex_limit: int) -> dict:
    """How large a d³ box fits on this GPU: unbricked, resident in bricks, and streamed.

    Examples
    --------
    >>> largest_box("raycast", 11 * 2**30, 2048)["unbricked"]
    2048
    >>> largest_box("raycast", 11 * 2**30, 2048)["resident_bricks"]
    2174
    """
    from geoshade.core.api import largest_cube_box

    free = float("inf") if budget is None else float(budget)
    unbricked = largest_cube_box(method, free, tex_limit, density=COUNT_GUESS)
    if budget is None:
        resident = None
    else:
        per_voxel = _estimate((512, 512, 512), method) / 512**3
        resident = int((RESIDENT_FRACTION * free / per_voxel) ** (1 / 3))
    return {"tex_limit": int(tex_limit), "gpu_budget_bytes": budget, "unbricked": unbricked,
            "resident_bricks": resident, "streamed": "any (one brick on the GPU at a time)"}


def choose_brick_side(box: Box, method: str, tex_limit: int, budget: int | None,
                      requested=None) -> int:
    """The brick side: ``requested`` if given, else the texture limit, shrunk (by halving)
    until one brick takes at most a quarter of the budget.

    Examples
    --------
    >>> box = Box((0, 0, 0), (4000, 4000, 4000))
    >>> [choose_brick_side(box, "raycast", 2048, b) for b in (None, 2**30)]
    [2048, 512]
    """
    if requested not in (None, True):
        return int(requested)
    side = int(tex_limit)
    if budget is not None:
        while side > MIN_BRICK and _estimate((min(side, n) for n in box.size), method) > budget / 4:
            side //= 2
    return side


def needs_bricks(box: Box, method: str, tex_limit: int, budget: int | None, requested=None
                 ) -> bool:
    """True when ``box`` must be (or was asked to be) rendered in bricks.

    Examples
    --------
    >>> needs_bricks(Box((0, 0, 0), (3000, 100, 100)), "raycast", 2048, None)
    True
    >>> needs_bricks(Box((0, 0, 0), (100, 100, 100)), "raycast", 2048, 2**30, requested=50)
    True
    """
    if requested is False:
        return False
    if requested not in (None, True):
        return max(box.size) > int(requested)
    if requested is True:
        return True
    if method != "cubes" and max(box.size) > tex_limit:
        return True
    if budget is None or _estimate((MIN_BRICK,) * 3, method) > budget / 4:
        return False  # unknown, or too small for any brick: the ordinary check says what fits
    return _estimate(box.size, method) > budget


# --------------------------------------------------------------------------------------------
# the bricked visual
# --------------------------------------------------------------------------------------------
@dataclass
class BrickedMaps:
    """What CoreView reads of ``maps`` for a bricked box: the selected count and the box."""

    count: int
    shape_xyz: tuple[int, int, int]
    box: Box
    bricks: list[Box] = field(default_factory=list)
    counts: list[int] = field(default_factory=list)


def _translate(offset) -> np.ndarray:
    m = np.eye(4)
    m[:3, 3] = offset
    return m


class BrickedVisual:
    """Draws a big box as bricks, each with its own selection maps and visual.

    Parameters
    ----------
    ctx : moderngl.Context
    volume : VoxelVolume
        Usually lazy (dask); each brick's maps are built from it when needed.
    box : Box
    lo, hi : float
        Selection range; ``color_range`` the colour range (default the selection range).
    make_visual : callable(maps) -> visual
        Builds one brick's visual (CoreView's ``_make_visual`` with the brick's maps).
    brick_side : int
    budget : int or None
        GPU bytes the bricks may use; None: unknown (assume resident fits).
    scheduler : optional
        Where the maps are built (see :func:`geoshade.compute.lazy.using_scheduler`).

    Attributes
    ----------
    gpu_bytes : int
        Peak bytes on the GPU at one time (all bricks when resident, the largest when streamed).
    """

    def __init__(self, ctx, volume: VoxelVolume, box: Box, lo: float, hi: float, color_range,
                 make_visual, brick_side: int, budget: int | None, scheduler=None,
                 progress=None, host_cache_bytes: int = HOST_CACHE_BYTES, method: str = "raycast"):
        self.ctx, self.volume, self.box = ctx, volume, box
        self.make_visual, self.scheduler, self.progress = make_visual, scheduler, progress
        self.method, self.budget, self.brick_side = method, budget, int(brick_side)
        self.host_cache_bytes = int(host_cache_bytes)
        self.bricks = plan_bricks(box, self.brick_side)
        need = sum(_estimate(b.size, method) for b in self.bricks)
        self.resident = budget is None or need <= RESIDENT_FRACTION * budget
        self.visuals: list = []
        self.stream_visual = None
        self.host_maps: dict[int, object] = {}
        self.peak_bytes = 0
        self.rebuilds = 0
        self.set_range(lo, hi, color_range)

    # ------------------------------------------------------------------------------------------
    def _maps(self, i: int):
        from geoshade.compute.lazy import selection_maps

        m = self.host_maps.get(i)
        if m is not None:
            return m
        b = self.bricks[i]
        clo, chi = self.color_range
        m = selection_maps(self.volume.data, b, self.lo, self.hi, clo, chi,
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

    # ------------------------------------------------------------------------------------------
    @property
    def gpu_bytes(self) -> int:
        return int(self.peak_bytes)

    @property
    def extra_stats(self) -> dict:
        return {"bricks": len(self.bricks), "brick_side": self.brick_side,
                "brick_mode": "resident" if self.resident else "streamed",
                "brick_map_rebuilds": self.rebuilds,
                "gpu_budget_bytes": self.budget,
                "largest_box": largest_box(self.method, self.budget, _tex_limit(self.ctx))}

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

    def upload(self, maps) -> None:  # CoreView calls this for a new range of the same visual
        raise InputError("bricked view: use set_range on the BrickedVisual")

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


# --------------------------------------------------------------------------------------------
# the CoreView hook
# --------------------------------------------------------------------------------------------
def maybe_bricked(view, maps_ok: bool = False) -> bool:
    """``CoreView._rebuild`` for big boxes and dask clusters; False: the ordinary path runs.

    Takes over when the box needs bricks (see :func:`needs_bricks`; ``view.bricks``), when
    ``view.scheduler`` is set, or when the volume is a dask array (zarr, HDF5, lazy TIFF): the
    maps are then built with :func:`geoshade.compute.lazy.selection_maps` (bit for bit the
    same maps, read and computed in parallel tasks; see :func:`build_maps`).
    """
    requested = getattr(view, "bricks", None)
    scheduler = getattr(view, "scheduler", None)
    st = view.state
    tex = _tex_limit(view.ctx)
    budget = gpu_budget(view.ctx, view.gpu_memory_limit)
    clo_chi = view.color_range if view.color_range is not None else (st.lo, st.hi)
    if needs_bricks(st.box, view.method, tex, budget, requested):
        side = choose_brick_side(st.box, view.method, tex, budget, requested)
        if side > tex:
            raise GPUMemoryError(f"bricks: a brick side of {side} exceeds this GPU's 3D texture "
                                 f"limit of {tex}")
        if isinstance(view.visual, BrickedVisual) and view.visual.box == st.box:
            view.visual.set_range(st.lo, st.hi, clo_chi)
        else:
            view._release_visual()
            view.visual = BrickedVisual(view.ctx, view.volume, st.box, st.lo, st.hi, clo_chi,
                                        _maker(view), side, budget, scheduler, view.progress,
                                        method=view.method)
        view.maps = view.visual.maps
        view.prepare_ms, view.upload_ms = view.visual.prepare_ms, view.visual.upload_ms
        return True
    if isinstance(view.visual, BrickedVisual):
        view._release_visual()
    return False  # one box: CoreView builds the maps (see build_maps) and uploads them


def _is_dask(data) -> bool:
    return type(data).__module__.split(".")[0] == "dask"


def build_maps(data, box, lo, hi, clo, chi, scheduler=None, progress=None):
    """The selection maps of one box: dask tasks for a dask volume or a given scheduler
    (:func:`geoshade.compute.lazy.selection_maps`), else the in-memory slab loop; both give
    the same maps bit for bit."""
    if scheduler is None and not _is_dask(data):
        from geoshade.compute.bitmaps import build_selection_maps

        return build_selection_maps(data, box, lo, hi, clo, chi, progress=progress)
    from geoshade.compute.lazy import selection_maps

    return selection_maps(data, box, lo, hi, clo, chi, scheduler=scheduler, progress=progress)


def _maker(view):
    """A visual factory for one brick's maps, using CoreView's own ``_make_visual``."""

    def make(maps):
        saved = view.maps
        view.maps = maps
        try:
            return view._make_visual()
        finally:
            view.maps = saved

    return make


# --------------------------------------------------------------------------------------------
# overviews of a multiscale store
# --------------------------------------------------------------------------------------------
def overview_level(path, method: str = "raycast", tex_limit: int = DEFAULT_TEX_LIMIT,
                   budget: float | None = None, max_voxels: float = 512**3) -> int:
    """The finest pyramid level of a store whose whole volume fits unbricked (texture limit and
    ``budget``) and has at most ``max_voxels`` voxels (the overview should come quickly).

    Examples
    --------
    >>> overview_level("no/such.zarr")
    Traceback (most recent call last):
    ...
    geoshade.errors.InputError: no/such.zarr: no such file
    """
    from geoshade.io.ingest import read_level, store_levels

    n = store_levels(path)
    for k in range(n):
        vol = read_level(path, k)
        size = vol.shape_xyz
        fits = max(size) <= tex_limit and math.prod(size) <= max_voxels
        if budget is not None:
            fits = fits and _estimate(size, method) <= budget
        if fits:
            return k
    return n - 1


def render_overview(path, range=None, level=None, **render_kw):
    """Render a whole ingested core from a coarse pyramid level.

    Parameters
    ----------
    path : str or Path
        A store written by :func:`geoshade.io.ingest.ingest`.
    range : (lo, hi)
        Selection range (the values are level 0's: ``nearest`` pyramids keep them).
    level : int, optional
        Pyramid level; default :func:`overview_level`.
    **render_kw
        Passed to :func:`geoshade.core.render` (``size``, ``view``, ``method``, ``ctx`` ...).

    Returns
    -------
    image, stats
        ``stats["level"]`` is the level drawn; the world box is the whole core's, so a camera
        framed on it frames the level-0 core as well.

    Examples
    --------
    >>> img, st = render_overview("core.zarr", range=(0, 80), size="64x64")  # doctest: +SKIP
    """
    from geoshade.core.api import render
    from geoshade.io.ingest import read_level

    if level is None:
        level = overview_level(path, method=render_kw.get("method", "raycast") or "raycast")
    vol = read_level(path, level)
    img, stats = render(vol, range=range, **render_kw)
    stats["level"] = int(level)
    stats["level_shape_xyz"] = list(vol.shape_xyz)
    return img, stats


__all__ = [
    "BrickedMaps",
    "BrickedVisual",
    "choose_brick_side",
    "gpu_budget",
    "largest_box",
    "maybe_bricked",
    "needs_bricks",
    "overview_level",
    "plan_bricks",
    "render_overview",
]
