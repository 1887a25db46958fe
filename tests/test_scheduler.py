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
    for name in scheduler.LOCAL_SCHEDULERS:   # dask's name of each
        with scheduler.using_scheduler(name) as s:
            assert s == {"sync": "synchronous", "single-threaded": "synchronous"}.get(name, name)


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
    from geoshade.compute.voxels.porosity import porosity

    with scheduler.using_scheduler("local:1", processes=False) as client:
        assert len(scheduler.live_workers(client)) == 1
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


# --- the parsed value (issue 23) ---------------------------------------------------------------
@pytest.mark.parametrize(("given", "kind", "value"), [
    (None, "here", "here"), ("threads", "threads", "threads"),
    ("sync", "synchronous", "synchronous"), ("synchronous", "synchronous", "synchronous"),
    ("single-threaded", "synchronous", "synchronous"), ("processes", "processes", "processes"),
    ("local:4", "local", "local:4"), (" LOCAL:2 ", "local", "local:2"),
    ("tcp://10.0.0.5:8786", "address", "tcp://10.0.0.5:8786"),
    ("tls://sched.example.org:8786", "address", "tls://sched.example.org:8786"),
    ("10.0.0.5:8786", "address", "10.0.0.5:8786"), ("tcp://[::1]:8786", "address",
                                                    "tcp://[::1]:8786"),
])
def test_scheduler_parse_accepts(given, kind, value):
    s = scheduler.Scheduler.parse(given)
    assert (s.kind, str(s)) == (kind, value)
    assert s.is_cluster == (kind in ("local", "address"))
    assert scheduler.Scheduler.parse(s) is s   # parsed once: a Scheduler passes through


@pytest.mark.parametrize("bad", ["banana", "", "local:0", "local:x", "tcp://host", "host:99999",
                                 "http://host:8786", 3, 2.5, ["threads"]])
def test_scheduler_parse_refuses_in_one_line(bad):
    with pytest.raises(InputError) as err:
        scheduler.Scheduler.parse(bad)
    msg = str(err.value)
    assert "\n" not in msg and msg.startswith("scheduler ")


def test_a_client_is_taken_as_is():
    class FakeClient:   # what is_client looks for
        def submit(self): ...

        def scheduler_info(self): ...

    c = FakeClient()
    s = scheduler.Scheduler.parse(c)
    assert s.kind == "client" and s.client is c and s.is_cluster
    session = scheduler.SchedulerSession(s)
    assert session.client() is c and session.starts == 0   # given: not ours to start or close
    session.close()


def test_option_fields_hold_the_parsed_value():
    from geoshade.core.options import CoreOptions
    from geoshade.grid.options import GridOptions

    for cls in (GridOptions, CoreOptions):
        assert cls.parse(scheduler="local:3").scheduler == scheduler.Scheduler("local", workers=3)
        # none given: here (this process), the one meaning of None
        assert scheduler.Scheduler.parse(cls.parse().scheduler) is scheduler.HERE
        with pytest.raises(InputError, match=r"^scheduler 'banana': expected threads"):
            cls.parse(scheduler="banana")


def test_a_session_starts_one_cluster_and_closes_it():
    pytest.importorskip("distributed")
    from geoshade.compute.voxels.lazy import compute

    da = pytest.importorskip("dask.array")
    session = scheduler.SchedulerSession("local:1", processes=False)
    assert not session.started
    for _ in range(3):   # three computations, one cluster
        (total,) = compute(da.ones(10, chunks=5).sum(), scheduler=session)
        assert float(total) == 10.0
    client = session.client()
    assert session.starts == 1 and client.status == "running"
    session.close()
    assert not session.started and client.status == "closed"
    session.close()   # idempotent


def _cli(argv, capsys):
    from geoshade.cli.main import main

    rc = main(argv)
    return rc, capsys.readouterr().err


def test_scheduler_banana_is_refused_before_gl(tmp_path, capsys, monkeypatch):
    """``--scheduler banana``: one line and the input error's exit code, before any GL
    context (in memory and on a store alike; before, it was ignored in memory and failed after
    GL on a store)."""
    import geoshade.render.context as context
    from geoshade.io.stores.grid_store import ingest_grid
    from tests.grid_cases import grid_cases

    def no_gl(*a, **k):
        raise AssertionError("a GL context was made")

    paths = grid_cases().write_case(tmp_path, 6, 5, 3)
    ingest_grid(paths["EGRID"], tmp_path / "g.zarr", chunks=(4, 4, 3))
    np.save(tmp_path / "v.npy", np.arange(4 * 5 * 6, dtype=np.uint16).reshape(4, 5, 6))
    monkeypatch.setattr(context, "get_context", no_gl)
    for argv in (["grid", "render", str(paths["EGRID"]), "--property", "PORO"],
                 ["grid", "render", str(tmp_path / "g.zarr"), "--property", "PORO"],
                 ["core", "render", str(tmp_path / "v.npy")]):
        rc, err = _cli([*argv, "--scheduler", "banana", "-o", str(tmp_path / "x.png")], capsys)
        assert rc == InputError.exit_code, (argv, err)
        assert len(err.strip().splitlines()) == 1 and "scheduler 'banana'" in err
        assert not (tmp_path / "x.png").exists()


