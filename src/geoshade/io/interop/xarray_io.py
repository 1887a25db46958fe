"""geoshade models ⇄ xarray (the ``netcdf`` extra): labelled arrays with coordinates and units.

=======================  =============================================  ===========================
model                    xarray                                         coordinates
=======================  =============================================  ===========================
``VoxelVolume``          ``DataArray`` dims ``(z, y, x)``               voxel *centres* (CF), in
                                                                        the volume's unit
``FieldSeries`` regular  ``DataArray`` dims ``(time, z, y, x)``         *nodes* (where the values
                                                                        are sampled)
``FieldSeries`` on a     ``DataArray`` dims ``(time, k, j, i)``         cell indices i, j, k
corner-point grid                                                       (0-based)
``CornerPointGrid``      ``Dataset``: ``COORD``, ``ZCORN``,             i, j, k; ``time`` (report
                         ``ACTNUM``, every property ``(k, j, i)``,      dates), ``step``,
                         every report keyword ``(time, k, j, i)``       ``report``
=======================  =============================================  ===========================

Every array is the model's own memory seen in C order, slowest axis first (a grid's F-order
``[i, j, k]`` arrays as ``(k, j, i)``): nothing is copied, and report steps and lazy fields stay
lazy (dask). ``time`` holds ``datetime64`` dates where every step has an ISO date, else the
step labels. Units go in ``attrs["units"]``: the values' on the array, the length unit on the
x, y, z coordinates; ``attrs["geoshade_model"]`` names the model, so :func:`from_xarray` gives
it back. A DataArray from elsewhere converts too: x, y, z dimensions (any order, regular
coordinates, ascending or descending, as a GeoTOP netCDF) give a volume (3D, coordinates are
cell centres) or a field (with a time dimension, coordinates are nodes); i, j, k dimensions
with ``grid=`` give a field on that grid.

Examples
--------
>>> import numpy as np
>>> from geoshade.models import VoxelVolume
>>> vol = VoxelVolume(np.zeros((2, 3, 4), np.float32), spacing=(10, 10, 0.5),
...                   origin=(1000, 2000, -5), unit="m")
>>> da = to_xarray(vol)
>>> da.dims, da.x.values.tolist(), da.z.attrs["units"]
(('z', 'y', 'x'), [1005.0, 1015.0, 1025.0, 1035.0], 'm')
>>> back = from_xarray(da)
>>> back.origin, back.spacing
((1000.0, 2000.0, -5.0), (10.0, 10.0, 0.5))
"""

from __future__ import annotations

import re
from typing import Any

import numpy as np

from geoshade.errors import InputError, require
from geoshade.models import CornerPointGrid, FieldSeries, VoxelVolume
from geoshade.models.names import step_names
from geoshade.models.units import value_unit

_DATE = re.compile(r"^\d{4}-\d{2}-\d{2}$")
_AXES = {"x": "X", "y": "Y", "z": "Z"}


def _xr():
    return require("xarray", "netcdf", "converting to or from xarray")


def _lazy_steps(get, n: int, shape, dtype):
    """(n, *shape) dask array whose step k is ``get(k)`` (read when computed)."""
    import dask
    import dask.array as da

    return da.stack([da.from_delayed(dask.delayed(get)(k), shape, dtype) for k in range(n)])


def _time_coords(labels, reports=()) -> dict:
    labels = [str(t) for t in labels]
    out: dict = {}
    if labels and all(_DATE.match(t) for t in labels):
        out["time"] = ("time", np.array(labels, "datetime64[ns]"))
    else:
        out["time"] = ("time", np.array(labels, dtype=object))
    out["step"] = ("time", np.arange(len(labels)))
    if reports and len(reports) == len(labels):
        out["report"] = ("time", np.asarray(reports, np.int64))
    return out


def _time_labels(da) -> list[str]:
    if "time" not in da.coords:
        return [f"step {k}" for k in range(da.sizes["time"])]
    t = np.asarray(da["time"].values)
    if np.issubdtype(t.dtype, np.datetime64):
        return [str(v) for v in np.datetime_as_string(t, unit="D")]
    return [str(v) for v in t]


def _axis_coord(origin: float, step: float, n: int, unit: str, axis: str, centred: bool):
    pos = origin + (np.arange(n) + (0.5 if centred else 0.0)) * step
    return (axis, pos, {"units": unit, "axis": _AXES[axis]} if unit else {"axis": _AXES[axis]})


