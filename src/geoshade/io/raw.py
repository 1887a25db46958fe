"""Headerless raw volumes (ImageJ, Avizo, ParaView "raw" export).

A raw file holds ``NX * NY * NZ`` values and nothing else (or a fixed-size header that
``offset`` skips), x varying fastest, then y, then z.  That is exactly the C order of a
``(nz, ny, nx)`` array, so the file is mapped with :class:`numpy.memmap` and never copied.
"""

from __future__ import annotations

import math
import os

import numpy as np

from geoshade.errors import InputError
from geoshade.io.paths import check_file
from geoshade.models import VoxelVolume

#: dtype names :func:`read_raw` accepts (short numpy codes map onto them)
RAW_DTYPES: dict[str, str] = {
    "uint8": "u1",
    "uint16": "u2",
    "int8": "i1",
    "int16": "i2",
    "uint32": "u4",
    "int32": "i4",
    "float32": "f4",
    "float64": "f8",
}
_SHORT = {code: name for name, code in RAW_DTYPES.items()}
_ENDIAN = {"little": "<", "big": ">"}


def raw_dtype(dtype, endian: str = "little", path="") -> np.dtype:
    """The numpy dtype (with byte order) for a raw-file dtype name and endianness.

    Parameters
    ----------
    dtype : str or numpy dtype
        ``uint8 uint16 int8 int16 uint32 int32 float32 float64`` or the short forms
        ``u1 u2 i1 i2 u4 i4 f4 f8``; a numpy dtype or scalar type of one of these.
    endian : {"little", "big"}
        Byte order of the values in the file.
    path : str or Path, optional
        File name used in error messages.

    Returns
    -------
    numpy.dtype

    Raises
    ------
    InputError
        For an unknown dtype or endianness.

    Examples
    --------
    >>> raw_dtype("u2", "big").str
    '>u2'
    >>> raw_dtype("float32").str
    '<f4'
    """
    pre = f"{path}: " if path else ""
    key = endian.lower() if isinstance(endian, str) else endian
    if key not in _ENDIAN:
        raise InputError(f"{pre}endian: expected 'little' or 'big', got {endian!r}")
    if isinstance(dtype, str):
        name = dtype.strip().lower()
        name = _SHORT.get(name.lstrip("<>=|"), name)
    else:
        try:
            name = np.dtype(dtype).name
        except TypeError:
            name = repr(dtype)
    if name not in RAW_DTYPES:
        accepted = ", ".join(RAW_DTYPES) + " (or " + ", ".join(RAW_DTYPES.values()) + ")"
        raise InputError(f"{pre}dtype: {dtype!r} is not supported; expected one of {accepted}")
    return np.dtype(_ENDIAN[key] + RAW_DTYPES[name])


def as_xyz(values, field: str, path="", positive: bool = True) -> tuple[float, float, float]:
    """One number or three numbers ``(x, y, z)`` -> a tuple of three floats.

    Examples
    --------
    >>> as_xyz(0.5, "spacing")
    (0.5, 0.5, 0.5)
    >>> as_xyz([1, 2, 3], "spacing")
    (1.0, 2.0, 3.0)
    """
    pre = f"{path}: " if path else ""
    try:
        arr = np.asarray(values, dtype=np.float64).reshape(-1)
    except (TypeError, ValueError):
        arr = np.array([], dtype=np.float64)
    if arr.size == 1:
        arr = np.repeat(arr, 3)
    kind = "positive" if positive else "finite"
    if arr.size != 3 or not np.all(np.isfinite(arr)) or (positive and np.any(arr <= 0)):
        raise InputError(f"{pre}{field}: expected 1 or 3 {kind} numbers (x, y, z), got {values!r}")
    return (float(arr[0]), float(arr[1]), float(arr[2]))


def _check_shape(shape, path) -> tuple[int, int, int]:
    try:
        vals = [int(s) for s in shape]
        ok = len(vals) == 3 and all(float(a) == b for a, b in zip(shape, vals, strict=True))
    except (TypeError, ValueError):
        ok, vals = False, []
    if not ok:
        raise InputError(f"{path}: shape: expected 3 integers NX NY NZ (x fastest), got {shape!r}")
    if any(v < 1 for v in vals):
        raise InputError(
            f"{path}: shape: every size must be a positive integer, got NX NY NZ = "
            f"{' '.join(str(v) for v in vals)}"
        )
    return vals[0], vals[1], vals[2]


