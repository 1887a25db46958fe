"""What the digital-core part measures and shows beside the picture: porosity, the volume's
histogram, the default box and selection of a viewer, the colour range over a selection.
No GL."""

from __future__ import annotations

import os
import weakref
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from geoshade.compute.voxels.porosity import porosity as _porosity
from geoshade.compute.voxels.roi import Cylinder, MaskRoi, resolve_roi
from geoshade.compute.voxels.sample import LABEL_MAX, Sample, SampleRoi, warn_outside
from geoshade.compute.voxels.sample import detect_sample as _detect
from geoshade.compute.voxels.selection import check_range, iter_z_slabs
from geoshade.compute.voxels.threshold import thresholds as _thresholds
from geoshade.compute.voxels.threshold import value_histogram
from geoshade.errors import InputError
from geoshade.io import load
from geoshade.io.paths import check_file
from geoshade.io.volumes.sidecar import find_sidecar
from geoshade.models.volume import Box, VoxelVolume
from geoshade.progress import Progress
from geoshade.scheduler import checked
from geoshade.styles.categories import CategoricalPalette, categorical_palette
from geoshade.styles.options import ColorStyle

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
    (``roi``: ``"cylinder"`` fitted, ``"cylinder:CX,CY,R"``, a Cylinder, ``"sample"`` the
    sample detected in the box (:func:`detect_sample`; None without air); ``mask``: a
    VoxelVolume, an array or a file name read with :func:`geoshade.io.load`).

    >>> import geoshade
    >>> region(geoshade.synthetic_core(8), roi="cylinder:4,4,3")[1]
    Cylinder(cx=4.0, cy=4.0, r=3.0, fitted=False)
    """

    b = volume.resolve_box(box)
    if isinstance(roi, str) and roi.strip().lower() == "sample" and mask is None:
        return b, detect_sample(volume, b, progress=progress).roi  # None: no air, every voxel
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
    (scikit-image, on the same histogram it would make; :mod:`geoshade.compute.voxels.threshold`).

    Returns
    -------
    geoshade.compute.voxels.threshold.Thresholds
        ``otsu``, ``multiotsu``, ``vmin``, ``vmax``; ``pore_select()`` is the selection of the
        pore space, ``(vmin, otsu)``.

    Examples
    --------
    >>> import geoshade
    >>> t = geoshade.core.thresholds(geoshade.synthetic_core(16, dtype="uint8"))
    >>> t.vmin < t.otsu < t.vmax
    True
    """

    b, r = (box, roi) if _resolved(box, roi) else region(volume, box, roi, mask)
    return _thresholds(value_histogram(volume, b, r, progress=progress), classes=classes)


def _resolved(box, roi) -> bool:

    return isinstance(box, Box) and (roi is None or isinstance(roi, Cylinder | MaskRoi |
                                                                SampleRoi))


#: ``sample=`` of :func:`porosity`: detect the sample in air (default) or count every voxel
SAMPLE_MODES = ("auto", "none")
_SAMPLES: dict[int, tuple[Any, dict]] = {}  # id(volume) -> (weakref, {box: Sample})


def detect_sample(volume: VoxelVolume, box=None, progress: Progress | None = None):
    """The sample in the box, told from the air around it
    (:func:`geoshade.compute.voxels.sample.detect_sample`), remembered per volume and box.

    >>> import geoshade
    >>> geoshade.core.detect_sample(geoshade.synthetic_core(16)).status
    'no air'
    """

    b = volume.resolve_box(box)
    key = (tuple(b.offset), tuple(b.size))
    ref, found = _SAMPLES.get(id(volume), (None, None))
    if ref is None or found is None or ref() is not volume:
        ref, found = weakref.ref(volume), {}
        _SAMPLES[id(volume)] = (ref, found)
        weakref.finalize(volume, _SAMPLES.pop, id(volume), None)
    if key not in found:
        found[key] = _detect(volume, b, name=volume.name or "volume", progress=progress)
    return found[key]


def _label_refusal(volume: VoxelVolume, t) -> InputError:
    # every label of the image (the rarest first), none of a share that reads 0.0 %
    uses = " or ".join(f"--select {v:g} {v:g}" for v in t.label_choices())
    return InputError(f"{volume.name or 'volume'}: select auto: a label image "
                      f"({t.labels_text()}) — which value is pore? use {uses}")


