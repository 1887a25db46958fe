"""Files ⇄ models: one module per format; :func:`load` reads any kind of file of the format
table.

Every kind of file is one row of :data:`geoshade.io.formats.FORMATS` (suffixes, domain, reader
by name, ingest command, extra, the files of a case); :func:`load` finds the row of a path and
imports its reader only then, so ``import geoshade.io`` imports no reader and no reader package
(resfo, tifffile, zarr, rasterio ...). A new format is one row and one reader::

    from geoshade.io.formats import Format, register
    register(Format("grdecl2", "my grid", "grid", "mypkg.reader:read", (".mygrid",)))

A reader is ``reader(path, **hints) -> model``; :func:`load` passes it only the hints its
signature names. The readers and helpers below (``describe``, ``load_field``, ``read_tiff`` ...)
are imported when first used.
"""

from __future__ import annotations

import dataclasses
import importlib
import inspect
from pathlib import Path
from typing import Any

from geoshade.errors import InputError
from geoshade.io import formats
from geoshade.io.describe import describe, format_description  # (a module of the same name)
from geoshade.io.formats import FORMATS, Format, format_of, register_reader, resolve
from geoshade.io.paths import check_input
from geoshade.io.volumes.raw import as_xyz
from geoshade.models import CornerPointGrid, VoxelVolume
from geoshade.progress import Progress

#: hints any volume accepts, applied after reading when the reader does not take them
_VOLUME_HINTS = ("spacing", "unit", "origin")

#: names this package gives, imported from their module when first used
_LAZY = {
    "load_field": "geoshade.io.fields",
    "read_mhd": "geoshade.io.volumes.sidecar",
    "read_nhdr": "geoshade.io.volumes.sidecar",
    "read_npy": "geoshade.io.volumes.npy",
    "read_raw": "geoshade.io.volumes.raw",
    "read_tiff": "geoshade.io.volumes.tiff",
    "read_tiff_folder": "geoshade.io.volumes.tiff",
    "read_zarr": "geoshade.io.stores.zarr_io",
    "write_zarr": "geoshade.io.stores.zarr_io",
}


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module 'geoshade.io' has no attribute {name!r}")


def __dir__():
    return sorted(list(globals()) + list(_LAZY))


def _override(model, path, extra: dict):
    if not isinstance(model, VoxelVolume):
        raise InputError(f"{path}: hints {sorted(extra)} do not apply to this file type")
    changes: dict[str, Any] = {}
    if "spacing" in extra:
        changes["spacing"] = as_xyz(extra["spacing"], "spacing", path)
    if "origin" in extra:
        changes["origin"] = as_xyz(extra["origin"], "origin", path, positive=False)
    if "unit" in extra:
        changes["unit"] = str(extra["unit"])
    meta = dict(model.meta)
    kept = [
        a for a in meta.get("assumed", []) if not any(k in str(a).split("(")[0] for k in changes)
    ]
    if kept:
        meta["assumed"] = kept
    else:
        meta.pop("assumed", None)
    return dataclasses.replace(model, meta=meta, **changes)


