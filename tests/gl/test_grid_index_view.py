"""A grid store drawn from its index (issue 26, target 1) draws the picture it draws without one,
pixel for pixel: plain, property and step switches, filters (chunks skipped by their
statistics, chunks reused whole, chunks computed), slices; an old store without an index still
draws and says once that an index would help; a damaged index is ignored in one line."""

import json
import shutil
import warnings

import numpy as np
import pytest
import zarr

from geoshade.compute.grid.index_faces import store_index
from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.grid import GridView, sources
from geoshade.io.grids.params import add_params
from geoshade.io.stores.grid_store import ModelSource, open_grid_store, write_grid_store

SIZE = (160, 120)
CHUNKS = (7, 6, 3)   # borders cut both faults and the inactive blobs


@pytest.fixture(scope="module")
def stores(tmp_path_factory):
    folder = tmp_path_factory.mktemp("idx")
    grid = synthetic_grid(25, 19, 8, inactive_fraction=0.15, steps=3, seed=3)
    with_index = folder / "with.zarr"
    without = folder / "without.zarr"
    rep = write_grid_store(ModelSource(grid), with_index, CHUNKS, index=store_index)
    assert rep.index is not None and rep.index.faces > 0
    write_grid_store(ModelSource(grid), without, CHUNKS)
    return grid, with_index, without


def _draw(ctx, grid, **opts):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with GridView(grid, size=SIZE, ctx=ctx, annotations=False, **opts) as v:
            return v.draw(frames=1)


CASES = [
    {"property": "PORO"},
    {"property": "PORO", "faults": "hide"},
    {"property": "SWAT", "step": 2, "faults": "highlight", "edges": "quad"},
    {"property": "PERMX", "filter": "PERMX > 100"},
    {"property": "PORO", "filter": "PORO > 0.2 and not PERMX < 50", "faults": "hide"},
    {"property": "SWAT", "step": 1, "filter": "SWAT >= 0.2"},
    {"property": "PORO", "slice": "i=3:20,j=2:15,k=1:7"},
    {"property": "NTG", "filter": "0.3 < NTG", "slice": "i=8:25"},
    {"property": "PORO", "filter": "PORO > 99"},   # every chunk skipped: an empty view
]


@pytest.mark.parametrize("opts", CASES)
def test_the_index_draws_the_computed_picture(ctx, stores, opts):
    grid, with_index, without = stores
    a, sa = _draw(ctx, open_grid_store(with_index), **opts)
    b, sb = _draw(ctx, open_grid_store(without), **opts)
    m, sm = _draw(ctx, grid, **opts)
    np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(a, m)
    assert sa["faces_from"] == "index" and sb["faces_from"] == "computed"
    assert sa["index"] == "used" and sb["index"] != "used"
    for key in ("faces", "shown_cells", "color_range", "faceset_faces"):
        assert sa[key] == sb[key] == sm[key], key
    if opts.get("filter") or opts.get("slice"):
        assert sa["chunks_skipped"] + sa["chunks_from_index"] + sa["chunks_computed"] > 0
    else:
        assert sa["chunks_computed"] == 0 and sa["values_from"] == "index"


def test_a_filter_that_selects_nothing_in_most_chunks_skips_them(ctx, stores):
    grid, with_index, _ = stores
    hi = float(np.nanmax(np.where(grid.active, grid.properties["PERMX"], np.nan)))
    _, s = _draw(ctx, open_grid_store(with_index), property="PERMX",
                 filter=f"PERMX > {hi * 0.9}")
    assert s["chunks_skipped"] > 0


def test_switches_read_the_cached_face_values(ctx, stores):
    grid, with_index, without = stores
    imgs = []
    for path in (with_index, without):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            with GridView(open_grid_store(path), property="PORO", size=SIZE, ctx=ctx,
                          annotations=False) as v:
                v.draw(frames=1)
                v.update(property="PERMX")
                a, s1 = v.draw(frames=1)
                v.update(property="SWAT", step=0)
                v.update(step=2)
                b, s2 = v.draw(frames=1)
                imgs.append((a, b, s1, s2))
    (a1, b1, s1, s2), (a2, b2, _, _) = imgs
    np.testing.assert_array_equal(a1, a2)
    np.testing.assert_array_equal(b1, b2)
    assert s1["values_from"] == s2["values_from"] == "index"
    ref, _ = _draw(ctx, grid, property="SWAT", step=2)
    np.testing.assert_array_equal(b1, ref)


def test_an_old_store_warns_once_that_an_index_would_help(ctx, stores):
    _, _, without = stores
    with GridView(open_grid_store(without), property="PORO", size=SIZE, ctx=ctx,
                  annotations=False) as v:
        with warnings.catch_warnings(record=True) as rec:
            warnings.simplefilter("always")
            v.draw(frames=1)
            v.update(property="PERMX")
            _, s = v.draw(frames=1)
    said = [w for w in rec if "--index-only" in str(w.message)]
    assert len(said) == 1, [str(w.message) for w in rec]
    assert "\n" not in str(said[0].message)
    assert s["faces_from"] == "computed" and "--index-only" in s["index"]


