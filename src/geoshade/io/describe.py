"""What ``geoshade info PATH`` prints: a JSON-serialisable summary of a model.

Value statistics are computed in z-slabs of about ``SLAB_BYTES`` so that a volume larger than
memory is never read whole.  ``DESCRIBERS`` maps each model type to its describer (volumes,
grids, stack models; rasters of heights are described by
:func:`geoshade.io.layers.dem.describe_georeferenced`); a model's ``format`` is the title of its
file's row of the format table (:mod:`geoshade.io.formats`) where the reader did not name it.
What only some models need (a grid's restart wells, a raster's text) is named and imported when
used, so that ``geoshade.io`` gives :func:`describe` without importing any reader package.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from typing import Any

import numpy as np

from geoshade.io import formats
from geoshade.models import CornerPointGrid, StackModel, VoxelVolume
from geoshade.models.field import FieldSeries
from geoshade.models.grid import MAX_COORDINATE
from geoshade.models.summary_vectors import SummaryTable

#: where the wells of a grid's restart are described (imported when a grid is: resfo)
_RESTART_WELLS = "geoshade.io.grids.restart_wells:"
#: a grid's LGRs, media, notes and bounds over its active cells (io/grids/ecl_info.py)
_CASE_PARTS = "geoshade.io.grids.ecl_info:"
#: bytes read per slab when computing statistics
SLAB_BYTES = 64 << 20
#: a lazy volume (a store) larger than this is not read for statistics (its recorded value
#: range is shown instead)
STATS_MAX_BYTES = 64 << 30


def _slab_step(data, plane_bytes: int) -> int:
    step = max(1, SLAB_BYTES // max(1, plane_bytes))
    chunks = getattr(data, "chunks", None)
    if isinstance(chunks, tuple) and chunks and isinstance(chunks[0], int) and chunks[0] > 0:
        step = max(chunks[0], step // chunks[0] * chunks[0])  # whole zarr chunks along z
    return step


def volume_stats(volume: VoxelVolume) -> dict:
    """min, max, mean (and NaN count for floats) of a volume, read in z-slabs.

    Examples
    --------
    >>> import numpy as np
    >>> from geoshade.models import VoxelVolume
    >>> volume_stats(VoxelVolume(np.arange(8, dtype=np.uint8).reshape(2, 2, 2)))
    {'min': 0, 'max': 7, 'mean': 3.5}
    """
    data = volume.data
    nz, ny, nx = (int(n) for n in data.shape)
    is_float = np.issubdtype(volume.dtype, np.floating)
    step = _slab_step(data, ny * nx * volume.dtype.itemsize)
    lo, hi, total, count, nans = math.inf, -math.inf, 0.0, 0, 0
    for z0 in range(0, nz, step):
        slab = data[z0 : z0 + step]
        if hasattr(slab, "compute"):
            slab = slab.compute()
        slab = np.asarray(slab)
        if is_float:
            finite = np.isfinite(slab)
            n_ok = int(np.count_nonzero(finite))
            nans += int(np.count_nonzero(np.isnan(slab)))
            if n_ok < slab.size:
                slab = slab[finite]
        else:
            n_ok = slab.size
        if n_ok == 0:
            continue
        lo = min(lo, float(slab.min()))
        hi = max(hi, float(slab.max()))
        total += float(slab.sum(dtype=np.float64))
        count += n_ok
    out: dict[str, Any]
    if count == 0:
        out = {"min": None, "max": None, "mean": None}
    elif is_float:
        out = {"min": lo, "max": hi, "mean": total / count}
    else:
        out = {"min": int(lo), "max": int(hi), "mean": total / count}
    if is_float:
        out["nan_count"] = nans
    return out


def _storage(data) -> str:
    if isinstance(data, np.memmap) or isinstance(getattr(data, "base", None), np.memmap):
        return "memmap"
    if isinstance(data, np.ndarray):
        return "memory"
    mod = type(data).__module__.split(".")[0]
    return {"dask": "dask", "zarr": "zarr"}.get(mod, type(data).__name__)


def describe_volume(volume: VoxelVolume, stats: bool = True) -> dict:
    """Summary of a :class:`VoxelVolume` (see :func:`describe`)."""
    nx, ny, nz = volume.shape_xyz
    meta = volume.meta or {}
    d: dict[str, Any] = {
        "kind": "volume",
        "name": volume.name,
        "format": meta.get("format", ""),
        "source": meta.get("source", ""),
        "shape_xyz": [nx, ny, nz],
        "voxels": nx * ny * nz,
        "dtype": volume.dtype.name,
        "spacing": [float(s) for s in volume.spacing],
        "unit": volume.unit,
        "origin": [float(s) for s in volume.origin],
        "extent": [float(n * s) for n, s in zip((nx, ny, nz), volume.spacing, strict=True)],
        "bytes": nx * ny * nz * volume.dtype.itemsize,
        "lazy": bool(volume.is_lazy),
        "storage": _storage(volume.data),
        "assumed": [str(a) for a in meta.get("assumed", [])],
    }
    if meta.get("levels"):  # a multiscale zarr store (geoshade.io.stores.zarr_io, OME-Zarr)
        d["levels"] = int(meta["levels"])
        d["ngff"] = str(meta.get("ngff") or "")
    if stats and volume.is_lazy and d["bytes"] > STATS_MAX_BYTES:
        # a store's metadata may declare any size (a 400-byte zarr.json: 100000^3 voxels):
        # statistics only where recorded or small
        vr = meta.get("value_range")
        d.update({"min": vr[0], "max": vr[1], "mean": None} if vr else
                 {"min": None, "max": None, "mean": None})
        d["assumed"].append(f"statistics not computed: {d['bytes'] / 2**30:,.1f} GiB is more "
                            f"than the {STATS_MAX_BYTES >> 30} GiB info reads"
                            + ("; min and max as the ingest recorded them" if vr else ""))
    elif stats:
        d.update(volume_stats(volume))
    return d




def describe(model, stats: bool = True) -> dict:
    """A JSON-serialisable summary of a model, for ``geoshade info``.

    Parameters
    ----------
    model : VoxelVolume or another model with a describer in ``DESCRIBERS``
    stats : bool
        Compute value statistics (min, max, mean), streaming through the data in slabs.

    Returns
    -------
    dict
        For a volume: ``kind`` ("volume"), ``name``, ``format``, ``source``, ``shape_xyz``,
        ``voxels``, ``dtype``, ``spacing``, ``unit``, ``origin``, ``extent``, ``bytes``,
        ``lazy``, ``storage``, ``assumed`` (notes on values not found in the file) and
        ``min``, ``max``, ``mean`` (plus ``nan_count`` for floats).

    Examples
    --------
    >>> import json, numpy as np
    >>> from geoshade.models import VoxelVolume
    >>> d = describe(VoxelVolume(np.ones((2, 3, 4), np.uint16), name="demo"))
    >>> d["kind"], d["shape_xyz"], d["bytes"], d["mean"]
    ('volume', [4, 3, 2], 48, 1.0)
    >>> _ = json.dumps(d)
    """
    for cls in type(model).__mro__:
        if cls in DESCRIBERS:
            d = formats.resolve(DESCRIBERS[cls])(model, stats=stats)
            if not d.get("format") and d.get("source"):   # the row the file was read by
                fmt = formats.find(d["source"], sniff=False)
                d["format"] = fmt.title if fmt is not None else ""
            return d
    return {"kind": type(model).__name__, "name": str(getattr(model, "name", ""))}


def _num(v) -> str:
    if v is None:
        return "-"
    if isinstance(v, float):
        return f"{v:.6g}"
    return str(v)


def _bytes(n: int) -> str:
    for unit in ("B", "KiB", "MiB", "GiB", "TiB"):
        if n < 1024 or unit == "TiB":
            return f"{n} B" if unit == "B" else f"{n:.1f} {unit}"
        n /= 1024
    return f"{n} B"  # pragma: no cover


def format_description(d: dict) -> str:
    """Human-readable multi-line text for a :func:`describe` dict.

    Examples
    --------
    >>> import numpy as np
    >>> from geoshade.models import VoxelVolume
    >>> text = format_description(describe(VoxelVolume(np.zeros((2, 3, 4), np.uint8))))
    >>> print(text.splitlines()[1])
      voxels   4 × 3 × 2 (x, y, z) = 24
    """
    if d.get("kind") == "grid":  # corner-point grid part
        return format_grid_description(d)
    if d.get("kind") == "field":  # a field over time (iso part)
        return format_field_description(d)
    if d.get("kind") in ("dem", "georaster"):  # rasters of heights and drapes (rasterio)
        return formats.resolve("geoshade.io.layers.dem:format_dem")(d)
    if d.get("kind") != "volume":
        head = f"{d.get('name') or '?'}  ({d.get('kind', '?')})"
        rest = [f"  {k:<8} {v}" for k, v in d.items() if k not in ("name", "kind")]
        return "\n".join([head, *rest])
    unit = f" {d['unit']}" if d.get("unit") else ""
    fmt = f", {d['format']}" if d.get("format") else ""
    lines = [
        f"{d.get('name') or '(unnamed)'}  (volume{fmt})",
        "  voxels   {} × {} × {} (x, y, z) = {:,}".format(*d["shape_xyz"], d["voxels"]),
        f"  dtype    {d['dtype']}, {_bytes(d['bytes'])}, "
        + ("lazy (" + d["storage"] + ")" if d["lazy"] else d["storage"]),
        "  spacing  " + " × ".join(_num(s) for s in d["spacing"]) + unit,
        "  size     " + " × ".join(_num(s) for s in d["extent"]) + unit,
        "  origin   " + ", ".join(_num(s) for s in d["origin"]) + unit,
    ]
    if "min" in d:
        vals = f"  values   min {_num(d['min'])}, max {_num(d['max'])}, mean {_num(d['mean'])}"
        if d.get("nan_count"):
            vals += f", {d['nan_count']:,} NaN"
        lines.append(vals)
    if d.get("levels"):
        ome = f", OME-Zarr {d['ngff']}" if d.get("ngff") else ""
        lines.append(f"  levels   {d['levels']} (multiscale{ome})")
    th = d.get("threshold")
    if th and th.get("labels"):  # a label image: which value is pore is the user's to say
        labs = th["labels"]
        text = ", ".join(f"{_num(e['value'])}: {100 * e['fraction']:.1f} %" for e in labs)
        offered = th.get("label_select") or [[e["value"]] * 2 for e in labs]  # every label
        uses = " or ".join(f"--select {_num(v)} {_num(v)}" for v, _ in offered)
        lines.append(f"  labels   {text} (a label image: which value is pore? {uses})")
    elif th and "otsu" in th:
        lo, hi = th["pore_select"]
        multi = ", ".join(_num(v) for v in th.get("multiotsu", []))
        lines.append(f"  threshold Otsu {_num(th['otsu'])}"
                     + (f"; multi-Otsu ({th['classes']} classes) {multi}" if multi else ""))
        why = th.get("pore_text") or f"dark phase ≤ Otsu {_num(th['otsu'])} taken as pore"
        lines.append(f"  pores    --select {_num(lo)} {_num(hi)} (or --select auto): {why}")
    elif th and th.get("note"):
        lines.append(f"  threshold {th['note']}")
    if d.get("source"):
        lines.append(f"  source   {d['source']}")
    for note in d.get("assumed", []):
        lines.append(f"  assumed  {note}")
    return "\n".join(lines)


# --- corner-point grids (grid part) ----------------------------------------------------------
def describe_grid(grid, stats: bool = True) -> dict:
    """Summary of a :class:`~geoshade.models.CornerPointGrid` for ``geoshade info``.

    Keys: ``kind`` ("grid"), ``name``, ``format``, ``source``, ``dims``, ``cells``,
    ``active_cells``, ``properties`` (names; with ``stats`` also ``property_stats``: NaN-aware
    min/max/mean over the active cells), ``steps``, ``step_dates``, ``step_keywords``,
    ``faults`` (name and face count), ``wells``, ``units``, ``unit_system`` (METRIC, FIELD,
    LAB, PVT-M from a deck; '' where the file does not say), ``geometry`` (corner-point,
    block-centred, IJK index space), ``index_space``, ``missing_includes`` (INCLUDEs not found,
    read with ``skip_missing``), ``skipped_keywords`` (keywords the reader did not use),
    ``mapaxes``, ``bounds``.

    Examples
    --------
    >>> import numpy as np
    >>> from geoshade.models import CornerPointGrid
    >>> coord = np.array([[[0, 0, 0, 0, 0, 1], [0, 1, 0, 0, 1, 1]],
    ...                   [[1, 0, 0, 1, 0, 1], [1, 1, 0, 1, 1, 1]]], float)
    >>> g = CornerPointGrid(coord, np.repeat([[[0.0, 1.0]]], 2, 0).repeat(2, 1))
    >>> d = describe_grid(g)
    >>> d["dims"], d["active_cells"], d["bounds"]
    ([1, 1, 1], 1, [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]])
    """
    nx, ny, nz = grid.dims
    meta = grid.meta if isinstance(grid.meta, dict) else {}
    nsteps = len(grid.steps) or len(grid.step_dates)
    keywords = list(meta.get("step_keywords") or (grid.steps[0] if grid.steps else []))
    d: dict[str, Any] = {
        "kind": "grid", "name": grid.name, "format": meta.get("format", ""),
        "source": meta.get("source", grid.name), "dims": [nx, ny, nz], "cells": nx * ny * nz,
        "active_cells": grid.nactive, "properties": list(grid.properties), "steps": nsteps,
        "step_dates": list(grid.step_dates), "step_keywords": keywords,
        "faults": [{"name": f.name, "faces": len(f.faces)} for f in grid.faults],
        "wells": [w.name for w in meta.get("wells", [])], "units": grid.units,
        "unit_system": meta.get("unit_system", ""),
        "geometry": meta.get("geometry", "corner-point"),
        "index_space": bool(meta.get("index_space", False)),
        "missing_includes": list(meta.get("missing_includes", [])),
        "skipped_keywords": list(meta.get("skipped_keywords", [])),
        "restart": (meta.get("restart") or {}).get("summary", ""),
        "mapaxes": None if grid.mapaxes is None else [float(v) for v in grid.mapaxes],
        "bounds": None,
    }
    if not isinstance(grid.zcorn, np.ndarray):  # a grid store: streamed, never whole
        d["bounds"], stats_lazy = _lazy_grid_numbers(grid, stats)
        if stats:
            d["property_stats"] = stats_lazy
        stats = False
    else:
        d["bounds"] = [[float(v) for v in row] for row in grid.bounds()]
    if stats:
        act = grid.active
        ps = {}
        for name, arr in grid.properties.items():
            v = np.asarray(arr)[act]
            v = v[np.isfinite(v)] if v.dtype.kind == "f" else v
            ps[name] = ({"min": float(v.min()), "max": float(v.max()), "mean": float(v.mean())}
                        if v.size else {"min": None, "max": None, "mean": None})
        d["property_stats"] = ps

    d["sim_wells"] = formats.resolve(_RESTART_WELLS + "describe_restart_wells")(grid)
    d.update(formats.resolve(_CASE_PARTS + "describe_case_parts")(grid))  # LGRs, media, bounds
    return d


def _lazy_grid_numbers(grid, stats: bool) -> tuple[list, dict]:
    """Bounds and property statistics of a grid whose arrays are dask arrays (a grid store),
    in one streamed dask pass: chunk by chunk, never a whole array in memory."""
    import dask
    import dask.array as da


    c = np.asarray(grid.coord).reshape(-1, 6)
    z = da.asarray(grid.zcorn)
    zu = da.where(abs(z) <= MAX_COORDINATE, z, np.nan)
    todo = [da.nanmin(zu), da.nanmax(zu)]
    names = list(grid.properties) if stats else []
    act = da.asarray(grid.actnum) != 0
    for name in names:
        v = da.asarray(grid.properties[name])
        v = da.where(act & da.isfinite(v), v, np.nan).astype(np.float64)
        todo += [da.nanmin(v), da.nanmax(v), da.nanmean(v)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN chunks
        out = [float(x) for x in dask.compute(*todo)]
    xs, ys = np.r_[c[:, 0], c[:, 3]], np.r_[c[:, 1], c[:, 4]]
    bounds = [[float(xs.min()), float(ys.min()), out[0]], [float(xs.max()), float(ys.max()),
                                                           out[1]]]
    ps = {}
    for q, name in enumerate(names):
        lo, hi, mean = out[2 + 3 * q: 5 + 3 * q]
        ps[name] = ({"min": lo, "max": hi, "mean": mean} if np.isfinite(lo)
                    else {"min": None, "max": None, "mean": None})
    return bounds, ps


def format_grid_description(d: dict) -> str:
    """Text for a :func:`describe_grid` dict (see :func:`format_description`)."""
    fmt = f", {d['format']}" if d.get("format") else ""
    b = d["bounds"]
    geometry = d.get("geometry", "corner-point")
    unit = "(cells)" if d.get("index_space") else d.get("units") or ""
    lines = [f"{d.get('name') or '(unnamed)'}  (corner-point grid{fmt})",
             "  cells    {} × {} × {} = {:,}, active {:,}".format(*d["dims"], d["cells"],
                                                                 d["active_cells"]),
             f"  bounds   x {_num(b[0][0])}..{_num(b[1][0])}, y {_num(b[0][1])}..{_num(b[1][1])}"
             f", depth {_num(b[0][2])}..{_num(b[1][2])} {unit}".rstrip()]
    if geometry != "corner-point":
        lines.append(f"  geometry {geometry}" + (": no geometry was read, unit cells (x = I, "
                                                 "y = J, depth = K)" if d.get("index_space")
                                                 else ""))
    if d.get("unit_system"):
        lines.append(f"  units    {d['unit_system']}"
                     + (f" (lengths in {d['units']})" if d.get("units") else ""))
    ps = d.get("property_stats", {})
    for name in d["properties"]:
        st = ps.get(name)
        rng = f"  {_num(st['min'])}..{_num(st['max'])}, mean {_num(st['mean'])}" if st else ""
        lines.append(f"  property {name}{rng}")
    if d["steps"]:
        dates = d["step_dates"]
        span = f" ({dates[0]} .. {dates[-1]})" if dates and dates[0] else ""
        lines.append(f"  steps    {d['steps']}{span}: {', '.join(d['step_keywords'])}")
    if d["faults"]:
        lines.append(f"  faults   {len(d['faults'])}: " + ", ".join(
            f"{f['name']} ({f['faces']} faces)" for f in d["faults"]))
    if d.get("restart"):
        lines.append(f"  restart  {d['restart']}")
    if d["wells"]:
        lines.append(f"  wells    {len(d['wells'])}: {', '.join(d['wells'])}")

    lines += formats.resolve(_RESTART_WELLS + "format_restart_wells")(d.get("sim_wells"))
    lines += formats.resolve(_CASE_PARTS + "format_case_parts")(d)
    if d.get("mapaxes"):
        lines.append("  mapaxes  " + " ".join(_num(v) for v in d["mapaxes"]))
    if d.get("skipped_keywords"):
        lines.append(f"  skipped  {len(d['skipped_keywords'])} keywords not used: "
                     + ", ".join(d["skipped_keywords"]))
    if d.get("missing_includes"):
        n = len(d["missing_includes"])
        lines.append(f"  missing  {n} INCLUDE file{'s' if n != 1 else ''}: "
                     + ", ".join(d["missing_includes"]))
    if d.get("source"):
        lines.append(f"  source   {d['source']}")
    return "\n".join(lines)


# --- fields over time (iso part) ---------------------------------------------------------------
def describe_field(field: FieldSeries, stats: bool = True) -> dict:
    """What ``geoshade info PATH --keyword NAME`` says of a field over time, as the iso part
    reads it: its nodes, where the file's coordinates place them (uneven, flipped, depth made
    z up: the notes), its steps with their dates (a dimension that is not time is never a step:
    ``selected``), the quantities it can be coloured by, and the values of the step shown
    first (one step read, not all).

    >>> import numpy as np
    >>> d = describe_field(FieldSeries(np.arange(24.0).reshape(2, 3, 4), name="P",
    ...                                coords=([0, 1, 2, 3], [0, 1, 5], [-9, 0])))
    >>> d["kind"], d["nodes_xyz"], d["steps"], d["z"], d["min"], d["max"]
    ('field', [4, 3, 2], 1, [-9.0, 0.0], 0.0, 23.0)
    """
    meta = field.meta or {}
    b = field.bounds()
    times = [str(t) for t in field.times]
    dated = [t for t in times if not t.startswith("step ")]
    d: dict[str, Any] = {
        "kind": "field", "name": field.name, "format": meta.get("format", ""),
        "source": str(field.source or ""), "nodes_xyz": [int(n) for n in field.shape_xyz],
        "steps": int(field.nsteps), "first": dated[0] if dated else None,
        "last": dated[-1] if dated else None,
        "placement": ("corner-point cells" if field.is_cornerpoint else
                      "the file's coordinates (uneven)" if field.is_rectilinear else
                      "regular nodes"),
        "x": [float(b[0, 0]), float(b[1, 0])], "y": [float(b[0, 1]), float(b[1, 1])],
        "z": [float(b[0, 2]), float(b[1, 2])], "length_unit": field.length_unit or "",
        "unit": field.unit or "", "notes": [str(n) for n in meta.get("notes") or ()],
        "selected": dict(meta.get("selected") or {}),
        "quantities": list(meta.get("quantities") or field.properties),
    }
    if stats:
        k = int(meta.get("default_step", -1)) % max(field.nsteps, 1)
        v = np.asarray(field.step(k), np.float64)
        act = field.active
        ok = np.isfinite(v) & (True if act is None else np.asarray(act, bool))
        d["step_shown"] = times[k] if times else f"step {k}"
        if ok.any():
            d.update(min=float(v[ok].min()), max=float(v[ok].max()),
                     mean=float(v[ok].mean()))
        d["nan_count"] = int((~np.isfinite(v)).sum())
    return d


def format_field_description(d: dict) -> str:
    """The text of :func:`describe_field`'s dict."""
    unit = f" {d['length_unit']}" if d.get("length_unit") else ""
    nx, ny, nz = d["nodes_xyz"]
    steps = (f"{d['steps']} ({d['first']} .. {d['last']})" if d.get("first") else
             f"{d['steps']} (no dates)")
    fmt = f", {d['format']}" if d.get("format") else ""
    lines = [f"{d.get('name') or '(unnamed)'}  (field over time{fmt})",
             f"  nodes    {nx} × {ny} × {nz} (x, y, z) = {nx * ny * nz:,}",
             f"  steps    {steps}",
             f"  placed   by {d['placement']}: x {_num(d['x'][0])}..{_num(d['x'][1])}, "
             f"y {_num(d['y'][0])}..{_num(d['y'][1])}, "
             + (f"depth {_num(d['z'][0])}..{_num(d['z'][1])}{unit}"
                if d["placement"] == "corner-point cells" else
                f"z {_num(d['z'][0])}..{_num(d['z'][1])}{unit} (up)")]
    if "min" in d:
        u = f" {d['unit']}" if d.get("unit") else ""
        lines.append(f"  values   min {_num(d['min'])}, max {_num(d['max'])}, mean "
                     f"{_num(d['mean'])}{u} at {d['step_shown']}"
                     + (f", {d['nan_count']:,} NaN" if d.get("nan_count") else ""))
    for dim, value in (d.get("selected") or {}).items():
        lines.append(f"  selected {dim} = {value} (not time)")
    if d.get("quantities"):
        lines.append(f"  colour   by {', '.join(map(str, d['quantities']))}")
    lines += [f"  note     {n}" for n in d.get("notes") or ()]
    if d.get("source"):
        lines.append(f"  source   {d['source']}")
    return "\n".join(lines)


#: model type -> function(model, stats) -> dict, or the ``"module:function"`` that names it
DESCRIBERS: dict[type, str | Callable[..., dict]] = {
    VoxelVolume: describe_volume, CornerPointGrid: describe_grid, FieldSeries: describe_field,
    StackModel: "geoshade.io.layers.stackfile:describe_stacks",
    SummaryTable: "geoshade.io.grids.summary:describe_summary"}
