"""Acceptance: ECLIPSE/OPM output as the industry ships it (issue 31, items 1 and 5).

Cases (tests/acceptance/ecl_cases.py, made at test time; nothing committed but the code):

- OPM Flow 2026.4 on SPE1 with two CARFIN local grid refinements: EGRID/INIT/UNRST with LGR
  sections. Oracle: resfo's arrays (HOSTNUM, the LGRs' INIT and restart arrays), the deck's
  CARFIN boxes.
- OPM Flow on SPE1 with 24 hourly then 2 daily steps, non-unified (X0000 … X0026). Oracle:
  resfo's INTEHEAD (day, month, year, hour).
- SPE1 rewritten as ECLIPSE lays out DUALPORO and DUALPERM cases. Oracle: the arrays written,
  read back by resfo (matrix then fracture active cells).
- Reek (ECLIPSE's own EGRID, shared data) alone, and written as an old binary GRID. Oracle: xtgeo's
  corners, resfo's ACTNUM.
- SPE1 with ECLIPSE 2018's zero corners for inactive cells and -1e20 in an INIT array. Oracle:
  numpy over resfo's arrays.
"""

from __future__ import annotations

import json
import re
import shutil

import numpy as np
import pytest

from geoshade.errors import InputError
from geoshade.io import load
from tests.acceptance import ecl_cases
from tests.acceptance.conftest import title_text
from tests.acceptance.make_cases import SHARED, CaseUnavailableError

resfo = pytest.importorskip("resfo")


def _made(make, *args):
    try:
        return make(*args)
    except CaseUnavailableError as err:
        pytest.skip(str(err))


@pytest.fixture(scope="module")
def lgr():
    return _made(ecl_cases.spe1_lgr)


@pytest.fixture(scope="module")
def hourly():
    return _made(ecl_cases.spe1_hourly)


@pytest.fixture(scope="module", params=[1, 2], ids=["dualporo", "dualperm"])
def dual(request):
    return _made(ecl_cases.spe1_dual, ecl_cases.CACHE, request.param), request.param


@pytest.fixture(scope="module")
def reek_grid():
    return _made(ecl_cases.reek_grid_file)


@pytest.fixture(scope="module")
def eclipse_style():
    return _made(ecl_cases.spe1_eclipse_style)


def _records(path) -> list[tuple[str, np.ndarray]]:
    return [(k.strip(), v) for k, v in resfo.read(path)]


def _sections(records) -> dict[str, list[tuple[str, np.ndarray]]]:
    """The records of each LGR section (``LGR`` … next ``LGR``/``ENDLGR``/``LGRSGONE``)."""
    out: dict[str, list] = {}
    cur = None
    for k, v in records:
        if k == "LGR":
            cur = out.setdefault(bytes(v[0]).decode().strip(), [])
        elif k in ("ENDLGR", "LGRSGONE", "SEQNUM"):
            cur = None
        elif cur is not None:
            cur.append((k, v))
    return out


# --- local grid refinements (OPM Flow CARFIN) ---------------------------------------------------
def test_info_lists_every_lgr_with_its_size_and_host_box(cli, lgr):
    rc, out, err = cli("info", lgr)
    assert rc == 0, err
    assert "2 local grid refinements" in out
    for name, (i1, i2, j1, j2, k1, k2), (nx, ny, nz) in ecl_cases.LGRS:
        kk = f"K={k1}" if k1 == k2 else f"K={k1}..{k2}"
        assert f"{name} {nx}×{ny}×{nz} in I={i1}..{i2} J={j1}..{j2} {kk}: {nx * ny * nz} cells" \
            in out, out
    rc, out, _ = cli("info", "--json", lgr)
    d = json.loads(out)
    hosts = {n: np.asarray(dict(s)["HOSTNUM"]) - 1 for n, s in
             _sections(_records(lgr)).items()}
    for item in d["lgrs"]:  # the host box from resfo's HOSTNUM
        i, j, k = np.unravel_index(hosts[item["name"]], (10, 10, 3), order="F")
        assert item["host_box"] == [[int(a.min()) + 1, int(a.max()) + 1] for a in (i, j, k)]


