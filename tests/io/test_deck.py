"""Decks (.DATA): INCLUDEs, edit keywords, faults, wells; well-trajectory files."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from geoshade.compute.grid.geometry import cell_centres
from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.errors import InputError
from geoshade.io import load
from geoshade.io.grids.deck import read_deck
from geoshade.io.grids.grdecl_writer import write_grdecl
from geoshade.io.grids.welltraj import read_wells


def _deck(tmp_path, body: str, grid=None):
    grid = grid or synthetic_grid(6, 5, 4, seed=5)
    inc = tmp_path / "include" / "grid"
    inc.mkdir(parents=True, exist_ok=True)
    write_grdecl(grid, inc / "g.grdecl")
    f = tmp_path / "model" / "CASE.DATA"
    f.parent.mkdir(exist_ok=True)
    f.write_text(body)
    return grid, f


BODY = """RUNSPEC
TITLE
 a title line with WORDS / and a slash
DIMENS
 6 5 4 /
OIL
WATER
START
 1 JAN 2000 /
PATHS
 'GRIDINC' '../include/grid' /
/
GRID
INCLUDE
 '$GRIDINC/g.grdecl' /
MULTIPLY
 PORO 2 1 3 1* 1* 1 1 /   -- only layer 1 of i = 1..3
/
EQUALS
 'MULTZ' 0.5 1 6 1 5 2 2 /
 NTG 0.7 /
/
COPY
 PORO PORX /
/
ADD
 PORX 1 /
/
PROPS
SWOF
 0 0 1 0
 1 1 0 0 /
SOLUTION
EQUIL
 2000 300 2100 0 0 0 1 0 20 /
SCHEDULE
WELSPECS
 'P1' 'G' 2 3 1* OIL /
 'I1' 'G' 5 1 1* WATER /
/
COMPDAT
 'P1' 2* 1 2 OPEN /
 'P1' 3 3 3 3 OPEN /
 'I*' 5 1 2 4 OPEN /
/
DATES
 1 FEB 2000 /
/
WCONPROD
 P1 OPEN ORAT 100 /
