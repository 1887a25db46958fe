"""Porosity of a box: the fraction of its voxels inside an absorption range, and its profile.

The volume is streamed in z-slabs (see :func:`geoshade.compute.selection.iter_z_slabs`), so a box
of any size is measured with a bounded amount of memory. Counts are exact integers; fractions
are ``count / total`` in float64, which equals numpy's ``((a >= lo) & (a <= hi)).mean()``.
"""

from __future__ import annotations

import csv
import io
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from geoshade.compute.selection import (
    SLAB_BYTES,
    check_range,
    iter_z_slabs,
    resolve_data_box,
    select,
)
from geoshade.errors import InputError
from geoshade.progress import Progress

#: axis name -> (index in x, y, z order, axes of a (nz, ny, nx) slab to sum over)
_AXES = {"x": (0, (0, 1)), "y": (1, (0, 2)), "z": (2, (1, 2))}


@dataclass
class PorosityResult:
    """Porosity of a box and its profile along one axis.

    porosity:  float                total fraction of the box's voxels with ``lo <= v <= hi``
    profile:   (n,) float64          the fraction in each slice across ``axis``
    axis:      "x" | "y" | "z"       axis along which the profile runs
    positions: (n,) int64            absolute slice indices (voxels) of the profile
    count:     int                   selected voxels in the box
    total:     int                   voxels in the box
    counts:    (n,) int64            selected voxels in each slice
    range:     (lo, hi)              the absorption range
    box:       [x0, y0, z0, nx, ny, nz]
    spacing:   float | None          voxel size along ``axis`` (None: unknown)
    origin:    float                 world position of voxel 0's corner along ``axis``
    unit:      str                   length unit of spacing ("" if unknown)
    """

    porosity: float
    profile: np.ndarray
    axis: str
    positions: np.ndarray
    count: int
    total: int
    counts: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    range: tuple[float, float] = (0.0, 0.0)
    box: list[int] = field(default_factory=list)
    spacing: float | None = None
    origin: float = 0.0
    unit: str = ""

    def coordinates(self) -> np.ndarray:
        """Slice centres in world units (``origin + (i + 0.5) * spacing``), or the indices."""
        if self.spacing is None:
            return self.positions.astype(np.float64)
        return self.origin + (self.positions + 0.5) * self.spacing

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict: ``porosity, profile, axis, positions, range, box`` and the rest."""
        return {
            "porosity": float(self.porosity),
            "profile": [float(v) for v in self.profile],
            "axis": self.axis,
            "positions": [int(v) for v in self.positions],
            "range": [float(self.range[0]), float(self.range[1])],
            "box": [int(v) for v in self.box],
            "count": int(self.count),
            "total": int(self.total),
            "counts": [int(v) for v in self.counts],
            "spacing": None if self.spacing is None else float(self.spacing),
            "origin": float(self.origin),
            "unit": self.unit,
        }


def porosity(
    data,
    lo,
    hi,
    box=None,
    axis: str = "z",
    progress: Progress | None = None,
    slab_bytes: int = SLAB_BYTES,
) -> PorosityResult:
    """Fraction of a box's voxels with ``lo <= v <= hi``, in all and slice by slice along ``axis``.

    Parameters
    ----------
    data : VoxelVolume or (nz, ny, nx) array
        Numpy array, memmap, dask or zarr array; read in z-slabs of about ``slab_bytes``.
    lo, hi : number
        Absorption range, inclusive (pore space or mineral skeleton).
    box : Box, [x0, y0, z0, nx, ny, nz] or None
        Sub-volume (None: all of it).
    axis : {"x", "y", "z"}
        Axis of the profile.
    progress : callable(done, total), optional
        Called after each slab with the z slices done and in all.
    slab_bytes : int
        Input bytes per slab.

    Returns
    -------
    PorosityResult

    Examples
    --------
    >>> a = np.zeros((4, 2, 2), np.uint8); a[0] = 1; a[1, 0, 0] = 1
    >>> r = porosity(a, 0, 0)
    >>> r.porosity, r.profile.tolist(), r.positions.tolist()
    (0.6875, [0.0, 0.75, 1.0, 1.0], [0, 1, 2, 3])
    """
    if axis not in _AXES:
        raise InputError(f"axis: expected one of x, y, z, got {axis!r}")
    arr, box, vol = resolve_data_box(data, box)
    flo, fhi = check_range(lo, hi, arr.dtype)
    p, sum_axes = _AXES[axis]
    size = box.size[p]
    counts = np.zeros(size, np.int64)
    for z, slab in iter_z_slabs(arr, box, 1, slab_bytes, progress):
        sel = select(slab, flo, fhi)
        part = np.count_nonzero(sel, axis=sum_axes).astype(np.int64)
        if axis == "z":
            counts[z : z + slab.shape[0]] += part
        else:
            counts += part
    return result_from_counts(counts, box, vol, axis, (flo, fhi))


def result_from_counts(counts, box, vol, axis: str, rng) -> PorosityResult:
    """The :class:`PorosityResult` of per-slice selected-voxel ``counts`` along ``axis``.

    >>> from geoshade.models import Box
    >>> result_from_counts(np.array([1, 3]), Box((0, 0, 0), (2, 1, 2)), None, "z", (0, 0)).profile
    array([0.5, 1.5])
    """
    p = _AXES[axis][0]
    counts = np.asarray(counts, np.int64)
    size = box.size[p]
    total = box.nvoxels
    count = int(counts.sum())
    return PorosityResult(
        porosity=count / total,
        profile=counts / np.float64(total // size),
        axis=axis,
        positions=box.offset[p] + np.arange(size, dtype=np.int64),
        count=count,
        total=total,
        counts=counts,
        range=tuple(rng),
        box=[*box.offset, *box.size],
        spacing=None if vol is None or not vol.unit else float(vol.spacing[p]),
        origin=0.0 if vol is None else float(vol.origin[p]),
        unit="" if vol is None else vol.unit,
    )


def csv_text(result: PorosityResult) -> str:
    """The profile as CSV text: one row per slice (write it with ``geoshade.io.output``).

    Columns: ``<axis>`` (slice index), ``<axis>_<unit>`` (slice centre, only when the unit is
    known), ``count``, ``voxels``, ``porosity``. Floats are written with full precision.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> r = porosity(np.array([[[0, 1]], [[0, 0]]], np.uint8), 0, 0)
    >>> print(csv_text(r).strip())
    z,count,voxels,porosity
    0,1,2,0.5
    1,2,2,1.0
    """
    per_slice = result.total // max(1, len(result.profile))
    coord = bool(result.unit) and result.spacing is not None
    header = [result.axis] + ([f"{result.axis}_{result.unit}"] if coord else [])
    header += ["count", "voxels", "porosity"]
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(header)
    coords = result.coordinates()
    for i in range(len(result.profile)):  # one row per slice, not per voxel
        row = [int(result.positions[i])] + ([repr(float(coords[i]))] if coord else [])
        row += [int(result.counts[i]), per_slice, repr(float(result.profile[i]))]
        w.writerow(row)
    return buf.getvalue()