# ==============================================================================================
# to xarray
# ==============================================================================================
def to_xarray(model, name: str | None = None, units: dict | None = None):
    """A geoshade model as an xarray ``DataArray`` (volumes, fields) or ``Dataset`` (grids).

    Parameters
    ----------
    model : VoxelVolume, FieldSeries or CornerPointGrid
    name : str, optional
        A grid: the one property or report keyword to return as a DataArray (default: the
        whole grid as a Dataset). A volume or field: the DataArray's name (default its own).
    units : dict, optional
        A grid: property name -> unit, for ``attrs["units"]``, over the grid's own ECLIPSE
        keyword units (:func:`geoshade.models.units.value_unit`).

    Returns
    -------
    xarray.DataArray or xarray.Dataset

    Examples
    --------
    >>> from geoshade.compute.grid.synthetic import synthetic_grid
    >>> ds = to_xarray(synthetic_grid(4, 3, 2))
    >>> ds["PORO"].dims, ds["SWAT"].dims, ds.sizes["time"]
    (('k', 'j', 'i'), ('time', 'k', 'j', 'i'), 4)
    """
    if isinstance(model, VoxelVolume):
        return volume_to_xarray(model, name)
    if isinstance(model, FieldSeries):
        return field_to_xarray(model, name)
    if isinstance(model, CornerPointGrid):
        ds = grid_to_xarray(model, units)
        if name is None:
            return ds
        found = [v for v in ds.data_vars if str(v).upper() == str(name).upper()]
        if not found:
            raise InputError(f"{model.name or 'grid'}: no property {name!r}; it has "
                             f"{', '.join(map(str, ds.data_vars))}")
        return ds[found[0]]
    raise InputError(f"to_xarray: cannot convert a {type(model).__name__}; expected a "
                     "VoxelVolume, FieldSeries or CornerPointGrid")


def volume_to_xarray(volume: VoxelVolume, name: str | None = None):
    """A volume as a ``DataArray`` ``(z, y, x)`` with voxel-centre coordinates.

    The data is the volume's own array (numpy, memmap or dask: not read, not copied).

    Examples
    --------
    >>> v = VoxelVolume(np.arange(8, dtype=np.uint8).reshape(2, 2, 2), unit="um")
    >>> volume_to_xarray(v, "CT").y.values.tolist()
    [0.5, 1.5]
    """
    xr = _xr()
    nx, ny, nz = volume.shape_xyz
    (ox, oy, oz), (dx, dy, dz) = volume.origin, volume.spacing
    coords = {"z": _axis_coord(oz, dz, nz, volume.unit, "z", True),
              "y": _axis_coord(oy, dy, ny, volume.unit, "y", True),
              "x": _axis_coord(ox, dx, nx, volume.unit, "x", True)}
    attrs = {"geoshade_model": "VoxelVolume", "spacing": [dx, dy, dz],
             "source": volume.name}
    for key in ("crs", "units"):
        if volume.meta.get(key):
            attrs[key] = str(volume.meta[key])
    label = name or volume.meta.get("variable") or "values"
    return xr.DataArray(volume.data, dims=("z", "y", "x"), coords=coords, name=str(label),
                        attrs=attrs)


def _field_values(field: FieldSeries):
    v = field.values
    if (isinstance(v, np.ndarray) or hasattr(v, "dask")) and len(v.shape) == 4:
        return v  # one 4D numpy, memmap or dask array: as it is
    return _lazy_steps(field.step, field.nsteps, field.shape, np.float32)


