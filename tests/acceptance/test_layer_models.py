"""Acceptance: a layer model in netCDF (top/bottom surfaces per layer) as stacks (issue 31,
item 3).

The case is made at test time from the real Drogon horizons of tests/data/real/rms_irap_drogon
(equinor/xtgeo-testdata, LGPL-3.0): xtgeo samples the four rotated IRAP horizons onto one
north-up 50 m grid (``RegularSurface.resample``), and the three Volantis zones between them are
written the two ways layer models ship — REGIS style, ``top``/``bottom (layer, y, x)`` with the
layer names as the ``layer`` coordinate, elevations in m; and MODFLOW style, ``top (y, x)`` +
``botm (layer, y, x)`` as depths with ``positive="down"``. Oracle: numpy over xtgeo's arrays
(each column's zone top and bottom).
"""

from __future__ import annotations

import numpy as np
import pytest

from tests.acceptance.conftest import annotations, legend_names, title_text, view_screenshot

xtgeo = pytest.importorskip("xtgeo")
xr = pytest.importorskip("xarray")
pytest.importorskip("netCDF4")

HORIZONS = ("01_topvolantis", "02_toptherys", "03_topvolon", "04_basevolantis")
ZONES = ["Volantis top–Therys", "Therys–Volon", "Volon–base Volantis"]
CELL = 50.0


@pytest.fixture(scope="module")
def depths(real):
    """(4, ny, nx) depths of the horizons on one north-up grid (NaN outside), x, y centres."""
    surfs = [xtgeo.surface_from_file(real / "rms_irap_drogon" / f"{h}.gri") for h in HORIZONS]
    x, y = surfs[0].get_xy_values()
    x0, x1 = float(x.min()), float(x.max())
    y0, y1 = float(y.min()), float(y.max())
    nx, ny = int((x1 - x0) // CELL) + 1, int((y1 - y0) // CELL) + 1
    out = []
    for s in surfs:
        r = xtgeo.RegularSurface(ncol=nx, nrow=ny, xori=x0, yori=y0, xinc=CELL, yinc=CELL,
                                 values=0.0)
        r.resample(s)
        out.append(np.ma.filled(r.values.astype(float), np.nan).T)   # (ny, nx), row 0 south
    xs, ys = x0 + CELL * np.arange(nx), y0 + CELL * np.arange(ny)
    return np.stack(out), xs, ys


@pytest.fixture(scope="module")
def regis(depths, tmp_path_factory):
    d, xs, ys = depths
    out = tmp_path_factory.mktemp("layers") / "drogon_layers.nc"
    xr.Dataset({"top": (("layer", "y", "x"), -d[:-1][:, ::-1], {"units": "m"}),
                "bottom": (("layer", "y", "x"), -d[1:][:, ::-1], {"units": "m"})},
               coords={"layer": ZONES, "x": xs, "y": ys[::-1]}).to_netcdf(out)
    return out


@pytest.fixture(scope="module")
def modflow(depths, tmp_path_factory):
    d, xs, ys = depths
    out = tmp_path_factory.mktemp("layers") / "drogon_modflow.nc"
    down = {"units": "m", "positive": "down"}
    xr.Dataset({"top": (("y", "x"), d[0], down), "botm": (("layer", "y", "x"), d[1:], down)},
               coords={"layer": [1, 2, 3], "x": xs, "y": ys}).to_netcdf(out)
    return out


def _zones(model):
    """Per column, {code: (bottom, top)} heights of its material intervals."""
    z = lambda lv: model.origin[2] + float(lv) * model.spacing[2]   # noqa: E731
    out = []
    for c in range(model.ncols):
        a, b = model.offsets[c], model.offsets[c + 1]
        ends = [*model.starts[a + 1:b], model.nlevels]
        out.append({int(model.codes[i]): (z(model.starts[i]), z(ends[i - a]))
                    for i in range(a, b) if model.codes[i] >= 0})
    return out


def _check(model, depths):
    d, xs, ys = depths
    nx = xs.size
    zones = _zones(model)
    assert model.shape == (xs.size, ys.size)
    assert model.origin[:2] == pytest.approx((xs[0] - CELL / 2, ys[0] - CELL / 2))
    z0, dz = model.origin[2], model.spacing[2]
    level = lambda h: np.float32((h - z0) / dz)   # noqa: E731  (heights as float32 levels)
    present = 0
    for c, got in enumerate(zones):
        j, i = divmod(c, nx)
        want = {}
        for k in range(3):
            t, b = -d[k, j, i], -d[k + 1, j, i]
            if np.isfinite(t) and np.isfinite(b) and level(t) > level(b):
                want[k + 1] = (b, t)
        assert sorted(got) == sorted(want), (c, got, want)
        for k, (b, t) in want.items():
            assert got[k][0] == pytest.approx(b, abs=2e-3)
            assert got[k][1] == pytest.approx(t, abs=2e-3)
        present += len(want)
    assert present > 0.3 * 3 * model.ncols
    return zones


def test_regis_style_layers_equal_the_horizons(regis, depths):
    import geoshade

    model = geoshade.load(regis)
    assert model.legend.names == tuple(ZONES) and model.meta["layout"] == "top/bottom"
    _check(model, depths)


def test_modflow_style_depths_are_the_same_model(regis, modflow, depths):
    import geoshade

    a, b = geoshade.load(regis), geoshade.load(modflow)
    assert b.meta["layout"] == "top + botm"
    assert any("positive down" in n for n in b.meta["notes"])
    assert b.legend.names == ("layer 1", "layer 2", "layer 3")
    assert _check(b, depths) == _check(a, depths)


def test_stacks_convert_writes_the_model(cli, regis, tmp_path):
    out = tmp_path / "drogon.stacks.npz"
    rc, text, err = cli("stacks", "convert", regis, "-o", out, "--stats", tmp_path / "s.json")
    assert rc == 0, err
    assert f"{out}:" in text and "intervals" in text
    import geoshade

    back = geoshade.load(out)
    model = geoshade.load(regis)
    assert np.array_equal(back.starts, model.starts) and np.array_equal(back.codes, model.codes)
    assert back.legend.names == tuple(ZONES)


@pytest.mark.gl
def test_stacks_render_on_the_file_names_the_layers(cli, regis):
    st = cli.render("layer_model_drogon", "stacks", "render", regis, "--exaggeration", "20",
                    "--size", "800x600")
    assert legend_names(st) == ZONES
    assert annotations(st)["legend"]["title"] == "layer" or "layer" in title_text(st)
    hidden = cli.render("layer_model_drogon_hidden", "stacks", "render", regis,
                        "--exaggeration", "20", "--size", "800x600", "--hide", "1")
    assert 1 in hidden["hidden"]


@pytest.mark.gl
def test_viewer_screenshot(pictures, modflow):
    img = view_screenshot(pictures, "layer_model_view", modflow)
    assert (np.abs(img[..., :3].astype(int) - 255).sum(-1) > 30).mean() > 0.05
