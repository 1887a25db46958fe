"""``geoshade info DEM.tif``, ``stacks convert DEM.tif [--surface ...] [--top DEM]`` and
``stacks render --drape ORTHO.tif`` end to end, and the bad inputs (one line each)."""

from __future__ import annotations

import json

import numpy as np
import pytest

rasterio = pytest.importorskip("rasterio", reason="the geo extra (rasterio) is not installed")
from affine import Affine  # noqa: E402

from geoshade.cli.main import main  # noqa: E402
from geoshade.io.layers.stackfile import read_stacks  # noqa: E402

NODATA = -9999.0


def run(capsys, *argv):
    rc = main([str(a) for a in argv])
    out = capsys.readouterr()
    return rc, out.out, out.err


def write_tif(path, bands, x0=500.0, ytop=800.0, cell=10.0, crs="EPSG:28992", nodata=NODATA):
    a = np.asarray(bands)
    a = a[None] if a.ndim == 2 else a
    with rasterio.open(path, "w", driver="GTiff", width=a.shape[2], height=a.shape[1],
                       count=a.shape[0], dtype=a.dtype, crs=crs, nodata=nodata,
                       transform=Affine(cell, 0, x0, 0, -cell, ytop)) as dst:
        dst.write(a)
    return path


def heights(nx=24, ny=18) -> np.ndarray:
    y, x = np.mgrid[0:ny, 0:nx]
    return (40 + 6 * np.sin(x / 4.0) + 3 * np.cos(y / 5.0)).astype(np.float32)


@pytest.fixture
def dem(tmp_path):
    z = heights()
    z[0, :4] = NODATA
    return write_tif(tmp_path / "dem.tif", z), z


def one_line(err: str) -> bool:
    return len(err.strip().splitlines()) == 1 and "Traceback" not in err


def test_info_describes_a_dem_and_an_orthophoto(capsys, tmp_path, dem):
    path, z = dem
    rc, text, err = run(capsys, "info", path)
    assert rc == 0, err
    ok = z[z != NODATA]
    for want in ("(DEM", "24 × 18 cells", "cell     10 × 10", "x 500..740, y 620..800",
                 "EPSG:28992", "4 cells", f"min {ok.min():.6g}", f"max {ok.max():.6g}"):
        assert want in text, (want, text)
    rc, text, _ = run(capsys, "info", path, "--json")
    d = json.loads(text)
    assert d["kind"] == "dem" and d["nodata_cells"] == 4 and d["nodata"] == NODATA
    assert d["extent"] == [500.0, 620.0, 740.0, 800.0] and d["min"] == float(ok.min())
    rgb = write_tif(tmp_path / "ortho.tif", np.zeros((3, 5, 6), np.uint8), nodata=None)
    rc, text, _ = run(capsys, "info", rgb)
    assert rc == 0 and "3 bands" in text and "drape" in text


def test_convert_a_dem_writes_a_terrain_model(capsys, tmp_path, dem):
    path, z = dem
    out, stats = tmp_path / "t.stacks.npz", tmp_path / "c.json"
    rc, text, err = run(capsys, "stacks", "convert", path, "-o", out, "--stats", stats)
    assert rc == 0, err
    m = read_stacks(out)
    s = json.loads(stats.read_text())
    valid = (z != NODATA)[::-1].ravel()
    h = z[::-1].ravel().astype(np.float64)
    assert s["base"] == m.origin[2] < h[valid].min() and s["nodata_columns"] == 4
    assert np.array_equal(m.column_tops()[valid], (h[valid] - s["base"]).astype(np.float32))
    assert (m.counts()[~valid] == 0).all() and m.crs == "EPSG:28992"
    assert s["bytes_octree"] is None and "4 nodata columns empty" in text
    rc, _, err = run(capsys, "stacks", "convert", path, "-o", tmp_path / "b.stacks.npz",
                     "--base", 0, "--dz", 0.5)
    assert rc == 0, err
    m = read_stacks(tmp_path / "b.stacks.npz")
    assert m.origin[2] == 0 and np.array_equal(m.column_tops()[valid],
                                                (h[valid] / 0.5).astype(np.float32))


def test_convert_surfaces_makes_a_layered_model(capsys, tmp_path, dem):
    path, z = dem
    low = np.where(z == NODATA, NODATA, z - 5).astype(np.float32)
    low[5, 5] = z[5, 5] + 1                        # above the top: clamped, with a warning
    b1 = write_tif(tmp_path / "b1.tif", low)
    out = tmp_path / "l.stacks.npz"
    rc, _, err = run(capsys, "stacks", "convert", "--surface", path, "--surface", b1,
                     "--base", 20, "-o", out)
    assert rc == 0, err
    assert "1 cells where a surface lies above" in err
    m = read_stacks(out)
    assert m.legend.names == ("dem – b1", "b1 – base 20") and m.origin[2] == 20
    sel = m.codes == 1
    lv = (np.minimum(low, z)[::-1].ravel().astype(np.float64) - 20).astype(np.float32)
    assert np.array_equal(m.starts[sel], lv[m.column_ids()[sel]])


