"""NumPy ``.npy`` / ``.npz`` volumes.

A 3D array is taken as ``(nz, ny, nx)`` (x varying fastest, as numpy stores C-order arrays).
``.npy`` files are memory-mapped; ``.npz`` archives are read into memory (numpy cannot map
members of a zip file).  Boolean arrays (segmentations, e.g. from PoreSpy) are viewed as uint8
0/1 without copying.  Neither format stores a voxel size: spacing 1.0 is assumed.
"""

from __future__ import annotations

import zipfile
from pathlib import Path

import numpy as np

from geoshade.errors import InputError
from geoshade.models import VoxelVolume

#: member names tried, in this order, in an ``.npz`` holding several arrays
NPZ_KEYS = ("data", "volume")


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
    p = Path(path)
    if not p.exists():
        raise InputError(f"{path}: no such file")
    if p.is_dir():
        raise InputError(f"{path}: is a folder; expected a .npy or .npz file")
    if zipfile.is_zipfile(p):
        return _read_npz(p, path)
    try:
        arr = np.load(p, mmap_mode="r", allow_pickle=False)
    except (ValueError, OSError, EOFError) as err:
        raise InputError(f"{path}: not a readable .npy array ({err})") from err
    if arr.ndim == 4:  # (time, nz, ny, nx): only a field over time reads it
        from geoshade.io.fields import load_field

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
            arr = z[key]
    except InputError:
        raise
    except (ValueError, OSError, EOFError, zipfile.BadZipFile) as err:
        raise InputError(f"{path}: not a readable .npz archive ({err})") from err
    return _volume(arr, path, f"array {key!r}", {"format": "npz", "source": str(path), "key": key})