def _size_hint(nbytes: int, nx: int, ny: int, nz: int, dt: np.dtype) -> str:
    """What the payload of ``nbytes`` bytes would fit, e.g. ``' = 110×110×110 uint8'``."""
    for name, code in RAW_DTYPES.items():
        other = np.dtype(code)
        if other.itemsize != dt.itemsize and nbytes == nx * ny * nz * other.itemsize:
            return f" = {nx}×{ny}×{nz} {name}"
    if nbytes <= 0 or nbytes % dt.itemsize:
        return ""
    n = nbytes // dt.itemsize
    fits = []
    side = round(n ** (1.0 / 3.0))
    for c in (side - 1, side, side + 1):
        if c > 0 and c**3 == n:
            fits.append(f"{c}×{c}×{c}")
    if n % (nx * ny) == 0:
        cand = f"{nx}×{ny}×{n // (nx * ny)}"
        if cand not in fits:
            fits.append(cand)
    if not fits:
        return f" = {n} {dt.name} values"
    return " = " + " or ".join(f"{f} {dt.name}" for f in fits)


def read_raw(
    path,
    shape,
    dtype,
    endian: str = "little",
    spacing=None,
    unit: str = "",
    offset: int = 0,
    origin=(0.0, 0.0, 0.0),
) -> VoxelVolume:
    """Map a headerless raw file as a :class:`VoxelVolume` without reading it.

    Parameters
    ----------
    path : str or Path
        The raw file.
    shape : sequence of 3 int
        ``(NX, NY, NZ)``: number of voxels along x (varying fastest in the file), y and z.
    dtype : str or numpy dtype
        ``uint8 uint16 int8 int16 uint32 int32 float32 float64`` (or ``u1 u2 i2 f4`` ...).
    endian : {"little", "big"}
        Byte order of multi-byte values.
    spacing : float or sequence of 3 float, optional
        Voxel size (x, y, z); raw files do not store it, so the default is 1.0 (noted in
        ``meta["assumed"]``).
    unit : str
        Length unit of ``spacing`` ("" if unknown).
    offset : int
        Bytes to skip at the start of the file (a header).
    origin : float or sequence of 3 float
        Position of the first voxel's corner.

    Returns
    -------
    VoxelVolume
        ``data`` is a read-only ``numpy.memmap`` of shape ``(NZ, NY, NX)``.

    Raises
    ------
    InputError
        Missing file, bad shape/dtype/endian, or a file size that does not match
        ``offset + NX*NY*NZ*itemsize`` (the message says what the size would fit).

    Examples
    --------
    >>> import numpy as np, tempfile, os
    >>> f = os.path.join(tempfile.mkdtemp(), "cube.raw")
    >>> np.arange(24, dtype="<u2").tofile(f)
    >>> vol = read_raw(f, shape=(4, 3, 2), dtype="uint16")
    >>> vol.data.shape, int(vol.data[1, 0, 0])
    ((2, 3, 4), 12)
    """
    p = check_file(path, "a raw file")
    nx, ny, nz = _check_shape(shape, path)
    dt = raw_dtype(dtype, endian, path)
    try:
        offset = int(offset)
    except (TypeError, ValueError):
        offset = -1
    if offset < 0:
        raise InputError(f"{path}: offset: expected a byte count >= 0, got {offset!r}")
    actual = os.path.getsize(p)
    payload = nx * ny * nz * dt.itemsize
    expected = offset + payload
    if offset and offset >= actual:
        raise InputError(
            f"{path}: offset: the {offset}-byte header to skip reaches past the end of the file "
            f"({actual} bytes); --shape {nx} {ny} {nz} --dtype {dt.name} expects {expected} bytes"
        )
    if actual != expected:
        hint = _size_hint(actual - offset, nx, ny, nz, dt)
        head = f" after the {offset}-byte offset" if offset else ""
        what = "truncated, or " if actual < expected else ""
        raise InputError(
            f"{path}: file has {actual} bytes{head}{hint}; --shape {nx} {ny} {nz} --dtype "
            f"{dt.name} expects {expected} bytes ({what}wrong shape, dtype or offset)"
        )
    data = np.memmap(p, dtype=dt, mode="r", offset=offset, shape=(nz, ny, nx), order="C")
    meta: dict = {"format": "raw", "source": str(path), "endian": endian, "offset": offset}
    if spacing is None:
        sp = (1.0, 1.0, 1.0)
        meta["assumed"] = ["spacing 1.0 (raw files do not store the voxel size)"]
    else:
        sp = as_xyz(spacing, "spacing", path)
    og = as_xyz(origin, "origin", path, positive=False)
    return VoxelVolume(data=data, spacing=sp, origin=og, unit=unit or "", name=p.name, meta=meta)


def raw_nbytes(shape, dtype) -> int:
    """Bytes of a raw file of ``shape`` (NX, NY, NZ) and ``dtype``.

    Examples
    --------
    >>> raw_nbytes((100, 100, 100), "uint16")
    2000000
    """
    return math.prod(int(s) for s in shape) * raw_dtype(dtype).itemsize
