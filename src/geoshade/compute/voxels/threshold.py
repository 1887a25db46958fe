"""Suggested thresholds of a volume: Otsu and multi-Otsu (scikit-image), streamed.

scikit-image computes both from a histogram (``skimage.exposure.histogram``): for integer
images one bin per integer value (no rebinning), for floats 256 equal bins between the
minimum and the maximum.  :func:`value_histogram` builds that same histogram z-slab by z-slab
(optionally only over the voxels of a box and an ROI), so a volume larger than memory gets
exactly the threshold ``skimage.filters.threshold_otsu(values)`` would give, and
:func:`thresholds` hands it to scikit-image (``hist=``).

Multi-Otsu's cost grows with the square of the bins, so a histogram of more than
:data:`MULTI_BINS` bins (a wide 16-bit range) is merged into that many equal bins first
(the same as ``threshold_multiotsu(hist=...)`` of the merged histogram).

NaN and infinite values are not counted.  The classes follow scikit-image: the pore (dark)
class is ``v <= threshold``.  An image with at most
:data:`~geoshade.compute.voxels.sample.LABEL_MAX`
distinct values is a label image (segmented): :attr:`Thresholds.labels` lists its values and
their fractions, no side of a threshold is suggested as pore (which label is pore is the
user's to say), every label of at least :data:`LABEL_SHOWN` of the voxels is offered
(:meth:`Thresholds.label_choices`), and Otsu's thresholds are named by a label present: the
largest label at or below each (the same split; a value between two labels is 0 % of the
image).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from geoshade.compute.voxels.sample import LABEL_MAX
from geoshade.compute.voxels.selection import iter_z_slabs, resolve_data_box
from geoshade.errors import InputError, require
from geoshade.progress import Progress

#: bins of a float histogram (scikit-image's default ``nbins``)
FLOAT_BINS = 256
#: most bins multi-Otsu is run on (wider integer histograms are merged to this many)
MULTI_BINS = 256
#: widest integer value span histogrammed one bin per value
MAX_INT_SPAN = 1 << 24
#: a label image's labels offered as a selection: those of at least this share of the voxels
#: (rounded to one decimal of a percent, fewer would read "0.0 %")
LABEL_SHOWN = 0.0005


@dataclass
class ValueHistogram:
    """counts: (n,) int64 per bin; centers: (n,) the bins' values (the integers themselves
    for integer data); integer: one bin per integer value; voxels: values counted."""

    counts: np.ndarray
    centers: np.ndarray
    integer: bool
    voxels: int = 0
    limits: tuple[float, float] | None = None  # the finite values' min and max (floats)
    #: floats: {value: voxels} of the distinct values where there are at most LABEL_MAX
    distinct: dict | None = None

    def label_values(self) -> list[tuple[float, int]] | None:
        """``[(value, voxels), ...]`` of a label image (at most
        :data:`~geoshade.compute.voxels.sample.LABEL_MAX` distinct values), else None.

        >>> value_histogram(np.array([[[0, 255, 0, 0]]], np.uint8)).label_values()
        [(0.0, 3), (255.0, 1)]
        """
        if not self.integer:
            if self.distinct is None:
                return None
            return [(float(v), int(n)) for v, n in sorted(self.distinct.items())]
        nz = np.flatnonzero(self.counts)
        if nz.size > LABEL_MAX:
            return None
        return [(float(self.centers[i]), int(self.counts[i])) for i in nz]

    def trimmed(self) -> ValueHistogram:
        """Without the empty bins at both ends (scikit-image's ``source_range='image'``)."""
        nz = np.flatnonzero(self.counts)
        if nz.size == 0:
            return self
        a, b = int(nz[0]), int(nz[-1]) + 1
        return ValueHistogram(self.counts[a:b], self.centers[a:b], self.integer, self.voxels,
                              self.limits, self.distinct)


def _inside(roi, box, z: int, dz: int):
    if roi is None:
        return None
    zs, ys, xs = box.slices()
    return roi.inside(slice(zs.start + z, zs.start + z + dz), ys, xs)


def _values(slab: np.ndarray, inside) -> np.ndarray:
    if inside is not None:
        slab = slab[np.broadcast_to(inside, slab.shape)]
    else:
        slab = slab.ravel()
    if slab.dtype.kind == "f":
        slab = slab[np.isfinite(slab)]
    return slab


def value_histogram(data, box=None, roi=None, progress: Progress | None = None
                    ) -> ValueHistogram:
    """The histogram scikit-image thresholds on, over a box (and ROI), read in z-slabs.

    Parameters
    ----------
    data : VoxelVolume or (nz, ny, nx) array
    box : Box, [x0, y0, z0, nx, ny, nz] or None
    roi : Cylinder or MaskRoi, optional
        Only the voxels inside count (:mod:`geoshade.compute.voxels.roi`).

    Returns
    -------
    ValueHistogram
        Integer data: one bin per integer value from the minimum to the maximum present; floats:
        :data:`FLOAT_BINS` equal bins over the finite values (two passes).

    Examples
    --------
    >>> h = value_histogram(np.array([[[3, 5, 5, 9]]], np.uint8))
    >>> h.centers.tolist(), h.counts.tolist()
    ([3, 4, 5, 6, 7, 8, 9], [1, 0, 2, 0, 0, 0, 1])
    """
    arr, box, _ = resolve_data_box(data, box)
    dt = np.dtype(arr.dtype)
    small = dt.kind in "ui" and dt.itemsize <= 2
    nz = box.size[2]
    two = not small

    def rep(base):
        if progress is None:
            return None
        return lambda d, t: progress(base + d, (2 if two else 1) * nz)

    lo, hi = np.inf, -np.inf
    if two:  # limits first
        for z, slab in iter_z_slabs(arr, box, 1, progress=rep(0)):
            v = _values(slab, _inside(roi, box, z, slab.shape[0]))
            if v.size:
                lo, hi = min(lo, v.min().item()), max(hi, v.max().item())
        if not np.isfinite(lo):
            raise InputError("threshold: no finite value in the voxels measured")
    if small or (dt.kind in "ui" and hi - lo <= MAX_INT_SPAN):
        off = -int(np.iinfo(dt).min) if small else -int(lo)
        n = (1 << (8 * dt.itemsize)) if small else int(hi - lo) + 1
        full = np.zeros(n, np.int64)
        for z, slab in iter_z_slabs(arr, box, 1, progress=rep(nz if two else 0)):
            v = _values(slab, _inside(roi, box, z, slab.shape[0]))
            full += np.bincount((v.astype(np.int64) + off), minlength=n)
        h = ValueHistogram(full, np.arange(n, dtype=np.int64) - off, True, int(full.sum()))
        h = h.trimmed()
        if h.voxels == 0:
            raise InputError("threshold: no voxel to measure (empty box or ROI)")
        return h
    # the edges in the data's float type, as numpy makes them from scikit-image's call
    lo_t, hi_t = dt.type(lo), dt.type(hi)
    edges = np.histogram_bin_edges(np.zeros(0, dt), bins=FLOAT_BINS, range=(lo_t, hi_t))
    counts = np.zeros(FLOAT_BINS, np.int64)
    distinct: dict | None = {}
    for z, slab in iter_z_slabs(arr, box, 1, progress=rep(nz)):
        v = _values(slab, _inside(roi, box, z, slab.shape[0]))
        counts += np.histogram(v, bins=edges)[0]
        if distinct is not None:  # a float label image: its values exactly (stops at 17)
            for u, c in zip(*np.unique(v, return_counts=True), strict=True):
                distinct[float(u)] = distinct.get(float(u), 0) + int(c)
            if len(distinct) > LABEL_MAX:
                distinct = None
    centers = (edges[:-1] + edges[1:]) / 2
    return ValueHistogram(counts, centers, False, int(counts.sum()), (float(lo), float(hi)),
                          distinct)


def _merged(h: ValueHistogram, bins: int) -> ValueHistogram:
    """``h`` merged into at most ``bins`` equal bins (centres: the merged bins' middles)."""
    n = h.counts.size
    if n <= bins:
        return h
    idx = np.minimum((np.arange(n) * bins) // n, bins - 1)
    counts = np.bincount(idx, weights=h.counts, minlength=bins).astype(np.int64)
    first = np.searchsorted(idx, np.arange(bins))
    last = np.append(first[1:], n) - 1
    centers = (h.centers[first].astype(np.float64) + h.centers[last]) / 2
    return ValueHistogram(counts, centers, False, h.voxels, h.limits)


@dataclass
class Thresholds:
    """Suggested thresholds of a set of voxels (scikit-image's Otsu and multi-Otsu).

    otsu:      Otsu's threshold; the pore (dark) class is ``v <= otsu``
    multiotsu: the ``classes - 1`` multi-Otsu thresholds (ascending), or [] where there are
               fewer distinct values than classes
    vmin, vmax: the values present
    voxels:    values counted
    labels:    ``[(value, voxels), ...]`` of a label image (few distinct values), else None;
               then :meth:`pore_select` is None: which label is pore is not guessed
    """

    otsu: float
    multiotsu: list[float] = field(default_factory=list)
    classes: int = 3
    vmin: float = 0.0
    vmax: float = 0.0
    voxels: int = 0
    integer: bool = True
    labels: list[tuple[float, int]] | None = None

    def pore_select(self) -> tuple[float, float] | None:
        """The selection of the pore space of a grey-scale image: the dark phase, the values
        up to Otsu's threshold (pores absorb least); None for a label image."""
        return None if self.labels is not None else (self.vmin, self.otsu)

    def label_choices(self) -> list[float]:
        """A label image's labels to offer as selections (``--select V V``): every label of at
        least :data:`LABEL_SHOWN` of the voxels, the rarest first; [] for a grey-scale image.

        >>> Thresholds(0.0, labels=[(0.0, 1), (1.0, 555), (2.0, 9444)]).label_choices()
        [1.0, 2.0]
        """
        if not self.labels:
            return []
        n = sum(c for _, c in self.labels) or 1
        kept = [(v, c) for v, c in self.labels if c / n >= LABEL_SHOWN]
        return [v for v, _ in sorted(kept, key=lambda vc: vc[1])]

    def labels_text(self) -> str:
        """``0: 86.4 %, 255: 13.6 %`` for a label image ('' otherwise).

        >>> Thresholds(0.0, labels=[(0.0, 864), (255.0, 136)]).labels_text()
        '0: 86.4 %, 255: 13.6 %'
        """
        if not self.labels:
            return ""
        n = sum(c for _, c in self.labels) or 1
        return ", ".join(f"{v:g}: {100 * c / n:.1f} %" for v, c in self.labels)

    def to_dict(self) -> dict[str, Any]:
        sel = self.pore_select()
        n = sum(c for _, c in self.labels or []) or 1
        return {"otsu": self.otsu, "multiotsu": list(self.multiotsu), "classes": self.classes,
                "vmin": self.vmin, "vmax": self.vmax, "voxels": self.voxels,
                "pore_select": None if sel is None else list(sel),
                "labels": None if self.labels is None else
                [{"value": v, "voxels": c, "fraction": c / n} for v, c in self.labels],
                "label_select": [[v, v] for v in self.label_choices()]}


def _num(v, integer: bool) -> float:
    return float(int(v)) if integer else float(v)


def thresholds(hist: ValueHistogram, classes: int = 3) -> Thresholds:
    """Otsu's and multi-Otsu's thresholds of a :func:`value_histogram`.

    Examples
    --------
    >>> a = np.repeat(np.array([10, 12, 80, 82, 200, 201], np.uint8), 5)[None, None]
    >>> t = thresholds(value_histogram(a))
    >>> t.otsu, t.multiotsu
    (82.0, [12.0, 82.0])
    """
    filters = require("skimage.filters", "threshold", "suggesting a threshold (Otsu)")
    h = hist.trimmed()
    if h.counts.size == 0 or np.count_nonzero(h.counts) < 2:
        v = float(h.centers[0]) if h.counts.size else float("nan")
        raise InputError(f"threshold: every voxel measured has the value {v:g}; there is no "
                         "threshold to suggest")
    otsu = filters.threshold_otsu(hist=(h.counts, h.centers))
    m = _merged(h, MULTI_BINS)
    multi: list[float] = []
    if np.count_nonzero(m.counts) >= classes:
        mt = filters.threshold_multiotsu(hist=(m.counts, m.centers), classes=classes)
        multi = [_num(v, m.integer) for v in mt]
    vmin, vmax = h.limits or (_num(h.centers[0], True), _num(h.centers[-1], True))
    labels = hist.label_values()
    otsu = _num(otsu, h.integer)
    if labels:   # named by the label at or below: the same classes, a value present
        otsu, multi = _on_label(otsu, labels), [_on_label(v, labels) for v in multi]
    return Thresholds(otsu, multi, classes, vmin, vmax, h.voxels, h.integer, labels)


def _on_label(t: float, labels) -> float:
    """The largest label at or below ``t`` (the first label where none is).

    >>> _on_label(127.0, [(0.0, 5), (255.0, 3)]), _on_label(255.0, [(0.0, 5), (255.0, 3)])
    (0.0, 255.0)
    """
    below = [v for v, _ in labels if v <= t]
    return float(below[-1] if below else labels[0][0])


__all__ = ["FLOAT_BINS", "LABEL_SHOWN", "MULTI_BINS", "Thresholds", "ValueHistogram", "thresholds",
           "value_histogram"]
