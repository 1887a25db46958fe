"""A grid store's coarse level of detail, kept inside the store.

:func:`geoshade.grid.lod.write_coarse_level` merges a complete grid store's cells ``f × f × f``
along pillars (:func:`geoshade.compute.grid.coarse.coarse_grid`, tile by tile from the lazy
store: bounded memory) and :func:`write_level` writes the result as a small grid store of its
own inside the fine one::

    CASE.zarr/
      lod/            a grid store (coord, zcorn, actnum, props, steps; CRC-checked), its
                      ``meta.lod`` = {factor, fine_dims, fine_nactive, fine_digest}

It is written beside (``lod.partial``) and renamed into place (:func:`geoshade.io.output.publish`),
so a reader sees no level or a whole one; writing again replaces it.  :func:`read_coarse_level`
reads it into memory (it is ``f³`` times smaller than the grid), or None when the store has
none; a GridView with ``progressive=True`` draws it first.

A level is bound to the grid it was merged from: ``fine_digest`` is the digest of the fine
store's arrays (:mod:`geoshade.io.stores.binding`), and the level's own record is sealed with
its arrays, so a level copied from another grid of the same size, one left from before the
grid was ingested again, or one edited, is refused (:class:`StaleLevelError`: the View then
draws without a preview and says why in one line); a malformed record is one line naming it.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from geoshade.errors import InputError
from geoshade.io.stores.binding import UnboundRecordWarning
from geoshade.io.stores.chunks import DamagedStoreError
from geoshade.io.stores.grid_store import ModelSource, open_grid_store, write_grid_store
from geoshade.models.grid import CornerPointGrid
from geoshade.scheduler import dask_get

#: the coarse level's folder inside a grid store
LOD_NAME = "lod"


class StaleLevelError(InputError):
    """A store's coarse level that is not the level of the grid it is in (made for another
    grid, or for the arrays before they were written again, or edited)."""


def lod_path(store) -> Path:
    """Where a store keeps its coarse level (:data:`LOD_NAME` inside it)."""
    return Path(store) / LOD_NAME


#: cells per chunk of a coarse level: read whole when a View opens, so few large chunks
LEVEL_CHUNK_CELLS = 1 << 22


def level_chunks(dims) -> tuple[int, int, int]:
    """Chunks of a coarse level: up to 512 × 512 cells in i, j and the layers that make about
    :data:`LEVEL_CHUNK_CELLS` (a 500 × 500 × 63 level: 16 layers a chunk).

    >>> level_chunks((500, 500, 63)), level_chunks((4, 3, 2))
    ((500, 500, 16), (4, 3, 2))
    """
    ci, cj = min(int(dims[0]), 512), min(int(dims[1]), 512)
    return ci, cj, max(1, min(int(dims[2]), LEVEL_CHUNK_CELLS // (ci * cj)))


def write_level(store, coarse: CornerPointGrid, fine: CornerPointGrid, f: int,
                index=None) -> Path:
    """Keep ``coarse`` (the coarse level of the complete grid store ``store``, opened as
    ``fine``, with factor ``f``) inside the store, atomically (see the module); returns its
    path.  :func:`geoshade.grid.lod.write_coarse_level` computes and writes it. ``index``: the
    store index builder (:func:`geoshade.compute.grid.index_faces.store_index`): the level
    gets its own index (faces, depth ranges), so a preview opens it without computing faces."""
    src = ModelSource(coarse)
    src.meta["lod"] = {"factor": int(f), "fine_dims": [int(n) for n in fine.dims],
                       "fine_nactive": int(fine.nactive),
                       "fine_digest": str(fine.meta.get("digest", ""))}
    out = lod_path(store)
    write_grid_store(src, out, chunks=level_chunks(coarse.dims), overwrite=True,
                     input_label=f"{Path(store).name} (coarse level)", index=index)
    return out


def coarse_level_info(store) -> dict | None:
    """``{"factor", "fine_dims", "fine_nactive"}`` of the store's coarse level, or None."""
    p = lod_path(store)
    if not (p / "zarr.json").is_file():
        return None
    return dict(open_grid_store(p).meta.get("lod") or {}) or None


