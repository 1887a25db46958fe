"""The sample in a tomogram: its footprint over the slices, told from the air around it.

A core is usually scanned in air: the voxels around the sample are as dark as its pores, so a
pore selection (``--select auto``: the dark phase) also takes the air.  Porosity is the pore
fraction *of the sample*, so the air must be left out of both counts.  A porous material that
fills the box (a foam, a fibre preform, a cube cut from inside a rock) has no air: its dark
voxels are all pores, and leaving any out would be wrong.

:func:`detect_sample` finds the sample without a shape model (a cylinder or any other prism
along z) and without random sampling, and fires only where there *is* a frame of air:

1. read up to :data:`SAMPLE_SLICES` z slices of the box, evenly spaced (first and last
   included; from a chunked store, from a few chunk layers only, see :func:`read_slices`);
2. a label image (at most :data:`LABEL_MAX` distinct values in those slices) is not searched:
   its phases are labels, not brightness, and no value can be told to be air;
3. Otsu's threshold (:func:`skimage.filters.threshold_otsu`) of their values splits the dark
   phase (air and pores) from the bright one (the solid);
4. the frame test (:func:`measure_frame`): the pixels bright in any slice, holes (pores enclosed
   by solid) filled, the largest connected part kept: a first footprint.  There is air only
   where (a) at least :data:`AIR_MIN` of the slice lies outside it, (b) at least
   :data:`RING_AIR` of the slices' border ring (:data:`RING_SHARE` of the side wide) lies
   outside it, the frame a sample in air leaves around itself, and (c) it is convex (its area
   at least :data:`CONVEX` of its convex hull's), as a cylinder or a prism is.  A porous
   material that fills the box fails (b) or (c): its solid reaches the border in every part of
   the ring, or the union of its fibres is ragged.  The same test with the phases swapped
   finds a *bright* frame (a sample in a bright holder, a reconstruction filled outside its
   circle with a bright value).  What was measured is kept either way
   (:attr:`Sample.measured`) and said (:meth:`Sample.text`);
5. the slices holding the sample: those whose footprint is at least half as solid as the most
   solid slice read, the two ends found by bisection (a sample that ends inside the volume,
   with air above and below it); the footprint is then made again from those slices: their
   union, less up to :data:`RIM_LAYERS` layers of its edge bright in at most half of them (the
   partial-volume rim at the sample's surface), with the pixels whose centres lie in the
   convex hull of what is left (pores open to the sample's surface are sample: a sample in a
   frame is convex);
6. a footprint covering more than :data:`NO_AIR` of the slices, over every slice, leaves no
   air around the sample: every voxel is sample.

The sample is a prism along z: every slice of ``[z0, z1)`` uses the same x-y footprint.
:class:`SampleRoi` evaluates it on any block (z-slabs, dask chunks, bricks), like the ROIs of
:mod:`geoshade.compute.voxels.roi`.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np

from geoshade.compute.voxels.selection import resolve_data_box
from geoshade.errors import InputError, MissingExtraError, require

#: z slices :func:`detect_sample` reads
SAMPLE_SLICES = 16
#: values of each slice used for the threshold (a regular subsample)
SAMPLE_VALUES = 1 << 18
#: at most this many distinct values: a label image (segmented), not a grey-scale one
LABEL_MAX = 16
#: a footprint covering more than this fraction of the slices leaves no air around the sample
NO_AIR = 0.97
#: largest slice (voxels, y × x of the box) the detection reads; beyond it, and without scipy,
#: the detection is skipped and says so (every voxel counts): never a crawl through a huge slice
SLICE_BUDGET = 1 << 26
#: smallest slice (voxels) and fewest slices in which a sample can be told from air: a toy
#: volume (a gradient of 4³ values) is not searched, every voxel counts (said in the notes)
SLICE_MIN, SLICES_MIN = 8 * 8, 2
#: warn when more than this fraction of the selected voxels lies outside the sample
OUTSIDE_WARN = 0.2
#: the border ring of a slice measured for air: this share of the shorter side wide (>= 1 px)
RING_SHARE = 0.04
#: at least this share of the border ring must lie outside the footprint: a frame of air
RING_AIR = 0.5
#: at least this share of the slice must lie outside the footprint (less is no air)
AIR_MIN = 0.01
#: the footprint's area over its convex hull's: a sample in air is a convex prism or cylinder
CONVEX = 0.95
#: a sample is at least this share of the slice (a speck in a frame is no sample)
SAMPLE_MIN = 0.05
#: a bright frame is a fill: at least this share of its voxels hold one value
FILL_MIN = 0.9


class SampleWarning(UserWarning):
    """Much of a selection lies outside the sample (air): one line saying how much."""


def _pct(f: float) -> str:
    return f"{100 * f:.1f} %"


@dataclass(frozen=True, eq=False)
class SampleRoi:
    """The voxels inside a sample's footprint, a prism along z (see the module).

    footprint: (ny, nx) bool   the footprint over the x-y region of the box it was found in
    y0, x0:    int             where that region starts in the volume (voxels)
    threshold: float           Otsu's threshold between air and solid

    Examples
    --------
    >>> s = SampleRoi(np.array([[0, 1], [1, 1]], bool), 1, 1, 10.0)
    >>> s.inside(slice(0, 2), slice(0, 3), slice(0, 3)).astype(int)[0]
    array([[0, 0, 0],
           [0, 0, 1],
           [0, 1, 1]])
    """

    footprint: np.ndarray
    y0: int = 0
    x0: int = 0
    threshold: float = 0.0
    z0: int | None = None  # the slices holding the sample: z0 <= z < z1 (None: every slice)
    z1: int | None = None

    kind = "sample"

    @property
    def fraction(self) -> float:
        """The footprint's share of the slices of the region it was found in."""
        return float(self.footprint.mean()) if self.footprint.size else 0.0

    def inside(self, zs: slice, ys: slice, xs: slice) -> np.ndarray:
        """Bool ``(1, ny, nx)`` (broadcasts over z): the voxels of the block inside."""
        ny, nx = ys.stop - ys.start, xs.stop - xs.start
        out = np.zeros((ny, nx), bool)
        fy, fx = self.footprint.shape
        a0, a1 = max(ys.start, self.y0), min(ys.stop, self.y0 + fy)
        b0, b1 = max(xs.start, self.x0), min(xs.stop, self.x0 + fx)
        if a0 < a1 and b0 < b1:
            out[a0 - ys.start:a1 - ys.start, b0 - xs.start:b1 - xs.start] = \
                self.footprint[a0 - self.y0:a1 - self.y0, b0 - self.x0:b1 - self.x0]
        if self.z0 is None or (zs.start >= self.z0 and zs.stop <= self.z1):
            return out[None]
        z = np.arange(zs.start, zs.stop)
        return out[None] & ((z >= self.z0) & (z < self.z1))[:, None, None]

    def contains(self, x, y, z) -> np.ndarray:
        """Whether voxels ``(x, y, z)`` (volume indices, arrays) are inside (the picker's test,
        as :meth:`inside` for blocks).

        >>> s = SampleRoi(np.array([[0, 1], [1, 1]], bool), 1, 1, 10.0, z0=1, z1=3)
        >>> s.contains(np.array([2, 1, 2]), np.array([1, 1, 2]), np.array([1, 1, 3])).tolist()
        [True, False, False]
        """
        x, y, z = (np.asarray(v, np.int64) for v in (x, y, z))
        fy, fx = self.footprint.shape
        iy, ix = y - self.y0, x - self.x0
        ok = (iy >= 0) & (iy < fy) & (ix >= 0) & (ix < fx)
        out = np.zeros(ok.shape, bool)
        out[ok] = self.footprint[iy[ok], ix[ok]]
        if self.z0 is not None:
            out &= (z >= self.z0) & (z < self.z1)
        return out

    def text(self) -> str:
        zr = "" if self.z0 is None else f", slices z {self.z0}..{self.z1 - 1}"
        return f"the detected sample ({_pct(self.fraction)} of the slices{zr})"

    def to_dict(self) -> dict[str, Any]:
        return {"kind": "sample", "fraction": self.fraction, "threshold": self.threshold,
                "z": None if self.z0 is None else [self.z0, self.z1], "text": self.text()}


