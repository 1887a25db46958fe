"""Block-centred decks (DX/DY/DZ/TOPS, DXV/DYV/DZV/DEPTHZ, BOX, EQUALS) against OPM.

The oracle is the EGRID that OPM Flow (``opm-simulators`` from PyPI) writes when it starts on
the same deck: its COORD and ZCORN are OPM's ``EclipseGrid`` of the deck, stored in float32.
OPM reads only the raw DX/DY/DZ/TOPS keywords (no BOX or EQUALS), so a deck that uses those is
compared with OPM's grid of the same deck written out in full.  xtgeo reads corner-point
GRDECL only (no block-centred keywords), so it is no oracle here.
"""

from __future__ import annotations

import subprocess
import sys
import warnings

import numpy as np
import pytest

from geoshade.errors import InputError
from geoshade.io import load
from geoshade.io.grids.block_centred import depthz_geometry, dtops_geometry, fill_tops
from geoshade.io.grids.deck import read_deck
from geoshade.io.grids.grdecl import read_grdecl

# what OPM Flow needs to start (two phases, one of everything); not read by geoshade's grid
_REST = """PORO
 {n}*0.2 /
PERMX
 {n}*100 /
PERMY
 {n}*100 /
PERMZ
 {n}*10 /
PROPS
PVTW
 200 1.0 4e-5 0.5 0 /
PVDO
 100 1.01 1.0
 300 1.00 1.0 /
DENSITY
 800 1000 1 /
ROCK
 200 1e-5 /
SWOF
 0.1 0 1 0
 0.9 1 0 0 /
SOLUTION
EQUIL
 1000 200 2000 0 0 0 /
SCHEDULE
TSTEP
 1 /
END
"""


def _arr(a) -> str:
    """A cell array in file order (i fastest), 8 values a line."""
    v = [f"{x:.10g}" for x in np.ravel(a, order="F")]
    return "\n".join(" " + " ".join(v[i:i + 8]) for i in range(0, len(v), 8))


def _deck(path, dims, grid: str, units: str = "METRIC"):
    nx, ny, nz = dims
    path.write_text(f"RUNSPEC\nDIMENS\n {nx} {ny} {nz} /\nOIL\nWATER\n{units}\nSTART\n 1 'JAN' "
                    "2020 /\nWELLDIMS\n 2 2 1 2 /\nTABDIMS\n 1 1 10 10 /\nUNIFOUT\nGRID\n"
                    f"{grid}" + _REST.format(n=nx * ny * nz))
    return path


def _opm_grid(deck):
    """COORD (nx+1, ny+1, 6) and ZCORN (2nx, 2ny, 2nz) of the EGRID OPM Flow writes."""
    pytest.importorskip("opm.simulators", reason="OPM Flow (pip install opm-simulators)")
    resfo = pytest.importorskip("resfo")
    code = ("import sys; from opm.simulators import BlackOilSimulator as B; "
            "s = B(sys.argv[1]); s.step_init()")
    run = subprocess.run([sys.executable, "-c", code, deck.name], cwd=deck.parent,
                         capture_output=True, text=True, timeout=120)
    egrid = deck.with_suffix(".EGRID")
    assert egrid.exists(), run.stdout[-2000:] + run.stderr[-2000:]
    kw = {k.strip(): np.asarray(v) for k, v in resfo.read(egrid)}
    nx, ny, nz = (int(v) for v in kw["GRIDHEAD"][1:4])
    return (kw["COORD"].reshape(ny + 1, nx + 1, 6).transpose(1, 0, 2),
            kw["ZCORN"].reshape((2 * nx, 2 * ny, 2 * nz), order="F"))


