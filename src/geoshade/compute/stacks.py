"""Voxels ⇄ stacks, borehole columns, the GPU interval form and the memory of the GPU layouts.

Everything here is vectorised numpy over whole slabs of columns (no Python loop over columns).

- :func:`voxels_to_stacks` / :func:`stacks_to_voxels`: exact round trip for labelled voxels.
- :func:`interval_counts`: intervals per column of a label array (runs of equal values).
- :func:`place_boreholes`: borehole logs → borehole columns of a model.
- :func:`gpu_intervals`: the paper's GPU form, ``(material, accumulated height)`` per interval.
- :func:`layout_plan`: texture/buffer shapes and consumed/wasted bytes of the five layouts of
  Section 4.2 (Table 3), with the texture-limit checks; the renderer allocates from this plan.
- :func:`synthetic_layers`: layered models of any size, generated directly as stacks.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from geoshade.errors import GPUMemoryError, InputError
from geoshade.models.stacks import EMPTY, BoreholeLogs, Legend, StackModel, merge_legends

#: the five GPU layouts of Section 4.2, in the paper's order (and the dense baseline)
LAYOUTS = ("textures", "r-supertexels", "l-supertexels", "texture3d", "ssbo")
LAYOUT_NAMES = {"textures": "1-Textures", "r-supertexels": "2-R-Supertexels",
                "l-supertexels": "3-L-Supertexels", "texture3d": "4-3D-Texture",
                "ssbo": "5-SSBO", "dense": "dense 3D texture"}
#: bytes of one GPU interval (RG16F: material, accumulated height) and of one index entry
#: (RG32UI / two uint: pointer, count | borehole flag << 31)
INTERVAL_BYTES, INDEX_BYTES = 4, 8
#: default GPU limits (OpenGL 4.5 minimums are lower; these are llvmpipe's and most GPUs')
DEFAULT_LIMITS = {"max_texture_size": 16384, "max_3d_texture_size": 2048,
                  "max_ssbo_bytes": 128 << 20}
#: cells per slab when streaming through a volume
SLAB_CELLS = 1 << 24


# ==============================================================================================
# voxels -> stacks
# ==============================================================================================
def _to_codes(block: np.ndarray, empty, where: str) -> np.ndarray:
    """int32 codes of a label block, EMPTY for NaN / the empty value."""
    a = np.asarray(block)
    if np.issubdtype(a.dtype, np.floating):
        miss = np.isnan(a)
        if empty is not None and not (isinstance(empty, float) and math.isnan(empty)):
            miss |= a == empty
        vals = np.where(miss, 0, a)
        if not np.isfinite(vals).all() or (vals != np.round(vals)).any():
            raise InputError(f"{where}labels: expected integer material codes (NaN = empty), "
                             "found non-integer values")
        out = vals.astype(np.int64)
    elif np.issubdtype(a.dtype, np.integer) or a.dtype == np.bool_:
        out = a.astype(np.int64)
        miss = (out == int(empty)) if empty is not None else np.zeros(a.shape, bool)
    else:
        raise InputError(f"{where}labels: dtype {a.dtype} is not a label type")
    if ((out == EMPTY) & ~miss).any():
        raise InputError(f"{where}labels: code {EMPTY} is reserved for empty; pass empty=-1 "
                         "if it means empty")
    if out.size and (out.min() < -(2**31) or out.max() >= 2**31):
        raise InputError(f"{where}labels: codes must fit in int32")
    out[miss] = EMPTY
    return out.astype(np.int32)


def interval_counts(labels, empty=None) -> np.ndarray:
    """Intervals per column of a ``(nz, ny, nx)`` label array, as ``(ny, nx)`` int64.

    The count is the number of runs of equal values along z, not counting a leading run of
    empties (the canonical stack of :func:`voxels_to_stacks`).

    Examples
    --------
    >>> a = np.array([[[1]], [[1]], [[2]], [[0]]])       # z = 0..3 of one column
    >>> interval_counts(a, empty=0).tolist()             # runs 1 1 | 2 | 0
    [[3]]
    """
    a = _to_codes(np.asarray(labels), empty, "")
    start = np.empty(a.shape, bool)
    start[0] = a[0] != EMPTY
    start[1:] = a[1:] != a[:-1]
    return start.sum(axis=0, dtype=np.int64)


def voxels_to_stacks(labels, empty=None, spacing=(1.0, 1.0, 1.0), origin=(0.0, 0.0, 0.0),
                     legend: Legend | None = None, crs: str = "", unit: str = "",
                     name: str = "", progress=None) -> StackModel:
    """Convert a labelled voxel model to stacks (exactly; see :func:`stacks_to_voxels`).

    Parameters
    ----------
    labels : (nz, ny, nx) array
        Integer or float material codes, z up (numpy, memmap or dask; read in y-slabs).
    empty : number, optional
        The value meaning empty. NaN always means empty in float arrays.
    spacing, origin : 3 floats
        Voxel size (dx, dy, dz) and the world position of voxel (0, 0, 0)'s corner.
    legend : Legend, optional
        Default: generated for the codes present.
    progress : callable(done, total), optional

    Returns
    -------
    StackModel
        ``nlevels = nz``, one canonical stack per column.

    Examples
    --------
    >>> a = np.zeros((4, 1, 2), np.int16)               # 2 columns, 4 levels
    >>> a[:2, 0, 0] = 5; a[1:, 0, 1] = 6; a[3, 0, 1] = 7
    >>> m = voxels_to_stacks(a, empty=0)
    >>> m.offsets.tolist(), m.starts.tolist(), m.codes.tolist()
    ([0, 2, 4], [0.0, 2.0, 1.0, 3.0], [5, -1, 6, 7])
    """
    shape = getattr(labels, "shape", None)
    if shape is None or len(shape) != 3:
        raise InputError(f"{name + ': ' if name else ''}labels: expected a 3D array (nz, ny, nx),"
                         f" got shape {shape}")
    nz, ny, nx = (int(s) for s in shape)
    where = f"{name}: " if name else ""
    rows = max(1, SLAB_CELLS // max(1, nz * nx))
    starts, codes, counts = [], [], []
    for y0 in range(0, ny, rows):
        block = labels[:, y0:y0 + rows, :]
        if hasattr(block, "compute"):
            block = block.compute()
        a = _to_codes(block, empty, where).reshape(nz, -1)
        start = np.empty(a.shape, bool)
        start[0] = a[0] != EMPTY
        start[1:] = a[1:] != a[:-1]
        st = start.T  # (columns, nz): nonzero walks columns in order, z ascending in each
        col, z = np.nonzero(st)
        counts.append(st.sum(axis=1, dtype=np.int64))
        starts.append(z.astype(np.float32))
        codes.append(a[z, col])
        if progress is not None:
            progress(min(ny, y0 + rows), ny)
    cnt = np.concatenate(counts)
    offsets = np.concatenate([[0], np.cumsum(cnt)]).astype(np.int64)
    s = np.concatenate(starts)
    c = np.concatenate(codes).astype(np.int32)
    if legend is None:
        legend = Legend.from_codes(np.unique(c))
    return StackModel(offsets=offsets, starts=s, codes=c, shape=(nx, ny), nlevels=nz,
                      legend=legend, origin=tuple(origin), spacing=tuple(spacing), crs=crs,
                      unit=unit, name=name)


# ==============================================================================================
# stacks -> voxels
# ==============================================================================================
def stacks_to_voxels(model: StackModel, dtype=np.int32, fill=EMPTY, region=None) -> np.ndarray:
    """The voxel model of ``model``: level ``k`` takes the code of the interval holding k + ½.

    Parameters
    ----------
    dtype : numpy dtype
        Output dtype (float types turn EMPTY into ``fill``, NaN by default for floats).
    fill : number
        Value of empty voxels (default EMPTY, or NaN for a float dtype).
    region : (x0, x1, y0, y1, z0, z1), optional
        Only this sub-box of columns and levels.

    Returns
    -------
    (nz, ny, nx) array
        The exact inverse of :func:`voxels_to_stacks` for models with integer heights.

    Examples
    --------
    >>> a = np.array([[[5, 0]], [[5, 6]], [[0, 6]], [[0, 7]]], np.int16)
    >>> m = voxels_to_stacks(a, empty=0)
    >>> np.array_equal(stacks_to_voxels(m, np.int16, fill=0), a)
    True
    """
    nx, ny = model.shape
    x0, x1, y0, y1, z0, z1 = region if region is not None else (0, nx, 0, ny, 0, model.nlevels)
    dtype = np.dtype(dtype)
    if np.issubdtype(dtype, np.floating) and fill == EMPTY:
        fill = np.nan
    nzr, nyr, nxr = z1 - z0, y1 - y0, x1 - x0
    if model.nintervals and bool((model.starts == np.round(model.starts)).all()):
        return _fill_integer(model, dtype, fill, (x0, x1, y0, y1, z0, z1))
    out = np.empty((nzr, nyr, nxr), dtype)
    if model.codes.size == 0:  # nothing but air
        out.fill(fill)
        return out
    L = float(model.nlevels + 1)
    keys = model.column_ids().astype(np.float64) * L + model.starts.astype(np.float64)
    zc = np.arange(z0, z1, dtype=np.float64) + 0.5
    rows = max(1, SLAB_CELLS // max(1, nzr * nxr))
    ix = np.arange(x0, x1, dtype=np.int64)
    for ya in range(y0, y1, rows):
        yb = min(y1, ya + rows)
        cols = (ix[None, :] + nx * np.arange(ya, yb, dtype=np.int64)[:, None]).ravel()
        q = cols[:, None] * L + zc[None, :]
        idx = np.searchsorted(keys, q.ravel(), side="right").reshape(q.shape) - 1
        valid = idx >= model.offsets[cols][:, None]
        vals = np.where(valid, model.codes[np.maximum(idx, 0)], EMPTY)
        block = vals.T.reshape(nzr, yb - ya, nxr)
        if fill == EMPTY and not np.issubdtype(dtype, np.floating):
            out[:, ya - y0:yb - y0, :] = block
        else:
            out[:, ya - y0:yb - y0, :] = np.where(block == EMPTY, fill, block)
    return out


def _fill_integer(model: StackModel, dtype, fill, region) -> np.ndarray:
    """:func:`stacks_to_voxels` for whole-level heights: each interval writes its run of
    levels (``np.repeat``), in slabs of rows."""
    x0, x1, y0, y1, z0, z1 = region
    nx = model.shape[0]
    nzr, nyr, nxr = z1 - z0, y1 - y0, x1 - x0
    out = np.empty((nzr, nyr, nxr), dtype)
    starts = model.starts.astype(np.int64)
    ends = model.ends().astype(np.int64)
    rows = max(1, SLAB_CELLS // max(1, nzr * nxr))
    ix = np.arange(x0, x1, dtype=np.int64)
    for ya in range(y0, y1, rows):
        yb = min(y1, ya + rows)
        cols = (ix[None, :] + nx * np.arange(ya, yb, dtype=np.int64)[:, None]).ravel()
        cnt = model.offsets[cols + 1] - model.offsets[cols]
        idx = np.repeat(model.offsets[cols] - np.concatenate([[0], np.cumsum(cnt)[:-1]]),
                        cnt) + np.arange(int(cnt.sum()))       # intervals of these columns
        local = np.repeat(np.arange(cols.size, dtype=np.int64), cnt)
        s = np.clip(starts[idx], z0, z1)
        e = np.clip(ends[idx], z0, z1)
        length = e - s
        flat = np.full(cols.size * nzr, EMPTY, np.int32)
        first = local * nzr + (s - z0)
        total = int(length.sum())
        off = np.repeat(first - np.concatenate([[0], np.cumsum(length)[:-1]]), length)
        flat[off + np.arange(total)] = np.repeat(model.codes[idx], length)
        block = flat.reshape(cols.size, nzr).T.reshape(nzr, yb - ya, nxr)
        if fill == EMPTY and not np.issubdtype(dtype, np.floating):
            out[:, ya - y0:yb - y0, :] = block
        else:
            out[:, ya - y0:yb - y0, :] = np.where(block == EMPTY, fill, block)
    return out


# ==============================================================================================
# boreholes
# ==============================================================================================
def _group_cummin(values: np.ndarray, groups: np.ndarray) -> np.ndarray:
    """Running minimum of ``values`` restarting at each new group (groups sorted ascending)."""
    if values.size == 0:
        return values.copy()
    span = float(np.ptp(values)) + 1.0
    g = np.unique(groups, return_inverse=True)[1].astype(np.float64)
    shifted = values - g * span
    return np.minimum.accumulate(shifted) + g * span


def place_boreholes(model: StackModel, logs: BoreholeLogs, strict: bool = False) -> StackModel:
    """Put borehole logs into the model's columns: each becomes a flagged borehole column.

    A borehole's layers replace the stack of the column that holds its (x, y) over the log's
    depth range: above the log's top is air, below its bottom the model's intervals stay
    (``log_base`` of the column marks where the log starts). Where several boreholes fall into
    one column, the deepest one is used. Layers are clipped to the model's vertical extent;
    gaps in a log become EMPTY intervals; neighbouring layers of one code are merged.

    Parameters
    ----------
    strict : bool
        Overlapping layers in one log raise InputError (True) or are clipped so that each layer
        ends where the layer above it starts (False, the default for real logs).

    Returns
    -------
    StackModel
        A new model; ``meta["boreholes"]`` says how many were placed, outside the grid, left out
        as duplicates of a column, and how many layers were clipped.

    Examples
    --------
    >>> m = voxels_to_stacks(np.full((4, 1, 2), 1, np.int8))
    >>> logs = BoreholeLogs(["B"] * 2, [1.5, 1.5], [0.5, 0.5], [3.0, 1.0], [1.0, 0.5], [9, 8])
    >>> b = place_boreholes(m, logs)
    >>> b.borehole.tolist(), b.codes[b.offsets[1]:].tolist(), b.starts[b.offsets[1]:].tolist()
    ([False, True], [1, 8, 9, -1], [0.0, 0.5, 1.0, 3.0])
    >>> b.log_base.tolist(), b.log_intervals()[b.offsets[1]:].tolist()
    ([0.0, 0.5], [False, True, True, True])
    """
    nx, ny = model.shape
    dx, dy, dz = model.spacing
    x0, y0, z0 = model.origin
    where = f"{logs.name}: " if logs.name else ""
    ix = np.floor((logs.x - x0) / dx).astype(np.int64)
    iy = np.floor((logs.y - y0) / dy).astype(np.int64)
    inside = (ix >= 0) & (ix < nx) & (iy >= 0) & (iy < ny)
    ids, inv = np.unique(logs.borehole, return_inverse=True)
    bh_inside = np.zeros(ids.size, bool)
    np.logical_or.at(bh_inside, inv, inside)
    col = ix + nx * iy
    # one borehole per column: the deepest
    bh_col = np.full(ids.size, -1, np.int64)
    bh_col[inv[inside]] = col[inside]
    bh_bottom = np.full(ids.size, np.inf)
    np.minimum.at(bh_bottom, inv, logs.bottom)
    cand = np.nonzero(bh_col >= 0)[0]
    order = cand[np.lexsort((bh_bottom[cand], bh_col[cand]))]
    first = np.ones(order.size, bool)
    first[1:] = bh_col[order][1:] != bh_col[order][:-1]
    chosen = np.zeros(ids.size, bool)
    chosen[order[first]] = True
    rows = chosen[inv] & inside
    lo = ((logs.bottom[rows] - z0) / dz).astype(np.float32)
    hi = ((logs.top[rows] - z0) / dz).astype(np.float32)
    cd = logs.code[rows]
    lc = col[rows]
    name = ids[inv[rows]]
    if strict:
        bad = ~(hi > lo)
        if bad.any():
            i = int(np.argmax(bad))
            raise InputError(f"{where}borehole {name[i]}: layer with top {logs.top[rows][i]:g} "
                             f"<= bottom {logs.bottom[rows][i]:g} (non-monotonic)")
    lo, hi = np.clip(lo, 0, model.nlevels), np.clip(hi, 0, model.nlevels)
    keep = hi > lo
    lo, hi, cd, lc, name = lo[keep], hi[keep], cd[keep], lc[keep], name[keep]
    order = np.lexsort((-hi, lc))  # per column, from the top down
    lo, hi, cd, lc, name = lo[order], hi[order], cd[order], lc[order], name[order]
    same = np.zeros(lc.size, bool)
    same[1:] = lc[1:] == lc[:-1]
    prev_lo = np.full(lc.size, np.inf, np.float32)
    prev_lo[1:] = _group_cummin(lo.astype(np.float64), lc)[:-1]
    prev_lo[~same] = np.inf
    over = hi > prev_lo + 1e-9
    if strict and over.any():
        i = int(np.argmax(over))
        raise InputError(f"{where}borehole {name[i]}: layer [{lo[i] * dz + z0:g}, "
                         f"{hi[i] * dz + z0:g}] m overlaps the layer above it (overlapping)")
    clipped = int(over.sum())
    hi = np.minimum(hi, prev_lo)
    keep = hi > lo
    log_legend = logs.legend if logs.legend is not None else Legend.from_codes(logs.code)
    legend = merge_legends(model.legend, log_legend)
    lc, lo, hi, cd = lc[keep], lo[keep], hi[keep], cd[keep]
    log = StackModel.from_layers(model.shape, model.nlevels, lc, lo, hi, cd,
                                 legend=legend).canonical()
    # splice: the log over its depth range, the model's intervals below the log's bottom
    cols = np.unique(lc)
    base = np.full(model.ncols, np.inf, np.float32)
    np.minimum.at(base, lc, lo)
    mcol = model.column_ids()
    below = np.isfinite(base[mcol]) & (model.starts < base[mcol])
    lcol = log.column_ids()
    k = np.concatenate([mcol[below], lcol])
    order = np.argsort(k, kind="stable")
    spliced = StackModel(
        offsets=np.concatenate([[0], np.cumsum(np.bincount(k, minlength=model.ncols))]),
        starts=np.concatenate([model.starts[below], log.starts])[order],
        codes=np.concatenate([model.codes[below], log.codes])[order], shape=model.shape,
        nlevels=model.nlevels, legend=legend)
    out = model.replace_columns(cols, spliced, flag_boreholes=True, log_base=base[cols])
    out.meta["boreholes"] = {
        "boreholes": int(ids.size), "placed": int(chosen.sum()),
        "outside": int((~bh_inside).sum()),
        "duplicates": int(bh_inside.sum() - chosen.sum()), "layers_clipped": clipped,
        "columns": int(np.unique(lc).size)}
    return out


# ==============================================================================================
# the GPU form and the layouts of Section 4.2
# ==============================================================================================
@dataclass
class GpuIntervals:
    """The stacks as the GPU layouts hold them (the paper's "accumulated height" form).

    Each column's intervals, bottom-up from level 0: ``(material, end)``; interval ``i`` spans
    ``[end[i-1], end[i])`` with ``end[-1] = 0``. A leading empty range is an explicit EMPTY
    interval; the air above a column's top is not stored.

    first:  (ncols,) int64   index of the column's first interval
    count:  (ncols,) int64   intervals of the column
    flag:   (ncols,) bool    borehole column
    mat:    (n,) int32       palette index: 0 = empty, ``1 + i`` = the legend's i-th material
    end:    (n,) float32     accumulated height (levels)
    log:    (n,) bool        the interval comes from a borehole log
    """

    first: np.ndarray
    count: np.ndarray
    flag: np.ndarray
    mat: np.ndarray
    end: np.ndarray
    log: np.ndarray
    shape: tuple[int, int]
    nlevels: int

    @property
    def n(self) -> int:
        return int(self.end.size)

    @property
    def max_count(self) -> int:
        return int(self.count.max(initial=0))

    @property
    def ztop(self) -> float:
        return float(self.end.max(initial=0.0))


def gpu_intervals(model: StackModel) -> GpuIntervals:
    """Convert to the GPU form (see :class:`GpuIntervals`).

    Examples
    --------
    >>> m = StackModel([0, 3], [2, 3, 5], [4, 6, EMPTY], (1, 1), 8)
    >>> g = gpu_intervals(m)
    >>> g.mat.tolist(), g.end.tolist(), g.count.tolist()
    ([0, 1, 2], [2.0, 3.0, 5.0], [3])
    """
    cnt = model.counts()
    col = model.column_ids()
    n = model.nintervals
    has = cnt > 0
    last = model.offsets[1:][has] - 1
    drop = np.zeros(n, bool)
    drop[last] = model.codes[last] == EMPTY
    first_idx = model.offsets[:-1][has]
    lead_cols = np.nonzero(has)[0][model.starts[first_idx] > 0]
    lead_start = model.starts[model.offsets[:-1][lead_cols]]
    keep = ~drop
    k = np.concatenate([lead_cols, col[keep]])
    mat = np.concatenate([np.zeros(lead_cols.size, np.int32),
                          model.legend.index_of(model.codes[keep])])
    end = np.concatenate([lead_start, model.ends()[keep]]).astype(np.float32)
    log = np.concatenate([np.zeros(lead_cols.size, bool), model.log_intervals()[keep]])
    order = np.argsort(k, kind="stable")
    count = np.bincount(k, minlength=model.ncols).astype(np.int64)
    first = np.concatenate([[0], np.cumsum(count)[:-1]]).astype(np.int64)
    return GpuIntervals(first=first, count=count, flag=model.borehole.copy(), mat=mat[order],
                        end=end[order], log=log[order], shape=model.shape,
                        nlevels=model.nlevels)


def min_perimeter_rect(m: int) -> tuple[int, int]:
    """Eq. (3): ``argmin w + h`` subject to ``w·h >= m`` (ties: the smaller area), ``w >= h``.

    >>> min_perimeter_rect(5), min_perimeter_rect(10), min_perimeter_rect(16)
    ((3, 2), (5, 2), (4, 4))
    """
    m = max(1, int(m))
    h = np.arange(1, math.isqrt(m) + 2)
    w = -(-m // h)
    key = (w + h) * (4 * m + 4) + w * h
    i = int(np.argmin(key))
    return int(max(w[i], h[i])), int(min(w[i], h[i]))


def exact_rect(n: int, limit: int) -> tuple[int, int]:
    """The 1-Textures intervals texture: ``w·h = n'`` exactly, ``n' >= n`` the first that
    factorises with both sides ``<= limit`` (a prime n' is skipped: the paper adds one).

    >>> exact_rect(309433, 16384)          # the paper's Dataset A: 309433 is prime
    (646, 479)
    """
    n = max(1, int(n))
    if n > limit * limit:
        raise GPUMemoryError(f"textures layout: {n:,} intervals exceed a {limit}×{limit} "
                             "texture; use the ssbo layout")
    for cand in range(n, n + 4 * limit):
        h = np.arange(1, math.isqrt(cand) + 1)
        h = h[cand % h == 0]
        w = cand // h
        ok = (w <= limit) & ((h > 1) | (cand <= limit and cand == n))
        if ok.any():
            i = int(np.nonzero(ok)[0][-1])
            return int(w[i]), int(h[i])
    raise GPUMemoryError(f"textures layout: no texture of at most {limit}² holds {n:,} "
                         "intervals")  # pragma: no cover


def layout_plan(layout: str, shape, n: int, m: int, limits: dict | None = None) -> dict:
    """Texture/buffer shapes and the memory of one layout (the paper's Table 3).

    Parameters
    ----------
    layout : one of :data:`LAYOUTS`
    shape : (nx, ny)
    n : int
        GPU intervals (:attr:`GpuIntervals.n`).
    m : int
        Most intervals in one column (:attr:`GpuIntervals.max_count`).
    limits : dict, optional
        ``max_texture_size``, ``max_3d_texture_size``, ``max_ssbo_bytes`` (the GPU's; default
        :data:`DEFAULT_LIMITS`).

    Returns
    -------
    dict
        ``layout``, ``objects`` (name -> shape), ``consumed`` and ``wasted`` bytes, ``super``
        (supertexel w, h) where it applies.

    Raises
    ------
    GPUMemoryError
        The layout exceeds a texture or buffer limit; the message names the limit and a layout
        that fits.

    Examples
    --------
    >>> p = layout_plan("r-supertexels", (200, 250), 309433, 10)   # Dataset A
    >>> p["objects"]["intervals"], round(p["consumed"] / 2**20, 2), round(p["wasted"] / 2**20, 2)
    ((1000, 500), 1.91, 0.73)
    >>> round(layout_plan("ssbo", (200, 250), 309433, 10)["consumed"] / 2**20, 2)
    1.56
    """
    if layout not in LAYOUTS:
        raise InputError(f"layout: unknown layout {layout!r}; expected one of "
                         f"{', '.join(LAYOUTS)}")
    lim = {**DEFAULT_LIMITS, **(limits or {})}
    nx, ny = (int(v) for v in shape)
    ncols, m = nx * ny, max(1, int(m))
    t2, t3, sb = lim["max_texture_size"], lim["max_3d_texture_size"], lim["max_ssbo_bytes"]
    name = LAYOUT_NAMES[layout]
    hint = "use the ssbo or textures layout"

    def too_big(what: str, w: int, h: int, lim_: int, d: int | None = None) -> GPUMemoryError:
        dims = f"{w}×{h}" + (f"×{d}" if d else "")
        return GPUMemoryError(f"layout {layout} ({name}): the {what} texture would be {dims}, "
                              f"beyond this GPU's limit of {lim_} per side; {hint}")

    plan = {"layout": layout, "name": name, "intervals": int(n), "max_intervals": m,
            "super": None}
    if layout in ("textures", "ssbo"):
        if layout == "textures":
            if nx > t2 or ny > t2:
                raise too_big("indices", nx, ny, t2)
            w, h = exact_rect(n, t2)
            plan["objects"] = {"indices": (nx, ny), "intervals": (w, h)}
            slots = w * h
        else:
            for what, nbytes in (("indices", ncols * INDEX_BYTES), ("intervals",
                                                                    n * INTERVAL_BYTES)):
                if nbytes > sb:
                    raise GPUMemoryError(f"layout ssbo: the {what} buffer needs "
                                         f"{nbytes / 2**20:.1f} MiB, beyond this GPU's SSBO "
                                         f"limit of {sb / 2**20:.0f} MiB")
            plan["objects"] = {"indices": (ncols,), "intervals": (max(n, 1),)}
            slots = max(n, 1)
        plan["consumed"] = ncols * INDEX_BYTES + slots * INTERVAL_BYTES
        plan["wasted"] = (slots - n) * INTERVAL_BYTES
        return plan
    if layout == "r-supertexels":
        a, b = min_perimeter_rect(m)
        if nx * a > t2 or ny * b > t2:
            raise too_big("intervals", nx * a, ny * b, t2)
        plan["objects"] = {"intervals": (nx * a, ny * b)}
        plan["super"] = (a, b)
        slots = a * b
    elif layout == "l-supertexels":
        if nx * m > t2 or ny > t2:
            raise too_big("intervals", nx * m, ny, t2)
        plan["objects"] = {"intervals": (nx * m, ny)}
        slots = m
    else:  # texture3d
        if max(nx, ny, m) > t3:
            raise too_big("intervals", nx, ny, t3, m)
        plan["objects"] = {"intervals": (nx, ny, m)}
        slots = m
    plan["slots"] = slots
    plan["consumed"] = ncols * slots * INTERVAL_BYTES
    plan["wasted"] = (ncols * slots - n) * INTERVAL_BYTES
    return plan


def memory_table(model: StackModel, voxel_bytes: int = 4) -> dict:
    """Table 1 of the paper for one model (octree apart: :mod:`geoshade.compute.voxels.octree`).

    ``bytes_voxels`` is the dense model at ``voxel_bytes`` per voxel (4 as in the paper),
    ``bytes_stacks`` the compact stacks as the paper counts them (8 B per column index, 4 B per
    interval: the consumed memory of 1-Textures / 5-SSBO).

    >>> m = voxels_to_stacks(np.ones((10, 3, 4), np.int8))
    >>> t = memory_table(m); t["bytes_voxels"], t["bytes_stacks"]
    (480, 144)
    """
    g = gpu_intervals(model)
    bv = model.ncols * model.nlevels * voxel_bytes
    bs = model.ncols * INDEX_BYTES + g.n * INTERVAL_BYTES
    return {"columns": model.ncols, "intervals": model.nintervals, "gpu_intervals": g.n,
            "max_intervals": g.max_count, "bytes_voxels": bv, "bytes_stacks": bs,
            "saving_vs_voxels": 1.0 - bs / bv}


# ==============================================================================================
# synthetic layered models (generated as stacks: no voxels needed)
# ==============================================================================================
def _smooth_field(nx: int, ny: int, rng, waves: int = 6) -> np.ndarray:
    """(ny, nx) smooth random field in about [-1, 1]: a sum of random plane waves."""
    x = np.arange(nx, dtype=np.float32)[None, :] / max(nx, 1)
    y = np.arange(ny, dtype=np.float32)[:, None] / max(ny, 1)
    f = np.zeros((ny, nx), np.float32)
    for _ in range(waves):
        kx, ky = rng.normal(0, 3.0, 2)
        ph = rng.uniform(0, 2 * np.pi)
        f += np.sin(2 * np.pi * (kx * x + ky * y) + ph).astype(np.float32)
    return f / math.sqrt(waves / 2)


def synthetic_layers(nx: int, ny: int, nz: int, max_intervals: int = 10,
                     mean_intervals: float | None = None, seed: int = 0,
                     spacing=(1.0, 1.0, 1.0)) -> StackModel:
    """A layer-cake model with pinch-outs and relief, built directly as stacks.

    ``max_intervals`` layers lie on a flat bottom, under air; the deepest is everywhere, each
    other layer is present in a fraction of the columns (pinch-outs) so that the mean number of
    layers per column is about ``mean_intervals`` (the GPU intervals per column; the air above
    adds one interval per column on the CPU side), and column (0, 0) holds all of them.
    Every present layer is at least one level thick and heights are whole levels, so
    :func:`stacks_to_voxels` gives its exact voxel model.

    Examples
    --------
    >>> m = synthetic_layers(20, 10, 32, max_intervals=6, seed=1)
    >>> m.shape, m.nlevels, m.max_intervals, int(m.counts().min()) >= 2
    ((20, 10), 32, 7, True)
    """
    rng = np.random.default_rng(seed)
    L = max(1, int(max_intervals))
    if mean_intervals is None:
        mean_intervals = 0.62 * L
    present = float(np.clip((mean_intervals - 1) / max(L - 1, 1), 0.02, 1.0))
    thick = np.zeros((L, ny, nx), np.float32)
    for k in range(L):
        f = _smooth_field(nx, ny, rng)
        cut = np.quantile(f, 1.0 - present) if (present < 1 and k > 0) else -np.inf
        on = f > cut
        on[0, 0] = True
        thick[k] = np.where(on, 1.0 + 0.5 * np.tanh(f - cut if k else f) + 0.5, 0.0)
    top_target = 0.8 * nz * (1.0 + 0.1 * _smooth_field(nx, ny, rng))
    scale = top_target / thick.sum(axis=0)
    lev = np.where(thick > 0, np.maximum(1, np.round(thick * scale[None])), 0).astype(np.int64)
    bounds = np.concatenate([np.zeros((1, ny, nx), np.int64), np.cumsum(lev, axis=0)])
    bounds = np.minimum(bounds, nz - 1)  # always air above the surface
    lo, hi = bounds[:-1], bounds[1:]
    present_mask = hi > lo
    surface = bounds[-1].ravel()
    codes = np.broadcast_to(np.arange(1, L + 1, dtype=np.int32)[:, None, None], lo.shape)
    colk = np.broadcast_to(np.arange(nx * ny).reshape(ny, nx)[None], lo.shape)
    kk = np.concatenate([colk[present_mask], np.arange(nx * ny)])
    ss = np.concatenate([lo[present_mask], surface])
    cc = np.concatenate([codes[present_mask], np.full(nx * ny, EMPTY, np.int32)])
    order = np.lexsort((ss, kk))
    offsets = np.concatenate([[0], np.cumsum(np.bincount(kk, minlength=nx * ny))])
    rgb = np.array([[166, 206, 227], [31, 120, 180], [178, 223, 138], [51, 160, 44],
                    [251, 154, 153], [227, 26, 28], [253, 191, 111], [255, 127, 0],
                    [202, 178, 214], [106, 61, 154], [255, 255, 153], [177, 89, 40]])
    rgba = np.concatenate([rgb[np.arange(L) % len(rgb)], np.full((L, 1), 255)], axis=1)
    legend = Legend(np.arange(1, L + 1), tuple(f"layer {k}" for k in range(1, L + 1)), rgba)
    return StackModel(offsets=offsets, starts=ss[order], codes=cc[order], shape=(nx, ny),
                      nlevels=nz, legend=legend, spacing=tuple(spacing),
                      name=f"synthetic {nx}×{ny}×{nz}", meta={"seed": seed})
