"""The cluster drawings (ClusterFaces, ClusterBricks) answer the same calls as the
single-process ones (tests/gl/test_backends.py) and draw the same pictures on a LocalCluster of
2 processes (gl)."""

from __future__ import annotations

import numpy as np
import pytest

from geoshade.compute.voxels.synthetic import synthetic_core
from geoshade.core import CoreView
from geoshade.grid import GridView
from tests.gl.test_backends import SIZE, drive_bricks, drive_faces

pytest.importorskip("distributed", reason="the distributed extra is not installed")

pytestmark = pytest.mark.gl


def test_cluster_faces_answer_the_same_calls(ctx, cluster_client, tmp_path):
    from geoshade.compute.grid.synthetic import synthetic_grid
    from geoshade.io.stores.grid_store import ModelSource, open_grid_store, write_grid_store

    grid = synthetic_grid(16, 12, 6, seed=4, steps=2)
    write_grid_store(ModelSource(grid), tmp_path / "g.zarr", chunks=(8, 8, 3))
    store = open_grid_store(tmp_path / "g.zarr")
    with GridView(store, ctx=ctx, size=SIZE, property="PORO", annotations=False) as one:
        ref = drive_faces(one)
    with GridView(store, ctx=ctx, size=SIZE, property="PORO", annotations=False,
                  distributed=True, scheduler=cluster_client) as v:
        assert v.drawing.name == "cluster" and v.visual is None
        got = drive_faces(v)
        assert v.work.starts == 0   # a client given: the View neither starts nor closes it
    assert cluster_client.status == "running"
    for i, (x, y) in enumerate(zip(ref, got, strict=True)):
        np.testing.assert_array_equal(x, y, err_msg=f"picture {i}")


def test_cluster_bricks_answer_the_same_calls(ctx, cluster_client):
    vol = synthetic_core(64, porosity=0.3, seed=5)
    kw = {"ctx": ctx, "size": SIZE, "select": (0, 15000), "method": "raycast",
          "annotations": False, "bricks": 32}
    with CoreView(vol, **kw) as one:
        ref = drive_bricks(one)
    with CoreView(vol, distributed=True, scheduler=cluster_client, **kw) as v:
        assert v.drawing.name == "cluster" and v.visual is None
        got = drive_bricks(v)
    for i, (x, y) in enumerate(zip(ref, got, strict=True)):
        np.testing.assert_array_equal(x, y, err_msg=f"picture {i}")
