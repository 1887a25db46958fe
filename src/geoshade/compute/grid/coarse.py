"""A coarse level of detail of a corner-point grid: cells merged ``f × f × f`` along pillars.

The coarse grid keeps every ``f``-th pillar (and the last) of the fine grid. Coarse cell
``(I, J, K)`` covers the fine cells ``[fI, min(fI + f, nx)) × … × …`` (a partial block at the
far edge where a dimension is not a multiple of ``f``); its corner ``(a, b, c)`` is the corner
``(a, b, c)`` of the fine cell at that corner of the block, so the corner depths on each kept
pillar are the fine grid's own, and a fault's throw at a kept pillar is kept exactly::

    coarse zcorn[2I + a, …] = fine zcorn[2 (fI + a (n_I - 1)) + a, …]   (n_I: cells in the block)

A coarse cell is active when any of its fine cells is; a coarse value is the mean of the
active fine values (float arrays, computed in float64, stored in the array's dtype) or their
mode (integer arrays and the names given as ``modes``: the most frequent active value, the
smallest on a tie); a block without an active cell holds NaN (float) or 0 (integer).

The work runs in tiles of whole coarse blocks (at most :data:`TILE_CELLS` fine cells each),
read from numpy, dask or zarr arrays one tile at a time, so memory stays bounded whatever the
grid's size.  ``f = 1`` gives the grid back unchanged (a copy).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from geoshade.errors import InputError
from geoshade.models.grid import CornerPointGrid, Fault
from geoshade.scheduler import dask_get

#: fine cells per tile (one tile's arrays, ZCORN included, are ~ 40 bytes a cell)
TILE_CELLS = 1 << 21
#: merge factors a coarse level may use
FACTORS = (1, 2, 4, 8)


def check_factor(f) -> int:
    """``f`` as a merge factor of :data:`FACTORS`, else one line.

    >>> check_factor("4")
    4
    """
    try:
        v = int(f)
    except (TypeError, ValueError):
        v = -1
    if v not in FACTORS or (isinstance(f, float) and not float(f).is_integer()):
        raise InputError(f"factor: expected one of {', '.join(map(str, FACTORS))}, got {f!r}")
    return v


def coarse_dims(dims, f: int) -> tuple[int, int, int]:
    """The coarse grid's ``(nx, ny, nz)``: each dimension divided by ``f``, rounded up.

    >>> coarse_dims((10, 8, 3), 4)
    (3, 2, 1)
    """
    return tuple(-(-int(n) // f) for n in dims)  # type: ignore[return-value]


def pillar_index(n: int, f: int) -> np.ndarray:
    """The fine pillars kept along one axis of ``n`` cells: every ``f``-th and the last.

    >>> pillar_index(5, 2).tolist()
    [0, 2, 4, 5]
    """
    nc = -(-n // f)
    return np.minimum(np.arange(nc + 1) * f, n)


def corner_index(n: int, f: int) -> np.ndarray:
    """Fine ZCORN indices of the coarse ZCORN along one axis of ``n`` cells (see the module).

    >>> corner_index(5, 2).tolist()
    [0, 3, 4, 7, 8, 9]
    """
    nc = -(-n // f)
    first = np.arange(nc) * f
    last = np.minimum(first + f, n) - 1
    out = np.empty(2 * nc, np.int64)
    out[0::2] = 2 * first
    out[1::2] = 2 * last + 1
    return out


def _read(a, sl) -> np.ndarray:
    part = a[sl]
    if hasattr(part, "compute"):
        part = part.compute(scheduler=dask_get(None))
    return np.asarray(part)


def _blocks(a: np.ndarray, f: int) -> np.ndarray:
    """``(ni, nj, nk)`` → ``(ci, cj, ck, f³)`` blocks, padded with the first cell of each
    block (masked out by the caller's padded activity)."""
    ni, nj, nk = a.shape
    ci, cj, ck = -(-ni // f), -(-nj // f), -(-nk // f)
    pad = ((0, ci * f - ni), (0, cj * f - nj), (0, ck * f - nk))
    if any(p[1] for p in pad):
        a = np.pad(a, pad, mode="edge")
    return (a.reshape(ci, f, cj, f, ck, f).transpose(0, 2, 4, 1, 3, 5)
            .reshape(ci, cj, ck, f ** 3))


def block_mode(values: np.ndarray, valid: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per row of ``values (n, m)``: the most frequent value among the ``valid`` entries (the
    smallest on a tie) and whether the row had any (vectorised: sort, run lengths).

    >>> v = np.array([[3, 1, 3, 1, 2], [5, 5, 7, 7, 7]])
    >>> m, ok = block_mode(v, np.array([[1, 1, 1, 1, 0], [1, 1, 0, 0, 0]], bool))
    >>> m.tolist(), ok.tolist()
    ([1, 5], [True, True])
    """
    n, m = values.shape
    big = np.iinfo(np.int64).max
    s = np.sort(np.where(valid, values.astype(np.int64), big), axis=1)
    idx = np.broadcast_to(np.arange(m), (n, m))
    start = np.ones((n, m), bool)
    start[:, 1:] = s[:, 1:] != s[:, :-1]
    run0 = np.maximum.accumulate(np.where(start, idx, 0), axis=1)
    count = np.where(s != big, idx - run0 + 1, 0)
    best = np.argmax(count, axis=1)   # first position reaching the longest run: smallest value
    mode = s[np.arange(n), best]
    ok = count[np.arange(n), best] > 0
    return np.where(ok, mode, 0), ok


def coarse_values(values: np.ndarray, active: np.ndarray, f: int,
                  mode: bool | None = None) -> np.ndarray:
    """One array's coarse values over whole blocks (see the module): the mean of the active
    fine values, or their mode (``mode``; default: for an integer dtype).

    >>> v = np.arange(8, dtype=np.float32).reshape(2, 2, 2)
    >>> coarse_values(v, np.ones((2, 2, 2), bool), 2)[0, 0, 0]
    np.float32(3.5)
    """
    v = np.asarray(values)
    integer = np.issubdtype(v.dtype, np.integer) or v.dtype == bool
    use_mode = integer if mode is None else bool(mode)
    act = _blocks(_pad_false(np.asarray(active) != 0, f), f)   # padding: never active
    b = _blocks(v, f)
    shape = b.shape[:3]
    if use_mode:
        m, ok = block_mode(b.reshape(-1, b.shape[3]), act.reshape(-1, act.shape[3]))
        out = m.reshape(shape)
        if integer:
            return out.astype(v.dtype)
        return np.where(ok.reshape(shape), out, np.nan).astype(v.dtype)
    n = act.sum(axis=3)
    s = np.where(act, b.astype(np.float64), 0.0).sum(axis=3)
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = np.where(n > 0, s / np.maximum(n, 1), np.nan)
    if integer:
        return np.where(n > 0, np.rint(mean), 0).astype(v.dtype)
    return mean.astype(v.dtype if np.issubdtype(v.dtype, np.floating) else np.float64)


def _tiles(cdims, f: int, kgroup: int = 1):
    """Tiles of whole coarse blocks, as coarse index ranges, about :data:`TILE_CELLS` fine
    cells each (whole coarse layers in i and j where they fit; else ``kgroup`` coarse layers,
    a store's chunk depth, in square columns)."""
    ci, cj, ck = cdims
    per_layer = ci * cj * f ** 3
    if per_layer <= TILE_CELLS:
        kb = max(1, TILE_CELLS // per_layer)
        for k0 in range(0, ck, kb):
            yield (0, ci), (0, cj), (k0, min(ck, k0 + kb))
        return
    kb = max(1, min(int(kgroup), ck))
    side = max(1, int(math.sqrt(TILE_CELLS / (f ** 3 * kb))))
    for k0 in range(0, ck, kb):
        for j0 in range(0, cj, side):
            for i0 in range(0, ci, side):
                yield (i0, min(ci, i0 + side)), (j0, min(cj, j0 + side)), (k0, min(ck, k0 + kb))


def _on_blocks(fc: np.ndarray, dims, f: int) -> np.ndarray:
    """Which fault faces ((n, 4) i, j, k, face) lie on coarse block boundaries."""
    ijk, face = fc[:, :3], fc[:, 3]
    axis, plus = face % 3, face < 3
    pos = ijk[np.arange(len(fc)), axis]
    n = np.asarray(dims, np.int64)[axis]
    return np.where(plus, ((pos + 1) % f == 0) | (pos + 1 == n), pos % f == 0)


def _coarse_faults(faults, dims, f: int) -> list[Fault]:
    """The fault faces that lie on coarse block boundaries, as coarse faces (deduplicated)."""
    out = []
    for fl in faults:
        fc = np.asarray(fl.faces, np.int64).reshape(-1, 4)
        if not len(fc):
            continue
        on = _on_blocks(fc, dims, f)
        c = np.concatenate([fc[on, :3] // f, fc[on, 3, None]], axis=1)
        if len(c):
            out.append(Fault(fl.name, np.unique(c, axis=0).astype(np.int32)))
    return out


def faults_inside_blocks(faults, dims, f: int) -> int:
    """Fault faces of the fine grid inside coarse blocks (not on their boundaries): where the
    coarse level of factor ``f`` smooths a fault's throw away (the preview says so).

    >>> faults_inside_blocks([Fault("F", np.array([[0, 0, 0, 0], [1, 0, 0, 0]]))], (4, 1, 1), 2)
    1
    """
    return int(sum(np.count_nonzero(~_on_blocks(np.asarray(fl.faces, np.int64).reshape(-1, 4),
                                                dims, f))
                   for fl in faults if len(fl.faces)))


def merged_cells(cell, f: int, dims) -> tuple[tuple, tuple]:
    """The first and last fine cells (i, j, k) that coarse cell ``cell`` of factor ``f``
    merges (a partial block at the far edge: see the module).

    >>> merged_cells((1, 0, 2), 4, (6, 4, 12))
    ((4, 0, 8), (5, 3, 11))
    """
    lo = [f * int(c) for c in cell]
    return tuple(lo), tuple(min(a + f, int(n)) - 1 for a, n in zip(lo, dims, strict=True))


def coarse_grid(grid: CornerPointGrid, f: int, modes=(),
                progress: Callable[[int, int], object] | None = None) -> CornerPointGrid:
    """The grid's coarse level of detail with merge factor ``f`` (see the module).

    Parameters
    ----------
    grid : CornerPointGrid
        In memory or lazy (a grid store's dask arrays: read one tile at a time).
    f : int
        Cells merged along each axis (1, 2, 4 or 8).
    modes : iterable of str
        Property or report-step keywords (besides integer arrays) whose coarse value is the
        mode, e.g. a facies code stored as float.
    progress : callable(done, total), optional
        Called after each tile.

    Returns
    -------
    CornerPointGrid
        In memory; ``meta["lod"]`` = ``{"factor": f, "fine_dims": [nx, ny, nz]}``.

    Examples
    --------
    >>> from geoshade.compute.grid.synthetic import synthetic_grid
    >>> g = synthetic_grid(8, 6, 4)
    >>> c = coarse_grid(g, 2)
    >>> c.dims, c.meta["lod"]["factor"]
    ((4, 3, 2), 2)
    """
    f = check_factor(f)
    dims = grid.dims
    cdims = coarse_dims(dims, f)
    modes = {str(m).upper() for m in modes}
    ix = [pillar_index(n, f) for n in dims[:2]]
    coord = np.asarray(_read(grid.coord, (slice(None),) * 3), np.float64)[np.ix_(*ix)]
    zc = np.empty(tuple(2 * n for n in cdims), np.dtype(grid.zcorn.dtype))
    act = np.zeros(cdims, np.uint8)
    props = {n: np.empty(cdims, _out_dtype(a)) for n, a in grid.properties.items()}
    steps = [{n: np.empty(cdims, _out_dtype(a)) for n, a in st.items()} for st in grid.steps]
    chunks = grid.meta.get("chunks") or (0, 0, f)   # a store's: read each chunk about once
    tiles = list(_tiles(cdims, f, max(1, int(chunks[2]) // f)))
    for q, ((i0, i1), (j0, j1), (k0, k1)) in enumerate(tiles):
        fine = tuple(slice(a * f, min(b * f, n)) for (a, b), n in
                     zip(((i0, i1), (j0, j1), (k0, k1)), dims, strict=True))
        csl = (slice(i0, i1), slice(j0, j1), slice(k0, k1))
        a = _read(grid.actnum, fine) != 0
        act[csl] = _blocks(_pad_false(a, f), f).any(axis=3)
        zsl = tuple(slice(2 * s.start, 2 * s.stop) for s in fine)
        z = _read(grid.zcorn, zsl)
        idx = [corner_index(s.stop - s.start, f) for s in fine]
        zc[tuple(slice(2 * s.start, 2 * s.stop) for s in csl)] = z[np.ix_(*idx)]
        for n, arr in grid.properties.items():
            props[n][csl] = coarse_values(_read(arr, fine), a, f, _mode(n, modes))
        for t, st in enumerate(grid.steps):
            for n, arr in st.items():
                steps[t][n][csl] = coarse_values(_read(arr, fine), a, f, _mode(n, modes))
        if progress is not None:
            progress(q + 1, len(tiles))
    meta = {k: v for k, v in grid.meta.items() if k in ("codes", "unrst_seqnum", "index_space",
                                                         "step_keywords")}
    meta["lod"] = {"factor": f, "fine_dims": [int(n) for n in dims]}
    return CornerPointGrid(coord=coord, zcorn=zc, actnum=act, mapaxes=grid.mapaxes,
                           properties=props, steps=steps, step_dates=list(grid.step_dates),
                           faults=_coarse_faults(grid.faults, dims, f), units=grid.units,
                           name=grid.name, meta=meta)


def _pad_false(a: np.ndarray, f: int) -> np.ndarray:
    pad = tuple((0, -(-n // f) * f - n) for n in a.shape)
    return np.pad(a, pad) if any(p[1] for p in pad) else a


def _mode(name: str, modes: set) -> bool | None:
    return True if name.upper() in modes else None


def _out_dtype(a) -> np.dtype:
    dt = np.dtype(a.dtype)
    return dt if (np.issubdtype(dt, np.floating) or np.issubdtype(dt, np.integer)) \
        else np.dtype(np.float64)


__all__ = ["FACTORS", "TILE_CELLS", "block_mode", "check_factor", "coarse_dims", "coarse_grid",
           "coarse_values", "corner_index", "faults_inside_blocks", "merged_cells",
           "pillar_index"]
