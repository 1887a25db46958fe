"""Local grid refinements: EGRID, INIT and UNRST LGR sections written with resfo as OPM Flow and
ECLIPSE lay them out (see geoshade.io.grids.lgr), read back and compared with resfo's arrays."""

from __future__ import annotations

import numpy as np
import pytest
import resfo

from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.errors import InputError
from geoshade.io.grids.ecl import load_case, read_egrid
from geoshade.io.grids.ecl_info import describe_case_parts, format_case_parts
from geoshade.models import CornerPointGrid

NX, NY, NZ = 4, 3, 2
#: the LGR: hosts I=2..3 J=1..2 K=2 (1-based), each split 2×2×1
BOX, SUB = ((1, 2), (0, 1), (1, 1)), (4, 4, 1)


def _kw(name: str) -> str:
    return f"{name:<8}"


def _box_grid(dims, x0=0.0, y0=0.0, z0=100.0, d=1.0) -> CornerPointGrid:
    nx, ny, nz = dims
    i, j = np.meshgrid(np.arange(nx + 1.0), np.arange(ny + 1.0), indexing="ij")
    coord = np.stack([x0 + i * d, y0 + j * d, 0 * i, x0 + i * d, y0 + j * d, 0 * i + 1], -1)
    zc = np.empty((2 * nx, 2 * ny, 2 * nz), np.float32)
    for k in range(nz):
        zc[..., 2 * k], zc[..., 2 * k + 1] = z0 + k, z0 + k + 1
    return CornerPointGrid(coord, zc)


def _grid_records(g: CornerPointGrid, lgr_nr: int = 0) -> list:
    nx, ny, nz = g.dims
    head = np.zeros(100, np.int32)
    head[:5] = (1, nx, ny, nz, lgr_nr)
    return [(_kw("GRIDHEAD"), head),
            (_kw("COORD"), np.asarray(g.coord).transpose(1, 0, 2).reshape(-1).astype(np.float32)),
            (_kw("ZCORN"), np.asarray(g.zcorn).reshape(-1, order="F").astype(np.float32)),
            (_kw("ACTNUM"), np.asarray(g.actnum).reshape(-1, order="F").astype(np.int32))]


def _hostnum() -> np.ndarray:
    """1-based global host of each LGR cell (i fastest), two LGR cells a host along i and j."""
    li, lj, lk = np.meshgrid(*(np.arange(n) for n in SUB), indexing="ij")
    gi, gj, gk = BOX[0][0] + li // 2, BOX[1][0] + lj // 2, BOX[2][0] + lk
    return (gi + NX * (gj + NY * gk) + 1).reshape(-1, order="F").astype(np.int32)


def _head(dims, nact, date=(1, 1, 2001)) -> np.ndarray:
    h = np.zeros(411, np.int32)
    h[8:12] = (*dims, nact)
    h[64:67] = date
    return h


def write_lgr_case(folder, nsteps=2, lgr_active=None, init_lgr=True, unrst=True):
    """A 4×3×2 case with one LGR (named LGR1, 4×4×1 in I=2..3 J=1..2 K=2); returns the EGRID.

    Global PORO = cell number / 100, LGR PORO = 0.5 + LGR cell number / 1000; SWAT of step k:
    global 0.1·k, LGR 0.2 + 0.1·k (the LGR's INTEHEAD carries the LGR's own sizes)."""
    g = synthetic_grid(NX, NY, NZ, seed=3)
    g.actnum = np.ones(g.dims, np.uint8)
    lgr = _box_grid(SUB, 1.0, 0.0, 101.0, 0.5)
    if lgr_active is not None:
        lgr.actnum = lgr_active
    n, nl = g.ncells, lgr.ncells
    fh = np.zeros(100, np.int32)
    fh[:2] = (3, 2007)
    egrid = folder / "LCASE.EGRID"
    end = np.zeros(0, np.int32)
    resfo.write(egrid, [(_kw("FILEHEAD"), fh), *_grid_records(g), (_kw("ENDGRID"), end),
                        (_kw("LGR"), ["LGR1"]), (_kw("LGRPARNT"), [""]), *_grid_records(lgr, 1),
                        (_kw("HOSTNUM"), _hostnum()), (_kw("ENDGRID"), end),
                        (_kw("ENDLGR"), end)])
    la = lgr.active.reshape(-1, order="F")
    init = [(_kw("INTEHEAD"), _head(g.dims, n)),
            (_kw("PORO"), (np.arange(n) / 100).astype(np.float32))]
    if init_lgr:
        init += [(_kw("LGR"), ["LGR1"]),
                 (_kw("LGRHEADI"), np.array([1, 100] + [0] * 43, np.int32)),
                 (_kw("INTEHEAD"), _head(lgr.dims, int(la.sum()))),
                 (_kw("PORO"), (0.5 + np.arange(nl)[la] / 1000).astype(np.float32)),
                 (_kw("LGRSGONE"), np.zeros(0, np.int32))]
    init.append((_kw("TABDIMS"), np.zeros(100, np.int32)))
    resfo.write(folder / "LCASE.INIT", init)
    if unrst:
        recs = []
        for k in range(nsteps):
            recs += [(_kw("SEQNUM"), np.array([k], np.int32)),
                     (_kw("INTEHEAD"), _head(g.dims, n, (1, k + 1, 2001))),
                     (_kw("STARTSOL"), resfo.MESS), (_kw("SWAT"), np.full(n, 0.1 * k, np.float32)),
                     (_kw("LGRNAMES"), ["LGR1"]), (_kw("ENDSOL"), resfo.MESS),
                     (_kw("LGR"), ["LGR1"]), (_kw("INTEHEAD"), _head(lgr.dims, int(la.sum()))),
                     (_kw("STARTSOL"), resfo.MESS),
                     (_kw("SWAT"), np.full(int(la.sum()), 0.2 + 0.1 * k, np.float32)),
                     (_kw("ENDSOL"), resfo.MESS), (_kw("ENDLGR"), np.zeros(1, np.int32))]
        resfo.write(folder / "LCASE.UNRST", recs)
    return egrid


