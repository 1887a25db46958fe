"""Scalar fields over time (:class:`~geoshade.models.FieldSeries`) from files.

``.npy``, ``.npz`` and ``.zarr`` are registered for voxel volumes in :func:`geoshade.io.load`,
so fields have their own entry point, :func:`load_field` (``geoshade iso`` uses it). Formats:

============================  ====================================================================
``.npy``                      one array, ``(nz, ny, nx)`` or ``(time, nz, ny, nx)``; memory-mapped
``.npz``                      several arrays; ``keyword`` picks one (default: the only 3D/4D
                              array, or ``data``/``values``); optional 1D members ``spacing``,
                              ``origin`` (x, y, z) and ``times``
``.zarr`` folder              arrays of a group (or a lone array) as in ``.npz``, read lazily;
                              attributes ``spacing``, ``origin``, ``unit``, ``times``; a store
                              written by xarray (its arrays name their dims) is read as netCDF
``.nc .nc4 .cdf .netcdf``     netCDF through xarray (lazy), placed by the file's own
                              coordinates (:mod:`geoshade.io.field_axes`): x, y, z and time
                              told by CF attributes, units and names; uneven, decreasing and
                              positive-down coordinates drawn where they are (z up); a dim
                              that is not time (``percentile``) chosen with
                              ``VAR[DIM=VALUE]``, never taken as time steps
ECLIPSE / OPM case            ``.EGRID``, ``.UNRST``, ``.INIT``, ``.DATA`` or the case name:
                              corner-point geometry + the restart keyword (default ``SWAT``) of
                              every report step, through :func:`geoshade.io.grids.ecl.load_case`
============================  ====================================================================

A ``.DATA`` deck without its run beside it (no EGRID and INIT of the same case name,
:func:`is_bare_deck`) is not a field over time: read it with :func:`geoshade.io.load` (a
:class:`~geoshade.models.CornerPointGrid` of static properties, as ``grid render`` does) and show
one keyword with ``geoshade.view(grid, as_="iso", keyword=...)`` (``geoshade iso`` does that).

Every reader returns node values in the one layout of :class:`FieldSeries`: each step
``(nz, ny, nx)``, x fastest.
"""

from __future__ import annotations

import dataclasses
import warnings
import zipfile
from pathlib import Path

import numpy as np

from geoshade.errors import InputError, require
from geoshade.io import formats
from geoshade.io.field_axes import parse_keyword, read_dataset, role_by_name
from geoshade.models.field import FieldSeries, GridSteps

#: member/array names tried, in order, when no keyword is given
DEFAULT_NAMES = ("data", "values", "field", "saturation", "SWAT")
#: netCDF suffixes
NETCDF_SUFFIXES = (".nc", ".nc4", ".cdf", ".netcdf")
#: ECLIPSE/OPM output suffixes that name a case
ECLIPSE_SUFFIXES = (".egrid", ".unrst", ".init", ".data", ".smspec", ".unsmry", ".grid")
#: default keyword of an ECLIPSE case
DEFAULT_KEYWORD = "SWAT"
_META = ("spacing", "origin", "times")


def _names(color_by) -> list[str]:
    if color_by is None:
        return []
    if isinstance(color_by, str):
        return [color_by]
    return [str(c) for c in color_by]


def _xyz(v, what: str, path) -> tuple[float, float, float] | None:
    if v is None:
        return None
    try:
        a = [float(x) for x in np.ravel(np.asarray(v, dtype=float))]
    except (TypeError, ValueError):
        raise InputError(f"{path}: {what}: expected 3 numbers (x, y, z), got {v!r}") from None
    if len(a) == 1:
        a = a * 3
    if len(a) != 3:
        raise InputError(f"{path}: {what}: expected 3 numbers (x, y, z), got {len(a)}")
    return tuple(a)


