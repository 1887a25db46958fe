"""Chunk checksums of the zarr stores geoshade writes, and the reads that verify them.

A store written by :func:`geoshade.io.stores.ingest.ingest` or
:func:`geoshade.io.stores.zarr_io.write_zarr`
stores *every* chunk (zeros too) and keeps, in each array's attributes, a checksum record::

    "checksums": {"algorithm": "crc32", "of": "chunk values, C order, little-endian",
                  "shape": [nz, ny, nx], "dtype": "uint16", "chunks": [cz, cy, cx],
                  "crc32": [...]}          # one per chunk, the chunk grid in C order

(the CRC-32 of a chunk's decoded values, clipped to the array at its edges, as the ingest
already computes per slab for resuming).  :class:`StoreArray` reads such an array chunk by chunk
and checks each chunk it touches: a missing chunk, a chunk that does not decode, or one whose
values do not match its CRC is a :class:`DamagedStoreError` naming the store and the chunk —
never zeros, never a traceback.  Reading costs one ``stat`` and one CRC-32 per chunk (CRC-32 runs
at several GB/s, faster than the zstd that decodes the chunk).

Stores geoshade did not write (no record) are read by the zarr rule: a chunk that is not stored
holds the array's fill value (zarr writers skip empty chunks, so geoshade cannot tell a lost chunk
from an empty one there); their decoding errors are still one line naming the chunk.
"""

from __future__ import annotations

import math
import os
import stat
import threading
import zlib
from itertools import product
from pathlib import Path
from typing import Any

import numpy as np

from geoshade.errors import InputError
from geoshade.io.paths import one_line

#: attribute of an array holding its checksum record
CHECKSUM_ATTR = "checksums"
#: the one algorithm written and read
ALGORITHM = "crc32"
#: the ``checksums`` attribute of an array an ingest is still writing
PENDING = "pending"


class DamagedStoreError(InputError):
    """A zarr store's chunk or metadata is missing, undecodable or does not match its checksum."""


def value_crc(block: np.ndarray) -> int:
    """CRC-32 of an array's values in C order, little-endian.

    Examples
    --------
    >>> value_crc(np.array([1, 2], "<u2")) == value_crc(np.array([1, 2], ">u2"))
    True
    """
    a = np.ascontiguousarray(block, dtype=np.asarray(block).dtype.newbyteorder("<"))
    return zlib.crc32(a.reshape(-1).view(np.uint8).data)


def chunk_crcs(slab: np.ndarray, chunks_yx) -> list[int]:
    """CRC-32 of each chunk of a slab that is one chunk row deep: ``(iy, ix)`` in C order.

    Examples
    --------
    >>> len(chunk_crcs(np.zeros((2, 5, 4), np.uint8), (2, 2)))
    6
    """
    cy, cx = (int(c) for c in chunks_yx)
    _, ny, nx = slab.shape
    return [value_crc(slab[:, y : y + cy, x : x + cx])
            for y in range(0, ny, cy) for x in range(0, nx, cx)]