@dataclass(frozen=True)
class FrameMeasure:
    """What :func:`measure_frame` measured of a footprint (the sample's phase in any slice read,
    holes filled, its largest part) against the air around it.

    frame:     ``"dark"`` (air around a bright sample) or ``"bright"`` (a bright frame)
    footprint: the footprint's share of the slice
    ring_air:  the share of the slices' border ring outside the footprint
    convexity: the footprint's area over its convex hull's (1.0: convex)
    ring:      the ring's width (pixels)
    fill:      a bright frame: the share of its voxels holding its most common value (a
               reconstruction's fill); None for air
    """

    frame: str
    footprint: float
    ring_air: float
    convexity: float
    ring: int
    fill: float | None = None

    @property
    def air(self) -> float:
        """The share of the slice outside the footprint."""
        return 1.0 - self.footprint

    def is_frame(self) -> bool:
        """A frame around a sample: enough air, along the border, around a convex footprint
        (see the module)."""
        return not self._failed()

    def _failed(self) -> list[str]:
        what = "air" if self.frame == "dark" else "bright frame"
        out = []
        if self.footprint < SAMPLE_MIN:
            out.append(f"sample {_pct(self.footprint)} of the slices (needs {SAMPLE_MIN:.0%})")
        if self.air < AIR_MIN:
            out.append(f"solid fills {_pct(self.footprint)} of the slices")
        if self.ring_air < RING_AIR:
            out.append(f"border ring {_pct(self.ring_air)} {what} (a frame needs "
                       f"{RING_AIR:.0%})")
        if self.convexity < CONVEX:
            out.append(f"solid {_pct(self.convexity)} convex (a sample needs {CONVEX:.0%})")
        if self.frame == "bright" and (self.fill or 0.0) < FILL_MIN:
            out.append(f"frame {_pct(self.fill or 0.0)} one value (a fill needs "
                       f"{FILL_MIN:.0%})")
        return out

    def why_not(self) -> str:
        """Why this is no frame, in words ('' when it is one): every test it fails.

        >>> FrameMeasure("dark", 0.62, 0.493, 0.894, 4).why_not()
        'border ring 49.3 % air (a frame needs 50%), solid 89.4 % convex (a sample needs 95%)'
        """
        return ", ".join(self._failed())

    def to_dict(self) -> dict[str, Any]:
        return {"frame": self.frame, "footprint": self.footprint, "air": self.air,
                "ring_air": self.ring_air, "convexity": self.convexity, "ring": self.ring,
                "fill": self.fill,
                "limits": {"sample": SAMPLE_MIN, "air": AIR_MIN, "ring_air": RING_AIR,
                           "convexity": CONVEX, "fill": FILL_MIN}}


