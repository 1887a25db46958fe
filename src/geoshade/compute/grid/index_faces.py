"""What a grid store's index holds, computed (issue 26, target 1), and the faces of a filter or
slice made from it: :mod:`geoshade.io.stores.grid_index` writes and reads the arrays.

- :func:`store_index`: the visible faces of the unfiltered grid (chunk by chunk,
  :func:`~geoshade.compute.grid.chunks.visible_faces_chunked`), their corner depths, their
  grouping by chunk, each chunk's active count, each cell array's per-chunk min/max/count of
  its active finite values, and the face cells' values of every array and step.
- :func:`chunk_status`: which chunks a filter and slice cannot select (skipped unread), select
  wholly, or must read.
- :func:`index_faces`: the visible faces of a shown mask from the index's fault flags, with no
  ZCORN read: a face of an active cell is visible when it is at the grid's boundary, the cell
  across is not shown, or the two cells' corners do not match — and the unfiltered grid's
  faces record that mismatch (a face between two active cells is there only when mismatched;
  a face towards an inactive cell carries its fault flag).  The rule of
  :func:`~geoshade.compute.grid.faces.visible_faces`, so the faces are the same, bit for bit.
"""

from __future__ import annotations

import ast
import operator
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from geoshade.compute.grid.chunks import (
    FACE_ABC,
    CellGroups,
    chunk_source,
    corners_in_block,
    face_corner_depths,
    visible_faces_chunked,
)
from geoshade.compute.grid.faces import drawing_slab, visible_faces
from geoshade.compute.grid.filters import Filter
from geoshade.compute.grid.geometry import orientation_sign
from geoshade.models.grid import MAX_COORDINATE, CornerPointGrid
from geoshade.progress import Progress, resolve, scaled
from geoshade.scheduler import dask_get

__all__ = ["FAULT_TOL", "IndexFaces", "cell_arrays", "chunk_numbers", "chunk_status", "index_faces",
           "sample_faces", "store_index"]

#: fault tolerance of the stored faces (the View's faces use the same)
FAULT_TOL = 0.0
#: bytes of chunks (every cell array) read at once while the statistics are gathered
BATCH_BYTES = 256 << 20
#: cells of the back-face orientation sample (``geoshade.grid.lazy.orientation``'s)
ORIENTATION_SAMPLES = 4096
_CORNERS8 = np.array([(c & 1, c >> 1 & 1, c >> 2 & 1) for c in range(8)])
#: (6, 3) the cell across each face 0..5 = I+ J+ K+ I- J- K-
_OFFSETS = np.array([(1, 0, 0), (0, 1, 0), (0, 0, 1), (-1, 0, 0), (0, -1, 0), (0, 0, -1)],
                    np.int64)


def cell_arrays(grid) -> list[tuple[str, int | None]]:
    """``(key, step)`` of every cell array of a store grid: ``("props/PORO", None)``, then
    ``("steps/SWAT", t)`` for every step."""
    out: list[tuple[str, int | None]] = [(f"props/{n}", None) for n in grid.properties]
    kws = list(grid.meta.get("step_keywords") or (grid.steps[0] if grid.steps else []))
    out += [(f"steps/{kw}", t) for kw in kws for t in range(len(grid.steps))]
    return out


def cell_array(grid, key: str, t: int | None):
    """The cell array ``key`` (``props/NAME`` or ``steps/KW`` at step ``t``) of a grid."""
    kind, name = key.split("/", 1)
    return grid.properties[name] if kind == "props" else grid.steps[int(t)][name]


