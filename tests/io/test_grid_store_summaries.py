"""Colour-scale summaries stored at ingest (geoshade.io.stores.grid_store): each property's and
report
step array's :class:`ValueSummary` over the active cells equals ``summarise`` of the arrays read
back (numpy and dask passes as oracles), exactly, through resumes; older stores still open."""

from __future__ import annotations

import json

import numpy as np
import pytest

from geoshade.compute.grid import cell_values
from geoshade.compute.grid.cell_values import summarise, summary_to_json
from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.io.stores import grid_store
from geoshade.io.stores.chunks import DamagedStoreError
from geoshade.io.stores.grid_store import (
    ModelSource,
    ingest_grid,
    open_grid_store,
    write_grid_store,
)
from geoshade.models import CornerPointGrid
from tests.grid_cases import grid_cases
from tests.io.grid_store_support import interrupted_ingest
from tests.io.test_grid_store import CHUNKS, DIMS, _write_case


def _row(s) -> list:
    """A summary as comparable numbers (NaN as None: NaN != NaN)."""
    return summary_to_json(s)


def _check(store) -> int:
    """Every stored summary equals summarise() of the array read back (numpy and dask)."""
    g = open_grid_store(store)
    stored = g.meta["summaries"]
    act = np.asarray(g.actnum)
    checked = 0
    for name, arr in g.properties.items():
        want = summarise(np.asarray(arr), act)
        assert _row(stored[f"props/{name}"]) == _row(want), name
        assert _row(summarise(arr, g.actnum)) == _row(want), name  # the dask pass
        checked += 1
    for t, step in enumerate(g.steps):
        for kw, arr in step.items():
            want = summarise(np.asarray(arr), act)
            assert _row(stored[f"steps/{kw}"][t]) == _row(want), (kw, t)
            checked += 1
    assert sorted(stored) == sorted([f"props/{n}" for n in g.properties]
                                    + [f"steps/{k}" for k in g.meta["step_keywords"]])
    return checked


@pytest.fixture(scope="module")
def case(tmp_path_factory):
    d = tmp_path_factory.mktemp("scase")
    return _write_case(str(d), synthetic_grid(*DIMS, seed=4, inactive_fraction=0.15))


def test_ingested_case_summaries_equal_summarise(case, tmp_path):
    # PORO (NaN in inactive cells), FIPNUM (int32), PORV (all cells, a 0), SWAT (0 at the
    # first cell: non-positive), PRESSURE (float64), 3 steps
    rep = ingest_grid(case, tmp_path / "c.zarr", chunks=CHUNKS)
    assert _check(rep.path) == 3 + 2 * 3


def test_special_values_across_slabs(tmp_path):
    g = synthetic_grid(9, 7, 8, seed=1, inactive_fraction=0.2)
    rng = np.random.default_rng(0)
    v = rng.normal(size=g.dims).astype(np.float32)
    v[:, :, 0:2] = np.nan                        # a slab without any finite value
    v[2, 3, 4], v[5, 1, 5] = np.inf, -np.inf      # infinities count as without value
    v[:, :, 6:8] = -np.abs(v[:, :, 6:8])          # a slab without positive values
    v[1, 1, 7] = 0.0
    g.properties["ODD"] = np.asfortranarray(v)
    g.properties["EMPTY"] = np.full(g.dims, np.nan, np.float32, order="F")
    g.properties["CODE"] = np.asfortranarray(rng.integers(-3, 9, g.dims).astype(np.int32))
    rep = write_grid_store(ModelSource(g), tmp_path / "s.zarr", chunks=(4, 3, 2))
    assert _check(rep.path) == len(g.properties) + sum(len(st) for st in g.steps)
    s = open_grid_store(rep.path).meta["summaries"]["props/EMPTY"]
    assert np.isnan(s.lo) and np.isnan(s.pos_hi) and s.count == g.nactive == s.nonfinite


def test_benchmark_case_writer_stores_them(tmp_path):
    import sys

    sys.path.insert(0, str(grid_cases().__file__).rsplit("/", 1)[0])
    try:
        import grid_store_case
    finally:
        sys.path.pop(0)
    rep = grid_store_case.write_store_case(tmp_path / "b.zarr", 20, 13, 9, steps=2,
                                           chunks=(8, 8, 4))
    assert _check(rep.path) == 2 + 2


