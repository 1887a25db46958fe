"""The core's routes for the memory plan (:mod:`geoshade.io.plan`): how a box of a volume can be
drawn, with the resident memory, address space and GPU bytes of each, from the file's header.

- ``memory``: the box in one visual; the volume held (``.npz``, a TIFF read whole) or mapped
  (raw, ``.npy``: the box's pages are read, the whole file is mapped) or read by blocks (a
  store, HDF5); its selection maps and GPU objects (:func:`geoshade.compute.voxels.bitmaps.
  gpu_bytes_estimate`, the sizes the renderer allocates; a software renderer keeps a copy of
  them in memory);
- ``bricks``: the box in bricks within a GPU budget (:mod:`geoshade.compute.voxels.bricks`), the
  file
  read block by block, never mapped (:func:`geoshade.io.volumes.slabs.unmapped`); the host
  cache of brick maps bounded by the ``memory`` budget (:func:`geoshade.compute.voxels.bricks.
  host_cache`);
- ``level``: a store's coarser pyramid level drawn whole (the whole core, fewer voxels);
- ``store``: ``geoshade core ingest`` first (a chunked multiscale store), then its bricks or a
  level.

Calibration (peak RSS and address space of ``geoshade core render`` on this project's 2-core
llvmpipe machine, uint8 volumes, ``--size 320x240``, measured with ``/proc/PID/status``
``VmHWM``/``VmPeak``; docs/NOTES.md "Memory plan" has the commands):

==============================================  =========  ==========  ===============
run                                             peak RSS   peak VM     estimate (RSS)
==============================================  =========  ==========  ===============
256³ raw, in memory (mapped)                    363 MiB    1406 MiB    362 MiB
512³ raw, in memory (mapped)                    742 MiB    1784 MiB    747 MiB
768³ raw, in memory (mapped)                    1799 MiB   2846 MiB    1734 MiB
256³ raw, bricks: GPU 16 MiB, cache 75 MiB      441 MiB    1552 MiB    409 MiB
512³ raw, bricks: GPU 64 MiB, cache 75 MiB      680 MiB    1794 MiB    618 MiB
768³ raw, bricks: GPU 64 MiB, cache 75 MiB      1174 MiB   2275 MiB    1120 MiB
768³ raw, bricks: GPU 256 MiB, cache 250 MiB    1305 MiB   2461 MiB    1391 MiB
==============================================  =========  ==========  ===============

In memory, RSS = :data:`BASE` + the box's data + twice its GPU objects (the maps built on the
host, and the software renderer's copy of the textures); the address space adds
:data:`VM_EXTRA` (libraries, thread stacks and arenas) and the rest of a mapped file.  In
bricks (the file read by blocks, nothing mapped), RSS = :data:`BRICKS_BASE` +
:data:`BRICKS_VOXEL` a voxel of the box + half the GPU budget + the host cache of maps; the
address space adds :data:`BRICKS_VM_EXTRA`.  The bricks' 1.65 B a voxel is what llvmpipe keeps
of the streamed bricks' objects; on a GPU with its own memory it should be less.
"""

from __future__ import annotations

import dataclasses
import math

from geoshade.compute.voxels.bitmaps import gpu_bytes_estimate
from geoshade.compute.voxels.bricks import COUNT_GUESS, DEFAULT_TEX_LIMIT, MIN_BRICK, host_cache
from geoshade.io.plan import GIB, MIB, Header, Route
from geoshade.io.stores.zarr_io import read_level
from geoshade.io.volumes.slabs import block_bytes, unmapped

#: resident memory of a core render besides the data: Python, numpy, dask, numba, the
#: software renderer (measured: 256³ and 512³ raw renders, see the module)
BASE = 309 * MIB
#: address space beyond the resident memory (libraries mapped, thread stacks and arenas)
VM_EXTRA = int(1.05 * GIB)
#: resident memory of a bricked render besides its voxels, bricks and cache (measured)
BRICKS_BASE = 300 * MIB
#: resident bytes per voxel of the box a bricked render streams (measured on llvmpipe: 2.1,
#: 1.8 and 1.6 at 256³, 512³ and 768³; the renderer's copies of the streamed bricks' objects)
BRICKS_VOXEL = 1.65
#: address space beyond a bricked render's resident memory (dask's threads and libraries)
BRICKS_VM_EXTRA = int(1.1 * GIB)
#: smallest GPU budget the plan gives bricks (a few bricks of :data:`MIN_BRICK`)
MIN_BUDGET = 64 * MIB
#: the software renderer keeps a copy of every GPU object in host memory; a budget share
GPU_COPIES = 2


def _box(header: Header, options) -> tuple[int, int, int]:
    box = getattr(options, "box", None)
    if box is None:
        return tuple(int(n) for n in header.shape[:3])
    return tuple(int(n) for n in getattr(box, "size", box[3:6]))


def _method(options) -> str:
    m = getattr(options, "method", "auto") or "auto"
    return "raycast" if m == "auto" else m


def gpu_bytes(size, method: str) -> int:
    """GPU bytes of a box of ``size`` (x, y, z) voxels for ``method``, half of them selected."""
    return gpu_bytes_estimate(size, method, int(math.prod(size) * COUNT_GUESS))


