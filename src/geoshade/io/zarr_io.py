"""Zarr volumes (zarr-python 2.17+ and 3.x): chunked, compressed, read lazily.

A store holds one 3D array ``(nz, ny, nx)``, either at its root or inside a group as
``data`` or ``0`` (level 0 of a multiscale pyramid, as OME-Zarr writes it).  Attributes, on the
array or its group:

- ``spacing``: ``[sx, sy, sz]`` voxel size (x, y, z)
- ``unit``: length unit of ``spacing`` and ``origin``
- ``origin``: ``[x0, y0, z0]`` position of the first voxel's corner

OME-Zarr ``multiscales`` metadata (axes, ``scale`` and ``translation`` transformations) is used
when those attributes are absent.
"""

from __future__ import annotations

import os
import shutil
import uuid
from pathlib import Path
from typing import Any

import numpy as np

from geoshade.errors import InputError
from geoshade.io.raw import as_xyz
from geoshade.models import VoxelVolume

#: files that mark a folder as a zarr store (v3, v2 array, v2 group)
ZARR_MARKERS = ("zarr.json", ".zarray", ".zgroup")

#: names of the array inside a group, tried in this order
ARRAY_NAMES = ("data", "0")

#: bytes per slab when copying a volume into a store
SLAB_BYTES = 64 << 20


def is_zarr_store(path) -> bool:
    """True if ``path`` is a folder named ``*.zarr`` or holding zarr metadata.

    Examples
    --------
    >>> is_zarr_store("no/such/folder")
    False
    """
    p = Path(path)
    if not p.is_dir():
        return False
    return p.suffix.lower() == ".zarr" or any((p / m).exists() for m in ZARR_MARKERS)


def as_lazy(array) -> Any:
    """A dask array over ``array`` (a zarr array, or anything ``dask.array.from_array`` takes).

    Examples
    --------
    >>> import numpy as np
    >>> as_lazy(np.zeros((2, 2, 2))).shape
    (2, 2, 2)
    """
    import dask.array as da
    import zarr

    if isinstance(array, zarr.Array):
        return da.from_zarr(array)
    return da.from_array(array)


def _open(path):
    import zarr

    try:
        return zarr.open(str(path), mode="r")
    except Exception as err:  # zarr raises many kinds; one line for the user
        raise InputError(
            f"{path}: not a readable zarr store ({type(err).__name__}: {err})"
        ) from err


def _ome_transforms(attrs: dict, path) -> tuple[str, dict]:
    """(array path, {spacing, unit, origin}) from OME-Zarr ``multiscales`` attributes."""
    ms = attrs.get("multiscales") or attrs.get("ome", {}).get("multiscales")
    if not ms:
        return "", {}
    ms0 = ms[0]
    datasets = ms0.get("datasets") or [{}]
    sub = str(datasets[0].get("path", ""))
    axes = ms0.get("axes") or []
    names = [a.get("name") if isinstance(a, dict) else str(a) for a in axes]
    out: dict = {}
    scale, trans = None, None
    for tr in datasets[0].get("coordinateTransformations", []):
        if tr.get("type") == "scale":
            scale = tr.get("scale")
        elif tr.get("type") == "translation":
            trans = tr.get("translation")
    if names and all(n in names for n in "zyx"):
        idx = [names.index(n) for n in "xyz"]
        if scale and len(scale) == len(names):
            out["spacing"] = [scale[i] for i in idx]
        if trans and len(trans) == len(names):
            out["origin"] = [trans[i] for i in idx]
        units = {
            a.get("unit") for a in axes if isinstance(a, dict) and a.get("name") in ("z", "y", "x")
        }
        if len(units) == 1 and None not in units:
            out["unit"] = _short_unit(units.pop())
    return sub, out


def _short_unit(unit: str) -> str:
    return {
        "micrometer": "um",
        "millimeter": "mm",
        "nanometer": "nm",
        "meter": "m",
        "centimeter": "cm",
    }.get(unit, unit)


def _check_complete(attrs: dict, path) -> None:
    """Refuse a store whose ``ingest`` attribute says it is unfinished (geoshade.io.ingest)."""
    ing = attrs.get("ingest")
    if isinstance(ing, dict) and not ing.get("complete", False):
        raise InputError(
            f"{path}: incomplete store (its ingest was interrupted or is still running; "
            "ingest.complete is false); run the same 'geoshade core ingest' again to finish it"
        )


