"""HDF5 volumes (h5py), read lazily: one 3D dataset ``(nz, ny, nx)`` of a ``.h5``/``.hdf5`` file.

The dataset is found by the ``dataset`` hint (an HDF5 path such as ``/exchange/data``), else it
is the only 3D dataset of the file, else the first of ``data``, ``volume``, ``exchange/data``,
``0`` that exists.  Voxel size, in this order of preference, from the dataset's or the file's
attributes:

- ``spacing`` (x, y, z) with ``unit``;
- ``element_size_um`` (z, y, x; Fiji / ilastik), unit ``um``;
- ``voxel_size`` (x, y, z) with ``unit``.

The data stay on disk: ``VoxelVolume.data`` is a dask array over :class:`H5Array`, a small
picklable view that opens the file in whichever process reads a block (so the same volume
works on the threaded scheduler and on a ``dask.distributed`` cluster).
"""

from __future__ import annotations

import os
import threading
from typing import Any

import numpy as np

from geoshade.errors import GeoshadeError, InputError, require
from geoshade.io.paths import check_file, one_line
from geoshade.io.volumes.raw import as_xyz
from geoshade.models import VoxelVolume

#: file suffixes of HDF5 files
HDF5_SUFFIXES = (".h5", ".hdf5", ".hdf", ".he5")

#: dataset paths tried, in this order, when a file holds several 3D datasets
DATASET_NAMES = ("data", "volume", "exchange/data", "0")

#: bytes per dask block when the dataset is not chunked (whole z slabs)
BLOCK_BYTES = 64 << 20

_LOCK = threading.Lock()  # libhdf5 is not thread-safe: one read at a time per process


def _h5py():
    return require("h5py", "hdf5", "reading HDF5 volumes")


class H5Array:
    """A lazy, picklable, read-only view of one HDF5 dataset (``shape``, ``dtype``, slicing).

    The file is opened on first access in each process and kept open; pickling sends only the
    path and the dataset name.

    Examples
    --------
    >>> import h5py, numpy as np, tempfile, os
    >>> f = os.path.join(tempfile.mkdtemp(), "v.h5")
    >>> with h5py.File(f, "w") as h:
    ...     _ = h.create_dataset("data", data=np.arange(24, dtype=np.uint8).reshape(2, 3, 4))
    >>> a = H5Array(f, "data")
    >>> a.shape, int(a[1, 2, 3])
    ((2, 3, 4), 23)
    """

    def __init__(self, path, name: str):
        self.path, self.name = str(path), str(name)
        self._file = None
        self._pid = None
        d = self._dataset()
        self.shape = tuple(int(n) for n in d.shape)
        self.dtype = np.dtype(d.dtype)
        self.ndim = len(self.shape)
        self.chunks = tuple(int(c) for c in d.chunks) if d.chunks else None

    def _dataset(self):
        if self._file is None or self._pid != os.getpid():
            self._file = _h5py().File(self.path, "r")
            self._pid = os.getpid()
        return self._file[self.name]

    def __getitem__(self, key) -> np.ndarray:
        with _LOCK:
            try:
                return np.asarray(self._dataset()[key])
            except (GeoshadeError, MemoryError):
                raise
            except Exception as err:  # h5py: OSError, RuntimeError, KeyError, ValueError ...
                raise InputError(f"{self.path}: dataset {self.name!r}: cannot be read, the file "
                                 f"is damaged or truncated ({one_line(err)})") from None

    def __getstate__(self) -> dict:
        state = dict(self.__dict__)
        state["_file"], state["_pid"] = None, None
        return state

    def __repr__(self) -> str:
        return f"H5Array({self.path!r}, {self.name!r}, shape={self.shape}, dtype={self.dtype})"


def _datasets_3d(h5) -> list[str]:
    h5py = _h5py()
    found: list[str] = []

    def visit(name, obj):
        if isinstance(obj, h5py.Dataset) and len(obj.shape) == 3:
            found.append(name)

    h5.visititems(visit)
    return found


def _pick(h5, path, dataset) -> str:
    if dataset:
        name = str(dataset).strip("/")
        if name not in h5:
            raise InputError(
                f"{path}: dataset: no dataset {dataset!r} in the file; its 3D datasets are "
                f"{_datasets_3d(h5) or 'none'}"
            )
        if not isinstance(h5[name], _h5py().Dataset):
            raise InputError(f"{path}: dataset: {dataset!r} is a group, expected a dataset")
        return name
    found = _datasets_3d(h5)
    if len(found) == 1:
        return found[0]
    for name in DATASET_NAMES:
        if name in found:
            return name
    if not found:
        raise InputError(f"{path}: holds no 3D dataset (nz, ny, nx); expected a volume")
    raise InputError(
        f"{path}: holds several 3D datasets {found}; choose one with dataset=PATH (--dataset)"
    )


def _spacing(attrs_list, path) -> tuple[tuple[float, float, float] | None, str, str]:
    """(spacing xyz or None, unit, where it came from)."""
    for attrs in attrs_list:
        if "spacing" in attrs:
            unit = attrs.get("unit", "")
            unit = unit.decode() if isinstance(unit, bytes) else str(unit)
            return as_xyz(np.asarray(attrs["spacing"]), "spacing attribute", path), unit, "spacing"
        if "element_size_um" in attrs:
            zyx = np.asarray(attrs["element_size_um"], dtype=np.float64).reshape(-1)
            if zyx.size == 3:
                zyx = zyx[::-1]
            return as_xyz(zyx, "element_size_um attribute", path), "um", "element_size_um"
        if "voxel_size" in attrs:
            unit = attrs.get("unit", "")
            unit = unit.decode() if isinstance(unit, bytes) else str(unit)
            vs = np.asarray(attrs["voxel_size"])
            return as_xyz(vs, "voxel_size attribute", path), unit, "voxel_size"
    return None, "", ""


