"""Files ⇄ models: one module per format; :func:`load` picks the reader.

Readers are registered by file suffix in :data:`READERS`, by a suffix pattern in
:data:`PATTERN_READERS` (``.X0001``: a report number in the suffix) and, for folders, by a test in
:data:`FOLDER_READERS`.  A new format (GRDECL, EGRID, netCDF, ...) adds itself there, e.g.::

    from geoshade.io import register_reader
    register_reader((".grdecl",), read_grdecl, "GRDECL corner-point grid")

A reader is ``reader(path, **hints) -> model``; :func:`load` passes it only the hints its
signature names.
"""

from __future__ import annotations

import dataclasses
import inspect
import re
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

from geoshade.errors import InputError
from geoshade.io.describe import describe, format_description
from geoshade.io.fields import load_field
from geoshade.io.grids.deck import read_deck
from geoshade.io.grids.ecl import CASE_SUFFIXES, load_case
from geoshade.io.grids.ecl_records import RESTART_SUFFIX
from geoshade.io.grids.grdecl import read_grdecl
from geoshade.io.grids.params import add_params
from geoshade.io.grids.roff import ROFF_SUFFIXES, read_roff
from geoshade.io.interop import register_conversions
from geoshade.io.layers.geotop import read_geotop
from geoshade.io.layers.stackfile import SUFFIX as STACKS_SUFFIX
from geoshade.io.layers.stackfile import read_stacks
from geoshade.io.paths import check_input
from geoshade.io.stores.grid_store import is_grid_store, open_grid_store
from geoshade.io.stores.zarr_io import is_zarr_store, read_zarr, write_zarr
from geoshade.io.volumes.hdf5 import HDF5_SUFFIXES, read_hdf5
from geoshade.io.volumes.npy import read_npy
from geoshade.io.volumes.raw import as_xyz, cube_hints, read_raw
from geoshade.io.volumes.sidecar import (
    MHD_SUFFIXES,
    NRRD_SUFFIXES,
    find_sidecar,
    read_header_volume,
    read_mhd,
    read_nhdr,
)
from geoshade.io.volumes.tiff import TIFF_SUFFIXES, read_tiff, read_tiff_folder
from geoshade.models import CornerPointGrid, VoxelVolume
from geoshade.progress import Progress

Reader = Callable[..., Any]


def _read_raw_hinted(
    path,
    shape=None,
    dtype=None,
    endian=None,
    spacing=None,
    unit=None,
    offset=None,
    origin=None,
):
    """:func:`read_raw` with what the user did not give found: a ``.nhdr``/``.mhd`` header
    beside the file that names it (:func:`geoshade.io.volumes.sidecar.find_sidecar`) when there is
    no
    ``shape``, else the cube the file size allows (:func:`geoshade.io.volumes.raw.infer_shape`)."""
    if shape is None:

        side = find_sidecar(path)
        if side is not None:
            if dtype is not None or offset is not None or endian is not None:
                raise InputError(f"{path}: {side.name} beside it gives the shape, dtype, byte "
                                 "order and offset; give them all (--shape ...) to override it, "
                                 "or none")
            vol = read_header_volume(side, spacing=spacing, unit=unit, origin=origin)
            return dataclasses.replace(vol, meta={**vol.meta, "header": str(side)})
    if dtype is None:

        cubes = cube_hints(path, offset or 0)
        fits = f"; its size fits the cube {cubes}" if cubes else ""
        raise InputError(
            f"{path}: headerless raw file and no .nhdr/.mhd header beside it; give --shape NX NY "
            f"NZ and --dtype (the shape may be left out for a cube{fits}), e.g. --shape 110 110 "
            "110 --dtype uint8"
        )
    return read_raw(
        path, shape, dtype, endian=endian or "little", spacing=spacing, unit=unit or "",
        offset=offset or 0, origin=(0.0, 0.0, 0.0) if origin is None else origin,
    )


#: lower-case file suffix -> reader
READERS: dict[str, Reader] = {}

#: suffix -> short description, for messages and ``--help``
FORMATS: dict[str, str] = {}

#: (compiled pattern, reader, description) for suffixes that are a family (``.X0001``), tried
#: after :data:`READERS` with ``pattern.fullmatch(suffix)``
PATTERN_READERS: list[tuple[re.Pattern, Reader, str]] = []

#: (description, test(path) -> bool, reader) tried in order for folders without a known suffix
FOLDER_READERS: list[tuple[str, Callable[[Path], bool], Reader]] = []


def register_reader(suffixes: Iterable[str], reader: Reader, description: str) -> None:
    """Make :func:`load` read files ending in ``suffixes`` with ``reader``.

    Examples
    --------
    >>> register_reader((".myvol",), read_npy, "my volume")
    >>> READERS[".myvol"] is read_npy
    True
    >>> del READERS[".myvol"], FORMATS[".myvol"]
    """
    for s in suffixes:
        key = s.lower() if s.startswith(".") else "." + s.lower()
        READERS[key] = reader
        FORMATS[key] = description


def _is_tiff_folder(path: Path) -> bool:
    return any(
        f.suffix.lower() in TIFF_SUFFIXES and f.is_file() and not f.name.startswith(".")
        for f in path.iterdir()
    )


