"""Terrain as users have it (issue 31 item 3), through the format table's ``terrain`` rows: Arc
ASCII grids (``.asc`` + ``.prj``), SRTM tiles (``.hgt``, ``.hgt.zip``) next to GeoTIFF, on the
GeoTIFF DEM's route (``geoshade.load``, ``info``, ``stacks convert``/``render``). Oracle:
rasterio's own reading of the same files (and its reprojection). A raster without CRS whose
extent looks like degrees is taken as EPSG:4326 and says so; never drawn as metres."""

from __future__ import annotations

import json
import zipfile

import numpy as np
import pytest

rasterio = pytest.importorskip("rasterio", reason="the geo extra (rasterio) is not installed")
from rasterio.crs import CRS  # noqa: E402
from rasterio.warp import calculate_default_transform  # noqa: E402

import geoshade  # noqa: E402
from geoshade.cli.main import main  # noqa: E402
from geoshade.io import formats  # noqa: E402
from geoshade.io.layers.dem import read_dem  # noqa: E402

NODATA = -9999
SRTM = 1201   # samples a side of a 3 arc-second tile


def run(capsys, *argv):
    rc = main([str(a) for a in argv])
    out = capsys.readouterr()
    return rc, out.out, out.err


def heights(nx: int, ny: int) -> np.ndarray:
    y, x = np.mgrid[0:ny, 0:nx]
    return np.round(120 + 30 * np.sin(x / 5.0) + 12 * np.cos(y / 3.0), 2)


def write_asc(path, z, x0, y0, cell, prj: str | None = None):
    """An Arc ASCII grid (row 0 north) and, with ``prj``, its CRS beside it as WKT."""
    lines = [f"ncols {z.shape[1]}", f"nrows {z.shape[0]}", f"xllcorner {x0!r}",
             f"yllcorner {y0!r}", f"cellsize {cell!r}", f"NODATA_value {NODATA}"]
    lines += [" ".join(f"{v:g}" for v in row) for row in z]
    path.write_text("\n".join(lines) + "\n")
    if prj:
        path.with_suffix(".prj").write_text(CRS.from_user_input(prj).to_wkt())
    return path


def write_hgt(path, seed: int = 0) -> np.ndarray:
    """An SRTM tile: big-endian int16, 1201 x 1201, row 0 north; its name places it."""
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[0:SRTM, 0:SRTM]
    z = (800 + 600 * np.sin(x / 150.0) * np.cos(y / 200.0) + rng.integers(0, 5, x.shape))
    z = z.astype(">i2")
    z[:3, :5] = -32768   # voids
    z.tofile(path)
    return z


def rasterio_heights(path) -> np.ndarray:
    with rasterio.open(path) as f:
        return np.ma.filled(f.read(1, masked=True).astype(np.float64), np.nan)


@pytest.fixture
def asc(tmp_path):
    z = heights(40, 30)
    z[0, :3] = NODATA
    return write_asc(tmp_path / "dem.asc", z, 155000.0, 463000.0, 25.0, prj="EPSG:28992"), z


def test_terrain_rows_of_the_table():
    for name, row in (("dem.asc", "arc-ascii"), ("N46E008.hgt", "srtm"),
                      ("N46E008.HGT.ZIP", "srtm"), ("dem.tif", "geotiff")):
        fmt = formats.find(name, sniff=False)
        assert fmt.name == row and fmt.domain == "terrain" and fmt.extra == "geo"
    assert all(f.reader == "geoshade.io.layers.dem:read_dem" for f in formats.FORMATS
               if f.domain == "terrain" and f.name != "irap")   # IRAP: io/layers/irap.py


def test_arc_ascii_reads_as_rasterio_does(asc):
    path, _ = asc
    d = read_dem(path)
    want = rasterio_heights(path)
    np.testing.assert_array_equal(d.data[::-1], want)   # row 0 south
    with rasterio.open(path) as f:
        assert d.crs == "EPSG:28992" == f"EPSG:{f.crs.to_epsg()}"
        assert d.origin == (f.bounds.left, f.bounds.bottom) and d.spacing == f.res
    assert np.isnan(d.data[-1, :3]).all() and "assumed_crs" not in d.meta
    assert [p.name for p in formats.case_files(path)] == ["dem.asc", "dem.prj"]


def test_arc_ascii_loads_as_a_terrain_model(asc):
    path, _ = asc
    model = geoshade.load(path)
    want = rasterio_heights(path)[::-1].ravel()   # columns c = ix + nx * iy, row 0 south
    ok = np.isfinite(want)
    assert type(model).__name__ == "StackModel" and model.crs == "EPSG:28992"
    tops = model.column_tops().astype(np.float64) + model.origin[2]
    np.testing.assert_allclose(tops[ok], want[ok], atol=1e-4)
    assert (model.counts()[~ok] == 0).all()


