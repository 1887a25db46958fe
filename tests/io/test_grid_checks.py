"""The checks behind the corruption suite of the grid inputs, one by one (issue 12): finite
geometry and inverted cells in the model, NaN/inf tokens read alike by both GRDECL paths, memory
checks, the ECLIPSE record walker, formatted files, filter bounds."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import resfo

import geoshade.io.grids.grdecl as gr
import geoshade.io.grids.grid_checks as gc
from geoshade.compute.grid.filters import MAX_DEPTH, MAX_LENGTH, cell_filter
from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.errors import InputError
from geoshade.io import paths
from geoshade.io.grids.ecl import load_case
from geoshade.io.grids.ecl_records import RecordError, data_bytes, scan
from geoshade.io.grids.grdecl import read_grdecl
from geoshade.models import CornerPointGrid

COORD = " ".join(f"{i} {j} 0 {i} {j} 10" for j in range(2) for i in range(3))


def _grdecl(tmp_path, extra="", zcorn="8*1 8*2 8*2 8*3", name="g.grdecl"):
    f = tmp_path / name
    f.write_text(f"SPECGRID\n 2 1 2 1 F /\nCOORD\n{COORD} /\nZCORN\n{zcorn} /\n{extra}")
    return f


def _err(fn, *args) -> str:
    with pytest.raises(InputError) as ei, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fn(*args)
    assert "\n" not in str(ei.value)
    return str(ei.value)


# --- the model ---------------------------------------------------------------------------------
def test_check_geometry_names_keyword_index_and_cell():
    g = synthetic_grid(4, 3, 2, seed=1)
    z = np.array(g.zcorn, order="F")
    q = 37
    z.reshape(-1, order="F")[q] = np.nan
    a, b, c = np.unravel_index(q, z.shape, order="F")
    msg = _err(CornerPointGrid, g.coord, z, g.actnum, None, {}, [], [], [], "", "G")
    assert msg == (f"G: ZCORN: value nan at index {q} (cell i={a // 2 + 1} j={b // 2 + 1} "
                   f"k={c // 2 + 1}) is not a finite depth (expected |z| <= 1e+10)")
    co = np.array(g.coord)
    co[2, 1, 4] = 3e38  # pillar i=2 j=1 (0-based), bottom y; file index (1·5 + 2)·6 + 4
    msg = _err(CornerPointGrid, co, g.zcorn, None, None, {}, [], [], [], "", "G")
    assert msg.startswith("G: COORD: value 3e+38 at index 46 (pillar i=3 j=2, bottom y) is not "
                          "a finite coordinate")


def test_bounds_and_depth_range_use_usable_values_only():
    from geoshade.grid.geometry import display_bounds

    g = synthetic_grid(6, 5, 3, seed=2)
    ref = g.bounds()
    lo, hi = g.active_depth_range()
    assert (lo, hi) == tuple(display_bounds(g)[:, 2])
    np.asarray(g.zcorn)[0, 0, 0] = np.nan  # damaged after construction
    np.asarray(g.zcorn)[1, 0, 0] = 3e38
    np.asarray(g.coord)[0, 0, 0] = np.inf
    b = g.bounds()
    assert np.isfinite(b).all() and b[1, 2] == ref[1, 2] and b[0, 0] >= ref[0, 0]
    lo2, hi2 = g.active_depth_range()
    assert np.isfinite([lo2, hi2]).all() and hi2 <= hi


def test_inverted_cells_counts_active_cells_only():
    g = synthetic_grid(5, 4, 3, seed=3, inactive_fraction=0.2)
    z = np.array(g.zcorn, order="F")
    act = np.argwhere(g.active)[:4]
    off = np.argwhere(~g.active)[:2]
    for i, j, k in np.concatenate([act, off]):
        z[2 * i, 2 * j, 2 * k], z[2 * i, 2 * j, 2 * k + 1] = (z[2 * i, 2 * j, 2 * k + 1] + 1,
                                                              z[2 * i, 2 * j, 2 * k])
    g2 = CornerPointGrid(g.coord, z, g.actnum)
    n, first = g2.inverted_cells()
    want = min((tuple(int(v) for v in c) for c in act), key=lambda c: (c[2], c[1], c[0]))
    assert n == 4 and first == want
    assert synthetic_grid(5, 4, 3, seed=3).inverted_cells() == (0, None)


# --- GRDECL tokens -----------------------------------------------------------------------------
@pytest.mark.parametrize("small", [True, False])
def test_nan_and_inf_tokens_read_alike_on_both_paths(tmp_path, monkeypatch, small):
    if not small:
        monkeypatch.setattr(gr, "SMALL_VALUES", 0)
    f = _grdecl(tmp_path, "PORO\n 0.1 nan -Infinity 1*NaN /\nMYPROP\n 1_0 2 3 4 /\n")
    with pytest.warns(UserWarning, match="keyword MYPROP"):  # 1_0 is not a number
        g = read_grdecl(f)
    p = g.properties["PORO"].ravel(order="F")
    assert p[0] == np.float32(0.1) and np.isnan(p[[1, 3]]).all() and p[2] == -np.inf
    assert "MYPROP" not in g.properties
    assert _err(read_grdecl, _grdecl(tmp_path, "PERMX\n 1_0 2 3 4 /\n")).endswith(
        "PERMX: non-numeric token '1_0' at value 1; expected 4 numbers (nx·ny·nz)")
    assert _err(read_grdecl, _grdecl(tmp_path, "ACTNUM\n 1 nan 2*1 /\n")).endswith(
        "ACTNUM: value 'nan' at value 2 is not an integer of 32 bits; expected 4 integers "
        "(nx·ny·nz)")
    assert "FIPNUM: value '2*3e38' at value 3 is not an integer" in _err(
        read_grdecl, _grdecl(tmp_path, "FIPNUM\n 1 1 2*3e38 /\n"))
    msg = _err(read_grdecl, _grdecl(tmp_path, zcorn="8*1 8*2 7*2 inf 8*3"))
    assert msg.endswith("ZCORN: value inf at index 23 (cell i=2 j=1 k=2) is not a finite depth "
                        "(expected |z| <= 1e+10)")


def test_memory_checks(tmp_path, monkeypatch):
    monkeypatch.setattr(paths, "mem_available", lambda: 50 << 20)
    f = _grdecl(tmp_path)
    f.write_text(f.read_text().replace(" 2 1 2 1 F /", " 300 100 100 1 F /"))
    assert gc.grid_bytes((300, 100, 100)) == 33 * 3 * 10**6 + 48 * 301 * 101
    with pytest.raises(paths.NotEnoughMemoryError) as ei:
        read_grdecl(f)
    assert str(ei.value) == (f"{f}: reading the grid of SPECGRID 300×100×100 (3e+06 cells: "
                             "ZCORN, COORD and ACTNUM) needs 95.8 MiB of memory and 50.0 MiB are "
                             "available (MemAvailable)")
    monkeypatch.setattr(paths, "mem_available", lambda: None)  # unknown: not refused here
    assert "COORD: expected" in _err(read_grdecl, f)


# --- ECLIPSE records ---------------------------------------------------------------------------
def test_data_bytes_agree_with_resfo(tmp_path):
    from resfo._unformatted.common import bytes_in_array

    for t in ("INTE", "REAL", "DOUB", "LOGI", "CHAR", "C010", "MESS"):
        for n in (0, 1, 104, 105, 106, 999, 1000, 1001, 2500):
            if t == "MESS" and n:
                continue
            assert data_bytes(n, t) == bytes_in_array(n, t.encode()), (t, n)
    f = tmp_path / "A.INIT"
    resfo.write(f, [("INTEHEAD", np.zeros(411, np.int32)), ("KEYS    ", np.array(["a"] * 300)),
                    ("STARTSOL", resfo.MESS), ("X       ", np.arange(2500.0))])
    recs = list(scan(f))
    assert [r.keyword for r in recs] == ["INTEHEAD", "KEYS", "STARTSOL", "X"]
    assert recs[-1].end == f.stat().st_size
    assert np.array_equal(recs[-1].read("f"), np.arange(2500.0))
    with pytest.raises(RecordError, match="X: values of type DOUB; expected INTE"):
        recs[-1].read("i")


def test_formatted_init_beside_binary_egrid(tmp_path):
    """A formatted INIT named .FINIT is read (resfo's formatted reader); damaged, one line."""
    g = synthetic_grid(3, 2, 2, seed=5, inactive_fraction=0)
    nx, ny, nz = g.dims
    head = np.zeros(100, np.int32)
    head[:4] = (1, nx, ny, nz)
    egrid = tmp_path / "C.EGRID"
    resfo.write(egrid, [("GRIDHEAD", head),
                        ("COORD   ", np.asarray(g.coord).transpose(1, 0, 2).reshape(-1)
                         .astype(np.float32)),
                        ("ZCORN   ", np.asarray(g.zcorn).ravel(order="F").astype(np.float32)),
                        ("ENDGRID ", np.zeros(0, np.int32))])
    ih = np.zeros(411, np.int32)
    ih[8:12] = (nx, ny, nz, g.ncells)
    poro = np.arange(g.ncells, dtype=np.float32) / 100
    resfo.write(tmp_path / "C.FINIT", [("INTEHEAD", ih), ("PORO    ", poro)],
                resfo.Format.FORMATTED)
    case = load_case(egrid)
    assert np.allclose(case.properties["PORO"].ravel(order="F"), poro)
    text = (tmp_path / "C.FINIT").read_text()
    for cut, kw in ((len(text) // 2, "INTEHEAD"), (len(text) - 10, "PORO")):
        (tmp_path / "C.FINIT").write_text(text[:cut])
        msg = _err(load_case, egrid)
        assert msg.startswith(f"{tmp_path / 'C.FINIT'}: {kw}: damaged formatted record"), msg


# --- filters -----------------------------------------------------------------------------------
def test_cell_filter_bounds():
    props = {"PORO": np.zeros((2, 1, 1))}
    assert f"at most {MAX_LENGTH}" in _err(cell_filter, "PORO > 0 " + " " * MAX_LENGTH + "x",
                                           props, (2, 1, 1))
    assert f"more than {MAX_DEPTH} levels" in _err(cell_filter, "not " * (MAX_DEPTH + 1) +
                                                   "PORO > 0", props, (2, 1, 1))
    assert "number 1e999 is not a finite float64" in _err(cell_filter, "PORO > 1e999", props,
                                                          (2, 1, 1))
    ok = cell_filter("not " * (MAX_DEPTH - 4) + "PORO > -1", props, (2, 1, 1))
    assert ok.all()