def _arrays(path) -> list[tuple[str, np.ndarray]]:
    return [(k.strip(), v) for k, v in resfo.read(path)]


def test_egrid_lgr_geometry_equals_resfo(tmp_path):
    egrid = write_lgr_case(tmp_path)
    g = read_egrid(egrid)
    (r,) = g.refinements
    recs = _arrays(egrid)
    lgr_at = next(q for q, (k, _) in enumerate(recs) if k == "LGR")
    sec = dict(recs[lgr_at:])
    assert r.name == "LGR1" and r.parent == "" and r.dims == SUB
    assert np.array_equal(r.grid.coord.transpose(1, 0, 2).reshape(-1), sec["COORD"])
    assert np.array_equal(r.grid.zcorn.reshape(-1, order="F"), sec["ZCORN"])
    assert np.array_equal(r.hostnum.reshape(-1, order="F") + 1, sec["HOSTNUM"])
    assert r.host_box == BOX and r.label() == "LGR1 4×4×1 in I=2..3 J=1..2 K=2"
    # the global grid is the first section's, untouched by the LGR's records after it
    assert g.dims == (NX, NY, NZ)
    assert np.array_equal(g.zcorn.reshape(-1, order="F"), dict(recs[:lgr_at])["ZCORN"])
    hosts = g.host_cells()
    assert hosts.sum() == 4 and hosts[1:3, 0:2, 1].all()


def test_init_and_unrst_lgr_sections_are_the_lgrs(tmp_path):
    """The LGR's INTEHEAD (4×4×1) is not read as the global one; its arrays go to its grid."""
    egrid = write_lgr_case(tmp_path, nsteps=3)
    case = load_case(egrid)
    (r,) = case.refinements
    init = _arrays(egrid.with_suffix(".INIT"))
    poro = [v for k, v in init if k == "PORO"]
    assert np.array_equal(case.properties["PORO"].reshape(-1, order="F"), poro[0])
    assert np.array_equal(r.grid.properties["PORO"].reshape(-1, order="F"), poro[1])
    swat = [v for k, v in _arrays(egrid.with_suffix(".UNRST")) if k == "SWAT"]
    assert len(case.steps) == len(r.grid.steps) == 3
    for k in range(3):
        assert np.array_equal(case.steps[k]["SWAT"].reshape(-1, order="F"), swat[2 * k])
        assert np.array_equal(r.grid.steps[k]["SWAT"].reshape(-1, order="F"), swat[2 * k + 1])
    assert r.grid.step_dates == case.step_dates == ["2001-01-01", "2001-02-01", "2001-03-01"]
    assert "TABDIMS" not in r.grid.properties  # a global record after LGRSGONE


def test_lgr_steps_lazy_equal_eager(tmp_path):
    egrid = write_lgr_case(tmp_path, nsteps=3)
    eager, lazy = load_case(egrid), load_case(egrid, eager_bytes=0)
    for k in range(3):
        assert np.array_equal(lazy.refinements[0].grid.steps[k]["SWAT"],
                              eager.refinements[0].grid.steps[k]["SWAT"])
    view = lazy.refinements[0].grid.meta["unrst"]
    assert view.keywords == ["SWAT"] and view.lgr == "LGR1"


