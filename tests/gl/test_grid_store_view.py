"""A grid out of core (a grid store: dask arrays) draws the picture of the same grid in memory:
faces chunk by chunk, corner depths and face-cell values gathered from their chunks."""


import numpy as np
import pytest

import geoshade
from geoshade.errors import InputError
from geoshade.grid import GridView
from geoshade.io.stores.grid_store import ingest_grid, open_grid_store
from tests.grid_cases import grid_cases as benchmark_cases

SIZE = (160, 120)


@pytest.fixture(scope="module")
def case(tmp_path_factory):
    grid_cases = benchmark_cases()
    folder = tmp_path_factory.mktemp("case")
    paths = grid_cases.write_case(folder, 30, 21, 7, steps=2)
    store = folder / "c.zarr"
    ingest_grid(paths["EGRID"], store, chunks=(8, 8, 3))  # chunk borders cut both faults
    return geoshade.load(paths["EGRID"]), open_grid_store(store)


@pytest.mark.parametrize("opts", [
    {"property": "PORO"},
    {"property": "PERMX", "filter": "PORO > 0.2", "slice": "i=3:25,k=1:6"},
    {"property": "SWAT", "step": 1, "faults": "highlight", "edges": "quad"},
    {"property": "log10(PERMX)", "faults": "hide"},
])
def test_a_grid_store_draws_the_in_memory_picture(ctx, case, opts):
    mem, lazy = case
    assert not isinstance(lazy.zcorn, np.ndarray)
    with GridView(mem, size=SIZE, ctx=ctx, annotations=False, **opts) as a:
        ia, sa = a.draw(frames=1)
    with GridView(lazy, size=SIZE, ctx=ctx, annotations=False, **opts) as b:
        ib, sb = b.draw(frames=1)
    np.testing.assert_array_equal(ia, ib)
    for key in ("faces", "shown_cells", "color_range", "gpu_bytes", "zcorn_max_error"):
        assert sa[key] == sb[key], key


def test_a_grid_store_switches_property_step_and_filter(ctx, case):
    mem, lazy = case
    with GridView(lazy, property="PORO", size=SIZE, ctx=ctx, annotations=False) as v:
        v.draw(frames=1)
        v.update(property="SWAT", step=0)
        v.update(filter="SWAT > 0.3")
        img, _ = v.draw(frames=1)
    with GridView(mem, property="SWAT", step=0, filter="SWAT > 0.3", size=SIZE, ctx=ctx,
                  annotations=False) as m:
        ref, _ = m.draw(frames=1)
    np.testing.assert_array_equal(img, ref)


@pytest.mark.parametrize("opts,match", [
    ({"approach": 2}, "approach 3 and zcorn_store='faces'"),
    ({"approach": 3, "zcorn_store": "grid"}, "approach 3 and zcorn_store='faces'"),
    ({"plane": "1,0,0,0"}, "cutting plane needs every cell centre"),
])
def test_what_a_grid_store_does_not_draw_is_one_line(ctx, case, opts, match):
    with pytest.raises(InputError, match=match):
        GridView(case[1], property="PORO", size=SIZE, ctx=ctx, **opts)
