"""Pictures of a core store drawn on a LocalCluster of 2 processes equal the single-process
pictures, lost workers are detected and their bricks redone (gl)."""

from __future__ import annotations

import os
import threading
import time
import warnings

import numpy as np
import pytest

from geoshade.compute.voxels.synthetic import synthetic_core
from geoshade.core import CoreView
from geoshade.render.camera import Camera

distributed = pytest.importorskip("distributed", reason="the distributed extra is not installed")

pytestmark = pytest.mark.gl

SIZE = (128, 128)
SELECT = (0, 12000)
N = 64


@pytest.fixture
def client(cluster_client):
    return cluster_client


@pytest.fixture(scope="module")
def store(tmp_path_factory):
    """A synthetic core written as a zarr store and read back lazily (the workers read it)."""
    from geoshade.io import load
    from geoshade.io.stores.zarr_io import write_zarr

    path = tmp_path_factory.mktemp("dist") / "core.zarr"
    write_zarr(synthetic_core(N, porosity=0.3, seed=2), path, chunks=(32, 32, 32))
    vol = load(path)
    assert vol.is_lazy
    return vol


def _inside_camera(vol):
    """A perspective camera whose eye is inside the box (in a hollowed-out cavity)."""
    c = np.asarray(vol.shape_xyz, float) / 2 + 0.3
    return Camera(target=c, distance=4.0, azimuth=30.0, elevation=20.0, fovy=60.0,
                  radius=float(np.linalg.norm(vol.shape_xyz)) / 2)


def _single(vol, camera, **kw):
    with CoreView(vol, select=SELECT, size=SIZE, **kw) as v:
        return v.draw(camera, frames=1)


def _distributed(vol, client, camera, **kw):

    with CoreView(vol, distributed=True, scheduler=client, select=SELECT, size=SIZE, **kw) as v:
        return v.draw(camera, frames=1)


@pytest.mark.parametrize("camera", ["iso", "top", "front", "ortho", "inside"])
def test_two_workers_draw_the_single_process_picture(ctx, client, store, camera):
    cam = {"ortho": {"view": "iso", "ortho": True, "azimuth": 60},
           "inside": _inside_camera(store)}.get(camera, camera)
    img1, s1 = _single(store, cam)
    img_b, sb = _single(store, cam, bricks=32)     # one process, the same bricks
    img2, s2 = _distributed(store, client, cam)
    assert (img1[..., 3] > 0).mean() > 0.2
    np.testing.assert_array_equal(img2, img_b)
    # inside the box too: the ray caster's proxy is not clipped at the far plane (it was, and
    # the whole box then missed voxels its bricks drew)
    np.testing.assert_array_equal(img2, img1)
    d = s2["distributed"]
    assert s2["brick_mode"] == "distributed" and s2["bricks"] == 8 and s2["brick_side"] == 32
    assert sorted(d["bricks_per_worker"].values()) == [4, 4]     # 8 equal bricks, balanced
    assert s2["voxels_selected"] == s1["voxels_selected"]
    # the counts sum the bricks' own counts, as the single-process bricked View does
    assert s2["voxels_drawn"] == sb["voxels_drawn"]
    # direct-send: the tiles stay on the workers, the client receives one picture
    assert d["compositing"] == "workers"
    assert d["bytes_moved"] == d["client_bytes"] + d["request_bytes"] > 0
    assert d["client_bytes"] == SIZE[0] * SIZE[1] * 8        # RGBA8 + float32 depth
    assert d["tile_bytes"] == d["tile_pixels"] * 10          # RGBA8 + float32 depth + u16 rank
    assert d["slowest_worker"] in d["bricks_per_worker"] and d["composite_ms"] >= 0
    assert d["lost"] == [] and "warning" not in s2


