"""Sector models: the cells selected by a filter, slice and plane written as GRDECL and as
EGRID + INIT, read back equal to the selection through geoshade, xtgeo and resfo."""

from __future__ import annotations

import numpy as np
import pytest

import geoshade.grid
from geoshade.cli.main import main
from geoshade.compute.grid.geometry import cell_centres
from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.errors import InputError
from geoshade.grid.export import cell_volumes, selected_cells
from geoshade.io import load
from geoshade.io.grids.grdecl_writer import write_grdecl

xtgeo = pytest.importorskip("xtgeo")
resfo = pytest.importorskip("resfo")

FILTER, SLICE = "PORO > 0.18 and PERMX > 50", "i=2:9,j=1:7"


@pytest.fixture(scope="module")
def grid():
    return synthetic_grid(11, 9, 5, inactive_fraction=0.15, seed=3)


def _expected(g):
    """The selection computed here from its definition (numpy): active, in the box, passing."""
    m = g.active.copy()
    m &= (g.properties["PORO"] > 0.18) & (g.properties["PERMX"] > 50)
    box = np.zeros(g.dims, bool)
    box[2:9, 1:7, :] = True
    return m & box


def _box_of(m):
    idx = np.argwhere(m)
    lo, hi = idx.min(axis=0), idx.max(axis=0) + 1
    return tuple(slice(int(a), int(b)) for a, b in zip(lo, hi, strict=True))


def test_selection_is_the_definition(grid):
    m = selected_cells(grid, filter=FILTER, slice=SLICE)
    assert np.array_equal(m, _expected(grid)) and 0 < m.sum() < grid.nactive


def test_plane_keeps_the_cells_whose_centre_is_above(grid):
    depth = cell_centres(grid)[..., 2]
    mid = float(np.median(depth[grid.active]))
    m = selected_cells(grid, plane=f"0,0,1,{-mid}")  # z up: keep z >= -mid, depth <= mid
    assert np.array_equal(m, grid.active & (depth <= mid))


def test_grdecl_sector_reads_back_through_geoshade_and_xtgeo(grid, tmp_path):
    out = geoshade.grid.export_sector(grid, tmp_path / "S.grdecl", filter=FILTER, slice=SLICE)
    sel = _expected(grid)
    box = _box_of(sel)
    assert out.box == box and out.cells == int(sel.sum())
    back = load(tmp_path / "S.grdecl")
    assert back.dims == tuple(s.stop - s.start for s in box)
    assert np.array_equal(back.active, sel[box])
    assert np.array_equal(back.corners(), grid.corners(box))  # every digit kept
    for name, arr in grid.properties.items():
        assert np.array_equal(back.properties[name], arr[box]), name
    # xtgeo: dimensions, active cells, a property and the cell corners
    xg = xtgeo.grid_from_file(tmp_path / "S.grdecl")
    assert xg.dimensions == back.dims and xg.nactive == out.cells
    assert np.array_equal(xg.get_actnum().values.filled(0) != 0, sel[box])
    poro = xtgeo.gridproperty_from_file(tmp_path / "S.grdecl", name="PORO", grid=xg)
    assert np.allclose(poro.values[sel[box]], grid.properties["PORO"][box][sel[box]],
                       rtol=0, atol=1e-7)
    i, j, k = (int(v) for v in np.argwhere(sel[box])[0])
    xc = np.asarray(xg.get_xyz_cell_corners((i + 1, j + 1, k + 1), activeonly=False,
                                            zerobased=False)).reshape(8, 3)
    ours = back.corners()[i, j, k]
    t = back.map_transform()  # xtgeo gives map coordinates (MAPAXES applied)
    ours[:, :2] = ours[:, :2] @ t[:2, :2].T + t[:2, 2]
    assert np.allclose(np.sort(xc, axis=0), np.sort(ours, axis=0), rtol=0, atol=1e-3)