def auto_select(volume: VoxelVolume, box=None, roi=None, mask=None,
                progress: Progress | None = None) -> tuple[tuple[float, float], dict]:
    """The selection of the pore space of a grey-scale image, and how it was found.

    The dark phase: the values up to Otsu's threshold of the voxels of ``box`` inside ``roi``
    (pores hold air, which absorbs the least X-rays).  Without an ROI the air around a sample
    scanned in air is part of that histogram on purpose: it is the dark phase the pores hold,
    and Otsu splits it from the solid (a threshold inside the sample alone would split two
    solid phases of a three-phase rock or concrete); :func:`porosity` then counts only the
    sample (:func:`detect_sample`).  ``roi="sample"`` (the detected sample as an ROI, to draw
    only it) takes the same threshold.  A label
    image (at most :data:`~geoshade.compute.voxels.sample.LABEL_MAX` distinct values) is refused in
    one line listing its values and their fractions: which label is pore is not guessed.

    Returns
    -------
    ((lo, hi), how)
        ``how``: ``{"method": "otsu", "threshold", "side": "dark", "text", "within", ...}``;
        ``text`` says which side was taken and why (the CLI, the picture, the JSON and the plot
        show it).

    Examples
    --------
    >>> import geoshade
    >>> sel, how = geoshade.core.auto_select(geoshade.synthetic_core(16, dtype="uint8"))
    >>> sel[1] == how["threshold"], how["method"], how["text"].split(" ≤")[0]
    (True, 'otsu', 'dark phase')
    """
    b, r = (box, roi) if _resolved(box, roi) and mask is None else region(volume, box, roi,
                                                                          mask)

    if isinstance(r, SampleRoi):  # the detected sample: the same threshold as without an ROI
        r = None
    t = thresholds(volume, b, r, progress=progress)
    if t.labels is not None:
        raise _label_refusal(volume, t)
    within = "the box" if r is None else r.text()
    if r is None and detect_sample(volume, b).roi is not None:
        within = "the box, the air around the sample included"
    lo, hi = t.pore_select()
    text = (f"dark phase ≤ Otsu {t.otsu:,.6g} taken as pore (pores hold air, which absorbs "
            f"least; Otsu of {within})")
    return (lo, hi), {"method": "otsu", "threshold": t.otsu, "side": "dark", "within": within,
                      "text": text, "multiotsu": t.multiotsu, "vmin": t.vmin, "vmax": t.vmax,
                      "voxels": t.voxels}


def resolve_select(volume: VoxelVolume, select, box=None, roi=None, mask=None,
                   progress: Progress | None = None
                   ) -> tuple[tuple[float, float], dict | None]:
    """``select`` as every path takes it (CLI, viewer, notebook): ``(lo, hi)`` checked against
    the volume's dtype, or ``"auto"`` turned into the pore space by :func:`auto_select`; and how
    it was found (None for numbers).

    >>> import geoshade
    >>> geoshade.core.resolve_select(geoshade.synthetic_core(8), (0, 9))
    ((0.0, 9.0), None)
    """
    how = None
    if is_auto(select):
        select, how = auto_select(volume, box, roi, mask, progress=progress)
    try:
        lo, hi = select
    except (TypeError, ValueError):
        raise InputError(f"select: expected two numbers LO HI or 'auto', got {select!r}"
                         ) from None
    return check_range(lo, hi, volume.dtype, name="select"), how