register_reader(
    (".raw", ".bin", ".img", ".vol", ".dat"),
    _read_raw_hinted,
    "headerless raw volume: --dtype, and --shape unless a cube or a .nhdr/.mhd beside it",
)
register_reader(NRRD_SUFFIXES, read_nhdr,
                "NRRD volume (.nhdr header + raw file, or .nrrd), needs the nrrd extra")
register_reader(MHD_SUFFIXES, read_mhd, "MetaImage volume (.mhd header + raw file, or .mha)")
register_reader(TIFF_SUFFIXES, read_tiff, "TIFF stack")
register_reader((".npy", ".npz"), read_npy, "NumPy array")


def _read_store(path):
    """A zarr store: a grid store (``grid_store`` attribute) as a lazy corner-point grid, any
    other store as a volume (:func:`read_zarr`)."""

    return open_grid_store(path) if is_grid_store(path) else read_zarr(path)


register_reader((".zarr",), _read_store, "zarr store (a volume, or a grid store of "
                "'geoshade grid ingest')")
register_reader((".nc",), read_geotop, "GeoTOP netCDF, variable=lithok|strat")
register_reader((STACKS_SUFFIX,), read_stacks, "geoshade stack model")
register_reader(HDF5_SUFFIXES, read_hdf5, "HDF5 dataset, lazy (dataset=PATH if several)")
register_reader((".grdecl", ".grid", ".inc"), read_grdecl, "GRDECL corner-point grid")
register_reader(CASE_SUFFIXES, load_case,
                "ECLIPSE/OPM case: any of its files, binary or formatted (EGRID + INIT, "
                "restarts beside it)")
PATTERN_READERS.append((RESTART_SUFFIX, load_case, "ECLIPSE/OPM non-unified restart (.X0001, "
                        ".F0001; the case's EGRID + INIT beside it)"))
register_reader(ROFF_SUFFIXES, read_roff,
                "ROFF grid (RMS), properties=[parameter files] or NAME--PROP.roff beside it")
register_reader((".data",), read_deck, "ECLIPSE/OPM input deck")
FOLDER_READERS.append(("zarr store (zarr.json/.zarray/.zgroup)", is_zarr_store, _read_store))
FOLDER_READERS.append(("folder of TIFF slices", _is_tiff_folder, read_tiff_folder))

#: hints any volume accepts, applied after reading when the reader does not take them
_VOLUME_HINTS = ("spacing", "unit", "origin")


def _formats_text() -> str:
    by_desc: dict[str, list[str]] = {}
    for suf, desc in FORMATS.items():
        by_desc.setdefault(desc, []).append(suf)
    parts = [f"{'/'.join(sufs)} ({desc})" for desc, sufs in by_desc.items()]
    parts += [desc for _, _, desc in PATTERN_READERS]
    parts += [desc for desc, _, _ in FOLDER_READERS]
    return "; ".join(parts)


def _pick_reader(p: Path, path) -> Reader:
    suffixes = [s.lower() for s in p.suffixes]
    for n in (2, 1):
        key = "".join(suffixes[-n:]) if len(suffixes) >= n else None
        if key in READERS:
            return READERS[key]
    for pattern, reader, _ in PATTERN_READERS:
        if pattern.fullmatch(p.suffix):
            return reader
    if p.is_dir():
        for _, test, reader in FOLDER_READERS:
            if test(p):
                return reader
        raise InputError(
            f"{path}: folder is not a known volume; expected one of: {_formats_text()}"
        )
    raise InputError(
        f"{path}: unknown file type {p.suffix or '(no suffix)'!r}; expected one of: "
        f"{_formats_text()}"
    )


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
        ``.raw .bin .img .vol .dat`` (headerless: ``dtype``, and ``shape`` unless the file is
        a cube or a ``.nhdr``/``.mhd`` header beside it names it), ``.nhdr .nrrd .mhd .mha``
        (headers with their raw data; spacing and unit from them), ``.tif
        .tiff``, a folder of TIFF slices, ``.npy .npz``, a ``.zarr`` folder or any folder with
        ``zarr.json``/``.zarray``/``.zgroup``; any file of an ECLIPSE/OPM case (``.EGRID .INIT
        .UNRST .X0001`` and the formatted ``.FEGRID .FINIT .FUNRST .F0001``: the case is
        opened), a ROFF grid (``.roff .roffasc``; ``properties=[...]`` parameter files); plus
        whatever later parts register in :data:`READERS`.
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

    Examples
    --------
    >>> import numpy as np, tempfile, os
    >>> f = os.path.join(tempfile.mkdtemp(), "core.raw")
    >>> np.zeros((4, 3, 2), np.uint8).tofile(f)
    >>> load(f, shape=(2, 3, 4), dtype="uint8", spacing=0.5).spacing
    (0.5, 0.5, 0.5)
    """
    p = check_input(path)  # a FIFO, device or socket is refused before anything opens it
    reader = _pick_reader(p, path)
    if p.is_dir() and reader not in {r for _, _, r in FOLDER_READERS}:
        desc = next((d for s, d in FORMATS.items() if READERS[s] is reader), "file")
        raise InputError(f"{path}: is a folder; expected a file ({desc})")
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
        model = add_params(model, [param_files] if isinstance(param_files, str | Path)
                           else list(param_files))
    return model


register_conversions()   # the models' to_pyvista()/to_xarray() methods


__all__ = [
    "FOLDER_READERS",
    "FORMATS",
    "PATTERN_READERS",
    "READERS",
    "describe",
    "format_description",
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
