"""A field's own axes in a netCDF file or an xarray zarr store: which dimension is x, y, z or
time, and where the nodes lie.

:func:`read_dataset` turns one variable of an ``xarray.Dataset`` into a
:class:`~geoshade.models.FieldSeries` placed by the file's own coordinates:

- **Roles.** A dimension is *time* only when the file says so: its name (``time``, ``t``,
  ``step`` …), CF ``axis="T"`` or ``standard_name="time"``, units ``"<unit> since <date>"`` or
  dates as values. x, y and z come from CF ``axis``, ``standard_name``, ``positive`` and units
  (``degrees_east``), then from names (``x``/``lon``/``easting``, ``y``/``lat``/``northing``,
  ``z``/``depth``/``layer``/``level``); three dimensions nothing names are z, y, x in the
  order stored. Any other dimension (``percentile``, ``realization``, ``band`` …) is never
  taken as time: one value is chosen with ``VAR[DIM=VALUE]`` (``--keyword
  'kh[percentile=50]'``), and a file that needs it and has none is one line saying so. A
  dimension of one value is dropped.
- **Coordinates.** Along each spatial dimension the coordinate is the variable that says most
  about position: CF attributes, then units of length, then a name of the role; a plain index
  (``0..n-1``, ``1..n`` without units) only when there is nothing else, and then the nodes are
  one unit apart and the note says so. A CF ``bounds`` pair along the dimension gives centres
  where no coordinate does.
- **Up is up.** ``positive="down"`` — or a coordinate named or standard-named ``depth`` without
  ``positive`` — is depth: z = −depth (the note says which). A decreasing coordinate is flipped
  so nodes run in increasing order.
- **Uneven spacing** (layers 2–200 m thick) is kept: the field is a rectilinear one
  (``FieldSeries.coords``) and the isosurface passes through the nodes where they are.
- **Units.** x, y and z in units of length (m, km, ft …) are brought to one unit (metres when
  they differ); longitudes and latitudes in degrees are drawn in metres from the centre
  (equirectangular, said in the notes), so a degree is never drawn as a metre.

Every decision that the file does not state is in ``meta["notes"]``: the picture's subtitle,
the stats JSON and ``repr`` show it.
"""

from __future__ import annotations

import math
import re

import numpy as np

from geoshade.errors import InputError
from geoshade.models.field import FieldSeries

#: dimension names that are time
TIME_NAMES = ("time", "t", "times", "step", "steps", "report_step", "date", "datetime")
#: names of the spatial roles, in the order they are looked for
ROLE_NAMES = {
    "x": ("x", "lon", "longitude", "easting", "east", "i", "col", "column", "xc", "x_coord",
          "nx", "ncol"),
    "y": ("y", "lat", "latitude", "northing", "north", "j", "row", "yc", "y_coord", "ny",
          "nrow"),
    "z": ("z", "depth", "k", "layer", "layers", "lay", "level", "lev", "elevation", "height",
          "altitude", "zc", "z_coord", "nz", "nlay"),
}
#: CF standard names of the spatial roles
STANDARD_NAMES = {
    "x": ("projection_x_coordinate", "longitude", "grid_longitude"),
    "y": ("projection_y_coordinate", "latitude", "grid_latitude"),
    "z": ("depth", "height", "altitude", "height_above_reference_ellipsoid",
          "height_above_mean_sea_level", "depth_below_geoid", "depth_below_sea_floor",
          "height_above_geopotential_datum", "model_level_number"),
}
#: units of length and their size in metres
LENGTH_UNITS = {"m": 1.0, "metre": 1.0, "meter": 1.0, "metres": 1.0, "meters": 1.0,
                "km": 1000.0, "kilometre": 1000.0, "kilometer": 1000.0, "cm": 0.01,
                "mm": 0.001, "ft": 0.3048, "feet": 0.3048, "foot": 0.3048,
                "us_survey_foot": 1200 / 3937, "ftus": 1200 / 3937}
