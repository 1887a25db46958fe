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
from geoshade.io.paths import check_file, guard_mapped
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
    >>> raw_dtype(">u2").str, raw_dtype(np.dtype(">i4")).str
    ('>u2', '>i4')
    """
    pre = f"{path}: " if path else ""
    key = endian.lower() if isinstance(endian, str) else endian
    if key not in _ENDIAN:
        raise InputError(f"{pre}endian: expected 'little' or 'big', got {endian!r}")
    order = ""   # a byte order the dtype itself names ('>u2', np.dtype('>u2')) wins
    if isinstance(dtype, str):
        name = dtype.strip().lower()
        order = name[:1] if name[:1] in "<>" else ""
        name = _SHORT.get(name.lstrip("<>=|"), name)
    else:
        try:
            dt = np.dtype(dtype)
            name = dt.name
            order = {"<": "<", ">": ">"}.get(dt.byteorder, "")
        except TypeError:
            name = repr(dtype)
    if name not in RAW_DTYPES:
        accepted = ", ".join(RAW_DTYPES) + " (or " + ", ".join(RAW_DTYPES.values()) + ")"
        raise InputError(f"{pre}dtype: {dtype!r} is not supported; expected one of {accepted}")
    if order and key == "big" and order == "<":
        raise InputError(f"{pre}dtype {dtype!r} is little-endian but endian is 'big'; give one "
                         "byte order")
    return np.dtype((order or _ENDIAN[key]) + RAW_DTYPES[name])


def native_order(a, lazy: bool = False):
    """``a`` with its values in this machine's byte order: ``a`` itself when they are already
    (or bytes), else a native copy; ``lazy``: a dask array converting chunk by chunk (a
    big-endian memmap shown in napari is never read whole).

    ``numpy.memmap`` of a big-endian TIFF or raw file is read-only, so a library that swaps in
    place (VTK through PyVista) or uploads the bytes as they are (OpenGL, vispy) needs this.

    >>> a = np.arange(3, dtype=">u2")
    >>> native_order(a).dtype.isnative, native_order(a).tolist()
    (True, [0, 1, 2])
    >>> b = np.arange(3, dtype=np.uint16)
    >>> native_order(b) is b
    True
    """
    dt = getattr(a, "dtype", None)
    if dt is None or dt.isnative:
        return a
    native = dt.newbyteorder("=")
    if lazy or hasattr(a, "dask"):
        import dask.array as da

        arr = a if hasattr(a, "dask") else da.from_array(a, chunks="auto")
        return arr.astype(native)
    return np.asarray(a).astype(native)


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


#: square-slice layouts :func:`fitting_shapes` offers: NZ = k * NX for these k
ASPECTS = (2, 4, 0.5)
#: slice sides :func:`fitting_shapes` tries for square slices of any depth
COMMON_SIDES = (128, 256, 384, 500, 512, 768, 1000, 1024, 1500, 1536, 2000, 2048, 2560, 4096)
#: most shapes an error lists
MAX_LISTED = 5


def _icbrt(n: int) -> int | None:
    """The integer cube root of ``n`` if ``n`` is a cube, else None."""
    if n < 1:
        return None
    c = round(n ** (1.0 / 3.0))
    for k in (c - 1, c, c + 1):
        if k > 0 and k**3 == n:
            return k
    return None


def fitting_shapes(nvalues: int, limit: int = MAX_LISTED) -> list[tuple[int, int, int]]:
    """Shapes ``(NX, NY, NZ)`` of ``nvalues`` values a raw file might hold: the cube, square
    slices ``S×S×kS`` for the aspects in :data:`ASPECTS`, then square slices of the
    :data:`COMMON_SIDES` (the most cube-like first); at most ``limit``.

    Examples
    --------
    >>> fitting_shapes(512 ** 3)[:3]
    [(512, 512, 512), (256, 256, 2048), (1024, 1024, 128)]
    >>> fitting_shapes(2 * 300 ** 3)
    [(300, 300, 600), (500, 500, 216)]
    """
    out: list[tuple[int, int, int]] = []
    c = _icbrt(nvalues)
    if c:
        out.append((c, c, c))
    for k in ASPECTS:
        m = nvalues / k
        s = _icbrt(round(m)) if float(m).is_integer() else None
        if s and s * s * round(s * k) == nvalues and (s, s, round(s * k)) not in out:
            out.append((s, s, round(s * k)))
    square = [(side, side, nvalues // (side * side)) for side in COMMON_SIDES
              if nvalues % (side * side) == 0
              and 1 / 16 <= nvalues // (side * side) / side <= 16]  # not a thin sheet
    square.sort(key=lambda s: abs(math.log(s[2] / s[0])))  # the most cube-like first
    out += [s for s in square if s not in out]
    return out[:limit]


def _shapes_text(shapes) -> str:
    return ", ".join("×".join(map(str, s)) for s in shapes)


def infer_shape(path, dtype, offset: int = 0) -> tuple[tuple[int, int, int], str]:
    """The shape of a headerless raw file whose size allows exactly one cube of ``dtype``
    values, and a note for ``meta["assumed"]``.

    Raises
    ------
    InputError
        One line: the file size, the shapes that fit it (:func:`fitting_shapes`) and that
        ``--shape`` is needed.

    Examples
    --------
    >>> import tempfile, os
    >>> f = os.path.join(tempfile.mkdtemp(), "c.raw")
    >>> np.zeros(8 ** 3, np.uint16).tofile(f)
    >>> infer_shape(f, "uint16")[0]
    (8, 8, 8)
    """
    p = check_file(path, "a raw file")
    dt = raw_dtype(dtype, "little", path)
    size = os.path.getsize(p) - int(offset)
    n, rest = divmod(size, dt.itemsize)
    if size > 0 and not rest:
        c = _icbrt(n)
        if c:
            return (c, c, c), (f"shape {c}×{c}×{c} (a cube: the only shape the {size}-byte "
                               f"{dt.name} file size allows without --shape)")
    head = f" after the {offset}-byte offset" if offset else ""
    if size <= 0 or rest:
        raise InputError(f"{path}: shape: the file has {size} bytes{head}, not a whole number "
                         f"of {dt.name} values ({dt.itemsize} bytes each); check --dtype and "
                         "--offset, and give --shape NX NY NZ")
    fits = fitting_shapes(n)
    listed = f"; shapes that fit: {_shapes_text(fits)}" if fits else ""
    raise InputError(f"{path}: shape: {size} bytes{head} = {n} {dt.name} values, not a cube"
                     f"{listed}; give --shape NX NY NZ")


def cube_hints(path, offset: int = 0) -> str:
    """What a file of unknown dtype could be, as cubes per dtype: ``512³ uint8`` ...

    >>> import tempfile, os
    >>> f = os.path.join(tempfile.mkdtemp(), "c.raw")
    >>> np.zeros(8 ** 3, np.uint16).tofile(f)
    >>> cube_hints(f)
    '8×8×8 int16/uint16'
    """
    size = os.path.getsize(check_file(path, "a raw file")) - int(offset)
    by_size: dict[int, list[str]] = {}
    for name, code in RAW_DTYPES.items():
        by_size.setdefault(np.dtype(code).itemsize, []).append(name)
    hints = []
    for item, names in sorted(by_size.items()):
        n, rest = divmod(size, item)
        c = _icbrt(n) if size > 0 and not rest else None
        if c:
            hints.append(f"{c}×{c}×{c} {'/'.join(sorted(names))}")
    return ", ".join(hints)


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
    shape : sequence of 3 int or None
        ``(NX, NY, NZ)``: number of voxels along x (varying fastest in the file), y and z;
        None: the cube the file size allows (:func:`infer_shape`; an error lists the shapes
        that fit when it is not a cube).
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
    dt = raw_dtype(dtype, endian, path)
    try:
        offset = int(offset)
    except (TypeError, ValueError):
        offset = -1
    if offset < 0:
        raise InputError(f"{path}: offset: expected a byte count >= 0, got {offset!r}")
    inferred = None
    if shape is None:
        shape, inferred = infer_shape(path, dt, offset)
    nx, ny, nz = _check_shape(shape, path)
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
    guard_mapped(path)  # a file truncated while mapped: one line, not a silent SIGBUS
    data = np.memmap(p, dtype=dt, mode="r", offset=offset, shape=(nz, ny, nx), order="C")
    meta: dict = {"format": "raw", "source": str(path),
                  "endian": "big" if dt.byteorder == ">" else endian, "offset": offset}
    meta["assumed"] = [inferred] if inferred else []
    if spacing is None:
        sp = (1.0, 1.0, 1.0)
        meta["assumed"].append("spacing 1.0 (raw files do not store the voxel size)")
    else:
        sp = as_xyz(spacing, "spacing", path)
    if not unit:
        meta["assumed"].append("unit voxel (raw files store no length unit; --unit names one)")
    if not meta["assumed"]:
        del meta["assumed"]
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
