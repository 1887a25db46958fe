"""The fast paths of a filter or slice on a grid store (issue 34, item 2) give what the general
paths give, exactly: a store's chunk decoded here equals zarr's decoding (zstd and lz4, edge
chunks), blocks read straight from the store equal dask's, a shown block evaluated here equals
the lazy mask's, the faces made with their corners in one compiled pass equal the in-memory
faces and ZCORN's corners, and the drawing order by rows equals the whole sort whatever order
the parts come in."""

import numpy as np
import pytest
import zarr

from geoshade.compute.grid.chunks import (
    block_reader,
    chunk_source,
    face_corner_depths,
    shown_block_reader,
    shown_mask_lazy,
)
from geoshade.compute.grid.faces import (
    _face_set_by_groups,
    _face_set_in_drawing_order,
    _fault_lookup,
    visible_faces,
)
from geoshade.compute.grid.filters import cell_filter
from geoshade.compute.grid.index_faces import chunk_status, index_faces, store_index
from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.grid.geometry import parse_slice
from geoshade.io.stores.chunks import DamagedStoreError
from geoshade.io.stores.grid_index import GridIndex, open_index
from geoshade.io.stores.grid_store import ModelSource, open_grid_store, write_grid_store

CHUNKS = (7, 6, 3)   # chunk borders cut the faults and the inactive blobs; edge chunks clipped


@pytest.fixture(scope="module", params=["zstd", "lz4"])
def made(request, tmp_path_factory):
    grid = synthetic_grid(25, 19, 8, inactive_fraction=0.2, steps=2, seed=7)
    store = tmp_path_factory.mktemp("fast") / "s.zarr"
    write_grid_store(ModelSource(grid), store, CHUNKS, index=store_index,
                     compressor=request.param)
    return grid, store


def test_a_chunk_decoded_here_is_zarrs(made):
    _, store = made
    lazy = open_grid_store(store)
    for name, arr in (("zcorn", lazy.zcorn), ("actnum", lazy.actnum),
                      ("props/PORO", lazy.properties["PORO"])):
        src = chunk_source(arr)
        assert src is not None and src._direct(), name
        z = zarr.open_array(str(store / name), mode="r")
        for coords in ((0, 0, 0), tuple(g - 1 for g in src.grid)):   # an edge chunk too
            sl = tuple(slice(c * n, min(s, (c + 1) * n))
                       for c, n, s in zip(coords, src.chunks, src.shape, strict=True))
            got = src.chunk(coords)
            want = np.asarray(z[sl])
            assert got.flags.c_contiguous and got.flags.writeable
            np.testing.assert_array_equal(got, want, err_msg=f"{name} {coords}")


def test_a_truncated_chunk_is_one_line_naming_it(made, tmp_path):
    import shutil

    _, store = made
    copy = tmp_path / "c.zarr"
    shutil.copytree(store, copy)
    chunk = copy / "zcorn" / "c" / "0" / "0" / "0"
    chunk.write_bytes(chunk.read_bytes()[:40])
    src = chunk_source(open_grid_store(copy).zcorn)
    with pytest.raises(DamagedStoreError, match=r"chunk zcorn/c/0/0/0 is damaged"):
        src.chunk((0, 0, 0))


def test_blocks_read_straight_from_the_store_are_dasks(made):
    _, store = made
    lazy = open_grid_store(store)
    read = block_reader(lazy.zcorn)
    for i in ((0, 0, 0), (1, 2, 1), tuple(n - 1 for n in lazy.zcorn.numblocks)):
        np.testing.assert_array_equal(read(i), lazy.zcorn.blocks[i].compute())
    # an array computed on has no chunk source: read through dask
    assert chunk_source(lazy.zcorn + 1) is None
    np.testing.assert_array_equal(block_reader(lazy.zcorn + 1)((0, 0, 0)),
                                  lazy.zcorn.blocks[0, 0, 0].compute() + 1)


@pytest.mark.parametrize("expr, spec", [("PORO > 0.2", None), (None, "i=3:20,k=2:7"),
                                        ("SWAT >= 0.3 and PERMX < 500", "j=4:15")])
def test_a_shown_block_evaluated_here_is_the_lazy_masks(made, expr, spec):
    _, store = made
    lazy = open_grid_store(store)
    box = parse_slice(spec, lazy.dims) if spec else None
    mask = shown_mask_lazy(lazy, expr, box, step=1)
    read = shown_block_reader(lazy, expr, box, step=1)
    for i in np.ndindex(*mask.numblocks):
        np.testing.assert_array_equal(read(i), mask.blocks[i].compute(), err_msg=str(i))


@pytest.mark.parametrize("expr, spec", [("PORO > 0.2", None), (None, "i=3:20,j=2:17"),
                                        ("PERMX > 100", "k=1:6")])
