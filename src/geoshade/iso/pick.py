"""Picking in the isosurface view: the point of the shown surface a pixel's ray meets first.

The surface is the one drawn now: the shown step's field (inactive, NaN and infinite nodes
outside, as the GPU gets them: cells with such a corner left out, or closing the surface with
``caps``) at the current level, triangulated by the GPU's own table in the cells the ray crosses
only (:func:`geoshade.compute.pick.cell_isosurface`). On a regular grid
those cells come from a walk through the field (at most ``nx + ny + nz``); on a corner-point
grid from the boxes of the cell columns, nearest first, until a hit is nearer than the next.
The value is the colour property interpolated at the hit (as the GPU interpolates it), or the
level where the surface has one colour.
"""

from __future__ import annotations

import weakref

import numpy as np

from geoshade.compute.mesh.marching_cubes import CORNERS, EDGES, OUTSIDE, OUTSIDE_BELOW, case_table
from geoshade.compute.pick import (
    CHUNK_CELLS,
    Ray,
    cell_isosurface,
    ray_boxes,
    ray_cells,
    ray_triangles,
)
from geoshade.iso.api import _cell_centres
from geoshade.iso.diff import DELTA
from geoshade.iso.options import field_reports
from geoshade.models.steps import step_label
from geoshade.render.pick import Pick, nearest_with_refinements, register_picker
from geoshade.styles.units import value_unit

_CACHE: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _cornerpoint_geometry(view):
    """(node positions (nz, ny, nx, 3) x, y, depth — x, y, z on a rectilinear grid; column
    boxes lo, hi (ny-1, nx-1, 3)) of a corner-point or rectilinear field, made once per field
    (nodes without coordinates sit where the renderer puts them: at the minimum corner)."""

    entry = _CACHE.setdefault(view, {})
    key = id(view.field)
    if entry.get("geometry", (None,))[0] != key:
        f = view.field
        c = f.node_positions() if f.is_rectilinear else _cell_centres(f)
        ok = np.isfinite(c).all(axis=-1)
        c = np.where(ok[..., None], c, c[ok].min(axis=0))
        cmin, cmax = c.min(axis=0), c.max(axis=0)  # (ny, nx, 3)
        lo = np.minimum.reduce([cmin[:-1, :-1], cmin[1:, :-1], cmin[:-1, 1:], cmin[1:, 1:]])
        hi = np.maximum.reduce([cmax[:-1, :-1], cmax[1:, :-1], cmax[:-1, 1:], cmax[1:, 1:]])
        entry["geometry"] = (key, c, lo, hi)
    return entry["geometry"][1:]


def _step(view, k: int):
    """(values, colour property or None) of step ``k``, read once per step."""
    f, name = view.field, view.options.color_by
    entry = _CACHE.setdefault(view, {})
    key = (id(f), k, name)
    if entry.get("step", (None,))[0] != key:
        prop = f.property_step(name, k) if name is not None else None
        entry["step"] = (key, f.step(k), prop)
    return entry["step"][1:]


def _surface(view, cells, values, prop, positions):
    """(triangles, owners, vertex properties), corner positions and the cells kept, of
    ``cells`` ((m, 3) x, y, z of the marching-cubes cells) at the level."""
    f = view.field
    node = cells[:, None, :] + CORNERS[None, :, :]  # (m, 8, 3) x, y, z
    x, y, z = node[..., 0], node[..., 1], node[..., 2]
    v = np.asarray(values[z, y, x], np.float32)
    bad = ~np.isfinite(v) | (v <= OUTSIDE_BELOW)
    if f.active is not None:
        bad |= ~np.asarray(f.active, bool)[z, y, x]
    if not view.options.caps:  # open surface: a cell with an outside corner makes nothing
        whole = ~bad.any(axis=1)
        cells, node, v, bad = cells[whole], node[whole], v[whole], bad[whole]
        x, y, z = node[..., 0], node[..., 1], node[..., 2]
    v = np.where(bad, OUTSIDE, v)
    pos = node.astype(np.float64) if positions is None else positions[z, y, x]
    cp = None if prop is None else np.asarray(prop, np.float64)[z, y, x]
    return cell_isosurface(v, view.level, pos, cp), pos, cells, v, cp


def _triangle_code(level: float, v, cp, owner, q: int) -> float:
    """The code a categorical surface draws triangle ``q`` in, as the GPU does (color_mode 2):
    the code of the node nearer to the crossing on its first vertex's edge."""

    row = int(owner[q])
    slot = q - int(np.searchsorted(owner, row))          # the triangle's place in its cell
    weights = (1 << np.arange(8)).astype(np.int64)
    s = np.float32(level)
    k = int(((v[row] < s).astype(np.int64) * weights).sum())
    edge = int(case_table()[k, 3 * slot])
    a, b = int(EDGES[edge, 0]), int(EDGES[edge, 1])
    va, vb = np.float32(v[row, a]), np.float32(v[row, b])
    out = va <= OUTSIDE_BELOW or vb <= OUTSIDE_BELOW
    w = np.float32(0.5) if out else (s - va) / (vb - va)
    return float(cp[row, a] if w < 0.5 else cp[row, b])


