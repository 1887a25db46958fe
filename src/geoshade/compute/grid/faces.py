"""Visible faces of a corner-point grid, as the paper defines them (approaches 2 and 3).

A face of a shown cell is visible when any of these holds:

1. it is on the grid boundary;
2. the cell across it is not shown (inactive, filtered out or sliced away);
3. it joins non-matching cells: at least one of the four corner depths of the face differs
   between the two cells (a fault throw along i/j, a gap or overlap along k).

Faces are coded 0..5 = I+ J+ K+ I- J- K- (the FAULTS keyword's X Y Z X- Y- Z-).
:func:`visible_faces` is vectorised over k-slabs; :func:`brute_force_visible_faces` is the
plain-loop reference that the tests compare it with.
"""

from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np

from geoshade.compute.grid import kernels as grid_kernels
from geoshade.errors import InputError
from geoshade.models import CornerPointGrid

#: cells per k-slab
SLAB_CELLS = 1 << 22
FACE_NAMES = ("I+", "J+", "K+", "I-", "J-", "K-")
#: cell offset across each face
FACE_OFFSETS = np.array([(1, 0, 0), (0, 1, 0), (0, 0, 1), (-1, 0, 0), (0, -1, 0), (0, 0, -1)])


def drawing_slab(dims) -> int:
    """Layers per k-slab of the faces' drawing order (k-slab, face code, k, j, i): the slabs
    :func:`visible_faces` works in.  A grid drawn in parts whose layer ranges are whole slabs
    (:mod:`geoshade.grid.distributed`) draws each part's faces in the same relative order.

    >>> drawing_slab((1000, 1000, 100)), drawing_slab((2000, 2000, 250))
    (4, 1)
    """
    nx, ny = int(dims[0]), int(dims[1])
    return max(1, SLAB_CELLS // max(1, nx * ny))


@dataclass
class FaceSet:
    """Visible faces.

    cells:           (n, 3) int32  i, j, k of the cell that owns the face
    face:            (n,) uint8    0..5 = I+ J+ K+ I- J- K-
    fault:           (n,) bool     the cell across exists and the shared face does not match
    fault_id:        (n,) int16    index into ``grid.faults`` when FAULTS names the face, else -1
    neighbour_shown: (n,) bool     the cell across exists and is shown
    dims:            (nx, ny, nz) of the grid (default: the extent of ``cells``)
    shown:           cells shown, where the computation counted them (chunk by chunk), else None
    """

    cells: np.ndarray
    face: np.ndarray
    fault: np.ndarray
    fault_id: np.ndarray
    neighbour_shown: np.ndarray
    dims: tuple[int, int, int] | None = None
    shown: int | None = None

    def __len__(self) -> int:
        return int(self.face.shape[0])

    def _dims(self) -> tuple[int, int, int]:
        if self.dims is not None:
            return tuple(self.dims)
        return tuple(int(v) for v in self.cells.max(axis=0, initial=0) + 1)

    def cell_index(self) -> np.ndarray:
        """(n,) int64 linear cell index ``i + nx (j + ny k)`` (file / F order)."""
        nx, ny, _ = self._dims()
        c = self.cells.astype(np.int64)
        return c[:, 0] + nx * (c[:, 1] + ny * c[:, 2])

    def sorted(self) -> FaceSet:
        """The same faces ordered by (cell index, face)."""
        order = np.lexsort((self.face, self.cell_index()))
        return FaceSet(self.cells[order], self.face[order], self.fault[order],
                       self.fault_id[order], self.neighbour_shown[order], self.dims, self.shown)

    def in_drawing_order(self) -> FaceSet:
        """The same faces in :func:`visible_faces`'s order (k-slab, face code, k, j, i): faces
        computed elsewhere (chunk by chunk) then draw the same picture, coplanar fault faces
        included (the first drawn wins a depth tie)."""
        order = self.drawing_order()
        return FaceSet(self.cells[order], self.face[order], self.fault[order],
                       self.fault_id[order], self.neighbour_shown[order], self.dims, self.shown)

    def drawing_order(self) -> np.ndarray:
        """(n,) int64: the permutation that puts the faces in drawing order (see
        :meth:`in_drawing_order`), from one int64 key per face (the order's 16 bytes a face
        and batches of temporaries, not a lexsort over five columns).

        >>> fs = FaceSet(np.array([[1, 0, 1], [0, 0, 1], [5, 0, 0]], np.int32),
        ...              np.array([2, 2, 0], np.uint8), *(np.zeros(3, t) for t in (bool,
        ...              np.int16, bool)), dims=(6, 1, 2))
        >>> fs.drawing_order().tolist()
        [2, 1, 0]
        """
        nx, ny, nz = self._dims()
        step = drawing_slab((nx, ny, nz))
        ncells = nx * ny * nz
        n = len(self)
        key = np.empty(n, np.int64)
        for a in range(0, n, SLAB_CELLS):  # batches of faces, not cells
            c = self.cells[a:a + SLAB_CELLS]
            k = c[:, 2].astype(np.int64)
            # (k-slab, face) group, then the cell number (k, j, i): unique per face
            g = (k // step) * 6 + self.face[a:a + SLAB_CELLS]
            key[a:a + SLAB_CELLS] = g * ncells + (c[:, 0] + nx * (c[:, 1] + ny * k))
            del c, k, g
        order = np.argsort(key)
        del key
        return order

    def per_cell(self) -> tuple[np.ndarray, np.ndarray]:
        """(cells (m, 3) int32, mask (m,) uint8): each cell with a visible face once, and the
        bit mask of its visible faces (bit f for face f), ordered by cell index.

        Examples
        --------
        >>> from geoshade.compute.grid.synthetic import synthetic_grid
        >>> fs = visible_faces(synthetic_grid(1, 1, 1, faults=False, inactive_fraction=0))
        >>> fs.per_cell()[1].tolist()
        [63]
        """
        idx = self.cell_index()
        uniq, inv = np.unique(idx, return_inverse=True)
        mask = np.zeros(uniq.size, np.uint8)
        np.bitwise_or.at(mask, inv, (1 << self.face.astype(np.uint8)).astype(np.uint8))
        nx, ny, _ = self._dims()
        cells = np.stack([uniq % nx, uniq // nx % ny, uniq // (nx * ny)], 1).astype(np.int32)
        return cells, mask


@dataclass
class FaceCount:
    """What is left of a :class:`FaceSet` once its faces are on the GPU (a grid out of core
    keeps no per-face columns on the CPU): their number and the shown cells.

    >>> len(FaceCount(12, 5))
    12
    """

    n: int
    shown: int | None = None

    def __len__(self) -> int:
        return int(self.n)


def _shown(grid: CornerPointGrid, shown) -> np.ndarray:
    if shown is None:
        return grid.active
    s = np.asarray(shown)
    if s.shape != grid.dims:
        raise InputError(f"visible_faces: shown must have the grid shape {grid.dims}, got "
                         f"{s.shape}")
    return s.astype(bool, copy=False)


def _mismatch(a: np.ndarray, b: np.ndarray, tol: float) -> np.ndarray:
    """Corner by corner: do the depths differ by more than ``tol``?"""
    return a != b if tol <= 0 else np.abs(a.astype(np.float64) - b) > tol


def _fault_lookup(grid: CornerPointGrid):
    """(sorted keys, fault index) for every face FAULTS names, from both sides of the face."""
    nx, ny, nz = grid.dims
    keys, ids = [], []
    for fi, f in enumerate(grid.faults):  # faults, not cells
        fc = f.faces.astype(np.int64)
        if not len(fc):
            continue
        for side in (0, 1):
            if side:
                nb = fc[:, :3] + FACE_OFFSETS[fc[:, 3]]
                ok = np.all((nb >= 0) & (nb < (nx, ny, nz)), axis=1)
                cells, face = nb[ok], (fc[ok, 3] + 3) % 6
            else:
                cells, face = fc[:, :3], fc[:, 3]
            lin = cells[:, 0] + nx * (cells[:, 1] + ny * cells[:, 2])
            keys.append(lin * 6 + face)
            ids.append(np.full(len(lin), fi, np.int16))
    if not keys:
        return np.zeros(0, np.int64), np.zeros(0, np.int16)
    k = np.concatenate(keys)
    i = np.concatenate(ids)
    k, first = np.unique(k, return_index=True)  # a face named twice keeps its first fault
    return k, i[first]


def visible_faces(grid: CornerPointGrid, shown=None, fault_tol: float = 0.0,
                  kernels: bool | None = None) -> FaceSet:
    """The visible faces of the shown cells (see the module text for the rule).

    Parameters
    ----------
    grid : CornerPointGrid
    shown : (nx, ny, nz) bool array, optional
        Cells to draw; default the active cells.  The renderer passes
        ``active & filter & slice``.
    fault_tol : float
        Corner depths closer than this count as matching.
    kernels : bool, optional
        Use the numba kernels (:mod:`geoshade.compute.grid.kernels`: one parallel pass, no
        temporaries) or the numpy slabs; default: the kernels from
        :data:`~geoshade.compute.grid.kernels.MIN_CELLS` cells on.  Both give the same faces in
        the same order.

    Returns
    -------
    FaceSet
        Grouped by k-slab, then by face code; in each group ordered by (k, j, i).

    Examples
    --------
    >>> from geoshade.compute.grid.synthetic import synthetic_grid
    >>> g = synthetic_grid(4, 3, 2, faults=False, inactive_fraction=0)
    >>> len(visible_faces(g))  # the box's surface: 2·(4·3 + 4·2 + 3·2)
    52
    >>> fs = visible_faces(synthetic_grid(6, 3, 2, inactive_fraction=0))
    >>> int(fs.fault.sum()) > 0, sorted(set(fs.fault_id[fs.fault].tolist()))
    (True, [0, 1])
    """
    s_all = _shown(grid, shown)
    nx, ny, nz = grid.dims
    z = grid.zcorn
    tol = float(fault_tol)
    keys, kid = _fault_lookup(grid)
    step = drawing_slab(grid.dims)
    parts: list[tuple] = []
    fast = kernels if kernels is not None else grid_kernels.use_kernels(nx * ny * nz)
    if fast and isinstance(z, np.ndarray):

        zf = grid_kernels._f(z, np.float32)
        sf = grid_kernels._f(s_all, np.uint8)
        with ThreadPoolExecutor(max(1, min(4, os.cpu_count() or 1))) as pool:
            # slabs of layers on threads (the kernel releases the GIL), kept in order
            parts = list(pool.map(lambda k0: grid_kernels.faces_in_slab(
                zf, sf, k0, min(nz, k0 + step), tol), range(0, nz, step)))
        return _face_set(grid, parts, keys, kid)
    for k0 in range(0, nz, step):  # slabs of layers
        k1 = min(nz, k0 + step)
        nk = k1 - k0
        s = s_all[:, :, k0:k1]
        zs = z[:, :, 2 * k0:2 * k1]
        # mismatch across each interior face, reduced over its 2x2 corners
        mi = _mismatch(zs[1:-1:2], zs[2::2], tol)
        mi = mi[:, 0::2, 0::2] | mi[:, 1::2, 0::2] | mi[:, 0::2, 1::2] | mi[:, 1::2, 1::2]
        mj = _mismatch(zs[:, 1:-1:2], zs[:, 2::2], tol)
        mj = mj[0::2, :, 0::2] | mj[1::2, :, 0::2] | mj[0::2, :, 1::2] | mj[1::2, :, 1::2]
        # k pairs (k, k+1) for k in [p0, p1): bottom of k against top of k+1
        p0, p1 = max(k0 - 1, 0), min(k1, nz - 1)
        mk = _mismatch(z[:, :, 2 * p0 + 1:2 * p1:2], z[:, :, 2 * p0 + 2:2 * p1 + 1:2], tol)
        mk = mk[0::2, 0::2] | mk[1::2, 0::2] | mk[0::2, 1::2] | mk[1::2, 1::2]
        for f in range(6):
            exists = np.zeros((nx, ny, nk), bool)
            nb = np.zeros((nx, ny, nk), bool)
            bad = np.zeros((nx, ny, nk), bool)
            if f == 0:
                exists[:-1], nb[:-1], bad[:-1] = True, s[1:], mi
            elif f == 3:
                exists[1:], nb[1:], bad[1:] = True, s[:-1], mi
            elif f == 1:
                exists[:, :-1], nb[:, :-1], bad[:, :-1] = True, s[:, 1:], mj
            elif f == 4:
                exists[:, 1:], nb[:, 1:], bad[:, 1:] = True, s[:, :-1], mj
            elif f == 2:  # cell k has k+1 while k < nz-1; pair k is mk[..., k - p0]
                hi = min(k1, nz - 1) - k0
                exists[:, :, :hi] = True
                nb[:, :, :hi] = s_all[:, :, k0 + 1:k0 + 1 + hi]
                bad[:, :, :hi] = mk[:, :, k0 - p0:k0 - p0 + hi]
            else:  # K-: cell k has k-1 while k > 0; pair k-1 is mk[..., k-1-p0]
                lo = 1 if k0 == 0 else 0
                exists[:, :, lo:] = True
                nb[:, :, lo:] = s_all[:, :, k0 + lo - 1:k1 - 1]
                bad[:, :, lo:] = mk[:, :, k0 + lo - 1 - p0:k1 - 1 - p0]
            bad &= exists
            vis = s & (~exists | ~nb | bad)
            kk, jj, ii = np.nonzero(vis.T)  # memory order of an F array: i fastest
            cells = np.stack([ii, jj, kk + k0], 1).astype(np.int32)
            parts.append((cells, np.full(len(ii), f, np.uint8), bad.T[kk, jj, ii],
                          nb.T[kk, jj, ii]))
    return _face_set(grid, parts, keys, kid)


def _face_set(grid: CornerPointGrid, parts: list[tuple], keys, kid) -> FaceSet:
    """One FaceSet from per-slab ``(cells, face, fault, neighbour_shown)`` parts, fault ids
    looked up in the FAULTS ``keys``."""
    if parts:
        # filled part by part, each part dropped once copied: at most one part's memory
        # beyond the result (a filter showing 1e7 faces would otherwise hold both copies)
        n = sum(len(p[1]) for p in parts)
        cells = np.empty((n, 3), np.int32)
        face, fault, nbs = np.empty(n, np.uint8), np.empty(n, bool), np.empty(n, bool)
        at = 0
        while parts:
            c, f, b, nb = parts.pop(0)
            m = len(f)
            cells[at:at + m], face[at:at + m], fault[at:at + m], nbs[at:at + m] = c, f, b, nb
            at += m
            del c, f, b, nb
    else:  # pragma: no cover - nz >= 1 always gives slabs
        cells = np.zeros((0, 3), np.int32)
        face, fault, nbs = np.zeros(0, np.uint8), np.zeros(0, bool), np.zeros(0, bool)
    return _with_fault_ids(grid, cells, face, fault, nbs, keys, kid)


def _with_fault_ids(grid: CornerPointGrid, cells, face, fault, nbs, keys, kid) -> FaceSet:
    """The FaceSet of these columns, fault ids looked up in the FAULTS ``keys``."""
    nx, ny, _ = grid.dims
    fid = np.full(len(face), -1, np.int16)
    if len(keys):
        for a in range(0, len(face), SLAB_CELLS):  # batches of faces: bounded temporaries
            c = cells[a:a + SLAB_CELLS].astype(np.int64)
            q = (c[:, 0] + nx * (c[:, 1] + ny * c[:, 2])) * 6 + face[a:a + SLAB_CELLS]
            pos = np.clip(np.searchsorted(keys, q), 0, len(keys) - 1)
            hit = keys[pos] == q
            fid[a:a + SLAB_CELLS][hit] = kid[pos[hit]]
            del c, q, pos, hit
    return FaceSet(cells, face, fault.astype(bool), fid, nbs.astype(bool), grid.dims)


#: the counting sort of :func:`_face_set_in_drawing_order` keeps one int64 per row of the
#: drawing order (6 nz ny of them); beyond this many it sorts group by group instead
MAX_DRAWING_ROWS = 1 << 25


def _face_set_in_drawing_order(grid: CornerPointGrid, parts: list[tuple], keys, kid,
                               with_corners: bool = False, in_i_order: bool = False):
    """:func:`_face_set` of parts in any order (a grid's chunks), assembled straight into
    :func:`visible_faces`'s drawing order (k-slab, face code, k, j, i).

    ``parts``: ``(cells, face, fault, neighbour_shown)`` per part, or with a fifth column, the
    ``(n, 4)`` corner depths of each face (``with_corners``: returned beside the face set, in
    the same order).  Parts are boxes of cells that do not overlap (chunks); their faces in
    any order; ``in_i_order``: the parts come so that parts sharing rows come by ascending i
    (chunks in (k, j, i) chunk order: placed as they come, the rows' writes close together).

    A stable counting sort by *row* (k-slab, face code, k, j), compiled: each part's faces are
    put in row order inside the part (most parts come so; the others are sorted, one part at
    a time), then the parts are placed in order of their first i, so the faces of a row come
    in i order.  One pass to count, one to place, one to check (numba; 8 bytes a row of the
    grid), no whole-set sort.  Memory: the face set and one part of temporaries; each part is
    dropped once placed.  Grids with more than :data:`MAX_DRAWING_ROWS` rows are sorted group
    by group (:func:`_face_set_by_groups`).
    """
    nx, ny, nz = grid.dims
    step = drawing_slab(grid.dims)
    nrows = 6 * (-(-nz // step)) * step * ny
    if nrows > MAX_DRAWING_ROWS:
        return _face_set_by_groups(grid, parts, keys, kid, with_corners)
    counts = np.zeros(nrows, np.int64)
    first_i = []
    for n_, p in enumerate(parts):  # parts (chunks), not cells: each in row order
        ok = grid_kernels.drawing_rows(p[0], p[1], step, ny, counts)[1]   # counted
        if not ok:
            rows = grid_kernels.drawing_rows(p[0], p[1], step, ny)[0]
            o = np.argsort(rows * nx + p[0][:, 0])   # (row, i) is unique per face
            parts[n_] = p = tuple(col[o] for col in p)
            del o, rows
        first_i.append(int(p[0][:, 0].min()) if len(p[1]) else -1)
    cursor = np.concatenate([[0], np.cumsum(counts)[:-1]]).astype(np.int64)
    del counts
    n = int(sum(len(p[1]) for p in parts))
    cells = np.empty((n, 3), np.int32)
    face, fault, nbs = np.empty(n, np.uint8), np.empty(n, bool), np.empty(n, bool)
    corners = np.empty((n, 4), np.float32) if with_corners else None
    if not in_i_order:
        order = sorted(range(len(parts)), key=lambda q: first_i[q])   # stable
        parts = [parts[q] for q in order]
    out = (cells, face, fault, nbs,
           corners if corners is not None else np.zeros((0, 4), np.float32))
    while parts:  # each part dropped once placed
        p = parts.pop(0)
        grid_kernels.place_faces(p if corners is not None else p[:4], step, ny, cursor, out)
        del p
    fs = _with_fault_ids(grid, cells, face, fault, nbs, keys, kid)
    if n and not grid_kernels.in_drawing_order(cells, face, step, ny):
        # parts that were not boxes of a partition: one whole sort
        o = fs.drawing_order()
        fs = FaceSet(cells[o], face[o], fault[o], fs.fault_id[o], nbs[o], fs.dims)
        corners = corners[o] if corners is not None else None
    return (fs, corners) if with_corners else fs


def _face_set_by_groups(grid: CornerPointGrid, parts: list[tuple], keys, kid,
                        with_corners: bool = False):
    """:func:`_face_set_in_drawing_order` for grids with very many rows: each part's faces
    are placed in their (k-slab, face) group as the part is dropped (a stable counting sort),
    then each group is ordered by cell number on its own."""
    nx, ny, nz = grid.dims
    step = drawing_slab(grid.dims)
    ngroups = 6 * (-(-nz // step))

    counts = np.zeros(ngroups, np.int64)
    for p in parts:  # parts (chunks), not cells
        counts += np.bincount((p[0][:, 2].astype(np.int64) // step) * 6 + p[1],
                              minlength=ngroups)
    starts = np.concatenate([[0], np.cumsum(counts)])
    n = int(starts[-1])
    cells = np.empty((n, 3), np.int32)
    face, fault, nbs = np.empty(n, np.uint8), np.empty(n, bool), np.empty(n, bool)
    corners = np.empty((n, 4), np.float32) if with_corners else None
    cursor = starts[:-1].copy()
    while parts:  # each part dropped once placed
        p = parts.pop(0)
        c, f = p[0], p[1]
        g = (c[:, 2].astype(np.int64) // step) * 6 + f
        o = np.argsort(g, kind="stable")
        gs = g[o]
        first = np.searchsorted(gs, gs, side="left")
        pos = cursor[gs] + (np.arange(gs.size) - first)
        cursor += np.bincount(gs, minlength=ngroups)
        cells[pos], face[pos], fault[pos], nbs[pos] = c[o], f[o], p[2][o], p[3][o]
        if corners is not None:
            corners[pos] = p[4][o]
        del p, c, f, g, o, gs, first, pos
    for gi in np.flatnonzero(counts > 1):  # groups (k-slab, face code), not cells
        a, b = int(starts[gi]), int(starts[gi + 1])
        cc = cells[a:b].astype(np.int64)
        o = np.argsort(cc[:, 0] + nx * (cc[:, 1] + ny * cc[:, 2]))  # (k, j, i): unique
        cells[a:b], fault[a:b], nbs[a:b] = cells[a:b][o], fault[a:b][o], nbs[a:b][o]
        if corners is not None:
            corners[a:b] = corners[a:b][o]
        del cc, o
    fs = _with_fault_ids(grid, cells, face, fault, nbs, keys, kid)
    return (fs, corners) if with_corners else fs


def _face_corners(zcorn, i, j, k, f):
    """The 4 corner depths of face f of cell (i, j, k), in a fixed order (test reference)."""
    axis, plus = f % 3, f < 3
    out = []
    for u in (0, 1):
        for v in (0, 1):
            abc = [None, None, None]
            abc[axis] = 1 if plus else 0
            others = [d for d in range(3) if d != axis]
            abc[others[0]], abc[others[1]] = u, v
            out.append(float(zcorn[2 * i + abc[0], 2 * j + abc[1], 2 * k + abc[2]]))
    return out


def brute_force_visible_faces(grid: CornerPointGrid, shown=None,
                              fault_tol: float = 0.0) -> FaceSet:
    """Plain-loop reference of :func:`visible_faces` for small grids (tests only).

    Returns the faces ordered by (cell index, face), like :meth:`FaceSet.sorted`.

    Examples
    --------
    >>> from geoshade.compute.grid.synthetic import synthetic_grid
    >>> g = synthetic_grid(5, 4, 3, seed=2)
    >>> a, b = visible_faces(g).sorted(), brute_force_visible_faces(g)
    >>> bool(np.array_equal(a.cells, b.cells) and np.array_equal(a.fault_id, b.fault_id))
    True
    """
    s = _shown(grid, shown)
    nx, ny, nz = grid.dims
    z = np.asarray(grid.zcorn)
    named = {}
    for fi, flt in enumerate(grid.faults):
        for i, j, k, f in flt.faces.tolist():
            named.setdefault((i, j, k, f), fi)
            di, dj, dk = FACE_OFFSETS[f]
            named.setdefault((i + di, j + dj, k + dk, (f + 3) % 6), fi)
    rows = []
    for k in range(nz):
        for j in range(ny):
            for i in range(nx):
                if not s[i, j, k]:
                    continue
                for f in range(6):
                    di, dj, dk = FACE_OFFSETS[f]
                    a, b, c = i + di, j + dj, k + dk
                    inside = 0 <= a < nx and 0 <= b < ny and 0 <= c < nz
                    nb_shown = bool(inside and s[a, b, c])
                    bad = False
                    if inside:
                        mine = _face_corners(z, i, j, k, f)
                        theirs = _face_corners(z, a, b, c, (f + 3) % 6)
                        bad = any(abs(p - q) > fault_tol for p, q in zip(mine, theirs,
                                                                          strict=True))
                    if not inside or not nb_shown or bad:
                        rows.append((i, j, k, f, bad, named.get((i, j, k, f), -1), nb_shown))
    arr = np.array(rows, dtype=np.int64).reshape(-1, 7)
    return FaceSet(arr[:, :3].astype(np.int32), arr[:, 3].astype(np.uint8),
                   arr[:, 4].astype(bool), arr[:, 5].astype(np.int16), arr[:, 6].astype(bool),
                   grid.dims)