#: metres per degree of latitude (mean Earth radius 6371008.8 m)
METRES_PER_DEGREE = 6371008.8 * math.pi / 180
_DEGREE_UNITS = ("degrees_east", "degree_east", "degrees_e", "degreese", "degrees_north",
                 "degree_north", "degrees_n", "degreesn", "degrees", "degree", "deg")
_SELECT = re.compile(r"^\s*([^\[\]]+?)\s*\[(.*)\]\s*$")


# --- keyword ----------------------------------------------------------------------------------
def parse_keyword(keyword) -> tuple[str | None, dict[str, str]]:
    """``"kh[percentile=50]"`` → ``("kh", {"percentile": "50"})``; a plain name has no choice.

    >>> parse_keyword("kh[percentile=50, realization=3]")
    ('kh', {'percentile': '50', 'realization': '3'})
    >>> parse_keyword("SWAT"), parse_keyword(None)
    (('SWAT', {}), (None, {}))
    """
    if keyword is None:
        return None, {}
    m = _SELECT.match(str(keyword))
    if m is None:
        return str(keyword), {}
    pick: dict[str, str] = {}
    for part in m.group(2).split(","):
        if not part.strip():
            continue
        dim, eq, value = part.partition("=")
        if not eq or not dim.strip() or not value.strip():
            raise InputError(f"keyword {keyword!r}: expected NAME[DIM=VALUE, ...], e.g. "
                             "kh[percentile=50]")
        pick[dim.strip()] = value.strip()
    return m.group(1), pick


# --- roles ------------------------------------------------------------------------------------
def _attr(var, key: str) -> str:
    return str(var.attrs.get(key, "") or "").strip()


def _unit_of(var) -> str:
    return _attr(var, "units").lower().replace(" ", "_")


def _is_time_var(var) -> bool:
    kind = np.asarray(var.values).dtype.kind if var.size else var.dtype.kind
    if kind in "Mm":
        return True
    if kind == "O" and var.size and hasattr(np.ravel(var.values)[0], "calendar"):   # cftime
        return True
    units = _attr(var, "units").lower()
    return (_attr(var, "axis").upper() == "T" or _attr(var, "standard_name").lower() == "time"
            or " since " in units)


def _candidates(ds, dim: str) -> list:
    """The 1D variables along ``dim`` (its coordinate first), and CF bounds pairs."""
    out = []
    if dim in ds.variables and ds.variables[dim].dims == (dim,):
        out.append((dim, ds.variables[dim]))
    for name, var in ds.variables.items():
        if str(name) != dim and var.dims == (dim,):
            out.append((str(name), var))
    return out


def _role_by_attrs(var) -> str | None:
    axis = _attr(var, "axis").upper()
    if axis in ("X", "Y", "Z"):
        return axis.lower()
    std = _attr(var, "standard_name").lower()
    for role, names in STANDARD_NAMES.items():
        if std in names:
            return role
    if _attr(var, "positive").lower() in ("up", "down"):
        return "z"
    units = _unit_of(var)
    if units in ("degrees_east", "degree_east", "degrees_e", "degreese"):
        return "x"
    if units in ("degrees_north", "degree_north", "degrees_n", "degreesn"):
        return "y"
    return None


def role_by_name(name: str) -> str | None:
    """The spatial role a name gives (``"x"``, ``"y"``, ``"z"``) or None.

    >>> role_by_name("Depth"), role_by_name("lon"), role_by_name("percentile")
    ('z', 'x', None)
    """
    low = name.lower()
    for role, names in ROLE_NAMES.items():
        if low in names:
            return role
    return None


