"""The GRDECL writer: exact round trip through our reader, read back by xtgeo, atomic, progress."""

from __future__ import annotations

import sys

import numpy as np
import pytest

import geoshade.io.grids.grdecl_writer as gw
from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.errors import InputError
from geoshade.io import load
from geoshade.io.grids.grdecl_writer import write_grdecl
from tests.io.test_grdecl import xtgeo_zcorn


def test_write_read_round_trip_is_exact(tmp_path):
    g = synthetic_grid(9, 6, 5, seed=7)
    calls = []
    f = write_grdecl(g, tmp_path / "rt.GRDECL", progress=lambda d, t: calls.append((d, t)))
    values = g.coord.size + g.zcorn.size + g.actnum.size + sum(
        v.size for v in g.properties.values())
    assert calls and calls[-1] == (values, values)  # progress counts values, ends at the total
    assert [d for d, _ in calls] == sorted(d for d, _ in calls)
    assert "*" in f.read_text()  # N*value compression was used
    h = load(f)  # through the reader registry
    assert np.array_equal(h.coord, g.coord) and np.array_equal(h.zcorn, g.zcorn)
    assert np.array_equal(h.actnum, g.actnum) and np.array_equal(h.mapaxes, g.mapaxes)
    for k, v in g.properties.items():
        assert np.array_equal(h.properties[k], v) and h.properties[k].dtype == v.dtype, k
    for a, b in zip(g.faults, h.faults, strict=True):
        assert a.name == b.name
        assert np.array_equal(np.unique(a.faces, axis=0), np.unique(b.faces, axis=0))
    assert h.units == "METRES"
    assert not list(tmp_path.glob(".*.tmp"))  # atomic: no temporary left


def test_several_blocks_and_no_bar_without_a_callback(tmp_path, monkeypatch):
    monkeypatch.setattr(gw, "WRITE_BLOCK", 97)  # many blocks per array, runs cut by blocks
    monkeypatch.setitem(sys.modules, "tqdm", None)  # io draws no bar: tqdm is never imported
    g = synthetic_grid(6, 5, 4, seed=2)
    h = load(write_grdecl(g, tmp_path / "b.grdecl"))
    assert np.array_equal(h.zcorn, g.zcorn) and np.array_equal(h.coord, g.coord)
    for k, v in g.properties.items():
        assert np.array_equal(h.properties[k], v), k


def test_xtgeo_reads_what_we_write(tmp_path):
    xtgeo = pytest.importorskip("xtgeo")
    g = synthetic_grid(8, 6, 5, seed=11)
    f = write_grdecl(g, tmp_path / "x.grdecl")
    xg = xtgeo.grid_from_file(f, fformat="grdecl", relative_to="origin")
    assert tuple(xg.dimensions) == g.dims and xg.nactive == g.nactive
    assert np.array_equal(xg._actnumsv != 0, g.actnum != 0)
    assert np.array_equal(xtgeo_zcorn(xg, g.dims), g.zcorn)
    # xtgeo keeps COORD in float32 precision
    assert np.array_equal(xg._coordsv.astype(np.float32), np.asarray(g.coord, np.float32))
    xp = xtgeo.gridproperty_from_file(f, fformat="grdecl", name="PORO", grid=xg)
    assert np.array_equal(np.asarray(xp.values, np.float32)[g.active],
                          g.properties["PORO"][g.active])


def test_writer_refuses_missing_folder(tmp_path):
    with pytest.raises(InputError, match="output folder"):
        write_grdecl(synthetic_grid(2, 2, 2), tmp_path / "no" / "x.grdecl")