def _pick(names: list[str], shapes: dict, keyword, path, what: str, others=()) -> str:
    """The array to read: ``keyword``, else the only 3D/4D one not named in ``others``."""
    fields = [n for n in names if len(shapes[n]) >= 3]
    if keyword is not None:
        if keyword not in names:
            raise InputError(f"{path}: {what} {keyword!r} not found; it holds "
                             f"{', '.join(fields) or 'no 3D/4D arrays'}")
        return keyword
    rest = [n for n in fields if n not in others]
    if len(rest) == 1:
        return rest[0]
    for n in DEFAULT_NAMES:
        if n in fields:
            return n
    raise InputError(f"{path}: holds {len(fields)} 3D/4D arrays ({', '.join(fields) or 'none'}); "
                     "choose one with --keyword NAME")


def _select_step(fs: FieldSeries, step) -> FieldSeries:
    if step is None:
        return fs
    k = fs.check_step(step)
    props = {n: [fs.property_step(n, k)] for n in fs.properties}
    meta = {**fs.meta, "step": k}
    meta.pop("default_step", None)
    return FieldSeries([fs.step(k)], spacing=fs.spacing, origin=fs.origin, grid=fs.grid,
                       coords=fs.coords, active=fs.active, name=fs.name, unit=fs.unit,
                       length_unit=fs.length_unit, times=[fs.times[k]], properties=props,
                       source=fs.source, meta=meta)


# ----------------------------------------------------------------------------------------------
def _read_npy(p: Path, path, keyword, color_by, hints) -> FieldSeries:
    if zipfile.is_zipfile(p):
        return _read_npz(p, path, keyword, color_by, hints)
    if color_by:
        raise InputError(f"{path}: a .npy file holds one array, so there is nothing to colour by; "
                         "put several arrays into an .npz")
    try:
        arr = np.load(p, mmap_mode="r", allow_pickle=False)
    except (ValueError, OSError, EOFError) as err:
        raise InputError(f"{path}: not a readable .npy array ({err})") from err
    if arr.ndim not in (3, 4):
        raise InputError(f"{path}: array of shape {arr.shape}; expected (nz, ny, nx) or "
                         "(time, nz, ny, nx)")
    return FieldSeries(arr, name=keyword or p.stem, source=str(path), meta={"format": "npy"},
                       **hints)


def _read_npz(p: Path, path, keyword, color_by, hints) -> FieldSeries:
    try:
        z = np.load(p, allow_pickle=False)
    except (ValueError, OSError, EOFError, zipfile.BadZipFile) as err:
        raise InputError(f"{path}: not a readable .npz archive ({err})") from err
    with z:
        arrays = {k: z[k] for k in z.files}
    shapes = {k: a.shape for k, a in arrays.items()}
    name = _pick(list(arrays), shapes, keyword, path, "array", _names(color_by))
    props = {}
    for c in _names(color_by):
        props[c] = arrays[_pick(list(arrays), shapes, c, path, "array")]
    kw = dict(hints)
    kw.setdefault("spacing", _xyz(arrays.get("spacing"), "spacing", path))
    kw.setdefault("origin", _xyz(arrays.get("origin"), "origin", path))
    if "times" in arrays:
        kw["times"] = [str(t) for t in np.ravel(arrays["times"])]
    kw = {k: v for k, v in kw.items() if v is not None}
    same = [k for k, sh in shapes.items() if sh == shapes[name] and k != name]
    return FieldSeries(arrays[name], name=name, source=str(path), properties=props,
                       meta={"format": "npz", "key": name, "quantities": same}, **kw)