def _lod_record(p: Path, level: CornerPointGrid) -> tuple[int, tuple[int, ...], str]:
    """The level's ``meta.lod`` record, checked: (factor, fine dims, fine digest)."""
    lod = level.meta.get("lod")
    if not isinstance(lod, dict) or "factor" not in lod:
        raise DamagedStoreError(f"{p}: a coarse level without its 'lod' record")
    f, fine = lod.get("factor"), lod.get("fine_dims")
    if not isinstance(f, int) or isinstance(f, bool) or not 1 <= f <= 64:
        raise DamagedStoreError(f"{p}: damaged 'meta.lod.factor' attribute (expected an "
                                f"integer from 1 to 64, got {str(f)[:40]})")
    if not isinstance(fine, list) or len(fine) != 3 or not all(
            isinstance(n, int) and not isinstance(n, bool) and n > 0 for n in fine):
        raise DamagedStoreError(f"{p}: damaged 'meta.lod.fine_dims' attribute (expected three "
                                "positive integers)")
    return f, tuple(fine), str(lod.get("fine_digest") or "")


def read_coarse_level(store, expect_dims=None, lazy: bool = False,
                      expect_digest: str | None = None) -> CornerPointGrid | None:
    """The store's coarse level read into memory (numpy arrays; ``meta["lod"]`` says its
    factor), or None when the store has none. ``lazy``: opened as the grid store it is
    (dask arrays: a View draws it out of core, from its index when it has one).

    Raises
    ------
    StaleLevelError
        A level made for other dims than ``expect_dims`` (the fine grid's), for other arrays
        than those of ``expect_digest`` (the fine store's digest), or whose record was edited.
    DamagedStoreError
        A damaged level, or a malformed record (one line naming it).
    """
    p = lod_path(store)
    if not (p / "zarr.json").is_file():
        return None
    with warnings.catch_warnings():   # its binding is judged here, as the level's
        warnings.simplefilter("ignore", UnboundRecordWarning)
        lazy_grid = open_grid_store(p)
    f, fine, fine_digest = _lod_record(p, lazy_grid)
    again = f"'geoshade grid ingest --coarse F {store}' writes it again"
    if expect_dims is not None and fine != tuple(expect_dims):
        raise StaleLevelError(f"{p}: coarse level of a {'×'.join(map(str, fine))} grid, but the "
                              f"store holds {'×'.join(map(str, expect_dims))} cells; {again}")
    if tuple(-(-n // f) for n in fine) != lazy_grid.dims:
        raise DamagedStoreError(f"{p}: coarse level dims {lazy_grid.dims} do not match factor "
                                f"{f} of {fine}")
    bound = lazy_grid.meta.get("bound") or {}
    if not bound.get("described"):
        raise StaleLevelError(f"{p}: the coarse level's record is not bound to its arrays "
                              f"({bound.get('why') or 'no seal'}); {again}")
    if expect_digest is not None and fine_digest != expect_digest:
        why = ("another grid's, or made before the grid was ingested again" if fine_digest
               else "an older level, not bound to them")
        raise StaleLevelError(f"{p}: the coarse level was not made from the store's arrays "
                              f"({why}); {again}")

    if lazy:
        lazy_grid.name = str(Path(store))   # the title names the store, not its "lod" folder
        return lazy_grid

    def read(a):
        return np.asarray(a.compute(scheduler=dask_get(None)) if hasattr(a, "compute") else a)

    g = lazy_grid
    meta = dict(g.meta)
    meta.pop("store", None)
    meta["nactive"] = int(g.nactive)
    return CornerPointGrid(coord=read(g.coord), zcorn=read(g.zcorn),
                           actnum=read(g.actnum), mapaxes=g.mapaxes,
                           properties={k: read(v) for k, v in g.properties.items()},
                           steps=[{k: read(v) for k, v in st.items()} for st in g.steps],
                           step_dates=list(g.step_dates), faults=list(g.faults),
                           units=g.units, name=str(Path(store)), meta=meta)


__all__ = ["LEVEL_CHUNK_CELLS", "LOD_NAME", "StaleLevelError", "coarse_level_info", "level_chunks",
           "lod_path", "read_coarse_level", "write_level"]