def test_lgr_properties_and_steps_equal_resfo(lgr):
    case = load(lgr)
    init = _sections(_records(lgr.with_suffix(".INIT")))
    rst = _records(lgr.with_suffix(".UNRST"))
    steps = [k for k, (kw, _) in enumerate(rst) if kw == "SEQNUM"] + [len(rst)]
    assert [r.name for r in case.refinements] == ["LGR1", "LGR2"]
    for r in case.refinements:
        mine = dict(init[r.name])
        assert int(mine["INTEHEAD"][8]) * int(mine["INTEHEAD"][9]) * int(mine["INTEHEAD"][10]) \
            == r.grid.ncells  # the LGR's own INTEHEAD
        for kw in ("PORO", "PERMX", "PORV", "DEPTH"):
            assert np.array_equal(r.grid.properties[kw].reshape(-1, order="F"), mine[kw]), kw
        assert len(r.grid.steps) == len(case.steps) == len(steps) - 1 == 7
        for n in range(7):
            sec = dict(_sections(rst[steps[n]:steps[n + 1]])[r.name])
            for kw in ("SWAT", "PRESSURE", "SGAS"):
                assert np.array_equal(r.grid.steps[n][kw].reshape(-1, order="F"), sec[kw]), kw
    # the global grid's arrays are the global section's (an LGR's never replace them)
    glob = next(v for k, v in rst[steps[-2]:steps[-1]] if k == "SWAT")  # before the LGRs'
    assert glob.size == 300
    assert np.array_equal(case.steps[-1]["SWAT"].reshape(-1, order="F"), glob)


def test_refined_cells_fill_their_host_cells(lgr):
    """Each LGR's cells span exactly its host box (corners of the global host cells)."""
    case = load(lgr)
    for r in case.refinements:
        (i0, i1), (j0, j1), (k0, k1) = r.host_box
        host = case.corners((slice(i0, i1 + 1), slice(j0, j1 + 1), slice(k0, k1 + 1)))
        sub = r.grid.corners()
        assert np.allclose(sub.reshape(-1, 3).min(0), host.reshape(-1, 3).min(0))
        assert np.allclose(sub.reshape(-1, 3).max(0), host.reshape(-1, 3).max(0))
        hn = np.unique(r.hostnum)
        assert hn.size == (i1 - i0 + 1) * (j1 - j0 + 1) * (k1 - k0 + 1)


def test_to_pyvista_holds_the_refined_cells(lgr):
    pv = pytest.importorskip("pyvista")
    mb = load(lgr).to_pyvista()
    assert isinstance(mb, pv.MultiBlock) and mb.keys() == ["GLOBAL", "LGR1", "LGR2"]
    assert [mb[k].n_cells for k in mb.keys()] == [300, 16, 64]
    hidden = (np.asarray(mb["GLOBAL"].cell_data["vtkGhostType"]) & 32) != 0
    assert int(hidden.sum()) == 4 + 8  # the host cells
    last = _sections(_records(lgr.with_suffix(".UNRST")))["LGR2"]
    assert np.array_equal(np.asarray(mb["LGR2"].cell_data["SWAT"]), dict(last)["SWAT"])


def test_without_the_restart_the_refined_cells_stay(cli, lgr, tmp_path):
    for suffix in (".EGRID", ".INIT"):
        shutil.copy(lgr.with_suffix(suffix), tmp_path / f"NORST{suffix}")
    case = load(tmp_path / "NORST.EGRID")
    assert [r.grid.ncells for r in case.refinements] == [16, 64]
    assert all(r.grid.properties and not r.grid.steps for r in case.refinements)
    rc, out, err = cli("info", tmp_path / "NORST.EGRID")
    assert rc == 0 and "LGR2 4×4×4 in I=7..8 J=7..8 K=2..3: 64 cells" in out, err


