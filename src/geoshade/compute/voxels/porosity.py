"""Porosity of a box: the fraction of its voxels inside an absorption range, and its profile.

One implementation: :func:`block_counts` counts one block; :func:`porosity` runs it on z-slabs
(see :func:`geoshade.compute.voxels.selection.iter_z_slabs`) or, with a ``scheduler``, on dask
chunks as
tasks, so a box of any size is measured with a bounded amount of memory, in one process or on a
cluster.  Counts are exact integers; fractions are ``count / total`` in float64, which equals
numpy's ``((a >= lo) & (a <= hi)).mean()``.  Which voxels count (box, ROI, detected sample) is
decided by :func:`geoshade.core.porosity`; docs/guide/core.rst says it in full.
"""

from __future__ import annotations

import csv
import io
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from geoshade.compute.voxels.lazy import as_dask, compute
from geoshade.compute.voxels.selection import (
    SLAB_BYTES,
    check_range,
    iter_z_slabs,
    resolve_data_box,
    select,
)
from geoshade.errors import InputError
from geoshade.progress import Progress
from geoshade.scheduler import Scheduler

#: axis name -> (index in x, y, z order, axes of a (nz, ny, nx) slab to sum over)
_AXES = {"x": (0, (0, 1)), "y": (1, (0, 2)), "z": (2, (1, 2))}


#: what the measured fraction is called (see :attr:`PorosityResult.quantity`)
PORES, SELECTED = "porosity", "selected fraction"