def load(path, progress: Progress | None = None, **hints) -> Any:
    """Read a file or folder and return the matching model.

    Parameters
    ----------
    path : str or Path
        Any kind of file of :data:`geoshade.io.formats.FORMATS`: ``.raw .bin .img .vol .dat``
        (headerless: ``dtype``, and ``shape`` unless the file is a cube or a ``.nhdr``/``.mhd``
        header beside it names it), ``.nhdr .nrrd .mhd .mha`` (headers with their raw data;
        spacing and unit from them), ``.tif .tiff``, a folder of TIFF slices, ``.npy .npz``, a
        ``.zarr`` folder or any folder with ``zarr.json``/``.zarray``/``.zgroup``, HDF5, GeoTOP
        netCDF, stack models; any file of an ECLIPSE/OPM case (``.EGRID .INIT .UNRST .X0001``
        and the formatted ``.FEGRID .FINIT .FUNRST .F0001``: the case is opened), GRDECL,
        decks, a ROFF grid (``.roff .roffasc``; ``properties=[...]`` parameter files); a
        raster of heights (a one-band GeoTIFF, Arc ASCII ``.asc``, SRTM ``.hgt``/``.hgt.zip``)
        is read as a :class:`~geoshade.io.layers.dem.Raster` (:func:`geoshade.load` makes it a
        terrain model).
    **hints
        Passed to the reader when its signature names them (raw: ``shape=(NX, NY, NZ)``,
        ``dtype``, ``endian``, ``offset``; tiff: ``lazy``).  ``spacing``, ``unit`` and
        ``origin`` override what a volume file says; ``params=[FILE, ...]``: ROFF or GRDECL
        property files added to a corner-point grid (:mod:`geoshade.io.grids.params`).
        Hints set to None are ignored; any other hint the format does not use is an error.
    progress : callable, optional
        ``progress(done, total)`` (see :mod:`geoshade.progress`), passed to readers that report
        it (GRDECL and decks: bytes; EGRID cases: report steps) and not to others; not a hint,
        so never an error.

    Returns
    -------
    model
        A :class:`~geoshade.models.VoxelVolume` for the volume formats.

    Raises
    ------
    InputError
        Missing path, a FIFO/device/socket, a folder where the format is a file, unknown
        format, missing or unused hints, or whatever the reader finds wrong with the file
        (always one line naming the file: damaged content, codec errors, sizes that do not fit
        the file or the available memory).
    MissingExtraError
        The format needs an optional extra that is not installed (one line naming
        ``pip install 'geoshade[extra]'``).

    Examples
    --------
    >>> import numpy as np, tempfile, os
    >>> f = os.path.join(tempfile.mkdtemp(), "core.raw")
    >>> np.zeros((4, 3, 2), np.uint8).tofile(f)
    >>> load(f, shape=(2, 3, 4), dtype="uint8", spacing=0.5).spacing
    (0.5, 0.5, 0.5)
    """
    p = check_input(path)  # a FIFO, device or socket is refused before anything opens it
    fmt = format_of(path)
    if p.is_dir() and not fmt.folder:
        raise InputError(f"{path}: is a folder; expected a file ({fmt.title})")
    reader = fmt.function()
    given = {k: v for k, v in hints.items() if v is not None}
    param_files = given.pop("params", None)   # property files for any grid (--param)
    params = inspect.signature(reader).parameters
    takes_any = any(pr.kind is inspect.Parameter.VAR_KEYWORD for pr in params.values())
    accepted = set(list(params)[1:]) - {"progress"}  # not a hint: passed below
    passed = {k: v for k, v in given.items() if takes_any or k in accepted}
    extra = {k: v for k, v in given.items() if k not in passed}
    unused = sorted(set(extra) - set(_VOLUME_HINTS))
    if unused:
        takes = sorted(accepted | set(_VOLUME_HINTS))
        raise InputError(
            f"{path}: {', '.join(unused)} does not apply to this file type; it takes "
            f"{', '.join(takes)}"
        )
    if progress is not None and "progress" in params:
        passed["progress"] = progress
    model = reader(path, **passed)
    if extra:
        model = _override(model, path, extra)
    if param_files:
        if not isinstance(model, CornerPointGrid):
            raise InputError(f"{path}: --param (property files) applies to corner-point "
                             f"grids; this is a {type(model).__name__}")
        add_params = resolve("geoshade.io.grids.params:add_params")
        model = add_params(model, [param_files] if isinstance(param_files, str | Path)
                           else list(param_files))
    return model


__all__ = [
    "FORMATS",
    "Format",
    "describe",
    "format_description",
    "formats",
    "load",
    "load_field",
    "read_mhd",
    "read_nhdr",
    "read_npy",
    "read_raw",
    "read_tiff",
    "read_tiff_folder",
    "read_zarr",
    "register_reader",
    "write_zarr",
]