def _nearest(ray: Ray, cells, values, prop, positions, view):
    """(t, cell row, hit point, property) of the nearest triangle, or None."""
    (tri, owner, tp), pos, cells, v, cp = _surface(view, cells, values, prop, positions)
    if owner.size == 0:
        return None
    t, u, w = ray_triangles(ray, tri)
    q = int(np.argmin(t))
    if not np.isfinite(t[q]):
        return None
    pv = None if tp is None else float((1 - u[q] - w[q]) * tp[q, 0] + u[q] * tp[q, 1]
                                       + w[q] * tp[q, 2])
    if pv is not None and getattr(view, "categories", None) is not None:
        pv = _triangle_code(view.level, v, cp, owner, q)   # one code per triangle, not a blend
    row = int(owner[q])
    point = ray.at(float(t[q]))
    corner = int(np.argmin(np.linalg.norm(pos[row] - point, axis=1)))
    return float(t[q]), cells[row] + CORNERS[corner], point, pv


@register_picker("iso")
def pick_iso(view, ray: Ray) -> Pick | None:
    """The surface point an IsoView shows along ``ray`` (display world), or None; a point of
    a local grid refinement's surface where it is the nearer (named by its LGR and local I, J,
    K: :mod:`geoshade.iso.refined`)."""
    return nearest_with_refinements(view, ray, _pick_surface)


def _pick_surface(view, ray: Ray) -> Pick | None:
    if view.empty_reason() is not None:
        return None
    f = view.field
    nz, ny, nx = f.shape
    values, prop = _step(view, view.step)
    flip = -1.0 if f.is_cornerpoint else 1.0     # corner-point nodes: x, y, depth
    if f.is_cornerpoint or f.is_rectilinear:
        exag = float(view.options.exaggeration)
        local = ray.transformed(np.diag([1.0, 1.0, flip / exag, 1.0]))
        positions, lo, hi = _cornerpoint_geometry(view)
        t_in, t_out = ray_boxes(local, lo, hi)
        cand = np.flatnonzero((t_in <= t_out).ravel())
        order = np.argsort(t_in.ravel()[cand], kind="stable")
        cand, starts = cand[order], t_in.ravel()[cand][order]
        per = max(1, CHUNK_CELLS // max(nz - 1, 1))
        best = None
        for s in range(0, cand.size, per):
            if best is not None and starts[s] > best[0]:
                break
            cy, cx = np.divmod(cand[s:s + per], nx - 1)
            zz = np.arange(nz - 1)
            cells = np.stack([np.repeat(cx, nz - 1), np.repeat(cy, nz - 1),
                              np.tile(zz, cx.size)], axis=1)
            hit = _nearest(local, cells, values, prop, positions, view)
            if hit is not None and (best is None or hit[0] < best[0]):
                best = hit
    else:
        local = ray.transformed(np.linalg.inv(view.model_matrix))  # node index space
        cells, _, _ = ray_cells(local, (nx - 1, ny - 1, nz - 1))
        best = None if cells.size == 0 else _nearest(local, cells, values, prop, None, view)
    if best is None:
        return None
    t, node, point, pv = best
    i, j, k = (int(v) for v in node)
    if f.is_cornerpoint:
        world = np.array([point[0], point[1], -point[2]])
        depth = float(point[2])
        label = ijk = f"I={i + 1} J={j + 1} K={k + 1}"
    elif f.is_rectilinear:
        world, depth = np.asarray(point, np.float64), float(point[2])
        label, ijk = f"node x={i} y={j} z={k}", ""
    else:
        m = f.index_to_world()
        world = m[:3, :3] @ point + m[:3, 3]
        depth = float(world[2])
        label, ijk = f"node x={i} y={j} z={k}", ""
    value, name, unit = _value(view, pv)
    # a field placed by its file's coordinates has z up (depth taken as -z): an elevation
    vertical = "elevation" if (f.meta or {}).get("axes") and not f.is_cornerpoint else "depth"
    return Pick("iso", (i, j, k), (float(world[0]), float(world[1]), float(world[2])), depth,
                value, name, unit, label=label, ijk_label=ijk,
                length_unit=view._length_unit(), extra=_extra(view), t=t, vertical=vertical)


def _value(view, pv) -> tuple:
    """(value, name, unit) of the read-out."""

    f, name = view.field, view.options.color_by
    if name is not None:
        return pv, DELTA + name if view.differenced(name) else name, value_unit(f, name)
    return float(view.level), f.name or "field", value_unit(f, f.name)


def _extra(view) -> tuple[tuple[str, str], ...]:

    f = view.field
    out = [("step", step_label(view.step, f.times, field_reports(f)))]
    if view.options.color_by is not None:
        out.insert(0, ("surface", f"{f.name or 'field'} = {view.level:g}"))
    return tuple(out)


__all__ = ["pick_iso"]