def porosity(volume: VoxelVolume, select=None, box=None, axis: str = "z", progress=None,
             scheduler=None, range=None, roi=None, mask=None, sample: str = "auto"):
    """Pore fraction of the sample inside ``box`` for values in ``select``: total and a profile
    along ``axis``.

    What counts (docs/guide/core.rst, "What porosity counts"): the selected voxels of
    ``box`` ∩ region, over the voxels of ``box`` ∩ region, where the region is ``roi``/``mask``
    when given, else the sample detected in air (``sample="auto"``,
    :func:`detect_sample`; ``"none"``: every voxel of the box).  When more than 20 % of the
    selected voxels lie outside the detected sample, a
    :class:`~geoshade.compute.voxels.sample.SampleWarning` says how many (and ``warning``).

    ``select`` is ``(lo, hi)`` or ``"auto"`` (:func:`auto_select`; the result's
    ``select_auto`` says how). ``roi``: ``"cylinder"`` (fitted to the sample),
    ``"cylinder:CX,CY,R"`` (voxels) or a Cylinder; ``mask``: a volume (nonzero = inside), an
    array or a file. ``range`` is the deprecated name of ``select``.  ``scheduler``: the
    porosity runs as dask tasks there (the same function and result).

    >>> import geoshade
    >>> r = geoshade.core.porosity(geoshade.synthetic_core(16), (0, 15000))
    >>> 0 <= r.porosity <= 1, r.sample["status"]
    (True, 'no air')
    """

    if select is None:
        select = range
    if select is None:
        raise InputError("select: porosity needs the pore values LO HI (--select LO HI) or "
                         "'auto' (Otsu)")
    if axis not in ("x", "y", "z"):
        raise InputError(f"axis: expected x, y or z, got {axis!r}")
    scheduler = checked(scheduler)   # one line before any work for what is no scheduler
    if sample not in SAMPLE_MODES:
        raise InputError(f"sample: expected one of {', '.join(SAMPLE_MODES)}, got {sample!r}")
    b, r = region(volume, box, roi, mask)
    _check_stored(volume, b)
    (lo, hi), how = resolve_select(volume, select, b, r)
    if (isinstance(roi, SampleRoi) and sample == "auto"
            and detect_sample(volume, b).roi is roi):
        r = None   # the sample a View detected and draws by default: counted as the sample
    if r is not None:
        note = getattr(r, "note", "")
        smp, sdict = None, {"status": "roi", "text": f"counted inside {r.text()}"
                            + (f" ({note})" if note else "")}
    elif sample == "none":
        smp, sdict = None, {"status": "off", "text": "every voxel of the box counts "
                                                     "(sample detection off)"}
    else:
        found: Sample = detect_sample(volume, b)
        smp, sdict = found.roi, found.to_dict()
    res = _porosity(volume, lo, hi, box=b, axis=axis, progress=progress, roi=r, sample=smp,
                    scheduler=scheduler)
    res.select_auto, res.sample = how, sdict
    # a label image's value is a phase: which one is pore is not known (PorosityResult.pores)
    res.label_image = (sdict.get("status") == "label image"
                       or detect_sample(volume, b).status == "label image")
    if smp is not None:
        res.warning = warn_outside(res.outside or 0, res.count, volume.name or "volume")
    return res


#: never-written chunks (zarr reads them as the fill value) a count may go through one by one
UNSTORED_BUDGET = 100_000


def _check_stored(volume: VoxelVolume, box: Box) -> None:
    """One line instead of a crawl: a store (not written by geoshade; zarr leaves chunks of the
    fill value unwritten) whose box spans more than :data:`UNSTORED_BUDGET` chunks beyond the
    ones it holds, e.g. a 400-byte ``zarr.json`` declaring 100000³ voxels.

    >>> import numpy as np
    >>> v = VoxelVolume(np.zeros((64, 64, 64), np.uint8), meta={"chunks_stored": [0, 8]})
    >>> _check_stored(v, v.full_box())   # 8 chunks of zeros: counted
    >>> v.meta.update(chunks_stored=[3, 4 * 10**6], chunks=[1, 1, 1])
    >>> _check_stored(v, v.full_box())
    Traceback (most recent call last):
    ...
    geoshade.errors.InputError: volume: the box spans 262,144 chunks but the store holds only 3:...
    """
    counted = (volume.meta or {}).get("chunks_stored")
    chunks = (volume.meta or {}).get("chunks") or getattr(volume.data, "chunksize", None)
    if not counted or chunks is None:
        return
    stored = int(counted[0])
    cz, cy, cx = (int(c) for c in chunks)
    (x0, y0, z0), (nx, ny, nz) = box.offset, box.size
    spanned = 1
    for o, n, c in ((x0, nx, cx), (y0, ny, cy), (z0, nz, cz)):
        spanned *= (o + n - 1) // c - o // c + 1
    if spanned - stored > UNSTORED_BUDGET:
        raise InputError(f"{volume.name or 'volume'}: the box spans {spanned:,} chunks but the "
                         f"store holds only {stored:,}: the others were never written (read as "
                         "the fill value) and counting them one by one would not end; give "
                         "--box within the stored part")


