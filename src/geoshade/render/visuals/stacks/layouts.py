"""Pack a model's GPU intervals into the arrays of each layout of Section 4.2 (numpy only).

Every layout stores an interval as the paper's RG16F pair ``(r, end)``: ``end`` the accumulated
height in levels, ``r = ±(palette index + 1)`` (palette index 0 = empty), negative for an
interval of a borehole log, 0 in an unused slot of the 1-Textures interval texture. The
fixed-size regions of 2-R-Supertexels, 3-L-Supertexels and 4-3D-Texture are filled after a
column's last interval with ``(±1, ztop)`` slots (negative in a borehole column): an empty
interval up to the box top, then empty intervals of no height, so a stack can be walked from
either end without knowing its length; their last slot tells whether the column holds a log (it
is a filler, or the column's top interval, which is the log's top in a borehole column).

============  ==========================================  ======================================
layout        objects                                     slot ``j`` of column ``(cx, cy)``
============  ==========================================  ======================================
textures      indices RG32UI ``nx × ny`` (first, count |  ``k = first + j`` at texel
              flag << 31); intervals RG16F ``w × h``,     ``(k % w, k // w)``
              ``w·h`` = the interval count (Eq. 3)
r-supertexels RG16F ``(nx·a) × (ny·b)``, ``a × b`` the    ``(cx·a + j % a, cy·b + j // a)``
              smallest-perimeter region with ``a·b ≥ m``
l-supertexels RG16F ``(nx·m) × ny``                       ``(cx·m + j, cy)``
texture3d     RG16F 3D ``nx × ny × m``                    ``(cx, cy, j)``
ssbo          indices ``uvec2[ncols]``, intervals         ``intervals[first + j]``
              ``uint[n]`` (``packHalf2x16``), std430
dense         R16UI 3D ``nx × ny × nz``: palette index,   (the dense baseline, not a stack
              bit 15 set in a borehole log                layout)
============  ==========================================  ======================================
"""

from __future__ import annotations

import numpy as np

from geoshade.compute.stacks import GpuIntervals, layout_plan
from geoshade.errors import InputError

#: how many palette indices an fp16 ``r`` holds exactly (integers up to 2048)
MAX_PALETTE = 2047


def encode_r(mat: np.ndarray, flag: np.ndarray) -> np.ndarray:
    """``±(mat + 1)`` as float16 (negative where ``flag``: borehole log intervals)."""
    return ((mat.astype(np.float32) + 1.0) * np.where(flag, -1.0, 1.0)).astype(np.float16)


def _slots(g: GpuIntervals, nslots: int, ztop16: np.float16) -> np.ndarray:
    """(ncols, nslots, 2) float16: each column's intervals, then filler slots."""
    ncols = g.count.size
    out = np.empty((ncols, nslots, 2), np.float16)
    out[..., 0] = encode_r(np.zeros(ncols, np.int32), g.flag)[:, None]
    out[..., 1] = ztop16
    col = np.repeat(np.arange(ncols), g.count)
    j = np.arange(g.n) - g.first[col]
    out[col, j, 0] = encode_r(g.mat, g.log)
    out[col, j, 1] = g.end.astype(np.float16)
    return out


