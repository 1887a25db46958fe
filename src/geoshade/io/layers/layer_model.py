"""Layer models (netCDF or zarr): per layer a top and a bottom surface on one x–y grid, as
national surveys and groundwater models ship them, read as a stack model (one material per
layer).

Two layouts are read, with the names used in practice (any case):

- **REGIS / survey style**: ``top(layer, y, x)`` and ``bottom(layer, y, x)`` (also ``bot``,
  ``botm``, ``base``); layers may leave gaps between them.
- **MODFLOW style**: ``top(y, x)`` (the model's top) and ``botm(layer, y, x)``: layer ``k``
  runs from ``botm[k-1]`` (``top`` for the first) down to ``botm[k]``.

Layers are listed top first. A missing thickness — NaN top or bottom, or top at or below
bottom — leaves no interval in that column (the layer is absent there). Where a layer's top
lies above the bottom of the layer over it, it is cut to that bottom (the upper layer wins;
a warning counts the cells). Heights are z up: a ``positive="down"`` attribute (or a
``standard_name`` of depth) makes them ``−value``. x and y are cell centres (CF), evenly
spaced (a decreasing axis is flipped).

The legend names the layers from the ``layer`` coordinate when it holds names, else from a
variable or attribute of names (``layer_name``, ``layer_names``, ``names``), else ``layer 1``,
``layer 2`` …; codes are ``1..K`` from the top.

:func:`read_layer_model` builds the :class:`~geoshade.models.stacks.StackModel` directly (per
column, bottom up: each present layer from its bottom, air or a gap from its top), heights as
float levels above the model's bottom, so a column's intervals end at the file's heights, not
at whole levels. numpy is the oracle of the tests.
"""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np

from geoshade.errors import GeoshadeError, InputError, require
from geoshade.io.paths import check_memory, one_line
from geoshade.models.stacks import EMPTY, Legend, StackModel

#: names of the top and bottom variables (any case), first found wins
TOP_NAMES = ("top", "tops", "ztop", "z_top", "top_elevation")
BOTTOM_NAMES = ("bottom", "bot", "botm", "bottoms", "base", "zbot", "z_bot", "z_bottom",
                "bottom_elevation")
#: variables or attributes holding the layer names
NAME_KEYS = ("layer_name", "layer_names", "layername", "names", "name", "unit_name",
             "formation")
#: names of the x and y dims
X_DIMS = ("x", "lon", "longitude", "easting", "col", "column", "i")
Y_DIMS = ("y", "lat", "latitude", "northing", "row", "j")
#: netCDF and zarr names a layer model may have
SUFFIXES = (".nc", ".nc4", ".cdf", ".netcdf", ".zarr")


def _open(path):
    xr = require("xarray", "netcdf", "reading layer models")
    p = Path(path)
    if p.suffix.lower() == ".zarr" or p.is_dir():
        with warnings.catch_warnings():   # a store without consolidated metadata is fine
            warnings.filterwarnings("ignore", "Failed to open Zarr store with consolidated")
            return xr.open_zarr(str(p), chunks=None)
    require("netCDF4", "netcdf", "reading layer models")
    return xr.open_dataset(p)


def _find(ds, names) -> str | None:
    low = {str(v).lower(): str(v) for v in ds.data_vars}
    return next((low[n] for n in names if n in low), None)


def _variables(ds) -> tuple[str, str] | None:
    """(top, bottom) variable names of a layer model, or None."""
    top, bottom = _find(ds, TOP_NAMES), _find(ds, BOTTOM_NAMES)
    if top is None or bottom is None:
        return None
    if ds[bottom].ndim != 3 or ds[top].ndim not in (2, 3):
        return None
    return top, bottom