def porosity_line(res) -> str:
    """One line saying the number and what it counts: what the CLI prints first and the
    picture's title repeats (:meth:`PorosityResult.notes` follow it).

    >>> import geoshade
    >>> porosity_line(geoshade.core.porosity(geoshade.synthetic_core(8), (0, 0)))
    'porosity 0.0000 (0 of 512 voxels in [0, 0])'
    """
    lo, hi = res.range
    where = ""
    if res.sample and res.sample.get("status") == "in air":
        where = " of the sample"
    elif res.roi and res.roi.get("kind") == "sample":
        where = " of the sample"
    elif res.roi:
        where = f" inside {res.roi['text']}"
    return (f"{res.quantity} {res.porosity:.4f} ({res.count:,} of {res.total:,} voxels{where} "
            f"in [{lo:g}, {hi:g}])")


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
    >>> from geoshade.compute.voxels.synthetic import synthetic_core
    >>> h = histogram(synthetic_core(16), bins=8)
    >>> int(h.counts.sum()), h.vmin < h.vmax
    (4096, True)
    """

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


#: largest box (voxels) whose values :func:`box_values` reads for the colour range and labels
VALUES_BUDGET = 1 << 28
_VALUES: dict[int, tuple[Any, dict]] = {}  # id(volume) -> (weakref, {box: BoxValues | None})


@dataclass(frozen=True)
class BoxValues:
    """The values present in a box: ``vmin``/``vmax`` (finite), ``codes`` the distinct values
    where there are at most :data:`~geoshade.compute.voxels.sample.LABEL_MAX` (a label image's
    labels, with ``counts``), else None; ``source``: ``"box"`` (read) or ``"store"`` (the
    ingest's recorded range, codes unknown)."""

    vmin: float
    vmax: float
    codes: np.ndarray | None = None
    counts: np.ndarray | None = None
    source: str = "box"

    @property
    def labels(self) -> bool:
        """A label image: few distinct whole-number values.

        >>> BoxValues(0, 2, np.array([0.0, 1.0, 2.0])).labels
        True
        """
        c = self.codes
        return c is not None and c.size >= 1 and bool(np.all(c == np.round(c)))


def box_values(volume: VoxelVolume, box=None) -> BoxValues | None:
    """The values present in ``box`` (:class:`BoxValues`), remembered per volume and box: read
    in z-slabs where the box holds at most :data:`VALUES_BUDGET` voxels (8- and 16-bit data by
    one exact bincount), else a store's recorded ``value_range``, else None (not known).

    >>> import numpy as np
    >>> v = VoxelVolume(np.array([[[3, 9, 3, 7]]], np.uint16))
    >>> b = box_values(v)
    >>> b.vmin, b.vmax, b.codes.tolist(), b.counts.tolist()
    (3.0, 9.0, [3.0, 7.0, 9.0], [2, 1, 1])
    """
    b = volume.resolve_box(box)
    key = (tuple(b.offset), tuple(b.size))
    ref, found = _VALUES.get(id(volume), (None, None))
    if ref is None or found is None or ref() is not volume:
        ref, found = weakref.ref(volume), {}
        _VALUES[id(volume)] = (ref, found)
        weakref.finalize(volume, _VALUES.pop, id(volume), None)
    if key not in found:
        found[key] = _read_values(volume, b)
    return found[key]


def _read_values(volume: VoxelVolume, b: Box) -> BoxValues | None:
    vr = (volume.meta or {}).get("value_range")
    if b.nvoxels > VALUES_BUDGET or (volume.is_lazy and vr is not None
                                     and b == volume.full_box()):
        return None if vr is None else BoxValues(float(vr[0]), float(vr[1]), source="store")
    dt = np.dtype(volume.dtype)
    if dt.kind in "uib" and dt.itemsize <= 2:
        off = -int(np.iinfo(dt).min) if dt.kind != "b" else 0
        full = np.zeros(1 << (8 * max(1, dt.itemsize)), np.int64)
        for _, slab in iter_z_slabs(volume.data, b):
            full += np.bincount((slab.astype(np.int64) + off).ravel(), minlength=full.size)
        present = np.flatnonzero(full)
        if present.size == 0:
            return None
        values = (present - off).astype(np.float64)
        few = present.size <= LABEL_MAX
        return BoxValues(float(values[0]), float(values[-1]), values if few else None,
                         full[present] if few else None)
    lo, hi = np.inf, -np.inf
    distinct: dict | None = {}
    for _, slab in iter_z_slabs(volume.data, b):
        v = slab[np.isfinite(slab)] if slab.dtype.kind == "f" else slab.ravel()
        if v.size == 0:
            continue
        lo, hi = min(lo, float(v.min())), max(hi, float(v.max()))
        if distinct is not None:
            u, c = np.unique(v, return_counts=True)
            for x, n in zip(u.tolist(), c.tolist(), strict=True):
                distinct[float(x)] = distinct.get(float(x), 0) + int(n)
            if len(distinct) > LABEL_MAX:
                distinct = None
    if not np.isfinite(lo):
        return None
    if distinct is None:
        return BoxValues(lo, hi)
    codes = np.array(sorted(distinct), np.float64)
    return BoxValues(lo, hi, codes, np.array([distinct[c] for c in codes], np.int64))


@dataclass(frozen=True)
class CoreColours:
    """How a core picture is coloured (:func:`core_colours`).

    style:      the colour style drawn with, its range explicit where it was automatic
    source:     where the colour range comes from: ``"style"`` (asked for), ``"selection"``,
                ``"data"`` (the values present in the box inside the selection, not the
                dtype's), ``"labels"`` (a label image drawn as classes)
    categories: the label image's palette (one qualitative colour per label), else None
    counts:     {label: voxels of the box} of a label image
    note:       what could not be done as asked ('' when all was)
    """

    style: ColorStyle
    source: str
    categories: CategoricalPalette | None = None
    counts: dict | None = None
    note: str = ""

    def to_dict(self) -> dict[str, Any]:
        d: dict[str, Any] = {"source": self.source, "range": None if self.style.range is None
                             else [float(v) for v in self.style.range]}
        if self.categories is not None:
            d["labels"] = [{"value": float(c), "voxels": int((self.counts or {}).get(c, 0)),
                            "rgba": list(self.categories.rgba_of(c))}
                           for c in self.categories.codes]
        if self.note:
            d["note"] = self.note
        return d


def core_colours(volume: VoxelVolume, select, box, color: ColorStyle) -> CoreColours:
    """The colours of a core picture: a label image (few distinct whole numbers,
    :func:`box_values`) as classes, one qualitative colour per label (unless
    ``color.categorical`` is False or a range is given); otherwise, where the selection is the
    dtype's whole range (the default: nothing asked), a colour range over the values present
    in the box (a uint16 image holding 6237..40103 is coloured over 6237..40103, not
    0..65535); a selection, a solid colour, a palette or a range given are kept.

    >>> import numpy as np
    >>> v = VoxelVolume(np.repeat(np.array([0, 1, 2], np.uint8), 8).reshape(2, 3, 4))
    >>> c = core_colours(v, (0, 255), v.full_box(), ColorStyle())
    >>> c.source, c.style.range, c.categories.codes.tolist()
    ('labels', (0.0, 2.0), [0.0, 1.0, 2.0])
    >>> g = VoxelVolume((np.arange(24, dtype=np.uint16) * 100 + 6237).reshape(2, 3, 4))
    >>> core_colours(g, (0, 65535), g.full_box(), ColorStyle()).style.range
    (6237.0, 8537.0)
    """
    if color.solid is not None or color.palette is not None:
        return CoreColours(color, "style")
    lo, hi = (float(v) for v in select)
    everything = (lo, hi) == volume.value_limits()   # the dtype's whole range: nothing asked
    vals = None
    if everything or color.categorical or (  # the box read only where it can change colours
            color.categorical is None and color.range is None
            and detect_sample(volume, box).status == "label image"):
        vals = box_values(volume, box)
    note = ""
    cat = color.categorical
    if cat is None:
        cat = color.range is None and vals is not None and vals.labels
    if cat:
        if vals is not None and vals.labels and vals.codes is not None:
            pal = categorical_palette(vals.codes)
            counts = dict(zip(vals.codes.tolist(), (vals.counts if vals.counts is not None
                                                    else np.zeros(vals.codes.size)).tolist(),
                              strict=True))
            style = color.with_(range=(pal.lo, pal.hi), categorical=True)
            return CoreColours(style, "labels", pal, counts)
        note = (f"categorical: the box holds more than {LABEL_MAX} distinct values (or "
                "fractions): drawn with a colour bar")
    if color.range is not None:
        return CoreColours(color, "style", note=note)
    if vals is not None and everything:
        clo, chi = max(lo, vals.vmin), min(hi, vals.vmax)
        if clo < chi and (clo, chi) != (lo, hi):
            return CoreColours(color.with_(range=(clo, chi), categorical=False), "data",
                               note=note)
    return CoreColours(color, "selection", note=note)


def default_box(volume: VoxelVolume, side: int = DEFAULT_BOX_SIDE) -> Box:
    """The whole volume, or a centred box of ``side`` voxels per axis where it is larger.

    >>> from geoshade.compute.voxels.synthetic import synthetic_core
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


__all__ = ["AUTO_SELECT", "BINS", "DEFAULT_BOX_SIDE", "SAMPLE_MODES", "VALUES_BUDGET", "BoxValues",
           "CoreColours", "Histogram", "auto_select", "box_values", "core_colours", "default_box",
           "default_range", "detect_sample", "display_color_range", "histogram", "is_auto",
           "porosity", "porosity_line", "region", "resolve_select", "thresholds"]
