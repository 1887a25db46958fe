"""The napari reader: geoshade's self-describing volumes as napari layer data.

Raw files are not offered (napari cannot ask for ``--shape``/``--dtype``).  A multiscale zarr
store (``core ingest``, any OME-Zarr image) becomes one multiscale image layer whose levels are
the store's levels (lazy dask arrays; napari reads only what it shows).
"""

from __future__ import annotations

import functools
import importlib.metadata
import inspect
import re
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from geoshade.errors import InputError
from geoshade.io import formats, load
from geoshade.io.stores.ome_zarr import ngff_unit
from geoshade.io.stores.zarr_io import is_zarr_store, read_level, store_levels
from geoshade.io.volumes.raw import native_order
from geoshade.models import VoxelVolume

#: what a napari reader returns: (data, layer keyword arguments, layer type)
LayerData = tuple[Any, dict, str]

#: bytes of one plane napari may read at once: a single-scale image is shown a whole (y, x)
#: plane at a time (a multiscale one from its coarsest level up); a store declaring a larger
#: plane would freeze napari while it reads it, so the reader refuses it in one line
PLANE_BYTES = 1 << 30

#: file suffixes the plugin opens (the napari.yaml patterns); others are left to other plugins
SUFFIXES = (".zarr", ".tif", ".tiff", ".npy", ".npz", ".h5", ".hdf5", ".hdf", ".he5", ".nhdr",
            ".nrrd", ".mhd", ".mha")


def _readable(path) -> bool:
    """True if geoshade reads ``path`` without hints: a volume of the format table
    (:mod:`geoshade.io.formats`) of a self-describing kind (a file ending in one of
    :data:`SUFFIXES`, a zarr store or a folder of TIFF slices)."""
    p = Path(path)
    fmt = formats.find(p)
    if fmt is None or fmt.domain != "volume":
        return False
    if p.is_dir():
        return bool(fmt.folder)
    return p.is_file() and p.suffix.lower() in SUFFIXES


def get_reader(path: str | Sequence[str]) -> Callable[..., list[LayerData]] | None:
    """The npe2 reader hook: :func:`read_layers` if geoshade reads ``path`` (every path of a list),
    else None so that napari asks another plugin.

    Examples
    --------
    >>> get_reader("scan.raw") is None  # a headerless raw file needs hints napari cannot give
    True
    """
    paths = [path] if isinstance(path, str | Path) else list(path)
    if not paths or not all(_readable(p) for p in paths):
        return None
    return read_layers


def read_layers(path: str | Sequence[str]) -> list[LayerData]:
    """Layer data for each path (see :func:`layer_data`)."""
    paths = [path] if isinstance(path, str | Path) else list(path)
    return [layer for p in paths for layer in layer_data(p)]


def _levels(path) -> list[VoxelVolume]:
    """The levels of a multiscale zarr store that fit as overviews (level 0 first)."""
    if not is_zarr_store(path):
        return []
    out = []
    for k in range(store_levels(path)):
        try:
            out.append(read_level(path, k))
        except InputError:
            if k == 0:
                raise
            break  # a level of another writer that is no smaller copy: the finer ones only
    return out


@functools.cache
def _napari_accepts(keyword: str) -> bool:
    """Whether the installed napari's layers take ``keyword`` (``units``, ``axis_labels``:
    napari >= 0.6): from the signature when napari is running, else from its version (importing
    napari to find out would take seconds)."""
    layers = sys.modules.get("napari.layers")
    if layers is not None:
        return keyword in inspect.signature(layers.Image.__init__).parameters
    try:
        version = importlib.metadata.version("napari")
    except importlib.metadata.PackageNotFoundError:
        return False
    parts = [int(v) for v in re.findall(r"\d+", version)[:2]]
    return len(parts) == 2 and (parts[0], parts[1]) >= (0, 6)


