"""GeoTOP voxel models (TNO, netCDF), their legends and DINOloket borehole logs.

- :func:`read_geotop`: a GeoTOP netCDF through xarray → a labelled :class:`VoxelVolume`
  ``(nz, ny, nx)`` float32 of one variable (``lithok`` lithoclass or ``strat``
  lithostratigraphic unit), NaN above ground. Coordinates are read as cell centres (CF), so the
  origin is the first centre minus half a cell; the CRS comes from the coordinates' ``epsg``
  attribute. ``meta["legend"]`` holds the legend (:func:`read_legend`).
- :func:`read_legend`: the TNO reference tables of ``legend_nlmod/`` (``REF_GTP_LITHO_CLASS.csv``,
  ``REF_GTP_STR_UNIT.csv``): code (``VOXEL_NR``) → name, RGB. The lithoclass table lists "o
  overig" without a number: geoshade gives it code :data:`LITHOK_OTHER` (10) for borehole layers
  that fit no class; the strat table's ``NN`` (0, unknown) plays that role for ``strat``.
- :func:`read_boreholes`: DINOloket borehole layers (parquet: ``nr x y surface top bottom lith
  zm zmk strat_2003 ...``; ``top``/``bottom`` are depths below ``surface``) →
  :class:`BoreholeLogs` with world heights and codes of the chosen variable.

The conversion to stacks is not done here (io does not import compute): see
:func:`geoshade.compute.stacks.voxels_to_stacks` and :func:`geoshade.stacks.convert`.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from geoshade.errors import GeoshadeError, InputError, require
from geoshade.io.field_axes import dim_roles, place_axes
from geoshade.io.paths import check_file, check_memory, one_line
from geoshade.models.stacks import BoreholeLogs, Legend
from geoshade.models.volume import VoxelVolume

#: the label variables of a GeoTOP file geoshade turns into stacks
VARIABLES = ("lithok", "strat")
#: legend table per variable, in ``legend_nlmod/``
LEGEND_FILES = {"lithok": "REF_GTP_LITHO_CLASS.csv", "strat": "REF_GTP_STR_UNIT.csv"}
#: the lithoclass given to borehole layers that fit no GeoTOP class ("o overig" of the table)
LITHOK_OTHER = 10
#: the strat code of unknown units (``NN`` in the table)
STRAT_UNKNOWN = 0
#: DINOloket main lithology -> lithoclass (sand is split by grain size, see _sand_class)
LITH_TO_LITHOK = {"V": 1, "K": 2, "L": 3, "G": 8, "SHE": 9}
#: NEN 5104 sand median classes -> lithoclass (fine 5: 63–150 µm, medium 6: 150–300 µm,
#: coarse 7: 300–2000 µm)
ZMK_TO_LITHOK = {"ZUF": 5, "ZZF": 5, "ZMF": 5, "ZFC": 5, "ZUFO": 5, "ZZFO": 5, "ZMFO": 5,
                 "ZMG": 6, "ZMGO": 6, "ZMC": 6, "ZZG": 6, "ZZGO": 6, "ZUG": 7, "ZGC": 7}


def _open(path):
    require("netCDF4", "netcdf", "reading GeoTOP netCDF")
    xr = require("xarray", "netcdf", "reading GeoTOP netCDF")

    p = check_file(path, "a netCDF file")
    try:
        return xr.open_dataset(p)
    except Exception as exc:  # xarray raises many types for unreadable files
        raise InputError(f"{path}: not a readable netCDF file ({one_line(exc)})") from None


def _placed(ds, var, path) -> dict:
    """The x, y, z of ``var`` as :mod:`geoshade.io.field_axes` places a field's: dims told by
    CF attributes, units and names; a positive-down depth made z up; decreasing axes flipped;
    nodes (cell centres) increasing."""
    where = f"{path}: "
    roles = dim_roles(ds, tuple(str(d) for d in var.dims), where)
    if len(var.dims) != 3 or sorted(roles.values()) != ["x", "y", "z"]:
        raise InputError(f"{path}: variable {var.name!r} has dimensions {var.dims}; expected x, "
                         "y, z (one value per voxel)")
    return place_axes(ds, {r: d for d, r in roles.items()}, where)


def _edges(c: np.ndarray) -> np.ndarray:
    """Cell edges of centres ``c`` (increasing): halfway between them, half a step past the
    ends.

    >>> _edges(np.array([1.0, 4.0, 11.0])).tolist()
    [-0.5, 2.5, 7.5, 14.5]
    """
    mid = (c[1:] + c[:-1]) / 2
    return np.concatenate([[c[0] - (mid[0] - c[0])], mid, [c[-1] + (c[-1] - mid[-1])]])


def _cf_edges(ds, name: str, zs: np.ndarray) -> np.ndarray | None:
    """The layers' edges from the z coordinate's CF ``bounds`` (in the placed frame: z up,
    increasing), or None when it has none or they leave gaps between layers."""
    var = ds.variables.get(name)
    bname = var.attrs.get("bounds") if var is not None else None
    if not bname or bname not in ds.variables:
        return None
    b = np.asarray(ds[bname].values, np.float64)
    raw = np.asarray(var.values, np.float64)
    if b.shape != (raw.size, 2):
        return None
    sign = -1.0 if np.allclose(np.sort(-raw), zs) else 1.0
    lo, hi = np.sort(sign * b, axis=1).T
    order = np.argsort(sign * raw)
    lo, hi = lo[order], hi[order]
    if not np.allclose(hi[:-1], lo[1:], rtol=1e-9, atol=1e-6):
        return None
    return np.concatenate([lo[:1], hi])


def _steps(axes: dict, path) -> dict:
    """(step, even) per axis; uneven x or y is one line (stacks need regular columns)."""
    steps = {}
    for role in ("x", "y", "z"):
        c = axes[role][1]
        d = np.diff(c) if c.size > 1 else np.array([1.0])
        even = bool(np.allclose(d, d[0], rtol=1e-6, atol=1e-9))
        if not even and role != "z":
            raise InputError(f"{path}: coordinate {axes[role][3]!r} is not regularly spaced; "
                             "stacks need columns on a regular grid")
        steps[role] = (float(d[0]) if even else float(d.mean()), even)
    return steps


def read_geotop(path, variable: str | None = None, legend_folder=None,
                uneven: bool = False) -> VoxelVolume:
    """Read one label variable of a GeoTOP netCDF as a ``(nz, ny, nx)`` float32 volume.

    Parameters
    ----------
    path : str or Path
        A GeoTOP netCDF with dimensions x, y, z in any order; the dims and their coordinates
        are told as :mod:`geoshade.io.field_axes` tells a field's (CF attributes, units, names:
        a top-down ``layer`` dim with a ``depth`` coordinate ``positive="down"`` too); x and y
        evenly spaced.
    variable : str, optional
        ``lithok`` (lithoclass) or ``strat``; any other x-y-z variable of the file with integer
        codes also works (with a generated legend). Default: ``lithok``, or the file's only
        3D variable.
    legend_folder : path, optional
        Folder with the TNO tables (default: ``legend_nlmod/`` next to the file, if present).
    uneven : bool
        Accept layers of uneven thickness: the volume's z spacing is then their mean and
        ``meta["z_edges"]`` holds the layers' true edges (what :func:`geoshade.stacks.convert`
        draws); without it such a file is one line saying which views keep the layers' heights,
        never a volume with its layers made equal.

    Returns
    -------
    VoxelVolume
        NaN where the file has no value (above ground). ``meta``: ``format`` "geotop",
        ``variable``, ``crs``, ``legend`` (:class:`Legend`), ``boreholes`` (path of a
        ``boreholes*.parquet`` next to the file, or None), ``notes`` (depth made z up, uneven
        layers), ``z_edges`` (uneven layers only).

    Raises
    ------
    InputError
        Missing or unreadable file, no such variable (the message lists the variables),
        uneven x or y, uneven z without ``uneven``.

    Examples
    --------
    >>> vol = read_geotop("../shared/data/geotop_usp/geotop_usp.nc")   # doctest: +SKIP
    >>> vol.shape_xyz, vol.spacing, vol.meta["crs"]                    # doctest: +SKIP
    ((19, 15, 313), (100.0, 100.0, 0.5), 'EPSG:28992')
    """
    ds = _open(path)
    try:
        three_d = [str(v) for v in ds.data_vars if ds[v].ndim == 3]
        if variable is None:
            variable = "lithok" if "lithok" in three_d else (three_d[0] if len(three_d) == 1
                                                             else "lithok")
        if variable not in ds.data_vars:
            raise InputError(f"{path}: no variable {variable!r}; the file has "
                             f"{', '.join(map(str, ds.data_vars)) or 'no variables'}")
        var = ds[variable]
        placed = _placed(ds, var, path)
        axes = placed["axes"]
        need = int(var.size) * (4 + np.dtype(var.dtype).itemsize)  # as stored + float32
        check_memory(need, path, f"variable {variable!r} ({'×'.join(map(str, var.shape))} "
                     f"{var.dtype})")
        data = np.asarray(var.transpose(axes["z"][0], axes["y"][0], axes["x"][0]).values,
                          np.float32)
        crs = ""
        for role in ("x", "y", "z"):
            name = axes[role][3]
            epsg = ds[name].attrs.get("epsg") if name in ds.variables else None
            if epsg:
                crs = f"EPSG:{epsg}"
                break
        attrs = dict(ds.attrs)
        zname = axes["z"][3]
        bname = ds[zname].attrs.get("bounds") if zname in ds.variables else None
        keep = [v for v in (zname, bname) if v and v in ds.variables]
        ds_bounds = ds[keep].load() if keep else ds[[]]
    except (GeoshadeError, MemoryError):
        raise
    except Exception as exc:  # netCDF4/HDF5 errors of a damaged file, undecodable values
        raise InputError(f"{path}: cannot be read, the file is damaged or truncated "
                         f"({one_line(exc)})") from None
    finally:
        ds.close()
    if crs == "EPSG:7415":  # RD New + NAP height: the horizontal part is EPSG:28992
        crs = "EPSG:28992"
    for axis, role in ((2, "x"), (1, "y"), (0, "z")):
        if axes[role][2]:
            data = np.flip(data, axis=axis)
    steps = _steps(axes, path)
    dx, dy, dz = steps["x"][0], steps["y"][0], steps["z"][0]
    xs, ys, zs = (axes[r][1] for r in ("x", "y", "z"))
    extra: dict = {}
    if not steps["z"][1]:
        if not uneven:
            d = np.diff(zs)
            unit = f" {placed['length_unit']}" if placed["length_unit"] else ""
            raise InputError(f"{path}: layer centres {d.min():.4g}–{d.max():.4g}{unit} apart "
                             f"along {axes['z'][3]!r}; a voxel volume needs even layers: draw it "
                             "with geoshade stacks render/convert (the layers keep their "
                             "heights) or geoshade iso render")
        edges = _cf_edges(ds_bounds, axes["z"][3], zs)
        if edges is None:
            edges = _edges(zs)
            placed["notes"].append("layer edges halfway between their centres (the file has "
                                   "no CF bounds; assumed)")
        extra["z_edges"] = edges
    z_lo = float(extra["z_edges"][0]) if extra else float(zs.min()) - dz / 2
    origin = (float(xs.min()) - dx / 2, float(ys.min()) - dy / 2, z_lo)
    p = Path(path)
    folder = Path(legend_folder) if legend_folder else p.parent / "legend_nlmod"
    legend = read_legend(variable, folder) if (folder / LEGEND_FILES.get(variable, "-")
                                                ).is_file() else None
    logs = sorted(p.parent.glob("boreholes*.parquet"))
    meta = {"format": "geotop", "source": str(path), "variable": variable, "crs": crs,
            "legend": legend, "boreholes": str(logs[0]) if logs else None,
            "title": attrs.get("title", ""),
            "assumed": ["coordinates are cell centres (CF)"], **extra}
    notes = [n for n in placed["notes"] if "without a unit" not in n and " apart" not in n]
    if notes:
        meta["notes"] = [f"{p.name}: {n}" for n in notes]
    return VoxelVolume(data=np.ascontiguousarray(data), spacing=(dx, dy, dz), origin=origin,
                       unit=placed["length_unit"] or "m", name=f"{p.name}:{variable}",
                       meta=meta)


def read_legend(variable: str, folder) -> Legend:
    """The TNO legend of ``lithok`` or ``strat`` from a ``legend_nlmod/`` folder.

    Examples
    --------
    >>> lg = read_legend("lithok", "../shared/data/geotop_usp/legend_nlmod")  # doctest: +SKIP
    >>> lg.codes.tolist()                                                      # doctest: +SKIP
    [0, 1, 2, 3, 5, 6, 7, 8, 9, 10]
    """
    pd = require("pandas", "parquet", "reading GeoTOP legends")

    if variable not in LEGEND_FILES:
        raise InputError(f"legend: no TNO table for variable {variable!r}; expected one of "
                         f"{', '.join(LEGEND_FILES)}")
    path = Path(folder) / LEGEND_FILES[variable]
    if not path.exists():
        raise InputError(f"{path}: no such file (the TNO legend table of {variable})")
    check_file(path, f"the TNO legend table of {variable} (a CSV file)")
    try:
        df = pd.read_csv(path, na_values=["Null"], keep_default_na=True)
    except Exception as exc:
        raise InputError(f"{path}: not a readable CSV table ({exc})") from None
    need = {"DESCRIPTION", "VOXEL_NR", "RED_DEC", "GREEN_DEC", "BLUE_DEC"}
    if not need <= set(df.columns):
        raise InputError(f"{path}: columns {sorted(need - set(df.columns))} missing")
    if variable == "lithok":
        other = df.iloc[:, 0].astype(str).str.lower() == "o"
        df.loc[other & df["VOXEL_NR"].isna(), "VOXEL_NR"] = LITHOK_OTHER
    df = df[df["VOXEL_NR"].notna()].drop_duplicates("VOXEL_NR")
    rgb = df[["RED_DEC", "GREEN_DEC", "BLUE_DEC"]].to_numpy(np.int64)
    rgba = np.concatenate([rgb, np.full((len(df), 1), 255)], axis=1)
    names = tuple(f"{c} {d}" for c, d in zip(df.iloc[:, 0], df["DESCRIPTION"], strict=True))
    return Legend(df["VOXEL_NR"].to_numpy(np.int64), names, rgba)


def _lookup(keys, table: dict, default: int) -> np.ndarray:
    """Vectorised dict lookup (pandas ``map``) with a default."""
    pd = require("pandas", "parquet", "reading borehole logs")

    return pd.Series(keys, dtype=object).map(table).fillna(default).to_numpy(np.int32)


def _sand_class(zm: np.ndarray, zmk: np.ndarray) -> np.ndarray:
    by_zm = np.where(zm < 150, 5, np.where(zm < 300, 6, 7))
    return np.where(np.isfinite(zm), by_zm, _lookup(zmk, ZMK_TO_LITHOK, 6)).astype(np.int32)


def read_boreholes(path, variable: str = "lithok", legend: Legend | None = None
                   ) -> BoreholeLogs:
    """DINOloket borehole layers (parquet) as :class:`BoreholeLogs` in world heights.

    ``lithok``: main lithology ``lith`` → lithoclass (sand by median ``zm`` µm, else by the NEN
    5104 class ``zmk``); unknown (``GM``, ``NBE``, …) → :data:`LITHOK_OTHER`. ``strat``: the unit
    ``strat_2003`` → its ``VOXEL_NR`` in the legend, unknown → :data:`STRAT_UNKNOWN`.

    Examples
    --------
    >>> logs = read_boreholes("../shared/data/geotop_usp/boreholes_usp.parquet")  # doctest: +SKIP
    >>> logs.nboreholes, len(logs)                                               # doctest: +SKIP
    (67, 1398)
    """
    pd = require("pandas", "parquet", "reading borehole logs")
    require("pyarrow", "parquet", "reading borehole logs")

    p = check_file(path, "a parquet table of borehole layers")
    try:
        df = pd.read_parquet(p)
    except Exception as exc:
        raise InputError(f"{path}: not a readable parquet table ({one_line(exc)})") from None
    need = {"nr", "x", "y", "surface", "top", "bottom", "lith"}
    if variable == "strat":
        need.add("strat_2003")
    if not need <= set(df.columns):
        raise InputError(f"{path}: columns {sorted(need - set(df.columns))} missing; expected "
                         "DINOloket borehole layers")
    surface = df["surface"].to_numpy(np.float64)
    top = surface - df["top"].to_numpy(np.float64)
    bottom = surface - df["bottom"].to_numpy(np.float64)
    if variable == "lithok":
        lith = df["lith"].astype(str).str.upper().to_numpy()
        code = _lookup(lith, LITH_TO_LITHOK, LITHOK_OTHER)
        sand = lith == "Z"
        zm = df["zm"].to_numpy(np.float64) if "zm" in df else np.full(len(df), np.nan)
        zmk = df["zmk"].astype(str).to_numpy() if "zmk" in df else np.full(len(df), "")
        code[sand] = _sand_class(zm[sand], zmk[sand])
    elif variable == "strat":
        units = df["strat_2003"].astype(str).to_numpy()
        lookup = {}
        if legend is not None:
            lookup = {n.split(" ", 1)[0]: int(c) for n, c in zip(legend.names, legend.codes,
                                                                   strict=True)}
        code = _lookup(units, lookup, STRAT_UNKNOWN)
    else:
        raise InputError(f"{path}: boreholes can be coded as lithok or strat, not {variable!r}")
    if legend is not None:
        known = np.isin(code, legend.codes)
        code = np.where(known, code, LITHOK_OTHER if variable == "lithok" else STRAT_UNKNOWN)
    return BoreholeLogs(borehole=df["nr"].astype(str).to_numpy(), x=df["x"].to_numpy(float),
                        y=df["y"].to_numpy(float), top=top, bottom=bottom, code=code,
                        legend=legend, name=p.name)
