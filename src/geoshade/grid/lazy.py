"""Drawing a grid out of core: what the GridView needs of a grid whose arrays are dask arrays over
a grid store (:func:`geoshade.io.stores.grid_store.open_grid_store`), computed chunk by chunk.

The GPU half is the in-memory one (approach 3 with faces): it gets the visible faces
(:func:`geoshade.compute.grid.chunks.visible_faces_chunked`), their corner depths
(:func:`~geoshade.compute.grid.chunks.face_corner_depths`) and one value per face cell
(:func:`~geoshade.compute.grid.chunks.gather_cells`); nothing reads a whole ZCORN or property
into memory.  The framing bounds are one streamed pass (dask reductions), remembered on the grid;
the colour scale's summaries are those the store keeps (computed at ingest,
:func:`stored_summary`), else :func:`geoshade.compute.grid.cell_values.summarise`'s dask pass.
"""

from __future__ import annotations

import warnings
import weakref
from itertools import pairwise

import numpy as np

from geoshade.compute.grid.chunks import CellGroups, gather_cells, gather_points
from geoshade.compute.grid.geometry import orientation_sign
from geoshade.compute.grid.index_faces import ORIENTATION_SAMPLES, orientation_sample, sample_faces
from geoshade.errors import InputError
from geoshade.io.stores.grid_index import DamagedIndexError, GridIndex, open_index
from geoshade.models.grid import MAX_COORDINATE, CornerPointGrid
from geoshade.scheduler import dask_get
from geoshade.styles.categories import distinct_codes


def is_lazy(grid: CornerPointGrid) -> bool:
    """True when the grid's ZCORN is not a numpy array (a dask array over a store)."""
    return not isinstance(grid.zcorn, np.ndarray)


def check_options(grid: CornerPointGrid, options) -> None:
    """One line for what the out-of-core path does not draw (before any work)."""
    if options.approach != 3 or options.zcorn_store != "faces":
        raise InputError(f"{grid.name or 'grid'}: a grid out of core (a grid store) is drawn "
                         "with approach 3 and zcorn_store='faces' (only the visible faces' "
                         f"corners reach the GPU); got approach {options.approach}"
                         + (f", zcorn_store={options.zcorn_store!r}" if options.approach == 3
                            else ""))
    if options.plane is not None:
        raise InputError(f"{grid.name or 'grid'}: a cutting plane needs every cell centre; "
                         "on a grid store use an IJK slice or a filter")


def bounds(grid: CornerPointGrid) -> tuple[np.ndarray, np.ndarray]:
    """(every corner's bounds, the display bounds: z over the active cells' corners), both
    (2, 3), in one dask pass over ZCORN and ACTNUM."""
    import dask
    import dask.array as da

    c = np.asarray(grid.coord).reshape(-1, 6)
    x = np.concatenate([c[:, 0], c[:, 3]])
    y = np.concatenate([c[:, 1], c[:, 4]])
    zb = _indexed(grid, "zbounds")
    if zb is not None:  # the chunks' depth ranges kept by the store's index: no ZCORN pass
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)   # a grid without active cells
            lo, hi, alo, ahi = (np.nanmin(zb[:, 0]), np.nanmax(zb[:, 1]),
                                np.nanmin(zb[:, 2]), np.nanmax(zb[:, 3]))
        return _framed(x, y, lo, hi, alo, ahi)
    z = da.asarray(grid.zcorn)
    act = da.asarray(grid.actnum) != 0
    act8 = da.repeat(da.repeat(da.repeat(act, 2, 0), 2, 1), 2, 2).rechunk(z.chunks)
    usable = abs(z) <= MAX_COORDINATE
    zu = da.where(usable, z, np.nan)
    za = da.where(act8 & usable, z, np.nan)
    lo, hi, alo, ahi = dask.compute(da.nanmin(zu), da.nanmax(zu), da.nanmin(za), da.nanmax(za),
                                   scheduler=dask_get(None))
    return _framed(x, y, lo, hi, alo, ahi)


def _framed(x, y, lo, hi, alo, ahi) -> tuple[np.ndarray, np.ndarray]:
    full = np.array([[x.min(), y.min(), lo], [x.max(), y.max(), hi]], np.float64)
    disp = full.copy()
    if np.isfinite(alo):
        disp[0, 2], disp[1, 2] = alo, ahi
    return full, disp