def test_egrid_sector_reads_back_through_resfo_xtgeo_and_geoshade(grid, tmp_path):
    out = geoshade.grid.export_sector(grid, tmp_path / "S.EGRID", filter=FILTER, slice=SLICE)
    sel = _expected(grid)
    box = _box_of(sel)
    assert [p.name for p in out.files] == ["S.EGRID", "S.INIT"]
    nx, ny, nz = (s.stop - s.start for s in box)
    # resfo: the records and their values
    recs = {kw.strip(): v for kw, v in resfo.read(tmp_path / "S.EGRID")}
    assert next(iter(recs)) == "FILEHEAD" and "ENDGRID" in recs
    assert recs["GRIDHEAD"][:4].tolist() == [1, nx, ny, nz]
    assert np.array_equal(recs["ACTNUM"], sel[box].reshape(-1, order="F").astype(np.int32))
    assert np.array_equal(recs["ZCORN"], np.asarray(grid.zcorn)[
        2 * box[0].start:2 * box[0].stop, 2 * box[1].start:2 * box[1].stop,
        2 * box[2].start:2 * box[2].stop].reshape(-1, order="F").astype(np.float32))
    coord = np.asarray(grid.coord)[box[0].start:box[0].stop + 1, box[1].start:box[1].stop + 1]
    assert np.array_equal(recs["COORD"], coord.transpose(1, 0, 2).reshape(-1)
                          .astype(np.float32))
    init = {kw.strip(): v for kw, v in resfo.read(tmp_path / "S.INIT")}
    assert init["INTEHEAD"][8:12].tolist() == [nx, ny, nz, out.cells]
    assert init["PORO"].size == out.cells  # active cells only, as simulators write
    assert np.array_equal(init["PORO"], grid.properties["PORO"][box].reshape(-1, order="F")[
        sel[box].reshape(-1, order="F")])
    # PORV against VTK's own cell volumes (an independent integration of the hexahedra)
    vtk_vol = _vtk_volumes(out.grid)
    want = vtk_vol * out.grid.properties["PORO"] * out.grid.properties["NTG"]
    want[~sel[box]] = 0
    assert np.allclose(init["PORV"], want.reshape(-1, order="F"), rtol=1e-6, atol=0)
    # xtgeo reads both files
    xg = xtgeo.grid_from_file(tmp_path / "S.EGRID")
    assert xg.dimensions == (nx, ny, nz) and xg.nactive == out.cells
    xp = xtgeo.gridproperty_from_file(tmp_path / "S.INIT", name="PERMX", grid=xg,
                                      fformat="init")
    assert np.array_equal(np.asarray(xp.values[sel[box]], np.float32),
                          grid.properties["PERMX"][box][sel[box]])
    # geoshade reads the case (EGRID + INIT)
    back = load(tmp_path / "S.EGRID")
    assert np.array_equal(back.active, sel[box]) and back.units == grid.units
    assert np.array_equal(back.zcorn, np.asarray(grid.zcorn)[2 * box[0].start:2 * box[0].stop,
                                                             2 * box[1].start:2 * box[1].stop,
                                                             2 * box[2].start:2 * box[2].stop])
    for name in grid.properties:
        assert np.array_equal(back.properties[name][back.active],
                              grid.properties[name][box][sel[box]]), name


def _vtk_volumes(g):
    pytest.importorskip("pyvista")
    from geoshade.io.interop.pyvista_io import grid_to_pyvista

    esg = grid_to_pyvista(g, step=None)
    esg.cell_data.remove("vtkGhostType")  # VTK's filters skip hidden cells
    return np.asarray(esg.compute_cell_sizes(length=False, area=False)["Volume"]).reshape(
        g.dims, order="F")


def test_cell_volumes_match_vtk(grid):
    assert np.allclose(cell_volumes(grid), _vtk_volumes(grid), rtol=1e-12, atol=0)


def test_faults_cut_to_the_box(grid):
    out, _ = geoshade.grid.export.cut_sector(grid, _expected(grid))
    for f in out.faults:
        assert (f.faces[:, :3] >= 0).all() and (f.faces[:, :3] < out.dims).all()
    assert sum(len(f.faces) for f in out.faults) > 0


def test_cli_export_and_failures_leave_nothing(tmp_path, capsys, grid):
    case = tmp_path / "case.grdecl"
    write_grdecl(grid, case)
    rc = main(["grid", "export", str(case), "--filter", FILTER, "--slice", SLICE,
               "-o", str(tmp_path / "sector.egrid")])
    text = capsys.readouterr().out
    assert rc == 0 and "sector I=" in text
    assert sorted(p.name for p in tmp_path.iterdir()) == ["case.grdecl", "sector.egrid",
                                                          "sector.init"]
    rc = main(["grid", "export", str(case), "--filter", "PORO > 5", "-o",
               str(tmp_path / "none.grdecl")])
    err = capsys.readouterr().err
    assert rc == 2 and "no cell is selected" in err and len(err.strip().splitlines()) == 1
    rc = main(["grid", "export", str(case), "-o", str(case)])
    assert rc == 2 and "names an input" in capsys.readouterr().err
    rc = main(["grid", "export", str(case), "-o", str(tmp_path / "s.vtu")])
    assert rc == 2 and "expected a name ending in" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["case.grdecl", "sector.egrid",
                                                          "sector.init"]


def test_long_names_refused_before_writing(tmp_path):
    g = synthetic_grid(3, 3, 2)
    g.properties["PERMEABILITY"] = g.properties["PERMX"]
    with pytest.raises(InputError, match="1 to 8 ASCII characters"):
        geoshade.grid.export_sector(g, tmp_path / "S.EGRID")
    assert list(tmp_path.iterdir()) == []