def test_faces_with_their_corners_in_one_pass_are_the_in_memory_ones(made, expr, spec):
    grid, store = made
    lazy = open_grid_store(store)
    idx = open_index(lazy)
    assert isinstance(idx, GridIndex), idx
    box = parse_slice(spec, grid.dims) if spec else (slice(None),) * 3
    mask = grid.active.copy()
    if expr:
        mask &= cell_filter(expr, grid.properties, grid.dims)
    inside = np.zeros(grid.dims, bool)
    inside[box] = True
    mask &= inside
    status = chunk_status(lazy, idx.nactive, idx.stats, expr, box if spec else None)
    shown_of = shown_block_reader(lazy, expr, box if spec else None)
    cells, face, fault, nbs = idx.faces()
    stored = idx.corners()

    def chunk_faces(c):
        pos = idx.chunk_positions(c)
        return cells[pos], face[pos], fault[pos], nbs[pos]

    parts, shown, _ = index_faces(lazy, status, lambda sel: [shown_of(i) for i in sel],
                                  chunk_faces, idx.nactive, zcorn_block=block_reader(lazy.zcorn),
                                  chunk_corners=lambda c: stored[idx.chunk_positions(c)])
    assert all(len(p) == 5 for p in parts)
    got, corners = _face_set_in_drawing_order(grid, parts, *_fault_lookup(grid),
                                              with_corners=True)
    ref = visible_faces(grid, shown=mask)
    assert shown == int(mask.sum())
    for k in ("cells", "face", "fault", "fault_id", "neighbour_shown"):
        np.testing.assert_array_equal(getattr(got, k), getattr(ref, k), k)
    np.testing.assert_array_equal(corners, face_corner_depths(grid.zcorn, ref.cells, ref.face))


