"""The old ECLIPSE GRID file: cells' corners written with resfo (from xtgeo's corners of an EGRID,
the oracle), read back as a corner-point grid; told from GRDECL text of the same suffix."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import resfo

from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.errors import InputError
from geoshade.io import load
from geoshade.io.grids.ecl import load_case, read_egrid
from geoshade.io.grids.ecl_gridfile import is_ecl_grid, read_ecl_grid
from geoshade.io.grids.grdecl_writer import write_grdecl

xtgeo = pytest.importorskip("xtgeo")


def _kw(name: str) -> str:
    return f"{name:<8}"


def _egrid(folder, g):
    nx, ny, nz = g.dims
    head = np.zeros(100, np.int32)
    head[:4] = (1, nx, ny, nz)
    path = folder / "SRC.EGRID"
    fh = np.zeros(100, np.int32)
    fh[:2] = (3, 2007)
    resfo.write(path, [
        (_kw("FILEHEAD"), fh), (_kw("GRIDUNIT"), ["METRES", ""]), (_kw("GRIDHEAD"), head),
        (_kw("COORD"), np.asarray(g.coord).transpose(1, 0, 2).reshape(-1).astype(np.float32)),
        (_kw("ZCORN"), np.asarray(g.zcorn).reshape(-1, order="F").astype(np.float32)),
        (_kw("ACTNUM"), np.asarray(g.actnum).reshape(-1, order="F").astype(np.int32)),
        (_kw("ENDGRID"), np.zeros(0, np.int32))])
    return path


def _xtgeo_corners(egrid) -> tuple[np.ndarray, np.ndarray]:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        x = xtgeo.grid_from_file(egrid, relative_to="origin")
        nx, ny, nz = x.dimensions
        c = np.stack([p.values.data for p in x.get_xyz_corners()], -1)
        return c.reshape(nx, ny, nz, 8, 3), np.asarray(x.get_actnum().values.filled(0))


def _cells(corners, act, only_active=False, width=5, k_offset=0):
    nx, ny, nz = act.shape
    recs = []
    for k in range(nz):
        for j in range(ny):
            for i in range(nx):
                if only_active and not act[i, j, k]:
                    continue
                co = [i + 1, j + 1, k + 1 + k_offset, 1 + i + nx * (j + ny * k), int(act[i, j, k]),
                      0, 0][:width]
                recs += [(_kw("COORDS"), np.int32(co)),
                         (_kw("CORNERS"), corners[i, j, k].astype(np.float32).ravel())]
    return recs


def write_grid_file(folder, g, name="CASE.GRID", only_active=False, fmt=resfo.Format.UNFORMATTED,
                    dual=False):
    corners, act = _xtgeo_corners(_egrid(folder, g))
    nz = g.dims[2] * (2 if dual else 1)
    recs = [(_kw("DIMENS"), np.int32([g.dims[0], g.dims[1], nz])), (_kw("RADIAL"), ["FALSE"]),
            *_cells(corners, act, only_active)]
    if dual:
        frac = act.copy()
        frac[0, 0, 0] = 0
        recs += _cells(corners, frac, k_offset=g.dims[2])
    resfo.write(folder / name, recs, fmt)
    return folder / name, corners, act


def test_binary_grid_equals_xtgeo_corners(tmp_path):
    g = synthetic_grid(5, 4, 3, seed=7)
    path, corners, act = write_grid_file(tmp_path, g)
    grid = read_ecl_grid(path)
    assert grid.dims == g.dims and grid.meta["format"] == "GRID"
    assert np.allclose(grid.corners(), corners, rtol=0, atol=1e-3)
    assert np.array_equal(grid.active, act != 0)
    src = read_egrid(tmp_path / "SRC.EGRID")
    assert np.array_equal(grid.zcorn, src.zcorn)


def test_formatted_grid_equals_binary(tmp_path):
    g = synthetic_grid(3, 2, 2, seed=1)
    b, _, _ = write_grid_file(tmp_path, g)
    f, _, _ = write_grid_file(tmp_path, g, "CASE.FGRID", fmt=resfo.Format.FORMATTED)
    gb, gf = read_ecl_grid(b), read_ecl_grid(f)
    assert gf.meta["format"] == "FGRID"
    assert np.array_equal(gb.zcorn, gf.zcorn) and np.array_equal(gb.coord, gf.coord)


def test_active_cells_only_gridfile_1(tmp_path):
    g = synthetic_grid(5, 4, 3, seed=7)
    path, corners, act = write_grid_file(tmp_path, g, only_active=True)
    grid = read_ecl_grid(path)
    a = act != 0
    assert grid.meta["cells_written"] == int(a.sum()) < g.ncells
    assert np.array_equal(grid.active, a)
    assert np.allclose(grid.corners()[a], corners[a], atol=1e-3)


def test_dual_porosity_grid_file_has_two_media(tmp_path):
    g = synthetic_grid(3, 3, 2, seed=5)
    path, corners, act = write_grid_file(tmp_path, g, dual=True)
    grid = read_ecl_grid(path)
    assert grid.dims == g.dims and grid.media == ("matrix", "fracture")
    frac = grid.select_medium("fracture")
    assert frac.nactive == int((act != 0).sum()) - int(act[0, 0, 0] != 0)
    assert np.allclose(grid.corners(), corners, atol=1e-3)


def test_lgr_in_a_grid_file(tmp_path):
    g = synthetic_grid(3, 3, 1, seed=5)
    path, _, _ = write_grid_file(tmp_path, g)
    recs = [(k.ljust(8), v) for k, v in resfo.read(path)]
    sub = np.array([[[x, y, z] for z in (10.0, 11.0) for y in (0.0, 0.5) for x in (0.0, 0.5)]],
                   np.float32)
    lgr = []
    for j in range(2):
        for i in range(2):
            c = sub[0] + np.array([0.5 * i, 0.5 * j, 0], np.float32)
            lgr += [(_kw("COORDS"), np.int32([i + 1, j + 1, 1, 1 + i + 2 * j, 1, 5, 0])),
                    (_kw("CORNERS"), c.ravel())]
    recs += [(_kw("LGR"), ["FINE", "GLOBAL"]), (_kw("DIMENS"), np.int32([2, 2, 1])),
             (_kw("LGRILG"), np.int32([2, 2, 2, 2, 1, 1])), *lgr]
    resfo.write(path, recs)
    grid = read_ecl_grid(path)
    (r,) = grid.refinements
    assert r.name == "FINE" and r.dims == (2, 2, 1) and r.box_text() == "I=2 J=2 K=1"
    assert np.allclose(r.grid.corners()[1, 1, 0, 7], [1.0, 1.0, 11.0])


def test_grid_suffix_is_told_apart_by_content(tmp_path):
    g = synthetic_grid(3, 2, 2, seed=1)
    path, _, _ = write_grid_file(tmp_path, g, name="A.grid")
    text = tmp_path / "B.grid"
    write_grdecl(g, text)
    assert is_ecl_grid(path) and not is_ecl_grid(text)
    assert load(path).meta["format"] == "GRID"
    assert np.array_equal(load(text).zcorn, g.zcorn)


def test_a_grid_file_opens_its_case(tmp_path):
    """INIT beside an old GRID is read; without it a note says what would add properties."""
    g = synthetic_grid(3, 2, 2, seed=1)
    path, _, act = write_grid_file(tmp_path, g)
    alone = load_case(path)
    assert alone.meta["notes"] == ["grid file alone: geometry only (CASE.INIT would add its "
                                   "properties, CASE.UNRST its report steps)"]
    head = np.zeros(411, np.int32)
    head[8:12] = (*g.dims, int((act != 0).sum()))
    poro = np.arange(int((act != 0).sum()), dtype=np.float32)
    resfo.write(tmp_path / "CASE.INIT", [(_kw("INTEHEAD"), head), (_kw("PORO"), poro)])
    case = load_case(tmp_path / "CASE.INIT")
    active = (act != 0).reshape(-1, order="F")
    assert case.meta["format"] == "GRID"
    assert np.array_equal(case.properties["PORO"].reshape(-1, order="F")[active], poro)


@pytest.mark.parametrize("change, message", [
    (lambda r: r[1:], "DIMENS: not found"),
    (lambda r: [*r[:2], (_kw("COORDS"), np.int32([9, 1, 1, 1, 1])), *r[3:]],
     "COORDS: cell 1 is I=9 J=1 K=1, outside DIMENS 3×2×2"),
    (lambda r: [*r[:3], (_kw("CORNERS"), np.zeros(20, np.float32)), *r[4:]],
     "CORNERS: expected 24 values"),
])
def test_damaged_grid_files_give_one_line(tmp_path, change, message):
    g = synthetic_grid(3, 2, 2, seed=1)
    path, _, _ = write_grid_file(tmp_path, g)
    recs = [(k.ljust(8), v) for k, v in resfo.read(path)]
    resfo.write(path, change(recs))
    with pytest.raises(InputError) as ei:
        read_ecl_grid(path)
    assert message in str(ei.value) and "\n" not in str(ei.value)
