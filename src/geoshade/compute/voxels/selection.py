"""Absorption ranges and the voxels they select, plus z-slab streaming over big boxes.

A *range* ``[lo, hi]`` is inclusive at both ends. Voxels whose value ``v`` satisfies
``lo <= v <= hi`` are *selected* (the paper's sampling condition); NaN is never selected.

Big boxes (``1000³`` voxels and more, numpy memmaps, dask or zarr arrays) are processed slab by
slab along z with :func:`iter_z_slabs`, so no full-size float or bool temporary is ever made.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from typing import Any

import numpy as np

from geoshade.errors import InputError
from geoshade.models import Box, VoxelVolume
from geoshade.progress import Progress

#: default amount of input data read per z-slab (bytes)
SLAB_BYTES = 64 * 2**20


def _fmt(v: float) -> str:
    """A number for a message: ``70000`` rather than ``70000.0``."""
    if math.isfinite(v) and float(v).is_integer():
        return str(int(v))
    return repr(float(v))


def _as_number(v: Any, which: str, name: str) -> float:
    try:
        f = float(v)
    except (TypeError, ValueError):
        raise InputError(f"{name}: {which} {v!r} is not a number; expected LO <= HI") from None
    if math.isnan(f):
        raise InputError(f"{name}: {which} is NaN; expected a number")
    return f


def check_range(lo, hi, dtype=None, name: str = "range") -> tuple[float, float]:
    """Check an inclusive value range and return it as two Python floats.

    Parameters
    ----------
    lo, hi : number
        Lower and upper bound, inclusive.
    dtype : numpy dtype or None
        For integer dtypes both bounds must be representable (``uint16``: 0..65535). ``None``
        skips that check.
    name : str
        What the range is called in error messages.

    Returns
    -------
    (float, float)
        ``(lo, hi)``.

    Raises
    ------
    InputError
        One line naming the problem: a NaN or non-number bound, ``lo > hi``, or a bound outside
        the dtype's values.

    Examples
    --------
    >>> check_range(100, 200, "uint16")
    (100.0, 200.0)
    >>> check_range(200, 100, "uint16")
    Traceback (most recent call last):
    ...
    geoshade.errors.InputError: range: lo 200 > hi 100; expected LO <= HI
    >>> check_range(0, 70000, "uint16")
    Traceback (most recent call last):
    ...
    geoshade.errors.InputError: range: 70000 outside uint16 [0, 65535]
    """
    flo = _as_number(lo, "lo", name)
    fhi = _as_number(hi, "hi", name)
    if flo > fhi:
        raise InputError(f"{name}: lo {_fmt(flo)} > hi {_fmt(fhi)}; expected LO <= HI")
    if dtype is not None:
        dt = np.dtype(dtype)
        if np.issubdtype(dt, np.integer):
            info = np.iinfo(dt)
            for v in (flo, fhi):
                if not info.min <= v <= info.max:
                    raise InputError(
                        f"{name}: {_fmt(v)} outside {dt.name} [{info.min}, {info.max}]"
                    )
    return flo, fhi


def int_bounds(lo: float, hi: float, dtype) -> tuple[Any, Any]:
    """Integer bounds equivalent to the real range ``[lo, hi]`` for an integer dtype.

    ``v >= lo`` equals ``v >= ceil(lo)`` and ``v <= hi`` equals ``v <= floor(hi)`` for integers;
    the result is returned as numpy scalars of ``dtype`` so comparisons never upcast. The range
    must already be checked with :func:`check_range`. An empty range gives ``lo > hi``.

    Examples
    --------
    >>> [int(b) for b in int_bounds(99.5, 200.9, "uint8")]
    [100, 200]
    """
    dt = np.dtype(dtype)
    info = np.iinfo(dt)
    ilo = max(math.ceil(lo), int(info.min))
    ihi = min(math.floor(hi), int(info.max))
    return dt.type(min(ilo, int(info.max))), dt.type(max(ihi, int(info.min)))


def select(block, lo, hi) -> np.ndarray:
    """Boolean mask of the values inside the inclusive range ``[lo, hi]``.

    Parameters
    ----------
    block : array_like
        Values of any shape (a numpy array, memmap or anything ``np.asarray`` accepts).
    lo, hi : number
        Inclusive bounds, checked with :func:`check_range` against ``block``'s dtype.

    Returns
    -------
    numpy.ndarray of bool
        Same shape as ``block``; NaN values are never selected.

    Examples
    --------
    >>> select(np.array([0, 5, 10, 11], dtype=np.uint8), 5, 10)
    array([False,  True,  True, False])
    >>> select(np.array([np.nan, 1.0]), -np.inf, np.inf)
    array([False,  True])
    """
    a = np.asarray(block)
    flo, fhi = check_range(lo, hi, a.dtype)
    if np.issubdtype(a.dtype, np.integer):
        ilo, ihi = int_bounds(flo, fhi, a.dtype)
        if ilo > ihi:
            return np.zeros(a.shape, dtype=bool)
        info = np.iinfo(a.dtype)
        if ilo == info.min:
            return a <= ihi
        if ihi == info.max:
            return a >= ilo
        m = a >= ilo
        m &= a <= ihi
        return m
    if np.issubdtype(a.dtype, np.bool_):
        a = a.view(np.uint8)
    m = a >= flo
    m &= a <= fhi
    return m


def resolve_data_box(data, box=None) -> tuple[Any, Box, VoxelVolume | None]:
    """Split a :class:`VoxelVolume` or a ``(nz, ny, nx)`` array into ``(array, Box, volume)``.

    ``box`` may be None (the whole volume), a :class:`Box` or ``[x0, y0, z0, nx, ny, nz]``; it is
    checked to lie inside the data. ``volume`` is None when a bare array was given.

    Examples
    --------
    >>> arr, box, vol = resolve_data_box(np.zeros((4, 3, 2), np.uint8), [0, 1, 1, 2, 2, 3])
    >>> box.size, vol is None
    ((2, 2, 3), True)
    """
    if isinstance(data, VoxelVolume):
        return data.data, data.resolve_box(box), data
    shape = getattr(data, "shape", None)
    if shape is None or getattr(data, "dtype", None) is None:
        raise InputError(
            f"volume data: expected a VoxelVolume or an array, got {type(data).__name__}"
        )
    if len(shape) != 3:
        raise InputError(f"volume data: expected 3 dimensions (nz, ny, nx), got shape {shape}")
    nz, ny, nx = (int(n) for n in shape)
    if box is None:
        box = Box((0, 0, 0), (nx, ny, nz))
    elif not isinstance(box, Box):
        box = Box.from_list(box)
    box.check_inside((nx, ny, nz))
    return data, box, None


def slab_depth(shape_xyz, itemsize: int, multiple: int = 8, slab_bytes: int = SLAB_BYTES) -> int:
    """Number of z slices per slab: a multiple of ``multiple`` holding about ``slab_bytes``.

    Examples
    --------
    >>> slab_depth((1000, 1000, 1000), 2)   # uint16: 32 slices of 2 MB each = 64 MB
    32
    >>> slab_depth((10, 10, 5), 1, multiple=8, slab_bytes=1)
    8
    """
    nx, ny, _ = (int(n) for n in shape_xyz)
    if multiple < 1:
        raise InputError(f"slab multiple: expected >= 1, got {multiple}")
    per_slice = max(1, nx * ny * int(itemsize))
    k = int(slab_bytes) // per_slice // multiple
    return max(1, k) * multiple


def iter_z_slabs(
    data,
    box: Box,
    multiple: int = 8,
    slab_bytes: int = SLAB_BYTES,
    progress: Progress | None = None,
) -> Iterator[tuple[int, np.ndarray]]:
    """Yield ``(z, slab)`` over ``box`` of a ``(nz, ny, nx)`` array, one z-slab at a time.

    ``z`` is the first slice of the slab relative to the box; ``slab`` is an in-memory numpy
    array ``(dz, ny, nx)`` (``np.asarray`` of the slice, so memmaps, dask and zarr arrays work).
    Every slab but the last holds a multiple of ``multiple`` slices. ``progress(done, total)``
    is called after each slab, counting z slices.

    Examples
    --------
    >>> a = np.arange(4 * 2 * 2, dtype=np.uint8).reshape(4, 2, 2)
    >>> [(z, s.shape) for z, s in iter_z_slabs(a, Box((0, 0, 0), (2, 2, 4)), 1, slab_bytes=8)]
    [(0, (2, 2, 2)), (2, (2, 2, 2))]
    """
    nx, ny, nz = box.size
    itemsize = np.dtype(data.dtype).itemsize
    depth = slab_depth((nx, ny, nz), itemsize, multiple, slab_bytes)
    sz, sy, sx = box.slices()
    for z in range(0, nz, depth):
        z1 = min(nz, z + depth)
        part = data[sz.start + z : sz.start + z1, sy, sx]
        if hasattr(part, "compute"):
            part = part.compute()
        yield z, np.asarray(part)
        if progress is not None:
            progress(z1, nz)
