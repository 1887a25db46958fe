"""Grid stores (geoshade.io.stores.grid_store): a case streamed into a chunked zarr store reads back
equal to the case (resfo and the in-memory readers as oracles), resumably, never half-done."""

from __future__ import annotations

import json
import os
import shutil

import numpy as np
import pytest
import resfo

from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.errors import InputError
from geoshade.io import load
from geoshade.io.grids.ecl import load_case
from geoshade.io.grids.ecl_records import RecordError, scan
from geoshade.io.stores import grid_store
from geoshade.io.stores.chunks import DamagedStoreError
from geoshade.io.stores.ecl_source import read_values
from geoshade.io.stores.grid_store import (
    ingest_grid,
    is_grid_store,
    open_grid_store,
    write_grid_store,
)
from geoshade.models import CornerPointGrid
from tests.corruption import clean_failure, run_cli
from tests.io.grid_store_support import interrupted_ingest

DIMS = (7, 5, 6)  # ZCORN 1680 values: slabs of 2 layers (560 values) cut its 1000-value blocks
CHUNKS = (3, 2, 2)


def _write_case(folder, grid: CornerPointGrid, steps: int = 3) -> str:
    """An EGRID + INIT + UNRST of ``grid`` written with resfo (active-cell INIT/UNRST arrays)."""
    nx, ny, nz = grid.dims
    act = grid.active.ravel(order="F")
    nact = int(act.sum())
    gh = np.zeros(100, np.int32)
    gh[:4] = (1, nx, ny, nz)
    coord = np.asarray(grid.coord).transpose(1, 0, 2).astype(np.float32).ravel()
    egrid = os.path.join(folder, "C.EGRID")
    resfo.write(egrid, [("GRIDHEAD", gh), ("GRIDUNIT", np.array([b"METRES  ", b"        "])),
                        ("COORD   ", coord),
                        ("ZCORN   ", grid.zcorn.astype(np.float32).ravel(order="F")),
                        ("ACTNUM  ", grid.actnum.astype(np.int32).ravel(order="F")),
                        ("ENDGRID ", np.zeros(0, np.int32))])
    head = np.zeros(411, np.int32)
    head[8:12] = (nx, ny, nz, nact)
    head[64:67] = (1, 1, 2001)
    poro = grid.properties["PORO"].ravel(order="F")[act].astype(np.float32)
    fip = grid.properties["FIPNUM"].ravel(order="F")[act].astype(np.int32)
    porv = np.arange(grid.ncells, dtype=np.float32)  # all cells, as PORV is
    resfo.write(os.path.join(folder, "C.INIT"), [("INTEHEAD", head), ("PORO    ", poro),
                                                 ("FIPNUM  ", fip), ("PORV    ", porv)])
    recs = []
    for t in range(steps):
        h = head.copy()
        h[64:67] = (1, 1 + t, 2001)
        swat = (np.linspace(0, 1, nact) * (t + 1) / steps).astype(np.float32)
        pres = (200.0 + np.arange(nact) + t).astype(np.float64)
        recs += [("SEQNUM  ", np.array([t], np.int32)), ("INTEHEAD", h), ("SWAT    ", swat),
                 ("PRESSURE", pres)]
    resfo.write(os.path.join(folder, "C.UNRST"), recs)
    return egrid


@pytest.fixture(scope="module")
def case(tmp_path_factory):
    d = tmp_path_factory.mktemp("gcase")
    g = synthetic_grid(*DIMS, seed=4, inactive_fraction=0.15)
    return _write_case(str(d), g)


def _arrays(grid: CornerPointGrid) -> dict:
    out = {"zcorn": grid.zcorn, "actnum": grid.actnum, "coord": grid.coord}
    out.update({f"p/{k}": v for k, v in grid.properties.items()})
    for t, step in enumerate(grid.steps):
        out.update({f"s{t}/{k}": step[k] for k in step})
    return {k: np.asarray(v) for k, v in out.items()}


def _assert_same(a: dict, b: dict) -> None:
    assert sorted(a) == sorted(b)
    for k in a:
        assert a[k].shape == b[k].shape, k
        np.testing.assert_array_equal(a[k], b[k], err_msg=k)


def test_read_values_equals_resfo_across_blocks(tmp_path):
    f = tmp_path / "A.INIT"
    vals = np.arange(2345, dtype=np.float32) * 0.5
    ints = np.arange(1000, dtype=np.int32) - 7
    resfo.write(str(f), [("PORO    ", vals), ("FIPNUM  ", ints)])
    rec, rec_i = list(scan(f))
    for q0, q1 in [(0, 2345), (999, 1001), (1000, 2000), (2001, 2345), (5, 6), (1500, 1500)]:
        np.testing.assert_array_equal(read_values(rec, q0, q1), vals[q0:q1])
    np.testing.assert_array_equal(read_values(rec_i, 0, 1000), ints)
    assert read_values(rec, 0, 10).dtype.isnative


