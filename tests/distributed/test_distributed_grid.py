"""A corner-point grid whose faces are computed and drawn on a LocalCluster of 2 processes: the
pictures equal the single-process pictures (several cameras, faults highlighted, filters,
slices, property and step switches), a lost worker's parts are redone (gl)."""

from __future__ import annotations

import itertools
import os
import warnings

import numpy as np
import pytest

from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.grid import GridView

distributed = pytest.importorskip("distributed", reason="the distributed extra is not installed")

pytestmark = pytest.mark.gl

SIZE = (200, 150)
DIMS = (24, 20, 12)
#: cells per k-slab of the drawing order in this module (one layer of the test grid): the
#: default (4 M cells) makes a small grid one slab, hence one part
SLAB = DIMS[0] * DIMS[1]


def _set_slab(n: int) -> int:
    import geoshade.compute.grid.faces as gf

    old = gf.SLAB_CELLS
    gf.SLAB_CELLS = int(n)
    return old


@pytest.fixture
def client(cluster_client):
    """The module's client, with the drawing order's k-slab one layer here and on the workers
    (a restarted worker starts with the default again: set on every test)."""
    cl = cluster_client
    old = _set_slab(SLAB)
    cl.run(_set_slab, SLAB)
    yield cl
    _set_slab(old)


@pytest.fixture(scope="module")
def store(tmp_path_factory):
    """A faulted synthetic grid (inactive cells, report steps) as a grid store, read lazily."""
    from geoshade.io.stores.grid_store import ModelSource, open_grid_store, write_grid_store

    path = tmp_path_factory.mktemp("dgrid") / "grid.zarr"
    write_grid_store(ModelSource(synthetic_grid(*DIMS, seed=4, steps=3)), path,
                     chunks=(8, 8, 5))   # chunk layers cut the parts' layer ranges
    return open_grid_store(path)


def _single(grid, camera, count: bool = True, **kw):
    """One process's picture; ``count=False``: a plain frame (back faces culled, which may
    differ from the counting frame at a few silhouette pixels), as the distributed frame."""
    with GridView(grid, size=SIZE, **kw) as v:
        return v.draw(camera, frames=1, count=count)


def _distributed(grid, client, camera, **kw):

    with GridView(grid, distributed=True, scheduler=client, size=SIZE, **kw) as v:
        return v.draw(camera, frames=1)


CAMERAS = {"iso": "iso", "top": "top", "front-ortho": {"view": "front", "ortho": True},
           "close": {"view": "iso", "azimuth": 200, "elevation": 15, "zoom": 3.0}}
STYLES = {
    "plain": {"property": "PORO"},
    "faults": {"property": "PERMX", "faults": "highlight", "edges": True, "exaggeration": 5},
    "filter-slice": {"property": "PORO", "filter": "PORO > 0.15", "slice": "i=2:20,k=1:11",
                     "edges": True, "exaggeration": 4},
}


@pytest.mark.parametrize("style", sorted(STYLES))
@pytest.mark.parametrize("camera", sorted(CAMERAS))
def test_two_workers_draw_the_single_process_picture(ctx, client, store, camera, style):
    kw = STYLES[style]
    ref, s0 = _single(store, CAMERAS[camera], **kw)
    img, s1 = _distributed(store, client, CAMERAS[camera], **kw)
    np.testing.assert_array_equal(img, ref)
    for k in ("faces", "faces_drawn", "shown_cells", "faceset_faces", "color_range"):
        assert s1[k] == s0[k], k
    d = s1["distributed"]
    assert d["workers"] == 2 and d["lost"] == []
    assert sorted(map(tuple, d["parts"])) == [(0, 3), (3, 6), (6, 9), (9, 12)]
    assert sorted(d["bricks_per_worker"].values()) == [2, 2]
    assert s1["gpu_bytes"] == sum(s1["distributed"]["worker_gpu_bytes"].values()) > 0