def _read(f, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return (read_deck if f.suffix == ".DATA" else read_grdecl)(f, **kw)


def _same_as_opm(grid, opm) -> None:
    coord, zcorn = opm
    np.testing.assert_array_equal(grid.coord.astype(np.float32), coord)
    np.testing.assert_array_equal(grid.zcorn, zcorn)


SPE1 = (10, 10, 3)
SPE1_GRID = ("DX\n 300*1000 /\nDY\n 300*1000 /\nDZ\n 100*20 100*30 100*50 /\n"
             "TOPS\n 100*8325 /\n")


def test_spe1_like_field_deck_equals_opm(tmp_path):
    """SPE1's grid as SPE1 writes it (FIELD units, TOPS for the top layer only)."""
    f = _deck(tmp_path / "SPE1.DATA", SPE1, SPE1_GRID, "FIELD")
    g = _read(f)
    assert g.dims == SPE1 and g.units == "FEET" and g.meta["unit_system"] == "FIELD"
    assert g.meta["geometry"] == "block-centred (DX, DY, DZ, TOPS)"
    assert g.properties["PORO"].shape == SPE1 and "DX" not in g.properties
    assert float(g.zcorn[0, 0, -1]) == 8325 + 100 and g.bounds()[1][0] == 10_000
    _same_as_opm(g, _opm_grid(f))


def test_box_and_equals_equal_the_full_arrays(tmp_path):
    """EQUALS and BOX (which OPM's grid ignores) give the grid OPM makes from full arrays."""
    full = _deck(tmp_path / "FULL.DATA", SPE1, SPE1_GRID, "FIELD")
    equals = _deck(tmp_path / "EQ.DATA", SPE1,
                   "EQUALS\n 'DX' 1000 /\n 'DY' 1000 /\n 'TOPS' 8325 1 10 1 10 1 1 /\n"
                   " 'DZ' 20 4* 1 1 /\n 'DZ' 30 4* 2 2 /\n 'DZ' 50 4* 3 3 /\n/\n", "FIELD")
    box = _deck(tmp_path / "BOX.DATA", SPE1,
                "DX\n 100*1000 /\nDY\n 100*1000 /\nBOX\n 1 10 1 10 1 1 /\nTOPS\n 100*8325 /\n"
                "DZ\n 100*20 /\nENDBOX\nBOX\n 1 10 1 10 2 3 /\nDZ\n 100*30 100*10 /\nENDBOX\n"
                "MULTIPLY\n 'DZ' 5 1 10 1 10 3 3 /\n/\n", "FIELD")
    opm = _opm_grid(full)
    for f in (equals, box):
        _same_as_opm(_read(f), opm)


def test_irregular_cells_equal_opm(tmp_path):
    """Sizes that change cell by cell and layer by layer (slanted pillars), TOPS per column
    (steps between columns), TOPS of the deeper layers given and consistent to 1e-7."""
    rng = np.random.default_rng(7)
    dims = nx, ny, nz = 5, 4, 3
    dx, dy = rng.uniform(50, 150, dims).round(2), rng.uniform(40, 80, dims).round(2)
    dz = rng.uniform(1, 10, dims).round(3)
    tops = np.empty(dims)
    tops[:, :, 0] = rng.uniform(1000, 1010, (nx, ny)).round(3)
    for k in range(1, nz):
        tops[:, :, k] = tops[:, :, k - 1] + dz[:, :, k - 1] + 1e-7  # snapped to the sum
    grid = f"DX\n{_arr(dx)} /\nDY\n{_arr(dy)} /\nDZ\n{_arr(dz)} /\n"
    top_only = _deck(tmp_path / "TOP.DATA", dims, grid + f"TOPS\n{_arr(tops[:, :, 0])} /\n")
    every = _deck(tmp_path / "ALL.DATA", dims, grid + f"TOPS\n{_arr(tops)} /\n")
    opm = _opm_grid(top_only)
    _same_as_opm(_read(top_only), opm)
    _same_as_opm(_read(every), opm)


def test_top_layer_sizes_and_vectors_equal_opm(tmp_path):
    """DX/DY given for the top layer only (the layers below repeat it); DZV and DXV."""
    rng = np.random.default_rng(3)
    dims = nx, ny, nz = 4, 3, 5
    f = _deck(tmp_path / "V.DATA", dims,
              f"DX\n{_arr(rng.uniform(10, 20, (nx, ny)).round(1))} /\nDYV\n"
              f"{_arr(rng.uniform(5, 9, ny).round(2))} /\nDZV\n{_arr(np.arange(1, nz + 1))} /\n"
              f"TOPS\n{_arr(rng.uniform(2000, 2005, (nx, ny)).round(2))} /\n")
    g = _read(f)
    assert g.meta["geometry"] == "block-centred (DX, DYV, DZV, TOPS)"
    _same_as_opm(g, _opm_grid(f))


def test_depthz_equals_opm(tmp_path):
    """DXV/DYV/DZV + DEPTHZ: a tilted, bumpy top surface at the pillars (as a GRDECL too)."""
    rng = np.random.default_rng(5)
    dims = nx, ny, nz = 6, 4, 3
    depthz = 1500 + 3.5 * np.arange(nx + 1)[:, None] + rng.uniform(0, 2, (nx + 1, ny + 1))
    grid = (f"DXV\n{_arr(rng.uniform(80, 120, nx).round(1))} /\nDYV\n {ny}*75.5 /\n"
            f"DZV\n 2.5 4 1.25 /\nDEPTHZ\n{_arr(depthz.round(4))} /\n")
    f = _deck(tmp_path / "DZ.DATA", dims, grid)
    g = _read(f)
    assert g.meta["geometry"] == "block-centred (DXV, DYV, DZV, DEPTHZ)"
    opm = _opm_grid(f)
    _same_as_opm(g, opm)
    gf = tmp_path / "dz.grdecl"
    gf.write_text(f"SPECGRID\n {nx} {ny} {nz} 1 F /\n{grid}")
    grdecl = _read(gf)
    assert "unit_system" not in grdecl.meta and grdecl.units == ""
    _same_as_opm(grdecl, opm)


def test_rules_without_opm():
    """The documented rules on small arrays (run everywhere, OPM or not)."""
    # TOPS of a deeper layer: the sum, snapped within 1e-6, or kept (a gap stays a gap)
    tops = np.array([[[100.0, np.nan, 130.0 + 5e-7, 200.0]]])
    assert fill_tops(tops, np.full((1, 1, 4), 15.0))[0, 0].tolist() == [100, 115, 130, 200]
    one = np.ones((1, 1, 2))
    coord, zcorn, moved = dtops_geometry(2 * one, 3 * one, 10 * one,
                                         np.array([[[0.0, 15.0]]]))
    assert zcorn[0, 0].tolist() == [0, 10, 15, 25] and moved == 0
    assert coord[1, 1].tolist() == [2, 3, 0, 2, 3, 20]
    # an overlap is cut at the bottom of the cell above (OPM's fixupZCORN)
    _, zcorn, moved = dtops_geometry(one, one, 10 * one, np.array([[[0.0, 8.0]]]))
    assert zcorn[0, 0].tolist() == [0, 10, 10, 18] and moved == 2
    # DEPTHZ: corners follow the surface; each layer adds DZV
    coord, zcorn, _ = depthz_geometry(np.array([1.0]), np.array([1.0]), np.array([2.0, 3.0]),
                                      np.array([[10.0, 11.0], [12.0, 13.0]]))
    assert zcorn[:, :, 0].tolist() == [[10, 11], [12, 13]]
    assert zcorn[1, 1].tolist() == [13, 15, 15, 18] and coord[1, 0].tolist() == [1, 0, 12,
                                                                                  1, 0, 17]


def test_grdecl_and_edits(tmp_path):
    """A GRDECL file with block-centred keywords; COPY/ADD on them in a deck; top-layer DZ."""
    f = tmp_path / "b.grdecl"
    f.write_text("SPECGRID\n 2 2 2 1 F /\nDX\n 8*10 /\nDY\n 4*20 /\nDZ\n 4*1 4*2 /\n"
                 "TOPS\n 4*100 /\nPORO\n 8*0.3 /\n")
    g = _read(f)
    assert g.zcorn[0, 0].tolist() == [100, 101, 101, 103] and g.coord[2, 2, :2].tolist() == \
        [20, 40]
    f.write_text("SPECGRID\n 2 2 2 1 F /\nEQUALS\n DX 10 /\n DY 20 /\n DZ 1 /\n TOPS 100 4* 1 1 /\n"
                 " PORO 0.25 /\n/\nMULTIPLY\n DZ 2 4* 2 2 /\n/\n")  # a GRDECL file edits too
    g2 = _read(f)
    np.testing.assert_array_equal(g2.zcorn, g.zcorn)
    assert g2.properties["PORO"].min() == 0.25 and g2.meta["skipped_keywords"] == []
    d = _deck(tmp_path / "E.DATA", (2, 2, 2), "DX\n 4*10 /\nCOPY\n DX DY /\n DX DZ /\n/\n"
              "ADD\n DZ -9 /\n/\nTOPS\n 4*100 /\n", "LAB")
    g = _read(d)
    assert g.coord[2, 2, :2].tolist() == [20, 20] and g.zcorn[0, 0].tolist() == [100, 101, 101,
                                                                                  102]
    assert g.units == "CM" and g.meta["unit_system"] == "LAB"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert load(d).meta["geometry"] == "block-centred (DX, DY, DZ, TOPS)"


@pytest.mark.parametrize("grid, message", [
    ("DX\n 3*1 /\nDY\n 8*1 /\nDZ\n 8*1 /\nTOPS\n 4*0 /\n",
     "DX: expected 8 values (nx·ny·nz), or at least the top layer's 4 (nx·ny), got 3 values"),
    ("DX\n 8*1 1 /\nDY\n 8*1 /\nDZ\n 8*1 /\nTOPS\n 4*0 /\n", "got 9 values"),
    # a repeat that runs past the grid: the same words whether numba's scanner is loaded or not
    ("DX\n 9*1 /\nDY\n 8*1 /\nDZ\n 8*1 /\nTOPS\n 4*0 /\n",
     "got a non-numeric value or a repeat running past the grid"),
    ("DX\n 8*1 /\nDY\n 8*1 /\nTOPS\n 4*0 /\n",
     "block-centred geometry without DZ; expected DX (or DXV), DY (or DYV), DZ (or DZV) and "
     "TOPS, or DXV, DYV, DZV and DEPTHZ; --skip-missing shows the cells in IJK index space"),
    ("DX\n 8*1 /\nDY\n 8*1 /\nDZ\n 4*1 2*-1 2*1 /\nTOPS\n 4*0 /\n",
     "DZ: value -1 at cell i=1 j=1 k=2; expected a finite size >= 0"),
    ("EQUALS\n DX 1 /\n DY 1 /\n DZ 1 /\n TOPS 0 1 1 1 2 1 1 /\n/\n",
     "TOPS: no value for cell i=2 j=1 k=1; expected a value for every cell of the top layer"),
    ("DXV\n 1 2 3 /\n", "DXV: expected 2 values (nx), got 3"),
    ("DXV\n 2*1 /\nDYV\n 2*1 /\nDZV\n 2*1 /\nDEPTHZ\n 8*0 /\n",
     "DEPTHZ: expected 9 values ((nx+1)·(ny+1)), got 8"),
    ("DX\n 8*1 /\nDY\n 8*1 /\nDZ\n 8*x /\n", "DZ: expected 8 values (nx·ny·nz), or at least"),
    ("DX\n 8*1 /\nDY\n 8*1 /\nDZ\n 8*1 /\nTOPS\n 4*0 /\nCOORD\n 54*0 /\nZCORN\n 64*0 /\n",
     "both COORD/ZCORN and block-centred DX, DY, DZ, TOPS; expected one kind of geometry"),
])
def test_bad_block_centred_input(tmp_path, grid, message):
    f = tmp_path / "BAD.DATA"
    f.write_text(f"RUNSPEC\nDIMENS\n 2 2 2 /\nGRID\n{grid}")
    with pytest.raises(InputError) as ei:
        _read(f)
    text = str(ei.value)
    assert text.startswith(f"{f}: ") and message in text and "\n" not in text