def cell_chunks(grid) -> tuple[tuple[int, ...], ...]:
    """The cell chunks (dask per-axis tuples) of a store grid (half its ZCORN's)."""
    return tuple(tuple(c // 2 for c in axis) for axis in grid.zcorn.chunks)


def chunk_numbers(cells: np.ndarray, chunks) -> np.ndarray:
    """(n,) int64 chunk number (C order of the chunk grid) of each (i, j, k) cell.

    Examples
    --------
    >>> chunk_numbers(np.array([[0, 0, 0], [3, 1, 2]]), ((2, 2), (2,), (2, 1))).tolist()
    [0, 3]
    """
    ends = [np.cumsum(axis) for axis in chunks]
    nb = [len(axis) for axis in chunks]
    out = np.zeros(len(cells), np.int64)
    for a in range(3):
        out = out * nb[a] + np.searchsorted(ends[a], np.asarray(cells)[:, a], side="right")
    return out


def orientation_sample(dims, samples: int = ORIENTATION_SAMPLES) -> np.ndarray:
    """(n, 3) int64 i, j, k of the cells whose corners decide a grid's back-face sign: spread
    over the grid (the active ones among them are used)."""
    nx, ny, nz = dims
    n = nx * ny * nz
    num = np.unique(np.linspace(0, n - 1, min(4 * samples, n)).astype(np.int64))
    return np.stack([num % nx, num // nx % ny, num // (nx * ny)], 1)


def store_index(grid, progress: Progress | None = None, scheduler=None) -> dict:
    """The arrays of a store grid's index (names as in :mod:`geoshade.io.stores.grid_index`).

    Parameters
    ----------
    grid : CornerPointGrid
        A grid store opened lazily (dask arrays chunked as the store).
    progress : callable(done, total), optional
        Called as chunks are done (faces, then statistics and face values).
    scheduler : optional
        Where the faces' chunk tasks run (:func:`visible_faces_chunked`).

    Returns
    -------
    dict
        name -> numpy array; ``stats/<key>`` is ``(nt, nchunks, 3)`` (min, max, count; NaN
        min/max where the count is 0), ``values/<key>`` ``(nt, m)``, ``zbounds``
        ``(nchunks, 4)`` each chunk's min/max depth of its usable corners, then of its active
        cells' (NaN where none), ``orientation`` ``(1,)`` the back-face sign of
        :func:`orientation_sample`'s active cells.

    Memory: the faces and their corners, plus a batch of chunks of every array
    (:data:`BATCH_BYTES`).

    Examples
    --------
    >>> import os, tempfile
    >>> from geoshade.compute.grid.synthetic import synthetic_grid
    >>> from geoshade.compute.grid.faces import drawing_slab, visible_faces
    >>> from geoshade.io.stores.grid_store import ModelSource, open_grid_store, write_grid_store
    >>> g = synthetic_grid(6, 5, 4, steps=1)
    >>> rep = write_grid_store(ModelSource(g), os.path.join(tempfile.mkdtemp(), "g.zarr"),
    ...                        (3, 3, 2))
    >>> out = store_index(open_grid_store(rep.path))
    >>> bool((out["faces/cells"] == visible_faces(g).cells).all()), out["stats/props/PORO"].shape
    (True, (1, 8, 3))
    """
    import dask

    ch = cell_chunks(grid)
    nb = tuple(len(a) for a in ch)
    nch = int(np.prod(nb))
    total = 2 * nch + 1
    cb = resolve(progress)
    fs = visible_faces_chunked(grid, None, FAULT_TOL, scheduler=scheduler,
                               progress=scaled(progress, 0, nch, total))
    cells, face = fs.cells, fs.face
    flags = fs.fault.astype(np.uint8) | (fs.neighbour_shown.astype(np.uint8) << 1)
    del fs
    out: dict[str, np.ndarray] = {"faces/cells": cells, "faces/face": face,
                                  "faces/flags": flags}
    out["faces/corners"] = face_corner_depths(grid.zcorn, cells, face)
    cb(nch + 1, total)
    cnum = chunk_numbers(cells, ch)
    out["faces/by_chunk"] = np.argsort(cnum, kind="stable").astype(np.int64)
    out["faces/offsets"] = np.concatenate(
        [[0], np.cumsum(np.bincount(cnum, minlength=nch))]).astype(np.int64)
    del cnum
    nx, ny, _ = grid.dims
    c64 = cells.astype(np.int64)
    face_cells = np.unique(c64[:, 0] + nx * (c64[:, 1] + ny * c64[:, 2]))
    del c64
    out["cells"] = face_cells
    groups = CellGroups(face_cells, grid.dims, ch)
    gmap = {int(np.ravel_multi_index(tuple(b), nb)): g for g, b in enumerate(groups.blocks)}
    keys = cell_arrays(grid)
    lazies = [cell_array(grid, k, t) for k, t in keys]
    nact = np.zeros(nch, np.int64)
    nts = {k: (1 if t is None else len(grid.steps)) for k, t in keys}
    stats = {k: np.zeros((nts[k], nch, 3)) for k in nts}
    values = {k: np.zeros((nts[k], face_cells.size), cell_array(grid, k, t).dtype)
              for k, t in keys}
    zb = np.full((nch, 4), np.nan)
    sample = orientation_sample(grid.dims)
    snum = chunk_numbers(sample, ch)
    s_act = np.zeros(len(sample), bool)
    s_z = np.zeros((len(sample), 8))
    starts = [np.concatenate([[0], np.cumsum(a)]) for a in ch]
    per = int(np.prod([max(a) for a in ch])) * (33 + sum(a.dtype.itemsize for a in lazies))
    batch = max(1, BATCH_BYTES // max(1, per))
    idxs = list(np.ndindex(*nb))
    for b0 in range(0, nch, batch):  # batches of chunks: every array's blocks read once
        sel = idxs[b0:b0 + batch]
        got = list(dask.compute(*[grid.actnum.blocks[i] for i in sel],
                                *[a.blocks[i] for a in lazies for i in sel],
                                *[grid.zcorn.blocks[i] for i in sel],
                                scheduler=dask_get("threads"), num_workers=2))
        for n, i in enumerate(sel):
            c = b0 + n
            act = np.asarray(got[n]) != 0
            nact[c] = int(np.count_nonzero(act))
            z = np.asarray(got[len(sel) * (len(keys) + 1) + n])
            _depths(z, act, zb[c])
            mine = np.flatnonzero(snum == c)
            if mine.size:  # the orientation sample's cells in this chunk
                loc = sample[mine] - np.array([starts[a][i[a]] for a in range(3)])
                s_act[mine] = act[loc[:, 0], loc[:, 1], loc[:, 2]]
                q = 2 * loc[:, None, :] + _CORNERS8[None]
                s_z[mine] = z[q[..., 0], q[..., 1], q[..., 2]]
            g = gmap.get(c)
            for a, (k, t) in enumerate(keys):
                v = np.asarray(got[len(sel) * (a + 1) + n])
                ok = act & np.isfinite(v) if v.dtype.kind == "f" else act
                w = v[ok]
                row = 0 if t is None else t
                stats[k][row, c] = ((float(w.min()), float(w.max()), w.size) if w.size
                                    else (np.nan, np.nan, 0))
                if g is not None:
                    lo, hi = groups.bounds[g], groups.bounds[g + 1]
                    values[k][row, groups.order[lo:hi]] = np.ravel(v, order="C")[
                        groups.local[lo:hi]]
        got.clear()
        cb(nch + 1 + min(nch, b0 + batch), total)
    out["nactive"] = nact
    out["zbounds"] = zb
    coord = np.asarray(grid.coord)
    out["orientation"] = np.array([float(orientation_sign(
        coord, sample[s_act, 0], sample[s_act, 1], s_z[s_act]))
        if s_act.any() else 0.0])
    for k in nts:
        out[f"stats/{k}"] = stats[k]
        out[f"values/{k}"] = values[k]
    cb(total, total)
    return out


def _depths(z: np.ndarray, act: np.ndarray, row: np.ndarray) -> None:
    """``row[:] = `` min/max depth of a ZCORN chunk's usable corners, then of its active
    cells' (NaN where none): the parts of :func:`geoshade.grid.lazy.bounds`."""
    usable = np.abs(z) <= MAX_COORDINATE
    act8 = act.repeat(2, 0).repeat(2, 1).repeat(2, 2)
    for col, m in ((0, usable), (2, usable & act8)):
        if m.any():
            w = z[m]
            row[col], row[col + 1] = float(w.min()), float(w.max())


def sample_faces(grid, index, cc) -> str:
    """``""`` when a store index's faces of the chunk of cells ``cc`` are those computed again
    from the chunk's ZCORN and ACTNUM (one chunk read: the faces between its own cells and
    towards the grid's boundary, their fault and neighbour flags and corner depths), else what
    differs: the sample :func:`geoshade.io.stores.grid_index.open_index` takes as ``check``.

    Examples
    --------
    >>> import os, tempfile
    >>> from geoshade.compute.grid.synthetic import synthetic_grid
    >>> from geoshade.io.stores.grid_index import open_index
    >>> from geoshade.io.stores.grid_store import ModelSource, open_grid_store, write_grid_store
    >>> rep = write_grid_store(ModelSource(synthetic_grid(6, 5, 4)), os.path.join(
    ...     tempfile.mkdtemp(), "g.zarr"), (3, 3, 2), index=store_index)
    >>> g = open_grid_store(rep.path)
    >>> sample_faces(g, open_index(g), (1, 0, 1))
    ''
    """
    ch = cell_chunks(grid)
    nb = tuple(len(a) for a in ch)
    lo = np.array([sum(ch[a][:cc[a]]) for a in range(3)], np.int64)
    hi = lo + np.array([ch[a][cc[a]] for a in range(3)], np.int64)
    # the chunk's own ZCORN and ACTNUM chunks, read by the store's reader where it has one
    zsrc, asrc = chunk_source(grid.zcorn), chunk_source(grid.actnum)
    zc = np.asarray(zsrc.chunk(tuple(cc)) if zsrc is not None else grid.zcorn[
        2 * lo[0]:2 * hi[0], 2 * lo[1]:2 * hi[1], 2 * lo[2]:2 * hi[2]], np.float32)
    act = np.asarray(asrc.chunk(tuple(cc)) if asrc is not None else
                     grid.actnum[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2]])
    coord = np.asarray(grid.coord)[lo[0]:hi[0] + 1, lo[1]:hi[1] + 1]
    sub = CornerPointGrid(coord=np.array(coord), zcorn=np.asfortranarray(zc),
                          actnum=np.asfortranarray(act))
    fs = visible_faces(sub, fault_tol=FAULT_TOL)
    dims = np.asarray(grid.dims, np.int64)

    def rows(cells, face, fault, nbs, corners):
        """The faces whose cell across is in the chunk or beyond the grid, sorted."""
        cells = np.asarray(cells, np.int64)
        face = np.asarray(face, np.int64)
        across = cells + _OFFSETS[face]
        keep = ((across >= lo) & (across < hi)).all(1) | ((across < 0) | (across >= dims)).any(1)
        r = np.concatenate([cells[keep], face[keep, None], np.asarray(fault)[keep, None],
                            np.asarray(nbs)[keep, None]], 1).astype(np.int64)
        order = np.lexsort(r.T[::-1])
        return r[order], np.asarray(corners)[keep][order]

    mine, mine_z = rows(fs.cells.astype(np.int64) + lo, fs.face, fs.fault, fs.neighbour_shown,
                        face_corner_depths(zc, fs.cells, fs.face))
    # the chunk's faces lie in one k-slab's span of the drawing order: that span is read
    pos = np.sort(index.chunk_positions(int(np.ravel_multi_index(tuple(cc), nb))))
    flags = index.part("faces/flags", pos)
    theirs, theirs_z = rows(index.part("faces/cells", pos), index.part("faces/face", pos),
                            (flags & 1) != 0, (flags & 2) != 0, index.part("faces/corners", pos))
    where = f"chunk {'/'.join(map(str, cc))}"
    if mine.shape != theirs.shape or not np.array_equal(mine, theirs):
        return (f"{where}: its faces are not those of the store's cells ({len(theirs)} kept, "
                f"{len(mine)} computed)")
    if not np.array_equal(mine_z, theirs_z, equal_nan=True):
        return f"{where}: its faces' corner depths are not the store's"
    return ""


# --------------------------------------------------------------------------------------------
# which chunks a filter or slice can select
# --------------------------------------------------------------------------------------------
_OPS = {ast.Lt: operator.lt, ast.LtE: operator.le, ast.Gt: operator.gt, ast.GtE: operator.ge,
        ast.Eq: operator.eq, ast.NotEq: operator.ne}
_MIRROR = {ast.Lt: ast.Gt, ast.LtE: ast.GtE, ast.Gt: ast.Lt, ast.GtE: ast.LtE, ast.Eq: ast.Eq,
           ast.NotEq: ast.NotEq}


def _const(node) -> float | None:
    if isinstance(node, ast.Constant) and isinstance(node.value, int | float) \
            and not isinstance(node.value, bool):
        return float(node.value)
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub | ast.UAdd):
        v = _const(node.operand)
        return None if v is None else (-v if isinstance(node.op, ast.USub) else v)
    return None


def _compare(op, st: np.ndarray, nact: np.ndarray, dtype, c: float):
    """(never, always) per chunk of ``NAME op c`` from the chunks' (min, max, count): the
    comparison made in the array's dtype, as the filter makes it (NaN compares false, except
    with ``!=``)."""
    lo, hi, cnt = st[:, 0], st[:, 1], st[:, 2]
    empty = cnt == 0
    full = cnt == nact
    lt = np.where(empty, 0, lo).astype(dtype)
    ht = np.where(empty, 0, hi).astype(dtype)
    f = _OPS[op]
    if op in (ast.Gt, ast.GtE):
        never, always = empty | ~f(ht, c), full & ~empty & f(lt, c)
    elif op in (ast.Lt, ast.LtE):
        never, always = empty | ~f(lt, c), full & ~empty & f(ht, c)
    elif op is ast.Eq:
        inside = (lt <= c) & (ht >= c)
        never, always = empty | ~inside, full & ~empty & (lt == c) & (ht == c)
    else:  # !=: a NaN cell passes
        never = full & ~empty & (lt == c) & (ht == c)
        always = empty | (lt > c) | (ht < c)
    return np.asarray(never, bool), np.asarray(always, bool)


def chunk_status(grid, nactive: np.ndarray, stats, filter=None, slice=None, step=None
                 ) -> np.ndarray:
    """(nchunks,) uint8 per chunk of cells (C order): 0 the filter and slice select no cell
    there (proved by its statistics or the slice box), 1 they select every active cell, 2
    unknown (its cells must be read).

    Comparisons of a property (or the step's keyword) with a number, chained or combined by
    and/or/not, are decided from the chunk's min/max/count (``stats(key, t)``: (nchunks, 3));
    anything else (arithmetic, functions, two properties, an array ``stats`` gives None
    for) counts as unknown.

    Examples
    --------
    >>> import dask.array as da
    >>> from geoshade.models import CornerPointGrid
    >>> g = CornerPointGrid(np.zeros((3, 2, 6)), da.zeros((4, 2, 2), np.float32, chunks=2),
    ...                     properties={"P": da.from_array(np.array([1., 5.]).reshape(2, 1, 1))})
    >>> st = {"props/P": np.array([[1.0, 1.0, 1], [5.0, 5.0, 1]])}
    >>> chunk_status(g, np.array([1, 1]), lambda k, t: st[k], "P > 2").tolist()
    [0, 1]
    """
    nact = np.asarray(nactive)
    nch = nact.size
    never = nact == 0
    always = np.ones(nch, bool)
    f = Filter.parse(filter)
    if f is not None:
        avail = {n: ("props/" + n, None) for n in grid.properties}
        if step is not None and grid.steps:
            avail.update({k: ("steps/" + k, int(step)) for k in grid.steps[int(step)]
                          if k not in avail})
        used = f.resolve(list(avail))
        unknown = (np.zeros(nch, bool), np.zeros(nch, bool))

        def pair(left, op, right):
            if isinstance(right, ast.Name) and _const(left) is not None:
                left, op, right = right, _MIRROR[op], left
            c = _const(right)
            if not isinstance(left, ast.Name) or c is None or left.id not in used:
                return unknown
            key, t = avail[used[left.id]]
            st = stats(key, t)
            if st is None:
                return unknown
            return _compare(op, st, nact, cell_array(grid, key, t).dtype, c)

        def cond(node):
            if isinstance(node, ast.Expression):
                return cond(node.body)
            if isinstance(node, ast.BoolOp):
                parts = [cond(v) for v in node.values]
                n = np.stack([p[0] for p in parts])
                a = np.stack([p[1] for p in parts])
                if isinstance(node.op, ast.And):
                    return n.any(0), a.all(0)
                return n.all(0), a.any(0)
            if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.Not):
                n, a = cond(node.operand)
                return a, n
            if isinstance(node, ast.Compare):
                out_n, out_a = np.zeros(nch, bool), np.ones(nch, bool)
                left = node.left
                for op, right in zip(node.ops, node.comparators, strict=True):
                    n, a = pair(left, type(op), right)
                    out_n, out_a = out_n | n, out_a & a
                    left = right
                return out_n, out_a
            return unknown

        n, a = cond(ast.parse(f.expr, mode="eval"))
        never |= n
        always &= a
    if slice is not None:
        ch = cell_chunks(grid)
        nb = tuple(len(axis) for axis in ch)
        for axis, s in enumerate(slice):
            box = np.zeros(grid.dims[axis], bool)
            box[s] = True
            ends = np.cumsum(ch[axis])
            some = np.array([box[e - w:e].any() for e, w in zip(ends, ch[axis], strict=True)])
            every = np.array([box[e - w:e].all() for e, w in zip(ends, ch[axis], strict=True)])
            shape = [1, 1, 1]
            shape[axis] = -1
            never |= np.broadcast_to(~some.reshape(shape), nb).reshape(-1)
            always &= np.broadcast_to(every.reshape(shape), nb).reshape(-1)
    return np.where(never, 0, np.where(always, 1, 2)).astype(np.uint8)


# --------------------------------------------------------------------------------------------
# the faces of a shown mask, from the index
# --------------------------------------------------------------------------------------------
def _across(mask: np.ndarray, axis: int, side: int, outside: bool) -> np.ndarray:
    """``mask`` of each chunk's face neighbour on ``side`` (+1/-1) of ``axis``; ``outside``
    where there is none (the grid's boundary)."""
    out = np.full(mask.shape, outside, bool)
    src = [slice(None)] * 3
    dst = [slice(None)] * 3
    src[axis], dst[axis] = (slice(1, None), slice(0, -1)) if side == 1 else \
        (slice(0, -1), slice(1, None))
    out[tuple(dst)] = mask[tuple(src)]
    return out


def _neighbour(idx: tuple, axis: int, side: int, nb: tuple) -> tuple | None:
    j = list(idx)
    j[axis] += side
    return tuple(j) if 0 <= j[axis] < nb[axis] else None


def index_faces(grid, status: np.ndarray, read_shown, chunk_faces, nactive: np.ndarray,
                workers: int = 2, progress: Progress | None = None, zcorn_block=None,
                chunk_corners=None) -> tuple[list, int, dict]:
    """The visible faces of the cells a filter/slice shows, chunk by chunk, from the index.

    Parameters
    ----------
    grid : CornerPointGrid
        The store grid (its dims and cell chunks).
    status : (nchunks,) uint8
        :func:`chunk_status`: 0 chunks are not read (nothing shown), 1 chunks whose face
        neighbours are all 1 (or the grid's boundary) take the index's faces as they are,
        the others are computed.
    read_shown : callable(list of chunk index tuples) -> list of bool blocks
        The shown cells (``active & filter & slice``) of those chunks, read together.
    chunk_faces : callable(c) -> (cells, face, fault, neighbour_shown)
        The index's faces of chunk ``c`` (C order number).
    nactive : (nchunks,) int
        Active cells per chunk.
    zcorn_block, chunk_corners : callable, optional
        With both, each part carries its faces' ``(n, 4)`` corner depths too, taken where the
        faces are made: ``zcorn_block(i)`` is chunk ``i``'s ZCORN block (C order, read once,
        for the chunks computed here), ``chunk_corners(c)`` the index's corners of chunk
        ``c``'s stored faces (chunks reused).  No second pass over ZCORN for the drawn faces.

    Returns
    -------
    (parts, shown, counts)
        ``parts``: ``(cells, face, fault, neighbour_shown[, corners])`` per chunk, each in
        drawing-row order where it could be made so (any order: assemble them with
        :func:`~geoshade.compute.grid.faces._face_set_in_drawing_order`);
        ``shown``: the shown cells; ``counts``: chunks ``skipped``, ``from_index``,
        ``computed``.
    """
    made = IndexFaces(grid, status, read_shown, chunk_faces, nactive, workers, progress,
                      zcorn_block, chunk_corners)
    parts, shown = made.parts()
    return parts, shown, made.counts


class IndexFaces:
    """:func:`index_faces` in steps: made with the same arguments, it reads the shown cells
    of every chunk it needs (kept as bits); :meth:`parts` then makes the faces of any chunks,
    and :meth:`layers` groups the chunks into runs of whole k-slabs of the drawing order, so
    a caller can make, assemble and hand on the faces a layer at a time (the faces of a
    layer follow those of the layer above in the drawing order)."""

    def __init__(self, grid, status: np.ndarray, read_shown, chunk_faces, nactive: np.ndarray,
                 workers: int = 2, progress: Progress | None = None, zcorn_block=None,
                 chunk_corners=None):
        self.grid, self.chunk_faces, self.nactive = grid, chunk_faces, nactive
        self.workers = max(1, int(workers))
        self.zcorn_block, self.chunk_corners = zcorn_block, chunk_corners
        ch = cell_chunks(grid)
        self.nb = nb = tuple(len(a) for a in ch)
        self.starts = [np.concatenate([[0], np.cumsum(a)]) for a in ch]
        idxs = list(np.ndindex(*nb))
        self.st = st = np.asarray(status).reshape(nb)
        whole = st == 1
        reuse = whole.copy()
        for axis in range(3):  # reused as is: every existing face neighbour selected wholly
            for side in (-1, 1):
                reuse &= _across(whole, axis, side, outside=True)
        self.reuse = reuse
        self.compute = compute = (st != 0) & ~reuse
        need = compute.copy()   # and their face neighbours' shown cells
        for axis in range(3):
            for side in (-1, 1):
                need |= _across(compute, axis, side, outside=False) & (st != 0)
        self.cb = resolve(progress)
        self.packed: dict[tuple, tuple] = {}
        want = [i for i in idxs if need[i]]
        per = max(1, (64 << 20) // max(1, int(np.prod([max(a) for a in ch]))))
        self.ncomp, self.done = int(compute.sum()), 0
        for b0 in range(0, len(want), per):  # read in batches, kept as bits
            sel = want[b0:b0 + per]
            for i, blk in zip(sel, read_shown(sel), strict=True):
                b = np.asarray(blk, bool)
                self.packed[i] = (np.packbits(b, axis=None), b.shape)
        self.todo = [i for i in idxs if st[i] != 0]
        self.step = drawing_slab(grid.dims)
        self.counts = {"skipped": int((st == 0).sum()), "from_index": int(reuse.sum()),
                       "computed": self.ncomp}

    def layers(self) -> list[list[tuple]]:
        """The chunks to read (status not 0), grouped by layers of chunks whose k-range ends
        on a k-slab boundary of the drawing order (or the grid's last layer), top down; in a
        layer, in (k, j, i) chunk order (the chunks sharing rows of the drawing order one
        after the other, by ascending i)."""
        ks = self.starts[2]
        out: list[list[tuple]] = []
        group: list[int] = []
        for kc in range(self.nb[2]):
            group.append(kc)
            end = int(ks[kc + 1])
            if end % self.step == 0 or end == self.grid.dims[2]:
                out.append(sorted((i for i in self.todo if i[2] in group),
                                  key=lambda i: (i[2], i[1], i[0])))
                group = []
        return out

    def _one(self, i: tuple) -> tuple[tuple, int]:
        """The faces of chunk ``i`` and its shown cells (a task: numpy and the kernel release
        the GIL)."""
        nb, st, starts, packed = self.nb, self.st, self.starts, self.packed
        with_z = self.zcorn_block is not None and self.chunk_corners is not None
        c = int(np.ravel_multi_index(i, nb))
        if self.reuse[i]:
            part = self.chunk_faces(c)
            return ((*part, self.chunk_corners(c)) if with_z else part), int(self.nactive[c])
        if st[i] == 1:  # selected wholly: only the borders change
            part = _border_faces(i, nb, st, starts, packed, self.chunk_faces(c))
            if with_z:
                part, kept = part
                cz = self.chunk_corners(c)[kept]
                new = part[1].size - cz.shape[0]
                z = self.zcorn_block(i) if new else None
                added = (corners_in_block(z, part[0][-new:] - _origin(i, starts), part[1][-new:])
                         if new else np.zeros((0, 4), np.float32))
                part = (*part, np.concatenate([cz, added]))
            else:
                part = part[0]
            return part, int(self.nactive[c])
        z = self.zcorn_block(i) if with_z else None
        return (_chunk_faces(i, nb, starts, packed, self.chunk_faces(c), z, self.step),
                int(np.count_nonzero(_bits(packed[i]))))

    def parts(self, todo: list[tuple] | None = None) -> tuple[list, int]:
        """``(parts, shown)``: the faces of chunks ``todo`` (default: every chunk to read),
        one part each (see :func:`index_faces`), and their shown cells."""
        parts: list = []
        shown = 0
        todo = self.todo if todo is None else todo
        with ThreadPoolExecutor(self.workers) as pool:
            for i, (part, n) in zip(todo, pool.map(self._one, todo), strict=True):
                parts.append(part)
                shown += n
                if self.compute[i]:
                    self.done += 1
                    self.cb(self.done, self.ncomp)
        return parts, shown


def _bits(p: tuple) -> np.ndarray:
    bits, shape = p
    return np.unpackbits(bits, count=int(np.prod(shape))).astype(bool).reshape(shape)


def _border_faces(idx, nb, st, starts, packed, own_faces) -> tuple:
    """The visible faces of a chunk whose active cells are all shown: the index's, but for
    the faces of its border layers towards face neighbours not wholly selected, which are
    decided anew from the neighbour's facing layer (2-D work, no 3-D pass)."""
    fc, ff, fb, fn = (np.asarray(a) for a in own_faces)
    keep = np.ones(len(ff), bool)
    s = _bits(packed[idx])
    origin = np.array([starts[ax][idx[ax]] for ax in range(3)], np.int64)
    add = []
    for axis in range(3):
        for side in (-1, 1):
            j = _neighbour(idx, axis, side, nb)
            if j is None or st[j] == 1:
                continue
            f = axis if side == 1 else axis + 3
            n_own = s.shape[axis]
            border = 0 if side == -1 else n_own - 1
            on = (ff == f) & (fc[:, axis] - origin[axis] == border)
            keep &= ~on
            layer = [slice(None)] * 3
            layer[axis] = slice(border, border + 1)
            sl = s[tuple(layer)]
            if j in packed:
                other = [slice(None)] * 3
                other[axis] = slice(-1, None) if side == -1 else slice(0, 1)
                nl = _bits(packed[j])[tuple(other)]
            else:
                nl = np.zeros_like(sl)
            bad = np.zeros_like(sl)
            m = on & fb
            loc = fc[m].astype(np.int64) - origin
            loc[:, axis] = 0
            bad[loc[:, 0], loc[:, 1], loc[:, 2]] = True
            vis = sl & (~nl | bad)
            flat = np.flatnonzero(vis)
            ii, jj, kk = np.unravel_index(flat, vis.shape)
            cells = np.stack([ii, jj, kk], 1) + origin
            cells[:, axis] += border
            add.append((cells.astype(np.int32), np.full(flat.size, f, np.uint8),
                        bad.reshape(-1)[flat], nl.reshape(-1)[flat]))
    parts = [(fc[keep], ff[keep], fb[keep], fn[keep]), *add]
    # the chunk's stored faces kept come first: ``keep`` selects their corners
    return tuple(np.concatenate([p[k] for p in parts]) for k in range(4)), keep


def _origin(idx: tuple, starts) -> np.ndarray:
    return np.array([starts[ax][idx[ax]] for ax in range(3)], np.int64)


def _chunk_faces(idx, nb, starts, packed, own_faces, z=None, step: int = 1) -> tuple:
    """The visible faces of one chunk's shown cells: its shown block with the face
    neighbours' facing layers as halo, the mismatches from the index's fault flags; in
    drawing-row order (k-slab, face code, k, j, i), one compiled pass
    (:func:`~geoshade.compute.grid.kernels_numba.shown_chunk_faces`) that also takes each
    face's corner depths from the chunk's ZCORN block ``z`` when given (a fifth column)."""
    from geoshade.compute.grid import kernels_numba as kn

    s = _bits(packed[idx])
    a, b, c = s.shape
    pad = np.zeros((a + 2, b + 2, c + 2), np.uint8)     # shown, with the halo
    ex = np.zeros((a + 2, b + 2, c + 2), np.uint8)      # the cell exists (in the grid)
    pad[1:-1, 1:-1, 1:-1] = s
    ex[1:-1, 1:-1, 1:-1] = 1
    for axis in range(3):
        for side in (-1, 1):
            j = _neighbour(idx, axis, side, nb)
            if j is None:
                continue
            dst = [slice(1, -1)] * 3
            dst[axis] = slice(0, 1) if side == -1 else slice(-1, None)
            ex[tuple(dst)] = 1
            if j in packed:  # a selected neighbour (unselected ones show nothing)
                nbr = _bits(packed[j])
                layer = [slice(None)] * 3
                layer[axis] = slice(-1, None) if side == -1 else slice(0, 1)
                pad[tuple(dst)] = nbr[tuple(layer)]
    origin = _origin(idx, starts)
    bad = np.zeros((a, b, c, 6), np.uint8)
    fc, ff, fb, _ = own_faces
    if len(ff):
        loc = np.asarray(fc, np.int64) - origin
        m = np.asarray(fb, bool)
        bad[loc[m, 0], loc[m, 1], loc[m, 2], np.asarray(ff)[m]] = 1
    zb = (np.zeros((0, 0, 0), np.float32) if z is None
          else np.ascontiguousarray(z, np.float32))
    cells, face, fault, nbs, corners = kn.shown_chunk_faces(
        pad, ex, bad, zb, FACE_ABC, _OFFSETS, int(origin[0]), int(origin[1]), int(origin[2]),
        int(step))
    return (cells, face, fault, nbs) if z is None else (cells, face, fault, nbs, corners)
