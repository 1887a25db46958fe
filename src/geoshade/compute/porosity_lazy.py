"""Porosity out of core with an ROI: the dask graph of :func:`geoshade.compute.porosity.porosity`.

Each chunk evaluates the ROI from its own location (:mod:`geoshade.compute.roi`), so no
full-size mask exists; the result equals the in-memory slab loop bit for bit.
"""

from __future__ import annotations

import numpy as np

from geoshade.compute.lazy import as_dask, compute
from geoshade.compute.porosity import _AXES, PorosityResult, below_mask, result_from_counts
from geoshade.compute.selection import check_range, resolve_data_box, select
from geoshade.errors import InputError
from geoshade.progress import Progress


def _inside(roi, offset, shape, block_info):
    if roi is None:
        return None
    loc = block_info[0]["array-location"]
    zs, ys, xs = (slice(o + a, o + b) for o, (a, b) in zip(offset[::-1], loc, strict=True))
    return np.broadcast_to(roi.inside(zs, ys, xs), shape)


def _selected(block, lo, hi, roi, offset, block_info=None):
    sel = select(block, lo, hi)
    ins = _inside(roi, offset, block.shape, block_info)
    return sel if ins is None else sel & ins


def _low(block, lo, roi, offset, block_info=None):
    low = below_mask(np.asarray(block), lo)
    ins = _inside(roi, offset, block.shape, block_info)
    return low if ins is None else low & ins


def _in_roi(block, roi, offset, block_info=None):
    return np.array(_inside(roi, offset, block.shape, block_info))


def porosity(data, lo, hi, box=None, axis: str = "z", roi=None, scheduler=None,
             progress: Progress | None = None) -> PorosityResult:
    """:func:`geoshade.compute.porosity.porosity` (with ``roi``) as dask tasks on ``scheduler``.

    Examples
    --------
    >>> from geoshade.compute.roi import Cylinder
    >>> from geoshade.compute.porosity import porosity as in_memory
    >>> a = (np.arange(6 * 8 * 8) % 7).astype(np.uint8).reshape(6, 8, 8)
    >>> c = Cylinder(4, 4, 3)
    >>> r, ref = porosity(a, 0, 2, roi=c), in_memory(a, 0, 2, roi=c)
    >>> r.porosity == ref.porosity and r.profile.tolist() == ref.profile.tolist()
    True
    """
    if axis not in _AXES:
        raise InputError(f"axis: expected one of x, y, z, got {axis!r}")
    arr, box, vol = resolve_data_box(data, box)
    flo, fhi = check_range(lo, hi, arr.dtype)
    x = as_dask(arr)[box.slices()]
    sum_axes = _AXES[axis][1]
    off = tuple(box.offset)
    counts_g = x.map_blocks(_selected, flo, fhi, roi, off, dtype=bool).sum(
        axis=sum_axes, dtype=np.int64)
    below_g = x.map_blocks(_low, flo, roi, off, dtype=bool).sum(dtype=np.int64)
    graphs = [counts_g, below_g]
    if roi is not None:
        graphs.append(x.map_blocks(_in_roi, roi, off, dtype=bool).sum(axis=sum_axes,
                                                                         dtype=np.int64))
    out = compute(*graphs, scheduler=scheduler, progress=progress)
    voxels = out[2] if roi is not None else None
    return result_from_counts(out[0], box, vol, axis, (flo, fhi), voxels=voxels,
                              below=int(out[1]), roi=roi)


__all__ = ["porosity"]