@dataclass
class PorosityResult:
    """Porosity of a box (within an optional ROI) and its profile along one axis.

    porosity:  float                selected voxels / voxels measured (box ∩ ROI)
    profile:   (n,) float64          the fraction in each slice across ``axis`` (NaN where a
                                     slice holds no voxel of the ROI)
    axis:      "x" | "y" | "z"       axis along which the profile runs
    positions: (n,) int64            absolute slice indices (voxels) of the profile
    count:     int                   selected voxels measured
    total:     int                   voxels measured (the box's, or those inside the ROI)
    counts:    (n,) int64            selected voxels in each slice
    range:     (lo, hi)              the selection (values selected, inclusive)
    box:       [x0, y0, z0, nx, ny, nz]
    spacing:   float | None          voxel size along ``axis`` (None: unknown)
    origin:    float                 world position of voxel 0's corner along ``axis``
    unit:      str                   length unit of spacing ("" if unknown)
    voxels:    (n,) int64            voxels measured in each slice (the profile's denominators)
    below:     int                   voxels measured with a value below the selection
    roi:       dict | None           the region of interest (``Cylinder.to_dict()`` ...)
    select_auto: dict | None         how an automatic selection was found (Otsu's threshold,
                                     which side was taken as pore and why: ``text``)
    sample:    dict | None           what counts as the sample (:class:`geoshade.compute.
                                     sample.Sample`: ``status``, ``fraction``, ``text``)
    outside:   int | None            selected voxels of box ∩ ROI outside the detected sample
                                     (air; not counted)
    label_image: bool                the volume is a label image (segmented; few distinct
                                     values): which label is pore is not known (see
                                     :attr:`pores`)
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
    voxels: np.ndarray | None = None
    below: int | None = None
    roi: dict | None = None
    select_auto: dict | None = None
    sample: dict | None = None
    outside: int | None = None
    warning: str | None = None
    label_image: bool = False

    @property
    def outside_fraction(self) -> float | None:
        """Of the selected voxels of box ∩ ROI, the share outside the detected sample."""
        if self.outside is None:
            return None
        every = self.outside + self.count
        return self.outside / every if every else 0.0

    def notes(self) -> list[str]:
        """What decides the number, in words (the CLI prints them, the picture and the plot
        show them): how an automatic selection was made, what counts as the sample, and the
        warning when much of the selection lies outside it."""
        out = []
        if self.select_auto and self.select_auto.get("text"):
            out.append(str(self.select_auto["text"]))
        if self.sample and self.sample.get("text"):
            out.append(str(self.sample["text"]))
        elif self.roi:
            out.append(f"counted inside {self.roi.get('text', 'the ROI')}")
        if self.warning:
            f = self.outside_fraction or 0.0
            out.append(f"{100 * f:.1f} % of the selected voxels are air outside the sample "
                       "(not counted)")
        return out

    @property
    def pores(self) -> bool:
        """The selection is the pore space: it starts at the darkest voxel measured (none lies
        below it: the low-value side, pores and air in an absorption image) and leaves some
        voxels out above it.  Otherwise the fraction is a "selected fraction" (a mineral phase,
        a band of values, or everything).  Unknown (``below`` None): pores.

        In a label image a value is a phase, not a brightness: the selection is called pores
        only where it is one label, the lowest (as segmentations number the pore phase 0), and
        a minority of the voxels; any other label (a solid phase, or a label that is most of
        the image, which nothing says is pore) is a "selected fraction".

        >>> r = PorosityResult(0.822, np.zeros(1), "z", np.zeros(1, int), 822, 1000,
        ...                    range=(0.0, 0.0), below=0, label_image=True)
        >>> r.quantity   # the lowest label, but most of the image: a grain phase
        'selected fraction'
        """
        if self.below is None:
            return True
        if self.label_image and not (self.range[0] == self.range[1]
                                     and 2 * self.count < self.total):
            return False
        return self.below == 0 and self.count < self.total

    @property
    def quantity(self) -> str:
        """``"porosity"`` or ``"selected fraction"`` (see :attr:`pores`)."""
        return PORES if self.pores else SELECTED

    def coordinates(self) -> np.ndarray:
        """Slice centres in world units (``origin + (i + 0.5) * spacing``), or the indices."""
        if self.spacing is None:
            return self.positions.astype(np.float64)
        return self.origin + (self.positions + 0.5) * self.spacing

    def coordinate_name(self) -> str | None:
        """The name of the slice-centre column: ``z_um`` (unit known), ``z_coord`` (a spacing
        without unit) or None (voxel indices only)."""
        if self.spacing is None:
            return None
        return f"{self.axis}_{unit_tag(self.unit)}" if self.unit else f"{self.axis}_coord"

    def per_slice(self) -> np.ndarray:
        """Voxels measured in each slice, ``(n,) int64``."""
        if self.voxels is not None:
            return np.asarray(self.voxels, np.int64)
        n = max(1, len(self.profile))
        return np.full(len(self.profile), self.total // n, np.int64)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict: ``porosity, profile, axis, positions, range, box`` and the rest
        (``quantity``, ``select``, ``coordinates`` in ``unit``, ``voxels`` per slice, ``roi``).
        A slice without voxels in the ROI has a ``null`` profile value."""
        coord = self.coordinate_name()
        return {
            "porosity": float(self.porosity),
            "quantity": self.quantity,
            "label_image": bool(self.label_image),
            "profile": [float(v) if np.isfinite(v) else None for v in self.profile],
            "axis": self.axis,
            "positions": [int(v) for v in self.positions],
            "range": [float(self.range[0]), float(self.range[1])],
            "select": [float(self.range[0]), float(self.range[1])],
            "select_auto": self.select_auto,
            "sample": self.sample,
            "outside": None if self.outside is None else int(self.outside),
            "outside_fraction": self.outside_fraction,
            "warning": self.warning,
            "notes": self.notes(),
            "box": [int(v) for v in self.box],
            "roi": self.roi,
            "count": int(self.count),
            "total": int(self.total),
            "counts": [int(v) for v in self.counts],
            "voxels": [int(v) for v in self.per_slice()],
            "below": None if self.below is None else int(self.below),
            "spacing": None if self.spacing is None else float(self.spacing),
            "origin": float(self.origin),
            "unit": self.unit,
            "coordinate": coord,
            "coordinates": None if coord is None else [float(v) for v in self.coordinates()],
        }