def test_info_of_an_arc_ascii_grid(capsys, asc):
    path, _ = asc
    rc, text, err = run(capsys, "info", path, "--json")
    assert rc == 0, err
    d = json.loads(text)
    want = rasterio_heights(path)
    assert d["kind"] == "dem" and d["format"] == "Arc ASCII grid (rasterio)"
    assert d["crs"] == "EPSG:28992" and d["size"] == [40, 30]
    assert (d["min"], d["max"]) == (np.nanmin(want), np.nanmax(want))
    assert d["nodata_cells"] == 3 and "assumed" not in d


@pytest.fixture
def srtm(tmp_path):
    path = tmp_path / "N46E008.hgt"
    z = write_hgt(path)
    zipped = tmp_path / "N46E008.hgt.zip"
    with zipfile.ZipFile(zipped, "w", zipfile.ZIP_DEFLATED) as zf:
        zf.write(path, path.name)
    return path, zipped, z


def test_srtm_tile_reads_as_rasterio_does(srtm):
    path, zipped, z = srtm
    want = rasterio_heights(path)
    assert np.isnan(want[:3, :5]).all() and np.array_equal(want[5:, 5:], z[5:, 5:])
    for f in (path, zipped):
        d = read_dem(f, project=False)
        np.testing.assert_array_equal(d.data[::-1], want)
        assert d.crs == "EPSG:4326" and d.shape == (SRTM, SRTM)
        half = 1 / 2400   # the SRTM samples are cell centres on whole degrees
        np.testing.assert_allclose(d.origin, (8 - half, 46 - half))
        np.testing.assert_allclose(d.spacing, (1 / 1200, 1 / 1200))


def test_srtm_tile_loads_where_rasterio_reprojects_it(srtm):
    path, zipped, _ = srtm
    with rasterio.open(path) as f:
        t, w, h = calculate_default_transform(f.crs, "EPSG:32632", f.width, f.height, *f.bounds)
    cell = max(abs(t.a), abs(t.e))
    left, top, right, bottom = t.c, t.f, t.c + w * t.a, t.f + h * t.e
    for f in (path, zipped):
        with pytest.warns(UserWarning, match="reprojected from EPSG:4326"):
            model = geoshade.load(f)
        assert model.crs == "EPSG:32632"   # UTM 32N: the tile's centre, 8.5° E
        assert any("reprojected" in n for n in model.meta["notes"])
        (x0, y0, _), (x1, y1, z1) = np.asarray(model.bounds())
        for ours, theirs in ((x0, left), (x1, right), (y0, bottom), (y1, top)):
            assert abs(ours - theirs) <= 2 * cell, (ours, theirs)
        assert abs(z1 - np.nanmax(rasterio_heights(path))) <= 5


def test_info_of_a_zipped_srtm_tile(capsys, srtm):
    _, zipped, _ = srtm
    rc, text, err = run(capsys, "info", zipped)
    assert rc == 0, err
    assert "(DEM, SRTM height tile (rasterio))" in text and "EPSG:32632" in text
    assert "reprojected from EPSG:4326" in text


def test_raster_without_crs_in_degrees_is_taken_as_wgs84_and_says_so(capsys, tmp_path):
    path = write_asc(tmp_path / "nocrs.asc", heights(60, 48), 8.0, 46.0, 1 / 1200)
    with pytest.warns(UserWarning, match="assumed EPSG:4326"):
        d = read_dem(path)
    assert d.crs == "EPSG:32632" and "looks like degrees" in d.meta["assumed_crs"]
    assert 60 < d.spacing[0] < 80   # metres, not 0.00083 "metres"
    rc, text, err = run(capsys, "info", path, "--json")
    assert rc == 0, err
    info = json.loads(text)
    assert info["crs"] == "EPSG:32632" and "assumed EPSG:4326" in info["assumed"][0]
    with pytest.warns(UserWarning):
        model = geoshade.load(path)
    assert "assumed EPSG:4326" in " ".join(model.meta["notes"])


def test_raster_without_crs_in_metres_is_taken_as_it_is(tmp_path):
    path = write_asc(tmp_path / "local.asc", heights(20, 10), 1000.0, 2000.0, 5.0)
    d = read_dem(path)
    assert d.crs == "" and d.origin == (1000.0, 2000.0) and "assumed_crs" not in d.meta


@pytest.mark.gl
def test_render_of_a_degree_raster_without_crs_is_not_empty(capsys, tmp_path):
    path = write_asc(tmp_path / "nocrs.asc", heights(60, 48), 8.0, 46.0, 1 / 1200)
    out, stats = tmp_path / "t.png", tmp_path / "t.json"
    rc, _, err = run(capsys, "stacks", "render", path, "-o", out, "--size", "160x120",
                     "--frames", 1, "--stats", stats, "--no-annotations")
    assert rc == 0, err
    s = json.loads(stats.read_text())
    assert "assumed EPSG:4326" in " ".join(s["notes"])
    assert "warning" not in s   # no EmptySceneWarning
    from PIL import Image

    img = np.asarray(Image.open(out))
    background = img[0, 0]
    assert (np.abs(img.astype(int) - background).sum(axis=-1) > 0).mean() > 0.1