def test_inactive_lgr_cells_map_to_nan(tmp_path):
    act = np.ones(SUB, np.uint8)
    act[0, 0, 0] = act[3, 3, 0] = 0
    case = load_case(write_lgr_case(tmp_path, lgr_active=act))
    sub = case.refinements[0].grid
    assert sub.nactive == 14
    assert np.isnan(sub.properties["PORO"][~sub.active]).all()
    assert np.isnan(sub.steps[1]["SWAT"][~sub.active]).all()
    assert np.allclose(sub.steps[1]["SWAT"][sub.active], 0.3)


def test_without_restart_or_init_the_lgrs_stay(tmp_path):
    """No UNRST: the refined cells keep their INIT properties; no INIT: their geometry, and
    info lists them either way."""
    case = load_case(write_lgr_case(tmp_path, unrst=False))
    assert case.refinements[0].grid.properties and not case.refinements[0].grid.steps
    (tmp_path / "LCASE.INIT").unlink()
    alone = load_case(tmp_path / "LCASE.EGRID")
    assert len(alone.refinements) == 1 and not alone.refinements[0].grid.properties
    d = describe_case_parts(alone)
    assert d["lgrs"][0]["host_box"] == [[2, 3], [1, 2], [2, 2]]
    lines = format_case_parts(d)
    assert lines[1].startswith("    LGR1 4×4×1 in I=2..3 J=1..2 K=2: 16 cells, 16 active, 4 host")
    assert any("LCASE.INIT would add its properties" in x for x in lines)


def test_an_init_without_the_lgr_section_says_so(tmp_path):
    case = load_case(write_lgr_case(tmp_path, init_lgr=False))
    sub = case.refinements[0].grid
    assert not sub.properties and "no section for LGR LGR1" in sub.meta["notes"][0]


def test_pyvista_has_the_refined_cells(tmp_path):
    pv = pytest.importorskip("pyvista")
    case = load_case(write_lgr_case(tmp_path))
    mb = case.to_pyvista(step=1)
    assert isinstance(mb, pv.MultiBlock) and mb.keys() == ["GLOBAL", "LGR1"]
    ghost = np.asarray(mb["GLOBAL"].cell_data["vtkGhostType"]).reshape(case.dims, order="F")
    assert ((ghost & 32) != 0).sum() == 4 and (ghost[1:3, 0:2, 1] & 32).all()
    lgr = mb["LGR1"]
    assert lgr.n_cells == 16 and np.allclose(lgr.cell_data["SWAT"], 0.3)
    assert np.asarray(lgr.field_data["geoshade_host_box"]).tolist() == [2, 3, 1, 2, 2, 2]


def _rewrite(path, change):
    recs = [(f"{k:<8}", v) for k, v in change(_arrays(path))]
    resfo.write(path, recs)


@pytest.mark.parametrize("damage, message", [
    (lambda r: [x for x in r if x[0] != "HOSTNUM"], "LGR LGR1: HOSTNUM: not found"),
    (lambda r: [(k, v + 100 if k == "HOSTNUM" else v) for k, v in r],
     "LGR LGR1: HOSTNUM: host cell 114 outside the 4×3×2 parent grid (1..24)"),
    (lambda r: [(k, v[:-1] if k == "HOSTNUM" else v) for k, v in r],
     "LGR LGR1: HOSTNUM: expected 16 values (the LGR's cells), got 15"),
    (lambda r: [(k, ["NOSUCH"] if k == "LGRPARNT" else v) for k, v in r],
     "LGR LGR1: LGRPARNT: parent NOSUCH is not a grid defined before it"),
])
def test_damaged_lgr_sections_give_one_line(tmp_path, damage, message):
    egrid = write_lgr_case(tmp_path)

    def change(recs):
        cut = next(q for q, (k, _) in enumerate(recs) if k == "LGR")
        return recs[:cut] + damage(recs[cut:])

    _rewrite(egrid, change)
    with pytest.raises(InputError) as ei:
        load_case(egrid)
    assert message in str(ei.value) and "\n" not in str(ei.value)


def test_lgr_zcorn_of_the_wrong_size_names_the_lgr(tmp_path):
    egrid = write_lgr_case(tmp_path)
    _rewrite(egrid, lambda r: [(k, v[:-8] if k == "ZCORN" and v.size == 128 else v)
                               for k, v in r])
    with pytest.raises(InputError, match=r"LGR LGR1: ZCORN: expected 128 values"):
        load_case(egrid)


def test_a_restart_lgr_section_with_a_wrong_intehead_names_the_lgr(tmp_path):
    egrid = write_lgr_case(tmp_path)

    def change(recs):
        out, inside = [], False
        for k, v in recs:
            inside = (inside or k == "LGR") and k != "ENDLGR"
            if inside and k == "INTEHEAD":
                v = v.copy()
                v[8] = 5
            out.append((k, v))
        return out

    _rewrite(egrid.with_suffix(".UNRST"), change)
    with pytest.raises(InputError, match=r"\(LGR LGR1\): INTEHEAD: the file is for a 5×4×1"):
        load_case(egrid)
