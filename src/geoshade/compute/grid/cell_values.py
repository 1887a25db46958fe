"""What a colour scale needs to know of a property over the active cells, in one bounded pass.

A colour bar's range (linear or log), the automatic log decision and the count of cells without
a value depend on *every* active cell, while the GPU only needs the colours of the cells with a
visible face.  :func:`summarise` reads the property once, k-slab by k-slab (no float64 copy of a
1e8-cell array), and the view colours only the cells it draws.
"""

from __future__ import annotations

import numpy as np

from geoshade.models.summary import (  # the summary's data and its exact combination
    SLAB_CELLS,
    ValueSummary,
    combine,
    part_from_json,
    part_to_json,
    summary_from_json,
    summary_part,
    summary_to_json,
)
from geoshade.scheduler import dask_get

__all__ = ["KERNEL_CELLS", "SLAB_CELLS", "ValueSummary", "combine", "kernel_part",
           "part_from_json", "part_to_json", "summarise", "summary_from_json", "summary_part",
           "summary_to_json"]

#: from this many cells on, one compiled pass (numba) instead of numpy slabs
KERNEL_CELLS = 1 << 22


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
        from geoshade.compute.grid import kernels_numba as k

        a = act.view(np.uint8) if act.dtype == bool else act
        return combine(k.value_summary(v.reshape(-1, order="F"), a.reshape(-1, order="F")))
    return combine(summary_part(v, act))


def kernel_part(values, active=None) -> np.ndarray:
    """:func:`geoshade.models.summary.summary_part` in one compiled pass over the block in its
    own memory order (a dask chunk).

    Examples
    --------
    >>> kernel_part(np.array([[[2.0, -1.0, np.nan]]]), np.array([[[1, 1, 0]]])).tolist()
    [-1.0, 2.0, 2.0, 2.0, 0.0, 1.0, 2.0]
    """
    from geoshade.compute.grid import kernels_numba as k

    v = np.asarray(values)
    a = (np.ones(v.shape, np.uint8) if active is None
         else np.asarray(active).view(np.uint8) if np.asarray(active).dtype == bool
         else np.asarray(active))
    if a.shape != v.shape:
        raise ValueError(f"kernel_part: active has shape {a.shape}, values {v.shape}")
    if v.dtype.kind != "f":  # integer properties: their values as float64 (as summarise does)
        v = v.astype(np.float64)
    a8 = a.astype(np.uint8, copy=False)
    if v.flags.f_contiguous and not v.flags.c_contiguous:  # both in v's own memory order
        out = k.value_summary(v.ravel(order="F"), a8.ravel(order="F"))
    else:
        out = k.value_summary(v.ravel(order="C"), a8.ravel(order="C"))
    return np.array(out, np.float64)


def _block_summary(v, a):
    return kernel_part(np.asarray(v), np.asarray(a, np.uint8)).reshape(1, 1, 1, 7)


def _summarise_dask(values, active) -> ValueSummary:
    """:func:`summarise` of a dask property (a grid store): one numba pass per chunk,
    combined (:func:`combine`); never a whole array in memory."""
    import dask.array as da

    v = da.asarray(values)
    a = da.asarray(active).astype(np.uint8).rechunk(v.chunks)
    parts = da.map_blocks(_block_summary, v, a, dtype=np.float64, new_axis=3,
                          chunks=(1, 1, 1, 7)).compute(scheduler=dask_get(None)).reshape(-1, 7)
    return combine(parts)
