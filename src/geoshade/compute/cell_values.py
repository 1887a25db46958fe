"""What a colour scale needs to know of a property over the active cells, in one bounded pass.

A colour bar's range (linear or log), the automatic log decision and the count of cells without
a value depend on *every* active cell, while the GPU only needs the colours of the cells with a
visible face.  :func:`summarise` reads the property once, k-slab by k-slab (no float64 copy of a
1e8-cell array), and the view colours only the cells it draws.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: cells per slab
SLAB_CELLS = 1 << 22
#: from this many cells on, one compiled pass (numba) instead of numpy slabs
KERNEL_CELLS = 1 << 22


@dataclass(frozen=True)
class ValueSummary:
    """Finite and positive extremes of a property over the active cells.

    lo, hi:            finite min/max (NaN when no active cell has a finite value)
    pos_lo, pos_hi:    min/max of the finite positive values (NaN when there is none)
    nonfinite:         active cells whose value is NaN or infinite
    nonpositive:       active cells with a finite value <= 0 (no value on a log scale)
    count:             active cells
    """

    lo: float
    hi: float
    pos_lo: float
    pos_hi: float
    nonfinite: int
    nonpositive: int
    count: int

    def extremes(self, log: bool = False) -> np.ndarray:
        """The (at most two) values whose range is the property's: what
        :meth:`ColorStyle.default_range` and :meth:`ColorStyle.resolved` need to see."""
        a, b = (self.pos_lo, self.pos_hi) if log else (self.lo, self.hi)
        return np.array([a, b]) if np.isfinite(a) else np.zeros(0)

    def gaps(self, log: bool = False) -> int:
        """Active cells without a colour-scale value (log: non-positive ones too)."""
        return self.nonfinite + (self.nonpositive if log else 0)


def summarise(values, active=None) -> ValueSummary:
    """:class:`ValueSummary` of ``values`` (nx, ny, nz) over the ``active`` cells (default all);
    numpy (slabs, or one compiled pass from :data:`KERNEL_CELLS` cells on) or dask (chunk by
    chunk: a grid store's property, ``active`` its ACTNUM).

    Examples
    --------
    >>> v = np.array([[[0.5, -1.0, np.nan, 20.0]]])
    >>> s = summarise(v, np.array([[[1, 1, 1, 0]]], bool))
    >>> (s.lo, s.hi, s.pos_lo, s.pos_hi, s.nonfinite, s.nonpositive, s.count)
    (-1.0, 0.5, 0.5, 0.5, 1, 1, 3)
    """
    if not isinstance(values, np.ndarray) and hasattr(values, "chunks") and active is not None:
        return _summarise_dask(values, active)
    v = np.asarray(values)
    act = None if active is None else np.asarray(active)
    if act is not None and act.dtype != bool:  # ACTNUM as given (0/1): a mask, not indices
        act = act != 0
    if act is not None and v.shape == act.shape and v.size >= KERNEL_CELLS \
            and v.dtype.kind == "f" and v.flags.f_contiguous and act.flags.f_contiguous:
        from geoshade.compute import grid_kernels_numba as k

        a = act.view(np.uint8) if act.dtype == bool else act
        out = k.value_summary(v.reshape(-1, order="F"), a.reshape(-1, order="F"))
        nan = float("nan")
        lo, hi, plo, phi = (float(x) for x in out[:4])
        return ValueSummary(lo if lo <= hi else nan, hi if lo <= hi else nan,
                            plo if plo <= phi else nan, phi if plo <= phi else nan,
                            int(out[4]), int(out[5]), int(out[6]))
    nz = v.shape[2] if v.ndim == 3 else 1
    per = max(1, int(np.prod(v.shape[:2])) if v.ndim == 3 else v.size)
    step = max(1, SLAB_CELLS // per)
    lo = pos_lo = np.inf
    hi = pos_hi = -np.inf
    nonfinite = nonpositive = count = 0
    for k0 in range(0, nz, step):  # slabs of layers, not cells
        s = v[:, :, k0:k0 + step] if v.ndim == 3 else v
        if act is not None:
            s = s[act[:, :, k0:k0 + step] if v.ndim == 3 else act]
        s = np.asarray(s).ravel()
        count += s.size
        fin = np.isfinite(s)
        nf = int(np.count_nonzero(fin))
        nonfinite += s.size - nf
        if nf:
            f = s[fin] if nf < s.size else s
            lo, hi = min(lo, float(f.min())), max(hi, float(f.max()))
            pos = f[f > 0]
            nonpositive += f.size - pos.size
            if pos.size:
                pos_lo, pos_hi = min(pos_lo, float(pos.min())), max(pos_hi, float(pos.max()))
    nan = float("nan")
    return ValueSummary(lo if lo <= hi else nan, hi if lo <= hi else nan,
                        pos_lo if pos_lo <= pos_hi else nan, pos_hi if pos_lo <= pos_hi else nan,
                        nonfinite, nonpositive, count)


def summary_part(values, active=None) -> np.ndarray:
    """``(7,)`` float64 partial summary of one block (a chunk, an ingest slab) of ``values``
    over its ``active`` cells (0/1 or bool, same shape; default all): lo, hi, pos_lo, pos_hi
    (±inf when there is none), nonfinite, nonpositive, count.  One compiled pass over the
    block in its own memory order; :func:`combine` joins parts exactly as one pass would.

    Examples
    --------
    >>> summary_part(np.array([[[2.0, -1.0, np.nan]]]), np.array([[[1, 1, 0]]])).tolist()
    [-1.0, 2.0, 2.0, 2.0, 0.0, 1.0, 2.0]
    """
    from geoshade.compute import grid_kernels_numba as k

    v = np.asarray(values)
    a = (np.ones(v.shape, np.uint8) if active is None
         else np.asarray(active).view(np.uint8) if np.asarray(active).dtype == bool
         else np.asarray(active))
    if a.shape != v.shape:
        raise ValueError(f"summary_part: active has shape {a.shape}, values {v.shape}")
    if v.dtype.kind != "f":  # integer properties: their values as float64 (as summarise does)
        v = v.astype(np.float64)
    order = "F" if v.flags.f_contiguous and not v.flags.c_contiguous else "C"
    out = k.value_summary(v.ravel(order=order), a.astype(np.uint8, copy=False).ravel(
        order=order))
    return np.array(out, np.float64)


def combine(parts) -> ValueSummary:
    """One :class:`ValueSummary` from :func:`summary_part` rows ((m, 7), or a list of them):
    extremes of the extremes, sums of the counts (exact: the same as one pass)."""
    p = np.asarray(parts, np.float64).reshape(-1, 7)
    nan = float("nan")
    if not len(p):
        return ValueSummary(nan, nan, nan, nan, 0, 0, 0)
    lo, hi = float(p[:, 0].min()), float(p[:, 1].max())
    plo, phi = float(p[:, 2].min()), float(p[:, 3].max())
    return ValueSummary(lo if lo <= hi else nan, hi if lo <= hi else nan,
                        plo if plo <= phi else nan, phi if plo <= phi else nan,
                        int(p[:, 4].sum()), int(p[:, 5].sum()), int(p[:, 6].sum()))


def part_to_json(part) -> list:
    """A :func:`summary_part` row as JSON numbers (±inf as None: JSON has no infinities)."""
    return [float(x) if np.isfinite(x) else None for x in np.asarray(part, np.float64)[:4]] \
        + [int(x) for x in np.asarray(part)[4:7]]


def part_from_json(row) -> np.ndarray:
    """The inverse of :func:`part_to_json` (None: +inf for a minimum, -inf for a maximum)."""
    if not isinstance(row, (list, tuple)) or len(row) != 7:
        raise ValueError(f"expected 7 numbers, got {row!r}")
    fill = (np.inf, -np.inf, np.inf, -np.inf)
    return np.array([fill[i] if row[i] is None else float(row[i]) for i in range(4)]
                    + [float(int(x)) for x in row[4:]], np.float64)


def summary_to_json(s: ValueSummary) -> list:
    """A :class:`ValueSummary` as the row :func:`part_from_json` reads (NaN extremes: None)."""
    return [None if not np.isfinite(x) else float(x) for x in (s.lo, s.hi, s.pos_lo,
                                                                s.pos_hi)] \
        + [int(s.nonfinite), int(s.nonpositive), int(s.count)]


def summary_from_json(row) -> ValueSummary:
    """A :class:`ValueSummary` from :func:`summary_to_json`'s row (raises ValueError)."""
    return combine(part_from_json(row))


def _block_summary(v, a):
    return summary_part(np.asarray(v), np.asarray(a, np.uint8)).reshape(1, 1, 1, 7)


def _summarise_dask(values, active) -> ValueSummary:
    """:func:`summarise` of a dask property (a grid store): one numba pass per chunk,
    combined (:func:`combine`); never a whole array in memory."""
    import dask.array as da

    v = da.asarray(values)
    a = da.asarray(active).astype(np.uint8).rechunk(v.chunks)
    parts = da.map_blocks(_block_summary, v, a, dtype=np.float64, new_axis=3,
                          chunks=(1, 1, 1, 7)).compute().reshape(-1, 7)
    return combine(parts)