def is_layer_model(path) -> bool:
    """Whether ``path`` is a netCDF file or zarr store holding a layer model (``top`` and
    ``bottom``/``botm`` surfaces per layer); only the metadata is read.

    >>> import tempfile, os, numpy as np, xarray as xr
    >>> f = os.path.join(tempfile.mkdtemp(), "m.nc")
    >>> xr.Dataset({"top": (("layer", "y", "x"), np.zeros((2, 2, 2))),
    ...             "bot": (("layer", "y", "x"), np.zeros((2, 2, 2)))}).to_netcdf(f)
    >>> is_layer_model(f)
    True
    """
    p = Path(path)
    zarr = p.suffix.lower() == ".zarr"
    # only a regular file or a store folder is opened (a FIFO or a device is never read here)
    if p.suffix.lower() not in SUFFIXES or not (p.is_dir() if zarr else p.is_file()):
        return False
    try:
        ds = _open(p)
    except Exception:   # not ours to judge: the other readers say why
        return False
    try:
        return _variables(ds) is not None
    finally:
        ds.close()


def is_voxel_model(path) -> bool:
    """The format table's test of a GeoTOP-like voxel netCDF: anything but a layer model."""
    return not is_layer_model(path)


def _axis(ds, dims, names, what: str, path) -> tuple[str, np.ndarray]:
    """(dim, centre coordinates) of the x or y dim."""
    dim = next((d for d in dims if d.lower() in names), None)
    if dim is None:
        raise InputError(f"{path}: no {what} dimension among {', '.join(dims)}; expected one of "
                         f"{', '.join(names[:3])}")
    n = int(ds.sizes[dim])
    if dim in ds.coords:
        c = np.asarray(ds[dim].values, np.float64)
    else:
        c = np.arange(n, dtype=np.float64)
    if c.size > 1:
        d = np.diff(c)
        if not np.allclose(d, d[0], rtol=1e-6) or d[0] == 0:
            raise InputError(f"{path}: coordinate {dim!r} is not evenly spaced; stacks need "
                             "columns on a regular grid (resample the model first)")
    return dim, c


def _names(ds, layer_dim: str, k: int) -> list[str]:
    if layer_dim in ds.coords and ds[layer_dim].dtype.kind in "OUS":
        return [str(v).strip() for v in ds[layer_dim].values]
    for key in NAME_KEYS:
        for name, var in ds.variables.items():
            if str(name).lower() == key and var.dims == (layer_dim,) and \
                    var.dtype.kind in "OUS":
                return [str(v).strip() for v in var.values]
    for attrs in (ds.attrs,):
        for key in NAME_KEYS:
            v = attrs.get(key)
            if v is None:
                continue
            names = [s.strip() for s in v.split(",")] if isinstance(v, str) else \
                [str(s) for s in np.ravel(v)]
            if len(names) == k:
                return names
    return [f"layer {i + 1}" for i in range(k)]


def _down(var) -> bool:
    return (str(var.attrs.get("positive", "")).lower() == "down"
            or str(var.attrs.get("standard_name", "")).lower().startswith("depth"))


def _crs(ds, var) -> str:
    gm = var.attrs.get("grid_mapping")
    for holder in ([ds[gm]] if gm in ds.variables else []) + [ds]:
        for key in ("epsg_code", "epsg", "crs", "crs_wkt", "spatial_ref"):
            v = holder.attrs.get(key)
            if v is None or str(v) == "":
                continue
            s = str(v)
            if s.isdigit():
                return f"EPSG:{s}"
            return s
    return ""