def array_key(grid: CornerPointGrid, values) -> tuple[str, int | None] | None:
    """``("props/NAME", None)`` or ``("steps/KW", t)`` when ``values`` is one of a grid
    store's own arrays (the very object :func:`~geoshade.io.stores.grid_store.open_grid_store`
    made), else None (an expression, a derived or replaced array).

    Examples
    --------
    >>> g = CornerPointGrid(np.zeros((2, 2, 6)), np.zeros((2, 2, 2), np.float32),
    ...                     properties={"P": np.ones((1, 1, 1))})
    >>> array_key(g, g.properties["P"]), array_key(g, np.ones((1, 1, 1)))
    (('props/P', None), None)
    """
    own = grid.__dict__.get("_store_arrays")
    if own is not None:  # a grid store: its own arrays only (not a --param added or replacing)
        return next(((k, t) for k, t, a in own if a is values), None)
    for name, arr in grid.properties.items():
        if arr is values:
            return f"props/{name}", None
    for t, step in enumerate(grid.steps):
        for kw in step:
            if step[kw] is values:
                return f"steps/{kw}", t
    return None


def stored_summary(grid: CornerPointGrid, values):
    """The :class:`~geoshade.compute.grid.cell_values.ValueSummary` a grid store keeps of
    ``values`` (computed over the active cells at ingest: ``grid.meta["summaries"]``) when
    ``values`` is one of the store's own arrays (a property, a report step's array: the very
    object :func:`~geoshade.io.stores.grid_store.open_grid_store` made), else None (an expression, a
    derived or replaced array, an older store).

    Examples
    --------
    >>> from geoshade.compute.grid.cell_values import summarise
    >>> g = CornerPointGrid(np.zeros((2, 2, 6)), np.zeros((2, 2, 2), np.float32),
    ...                     properties={"P": np.ones((1, 1, 1))},
    ...                     meta={"summaries": {"props/P": summarise(np.ones((1, 1, 1)))}})
    >>> stored_summary(g, g.properties["P"]).hi, stored_summary(g, np.ones((1, 1, 1)))
    (1.0, None)
    """
    stored = grid.meta.get("summaries") if isinstance(grid.meta, dict) else None
    key = array_key(grid, values) if stored else None
    if key is None or stored is None:
        return None
    if key[1] is None:
        return stored.get(key[0])
    rows = stored.get(key[0])
    return rows[key[1]] if rows is not None and key[1] < len(rows) else None


def stored_codes(grid: CornerPointGrid, values):
    """The distinct active values a grid store keeps of ``values`` (one of its own integer
    properties: ``grid.meta["distinct_codes"]``), float64 sorted; None where it keeps none (an
    expression, a float array, an older store, more than 4096 codes).

    >>> g = CornerPointGrid(np.zeros((2, 2, 6)), np.zeros((2, 2, 2), np.float32),
    ...                     properties={"F": np.ones((1, 1, 1), np.int32)},
    ...                     meta={"distinct_codes": {"props/F": np.array([1.0])}})
    >>> stored_codes(g, g.properties["F"]).tolist(), stored_codes(g, np.ones((1, 1, 1)))
    ([1.0], None)
    """
    stored = grid.meta.get("distinct_codes") if isinstance(grid.meta, dict) else None
    key = array_key(grid, values) if stored else None
    if key is None or stored is None or key[1] is not None:
        return None
    return stored.get(key[0])


def lazy_codes(grid: CornerPointGrid, values) -> np.ndarray:
    """The distinct finite values of a grid store's ``values`` over its active cells (what
    :func:`geoshade.styles.categories.distinct_codes` gives in memory): those kept at ingest
    (:func:`stored_codes`), else one dask pass, chunk by chunk."""
    codes = stored_codes(grid, values)
    if codes is not None:
        return codes
    if isinstance(values, np.ndarray):   # a --param beside the store: in memory already
        return distinct_codes(values, np.asarray(grid.actnum) != 0)
    import dask
    import dask.array as da

    v = da.asarray(values)
    a = da.asarray(grid.actnum).rechunk(v.chunks) != 0
    parts = [dask.delayed(distinct_codes)(vb, ab)
             for vb, ab in zip(v.to_delayed().ravel(), a.to_delayed().ravel(), strict=True)]
    found = dask.compute(*parts, scheduler=dask_get(None))
    return np.unique(np.concatenate(found)) if found else np.zeros(0)


def count_in(values, active, codes) -> int:
    """Active cells whose value is one of ``codes`` (numpy, or chunk by chunk for a dask
    array: never a whole store array in memory).

    >>> count_in(np.array([[[1, -999, -999]]]), np.array([[[1, 1, 0]]]), [-999])
    1
    """
    if isinstance(values, np.ndarray):
        return int(np.count_nonzero(np.isin(values, codes) & (np.asarray(active) != 0)))
    import dask.array as da

    v = da.asarray(values)
    hit = da.isin(v, np.asarray(codes)) & (da.asarray(active).rechunk(v.chunks) != 0)
    return int(hit.sum().compute(scheduler=dask_get(None)))