/
END
"""


def test_deck_with_paths_edits_and_wells(tmp_path):
    g, f = _deck(tmp_path, BODY)
    with pytest.warns(UserWarning, match="keywords not used by the grid reader") as rec:
        d = load(f)  # the reader registry picks read_deck
    assert len(rec) == 1
    msg = str(rec[0].message)
    assert msg.startswith(f"{f}: ") and "SWOF" in msg and "EQUIL" in msg
    assert d.dims == g.dims and np.array_equal(d.zcorn, g.zcorn)
    assert d.meta["format"] == "DATA deck"
    poro = g.properties["PORO"]
    exp = poro.copy()
    exp[0:3, :, 0] *= 2
    assert np.array_equal(d.properties["PORO"], exp)
    assert np.array_equal(d.properties["PORX"], exp + 1)
    mz = d.properties["MULTZ"]
    assert (mz[:, :, 1] == 0.5).all() and (mz[:, :, [0, 2, 3]] == 1.0).all()  # default 1
    assert (d.properties["NTG"] == np.float32(0.7)).all()
    assert [x.name for x in d.faults] == ["FA", "FB"]
    wells = {w.name: w for w in d.meta["wells"]}
    assert list(wells) == ["P1", "I1"]
    p1 = wells["P1"]
    assert p1.cells.tolist() == [[1, 2, 0], [1, 2, 1], [2, 2, 2]]
    assert np.allclose(p1.markers, cell_centres(d, p1.cells))
    # the pipe: top of the head column, then its completions' centres in COMPDAT order
    assert np.allclose(p1.points[1:], cell_centres(d, p1.cells))
    top = d.corners((slice(1, 2), slice(2, 3), slice(0, 1)))[0, 0, 0, :4].mean(axis=0)
    assert np.allclose(p1.points[0], top)
    assert wells["I1"].cells.tolist() == [[4, 0, 1], [4, 0, 2], [4, 0, 3]]


def test_deck_errors(tmp_path):
    _, f = _deck(tmp_path, BODY.replace("$GRIDINC/g.grdecl", "nowhere/g.grdecl"))
    with pytest.raises(InputError) as ei, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        read_deck(f)
    assert str(ei.value) == (f"{f}: INCLUDE 'nowhere/g.grdecl': no such file (looked in "
                             f"{f.parent}); --skip-missing reads the rest")
    _, f = _deck(tmp_path, BODY.replace("'P1' 3 3 3 3 OPEN", "'P1' 3 3 9 9 OPEN"))
    with pytest.raises(InputError, match=r"well P1: cell \(3, 3, 9\) is outside the grid"), \
            warnings.catch_warnings():
        warnings.simplefilter("ignore")
        read_deck(f)
    _, f = _deck(tmp_path, BODY.replace("DIMENS\n 6 5 4", "DIMENS\n 6 5 5"))
    with pytest.raises(InputError, match=r"SPECGRID: \(6, 5, 4\) differs from the grid size"):
        read_deck(f)


@pytest.mark.data
def test_reek_deck(shared_data):
    deck = shared_data / "reek_cornerpoint" / "model" / "2_R001_REEK-0.DATA"
    init = shared_data / "reek_cornerpoint" / "opm_flow_run" / "2_R001_REEK-0.INIT"
    if not deck.is_file():
        pytest.skip("Reek deck is absent")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        g = read_deck(deck)
    assert g.dims == (40, 64, 14) and g.nactive == 35820
    assert [f.name for f in g.faults] == ["F1", "F2", "F3", "F4", "F5", "F6"]
    names = [w.name for w in g.meta["wells"]]
    assert names == ["OP_1", "OP_2", "OP_3", "WI_1", "WI_2", "OP_4", "OP_5", "WI_3"]
    op2 = g.meta["wells"][1]
    assert op2.cells[:3].tolist() == [[19, 14, 0], [19, 14, 1], [18, 14, 1]]  # 1-based 20 15 1..
    assert np.allclose(op2.markers, cell_centres(g, op2.cells))
    assert len(op2.points) == len(op2.cells) + 1   # head, then each completion
    types = {w.name: w.type for w in g.meta["wells"]}   # WCONHIST / WCONINJH
    assert types == {**{f"OP_{n}": "producer" for n in range(1, 6)},
                     **{f"WI_{n}": "water injector" for n in range(1, 4)}}
    if init.is_file():  # the deck's edits give the simulator's INIT values
        from geoshade.io.grids.ecl import load_case

        case = load_case(init.with_suffix(".EGRID"))
        act = case.active
        for name in ("PORO", "PERMX", "PERMZ", "SWL", "SWCR", "SGU", "MULTZ", "FIPNUM",
                     "EQLNUM", "SWATINIT"):
            assert np.allclose(g.properties[name][act], case.properties[name][act],
                               rtol=1e-6), name


def test_read_wells_file(tmp_path):
    f = tmp_path / "w.txt"
    f.write_text("# two wells\nWELL OP 1\n0 0 1000\n10 0 1100 # TD\nMARKER 5 0 1050 top\n\n"
                 "well B\n1 2 3\n")
    ws = read_wells(f)
    assert [w.name for w in ws] == ["OP 1", "B"]
    assert ws[0].points.tolist() == [[0, 0, 1000], [10, 0, 1100]]
    assert ws[0].markers.tolist() == [[5, 0, 1050]] and ws[0].cells.tolist() == [[-1, -1, -1]]
    assert ws[1].markers.shape == (0, 3)
    for text, msg in (("1 2 3\n", ":1: expected a 'WELL name' line"),
                      ("WELL A\n1 2\n", ":2: expected a point as 3 numbers"),
                      ("WELL A\n1 2 x\n", ":2: expected a point as 3 numbers 'x y z'"),
                      ("WELL A\nMARKER 1 2\n", ":2: expected MARKER x y z [label]"),
                      ("WELL A\nWELL B\n1 2 3\n", ":1: well A has no trajectory points"),
                      ("# nothing\n", ": no wells")):
        f.write_text(text)
        with pytest.raises(InputError) as ei:
            read_wells(f)
        assert str(ei.value).startswith(str(f)) and msg in str(ei.value), text


def test_deck_well_types_and_completion_states(tmp_path):
    body = BODY.replace("WELSPECS\n", "WELSPECS\n 'G1' 'G' 1 1 1* GAS /\n"
                        " 'U1' 'G' 1 2 1* OIL /\n", 1)
    body += ("WCONPROD\n 'P*' OPEN ORAT 100 /\n/\nWCONINJE\n 'I1' WATER OPEN RATE 50 /\n"
             " 'G1' GAS OPEN RATE 5 /\n/\nCOMPDAT\n 'I1' 5 1 3 3 SHUT /\n/\n")
    _, f = _deck(tmp_path, body)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        g = read_deck(f)
    wells = {w.name: w for w in g.meta["wells"]}
    assert {n: w.type for n, w in wells.items()} == {
        "G1": "gas injector", "U1": "unknown", "P1": "producer", "I1": "water injector"}
    i1 = wells["I1"]   # the later SHUT record of layer 3 closes it and keeps its place
    assert i1.cells.tolist() == [[4, 0, 1], [4, 0, 2], [4, 0, 3]]
    assert i1.cell_open.tolist() == [True, False, True]
    assert wells["P1"].cell_open.all()
    assert len(wells["U1"].points) == g.dims[2] + 1   # no completion: down its head column