def pack(layout: str, g: GpuIntervals, limits: dict | None = None) -> dict:
    """The arrays of ``layout`` for ``g``, and its plan (``compute.stacks.layout_plan``).

    Returns
    -------
    dict
        ``plan`` (shapes and consumed/wasted bytes), ``arrays`` (name -> numpy array in the
        shape the GPU object takes), ``ztop`` (the box top, as float16 rounds it).

    Examples
    --------
    >>> from geoshade.compute.stacks import gpu_intervals, synthetic_layers
    >>> g = gpu_intervals(synthetic_layers(6, 5, 20, max_intervals=4, seed=0))
    >>> p = pack("l-supertexels", g)
    >>> p["arrays"]["intervals"].shape == (5, 6 * g.max_count, 2)
    True
    >>> sum(a.nbytes for a in p["arrays"].values()) == p["plan"]["consumed"]
    True
    """
    if int(g.mat.max(initial=0)) > MAX_PALETTE:
        raise InputError(f"stacks: {int(g.mat.max())} materials; at most {MAX_PALETTE} fit fp16")
    nx, ny = g.shape
    ztop16 = np.float16(g.ztop)
    if layout == "dense":
        return {"plan": dense_plan(g), "arrays": dense_arrays(g), "ztop": float(ztop16)}
    plan = layout_plan(layout, g.shape, g.n, g.max_count, limits)
    objs = plan["objects"]
    if layout in ("textures", "ssbo"):
        r = encode_r(g.mat, g.log)
        e = g.end.astype(np.float16)
        cf = (g.count.astype(np.uint64) | (g.flag.astype(np.uint64) << np.uint64(31)))
        index = np.stack([g.first.astype(np.uint32), cf.astype(np.uint32)], axis=-1)
        if layout == "textures":
            w, h = objs["intervals"]
            iv = np.zeros((w * h, 2), np.float16)
            iv[:g.n, 0], iv[:g.n, 1] = r, e
            arrays = {"indices": index.reshape(ny, nx, 2), "intervals": iv.reshape(h, w, 2)}
        else:
            words = np.zeros(max(g.n, 1), np.uint32)
            words[:g.n] = (r.view(np.uint16).astype(np.uint32)
                           | (e.view(np.uint16).astype(np.uint32) << np.uint32(16)))
            arrays = {"indices": index.reshape(-1, 2), "intervals": words}
    else:
        m = plan["slots"]
        s = _slots(g, m, ztop16).reshape(ny, nx, m, 2)
        if layout == "r-supertexels":
            a, b = plan["super"]
            arrays = {"intervals": s.reshape(ny, nx, b, a, 2).transpose(0, 2, 1, 3, 4)
                      .reshape(ny * b, nx * a, 2)}
        elif layout == "l-supertexels":
            arrays = {"intervals": s.reshape(ny, nx * m, 2)}
        else:
            arrays = {"intervals": s.transpose(2, 0, 1, 3)}
    arrays = {k: np.ascontiguousarray(v) for k, v in arrays.items()}
    return {"plan": plan, "arrays": arrays, "ztop": float(ztop16)}


def dense_levels(g: GpuIntervals) -> int:
    """Levels of the dense baseline texture: whole levels up to the box top."""
    return max(1, int(np.ceil(g.ztop)))


def dense_plan(g: GpuIntervals) -> dict:
    nx, ny = g.shape
    nz = dense_levels(g)
    return {"layout": "dense", "name": "dense 3D texture", "intervals": g.n,
            "max_intervals": g.max_count, "objects": {"dense": (nx, ny, nz)},
            "consumed": nx * ny * nz * 2, "wasted": 0, "super": None}


def dense_arrays(g: GpuIntervals, chunk: int = 1 << 22) -> dict:
    """R16UI ``(nz, ny, nx)``: palette index of the interval holding level k + ½, bit 15 set
    for a borehole log interval (built in slabs of rows of about ``chunk`` voxels)."""
    nx, ny = g.shape
    nz = dense_levels(g)
    col = np.repeat(np.arange(nx * ny), g.count)
    keys = col.astype(np.float64) * (nz + 2) + g.end.astype(np.float16).astype(np.float64)
    val = (g.mat | (g.log.astype(np.int32) << 15)).astype(np.uint16)
    dense = np.zeros((nz, ny, nx), np.uint16)
    rows = max(1, chunk // max(1, nx * nz))
    for y0 in range(0, ny, rows):
        cols = np.arange(y0 * nx, min(ny, y0 + rows) * nx)
        q = cols[:, None].astype(np.float64) * (nz + 2) + np.arange(nz) + 0.5
        idx = np.searchsorted(keys, q.ravel(), side="right").reshape(q.shape)
        ok = idx < (g.first[cols] + g.count[cols])[:, None]
        v = np.where(ok, val[np.minimum(idx, max(g.n - 1, 0))], 0) if g.n else \
            np.zeros(q.shape, np.uint16)
        dense[:, y0:y0 + rows, :] = v.T.reshape(nz, -1, nx)
    return {"dense": dense}