def test_a_labelled_volume_takes_its_top_from_a_dem(capsys, tmp_path):
    a = np.zeros((12, 6, 8), np.int16)               # z up: material 2 under 1, 12 levels
    a[:8] = 2
    a[8:10] = 1
    np.save(tmp_path / "labels.npy", a)
    top = np.full((6, 8), 5.5, np.float32)           # row 0 north; no CRS: taken as it is
    top[:, 4:] = 11.25
    dem = write_tif(tmp_path / "top.tif", top, x0=0.0, ytop=6.0, cell=1.0, crs=None)
    out = tmp_path / "m.stacks.npz"
    rc, _, err = run(capsys, "stacks", "convert", tmp_path / "labels.npy", "--empty", 0,
                     "--top", dem, "-o", out)
    assert rc == 0, err
    m = read_stacks(out)
    assert np.array_equal(m.column_tops(), top[::-1].ravel())
    assert m.meta["top_source"] == str(dem)


@pytest.mark.gl
def test_render_with_a_georeferenced_drape(capsys, tmp_path, dem):
    path, z = dem
    model = tmp_path / "t.stacks.npz"
    assert run(capsys, "stacks", "convert", path, "-o", model)[0] == 0
    ny, nx = z.shape
    img = np.zeros((3, ny, nx // 2), np.uint8)
    img[0] = 255
    half = write_tif(tmp_path / "half.tif", img, x0=500.0 + nx * 5.0, nodata=None)
    stats = tmp_path / "s.json"
    rc, _, err = run(capsys, "stacks", "render", model, "--drape", half, "-o",
                     tmp_path / "d.png", "--size", "96x72", "--frames", 1, "--view", "top",
                     "--stats", stats)
    assert rc == 0, err
    assert "the drape covers 50.0 % of the model's extent" in err
    s = json.loads(stats.read_text())
    assert s["drape"] is True and s["drape_pixels"] > 0 and s["drape_covered"] == 0.5
    assert s["top"] == "smooth"
    # the same render straight from the DEM (converted on the fly)
    rc, _, err = run(capsys, "stacks", "render", path, "-o", tmp_path / "e.png", "--size",
                     "96x72", "--frames", 1, "--stats", stats)
    assert rc == 0, err
    assert json.loads(stats.read_text())["drape"] is False


@pytest.mark.parametrize("case, what", [
    ("far drape", "no overlap, nothing to drape"),
    ("rgb dem", "3 bands; a DEM has one band"),
    ("junk top", "not a raster rasterio can read"),
    ("high base", "base: 100 is not below the lowest surface height"),
    ("no input", "give INPUT, or the surfaces with --surface"),
    ("top of dem", "a DEM top is for a voxel model"),
    ("far surface", "no overlap"),
])
def test_bad_dem_inputs_are_one_line_errors(capsys, tmp_path, dem, case, what):
    path, _ = dem
    out = tmp_path / "o.stacks.npz"
    rgb = write_tif(tmp_path / "rgb.tif", np.zeros((3, 4, 5), np.uint8), nodata=None)
    junk = tmp_path / "junk.tif"
    junk.write_bytes(b"no tiff here")
    far = write_tif(tmp_path / "far.tif", np.zeros((3, 4, 5), np.uint8), x0=9e5, nodata=None)
    far_dem = write_tif(tmp_path / "far_dem.tif", heights(5, 4), x0=9e5)
    np.save(tmp_path / "labels.npy", np.ones((4, 3, 3), np.int8))
    argv = {
        "far drape": ("stacks", "render", path, "--drape", far, "-o", tmp_path / "o.png",
                      "--size", "32x24"),
        "rgb dem": ("stacks", "convert", rgb, "-o", out),
        "junk top": ("stacks", "convert", tmp_path / "labels.npy", "--top", junk, "-o", out),
        "high base": ("stacks", "convert", path, "--base", 100, "-o", out),
        "no input": ("stacks", "convert", "-o", out),
        "top of dem": ("stacks", "convert", path, "--top", path, "-o", out),
        "far surface": ("stacks", "convert", path, "--surface", far_dem, "-o", out),
    }[case]
    rc, _, err = run(capsys, *argv)
    assert rc == 2 and what in err, err
    assert one_line(err), err
    assert not out.exists() and not (tmp_path / "o.png").exists()


def test_a_dem_without_the_geo_extra_names_it(capsys, monkeypatch, dem):
    import sys

    path, _ = dem
    for key in [k for k in sys.modules if k == "rasterio" or k.startswith("rasterio.")]:
        monkeypatch.setitem(sys.modules, key, None)
    monkeypatch.setitem(sys.modules, "rasterio", None)
    for argv in (("info", path), ("stacks", "convert", path, "-o", path.with_name("t.stacks.npz"))):
        rc, _, err = run(capsys, *argv)
        assert rc == 7 and one_line(err), err  # EXIT_EXTRA
        assert "needs rasterio, which is not installed: pip install 'geoshade[geo]'" in err