def memory_route(header: Header, options=None, level: int | None = None) -> Route:
    """The box drawn in one visual, the volume held, mapped or read by blocks."""
    size = _box(header, options) if level is None else header.levels[level]
    method = _method(options)
    item = header.itemsize
    box_bytes = math.prod(size) * item
    held = header.count * item if header.storage == "held" else (
        box_bytes if header.storage == "mapped" else 2 * block_bytes(header.dtype or "uint8"))
    gpu = gpu_bytes(size, method)
    ram = BASE + held + GPU_COPIES * gpu
    mapped = header.file_bytes - box_bytes if header.storage == "mapped" else 0
    if level is None:
        title = "read by chunks" if header.kind == "volume-store" else "in memory"
        return Route("memory", title, ram, ram + VM_EXTRA + max(0, mapped), gpu,
                     gpu_binding=False)
    nx, ny, nz = size
    return Route("level", f"from pyramid level {level}", ram, ram + VM_EXTRA, gpu,
                 gpu_binding=False, reduced=f"pyramid level {level}: {nx}×{ny}×{nz} voxels of "
                         f"{'×'.join(map(str, header.levels[0]))}",
                 load=lambda: _level(header.path, level))


def bricks_route(header: Header, options=None, ram_cap: int | None = None,
                 ready: bool = True, how: str = "") -> Route:
    """The box in bricks, the file read by blocks, within ``ram_cap`` (the resident memory the
    plan lets it use, its margin taken): the host cache of maps
    (:func:`geoshade.compute.voxels.bricks.
    host_cache` of it) and a GPU budget from what is left (the whole box's GPU bytes when
    nothing bounds it)."""
    size = _box(header, options)
    method = _method(options)
    whole = gpu_bytes(size, method)
    memory = None if ram_cap is None else max(0, int(ram_cap))
    cache = min(host_cache(memory), whole)
    streamed = int(BRICKS_BASE + BRICKS_VOXEL * math.prod(size) + cache)
    budget = whole if memory is None else max(MIN_BUDGET, min(whole, 2 * (memory - streamed)))
    ram = streamed + budget // 2
    side = max(MIN_BRICK, min(DEFAULT_TEX_LIMIT, int((budget / 4) ** (1 / 3))))
    opts = {"gpu_memory": int(budget)}
    if memory is not None:
        opts["memory"] = memory
    title = "in bricks, read by " + ("chunks" if header.kind == "volume-store" else "blocks")
    return Route("bricks", title, ram, ram + BRICKS_VM_EXTRA, budget, gpu_binding=False,
                 ready=ready, how=how, options=opts,
                 adapt=unmapped if header.storage == "mapped" else None,
                 note=f"bricks of up to {side}³ within {budget >> 20} MiB of GPU memory")


def core_routes(header: Header, options=None, ram_cap: int | None = None) -> list[Route]:
    """Every route for ``header`` (a volume or a volume store) and the box of ``options``;
    ``ram_cap``: the resident memory a bricks route may plan for (see :func:`bricks_route`);
    none for an empty box (the View says what is wrong with it)."""
    if min(_box(header, options)) < 1 or header.count < 1:
        return []
    if header.kind == "volume-store":
        routes = [memory_route(header, options),
                  bricks_route(header, options, ram_cap)]
        routes += [memory_route(header, options, level=k) for k in range(1, len(header.levels))]
        return routes
    store = _store_name(header.path)
    ingest = f"geoshade core ingest {header.path} -o {store}"
    routes = [memory_route(header, options),
              bricks_route(header, options, ram_cap,
                           ready=header.storage in ("mapped", "lazy"),
                           how="" if header.storage in ("mapped", "lazy") else ingest)]
    half = tuple(-(-int(n) // 2) for n in header.shape[:3])
    if min(half) >= 1 and header.count > 1:   # a store's first overview level, once ingested
        lv = dataclasses.replace(header, kind="volume-store", levels=(tuple(header.shape[:3]),
                                                                      half), storage="lazy")
        r = memory_route(lv, None, level=1)
        routes.append(dataclasses.replace(
            r, title="from a store's pyramid level 1", ready=False, load=None,
            how=f"{ingest}, then render {store} --level 1"))
    return routes


def _level(path, level: int):
    """Pyramid level ``level`` of a store, named so that its picture says which."""
    vol = read_level(path, level)
    if (vol.name or "").endswith(f"[{level}]"):   # already says it (``core.zarr[1]``)
        return vol
    return dataclasses.replace(vol, name=f"{vol.name or path} (pyramid level {level})")


def _store_name(path) -> str:
    name = str(path).rstrip("/")
    for suf in (".raw", ".npy", ".npz", ".tif", ".tiff", ".nhdr", ".nrrd", ".mhd", ".mha",
                ".h5", ".hdf5"):
        if name.lower().endswith(suf):
            return name[: -len(suf)] + ".zarr"
    return name + ".zarr"


__all__ = ["BASE", "BRICKS_BASE", "BRICKS_VM_EXTRA", "BRICKS_VOXEL", "VM_EXTRA", "bricks_route",
           "core_routes", "gpu_bytes", "memory_route"]
