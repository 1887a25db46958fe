"""Picking in the stacks view: the first interval a pixel's ray passes through that is drawn.

The ray is cast in index space (x, y in columns, z in levels) as the ray caster does: clipped to
the box, the near/far planes and the section; it crosses the columns in order (a 2D walk,
:func:`geoshade.compute.pick.ray_cells`), and in each column the intervals of the GPU form
(float16 heights, as the layouts hold them); the first with a material that is not hidden or
fully transparent (in borehole mode: a log interval of a borehole column) is the pick. With the
smooth top (terrain) a descending ray meets the top where it crosses the surface interpolated
between column centres, as the ray caster draws it (sampled per column, then bisected).
"""

from __future__ import annotations

import numpy as np

from geoshade.compute.pick import Ray, ray_boxes, ray_cells
from geoshade.render.pick import Pick, register_picker


def _section_clip(ray: Ray, section, t0: float, t1: float) -> tuple[float, float]:
    """``[t0, t1]`` cut by the index-space section ``(nx, ny, nz, d)`` (keeps ``n·p <= d``)."""
    if section is None:
        return t0, t1
    n, d = np.asarray(section[:3], float), float(section[3])
    s0 = float(n @ ray.origin) - d
    sd = float(n @ ray.direction)
    if abs(sd) < 1e-20:
        return (t0, t1) if s0 <= 0 else (1.0, 0.0)
    tc = -s0 / sd
    return (t0, min(t1, tc)) if sd > 0 else (max(t0, tc), t1)


