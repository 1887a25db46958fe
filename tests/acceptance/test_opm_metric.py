"""Acceptance: Reek in METRIC units: the deck (faults, FIPNUM/EQLNUM regions, wells from
WELSPECS/COMPDAT/WCONHIST/WCONINJH) and its OPM Flow run (37 report steps).

Read in place from ../shared/data/reek_cornerpoint (equinor/res2df, GPL-3.0; the run made with
OPM Flow 2026.04). Oracles: resfo (EGRID/INIT/UNRST), the deck's own text (fault and well names).
"""

from __future__ import annotations

import re

import numpy as np
import pytest

from tests.acceptance.conftest import (
    annotations,
    colorbar_label,
    inside_picture,
    legend_names,
    title_text,
    view_screenshot,
)

resfo = pytest.importorskip("resfo")
pytestmark = pytest.mark.data  # reads ../shared/data

DECK = "reek_cornerpoint/model/2_R001_REEK-0.DATA"
RUN = "reek_cornerpoint/opm_flow_run/2_R001_REEK-0.EGRID"


@pytest.fixture(scope="module")
def deck(shared):
    return shared / DECK


@pytest.fixture(scope="module")
def run(shared):
    return shared / RUN


def _read(path) -> dict[str, np.ndarray]:
    return {k.strip(): np.asarray(v) for k, v in resfo.read(path)}


def _restart(egrid, keyword: str) -> list[np.ndarray]:
    return [np.asarray(v) for k, v in resfo.read(egrid.with_suffix(".UNRST"))
            if k.strip() == keyword]


def _deck_names(path, keyword: str) -> list[str]:
    """The first item of each record of ``keyword`` in a deck or include file (the oracle)."""
    names: list[str] = []
    inside = False
    for line in path.read_text(errors="replace").splitlines():
        line = line.split("--")[0].strip()
        if not line:
            continue
        if re.fullmatch(keyword, line, re.IGNORECASE):
            inside = True
            continue
        if inside:
            if line.startswith("/"):
                inside = False
                continue
            names.append(line.split()[0].strip("'\""))
    return names


def _records(path, keyword: str) -> list[list[str]]:
    """Every record of every ``keyword`` block of a schedule file, as quote-stripped items."""
    out: list[list[str]] = []
    inside = False
    for line in path.read_text(errors="replace").splitlines():
        line = line.split("--")[0].strip()
        if not line:
            continue
        if not inside:
            inside = re.fullmatch(keyword, line, re.IGNORECASE) is not None
            continue
        if line.startswith("/"):
            inside = False
            continue
        out.append([t.strip("'\"") for t in line.rstrip("/").split()])
    return out


def test_deck_wells_types_and_completions_equal_the_schedule(shared, deck):
    """Wells from WELSPECS/COMPDAT typed by WCONHIST/WCONINJH, completed in COMPDAT's cells."""
    import geoshade

    schedule = shared / "reek_cornerpoint/include/schedule/reek_history.sch"
    types = {r[0]: "producer" for kw in ("WCONHIST", "WCONPROD") for r in _records(schedule, kw)}
    phases = {"WATER": "water injector", "GAS": "gas injector", "OIL": "oil injector"}
    types |= {r[0]: phases[r[1].upper()] for kw in ("WCONINJH", "WCONINJE")
              for r in _records(schedule, kw)}
    cells: dict[str, set] = {}
    for r in _records(schedule, "COMPDAT"):
        i, j, k1, k2 = (int(v) for v in r[1:5])
        cells.setdefault(r[0], set()).update((i, j, k) for k in range(k1, k2 + 1))
    with pytest.warns(Warning):
        grid = geoshade.load(deck)
    wells = {w.name: w for w in grid.meta["wells"]}
    assert set(wells) == set(types) == set(cells)
    for name, w in wells.items():
        assert w.type == types[name], (name, w.type)
        assert len(w.markers) == len(cells[name]), name


def test_info_says_metric_steps_and_regions(cli, run):
    rc, out, err = cli("info", run)
    assert rc == 0, err
    assert _read(run.with_suffix(".INIT"))["INTEHEAD"][2] == 1  # 1 = METRIC
    assert re.search(r"units\s+METRIC", out), out
    n = len(_restart(run, "PRESSURE"))
    assert f"steps    {n} " in out and n == 37


@pytest.mark.gl
@pytest.mark.parametrize("part", ["grid", "iso"])
def test_pressure_is_in_bar_in_every_part(cli, run, part):
    p = _restart(run, "PRESSURE")[-1]
    if part == "grid":
        st = cli.render("reek_grid_pressure", "grid", "render", run, "--property", "PRESSURE",
                        "--size", "640x480")
        bar = annotations(st)["colorbar"]
        assert (bar["lo"], bar["hi"]) == pytest.approx((float(p.min()), float(p.max())),
                                                        rel=1e-6)
    else:
        st = cli.render("reek_iso_swat_by_pressure", "iso", "render", run, "--keyword", "SWAT",
                        "--level", "0.5", "--color-by", "PRESSURE", "--size", "640x480")
    assert st["unit_system"] == "METRIC"
    assert colorbar_label(st) == "PRESSURE [bar]"


@pytest.mark.gl
@pytest.mark.parametrize("keyword", ["FIPNUM", "EQLNUM"])
def test_region_codes_get_one_legend_entry_each(cli, run, keyword):
    codes = np.unique(_read(run.with_suffix(".INIT"))[keyword])
    st = cli.render(f"reek_{keyword.lower()}", "grid", "render", run, "--property", keyword,
                    "--size", "640x480")
    assert legend_names(st) == [str(c) for c in codes], annotations(st)
    legend = annotations(st)["legend"]
    assert inside_picture(st, legend["bbox"]), legend
    assert not annotations(st).get("colorbar")
    assert not re.search(r"\bstep\b", title_text(st)), title_text(st)  # static property