def _damaged_copy(src, dst, how: str):
    shutil.copytree(src, dst)
    if how == "bytes":  # a value changed: its CRC-32 no longer matches
        arr = dst / "index" / "faces" / "corners"
        z = zarr.open_array(str(arr), mode="r+")
        v = np.asarray(z[...])
        v[0, 0] += 1.0
        z[...] = v
    elif how == "missing":
        shutil.rmtree(dst / "index" / "faces" / "cells")
    elif how == "partial":  # an attribute that says the index is not complete
        meta = json.loads((dst / "zarr.json").read_text())
        meta["attributes"]["grid_index"]["complete"] = False
        (dst / "zarr.json").write_text(json.dumps(meta))
    return dst


@pytest.mark.parametrize("how", ["bytes", "missing", "partial"])
def test_a_damaged_index_is_ignored_in_one_line(ctx, stores, tmp_path, how):
    grid, with_index, _ = stores
    bad = _damaged_copy(with_index, tmp_path / "bad.zarr", how)
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        img, s = _draw_keep(ctx, open_grid_store(bad), property="PORO")
    ref, _ = _draw(ctx, grid, property="PORO")
    np.testing.assert_array_equal(img, ref)
    said = [str(w.message) for w in rec if "index" in str(w.message)]
    assert len(said) == 1 and "\n" not in said[0], said
    assert s["faces_from"] == "computed"


def _draw_keep(ctx, grid, **opts):
    with GridView(grid, size=SIZE, ctx=ctx, annotations=False, **opts) as v:
        return v.draw(frames=1)


def test_corners_gathered_batch_by_batch_draw_the_same(ctx, stores, monkeypatch):
    """Beyond LAZY_CORNERS_AHEAD faces the corners are looked up while the records are built."""
    grid, with_index, _ = stores
    opts = {"property": "PORO", "filter": "PORO > 0.15", "slice": "i=2:24"}
    ref, _ = _draw(ctx, grid, **opts)
    monkeypatch.setattr(sources, "LAZY_CORNERS_AHEAD", 10)
    img, s = _draw(ctx, open_grid_store(with_index), **opts)
    np.testing.assert_array_equal(img, ref)
    assert s["faces"] > 10 and s["faces_from"] == "index"


def test_a_param_beside_the_index_is_read_not_taken_from_it(ctx, stores, tmp_path):
    """A --param that replaces PORO (and adds FACIES) is coloured and filtered by its own
    values: the index keeps serving the store's own arrays only (the picture of the store
    without an index, with the same param)."""
    grid, with_index, without = stores
    rng = np.random.default_rng(1)
    poro = rng.uniform(0.0, 0.4, grid.ncells)
    facies = rng.integers(1, 4, grid.ncells)
    f = tmp_path / "p.grdecl"
    f.write_text("PORO\n" + " ".join(f"{v:.4f}" for v in poro) + " /\nFACIES\n"
                 + " ".join(str(v) for v in facies) + " /\n")
    for opts in ({"property": "PORO"}, {"property": "FACIES", "filter": "PORO > 0.2"},
                 {"property": "PERMX", "filter": "FACIES == 2 and PERMX > 50"}):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            lazy = add_params(open_grid_store(with_index), [f])
            plain = add_params(open_grid_store(without), [f])
        a, sa = _draw(ctx, lazy, **opts)
        b, sb = _draw(ctx, plain, **opts)
        np.testing.assert_array_equal(a, b)
        assert sa["index"] == "used" and sa["faces"] == sb["faces"], sa["index"]
    # PORO replaced: the memory grid with the same param draws the same picture
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        mem = add_params(synthetic_grid(25, 19, 8, inactive_fraction=0.15, steps=3, seed=3),
                         [f])
        lazy = add_params(open_grid_store(with_index), [f])
    np.testing.assert_array_equal(_draw(ctx, lazy, property="PORO", filter="PORO > 0.2")[0],
                                  _draw(ctx, mem, property="PORO", filter="PORO > 0.2")[0])


def test_a_wholly_inactive_chunk_keeps_the_unfiltered_picture_on_the_stored_faces(ctx, tmp_path):
    """Chunks without an active cell hold no stored face: with no filter and no slice the
    stored faces are drawn as they are (no chunk computed), the picture the computed one."""
    grid = synthetic_grid(25, 19, 8, inactive_fraction=0.15, steps=1, seed=3)
    act = np.array(grid.actnum)
    act[:7, :6, :3] = 0      # one chunk of CHUNKS wholly inactive
    grid = type(grid)(coord=grid.coord, zcorn=grid.zcorn, actnum=act,
                      properties=grid.properties, steps=grid.steps, faults=grid.faults,
                      name=grid.name)
    store = write_grid_store(ModelSource(grid), tmp_path / "g.zarr", CHUNKS,
                             index=store_index).path
    a, sa = _draw(ctx, open_grid_store(store), property="PORO")
    m, _ = _draw(ctx, grid, property="PORO")
    np.testing.assert_array_equal(a, m)
    # every chunk taken as stored, the inactive one too (it was 'skipped', and the faces then
    # went through the filter path: grouped, looked up and assembled again, 10 s at 1e9)
    assert sa["faces_from"] == "index" and sa["chunks_computed"] == 0
    assert sa["chunks_skipped"] == 0 and sa["chunks_from_index"] == 4 * 4 * 3