def _surface(tops: np.ndarray, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """The smooth top (levels) at index-space points: bilinear between column centres, a
    column without material replaced by the mean of the others of its dual cell (as
    ``raycast.frag``'s ``surf_h``)."""
    ny, nx = tops.shape
    qx, qy = x - 0.5, y - 0.5
    ix, iy = np.floor(qx).astype(np.int64), np.floor(qy).astype(np.int64)
    fx, fy = qx - ix, qy - iy
    h = np.stack([tops[np.clip(iy + b, 0, ny - 1), np.clip(ix + a, 0, nx - 1)]
                  for b in (0, 1) for a in (0, 1)])               # (4, ...)
    ok = h > -1e29
    n = ok.sum(axis=0)
    mean = np.where(n > 0, np.where(ok, h, 0.0).sum(axis=0) / np.maximum(n, 1), 0.0)
    h = np.where(ok, h, mean)
    return (1 - fy) * ((1 - fx) * h[0] + fx * h[1]) + fy * ((1 - fx) * h[2] + fx * h[3])


def _smooth_hits(view, r: Ray, cols, c_in, c_out, samples: int = 33) -> np.ndarray:
    """Per crossed column, the t where the (descending) ray first is at or below the smooth
    top, inf where it stays above it."""
    from geoshade.render.visuals.stacks.visual import column_tops

    tops = column_tops(view.gpu)[..., 0].astype(np.float64)
    o, d = np.asarray(r.origin, float), np.asarray(r.direction, float)

    def gap(t):
        p = o + t[..., None] * d
        return p[..., 2] - _surface(tops, p[..., 0], p[..., 1])

    t = c_in[:, None] + (c_out - c_in)[:, None] * np.linspace(0.0, 1.0, samples)[None]
    below = gap(t) <= 0
    has = below.any(axis=1)
    k = np.argmax(below, axis=1)
    rows = np.arange(t.shape[0])
    hi = t[rows, k]
    lo = t[rows, np.maximum(k - 1, 0)]
    for _ in range(40):                      # bisection of [lo, hi] where k > 0
        mid = 0.5 * (lo + hi)
        down = gap(mid) <= 0
        hi = np.where(down, mid, hi)
        lo = np.where(down, lo, mid)
    return np.where(has, np.where(k > 0, hi, c_in), np.inf)


@register_picker("stacks")
def pick_stacks(view, ray: Ray) -> Pick | None:
    """The interval a StacksView shows along ``ray`` (display world), or None."""
    g, o, model = view.gpu, view.options, view.model
    m = view.model_matrix()
    r = ray.transformed(np.linalg.inv(m))  # index space
    lo, hi = view.visual.box(view.zlo())
    t0, t1 = (float(v) for v in ray_boxes(r, lo, hi))
    t0, t1 = _section_clip(r, view.section, t0, t1)
    if not t0 < t1:
        return None
    nx, ny = g.shape
    cols, c_in, c_out = ray_cells(Ray(r.origin, r.direction, t0, t1), (nx, ny))
    if cols.size == 0:
        return None
    c = cols[:, 0] + nx * cols[:, 1]
    cnt = g.count[c]
    if o.boreholes:
        cnt = np.where(g.flag[c], cnt, 0)
    if not cnt.any():
        return None
    # every interval of the crossed columns: (column row, interval index)
    row = np.repeat(np.arange(c.size), cnt)
    within = np.arange(row.size) - np.repeat(np.cumsum(cnt) - cnt, cnt)
    iv = g.first[c][row] + within
    end = g.end.astype(np.float16).astype(np.float64)
    top = end[iv]
    bottom = np.where(within > 0, end[iv - 1], 0.0)
    pal = g.mat[iv]
    alpha = view.palette()[:, 3]
    shown = (pal > 0) & (alpha[pal] > 0)
    if o.boreholes:
        shown &= g.log[iv]
    ta, tb = c_in[row], c_out[row]
    oz, dz = r.origin[2], r.direction[2]
    if getattr(view.visual, "smooth_top", False) and dz < 0:
        th_col = _smooth_hits(view, r, cols, c_in, c_out)
        ta = np.maximum(ta, th_col[row])
        z_hit = oz + dz * np.where(np.isfinite(th_col), th_col, 0.0)[row]
        is_top = iv == (g.first[c] + g.count[c] - 1)[row]
        top = np.where(is_top & (pal > 0), np.maximum(top, z_hit), top)
    if dz != 0:
        tl, th = (bottom - oz) / dz, (top - oz) / dz
        enter = np.maximum(ta, np.minimum(tl, th))
        leave = np.minimum(tb, np.maximum(tl, th))
        hit = shown & (leave > enter)
    else:
        za = oz
        enter = ta
        hit = shown & (bottom <= za) & (za < top)
    if not hit.any():
        return None
    q = np.flatnonzero(hit)[np.argmin(np.where(hit, enter, np.inf)[hit])]
    t = float(enter[q])
    p = r.at(t)  # index space
    cx, cy = (int(v) for v in cols[row[q]])
    col = cx + nx * cy
    terrain = getattr(view, "elevation", None) is not None   # palette = elevation bands
    code = int(model.legend.codes[0 if terrain else int(pal[q]) - 1])
    # the model's interval holding the point (the GPU form adds a leading empty interval)
    a, b = int(model.offsets[col]), int(model.offsets[col + 1])
    layer = max(0, int(np.searchsorted(model.starts[a:b], np.float32(p[2]), "right")) - 1)
    sp, og = np.asarray(model.spacing), np.asarray(model.origin)
    world = og + p * sp
    var = str(model.meta.get("variable", "") or "code")
    extra: tuple[tuple[str, str], ...] = (("material", str(model.legend.name_of(code))),)
    if model.borehole[col]:
        extra += (("borehole", "log" if bool(g.log[iv[q]]) else "model"),)
    unit = ""
    value: float | int = code
    if terrain:   # a terrain: the value is the height of the point, in the model's unit
        value, var, unit = float(world[2]), "elevation", view._length_unit()
    # z is up in a stack model: its vertical read-out is an elevation, never a depth
    return Pick("stacks", (cx, cy, layer), (float(world[0]), float(world[1]),
                                           float(world[2])), float(world[2]), value, var, unit,
                label=f"column x={cx} y={cy} interval {layer}",
                length_unit=view._length_unit(), extra=extra, t=t, vertical="elevation")


__all__ = ["pick_stacks"]
