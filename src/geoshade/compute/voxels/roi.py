"""Regions of interest beyond boxes: a cylinder along z and a mask volume.

A micro-CT core is usually a cylinder scanned in air; its porosity must count only the voxels
inside the sample.  An ROI here is a function of voxel coordinates evaluated on any block of
the volume (:meth:`Cylinder.inside`, :meth:`MaskRoi.inside` take the block's z, y, x slices
in the whole volume's voxel indices), so z-slabs, dask chunks and render bricks each evaluate
the part they read and no full-size mask is ever made.

Conventions (voxel index space, x fastest): voxel ``(i, j, k)`` covers ``[i, i + 1) ×
[j, j + 1) × [k, k + 1)`` and its centre is ``(i + 0.5, j + 0.5, k + 0.5)``.  A cylinder
``(cx, cy, r)`` keeps the voxels whose centre satisfies ``(x - cx)² + (y - cy)² <= r²``, in
every z slice.  A mask volume keeps the voxels where it is nonzero.

:func:`fit_cylinder` finds the cylinder of a core scanned in air (``--roi cylinder``); see its
docstring for the method.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from geoshade.compute.voxels import sample as smp
from geoshade.compute.voxels.sample import SampleRoi, detect_sample
from geoshade.compute.voxels.selection import resolve_data_box
from geoshade.errors import InputError, require

#: z slices :func:`fit_cylinder` reads (evenly spaced over the volume)
FIT_SLICES = 8
#: a footprint covering more of the slices than this leaves no air to fit a cylinder to
FILLED = 0.97


def _fmt(v: float) -> str:
    return f"{v:.6g}"


@dataclass(frozen=True)
class Cylinder:
    """A cylinder along z: axis at ``(cx, cy)``, radius ``r``, in voxels (see the module).

    Examples
    --------
    >>> c = Cylinder(2.0, 2.0, 1.5)
    >>> c.inside(slice(0, 1), slice(0, 4), slice(0, 4)).astype(int)[0]
    array([[0, 0, 0, 0],
           [0, 1, 1, 0],
           [0, 1, 1, 0],
           [0, 0, 0, 0]])
    """

    cx: float
    cy: float
    r: float
    fitted: bool = False
    #: what a fit found that changes the result's meaning (no air, cut by the volume's edge)
    note: str = field(default="", repr=False, compare=False)

    kind = "cylinder"

    def inside(self, zs: slice, ys: slice, xs: slice) -> np.ndarray:
        """Bool ``(1, ny, nx)`` (broadcasts over z): the voxels of the block inside."""
        x = np.arange(xs.start, xs.stop, dtype=np.float64) + 0.5 - self.cx
        y = np.arange(ys.start, ys.stop, dtype=np.float64) + 0.5 - self.cy
        return ((y * y)[:, None] + (x * x)[None, :] <= self.r * self.r)[None]

    def contains(self, x, y, z) -> np.ndarray:
        """Bool per voxel ``(x[i], y[i], z[i])`` (integer indices): inside the cylinder."""
        dx = np.asarray(x, np.float64) + 0.5 - self.cx
        dy = np.asarray(y, np.float64) + 0.5 - self.cy
        return dx * dx + dy * dy <= self.r * self.r

    def check(self, shape_xyz, name: str = "roi") -> None:
        """Raise unless the cylinder's circle overlaps the volume's x-y extent."""
        nx, ny, _ = (int(n) for n in shape_xyz)
        if not (math.isfinite(self.cx) and math.isfinite(self.cy) and math.isfinite(self.r)):
            raise InputError(f"{name}: cylinder CX,CY,R must be finite numbers, got {self.text()}")
        if self.r <= 0:
            raise InputError(f"{name}: cylinder radius must be > 0 voxels, got {_fmt(self.r)}")
        # nearest point of the x-y rectangle [0, nx] × [0, ny] to the axis
        qx, qy = min(max(self.cx, 0.5), nx - 0.5), min(max(self.cy, 0.5), ny - 0.5)
        if (qx - self.cx) ** 2 + (qy - self.cy) ** 2 > self.r**2:
            raise InputError(f"{name}: cylinder {self.text()} holds no voxel centre of the "
                             f"{nx}×{ny} (x×y) slices")

    def text(self) -> str:
        """``cylinder:CX,CY,R`` (what ``--roi`` takes)."""
        return f"cylinder:{_fmt(self.cx)},{_fmt(self.cy)},{_fmt(self.r)}"

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready description."""
        return {"kind": "cylinder", "cx": float(self.cx), "cy": float(self.cy),
                "r": float(self.r), "fitted": bool(self.fitted), "text": self.text(),
                "note": self.note}


