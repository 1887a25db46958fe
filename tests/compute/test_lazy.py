"""The dask paths of the core: porosity with a scheduler (the same block function as the slab
loop) and the out-of-core selection maps, equal to numpy and to the in-memory path bit for bit,
on local threads and on a dask.distributed cluster, with memory bounded by the chunks."""

from __future__ import annotations

import os
import time

import dask.array as da
import numpy as np
import pytest

from geoshade import scheduler
from geoshade.compute.voxels import lazy
from geoshade.compute.voxels.bitmaps import build_selection_maps
from geoshade.compute.voxels.porosity import porosity
from geoshade.errors import InputError
from geoshade.models import VoxelVolume

MAP_FIELDS = ("bits", "patch_bits", "patch_shape", "bricks", "color", "count", "shape_xyz")


def _data(dtype, shape=(37, 45, 70), seed=0):
    rng = np.random.default_rng(seed)
    a = (rng.random(shape) * 1000).astype(dtype) if np.dtype(dtype).kind == "f" else \
        rng.integers(np.iinfo(dtype).min, np.iinfo(dtype).max, shape, endpoint=True).astype(dtype)
    if np.dtype(dtype).kind == "f":
        a[1, 2, 3] = np.nan
        a[4, 5, 6] = np.inf
    return a


RANGES = {np.uint8: (40, 130), np.uint16: (1000, 30000), np.int16: (-5000, 7000),
          np.float32: (100.5, 640.25)}


def _same_porosity(r1, r2):
    assert r1.porosity == r2.porosity and r1.count == r2.count and r1.total == r2.total
    assert np.array_equal(r1.profile, r2.profile) and np.array_equal(r1.counts, r2.counts)
    assert np.array_equal(r1.positions, r2.positions) and r1.box == r2.box
    assert (r1.spacing, r1.origin, r1.unit, r1.range) == (r2.spacing, r2.origin, r2.unit, r2.range)


def _numpy_counts(a, lo, hi, box, axis):
    """The oracle: per-slice selected counts by numpy on the whole array."""
    x0, y0, z0, nx, ny, nz = box or [0, 0, 0, a.shape[2], a.shape[1], a.shape[0]]
    sub = a[z0:z0 + nz, y0:y0 + ny, x0:x0 + nx]
    sel = (sub >= lo) & (sub <= hi)
    return sel.sum(axis={"x": (0, 1), "y": (0, 2), "z": (1, 2)}[axis])


def _same_maps(m1, m2):
    for f in MAP_FIELDS:
        v1, v2 = getattr(m1, f), getattr(m2, f)
        if isinstance(v1, np.ndarray):
            assert v1.dtype == v2.dtype and np.array_equal(v1, v2), f
        else:
            assert v1 == v2, f


@pytest.mark.parametrize("dtype", list(RANGES))
def test_porosity_every_axis_bit_for_bit(dtype):
    a = _data(dtype)
    vol = VoxelVolume(da.from_array(a, chunks=(8, 16, 32)), spacing=(0.5, 1, 2), unit="um",
                      origin=(1, 2, 3))
    ref_vol = VoxelVolume(a, spacing=(0.5, 1, 2), unit="um", origin=(1, 2, 3))
    lo, hi = RANGES[dtype]
    for box in (None, [3, 5, 7, 61, 33, 25]):
        for axis in "xyz":
            ref = porosity(ref_vol, lo, hi, box=box, axis=axis)  # the slab loop
            np.testing.assert_array_equal(ref.counts, _numpy_counts(a, lo, hi, box, axis))
            for sched in ("threads", "synchronous"):  # dask tasks, the same block function
                _same_porosity(porosity(vol, lo, hi, box=box, axis=axis, scheduler=sched), ref)


@pytest.mark.parametrize("dtype", list(RANGES))
def test_selection_maps_bit_for_bit(dtype):
    a = _data(dtype, seed=1)
    d = da.from_array(a, chunks=(5, 20, 33))
    lo, hi = RANGES[dtype]
    box = [2, 3, 1, 66, 40, 33]
    for l, brick, slab in ((64, 8, 10_000), (7, 4, 64 << 20), (3, 3, 5_000)):
        ref = build_selection_maps(a, box, lo, hi, l=l, brick=brick, slab_bytes=slab)
        got = lazy.selection_maps(d, box, lo, hi, l=l, brick=brick, slab_bytes=slab)
        _same_maps(got, ref)
    clo, chi = (lo - 10, hi + 10)
    ref = build_selection_maps(a, box, lo, hi, clo, chi)
    _same_maps(lazy.selection_maps(d, box, lo, hi, clo, chi, scheduler="synchronous"), ref)