# --- hourly report steps, non-unified -----------------------------------------------------------
def test_hourly_steps_keep_their_hour(hourly):
    folder = hourly.parent
    heads = [dict(_records(f))["INTEHEAD"] for f in sorted(folder.glob("HOURLY.X*"))]
    case = load(hourly)
    want = [f"{h[66]:04d}-{h[65]:02d}-{h[64]:02d} {h[206]:02d}:{h[207]:02d}" for h in heads]
    assert case.step_dates == want and len(set(want)) == 27
    assert case.step_dates[13] == "2015-01-01 13:00"


def test_a_non_unified_file_opens_its_own_step(hourly, cli):
    x12 = hourly.with_name("HOURLY.X0012")
    case = load(x12)
    assert case.meta["default_step"] == 12 and case.meta["unrst_seqnum"][12] == 12
    options = pytest.importorskip("geoshade.grid.options")
    assert options.GridOptions.check_step(None, case) == 12
    assert np.array_equal(case.steps[12]["SWAT"].reshape(-1, order="F"),
                          dict(_records(x12))["SWAT"])
    rc, out, _ = cli("info", x12)
    assert rc == 0 and "opened HOURLY.X0012: report 12 (step 12)" in out


def test_a_date_of_24_steps_asks_which(hourly):
    case = load(hourly)
    options = pytest.importorskip("geoshade.grid.options")
    with pytest.raises(InputError) as ei:
        options.GridOptions.check_step("2015-01-01", case)
    assert "24 steps have that date" in str(ei.value) and "\n" not in str(ei.value)
    assert options.GridOptions.check_step("2015-01-01 06:00", case) == 6


@pytest.mark.gl
def test_the_picture_of_a_non_unified_file_is_its_step_with_its_hour(hourly, cli):
    st = cli.render("hourly_x0012", "grid", "render", hourly.with_name("HOURLY.X0012"),
                    "--property", "PRESSURE", "--size", "640x480")
    head = dict(_records(hourly.with_name("HOURLY.X0012")))["INTEHEAD"]
    assert int(head[206]) == 12
    assert "report 12 · 2015-01-01 12:00" in title_text(st), title_text(st)
    rc, _, err = cli("grid", "render", hourly, "--step", "2015-01-01", "-o", cli.tmp / "x.png")
    assert rc == 2 and "24 steps have that date" in err and err.count("\n") == 1


@pytest.mark.gl
def test_a_case_with_lgrs_is_drawn_not_refused(lgr, cli):
    st = cli.render("spe1_lgr_swat", "grid", "render", lgr, "--property", "SWAT",
                    "--size", "640x480")
    assert st["shown_cells"] == 288 and len(st["refinements"]) == 2   # hosts: refined


# --- dual porosity / permeability ---------------------------------------------------------------
def test_dual_media_equal_the_files(dual, cli):
    egrid, kind = dual
    case = load(egrid)
    act = np.asarray(dict(_records(egrid))["ACTNUM"]).reshape((10, 10, 3), order="F")
    init = dict(_records(egrid.with_suffix(".INIT")))
    assert case.media == ("matrix", "fracture") and case.meta["dual"] == (
        "dual porosity" if kind == 1 else "dual permeability")
    m, f = (act & 1) != 0, (act & 2) != 0
    nm = int(m.sum())
    frac = case.select_medium("fracture")
    assert frac.nactive == int(f.sum()) == 198 and case.nactive == nm == 300
    poro = init["PORO"]
    assert np.array_equal(case.properties["PORO"].reshape(-1, order="F"), poro[:nm])
    got = frac.properties["PORO"].reshape(-1, order="F")[f.reshape(-1, order="F")]
    assert np.array_equal(got, poro[nm:])
    swat = [v for k, v in _records(egrid.with_suffix(".UNRST")) if k == "SWAT"][-1]
    got = frac.steps[-1]["SWAT"].reshape(-1, order="F")[f.reshape(-1, order="F")]
    assert np.array_equal(got, swat[nm:])
    rc, out, err = cli("info", egrid)
    assert rc == 0 and "media    dual" in out and "--medium fracture" in out, err


