"""Acceptance: SPE1 simulated by OPM Flow in FIELD units, with a gas injector and a producer.

The deck is tests/data/real/opm_spe1_field/SPE1CASE1.DATA (OPM/opm-tests, ODbL); OPM Flow runs it
at test time (make_cases.spe1_field). Oracles: resfo (every array of EGRID/INIT/UNRST),
scikit-image (the isosurface), the deck (well names and types).
"""

from __future__ import annotations

import re

import numpy as np
import pytest

from tests.acceptance.conftest import (
    annotations,
    colorbar_label,
    inside_picture,
    title_text,
    view_screenshot,
)

resfo = pytest.importorskip("resfo")

NX, NY, NZ = 10, 10, 3


def _restart(egrid, keyword: str) -> list[np.ndarray]:
    """Every report step's array of ``keyword`` (active cells) from the UNRST, by resfo."""
    return [np.asarray(v) for k, v in resfo.read(egrid.with_suffix(".UNRST"))
            if k.strip() == keyword]


def _init(egrid) -> dict[str, np.ndarray]:
    return {k.strip(): np.asarray(v) for k, v in resfo.read(egrid.with_suffix(".INIT"))}


def _cells(values: np.ndarray) -> np.ndarray:
    """Active-cell values (all cells of SPE1 are active) as an (nx, ny, nz) array."""
    return values.reshape((NX, NY, NZ), order="F")


def test_info_says_field_units_steps_and_wells(cli, spe1):
    rc, out, err = cli("info", spe1)
    assert rc == 0, err
    intehead = _init(spe1)["INTEHEAD"]
    assert intehead[2] == 2  # the unit system resfo reads: 2 = FIELD
    assert re.search(r"units\s+FIELD", out), out
    assert "FEET" in out
    n = len(_restart(spe1, "PRESSURE"))
    assert n == 121 and f"steps    {n} " in out
    # the deck's wells: PROD produces oil (WCONPROD), INJ injects gas (WCONINJE)
    assert re.search(r"PROD\s+producer", out) and re.search(r"INJ\s+gas injector", out), out


@pytest.mark.gl
def test_grid_pressure_colour_bar_says_psia_and_its_range_is_resfos(cli, spe1):
    p = _restart(spe1, "PRESSURE")[-1]
    st = cli.render("spe1_grid_pressure", "grid", "render", spe1, "--property", "PRESSURE",
                    "--size", "640x480")
    assert st["unit"] == "psia" and st["unit_system"] == "FIELD"
    assert colorbar_label(st) == "PRESSURE [psia]"
    bar = annotations(st)["colorbar"]
    assert (bar["lo"], bar["hi"]) == pytest.approx((float(p.min()), float(p.max())), rel=1e-6)
    assert st["shown_cells"] == NX * NY * NZ


@pytest.mark.gl
def test_iso_colour_bar_says_psia_like_the_grid(cli, spe1):
    st = cli.render("spe1_iso_sgas_by_pressure", "iso", "render", spe1, "--keyword", "SGAS",
                    "--level", "0.1", "--color-by", "PRESSURE", "--size", "640x480")
    assert st["unit_system"] == "FIELD"
    assert colorbar_label(st) == "PRESSURE [psia]"


@pytest.mark.gl
@pytest.mark.parametrize("part", ["grid", "iso"])
def test_rs_is_in_field_units_in_every_part(cli, spe1, part):
    """RS of a FIELD case is Mscf/stb, never the METRIC sm³/sm³."""
    if part == "grid":
        st = cli.render("spe1_grid_rs", "grid", "render", spe1, "--property", "RS",
                        "--size", "480x360")
    else:
        st = cli.render("spe1_iso_sgas_by_rs", "iso", "render", spe1, "--keyword", "SGAS",
                        "--level", "0.1", "--color-by", "RS", "--size", "480x360")
    label = colorbar_label(st)
    assert label.startswith("RS [") and "sm" not in label, label
    assert re.search(r"Mscf/stb", label, re.IGNORECASE), label


@pytest.mark.gl
def test_static_property_title_has_no_step(cli, spe1):
    st = cli.render("spe1_grid_permx", "grid", "render", spe1, "--property", "PERMX",
                    "--size", "480x360")
    title = title_text(st)
    assert "PERMX" in title
    assert not re.search(r"\bstep\b|\breport\b|20\d\d-\d\d-\d\d", title), title
    assert colorbar_label(st) == "PERMX [mD]"