def field_to_xarray(field: FieldSeries, name: str | None = None):
    """A field over time as a ``DataArray``: ``(time, z, y, x)`` with node coordinates on a
    regular grid, ``(time, k, j, i)`` with cell indices on a corner-point grid.

    Steps read lazily stay lazy (a dask array reading one step when computed).

    Examples
    --------
    >>> f = FieldSeries(np.zeros((2, 2, 3, 4)), spacing=(2, 2, 1), name="SWAT",
    ...                 times=["2001-01-01", "2002-01-01"])
    >>> da = field_to_xarray(f)
    >>> da.dims, da.x.values.tolist(), str(da.time.values[1])[:10]
    (('time', 'z', 'y', 'x'), [0.0, 2.0, 4.0, 6.0], '2002-01-01')
    """
    xr = _xr()
    nz, ny, nx = field.shape
    reports = field.grid.meta.get("unrst_seqnum") or () if field.grid is not None else ()
    coords = _time_coords(field.times, reports)
    if field.grid is None:
        (ox, oy, oz), (dx, dy, dz) = field.origin, field.spacing
        unit = field.length_unit
        coords.update(z=_axis_coord(oz, dz, nz, unit, "z", False),
                      y=_axis_coord(oy, dy, ny, unit, "y", False),
                      x=_axis_coord(ox, dx, nx, unit, "x", False))
        if field.is_rectilinear:   # the nodes' own uneven coordinates
            for axis, values in zip("xyz", field.axes(), strict=True):
                coords[axis] = (axis, values, coords[axis][2])
        dims = ("time", "z", "y", "x")
    else:
        coords.update(k=np.arange(nz), j=np.arange(ny), i=np.arange(nx))
        dims = ("time", "k", "j", "i")
    attrs: dict[str, Any] = {"geoshade_model": "FieldSeries", "source": field.source}
    if field.unit:
        attrs["units"] = field.unit
    if field.grid is None and not field.is_rectilinear:
        attrs["spacing"] = list(field.spacing)
    da = xr.DataArray(_field_values(field), dims=dims, coords=coords,
                      name=str(name or field.name or "values"), attrs=attrs)
    if field.active is not None and field.grid is None:
        da.coords["active"] = (dims[1:], np.asarray(field.active))
    return da


def grid_to_xarray(grid: CornerPointGrid, units: dict | None = None):
    """A corner-point grid as a ``Dataset``: geometry, ACTNUM, properties and report keywords.

    ``COORD`` ``(coord, pillar_j, pillar_i)``, ``ZCORN`` ``(corner_k, corner_j, corner_i)``,
    ``ACTNUM`` and each property ``(k, j, i)``, each report keyword ``(time, k, j, i)`` (lazy:
    a step is read when computed). Every array is the grid's own F-order array seen
    transposed (no copy), so ``Dataset.to_netcdf`` writes the grid in the file's order.

    Examples
    --------
    >>> from geoshade.compute.grid.synthetic import synthetic_grid
    >>> ds = grid_to_xarray(synthetic_grid(4, 3, 2))
    >>> ds["PERMX"].attrs["units"], ds["SWAT"].attrs["units"]
    ('mD', 'fraction')
    >>> ds["ZCORN"].shape, ds["ACTNUM"].dtype.name, str(ds.time.values[0])[:4]
    ((4, 6, 8), 'uint8', '2000')
    """
    xr = _xr()
    nx, ny, nz = grid.dims
    own = {n: value_unit(grid, n) for n in [*grid.properties, *step_names(grid)]}
    units = {str(k).upper(): v for k, v in {**own, **(units or {})}.items()}
    data: dict[str, Any] = {
        "COORD": (("coord", "pillar_j", "pillar_i"), np.asarray(grid.coord).T),
        "ZCORN": (("corner_k", "corner_j", "corner_i"), np.asarray(grid.zcorn).T),
        "ACTNUM": (("k", "j", "i"), np.asarray(grid.actnum).T)}
    coords: dict = {"k": np.arange(nz), "j": np.arange(ny), "i": np.arange(nx)}
    for name, arr in grid.properties.items():
        data[str(name)] = (("k", "j", "i"), arr.T)
    if grid.steps:
        dates = list(grid.step_dates) + [""] * (len(grid.steps) - len(grid.step_dates))
        labels = [d if d else f"step {k}" for k, d in enumerate(dates)]
        coords.update(_time_coords(labels, grid.meta.get("unrst_seqnum") or ()))
        for name in step_names(grid):
            a0 = grid.steps[0][name]

            def get(k, name=name):
                return np.asarray(grid.steps[k][name]).T

            data[str(name)] = (("time", "k", "j", "i"),
                               _lazy_steps(get, len(grid.steps), (nz, ny, nx), a0.dtype))
    ds = xr.Dataset(data, coords=coords,
                    attrs={"geoshade_model": "CornerPointGrid", "length_unit": grid.units,
                           "source": grid.name,
                           **({"mapaxes": [float(v) for v in grid.mapaxes]}
                              if grid.mapaxes is not None else {})})
    for name in ds.data_vars:
        if str(name).upper() in units and units[str(name).upper()]:
            ds[name].attrs["units"] = units[str(name).upper()]
    ds["COORD"].attrs["units"] = ds["ZCORN"].attrs["units"] = grid.units
    return ds


