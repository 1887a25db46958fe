"""The coarse level of detail of a corner-point grid (geoshade.compute.grid.coarse) against a
per-block numpy oracle, in memory and from a lazy grid store, and its storage in a store."""

from __future__ import annotations

import numpy as np
import pytest

from geoshade.compute.grid import coarse as grid_coarse
from geoshade.compute.grid.coarse import coarse_grid
from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.errors import InputError


def oracle(grid, f):
    """The coarse grid's arrays by a loop over blocks (an independent reading of the rule)."""
    nx, ny, nz = grid.dims
    cx, cy, cz = -(-nx // f), -(-ny // f), -(-nz // f)
    coord = np.asarray(grid.coord)
    zc = np.asarray(grid.zcorn)
    act = np.asarray(grid.actnum) != 0
    pil = [[min(p * f, n) for p in range(c + 1)] for c, n in ((cx, nx), (cy, ny))]
    out = {"coord": coord[np.ix_(pil[0], pil[1])], "zcorn": np.empty((2 * cx, 2 * cy, 2 * cz)),
           "actnum": np.zeros((cx, cy, cz), bool), "props": {}}
    for name in grid.properties:
        out["props"][name] = np.zeros((cx, cy, cz))
    for I in range(cx):
        for J in range(cy):
            for K in range(cz):
                bi = range(I * f, min(I * f + f, nx))
                bj = range(J * f, min(J * f + f, ny))
                bk = range(K * f, min(K * f + f, nz))
                for a in (0, 1):
                    for b in (0, 1):
                        for c in (0, 1):
                            i = bi[-1] if a else bi[0]
                            j = bj[-1] if b else bj[0]
                            k = bk[-1] if c else bk[0]
                            out["zcorn"][2 * I + a, 2 * J + b, 2 * K + c] = \
                                zc[2 * i + a, 2 * j + b, 2 * k + c]
                blk = np.ix_(list(bi), list(bj), list(bk))
                m = act[blk]
                out["actnum"][I, J, K] = m.any()
                for name, arr in grid.properties.items():
                    v = np.asarray(arr)[blk][m]
                    if np.issubdtype(np.asarray(arr).dtype, np.integer):
                        if v.size:
                            vals, counts = np.unique(v, return_counts=True)
                            r = vals[np.argmax(counts)]   # unique sorts: smallest on a tie
                        else:
                            r = 0
                    else:
                        r = v.astype(np.float64).mean() if v.size else np.nan
                    out["props"][name][I, J, K] = r
    return out


@pytest.mark.parametrize("f", [2, 4])
@pytest.mark.parametrize("dims", [(8, 8, 4), (12, 8, 8), (10, 7, 5)])
def test_coarse_grid_equals_the_oracle(f, dims):
    g = synthetic_grid(*dims, seed=5, inactive_fraction=0.3)
    g.properties["FIPNUM"] = (np.arange(g.ncells) % 3).reshape(g.dims).astype(np.int32)
    g.actnum = np.asarray(g.actnum).copy()
    g.actnum[:f, :f, :f] = 0            # one whole inactive block
    g.actnum[f, 0, 0] = 0               # and one partly inactive
    c = coarse_grid(g, f)
    ref = oracle(g, f)
    assert c.dims == ref["actnum"].shape
    np.testing.assert_array_equal(c.coord, ref["coord"])
    np.testing.assert_array_equal(c.zcorn, ref["zcorn"].astype(c.zcorn.dtype))
    np.testing.assert_array_equal(c.active, ref["actnum"])
    assert 0 < c.nactive < c.ncells and not c.active[0, 0, 0]
    for name, arr in ref["props"].items():
        got = np.asarray(c.properties[name], np.float64)
        if np.issubdtype(np.asarray(g.properties[name]).dtype, np.integer):
            np.testing.assert_array_equal(got, arr)
        else:
            np.testing.assert_allclose(got, arr.astype(np.asarray(g.properties[name]).dtype),
                                       rtol=1e-6, equal_nan=True)


def test_mode_ties_take_the_smallest_and_skip_inactive():
    v = np.zeros((2, 2, 2), np.int32)
    v.flat[:] = [5, 3, 5, 3, 9, 9, 9, 1]
    act = np.ones((2, 2, 2), bool)
    act.flat[4:7] = False          # the three 9s do not count
    assert grid_coarse.coarse_values(v, act, 2)[0, 0, 0] == 3


def test_factor_one_is_the_grid():
    g = synthetic_grid(9, 7, 5, seed=2)
    c = coarse_grid(g, 1)
    np.testing.assert_array_equal(c.coord, g.coord)
    np.testing.assert_array_equal(c.zcorn, g.zcorn)
    np.testing.assert_array_equal(c.active, g.active)
    for name, arr in g.properties.items():
        np.testing.assert_array_equal(np.asarray(c.properties[name]),
                                      np.where(g.active, arr, np.asarray(c.properties[name])))
    for t, st in enumerate(g.steps):
        for name, arr in st.items():
            a = np.asarray(arr)
            np.testing.assert_array_equal(np.asarray(c.steps[t][name])[g.active], a[g.active])
    assert [(fl.name, fl.faces.tolist()) for fl in c.faults] == \
        [(fl.name, np.unique(fl.faces, axis=0).tolist()) for fl in g.faults]


def test_fault_throw_kept_at_coarse_pillars():
    """At a kept pillar, the coarse corner depths are the fine ones on both sides of a
    fault: the throw the fine grid has there is the coarse grid's."""
    g = synthetic_grid(16, 12, 8, seed=1)
    c = coarse_grid(g, 4)
    zf, zcc = np.asarray(g.zcorn), np.asarray(c.zcorn)
    # fine pillar i = 8 (coarse pillar 2): cell 7 side (a=1) and cell 8 side (a=0), top layer
    fine_throw = zf[2 * 7 + 1, 0, 0] - zf[2 * 8, 0, 0]
    coarse_throw = zcc[2 * 1 + 1, 0, 0] - zcc[2 * 2, 0, 0]
    assert coarse_throw == fine_throw
    assert any(len(fl.faces) for fl in c.faults)


def test_tiles_bound_memory_and_agree(monkeypatch):
    g = synthetic_grid(12, 10, 6, seed=4)
    whole = coarse_grid(g, 2)
    monkeypatch.setattr(grid_coarse, "TILE_CELLS", 64)   # many small tiles (i, j, k)
    seen = []
    tiled = coarse_grid(g, 2, progress=lambda d, t: seen.append(t))
    assert seen and seen[0] > 6
    np.testing.assert_array_equal(tiled.zcorn, whole.zcorn)
    for name in g.properties:
        np.testing.assert_array_equal(tiled.properties[name], whole.properties[name])


def test_lazy_store_grid_equals_in_memory(tmp_path):
    from geoshade.io.stores.grid_store import ModelSource, open_grid_store, write_grid_store

    g = synthetic_grid(12, 9, 6, seed=3)
    write_grid_store(ModelSource(g), tmp_path / "g.zarr", chunks=(5, 4, 3), input_label="g")
    lazy = open_grid_store(tmp_path / "g.zarr")
    a, b = coarse_grid(lazy, 2), coarse_grid(g, 2)
    np.testing.assert_array_equal(a.zcorn, b.zcorn)
    np.testing.assert_array_equal(a.active, b.active)
    for name in g.properties:
        np.testing.assert_array_equal(a.properties[name], b.properties[name])


@pytest.mark.parametrize("bad", [3, 0, "x", 2.5])
def test_bad_factor_one_line(bad):
    with pytest.raises(InputError, match="factor: expected one of 1, 2, 4, 8"):
        coarse_grid(synthetic_grid(4, 4, 2), bad)


def test_coarse_level_kept_in_the_store(tmp_path):
    from geoshade.grid.lod import read_coarse_level, write_coarse_level
    from geoshade.io.stores.grid_store import ModelSource, open_grid_store, write_grid_store

    g = synthetic_grid(12, 8, 8, seed=6)
    store = tmp_path / "g.zarr"
    write_grid_store(ModelSource(g), store, chunks=(6, 4, 4), input_label="g")
    assert read_coarse_level(store) is None
    write_coarse_level(store, 4)
    write_coarse_level(store, 2)              # replaces it, atomically
    c = read_coarse_level(store, expect_dims=g.dims)
    ref = coarse_grid(g, 2)
    assert c.meta["lod"]["factor"] == 2 and c.meta["lod"]["fine_dims"] == [12, 8, 8]
    np.testing.assert_array_equal(c.zcorn, ref.zcorn)
    np.testing.assert_array_equal(c.active, ref.active)
    for name in g.properties:
        np.testing.assert_array_equal(c.properties[name], ref.properties[name])
    assert sorted(p.name for p in tmp_path.iterdir()) == ["g.zarr"]
    assert not any(p.name.startswith(("lod.", ".lod")) for p in store.iterdir())
    assert open_grid_store(store).dims == g.dims     # the fine store still opens
    with pytest.raises(InputError, match="coarse level of a 12×8×8 grid"):
        read_coarse_level(store, expect_dims=(1, 2, 3))


def test_coarse_level_of_an_incomplete_store_one_line(tmp_path):
    from geoshade.grid.lod import write_coarse_level

    with pytest.raises(InputError, match="not a geoshade grid store"):
        write_coarse_level(tmp_path, 2)


def test_auto_factor(tmp_path, monkeypatch):
    from geoshade.grid import lod
    from geoshade.io.stores.grid_store import ModelSource, write_grid_store

    g = synthetic_grid(16, 16, 8, seed=6)
    store = tmp_path / "g.zarr"
    write_grid_store(ModelSource(g), store, chunks=(8, 8, 4), input_label="g")
    lod.write_coarse_level(store, "auto")            # within the budget: the least, 2
    assert lod.read_coarse_level(store).meta["lod"]["factor"] == 2
    monkeypatch.setattr(lod, "PREVIEW_CELLS", 8)     # 2048 cells: 2 -> 256, 4 -> 32, 8 -> 4
    lod.write_coarse_level(store, "auto")
    assert lod.read_coarse_level(store).meta["lod"]["factor"] == 8
    assert lod.preview_factor(10**9, 1 << 21) == 8 and lod.preview_factor(10**8, 1 << 21) == 4
