"""What a volume file declares, read from its header alone (the ``header`` functions of the
volume rows of :mod:`geoshade.io.formats`): shape, dtype, and how its reader holds the data —
``mapped`` (raw, uncompressed ``.npy``, contiguous TIFF: file pages, never copied), ``lazy``
(HDF5, a compressed TIFF beyond :data:`~geoshade.io.volumes.tiff.EAGER_LIMIT_BYTES`: read by
blocks) or ``held`` (``.npz``, a compressed TIFF read whole).

No voxel is read: a raw file's shape comes from the hints, the ``.nhdr``/``.mhd`` beside it or
the cube its size allows; a ``.npy`` from its header; a TIFF from its page tags; an HDF5 file
from its dataset's metadata.

>>> import numpy as np, tempfile, os
>>> f = os.path.join(tempfile.mkdtemp(), "c.raw")
>>> np.zeros((4, 5, 6), np.uint16).tofile(f)
>>> h = raw_header(f, shape=(6, 5, 4), dtype="uint16")
>>> h.shape, h.dtype, h.storage, h.file_bytes
((6, 5, 4), 'uint16', 'mapped', 240)
"""

from __future__ import annotations

import math
import os
import zipfile
from dataclasses import replace

import numpy as np
import tifffile

from geoshade.errors import InputError, require
from geoshade.io.paths import captured_logs, check_file, check_folder, one_line
from geoshade.io.plan import Header
from geoshade.io.volumes.npy import NPZ_ERRORS, NPZ_KEYS, _check_held, read_header
from geoshade.io.volumes.raw import infer_shape, raw_dtype
from geoshade.io.volumes.sidecar import (
    MET_TYPES,
    MHD_SUFFIXES,
    NRRD_TYPES,
    data_file_of,
    find_sidecar,
    parse_mhd,
)
from geoshade.io.volumes.sidecar import (
    nrrd_header as read_nrrd_header,
)
from geoshade.io.volumes.tiff import EAGER_LIMIT_BYTES, list_slices


def _xyz(shape_zyx) -> tuple[int, int, int]:
    nz, ny, nx = (int(n) for n in shape_zyx)
    return nx, ny, nz


def raw_header(path, shape=None, dtype=None, endian=None, offset=None) -> Header | None:
    """A raw file's shape and dtype from the hints, else the header beside it, else the cube
    its size allows; None without a dtype (the reader then says what to give)."""
    p = check_file(path, "a raw file")
    if shape is None:
        side = find_sidecar(p)
        if side is not None:
            h = (mhd_header if side.suffix.lower() in MHD_SUFFIXES else nrrd_header)(side)
            return replace(h, path=str(path), format="raw")
    if dtype is None:
        return None
    dt = raw_dtype(dtype, endian or "little", path)
    if shape is None:
        shape, _ = infer_shape(p, dt, int(offset or 0))
    nx, ny, nz = (int(n) for n in shape)
    return Header(str(path), "raw", "volume", (nx, ny, nz), dt.name, os.path.getsize(p),
                  storage="mapped", hints={"shape": (nx, ny, nz), "dtype": dt.name,
                                           "endian": endian, "offset": offset})


def mhd_header(path) -> Header:
    """A MetaImage header's ``DimSize`` and ``ElementType``."""
    fields, _ = parse_mhd(path)
    try:
        shape = tuple(int(v) for v in fields.get("DimSize", "").split())
    except ValueError:
        shape = ()
    et = str(fields.get("ElementType", "")).upper()
    if len(shape) != 3 or et not in MET_TYPES:
        raise InputError(f"{path}: DimSize/ElementType: expected three sizes and one of "
                         f"{', '.join(MET_TYPES)}")
    compressed = str(fields.get("CompressedData", "")).lower() in ("true", "1", "yes")
    data = data_file_of(path)
    size = os.path.getsize(data) if data is not None and data.is_file() else \
        os.path.getsize(check_file(path))
    return Header(str(path), "metaimage", "volume", shape, MET_TYPES[et], size,
                  storage="held" if compressed else "mapped")


def nrrd_header(path) -> Header:
    """An NRRD header's ``sizes``, ``type`` and ``encoding`` (gzip/bzip2 data are decoded
    into memory: held)."""
    h, _ = read_nrrd_header(path)
    sizes = tuple(int(v) for v in np.asarray(h.get("sizes", ())).ravel())
    kind = NRRD_TYPES.get(str(h.get("type", "")).lower())
    if len(sizes) != 3 or kind is None:
        raise InputError(f"{path}: sizes/type: expected a 3D volume of one of "
                         f"{', '.join(sorted(set(NRRD_TYPES.values())))}")
    enc = str(h.get("encoding", "raw")).lower()
    data = data_file_of(path)
    size = os.path.getsize(data) if data is not None and data.is_file() else \
        os.path.getsize(check_file(path))
    return Header(str(path), "nrrd", "volume", sizes, kind, size,
                  storage="mapped" if enc == "raw" else "held")


