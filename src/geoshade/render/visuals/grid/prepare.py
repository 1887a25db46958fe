"""What each approach uploads, packed on the CPU with numpy (no GL, no loops over cells).

Every array here has exactly the size :func:`layout.gpu_plan` gives for it; the visual uploads
them as they are. Cells are numbered ``i + j*nx + k*nx*ny`` (the F-order flat index of the
model's arrays); ZCORN values ``(2i+a) + 2nx*((2j+b) + 2ny*(2k+c'))`` (F-order flat index of
``zcorn``).
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import pairwise

import numpy as np

from geoshade.compute.grid import kernels as grid_kernels
from geoshade.errors import InputError
from geoshade.render.visuals.grid import layout

_CORNER_ABC = np.array([[c & 1, c >> 1 & 1, c >> 2 & 1] for c in range(8)], np.int64)  # (8, 3)


def color_index(values: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """1-byte palette indices ``round((v - lo) / (hi - lo) * 255)``, clipped; NaN -> 0.

    >>> color_index(np.array([0.0, 0.5, 1.0, 2.0, np.nan]), 0.0, 1.0).tolist()
    [0, 128, 255, 255, 0]
    """
    if np.size(values) >= grid_kernels.MIN_CELLS and np.asarray(values).dtype.kind in "fiu":
        return grid_kernels.color_codes(np.asarray(values), lo, hi)   # the same, compiled
    v = np.asarray(values, np.float64)
    span = float(hi) - float(lo)
    t = (v - float(lo)) / span if span > 0 else np.zeros_like(v)
    t = np.nan_to_num(t, nan=0.0, posinf=1.0, neginf=0.0)
    return np.clip(np.rint(t * 255.0), 0, 255).astype(np.uint8)


def cell_numbers(cells: np.ndarray, dims) -> np.ndarray:
    """``i + j*nx + k*nx*ny`` of ``(n, 3)`` cells as int64 (compiled from a million)."""
    nx, ny, _ = dims
    if len(cells) >= grid_kernels.MIN_CELLS and np.asarray(cells).dtype == np.int32:
        return grid_kernels.cell_numbers(cells, nx, ny)
    c = np.asarray(cells, np.int64)
    return c[:, 0] + nx * (c[:, 1] + ny * c[:, 2])


def face_corner_abc(face: np.ndarray) -> np.ndarray:
    """``(n, 4, 3)`` corner offsets (a, b, c') of corners A, B, C, D of each face."""
    return _CORNER_ABC[layout.FACE_CORNER_TABLE[np.asarray(face, np.int64)]]


def zcorn_indices(cells: np.ndarray, face: np.ndarray, dims) -> np.ndarray:
    """``(n, 4)`` uint32 ZCORN flat indices of corners A, B, C, D of each face (approach 3)."""
    nx, ny, nz = dims
    if 8 * nx * ny * nz > 2**32:
        raise InputError(f"grid {nx}x{ny}x{nz}: more than 2^32 ZCORN values; approach 3 with "
                         "zcorn_store='grid' cannot index them (use zcorn_store='faces')")
    c = np.asarray(cells, np.int64)
    base = 2 * c[:, 0] + 2 * nx * (2 * c[:, 1] + 2 * ny * 2 * c[:, 2])
    abc = _CORNER_ABC[layout.FACE_CORNER_TABLE]                       # (6, 4, 3)
    offset = abc[..., 0] + 2 * nx * (abc[..., 1] + 2 * ny * abc[..., 2])  # (6, 4)
    return (base[:, None] + offset[np.asarray(face, np.int64)]).astype(np.uint32)


def draw_ranges(highlight: np.ndarray, group: np.ndarray | None = None, n_groups: int = 1
                ) -> tuple[np.ndarray, list[tuple[int, int, int, bool]]]:
    """A stable order of faces by (group, highlight) and the draw ranges it makes.

    Returns ``order`` and a list of ``(first, count, group, highlighted)`` ranges (empty ones
    left out): approaches 1 and 3 draw plain faces and faces to highlight in separate calls,
    with a uniform, instead of storing a flag per face.

    >>> order, ranges = draw_ranges(np.array([1, 0, 0, 1], bool), np.array([0, 0, 1, 1]), 2)
    >>> order.tolist(), ranges
    ([1, 0, 2, 3], [(0, 1, 0, False), (1, 1, 0, True), (2, 1, 1, False), (3, 1, 1, True)])
    """
    hl = np.asarray(highlight, bool).astype(np.int64)
    g = np.zeros(hl.size, np.int64) if group is None else np.asarray(group, np.int64)
    order = np.lexsort((hl, g))
    counts = np.bincount(2 * g + hl, minlength=2 * n_groups)
    ranges, first = [], 0
    for key, cnt in enumerate(counts.tolist()):
        if cnt:
            ranges.append((first, int(cnt), key // 2, bool(key % 2)))
        first += int(cnt)
    return order, ranges


def draw_runs(key: np.ndarray, most: int) -> list[tuple[int, int, int, bool]] | None:
    """The draw ranges of the faces *in their order*: one per run of equal keys
    (``2 * group + highlighted``), or None when there are more than ``most`` runs (then
    :func:`draw_ranges_keyed` sorts them).  Faces in drawing order come in a few runs of a
    2^29-cell bucket: no order array (8 bytes a face) and the order kept.

    >>> draw_runs(np.array([0, 0, 2, 2, 0], np.uint8), 8)
    [(0, 2, 0, False), (2, 2, 1, False), (4, 1, 0, False)]
    >>> draw_runs(np.array([0, 1, 0, 1], np.uint8), 3) is None
    True
    """
    k = np.asarray(key)
    if not k.size:
        return []
    starts = np.flatnonzero(k[1:] != k[:-1]) + 1
    if starts.size + 1 > most:
        return None
    bounds = np.concatenate([[0], starts, [k.size]])
    return [(int(a), int(b - a), int(k[a]) // 2, bool(int(k[a]) % 2))
            for a, b in pairwise(bounds.tolist())]


def draw_ranges_keyed(key: np.ndarray, n_groups: int
                      ) -> tuple[np.ndarray, list[tuple[int, int, int, bool]]]:
    """:func:`draw_ranges` from one small integer a face, ``2 * group + highlighted``
    (uint8: a stable radix sort, one byte a face instead of two int64 columns); the same
    order and ranges.

    >>> order, ranges = draw_ranges_keyed(np.array([1, 0, 2, 3], np.uint8), 2)
    >>> order.tolist(), ranges
    ([1, 0, 2, 3], [(0, 1, 0, False), (1, 1, 0, True), (2, 1, 1, False), (3, 1, 1, True)])
    """
    k = np.asarray(key)
    order = np.argsort(k, kind="stable")
    return order, key_ranges(np.bincount(k, minlength=2 * n_groups))


def key_ranges(counts: np.ndarray) -> list[tuple[int, int, int, bool]]:
    """The draw ranges of faces sorted by key (``2 * group + highlighted``), from the count
    of each key: ``(first, count, group, highlighted)``, empty ones left out.

    >>> key_ranges(np.array([2, 0, 1, 3]))
    [(0, 2, 0, False), (2, 1, 1, False), (3, 3, 1, True)]
    """
    ranges, first = [], 0
    for kk, cnt in enumerate(np.asarray(counts).tolist()):
        if cnt:
            ranges.append((first, int(cnt), kk // 2, bool(kk % 2)))
        first += int(cnt)
    return ranges


def cell_list(face_cells: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The distinct cells of the faces (``(m,)`` int64, ascending) and each face's place in
    that list (``(n,)`` int32, int64 from 2^31 cells on): one sort of the faces' cell numbers
    (in drawing order they are sorted runs), no bitmap of the whole grid.

    >>> cells, slot = cell_list(np.array([7, 3, 7, 9], np.uint32))
    >>> cells.tolist(), slot.tolist()
    ([3, 7, 9], [1, 0, 1, 2])
    """
    fc = np.asarray(face_cells).reshape(-1)
    if not fc.size:
        return np.zeros(0, np.int64), np.zeros(0, np.int32)
    s = np.sort(fc, kind="stable")
    keep = np.empty(s.size, bool)
    keep[0] = True
    np.not_equal(s[1:], s[:-1], out=keep[1:])
    cells = s[keep].astype(np.int64)
    del s, keep
    slot = np.empty(fc.size, np.int32 if cells.size < 2**31 else np.int64)
    step = 1 << 22
    for a in range(0, fc.size, step):  # batches of faces: bounded int64 temporaries
        slot[a:a + step] = np.searchsorted(cells, fc[a:a + step].astype(np.int64))
    return cells, slot


# --- approach 1 -----------------------------------------------------------------------------
@dataclass
class NodeGeometry:
    """Grid nodes of a (near-)conforming grid for approach 1.

    positions: ((nx+1)*(ny+1)*(nz+1), 3) uint16  node x, y, z in the local box, node
               ``I + (nx+1)*(J + (ny+1)*K)``
    lo, step:  (3,) float  local coordinate = lo + code * step
    spread:    float  largest difference between the corner depths that meet at one node (over
               active cells): 0 for a conforming grid
    mismatched_nodes: int  nodes where the corners differ by more than the tolerance
    z_error: float  largest |decoded - node depth| of the 16-bit depths
    """

    positions: np.ndarray
    lo: np.ndarray
    step: np.ndarray
    spread: float
    mismatched_nodes: int
    z_error: float = 0.0


def node_geometry(coord_local: np.ndarray, zcorn: np.ndarray, active: np.ndarray,
                  z_offset: float, rtol: float = 1e-6) -> NodeGeometry:
    """Node depths as the mean of the active corners meeting there, and their x, y on the pillars.

    ``coord_local`` is the (nx+1, ny+1, 6) COORD with the local origin subtracted (z included);
    ``zcorn`` the model's ZCORN (depths, not shifted); ``z_offset`` the local origin's depth.
    """
    nx, ny = coord_local.shape[0] - 1, coord_local.shape[1] - 1
    nz = zcorn.shape[2] // 2
    z = np.asarray(zcorn, np.float64)
    act = np.repeat(np.repeat(np.repeat(np.asarray(active, bool), 2, 0), 2, 1), 2, 2)
    zp = np.full((2 * nx + 2, 2 * ny + 2, 2 * nz + 2), np.nan)
    zp[1:-1, 1:-1, 1:-1] = np.where(act, z, np.nan)
    shape = (nx + 1, ny + 1, nz + 1)
    total, count = np.zeros(shape), np.zeros(shape)
    zmin, zmax = np.full(shape, np.inf), np.full(shape, -np.inf)
    for sa in (0, 1):
        for sb in (0, 1):
            for sc in (0, 1):
                v = zp[sa::2, sb::2, sc::2]
                ok = ~np.isnan(v)
                total += np.where(ok, v, 0.0)
                count += ok
                zmin = np.where(ok, np.minimum(zmin, v), zmin)
                zmax = np.where(ok, np.maximum(zmax, v), zmax)
    has = count > 0
    fill = float(np.mean(z)) if z.size else 0.0
    node_z = np.where(has, total / np.maximum(count, 1), fill)
    spread_arr = np.where(has, zmax - zmin, 0.0)
    span = float(np.ptp(z)) if z.size else 0.0
    tol = rtol * max(span, 1.0)
    mismatched = int(np.count_nonzero(spread_arr > tol))
    zl = node_z - z_offset  # local depth
    top = coord_local[:, :, None, :3]
    bot = coord_local[:, :, None, 3:]
    dz = bot[..., 2] - top[..., 2]
    t = np.where(dz != 0, (zl - top[..., 2]) / np.where(dz != 0, dz, 1.0), 0.0)
    xyz = np.stack([top[..., 0] + t * (bot[..., 0] - top[..., 0]),
                    top[..., 1] + t * (bot[..., 1] - top[..., 1]), zl], axis=-1)
    flat = xyz.reshape(-1, 3, order="F")  # node I + (nx+1)(J + (ny+1)K)
    lo = flat.min(axis=0)
    hi = flat.max(axis=0)
    step = np.where(hi > lo, (hi - lo) / 65535.0, 1.0)
    codes = np.rint((flat - lo) / step).clip(0, 65535).astype(np.uint16)
    err = float(np.abs(lo[2] + codes[:, 2] * step[2] - flat[:, 2]).max(initial=0.0))
    return NodeGeometry(np.ascontiguousarray(codes), lo, step, float(spread_arr.max(initial=0.0)),
                        mismatched, err)


def node_colors(ci: np.ndarray, dims) -> np.ndarray:
    """``(nodes, 2)`` uint8: colour 1 = cell (I, J, K), colour 2 = cell (I-1, J-1, K-1) (Table 1).

    ``ci`` is the per-cell colour index, flat in cell-number order.
    """
    nx, ny, nz = dims
    c = np.asarray(ci, np.uint8).reshape((nx, ny, nz), order="F")
    out = np.zeros((nx + 1, ny + 1, nz + 1, 2), np.uint8, order="F")
    out[:nx, :ny, :nz, 0] = c
    out[1:, 1:, 1:, 1] = c
    return np.ascontiguousarray(
        np.stack([out[..., 0].ravel(order="F"), out[..., 1].ravel(order="F")], axis=1))


def node_triangles(cells: np.ndarray, face: np.ndarray, dims) -> np.ndarray:
    """``(n, 6)`` uint32 node indices of triangles (A, B, C), (A, C, D) of each face.

    A is the face's provoking node: (i, j, k) for minus faces, (i+1, j+1, k+1) for plus faces.
    """
    nx, ny, nz = dims
    if (nx + 1) * (ny + 1) * (nz + 1) >= 2**32:
        raise InputError(f"grid {nx}x{ny}x{nz}: too many nodes for 32-bit indices (approach 1)")
    c = np.asarray(cells, np.int64)
    base = c[:, 0] + (nx + 1) * (c[:, 1] + (ny + 1) * c[:, 2])
    abc = _CORNER_ABC[layout.FACE_CORNER_TABLE]                               # (6, 4, 3)
    offset = abc[..., 0] + (nx + 1) * (abc[..., 1] + (ny + 1) * abc[..., 2])  # (6, 4)
    node = base[:, None] + offset[np.asarray(face, np.int64)]                 # A B C D
    return node[:, [0, 1, 2, 0, 2, 3]].astype(np.uint32)


# --- approach 2 -----------------------------------------------------------------------------
@dataclass
class CellRecords:
    """Approach 2: one 8-byte record per cell with a visible face (Table 2).

    cells:   (m,) int64 cell numbers, ascending
    mask:    (m,) uint8  visibility bits in the paper's order (-X, X, -Y, Y, -Z, Z)
    fault:   (m,) uint8  the same bits for faces to highlight
    """

    cells: np.ndarray
    mask: np.ndarray
    fault: np.ndarray

    def pack(self, ci: np.ndarray) -> np.ndarray:
        """``(m, 2)`` uint32 words: cell number; fault | mask << 16 | colour << 24; ``ci``
        holds one colour index per record (``(m,)``)."""
        out = np.empty((self.cells.size, 2), np.uint32)
        out[:, 0] = self.cells.astype(np.uint32)
        colour = np.asarray(ci, np.uint8).ravel().astype(np.uint32)
        out[:, 1] = (self.fault.astype(np.uint32) << layout.A2_FAULT_SHIFT
                     | self.mask.astype(np.uint32) << layout.A2_MASK_SHIFT
                     | colour << layout.A2_COLOR_SHIFT)
        return out


_PAPER_BIT = np.array([1 << layout.PAPER_MASK_BIT[f] for f in range(6)], np.int64)


def cell_records(cells: np.ndarray, face: np.ndarray, highlight: np.ndarray, dims) -> CellRecords:
    """Group visible faces by cell into approach-2 records."""
    nx, ny, nz = dims
    if nx * ny * nz >= 2**32:
        raise InputError(f"grid {nx}x{ny}x{nz}: cell numbers do not fit 32 bits (approach 2)")
    lin = cell_numbers(cells, dims)
    uniq, inv = np.unique(lin, return_inverse=True)
    bits = _PAPER_BIT[np.asarray(face, np.int64)]
    # each (cell, face) occurs once, so a sum of distinct bits is their OR
    mask = np.bincount(inv, weights=bits, minlength=uniq.size).astype(np.uint8)
    hl = np.bincount(inv, weights=np.where(np.asarray(highlight, bool), bits, 0),
                     minlength=uniq.size).astype(np.uint8)
    return CellRecords(uniq, mask, hl)


# --- approach 3, faces storage ---------------------------------------------------------------
def face_records(cells: np.ndarray, face: np.ndarray, dims, zsource: np.ndarray | None,
                 z_offset: float = 0.0, quantise: tuple[float, float] | None = None,
                 corners: np.ndarray | None = None, numbers: np.ndarray | None = None
                 ) -> tuple[np.ndarray, float]:
    """``(n, 3)`` uint32 (16-bit depths) or ``(n, 5)`` uint32 (32-bit) face records, and the
    largest quantisation error of their corners (0 unless ``quantise``).

    ``zsource`` is the F-order flat ZCORN: uint16 codes (stored as they are) or depths (stored
    as float32 ``depth - z_offset``, or, with ``quantise=(z0, scale)``, as the 16-bit codes
    ``rint((depth - z0) / scale)`` that :func:`geoshade.compute.grid.geometry.zcorn_quantise`
    gives the same corners: only the drawn corners are quantised). ``corners`` ``(n, 4)``:
    the depths of corners A, B, C, D already gathered (a grid out of core:
    :func:`geoshade.compute.grid.chunks.face_corner_depths`), instead of ``zsource``;
    ``numbers``: the cells' numbers when the caller has them. Word 0 =
    cell number << 3 | face, then the depths of corners A, B, C, D.
    """
    nx, ny, nz = dims
    if nx * ny * nz > 2**32:
        raise InputError(f"grid {nx}x{ny}x{nz}: more than 2^32 cells; approach 3 with "
                         "zcorn_store='faces' numbers cells with 32 bits")
    # cell numbers beyond 2^29 keep their low 29 bits here; the draw call of their range adds
    # the rest (``cell_base``, :func:`a3f_buckets`)
    if corners is not None and np.asarray(face).size >= 1 << 16:   # compiled, the same bits
        num = cell_numbers(cells, dims) if numbers is None else numbers
        return grid_kernels.face_words(num, face, corners, layout.A3F_BUCKET_BITS,
                                       layout.A3F_FACE_BITS, z_offset, quantise)
    lin = (cell_numbers(cells, dims) if numbers is None else np.asarray(numbers, np.int64)) \
        & ((1 << layout.A3F_BUCKET_BITS) - 1)
    if corners is not None:
        zv = np.asarray(corners).reshape(-1, 4)
    else:
        zi = zcorn_indices(cells, face, dims).astype(np.int64)
        zv = np.asarray(zsource)[zi]  # (n, 4)
        del zi
    head = (lin.astype(np.uint32) << np.uint32(layout.A3F_FACE_BITS)) | np.asarray(
        face, np.uint32)
    err = 0.0
    if quantise is not None:
        z0, scale = (float(v) for v in quantise)
        q = (zv.astype(np.float64) - z0) / scale
        np.rint(q, out=q)
        np.clip(q, 0, 65535, out=q)
        codes = q.astype(np.uint16)
        q *= scale
        q += z0
        q -= zv
        err = float(np.abs(q, out=q).max(initial=0.0))
        zv = codes
    if zv.dtype == np.uint16:
        out = np.empty((lin.size, 3), np.uint32)
        out[:, 0] = head
        out[:, 1:] = np.ascontiguousarray(zv).view(np.uint32)
        return out, err
    out = np.empty((lin.size, 5), np.uint32)
    out[:, 0] = head
    local = (zv.astype(np.float64) - float(z_offset)).astype(np.float32)
    out[:, 1:] = np.ascontiguousarray(local).view(np.uint32)
    return out, err


#: faces whose records :class:`StagedFaces` builds at a time
STAGE_BATCH = 1 << 20


@dataclass
class StagedFaces:
    """Approach 3 face records built on the CPU, block by block, with no GL (a grid out of
    core: a filter's faces are made and staged a layer at a time while the next layer is read;
    :meth:`~geoshade.render.visuals.grid.visual.GridVisual.set_staged` uploads them, freeing
    each block once uploaded).

    ``blocks``: ``(records, key, add)``, one per :meth:`add` (a layer), in drawing order: the
    records of :func:`face_records` (16-bit depths with ``quantise``, else float32 ``depth -
    z_offset``), each face's key ``2 * 2^29-cell bucket + highlighted`` and which add staged
    it; a face's cell number is in its record and key (:meth:`face_cells`).
    Memory: ``4 * words + 1`` bytes a face (21 with 32-bit depths), the GPU's records plus
    one, and the adds' lists of cells with a face (8 bytes a cell, kept as the visual's),
    instead of the faces' columns and corners (~33 bytes a face) until the upload.

    Examples
    --------
    >>> st = StagedFaces((4, 3, 2))
    >>> st.add(np.array([[1, 2, 1]], np.int32), np.array([2], np.uint8), None,
    ...        np.array([[5.0, 6.0, 7.0, 8.0]], np.float32))
    >>> st.n, st.blocks[0][0].shape, st.face_cells(*st.blocks[0][:2]).tolist()
    (1, (1, 5), [21])
    """

    dims: tuple
    z_offset: float = 0.0
    quantise: tuple | None = None
    blocks: list = None  # type: ignore[assignment]
    n: int = 0
    zerr: float = 0.0

    def __post_init__(self) -> None:
        self.blocks = [] if self.blocks is None else self.blocks
        self.dims = tuple(int(v) for v in self.dims)
        self._cells: list = []       # each add's cells with a face, ascending
        self._after = True           # every add's cells above the previous adds'
        self._whole: np.ndarray | None = None   # the adds' lists as one (cell_list)
        self._last = -1

    def cell_list(self) -> tuple[np.ndarray, None] | None:
        """``(cells with a face, None)``, ascending int64: the adds' lists one after the other
        when each add's cells lie above the previous adds' (a filter's layers, top down); None
        otherwise (then :func:`cell_list` sorts every face's cell)."""
        if not self._after:
            return None
        if self._whole is None:   # one list, the adds' lists views of it (not two copies)
            whole = (self._cells[0] if len(self._cells) == 1 else np.concatenate(self._cells)
                     if self._cells else np.zeros(0, np.int64))
            at = np.cumsum([0] + [u.size for u in self._cells]).tolist()
            self._cells = [whole[a:b] for a, b in pairwise(at)]
            self._whole = whole
        return self._whole, None

    def slots(self, face_cells: np.ndarray, layer: int) -> np.ndarray:
        """Places of cells ``face_cells`` of add ``layer`` in :meth:`cell_list`."""
        off = sum(u.size for u in self._cells[:layer])
        return np.searchsorted(self._cells[layer], face_cells.astype(np.int64)) + off

    @staticmethod
    def face_cells(records: np.ndarray, key: np.ndarray) -> np.ndarray:
        """``(n,)`` int64 cell numbers of faces from their records (the cell's low 29 bits)
        and keys (its 2^29-cell range)."""
        num = (np.asarray(records)[:, 0] >> np.uint32(layout.A3F_FACE_BITS)).astype(np.int64)
        if np.asarray(key).size and int(key.max()) > 1:
            num += (np.asarray(key, np.int64) >> 1) << layout.A3F_BUCKET_BITS
        return num

    @property
    def words(self) -> int:
        """uint32 words a record: 3 with 16-bit depths, else 5."""
        return 3 if self.quantise is not None else 5

    @property
    def nbytes(self) -> int:
        """Bytes staged."""
        return int(sum(b[0].nbytes + b[1].nbytes for b in self.blocks)
                   + sum(c.nbytes for c in self._cells))

    def add(self, cells: np.ndarray, face: np.ndarray, highlight, corners: np.ndarray) -> None:
        """Stage faces (the next ones in drawing order) with their ``(n, 4)`` corner depths;
        ``highlight``: None or ``(n,)`` bool."""
        cells = np.asarray(cells).reshape(-1, 3)
        n = int(np.asarray(face).size)
        big = int(np.prod(self.dims)) > (1 << layout.A3F_BUCKET_BITS)
        layer = len(self._cells)
        self._whole = None
        num_all = cell_numbers(cells, self.dims)
        if self._after:   # this add's cells with a face (a layer: a few million)
            # a stable sort (timsort: a layer's faces are ~100 sorted runs, 3x faster than
            # quicksort here); numpy's unique hashes, ~10x slower
            u = np.sort(num_all, kind="stable")
            keep = np.empty(u.size, bool)
            keep[:1] = True
            np.not_equal(u[1:], u[:-1], out=keep[1:])
            u = u[keep]
            del keep
            if u.size and u[0] <= self._last:
                self._after, self._cells = False, []
            else:
                self._cells.append(u)
                self._last = int(u[-1]) if u.size else self._last
            del u
        if not n:
            return
        rec = np.empty((n, self.words), np.uint32)   # the layer's records: one GPU buffer
        key = np.empty(n, np.uint16 if big else np.uint8)
        for f0 in range(0, n, STAGE_BATCH):   # bounded temporaries
            sl = slice(f0, min(n, f0 + STAGE_BATCH))
            num = num_all[sl]
            rec[sl], err = face_records(cells[sl], np.asarray(face[sl]), self.dims, None,
                                        self.z_offset, quantise=self.quantise,
                                        corners=corners[sl], numbers=num)
            key[sl] = 2 * a3f_buckets(num)
            if highlight is not None:
                key[sl] += np.asarray(highlight[sl], bool)
            self.zerr = max(self.zerr, err)
            del num
        self.blocks.append((rec, key, layer))
        self.n += n
        del num_all


def a3f_buckets(cell_numbers_: np.ndarray) -> np.ndarray:
    """``(n,)`` int64: which 2^29-cell range each face's cell is in (0 below 2^29 cells); faces
    of one range are drawn with ``cell_base = bucket << 29``."""
    return np.asarray(cell_numbers_, np.int64) >> layout.A3F_BUCKET_BITS


# --- linear textures ---------------------------------------------------------------------------
def to_linear_texture(flat: np.ndarray, per_texel: int) -> np.ndarray:
    """Pad a flat array into a ``(h, w, per_texel)`` block for a linear 2D texture."""
    flat = np.asarray(flat).ravel()
    texels = -(-flat.size // per_texel)
    w, h = layout.linear_texture_shape(texels)
    out = np.zeros(w * h * per_texel, flat.dtype)
    out[:flat.size] = flat
    return out.reshape(h, w, per_texel) if per_texel > 1 else out.reshape(h, w)


def coord_texture(coord_local: np.ndarray) -> np.ndarray:
    """COORD as RGB32F texels ``(h, w, 3)``: pillar ``p = I + (nx+1)*J`` -> texel 2p (top),
    2p+1 (bottom)."""
    rows = np.asarray(coord_local, np.float32).transpose(1, 0, 2).reshape(-1, 3)
    w, h = layout.linear_texture_shape(rows.shape[0])
    out = np.zeros((w * h, 3), np.float32)
    out[: rows.shape[0]] = rows
    return out.reshape(h, w, 3)
