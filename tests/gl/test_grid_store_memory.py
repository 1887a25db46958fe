"""A filter that shows many faces of a grid out of core is uploaded batch by batch (corner depths
gathered per batch, records written into the GPU buffer, no per-face columns kept): shrunk
batches here, the picture equals the in-memory one, through highlights and 2^k-cell ranges."""

import numpy as np
import pytest

import geoshade
from geoshade.compute.grid.faces import FaceCount
from geoshade.grid import GridView
from geoshade.grid import sources as grid_sources
from geoshade.io.stores.grid_store import ingest_grid, open_grid_store
from geoshade.render.visuals.grid import layout
from geoshade.render.visuals.grid import visual as grid_visual
from tests.grid_cases import grid_cases as benchmark_cases

SIZE = (160, 120)


@pytest.fixture(scope="module")
def case(tmp_path_factory):
    folder = tmp_path_factory.mktemp("mcase")
    paths = benchmark_cases().write_case(folder, 30, 21, 7, steps=2)
    store = folder / "c.zarr"
    ingest_grid(paths["EGRID"], store, chunks=(8, 8, 3))
    return geoshade.load(paths["EGRID"]), open_grid_store(store)


@pytest.mark.parametrize("opts", [
    {"property": "PORO", "filter": "PORO > 0.15"},
    {"property": "SWAT", "step": 1, "faults": "highlight", "edges": "quad"},
    {"property": "PERMX", "faults": "hide", "slice": "i=2:28"},
])
@pytest.mark.parametrize("bucket_bits", [None, 7])
def test_batched_upload_draws_the_in_memory_picture(ctx, case, monkeypatch, opts,
                                                     bucket_bits):
    mem, lazy = case
    with GridView(mem, size=SIZE, ctx=ctx, annotations=False, **opts) as a:
        ref, sa = a.draw(frames=1)
    monkeypatch.setattr(grid_sources, "LAZY_CORNERS_AHEAD", 0)       # corners per batch
    monkeypatch.setattr(grid_visual, "CORNER_BATCH", 256)
    monkeypatch.setattr(grid_visual, "FACE_BATCH", 64)
    if bucket_bits:
        monkeypatch.setattr(layout, "A3F_BUCKET_BITS", bucket_bits)
    with GridView(lazy, size=SIZE, ctx=ctx, annotations=False, **opts) as b:
        img, sb = b.draw(frames=1)
        assert isinstance(b.faces, FaceCount) and len(b.faces) == sb["faceset_faces"]
        if bucket_bits:
            assert len(b.visual.ranges) > 2
        b.update(property="PORO")  # colours of the kept cell list
        again, _ = b.draw(frames=1)
    np.testing.assert_array_equal(img, ref)
    for key in ("faces", "shown_cells", "faceset_faces", "color_range", "gpu_bytes",
                "zcorn_max_error"):
        assert sa[key] == sb[key], key
    with GridView(mem, size=SIZE, ctx=ctx, annotations=False, **{**opts, "property": "PORO"}
                  ) as c:
        np.testing.assert_array_equal(again, c.draw(frames=1)[0])
