"""Dask plumbing of the digital core: running graphs on a scheduler, wrapping arrays as dask
arrays, and the out-of-core selection maps.

- :func:`compute` runs graphs on a scheduler (:mod:`geoshade.scheduler`) with task progress;
  :func:`as_dask` wraps numpy, memmaps (:class:`MemmapArray`, picklable), zarr and HDF5 arrays.
  :func:`geoshade.compute.voxels.porosity.porosity` uses both for its ``scheduler=`` path (the same
  block function as its slab loop: one implementation).
- :func:`selection_maps` equals :func:`geoshade.compute.voxels.bitmaps.build_selection_maps` bit for
  bit (each task runs the same numpy slab function; only exact integers are summed).
- :func:`ramp_volume` / :func:`ramp_count`: a lazy volume generated chunk by chunk and its exact
  oracle, for tests and benchmarks beyond memory.

Where they run (``scheduler=``): a :class:`~geoshade.scheduler.Scheduler` or what it parses
(``None``, ``here``: dask's threads; a dask local scheduler by name, a ``distributed.Client``,
an address, ``"local:N"``), or a View's :class:`~geoshade.scheduler.SchedulerSession`.

Memory: a task holds one input block plus its bool mask (and, for the selection maps, one z slab
of the box); the peak is about ``block bytes × 3 × threads`` per worker, independent of the
volume.  Raw files (numpy memmaps) and HDF5 datasets are wrapped so that tasks sent to other
processes re-open the file instead of carrying the data.
"""

from __future__ import annotations

import contextlib
import math
import mmap
from collections.abc import Iterator
from typing import Any

import numpy as np

from geoshade.compute.voxels.bitmaps import (
    SelectionMaps,
    maps_args,
    pack_bits,
    patch_grid,
    slab_maps,
    words_per_row,
)
from geoshade.compute.voxels.selection import (
    SLAB_BYTES,
    resolve_data_box,
    slab_depth,
)
from geoshade.errors import InputError
from geoshade.models import VoxelVolume
from geoshade.progress import Progress
from geoshade.scheduler import dask_get, using_scheduler

#: bytes per block when a numpy array is wrapped as a dask array
BLOCK_BYTES = 64 << 20


# --------------------------------------------------------------------------------------------
# schedulers (geoshade.scheduler) and task progress
# --------------------------------------------------------------------------------------------
def _is_local(s) -> bool:
    return isinstance(s, str)


class _Progress:
    """A dask local-scheduler callback calling ``progress(done, total)`` per finished task."""

    def __init__(self, progress: Progress | None):
        self.progress = progress

    @contextlib.contextmanager
    def __call__(self, sched) -> Iterator[None]:
        if self.progress is None or not _is_local(sched):
            yield
            return
        from dask.callbacks import Callback

        state = {"done": 0, "total": 0}
        cb = self.progress

        def start_state(dsk, st):
            state["total"] = sum(len(st[k]) for k in ("ready", "waiting"))

        def posttask(key, result, dsk, st, worker_id):
            state["done"] += 1
            cb(state["done"], max(state["total"], state["done"]))

        with Callback(start_state=start_state, posttask=posttask):
            yield


def compute(*graphs, scheduler=None, progress=None):
    """``dask.compute(*graphs)`` on ``scheduler`` (see :func:`geoshade.scheduler.using_scheduler`).

    Examples
    --------
    >>> import dask.array as da
    >>> compute(da.ones(10, chunks=5).sum())
    (np.float64(10.0),)
    """
    import dask

    with using_scheduler(scheduler) as sched, _Progress(progress)(sched):
        return dask.compute(*graphs, scheduler=dask_get(sched))