def _read_zarr(p: Path, path, keyword, color_by, hints) -> FieldSeries:
    import zarr

    if _xarray_zarr(p):
        return _read_zarr_dataset(p, path, keyword, color_by, hints)

    try:
        node = zarr.open(str(p), mode="r")
    except Exception as err:  # zarr raises many kinds
        raise InputError(f"{path}: not a readable zarr store ({type(err).__name__}: {err})"
                         ) from err
    if hasattr(node, "array_keys"):
        arrays = {k: node[k] for k in node.array_keys()}
        attrs = dict(node.attrs)
    else:
        arrays = {p.stem: node}
        attrs = {}
    shapes = {k: tuple(a.shape) for k, a in arrays.items()}
    name = _pick(list(arrays), shapes, keyword, path, "array", _names(color_by))
    arr = arrays[name]
    coords = _coordinate_arrays(arrays, shapes[name])
    if coords:   # 1D arrays x/y/z, depth ... beside it: placed as netCDF coordinates are
        return _read_xarray(_as_dataset(arrays, shapes, coords, name, color_by, attrs), path,
                            keyword, color_by, hints, "zarr")
    attrs = {**attrs, **dict(arr.attrs)}
    props = {c: arrays[_pick(list(arrays), shapes, c, path, "array")] for c in _names(color_by)}
    kw = dict(hints)
    kw.setdefault("spacing", _xyz(attrs.get("spacing"), "spacing attribute", path))
    kw.setdefault("origin", _xyz(attrs.get("origin"), "origin attribute", path))
    if attrs.get("times"):
        kw["times"] = [str(t) for t in attrs["times"]]
    kw = {k: v for k, v in kw.items() if v is not None}
    return FieldSeries(arr, name=name, unit=str(attrs.get("unit", "")), source=str(path),
                       properties=props, meta={"format": "zarr", "key": name}, **kw)


def _coordinate_arrays(arrays: dict, shape: tuple) -> dict[str, str]:
    """1D arrays of a zarr group named as x, y or z coordinates (``x``, ``lon``, ``depth``,
    ``z`` ...) whose length is the field's along that axis: ``{array name: axis}``."""
    if len(shape) not in (3, 4):
        return {}
    nz, ny, nx = shape[-3:]
    size = {"x": nx, "y": ny, "z": nz}
    out = {}
    for k, a in arrays.items():
        role = role_by_name(k)
        if role is not None and len(a.shape) == 1 and a.shape[0] == size[role] and \
                np.dtype(a.dtype).kind in "fiu":
            out[k] = role
    return out


def _as_dataset(arrays: dict, shapes: dict, coords: dict, name: str, color_by, attrs: dict):
    """The zarr group as an xarray Dataset: the field (and colour arrays) on dims
    ``(time,) z, y, x``, the coordinate arrays (with their attributes) on their dims."""
    import dask.array as da

    xr = require("xarray", "netcdf", "reading zarr fields with coordinate arrays")
    dims = ("z", "y", "x")
    data = {}
    for k in [name, *(c for c in _names(color_by) if c in arrays)]:
        nd = len(shapes[k])
        if nd not in (3, 4):
            continue
        vattrs = dict(arrays[k].attrs)
        data[k] = ((("time",) if nd == 4 else ()) + dims, da.from_zarr(arrays[k]), vattrs)
    cs = {k: (axis, np.asarray(arrays[k][:]), dict(arrays[k].attrs)) for k, axis in coords.items()}
    if attrs.get("times") and len(shapes[name]) == 4:
        cs["time"] = ("time", [str(t) for t in attrs["times"]])
    return xr.Dataset(data, coords=cs)


def _read_netcdf(p: Path, path, keyword, color_by, hints) -> FieldSeries:
    require("netCDF4", "netcdf", "reading netCDF fields")
    xr = require("xarray", "netcdf", "reading netCDF fields")

    try:
        ds = xr.open_dataset(p, chunks={}, decode_times=True)
    except Exception as err:
        raise InputError(f"{path}: not a readable netCDF file ({type(err).__name__}: {err})"
                         ) from err
    return _read_xarray(ds, path, keyword, color_by, hints, "netcdf")