@pytest.mark.gl
@pytest.mark.parametrize("part", ["grid", "iso"])
def test_exaggeration_is_said_in_the_title(cli, spe1, part):
    args = (["grid", "render", spe1, "--property", "PRESSURE"] if part == "grid" else
            ["iso", "render", spe1, "--keyword", "SGAS", "--level", "0.1"])
    st = cli.render(f"spe1_{part}_exaggeration5", *args, "--exaggeration", "5",
                    "--size", "480x360")
    assert st["exaggeration"] == 5
    assert re.search(r"exaggerat\w*\D{0,6}5|[×x]\s?5\b|\b5\s?[×x]", title_text(st)), \
        title_text(st)


@pytest.mark.gl
def test_wells_are_named_pipes_with_their_type_colours(cli, spe1):
    st = cli.render("spe1_grid_wells", "grid", "render", spe1, "--property", "SGAS",
                    "--size", "640x480")
    labels = {lab["text"]: lab for lab in annotations(st).get("labels", [])}
    assert set(labels) == {"PROD", "INJ"}
    assert all(inside_picture(st, lab["bbox"]) for lab in labels.values())
    assert sorted(st["sim_well_names"]) == ["INJ", "PROD"]


@pytest.mark.gl
def test_deck_wells_are_named_like_restart_wells(cli, spe1, tmp_path):
    """The deck alone (no run beside it): wells from WELSPECS/COMPDAT, named."""
    deck = tmp_path / "SPE1CASE1.DATA"
    deck.write_bytes(spe1.with_suffix(".DATA").read_bytes())
    st = cli.render("spe1_deck_wells", "grid", "render", deck, "--property", "PERMX",
                    "--size", "640x480")
    names = {lab["text"] for lab in annotations(st).get("labels", [])}
    assert names == {"PROD", "INJ"}, annotations(st).get("labels")


def test_api_numbers_equal_resfo(spe1):
    import geoshade

    grid = geoshade.load(spe1)
    assert grid.dims == (NX, NY, NZ)
    init = _init(spe1)
    np.testing.assert_array_equal(grid.properties["PORO"], _cells(init["PORO"]))
    np.testing.assert_array_equal(grid.properties["PERMX"], _cells(init["PERMX"]))
    pressure = _restart(spe1, "PRESSURE")
    assert len(grid.steps) == len(pressure) == 121
    for k in (0, 60, -1):
        np.testing.assert_array_equal(grid.steps[k]["PRESSURE"], _cells(pressure[k]))
    swat = _restart(spe1, "SWAT")
    np.testing.assert_array_equal(grid.steps[-1]["SWAT"], _cells(swat[-1]))


def test_repr_is_short_and_says_sizes_and_steps(spe1):
    import geoshade

    text = repr(geoshade.load(spe1))
    assert len(text) < 2000, f"{len(text)} characters: {text[:200]}"
    assert "10" in text and "121" in text, text


def test_to_pyvista_and_to_xarray_carry_the_cells(spe1):
    import geoshade

    pv = pytest.importorskip("pyvista")
    grid = geoshade.load(spe1)
    ds = geoshade.to_pyvista(grid)
    assert isinstance(ds, pv.DataSet)
    assert ds.n_cells == NX * NY * NZ
    init = _init(spe1)
    poro = np.asarray(ds.cell_data["PORO"])
    assert sorted(poro.tolist()) == sorted(init["PORO"].astype(poro.dtype).tolist())
    xr = geoshade.to_xarray(grid)
    assert "PORO" in xr
    np.testing.assert_array_equal(np.asarray(xr["PORO"]).ravel(),
                                  np.asarray(grid.properties["PORO"]).ravel())


def test_sector_export_equals_the_selected_cells(cli, spe1, tmp_path):
    out = tmp_path / "SECTOR.EGRID"
    rc, _, err = cli("grid", "export", spe1, "--slice", "i=2:7,j=0:4,k=1:3", "-o", out)
    assert rc == 0, err
    head = {k.strip(): np.asarray(v) for k, v in resfo.read(out)}["GRIDHEAD"]
    assert tuple(int(v) for v in head[1:4]) == (5, 4, 2)
    sector = {k.strip(): np.asarray(v) for k, v in resfo.read(out.with_suffix(".INIT"))}
    permx = _cells(_init(spe1)["PERMX"])[2:7, 0:4, 1:3]
    np.testing.assert_array_equal(sector["PERMX"], permx.ravel(order="F"))


