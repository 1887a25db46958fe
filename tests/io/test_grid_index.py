"""A grid store's index (issue 26, target 1): what ingest stores equals what is computed without
it (faces, corner depths, per-chunk statistics, face-cell values), chunk skipping selects exactly
the cells of the full filter, ``--index-only`` gives the ingest's index, and a failed or refused
run leaves the store as it was."""

import json
import shutil

import numpy as np
import pytest

from geoshade.compute.grid.chunks import face_corner_depths, visible_faces_chunked
from geoshade.compute.grid.faces import (
    _face_set_in_drawing_order,
    _fault_lookup,
    visible_faces,
)
from geoshade.compute.grid.filters import cell_filter
from geoshade.compute.grid.index_faces import (
    chunk_numbers,
    chunk_status,
    index_faces,
    store_index,
)
from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.grid.geometry import parse_slice
from geoshade.grid.lazy import bounds, orientation
from geoshade.io.grids.grdecl_writer import write_grdecl
from geoshade.io.stores import grid_index
from geoshade.io.stores.grid_index import GridIndex, add_index, open_index
from geoshade.io.stores.grid_store import (
    ModelSource,
    ingest_grid,
    open_grid_store,
    write_grid_store,
)
from tests.corruption import clean_failure, run_cli
from tests.io.grid_store_support import interrupted_ingest

CHUNKS = (7, 6, 3)   # borders cut both faults (i = 8, j = 12) and the inactive blobs


@pytest.fixture(scope="module")
def made(tmp_path_factory):
    folder = tmp_path_factory.mktemp("gi")
    grid = synthetic_grid(25, 19, 8, inactive_fraction=0.2, steps=3, seed=5)
    store = folder / "s.zarr"
    write_grid_store(ModelSource(grid), store, CHUNKS, index=store_index)
    return grid, store


def _index(store) -> tuple:
    lazy = open_grid_store(store)
    idx = open_index(lazy)
    assert isinstance(idx, GridIndex), idx
    return lazy, idx


def _blocks(grid):
    """(chunk number, slices) of every chunk of cells, C order."""
    nx, ny, nz = grid.dims
    out = []
    for a in range(0, nx, CHUNKS[0]):
        for b in range(0, ny, CHUNKS[1]):
            for c in range(0, nz, CHUNKS[2]):
                out.append((slice(a, a + CHUNKS[0]), slice(b, b + CHUNKS[1]),
                            slice(c, c + CHUNKS[2])))
    return out


def test_stored_faces_equal_the_computed_ones(made):
    grid, store = made
    lazy, idx = _index(store)
    cells, face, fault, nbs = idx.faces()
    for fs in (visible_faces(grid), visible_faces_chunked(lazy)):  # in memory, chunk by chunk
        np.testing.assert_array_equal(cells, fs.cells)
        np.testing.assert_array_equal(face, fs.face)
        np.testing.assert_array_equal(fault, fs.fault)
        np.testing.assert_array_equal(nbs, fs.neighbour_shown)
    assert fault.any() and (~nbs).any()   # the case has faults and inactive borders
    np.testing.assert_array_equal(idx.corners(), face_corner_depths(grid.zcorn, cells, face))
    # grouped by chunk: every chunk's positions are its faces, in drawing order
    cnum = chunk_numbers(cells, tuple(tuple(a) for a in idx.chunks))
    seen = []
    for c in range(len(_blocks(grid))):
        pos = idx.chunk_positions(c)
        assert (cnum[pos] == c).all() and (np.diff(pos) > 0).all()
        seen.append(pos)
    assert np.array_equal(np.sort(np.concatenate(seen)), np.arange(len(face)))


def test_chunk_statistics_equal_numpys(made):
    grid, store = made
    _lazy, idx = _index(store)
    act = grid.active
    arrays = [("props/" + n, None, np.asarray(v)) for n, v in grid.properties.items()]
    arrays += [("steps/SWAT", t, np.asarray(s["SWAT"])) for t, s in enumerate(grid.steps)]
    assert any(np.asarray(v).dtype.kind == "i" for _, _, v in arrays)   # FIPNUM
    for c, sl in enumerate(_blocks(grid)):
        a = act[sl]
        assert idx.nactive[c] == np.count_nonzero(a)
        for key, t, v in arrays:
            w = v[sl][a]
            w = w[np.isfinite(w)]
            lo, hi, n = idx.stats(key, t)[c]
            assert n == w.size, (key, t, c)
            if w.size:
                assert (lo, hi) == (float(w.min()), float(w.max())), (key, t, c)
            else:
                assert np.isnan(lo) and np.isnan(hi)


