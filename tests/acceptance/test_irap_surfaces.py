"""Acceptance: RMS horizons as IRAP surfaces, and a rotated GeoTIFF (issue 31, item 3).

Files as they ship (tests/data/real/rms_irap_drogon, equinor/xtgeo-testdata, LGPL-3.0): Drogon's
four horizons ``01_topvolantis.gri`` … ``04_basevolantis.gri`` (IRAP binary, rotated 30°, depths)
and Reek's ``reek_stooip_map.gri`` (not rotated, 5033 undefined nodes). Made from them at test
time: Drogon's top written as a GeoTIFF whose transform carries the rotation (rasterio).
Oracle: xtgeo (node values, header; ``get_value_from_xy``: the bilinear value at any point of a
rotated surface).
"""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from tests.acceptance.conftest import annotations, colorbar_label, title_text, view_screenshot

xtgeo = pytest.importorskip("xtgeo")
rasterio = pytest.importorskip("rasterio")

CASE = "rms_irap_drogon"
HORIZONS = ("01_topvolantis", "02_toptherys", "03_topvolon", "04_basevolantis")


@pytest.fixture(scope="module")
def case(real):
    return real / CASE


@pytest.fixture(scope="module")
def top(case):
    return case / "01_topvolantis.gri"


@pytest.fixture(scope="module")
def xtop(top):
    return xtgeo.surface_from_file(top)


def _column_centres(model):
    nx, ny = model.shape
    x = model.origin[0] + (np.arange(nx) + 0.5) * model.spacing[0]
    y = model.origin[1] + (np.arange(ny) + 0.5) * model.spacing[1]
    return x, y


