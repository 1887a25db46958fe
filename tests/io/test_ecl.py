"""EGRID / INIT / UNRST through resfo: Reek against xtgeo and against the GRDECL reader."""

from __future__ import annotations

import shutil
import warnings

import numpy as np
import pytest
import resfo

from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.errors import InputError
from geoshade.io import describe, format_description, load
from geoshade.io.grids.ecl import (
    LazyStep,
    UnrstIndex,
    load_case,
    read_egrid,
    read_init,
    read_unrst,
    step_property,
)
from geoshade.io.grids.grdecl import read_grdecl


def _kw(name: str) -> str:
    return f"{name:<8}"


def _write_case(folder, grid, nsteps=3, init=True, zcorn_cut=0):
    """A small EGRID/INIT/UNRST case written with resfo from a synthetic grid."""
    nx, ny, nz = grid.dims
    head = np.zeros(100, np.int32)
    head[:4] = (1, nx, ny, nz)
    z = np.asarray(grid.zcorn).reshape(-1, order="F").astype(np.float32)
    egrid = folder / "CASE.EGRID"
    resfo.write(egrid, [
        (_kw("GRIDHEAD"), head),
        (_kw("COORD"), np.asarray(grid.coord).transpose(1, 0, 2).reshape(-1).astype(np.float32)),
        (_kw("ZCORN"), z[:z.size - zcorn_cut]),
        (_kw("ACTNUM"), np.asarray(grid.actnum).reshape(-1, order="F").astype(np.int32)),
        (_kw("ENDGRID"), np.zeros(0, np.int32))])
    mask = grid.active.reshape(-1, order="F")
    ih = np.zeros(411, np.int32)
    ih[8:12] = (nx, ny, nz, grid.nactive)
    if init:
        resfo.write(folder / "CASE.INIT", [
            (_kw("INTEHEAD"), ih),
            (_kw("PORO"), grid.properties["PORO"].reshape(-1, order="F")[mask]),
            (_kw("FIPNUM"), grid.properties["FIPNUM"].reshape(-1, order="F")[mask])])
    entries = []
    for k in range(nsteps):
        ihk = ih.copy()
        ihk[64:67] = (1, k + 1, 2001)
        sw = np.full(grid.nactive, 0.1 * k, np.float32)
        entries += [(_kw("SEQNUM"), np.array([k * 10], np.int32)), (_kw("INTEHEAD"), ihk),
                    (_kw("SWAT"), sw), (_kw("PRESSURE"), sw + 100)]
    resfo.write(folder / "CASE.UNRST", entries)
    return egrid


def test_synthetic_case_round_trip(tmp_path):
    g = synthetic_grid(5, 4, 3, seed=4)
    egrid = _write_case(tmp_path, g)
    case = load(egrid)  # the reader registry picks load_case
    assert case.dims == g.dims and case.nactive == g.nactive
    assert np.array_equal(case.zcorn, g.zcorn)
    assert np.array_equal(case.coord, np.asarray(g.coord, np.float32))
    assert np.array_equal(case.properties["PORO"][g.active], g.properties["PORO"][g.active])
    assert np.isnan(case.properties["PORO"][~g.active]).all()
    assert case.properties["FIPNUM"].dtype == np.int32
    assert (case.properties["FIPNUM"][~g.active] == 0).all()
    assert case.step_dates == ["2001-01-01", "2001-02-01", "2001-03-01"]
    assert case.meta["unrst_seqnum"] == [0, 10, 20]
    assert [float(np.nanmax(s["SWAT"])) for s in case.steps] == pytest.approx([0, 0.1, 0.2])
    # lazy steps read the same arrays, on access
    lazy = load_case(egrid, eager_bytes=0)
    assert all(isinstance(s, LazyStep) for s in lazy.steps)
    assert "SWAT" in lazy.steps[1] and sorted(lazy.steps[1]) == ["PRESSURE", "SWAT"]
    for k in range(3):
        assert np.array_equal(lazy.steps[k]["PRESSURE"], case.steps[k]["PRESSURE"],
                              equal_nan=True)
    assert np.array_equal(step_property(lazy, 2, "SWAT"), case.steps[2]["SWAT"], equal_nan=True)
    only = load_case(egrid, keywords=["swat"])
    assert only.meta["step_keywords"] == ["SWAT"]
    d = describe(case)
    assert d["steps"] == 3 and d["step_keywords"] == ["SWAT", "PRESSURE"]
    assert "steps    3 (2001-01-01 .. 2001-03-01)" in format_description(d)


def _one_line(fn, *args, **kw) -> str:
    with pytest.raises(InputError) as ei:
        fn(*args, **kw)
    assert "\n" not in str(ei.value)
    return str(ei.value)