# --------------------------------------------------------------------------------------------
# wrapping arrays
# --------------------------------------------------------------------------------------------
class MemmapArray:
    """A picklable view of a C-ordered array in a file (what a raw-file memmap maps).

    Examples
    --------
    >>> import tempfile, os
    >>> f = os.path.join(tempfile.mkdtemp(), "a.raw")
    >>> np.arange(24, dtype="<u2").tofile(f)
    >>> m = MemmapArray(f, "<u2", 0, (2, 3, 4))
    >>> int(m[1, 2, 3]), m.shape
    (23, (2, 3, 4))
    """

    def __init__(self, filename, dtype, offset: int, shape):
        self.filename, self.dtype = str(filename), np.dtype(dtype)
        self.offset, self.shape = int(offset), tuple(int(n) for n in shape)
        self.ndim = len(self.shape)
        self._map = None

    def _array(self) -> np.ndarray:
        if self._map is None:
            try:
                self._map = np.memmap(self.filename, self.dtype, "r", self.offset, self.shape)
            except (OSError, ValueError) as err:  # the file shrank or went since it was opened
                first = (str(err).strip().splitlines() or [type(err).__name__])[0]
                raise InputError(f"{self.filename}: cannot be mapped again ({first}); the file "
                                 "changed since it was opened") from None
        return self._map

    def __getitem__(self, key) -> np.ndarray:
        return np.array(self._array()[key])

    def __getstate__(self) -> dict:
        return {**self.__dict__, "_map": None}


def _memmap_source(a) -> MemmapArray | None:
    mm, fn = getattr(a, "_mmap", None), getattr(a, "filename", None)
    if mm is None or fn is None or not a.flags.c_contiguous:
        return None
    try:
        base = np.frombuffer(mm, np.uint8).ctypes.data
    except (TypeError, ValueError):
        return None
    start = a.ctypes.data - base + (int(a.offset) - int(a.offset) % mmap.ALLOCATIONGRANULARITY)
    return MemmapArray(fn, a.dtype, start, a.shape)


def as_dask(data, chunks=None):
    """A dask array over a volume's data (a dask array is returned as it is).

    numpy arrays get blocks of about ``BLOCK_BYTES``; a numpy memmap becomes a
    :class:`MemmapArray` (picklable: tasks on other processes map the file themselves).

    Examples
    --------
    >>> as_dask(np.zeros((4, 4, 4), np.uint8)).chunks
    ((4,), (4,), (4,))
    """
    import dask.array as da

    if isinstance(data, VoxelVolume):
        data = data.data
    if isinstance(data, da.Array):
        return data if chunks is None else data.rechunk(chunks)
    src = _memmap_source(data) if isinstance(data, np.memmap) else None
    if chunks is None:
        chunks = getattr(data, "chunks", None)
        if not (isinstance(chunks, tuple) and len(chunks) == 3
                and all(isinstance(c, int) for c in chunks)):
            chunks = da.core.normalize_chunks("auto", data.shape, limit=BLOCK_BYTES,
                                              dtype=data.dtype)
    if src is not None:
        return da.from_array(src, chunks=chunks, asarray=True, fancy=False, lock=False,
                             name="memmap-" + _token(src.filename, src.offset, src.shape,
                                                     src.dtype.str))
    if hasattr(data, "chunks") and not isinstance(data, np.ndarray):
        import zarr

        if isinstance(data, zarr.Array):
            return da.from_zarr(data, chunks=chunks)
    return da.from_array(data, chunks=chunks)


def _token(*parts) -> str:
    from dask.base import tokenize

    return tokenize(*parts)


def _box_array(data, box):
    """(dask array of the box, Box, VoxelVolume or None)."""
    arr, box, vol = resolve_data_box(data, box)
    return as_dask(arr)[box.slices()], box, vol


# --------------------------------------------------------------------------------------------
# selection maps and colour index map
# --------------------------------------------------------------------------------------------
def _maps_block(slab, flo, fhi, clo, chi, l, brick):
    """One z slab -> (bits, patch mask, bricks, colour, count array): a task of the graph."""
    *maps, count = slab_maps(slab, flo, fhi, clo, chi, l, brick)
    return (*maps, np.array([count], np.int64))