# ==============================================================================================
# from xarray
# ==============================================================================================
def _regular(da, dim: str, where: str) -> tuple[np.ndarray, float]:
    n = da.sizes[dim]
    if dim not in da.coords:
        return np.arange(n, dtype=np.float64), 1.0
    v = np.asarray(da[dim].values, np.float64)
    if v.size == 1:
        sp = da.attrs.get("spacing")
        return v, float(sp["xyz".index(dim)]) if sp is not None else 1.0
    d = np.diff(v)
    if d[0] == 0 or not np.allclose(d, d[0], rtol=1e-6, atol=0):
        raise InputError(f"{where}coordinate {dim!r} is not regularly spaced; a volume needs "
                         "a regular grid")
    return v, float(d[0])


def from_xarray(obj, grid: CornerPointGrid | None = None, name: str | None = None):
    """The geoshade model of an xarray ``DataArray`` or ``Dataset``.

    Parameters
    ----------
    obj : xarray.DataArray or xarray.Dataset
        A DataArray with dims x, y, z (a volume; coordinates are voxel centres) or time, x, y,
        z (a field; coordinates are nodes), any order; with dims (time,) k, j, i and ``grid``:
        a field on that grid. A Dataset with COORD and ZCORN: a corner-point grid; another
        Dataset: its variable ``name`` (or its only variable).
    grid : CornerPointGrid, optional
        The grid of a field given by cell indices.
    name : str, optional
        The variable of a Dataset.

    Returns
    -------
    VoxelVolume, FieldSeries or CornerPointGrid
        Sharing the xarray object's memory (a descending axis is flipped: a view).

    Raises
    ------
    InputError
        Dimensions that are none of these, irregular coordinates, a grid of another size.

    Examples
    --------
    >>> import xarray as xr
    >>> da = xr.DataArray(np.zeros((3, 2, 2), np.float32), dims=("x", "y", "z"),
    ...                   coords={"x": [25., 15., 5.], "y": [0.25, 0.75], "z": [-1., 1.]})
    >>> v = from_xarray(da)
    >>> v.shape_xyz, v.origin, v.spacing
    ((3, 2, 2), (0.0, 0.0, -2.0), (10.0, 0.5, 2.0))
    """
    xr = _xr()
    if isinstance(obj, xr.Dataset):
        if "COORD" in obj.data_vars and "ZCORN" in obj.data_vars:
            return grid_from_xarray(obj)
        names = [str(v) for v in obj.data_vars]
        if name is None and len(names) != 1:
            raise InputError(f"from_xarray: the Dataset has {len(names)} variables "
                             f"({', '.join(names)}); name one")
        key = names[0] if name is None else name
        if key not in obj.data_vars:
            raise InputError(f"from_xarray: no variable {key!r}; the Dataset has "
                             f"{', '.join(names)}")
        obj = obj[key]
    if not isinstance(obj, xr.DataArray):
        raise InputError(f"from_xarray: expected an xarray DataArray or Dataset, got "
                         f"{type(obj).__name__}")
    dims = set(map(str, obj.dims))
    where = f"{obj.name}: " if obj.name is not None else ""
    if dims in ({"x", "y", "z"}, {"time", "x", "y", "z"}):
        return _regular_from_xarray(obj, where)
    if dims in ({"i", "j", "k"}, {"time", "i", "j", "k"}):
        if grid is None:
            raise InputError(f"{where}dims i, j, k are cells of a corner-point grid; pass "
                             "grid=")
        da = obj if "time" in dims else obj.expand_dims("time")
        da = da.transpose("time", "k", "j", "i")
        return FieldSeries(da.data, grid=grid, name=str(obj.name or ""),
                           unit=str(obj.attrs.get("units", "")), times=_time_labels(da),
                           length_unit=grid.units, source=str(obj.attrs.get("source", "")))
    raise InputError(f"{where}dims {tuple(map(str, obj.dims))}: expected x, y, z (a volume), "
                     "time, x, y, z (a field) or (time,) k, j, i with grid= (a field on a "
                     "corner-point grid)")


