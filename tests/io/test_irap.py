"""IRAP surfaces (RMS classic, ASCII and binary) and rotated GeoTIFFs as terrain (issue 31, item 3).

Oracle: xtgeo (``surface_from_file``: node values, header, rotation; ``get_value_from_xy``:
bilinear values at a point of a rotated surface) on the real Drogon and Reek surfaces of
xtgeo-testdata (tests/data/real/rms_irap_drogon), and rasterio for the GeoTIFFs written here.
"""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import numpy as np
import pytest

from geoshade.errors import InputError
from geoshade.io import formats
from geoshade.io.layers.dem import read_dem, read_terrain
from geoshade.io.layers.irap import UNDEF, is_irap_binary, read_irap, read_irap_values

xtgeo = pytest.importorskip("xtgeo")
rasterio = pytest.importorskip("rasterio")

DROGON = Path(__file__).parents[1] / "data" / "real" / "rms_irap_drogon"
TOP, STOOIP = DROGON / "01_topvolantis.gri", DROGON / "reek_stooip_map.gri"


def _xtgeo_nodes(path) -> np.ndarray:
    """xtgeo's node values as (ny, nx), NaN undefined (xtgeo holds (ncol, nrow))."""
    return np.ma.filled(xtgeo.surface_from_file(path).values.astype(float), np.nan).T


def _centres(r):
    ny, nx = r.data.shape
    return (r.origin[0] + (np.arange(nx) + 0.5) * r.spacing[0],
            r.origin[1] + (np.arange(ny) + 0.5) * r.spacing[1])


def _check_against_xtgeo(r, path, n=400, sign=1.0):
    """Every sampled cell centre: ours equals xtgeo's bilinear value where xtgeo has one."""
    s = xtgeo.surface_from_file(path)
    xs, ys = _centres(r)
    rng = np.random.default_rng(7)
    finite = np.argwhere(np.isfinite(r.data))
    compared = 0
    for j, i in finite[rng.choice(len(finite), n, replace=False)]:
        v = s.get_value_from_xy((xs[i], ys[j]))
        if v is None:      # the half cell at the hull's edge: ours holds the edge node's value
            continue
        assert sign * r.data[j, i] == pytest.approx(v, abs=1e-6, rel=1e-9), (j, i)
        compared += 1
    assert compared > n * 0.9
    return s


@pytest.mark.parametrize("path", [TOP, STOOIP], ids=["drogon", "stooip"])
def test_binary_nodes_equal_xtgeo(path):
    head, z = read_irap_values(path)
    s = xtgeo.surface_from_file(path)
    assert is_irap_binary(path)
    assert (head["nx"], head["ny"]) == (s.ncol, s.nrow)
    assert (head["xinc"], head["yinc"]) == pytest.approx((s.xinc, s.yinc))
    assert (head["xori"], head["yori"], head["rotation"]) == pytest.approx(
        (s.xori, s.yori, s.rotation))
    np.testing.assert_array_equal(z, _xtgeo_nodes(path))
    assert int(np.isnan(z).sum()) == int(np.ma.getmaskarray(s.values).sum())


def test_ascii_written_by_xtgeo_reads_the_same(tmp_path):
    for path in (TOP, STOOIP):
        out = tmp_path / (path.stem + ".fgr")
        xtgeo.surface_from_file(path).to_file(out, fformat="irap_ascii")
        assert not is_irap_binary(out)
        h1, z1 = read_irap_values(out)
        h2, z2 = read_irap_values(path)
        np.testing.assert_allclose(z1, z2, rtol=1e-6, atol=1e-6, equal_nan=True)  # 6 decimals
        assert h1["rotation"] == pytest.approx(h2["rotation"])
        # RMS also names the ASCII form .gri: the content decides
        same = tmp_path / (path.stem + "_ascii.gri")
        shutil.copy(out, same)
        np.testing.assert_array_equal(read_irap_values(same)[1], z1)


def test_unrotated_map_is_its_nodes_as_cells():
    r = read_irap(STOOIP, positive="up")
    s = xtgeo.surface_from_file(STOOIP)
    np.testing.assert_array_equal(r.data, _xtgeo_nodes(STOOIP))   # row j = 0 is south
    assert r.origin == (s.xori - s.xinc / 2, s.yori - s.yinc / 2)
    assert r.spacing == (s.xinc, s.yinc) and "rotated" not in r.meta


def test_rotated_surface_is_placed_with_its_rotation():
    r = read_irap(TOP)   # depth, positive down: heights are -value
    assert r.meta["rotation"] == pytest.approx(30.0)
    assert "rotated 30°" in r.meta["rotated"] and "north-up" in r.meta["rotated"]
    assert any("depth" in a for a in r.meta["assumed"])
    s = _check_against_xtgeo(r, TOP, sign=-1.0)
    # the north-up grid covers the rotated one's footprint, NaN outside it
    x, y = s.get_xy_values()
    xs, ys = _centres(r)
    assert xs[0] - r.spacing[0] < float(x.min()) < xs[0] + r.spacing[0]
    assert ys[-1] - r.spacing[1] < float(y.max()) < ys[-1] + r.spacing[1]
    corner = r.data[:5, :5]            # the south-west corner lies outside a turned rectangle
    assert np.isnan(corner).all()
    assert np.nanmin(-r.data) >= float(s.values.min()) - 1e-6
    assert np.nanmax(-r.data) <= float(s.values.max()) + 1e-6