def _read_xarray(ds, path, keyword, color_by, hints, fmt: str) -> FieldSeries:
    """A dataset's variable placed by its own coordinates (:mod:`geoshade.io.field_axes`)."""
    name, pick = parse_keyword(keyword)
    names = [str(v) for v in ds.data_vars]
    if name is not None:   # names of variables: any case
        name = next((n for n in names if n == name), None) or next(
            (n for n in names if n.lower() == name.lower()), name)
    shapes = {k: ds[k].shape for k in names}
    others = [parse_keyword(c)[0] for c in _names(color_by)]
    var = _pick(names, shapes, name, path, "variable", others)
    fs = read_dataset(ds, path, var, pick, _names(color_by), hints, fmt, keyword=keyword)
    same = [n for n in names if n != var and ds[n].dims == ds[var].dims]
    return dataclasses.replace(fs, meta={**fs.meta, "quantities": same})


def _xarray_zarr(p: Path) -> bool:
    """Whether a zarr store was written by xarray (its arrays name their dims), so that its
    coordinates place the field."""
    import zarr

    try:
        node = zarr.open(str(p), mode="r")
    except Exception:   # the raw reader says why
        return False
    arrays = [node[k] for k in node.array_keys()] if hasattr(node, "array_keys") else [node]
    for a in arrays:
        if "_ARRAY_DIMENSIONS" in a.attrs:
            return True
        names = getattr(getattr(a, "metadata", None), "dimension_names", None)
        if names and any(n is not None for n in names):
            return True
    return False


def _read_zarr_dataset(p: Path, path, keyword, color_by, hints) -> FieldSeries:
    xr = require("xarray", "netcdf", "reading zarr fields with coordinates")
    try:
        with warnings.catch_warnings():   # a store without consolidated metadata is fine
            warnings.filterwarnings("ignore", "Failed to open Zarr store with consolidated")
            ds = xr.open_zarr(str(p), chunks={}, decode_times=True)
    except Exception as err:
        raise InputError(f"{path}: not a readable xarray zarr store ({type(err).__name__}: "
                         f"{err})") from err
    return _read_xarray(ds, path, keyword, color_by, hints, "zarr")


def _is_case_file(p: Path) -> bool:
    """A file of an ECLIPSE/OPM case by the ``eclipse`` row of the format table (EGRID, INIT,
    UNRST, X0001, their formatted forms, SMSPEC ...)."""
    fmt = formats.find(p, sniff=False)
    return fmt is not None and fmt.name == "eclipse"


def _is_eclipse(p: Path) -> bool:
    if p.suffix.lower() in ECLIPSE_SUFFIXES or _is_case_file(p):   # formatted, X0001, ...
        return True
    if p.suffix == "" and not p.exists():
        return any(p.parent.glob(p.name + ".*"))
    return False


def is_bare_deck(path) -> bool:
    """Whether ``path`` is a ``.DATA`` deck without its run beside it (no EGRID + INIT of the same
    case name): :func:`geoshade.io.load` reads such a deck (static properties, as ``grid
    render`` does); a deck with its run is read as the run (report steps) by :func:`load_field`.

    >>> import os, tempfile
    >>> d = tempfile.mkdtemp()
    >>> deck = os.path.join(d, "CASE.DATA")
    >>> is_bare_deck(deck), is_bare_deck(os.path.join(d, "CASE.EGRID"))
    (True, False)
    >>> open(os.path.join(d, "CASE.EGRID"), "wb").close()   # an EGRID alone is not a run
    >>> is_bare_deck(deck)
    True
    >>> open(os.path.join(d, "CASE.INIT"), "wb").close()
    >>> is_bare_deck(deck)
    False
    """
    p = Path(path)
    if p.suffix.lower() != ".data":
        return False
    stem = p.name[: -len(p.suffix)]

    def beside(ext: str) -> bool:
        return any((p.parent / (stem + e)).is_file() for e in (ext.upper(), ext.lower()))

    return not ((beside(".egrid") or beside(".fegrid")) and (beside(".init") or beside(".finit")))


