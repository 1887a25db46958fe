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


#: what ``select`` takes to select the pore space by Otsu's threshold
AUTO_SELECT = ("auto", "otsu")


def is_auto(select) -> bool:
    """``select`` asks for the pore space by Otsu's threshold (``"auto"`` or ``"otsu"``).

    >>> is_auto("auto"), is_auto(("auto",)), is_auto((0, 80))
    (True, True, False)
    """
    if isinstance(select, list | tuple) and len(select) == 1:
        select = select[0]
    return isinstance(select, str) and select.strip().lower() in AUTO_SELECT


def region(volume: VoxelVolume, box=None, roi=None, mask=None, progress=None):
    """``(Box, ROI or None)``: the box checked against the volume and the ROI resolved
    (``roi``: ``"cylinder"`` fitted, ``"cylinder:CX,CY,R"``, a Cylinder; ``mask``: a
    VoxelVolume, an array or a file name read with :func:`geoshade.io.load`).

    >>> import geoshade
    >>> region(geoshade.synthetic_core(8), roi="cylinder:4,4,3")[1]
    Cylinder(cx=4.0, cy=4.0, r=3.0, fitted=False)
    """
    from geoshade.compute.roi import MaskRoi, resolve_roi

    b = volume.resolve_box(box)
    if isinstance(mask, str) or hasattr(mask, "__fspath__"):
        mvol = _load_mask(mask, volume)
        mask = MaskRoi(getattr(mvol, "data", mvol), str(mask))
    elif isinstance(mask, VoxelVolume):
        mask = MaskRoi(mask.data, mask.name or "mask")
    return b, resolve_roi(roi, volume.data, mask=mask, name=volume.name or "volume",
                          progress=progress)


_RAW_SUFFIXES = (".raw", ".bin", ".img", ".vol", ".dat")


def _load_mask(path, volume: VoxelVolume):
    """A mask file: any volume :func:`geoshade.io.load` reads; a headerless raw mask is read
    with the volume's shape, one uint8 or uint16 value per voxel (told by its size)."""
    import os
    from pathlib import Path

    from geoshade.io import load
    from geoshade.io.paths import check_file
    from geoshade.io.volumes.sidecar import find_sidecar

    if Path(path).suffix.lower() in _RAW_SUFFIXES and find_sidecar(path) is None:
        n = int(np.prod(volume.shape_xyz, dtype=np.int64))
        size = os.path.getsize(check_file(path, "a mask file"))
        dtype = {n: "uint8", 2 * n: "uint16"}.get(size)
        if dtype is None:
            raise InputError(f"{path}: mask: a headerless raw mask holds one uint8 or uint16 "
                             f"value per voxel of the volume ({n} voxels), but it has {size} "
                             "bytes")
        return load(path, shape=volume.shape_xyz, dtype=dtype)
    return load(path)


def thresholds(volume: VoxelVolume, box=None, roi=None, mask=None, classes: int = 3,
               progress: Progress | None = None):
    """Suggested thresholds of the voxels of ``box`` inside ``roi``: Otsu's and multi-Otsu's
    (scikit-image, on the same histogram it would make; :mod:`geoshade.compute.threshold`).

    Returns
    -------
    geoshade.compute.threshold.Thresholds
        ``otsu``, ``multiotsu``, ``vmin``, ``vmax``; ``pore_select()`` is the selection of the
        pore space, ``(vmin, otsu)``.

    Examples
    --------
    >>> import geoshade
    >>> t = geoshade.core.thresholds(geoshade.synthetic_core(16, dtype="uint8"))
    >>> t.vmin < t.otsu < t.vmax
    True
    """
    from geoshade.compute.threshold import thresholds as _thresholds
    from geoshade.compute.threshold import value_histogram

    b, r = (box, roi) if _resolved(box, roi) else region(volume, box, roi, mask)
    return _thresholds(value_histogram(volume, b, r, progress=progress), classes=classes)


def _resolved(box, roi) -> bool:
    from geoshade.compute.roi import Cylinder, MaskRoi

    return isinstance(box, Box) and (roi is None or isinstance(roi, Cylinder | MaskRoi))


def auto_select(volume: VoxelVolume, box=None, roi=None, mask=None,
                progress: Progress | None = None) -> tuple[tuple[float, float], dict]:
    """The selection of the pore space: the values up to Otsu's threshold of the voxels of
    ``box`` inside ``roi``; and how it was found (``{"method": "otsu", "threshold": t, ...}``).

    >>> import geoshade
    >>> sel, how = geoshade.core.auto_select(geoshade.synthetic_core(16, dtype="uint8"))
    >>> sel[1] == how["threshold"], how["method"]
    (True, 'otsu')
    """
    t = thresholds(volume, box, roi, mask, progress=progress)
    lo, hi = t.pore_select()
    return (lo, hi), {"method": "otsu", "threshold": t.otsu, "multiotsu": t.multiotsu,
                      "vmin": t.vmin, "vmax": t.vmax, "voxels": t.voxels}


def porosity(volume: VoxelVolume, select=None, box=None, axis: str = "z", progress=None,
             scheduler=None, range=None, roi=None, mask=None):
    """Pore fraction inside ``box`` (and ``roi``/``mask``) for values in ``select``: total and a
    profile along ``axis``.

    ``select`` is ``(lo, hi)`` or ``"auto"`` (the values up to Otsu's threshold of the voxels
    measured; the result's ``select_auto`` says how). ``roi``: ``"cylinder"`` (fitted to the
    sample), ``"cylinder:CX,CY,R"`` (voxels) or a Cylinder; ``mask``: a volume (nonzero =
    inside), an array or a file. Voxels outside count neither as pores nor as voxels.
    ``range`` is the deprecated name of ``select``.

    >>> import geoshade
    >>> r = geoshade.core.porosity(geoshade.synthetic_core(16), (0, 15000))
    >>> 0 <= r.porosity <= 1
    True
    """
    if select is None:
        select = range
    if select is None:
        raise InputError("select: porosity needs the pore values LO HI (--select LO HI) or "
                         "'auto' (Otsu)")
    if axis not in ("x", "y", "z"):
        raise InputError(f"axis: expected x, y or z, got {axis!r}")
    b, r = region(volume, box, roi, mask)
    how = None
    if is_auto(select):
        select, how = auto_select(volume, b, r)
    try:
        lo, hi = select
    except (TypeError, ValueError):
        raise InputError(f"select: expected two numbers LO HI or 'auto', got {select!r}"
                         ) from None
    lo, hi = check_range(lo, hi, volume.dtype, name="select")
    if scheduler is not None:  # a dask graph on that scheduler (same result)
        from geoshade.compute.porosity_lazy import porosity as lazy_porosity

        res = lazy_porosity(volume, lo, hi, box=b, axis=axis, roi=r, scheduler=scheduler,
                            progress=progress)
    else:
        res = _porosity(volume, lo, hi, box=b, axis=axis, progress=progress, roi=r)
    res.select_auto = how
    return res


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


__all__ = ["AUTO_SELECT", "BINS", "DEFAULT_BOX_SIDE", "Histogram", "auto_select", "default_box",
           "default_range", "display_color_range", "histogram", "is_auto", "porosity", "region",
           "thresholds"]