def test_switches_send_a_camera_or_a_colour_scale(ctx, client, store):
    """Property, step, difference, colour, filter, slice, fault mode, edges and exaggeration
    changes equal a single-process View after the same changes; a camera change moves no grid
    data, a property switch recolours the workers' faces without computing them again."""

    with GridView(store, size=SIZE, property="PORO") as one, \
            GridView(store, distributed=True, scheduler=client, size=SIZE, property="PORO") as dist:
        built = {p: i["faces_ms"] for p, i in dist.drawing.renderer.scene.counts.items()}
        for changes in ({}, {"property": "SWAT", "step": 1}, {"step": 2}, {"diff": 0},
                        {"diff": None}, {"color": "magma_r"}, {"property": "PERMX"},
                        {"filter": "PERMX > 50", "faults": "highlight"},
                        {"slice": "j=3:17", "edges": True}, {"exaggeration": 6.0},
                        {"zcorn_bits": 32}):
            one.update(**changes)
            dist.update(**changes)
            for cam in ("iso", {"view": "right", "ortho": True}):
                a, sa = one.draw(cam, frames=1)
                b, sb = dist.draw(cam, frames=1)
                np.testing.assert_array_equal(b, a, err_msg=str(changes))
                assert sb["faces"] == sa["faces"] and sb["color_range"] == sa["color_range"]
            if changes == {"step": 2}:   # a colour switch: the faces were not recomputed
                now = {p: i["faces_ms"] for p, i in dist.drawing.renderer.scene.counts.items()}
                assert now == built
            # a frame sends a camera and the parts' ranks: a few hundred bytes per worker
            assert sb["distributed"]["request_bytes"] < 4000


def test_in_memory_grid_and_geoshade_view(ctx, client):
    """An in-memory grid travels to the workers whole; ``geoshade.view(..., distributed=True)``
    picks the distributed grid View."""
    import geoshade

    g = synthetic_grid(*DIMS, seed=9, steps=1)
    ref, _ = _single(g, "iso", property="PERMX", faults="highlight")
    with geoshade.view(g, distributed=True, scheduler=client, size=SIZE, property="PERMX",
                       faults="highlight") as v:
        assert isinstance(v, GridView) and v.drawing.name == "cluster"
        img, st = v.draw("iso", frames=1)
        # later changes send the workers no grid: they keep the one of the first load
        assert v.drawing._spec(v.options, [0]).grid is None
        v.update(property="PORO", filter="PORO > 0.2")
        img2, _ = v.draw("iso", frames=1)
    np.testing.assert_array_equal(img, ref)
    assert st["method"] == "approach 3 (faces), distributed"
    ref2, _ = _single(g, "iso", property="PORO", faults="highlight", filter="PORO > 0.2")
    np.testing.assert_array_equal(img2, ref2)


def _exit_in_render():
    import geoshade.render.distributed.worker as mod

    def die(*args, **kwargs):
        os._exit(1)

    mod.render_tile = die


def test_worker_killed_mid_frame_is_reported_and_its_parts_redone(ctx, client, store):
    from geoshade.render.distributed import WorkerLostWarning

    kw = {"property": "PORO", "faults": "highlight"}
    ref, _ = _single(store, "iso", count=False, **kw)
    with GridView(store, distributed=True, scheduler=client, size=SIZE, worker_timeout=60,
                  **kw) as v:
        survivor, victim = sorted(v.drawing.renderer.actors)[:2]
        client.run(_exit_in_render, workers=[victim])
        with pytest.warns(WorkerLostWarning, match=victim.replace(".", r"\.")):
            img1, s1 = v.draw("iso", frames=1, count=False)
        d = s1["distributed"]
        assert d["lost"] == [victim] and d["redone"] == 2
        assert d["bricks_per_worker"] == {survivor: 4}
        with warnings.catch_warnings():
            warnings.simplefilter("error", WorkerLostWarning)
            img2, _ = v.draw("top", frames=1, count=False)
    np.testing.assert_array_equal(img1, ref)
    np.testing.assert_array_equal(img2, _single(store, "top", count=False, **kw)[0])


