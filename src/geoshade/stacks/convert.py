"""Converting voxels (GeoTOP netCDF, labelled volumes, arrays) to stack models, and the
memory a stack model takes (Table 1 of the paper). No GL."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from geoshade.compute.stacks import memory_table, place_boreholes, voxels_to_stacks
from geoshade.compute.voxels.octree import octree_memory, octree_of_stacks
from geoshade.errors import InputError, where
from geoshade.io import formats, load
from geoshade.io.layers.geotop import read_boreholes
from geoshade.io.layers.layer_model import is_layer_model, read_layer_model
from geoshade.models.stacks import BoreholeLogs, StackModel
from geoshade.models.volume import VoxelVolume
from geoshade.stacks.terrain import apply_top, read_surfaces, top_from_dem


def convert(source, variable: str | None = None, empty=None, boreholes="auto",
            strict_boreholes: bool = False, progress=None, *, surfaces=None,
            base: float | None = None, dz: float = 1.0, top=None,
            positive: str | None = None) -> StackModel:
    """A :class:`StackModel` from a file, a labelled volume, an array or a model.

    Parameters
    ----------
    source : path, VoxelVolume, (nz, ny, nx) array, StackModel or None
        ``.nc`` (GeoTOP), ``.npy``/``.npz``/TIFF/zarr labels (z up), ``.stacks.npz`` (returned
        as read); a georeferenced one-band raster (GeoTIFF, Arc ASCII, SRTM, IRAP surface) is a
        DEM: a terrain model (a column per cell from the DEM height down to ``base``; see
        :mod:`geoshade.stacks.terrain`); a layer model (netCDF or zarr with ``top`` and
        ``bottom``/``botm`` per layer) is one material per layer
        (:mod:`geoshade.io.layers.layer_model`).
    surfaces : sequence of paths, optional
        More surfaces under ``source`` (or all of them when ``source`` is None), top to
        bottom: a layered model, one unit per interval between consecutive surfaces.
    base : float, optional
        Bottom of a terrain model (default: the DEM's lowest height minus 10 % of the relief,
        at least ``dz``); with several surfaces, one more unit down to it.
    dz : float
        Level height of a model made from surfaces (1 unit of the DEM's heights).
    positive : {"down", "up"}, optional
        The sign of IRAP surfaces' values, which the file does not state: ``down`` (depths,
        RMS's horizons; the default, said as assumed) or ``up`` (heights). Refused for other
        sources.
    top : path, optional
        A DEM that becomes the top of a voxel model's columns (cut or extended to it), read by
        its georeference on the model's grid.
    variable : str, optional
        netCDF variable (``lithok`` or ``strat``).
    empty : number, optional
        The label meaning empty (NaN always does for float labels).
    boreholes : "auto", path, BoreholeLogs or None
        Borehole logs to place into the model's columns; ``auto`` uses a ``boreholes*.parquet``
        next to a GeoTOP file when there is one.

    Examples
    --------
    >>> import numpy as np, geoshade.stacks as st
    >>> a = np.zeros((6, 3, 4), np.int8); a[:4] = 2; a[:2] = 1
    >>> m = st.convert(a, empty=0)
    >>> m.shape, m.nintervals, m.max_intervals
    ((4, 3), 36, 3)
    """
    if surfaces or (isinstance(source, str | Path) and _is_dem(source)):

        paths = ([source] if source is not None else []) + list(surfaces or [])
        return read_surfaces(paths, base=base, dz=dz, progress=progress, positive=positive)
    if positive is not None:
        raise InputError(f"{source}: --positive (positive=) applies to IRAP surfaces (a DEM "
                         "or --surface), whose values state no sign")
    if isinstance(source, StackModel):
        return source if top is None else _top(source, top)
    logs_path = None
    if isinstance(source, (str, Path)) and is_layer_model(source):   # netCDF or zarr
        model = read_layer_model(source)
        return model if top is None else _top(model, top)
    if isinstance(source, (str, Path)):
        hints: dict = {"variable": variable} if variable else {}
        fmt = formats.find(source)
        if fmt is not None and fmt.name == "geotop":   # uneven layers keep their heights here
            hints["uneven"] = True
        obj = load(source, **hints)
        if isinstance(obj, StackModel):
            return obj if top is None else _top(obj, top)
        source = obj
    if isinstance(source, VoxelVolume):
        meta = source.meta or {}
        legend = meta.get("legend")
        logs_path = meta.get("boreholes")
        data, spacing, origin = source.data, source.spacing, source.origin
        name, crs, unit = source.name, meta.get("crs", ""), source.unit
        variable = meta.get("variable", variable)
    elif not hasattr(source, "dtype"):  # a grid, a field, ...: no labels to convert
        name = getattr(source, "name", "") or ""
        raise InputError(f"{where(name)}stacks: expected a labelled voxel volume (or GeoTOP, a "
                         f"layer model, a DEM or a stack model), got a {type(source).__name__}")
    else:
        data = np.asarray(source)
        legend, spacing, origin, name, crs, unit = None, (1.0, 1.0, 1.0), (0.0,) * 3, "", "", ""

    model = voxels_to_stacks(data, empty=empty, spacing=spacing, origin=origin, legend=legend,
                             crs=crs, unit=unit, name=name, progress=progress)
    if isinstance(source, VoxelVolume) and (source.meta or {}).get("notes"):
        model.meta["notes"] = list(source.meta["notes"])     # depth made z up, ...
    if isinstance(source, VoxelVolume) and (source.meta or {}).get("z_edges") is not None:
        model = on_edges(model, source.meta["z_edges"])
    if model.nintervals == 0 or not (np.asarray(model.codes) != -1).any():
        what = "NaN" if empty is None else f"NaN or {empty}"
        raise InputError(f"{name or 'labels'}: every value is empty ({what}); there is no "
                         "material to convert to stacks (check --variable and --empty)")
    if variable:
        model.meta["variable"] = variable
    if top is not None:
        model = _top(model, top)
    logs = None
    if isinstance(boreholes, BoreholeLogs):
        logs = boreholes
    elif boreholes is not None and boreholes != "auto":
        logs = _read_logs(boreholes, variable, model)
    elif boreholes == "auto" and logs_path:
        logs = _read_logs(logs_path, variable, model)
    if logs is not None:
        model = place_boreholes(model, logs, strict=strict_boreholes)
        model.meta["boreholes_source"] = str(logs.name)
    return model


def on_edges(model: StackModel, edges) -> StackModel:
    """A stack model converted from voxels (level ``k`` = voxel layer ``k``) with its levels
    moved to the layers' true heights ``edges`` (``nz + 1`` increasing): each interval starts
    at its layer's bottom edge, whatever the layers' thicknesses. The level height is the
    thinnest layer's (rounded so that the model's top is a whole number of levels).

    >>> import numpy as np
    >>> m = StackModel([0, 2], [0.0, 2.0], [7, 8], (1, 1), 3)
    >>> e = on_edges(m, [-200.0, -50.0, -10.0, -2.0])
    >>> e.origin[2], e.spacing[2], e.nlevels, (e.origin[2] + e.starts * e.spacing[2]).tolist()
    (-200.0, 7.92, 25, [-200.0, -10.0])
    """
    e = np.asarray(edges, np.float64)
    if e.ndim != 1 or e.size != model.nlevels + 1 or (np.diff(e) <= 0).any():
        raise InputError(f"{model.name or 'model'}: z edges: expected {model.nlevels + 1} "
                         f"increasing heights, got {e.size}")
    total = float(e[-1] - e[0])
    nlevels = math.ceil(total / float(np.diff(e).min()) - 1e-9)
    dz = total / nlevels
    idx = np.rint(np.asarray(model.starts, np.float64)).astype(np.int64)
    starts = ((e[idx] - e[0]) / dz).astype(np.float32)
    meta = {**model.meta, "uneven_layers": [float(v) for v in np.diff(e)[[0, -1]]]}
    unit = f" {model.unit}" if model.unit else ""
    meta["notes"] = [*meta.get("notes", []), f"layers {np.diff(e).min():.4g}–"
                     f"{np.diff(e).max():.4g}{unit} thick, kept at their heights"]
    return StackModel(model.offsets, starts, model.codes, model.shape, nlevels, model.legend,
                      origin=(model.origin[0], model.origin[1], float(e[0])),
                      spacing=(model.spacing[0], model.spacing[1], dz), borehole=model.borehole,
                      crs=model.crs, unit=model.unit, name=model.name, meta=meta,
                      log_base=model.log_base)


def _is_dem(path) -> bool:
    from geoshade.io.layers.dem import is_georeferenced

    return is_georeferenced(path)


def _top(model: StackModel, top) -> StackModel:

    if isinstance(top, str | Path):
        return top_from_dem(model, top)
    return apply_top(model, top)


def _read_logs(path, variable, model: StackModel) -> BoreholeLogs:
    var = variable if variable in ("lithok", "strat") else "lithok"
    return read_boreholes(path, var, model.legend)


def memory_stats(model: StackModel, octree: bool = True, progress=None) -> dict:
    """Table 1 of the paper: bytes of the dense voxels (4 B/voxel), a real octree, the stacks.

    Examples
    --------
    >>> import numpy as np, geoshade.stacks as st
    >>> s = st.memory_stats(st.convert(np.ones((8, 2, 2), np.int8)))
    >>> s["bytes_voxels"], s["bytes_stacks"], s["octree_nodes"]
    (128, 48, 25)
    """
    t = memory_table(model)
    if octree:

        counts = octree_of_stacks(model, progress=progress)
        full = octree_memory(counts)
        six = octree_memory(counts, max_depth=6)
        t.update(bytes_octree=full["bytes"], octree_nodes=full["nodes"],
                 octree_side=full["side"], bytes_octree_6_levels=six["bytes"])
    return t


__all__ = ["convert", "memory_stats", "on_edges"]