def _refuse_outside(d, name: str, path) -> None:
    """Refuse a dataset whose data lie in other files: external storage (raw files named in
    the HDF5 file, a FIFO among them would hang the reader) and virtual datasets (mapped from
    other HDF5 files). A shared ``.h5`` could otherwise make a reader draw, or an ingest copy
    into a store, any file the user can read. One line naming every outside file."""
    outside: list[str] = []
    kind = ""
    try:
        ext = d.external
    except Exception:  # h5py without the property: no external storage read either
        ext = None
    if ext:
        kind = "external storage"
        outside = [str(e[0], "utf-8", "replace") if isinstance(e[0], bytes) else str(e[0])
                   for e in ext]
    elif getattr(d, "is_virtual", False):
        kind = "a virtual dataset"
        try:
            outside = sorted({str(m.file_name) for m in d.virtual_sources()})
        except Exception:
            outside = ["?"]
    if kind:
        shown = ", ".join(repr(f) for f in outside[:5])
        more = f" and {len(outside) - 5} more" if len(outside) > 5 else ""
        raise InputError(f"{path}: dataset {name!r} keeps its data in other files ({kind}: "
                         f"{shown}{more}); geoshade reads only data stored inside the file: "
                         "copy them in first (h5repack, or h5py's ds[...] into a new file)")


def read_hdf5(path, dataset: str | None = None) -> VoxelVolume:
    """Open one 3D dataset of an HDF5 file as a lazy :class:`VoxelVolume`.

    Parameters
    ----------
    path : str or Path
        A ``.h5``/``.hdf5`` file.
    dataset : str, optional
        HDF5 path of the volume (``/exchange/data``); needed when the file holds several 3D
        datasets and none is named ``data``, ``volume``, ``exchange/data`` or ``0``.

    Returns
    -------
    VoxelVolume
        ``data`` is a dask array (blocks = the dataset's chunks, or z slabs of ~64 MiB) when
        dask is installed, else an :class:`H5Array`; nothing is read until it is sliced.
        ``meta["dataset"]`` names the dataset; a missing voxel size is assumed 1.0.

    Raises
    ------
    InputError
        Missing or unreadable file, no (or an ambiguous) 3D dataset, bad attributes.

    Examples
    --------
    >>> import h5py, numpy as np, tempfile, os
    >>> f = os.path.join(tempfile.mkdtemp(), "core.h5")
    >>> with h5py.File(f, "w") as h:
    ...     d = h.create_dataset("scan/volume", data=np.ones((4, 5, 6), np.uint16))
    ...     d.attrs["element_size_um"] = [2.0, 1.0, 1.0]
    >>> vol = read_hdf5(f)
    >>> vol.shape_xyz, vol.spacing, vol.unit, vol.meta["dataset"]
    ((6, 5, 4), (1.0, 1.0, 2.0), 'um', 'scan/volume')
    """
    h5py = _h5py()
    p = check_file(path, "an HDF5 file")
    try:
        h5 = h5py.File(p, "r")
    except OSError as err:
        raise InputError(f"{path}: not a readable HDF5 file ({one_line(err)})") from None
    try:
        with h5:
            name = _pick(h5, path, dataset)
            d = h5[name]
            if len(d.shape) != 3:
                raise InputError(
                    f"{path}: dataset {name!r} has shape {tuple(d.shape)}; expected 3D (nz, ny, "
                    "nx)"
                )
            _refuse_outside(d, name, path)
            spacing, unit, src = _spacing([dict(d.attrs), dict(h5.attrs)], path)
            origin_attr = d.attrs.get("origin", h5.attrs.get("origin"))
        arr = H5Array(p, name)
    except (GeoshadeError, MemoryError):
        raise
    except Exception as err:  # a damaged file: h5py raises OSError, RuntimeError, KeyError ...
        raise InputError(f"{path}: damaged HDF5 file ({one_line(err)})") from None
    meta: dict[str, Any] = {"format": "hdf5", "source": str(path), "dataset": name}
    assumed = []
    if spacing is None:
        spacing = (1.0, 1.0, 1.0)
        assumed.append("spacing 1.0 (no spacing/element_size_um attribute)")
    else:
        meta["spacing_from"] = src
    origin = (0.0, 0.0, 0.0)
    if origin_attr is not None:
        origin = as_xyz(np.asarray(origin_attr), "origin attribute", path, positive=False)
    if assumed:
        meta["assumed"] = assumed
    return VoxelVolume(
        data=_as_dask(arr), spacing=spacing, origin=origin, unit=unit, name=p.name, meta=meta
    )


def _as_dask(arr: H5Array):
    import dask.array as da

    nz, ny, nx = arr.shape
    if arr.chunks:
        chunks = arr.chunks
    else:
        plane = max(1, ny * nx * arr.dtype.itemsize)
        chunks = (max(1, min(nz, BLOCK_BYTES // plane)), ny, nx)
    from dask.base import tokenize

    st = os.stat(arr.path)
    token = tokenize(os.path.abspath(arr.path), arr.name, st.st_mtime_ns, st.st_size)
    return da.from_array(arr, chunks=chunks, lock=False, asarray=True, fancy=False,
                         name=f"hdf5-{token}")
