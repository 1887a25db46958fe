"""Terrain and layered models from surfaces (DEMs), and a DEM top for a voxel model: the
paper's "surface and subsurface" in one stack model. No GL.

- :func:`from_surfaces`: one DEM → a terrain model (a column per DEM cell, from the DEM height
  down to a base); several surfaces, top to bottom → a layered model (one unit per interval
  between consecutive surfaces). Nodata cells of the top surface are empty columns.
- :func:`apply_top`: cut or extend the top of each column of a model to a height map (a DEM
  resampled to the model's grid): the GeoTOP model under the AHN terrain.

Heights are stored as levels above the model bottom ``z0`` (``level = (z - z0) / dz``, float32),
so a column's top is the DEM height itself (to float32 precision), not a whole voxel: the
renderer's smooth top (``top="smooth"``) interpolates the tops between column centres.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from geoshade.errors import InputError
from geoshade.models.stacks import EMPTY, Legend, StackModel
from geoshade.styles.palette import colormap

#: colour of a one-DEM terrain column (earth) where it is not coloured by elevation
TERRAIN_RGBA = (176, 150, 110, 255)
#: a terrain from one DEM is coloured by elevation in this many bands of ...
ELEVATION_BANDS = 64
#: ... this colour map, over this part of it (matplotlib's terrain without its sea blues)
ELEVATION_CMAP, ELEVATION_SPAN = "terrain", (0.22, 0.95)
#: default margin of the base under a DEM's lowest cell: this fraction of the relief ...
BASE_MARGIN = 0.1
#: ... and at least this many levels
BASE_MARGIN_LEVELS = 1.0


def default_base(top: np.ndarray, dz: float = 1.0) -> float:
    """The default base of a terrain model: the lowest height minus 10 % of the relief (at least
    one level), rounded down to a multiple of ``dz``.

    >>> default_base(np.array([[10.0, 30.0]]))
    8.0
    """
    lo, hi = float(np.nanmin(top)), float(np.nanmax(top))
    margin = max(BASE_MARGIN * (hi - lo), BASE_MARGIN_LEVELS * dz)
    return math.floor((lo - margin) / dz) * dz


def _names(paths, names) -> list[str]:
    if names:
        return [str(n) for n in names]
    return [Path(p).name.split(".")[0] if isinstance(p, str | Path) else f"surface {i}"
            for i, p in enumerate(paths)]


def from_surfaces(surfaces, base: float | None = None, dz: float = 1.0, origin=(0.0, 0.0),
                  spacing=(1.0, 1.0), crs: str = "", unit: str = "", name: str = "",
                  surface_names=None, unit_names=None) -> StackModel:
    """A terrain (one surface) or layered (several) stack model.

    Parameters
    ----------
    surfaces : sequence of (ny, nx) float arrays, top to bottom, row 0 south
        Heights on one grid; NaN = no data. Later surfaces crossing earlier ones (above them)
        are clamped to them (the upper surface wins; a warning counts the cells); a NaN in a
        lower surface where the top has data takes the height of the surface above it (the unit
        above is absent there; counted in the same warning).
    base : float, optional
        One surface: the bottom of every column (default :func:`default_base`). Several
        surfaces: adds one more unit from the last surface down to ``base`` (default: none, the
        last surface is the bottom).
    dz : float
        Height of one level (the model's vertical unit step).
    origin, spacing : (x0, y0), (dx, dy)
        Lower-left corner and cell size of the grid.
    surface_names, unit_names : sequence of str, optional
        Names of the surfaces (units are named ``upper – lower``) or of the units directly.

    Returns
    -------
    StackModel
        Units coded ``1, 2, …`` from the top; ``meta``: ``terrain`` True, ``base``, ``surfaces``,
        ``nodata_columns``, ``crossing_cells``, ``color_by`` (``elevation`` for one DEM: the
        views colour it by height, :func:`elevation_colours`; else ``material``).

    Examples
    --------
    >>> top = np.array([[5.0, 6.5], [np.nan, 7.25]])
    >>> m = from_surfaces([top], base=0.0)
    >>> m.column_tops().tolist(), m.counts().tolist(), m.nlevels
    ([5.0, 6.5, 0.0, 7.25], [2, 2, 0, 2], 8)
    >>> m2 = from_surfaces([top, top - 2, top - 3], surface_names=["a", "b", "c"])
    >>> m2.legend.names, m2.origin[2]
    (('a – b', 'b – c'), 2.0)
    """
    if not isinstance(dz, int | float) or not math.isfinite(dz) or dz <= 0:
        raise InputError(f"dz: expected a level height > 0, got {dz!r}")
    arrs = [np.asarray(s, np.float64) for s in surfaces]
    if not arrs:
        raise InputError("surfaces: expected at least one surface (a DEM)")
    shape = arrs[0].shape
    if len(shape) != 2:
        raise InputError(f"surfaces: expected 2D height maps, got shape {shape}")
    for i, a in enumerate(arrs[1:], 1):
        if a.shape != shape:
            raise InputError(f"surface {i + 1}: shape {a.shape}; expected {shape} (the first "
                             "surface's grid; resample it first)")
    top = arrs[0]
    valid = np.isfinite(top)
    if not valid.any():
        raise InputError("surfaces: the top surface has no data")
    snames = _names(surface_names or [f"surface {i + 1}" for i in range(len(arrs))], None)
    stack = np.stack(arrs)                         # (k, ny, nx), top first
    crossing = 0
    filled = 0
    for i in range(1, stack.shape[0]):             # k surfaces: a few; cells vectorised
        upper = stack[i - 1]
        lower = stack[i]
        gap = valid & ~np.isfinite(lower)
        filled += int(gap.sum())
        lower[gap] = upper[gap]
        cross = valid & (lower > upper)
        crossing += int(cross.sum())
        lower[cross] = upper[cross]
    if crossing or filled:
        what = []
        if crossing:
            what.append(f"{crossing} cells where a surface lies above the one listed before it "
                        "(clamped to it: the upper surface wins)")
        if filled:
            what.append(f"{filled} cells with no data in a lower surface (the unit above is "
                        "absent there)")
        warnings.warn("surfaces: " + "; ".join(what), stacklevel=2)
    lowest = float(np.nanmin(stack[-1][valid]))
    if stack.shape[0] == 1 or base is not None:
        if base is None:
            base = default_base(top[valid], dz)
        base = float(base)
        if not math.isfinite(base) or base >= lowest:
            raise InputError(f"base: {base:g} is not below the lowest surface height "
                             f"{lowest:g}; expected --base below it")
        stack = np.concatenate([stack, np.full((1, *shape), base)])
        snames = [*snames, f"base {base:g}"] if stack.shape[0] > 2 else [*snames, "base"]
        z0 = base
    else:
        z0 = math.floor(lowest / dz) * dz
    levels = ((stack - z0) / dz).astype(np.float32)   # (k, ny, nx)
    levels[:, ~valid] = np.nan
    nunits = levels.shape[0] - 1
    # bottom-up per column: unit nunits-1 (lowest) ... unit 0, then air from the top
    starts_bu = np.concatenate([levels[:0:-1], levels[:1]])          # (k, ny, nx)
    present = np.concatenate([levels[-2::-1] > levels[:0:-1], valid[None]])
    present &= valid[None]
    codes_bu = np.concatenate([np.arange(nunits, 0, -1), [EMPTY]]).astype(np.int32)
    k = present.shape[0]
    pres = present.reshape(k, -1).T                   # (ncols, k)
    counts = pres.sum(axis=1)
    offsets = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
    starts = starts_bu.reshape(k, -1).T[pres]
    codes = np.broadcast_to(codes_bu, pres.shape)[pres]
    top_lv = float(np.nanmax(levels[0]))
    nlevels = math.floor(top_lv) + 1
    if unit_names:
        if len(unit_names) != nunits:
            raise InputError(f"unit names: expected {nunits} names, got {len(unit_names)}")
        unames = [str(n) for n in unit_names]
    elif nunits == 1 and len(arrs) == 1:
        unames = ["terrain"]
    else:
        unames = [f"{snames[i]} – {snames[i + 1]}" for i in range(nunits)]
    if nunits == 1:
        rgba = np.array([TERRAIN_RGBA], np.uint8)
    else:
        rgba = Legend.from_codes(np.arange(1, nunits + 1)).rgba
    legend = Legend(np.arange(1, nunits + 1, dtype=np.int32), tuple(unames), rgba)
    meta = {"terrain": True, "base": float(z0), "dz": float(dz),
            # one DEM: drawn in elevation colours with a height colour bar (StacksView)
            "color_by": "elevation" if nunits == 1 and len(arrs) == 1 else "material",
            "surfaces": [str(s) for s in snames], "nodata_columns": int((~valid).sum()),
            "crossing_cells": crossing, "filled_cells": filled}
    return StackModel(offsets, starts, codes, (shape[1], shape[0]), nlevels, legend,
                      origin=(float(origin[0]), float(origin[1]), float(z0)),
                      spacing=(float(spacing[0]), float(spacing[1]), float(dz)), crs=crs,
                      unit=unit, name=name, meta=meta)


def apply_top(model: StackModel, top: np.ndarray) -> StackModel:
    """Cut or extend each column's top to the heights ``top`` (``(ny, nx)`` world heights on the
    model's grid, row 0 south; NaN leaves a column as it is).

    Intervals above the new top are cut; the interval holding it ends there; a column whose
    material ends below it has its top material extended up to it (through the air above, not
    through caves or gaps lower down). A column with no material stays empty. ``nlevels``
    grows when the top rises above the box.

    Examples
    --------
    >>> m = StackModel([0, 3, 5], [0, 2, 4, 0, 3], [1, 2, EMPTY, 1, EMPTY], (2, 1), 6)
    >>> t = apply_top(m, np.array([[3.5, 5.5]]))
    >>> t.starts.tolist(), t.codes.tolist(), t.offsets.tolist()
    ([0.0, 2.0, 3.5, 0.0, 5.5], [1, 2, -1, 1, -1], [0, 3, 5])
    """
    t = np.asarray(top, np.float64)
    nx, ny = model.shape
    if t.shape != (ny, nx):
        raise InputError(f"top: shape {t.shape}; expected {(ny, nx)} (the model's grid)")
    dz, z0 = model.spacing[2], model.origin[2]
    lv = ((t - z0) / dz).astype(np.float32).ravel()        # (ncols,)
    col = model.column_ids()
    n = model.nintervals
    starts, codes = model.starts, model.codes
    has_top = np.isfinite(lv)
    mat = codes != EMPTY
    cnt_mat = np.bincount(col[mat], minlength=model.ncols)
    use = has_top & (cnt_mat > 0) & (lv > 0)
    # the last material interval of each column (the surface's material)
    last_mat = np.full(model.ncols, -1, np.int64)
    idx = np.nonzero(mat)[0]
    np.maximum.at(last_mat, col[idx], idx)
    keep = np.ones(n, bool)
    u = use[col]
    keep &= ~(u & (starts >= lv[col]))                     # cut above the new top
    keep &= ~(u & (np.arange(n) > last_mat[col]))          # air above the old top
    new_col = col[keep]
    new_starts = starts[keep]
    new_codes = codes[keep]
    add_cols = np.nonzero(use)[0]
    all_col = np.concatenate([new_col, add_cols])
    all_starts = np.concatenate([new_starts, lv[add_cols]])
    all_codes = np.concatenate([new_codes, np.full(add_cols.size, EMPTY, np.int32)])
    order = np.lexsort((all_starts, all_col))
    all_col, all_starts, all_codes = all_col[order], all_starts[order], all_codes[order]
    counts = np.bincount(all_col, minlength=model.ncols)
    offsets = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
    # an air interval right after another (the new top inside a gap) or first in its column
    # (the new top under the column's first start) says nothing: dropped
    same = np.zeros(all_codes.size, bool)
    same[1:] = all_col[1:] == all_col[:-1]
    air = all_codes == EMPTY
    prev_air = np.zeros(all_codes.size, bool)
    prev_air[1:] = air[:-1]
    drop = air & (~same | prev_air)
    if drop.any():
        all_col, all_starts, all_codes = all_col[~drop], all_starts[~drop], all_codes[~drop]
        counts = np.bincount(all_col, minlength=model.ncols)
        offsets = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
    nlevels = max(model.nlevels, math.floor(float(np.nanmax(lv[use]) if use.any()
                                                       else 0.0)) + 1)
    ignored = int((has_top & (cnt_mat == 0)).sum())
    below = int((has_top & (cnt_mat > 0) & (lv <= 0)).sum())
    if ignored or below or (~has_top).any():
        warnings.warn(f"top: {int((~has_top).sum())} columns without a height (kept as they "
                      f"were), {ignored} columns without material (kept empty), {below} "
                      "columns whose top is under the model's bottom (kept)", stacklevel=2)
    meta = {**model.meta, "top_from_dem": True, "terrain": True,
            "top_columns": int(use.sum())}
    return StackModel(offsets, all_starts, all_codes, model.shape, nlevels, model.legend,
                      origin=model.origin, spacing=model.spacing, borehole=model.borehole,
                      crs=model.crs, unit=model.unit, name=model.name, meta=meta,
                      log_base=model.log_base)


def read_surfaces(paths, base: float | None = None, dz: float = 1.0, unit_names=None,
                  progress=None, positive: str | None = None) -> StackModel:
    """A terrain (one DEM) or layered (several surfaces, top to bottom) model from rasters of the
    ``terrain`` rows (GeoTIFF, Arc ASCII, SRTM, IRAP surfaces).

    The surfaces after the first are resampled (by their georeference; average onto larger
    cells, else bilinear) to the first one's grid when their grid differs. See
    :func:`from_surfaces` for ``base``, ``dz``, crossing surfaces and nodata. ``positive``:
    the sign of IRAP surfaces' values (``"down"``, RMS's depths, the default; ``"up"``:
    heights), refused for rasters of heights.

    Examples
    --------
    >>> m = read_surfaces(["dem.tif"])                      # doctest: +SKIP
    >>> m = read_surfaces(["top.tif", "base1.tif", "base2.tif"], dz=0.5)  # doctest: +SKIP
    """
    from geoshade.io.layers.dem import read_terrain, resample

    paths = [str(p) for p in paths]
    if not paths:
        raise InputError("surfaces: expected at least one DEM")
    sign = {} if positive is None else {"positive": positive}
    first = read_terrain(paths[0], **sign)
    if first.meta.get("geographic"):
        raise InputError(f"{paths[0]}: CRS {first.crs} is geographic (cells of "
                         f"{first.spacing[0]:g}° against heights in metres); expected a "
                         "projected CRS: reproject the DEM first (gdalwarp -t_srs EPSG:…)")
    arrays = [first.data]
    for i, p in enumerate(paths[1:], 1):
        if progress is not None:
            progress(i, len(paths))
        r = read_terrain(p, **sign)
        same = (r.shape == first.shape and np.allclose(r.origin, first.origin)
                and np.allclose(r.spacing, first.spacing)
                and (r.crs == first.crs or not r.crs or not first.crs))
        arrays.append(r.data if same else
                      resample(r, first.origin, first.spacing, first.shape, first.crs,
                               what=p))
    if progress is not None:
        progress(len(paths), len(paths))
    names = [Path(p).name.split(".")[0] for p in paths]
    model = from_surfaces(arrays, base=base, dz=dz, origin=first.origin,
                          spacing=first.spacing, crs=first.crs,
                          unit=first.unit or ("m (assumed)" if first.meta.get(
                              "length_unit_assumed") else "m"),
                          name=first.name if len(paths) == 1 else f"{first.name} (layered)",
                          surface_names=names, unit_names=unit_names)
    model.meta.update({"surface_files": paths, "variable": "terrain" if len(paths) == 1
                       else "unit", "nodata": first.nodata})
    notes = [f"{first.name}: {first.meta[k]}" for k in ("reprojected", "rotated")
             if first.meta.get(k)]    # the picture and the JSON say so
    notes += [f"{first.name}: {a}" for a in first.meta.get("assumed", [])
              if a != first.meta.get("assumed_crs")]
    if notes:
        model.meta["notes"] = notes
    return model


def top_from_dem(model: StackModel, path, method: str = "auto") -> StackModel:
    """:func:`apply_top` with a DEM file, resampled to the model's grid by its georeference
    (``average`` onto coarser cells, else bilinear)."""
    from geoshade.io.layers.dem import read_terrain, resample

    dem = read_terrain(path)
    nx, ny = model.shape
    top = resample(dem, model.origin[:2], model.spacing[:2], (nx, ny), model.crs,
                   method=method, what=str(path))
    out = apply_top(model, top)
    out.meta["top_source"] = str(path)
    return out




@dataclass(frozen=True)
class ElevationColours:
    """A terrain coloured by the elevation of each column's top, in ``n`` bands of equal
    height from ``lo`` to ``hi`` (model units).

    band:   (ncols,) int   band of each column (0..n-1; -1 for a column with nothing)
    levels: (n, 4) uint8   RGBA of each band
    """

    lo: float
    hi: float
    band: np.ndarray
    levels: np.ndarray

    @property
    def n(self) -> int:
        return len(self.levels)

    def colorbar_palette(self) -> np.ndarray:
        """(256, 4) uint8: the bands laid over a colour bar's 256 entries (entry ``i`` is band
        ``i * n // 256``), so the bar shows the picture's colours band for band."""
        return np.ascontiguousarray(self.levels[np.arange(256) * self.n // 256])


def elevation_colours(model: StackModel, n: int = ELEVATION_BANDS) -> ElevationColours | None:
    """The elevation colouring of a terrain made from one DEM (``meta["color_by"]`` is
    ``elevation``), else None. A column's band is that of its top's height.

    Examples
    --------
    >>> m = from_surfaces([np.array([[0.0, 10.0], [20.0, np.nan]])], base=-5.0)
    >>> ec = elevation_colours(m, n=4)
    >>> ec.lo, ec.hi, ec.band.tolist()
    (0.0, 20.0, [0, 2, 3, -1])
    """
    if ((model.meta or {}).get("color_by") != "elevation" or model.legend is None
            or len(model.legend) != 1):
        return None

    z = model.origin[2] + model.column_tops().astype(np.float64) * model.spacing[2]
    has = model.counts() > 0
    if not has.any():
        return None
    lo, hi = float(z[has].min()), float(z[has].max())
    span = hi - lo if hi > lo else 1.0
    band = np.clip(np.floor((z - lo) / span * n), 0, n - 1).astype(np.int64)
    band[~has] = -1
    levels = colormap(ELEVATION_CMAP)(np.linspace(*ELEVATION_SPAN, n), bytes=True)
    return ElevationColours(lo, hi, band, np.ascontiguousarray(levels, np.uint8))


__all__ = ["ElevationColours", "apply_top", "default_base", "elevation_colours", "from_surfaces",
           "read_surfaces", "top_from_dem"]