def test_resumed_ingest_stores_the_same_summaries(case, tmp_path, monkeypatch):
    interrupted_ingest(monkeypatch, case, tmp_path / "r.zarr", chunks=CHUNKS)
    rep = ingest_grid(case, tmp_path / "r.zarr", chunks=CHUNKS)
    assert rep.resumed
    fresh = ingest_grid(case, tmp_path / "f.zarr", chunks=CHUNKS)
    a, b = (json.loads((p / "zarr.json").read_text())["attributes"]["summaries"]
            for p in (rep.path, fresh.path))
    assert a == b
    _check(rep.path)


def test_resumed_from_an_older_ingest_stores_none(case, tmp_path, monkeypatch):
    """Slabs recorded by a version without summaries: the store is written without them."""
    def stop(done):
        raise KeyboardInterrupt

    monkeypatch.setattr(grid_store, "_after_slab", stop)
    with pytest.raises(KeyboardInterrupt):
        ingest_grid(case, tmp_path / "o.zarr", chunks=CHUNKS)
    monkeypatch.setattr(grid_store, "_after_slab", None)
    prog = tmp_path / "o.zarr.partial.progress.json"
    state = json.loads(prog.read_text())
    for slab in state["slabs"]:
        del slab["summary"]
    prog.write_text(json.dumps(state))
    rep = ingest_grid(case, tmp_path / "o.zarr", chunks=CHUNKS)
    assert rep.resumed
    assert "summaries" not in json.loads((rep.path / "zarr.json").read_text())["attributes"]
    assert open_grid_store(rep.path).meta["summaries"] == {}


@pytest.fixture
def store(tmp_path):
    g = synthetic_grid(6, 5, 4, seed=2)
    g.steps = [{"SWAT": np.asfortranarray(g.properties["PORO"] * (t + 1))} for t in range(2)]
    g.step_dates = ["2001-01-01", "2001-02-01"]
    return write_grid_store(ModelSource(g), tmp_path / "v.zarr", chunks=(4, 4, 2)).path


def _drop_summaries(path) -> None:
    meta = json.loads((path / "zarr.json").read_text())
    del meta["attributes"]["summaries"]
    (path / "zarr.json").write_text(json.dumps(meta))


def test_older_store_without_summaries_opens(store):
    _drop_summaries(store)
    g = open_grid_store(store)
    assert g.meta["summaries"] == {}
    from geoshade.grid.lazy import stored_summary

    assert stored_summary(g, g.properties["PORO"]) is None


def test_damaged_summaries_are_one_line(store):
    meta = json.loads((store / "zarr.json").read_text())
    meta["attributes"]["summaries"]["props/PORO"] = [1, 2]
    (store / "zarr.json").write_text(json.dumps(meta))
    with pytest.raises(DamagedStoreError, match=r"damaged 'summaries' attribute .*7 numbers"):
        open_grid_store(store)


def test_stored_summary_is_only_for_the_stores_own_arrays(store):
    from geoshade.grid.lazy import stored_summary

    g = open_grid_store(store)
    act = np.asarray(g.actnum)
    assert _row(stored_summary(g, g.properties["PORO"])) == _row(
        summarise(np.asarray(g.properties["PORO"]), act))
    for t in range(2):
        assert _row(stored_summary(g, g.steps[t]["SWAT"])) == _row(
            summarise(np.asarray(g.steps[t]["SWAT"]), act))
    assert stored_summary(g, g.properties["PORO"] * 2) is None   # an expression's array
    assert stored_summary(CornerPointGrid(g.coord, np.asarray(g.zcorn)), act) is None


def test_view_uses_stored_summaries(ctx, store, monkeypatch):
    """The view takes a store's own summary without a pass over the array; an expression (and an
    older store) still gets summarise's pass; the pictures are the same."""
    from geoshade.grid import GridView

    calls = []
    real = cell_values.summarise

    def counted(values, active=None):
        calls.append(values)
        return real(values, active)

    import geoshade.grid.colours as grid_colours

    monkeypatch.setattr(cell_values, "summarise", counted)
    monkeypatch.setattr(grid_colours, "summarise", counted)   # the name the View's colours call
    opts = {"size": (96, 72), "ctx": ctx, "annotations": False}
    g = open_grid_store(store)
    with GridView(g, property="PORO", **opts) as v:
        img, st = v.draw(frames=1)
        v.update(property="SWAT", step=0)
        v.update(property="SWAT", step=1)
        assert not calls
        v.update(property="log10(PORO)")
        assert len(calls) == 1
    _drop_summaries(store)
    with GridView(open_grid_store(store), property="PORO", **opts) as w:
        ref, sr = w.draw(frames=1)
    assert len(calls) == 2
    np.testing.assert_array_equal(img, ref)
    assert st["color_range"] == sr["color_range"]
