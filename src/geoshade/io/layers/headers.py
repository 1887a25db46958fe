"""What a layered model declares, read from its header alone (the ``header`` functions of the
``stacks`` and ``geotop`` rows of :mod:`geoshade.io.formats`).

- a ``.stacks.npz`` (:mod:`geoshade.io.layers.stackfile`): the columns and levels of its JSON
  header and the interval count of its ``starts`` member's ``.npy`` header (a few hundred bytes
  decompressed; no array);
- a GeoTOP netCDF voxel model: the dims of its class variable (netCDF4 reads metadata only).

>>> import tempfile, os
>>> from geoshade.compute.stacks import synthetic_layers
>>> from geoshade.io.layers.stackfile import write_stacks
>>> p = write_stacks(os.path.join(tempfile.mkdtemp(), "m.stacks.npz"),
...                  synthetic_layers(20, 10, 16, seed=1))
>>> h = stacks_header(p)
>>> h.kind, h.shape, h.intervals == len(__import__("geoshade").load(p).codes)
('stacks', (20, 10), True)
"""

from __future__ import annotations

import json
import os
import zipfile

from geoshade.errors import InputError, require
from geoshade.io.paths import check_file, one_line
from geoshade.io.plan import Header
from geoshade.io.volumes.npy import NPZ_ERRORS, read_header


def stacks_header(path) -> Header | None:
    """A stack model's columns ``(nx, ny)``, levels and intervals (None: not a stack model; the
    reader says why)."""
    p = check_file(path, "a .stacks.npz file")
    try:
        with zipfile.ZipFile(p) as z:
            names = set(z.namelist())
            if "header.npy" not in names or "starts.npy" not in names:
                return None
            with z.open("header.npy") as fh:
                shape, _, _ = read_header(fh, path, "member 'header'")
                if shape[0] > 1 << 20:
                    return None
                head = json.loads(fh.read(shape[0]).decode())
            with z.open("starts.npy") as fh:
                (n,), _, _ = read_header(fh, path, "member 'starts'")
    except (*NPZ_ERRORS, UnicodeDecodeError, RecursionError, ValueError, TypeError) as err:
        raise InputError(f"{path}: not a readable stack model ({one_line(err)})") from None
    try:
        nx, ny = (int(v) for v in head["shape"])
        levels = int(head.get("nlevels", 0))
    except (KeyError, TypeError, ValueError):
        return None
    return Header(str(path), "stacks", "stacks", (nx, ny), file_bytes=os.path.getsize(p),
                  intervals=int(n), levels=((nx, ny, levels),))


def netcdf_header(path, variable=None) -> Header | None:
    """A GeoTOP-like voxel model's dims ``(x, y, z)`` from its class variable (``lithok`` or
    ``strat``, or ``variable``); None where there is no 3D variable."""
    nc = require("netCDF4", "netcdf", "reading netCDF files")
    p = check_file(path, "a netCDF file")
    try:
        with nc.Dataset(p) as ds:
            names = [variable] if variable else ["lithok", "strat",
                                                 *[v for v in ds.variables]]
            var = next((ds.variables[n] for n in names if n in ds.variables
                        and len(ds.variables[n].shape) == 3), None)
            if var is None:
                return None
            dims = dict(zip(var.dimensions, var.shape, strict=True))
            dt = var.dtype.name
    except (OSError, RuntimeError, ValueError, KeyError) as err:
        raise InputError(f"{path}: not a readable netCDF file ({one_line(err)})") from None
    vertical = ("z", "depth", "layer", "level")
    nz = next((v for d, v in dims.items() if d.lower() in vertical), next(iter(dims.values())))
    across = {d.lower(): v for d, v in dims.items() if d.lower() not in vertical}
    nx = across.get("x", list(across.values())[-1] if across else 1)
    ny = across.get("y", next(iter(across.values())) if across else 1)
    return Header(str(path), "geotop", "layers", (int(nx), int(ny), int(nz)), dt,
                  os.path.getsize(p), storage="held")


__all__ = ["netcdf_header", "stacks_header"]
