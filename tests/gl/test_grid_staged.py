"""A filter or slice of a grid store is made a layer of chunks at a time and built straight into
GPU records (issue 34, item 2: the faces' columns of one layer held, not of all): the picture
equals the in-memory one pixel for pixel, with the faces drawn in their order (few runs) or
sorted by key (many runs of highlights and 2^k-cell ranges), and the layers' records are freed
once uploaded."""

import numpy as np
import pytest

import geoshade
from geoshade.compute.grid import faces as faces_mod
from geoshade.compute.grid.faces import FaceSet
from geoshade.compute.grid.index_faces import store_index
from geoshade.grid import GridView
from geoshade.io.stores.grid_store import ingest_grid, open_grid_store
from geoshade.render.visuals.grid import layout
from geoshade.render.visuals.grid import visual as grid_visual
from tests.grid_cases import grid_cases as benchmark_cases

SIZE = (160, 120)


@pytest.fixture(scope="module")
def case(tmp_path_factory):
    folder = tmp_path_factory.mktemp("staged")
    paths = benchmark_cases().write_case(folder, 30, 21, 9, steps=2)
    store = folder / "c.zarr"
    ingest_grid(paths["EGRID"], store, chunks=(8, 8, 2), index=store_index)   # 5 layers
    return geoshade.load(paths["EGRID"]), open_grid_store(store)


@pytest.mark.parametrize("opts", [
    {"property": "PORO", "filter": "PORO > 0.15"},
    {"property": "SWAT", "step": 1, "filter": "SWAT > 0.45", "faults": "highlight"},
    {"property": "SWAT", "step": 1, "filter": "SWAT > 0.2", "faults": "highlight"},  # every cell
    {"property": "PERMX", "faults": "hide", "slice": "i=2:28,k=1:8"},
])
@pytest.mark.parametrize("runs", [1, 1024])   # 1: every range sorted by key
def test_staged_layers_draw_the_in_memory_picture(ctx, case, monkeypatch, opts, runs):
    mem, lazy = case
    monkeypatch.setattr(grid_visual, "MAX_DRAW_RUNS", runs)
    monkeypatch.setattr(layout, "A3F_BUCKET_BITS", 9)   # ranges of 512 cells
    monkeypatch.setattr(faces_mod, "SLAB_CELLS", 2 * 30 * 21)   # k-slabs of 2: 5 layers
    with GridView(mem, size=SIZE, ctx=ctx, annotations=False, **opts) as a:
        ref, sa = a.draw(frames=1)
    def no_whole_sort(self):   # the layers come in order: never the fallback's whole sort
        raise AssertionError("the staged faces were sorted whole")

    monkeypatch.setattr(FaceSet, "drawing_order", no_whole_sort)
    with GridView(lazy, size=SIZE, ctx=ctx, annotations=False, **opts) as b:
        img, sb = b.draw(frames=1)
        assert sb["faces_from"] == "index"
        # a filter every active cell passes draws the index's own faces (no chunk computed)
        assert sb.get("staged", False) is (sb["chunks_computed"] > 0)
        assert len(b.visual.ranges) > 2
        # in their order: a GPU buffer a layer, the ranges drawn across them
        assert (len(b.visual._parts) > 1) is (bool(sb.get("staged")) and runs > 1)
        b.update(property="PORO")  # colours of the kept cell list
        again, _ = b.draw(frames=1)
        b.update(filter="PORO > 0.25")   # a live change takes the same path
        live, _ = b.draw(frames=1)
    np.testing.assert_array_equal(img, ref)
    for key in ("faces", "shown_cells", "faceset_faces", "color_range", "gpu_bytes",
                "zcorn_max_error"):
        assert sa[key] == sb[key], key
    with GridView(mem, size=SIZE, ctx=ctx, annotations=False, **{**opts, "property": "PORO"}
                  ) as c:
        np.testing.assert_array_equal(again, c.draw(frames=1)[0])
        c.update(filter="PORO > 0.25")
        np.testing.assert_array_equal(live, c.draw(frames=1)[0])


def test_staged_blocks_are_freed_as_they_are_uploaded(ctx, case, monkeypatch):
    _, lazy = case
    monkeypatch.setattr(faces_mod, "SLAB_CELLS", 2 * 30 * 21)   # k-slabs of 2: 5 layers
    with GridView(lazy, size=SIZE, ctx=ctx, annotations=False, property="PORO") as v:
        prepared = v.prepare_faces(filter="PORO > 0.1")
        staged = prepared.staged
        assert staged is not None and staged.n == prepared.faces.n and staged.blocks
        assert staged.nbytes >= staged.n * (4 * staged.words + 1)
        assert staged.cell_list() is not None   # layers top down: no sort of every face
        sizes = [b[0].shape[0] for b in staged.blocks]
        v.apply_faces(prepared)
        assert prepared.staged is None and not staged.blocks
        assert v.draw(frames=1)[1]["faces"] == staged.n
        # each layer's records are their own GPU buffer, made with them (no whole buffer
        # reserved beside the staged blocks); counted under one name as the plan says
        vis = v.visual
        assert len(sizes) > 1 and [p[1] for p in vis._parts] == sizes
        assert [p[0] for p in vis._parts] == np.concatenate([[0], np.cumsum(sizes)[:-1]]).tolist()
        assert vis.cache.breakdown() == vis.plan()
        assert set(vis.geometry_objects()) >= {p[2] for p in vis._parts}
        v.update(filter=None)   # the blocks' buffers go with their faces
        assert vis._parts == [] and not any("@" in k for k in vis.cache._objects)