def test_cli_distributed_grid_render_equals_one_process(ctx, client, store, tmp_path, capsys):
    """``geoshade grid render STORE --distributed --scheduler ADDRESS``: the same PNG,
    annotations included; ``--parts`` without ``--distributed`` is one line."""
    import json

    from PIL import Image

    from geoshade.cli.main import main

    common = [store.meta["store"], "--property", "PORO", "--faults", "highlight", "--size",
              "240x180", "--frames", "1"]
    assert main(["grid", "render", *common, "-o", str(tmp_path / "one.png")]) == 0
    assert main(["grid", "render", *common, "-o", str(tmp_path / "dist.png"), "--stats",
                 str(tmp_path / "dist.json"), "--distributed", "--scheduler",
                 client.scheduler.address, "--parts", "3"]) == 0
    assert "2 workers" in capsys.readouterr().out
    one = np.asarray(Image.open(tmp_path / "one.png"))
    np.testing.assert_array_equal(np.asarray(Image.open(tmp_path / "dist.png")), one)
    d = json.loads((tmp_path / "dist.json").read_text())["distributed"]
    assert len(d["parts"]) == 3 and d["lost"] == []
    assert main(["grid", "render", *common, "-o", str(tmp_path / "no.png"), "--parts",
                 "3"]) == 2
    assert "--parts: applies to --distributed" in capsys.readouterr().err
    assert not (tmp_path / "no.png").exists()


def test_what_a_cluster_does_not_draw_is_one_line(store):
    from geoshade.errors import InputError

    with pytest.raises(InputError, match=r"needs a dask\.distributed cluster"):
        GridView(store, distributed=True, property="PORO")
    with pytest.raises(InputError, match="approach 3"):
        GridView(store, distributed=True, scheduler="tcp://127.0.0.1:9", approach=2)
    with pytest.raises(InputError, match="cutting plane"):
        GridView(store, distributed=True, scheduler="tcp://127.0.0.1:9", plane="1,0,0")
    with pytest.raises(InputError, match="parts"):
        GridView(store, distributed=True, scheduler="tcp://127.0.0.1:9", parts=0)


def test_plan_parts_whole_slabs_and_chunk_layers():
    from geoshade.compute.grid.faces import drawing_slab
    from geoshade.grid.distributed import plan_parts

    for dims, n, ck in (((1000, 1000, 100), 8, None), ((2000, 2000, 250), 4, 50),
                        ((300, 300, 90), 5, 16), ((4000, 4000, 7), 16, 3)):
        parts = plan_parts(dims, n, ck)
        slab = drawing_slab(dims)
        assert parts[0][0] == 0 and parts[-1][1] == dims[2]
        assert all(a[1] == b[0] for a, b in itertools.pairwise(parts))
        assert 1 <= len(parts) <= n
        assert all(k0 % slab == 0 for k0, _ in parts)
        sizes = [k1 - k0 for k0, k1 in parts]
        assert max(sizes) - min(sizes) <= 2 * slab * (ck or 1)


def test_viewer_screenshot_distributed_grid(ctx, client, store, tmp_path):
    """``geoshade view STORE --distributed --scheduler ADDRESS --screenshot``: the first frame
    equals the single-process viewer's (the viewer processes use the default drawing slab, so
    the workers do too here)."""
    pytest.importorskip("PySide6", reason="the desktop viewer needs PySide6 (geoshade[viewer])")
    import subprocess
    import sys

    from PIL import Image

    client.run(_set_slab, 1 << 22)
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY",
                                                            "QT_QPA_PLATFORM")}
    base = [sys.executable, "-m", "geoshade.cli.main", "view", store.meta["store"],
            "--property", "PORO", "--size", "200x160"]
    for name, more in (("one.png", []), ("dist.png", ["--distributed", "--scheduler",
                                                      client.scheduler.address])):
        r = subprocess.run([*base, "--screenshot", name, *more], cwd=tmp_path, env=env,
                           capture_output=True, text=True, timeout=300)
        assert r.returncode == 0, r.stderr
    one = np.asarray(Image.open(tmp_path / "one.png"))
    np.testing.assert_array_equal(np.asarray(Image.open(tmp_path / "dist.png")), one)
    assert len(np.unique(one.reshape(-1, one.shape[-1]), axis=0)) > 50   # a grid, not a blank


def test_fewer_parts_than_asked_is_said_once(ctx, client, store):
    """A grid has as many parts as it has k-slabs at most (12 here): asking for more draws in
    12, said once as a warning and in every frame's notes."""

    with GridView(store, distributed=True, scheduler=client, size=SIZE, property="PORO",
                             parts=20) as v:
        with pytest.warns(UserWarning, match=r"drawn in 12 part\(s\), not 20"):
            _, s1 = v.draw("iso", frames=1)
        with warnings.catch_warnings():
            warnings.simplefilter("error", UserWarning)
            _, s2 = v.draw("top", frames=1)
    assert len(s1["distributed"]["parts"]) == 12
    assert any("not 20" in n for n in s2["notes"])