@dataclass
class Sample:
    """What :func:`detect_sample` found.

    roi:       SampleRoi | None  the footprint (None: every voxel is sample)
    status:    str               ``"in air"`` (a footprint with a frame around it: air, or a
                                 bright frame, see ``frame``), ``"no air"`` (the sample fills
                                 the slices), ``"label image"`` (not searched), ``"skipped"``
                                 or ``"roi"`` (the user's ROI is the sample)
    threshold: float | None      Otsu's threshold between air and solid
    fraction:  float             the footprint's share of the slices (1.0 without air)
    measured:  FrameMeasure | None  the frame test's numbers (see :func:`measure_frame`)
    """

    roi: SampleRoi | None
    status: str
    threshold: float | None = None
    fraction: float = 1.0
    z: tuple[int, int] | None = None  # the slices holding the sample, [z0, z1)
    why: str = ""  # status "skipped": why the detection did not run
    measured: FrameMeasure | None = None

    @property
    def frame(self) -> str | None:
        """``"dark"`` (air) or ``"bright"``: what surrounds a sample found; None otherwise."""
        return self.measured.frame if self.status == "in air" and self.measured else None

    def text(self) -> str:
        """What is counted as the sample, in words, with what was measured.

        >>> Sample(None, "no air").text()
        'no air around the sample: every voxel is sample'
        >>> Sample(None, "no air", measured=FrameMeasure("dark", 0.62, 0.39, 0.98, 4)).text()
        'no air around the sample: every voxel is sample; border ring 39.0 % air (a frame \
needs 50%)'
        """
        m = self.measured
        if self.status == "in air":
            zr = "" if self.z is None else f", z {self.z[0]}..{self.z[1] - 1}"
            what = "the bright frame" if self.frame == "bright" else "the air"
            ring = "" if m is None else f"; border ring {_pct(m.ring_air)} {what[4:]}"
            return (f"counted inside the detected sample ({_pct(self.fraction)} of the slices"
                    f"{zr}); {what} around it left out{ring}")
        if self.status == "label image":
            return "a label image: no air detected, every voxel of the box counts"
        if self.status == "roi":
            return "counted inside the region of interest"
        if self.status == "skipped":
            return (f"sample detection skipped ({self.why}): every voxel of the box counts; "
                    "give --roi if the sample sits in air")
        why = "" if m is None or not m.why_not() else f"; {m.why_not()}"
        return f"no air around the sample: every voxel is sample{why}"

    def to_dict(self) -> dict[str, Any]:
        return {"status": self.status, "threshold": self.threshold, "fraction": self.fraction,
                "z": None if self.z is None else list(self.z), "frame": self.frame,
                "measured": None if self.measured is None else self.measured.to_dict(),
                "text": self.text()}


