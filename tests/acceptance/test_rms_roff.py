"""Acceptance: the Reek simulation grid exported from RMS as ROFF, its parameters and RMS wells.

Files as they ship (tests/data/real/rms_roff_reek, equinor/xtgeo-testdata, LGPL-3.0): the grid
``reek_sim_grid.roff``, parameters ``reek_sim_{poro,zone,facies2}.roff`` (not renamed to the FMU
``GRID--NAME.roff`` pattern) and the RMS ASCII wells ``OP_1.w``, ``WI_1.w``. Oracle: xtgeo.
"""

from __future__ import annotations

import numpy as np
import pytest

from tests.acceptance.conftest import (
    annotations,
    colorbar_label,
    inside_picture,
    legend_entries,
    legend_names,
    view_screenshot,
)

xtgeo = pytest.importorskip("xtgeo")

CASE = "rms_roff_reek"
PARAMS = ("reek_sim_poro.roff", "reek_sim_zone.roff", "reek_sim_facies2.roff")
FACIES = ["SHALE", "FINESAND", "COARSESAND"]  # codes 0, 1, 2 in reek_sim_facies2.roff
ZONES = ["Below_Top_reek", "Below_Mid_reek", "Below_Low_reek"]  # codes 1, 2, 3


@pytest.fixture(scope="module")
def case(real):
    return real / CASE


@pytest.fixture(scope="module")
def xgrid(case):
    return xtgeo.grid_from_file(case / "reek_sim_grid.roff")


@pytest.fixture(scope="module")
def grid(case):
    import geoshade

    return geoshade.load(case / "reek_sim_grid.roff",
                         properties=[case / p for p in PARAMS])


def _xprop(case, xgrid, name: str):
    return xtgeo.gridproperty_from_file(case / name, grid=xgrid)


def test_info_counts_equal_xtgeo(cli, case, xgrid):
    rc, out, err = cli("info", case / "reek_sim_grid.roff")
    assert rc == 0, err
    nx, ny, nz = xgrid.dimensions
    assert f"{nx} × {ny} × {nz} = {nx * ny * nz:,}, active {xgrid.nactive:,}" in out, out


def test_grid_and_parameters_equal_xtgeo(case, xgrid, grid):
    assert grid.dims == tuple(xgrid.dimensions)
    np.testing.assert_array_equal(grid.actnum.astype(bool), xgrid.get_actnum().values == 1)
    for file, name in zip(PARAMS, ("PORO", "Zone", "FACIES"), strict=True):
        xp = _xprop(case, xgrid, file)
        active = ~np.ma.getmaskarray(xp.values)
        np.testing.assert_array_equal(np.asarray(grid.properties[name])[active],
                                      np.ma.getdata(xp.values)[active].astype(
                                          grid.properties[name].dtype))
    assert grid.meta["codes"]["FACIES"] == {0: "SHALE", 1: "FINESAND", 2: "COARSESAND"}
    assert grid.meta["codes"]["Zone"] == dict(enumerate(ZONES, start=1))
    corners_x = xgrid.get_xyz_corners()
    assert grid.bounds is not None and corners_x is not None


@pytest.mark.gl
def test_facies_gets_a_legend_with_its_roff_names_api(pictures, grid):
    from PIL import Image

    import geoshade

    with geoshade.view(grid, property="FACIES", annotations=True, size=(640, 480)) as v:
        rgba, st = v.draw()
    Image.fromarray(rgba).save(pictures / "roff_facies_api.png")
    assert legend_names(st) == FACIES, annotations(st)
    legend = annotations(st)["legend"]
    assert inside_picture(st, legend["bbox"]), legend
    assert not annotations(st).get("colorbar"), "a code property has no continuous colour bar"


@pytest.mark.gl
def test_facies_from_a_param_file_as_it_ships_cli(cli, case):
    """``--param`` takes a ROFF parameter file whatever its name."""
    st = cli.render("roff_facies_cli", "grid", "render", case / "reek_sim_grid.roff",
                    "--param", case / "reek_sim_facies2.roff", "--property", "FACIES",
                    "--exaggeration", "5", "--size", "640x480")
    assert legend_names(st) == FACIES, annotations(st)
    assert inside_picture(st, annotations(st)["legend"]["bbox"])


