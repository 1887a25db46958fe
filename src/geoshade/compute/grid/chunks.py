"""Visible faces and face-cell gathers of out-of-core corner-point grids, chunk by chunk (dask).

:func:`visible_faces_chunked` runs the in-memory rule (:func:`~geoshade.compute.grid.faces.
visible_faces`) on each chunk of cells plus a one-cell halo of ZCORN and of the shown mask, and
keeps the faces of the chunk's own cells: a face at the chunk's border is tested against the
halo cell across it (shown? matching corners?), and the grid boundary is a boundary only where
the halo is absent, i.e. at the real boundary.  The halo is made of the six face neighbours'
*skins* (their first or last cell layer, one small task per chunk), so each chunk is decoded
once and only skins travel between workers; the halo's edges and corners stay unshown, as no
face of an own cell touches them.  The faces are therefore the in-memory ones,
bit for bit (compare after :meth:`FaceSet.sorted`), whatever the chunks cut: faults, inactive
blocks, filters.  Tasks run where the :class:`~geoshade.scheduler.Scheduler` says: dask threads
(the default, ``here``), another local dask scheduler, or a ``dask.distributed`` cluster
(``"local:2"``, an address, a client, a View's session).

:func:`face_corner_depths` and :func:`gather_cells` read only the chunks that hold the given
cells, one chunk at a time (sort the cells by chunk, read a chunk, take, scatter back): a
property or report-step switch reads the face cells' chunks of that one array.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

import numpy as np

from geoshade.compute.grid.faces import (
    FaceSet,
    _face_set_in_drawing_order,
    _fault_lookup,
    visible_faces,
)
from geoshade.compute.grid.filters import Filter
from geoshade.errors import InputError
from geoshade.models import CornerPointGrid
from geoshade.progress import Progress
from geoshade.scheduler import dask_get, is_client, using_scheduler

__all__ = ["FACE_CORNERS", "CellGroups", "block_reader", "chunk_source", "face_corner_depths",
           "gather_cells", "gather_points", "run_tasks", "shown_block_reader", "shown_mask_lazy",
           "visible_faces_chunked"]

#: bytes of chunks a gather reads in one dask call (:meth:`CellGroups.gather`)
GATHER_BATCH_BYTES = 64 << 20
#: cells a :class:`CellGroups` numbers at a time while it is made
GROUP_BATCH = 1 << 22
#: cells per chunk when the grid's arrays are numpy (no chunks of their own)
DEFAULT_CHUNKS = (64, 64, 16)
#: corners (A, B, C, D) of each face 0..5 = I+ J+ K+ I- J- K- (corner c = a + 2b + 4c'); the
#: table of ``render/visuals/grid/layout.py`` (compute cannot import render: a test asserts
#: that both are equal)
FACE_CORNERS = {0: (7, 5, 1, 3), 1: (7, 3, 2, 6), 2: (7, 6, 4, 5),
                3: (0, 4, 6, 2), 4: (0, 1, 5, 4), 5: (0, 2, 3, 1)}
_CORNER_ABC = np.array([(c & 1, c >> 1 & 1, c >> 2 & 1) for c in range(8)], np.int64)
#: (6, 4, 3): the (a, b, c') offsets of corners A..D of each face
FACE_ABC = _CORNER_ABC[np.array([FACE_CORNERS[f] for f in range(6)])]


def _dask():
    import dask.array as da

    return da


def _is_dask(a) -> bool:
    return hasattr(a, "dask") and hasattr(a, "chunks") and hasattr(a, "blocks")


def _cell_chunks(grid: CornerPointGrid, chunks=None) -> tuple:
    """Cell chunks (dask's per-axis tuples) for the grid's arrays."""
    nx, ny, nz = grid.dims
    if chunks is None and _is_dask(grid.zcorn):
        zc = grid.zcorn.chunks
        if all(c % 2 == 0 for axis in zc for c in axis):
            return tuple(tuple(c // 2 for c in axis) for axis in zc)
    if chunks is None:
        chunks = grid.meta.get("chunks") if isinstance(grid.meta, dict) else None
    ch = tuple(int(c) for c in (chunks or DEFAULT_CHUNKS))
    if len(ch) != 3 or min(ch) < 1:
        raise InputError(f"chunks: expected three positive integers (ci, cj, ck), got {chunks!r}")
    return tuple(_split(n, c) for n, c in zip((nx, ny, nz), ch, strict=True))


def _split(n: int, c: int) -> tuple:
    return tuple(min(c, n - a) for a in range(0, n, c))


def _lazy(arr, chunks):
    """``arr`` as a dask array with these chunks (rechunked only when they differ)."""
    da = _dask()
    a = arr if _is_dask(arr) else da.from_array(arr, chunks=chunks)
    return a if a.chunks == chunks else a.rechunk(chunks)


def shown_mask_lazy(grid: CornerPointGrid, filter=None, slice=None, step=None, chunks=None):
    """``active & filter & slice`` as a lazy (nx, ny, nz) bool dask array, block by block.

    Parameters
    ----------
    grid : CornerPointGrid
        Numpy or dask arrays (e.g. from :func:`geoshade.io.stores.grid_store.open_grid_store`).
    filter : str or Filter, optional
        A cell filter (:class:`~geoshade.compute.grid.filters.Filter` grammar); evaluated on each
        block of the properties it names (it is element-wise).
    slice : (slice, slice, slice), optional
        An IJK box (``geoshade.grid.geometry.parse_slice`` makes one from ``"i=1:3,k=4"``).
    step : int, optional
        A report step whose keywords the filter may name too.

    Examples
    --------
    >>> from geoshade.compute.grid.synthetic import synthetic_grid
    >>> g = synthetic_grid(6, 5, 4)
    >>> m = shown_mask_lazy(g, "PORO > 0.2", (slice(1, 5), slice(None), slice(None)))
    >>> bool((m.compute() == (g.active & (g.properties["PORO"] > 0.2))
    ...       & (np.arange(6) >= 1)[:, None, None] & (np.arange(6) < 5)[:, None, None]).all())
    True
    """
    da = _dask()
    ch = _cell_chunks(grid, chunks)
    shown = _lazy(grid.actnum, ch) != 0
    f = Filter.parse(filter)
    if f is not None:
        avail = dict(grid.properties)
        if step is not None and grid.steps:
            avail.update({k: v for k, v in grid.steps[int(step)].items() if k not in avail})
        used = f.resolve(list(avail))
        names = tuple(used)
        arrays = [_lazy(avail[used[n]], ch) for n in names]
        mask = da.map_blocks(_filter_block, *arrays, expr=f.expr, names=names, dtype=bool,
                             meta=np.empty((0, 0, 0), bool))
        shown = shown & mask
    if slice is not None:
        box = [np.zeros(n, bool) for n in grid.dims]
        for b, s in zip(box, slice, strict=True):
            b[s] = True
        m = (da.from_array(box[0], chunks=(ch[0],))[:, None, None]
             & da.from_array(box[1], chunks=(ch[1],))[None, :, None]
             & da.from_array(box[2], chunks=(ch[2],))[None, None, :])
        shown = shown & m
    return shown


def chunk_source(array):
    """The object a dask ``array`` was made from by ``dask.array.from_array`` when that object
    reads its own chunks (``chunk(coords)``: a grid store's checked chunk reader) and the
    array's blocks are its chunks, as made (not sliced, rechunked or computed on); else None.
    """
    if not _is_dask(array) or len(array.dask.layers) != 2:
        return None
    try:
        src = array.dask["original-" + array.name]
    except KeyError:
        return None
    if (callable(getattr(src, "chunk", None))
            and tuple(getattr(src, "shape", ())) == tuple(array.shape)
            and len(getattr(src, "chunks", ())) == array.ndim
            and all(tuple(axis[:-1]) == (int(c),) * (len(axis) - 1)
                    for axis, c in zip(array.chunks, src.chunks, strict=True))):
        return src
    return None


def block_reader(array):
    """``read(i) -> ndarray``: block ``i`` (chunk grid coordinates) of a dask ``array``:
    straight from its :func:`chunk_source` where it has one (a grid store's chunk of 8 MB in
    ~5 ms instead of ~13 ms through a dask graph), else through dask, synchronously (the
    caller runs blocks on its own threads).

    Examples
    --------
    >>> import dask.array as da
    >>> block_reader(da.arange(6, chunks=4))((1,)).tolist()
    [4, 5]
    """
    src = chunk_source(array)
    if src is not None:
        return lambda i: np.asarray(src.chunk(tuple(int(v) for v in i)))
    sync = dask_get("synchronous")
    return lambda i: np.asarray(array.blocks[tuple(int(v) for v in i)].compute(scheduler=sync))


def _box(ch: tuple, i: tuple) -> tuple:
    """The cells of chunk ``i`` of the per-axis chunk sizes ``ch``, as slices."""
    return tuple(slice(sum(axis[:n]), sum(axis[:n + 1])) for axis, n in zip(ch, i, strict=True))


def shown_block_reader(grid: CornerPointGrid, filter=None, slice=None, step=None, chunks=None):
    """``read(i) -> (a, b, c) bool``: block ``i`` of :func:`shown_mask_lazy`'s mask, read and
    evaluated here with no dask graph (:func:`block_reader` for the arrays chunked as the
    cells are, a slice of the others), for a caller that runs blocks on its own threads.

    Examples
    --------
    >>> from geoshade.compute.grid.synthetic import synthetic_grid
    >>> g = synthetic_grid(6, 5, 4)
    >>> read = shown_block_reader(g, "PORO > 0.2", (slice(1, 5), slice(None), slice(None)),
    ...                           chunks=(3, 5, 4))
    >>> lazy = shown_mask_lazy(g, "PORO > 0.2", (slice(1, 5), slice(None), slice(None)),
    ...                        chunks=(3, 5, 4))
    >>> bool((read((1, 0, 0)) == lazy.blocks[1, 0, 0].compute()).all())
    True
    """
    ch = _cell_chunks(grid, chunks)

    def reader(arr):
        if _is_dask(arr) and tuple(arr.chunks) == ch:
            return block_reader(arr)
        return lambda i: np.asarray(arr[_box(ch, i)])

    act = reader(grid.actnum)
    f = Filter.parse(filter)
    props: list = []
    if f is not None:
        avail = dict(grid.properties)
        if step is not None and grid.steps:
            avail.update({k: v for k, v in grid.steps[int(step)].items() if k not in avail})
        used = f.resolve(list(avail))
        props = [(n, reader(avail[used[n]])) for n in used]
    box = None
    if slice is not None:
        box = [np.zeros(n, bool) for n in grid.dims]
        for b, sl in zip(box, slice, strict=True):
            b[sl] = True

    def read(i: tuple) -> np.ndarray:
        shown = act(i) != 0
        if f is not None:
            shown &= np.asarray(Filter(f.expr).mask({n: r(i) for n, r in props}, shown.shape),
                                bool)
        if box is not None:
            sl = _box(ch, i)
            shown &= (box[0][sl[0]][:, None, None] & box[1][sl[1]][None, :, None]
                      & box[2][sl[2]][None, None, :])
        return shown

    return read


def _filter_block(*blocks, expr: str, names: tuple):
    return Filter(expr).mask(dict(zip(names, blocks, strict=True)), blocks[0].shape)


def _faces_block(zc: np.ndarray, sh: np.ndarray, lo: tuple, own: tuple, origin: tuple,
                 tol: float) -> tuple:
    """The faces of the own cells of one chunk with its halo (task on a worker).

    ``lo``: own cells start at this local index (1 where there is a halo below, else 0);
    ``own``: number of own cells per axis; ``origin``: global index of local cell 0.
    """
    ni, nj, _ = sh.shape
    coord = np.zeros((ni + 1, nj + 1, 6))
    coord[..., 5] = 1.0
    sub = CornerPointGrid(coord, np.asarray(zc, np.float32), name="chunk")
    fs = visible_faces(sub, np.asarray(sh, bool), tol)
    c = fs.cells
    keep = np.ones(len(fs), bool)
    for a in range(3):
        keep &= (c[:, a] >= lo[a]) & (c[:, a] < lo[a] + own[a])
    cells = c[keep] + np.asarray(origin, np.int32)
    return cells, fs.face[keep], fs.fault[keep], fs.neighbour_shown[keep]


def _skins(zb: np.ndarray, sb: np.ndarray) -> dict:
    """The first and last cell layer of a chunk along each axis (ZCORN's two corner planes and
    the shown cells): what its face neighbours need as their halo (task)."""
    zb, sb = np.asarray(zb), np.asarray(sb)
    out = {}
    for a in range(3):
        n = sb.shape[a]
        out[a, 0] = (np.take(zb, [0, 1], axis=a), np.take(sb, [0], axis=a))
        out[a, 1] = (np.take(zb, [2 * n - 2, 2 * n - 1], axis=a), np.take(sb, [n - 1], axis=a))
    return out


def _faces_skinned(zb, sb, lo: tuple, hi: tuple, origin: tuple, tol: float, kspan, *skins
                   ) -> tuple:
    """:func:`_faces_block` on a chunk whose halo is its face neighbours' skins (task).

    ``skins``: for each axis with a low neighbour, then each with a high one (in axis order),
    that neighbour's :func:`_skins`.  The halo's edges and corners (diagonal neighbours) are
    left unshown: no face of an own cell touches them.  ``kspan``: None, or ``(k0, k1)``: keep
    (and count) only the own cells of layers ``k0 <= k < k1``.
    """
    zb, sb = np.asarray(zb, np.float32), np.asarray(sb, bool)
    own = sb.shape
    shape = tuple(own[a] + lo[a] + hi[a] for a in range(3))
    zc = np.zeros(tuple(2 * n for n in shape), np.float32)
    sh = np.zeros(shape, bool)
    zc[tuple(slice(2 * lo[a], 2 * (lo[a] + own[a])) for a in range(3))] = zb
    sh[tuple(slice(lo[a], lo[a] + own[a]) for a in range(3))] = sb
    it = iter(skins)
    for side in (0, 1):
        for a in range(3):
            if not (lo[a] if side == 0 else hi[a]):
                continue
            zs, ss = next(it)[a, 1 - side]  # a low neighbour gives its last layer
            pos = 0 if side == 0 else shape[a] - 1
            cz = [slice(2 * lo[b], 2 * (lo[b] + own[b])) for b in range(3)]
            cs = [slice(lo[b], lo[b] + own[b]) for b in range(3)]
            cz[a], cs[a] = slice(2 * pos, 2 * pos + 2), slice(pos, pos + 1)
            zc[tuple(cz)] = zs
            sh[tuple(cs)] = ss
    # the own cells shown are counted here, where the chunk is decoded anyway
    out = _faces_block(zc, sh, lo, own, origin, tol)
    if kspan is None:
        return (*out, int(np.count_nonzero(sb)))
    k0 = origin[2] + lo[2]  # global layer of the chunk's first own cell
    a, b = max(0, kspan[0] - k0), max(0, min(own[2], kspan[1] - k0))
    keep = (out[0][:, 2] >= kspan[0]) & (out[0][:, 2] < kspan[1])
    return (*(x[keep] for x in out), int(np.count_nonzero(sb[:, :, a:b])))


def _independent(a):
    """A copy of the dask array ``a``'s graph under new keys (computed apart from ``a``) where
    it is ``da.from_array``'s (a store's array read as it is), else ``a`` itself (dask's
    ``clone`` loses keys of rechunks and broadcast slices)."""
    from dask.graph_manipulation import clone

    layers = set(getattr(a.__dask_graph__(), "layers", {}))
    if not layers or not layers <= {a.name, f"original-{a.name}"}:  # not da.from_array's
        return a
    return clone(a, assume_layers=False)


def _tasks(grid: CornerPointGrid, shown, fault_tol: float, chunks, kspan=None):
    """Two delayed tasks per chunk of cells: its skins (:func:`_skins`), then its faces with the
    six face neighbours' skins as halo (:func:`_faces_skinned`).  Each chunk is read (decoded)
    once; only the thin skins travel between tasks or workers.  ``kspan`` ``(k0, k1)``: only
    the chunks holding layers ``k0 <= k < k1`` (and their neighbours' skins)."""
    import dask

    ch = _cell_chunks(grid, chunks)
    zch = tuple(tuple(2 * c for c in axis) for axis in ch)
    if shown is None:
        sh = _lazy(grid.actnum, ch) != 0
    else:
        if tuple(shown.shape) != tuple(grid.dims):
            raise InputError(f"visible_faces: shown must have the grid shape {grid.dims}, got "
                             f"{tuple(shown.shape)}")
        sh = _lazy(shown, ch).astype(bool)
    zl = _lazy(grid.zcorn, zch)
    zb, sb = zl.to_delayed(), sh.to_delayed()
    # the skins read their ZCORN chunks on their own (a clone of the graph: each chunk decoded
    # twice) so that no decoded ZCORN chunk waits in memory for its faces task: only skins and
    # the shown masks' (8x smaller) chunks do (a plane of 8 MiB ZCORN chunks of a 1e9-cell
    # store was ~2 GiB)
    zs, ss = _independent(zl).to_delayed(), sb
    nb = tuple(len(axis) for axis in ch)
    skin = dask.delayed(_skins, pure=True)
    skins = {idx: skin(zs[idx], ss[idx]) for idx in np.ndindex(*nb)}
    starts = [np.concatenate([[0], np.cumsum(axis)]) for axis in ch]
    fn = dask.delayed(_faces_skinned, pure=True)
    out = []
    span = None if kspan is None else (int(kspan[0]), int(kspan[1]))
    for idx in np.ndindex(*nb):
        if span is not None and not (starts[2][idx[2]] < span[1]
                                     and starts[2][idx[2] + 1] > span[0]):
            continue
        lo = tuple(int(idx[a] > 0) for a in range(3))
        hi = tuple(int(idx[a] < nb[a] - 1) for a in range(3))
        origin = tuple(int(starts[a][idx[a]]) - lo[a] for a in range(3))
        near = []
        for side, flags in ((-1, lo), (1, hi)):
            for a in range(3):
                if flags[a]:
                    j = list(idx)
                    j[a] += side
                    near.append(skins[tuple(j)])
        inside = span is None or (starts[2][idx[2]] >= span[0]
                                  and starts[2][idx[2] + 1] <= span[1])
        out.append(fn(zb[idx], sb[idx], lo, hi, origin, float(fault_tol),
                      None if inside else span, *near))
    return out


def visible_faces_chunked(grid: CornerPointGrid, shown=None, fault_tol: float = 0.0,
                          scheduler=None, progress: Progress | None = None,
                          chunks=None, kspan=None) -> FaceSet:
    """The visible faces of ``grid`` computed chunk by chunk (see the module text).

    Parameters
    ----------
    grid : CornerPointGrid
        Its ZCORN and ACTNUM may be dask arrays (a grid store) or numpy.
    shown : (nx, ny, nz) bool array (numpy or dask), optional
        Cells to draw (``active & filter & slice``, e.g. :func:`shown_mask_lazy`); default the
        active cells.
    fault_tol : float
        Corner depths closer than this count as matching.
    scheduler : Scheduler, SchedulerSession or what Scheduler.parse takes, optional
        Where the chunk tasks run (None, ``here``: dask threads).
    progress : callable(done, total), optional
        Called as chunks finish.
    chunks : (ci, cj, ck), optional
        Cells per task when the grid's arrays are numpy (default the grid's
        ``meta["chunks"]`` or :data:`DEFAULT_CHUNKS`); a dask ZCORN's own chunks are used.
    kspan : (k0, k1), optional
        Only the faces (and shown count) of the cells in layers ``k0 <= k < k1``; only the
        chunks holding them are read, plus their neighbours' skins (a part of a grid drawn
        on one worker of a cluster, :mod:`geoshade.grid.distributed`).

    Returns
    -------
    FaceSet
        In :func:`visible_faces`'s drawing order (k-slab, face code, k, j, i): equal to
        :func:`visible_faces`, whatever the chunks (of a ``kspan``: those faces, in that order).

    Examples
    --------
    >>> from geoshade.compute.grid.synthetic import synthetic_grid
    >>> g = synthetic_grid(9, 6, 4)
    >>> a = visible_faces_chunked(g, chunks=(3, 4, 2)).sorted()
    >>> b = visible_faces(g).sorted()
    >>> all(np.array_equal(getattr(a, k), getattr(b, k))
    ...     for k in ("cells", "face", "fault", "fault_id", "neighbour_shown"))
    True
    """
    tasks = _tasks(grid, shown, fault_tol, chunks, kspan)
    results = run_tasks(tasks, scheduler, progress)
    return _assemble(grid, results)


def run_tasks(tasks: list, scheduler, progress: Progress | None = None) -> list:
    """Compute the delayed tasks (or dask arrays) on ``scheduler`` (a
    :class:`~geoshade.scheduler.Scheduler` or what it parses, None: dask threads; or a View's
    :class:`~geoshade.scheduler.SchedulerSession`), in order, reporting each finished one."""
    import dask

    total = len(tasks)
    with using_scheduler(scheduler) as sched:
        if is_client(sched):
            from distributed import as_completed

            futures = sched.compute(tasks)
            pos = {f.key: n for n, f in enumerate(futures)}
            results: list = [None] * total
            for done, fut in enumerate(as_completed(futures, loop=sched.loop), 1):
                results[pos[fut.key]] = fut.result()
                fut.release()
                if progress is not None:
                    progress(done, total)
            return results
        if progress is None:
            return list(dask.compute(*tasks, scheduler=dask_get(sched)))
        from dask.callbacks import Callback

        keys = {t.key for t in tasks}
        count = [0]

        def posttask(key, result, dsk, state, worker_id):
            if key in keys:
                count[0] += 1
                progress(count[0], total)

        with Callback(posttask=posttask):
            return list(dask.compute(*tasks, scheduler=dask_get(sched)))


def _assemble(grid: CornerPointGrid, results: list) -> FaceSet:
    """One FaceSet from the chunks' ``(cells, face, fault, neighbour_shown, shown)`` results,
    in :func:`visible_faces`'s drawing order
    (:func:`geoshade.compute.grid.faces._face_set_in_drawing_order`: placed part by part, the
    fault lookup of the in-memory path), with the shown cells counted."""
    shown = sum(int(r[4]) for r in results)
    parts = [tuple(r[:4]) for r in results]
    results.clear()  # each part is dropped once placed in the face set
    fs = _face_set_in_drawing_order(grid, parts, *_fault_lookup(grid))
    fs.shown = shown
    return fs


# --------------------------------------------------------------------------------------------
# gathers: values of given cells, chunk by chunk
# --------------------------------------------------------------------------------------------
def _by_chunk(array, idx: np.ndarray, take, out: np.ndarray, workers: int) -> np.ndarray:
    """For each chunk of the dask ``array`` holding some of the points ``idx`` ((n, ndim)
    indices): read it once and ``out[sel] = take(block, local indices, sel)``; ``workers``
    chunks at a time."""

    bounds = [np.cumsum(axis) for axis in array.chunks]
    flat = np.zeros(len(idx), np.int64)
    for a, b in enumerate(bounds):
        flat = flat * array.numblocks[a] + np.searchsorted(b, idx[:, a], side="right")
    order = np.argsort(flat, kind="stable")
    uniq, first = np.unique(flat[order], return_index=True)
    del flat
    ends = np.append(first[1:], len(order))
    starts0 = [np.concatenate([[0], b[:-1]]) for b in bounds]
    read = block_reader(array)   # the store's reader where it has one, else dask, here

    def one(n: int):
        coords = np.unravel_index(int(uniq[n]), array.numblocks)
        block = read(coords)
        sel = order[first[n]:ends[n]]
        local = idx[sel] - np.array([s[c] for s, c in zip(starts0, coords, strict=True)])
        return sel, take(block, local, sel)

    with ThreadPoolExecutor(max(1, int(workers))) as pool:
        for sel, vals in pool.map(one, range(len(uniq))):
            out[sel] = vals
    return out


def gather_points(array, idx: np.ndarray, workers: int = 2) -> np.ndarray:
    """``array[idx[:, 0], idx[:, 1], ...]`` reading only the chunks that hold the points.

    A numpy array is indexed directly; a dask array is read chunk by chunk (points sorted by
    chunk, each chunk read once, ``workers`` chunks at a time), so memory is a few chunks plus
    the output and the sort.

    Examples
    --------
    >>> import dask.array as da
    >>> a = np.arange(60.0).reshape(3, 4, 5)
    >>> idx = np.array([[2, 3, 4], [0, 0, 0], [1, 2, 3]])
    >>> gather_points(da.from_array(a, chunks=(2, 2, 2)), idx).tolist()
    [59.0, 0.0, 33.0]
    """
    idx = np.asarray(idx).reshape(-1, array.ndim)
    if not _is_dask(array):
        return np.asarray(array)[tuple(idx.T)]
    out = np.empty(len(idx), array.dtype)
    if not len(idx):
        return out
    return _by_chunk(array, idx, lambda block, local, sel: block[tuple(local.T)], out, workers)


def gather_cells(array, cells: np.ndarray | None, workers: int = 2,
                 groups: CellGroups | None = None) -> np.ndarray:
    """``(n,)`` values of an (nx, ny, nz) cell array (property, report step) at ``cells``
    ((n, 3) i, j, k), reading only the chunks that hold them (:func:`gather_points`), or, with
    ``groups`` (a :class:`CellGroups` of these cells for the array's chunks), without sorting
    them again (``cells`` is then not used).

    Examples
    --------
    >>> import dask.array as da
    >>> a = np.arange(24).reshape(2, 3, 4)
    >>> gather_cells(da.from_array(a, chunks=(1, 2, 2)), np.array([[1, 2, 3], [0, 1, 0]])).tolist()
    [23, 4]
    """
    if groups is not None and _is_dask(array):
        return groups.gather(array, workers)
    if cells is None:
        raise ValueError("gather_cells: cells are needed without groups of a dask array")
    return gather_points(array, cells, workers)


class CellGroups:
    """Cells of a gather grouped by the chunk that holds them, once, for every array with the
    same chunks (a property or report-step switch reads and scatters only, no sort).

    Parameters
    ----------
    numbers : (n,) int
        Cell numbers ``i + nx (j + ny k)`` (F order), e.g. the cells with a visible face.
    dims : (nx, ny, nz)
    chunks : dask chunks of the cell arrays (per-axis tuples)

    Memory: 8 bytes per cell (``order`` and the in-chunk offsets ``local``, int32 each below
    2^31 cells, else int64 order) plus a few bytes per chunk; building it takes a few int64
    temporaries of n.

    Examples
    --------
    >>> import dask.array as da
    >>> a = da.from_array(np.arange(24.0).reshape(2, 3, 4, order="F"), chunks=(1, 2, 2))
    >>> g = CellGroups(np.array([23, 4, 0]), (2, 3, 4), a.chunks)
    >>> g.gather(a).tolist() == np.asarray(a).ravel(order="F")[[23, 4, 0]].tolist()
    True
    """

    def __init__(self, numbers: np.ndarray, dims, chunks):
        num = np.asarray(numbers).reshape(-1)
        self.n, self.dims = int(num.size), tuple(int(v) for v in dims)
        self.chunks = tuple(tuple(int(c) for c in axis) for axis in chunks)
        nb = tuple(len(axis) for axis in self.chunks)
        nblocks = int(np.prod(nb))
        # the chunk of each cell (C order of the chunk grid) in the smallest integer: a
        # store's few thousand chunks sort as uint16 (numpy's radix sort: linear time)
        kdt = (np.uint16 if nblocks <= 1 << 16 else np.int32 if nblocks < 1 << 31
               else np.int64)
        flat = np.empty(self.n, kdt)
        local = np.empty(self.n, np.int32)
        # per axis, a coordinate's chunk, its offset in the chunk and the chunk's size: tables
        # of the axis' length; one compiled pass looks every cell up (no search, no temporaries)
        from geoshade.compute.grid import kernels_numba as k

        blk = [np.repeat(np.arange(len(axis), dtype=np.int64), axis) for axis in self.chunks]
        off = [np.concatenate([np.arange(n, dtype=np.int64) for n in axis])
               for axis in self.chunks]
        size = [np.repeat(np.asarray(axis, np.int64), axis) for axis in self.chunks]
        for b0 in range(0, self.n, GROUP_BATCH):  # batches of cells: bounded temporaries
            x = np.asarray(num[b0:b0 + GROUP_BATCH], np.int64)
            k.chunk_keys(x, *self.dims, *blk, *off, size[1], size[2], nb[1], nb[2],
                         flat[b0:b0 + x.size], local[b0:b0 + x.size])
            del x
        order = np.argsort(flat, kind="stable")
        fs = flat[order]
        del flat
        head = np.flatnonzero(fs[1:] != fs[:-1]) + 1 if self.n else np.zeros(0, np.int64)
        self.bounds = np.concatenate([[0], head, [self.n]]).astype(np.int64)
        self.blocks = (np.stack(np.unravel_index(fs[self.bounds[:-1]].astype(np.int64), nb), 1)
                       if self.n else np.zeros((0, 3), np.int64))
        del fs, head
        self.local = local[order]   # C-order offset inside the chunk, int32
        del local
        self.order = order.astype(np.int32) if self.n < 2**31 else order
        del order

    @property
    def nbytes(self) -> int:
        """Bytes held (the per-cell arrays and the per-chunk table)."""
        return int(self.order.nbytes + self.local.nbytes + self.bounds.nbytes
                   + self.blocks.nbytes)

    def fits(self, numbers: np.ndarray, dims, chunks) -> bool:
        """Whether these groups were made for ``numbers`` (same size) on these chunks."""
        return (np.asarray(numbers).size == self.n and tuple(dims) == self.dims
                and tuple(tuple(axis) for axis in chunks) == self.chunks)

    def gather(self, array, workers: int = 2) -> np.ndarray:
        """``(n,)`` values of the dask cell ``array`` (these chunks) at the cells, in their
        order: each chunk holding some is read once, in batches of at most
        :data:`GATHER_BATCH_BYTES` of chunks computed together on ``workers`` threads (one
        dask call per batch, not per chunk: half the time per chunk)."""
        if tuple(tuple(axis) for axis in array.chunks) != self.chunks:
            raise ValueError("CellGroups.gather: the array's chunks are not the groups'")
        out = np.empty(self.n, array.dtype)
        for g, block in self.blocks_of(array, workers):
            a, b = self.bounds[g], self.bounds[g + 1]
            out[self.order[a:b]] = np.ravel(np.asarray(block), order="C")[self.local[a:b]]
        return out

    def blocks_of(self, array, workers: int = 2):
        """Yield ``(g, block)``: the chunk of ``array`` holding group ``g``'s cells, for every
        group, read in batches of at most :data:`GATHER_BATCH_BYTES` (one dask call each, on
        ``workers`` threads).  ``array``'s chunk grid must be the groups' (its chunks may be a
        multiple of them: ZCORN's are twice the cells')."""
        import dask

        nbytes = int(np.prod([max(axis) for axis in array.chunks])) * array.dtype.itemsize
        per = max(1, GATHER_BATCH_BYTES // max(1, nbytes))
        if chunk_source(array) is not None:   # a store's own chunk reader: no dask graph
            read = block_reader(array)
            with ThreadPoolExecutor(max(1, int(workers))) as pool:
                for g0 in range(0, len(self.blocks), per):  # batches: bounded memory
                    gs = range(g0, min(len(self.blocks), g0 + per))
                    yield from zip(gs, pool.map(lambda g: read(self.blocks[g]), gs),
                                   strict=True)
            return
        for g0 in range(0, len(self.blocks), per):  # batches of chunks
            gs = range(g0, min(len(self.blocks), g0 + per))
            blocks = list(dask.compute(*[array.blocks[tuple(int(v) for v in self.blocks[g])]
                                         for g in gs], scheduler=dask_get("threads"),
                                       num_workers=max(1, int(workers))))
            for g in gs:
                yield g, blocks[g - g0]
                blocks[g - g0] = None


def face_corner_depths(zcorn, cells: np.ndarray, face: np.ndarray, workers: int = 2
                       ) -> np.ndarray:
    """``(n, 4)`` float32 depths of corners A, B, C, D of each face (the order of
    ``render/visuals/grid/prepare.py: zcorn_indices``), reading only the ZCORN chunks that
    hold them.

    Examples
    --------
    >>> from geoshade.compute.grid.synthetic import synthetic_grid
    >>> g = synthetic_grid(3, 2, 2)
    >>> face_corner_depths(g.zcorn, np.array([[0, 0, 0]]), np.array([2])).shape
    (1, 4)
    """
    c = np.asarray(cells).reshape(-1, 3)
    f = np.asarray(face).reshape(-1)  # face codes as given (uint8): no int64 copy
    even = _is_dask(zcorn) and all(n % 2 == 0 for axis in zcorn.chunks for n in axis)
    if not even:  # numpy, or chunks that cut cells: corner by corner
        idx = (2 * c[:, None, :].astype(np.int64) + FACE_ABC[f]).reshape(-1, 3)
        return gather_points(zcorn, idx, workers).astype(np.float32, copy=False).reshape(-1, 4)
    # a cell's 8 corners lie in one ZCORN chunk: group the faces by their cell's chunk
    # (CellGroups of the cell numbers: 8 bytes a face, no (n, 3) int64 indices)
    out = np.empty((len(f), 4), np.float32)
    if not len(f):
        return out
    dims = tuple(int(n) // 2 for n in zcorn.shape)
    cch = tuple(tuple(n // 2 for n in axis) for axis in zcorn.chunks)
    num = np.empty(len(f), np.int64)
    for a in range(0, len(f), GROUP_BATCH):  # batches of faces
        cb = c[a:a + GROUP_BATCH].astype(np.int64)
        num[a:a + GROUP_BATCH] = cb[:, 0] + dims[0] * (cb[:, 1] + dims[1] * cb[:, 2])
        del cb
    groups = CellGroups(num, dims, cch)
    del num
    for g, block in groups.blocks_of(zcorn, workers):
        lo, hi = groups.bounds[g], groups.bounds[g + 1]
        sel = groups.order[lo:hi]
        loc = groups.local[lo:hi].astype(np.int64)
        sj, sk = block.shape[1] // 2, block.shape[2] // 2
        ijk = np.stack([loc // (sj * sk), loc // sk % sj, loc % sk], 1)  # in-chunk i, j, k
        out[sel] = corners_in_block(block, ijk, f[sel])
    return out


def corners_in_block(z: np.ndarray, local: np.ndarray, face: np.ndarray) -> np.ndarray:
    """``(n, 4)`` float32 depths of corners A, B, C, D of faces ``face`` of the cells at
    ``local`` (in-chunk i, j, k) from the chunk's ZCORN block ``z`` (``(2a, 2b, 2c)``, any
    order)."""
    loc = np.asarray(local, np.int64).reshape(-1, 3)
    abc = FACE_ABC[np.asarray(face, np.int64)]                   # (n, 4, 3)
    return np.asarray(z[2 * loc[:, None, 0] + abc[..., 0], 2 * loc[:, None, 1] + abc[..., 1],
                        2 * loc[:, None, 2] + abc[..., 2]], np.float32)