def _sample(model, n=300, seed=3):
    """Columns with material, sampled: (column ids, x, y)."""
    has = np.flatnonzero(model.counts() > 0)
    cols = np.random.default_rng(seed).choice(has, min(n, has.size), replace=False)
    x, y = _column_centres(model)
    nx = model.shape[0]
    return cols, x[cols % nx], y[cols // nx]


def test_info_says_rotation_and_depth(cli, top, xtop):
    rc, out, err = cli("info", top)
    assert rc == 0, err
    assert "IRAP surface (RMS)" in out and "rotated 30°" in out
    assert "values are depths" in out and "metres assumed" in out
    lo, hi = re.findall(r"min (-?[\d.]+), max (-?[\d.]+)", out)[0]
    assert -float(xtop.values.max()) - 1e-3 <= float(lo) and float(hi) <= \
        -float(xtop.values.min()) + 1e-3


def test_a_horizon_loads_where_xtgeo_places_it(top, xtop):
    import geoshade

    model = geoshade.load(top)
    heights = model.origin[2] + model.column_tops() * model.spacing[2]
    cols, xs, ys = _sample(model)
    compared = 0
    for c, x, y in zip(cols, xs, ys, strict=True):
        v = xtop.get_value_from_xy((x, y))
        if v is not None:
            assert heights[c] == pytest.approx(-v, abs=2e-3), (x, y)
            compared += 1
    assert compared > 0.9 * len(cols)
    assert any("rotated 30°" in n for n in model.meta["notes"])
    assert model.unit == "m (assumed)"


def test_undefined_nodes_are_empty_columns(case):
    import geoshade

    path = case / "reek_stooip_map.gri"
    s = xtgeo.surface_from_file(path)
    model = geoshade.load(path)
    assert model.shape == (s.ncol, s.nrow)
    assert int((model.counts() == 0).sum()) == int(np.ma.getmaskarray(s.values).sum()) == 5033


@pytest.mark.gl
def test_positive_up_takes_the_values_as_heights(cli, top, xtop, tmp_path):
    """``--positive up`` (an IRAP map of heights, e.g. a thickness or a topography): the bar
    spans xtgeo's values themselves and nothing is said assumed of the sign; ``--positive
    down`` is told, not assumed; a GeoTIFF (heights) refuses the flag in one line."""
    st = cli.render("irap_drogon_up", "stacks", "render", top, "--size", "640x480",
                    "--positive", "up")
    bar = annotations(st)["colorbar"]
    assert float(xtop.values.min()) - 1e-3 <= bar["lo"] < bar["hi"] <= \
        float(xtop.values.max()) + 1e-3
    import geoshade
    from geoshade.stacks import convert

    told = convert(top, positive="down").meta.get("notes") or []
    assumed = geoshade.load(top).meta.get("notes") or []
    assert not any("depths (RMS)" in n for n in told)
    assert any("depths (RMS)" in n for n in assumed)
    tif = tmp_path / "dem.tif"
    with rasterio.open(tif, "w", driver="GTiff", width=4, height=3, count=1, dtype="float32",
                       crs="EPSG:32631", transform=rasterio.transform.from_origin(
                           0, 30, 10, 10)) as dst:
        dst.write(np.ones((1, 3, 4), np.float32))
    rc, _, err = cli("stacks", "render", tif, "-o", tmp_path / "x.png", "--positive", "up")
    assert rc == 2 and err.count("\n") == 1 and "applies to IRAP surfaces" in err, err


@pytest.mark.gl
def test_render_a_horizon_with_its_elevation_bar(cli, top, xtop):
    st = cli.render("irap_drogon_top", "stacks", "render", top, "--size", "800x600")
    assert re.match(r"elevation \[m \(assumed\)\]", colorbar_label(st)), colorbar_label(st)
    bar = annotations(st)["colorbar"]
    assert -float(xtop.values.max()) - 1e-3 <= bar["lo"] < bar["hi"] <= \
        -float(xtop.values.min()) + 1e-3
    assert "rotated 30°" in title_text(st)


@pytest.mark.gl
def test_pick_on_a_horizon_is_its_depth(cli, top, xtop):
    st = cli.render("irap_drogon_pick", "stacks", "render", top, "--size", "640x480",
                    "--pick", "320,240")
    p = st["pick"]
    assert p["vertical"] == "elevation"
    x, y, z = p["world"]
    window = [xtop.get_value_from_xy((x + dx, y + dy)) for dx in (-60, 0, 60)
              for dy in (-60, 0, 60)]
    window = [-w for w in window if w is not None]
    assert window and min(window) - 1 <= z <= max(window) + 1, (z, window)


@pytest.mark.gl
def test_four_horizons_are_a_layered_model(cli, case):
    import geoshade
    from geoshade.stacks import convert

    paths = [case / f"{h}.gri" for h in HORIZONS]
    st = cli.render("irap_drogon_layers", "stacks", "render", paths[0],
                    *[a for p in paths[1:] for a in ("--surface", p)],
                    "--exaggeration", "20", "--size", "800x600")
    entries = [e["text"] for e in annotations(st)["legend"]["entries"]]
    assert entries == [f"{k + 1} {HORIZONS[k]} – {HORIZONS[k + 1]}" for k in range(3)]
    model = convert(None, surfaces=paths)
    assert isinstance(model, geoshade.StackModel)
    xs_ = [xtgeo.surface_from_file(p) for p in paths]
    cols, xs, ys = _sample(model, n=120)
    z = lambda lv: model.origin[2] + float(lv) * model.spacing[2]   # noqa: E731
    checked = 0
    for c, x, y in zip(cols, xs, ys, strict=True):
        depths = [s.get_value_from_xy((x, y)) for s in xs_]
        if any(d is None for d in depths):
            continue
        a, b = model.offsets[c], model.offsets[c + 1]
        starts = {int(k): z(s) for s, k in zip(model.starts[a:b], model.codes[a:b],
                                                strict=True)}
        for k in (1, 2, 3):      # unit k lies between horizon k (top) and k + 1
            if depths[k] > depths[k - 1] + 1e-2:     # present (thicker than float32 noise)
                assert starts[k] == pytest.approx(-depths[k], abs=2e-3), (x, y, k)
        checked += 1
    assert checked > 50


# --- rotated GeoTIFF ---------------------------------------------------------------------------
@pytest.fixture(scope="module")
def rotated_tif(top, xtop, tmp_path_factory):
    """Drogon's top depth as a GeoTIFF with rotation terms in its transform."""
    from affine import Affine

    s = xtop
    rot = math.radians(s.rotation)
    c, sn = math.cos(rot), math.sin(rot)
    ny = s.nrow
    corner = (s.xori - (ny - 1) * s.yinc * sn, s.yori + (ny - 1) * s.yinc * c)
    t = Affine(s.xinc * c, s.yinc * sn, corner[0], s.xinc * sn, -s.yinc * c, corner[1]) \
        @ Affine.translation(-0.5, -0.5)
    z = np.ma.filled(s.values.astype(np.float32), -9999.0).T[::-1]   # row 0: the last j
    out = tmp_path_factory.mktemp("rotated") / "drogon_top_rotated.tif"
    with rasterio.open(out, "w", driver="GTiff", width=s.ncol, height=ny, count=1,
                       dtype="float32", crs="EPSG:23031", transform=t, nodata=-9999.0) as dst:
        dst.write(z, 1)
    return out


def test_rotated_geotiff_loads_where_xtgeo_places_the_surface(rotated_tif, xtop):
    import geoshade

    with rasterio.open(rotated_tif) as f:
        assert f.transform.b != 0 and f.transform.d != 0
    model = geoshade.load(rotated_tif)
    assert any("rotated 30°" in n for n in model.meta["notes"]) and model.crs == "EPSG:23031"
    heights = model.origin[2] + model.column_tops() * model.spacing[2]
    cols, xs, ys = _sample(model)
    compared = 0
    for c, x, y in zip(cols, xs, ys, strict=True):
        v = xtop.get_value_from_xy((x, y))
        if v is not None:            # a GeoTIFF's values are heights as written: the depths
            assert heights[c] == pytest.approx(v, abs=2e-3), (x, y)
            compared += 1
    assert compared > 0.9 * len(cols)


@pytest.mark.gl
def test_rotated_geotiff_renders_and_says_so(cli, rotated_tif):
    st = cli.render("rotated_geotiff", "stacks", "render", rotated_tif, "--size", "800x600")
    assert "rotated 30°" in title_text(st)
    assert st["columns"] > 0


@pytest.mark.gl
def test_viewer_screenshot(pictures, top):
    img = view_screenshot(pictures, "irap_view", top)
    assert (np.abs(img[..., :3].astype(int) - 255).sum(-1) > 30).mean() > 0.05

