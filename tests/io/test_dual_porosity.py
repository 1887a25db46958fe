"""Dual porosity / dual permeability: EGRID, INIT and UNRST written with resfo as ECLIPSE lays them
out (FILEHEAD item 6, ACTNUM 0..3, the matrix's then the fracture's active cells), and with the
deck's doubled NZ; both media read back equal to resfo's arrays."""

from __future__ import annotations

import numpy as np
import pytest
import resfo

from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.errors import InputError
from geoshade.io.grids.ecl import load_case, read_egrid
from geoshade.io.grids.ecl_info import describe_case_parts, format_case_parts

DIMS = (4, 3, 2)


def _kw(name: str) -> str:
    return f"{name:<8}"


def _head(nz, nact, month=1) -> np.ndarray:
    h = np.zeros(411, np.int32)
    h[8:12] = (DIMS[0], DIMS[1], nz, nact)
    h[64:67] = (1, month, 2001)
    return h


def write_dual(folder, kind=1, doubled=False, nsteps=2):
    """A dual case: matrix all active but cell 0, fracture active in every second cell.

    ACTNUM 0..3 (ECLIPSE) or, ``doubled``, NZ 4 with the fracture layers repeating the matrix
    layers' corners (ACTNUM 0/1 per half). PORO: matrix 0.2 + n/1000, fracture 0.01 + n/1000
    over each medium's active cells n; SWAT of step k: matrix 0.1·k, fracture 0.5 + 0.1·k."""
    g = synthetic_grid(*DIMS, seed=2)
    n = g.ncells
    m = np.ones(n, bool)
    m[0] = False
    f = np.arange(n) % 2 == 1
    nm, nf = int(m.sum()), int(f.sum())
    fh = np.zeros(100, np.int32)
    fh[:2], fh[5] = (3, 2007), kind
    head = np.zeros(100, np.int32)
    coord = np.asarray(g.coord).transpose(1, 0, 2).reshape(-1).astype(np.float32)
    z = np.asarray(g.zcorn).reshape(-1, order="F").astype(np.float32)
    if doubled:
        head[:4] = (1, DIMS[0], DIMS[1], 2 * DIMS[2])
        z, act = np.concatenate([z, z]), np.concatenate([m, f]).astype(np.int32)
    else:
        head[:4] = (1, *DIMS)
        act = (m * 1 + f * 2).astype(np.int32)
    egrid = folder / "DUAL.EGRID"
    resfo.write(egrid, [(_kw("FILEHEAD"), fh), (_kw("GRIDHEAD"), head), (_kw("COORD"), coord),
                        (_kw("ZCORN"), z), (_kw("ACTNUM"), act),
                        (_kw("ENDGRID"), np.zeros(0, np.int32))])
    logi = np.zeros(121, bool)
    logi[14] = True
    porv = np.concatenate([np.where(m, 10.0, 0), np.where(f, 1.0, 0)]).astype(np.float32)
    resfo.write(egrid.with_suffix(".INIT"), [
        (_kw("INTEHEAD"), _head(2 * DIMS[2], nm + nf)), (_kw("LOGIHEAD"), logi),
        (_kw("PORV"), porv),
        (_kw("PORO"), np.concatenate([0.2 + np.arange(nm) / 1000,
                                      0.01 + np.arange(nf) / 1000]).astype(np.float32))])
    recs = []
    for k in range(nsteps):
        recs += [(_kw("SEQNUM"), np.array([k], np.int32)),
                 (_kw("INTEHEAD"), _head(2 * DIMS[2], nm + nf, k + 1)),
                 (_kw("SWAT"), np.concatenate([np.full(nm, 0.1 * k), np.full(nf, 0.5 + 0.1 * k)]
                                              ).astype(np.float32))]
    resfo.write(egrid.with_suffix(".UNRST"), recs)
    return egrid, m.reshape(DIMS, order="F"), f.reshape(DIMS, order="F")


def _scatter(values, mask) -> np.ndarray:
    out = np.full(mask.size, np.nan)
    out[mask.reshape(-1, order="F")] = values
    return out.reshape(mask.shape, order="F")