def _egrid_of(p: Path, path) -> Path:
    """What opens the case: ``path`` itself when it is a file of the case (EGRID, FEGRID,
    INIT, UNRST, X0001, ...: :func:`geoshade.io.grids.ecl.load_case` finds the others beside it), or
    the grid of the same case name beside a deck."""
    if _is_case_file(p):
        if not p.exists():
            raise InputError(f"{path}: no such file")
        return p
    stem = p.name[: -len(p.suffix)] if p.suffix.lower() in ECLIPSE_SUFFIXES else p.name
    for ext in (".EGRID", ".egrid", ".FEGRID", ".fegrid"):
        cand = p.parent / (stem + ext)
        if cand.is_file():
            return cand
    raise InputError(f"{path}: no {stem}.EGRID beside it; an ECLIPSE/OPM case needs its EGRID "
                     "(+ INIT, and UNRST for time steps)")


def _read_eclipse(p: Path, path, keyword, color_by, hints) -> FieldSeries:
    if hints:
        raise InputError(f"{path}: {', '.join(sorted(hints))} does not apply to a corner-point "
                         "case (its geometry comes from the EGRID)")
    if is_bare_deck(p):
        raise InputError(f"{path}: a deck without its run (no EGRID and INIT of the case beside "
                         "it) has no report steps; read its static properties with "
                         "geoshade.load(path) and show one with geoshade.view(grid, as_='iso', "
                         "keyword=NAME) (geoshade iso render does that)")
    egrid = _egrid_of(p, path)
    # the case's reader, imported now (resfo): the eclipse row of the format table
    load_case = formats.format_of(egrid).function()
    step_property = formats.resolve("geoshade.io.grids.ecl:step_property")
    kw = (keyword or DEFAULT_KEYWORD).upper()
    wanted = [kw, *(c.upper() for c in _names(color_by) if c.upper() != kw)]
    with warnings.catch_warnings(record=True) as seen:  # one warning, not one per try
        warnings.simplefilter("always")
        try:
            grid = load_case(egrid, keywords=wanted)
        except InputError:  # a static (INIT) keyword, or one the restart lacks
            grid = None
    if grid is None:
        grid = load_case(egrid, keywords=None)  # index everything
    else:
        for w in seen:
            warnings.warn(w.message, stacklevel=2)
    steps = list(grid.steps or [])
    static = grid.properties or {}
    in_steps = set(grid.meta.get("step_keywords") or (steps[0] if steps else ()))

    def series(name: str):
        if name in in_steps:
            return GridSteps(grid, name, len(steps), read=step_property)
        if name in static:
            return [np.asarray(static[name]).T]
        have = ", ".join(sorted(in_steps)) or "no cell keywords"
        stat = ", ".join(sorted(static))
        raise InputError(f"{path}: keyword {name} is not in the restart file; it holds {have}"
                         + (f" (and the INIT file {stat})" if stat else ""))

    values = series(kw)
    props = {c: series(c) for c in wanted[1:]}
    n = len(values)
    dates = list(grid.step_dates or [])
    times = [d or f"step {k}" for k, d in enumerate(dates)] if len(dates) == n else []
    # what else the case can colour the surface by: its restart and INIT cell keywords
    quantities = sorted((set(in_steps) | set(static) | set(_restart_keywords(egrid, grid)))
                        - {kw})
    meta = {"format": "eclipse", "keyword": kw, "egrid": str(egrid), "quantities": quantities}
    if kw in in_steps and len(grid.meta.get("unrst_seqnum") or ()) == n:
        meta["reports"] = list(grid.meta["unrst_seqnum"])   # steps by report number (R36)
    if kw in in_steps and grid.meta.get("default_step") is not None:
        # a non-unified restart file opened itself (CASE.X0012): its own report is shown
        meta["default_step"] = int(grid.meta["default_step"])
        meta["notes"] = [n for n in grid.meta.get("notes") or () if "opened" in str(n)]
    return FieldSeries(values, grid=grid, name=kw, length_unit=grid.units, times=times,
                       properties=props, source=str(path), meta=meta)