def layer_intervals(top: np.ndarray, bottom: np.ndarray, z0: float, dz: float):
    """Stack intervals of a layer model: ``(offsets, starts, codes, cut cells)``.

    ``top``, ``bottom``: ``(K, ncols)`` heights (NaN: layer absent), layers top first. Layer
    ``k`` is code ``k + 1``; a gap under a layer and the air over the top one are
    :data:`EMPTY`. A top above the bottom of the nearest present layer over it is cut to it.

    >>> t = np.array([[10.0, 5.0], [8.0, np.nan], [4.0, 3.0]])
    >>> b = np.array([[8.0, 5.0], [6.0, np.nan], [0.0, 0.0]])
    >>> off, st, co, cut = layer_intervals(t, b, 0.0, 1.0)
    >>> off.tolist(), st.tolist(), co.tolist(), cut
    ([0, 5, 7], [0.0, 4.0, 6.0, 8.0, 10.0, 0.0, 3.0], [3, -1, 2, 1, -1, 3, -1], 0)
    """
    k, ncols = top.shape
    t = ((top - z0) / dz).astype(np.float32)
    b = ((bottom - z0) / dz).astype(np.float32)
    ceiling = np.full(ncols, np.inf, np.float32)
    present = np.zeros((k, ncols), bool)
    cut = 0
    for i in range(k):   # K layers (tens to a few hundred): columns vectorised
        ok = np.isfinite(t[i]) & np.isfinite(b[i])
        over = ok & (t[i] > ceiling)
        cut += int(over.sum())
        ti = np.where(over, ceiling, t[i])
        bi = np.minimum(b[i], ti)
        p = ok & (ti > bi)
        t[i], b[i] = ti, bi
        present[i] = p
        ceiling = np.where(p, bi, ceiling)
    layer, col = np.nonzero(present)
    cols = np.concatenate([col, col])
    starts = np.concatenate([b[layer, col], t[layer, col]])
    codes = np.concatenate([layer + 1, np.full(layer.size, EMPTY)]).astype(np.int32)
    order = np.lexsort((codes == EMPTY, starts, cols))
    cols, starts, codes = cols[order], starts[order], codes[order]
    same = np.zeros(cols.size, bool)
    same[1:] = (cols[1:] == cols[:-1]) & (starts[1:] == starts[:-1])
    keep = ~(same & (codes == EMPTY))        # a layer's top on the next one's bottom: no gap
    cols, starts, codes = cols[keep], starts[keep], codes[keep]
    counts = np.bincount(cols, minlength=ncols)
    offsets = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
    return offsets, starts.astype(np.float32), codes, cut


def read_layer_model(path, dz: float | None = None) -> StackModel:
    """Read a layer model (``top``/``bottom`` per layer, or MODFLOW ``top`` + ``botm``) as
    a stack model.

    Parameters
    ----------
    path : path
        A netCDF file or a zarr store.
    dz : float, optional
        Height of one level (default 1 in the model's unit, 0.01 of it when the model is
        less than 10 units thick); intervals start at the file's heights whatever ``dz``.

    Returns
    -------
    StackModel
        One material per layer (codes 1..K from the top, legend from the layer names),
        ``meta``: ``format`` "layer-model", ``layers``, ``layout`` (``top/bottom`` or
        ``top + botm``), ``absent`` (layer cells without thickness), ``cut_cells``,
        ``terrain`` True (a smooth top), ``notes``.

    Raises
    ------
    InputError
        No top and bottom variables, bottoms without a layer dim, uneven x or y, no layer
        with a thickness anywhere.

    Examples
    --------
    >>> import tempfile, os, numpy as np, xarray as xr
    >>> f = os.path.join(tempfile.mkdtemp(), "m.nc")
    >>> xr.Dataset({"top": (("y", "x"), np.full((2, 3), 10.0)),
    ...             "botm": (("layer", "y", "x"), np.stack([np.full((2, 3), 4.0),
    ...                                                      np.full((2, 3), 0.0)]))},
    ...            coords={"x": [5.0, 15.0, 25.0], "y": [5.0, 15.0]}).to_netcdf(f)
    >>> m = read_layer_model(f)
    >>> m.shape, m.legend.names, m.meta["layout"], m.origin
    ((3, 2), ('layer 1', 'layer 2'), 'top + botm', (0.0, 0.0, 0.0))
    """
    try:
        ds = _open(path)
    except GeoshadeError:
        raise
    except Exception as exc:
        raise InputError(f"{path}: not a readable netCDF file or zarr store "
                         f"({one_line(exc)})") from None
    try:
        return _read(ds, path, dz)
    except (GeoshadeError, MemoryError):
        raise
    except Exception as exc:   # netCDF4/HDF5 errors of a damaged file
        raise InputError(f"{path}: cannot be read, the file is damaged or truncated "
                         f"({one_line(exc)})") from None
    finally:
        ds.close()


