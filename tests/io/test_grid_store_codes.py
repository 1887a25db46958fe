"""Distinct codes of integer arrays stored at ingest (grid store attribute ``distinct_codes``):
each integer property's kept codes equal numpy's distinct active values of the array read back
(and the dask pass of geoshade.grid.lazy), through resumes; more than the limit keeps none; older
stores open without them; a damaged attribute is one line."""

from __future__ import annotations

import json

import numpy as np
import pytest

from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.grid.lazy import count_in, lazy_codes, stored_codes
from geoshade.io.stores import grid_store
from geoshade.io.stores.chunks import DamagedStoreError
from geoshade.io.stores.grid_store import ModelSource, open_grid_store, write_grid_store
from geoshade.models.summary import codes_part, merge_codes
from geoshade.styles.categories import distinct_codes


def _grid(seed=2):
    g = synthetic_grid(9, 7, 6, seed=seed, inactive_fraction=0.2)
    rng = np.random.default_rng(seed)
    g.properties["FACIES"] = np.asfortranarray(rng.choice([-3, 0, 7, 1000], g.dims)
                                               .astype(np.int16))
    g.properties["MANY"] = np.asfortranarray(np.arange(g.ncells, dtype=np.int64)
                                             .reshape(g.dims) * 7919)
    return g


@pytest.fixture(scope="module")
def store(tmp_path_factory):
    return write_grid_store(ModelSource(_grid()), tmp_path_factory.mktemp("codes") / "c.zarr",
                            chunks=(4, 3, 2)).path


def test_kept_codes_are_the_distinct_active_values(store):
    g = open_grid_store(store)
    act = np.asarray(g.actnum) != 0
    kept = g.meta["distinct_codes"]
    assert sorted(kept) == ["props/FACIES", "props/FIPNUM", "props/MANY"]   # integers only
    for name in ("FIPNUM", "FACIES"):
        want = distinct_codes(np.asarray(g.properties[name]), act)
        assert want.size >= 2
        np.testing.assert_array_equal(stored_codes(g, g.properties[name]), want)
        np.testing.assert_array_equal(lazy_codes(g, g.properties[name]), want)
    assert kept["props/MANY"] is None or kept["props/MANY"].size <= 4096
    assert stored_codes(g, g.properties["PORO"]) is None        # floats: none kept


def test_more_codes_than_the_limit_keep_none(tmp_path, monkeypatch):
    monkeypatch.setattr(grid_store, "codes_part",
                        lambda v, a: codes_part(v, a, limit=5))
    g = open_grid_store(write_grid_store(ModelSource(_grid()), tmp_path / "m.zarr",
                                         chunks=(4, 3, 2)).path)
    assert g.meta["distinct_codes"]["props/MANY"] is None
    assert g.meta["distinct_codes"]["props/FACIES"] is not None
    act = np.asarray(g.actnum) != 0
    np.testing.assert_array_equal(lazy_codes(g, g.properties["MANY"]),   # the dask pass
                                  distinct_codes(np.asarray(g.properties["MANY"]), act))


def test_an_older_store_opens_and_its_codes_come_from_one_pass(store, tmp_path):
    import shutil

    old = tmp_path / "old.zarr"
    shutil.copytree(store, old)
    meta = json.loads((old / "zarr.json").read_text())
    del meta["attributes"]["distinct_codes"]
    (old / "zarr.json").write_text(json.dumps(meta))
    g = open_grid_store(old)
    assert g.meta["distinct_codes"] == {} and stored_codes(g, g.properties["FIPNUM"]) is None
    np.testing.assert_array_equal(
        lazy_codes(g, g.properties["FACIES"]),
        distinct_codes(np.asarray(g.properties["FACIES"]), np.asarray(g.actnum) != 0))


@pytest.mark.parametrize("junk", ["text", {"props/FIPNUM": "1,2"}, {"props/FIPNUM": [1.5]}])
def test_a_damaged_codes_attribute_is_one_line(store, tmp_path, junk):
    import shutil

    bad = tmp_path / "bad.zarr"
    shutil.copytree(store, bad)
    meta = json.loads((bad / "zarr.json").read_text())
    meta["attributes"]["distinct_codes"] = junk
    (bad / "zarr.json").write_text(json.dumps(meta))
    with pytest.raises(DamagedStoreError, match=r"bad\.zarr: damaged 'distinct_codes' attribute"):
        open_grid_store(bad)


def test_merge_and_count_agree_with_numpy():
    rng = np.random.default_rng(0)
    v = rng.integers(-5, 5, (6, 5, 4))
    act = rng.random((6, 5, 4)) > 0.3
    parts = [codes_part(v[:, :, k:k + 1], act[:, :, k:k + 1]) for k in range(4)]
    assert merge_codes(parts) == sorted(set(v[act].tolist()))
    assert codes_part(v + 10**9, act) == sorted(set((v[act] + 10**9).tolist()))   # sorted path
    assert codes_part(v, np.zeros_like(act)) == []
    import dask.array as da

    assert count_in(da.from_array(v, chunks=2), da.from_array(act, chunks=3), [-5, 4]) \
        == int(np.isin(v[act], [-5, 4]).sum()) == count_in(v, act, [-5, 4])


def test_resumed_ingest_keeps_the_same_codes(tmp_path, monkeypatch):
    from geoshade.io.stores.grid_store import ingest_grid
    from tests.io.grid_store_support import interrupted_ingest
    from tests.io.test_grid_store import CHUNKS, DIMS, _write_case

    case = _write_case(str(tmp_path), synthetic_grid(*DIMS, seed=4, inactive_fraction=0.15))
    interrupted_ingest(monkeypatch, case, tmp_path / "r.zarr", chunks=CHUNKS)
    rep = ingest_grid(case, tmp_path / "r.zarr", chunks=CHUNKS)
    fresh = ingest_grid(case, tmp_path / "f.zarr", chunks=CHUNKS)
    a, b = (json.loads((p / "zarr.json").read_text())["attributes"].get("distinct_codes")
            for p in (rep.path, fresh.path))
    assert rep.resumed and a == b and a.get("props/FIPNUM")


def test_code_names_survive_the_store_and_damaged_ones_are_one_line(tmp_path):
    """A property's code names (ROFF's) are kept in the store's meta (JSON keys are text;
    they come back as the integer codes); damaged ones are one line."""
    g = _grid()
    g.meta["codes"] = {"FACIES": {-3: "SHALE", 7: "SAND"}}
    path = write_grid_store(ModelSource(g), tmp_path / "n.zarr", chunks=(4, 3, 2)).path
    assert open_grid_store(path).meta["codes"] == {"FACIES": {-3: "SHALE", 7: "SAND"}}
    meta = json.loads((path / "zarr.json").read_text())
    meta["attributes"]["meta"]["codes"] = {"FACIES": {"sand": "SAND"}}
    (path / "zarr.json").write_text(json.dumps(meta))
    with pytest.raises(DamagedStoreError, match=r"n\.zarr: damaged 'meta' attribute: its code"):
        open_grid_store(path)