@pytest.mark.gl
@pytest.mark.parametrize("size", ["800x600", "320x240"])
def test_deck_faults_and_named_wells(cli, deck, shared, size):
    faults = sorted(set(_deck_names(shared / "reek_cornerpoint/include/grid/reek.faults",
                                    "FAULTS")))
    schedule = shared / "reek_cornerpoint/include/schedule/reek_history.sch"
    wells = sorted(set(_deck_names(schedule, "WELSPECS")))
    assert len(faults) == 6 and len(wells) == 8
    import geoshade

    with pytest.warns(Warning):
        grid = geoshade.load(deck)
    assert sorted({f.name for f in grid.faults}) == faults
    st = cli.render(f"reek_deck_fipnum_wells_{size}", "grid", "render", deck, "--property",
                    "FIPNUM", "--exaggeration", "5", "--size", size)
    labels = annotations(st).get("labels", [])
    shown = sorted(lab["text"] for lab in labels)
    hidden = st.get("well_labels_hidden", 0)
    assert len(shown) + hidden == len(wells) and set(shown) <= set(wells), labels
    if hidden:
        assert re.search(rf"{hidden}\D+hidden|hidden\D+{hidden}", title_text(st)), title_text(st)
    assert re.search(r"exaggerat\w*\D{0,6}5|[×x]\s?5\b", title_text(st)), title_text(st)
    boxes = [lab["bbox"] for lab in labels]
    for i, a in enumerate(boxes):  # labels placed without overlap
        for b in boxes[i + 1:]:
            assert (a[0] + a[2] <= b[0] or b[0] + b[2] <= a[0] or a[1] + a[3] <= b[1]
                    or b[1] + b[3] <= a[1]), (a, b)


def test_deck_and_run_grids_agree_with_resfo(deck, run):
    import geoshade

    with pytest.warns(Warning):
        from_deck = geoshade.load(deck)
    from_run = geoshade.load(run)
    egrid = _read(run)
    nx, ny, nz = (int(v) for v in egrid["GRIDHEAD"][1:4])
    assert from_run.dims == from_deck.dims == (nx, ny, nz)
    assert from_run.nactive == int((egrid["ACTNUM"] > 0).sum())
    np.testing.assert_array_equal(from_run.zcorn, egrid["ZCORN"].reshape(
        (2 * nx, 2 * ny, 2 * nz), order="F"))
    swat = _restart(run, "SWAT")
    act = from_run.actnum.astype(bool)
    got = np.asarray(from_run.steps[-1]["SWAT"]).ravel(order="F")[act.ravel(order="F")]
    np.testing.assert_array_equal(got, swat[-1])


def test_exports_of_the_run(cli, run, tmp_path):
    import geoshade

    grid = geoshade.load(run)
    xr = geoshade.to_xarray(grid)
    assert "PORO" in xr
    pv = pytest.importorskip("pyvista")
    ds = geoshade.to_pyvista(grid)
    assert isinstance(ds, pv.DataSet) and ds.n_cells in (grid.ncells, grid.nactive)
    poro = _read(run.with_suffix(".INIT"))["PORO"]
    assert np.nansum(np.asarray(ds.cell_data["PORO"]).astype(np.float64)) == pytest.approx(
        float(poro.astype(np.float64).sum()), rel=1e-9)
    out = tmp_path / "SECTOR.EGRID"
    rc, _, err = cli("grid", "export", run, "--filter", "FIPNUM == 1", "-o", out)
    assert rc == 0, err
    init = _read(out.with_suffix(".INIT"))
    assert set(np.unique(init["FIPNUM"]).tolist()) <= {1, 2, 3, 4, 5, 6}
    fip = np.asarray(grid.properties["FIPNUM"])
    assert int((init["FIPNUM"] == 1).sum()) == int((fip[grid.actnum.astype(bool)] == 1).sum())


@pytest.mark.gl
def test_viewer_screenshot_of_the_deck(pictures, deck):
    img = view_screenshot(pictures, "reek_view_deck_fipnum", deck, "--property", "FIPNUM",
                          "--exaggeration", "5")
    assert (np.abs(img[..., :3].astype(int) - 255).sum(-1) > 30).mean() > 0.05


@pytest.mark.gl
def test_grdecl_property_file_by_param(cli, shared):
    """``--param`` with a GRDECL property file beside a GRDECL grid (both exported from RMS)."""
    xtgeo = pytest.importorskip("xtgeo")
    folder = shared / "reek_cornerpoint" / "include" / "grid"
    xgrid = xtgeo.grid_from_file(folder / "reek.grid", fformat="grdecl")
    poro = xtgeo.gridproperty_from_file(folder / "reek.poro", fformat="grdecl", name="PORO",
                                        grid=xgrid)
    st = cli.render("reek_grdecl_param_poro", "grid", "render", folder / "reek.grid", "--param",
                    folder / "reek.poro", "--property", "PORO", "--size", "480x360")
    bar = annotations(st)["colorbar"]
    assert bar["label"] == "PORO [fraction]"
    assert (bar["lo"], bar["hi"]) == pytest.approx((float(poro.values.min()),
                                                    float(poro.values.max())), rel=1e-6)
    assert st["shown_cells"] == xgrid.nactive