def cells_ijk(numbers: np.ndarray, dims) -> np.ndarray:
    """(n, 3) int64 i, j, k of cell numbers ``i + nx (j + ny k)``."""
    nx, ny, _ = dims
    n = np.asarray(numbers, np.int64)
    return np.stack([n % nx, n // nx % ny, n // (nx * ny)], 1)


#: the chunk grouping of each live gathered cell list: id(list) -> (weak reference, CellGroups)
_GROUPS: dict = {}
#: cell lists up to this many cells keep their chunk grouping (8 bytes a cell) for the next
#: switch; a longer ascending list (a 1e9 filter's ~5e7 cells) is grouped a k-layer of chunks
#: at a time and not kept: ~0.4 GB less held and built, a regrouping at each switch instead
KEEP_GROUPS = 1 << 24


def values_at(array, numbers: np.ndarray, dims) -> np.ndarray:
    """Values of a cell array at the given cell numbers, reading only their chunks.

    The grouping of ``numbers`` by chunk (:class:`~geoshade.compute.grid.chunks.CellGroups`:
    8 bytes per cell) is kept while that very array of numbers lives (a view's list of cells
    with a visible face; one per part of a grid drawn in parts), so the next property or report
    step with the same chunks only reads and scatters; it goes with the list.
    """


    if isinstance(array, np.ndarray):
        return array.ravel(order="F")[numbers]
    if np.asarray(numbers).size > KEEP_GROUPS:
        return _values_by_layer(array, np.asarray(numbers), dims)
    key = id(numbers)
    ref, groups = _GROUPS.get(key, (None, None))
    if ref is None or ref() is not numbers or not groups.fits(numbers, dims, array.chunks):
        _GROUPS.pop(key, None)  # the old grouping goes before the new one is made
        groups = CellGroups(numbers, dims, array.chunks)

        def drop(r, key=key) -> None:  # the list is gone (new faces): so is its grouping
            if _GROUPS.get(key, (None,))[0] is r:
                del _GROUPS[key]

        try:
            _GROUPS[key] = (weakref.ref(numbers, drop), groups)
        except TypeError:  # an object without weak references: not kept
            pass
    return gather_cells(array, None, groups=groups)


def _values_by_layer(array, numbers: np.ndarray, dims) -> np.ndarray:
    """:func:`values_at` of a long list without keeping its grouping: ascending cell numbers
    (F order) of a k-layer of chunks are one run of the list, grouped and read a layer at a
    time (temporaries of one layer); any other order is grouped whole."""
    if numbers.size > 1 and not bool((numbers[1:] >= numbers[:-1]).all()):
        return gather_cells(array, None, groups=CellGroups(numbers, dims, array.chunks))
    out = np.empty(numbers.size, array.dtype)
    bounds = np.cumsum((0, *array.chunks[2]), dtype=np.int64) * (int(dims[0]) * int(dims[1]))
    cuts = np.searchsorted(numbers, bounds).tolist()
    for a, b in pairwise(cuts):
        if b > a:
            out[a:b] = gather_cells(array, None,
                                    groups=CellGroups(numbers[a:b], dims, array.chunks))
    return out


def store_index_of(grid: CornerPointGrid) -> GridIndex | str:
    """A grid store's checked index (:func:`~geoshade.io.stores.grid_index.open_index`,
    opened once and kept on the grid), or one line why there is none ("" for a grid that is
    not a store)."""
    if not isinstance(grid.meta, dict) or not grid.meta.get("store"):
        return ""
    idx = grid.__dict__.get("_store_index")
    if idx is None:
        idx = grid.__dict__["_store_index"] = open_index(grid, sample_faces)
    return idx


def _indexed(grid: CornerPointGrid, name: str) -> np.ndarray | None:
    """The array ``name`` of a grid store's index, or None (no store, no index, or a damaged
    one: computed as without it)."""
    idx = store_index_of(grid)
    if not isinstance(idx, GridIndex):
        return None
    try:
        return idx.array(name)
    except DamagedIndexError:
        return None


def orientation(grid: CornerPointGrid, samples: int = ORIENTATION_SAMPLES) -> float:
    """:func:`~geoshade.render.visuals.grid.visual.grid_orientation` from a sample of cells
    read chunk by chunk (cells spread over the grid; the active ones among them), or the one
    a grid store's index keeps (the same sample, computed at ingest)."""

    stored = _indexed(grid, "orientation")
    if stored is not None and samples == ORIENTATION_SAMPLES:
        return float(stored[0])
    ijk = orientation_sample(grid.dims, samples)
    act = np.asarray(gather_points(grid.actnum, ijk)) != 0
    ijk = ijk[act]
    if not len(ijk):
        return 0.0
    corners = np.array([(c & 1, c >> 1 & 1, c >> 2 & 1) for c in range(8)])
    pts_idx = (2 * ijk[:, None, :] + corners[None]).reshape(-1, 3)
    zc8 = np.asarray(gather_points(grid.zcorn, pts_idx), np.float64).reshape(-1, 8)
    return orientation_sign(grid.coord, ijk[:, 0], ijk[:, 1], zc8)