def dim_roles(ds, dims: tuple[str, ...], where: str) -> dict[str, str]:
    """Each dim's role: ``time``, ``x``, ``y``, ``z`` or ``other``.

    >>> import xarray as xr, numpy as np
    >>> ds = xr.Dataset({"kh": (("percentile", "layer", "y", "x"), np.zeros((3, 4, 2, 2)))},
    ...                 coords={"percentile": [10, 50, 75]})
    >>> dim_roles(ds, ("percentile", "layer", "y", "x"), "f.nc")
    {'percentile': 'other', 'layer': 'z', 'y': 'y', 'x': 'x'}
    """
    roles: dict[str, str] = {}
    for dim in dims:
        cands = _candidates(ds, dim)
        if dim.lower() in TIME_NAMES or any(_is_time_var(v) for _, v in cands):
            roles[dim] = "time"
            continue
        role = next((r for _, v in cands if (r := _role_by_attrs(v)) is not None), None)
        if role is None:
            role = role_by_name(dim) or next(
                (r for n, _ in cands if (r := role_by_name(n)) is not None), None)
        roles[dim] = role or "?"
    spatial = [d for d in dims if roles[d] in ("x", "y", "z")]
    for role in ("x", "y", "z"):
        named = [d for d in spatial if roles[d] == role]
        if len(named) > 1:
            raise InputError(f"{where}dims {', '.join(named)} are all {role}; expected one "
                             f"{role} dimension")
    unknown = [d for d in dims if roles[d] == "?"]
    missing = [r for r in ("z", "y", "x") if r not in roles.values()]
    if missing and unknown:   # unnamed dims take the missing roles, stored order (.., z, y, x)
        take = unknown[-len(missing):] if len(unknown) >= len(missing) else unknown
        for d, r in zip(take, missing[-len(take):], strict=True):
            roles[d] = r
    times = [d for d in dims if roles[d] == "time"]
    if len(times) > 1:
        raise InputError(f"{where}dims {', '.join(times)} are all time; expected one time "
                         "dimension")
    return {d: ("other" if r == "?" else r) for d, r in roles.items()}


# --- coordinates ------------------------------------------------------------------------------
def _index_like(values: np.ndarray, var) -> bool:
    n = values.size
    return (not _attr(var, "units") and np.issubdtype(values.dtype, np.integer)
            and (np.array_equal(values, np.arange(n)) or np.array_equal(values,
                                                                         np.arange(1, n + 1))))


def _score(name: str, var, role: str) -> int:
    if _role_by_attrs(var) == role:
        return 4
    units = _unit_of(var)
    if units in LENGTH_UNITS or units in _DEGREE_UNITS:
        return 3
    if role_by_name(name) == role:
        return 2
    return 1


def _bounds_centres(ds, dim: str) -> tuple[str, np.ndarray] | None:
    """Centres of a CF bounds pair ``(dim, 2)`` along ``dim`` (``layer_bnds`` …)."""
    for name, var in ds.variables.items():
        if var.dims[:1] == (dim,) and len(var.dims) == 2 and var.shape[1] == 2 and \
                var.dtype.kind in "fiu":
            return str(name), np.asarray(var.values, np.float64).mean(axis=1)
    return None


def axis_coordinate(ds, dim: str, role: str) -> tuple[str | None, np.ndarray | None, object]:
    """(name, values float64, the variable) of the coordinate that places ``dim``; (None, None,
    None) when the file has only an index."""
    best = None
    for name, var in _candidates(ds, dim):
        if var.dtype.kind not in "fiu":
            continue
        v = np.asarray(var.values)
        if v.ndim != 1 or not np.isfinite(v.astype(np.float64)).all():
            continue
        s = 0 if _index_like(v, var) else _score(name, var, role)
        if best is None or s > best[0]:
            best = (s, name, v.astype(np.float64), var)
    if best is not None and best[0] > 0:
        return best[1], best[2], best[3]
    bounds = _bounds_centres(ds, dim)
    if bounds is not None:
        return bounds[0], bounds[1], ds.variables[bounds[0]]
    return None, None, None


def _down(name: str, var) -> str | None:
    """Why the coordinate is depth (positive down), or None."""
    positive = _attr(var, "positive").lower()
    if positive == "down":
        return 'positive="down"'
    if positive == "up":
        return None
    if _attr(var, "standard_name").lower().startswith("depth"):
        return "standard_name depth"
    if "depth" in name.lower():
        return "its name"
    return None


def _length_factor(units: str) -> float | None:
    return LENGTH_UNITS.get(units)


def _short(v: float) -> str:
    return f"{v:.4g}"