def test_footprints_only_and_a_camera_change_sends_no_data(ctx, client, store):

    with CoreView(store, distributed=True, scheduler=client, select=SELECT, size=SIZE) as v:
        sent = []
        real = v.drawing.renderer._ensure
        v.drawing.renderer._ensure = lambda which: sent.append(which) or real(which)
        _, sa = v.draw("top", frames=1, count=False)
        img_b, sb = v.draw("iso", frames=1, count=False)
        assert sent == []   # a camera change built and sent no bricks
        da, db = sa["distributed"], sb["distributed"]
        # each worker returns its own footprint, not the picture: less than 2 full pictures
        assert da["tile_pixels"] < 2 * SIZE[0] * SIZE[1]
        assert max(da["request_bytes"], db["request_bytes"]) < 4096
        # a new selection rebuilds the scene on the workers, same picture as one process
        v.update(select=(0, 9000))
        img_c, _ = v.draw("iso", frames=1)
    np.testing.assert_array_equal(img_b, _single(store, "iso")[0])
    with CoreView(store, select=(0, 9000), size=SIZE) as one:
        np.testing.assert_array_equal(img_c, one.draw("iso", frames=1)[0])


def test_in_memory_volume_exaggeration_and_annotations(ctx, client):
    vol = synthetic_core(48, porosity=0.25, seed=9)
    kw = {"exaggeration": 2.0, "annotations": True, "size": (256, 200)}
    with CoreView(vol, select=SELECT, **kw) as one:
        img1, s1 = one.draw("iso", frames=1)
    from geoshade.core import render

    img2, s2 = render(vol, "iso", frames=1, distributed=True, scheduler=client, select=SELECT,
                      **kw)
    np.testing.assert_array_equal(img2, img1)     # colour bar, triad and title drawn once
    assert s2["annotations"]["colorbar"] == s1["annotations"]["colorbar"]


def _exit_in_render(worker_module="geoshade.render.distributed.worker"):
    """Run on one worker: its next tile kills the worker process mid-frame."""
    import importlib

    mod = importlib.import_module(worker_module)

    def die(*args, **kwargs):
        os._exit(1)

    mod.render_tile = die


def test_worker_killed_mid_frame_is_reported_and_its_bricks_redone(ctx, client, store):
    from geoshade.render.distributed import WorkerLostWarning

    ref, _ = _single(store, "iso")
    with CoreView(store, distributed=True, scheduler=client, select=SELECT, size=SIZE,
                             worker_timeout=60) as v:
        img0, _ = v.draw("iso", frames=1)
        victim = sorted(v.drawing.renderer.actors)[1]
        survivor = sorted(v.drawing.renderer.actors)[0]
        client.run(_exit_in_render, workers=[victim])
        with pytest.warns(WorkerLostWarning, match=victim.replace(".", r"\.")):
            img1, s1 = v.draw("iso", frames=1, count=False)
        d = s1["distributed"]
        assert d["lost"] == [victim] and d["redone"] == 4
        assert d["bricks_per_worker"] == {survivor: 8}
        assert victim in s1["warning"] and "re-assigned" in s1["warning"]
        # the next frames run on the survivor alone, with no new warning
        with warnings.catch_warnings():
            warnings.simplefilter("error", WorkerLostWarning)
            img2, s2 = v.draw("front", frames=1, count=False)
    np.testing.assert_array_equal(img0, ref)
    np.testing.assert_array_equal(img1, ref)
    np.testing.assert_array_equal(img2, _single(store, "front")[0])
    assert s2["distributed"]["lost"] == []


def test_worker_killed_between_frames(ctx, client, store):
    from geoshade.render.distributed import WorkerLostWarning

    with CoreView(store, distributed=True, scheduler=client, select=SELECT, size=SIZE) as v:
        v.draw("top", frames=1, count=False)
        victim = sorted(v.drawing.renderer.actors)[0]

        def kill():
            try:
                client.run(os._exit, 1, workers=[victim])
            except Exception:  # the worker dies before it answers
                pass

        t = threading.Thread(target=kill, daemon=True)
        t.start()
        t.join(60)
        for _ in range(300):   # until the scheduler has noticed
            if victim not in client.nthreads():
                break
            time.sleep(0.1)
        with pytest.warns(WorkerLostWarning, match="re-assigned"):
            img, s = v.draw("top", frames=1, count=False)
    np.testing.assert_array_equal(img, _single(store, "top")[0])
    assert s["distributed"]["lost"] == [victim] and s["distributed"]["redone"] == 4


