"""A grid store's coarse level of detail: computed (:mod:`geoshade.compute.grid_coarse`) and
kept inside the store (:mod:`geoshade.io.stores.grid_lod`); what a progressive GridView draws
first."""

from __future__ import annotations

from pathlib import Path

from geoshade.compute.grid_coarse import check_factor, coarse_grid
from geoshade.io.stores.grid_lod import read_coarse_level, write_level
from geoshade.io.stores.grid_store import open_grid_store
from geoshade.progress import Progress

#: the merge factor ``geoshade grid ingest --coarse`` uses when none is given
DEFAULT_FACTOR = 4


def write_coarse_level(store, f: int = DEFAULT_FACTOR, progress: Progress | None = None,
                       modes=()) -> Path:
    """Compute the coarse level of the complete grid store ``store`` with factor ``f`` and keep
    it inside the store, written beside and renamed (replacing an earlier one); its path.

    Parameters
    ----------
    store : str or Path
        A complete grid store (``geoshade grid ingest``).
    f : int
        Cells merged along each axis (2 or 4; 1 and 8 are accepted too).
    progress : callable(done, total), optional
        Called after each tile of the fine grid (memory stays bounded: one tile at a time).
    modes : iterable of str
        Float arrays whose coarse value is the mode (codes), besides integer arrays.

    Examples
    --------
    >>> import tempfile, os
    >>> from geoshade.compute.synthetic_grid import synthetic_grid
    >>> from geoshade.io.stores.grid_store import ModelSource, write_grid_store
    >>> d = tempfile.mkdtemp()
    >>> _ = write_grid_store(ModelSource(synthetic_grid(8, 6, 4)), os.path.join(d, "g.zarr"),
    ...                      chunks=(4, 4, 2), input_label="g")
    >>> _ = write_coarse_level(os.path.join(d, "g.zarr"), 2)
    >>> read_coarse_level(os.path.join(d, "g.zarr")).dims
    (4, 3, 2)
    """
    f = check_factor(f)
    grid = open_grid_store(store)           # refuses an incomplete store (one line)
    return write_level(store, coarse_grid(grid, f, modes=modes, progress=progress), grid, f)


__all__ = ["DEFAULT_FACTOR", "read_coarse_level", "write_coarse_level"]