def selection_maps_graph(data, box=None, lo=0, hi=0, color_lo=None, color_hi=None, l: int = 64,
                         brick: int = 8, slab_bytes: int = SLAB_BYTES) -> dict:
    """Dask arrays of the selection maps of a box (nothing is computed).

    Returns
    -------
    dict
        ``bits (nz, ny, ceil(nx/32)) uint32``, ``patch_mask (q_p, m_p, n_p) bool``,
        ``bricks`` uint8, ``color (nz, ny, nx) uint8``, ``counts (slabs,) int64`` (selected
        voxels per z slab), and ``box``, ``range``, ``color_range``, ``l``, ``brick``.

    Examples
    --------
    >>> g = selection_maps_graph(np.arange(64, dtype=np.uint8).reshape(4, 4, 4), None, 0, 9)
    >>> int(g["counts"].sum().compute()), g["bits"].shape
    (10, (4, 4, 1))
    """
    import dask.array as da
    from dask import delayed

    x, box, _ = _box_array(data, box)
    l, brick, flo, fhi, clo, chi = maps_args(x.dtype, lo, hi, color_lo, color_hi, l, brick)
    nx, ny, nz = box.size
    n_p, m_p, _ = patch_grid(nx, ny, nz, l)
    depth = slab_depth((nx, ny, nz), x.dtype.itemsize, math.lcm(8, brick), slab_bytes)
    xs = x.rechunk((depth, ny, nx))
    nw = words_per_row(nx)
    by, bx = -(-ny // brick), -(-nx // brick)
    outs: dict[str, list] = {"bits": [], "patch_mask": [], "bricks": [], "color": [],
                             "counts": []}
    for i, blk in enumerate(xs.to_delayed().ravel()):
        dz = min(depth, nz - i * depth)
        parts = delayed(_maps_block, nout=5, pure=True)(blk, flo, fhi, clo, chi, l, brick)
        outs["bits"].append(da.from_delayed(parts[0], (dz, ny, nw), np.uint32))
        outs["patch_mask"].append(da.from_delayed(parts[1], (dz, m_p, n_p), bool))
        outs["bricks"].append(da.from_delayed(parts[2], (-(-dz // brick), by, bx), np.uint8))
        outs["color"].append(da.from_delayed(parts[3], (dz, ny, nx), np.uint8))
        outs["counts"].append(da.from_delayed(parts[4], (1,), np.int64))
    g: dict[str, Any] = {k: da.concatenate(v, axis=0) for k, v in outs.items()}
    g.update(box=box, range=(flo, fhi), color_range=(clo, chi), l=l, brick=brick)
    return g


def selection_maps(data, box=None, lo=0, hi=0, color_lo=None, color_hi=None, l: int = 64,
                   brick: int = 8, scheduler=None, progress=None,
                   slab_bytes: int = SLAB_BYTES) -> SelectionMaps:
    """:func:`geoshade.compute.voxels.bitmaps.build_selection_maps` from a lazy volume, out of core.

    The input is read in z slabs of the box (each a task); the result (about 1.13 bytes per
    box voxel) is assembled in memory.  On a local scheduler each slab's maps are written
    straight into the result arrays; on a cluster they come back and are concatenated.

    Examples
    --------
    >>> from geoshade.compute.voxels.bitmaps import build_selection_maps
    >>> a = np.arange(4 * 5 * 40, dtype=np.uint16).reshape(4, 5, 40)
    >>> m = selection_maps(a, None, 100, 299)
    >>> ref = build_selection_maps(a, None, 100, 299)
    >>> m.count == ref.count and np.array_equal(m.bits, ref.bits)
    True
    """
    import dask.array as da

    g = selection_maps_graph(data, box, lo, hi, color_lo, color_hi, l, brick, slab_bytes)
    box = g["box"]
    nx, ny, nz = box.size
    n_p, m_p, q_p = patch_grid(nx, ny, nz, g["l"])
    names = ("bits", "patch_mask", "bricks", "color")
    with using_scheduler(scheduler) as sched:
        if _is_local(sched) and sched != "processes":  # same memory: write in place
            targets = {k: np.empty(g[k].shape, g[k].dtype) for k in names}
            stored = da.store([g[k] for k in names], [targets[k] for k in names], lock=False,
                              compute=False)
            _, counts = compute(stored, g["counts"], scheduler=sched, progress=progress)
            res = targets
        else:
            *arrs, counts = compute(*(g[k] for k in names), g["counts"], scheduler=sched)
            res = dict(zip(names, arrs, strict=True))
    return SelectionMaps(
        bits=np.asarray(res["bits"], np.uint32),
        patch_bits=pack_bits(np.asarray(res["patch_mask"], bool)),
        patch_shape=(n_p, m_p, q_p),
        bricks=np.asarray(res["bricks"], np.uint8),
        color=np.asarray(res["color"], np.uint8),
        count=int(np.asarray(counts, np.int64).sum()),
        shape_xyz=(nx, ny, nz),
        box=box,
        range=g["range"],
        color_range=g["color_range"],
        l=g["l"],
        brick=g["brick"],
    )


# --------------------------------------------------------------------------------------------
# a volume generated block by block (never materialised): tests and benchmarks
# --------------------------------------------------------------------------------------------
def _ramp_block(block_info=None, out_dtype="uint8"):
    (z0, z1), (y0, y1), (x0, x1) = block_info[None]["array-location"]
    u8 = np.uint8
    x = (np.arange(x0, x1) % 256).astype(u8)
    y = ((2 * np.arange(y0, y1)) % 256).astype(u8)
    z = ((3 * np.arange(z0, z1)) % 256).astype(u8)
    plane = y[:, None] + x[None, :]  # uint8 arithmetic wraps: mod 256
    out = np.empty((z1 - z0, y1 - y0, x1 - x0), u8)
    np.add(plane[None], z[:, None, None], out=out)
    return out if np.dtype(out_dtype) == u8 else out.astype(out_dtype)


def ramp_volume(shape_xyz, chunks=(64, 1024, 1024), dtype="uint8"):
    """A lazy volume ``v(x, y, z) = (x + 2y + 3z) mod 256``, generated chunk by chunk.

    Nothing is stored: each task makes its block from its position, so a volume far larger
    than memory costs one block per running task.  :func:`ramp_count` is its exact oracle.

    Examples
    --------
    >>> v = ramp_volume((4, 3, 2), chunks=(1, 2, 3))
    >>> v.compute()[1, 2].tolist()
    [7, 8, 9, 10]
    """
    import dask.array as da

    nx, ny, nz = (int(n) for n in shape_xyz)
    ch = da.core.normalize_chunks(tuple(chunks), (nz, ny, nx))
    dt = np.dtype(dtype)
    return da.map_blocks(_ramp_block, dtype=dt, chunks=ch, meta=np.empty((0, 0, 0), dt),
                         name="ramp-" + _token(nx, ny, nz, ch, dt.str), out_dtype=dt.str)


def ramp_count(shape_xyz, lo: int, hi: int) -> int:
    """Exact number of voxels of :func:`ramp_volume` with ``lo <= v <= hi`` (0..255).

    Examples
    --------
    >>> v = ramp_volume((300, 5, 7), chunks=(7, 5, 300))
    >>> ramp_count((300, 5, 7), 10, 99) == int(((v >= 10) & (v <= 99)).sum().compute())
    True
    """
    nx, ny, nz = (int(n) for n in shape_xyz)
    lo, hi = max(0, int(lo)), min(255, int(hi))
    if lo > hi:
        return 0
    # rows (y, z) by their offset c = (2y + 3z) mod 256: counted with a 256-bin histogram
    cy = np.bincount((2 * np.arange(ny)) % 256, minlength=256).astype(np.int64)
    cz = np.bincount((3 * np.arange(nz)) % 256, minlength=256).astype(np.int64)
    rows = np.zeros(256, np.int64)
    for s in range(256):  # 256 residues, not voxels
        rows[(s + np.arange(256)) % 256] += cz[s] * cy
    # selected x of a row with offset c: full periods plus the remainder
    full, rest = divmod(nx, 256)
    v = (np.arange(256)[:, None] + np.arange(256)[None, :]) % 256  # (c, x mod 256)
    insel = (v >= lo) & (v <= hi)
    per_row = full * insel.sum(axis=1) + insel[:, :rest].sum(axis=1)
    return int((rows * per_row).sum())


__all__ = ["BLOCK_BYTES", "MemmapArray", "as_dask", "compute", "ramp_count", "ramp_volume",
           "selection_maps", "selection_maps_graph"]