def grid_shape(shape, chunks) -> tuple[int, ...]:
    """Chunks along each axis.

    >>> grid_shape((5, 4, 3), (2, 4, 4))
    (3, 1, 1)
    """
    return tuple(-(-int(n) // int(c)) for n, c in zip(shape, chunks, strict=True))


def checksum_record(shape, dtype, chunks, crcs) -> dict:
    """The ``checksums`` attribute of an array (see the module's docstring).

    >>> checksum_record((2, 2, 2), "uint8", (2, 2, 2), [7])["crc32"]
    [7]
    """
    crcs = [int(c) for c in crcs]
    n = math.prod(grid_shape(shape, chunks))
    if len(crcs) != n:
        raise ValueError(f"checksum record: {len(crcs)} CRCs for {n} chunks")
    return {"algorithm": ALGORITHM, "of": "chunk values, C order, little-endian",
            "shape": [int(v) for v in shape], "dtype": np.dtype(dtype).name,
            "chunks": [int(v) for v in chunks], "crc32": crcs}


def check_record(arr, store, where: str) -> list[int] | None:
    """The CRCs of ``arr``'s checksum record after checking that the array's metadata are the
    ones geoshade wrote (the cheap check at open); None for an array without a record.

    Raises
    ------
    DamagedStoreError
        The record is malformed, or the array's shape, dtype or chunks differ from it (its
        ``zarr.json`` was edited or damaged).
    """
    rec = dict(arr.attrs).get(CHECKSUM_ATTR)
    if rec is None:
        return None
    pre = f"{store}: array {where or '/'}"
    if rec == PENDING:
        raise InputError(f"{pre}: incomplete store (an ingest is still writing this array, or "
                         "was interrupted); run the same 'geoshade core ingest' again to finish it")
    try:
        if rec.get("algorithm") != ALGORITHM:
            raise DamagedStoreError(f"{pre}: checksum algorithm {rec.get('algorithm')!r}; "
                                    f"expected {ALGORITHM!r}")
        wrote = (tuple(int(v) for v in rec["shape"]), np.dtype(rec["dtype"]).name,
                 tuple(int(v) for v in rec["chunks"]))
        crcs = [int(c) for c in rec["crc32"]]
    except DamagedStoreError:
        raise
    except (AttributeError, KeyError, TypeError, ValueError) as err:
        raise DamagedStoreError(f"{pre}: damaged checksum record ({one_line(err)})") from None
    has = (tuple(int(v) for v in arr.shape), np.dtype(arr.dtype).name,
           tuple(int(v) for v in arr.chunks))
    if has != wrote:
        def desc(t):
            return f"shape {list(t[0])} {t[1]} chunks {list(t[2])}"

        raise DamagedStoreError(
            f"{pre}: its zarr.json says {desc(has)} but geoshade wrote {desc(wrote)}; the "
            "metadata were changed or damaged")
    if len(crcs) != math.prod(grid_shape(wrote[0], wrote[2])):
        raise DamagedStoreError(f"{pre}: damaged checksum record ({len(crcs)} CRCs for "
                                f"{math.prod(grid_shape(wrote[0], wrote[2]))} chunks)")
    return crcs


def _index(key, shape) -> tuple[list, list, list]:
    """Per axis: (lo, hi) of the region a key touches, the key relative to it, squeezed axes."""
    key = key if isinstance(key, tuple) else (key,)
    if any(k is Ellipsis for k in key):
        i = next(i for i, k in enumerate(key) if k is Ellipsis)
        key = key[:i] + (slice(None),) * (len(shape) - len(key) + 1) + key[i + 1:]
    key = key + (slice(None),) * (len(shape) - len(key))
    if len(key) != len(shape):
        raise IndexError(f"too many indices for an array of {len(shape)} dimensions")
    bounds: list[tuple[int, int]] = []
    rel: list[Any] = []
    squeeze: list[int] = []
    for axis, (k, n) in enumerate(zip(key, shape, strict=True)):
        if isinstance(k, (int, np.integer)):
            i = int(k) + (n if k < 0 else 0)
            if not 0 <= i < n:
                raise IndexError(f"index {k} is out of bounds for axis {axis} with size {n}")
            bounds.append((i, i + 1))
            rel.append(slice(0, 1))
            squeeze.append(axis)
        elif isinstance(k, slice) and k.indices(n)[2] == 1:
            start, stop, _ = k.indices(n)
            stop = max(start, stop)
            bounds.append((start, stop))
            rel.append(slice(0, stop - start))
        else:
            ind = np.arange(n)[k] if isinstance(k, slice) else np.asarray(k)
            if ind.dtype == bool:
                ind = np.nonzero(ind)[0]
            ind = np.where(ind < 0, ind + n, ind).astype(np.intp).reshape(-1)
            lo, hi = (int(ind.min()), int(ind.max()) + 1) if ind.size else (0, 0)
            bounds.append((lo, hi))
            rel.append(ind - lo)
    return bounds, rel, squeeze


class StoreArray:
    """A read-only, picklable view of one array of a zarr store on disk that checks every chunk
    it reads (see the module's docstring); dask reads it block by block (:meth:`as_dask`).

    Parameters
    ----------
    root : path
        The store's folder (what ``zarr.open`` opened).
    path : str
        The array inside it (``"0"``; ``""`` for a store that is one array).
    label : str
        The store as the user named it, for messages.
    crcs : list of int, optional
        The chunks' CRC-32s (from :func:`check_record`): every chunk must exist and match.

    Examples
    --------
    >>> import tempfile, os, zarr
    >>> d = os.path.join(tempfile.mkdtemp(), "a.zarr")
    >>> z = zarr.open_array(d, mode="w", shape=(4, 4, 4), chunks=(2, 4, 4), dtype="u1")
    >>> z[:] = 7
    >>> a = StoreArray(d, "", "a.zarr")
    >>> a.shape, int(a[3, 2, 1]), a[1:3, 0, :2].tolist()
    ((4, 4, 4), 7, [[7, 7], [7, 7]])
    >>> os.remove(os.path.join(d, "c", "1", "0", "0"))
    >>> StoreArray(d, "", "a.zarr", crcs=[value_crc(np.full((2, 4, 4), 7, "u1"))] * 2)[2, 0, 0]
    Traceback (most recent call last):
    ...
    geoshade.io.stores.chunks.DamagedStoreError: a.zarr: chunk c/1/0/0 is missing; ...
    """

    def __init__(self, root, path: str, label: str, crcs: list[int] | None = None, arr=None):
        self.root, self.path, self.label = str(root), str(path).strip("/"), str(label)
        self.crcs = crcs
        self._arr = arr
        self._pid = os.getpid() if arr is not None else None
        self._lock = threading.Lock()
        self._plain: bool | None = None
        a = self._array()
        self.shape = tuple(int(n) for n in a.shape)
        self.dtype = np.dtype(a.dtype)
        self.ndim = len(self.shape)
        # the unit read from disk: a shard of a sharded (foreign) array, else a chunk
        self.chunks = tuple(int(c) for c in (getattr(a, "shards", None) or a.chunks))
        self.grid = grid_shape(self.shape, self.chunks)

    def _array(self):
        if self._arr is None or self._pid != os.getpid():
            import zarr

            with self._lock:
                try:
                    self._arr = zarr.open_array(store=self.root, path=self.path, mode="r")
                except Exception as err:
                    raise DamagedStoreError(f"{self.label}: array {self.path or '/'} cannot be "
                                            f"opened ({one_line(err)})") from None
                self._pid = os.getpid()
        return self._arr

    def __getstate__(self) -> dict:
        return {**self.__dict__, "_arr": None, "_pid": None, "_lock": None}

    def __setstate__(self, state: dict) -> None:
        self.__dict__.update(state)
        self._lock = threading.Lock()

    def __repr__(self) -> str:
        return (f"StoreArray({self.label!r}, {self.path!r}, shape={self.shape}, "
                f"dtype={self.dtype}, verified={self.crcs is not None})")

    def chunk_name(self, coords) -> str:
        """``0/c/1/0/2``: the chunk's key inside the store."""
        key = self._array().metadata.encode_chunk_key(tuple(int(c) for c in coords))
        return f"{self.path}/{key}" if self.path else key

    def chunk_file(self, coords) -> Path:
        return Path(self.root) / self.chunk_name(coords)

    def chunk(self, coords) -> np.ndarray:
        """The decoded, checked values of chunk ``coords`` (clipped at the array's edges)."""
        coords = tuple(int(c) for c in coords)
        verified = self.crcs is not None
        try:
            mode: int | None = os.stat(self.chunk_file(coords)).st_mode
        except (FileNotFoundError, NotADirectoryError):
            mode = None
        except OSError as err:
            raise DamagedStoreError(f"{self.label}: chunk {self.chunk_name(coords)} cannot be "
                                    f"read ({one_line(err)})") from None
        if mode is None and verified:
            raise DamagedStoreError(
                f"{self.label}: chunk {self.chunk_name(coords)} is missing; geoshade stores every "
                "chunk, so the store is damaged (it would read as zeros): ingest it again")
        if mode is not None and not stat.S_ISREG(mode):  # a folder, or a FIFO that would block
            raise DamagedStoreError(f"{self.label}: chunk {self.chunk_name(coords)} is not a "
                                    "regular file; the store is damaged")
        sl = tuple(slice(i * c, min(n, (i + 1) * c))
                   for i, c, n in zip(coords, self.chunks, self.shape, strict=True))
        try:
            block = (self._decoded(coords, sl) if mode is not None and self._direct()
                     else np.asarray(self._array()[sl]))
        except MemoryError:
            raise
        except Exception as err:  # codecs raise many types: one line naming the chunk
            raise DamagedStoreError(f"{self.label}: chunk {self.chunk_name(coords)} is damaged "
                                    f"({one_line(err)})") from None
        want = tuple(s.stop - s.start for s in sl)
        if block.shape != want:
            raise DamagedStoreError(f"{self.label}: chunk {self.chunk_name(coords)} is damaged "
                                    f"(decoded shape {block.shape}, expected {want})")
        if verified:
            flat = int(np.ravel_multi_index(coords, self.grid))
            if value_crc(block) != self.crcs[flat]:  # type: ignore[index]
                raise DamagedStoreError(
                    f"{self.label}: chunk {self.chunk_name(coords)} is damaged (its values do "
                    "not match the CRC-32 recorded when it was written)")
        return block

    def _direct(self) -> bool:
        """Whether a chunk file is decoded here (read, blosc, ``frombuffer``) instead of through
        zarr's codec pipeline: a zarr v3 array of plain chunks (no shards) whose codecs are
        exactly ``bytes`` (little-endian) then ``blosc`` — what geoshade writes.  zarr's
        pipeline costs ~3 ms a chunk of 8 MB beyond the decompression (issue 34)."""
        if self._plain is None:
            a = self._array()
            m = a.metadata
            codecs = [type(c).__name__ for c in getattr(m, "codecs", ())]
            endian = getattr(getattr(m, "codecs", [None])[0], "endian", None)
            self._plain = (getattr(m, "zarr_format", 2) == 3 and a.shards is None
                           and codecs == ["BytesCodec", "BloscCodec"]
                           and getattr(endian, "value", endian) in ("little", None)
                           and self.dtype.byteorder in ("<", "=", "|"))
        return bool(self._plain)

    def _decoded(self, coords, sl) -> np.ndarray:
        """Chunk ``coords`` decoded from its file (see :meth:`_direct`), clipped to ``sl``."""
        from numcodecs import blosc

        block = np.empty(self.chunks, self.dtype)
        with open(self.chunk_file(coords), "rb") as fh:
            data = fh.read()
        size = int.from_bytes(data[4:8], "little") if len(data) >= 16 else -1  # blosc header
        if size != block.nbytes:
            raise ValueError(f"blosc frame of {size} B, expected {block.nbytes} B")
        blosc.decompress(data, block)
        edge = tuple(slice(0, s.stop - s.start) for s in sl)
        return block if block.shape == tuple(e.stop for e in edge) else \
            np.ascontiguousarray(block[edge])

    def chunk_coords(self):
        """Every chunk's coordinates, in C order."""
        return product(*(range(g) for g in self.grid))

    def __getitem__(self, key) -> Any:
        bounds, rel, squeeze = _index(key, self.shape)
        region = self._region(bounds)
        sl = tuple(r if isinstance(r, slice) else slice(None) for r in rel)
        out = region[sl]
        for axis, r in enumerate(rel):
            if not isinstance(r, slice):
                out = np.take(out, r, axis=axis)
        return out.reshape([n for a, n in enumerate(out.shape) if a not in squeeze]) \
            if squeeze else out

    def _region(self, bounds) -> np.ndarray:
        size = tuple(hi - lo for lo, hi in bounds)
        if min(size, default=1) <= 0:
            return np.empty(size, self.dtype)
        first = [lo // c for (lo, _), c in zip(bounds, self.chunks, strict=True)]
        last = [(hi - 1) // c for (_, hi), c in zip(bounds, self.chunks, strict=True)]
        out = None
        for coords in product(*(range(a, b + 1) for a, b in zip(first, last, strict=True))):
            block = self.chunk(coords)
            start = [i * c for i, c in zip(coords, self.chunks, strict=True)]
            whole = all(s == lo and s + n == hi for s, n, (lo, hi)
                        in zip(start, block.shape, bounds, strict=True))
            if whole:
                return block
            if out is None:
                out = np.empty(size, self.dtype)
            src, dst = [], []
            for s, n, (lo, hi) in zip(start, block.shape, bounds, strict=True):
                a, b = max(s, lo), min(s + n, hi)
                src.append(slice(a - s, b - s))
                dst.append(slice(a - lo, b - lo))
            out[tuple(dst)] = block[tuple(src)]
        assert out is not None
        return out

    def as_dask(self):
        """A dask array over this view, one block per chunk."""
        import dask.array as da
        from dask.base import tokenize

        meta_file = Path(self.root) / self.path / "zarr.json"
        if not meta_file.exists():
            meta_file = Path(self.root) / self.path / ".zarray"
        try:
            mtime = meta_file.stat().st_mtime_ns
        except OSError:
            mtime = 0
        token = tokenize(os.path.abspath(self.root), self.path, mtime, self.shape, self.dtype.str,
                         self.chunks, self.crcs is not None)
        return da.from_array(self, chunks=self.chunks, asarray=True, fancy=False, lock=False,
                             name=f"zarr-{token}", meta=np.empty((0,) * self.ndim, self.dtype))
