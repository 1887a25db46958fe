"""The cluster of the distributed rendering tests: one LocalCluster of 2 worker processes
(1 thread each) per test module (start-up is slow; a module may kill workers)."""

from __future__ import annotations

import pytest


@pytest.fixture(scope="module")
def cluster():
    distributed = pytest.importorskip("distributed",
                                      reason="the distributed extra is not installed")
    c = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                 dashboard_address=None, silence_logs=50)
    client = distributed.Client(c, set_as_default=False)
    yield c, client
    client.close()
    c.close()


@pytest.fixture
def cluster_client(cluster):
    """The module's client once both workers are up (a killed worker is restarted by its
    nanny)."""
    _, cl = cluster
    cl.wait_for_workers(2, timeout=60)
    return cl
