"""What the digital-core part measures and shows beside the picture: porosity, the volume's
histogram, the default box and selection of a viewer, the colour range over a selection.
No GL."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from geoshade.compute.porosity import porosity as _porosity
from geoshade.compute.selection import check_range
from geoshade.errors import InputError
from geoshade.models.volume import Box, VoxelVolume
from geoshade.progress import Progress

#: bins of the histogram a viewer shows under its selection sliders
BINS = 256
#: a volume larger than this many voxels a side opens on a centred box of this side
DEFAULT_BOX_SIDE = 512


def porosity(volume: VoxelVolume, select=None, box=None, axis: str = "z", progress=None,
             scheduler=None, range=None):
    """Pore fraction inside ``box`` for values in ``select``: total and a profile along ``axis``.

    ``range`` is the deprecated name of ``select``.

    >>> import geoshade
    >>> r = geoshade.core.porosity(geoshade.synthetic_core(16), (0, 15000))
    >>> 0 <= r.porosity <= 1
    True
    """
    if select is None:
        select = range
    if select is None:
        raise InputError("select: porosity needs the pore values LO HI (--select LO HI)")
    try:
        lo, hi = select
    except (TypeError, ValueError):
        raise InputError(f"select: expected two numbers LO HI, got {select!r}") from None
    lo, hi = check_range(lo, hi, volume.dtype, name="select")
    if axis not in ("x", "y", "z"):
        raise InputError(f"axis: expected x, y or z, got {axis!r}")
    if scheduler is not None:  # a dask graph on that scheduler (same result)
        from geoshade.compute.lazy import porosity as lazy_porosity

        return lazy_porosity(volume, lo, hi, box=volume.resolve_box(box), axis=axis,
                             scheduler=scheduler, progress=progress)
    return _porosity(volume, lo, hi, box=volume.resolve_box(box), axis=axis, progress=progress)


@dataclass
class Histogram:
    """counts: (bins,) int64 over equal bins from ``edges[0]`` to ``edges[-1]``; vmin/vmax: the
    finite data limits; nonfinite: NaN/inf voxels (not counted)."""

    counts: np.ndarray
    edges: np.ndarray
    vmin: float
    vmax: float
    nonfinite: int = 0


def histogram(volume: VoxelVolume, bins: int = BINS,
              progress: Progress | None = None) -> Histogram:
    """Histogram of the whole volume, read in z-slabs (lazy volumes are never read whole).

    8- and 16-bit data take one pass (an exact bincount rebinned over the data's limits); other
    dtypes two (limits, then counts).

    Examples
    --------
    >>> from geoshade.compute.synthetic import synthetic_core
    >>> h = histogram(synthetic_core(16), bins=8)
    >>> int(h.counts.sum()), h.vmin < h.vmax
    (4096, True)
    """
    from geoshade.compute.selection import iter_z_slabs

    data, box, dt = volume.data, volume.full_box(), volume.dtype
    if dt.kind in "ui" and dt.itemsize <= 2:
        off = -int(np.iinfo(dt).min)
        full = np.zeros(1 << (8 * dt.itemsize), np.int64)
        for _, slab in iter_z_slabs(data, box, 1, progress=progress):
            full += np.bincount((slab.astype(np.int64) + off).ravel(), minlength=full.size)
        present = np.flatnonzero(full)
        vmin, vmax = float(present[0] - off), float(present[-1] - off)
        values = np.arange(full.size, dtype=np.float64) - off
        edges = np.histogram_bin_edges(np.zeros(0), bins=bins, range=(vmin, vmax + 1))
        counts = np.histogram(values, bins=edges, weights=full)[0].astype(np.int64)
        return Histogram(counts, edges, vmin, vmax)
    total = max(1, box.size[2])

    def half(done, _total, base):
        if progress is not None:
            progress(base + done, 2 * total)

    vmin, vmax, bad = np.inf, -np.inf, 0
    for _, slab in iter_z_slabs(data, box, 1, progress=lambda d, t: half(d, t, 0)):
        fin = np.isfinite(slab)
        bad += int(fin.size - np.count_nonzero(fin))
        if fin.any():
            vmin, vmax = min(vmin, float(slab[fin].min())), max(vmax, float(slab[fin].max()))
    if not np.isfinite(vmin):
        raise InputError(f"{volume.name or 'volume'}: no finite value to show")
    hi = vmax if vmax > vmin else vmin + 1
    counts = np.zeros(bins, np.int64)
    for _, slab in iter_z_slabs(data, box, 1, progress=lambda d, t: half(d, t, total)):
        counts += np.histogram(slab, bins=bins, range=(vmin, hi))[0]
    return Histogram(counts, np.linspace(vmin, hi, bins + 1), vmin, vmax, bad)


def default_box(volume: VoxelVolume, side: int = DEFAULT_BOX_SIDE) -> Box:
    """The whole volume, or a centred box of ``side`` voxels per axis where it is larger.

    >>> from geoshade.compute.synthetic import synthetic_core
    >>> default_box(synthetic_core(16), side=8)
    Box(offset=(4, 4, 4), size=(8, 8, 8))
    """
    nx, ny, nz = volume.shape_xyz
    sx, sy, sz = min(nx, side), min(ny, side), min(nz, side)
    return Box(((nx - sx) // 2, (ny - sy) // 2, (nz - sz) // 2), (sx, sy, sz))


def default_range(volume: VoxelVolume, hist: Histogram) -> tuple[float, float]:
    """The selection a viewer opens with: ``meta['pore_range']`` where the file says, else the
    lower half of the values present (the darker phase: pores in absorption images)."""
    pr = (volume.meta or {}).get("pore_range")
    if pr is not None:
        return float(pr[0]), float(pr[1])
    mid = (hist.vmin + hist.vmax) / 2
    if volume.dtype.kind in "ui":
        mid = float(np.floor(mid))
    return hist.vmin, mid


def display_color_range(hist: Histogram, lo: float, hi: float) -> tuple[float, float]:
    """Colours spread over the values present inside the selection (as the demo does)."""
    clo, chi = max(lo, hist.vmin), min(hi, hist.vmax)
    return (clo, chi) if clo < chi else (lo, hi)


__all__ = ["BINS", "DEFAULT_BOX_SIDE", "Histogram", "default_box", "default_range",
           "display_color_range", "histogram", "porosity"]