def unit_tag(unit: str) -> str:
    """A length unit as an ASCII column suffix: ``µm`` -> ``um``.

    >>> unit_tag("µm"), unit_tag("mm")
    ('um', 'mm')
    """
    u = str(unit).replace("µ", "u").replace("μ", "u")
    return "".join(c if c.isalnum() else "_" for c in u) or "unit"


def _inside_all(rois, zs: slice, ys: slice, xs: slice, shape) -> np.ndarray | None:
    """Bool (broadcastable to ``shape``): inside every ROI of ``rois`` (None: no ROI)."""
    out = None
    for r in rois:
        if r is not None:
            m = r.inside(zs, ys, xs)
            out = m if out is None else out & m
    return None if out is None else np.broadcast_to(out, shape)


def block_counts(block, lo: float, hi: float, where, axis: str, roi=None, sample=None):
    """The counts of one block of the box: the one function the slab loop and the dask tasks
    of :func:`porosity` run.

    Parameters
    ----------
    block : (dz, dy, dx) array
    where : (zs, ys, xs) slices
        The block's place in the whole volume (voxels), where the ROIs are evaluated.
    roi, sample : ROI or None
        Voxels outside either do not count; ``sample`` is the detected sample
        (:mod:`geoshade.compute.voxels.sample`).

    Returns
    -------
    (counts, voxels, below, outside)
        Selected voxels per slice of the block across ``axis`` ``(n,) int64``, voxels measured
        per slice (None without ROI or sample), voxels measured below ``lo``, and selected
        voxels inside ``roi`` but outside ``sample``.

    Examples
    --------
    >>> b = np.array([[[0, 5], [9, 0]]], np.uint8)
    >>> w = (slice(0, 1), slice(0, 2), slice(0, 2))
    >>> c, v, below, out = block_counts(b, 0, 0, w, "x")
    >>> c.tolist(), v, below, out
    ([1, 1], None, 0, 0)
    """
    block = np.asarray(block)
    sum_axes = _AXES[axis][1]
    sel = select(block, lo, hi)
    low = below_mask(block, lo)
    zs, ys, xs = where
    inside = _inside_all((roi,), zs, ys, xs, block.shape)
    outside = 0
    voxels = None
    if sample is not None:
        in_sample = _inside_all((sample,), zs, ys, xs, block.shape)
        away = sel & ~in_sample
        if inside is not None:
            away &= inside
        outside = int(np.count_nonzero(away))
        inside = in_sample if inside is None else inside & in_sample
    if inside is not None:
        sel &= inside
        low &= inside
        voxels = np.count_nonzero(inside, axis=sum_axes).astype(np.int64)
    counts = np.count_nonzero(sel, axis=sum_axes).astype(np.int64)
    return counts, voxels, int(np.count_nonzero(low)), outside