def npy_header(path) -> Header | None:
    """A ``.npy`` header (mapped) or the chosen member of an ``.npz`` (held); None for an array
    that is not 3D (a 4D ``.npy`` is a field over time)."""
    p = check_file(path, "a .npy or .npz file")
    size = os.path.getsize(p)
    if zipfile.is_zipfile(p):
        try:
            with zipfile.ZipFile(p) as z:
                names = [n[:-4] for n in z.namelist() if n.endswith(".npy")]
                name = names[0] if len(names) == 1 else next(
                    (k for k in NPZ_KEYS if k in names), None)
                if name is None:
                    return None
                with z.open(name + ".npy") as fh:
                    shape, dt, off = read_header(fh, path, f"member '{name}.npy'")
                held = z.getinfo(name + ".npy").file_size - off
        except NPZ_ERRORS as err:
            raise InputError(f"{path}: not a readable .npz archive ({one_line(err)})") from None
        storage = "held"
        _check_held(shape, np.dtype(dt), held, path, f"member '{name}.npy'")
    else:
        with open(p, "rb") as fh:
            shape, dt, off = read_header(fh, path)
        _check_held(shape, np.dtype(dt), size - off, path, "")   # as the reader refuses it
        storage = "mapped"
    if len(shape) != 3:
        return None
    return Header(str(path), "numpy", "volume", _xyz(shape), np.dtype(dt).name, size,
                  storage=storage)


def tiff_header(path) -> Header | None:
    """A TIFF's first image series: its shape (the last two axes are y, x; the others make z)
    and dtype from the tags; mapped when stored contiguously uncompressed."""
    p = check_file(path, "a TIFF file")
    with captured_logs("tifffile"):
        try:
            with tifffile.TiffFile(p) as tf:
                if not tf.series:
                    return None
                s = tf.series[0]
                shape, dt, contiguous = tuple(s.shape), np.dtype(s.dtype), \
                    s.dataoffset is not None
        except (tifffile.TiffFileError, OSError, ValueError, KeyError, IndexError) as err:
            raise InputError(f"{path}: not a readable TIFF ({one_line(err)})") from None
    if len(shape) < 3:
        return None
    nz = math.prod(int(n) for n in shape[:-2])
    nbytes = nz * int(shape[-2]) * int(shape[-1]) * dt.itemsize
    storage = "mapped" if contiguous else ("lazy" if nbytes > EAGER_LIMIT_BYTES else "held")
    return Header(str(path), "tiff", "volume", (int(shape[-1]), int(shape[-2]), nz), dt.name,
                  os.path.getsize(p), storage=storage)


def tiff_folder_header(path) -> Header | None:
    """A folder of TIFF slices: the slice count, and the first slice's size and dtype."""
    folder = check_folder(path, "a folder of TIFF slices")
    slices = list_slices(folder)
    if not slices:
        return None
    first = tiff_header(slices[0])
    if first is None:
        return None
    nx, ny, _ = first.shape
    nbytes = len(slices) * nx * ny * np.dtype(first.dtype).itemsize
    return Header(str(path), "tiff-folder", "volume", (nx, ny, len(slices)), first.dtype,
                  sum(os.path.getsize(s) for s in slices),
                  storage="lazy" if nbytes > EAGER_LIMIT_BYTES else "held")


def hdf5_header(path, dataset=None) -> Header | None:
    """An HDF5 dataset's shape and dtype from its metadata (read lazily by blocks)."""
    h5py = require("h5py", "hdf5", "reading HDF5 files")
    p = check_file(path, "an HDF5 file")
    try:
        with h5py.File(p, "r") as h5:
            names: list[str] = []
            h5.visititems(lambda n, o: names.append(n) if isinstance(o, h5py.Dataset)
                          and len(o.shape) == 3 else None)
            name = str(dataset).strip("/") if dataset else (
                names[0] if len(names) == 1 else next(
                    (n for n in ("data", "volume", "exchange/data", "0") if n in names), None))
            if name is None or name not in h5:
                return None
            d = h5[name]
            shape, dt = tuple(d.shape), np.dtype(d.dtype)
    except (OSError, ValueError, KeyError, TypeError) as err:
        raise InputError(f"{path}: not a readable HDF5 file ({one_line(err)})") from None
    if len(shape) != 3:
        return None
    return Header(str(path), "hdf5", "volume", _xyz(shape), dt.name, os.path.getsize(p),
                  storage="lazy")


__all__ = ["hdf5_header", "mhd_header", "npy_header", "nrrd_header", "raw_header",
           "tiff_folder_header", "tiff_header"]
