"""What a zarr store declares, read from its metadata alone (the ``header`` function of the
``zarr`` row of :mod:`geoshade.io.formats`): no chunk is read.

- a grid store (``geoshade grid ingest``): its dims, chunks, active cells, cell arrays, the
  faces its index holds, and its coarse level (factor, dims, indexed faces);
- a volume store (``geoshade core ingest``, any zarr array or group of arrays): the shape and
  dtype of every level, finest first, and its chunks.

The figures are what the store's attributes say; a store whose records are stale or damaged is
said so when it is opened (:func:`geoshade.io.stores.grid_store.open_grid_store`), not here.

>>> import numpy as np, tempfile, os
>>> from geoshade.io.stores.zarr_io import write_zarr
>>> from geoshade.models import VoxelVolume
>>> p = write_zarr(VoxelVolume(np.zeros((4, 6, 8), np.uint16)),
...                os.path.join(tempfile.mkdtemp(), "v.zarr"))
>>> h = zarr_header(p)
>>> h.kind, h.shape, h.dtype, h.levels
('volume-store', (8, 6, 4), 'uint16', ((8, 6, 4),))
"""

from __future__ import annotations

import json
import math
import os
import stat
from pathlib import Path

import numpy as np

from geoshade.io.paths import check_folder
from geoshade.io.plan import Header

#: the coarse level's folder inside a grid store (as :mod:`geoshade.io.stores.grid_lod`)
LOD_NAME = "lod"


#: metadata files larger than this are not read (a store's are a few kB)
META_BYTES = 16 << 20


def _json(path: Path) -> dict | None:
    """A metadata file's JSON object: read only when it is a regular file of sensible size
    (a FIFO named ``zarr.json`` is never opened, so it cannot block)."""
    try:
        if not stat.S_ISREG(os.stat(path).st_mode):
            return None
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
        with os.fdopen(fd, "rb") as fh:
            st = os.fstat(fh.fileno())
            if not stat.S_ISREG(st.st_mode) or st.st_size > META_BYTES:
                return None
            meta = json.loads(fh.read())
    except (OSError, ValueError, RecursionError, UnicodeDecodeError):
        return None
    return meta if isinstance(meta, dict) else None


def _attrs(store: Path) -> dict:
    meta = _json(store / "zarr.json") or _json(store / ".zattrs") or {}
    attrs = meta.get("attributes", meta) if "zarr_format" in meta else meta
    return attrs if isinstance(attrs, dict) else {}


def _ints(value, n: int) -> tuple[int, ...] | None:
    try:
        out = tuple(int(v) for v in value)
    except (TypeError, ValueError, OverflowError):
        return None
    return out if len(out) == n and min(out) > 0 else None


def _array_meta(folder: Path) -> tuple[tuple[int, ...], str, tuple[int, ...] | None] | None:
    """(shape, dtype, chunks) of a zarr v3 or v2 array folder, None if it is none."""
    v3 = _json(folder / "zarr.json")
    if v3 is not None and v3.get("node_type") == "array":
        shape = tuple(int(v) for v in v3.get("shape", ()))
        grid = v3.get("chunk_grid", {}).get("configuration", {}).get("chunk_shape")
        return shape, str(v3.get("data_type", "")), None if grid is None else tuple(grid)
    v2 = _json(folder / ".zarray")
    if v2 is not None:
        try:
            dtype = np.dtype(v2.get("dtype")).name
        except TypeError:
            dtype = ""
        return tuple(int(v) for v in v2.get("shape", ())), dtype, tuple(v2.get("chunks", ()))
    return None


def _grid_header(path, store: Path, attrs: dict) -> Header | None:
    gs = attrs.get("grid_store")
    if not isinstance(gs, dict):
        return None
    dims = _ints(gs.get("dims"), 3)
    if dims is None:
        return None
    nactive = gs.get("nactive") if isinstance(gs.get("nactive"), int) else None
    props = gs.get("properties") if isinstance(gs.get("properties"), list) else []
    kws = gs.get("step_keywords") if isinstance(gs.get("step_keywords"), list) else []
    nsteps = len(attrs.get("step_dates") or []) if isinstance(attrs.get("step_dates"),
                                                              list) else 0
    index = attrs.get("grid_index") if isinstance(attrs.get("grid_index"), dict) else {}
    faces = index.get("faces") if isinstance(index.get("faces"), int) else None
    coarse = None
    lod = _attrs(store / LOD_NAME)
    if isinstance(lod.get("grid_store"), dict):
        ldims = _ints(lod["grid_store"].get("dims"), 3)
        lmeta = lod.get("meta") if isinstance(lod.get("meta"), dict) else {}
        rec = lmeta.get("lod") if isinstance(lmeta.get("lod"), dict) else {}
        lindex = lod.get("grid_index") if isinstance(lod.get("grid_index"), dict) else {}
        if ldims is not None and isinstance(rec.get("factor"), int):
            coarse = {"factor": int(rec["factor"]), "dims": list(ldims),
                      "faces": lindex.get("faces") if isinstance(lindex.get("faces"), int)
                      else None}
    notes = [] if faces is not None else ["no index: the visible faces are estimated"]
    return Header(str(path), "zarr", "grid-store", dims, nactive=nactive,
                  arrays=len(props) + len(kws) * nsteps, faces=faces, coarse=coarse,
                  storage="lazy", hints={"chunks": _ints(gs.get("chunks"), 3)},
                  notes=tuple(notes))


def zarr_header(path) -> Header | None:
    """A grid store's or a volume store's header (see the module); None for a store of
    neither kind (the reader says why)."""
    store = check_folder(path, "a zarr store (a folder)")
    attrs = _attrs(store)
    grid = _grid_header(path, store, attrs)
    if grid is not None or "grid_store" in attrs:
        return grid
    levels = []
    root = _array_meta(store)
    if root is not None:
        levels.append((root, store))
    else:
        for sub in sorted(store.iterdir(), key=lambda q: q.name):
            if sub.is_dir() and not sub.name.startswith("."):
                m = _array_meta(sub)
                if m is not None and len(m[0]) == 3:
                    levels.append((m, sub))
    levels = [lv for lv in levels if len(lv[0][0]) == 3]
    if not levels:
        return None
    levels.sort(key=lambda lv: -math.prod(lv[0][0]))
    shapes = tuple(tuple(int(n) for n in reversed(m[0])) for m, _ in levels)
    (_, dtype, chunks), _ = levels[0]
    return Header(str(path), "zarr", "volume-store", shapes[0], dtype, levels=shapes,
                  storage="lazy", hints={"chunks": chunks})


__all__ = ["zarr_header"]