@dataclass(frozen=True, eq=False)
class MaskRoi:
    """The voxels where a mask volume of the same shape is nonzero.

    data: (nz, ny, nx) any dtype; numpy, memmap, zarr or dask (read block by block)
    name: where it came from, for messages

    Examples
    --------
    >>> m = MaskRoi(np.eye(3, dtype=np.uint8)[None], "eye")
    >>> m.inside(slice(0, 1), slice(0, 2), slice(0, 3)).astype(int)
    array([[[1, 0, 0],
            [0, 1, 0]]])
    """

    data: Any
    name: str = "mask"

    kind = "mask"

    def inside(self, zs: slice, ys: slice, xs: slice) -> np.ndarray:
        """Bool ``(nz, ny, nx)``: the mask's block, nonzero = inside."""
        part = self.data[zs, ys, xs]
        if hasattr(part, "compute"):
            part = part.compute()
        return np.asarray(part) != 0

    def check(self, shape_xyz, name: str = "mask") -> None:
        """Raise unless the mask has the volume's shape."""
        shape = tuple(int(n) for n in getattr(self.data, "shape", ()))
        want = tuple(int(n) for n in shape_xyz)[::-1]
        if shape != want:
            got = "×".join(map(str, shape[::-1])) if len(shape) == 3 else str(shape)
            raise InputError(f"{self.name}: {name}: a mask of {got} voxels (x×y×z) does not "
                             f"match the volume's {'×'.join(map(str, want[::-1]))}")

    def text(self) -> str:
        return f"mask:{self.name}"

    def to_dict(self) -> dict[str, Any]:
        return {"kind": "mask", "source": self.name, "text": self.text()}


#: what ``roi`` may be once resolved
Roi = Cylinder | MaskRoi

_NUM = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
_CYL = re.compile(rf"cylinder:\s*({_NUM})\s*,\s*({_NUM})\s*,\s*({_NUM})")


def parse_roi(value) -> Cylinder | str | None:
    """``--roi`` text -> a :class:`Cylinder`, ``"cylinder"`` (fit it to the sample),
    ``"sample"`` (the sample detected in air, :mod:`geoshade.compute.voxels.sample`) or None.

    Accepts ``cylinder`` (auto), ``cylinder:CX,CY,R`` (voxels), ``sample``, a
    :class:`Cylinder`, a :class:`MaskRoi`, a
    :class:`~geoshade.compute.voxels.sample.SampleRoi`, or a dict ``{"cx":, "cy":, "r":}``.

    Examples
    --------
    >>> parse_roi("cylinder:10,12.5,8")
    Cylinder(cx=10.0, cy=12.5, r=8.0, fitted=False)
    >>> parse_roi("cylinder")
    'cylinder'
    >>> parse_roi("sphere:1,2,3")
    Traceback (most recent call last):
    ...
    geoshade.errors.InputError: roi: expected 'cylinder' (fitted to the sample), \
'cylinder:CX,CY,R' (voxels) or 'sample' (detected in air), got 'sphere:1,2,3'
    """

    if value is None or isinstance(value, Cylinder | MaskRoi | SampleRoi):
        return value
    if isinstance(value, dict):
        try:
            return Cylinder(float(value["cx"]), float(value["cy"]), float(value["r"]))
        except (KeyError, TypeError, ValueError):
            raise InputError(f"roi: a cylinder dict needs numbers cx, cy, r; got {value!r}"
                             ) from None
    text = str(value).strip()
    if text.lower() in ("cylinder", "cylinder:auto", "auto"):
        return "cylinder"
    if text.lower() == "sample":
        return "sample"
    m = _CYL.fullmatch(text)
    if m is None:
        raise InputError(f"roi: expected 'cylinder' (fitted to the sample), "
                         f"'cylinder:CX,CY,R' (voxels) or 'sample' (detected in air), got "
                         f"{text!r}")
    cx, cy, r = (float(g) for g in m.groups())
    if r <= 0:
        raise InputError(f"roi: cylinder radius must be > 0 voxels, got {m.group(3)}")
    return Cylinder(cx, cy, r)


