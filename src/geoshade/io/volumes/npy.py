"""NumPy ``.npy`` / ``.npz`` volumes.

A 3D array is taken as ``(nz, ny, nx)`` (x varying fastest, as numpy stores C-order arrays).
``.npy`` files are memory-mapped; ``.npz`` archives are read into memory (numpy cannot map
members of a zip file).  Boolean arrays (segmentations, e.g. from PoreSpy) are viewed as uint8
0/1 without copying.  Neither format stores a voxel size: spacing 1.0 is assumed.

Before any array is mapped or read, its header is checked against the bytes the file (or the
archive member) holds, so a truncated file or a header claiming a huge shape is one line, not an
allocation of that size; an ``.npz`` member (read into memory) must also fit the available
memory (:func:`geoshade.io.paths.check_memory`).
"""

from __future__ import annotations

import math
import os
import zipfile
import zlib
from pathlib import Path
from typing import IO

import numpy as np
from numpy.lib import format as npformat

from geoshade.errors import InputError
from geoshade.io.fields import load_field
from geoshade.io.paths import check_file, check_memory, format_bytes, guard_mapped, one_line
from geoshade.models import VoxelVolume

#: what reading an ``.npz`` member can raise on a damaged archive
NPZ_ERRORS = (ValueError, OSError, EOFError, zipfile.BadZipFile, zlib.error, KeyError)

#: member names tried, in this order, in an ``.npz`` holding several arrays
NPZ_KEYS = ("data", "volume")


def read_header(fh: IO[bytes], path, what: str = "") -> tuple[tuple[int, ...], np.dtype, int]:
    """(shape, dtype, header bytes) of the ``.npy`` data starting at ``fh``'s position.

    Raises
    ------
    InputError
        Not a ``.npy`` header, a damaged one, or Python objects (pickles) instead of numbers.

    Examples
    --------
    >>> import io
    >>> buf = io.BytesIO(); np.save(buf, np.zeros((2, 3), np.uint16)); _ = buf.seek(0)
    >>> read_header(buf, "a.npy")
    ((2, 3), dtype('uint16'), 128)
    """
    where = f"{path}: {what + ': ' if what else ''}"
    start = fh.tell()
    try:
        version = npformat.read_magic(fh)
        if version == (1, 0):
            shape, _, dtype = npformat.read_array_header_1_0(fh)
        elif version == (2, 0):
            shape, _, dtype = npformat.read_array_header_2_0(fh)
        else:  # (3, 0): the 2.0 layout with a UTF-8 header; numpy has no public reader for it
            raise ValueError(f".npy format version {version[0]}.{version[1]} is not supported; "
                             "expected 1.0 or 2.0")
    except (ValueError, OSError, EOFError, SyntaxError, TypeError) as err:
        raise InputError(f"{where}not a readable .npy array ({one_line(err)})") from None
    if dtype.hasobject:
        raise InputError(f"{where}holds Python objects (a pickle); expected an array of numbers")
    return tuple(int(n) for n in shape), np.dtype(dtype), fh.tell() - start


def _check_held(shape, dtype, held: int, path, what: str) -> int:
    """Bytes of the data; an error when the header claims more than ``held`` bytes."""
    nbytes = math.prod(shape) * dtype.itemsize
    if nbytes > held:
        raise InputError(
            f"{path}: {what} header says shape {shape} {dtype.name} ({format_bytes(nbytes)}) but "
            f"the {'member' if 'member' in what else 'file'} holds {max(0, held)} bytes of data "
            "(truncated or damaged)")
    return nbytes


