"""Planning boxes larger than a GPU allows: bricks, their sizes, what fits (no GL).

A box is split into *bricks* (:func:`plan_bricks`) no larger than the 3D-texture limit per axis
(2048 on most GPUs) and small enough for the GPU memory. Each brick gets its own selection maps
(:func:`selection_maps_for`, bit for bit the in-memory maps of that brick) and its own visual
(:mod:`geoshade.render.visuals.bricked`). Two modes:

- *resident*: all bricks fit the GPU budget at once; built and uploaded once, drawn every frame;
- *streamed*: they do not fit; one visual is re-uploaded brick after brick in every frame, the
  maps kept in host memory up to a cache size and rebuilt from the lazy volume beyond that.

The functions here decide sizes only; the GPU's limits are passed in as numbers.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from geoshade.compute.voxels.bitmaps import build_selection_maps, gpu_bytes_estimate
from geoshade.compute.voxels.lazy import selection_maps
from geoshade.errors import InputError
from geoshade.models.volume import Box
from geoshade.scheduler import Scheduler

#: the 3D-texture limit assumed when the context does not say
DEFAULT_TEX_LIMIT = 2048
#: brick sides are multiples of these along (x, y, z): 32-bit words along x, 8³ occupancy bricks
ALIGN = (32, 8, 8)
#: fraction of the GPU memory budget the resident bricks may use (the unbricked check uses all)
RESIDENT_FRACTION = 1.0
#: host bytes of brick maps kept between frames in streamed mode (default)
HOST_CACHE_BYTES = 2 << 30
#: the share of a ``memory`` budget (the RAM the picture may use) the streamed maps may hold
CACHE_SHARE = 0.1


def host_cache(memory: int | None) -> int:
    """Host bytes of brick maps a streamed picture keeps between frames: :data:`HOST_CACHE_BYTES`,
    or :data:`CACHE_SHARE` of a ``memory`` budget when that is less.

    >>> host_cache(None) == HOST_CACHE_BYTES, host_cache(1 << 30) >> 20
    (True, 102)
    """
    if memory is None:
        return HOST_CACHE_BYTES
    return int(min(HOST_CACHE_BYTES, CACHE_SHARE * int(memory)))
#: smallest brick side chosen automatically; a GPU budget that cannot hold a few such bricks
#: is reported as too small instead of being bricked
MIN_BRICK = 64
#: selected fraction assumed for methods whose GPU memory depends on the count (gs, cubes)
COUNT_GUESS = 0.5


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


#: most bricks one picture is drawn in (each brick is a visual with its maps and GL objects)
MAX_BRICKS = 4096
#: host bytes a resident brick costs beyond its maps (its visual and the driver's copies of its
#: GL objects: 3–5 MB were measured on llvmpipe whatever the brick's content)
HOST_BYTES_PER_BRICK = 5 << 20


def brick_count(box: Box, max_side) -> int:
    """How many bricks :func:`plan_bricks` makes, without making them.

    >>> brick_count(Box((0, 0, 0), (110, 110, 110)), 2)
    166375
    """
    ms = (max_side,) * 3 if np.isscalar(max_side) else tuple(max_side)
    if min(int(m) for m in ms) < 1:
        raise InputError(f"bricks: the brick side must be >= 1, got {max_side!r}")
    return math.prod(len(_split(n, int(m), a)) for n, m, a in zip(box.size, ms, ALIGN,
                                                                  strict=True))


def resident(box: Box, side: int, method: str, budget: int | None) -> bool:
    """True when every brick of ``box`` stays on the GPU at once (``budget`` None: unknown, so
    they do); else they are streamed one at a time.

    >>> resident(Box((0, 0, 0), (512, 512, 512)), 256, "raycast", None)
    True
    >>> resident(Box((0, 0, 0), (512, 512, 512)), 256, "raycast", 2**20)
    False
    """
    need = sum(estimate_bytes(b.size, method) for b in plan_bricks(box, side))
    return budget is None or need <= RESIDENT_FRACTION * budget


def _side_that_fits(box: Box, side: int, method: str, host_free: int) -> int | None:
    """The smallest brick side above ``side`` whose resident bricks fit in ``host_free``."""
    for s in range(int(side) + 1, max(box.size) + 1):
        n = brick_count(box, s)
        if n <= MAX_BRICKS and n * (estimate_bytes([min(s, v) for v in box.size], method)
                                    + HOST_BYTES_PER_BRICK) <= host_free:
            return s
    return None


def check_resident(box: Box, side: int, method: str, budget: int | None,
                   host_free: int | None) -> None:
    """Refuse in one line, before any brick is built, bricks that are all resident (see
    :func:`resident`) but cannot all be held in ``host_free`` bytes of host memory: each holds
    its visual and the driver's copies of its GL objects (:data:`HOST_BYTES_PER_BRICK`) at once,
    and beyond the memory or the address-space limit a software renderer dies with SIGSEGV or
    "LLVM ERROR" instead of a line. The message gives the brick side that fits.

    Examples
    --------
    >>> check_resident(Box((0, 0, 0), (110, 110, 110)), 32, "raycast", None, 2**31)
    >>> check_resident(Box((0, 0, 0), (110, 110, 110)), 12, "raycast", None, 2**31)
    Traceback (most recent call last):
    ...
    geoshade.errors.InputError: bricks 12: box 110×110×110 would be drawn in 1,960 bricks ...
    """
    count = brick_count(box, side)
    per = estimate_bytes([min(side, n) for n in box.size], method) + HOST_BYTES_PER_BRICK
    if host_free is None or count * per <= host_free or not resident(box, side, method, budget):
        return
    fits = _side_that_fits(box, side, method, host_free)
    sx, sy, sz = box.size
    gib = 2**30
    raise InputError(f"bricks {side}: box {sx}×{sy}×{sz} would be drawn in {count:,} bricks "
                     f"holding {count * per / gib:.2f} GiB of host memory at once (each its maps "
                     f"and the driver's copies of its GL objects), more than the "
                     f"{host_free / gib:.2f} GiB available; give "
                     + (f"--bricks {fits} or larger" if fits else "a smaller --box")
                     + (" or --bricks 0 (one piece)" if fits is None or max(box.size) > fits
                        else ""))


def check_brick_budget(box: Box, side: int, method: str, host_free: int | None,
                       default_box_bytes: int | None = None) -> dict:
    """Plan the host memory of drawing ``box`` in bricks of ``side`` before any is built.

    Parameters
    ----------
    box : Box
    side : int
        The brick side (:func:`choose_brick_side`).
    method : str
    host_free : int or None
        Bytes of host memory available (None: unknown; only the brick count is checked).
    default_box_bytes : int or None
        The volume's bytes when ``box`` is the whole volume because no box was given: a whole
        volume larger than the host memory is refused (a store's metadata may declare any
        size) instead of read brick after brick.
    Returns
    -------
    dict
        ``count`` bricks, ``host_bytes_per_brick`` (maps and visual), ``host_bytes`` when all
        are resident.

    Raises
    ------
    InputError
        One line: more bricks than :data:`MAX_BRICKS`, one brick larger than the host memory,
        or a default box beyond it.

    Examples
    --------
    >>> check_brick_budget(Box((0, 0, 0), (110, 110, 110)), 2, "raycast", None)
    Traceback (most recent call last):
    ...
    geoshade.errors.InputError: bricks 2: box 110×110×110 would be drawn in 166,375 bricks, more ...
    >>> check_brick_budget(Box((0, 0, 0), (512, 512, 512)), 256, "raycast", 2**34)["count"]
    8
    """
    sx, sy, sz = box.size
    gib = 2**30
    if host_free is not None and default_box_bytes is not None and default_box_bytes > host_free:
        raise InputError(f"box {sx}×{sy}×{sz}: the whole volume ({default_box_bytes / gib:,.1f} "
                         f"GiB) is more than the {host_free / gib:.2f} GiB of memory available; "
                         "give a --box (or a coarser --level) to draw a part of it")
    count = brick_count(box, side)
    if count > MAX_BRICKS:
        need = max(1, math.ceil((box.nvoxels / MAX_BRICKS) ** (1 / 3)))
        raise InputError(f"bricks {side}: box {sx}×{sy}×{sz} would be drawn in {count:,} bricks, "
                         f"more than the {MAX_BRICKS} one picture may use (each holds host and "
                         f"GPU memory); give --bricks {max(need, side * 2)} or larger, or a "
                         "smaller --box")
    brick = tuple(min(side, n) for n in box.size)
    per = estimate_bytes(brick, method) + HOST_BYTES_PER_BRICK
    plan = {"count": count, "host_bytes_per_brick": per, "host_bytes": count * per}
    if host_free is not None and per > host_free:
        raise InputError(f"bricks {side}: one brick of {brick[0]}×{brick[1]}×{brick[2]} needs "
                         f"{per / gib:.2f} GiB of host memory, {host_free / gib:.2f} GiB are "
                         "available; give a smaller --bricks side")
    return plan


def estimate_bytes(size, method: str) -> int:
    """GPU bytes of a box of ``size`` (x, y, z) voxels for ``method``, half of them selected."""
    size = tuple(int(v) for v in size)
    n = math.prod(size)
    return gpu_bytes_estimate(size, method, int(n * COUNT_GUESS))


def largest_cube_box(method: str, free_bytes: float, tex_limit: int, density: float = 0.5) -> int:
    """Side d of the largest d³ box whose GPU objects fit in ``free_bytes``.

    >>> largest_cube_box("raycast", float("inf"), 2048)
    2048
    """
    lo, hi = 1, max(1, int(tex_limit))
    while lo < hi:
        mid = (lo + hi + 1) // 2
        count = int(mid**3 * density)
        if gpu_bytes_estimate((mid, mid, mid), method, count) <= free_bytes:
            lo = mid
        else:
            hi = mid - 1
    return lo


def largest_box(method: str, budget: float | None, tex_limit: int) -> dict:
    """How large a d³ box fits on this GPU: unbricked, resident in bricks, and streamed.

    Examples
    --------
    >>> largest_box("raycast", 11 * 2**30, 2048)["unbricked"]
    2048
    >>> largest_box("raycast", 11 * 2**30, 2048)["resident_bricks"]
    2174
    """
    free = float("inf") if budget is None else float(budget)
    unbricked = largest_cube_box(method, free, tex_limit, density=COUNT_GUESS)
    if budget is None:
        resident = None
    else:
        per_voxel = estimate_bytes((512, 512, 512), method) / 512**3
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
        while side > MIN_BRICK and estimate_bytes((min(side, n) for n in box.size),
                                                  method) > budget / 4:
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
    if budget is None or estimate_bytes((MIN_BRICK,) * 3, method) > budget / 4:
        return False  # unknown, or too small for any brick: the ordinary check says what fits
    return estimate_bytes(box.size, method) > budget


def fits_message(box: Box, method: str, count: int, tex_limit: int, free: int | None
                 ) -> str | None:
    """Why ``box`` does not fit unbricked (None: it fits), with the largest cube that does."""
    need = gpu_bytes_estimate(box.size, method, count)
    too_wide = method != "cubes" and max(box.size) > tex_limit
    if not (too_wide or (free is not None and need > free)):
        return None
    side = largest_cube_box(method, free if free else float("inf"), tex_limit,
                            density=count / max(box.nvoxels, 1))
    what = (f"exceeds the 3D texture limit of {tex_limit} per axis" if too_wide else
            f"needs {need / 2**30:.2f} GiB of GPU memory, {(free or 0) / 2**30:.2f} GiB free")
    return (f"box {box.size[0]}×{box.size[1]}×{box.size[2]} with method {method} {what}; "
            f"a box of up to {side}³ voxels fits (use --box)")


@dataclass
class BrickedMaps:
    """What a View reads of the maps of a bricked box: the selected count and the box."""

    count: int
    shape_xyz: tuple[int, int, int]
    box: Box
    bricks: list[Box] = field(default_factory=list)
    counts: list[int] = field(default_factory=list)


def is_dask(data) -> bool:
    return type(data).__module__.split(".")[0] == "dask"


def selection_maps_for(data, box, lo, hi, clo, chi, scheduler=None, progress=None):
    """The selection maps of one box: dask tasks for a dask volume or a scheduler other than
    :data:`~geoshade.scheduler.HERE` (:func:`geoshade.compute.voxels.lazy.selection_maps`), else the
    in-memory slab loop
    (:func:`geoshade.compute.voxels.bitmaps.build_selection_maps`); both give the same maps bit for
    bit."""
    if Scheduler.parse(scheduler).in_place and not is_dask(data):

        return build_selection_maps(data, box, lo, hi, clo, chi, progress=progress)

    return selection_maps(data, box, lo, hi, clo, chi, scheduler=scheduler, progress=progress)


__all__ = ["ALIGN", "CACHE_SHARE", "COUNT_GUESS", "DEFAULT_TEX_LIMIT", "HOST_BYTES_PER_BRICK",
           "HOST_CACHE_BYTES", "MAX_BRICKS", "MIN_BRICK", "BrickedMaps", "brick_count",
           "check_brick_budget", "check_resident", "choose_brick_side", "estimate_bytes",
           "fits_message", "host_cache", "largest_box", "largest_cube_box", "needs_bricks",
           "plan_bricks", "resident", "selection_maps_for"]
