"""A grid store's coarse level of detail: computed (:mod:`geoshade.compute.grid.coarse`) and
kept inside the store (:mod:`geoshade.io.stores.grid_lod`); what a progressive GridView draws
first."""

from __future__ import annotations

from pathlib import Path

from geoshade.compute.grid.coarse import check_factor, coarse_grid
from geoshade.compute.grid.index_faces import store_index
from geoshade.errors import InputError
from geoshade.grid.lazy import is_lazy, store_index_of
from geoshade.io.stores.grid_index import GridIndex
from geoshade.io.stores.grid_lod import read_coarse_level, write_level
from geoshade.io.stores.grid_store import open_grid_store
from geoshade.io.stores.ingest_lock import IngestLock
from geoshade.models.grid import CornerPointGrid
from geoshade.progress import Progress

#: the merge factor ``geoshade grid ingest --coarse`` uses when none is given: ``auto``, the
#: smallest of 2, 4, 8 whose level has at most :data:`PREVIEW_CELLS` cells (a 1e8-cell grid: 4,
#: 1e9: 8; a preview of 15.6 M cells, a 1e9 grid's at 4, took 20 s to draw here, 2 M cells 3.5 s)
DEFAULT_FACTOR = "auto"
#: cells of a progressive GridView's preview at most (a grid in memory is merged by the
#: smallest factor that gives no more; a store draws its stored level)
PREVIEW_CELLS = 1 << 21


def preview_factor(ncells: int, budget: int | None = None) -> int | None:
    """The merge factor of an in-memory grid's preview: the smallest of 2, 4, 8 that leaves at
    most ``budget`` (:data:`PREVIEW_CELLS`) cells, None when the grid is within it.

    >>> preview_factor(1000), preview_factor(10**8)
    (None, 4)
    """
    budget = PREVIEW_CELLS if budget is None else budget
    if ncells <= budget:
        return None
    return next((f for f in (2, 4) if ncells / f**3 <= budget), 8)


def coarse_level(grid: CornerPointGrid) -> tuple[CornerPointGrid | None, str]:
    """The coarse level of detail a progressive GridView of ``grid`` draws first, or None and
    why: a grid store's stored level (drawn out of core from its own index; a level written
    before levels had one is read into memory), else a store without one (the note says how to
    add one); a grid in memory merged by :func:`preview_factor` (None: small enough).

    >>> from geoshade.compute.grid.synthetic import synthetic_grid
    >>> coarse_level(synthetic_grid(4, 3, 2))
    (None, '')
    """
    if not is_lazy(grid):
        f = preview_factor(grid.ncells)
        return (None, "") if f is None else (coarse_grid(grid, f), "")
    store = grid.meta.get("store")
    digest = grid.meta.get("digest")
    try:   # a level of another grid, stale, edited or damaged: not drawn, said in one line
        coarse = read_coarse_level(store, grid.dims, lazy=True, expect_digest=digest) \
            if store else None
        # its index opened once and kept on it (the View draws it from that index)
        if coarse is not None and not isinstance(store_index_of(coarse), GridIndex):
            coarse = read_coarse_level(store, grid.dims, expect_digest=digest)
    except InputError as err:
        return None, f"progressive: the full picture only, its coarse level is not used: {err}"
    if coarse is None:
        return None, ("progressive: no coarse level in the store, the full picture only (add "
                      f"one: 'geoshade grid ingest --coarse auto {store}')")
    return coarse, ""


def write_coarse_level(store, f: int | str = DEFAULT_FACTOR, progress: Progress | None = None,
                       modes=()) -> Path:
    """Compute the coarse level of the complete grid store ``store`` with factor ``f`` and keep
    it inside the store, written beside and renamed (replacing an earlier one); its path.

    Parameters
    ----------
    store : str or Path
        A complete grid store (``geoshade grid ingest``).
    f : int or "auto"
        Cells merged along each axis (2, 4 or 8; 1 too); ``auto``: the smallest whose level
        has at most :data:`PREVIEW_CELLS` cells (at least 2).
    progress : callable(done, total), optional
        Called after each tile of the fine grid (memory stays bounded: one tile at a time).
    modes : iterable of str
        Float arrays whose coarse value is the mode (codes), besides integer arrays.

    Examples
    --------
    >>> import tempfile, os
    >>> from geoshade.compute.grid.synthetic import synthetic_grid
    >>> from geoshade.io.stores.grid_store import ModelSource, write_grid_store
    >>> d = tempfile.mkdtemp()
    >>> _ = write_grid_store(ModelSource(synthetic_grid(8, 6, 4)), os.path.join(d, "g.zarr"),
    ...                      chunks=(4, 4, 2), input_label="g")
    >>> _ = write_coarse_level(os.path.join(d, "g.zarr"), 2)
    >>> read_coarse_level(os.path.join(d, "g.zarr")).dims
    (4, 3, 2)
    """
    grid = open_grid_store(store)           # refuses an incomplete store (one line)
    f = (preview_factor(grid.ncells) or 2) if str(f).lower() == "auto" else check_factor(f)
    with IngestLock(store, task="grid ingest --coarse"):   # one writer of the store at a time
        return write_level(store, coarse_grid(grid, f, modes=modes, progress=progress), grid,
                           f, index=store_index)


__all__ = ["DEFAULT_FACTOR", "PREVIEW_CELLS", "coarse_level", "preview_factor", "read_coarse_level",
           "write_coarse_level"]