@pytest.mark.gl
def test_the_medium_option_draws_the_fracture(dual, cli):
    """``--medium fracture``: the fracture's active cells (resfo's ACTNUM & 2) coloured by its
    own PORO, the title saying which medium; matrix by default; a one-medium case refuses it."""
    egrid, kind = dual
    act = np.asarray(dict(_records(egrid))["ACTNUM"])
    st = cli.render(f"dual{kind}_fracture", "grid", "render", egrid, "--medium", "fracture",
                    "--property", "PORO", "--size", "640x480")
    assert st["shown_cells"] == int(((act & 2) != 0).sum()) == 198
    assert "(fracture)" in title_text(st), title_text(st)
    st = cli.render(f"dual{kind}_matrix", "grid", "render", egrid, "--property", "PORO",
                    "--size", "640x480")
    assert st["shown_cells"] == int(((act & 1) != 0).sum()) and "(matrix)" in title_text(st)


def test_the_medium_option_on_one_medium_is_one_line(lgr, cli):
    rc, _, err = cli("grid", "render", lgr, "--medium", "fracture", "-o", cli.tmp / "m.png")
    assert rc == 2 and "has one medium" in err and err.count("\n") == 1


# --- grid files alone ---------------------------------------------------------------------------
def test_an_eclipse_egrid_alone_draws_its_geometry(cli):
    egrid = SHARED / "reek_cornerpoint" / "model" / "2_R001_REEK-0.EGRID"
    if not egrid.is_file():
        pytest.skip(f"{egrid} is absent (shared data)")
    rc, out, err = cli("info", egrid)
    assert rc == 0, err
    act = np.asarray(dict(_records(egrid))["ACTNUM"])
    assert f"active {int((act != 0).sum()):,}" in out
    assert "note     grid file alone: geometry only (2_R001_REEK-0.INIT would add its " \
        "properties, 2_R001_REEK-0.UNRST its report steps)" in out


def test_the_old_grid_file_equals_xtgeos_corners(reek_grid, cli):
    corners = np.load(reek_grid.with_name("corners.npy"))
    grid = load(reek_grid)
    assert grid.meta["format"] == "GRID" and grid.dims == corners.shape[:3]
    assert np.allclose(grid.corners(), corners, rtol=0, atol=1e-6 * np.abs(corners).max())
    egrid = SHARED / "reek_cornerpoint" / "model" / "2_R001_REEK-0.EGRID"
    act = np.asarray(dict(_records(egrid))["ACTNUM"])
    assert grid.nactive == int((act != 0).sum())
    rc, out, err = cli("info", reek_grid)
    assert rc == 0 and "40 × 64 × 14" in out and "grid file alone" in out, err


# --- ECLIPSE 2018's inactive zero corners and undefined values ----------------------------------
def test_info_bounds_and_ranges_leave_out_what_is_no_value(eclipse_style, cli):
    recs = dict(_records(eclipse_style))
    z = np.asarray(recs["ZCORN"]).reshape((20, 20, 6), order="F")
    act = np.asarray(recs["ACTNUM"]).reshape((10, 10, 3), order="F") != 0
    live = z[np.repeat(np.repeat(np.repeat(act, 2, 0), 2, 1), 2, 2)]
    assert z.min() == 0  # the file's zero corners
    rc, out, err = cli("info", "--json", eclipse_style)
    assert rc == 0, err
    d = json.loads(out)
    assert d["bounds"][0][2] == pytest.approx(float(live.min()))
    assert d["bounds"][1][2] == pytest.approx(float(live.max()))
    swl = np.asarray(dict(_records(eclipse_style.with_suffix(".INIT")))["SWL"])
    ok = swl[np.abs(swl) < 1e19]
    assert d["property_stats"]["SWL"]["min"] == pytest.approx(float(ok.min()))
    rc, out, _ = cli("info", eclipse_style)
    assert re.search(r"depth 8325\.?\d*\.\.8425", out) and "-1e+20" not in out, out
