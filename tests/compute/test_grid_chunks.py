"""Chunked visible faces and gathers (geoshade.compute.grid.chunks) equal the in-memory ones."""

from __future__ import annotations

import dask.array as da
import numpy as np
import pytest

from geoshade.compute.grid.chunks import (
    FACE_CORNERS,
    face_corner_depths,
    gather_cells,
    shown_mask_lazy,
    visible_faces_chunked,
)
from geoshade.compute.grid.faces import brute_force_visible_faces, visible_faces
from geoshade.compute.grid.filters import Filter
from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.errors import InputError

FIELDS = ("cells", "face", "fault", "fault_id", "neighbour_shown")
NX, NY, NZ = 12, 9, 5
#: chunks whose borders cut the faults at i = nx // 3 = 4 and j = 2 ny // 3 = 6
CUTS = [(4, 6, 2), (2, 3, 1), (5, 2, 3), (1, 1, 1), (NX, NY, NZ)]


def assert_equal_faces(a, b):
    a, b = a.sorted(), b.sorted()
    assert len(a) == len(b)
    for k in FIELDS:
        np.testing.assert_array_equal(getattr(a, k), getattr(b, k), err_msg=k)
    assert tuple(a.dims) == tuple(b.dims)


@pytest.fixture(scope="module")
def grid():
    g = synthetic_grid(NX, NY, NZ, seed=3, inactive_fraction=0.2)
    # an inactive block across chunk borders too
    g.actnum[3:6, 5:8, 1:3] = 0
    assert g.faults and not g.active.all()
    return g


@pytest.fixture(scope="module")
def store(grid, tmp_path_factory):
    from geoshade.io.stores.grid_store import ModelSource, open_grid_store, write_grid_store

    path = tmp_path_factory.mktemp("gstore") / "g.zarr"
    write_grid_store(ModelSource(grid), path, chunks=(4, 6, 2))
    return open_grid_store(path)


@pytest.mark.parametrize("chunks", CUTS)
def test_chunked_equals_in_memory(grid, chunks):
    fs = visible_faces_chunked(grid, chunks=chunks)
    assert_equal_faces(fs, visible_faces(grid))
    assert fs.fault.any() and (fs.fault_id >= 0).any()


def test_equals_brute_force_with_tolerance(grid):
    assert_equal_faces(visible_faces_chunked(grid, fault_tol=3.0, chunks=(4, 6, 2)),
                       brute_force_visible_faces(grid, fault_tol=3.0))


@pytest.mark.parametrize("chunks", [(4, 6, 2), (3, 2, 2)])
def test_filter_and_slice_cut_by_chunks(grid, chunks):
    box = (slice(2, 11), slice(1, None), slice(0, 4))
    lazy = shown_mask_lazy(grid, "poro > 0.2 and FIPNUM >= 1", box, chunks=chunks)
    mask = grid.active & Filter("poro > 0.2 and FIPNUM >= 1").mask(grid.properties, grid.dims)
    inbox = np.zeros(grid.dims, bool)
    inbox[box] = True
    mask &= inbox
    np.testing.assert_array_equal(lazy.compute(), mask)
    assert 0 < mask.sum() < mask.size
    assert_equal_faces(visible_faces_chunked(grid, lazy, chunks=chunks), visible_faces(grid, mask))


def test_report_step_filter(grid):
    lazy = shown_mask_lazy(grid, "SWAT > 0.4", step=2, chunks=(5, 5, 2))
    want = grid.active & (grid.steps[2]["SWAT"] > 0.4)
    np.testing.assert_array_equal(lazy.compute(), want)


def test_store_backed_grid(grid, store):
    assert type(store.zcorn).__name__ == "Array"
    fs = visible_faces_chunked(store)
    assert_equal_faces(fs, visible_faces(grid))
    lazy = shown_mask_lazy(store, "PERMX > 50", (slice(None), slice(2, 8), slice(None)))
    assert_equal_faces(visible_faces_chunked(store, lazy),
                       visible_faces(grid, lazy.compute()))


def test_progress_and_schedulers(grid):
    calls = []
    fs = visible_faces_chunked(grid, chunks=(4, 6, 2), progress=lambda d, t: calls.append((d, t)),
                               scheduler="synchronous")
    n = 3 * 2 * 3
    assert calls[-1] == (n, n) and len(calls) == n
    assert_equal_faces(fs, visible_faces(grid))


def test_bad_shown(grid):
    with pytest.raises(InputError, match="shown must have the grid shape"):
        visible_faces_chunked(grid, np.ones((2, 2, 2), bool))
    with pytest.raises(InputError, match="chunks"):
        visible_faces_chunked(grid, chunks=(0, 1, 1))


@pytest.fixture(scope="module")
def cluster():
    distributed = pytest.importorskip("distributed")
    lc = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None, silence_logs=40)
    client = distributed.Client(lc, set_as_default=False)
    yield client
    client.close()
    lc.close()


def test_local_cluster_equals_threads(store, cluster):
    lazy = shown_mask_lazy(store, "PORO > 0.15", (slice(1, None), slice(None), slice(None)))
    threads = visible_faces_chunked(store, lazy)
    calls = []
    dist = visible_faces_chunked(store, lazy, scheduler=cluster,
                                 progress=lambda d, t: calls.append((d, t)))
    assert_equal_faces(dist, threads)
    assert calls and calls[-1][0] == calls[-1][1]


# --- gathers --------------------------------------------------------------------------------
def test_gather_cells_equals_fancy_indexing(grid, store):
    rng = np.random.default_rng(0)
    cells = np.stack([rng.integers(0, n, 200) for n in grid.dims], 1).astype(np.int32)
    for name in ("PORO", "FIPNUM"):
        got = gather_cells(store.properties[name], cells)
        want = grid.properties[name][cells[:, 0], cells[:, 1], cells[:, 2]]
        np.testing.assert_array_equal(got, want)
        assert got.dtype == want.dtype
    got = gather_cells(store.steps[1]["SWAT"], cells)
    np.testing.assert_array_equal(got, grid.steps[1]["SWAT"][tuple(cells.T)])
    odd = da.from_array(grid.properties["PERMX"], chunks=(5, 2, 3))
    np.testing.assert_array_equal(gather_cells(odd, cells),
                                  grid.properties["PERMX"][tuple(cells.T)])
    assert gather_cells(odd, cells[:0]).shape == (0,)


def test_face_corner_depths_match_the_renderer(grid, store):
    from geoshade.render.visuals.grid import layout
    from geoshade.render.visuals.grid.prepare import zcorn_indices

    assert FACE_CORNERS == layout.FACE_CORNERS
    fs = visible_faces(grid)
    want = grid.zcorn.ravel(order="F")[zcorn_indices(fs.cells, fs.face, grid.dims)]
    got = face_corner_depths(store.zcorn, fs.cells, fs.face)
    assert got.dtype == np.float32 and got.shape == (len(fs), 4)
    np.testing.assert_array_equal(got, want)
    np.testing.assert_array_equal(face_corner_depths(grid.zcorn, fs.cells, fs.face), want)
    odd = da.from_array(grid.zcorn, chunks=(5, 3, 3))  # chunks cutting cells: corner by corner
    np.testing.assert_array_equal(face_corner_depths(odd, fs.cells, fs.face), want)
    assert face_corner_depths(store.zcorn, fs.cells[:0], fs.face[:0]).shape == (0, 4)