def test_a_view_starts_its_cluster_once_and_release_closes_it(ctx, tmp_path):
    """A grid store viewed on ``local:1``: one LocalCluster for the View's life across several
    filter changes (before: one started and stopped per change), closed by release()."""
    pytest.importorskip("distributed")
    from geoshade.grid import GridView
    from geoshade.io.stores.grid_store import ingest_grid, open_grid_store
    from tests.grid_cases import grid_cases

    paths = grid_cases().write_case(tmp_path, 10, 8, 4)
    ingest_grid(paths["EGRID"], tmp_path / "g.zarr", chunks=(4, 4, 2))
    store = open_grid_store(tmp_path / "g.zarr")
    with GridView(store, ctx=ctx, size=(64, 48), property="PORO", scheduler="local:1") as one:
        ref = {f: one.update(filter=f) or one.draw(frames=1)[0]
               for f in ("PORO > 0.2", "PERMX > 100")}
    view = GridView(store, ctx=ctx, size=(64, 48), property="PORO", scheduler="local:1")
    client = view.work.client()
    for f in ("PORO > 0.2", "PERMX > 100", None, "PORO > 0.2"):
        view.update(filter=f)
        img, _ = view.draw(frames=1)
        if f in ref:
            np.testing.assert_array_equal(img, ref[f])
    assert view.work.starts == 1 and view.work.client() is client
    assert client.status == "running"
    with pytest.raises(InputError, match="scheduler: fixed when the"):
        view.update(scheduler="local:2")
    view.release()
    assert client.status == "closed" and not view.work.started


def test_an_indexed_store_filters_on_the_views_cluster(ctx, tmp_path):
    """A grid store with its index, viewed on ``local:1``: the filter's shown cells are computed
    on the View's cluster (tasks in its task stream), and the picture is the one drawn on this
    process's threads."""
    pytest.importorskip("distributed")
    from distributed import get_task_stream

    from geoshade.compute.grid.index_faces import store_index
    from geoshade.compute.grid.synthetic import synthetic_grid
    from geoshade.grid import GridView
    from geoshade.io.stores.grid_store import ModelSource, open_grid_store, write_grid_store

    path = write_grid_store(ModelSource(synthetic_grid(12, 9, 6, inactive_fraction=0.1,
                                                       seed=2)),
                            tmp_path / "i.zarr", (5, 4, 3), index=store_index).path
    opts = {"size": (64, 48), "property": "PORO", "filter": "PERMX > 100"}
    with GridView(open_grid_store(path), ctx=ctx, **opts) as here:
        ref, rs = here.draw(frames=1)
    assert rs["faces_from"] == "index" and rs["chunks_computed"] > 0
    with GridView(open_grid_store(path), ctx=ctx, scheduler="local:1",
                  **{**opts, "filter": None}) as view:
        client = view.work.client()
        with get_task_stream(client) as ts:
            view.update(filter="PERMX > 100")
            img, st = view.draw(frames=1)
        assert st["faces_from"] == "index" and len(ts.data) > 0
    np.testing.assert_array_equal(img, ref)


def test_ingest_and_porosity_refuse_what_is_no_scheduler(tmp_path):
    """io.stores.ingest and core porosity take the same value: one line, before any work."""
    from geoshade.compute.voxels.synthetic import synthetic_core
    from geoshade.core import porosity
    from geoshade.io.stores.ingest import ingest

    src = tmp_path / "v.npy"
    np.save(src, np.zeros((4, 4, 4), np.uint8))
    with pytest.raises(InputError, match=r"^scheduler 'banana': expected threads"):
        ingest(src, tmp_path / "c.zarr", scheduler="banana")
    assert not (tmp_path / "c.zarr").exists()
    with pytest.raises(InputError, match=r"^scheduler 'banana': expected threads"):
        porosity(synthetic_core(8), (0, 100), scheduler="banana")
    s = scheduler.SchedulerSession("local:1", processes=False)
    try:   # a session is taken by client_for as its owner's (not closed there)
        client, owned = scheduler.client_for(s)
        assert client is s.client() and not owned and s.starts == 1
    finally:
        s.close()