def place_axes(ds, dims: dict[str, str], where: str) -> dict:
    """Positions along the spatial dims: ``{"x": (dim, coords, flip), ...}``, the length unit
    and the notes.

    ``dims`` maps a role to its dim. Coordinates are increasing, z up, in one unit.
    """
    out: dict = {}
    notes: list[str] = []
    units: dict[str, str] = {}
    for role in ("x", "y", "z"):
        dim = dims[role]
        name, c, var = axis_coordinate(ds, dim, role)
        n = int(ds.sizes[dim])
        if c is None:
            c = np.arange(n, dtype=np.float64)
            notes.append(f"{role}: no coordinate for dim {dim!r}; nodes one unit apart "
                         "(assumed)")
            units[role] = ""
        else:
            units[role] = _unit_of(var)
            if role == "z":
                why = _down(name, var)
                if why is not None:
                    c = -c
                    notes.append(f"z = −{name} ({why})")
            if c.size > 1:
                d = np.diff(c)
                if (d == 0).any() or not ((d > 0).all() or (d < 0).all()):
                    raise InputError(f"{where}coordinate {name!r} of dim {dim!r} is not "
                                     "strictly monotonic; expected node coordinates in order")
        flip = bool(c.size > 1 and c[1] < c[0])
        out[role] = [dim, c[::-1] if flip else c, flip, name]
    _units(out, units, notes)
    unit = out.pop("_unit")
    for role in ("x", "y", "z"):
        c = out[role][1]
        if c.size > 2:
            d = np.diff(c)
            if not np.allclose(d, d.mean(), rtol=1e-6):
                notes.append(f"{role} nodes {_short(d.min())}–{_short(d.max())}"
                             f"{' ' + unit if unit else ''} apart, drawn where they are")
    return {"axes": out, "notes": notes, "length_unit": unit}


def _units(out: dict, units: dict, notes: list) -> None:
    """Bring x, y, z to one length unit; degrees of longitude/latitude to metres."""
    deg = [r for r in ("x", "y") if units[r] in _DEGREE_UNITS or
           (out[r][3] or "").lower() in ("lon", "longitude", "lat", "latitude")]
    if len(deg) == 2:
        lon, lat = out["x"][1], out["y"][1]
        lon0, lat0 = float(lon.mean()), float(lat.mean())
        out["x"][1] = (lon - lon0) * METRES_PER_DEGREE * math.cos(math.radians(lat0))
        out["y"][1] = (lat - lat0) * METRES_PER_DEGREE
        notes.append(f"x, y in degrees: drawn in metres from {lon0:.4f}°E {lat0:.4f}°N "
                     "(equirectangular)")
        zf = _length_factor(units["z"])
        if zf is not None and zf != 1.0:
            out["z"][1] = out["z"][1] * zf
            notes.append(f"z from {units['z']} to m")
        out["_unit"] = "m" if zf is not None else ""
        if zf is None:
            notes.append("z has no unit of length; taken as metres (assumed)")
            out["_unit"] = "m"
        return
    factors = {r: _length_factor(units[r]) for r in ("x", "y", "z")}
    known = {r: f for r, f in factors.items() if f is not None}
    if not known:
        out["_unit"] = ""
        return
    if len(set(known.values())) == 1 and len(known) == 3:
        out["_unit"] = _canonical(units["x"])
        return
    for r, f in known.items():
        if f != 1.0:
            out[r][1] = out[r][1] * f
    changed = [r for r, f in known.items() if f != 1.0]
    if changed:
        notes.append(f"{', '.join(changed)} converted to m (units "
                     f"{', '.join(units[r] for r in changed)})")
    unknown = [r for r in ("x", "y", "z") if r not in known]
    if unknown:
        notes.append(f"{', '.join(unknown)} without a unit: taken as metres (assumed)")
    out["_unit"] = "m"


def _canonical(units: str) -> str:
    f = LENGTH_UNITS.get(units)
    return {1.0: "m", 1000.0: "km", 0.3048: "ft"}.get(f, units) if f is not None else units