def test_bad_cases_give_one_line(tmp_path):
    g = synthetic_grid(4, 3, 2, seed=1)
    a = tmp_path / "a"
    a.mkdir()
    egrid = _write_case(a, g, init=False)
    alone = load_case(egrid)  # a grid file alone: its geometry, and what INIT would add
    assert alone.dims == g.dims and not alone.properties and len(alone.steps) == 3
    assert alone.meta["notes"][0] == "no INIT beside the grid: CASE.INIT would add its properties"
    b = tmp_path / "b"
    b.mkdir()
    egrid = _write_case(b, g, zcorn_cut=5)
    assert _one_line(read_egrid, egrid) == (f"{egrid}: ZCORN: expected 192 values "
                                            "(2·nx·2·ny·2·nz) for GRIDHEAD 4×3×2, got 187")
    c = tmp_path / "c"
    c.mkdir()
    case = load_case(_write_case(c, g))
    assert _one_line(step_property, case, 3, "SWAT") == (
        f"{case.name}: step 3 does not exist; the case has 3 report steps (0-2)")
    lazy = load_case(c / "CASE.EGRID", eager_bytes=0)
    assert _one_line(step_property, lazy, -1, "SWAT").endswith(
        "step -1 does not exist; the case has 3 report steps (0-2)")
    assert _one_line(step_property, lazy, 0, "SOIL").endswith(
        "SOIL is not in report step 0; it has SWAT, PRESSURE")
    assert "SOIL: not in any report step" in _one_line(UnrstIndex, c / "CASE.UNRST", case,
                                                       ["SOIL"])
    other = synthetic_grid(4, 3, 2, seed=1, inactive_fraction=0.3)
    assert "INTEHEAD: the file is for a 4×3×2 grid with" in _one_line(
        read_init, c / "CASE.INIT", other)
    (tmp_path / "junk.EGRID").write_bytes(b"not an egrid at all")
    assert _one_line(read_egrid, tmp_path / "junk.EGRID").startswith(f"{tmp_path / 'junk.EGRID'}")


# --- Reek --------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def opm(shared_data):
    d = shared_data / "reek_cornerpoint" / "opm_flow_run"
    if not (d / "2_R001_REEK-0.UNRST").is_file():
        pytest.skip("Reek OPM run is absent")
    return d


@pytest.mark.data
def test_reek_egrid_and_grdecl_same_geometry(opm, shared_data):
    grdecl = read_grdecl(shared_data / "reek_cornerpoint/include/grid/reek.grid")
    for egrid in (opm / "2_R001_REEK-0.EGRID",
                  shared_data / "reek_cornerpoint/model/2_R001_REEK-0.EGRID"):
        e = read_egrid(egrid)
        assert e.dims == grdecl.dims and e.units == grdecl.units == "METRES"
        assert np.array_equal(e.zcorn, grdecl.zcorn)
        assert np.allclose(e.coord, grdecl.coord, rtol=1e-7, atol=0)  # float32 in the EGRID
        assert np.allclose(e.corners(), grdecl.corners(), rtol=1e-6, atol=1e-3)
        assert np.allclose(e.mapaxes, grdecl.mapaxes, rtol=1e-7)
        # the simulator deactivated 3 of the GRDECL's active cells (pore volume / pinch-out)
        assert e.nactive == 35817 and grdecl.nactive == 35820
        assert not (e.active & ~grdecl.active).any()


@pytest.mark.data
def test_reek_case_equals_xtgeo(opm):
    xtgeo = pytest.importorskip("xtgeo")
    case = load_case(opm / "2_R001_REEK-0.EGRID")
    xg = xtgeo.grid_from_file(opm / "2_R001_REEK-0.EGRID", fformat="egrid")
    assert case.dims == tuple(xg.dimensions) and case.nactive == xg.nactive == 35817
    act = case.active
    for name in ("PORO", "PERMX", "NTG", "FIPNUM", "PORV"):
        xp = xtgeo.gridproperty_from_file(opm / "2_R001_REEK-0.INIT", fformat="init", name=name,
                                          grid=xg)
        assert np.array_equal(case.properties[name][act],
                              np.asarray(xp.values.data, case.properties[name].dtype)[act]), name
    # UNRST: 37 monthly steps in file order, values equal xtgeo's by date
    assert len(case.steps) == len(case.step_dates) == 37
    assert case.step_dates[0] == "2000-01-01" and case.step_dates[-1] == "2003-01-01"
    assert case.step_dates == sorted(case.step_dates)
    assert case.meta["unrst_seqnum"] == sorted(case.meta["unrst_seqnum"])
    for k in (0, 12, 36):
        date = int(case.step_dates[k].replace("-", ""))
        for name in ("SWAT", "PRESSURE"):
            xp = xtgeo.gridproperty_from_file(opm / "2_R001_REEK-0.UNRST", fformat="unrst",
                                              name=name, date=date, grid=xg)
            assert np.allclose(case.steps[k][name][act], np.asarray(xp.values.data)[act],
                               rtol=1e-6, atol=0), (name, k)
    # the water front moves: SWAT differs between the first and the last step
    assert np.nanmax(np.abs(case.steps[-1]["SWAT"] - case.steps[0]["SWAT"])) > 0.05


@pytest.mark.data
def test_reek_unrst_reader_and_missing_init(opm, tmp_path):
    grid = read_egrid(opm / "2_R001_REEK-0.EGRID")
    seen = []
    steps, dates = read_unrst(opm / "2_R001_REEK-0.UNRST", grid, keywords=["SWAT"],
                              progress=lambda d, t: seen.append(d))
    assert len(steps) == len(dates) == 37 and seen == list(range(1, 38))
    assert all(list(s) == ["SWAT"] for s in steps)
    shutil.copy(opm / "2_R001_REEK-0.EGRID", tmp_path / "R.EGRID")
    alone = load_case(tmp_path / "R.EGRID")  # the EGRID alone: geometry, and what would add more
    assert alone.nactive == grid.nactive and not alone.properties and not alone.steps
    assert alone.meta["notes"] == ["grid file alone: geometry only (R.INIT would add its "
                                   "properties, R.UNRST its report steps)"]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        text = format_description(describe(load(opm / "2_R001_REEK-0.EGRID")))
    assert "active 35,817" in text and "steps    37" in text
