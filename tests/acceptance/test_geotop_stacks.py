"""Acceptance: a layered voxel model as it ships: GeoTOP v1.6 (TNO) around Utrecht Science Park.

Read in place from ../shared/data/geotop_usp (Deltares geost, LGPL-3.0; TNO open data), with the
TNO code tables of legend_nlmod/ (nlmod, MIT). Oracles: xarray (the netCDF codes) and the TNO
table (names and colours of the lithoclasses).
"""

from __future__ import annotations

import csv

import numpy as np
import pytest

from tests.acceptance.conftest import annotations, inside_picture, title_text, view_screenshot

xr = pytest.importorskip("xarray")
pytestmark = pytest.mark.data  # reads ../shared/data


@pytest.fixture(scope="module")
def geotop(shared):
    return shared / "geotop_usp" / "geotop_usp.nc"


def _litho_table(shared) -> dict[int, tuple[str, tuple[int, int, int]]]:
    path = shared / "geotop_usp" / "legend_nlmod" / "REF_GTP_LITHO_CLASS.csv"
    with path.open(newline="", encoding="utf-8") as f:
        return {int(r["VOXEL_NR"]): (r["DESCRIPTION"], (int(r["RED_DEC"]), int(r["GREEN_DEC"]),
                                                         int(r["BLUE_DEC"])))
                for r in csv.DictReader(f) if r["VOXEL_NR"].strip().isdigit()}


def test_info_equals_xarray(cli, geotop):
    with xr.open_dataset(geotop) as ds:
        lithok = ds["lithok"].values
        sizes = ds.sizes["x"], ds.sizes["y"], ds.sizes["z"]
        x0 = float(ds["x"].values.min())
    rc, out, err = cli("info", geotop)
    assert rc == 0, err
    assert "{} × {} × {}".format(*sizes) in out, out
    assert f"{int(np.isnan(lithok).sum()):,} NaN" in out
    assert f"min {np.nanmin(lithok):g}, max {np.nanmax(lithok):g}" in out
    assert f"origin   {x0 - 50:g}" in out  # cell centres in the file, origin at the corner


@pytest.mark.gl
def test_lithoclass_legend_has_the_tno_names_and_colours(cli, geotop, shared):
    with xr.open_dataset(geotop) as ds:
        lithok = ds["lithok"].values
        nx, ny = ds.sizes["x"], ds.sizes["y"]
    codes = np.unique(lithok[~np.isnan(lithok)]).astype(int)
    table = _litho_table(shared)
    st = cli.render("geotop_lithok", "stacks", "render", geotop, "--variable", "lithok",
                    "--logs", "none", "--exaggeration", "20", "--size", "800x600")
    assert st["columns"] == nx * ny
    legend = annotations(st)["legend"]
    assert inside_picture(st, legend["bbox"]), legend
    entries = legend["entries"]
    assert len(entries) == len(codes)
    for code, entry in zip(codes, entries, strict=True):
        name, rgb = table[int(code)]
        assert entry["text"].startswith(str(code)) and entry["text"].endswith(name), entry
        assert tuple(entry["rgba"][:3]) == rgb, (entry, rgb)
    assert "20" in title_text(st)


@pytest.mark.gl
def test_viewer_screenshot(pictures, geotop):
    img = view_screenshot(pictures, "geotop_view", geotop, "--exaggeration", "20")
    assert (np.abs(img[..., :3].astype(int) - 255).sum(-1) > 30).mean() > 0.02