@pytest.mark.gl
def test_zone_legend_names_every_code_unclipped(cli, case, xgrid):
    """Zone codes 1..3 named by the file (28 active cells are undefined, -999: a "no value"
    entry for them may follow)."""
    xp = _xprop(case, xgrid, "reek_sim_zone.roff")
    undefined = int(np.ma.getmaskarray(xp.values)[xgrid.get_actnum().values == 1].sum())
    assert undefined == 28
    st = cli.render("roff_zone_cli", "grid", "render", case / "reek_sim_grid.roff",
                    "--param", case / "reek_sim_zone.roff", "--property", "Zone",
                    "--size", "480x360")
    names = legend_names(st)
    assert names in (ZONES, [*ZONES, "no value"]), annotations(st)
    legend = annotations(st)["legend"]
    assert inside_picture(st, legend["bbox"]), legend
    assert not legend.get("title") or inside_picture(st, legend["bbox"])


@pytest.mark.gl
def test_zone_from_a_grid_store_is_the_in_memory_picture(cli, case, pictures, tmp_path):
    """The grid ingested into a store, Zone given beside it: the same categories, the same
    28 undefined (-999) cells without a value and the same picture as the ROFF grid in memory
    (only the title's file name differs)."""
    from PIL import Image

    store = tmp_path / "reek.zarr"
    rc, _, err = cli("grid", "ingest", case / "reek_sim_grid.roff", "-o", store,
                     "--chunks", "16", "16", "4")
    assert rc == 0, err
    args = ("--param", case / "reek_sim_zone.roff", "--property", "Zone", "--size", "480x360")
    mem = cli.render("roff_zone_memory", "grid", "render", case / "reek_sim_grid.roff", *args)
    sto = cli.render("roff_zone_store", "grid", "render", store, *args)
    for key in ("categories", "no_value_cells", "color_range"):
        assert mem[key] == sto[key], key
    assert mem["categories"] == [1.0, 2.0, 3.0] and mem["no_value_cells"] == 28
    assert legend_names(sto) == legend_names(mem)
    a, b = (np.array(Image.open(pictures / f"{n}.png")) for n in ("roff_zone_memory",
                                                                     "roff_zone_store"))
    ann = annotations(mem)
    below = max(t["y"] for t in ann["title"]) + 2 * ann["font_px"]   # the title's line(s)
    a[:below, : a.shape[1] // 2], b[:below, : b.shape[1] // 2] = 0, 0   # (names the file)
    np.testing.assert_array_equal(a, b)


@pytest.mark.gl
def test_a_store_of_the_grid_with_its_parameters_keeps_the_code_names(grid, tmp_path):
    """The grid and its parameters written to a store: facies and zones keep the names the
    ROFF files give their codes (legend and pick), their categories and the -999 cells."""
    from geoshade.grid import GridView
    from geoshade.io.stores.grid_store import ModelSource, open_grid_store, write_grid_store

    store = open_grid_store(write_grid_store(ModelSource(grid), tmp_path / "p.zarr",
                                             (16, 16, 4)).path)
    assert store.meta["codes"] == grid.meta["codes"]
    for prop, names in (("FACIES", FACIES), ("Zone", ZONES)):
        got = []
        for g in (grid, store):
            with GridView(g, size=(480, 360), property=prop) as v:
                st = v.draw(frames=1)[1]
                got.append((st, [t.split(" ", 1)[1] for t, _ in v._color_key(st).entries]))
        (sa, la), (sb, lb) = got
        assert la[:3] == lb[:3] == names, (la, lb)
        for key in ("categories", "no_value_cells", "color_range"):
            assert sa[key] == sb[key], (prop, key)


@pytest.mark.gl
def test_continuous_override_draws_a_colour_bar(cli, case):
    st = cli.render("roff_facies_continuous", "grid", "render", case / "reek_sim_grid.roff",
                    "--param", case / "reek_sim_facies2.roff", "--property", "FACIES",
                    "--continuous", "--size", "480x360")
    assert colorbar_label(st).startswith("FACIES") and not legend_entries(st)


@pytest.mark.gl
def test_poro_colour_bar_spans_xtgeos_range(pictures, case, xgrid, grid):
    from PIL import Image

    import geoshade

    xp = _xprop(case, xgrid, "reek_sim_poro.roff")
    with geoshade.view(grid, property="PORO", annotations=True, size=(480, 360)) as v:
        rgba, st = v.draw()
    Image.fromarray(rgba).save(pictures / "roff_poro_api.png")
    bar = annotations(st)["colorbar"]
    assert bar["label"].startswith("PORO")
    assert (bar["lo"], bar["hi"]) == pytest.approx((float(xp.values.min()),
                                                    float(xp.values.max())), rel=1e-6)
    assert "step" not in "\n".join(t["text"] for t in annotations(st)["title"])


def test_rms_wells_equal_xtgeo(case):
    from geoshade.io.grids.welltraj import read_rms_wells

    for name in ("OP_1", "WI_1"):
        (traj,) = read_rms_wells(case / f"{name}.w")
        w = xtgeo.well_from_file(case / f"{name}.w")
        df = w.get_dataframe()
        assert traj.name == name
        xyz = np.column_stack([df["X_UTME"], df["Y_UTMN"], df["Z_TVDSS"]])
        ours = np.asarray(traj.points)
        assert ours.shape == xyz.shape
        np.testing.assert_allclose(ours[:, :2], xyz[:, :2], rtol=0, atol=1e-3)
        np.testing.assert_allclose(np.abs(ours[:, 2]), np.abs(xyz[:, 2]), rtol=0, atol=1e-3)


def test_rms_file_with_several_wells_reads_them_all(case, tmp_path):
    """RMS ASCII files one after another in one file: every well read, not refused."""
    from geoshade.io.grids.welltraj import read_rms_wells

    both = tmp_path / "reek_wells.w"
    both.write_bytes((case / "OP_1.w").read_bytes() + (case / "WI_1.w").read_bytes())
    wells = read_rms_wells(both)
    assert [w.name for w in wells] == ["OP_1", "WI_1"]
    for w in wells:
        n = len(xtgeo.well_from_file(case / f"{w.name}.w").get_dataframe())
        assert len(np.asarray(w.points)) == n


@pytest.mark.gl
def test_wells_from_rms_files_are_named(cli, case, tmp_path):
    both = tmp_path / "reek_wells.w"
    both.write_bytes((case / "OP_1.w").read_bytes() + (case / "WI_1.w").read_bytes())
    st = cli.render("roff_rms_wells", "grid", "render", case / "reek_sim_grid.roff",
                    "--param", case / "reek_sim_poro.roff", "--property", "PORO",
                    "--wells", both, "--wells-coords", "map", "--size", "640x480")
    names = sorted(lab["text"] for lab in annotations(st).get("labels", []))
    assert names == ["OP_1", "WI_1"], annotations(st).get("labels")


def test_exports_carry_the_parameters(grid, tmp_path):
    import geoshade

    pv = pytest.importorskip("pyvista")
    ds = geoshade.to_pyvista(grid)
    assert isinstance(ds, pv.DataSet)
    assert ds.n_cells in (grid.ncells, grid.nactive)
    assert set(ds.cell_data.keys()) >= {"PORO", "FACIES"}
    xr = geoshade.to_xarray(grid)
    facies = xr["FACIES"].transpose("i", "j", "k")
    np.testing.assert_array_equal(np.asarray(facies), np.asarray(grid.properties["FACIES"]))


def test_sector_export_reads_back_in_xtgeo(cli, case, tmp_path):
    out = tmp_path / "sector.grdecl"
    rc, _, err = cli("grid", "export", case / "reek_sim_grid.roff", "--param",
                     case / "reek_sim_poro.roff", "--slice", "i=10:20,j=20:40,k=0:5", "-o", out)
    assert rc == 0, err
    sector = xtgeo.grid_from_file(out, fformat="grdecl")
    assert tuple(sector.dimensions) == (10, 20, 5)


@pytest.mark.gl
def test_viewer_screenshot(pictures, case):
    img = view_screenshot(pictures, "roff_view", case / "reek_sim_grid.roff",
                          "--exaggeration", "5")
    assert img.shape == (360, 480, 4)
    assert (np.abs(img[..., :3].astype(int) - 255).sum(-1) > 30).mean() > 0.05
