"""Voxel volumes (micro-CT digital rock) and boxes inside them."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from geoshade.errors import InputError
from geoshade.models import reprs
from geoshade.models.convert import convert

#: dtypes a volume may hold (absorption values as the scanner wrote them, or labels)
SUPPORTED_DTYPES = ("uint8", "uint16", "int8", "int16", "uint32", "int32", "float32", "float64")


@dataclass(frozen=True)
class Box:
    """An axis-aligned sub-volume, in voxels, in ``x, y, z`` order.

    offset: (3,) int  first voxel (x0, y0, z0)
    size:   (3,) int  number of voxels (nx, ny, nz), each >= 1
    """

    offset: tuple[int, int, int]
    size: tuple[int, int, int]

    @classmethod
    def from_list(cls, values) -> Box:
        """``[x0, y0, z0, nx, ny, nz]`` -> Box."""
        v = [int(a) for a in values]
        if len(v) != 6:
            raise InputError(f"box: expected 6 integers X0 Y0 Z0 NX NY NZ, got {len(v)}")
        return cls((v[0], v[1], v[2]), (v[3], v[4], v[5]))

    @property
    def stop(self) -> tuple[int, int, int]:
        (x0, y0, z0), (nx, ny, nz) = self.offset, self.size
        return (x0 + nx, y0 + ny, z0 + nz)

    @property
    def nvoxels(self) -> int:
        return int(np.prod(self.size, dtype=np.int64))

    def slices(self) -> tuple[slice, slice, slice]:
        """Numpy slices into a ``(nz, ny, nx)`` array."""
        (x0, y0, z0), (x1, y1, z1) = self.offset, self.stop
        return (slice(z0, z1), slice(y0, y1), slice(x0, x1))

    def check_inside(self, shape_xyz, name: str = "box") -> None:
        """Raise :class:`InputError` unless the box is non-empty and inside ``shape_xyz``."""
        if any(s < 1 for s in self.size):
            raise InputError(f"{name}: size {self.size} is empty; every size must be >= 1")
        if any(o < 0 for o in self.offset) or any(
            e > n for e, n in zip(self.stop, shape_xyz, strict=True)
        ):
            raise InputError(
                f"{name}: offset {self.offset} size {self.size} reaches {self.stop}, outside the "
                f"volume of {tuple(int(n) for n in shape_xyz)} voxels (x, y, z)"
            )


@dataclass
class VoxelVolume:
    """A regular 3D grid of scalar values.

    data:    (nz, ny, nx) integer or float   values, x varying fastest (the raw-file order);
             a numpy array, a ``numpy.memmap`` or a dask array (kept lazy)
    spacing: (3,) float                      voxel size along (x, y, z), in ``unit``
    origin:  (3,) float                      position of voxel (0, 0, 0)'s corner, in ``unit``
    unit:    str                             length unit of spacing and origin ("" if unknown)
    name:    str                             where it came from (file name), for messages
    """

    data: Any
    spacing: tuple[float, float, float] = (1.0, 1.0, 1.0)
    origin: tuple[float, float, float] = (0.0, 0.0, 0.0)
    unit: str = ""
    name: str = ""
    meta: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        where = f"{self.name}: " if self.name else ""
        shape = getattr(self.data, "shape", None)
        dtype = getattr(self.data, "dtype", None)
        if shape is None or dtype is None:
            raise InputError(
                f"{where}volume data: expected an array, got {type(self.data).__name__}")
        if len(shape) != 3:
            raise InputError(
                f"{where}volume data: expected 3 dimensions (nz, ny, nx), got shape {shape}")
        if any(int(n) < 1 for n in shape):
            raise InputError(f"{where}volume data: every dimension must be >= 1, got shape {shape}")
        if np.dtype(dtype).name not in SUPPORTED_DTYPES:
            raise InputError(
                f"{where}volume data: dtype {np.dtype(dtype).name} is not supported; "
                f"expected one of {', '.join(SUPPORTED_DTYPES)}"
            )
        sp = tuple(float(s) for s in self.spacing)
        if len(sp) != 3 or not all(np.isfinite(sp)) or min(sp) <= 0:
            raise InputError(
                f"{where}spacing: expected 3 positive numbers (x, y, z), got {self.spacing}")
        og = tuple(float(s) for s in self.origin)
        if len(og) != 3 or not all(np.isfinite(og)):
            raise InputError(
                f"{where}origin: expected 3 finite numbers (x, y, z), got {self.origin}")
        self.spacing, self.origin = sp, og

    def __repr__(self) -> str:
        """Sizes, value type, spacing, bounds (no values; like xarray's repr).

        >>> print(VoxelVolume(np.zeros((2, 3, 4), ">u2"), spacing=(2, 2, 1), unit="um",
        ...                   name="a.raw"))
        <VoxelVolume 'a.raw'>
        Dimensions:  x: 4, y: 3, z: 2 (24 voxels)
        Values:      uint16 (big-endian)
        Spacing:     2 × 2 × 1 um
        Bounds:      x 0–8, y 0–6, z 0–2 um
        """
        nx, ny, nz = self.shape_xyz
        b = self.bounds()
        return reprs.block("VoxelVolume", self.name, [
            ("Dimensions", f"x: {nx}, y: {ny}, z: {nz} ({reprs.count(nx * ny * nz)} voxels)"),
            ("Values", reprs.array_kind(self.data)),
            ("Spacing", f"{' × '.join(reprs.num(s) for s in self.spacing)} {self.unit}".rstrip()),
            ("Bounds", reprs.span(b[0], b[1], unit=self.unit)),
            ("Format", str(self.meta.get("format") or "")),
        ])

    @property
    def shape_xyz(self) -> tuple[int, int, int]:
        """Number of voxels along (x, y, z)."""
        nz, ny, nx = self.data.shape
        return (int(nx), int(ny), int(nz))

    @property
    def dtype(self) -> np.dtype:
        return np.dtype(self.data.dtype)

    @property
    def is_lazy(self) -> bool:
        return not isinstance(self.data, np.ndarray)

    def full_box(self) -> Box:
        return Box((0, 0, 0), self.shape_xyz)

    def resolve_box(self, box) -> Box:
        """Accept None (whole volume), a Box or ``[x0, y0, z0, nx, ny, nz]``; check it."""
        if box is None:
            return self.full_box()
        if not isinstance(box, Box):
            box = Box.from_list(box)
        box.check_inside(self.shape_xyz, name=f"{self.name + ': ' if self.name else ''}box")
        return box

    def read_box(self, box=None) -> np.ndarray:
        """The values inside ``box`` as an in-memory ``(nz, ny, nx)`` array (a view if possible)."""
        box = self.resolve_box(box)
        sub = self.data[box.slices()]
        if hasattr(sub, "compute"):
            sub = sub.compute()
        return np.asarray(sub)

    def value_limits(self) -> tuple[float, float]:
        """The representable range of the dtype (integers) or (-inf, inf) for floats."""
        if np.issubdtype(self.dtype, np.integer):
            info = np.iinfo(self.dtype)
            return float(info.min), float(info.max)
        return float("-inf"), float("inf")

    def bounds(self, box=None) -> np.ndarray:
        """(2, 3) float: world-space min and max corner (x, y, z) of ``box`` (default: whole)."""
        box = self.resolve_box(box)
        sp, og = np.asarray(self.spacing), np.asarray(self.origin)
        lo = og + np.asarray(box.offset) * sp
        hi = og + np.asarray(box.stop) * sp
        return np.stack([lo, hi])

    # --- conversions (geoshade.api; models import nothing above them) --------------------------
    def to_pyvista(self, **options):
        """This volume as a PyVista ``ImageData`` (voxels are cells) (:func:`geoshade.to_pyvista`;
        options of :func:`geoshade.io.interop.pyvista_io.volume_to_pyvista`)."""

        return convert("to_pyvista", self, **options)

    def to_xarray(self, name: str | None = None):
        """This volume as xarray: a ``DataArray`` ``(z, y, x)`` with voxel-centre coordinates
        (:func:`geoshade.to_xarray`)."""

        return convert("to_xarray", self, name=name)