def porosity(
    data,
    lo,
    hi,
    box=None,
    axis: str = "z",
    progress: Progress | None = None,
    slab_bytes: int = SLAB_BYTES,
    roi=None,
    sample=None,
    scheduler=None,
) -> PorosityResult:
    """Fraction of a box's voxels with ``lo <= v <= hi``, in all and slice by slice along ``axis``.

    One implementation for every path: without ``scheduler`` the box is read in z-slabs of
    about ``slab_bytes`` (any array: numpy, memmap, zarr, dask); with one, each dask chunk is a
    task on that scheduler.  Both run :func:`block_counts` on their blocks and add exact
    integers, so the results are equal bit for bit.

    Parameters
    ----------
    data : VoxelVolume or (nz, ny, nx) array
        Numpy array, memmap, dask or zarr array.
    lo, hi : number
        Absorption range, inclusive (pore space or mineral skeleton).
    box : Box, [x0, y0, z0, nx, ny, nz] or None
        Sub-volume (None: all of it).
    axis : {"x", "y", "z"}
        Axis of the profile.
    progress : callable(done, total), optional
        Called after each slab (z slices) or task.
    slab_bytes : int
        Input bytes per slab.
    roi : Cylinder or MaskRoi, optional
        Only the voxels inside count, in the numerator and the denominator
        (:mod:`geoshade.compute.voxels.roi`; evaluated block by block).
    sample : SampleRoi, optional
        The detected sample (:func:`geoshade.compute.voxels.sample.detect_sample`): voxels outside
        count neither; the selected ones outside it are reported (``outside``).
    scheduler : optional
        Where the dask tasks run (:mod:`geoshade.scheduler`); None (``here``): the slab loop
        in this process.

    Returns
    -------
    PorosityResult

    Examples
    --------
    >>> a = np.zeros((4, 2, 2), np.uint8); a[0] = 1; a[1, 0, 0] = 1
    >>> r = porosity(a, 0, 0)
    >>> r.porosity, r.profile.tolist(), r.positions.tolist()
    (0.6875, [0.0, 0.75, 1.0, 1.0], [0, 1, 2, 3])
    >>> porosity(a, 0, 0, scheduler="synchronous").counts.tolist() == r.counts.tolist()
    True
    """
    if axis not in _AXES:
        raise InputError(f"axis: expected one of x, y, z, got {axis!r}")
    arr, box, vol = resolve_data_box(data, box)
    flo, fhi = check_range(lo, hi, arr.dtype)
    if not Scheduler.parse(scheduler).in_place:
        parts = _dask_parts(arr, box, flo, fhi, axis, roi, sample, scheduler, progress)
    else:
        parts = _slab_parts(arr, box, flo, fhi, axis, roi, sample, slab_bytes, progress)
    p = _AXES[axis][0]
    counts = np.zeros(box.size[p], np.int64)
    measured = roi is not None or sample is not None
    voxels = np.zeros(box.size[p], np.int64) if measured else None
    below = outside = 0
    for start, (c, v, b, o) in parts:  # start: the block's first slice across axis (box)
        counts[start:start + c.size] += c
        if voxels is not None:
            voxels[start:start + v.size] += v
        below += b
        outside += o
    res = result_from_counts(counts, box, vol, axis, (flo, fhi), voxels=voxels, below=below,
                             roi=roi)
    if sample is not None:
        res.outside = outside
    return res


def _slab_parts(arr, box, lo, hi, axis, roi, sample, slab_bytes, progress):
    p = _AXES[axis][0]
    bz, by, bx = box.slices()
    for z, slab in iter_z_slabs(arr, box, 1, slab_bytes, progress):
        where = (slice(bz.start + z, bz.start + z + slab.shape[0]), by, bx)
        yield (z if p == 2 else 0), block_counts(slab, lo, hi, where, axis, roi, sample)


def _dask_parts(arr, box, lo, hi, axis, roi, sample, scheduler, progress):
    from dask import delayed


    x = as_dask(arr)[box.slices()]
    p = _AXES[axis][0]
    starts = [np.concatenate([[0], np.cumsum(c)[:-1]]).astype(int) for c in x.chunks]
    tasks, first = [], []
    blocks = x.to_delayed()
    run = delayed(block_counts, pure=True)
    for idx in np.ndindex(*x.numblocks):
        o = [int(starts[d][i]) for d, i in enumerate(idx)]  # z, y, x offsets in the box
        n = [int(x.chunks[d][i]) for d, i in enumerate(idx)]
        where = tuple(slice(off + a, off + a + b) for off, a, b in
                      zip(box.offset[::-1], o, n, strict=True))
        tasks.append(run(blocks[idx], lo, hi, where, axis, roi, sample))
        first.append(o[2 - p])
    done = compute(*tasks, scheduler=scheduler, progress=progress)
    return zip(first, done, strict=True)