def _read(ds, path, dz) -> StackModel:
    found = _variables(ds)
    if found is None:
        raise InputError(f"{path}: no layer model: expected a top variable ({TOP_NAMES[0]}) "
                         f"and bottoms per layer ({', '.join(BOTTOM_NAMES[:3])}); it holds "
                         f"{', '.join(map(str, ds.data_vars)) or 'no variables'}")
    top_name, bot_name = found
    bot = ds[bot_name]
    dims = tuple(str(d) for d in bot.dims)
    xdim, xs = _axis(ds, dims, X_DIMS, "x", path)
    ydim, ys = _axis(ds, dims, Y_DIMS, "y", path)
    layer_dim = next(d for d in dims if d not in (xdim, ydim))
    k, ny, nx = int(ds.sizes[layer_dim]), ys.size, xs.size
    check_memory(k * ny * nx * 8 * 4, path, f"a layer model of {k} layers × {nx}×{ny} cells")
    bottom = np.asarray(bot.transpose(layer_dim, ydim, xdim).values, np.float64)
    tvar = ds[top_name]
    if tvar.ndim == 3:
        top = np.asarray(tvar.transpose(layer_dim, ydim, xdim).values, np.float64)
        layout = "top/bottom"
    else:
        first = np.asarray(tvar.transpose(ydim, xdim).values, np.float64)
        top = np.concatenate([first[None], bottom[:-1]])
        layout = "top + botm"
    notes = []
    if _down(bot) or _down(tvar):
        top, bottom = -top, -bottom
        notes.append("depths (positive down), drawn as height = −depth")
    if xs.size > 1 and xs[1] < xs[0]:
        xs, top, bottom = xs[::-1], top[:, :, ::-1], bottom[:, :, ::-1]
    if ys.size > 1 and ys[1] < ys[0]:
        ys, top, bottom = ys[::-1], top[:, ::-1], bottom[:, ::-1]
    dx = float(xs[1] - xs[0]) if xs.size > 1 else 1.0
    dy = float(ys[1] - ys[0]) if ys.size > 1 else dx
    finite = np.isfinite(top) & np.isfinite(bottom) & (top > bottom)
    if not finite.any():
        raise InputError(f"{path}: no layer has a thickness anywhere (every top is NaN or at "
                         "or below its bottom)")
    lo, hi = float(bottom[finite].min()), float(top[finite].max())
    if dz is None:
        dz = 1.0 if hi - lo >= 10 else 0.01
    if not (isinstance(dz, int | float) and math.isfinite(dz) and dz > 0):
        raise InputError(f"dz: expected a level height > 0, got {dz!r}")
    z0 = math.floor(lo / dz) * dz
    offsets, starts, codes, cut = layer_intervals(top.reshape(k, -1), bottom.reshape(k, -1),
                                                  z0, dz)
    if cut:
        warnings.warn(f"{path}: {cut} layer cells whose top lies above the bottom of the layer "
                      "over them were cut to it (the upper layer wins)", stacklevel=3)
    names = _names(ds, layer_dim, k)
    units = str(bot.attrs.get("units", "") or tvar.attrs.get("units", "")).strip()
    unit = {"m": "m", "metre": "m", "meter": "m", "metres": "m", "meters": "m",
            "ft": "ft", "feet": "ft"}.get(units.lower(), units)
    if not unit:
        unit = "m (assumed)"
        notes.append("no length unit in the file, metres assumed")
    legend = Legend(np.arange(1, k + 1, dtype=np.int32),
                    tuple(f"{n}" for n in names), Legend.from_codes(np.arange(1, k + 1)).rgba)
    nlevels = math.floor((hi - z0) / dz) + 1
    absent = int(k * ny * nx - finite.sum())
    meta = {"format": "layer-model", "source": str(path), "variable": "layer",
            "layers": names, "layout": layout, "top_variable": top_name,
            "bottom_variable": bot_name, "absent": absent, "cut_cells": cut,
            "terrain": True, "color_by": "material", "base": float(z0), "dz": float(dz),
            "surfaces": names, "nodata_columns": int((np.diff(offsets) == 0).sum()),
            "notes": [f"{Path(path).name}: {n}" for n in notes]}
    return StackModel(offsets, starts, codes, (nx, ny), nlevels, legend,
                      origin=(float(xs[0]) - dx / 2, float(ys[0]) - dy / 2, float(z0)),
                      spacing=(dx, dy, float(dz)), crs=_crs(ds, bot), unit=unit,
                      name=Path(path).name, meta=meta)


__all__ = ["is_layer_model", "is_voxel_model", "layer_intervals", "read_layer_model"]