# --- choosing values of other dims --------------------------------------------------------------
def _choose(ds, var: str, dim: str, value: str, where: str):
    """The index along ``dim`` named by ``value`` (a coordinate value, or an index)."""
    n = int(ds.sizes[dim])
    coord = ds.variables[dim] if dim in ds.variables else None
    if coord is None:
        try:
            k = int(value)
        except ValueError:
            raise InputError(f"{where}{var}[{dim}={value}]: dim {dim!r} has no coordinate; "
                             f"give an index 0..{n - 1}") from None
        if not 0 <= k < n:
            raise InputError(f"{where}{var}[{dim}={value}]: index out of 0..{n - 1}")
        return k
    vals = np.ravel(np.asarray(coord.values))
    if vals.dtype.kind in "fiu":
        text = value[1:] if value[:1].lower() in ("p", "q") and value[1:] else value
        try:
            want = float(text)
        except ValueError:
            want = None
        hits = [] if want is None else np.flatnonzero(np.isclose(vals.astype(float), want))
    else:
        hits = [i for i, v in enumerate(vals) if str(v).strip().lower() == value.lower()]
    if len(hits) != 1:
        raise InputError(f"{where}{var}[{dim}={value}]: no such {dim}; it has "
                         f"{_values_text(vals)}")
    return int(hits[0])


def _values_text(vals, most: int = 12) -> str:
    txt = [f"{v:g}" if isinstance(v, float | np.floating) else str(v) for v in vals[:most]]
    return ", ".join(txt) + (" …" if len(vals) > most else "")


