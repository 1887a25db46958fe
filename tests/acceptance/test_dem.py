"""Acceptance: a real DEM as SRTM-like data ships: geographic (EPSG:4326) int16 metres.

USGS elevations of the Jacksboro fault (Tennessee) from matplotlib's sample data, written as a
GeoTIFF by make_cases.jacksboro_dem. Oracle: rasterio (the file's values, and its own
reprojection to UTM zone 16N by rasterio.warp).
"""

from __future__ import annotations

import re

import numpy as np
import pytest

from tests.acceptance.conftest import annotations, colorbar_label, title_text, view_screenshot

rasterio = pytest.importorskip("rasterio")

UTM16 = "EPSG:32616"  # the UTM zone of the DEM's centre (-84.25°)


@pytest.fixture(scope="module")
def heights(dem):
    with rasterio.open(dem) as f:
        return f.read(1)


@pytest.fixture(scope="module")
def dem_utm(dem, tmp_path_factory):
    """The DEM reprojected by rasterio (nearest neighbour) to UTM 16N: the oracle's copy."""
    from rasterio.warp import Resampling, calculate_default_transform, reproject

    out = tmp_path_factory.mktemp("dem") / "jacksboro_utm16.tif"
    with rasterio.open(dem) as src:
        transform, w, h = calculate_default_transform(src.crs, UTM16, src.width, src.height,
                                                      *src.bounds)
        profile = {**src.profile, "crs": UTM16, "transform": transform, "width": w,
                   "height": h, "nodata": -32768}
        with rasterio.open(out, "w", **profile) as dst:
            reproject(rasterio.band(src, 1), rasterio.band(dst, 1),
                      resampling=Resampling.nearest)
    return out


def _rasterio_bilinear(dem) -> np.ndarray:
    """The DEM reprojected by rasterio (bilinear) onto UTM 16N's default grid; NaN outside."""
    from rasterio.warp import Resampling, calculate_default_transform, reproject

    with rasterio.open(dem) as src:
        transform, w, h = calculate_default_transform(src.crs, UTM16, src.width, src.height,
                                                      *src.bounds)
        out = np.full((h, w), np.nan, np.float32)
        reproject(rasterio.band(src, 1), out, dst_transform=transform, dst_crs=UTM16,
                  resampling=Resampling.bilinear, dst_nodata=np.nan)
    return out


def test_info_describes_the_dem_as_rasterio_reprojects_it(cli, dem):
    oracle = _rasterio_bilinear(dem)
    rc, out, err = cli("info", dem)
    assert rc == 0, err
    assert "EPSG:4326" in out + err and "EPSG:32616" in out, out + err
    assert f"{oracle.shape[1]} × {oracle.shape[0]} cells" in out, out
    assert f"min {np.nanmin(oracle):g}, max {np.nanmax(oracle):g}" in out, out
    assert f"{int(np.isnan(oracle).sum()):,} cells" in out, out


@pytest.mark.gl
def test_projected_dem_has_an_elevation_colour_bar(cli, dem_utm, heights):
    st = cli.render("dem_utm_terrain", "stacks", "render", dem_utm, "--size", "640x480")
    label = colorbar_label(st)
    assert re.match(r"(elevation|height)\b.*\[m\]", label), annotations(st)
    bar = annotations(st)["colorbar"]
    assert (bar["lo"], bar["hi"]) == (float(heights.min()), float(heights.max()))
    legend = annotations(st).get("legend") or {}
    assert [e["text"] for e in legend.get("entries", [])] != ["1 terrain"]


@pytest.mark.gl
def test_geographic_dem_is_reprojected_with_one_note(cli, dem, heights):
    st = cli.render("dem_4326_terrain", "stacks", "render", dem, "--exaggeration", "3",
                    "--size", "640x480")
    notes = " ".join(map(str, st.get("notes", []))) + " " + title_text(st)
    assert re.search(r"UTM|32616|reproject", notes, re.IGNORECASE), notes
    assert re.match(r"(elevation|height)\b.*\[m\]", colorbar_label(st))
    bar = annotations(st)["colorbar"]
    assert heights.min() - 1 <= bar["lo"] and bar["hi"] <= heights.max() + 1
    assert re.search(r"exaggerat\w*\D{0,6}3|[×x]\s?3\b", title_text(st)), title_text(st)


def test_geographic_dem_loads_like_rasterio_reprojects_it(dem, dem_utm):
    """The model of the geographic DEM lies where rasterio puts it in UTM 16N, at its heights."""
    import geoshade

    model = geoshade.load(dem)
    assert len(repr(model)) < 2000
    assert "32616" in str(model.crs) or "UTM" in str(model.crs).upper(), model.crs
    (x0, y0, z0), (x1, y1, z1) = np.asarray(model.bounds())
    with rasterio.open(dem_utm) as f:
        b = f.bounds
        cell = max(f.res)
    bilinear = _rasterio_bilinear(dem)
    assert abs(z1 - np.nanmax(bilinear)) <= 1 and z0 <= np.nanmin(bilinear)
    for ours, theirs in ((x0, b.left), (x1, b.right), (y0, b.bottom), (y1, b.top)):
        assert abs(ours - theirs) <= 2 * cell, (ours, theirs)


@pytest.mark.gl
def test_pick_on_terrain_says_elevation(cli, dem_utm, dem, heights):
    st = cli.render("dem_utm_pick", "stacks", "render", dem_utm, "--size", "640x480",
                    "--pick", "320,240")
    pick = st["pick"]
    assert pick["vertical"] == "elevation" and "depth" not in pick["text"], pick
    x, y, z = pick["world"]
    from rasterio.warp import transform

    with rasterio.open(dem) as f:
        (lon,), (lat,) = transform(UTM16, f.crs, [x], [y])
        row, col = f.index(lon, lat)
    window = heights[max(row - 2, 0):row + 3, max(col - 2, 0):col + 3]
    assert window.min() - 2 <= z <= window.max() + 2, (z, window)


@pytest.mark.gl
def test_viewer_screenshot(pictures, dem_utm):
    img = view_screenshot(pictures, "dem_view", dem_utm)
    assert (np.abs(img[..., :3].astype(int) - 255).sum(-1) > 30).mean() > 0.05