def test_read_values_damaged_marker(tmp_path):
    f = tmp_path / "A.INIT"
    resfo.write(str(f), [("PORO    ", np.arange(2345, dtype=np.float32))])
    rec = next(iter(scan(f)))
    raw = bytearray(f.read_bytes())
    pos = rec.start + 24 + 4 + 4000  # the first block's end marker
    raw[pos:pos + 4] = (77).to_bytes(4, "big")
    f.write_bytes(bytes(raw))
    with pytest.raises(RecordError, match="PORO: damaged record"):
        read_values(rec, 0, 2345)


def test_ingest_reads_back_equal_to_the_case(case, tmp_path):
    rep = ingest_grid(case, tmp_path / "c.zarr", chunks=CHUNKS)
    assert rep.slabs == 3 and rep.slabs_written == 3 and not rep.resumed
    store = open_grid_store(rep.path)
    ref = load_case(case)
    assert store.dims == ref.dims and store.meta["chunks"] == CHUNKS
    assert store.step_dates == ref.step_dates and store.units == ref.units == "METRES"
    assert type(store.zcorn).__name__ == "Array"  # dask: nothing read yet
    assert store.zcorn.chunks[0][0] == 2 * CHUNKS[0] and store.actnum.chunks[2][0] == CHUNKS[2]
    _assert_same(_arrays(store), _arrays(ref))
    # resfo, the independent oracle, for the raw arrays
    egrid = dict((k.strip(), v) for k, v in resfo.read(case))
    np.testing.assert_array_equal(np.asarray(store.zcorn).ravel(order="F"), egrid["ZCORN"])
    np.testing.assert_array_equal(np.asarray(store.actnum).ravel(order="F"), egrid["ACTNUM"])
    init = dict((k.strip(), v) for k, v in resfo.read(case.replace(".EGRID", ".INIT")))
    act = np.asarray(store.actnum).ravel(order="F") != 0
    poro = np.asarray(store.properties["PORO"]).ravel(order="F")
    np.testing.assert_array_equal(poro[act], init["PORO"])
    assert np.isnan(poro[~act]).all()
    assert (np.asarray(store.properties["FIPNUM"]).ravel(order="F")[~act] == 0).all()
    np.testing.assert_array_equal(np.asarray(store.properties["PORV"]).ravel(order="F"),
                                  init["PORV"])
    # geoshade.load dispatches on the attributes
    again = load(rep.path)
    assert isinstance(again, CornerPointGrid) and again.dims == ref.dims


def test_grdecl_ingest_keeps_faults(tmp_path):
    from geoshade.io.grids.grdecl import read_grdecl
    from geoshade.io.grids.grdecl_writer import write_grdecl

    g = synthetic_grid(6, 6, 3, seed=1)
    src = write_grdecl(g, tmp_path / "g.grdecl")
    rep = ingest_grid(src, tmp_path / "g.zarr", chunks=(4, 4, 2))
    store, ref = open_grid_store(rep.path), read_grdecl(src)
    assert [f.name for f in store.faults] == [f.name for f in ref.faults]
    for a, b in zip(store.faults, ref.faults, strict=True):
        np.testing.assert_array_equal(a.faces, b.faces)
    _assert_same(_arrays(store), _arrays(ref))


def test_ingest_resumes_and_partial_never_reads_complete(case, tmp_path, monkeypatch):
    out = tmp_path / "r.zarr"
    partial = tmp_path / "r.zarr.partial"
    interrupted_ingest(monkeypatch, case, out, chunks=CHUNKS)
    assert not out.exists() and partial.is_dir() and is_grid_store(partial)
    with pytest.raises(InputError, match="incomplete grid store"):
        open_grid_store(partial)
    with pytest.raises(InputError, match="incomplete grid store"):
        load(partial)
    rep = ingest_grid(case, out, chunks=CHUNKS)
    assert rep.resumed and rep.slabs_skipped == 2 and rep.slabs_written == 1
    assert not partial.exists() and not (tmp_path / "r.zarr.partial.progress.json").exists()
    fresh = ingest_grid(case, tmp_path / "f.zarr", chunks=CHUNKS)
    _assert_same(_arrays(open_grid_store(rep.path)), _arrays(open_grid_store(fresh.path)))


