"""A grid store draws a region or facies property as the same grid in memory draws it: as
categories (one qualitative colour per code, the legend's entries), with or without a filter or a
slice, from the codes kept at ingest or, for an older store, from one chunked pass; an integer
--param beside the store likewise; ROFF's undefined code (-999) stays "no value" after ingest."""

import json
import shutil
import warnings

import numpy as np
import pytest

from geoshade.compute.grid.index_faces import store_index
from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.grid import GridView
from geoshade.io.grids.params import add_params
from geoshade.io.stores.grid_store import ModelSource, open_grid_store, write_grid_store

SIZE = (200, 150)
CHUNKS = (7, 6, 3)


def _grid():
    g = synthetic_grid(25, 19, 8, inactive_fraction=0.15, steps=2, seed=5)
    rng = np.random.default_rng(5)
    facies = rng.choice([-999, 1, 2, 4], g.dims, p=[0.1, 0.3, 0.3, 0.3]).astype(np.int32)
    g.properties["FACIES"] = np.asfortranarray(facies)
    return g


@pytest.fixture(scope="module")
def case(tmp_path_factory):
    folder = tmp_path_factory.mktemp("cat")
    grid = _grid()
    store = folder / "c.zarr"
    write_grid_store(ModelSource(grid), store, CHUNKS, index=store_index)
    roff = _grid()
    roff.meta["format"] = "ROFF"   # as read from a ROFF file: -999 is "no value"
    roff_store = folder / "r.zarr"
    write_grid_store(ModelSource(roff), roff_store, CHUNKS)
    return grid, store, roff, roff_store


def _draw(ctx, grid, **opts):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with GridView(grid, size=SIZE, ctx=ctx, **opts) as v:
            img, stats = v.draw(frames=1)
            return img, stats, v.legend_spec() if hasattr(v, "legend_spec") else None


@pytest.mark.parametrize("opts", [
    {"property": "FIPNUM"},
    {"property": "FIPNUM", "filter": "PORO > 0.2"},
    {"property": "FACIES", "slice": "i=3:20,k=2:7"},
    {"property": "FACIES", "filter": "FIPNUM == 2 and PERMX > 50"},
])
def test_a_store_draws_categories_as_memory_does(ctx, case, opts):
    grid, store, _, _ = case
    a, sa, _ = _draw(ctx, grid, **opts)
    b, sb, _ = _draw(ctx, open_grid_store(store), **opts)
    assert sa["categories"] and sa["categories"] == sb["categories"]
    assert sa["color_range"] == sb["color_range"]
    np.testing.assert_array_equal(a, b)     # the legend too (annotations on)


def test_an_older_store_draws_them_from_one_pass(ctx, case, tmp_path):
    grid, store, _, _ = case
    old = tmp_path / "old.zarr"
    shutil.copytree(store, old)
    meta = json.loads((old / "zarr.json").read_text())
    del meta["attributes"]["distinct_codes"]
    (old / "zarr.json").write_text(json.dumps(meta))
    a, sa, _ = _draw(ctx, grid, property="FIPNUM", filter="PORO > 0.2")
    b, sb, _ = _draw(ctx, open_grid_store(old), property="FIPNUM", filter="PORO > 0.2")
    assert sb["categories"] == sa["categories"] == [1.0, 2.0]
    np.testing.assert_array_equal(a, b)


def test_an_integer_param_beside_a_store_is_categories_too(ctx, case, tmp_path):
    grid, store, _, _ = case
    rng = np.random.default_rng(2)
    zone = rng.integers(1, 5, grid.ncells)
    f = tmp_path / "z.grdecl"
    f.write_text("ZONE\n" + " ".join(str(v) for v in zone) + " /\n")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        mem, lazy = add_params(_grid(), [f]), add_params(open_grid_store(store), [f])
    a, sa, _ = _draw(ctx, mem, property="ZONE", filter="PORO > 0.2")
    b, sb, _ = _draw(ctx, lazy, property="ZONE", filter="PORO > 0.2")
    assert sa["categories"] == sb["categories"] == [1.0, 2.0, 3.0, 4.0]
    np.testing.assert_array_equal(a, b)


def test_roffs_undefined_code_stays_no_value_in_a_store(ctx, case):
    _, _, roff, roff_store = case
    a, sa, _ = _draw(ctx, roff, property="FACIES")
    b, sb, _ = _draw(ctx, open_grid_store(roff_store), property="FACIES")
    assert sa["categories"] == sb["categories"] == [1.0, 2.0, 4.0]   # -999: no value
    assert sa["no_value_cells"] == sb["no_value_cells"] > 0
    np.testing.assert_array_equal(a, b)