def test_face_cell_values_are_the_cells_values(made):
    grid, store = made
    _lazy, idx = _index(store)
    nx, ny, _ = grid.dims
    c = visible_faces(grid).cells.astype(np.int64)
    want = np.unique(c[:, 0] + nx * (c[:, 1] + ny * c[:, 2]))
    np.testing.assert_array_equal(idx.cells, want)
    for name, v in grid.properties.items():
        np.testing.assert_array_equal(idx.values(f"props/{name}", None),
                                      np.asarray(v).ravel(order="F")[want])
    for t, s in enumerate(grid.steps):
        np.testing.assert_array_equal(idx.values("steps/SWAT", t),
                                      np.asarray(s["SWAT"]).ravel(order="F")[want])


FILTERS = ["PERMX > 150", "PORO <= 0.18", "0.15 < PORO < 0.25", "not PORO > 0.2",
           "PERMX > 400 or NTG < 0.4", "FIPNUM == 2", "FIPNUM != 1", "2 > FIPNUM",
           "PORO > 0.2 and log10(PERMX) > 2", "SWAT > 0.5", "PERMX >= -1"]


@pytest.mark.parametrize("expr", FILTERS)
@pytest.mark.parametrize("spec", [None, "i=3:20,k=2:7"])
def test_skipping_chunks_selects_the_cells_of_the_full_filter(made, expr, spec):
    grid, store = made
    lazy, idx = _index(store)
    box = parse_slice(spec, grid.dims)
    props = {**grid.properties, **grid.steps[1]}
    mask = grid.active & cell_filter(expr, props, grid.dims)
    inside = np.zeros(grid.dims, bool)
    inside[box] = True
    mask &= inside
    status = chunk_status(lazy, idx.nactive, idx.stats, expr, box if spec else None, step=1)
    for c, sl in enumerate(_blocks(grid)):
        if status[c] == 0:
            assert not mask[sl].any(), (expr, c)
        elif status[c] == 1:
            assert np.array_equal(mask[sl], grid.active[sl]), (expr, c)
    # the faces from the index (read only the undecided chunks) are the full filter's
    blocks = _blocks(grid)
    read = []

    def read_shown(sel):
        read.extend(sel)
        return [mask[blocks[int(np.ravel_multi_index(i, idx.nb))]] for i in sel]

    cells, face, fault, nbs = idx.faces()

    def chunk_faces(c):
        pos = idx.chunk_positions(c)
        return cells[pos], face[pos], fault[pos], nbs[pos]

    parts, shown, counts = index_faces(lazy, status, read_shown, chunk_faces, idx.nactive)
    got = _face_set_in_drawing_order(grid, parts, *_fault_lookup(grid))
    ref = visible_faces(grid, shown=mask)
    assert shown == int(mask.sum())
    for k in ("cells", "face", "fault", "fault_id", "neighbour_shown"):
        np.testing.assert_array_equal(getattr(got, k), getattr(ref, k), k)
    assert counts["skipped"] == int((status == 0).sum())
    nb = idx.nb
    assert all(status[np.ravel_multi_index(i, nb)] != 0 for i in read)


def test_some_filters_skip_and_reuse_chunks(made):
    _, store = made
    lazy, idx = _index(store)
    s = chunk_status(lazy, idx.nactive, idx.stats, "SWAT > 0.5", None, step=1)
    assert (s == 0).any()
    s = chunk_status(lazy, idx.nactive, idx.stats, "PERMX >= -1", None)
    assert (s[idx.nactive > 0] == 1).all()
    s = chunk_status(lazy, idx.nactive, idx.stats, "PORO > 0.2",
                     parse_slice("i=0:7", lazy.dims))
    assert (s.reshape(idx.nb)[1:] == 0).all()


def _arrays(store):
    import zarr

    root = zarr.open_group(str(store / "index"), mode="r")
    out = {}
    for name in ["faces/cells", "faces/face", "faces/flags", "faces/corners",
                 "faces/by_chunk", "faces/offsets", "nactive", "cells"]:
        out[name] = np.asarray(root[name][...])
    return out