def _refusal(ds, var: str, dim: str, where: str) -> InputError:
    coord = ds.variables[dim] if dim in ds.variables else None
    n = int(ds.sizes[dim])
    vals = np.ravel(np.asarray(coord.values)) if coord is not None else np.arange(n)
    example = _values_text(vals[len(vals) // 2:len(vals) // 2 + 1])
    return InputError(
        f"{where}variable {var!r} has dim {dim!r} ({n} values: {_values_text(vals)}) that is "
        "neither time (a time name, axis T, units 'since' or dates) nor x, y, z; choose one "
        f"with --keyword '{var}[{dim}={example}]' (keyword=)")


def time_labels(ds, dim: str) -> list[str]:
    """One label per step: dates (with the hour when some step has one), else the values."""
    if dim not in ds.variables:
        return []
    v = np.ravel(np.asarray(ds.variables[dim].values))
    if v.dtype.kind == "M":
        day = v.astype("datetime64[D]")
        unit = "D" if (v == day).all() else "m"
        return [str(np.datetime_as_string(t, unit=unit)).replace("T", " ") for t in v]
    units = _attr(ds.variables[dim], "units")
    return [f"{t} {units}".strip() if v.dtype.kind not in "fiu" else
            f"{t:g} {units}".strip() for t in v]


def arrange(ds, var: str, pick: dict[str, str], where: str, roles=None):
    """``ds[var]`` with other dims chosen, in ``(time?, z, y, x)`` order, and its plan."""
    da = ds[var]
    dims = tuple(str(d) for d in da.dims)
    roles = roles or dim_roles(ds, dims, where)
    low = {d.lower(): d for d in dims}
    chosen: dict[str, int] = {}
    for key, value in pick.items():
        dim = low.get(key.lower())
        if dim is None:
            raise InputError(f"{where}{var}[{key}=…]: {var!r} has no dim {key!r}; its dims are "
                             f"{', '.join(dims)}")
        chosen[dim] = _choose(ds, var, dim, value, where)
    for dim in dims:
        if roles.get(dim) == "other" and dim not in chosen:
            if int(ds.sizes[dim]) != 1:
                raise _refusal(ds, var, dim, where)
            chosen[dim] = 0
    if chosen:
        da = da.isel(chosen)
    by_role = {r: d for d, r in roles.items() if d in da.dims}
    space = [by_role.get(r) for r in ("z", "y", "x")]
    if None in space:
        raise InputError(f"{where}variable {var!r} has dims {dims}; expected 3 spatial dims "
                         "(x, y, z) and an optional time dim")
    tdim = by_role.get("time")
    da = da.transpose(*(([tdim] if tdim else []) + space))
    return da, tdim, {d: ds.variables[d].values[i] if d in ds.variables else i
                      for d, i in chosen.items()}, roles


def read_dataset(ds, path, name: str, pick: dict[str, str], color_by: list[str], hints: dict,
                 fmt: str, keyword=None) -> FieldSeries:
    """Variable ``name`` of ``ds`` as a :class:`FieldSeries` placed by the file's coordinates
    (see the module's description); ``color_by`` names more variables on the same nodes.

    Examples
    --------
    >>> import xarray as xr, numpy as np
    >>> ds = xr.Dataset({"kh": (("layer", "y", "x"), np.arange(12.0).reshape(3, 2, 2))},
    ...                 coords={"layer": [1, 2, 3], "x": [0.0, 100.0], "y": [0.0, 100.0],
    ...                         "depth": ("layer", [1.0, 5.0, 200.0], {"positive": "down",
    ...                                                                "units": "m"})})
    >>> f = read_dataset(ds, "f.nc", "kh", {}, [], {}, "netcdf")
    >>> f.axes()[2].tolist(), f.step(0)[:, 0, 0].tolist(), f.length_unit
    ([-200.0, -5.0, -1.0], [8.0, 4.0, 0.0], 'm')
    >>> f.meta["notes"]
    ['z = −depth (positive="down")', 'x, y without a unit: taken as metres (assumed)', \
'z nodes 4–195 m apart, drawn where they are']
    """
    where = f"{path}: "
    da, tdim, chosen, roles = arrange(ds, name, pick, where)
    by_role = {r: d for d, r in roles.items() if r in ("x", "y", "z") and d in da.dims}
    placed = place_axes(ds, by_role, where)
    axes, notes = placed["axes"], list(placed["notes"])
    flips = {axes[r][0]: slice(None, None, -1) for r in ("x", "y", "z") if axes[r][2]}
    if flips:
        da = da.isel(flips)
    for dim, value in chosen.items():
        if int(ds.sizes[dim]) > 1:
            notes.insert(0, f"{dim} = {value}")
    props = {}
    for c in color_by:
        cname, cpick = parse_keyword(c)
        if cname not in ds.data_vars:
            raise InputError(f"{where}variable {cname!r} not found; it holds "
                             f"{', '.join(map(str, ds.data_vars))}")
        own = {d: v for d, v in pick.items() if d in ds[cname].dims}
        pda, _, _, proles = arrange(ds, cname, {**own, **cpick}, where)
        for r in ("x", "y", "z"):
            pdim = next(d for d, rr in proles.items() if rr == r and d in pda.dims)
            if pdim != axes[r][0]:
                raise InputError(f"{where}{cname}: its {r} dim is {pdim!r}, {name}'s is "
                                 f"{axes[r][0]!r}; colour by a variable on the same nodes")
        pflips = {d: s for d, s in flips.items() if d in pda.dims}
        props[c] = pda.isel(pflips) if pflips else pda
    coords = tuple(axes[r][1] for r in ("x", "y", "z"))
    kw: dict = {"coords": coords}
    if "spacing" in hints:   # the user's even spacing wins over the file's coordinates
        kw = {"spacing": hints["spacing"],
              "origin": hints.get("origin", tuple(float(c[0]) for c in coords))}
        notes.append("spacing given: nodes evenly spaced, the file's coordinates not used")
    elif "origin" in hints:
        kw = {"coords": tuple(c - c[0] + o for c, o in zip(coords, hints["origin"],
                                                            strict=True))}
    meta = {"format": fmt, "variable": name, "keyword": keyword or name, "notes": notes,
            "axes": {r: {"dim": axes[r][0], "coordinate": axes[r][3], "flipped": axes[r][2]}
                     for r in ("x", "y", "z")},
            "selected": {d: _plain(v) for d, v in chosen.items()}}
    if tdim is not None:
        meta["time_dim"] = tdim
    return FieldSeries(da.data, name=name, unit=str(da.attrs.get("units", "")),
                       length_unit=placed["length_unit"],
                       times=time_labels(ds, tdim) if tdim else [], properties=props,
                       source=str(path), meta=meta, **kw)


def _plain(v):
    return v.item() if hasattr(v, "item") else v
