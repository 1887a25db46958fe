"""Ingest a volume into a chunked, multiscale zarr v3 store, with bounded memory and resumably.

``ingest(INPUT, CORE.zarr)`` reads a folder of TIFF slices, a multi-page TIFF, a raw file
(``shape``/``dtype`` hints) or an HDF5 dataset and writes::

    CORE.zarr/                  zarr v3 group, an OME-Zarr (NGFF 0.5) multiscale image
      zarr.json                 attributes: spacing, unit, origin, value_range, axes,
                                ome {version: 0.5, multiscales} (geoshade.io.stores.ome_zarr),
                                ingest {complete: true, ...}
      0/                        level 0: the full-resolution (nz, ny, nx) array, chunked
      1/, 2/, ...               level k: each axis halved from level k-1 (ceil), same chunks

Memory is bounded: the input is streamed in *slabs* of whole chunk rows (``cz`` slices along z),
so at most ``workers`` slabs of ``cz × ny × nx`` values are in memory, whatever the depth of the
volume.  Level k is made from level k-1 read back from the store, slab by slab.

Resumable and never half-presented:

- the store is written under ``CORE.zarr.partial`` and renamed to ``CORE.zarr`` only when every
  slab of every level is written and ``ingest.complete`` is set (``read_zarr`` refuses a store
  whose ``ingest.complete`` is false);
- after each slab, ``CORE.zarr.partial.progress.json`` (written atomically) records it with
  the CRC-32 of its values; running the same ingest again skips the recorded slabs (it checks that
  the input and the settings are unchanged, and re-reads the last recorded slabs to verify their
  CRC; ``verify=True`` re-reads them all);
- a full disk (``ENOSPC``/``EDQUOT``) stops the ingest with one line; the partial store stays
  marked incomplete, for resuming once space is freed.

Zarr writes each chunk file atomically (a temporary file renamed into place), so an interrupted
slab leaves whole old or whole new chunks; the slab is simply written again on resume.

Damage is never silent (issue 12): every chunk is stored, zeros too, and each level keeps the
CRC-32 of every chunk (computed with the slab's CRC, kept in the progress file, written into the
level's attributes at the end; :mod:`geoshade.io.stores.chunks`), so reading refuses a missing or
damaged chunk.  One ingest at a time per store: ``CORE.zarr.lock``
(:mod:`geoshade.io.stores.ingest_lock`)
makes a second one stop at once with ``another ingest is writing CORE.zarr (pid N)``, touching
nothing; a lock left by a dead process is taken over.  The memory of the slabs in flight is
checked against the available memory before the first one is read.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import math
import mmap
import shutil
import time
import warnings
import zlib
from concurrent.futures import FIRST_COMPLETED, ThreadPoolExecutor, wait
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from geoshade.errors import EXIT_DISK_FULL, GeoshadeError, InputError, require
from geoshade.io import formats, load
from geoshade.io.output import check_replace
from geoshade.io.paths import check_input, check_memory
from geoshade.io.stores.chunks import ALGORITHM, PENDING, checksum_record, chunk_crcs
from geoshade.io.stores.ingest_lock import IngestLock
from geoshade.io.stores.ome_zarr import multiscales_attrs
from geoshade.io.stores.partial_store import (
    _disk_error,
    _load_progress,
    _progress_path,
    _save_progress,
    publish,
    refuse_planted,
)
from geoshade.io.stores.zarr_io import is_zarr_store, read_level, store_levels  # noqa: F401  (re-exported)
from geoshade.models import VoxelVolume
from geoshade.progress import Progress
from geoshade.scheduler import Scheduler, checked, client_for, dask_get, live_workers

#: format version of the ``ingest`` attribute and the progress file
INGEST_VERSION = 2  # 2: every chunk stored, with its CRC-32 (issue 12)
#: default chunk shape (cz, cy, cx)
DEFAULT_CHUNKS = (128, 128, 128)
#: suffix of the folder an unfinished ingest writes into
PARTIAL_SUFFIX = ".partial"
#: automatic pyramid: halve until the largest side is at most this
COARSEST_SIDE = 256
#: downsampling methods of the pyramid
DOWNSAMPLE = ("nearest", "mean")


class DiskFullError(GeoshadeError, OSError):
    """The disk filled up while writing a store; the partial store is kept for resuming."""

    exit_code = EXIT_DISK_FULL


@dataclass
class IngestReport:
    """What :func:`ingest` did.

    path:           Path                 the finished store
    shape_xyz:      (nx, ny, nz)         level-0 voxels
    dtype:          str                  value type
    chunks:         (cz, cy, cx)         chunk shape of every level
    levels:         list of (nx, ny, nz) the pyramid, level 0 first
    value_range:    [min, max] or None   of the finite values
    slabs_written:  int                  slabs written in this run (all levels)
    slabs_skipped:  int                  slabs found complete from an earlier run
    seconds:        float                wall time of this run
    bytes_read:     int                  input bytes read in this run (level 0)
    """

    path: Path
    shape_xyz: tuple[int, int, int]
    dtype: str
    chunks: tuple[int, int, int]
    levels: list[tuple[int, int, int]]
    value_range: list | None
    slabs_written: int = 0
    slabs_skipped: int = 0
    seconds: float = 0.0
    bytes_read: int = 0
    resumed: bool = False
    notes: list[str] = field(default_factory=list)


# --------------------------------------------------------------------------------------------
# helpers
# --------------------------------------------------------------------------------------------
def _check_chunks(chunks) -> tuple[int, int, int]:
    try:
        c = tuple(int(v) for v in chunks)
    except (TypeError, ValueError):
        c = ()
    if len(c) != 3 or min(c) < 1:
        raise InputError(f"chunks: expected 3 positive integers (cz, cy, cx), got {chunks!r}")
    return c  # type: ignore[return-value]


def level_shapes(shape_zyx, levels: int | None = None) -> list[tuple[int, int, int]]:
    """Array shapes ``(nz, ny, nx)`` of the pyramid, level 0 first; each level halves (ceil).

    ``levels=None`` halves until the largest side is at most ``COARSEST_SIDE``.

    Examples
    --------
    >>> level_shapes((7360, 2600, 2600))[-1]
    (230, 82, 82)
    >>> level_shapes((5, 4, 3), levels=3)
    [(5, 4, 3), (3, 2, 2), (2, 1, 1)]
    >>> level_shapes((32, 32, 32), levels=40)
    Traceback (most recent call last):
    ...
    geoshade.errors.InputError: levels: expected 1..6 for 32×32×32 voxels (1 = no pyramid; ...
    """
    shape = tuple(int(n) for n in shape_zyx)
    if levels is None:
        levels = 1
        s = shape
        while max(s) > COARSEST_SIDE:
            s = tuple(-(-n // 2) for n in s)
            levels += 1
    levels = int(levels)
    most = 1 + max(0, math.ceil(math.log2(max(shape)))) if shape and max(shape) > 0 else 1
    if not 1 <= levels <= most:   # beyond `most` every level is one voxel again
        nz, ny, nx = shape
        raise InputError(f"levels: expected 1..{most} for {nx}×{ny}×{nz} voxels (1 = no "
                         f"pyramid; level {most - 1} is 1 voxel a side), got {levels}")
    out = [shape]
    for _ in range(levels - 1):
        out.append(tuple(-(-n // 2) for n in out[-1]))
    return out


def downsample2(block: np.ndarray, method: str = "nearest") -> np.ndarray:
    """Halve a ``(nz, ny, nx)`` block along each axis (odd sizes: the last voxel counts alone).

    ``nearest`` keeps voxel ``(2i, 2j, 2k)`` (the values stay values of the scan, so a range
    selects the same phases at every level); ``mean`` averages each 2×2×2 group (integers
    rounded half up; odd edges padded by repetition).

    Examples
    --------
    >>> a = np.arange(8, dtype=np.uint8).reshape(2, 2, 2)
    >>> downsample2(a).tolist(), downsample2(a, "mean").tolist()
    ([[[0]]], [[[4]]])
    """
    a = np.asarray(block)
    if method == "nearest":
        return np.ascontiguousarray(a[::2, ::2, ::2])
    if method != "mean":
        raise InputError(f"downsample: expected one of {', '.join(DOWNSAMPLE)}, got {method!r}")
    pad = [(0, n % 2) for n in a.shape]
    if any(p[1] for p in pad):
        a = np.pad(a, pad, mode="edge")
    nz, ny, nx = a.shape
    v = a.reshape(nz // 2, 2, ny // 2, 2, nx // 2, 2)
    if a.dtype.kind in "ui":
        s = v.sum(axis=(1, 3, 5), dtype=np.int64)
        return ((s + 4) // 8).astype(a.dtype)
    return v.mean(axis=(1, 3, 5), dtype=np.float64).astype(a.dtype)


def _fingerprint(path: Path) -> str:
    """A hash of the input's file names, sizes and modification times."""
    h = hashlib.sha1()
    files = sorted(p for p in path.rglob("*") if p.is_file()) if path.is_dir() else [path]
    for f in files:
        st = f.stat()
        h.update(f"{f.relative_to(path) if path.is_dir() else f.name}|{st.st_size}|"
                 f"{st.st_mtime_ns}\n".encode())
    return h.hexdigest()


def _open_source(input_path, hints: dict) -> VoxelVolume:
    """The input as a lazy/memory-mapped :class:`VoxelVolume` (never read whole): a kind of file
    the format table says ``core ingest`` takes."""
    p = Path(input_path)
    fmt = formats.ingested_by(p, "core")
    given = {k: v for k, v in hints.items() if v is not None}
    if fmt.name in ("tiff", "tiff-folder"):
        given["lazy"] = True  # read page by page, slice by slice
    return load(p, **given)


_SOURCES: dict[str, VoxelVolume] = {}


def _source(spec: str) -> VoxelVolume:
    """The source volume for ``spec`` (JSON of path and hints), opened once per process."""
    vol = _SOURCES.get(spec)
    if vol is None:
        d = json.loads(spec)
        vol = _open_source(d["path"], d["hints"])
        _SOURCES[spec] = vol
    return vol


def _file_start(a: np.ndarray) -> int | None:
    """Byte offset in its file of a C-contiguous numpy memmap's first value (None: unknown)."""
    mm, fn = getattr(a, "_mmap", None), getattr(a, "filename", None)
    if mm is None or fn is None or not a.flags.c_contiguous:
        return None
    try:
        base = np.frombuffer(mm, np.uint8).ctypes.data
    except (TypeError, ValueError):
        return None
    return a.ctypes.data - base + (int(a.offset) - int(a.offset) % mmap.ALLOCATIONGRANULARITY)


def _read(data, sl) -> np.ndarray:
    """The z slab ``sl`` of ``data`` in memory.

    A raw file's memmap is read with a plain file read: pages of a mapping count in the
    process's resident memory until it is unmapped, so reading a whole core through it would
    look like (and, under memory pressure, act like) holding the core in memory.
    """
    if isinstance(data, np.memmap) and len(sl) == 1 and sl[0].step in (None, 1):
        start = _file_start(data)
        if start is not None:
            z0, z1, _ = sl[0].indices(data.shape[0])
            plane = math.prod(data.shape[1:])
            offset = start + z0 * plane * data.dtype.itemsize
            out = np.fromfile(data.filename, dtype=data.dtype, count=(z1 - z0) * plane,
                              offset=offset)
            if out.size != (z1 - z0) * plane:  # the file shrank since it was opened
                end = offset + (z1 - z0) * plane * data.dtype.itemsize
                raise InputError(f"{data.filename}: ended at byte {offset + out.nbytes:,} while "
                                 f"slices {z0}–{z1 - 1} were read, which end at byte {end:,}: "
                                 "the file was truncated or changed while it was read; ingest "
                                 "it again once it is complete")
            return out.reshape((z1 - z0, *data.shape[1:]))
    part = data[sl]
    if hasattr(part, "compute"):
        part = part.compute(scheduler=dask_get("synchronous"))
    return np.ascontiguousarray(np.asarray(part))


def _slab_stats(a: np.ndarray) -> dict:
    out: dict[str, Any] = {"crc": zlib.crc32(memoryview(a).cast("B"))}
    if a.dtype.kind == "f":
        fin = a[np.isfinite(a)]
        out["min"] = float(fin.min()) if fin.size else None
        out["max"] = float(fin.max()) if fin.size else None
    else:
        out["min"], out["max"] = int(a.min()), int(a.max())
    return out


def _write_slab(spec: str, store: str, level: int, index: int, cz: int, method: str) -> dict:
    """Task: write slab ``index`` of ``level``; returns its min, max, CRC and bytes read."""
    import zarr

    arr = zarr.open_array(store=store, path=str(level), mode="r+").with_config(
        {"write_empty_chunks": True})  # every chunk stored: a missing one is damage
    z0 = index * cz
    z1 = min(arr.shape[0], z0 + cz)
    if level == 0:
        src = _source(spec)
        slab = _read(src.data, (slice(z0, z1),))
        nbytes = slab.nbytes
        if slab.dtype != arr.dtype:
            slab = slab.astype(arr.dtype)
    else:  # read level - 1 in pieces of ~cz slices: memory ~ one level-0-sized slab
        prev = zarr.open_array(store=store, path=str(level - 1), mode="r")
        step = cz + cz % 2  # even, so that the pieces halve exactly like the whole
        stop = min(prev.shape[0], 2 * z1)
        slab = np.concatenate([downsample2(np.asarray(prev[a : min(stop, a + step)]), method)
                               for a in range(2 * z0, stop, step)])
        nbytes = 0
    arr[z0:z1] = slab
    return {**_slab_stats(slab), "chunks": chunk_crcs(slab, arr.chunks[1:]),
            "bytes": int(nbytes)}


def _slab_crc(store: str, level: int, index: int, cz: int) -> int:
    import zarr

    arr = zarr.open_array(store=store, path=str(level), mode="r")
    z0 = index * cz
    a = np.ascontiguousarray(arr[z0 : min(arr.shape[0], z0 + cz)])
    return zlib.crc32(memoryview(a).cast("B"))


# --------------------------------------------------------------------------------------------
# executors: inline, threads, or a dask.distributed client
# --------------------------------------------------------------------------------------------
class _Runner:
    """Runs slab tasks with at most ``workers`` in flight; yields (key, result) as they end."""

    def __init__(self, workers: int = 1, scheduler=None):
        self.workers = max(1, int(workers))
        self.client, self._own = None, False
        self.pool = None
        if Scheduler.parse(scheduler).is_cluster:
            self.client, self._own = client_for(scheduler)
            self.workers = max(1, len(live_workers(self.client)))
        elif self.workers > 1:
            self.pool = ThreadPoolExecutor(self.workers, thread_name_prefix="geoshade-ingest")

    def run(self, jobs):
        """``jobs``: iterable of (key, fn, args); yields (key, result) in completion order."""
        jobs = iter(jobs)
        if self.client is None and self.pool is None:
            for key, fn, args in jobs:
                yield key, fn(*args)
            return
        pending: dict = {}
        limit = self.workers * (2 if self.client is not None else 1)
        while True:
            while len(pending) < limit:
                nxt = next(jobs, None)
                if nxt is None:
                    break
                key, fn, args = nxt
                fut = (self.client.submit(fn, *args, pure=False) if self.client is not None
                       else self.pool.submit(fn, *args))
                pending[fut] = key
            if not pending:
                return
            if self.client is not None:
                dwait = require("distributed", "distributed", "a dask cluster").wait

                with self.client.as_current():  # wait() needs it; ours is not the default
                    done = dwait(list(pending), return_when="FIRST_COMPLETED").done
            else:
                done = wait(list(pending), return_when=FIRST_COMPLETED).done
            for fut in done:
                key = pending.pop(fut)
                try:
                    yield key, fut.result()
                except BaseException:
                    for other in pending:
                        other.cancel()
                    raise

    def close(self):
        if self.pool is not None:
            self.pool.shutdown(wait=True, cancel_futures=True)
        if self.client is not None and self._own:
            self.client.close()


# --------------------------------------------------------------------------------------------
# the ingest
# --------------------------------------------------------------------------------------------
def ingest(
    input,
    output_zarr,
    chunks=DEFAULT_CHUNKS,
    levels: int | None = None,
    progress: Progress | None = None,
    *,
    shape=None,
    dtype=None,
    endian: str | None = None,
    offset: int | None = None,
    dataset: str | None = None,
    spacing=None,
    unit: str | None = None,
    origin=None,
    downsample: str = "nearest",
    overwrite: bool = False,
    workers: int = 1,
    scheduler=None,
    verify: bool = False,
) -> IngestReport:
    """Write ``input`` into a chunked multiscale zarr v3 store at ``output_zarr``.

    Parameters
    ----------
    input : str or Path
        A folder of TIFF slices, a multi-page TIFF, a raw file (give ``shape`` and ``dtype``),
        an HDF5 file (``dataset`` if it holds several 3D datasets), or anything
        :func:`geoshade.load` reads.
    output_zarr : str or Path
        The store to create (conventionally ``*.zarr``).
    chunks : (cz, cy, cx)
        Chunk shape of every level (clipped to the level's shape).  Memory in use is about
        ``workers × cz × ny × nx`` values.
    levels : int, optional
        Number of pyramid levels including level 0 (1: none).  Default: halve until the largest
        side is at most ``COARSEST_SIDE`` (256).
    progress : callable(done, total), optional
        Called after each slab (all levels counted).
    shape, dtype, endian, offset : optional
        Raw-file hints (``shape`` is ``(NX, NY, NZ)``).
    dataset : str, optional
        HDF5 dataset path.
    spacing, unit, origin : optional
        Override what the input says (spacing and origin in x, y, z order).
    downsample : {"nearest", "mean"}
        How each pyramid level halves the one before.
    overwrite : bool
        Replace an existing complete store (and restart an unfinished one with other settings).
    workers : int
        Slabs written concurrently by threads (each holds one slab in memory).
    scheduler : Scheduler, str or distributed.Client, optional
        A cluster (address, ``"local:N"`` or client, see :func:`geoshade.scheduler.client_for`)
        writes the slabs as tasks (its workers must see ``input`` and ``output_zarr`` at the
        same paths); None or a local scheduler: this process's ``workers`` threads.
    verify : bool
        Re-read every slab found complete from an earlier run and compare its CRC-32.

    Returns
    -------
    IngestReport

    Raises
    ------
    InputError
        Bad input (what :func:`geoshade.load` finds), bad settings, an existing output, or an
        unfinished ingest of another input or other settings.
    DiskFullError
        The disk filled up (one line; the partial store is kept, marked incomplete).

    Examples
    --------
    >>> import numpy as np, tempfile, os
    >>> from geoshade.io.stores.zarr_io import read_zarr
    >>> d = tempfile.mkdtemp()
    >>> np.arange(6 * 5 * 4, dtype=np.uint16).reshape(6, 5, 4).tofile(os.path.join(d, "v.raw"))
    >>> rep = ingest(os.path.join(d, "v.raw"), os.path.join(d, "v.zarr"), chunks=(2, 4, 4),
    ...              levels=2, shape=(4, 5, 6), dtype="uint16", spacing=(0.5, 0.5, 0.5))
    >>> rep.levels, rep.value_range
    ([(4, 5, 6), (2, 3, 3)], [0, 119])
    >>> vol = read_zarr(rep.path)
    >>> int(vol.data[5, 4, 3]), vol.spacing
    (119, (0.5, 0.5, 0.5))
    """
    t0 = time.perf_counter()
    scheduler = checked(scheduler)   # one line before any work for what is no scheduler
    if downsample not in DOWNSAMPLE:
        raise InputError(f"downsample: expected one of {', '.join(DOWNSAMPLE)}, got "
                         f"{downsample!r}")
    src_path = Path(input)
    out = Path(output_zarr)
    check_input(src_path)
    if out.resolve() == src_path.resolve():
        raise InputError(f"{output_zarr}: the output would replace the input")
    check_replace(out, formats.case_files(src_path))   # an input's folder, a link, a device...
    if out.exists() and not overwrite:
        raise InputError(f"{output_zarr}: already exists; pass --overwrite (overwrite=True) to "
                         "replace it")
    hints = {"shape": None if shape is None else [int(v) for v in shape], "dtype": dtype,
             "endian": endian, "offset": offset, "dataset": dataset,
             "spacing": None if spacing is None else list(np.broadcast_to(
                 np.asarray(spacing, float), (3,))),
             "unit": unit, "origin": None if origin is None else list(np.broadcast_to(
                 np.asarray(origin, float), (3,)))}
    hints = {k: v for k, v in hints.items() if v is not None}
    vol = _open_source(src_path, hints)
    spec = json.dumps({"path": str(src_path.resolve()), "hints": hints}, sort_keys=True)
    _SOURCES[spec] = vol
    try:
        shapes = level_shapes(vol.data.shape, levels)
    except InputError as err:   # the input's name first
        raise InputError(f"{input}: {err}") from None
    ch = _check_chunks(chunks)
    dt = np.dtype(vol.dtype).newbyteorder("=")
    params = {
        "version": INGEST_VERSION, "input": str(src_path.resolve()),
        "fingerprint": _fingerprint(src_path), "hints": hints, "shape": list(shapes[0]),
        "dtype": dt.name, "chunks": list(ch), "levels": len(shapes), "downsample": downsample,
        "spacing": list(vol.spacing), "origin": list(vol.origin), "unit": vol.unit,
    }
    partial = out.with_name(out.name + PARTIAL_SUFFIX)
    refuse_planted(partial)
    if not Scheduler.parse(scheduler).is_cluster:  # on a cluster: in the workers' memory
        slab = shapes[0][1] * shapes[0][2] * min(ch[0], shapes[0][0]) * dt.itemsize
        check_memory(max(1, int(workers)) * slab, input, f"and writing {max(1, int(workers))} "
                     f"slab(s) of {min(ch[0], shapes[0][0])}×{shapes[0][1]}×{shapes[0][2]} "
                     f"{dt.name} at a time", "use smaller --chunks CZ or fewer --workers")
    made = [d for d in (out.parent, *out.parent.parents) if not d.exists()]
    out.parent.mkdir(parents=True, exist_ok=True)
    ok = False
    try:
        with IngestLock(out, str(src_path)) as lock:  # before anything is written
            fresh = not partial.exists()
            try:
                report = _ingest_locked(lock, t0, out, output_zarr, partial, params, shapes, ch,
                                        dt, vol, spec, downsample, workers, scheduler, overwrite,
                                        verify, progress)
            except GeoshadeError as err:  # a damaged input, bad settings: no resume to keep
                if fresh and not isinstance(err, DiskFullError):
                    shutil.rmtree(partial, ignore_errors=True)
                    _progress_path(partial).unlink(missing_ok=True)
                raise
        ok = True
        return report
    finally:
        if not ok:  # folders this run made for the output, if still empty
            for d in made:
                with contextlib.suppress(OSError):
                    d.rmdir()


def _ingest_locked(lock: IngestLock, t0, out: Path, output_zarr, partial: Path, params: dict,
                   shapes, ch, dt, vol: VoxelVolume, spec: str, downsample: str, workers,
                   scheduler, overwrite: bool, verify: bool, progress) -> IngestReport:
    if out.exists() and not overwrite:  # another ingest may have finished it meanwhile
        raise InputError(f"{output_zarr}: already exists; pass --overwrite (overwrite=True) to "
                         "replace it")
    need, free = estimate_bytes(shapes[0], dt, len(shapes)), shutil.disk_usage(out.parent).free
    if need > free:
        warnings.warn(f"{output_zarr}: the store needs up to {need / 2**30:.1f} GiB before "
                      f"compression and {free / 2**30:.1f} GiB are free; it fits only if the "
                      "data compress well", UserWarning, stacklevel=2)
    report = IngestReport(
        path=out, shape_xyz=vol.shape_xyz, dtype=dt.name, chunks=ch,
        levels=[(s[2], s[1], s[0]) for s in shapes], value_range=None)
    if vol.meta.get("assumed"):
        report.notes += [f"assumed {a}" for a in vol.meta["assumed"]]
    if lock.took_over:
        report.notes.append(f"took over the lock of an ingest that is no longer running (pid "
                            f"{lock.took_over.get('pid', '?')})")
    runner = _Runner(workers, scheduler)  # an unreachable scheduler fails before any write
    try:
        state = _prepare(partial, params, shapes, ch, dt, overwrite, report, verify)
        _run_levels(partial, spec, state, shapes, ch, downsample, runner, progress, report)
        _finish(partial, out, state, shapes, vol, report)
    except GeoshadeError:
        raise
    except BaseException as err:
        disk = _disk_error(err)
        if disk is None:
            raise
        done = sum(len(v) for v in (_load_progress(partial) or {}).get("done", {}).values())
        total = sum(-(-s[0] // min(ch[0], s[0])) for s in shapes)
        free = shutil.disk_usage(out.parent).free if out.parent.exists() else 0
        raise DiskFullError(
            f"{output_zarr}: disk full while writing the store ({disk.strerror or disk}); "
            f"{free / 2**30:.2f} GiB free on that disk. The unfinished store {partial.name} "
            f"({done} of {total} slabs done) is kept, marked incomplete: free space and run the "
            f"same ingest again to resume, or delete it") from None
    finally:
        runner.close()
    report.seconds = time.perf_counter() - t0
    return report


def _prepare(partial: Path, params: dict, shapes, ch, dt, overwrite: bool,
             report: IngestReport, verify: bool) -> dict:
    """Create the partial store, or reopen an unfinished one with the same settings."""
    import zarr

    if not partial.exists():
        _progress_path(partial).unlink(missing_ok=True)  # stale: its store was deleted
    state = _load_progress(partial) if partial.exists() else None
    if partial.exists() and state is None and _partial_complete(partial):
        return {"params": params, "done": {}, "finished": True}
    if state is not None and state.get("params") != params:
        if not overwrite:
            diff = sorted(k for k in params if state.get("params", {}).get(k) != params[k])
            raise InputError(
                f"{partial}: an unfinished ingest with another input or settings ({', '.join(diff)}"
                f" differ); pass --overwrite (overwrite=True) to start again")
        state = None
    if state is not None:
        report.resumed = True
        _verify_done(partial, state, shapes, ch, verify)
        report.slabs_skipped = sum(len(v) for v in state["done"].values())
        return state
    if partial.exists():
        shutil.rmtree(partial)
    g = zarr.open_group(str(partial), mode="w", zarr_format=3)
    g.attrs.update({"ingest": {"complete": False, "version": INGEST_VERSION,
                               "source": Path(params["input"]).name}})  # no user's folders
    for k, s in enumerate(shapes):
        g.create_array(str(k), shape=s, chunks=tuple(min(c, n) for c, n in zip(ch, s, strict=True)),
                       dtype=dt, fill_value=0, dimension_names=("z", "y", "x"),
                       config={"write_empty_chunks": True},
                       attributes={"checksums": PENDING})  # the record comes at the end
    state = {"params": params, "done": {str(k): {} for k in range(len(shapes))}}
    _save_progress(partial, state)
    return state


def _partial_complete(partial: Path) -> bool:
    try:
        meta = json.loads((partial / "zarr.json").read_text())
    except (OSError, json.JSONDecodeError):
        return False
    return bool(meta.get("attributes", {}).get("ingest", {}).get("complete"))


def _verify_done(partial: Path, state: dict, shapes, ch, everything: bool) -> None:
    """Drop recorded slabs whose data no longer match their CRC (the last ones, or all)."""
    for level, done in state["done"].items():
        cz = min(ch[0], shapes[int(level)][0])
        keys = sorted(done, key=int)
        check = keys if everything else keys[-2:]
        for key in check:
            if _slab_crc(str(partial), int(level), int(key), cz) != done[key]["crc"]:
                del done[key]


def _run_levels(partial: Path, spec: str, state: dict, shapes, ch, method: str,
                runner: _Runner, progress, report: IngestReport) -> None:
    if state.get("finished"):
        return
    counts = [-(-s[0] // min(ch[0], s[0])) for s in shapes]
    total = sum(counts)
    for level, n in enumerate(counts):  # level by level: k is made from k - 1
        cz = min(ch[0], shapes[level][0])
        done = state["done"].setdefault(str(level), {})
        todo = [i for i in range(n) if str(i) not in done]
        jobs = ((i, _write_slab, (spec, str(partial), level, i, cz, method)) for i in todo)
        for i, res in runner.run(jobs):
            report.bytes_read += res.pop("bytes")
            done[str(i)] = res
            report.slabs_written += 1
            _save_progress(partial, state)
            if progress is not None:
                progress(sum(len(v) for v in state["done"].values()), total)


def _finish(partial: Path, out: Path, state: dict, shapes, vol: VoxelVolume,
            report: IngestReport) -> None:
    import zarr

    g = zarr.open_group(str(partial), mode="r+")
    if not state.get("finished"):
        done0 = state["done"]["0"].values()
        mins = [d["min"] for d in done0 if d["min"] is not None]
        maxs = [d["max"] for d in done0 if d["max"] is not None]
        vr = [min(mins), max(maxs)] if mins else None
        for k in range(len(shapes)):
            a = g[str(k)]
            f = 2**k
            done = state["done"][str(k)]
            crcs = [c for i in sorted(done, key=int) for c in done[i]["chunks"]]
            a.attrs.update({"spacing": [s * f for s in vol.spacing], "origin": list(vol.origin),
                            "unit": vol.unit, "level": k, "axes": ["z", "y", "x"],
                            "checksums": checksum_record(a.shape, a.dtype, a.chunks, crcs)})
        name = Path(state["params"]["input"]).name
        g.attrs.update({
            "spacing": list(vol.spacing), "origin": list(vol.origin), "unit": vol.unit,
            "value_range": vr, "axes": ["z", "y", "x"],
            **multiscales_attrs(name, shapes, vol.spacing, vol.origin, vol.unit,
                                state["params"]["downsample"]),
            "ingest": {"complete": True, "version": INGEST_VERSION,
                       "source": name, "levels": len(shapes),  # the name, not its folders
                       "chunks": state["params"]["chunks"],
                       "downsample": state["params"]["downsample"],
                       "dtype": state["params"]["dtype"], "checksums": ALGORITHM,
                       "assumed": [str(a) for a in vol.meta.get("assumed", [])]},
        })
        _progress_path(partial).unlink(missing_ok=True)
    report.value_range = g.attrs.get("value_range")
    publish(partial, out)


# --------------------------------------------------------------------------------------------
# sizes (reading the pyramid back: geoshade.io.stores.zarr_io.read_level, store_levels)
# --------------------------------------------------------------------------------------------
def estimate_bytes(shape_zyx, dtype, levels: int | None = None) -> int:
    """Uncompressed bytes of a store with its pyramid (an upper bound before compression).

    Examples
    --------
    >>> estimate_bytes((100, 100, 100), "uint8", levels=2)
    1125000
    """
    itemsize = np.dtype(dtype).itemsize
    return int(sum(math.prod(s) for s in level_shapes(shape_zyx, levels)) * itemsize)