#: chunk layers (along z) read from a chunked store (zarr, dask) to find the sample
SAMPLE_LAYERS = 4


def _z_chunk(data) -> int:
    """The z size of a chunked array's chunks (zarr, dask), 1 for numpy and memmaps."""
    chunks = getattr(data, "chunks", None)
    if isinstance(chunks, tuple) and chunks:
        c = chunks[0]
        if isinstance(c, tuple):  # dask: the sizes of the chunks along z
            c = max(c) if c else 1
        if isinstance(c, int | np.integer) and c > 1:
            return int(c)
    return 1


def _read(data, zs: slice, ys: slice, xs: slice) -> np.ndarray:
    part = data[zs, ys, xs]
    if hasattr(part, "compute"):
        part = part.compute()
    return np.asarray(part)


def _spread(a: int, b: int, n: int) -> np.ndarray:
    """Up to ``n`` integers evenly spread over ``[a, b]`` (both ends included)."""
    return np.unique(np.linspace(a, b, max(1, min(int(n), b - a + 1))).round().astype(int))


class _SliceReader:
    """One z slice of a box at a time; a chunked store's chunk layer is read once and kept."""

    def __init__(self, data, box):
        self.data, self.box, self.cz = data, box, _z_chunk(data)
        self.layer: tuple[int, int, np.ndarray] | None = None

    def __call__(self, z: int) -> np.ndarray:
        zb, ys, xs = self.box.slices()
        if self.cz <= 1:
            return _read(self.data, slice(z, z + 1), ys, xs)[0]
        if self.layer is None or not self.layer[0] <= z < self.layer[1]:
            k = z // self.cz
            z0, z1 = max(zb.start, k * self.cz), min(zb.stop, (k + 1) * self.cz)
            self.layer = (z0, z1, _read(self.data, slice(z0, z1), ys, xs))
        return self.layer[2][z - self.layer[0]]