def read_member(z, key: str, path) -> np.ndarray:
    """Member ``key`` of an open ``.npz`` (:func:`numpy.load`), after checking its header
    against the member's size and the available memory.

    Examples
    --------
    >>> import io
    >>> buf = io.BytesIO(); np.savez(buf, data=np.ones((2, 2), np.uint8)); _ = buf.seek(0)
    >>> with np.load(buf) as z:
    ...     read_member(z, "data", "a.npz").sum()
    np.uint64(4)
    """
    zf = z.zip
    names = zf.namelist()
    name = key + ".npy" if key + ".npy" in names else key
    try:
        info = zf.getinfo(name)
        with zf.open(info) as fh:
            shape, dtype, head = read_header(fh, path, f"member {name!r}")
    except InputError:
        raise
    except NPZ_ERRORS as err:
        raise InputError(f"{path}: member {name!r} is damaged ({one_line(err)})") from None
    nbytes = _check_held(shape, dtype, info.file_size - head, path, f"member {name!r}:")
    check_memory(nbytes, path, f"member {name!r} ({'×'.join(map(str, shape))} {dtype.name})")
    try:
        return np.asarray(z[key])
    except NPZ_ERRORS as err:
        raise InputError(f"{path}: member {name!r} is damaged ({one_line(err)})") from None


def _volume(arr: np.ndarray, path, what: str, meta: dict) -> VoxelVolume:
    if arr.ndim != 3:
        raise InputError(
            f"{path}: {what} has {arr.ndim} dimensions, shape {arr.shape}; "
            "expected a 3D array (nz, ny, nx)"
        )
    if arr.dtype == np.bool_:
        arr = arr.view(np.uint8)
        meta["converted"] = "bool viewed as uint8 (0/1)"
    meta["assumed"] = ["spacing 1.0 (numpy files do not store the voxel size)"]
    return VoxelVolume(data=arr, name=Path(path).name, meta=meta)


def read_npy(path):
    """Read a 3D ``.npy`` array (memory-mapped) or a ``.npz`` archive as a volume.

    A 4D ``.npy`` array ``(time, nz, ny, nx)`` can only be a field over time: it is read as a
    :class:`~geoshade.models.FieldSeries` (:func:`geoshade.io.load_field`).

    Parameters
    ----------
    path : str or Path
        ``.npy`` file holding one 3D array ``(nz, ny, nx)``, or ``.npz`` archive holding a
        single 3D array or one named ``data`` or ``volume``.

    Returns
    -------
    VoxelVolume
        For ``.npy`` the data is a read-only ``numpy.memmap`` (nothing is copied).

    Raises
    ------
    InputError
        Missing or unreadable file, an array that is not 3D, an ``.npz`` with several arrays
        and none named ``data``/``volume``, or an unsupported dtype.

    Examples
    --------
    >>> import numpy as np, tempfile, os
    >>> f = os.path.join(tempfile.mkdtemp(), "v.npy")
    >>> np.save(f, np.zeros((2, 3, 4), np.uint8))
    >>> read_npy(f).shape_xyz
    (4, 3, 2)
    """
    p = check_file(path, "a .npy or .npz file")
    if zipfile.is_zipfile(p):
        return _read_npz(p, path)
    with open(p, "rb") as fh:
        shape, dtype, head = read_header(fh, path)
    _check_held(shape, dtype, os.path.getsize(p) - head, path, "the")
    try:
        guard_mapped(path)  # a file truncated while mapped: one line, not a silent SIGBUS
        arr = np.load(p, mmap_mode="r", allow_pickle=False)
    except (ValueError, OSError, EOFError) as err:
        raise InputError(f"{path}: not a readable .npy array ({one_line(err)})") from None
    if arr.ndim == 4:  # (time, nz, ny, nx): only a field over time reads it

        return load_field(path)
    return _volume(arr, path, "array", {"format": "npy", "source": str(path)})


def _read_npz(p: Path, path) -> VoxelVolume:
    try:
        with np.load(p, allow_pickle=False) as z:
            keys = list(z.files)
            if len(keys) == 1:
                key = keys[0]
            else:
                key = next((k for k in NPZ_KEYS if k in keys), None)
                if key is None:
                    raise InputError(
                        f"{path}: .npz holds {len(keys)} arrays {keys}; expected a single "
                        f"array or one named {' or '.join(repr(k) for k in NPZ_KEYS)}"
                    )
            arr = read_member(z, key, path)
    except InputError:
        raise
    except NPZ_ERRORS as err:
        raise InputError(f"{path}: not a readable .npz archive ({one_line(err)})") from None
    return _volume(arr, path, f"array {key!r}", {"format": "npz", "source": str(path), "key": key})