def test_no_cluster_or_no_bricks_is_one_line(store):
    from geoshade.errors import InputError

    with pytest.raises(InputError, match=r"needs a dask\.distributed cluster"):
        CoreView(store, distributed=True, select=SELECT, size=SIZE)
    with pytest.raises(InputError, match=r"needs a dask\.distributed cluster"):
        CoreView(store, distributed=True, select=SELECT, size=SIZE, scheduler="threads")
    with pytest.raises(InputError, match="draws the box in bricks"):
        CoreView(store, distributed=True, select=SELECT, size=SIZE, scheduler="local:2",
                 bricks=False)
    # geoshade.view passes distributed=True to the core View (which then wants a cluster)
    import geoshade

    with pytest.raises(InputError, match=r"needs a dask\.distributed cluster"):
        geoshade.view(store, distributed=True, select=SELECT, size=SIZE)


def test_cli_distributed_render_equals_one_process(ctx, client, store, tmp_path, capsys):
    """``geoshade core render STORE --scheduler ADDRESS --distributed`` (the module's cluster by
    address): the same PNG, annotations included, and the per-frame figures in the stats."""
    import json

    from PIL import Image

    from geoshade.cli.main import main

    src = store.meta["source"]
    common = [src, "--select", *map(str, SELECT), "--size", "256x200", "--frames", "1"]
    assert main(["core", "render", *common, "-o", str(tmp_path / "one.png")]) == 0
    assert main(["core", "render", *common, "-o", str(tmp_path / "dist.png"), "--stats",
                 str(tmp_path / "dist.json"), "--scheduler", client.scheduler.address,
                 "--distributed", "--worker-timeout", "60"]) == 0
    out = capsys.readouterr().out
    assert "2 workers" in out and "MiB moved per frame" in out
    one = np.asarray(Image.open(tmp_path / "one.png"))
    dist = np.asarray(Image.open(tmp_path / "dist.png"))
    np.testing.assert_array_equal(dist, one)
    st = json.loads((tmp_path / "dist.json").read_text())
    d = st["distributed"]
    assert {"bytes_moved", "slowest_worker", "slowest_worker_ms", "composite_ms",
            "bricks_per_worker", "lost"} <= set(d)
    assert sum(d["bricks_per_worker"].values()) == st["bricks"]
    # --distributed needs a cluster: one line, exit 2, nothing written
    assert main(["core", "render", *common, "-o", str(tmp_path / "no.png"),
                 "--distributed"]) == 2
    assert "--scheduler" in capsys.readouterr().err
    assert not (tmp_path / "no.png").exists()


def test_viewer_screenshot_distributed(ctx, client, store, tmp_path):
    """``geoshade view STORE --distributed --scheduler ADDRESS --screenshot``: the first frame
    equals the single-process viewer's."""
    pytest.importorskip("PySide6", reason="the desktop viewer needs PySide6 (geoshade[viewer])")
    import subprocess
    import sys

    from PIL import Image

    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY",
                                                            "QT_QPA_PLATFORM")}
    base = [sys.executable, "-m", "geoshade.cli.main", "view", store.meta["source"], "--select",
            *map(str, SELECT), "--size", "200x160"]
    for name, more in (("one.png", []), ("dist.png", ["--distributed", "--scheduler",
                                                      client.scheduler.address])):
        r = subprocess.run([*base, "--screenshot", name, *more], cwd=tmp_path, env=env,
                           capture_output=True, text=True, timeout=300)
        assert r.returncode == 0, r.stderr
    np.testing.assert_array_equal(np.asarray(Image.open(tmp_path / "dist.png")),
                                  np.asarray(Image.open(tmp_path / "one.png")))
