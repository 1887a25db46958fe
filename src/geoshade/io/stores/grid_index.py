"""A grid store's index: what the first picture, a property or step switch, a filter and a slice
need, kept at ingest so that opening a store does not read ZCORN (issue 26, target 1).

Written by :func:`build_index` into the store's ``index`` group, before the store is presented
(:func:`geoshade.io.stores.grid_store.ingest_grid`'s finish step), or added to an existing store
by :func:`add_index` (``geoshade grid ingest --index-only STORE``: written beside as
``index.building``, then renamed, the attribute written last)::

    index/
      faces/cells    (n, 3) int32    cell of each visible face of the unfiltered grid (the
                                     active cells' faces: visible_faces_chunked, shown=None),
                                     in the drawing order (k-slab, face code, k, j, i)
      faces/face     (n,)   uint8    face code 0..5 (I+ J+ K+ I- J- K-)
      faces/flags    (n,)   uint8    bit 0: fault (the shared face does not match), bit 1: the
                                     cell across is active (neighbour_shown)
      faces/corners  (n, 4) float32  depths of the face's corners A, B, C, D
      faces/by_chunk (n,)   int64    face positions grouped by chunk of cells (C order of the
                                     chunk grid), drawing order inside a chunk
      faces/offsets  (nchunks + 1,) int64  chunk c's faces are by_chunk[offsets[c]:offsets[c+1]]
      nactive        (nchunks,) int64  active cells per chunk
      stats/<array>  (nt, nchunks, 3) float64  min, max, count of the active finite values of
                                     each chunk (nt = 1 for props/*, the steps for steps/*)
      cells          (m,) int64      the face cells' numbers i + nx (j + ny k), ascending
      values/<array> (nt, m)         each array's values at those cells (the face-cell value
                                     cache: a property or step switch reads one row)

The root attribute ``grid_index`` records the format version (:data:`INDEX_VERSION`), what
the index was computed from (dims, chunks, fault tolerance, arrays, steps, and the digest of the
store's arrays, :mod:`geoshade.io.stores.binding`), the face and cell counts, a CRC-32 of every
array's values and a seal of all that: :func:`open_index` checks them all and computes one
chunk again (its active count, statistics, face-cell values and, with ``check``, its faces), so
a partial, stale, damaged, edited index or one copied from another store is ignored with one
line (the store is then drawn as without one), never drawn wrong.  Memory while building: the
faces (as a chunked computation does) plus a batch of chunks of every cell array
(:data:`BATCH_BYTES`).  One writer at a time: ``--index-only`` holds the store's ingest lock
(:class:`~geoshade.io.stores.ingest_lock.IngestLock`).
"""

from __future__ import annotations

import json
import shutil
import time
import zlib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from geoshade.errors import InputError
from geoshade.io.output import atomic_write_bytes, publish
from geoshade.io.paths import one_line
from geoshade.io.stores.binding import sample_chunk, seal
from geoshade.io.stores.ingest_lock import IngestLock
from geoshade.progress import Progress
from geoshade.scheduler import dask_get

__all__ = ["ATTR", "INDEX_VERSION", "GridIndex", "IndexBuild", "add_index", "build_index",
           "open_index", "sample", "write_index"]

#: format version of the ``grid_index`` attribute and the ``index`` group
INDEX_VERSION = 1
#: the root attribute that describes the index
ATTR = "grid_index"
#: the index group inside the store
GROUP = "index"
#: fault tolerance of the stored faces (the View's faces use the same)
FAULT_TOL = 0.0
#: rows per zarr chunk of the index's arrays
ROWS = 1 << 22
#: the one line that says an index would help
NO_INDEX_NOTE = ("{store}: no index in this grid store; 'geoshade grid ingest --index-only "
                 "{store}' would make opening, property/step switches, filters and slices "
                 "faster")


def _crc(a: np.ndarray) -> int:
    b = np.ascontiguousarray(a, dtype=np.asarray(a).dtype.newbyteorder("<"))
    return zlib.crc32(b.reshape(-1).view(np.uint8).data)


def _keys(grid) -> list[str]:
    """The index's array keys for a store grid: ``props/NAME``, ``steps/KW`` (the store's
    own arrays, not those a ``--param`` added)."""
    own = grid.__dict__.get("_store_arrays")
    if own is not None:
        return sorted({k for k, _, _ in own})
    kws = list(grid.meta.get("step_keywords") or (grid.steps[0] if grid.steps else []))
    return sorted([f"props/{n}" for n in grid.properties] + [f"steps/{k}" for k in kws])