def inside_count(roi: Roi | None, box_slices) -> np.ndarray | None:
    """Voxels inside ``roi`` in each z slice of a block, ``(nz,) int64`` (None: no ROI)."""
    if roi is None:
        return None
    zs, ys, xs = box_slices
    m = roi.inside(zs, ys, xs)
    n = np.count_nonzero(m, axis=(1, 2)).astype(np.int64)
    return np.broadcast_to(n, (zs.stop - zs.start,)).copy()


def outside_value(dtype, lo: float, hi: float) -> tuple[np.dtype, Any]:
    """A dtype and a value of it that the selection ``[lo, hi]`` never selects.

    Integers: the dtype's minimum (below ``lo``) or maximum (above ``hi``) where the selection
    leaves one free, else the next wider signed integer and a value just outside (float64 and
    NaN for 32-bit integers, exact for them); floats: NaN.

    Examples
    --------
    >>> outside_value("uint8", 10, 80)
    (dtype('uint8'), 0)
    >>> outside_value("uint8", 0, 255)
    (dtype('int16'), -1)
    """
    dt = np.dtype(dtype)
    if dt.kind == "f":
        return dt, dt.type(np.nan)
    info = np.iinfo(dt)
    if lo > info.min:
        return dt, int(info.min)
    if hi < info.max:
        return dt, int(info.max)
    wider = np.dtype({1: np.int16, 2: np.int32}.get(dt.itemsize, np.float64))
    if wider.kind == "f":
        return wider, np.nan
    return wider, int(info.min) - 1


class RoiMasked:
    """A read-only array view of a volume's data where voxels outside ``roi`` read as
    ``fill`` (a value the selection never takes, :func:`outside_value`).

    Only the blocks read are masked (``data[z0:z1, y0:y1, x0:x1]``), so selection maps built
    slab by slab or brick by brick evaluate the ROI on what they read.

    Examples
    --------
    >>> a = np.arange(16, dtype=np.uint8).reshape(1, 4, 4)
    >>> m = RoiMasked(a, Cylinder(2, 2, 1.0), *outside_value(a.dtype, 1, 20))
    >>> m[0:1, 0:4, 0:4][0]
    array([[ 0,  0,  0,  0],
           [ 0,  5,  6,  0],
           [ 0,  9, 10,  0],
           [ 0,  0,  0,  0]], dtype=uint8)
    """

    def __init__(self, data, roi: Roi, dtype, fill):
        self.data, self.roi = data, roi
        self.dtype, self.fill = np.dtype(dtype), fill
        self.shape = tuple(int(n) for n in data.shape)
        self.ndim = 3

    def __getitem__(self, key):
        if not (isinstance(key, tuple) and len(key) == 3
                and all(isinstance(k, slice) and k.step in (None, 1) for k in key)):
            raise TypeError("RoiMasked reads blocks: data[z0:z1, y0:y1, x0:x1]")
        zs, ys, xs = (slice(*k.indices(n)[:2]) for k, n in zip(key, self.shape, strict=True))
        part = self.data[zs, ys, xs]
        if hasattr(part, "compute"):
            part = part.compute()
        part = np.asarray(part)
        if part.dtype != self.dtype:
            part = part.astype(self.dtype)
        return np.where(self.roi.inside(zs, ys, xs), part, self.dtype.type(self.fill))


def _mask_block(block, roi, dtype, fill, block_info=None):
    loc = block_info[0]["array-location"]
    zs, ys, xs = (slice(a, b) for a, b in loc)
    return np.where(roi.inside(zs, ys, xs), np.asarray(block).astype(dtype, copy=False),
                    np.dtype(dtype).type(fill))