def layer_kwargs(volume: VoxelVolume, name: str | None = None) -> dict:
    """napari keyword arguments placing ``volume`` in world coordinates: ``scale`` (the spacing
    in z, y, x order), ``translate`` (the first voxel's centre: napari puts pixel centres at
    ``translate + index * scale``), ``metadata`` (unit, source, spacing and origin as geoshade
    says them), and ``units``/``axis_labels`` where napari takes them.

    Examples
    --------
    >>> import numpy as np
    >>> kw = layer_kwargs(VoxelVolume(np.zeros((2, 2, 2), np.uint8), spacing=(1, 2, 4),
    ...                               origin=(10, 0, 0), unit="um", name="v"))
    >>> kw["scale"], kw["translate"], kw["metadata"]["unit"]
    ((4.0, 2.0, 1.0), (2.0, 1.0, 10.5), 'um')
    """
    sx, sy, sz = volume.spacing
    ox, oy, oz = volume.origin
    meta = volume.meta or {}
    kw: dict[str, Any] = {
        "name": name or volume.name or "volume",
        "scale": (sz, sy, sx),
        "translate": (oz + sz / 2, oy + sy / 2, ox + sx / 2),
        "metadata": {"unit": volume.unit, "source": str(meta.get("source") or volume.name),
                     "format": str(meta.get("format", "")), "spacing_xyz": list(volume.spacing),
                     "origin_xyz": list(volume.origin), "geoshade": True},
    }
    if meta.get("assumed"):
        kw["metadata"]["assumed"] = [str(a) for a in meta["assumed"]]
    unit = ngff_unit(volume.unit)  # a name pint (napari's units) knows
    if unit and _napari_accepts("units"):
        kw["units"] = (unit,) * 3
    if _napari_accepts("axis_labels"):
        kw["axis_labels"] = ("z", "y", "x")
    return kw


def _check_plane(vol: VoxelVolume, path, multiscale: bool) -> None:
    """Refuse, before napari reads anything, a volume one of whose (y, x) planes is more than
    :data:`PLANE_BYTES` (a store may declare any size: 1e15 voxels in a 400-byte zarr.json)."""
    nx, ny, _ = vol.shape_xyz
    nbytes = nx * ny * np.dtype(vol.dtype).itemsize
    if nbytes <= PLANE_BYTES:
        return
    which = "its coarsest level's planes are" if multiscale else "one plane is"
    raise InputError(f"{path}: {which} {ny}×{nx} voxels ({nbytes / 2**30:,.1f} GiB), more than "
                     f"the {PLANE_BYTES / 2**30:.0f} GiB napari may read at once; ingest it "
                     "with levels (geoshade core ingest: halved down to 256 a side) so that "
                     "napari shows one that fits")


def layer_data(path) -> list[LayerData]:
    """One napari layer for a volume geoshade reads: an image layer (a labels layer for a store
    written as labels), multiscale for a multiscale zarr store.

    Parameters
    ----------
    path : str or Path
        A zarr store (geoshade's or any OME-Zarr image), a TIFF stack or folder of TIFF slices,
        ``.npy``/``.npz``, HDF5 with one 3D dataset, or whatever else :func:`geoshade.load`
        reads without hints.

    Returns
    -------
    list of (data, kwargs, layer_type)
        ``data`` is level 0 (numpy, memmap or dask), or the list of levels when the store has
        several; ``kwargs`` from :func:`layer_kwargs` plus ``multiscale`` and, when the store
        records them, ``contrast_limits``.

    Raises
    ------
    InputError
        Whatever :func:`geoshade.load` finds wrong (one line naming the file), a model that
        is not a voxel volume, or a plane napari would read at once beyond
        :data:`PLANE_BYTES` (nothing is read).

    Examples
    --------
    >>> import numpy as np, tempfile, os
    >>> f = os.path.join(tempfile.mkdtemp(), "v.npy")
    >>> np.save(f, np.arange(24, dtype=np.uint8).reshape(2, 3, 4))
    >>> [(data, kw, kind)] = layer_data(f)
    >>> data.shape, kw["scale"], kind
    ((2, 3, 4), (1.0, 1.0, 1.0), 'image')
    """
    p = Path(path)
    levels = _levels(p)
    vol = levels[0] if levels else load(p)
    if not isinstance(vol, VoxelVolume):
        raise InputError(f"{path}: a {type(vol).__name__}, not a voxel volume; the napari "
                         "plugin opens volumes")
    multiscale = len(levels) > 1
    _check_plane(levels[-1] if multiscale else vol, path, multiscale)
    kw = layer_kwargs(vol, name=p.name)
    # napari uploads the bytes as they are: a big-endian memmap becomes native chunk by chunk
    data: Any = ([native_order(lv.data, lazy=True) for lv in levels] if multiscale
                 else native_order(vol.data, lazy=True))
    kw["multiscale"] = multiscale
    kind = "labels" if vol.meta.get("labels") else "image"
    vr = vol.meta.get("value_range")
    if kind == "image" and vr is not None and vr[0] is not None and vr[1] > vr[0]:
        kw["contrast_limits"] = [float(vr[0]), float(vr[1])]
    if kind == "labels" and np.dtype(vol.dtype).kind == "f":
        kind = "image"  # napari labels are integers
    return [(data, kw, kind)]


__all__ = ["PLANE_BYTES", "SUFFIXES", "get_reader", "layer_data", "layer_kwargs", "read_layers"]