def test_memmap_and_zarr_sources(tmp_path):
    import zarr

    a = _data(np.uint16, (20, 30, 40), seed=4)
    f = tmp_path / "v.raw"
    a.tofile(f)
    mm = np.memmap(f, np.uint16, "r", shape=a.shape)
    x = lazy.as_dask(mm)
    assert x.name.startswith("memmap-")  # a picklable file view, not the mapped values
    z = zarr.open_array(str(tmp_path / "v.zarr"), mode="w", shape=a.shape, chunks=(7, 30, 40),
                        dtype=a.dtype)
    z[:] = a
    ref = porosity(a, 100, 40000, axis="y")
    for src in (mm, z):
        _same_porosity(porosity(src, 100, 40000, axis="y", scheduler="threads"), ref)


def test_progress_is_reported():
    seen = []
    porosity(da.ones((8, 8, 8), chunks=4, dtype=np.uint8), 1, 1, scheduler="threads",
             progress=lambda d, t: seen.append((d, t)))
    assert seen and seen[-1][0] == seen[-1][1] and all(d <= t for d, t in seen)


def test_unreachable_scheduler_is_one_line(monkeypatch):
    monkeypatch.setattr(scheduler, "CONNECT_TIMEOUT_S", 1)
    t0 = time.perf_counter()
    with pytest.raises(InputError) as err:
        porosity(np.zeros((2, 2, 2), np.uint8), 0, 0, scheduler="tcp://127.0.0.1:9")
    msg = str(err.value)
    assert "\n" not in msg and "tcp://127.0.0.1:9: unreachable" in msg and "--scheduler" in msg
    assert time.perf_counter() - t0 < 30


def test_ramp_oracle():
    v = lazy.ramp_volume((300, 7, 11), chunks=(4, 7, 128))
    a = v.compute()
    assert a.dtype == np.uint8 and a[3, 2, 1] == (1 + 2 * 2 + 3 * 3) % 256
    for lo, hi in ((0, 99), (17, 200), (255, 255)):
        assert lazy.ramp_count((300, 7, 11), lo, hi) == int(((a >= lo) & (a <= hi)).sum())
    assert lazy.ramp_volume((3, 3, 3), chunks=(3, 3, 3), dtype="uint16").compute().dtype == \
        np.uint16


# --------------------------------------------------------------------------------------------
# a real cluster: worker processes with a memory limit each
# --------------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def cluster():
    pytest.importorskip("distributed", reason="the distributed extra is not installed")
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, memory_limit="512MB",
                      dashboard_address=None, silence_logs=40) as c, Client(c) as client:
        yield client


def test_same_results_on_a_cluster(cluster, tmp_path):
    a = _data(np.uint16, (30, 40, 50), seed=5)
    f = tmp_path / "c.raw"
    a.tofile(f)
    mm = np.memmap(f, np.uint16, "r", shape=a.shape)  # tasks re-map the file on the workers
    box = [1, 2, 3, 45, 33, 20]
    _same_porosity(porosity(mm, 2000, 50000, box=box, axis="x", scheduler=cluster),
                   porosity(a, 2000, 50000, box=box, axis="x"))
    _same_maps(lazy.selection_maps(mm, box, 2000, 50000, scheduler=cluster),
               build_selection_maps(a, box, 2000, 50000))
    addr = cluster.scheduler.address
    _same_porosity(porosity(mm, 2000, 50000, scheduler=addr), porosity(a, 2000, 50000))


def test_volume_three_times_the_cluster_memory(cluster):
    """3 GiB, generated chunk by chunk, through 2 workers of 512 MB: exact, no worker lost."""
    from distributed.diagnostics import MemorySampler

    shape = (1024, 1024, 3072)  # x, y, z: 3 GiB of uint8 in 64 MiB chunks
    v = lazy.ramp_volume(shape, chunks=(64, 1024, 1024))
    assert v.nbytes >= 3 * 2 * 512e6
    pids = cluster.run(os.getpid)
    ms = MemorySampler()
    with ms.sample("porosity", interval=0.2):
        r = porosity(v, 0, 99, axis="z", scheduler=cluster)
    assert r.count == lazy.ramp_count(shape, 0, 99) and r.porosity == 400 / 1024
    assert np.all(r.profile == 400 / 1024)
    assert cluster.run(os.getpid) == pids  # the same two worker processes: none was killed
    peak = float(ms.to_pandas()["porosity"].max())
    assert 0 < peak < 2 * 512e6  # both workers together stayed under their limits