def _restart_keywords(egrid: Path, grid) -> list[str]:
    """The cell keywords (one value per active cell) of the first report step of the case's
    unified restart file, read from its record headers only (none: no unified restart)."""
    import resfo

    unrst = next((q for q in (egrid.with_suffix(".UNRST"), egrid.with_suffix(".FUNRST"))
                  if q.is_file()), None)
    if unrst is None:
        return []
    n, seen, out = int(grid.nactive), 0, []
    try:
        for rec in resfo.lazy_read(unrst):
            kw = rec.read_keyword().strip()
            if kw == "SEQNUM":
                seen += 1
                if seen > 1:
                    break
            elif rec.read_length() == n and kw not in out:
                out.append(kw)
    except (resfo.ResfoParsingError, OSError, ValueError):
        return out   # what the headers said before the damage (the reader says the rest)
    return out


def load_field(path, keyword=None, step=None, color_by=None, spacing=None,
               origin=None) -> FieldSeries:
    """Read a scalar field (one or many time steps) for the isosurface view.

    Parameters
    ----------
    path : str or Path
        ``.npy``, ``.npz``, a ``.zarr`` store, a netCDF file, or an ECLIPSE/OPM case (``.EGRID``,
        ``.UNRST``, ``.DATA`` or the case name without suffix).
    keyword : str, optional
        Which array / variable / restart keyword (ECLIPSE default ``SWAT``; e.g. ``SGAS``,
        ``PRESSURE``).
    step : int, optional
        Keep only this step (default: all).
    color_by : str or list of str, optional
        Other quantities of the same file to load as ``properties`` (e.g. ``PRESSURE``).
    spacing, origin : 3 floats, optional
        Override what the file says (regular grids).

    Returns
    -------
    FieldSeries

    Raises
    ------
    InputError
        Missing file, unknown format, a keyword the file lacks, a step that does not exist,
        mismatched shapes between steps, arrays that are not 3D/4D.

    Examples
    --------
    >>> import numpy as np, tempfile, os
    >>> f = os.path.join(tempfile.mkdtemp(), "s.npz")
    >>> np.savez(f, SWAT=np.zeros((4, 3, 5, 6), np.float32), PRESSURE=np.ones((4, 3, 5, 6)))
    >>> fs = load_field(f, keyword="SWAT", color_by="PRESSURE")
    >>> fs.nsteps, fs.shape, list(fs.properties)
    (4, (3, 5, 6), ['PRESSURE'])
    >>> load_field(f, keyword="SWAT", step=9)
    Traceback (most recent call last):
    ...
    geoshade.errors.InputError: ...s.npz: step 9 does not exist: SWAT has 4 steps (0..3)
    """
    p = Path(path)
    hints = {}
    if spacing is not None:
        hints["spacing"] = _xyz(spacing, "spacing", path)
    if origin is not None:
        hints["origin"] = _xyz(origin, "origin", path)
    suffix = p.suffix.lower()
    if _is_eclipse(p):
        fs = _read_eclipse(p, path, keyword, color_by, hints)
    elif not p.exists():
        raise InputError(f"{path}: no such file")
    elif suffix in (".npy", ".npz"):
        fs = _read_npy(p, path, keyword, color_by, hints)
    elif suffix == ".zarr" or (p.is_dir() and any((p / m).exists() for m in
                                                  ("zarr.json", ".zarray", ".zgroup"))):
        fs = _read_zarr(p, path, keyword, color_by, hints)
    elif suffix in NETCDF_SUFFIXES:
        fs = _read_netcdf(p, path, keyword, color_by, hints)
    else:
        raise InputError(f"{path}: unknown field format {p.suffix or '(no suffix)'!r}; expected "
                         ".npy, .npz, .zarr, netCDF (.nc) or an ECLIPSE/OPM case (.EGRID, "
                         ".UNRST, .DATA)")
    return _select_step(fs, step)