def test_negative_yinc_and_rotation_as_xtgeo_places_them(tmp_path):
    p = tmp_path / "neg.fgr"
    p.write_text("-996 3 10 -20\n100 110 200 240\n2 30 100 200\n0 0 0 0 0 0 0\n"
                 "1 2 3 4 5 6\n")
    r = read_irap(p, positive="up")
    s = xtgeo.surface_from_file(p, fformat="irap_ascii")
    xs, ys = _centres(r)
    seen = 0
    for j, i in np.argwhere(np.isfinite(r.data)):
        v = s.get_value_from_xy((xs[i], ys[j]))
        if v is not None:
            assert r.data[j, i] == pytest.approx(v)
            seen += 1
    assert seen >= 3


def test_irap_is_a_terrain_row_read_by_load(tmp_path):
    import geoshade

    for name in ("a.gri", "a.irap", "a.fgr", "a.irapbin"):
        fmt = formats.find(name, sniff=False)
        assert fmt.name == "irap" and fmt.domain == "terrain"
    assert read_terrain(TOP).meta["format"] == "irap"
    model = geoshade.load(TOP)
    assert type(model).__name__ == "StackModel"
    assert any("rotated 30°" in n for n in model.meta["notes"])
    assert model.unit == "m (assumed)"
    top = model.origin[2] + model.column_tops() * model.spacing[2]
    has = model.counts() > 0
    r = read_irap(TOP)
    np.testing.assert_allclose(np.sort(top[has]), np.sort(r.data[np.isfinite(r.data)]),
                               atol=1e-3)


def test_info_describes_an_irap_surface(capsys):
    from geoshade.cli.main import main

    assert main(["info", str(TOP)]) == 0
    out = capsys.readouterr().out
    r = read_irap(TOP)
    assert "IRAP surface (RMS)" in out and "rasterio" not in out.splitlines()[0]
    assert "rotated 30°" in out and "depth" in out and "metres assumed" in out
    assert f"min {np.nanmin(r.data):.6g}, max {np.nanmax(r.data):.6g}" in out


@pytest.mark.parametrize("damage,expect", [
    (lambda b: b[:200], "truncated"),
    (lambda b: b[:8] + b"\x00" * 24 + b[32:], None),
    (lambda b: b"hello world", "not a number|IRAP"),
    (lambda b: b[:-3000], "truncated|values for"),
])
def test_damaged_files_are_one_line(tmp_path, damage, expect):
    p = tmp_path / "bad.gri"
    p.write_bytes(damage(STOOIP.read_bytes()))
    with pytest.raises(InputError) as err:
        read_irap(p)
    msg = str(err.value)
    assert "\n" not in msg and str(p) in msg
    if expect:
        assert any(e in msg for e in expect.split("|")), msg


def test_all_undefined_is_one_line(tmp_path):
    p = tmp_path / "u.fgr"
    p.write_text(f"-996 2 1 1\n0 1 0 1\n2 0 0 0\n0 0 0 0 0 0 0\n{UNDEF} {UNDEF} {UNDEF} {UNDEF}\n")
    with pytest.raises(InputError, match="every node is undefined"):
        read_irap(p)


# --- rotated GeoTIFF ---------------------------------------------------------------------------
def _rotated_tif(path, crs="EPSG:23031"):
    """Drogon's top written as a GeoTIFF whose transform carries the IRAP rotation."""
    from affine import Affine

    head, z = read_irap_values(TOP)
    rot = math.radians(head["rotation"])
    c, s = math.cos(rot), math.sin(rot)
    ny = head["ny"]
    top = (head["xori"] - (ny - 1) * head["yinc"] * s, head["yori"] + (ny - 1) * head["yinc"] * c)
    t = Affine(head["xinc"] * c, head["yinc"] * s, top[0], head["xinc"] * s,
               -head["yinc"] * c, top[1]) @ Affine.translation(-0.5, -0.5)
    with rasterio.open(path, "w", driver="GTiff", width=head["nx"], height=ny, count=1,
                       dtype="float32", crs=crs, transform=t, nodata=-9999.0) as dst:
        dst.write(np.where(np.isfinite(z), z, -9999.0)[::-1].astype(np.float32), 1)
    return path


def test_rotated_geotiff_is_placed_with_its_rotation(tmp_path):
    tif = _rotated_tif(tmp_path / "rot.tif")
    with rasterio.open(tif) as f:
        assert f.transform.b != 0 and f.transform.d != 0   # rotation terms
    d = read_dem(tif)
    assert "rotated 30°" in d.meta["rotated"] and d.crs == "EPSG:23031"
    _check_against_xtgeo(d, TOP)                  # the same nodes, values as xtgeo places them
    irap = read_irap(TOP, positive="up")
    np.testing.assert_allclose(d.data, irap.data, rtol=1e-6, equal_nan=True)
    assert d.origin == pytest.approx(irap.origin) and d.spacing == pytest.approx(irap.spacing)


@pytest.mark.filterwarnings("ignore:.*the drape covers")
def test_rotated_drape_is_placed_by_the_warp(tmp_path):
    from affine import Affine

    from geoshade.io.layers.dem import drape_for

    p = tmp_path / "drape.tif"
    t = Affine.translation(1000, 2000) @ Affine.rotation(20) @ Affine.scale(10, -10)
    img = np.full((3, 40, 60), 200, np.uint8)
    with rasterio.open(p, "w", driver="GTiff", width=60, height=40, count=3, dtype="uint8",
                       crs="EPSG:28992", transform=t) as dst:
        dst.write(img)
    rgba, covered = drape_for(p, (1000.0, 1600.0), (10.0, 10.0), (60, 40), "EPSG:28992")
    assert 0 < covered <= 1 and rgba.shape[2] == 4
    assert (rgba[..., 3] == 0).any() and (rgba[..., 3] == 255).any()   # corners outside
