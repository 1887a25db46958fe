"""A volume in a file read block by block with plain reads, never mapped: what the memory plan's
``bricks`` route draws a raw or ``.npy`` volume from when mapping the whole file would not fit
the address space (``ulimit -v``) or the memory.

A mapped file costs no memory until it is read, but its whole length counts against
``RLIMIT_AS``, and every page read stays resident until the kernel needs it; reading each
block with ``os.pread`` holds only the block.  :class:`FileBlocks` is picklable (a cluster's
workers read their blocks themselves).

>>> import numpy as np, tempfile, os
>>> f = os.path.join(tempfile.mkdtemp(), "v.raw")
>>> a = np.arange(4 * 5 * 6, dtype="<u2").reshape(4, 5, 6)
>>> a.tofile(f)
>>> b = FileBlocks(f, "<u2", 0, (4, 5, 6))
>>> bool((b[1:3, 2:5, 1:4] == a[1:3, 2:5, 1:4]).all()), b[3, 4, 5]
(True, np.uint16(119))
"""

from __future__ import annotations

import dataclasses
import math
import os

import numpy as np

from geoshade.errors import InputError
from geoshade.models import VoxelVolume

#: voxels per block of the dask array over a file (about 16 MiB of uint8)
BLOCK_SHAPE = (64, 256, 1024)


class FileBlocks:
    """A C-ordered ``(nz, ny, nx)`` array stored in ``filename`` at ``offset``, read per
    request: each z-plane's rows ``y0:y1`` are one ``os.pread``."""

    def __init__(self, filename, dtype, offset: int, shape):
        self.filename, self.dtype = str(filename), np.dtype(dtype)
        self.offset, self.shape = int(offset), tuple(int(n) for n in shape)
        self.ndim = 3

    def __getitem__(self, key) -> np.ndarray:
        key = key if isinstance(key, tuple) else (key,)
        key = key + (slice(None),) * (3 - len(key))
        _, ny, nx = self.shape
        picks, drop = [], []
        for k, n in zip(key, self.shape, strict=True):
            if isinstance(k, int | np.integer):
                i = int(k) + (n if k < 0 else 0)
                picks.append((i, i + 1, 1))
                drop.append(True)
            else:
                picks.append(k.indices(n))
                drop.append(False)
        (z0, z1, zs), (y0, y1, ys), (x0, x1, xs) = picks
        zr = range(z0, z1, zs)
        rows = max(0, y1 - y0)
        item = self.dtype.itemsize
        out = np.empty((len(zr), rows, nx), self.dtype)
        with open(self.filename, "rb") as fh:
            fd = fh.fileno()
            for n, z in enumerate(zr):
                start = self.offset + ((z * ny) + y0) * nx * item
                want = rows * nx * item
                buf = os.pread(fd, want, start)
                if len(buf) != want:
                    raise InputError(f"{self.filename}: the file shrank while it was read "
                                     f"(plane {z} is cut); read it again once it is complete")
                out[n] = np.frombuffer(buf, self.dtype).reshape(rows, nx)
        a = out[:, ::ys, x0:x1:xs]
        index = tuple(0 if d else slice(None) for d in drop)
        return a[index]


def unmapped(volume: VoxelVolume) -> VoxelVolume:
    """``volume`` (whose data is a ``numpy.memmap`` of a raw or ``.npy`` file) with its data a
    dask array over :class:`FileBlocks` of the same file: nothing mapped, read block by block.
    Any other volume is returned as it is."""
    import dask.array as da

    a = volume.data
    if not isinstance(a, np.memmap) or getattr(a, "filename", None) is None or \
            not a.flags.c_contiguous or a.ndim != 3:
        return volume
    src = FileBlocks(a.filename, a.dtype, int(a.offset), a.shape)
    chunks = tuple(min(c, n) for c, n in zip(BLOCK_SHAPE, a.shape, strict=True))
    name = f"fileblocks-{abs(hash((src.filename, src.offset, src.shape, src.dtype.str)))}"
    data = da.from_array(src, chunks=chunks, asarray=True, fancy=False, lock=False, name=name)
    meta = {**volume.meta, "storage": "blocks (read, not mapped)"}
    return dataclasses.replace(volume, data=data, meta=meta)


def block_bytes(dtype) -> int:
    """Bytes of one block of :data:`BLOCK_SHAPE`."""
    return math.prod(BLOCK_SHAPE) * np.dtype(dtype).itemsize


__all__ = ["BLOCK_SHAPE", "FileBlocks", "block_bytes", "unmapped"]