def masked_data(data, roi: Roi | None, lo: float, hi: float):
    """The volume's data with voxels outside ``roi`` set to a value ``[lo, hi]`` never selects.

    ``data`` itself when there is no ROI; for a dask array, a dask array (the ROI evaluated
    per chunk, from the chunk's location: give the whole volume's array); else a
    :class:`RoiMasked` view.

    Examples
    --------
    >>> a = np.full((2, 3, 3), 7, np.uint8)
    >>> int((np.asarray(masked_data(a, Cylinder(1.5, 1.5, 0.5), 0, 9)[0:2, 0:3, 0:3]) == 7).sum())
    2
    """
    if roi is None:
        return data
    dtype, fill = outside_value(data.dtype, lo, hi)
    if type(data).__module__.split(".")[0] == "dask":
        return data.map_blocks(_mask_block, roi, dtype, fill, dtype=dtype)
    return RoiMasked(data, roi, dtype, fill)


# --------------------------------------------------------------------------------------------
# fitting the cylinder of a core scanned in air
# --------------------------------------------------------------------------------------------
def fit_cylinder(data, n_slices: int = FIT_SLICES, name: str = "volume",
                 progress=None) -> Cylinder:
    """The cylinder of a core scanned in air, fitted to the sample's footprint.

    Method (deterministic, no random sampling):

    1. the sample's footprint as :func:`geoshade.compute.voxels.sample.detect_sample` finds it
       (``n_slices`` z slices evenly spaced, Otsu's threshold between air and solid, each
       slice's solid with holes filled, united, largest connected part);
    2. the axis is the footprint's centroid (voxel centres) and the radius that of a circle of
       the same area, ``sqrt(area / π)``; where the field of view cuts the sample (the
       footprint touches a side of the slices), a least-squares circle (Kåsa) through the
       footprint's edge pixels inside the slices instead.

    No air around the sample (a footprint over more than :data:`FILLED` of the slices: a cube
    cut from inside a sample) keeps the whole volume: the circle through the slices' corners,
    with a ``note`` saying so.  A fitted circle that reaches within a voxel of the slices' side
    also gets a ``note`` (the field of view may cut the sample; check the fit).

    Raises InputError when the values are all equal, the image is a label image (its phases
    cannot be told from air), or too little edge lies inside the slices.

    Parameters
    ----------
    data : (nz, ny, nx) array
        Numpy, memmap, zarr or dask (only the chosen slices are read).
    n_slices : int
        Slices to read.

    Returns
    -------
    Cylinder
        ``fitted=True``; ``note`` non-empty where the fit needs a look.

    Examples
    --------
    >>> z, y, x = np.mgrid[0:4, 0:40, 0:40] + 0.5
    >>> solid = (x - 20) ** 2 + (y - 17) ** 2 <= 12 ** 2
    >>> a = (np.where(solid, 180, 10) + (x * y) % 30).astype(np.uint8)
    >>> a[:, 17, 20] = 10   # a pore
    >>> c = fit_cylinder(a)
    >>> round(c.cx, 1), round(c.cy, 1), abs(c.r - 12) < 0.3, c.note
    (20.0, 17.0, True, '')
    >>> whole = fit_cylinder(a[:, 10:24, 14:26])   # cut from inside the sample: no air
    >>> whole.text(), whole.note.split(":")[0]
    ('cylinder:6,7,9.21954', 'no air around the sample')
    """
    ndi = require("scipy.ndimage", "threshold", "fitting a cylinder ROI")
    _, ny, nx = (int(n) for n in data.shape)
    _, box, _ = resolve_data_box(data, None)
    slices = smp.read_slices(data, box, n_slices, progress)
    values = smp.subsample(slices)
    distinct = smp.distinct_values(values)
    if distinct is not None and distinct.size < 2:
        raise InputError(f"{name}: roi: cannot fit a cylinder, the slices hold one value only; "
                         "give --roi cylinder:CX,CY,R")
    if distinct is not None:
        raise InputError(f"{name}: roi: cannot fit a cylinder to a label image (its phases are "
                         "labels, none can be told to be air); give --roi cylinder:CX,CY,R or "
                         "--mask")
    try:
        t = smp.air_threshold(values, name)
    except InputError:
        raise InputError(f"{name}: roi: cannot fit a cylinder, the slices hold one value only; "
                         "give --roi cylinder:CX,CY,R") from None
    foot = smp.footprint(slices, t, ndi)
    if not foot.any():
        raise InputError(f"{name}: roi: no sample found above Otsu's threshold {t:g}; give "
                         "--roi cylinder:CX,CY,R")
    if foot.mean() > FILLED:
        return Cylinder(nx / 2, ny / 2, math.hypot(nx / 2, ny / 2), fitted=True,
                        note=f"no air around the sample: it fills {100 * foot.mean():.1f} % "
                             "of the slices, so the whole volume is kept")
    clipped = foot[0].any() or foot[-1].any() or foot[:, 0].any() or foot[:, -1].any()
    if clipped:  # cut by the field of view: a circle through its edge inside the slices
        c = _fit_edge(foot, ndi, name)
    else:
        jj, ii = np.nonzero(foot)
        c = Cylinder(float(ii.mean() + 0.5), float(jj.mean() + 0.5),
                     math.sqrt(float(jj.size) / math.pi), fitted=True)
    if c.cx - c.r < 1 or c.cy - c.r < 1 or c.cx + c.r > nx - 1 or c.cy + c.r > ny - 1:
        c = Cylinder(c.cx, c.cy, c.r, fitted=True,
                     note=f"the fitted cylinder (radius {c.r:.1f}) touches the edge of the "
                          f"{nx}×{ny} slices: the field of view may cut the sample, or there "
                          "is little air; check it or give --roi cylinder:CX,CY,R")
    return c