def read_zarr(path) -> VoxelVolume:
    """Open a zarr store as a lazy :class:`VoxelVolume`.

    Parameters
    ----------
    path : str or Path
        A zarr folder: an array, or a group holding an array named ``data`` or ``0``.

    Returns
    -------
    VoxelVolume
        ``data`` is a dask array when dask is installed, else the zarr array (nothing is read
        until it is sliced).  Missing ``spacing``/``origin`` are taken as 1.0 / 0.0 and listed in
        ``meta["assumed"]``.

    Raises
    ------
    InputError
        Not a store, no suitable array, not 3D, or bad attributes.

    Examples
    --------
    >>> import numpy as np, tempfile, os
    >>> from geoshade.models import VoxelVolume
    >>> f = os.path.join(tempfile.mkdtemp(), "v.zarr")
    >>> _ = write_zarr(VoxelVolume(np.ones((2, 3, 4), np.uint8), spacing=(2, 2, 2)), f)
    >>> vol = read_zarr(f)
    >>> vol.shape_xyz, vol.spacing
    ((4, 3, 2), (2.0, 2.0, 2.0))
    """
    p = Path(path)
    if not p.exists():
        raise InputError(f"{path}: no such file")
    node = _open(p)
    attrs: dict = {}
    where = ""
    if hasattr(node, "array_keys"):  # a group
        gattrs = dict(node.attrs)
        sub, ome = _ome_transforms(gattrs, path)
        keys = list(node.array_keys())
        names = ([sub] if sub else []) + list(ARRAY_NAMES)
        name = next((n for n in names if n in keys), None)
        if name is None:
            raise InputError(
                f"{path}: zarr group has no array named {' or '.join(repr(n) for n in names)}; "
                f"it holds arrays {keys or 'none'}"
            )
        arr = node[name]
        attrs = {**ome, **gattrs, **dict(arr.attrs)}
        _check_complete(gattrs, path)  # issue 6: refuse an unfinished `geoshade core ingest`
        where = f"/{name}"
    else:
        arr = node
        attrs = dict(arr.attrs)
    if len(arr.shape) != 3:
        raise InputError(
            f"{path}{where}: expected a 3D array (nz, ny, nx), got shape {tuple(arr.shape)}"
        )
    meta: dict = {"format": "zarr", "source": str(path), "chunks": tuple(arr.chunks)}
    assumed = []
    if attrs.get("spacing") is not None:
        spacing = as_xyz(attrs["spacing"], "spacing attribute", path)
    else:
        spacing = (1.0, 1.0, 1.0)
        assumed.append("spacing 1.0 (no 'spacing' attribute)")
    if attrs.get("origin") is not None:
        origin = as_xyz(attrs["origin"], "origin attribute", path, positive=False)
    else:
        origin = (0.0, 0.0, 0.0)
        assumed.append("origin 0.0 (no 'origin' attribute)")
    if assumed:
        meta["assumed"] = assumed
    if attrs.get("value_range") is not None:  # written by geoshade.io.ingest
        meta["value_range"] = list(attrs["value_range"])
    unit = str(attrs.get("unit") or "")
    return VoxelVolume(
        data=as_lazy(arr), spacing=spacing, origin=origin, unit=unit, name=p.name, meta=meta
    )


def _chunks(chunks, shape) -> tuple[int, int, int]:
    try:
        c = [int(v) for v in chunks]
    except (TypeError, ValueError):
        c = []
    if len(c) != 3 or min(c) < 1:
        raise InputError(f"chunks: expected 3 positive integers (cz, cy, cx), got {chunks!r}")
    return tuple(min(a, int(n)) for a, n in zip(c, shape, strict=True))


def write_zarr(volume: VoxelVolume, path, chunks=(64, 64, 64), overwrite: bool = False) -> Path:
    """Write a volume to a zarr array store, atomically.

    The store is written to a hidden sibling folder and renamed into place at the end, so a
    reader never sees a half-written store.

    Parameters
    ----------
    volume : VoxelVolume
        The volume (numpy, memmap, dask or zarr data; copied in z-slabs of ~64 MiB).
    path : str or Path
        Folder to create (conventionally ``*.zarr``).
    chunks : sequence of 3 int
        Chunk shape ``(cz, cy, cx)`` in array order; clipped to the volume.
    overwrite : bool
        Replace an existing ``path``; otherwise an existing path is an error.

    Returns
    -------
    Path
        ``path``.

    Examples
    --------
    >>> import numpy as np, tempfile, os
    >>> from geoshade.models import VoxelVolume
    >>> vol = VoxelVolume(np.arange(24, dtype=np.uint16).reshape(2, 3, 4), unit="um")
    >>> out = write_zarr(vol, os.path.join(tempfile.mkdtemp(), "v.zarr"))
    >>> int(read_zarr(out).data[1, 2, 3])
    23
    """
    import zarr

    p = Path(path)
    if p.exists() and not overwrite:
        raise InputError(f"{path}: already exists; pass overwrite=True to replace it")
    data = volume.data
    shape = tuple(int(n) for n in data.shape)
    ch = _chunks(chunks, shape)
    dtype = np.dtype(volume.dtype).newbyteorder("=")
    p.parent.mkdir(parents=True, exist_ok=True)
    tmp = p.parent / f".{p.name}.tmp-{os.getpid()}-{uuid.uuid4().hex[:8]}"
    try:
        arr = zarr.open_array(store=str(tmp), mode="w", shape=shape, chunks=ch, dtype=dtype)
        plane = max(1, shape[1] * shape[2] * dtype.itemsize)
        step = max(1, SLAB_BYTES // plane // ch[0]) * ch[0]
        for z0 in range(0, shape[0], step):
            slab = data[z0 : z0 + step]
            if hasattr(slab, "compute"):
                slab = slab.compute()
            arr[z0 : z0 + step] = np.asarray(slab, dtype=dtype)
        arr.attrs.update(
            {
                "spacing": list(volume.spacing),
                "origin": list(volume.origin),
                "unit": volume.unit,
                "axes": ["z", "y", "x"],
            }
        )
        if p.exists():
            old = p.parent / f".{p.name}.old-{uuid.uuid4().hex[:8]}"
            os.rename(p, old)
            os.rename(tmp, p)
            shutil.rmtree(old, ignore_errors=True)
        else:
            os.rename(tmp, p)
    finally:
        if tmp.exists():
            shutil.rmtree(tmp, ignore_errors=True)
    return p