@pytest.mark.gl
def test_iso_mesh_equals_scikit_image(cli, spe1, tmp_path):
    measure = pytest.importorskip("skimage.measure")
    meshio = pytest.importorskip("meshio")
    sgas = _cells(_restart(spe1, "SGAS")[-1]).astype(np.float64)
    verts, faces, _, _ = measure.marching_cubes(sgas, 0.1, method="lorensen")
    ply = tmp_path / "front.ply"
    st = cli.render("spe1_iso_mesh", "iso", "render", spe1, "--keyword", "SGAS", "--level",
                    "0.1", "--mesh", ply, "--size", "320x240")
    mesh = meshio.read(ply)
    assert st["triangles"] == len(faces) == sum(len(c.data) for c in mesh.cells)
    assert len(mesh.points) == len(verts)


@pytest.mark.gl
def test_viewer_screenshot_shows_the_case(pictures, spe1):
    img = view_screenshot(pictures, "spe1_view_pressure", spe1, "--property", "PRESSURE",
                          "--exaggeration", "5")
    assert img.shape == (360, 480, 4)
    rgb = img[..., :3].astype(int)
    assert (np.abs(rgb - 255).sum(-1) > 30).mean() > 0.1  # drawn, not a blank picture


@pytest.mark.gl
def test_animation_colour_range_spans_every_step(cli, spe1, pictures, tmp_path):
    """``iso animate``: the colour range over all steps (not step 0's), and each frame's
    isosurface equal to scikit-image's at that step."""
    measure = pytest.importorskip("skimage.measure")
    import json

    stats = tmp_path / "anim.json"
    rc, _, err = cli("iso", "animate", spe1, "--keyword", "SGAS", "--level", "0.1",
                     "--color-by", "PRESSURE", "--size", "160x120", "-o",
                     pictures / "spe1_iso_animate.gif", "--stats", stats)
    assert rc == 0, err
    st = json.loads(stats.read_text())
    pressure = np.concatenate(_restart(spe1, "PRESSURE"))
    assert st["color_range"] == pytest.approx([float(pressure.min()), float(pressure.max())],
                                              rel=1e-6)
    sgas = _restart(spe1, "SGAS")
    assert st["frames"] == len(sgas)
    for k in (1, 30, 120):
        field = _cells(sgas[k]).astype(np.float64)
        _, faces, _, _ = measure.marching_cubes(field, 0.1, method="lorensen")
        assert st["triangles"][k] == len(faces), k


@pytest.mark.gl
@pytest.mark.parametrize("part", ["grid", "iso"])
def test_pick_says_psia_and_feet_and_resfos_value(cli, spe1, part):
    p = _cells(_restart(spe1, "PRESSURE")[-1])
    if part == "grid":
        st = cli.render("spe1_grid_pick", "grid", "render", spe1, "--property", "PRESSURE",
                        "--size", "640x480", "--pick", "320,240")
    else:
        st = cli.render("spe1_iso_pick", "iso", "render", spe1, "--keyword", "SGAS", "--level",
                        "0.1", "--color-by", "PRESSURE", "--size", "480x360", "--pick",
                        "240,200")
    pick = st["pick"]
    assert pick["unit"] == "psia" and pick["length_unit"] == "ft", pick
    assert "psia" in pick["text"] and "bar" not in pick["text"]
    i, j, k = pick["index"]
    if part == "grid":
        assert pick["value"] == pytest.approx(float(p[i, j, k]), rel=1e-6)
    else:  # interpolated on the surface between the cell centres around the picked cell
        near = p[max(i - 1, 0):i + 2, max(j - 1, 0):j + 2, max(k - 1, 0):k + 2]
        assert near.min() - 1e-3 <= pick["value"] <= near.max() + 1e-3, (pick, near)


def test_deck_wells_typed_by_wconprod_and_wconinje(real, tmp_path):
    """The deck alone: PROD (WCONPROD) a producer, INJ (WCONINJE 'GAS') a gas injector, each
    completed in its one COMPDAT cell (10, 10, 3) and (1, 1, 1), 1-based."""
    import warnings

    import geoshade

    deck = tmp_path / "SPE1CASE1.DATA"
    deck.write_bytes((real / "opm_spe1_field" / "SPE1CASE1.DATA").read_bytes())
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        grid = geoshade.load(deck)
    assert grid.meta["unit_system"] == "FIELD"
    wells = {w.name: w for w in grid.meta["wells"]}
    assert {n: w.type for n, w in wells.items()} == {"PROD": "producer", "INJ": "gas injector"}
    assert [len(w.markers) for w in (wells["PROD"], wells["INJ"])] == [1, 1]
    # cell centres from the deck's DX = DY = 1000 ft, DZ = 20/30/50 ft, TOPS = 8325 ft
    np.testing.assert_allclose(wells["PROD"].markers, [[9500, 9500, 8325 + 20 + 30 + 25]])
    np.testing.assert_allclose(wells["INJ"].markers, [[500, 500, 8325 + 10]])