def slice_positions(data, box, n_slices: int = SAMPLE_SLICES) -> np.ndarray:
    """The z slices (volume indices) :func:`read_slices` reads, ascending."""
    zb, _, _ = box.slices()
    cz = _z_chunk(data)
    if cz <= 1:
        return _spread(zb.start, zb.stop - 1, n_slices)
    layers = _spread(zb.start // cz, (zb.stop - 1) // cz, SAMPLE_LAYERS)
    per = max(1, -(-int(n_slices) // len(layers)))
    return np.concatenate([_spread(max(zb.start, int(k) * cz),
                                   min(zb.stop, (int(k) + 1) * cz) - 1, per) for k in layers])


def read_slices(data, box, n_slices: int = SAMPLE_SLICES, progress=None) -> list[np.ndarray]:
    """About ``n_slices`` z slices of ``box`` (a :class:`~geoshade.models.Box`), evenly spaced,
    first and last included, each ``(ny, nx)`` (at :func:`slice_positions`).

    A chunked store (zarr, dask) decompresses a whole chunk to give one slice, so there the
    slices come from at most :data:`SAMPLE_LAYERS` chunk layers along z (evenly spaced), each
    read once: the cost stays a few chunk layers however deep the volume is.
    """
    return _read_at(_SliceReader(data, box), slice_positions(data, box, n_slices), progress)


def _read_at(read, zs, progress=None) -> list[np.ndarray]:
    """The slices ``zs`` through ``read``, with progress per slice."""
    out = []
    for i, z in enumerate(zs):
        out.append(read(int(z)))
        if progress is not None:
            progress(i + 1, len(zs))
    return out


def _z_extent(read, zs, slices, foot, phase) -> tuple[int, int]:
    """``[z0, z1)``: the slices holding the sample, those whose footprint is at least half as
    much of the sample's phase (``phase(slice)``: bool) as the most solid slice read; the ends
    found by bisection between the slices read (a few more slices)."""
    def solid(s) -> float:
        return float(np.count_nonzero(phase(s)[foot])) / max(1, int(foot.sum()))

    fz = [solid(s) for s in slices]
    level = 0.5 * max(fz)

    def holds(z: int) -> bool:
        return solid(read(z)) >= level

    idx = [i for i, f in enumerate(fz) if f >= level]
    i0, i1 = idx[0], idx[-1]
    a, b = (int(zs[i0 - 1]), int(zs[i0])) if i0 > 0 else (None, int(zs[0]))
    if a is not None:  # a: not, b: holds
        while b - a > 1:
            m = (a + b) // 2
            a, b = (a, m) if holds(m) else (m, b)
    z0 = b
    a, b = (int(zs[i1]), int(zs[i1 + 1])) if i1 + 1 < len(zs) else (int(zs[-1]), None)
    if b is not None:  # a: holds, b: not
        while b - a > 1:
            m = (a + b) // 2
            a, b = (m, b) if holds(m) else (a, m)
    return z0, a + 1


def distinct_values(values: np.ndarray, limit: int = LABEL_MAX) -> np.ndarray | None:
    """The distinct finite values, or None where there are more than ``limit``.

    >>> distinct_values(np.array([0, 255, 0, 255], np.uint8)).tolist()
    [0, 255]
    >>> distinct_values(np.arange(40), limit=16) is None
    True
    """
    v = values[np.isfinite(values)] if values.dtype.kind == "f" else values
    if v.size > 4096 and np.unique(v[:4096]).size > limit:  # grey-scale: told at once
        return None
    u = np.unique(v)
    return None if u.size > limit else u


def footprint(slices: list[np.ndarray], threshold: float, ndi, quorum: float = 0.0
              ) -> np.ndarray:
    """The sample's footprint ``(ny, nx) bool``: the pixels above ``threshold`` in more than
    ``quorum`` of the slices (0: any; 0.5: at least half, which leaves out the partial-volume
    rim and the pores of a few slices), holes filled, its largest connected part."""
    count = np.zeros(slices[0].shape, np.int32)
    for s in slices:
        with np.errstate(invalid="ignore"):
            count += s > threshold
    foot = ndi.binary_fill_holes(count > quorum * len(slices) if quorum else count > 0)
    labels, n = ndi.label(foot)
    if n == 0:
        return foot
    sizes = np.bincount(labels.ravel())[1:]
    return labels == (int(np.argmax(sizes)) + 1)


def subsample(slices: list[np.ndarray]) -> np.ndarray:
    """A regular subsample of the slices' finite values (at most :data:`SAMPLE_VALUES` a
    slice): what the label test and Otsu's threshold look at."""
    ny, nx = slices[0].shape
    step = max(1, math.isqrt(max(1, ny * nx // SAMPLE_VALUES)))
    values = np.concatenate([s[::step, ::step].ravel() for s in slices])
    return values[np.isfinite(values)] if values.dtype.kind == "f" else values


def air_threshold(values: np.ndarray, name: str = "volume") -> float:
    """Otsu's threshold of :func:`subsample` values."""
    filters = require("skimage.filters", "threshold", "detecting the sample (Otsu)")
    if values.size == 0 or values.min() == values.max():
        raise InputError(f"{name}: sample: the slices hold one value only; no sample to find")
    return float(filters.threshold_otsu(values))


def border_ring(shape: tuple[int, int]) -> np.ndarray:
    """``(ny, nx) bool``: the border ring of a slice, :data:`RING_SHARE` of its shorter side
    wide (at least one pixel).

    >>> border_ring((5, 6)).astype(int)[:2].tolist()
    [[1, 1, 1, 1, 1, 1], [1, 0, 0, 0, 0, 1]]
    """
    ny, nx = shape
    w = max(1, round(RING_SHARE * min(ny, nx)))
    ring = np.ones((ny, nx), bool)
    ring[w:ny - w, w:nx - w] = False
    return ring


def _convexity(foot: np.ndarray) -> float:
    """The footprint's area over its convex hull's (scikit-image's ``convex_hull_image``)."""
    morphology = require("skimage.morphology", "threshold", "detecting the sample")
    n = int(foot.sum())
    if n == 0:
        return 0.0
    hull = int(morphology.convex_hull_image(foot).sum())
    return min(1.0, n / hull) if hull else 1.0


def measure_frame(masks: list[np.ndarray], ndi, frame: str = "dark", values=None
                  ) -> tuple[np.ndarray, FrameMeasure]:
    """The first footprint of ``masks`` (the sample's phase per slice: ``s > t`` for a dark
    frame, ``s <= t`` for a bright one) and the frame test's numbers (see the module, step 4);
    ``values``: the slices, to measure a bright frame's fill.

    >>> yy, xx = np.mgrid[0:40, 0:40] + 0.5
    >>> disc = (xx - 20) ** 2 + (yy - 20) ** 2 <= 15 ** 2
    >>> import scipy.ndimage as ndi
    >>> foot, m = measure_frame([disc, disc], ndi)
    >>> m.is_frame(), round(m.ring_air, 2), m.convexity > 0.95
    (True, 1.0, True)
    """
    union = np.zeros(masks[0].shape, bool)
    for m in masks:
        union |= m
    foot = ndi.binary_fill_holes(union)
    labels, n = ndi.label(foot)
    if n > 1:
        sizes = np.bincount(labels.ravel())[1:]
        foot = labels == (int(np.argmax(sizes)) + 1)
    ring = border_ring(foot.shape)
    w = max(1, round(RING_SHARE * min(foot.shape)))
    fill = None
    if frame == "bright" and values is not None and not foot.all():
        out = np.concatenate([v[~foot].ravel() for v in values])
        _, counts = np.unique(out, return_counts=True)
        fill = float(counts.max() / out.size)
    return foot, FrameMeasure(frame, float(foot.mean()), float(1.0 - foot[ring].mean()),
                              _convexity(foot), int(w), fill)


def detect_sample(data, box=None, name: str = "volume", n_slices: int = SAMPLE_SLICES,
                  progress=None) -> Sample:
    """The sample's footprint in the box, told from the air around it (see the module).

    Parameters
    ----------
    data : VoxelVolume or (nz, ny, nx) array
        Numpy, memmap, zarr or dask (only the chosen slices are read).
    box : Box, [x0, y0, z0, nx, ny, nz] or None
    name : str
        The volume's name, for messages.
    n_slices : int
        Slices to read.

    Returns
    -------
    Sample
        ``status`` ``"in air"`` with a :class:`SampleRoi`, or ``"no air"`` / ``"label image"``
        with none (every voxel counts); ``measured``: the frame test's numbers.

    Examples
    --------
    >>> z, y, x = np.mgrid[0:4, 0:40, 0:40] + 0.5
    >>> solid = (x - 20) ** 2 + (y - 17) ** 2 <= 12 ** 2
    >>> a = (np.where(solid, 180, 10) + (x * y) % 30).astype(np.uint8)   # grey values
    >>> a[:, 17, 20] = 10  # a pore inside the sample
    >>> s = detect_sample(a)
    >>> s.status, int(s.roi.footprint.sum()) == int(solid[0].sum()), s.frame
    ('in air', True, 'dark')
    >>> detect_sample(a[:, 10:24, 14:26]).status   # cut from inside it: no air
    'no air'
    """

    arr, box, _ = resolve_data_box(data, box)
    area = int(box.size[0]) * int(box.size[1])
    if area > SLICE_BUDGET:
        return Sample(None, "skipped", why=f"slices of {area:,} voxels exceed its read budget "
                                           f"of {SLICE_BUDGET:,}")
    try:
        ndi = require("scipy.ndimage", "threshold", "detecting the sample")
    except MissingExtraError as err:
        return Sample(None, "skipped", why=str(err))
    read = _SliceReader(arr, box)
    zs = slice_positions(arr, box, n_slices)
    slices = _read_at(read, zs, progress)
    values = subsample(slices)
    if distinct_values(values) is not None:
        return Sample(None, "label image")
    if area < SLICE_MIN or int(box.size[2]) < SLICES_MIN:
        return Sample(None, "skipped", why=f"a box of {box.size[0]}×{box.size[1]}×{box.size[2]} "
                                           "voxels is too small to tell a sample from air")
    t = air_threshold(values, name)
    with np.errstate(invalid="ignore"):
        foot, measured = measure_frame([s > t for s in slices], ndi, "dark")
        if not measured.is_frame():   # no air: a bright frame around a darker sample?
            bfoot, bright = measure_frame([s <= t for s in slices], ndi, "bright", slices)
            if bright.is_frame():
                foot, measured = bfoot, bright
    if not measured.is_frame():
        return Sample(None, "no air", t, 1.0, measured=measured)

    def phase(s: np.ndarray) -> np.ndarray:   # the sample's phase (the frame's other side)
        with np.errstate(invalid="ignore"):
            return s > t if measured.frame == "dark" else s <= t

    zb, ys, xs = box.slices()
    z0, z1 = _z_extent(read, zs, slices, foot, phase)
    held = [phase(s) for s, z in zip(slices, zs, strict=True) if z0 <= z < z1] or \
        [phase(s) for s in slices]
    whole, _ = measure_frame(held, ndi)
    if whole.mean() > NO_AIR:  # the union fills the slices: no air
        foot = np.ones_like(whole)
    else:  # the union without its partial-volume rim, pores open to the surface kept
        foot = _peeled(whole, held, ndi, RIM_LAYERS if measured.frame == "dark" else 0)
    frac = float(foot.mean())
    if frac == 1.0 and (z0, z1) == (zb.start, zb.stop):
        return Sample(None, "no air", t, 1.0, measured=measured)
    whole_z = (z0, z1) == (zb.start, zb.stop)
    roi = SampleRoi(foot, ys.start, xs.start, t, None if whole_z else z0,
                    None if whole_z else z1)
    return Sample(roi, "in air", t, frac, None if whole_z else (z0, z1), measured=measured)


#: layers of the footprint's edge peeled where they are of the sample's phase in fewer than
#: half of the slices holding it (the partial-volume rim: a voxel half sample, half air)
RIM_LAYERS = 2


def _peeled(whole: np.ndarray, masks: list[np.ndarray], ndi, layers: int = RIM_LAYERS
            ) -> np.ndarray:
    """``whole`` (the union footprint) less up to ``layers`` layers of its edge that are of the
    sample's phase in at most half of ``masks`` (the partial-volume rim against air; a bright
    fill has none), then the pixels whose centres lie in the convex hull of what is left (a
    sample in a frame is convex: pores open to its surface are sample)."""
    morphology = require("skimage.morphology", "threshold", "detecting the sample")
    count = np.zeros(whole.shape, np.int32)
    for m in masks:
        count += m
    weak = count <= 0.5 * len(masks)
    foot = whole.copy()
    for _ in range(layers):
        edge = foot & ~ndi.binary_erosion(foot, border_value=1)
        cut = edge & weak
        if not cut.any():
            break
        foot &= ~cut
    labels, n = ndi.label(foot)
    if n > 1:
        foot = labels == (int(np.argmax(np.bincount(labels.ravel())[1:])) + 1)
    if not foot.any():
        return whole
    return foot | morphology.convex_hull_image(foot, offset_coordinates=False)


def warn_outside(outside: int, selected: int, name: str = "volume") -> str | None:
    """The one-line warning when more than :data:`OUTSIDE_WARN` of the ``selected +
    outside`` voxels lie outside the sample (issued as a :class:`SampleWarning`), else None.

    >>> import warnings
    >>> with warnings.catch_warnings(record=True):
    ...     print(warn_outside(82, 18, "snow"))
    snow: 82.0 % of the selected voxels lie outside the detected sample (air); they are not \
counted (--sample none counts them)
    """
    every = outside + selected
    if every == 0 or outside / every <= OUTSIDE_WARN:
        return None
    text = (f"{name}: {_pct(outside / every)} of the selected voxels lie outside the detected "
            "sample (air); they are not counted (--sample none counts them)")
    warnings.warn(text, SampleWarning, stacklevel=3)
    return text


__all__ = ["AIR_MIN", "CONVEX", "FILL_MIN", "LABEL_MAX", "NO_AIR", "OUTSIDE_WARN", "RIM_LAYERS",
           "RING_AIR", "RING_SHARE", "SAMPLE_LAYERS", "SAMPLE_MIN", "SAMPLE_SLICES",
           "FrameMeasure", "Sample", "SampleRoi", "SampleWarning", "air_threshold", "border_ring",
           "detect_sample", "distinct_values", "footprint", "measure_frame", "read_slices",
           "slice_positions", "subsample", "warn_outside"]