def _cell_chunks(grid) -> list[list[int]]:
    return [[int(c) // 2 for c in axis] for axis in grid.zcorn.chunks]


# --------------------------------------------------------------------------------------------
# building
# --------------------------------------------------------------------------------------------
@dataclass
class IndexBuild:
    """What :func:`build_index` wrote: faces, face cells, chunks, seconds, bytes on disk."""

    faces: int = 0
    cells: int = 0
    chunks: int = 0
    seconds: float = 0.0
    attrs: dict = field(default_factory=dict)


def write_index(grid, arrays: dict, out) -> IndexBuild:
    """Write the index ``arrays`` of a store grid (:func:`geoshade.compute.grid.index_faces.
    store_index`) as the zarr group ``out`` (``STORE/index``, or ``STORE/index.building``
    then renamed); its ``attrs`` are the ``grid_index`` attribute to record once the group is
    in place (with the CRC-32 of every array)."""
    import zarr
    from zarr.codecs import BloscCodec

    codec = BloscCodec(cname="zstd", clevel=3, shuffle="shuffle")
    root = zarr.open_group(str(out), mode="w", zarr_format=3)
    crcs: dict[str, object] = {}
    for name, a in arrays.items():
        a = np.ascontiguousarray(a)
        rows = name.startswith("values/")
        chunks = ((1, min(ROWS, max(1, a.shape[1]))) if rows
                  else (min(ROWS, max(1, a.shape[0])), *a.shape[1:]))
        arr = root.create_array(name, shape=a.shape, dtype=a.dtype, chunks=chunks,
                                compressors=codec)
        if a.size:
            arr[...] = a
        crcs[name] = [_crc(r) for r in a] if rows else _crc(a)
    nf, nc = len(arrays["faces/face"]), len(arrays["cells"])
    attrs = {"version": INDEX_VERSION, "complete": True, "dims": [int(v) for v in grid.dims],
             "chunks": _cell_chunks(grid), "fault_tol": FAULT_TOL, "faces": int(nf),
             "cells": int(nc), "nchunks": len(arrays["nactive"]), "arrays": _keys(grid),
             "steps": len(grid.steps), "crc32": crcs, "digest": _digest(grid)}
    attrs = json.loads(json.dumps(attrs))   # as the store gives it back
    attrs["seal"] = seal(attrs["digest"], ATTR, attrs)
    return IndexBuild(int(nf), int(nc), len(arrays["nactive"]), 0.0, attrs)


def _digest(grid) -> str:
    """The digest of the store's arrays the grid was opened from (binding.py)."""
    return str(grid.meta.get("digest", "")) if isinstance(grid.meta, dict) else ""


def build_index(grid, out, builder, progress: Progress | None = None) -> IndexBuild:
    """Compute (``builder(grid, progress)``: the arrays) and write a store grid's index."""
    t0 = time.perf_counter()
    built = write_index(grid, builder(grid, progress), out)
    built.seconds = time.perf_counter() - t0
    return built


def _write_attr(store: Path, value: dict | None) -> None:
    """Set (or, with None, remove) the ``grid_index`` attribute of the store's root
    ``zarr.json``, atomically (a temporary file renamed over it)."""
    meta_path = store / "zarr.json"
    meta = json.loads(meta_path.read_text())
    attrs = meta.setdefault("attributes", {})
    if value is None:
        attrs.pop(ATTR, None)
    else:
        attrs[ATTR] = value
    atomic_write_bytes(meta_path, json.dumps(meta, indent=2).encode())


def add_index(grid, builder, progress: Progress | None = None) -> IndexBuild:
    """Add (or rebuild) the index of an opened complete grid store (``geoshade grid ingest
    --index-only STORE``: :func:`~geoshade.io.stores.grid_store.open_grid_store` refuses what
    is not one, in one line): written beside as ``index.building``, the old one moved aside,
    the new one renamed in and the attribute written last; a failed run leaves the store as
    it was (and openable).

    Parameters
    ----------
    grid : CornerPointGrid
        The store, opened lazily (``grid.meta["store"]`` is its folder).
    builder : callable(grid, progress) -> dict
        Computes the arrays (:func:`geoshade.compute.grid.index_faces.store_index`).
    progress : callable(done, total), optional
    """
    p = Path(str(grid.meta.get("store", "")))
    if not (p / "zarr.json").is_file():
        raise InputError(f"{p}: not a geoshade grid store (no zarr.json); make one with "
                         "'geoshade grid ingest CASE -o STORE'")
    with IngestLock(p, task="grid ingest --index-only"):   # one writer of the store at a time
        attrs = json.loads((p / "zarr.json").read_text()).get("attributes", {})
        gs = attrs.get("grid_store") if isinstance(attrs.get("grid_store"), dict) else {}
        if gs.get("digest", _digest(grid)) != _digest(grid):
            raise InputError(f"{p}: the store was replaced after it was opened (another ingest "
                             "wrote it); run the same command again")
        building = p / (GROUP + ".building")
        shutil.rmtree(building, ignore_errors=True)
        before = attrs.get(ATTR)
        moved = False
        try:
            built = build_index(grid, building, builder, progress)
            _write_attr(p, None)  # no reader takes the old index while the folders change
            # the one atomic publish: the old index moved aside, the new renamed in, the old
            # removed after (a failed rename puts the old one back); inside the store opened
            publish(building, p / GROUP, checked=True)
            moved = True
            _write_attr(p, built.attrs)
        finally:
            shutil.rmtree(building, ignore_errors=True)
            if not moved:   # the index as it was, with its attribute
                _write_attr(p, before)
    return built


# --------------------------------------------------------------------------------------------
# reading
# --------------------------------------------------------------------------------------------
class DamagedIndexError(Exception):
    """An index array that does not match its record (read back as one line)."""


class GridIndex:
    """A checked grid store index (made by :func:`open_index`): reads its arrays on demand,
    each checked against its recorded CRC-32 (:class:`DamagedIndexError` when not)."""

    def __init__(self, store: Path, attrs: dict, grid):
        import zarr

        self.store, self.attrs = store, attrs
        self.root = zarr.open_group(str(store / GROUP), mode="r")
        self.dims = tuple(grid.dims)
        self.chunks = _cell_chunks(grid)
        self.nb = tuple(len(a) for a in self.chunks)
        self.nfaces, self.ncells = int(attrs["faces"]), int(attrs["cells"])
        self._cache: dict = {}

    def _read(self, name: str, row: int | None = None) -> np.ndarray:
        key = (name, row)
        if key in self._cache:
            return self._cache[key]
        a = self._reading(name, lambda arr: np.asarray(arr[...] if row is None else arr[row]))
        want = self.attrs["crc32"].get(name)
        if row is not None and isinstance(want, list):
            want = want[row] if row < len(want) else None
        if want is None or want != _crc(a):
            raise DamagedIndexError(f"{self.store}: index array {name} does not match its "
                                    "CRC-32 (damaged)")
        if name in ("faces/by_chunk", "faces/offsets", "nactive", "cells", "zbounds",
                    "orientation") or \
                name.startswith("stats/"):
            self._cache[key] = a  # small or used by every filter: kept
        return a

    def part(self, name: str, sel, row: int | None = None) -> np.ndarray:
        """Rows ``sel`` (a slice, or ascending positions) of index array ``name`` (at
        ``row`` of a per-step array), read from the chunks holding them: no whole read, so
        no CRC-32 check (the sample checks of :func:`open_index` compare what they read
        against the store; the whole-array reads that draw check it)."""
        whole = self._cache.get((name, row))
        if whole is not None:
            return whole[sel]
        if isinstance(sel, slice):
            return self._reading(name, lambda arr: np.asarray(arr[sel] if row is None
                                                              else arr[row, sel]))
        pos = np.asarray(sel, np.int64)
        lo, hi = (int(pos[0]), int(pos[-1]) + 1) if pos.size else (0, 0)
        # the span's chunks, then the rows
        block = self._reading(name, lambda arr: np.asarray(arr[lo:hi] if row is None
                                                           else arr[row, lo:hi]))
        return block[pos - lo]

    def _reading(self, name: str, read):
        """``read(array)`` of index array ``name``; what fails is one line naming the store
        and the array (:class:`DamagedIndexError`)."""
        try:
            return read(self.root[name])
        except Exception as err:
            raise DamagedIndexError(f"{self.store}: index array {name} cannot be read "
                                    f"({one_line(err)})") from None

    def array(self, name: str) -> np.ndarray:
        """A small array of the index by name (``zbounds``, ``orientation``), checked."""
        if name not in self.attrs["crc32"]:
            raise DamagedIndexError(f"{self.store}: the index has no {name}")
        return self._read(name)

    def faces(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``(cells, face, fault, neighbour_shown)`` of the unfiltered grid, drawing order."""
        flags = self._read("faces/flags")
        return (self._read("faces/cells"), self._read("faces/face"), (flags & 1) != 0,
                (flags & 2) != 0)

    def corners(self) -> np.ndarray:
        """``(n, 4)`` float32 corner depths of :meth:`faces`."""
        return self._read("faces/corners")

    def chunk_positions(self, c: int) -> np.ndarray:
        """Positions (in :meth:`faces`) of chunk ``c``'s faces (drawing order)."""
        off = self._read("faces/offsets")
        return self._read("faces/by_chunk")[off[c]:off[c + 1]]

    @property
    def nactive(self) -> np.ndarray:
        """(nchunks,) active cells per chunk."""
        return self._read("nactive")

    def stats(self, key: str, t: int | None) -> np.ndarray:
        """(nchunks, 3) min, max, count of the active finite values of ``key`` (at ``t``)."""
        return self._read(f"stats/{key}")[0 if t is None else int(t)]

    @property
    def cells(self) -> np.ndarray:
        """(m,) int64 face-cell numbers, ascending."""
        return self._read("cells")

    def values(self, key: str, t: int | None) -> np.ndarray:
        """(m,) values of ``key`` (at step ``t``) at :attr:`cells` (the face-cell cache)."""
        return self._read(f"values/{key}", 0 if t is None else int(t))


def open_index(grid, check=None) -> GridIndex | str:
    """The checked index of a store grid, or one line saying why it is not used (absent:
    :data:`NO_INDEX_NOTE`; stale, damaged, edited or made for other arrays: what does not
    match).

    Besides its records (format, dims, chunks, arrays, shapes, the arrays' digest and the seal,
    :mod:`geoshade.io.stores.binding`), one chunk of cells (:func:`~geoshade.io.stores.binding.
    sample_chunk`) is computed again: its active count, every own array's statistics and
    face-cell values there (one report step), and with ``check(grid, index, chunk) -> str``
    (:func:`geoshade.compute.grid.index_faces.sample_faces`: io computes no faces) its faces.

    Examples
    --------
    >>> import os, tempfile
    >>> from geoshade.compute.grid.synthetic import synthetic_grid
    >>> from geoshade.compute.grid.index_faces import store_index
    >>> from geoshade.io.stores.grid_store import ModelSource, open_grid_store, write_grid_store
    >>> d = tempfile.mkdtemp()
    >>> src = ModelSource(synthetic_grid(6, 5, 4, steps=2))
    >>> rep = write_grid_store(src, os.path.join(d, "g.zarr"), (4, 4, 2), index=store_index)
    >>> idx = open_index(open_grid_store(rep.path))
    >>> idx.nfaces == rep.index.faces, idx.values("steps/SWAT", 1).shape == (idx.ncells,)
    (True, True)
    >>> old = write_grid_store(src, os.path.join(d, "old.zarr"), (4, 4, 2))
    >>> "--index-only" in open_index(open_grid_store(old.path))
    True
    """
    store = Path(str(grid.meta.get("store", "")))
    try:
        meta = json.loads((store / "zarr.json").read_text())
        attrs = meta.get("attributes", {}).get(ATTR)
    except (OSError, ValueError, AttributeError, RecursionError):
        attrs = None
    if attrs is None:
        return NO_INDEX_NOTE.format(store=store)
    try:
        if not isinstance(attrs, dict) or not attrs.get("complete"):
            raise ValueError("incomplete")
        if int(attrs["version"]) != INDEX_VERSION:
            raise ValueError(f"format version {attrs['version']}, expected {INDEX_VERSION}")
        if [int(v) for v in attrs["dims"]] != list(grid.dims):
            raise ValueError(f"dims {attrs['dims']}, the store's are {list(grid.dims)}")
        if [list(a) for a in attrs["chunks"]] != _cell_chunks(grid):
            raise ValueError("its chunks are not the store's")
        if float(attrs["fault_tol"]) != FAULT_TOL:
            raise ValueError(f"fault tolerance {attrs['fault_tol']}")
        if attrs["arrays"] != _keys(grid) or int(attrs["steps"]) != len(grid.steps):
            raise ValueError("its arrays or steps are not the store's")
        if not isinstance(attrs["crc32"], dict):
            raise ValueError("no CRC-32s")
        digest = _digest(grid)
        if attrs.get("digest") != digest:
            raise ValueError("it was made for other arrays than the store's" if
                             attrs.get("digest") else "an older index, not bound to the "
                             "store's arrays")
        if attrs.get("seal") != seal(digest, ATTR, {k: v for k, v in attrs.items()
                                                    if k != "seal"}):
            raise ValueError("its record was changed after it was written")
        index = GridIndex(store, attrs, grid)
        nf, nc = index.nfaces, index.ncells
        for name, shape in (("faces/cells", (nf, 3)), ("faces/corners", (nf, 4)),
                            ("faces/flags", (nf,)), ("faces/face", (nf,)),
                            ("faces/by_chunk", (nf,)), ("cells", (nc,))):
            if tuple(index.root[name].shape) != shape:
                raise ValueError(f"{name} has shape {tuple(index.root[name].shape)}")
        why = sample(grid, index)
        if not why and check is not None:
            why = check(grid, index, sample_chunk(digest, index.nb))
        if why:
            raise ValueError(why)
    except Exception as err:  # any mismatch: drawn without the index, said in one line
        why = str(err)[:200] if type(err) is ValueError else one_line(err)
        return (f"{store}: its index is not used ({why}); 'geoshade grid ingest --index-only "
                f"{store}' rebuilds it")
    return index


def sample(grid, index: GridIndex) -> str:
    """``""`` when the index agrees with the store's arrays in its sampled chunk of cells
    (:func:`~geoshade.io.stores.binding.sample_chunk`): the active count (and the total the
    store keeps), each own array's min/max/count and its values at the chunk's face cells (a
    report step's arrays at one sampled step); else what differs."""
    digest = _digest(grid)
    cc = sample_chunk(digest, index.nb)
    c = int(np.ravel_multi_index(cc, index.nb))
    where = f"chunk {'/'.join(map(str, cc))}"
    # one chunk each, here (dask's function: no import of distributed to look for a client)
    act = np.asarray(grid.actnum.blocks[cc].compute(scheduler=dask_get("synchronous"))) != 0
    if int(index.nactive[c]) != int(act.sum()):
        return f"{where}: {int(index.nactive[c])} active cells, ACTNUM has {int(act.sum())}"
    bound = (grid.meta.get("bound") or {}).get("derived") if isinstance(grid.meta, dict) \
        else None
    if bound and int(index.nactive.sum()) != int(grid.nactive):
        return f"{int(index.nactive.sum())} active cells, the store has {int(grid.nactive)}"
    lo = np.array([sum(index.chunks[a][:cc[a]]) for a in range(3)])
    hi = lo + np.array([index.chunks[a][cc[a]] for a in range(3)])
    nx, ny, _ = index.dims
    num = index.cells   # ascending: the chunk's layers are one run of it
    a, b = np.searchsorted(num, [lo[2] * nx * ny, hi[2] * nx * ny])
    sub = num[a:b]
    ijk = np.stack([sub % nx, sub // nx % ny, sub // (nx * ny)], 1)
    inside = a + np.flatnonzero(((ijk >= lo) & (ijk < hi)).all(1))
    loc = ijk[inside - a] - lo
    nt = len(grid.steps)
    t0 = sample_chunk(digest, (nt,), salt=1)[0] if nt else 0
    for key, t, arr in grid.__dict__.get("_store_arrays") or ():
        if t is not None and t != t0:
            continue
        v = np.asarray(arr.blocks[cc].compute(scheduler=dask_get("synchronous")))
        w = v[act & np.isfinite(v)] if v.dtype.kind == "f" else v[act]
        want = np.array([w.min(), w.max(), w.size], np.float64) if w.size else \
            np.array([np.nan, np.nan, 0.0])
        if not np.array_equal(index.stats(key, t)[c], want, equal_nan=True):
            return f"{where}: the statistics of {key} differ from its values"
        got = index.part(f"values/{key}", inside, 0 if t is None else int(t))
        if not np.array_equal(got, v[loc[:, 0], loc[:, 1], loc[:, 2]],
                              equal_nan=v.dtype.kind == "f"):
            return f"{where}: the face-cell values of {key} differ from its values"
    return ""