def _regular_from_xarray(obj, where: str):
    field = "time" in obj.dims
    order = ("time", "z", "y", "x") if field else ("z", "y", "x")
    da = obj.transpose(*order)
    axes = {d: _regular(da, d, where) for d in ("x", "y", "z")}
    data = da.data
    flip = tuple(order.index(d) for d, (_, s) in axes.items() if s < 0)
    if flip:
        data = data[tuple(slice(None, None, -1) if a in flip else slice(None)
                          for a in range(len(order)))]
    sp = tuple(abs(axes[d][1]) for d in ("x", "y", "z"))
    lo = tuple(float(axes[d][0].min()) for d in ("x", "y", "z"))
    unit = next((str(da[d].attrs["units"]) for d in ("x", "y", "z")
                 if d in da.coords and da[d].attrs.get("units")), "")
    source = str(da.attrs.get("source", ""))
    if field:
        active = None
        if "active" in da.coords:
            active = np.asarray(da.coords["active"].transpose("z", "y", "x").values)
            if flip:
                active = active[tuple(slice(None, None, -1) if a + 1 in flip else slice(None)
                                      for a in range(3))]
        return FieldSeries(data, spacing=sp, origin=lo, active=active,  # type: ignore[arg-type]
                           name=str(da.name or ""), unit=str(da.attrs.get("units", "")),
                           length_unit=unit, times=_time_labels(da), source=source)
    origin = tuple(lo[q] - sp[q] / 2 for q in range(3))
    meta = {"format": "xarray", "variable": str(da.name or "values")}
    for key in ("crs", "units"):
        if da.attrs.get(key):
            meta[key] = str(da.attrs[key])
    return VoxelVolume(data, spacing=sp, origin=origin, unit=unit,  # type: ignore[arg-type]
                       name=source or str(da.name or ""), meta=meta)


def grid_from_xarray(ds) -> CornerPointGrid:
    """The :class:`CornerPointGrid` of a Dataset made by :func:`grid_to_xarray` (or read back
    from its netCDF): geometry, ACTNUM, properties, report keywords and dates.

    Examples
    --------
    >>> from geoshade.compute.grid.synthetic import synthetic_grid
    >>> g = synthetic_grid(4, 3, 2)
    >>> back = grid_from_xarray(grid_to_xarray(g))
    >>> bool(np.array_equal(back.zcorn, g.zcorn)), len(back.steps), back.step_dates == \
g.step_dates
    (True, 4, True)
    """
    need = {"COORD": ("coord", "pillar_j", "pillar_i"),
            "ZCORN": ("corner_k", "corner_j", "corner_i")}
    for key, dims in need.items():
        if tuple(map(str, ds[key].dims)) != dims:
            raise InputError(f"from_xarray: {key} has dims {ds[key].dims}; expected {dims}")
    coord = np.asarray(ds["COORD"].values).T
    zcorn = np.asarray(ds["ZCORN"].values).T
    props, dynamic = {}, {}
    for name in ds.data_vars:
        var = ds[name]
        if name in need:
            continue
        if set(map(str, var.dims)) == {"i", "j", "k"}:
            props[str(name)] = np.asarray(var.transpose("k", "j", "i").values).T
        elif set(map(str, var.dims)) == {"time", "i", "j", "k"}:
            dynamic[str(name)] = var.transpose("time", "k", "j", "i")
    actnum = props.pop("ACTNUM", None)
    steps, dates = [], []
    if dynamic:
        first = next(iter(dynamic.values()))
        labels = _time_labels(first)
        dates = [t if _DATE.match(t) else "" for t in labels]
        steps = [{n: np.asarray(v.isel(time=k).values).T for n, v in dynamic.items()}
                 for k in range(first.sizes["time"])]
    meta: dict[str, Any] = {"format": "xarray"}
    if "report" in ds.coords:
        meta["unrst_seqnum"] = [int(r) for r in ds["report"].values]
    mapaxes = ds.attrs.get("mapaxes")
    return CornerPointGrid(coord, zcorn, actnum=actnum, properties=props, steps=steps,
                           step_dates=dates, mapaxes=None if mapaxes is None
                           else np.asarray(mapaxes, float), units=str(ds.attrs.get(
                               "length_unit", "")), name=str(ds.attrs.get("source", "")),
                           meta=meta)


__all__ = ["field_to_xarray", "from_xarray", "grid_from_xarray", "grid_to_xarray",
           "to_xarray", "volume_to_xarray"]
