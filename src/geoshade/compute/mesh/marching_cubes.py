"""CPU marching cubes: the case table shared with the GPU, and the reference (oracle) for it.

Cell and table conventions (the GPU's geometry shader uses exactly these, emitted from here):

- A *cell* of a ``(nz, ny, nx)`` node array is the cube between nodes ``(z..z+1, y..y+1,
  x..x+1)``; there are ``(nz-1)(ny-1)(nx-1)`` cells.  Corner ``p`` of a cell is the node at offset
  ``(p & 1, p >> 1 & 1, p >> 2 & 1)`` along ``(x, y, z)``.
- The paper's classification (Section 3): ``K = Σ_p 2^p [S(V_p) < S*]``, computed in float32 on
  both sides so CPU and GPU classify every cell identically.
- Edges 0–3 run along x, 4–7 along y, 8–11 along z (:data:`EDGES`); each is stored from its lower
  to its upper corner, so the cells that share an edge compute bit-identical vertices (Eq. (1)).
- :func:`case_table` is the table ``T``: 256 rows of 16 edge indices, 3 per triangle, ``-1``
  after the last. It is *derived* here (loops of the surface on the cube's faces, fanned into
  triangles) instead of typed in: on a face whose diagonal corners agree (the ambiguous face),
  the corners below the level are cut off separately, so two cells sharing a face always agree
  and the surface has no cracks. Only cells with such a face can triangulate differently from
  Lorensen's classic table (:func:`ambiguous_cases`); every row has at most 5 triangles.
- Outside values: a node that is inactive, NaN or ±inf is stored as :data:`OUTSIDE`. By default
  (``caps=False``) a cell with an outside corner makes no triangles: the surface stays open there,
  as at the grid's outer boundary (on a reservoir grid: open along ACTNUM instead of a box
  around the active cells). With ``caps=True`` outside nodes are below every level ("outside
  the displacing fluid") and the surface closes: an edge with an outside end gets its vertex at
  the edge's midpoint (on a corner-point grid: halfway between the cell centres, near their
  shared face).

>>> import numpy as np
>>> z, y, x = np.mgrid[0:8, 0:8, 0:8].astype(np.float32)
>>> res = marching_cubes(z, 3.5)       # the plane z = 3.5 across 7 × 7 cells
>>> res.count, round(float(surface_area(res.triangles)), 6)
(98, 49.0)
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from geoshade.errors import InputError

#: stored for inactive / NaN / inf nodes: below every level (float32, finite)
OUTSIDE = np.float32(-3.0e38)
#: a stored value at or below this is an outside node
OUTSIDE_BELOW = np.float32(-1.0e38)
#: corner p -> offset (x, y, z)
CORNERS = np.array([[p & 1, p >> 1 & 1, p >> 2 & 1] for p in range(8)], dtype=np.int64)
#: edge -> (lower corner, upper corner); 0-3 along x, 4-7 along y, 8-11 along z
EDGES = np.array(
    [[2 * (e & 1) + 4 * (e >> 1), 1 + 2 * (e & 1) + 4 * (e >> 1)] for e in range(4)]
    + [[(e & 1) + 4 * (e >> 1), (e & 1) + 2 + 4 * (e >> 1)] for e in range(4)]
    + [[(e & 1) + 2 * (e >> 1), (e & 1) + 2 * (e >> 1) + 4] for e in range(4)],
    dtype=np.int64,
)
#: most triangles one cell can hold
MAX_TRIANGLES = 5
#: entries per table row (5 triangles × 3 edges + the -1 terminator)
ROW = 16
#: bytes of the temporaries of :func:`patch_ranges` per slab of slices
RANGES_SLAB_BYTES = 4 << 20


# ----------------------------------------------------------------------------------------------
# the case table
# ----------------------------------------------------------------------------------------------
def _faces():
    """(outward normal, 4 corners in cyclic order, 4 edges between consecutive corners)."""
    faces = []
    for axis in range(3):
        u, v = [a for a in range(3) if a != axis]
        for side in (0, 1):
            cyc = [(0, 0), (1, 0), (1, 1), (0, 1)]
            corners = []
            for cu, cv in cyc:
                off = [0, 0, 0]
                off[axis], off[u], off[v] = side, cu, cv
                corners.append(off[0] + 2 * off[1] + 4 * off[2])
            edges = []
            for a, b in zip(corners, corners[1:] + corners[:1], strict=True):
                pair = sorted((a, b))
                edges.append(next(e for e in range(12) if list(EDGES[e]) == pair))
            normal = np.zeros(3)
            normal[axis] = 1.0 if side else -1.0
            faces.append((normal, corners, edges))
    return faces


def _fan(loop: list[int], face_edges: list[set]) -> list[int]:
    """Fan-triangulate a loop of edges from the first start that puts no triangle flat into a
    face of the cube (three vertices on one face: a fin in the face plane)."""
    n = len(loop)
    best, best_flat = None, None
    for s in range(n):
        rot = loop[s:] + loop[:s]
        tri = [(rot[0], rot[i], rot[i + 1]) for i in range(1, n - 1)]
        flat = sum(any(set(t) <= f for f in face_edges) for t in tri)
        if best is None or flat < best_flat:
            best, best_flat = tri, flat
        if flat == 0:
            break
    return [e for t in best for e in t]


@functools.lru_cache(maxsize=1)
def _tables() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    mid = (CORNERS[EDGES[:, 0]] + CORNERS[EDGES[:, 1]]) / 2.0
    faces = _faces()
    face_edges = [set(edges) for _, _, edges in faces]
    table = np.full((256, ROW), -1, dtype=np.int8)
    count = np.zeros(256, dtype=np.int8)
    ambiguous = np.zeros(256, dtype=bool)
    for K in range(256):
        below = [(K >> p) & 1 for p in range(8)]
        nxt: dict[int, int] = {}
        for normal, corners, edges in faces:
            b = [below[c] for c in corners]
            crossed = [e for i, e in enumerate(edges) if b[i] != b[(i + 1) % 4]]
            if not crossed:
                continue
            if len(crossed) == 4:  # ambiguous face: cut each corner below the level off alone
                ambiguous[K] = True
                pieces = [((edges[i - 1], edges[i]), CORNERS[corners[i]].astype(float))
                          for i in range(4) if b[i]]
            else:
                ref = CORNERS[[c for c, bb in zip(corners, b, strict=True) if bb]].mean(axis=0)
                pieces = [((crossed[0], crossed[1]), ref)]
            for (e1, e2), ref in pieces:
                d = mid[e2] - mid[e1]
                centre = (mid[e1] + mid[e2]) / 2
                # orient so that the face normal × the segment points to the side below
                if np.dot(np.cross(normal, d), ref - centre) < 0:
                    e1, e2 = e2, e1
                if e1 in nxt:
                    raise AssertionError(f"case {K}: edge {e1} leaves twice")
                nxt[e1] = e2
        tris: list[int] = []
        todo = set(nxt)
        while todo:
            start = min(todo)
            loop = [start]
            while nxt[loop[-1]] != start:
                loop.append(nxt[loop[-1]])
            todo -= set(loop)
            tris += _fan(loop, face_edges)
        if len(tris) > 3 * MAX_TRIANGLES:
            raise AssertionError(f"case {K}: {len(tris) // 3} triangles")
        table[K, : len(tris)] = tris
        count[K] = len(tris) // 3
    table.setflags(write=False)
    count.setflags(write=False)
    ambiguous.setflags(write=False)
    return table, count, ambiguous


def case_table() -> np.ndarray:
    """The table ``T``: ``(256, 16) int8``, edge indices 3 per triangle, ``-1`` after the last.

    The GPU uploads exactly this array as its integer 2D texture.

    Examples
    --------
    >>> T = case_table()
    >>> T.shape, T.dtype.name, T[0].tolist()[:3], T[1].tolist()[:4]
    ((256, 16), 'int8', [-1, -1, -1], [0, 8, 4, -1])
    """
    return _tables()[0]


def triangle_counts() -> np.ndarray:
    """``(256,) int8``: triangles of each case (0..5).

    >>> int(triangle_counts()[1]), int(triangle_counts().max())
    (1, 5)
    """
    return _tables()[1]


def ambiguous_cases() -> np.ndarray:
    """``(256,) bool``: cases with an ambiguous face, the only ones that may differ from Lorensen.

    >>> int(ambiguous_cases().sum())
    120
    """
    return _tables()[2]


# ----------------------------------------------------------------------------------------------
# values, classification, counts
# ----------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class PreparedValues:
    """Node values ready for marching (and for upload to the GPU).

    values:     (nz, ny, nx) float32  the field, :data:`OUTSIDE` at outside nodes
    nonfinite:  int                   active nodes that were NaN or ±inf
    inactive:   int                   nodes masked out by ``active``
    vmin, vmax: float or None         range of the finite active values (None if there are none)
    """

    values: np.ndarray
    nonfinite: int
    inactive: int
    vmin: float | None
    vmax: float | None


def prepare_values(values, active=None) -> PreparedValues:
    """``values`` as float32 with inactive, NaN and ±inf nodes set to :data:`OUTSIDE`.

    The input is never modified. When nothing needs setting (every node active and finite) and
    the input already is float32, ``values`` is a read-only view of it: no copy.

    Parameters
    ----------
    values : (nz, ny, nx) array_like
    active : (nz, ny, nx) bool, optional

    Examples
    --------
    >>> p = prepare_values(np.array([[[0.5, np.nan], [np.inf, 1.0]]]))
    >>> p.nonfinite, p.vmin, p.vmax, bool(p.values[0, 0, 1] == OUTSIDE)
    (2, 0.5, 1.0, True)
    >>> a = np.ones((2, 2, 2), np.float32)
    >>> np.shares_memory(prepare_values(a).values, a)
    True
    """
    v = np.asarray(values.compute() if hasattr(values, "compute") else values)
    if v.ndim != 3:
        raise InputError(f"values: expected a 3D (nz, ny, nx) array, got shape {v.shape}")
    act = None
    if active is not None:
        act = np.asarray(active, dtype=bool)
        if act.shape != v.shape:
            raise InputError(f"active: expected shape {v.shape}, got {act.shape}")
        if act.all():
            act = None
    v32 = v if v.dtype == np.float32 else v.astype(np.float32)
    if act is None:
        lo, hi = v32.min(), v32.max()  # NaN or inf anywhere shows here, without a temporary
        if np.isfinite(lo) and np.isfinite(hi) and lo > OUTSIDE_BELOW:
            view = v32.view()
            view.flags.writeable = False
            return PreparedValues(view, 0, 0, float(lo), float(hi))
    out = v32.copy() if v32 is v else v32
    bad = ~np.isfinite(out) | (out <= OUTSIDE_BELOW)
    nonfinite = int(np.count_nonzero(bad if act is None else bad & act))
    inactive = 0 if act is None else int(act.size - np.count_nonzero(act))
    if act is not None:
        bad |= ~act
    out[bad] = OUTSIDE
    good = ~bad
    if not good.any():
        return PreparedValues(out, nonfinite, inactive, None, None)
    vmin = float(np.min(out, where=good, initial=np.inf))
    vmax = float(np.max(out, where=good, initial=-np.inf))
    return PreparedValues(out, nonfinite, inactive, vmin, vmax)


def _values32(values) -> np.ndarray:
    v = values.values if isinstance(values, PreparedValues) else values
    v = np.asarray(v)
    if v.ndim != 3 or min(v.shape) < 2:
        raise InputError(f"values: expected a (nz, ny, nx) array with at least 2 nodes per "
                         f"axis, got shape {v.shape}")
    return v if v.dtype == np.float32 else v.astype(np.float32)


def open_cells(values) -> np.ndarray | None:
    """``(nz-1, ny-1, nx-1) bool``: cells with an outside corner (inactive, NaN, ±inf), which
    make no triangles unless ``caps``; None when there is no outside node (the usual case, no
    temporary).

    >>> v = np.zeros((3, 2, 2), np.float32); v[0, 0, 0] = OUTSIDE
    >>> open_cells(v).ravel().tolist(), open_cells(np.zeros((2, 2, 2), np.float32))
    ([True, False], None)
    """
    v = _values32(values)
    if not v.min() <= OUTSIDE_BELOW:
        return None
    out = v <= OUTSIDE_BELOW
    # any corner: OR along x, then y, then z (3 passes over the cells, not 8)
    a = out[:, :, :-1] | out[:, :, 1:]
    a = a[:, :-1] | a[:, 1:]
    return a[:-1] | a[1:]


def classify(values, level: float, caps: bool = False) -> np.ndarray:
    """The paper's ``K`` of every cell: ``(nz-1, ny-1, nx-1) uint8``.

    ``values`` is a float32 array (see :func:`prepare_values`); the comparison is in float32.
    Without ``caps`` a cell with an outside corner (:func:`open_cells`) gets ``K = 0``: no
    triangles, the surface stays open there. With ``caps`` outside nodes count as below the
    level and close the surface.

    Examples
    --------
    >>> v = np.zeros((2, 2, 2), np.float32); v[0, 0, 0] = -1
    >>> classify(v, -0.5).tolist()
    [[[1]]]
    >>> v[1, 1, 1] = OUTSIDE
    >>> classify(v, -0.5).tolist(), classify(v, -0.5, caps=True).tolist()
    ([[[0]]], [[[129]]])
    """
    v = _values32(values)
    s = np.float32(level)
    below = v < s
    nz, ny, nx = v.shape
    K = np.zeros((nz - 1, ny - 1, nx - 1), dtype=np.uint8)
    for p, (cx, cy, cz) in enumerate(CORNERS):  # 8 corners, not cells
        K |= below[cz : cz + nz - 1, cy : cy + ny - 1, cx : cx + nx - 1].astype(np.uint8) << p
    if not caps:
        gone = open_cells(v)
        if gone is not None:
            K[gone] = 0
    return K


def triangle_count(values, level: float, caps: bool = False) -> int:
    """Number of triangles the table gives for ``values`` at ``level`` (the GPU's count).

    >>> v = np.random.default_rng(0).random((6, 7, 8)).astype(np.float32)
    >>> triangle_count(v, 0.5) == marching_cubes(v, 0.5).count
    True
    """
    K = classify(values, level, caps)
    return int(np.bincount(K.ravel(), minlength=256) @ triangle_counts().astype(np.int64))


def ambiguous_cell_count(values, level: float, caps: bool = False) -> int:
    """Cells whose case has an ambiguous face (where tables may legitimately differ).

    >>> ambiguous_cell_count(np.zeros((3, 3, 3), np.float32), 0.5)
    0
    """
    K = classify(values, level, caps)
    return int(np.bincount(K.ravel(), minlength=256)[ambiguous_cases()].sum())


# ----------------------------------------------------------------------------------------------
# triangles
# ----------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class MarchingCubesResult:
    """Triangle soup of an isosurface, in the GPU's order within each cell.

    triangles: (n, 3, 3) float32|float64  vertex positions: index space ``(x, y, z)`` (node
               (i, j, k) at (i, j, k)) unless ``positions`` was given
    cells:     (n,) int64                 linear cell index ``(z * (ny-1) + y) * (nx-1) + x``
    slots:     (n,) int8                  triangle number within its cell's table row (0..4)
    """

    triangles: np.ndarray
    cells: np.ndarray
    slots: np.ndarray

    @property
    def count(self) -> int:
        return int(self.cells.size)


def marching_cubes(values, level: float, positions=None, caps: bool = False
                   ) -> MarchingCubesResult:
    """The reference isosurface: same classification, table and Eq. (1) as the GPU.

    Parameters
    ----------
    values : (nz, ny, nx) float32 array or :class:`PreparedValues`
        Node values (outside nodes already set to :data:`OUTSIDE`, see :func:`prepare_values`).
    level : float
        ``S*``; compared in float32.
    positions : (nz, ny, nx, 3) float, optional
        Real coordinates of the nodes (on a corner-point grid: the cell centres). Vertices are
        placed by Eq. (1) between these; default: index space.
    caps : bool
        Close the surface along outside nodes (see :func:`classify`); default open.

    Returns
    -------
    MarchingCubesResult

    Examples
    --------
    >>> z, y, x = np.mgrid[0:3, 0:3, 0:3].astype(np.float32)
    >>> r = marching_cubes(x, 0.25)
    >>> r.count, sorted({float(v) for v in r.triangles[..., 0].ravel()})
    (8, [0.25])
    """
    v = _values32(values)
    nz, ny, nx = v.shape
    K = classify(v, level, caps).ravel()
    ntri = triangle_counts()[K]
    cells = np.flatnonzero(ntri)
    rows = case_table()[K[cells], :15].astype(np.int64)  # (m, 15)
    keep = rows >= 0
    edge = rows[keep]  # vertices in cell-major, table order
    vcell = np.repeat(cells, keep.sum(axis=1))
    cz, rem = np.divmod(vcell, (ny - 1) * (nx - 1))
    cy, cx = np.divmod(rem, nx - 1)
    base = np.stack([cx, cy, cz], axis=1)
    a = base + CORNERS[EDGES[edge, 0]]
    b = base + CORNERS[EDGES[edge, 1]]
    flat = v.ravel()
    ia = (a[:, 2] * ny + a[:, 1]) * nx + a[:, 0]
    ib = (b[:, 2] * ny + b[:, 1]) * nx + b[:, 0]
    va, vb = flat[ia], flat[ib]
    s = np.float32(level)
    out_end = (va <= OUTSIDE_BELOW) | (vb <= OUTSIDE_BELOW)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(out_end, np.float32(0.5), (s - va) / (vb - va)).astype(np.float32)
    if positions is None:
        pa, pb = a.astype(np.float32), b.astype(np.float32)
    else:
        pos = np.asarray(positions)
        if pos.shape != (nz, ny, nx, 3):
            raise InputError(f"positions: expected shape {(nz, ny, nx, 3)}, got {pos.shape}")
        pos = pos.reshape(-1, 3)
        pa, pb = pos[ia], pos[ib]
    p = pa + t[:, None] * (pb - pa)
    tri_cells = np.repeat(cells, ntri[cells])
    first = np.concatenate([[0], np.cumsum(ntri[cells], dtype=np.int64)[:-1]])
    slots = (np.arange(tri_cells.size) - np.repeat(first, ntri[cells])).astype(np.int8)
    return MarchingCubesResult(p.reshape(-1, 3, 3), tri_cells.astype(np.int64), slots)


def triangle_areas(triangles) -> np.ndarray:
    """``(n,)`` areas of ``(n, 3, 3)`` triangles (float64).

    >>> triangle_areas(np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0]]])).tolist()
    [0.5]
    """
    t = np.asarray(triangles, dtype=np.float64)
    return 0.5 * np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), axis=1)


def surface_area(triangles) -> float:
    """Total area of ``(n, 3, 3)`` triangles.

    >>> surface_area(np.zeros((0, 3, 3)))
    0.0
    """
    return float(triangle_areas(triangles).sum()) if len(triangles) else 0.0


# ----------------------------------------------------------------------------------------------
# per-patch value ranges (skipping patches that cannot hold the level)
# ----------------------------------------------------------------------------------------------
#: slice axis -> numpy axes (slices, rows, columns) of a ``(nz, ny, nx)`` array. The paper
#: stacks patch-quads along z (slices of x-y patches); stacking them along the axis the surface
#: faces (e.g. the flow direction of a displacement front) leaves fewer patches crossing it.
SLICE_AXES = {"z": (0, 1, 2), "y": (1, 0, 2), "x": (2, 0, 1)}
#: slice axis -> field axes (x = 0, y = 1, z = 2) of the patch's (column, row, slice): what the
#: GPU maps a patch-space cell index through
PATCH_AXES = {"z": (0, 1, 2), "y": (0, 2, 1), "x": (1, 2, 0)}


def _axis(axis: str) -> tuple[int, int, int]:
    if axis not in SLICE_AXES:
        raise InputError(f"slice axis: expected one of x, y, z, got {axis!r}")
    return SLICE_AXES[axis]


def patch_grid(shape_zyx, patch_level: int = 64, axis: str = "z") -> tuple[int, int, int]:
    """``(n_p, m_p, q_p)`` patch-quads over the cells of a ``(nz, ny, nx)`` node array.

    Each patch covers ``D × D`` cells (``D = patch_level + 1``) of one slice of cells. With the
    paper's slices along z: ``n_p = ceil((nx-1)/D)``, ``m_p = ceil((ny-1)/D)``, ``q_p = nz-1``;
    ``axis`` = "x" or "y" stacks the slices along that axis instead (rows and columns are the
    other two axes, in z, y, x order of precedence).

    >>> patch_grid((101, 101, 101)), patch_grid((11, 21, 31), 4, axis="x")
    ((2, 2, 100), (4, 2, 30))
    """
    s, r, c = _axis(axis)
    shape = tuple(int(n) for n in shape_zyx)
    D = int(patch_level) + 1
    return (-(-(shape[c] - 1) // D), -(-(shape[r] - 1) // D), shape[s] - 1)


def _block_reduce(a: np.ndarray, D: int, axis: int, ufunc) -> np.ndarray:
    """Reduce over node blocks ``[D b, D b + D]`` (D+1 nodes, overlapping by one) along axis."""
    n = a.shape[axis]
    starts = np.arange(0, n - 1, D)
    blocks = ufunc.reduceat(a, starts, axis=axis)  # nodes [D b, D b + D - 1] (last: to n-1)
    nxt = np.minimum(starts + D, n - 1)
    return ufunc(blocks, np.take(a, nxt, axis=axis))


def patch_ranges(values, patch_level: int = 64, axis: str = "z", caps: bool = False
                 ) -> np.ndarray:
    """``(q_p, m_p, n_p, 2) float32``: min and max node value under each patch-quad.

    A patch can hold the level ``S*`` only if ``min < S* <= max``. Without ``caps`` outside
    nodes make no triangles and are left out of the minimum (a patch of outside nodes only has
    ``(+inf, OUTSIDE)``: never live); with ``caps`` they count with their stored value
    :data:`OUTSIDE` (below every level). Computed in the array's own layout (fast) and
    transposed to patch order.

    Examples
    --------
    >>> v = np.zeros((3, 4, 70), np.float32); v[2, 3, 69] = 1
    >>> r = patch_ranges(v)
    >>> r.shape, r[1, 0, 1].tolist(), r[0, 0, 0].tolist()
    ((2, 1, 2, 2), [0.0, 1.0], [0.0, 0.0])
    >>> patch_ranges(v, axis="x").shape
    (69, 1, 1, 2)
    >>> v[0, 0, 0] = OUTSIDE
    >>> float(patch_ranges(v)[0, 0, 0, 0]), bool(patch_ranges(v, caps=True)[0, 0, 0, 0] == OUTSIDE)
    (0.0, True)
    """
    v = _values32(values)
    s, r, c = _axis(axis)
    D = int(patch_level) + 1
    n = v.shape[s]
    plane = v.size // n
    step = max(1, RANGES_SLAB_BYTES // max(1, 4 * plane))  # slices per slab: bounded temporaries
    # open surface: outside nodes are left out of the minimum (+inf there)
    skip_out = not caps and bool(v.min() <= OUTSIDE_BELOW)
    out = np.empty((n - 1, *patch_grid(v.shape, patch_level, axis)[1::-1], 2), np.float32)
    for s0 in range(0, n - 1, step):  # slabs of slices, not cells
        s1 = min(n - 1, s0 + step)
        a, b = [slice(None)] * 3, [slice(None)] * 3
        a[s], b[s] = slice(s0, s1), slice(s0 + 1, s1 + 1)
        if skip_out:
            va, vb = v[tuple(a)], v[tuple(b)]
            lo = np.minimum(np.where(va <= OUTSIDE_BELOW, np.float32(np.inf), va),
                            np.where(vb <= OUTSIDE_BELOW, np.float32(np.inf), vb))
        else:
            lo = np.minimum(v[tuple(a)], v[tuple(b)])
        lo = _block_reduce(_block_reduce(lo, D, r, np.minimum), D, c, np.minimum)
        hi = np.maximum(v[tuple(a)], v[tuple(b)])
        hi = _block_reduce(_block_reduce(hi, D, r, np.maximum), D, c, np.maximum)
        both = np.stack([lo, hi], axis=-1).transpose(s, r, c, 3)
        out[s0:s1] = both   # written in place: no list of parts, no concatenated copy
    return out


def live_patch_cells(ranges, shape_zyx, level: float, patch_level: int = 64,
                     axis: str = "z") -> int:
    """Cells of the patches whose ``ranges`` (:func:`patch_ranges`) can hold ``level``.

    >>> v = np.zeros((3, 4, 70), np.float32); v[2, 3, 69] = 1
    >>> live_patch_cells(patch_ranges(v), v.shape, 0.5)   # slice 1, the second patch: 3 × 4 cells
    12
    """
    r = np.asarray(ranges)
    _, ri, ci = _axis(axis)
    shape = tuple(int(n) for n in shape_zyx)
    s = np.float32(level)
    live = (r[..., 0] < s) & (s <= r[..., 1])
    D = int(patch_level) + 1
    wc = np.minimum(D, (shape[ci] - 1) - D * np.arange(r.shape[2]))
    wr = np.minimum(D, (shape[ri] - 1) - D * np.arange(r.shape[1]))
    return int((live * (wr[:, None] * wc[None, :])[None]).sum())


def best_slice_axis(values, level: float, patch_level: int = 64, caps: bool = False,
                    keep: dict | None = None) -> tuple[str, dict]:
    """The slice axis leaving the fewest cells in patches that can hold ``level``.

    Returns the axis (ties: z, the paper's, then y, then x) and ``{axis: cells}``; ``keep``
    (a dict) receives ``{axis: patch_ranges}`` of the chosen axis, for the caller to use
    rather than computing them again (the other axes' are dropped as soon as beaten).

    >>> z, y, x = np.mgrid[0:20, 0:20, 0:20].astype(np.float32)
    >>> best_slice_axis(x, 9.5, 4)[0]     # a plane x = 9.5: slices along x
    'x'
    """
    v = _values32(values)
    cells, best = {}, None
    for a in ("z", "y", "x"):
        ranges = patch_ranges(v, patch_level, a, caps)
        cells[a] = live_patch_cells(ranges, v.shape, level, patch_level, a)
        if best is None or cells[a] < cells[best[0]]:   # ties: the earlier axis
            best = (a, ranges)
        del ranges
    if keep is not None:
        keep[best[0]] = best[1]
    return best[0], cells


def cells_in_live_patches(values, level: float, patch_level: int = 64, axis: str = "z",
                          caps: bool = False) -> int:
    """Cells of the patches that can hold ``level`` (what the GPU marches with skipping on).

    >>> v = np.zeros((3, 4, 70), np.float32); v[2, 3, 69] = 1
    >>> cells_in_live_patches(v, 0.5)
    12
    """
    v = _values32(values)
    return live_patch_cells(patch_ranges(v, patch_level, axis, caps), v.shape, level,
                            patch_level, axis)
