"""geoshade.scheduler: local schedulers by name, clients, addresses and ``local:N`` clusters."""

from __future__ import annotations

import time

import numpy as np
import pytest

from geoshade import scheduler
from geoshade.errors import InputError


def test_local_names_and_none_pass_through():
    with scheduler.using_scheduler() as s:
        assert s == "threads"
    for name in scheduler.LOCAL_SCHEDULERS:
        with scheduler.using_scheduler(name) as s:
            assert s == name


@pytest.mark.parametrize("bad", ["threads", None, "local:0", "local:x", "local:"])
def test_client_for_refuses_what_is_not_a_cluster(bad):
    with pytest.raises(InputError) as err:
        scheduler.client_for(bad)
    assert "\n" not in str(err.value) and str(err.value).startswith("scheduler ")


def test_unreachable_address_is_one_line(monkeypatch):
    monkeypatch.setattr(scheduler, "CONNECT_TIMEOUT_S", 1)
    t0 = time.perf_counter()
    with pytest.raises(InputError) as err:
        scheduler.client_for("tcp://127.0.0.1:9")
    msg = str(err.value)
    assert "\n" not in msg and "tcp://127.0.0.1:9: unreachable" in msg
    assert time.perf_counter() - t0 < 30


def test_local_cluster_started_used_and_shut_down():
    da = pytest.importorskip("dask.array")
    from geoshade.compute.porosity import porosity

    with scheduler.using_scheduler("local:1", processes=False) as client:
        assert len(client.scheduler_info()["workers"]) == 1
        cluster = client.cluster
        r = porosity(np.ones((4, 4, 4), np.uint8), 1, 1, scheduler=client)
        assert r.porosity == 1.0
        assert float(da.ones(10, chunks=5).sum().compute(scheduler=client)) == 10.0
        # a client given is used as is and not closed
        assert scheduler.client_for(client) == (client, False)
        with scheduler.using_scheduler(client) as same:
            assert same is client
        assert client.status == "running"
    assert client.status == "closed" and cluster.status.name == "closed"


def test_ingest_on_a_local_cluster_equals_inline(tmp_path):
    """io.ingest's slab runner takes the same schedulers (one client code for io and compute)."""
    from geoshade.io import load
    from geoshade.io.stores.ingest import ingest

    a = np.random.default_rng(3).integers(0, 60000, (9, 7, 11)).astype(np.uint16)
    src = tmp_path / "v.npy"
    np.save(src, a)
    calls = []
    with scheduler.using_scheduler("local:1", processes=False) as client:
        rep = ingest(src, tmp_path / "c.zarr", chunks=(4, 7, 11), levels=2, scheduler=client,
                     progress=lambda d, t: calls.append((d, t)))
        assert client.status == "running"  # a client given is not closed by ingest
    assert rep.slabs_written == 3 + 2 and calls[-1] == (5, 5)  # z slabs of levels 0 and 1
    np.testing.assert_array_equal(load(tmp_path / "c.zarr").read_box(), a)
