"""Digital-core part adapter: range over the histogram, box, method, porosity profile.

The selection maps of a new range or box are built off the GUI thread (a :class:`Job`):
``compute`` runs :func:`geoshade.compute.bitmaps.build_selection_maps` and the porosity, ``apply``
hands the maps to the :class:`~geoshade.core.CoreView`, which uploads them.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from geoshade.errors import InputError
from geoshade.models.volume import Box, VoxelVolume
from geoshade.viewer.parts.base import Job, Part, Progress, fmt_int, unknown_settings

#: bins of the histogram under the range sliders
BINS = 256
#: a volume larger than this many voxels a side opens on a centred box of this side
DEFAULT_BOX_SIDE = 512


@dataclass
class Histogram:
    """counts: (bins,) int64 over equal bins from ``edges[0]`` to ``edges[-1]``; vmin/vmax: the
    finite data limits; nonfinite: NaN/inf voxels (not counted)."""

    counts: np.ndarray
    edges: np.ndarray
    vmin: float
    vmax: float
    nonfinite: int = 0


def volume_histogram(volume: VoxelVolume, bins: int = BINS,
                     progress: Progress | None = None) -> Histogram:
    """Histogram of the whole volume, read in z-slabs (lazy volumes are never read whole).

    8- and 16-bit data take one pass (an exact bincount rebinned over the data's limits); other
    dtypes two (limits, then counts).

    Examples
    --------
    >>> from geoshade.compute.synthetic import synthetic_core
    >>> h = volume_histogram(synthetic_core(16), bins=8)
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
    """The whole volume, or a centred box of ``side`` voxels per axis where it is larger."""
    shape = volume.shape_xyz
    size = tuple(min(n, side) for n in shape)
    off = tuple((n - s) // 2 for n, s in zip(shape, size, strict=True))
    return Box(off, size)


def default_range(volume: VoxelVolume, hist: Histogram) -> tuple[float, float]:
    """``meta['pore_range']`` where the file says, else the lower half of the data's values."""
    pr = (volume.meta or {}).get("pore_range")
    if pr is not None:
        return float(pr[0]), float(pr[1])
    mid = (hist.vmin + hist.vmax) / 2
    if volume.dtype.kind in "ui":
        mid = float(np.floor(mid))
    return hist.vmin, mid


@dataclass
class Prepared:
    box: Box
    lo: float
    hi: float
    color_range: tuple[float, float]
    maps: object
    prepare_ms: float
    porosity: object


def color_range(hist: Histogram, lo: float, hi: float) -> tuple[float, float]:
    """Colours spread over the values present in the range (as ``geoshade demo`` does)."""
    clo, chi = max(lo, hist.vmin), min(hi, hist.vmax)
    return (clo, chi) if clo < chi else (lo, hi)


def prepare_selection(volume: VoxelVolume, hist: Histogram, range=None, box=None,
                      axis: str = "z", progress: Progress | None = None) -> Prepared:
    """CPU half of a new selection (any thread): selection maps and porosity.

    ``range`` None: :func:`default_range`; ``box`` None: :func:`default_box`.
    """
    from geoshade.compute.bitmaps import build_selection_maps
    from geoshade.compute.porosity import porosity
    from geoshade.compute.selection import check_range

    rng = default_range(volume, hist) if range is None else range
    lo, hi = check_range(*rng, volume.dtype)
    bx = default_box(volume) if box is None else volume.resolve_box(box)
    clo, chi = color_range(hist, lo, hi)
    t0 = time.perf_counter()
    maps = build_selection_maps(volume.data, bx, lo, hi, clo, chi, progress=progress)
    ms = (time.perf_counter() - t0) * 1000
    poro = porosity(volume, lo, hi, box=bx, axis=axis)
    return Prepared(bx, lo, hi, (clo, chi), maps, ms, poro)


class CorePart(Part):
    """The digital-core view of a :class:`VoxelVolume`.

    Settings: ``range`` (lo, hi), ``box`` ([x0, y0, z0, nx, ny, nz] or None), ``method``,
    ``axis`` (of the porosity profile).
    """

    kind = "core"
    title = "digital core"

    def __init__(self, volume: VoxelVolume, size=(800, 600), range=None, box=None,
                 method: str = "auto", axis: str = "z", histogram: Histogram | None = None,
                 prepared: Prepared | None = None, ctx=None):
        from geoshade.core import CoreView

        if not isinstance(volume, VoxelVolume):
            raise InputError(f"volume: expected a VoxelVolume, got {type(volume).__name__}")
        self.volume = volume
        self.hist = histogram if histogram is not None else volume_histogram(volume)
        self.axis = axis
        prep = prepared or prepare_selection(volume, self.hist, range, box, axis)
        # a 1-voxel view first: the real maps come from the CPU half (see core_apply)
        self.view = CoreView(volume, range=(prep.lo, prep.hi), box=[*prep.box.offset, 1, 1, 1],
                             method=method, size=size, ctx=ctx)
        self.method_name = method  # as asked ("auto" stays "auto"; the stats say what it is)
        self.porosity = None
        self._apply(prep)

    @classmethod
    def precompute(cls, volume, settings: dict, progress: Progress | None = None) -> dict:
        """CPU half of opening (any thread): the histogram and the first selection maps."""
        hist = volume_histogram(volume, progress=progress)
        prep = prepare_selection(volume, hist, settings.get("range"), settings.get("box"),
                                 settings.get("axis", "z"), progress)
        return {"histogram": hist, "prepared": prep}

    @classmethod
    def accepts(cls, model) -> bool:
        return isinstance(model, VoxelVolume) and not (model.meta or {}).get("legend")

    @classmethod
    def demo(cls):
        from geoshade.compute.synthetic import synthetic_core

        return synthetic_core(64, porosity=0.2, seed=7), {}

    # --- the two halves of a new selection ----------------------------------------------------
    def prepare(self, range, box, progress: Progress | None = None) -> Prepared:
        """CPU only (any thread): selection maps and porosity of ``range`` inside ``box``."""
        return prepare_selection(self.volume, self.hist, range, box, self.axis, progress)

    def _apply(self, prep: Prepared) -> None:
        core_apply(self.view, prep)
        self.porosity = prep.porosity

    def selection_job(self, range=None, box=None) -> Job:
        st = self.view.state
        rng = (st.lo, st.hi) if range is None else tuple(range)
        bx = st.box if box is None else box
        return Job("selection", "building bit maps",
                   lambda progress: self.prepare(rng, bx, progress), self._apply)

    # --- settings ------------------------------------------------------------------------------
    def settings(self) -> dict:
        st = self.view.state
        return {"range": (st.lo, st.hi), "box": [*st.box.offset, *st.box.size],
                "method": self.method_name, "axis": self.axis}

    def apply(self, **settings) -> list[Job]:
        extra = set(settings) - {"range", "box", "method", "axis"}
        if extra:
            raise unknown_settings(self, extra)
        if "method" in settings:
            self.view.set_method(settings["method"])
            self.method_name = settings["method"]
        if "axis" in settings:
            if settings["axis"] not in ("x", "y", "z"):
                raise InputError(f"axis: expected x, y or z, got {settings['axis']!r}")
            self.axis = settings["axis"]
        if {"range", "box", "axis"} & set(settings):
            return [self.selection_job(settings.get("range"), settings.get("box"))]
        return []

    def readout(self, stats: dict) -> str:
        poro = "" if self.porosity is None else f" · porosity {self.porosity.porosity:.4f}"
        drawn = stats.get("voxels_drawn")
        return (f"{stats.get('method')} · {fmt_int(stats.get('voxels_selected'))} voxels "
                f"selected · {'…' if drawn is None else fmt_int(drawn)} drawn{poro}")


def core_apply(view, prep: Prepared) -> None:
    """Hand CPU-built selection maps to a CoreView, which uploads them (GL thread)."""
    view.apply_selection(prep)
