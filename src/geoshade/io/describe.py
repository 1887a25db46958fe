"""What ``geoshade info PATH`` prints: a JSON-serialisable summary of a model.

Value statistics are computed in z-slabs of about ``SLAB_BYTES`` so that a volume larger than
memory is never read whole.  Other parts add a describer for their model type to
``DESCRIBERS``.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from geoshade.models import VoxelVolume

#: bytes read per slab when computing statistics
SLAB_BYTES = 64 << 20


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
    if stats:
        d.update(volume_stats(volume))
    return d


#: model type -> function(model, stats) -> dict; later parts register their models here
DESCRIBERS: dict[type, Callable[..., dict]] = {VoxelVolume: describe_volume}


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
            return DESCRIBERS[cls](model, stats=stats)
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
    if d.get("source"):
        lines.append(f"  source   {d['source']}")
    for note in d.get("assumed", []):
        lines.append(f"  assumed  {note}")
    return "\n".join(lines)