def test_index_only_gives_the_ingests_index(made, tmp_path, capsys):
    grid, store = made
    old = tmp_path / "old.zarr"
    write_grid_store(ModelSource(grid), old, CHUNKS)   # an old store: no index
    assert isinstance(open_index(open_grid_store(old)), str)
    rc, out, err = run_cli(capsys, ["grid", "ingest", "--index-only", old])
    assert rc == 0 and "index of" in out, err
    a, b = _arrays(store), _arrays(old)
    for k in a:
        np.testing.assert_array_equal(a[k], b[k], k)
    ma = json.loads((store / "zarr.json").read_text())["attributes"]["grid_index"]
    mb = json.loads((old / "zarr.json").read_text())["attributes"]["grid_index"]
    assert ma == mb
    assert not (old / "index.building").exists() and not (old / "index.old").exists()
    # again: rebuilt in place, the same
    rc, _, _ = run_cli(capsys, ["grid", "ingest", "--index-only", old])
    assert rc == 0 and json.loads((old / "zarr.json").read_text())["attributes"][
        "grid_index"] == ma


def test_a_failed_index_only_leaves_the_store_as_it_was(made, tmp_path):
    grid, _store = made
    old = tmp_path / "o.zarr"
    write_grid_store(ModelSource(grid), old, CHUNKS, index=store_index)
    before = (old / "zarr.json").read_text()

    def broken(g, progress):
        raise RuntimeError("stopped")

    with pytest.raises(RuntimeError):
        add_index(open_grid_store(old), broken)
    assert (old / "zarr.json").read_text() == before
    assert isinstance(open_index(open_grid_store(old)), GridIndex)
    assert not (old / "index.building").exists()


def test_index_only_refuses_what_is_not_a_complete_grid_store(made, tmp_path, capsys,
                                                             monkeypatch):
    grid, store = made
    clean_failure(capsys, ["grid", "ingest", "--index-only", tmp_path], names=tmp_path.name)
    part = tmp_path / "p.zarr"
    write_grid_store(ModelSource(grid), part, CHUNKS)
    meta = json.loads((part / "zarr.json").read_text())
    meta["attributes"]["grid_store"]["complete"] = False
    (part / "zarr.json").write_text(json.dumps(meta))
    clean_failure(capsys, ["grid", "ingest", "--index-only", part], names="p.zarr",
                  expect="incomplete")
    clean_failure(capsys, ["grid", "ingest", "--index-only", store, "-o", tmp_path / "x"],
                  names="--index-only")


def test_cli_ingest_writes_the_index(tmp_path, capsys):
    path = tmp_path / "g.grdecl"
    write_grdecl(synthetic_grid(9, 7, 5, steps=0), path)
    out = tmp_path / "g.zarr"
    rc, text, err = run_cli(capsys, ["grid", "ingest", path, "-o", out, "--chunks", 4, 4, 2])
    assert rc == 0 and "index of" in text, err
    lazy = open_grid_store(out)
    idx = open_index(lazy)
    assert isinstance(idx, GridIndex)
    np.testing.assert_array_equal(idx.faces()[0], visible_faces_chunked(lazy).cells)
    assert grid_index.INDEX_VERSION == json.loads((out / "zarr.json").read_text())[
        "attributes"]["grid_index"]["version"]


def test_a_stale_index_is_not_used(made, tmp_path):
    _grid, store = made
    copy = tmp_path / "c.zarr"
    shutil.copytree(store, copy)
    meta = json.loads((copy / "zarr.json").read_text())
    meta["attributes"]["grid_index"]["version"] = 99
    (copy / "zarr.json").write_text(json.dumps(meta))
    why = open_index(open_grid_store(copy))
    assert isinstance(why, str) and "format version 99" in why and "\n" not in why


def test_kept_bounds_and_orientation_equal_the_computed_ones(made):
    _, store = made
    kept, plain = open_grid_store(store), open_grid_store(store)
    plain.__dict__["_store_index"] = ""   # as a store without an index: computed
    for a, b in zip(bounds(kept), bounds(plain), strict=True):
        np.testing.assert_array_equal(a, b)
    assert orientation(kept) == orientation(plain) != 0
    assert isinstance(open_index(kept).array("zbounds"), np.ndarray)


def test_a_resumed_ingest_writes_the_same_index(tmp_path, monkeypatch):
    path = tmp_path / "g.grdecl"
    write_grdecl(synthetic_grid(9, 7, 6, steps=0, inactive_fraction=0.2), path)
    fresh, resumed = tmp_path / "a.zarr", tmp_path / "b.zarr"
    ingest_grid(path, fresh, chunks=(4, 3, 2), index=store_index)
    interrupted_ingest(monkeypatch, path, resumed, after=1, chunks=(4, 3, 2), index=store_index)
    assert not resumed.exists()
    rep = ingest_grid(path, resumed, chunks=(4, 3, 2), index=store_index)
    assert rep.resumed and rep.index is not None
    a, b = _arrays(fresh), _arrays(resumed)
    for k in a:
        np.testing.assert_array_equal(a[k], b[k], k)