@pytest.mark.parametrize("doubled", [False, True], ids=["actnum-0123", "nz-doubled"])
@pytest.mark.parametrize("kind", [1, 2], ids=["dualporo", "dualperm"])
def test_both_media_equal_resfo(tmp_path, kind, doubled):
    egrid, m, f = write_dual(tmp_path, kind, doubled)
    case = load_case(egrid)
    assert case.dims == DIMS and case.media == ("matrix", "fracture")
    assert case.medium == "matrix" and case.meta["dual"] == ("dual porosity", "dual "
                                                             "permeability")[kind - 1]
    init = {k.strip(): v for k, v in resfo.read(egrid.with_suffix(".INIT"))}
    nm = int(m.sum())
    assert np.array_equal(case.active, m)
    assert np.allclose(case.properties["PORO"], _scatter(init["PORO"][:nm], m), equal_nan=True)
    assert np.allclose(case.properties["PORV"].reshape(-1, order="F"), init["PORV"][:m.size])
    frac = case.select_medium("fracture")
    assert frac.medium == "fracture" and np.array_equal(frac.active, f)
    assert np.allclose(frac.properties["PORO"], _scatter(init["PORO"][nm:], f), equal_nan=True)
    assert np.allclose(frac.properties["PORV"].reshape(-1, order="F"), init["PORV"][m.size:])
    swat = [v for k, v in resfo.read(egrid.with_suffix(".UNRST")) if k.strip() == "SWAT"]
    for k in range(2):
        assert np.allclose(case.steps[k]["SWAT"], _scatter(swat[k][:nm], m), equal_nan=True)
        assert np.allclose(frac.steps[k]["SWAT"], _scatter(swat[k][nm:], f), equal_nan=True)
    # the geometry is shared: the matrix's corners (the doubled file's first half)
    z = np.asarray(resfo.read(egrid)[3][1])
    assert np.array_equal(case.zcorn.reshape(-1, order="F"), z[:case.zcorn.size])
    assert frac.select_medium("matrix").properties is case.properties


def test_lazy_steps_of_both_media(tmp_path):
    egrid, _, _ = write_dual(tmp_path, nsteps=3)
    eager, lazy = load_case(egrid), load_case(egrid, eager_bytes=0)
    for medium in ("matrix", "fracture"):
        a, b = eager.select_medium(medium), lazy.select_medium(medium)
        for k in range(3):
            assert np.array_equal(a.steps[k]["SWAT"], b.steps[k]["SWAT"], equal_nan=True)
        assert b.meta["unrst"].medium == medium


def test_select_medium_refuses_what_is_not_there(tmp_path):
    egrid, _, _ = write_dual(tmp_path)
    case = load_case(egrid)
    with pytest.raises(InputError, match="medium vugs: expected one of matrix, fracture"):
        case.select_medium("vugs")
    single = synthetic_grid(2, 2, 1)
    assert single.select_medium("matrix") is single and single.media == ()
    with pytest.raises(InputError, match="has one medium"):
        single.select_medium("fracture")


def test_info_names_the_media(tmp_path):
    egrid, _, _ = write_dual(tmp_path)
    lines = format_case_parts(describe_case_parts(load_case(egrid)))
    assert lines == ["  media    dual porosity: matrix, fracture (showing the matrix; --medium "
                     "fracture)"]


def test_egrid_alone_of_a_dual_case(tmp_path):
    egrid, m, f = write_dual(tmp_path)
    g = read_egrid(egrid)
    assert g.nactive == int(m.sum()) and g.select_medium("fracture").nactive == int(f.sum())


def test_an_init_of_a_single_grid_beside_a_dual_egrid_is_one_line(tmp_path):
    egrid, _, _ = write_dual(tmp_path)
    resfo.write(egrid.with_suffix(".INIT"), [(_kw("INTEHEAD"), _head(DIMS[2] + 1, 7))])
    with pytest.raises(InputError, match="INTEHEAD: the file is for a 4×3×3 grid with 7 active"):
        load_case(egrid)
