"""Compositing off the client (issue 26, direct-send): on a LocalCluster of 2 processes the
workers composite bands of the picture among themselves and the client receives one picture per
frame; the picture equals client-side compositing and the single process, pixel for pixel (gl).
"""

from __future__ import annotations

import numpy as np
import pytest

from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.compute.voxels.synthetic import synthetic_core
from geoshade.core import CoreView
from geoshade.grid import GridView

distributed = pytest.importorskip("distributed", reason="the distributed extra is not installed")

pytestmark = pytest.mark.gl

SIZE = (160, 120)
PICTURE_BYTES = SIZE[0] * SIZE[1] * 8   # RGBA8 + float32 depth: what the client needs


@pytest.fixture(scope="module")
def core_store(tmp_path_factory):
    from geoshade.io import load
    from geoshade.io.stores.zarr_io import write_zarr

    path = tmp_path_factory.mktemp("ds") / "core.zarr"
    write_zarr(synthetic_core(48, porosity=0.3, seed=5), path, chunks=(24, 24, 24))
    return load(path)


def _renderer(view):
    return view.drawing.renderer


def _both(view, camera):
    """The View's picture with worker-side and with client-side compositing."""
    r = _renderer(view)
    r.compositing = "workers"
    a, sa = view.draw(camera, frames=1, count=False)
    r.compositing = "client"
    b, sb = view.draw(camera, frames=1, count=False)
    r.compositing = "workers"
    return a, sa["distributed"], b, sb["distributed"]


@pytest.mark.parametrize("camera", ["iso", "top", {"view": "front", "ortho": True}])
def test_core_bands_composited_on_workers_equal_the_client_composite(ctx, cluster_client,
                                                                     core_store, camera):
    with CoreView(core_store, select=(0, 12000), size=SIZE, bricks=24) as one:
        ref, _ = one.draw(camera, frames=1, count=False)
    with CoreView(core_store, distributed=True, scheduler=cluster_client, select=(0, 12000),
                  size=SIZE) as v:
        a, da, b, db = _both(v, camera)
    assert (ref[..., 3] > 0).mean() > 0.1
    np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(a, ref)
    assert da["compositing"] == "workers" and db["compositing"] == "client"
    # the client receives one picture whatever the workers; the tiles travelled between workers
    assert da["client_bytes"] <= 1.1 * PICTURE_BYTES
    assert db["client_bytes"] == db["tile_bytes"] > 0
    assert da["peer_bytes"] > 0 and da["workers"] == 2


@pytest.fixture
def slab_client(cluster_client):
    """One layer per k-slab of the drawing order on client and workers (several parts)."""
    import geoshade.compute.grid.faces as gf

    def set_slab(n):
        old = gf.SLAB_CELLS
        gf.SLAB_CELLS = int(n)
        return old

    old = set_slab(16 * 12)
    cluster_client.run(set_slab, 16 * 12)
    yield cluster_client
    set_slab(old)


@pytest.mark.parametrize("style", [{"property": "PORO"},
                                   {"property": "PERMX", "faults": "highlight", "edges": True,
                                    "exaggeration": 4, "filter": "PORO > 0.12"}])
def test_grid_bands_composited_on_workers_equal_one_process(ctx, slab_client, style):
    grid = synthetic_grid(16, 12, 8, seed=3)
    with GridView(grid, size=SIZE, **style) as one:
        ref, _ = one.draw("iso", frames=1, count=False)
    with GridView(grid, distributed=True, scheduler=slab_client, size=SIZE, **style) as v:
        a, da, b, db = _both(v, "iso")
        bytes_workers = [v.draw(c, frames=1, count=False)[1]["distributed"]["client_bytes"]
                         for c in ("top", "front")]
    np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(a, ref)
    assert da["client_bytes"] <= 1.1 * PICTURE_BYTES
    assert all(x <= 1.1 * PICTURE_BYTES for x in bytes_workers)
    assert db["client_bytes"] > da["client_bytes"] * 0.5   # tiles: ~10 B per covered pixel


def test_unknown_compositing_is_one_line():
    from geoshade.errors import GeoshadeError
    from geoshade.render.distributed.client import DistributedRenderer

    with pytest.raises(GeoshadeError, match="compositing 'gpu': expected one of workers, client"):
        DistributedRenderer.__init__(object.__new__(DistributedRenderer), None,
                                     compositing="gpu")