def _fit_edge(foot: np.ndarray, ndi, name: str) -> Cylinder:
    """Least-squares circle (Kåsa) through the footprint's edge pixels that are not on the
    slice's border, for a sample the field of view cuts; the radius to the pixels' outer side
    (+0.5)."""
    edge = foot & ~ndi.binary_erosion(foot)
    edge[0, :] = edge[-1, :] = False
    edge[:, 0] = edge[:, -1] = False
    jj, ii = np.nonzero(edge)
    if jj.size < 8:
        raise InputError(f"{name}: roi: too little of the sample's edge lies inside the slices "
                         "to fit a cylinder; give --roi cylinder:CX,CY,R")
    x, y = ii + 0.5, jj + 0.5
    A = np.column_stack([x, y, np.ones_like(x)])
    (a, b, c), *_ = np.linalg.lstsq(A, x * x + y * y, rcond=None)
    cx, cy = a / 2, b / 2
    r = math.sqrt(max(c + cx * cx + cy * cy, 0.0)) + 0.5
    return Cylinder(float(cx), float(cy), float(r), fitted=True)


def resolve_roi(roi, data, mask=None, name: str = "volume", progress=None) -> Roi | None:
    """``roi`` (see :func:`parse_roi`) and/or ``mask`` (a :class:`MaskRoi` or array) checked
    against ``data`` and, for ``"cylinder"``, fitted (:func:`fit_cylinder`).

    Examples
    --------
    >>> resolve_roi("cylinder:2,2,1", np.zeros((1, 4, 4), np.uint8))
    Cylinder(cx=2.0, cy=2.0, r=1.0, fitted=False)
    """
    shape_xyz = tuple(int(n) for n in data.shape)[::-1]
    if mask is not None:
        if roi is not None:
            raise InputError("roi: give either a cylinder (--roi) or a mask (--mask), not both")
        m = mask if isinstance(mask, MaskRoi) else MaskRoi(getattr(mask, "data", mask),
                                                           getattr(mask, "name", "") or "mask")
        m.check(shape_xyz)
        return m
    r = parse_roi(roi)
    if r is None:
        return None
    if r == "cylinder":
        r = fit_cylinder(data, name=name, progress=progress)
    elif r == "sample":  # None where there is no air (or a label image): every voxel

        return detect_sample(data, None, name=name, progress=progress).roi
    assert not isinstance(r, str)
    if hasattr(r, "check"):
        r.check(shape_xyz)
    return r


__all__ = ["FIT_SLICES", "Cylinder", "MaskRoi", "Roi", "RoiMasked", "fit_cylinder",
           "inside_count", "masked_data", "outside_value", "parse_roi", "resolve_roi"]
