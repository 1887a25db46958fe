"""Ray casting for picking: what a pixel's ray meets first, in numpy (no GL).

The Views pick on the CPU, so a pick is the same on llvmpipe and on any GPU. Every function
here takes a ray ``p(t) = origin + t · direction`` with ``t`` in ``[t0, t1]`` (for a pixel:
``t = 0`` on the near plane, ``t = 1`` on the far plane, see :class:`Ray`) in the model's own
coordinates, and bounds its work by what the ray crosses:

- :func:`ray_boxes` — slab test against many axis-aligned boxes at once;
- :func:`ray_cells` — the cells of a regular 2D or 3D grid a ray crosses, in order (a DDA
  written with sorted plane crossings: at most ``sum(shape)`` cells);
- :func:`ray_triangles` — Möller–Trumbore against many triangles at once;
- :func:`quad_triangles` — cells given by 8 corners split into triangles along the diagonal
  the renderer uses;
- :func:`cell_isosurface` — marching cubes of a few cells (the table the GPU uses, the same
  triangles as :func:`geoshade.compute.mesh.marching_cubes.marching_cubes`);
- :func:`grid_ray_hit` — the first shown cell of a corner-point grid along a ray: the columns
  whose boxes the ray crosses, in order, in chunks, stopping at the first hit (a 1e8-cell grid is
  never copied; the work is the columns crossed).

>>> ray = Ray(np.array([0.5, 0.5, 10.0]), np.array([0.0, 0.0, -16.0]))
>>> cells, t_in, t_out = ray_cells(ray, (2, 2, 4))
>>> cells[:, 2].tolist(), float(t_in[0])
([3, 2, 1, 0], 0.375)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from geoshade.compute.grid.geometry import pillar_points
from geoshade.compute.mesh.marching_cubes import (
    EDGES,
    OUTSIDE_BELOW,
    case_table,
    triangle_counts,
)

#: cells tested per chunk of :func:`grid_ray_hit` (12 triangles each: bounded temporaries)
CHUNK_CELLS = 1 << 14
#: relative tolerance of the triangle test: a ray through a shared edge hits both triangles
EDGE_TOL = 1e-9


@dataclass(frozen=True)
class Ray:
    """A ray ``p(t) = origin + t · direction`` for ``t0 <= t <= t1``.

    origin:    (3,) float64
    direction: (3,) float64  (not normalised: a pixel's ray spans near to far for t in [0, 1])
    t0, t1:    float         the visible part of the ray
    eye:       (3,) float64 or None   where a perspective camera's rays start (None:
               orthographic, every ray parallel); for back-face culling
    """

    origin: np.ndarray
    direction: np.ndarray
    t0: float = 0.0
    t1: float = 1.0
    eye: np.ndarray | None = None

    def at(self, t) -> np.ndarray:
        """Points at ``t`` (scalar: (3,); array: (n, 3))."""
        t = np.asarray(t, np.float64)
        return self.origin + t[..., None] * self.direction

    def transformed(self, matrix) -> Ray:
        """The same ray through the affine 4×4 ``matrix`` (``t`` keeps its meaning).

        >>> m = np.diag([2.0, 2.0, 2.0, 1.0])
        >>> Ray(np.ones(3), np.ones(3)).transformed(m).at(1.0).tolist()
        [4.0, 4.0, 4.0]
        """
        m = np.asarray(matrix, np.float64)
        eye = None if self.eye is None else m[:3, :3] @ self.eye + m[:3, 3]
        return Ray(m[:3, :3] @ self.origin + m[:3, 3], m[:3, :3] @ self.direction,
                   self.t0, self.t1, eye)

    def clipped(self, t0: float, t1: float) -> Ray:
        """The same ray seen only for ``t0 <= t <= t1``."""
        return Ray(self.origin, self.direction, float(t0), float(t1), self.eye)


def unproject(inverse_view_projection, ndc_x: float, ndc_y: float, eye=None) -> Ray:
    """The ray of a point of the picture in normalised device coordinates: from the near plane
    (``t = 0``) to the far plane (``t = 1``), in world coordinates (``eye``: the perspective
    camera's position, kept for back-face culling).

    >>> r = unproject(np.eye(4), 0.25, -0.5)
    >>> r.origin.tolist(), r.direction.tolist()
    ([0.25, -0.5, -1.0], [0.0, 0.0, 2.0])
    """
    inv = np.asarray(inverse_view_projection, np.float64)
    near = inv @ np.array([ndc_x, ndc_y, -1.0, 1.0])
    far = inv @ np.array([ndc_x, ndc_y, 1.0, 1.0])
    near, far = near[:3] / near[3], far[:3] / far[3]
    return Ray(near, far - near, eye=None if eye is None else np.asarray(eye, np.float64))


def ray_boxes(ray: Ray, lo, hi) -> tuple[np.ndarray, np.ndarray]:
    """``(t_in, t_out)`` of the ray against axis-aligned boxes ``[lo, hi]`` (``(..., k)``, k = 2
    or 3: the first k coordinates of the ray), clipped to ``[t0, t1]``; a miss has
    ``t_in > t_out``.

    >>> ray = Ray(np.array([-1.0, 0.5, 0.5]), np.array([4.0, 0.0, 0.0]))
    >>> t_in, t_out = ray_boxes(ray, np.zeros((2, 3)), np.array([[1, 1, 1], [1, 0.4, 1.0]]))
    >>> float(t_in[0]), float(t_out[0]), bool(t_in[1] > t_out[1])
    (0.25, 0.5, True)
    """
    lo, hi = np.asarray(lo, np.float64), np.asarray(hi, np.float64)
    k = lo.shape[-1]
    o, d = ray.origin[:k], ray.direction[:k]
    zero = d == 0
    inv = np.divide(1.0, d, out=np.zeros(k), where=~zero)
    ta, tb = (lo - o) * inv, (hi - o) * inv
    t_lo, t_hi = np.minimum(ta, tb), np.maximum(ta, tb)
    if zero.any():  # parallel to a slab: inside it everywhere or nowhere
        inside = (o >= lo) & (o <= hi)
        t_lo = np.where(zero, np.where(inside, -np.inf, np.inf), t_lo)
        t_hi = np.where(zero, np.where(inside, np.inf, -np.inf), t_hi)
    return np.maximum(t_lo.max(axis=-1), ray.t0), np.minimum(t_hi.min(axis=-1), ray.t1)


def ray_cells(ray: Ray, shape) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The cells of a regular grid the ray crosses, in order along it.

    Cell ``c`` covers ``[c, c + 1]`` along each axis (index space); ``shape`` has 2 or 3 entries
    (the first 2 or 3 coordinates of the ray are used).

    Returns
    -------
    cells : (m, k) int64
    t_in, t_out : (m,) float64
        Where the ray enters and leaves each cell (``t_in`` ascending, within ``[t0, t1]``).
    """
    shape = np.asarray(shape, np.int64)
    k = shape.size
    box_in, box_out = ray_boxes(ray, np.zeros(k), shape.astype(np.float64))
    t_a, t_b = float(box_in), float(box_out)
    if not t_a < t_b:
        return np.zeros((0, k), np.int64), np.zeros(0), np.zeros(0)
    o, d = ray.origin[:k], ray.direction[:k]
    ts = [np.array([t_a, t_b])]
    for ax in range(k):
        if d[ax] == 0:
            continue
        p0, p1 = sorted((o[ax] + t_a * d[ax], o[ax] + t_b * d[ax]))
        planes = np.arange(np.floor(p0) + 1, np.ceil(p1))
        ts.append((planes - o[ax]) / d[ax])
    t = np.unique(np.clip(np.concatenate(ts), t_a, t_b))
    t_in, t_out = t[:-1], t[1:]
    keep = t_out > t_in
    t_in, t_out = t_in[keep], t_out[keep]
    mid = 0.5 * (t_in + t_out)
    cells = np.floor(o + mid[:, None] * d).astype(np.int64)
    np.clip(cells, 0, shape - 1, out=cells)
    return cells, t_in, t_out


def ray_triangles(ray: Ray, triangles) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Möller–Trumbore for ``(n, 3, 3)`` triangles: ``(t, u, v)`` each ``(n,)``; ``t`` is inf
    where the triangle is missed, parallel, degenerate or outside ``[t0, t1]``; the hit point is
    ``(1 - u - v) A + u B + v C``. A ray through an edge hits both triangles that share it.

    >>> tri = np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0]]], float)
    >>> t, u, v = ray_triangles(Ray(np.array([0.2, 0.3, 1.0]), np.array([0, 0, -2.0])), tri)
    >>> float(t[0]), float(u[0]), float(v[0])
    (0.5, 0.2, 0.3)
    """
    tri = np.asarray(triangles, np.float64).reshape(-1, 3, 3)
    o, d = ray.origin, ray.direction
    a = tri[:, 0]
    e1, e2 = tri[:, 1] - a, tri[:, 2] - a
    p = np.cross(d, e2)
    det = np.einsum("ij,ij->i", e1, p)
    scale = np.linalg.norm(e1, axis=1) * np.linalg.norm(e2, axis=1) * np.linalg.norm(d)
    ok = np.abs(det) > 1e-14 * scale
    inv = np.divide(1.0, det, out=np.zeros_like(det), where=ok)
    s = o - a
    u = np.einsum("ij,ij->i", s, p) * inv
    q = np.cross(s, e1)
    v = (q @ d) * inv
    t = np.einsum("ij,ij->i", e2, q) * inv
    ok &= (u >= -EDGE_TOL) & (v >= -EDGE_TOL) & (u + v <= 1.0 + EDGE_TOL)
    ok &= (t >= ray.t0) & (t <= ray.t1)
    return np.where(ok, t, np.inf), u, v


def quad_triangles(corners, quads) -> np.ndarray:
    """Cells given by their corners, as triangles: each quad ``(A, B, C, D)`` of ``quads``
    split along ``A–C`` into ``ABC`` and ``ACD``.

    Parameters
    ----------
    corners : (m, c, 3) float
    quads : (f, 4) int
        Corner numbers of each face (e.g. the grid renderer's face table).

    Returns
    -------
    (m, 2f, 3, 3) float64: triangle ``2q`` and ``2q + 1`` are face ``q``'s.

    >>> sq = np.array([[[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]], float)
    >>> quad_triangles(sq, [[0, 1, 2, 3]])[0, :, :, :2].tolist()
    [[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]], [[0.0, 0.0], [1.0, 1.0], [0.0, 1.0]]]
    """
    c = np.asarray(corners, np.float64)
    q = np.asarray(quads, np.int64)
    idx = np.stack([q[:, [0, 1, 2]], q[:, [0, 2, 3]]], axis=1).reshape(-1, 3)  # (2f, 3)
    return c[:, idx]


def cell_isosurface(corner_values, level: float, corner_positions,
                    corner_props=None) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """Marching cubes of a few cells, with the table, classification and vertex rule (Eq. (1))
    of :func:`geoshade.compute.mesh.marching_cubes.marching_cubes` (the GPU's).

    Parameters
    ----------
    corner_values : (m, 8) float
        Node values at the cells' corners (corner ``p`` at offset ``(p & 1, p >> 1 & 1,
        p >> 2 & 1)`` along x, y, z), outside nodes at or below
        :data:`~geoshade.compute.mesh.marching_cubes.OUTSIDE_BELOW`; compared in float32.
    level : float
    corner_positions : (m, 8, 3) float
        Where the corners are.
    corner_props : (m, 8) float, optional
        A quantity interpolated to the vertices as the positions are.

    Returns
    -------
    triangles : (n, 3, 3) float64
    owner : (n,) int64
        The cell (row of the inputs) of each triangle.
    props : (n, 3) float64 or None
        The quantity at each triangle's vertices.
    """
    v = np.asarray(corner_values, np.float32).reshape(-1, 8)
    pos = np.asarray(corner_positions, np.float64).reshape(-1, 8, 3)
    s = np.float32(level)
    weights = (1 << np.arange(8)).astype(np.int64)
    K = ((v < s).astype(np.int64) * weights).sum(axis=1)
    ntri = triangle_counts()[K].astype(np.int64)
    cells = np.flatnonzero(ntri)
    rows = case_table()[K[cells], :15].astype(np.int64)
    keep = rows >= 0
    edge = rows[keep]
    vcell = np.repeat(cells, keep.sum(axis=1))
    ca, cb = EDGES[edge, 0], EDGES[edge, 1]
    va, vb = v[vcell, ca], v[vcell, cb]
    out_end = (va <= OUTSIDE_BELOW) | (vb <= OUTSIDE_BELOW)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(out_end, np.float32(0.5), (s - va) / (vb - va)).astype(np.float32)
    pa, pb = pos[vcell, ca], pos[vcell, cb]
    p = pa + t[:, None].astype(np.float64) * (pb - pa)
    owner = np.repeat(cells, ntri[cells])
    props = None
    if corner_props is not None:
        cp = np.asarray(corner_props, np.float64).reshape(-1, 8)
        qa, qb = cp[vcell, ca], cp[vcell, cb]
        props = (qa + t * (qb - qa)).reshape(-1, 3)
    return p.reshape(-1, 3, 3), owner, props


def gather(a, *index) -> np.ndarray:
    """``a[index]`` for broadcastable integer index arrays, reading only those elements: numpy
    arrays and memmaps directly, dask and zarr arrays through ``vindex``."""
    if isinstance(a, np.ndarray):
        return a[index]
    if hasattr(a, "vindex"):
        r = a.vindex[tuple(np.broadcast_arrays(*index))]
        return np.asarray(r.compute() if hasattr(r, "compute") else r)
    return np.asarray(a)[index]


# --- corner-point grids ---------------------------------------------------------------------
@dataclass(frozen=True)
class GridHit:
    """The first shown cell along a ray: ``cell`` (i, j, k), ``face`` (0..5 = I+ J+ K+ I- J-
    K-), ``t`` on the ray and ``point`` (x, y, depth in the grid's coordinates)."""

    cell: tuple[int, int, int]
    face: int
    t: float
    point: np.ndarray


def column_boxes(coord, depth_range) -> tuple[np.ndarray, np.ndarray]:
    """``(lo, hi)`` each ``(nx, ny, 3)``: a box around each column of cells between the depths
    ``depth_range`` (x, y from the column's four pillars at both depths; pillars are straight,
    so a cell between those depths lies inside)."""
    c = np.asarray(coord, np.float64)
    z0, z1 = (float(v) for v in depth_range)
    z = np.broadcast_to(np.array([z0, z1]), (*c.shape[:2], 2))
    xy = pillar_points(c, z)[..., :2]  # (nx+1, ny+1, 2, 2)
    pmin, pmax = xy.min(axis=2), xy.max(axis=2)
    cmin = np.minimum.reduce([pmin[:-1, :-1], pmin[1:, :-1], pmin[:-1, 1:], pmin[1:, 1:]])
    cmax = np.maximum.reduce([pmax[:-1, :-1], pmax[1:, :-1], pmax[:-1, 1:], pmax[1:, 1:]])
    shape = cmin.shape[:2]
    lo = np.concatenate([cmin, np.full((*shape, 1), z0)], axis=-1)
    hi = np.concatenate([cmax, np.full((*shape, 1), z1)], axis=-1)
    return lo, hi


def cell_corners(coord, zcorn, cells) -> np.ndarray:
    """(m, 8, 3) corner points (x, y, depth) of ``cells`` ((m, 3) i, j, k): corner
    ``a + 2b + 4c`` along i, j, k, as :meth:`CornerPointGrid.corners` numbers them."""
    ijk = np.asarray(cells, np.int64).reshape(-1, 3)
    i, j, k = ijk[:, 0], ijk[:, 1], ijk[:, 2]
    out = np.empty((ijk.shape[0], 8, 3))
    for c in range(8):
        a, b, cc = c & 1, c >> 1 & 1, c >> 2 & 1
        z = gather(zcorn, 2 * i + a, 2 * j + b, 2 * k + cc).astype(np.float64)
        pil = gather(coord, i + a, j + b).astype(np.float64)
        out[:, c] = pillar_points(pil, z)
    return out


def drawn_faces(zcorn, shown, cells, hide_faults: bool = False) -> np.ndarray:
    """(m, 6) bool: which faces (0..5 = I+ J+ K+ I- J- K-) of the shown ``cells`` ((m, 3)) are
    drawn, by the rule of :func:`geoshade.compute.grid.faces.visible_faces` (boundary, a
    neighbour not shown, or corner depths that differ across the face), read locally: only
    the cells' and their neighbours' ZCORN. ``hide_faults``: as the view's ``faults="hide"``,
    faces against a shown neighbour are never drawn.

    >>> from geoshade.compute.grid.synthetic import synthetic_grid
    >>> g = synthetic_grid(3, 3, 3, faults=False, inactive_fraction=0)
    >>> drawn_faces(g.zcorn, g.active, [[1, 1, 1], [0, 1, 1]]).astype(int).tolist()
    [[0, 0, 0, 0, 0, 0], [0, 0, 0, 1, 0, 0]]
    """
    c = np.asarray(cells, np.int64).reshape(-1, 3)
    dims = np.asarray(shown.shape, np.int64)
    out = np.zeros((c.shape[0], 6), bool)
    bits = np.array([[u, v] for u in (0, 1) for v in (0, 1)])  # the face's 4 corners
    for f in range(6):
        axis, plus = f % 3, f < 3
        step = np.zeros(3, np.int64)
        step[axis] = 1 if plus else -1
        nb = c + step
        exists = np.all((nb >= 0) & (nb < dims), axis=1)
        nbc = np.where(exists[:, None], nb, c)
        nb_shown = exists & np.asarray(shown[nbc[:, 0], nbc[:, 1], nbc[:, 2]], bool)
        vis = ~nb_shown
        if not hide_faults and exists.any():
            others = [d for d in range(3) if d != axis]
            idx = np.empty((c.shape[0], 4, 3), np.int64)
            idx[..., axis] = (2 * c[:, axis] + (1 if plus else 0))[:, None]
            for q, d in enumerate(others):
                idx[..., d] = 2 * c[:, d][:, None] + bits[None, :, q]
            jdx = idx.copy()
            jdx[..., axis] += 1 if plus else -1
            jdx[..., axis] = np.clip(jdx[..., axis], 0, 2 * dims[axis] - 1)
            mine = gather(zcorn, idx[..., 0], idx[..., 1], idx[..., 2])
            theirs = gather(zcorn, jdx[..., 0], jdx[..., 1], jdx[..., 2])
            vis |= exists & np.any(mine != theirs, axis=1)
        out[:, f] = vis
    return out


def front_facing(corners, quads, ray: Ray, orientation: float) -> np.ndarray:
    """(m, f) bool: faces the renderer's back-face cull keeps (its test, in the cells' space):
    ``orientation · (C - A) × (D - B) · to_eye >= 0``, ``to_eye`` from the face's centre to the
    eye (perspective) or against the ray (orthographic); ``orientation`` is +1 or -1 as the
    corner order turns in that space (0: nothing is culled)."""
    c = np.asarray(corners, np.float64)
    q = np.asarray(quads, np.int64)
    a, b, cc, d = (c[:, q[:, n]] for n in range(4))  # (m, f, 3)
    n = np.cross(cc - a, d - b)
    if ray.eye is None:
        to_eye = np.broadcast_to(-ray.direction, n.shape)
    else:
        to_eye = ray.eye - 0.25 * (a + b + cc + d)
    return float(orientation) * np.einsum("mfk,mfk->mf", n, to_eye) >= 0


def grid_ray_hit(coord, zcorn, shown, ray: Ray, quads, depth_range, hide_faults: bool = False,
                 boxes=None, chunk_cells: int = CHUNK_CELLS,
                 cull: float = 0.0) -> GridHit | None:
    """The first drawn face of a shown cell of a corner-point grid that ``ray`` meets.

    Parameters
    ----------
    coord : (nx+1, ny+1, 6), zcorn : (2nx, 2ny, 2nz)
        The grid (:class:`~geoshade.models.CornerPointGrid`); only the pillars and the ZCORN of
        the columns the ray crosses (and of their neighbours) are read.
    shown : (nx, ny, nz) bool
        The cells drawn.
    ray : Ray
        In grid coordinates (x, y, depth).
    quads : (6, 4) int
        Corners of faces 0..5, split along their A–C diagonal as the renderer does.
    depth_range : (zmin, zmax)
        Depths holding every cell (e.g. ``grid.bounds()[:, 2]``).
    hide_faults : bool
        Faces against a shown neighbour are not drawn (:func:`drawn_faces`).
    boxes : (lo, hi), optional
        :func:`column_boxes` (kept by a caller that picks often).
    chunk_cells : int
        Cells tested per chunk.
    cull : float
        0: every drawn face counts (the renderer's counting frame); +1 or -1: the faces it
        culls as back faces do not (:func:`front_facing`, the grid's orientation).

    Returns
    -------
    GridHit or None
    """
    ny = coord.shape[1] - 1
    nz = zcorn.shape[2] // 2
    lo, hi = boxes if boxes is not None else column_boxes(coord, depth_range)
    t_in, t_out = ray_boxes(ray, lo, hi)
    cand = np.flatnonzero((t_in <= t_out).ravel())
    if cand.size == 0:
        return None
    t_in, t_out = t_in.ravel()[cand], t_out.ravel()[cand]
    order = np.argsort(t_in, kind="stable")
    cand, t_in, t_out = cand[order], t_in[order], t_out[order]
    ci, cj = np.divmod(cand, ny)
    o, d = ray.origin, ray.direction
    span = float(depth_range[1]) - float(depth_range[0])
    eps = 1e-9 * max(span, 1.0)
    per = max(1, chunk_cells // max(nz, 1))
    ab = np.array([0, 1])
    best_t, best = np.inf, None
    for s in range(0, cand.size, per):
        if t_in[s] > best_t:
            break
        i, j = ci[s:s + per], cj[s:s + per]
        da, db = o[2] + t_in[s:s + per] * d[2], o[2] + t_out[s:s + per] * d[2]
        dmin, dmax = np.minimum(da, db) - eps, np.maximum(da, db) + eps
        z = gather(zcorn, (2 * i)[:, None, None, None] + ab[None, :, None, None],
                   (2 * j)[:, None, None, None] + ab[None, None, :, None],
                   np.arange(2 * nz)[None, None, None, :]).astype(np.float64)
        z = z.reshape(i.size, 4, nz, 2)
        zmin, zmax = z.min(axis=(1, 3)), z.max(axis=(1, 3))  # (C, nz)
        sh = np.asarray(shown[i[:, None], j[:, None], np.arange(nz)[None, :]], bool)
        sel = sh & (zmax >= dmin[:, None]) & (zmin <= dmax[:, None])
        col, kk = np.nonzero(sel)
        if col.size == 0:
            continue
        cells = np.stack([i[col], j[col], kk], axis=1)
        faces = drawn_faces(zcorn, shown, cells, hide_faults)  # (m, 6)
        keep = faces.any(axis=1)
        cells, faces = cells[keep], faces[keep]
        if cells.size == 0:
            continue
        corners = cell_corners(coord, zcorn, cells)
        if cull:
            faces &= front_facing(corners, quads, ray, cull)
        tri = quad_triangles(corners, quads)  # (m, 12, 3, 3)
        t, _, _ = ray_triangles(ray, tri.reshape(-1, 3, 3))
        t = np.where(np.repeat(faces, 2, axis=1), t.reshape(cells.shape[0], -1), np.inf)
        q = int(np.argmin(t))
        tq = float(t.flat[q])
        if tq < best_t:
            m, tri_no = divmod(q, t.shape[1])
            best_t = tq
            c = cells[m]
            best = GridHit((int(c[0]), int(c[1]), int(c[2])), tri_no // 2, tq, ray.at(tq))
    return best


__all__ = ["CHUNK_CELLS", "EDGE_TOL", "GridHit", "Ray", "cell_corners", "cell_isosurface",
           "column_boxes", "drawn_faces", "front_facing", "gather", "grid_ray_hit",
           "quad_triangles", "ray_boxes", "ray_cells", "ray_triangles", "unproject"]