# --- one meaning (issue 30) ---------------------------------------------------------------------
def test_none_is_here_with_one_meaning(monkeypatch):
    """``scheduler=None`` is :data:`HERE` everywhere: this process, arrays in memory computed in
    place (no dask graph), a dask array on dask's threads; any other scheduler, "threads"
    included, runs every computation as dask tasks. The results are equal bit for bit."""
    import geoshade.compute.voxels.bricks as bricks
    from geoshade.compute.voxels.porosity import porosity

    da = pytest.importorskip("dask.array")
    here = scheduler.Scheduler.parse(None)
    assert here is scheduler.HERE and here.in_place and not here.is_cluster
    assert here.dask == "threads" and scheduler.checked(None) is here
    assert not scheduler.Scheduler.parse("threads").in_place
    a = np.random.default_rng(2).integers(0, 100, (12, 10, 8)).astype(np.uint8)
    loops = []
    real = bricks.build_selection_maps
    monkeypatch.setattr(bricks, "build_selection_maps",
                        lambda *args, **kw: loops.append(1) or real(*args, **kw))
    maps = {s: bricks.selection_maps_for(a, None, 10, 60, 10, 60, scheduler=s)
            for s in (None, here, "threads", "sync")}
    assert len(loops) == 2   # None and HERE: the in-place loop; the named ones: dask
    for m in maps.values():
        np.testing.assert_array_equal(m.bits, maps[None].bits)
    assert len(loops) == 2
    bricks.selection_maps_for(da.from_array(a, chunks=4), None, 10, 60, 10, 60)
    assert len(loops) == 2   # a dask array: dask tasks, on dask's threads
    ref = porosity(a, 10, 60)
    for s in (here, "threads", "sync"):
        np.testing.assert_array_equal(porosity(a, 10, 60, scheduler=s).counts, ref.counts)


def test_a_parsed_scheduler_is_never_parsed_again(monkeypatch):
    """``local:N`` is read once: the client is made from the parsed value (nothing turns it
    back into text to read it again)."""
    pytest.importorskip("distributed")
    s = scheduler.Scheduler.parse("local:1")

    def again(name):
        raise AssertionError(f"{name!r} parsed again")

    monkeypatch.setattr(scheduler, "_workers", again)
    session = scheduler.SchedulerSession(s, processes=False)
    try:
        assert session.scheduler is s and len(scheduler.live_workers(session.client())) == 1
        with scheduler.using_scheduler(session) as client:
            assert client is session.client()
    finally:
        session.close()


def test_local_n_means_the_same_for_core_and_grid(ctx):
    """``scheduler="local:1"`` without ``distributed``: the View's dask work (a core's
    porosity and selection maps, a grid store's faces) runs on the one cluster it starts,
    and the pictures are the ones drawn here; ``distributed`` alone says where the drawing
    happens."""
    pytest.importorskip("distributed")
    from distributed import get_task_stream

    from geoshade.compute.voxels.synthetic import synthetic_core
    from geoshade.core import CoreView

    vol = synthetic_core(32, porosity=0.3, seed=5)
    opts = {"ctx": ctx, "size": (64, 48), "select": (0, 15000), "porosity": "z"}
    with CoreView(vol, **opts) as here:
        ref, rs = here.draw(frames=1)
        assert here.work.scheduler is scheduler.HERE and here.work.starts == 0
    with CoreView(vol, scheduler="local:1", **opts) as view:
        assert view.drawing.name != "cluster"
        client = view.work.client()
        with get_task_stream(client) as ts:
            view.update(select=(0, 12000))
            view.update(select=(0, 15000))
        img, st = view.draw(frames=1)
        assert len(ts.data) > 0 and view.work.starts == 1
    np.testing.assert_array_equal(img, ref)
    assert st["porosity"] == rs["porosity"]


@pytest.mark.parametrize("quiet", [True, False])
def test_quiet_cluster_logs_holds_after_distributed_is_imported(quiet):
    """Importing ``distributed`` sets its loggers' levels from dask's config (INFO), so a level
    set before was lost, and a cluster of threads shutting down after it handed back its raised
    handler levels printed "Batched Comm Closed" and a traceback on a command's stderr. With
    :func:`quiet_cluster_logs` (what the command line calls) its import is followed by the
    levels again; without it, the same message is printed (the oracle that it reaches stderr)."""
    import subprocess
    import sys

    pytest.importorskip("distributed")
    code = ("import logging\nfrom geoshade import scheduler\n"
            + ("scheduler.quiet_cluster_logs()\n" if quiet else "")
            + "scheduler._distributed()\n"
            "try:\n    raise OSError('closed')\nexcept OSError:\n"
            "    logging.getLogger('distributed.batched').info('Batched Comm Closed', "
            "exc_info=True)\n"
            "logging.getLogger('distributed.client').warning('client noise')\n")
    err = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True, timeout=120).stderr
    if quiet:
        assert err == ""
    else:
        assert "Batched Comm Closed" in err and "Traceback" in err and "client noise" in err