def _chunk_parts(grid, chunks, rng):
    """The in-memory faces cut into chunk parts (each shuffled), with their corners."""
    fs = visible_faces(grid)
    corners = face_corner_depths(grid.zcorn, fs.cells, fs.face)
    key = (fs.cells // np.array(chunks)) @ np.array([10_000, 100, 1])
    parts = []
    for k in np.unique(key):
        sel = np.flatnonzero(key == k)
        sel = sel[rng.permutation(sel.size)]
        parts.append((fs.cells[sel], fs.face[sel], fs.fault[sel], fs.neighbour_shown[sel],
                      corners[sel]))
    return fs, corners, [parts[i] for i in rng.permutation(len(parts))]


def test_the_drawing_order_by_rows_is_the_whole_sort_in_any_part_order():
    grid = synthetic_grid(23, 17, 9, inactive_fraction=0.15, seed=3)
    rng = np.random.default_rng(0)
    fs, corners, parts = _chunk_parts(grid, (5, 4, 2), rng)
    keys = _fault_lookup(grid)
    got, gc = _face_set_in_drawing_order(grid, list(parts), *keys, with_corners=True)
    alt, ac = _face_set_by_groups(grid, list(parts), *keys, with_corners=True)
    for k in ("cells", "face", "fault", "fault_id", "neighbour_shown"):
        np.testing.assert_array_equal(getattr(got, k), getattr(fs, k), k)
        np.testing.assert_array_equal(getattr(alt, k), getattr(fs, k), k)
    np.testing.assert_array_equal(gc, corners)
    np.testing.assert_array_equal(ac, corners)
    # parts that are not boxes (faces dealt out at random): the check sorts the whole set
    every = tuple(np.concatenate([p[c] for p in parts]) for c in range(5))
    deal = rng.integers(0, 4, every[1].size)
    odd = [tuple(col[deal == d] for col in every) for d in range(4)]
    got, gc = _face_set_in_drawing_order(grid, odd, *keys, with_corners=True)
    np.testing.assert_array_equal(got.cells, fs.cells)
    np.testing.assert_array_equal(gc, corners)


def test_staged_layers_list_their_cells_without_sorting_every_face():
    from geoshade.render.visuals.grid.prepare import StagedFaces, cell_list

    grid = synthetic_grid(9, 7, 4, seed=1)
    fs = visible_faces(grid)
    corners = face_corner_depths(grid.zcorn, fs.cells, fs.face)
    layers = [np.flatnonzero(fs.cells[:, 2] == k) for k in range(4)]
    num = fs.cells[:, 0] + 9 * (fs.cells[:, 1] + 7 * fs.cells[:, 2].astype(np.int64))
    top_down = StagedFaces(grid.dims)
    for sel in layers:
        top_down.add(fs.cells[sel], fs.face[sel], None, corners[sel])
    cells, _ = top_down.cell_list()
    order = np.concatenate(layers)
    want_cells, want_slot = cell_list(num[order])
    np.testing.assert_array_equal(cells, want_cells)
    assert len(top_down.blocks) == len(layers)   # a block (one GPU buffer) a layer
    got = np.concatenate([top_down.slots(top_down.face_cells(rec, key), layer)
                          for rec, key, layer in top_down.blocks])
    np.testing.assert_array_equal(got, want_slot)
    np.testing.assert_array_equal(   # the cells come back from the records and keys
        np.concatenate([top_down.face_cells(rec, key) for rec, key, _ in top_down.blocks]),
        num[order])
    bottom_up = StagedFaces(grid.dims)
    for sel in layers[::-1]:   # cells below the previous layer's: the whole sort instead
        bottom_up.add(fs.cells[sel], fs.face[sel], None, corners[sel])
    assert bottom_up.cell_list() is None and bottom_up.n == len(fs)


@pytest.mark.parametrize("quantise", [None, (1000.0, 0.05), (1500.0, 0.0313)])
@pytest.mark.parametrize("z_offset", [0.0, 1234.5])
def test_compiled_face_records_and_colours_are_the_numpy_ones(quantise, z_offset):
    from geoshade.compute.grid import kernels
    from geoshade.render.visuals.grid import prepare

    rng = np.random.default_rng(1)
    n, dims = 200_000, (900, 700, 60)
    cells = np.stack([rng.integers(0, d, n) for d in dims], 1).astype(np.int32)
    face = rng.integers(0, 6, n).astype(np.uint8)
    corners = rng.normal(2000, 300, (n, 4)).astype(np.float32)
    corners[::1000] = 99999.0   # beyond the 16-bit codes: clipped
    parts = [prepare.face_records(cells[a:a + 1000], face[a:a + 1000], dims, None, z_offset,
                                  quantise=quantise, corners=corners[a:a + 1000])
             for a in range(0, n, 1000)]   # below the compiled path's size: numpy
    got, err = prepare.face_records(cells, face, dims, None, z_offset, quantise=quantise,
                                    corners=corners)
    np.testing.assert_array_equal(got, np.concatenate([p[0] for p in parts]))
    assert err == max(p[1] for p in parts)
    np.testing.assert_array_equal(
        kernels.cell_numbers(cells, 900, 700),
        cells[:, 0] + 900 * (cells[:, 1] + 700 * cells[:, 2].astype(np.int64)))
    v = rng.normal(0.5, 0.6, 3_000_000).astype(np.float32)
    v[::97], v[::101], v[::103] = np.nan, np.inf, -np.inf
    for lo, hi in ((0.0, 1.0), (-3.0, 800.0), (5.0, 5.0)):
        t = np.nan_to_num((v.astype(np.float64) - lo) / (hi - lo) if hi > lo
                          else np.zeros(v.size), nan=0.0, posinf=1.0, neginf=0.0)
        want = np.clip(np.rint(t * 255.0), 0, 255).astype(np.uint8)
        np.testing.assert_array_equal(prepare.color_index(v, lo, hi), want)


def test_index_parts_are_the_whole_arrays_rows(made, tmp_path):
    """The index's sample checks read the sampled chunk's rows only (GridIndex.part): the same
    rows as the whole checked arrays, for slices, positions and per-step arrays; an unreadable
    array is a DamagedIndexError naming it, and open_index still samples the faces."""
    import shutil

    from geoshade.compute.grid.index_faces import sample_faces
    from geoshade.io.stores.grid_index import DamagedIndexError

    _, store = made
    idx = open_index(open_grid_store(store), sample_faces)
    assert isinstance(idx, GridIndex)
    pos = np.sort(idx.chunk_positions(idx.nb[0] * idx.nb[1] + 1))
    cells, face, _, _ = idx.faces()
    for name, whole in (("faces/cells", cells), ("faces/face", face),
                        ("faces/corners", idx.corners())):
        np.testing.assert_array_equal(idx.part(name, pos), whole[pos], err_msg=name)
        np.testing.assert_array_equal(idx.part(name, slice(3, 40)), whole[3:40])
        assert idx.part(name, pos[:0]).shape[0] == 0
    np.testing.assert_array_equal(idx.part("values/steps/SWAT", pos[:5] % idx.ncells, 1),
                                  idx.values("steps/SWAT", 1)[pos[:5] % idx.ncells])
    np.testing.assert_array_equal(idx.part("nactive", slice(0, 4)), idx.nactive[:4])  # kept
    broken = tmp_path / "b.zarr"
    shutil.copytree(store, broken)
    for chunk in (broken / "index" / "faces" / "cells" / "c").rglob("*"):
        if chunk.is_file():
            chunk.write_bytes(b"\0" * 7)
    damaged = GridIndex(broken, idx.attrs, open_grid_store(broken))
    with pytest.raises(DamagedIndexError, match="faces/cells"):
        damaged.part("faces/cells", pos)
    assert "not used" in open_index(open_grid_store(broken), sample_faces)


def test_a_store_drawn_out_of_core_maps_big_allocations_apart(made):
    """Opening a store's faces source sets glibc's fixed mmap threshold once (freed layers'
    arrays given back, not kept on the heaps); a grid in memory leaves the process as it is."""
    import ctypes.util

    from geoshade.grid.sources import open_source
    from geoshade.io import paths

    _, store = made
    open_source(open_grid_store(store))
    on_glibc = ctypes.util.find_library("c") is not None and hasattr(ctypes.CDLL(None),
                                                                     "mallopt")
    assert paths._MAPPED_APART is on_glibc
    assert paths.map_big_allocations() is on_glibc   # once: asked again, nothing more
