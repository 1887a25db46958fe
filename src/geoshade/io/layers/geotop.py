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


def _axis(ds, name: str, path) -> tuple[np.ndarray, float]:
    if name not in ds.coords:
        raise InputError(f"{path}: coordinate {name!r} missing; expected a GeoTOP grid with "
                         "x, y, z coordinates")
    v = np.asarray(ds[name].values, np.float64)
    if v.size == 1:
        return v, 1.0
    d = np.diff(v)
    if not np.allclose(d, d[0], rtol=1e-6, atol=1e-9) or d[0] == 0:
        raise InputError(f"{path}: coordinate {name!r} is not regularly spaced")
    return v, float(d[0])


def read_geotop(path, variable: str | None = None, legend_folder=None) -> VoxelVolume:
    """Read one label variable of a GeoTOP netCDF as a ``(nz, ny, nx)`` float32 volume.

    Parameters
    ----------
    path : str or Path
        A GeoTOP netCDF with dimensions x, y, z (any order) and regular coordinates.
    variable : str, optional
        ``lithok`` (lithoclass) or ``strat``; any other x-y-z variable of the file with integer
        codes also works (with a generated legend). Default: ``lithok``, or the file's only
        x-y-z variable.
    legend_folder : path, optional
        Folder with the TNO tables (default: ``legend_nlmod/`` next to the file, if present).

    Returns
    -------
    VoxelVolume
        NaN where the file has no value (above ground). ``meta``: ``format`` "geotop",
        ``variable``, ``crs``, ``legend`` (:class:`Legend`), ``boreholes`` (path of a
        ``boreholes*.parquet`` next to the file, or None).

    Raises
    ------
    InputError
        Missing or unreadable file, no such variable (the message lists the variables),
        irregular coordinates.

    Examples
    --------
    >>> vol = read_geotop("../shared/data/geotop_usp/geotop_usp.nc")   # doctest: +SKIP
    >>> vol.shape_xyz, vol.spacing, vol.meta["crs"]                    # doctest: +SKIP
    ((19, 15, 313), (100.0, 100.0, 0.5), 'EPSG:28992')
    """
    ds = _open(path)
    try:
        if variable is None:
            three_d = [str(v) for v in ds.data_vars if set(ds[v].dims) == {"x", "y", "z"}]
            variable = "lithok" if "lithok" in three_d else (three_d[0] if len(three_d) == 1
                                                             else "lithok")
        if variable not in ds.data_vars:
            raise InputError(f"{path}: no variable {variable!r}; the file has "
                             f"{', '.join(map(str, ds.data_vars)) or 'no variables'}")
        var = ds[variable]
        if set(var.dims) != {"x", "y", "z"}:
            raise InputError(f"{path}: variable {variable!r} has dimensions {var.dims}; "
                             "expected x, y, z")
        xs, dx = _axis(ds, "x", path)
        ys, dy = _axis(ds, "y", path)
        zs, dz = _axis(ds, "z", path)
        need = int(var.size) * (4 + np.dtype(var.dtype).itemsize)  # as stored + float32
        check_memory(need, path, f"variable {variable!r} ({'×'.join(map(str, var.shape))} "
                     f"{var.dtype})")
        data = np.asarray(var.transpose("z", "y", "x").values, np.float32)
        crs = ""
        for c in ("x", "y", "z"):
            epsg = ds[c].attrs.get("epsg")
            if epsg:
                crs = f"EPSG:{epsg}"
                break
        attrs = dict(ds.attrs)
    except (GeoshadeError, MemoryError):
        raise
    except Exception as exc:  # netCDF4/HDF5 errors of a damaged file, undecodable values
        raise InputError(f"{path}: cannot be read, the file is damaged or truncated "
                         f"({one_line(exc)})") from None
    finally:
        ds.close()
    if crs == "EPSG:7415":  # RD New + NAP height: the horizontal part is EPSG:28992
        crs = "EPSG:28992"
    for axis, step in ((2, dx), (1, dy), (0, dz)):
        if step < 0:
            data = np.flip(data, axis=axis)
    dx, dy, dz = abs(dx), abs(dy), abs(dz)
    origin = (float(xs.min()) - dx / 2, float(ys.min()) - dy / 2, float(zs.min()) - dz / 2)
    p = Path(path)
    folder = Path(legend_folder) if legend_folder else p.parent / "legend_nlmod"
    legend = read_legend(variable, folder) if (folder / LEGEND_FILES.get(variable, "-")
                                                ).is_file() else None
    logs = sorted(p.parent.glob("boreholes*.parquet"))
    meta = {"format": "geotop", "source": str(path), "variable": variable, "crs": crs,
            "legend": legend, "boreholes": str(logs[0]) if logs else None,
            "title": attrs.get("title", ""),
            "assumed": ["coordinates are cell centres (CF)"]}
    return VoxelVolume(data=np.ascontiguousarray(data), spacing=(dx, dy, dz), origin=origin,
                       unit="m", name=f"{p.name}:{variable}", meta=meta)


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
