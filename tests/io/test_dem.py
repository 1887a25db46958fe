"""DEMs and drapes through rasterio: terrain and layered stack models whose tops and bases equal
the surfaces, a DEM top for a voxel model, drapes placed by their georeference (no GL)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

rasterio = pytest.importorskip("rasterio", reason="the geo extra (rasterio) is not installed")
from affine import Affine  # noqa: E402  (rasterio's dependency)

import geoshade.stacks as st  # noqa: E402
from geoshade.errors import InputError  # noqa: E402
from geoshade.io.layers.dem import (  # noqa: E402
    describe_dem,
    drape_for,
    is_georeferenced,
    read_dem,
    resample,
)
from geoshade.models.stacks import EMPTY  # noqa: E402
from geoshade.models.volume import VoxelVolume  # noqa: E402
from geoshade.stacks.terrain import apply_top, default_base, from_surfaces  # noqa: E402

NODATA = -9999.0
X0, YTOP, CELL = 155000.0, 463000.0, 25.0


def write_tif(path, bands, x0=X0, ytop=YTOP, cell=CELL, crs="EPSG:28992", nodata=NODATA):
    """A GeoTIFF of (count, ny, nx) or (ny, nx) bands, row 0 north."""
    a = np.asarray(bands)
    a = a[None] if a.ndim == 2 else a
    with rasterio.open(path, "w", driver="GTiff", width=a.shape[2], height=a.shape[1],
                       count=a.shape[0], dtype=a.dtype, crs=crs, nodata=nodata,
                       transform=Affine(cell, 0, x0, 0, -cell, ytop)) as dst:
        dst.write(a)
    return path


def smooth_dem(nx=40, ny=30, seed=0) -> np.ndarray:
    """(ny, nx) float32 heights, row 0 north: two hills, a slope, a little noise."""
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[0:ny, 0:nx].astype(np.float64)
    z = 12 + 8 * np.exp(-((x - 12) ** 2 + (y - 10) ** 2) / 60) \
        + 5 * np.exp(-((x - 30) ** 2 + (y - 20) ** 2) / 40) + 0.1 * x
    return (z + rng.normal(0, 0.01, z.shape)).astype(np.float32)


@pytest.fixture
def dem(tmp_path):
    z = smooth_dem()
    z[:2, :3] = NODATA                       # north-west corner: no data
    return write_tif(tmp_path / "dem.tif", z), z


def test_read_dem_has_georeference_nodata_and_south_first_rows(dem):
    path, z = dem
    d = read_dem(path)
    ny, nx = z.shape
    assert d.shape == (nx, ny) and d.crs == "EPSG:28992" and d.nodata == NODATA
    assert d.origin == (X0, YTOP - ny * CELL) and d.spacing == (CELL, CELL)
    expect = np.where(z == NODATA, np.nan, z.astype(np.float64))[::-1]
    assert np.array_equal(d.data, expect, equal_nan=True)
    with rasterio.open(path) as src:                    # the same extent rasterio reports
        assert d.bounds == tuple(src.bounds)
    info = describe_dem(d)
    assert info["nodata_cells"] == 6 and info["size"] == [nx, ny]
    assert info["min"] == float(z[z != NODATA].min()) and info["crs"] == "EPSG:28992"
    assert is_georeferenced(path)


def test_terrain_model_tops_equal_the_dem(dem):
    path, z = dem
    m = st.convert(path)
    ny, nx = z.shape
    valid = (z != NODATA)[::-1].ravel()                  # columns: x fastest, row 0 south
    heights = z[::-1].ravel().astype(np.float64)
    base = default_base(heights[valid])
    assert m.shape == (nx, ny) and m.origin == (X0, YTOP - ny * CELL, base)
    assert m.spacing == (CELL, CELL, 1.0) and m.crs == "EPSG:28992"
    assert m.meta["terrain"] and m.meta["nodata_columns"] == 6
    # each column: the terrain from the base up to the DEM height, then air
    counts = m.counts()
    assert (counts[~valid] == 0).all() and (counts[valid] == 2).all()
    first = m.offsets[:-1][valid]
    assert (m.starts[first] == 0).all() and (m.codes[first] == 1).all()
    assert (m.codes[first + 1] == EMPTY).all()
    # the top is the DEM height (levels above the base, float32), exactly
    tops = m.column_tops()[valid]
    assert np.array_equal(tops, ((heights[valid] - base) / 1.0).astype(np.float32))
    world = m.origin[2] + tops.astype(np.float64) * m.spacing[2]
    assert np.allclose(world, heights[valid], rtol=0, atol=np.spacing(np.float32(64)))
    assert base < heights[valid].min()


def test_terrain_base_and_dz_are_honoured_and_checked(dem):
    path, z = dem
    m = st.convert(path, base=0.0, dz=0.5)
    valid = (z != NODATA)[::-1].ravel()
    expect = (z[::-1].ravel().astype(np.float64)[valid] / 0.5).astype(np.float32)
    assert m.origin[2] == 0.0 and np.array_equal(m.column_tops()[valid], expect)
    with pytest.raises(InputError, match="base: 15 is not below the lowest surface height"):
        st.convert(path, base=15.0)


def test_layered_model_tops_and_bases_equal_the_surfaces(tmp_path):
    top = smooth_dem()
    mid = (top - 3.0 - 0.05 * np.arange(top.shape[1])[None]).astype(np.float32)
    low = mid - np.float32(4.0)
    low[5, 5] = mid[5, 5] + 2.0                # crosses the surface above: clamped to it
    mid[7, 8] = NODATA                          # no data in a lower surface: unit 1 absent
    paths = [write_tif(tmp_path / f"{n}.tif", a)
             for n, a in (("top", top), ("mid", mid), ("low", low))]
    with pytest.warns(UserWarning, match="1 cells where a surface lies above"):
        m = st.convert(None, surfaces=paths)
    assert m.legend.names == ("top – mid", "mid – low") and m.max_intervals == 3
    s = [a[::-1].ravel().astype(np.float64) for a in (top, mid, low)]
    s[1] = np.where(s[1] == NODATA, s[0], s[1])            # the rule: takes the one above
    s[2] = np.minimum(s[2], s[1])                          # the rule: clamped to the one above
    z0 = m.origin[2]
    assert z0 == np.floor(s[2].min())
    lv = [((a - z0) / m.spacing[2]).astype(np.float32) for a in s]
    # per column bottom-up: unit 2 from low, unit 1 from mid, air from top (zero-thickness
    # units left out): rebuild the expected CSR with numpy
    c = np.arange(m.ncols)
    col = m.column_ids()
    for code, start, upper in ((2, lv[2], lv[1]), (1, lv[1], lv[0])):
        present = upper > start
        sel = m.codes == code
        assert np.array_equal(col[sel], c[present])
        assert np.array_equal(m.starts[sel], start[present])
    air = m.codes == EMPTY
    assert np.array_equal(col[air], c) and np.array_equal(m.starts[air], lv[0])
    assert (m.counts() == 1 + (lv[1] > lv[2]) + (lv[0] > lv[1])).all()


def test_surfaces_on_another_grid_are_resampled_to_the_first(tmp_path):
    top = smooth_dem(20, 16)
    fine = np.kron(top - 5.0, np.ones((2, 2))).astype(np.float32)   # the same heights, 2×2
    a = write_tif(tmp_path / "top.tif", top)
    b = write_tif(tmp_path / "fine.tif", fine, cell=CELL / 2)
    m = st.convert(a, surfaces=[b])
    r = resample(read_dem(b), m.origin[:2], m.spacing[:2], m.shape, m.crs)
    # onto cells twice as large: the average of each 2×2 block of equal values, its value
    assert np.allclose(r, (top - 5.0)[::-1], atol=1e-5)
    sel = m.codes == 1
    lv = ((r.ravel() - m.origin[2]) / m.spacing[2]).astype(np.float32)
    assert np.array_equal(m.starts[sel], lv)


def test_voxel_model_takes_its_top_from_a_dem(tmp_path):
    # a GeoTOP-like model: 10 × 8 columns of 100 m, 0.5 m voxels from -10 m, EPSG:28992
    nz, ny, nx = 40, 8, 10
    labels = np.full((nz, ny, nx), np.nan, np.float32)
    labels[:10] = 3
    labels[10:24] = 5
    labels[30:34, 2:4, 2:4] = 7                  # a lens above the ground of most columns
    vol = VoxelVolume(labels, spacing=(100.0, 100.0, 0.5), origin=(X0, YTOP - ny * 100, -10),
                      meta={"crs": "EPSG:28992"}, name="geotop")
    # AHN-like DEM: 25 m cells over the model's extent, heights -4 .. 3.4 m
    y, x = np.mgrid[0:ny * 4, 0:nx * 4]
    dem = (-4.0 + 0.15 * x + 0.05 * y).astype(np.float32)        # row 0 north
    path = write_tif(tmp_path / "ahn.tif", dem, cell=25.0)
    m = st.convert(vol, top=path)
    # oracle: the mean of each column's 4×4 DEM cells (rasterio's average resampling)
    expect = dem.reshape(ny, 4, nx, 4).astype(np.float64).mean(axis=(1, 3))[::-1].ravel()
    lv = ((expect + 10) / 0.5).astype(np.float32)
    tops = m.column_tops()
    assert np.allclose(tops, lv, atol=1e-5)
    assert m.meta["top_from_dem"] and m.meta["top_source"] == str(path)
    # below the new top the model is unchanged: the first intervals are 3 from 0, 5 from 10
    first = m.offsets[:-1]
    assert (m.codes[first] == 3).all() and (m.starts[first] == 0).all()
    assert (m.codes[first + 1] == 5).all() and (m.starts[first + 1] == 10).all()
    # cut (top under level 24: material 5 ends there) or extended (material 5 up to the top)
    assert (m.codes[m.offsets[1:] - 1] == EMPTY).all()
    assert (lv < 24).any() and (lv > 24).any()           # both happen
    assert not (m.codes == 7).any()                     # the lens at levels 30-34: cut away


def test_apply_top_cuts_extends_and_keeps():
    from geoshade.models.stacks import StackModel

    m = StackModel([0, 3, 5, 5], [0, 2, 4, 0, 3], [1, 2, EMPTY, 1, EMPTY], (3, 1), 6)
    with pytest.warns(UserWarning, match="1 columns without material"):
        t = apply_top(m, np.array([[1.5, 7.25, 3.0]]))
    assert t.offsets.tolist() == [0, 2, 4, 4]
    assert t.starts.tolist() == [0, 1.5, 0, 7.25] and t.codes.tolist() == [1, EMPTY, 1, EMPTY]
    assert t.nlevels == 8


def test_crossing_and_bad_inputs_are_one_line(tmp_path, dem):
    path, _ = dem
    rgb = write_tif(tmp_path / "rgb.tif", np.zeros((3, 4, 5), np.uint8), nodata=None)
    with pytest.raises(InputError, match="3 bands; a DEM has one band"):
        read_dem(rgb)
    junk = tmp_path / "junk.tif"
    junk.write_bytes(b"not a tiff at all")
    with pytest.raises(InputError, match="not a raster rasterio can read"):
        read_dem(junk)
    empty = write_tif(tmp_path / "nodata.tif", np.full((3, 3), NODATA, np.float32))
    with pytest.raises(InputError, match="every cell is nodata"):
        read_dem(empty)
    small = write_tif(tmp_path / "small.tif", smooth_dem(5, 5))
    with pytest.raises(InputError, match="shape"):
        from_surfaces([smooth_dem(), smooth_dem(5, 5)])
    far = write_tif(tmp_path / "far.tif", smooth_dem(5, 5), x0=0.0, ytop=1000.0)
    with pytest.raises(InputError, match="no overlap"):
        st.convert(path, surfaces=[far])
    del small


def test_drape_is_cropped_resampled_and_its_overlap_checked(tmp_path, dem):
    path, z = dem
    m = st.convert(path)
    ny, nx = z.shape
    # an orthophoto of 12.5 m pixels over exactly the model's extent, west half red
    img = np.zeros((3, ny * 2, nx * 2), np.uint8)
    img[0, :, :nx] = 255
    img[2, :, nx:] = 255
    full = write_tif(tmp_path / "ortho.tif", img, cell=12.5, nodata=None)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        rgba, frac = drape_for(full, m.origin[:2], m.spacing[:2], m.shape, m.crs)
    assert frac == 1.0 and rgba.shape == (ny * 2, nx * 2, 4)
    assert np.array_equal(rgba[..., :3], np.moveaxis(img, 0, -1)) and (rgba[..., 3] == 255).all()
    # the east 40 % of the model only
    east = write_tif(tmp_path / "east.tif", img[:, :, :32], x0=X0 + 0.6 * nx * CELL,
                     cell=12.5, nodata=None)
    with pytest.warns(UserWarning, match=r"covers 40\.0 % of the model's extent"):
        rgba, frac = drape_for(east, m.origin[:2], m.spacing[:2], m.shape, m.crs)
    assert frac == pytest.approx(0.4)
    assert (rgba[:, : int(0.6 * nx * 2) - 1, 3] == 0).all()
    assert (rgba[:, int(0.6 * nx * 2) + 1:, 3] == 255).all()
    far = write_tif(tmp_path / "far.tif", img, x0=0.0, ytop=1000.0, cell=12.5, nodata=None)
    with pytest.raises(InputError, match="no overlap, nothing to drape"):
        drape_for(far, m.origin[:2], m.spacing[:2], m.shape, m.crs)
    with pytest.raises(InputError, match="no overlap"):   # checked with the options, before GL
        st.StacksOptions.parse(m, drape=far)
    two = write_tif(tmp_path / "two.tif", img[:2], cell=12.5, nodata=None)
    with pytest.raises(InputError, match="2 bands; expected a drape image"):
        drape_for(two, m.origin[:2], m.spacing[:2], m.shape, m.crs)


@pytest.mark.data
def test_geotop_takes_its_top_from_a_dem(shared_data, tmp_path):
    nc = shared_data / "geotop_usp" / "geotop_usp.nc"
    pytest.importorskip("netCDF4", reason="the netcdf extra is not installed")
    m = st.convert(nc, boreholes=None)
    nx, ny = m.shape
    ground = m.origin[2] + m.column_tops().reshape(ny, nx).astype(np.float64) * m.spacing[2]
    # an AHN-like DEM of 25 m cells (4×4 per GeoTOP column): the ground with a 1.5 m wave
    yy, xx = np.mgrid[0:ny * 4, 0:nx * 4]
    dem = (np.kron(ground, np.ones((4, 4))) + 1.5 * np.sin(xx / 6.0) * np.cos(yy / 5.0))
    dem = dem.astype(np.float32)
    path = write_tif(tmp_path / "ahn.tif", dem[::-1], x0=m.origin[0],
                     ytop=m.origin[1] + ny * m.spacing[1], cell=25.0, crs=m.crs)
    t = st.convert(nc, boreholes=None, top=path)
    expect = dem.astype(np.float64).reshape(ny, 4, nx, 4).mean(axis=(1, 3)).ravel()
    lv = ((expect - m.origin[2]) / m.spacing[2]).astype(np.float32)
    assert np.allclose(t.column_tops(), lv, atol=1e-4)
    # under the lower of both tops every column is what GeoTOP says
    from geoshade.compute.stacks import stacks_to_voxels

    a, b = stacks_to_voxels(m), stacks_to_voxels(t)
    keep = np.arange(a.shape[0])[:, None, None] + 1 <= np.minimum(
        m.column_tops(), t.column_tops()).reshape(ny, nx)[None]
    assert b.shape[0] >= a.shape[0] and keep.sum() > 0.5 * a[a != EMPTY].size
    assert np.array_equal(a[keep], b[: a.shape[0]][keep])


def test_a_grid_without_crs_is_taken_as_it_is_with_a_warning(tmp_path):
    top = smooth_dem(20, 16)
    a = write_tif(tmp_path / "top.tif", top)
    fine = np.kron(top - 5.0, np.ones((2, 2))).astype(np.float32)
    b = write_tif(tmp_path / "fine.tif", fine, cell=CELL / 2, crs=None)
    with pytest.warns(UserWarning, match="has no CRS .*EPSG:28992.*taken as they are"):
        m = st.convert(a, surfaces=[b])
    lv = (((top - 5.0)[::-1].ravel().astype(np.float64) - m.origin[2]) / m.spacing[2])
    assert np.allclose(m.starts[m.codes == 1], lv.astype(np.float32), atol=1e-5)
    # a drape in another CRS is reprojected: its coverage is that of its bounds in the model's
    from rasterio.warp import transform_bounds

    img = np.full((3, 8, 8), 200, np.uint8)
    lon_lat = transform_bounds("EPSG:28992", "EPSG:4326", X0 + 100, YTOP - 300, X0 + 300,
                               YTOP - 100)
    wgs = write_tif(tmp_path / "wgs.tif", img, x0=lon_lat[0], ytop=lon_lat[3],
                    cell=(lon_lat[2] - lon_lat[0]) / 8, crs="EPSG:4326", nodata=None)
    with rasterio.open(wgs) as src:
        back = transform_bounds(src.crs, "EPSG:28992", *src.bounds)
    ext = m.bounds()
    area = (min(back[2], ext[1, 0]) - max(back[0], ext[0, 0])) \
        * (min(back[3], ext[1, 1]) - max(back[1], ext[0, 1]))
    with pytest.warns(UserWarning, match="the drape covers"):
        rgba, frac = drape_for(wgs, m.origin[:2], m.spacing[:2], m.shape, m.crs)
    full = (ext[1, 0] - ext[0, 0]) * (ext[1, 1] - ext[0, 1])
    assert frac == pytest.approx(area / full, rel=1e-9)
    assert (rgba[..., 3] == 255).sum() == pytest.approx(frac * rgba[..., 3].size, rel=0.15)


def test_geoshade_load_reads_a_dem_as_a_terrain_model(dem):
    import geoshade
    from geoshade.models import StackModel

    model = geoshade.load(dem[0])
    assert isinstance(model, StackModel)
    assert geoshade.api.view_kind(model) == "stacks"


def test_geographic_dem_is_reprojected_to_utm_of_its_centre(tmp_path):
    """An SRTM-like DEM in EPSG:4326 becomes a metric terrain (UTM 31N here) with one note; its
    heights at given places equal the source's there (bilinear both ways)."""
    from rasterio.warp import transform

    z = smooth_dem(60, 40)
    geo = write_tif(tmp_path / "wgs84.tif", z, x0=5.0, ytop=52.04, cell=0.001, crs="EPSG:4326")
    with pytest.warns(UserWarning, match="reprojected from EPSG:4326 .degrees. to EPSG:32631 "
                                        "[(]UTM zone 31N, the DEM's centre[)]: "):
        r = read_dem(geo)
    assert r.crs == "EPSG:32631" and not r.meta["geographic"]
    assert r.spacing[0] == r.spacing[1] and 60 < r.spacing[0] < 115   # metres, not degrees
    # heights at the centres of source cells, found in the metric raster by their UTM position
    rows, cols = np.meshgrid(np.arange(8, 32, 5), np.arange(8, 52, 7), indexing="ij")
    lon = 5.0 + (cols.ravel() + 0.5) * 0.001
    lat = 52.04 - (rows.ravel() + 0.5) * 0.001
    xs, ys = transform("EPSG:4326", r.crs, lon, lat)
    ix = (np.asarray(xs) - r.origin[0]) / r.spacing[0] - 0.5
    iy = (np.asarray(ys) - r.origin[1]) / r.spacing[1] - 0.5   # row 0 south
    i0, j0 = np.floor(ix).astype(int), np.floor(iy).astype(int)
    fx, fy = ix - i0, iy - j0
    d = r.data
    got = ((1 - fx) * (1 - fy) * d[j0, i0] + fx * (1 - fy) * d[j0, i0 + 1]
           + (1 - fx) * fy * d[j0 + 1, i0] + fx * fy * d[j0 + 1, i0 + 1])
    want = z[rows.ravel(), cols.ravel()]
    span = float(z.max() - z.min())
    assert np.abs(got - want).max() < 0.03 * span
    # the terrain built from it says so; degrees are kept when asked
    with pytest.warns(UserWarning, match="reprojected"):
        m = st.convert(geo)
    assert m.crs == "EPSG:32631" and "reprojected from EPSG:4326" in m.meta["notes"][0]
    assert read_dem(geo, project=False).crs == "EPSG:4326"
    from geoshade.io.layers.dem import describe_dem, format_dem

    assert "note     reprojected from EPSG:4326" in format_dem(describe_dem(r))