def below_mask(slab: np.ndarray, lo: float) -> np.ndarray:
    """Bool: values below ``lo`` (integers compared with ``ceil(lo)``, no upcast)."""
    if np.issubdtype(slab.dtype, np.integer):
        info = np.iinfo(slab.dtype)
        ilo = math.ceil(lo)
        if ilo <= info.min:
            return np.zeros(slab.shape, bool)
        if ilo > info.max:
            return np.ones(slab.shape, bool)
        return slab < slab.dtype.type(ilo)
    return slab < lo


def result_from_counts(counts, box, vol, axis: str, rng, voxels=None, below=None,
                       roi=None) -> PorosityResult:
    """The :class:`PorosityResult` of per-slice selected-voxel ``counts`` along ``axis``
    (``voxels``: voxels measured per slice, default every voxel of the box's slices).

    >>> from geoshade.models import Box
    >>> result_from_counts(np.array([1, 3]), Box((0, 0, 0), (2, 1, 2)), None, "z", (0, 0)).profile
    array([0.5, 1.5])
    """
    p = _AXES[axis][0]
    counts = np.asarray(counts, np.int64)
    size = box.size[p]
    if voxels is None:
        total = box.nvoxels
        profile = counts / np.float64(total // size)
    else:
        voxels = np.asarray(voxels, np.int64)
        total = int(voxels.sum())
        if total == 0:
            raise InputError(f"roi: no voxel of box {[*box.offset, *box.size]} lies inside "
                             f"the region of interest ({roi.text() if roi else '?'})")
        with np.errstate(invalid="ignore", divide="ignore"):
            profile = np.where(voxels > 0, counts / np.maximum(voxels, 1), np.nan)
    count = int(counts.sum())
    spacing = None
    if vol is not None and (vol.unit or tuple(vol.spacing) != (1.0, 1.0, 1.0)):
        spacing = float(vol.spacing[p])  # known: a unit, or a spacing someone gave
    return PorosityResult(
        porosity=count / total,
        profile=profile,
        axis=axis,
        positions=box.offset[p] + np.arange(size, dtype=np.int64),
        count=count,
        total=total,
        counts=counts,
        range=tuple(rng),
        box=[*box.offset, *box.size],
        spacing=spacing,
        origin=0.0 if vol is None else float(vol.origin[p]),
        unit="" if vol is None else vol.unit,
        voxels=voxels,
        below=None if below is None else int(below),
        roi=None if roi is None else roi.to_dict(),
    )


def csv_text(result: PorosityResult) -> str:
    """The profile as CSV text: one row per slice (write it with ``geoshade.io.output``).

    Columns: ``<axis>`` (slice index), the slice centre in the length unit (``z_um``; see
    :meth:`PorosityResult.coordinate_name`; only when the spacing is known), ``count``,
    ``voxels`` (measured in the slice: inside the ROI), and ``porosity`` (or
    ``selected_fraction`` when the selection is not the pore space, see
    :attr:`PorosityResult.pores`). Floats are written with full precision; a slice with no
    voxel in the ROI has an empty fraction.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> r = porosity(np.array([[[0, 1]], [[0, 0]]], np.uint8), 0, 0)
    >>> print(csv_text(r).strip())
    z,count,voxels,porosity
    0,1,2,0.5
    1,2,2,1.0
    """
    coord = result.coordinate_name()
    header = [result.axis] + ([coord] if coord else [])
    header += ["count", "voxels", "porosity" if result.pores else "selected_fraction"]
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(header)
    coords = result.coordinates()
    per_slice = result.per_slice()
    for i in range(len(result.profile)):  # one row per slice, not per voxel
        f = float(result.profile[i])
        row = [int(result.positions[i])] + ([repr(float(coords[i]))] if coord else [])
        row += [int(result.counts[i]), int(per_slice[i]), repr(f) if math.isfinite(f) else ""]
        w.writerow(row)
    return buf.getvalue()
