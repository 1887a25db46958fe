"""Hostile neighbours (issue 25, class 2): clusters are trusted or not used.

``local:N`` talks TLS with throw-away certificates and serves no HTTP pages, so another local
process can neither submit code nor read worker pages; N is bounded by the cores; an address is
``tls://`` with dask's certificates or a warned plain ``tcp://`` beyond this machine; a cluster
without workers is one line after a time-out instead of a wait forever.
"""

from __future__ import annotations

import os
import urllib.error
import urllib.request
import warnings

import pytest

from geoshade import scheduler
from geoshade.errors import InputError
from tests.hostile import RESULTS, record, run, summary

CLUSTER = "2 cluster trust"
distributed = pytest.importorskip("distributed")


def _attack(address: str, marker) -> str:
    """What a local process without the certificates gets: '' when it could not run code."""
    def plant():
        open(marker, "w").close()  # the marker an attacker would leave

    for addr in (address, address.replace("tls://", "tcp://")):
        try:
            c = distributed.Client(addr, timeout="3s", set_as_default=False)
        except Exception:  # refused: no certificate, or not TLS
            continue
        try:
            c.submit(plant).result(timeout=5)
        finally:
            c.close()
        return f"{addr} accepted a client without certificates"
    return ""


def test_local_cluster_is_tls_without_http_pages(tmp_path):
    """``local:1`` (worker processes): the scheduler talks TLS only, a process without the
    throw-away certificates cannot submit code (no marker file appears), the HTTP server
    answers no page, and closing the client ends the cluster."""
    pytest.importorskip("cryptography")
    marker = tmp_path / "marker"
    client, owned = scheduler.client_for("local:1", processes=True)
    try:
        address = client.scheduler.address
        why = "" if address.startswith("tls://127.0.0.1:") else f"address {address}"
        assert client.submit(sum, [1, 2]).result() == 3  # the cluster works for its owner
        why = why or _attack(address, marker)
        why = why or ("" if not marker.exists() else "the marker file appeared")
        http = getattr(client.cluster.scheduler, "http_server", None)
        port = next(iter(http._sockets.values())).getsockname()[1] if http else None
        assert http is None or port, "the HTTP server's port was not found"
        for page in ("/info/main/workers.html", "/json/identity.json", "/health", "/logs"):
            if port is None or why:
                break
            try:
                urllib.request.urlopen(f"http://127.0.0.1:{port}{page}", timeout=3)
                why = f"{page} answered"
            except urllib.error.HTTPError as err:
                why = "" if err.code == 404 else f"{page}: HTTP {err.code}"
            except OSError:
                pass
        cluster = client.cluster
    finally:
        client.close()
    why = why or ("" if owned and cluster.status.name == "closed" else "the cluster outlived "
                  "its client")
    record(CLUSTER, "local:1 TLS, no code from outside, no HTTP pages", why)


def test_local_cluster_bounded_by_the_cores():
    n = (os.cpu_count() or 1) + 1
    with pytest.raises(InputError) as info:
        scheduler.client_for(f"local:{n}")
    text = str(info.value)
    why = "" if f"at most local:{n - 1}" in text and "\n" not in text else text
    record(CLUSTER, f"local:{n} above the cores", why)


def test_plain_tcp_beyond_localhost_warns_tls_needs_certificates(tmp_path):
    import dask

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        scheduler._remote_security("tcp://127.0.0.1:8786")
        scheduler._remote_security("tcp://localhost:8786")
        quiet = len(caught)
        scheduler._remote_security("tcp://10.20.30.40:8786")
    why = "" if quiet == 0 and len(caught) == 1 and "can run code" in str(caught[0].message) \
        else f"{quiet} warnings for localhost, {len(caught) - quiet} for a remote address"
    with pytest.raises(InputError, match="tls:// needs certificates"):
        scheduler._remote_security("tls://10.20.30.40:8786")
    ca = tmp_path / "ca.pem"
    ca.write_text("not read here")
    with dask.config.set({"distributed.comm.tls.ca-file": str(ca)}):
        sec = scheduler._remote_security("tls://10.20.30.40:8786")
    why = why or ("" if sec is not None and sec.tls_ca_file == str(ca) else "no Security")
    record(CLUSTER, "tcp:// warned beyond localhost, tls:// with dask's certificates", why)


def test_cluster_without_workers_is_one_line(monkeypatch):
    """A scheduler with no worker: one line after the time-out (the work waited forever)."""
    cluster = distributed.LocalCluster(n_workers=0, processes=False, protocol="tcp://",
                                       host="127.0.0.1", dashboard_address=None)
    monkeypatch.setattr(scheduler, "WORKER_TIMEOUT_S", 2)
    try:
        with pytest.raises(InputError) as info:
            scheduler.client_for(cluster.scheduler_address)
    finally:
        cluster.close()
    text = str(info.value)
    why = "" if "no worker joined the cluster within 2 s" in text and "\n" not in text else text
    record(CLUSTER, "cluster without workers", why)


def test_trust_is_stated_in_help(tmp_path):
    r = run(["geoshade", "core", "porosity", "--help"], tmp_path, timeout=60,
            env={"COLUMNS": "400"})  # argparse breaks lines after a hyphen ("throw- away")
    text = " ".join(r.out.split())
    why = "" if r.rc == 0 and "TLS with throw-away certificates" in text and "tls://" in text \
        else f"exit {r.rc}: --help says nothing of trust"
    record(CLUSTER, "--help states the trust", why)


def test_zz_counts():
    if CLUSTER in RESULTS:
        print(summary(CLUSTER))
        assert all(ok for _, ok, _ in RESULTS[CLUSTER]), summary(CLUSTER)