def test_other_settings_do_not_resume(case, tmp_path, monkeypatch):
    def stop(done):
        raise KeyboardInterrupt

    monkeypatch.setattr(grid_store, "_after_slab", stop)
    with pytest.raises(KeyboardInterrupt):
        ingest_grid(case, tmp_path / "o.zarr", chunks=CHUNKS)
    monkeypatch.setattr(grid_store, "_after_slab", None)
    with pytest.raises(InputError, match=r"another input or settings .*chunks"):
        ingest_grid(case, tmp_path / "o.zarr", chunks=(4, 4, 2))
    rep = ingest_grid(case, tmp_path / "o.zarr", chunks=(4, 4, 2), overwrite=True)
    assert not rep.resumed and open_grid_store(rep.path).meta["chunks"] == (4, 4, 2)


def test_core_store_still_loads_as_a_volume(tmp_path):
    from geoshade.io.stores.zarr_io import write_zarr
    from geoshade.models import VoxelVolume

    f = tmp_path / "v.zarr"
    write_zarr(VoxelVolume(np.ones((2, 3, 4), np.uint8)), f)
    assert not is_grid_store(f)
    assert isinstance(load(f), VoxelVolume)
    with pytest.raises(InputError, match="not a geoshade grid store"):
        open_grid_store(f)


@pytest.fixture
def small_store(tmp_path):
    from geoshade.io.stores.grid_store import ModelSource

    g = synthetic_grid(5, 4, 4, seed=2)
    return write_grid_store(ModelSource(g), tmp_path / "s.zarr", chunks=(3, 3, 2)).path


def test_missing_or_damaged_chunk_is_one_line(small_store):
    chunk = next((small_store / "zcorn" / "c").rglob("*"))
    while chunk.is_dir():
        chunk = next(chunk.iterdir())
    os.remove(chunk)
    g = open_grid_store(small_store)
    with pytest.raises(DamagedStoreError, match=r"chunk zcorn/c/.* is missing"):
        np.asarray(g.zcorn)
    p = next((small_store / "props" / "PORO" / "c").rglob("*"))
    while p.is_dir():
        p = next(p.iterdir())
    p.write_bytes(p.read_bytes()[:-3] + b"xyz")
    with pytest.raises(DamagedStoreError, match=r"PORO/c/.* is damaged"):
        np.asarray(g.properties["PORO"])


def test_damaged_attributes_are_one_line(small_store, tmp_path):
    meta = json.loads((small_store / "zarr.json").read_text())
    meta["attributes"]["grid_store"]["dims"] = "junk"
    (small_store / "zarr.json").write_text(json.dumps(meta))
    with pytest.raises(DamagedStoreError, match="damaged 'grid_store' attribute"):
        open_grid_store(small_store)
    shutil.rmtree(small_store / "actnum")
    meta["attributes"]["grid_store"]["dims"] = [5, 4, 4]
    (small_store / "zarr.json").write_text(json.dumps(meta))
    with pytest.raises(DamagedStoreError, match="array actnum is missing"):
        open_grid_store(small_store)


def test_cli_ingest(case, tmp_path, capsys):
    out = tmp_path / "cli.zarr"
    rc, text, _ = run_cli(capsys, ["grid", "ingest", case, "-o", out, "--chunks", 4, 4, 3])
    assert rc == 0 and "3 of" not in text and "2 of 2 slabs written" in text
    assert isinstance(load(out), CornerPointGrid)
    clean_failure(capsys, ["grid", "ingest", case, "-o", out], names="cli.zarr",
                  expect="already exists")
    clean_failure(capsys, ["grid", "ingest", case, "-o", tmp_path / "x.zarr", "--chunks", 0, 1,
                           1], names="chunks", watch=[tmp_path])


def test_describe_a_store_streams_and_says_what_the_case_says(case, tmp_path):
    """``geoshade info`` of a store: the numbers of the case in memory, from dask reductions
    (no whole array read), ACTNUM's count from the store's attributes."""
    from geoshade.io.describe import describe

    rep = ingest_grid(case, tmp_path / "d.zarr", chunks=CHUNKS)
    store, ref = open_grid_store(rep.path), load_case(case)
    a, b = describe(store), describe(ref)
    assert a["active_cells"] == b["active_cells"] == ref.nactive
    np.testing.assert_allclose(a["bounds"], b["bounds"])
    assert a["property_stats"].keys() == b["property_stats"].keys()
    for name, st in b["property_stats"].items():
        for k in ("min", "max"):
            assert a["property_stats"][name][k] == pytest.approx(st[k]), (name, k)
        assert a["property_stats"][name]["mean"] == pytest.approx(st["mean"], rel=1e-6)
