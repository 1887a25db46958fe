"""Corner-point grid geometry: points on pillars, cell centres, node depths, conformity, and
the paper's 16-bit ZCORN packing.

All functions take the arrays of :class:`~geoshade.models.CornerPointGrid` (``coord`` (nx+1,
ny+1, 6), ``zcorn`` (2nx, 2ny, 2nz), indexed ``[i, j, k]``) and work on k-slabs so that a
1e8-cell grid never needs more than a few hundred MB of temporaries.
"""

from __future__ import annotations

import numpy as np

from geoshade.errors import InputError
from geoshade.models import CornerPointGrid

#: cells per slab in the slab-wise loops
SLAB_CELLS = 1 << 22


def _slabs(nx: int, ny: int, nz: int):
    step = max(1, SLAB_CELLS // max(1, nx * ny))
    for k0 in range(0, nz, step):  # slabs of layers, not cells
        yield k0, min(nz, k0 + step)


def pillar_points(coord: np.ndarray, z: np.ndarray) -> np.ndarray:
    """Points at depth ``z`` on the pillars (linear between a pillar's top and bottom points).

    Parameters
    ----------
    coord : (..., 6) array
        Pillars ``x1 y1 z1 x2 y2 z2`` (e.g. ``grid.coord``, or a part of it).
    z : array
        Depths; shape ``coord.shape[:-1]`` plus any trailing axes (one pillar's depths along
        them).  A pillar with ``z1 == z2`` keeps its top ``x, y``.

    Returns
    -------
    (*z.shape, 3) float64

    Examples
    --------
    >>> coord = np.array([[0.0, 0.0, 1000.0, 10.0, 0.0, 1100.0]])
    >>> pillar_points(coord, np.array([[1050.0, 1100.0]])).tolist()
    [[[5.0, 0.0, 1050.0], [10.0, 0.0, 1100.0]]]
    """
    coord = np.asarray(coord, np.float64)
    z = np.asarray(z, np.float64)
    extra = z.ndim - (coord.ndim - 1)
    if extra < 0 or z.shape[:coord.ndim - 1] != coord.shape[:-1]:
        raise InputError(f"pillar_points: z shape {z.shape} does not start with the pillar "
                         f"shape {coord.shape[:-1]}")
    x1, y1, z1, x2, y2, z2 = (coord[..., q].reshape(coord.shape[:-1] + (1,) * extra)
                              for q in range(6))
    dz = z2 - z1
    t = np.where(dz != 0, (z - z1) / np.where(dz != 0, dz, 1.0), 0.0)
    out = np.empty((*z.shape, 3))
    out[..., 0] = x1 + t * (x2 - x1)
    out[..., 1] = y1 + t * (y2 - y1)
    out[..., 2] = z
    return out


def _centres_for(coord, zcorn, i, j, k) -> np.ndarray:
    """Mean of the 8 corners of cells (i, j, k) (broadcastable index arrays)."""
    acc = None
    for a in (0, 1):
        for b in (0, 1):
            pil = coord[i + a, j + b]  # (..., 6)
            for c in (0, 1):
                z = np.asarray(zcorn[2 * i + a, 2 * j + b, 2 * k + c], np.float64)
                p = pillar_points(np.broadcast_to(pil, (*z.shape, 6)), z)
                acc = p if acc is None else acc + p
    return acc / 8.0


def cell_centres(grid: CornerPointGrid, cells=None, dtype=np.float64) -> np.ndarray:
    """Cell centres: the mean of each cell's 8 corner points.

    Parameters
    ----------
    grid : CornerPointGrid
    cells : (m, 3) int array, optional
        Only these cells (0-based i, j, k).
    dtype : numpy dtype
        Of the result (float64 by default; float32 halves the memory of a full grid).

    Returns
    -------
    (nx, ny, nz, 3) array, or (m, 3) for ``cells``

    Examples
    --------
    >>> from geoshade.compute.grid.synthetic import synthetic_grid
    >>> g = synthetic_grid(4, 3, 2, faults=False)
    >>> c = cell_centres(g)
    >>> c.shape, np.allclose(c, g.corners().mean(axis=3))
    ((4, 3, 2, 3), True)
    >>> np.allclose(cell_centres(g, [[1, 2, 1]]), c[1, 2, 1])
    True
    """
    coord = np.asarray(grid.coord)
    zcorn = grid.zcorn
    nx, ny, nz = grid.dims
    if cells is not None:
        ijk = np.asarray(cells, np.int64).reshape(-1, 3)
        if len(ijk) and ((ijk < 0).any() or (ijk >= (nx, ny, nz)).any()):
            raise InputError(f"cell_centres: cells outside the grid {grid.dims}")
        return _centres_for(coord, zcorn, ijk[:, 0], ijk[:, 1], ijk[:, 2]).astype(dtype)
    out = np.empty((nx, ny, nz, 3), dtype)
    # on a pillar x = ax + bx z, y = ay + by z (b = 0 for a flat pillar)
    dz = coord[..., 5] - coord[..., 2]
    bx = np.where(dz != 0, (coord[..., 3] - coord[..., 0]) / np.where(dz != 0, dz, 1), 0.0)
    by = np.where(dz != 0, (coord[..., 4] - coord[..., 1]) / np.where(dz != 0, dz, 1), 0.0)
    ax, ay = coord[..., 0] - bx * coord[..., 2], coord[..., 1] - by * coord[..., 2]
    for k0, k1 in _slabs(nx, ny, nz):
        sx = np.zeros((nx, ny, k1 - k0))
        sy, sz = np.zeros_like(sx), np.zeros_like(sx)
        for a in (0, 1):
            for b in (0, 1):
                p = (slice(a, a + nx), slice(b, b + ny))
                zab = zcorn[a::2, b::2, 2 * k0:2 * k1].astype(np.float64)
                zsum = zab[:, :, 0::2] + zab[:, :, 1::2]  # top + bottom corner on this pillar
                sx += 2 * ax[p][..., None] + bx[p][..., None] * zsum
                sy += 2 * ay[p][..., None] + by[p][..., None] * zsum
                sz += zsum
        out[:, :, k0:k1, 0] = sx / 8
        out[:, :, k0:k1, 1] = sy / 8
        out[:, :, k0:k1, 2] = sz / 8
    return out


def node_depths(zcorn: np.ndarray, dtype=np.float32) -> np.ndarray:
    """(nx+1, ny+1, nz+1) depth of each grid node: the mean of the cell corners that meet there.

    For a conforming grid (:func:`is_conforming`) every corner at a node has the same depth,
    so this is exact; it is the vertex array of the paper's first approach (with
    :func:`pillar_points` for x, y).

    Examples
    --------
    >>> z = np.zeros((2, 2, 2), np.float32); z[..., 1] = 10
    >>> node_depths(z)[..., 1].tolist()
    [[10.0, 10.0], [10.0, 10.0]]
    """
    zc = np.asarray(zcorn)
    nx, ny, nz = zc.shape[0] // 2, zc.shape[1] // 2, zc.shape[2] // 2
    acc = np.zeros((nx + 1, ny + 1, nz + 1), np.float64)
    cnt = np.zeros((nx + 1, ny + 1, nz + 1), np.float64)
    for a in (0, 1):
        for b in (0, 1):
            for c in (0, 1):
                acc[a:a + nx, b:b + ny, c:c + nz] += zc[a::2, b::2, c::2]
                cnt[a:a + nx, b:b + ny, c:c + nz] += 1
    return np.asfortranarray(acc / cnt, dtype)


def is_conforming(grid: CornerPointGrid, tol: float = 0.0) -> bool:
    """True if every pair of neighbour cells shares its face's corners (within ``tol``).

    Neighbours along i and j share their pillars, so their shared face matches when the 4
    corner depths agree; along k the bottom of a cell must meet the top of the next.  A grid
    that passes can be drawn with the paper's first approach (one vertex per node).

    Examples
    --------
    >>> from geoshade.compute.grid.synthetic import synthetic_grid
    >>> is_conforming(synthetic_grid(6, 5, 3, faults=False)), is_conforming(synthetic_grid(6, 5, 3))
    (True, False)
    """
    z = grid.zcorn
    nx, ny, nz = grid.dims
    for k0, k1 in _slabs(nx, ny, nz):
        s = z[:, :, 2 * k0:2 * k1]
        if np.any(np.abs(s[1:-1:2].astype(np.float64) - s[2::2]) > tol):
            return False
        if np.any(np.abs(s[:, 1:-1:2].astype(np.float64) - s[:, 2::2]) > tol):
            return False
        kk = z[:, :, 2 * k0 + 1:min(2 * k1 + 1, 2 * nz - 1):2]
        kn = z[:, :, 2 * k0 + 2:min(2 * k1 + 2, 2 * nz):2]
        if np.any(np.abs(kk.astype(np.float64) - kn) > tol):
            return False
    return True


def orientation_sign(coord: np.ndarray, i: np.ndarray, j: np.ndarray, zc8: np.ndarray) -> float:
    """+1 / -1: the sign of d(x, y, depth)/d(i, j, k) over cells (the majority), 0 if none.

    ``i, j`` are the cells' column indices, ``zc8`` ``(n, 8)`` their corner depths in ZCORN
    corner order (corner ``c`` = ``a + 2b + 4c'``); the corners lie on their pillars in
    ``coord`` (nx+1, ny+1, 6).
    """
    if len(i) == 0:
        return 0.0
    coord = np.asarray(coord, np.float64)
    zc8 = np.asarray(zc8, np.float64)
    pts = np.empty((len(i), 8, 3))
    for c in range(8):  # corners, not cells
        a, b = c & 1, c >> 1 & 1
        pil = coord[i + a, j + b]
        z = zc8[:, c]
        dz = pil[:, 5] - pil[:, 2]
        t = np.where(dz != 0, (z - pil[:, 2]) / np.where(dz != 0, dz, 1.0), 0.0)
        pts[:, c, 0] = pil[:, 0] + t * (pil[:, 3] - pil[:, 0])
        pts[:, c, 1] = pil[:, 1] + t * (pil[:, 4] - pil[:, 1])
        pts[:, c, 2] = z
    sel = np.array([[c for c in range(8) if c >> ax & 1] for ax in range(3)])
    nsel = np.array([[c for c in range(8) if not c >> ax & 1] for ax in range(3)])
    jac = np.stack([pts[:, sel[ax]].mean(1) - pts[:, nsel[ax]].mean(1) for ax in range(3)], 1)
    return float(np.sign(np.sign(np.linalg.det(jac)).sum()))


def _pillar_of_columns(n2: int) -> np.ndarray:
    """For corner columns 0..2n-1 along one axis, the pillar each lies on: (c + 1) // 2."""
    return (np.arange(n2) + 1) // 2


def zcorn_quantiser(zmin: float, zmax: float, bits: int = 16) -> tuple[float, float]:
    """``(z0, scale)`` of the paper's global packing of depths ``zmin..zmax`` into ``bits``
    bits (``code = rint((z - z0) / scale)``): what :func:`zcorn_quantise` uses, for quantising
    only some corners (the drawn faces') with the same codes.

    >>> z0, scale = zcorn_quantiser(1000.0, 1065.535, 16)
    >>> z0, round(scale, 9)
    (1000.0, 0.001)
    """
    levels = (1 << bits) - 1
    return float(zmin), ((float(zmax) - float(zmin)) / levels if zmax > zmin else 1.0)


def zcorn_quantise(zcorn: np.ndarray, bits: int = 16, mode: str = "global"):
    """Pack ZCORN into ``bits``-bit unsigned codes (the paper: two 16-bit depths per 4 bytes).

    ``z ≈ z0 + code · scale``.  ``mode="global"`` is the paper's packing: one ``z0`` and
    ``scale`` for the whole grid (error up to half of ``(zmax - zmin) / (2**bits - 1)``).
    ``mode="pillar"`` keeps one ``z0``/``scale`` per pillar ((nx+1, ny+1) float32 arrays,
    +8 bytes per pillar): the error shrinks to half of each pillar's own depth range per level.

    Parameters
    ----------
    zcorn : (2nx, 2ny, 2nz) array
    bits : int
        1 to 16.
    mode : {"global", "pillar"}

    Returns
    -------
    codes : (2nx, 2ny, 2nz) uint16, F-order (same layout as ``zcorn``)
    z0, scale : float, or (nx+1, ny+1) float32 arrays for ``mode="pillar"``
    max_abs_error : float
        Largest ``|dequantised - zcorn|`` (float64 arithmetic).

    Examples
    --------
    >>> z = np.linspace(1000, 1100, 16, dtype=np.float32).reshape(2, 2, 4)
    >>> codes, z0, scale, err = zcorn_quantise(z)
    >>> codes.dtype, float(z0), err <= scale / 2 + 1e-9
    (dtype('uint16'), 1000.0, True)
    >>> bool(np.abs(zcorn_dequantise(codes, z0, scale) - z).max() <= err + 1e-4)
    True
    """
    if not isinstance(bits, int | np.integer) or not 1 <= bits <= 16:
        raise InputError(f"zcorn_quantise: bits must be an integer 1..16, got {bits!r}")
    if mode not in ("global", "pillar"):
        raise InputError(f"zcorn_quantise: mode must be 'global' or 'pillar', got {mode!r}")
    z = np.asarray(zcorn)
    levels = (1 << bits) - 1
    n2x, n2y, _ = z.shape
    if mode == "global":
        z0, scale = zcorn_quantiser(float(z.min()), float(z.max()), bits)
        z0_col = np.float64(z0)
        sc_col = np.float64(scale)
    else:
        cmin = z.min(axis=2).astype(np.float64)
        cmax = z.max(axis=2).astype(np.float64)
        pi, pj = _pillar_of_columns(n2x), _pillar_of_columns(n2y)
        pmin = np.full((n2x // 2 + 1, n2y // 2 + 1), np.inf)
        pmax = np.full_like(pmin, -np.inf)
        np.minimum.at(pmin, (pi[:, None], pj[None, :]), cmin)
        np.maximum.at(pmax, (pi[:, None], pj[None, :]), cmax)
        z0 = pmin.astype(np.float32)
        scale = np.where(pmax > pmin, (pmax - pmin) / levels, 1.0).astype(np.float32)
        z0_col = z0.astype(np.float64)[pi][:, pj][..., None]
        sc_col = scale.astype(np.float64)[pi][:, pj][..., None]
    codes = np.empty(z.shape, np.uint16, order="F")
    err = 0.0
    nz2 = z.shape[2]
    step = max(1, (1 << 22) // max(1, n2x * n2y))  # corner layers per slab: ~4e6 values
    for c0 in range(0, nz2, step):  # slabs of corner layers, in place in one float64 buffer
        s = z[:, :, c0:c0 + step].astype(np.float64)
        q = s - z0_col
        q /= sc_col
        np.rint(q, out=q)
        np.clip(q, 0, levels, out=q)
        codes[:, :, c0:c0 + step] = q
        q *= sc_col
        q += z0_col
        q -= s
        err = max(err, float(np.abs(q, out=q).max(initial=0.0)))
    return codes, z0, scale, err


def zcorn_dequantise(codes: np.ndarray, z0, scale) -> np.ndarray:
    """Inverse of :func:`zcorn_quantise`: float32 depths ``z0 + codes · scale``.

    Examples
    --------
    >>> zcorn_dequantise(np.array([[[0, 2]]], np.uint16), 1000.0, 0.5).tolist()
    [[[1000.0, 1001.0]]]
    """
    c = np.asarray(codes)
    if np.ndim(z0) == 0:
        return (np.float64(z0) + c * np.float64(scale)).astype(np.float32)
    pi, pj = _pillar_of_columns(c.shape[0]), _pillar_of_columns(c.shape[1])
    z0c = np.asarray(z0, np.float64)[pi][:, pj][..., None]
    scc = np.asarray(scale, np.float64)[pi][:, pj][..., None]
    return np.asfortranarray(z0c + c * scc, np.float32)
